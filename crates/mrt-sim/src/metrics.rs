//! What the robots believed against the truth, over a match or a series (`mrt sim --metrics
//! FILE.json`): localization, the ball, the other robots, the kidnapped robots' recovery.
//!
//! Every key of the JSON file ([`Metrics`]) is documented in `docs/localization.md`. Errors
//! are pooled over every robot and every published estimate; quantiles come from histograms of
//! 1 mm, 0.01° and 1 mm/s bins, so a series of any length takes the same memory.

use crate::game::MatchReport;
use serde::Serialize;

/// A histogram of non-negative samples with their exact sum: quantiles to one bin.
#[derive(Clone, Debug)]
struct Histogram {
    bin: f64,
    counts: Vec<u64>,
    sum: f64,
    n: u64,
}

impl Histogram {
    /// Bins of `bin` up to `max`; larger samples fall in the last bin.
    fn new(bin: f64, max: f64) -> Histogram {
        Histogram { bin, counts: vec![0; (max / bin).ceil() as usize + 1], sum: 0.0, n: 0 }
    }

    fn add(&mut self, v: f64) {
        if !v.is_finite() {
            return;
        }
        let v = v.max(0.0);
        let last = self.counts.len() - 1;
        let k = ((v / self.bin) as usize).min(last);
        self.counts[k] += 1;
        self.sum += v;
        self.n += 1;
    }

    fn mean(&self) -> Option<f64> {
        (self.n > 0).then(|| self.sum / self.n as f64)
    }

    /// The `q` quantile (nearest rank), at its bin's centre.
    fn quantile(&self, q: f64) -> Option<f64> {
        if self.n == 0 {
            return None;
        }
        let rank = ((self.n - 1) as f64 * q.clamp(0.0, 1.0)).round() as u64;
        let mut seen = 0;
        for (k, &c) in self.counts.iter().enumerate() {
            seen += c;
            if seen > rank {
                return Some((k as f64 + 0.5) * self.bin);
            }
        }
        None
    }
}

/// Gathers [`MatchReport`]s into [`Metrics`].
#[derive(Clone, Debug)]
pub struct MetricsBook {
    matches: u64,
    position: Histogram,
    heading: Histogram,
    ball: Histogram,
    ball_velocity: Histogram,
    kidnaps: u64,
    recoveries: Vec<f64>,
    relocalized: u64,
    falsely_relocalized: u64,
    robots: Histogram,
    robot_classes: [u64; 3],
    phantoms: u64,
    remembered: Histogram,
    remembered_phantoms: u64,
}

impl Default for MetricsBook {
    fn default() -> Self {
        MetricsBook {
            matches: 0,
            position: Histogram::new(0.001, 30.0),
            heading: Histogram::new(0.01f64.to_radians(), std::f64::consts::PI),
            ball: Histogram::new(0.001, 30.0),
            ball_velocity: Histogram::new(0.001, 30.0),
            kidnaps: 0,
            recoveries: Vec::new(),
            relocalized: 0,
            falsely_relocalized: 0,
            robots: Histogram::new(0.001, 30.0),
            robot_classes: [0; 3],
            phantoms: 0,
            remembered: Histogram::new(0.001, 30.0),
            remembered_phantoms: 0,
        }
    }
}

impl MetricsBook {
    /// Adds one match.
    pub fn add(&mut self, r: &MatchReport) {
        self.matches += 1;
        let l = &r.localization;
        l.position.iter().for_each(|&v| self.position.add(v));
        l.heading.iter().for_each(|&v| self.heading.add(v));
        l.ball.iter().for_each(|&v| self.ball.add(v));
        l.ball_velocity.iter().for_each(|&v| self.ball_velocity.add(v));
        self.kidnaps += r.kidnaps.len() as u64;
        self.recoveries.extend(r.kidnaps.iter().filter_map(|k| k.recovered_after));
        self.relocalized += l.relocalized;
        self.falsely_relocalized += l.falsely_relocalized;
        let e = &l.robots;
        e.position.iter().for_each(|&v| self.robots.add(v));
        for (slot, n) in
            self.robot_classes.iter_mut().zip([e.class_right, e.class_wrong, e.class_unknown])
        {
            *slot += n;
        }
        self.phantoms += e.phantoms;
        e.remembered.iter().for_each(|&v| self.remembered.add(v));
        self.remembered_phantoms += e.remembered_phantoms;
    }

    /// The metrics so far.
    pub fn metrics(&self) -> Metrics {
        let mut rec = self.recoveries.clone();
        rec.sort_by(f64::total_cmp);
        let deg = |v: Option<f64>| v.map(f64::to_degrees);
        Metrics {
            matches: self.matches,
            localization: LocalizationMetrics {
                mean_m: self.position.mean(),
                median_m: self.position.quantile(0.5),
                p95_m: self.position.quantile(0.95),
                heading_mean_deg: deg(self.heading.mean()),
                heading_median_deg: deg(self.heading.quantile(0.5)),
                heading_p95_deg: deg(self.heading.quantile(0.95)),
                samples: self.position.n,
                relocalized: self.relocalized,
                falsely_relocalized: self.falsely_relocalized,
            },
            ball: BallMetrics {
                mean_m: self.ball.mean(),
                median_m: self.ball.quantile(0.5),
                p95_m: self.ball.quantile(0.95),
                samples: self.ball.n,
                velocity_mean_mps: self.ball_velocity.mean(),
                velocity_p95_mps: self.ball_velocity.quantile(0.95),
                velocity_samples: self.ball_velocity.n,
            },
            robots: RobotMetrics {
                mean_m: self.robots.mean(),
                median_m: self.robots.quantile(0.5),
                p95_m: self.robots.quantile(0.95),
                samples: self.robots.n,
                class_right: self.robot_classes[0],
                class_wrong: self.robot_classes[1],
                class_unknown: self.robot_classes[2],
                phantoms: self.phantoms,
                remembered_median_m: self.remembered.quantile(0.5),
                remembered_p95_m: self.remembered.quantile(0.95),
                remembered_samples: self.remembered.n,
                remembered_phantoms: self.remembered_phantoms,
            },
            kidnap: KidnapMetrics {
                count: self.kidnaps,
                recovered: rec.len() as u64,
                median_recovery_s: (!rec.is_empty()).then(|| rec[(rec.len() - 1) / 2]),
                max_recovery_s: rec.last().copied(),
            },
        }
    }
}

/// `mrt sim --metrics`: the robots' beliefs against the truth (`null` where there was no
/// sample).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Metrics {
    /// Matches pooled.
    pub matches: u64,
    /// The robots' own poses.
    pub localization: LocalizationMetrics,
    /// The ball, while seen.
    pub ball: BallMetrics,
    /// The other robots the robots anchored (MAP), while seen.
    pub robots: RobotMetrics,
    /// The kidnapped robots.
    pub kidnap: KidnapMetrics,
}

/// Position and heading errors of every robot's own estimate, every cycle.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LocalizationMetrics {
    /// Mean position error, m.
    pub mean_m: Option<f64>,
    /// Median position error, m.
    pub median_m: Option<f64>,
    /// 95th percentile of the position error, m.
    pub p95_m: Option<f64>,
    /// Mean heading error, degrees.
    pub heading_mean_deg: Option<f64>,
    /// Median heading error, degrees.
    pub heading_median_deg: Option<f64>,
    /// 95th percentile of the heading error, degrees.
    pub heading_p95_deg: Option<f64>,
    /// Estimates compared.
    pub samples: u64,
    /// Global relocalizations: a robot's relocalizer moved its estimate (MUREA).
    pub relocalized: u64,
    /// Those that left the estimate more than 1 m from the truth
    /// ([`crate::game::FALSELY_RELOCALIZED`]).
    pub falsely_relocalized: u64,
}

/// The ball's position error in every estimate made while the robot saw it, and its velocity
/// error where the robot estimated one.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BallMetrics {
    /// Mean position error, m.
    pub mean_m: Option<f64>,
    /// Median position error, m.
    pub median_m: Option<f64>,
    /// 95th percentile of the position error, m.
    pub p95_m: Option<f64>,
    /// Estimates compared.
    pub samples: u64,
    /// Mean velocity error (length of the difference), m/s.
    pub velocity_mean_mps: Option<f64>,
    /// 95th percentile of the velocity error, m/s.
    pub velocity_p95_mps: Option<f64>,
    /// Velocity estimates compared.
    pub velocity_samples: u64,
}

/// The other robots as each robot's world model anchored them (MAP, `mrt_world::anchor`), in
/// every snapshot, for the anchors seen in that frame: the distance to the nearest real robot,
/// and whether the anchor's class is that robot's team.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotMetrics {
    /// Mean distance to the nearest real robot, m.
    pub mean_m: Option<f64>,
    /// Median distance, m.
    pub median_m: Option<f64>,
    /// 95th percentile, m.
    pub p95_m: Option<f64>,
    /// Anchors compared.
    pub samples: u64,
    /// Anchors whose class (teammate or opponent) was right.
    pub class_right: u64,
    /// Anchors of the wrong team.
    pub class_wrong: u64,
    /// Anchors of unknown team (marker not seen, no teammate reporting there).
    pub class_unknown: u64,
    /// Anchors more than 1 m from every robot ([`crate::game::PHANTOM`]).
    pub phantoms: u64,
    /// For the anchors not seen in their frame but still reliable enough for the behaviors
    /// (0.3): median distance to the nearest robot, m.
    pub remembered_median_m: Option<f64>,
    /// Their 95th percentile, m.
    pub remembered_p95_m: Option<f64>,
    /// Such anchors compared.
    pub remembered_samples: u64,
    /// Those more than 1 m from every robot.
    pub remembered_phantoms: u64,
}

/// Robots carried elsewhere without being told (`mrt sim --kidnap N`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KidnapMetrics {
    /// Kidnaps.
    pub count: u64,
    /// Kidnaps after which the robot's estimate came back within 0.3 m of the truth
    /// ([`crate::game::RECOVERED`]) before the next one or the end of the match.
    pub recovered: u64,
    /// Median time to recover, s of simulated time.
    pub median_recovery_s: Option<f64>,
    /// Longest time to recover, s.
    pub max_recovery_s: Option<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::game::{Kidnap, LocalizationErrors};
    use mrt_core::Pose2;

    fn report(position: Vec<f64>, kidnaps: Vec<Kidnap>) -> MatchReport {
        let mut localization = LocalizationErrors::default();
        localization.heading = vec![0.0; position.len()];
        localization.position = position;
        localization.ball = vec![0.1, 0.3];
        (localization.relocalized, localization.falsely_relocalized) = (3, 1);
        localization.robots = crate::game::RobotErrors {
            position: vec![0.1, 0.2, 1.5],
            class_right: 1,
            class_wrong: 0,
            class_unknown: 1,
            phantoms: 1,
            remembered: vec![0.5],
            remembered_phantoms: 0,
        };
        MatchReport {
            seed: 1,
            score: (0, 0),
            stats: Default::default(),
            trajectory_hash: 0,
            duration: 1.0,
            calls: Vec::new(),
            shots: Vec::new(),
            frames: Vec::new(),
            beliefs: Vec::new(),
            faults: Vec::new(),
            localization,
            kidnaps,
        }
    }

    #[test]
    fn errors_are_pooled_over_matches_with_quantiles_to_a_millimetre() {
        let mut book = MetricsBook::default();
        // 0.000, 0.010, ..., 0.990 m, then the same again: 200 samples.
        let errors: Vec<f64> = (0..100).map(|k| f64::from(k) * 0.01).collect();
        let kidnap =
            |after| Kidnap { robot: 0, at: 5.0, to: Pose2::default(), recovered_after: after };
        book.add(&report(errors.clone(), vec![kidnap(Some(0.4)), kidnap(None)]));
        book.add(&report(errors, vec![kidnap(Some(1.2)), kidnap(Some(0.6))]));
        let m = book.metrics();
        assert_eq!(m.matches, 2);
        assert_eq!(m.localization.samples, 200);
        let near = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 0.001);
        assert!(near(m.localization.mean_m, 0.495), "{m:?}");
        // Rank round(199 × 0.5) = 100 of the sorted 200: 0.50 m, in the bin [0.500, 0.501).
        assert!(near(m.localization.median_m, 0.5005), "{m:?}");
        assert!(near(m.localization.p95_m, 0.9405), "rank 189: 0.94 m: {m:?}");
        assert!(near(m.ball.mean_m, 0.2), "{m:?}");
        assert_eq!((m.ball.samples, m.ball.velocity_samples), (4, 0));
        assert_eq!(m.ball.velocity_mean_mps, None);
        assert_eq!((m.kidnap.count, m.kidnap.recovered), (4, 3));
        assert_eq!((m.kidnap.median_recovery_s, m.kidnap.max_recovery_s), (Some(0.6), Some(1.2)));
        let json = serde_json::to_value(&m).unwrap_or_default();
        assert_eq!(json["kidnap"]["recovered"], 3);
        assert_eq!((m.localization.relocalized, m.localization.falsely_relocalized), (6, 2));
        assert!(json["ball"]["velocity_mean_mps"].is_null());
        // The anchored robots of both matches: 0.1, 0.2, 1.5 m twice.
        assert_eq!(m.robots.samples, 6);
        assert!(near(m.robots.mean_m, 0.6), "{m:?}");
        assert_eq!((m.robots.class_right, m.robots.class_unknown, m.robots.phantoms), (2, 2, 2));
        assert_eq!(json["robots"]["class_wrong"], 0);
    }

    #[test]
    fn an_empty_book_has_no_numbers_and_bad_samples_are_left_out() {
        let mut book = MetricsBook::default();
        assert_eq!(book.metrics().localization.median_m, None);
        book.add(&report(vec![f64::NAN, f64::INFINITY, 1e9, 0.2], Vec::new()));
        let m = book.metrics();
        assert_eq!(m.localization.samples, 2, "NaN and ∞ are not errors");
        assert!(m.localization.p95_m.is_some_and(|p| p >= 30.0), "huge errors in the last bin");
    }
}
