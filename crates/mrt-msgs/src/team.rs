//! What teammates tell each other (ISocRob seed `003` §3.1, TeamChaos seed `001` §2.3): each
//! robot's own pose and ball, every cycle.

use crate::robot::{Estimate, WorldSnapshot};
use serde::{Deserialize, Serialize};

/// What a robot tells its teammates every cycle (team frame, mm): its own pose and its own
/// sighting of the ball (never what it heard from others, so stale news does not circulate).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MateReport {
    /// The robot's player number.
    pub id: u32,
    /// Whether it keeps goal.
    pub keeper: bool,
    /// Where it believes it is.
    pub pose: Estimate,
    /// Where it believes the ball is (quality 0 when it has no idea).
    pub ball: Estimate,
    /// One standard deviation of `ball`'s position, mm (0: not known; the team then reads it
    /// from the quality).
    #[serde(default)]
    pub ball_sigma: f64,
}

impl MateReport {
    /// The report of robot `id` on its world snapshot (before the team's reports are merged
    /// into it), with no ball uncertainty ([`MateReport::with_ball_sigma`] adds it).
    pub fn of(id: u32, keeper: bool, w: &WorldSnapshot) -> MateReport {
        MateReport { id, keeper, pose: w.my_pos, ball: w.global_ball, ball_sigma: 0.0 }
    }

    /// The same report with the ball's standard deviation, mm.
    pub fn with_ball_sigma(self, ball_sigma: f64) -> MateReport {
        MateReport { ball_sigma, ..self }
    }
}
