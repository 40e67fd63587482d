-- goalkeeper (seed 001 §4.3, figure 7): the top of the goalkeeper hierarchy. Meta-rules choose
-- and blend the sub-behaviors by context: get out of the net, scan for a lost ball, localize
-- when lost, clear a ball in the penalty area, otherwise cut the ball's way to the net, and
-- go back home when away from the goal area. In READY it walks to its kickoff position first.
if chaos.getKickoffPose() then
  use(1, "ready")
  return
end
local seen = ballSeen()
local lost = NOT(wellLocalized())
use(inOwnNet(), "gkkeepout")
use(AND(NOT(inOwnNet()), NOT(seen)), "gkscanobj")
use(AND(NOT(inOwnNet()), seen, lost), "gklocalize")
use(AND(NOT(inOwnNet()), seen, NOT(lost), ballInArea()), "gkclearb")
use(AND(NOT(inOwnNet()), seen, NOT(lost), NOT(ballInArea()), inGoalArea()), "gkcutb")
use(AND(NOT(inOwnNet()), seen, NOT(lost), NOT(ballInArea()), NOT(inGoalArea())), "gkkeeparea")
