//! A robot whose devices are a world's (docs/devices.md): the robot program of [`RemoteRobot`]
//! run one cycle per `sense` its world sends, answering each with an `act`. Any world that
//! speaks the device protocol (MuJoCo, a Python stub, a real robot's bridge) drives it; the
//! transport is the caller's ([`WorldPort`] out, [`WorldMail`] in; `mrt robot` uses zenoh).
//!
//! What the world sends passes the protocol's [`Gate`] first: a message that cannot be used is
//! counted, logged and dropped, the robot runs no cycle for it and answers nothing, so the
//! world's safe command holds and nothing a world sends stops the program.

use crate::base::Base;
use crate::devices::Loaded;
use crate::error::RobotError;
use crate::remote::{Cycle, RemoteRobot, RobotRun};
use mrt_core::Time;
use mrt_devices::messages::Fault;
use mrt_devices::{Act, Admitted, Bye, Gate, Keys, Readings, Refusal, PROTOCOL};
use mrt_msgs::{Displacement, Odometry};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

/// Where a world robot's answers go (`put` on a zenoh key, in `mrt robot`).
pub trait WorldPort {
    /// Sends `bytes` on `key`.
    fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), RobotError>;
}

/// What reaches a world robot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WorldMail {
    /// Bytes put on the robot's `sense` key.
    Sense(Vec<u8>),
    /// Bytes put on the world's `end` key.
    End(Vec<u8>),
    /// The world's liveliness token, seen before, went away: its process or its link ended.
    Gone,
}

/// How a world robot's match went.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WorldRun {
    /// The robot's cycles and teammates' lateness.
    pub robot: RobotRun,
    /// The world's last word, sent back with the robot's.
    pub bye: Bye,
}

/// One robot on a world's devices (module doc).
pub struct WorldRobot {
    robot: RemoteRobot,
    base: Base,
    keys: Keys,
    gate: Gate,
    /// Refusals logged, by reason (the first of each, then every hundredth).
    logged: Vec<(&'static str, u64)>,
}

impl WorldRobot {
    /// Robot `robot` (its program, on a base of `base`) named by `keys` in its world.
    pub fn new(robot: RemoteRobot, base: Base, keys: Keys) -> WorldRobot {
        let gate = Gate::new(keys.world(), keys.robot(), base.wheels());
        WorldRobot { robot, base, keys, gate, logged: Vec::new() }
    }

    /// The robot program (to link its Agora to the team's network).
    pub fn robot_mut(&mut self) -> &mut RemoteRobot {
        &mut self.robot
    }

    /// The robot's keys.
    pub fn keys(&self) -> &Keys {
        &self.keys
    }

    /// Runs cycles as the world's steps come on `mail`, answering on `port`, until the world's
    /// `end` (then the Members close and the robot's `bye` is sent) or `silence` without any
    /// step.
    pub fn run(
        mut self,
        mail: &Receiver<WorldMail>,
        port: &dyn WorldPort,
        silence: Duration,
    ) -> Result<WorldRun, RobotError> {
        let mut run = RobotRun::default();
        let mut heard = Instant::now();
        loop {
            let left = silence.saturating_sub(heard.elapsed());
            let m = match mail.recv_timeout(left) {
                Ok(m) => m,
                Err(RecvTimeoutError::Timeout) => {
                    let world = self.keys.world().to_string();
                    return Err(RobotError::WorldSilent { world, silence });
                }
                Err(RecvTimeoutError::Disconnected) => return Err(RobotError::LinkClosed),
            };
            match m {
                WorldMail::Sense(bytes) => match self.gate.admit(&bytes, Instant::now()) {
                    Ok(Admitted::Step(readings)) => {
                        heard = Instant::now();
                        run.first_frame.get_or_insert(heard);
                        let (step, time) = (readings.step, readings.time);
                        let act = self.step(*readings, &mut run)?;
                        let bytes = serde_json::to_vec(&act)?;
                        port.put(&self.keys.act(), bytes.clone())?;
                        self.gate.answered(step, time, bytes);
                        run.first_answer.get_or_insert_with(Instant::now);
                    }
                    Ok(Admitted::Repeat(answer)) => {
                        heard = Instant::now();
                        port.put(&self.keys.act(), answer)?;
                    }
                    Err(refusal) => self.log(&refusal),
                },
                WorldMail::End(bytes) => match self.gate.admit_end(&bytes) {
                    Ok(_) => return self.end(run, port),
                    Err(refusal) => self.log(&refusal),
                },
                WorldMail::Gone => {
                    return Err(RobotError::WorldGone(self.keys.world().to_string()))
                }
            }
        }
    }

    fn log(&mut self, refusal: &Refusal) {
        let reason = refusal.reason();
        let n = match self.logged.iter_mut().find(|(r, _)| *r == reason) {
            Some((_, n)) => {
                *n += 1;
                *n
            }
            None => {
                self.logged.push((reason, 1));
                1
            }
        };
        if n == 1 || n % 100 == 0 {
            tracing::warn!(
                robot = self.keys.robot(),
                "dropped a message from the world ({n} {reason} so far): {}",
                refusal.to_string().escape_debug()
            );
        }
    }

    /// One cycle on a step's readings, and the answer.
    fn step(&mut self, r: Readings, run: &mut RobotRun) -> Result<Act, RobotError> {
        let wheels = match &r.wheel_turns {
            Some(turns) => self.base.motion(turns)?,
            None => Displacement::default(),
        };
        let odometry = r.odometry.then_some(Odometry { mice: r.mice, wheels, placed: r.placed });
        let cycle = Cycle {
            at: Time::from_secs_f64(r.time),
            first: r.step == 0,
            readings: Loaded { odometry, camera: r.camera, game: Some(r.game), sonars: r.sonars },
        };
        let did = self.robot.cycle(cycle, run)?;
        let (wheels, twist) = match &did.duty {
            Some(duty) => {
                let speeds = self.base.wheel_speeds(duty)?;
                let t = self.base.twist_for(duty)?;
                (Some(speeds), Some(t))
            }
            None => (None, None),
        };
        Ok(Act {
            protocol: PROTOCOL,
            world: self.keys.world().into(),
            run: r.run,
            robot: self.keys.robot().into(),
            step: r.step,
            wheels,
            twist,
            kick: did.kick,
            pan: did.pan,
            faults: did.faults,
        })
    }

    fn end(self, robot: RobotRun, port: &dyn WorldPort) -> Result<WorldRun, RobotError> {
        let bye = Bye {
            protocol: PROTOCOL,
            world: self.keys.world().into(),
            run: self.gate.run().unwrap_or_default().into(),
            robot: self.keys.robot().into(),
            steps: robot.cycles,
            faults: self
                .robot
                .finish()?
                .into_iter()
                .map(|f| Fault {
                    name: f.name,
                    count: f.count,
                    never_ran: f.never_ran,
                    error: f.error,
                })
                .collect(),
            dropped: self.gate.dropped(),
        };
        let bytes = serde_json::to_vec(&bye)?;
        port.put(&self.keys.bye(), bytes)?;
        Ok(WorldRun { robot, bye })
    }
}
