//! The robot program never reads the simulator's truth: what it knows,
//! it knows from its devices. Two ways it could cheat, each tested:
//!
//! - by code: a robot-side crate that depends on the simulator could read its world. None
//!   does (their manifests are read here);
//! - by data: a simulated device that reports what no real device measures. A camera frame
//!   carries what a camera measures and nothing else (no ball velocity: the world model tracks
//!   the ball, MAP's Kalman filter), with the object sensor and with vision: every camera frame
//!   on the robots' buses during a match is checked, and the robots still know how the ball
//!   rolls.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType};
use mrt_msgs::{CameraFrame, Percepts, WorldSnapshot};
use mrt_robot::spec::Stack;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::{PerceptSource, SimConfig};
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::{Arc, Mutex};

/// The crates a robot runs (the simulator's only bridge to them is the bus).
const ROBOT_SIDE: [&str; 9] = [
    "mrt-core",
    "mrt-dcdt",
    "mrt-msgs",
    "mrt-perception",
    "mrt-world",
    "mrt-fuzzy",
    "mrt-script",
    "mrt-plan",
    "mrt-robot",
];

#[test]
fn no_robot_side_crate_depends_on_the_simulator() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    for name in ROBOT_SIDE {
        let manifest = crates.join(name).join("Cargo.toml");
        let text = std::fs::read_to_string(&manifest)
            .unwrap_or_else(|e| panic!("{}: {e}", manifest.display()));
        let table: toml::Table = text.parse().unwrap();
        for section in ["dependencies", "build-dependencies"] {
            let deps = table.get(section).and_then(|d| d.as_table());
            let named = deps.is_some_and(|d| d.keys().any(|k| k == "mrt-sim" || k == "mrt-cli"));
            assert!(!named, "{name} names the simulator in [{section}]");
        }
    }
}

/// What a camera measures: the keys a camera frame may carry.
const MEASURED: [&str; 6] = ["time", "sightings", "robots", "image", "pan", "up_image"];

/// What the robots' devices put on the bus, and what their world models concluded.
#[derive(Default)]
struct Heard {
    frames: usize,
    /// The keys of the camera frames that are not in [`MEASURED`].
    unmeasured: BTreeSet<String>,
    percepts: usize,
    snapshots: usize,
    /// Snapshots whose ball moves (the world model's ball tracker).
    snapshots_with_velocity: usize,
}

/// A monitor on a team's link: every camera frame, percept and world snapshot of the team.
struct Listener(Arc<Mutex<Heard>>);

impl Member for Listener {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<CameraFrame>(RequestType::Remote);
        ctx.subscribe_to::<Percepts>(RequestType::Remote);
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Remote);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut heard = self.0.lock().unwrap();
        while let Some(m) = ctx.receive_msg() {
            if let Ok(f) = m.get::<CameraFrame>() {
                heard.frames += 1;
                let json = serde_json::to_value(f).unwrap();
                let keys = json.as_object().unwrap().keys();
                heard.unmeasured.extend(keys.filter(|k| !MEASURED.contains(&k.as_str())).cloned());
            } else if m.is::<Percepts>() {
                heard.percepts += 1;
            } else if let Ok(w) = m.get::<WorldSnapshot>() {
                heard.snapshots += 1;
                heard.snapshots_with_velocity += usize::from(w.ball_vel.inner.norm() > 0.0);
            }
        }
        Ok(())
    }
}

fn listen(source: PerceptSource) -> Heard {
    let mut cfg = SimConfig::oracle();
    cfg.sensor.percepts = source;
    cfg.rules.half_duration = 5.0;
    cfg.rules.team_size = 2;
    let mut m = BusMatch::new(&cfg, 4, Stack::Milan, Some(Stack::Chaos), None).unwrap();
    let heard = Arc::new(Mutex::new(Heard::default()));
    for (team, id) in [(0, 90), (1, 91)] {
        let link = m.team_link(team).cloned().unwrap();
        let mut agora = m.executor().agora_builder(id).inner_link(&link).build().unwrap();
        let listener = agora.add_member(Listener(heard.clone()), Activation::OnMessage);
        agora.activate_member(listener).unwrap();
        m.executor().add_agora(agora).unwrap();
    }
    while !m.pitch().unwrap().finished() {
        m.cycle().unwrap();
    }
    let heard = std::mem::take(&mut *heard.lock().unwrap());
    heard
}

#[test]
fn the_object_sensor_reports_only_what_a_camera_measures() {
    let h = listen(PerceptSource::Oracle);
    assert!(h.frames > 100 && h.snapshots > 100, "{} frames {} snapshots", h.frames, h.snapshots);
    assert!(h.unmeasured.is_empty(), "camera frames carry {:?}", h.unmeasured);
    assert!(
        h.snapshots_with_velocity > 0,
        "the ball tracker gave no velocity: {} snapshots",
        h.snapshots
    );
}

#[test]
fn the_camera_images_carry_only_what_a_camera_measures() {
    let h = listen(PerceptSource::Vision);
    assert!(h.frames > 100 && h.percepts > 100, "{} frames {} percepts", h.frames, h.percepts);
    assert!(h.unmeasured.is_empty(), "camera frames carry {:?}", h.unmeasured);
    assert!(
        h.snapshots_with_velocity > 0,
        "the ball tracker gave no velocity: {} snapshots",
        h.snapshots
    );
}
