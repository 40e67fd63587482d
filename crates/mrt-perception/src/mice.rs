//! Dead reckoning with two optical mice (MRT manual ch. 4).
//!
//! # Geometry (the manual's "initial hypothesis", §4.1)
//!
//! The two mice are a distance `D` apart, parallel to each other and orthogonal to the line
//! that joins them; the robot is their mid-point and faces where the mice face. In the robot
//! frame (x forward, y left) the left mouse is at `(0, D/2)`, the right one at `(0, −D/2)`.
//! Each mouse reports its motion in its own frame: `ȳ` along its longitudinal axis (the robot's
//! forward direction) and `x̄` along the joining line, positive **to the right** (as a desk
//! mouse's x). So a reading `(x̄, ȳ)` is the vector `(ȳ, −x̄)` in the robot frame. Readings are in
//! metres: divide the counts by the mouse resolution first (calibration, §4.2).
//!
//! During one sampling period the robot moves on an arc of circle (constant speeds), and so does
//! each mouse, around the same centre and by the same angle `Δθ`. Since the mouse turns with the
//! robot, it sees a constant direction of motion: it reports the arc length `l` in the direction
//! `α` from its x axis. The rigid link between the mice makes their `x̄` equal (`x̄_r = x̄_l`), the
//! redundancy used for error detection ([`MiceOdometry::check`]) and reduction
//! ([`MiceOdometry::reduce`], §4.2).
//!
//! Mice mounted otherwise (IANUS3 has them "on the opposite side of the robot diagonal", ch. 12.7,
//! with the calibration angles `σ_r`, `σ_l`, `δ` of §4.2) are not modelled here: their
//! calibration and their odometry are in [`crate::mice_calibration`]
//! ([`crate::mice_calibration::MiceMounting::displacement`]).
//!
//! # The manual's formulas, with their typos fixed
//!
//! 1. **Eq. (4.2)** prints `Δθ = √(r_l² + r_r² − 2 cos(γ) l_r l_l) / D · sign(ȳ_r − ȳ_l)`. The
//!    squares must be of the arc **lengths**, not the radii. Substituting `r = l / Δθ` into the
//!    cosine rule (4.1) `D² = r_r² + r_l² − 2 cos(γ) r_r r_l` gives `D² Δθ² = l_r² + l_l² −
//!    2 cos(γ) l_r l_l`, hence **`Δθ = √(l_r² + l_l² − 2 cos(γ) l_r l_l) / D · sign(ȳ_r − ȳ_l)`**.
//!    As printed the formula needs the radii, which need `Δθ`: it is circular, and wrong (test
//!    `typo_4_2_radii_instead_of_lengths`).
//! 2. **Eqs. (4.3), (4.4)** print `X_{t+1} = X_t + √(Δx² + Δy²) + cos(Θ_t + arctan(Δy/Δx))`
//!    (and `+ sin` for `Y`). The cos and sin terms **multiply** the distance: **`X_{t+1} = X_t +
//!    √(Δx² + Δy²) · cos(Θ_t + atan2(Δy, Δx))`**, **`Y_{t+1} = Y_t + √(Δx² + Δy²) · sin(Θ_t +
//!    atan2(Δy, Δx))`** (test `typo_4_3_4_4_plus_instead_of_times`).
//! 3. In the same equations `arctan(Δy/Δx)` must be the two-argument **`atan2(Δy, Δx)`**:
//!    `arctan` of the ratio loses the quadrant (a step backwards, `Δx < 0`, would be added
//!    forwards) and divides by zero for a sideways step or a turn in place (test
//!    `typo_4_3_4_4_arctan_loses_the_quadrant`).
//! 4. `sign(0)` must be 0 in (4.2): with `ȳ_r = ȳ_l` the robot does not turn. (Rust's
//!    `f64::signum(0.0)` is `1.0`.)
//!
//! # Numerics
//!
//! The radicand of (4.2) is evaluated as `(l_r − l_l)² + 4 l_r l_l sin²(γ/2)`, the same value
//! (`cos γ = 1 − 2 sin²(γ/2)`) without the cancellation of the printed form when both mice read
//! nearly the same vector (straight runs). The chord of each mouse's arc, `2 r sin(|Δθ|/2)` with
//! `r = l / |Δθ|`, is evaluated as `l · sinc(Δθ/2)`, finite when `Δθ = 0`.

use crate::error::{non_negative, PerceptionError};
use mrt_core::{arc_velocity, sinc, Pose2};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;

pub use mrt_msgs::{Displacement, MiceReadings};

/// The intermediate quantities of the manual's derivation (§4.1), for inspection and tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MiceArcs {
    /// `l_l`: arc length of the left mouse, m.
    pub length_left: f64,
    /// `l_r`: arc length of the right mouse, m.
    pub length_right: f64,
    /// `α_l`: angle from the left mouse's x axis to its direction of motion, rad.
    pub alpha_left: f64,
    /// `α_r`: the same for the right mouse, rad.
    pub alpha_right: f64,
    /// `γ = |α_r − α_l|`, the angle between the two radii, rad.
    pub gamma: f64,
    /// `Δθ`, eq. (4.2) corrected, rad.
    pub dtheta: f64,
    /// `r_l = l_l / |Δθ|`, m (infinite when the robot does not turn).
    pub radius_left: f64,
    /// `r_r = l_r / |Δθ|`, m.
    pub radius_right: f64,
}

/// The two-mice odometry sensor: mice `distance` (`D`) apart, and the tolerance of the
/// `x̄_r = x̄_l` check.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "MiceOdometryParams")]
pub struct MiceOdometry {
    distance: f64,
    tolerance: f64,
}

/// What a serialized [`MiceOdometry`] holds, checked by [`MiceOdometry::new`] when read.
#[derive(Deserialize)]
struct MiceOdometryParams {
    distance: f64,
    tolerance: f64,
}

impl TryFrom<MiceOdometryParams> for MiceOdometry {
    type Error = PerceptionError;
    fn try_from(p: MiceOdometryParams) -> Result<Self, PerceptionError> {
        MiceOdometry::new(p.distance, p.tolerance)
    }
}

/// `sign` with `sign(0) = 0`, as in eq. (4.2).
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// How far apart two mice on a robot can be, m: eq. (4.1) divides by this distance, so one
/// of a millimetre would turn every reading's last bit into a spin, and mice farther apart
/// than 2 m are not on one robot.
pub const MICE_DISTANCE: std::ops::RangeInclusive<f64> = 0.01..=2.0;

impl MiceOdometry {
    /// A sensor with the mice `distance` metres apart (within [`MICE_DISTANCE`]); readings
    /// whose `x̄` differ by more than `tolerance` metres (finite, ≥ 0) fail
    /// [`MiceOdometry::check`].
    pub fn new(distance: f64, tolerance: f64) -> Result<Self, PerceptionError> {
        if !MICE_DISTANCE.contains(&distance) {
            return Err(PerceptionError::InvalidParameter {
                name: "distance",
                value: distance,
                expected: "between 0.01 and 2 m (MICE_DISTANCE)",
            });
        }
        Ok(Self { distance, tolerance: non_negative("tolerance", tolerance)? })
    }

    /// `D`, metres.
    pub const fn distance(&self) -> f64 {
        self.distance
    }

    /// The tolerance of the consistency check, metres.
    pub const fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The error detection of §4.1/§4.2: the readings are finite and `|x̄_r − x̄_l| <=
    /// tolerance`. Passing does not prove the readings right, only that they fit the model.
    pub fn check(&self, r: &MiceReadings) -> Result<(), PerceptionError> {
        if !r.is_finite() {
            return Err(PerceptionError::NonFiniteInput { name: "mice readings" });
        }
        if (r.x_right - r.x_left).abs() > self.tolerance {
            return Err(PerceptionError::MiceInconsistent {
                x_left: r.x_left,
                x_right: r.x_right,
                tolerance: self.tolerance,
            });
        }
        Ok(())
    }

    /// Arc lengths, angles and radii of §4.1, and `Δθ` by the cosine rule (eq. 4.1, 4.2
    /// corrected). No check.
    pub fn arcs(&self, r: &MiceReadings) -> MiceArcs {
        // l and α of each mouse, in its own frame (x̄ to the right, ȳ forward).
        let length_left = r.x_left.hypot(r.y_left);
        let length_right = r.x_right.hypot(r.y_right);
        let alpha_left = r.y_left.atan2(r.x_left);
        let alpha_right = r.y_right.atan2(r.x_right);
        let gamma = (alpha_right - alpha_left).abs();
        // Eq. (4.2), corrected: l², not r², under the root (see the module doc, typo 1);
        // l_r² + l_l² − 2 cos(γ) l_r l_l rewritten as (l_r − l_l)² + 4 l_r l_l sin²(γ/2).
        let half = (0.5 * gamma).sin();
        let radicand =
            (length_right - length_left).powi(2) + 4.0 * length_right * length_left * half * half;
        let dtheta = radicand.max(0.0).sqrt() / self.distance * sign(r.y_right - r.y_left);
        // r = l / θ: both mice turn by the same angle Δθ.
        let radius = |l: f64| if dtheta == 0.0 { f64::INFINITY } else { l / dtheta.abs() };
        MiceArcs {
            length_left,
            length_right,
            alpha_left,
            alpha_right,
            gamma,
            dtheta,
            radius_left: radius(length_left),
            radius_right: radius(length_right),
        }
    }

    /// The robot's motion from the four readings, as the manual derives it (§4.1): `Δθ` by the
    /// cosine rule, the radii `l / Δθ`, the new position of each mouse at the end of its arc,
    /// and the robot's new position as their mid-point. Fails if [`MiceOdometry::check`]
    /// does.
    ///
    /// Valid for `|Δθ| < π` per period (the sign rule of eq. 4.2).
    pub fn displacement(&self, r: &MiceReadings) -> Result<Displacement, PerceptionError> {
        self.check(r)?;
        Ok(self.displacement_unchecked(r))
    }

    /// [`MiceOdometry::displacement`] without the check: inconsistent readings give the
    /// manual's formulas applied as they are; non-finite ones give NaN.
    pub fn displacement_unchecked(&self, r: &MiceReadings) -> Displacement {
        let a = self.arcs(r);
        let half_turn = 0.5 * a.dtheta;
        // Each mouse ends its arc at its start plus the chord: length 2 r sin(|Δθ|/2) =
        // l sinc(Δθ/2), direction = initial direction of motion + Δθ/2. The initial direction in
        // the robot frame is α − π/2 (the mouse x axis points to the robot's right).
        let chord = |l: f64, alpha: f64| {
            let len = l * sinc(half_turn);
            let (s, c) = (alpha - FRAC_PI_2 + half_turn).sin_cos();
            (len * c, len * s)
        };
        let half_d = 0.5 * self.distance;
        let (clx, cly) = chord(a.length_left, a.alpha_left);
        let (crx, cry) = chord(a.length_right, a.alpha_right);
        let left_new = (clx, half_d + cly);
        let right_new = (crx, -half_d + cry);
        // The robot is the mid-point of the mice.
        Displacement::new(
            0.5 * (left_new.0 + right_new.0),
            0.5 * (left_new.1 + right_new.1),
            a.dtheta,
        )
    }

    /// The robot's motion from readings that can be trusted, and whether it needed the §4.2
    /// reduction ([`MiceOdometry::reduce`]); `None` when they cannot (then the wheels are the
    /// better guess). A reduction that scales a reading by more than 2 is refused: a mouse
    /// under-reads by at most half in the sensor model, and a larger factor amplifies noise in
    /// a small `x̄`.
    pub fn motion(&self, r: &MiceReadings) -> Option<(Displacement, bool)> {
        match self.displacement(r) {
            Ok(d) => Some((d, false)),
            Err(PerceptionError::MiceInconsistent { .. }) => {
                let fixed = self.reduce(r).ok()?;
                let grew = |a: f64, b: f64, c: f64, d: f64| a.hypot(b) <= 2.0 * c.hypot(d);
                let plausible = grew(fixed.x_left, fixed.y_left, r.x_left, r.y_left)
                    && grew(fixed.x_right, fixed.y_right, r.x_right, r.y_right);
                plausible.then(|| self.displacement(&fixed).ok().map(|d| (d, true))).flatten()
            }
            Err(_) => None,
        }
    }

    /// The forward model, for a simulator: what each mouse reads, in its own frame, when the
    /// robot moves by `(dx, dy, dtheta)` (robot frame at the start) along an arc in one
    /// sampling period. The robot's constant velocity `(vx, vy)` over the period follows from
    /// the arc; a mouse at `p` moves at `v + ω × p` in the (turning) robot frame, constant over
    /// the period, so it reads that times the period. Always `x̄_l = x̄_r`.
    ///
    /// Valid for `|dtheta| < π` (the range [`MiceOdometry::displacement`] can invert).
    pub fn readings_for(&self, dx: f64, dy: f64, dtheta: f64) -> MiceReadings {
        let (vx, vy) = arc_velocity(dx, dy, dtheta);
        let half = 0.5 * self.distance * dtheta;
        // Left mouse at (0, D/2): (vx − ω D/2, vy); right at (0, −D/2): (vx + ω D/2, vy).
        // Mouse frame: x̄ = −(robot y), ȳ = robot x.
        MiceReadings::new(-vy, vx - half, -vy, vx + half)
    }

    /// The error reduction of §4.2. A mouse never reads more than it moved (it misses motion
    /// when it lifts or the floor is too uniform), and a miss shortens its reading without
    /// changing its direction `α`. So when `x̄_r ≠ x̄_l`, the mouse with the smaller `|x̄|`
    /// under-read: its reading is scaled up until its `x̄` equals the other's. If only that
    /// mouse erred, this restores the true readings; otherwise it reduces the error.
    ///
    /// Consistent readings are returned unchanged. Fails on non-finite readings, or when the
    /// two `x̄` have opposite signs or the short one is 0 (no direction to scale along).
    pub fn reduce(&self, r: &MiceReadings) -> Result<MiceReadings, PerceptionError> {
        match self.check(r) {
            Ok(()) => return Ok(*r),
            Err(PerceptionError::MiceInconsistent { .. }) => {}
            Err(e) => return Err(e),
        }
        let irreducible = PerceptionError::MiceIrreducible { x_left: r.x_left, x_right: r.x_right };
        if r.x_left * r.x_right <= 0.0 {
            return Err(irreducible);
        }
        let mut out = *r;
        if r.x_left.abs() < r.x_right.abs() {
            let k = r.x_right / r.x_left;
            out.x_left = r.x_right;
            out.y_left = r.y_left * k;
        } else {
            let k = r.x_left / r.x_right;
            out.x_right = r.x_left;
            out.y_right = r.y_right * k;
        }
        Ok(out)
    }
}

/// The absolute pose after a displacement, eqs. (4.3)–(4.5) with their typos fixed (module doc,
/// typos 2 and 3):
///
/// `X' = X + √(Δx² + Δy²) · cos(Θ + atan2(Δy, Δx))`,
/// `Y' = Y + √(Δx² + Δy²) · sin(Θ + atan2(Δy, Δx))`, `Θ' = Θ + Δθ`.
///
/// The same as `pose.compose(&d.as_pose())`.
pub fn update_pose(pose: &Pose2, d: &Displacement) -> Pose2 {
    let dist = d.dx.hypot(d.dy);
    let dir = pose.theta + d.dy.atan2(d.dx);
    Pose2::new(pose.x + dist * dir.cos(), pose.y + dist * dir.sin(), pose.theta + d.dtheta)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::PI;

    /// Reading a sensor from a file checks it like `new` does: `D = 0` would divide by zero.
    #[test]
    fn deserializing_checks_the_parameters() {
        let ok: MiceOdometry =
            serde_json::from_str(r#"{"distance": 0.2, "tolerance": 0.001}"#).unwrap();
        assert_eq!(ok, MiceOdometry::new(0.2, 0.001).unwrap());
        assert!(serde_json::from_str::<MiceOdometry>(r#"{"distance": 0.0, "tolerance": 0.001}"#)
            .is_err());
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    fn mice() -> MiceOdometry {
        // D = 0.2 m, 1 mm tolerance.
        match MiceOdometry::new(0.2, 1e-3) {
            Ok(m) => m,
            Err(e) => panic!("{e}"),
        }
    }

    fn disp(m: &MiceOdometry, r: MiceReadings) -> Displacement {
        match m.displacement(&r) {
            Ok(d) => d,
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn straight_forward_and_sideways() {
        let m = mice();
        // 10 cm forward: both mice read ȳ = 0.1, x̄ = 0.
        assert_eq!(m.readings_for(0.1, 0.0, 0.0), MiceReadings::new(0.0, 0.1, 0.0, 0.1));
        let d = disp(&m, MiceReadings::new(0.0, 0.1, 0.0, 0.1));
        assert!(close(d.dx, 0.1) && close(d.dy, 0.0) && d.dtheta == 0.0, "{d:?}");
        // 5 cm to the left: both read x̄ = −0.05 (their x axes point right).
        assert_eq!(m.readings_for(0.0, 0.05, 0.0), MiceReadings::new(-0.05, 0.0, -0.05, 0.0));
        let d = disp(&m, MiceReadings::new(-0.05, 0.0, -0.05, 0.0));
        assert!(close(d.dx, 0.0) && close(d.dy, 0.05) && d.dtheta == 0.0, "{d:?}");
        let a = m.arcs(&MiceReadings::new(0.0, 0.1, 0.0, 0.1));
        assert!(a.radius_left.is_infinite() && a.gamma == 0.0);
    }

    #[test]
    fn pure_rotation() {
        let m = mice();
        // Turning 0.1 rad counter-clockwise in place: each mouse runs an arc of radius D/2 = 0.1
        // and length 0.1 · 0.1 = 0.01, the right one forwards, the left one backwards.
        let r = MiceReadings::new(0.0, -0.01, 0.0, 0.01);
        let f = m.readings_for(0.0, 0.0, 0.1);
        assert!(close(f.y_left, -0.01) && close(f.y_right, 0.01) && f.x_left == 0.0, "{f:?}");
        let a = m.arcs(&r);
        // α_l = −90°, α_r = 90° → γ = π, cos γ = −1:
        // Δθ = √(0.01² + 0.01² + 2·0.01·0.01) / 0.2 = 0.02 / 0.2 = 0.1; radii 0.01/0.1 = 0.1.
        assert!(close(a.gamma, PI) && close(a.dtheta, 0.1), "{a:?}");
        assert!(close(a.radius_left, 0.1) && close(a.radius_right, 0.1));
        let d = disp(&m, r);
        // The mid-point does not move.
        assert!(close(d.dx, 0.0) && close(d.dy, 0.0) && close(d.dtheta, 0.1), "{d:?}");
        // Clockwise: the signs swap.
        let d = disp(&m, MiceReadings::new(0.0, 0.01, 0.0, -0.01));
        assert!(close(d.dx, 0.0) && close(d.dy, 0.0) && close(d.dtheta, -0.1), "{d:?}");
    }

    #[test]
    fn arcs_left_and_right() {
        let m = mice();
        // Left arc: the centre of rotation 1 m to the left, Δθ = 0.1. The robot's arc is
        // 0.1 m long; the right mouse's radius is 1.1 (arc 0.11), the left's 0.9 (arc 0.09).
        let r = MiceReadings::new(0.0, 0.09, 0.0, 0.11);
        let a = m.arcs(&r);
        // γ = 0: Δθ = √(0.11² + 0.09² − 2·0.11·0.09) / 0.2 = 0.02 / 0.2 = 0.1.
        assert!(a.gamma == 0.0 && close(a.dtheta, 0.1), "{a:?}");
        assert!(close(a.radius_left, 0.9) && close(a.radius_right, 1.1), "{a:?}");
        // The robot ends on the circle of radius 1 around (0, 1): (sin 0.1, 1 − cos 0.1) =
        // (0.0998334166, 0.0049958347).
        let d = disp(&m, r);
        assert!(close(d.dx, 0.1f64.sin()) && close(d.dy, 1.0 - 0.1f64.cos()), "{d:?}");
        assert!((d.dx - 0.099_833_416_6).abs() < 1e-10 && (d.dy - 0.004_995_834_7).abs() < 1e-10);
        assert!(close(d.dtheta, 0.1));
        // Right arc: the mirror image.
        let d = disp(&m, MiceReadings::new(0.0, 0.11, 0.0, 0.09));
        assert!(close(d.dx, 0.1f64.sin()) && close(d.dy, -(1.0 - 0.1f64.cos())), "{d:?}");
        assert!(close(d.dtheta, -0.1));
        // And the forward model gives those readings back.
        let f = m.readings_for(0.1f64.sin(), 1.0 - 0.1f64.cos(), 0.1);
        assert!(close(f.y_left, 0.09) && close(f.y_right, 0.11) && close(f.x_left, 0.0), "{f:?}");
    }

    #[test]
    fn arc_with_a_sideways_component() {
        let m = mice();
        // Holonomic motion: constant body velocity (0.1, 0.05) per period while turning 0.2.
        // Left mouse: (0.1 − 0.2·0.1, 0.05) = (0.08, 0.05) → x̄ = −0.05, ȳ = 0.08;
        // right mouse: (0.12, 0.05) → x̄ = −0.05, ȳ = 0.12.
        let r = MiceReadings::new(-0.05, 0.08, -0.05, 0.12);
        let a = m.arcs(&r);
        // l_l = √(0.0089), l_r = √(0.0169) = 0.13, γ = atan2(0.12, −0.05) − atan2(0.08, −0.05)
        // = |1.965587 − 2.129396| = 0.163808;
        // l_r² + l_l² − 2 cos γ l_r l_l = 0.0169 + 0.0089 − 2·0.986614·0.13·0.0943398 = 0.0016
        // = 0.04² → Δθ = 0.04 / 0.2 = 0.2.
        assert!((a.gamma - 0.163_808).abs() < 1e-6 && close(a.dtheta, 0.2), "{a:?}");
        // Robot: sinc(0.1)·R(0.1)·(0.1, 0.05), sinc(0.1) = 0.998334166:
        // R(0.1)(0.1, 0.05) = (0.0995004 − 0.0049917, 0.0099833 + 0.0497502)
        //                   = (0.0945087, 0.0597335) → (0.0943513, 0.0596340).
        let d = disp(&m, r);
        assert!((d.dx - 0.094_351_3).abs() < 1e-7 && (d.dy - 0.059_634_0).abs() < 1e-7, "{d:?}");
    }

    #[test]
    fn constraint_is_checked() {
        let m = mice();
        // x̄ differ by 2 mm > 1 mm.
        let bad = MiceReadings::new(0.010, 0.1, 0.012, 0.1);
        assert_eq!(
            m.displacement(&bad),
            Err(PerceptionError::MiceInconsistent {
                x_left: 0.010,
                x_right: 0.012,
                tolerance: 1e-3
            })
        );
        // 0.5 mm: within tolerance.
        assert!(m.displacement(&MiceReadings::new(0.010, 0.1, 0.0105, 0.1)).is_ok());
        assert!(matches!(
            m.displacement(&MiceReadings::new(f64::NAN, 0.1, 0.0, 0.1)),
            Err(PerceptionError::NonFiniteInput { .. })
        ));
        // The unchecked form still answers (by the manual's formulas as they are).
        let d = m.displacement_unchecked(&bad);
        assert!(d.dx.is_finite() && d.dtheta.is_finite());
        for d in [0.0, 1e-300, 0.009, 2.5, 1e6, f64::NAN, f64::INFINITY] {
            assert!(MiceOdometry::new(d, 1e-3).is_err(), "{d}");
        }
        assert!(MiceOdometry::new(0.01, 1e-3).is_ok() && MiceOdometry::new(2.0, 1e-3).is_ok());
        assert!(MiceOdometry::new(0.2, -1.0).is_err());
    }

    #[test]
    fn reduction_restores_a_mouse_that_under_read() {
        let m = mice();
        // True readings of the sideways arc above; the left mouse lost 40 % of its motion:
        // (−0.05, 0.08)·0.6 = (−0.03, 0.048). Scaling it by x̄_r/x̄_l = 5/3 restores it.
        let faulty = MiceReadings::new(-0.03, 0.048, -0.05, 0.12);
        assert!(m.check(&faulty).is_err());
        let fixed = match m.reduce(&faulty) {
            Ok(f) => f,
            Err(e) => panic!("{e}"),
        };
        assert!(close(fixed.x_left, -0.05) && close(fixed.y_left, 0.08), "{fixed:?}");
        assert_eq!((fixed.x_right, fixed.y_right), (-0.05, 0.12));
        // Same with the right mouse at fault.
        let fixed = m.reduce(&MiceReadings::new(-0.05, 0.08, -0.025, 0.06));
        assert!(matches!(fixed, Ok(f) if close(f.x_right, -0.05) && close(f.y_right, 0.12)));
        // Consistent: unchanged. Opposite signs, or a mouse that read nothing: irreducible.
        let ok = MiceReadings::new(0.0, 0.1, 0.0, 0.1);
        assert_eq!(m.reduce(&ok), Ok(ok));
        assert!(matches!(
            m.reduce(&MiceReadings::new(0.01, 0.1, -0.01, 0.1)),
            Err(PerceptionError::MiceIrreducible { .. })
        ));
        assert!(matches!(
            m.reduce(&MiceReadings::new(0.0, 0.0, -0.05, 0.1)),
            Err(PerceptionError::MiceIrreducible { .. })
        ));
    }

    /// Typo 4: `sign(0)` is 0. Readings with `ȳ_r = ȳ_l` but `x̄` off by 2 mm (unchecked):
    /// the radicand is 0.002² > 0, so with Rust's `signum(0.0) = 1` the robot would turn
    /// +0.002 / 0.2 = +0.01 rad; by the manual, `sign(0) = 0`: no turn.
    #[test]
    fn typo_sign_of_zero() {
        let m = mice();
        let r = MiceReadings::new(0.0, 0.1, 0.002, 0.1);
        let literal_signum = ((r.x_right - r.x_left).powi(2)).sqrt() / 0.2 * 0.0f64.signum();
        assert!(close(literal_signum, 0.01));
        assert_eq!(m.arcs(&r).dtheta, 0.0);
    }

    /// Typo 1: eq. (4.2) as printed, with the radii squared under the root.
    #[test]
    fn typo_4_2_radii_instead_of_lengths() {
        let m = mice();
        // Pure rotation by 0.1 (test above): l = 0.01, r = 0.1, γ = π.
        let (l, r, gamma, d) = (0.01f64, 0.1f64, PI, 0.2);
        let printed = (r * r + r * r - 2.0 * gamma.cos() * l * l).sqrt() / d;
        let corrected = (l * l + l * l - 2.0 * gamma.cos() * l * l).sqrt() / d;
        // Printed: √(0.01 + 0.01 + 0.0002) / 0.2 = √0.0202 / 0.2 = 0.710634; corrected: 0.1.
        assert!((printed - 0.710_633_5).abs() < 1e-6, "{printed}");
        assert!(close(corrected, 0.1));
        assert!(close(m.arcs(&MiceReadings::new(0.0, -0.01, 0.0, 0.01)).dtheta, corrected));
        // The library's cancellation-free radicand equals the printed cosine-rule form, e.g.
        // on the sideways arc: (l_r − l_l)² + 4 l_r l_l sin²(γ/2) = l_r² + l_l² − 2 cos γ l_r l_l.
        let a = m.arcs(&MiceReadings::new(-0.05, 0.08, -0.05, 0.12));
        let cosine_rule = (a.length_right.powi(2) + a.length_left.powi(2)
            - 2.0 * a.gamma.cos() * a.length_right * a.length_left)
            .sqrt()
            / 0.2;
        assert!((a.dtheta - cosine_rule).abs() < 1e-12);
    }

    /// Typo 2: eqs. (4.3), (4.4) add the cos/sin term instead of multiplying.
    #[test]
    fn typo_4_3_4_4_plus_instead_of_times() {
        // 0.1 m straight ahead from (0, 0) facing +x.
        let (x, y, th, dx, dy) = (0.0f64, 0.0f64, 0.0f64, 0.1f64, 0.0f64);
        let dist = (dx * dx + dy * dy).sqrt();
        let printed_x = x + dist + (th + (dy / dx).atan()).cos();
        let printed_y = y + dist + (th + (dy / dx).atan()).sin();
        // Printed: X = 0 + 0.1 + cos 0 = 1.1, Y = 0 + 0.1 + sin 0 = 0.1: nonsense.
        assert!(close(printed_x, 1.1) && close(printed_y, 0.1));
        let p = update_pose(&Pose2::identity(), &Displacement::new(dx, dy, 0.0));
        assert!(close(p.x, 0.1) && close(p.y, 0.0), "{p:?}");
        // From (1, 2) facing +y, 0.3 forward and 0.4 left (distance 0.5): the robot's left is
        // −x, so it ends at (1 − 0.4, 2 + 0.3) = (0.6, 2.3).
        let p = update_pose(&Pose2::new(1.0, 2.0, PI / 2.0), &Displacement::new(0.3, 0.4, 0.2));
        assert!(close(p.x, 0.6) && close(p.y, 2.3) && close(p.theta, PI / 2.0 + 0.2), "{p:?}");
    }

    /// Typo 3: `arctan(Δy/Δx)` loses the quadrant.
    #[test]
    fn typo_4_3_4_4_arctan_loses_the_quadrant() {
        // 0.1 m straight back from the origin facing +x: Δx = −0.1, Δy = 0.
        let (dx, dy) = (-0.1f64, 0.0f64);
        let dist = dx.hypot(dy);
        let with_arctan = dist * (dy / dx).atan().cos(); // arctan(−0) = −0 → +0.1: wrong way
        assert!(close(with_arctan, 0.1));
        let p = update_pose(&Pose2::identity(), &Displacement::new(dx, dy, 0.0));
        assert!(close(p.x, -0.1) && close(p.y, 0.0), "{p:?}");
        // Straight sideways: Δy/Δx = 1/0 — atan2 is fine.
        let p = update_pose(&Pose2::identity(), &Displacement::new(0.0, 0.1, 0.0));
        assert!(close(p.x, 0.0) && close(p.y, 0.1), "{p:?}");
    }

    proptest! {
        /// `displacement ∘ readings_for` is the identity on small motions, and the forward
        /// model always satisfies the manual's constraint `x̄_r = x̄_l`.
        #[test]
        fn readings_for_then_displacement_is_identity(dx in -0.2f64..0.2, dy in -0.2f64..0.2,
                                                      dth in -1.0f64..1.0) {
            let m = mice();
            let r = m.readings_for(dx, dy, dth);
            prop_assert_eq!(r.x_left, r.x_right);
            let d = m.displacement(&r);
            prop_assert!(d.is_ok());
            if let Ok(d) = d {
                prop_assert!((d.dx - dx).abs() < 1e-12 && (d.dy - dy).abs() < 1e-12
                    && (d.dtheta - dth).abs() < 1e-12, "{:?} vs ({}, {}, {})", d, dx, dy, dth);
            }
        }

        /// Eqs. (4.3)–(4.5) corrected equal composing the relative pose.
        #[test]
        fn update_pose_is_compose(x in -5.0f64..5.0, y in -5.0f64..5.0, th in -3.0f64..3.0,
                                  dx in -0.3f64..0.3, dy in -0.3f64..0.3, dth in -0.5f64..0.5) {
            let pose = Pose2::new(x, y, th);
            let d = Displacement::new(dx, dy, dth);
            let a = update_pose(&pose, &d);
            let b = pose.compose(&d.as_pose());
            prop_assert!((a.x - b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12);
            prop_assert!(mrt_core::angle_diff(a.theta, b.theta).abs() < 1e-12);
        }
    }
}
