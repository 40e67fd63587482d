//! The device frames of the distributed simulator: a robot whose simulator runs in another
//! process gets its devices' readings in a [`DeviceFrame`] per cycle and answers with what its
//! drivers did ([`DeviceAct`]); at the [`FinalWhistle`] it sends its Members' faults
//! ([`RobotEnd`]). A real robot never sees these: its devices are its own.

use crate::sensing::{CameraFrame, GameInfo, Odometry, Sonar};
use serde::{Deserialize, Serialize};

/// What robot `robot`'s devices read at the start of control cycle `cycle`.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DeviceFrame {
    /// The robot (0 .. 2 × team size).
    pub robot: u32,
    /// The control cycle (0 at kickoff of the first half).
    pub cycle: u64,
    /// The mice and wheels since the last cycle.
    pub odometry: Odometry,
    /// The object sensor's frame.
    pub camera: CameraFrame,
    /// The game controller's news.
    pub game: GameInfo,
    /// The sonar ring.
    pub sonars: Vec<Sonar>,
    /// Robots the simulator is not waiting for (silent, or known gone): teammates do not wait
    /// for their reports either, until they speak again.
    pub not_awaited: Vec<u32>,
}

/// What robot `robot`'s drivers did in control cycle `cycle`.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DeviceAct {
    /// The robot.
    pub robot: u32,
    /// The control cycle answered.
    pub cycle: u64,
    /// The duty cycles the motor driver set last, if any.
    pub duty: Option<Vec<f64>>,
    /// Whether the kicker fired.
    pub kick: bool,
    /// The camera's pan joint set-point, rad, if the gaze control turned it.
    #[serde(default)]
    pub pan: Option<f64>,
    /// Faults of the robot's software noted this cycle.
    pub faults: Vec<String>,
}

/// The match is over: robots close their Members and answer with a [`RobotEnd`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FinalWhistle {
    /// Control cycles played.
    pub cycles: u64,
}

/// A robot's last word: its Members that failed to start, failed jobs or panicked.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotEnd {
    /// The robot.
    pub robot: u32,
    /// Its Members' faults.
    pub faults: Vec<MemberFault>,
}

/// A Member of a robot's Agora that failed to start, failed jobs or panicked (each time it was
/// restarted), or whose mailbox lost messages, from its executor's report.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemberFault {
    /// The Member's name.
    pub name: String,
    /// Errors, panics and restarts (at least 1).
    pub count: u64,
    /// Whether it never completed a cycle (it failed from the start).
    pub never_ran: bool,
    /// Its last error.
    pub error: String,
}
