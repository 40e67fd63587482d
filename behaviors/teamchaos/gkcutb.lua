-- gkcutb (seed 001 §4.1): keep the goalkeeper on the trajectory from the ball to the centre
-- of our net, head towards the ball, and clear with a front kick when the ball is close and
-- the robot points to a safe area. The seed's rules, one for one.
local off = offsetFromBallToNet()
local posLeft, posAhead, posRight = TOR(50, 300)(off), TRI(-150, 0, 150)(off), TOL(-300, -50)(off)
rule(posLeft, "strafe", "RIGHT")
rule(posAhead, "strafe", "NONE")
rule(posRight, "strafe", "LEFT")
rule(headedLeft(), "turn", "RIGHT")
rule(headedAhead(), "turn", "NONE")
rule(headedRight(), "turn", "LEFT")
rule(AND(freeToKick(), ballClose()), "kick", "FRONTKICK")
always("go", "STAY")
need(1, BALL)
