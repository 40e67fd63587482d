//! What belongs to one robot, apart from any simulator's world: its base, its body's size and
//! kicker reach, its sensors (the mice's mounting, the camera's noise), the field it plays on,
//! its guidance, its control period and its team's size. The simulator builds one from its
//! world configuration (`mrt_sim::config::SimConfig::robot`); a real robot fills its own.

use crate::base::Base;
use mrt_perception::mice::MiceOdometry;
use mrt_plan::guide::Guidance;
use mrt_world::{FieldMap, WorldModel};

/// The camera's measurement noise as the world model assumes it: a relative distance error
/// and a bearing error (rad), one standard deviation each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraNoise {
    /// Distance error, as a fraction of the distance.
    pub distance: f64,
    /// Bearing error, rad.
    pub bearing: f64,
}

/// One robot's configuration (module doc). SI units: metres, seconds, radians.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotConfig {
    /// The control period: every cycle of the robot's Members, s.
    pub control_period: f64,
    /// The wheels and their limits.
    pub base: Base,
    /// Radius of the round footprint, m.
    pub radius: f64,
    /// How far in front of the robot's edge the ball may be for a kick to reach it, m.
    pub kick_reach: f64,
    /// Radius of the ball, m.
    pub ball_radius: f64,
    /// The field played on.
    pub field: FieldMap,
    /// The two optical mice's mounting (manual ch. 4).
    pub mice: MiceOdometry,
    /// The camera's noise.
    pub camera: CameraNoise,
    /// Guidance between the behaviors and the motors (ISocRob seed `003` §3.2.3).
    pub guidance: Guidance,
    /// Robots per team (robot 0 of each keeps goal).
    pub team_size: usize,
}

impl RobotConfig {
    /// The robot's world model as it starts: its field map, its mice, its camera's noise, the
    /// pose unknown until it is put down.
    pub fn world_model(&self) -> WorldModel {
        WorldModel::new(self.field, self.mice, self.camera.distance, self.camera.bearing)
    }

    /// The control period as a `Duration` (a non-finite or negative period is 0).
    pub fn period(&self) -> std::time::Duration {
        std::time::Duration::try_from_secs_f64(self.control_period).unwrap_or_default()
    }
}
