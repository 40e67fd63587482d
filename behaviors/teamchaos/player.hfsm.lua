-- A field player for a whole match: wait while the game is stopped, look for the ball when it
-- is lost, and play the Attacker (seed 001 §5.2) while it is seen. The Attacker machine is
-- reused from its own file, not copied (seed §5.1: meta-states are referenced, not duplicated).

include "attacker.hfsm.lua"

local function playing() return chaos.getCurrentState() == "PLAYING" end

machine "Player" {
  initial = "Wait",
  states = {
    Wait = function() chaos.setBehavior("stand") end,
    Search = function() chaos.setBehavior("lookball") end,
    Play = meta "Attacker",
  },
  transitions = {
    { name = "Start", from = "Wait", to = "Search", test = playing },
    -- Checked first (enclosing level): the referee stopped the game.
    { name = "Stop", from = "Search", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "Stop", from = "Play", to = "Wait", priority = -1, test = function() return not playing() end },
    { name = "BallSeen", from = "Search", to = "Play", test = "chaos.lps_getLpo(BALL).reliability > 0.5" },
    { name = "BallLost", from = "Play", to = "Search", test = "chaos.lps_getLpo(BALL).reliability < 0.2" },
  },
}
