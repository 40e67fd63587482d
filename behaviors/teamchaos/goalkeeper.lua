-- goalkeeper (ThinkingCap/TeamChaos report §4.3, figure 7): the top of the goalkeeper hierarchy. Meta-rules choose
-- and blend the sub-behaviors by context: get out of the net, scan for a lost ball, localize
-- when lost, clear a ball in the penalty area within reach (1.5 m: farther, an opponent gets
-- there first and shoots at an empty net), otherwise hold the spot on the goal line that cuts
-- the ball's way to the net (gkcutb, which also brings the keeper home: the seed's gkkeeparea
-- stays shipped but unused; with it the keeper faced the field, not the ball, on its way
-- back). In READY it walks to its kickoff position first.
if chaos.getKickoffPose() then
  use(1, "ready")
  return
end
local seen = ballSeen()
local lost = NOT(wellLocalized())
local clear = AND(ballInArea(), TOL(800, 1500)(lpo(BALL).rho))
use(inOwnNet(), "gkkeepout")
use(AND(NOT(inOwnNet()), NOT(seen)), "gkscanobj")
use(AND(NOT(inOwnNet()), seen, lost), "gklocalize")
use(AND(NOT(inOwnNet()), seen, NOT(lost), clear), "gkclearb")
use(AND(NOT(inOwnNet()), seen, NOT(lost), NOT(clear)), "gkcutb")
