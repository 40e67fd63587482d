//! Guidance: the ISocRob Guidance µAgent (ISocRob-2000 report §3.2.3) on top of
//! [`crate::kinematics`]. [`Guidance`] is the µAgent as one call per control cycle: it runs
//! the mode a behavior's command asks for. Its three motion modes:
//!
//! - **Velocity mode** ([`VelocityGuard`]): a velocity reference goes to the motors "unless an
//!   obstacle is found by the sonars. If this is the case, the robot movement is simply halted".
//!   Here the reference is a [`Twist`] (turn it into wheel speeds with
//!   [`Kinematics::inverse`](crate::kinematics::Kinematics::inverse)), "found" means a sonar
//!   within a cone around the direction of motion reads less than a safety distance, and
//!   "halted" stops the translation only: turning in place stays allowed, so a behavior can turn
//!   away (the seed's footnote 12 calls the full stop "a source of major headaches").
//! - **Position mode** ([`PositionMode`]): go to a posture with a proportional controller. The
//!   seed's position mode took wheel *position* references ("seldom used"); MRT's behaviors want
//!   "go there, face that way", so this mode takes a target [`Pose2`] and returns a [`Twist`].
//! - **Potential field mode** ([`PotentialField`]): "given an initial robot posture and a final
//!   one [...] the robot is attracted by the target position and repelled by any obstacle
//!   detected by the sonars. Additionally, the ball is considered here as an obstacle
//!   (repelling), so that this mode is also able to position itself behind the ball, while not
//!   touching it" ([`behind_ball`], [`sonar_obstacles`]).
//!
//! Everything is in the field frame (metres, radians) except twists and sonar bearings, which
//! are in the robot frame.

use crate::error::{positive, PlanError};
use crate::kinematics::{nearer_end, Steering, Twist};
use mrt_core::{angle_diff, Point2, Pose2, Vec2};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

pub use agent::{echo_obstacles, Guidance, Guided, Mode};
pub use mrt_msgs::Sonar;

mod agent;

/// What a guidance mode asks of the base.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GuidanceCommand {
    /// The velocity to apply (not yet limited by the base: pass it through
    /// [`Kinematics::limit`](crate::kinematics::Kinematics::limit)).
    pub twist: Twist,
    /// Velocity mode: the translation was stopped by a sonar. Position and potential modes:
    /// the target posture is reached within tolerance (the twist is then zero).
    pub done: bool,
}

/// Velocity mode: stops the translation when a sonar in the direction of motion reads less than
/// `safety_distance`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "VelocityGuardParams")]
pub struct VelocityGuard {
    safety_distance: f64,
    half_cone: f64,
}

/// What a serialized [`VelocityGuard`] holds, checked by [`VelocityGuard::new`] when read.
#[derive(Deserialize)]
struct VelocityGuardParams {
    safety_distance: f64,
    half_cone: f64,
}

impl TryFrom<VelocityGuardParams> for VelocityGuard {
    type Error = PlanError;
    fn try_from(p: VelocityGuardParams) -> Result<Self, PlanError> {
        VelocityGuard::new(p.safety_distance, p.half_cone)
    }
}

impl Default for VelocityGuard {
    /// 0.5 m from the centre, ±30°: with sixteen sonars (22.5° apart) the three looking ahead
    /// count. The seed gives no values; these are assumed.
    fn default() -> Self {
        Self { safety_distance: 0.5, half_cone: PI / 6.0 }
    }
}

impl VelocityGuard {
    /// A guard: `safety_distance` (m, from the robot centre) finite and > 0; `half_cone` (rad)
    /// in `(0, π]`: a sonar counts when its bearing is within `half_cone` of the direction of
    /// motion.
    pub fn new(safety_distance: f64, half_cone: f64) -> Result<Self, PlanError> {
        positive("safety_distance", safety_distance)?;
        if !(half_cone.is_finite() && half_cone > 0.0 && half_cone <= PI) {
            return Err(PlanError::InvalidParameter {
                name: "half_cone",
                value: half_cone,
                expected: "an angle in (0, π]",
            });
        }
        Ok(Self { safety_distance, half_cone })
    }

    /// The safety distance, m.
    pub const fn safety_distance(&self) -> f64 {
        self.safety_distance
    }

    /// The reference `twist`, or the same with `vx = vy = 0` (and `done`) if a sonar within the
    /// cone around the direction of translation `atan2(vy, vx)` reads less than the safety
    /// distance. Driving backwards looks backwards (IANUS3 runs both ways). A pure rotation is
    /// never stopped; sonars without an echo (non-finite range) are ignored; a non-finite twist
    /// gives a stop.
    pub fn apply(&self, twist: &Twist, sonars: &[Sonar]) -> GuidanceCommand {
        if !twist.is_finite() {
            return GuidanceCommand { twist: Twist::ZERO, done: true };
        }
        if twist.speed() <= 1e-9 {
            return GuidanceCommand { twist: *twist, done: false };
        }
        let direction = twist.vy.atan2(twist.vx);
        let blocked = sonars.iter().any(|s| {
            s.range.is_finite()
                && s.bearing.is_finite()
                && s.range < self.safety_distance
                && angle_diff(s.bearing, direction).abs() <= self.half_cone
        });
        if blocked {
            GuidanceCommand { twist: Twist::new(0.0, 0.0, twist.omega), done: true }
        } else {
            GuidanceCommand { twist: *twist, done: false }
        }
    }
}

/// The gains and limits of [`PositionMode`] (also used by [`PotentialField`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PositionParams {
    /// The base's kind: a differential drive turns toward where it must go.
    pub steering: Steering,
    /// Speed per metre of distance to the target, 1/s (> 0).
    pub gain: f64,
    /// Turn rate per radian of heading error, 1/s (> 0). For a differential drive keep it
    /// above `gain`: the heading then settles faster than the bearing to the target moves.
    pub heading_gain: f64,
    /// Top translational speed asked for, m/s (> 0).
    pub max_speed: f64,
    /// Top turn rate asked for, rad/s (> 0).
    pub max_omega: f64,
    /// The target is reached within this distance, m (> 0).
    pub position_tolerance: f64,
    /// ... and this heading error, rad (> 0).
    pub angle_tolerance: f64,
}

impl Default for PositionParams {
    /// Holonomic, 1.5 /s, 4 /s, 1.2 m/s (the IANUS3 top speed), 4 rad/s, 2 cm, 0.03 rad.
    fn default() -> Self {
        Self {
            steering: Steering::Holonomic,
            gain: 1.5,
            heading_gain: 4.0,
            max_speed: 1.2,
            max_omega: 4.0,
            position_tolerance: 0.02,
            angle_tolerance: 0.03,
        }
    }
}

/// Position mode: a proportional controller to a target posture.
///
/// The wanted velocity is `gain · (target − position)`, at most `max_speed`. A holonomic base
/// applies it directly (in its own frame) while turning at `heading_gain · heading error`. A
/// differential drive turns its front or its back, whichever is nearer, toward the wanted
/// direction at `heading_gain · error` and drives at `|velocity| · cos(error)` (negative:
/// backwards). Within `position_tolerance` both turn in place to the target heading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "PositionParams", into = "PositionParams")]
pub struct PositionMode {
    params: PositionParams,
}

impl TryFrom<PositionParams> for PositionMode {
    type Error = PlanError;
    fn try_from(p: PositionParams) -> Result<Self, PlanError> {
        Self::new(p)
    }
}

impl From<PositionMode> for PositionParams {
    fn from(m: PositionMode) -> Self {
        m.params
    }
}

/// `v` shortened to at most `max`.
fn saturate(v: Vec2, max: f64) -> Vec2 {
    let n = v.norm();
    if n > max {
        v * (max / n)
    } else {
        v
    }
}

fn pose_is_finite(p: &Pose2) -> bool {
    p.x.is_finite() && p.y.is_finite() && p.theta.is_finite()
}

impl PositionMode {
    /// A controller; every number must be finite and > 0.
    pub fn new(params: PositionParams) -> Result<Self, PlanError> {
        positive("gain", params.gain)?;
        positive("heading_gain", params.heading_gain)?;
        positive("max_speed", params.max_speed)?;
        positive("max_omega", params.max_omega)?;
        positive("position_tolerance", params.position_tolerance)?;
        positive("angle_tolerance", params.angle_tolerance)?;
        Ok(Self { params })
    }

    /// The parameters.
    pub const fn params(&self) -> &PositionParams {
        &self.params
    }

    /// The attraction toward `target`: `gain · (target − position)`, at most `max_speed`, m/s.
    pub fn attraction(&self, position: Point2, target: Point2) -> Vec2 {
        saturate((target - position) * self.params.gain, self.params.max_speed)
    }

    /// One control step from `pose` toward `target` (both field frame). Non-finite input gives
    /// a zero twist, not done.
    pub fn command(&self, pose: &Pose2, target: &Pose2) -> GuidanceCommand {
        if !(pose_is_finite(pose) && pose_is_finite(target)) {
            return GuidanceCommand::default();
        }
        self.follow(pose, target, self.attraction(pose.position(), target.position()))
    }

    /// Turns a wanted field-frame `velocity` into a twist, or the final turn when at `target`.
    fn follow(&self, pose: &Pose2, target: &Pose2, velocity: Vec2) -> GuidanceCommand {
        let p = &self.params;
        let turn = |err: f64| (p.heading_gain * err).clamp(-p.max_omega, p.max_omega);
        let heading_error = angle_diff(target.theta, pose.theta);
        if pose.distance(target) <= p.position_tolerance {
            if heading_error.abs() <= p.angle_tolerance {
                return GuidanceCommand { twist: Twist::ZERO, done: true };
            }
            return GuidanceCommand {
                twist: Twist::new(0.0, 0.0, turn(heading_error)),
                done: false,
            };
        }
        let velocity = saturate(velocity, p.max_speed);
        let twist = match p.steering {
            Steering::Holonomic => {
                let (s, c) = pose.theta.sin_cos();
                Twist::new(
                    c * velocity.x + s * velocity.y,
                    -s * velocity.x + c * velocity.y,
                    turn(heading_error),
                )
            }
            Steering::Differential => {
                let speed = velocity.norm();
                if speed <= 1e-12 {
                    Twist::ZERO
                } else {
                    let err = angle_diff(velocity.y.atan2(velocity.x), pose.theta);
                    Twist::new(speed * err.cos(), 0.0, turn(nearer_end(err)))
                }
            }
        };
        GuidanceCommand { twist, done: false }
    }
}

/// A circular obstacle in the field frame: another robot, a post, the ball, a sonar echo.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Obstacle {
    /// Centre, m.
    pub center: Point2,
    /// Radius, m (negative counts as 0).
    pub radius: f64,
}

impl Obstacle {
    /// An obstacle.
    pub fn new(x: f64, y: f64, radius: f64) -> Self {
        Self { center: Point2::new(x, y), radius }
    }
}

/// The obstacle part of [`PotentialField`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PotentialParams {
    /// The robot's radius, m (> 0): obstacles are grown by it.
    pub robot_radius: f64,
    /// Obstacles repel within this distance of their (grown) surface, m (> 0).
    pub influence: f64,
    /// Repulsion gain, m²/s (> 0): the push at surface distance `d` is
    /// `repulsion_gain · (1/d − 1/influence)`, m/s.
    pub repulsion_gain: f64,
    /// Closer than this to a grown surface, no motion toward the obstacle is allowed at all, m
    /// (> 0).
    pub safety_margin: f64,
}

impl Default for PotentialParams {
    /// Robot radius 0.25 m (a Middle Size League robot), influence 0.5 m, gain 0.3 m²/s,
    /// margin 2 cm. Assumed: the seed gives no values.
    fn default() -> Self {
        Self { robot_radius: 0.25, influence: 0.5, repulsion_gain: 0.3, safety_margin: 0.02 }
    }
}

/// Potential field mode: attraction to the target posture plus repulsion from circular
/// obstacles, turned into a twist like [`PositionMode`].
///
/// The field at position `p` for target `g` (field frame, m/s):
///
/// - attraction `gain · (g − p)`, at most `max_speed`;
/// - for each obstacle (centre `c`, radius grown by the robot's), at surface distance
///   `d < influence`: a push `m = repulsion_gain · (1/d − 1/influence) · min(1, (|g − p| /
///   influence)²)` along the outward normal `n`, and, while the obstacle lies between the robot
///   and the target (`(c − p)·(g − p) > 0`), the same `m` along the tangent of `n` that points
///   toward the target (counter-clockwise on a tie). The tangential part walks the robot around
///   the obstacle instead of stalling in front of it, where attraction and repulsion cancel
///   (the classic local minimum of potential fields). The factor on `|g − p|` fades the push out
///   near the target, so a target close to an obstacle (behind the ball) is still reached;
/// - the sum, at most `max_speed`.
///
/// Then, within `safety_margin` of a grown surface, any velocity toward that obstacle is
/// removed (a differential drive stops its translation), so the robot never enters it.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PotentialField {
    position: PositionMode,
    params: PotentialParams,
}

impl PotentialField {
    /// A field; `position` as for [`PositionMode::new`], the obstacle parameters finite and
    /// > 0.
    pub fn new(position: PositionParams, params: PotentialParams) -> Result<Self, PlanError> {
        let position = PositionMode::new(position)?;
        positive("robot_radius", params.robot_radius)?;
        positive("influence", params.influence)?;
        positive("repulsion_gain", params.repulsion_gain)?;
        positive("safety_margin", params.safety_margin)?;
        Ok(Self { position, params })
    }

    /// The gains and limits.
    pub const fn position_params(&self) -> &PositionParams {
        self.position.params()
    }

    /// The obstacle parameters.
    pub const fn params(&self) -> &PotentialParams {
        &self.params
    }

    /// The wanted velocity at `position` (field frame, m/s), see the type's doc. Obstacles with
    /// a non-finite centre or radius are ignored.
    pub fn field(&self, position: Point2, target: Point2, obstacles: &[Obstacle]) -> Vec2 {
        let p = &self.params;
        let to_goal = target - position;
        let goal_distance = to_goal.norm();
        let fade = (goal_distance / p.influence).powi(2).min(1.0);
        let mut f = self.position.attraction(position, target);
        for o in obstacles {
            let Some((n, d)) = self.normal(position, o) else { continue };
            if d >= p.influence {
                continue;
            }
            let m = p.repulsion_gain * (1.0 / d.max(1e-3) - 1.0 / p.influence) * fade;
            f += n * m;
            if (o.center - position).dot(&to_goal) > 0.0 {
                let t = Vec2::new(-n.y, n.x);
                f += if t.dot(&to_goal) < 0.0 { -t } else { t } * m;
            }
        }
        saturate(f, self.position.params.max_speed)
    }

    /// Outward unit normal from `o` at `position` and the distance to its grown surface.
    fn normal(&self, position: Point2, o: &Obstacle) -> Option<(Vec2, f64)> {
        if !(o.center.x.is_finite() && o.center.y.is_finite() && o.radius.is_finite()) {
            return None;
        }
        let off = position - o.center;
        let dist = off.norm();
        if dist <= 1e-12 {
            return None;
        }
        Some((off / dist, dist - o.radius.max(0.0) - self.params.robot_radius))
    }

    /// One control step from `pose` toward the posture `target` around `obstacles`. Non-finite
    /// `pose` or `target` give a zero twist, not done.
    pub fn command(&self, pose: &Pose2, target: &Pose2, obstacles: &[Obstacle]) -> GuidanceCommand {
        if !(pose_is_finite(pose) && pose_is_finite(target)) {
            return GuidanceCommand::default();
        }
        let field = self.field(pose.position(), target.position(), obstacles);
        let mut cmd = self.position.follow(pose, target, field);
        // The hard guard: no velocity into an obstacle closer than the safety margin.
        let (s, c) = pose.theta.sin_cos();
        for o in obstacles {
            let Some((n, d)) = self.normal(pose.position(), o) else { continue };
            if d >= self.params.safety_margin {
                continue;
            }
            let t = cmd.twist;
            let velocity = Vec2::new(c * t.vx - s * t.vy, s * t.vx + c * t.vy);
            let inward = -velocity.dot(&n);
            if inward <= 0.0 {
                continue;
            }
            cmd.twist = match self.position.params.steering {
                Steering::Differential => Twist::new(0.0, 0.0, t.omega),
                Steering::Holonomic => {
                    let v = velocity + n * inward; // the inward part removed
                    Twist::new(c * v.x + s * v.y, -s * v.x + c * v.y, t.omega)
                }
            };
        }
        cmd
    }
}

/// The posture "behind the ball": on the line from `goal` through `ball`, `distance` metres
/// past the ball, facing the ball (and the goal beyond it). Fails if ball and goal coincide or
/// a value is non-finite; `distance` must be finite and > 0 (keep it above the ball's radius
/// plus the robot's, so that the ball, as an [`Obstacle`], does not cover the target).
pub fn behind_ball(ball: Point2, goal: Point2, distance: f64) -> Result<Pose2, PlanError> {
    positive("distance", distance)?;
    if !(ball.x.is_finite() && ball.y.is_finite() && goal.x.is_finite() && goal.y.is_finite()) {
        return Err(PlanError::NonFiniteInput { name: "ball or goal" });
    }
    let line = goal - ball;
    let len = line.norm();
    if len <= 1e-12 {
        return Err(PlanError::BallOnGoal { x: ball.x, y: ball.y });
    }
    let u = line / len;
    let spot = ball - u * distance;
    Ok(Pose2::new(spot.x, spot.y, u.y.atan2(u.x)))
}

/// The sonar echoes seen from `pose`, as obstacles for [`PotentialField`]: each echo closer than
/// `max_range` becomes a circle of `echo_radius` whose near side is at the echo. Readings
/// without an echo (non-finite, ≤ 0 or ≥ `max_range`) are skipped.
pub fn sonar_obstacles(
    pose: &Pose2,
    sonars: &[Sonar],
    echo_radius: f64,
    max_range: f64,
) -> Vec<Obstacle> {
    let radius = if echo_radius.is_finite() { echo_radius.max(0.0) } else { 0.0 };
    sonars
        .iter()
        .filter(|s| {
            s.bearing.is_finite() && s.range.is_finite() && s.range > 0.0 && s.range < max_range
        })
        .map(|s| {
            let (sn, cs) = s.bearing.sin_cos();
            let at = s.range + radius;
            Obstacle { center: pose.transform_point(Point2::new(at * cs, at * sn)), radius }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    /// Reading a guard from a file checks it like `new` does.
    #[test]
    fn deserializing_checks_the_parameters() {
        let guard: Result<VelocityGuard, _> =
            serde_json::from_str(r#"{"safety_distance": -1.0, "half_cone": 0.5}"#);
        assert!(guard.is_err());
        let guard: Result<VelocityGuard, _> =
            serde_json::from_str(r#"{"safety_distance": 0.5, "half_cone": 0.5}"#);
        assert!(guard.is_ok());
    }

    #[test]
    fn velocity_guard_by_hand() {
        let g = VelocityGuard::default(); // 0.5 m, ±30°
        let ring: Vec<Sonar> =
            (0..16).map(|i| Sonar::new(Sonar::ring_bearing(i, 16), f64::INFINITY)).collect();
        let fwd = Twist::new(1.0, 0.0, 0.3);
        assert_eq!(g.apply(&fwd, &ring), GuidanceCommand { twist: fwd, done: false });
        // Sonar 1 (22.5°) sees something at 0.4 m: within the cone and too close.
        let mut near = ring.clone();
        near[1].range = 0.4;
        assert_eq!(
            g.apply(&fwd, &near),
            GuidanceCommand { twist: Twist::new(0.0, 0.0, 0.3), done: true }
        );
        // Sonar 2 (45°) is outside the ±30° cone: ignored.
        let mut side = ring.clone();
        side[2].range = 0.1;
        assert!(!g.apply(&fwd, &side).done);
        // Backwards: sonar 8 (180°) counts, sonar 0 not.
        let back = Twist::new(-0.5, 0.0, 0.0);
        let mut behind = ring.clone();
        behind[8].range = 0.3;
        assert!(g.apply(&back, &behind).done);
        assert!(!g.apply(&fwd, &behind).done);
        // Sideways to the left (holonomic): sonar 4 (90°).
        let mut left = ring.clone();
        left[4].range = 0.3;
        assert!(g.apply(&Twist::new(0.0, 0.8, 0.0), &left).done);
        // A pure rotation is never stopped.
        assert!(!g.apply(&Twist::new(0.0, 0.0, 1.0), &near).done);
        assert!(g.apply(&Twist::new(f64::NAN, 0.0, 0.0), &ring).done);
        assert!(VelocityGuard::new(0.0, 0.5).is_err());
        assert!(VelocityGuard::new(0.5, 4.0).is_err());
        assert!(close(Sonar::ring_bearing(4, 16), FRAC_PI_2));
    }

    #[test]
    fn position_command_by_hand() {
        let m = PositionMode::default(); // gain 1.5, max 1.2 m/s, heading gain 4
                                         // 0.4 m ahead: 1.5 · 0.4 = 0.6 m/s forward, already facing the target heading.
        let c = m.command(&Pose2::identity(), &Pose2::new(0.4, 0.0, 0.0));
        assert!(close(c.twist.vx, 0.6) && close(c.twist.vy, 0.0) && close(c.twist.omega, 0.0));
        // Facing +y, target 0.4 m to the field's +x: that is the robot's right, vy = −0.6; the
        // heading error −π/2 asks −4·π/2 = −6.28 rad/s, clamped to −4.
        let c = m.command(&Pose2::new(0.0, 0.0, FRAC_PI_2), &Pose2::new(0.4, 0.0, 0.0));
        assert!(close(c.twist.vx, 0.0) && close(c.twist.vy, -0.6) && close(c.twist.omega, -4.0));
        // Far: the speed saturates at 1.2.
        let c = m.command(&Pose2::identity(), &Pose2::new(3.0, 4.0, 0.0));
        assert!(close(c.twist.vx, 0.72) && close(c.twist.vy, 0.96), "{c:?}");
        // There, wrong heading: turn in place; right heading: done.
        let c = m.command(&Pose2::new(1.0, 1.0, 0.0), &Pose2::new(1.01, 1.0, 0.5));
        assert!(close(c.twist.omega, 2.0) && c.twist.vx == 0.0 && !c.done);
        assert!(m.command(&Pose2::new(1.0, 1.0, 0.5), &Pose2::new(1.01, 1.0, 0.51)).done);

        // Differential: target straight behind, 0.4 m: drive backwards at 0.6 without turning.
        let d = PositionMode::new(PositionParams {
            steering: Steering::Differential,
            ..PositionParams::default()
        });
        let Ok(d) = d else { panic!("valid params") };
        let c = d.command(&Pose2::identity(), &Pose2::new(-0.4, 0.0, 0.0));
        assert!(close(c.twist.vx, -0.6) && close(c.twist.omega, 0.0), "{c:?}");
        // Target 20° to the left: v = 0.6·cos 20° = 0.563816, ω = 4 · 0.349066 = 1.396263.
        let a = 20f64.to_radians();
        let c = d.command(&Pose2::identity(), &Pose2::new(0.4 * a.cos(), 0.4 * a.sin(), 0.0));
        assert!(close(c.twist.vx, 0.6 * a.cos()) && close(c.twist.omega, 4.0 * a), "{c:?}");
        assert!((c.twist.vx - 0.563_816).abs() < 1e-6 && (c.twist.omega - 1.396_263).abs() < 1e-6);
        assert!(c.twist.vy == 0.0);
        assert_eq!(
            m.command(&Pose2::new(f64::NAN, 0.0, 0.0), &Pose2::identity()),
            GuidanceCommand::default()
        );
        let bad = PositionParams { gain: -1.0, ..PositionParams::default() };
        assert!(PositionMode::new(bad).is_err());
    }

    #[test]
    fn field_by_hand() {
        let pos = PositionParams { gain: 1.0, max_speed: 1.0, ..PositionParams::default() };
        let pot = PotentialParams {
            robot_radius: 0.2,
            influence: 0.5,
            repulsion_gain: 0.2,
            ..PotentialParams::default()
        };
        let Ok(f) = PotentialField::new(pos, pot) else { panic!("valid params") };
        // No obstacle, target 0.5 m ahead: attraction 1 · 0.5.
        let v = f.field(Point2::origin(), Point2::new(0.5, 0.0), &[]);
        assert!(close(v.x, 0.5) && close(v.y, 0.0));
        // Obstacle at (0.6, 0), radius 0.1 (grown 0.3): surface distance 0.3 < 0.5.
        // Push m = 0.2·(1/0.3 − 1/0.5) = 0.266667, goal 2 m away (fade 1), outward n = (−1, 0).
        // The obstacle is in the way: tangent (−n.y, n.x) = (0, −1), a tie with the goal
        // direction → kept. Attraction (2, 0) saturated to (1, 0).
        // Sum: (1 − 0.266667, −0.266667), norm 0.78 < 1.
        let obstacle = [Obstacle::new(0.6, 0.0, 0.1)];
        let v = f.field(Point2::origin(), Point2::new(2.0, 0.0), &obstacle);
        let m = 0.2 * (1.0 / 0.3 - 2.0);
        assert!(close(v.x, 1.0 - m) && close(v.y, -m), "{v:?}");
        // Target behind the robot: the obstacle is not in the way, no tangential part:
        // (−1, 0) saturated + (−m, 0) → saturated to (−1, 0).
        let v = f.field(Point2::origin(), Point2::new(-2.0, 0.0), &obstacle);
        assert!(close(v.x, -1.0) && close(v.y, 0.0), "{v:?}");
        // Out of influence: attraction only.
        let v = f.field(Point2::origin(), Point2::new(2.0, 0.0), &[Obstacle::new(1.0, 0.0, 0.1)]);
        assert!(close(v.x, 1.0) && close(v.y, 0.0));
        // Near the target the push fades: target 0.25 m away (fade (0.25/0.5)² = 0.25), an
        // obstacle behind the robot at surface distance 0.3, outward normal (1, 0): attraction
        // (0.25, 0) plus 0.25·m forwards; not in the way, so no tangential part.
        let v = f.field(Point2::origin(), Point2::new(0.25, 0.0), &[Obstacle::new(-0.6, 0.0, 0.1)]);
        assert!(close(v.x, 0.25 + 0.25 * m) && close(v.y, 0.0), "{v:?}");
        let bad = PotentialParams { influence: 0.0, ..PotentialParams::default() };
        assert!(PotentialField::new(PositionParams::default(), bad).is_err());
    }

    #[test]
    fn safety_margin_blocks_inward_motion() {
        let Ok(f) = PotentialField::new(PositionParams::default(), PotentialParams::default())
        else {
            panic!("valid params")
        };
        // Robot (radius 0.25) at 0.26 from a point obstacle's centre: surface distance 0.01 <
        // 0.02. Target straight through the obstacle: whatever the field, nothing inward.
        let ob = [Obstacle::new(0.26, 0.0, 0.0)];
        let c = f.command(&Pose2::identity(), &Pose2::new(2.0, 0.0, 0.0), &ob);
        assert!(c.twist.vx <= 1e-12, "{c:?}");
    }

    #[test]
    fn behind_ball_by_hand() {
        // Ball at (1, 0), goal at (5, 0): 0.5 m behind is (0.5, 0), facing +x.
        let p = behind_ball(Point2::new(1.0, 0.0), Point2::new(5.0, 0.0), 0.5);
        assert!(matches!(p, Ok(p) if close(p.x, 0.5) && close(p.y, 0.0) && close(p.theta, 0.0)));
        // Ball at (0, 0), goal at (3, 4): behind by 1 m is (−0.6, −0.8), facing atan2(4, 3).
        let p = behind_ball(Point2::origin(), Point2::new(3.0, 4.0), 1.0);
        let want = 4f64.atan2(3.0);
        assert!(matches!(p, Ok(p) if close(p.x, -0.6) && close(p.y, -0.8) && close(p.theta, want)));
        assert!(matches!(
            behind_ball(Point2::new(1.0, 1.0), Point2::new(1.0, 1.0), 0.5),
            Err(PlanError::BallOnGoal { .. })
        ));
        assert!(behind_ball(Point2::origin(), Point2::new(1.0, 0.0), 0.0).is_err());
    }

    #[test]
    fn sonar_obstacles_by_hand() {
        // Robot at (1, 1) facing +y; sonar at bearing −90° (its right = field +x) sees 0.5 m.
        // Echo radius 0.1: centre 0.6 m away → (1.6, 1).
        let pose = Pose2::new(1.0, 1.0, FRAC_PI_2);
        let sonars =
            [Sonar::new(-FRAC_PI_2, 0.5), Sonar::new(0.0, f64::INFINITY), Sonar::new(0.0, 6.0)];
        let obs = sonar_obstacles(&pose, &sonars, 0.1, 5.0);
        assert_eq!(obs.len(), 1);
        assert!(
            close(obs[0].center.x, 1.6) && close(obs[0].center.y, 1.0) && close(obs[0].radius, 0.1)
        );
    }
}
