-- Shared definitions of the TeamChaos behaviors (ThinkingCap/TeamChaos report §4): field geometry and the fuzzy
-- predicates the rules use. Run once when the directory is loaded (and again when edited).
-- Units: LPS distances in mm and bearings in radians (left positive); the global frame has its
-- origin at the centre spot, x towards the opponent's net (NET1), our net (NET2) at
-- x = -field().half_length.

-- The field the robot plays on, from the world model's map (half_length, half_width,
-- goal_half_width, penalty_area_depth, in mm): 18 m x 12 m in the Middle Size League.
function field() return chaos.getField() end
GOAL_AREA_DEPTH = 750

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

-- Where to shoot: the side of the opponent's net away from its goalkeeper (the opponent MAP
-- anchored nearest that net), 250 mm inside the post; the middle when no keeper is anchored.
function aimPoint()
  local f = field()
  local keeper, best = nil, 2500
  for _, r in ipairs(chaos.getRobots()) do
    if r.class == "opponent" and r.reliability > 0.3 then
      local d = math.sqrt((r.x - f.half_length) ^ 2 + r.y ^ 2)
      if d < best then keeper, best = r, d end
    end
  end
  if not keeper then return f.half_length, 0 end
  local side = keeper.y > 0 and -1 or 1
  return f.half_length, side * (f.goal_half_width - 250)
end

-- The bearing to shoot at (rad, left positive). A robot localized well (quality at least
-- AIM_BY_POSE) aims by its global pose. The others aim by the opponent's net as the camera
-- sees it, moved from its middle to the aim point (the seed's alignment, for an AIBO that was
-- often lost), or by the pose when the net is not in view. With the cameras, a net cut by the
-- image's border is seen off its middle: in a vision match the camera's bearing was more than
-- 0.2 rad off the pose's in one Align cycle in five, the pose's heading 0.2 deg off the truth
-- (median). The Attacker then went back and forth between Align and DoKick.
AIM_BY_POSE = 0.6
-- Within CLEAR_ZONE mm of the centre of our net the attacker does not go round the ball to
-- shoot at the far net: the spot behind the ball on that line is then in our goal or beside
-- it, out of reach, and in vision matches the attacker-to-be stood on our goal line while
-- the Chaser poked the ball in. It clears the ball straight away from our net instead: the
-- spot behind the ball is then between it and our net. clearingPoint is the point 5 m out
-- along that way, nil outside the zone.
CLEAR_ZONE = 3000
-- The ball seen from the centre of our net: its distance (mm) and the unit vector towards it
-- (straight up the field for a ball on that centre).
local function ballFromOurNet()
  local b = chaos.getGlobalBall()
  local dx, dy = b.x + field().half_length, b.y
  local d = math.sqrt(dx * dx + dy * dy)
  if d < 1 then return 0, 1, 0 end
  return d, dx / d, dy / d
end
function clearingPoint()
  local d, ux, uy = ballFromOurNet()
  if d > CLEAR_ZONE then return nil end
  local b = chaos.getGlobalBall()
  return b.x + ux * 5000, b.y + uy * 5000
end
-- Where the attacker sends the ball: the clearing point near our net, else the aim point.
function targetPoint()
  local cx, cy = clearingPoint()
  if cx then return cx, cy end
  return aimPoint()
end
function aimBearing()
  local cx, cy = clearingPoint()
  if cx then return bearingTo(cx, cy) end
  local ax, ay = aimPoint()
  local n = lpo(NET1)
  if n.reliability > 0.1 and chaos.gsGetMyPos().quality < AIM_BY_POSE then
    return n.theta + bearingTo(ax, ay) - bearingTo(ax, 0)
  end
  return bearingTo(ax, ay)
end
local function aimOffBall() return aimBearing() - lpo(BALL).theta end
-- The aim seen left / right of the ball, or behind it (for alignment).
function netLeftOfBall() return TOR(0.05, 0.4)(aimOffBall()) end
function netRightOfBall() return TOL(-0.4, -0.05)(aimOffBall()) end
function netBehindBall() return TRI(-0.2, 0, 0.2)(aimOffBall()) end
function aimAligned() return math.abs(aimOffBall()) < 0.2 end

-- Localization.
function wellLocalized() return TOR(0.4, 0.8)(chaos.gsGetMyPos().quality) end

-- Goalkeeper geometry, from the global state.
-- Inside our own net: behind the goal line (x < -half_length), fading over 25 cm.
function inOwnNet()
  local hl = field().half_length
  return TOL(-hl - 100, -hl + 150)(chaos.gsGetMyPos().x)
end
function inGoalArea()
  local p, f = chaos.gsGetMyPos(), field()
  return AND(TOL(-f.half_length + GOAL_AREA_DEPTH, -f.half_length + GOAL_AREA_DEPTH + 500)(p.x),
             TOL(f.goal_half_width + 500, f.goal_half_width + 1000)(math.abs(p.y)))
end
function ballInArea()
  local b, f = chaos.getGlobalBall(), field()
  local line = -f.half_length + f.penalty_area_depth
  return AND(TOR(0.2, 0.5)(b.quality), TOL(line, line + 500)(b.x))
end

-- Signed lateral offset (mm) of the robot from the line joining the ball to the centre of our
-- net, positive when the robot is on the left of that line as seen from the field (+y).
function offsetFromBallToNet()
  local b, p = chaos.getGlobalBall(), chaos.gsGetMyPos()
  local nx = -field().half_length
  if math.abs(b.x - nx) < 1 then return p.y - b.y end
  local yline = b.y + (0 - b.y) * (p.x - b.x) / (nx - b.x)
  return p.y - yline
end

-- Team play: roles (ThinkingCap/TeamChaos report §5.1, figure 8: attacker, supporter, defender). Every field
-- player ranks itself by its distance to the global ball (its own sighting or a teammate's)
-- among the field players it hears from; the goalkeeper stays out of the ranking.
function ballKnown() return chaos.getGlobalBall().quality > 0.2 end

local function distanceToBall(x, y)
  local b = chaos.getGlobalBall()
  return math.sqrt((b.x - x) ^ 2 + (b.y - y) ^ 2)
end

-- 1 for the field player closest to the ball, 2 for the next, ... `margin` (mm) is taken off
-- the robot's own distance: the robot that holds a role keeps it until a teammate is clearly
-- better placed, so two robots do not swap roles at every cycle.
function ballRank(margin)
  local p = chaos.gsGetMyPos()
  local mine = distanceToBall(p.x, p.y) - (margin or 0)
  local rank = 1
  for _, m in ipairs(chaos.getMates()) do
    if not m.keeper and distanceToBall(m.x, m.y) < mine then rank = rank + 1 end
  end
  return rank
end

local function clampToField(x, y)
  local f = field()
  local mx, my = f.half_length - 500, f.half_width - 500
  return math.max(-mx, math.min(mx, x)), math.max(-my, math.min(my, y))
end

-- Where the supporter waits: 2 m behind the ball and 1.5 m towards the middle of the field,
-- ready for a rebound or a loose ball; never closer than SUPPORT_FLOOR mm to our goal line,
-- where it would crowd the keeper (vision matches: all three field players on our goal line
-- while the Chaser poked the ball in).
SUPPORT_FLOOR = 3000
function supportSpot()
  local b = chaos.getGlobalBall()
  local side = b.y > 0 and -1 or 1
  local x = math.max(b.x - 2000, -field().half_length + SUPPORT_FLOOR)
  return clampToField(x, b.y + side * 1500)
end

-- Where the defender stands: on the line from the centre of our net to the ball, 40 % of the
-- way out (between 2.5 m and 4.5 m from the net), cutting the ball's way to the goal.
function defendSpot()
  local d, ux, uy = ballFromOurNet()
  local r = math.min(d, math.max(2500, math.min(4500, 0.4 * d)))
  return clampToField(-field().half_length + ux * r, uy * r)
end

-- The bearing (rad, left positive) from the robot to a field point, and the point in the
-- robot's frame (forward, left) in mm.
function bearingTo(x, y)
  local p = chaos.gsGetMyPos()
  local a = math.atan(y - p.y, x - p.x) - p.theta
  return math.atan(math.sin(a), math.cos(a))
end
function inRobotFrame(x, y)
  local p = chaos.gsGetMyPos()
  local dx, dy = x - p.x, y - p.y
  local c, s = math.cos(p.theta), math.sin(p.theta)
  return dx * c + dy * s, -dx * s + dy * c
end

-- The unit vector from the ball to where the attacker sends it (targetPoint: the opponent's
-- net, or away from ours near it), and how far the robot is along it from the ball (mm;
-- negative: behind the ball, where a push sends the ball that way).
function ballToTarget()
  local b = chaos.getGlobalBall()
  local ax, ay = targetPoint()
  local ux, uy = ax - b.x, ay - b.y
  local n = math.max(1, math.sqrt(ux * ux + uy * uy))
  return ux / n, uy / n
end
function aheadOfBall()
  local b, p = chaos.getGlobalBall(), chaos.gsGetMyPos()
  local ux, uy = ballToTarget()
  return (p.x - b.x) * ux + (p.y - b.y) * uy
end

-- The spot `d` mm behind the ball on the line from the opponent's net; a robot on the wrong
-- side of the ball goes round it, 700 mm to the side it is on, so as not to push the ball
-- towards its own net.
function behindBall(d)
  local b, p = chaos.getGlobalBall(), chaos.gsGetMyPos()
  local ux, uy = ballToTarget()
  local x, y = b.x - ux * d, b.y - uy * d
  if (p.x - b.x) * ux + (p.y - b.y) * uy > -d / 2 then -- aheadOfBall(), its vector at hand
    local side = ((p.x - b.x) * uy - (p.y - b.y) * ux) > 0 and 1 or -1
    x, y = x + side * 700 * uy, y - side * 700 * ux
  end
  return clampToField(x, y)
end

-- The control variables at a Middle Size robot's speeds, the one place they are adapted: the
-- defaults are the seed's, for a four-legged AIBO (go up to 0.3 m/s, turn 90 deg/s, strafe
-- 0.2 m/s). The same labels, scaled, so the rules read the same. The set-points they become
-- (centroids): go FAST 4.8 m/s, SLOW 2.9 m/s; turn HARDLEFT 450 deg/s, LEFT 270 deg/s; strafe
-- LEFT 1.9 m/s. The base drives at most 1.2 m/s and 4 rad/s (229 deg/s), so every label but
-- STAY and NONE asks for its top speed: the team plays at full speed, and blends of STAY with
-- a faster label slow it down near a target.
scale("go", 19.2)
scale("turn", 6)
scale("strafe", 19.2)
