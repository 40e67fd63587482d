//! Global relocalization: MUREA (MRT manual ch. 7) watching the pose tracker and putting it
//! right when it is lost.
//!
//! The manual runs MUREA in two modes: tracking, around the odometry's prediction, and global,
//! "when the quality of the localization drops or on demand". Here the [`WorldModel`]'s EKF
//! tracks (it costs microseconds a frame) and a [`Relocalizer`] decides when the global mode
//! must run:
//!
//! 1. Every frame's percepts become MUREA [`Perception`]s ([`perceptions`]): the coloured nets,
//!    the landmark posts by their colour pattern, a sample of the field-line points. They go
//!    into a short **window** (the last [`Relocalizer::window`] seconds), each glimpse
//!    kept in the field frame of the tracker's pose when it was seen and carried to the
//!    robot's frame now by the tracker's motion since, so that a robot whose camera sees one
//!    thing at a time (a pan joint sweeping, ThinkingCap/TeamChaos report §2.1) still gathers enough to
//!    localize. (The tracker's motion, not the odometry's alone: a mouse that under-reads
//!    turns the dead reckoning by tenths of a radian, which the tracker's corrections undo.)
//!    Older glimpses weigh less (halved every [`HALF_LIFE`] s) and their tolerances grow
//!    with the distance driven and the angle turned since. When [`DISAGREE`] glimpses in a
//!    row do not fit the tracker's pose after some that did, the older ones are dropped: the
//!    odometry cannot feel a robot lifted and carried, so what it saw before says nothing of
//!    where it is.
//! 2. Every frame is scored at the tracker's pose ([`Murea::quality_at`], a few
//!    microseconds). While the pose explains at least [`SUSPECT`] of it, nothing else runs;
//!    nor on the first frame that it does not explain (a false sighting, or the first after a
//!    carry: the next frame tells).
//! 3. Otherwise, the whole window is scored at the tracker's pose. When that too falls below
//!    [`SUSPECT`] and the window holds two goals or posts worth [`MARKS`] together, at
//!    most every [`RETRY`] s, MUREA searches the whole field on the goals and posts, coarsely
//!    (25 cm, 4°: line points fit some line from almost anywhere and would keep every cell's
//!    bound high), then around that pose on everything (10 cm, 2°). The fix replaces the
//!    tracker's pose when it explains at least [`ACCEPT`] of the window, [`MARGIN`] more
//!    than the tracker's pose, lies apart from it, the search finished within its budget, and
//!    the coarse search found no other pose far from it that explains nearly as much (on a
//!    symmetric field, the mirrored pose).
//!
//!    With a single goal or post in the window but [`ONE_MARK_LINES`] line points or more
//!    (a forward camera that sees one post and the lines before it), MUREA searches the
//!    whole field on all of them at the fine accuracy, within [`ONE_MARK_CELLS`], and the
//!    fix is taken on the same terms when no other pose far from it explains nearly as much
//!    (a corner post with its two lines looks the same from its mirror image, and is
//!    refused). A search that gave no answer makes the next wait longer, up to
//!    [`ONE_MARK_BACKOFF`] s.
//!
//! 4. In ISocRob's **self mode** ([`Relocalizer::with_self_mode`], for a robot whose up
//!    camera sees the field lines all around it, ISocRob-2000 report §3.2.1), a frame with
//!    [`SELF_POINTS`] line points or more is searched even without two goals or posts: the
//!    Hough transform of its lines ([`crate::hough`]) gives the pose up to the field's
//!    half-turn symmetry, MUREA refines both twins on the window, and the fix is taken, on
//!    the same terms as above, when one of them explains [`MARGIN`] more than the other (a
//!    single goal or post in the window tells them apart).
//!
//! A robot carried elsewhere (the kidnapped robot of every RoboCup match) or one whose
//! tracker locked onto the wrong landmark is found again this way; a robot started anywhere
//! needs no placement.
//!
//! [`WorldModel`]: crate::model::WorldModel

use crate::field::FieldMap;
use crate::hough::{hough_lines, self_localize, HoughParams};
use crate::murea::{Fix, Kind, Map, Murea, Perception};
use mrt_core::frames::{Framed, Robot};
use mrt_core::{normalize_angle, Point2, Pose2};
use mrt_msgs::{PostSighting, Sighting, FIELD_OBJECTS};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::fmt;
use std::str::FromStr;

/// Which estimator keeps a robot's pose (`[localization] localizer` in a robot or simulator
/// file, `mrt sim --localizer`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Localizer {
    /// The EKF alone: it must be told where it starts, and when lost it only widens its
    /// uncertainty and listens again.
    Ekf,
    /// The EKF tracking, MUREA relocalizing globally when the EKF's pose stops explaining
    /// what the robot sees (module doc).
    #[default]
    Murea,
    /// The EKF tracking, ThinkingCap's fuzzy grid (GM, [`crate::gm`]) following every frame
    /// and moving the EKF when it is sure the EKF is elsewhere.
    Gm,
}

impl Localizer {
    /// Every localizer's name, as the files and the command line spell them.
    pub const NAMES: [&'static str; 3] = ["ekf", "murea", "gm"];
}

impl fmt::Display for Localizer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Localizer::Ekf => "ekf",
            Localizer::Murea => "murea",
            Localizer::Gm => "gm",
        })
    }
}

impl FromStr for Localizer {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "ekf" => Ok(Localizer::Ekf),
            "murea" => Ok(Localizer::Murea),
            "gm" => Ok(Localizer::Gm),
            _ => Err(format!(
                "unknown localizer `{s}` (expected one of: {})",
                Self::NAMES.join(", ")
            )),
        }
    }
}

/// Below this fraction of the window explained by the tracker's pose, MUREA searches.
pub const SUSPECT: f64 = 0.5;
/// A fix must explain at least this fraction of the window...
pub const ACCEPT: f64 = 0.65;
/// ... and this much more than the tracker's pose.
pub const MARGIN: f64 = 0.2;
/// Shortest time between two global searches, s.
pub const RETRY: f64 = 0.5;
/// An older glimpse's weight halves every this many seconds.
pub const HALF_LIFE: f64 = 0.5;
/// After this many glimpses in a row that the tracker's pose does not explain, the glimpses
/// before them are forgotten.
pub const DISAGREE: usize = 2;
/// A search takes the newest glimpses' perceptions until it has this many (its time grows
/// with them: docs/performance.md).
pub const WINDOW_PERCEPTIONS: usize = 24;
/// Two sightings of a goal or a post of one kind this close (m, in the field frame of the
/// tracker), or within their range tolerances combined, are one object seen twice.
pub const SAME_OBJECT: f64 = 0.5;
/// The goals and posts of the window must weigh this much together for a search.
pub const MARKS: f64 = 1.5;
/// With a single goal or post in the window, a search also needs this many field-line
/// points...
pub const ONE_MARK_LINES: usize = 10;
/// ... and stops after this many cells.
pub const ONE_MARK_CELLS: usize = 30_000;
/// The longest wait after one-mark searches that gave no answer, s.
pub const ONE_MARK_BACKOFF: f64 = 4.0;
/// The self mode searches without such marks when a frame has this many field-line points.
pub const SELF_POINTS: usize = 24;
/// At most this many line points of one frame become perceptions (evenly picked).
pub const LINE_POINTS: usize = 12;
/// Weight of one line point (a line point says less than a goal: it fits any point of any
/// line).
const LINE_WEIGHT: f64 = 0.3;
/// Tolerance growth per metre driven since a glimpse (odometry drift), m/m.
const DRIFT: f64 = 0.05;

/// The camera's measurement noise as the world model assumes it: a standard deviation of the
/// distance proportional to it (`distance`, a fraction) and one of the bearing (`bearing`,
/// rad). Robot files set it (`mrt_robot::config::RobotConfig::camera`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraNoise {
    /// Relative distance error.
    pub distance: f64,
    /// Bearing error, rad.
    pub bearing: f64,
}

impl CameraNoise {
    /// The standard deviations `(m, rad)` of a sighting at `distance`: the camera's, plus
    /// 1 cm and 0.3° of modelling error, or the sighting's own `sigma` where larger.
    pub fn sigma(&self, distance: f64, sigma: Option<(f64, f64)>) -> (f64, f64) {
        let (sd, sb) = (self.distance * distance + 0.01, self.bearing + 0.005);
        sigma.map_or((sd, sb), |(d, b)| (sd.max(d), sb.max(b)))
    }
}

/// What one frame showed, as [`perceptions`] reads it: nets and named landmarks in
/// field-object order with their standard deviations where known, the landmark posts by their
/// colour pattern, the corners of goals cut by the image's side, and the field-line points
/// (robot frame, m). [`FrameSeen::of`] starts from the sightings alone.
#[derive(Clone, Copy, Debug)]
pub struct FrameSeen<'a> {
    /// Nets and named landmarks, field-object order.
    pub sightings: &'a [Option<Sighting>; FIELD_OBJECTS],
    /// Each sighting's standard deviations (distance m, bearing rad), where known.
    pub sigmas: &'a [Option<(f64, f64)>; FIELD_OBJECTS],
    /// Landmark posts by their colour pattern.
    pub posts: &'a [PostSighting],
    /// Corners of goals cut by the image's side, by their goal's colour.
    pub goal_corners: &'a [PostSighting],
    /// Field-line points, robot frame (m).
    pub line_points: &'a [Framed<Robot, Point2>],
}

impl<'a> FrameSeen<'a> {
    /// The frame's `sightings`, with nothing else seen and no standard deviations known.
    pub fn of(sightings: &'a [Option<Sighting>; FIELD_OBJECTS]) -> Self {
        const UNKNOWN: [Option<(f64, f64)>; FIELD_OBJECTS] = [None; FIELD_OBJECTS];
        FrameSeen { sightings, sigmas: &UNKNOWN, posts: &[], goal_corners: &[], line_points: &[] }
    }
}

/// The MUREA perceptions of one frame ([`FrameSeen`]): its nets, landmarks, posts and goal
/// corners, and up to [`LINE_POINTS`] of its line points. Tolerances are three standard
/// deviations ([`CameraNoise::sigma`]), at least 5 cm and 1°.
pub fn perceptions(field: &FieldMap, noise: CameraNoise, seen: FrameSeen<'_>) -> Vec<Perception> {
    let FrameSeen { sightings, sigmas, posts, goal_corners, line_points } = seen;
    let point = |kind: Kind, z: &Sighting, sigma: Option<(f64, f64)>| {
        let (sd, sb) = noise.sigma(z.distance, sigma);
        Perception::point(kind, z.distance, z.bearing)
            .tolerances((3.0 * sd).max(0.05), (3.0 * sb).max(1f64.to_radians()))
    };
    let mut out = Vec::new();
    for (k, z) in sightings.iter().enumerate() {
        if let (Some(z), Some(kind)) = (z, Kind::of_object(field, k, true)) {
            out.push(point(kind, z, sigmas[k]));
        }
    }
    for post in posts {
        let kind = if post.east { Kind::EAST_POST } else { Kind::WEST_POST };
        out.push(point(kind, &post.sighting, Some(post.sigma)));
    }
    for corner in goal_corners {
        out.push(point(Kind::goal_corner(corner.east, true), &corner.sighting, Some(corner.sigma)));
    }
    let step = line_points.len().div_ceil(LINE_POINTS).max(1);
    for (x, y) in line_points.iter().step_by(step).map(|p| (p.inner.x, p.inner.y)) {
        let z = Sighting { distance: x.hypot(y), bearing: y.atan2(x) };
        out.push(point(Kind::LINE, &z, None).weighted(LINE_WEIGHT));
    }
    out.retain(|p| p.range.is_some_and(f64::is_finite) && p.bearing.is_some_and(f64::is_finite));
    out
}

/// What one frame showed, kept in the field frame of the tracker's pose then.
#[derive(Clone, Debug)]
struct Glimpse {
    time: f64,
    /// How far the robot had driven by then, m, and turned, rad.
    driven: (f64, f64),
    /// Each perception's point in the field frame, with the perception.
    seen: Vec<(Point2, Perception)>,
    /// Whether the tracker's pose explained it when it came (`None`: it weighs too little to
    /// say).
    fits: Option<bool>,
}

/// What the relocalizer did, counted since it started.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RelocalizerCounts {
    /// Global searches run.
    pub searches: u64,
    /// Fixes that replaced the tracker's pose.
    pub accepted: u64,
    /// Fixes refused as ambiguous.
    pub ambiguous: u64,
}

/// MUREA in the global mode, watching a pose tracker (module doc).
#[derive(Clone, Debug)]
pub struct Relocalizer {
    /// The global search: coarse (25 cm, 4°), on the goals and posts.
    coarse: Murea,
    /// The refinement around the coarse fix (10 cm, 2°), on everything.
    murea: Murea,
    /// The search on one goal or post and the lines: the refinement's accuracy over the
    /// whole field, within [`ONE_MARK_CELLS`].
    one_mark: Murea,
    /// Glimpses older than this are forgotten, s.
    pub window: f64,
    glimpses: VecDeque<Glimpse>,
    /// How far the robot drove (m) and turned (rad) since it started, as the odometry says.
    driven: (f64, f64),
    last_search: Option<f64>,
    /// After a one-mark search that gave no answer: how long it waited, and when the next
    /// may run (s).
    one_mark_backoff: Option<(f64, f64)>,
    counts: RelocalizerCounts,
    /// The self mode (module doc, 4.): the field, and this frame's field-line points (robot
    /// frame), when on.
    self_mode: Option<(FieldMap, Vec<Point2>)>,
}

impl Relocalizer {
    /// A relocalizer on `field`, whose goals and posts are told apart by colour, the coarse
    /// search within 60 000 cells and the fine one within 20 000, and a window of 1.5 s.
    pub fn new(field: &FieldMap) -> Relocalizer {
        let mut murea = Murea::new(Map::field(field, true));
        // The tracker refines the fix from the next sightings: 10 cm and 2° are enough.
        murea.accuracy = (0.1, 2f64.to_radians());
        murea.budget.cells = 20_000;
        let mut coarse = murea.clone();
        coarse.accuracy = (0.25, 4f64.to_radians());
        coarse.budget.cells = 60_000;
        let mut one_mark = murea.clone();
        one_mark.budget.cells = ONE_MARK_CELLS;
        Relocalizer {
            coarse,
            one_mark,
            murea,
            window: 1.5,
            glimpses: VecDeque::new(),
            driven: (0.0, 0.0),
            last_search: None,
            one_mark_backoff: None,
            counts: RelocalizerCounts::default(),
            self_mode: None,
        }
    }

    /// The same relocalizer in ISocRob's self mode too (module doc, 4.; ISocRob-2000 report §3.2.1):
    /// for a robot whose camera sees the field lines all around (the up camera).
    pub fn with_self_mode(mut self, field: &FieldMap) -> Relocalizer {
        self.self_mode = Some((*field, Vec::new()));
        self
    }

    /// Whether it runs the self mode.
    pub fn self_mode(&self) -> bool {
        self.self_mode.is_some()
    }

    /// This frame's field-line points (robot frame, m), for the self mode; call before
    /// [`Relocalizer::frame`].
    pub fn lines(&mut self, points: &[Framed<Robot, Point2>]) {
        if let Some((_, lines)) = &mut self.self_mode {
            lines.clear();
            lines.extend(points.iter().map(|p| p.inner));
        }
    }

    /// Whether the tracker's pose explained the last frame with perceptions: `None` before
    /// the first, or when that frame weighed too little to say (a few line points).
    pub fn last_fits(&self) -> Option<bool> {
        self.glimpses.back().and_then(|g| g.fits)
    }

    /// What it did so far.
    pub fn counts(&self) -> RelocalizerCounts {
        self.counts
    }

    /// The robot moved by `d` (robot frame) as the odometry says.
    pub fn moved(&mut self, d: Pose2) {
        if d.x.is_finite() && d.y.is_finite() && d.theta.is_finite() {
            self.driven.0 += d.x.hypot(d.y);
            self.driven.1 += d.theta.abs();
        }
    }

    /// The robot was put down somewhere by hand: what it saw before says nothing about where
    /// it is now.
    pub fn forget(&mut self) {
        self.glimpses.clear();
    }

    /// The perceptions of the window, in the robot's frame now, weighed by age and with
    /// tolerances grown by the drive since: the newest glimpses first, until
    /// [`WINDOW_PERCEPTIONS`] are taken. A goal or post seen again (of its kind, within
    /// [`SAME_OBJECT`] or the two sightings' range tolerances of it) is one perception at the
    /// weighted mean of its sightings: a far post seen twice 1 m apart (a camera's range
    /// error at 10 m) is one post, not two that no single pose explains. `pose`: the
    /// tracker's pose now.
    pub fn window_now(&self, now: f64, pose: Pose2) -> Vec<Perception> {
        // (field-frame point, the newest sighting's perception with grown tolerances,
        // the sum of the sightings' weights and of their weighted points)
        let mut seen: Vec<(Point2, Perception, f64, nalgebra::Vector2<f64>)> = Vec::new();
        for g in self.glimpses.iter().rev() {
            if seen.len() >= WINDOW_PERCEPTIONS {
                break;
            }
            let fade = 0.5f64.powf((now - g.time).max(0.0) / HALF_LIFE);
            let drift = DRIFT * (self.driven.0 - g.driven.0);
            let turned = self.driven.1 - g.driven.1;
            for (at, p) in &g.seen {
                let weight = (p.weight * fade).max(1e-3);
                let again = (p.kind != Kind::LINE)
                    .then(|| {
                        seen.iter_mut().find(|(first, q, ..)| {
                            q.kind == p.kind
                                && (first - at).norm()
                                    < SAME_OBJECT.max(q.range_tolerance.hypot(p.range_tolerance))
                        })
                    })
                    .flatten();
                if let Some((_, _, sum, mean)) = again {
                    *sum += weight;
                    *mean += at.coords * weight;
                    continue;
                }
                let q = pose.inverse_transform_point(*at);
                let range = q.coords.norm();
                let grown = Perception::point(p.kind, range, q.y.atan2(q.x))
                    .tolerances(
                        p.range_tolerance + drift,
                        p.bearing_tolerance + DRIFT * turned + drift / range.max(0.5),
                    )
                    .weighted(weight);
                seen.push((*at, grown, weight, at.coords * weight));
            }
        }
        seen.into_iter()
            .map(|(_, mut p, sum, mean)| {
                let q = pose.inverse_transform_point(Point2::from(mean / sum));
                p.range = Some(q.coords.norm());
                p.bearing = Some(q.y.atan2(q.x));
                // An object seen again and again is as sure as one seen now.
                p.weight = sum.min(1.0);
                p
            })
            .collect()
    }

    /// One frame's `perceptions` at `now` (s), with the tracker's `pose`. Returns MUREA's fix
    /// when it should replace the tracker's pose (module doc), `None` otherwise.
    pub fn frame(&mut self, now: f64, perceptions: Vec<Perception>, pose: Pose2) -> Option<Fix> {
        while self.glimpses.front().is_some_and(|g| now - g.time > self.window) {
            self.glimpses.pop_front();
        }
        if perceptions.is_empty() {
            return None;
        }
        // Whether the tracker's pose explains this frame: `None` when it weighs too little to
        // say (a few line points).
        let weight: f64 = perceptions.iter().map(|p| p.weight).sum();
        let fits = (weight >= 1.0).then(|| self.murea.quality_at(pose, &perceptions) >= SUSPECT);
        let seen = perceptions
            .into_iter()
            .filter_map(|p| {
                let (r, b) = (p.range?, p.bearing?);
                let at = Point2::new(r * b.cos(), r * b.sin());
                Some((pose.transform_point(at), p))
            })
            .collect();
        self.glimpses.push_back(Glimpse { time: now, driven: self.driven, seen, fits });
        // A run of glimpses that the tracker cannot explain after some that it could: the
        // robot was carried, or the tracker went wrong. What came before the run no longer
        // tells where the robot is now.
        let run = self.glimpses.iter().rev().take_while(|g| g.fits == Some(false)).count();
        if run >= DISAGREE && run < self.glimpses.len() {
            self.glimpses.drain(..self.glimpses.len() - run);
        }
        if fits == Some(true) {
            self.one_mark_backoff = None;
        }
        if self.glimpses.len() > 1 && (fits == Some(true) || (run > 0 && run < DISAGREE)) {
            // What it sees now agrees with the tracker, or disagrees for the first time (a
            // false sighting, or the first after a carry: the next frame tells).
            return None;
        }
        let window = self.window_now(now, pose);
        // Two goals or posts at least, worth [`MARKS`]: line points fit some line from
        // almost anywhere, and one object puts the robot anywhere on a circle round it.
        let marks: Vec<Perception> =
            window.iter().filter(|p| p.kind != Kind::LINE).copied().collect();
        let enough_marks = marks.len() >= 2 && marks.iter().map(|p| p.weight).sum::<f64>() >= MARKS;
        let lines_around = self.self_mode.as_ref().is_some_and(|(_, l)| l.len() >= SELF_POINTS);
        let lines = window.iter().filter(|p| p.kind == Kind::LINE).count();
        let one_mark = marks.len() == 1
            && lines >= ONE_MARK_LINES
            && self.one_mark_backoff.is_none_or(|(_, next)| now >= next);
        if !enough_marks && !lines_around && !one_mark {
            return None;
        }
        let tracked = self.murea.quality_at(pose, &window);
        if tracked >= SUSPECT || self.last_search.is_some_and(|t| now - t < RETRY) {
            return None;
        }
        self.last_search = Some(now);
        self.counts.searches += 1;
        if !enough_marks && one_mark && !lines_around {
            return self.one_mark_search(now, &window, pose, tracked);
        }
        if !enough_marks {
            return self.self_search(&window, pose, tracked);
        }
        // Globally on the goals and posts (the lines would keep every cell's bound high), then
        // around that pose with everything.
        let global = self.coarse.localize(&marks, self.coarse.whole_field());
        if global.timed_out || global.quality < ACCEPT {
            return None;
        }
        if !global.alternatives.is_empty() {
            self.counts.ambiguous += 1;
            return None;
        }
        let fix = self.murea.localize(&window, Murea::around(global.pose, 0.4, 0.15));
        if fix.timed_out {
            return None;
        }
        self.accept(fix, pose, tracked)
    }

    /// The search on one goal or post and the field lines (module doc, 3.): the whole field
    /// at the fine accuracy within [`ONE_MARK_CELLS`]. After one that ran out of cells or
    /// found other poses as good, the next waits twice as long as the last wait (from
    /// [`RETRY`] up to [`ONE_MARK_BACKOFF`]): a robot that sees the same post and lines for
    /// seconds would otherwise pay the whole budget every [`RETRY`] s.
    fn one_mark_search(
        &mut self,
        now: f64,
        window: &[Perception],
        pose: Pose2,
        tracked: f64,
    ) -> Option<Fix> {
        let fix = self.one_mark.localize(window, self.one_mark.whole_field());
        if fix.timed_out || !fix.alternatives.is_empty() {
            if !fix.alternatives.is_empty() {
                self.counts.ambiguous += 1;
            }
            let wait =
                self.one_mark_backoff.map_or(RETRY, |(w, _)| (2.0 * w).min(ONE_MARK_BACKOFF));
            self.one_mark_backoff = Some((wait, now + wait));
            return None;
        }
        self.accept(fix, pose, tracked)
    }

    /// `fix` when it should replace the tracker's `pose` (explaining `tracked` of the window):
    /// it explains at least [`ACCEPT`] of the window, [`MARGIN`] more than the tracker, and
    /// lies apart from it.
    fn accept(&mut self, fix: Fix, pose: Pose2, tracked: f64) -> Option<Fix> {
        let apart = (fix.pose.x - pose.x).hypot(fix.pose.y - pose.y) > 0.3
            || normalize_angle(fix.pose.theta - pose.theta).abs() > 0.2;
        if fix.quality < ACCEPT || fix.quality < tracked + MARGIN || !apart {
            return None;
        }
        self.counts.accepted += 1;
        self.one_mark_backoff = None;
        Some(fix)
    }

    /// The self mode's search (module doc, 4.): this frame's field lines through the Hough
    /// transform give a pose up to the field's half-turn symmetry; each of the two is refined
    /// on the window, whose goals or posts (one is enough) tell them apart.
    fn self_search(&mut self, window: &[Perception], pose: Pose2, tracked: f64) -> Option<Fix> {
        let (field, points) = self.self_mode.as_ref()?;
        let params = HoughParams::default();
        let lines = hough_lines(points, &params);
        let candidates = self_localize(field, points, &lines, &params);
        let best = candidates.first()?.explained;
        if best * 10 < points.len() * 8 {
            return None;
        }
        let mut fixes: Vec<Fix> = candidates
            .iter()
            .take_while(|c| c.explained == best)
            .take(2)
            .map(|c| self.murea.localize(window, Murea::around(c.pose, 0.4, 0.15)))
            .filter(|f| !f.timed_out)
            .collect();
        fixes.sort_by(|a, b| b.quality.total_cmp(&a.quality));
        let fix = fixes.first()?.clone();
        if fixes.get(1).is_some_and(|twin| twin.quality > fix.quality - MARGIN) {
            self.counts.ambiguous += 1;
            return None;
        }
        self.accept(fix, pose, tracked)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::sighting::{EAST_NET, WEST_NET};

    const NOISE: CameraNoise = CameraNoise { distance: 0.03, bearing: 0.02 };

    fn field() -> FieldMap {
        FieldMap::default()
    }

    /// What a robot at `pose` sees exactly of every net and landmark within 8 m.
    fn seen_from(pose: Pose2) -> [Option<Sighting>; FIELD_OBJECTS] {
        let f = field();
        std::array::from_fn(|k| {
            let at = f.object(k)?;
            let (dx, dy) = (at.x - pose.x, at.y - pose.y);
            (dx.hypot(dy) < 8.0).then(|| Sighting {
                distance: dx.hypot(dy),
                bearing: normalize_angle(dy.atan2(dx) - pose.theta),
            })
        })
    }

    #[test]
    fn localizer_names_round_trip_and_bad_names_say_what_is_expected() {
        for name in Localizer::NAMES {
            let l: Localizer = name.parse().unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(l.to_string(), name);
        }
        let err = "amcl".parse::<Localizer>().err().unwrap_or_default();
        assert!(err.contains("ekf, murea, gm"), "{err}");
    }

    #[test]
    fn the_frame_becomes_perceptions_by_kind_with_line_points_thinned() {
        let f = field();
        let mut sightings = [None; FIELD_OBJECTS];
        sightings[EAST_NET] = Some(Sighting { distance: 4.0, bearing: 0.1 });
        sightings[0] = Some(Sighting { distance: 1.0, bearing: 0.0 }); // the ball: not a landmark
        let posts = [PostSighting {
            sighting: Sighting { distance: 3.0, bearing: -0.2 },
            sigma: (0.2, 0.01),
            east: false,
            pixels: 40,
        }];
        let lines: Vec<Framed<Robot, Point2>> =
            (0..40).map(|i| Framed::new(Point2::new(1.0 + 0.1 * f64::from(i), 0.5))).collect();
        let p = perceptions(
            &f,
            NOISE,
            FrameSeen { posts: &posts, line_points: &lines, ..FrameSeen::of(&sightings) },
        );
        assert_eq!(p[0].kind, Kind::EAST_GOAL);
        assert!((p[0].range_tolerance - 0.39).abs() < 1e-12, "3 × (3 % of 4 m + 1 cm)");
        assert_eq!(p[1].kind, Kind::WEST_POST);
        assert!((p[1].range_tolerance - 0.6).abs() < 1e-12, "3 × its σ of 0.2 m");
        assert!((p[1].bearing_tolerance - 0.075).abs() < 1e-12, "3 × (0.02 + 0.005) rad");
        let lines = p.iter().filter(|q| q.kind == Kind::LINE).count();
        assert!((LINE_POINTS - 2..=LINE_POINTS).contains(&lines), "{lines}");
        assert!(p.iter().filter(|q| q.kind == Kind::LINE).all(|q| q.weight == LINE_WEIGHT));
    }

    /// The field-line points within 4 m of `pose`, every 10 cm, robot frame (an up camera's
    /// view, less its noise).
    fn lines_around(pose: Pose2) -> Vec<Framed<Robot, Point2>> {
        let mut out = Vec::new();
        for seg in field().lines() {
            let n = (seg.length() / 0.1) as usize;
            for k in 0..=n {
                let p = seg.a + (seg.b - seg.a) * (k as f64 / n as f64);
                let q = pose.inverse_transform_point(p);
                if q.coords.norm() <= 4.0 {
                    out.push(Framed::new(q));
                }
            }
        }
        out
    }

    /// The first fix of `r` over `frames` frames 0.1 s apart, each seeing `sightings` and the
    /// field-line points `lines` (robot frame), while its tracker stays at `wrong`.
    fn first_fix(
        r: &mut Relocalizer,
        frames: u32,
        (sightings, corners): (&[Option<Sighting>; FIELD_OBJECTS], &[PostSighting]),
        lines: &[Framed<Robot, Point2>],
        wrong: Pose2,
    ) -> Fix {
        let f = field();
        for k in 0..frames {
            r.lines(lines);
            let p = perceptions(
                &f,
                NOISE,
                FrameSeen { goal_corners: corners, line_points: lines, ..FrameSeen::of(sightings) },
            );
            if let Some(fix) = r.frame(0.1 * f64::from(k), p, wrong) {
                return fix;
            }
        }
        panic!("not found: {:?}", r.counts())
    }

    /// The ISocRob-2000 report's self mode (§3.2.1): a robot carried to a place where it sees one net only
    /// (the search on goals and posts needs two) is found again from the field lines all
    /// around it, the net telling the half-turn twins apart: with the self mode from the
    /// Hough lines of one frame, without it by MUREA's search on the net and the window's
    /// line points.
    #[test]
    fn the_self_mode_finds_a_carried_robot_from_the_lines_and_one_net() {
        let f = field();
        let truth = Pose2::new(-6.0, 1.5, 2.6);
        let wrong = Pose2::new(2.0, -2.0, 0.5);
        let mut seen = [None; FIELD_OBJECTS];
        seen[WEST_NET] = seen_from(truth)[WEST_NET];
        assert!(seen[WEST_NET].is_some());
        let lines = lines_around(truth);
        assert!(lines.len() >= SELF_POINTS);
        for self_mode in [false, true] {
            let mut r = Relocalizer::new(&f);
            if self_mode {
                r = r.with_self_mode(&f);
            }
            let fix = first_fix(&mut r, 20, (&seen, &[]), &lines, wrong);
            let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
            let turn = normalize_angle(fix.pose.theta - truth.theta).abs();
            assert!(err < 0.2 && turn < 0.05, "self mode {self_mode}: {fix:?}");
        }
    }

    /// A robot whose forward camera sees one post and the lines before it, for a second, is
    /// found again: two goals or posts are not needed when the lines say the rest.
    #[test]
    fn one_post_and_the_lines_in_view_find_a_carried_robot() {
        let f = field();
        // Looking north along the west penalty area: the north-west corner post (object 5,
        // at (−9, 6)) 7.6 m away, 9° to the left, the area's lines ahead. (Many views are
        // ambiguous with one post: a corner, or a post on the half-way line, looks the same
        // from its mirror image; the search then says so and waits.)
        let truth = Pose2::new(-6.0, -1.0, 7f64.atan2(-3.0) - 0.15);
        let wrong = Pose2::new(2.0, -2.0, 0.5);
        let mut one = [None; FIELD_OBJECTS];
        one[5] = seen_from(truth)[5];
        let bearing = one[5].map_or(1.0, |s: Sighting| s.bearing);
        assert!(bearing.abs() < 20f64.to_radians(), "the post in view: {bearing}");
        // The line points in a 40° field of view ahead, up to 4 m.
        let lines: Vec<Framed<Robot, Point2>> = lines_around(truth)
            .into_iter()
            .filter(|p| p.inner.x > 0.3 && p.inner.y.atan2(p.inner.x).abs() < 20f64.to_radians())
            .collect();
        assert!(lines.len() >= ONE_MARK_LINES, "{} line points in view", lines.len());
        let fix = first_fix(&mut Relocalizer::new(&f), 10, (&one, &[]), &lines, wrong);
        let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
        assert!(err < 0.2 && normalize_angle(fix.pose.theta - truth.theta).abs() < 0.05, "{fix:?}");
    }

    /// A keeper carried 2.8 m out in front of its own goal and facing it (a match once lost
    /// it for 165 s) sees no net, the goal being cut by the image's side, and no post: one
    /// corner of the goal and the lines before it find it again.
    #[test]
    fn a_goal_corner_and_the_lines_find_a_keeper_carried_before_its_goal() {
        let f = field();
        let truth = Pose2::new(6.24, -0.82, 0.0);
        let wrong = Pose2::new(8.67, 0.0, -0.58);
        // The east goal's south upright, at the outer face of its side.
        let [_, upright, ..] = f.goal_corners(true);
        let (dx, dy) = (upright.x - truth.x, upright.y - truth.y);
        let corner = PostSighting {
            sighting: Sighting { distance: dx.hypot(dy), bearing: dy.atan2(dx) - truth.theta },
            sigma: (0.02, 0.004),
            east: true,
            pixels: 5000,
        };
        let lines: Vec<Framed<Robot, Point2>> = lines_around(truth)
            .into_iter()
            .filter(|p| p.inner.x > 0.3 && p.inner.y.atan2(p.inner.x).abs() < 30f64.to_radians())
            .collect();
        assert!(lines.len() >= ONE_MARK_LINES, "{} line points in view", lines.len());
        let none = [None; FIELD_OBJECTS];
        let fix = first_fix(&mut Relocalizer::new(&f), 10, (&none, &[corner]), &lines, wrong);
        let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
        assert!(err < 0.2 && normalize_angle(fix.pose.theta - truth.theta).abs() < 0.05, "{fix:?}");
    }

    /// A one-mark search that runs out of cells is retried after 0.5, 1, 2, 4, 4 ... s, not
    /// every 0.5 s; a fix or a tracker that fits again starts the waits over.
    #[test]
    fn one_mark_searches_that_give_no_answer_back_off() {
        let f = field();
        let truth = Pose2::new(-5.5, 3.0, 2.8);
        let seen = seen_from(truth);
        let mark = (1..FIELD_OBJECTS).find(|&k| seen[k].is_some()).unwrap_or(0);
        let mut one = [None; FIELD_OBJECTS];
        one[mark] = seen[mark];
        let lines: Vec<Framed<Robot, Point2>> =
            lines_around(truth).into_iter().filter(|p| p.inner.x > 0.3).collect();
        let mut r = Relocalizer::new(&f);
        r.one_mark.budget.cells = 10; // every search runs out
        let wrong = Pose2::new(2.0, -2.0, 0.5);
        let mut searched = Vec::new();
        for k in 0..100 {
            let t = 0.1 * f64::from(k);
            let before = r.counts().searches;
            let p =
                perceptions(&f, NOISE, FrameSeen { line_points: &lines, ..FrameSeen::of(&one) });
            assert!(r.frame(t, p, wrong).is_none());
            if r.counts().searches > before {
                searched.push((10.0 * t).round() / 10.0);
            }
        }
        // The first frame searches at once (nothing agreed with the tracker before it).
        assert_eq!(searched, vec![0.0, 0.5, 1.5, 3.5, 7.5], "searched at {searched:?}");
        assert_eq!(r.one_mark_backoff.map(|b| b.0), Some(ONE_MARK_BACKOFF));
    }

    #[test]
    fn a_tracker_that_agrees_with_the_window_is_left_alone() {
        let f = field();
        let mut r = Relocalizer::new(&f);
        let truth = Pose2::new(2.0, 1.0, 0.3);
        for k in 0..10 {
            let seen = seen_from(truth);
            let p = perceptions(&f, NOISE, FrameSeen::of(&seen));
            assert!(r.frame(0.1 * f64::from(k), p, truth).is_none());
        }
        assert_eq!(r.counts().searches, 0, "the window fits the tracked pose");
    }

    #[test]
    fn a_kidnapped_robot_is_found_from_what_it_sees_after_the_carry() {
        let f = field();
        let mut r = Relocalizer::new(&f);
        let before = Pose2::new(-3.0, 2.0, 0.0);
        let mut t = 0.0;
        for _ in 0..10 {
            let p = perceptions(&f, NOISE, FrameSeen::of(&seen_from(before)));
            assert!(r.frame(t, p, before).is_none());
            t += 0.1;
        }
        // Carried to (3, −2) facing west; the odometry felt nothing, the tracker stays put.
        let after = Pose2::new(3.0, -2.0, 3.0);
        let mut fixed = None;
        for _ in 0..20 {
            let p = perceptions(&f, NOISE, FrameSeen::of(&seen_from(after)));
            if let Some(fix) = r.frame(t, p, before) {
                fixed = Some((t, fix));
                break;
            }
            t += 0.1;
        }
        let (when, fix) = fixed.unwrap_or_else(|| panic!("never relocalized: {:?}", r.counts()));
        assert!((fix.pose.x - 3.0).abs() < 0.1 && (fix.pose.y + 2.0).abs() < 0.1, "{fix:?}");
        assert!(normalize_angle(fix.pose.theta - 3.0).abs() < 0.05, "{fix:?}");
        assert!(when - 1.0 < 0.25, "found {:.1} s after the carry", when - 1.0);
    }

    #[test]
    fn glimpses_are_carried_into_the_robot_frame_by_the_tracker_s_motion() {
        let f = field();
        let mut r = Relocalizer::new(&f);
        // It sees the east net 4 m straight ahead, then turns 90° left and drives 1 m: the
        // tracker says it is at (0, 1) facing north.
        let mut sightings = [None; FIELD_OBJECTS];
        sightings[EAST_NET] = Some(Sighting { distance: 4.0, bearing: 0.0 });
        let p = perceptions(&f, NOISE, FrameSeen::of(&sightings));
        r.frame(0.0, p, Pose2::default());
        r.moved(Pose2::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        r.moved(Pose2::new(1.0, 0.0, 0.0));
        let w = r.window_now(0.5, Pose2::new(0.0, 1.0, std::f64::consts::FRAC_PI_2));
        // Now at (0, 1) facing north: the net is at (4, 0), i.e. 4.12 m at −104°.
        assert_eq!(w.len(), 1);
        assert!((w[0].range.unwrap_or(0.0) - 17f64.sqrt()).abs() < 1e-9);
        let expected = (-1f64).atan2(4.0) - std::f64::consts::FRAC_PI_2;
        assert!((w[0].bearing.unwrap_or(0.0) - expected).abs() < 1e-9);
        assert!((w[0].weight - 0.5).abs() < 1e-9, "half its weight after one half-life");
        assert!(w[0].range_tolerance > 0.43, "grown by the drive: {}", w[0].range_tolerance);
        assert_eq!(WEST_NET, 2);
    }

    /// The gaze test's robot (a defect once): a far post seen twice, 11.5 m and 10.3 m
    /// away (3σ each is about 1 m), was two posts that no pose explained together, and a
    /// search put the robot 1.7 m from where it stood.
    #[test]
    fn a_far_post_seen_twice_is_one_post_at_the_mean_of_its_sightings() {
        let f = field();
        let mut r = Relocalizer::new(&f);
        let post = |distance: f64| PostSighting {
            sighting: Sighting { distance, bearing: -0.58 },
            sigma: (0.0, 0.0),
            east: true,
            pixels: 10,
        };
        let none = [None; FIELD_OBJECTS];
        for (t, d) in [(0.0, 11.5), (0.1, 10.3)] {
            let p = perceptions(&f, NOISE, FrameSeen { posts: &[post(d)], ..FrameSeen::of(&none) });
            r.frame(t, p, Pose2::default());
        }
        let w = r.window_now(0.1, Pose2::default());
        assert_eq!(w.len(), 1, "{w:?}");
        let weights = [0.5f64.powf(0.1 / HALF_LIFE), 1.0];
        let mean = (11.5 * weights[0] + 10.3 * weights[1]) / (weights[0] + weights[1]);
        assert!((w[0].range.unwrap_or(0.0) - mean).abs() < 1e-9, "{w:?}");
        assert!((w[0].bearing.unwrap_or(0.0) + 0.58).abs() < 1e-9);
        // Two posts of one pattern 3 m apart stay two.
        let mut r = Relocalizer::new(&f);
        let p = perceptions(
            &f,
            NOISE,
            FrameSeen { posts: &[post(4.0), post(7.0)], ..FrameSeen::of(&none) },
        );
        r.frame(0.0, p, Pose2::default());
        assert_eq!(r.window_now(0.0, Pose2::default()).len(), 2);
    }
}
