//! What can go wrong setting up or running the robot program: [`RobotError`]. Each variant
//! says where the trouble is (the robot file, the bus, a stack's behaviors, the wheels, the
//! world's link) and keeps the error it came from as its source; and what a motor driver
//! refuses: [`DriverError`].

use std::path::PathBuf;

/// An error of the robot program (module doc).
#[derive(Debug, thiserror::Error)]
pub enum RobotError {
    /// A robot file's value is out of range or disagrees with another: the message names the
    /// key (`body.radius must be a finite number > 0, not -1`).
    #[error("{0}")]
    Config(String),
    /// A stack name that is not one of the stacks.
    #[error("unknown team stack '{0}' (chaos, milan, isocrob, chaser)")]
    UnknownStack(String),
    /// A base name that is not one of the bases.
    #[error("base must be differential or omni, not {0}")]
    UnknownBase(String),
    /// A stack asked for in a way it cannot run (a Chaos robot without its files, an ISocRob
    /// robot without its blackboard).
    #[error("{0}")]
    StackWiring(&'static str),
    /// The robot's Agora could not be built or one of its Members activated.
    #[error(transparent)]
    Bus(#[from] mrt_dcdt::DcdtError),
    /// ISocRob's blackboard refused a value.
    #[error(transparent)]
    Blackboard(#[from] mrt_blackboard::BbError),
    /// A team's blackboard `config.dat` could not be read.
    #[error(transparent)]
    BlackboardConfig(#[from] mrt_blackboard::config::ConfigError),
    /// A blackboard symbol pattern did not parse.
    #[error(transparent)]
    Symbol(#[from] mrt_blackboard::SymbolError),
    /// Team Milan's Mr. BRIAN files could not be loaded.
    #[error(transparent)]
    Brian(#[from] mrt_fuzzy::BrianError),
    /// The planner's map or parameters were refused.
    #[error(transparent)]
    Plan(#[from] mrt_plan::PlanError),
    /// The wheels' driver refused a command or a reading.
    #[error(transparent)]
    Driver(#[from] DriverError),
    /// A message to or from the world could not be encoded.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A robot file could not be written as TOML.
    #[error(transparent)]
    Toml(#[from] toml::ser::Error),
    /// A file or directory of compiled-in behaviors could not be written or removed.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A lock shared with a thread that panicked (the devices, a re-run's record).
    #[error("the {0} lock is poisoned")]
    Poisoned(&'static str),
    /// The world's link (the device protocol's transport) failed.
    #[error("the world's link: {0}")]
    World(String),
    /// The world sent no step for longer than the robot waits.
    #[error("no step from world {world} for {silence:?}")]
    WorldSilent {
        /// The world's name.
        world: String,
        /// How long the robot waited.
        silence: std::time::Duration,
    },
    /// The world's liveliness token went away before it ended the match.
    #[error("world {0} went away without ending the match")]
    WorldGone(String),
    /// The channel from the world's link closed.
    #[error("the link to the world closed")]
    LinkClosed,
    /// A robot number too large for an Agora id.
    #[error("robot {0} has no Agora id (at most u32::MAX - 1)")]
    RobotNumber(usize),
}

/// What a motor driver refuses.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum DriverError {
    /// Not one duty cycle per wheel.
    #[error("{got} duty cycles for {wheels} wheels")]
    WheelCount {
        /// Wheels of the base.
        wheels: usize,
        /// Duty cycles given.
        got: usize,
    },
}
