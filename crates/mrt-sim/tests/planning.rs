//! SPIKE on the robot: a behavior asks for a target "along a planned path";
//! guidance asks the robot's planner Member, which plans round the robots the world model
//! anchored, and follows the path in position mode. Two robots stand shoulder to shoulder on
//! the straight line: position mode alone would run into them.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use mrt_core::frames::{Framed, Team};
use mrt_core::Pose2;
use mrt_msgs::{RobotCommand, Target, WorldSnapshot};
use mrt_robot::brain::Brain;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::SimConfig;

/// Asks to be at `to`, straight (position mode) or along a planned path.
struct GoTo {
    to: Framed<Team, Pose2>,
    plan: bool,
}
impl Brain for GoTo {
    fn cycle(&mut self, _: &WorldSnapshot) -> RobotCommand {
        let target = Target { pose: self.to, avoid: false, plan: self.plan };
        RobotCommand { target: Some(target), ..RobotCommand::default() }
    }
}

/// Stands still.
struct Stand;
impl Brain for Stand {
    fn cycle(&mut self, _: &WorldSnapshot) -> RobotCommand {
        RobotCommand::default()
    }
}

/// Where the walker ends after `seconds`, and how near it came to the standing robots'
/// centres (m).
fn walk(plan: bool, seconds: f64) -> ((f64, f64), f64) {
    let mut cfg = SimConfig::oracle();
    cfg.rules.team_size = 2;
    cfg.rules.ready_duration = 100.0; // READY all along: robots may move, nobody is placed
    cfg.sensor.miss_probability = 0.0;
    // The walker and a teammate standing out of the way; the other team stands in the way.
    let walker: Vec<Box<dyn Brain + Send>> =
        vec![Box::new(GoTo { to: Framed::new(Pose2::new(4.0, 0.0, 0.0)), plan }), Box::new(Stand)];
    let wall: Vec<Box<dyn Brain + Send>> = vec![Box::new(Stand), Box::new(Stand)];
    let mut m = BusMatch::with_brains(&cfg, 1, walker, wall).unwrap();
    {
        let mut p = m.pitch().unwrap();
        p.world_mut().place_robot(0, Pose2::new(-4.0, 0.0, 0.0));
        p.world_mut().place_robot(1, Pose2::new(-8.0, 5.0, 0.0));
        p.world_mut().place_robot(2, Pose2::new(0.0, -0.3, std::f64::consts::PI));
        p.world_mut().place_robot(3, Pose2::new(0.0, 0.3, std::f64::consts::PI));
        p.world_mut().place_ball(0.0, 5.0);
    }
    let mut nearest = f64::INFINITY;
    for _ in 0..(seconds / cfg.rules.control_period).round() as usize {
        m.cycle().unwrap();
        let p = m.pitch().unwrap();
        let me = p.world().robot(0).unwrap();
        for k in [2, 3] {
            let o = p.world().robot(k).unwrap();
            nearest = nearest.min((me.x - o.x).hypot(me.y - o.y));
        }
    }
    let p = m.pitch().unwrap();
    let me = p.world().robot(0).unwrap();
    ((me.x, me.y), nearest)
}

#[test]
fn a_planned_target_is_reached_round_the_robots_in_the_way() {
    let ((x, y), nearest) = walk(true, 25.0);
    assert!((x - 4.0).hypot(y) < 0.3, "ended at ({x:.2}, {y:.2})");
    // Centres more than the two radii apart: it never touched them. (The plan keeps 0.1 m
    // more; driving to a point half a metre ahead cuts its corners by a few centimetres:
    // 0.535 m measured.)
    assert!(nearest > 0.52, "came within {nearest:.2} m");
    // Straight, in position mode, it runs into them.
    let (_, straight) = walk(false, 10.0);
    assert!(straight < 0.52, "straight came within {straight:.2} m");
}
