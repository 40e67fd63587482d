-- gkkeeparea (ThinkingCap/TeamChaos report §4.3): face forward, then move back into the goal area.
local p = chaos.gsGetMyPos()
local facingForward = TRI(-0.3, 0, 0.3)(p.theta)
local homeX = -field().half_length + GOAL_AREA_DEPTH / 2
rule(TOR(0.1, 0.6)(p.theta), "turn", "RIGHT")       -- turned left: turn right
rule(TOL(-0.6, -0.1)(p.theta), "turn", "LEFT")
rule(facingForward, "turn", "NONE")
rule(AND(facingForward, TOR(100, 800)(p.x - homeX)), "go", "SLOWBACK")
rule(AND(facingForward, TOR(100, 800)(homeX - p.x)), "go", "SLOW")
rule(OR(NOT(facingForward), TRI(-150, 0, 150)(p.x - homeX)), "go", "STAY")
rule(TOR(100, 600)(p.y), "strafe", "RIGHT")
rule(TOL(-600, -100)(p.y), "strafe", "LEFT")
rule(TRI(-200, 0, 200)(p.y), "strafe", "NONE")
need(1, NET1)
chaos.trackLandMarks()
