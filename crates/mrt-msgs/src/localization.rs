//! What the world model says about its own pose, for monitors, recorders and tests (ThinkingCap
//! ThinkingCap/TeamChaos report §4.1: the monitor shows the pose's uncertainty): the estimate in the field frame
//! with its uncertainty and what the filter used and refused, and its belief about the ball.

use mrt_core::frames::{Field, Framed};
use mrt_core::{Point2, Pose2, Vec2};
use serde::{Deserialize, Serialize};

/// What a pose filter used and refused, counted since it started.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FilterCounts {
    /// Cycles predicted with consistent mice readings.
    pub mice: u64,
    /// Cycles predicted with mice readings repaired by the §4.2 reduction.
    pub reduced: u64,
    /// Cycles predicted with the wheels (the mice could not be trusted).
    pub wheels: u64,
    /// Landmark sightings that corrected the pose.
    pub corrections: u64,
    /// Landmark sightings rejected as outliers.
    pub rejected: u64,
    /// Frames after which the filter admitted it was lost.
    pub lost: u64,
    /// Landmark posts of the vision named (told which post they are) by where the robot
    /// believed it was.
    #[serde(default)]
    pub posts_named: u64,
    /// Global searches run by the relocalizer (MUREA, `mrt_world::relocalize`).
    #[serde(default)]
    pub searches: u64,
    /// Times the relocalizer's fix replaced the filter's pose.
    #[serde(default)]
    pub relocalized: u64,
    /// Field-line points that corrected the pose.
    #[serde(default)]
    pub line_corrections: u64,
    /// Corrections refused because their result was not finite (the pose and its
    /// uncertainty kept as they were).
    #[serde(default)]
    pub refused: u64,
}

/// A robot's own pose estimate after a cycle, in the field frame (m, rad; not the team frame
/// of the behaviors' snapshot), published by its world state every cycle.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Localization {
    /// The estimate: field frame, metres from the centre spot, heading in radians.
    pub pose: Framed<Field, Pose2>,
    /// Standard deviation of the position (root mean square of x and y), m.
    pub sigma_xy: f64,
    /// Standard deviation of the heading, rad.
    pub sigma_theta: f64,
    /// The pose's quality, 0 (unknown) to 1.
    pub quality: f64,
    /// What the filter used and refused so far.
    pub counts: FilterCounts,
    /// Where the robot believes the ball is, when it has seen it.
    #[serde(default)]
    pub ball: Option<BallBelief>,
}

/// A robot's own belief about the ball, in the field frame (m, m/s): what its monitors and the
/// simulator's scoring compare with the truth.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BallBelief {
    /// Where it is.
    #[cfg_attr(feature = "schema", schemars(with = "[f64; 2]"))]
    pub at: Framed<Field, Point2>,
    /// How fast it moves (`None`: not seen in this frame).
    #[cfg_attr(feature = "schema", schemars(with = "Option<[f64; 2]>"))]
    pub velocity: Option<Framed<Field, Vec2>>,
    /// How long ago it was last seen, s (0: in this frame).
    pub seen_ago: f64,
}
