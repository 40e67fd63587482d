-- gotopos: go to the field point (TARGET_X, TARGET_Y), set by the HFSM state that calls it,
-- while facing the ball (the global ball when the robot's own camera lost it). The base is
-- holonomic: it moves forward and sideways at once, and turns on the way.
local p = chaos.gsGetMyPos()
local fw, left = inRobotFrame(TARGET_X or p.x, TARGET_Y or p.y)
rule(TOR(200, 1200)(fw), "go", "FAST")
rule(TRI(-300, 0, 300)(fw), "go", "STAY")
rule(TOL(-1200, -200)(fw), "go", "BACK")
rule(TOR(100, 600)(left), "strafe", "LEFT")
rule(TRI(-300, 0, 300)(left), "strafe", "NONE")
rule(TOL(-600, -100)(left), "strafe", "RIGHT")
-- Face the ball.
local b = chaos.getGlobalBall()
local a = ballSeen() > 0.5 and lpo(BALL).theta or bearingTo(b.x, b.y)
rule(TOR(0.6, 1.5)(a), "turn", "HARDLEFT")
rule(TRI(0, 0.6, 1.5)(a), "turn", "LEFT")
rule(TRI(-0.3, 0, 0.3)(a), "turn", "NONE")
rule(TRI(-1.5, -0.6, 0)(a), "turn", "RIGHT")
rule(TOL(-1.5, -0.6)(a), "turn", "HARDRIGHT")
need(1, BALL)
