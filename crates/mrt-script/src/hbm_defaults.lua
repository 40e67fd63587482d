-- Default HBM control variables (ThinkingCap/TeamChaos report §4.1): what the rules `rule(truth, VARIABLE, LABEL)`
-- can assert, and which robot command each one drives. A behavior directory's `hbm.lua` may
-- redefine any of them (same name) or add new ones.
--
-- Units are the robot command's: mm/s for go and strafe, degrees/s for turn (left positive),
-- a kick identifier for kick. Mamdani centroid keeps outputs inside the outer labels' cores:
-- FAST alone gives 250 mm/s, not 300.

variable {
  name = "go", command = "vlin", min = -300, max = 300, mode = "centroid",
  labels = {
    BACK = TOL(-300, -150),
    SLOWBACK = TRI(-300, -150, 0),
    STAY = TRI(-150, 0, 150),
    SLOW = TRI(0, 150, 300),
    FAST = TOR(150, 300),
  },
}

variable {
  name = "turn", command = "vrot", min = -90, max = 90, mode = "centroid",
  labels = {
    HARDRIGHT = TOL(-90, -45),
    RIGHT = TRI(-90, -45, 0),
    NONE = TRI(-45, 0, 45),
    LEFT = TRI(0, 45, 90),
    HARDLEFT = TOR(45, 90),
  },
}

variable {
  name = "strafe", command = "vlat", min = -200, max = 200, mode = "centroid",
  labels = {
    RIGHT = TRI(-200, -100, 0),
    NONE = TRI(-100, 0, 100),
    LEFT = TRI(0, 100, 200),
  },
}

-- Kicks are a choice, not a blend: the strongest label wins if it reaches 0.5.
variable {
  name = "kick", command = "kick", min = 0, max = 4, mode = "choice",
  labels = {
    NOKICK = SNG(0),
    FRONTKICK = SNG(1),
    HEADKICK = SNG(2),
    LEFTKICK = SNG(3),
    RIGHTKICK = SNG(4),
  },
}
