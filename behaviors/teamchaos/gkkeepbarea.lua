-- gkkeepbarea (ThinkingCap/TeamChaos report §4.3): face backwards (towards our net), then move to just below the
-- penalty area line.
local p = chaos.gsGetMyPos()
local back = math.abs(p.theta)                         -- pi when facing our net
local facingBack = TOR(math.pi - 0.4, math.pi - 0.05)(back)
local targetX = -field().half_length + field().penalty_area_depth - 300
rule(AND(NOT(facingBack), TOR(0, 0.1)(p.theta)), "turn", "LEFT")   -- turn the short way round
rule(AND(NOT(facingBack), TOL(-0.1, 0)(p.theta)), "turn", "RIGHT")
rule(facingBack, "turn", "NONE")
-- Facing back, going forward decreases x.
rule(AND(facingBack, TOR(100, 800)(p.x - targetX)), "go", "SLOW")
rule(AND(facingBack, TOR(100, 800)(targetX - p.x)), "go", "SLOWBACK")
rule(OR(NOT(facingBack), TRI(-150, 0, 150)(p.x - targetX)), "go", "STAY")
always("strafe", "NONE")
need(1, NET2)
chaos.trackLandMarks()
