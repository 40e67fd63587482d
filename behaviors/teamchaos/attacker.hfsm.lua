-- The Attacker HFSM (ThinkingCap/TeamChaos report §5.2, figures 10 and 11), as one Lua file like the seed's HFSM
-- editor generated. It expects the ball in direct view (a higher machine takes care of that).
-- Each state calls one low-level behavior of this directory; transitions test the LPS.

local function ball() return chaos.lps_getLpo(BALL) end

-- The attacker keeps the ball booked while it attacks (ThinkingCap/TeamChaos report §3.3: a teammate that also
-- goes for the ball waits for the booking); a booking not asked for again lapses in 5 s.
local function attack(behavior)
  chaos.bookBall()
  chaos.setBehavior(behavior)
end

machine "Attacker" {
  initial = "FaceBall",
  states = {
    -- Turn towards the ball.
    FaceBall = function() attack("faceball") end,
    -- Walk to the ball, keeping localized on the long way (the seed's GoToBall code).
    GoToBall = function()
      if chaos.gsGetMyPos().quality < 0.6 then
        chaos.trackLandMarks()
      end
      if chaos.lps_getLpo(NET1).seen_ago > 5 and chaos.lps_getLpo(NET2).seen_ago > 5 then
        chaos.setNeeded(NET1, 0.5) -- no net seen for a while: look for the opponent's
      end
      attack("go2ball")
    end,
    -- Close to the ball (about 50 cm): score.
    Score = meta "Score",
  },
  transitions = {
    { name = "BallAhead", from = "FaceBall", to = "GoToBall", test = "math.abs(chaos.lps_getLpo(BALL).theta) < 0.25" },
    { name = "NearBall", from = "GoToBall", to = "Score", priority = 1, test = "chaos.lps_getLpo(BALL).rho < 500" },
    { name = "BallAside", from = "GoToBall", to = "FaceBall", priority = 2, test = "math.abs(chaos.lps_getLpo(BALL).theta) > 0.8" },
    -- Checked before any transition inside Score: the ball got away.
    { name = "BallAway", from = "Score", to = "GoToBall", test = "chaos.lps_getLpo(BALL).rho > 900" },
  },
}

local function aligned() return aimAligned() end

machine "Score" {
  initial = "ApproachBall",
  states = {
    -- Precise approach: no localization tasks, eyes on the ball.
    ApproachBall = function() attack("go2ball") end,
    Align = function() attack("alignbnet1") end,
    DoKick = function() attack("dokick") end,
  },
  transitions = {
    -- The seed's Kickable: the ball is closer than 60 cm.
    { name = "Kickable", from = "ApproachBall", to = "DoKick", priority = 1,
      test = function() return ball().rho < 600 and aligned() end },
    { name = "Misaligned", from = "ApproachBall", to = "Align", priority = 2,
      test = function() return ball().rho < 600 and not aligned() end },
    { name = "Aligned", from = "Align", to = "DoKick", test = aligned },
    { name = "LostAlignment", from = "DoKick", to = "Align", test = function() return not aligned() end },
  },
}
