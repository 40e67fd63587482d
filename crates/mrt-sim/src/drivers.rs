//! The simulated motors: [`SimulatedAirboard`] is the robot program's
//! [`MotorDriver`] (AIRBoard-style, MRT manual ch. 5) on the pitch. It takes one PWM duty cycle
//! per wheel, as a real board does, turns them into the body velocity the base's wheels give
//! ([`Base::twist_for`]) and drives the simulated robot with it, so wheel-speed limits shape the
//! motion exactly as on a real base (a differential drive cannot move sideways; a command
//! beyond a wheel's top speed is scaled down as a whole, keeping its direction).

use mrt_robot::base::{Base, MotorDriver};
use mrt_robot::error::DriverError;

/// The simulated AIRBoard of one robot: duty cycles in, the robot's wheels turn in the world.
pub struct SimulatedAirboard {
    pitch: std::sync::Arc<std::sync::Mutex<crate::game::Pitch>>,
    robot: usize,
    base: Base,
}

impl SimulatedAirboard {
    /// The board of robot `robot` on `pitch`.
    pub fn new(
        pitch: std::sync::Arc<std::sync::Mutex<crate::game::Pitch>>,
        robot: usize,
        base: Base,
    ) -> Self {
        Self { pitch, robot, base }
    }
}

impl MotorDriver for SimulatedAirboard {
    fn wheels(&self) -> usize {
        self.base.wheels()
    }

    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DriverError> {
        let drive = self.base.twist_for(duty)?;
        if let Ok(mut p) = self.pitch.lock() {
            p.drive(self.robot, drive);
        }
        Ok(())
    }
}
