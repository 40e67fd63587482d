//! The PAM's camera control (ThinkingCap/TeamChaos report §2.1, after Saffiotti & LeBlanc 2000):
//! the behaviors state *perceptual needs*, one necessity in [0, 1] per LPS object
//! (`chaos.setNeeded`, Mr. BRIAN's `need` rules), and each cycle [`Gaze`] picks the object to
//! look at and turns the camera's pan joint towards it.
//!
//! - **Which object** (the seed's rule): the one with the highest need; when two or more share
//!   it, the one *least recently seen* (an object never seen comes first). Two objects needed
//!   alike are therefore looked at in turn, each as the other's anchor grows older.
//! - **Holding a fixation**: once the fixated object is in view, the gaze stays on it for
//!   [`GazeConfig::dwell`] seconds so that its anchor is confirmed by a few frames, and only
//!   then chooses again (without this the choice would flip on the first frame, and the joint
//!   would spend its time turning).
//! - **Where to turn**: to the anchor's bearing in the LPS, clamped to the joint's range. An
//!   object whose anchor is lost (reliability 0), or that is not in view `dwell` seconds after
//!   the joint reached its bearing, is *searched*: the joint sweeps from one end of its range
//!   to the other.
//! - **How fast**: never faster than the joint's [`PanJoint::max_speed`].
//!
//! Whatever else comes into view meanwhile is anchored as usual (the world model reads every
//! percept of every frame); gaze only chooses where the camera points. Angles are in the
//! robot's frame (rad, counter-clockwise positive, 0 straight ahead), times in seconds.
//!
//! ```
//! use mrt_msgs::robot::{lps, Lpo};
//! use mrt_world::gaze::{Gaze, GazeConfig, PanJoint};
//!
//! let joint = PanJoint { min: -1.5, max: 1.5, max_speed: 2.0 };
//! let mut gaze = Gaze::new(GazeConfig { joint, half_fov: 0.4, dwell: 0.3 });
//! let mut lps_now = vec![Lpo::default(); lps::COUNT];
//! // The ball was seen 1 s ago, 0.8 rad to the left; the behaviors need it.
//! lps_now[lps::BALL] = Lpo { rho: 2.0, theta: 0.8, reliability: 0.5, seen_ago: 1.0 };
//! let aim = gaze.step(&[(lps::BALL, 1.0)], &lps_now, 0.1);
//! assert_eq!(aim.object, Some(lps::BALL));
//! assert!((aim.pan - 0.2).abs() < 1e-12, "2 rad/s for 0.1 s towards 0.8 rad");
//! ```

use mrt_msgs::robot::Lpo;

/// A pan joint: its range and its top speed (rad, rad/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanJoint {
    /// The rightmost pan, rad (negative: to the right).
    pub min: f64,
    /// The leftmost pan, rad.
    pub max: f64,
    /// Top turning speed, rad/s.
    pub max_speed: f64,
}

impl PanJoint {
    /// `pan` within the joint's range (a non-finite pan is the middle of the range).
    pub fn clamp(&self, pan: f64) -> f64 {
        if pan.is_finite() {
            pan.clamp(self.min, self.max)
        } else {
            0.5 * (self.min + self.max)
        }
    }

    /// Whether the range and speed make a joint: finite, `min ≤ max`, speed > 0.
    pub fn is_valid(&self) -> bool {
        self.min.is_finite()
            && self.max.is_finite()
            && self.min <= self.max
            && self.max_speed.is_finite()
            && self.max_speed > 0.0
    }
}

/// What [`Gaze`] needs to know about the camera and how long it holds a fixation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GazeConfig {
    /// The pan joint.
    pub joint: PanJoint,
    /// Half the camera's horizontal field of view, rad: an object is in view when its bearing
    /// is within this of the pan.
    pub half_fov: f64,
    /// How long a fixation is held once its object is in view, s.
    pub dwell: f64,
}

/// Where the gaze points this cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aim {
    /// The fixated LPS object (`None`: nothing is needed, the head returns to the middle).
    pub object: Option<usize>,
    /// The pan to command, rad (within the joint's range and speed from the last one).
    pub pan: f64,
    /// Whether the object is searched by sweeping rather than looked at where its anchor is.
    pub searching: bool,
}

/// The PAM's gaze control (module doc).
#[derive(Clone, Debug)]
pub struct Gaze {
    cfg: GazeConfig,
    /// The pan commanded last, rad.
    pan: f64,
    /// The fixated object.
    fixation: Option<usize>,
    /// Seconds the fixated object has been in view (held until [`GazeConfig::dwell`]).
    held: f64,
    /// Seconds the joint has rested on the fixated object's bearing without seeing it.
    waited: f64,
    /// Sweep direction while searching: +1 to the left, −1 to the right.
    sweep: f64,
}

impl Gaze {
    /// A gaze at rest in the middle of the joint's range, fixating nothing.
    pub fn new(cfg: GazeConfig) -> Gaze {
        let pan = cfg.joint.clamp(0.0);
        Gaze { cfg, pan, fixation: None, held: 0.0, waited: 0.0, sweep: 1.0 }
    }

    /// The pan commanded last, rad.
    pub fn pan(&self) -> f64 {
        self.pan
    }

    /// The fixated object.
    pub fn fixation(&self) -> Option<usize> {
        self.fixation
    }

    /// One cycle of `dt` seconds: the needs `(LPS index, necessity)` (an index may repeat:
    /// the largest counts, as the seed's max-combination of active behaviors), the LPS now,
    /// and the next pan. Indices outside the LPS and non-finite needs are ignored.
    pub fn step(&mut self, needs: &[(usize, f64)], lps: &[Lpo], dt: f64) -> Aim {
        let dt = if dt.is_finite() { dt.max(0.0) } else { 0.0 };
        // Keep a fixation whose object came into view until it has been held `dwell` s.
        let keep = self.fixation.is_some_and(|o| {
            self.in_view(lps, o) && self.held < self.cfg.dwell && need_of(needs, o) > 0.0
        });
        if !keep {
            let choice = choose(needs, lps);
            if choice != self.fixation {
                self.fixation = choice;
                self.held = 0.0;
                self.waited = 0.0;
            } else if choice.is_some_and(|o| self.in_view(lps, o)) {
                // Held long enough: look again at the needs (the same object may win again).
                self.held = 0.0;
            }
        }
        let Some(object) = self.fixation else {
            self.pan = self.turn_to(0.5 * (self.cfg.joint.min + self.cfg.joint.max), dt);
            return Aim { object: None, pan: self.pan, searching: false };
        };
        let anchor = lps[object];
        let in_view = self.in_view(lps, object);
        if in_view {
            self.held += dt;
            self.waited = 0.0;
        }
        let bearing = self.cfg.joint.clamp(anchor.theta);
        let lost = anchor.reliability <= 0.0 || !anchor.theta.is_finite();
        let arrived = (self.pan - bearing).abs() <= 1e-6;
        if arrived && !in_view {
            self.waited += dt;
        }
        let searching = lost || self.waited > self.cfg.dwell;
        self.pan = if searching { self.search(dt) } else { self.turn_to(bearing, dt) };
        Aim { object: Some(object), pan: self.pan, searching }
    }

    /// `trackLandMarks` (ThinkingCap/TeamChaos report §3 and §4: "sets necessities for the most relevant
    /// landmarks or nets"; `gktracklms` "selects the least recently seen landmark"): the need
    /// `(slot, need)` for the landmark of `slots` to look at next. That is the fixated one
    /// while it is held, else the least recently seen whose anchor is within the camera's
    /// reach (a landmark behind the robot cannot be seen), else, none being known, the first
    /// (never seen: searched). Push it onto the needs given to [`Gaze::step`].
    pub fn landmark_need(&self, slots: &[usize], need: f64, lps: &[Lpo]) -> Option<(usize, f64)> {
        let (j, h) = (self.cfg.joint, self.cfg.half_fov);
        let reachable = |&o: &usize| {
            lps.get(o).is_some_and(|l| {
                l.reliability > 0.0 && l.theta >= j.min - h && l.theta <= j.max + h
            })
        };
        let held = self.fixation.filter(|o| slots.contains(o) && reachable(o) && self.held > 0.0);
        let oldest = || {
            let by_age = |a: &usize, b: &usize| age(&lps[*a]).total_cmp(&age(&lps[*b]));
            slots.iter().copied().filter(reachable).max_by(by_age)
        };
        let slot = held.or_else(oldest).or_else(|| slots.first().copied())?;
        Some((slot, need))
    }

    /// Whether object `o` was seen this cycle where the camera points now.
    fn in_view(&self, lps: &[Lpo], o: usize) -> bool {
        lps.get(o).is_some_and(|l| seen_now(l) && (l.theta - self.pan).abs() <= self.cfg.half_fov)
    }

    /// The pan after turning towards `target` for `dt` at most at the joint's top speed.
    fn turn_to(&self, target: f64, dt: f64) -> f64 {
        let step = self.cfg.joint.max_speed * dt;
        self.cfg.joint.clamp(self.pan + (target - self.pan).clamp(-step, step))
    }

    /// One step of the sweep from one end of the range to the other.
    fn search(&mut self, dt: f64) -> f64 {
        let j = self.cfg.joint;
        let next = self.pan + self.sweep * j.max_speed * dt;
        if next >= j.max {
            self.sweep = -1.0;
        } else if next <= j.min {
            self.sweep = 1.0;
        }
        j.clamp(next)
    }
}

/// Whether an anchor was refreshed by this cycle's percepts.
fn seen_now(l: &Lpo) -> bool {
    l.reliability > 0.0 && l.seen_ago <= 0.0
}

/// The need of object `o`: the largest stated, 0 when none (a non-finite need counts as 0).
fn need_of(needs: &[(usize, f64)], o: usize) -> f64 {
    needs
        .iter()
        .filter(|&&(i, v)| i == o && v.is_finite())
        .map(|&(_, v)| v.clamp(0.0, 1.0))
        .fold(0.0, f64::max)
}

/// How long ago an anchor was seen (an object never seen or lost: forever).
fn age(l: &Lpo) -> f64 {
    if l.reliability > 0.0 && l.seen_ago.is_finite() {
        l.seen_ago
    } else {
        f64::INFINITY
    }
}

/// The seed's choice: the highest need, ties to the least recently seen, then to the lowest
/// index (so that the choice is deterministic).
fn choose(needs: &[(usize, f64)], lps: &[Lpo]) -> Option<usize> {
    let mut best: Option<(usize, f64, f64)> = None;
    for (o, anchor) in lps.iter().enumerate() {
        let need = need_of(needs, o);
        if need <= 0.0 {
            continue;
        }
        let a = age(anchor);
        let better = match best {
            None => true,
            Some((_, n, b)) => need > n || (need == n && a > b),
        };
        if better {
            best = Some((o, need, a));
        }
    }
    best.map(|(o, _, _)| o)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::robot::lps;

    const DT: f64 = 0.04;

    fn gaze() -> Gaze {
        let joint = PanJoint { min: -1.6, max: 1.6, max_speed: 3.0 };
        Gaze::new(GazeConfig { joint, half_fov: 0.3, dwell: 0.2 })
    }

    /// A robot standing still with objects at fixed bearings: each cycle the camera sees the
    /// objects within its view of the pan, and the anchors of the others decay as the world
    /// model's do (reliability × `DECAY` per cycle, age growing).
    struct Stand {
        bearings: Vec<(usize, f64)>,
        lps: Vec<Lpo>,
    }

    impl Stand {
        fn new(bearings: &[(usize, f64)]) -> Stand {
            Stand { bearings: bearings.to_vec(), lps: vec![Lpo::default(); lps::COUNT] }
        }

        fn look(&mut self, pan: f64, half_fov: f64) {
            for l in &mut self.lps {
                if l.reliability > 0.0 {
                    l.reliability *= crate::model::DECAY;
                    l.seen_ago += DT;
                }
            }
            for &(o, b) in &self.bearings {
                if (b - pan).abs() <= half_fov {
                    self.lps[o] = Lpo { rho: 2.0, theta: b, reliability: 1.0, seen_ago: 0.0 };
                }
            }
        }
    }

    /// Runs `cycles` cycles; the fixation of each cycle and the oldest age each object reached
    /// after it was first seen.
    fn run(g: &mut Gaze, s: &mut Stand, needs: &[(usize, f64)], cycles: usize) -> Vec<Aim> {
        let mut aims = Vec::new();
        for _ in 0..cycles {
            s.look(g.pan(), g.cfg.half_fov);
            let aim = g.step(needs, &s.lps, DT);
            assert!(aim.pan >= g.cfg.joint.min && aim.pan <= g.cfg.joint.max);
            if let Some(last) = aims.last().map(|a: &Aim| a.pan) {
                assert!((aim.pan - last).abs() <= 3.0 * DT + 1e-12, "within the joint's speed");
            }
            aims.push(aim);
        }
        aims
    }

    #[test]
    fn equal_needs_alternate_between_ball_and_landmark_as_their_anchors_decay() {
        let (g, mut s) = (&mut gaze(), Stand::new(&[(lps::BALL, 1.0), (lps::LANDMARK0, -1.0)]));
        let needs = [(lps::BALL, 1.0), (lps::LANDMARK0, 1.0)];
        let aims = run(g, &mut s, &needs, 500);
        let switches = aims.windows(2).filter(|w| w[0].object != w[1].object).count();
        assert!(switches >= 20, "20 s of looking in turn: {switches} switches");
        // After the first sweep found both, neither anchor is ever left for long: an object
        // leaves the view at 0.7 rad from the middle, and the joint turns 1.4 rad (0.47 s) to
        // the other, holds it 0.2 s (plus the 0.3 rad to its bearing and back, 0.2 s) and
        // turns back (0.47 s): about 1.3 s.
        let mut oldest = [0.0_f64; 2];
        for _ in 0..250 {
            s.look(g.pan(), g.cfg.half_fov);
            g.step(&needs, &s.lps, DT);
            oldest[0] = oldest[0].max(s.lps[lps::BALL].seen_ago);
            oldest[1] = oldest[1].max(s.lps[lps::LANDMARK0].seen_ago);
        }
        assert!(oldest.iter().all(|&a| a < 1.4), "oldest ages {oldest:?}");
        let looked: Vec<Option<usize>> = aims.iter().map(|a| a.object).collect();
        assert!(looked.contains(&Some(lps::BALL)) && looked.contains(&Some(lps::LANDMARK0)));
    }

    #[test]
    fn the_highest_need_wins_and_the_other_object_is_not_looked_at() {
        let (g, mut s) = (&mut gaze(), Stand::new(&[(lps::BALL, 1.0), (lps::NET1, -1.0)]));
        // `trackbnet1` with the ball 400 mm away: BALL 1.0, NET1 0.7 (ThinkingCap/TeamChaos report §3).
        let aims = run(g, &mut s, &[(lps::BALL, 1.0), (lps::NET1, 0.7)], 200);
        assert!(aims.iter().all(|a| a.object == Some(lps::BALL)));
        assert!((aims[199].pan - 1.0).abs() < 1e-9, "resting on the ball");
        assert_eq!(s.lps[lps::NET1].reliability, 0.0, "the net was never in view");
    }

    #[test]
    fn a_repeated_index_counts_with_its_largest_need() {
        assert_eq!(need_of(&[(0, 0.2), (0, 0.9), (1, 1.0)], 0), 0.9);
        assert_eq!(need_of(&[(0, f64::NAN), (0, 7.0)], 0), 1.0, "clamped, NaN ignored");
        let mut lps_now = vec![Lpo::default(); 3];
        lps_now[0] = Lpo { reliability: 1.0, seen_ago: 0.0, ..Lpo::default() };
        lps_now[1] = Lpo { reliability: 0.3, seen_ago: 2.0, ..Lpo::default() };
        assert_eq!(choose(&[(0, 1.0), (1, 1.0)], &lps_now), Some(1), "least recently seen");
        assert_eq!(choose(&[(0, 1.0), (1, 1.0), (2, 1.0)], &lps_now), Some(2), "never seen");
        assert_eq!(choose(&[(0, 1.0), (1, 0.5), (9, 1.0)], &lps_now), Some(0), "out of LPS");
        assert_eq!(choose(&[], &lps_now), None);
    }

    #[test]
    fn tracked_landmarks_are_looked_at_least_recently_seen_first_and_the_ball_in_its_turn() {
        // The ball ahead-left, three landmarks to the right, one behind the robot.
        let objects = [(lps::BALL, 0.9), (3, -0.8), (4, -1.1), (5, -1.4), (6, 3.0)];
        let (g, mut s) = (&mut gaze(), Stand::new(&objects));
        // All were seen before, long ago (a gaze only aims at anchors it has).
        for (o, b) in objects.into_iter().skip(1) {
            s.lps[o] = Lpo { rho: 5.0, theta: b, reliability: 0.1, seen_ago: 9.0 };
        }
        let mut looks = std::collections::BTreeMap::new();
        let mut oldest = [0.0_f64; 4];
        for k in 0..500 {
            s.look(g.pan(), g.cfg.half_fov);
            let mut needs = vec![(lps::BALL, 1.0)];
            needs.extend(g.landmark_need(&[3, 4, 5, 6], 1.0, &s.lps));
            let aim = g.step(&needs, &s.lps, DT);
            *looks.entry(aim.object).or_insert(0) += 1;
            for (slot, o) in oldest.iter_mut().zip([lps::BALL, 3, 4, 5]) {
                if k > 100 {
                    *slot = slot.max(s.lps[o].seen_ago);
                }
            }
        }
        // The camera turns to the farthest landmark (5) and sees the two others on its way:
        // each anchor is refreshed every couple of seconds, the ball's too.
        assert!(looks[&Some(lps::BALL)] > 100 && looks[&Some(5)] > 100, "{looks:?}");
        assert!(oldest.iter().all(|&a| a < 2.0), "oldest ages: {oldest:?}");
        assert_eq!(looks.get(&Some(6)), None, "the landmark behind is out of reach");
        assert_eq!(g.landmark_need(&[], 1.0, &s.lps), None);
        assert_eq!(g.landmark_need(&[7, 8], 0.5, &s.lps), Some((7, 0.5)), "none known: searched");
    }

    #[test]
    fn a_lost_object_is_searched_by_sweeping_the_whole_range() {
        let (g, mut s) = (&mut gaze(), Stand::new(&[(lps::BALL, -1.4)]));
        let aims = run(g, &mut s, &[(lps::BALL, 1.0)], 100);
        assert!(aims[0].searching, "never seen: searched");
        let found = aims.iter().position(|a| !a.searching).expect("found by the sweep");
        assert!(aims[..found].iter().any(|a| a.pan >= 1.6 - 1e-9), "swept left first");
        assert!((aims[99].pan + 1.4).abs() < 1e-9, "then rests on it");
    }

    #[test]
    fn an_anchor_that_is_not_where_it_was_is_searched_after_the_dwell() {
        let mut g = gaze();
        let mut lps_now = vec![Lpo::default(); lps::COUNT];
        // Remembered 0.5 rad to the left, but no longer there: never seen again.
        lps_now[lps::BALL] = Lpo { rho: 1.0, theta: 0.5, reliability: 0.6, seen_ago: 1.0 };
        let aims: Vec<Aim> = (0..40).map(|_| g.step(&[(lps::BALL, 1.0)], &lps_now, DT)).collect();
        let arrived = aims.iter().position(|a| (a.pan - 0.5).abs() < 1e-9).expect("turned to it");
        assert!(!aims[arrived].searching);
        assert!(aims[arrived + 8].searching, "{:?}", &aims[arrived..arrived + 9]);
    }

    #[test]
    fn with_no_needs_the_head_returns_to_the_middle_and_bad_input_is_harmless() {
        let mut g = gaze();
        let lps_now = vec![Lpo { theta: f64::NAN, reliability: 1.0, ..Lpo::default() }; 4];
        let a = g.step(&[(0, 1.0)], &lps_now, DT);
        assert!(a.searching && a.pan.is_finite(), "a NaN bearing is searched");
        for _ in 0..30 {
            g.step(&[(0, 1.0)], &lps_now, DT);
        }
        assert!(g.pan() != 0.0);
        for _ in 0..100 {
            let a = g.step(&[], &lps_now, f64::INFINITY);
            assert_eq!(a.object, None);
        }
        let a = (0..100).map(|_| g.step(&[], &lps_now, DT)).last().expect("100 steps");
        assert_eq!(a.pan, 0.0);
        assert_eq!(g.step(&[(0, 1.0)], &[], DT).object, None, "an empty LPS");
    }
}
