//! The robot's hardware interface: its devices as its driver Members reach them — the camera
//! (object sensor), the optical mice and wheel encoders, the sonar ring, the motors
//! (AIRBoard-style duty cycles) and the kicker, plus whoever books software faults (a
//! referee's assistant, a log).
//!
//! The driver Members ([`crate::members`]) talk to a [`Devices`] only, so the same robot
//! program runs on any hardware:
//! - a real robot: a team implements [`Devices`] for its base, camera and mice (see
//!   ARCHITECTURE.md, "Adding a real robot");
//! - the simulated pitch in the same process (`mrt_sim::devices::PitchDevices`);
//! - [`LinkedDevices`]: a world reached over the network (docs/devices.md): it holds the
//!   readings of the step the world sent and gathers what the drivers did for the robot's
//!   answer (see [`crate::remote`] and [`crate::world`]).

use mrt_msgs::{CameraFrame, GameInfo, Odometry, Sonar};
use std::sync::{Arc, Mutex};

/// What a device could not do. The driver Member that asked reports it as its job's error;
/// the robot's other Members go on.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum DeviceError {
    /// The world sent no such reading for this cycle (`"odometry"`, `"camera"`...).
    #[error("no {0} reading this cycle")]
    NotRead(&'static str),
    /// This robot has no such device (`"kicker"`, `"pan joint on its camera"`...).
    #[error("this robot has no {0}")]
    Absent(&'static str),
    /// The device refused what it was asked (a duty cycle out of range, a pan that is not an
    /// angle...), in its own words.
    #[error("{0}")]
    Refused(String),
    /// The device cannot be reached: a panic while it was in use left its lock poisoned.
    #[error("the {0}'s lock is poisoned")]
    Poisoned(&'static str),
}

/// A robot's devices (module doc).
pub trait Devices: Send {
    /// The mice and the wheels since the last reading (first in a cycle).
    fn odometry(&mut self) -> Result<Odometry, DeviceError>;
    /// What the object sensor sees now (after the odometry).
    fn camera(&mut self) -> Result<CameraFrame, DeviceError>;
    /// The game controller's news (the referee's state, which way the team attacks, the
    /// robot's kickoff pose).
    fn game(&mut self) -> Result<GameInfo, DeviceError>;
    /// The sonar ring (after the camera).
    fn sonars(&mut self) -> Result<Vec<Sonar>, DeviceError>;
    /// Drives the motors: one PWM duty cycle per wheel.
    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DeviceError>;
    /// Fires the kicker.
    fn kick(&mut self) -> Result<(), DeviceError>;
    /// Turns the camera's pan joint to `pan` (rad, counter-clockwise from straight ahead),
    /// asked by the gaze control (`[gaze]` of the robot file) once per cycle within the
    /// joint's range and speed. A robot without a pan joint keeps this default, an error.
    fn set_pan(&mut self, _pan: f64) -> Result<(), DeviceError> {
        Err(DeviceError::Absent("pan joint on its camera"))
    }
    /// Books a fault of the robot's software now (a script error with its file and line).
    fn fault(&mut self, message: &str) -> Result<(), DeviceError>;
}

/// One robot's devices, shared by its driver Members.
pub type SharedDevices = Arc<Mutex<dyn Devices>>;

/// The devices of a robot whose simulator runs elsewhere: the readings of the current cycle
/// (set by the robot's runner before the cycle) and what the drivers did during it (taken by
/// the runner after the cycle).
#[derive(Debug, Default)]
pub struct LinkedDevices {
    odometry: Option<Odometry>,
    camera: Option<CameraFrame>,
    game: Option<GameInfo>,
    sonars: Option<Vec<Sonar>>,
    duty: Option<Vec<f64>>,
    kick: bool,
    pan: Option<f64>,
    faults: Vec<String>,
}

/// One cycle's readings of a robot's devices (`None`: that device gave none).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Loaded {
    /// The mice and the wheels.
    pub odometry: Option<Odometry>,
    /// The camera.
    pub camera: Option<CameraFrame>,
    /// The game controller.
    pub game: Option<GameInfo>,
    /// The sonar ring.
    pub sonars: Option<Vec<Sonar>>,
}

/// What a robot's drivers did in one cycle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Actuation {
    /// The last duty cycles set, if any (the motors keep the previous ones otherwise).
    pub duty: Option<Vec<f64>>,
    /// Whether the kicker fired.
    pub kick: bool,
    /// The pan joint's last set-point, if any (the joint stays where it is otherwise).
    pub pan: Option<f64>,
    /// Faults booked, in order.
    pub faults: Vec<String>,
}

impl LinkedDevices {
    /// The readings of the next cycle (each is read once; a device without a reading this
    /// cycle gives its driver an error).
    pub fn load(&mut self, readings: Loaded) {
        self.odometry = readings.odometry;
        self.camera = readings.camera;
        self.game = readings.game;
        self.sonars = readings.sonars;
    }

    /// What the drivers did since the last call.
    pub fn take(&mut self) -> Actuation {
        Actuation {
            duty: self.duty.take(),
            kick: std::mem::take(&mut self.kick),
            pan: self.pan.take(),
            faults: std::mem::take(&mut self.faults),
        }
    }
}

fn unread<T>(slot: &mut Option<T>, what: &'static str) -> Result<T, DeviceError> {
    slot.take().ok_or(DeviceError::NotRead(what))
}

impl Devices for LinkedDevices {
    fn odometry(&mut self) -> Result<Odometry, DeviceError> {
        unread(&mut self.odometry, "odometry")
    }

    fn camera(&mut self) -> Result<CameraFrame, DeviceError> {
        unread(&mut self.camera, "camera")
    }

    fn game(&mut self) -> Result<GameInfo, DeviceError> {
        unread(&mut self.game, "game controller")
    }

    fn sonars(&mut self) -> Result<Vec<Sonar>, DeviceError> {
        unread(&mut self.sonars, "sonar")
    }

    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DeviceError> {
        self.duty = Some(duty.to_vec());
        Ok(())
    }

    fn kick(&mut self) -> Result<(), DeviceError> {
        self.kick = true;
        Ok(())
    }

    fn set_pan(&mut self, pan: f64) -> Result<(), DeviceError> {
        self.pan = Some(pan);
        Ok(())
    }

    fn fault(&mut self, message: &str) -> Result<(), DeviceError> {
        self.faults.push(message.to_string());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linked_devices_give_each_reading_once_and_gather_what_the_drivers_did() {
        let mut d = LinkedDevices::default();
        assert!(d.camera().is_err(), "nothing loaded yet");
        let frame = CameraFrame { time: 1.5, ..CameraFrame::default() };
        d.load(Loaded {
            odometry: Some(Odometry::default()),
            camera: Some(frame.clone()),
            game: Some(GameInfo::default()),
            sonars: None,
        });
        assert_eq!(d.game().unwrap(), GameInfo::default());
        assert_eq!(d.camera().unwrap(), frame);
        assert_eq!(d.camera(), Err(DeviceError::NotRead("camera")), "read once");
        assert_eq!(d.sonars(), Err(DeviceError::NotRead("sonar")), "none loaded");
        assert_eq!(d.sonars().unwrap_err().to_string(), "no sonar reading this cycle");
        d.set_duty(&[0.1, -0.2]).unwrap();
        d.set_duty(&[0.3, 0.4]).unwrap();
        d.kick().unwrap();
        d.set_pan(0.4).unwrap();
        d.fault("go2ball.lua:3: boom").unwrap();
        let act = d.take();
        assert_eq!(act.duty, Some(vec![0.3, 0.4]), "the last set-point counts");
        assert!(act.kick);
        assert_eq!(act.pan, Some(0.4));
        assert_eq!(act.faults, ["go2ball.lua:3: boom"]);
        assert_eq!(d.take(), Actuation::default(), "taken once");
    }
}
