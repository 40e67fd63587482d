//! The device protocol's messages (docs/devices.md) as a robot reads them (a `sense` or an
//! `end` from a world, through the robot's gate) and as a world written in Rust reads them (an
//! `act` or a `bye`, through `mrt_devices::world::Answers`).

use super::{Harness, Seed, Target};
use crate::FuzzError;
use mrt_devices::world::{Answer, Answers};
use mrt_devices::{Admitted, Gate};
use std::path::Path;
use std::time::Instant;

/// What a world sends a robot.
pub(super) const DEVICES: Target = Target {
    name: "devices",
    about: "device protocol messages (sense, end) through the robot's Gate after a good step 0: every step it takes has finite readings and consistent images",
    keywords: &["\"protocol\"", "\"world\"", "\"run\"", "\"robot\"", "\"step\"", "\"time\"", "\"odometry\"", "\"mice\"", "\"wheels\"", "\"placed\"", "\"camera\"", "\"image\"", "\"encoding\"", "\"rgb8\"", "\"jpeg\"", "\"data\"", "\"objects\"", "\"ball\"", "\"east_net\"", "\"landmarks\"", "\"robots\"", "\"distance\"", "\"bearing\"", "\"sigma\"", "\"sonars\"", "\"game\"", "\"playing\"", "null", "1e999", "-1", "18446744073709551615"],
    structured: Some(crate::mutate::mutate_json),
    seeds: device_seeds,
    harness: |_| Ok(Box::new(Devices)),
};

/// A good step 0 of world `w`, robot `home-1`, run `r`, with a 2 × 2 image.
const STEP0: &str = r#"{"protocol":1,"world":"w","run":"r","robot":"home-1","step":0,"time":0.0,"odometry":{"mice":{"x_left":0.0,"y_left":0.01,"x_right":0.0,"y_right":0.01},"wheels":[0.2,0.2],"placed":{"x":-1.0,"y":0.0,"theta":0.0}},"camera":{"time":0.0,"pan":0.1,"image":{"width":2,"height":2,"encoding":"rgb8","data":"AAAAAAAAAAAAAAAA"}},"sonars":[{"bearing":0.0,"range":1.0},{"bearing":1.0,"range":null}],"game":{"state":"playing","attack":1,"kickoff_pose":null,"marker":"cyan"}}"#;

/// A step 1 whose camera frame is an object sensor's.
const OBJECTS: &str = r#"{"protocol":1,"world":"w","run":"r","robot":"home-1","step":1,"time":0.1,"camera":{"time":0.1,"pan":null,"image":null,"objects":{"ball":{"distance":2.0,"bearing":0.1},"east_net":null,"west_net":{"distance":9.0,"bearing":3.0},"landmarks":[null,{"distance":4.0,"bearing":-1.0}],"robots":[{"distance":1.5,"bearing":0.2,"sigma":[0.1,0.01],"marker":"magenta"}]}},"game":{"state":"playing","attack":-1}}"#;

/// The JSON examples of docs/devices.md (renamed to the harness's world and run), and steps
/// and ends of the harness's robot.
fn device_seeds(root: &Path) -> Result<Vec<Seed>, FuzzError> {
    let doc = root.join("docs/devices.md");
    let text =
        std::fs::read_to_string(&doc).map_err(|source| FuzzError::Io { path: doc, source })?;
    let mut seeds = Vec::new();
    for block in text.split("```json").skip(1) {
        let json = block.split("```").next().unwrap_or("");
        let json = json.replace("\"mujoco\"", "\"w\"").replace("\"7f3a09c2\"", "\"r\"");
        seeds.push(Seed::new("doc", json));
    }
    seeds.push(Seed::new(
        "step",
        STEP0.replace("\"step\":0,\"time\":0.0", "\"step\":1,\"time\":0.1"),
    ));
    seeds.push(Seed::new("step", STEP0));
    seeds.push(Seed::new("end", r#"{"protocol":1,"world":"w","run":"r","steps":1}"#));
    seeds.push(Seed::new("step", OBJECTS));
    Ok(seeds)
}

struct Devices;

impl Harness for Devices {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let mut gate = Gate::new("w", "home-1", 2);
        let now = Instant::now();
        if let Ok(Admitted::Step(r)) = gate.admit(STEP0.as_bytes(), now) {
            gate.answered(r.step, r.time, b"{}".to_vec());
        }
        let took = match gate.admit(input, now) {
            Ok(Admitted::Step(r)) => {
                // Documented: the readings of a step taken are numbers the robot can use.
                assert!(r.time.is_finite() && r.time >= 0.0);
                assert!(r.wheel_turns.iter().flatten().all(|x| x.is_finite()));
                assert!(
                    r.mice.is_finite() || [r.mice.x_left, r.mice.y_left].iter().all(|x| x.is_nan())
                );
                if let Some(f) = &r.camera {
                    // An image, consistent, or an object sensor's finite sightings.
                    assert!(f.image.as_ref().is_none_or(|i| i.is_consistent()));
                    let seen =
                        f.sightings.iter().flatten().chain(f.robots.iter().map(|r| &r.sighting));
                    for s in seen {
                        assert!(
                            s.distance.is_finite() && s.distance >= 0.0 && s.bearing.is_finite()
                        );
                    }
                }
                assert!(r.sonars.iter().flatten().all(|s| s.bearing.is_finite() && s.range >= 0.0));
                true
            }
            Ok(Admitted::Repeat(_)) => true,
            Err(_) => false,
        };
        took | gate.admit_end(input).is_ok()
    }
}

/// What a world's robots send it.
pub(super) const ANSWERS: Target = Target {
    name: "device-answers",
    about: "device protocol messages (act, bye) through a Rust world's Answers: every act it takes answers the step asked with finite numbers and a wheel per wheel",
    keywords: &["\"protocol\"", "\"world\"", "\"run\"", "\"robot\"", "\"step\"", "\"wheels\"", "\"twist\"", "\"vx\"", "\"omega\"", "\"kick\"", "\"pan\"", "\"faults\"", "\"steps\"", "\"dropped\"", "\"never_ran\"", "null", "true", "1e999", "-1", "18446744073709551615"],
    structured: Some(crate::mutate::mutate_json),
    seeds: answer_seeds,
    harness: |_| Ok(Box::new(WorldSide)),
};

/// An act of robot `home-1` of world `w`, run `r`, answering step 3.
const ACT: &str = r#"{"protocol":1,"world":"w","run":"r","robot":"home-1","step":3,"wheels":[18.2,19.9],"twist":{"vx":0.95,"vy":0.0,"omega":0.22},"kick":false,"pan":0.31,"faults":["behavior-1: go2ball.lua:3: boom"]}"#;

/// The act and the bye of docs/devices.md (renamed to the harness's world and run), and an act
/// of the harness's robot.
fn answer_seeds(root: &Path) -> Result<Vec<Seed>, FuzzError> {
    let mut seeds: Vec<Seed> =
        device_seeds(root)?.into_iter().filter(|s| s.slot == "doc").collect();
    seeds.push(Seed::new("act", ACT));
    Ok(seeds)
}

struct WorldSide;

impl Harness for WorldSide {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        let robots = ["home-1".to_string()];
        let Ok(mut answers) = Answers::new("w", "r", &robots, 2) else { return false };
        let act = "mrt/devices/1/w/home-1/act";
        let bye = "mrt/devices/1/w/home-1/bye";
        let mut took = false;
        for key in [act, bye] {
            match answers.take(key, input, Some(3)) {
                Some(Answer::Act(i, a)) => {
                    // Documented: an act taken answers the step asked, from the key's robot,
                    // with numbers a world can apply.
                    assert_eq!((i, a.step, a.robot.as_str()), (0, 3, "home-1"));
                    assert!(a
                        .wheels
                        .iter()
                        .all(|w| w.len() == 2 && w.iter().all(|x| x.is_finite())));
                    assert!(a
                        .twist
                        .iter()
                        .all(|t| [t.vx, t.vy, t.omega].iter().all(|x| x.is_finite())));
                    assert!(a.pan.is_none_or(f64::is_finite));
                    took = true;
                }
                Some(Answer::Bye(i, b)) => {
                    assert_eq!((i, b.run.as_str()), (0, "r"));
                    took = true;
                }
                None => {}
            }
        }
        took
    }
}
