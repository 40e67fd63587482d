//! MAP's tracker (MRT manual ch. 8, "Kalman filtering of the dynamic properties"): a Kalman
//! filter on one moving object's place and velocity in the field frame, fed by the robot's
//! sightings of it.
//!
//! The state is `(x, y, vx, vy)` (m, m/s). Between sightings the object rolls on, slowing by a
//! linear damping `c` (1/s: the ball's rolling friction; 0 for a constant-velocity model):
//! `v(t + dt) = v·e^(−c·dt)`, `p(t + dt) = p + v·(1 − e^(−c·dt))/c`. The process noise is a
//! random acceleration of [`Track::accel`] m/s² ([`BALL_ACCEL`] for a ball, a design
//! choice). A sighting is a position with its covariance ([`sighting_covariance`]: the
//! camera's range and bearing error and the robot's own pose uncertainty).
//!
//! A sighting whose Mahalanobis distance from the prediction exceeds the χ² gate
//! ([`GATE`], 99 % with two degrees of freedom) is not that object where the track expects it.
//! When the object could have got there from its last tracked place no faster than its top
//! speed ([`Track::with_top_speed`]; a ball's is a kick's, [`BALL_TOP_SPEED`]), it was kicked:
//! the track starts again from the sighting at once, moving at the speed it took. Otherwise,
//! once is a false sighting and is left out; [`RESTART_AFTER`] in a row is the object kicked
//! (or the robot carried) and the track starts again from the sighting, moving as the last
//! two sightings say (not still, as a track seen for the first time).
//!
//! A ball in play is not only rolling: robots push it, dribble it, stop it dead and kick it.
//! One random acceleration cannot fit both: a small one follows a rolling ball smoothly but
//! lags behind every push; a large one follows the pushes but passes the camera's noise on to
//! the velocity. [`Track::with_maneuver`] runs two models, a quiet one ([`Track::accel`]) and
//! a manoeuvre one ([`Track::maneuver`]), mixed by the *interacting multiple model* (IMM, Blom
//! and Bar-Shalom 1988; recalled literature, not the seeds'): before each sighting, each model
//! starts from a mixture of both weighted by the chance that the object switched from one to
//! the other ([`SWITCH_RATE`]); each is corrected by the sighting, whose likelihood under each
//! updates the models' probabilities; the track reads out their weighted combination. The
//! gate leaves out only a sighting that no model expects. With the ball's 0.5 and 8 m/s²
//! ([`BALL_ACCEL`], [`BALL_MANEUVER`]), the velocity error over 8 vision matches fell from
//! 0.363 m/s (quiet model alone) to 0.307 (docs/performance.md).
//!
//! ```
//! use mrt_world::track::Track;
//! use nalgebra::Matrix2;
//! // A ball rolling east at 1 m/s on a carpet with no friction, seen every 0.1 s.
//! let mut t = Track::new(0.0, 2.0);
//! let r = Matrix2::from_diagonal_element(0.02 * 0.02);
//! for k in 0..20 {
//!     let time = 0.1 * f64::from(k);
//!     t.update(time, (time, 0.5), r);
//! }
//! let (vx, vy) = t.velocity();
//! assert!((vx - 1.0).abs() < 0.1 && vy.abs() < 0.1);
//! ```

use nalgebra::{Matrix2, Matrix4, Matrix4x2, Vector2, Vector4};

/// χ² with two degrees of freedom at 99 %: a sighting farther than this (squared Mahalanobis
/// distance) from the prediction is gated out.
pub const GATE: f64 = 9.21;
/// The random acceleration of a rolling ball, m/s²: what its rolling friction model leaves
/// out (bumps, spin). Pushes, kicks and collisions are the manoeuvre model's
/// ([`BALL_MANEUVER`]) or, beyond it, the gate's, which restarts the track. A design choice,
/// measured with the quiet model alone, `mrt sim --seed S --metrics m.json`, seeds 1 and 2:
/// the velocity error with the object sensor is 0.39 and 0.35 m/s at 0.5 m/s², 0.56 and 0.51
/// at 2; with vision it is 0.30 and 0.33 at 0.5, 0.27 and 0.30 at 2. The exact sensor's loss
/// is the larger.
pub const BALL_ACCEL: f64 = 0.5;
/// After this many gated-out sightings in a row, the track restarts from the last.
pub const RESTART_AFTER: u32 = 2;
/// The fastest a ball in play moves, m/s: a kick (the simulator's and the MuJoCo world's
/// kickers give 6 m/s) with a margin. A gated-out sighting the ball could have reached from
/// its track at this speed restarts the track at once (module doc). A design choice, measured
/// with `mrt sim --seed S --metrics m.json`, seeds 10001–10004: the velocity error with
/// vision is 0.281 m/s when every gated-out sighting waits for a second one, 0.254 at 8 m/s
/// and 0.257 at 12.
pub const BALL_TOP_SPEED: f64 = 8.0;
/// The chance per second that a tracked object switches between the quiet and the
/// manoeuvre model (the IMM's Markov chain: `1 − e^(−rate·dt)` between two sightings).
pub const SWITCH_RATE: f64 = 1.0;
/// The ball's manoeuvre model's random acceleration, m/s²: a ball pushed or dribbled by a
/// robot, or stopped by one (module doc). A design choice, measured with `mrt sim --matches 8
/// --seed 1 --percepts vision --metrics m.json`: velocity error 0.307 m/s at 8, 0.302 at 16
/// (with the object sensor 0.50 at 8); one model alone gives 0.363 at 0.5 m/s², 0.330 at 2,
/// 0.304 at 8 and 0.340 at 16 with vision, but 1.07 at 8 with the object sensor, whose
/// noise is larger.
pub const BALL_MANEUVER: f64 = 8.0;
/// A restarted track takes its velocity from the two sightings that restarted it only when
/// they are this far apart in time at least, s (closer, their errors swamp the motion) ...
const MIN_START_INTERVAL: f64 = 0.02;
/// ... and at most this far (longer, the object may have been stopped or kicked again).
const MAX_START_INTERVAL: f64 = 0.5;
/// The velocity's standard deviation of a track just started, m/s (a ball may be rolling at
/// several metres a second when first seen).
const START_SPEED_SIGMA: f64 = 3.0;

/// One tracked object (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Linear damping of the velocity, 1/s.
    pub damping: f64,
    /// Random acceleration of the process noise, m/s² (the quiet model's, with a manoeuvre
    /// model).
    pub accel: f64,
    /// The manoeuvre model's random acceleration, m/s², when the track runs two models
    /// ([`Track::with_maneuver`]).
    pub maneuver: Option<f64>,
    /// The fastest the object moves, m/s ([`Track::with_top_speed`]).
    pub top_speed: Option<f64>,
    state: Option<State>,
    gated: u32,
    /// The last sighting the gate left out: `(time, place, covariance)`. A restart takes its
    /// velocity from it and the sighting that restarts the track.
    last_gated: Option<(f64, Vector2<f64>, Matrix2<f64>)>,
    counts: TrackCounts,
}

/// One motion model's estimate (module doc: the IMM).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Mode {
    /// Its random acceleration, m/s².
    accel: f64,
    x: Vector4<f64>,
    p: Matrix4<f64>,
    /// The probability that the object moves by this model.
    mu: f64,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct State {
    time: f64,
    /// The models: the first `n` are in use (one for a plain Kalman filter).
    modes: [Mode; 2],
    n: usize,
    /// Their combination, what the track reads out.
    x: Vector4<f64>,
    p: Matrix4<f64>,
}

impl State {
    fn modes(&self) -> &[Mode] {
        &self.modes[..self.n]
    }

    /// The combination of the models' estimates weighted by their probabilities (moment
    /// matching).
    fn combine(&mut self) {
        let (x, p) = mixture(self.modes().iter().map(|m| (m.mu, m.x, m.p)));
        self.x = x;
        self.p = p;
    }
}

/// The mean and covariance of a mixture of `(weight, mean, covariance)` (weights summing
/// to 1).
fn mixture(
    parts: impl Iterator<Item = (f64, Vector4<f64>, Matrix4<f64>)> + Clone,
) -> (Vector4<f64>, Matrix4<f64>) {
    let x: Vector4<f64> = parts.clone().map(|(w, x, _)| x * w).sum();
    let p = parts.map(|(w, xi, pi)| (pi + (xi - x) * (xi - x).transpose()) * w).sum();
    (x, p)
}

/// One model predicted to a sighting's time: its mixed-and-predicted estimate and the
/// model's predicted probability.
#[derive(Clone, Copy)]
struct Predicted {
    x: Vector4<f64>,
    p: Matrix4<f64>,
    c: f64,
}

/// A prediction and one sighting's innovation against it.
struct Innovation {
    innovation: Vector2<f64>,
    s_inv: Matrix2<f64>,
    d2: f64,
    /// The sighting's likelihood under the prediction, up to a constant factor.
    likelihood: f64,
}

/// What a track did with its sightings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TrackCounts {
    /// Sightings that updated the track.
    pub updates: u64,
    /// Sightings left out by the gate.
    pub gated: u64,
    /// Times the track started again (the first sighting, a kick, a pose that jumped).
    pub restarts: u64,
}

impl Track {
    /// A track with no sighting yet, of an object slowing by `damping` (1/s) under random
    /// accelerations of `accel` (m/s²).
    pub fn new(damping: f64, accel: f64) -> Track {
        Track {
            damping: damping.max(0.0),
            accel,
            maneuver: None,
            top_speed: None,
            state: None,
            gated: 0,
            last_gated: None,
            counts: TrackCounts::default(),
        }
    }

    /// The same track with a second motion model of random acceleration `accel` (m/s²), the
    /// two mixed by the IMM (module doc). Takes effect at the next start.
    pub fn with_maneuver(mut self, accel: f64) -> Track {
        self.maneuver = Some(accel).filter(|a| a.is_finite() && *a > 0.0);
        self
    }

    /// The same track of an object that moves no faster than `speed` (m/s): a sighting the
    /// gate leaves out that the object could have reached at that speed restarts the track
    /// at once (module doc).
    pub fn with_top_speed(mut self, speed: f64) -> Track {
        self.top_speed = Some(speed).filter(|v| v.is_finite() && *v > 0.0);
        self
    }

    /// What it did so far.
    pub fn counts(&self) -> TrackCounts {
        self.counts
    }

    /// Whether it has seen the object.
    pub fn is_started(&self) -> bool {
        self.state.is_some()
    }

    /// The object's place at its last sighting's time, m (field frame).
    pub fn position(&self) -> (f64, f64) {
        self.state.map_or((0.0, 0.0), |s| (s.x[0], s.x[1]))
    }

    /// Its velocity, m/s.
    pub fn velocity(&self) -> (f64, f64) {
        self.state.map_or((0.0, 0.0), |s| (s.x[2], s.x[3]))
    }

    /// The probability that the object is manoeuvring (kicked, pushed, dribbled): the
    /// manoeuvre model's; `None` without one or before the first sighting.
    pub fn maneuvering(&self) -> Option<f64> {
        self.state.filter(|s| s.n > 1).map(|s| s.modes[1].mu)
    }

    /// Forgets the object (the robot's pose jumped: the track lies in the frame it had).
    pub fn reset(&mut self) {
        self.state = None;
        self.gated = 0;
        self.last_gated = None;
    }

    /// Where it will be at `time`: `(x, y, vx, vy)`, without changing the track.
    pub fn predicted(&self, time: f64) -> Option<(f64, f64, f64, f64)> {
        let (x, _) = self.predicted_state(time)?;
        Some((x[0], x[1], x[2], x[3]))
    }

    /// The combined estimate predicted to `time`: mean and covariance.
    fn predicted_state(&self, time: f64) -> Option<(Vector4<f64>, Matrix4<f64>)> {
        let s = self.state?;
        let predicted = self.predict(&s, (time - s.time).max(0.0));
        Some(mixture(predicted[..s.n].iter().map(|m| (m.c, m.x, m.p))))
    }

    /// The IMM's interaction and prediction over `dt`: each model starts from the mixture
    /// of all models' estimates weighted by the chance that the object switched from one
    /// to the other ([`SWITCH_RATE`]), and rolls on by its own random acceleration.
    fn predict(&self, s: &State, dt: f64) -> [Predicted; 2] {
        let modes = s.modes();
        let switch = if modes.len() > 1 { 1.0 - (-SWITCH_RATE * dt).exp() } else { 0.0 };
        let to = |i: usize, j: usize| if i == j { 1.0 - switch } else { switch };
        let mut out = [Predicted { x: Vector4::zeros(), p: Matrix4::zeros(), c: 0.0 }; 2];
        for (j, (o, mode)) in out.iter_mut().zip(modes).enumerate() {
            let c: f64 = modes.iter().enumerate().map(|(i, m)| to(i, j) * m.mu).sum();
            let (x0, p0) = if c > 0.0 {
                mixture(modes.iter().enumerate().map(|(i, m)| (to(i, j) * m.mu / c, m.x, m.p)))
            } else {
                (mode.x, mode.p)
            };
            let (f, n) = self.transition(dt, mode.accel);
            *o = Predicted { x: f * x0, p: f * p0 * f.transpose() + n, c };
        }
        out
    }

    /// The transition matrix over `dt` and the process noise of random acceleration `accel`.
    fn transition(&self, dt: f64, accel: f64) -> (Matrix4<f64>, Matrix4<f64>) {
        let c = self.damping;
        let decay = (-c * dt).exp();
        // ∫₀^dt e^(−c·s) ds: dt when there is no damping.
        let reach = if c * dt > 1e-9 { (1.0 - decay) / c } else { dt };
        let mut f = Matrix4::identity();
        f[(0, 2)] = reach;
        f[(1, 3)] = reach;
        f[(2, 2)] = decay;
        f[(3, 3)] = decay;
        // A white random acceleration over dt, per axis (the constant-velocity model's Q).
        let q = accel * accel;
        let (q11, q12, q22) = (q * dt.powi(3) / 3.0, q * dt * dt / 2.0, q * dt);
        let mut n = Matrix4::zeros();
        for axis in 0..2 {
            n[(axis, axis)] = q11;
            n[(axis, axis + 2)] = q12;
            n[(axis + 2, axis)] = q12;
            n[(axis + 2, axis + 2)] = q22;
        }
        (f, n)
    }

    /// A sighting at `time` (s) of the object at `at` (m, field frame) with covariance `r`:
    /// predicts the track to `time` and corrects it (module doc). Returns whether the
    /// sighting was used (updated or restarted the track). A sighting that is not a number,
    /// or older than the track, is refused.
    pub fn update(&mut self, time: f64, at: (f64, f64), r: Matrix2<f64>) -> bool {
        let finite = at.0.is_finite() && at.1.is_finite() && time.is_finite();
        if !finite || r.iter().any(|v| !v.is_finite()) {
            return false;
        }
        let Some(s) = self.state else {
            self.start(time, at, r);
            return true;
        };
        if time < s.time {
            return false;
        }
        let predicted = self.predict(&s, time - s.time);
        let mut innovations = Vec::with_capacity(s.n);
        for m in &predicted[..s.n] {
            let Some(i) = innovation(m, at, r) else { return false };
            innovations.push(i);
        }
        // Gated out when no model expects it there.
        if innovations.iter().all(|i| i.d2 > GATE) {
            self.gated += 1;
            self.counts.gated += 1;
            if let Some(from) = self.kicked_from(&s, time, at) {
                self.start(time, at, r);
                self.start_moving(from);
                return true;
            }
            if self.gated >= RESTART_AFTER {
                let before = self.last_gated.take();
                self.start(time, at, r);
                if let Some(before) = before {
                    self.start_moving(before);
                }
                return true;
            }
            self.last_gated = Some((time, Vector2::new(at.0, at.1), r));
            return false;
        }
        self.gated = 0;
        let h = Matrix4x2::<f64>::identity().transpose();
        let mut next = s;
        for ((mode, m), i) in next.modes.iter_mut().zip(&predicted).zip(&innovations) {
            let k = m.p * h.transpose() * i.s_inv;
            // Joseph form: stays symmetric and positive.
            let i_kh = Matrix4::identity() - k * h;
            mode.x = m.x + k * i.innovation;
            mode.p = i_kh * m.p * i_kh.transpose() + k * r * k.transpose();
            mode.mu = m.c * i.likelihood;
        }
        let total: f64 = next.modes().iter().map(|m| m.mu).sum();
        for (mode, m) in next.modes.iter_mut().zip(&predicted).take(s.n) {
            // Both likelihoods too small to tell: the predicted probabilities stand.
            mode.mu = if total > 0.0 && total.is_finite() { mode.mu / total } else { m.c };
        }
        next.time = time;
        next.combine();
        self.state = Some(next);
        self.counts.updates += 1;
        true
    }

    /// Where the track expects the object at `time` (m) and the covariance of that place
    /// (m²), without changing the track; `None` before the first sighting. With
    /// [`squared_distance`], what the gate and the data association compare with [`GATE`].
    pub fn predicted_place(&self, time: f64) -> Option<((f64, f64), Matrix2<f64>)> {
        let (x, p) = self.predicted_state(time)?;
        Some(((x[0], x[1]), p.fixed_view::<2, 2>(0, 0).into_owned()))
    }

    /// One standard deviation of the object's place, m (the root of the position
    /// covariance's mean diagonal), predicted to `time`; `None` before the first sighting.
    pub fn sigma(&self, time: f64) -> Option<f64> {
        let (_, p) = self.predicted_state(time)?;
        Some(((p[(0, 0)] + p[(1, 1)]) / 2.0).max(0.0).sqrt())
    }

    /// The track's last place `(time, place, covariance)`, when the object could have left it
    /// no faster than its top speed to be seen at `at` at `time`: a kick from there.
    fn kicked_from(
        &self,
        s: &State,
        time: f64,
        at: (f64, f64),
    ) -> Option<(f64, Vector2<f64>, Matrix2<f64>)> {
        let top = self.top_speed?;
        let dt = time - s.time;
        if !(MIN_START_INTERVAL..=MAX_START_INTERVAL).contains(&dt) {
            return None;
        }
        let (f, _) = self.transition(dt, self.accel);
        let from = s.x.fixed_rows::<2>(0).into_owned();
        // The speed at `time` of an object that rolled from `from` to `at` in `dt`.
        let speed = (Vector2::new(at.0, at.1) - from).norm() * f[(2, 2)] / f[(0, 2)];
        (speed <= top).then(|| (s.time, from, s.p.fixed_view::<2, 2>(0, 0).into_owned()))
    }

    /// A track just restarted by the gate: the object was kicked, and the sighting before
    /// (`before`, also gated out) shows where from. Its velocity is the two sightings'
    /// difference over their interval, slowed by the damping to now, with the covariance of
    /// that difference, when the two are far enough apart in time to say.
    fn start_moving(&mut self, (t0, at0, r0): (f64, Vector2<f64>, Matrix2<f64>)) {
        let Some(time) = self.state.map(|s| s.time) else { return };
        let dt = time - t0;
        if !(MIN_START_INTERVAL..=MAX_START_INTERVAL).contains(&dt) {
            return;
        }
        let (f, _) = self.transition(dt, self.accel);
        let Some(s) = &mut self.state else { return };
        // p1 = p0 + v0·reach, v1 = v0·decay: v1 = (p1 − p0)·decay / reach.
        let (reach, decay) = (f[(0, 2)], f[(2, 2)]);
        let gain = decay / reach;
        let n = s.n;
        for m in &mut s.modes[..n] {
            let v = (m.x.fixed_rows::<2>(0) - at0) * gain;
            let cov = (m.p.fixed_view::<2, 2>(0, 0) + r0) * (gain * gain);
            m.x[2] = v[0];
            m.x[3] = v[1];
            let cross = m.p.fixed_view::<2, 2>(0, 0) * gain;
            m.p.fixed_view_mut::<2, 2>(2, 2).copy_from(&cov);
            m.p.fixed_view_mut::<2, 2>(0, 2).copy_from(&cross);
            m.p.fixed_view_mut::<2, 2>(2, 0).copy_from(&cross.transpose());
        }
        s.combine();
    }

    /// Starts the track at a sighting, still, every model alike and equally likely.
    fn start(&mut self, time: f64, at: (f64, f64), r: Matrix2<f64>) {
        let mut p = Matrix4::zeros();
        p.fixed_view_mut::<2, 2>(0, 0).copy_from(&r);
        let v = START_SPEED_SIGMA * START_SPEED_SIGMA;
        p[(2, 2)] = v;
        p[(3, 3)] = v;
        let x = Vector4::new(at.0, at.1, 0.0, 0.0);
        let n = if self.maneuver.is_some() { 2 } else { 1 };
        let mu = 1.0 / n as f64;
        let quiet = Mode { accel: self.accel, x, p, mu };
        let loud = Mode { accel: self.maneuver.unwrap_or(self.accel), ..quiet };
        self.state = Some(State { time, modes: [quiet, loud], n, x, p });
        self.gated = 0;
        self.counts.restarts += 1;
    }
}

/// A sighting at `at` with covariance `r` against one model's prediction `m`.
fn innovation(m: &Predicted, at: (f64, f64), r: Matrix2<f64>) -> Option<Innovation> {
    let h = Matrix4x2::<f64>::identity().transpose();
    let innovation = Vector2::new(at.0, at.1) - h * m.x;
    let s = h * m.p * h.transpose() + r;
    let s_inv = s.try_inverse()?;
    let d2 = (innovation.transpose() * s_inv * innovation)[0];
    let det = s.determinant();
    let likelihood = if det > 0.0 { (-0.5 * d2).exp() / det.sqrt() } else { 0.0 };
    Some(Innovation { innovation, s_inv, d2, likelihood })
}

/// The squared Mahalanobis distance of a sighting at `at` with covariance `r` from a
/// predicted place `mean` with covariance `p` ([`Track::predicted_place`]); `None` when the
/// summed covariance has no inverse.
pub fn squared_distance(
    (mean, p): ((f64, f64), Matrix2<f64>),
    at: (f64, f64),
    r: Matrix2<f64>,
) -> Option<f64> {
    let d = Vector2::new(at.0 - mean.0, at.1 - mean.1);
    let s_inv = (p + r).try_inverse()?;
    Some((d.transpose() * s_inv * d)[0])
}

/// The covariance (m², field frame) of an object seen at `range` (m) and `bearing` (rad,
/// robot frame) by a robot heading `theta` (rad) in the field, with the sighting's standard
/// deviations `sigma` = (range m, bearing rad) and the robot's own position covariance
/// `pose_xy` (m²) and heading variance `pose_theta` (rad²): the camera's error along and
/// across the line of sight, the heading's error swinging the object round the robot, and the
/// robot's position error carried along.
pub fn sighting_covariance(
    range: f64,
    bearing: f64,
    theta: f64,
    sigma: (f64, f64),
    pose_xy: Matrix2<f64>,
    pose_theta: f64,
) -> Matrix2<f64> {
    let (s, c) = (theta + bearing).sin_cos();
    let along = sigma.0 * sigma.0;
    let across = range * range * (sigma.1 * sigma.1 + pose_theta.max(0.0));
    let rot = Matrix2::new(c, -s, s, c);
    rot * Matrix2::new(along, 0.0, 0.0, across) * rot.transpose() + pose_xy
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic wobble in [−1, 1].
    fn wobble(k: u32) -> f64 {
        ((f64::from(k) * 12.9898).sin() * 43_758.545_3).rem_euclid(1.0) * 2.0 - 1.0
    }

    /// A ball at 1 m/s seen at 10 Hz has its velocity within 10 % after about 10 updates (here
    /// with up to 1 cm of noise per sighting, and the ball's random acceleration,
    /// [`BALL_ACCEL`]).
    #[test]
    fn the_predicted_place_gives_the_update_s_distance() {
        let mut t = Track::new(0.5, 1.0);
        let r = Matrix2::new(0.01, 0.002, 0.002, 0.02);
        for k in 0..5 {
            t.update(0.1 * f64::from(k), (0.3 * f64::from(k), 1.0), r);
        }
        assert_eq!(t.predicted_place(0.9).map(|p| p.0), t.predicted(0.9).map(|p| (p.0, p.1)));
        let state = t.state.unwrap();
        for at in [(1.5, 1.1), (2.0, 0.0), (-1.0, 3.0)] {
            // The update's own innovation, through the whole 4 × 4 prediction.
            let by_track = innovation(&t.predict(&state, 0.9 - state.time)[0], at, r).unwrap().d2;
            let cached = squared_distance(t.predicted_place(0.9).unwrap(), at, r).unwrap();
            assert!((by_track - cached).abs() <= 1e-9 * by_track.max(1.0), "{by_track} {cached}");
        }
        assert!(Track::new(0.0, 1.0).predicted_place(1.0).is_none());
    }

    #[test]
    fn a_rolling_ball_s_velocity_is_found_within_ten_percent_in_ten_sightings() {
        let mut t = Track::new(0.0, BALL_ACCEL);
        let r = Matrix2::from_diagonal_element(0.01 * 0.01);
        for k in 0..=10 {
            let time = 0.1 * f64::from(k);
            let at = (1.0 + time + 0.01 * wobble(k), -0.5 + 0.01 * wobble(k + 100));
            assert!(t.update(time, at, r));
        }
        let (vx, vy) = t.velocity();
        assert!((vx - 1.0).abs() < 0.1 && vy.abs() < 0.1, "({vx}, {vy})");
    }

    /// A kick: two sightings that the gate leaves out restart the track, whose velocity is
    /// then theirs (the ball rolled 0.5 m west in the 0.1 s between them: 5 m/s, slowed by
    /// nothing here), not 0 as for an object seen for the first time.
    #[test]
    fn a_track_restarted_by_a_kick_takes_the_velocity_of_the_two_sightings() {
        let mut t = Track::new(0.0, BALL_ACCEL);
        let r = Matrix2::from_diagonal_element(0.02 * 0.02);
        for k in 0..10 {
            assert!(t.update(0.1 * f64::from(k), (0.0, 0.0), r), "a ball lying still");
        }
        assert!(!t.update(1.0, (-1.0, 0.0), r), "the first sighting after the kick is gated");
        assert!(t.update(1.1, (-1.5, 0.0), r), "the second restarts the track");
        assert_eq!(t.counts().restarts, 2);
        let (vx, vy) = t.velocity();
        assert!((vx + 5.0).abs() < 1e-9 && vy.abs() < 1e-9, "({vx}, {vy})");
        // Its uncertainty is the two sightings': √2 × 2 cm / 0.1 s = 0.28 m/s per axis.
        let p = t.state.unwrap().p;
        assert!((p[(2, 2)].sqrt() - 0.2 * 2f64.sqrt()).abs() < 1e-9, "{p}");
        // A restart from sightings 0.6 s apart (the ball may have stopped, or been kicked
        // again, in between) starts still.
        let mut t = Track::new(0.0, BALL_ACCEL);
        for k in 0..10 {
            t.update(0.1 * f64::from(k), (0.0, 0.0), r);
        }
        assert!(!t.update(1.0, (-3.0, 0.0), r));
        assert!(t.update(1.6, (-3.0, 2.0), r));
        assert_eq!(t.counts().restarts, 2);
        assert_eq!(t.velocity(), (0.0, 0.0));
    }

    /// A ball slowing by rolling friction (damping 0.4/s, the simulator's): the track with the
    /// same damping follows it, and predicts where it stops rolling during an occlusion.
    #[test]
    fn a_ball_slowing_by_friction_is_tracked_and_predicted_through_an_occlusion() {
        let c = 0.4;
        let truth = |t: f64| {
            let v = 3.0 * (-c * t).exp();
            (3.0 * (1.0 - (-c * t).exp()) / c, v)
        };
        let mut track = Track::new(c, 2.0);
        let r = Matrix2::from_diagonal_element(0.02 * 0.02);
        for k in 0..=20 {
            let time = 0.1 * f64::from(k);
            track.update(time, (truth(time).0 + 0.02 * wobble(k), 0.02 * wobble(k + 7)), r);
        }
        let (vx, _) = track.velocity();
        assert!((vx - truth(2.0).1).abs() < 0.15, "{vx} vs {}", truth(2.0).1);
        // Two seconds unseen: predicted on its slowing course, within 20 cm.
        let (x, _, vx, _) = track.predicted(4.0).unwrap_or_default();
        assert!((x - truth(4.0).0).abs() < 0.2, "{x} vs {}", truth(4.0).0);
        assert!((vx - truth(4.0).1).abs() < 0.15);
        // A model without the friction overshoots.
        let mut straight = Track::new(0.0, 2.0);
        for k in 0..=20 {
            let time = 0.1 * f64::from(k);
            straight.update(time, (truth(time).0 + 0.02 * wobble(k), 0.02 * wobble(k + 7)), r);
        }
        let (far, ..) = straight.predicted(4.0).unwrap_or_default();
        assert!(far - truth(4.0).0 > 0.5, "{far}");
    }

    /// With a top speed, a kick restarts the track at its first sighting, moving at the
    /// speed it took; a sighting farther off than the top speed could reach is left out, and
    /// the track rolls on.
    #[test]
    fn a_kick_within_the_top_speed_restarts_the_track_at_its_first_sighting() {
        let mut t = Track::new(0.0, 2.0).with_maneuver(8.0).with_top_speed(8.0);
        let r = Matrix2::from_diagonal_element(0.02 * 0.02);
        for k in 0..10 {
            t.update(0.1 * f64::from(k), (0.0, 0.0), r);
        }
        // Kicked north at 6 m/s at 0.9 s: 0.6 m away at 1.0 s.
        assert!(t.update(1.0, (0.0, 0.6), r), "a kick restarts the track at once");
        assert_eq!(t.counts().restarts, 2, "{:?}", t.counts());
        let (vx, vy) = t.velocity();
        assert!(vx.abs() < 0.1 && (vy - 6.0).abs() < 0.3, "({vx}, {vy})");
        // 3 m away 0.1 s later (30 m/s): a false sighting, left out; the track rolls on.
        assert!(!t.update(1.1, (3.0, 0.7), r));
        assert!(t.update(1.2, (0.0, 1.8), r));
        let (vx, vy) = t.velocity();
        assert!(vx.abs() < 0.3 && (vy - 6.0).abs() < 0.5, "({vx}, {vy})");
        assert_eq!(t.counts().restarts, 2);
        // A speed that is not a number sets none.
        assert_eq!(Track::new(0.0, 2.0).with_top_speed(f64::NAN).top_speed, None);
    }

    /// A kick: the first sighting far off the course is left out, the second restarts the
    /// track there, and the new velocity is found within a few more.
    #[test]
    fn a_kicked_ball_restarts_the_track_and_a_single_false_sighting_does_not() {
        let mut t = Track::new(0.0, 2.0);
        let r = Matrix2::from_diagonal_element(0.02 * 0.02);
        for k in 0..10 {
            t.update(0.1 * f64::from(k), (0.0, 0.0), r);
        }
        assert!(!t.update(1.0, (3.0, 3.0), r), "a false sighting 4 m away is gated out");
        assert!(t.update(1.1, (0.0, 0.0), r));
        assert_eq!(t.counts().restarts, 1);
        // Kicked north at 5 m/s at 1.15 s.
        let at = |time: f64| (0.0, 5.0 * (time - 1.15));
        t.update(1.2, at(1.2), r);
        t.update(1.3, at(1.3), r);
        assert_eq!(t.counts().restarts, 2, "{:?}", t.counts());
        for k in 14..22 {
            let time = 0.1 * f64::from(k);
            assert!(t.update(time, at(time), r), "{time}");
        }
        let (vx, vy) = t.velocity();
        assert!(vx.abs() < 0.3 && (vy - 5.0).abs() < 0.3, "({vx}, {vy})");
    }

    /// The IMM against each of its models alone, on a ball rolling at 2 m/s that a robot
    /// stops dead at 1.5 s and another kicks away at 4 m/s at 3 s, seen every 0.1 s with
    /// 3 cm of noise: the quiet model is smooth but slow to follow the stop and the kick,
    /// the manoeuvre model follows them but passes the noise on while the ball rolls; the
    /// IMM follows the changes nearly as fast as the one and rolls nearly as smoothly as the
    /// other, so that its mean velocity error is below both.
    #[test]
    fn the_imm_follows_a_stop_and_a_kick_and_stays_smooth_while_the_ball_rolls() {
        let truth = |t: f64| match t {
            t if t < 1.5 => ((2.0 * t, 0.0), (2.0, 0.0)),
            t if t < 3.0 => ((3.0, 0.0), (0.0, 0.0)),
            t => ((3.0, 4.0 * (t - 3.0)), (0.0, 4.0)),
        };
        let r = Matrix2::from_diagonal_element(0.03 * 0.03);
        let run = |mut track: Track| {
            let mut errors = Vec::new();
            for k in 0..50 {
                let time = 0.1 * f64::from(k) + 0.05;
                let ((x, y), (vx, vy)) = truth(time);
                track.update(time, (x + 0.03 * wobble(k), y + 0.03 * wobble(k + 50)), r);
                let (ex, ey) = track.velocity();
                errors.push((ex - vx).hypot(ey - vy));
            }
            (errors.iter().sum::<f64>() / errors.len() as f64, track)
        };
        let (quiet, _) = run(Track::new(0.0, BALL_ACCEL));
        let (loud, _) = run(Track::new(0.0, BALL_MANEUVER));
        let (imm, track) = run(Track::new(0.0, BALL_ACCEL).with_maneuver(BALL_MANEUVER));
        assert!(imm < quiet && imm < loud, "IMM {imm:.3}, quiet {quiet:.3}, manoeuvre {loud:.3}");
        // Rolling steadily since the kick: the quiet model is the likelier.
        assert!(track.maneuvering().is_some_and(|m| m < 0.5), "{:?}", track.maneuvering());
        assert_eq!(Track::new(0.0, BALL_ACCEL).maneuvering(), None);
    }

    #[test]
    fn sightings_that_are_not_numbers_or_come_late_are_refused() {
        let mut t = Track::new(0.4, 2.0);
        let r = Matrix2::identity();
        assert!(!t.update(0.0, (f64::NAN, 0.0), r));
        assert!(!t.is_started());
        assert!(t.update(1.0, (1.0, 1.0), r));
        assert!(!t.update(0.5, (1.0, 1.0), r), "older than the track");
        assert!(!t.update(2.0, (1.0, 1.0), Matrix2::from_element(f64::INFINITY)));
        assert_eq!(t.position(), (1.0, 1.0));
    }

    /// The covariance of a sighting straight ahead of a robot facing east: the range error
    /// along x, the bearing error (times the range) across, the pose's added.
    #[test]
    fn a_sighting_s_covariance_lies_along_and_across_the_line_of_sight() {
        let c = sighting_covariance(4.0, 0.0, 0.0, (0.1, 0.01), Matrix2::zeros(), 0.0);
        assert!((c[(0, 0)] - 0.01).abs() < 1e-12 && (c[(1, 1)] - 0.0016).abs() < 1e-12);
        assert!(c[(0, 1)].abs() < 1e-12);
        // Facing north: the axes swap.
        let c = sighting_covariance(
            4.0,
            0.0,
            std::f64::consts::FRAC_PI_2,
            (0.1, 0.01),
            Matrix2::zeros(),
            0.0,
        );
        assert!((c[(1, 1)] - 0.01).abs() < 1e-12 && (c[(0, 0)] - 0.0016).abs() < 1e-12);
        let pose = Matrix2::from_diagonal_element(0.04);
        let c = sighting_covariance(4.0, 0.0, 0.0, (0.1, 0.0), pose, 0.0001);
        assert!((c[(0, 0)] - 0.05).abs() < 1e-12 && (c[(1, 1)] - (0.0016 + 0.04)).abs() < 1e-12);
    }
}
