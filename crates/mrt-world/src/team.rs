//! The team side of the world state (ISocRob seed `003` §3.1: each robot shares what it knows
//! with its teammates; TeamChaos seed `001` §2.1: the global ball): teammates' poses from their
//! [`MateReport`]s and the best ball sighting, one's own or a teammate's.

use mrt_msgs::{Estimate, Mate, MateReport, WorldSnapshot};

/// A teammate's ball counts this much of its own quality: a second-hand sighting, one cycle
/// old, is trusted a little less than one's own.
pub const SHARED_BALL: f64 = 0.9;

/// The team side of the world state: `w.mates` from the teammates' reports (in their order),
/// and the global ball replaced by a teammate's sighting when that is better than one's own
/// (quality × [`SHARED_BALL`]). The LPS stays what the robot itself perceived.
pub fn merge_team<'a>(w: &mut WorldSnapshot, reports: impl IntoIterator<Item = &'a MateReport>) {
    w.mates.clear();
    for r in reports {
        w.mates.push(Mate { id: r.id, at: r.pose, keeper: r.keeper });
        let shared = r.ball.quality * SHARED_BALL;
        if shared > w.global_ball.quality {
            w.global_ball = Estimate { pose: r.ball.pose, quality: shared };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::Pose2;

    #[test]
    fn teammates_and_their_better_ball_sightings_merge_into_the_world_state() {
        let mut w = WorldSnapshot {
            global_ball: Estimate { pose: Pose2::new(100.0, 0.0, 0.0), quality: 0.5 },
            ..Default::default()
        };
        let report = |id, q, x| MateReport {
            id,
            keeper: id == 0,
            pose: Estimate { pose: Pose2::new(-1000.0 * f64::from(id), 0.0, 0.0), quality: 0.9 },
            ball: Estimate { pose: Pose2::new(x, 50.0, 0.0), quality: q },
        };
        // 0.9 × 0.5 = 0.45 < 0.5: one's own sighting stays; 0.9 × 0.8 = 0.72 wins.
        let reports = [report(0, 0.5, 200.0), report(2, 0.8, 300.0), report(3, 0.7, 400.0)];
        merge_team(&mut w, &reports);
        assert_eq!(
            w.mates.iter().map(|m| (m.id, m.keeper)).collect::<Vec<_>>(),
            [(0, true), (2, false), (3, false)]
        );
        assert_eq!(w.mates[1].at.pose.x, -2000.0);
        assert!((w.global_ball.quality - 0.72).abs() < 1e-12, "{:?}", w.global_ball);
        assert_eq!((w.global_ball.pose.x, w.global_ball.pose.y), (300.0, 50.0));
        // A robot that sees the ball well keeps its own estimate.
        let mut sharp = WorldSnapshot {
            global_ball: Estimate { quality: 1.0, ..Default::default() },
            ..Default::default()
        };
        merge_team(&mut sharp, &reports);
        assert_eq!(sharp.global_ball.quality, 1.0);
        // The report carries the robot's own sighting, not the merged one.
        let r = MateReport::of(7, false, &w);
        assert_eq!((r.id, r.ball.quality), (7, w.global_ball.quality));
    }
}
