-- gkcutb (ThinkingCap/TeamChaos report §4.1): keep the goalkeeper between the ball and our net: on a line 400 mm
-- out of the goal line, level with the ball (within the posts), facing the ball; clear with a
-- front kick when the ball is close and the robot points to a safe area. The spot is a posture
-- for guidance (position mode: straight there at the base's speed, turning to the ball). With
-- gotopos' fuzzy labels the keeper strafed along the line at 0.4 m/s, a third of the base's
-- top speed, and fell behind the ball's moves.
-- A posture outranks the velocities of a blend: while goalkeeper's meta-rules also give
-- gkclearb a part, the keeper holds this spot rather than going for the ball.
local b, f, p = chaos.getGlobalBall(), field(), chaos.gsGetMyPos()
local lim = f.goal_half_width - 100
local x, y = -f.half_length + 400, math.max(-lim, math.min(lim, b.y))
chaos.setTarget(x, y, math.atan(b.y - p.y, b.x - p.x), false)
need(1, BALL)
rule(AND(freeToKick(), ballClose()), "kick", "FRONTKICK")
