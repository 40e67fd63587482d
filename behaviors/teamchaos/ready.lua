-- ready: in READY, walk to the kickoff position of the referee's formation (chaos.getKickoffPose,
-- team frame) facing the way it says; guidance drives there round the other robots
-- (potential-field mode, ISocRob-2000 report §3.2.3). Watch the ball meanwhile.
local p = chaos.getKickoffPose()
if p then chaos.setTarget(p.x, p.y, p.theta) end
always("go", "STAY")
always("turn", "NONE")
always("strafe", "NONE")
need(1, BALL)
