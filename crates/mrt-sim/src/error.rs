//! What can go wrong setting up or playing a simulated match: [`SimError`]. Each variant says
//! where the trouble is and keeps the error it came from as its source.

/// An error of the simulator (module doc).
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A configuration value is out of range or disagrees with another: the message names
    /// the key (`body.radius must be at most 0.575 m ...`).
    #[error("{0}")]
    Config(String),
    /// A robot of the match could not be set up or run.
    #[error(transparent)]
    Robot(#[from] mrt_robot::RobotError),
    /// The match's Agoras could not be built or a Member activated.
    #[error(transparent)]
    Bus(#[from] mrt_dcdt::DcdtError),
    /// The recording could not be written.
    #[error(transparent)]
    Record(#[from] mrt_monitor::RecordError),
    /// The device protocol refused a message or a name.
    #[error(transparent)]
    Protocol(#[from] mrt_devices::Refusal),
    /// A device-protocol message could not be encoded.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A base's wheels refused a command or a reading.
    #[error(transparent)]
    Driver(#[from] mrt_robot::error::DriverError),
    /// The planner, guidance or the indoor robot's mission refused its map or parameters.
    #[error(transparent)]
    Plan(#[from] mrt_plan::PlanError),
    /// An embedded or given file did not read.
    #[error(transparent)]
    File(#[from] mrt_core::FileError),
    /// The vision µAgent refused an image.
    #[error(transparent)]
    Vision(#[from] mrt_perception::vision::agent::VisionError),
    /// The mice's calibration failed.
    #[error(transparent)]
    Calibration(#[from] mrt_perception::mice_calibration::CalibrationError),
    /// A configuration could not be written as TOML.
    #[error(transparent)]
    Toml(#[from] toml::ser::Error),
    /// A lock shared with a thread that panicked.
    #[error("the {0} lock is poisoned")]
    Poisoned(&'static str),
    /// The match cannot go on: a robot that is not there, a link that closed, a run that did
    /// not finish, a panic caught.
    #[error("{0}")]
    Match(String),
}
