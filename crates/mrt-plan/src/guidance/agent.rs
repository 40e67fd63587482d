//! The Guidance µAgent of ISocRob (ISocRob-2000 report §3.2.3) as one call per control
//! cycle: it sits between the behaviors and the motor driver and runs the mode the behavior's
//! command asks for, with the sonar ring as its obstacle sensor.
//!
//! - a command **without a target** is a velocity reference: **velocity mode**
//!   ([`VelocityGuard`]) passes it on unless a sonar sees an obstacle in the direction of
//!   motion, then the translation is halted. Echoes from where the world model puts the ball
//!   are not obstacles here: a soccer robot must be able to touch the ball, and with a sonar
//!   ring it could not otherwise (the report's footnote on the headaches of halting);
//! - a command with a [`Target`] without `avoid`: **position mode** ([`PositionMode`]);
//! - with `avoid`: **potential-field mode** ([`PotentialField`]): the sonar echoes, the ball's
//!   included as the report says, repel; the target attracts;
//! - with `plan` (a pose on a planned path): **path mode**, position mode halted by the sonars
//!   as velocity mode is.
//!
//! SI throughout: the command's twist in m/s and rad/s, poses in the team frame in metres.
//!
//! ```
//! use mrt_core::frames::Framed;
//! use mrt_core::{Point2, Pose2, Twist};
//! use mrt_msgs::robot::{RobotCommand, Target};
//! use mrt_plan::guidance::{Guidance, Mode, Sonar};
//!
//! let guidance = Guidance::default();
//! let me = Framed::new(Pose2::new(0.0, 0.0, 0.0));
//! // Forward at 1 m/s, a wall 0.3 m ahead (sonar 0): halted, still turning.
//! let ring: Vec<Sonar> = (0..16).map(|i| Sonar::new(Sonar::ring_bearing(i, 16), 0.3)).collect();
//! let go = RobotCommand { twist: Twist::new(1.0, 0.0, 0.5), ..Default::default() };
//! let g = guidance.guide(&go, me, None, &ring);
//! assert!(g.halted && g.twist == Twist::new(0.0, 0.0, 0.5));
//! // The same echo where the ball is: not an obstacle, the robot goes on to the ball.
//! let g = guidance.guide(&go, me, Some(Framed::new(Point2::new(0.41, 0.0))), &ring);
//! assert!(!g.halted && g.twist == go.twist);
//! // Go to (1 m, 0) in position mode: straight ahead, at most 1.2 m/s.
//! let to = RobotCommand {
//!     target: Some(Target { pose: Framed::new(Pose2::new(1.0, 0.0, 0.0)), avoid: false, plan: false }),
//!     ..Default::default()
//! };
//! let g = guidance.guide(&to, me, None, &[]);
//! assert_eq!(g.mode, Mode::Position);
//! assert!((g.twist.vx - 1.2).abs() < 1e-9 && g.twist.vy.abs() < 1e-9);
//! ```

use super::{GuidanceCommand, Obstacle, PositionMode, PotentialField, Sonar, VelocityGuard};
use mrt_core::frames::{Framed, Team};
use mrt_core::{Point2, Pose2, Twist};
use mrt_msgs::robot::{RobotCommand, Target};

/// The mode guidance ran in one cycle.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// A velocity reference, halted by the sonars.
    #[default]
    Velocity,
    /// Straight to a target posture.
    Position,
    /// To a target posture around what the sonars see.
    Potential,
    /// To a pose on a planned path, straight, halted by the sonars.
    Path,
}

/// What guidance hands to the motor driver.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Guided {
    /// The body velocity to drive, robot frame (m/s, rad/s).
    pub twist: Twist,
    /// The mode that made it.
    pub mode: Mode,
    /// Velocity and path modes: a sonar halted the translation. Position and potential modes:
    /// the target is reached.
    pub halted: bool,
}

/// How near an echo must be to the ball's estimated centre to be the ball, beyond the ball's
/// radius (m): a sonar's beam and the estimate's noise put the echo off the ball's surface.
const BALL_ECHO_TOLERANCE: f64 = 0.15;

/// Radius of the obstacle a lone echo stands for in potential-field mode (m).
const ECHO_RADIUS: f64 = 0.1;

/// Echoes of neighbouring sonars closer than this to each other are one obstacle (m).
const SAME_OBSTACLE: f64 = 0.35;

/// The Guidance µAgent: the three modes and their parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guidance {
    guard: VelocityGuard,
    field: PotentialField,
    ball_radius: f64,
}

impl Default for Guidance {
    /// The defaults of [`VelocityGuard`] and [`PotentialField`] (a holonomic Middle Size
    /// League robot, 1.2 m/s) and a FIFA size 5 ball (0.11 m).
    fn default() -> Self {
        Guidance::new(VelocityGuard::default(), PotentialField::default(), 0.11)
    }
}

impl Guidance {
    /// Guidance with these modes; `ball_radius` (m) tells the ball's echoes apart.
    pub fn new(guard: VelocityGuard, field: PotentialField, ball_radius: f64) -> Self {
        let ball_radius = if ball_radius.is_finite() { ball_radius.max(0.0) } else { 0.0 };
        Guidance { guard, field, ball_radius }
    }

    /// One cycle: `cmd` from the behaviors, the robot's pose `me` and the ball's position
    /// (`None` when unknown), the sonar ring (robot frame, m from the centre).
    pub fn guide(
        &self,
        cmd: &RobotCommand,
        me: Framed<Team, Pose2>,
        ball: Option<Framed<Team, Point2>>,
        sonars: &[Sonar],
    ) -> Guided {
        let pose = me.inner;
        let Some(Target { pose: target, avoid, plan }) = cmd.target else {
            // Velocity mode: the reference itself, or its turn only.
            let (twist, halted) = self.halt_for_echoes(cmd.twist, &pose, ball, sonars);
            return Guided { twist, mode: Mode::Velocity, halted };
        };
        let target = target.inner;
        if plan {
            let GuidanceCommand { twist, .. } = self.position().command(&pose, &target);
            let (twist, halted) = self.halt_for_echoes(twist, &pose, ball, sonars);
            return Guided { twist, mode: Mode::Path, halted };
        }
        let (mode, GuidanceCommand { twist, done }) = if avoid {
            (Mode::Potential, self.field.command(&pose, &target, &echo_obstacles(&pose, sonars)))
        } else {
            (Mode::Position, self.position().command(&pose, &target))
        };
        Guided { twist, mode, halted: done }
    }

    /// Velocity mode's guard: `twist` with its translation stopped when a sonar that does not
    /// see the ball sees an obstacle in the direction of motion, and whether it was.
    fn halt_for_echoes(
        &self,
        twist: Twist,
        pose: &Pose2,
        ball: Option<Framed<Team, Point2>>,
        sonars: &[Sonar],
    ) -> (Twist, bool) {
        let ball = ball.map(|b| b.inner);
        let echoes: Vec<Sonar> =
            sonars.iter().filter(|s| !self.is_ball(pose, ball, s)).copied().collect();
        if self.guard.apply(&twist, &echoes).done {
            (Twist::new(0.0, 0.0, twist.omega), true)
        } else {
            (twist, false)
        }
    }

    /// Position mode with the potential field's gains and limits.
    fn position(&self) -> PositionMode {
        PositionMode::new(*self.field.position_params()).unwrap_or_default()
    }

    /// Whether echo `s` seen from `pose` comes from the ball at `ball` (m).
    fn is_ball(&self, pose: &Pose2, ball: Option<Point2>, s: &Sonar) -> bool {
        let Some(ball) = ball else { return false };
        if !(s.range.is_finite() && s.bearing.is_finite()) {
            return false;
        }
        let (sn, cs) = s.bearing.sin_cos();
        let echo = pose.transform_point(Point2::new(s.range * cs, s.range * sn));
        (echo - ball).norm() <= self.ball_radius + BALL_ECHO_TOLERANCE
    }
}

/// The obstacles the sonar ring sees from `pose` (field frame, m): the echoes of neighbouring
/// sonars (in ring order, the last next to the first) that lie within 0.35 m of
/// each other are one circle, whose near side is at their mean and whose radius covers them.
///
/// One circle per object matters: a robot ahead echoes in two or three sonars, and as separate
/// circles their sideways pushes cancel and leave the robot stalled in front of it; as one
/// circle the potential field walks round it.
pub fn echo_obstacles(pose: &Pose2, sonars: &[Sonar]) -> Vec<Obstacle> {
    let points: Vec<Option<Point2>> = sonars
        .iter()
        .map(|s| {
            (s.range.is_finite() && s.bearing.is_finite() && s.range > 0.0).then(|| {
                let (sn, cs) = s.bearing.sin_cos();
                pose.transform_point(Point2::new(s.range * cs, s.range * sn))
            })
        })
        .collect();
    let joined = |a: usize, b: usize| match (points[a], points[b]) {
        (Some(a), Some(b)) => (a - b).norm() <= SAME_OBSTACLE,
        _ => false,
    };
    mrt_core::ring_runs(points.len(), joined)
        .iter()
        .filter_map(|run| {
            let cluster: Vec<Point2> = run.iter().filter_map(|&k| points[k]).collect();
            circle(pose, &cluster)
        })
        .collect()
}

/// The circle standing for echoes `points` seen from `pose`: near side at their mean.
fn circle(pose: &Pose2, points: &[Point2]) -> Option<Obstacle> {
    let first = points.first()?;
    let sum = points.iter().fold(nalgebra::Vector2::zeros(), |s, p| s + (p - first));
    let mean = first + sum / points.len() as f64;
    let spread = points.iter().map(|p| (p - mean).norm()).fold(0.0, f64::max);
    let radius = spread.max(ECHO_RADIUS);
    let away = mean - pose.position();
    let u = if away.norm() > 1e-9 { away / away.norm() } else { away };
    let c = mean + u * radius;
    Some(Obstacle::new(c.x, c.y, radius))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::guidance::{PositionParams, PotentialParams};

    fn ring(range: f64) -> Vec<Sonar> {
        (0..16).map(|i| Sonar::new(Sonar::ring_bearing(i, 16), range)).collect()
    }

    fn at(x: f64, y: f64, theta: f64) -> Framed<Team, Pose2> {
        Framed::new(Pose2::new(x, y, theta))
    }

    fn ball(x: f64, y: f64) -> Option<Framed<Team, Point2>> {
        Some(Framed::new(Point2::new(x, y)))
    }

    /// Velocity mode passes a reference through unchanged when nothing is near, halts the
    /// translation for a robot ahead but not for the ball, and looks sideways for a sideways
    /// motion.
    #[test]
    fn velocity_mode_halts_for_obstacles_not_for_the_ball() {
        let g = Guidance::default();
        let me = at(1.0, 0.5, std::f64::consts::FRAC_PI_2); // facing +y
        let go = RobotCommand { twist: Twist::new(0.8, 0.0, -0.35), ..Default::default() };
        let free = g.guide(&go, me, None, &ring(f64::INFINITY));
        assert_eq!((free.twist, free.mode, free.halted), (go.twist, Mode::Velocity, false));
        // An echo 0.4 m ahead (inside 0.5 m): halted, turning kept.
        let mut near = ring(f64::INFINITY);
        near[0].range = 0.4;
        let h = g.guide(&go, me, None, &near);
        assert!(h.halted && h.twist == Twist::new(0.0, 0.0, -0.35), "{h:?}");
        // The ball 0.51 m ahead in the field (1, 1.01): its near side at 0.4 m is that echo.
        let b = g.guide(&go, me, ball(1.0, 1.01), &near);
        assert!(!b.halted && b.twist == go.twist, "{b:?}");
        // The ball elsewhere (behind the robot) does not hide the echo ahead.
        assert!(g.guide(&go, me, ball(1.0, 0.0), &near).halted);
        // Moving left looks at sonar 4 (90°), not sonar 0.
        let left = RobotCommand { twist: Twist::new(0.0, 0.5, 0.0), ..Default::default() };
        assert!(!g.guide(&left, me, None, &near).halted);
        near[4].range = 0.3;
        assert!(g.guide(&left, me, None, &near).halted);
    }

    /// Clustering by hand, robot at the origin facing +x, four sonars at 0°, 90°, 180°, 270°
    /// and then eight: echoes 0.5 m ahead and 0.5 m to the left are 0.71 m apart: two
    /// obstacles, each a lone echo (radius 0.1 m, centre 0.6 m out). With eight sonars, echoes
    /// at 0° (0.5 m) and 45° (0.5 m) are 0.38 m apart... still two; at 0.4 m they are
    /// 2 · 0.4 · sin 22.5° = 0.306 m apart: one circle, near side at their mean
    /// (0.341, 0.141), radius 0.153 (half their distance).
    #[test]
    fn neighbouring_echoes_are_one_obstacle() {
        let me = Pose2::new(0.0, 0.0, 0.0);
        let four = |r: [f64; 4]| -> Vec<Sonar> {
            (0..4).map(|i| Sonar::new(Sonar::ring_bearing(i, 4), r[i])).collect()
        };
        let inf = f64::INFINITY;
        let two = echo_obstacles(&me, &four([0.5, 0.5, inf, inf]));
        assert_eq!(two.len(), 2);
        assert!((two[0].center - Point2::new(0.6, 0.0)).norm() < 1e-9, "{two:?}");
        assert!((two[1].center - Point2::new(0.0, 0.6)).norm() < 1e-9 && two[1].radius == 0.1);
        assert!(echo_obstacles(&me, &four([inf; 4])).is_empty());
        let eight = |r0: f64, r1: f64| -> Vec<Obstacle> {
            let mut s: Vec<Sonar> =
                (0..8).map(|i| Sonar::new(Sonar::ring_bearing(i, 8), inf)).collect();
            (s[0].range, s[1].range) = (r0, r1);
            echo_obstacles(&me, &s)
        };
        assert_eq!(eight(0.5, 0.5).len(), 2);
        let one = eight(0.4, 0.4);
        assert_eq!(one.len(), 1, "{one:?}");
        let half = 0.4 * (std::f64::consts::PI / 8.0).sin();
        let mean = Point2::new((0.4 + 0.4 * 0.5f64.sqrt()) / 2.0, 0.4 * 0.5f64.sqrt() / 2.0);
        assert!((one[0].radius - half).abs() < 1e-9);
        let near_side = one[0].center - (mean - Point2::origin()).normalize() * half;
        assert!((near_side - mean).norm() < 1e-9, "{one:?}");
        // A ring whose last and first sonars see the same object: one obstacle, no wrap split.
        let mut s: Vec<Sonar> =
            (0..8).map(|i| Sonar::new(Sonar::ring_bearing(i, 8), inf)).collect();
        (s[7].range, s[0].range) = (0.4, 0.4);
        assert_eq!(echo_obstacles(&me, &s).len(), 1);
    }

    /// Position mode by hand: from (0, 0) facing +x to (0.5 m, 0.2 m) facing +x with gain
    /// 1.5 /s: velocity 1.5 · (0.5, 0.2) = (0.75, 0.3) m/s, under 1.2 m/s; no heading error.
    #[test]
    fn position_mode_by_hand() {
        let g = Guidance::default();
        let target = Target { pose: at(0.5, 0.2, 0.0), avoid: false, plan: false };
        let cmd = RobotCommand { target: Some(target), ..Default::default() };
        let out = g.guide(&cmd, at(0.0, 0.0, 0.0), None, &ring(0.3));
        assert_eq!(out.mode, Mode::Position);
        assert!((out.twist.vx - 0.75).abs() < 1e-9, "{out:?}");
        assert!((out.twist.vy - 0.3).abs() < 1e-9 && out.twist.omega.abs() < 1e-9);
        // There: done, standing still.
        let there = g.guide(&cmd, at(0.5, 0.2, 0.0), None, &[]);
        assert!(there.halted && there.twist.speed() == 0.0);
    }

    /// Path mode is position mode halted by the sonars: the same twist with nothing near, its
    /// translation stopped by an echo in the way, but not by the ball's.
    #[test]
    fn path_mode_is_position_mode_halted_by_the_sonars() {
        let g = Guidance::default();
        let to = |plan| RobotCommand {
            target: Some(Target { pose: at(0.5, 0.0, 0.0), avoid: false, plan }),
            ..Default::default()
        };
        let me = at(0.0, 0.0, 0.0);
        let free = g.guide(&to(true), me, None, &ring(f64::INFINITY));
        assert_eq!(free.mode, Mode::Path);
        assert_eq!(free.twist, g.guide(&to(false), me, None, &[]).twist);
        assert!(!free.halted && free.twist.vx > 0.5, "{free:?}");
        let mut near = ring(f64::INFINITY);
        near[0].range = 0.3;
        let h = g.guide(&to(true), me, None, &near);
        assert!(h.halted && h.twist.vx == 0.0 && h.mode == Mode::Path, "{h:?}");
        // The echo is the ball's (0.41 m ahead, its near side at 0.3 m): on it goes.
        assert!(!g.guide(&to(true), me, ball(0.41, 0.0), &near).halted);
        // Position mode itself drives into the echo.
        assert!(g.guide(&to(false), me, None, &near).twist.vx > 0.5);
    }

    /// Potential-field mode walks round an obstacle that position mode would drive into: a
    /// robot 1 m ahead on the way to a target 2 m ahead, seen by the sonars each cycle.
    #[test]
    fn potential_mode_goes_round_what_the_sonars_see() {
        let params = PositionParams::default();
        let g = Guidance::new(
            VelocityGuard::default(),
            PotentialField::new(params, PotentialParams::default()).unwrap(),
            0.11,
        );
        let obstacle = Point2::new(1.0, 0.0); // m, a robot of radius 0.25
        let sonars_at = |p: &Pose2| -> Vec<Sonar> {
            (0..16)
                .map(|i| {
                    let bearing = Sonar::ring_bearing(i, 16);
                    let dir = p.theta + bearing;
                    let (ox, oy) = (obstacle.x - p.x, obstacle.y - p.y);
                    // The ray from the centre meets the circle of radius 0.25 m?
                    let along = ox * dir.cos() + oy * dir.sin();
                    let off2 = ox * ox + oy * oy - along * along;
                    let range = if along > 0.0 && off2 < 0.0625 {
                        along - (0.0625 - off2).sqrt()
                    } else {
                        f64::INFINITY
                    };
                    Sonar::new(bearing, range)
                })
                .collect()
        };
        let target = Target { pose: at(2.0, 0.0, 0.0), avoid: true, plan: false };
        let cmd = RobotCommand { target: Some(target), ..Default::default() };
        let mut me = Pose2::new(0.0, 0.0, 0.0);
        let mut closest = f64::INFINITY;
        for _ in 0..400 {
            let out = g.guide(&cmd, Framed::new(me), None, &sonars_at(&me));
            assert_eq!(out.mode, Mode::Potential);
            let t = out.twist;
            let dt = 0.02;
            let (s, co) = me.theta.sin_cos();
            me.x += (t.vx * co - t.vy * s) * dt;
            me.y += (t.vx * s + t.vy * co) * dt;
            me.theta += t.omega * dt;
            closest = closest.min((me.x - obstacle.x).hypot(me.y - obstacle.y));
        }
        assert!((me.x - 2.0).abs() < 0.05 && me.y.abs() < 0.05, "reached: {me:?}");
        assert!(closest > 0.5, "never touched the obstacle (0.25 + 0.25 m): {closest}");
    }
}
