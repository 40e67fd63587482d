//! Which robot a program drives and which behavior stack drives it: [`RobotSpec`] and
//! [`Stack`]. The robot file names both (`[robot]`: `id`, `team_size`, `stack`); a match gives
//! each of its robots one.

use crate::error::RobotError;

/// A behavior stack.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stack {
    /// TeamChaos: Lua HFSM and fuzzy HBM behaviors.
    Chaos,
    /// Team Milan: Mr. BRIAN fuzzy behaviors (`configs/brian/milan`).
    Milan,
    /// The hand-written baseline.
    Chaser,
    /// Team ISocRob: the Machine µAgent's role state machines on a shared blackboard
    /// ([`crate::isocrob`]).
    Isocrob,
}

impl Stack {
    /// Parses `chaos`, `milan`, `chaser` or `isocrob`.
    pub fn parse(s: &str) -> Result<Stack, RobotError> {
        match s {
            "chaos" => Ok(Stack::Chaos),
            "milan" => Ok(Stack::Milan),
            "chaser" => Ok(Stack::Chaser),
            "isocrob" => Ok(Stack::Isocrob),
            other => Err(RobotError::UnknownStack(other.to_string())),
        }
    }

    /// The name.
    pub fn name(self) -> &'static str {
        match self {
            Stack::Chaos => "chaos",
            Stack::Milan => "milan",
            Stack::Chaser => "chaser",
            Stack::Isocrob => "isocrob",
        }
    }
}

/// One robot of a match: which robot it is (0 .. 2 × team size: home, then away), whether it
/// keeps goal and which behavior stack drives it. Its Agora's id is `robot + 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RobotSpec {
    /// The robot.
    pub robot: usize,
    /// Keeps goal (robot 0 of each team).
    pub keeper: bool,
    /// Its number within its team (0: the goalkeeper).
    pub mate: usize,
    /// What drives it.
    pub stack: Stack,
}

impl RobotSpec {
    /// Robot `robot` of a match with `team_size` robots a side, the home team playing `home`
    /// and the away team `away`.
    pub fn of(robot: usize, team_size: usize, (home, away): (Stack, Stack)) -> RobotSpec {
        let n = team_size.max(1);
        RobotSpec {
            robot,
            keeper: robot % n == 0,
            mate: robot % n,
            stack: if robot < n { home } else { away },
        }
    }

    /// The id of the robot's Agora.
    pub fn agora_id(&self) -> Result<u32, RobotError> {
        u32::try_from(self.robot + 1).map_err(|_| RobotError::RobotNumber(self.robot))
    }
}
