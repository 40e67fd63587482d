//! Perceptual needs steer the camera (ThinkingCap/TeamChaos report §2.1): a robot on
//! the simulated pitch whose behaviors need the ball and a landmark alike, with a narrow
//! camera on a pan joint, looks at them in turn as their anchors decay; with no joint it
//! never turns its camera.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use mrt_core::Pose2;
use mrt_msgs::robot::lps;
use mrt_msgs::{RobotCommand, WorldSnapshot};
use mrt_robot::brain::Brain;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::SimConfig;

/// A robot that stands still and states the same needs every cycle.
struct Needs(Vec<(usize, f64)>);
impl Brain for Needs {
    fn cycle(&mut self, _: &WorldSnapshot) -> RobotCommand {
        RobotCommand { needs: self.0.clone(), ..RobotCommand::default() }
    }
}

/// The south-east corner post: the second landmark of the field map (team frame of the home
/// team in the first half, which attacks east).
use mrt_msgs::sighting::SE_CORNER;

fn config(gaze: bool) -> SimConfig {
    let mut cfg = SimConfig::oracle();
    cfg.rules.team_size = 1;
    cfg.rules.ready_duration = 100.0; // nobody moves the robot for the whole test
    cfg.sensor.half_fov = 0.35; // a narrow camera: 40° wide
    cfg.sensor.miss_probability = 0.0;
    cfg.gaze.enabled = gaze;
    cfg
}

/// The pan of every cycle for `seconds`, the robot on the centre spot facing east, the ball
/// 2 m away at 60° to its left; the south-east corner is at −33.7°.
fn pans(cfg: &SimConfig, seconds: f64) -> Vec<f64> {
    let needs = vec![(lps::BALL, 1.0), (SE_CORNER, 1.0)];
    let mut m = BusMatch::with_brains(cfg, 1, vec![Box::new(Needs(needs))], vec![]).unwrap();
    {
        let mut p = m.pitch().unwrap();
        p.world_mut().place_robot(0, Pose2::new(0.0, 0.0, 0.0));
        let (s, c) = 60f64.to_radians().sin_cos();
        p.world_mut().place_ball(2.0 * c, 2.0 * s);
    }
    let cycles = (seconds / cfg.rules.control_period).round() as usize;
    (0..cycles)
        .map(|_| {
            m.cycle().unwrap();
            m.pitch().unwrap().pan(0).unwrap()
        })
        .collect()
}

#[test]
fn a_robot_that_needs_the_ball_and_a_landmark_looks_at_them_in_turn() {
    let pans = pans(&config(true), 30.0);
    let (ball, corner) = (60f64.to_radians(), (-6f64).atan2(9.0));
    // Which object the camera has in view each cycle (0.35 rad either side of the pan).
    let looking: Vec<Option<usize>> = pans
        .iter()
        .map(|&p| {
            if (p - ball).abs() <= 0.35 {
                Some(lps::BALL)
            } else if (p - corner).abs() <= 0.35 {
                Some(SE_CORNER)
            } else {
                None
            }
        })
        .collect();
    let mut seen: Vec<usize> = looking.iter().flatten().copied().collect();
    seen.dedup();
    assert!(seen.len() >= 20, "30 s of looking from one to the other: {seen:?}");
    // Neither is left out of view for long once both were found: at most 2 s between looks (the
    // joint turns 1.6 rad at 3 rad/s, holds each 0.3 s: a look every 1.7 s).
    for object in [lps::BALL, SE_CORNER] {
        let at: Vec<usize> = (0..looking.len()).filter(|&k| looking[k] == Some(object)).collect();
        let longest = at.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(usize::MAX);
        assert!(longest <= 20, "object {object} out of view {longest} cycles; pans {pans:?}");
    }
}

#[test]
fn a_camera_without_gaze_looks_straight_ahead() {
    assert!(pans(&config(false), 3.0).iter().all(|&p| p == 0.0));
}
