//! The device protocol's messages as a robot reads them (docs/devices.md): a `sense` or an
//! `end` from a world, through the robot's gate.

use super::{Harness, Seed, Target};
use crate::FuzzError;
use mrt_devices::{Admitted, Gate};
use std::path::Path;
use std::time::Instant;

/// What a world sends a robot.
pub(super) const DEVICES: Target = Target {
    name: "devices",
    about: "device protocol messages (sense, end) through the robot's Gate after a good step 0: every step it takes has finite readings and consistent images",
    keywords: &["\"protocol\"", "\"world\"", "\"run\"", "\"robot\"", "\"step\"", "\"time\"", "\"odometry\"", "\"mice\"", "\"wheels\"", "\"placed\"", "\"camera\"", "\"image\"", "\"encoding\"", "\"rgb8\"", "\"jpeg\"", "\"data\"", "\"sonars\"", "\"game\"", "\"playing\"", "null", "1e999", "-1", "18446744073709551615"],
    structured: Some(crate::mutate::mutate_json),
    seeds: device_seeds,
    harness: |_| Ok(Box::new(Devices)),
};

/// A good step 0 of world `w`, robot `home-1`, run `r`, with a 2 × 2 image.
const STEP0: &str = r#"{"protocol":1,"world":"w","run":"r","robot":"home-1","step":0,"time":0.0,"odometry":{"mice":{"x_left":0.0,"y_left":0.01,"x_right":0.0,"y_right":0.01},"wheels":[0.2,0.2],"placed":{"x":-1.0,"y":0.0,"theta":0.0}},"camera":{"time":0.0,"pan":0.1,"image":{"width":2,"height":2,"encoding":"rgb8","data":"AAAAAAAAAAAAAAAA"}},"sonars":[{"bearing":0.0,"range":1.0},{"bearing":1.0,"range":null}],"game":{"state":"playing","attack":1,"kickoff_pose":null,"marker":"cyan"}}"#;

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
                    assert!(f.image.as_ref().is_some_and(|i| i.is_consistent()));
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
