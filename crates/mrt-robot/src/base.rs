//! The robot's base and motors, in the spirit of the AIRBoard (MRT manual ch. 5): the
//! processing side turns a velocity command into one PWM duty cycle per wheel ([`Base::duties`]);
//! the driver side ([`MotorDriver`]) applies duty cycles to the motors. A real robot's driver
//! talks to its board; the simulator's turns duty cycles back into the body velocity its robot
//! follows ([`Base::twist_for`]), so wheel-speed limits shape the motion exactly as on a real
//! base (a command beyond a wheel's top speed is scaled down as a whole, keeping its
//! direction).
//!
//! Behaviors think holonomically: a Mr. BRIAN `SpeedAngle` or a TeamChaos strafe asks for a
//! direction of motion, which a Triskar drives as it is. A differential drive cannot move
//! sideways, so it steers toward the asked direction instead ([`follow_on_differential`]):
//! a sideways request turns the base while it drives the part of the request along its
//! heading, and the behavior, which sees the robot turn, closes the loop.

use crate::error::{DriverError, RobotError};
use mrt_core::Pose2;
use mrt_msgs::Displacement;
use mrt_plan::kinematics::{
    duty_cycle, integrate, nearer_end, DiffDrive, Kinematics, Omni3, OmniWheels, Steering, Twist,
    WheelSpeeds,
};

/// The driver side of the AIRBoard: one PWM duty cycle in `[-1, 1]` per wheel.
pub trait MotorDriver: Send {
    /// Number of wheels (motors).
    fn wheels(&self) -> usize;
    /// Drives the motors; values outside `[-1, 1]` or not finite are clamped (NaN: 0).
    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DriverError>;
}

/// A robot base: its kinematics and wheel limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Base {
    /// Two central wheels (the manual's IANUS3): no sideways motion.
    Differential(DiffDrive),
    /// Three omni wheels at 120° (the manual's Triskar): holonomic.
    Omni(Omni3),
}

impl Base {
    /// Parses `differential` (IANUS3) or `omni` (Triskar).
    pub fn parse(name: &str) -> Result<Base, RobotError> {
        match name {
            "differential" => Ok(Base::Differential(DiffDrive::ianus3())),
            "omni" => Ok(Base::Omni(Omni3::triskar())),
            other => Err(RobotError::UnknownBase(other.to_string())),
        }
    }

    /// How guidance may steer this base.
    pub fn steering(&self) -> Steering {
        match self {
            Base::Differential(_) => Steering::Differential,
            Base::Omni(_) => Steering::Holonomic,
        }
    }

    /// Number of wheels.
    pub fn wheels(&self) -> usize {
        match self {
            Base::Differential(_) => 2,
            Base::Omni(_) => 3,
        }
    }

    /// The processing side: a body velocity (robot frame, m/s and rad/s; a component that is
    /// not finite is 0) → one duty cycle per wheel. A twist beyond the wheels' top speed is
    /// scaled down as a whole (direction kept). On a differential base a sideways part steers
    /// the base toward it ([`follow_on_differential`]).
    pub fn duties(&self, twist: &Twist) -> Vec<f64> {
        let twist = twist.finite_or_zero();
        match self {
            Base::Differential(k) => {
                let w = k.inverse(&k.limit(&follow_on_differential(twist)));
                w.0.iter().map(|s| duty_cycle(*s, k.params().max_wheel_speed)).collect()
            }
            Base::Omni(k) => {
                let w = k.inverse(&k.limit(&twist));
                w.0.iter().map(|s| duty_cycle(*s, k.params().max_wheel_speed)).collect()
            }
        }
    }

    /// The motors' side: duty cycles → wheel speeds → the body velocity (robot frame, m/s and
    /// rad/s): what a base does with duty cycles (a simulator's motor model).
    pub fn twist_for(&self, duty: &[f64]) -> Result<Twist, DriverError> {
        Ok(self.forward(&self.wheel_speeds(duty)?))
    }

    /// The body velocity (robot frame, m/s and rad/s) that wheel speeds (rad/s, in wheel
    /// order) drive: what a simulator does with a robot's wheel set-points.
    pub fn twist_of(&self, wheels: &[f64]) -> Result<Twist, DriverError> {
        if wheels.len() != self.wheels() {
            return Err(DriverError::WheelCount { wheels: self.wheels(), got: wheels.len() });
        }
        Ok(self.forward(wheels))
    }

    /// The wheel speeds (rad/s, in wheel order) that duty cycles ask for: each duty cycle,
    /// clamped to `[-1, 1]` (NaN: 0), times the wheels' top speed.
    pub fn wheel_speeds(&self, duty: &[f64]) -> Result<Vec<f64>, DriverError> {
        if duty.len() != self.wheels() {
            return Err(DriverError::WheelCount { wheels: self.wheels(), got: duty.len() });
        }
        let top = match self {
            Base::Differential(k) => k.params().max_wheel_speed,
            Base::Omni(k) => k.params().max_wheel_speed,
        };
        Ok(duty.iter().map(|&x| if x.is_nan() { 0.0 } else { x.clamp(-1.0, 1.0) * top }).collect())
    }

    /// The motion the wheels' encoders tell: each wheel's turn (rad, in wheel order) over one
    /// period → the robot's displacement along the arc they drive, in the robot frame at the
    /// start of the period.
    pub fn motion(&self, turns: &[f64]) -> Result<Displacement, DriverError> {
        if turns.len() != self.wheels() {
            return Err(DriverError::WheelCount { wheels: self.wheels(), got: turns.len() });
        }
        let moved = integrate(Pose2::default(), &self.forward(turns), 1.0);
        Ok(Displacement::new(moved.x, moved.y, moved.theta))
    }

    /// The wheel speeds (rad/s, in wheel order) that drive the body at `twist` (robot frame,
    /// m/s and rad/s), unlimited; a differential base ignores `vy`. What a simulator's wheel
    /// encoders count: the speed each wheel turns at for the body's set-point.
    pub fn wheels_for(&self, twist: &Twist) -> Vec<f64> {
        match self {
            Base::Differential(k) => k.inverse(twist).0.to_vec(),
            Base::Omni(k) => k.inverse(twist).0.to_vec(),
        }
    }

    /// Wheel speeds (as many as the base has wheels) → the body velocity.
    fn forward(&self, w: &[f64]) -> Twist {
        let at = |i: usize| w.get(i).copied().unwrap_or(0.0);
        match self {
            Base::Differential(k) => k.forward(&WheelSpeeds([at(0), at(1)])),
            Base::Omni(k) => {
                let w: OmniWheels = WheelSpeeds([at(0), at(1), at(2)]);
                k.forward(&w)
            }
        }
    }
}

/// Turn rate per radian between the heading and a requested direction of motion, 1/s.
pub const STEER_GAIN: f64 = 3.0;

/// A sideways request this fast (m/s) or faster is steered toward alone; a slower one shares
/// the turn with the behavior's own turn rate in proportion.
pub const STEER_SPEED: f64 = 0.3;

/// How near (rad) to square with the heading a request's direction is a tie between the
/// base's front and back: the base then takes the end its behavior's own turn agrees with,
/// so that the two turns add up instead of cancelling (a search that spins while it drifts
/// sideways would otherwise stand still).
pub const STEER_TIE: f64 = 0.35;

/// A holonomic request (robot frame, m/s and rad/s) as a differential drive can follow it.
/// With no sideways part it is returned as it is (forward, backward, turning). Otherwise the
/// base drives the request's part along its heading, `speed · cos(direction)`, and turns
/// toward the direction at [`STEER_GAIN`] per radian, or toward its opposite when that is
/// behind (the base then backs into it, as [`mrt_plan::guidance::PositionMode`] does). The
/// behavior's own turn rate, which on a holonomic base would turn it while it slides (to
/// face the ball on its way behind it), gives way to the steering as the sideways part grows
/// to [`STEER_SPEED`]: a differential base must face where it goes, and turns to the ball
/// once it is there and the request is small. Within [`STEER_TIE`] of square, the end is the
/// one the behavior's turn agrees with. The result has `vy = 0`.
pub fn follow_on_differential(t: Twist) -> Twist {
    if !t.is_finite() {
        return Twist::ZERO;
    }
    if t.vy == 0.0 {
        return t;
    }
    let direction = t.vy.atan2(t.vx);
    let mut toward = nearer_end(direction);
    let square = (direction.abs() - std::f64::consts::FRAC_PI_2).abs() < STEER_TIE;
    if square && t.omega != 0.0 && toward.signum() != t.omega.signum() {
        // The other end: as far to turn within the tie, and the same way as the behavior.
        toward -= std::f64::consts::PI.copysign(toward);
    }
    let share = (t.vy.abs() / STEER_SPEED).min(1.0);
    let omega = (1.0 - share) * t.omega + share * STEER_GAIN * toward;
    Twist::new(t.speed() * direction.cos(), 0.0, omega)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(vx: f64, vy: f64, omega: f64) -> Twist {
        Twist::new(vx, vy, omega)
    }

    #[test]
    fn a_differential_base_steers_toward_a_sideways_request() {
        let b = Base::parse("differential").unwrap();
        // Ahead and to the left: forward at the request's projection, turning left.
        let d = b.twist_for(&b.duties(&cmd(0.5, 0.4, 0.0))).unwrap();
        assert!(d.vy == 0.0 && d.omega > 0.5 && d.vx > 0.0, "{d:?}");
        let straight = follow_on_differential(Twist::new(0.5, 0.4, 0.0));
        assert!((straight.vx - 0.5).abs() < 1e-9, "{straight:?}");
        // A pure strafe to the right turns right in place.
        let d = b.twist_for(&b.duties(&cmd(0.0, -0.4, 0.0))).unwrap();
        assert!(d.vx.abs() < 1e-9 && d.omega < -1.0, "{d:?}");
        // Behind and to the left: backs up, turning its back toward it (clockwise).
        let d = follow_on_differential(Twist::new(-0.5, 0.1, 0.0));
        assert!(d.vx < -0.4 && d.omega < 0.0, "{d:?}");
        // Without a sideways part nothing changes, backward included.
        for t in [Twist::new(0.5, 0.0, 0.3), Twist::new(-0.4, 0.0, -1.0), Twist::ZERO] {
            assert_eq!(follow_on_differential(t), t);
        }
        // A fast sideways request is steered toward alone; a slow one shares the turn with
        // the behavior's, which alone turns the base when the request has no sideways part.
        let fast = follow_on_differential(Twist::new(0.3, 0.6, -1.0));
        assert!((fast.omega - STEER_GAIN * 2f64.atan()).abs() < 1e-12, "{fast:?}");
        let slow = follow_on_differential(Twist::new(0.05, 0.01, -1.0));
        assert!(slow.omega < 0.0 && slow.omega > -1.0, "{slow:?}");
        assert_eq!(follow_on_differential(Twist::new(f64::NAN, 1.0, 0.0)), Twist::ZERO);
    }

    #[test]
    fn a_spin_and_a_sideways_drift_never_cancel_on_a_differential_base() {
        // A search turning at π rad/s while it drifts sideways (0.12 m/s, either side, a
        // little ahead or behind): the base turns the behavior's way, at least as fast as
        // the behavior's share of the turn.
        for omega in [std::f64::consts::PI, -std::f64::consts::PI] {
            for vy in [0.12, -0.12, 0.3, -0.3] {
                for vx in [-0.03, -0.001, 0.0, 0.001, 0.03] {
                    let d = follow_on_differential(Twist::new(vx, vy, omega));
                    let share = (vy.abs() / STEER_SPEED).min(1.0);
                    assert!(
                        d.omega.signum() == omega.signum()
                            && d.omega.abs() >= (1.0 - share) * omega.abs() - 1e-9,
                        "{vx} {vy} {omega}: {d:?}"
                    );
                }
            }
        }
        // Away from square the nearer end still wins whatever the behavior's turn: backing
        // up, steered clockwise below the behavior's share of its counter-clockwise turn.
        let d = follow_on_differential(Twist::new(-0.5, 0.1, 1.0));
        assert!(d.vx < -0.4 && d.omega < 1.0 - 0.1 / STEER_SPEED, "{d:?}");
    }

    #[test]
    fn an_omni_base_moves_any_way_and_commands_round_trip() {
        let b = Base::parse("omni").unwrap();
        let d = b.twist_for(&b.duties(&cmd(0.3, -0.4, 45f64.to_radians()))).unwrap();
        assert!((d.vx - 0.3).abs() < 1e-9 && (d.vy + 0.4).abs() < 1e-9, "{d:?}");
        assert!((d.omega - 45f64.to_radians()).abs() < 1e-9);
    }

    /// Triskar's wheels top out at 30 rad/s × 4 cm = 1.2 m/s of rim speed. Straight ahead,
    /// wheels 1 and 2 (at 120° and 240°) turn at ±sin 60° · v / r, so the top forward speed is
    /// 1.2 / sin 60° = 1.386 m/s; 5 m/s is scaled down to that, still straight ahead.
    #[test]
    fn too_fast_is_scaled_down_keeping_the_direction() {
        let b = Base::parse("omni").unwrap();
        let duty = b.duties(&cmd(5.0, 0.0, 0.0));
        assert!(duty.iter().all(|x| x.abs() <= 1.0 + 1e-12));
        let d = b.twist_for(&duty).unwrap();
        assert!((d.vx - 1.2 / 60f64.to_radians().sin()).abs() < 1e-6 && d.vy.abs() < 1e-9, "{d:?}");
    }

    #[test]
    fn encoder_turns_give_the_motion_the_wheels_drive() {
        for b in [Base::parse("differential").unwrap(), Base::parse("omni").unwrap()] {
            // What one second at these duty cycles turns the wheels by, moves the robot by
            // the arc of the twist they make.
            let duty = b.duties(&cmd(0.4, 0.0, 30f64.to_radians()));
            let turns = b.wheel_speeds(&duty).unwrap();
            let d = b.motion(&turns).unwrap();
            let p = integrate(Pose2::default(), &b.twist_for(&duty).unwrap(), 1.0);
            assert!((d.dx - p.x).abs() < 1e-12 && (d.dtheta - 30f64.to_radians()).abs() < 1e-9);
            assert!(d.dx > 0.3, "{d:?}");
            assert!(b.motion(&[0.1]).is_err());
        }
    }

    #[test]
    fn the_wheels_for_a_twist_drive_that_twist() {
        let t = Twist::new(0.6, 0.2, -0.8);
        let omni = Base::parse("omni").unwrap();
        let back = omni.twist_of(&omni.wheels_for(&t)).unwrap();
        assert!((back.vx - t.vx).abs() < 1e-12 && (back.vy - t.vy).abs() < 1e-12);
        assert!((back.omega - t.omega).abs() < 1e-12);
        // A differential base drives the twist without its sideways part.
        let diff = Base::parse("differential").unwrap();
        let back = diff.twist_of(&diff.wheels_for(&t)).unwrap();
        assert!((back.vx - t.vx).abs() < 1e-12 && back.vy == 0.0);
        assert!((back.omega - t.omega).abs() < 1e-12);
        assert_eq!((omni.wheels_for(&t).len(), diff.wheels_for(&t).len()), (3, 2));
        assert!(diff.twist_of(&[1.0]).is_err());
    }

    #[test]
    fn bad_duty_cycles_are_refused_or_clamped() {
        let b = Base::parse("differential").unwrap();
        assert_eq!(b.twist_for(&[0.5]), Err(DriverError::WheelCount { wheels: 2, got: 1 }));
        let d = b.twist_for(&[f64::NAN, 7.0]).unwrap();
        assert!(d.vx > 0.0 && d.omega > 0.0, "right wheel at full speed: {d:?}");
        assert!(Base::parse("legs").is_err());
        assert_eq!(b.duties(&cmd(f64::INFINITY, 0.0, f64::NAN)), vec![0.0, 0.0]);
    }
}
