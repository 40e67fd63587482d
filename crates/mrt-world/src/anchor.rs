//! MAP's anchors of the other robots (MRT manual ch. 8; TeamChaos' perceptual anchoring,
//! ThinkingCap/TeamChaos report §2.1): every robot the camera sees becomes an anchor, a symbol
//! with an identity that lasts, whose place and velocity a Kalman [`Track`] estimates.
//!
//! Each frame, in MAP's three steps:
//! 1. **Classification.** A robot percept is a Robot; the colour of its marker band, when the
//!    camera saw it, makes it a Teammate or an Opponent ([`Anchor::class`]: the marker its
//!    recent sightings show, against the team's own colour). Partial information stays
//!    generic: a robot whose marker was never seen stays a Robot (the team side may still make
//!    it a Teammate: `team::merge_team`, when a teammate reports being there).
//! 2. **Data association** (global nearest neighbour): the squared Mahalanobis distance of
//!    every percept from every anchor's prediction, gated at χ²₂ 99 % ([`GATE`]), and the
//!    assignment of least total distance (Kuhn–Munkres, `pathfinding`), so two robots that
//!    cross keep their identities; a percept whose marker contradicts an anchor's is never
//!    that anchor (two robots of different teams in a scrum do not swap).
//! 3. **Tracking.** A matched anchor's track is corrected. An unmatched one is predicted and
//!    its reliability fades, halving every second unseen ([`FADE`]); below [`FORGET`] it is
//!    forgotten, but for [`REACQUIRE_FOR`] seconds a percept within a wider gate
//!    ([`REACQUIRE_GATE`]) takes it back, identity and all, before a new anchor is made.
//!
//! MAP's merger takes the sonars too ([`Anchors::observe`]): an echo keeps an anchor the
//! camera does not see in track for [`ECHO_KEEP`], never makes one.
//!
//! The anchoring phases: an anchor is in **find** until it has been seen [`CONFIRM`] times
//! (one stray percept makes no robot), in **track** while seen, in **reacquire** while
//! predicted unseen ([`Phase`]).
//!
//! ```
//! use mrt_world::anchor::{Anchors, Phase, RobotPercept};
//! use mrt_msgs::Marker;
//! use nalgebra::Matrix2;
//! let mut anchors = Anchors::default();
//! let r = Matrix2::from_diagonal_element(0.05 * 0.05);
//! // A robot walking east at 1 m/s, seen every 0.1 s with its cyan marker.
//! for k in 0..10 {
//!     let t = 0.1 * f64::from(k);
//!     anchors.update(t, &[RobotPercept { at: (t, 2.0), r, marker: Some(Marker::Cyan) }]);
//! }
//! let a = &anchors.anchors()[0];
//! assert_eq!(a.phase(0.9), Phase::Track);
//! assert_eq!(a.class(Some(Marker::Magenta)), mrt_msgs::RobotClass::Opponent);
//! assert!((a.velocity().0 - 1.0).abs() < 0.2);
//! ```

use crate::track::{squared_distance, Track, GATE};
use mrt_msgs::{Marker, RobotClass};
use nalgebra::Matrix2;
use pathfinding::kuhn_munkres::kuhn_munkres_min;
use pathfinding::matrix::Matrix;

/// Random acceleration of a robot, m/s² (~1 m/s², a design choice).
pub const ROBOT_ACCEL: f64 = 1.0;
/// An unseen robot's predicted velocity fades at this rate, 1/s: robots stop and turn, and a
/// constant-velocity prediction over seconds would carry the anchor far from any robot.
pub const ROBOT_DAMPING: f64 = 0.5;
/// An unseen anchor's reliability is multiplied by this every second (a design choice).
pub const FADE: f64 = 0.5;
/// An anchor's reliability is multiplied by this every second the camera looks where it is
/// predicted and does not see it (a design choice: fading faster when the object should
/// have been visible): a robot gone from in front of the camera is forgotten within a second
/// instead of three.
pub const MISSED: f64 = 0.05;
/// Below this reliability an anchor is forgotten (≈ 3.3 s unseen).
pub const FORGET: f64 = 0.1;
/// Sightings an anchor needs before it leaves the find phase.
pub const CONFIRM: u32 = 2;
/// Seconds after the camera last saw an anchor during which sonar echoes may keep it in
/// track.
pub const ECHO_KEEP: f64 = 2.0;
/// Seconds a forgotten anchor may still be reacquired.
pub const REACQUIRE_FOR: f64 = 3.0;
/// The gate (squared Mahalanobis distance) within which a forgotten anchor is reacquired:
/// wider than [`GATE`], since its prediction is old.
pub const REACQUIRE_GATE: f64 = 4.0 * GATE;

/// Each sighting of a marker keeps this much of the marker evidence gathered before it.
pub const MARKER_MEMORY: f64 = 0.7;
/// Marker evidence (about two sightings) past which a percept of the other colour is another
/// robot, not this one.
pub const SETTLED: f64 = 1.5;

/// A track's predicted place and its covariance ([`Track::predicted_place`]).
type Predicted = ((f64, f64), Matrix2<f64>);

/// The cost the assignment gives a pair outside the gate: more than any number of pairs
/// inside it, so it is used only where no gated pair is left (and then dropped).
const FORBIDDEN: i64 = 1 << 40;
/// Gated squared distances are compared in these units (the assignment takes integers).
const COST_SCALE: f64 = 1e6;

/// One robot percept, in the field frame: its centre (m), the covariance of that place (m²)
/// and the marker colour seen on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotPercept {
    /// The robot's centre, m.
    pub at: (f64, f64),
    /// Covariance of `at`, m².
    pub r: Matrix2<f64>,
    /// The marker's colour, if the camera saw it.
    pub marker: Option<Marker>,
}

/// An anchor's phase in the anchoring process (ThinkingCap/TeamChaos report §2.1; anchoring's
/// usual three phases: find, track, reacquire).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// New: seen fewer than [`CONFIRM`] times.
    Find,
    /// Seen in the last frame.
    Track,
    /// Unseen since, predicted, fading, waiting to be seen again.
    Reacquire,
}

/// One anchored robot (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Anchor {
    id: u32,
    track: Track,
    hits: u32,
    last_seen: f64,
    /// When the camera (not a sonar) last saw it, s.
    last_camera: f64,
    /// Its reliability at `faded`, s: it fades from there at [`FADE`] a second.
    reliability: f64,
    faded: f64,
    /// Evidence of its marker being magenta and cyan: each sighting of a marker multiplies
    /// both by [`MARKER_MEMORY`] and adds 1 to its colour's (recent sightings count most).
    markers: (f64, f64),
}

impl Anchor {
    fn new(id: u32, time: f64, p: &RobotPercept) -> Anchor {
        let mut a = Anchor {
            id,
            track: Track::new(ROBOT_DAMPING, ROBOT_ACCEL),
            hits: 0,
            last_seen: time,
            last_camera: time,
            reliability: 1.0,
            faded: time,
            markers: (0.0, 0.0),
        };
        a.see(time, p);
        a
    }

    /// Its identity.
    pub fn id(&self) -> u32 {
        self.id
    }

    /// Where it is at `time`, m (field frame): the track's prediction.
    pub fn position(&self, time: f64) -> (f64, f64) {
        self.track.predicted(time).map_or(self.track.position(), |(x, y, _, _)| (x, y))
    }

    /// Its velocity at its last sighting, m/s.
    pub fn velocity(&self) -> (f64, f64) {
        self.track.velocity()
    }

    /// One standard deviation of its place at `time`, m.
    pub fn sigma(&self, time: f64) -> f64 {
        self.track.sigma(time).unwrap_or(f64::INFINITY)
    }

    /// How much it is to be trusted at `time`: 1 when seen then, [`FADE`] per second unseen
    /// ([`MISSED`] per second while it should have been in view and was not).
    pub fn reliability(&self, time: f64) -> f64 {
        self.reliability * FADE.powf((time - self.faded).max(0.0))
    }

    /// Fades it to `time`, at [`MISSED`] a second if the camera should have seen it.
    fn fade(&mut self, time: f64, in_view: bool) {
        let dt = (time - self.faded).max(0.0);
        self.reliability *= if in_view { MISSED } else { FADE }.powf(dt);
        self.faded = self.faded.max(time);
    }

    /// When it was last seen, s.
    pub fn last_seen(&self) -> f64 {
        self.last_seen
    }

    /// Its phase at `time`.
    pub fn phase(&self, time: f64) -> Phase {
        if self.hits < CONFIRM {
            Phase::Find
        } else if time <= self.last_seen {
            Phase::Track
        } else {
            Phase::Reacquire
        }
    }

    /// The marker colour its sightings show: the one with more evidence, when that is at
    /// least half a sighting's and twice the other's.
    pub fn marker(&self) -> Option<Marker> {
        let (m, c) = self.markers;
        if m >= 0.5 && m >= 2.0 * c {
            Some(Marker::Magenta)
        } else if c >= 0.5 && c >= 2.0 * m {
            Some(Marker::Cyan)
        } else {
            None
        }
    }

    /// Teammate or opponent by its [`marker`](Self::marker) against the team's own colour
    /// `own`; a Robot while its marker is unclear or `own` unknown.
    pub fn class(&self, own: Option<Marker>) -> RobotClass {
        match (own, self.marker()) {
            (Some(own), Some(seen)) if own == seen => RobotClass::Teammate,
            (Some(_), Some(_)) => RobotClass::Opponent,
            _ => RobotClass::Robot,
        }
    }

    /// Whether a percept may be this robot: not when it shows the other marker than this
    /// anchor's settled one ([`SETTLED`]; MAP's merging keeps concepts on one path of the hierarchy: a cyan robot is
    /// never a magenta one's next sighting, however near).
    fn admits(&self, p: &RobotPercept) -> bool {
        let (m, c) = self.markers;
        match p.marker {
            Some(Marker::Magenta) => !(c >= SETTLED && c >= 2.0 * m),
            Some(Marker::Cyan) => !(m >= SETTLED && m >= 2.0 * c),
            None => true,
        }
    }

    fn see(&mut self, time: f64, p: &RobotPercept) {
        if !self.track.update(time, p.at, p.r) {
            // Refused by the track's own gate (a reacquisition far from the old prediction):
            // the track starts again where the robot is, the identity stays.
            self.track.reset();
            self.track.update(time, p.at, p.r);
        }
        self.hits = self.hits.saturating_add(1);
        self.last_seen = time;
        self.reliability = 1.0;
        self.faded = time;
        let (m, c) = self.markers;
        match p.marker {
            Some(Marker::Magenta) => self.markers = (m * MARKER_MEMORY + 1.0, c * MARKER_MEMORY),
            Some(Marker::Cyan) => self.markers = (m * MARKER_MEMORY, c * MARKER_MEMORY + 1.0),
            // A sighting without a marker (too near, too far, hidden) changes nothing.
            None => {}
        }
    }
}

/// What the anchoring did so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AnchorCounts {
    /// Percepts that corrected an anchor.
    pub updates: u64,
    /// Anchors made.
    pub created: u64,
    /// Forgotten anchors taken back.
    pub reacquired: u64,
    /// Anchors forgotten.
    pub forgotten: u64,
    /// Percepts refused (not numbers).
    pub refused: u64,
    /// Sonar echoes that kept an anchor the camera did not see in track.
    pub echoes: u64,
}

/// The anchored robots (module doc).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Anchors {
    live: Vec<Anchor>,
    /// Forgotten anchors, with when they were forgotten, for reacquisition.
    forgotten: Vec<(f64, Anchor)>,
    next_id: u32,
    counts: AnchorCounts,
}

impl Anchors {
    /// The live anchors (in every phase).
    pub fn anchors(&self) -> &[Anchor] {
        &self.live
    }

    /// What it did so far.
    pub fn counts(&self) -> AnchorCounts {
        self.counts
    }

    /// Forgets every anchor (the robot's own pose jumped: the anchors' places were computed
    /// from the pose it had). Identities are not reused.
    pub fn reset(&mut self) {
        self.live.clear();
        self.forgotten.clear();
    }

    /// One frame's robot percepts at `time` (module doc). Frames must come in time order; a
    /// percept that is not a number, or whose covariance has a negative variance, is refused
    /// and counted.
    pub fn update(&mut self, time: f64, percepts: &[RobotPercept]) {
        self.observe(time, percepts, &[], |_| false);
    }

    /// [`update`](Self::update) with sonar `echoes` as well (MAP's merger, MRT manual ch. 8:
    /// percepts of several sensors): after the camera's percepts are associated, the echoes
    /// are associated with every anchor; one that falls to an anchor no percept took keeps it
    /// in track (a robot beside or behind the robot, out of the camera's view) for
    /// [`ECHO_KEEP`] after the camera last saw it. An echo never makes an anchor nor takes a
    /// forgotten one back: a sonar cannot tell a robot from a wall or a goal post.
    ///
    /// `in_view` says whether the camera looked at a place (field frame, m) this frame: an
    /// anchor predicted there and not seen fades at [`MISSED`] a second instead of [`FADE`].
    pub fn observe(
        &mut self,
        time: f64,
        percepts: &[RobotPercept],
        echoes: &[RobotPercept],
        in_view: impl Fn((f64, f64)) -> bool,
    ) {
        let given = percepts.len() + echoes.len();
        if !time.is_finite() {
            self.counts.refused += given as u64;
            return;
        }
        let sane = |p: &&RobotPercept| {
            p.at.0.is_finite()
                && p.at.1.is_finite()
                && p.r.iter().all(|v| v.is_finite())
                && p.r[(0, 0)] >= 0.0
                && p.r[(1, 1)] >= 0.0
        };
        let percepts: Vec<&RobotPercept> = percepts.iter().filter(sane).collect();
        let echoes: Vec<&RobotPercept> = echoes.iter().filter(sane).collect();
        self.counts.refused += (given - percepts.len() - echoes.len()) as u64;
        // Each anchor's prediction once a frame: a pair then costs a 2 × 2 inverse.
        let predicted: Vec<Option<Predicted>> =
            self.live.iter().map(|a| a.track.predicted_place(time)).collect();
        let anchors: Vec<(&Anchor, Option<Predicted>)> =
            self.live.iter().zip(predicted.iter().copied()).collect();
        let distance = |(a, pred): &(&Anchor, Option<Predicted>), p: &RobotPercept| {
            squared_distance(pred.filter(|_| a.admits(p))?, p.at, p.r)
        };
        let used = assign(&anchors, &percepts, distance, GATE);
        // The echoes, against every anchor: one that falls to an anchor the camera saw is
        // that robot's and is spent; one that falls to an unseen anchor keeps it in track.
        // (Offered to the unseen alone, a seen robot's echo would keep a stale anchor beside
        // it alive.) An echo within the gate of two anchors (a scrum) could be either
        // robot's: it is left out, or it would hand an anchor from one robot to its
        // neighbour.
        let echoes: Vec<&RobotPercept> = echoes
            .into_iter()
            .filter(|e| {
                let near = |a: &&(&Anchor, Option<Predicted>)| {
                    distance(a, e).is_some_and(|d| (0.0..=GATE).contains(&d))
                };
                anchors.iter().filter(near).count() <= 1
            })
            .collect();
        let heard = assign(&anchors, &echoes, distance, GATE);
        drop(anchors);
        let mut taken = vec![false; percepts.len()];
        for ((a, j), echo) in self.live.iter_mut().zip(&used).zip(heard) {
            if let Some(j) = *j {
                a.see(time, percepts[j]);
                a.last_camera = time;
                taken[j] = true;
                self.counts.updates += 1;
            } else if let Some(e) = echo {
                // An echo keeps an anchor only for ECHO_KEEP after the camera last saw it: a
                // sonar cannot tell whose echo it is, and a stale anchor's wide prediction
                // would catch stray echoes for ever.
                if time - a.last_camera <= ECHO_KEEP {
                    a.see(time, echoes[e]);
                    self.counts.echoes += 1;
                }
            }
        }
        // The unseen fade, faster where the camera looked; the faded are forgotten (kept a
        // while for reacquisition).
        // (Their predictions are this frame's, made before the updates that passed them by.)
        for (a, pred) in self.live.iter_mut().zip(&predicted).filter(|(a, _)| a.last_seen < time) {
            a.fade(time, pred.is_some_and(|(at, _)| in_view(at)));
        }
        let (keep, gone): (Vec<Anchor>, Vec<Anchor>) =
            self.live.drain(..).partition(|a| a.reliability(time) >= FORGET);
        self.live = keep;
        self.counts.forgotten += gone.len() as u64;
        self.forgotten.extend(gone.into_iter().map(|a| (time, a)));
        self.forgotten.retain(|(when, _)| time - when <= REACQUIRE_FOR);
        // The percepts no live anchor took: a forgotten anchor within the wider gate, or a
        // new anchor.
        let left: Vec<&RobotPercept> =
            percepts.iter().zip(&taken).filter(|(_, t)| !**t).map(|(p, _)| *p).collect();
        let old: Vec<(&Anchor, Option<Predicted>)> =
            self.forgotten.iter().map(|(_, a)| (a, a.track.predicted_place(time))).collect();
        let back = assign(&old, &left, distance, REACQUIRE_GATE);
        let mut revived = vec![false; left.len()];
        // Taken out of the forgotten list highest index first, so the others stay put.
        for (k, j) in back.iter().enumerate().rev() {
            let Some(j) = *j else { continue };
            revived[j] = true;
            let (_, mut a) = self.forgotten.remove(k);
            a.see(time, left[j]);
            self.live.push(a);
            self.counts.reacquired += 1;
        }
        for (p, _) in left.iter().zip(&revived).filter(|(_, r)| !**r) {
            let id = self.next_id;
            self.next_id = self.next_id.wrapping_add(1);
            self.live.push(Anchor::new(id, time, p));
            self.counts.created += 1;
        }
        self.live.sort_by_key(|a| a.id);
    }
}

/// The global-nearest-neighbour assignment of `percepts` to `anchors`: for each anchor the
/// percept it takes, if any, such that every pair's `distance` is within `gate` and the sum of
/// the pairs' distances is least among the assignments that pair the most. Kuhn–Munkres
/// runs only when some percept or anchor has two candidates within the gate.
fn assign<A, P>(
    anchors: &[A],
    percepts: &[&P],
    distance: impl Fn(&A, &P) -> Option<f64>,
    gate: f64,
) -> Vec<Option<usize>> {
    let (n, m) = (anchors.len(), percepts.len());
    let mut out = vec![None; n];
    if n == 0 || m == 0 {
        return out;
    }
    // Every pair's cost once, anchor by anchor.
    let costs: Vec<i64> = (0..n)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| match distance(&anchors[i], percepts[j]) {
            // A negative distance comes only from a covariance that is not one: never a pair.
            Some(d2) if (0.0..=gate).contains(&d2) => (d2 * COST_SCALE).round() as i64,
            _ => FORBIDDEN,
        })
        .collect();
    let cost = |i: usize, j: usize| costs[i * m + j];
    // The usual frame: every percept within the gate of at most one anchor and every anchor
    // of at most one percept. Then the pairs are the assignment, with no search.
    let gated = |i: usize, j: usize| cost(i, j) < FORBIDDEN;
    let lone_rows = (0..n).all(|i| (0..m).filter(|&j| gated(i, j)).count() <= 1);
    let lone_cols = (0..m).all(|j| (0..n).filter(|&i| gated(i, j)).count() <= 1);
    if lone_rows && lone_cols {
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = (0..m).find(|&j| gated(i, j));
        }
        return out;
    }
    // Kuhn–Munkres wants no more rows than columns: rows are the smaller side.
    let by_anchor = n <= m;
    let (rows, cols) = if by_anchor { (n, m) } else { (m, n) };
    let values: Vec<i64> = (0..rows)
        .flat_map(|r| (0..cols).map(move |c| (r, c)))
        .map(|(r, c)| if by_anchor { cost(r, c) } else { cost(c, r) })
        .collect();
    let Ok(weights) = Matrix::from_vec(rows, cols, values) else {
        return out;
    };
    let (_, assignment) = kuhn_munkres_min(&weights);
    for (r, &c) in assignment.iter().enumerate() {
        if weights[(r, c)] >= FORBIDDEN {
            continue;
        }
        let (i, j) = if by_anchor { (r, c) } else { (c, r) };
        out[i] = Some(j);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(sigma: f64) -> Matrix2<f64> {
        Matrix2::from_diagonal_element(sigma * sigma)
    }

    fn percept(x: f64, y: f64, marker: Option<Marker>) -> RobotPercept {
        RobotPercept { at: (x, y), r: r(0.05), marker }
    }

    #[test]
    fn two_robots_crossing_keep_their_identities() {
        // Robot A walks east along y = 0.1, robot B west along y = −0.1, 1 m/s each: they
        // meet at x = 0 at t = 1 s and pass within 0.2 m of each other. Percepts come in
        // an order that alternates, so the order cannot tell them apart.
        let mut anchors = Anchors::default();
        let mut ids = None;
        for k in 0..=20 {
            let t = 0.1 * f64::from(k);
            let a = percept(-1.0 + t, 0.1, None);
            let b = percept(1.0 - t, -0.1, None);
            let frame = if k % 2 == 0 { [a, b] } else { [b, a] };
            anchors.update(t, &frame);
            let live = anchors.anchors();
            assert_eq!(live.len(), 2, "t = {t}");
            // Which anchor is the eastbound one: the one whose velocity points east.
            let east = live.iter().find(|x| x.velocity().0 > 0.0 || x.hits < 3).map(|x| x.id);
            if k == 5 {
                ids = east;
            }
            if k > 5 {
                assert_eq!(east, ids, "t = {t}");
            }
        }
        // At the end the eastbound anchor is at x = 1, the westbound at x = −1.
        let live = anchors.anchors();
        let a = live.iter().find(|x| Some(x.id) == ids).unwrap();
        assert!((a.position(2.0).0 - 1.0).abs() < 0.1, "{:?}", a.position(2.0));
        assert!((a.velocity().0 - 1.0).abs() < 0.25, "{:?}", a.velocity());
        assert_eq!(anchors.counts().created, 2);
    }

    #[test]
    fn an_anchor_is_found_tracked_kept_while_hidden_and_forgotten_when_long_gone() {
        let mut anchors = Anchors::default();
        anchors.update(0.0, &[percept(2.0, 1.0, None)]);
        assert_eq!(anchors.anchors()[0].phase(0.0), Phase::Find, "one percept is no robot");
        anchors.update(0.1, &[percept(2.0, 1.0, None)]);
        assert_eq!(anchors.anchors()[0].phase(0.1), Phase::Track);
        // Hidden for 2 s: kept, predicted, reliability 0.5² = 0.25.
        anchors.update(2.1, &[]);
        let a = &anchors.anchors()[0];
        assert_eq!(a.phase(2.1), Phase::Reacquire);
        assert!((a.reliability(2.1) - 0.25).abs() < 1e-12);
        // Seen again where it was: the same anchor.
        anchors.update(2.2, &[percept(2.05, 1.0, None)]);
        assert_eq!(anchors.anchors().len(), 1);
        assert_eq!(anchors.anchors()[0].id(), 0);
        // Hidden 3.4 s: 0.5^3.4 < 0.1, forgotten.
        anchors.update(5.6, &[]);
        assert!(anchors.anchors().is_empty());
        assert_eq!(anchors.counts().forgotten, 1);
        // Seen 0.5 m away 1 s later: reacquired within the wider gate, identity kept.
        anchors.update(6.6, &[percept(2.5, 1.0, None)]);
        assert_eq!(anchors.anchors()[0].id(), 0);
        assert_eq!(anchors.counts().reacquired, 1);
        // Much later, elsewhere: a new anchor.
        anchors.update(20.0, &[]);
        anchors.update(30.0, &[percept(-3.0, 0.0, None)]);
        assert_eq!(anchors.anchors()[0].id(), 1);
    }

    /// MAP's merger with the sonars: an echo keeps a robot the camera lost sight of in track,
    /// but never makes an anchor, and the camera's percept wins where both see one.
    #[test]
    fn sonar_echoes_keep_unseen_anchors_in_track_and_make_none() {
        let mut anchors = Anchors::default();
        let echo = |x: f64, y: f64| RobotPercept { at: (x, y), r: r(0.1), marker: None };
        // An echo alone: nothing.
        anchors.observe(0.0, &[], &[echo(1.0, 1.0)], |_| false);
        assert!(anchors.anchors().is_empty());
        // Seen by the camera twice, walking east at 0.5 m/s with its cyan marker.
        anchors.observe(0.1, &[percept(1.0, 1.0, Some(Marker::Cyan))], &[], |_| false);
        anchors.observe(0.2, &[percept(1.05, 1.0, Some(Marker::Cyan))], &[], |_| false);
        // Out of the camera's view for 2 s, heard by the sonars all along: still tracked,
        // fully reliable, where the echoes put it, its team kept.
        for k in 1..=20 {
            let t = 0.2 + 0.1 * f64::from(k);
            anchors.observe(t, &[], &[echo(1.05 + 0.05 * f64::from(k), 1.0)], |_| false);
        }
        let a = &anchors.anchors()[0];
        assert_eq!((anchors.anchors().len(), a.phase(2.2)), (1, Phase::Track));
        assert_eq!(a.reliability(2.2), 1.0);
        assert!((a.position(2.2).0 - 2.05).abs() < 0.1, "{:?}", a.position(2.2));
        assert_eq!(a.marker(), Some(Marker::Cyan));
        assert_eq!(anchors.counts().echoes, 20);
        // The camera and the sonar both: the camera's percept is used, the echo left over.
        anchors.observe(2.3, &[percept(2.1, 1.0, None)], &[echo(2.1, 1.05)], |_| false);
        assert_eq!(anchors.counts().echoes, 20);
        assert_eq!(anchors.anchors().len(), 1);
    }

    /// Fading faster when the object should have been visible: where the camera looks and
    /// does not see an anchor, it fades at MISSED a second; elsewhere at FADE.
    #[test]
    fn an_anchor_the_camera_should_see_and_does_not_fades_fast() {
        let mut anchors = Anchors::default();
        anchors.update(0.0, &[percept(1.0, 0.0, None), percept(-1.0, 0.0, None)]);
        anchors.update(0.1, &[percept(1.0, 0.0, None), percept(-1.0, 0.0, None)]);
        // The camera looks east (x > 0): the eastern robot has gone, the western one is
        // behind the camera.
        let east = |(x, _): (f64, f64)| x > 0.0;
        for k in 2..=6 {
            anchors.observe(0.1 * f64::from(k), &[], &[], east);
        }
        let r: Vec<f64> = anchors.anchors().iter().map(|a| a.reliability(0.6)).collect();
        assert!((r[0] - MISSED.powf(0.5)).abs() < 1e-9, "{r:?}");
        assert!((r[1] - FADE.powf(0.5)).abs() < 1e-9, "{r:?}");
        // 0.05^0.8 < 0.1: the eastern one is forgotten after 0.8 s, the western one kept.
        for k in 7..=9 {
            anchors.observe(0.1 * f64::from(k), &[], &[], east);
        }
        assert_eq!(anchors.anchors().len(), 1);
        assert_eq!(anchors.anchors()[0].position(0.9).0, -1.0);
        // Seen again: fully reliable, fading from there.
        anchors.update(1.0, &[percept(-1.0, 0.0, None)]);
        assert_eq!(anchors.anchors()[0].reliability(1.0), 1.0);
        assert!((anchors.anchors()[0].reliability(2.0) - FADE).abs() < 1e-12);
    }

    #[test]
    fn the_marker_makes_a_robot_a_teammate_or_an_opponent() {
        let mut anchors = Anchors::default();
        // Seen twice without its marker: a Robot, whatever our colour.
        anchors.update(0.0, &[percept(1.0, 1.0, None)]);
        anchors.update(0.1, &[percept(1.0, 1.0, None)]);
        let a = &anchors.anchors()[0];
        assert_eq!(a.class(Some(Marker::Magenta)), RobotClass::Robot);
        // Then its cyan marker, twice: an opponent of the magenta team, a teammate of the cyan.
        anchors.update(0.2, &[percept(1.0, 1.0, Some(Marker::Cyan))]);
        anchors.update(0.25, &[percept(1.0, 1.0, Some(Marker::Cyan))]);
        let a = &anchors.anchors()[0];
        assert_eq!(a.class(Some(Marker::Magenta)), RobotClass::Opponent);
        assert_eq!(a.class(Some(Marker::Cyan)), RobotClass::Teammate);
        assert_eq!(a.class(None), RobotClass::Robot, "our colour unknown");
        // A magenta robot where the cyan one is: another robot (a scrum), not the same one
        // misread: a new anchor, and the cyan one stays an opponent.
        anchors.update(0.3, &[percept(1.0, 1.0, Some(Marker::Magenta))]);
        let live = anchors.anchors();
        assert_eq!(live.len(), 2);
        assert_eq!(live[0].class(Some(Marker::Magenta)), RobotClass::Opponent);
        assert_eq!((live[1].marker(), live[1].phase(0.3)), (Some(Marker::Magenta), Phase::Find));
        // Before a marker is settled, mixed evidence leaves it unknown: cyan then magenta
        // (0.7 against 1: not twice), then magenta again settles it (0.49 against 1.7).
        let mut fresh = Anchors::default();
        fresh.update(0.0, &[percept(1.0, 1.0, Some(Marker::Cyan))]);
        fresh.update(0.1, &[percept(1.0, 1.0, Some(Marker::Magenta))]);
        assert_eq!(fresh.anchors().len(), 1);
        assert_eq!(fresh.anchors()[0].marker(), None);
        fresh.update(0.2, &[percept(1.0, 1.0, Some(Marker::Magenta))]);
        assert_eq!(fresh.anchors()[0].marker(), Some(Marker::Magenta));
        // Sightings without a marker keep it.
        fresh.update(0.3, &[percept(1.0, 1.0, None)]);
        assert_eq!(fresh.anchors()[0].marker(), Some(Marker::Magenta));
    }

    #[test]
    fn a_percept_that_is_not_a_number_is_refused() {
        let mut anchors = Anchors::default();
        anchors.update(0.0, &[percept(f64::NAN, 0.0, None), percept(1.0, 0.0, None)]);
        assert_eq!(anchors.anchors().len(), 1);
        assert_eq!((anchors.counts().created, anchors.counts().refused), (1, 1));
        anchors.update(f64::INFINITY, &[percept(1.0, 0.0, None)]);
        assert_eq!(anchors.counts().refused, 2);
        let negative =
            RobotPercept { r: Matrix2::new(-1.0, 0.0, 0.0, 1.0), ..percept(1.0, 0.0, None) };
        anchors.update(0.1, &[negative]);
        assert_eq!(anchors.counts().refused, 3);
    }

    #[test]
    fn the_assignment_is_the_least_total_distance_not_the_greedy_one() {
        // Anchors at 0 and 1 (on a line), percepts at 0.6 and 1.7, distance = gap²: greedy
        // takes the nearest pair first (anchor 1 ↔ 0.6, 0.16) and leaves anchor 0 with 1.7
        // (2.89, gated out at 1.0); the optimal assignment pairs 0 ↔ 0.6 (0.36) and 1 ↔ 1.7
        // (0.49).
        let anchors = [0.0, 1.0];
        let percepts = [0.6, 1.7];
        let refs: Vec<&f64> = percepts.iter().collect();
        let out = assign(&anchors, &refs, |a, p| Some((a - *p).powi(2)), 1.0);
        assert_eq!(out, [Some(0), Some(1)]);
        // More percepts than anchors, and the other way round.
        let three = [0.1, 5.0, 0.9];
        let refs: Vec<&f64> = three.iter().collect();
        assert_eq!(assign(&anchors, &refs, |a, p| Some((a - *p).powi(2)), 1.0), [Some(0), Some(2)]);
        let one = [0.95];
        let refs: Vec<&f64> = one.iter().collect();
        assert_eq!(assign(&anchors, &refs, |a, p| Some((a - *p).powi(2)), 1.0), [None, Some(0)]);
        assert_eq!(assign(&anchors, &[], |a, p: &f64| Some((a - *p).powi(2)), 1.0), [None, None]);
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use proptest::prelude::*;

    fn any_percept() -> impl Strategy<Value = RobotPercept> {
        let coord = prop_oneof![-20.0..20.0f64, any::<f64>()];
        let var = prop_oneof![1e-6..1.0f64, any::<f64>()];
        let marker = prop_oneof![Just(None), Just(Some(Marker::Magenta)), Just(Some(Marker::Cyan))];
        (coord.clone(), coord, var.clone(), var, marker).prop_map(|(x, y, a, b, marker)| {
            RobotPercept { at: (x, y), r: Matrix2::new(a, 0.0, 0.0, b), marker }
        })
    }

    proptest! {
        /// Percepts of any numbers (a camera frame from the network) never panic the
        /// anchoring, and every live anchor stays a finite place with a reliability in
        /// [0, 1]; identities are never shared.
        #[test]
        fn any_percepts_leave_the_anchors_sane(
            frames in proptest::collection::vec(
                (0.0..0.5f64, proptest::collection::vec(any_percept(), 0..10)),
                1..12,
            )
        ) {
            let mut anchors = Anchors::default();
            let mut time = 0.0;
            for (dt, percepts) in frames {
                time += dt;
                anchors.update(time, &percepts);
                let mut ids: Vec<u32> = anchors.anchors().iter().map(Anchor::id).collect();
                ids.sort_unstable();
                ids.dedup();
                prop_assert_eq!(ids.len(), anchors.anchors().len());
                for a in anchors.anchors() {
                    let (x, y) = a.position(time);
                    prop_assert!(x.is_finite() && y.is_finite(), "{:?}", a);
                    let r = a.reliability(time);
                    prop_assert!((0.0..=1.0).contains(&r));
                }
            }
        }
    }
}
