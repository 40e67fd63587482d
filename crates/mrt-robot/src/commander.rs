//! The Commander (ThinkingCap report §2.1: the Commander Module between the behaviors and
//! the body): how a team's behaviors are adapted to the robot they run on.
//!
//! TeamChaos tuned its behaviors for AIBO walking speeds (about 0.3 m/s) and the AIBO's head;
//! on a Middle Size League base its `hbm.lua` scales the control variables (the one place the
//! speeds are adapted), and the Commander measures distances from a point ahead of the robot's
//! centre, as the seed's Commander Module turned set-points into a walking style for its own
//! body.

use crate::config::RobotConfig;
use mrt_core::frames::metres;
use mrt_msgs::WorldSnapshot;

/// How a team's behaviors are adapted to the robot's body: ThinkingCap's Commander Module
/// (report §2.1), which turned the behaviors' set-points into a walking style for the AIBO's
/// legs. Here the world state's LPS distances are shifted ([`Commander::perceive`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Commander {
    /// Subtracted from every LPS distance (m).
    pub edge: f64,
}

impl Commander {
    /// No adaptation.
    pub const PLAIN: Commander = Commander { edge: 0.0 };

    /// TeamChaos' behaviors on the configured robot: distances from a point ahead of the
    /// robot's centre chosen so that the
    /// behaviors' "touching" (`TOUCHING` in `hbm.lua` reaches 0.5 at 250 mm, where `dokick`
    /// fires) falls 30 mm inside the kicker's reach: a kick never fires at a ball it cannot
    /// reach and wastes the valve's recharge.
    pub fn chaos(cfg: &RobotConfig) -> Commander {
        // 250 mm + 30 mm, where the behaviors' millimetres say it.
        let touching = metres(280.0);
        Commander { edge: (cfg.radius + cfg.ball_radius + cfg.kick_reach - touching).max(0.0) }
    }

    /// The camera driver's side: distances from the robot's edge.
    pub fn perceive(&self, w: &mut WorldSnapshot) {
        for o in &mut w.lps {
            o.rho = (o.rho - self.edge).max(0.0);
        }
    }
}
