-- gkcutb (seed 001 §4.1): keep the goalkeeper between the ball and our net: on a line 400 mm
-- out of the goal line, level with the ball (within the posts), facing the ball; clear with a
-- front kick when the ball is close and the robot points to a safe area.
local b, f = chaos.getGlobalBall(), field()
local lim = f.goal_half_width - 100
TARGET_X = -f.half_length + 400
TARGET_Y = math.max(-lim, math.min(lim, b.y))
use(1, "gotopos")
rule(AND(freeToKick(), ballClose()), "kick", "FRONTKICK")
