-- Shared definitions of the TeamChaos behaviors (seed 001 §4): field geometry and the fuzzy
-- predicates the rules use. Run once when the directory is loaded (and again when edited).
-- Units: LPS distances in mm and bearings in radians (left positive); the global frame has its
-- origin at the centre spot, x towards the opponent's net (NET1), our net (NET2) at
-- x = -FIELD_HALF_LENGTH.

FIELD_HALF_LENGTH = 9000 -- Middle Size League field, 18 m x 12 m
GOAL_HALF_WIDTH = 1000
GOAL_AREA_DEPTH = 750
PENALTY_AREA_DEPTH = 2250

-- Membership functions (figure 5 style), built once.
local CLOSE = TOL(250, 750)         -- 1 up to 25 cm, 0 from 75 cm: 0.7 at 40 cm
local TOUCHING = TOL(150, 350)      -- close enough to kick
local FAR = TOR(800, 2000)
local RELIABLE = TOR(0.1, 0.5)      -- the anchor is trustworthy
local LEFT = TOR(0.05, 0.5)         -- bearing to the left (rad)
local AHEAD = TRI(-0.3, 0, 0.3)
local RIGHT = TOL(-0.5, -0.05)
local SAFE_HEADING = TOL(0.5, 1.2)  -- |heading| towards the opponent's half

function lpo(i) return chaos.lps_getLpo(i) end

-- Ball predicates.
function ballSeen() return RELIABLE(lpo(BALL).reliability) end
function ballClose() return AND(ballSeen(), CLOSE(lpo(BALL).rho)) end
function ballTouching() return AND(ballSeen(), TOUCHING(lpo(BALL).rho)) end
function ballFar() return AND(ballSeen(), FAR(lpo(BALL).rho)) end
function ballLeft() return LEFT(lpo(BALL).theta) end
function ballAhead() return AHEAD(lpo(BALL).theta) end
function ballRight() return RIGHT(lpo(BALL).theta) end

-- The robot is headed to the left of the ball when the ball is on its right, and so on.
function headedLeft() return ballRight() end
function headedAhead() return ballAhead() end
function headedRight() return ballLeft() end

-- Our heading points to a safe area (away from our own net).
function freeToKick() return SAFE_HEADING(math.abs(chaos.gsGetMyPos().theta)) end

-- The opponent's net seen left / right of the ball (for alignment).
function netLeftOfBall()
  local n, b = lpo(NET1), lpo(BALL)
  return AND(RELIABLE(n.reliability), TOR(0.05, 0.4)(n.theta - b.theta))
end
function netRightOfBall()
  local n, b = lpo(NET1), lpo(BALL)
  return AND(RELIABLE(n.reliability), TOL(-0.4, -0.05)(n.theta - b.theta))
end
function netBehindBall()
  local n, b = lpo(NET1), lpo(BALL)
  return AND(RELIABLE(n.reliability), TRI(-0.2, 0, 0.2)(n.theta - b.theta))
end

-- Localization.
function wellLocalized() return TOR(0.4, 0.8)(chaos.gsGetMyPos().quality) end

-- Goalkeeper geometry, from the global state.
-- Inside our own net: behind the goal line (x < -FIELD_HALF_LENGTH), fading over 25 cm.
function inOwnNet() return TOL(-FIELD_HALF_LENGTH - 100, -FIELD_HALF_LENGTH + 150)(chaos.gsGetMyPos().x) end
function inGoalArea()
  local p = chaos.gsGetMyPos()
  return AND(TOL(-FIELD_HALF_LENGTH + GOAL_AREA_DEPTH, -FIELD_HALF_LENGTH + GOAL_AREA_DEPTH + 500)(p.x),
             TOL(GOAL_HALF_WIDTH + 500, GOAL_HALF_WIDTH + 1000)(math.abs(p.y)))
end
function ballInArea()
  local b = chaos.getGlobalBall()
  return AND(TOR(0.2, 0.5)(b.quality),
             TOL(-FIELD_HALF_LENGTH + PENALTY_AREA_DEPTH, -FIELD_HALF_LENGTH + PENALTY_AREA_DEPTH + 500)(b.x))
end

-- Signed lateral offset (mm) of the robot from the line joining the ball to the centre of our
-- net, positive when the robot is on the left of that line as seen from the field (+y).
function offsetFromBallToNet()
  local b, p = chaos.getGlobalBall(), chaos.gsGetMyPos()
  local nx = -FIELD_HALF_LENGTH
  if math.abs(b.x - nx) < 1 then return p.y - b.y end
  local yline = b.y + (0 - b.y) * (p.x - b.x) / (nx - b.x)
  return p.y - yline
end
