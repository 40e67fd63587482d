//! What the acting side receives (MRT manual §2.1: acting modules; ISocRob seed `003` §3.2.3:
//! guidance between the behaviors and the motors).

use crate::robot::RobotCommand;
use mrt_core::Pose2;
use serde::{Deserialize, Serialize};

/// What guidance asks of the motor and kicker driver: the velocities to drive (mm/s, deg/s,
/// the units of the behaviors' [`RobotCommand`]) and the kick.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MotorCommand(pub RobotCommand);

/// A request to the planner (SPIKE, MRT manual ch. 9): a path from where the robot is to `to`,
/// round the robots its world model anchored. Guidance asks when a behavior's target says
/// `plan` ([`crate::Target::plan`]); SCARE or a behavior may ask too.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlanRequest {
    /// Where to go, team frame: mm, heading in radians.
    pub to: Pose2,
}

/// The planner's answer to a [`PlanRequest`]: the trajectory, or why there is none.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlannedPath {
    /// The request's goal, team frame (mm, rad).
    pub to: Pose2,
    /// Poses from the robot to the goal, team frame (mm, rad), at most 250 mm apart; empty
    /// when no path was found.
    pub poses: Vec<Pose2>,
    /// The path's length, m.
    pub length: f64,
    /// Why there is no path (empty when there is one).
    pub error: String,
}
