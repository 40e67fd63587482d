//! 2D geometry used across MRT: vectors, points, poses and angles.
//!
//! Built on `nalgebra` (no hand-written linear algebra). A [`Pose2`] is a robot posture
//! `(x, y, θ)` on the field: position in metres, heading in radians, counter-clockwise from +x.

use nalgebra::{Isometry2, Vector2};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};

/// A 2D vector (displacement, velocity) in metres or metres per second.
pub type Vec2 = Vector2<f64>;

/// A 2D point (position) in metres.
pub type Point2 = nalgebra::Point2<f64>;

/// Normalizes an angle in radians to `(-π, π]`. Non-finite input is returned unchanged.
///
/// ```
/// # use mrt_core::normalize_angle;
/// use std::f64::consts::PI;
/// assert!((normalize_angle(3.0 * PI) - PI).abs() < 1e-12);
/// assert!((normalize_angle(-PI) - PI).abs() < 1e-12);
/// ```
pub fn normalize_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let r = a.rem_euclid(TAU); // [0, 2π)
    if r > PI {
        r - TAU
    } else {
        r
    }
}

/// Normalizes an angle in radians to `[0, 2π)`. Non-finite input is returned unchanged.
pub fn normalize_angle_positive(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let r = a.rem_euclid(TAU);
    // rem_euclid can round up to exactly TAU for tiny negative inputs.
    if r >= TAU {
        0.0
    } else {
        r
    }
}

/// The signed shortest rotation from `from` to `to`, in `(-π, π]`.
pub fn angle_diff(to: f64, from: f64) -> f64 {
    normalize_angle(to - from)
}

/// A velocity of a body in its own frame (the robot frame: x forward, y to the left): `vx`
/// forward and `vy` to the left in m/s, `omega` counter-clockwise in rad/s. What behaviors ask
/// of guidance, guidance of the motor driver, and a world's motor model does with the wheels.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Twist {
    /// Forward speed, m/s.
    pub vx: f64,
    /// Leftward speed, m/s (always 0 for a differential drive after its wheel limits).
    pub vy: f64,
    /// Turn rate, rad/s, counter-clockwise.
    pub omega: f64,
}

impl Twist {
    /// Standing still.
    pub const ZERO: Twist = Twist { vx: 0.0, vy: 0.0, omega: 0.0 };

    /// A twist.
    pub const fn new(vx: f64, vy: f64, omega: f64) -> Self {
        Self { vx, vy, omega }
    }

    /// True if all three components are finite.
    pub fn is_finite(&self) -> bool {
        self.vx.is_finite() && self.vy.is_finite() && self.omega.is_finite()
    }

    /// Every component multiplied by `k`.
    pub fn scaled(&self, k: f64) -> Twist {
        Twist::new(self.vx * k, self.vy * k, self.omega * k)
    }

    /// The translational speed `√(vx² + vy²)`, m/s.
    pub fn speed(&self) -> f64 {
        self.vx.hypot(self.vy)
    }

    /// With every component that is not finite set to 0: what a motor driver does with a
    /// broken set-point.
    pub fn finite_or_zero(&self) -> Twist {
        let f = |x: f64| if x.is_finite() { x } else { 0.0 };
        Twist::new(f(self.vx), f(self.vy), f(self.omega))
    }
}

/// A posture on the plane: position `(x, y)` and heading `theta` (radians, in `(-π, π]`).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Pose2 {
    /// x coordinate (in the caller's unit: the robot world snapshot uses millimetres).
    pub x: f64,
    /// y coordinate, same unit as `x`.
    pub y: f64,
    /// Heading, radians, normalized to `(-π, π]` by the constructors.
    pub theta: f64,
}

impl Pose2 {
    /// A pose; `theta` is normalized to `(-π, π]`.
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Self { x, y, theta: normalize_angle(theta) }
    }

    /// The pose at the origin, facing +x.
    pub const fn identity() -> Self {
        Self { x: 0.0, y: 0.0, theta: 0.0 }
    }

    /// The position part.
    pub fn position(&self) -> Point2 {
        Point2::new(self.x, self.y)
    }

    /// The unit vector of the heading.
    pub fn heading(&self) -> Vec2 {
        Vec2::new(self.theta.cos(), self.theta.sin())
    }

    /// As an `nalgebra` isometry (rotation then translation).
    pub fn to_isometry(&self) -> Isometry2<f64> {
        Isometry2::new(Vec2::new(self.x, self.y), self.theta)
    }

    /// From an `nalgebra` isometry.
    pub fn from_isometry(iso: &Isometry2<f64>) -> Self {
        Self::new(iso.translation.x, iso.translation.y, iso.rotation.angle())
    }

    /// `self ⊕ other`: the pose `other`, expressed in the frame of `self`, seen in `self`'s
    /// parent frame. E.g. field pose of a robot ⊕ a displacement measured by the robot.
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        Self::from_isometry(&(self.to_isometry() * other.to_isometry()))
    }

    /// The inverse pose: `p.compose(&p.inverse())` is the identity.
    pub fn inverse(&self) -> Pose2 {
        Self::from_isometry(&self.to_isometry().inverse())
    }

    /// `self` expressed in the frame of `reference` (`reference⁻¹ ⊕ self`).
    pub fn relative_to(&self, reference: &Pose2) -> Pose2 {
        reference.inverse().compose(self)
    }

    /// A point given in this pose's frame (e.g. the robot's), in the parent frame (the field).
    pub fn transform_point(&self, p: Point2) -> Point2 {
        self.to_isometry() * p
    }

    /// A point given in the parent frame (the field), in this pose's frame (the robot's).
    pub fn inverse_transform_point(&self, p: Point2) -> Point2 {
        self.to_isometry().inverse_transform_point(&p)
    }

    /// Euclidean distance between the positions of two poses.
    pub fn distance(&self, other: &Pose2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// `sin(x) / x`, with its Taylor series near 0 (no 0/0).
///
/// ```
/// assert_eq!(mrt_core::sinc(0.0), 1.0);
/// assert!((mrt_core::sinc(1.0) - 1f64.sin()).abs() < 1e-15);
/// ```
pub fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        let x2 = x * x;
        1.0 - x2 / 6.0 + x2 * x2 / 120.0
    } else {
        x.sin() / x
    }
}

/// The displacement `(dx, dy)` in the starting robot frame after moving with the constant body
/// velocity `(vx, vy)` (per unit time) while turning by `dtheta`: `sinc(dθ/2) · R(dθ/2) · (vx,
/// vy)`. The robot follows an arc of circle, the motion model of the MRT manual §4.1 ("the
/// robot movement during a sampling period can be approximated by an arc of circumference"),
/// shared by the kinematics (`mrt-plan`) and the two-mice odometry (`mrt-perception`).
pub fn arc_displacement(vx: f64, vy: f64, dtheta: f64) -> (f64, f64) {
    let (s, c) = (0.5 * dtheta).sin_cos();
    let k = sinc(0.5 * dtheta);
    (k * (c * vx - s * vy), k * (s * vx + c * vy))
}

/// The inverse of [`arc_displacement`]: the constant body velocity (per unit time) that moves
/// the robot by `(dx, dy)` while it turns by `dtheta`. Valid for `|dtheta| < 2π`.
pub fn arc_velocity(dx: f64, dy: f64, dtheta: f64) -> (f64, f64) {
    let (s, c) = (0.5 * dtheta).sin_cos();
    let k = 1.0 / sinc(0.5 * dtheta);
    (k * (c * dx + s * dy), k * (-s * dx + c * dy))
}

/// The runs of neighbours on a ring of `n` items in order, the last next to the first (a sonar
/// ring round a body): items `k` and `k + 1` are in one run while `joined(k, k + 1)` (indices
/// taken round the ring). Each run lists its items' indices in ring order; the first run
/// starts after a break, so that no run wraps, and a ring joined all round is one run.
pub fn ring_runs(n: usize, joined: impl Fn(usize, usize) -> bool) -> Vec<Vec<usize>> {
    let start = (0..n).find(|&k| !joined((k + n - 1) % n, k)).unwrap_or(0);
    let mut runs = Vec::new();
    let mut run = Vec::new();
    for k in start..start + n {
        run.push(k % n);
        if !joined(k % n, (k + 1) % n) || k + 1 == start + n {
            runs.push(std::mem::take(&mut run));
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_runs_split_at_breaks_and_never_wrap() {
        // Items 0..6; joined pairs (5, 0), (0, 1) and (3, 4): runs {5, 0, 1}, {2}, {3, 4}.
        let joined = |a: usize, b: usize| matches!((a, b), (5, 0) | (0, 1) | (3, 4));
        assert_eq!(ring_runs(6, joined), [vec![2], vec![3, 4], vec![5, 0, 1]]);
        assert_eq!(ring_runs(3, |_, _| true), [vec![0, 1, 2]], "joined all round");
        assert_eq!(ring_runs(3, |_, _| false), [vec![0], vec![1], vec![2]]);
        assert!(ring_runs(0, |_, _| true).is_empty());
    }
    use proptest::prelude::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn normalize_angle_edges() {
        assert!(close(normalize_angle(0.0), 0.0));
        assert!(close(normalize_angle(PI), PI));
        assert!(close(normalize_angle(-PI), PI));
        assert!(close(normalize_angle(3.0 * FRAC_PI_2), -FRAC_PI_2));
        assert!(close(normalize_angle_positive(-FRAC_PI_2), 3.0 * FRAC_PI_2));
        assert!(normalize_angle(f64::NAN).is_nan());
        assert!(close(angle_diff(-3.0, 3.0), TAU - 6.0));
    }

    #[test]
    fn compose_and_points_by_hand() {
        // Robot at (1, 2) facing +y; 1 m ahead and 1 m to its left is (0, 3).
        let robot = Pose2::new(1.0, 2.0, FRAC_PI_2);
        let p = robot.transform_point(Point2::new(1.0, 1.0));
        assert!(close(p.x, 0.0) && close(p.y, 3.0));
        let back = robot.inverse_transform_point(p);
        assert!(close(back.x, 1.0) && close(back.y, 1.0));
        // Moving 1 m forward and turning left by 90° from there.
        let moved = robot.compose(&Pose2::new(1.0, 0.0, FRAC_PI_2));
        assert!(close(moved.x, 1.0) && close(moved.y, 3.0) && close(moved.theta, PI));
        assert!(close(robot.distance(&moved), 1.0));
        assert!(close(robot.heading().y, 1.0));
    }

    proptest! {
        #[test]
        fn arc_velocity_inverts_arc_displacement(vx in -1.0f64..1.0, vy in -1.0f64..1.0,
                                                 dth in -3.0f64..3.0) {
            let (dx, dy) = arc_displacement(vx, vy, dth);
            let (bx, by) = arc_velocity(dx, dy, dth);
            prop_assert!(close(bx, vx) && close(by, vy));
        }

        #[test]
        fn normalize_angle_is_in_range_and_equivalent(a in -1e4f64..1e4) {
            let n = normalize_angle(a);
            prop_assert!(n > -PI - 1e-12 && n <= PI + 1e-12);
            prop_assert!(close(n.sin(), a.sin()) && close(n.cos(), a.cos()));
            let p = normalize_angle_positive(a);
            prop_assert!((0.0..TAU).contains(&p));
        }

        #[test]
        fn pose_inverse_composes_to_identity(x in -10.0f64..10.0, y in -10.0f64..10.0, t in -7.0f64..7.0) {
            let p = Pose2::new(x, y, t);
            let id = p.compose(&p.inverse());
            prop_assert!(close(id.x, 0.0) && close(id.y, 0.0) && close(id.theta.sin(), 0.0));
            let r = Pose2::new(1.0, -2.0, 0.3);
            let back = r.compose(&p.relative_to(&r));
            prop_assert!(close(back.x, p.x) && close(back.y, p.y) && close(angle_diff(back.theta, p.theta), 0.0));
        }
    }
}
