//! # 05 — The robot program on its own devices (no simulator)
//!
//! What you learn: how a team runs MRT's robot program on its own hardware. The robot program
//! (`mrt-robot`: drivers, world model, behaviors, guidance, motor driver) talks to its
//! hardware through one trait, `Devices`; the simulator is one implementation, a real robot
//! is another. Here a toy robot on a table implements it in forty lines: its "camera" reports
//! the ball and the field's landmarks from where the robot is, its "mice" read its motion,
//! its "motors" move it by the base's kinematics. The baseline player (`Chaser`) then walks
//! to the ball and kicks, with no simulator linked (`cargo tree -p mrt-robot` has no physics
//! engine).
//!
//! Run: `cargo run -p mrt-examples --example 05_robot_on_its_own_devices`.

#![allow(clippy::print_stdout)] // examples talk to the user

use anyhow::{anyhow, Result};
use mrt_core::frames::{Field, Framed};
use mrt_core::{Point2, Pose2, SimClock};
use mrt_dcdt::SteppedExecutor;
use mrt_msgs::{
    CameraFrame, Displacement, GameInfo, GameState, Odometry, Sighting, Sonar, FIELD_OBJECTS,
};
use mrt_plan::kinematics::integrate;
use mrt_robot::config::{RobotConfig, RobotFile};
use mrt_robot::devices::{DeviceError, Devices};
use mrt_robot::members::add_robot;
use mrt_robot::spec::RobotSpec;
use mrt_robot::spec::Stack;
use std::sync::{Arc, Mutex};

/// The toy robot's hardware: where it truly is, where the ball is, what its motors were told.
pub struct TableRobot {
    cfg: RobotConfig,
    /// The robot's true pose (field frame, m): only the "hardware" knows it.
    pose: Pose2,
    ball: (f64, f64),
    duty: Vec<f64>,
    placed: bool,
    /// Cycles in which the kicker fired.
    pub kicks: Vec<usize>,
    cycle: usize,
}

impl Devices for TableRobot {
    fn odometry(&mut self) -> Result<Odometry, DeviceError> {
        // The motors move the robot for one period by the base's own kinematics; the mice
        // read that motion (the MRT manual's §4.1 forward model).
        let before = self.pose;
        let twist =
            self.cfg.base.twist_for(&self.duty).map_err(|e| DeviceError::Refused(e.to_string()))?;
        self.pose = integrate(self.pose, &twist, self.cfg.control_period);
        let d = self.pose.relative_to(&before);
        let placed = (!self.placed).then_some(Framed::new(before));
        self.placed = true;
        self.cycle += 1;
        Ok(Odometry {
            mice: self.cfg.mice.readings_for(d.x, d.y, d.theta),
            wheels: Displacement::new(d.x, d.y, d.theta),
            placed,
        })
    }

    fn camera(&mut self) -> Result<CameraFrame, DeviceError> {
        let mut frame = CameraFrame::default();
        for k in 0..FIELD_OBJECTS {
            let at = match self.cfg.field.object(k) {
                Some(p) => (p.x, p.y),
                None => self.ball, // object 0 is the ball
            };
            // Where it is for the robot (frames are types: a field point, a field pose).
            let me: Framed<Field, Pose2> = Framed::new(self.pose);
            let (distance, bearing) = me.range_bearing(Framed::new(Point2::new(at.0, at.1)));
            frame.sightings[k] = Some(Sighting { distance, bearing });
        }
        Ok(frame)
    }

    fn game(&mut self) -> Result<GameInfo, DeviceError> {
        Ok(GameInfo { state: GameState::Playing, attack: 1.0, kickoff_pose: None, marker: None })
    }

    fn sonars(&mut self) -> Result<Vec<Sonar>, DeviceError> {
        Ok((0..16).map(|i| Sonar::new(Sonar::ring_bearing(i, 16), f64::INFINITY)).collect())
    }

    fn set_duty(&mut self, duty: &[f64]) -> Result<(), DeviceError> {
        self.duty = duty.to_vec();
        Ok(())
    }

    fn kick(&mut self) -> Result<(), DeviceError> {
        self.kicks.push(self.cycle);
        // A kick that reaches the ball sends it 3 m on along the robot's heading.
        let (dx, dy) = (self.ball.0 - self.pose.x, self.ball.1 - self.pose.y);
        if dx.hypot(dy) < 0.5 {
            let (s, c) = self.pose.theta.sin_cos();
            self.ball = (self.ball.0 + 3.0 * c, self.ball.1 + 3.0 * s);
        }
        Ok(())
    }

    fn fault(&mut self, message: &str) -> Result<(), DeviceError> {
        Err(DeviceError::Refused(format!("the robot's software failed: {message}")))
    }
}

/// How the run went.
#[derive(Debug)]
pub struct Outcome {
    /// The robot's distance to the ball after each cycle, m.
    pub distances: Vec<f64>,
    /// Cycles in which the kicker fired.
    pub kicks: Vec<usize>,
}

/// Runs the baseline player for `cycles` control cycles on the toy robot, which starts 2 m
/// behind a ball that lies on the line to the opponent's net.
pub fn run(cycles: usize, verbose: bool) -> Result<Outcome> {
    // A robot file with the defaults: a Triskar base on the Middle Size League field; robot 1
    // of its team (a field player), driven by the baseline.
    let mut file = RobotFile::default();
    file.robot.id = 1;
    file.robot.stack = "chaser".into();
    let cfg = file.config().map_err(|e| anyhow!(e))?;
    let robot = TableRobot {
        cfg: cfg.clone(),
        pose: Pose2::new(-1.0, 0.0, 0.0),
        ball: (1.0, 0.0),
        duty: vec![0.0; cfg.base.wheels()],
        placed: false,
        kicks: Vec::new(),
        cycle: 0,
    };
    let devices = Arc::new(Mutex::new(robot));
    let mut exec = SteppedExecutor::new(SimClock::new(), cfg.period());
    let mut agora = exec.agora_builder(2).build()?;
    let spec = RobotSpec { robot: 1, keeper: false, mate: 1, stack: Stack::Chaser };
    add_robot(&mut agora, &cfg, &spec, std::path::Path::new(""), devices.clone())
        .map_err(|e| anyhow!(e))?;
    exec.add_agora(agora)?;
    let mut distances = Vec::new();
    for _ in 0..cycles {
        exec.run_for(cfg.period());
        let d = devices.lock().map_err(|_| anyhow!("poisoned"))?;
        let distance = (d.ball.0 - d.pose.x).hypot(d.ball.1 - d.pose.y);
        if verbose {
            println!("cycle {:2}: {distance:.3} m from the ball", d.cycle);
        }
        distances.push(distance);
    }
    for report in exec.finish() {
        if let Some(m) = report.members.iter().find(|m| m.last_error.is_some()) {
            return Err(anyhow!("member {} failed: {:?}", m.name, m.last_error));
        }
    }
    let kicks = devices.lock().map_err(|_| anyhow!("poisoned"))?.kicks.clone();
    if verbose {
        println!("kicked in cycles {kicks:?}");
    }
    Ok(Outcome { distances, kicks })
}

/// Runs the example.
pub fn main() -> Result<()> {
    run(30, true)?;
    Ok(())
}
