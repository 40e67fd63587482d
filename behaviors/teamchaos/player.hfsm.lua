-- A field player for a whole match (ThinkingCap/TeamChaos report §5.1, figure 8): wait while the game is stopped
-- (walking to the kickoff position in READY), then play one of three roles, renegotiated every cycle from the shared world state:
-- the field player closest to the ball is the Attacker (the seed's Attacker of §5.2, reused
-- from its own file, not copied), the next one the Supporter, the others Defenders. A player
-- that has lost the ball goes to where its teammates see it, or looks around for it. The
-- attacker books the ball (ThinkingCap/TeamChaos report §3.3): two players that both think themselves closest
-- do not both attack it.

include "attacker.hfsm.lua"

local function playing() return chaos.getCurrentState() == "PLAYING" end
local function target(x, y) TARGET_X, TARGET_Y = x, y end
local function ballSeenNow() return chaos.lps_getLpo(BALL).reliability > 0.5 end

-- Keep a role for 400 mm of advantage before handing it over.
local HOLD = 400

-- Roles that do not go for the ball give the ball booking back (ThinkingCap/TeamChaos report §3.3).
local function release() chaos.releaseBookedBall() end
local function booked() return chaos.haveBookedBall().booked end

machine "Player" {
  initial = "Wait",
  states = {
    Wait = function() release() chaos.setBehavior(chaos.getKickoffPose() and "ready" or "stand") end,
    Search = function()
      release()
      if ballKnown() then
        local b = chaos.getGlobalBall()
        target(b.x, b.y)
        chaos.setBehavior("gotopos")
      else
        chaos.setBehavior("lookball")
      end
    end,
    Attack = meta "Attacker",
    -- Far from the ball or on its wrong side: run to the spot behind it, facing it (an
    -- omnidirectional base turns on the way); the Attacker takes over close behind the ball.
    -- The attacker-to-be asks for the ball booking on its way; it attacks once it holds it.
    GetBehind = function() chaos.bookBall() target(behindBall(600)) chaos.setBehavior("gotopos") end,
    Support = function() release() target(supportSpot()) chaos.setBehavior("gotopos") end,
    Defend = function() release() target(defendSpot()) chaos.setBehavior("gotopos") end,
  },
  transitions = {
    { name = "Start", from = "Wait", to = "Search", test = playing },
    -- Checked first (enclosing level): the referee stopped the game.
    { name = "Stop", from = "Search", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "Stop", from = "Attack", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "Stop", from = "Support", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "Stop", from = "Defend", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "BallSeen", from = "Search", to = "GetBehind", test = function() return ballSeenNow() and ballRank(0) == 1 end },
    { name = "Support", from = "Search", to = "Support", priority = 1, test = function() return ballKnown() and ballRank(0) == 2 end },
    { name = "Defend", from = "Search", to = "Defend", priority = 2, test = function() return ballKnown() and ballRank(0) > 2 end },
    { name = "BallLost", from = "Attack", to = "Search", test = "chaos.lps_getLpo(BALL).reliability < 0.2" },
    { name = "WrongSide", from = "Attack", to = "GetBehind", priority = 2, test = function() return aheadOfBall() > -150 or chaos.lps_getLpo(BALL).rho > 2000 end },
    { name = "Behind", from = "GetBehind", to = "Attack", test = function() return aheadOfBall() < -250 and chaos.lps_getLpo(BALL).rho < 1500 and ballSeenNow() and booked() end },
    { name = "Stop", from = "GetBehind", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "GiveWay", from = "GetBehind", to = "Support", priority = 1, test = function() return ballRank(HOLD) > 1 end },
    { name = "BallLost", from = "GetBehind", to = "Search", priority = 2, test = function() return not ballKnown() end },
    { name = "GiveWay", from = "Attack", to = "Support", priority = 1, test = function() return ballRank(HOLD) > 1 end },
    { name = "TakeOver", from = "Support", to = "GetBehind", test = function() return ballSeenNow() and ballRank(-HOLD) == 1 end },
    { name = "TakeOver", from = "Defend", to = "GetBehind", test = function() return ballSeenNow() and ballRank(-HOLD) == 1 end },
    { name = "Swap", from = "Support", to = "Defend", priority = 1, test = function() return ballRank(HOLD) > 2 end },
    { name = "Swap", from = "Defend", to = "Support", priority = 1, test = function() return ballRank(-HOLD) <= 2 end },
    { name = "Closest", from = "Support", to = "Search", priority = 3, test = function() return ballRank(-HOLD) == 1 end },
    { name = "Closest", from = "Defend", to = "Search", priority = 3, test = function() return ballRank(-HOLD) == 1 end },
    { name = "BallLost", from = "Support", to = "Search", priority = 2, test = function() return not ballKnown() end },
    { name = "BallLost", from = "Defend", to = "Search", priority = 2, test = function() return not ballKnown() end },
  },
}
