-- lookball (ThinkingCap, ThinkingCap/TeamChaos report §4.3): turn on the spot until the ball is seen, towards
-- where it was last seen; slowly for the first 400 ms (the ball may be close), then faster.
-- As printed in the seed, which lays the first lines out garbled; the code is unchanged.
-- One guard added: when ball.theta is 0 the seed divides 0 by 0 (NaN); we keep the sign 1.
slowTime = 400
local ball = chaos.lps_getLpo(BALL)
local info = chaos.getBehaviorInfo()
if info.isNew > 0 then
  sgn = ball.theta / math.abs(ball.theta)
  if sgn ~= sgn then sgn = 1 end -- added guard: 0/0
  chaos.setGlobal("BALL_DIRECTION", INTEGER, sgn)
end
sgn = chaos.getGlobal("BALL_DIRECTION")
vrot = 0
if info.timer < slowTime then
  vrot = 50 * sgn
else
  vrot = 75 * sgn
end
chaos.setNeeded(BALL, 1.0)
chaos.setVlin(0)
chaos.setVrot(vrot)
chaos.setVlat(0)
