//! How well the vision µAgent sees: percepts from rendered images against the simulator's
//! truth.
//!
//! A survey draws random scenes on the field (a viewing robot, the ball, other robots; in half
//! the scenes the ball lies ahead of the viewer, as it mostly does in play), renders the
//! viewer's camera, runs the vision µAgent on the image and compares every percept with the
//! truth, in the robot's frame from its centre. Per kind of object it counts:
//! - **in view**: the object's reference point projects inside the image, no other robot
//!   stands between it and the viewer, and it is within the kind's range ([`MAX_RANGE`]);
//! - **found**: in view and reported;
//! - **wrong**: reported, but nothing of that kind is in view near it (off by more than
//!   [`WRONG_DISTANCE`] of its distance or [`WRONG_BEARING`]): a false positive;
//! - the errors of the percepts that are not wrong: distance relative to the true distance,
//!   bearing in degrees (medians and 90th percentiles).
//!
//! The reference points are the ball's centre (on the floor below it), the centre of each goal
//! line (the nets of the world model), the landmark posts' axes, the goals' corners on the
//! floor (reported for a goal cut by the image's side), and the nearest point of
//! every other robot's body (the obstacles). The whole survey is a pure function of the
//! configuration and the seed.
//!
//! ```
//! use mrt_sim::config::SimConfig;
//! use mrt_sim::survey::survey;
//!
//! let report = survey(&SimConfig::default(), 7, 20)?;
//! let ball = report.kind("ball").expect("the ball is surveyed");
//! assert!(ball.in_view > 0 && ball.found <= ball.in_view);
//! # Ok::<(), mrt_sim::SimError>(())
//! ```

use crate::config::SimConfig;
use crate::error::SimError;
use crate::render::{CameraState, Renderer, Scene};
use mrt_core::{normalize_angle, Pose2};
use mrt_msgs::{Percepts, Sighting};
use mrt_perception::camera::{Camera, Pinhole};
use mrt_perception::vision::agent::VisionAgent;
use mrt_perception::vision::colors::ColorTable;
use mrt_perception::vision::posts::PostShape;
use nalgebra::Point3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Objects farther than this are not counted as in view, m: the ball (a few pixels at
/// 8 m), the nets and posts (across the whole field), the other robots.
pub const MAX_RANGE: [(&str, f64); 5] =
    [("ball", 8.0), ("net", 25.0), ("post", 25.0), ("corner", 25.0), ("obstacle", 8.0)];
/// A percept off by more than this fraction of its distance is wrong.
pub const WRONG_DISTANCE: f64 = 0.3;
/// A percept off by more than this bearing is wrong, rad (10°).
pub const WRONG_BEARING: f64 = 0.1745;

/// What the survey found for one kind of object.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct KindReport {
    /// `ball`, `net`, `post`, `corner` or `obstacle`.
    pub kind: &'static str,
    /// Objects of this kind in view (module doc).
    pub in_view: u64,
    /// Of those, reported.
    pub found: u64,
    /// Percepts with nothing of this kind near them.
    pub wrong: u64,
    /// Median relative distance error of the right percepts.
    pub distance_median: f64,
    /// 90th percentile of the relative distance error.
    pub distance_p90: f64,
    /// Median bearing error, degrees.
    pub bearing_median_deg: f64,
    /// 90th percentile of the bearing error, degrees.
    pub bearing_p90_deg: f64,
}

/// A survey's result.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SurveyReport {
    /// Scenes drawn.
    pub scenes: usize,
    /// The seed.
    pub seed: u64,
    /// One line per kind: ball, net, post, corner, obstacle.
    pub kinds: Vec<KindReport>,
}

impl SurveyReport {
    /// The line of one kind.
    pub fn kind(&self, kind: &str) -> Option<&KindReport> {
        self.kinds.iter().find(|k| k.kind == kind)
    }

    /// The report as a table (Markdown), for a person and for `docs/`.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} scenes, seed {}\n\n| object | in view | found | wrong | distance error (median, p90) | bearing error (median, p90) |\n|---|---|---|---|---|---|\n",
            self.scenes, self.seed
        );
        for k in &self.kinds {
            let rate = if k.in_view > 0 { 100.0 * k.found as f64 / k.in_view as f64 } else { 0.0 };
            out += &format!(
                "| {} | {} | {} ({rate:.0} %) | {} | {:.1} %, {:.1} % | {:.2}°, {:.2}° |\n",
                k.kind,
                k.in_view,
                k.found,
                k.wrong,
                100.0 * k.distance_median,
                100.0 * k.distance_p90,
                k.bearing_median_deg,
                k.bearing_p90_deg
            );
        }
        out
    }
}

/// Accumulates one kind's counts and errors.
#[derive(Default)]
struct Tally {
    in_view: u64,
    found: u64,
    wrong: u64,
    distance: Vec<f64>,
    bearing: Vec<f64>,
}

impl Tally {
    /// Matches the reported `seen` against the true sightings `truth` of every object of the
    /// kind, each flagged whether it is in view (module doc); each true object is matched at
    /// most once, the nearest percept first. A percept of an object out of view (too far, or
    /// behind a robot by this survey's reckoning) is neither found nor wrong, but its error
    /// counts.
    fn add(&mut self, truth: &[(Sighting, bool)], seen: &[Sighting]) {
        self.in_view += truth.iter().filter(|(_, v)| *v).count() as u64;
        let mut taken = vec![false; truth.len()];
        for s in seen {
            let best = truth
                .iter()
                .enumerate()
                .filter(|(i, _)| !taken[*i])
                .map(|(i, (t, _))| (i, error(t, s)))
                .filter(|(_, (d, b))| *d <= WRONG_DISTANCE && *b <= WRONG_BEARING)
                .min_by(|a, b| (a.1 .0 + a.1 .1).total_cmp(&(b.1 .0 + b.1 .1)));
            match best {
                Some((i, (d, b))) => {
                    taken[i] = true;
                    if truth[i].1 {
                        self.found += 1;
                    }
                    self.distance.push(d);
                    self.bearing.push(b.to_degrees());
                }
                None => self.wrong += 1,
            }
        }
    }

    fn report(mut self, kind: &'static str) -> KindReport {
        KindReport {
            kind,
            in_view: self.in_view,
            found: self.found,
            wrong: self.wrong,
            distance_median: quantile(&mut self.distance, 0.5),
            distance_p90: quantile(&mut self.distance, 0.9),
            bearing_median_deg: quantile(&mut self.bearing, 0.5),
            bearing_p90_deg: quantile(&mut self.bearing, 0.9),
        }
    }
}

/// Relative distance error and absolute bearing error (rad) of `seen` against `truth`.
fn error(truth: &Sighting, seen: &Sighting) -> (f64, f64) {
    (
        (seen.distance - truth.distance).abs() / truth.distance.max(0.1),
        normalize_angle(seen.bearing - truth.bearing).abs(),
    )
}

/// The `q` quantile (nearest rank) of `v`; 0 when empty.
fn quantile(v: &mut [f64], q: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// Range and bearing of the field point `(x, y)` from `from` (robot frame).
fn sight(from: Pose2, x: f64, y: f64) -> Sighting {
    let (dx, dy) = (x - from.x, y - from.y);
    let (s, c) = from.theta.sin_cos();
    let (fx, fy) = (c * dx + s * dy, -s * dx + c * dy);
    Sighting { distance: fx.hypot(fy), bearing: fy.atan2(fx) }
}

/// Whether a robot of `robots` (radius `r`, other than the viewer) stands between the viewer
/// and the field point `(x, y)`.
fn hidden(viewer: Pose2, x: f64, y: f64, robots: &[(Pose2, bool)], r: f64) -> bool {
    let (ax, ay) = (viewer.x, viewer.y);
    let (dx, dy) = (x - ax, y - ay);
    let len2 = dx * dx + dy * dy;
    robots.iter().skip(1).any(|(p, _)| {
        let t = (((p.x - ax) * dx + (p.y - ay) * dy) / len2.max(1e-9)).clamp(0.0, 1.0);
        let (cx, cy) = (ax + t * dx - p.x, ay + t * dy - p.y);
        t > 0.0 && t < 1.0 && cx.hypot(cy) < r && (p.x - x).hypot(p.y - y) > r
    })
}

/// Whether the field point `(x, y, z)` shows in the image of `camera` on a robot at `viewer`.
fn in_image(camera: &Pinhole, viewer: Pose2, x: f64, y: f64, z: f64) -> bool {
    let s = sight(viewer, x, y);
    let p = Point3::new(s.distance * s.bearing.cos(), s.distance * s.bearing.sin(), z);
    camera.project(p).is_some_and(|px| camera.in_image(px))
}

fn range(kind: &str) -> f64 {
    MAX_RANGE.iter().find(|(k, _)| *k == kind).map_or(f64::INFINITY, |(_, r)| *r)
}

/// Surveys `scenes` random scenes of the world `cfg` (module doc).
pub fn survey(cfg: &SimConfig, seed: u64, scenes: usize) -> Result<SurveyReport, SimError> {
    let renderer = Renderer::new(cfg)?;
    let map = cfg.field;
    let camera = cfg
        .vision
        .camera
        .camera()
        .map_err(|e| SimError::Config(format!("vision.camera: {e}")))?
        .panned(0.0);
    let shape = PostShape { radius: cfg.vision.post_radius, height: cfg.vision.post_height };
    let mut agent = VisionAgent::new(camera, &ColorTable::shipped(), cfg.ball.radius)
        .post_shape(shape)
        .goal_width(map.goal_width);
    let (hl, hw) = (map.half_length(), map.half_width());
    let r = cfg.body.radius;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut state = CameraState::new(seed);
    let (mut ball_t, mut net_t, mut post_t, mut corner_t, mut obstacle_t) =
        (Tally::default(), Tally::default(), Tally::default(), Tally::default(), Tally::default());
    for scene_no in 0..scenes {
        let (robots, ball) = random_scene(&mut rng, hl, hw, r, cfg.ball.radius);
        let viewer = robots[0].0;
        let scene = Scene { ball: Some(ball), robots: robots.clone() };
        let image = renderer.render(&scene, viewer, 0.0, Some(0), &mut state);
        let p: Percepts = agent.see(&image, scene_no as f64, 0.0)?;
        let visible = |kind: &str, x: f64, y: f64, z: f64| {
            let s = sight(viewer, x, y);
            s.distance <= range(kind)
                && in_image(&camera, viewer, x, y, z)
                && !hidden(viewer, x, y, &robots, r)
        };
        // The ball.
        let truth =
            [(sight(viewer, ball.0, ball.1), visible("ball", ball.0, ball.1, cfg.ball.radius))];
        ball_t.add(&truth, p.sightings[mrt_msgs::sighting::BALL].as_slice());
        // The nets (the centres of the goal lines): in view when the feet of both posts of
        // the goal are.
        for k in [1, 2] {
            let Some(at) = map.object(k) else { continue };
            let gw = map.goal_width / 2.0;
            let seen_whole =
                visible("net", at.x, at.y + gw, 0.0) && visible("net", at.x, at.y - gw, 0.0);
            net_t.add(&[(sight(viewer, at.x, at.y), seen_whole)], p.sightings[k].as_slice());
        }
        // The landmark posts, at their feet.
        let truth: Vec<(Sighting, bool)> = (mrt_msgs::sighting::LANDMARK0..mrt_msgs::FIELD_OBJECTS)
            .filter_map(|k| map.object(k))
            .map(|at| (sight(viewer, at.x, at.y), visible("post", at.x, at.y, 0.0)))
            .collect();
        let seen: Vec<Sighting> = p.posts.iter().map(|q| q.sighting).collect();
        post_t.add(&truth, &seen);
        // The corners of the goals on the floor: in view when the corner is and its goal is
        // not seen whole (then its net is reported instead).
        for east in [true, false] {
            let corners = map.goal_corners(east);
            let whole = corners[..2].iter().all(|c| visible("net", c.x, c.y, 0.0));
            let truth: Vec<(Sighting, bool)> = corners
                .iter()
                .map(|c| (sight(viewer, c.x, c.y), !whole && visible("corner", c.x, c.y, 0.0)))
                .collect();
            let seen: Vec<Sighting> =
                p.goal_corners.iter().filter(|c| c.east == east).map(|c| c.sighting).collect();
            corner_t.add(&truth, &seen);
        }
        // The other robots, at their nearest point.
        let truth: Vec<(Sighting, bool)> = robots[1..]
            .iter()
            .map(|(q, _)| {
                let s = sight(viewer, q.x, q.y);
                let near = Sighting { distance: (s.distance - r).max(0.0), bearing: s.bearing };
                (near, visible("obstacle", q.x, q.y, 0.0))
            })
            .collect();
        let seen: Vec<Sighting> = p.robots.iter().map(|q| q.sighting).collect();
        obstacle_t.add(&truth, &seen);
    }
    Ok(SurveyReport {
        scenes,
        seed,
        kinds: vec![
            ball_t.report("ball"),
            net_t.report("net"),
            post_t.report("post"),
            corner_t.report("corner"),
            obstacle_t.report("obstacle"),
        ],
    })
}

/// A random scene: the viewer first (anywhere on the field, facing anywhere), four other
/// robots, and the ball (in half the scenes 0.5–4 m ahead of the viewer, within 30°), none
/// overlapping.
fn random_scene(
    rng: &mut ChaCha8Rng,
    hl: f64,
    hw: f64,
    r: f64,
    ball_r: f64,
) -> (Vec<(Pose2, bool)>, (f64, f64)) {
    let margin = r + 0.1;
    let mut robots: Vec<(Pose2, bool)> = Vec::new();
    let free = |robots: &[(Pose2, bool)], x: f64, y: f64, clearance: f64| {
        robots.iter().all(|(p, _)| (p.x - x).hypot(p.y - y) > clearance)
    };
    while robots.len() < 5 {
        let x = rng.random_range(-hl + margin..hl - margin);
        let y = rng.random_range(-hw + margin..hw - margin);
        let theta = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        if free(&robots, x, y, 2.0 * r + 0.05) {
            let home = robots.len() % 2 == 0;
            robots.push((Pose2::new(x, y, theta), home));
        }
    }
    let viewer = robots[0].0;
    loop {
        let (x, y) = if rng.random_bool(0.5) {
            let d = rng.random_range(0.5..4.0);
            let b = viewer.theta + rng.random_range(-0.5..0.5);
            (viewer.x + d * b.cos(), viewer.y + d * b.sin())
        } else {
            (rng.random_range(-hl..hl), rng.random_range(-hw..hw))
        };
        let inside = x.abs() < hl - ball_r && y.abs() < hw - ball_r;
        if inside && free(&robots, x, y, r + ball_r + 0.02) {
            return (robots, (x, y));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tally_matches_each_true_object_once_and_counts_the_rest_wrong() {
        let mut t = Tally::default();
        let s = |distance: f64, deg: f64| Sighting { distance, bearing: deg.to_radians() };
        // Two objects in view; percepts: one 2 % long, one 1° off, one far from both.
        // A third object out of view, seen 1 % short: neither found nor wrong.
        let truth = [(s(2.0, 0.0), true), (s(5.0, 20.0), true), (s(9.0, -60.0), false)];
        t.add(&truth, &[s(2.04, 0.0), s(5.0, 21.0), s(3.0, -40.0), s(8.91, -60.0)]);
        assert_eq!((t.in_view, t.found, t.wrong), (2, 2, 1));
        assert_eq!(t.distance.len(), 3);
        let k = t.report("post");
        assert!((k.distance_p90 - 0.02).abs() < 1e-9, "{k:?}");
        assert!((k.distance_median - 0.01).abs() < 1e-9, "{k:?}");
        assert!((k.bearing_p90_deg - 1.0).abs() < 1e-9, "{k:?}");
    }

    #[test]
    fn a_robot_between_hides_what_is_behind_it() {
        let viewer = Pose2::new(0.0, 0.0, 0.0);
        let robots = [(viewer, true), (Pose2::new(2.0, 0.05, 0.0), false)];
        assert!(hidden(viewer, 4.0, 0.0, &robots, 0.25));
        assert!(!hidden(viewer, 4.0, 1.5, &robots, 0.25));
        assert!(!hidden(viewer, 1.0, 0.0, &robots, 0.25), "in front of the robot");
    }
}
