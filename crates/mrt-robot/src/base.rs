//! The robot's base and motors, in the spirit of the AIRBoard (MRT manual ch. 5): the
//! processing side turns a velocity command into one PWM duty cycle per wheel ([`Base::duties`]);
//! the driver side ([`MotorDriver`]) applies duty cycles to the motors. A real robot's driver
//! talks to its board; the simulator's turns duty cycles back into the body velocity its robot
//! follows ([`Base::twist_for`]), so wheel-speed limits shape the motion exactly as on a real
//! base (a differential drive cannot move sideways; a command beyond a wheel's top speed is
//! scaled down as a whole, keeping its direction).

use mrt_core::frames::MM_PER_M;
use mrt_msgs::RobotCommand;
use mrt_plan::kinematics::{
    duty_cycle, DiffDrive, Kinematics, Omni3, OmniWheels, Steering, Twist, WheelSpeeds,
};

/// What a motor driver refuses.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum DriverError {
    /// Not one duty cycle per wheel.
    #[error("{got} duty cycles for {wheels} wheels")]
    WheelCount {
        /// Wheels of the base.
        wheels: usize,
        /// Duty cycles given.
        got: usize,
    },
}

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
    pub fn parse(name: &str) -> Result<Base, String> {
        match name {
            "differential" => Ok(Base::Differential(DiffDrive::ianus3())),
            "omni" => Ok(Base::Omni(Omni3::triskar())),
            other => Err(format!("robot.base must be differential or omni, not {other}")),
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

    /// The processing side: a command (mm/s, deg/s) → one duty cycle per wheel. A command
    /// beyond the wheels' top speed is scaled down as a whole (direction kept).
    pub fn duties(&self, cmd: &RobotCommand) -> Vec<f64> {
        let finite = |x: f64| if x.is_finite() { x } else { 0.0 };
        // The command's edge units (mm/s, deg/s: the behaviors' own) to SI.
        let twist = Twist::new(
            finite(cmd.vlin) / MM_PER_M,
            finite(cmd.vlat) / MM_PER_M,
            finite(cmd.vrot).to_radians(),
        );
        match self {
            Base::Differential(k) => {
                let w = k.inverse(&k.limit(&twist));
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
        if duty.len() != self.wheels() {
            return Err(DriverError::WheelCount { wheels: self.wheels(), got: duty.len() });
        }
        let d = |i: usize| {
            let x = duty[i];
            if x.is_nan() {
                0.0
            } else {
                x.clamp(-1.0, 1.0)
            }
        };
        Ok(match self {
            Base::Differential(k) => {
                let m = k.params().max_wheel_speed;
                k.forward(&WheelSpeeds([d(0) * m, d(1) * m]))
            }
            Base::Omni(k) => {
                let m = k.params().max_wheel_speed;
                let w: OmniWheels = WheelSpeeds([d(0) * m, d(1) * m, d(2) * m]);
                k.forward(&w)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cmd(vlin: f64, vlat: f64, vrot: f64) -> RobotCommand {
        RobotCommand { vlin, vlat, vrot, ..Default::default() }
    }

    #[test]
    fn a_differential_base_cannot_move_sideways() {
        let b = Base::parse("differential").unwrap();
        let d = b.twist_for(&b.duties(&cmd(500.0, 400.0, 0.0))).unwrap();
        assert!((d.vx - 0.5).abs() < 1e-9 && d.vy == 0.0, "{d:?}");
    }

    #[test]
    fn an_omni_base_moves_any_way_and_commands_round_trip() {
        let b = Base::parse("omni").unwrap();
        let d = b.twist_for(&b.duties(&cmd(300.0, -400.0, 45.0))).unwrap();
        assert!((d.vx - 0.3).abs() < 1e-9 && (d.vy + 0.4).abs() < 1e-9, "{d:?}");
        assert!((d.omega - 45f64.to_radians()).abs() < 1e-9);
    }

    /// Triskar's wheels top out at 30 rad/s × 4 cm = 1.2 m/s of rim speed. Straight ahead,
    /// wheels 1 and 2 (at 120° and 240°) turn at ±sin 60° · v / r, so the top forward speed is
    /// 1.2 / sin 60° = 1.386 m/s; 5 m/s is scaled down to that, still straight ahead.
    #[test]
    fn too_fast_is_scaled_down_keeping_the_direction() {
        let b = Base::parse("omni").unwrap();
        let duty = b.duties(&cmd(5000.0, 0.0, 0.0));
        assert!(duty.iter().all(|x| x.abs() <= 1.0 + 1e-12));
        let d = b.twist_for(&duty).unwrap();
        assert!((d.vx - 1.2 / 60f64.to_radians().sin()).abs() < 1e-6 && d.vy.abs() < 1e-9, "{d:?}");
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
