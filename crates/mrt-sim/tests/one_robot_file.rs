//! A simulator file and a robot file describe a robot with one schema: the simulator's
//! `[field]`, `[ball]`, `[body]`, `[sensors]`, `[guidance]`, `[vision]`, `[gaze]` and
//! `[localization]` are the robot file's own sections, so a robot file's values pasted into a
//! simulator file are read as they are, and every robot of the match gets them unchanged.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_robot::config::RobotFile;
use mrt_sim::config::SimConfig;
use std::path::Path;

fn shipped_robot_file() -> (String, RobotFile) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/robot/robot.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let file = RobotFile::from_toml(&text, "robot.toml").unwrap();
    (text, file)
}

/// The robot file's sections without the ones that say which robot this is and where its
/// devices are (`[robot]`, `[devices]`): what a world describes for all its robots.
fn robot_sections(text: &str) -> String {
    let mut table: toml::Table = toml::from_str(text).unwrap();
    table.remove("robot");
    table.remove("devices");
    toml::to_string(&table).unwrap()
}

#[test]
fn a_robot_files_sections_are_a_simulator_files_and_reach_every_robot_unchanged() {
    let (text, file) = shipped_robot_file();
    let sim = SimConfig::from_toml(&robot_sections(&text), "sim.toml").unwrap();
    for id in [0, 5] {
        let built = sim.robot_file(id, "chaos");
        assert_eq!(built.body, file.body);
        assert_eq!(built.sensors, file.sensors);
        assert_eq!(built.ball, file.ball);
        assert_eq!(built.field, file.field);
        assert_eq!(built.guidance, file.guidance);
        assert_eq!(built.localization, file.localization);
        assert_eq!(built.vision.camera, file.vision.camera);
        assert_eq!(built.robot.id, id);
    }
}

#[test]
fn a_value_changed_in_a_simulator_file_reaches_the_robots_and_the_world_alike() {
    let text = "[body]\nradius = 0.3\nmax_speed = 0.9\nmass = 25.0\n\
                [sensors]\nmice_distance = 0.15\ncamera_bearing_noise = 0.01\n\
                [ball]\nradius = 0.12\nrolling_damping = 0.6\n\
                [field]\nlength = 16.0\n[vision]\npost_radius = 0.12\n";
    let sim = SimConfig::from_toml(text, "sim.toml").unwrap();
    let robot = sim.robot().unwrap();
    // The robot program's view ...
    assert_eq!((robot.radius, robot.ball_radius, robot.ball_damping), (0.3, 0.12, 0.6));
    assert_eq!((robot.field.length, robot.camera.bearing), (16.0, 0.01));
    assert_eq!(robot.mice, mrt_perception::mice::MiceOdometry::new(0.15, 0.003).unwrap());
    // ... is the one definition the world simulates.
    assert_eq!((sim.body.radius, sim.body.mass, sim.ball.radius), (0.3, 25.0, 0.12));
    assert_eq!(sim.field.length, 16.0);
    let file = sim.robot_file(1, "milan");
    assert_eq!(file.vision.post_radius, 0.12);
    assert_eq!(file.body.max_speed, 0.9);
    // And the robot file the simulator writes for a distributed robot reads back the same.
    let again = RobotFile::from_toml(&file.to_toml().unwrap(), "robot.toml").unwrap();
    assert_eq!(again, file);
}

#[test]
fn the_robots_vision_is_the_worlds_choice_not_a_key_of_the_simulator_file() {
    let e = SimConfig::from_toml("[vision]\nenabled = true\n", "sim.toml").unwrap_err();
    assert!(e.to_string().contains("sensor.percepts"), "{e}");
    let vision = SimConfig::default();
    assert!(vision.robot_file(0, "chaos").vision.enabled, "the default world renders images");
    assert!(!SimConfig::oracle().robot_file(0, "chaos").vision.enabled);
}
