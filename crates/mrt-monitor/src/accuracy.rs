//! How far each robot's beliefs were from the truth in a recording that holds both
//! (`mrt sim --record`, `mrt world mujoco --record`): [`accuracy`] pairs every `Localization`
//! a robot published with the truth of the same instant (the last `/truth` at or before it)
//! and measures its pose, and its ball while it saw it, as `mrt sim`'s own report does. One
//! method for every world, so that their figures stand side by side (`mrt replay FILE
//! --accuracy`).

use crate::replay::{Recording, ReplayError};
use crate::view::{truth_index, Truth};
use mrt_core::{normalize_angle, Time};
use mrt_msgs::Localization;
use std::collections::BTreeMap;

/// Mean, median and 95th percentile of some errors.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Spread {
    /// How many errors.
    pub count: usize,
    /// Their mean.
    pub mean: f64,
    /// Their median.
    pub median: f64,
    /// Their 95th percentile (nearest rank).
    pub p95: f64,
}

impl Spread {
    /// The spread of `errors` (`None` when there are none).
    pub fn of(mut errors: Vec<f64>) -> Option<Spread> {
        errors.retain(|e| e.is_finite());
        if errors.is_empty() {
            return None;
        }
        errors.sort_by(f64::total_cmp);
        let n = errors.len();
        let rank = |q: f64| errors[((n - 1) as f64 * q).round() as usize];
        let mean = errors.iter().sum::<f64>() / n as f64;
        Some(Spread { count: n, mean, median: rank(0.5), p95: rank(0.95) })
    }
}

/// How far one robot's beliefs were from the truth (m, rad, m/s).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Accuracy {
    /// The robot's topic prefix, e.g. `home/1`.
    pub robot: String,
    /// Its position against the truth's, every `Localization`.
    pub position: Option<Spread>,
    /// Its heading against the truth's (absolute, rad).
    pub heading: Option<Spread>,
    /// Its ball against the truth's, in the cycles it saw the ball (`seen_ago` 0).
    pub ball: Option<Spread>,
    /// Its ball's velocity against the truth's, in those cycles when it had one.
    pub ball_velocity: Option<Spread>,
    /// Seconds from its first `Localization` to the first one within [`FOUND_WITHIN`] of the
    /// truth: how long a robot put down where it was not told took to find itself (0 for one
    /// that knew); `None` when it never did. For `all`, the slowest robot's.
    pub found_after: Option<f64>,
}

/// How close to the truth (m) a robot's estimate must come for it to have found itself: the
/// same bound as a kidnapped robot's recovery in `mrt sim --metrics`.
pub const FOUND_WITHIN: f64 = 0.3;

/// Every robot's [`Accuracy`] in `recording`, in topic order, then all robots together
/// (named `all`). Robots the truth does not hold (`home/k`, `away/k` beyond its robots) are
/// left out; a recording without `/truth` gives none.
pub fn accuracy(recording: &Recording) -> Result<Vec<Accuracy>, ReplayError> {
    let mut truths: BTreeMap<Time, Truth> = BTreeMap::new();
    let mut beliefs: BTreeMap<String, Vec<(Time, Localization)>> = BTreeMap::new();
    recording.scan(|e| {
        if e.topic == "/truth" {
            if let Ok(t) = serde_json::from_slice(e.json) {
                truths.insert(e.time, t);
            }
        } else if let Some(robot) =
            e.topic.strip_prefix('/').and_then(|t| t.strip_suffix("/Localization"))
        {
            if let Ok(l) = serde_json::from_slice(e.json) {
                beliefs.entry(robot.to_string()).or_default().push((e.time, l));
            }
        }
    })?;
    let mut all = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    let mut slowest = Some(0.0_f64);
    let mut out = Vec::new();
    for (robot, list) in beliefs {
        let mut errors = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
        let (mut first, mut found) = (None, None);
        for (t, l) in list {
            let Some((_, truth)) = truths.range(..=t).next_back() else { continue };
            let Some(i) = truth_index(&robot, Some(truth)) else { continue };
            let (p, real) = (l.pose.inner, truth.robots[i]);
            let off = (p.x - real.x).hypot(p.y - real.y);
            let first = *first.get_or_insert(t);
            if found.is_none() && off < FOUND_WITHIN {
                found = Some((t - first).as_secs_f64());
            }
            errors[0].push(off);
            errors[1].push(normalize_angle(p.theta - real.theta).abs());
            if let Some(ball) = l.ball.filter(|b| b.seen_ago <= 0.0) {
                let at = ball.at.inner;
                errors[2].push((at.x - truth.ball.0).hypot(at.y - truth.ball.1));
                if let Some(v) = ball.velocity {
                    let (tx, ty) = truth.ball_velocity;
                    errors[3].push((v.inner.x - tx).hypot(v.inner.y - ty));
                }
            }
        }
        if errors[0].is_empty() {
            continue;
        }
        for (a, e) in all.iter_mut().zip(&errors) {
            a.extend_from_slice(e);
        }
        slowest = slowest.zip(found).map(|(a, b)| a.max(b));
        out.push(Accuracy { found_after: found, ..spreads(robot, errors) });
    }
    if !out.is_empty() {
        out.push(Accuracy { found_after: slowest, ..spreads("all".into(), all) });
    }
    Ok(out)
}

fn spreads(robot: String, [position, heading, ball, velocity]: [Vec<f64>; 4]) -> Accuracy {
    Accuracy {
        robot,
        position: Spread::of(position),
        heading: Spread::of(heading),
        ball: Spread::of(ball),
        ball_velocity: Spread::of(velocity),
        found_after: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use mrt_core::frames::Framed;
    use mrt_core::{Point2, Pose2, Vec2};
    use mrt_msgs::{BallBelief, GameState};

    #[test]
    fn beliefs_are_measured_against_the_truth_of_their_instant() {
        let path = std::env::temp_dir().join(format!("mrt-accuracy-{}.mcap", std::process::id()));
        let mut rec = Recorder::create(&path).unwrap();
        for k in 0..10u64 {
            let t = Time::from_secs_f64(k as f64 * 0.1);
            let x = k as f64 * 0.1;
            let truth = Truth {
                ball: (2.0, 1.0),
                ball_velocity: (1.0, 0.0),
                robots: vec![Pose2::new(x, 0.0, 0.0), Pose2::new(-x, 0.0, 3.0)],
                home: 1,
                score: (0, 0),
                state: GameState::Playing,
            };
            rec.record("/truth", t, &truth).unwrap();
            // home/0 believes itself 0.3 m ahead and 0.1 rad off, the ball 0.5 m off while it
            // sees it (even cycles), at rest.
            let seen = k % 2 == 0;
            let home = Localization {
                pose: Framed::new(Pose2::new(x + 0.3, 0.0, 0.1)),
                ball: Some(BallBelief {
                    at: Framed::new(Point2::new(2.0, 1.5)),
                    velocity: Some(Framed::new(Vec2::zeros())),
                    seen_ago: if seen { 0.0 } else { 0.1 },
                }),
                ..Default::default()
            };
            rec.record("/home/0/Localization", t, &home).unwrap();
            // away/0 is the truth's robot 1, believed exactly (heading across ±π).
            let away = Localization {
                pose: Framed::new(Pose2::new(-x, 0.0, 3.0 - std::f64::consts::TAU)),
                ..Default::default()
            };
            rec.record("/away/0/Localization", t, &away).unwrap();
            // away/5 is not in the truth.
            rec.record("/away/5/Localization", t, &away).unwrap();
        }
        rec.finish().unwrap();
        let a = accuracy(&Recording::open(&path).unwrap()).unwrap();
        std::fs::remove_file(&path).ok();
        let names: Vec<&str> = a.iter().map(|a| a.robot.as_str()).collect();
        assert_eq!(names, ["away/0", "home/0", "all"]);
        let near = |s: Option<Spread>, v: f64, n: usize| {
            let s = s.unwrap();
            assert!(s.count == n && (s.mean - v).abs() < 1e-9 && (s.p95 - v).abs() < 1e-9, "{s:?}");
        };
        near(a[0].position, 0.0, 10);
        near(a[0].heading, 0.0, 10);
        assert_eq!(a[0].ball, None);
        near(a[1].position, 0.3, 10);
        near(a[1].heading, 0.1, 10);
        near(a[1].ball, 0.5, 5);
        near(a[1].ball_velocity, 1.0, 5);
        assert_eq!(a[2].position.unwrap().count, 20);
        assert_eq!(a[2].ball.unwrap().count, 5);
        assert_eq!(a[0].found_after, Some(0.0));
    }

    /// A robot put down 5 m from where it believes it is, whose estimate closes 0.5 m a
    /// cycle: 0.5 m off at the tenth cycle, within 0.3 m at the eleventh, 1.0 s after its
    /// first estimate. One that
    /// stays 1 m off never finds itself, and then neither does `all`.
    #[test]
    fn a_robot_found_itself_when_its_estimate_first_came_near_the_truth() {
        let path = std::env::temp_dir().join(format!("mrt-found-{}.mcap", std::process::id()));
        let mut rec = Recorder::create(&path).unwrap();
        for k in 0..20u64 {
            let t = Time::from_secs_f64(1.0 + k as f64 * 0.1);
            let truth = Truth {
                ball: (0.0, 0.0),
                ball_velocity: (0.0, 0.0),
                robots: vec![Pose2::new(0.0, 0.0, 0.0), Pose2::new(1.0, 1.0, 0.0)],
                home: 2,
                score: (0, 0),
                state: GameState::Playing,
            };
            rec.record("/truth", t, &truth).unwrap();
            let off = (5.0 - 0.5 * k as f64).max(0.05);
            let home =
                Localization { pose: Framed::new(Pose2::new(0.0, off, 0.0)), ..Default::default() };
            rec.record("/home/0/Localization", t, &home).unwrap();
            let lost =
                Localization { pose: Framed::new(Pose2::new(2.0, 1.0, 0.0)), ..Default::default() };
            rec.record("/home/1/Localization", t, &lost).unwrap();
        }
        rec.finish().unwrap();
        let a = accuracy(&Recording::open(&path).unwrap()).unwrap();
        std::fs::remove_file(&path).ok();
        let found = a[0].found_after.unwrap();
        assert!((found - 1.0).abs() < 1e-6, "{found}");
        assert_eq!((a[1].found_after, a[2].found_after), (None, None));
    }

    #[test]
    fn a_spread_is_of_the_finite_errors() {
        assert_eq!(Spread::of(vec![]), None);
        assert_eq!(Spread::of(vec![f64::NAN]), None);
        let s = Spread::of((1..=20).map(f64::from).chain([f64::INFINITY]).collect()).unwrap();
        assert_eq!((s.count, s.mean, s.median, s.p95), (20, 10.5, 11.0, 19.0));
    }
}
