//! Robot kinematics: twists, wheel speeds, the two MRT bases, and exact pose integration.
//!
//! - [`DiffDrive`]: the bi-directional IANUS3 base, "two independent, central, traction wheels",
//!   "can run up to 1.2 m/s" (MRT manual §12.5).
//! - [`Omni3`]: the holonomic Triskar base, "three independent, traction, omnidirectional wheels
//!   [...] placed at 120 degrees from each other" (MRT manual §12.6).
//!
//! Both implement [`Kinematics`]: wheel speeds from a [`Twist`] and back, a [`Kinematics::limit`]
//! that scales a twist so no wheel exceeds its top speed, and a [`Kinematics::ramp`] that bounds
//! wheel accelerations. The wheel speeds are the set points of the AIRBoard acting module, one per
//! motor (ch. 5); [`duty_cycle`] turns one into the open-loop PWM fraction of §5.1.
//!
//! Frames and units: the robot frame has x forward, y to the left, angles counter-clockwise;
//! speeds are m/s, rad/s; wheel speeds are wheel angular speeds in rad/s (positive = the wheel
//! pushes the robot forward for a differential drive, counter-clockwise about the robot centre
//! for an omni wheel).

use crate::error::{positive, PlanError};
pub use mrt_core::Twist;
use mrt_core::{arc_displacement, Pose2};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Wheel angular speeds (rad/s), one per wheel: `[left, right]` for a [`DiffDrive`], wheels in
/// the order of [`Omni3Params::wheel_angles`] for an [`Omni3`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WheelSpeeds<const N: usize>(pub [f64; N]);

/// The two wheels of a [`DiffDrive`], `[left, right]`.
pub type DiffWheels = WheelSpeeds<2>;

/// The three wheels of an [`Omni3`].
pub type OmniWheels = WheelSpeeds<3>;

impl<const N: usize> Default for WheelSpeeds<N> {
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl<const N: usize> WheelSpeeds<N> {
    /// The largest absolute wheel speed (NaN if any is NaN).
    pub fn max_abs(&self) -> f64 {
        self.0.iter().fold(0.0, |m: f64, w| if w.is_nan() { f64::NAN } else { m.max(w.abs()) })
    }

    /// True if every speed is finite.
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|w| w.is_finite())
    }

    /// Every speed multiplied by `k`.
    pub fn scaled(&self, k: f64) -> Self {
        Self(self.0.map(|w| w * k))
    }

    /// Non-finite speeds replaced by 0 (a NaN must never reach a motor).
    fn sanitized(&self) -> Self {
        Self(self.0.map(|w| if w.is_finite() { w } else { 0.0 }))
    }
}

impl WheelSpeeds<2> {
    /// A differential drive's wheels.
    pub const fn new(left: f64, right: f64) -> Self {
        Self([left, right])
    }

    /// The left wheel, rad/s.
    pub const fn left(&self) -> f64 {
        self.0[0]
    }

    /// The right wheel, rad/s.
    pub const fn right(&self) -> f64 {
        self.0[1]
    }
}

/// The turn that brings a differential drive's front or back, whichever is nearer, onto a
/// direction `err` radians off its heading (`err` in [−π, π]): `err` itself within ±π/2,
/// else folded by π into that range.
pub fn nearer_end(err: f64) -> f64 {
    if err > std::f64::consts::FRAC_PI_2 {
        err - std::f64::consts::PI
    } else if err < -std::f64::consts::FRAC_PI_2 {
        err + std::f64::consts::PI
    } else {
        err
    }
}

/// Whether a base can move sideways.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Steering {
    /// Any twist is feasible (Triskar).
    #[default]
    Holonomic,
    /// `vy` is always 0 (IANUS3); the base moves forward and backward equally well.
    Differential,
}

/// The model of a wheeled base.
pub trait Kinematics {
    /// One speed per wheel, rad/s.
    type Wheels: Copy + std::fmt::Debug + PartialEq;

    /// Holonomic or differential.
    fn steering(&self) -> Steering;

    /// The top speed of every wheel, rad/s.
    fn max_wheel_speed(&self) -> f64;

    /// Wheel speeds that realise `twist` (for a differential drive `vy` is ignored). A plain
    /// linear map: no limit is applied.
    fn inverse(&self, twist: &Twist) -> Self::Wheels;

    /// The twist that `wheels` produce.
    fn forward(&self, wheels: &Self::Wheels) -> Twist;

    /// `twist` made feasible: a differential drive drops `vy`, then the whole twist is scaled
    /// down by one factor so that no wheel exceeds [`Kinematics::max_wheel_speed`]. A single
    /// factor keeps the direction of motion and the path curvature (`omega / v`). A non-finite
    /// twist gives [`Twist::ZERO`].
    fn limit(&self, twist: &Twist) -> Twist;

    /// One control step from `current` toward `target` wheel speeds in `dt` seconds with no
    /// wheel changing by more than `max_wheel_accel · dt`. The change is scaled by one factor
    /// for all wheels (clamping each wheel alone would bend the path while accelerating);
    /// `target` is first scaled into the top speed as in [`Kinematics::limit`]. Non-finite
    /// speeds count as 0; `dt <= 0` or non-finite returns `current`.
    fn ramp(&self, current: &Self::Wheels, target: &Self::Wheels, dt: f64) -> Self::Wheels;
}

/// Scales a feasible-direction twist into the wheel speed limit.
fn limit_with<const N: usize>(twist: Twist, wheels: WheelSpeeds<N>, max_wheel_speed: f64) -> Twist {
    let m = wheels.max_abs();
    if m > max_wheel_speed {
        twist.scaled(max_wheel_speed / m)
    } else {
        twist
    }
}

/// The ramp shared by both bases.
fn ramp_with<const N: usize>(
    current: &WheelSpeeds<N>,
    target: &WheelSpeeds<N>,
    dt: f64,
    max_wheel_speed: f64,
    max_wheel_accel: f64,
) -> WheelSpeeds<N> {
    let current = current.sanitized();
    if !(dt.is_finite() && dt > 0.0) {
        return current;
    }
    let mut target = target.sanitized();
    let top = target.max_abs();
    if top > max_wheel_speed {
        target = target.scaled(max_wheel_speed / top);
    }
    let mut delta = [0.0; N];
    for (d, (t, c)) in delta.iter_mut().zip(target.0.iter().zip(current.0.iter())) {
        *d = t - c;
    }
    let largest = WheelSpeeds(delta).max_abs();
    let step = max_wheel_accel * dt;
    if largest <= step {
        return target;
    }
    let k = step / largest;
    let mut out = current.0;
    for (o, d) in out.iter_mut().zip(delta.iter()) {
        *o += d * k;
    }
    WheelSpeeds(out)
}

/// The parameters of a [`DiffDrive`] (also its serde form).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiffDriveParams {
    /// Wheel radius, m (> 0).
    pub wheel_radius: f64,
    /// Distance between the two wheels' contact points, m (> 0).
    pub track: f64,
    /// Top wheel speed, rad/s (> 0).
    pub max_wheel_speed: f64,
    /// Top wheel acceleration, rad/s² (> 0).
    pub max_wheel_accel: f64,
}

impl DiffDriveParams {
    /// IANUS3 (manual ch. 12.5). The manual gives only the top speed, 1.2 m/s, and that the two
    /// wheels are central; radius 5 cm, track 40 cm and 3 m/s² are assumed (a Middle Size
    /// League body is at most 50 cm wide). Top wheel speed = 1.2 / 0.05 = 24 rad/s.
    pub const IANUS3: DiffDriveParams = DiffDriveParams {
        wheel_radius: 0.05,
        track: 0.40,
        max_wheel_speed: 24.0,
        max_wheel_accel: 60.0,
    };
}

/// A differential drive: two coaxial wheels a `track` apart, the robot centre half-way
/// between them (IANUS3).
///
/// `left = (vx − ω·track/2) / r`, `right = (vx + ω·track/2) / r`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DiffDriveParams", into = "DiffDriveParams")]
pub struct DiffDrive {
    params: DiffDriveParams,
}

impl DiffDrive {
    /// A base; every parameter must be finite and > 0.
    pub fn new(params: DiffDriveParams) -> Result<Self, PlanError> {
        positive("wheel_radius", params.wheel_radius)?;
        positive("track", params.track)?;
        positive("max_wheel_speed", params.max_wheel_speed)?;
        positive("max_wheel_accel", params.max_wheel_accel)?;
        Ok(Self { params })
    }

    /// The IANUS3 base ([`DiffDriveParams::IANUS3`]).
    pub const fn ianus3() -> Self {
        Self { params: DiffDriveParams::IANUS3 }
    }

    /// The parameters.
    pub const fn params(&self) -> &DiffDriveParams {
        &self.params
    }

    /// The top robot speed, m/s (`max_wheel_speed · wheel_radius`).
    pub fn max_speed(&self) -> f64 {
        self.params.max_wheel_speed * self.params.wheel_radius
    }
}

impl Default for DiffDrive {
    fn default() -> Self {
        Self::ianus3()
    }
}

impl TryFrom<DiffDriveParams> for DiffDrive {
    type Error = PlanError;
    fn try_from(p: DiffDriveParams) -> Result<Self, PlanError> {
        Self::new(p)
    }
}

impl From<DiffDrive> for DiffDriveParams {
    fn from(d: DiffDrive) -> Self {
        d.params
    }
}

impl Kinematics for DiffDrive {
    type Wheels = DiffWheels;

    fn steering(&self) -> Steering {
        Steering::Differential
    }

    fn max_wheel_speed(&self) -> f64 {
        self.params.max_wheel_speed
    }

    fn inverse(&self, twist: &Twist) -> DiffWheels {
        let p = &self.params;
        let half = 0.5 * p.track * twist.omega;
        DiffWheels::new((twist.vx - half) / p.wheel_radius, (twist.vx + half) / p.wheel_radius)
    }

    fn forward(&self, wheels: &DiffWheels) -> Twist {
        let p = &self.params;
        let (l, r) = (wheels.left() * p.wheel_radius, wheels.right() * p.wheel_radius);
        Twist::new(0.5 * (l + r), 0.0, (r - l) / p.track)
    }

    fn limit(&self, twist: &Twist) -> Twist {
        if !twist.is_finite() {
            return Twist::ZERO;
        }
        let t = Twist::new(twist.vx, 0.0, twist.omega);
        limit_with(t, self.inverse(&t), self.params.max_wheel_speed)
    }

    fn ramp(&self, current: &DiffWheels, target: &DiffWheels, dt: f64) -> DiffWheels {
        ramp_with(current, target, dt, self.params.max_wheel_speed, self.params.max_wheel_accel)
    }
}

/// The parameters of an [`Omni3`] (also its serde form).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Omni3Params {
    /// Wheel radius, m (> 0).
    pub wheel_radius: f64,
    /// Distance from the robot centre to each wheel's contact point, m (> 0).
    pub base_radius: f64,
    /// Where each wheel sits on the base: its angle from the robot's x axis (forward),
    /// counter-clockwise, radians. Each wheel rolls along the tangent, positive
    /// counter-clockwise about the centre. Two wheels may not share an angle.
    pub wheel_angles: [f64; 3],
    /// Top wheel speed, rad/s (> 0).
    pub max_wheel_speed: f64,
    /// Top wheel acceleration, rad/s² (> 0).
    pub max_wheel_accel: f64,
}

impl Omni3Params {
    /// Triskar (manual ch. 12.6): three omni wheels 120° apart. The layout is taken as 0°,
    /// 120°, 240°: one wheel on the forward axis, two behind; it is symmetric about the x axis,
    /// so driving straight forward turns wheel 0 not at all and wheels 1, 2 equally and
    /// oppositely. The manual gives no dimensions: wheel radius 4 cm, base radius 20 cm, top
    /// rim speed 1.2 m/s (30 rad/s) and 2.4 m/s² (60 rad/s²) are assumed.
    pub const TRISKAR: Omni3Params = Omni3Params {
        wheel_radius: 0.04,
        base_radius: 0.20,
        wheel_angles: [0.0, 2.0 * PI / 3.0, 4.0 * PI / 3.0],
        max_wheel_speed: 30.0,
        max_wheel_accel: 60.0,
    };
}

/// A base on three omni wheels (Triskar).
///
/// Wheel `i` at angle `aᵢ` rolls along the tangent `(−sin aᵢ, cos aᵢ)`, so its rim speed is
/// `−sin aᵢ·vx + cos aᵢ·vy + base_radius·ω` and its angular speed that divided by the wheel
/// radius. The forward map is the inverse of that 3×3 matrix, computed once in
/// [`Omni3::new`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Omni3Params", into = "Omni3Params")]
pub struct Omni3 {
    params: Omni3Params,
    /// Twist → wheel speeds.
    to_wheels: Matrix3<f64>,
    /// Wheel speeds → twist.
    to_twist: Matrix3<f64>,
}

impl Omni3 {
    /// A base; radii and limits must be finite and > 0, angles finite and distinct.
    pub fn new(params: Omni3Params) -> Result<Self, PlanError> {
        let r = positive("wheel_radius", params.wheel_radius)?;
        let l = positive("base_radius", params.base_radius)?;
        positive("max_wheel_speed", params.max_wheel_speed)?;
        positive("max_wheel_accel", params.max_wheel_accel)?;
        for a in params.wheel_angles {
            if !a.is_finite() {
                return Err(PlanError::InvalidParameter {
                    name: "wheel_angles",
                    value: a,
                    expected: "finite angles",
                });
            }
        }
        let [a0, a1, a2] = params.wheel_angles;
        let unit = Matrix3::new(
            -a0.sin(),
            a0.cos(),
            1.0,
            -a1.sin(),
            a1.cos(),
            1.0,
            -a2.sin(),
            a2.cos(),
            1.0,
        );
        // The rows are the points (cos a, sin a) on the unit circle lifted to the plane z = 1
        // (rotated by 90°): the determinant is twice the area of their triangle, zero exactly
        // when two wheels coincide. 120° apart gives 3√3/2 ≈ 2.6.
        if unit.determinant().abs() < 1e-6 {
            return Err(PlanError::SingularWheelLayout { angles: params.wheel_angles });
        }
        let to_wheels = Matrix3::from_diagonal_element(1.0 / r)
            * unit
            * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, l));
        let to_twist = to_wheels
            .try_inverse()
            .ok_or(PlanError::SingularWheelLayout { angles: params.wheel_angles })?;
        Ok(Self { params, to_wheels, to_twist })
    }

    /// The Triskar base ([`Omni3Params::TRISKAR`]).
    pub fn triskar() -> Self {
        Self::default()
    }

    /// The parameters.
    pub const fn params(&self) -> &Omni3Params {
        &self.params
    }
}

impl Default for Omni3 {
    fn default() -> Self {
        #[allow(clippy::expect_used)]
        Self::new(Omni3Params::TRISKAR).expect("invariant: the Triskar parameters are valid")
    }
}

impl TryFrom<Omni3Params> for Omni3 {
    type Error = PlanError;
    fn try_from(p: Omni3Params) -> Result<Self, PlanError> {
        Self::new(p)
    }
}

impl From<Omni3> for Omni3Params {
    fn from(o: Omni3) -> Self {
        o.params
    }
}

impl Kinematics for Omni3 {
    type Wheels = OmniWheels;

    fn steering(&self) -> Steering {
        Steering::Holonomic
    }

    fn max_wheel_speed(&self) -> f64 {
        self.params.max_wheel_speed
    }

    fn inverse(&self, twist: &Twist) -> OmniWheels {
        let w = self.to_wheels * Vector3::new(twist.vx, twist.vy, twist.omega);
        WheelSpeeds([w.x, w.y, w.z])
    }

    fn forward(&self, wheels: &OmniWheels) -> Twist {
        let t = self.to_twist * Vector3::from(wheels.0);
        Twist::new(t.x, t.y, t.z)
    }

    fn limit(&self, twist: &Twist) -> Twist {
        if !twist.is_finite() {
            return Twist::ZERO;
        }
        limit_with(*twist, self.inverse(twist), self.params.max_wheel_speed)
    }

    fn ramp(&self, current: &OmniWheels, target: &OmniWheels, dt: f64) -> OmniWheels {
        ramp_with(current, target, dt, self.params.max_wheel_speed, self.params.max_wheel_accel)
    }
}

/// The open-loop PWM duty cycle for a wheel speed set point: `speed / max_wheel_speed`,
/// clamped to `[-1, 1]` (sign = direction). The AIRBoard drives each DC motor by PWM (MRT
/// manual §5.1); at steady state and light load a DC motor's speed is roughly proportional to
/// the mean voltage, i.e. to the duty cycle. The board's own speed loop (§5.3) corrects the
/// rest. Non-finite input or a non-positive `max_wheel_speed` give 0.
pub fn duty_cycle(speed: f64, max_wheel_speed: f64) -> f64 {
    if !(speed.is_finite() && max_wheel_speed.is_finite() && max_wheel_speed > 0.0) {
        return 0.0;
    }
    (speed / max_wheel_speed).clamp(-1.0, 1.0)
}

/// The pose reached from `pose` (field frame) after `dt` seconds at the constant `twist`
/// (robot frame), integrated exactly: the robot follows an arc of circle (a straight line when
/// `omega = 0`), the same motion model as the mice sensor (manual §4.1: "the robot movement
/// during a sampling period can be approximated by an arc of circumference").
///
/// A non-finite `twist` or `dt` returns `pose` unchanged. Units are the caller's: metres and
/// m/s here (note that [`mrt_msgs::robot`] snapshots use millimetres).
///
/// ```
/// use mrt_core::Pose2;
/// use mrt_plan::kinematics::{integrate, Twist};
/// use std::f64::consts::FRAC_PI_2;
/// // A quarter circle of radius 2/π: 1 m/s while turning at π/2 rad/s for 1 s.
/// let p = integrate(Pose2::identity(), &Twist::new(1.0, 0.0, FRAC_PI_2), 1.0);
/// let r = 2.0 / std::f64::consts::PI;
/// assert!((p.x - r).abs() < 1e-12 && (p.y - r).abs() < 1e-12 && (p.theta - FRAC_PI_2).abs() < 1e-12);
/// ```
pub fn integrate(pose: Pose2, twist: &Twist, dt: f64) -> Pose2 {
    if !(dt.is_finite() && twist.is_finite()) {
        return pose;
    }
    let dtheta = twist.omega * dt;
    let (dx, dy) = arc_displacement(twist.vx * dt, twist.vy * dt, dtheta);
    pose.compose(&Pose2::new(dx, dy, dtheta))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    fn close_twist(a: &Twist, b: &Twist) -> bool {
        close(a.vx, b.vx) && close(a.vy, b.vy) && close(a.omega, b.omega)
    }

    #[test]
    fn diff_drive_by_hand() {
        // IANUS3: r = 0.05, track = 0.4.
        let d = DiffDrive::ianus3();
        // 1 m/s straight: both wheels 1 / 0.05 = 20 rad/s.
        assert_eq!(d.inverse(&Twist::new(1.0, 0.0, 0.0)), DiffWheels::new(20.0, 20.0));
        // Turning in place at 1 rad/s: rims at ±0.2 m/s → ∓4 rad/s, the right wheel forward.
        let w = d.inverse(&Twist::new(0.0, 0.0, 1.0));
        assert!(close(w.left(), -4.0) && close(w.right(), 4.0), "{w:?}");
        // Forward: left 10, right 30 rad/s → rims 0.5 and 1.5 m/s → v = 1, ω = 1 / 0.4 = 2.5.
        let t = d.forward(&DiffWheels::new(10.0, 30.0));
        assert!(close_twist(&t, &Twist::new(1.0, 0.0, 2.5)), "{t:?}");
        assert!(close(d.max_speed(), 1.2));
        assert_eq!(d.steering(), Steering::Differential);
    }

    #[test]
    fn omni3_by_hand() {
        // Triskar: r = 0.04, L = 0.2, wheels at 0°, 120°, 240°.
        let o = Omni3::triskar();
        // Forward 1 m/s: wheel i turns at −sin(aᵢ)/r: 0, −(√3/2)/0.04, +(√3/2)/0.04.
        let s = 3f64.sqrt() / 2.0 / 0.04; // 21.650635...
        let w = o.inverse(&Twist::new(1.0, 0.0, 0.0));
        assert!(close(w.0[0], 0.0) && close(w.0[1], -s) && close(w.0[2], s), "{w:?}");
        // Left 1 m/s: cos(aᵢ)/r = 25, −12.5, −12.5.
        let w = o.inverse(&Twist::new(0.0, 1.0, 0.0));
        assert!(close(w.0[0], 25.0) && close(w.0[1], -12.5) && close(w.0[2], -12.5), "{w:?}");
        // Turning at 1 rad/s: L/r = 5 each.
        let w = o.inverse(&Twist::new(0.0, 0.0, 1.0));
        assert!(w.0.iter().all(|&x| close(x, 5.0)), "{w:?}");
        // And back: wheels (5, 5, 5) are a pure rotation.
        assert!(close_twist(&o.forward(&WheelSpeeds([5.0; 3])), &Twist::new(0.0, 0.0, 1.0)));
        assert_eq!(o.steering(), Steering::Holonomic);
    }

    #[test]
    fn limit_scales_uniformly_and_drops_vy_on_a_diff_drive() {
        let d = DiffDrive::ianus3();
        // 2 m/s → wheels 40 rad/s > 24: factor 0.6 → 1.2 m/s, the IANUS3 top speed.
        assert!(close_twist(&d.limit(&Twist::new(2.0, 0.0, 0.0)), &Twist::new(1.2, 0.0, 0.0)));
        // (1, 0.5, 5): vy dropped; left = (1 − 5·0.2)/0.05 = 0, right = (1 + 1)/0.05 = 40 →
        // factor 24/40 = 0.6 → (0.6, 0, 3); the curvature ω/v = 5 is kept.
        assert!(close_twist(&d.limit(&Twist::new(1.0, 0.5, 5.0)), &Twist::new(0.6, 0.0, 3.0)));
        // Within limits: unchanged (apart from vy).
        assert_eq!(d.limit(&Twist::new(0.5, 0.0, 1.0)), Twist::new(0.5, 0.0, 1.0));
        assert_eq!(d.limit(&Twist::new(f64::NAN, 0.0, 1.0)), Twist::ZERO);

        let o = Omni3::triskar();
        // Left 2 m/s: wheel 0 at 2·25 = 50 rad/s > 30 → factor 0.6 → 1.2 m/s.
        assert!(close_twist(&o.limit(&Twist::new(0.0, 2.0, 0.0)), &Twist::new(0.0, 1.2, 0.0)));
        // Holonomic: vy survives; a slow twist is unchanged.
        assert_eq!(o.limit(&Twist::new(0.3, 0.2, 0.1)), Twist::new(0.3, 0.2, 0.1));
    }

    #[test]
    fn ramp_by_hand() {
        let d = DiffDrive::ianus3(); // 60 rad/s², top 24 rad/s
                                     // From rest to (20, 10) in 0.1 s: step 6; largest change 20 → factor 0.3 → (6, 3).
        let w = d.ramp(&DiffWheels::default(), &DiffWheels::new(20.0, 10.0), 0.1);
        assert!(close(w.left(), 6.0) && close(w.right(), 3.0), "{w:?}");
        // The ratio 2:1 (the curvature) is kept. Close to the target: reached exactly.
        let w = d.ramp(&DiffWheels::new(19.0, 9.5), &DiffWheels::new(20.0, 10.0), 0.1);
        assert_eq!(w, DiffWheels::new(20.0, 10.0));
        // A target above the top speed is scaled first: (48, 24) → (24, 12).
        let w = d.ramp(&DiffWheels::new(23.0, 11.5), &DiffWheels::new(48.0, 24.0), 1.0);
        assert_eq!(w, DiffWheels::new(24.0, 12.0));
        // Bad dt: no change; NaN target counts as 0.
        let c = DiffWheels::new(1.0, 2.0);
        assert_eq!(d.ramp(&c, &DiffWheels::new(5.0, 5.0), -1.0), c);
        assert_eq!(d.ramp(&c, &DiffWheels::new(5.0, 5.0), f64::NAN), c);
        let w = d.ramp(&c, &DiffWheels::new(f64::NAN, 2.0), 1.0);
        assert_eq!(w, DiffWheels::new(0.0, 2.0));

        let o = Omni3::triskar(); // 60 rad/s²
        let w = o.ramp(&OmniWheels::default(), &WheelSpeeds([30.0, -15.0, 0.0]), 0.05);
        // Step 3, largest change 30 → factor 0.1.
        assert!(close(w.0[0], 3.0) && close(w.0[1], -1.5) && close(w.0[2], 0.0), "{w:?}");
    }

    #[test]
    fn parameters_are_validated() {
        let bad = DiffDriveParams { wheel_radius: 0.0, ..DiffDriveParams::IANUS3 };
        assert!(matches!(
            DiffDrive::new(bad),
            Err(PlanError::InvalidParameter { name: "wheel_radius", .. })
        ));
        let bad = DiffDriveParams { track: f64::NAN, ..DiffDriveParams::IANUS3 };
        assert!(matches!(
            DiffDrive::new(bad),
            Err(PlanError::InvalidParameter { name: "track", .. })
        ));
        let bad = DiffDriveParams { max_wheel_accel: -1.0, ..DiffDriveParams::IANUS3 };
        assert!(DiffDrive::new(bad).is_err());
        assert_eq!(DiffDrive::new(DiffDriveParams::IANUS3), Ok(DiffDrive::ianus3()));

        let bad = Omni3Params { base_radius: -0.2, ..Omni3Params::TRISKAR };
        assert!(matches!(
            Omni3::new(bad),
            Err(PlanError::InvalidParameter { name: "base_radius", .. })
        ));
        let bad = Omni3Params { wheel_angles: [0.0, 1.0, 1.0], ..Omni3Params::TRISKAR };
        assert!(matches!(Omni3::new(bad), Err(PlanError::SingularWheelLayout { .. })));
        // 0 and 2π are the same place on the base.
        let bad = Omni3Params { wheel_angles: [0.0, 2.0, 2.0 * PI], ..Omni3Params::TRISKAR };
        assert!(matches!(Omni3::new(bad), Err(PlanError::SingularWheelLayout { .. })));
        let bad = Omni3Params { wheel_angles: [0.0, f64::INFINITY, 2.0], ..Omni3Params::TRISKAR };
        assert!(Omni3::new(bad).is_err());
        // The other usual layout, 90°/210°/330°, is fine.
        let other = Omni3Params {
            wheel_angles: [FRAC_PI_2, FRAC_PI_2 + 2.0 * PI / 3.0, FRAC_PI_2 + 4.0 * PI / 3.0],
            ..Omni3Params::TRISKAR
        };
        let o = Omni3::new(other);
        assert!(o.is_ok());
    }

    #[test]
    fn duty_cycle_by_hand() {
        assert!(close(duty_cycle(12.0, 24.0), 0.5));
        assert!(close(duty_cycle(-30.0, 24.0), -1.0));
        assert_eq!(duty_cycle(f64::NAN, 24.0), 0.0);
        assert_eq!(duty_cycle(1.0, 0.0), 0.0);
    }

    #[test]
    fn integrate_quarter_circle_and_straight_lines() {
        // 1 m/s at π/2 rad/s for 1 s: radius v/ω = 2/π, centre (0, 2/π) on the left; a quarter
        // turn ends at (2/π, 2/π) facing +y.
        let r = 2.0 / PI;
        let p = integrate(Pose2::identity(), &Twist::new(1.0, 0.0, FRAC_PI_2), 1.0);
        assert!(close(p.x, r) && close(p.y, r) && close(p.theta, FRAC_PI_2), "{p:?}");
        // Sideways (holonomic) from a robot at (1, 2) facing +y: its left is −x.
        let p = integrate(Pose2::new(1.0, 2.0, FRAC_PI_2), &Twist::new(0.0, 0.5, 0.0), 2.0);
        assert!(close(p.x, 0.0) && close(p.y, 2.0) && close(p.theta, FRAC_PI_2), "{p:?}");
        // Non-finite input: unchanged.
        let start = Pose2::new(1.0, 2.0, 0.3);
        assert_eq!(integrate(start, &Twist::new(f64::NAN, 0.0, 0.0), 1.0), start);
    }

    /// Independent method: many tiny Euler steps of ẋ = R(θ)·v, θ̇ = ω.
    fn euler(pose: Pose2, t: &Twist, dt: f64, n: usize) -> Pose2 {
        let h = dt / n as f64;
        let (mut x, mut y, mut th) = (pose.x, pose.y, pose.theta);
        for _ in 0..n {
            let (s, c) = th.sin_cos();
            x += h * (c * t.vx - s * t.vy);
            y += h * (s * t.vx + c * t.vy);
            th += h * t.omega;
        }
        Pose2::new(x, y, th)
    }

    proptest! {
        #[test]
        fn integrate_matches_fine_euler(vx in -1.5f64..1.5, vy in -1.5f64..1.5, w in -6.0f64..6.0,
                                        th in -3.0f64..3.0) {
            let start = Pose2::new(0.3, -0.2, th);
            let t = Twist::new(vx, vy, w);
            let exact = integrate(start, &t, 0.5);
            let approx = euler(start, &t, 0.5, 20_000);
            // Euler's error is O(h): ≈ |v|·|ω|·dt·h/2 < 3·6·0.5·2.5e-5/2 ≈ 1.2e-4.
            prop_assert!((exact.x - approx.x).abs() < 2e-4 && (exact.y - approx.y).abs() < 2e-4,
                "{exact:?} vs {approx:?}");
            prop_assert!(mrt_core::angle_diff(exact.theta, approx.theta).abs() < 1e-9);
        }

        #[test]
        fn forward_inverts_inverse(vx in -2.0f64..2.0, vy in -2.0f64..2.0, w in -8.0f64..8.0) {
            let t = Twist::new(vx, vy, w);
            let o = Omni3::triskar();
            let back = o.forward(&o.inverse(&t));
            prop_assert!(close_twist(&back, &t), "{back:?}");
            let d = DiffDrive::ianus3();
            let back = d.forward(&d.inverse(&t));
            prop_assert!(close_twist(&back, &Twist::new(vx, 0.0, w)), "{back:?}");
        }

        #[test]
        fn limit_respects_top_speed_and_direction(vx in -5.0f64..5.0, vy in -5.0f64..5.0,
                                                  w in -20.0f64..20.0) {
            let t = Twist::new(vx, vy, w);
            let o = Omni3::triskar();
            let l = o.limit(&t);
            prop_assert!(o.inverse(&l).max_abs() <= o.max_wheel_speed() + 1e-9);
            // Same direction: l = k·t with 0 < k <= 1.
            let k = if t.vx.abs() > 1e-6 { l.vx / t.vx } else if t.vy.abs() > 1e-6 { l.vy / t.vy } else { 1.0 };
            prop_assert!(k > 0.0 && k <= 1.0 + 1e-12);
            prop_assert!(close_twist(&l, &t.scaled(k)));
            let d = DiffDrive::ianus3();
            prop_assert!(d.inverse(&d.limit(&t)).max_abs() <= d.max_wheel_speed() + 1e-9);
        }
    }

    #[test]
    fn serde_round_trip_validates() {
        // serde's own test format is not a dependency: go through the params directly.
        let p: DiffDriveParams = DiffDrive::ianus3().into();
        assert_eq!(p, DiffDriveParams::IANUS3);
        assert!(DiffDrive::try_from(DiffDriveParams { track: 0.0, ..p }).is_err());
        let p: Omni3Params = Omni3::triskar().into();
        assert_eq!(Omni3::try_from(p), Ok(Omni3::triskar()));
    }
}
