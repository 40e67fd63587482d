//! What the acting side receives (MRT manual §2.1: acting modules; ISocRob-2000 report
//! §3.2.3: guidance between the behaviors and the motors), and the planner's requests and
//! answers. SI throughout: metres, radians, seconds.

use mrt_core::frames::{Framed, Team};
use mrt_core::{Pose2, Twist};
use serde::{Deserialize, Serialize};

/// What guidance asks of the motor and kicker driver: the velocity to drive and whether to
/// kick.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MotorCommand {
    /// The body velocity, robot frame: m/s forward and to the left, rad/s counter-clockwise.
    pub twist: Twist,
    /// Fire the kicker this cycle.
    pub kick: bool,
}

/// A request to the planner (SPIKE, MRT manual ch. 9): a path from where the robot is to `to`,
/// round the robots its world model anchored. Guidance asks when a behavior's target says
/// `plan` ([`crate::Target::plan`]); SCARE or a behavior may ask too.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlanRequest {
    /// Where to go, team frame: metres, heading in radians.
    pub to: Framed<Team, Pose2>,
}

/// The planner's answer to a [`PlanRequest`]: the trajectory, or why there is none.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlannedPath {
    /// The request's goal, team frame (m, rad).
    pub to: Framed<Team, Pose2>,
    /// Poses from the robot to the goal, team frame (m, rad), at most 0.25 m apart; empty when
    /// no path was found.
    pub poses: Vec<Framed<Team, Pose2>>,
    /// The path's length, m.
    pub length: f64,
    /// Why there is no path (empty when there is one).
    pub error: String,
}
