//! The simulated robots' devices: [`PitchDevices`] implement the robot program's
//! [`Devices`] on the pitch of this process (camera, mice and wheels, sonars from the
//! simulator's sensor models; motors through the [`SimulatedAirboard`]; faults booked by the
//! referee's assistant).

use crate::drivers::SimulatedAirboard;
use crate::error::SimError;
use crate::game::Pitch;
use mrt_msgs::{CameraFrame, GameInfo, Odometry, Sonar};
use mrt_robot::base::MotorDriver;
use mrt_robot::devices::{DeviceError, Devices};
use std::sync::{Arc, Mutex};

/// The devices of robot `robot` on a pitch in this process.
pub struct PitchDevices {
    pitch: Arc<Mutex<Pitch>>,
    robot: usize,
    airboard: SimulatedAirboard,
}

impl PitchDevices {
    /// Robot `robot`'s devices on `pitch`.
    pub fn new(pitch: Arc<Mutex<Pitch>>, robot: usize) -> Result<PitchDevices, SimError> {
        let base = pitch.lock().map_err(|_| SimError::Poisoned("pitch"))?.base();
        let airboard = SimulatedAirboard::new(pitch.clone(), robot, base);
        Ok(PitchDevices { pitch, robot, airboard })
    }

    fn with<T>(&self, f: impl FnOnce(&mut Pitch, usize) -> T) -> Result<T, DeviceError> {
        let mut p = self.pitch.lock().map_err(|_| DeviceError::Poisoned("pitch"))?;
        Ok(f(&mut p, self.robot))
    }
}

impl Devices for PitchDevices {
    fn odometry(&mut self) -> Result<Odometry, DeviceError> {
        self.with(|p, i| p.odometry(i))
    }

    fn camera(&mut self) -> Result<CameraFrame, DeviceError> {
        self.with(|p, i| p.camera(i))
    }

    fn game(&mut self) -> Result<GameInfo, DeviceError> {
        self.with(|p, i| p.game_info(i))
    }

    fn sonars(&mut self) -> Result<Vec<Sonar>, DeviceError> {
        self.with(|p, i| p.sonar(i))
    }

    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DeviceError> {
        self.airboard.set_duty(duty).map_err(|e| DeviceError::Refused(e.to_string()))
    }

    fn kick(&mut self) -> Result<(), DeviceError> {
        self.with(|p, i| p.kick(i))
    }

    fn set_pan(&mut self, pan: f64) -> Result<(), DeviceError> {
        self.with(|p, i| p.set_pan(i, pan))?.map_err(|e| DeviceError::Refused(e.to_string()))
    }

    fn fault(&mut self, message: &str) -> Result<(), DeviceError> {
        self.with(|p, i| p.fault(i, 1, message))
    }
}
