//! The vision under real light: frames of the Middle Size field drawn by MuJoCo (an
//! independent renderer, `worlds/mujoco/`) through the shipped front camera
//! (`configs/vision/camera.toml`) under four lights — a bright stadium, the same at half the
//! brightness, a warm white, a low side light with hard shadows — and read with the one
//! shipped colour file (`configs/vision/colors.toml`). Each frame's truth (the ball's floor
//! point, or no ball) is in its directory's `truth.jsonl`, written by
//! `worlds/mujoco/render_frames.py dataset`.
//!
//! What must hold on every frame: a ball in view is found, within 5 % of its floor distance and
//! 1.5° of its bearing; a frame without a ball shows none.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_perception::camera::CameraModel;
use mrt_perception::source::load_image;
use mrt_perception::vision::agent::VisionAgent;
use mrt_perception::vision::colors::ColorTable;
use std::path::{Path, PathBuf};

/// The FIFA size 5 ball of the field (m).
const BALL_RADIUS: f64 = 0.11;

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// One frame's truth, as `render_frames.py` writes it.
struct Truth {
    file: String,
    /// Floor distance (m) and bearing (rad) of the ball from the point under the camera.
    ball: Option<(f64, f64)>,
}

fn truths(dir: &Path) -> Vec<Truth> {
    let text = std::fs::read_to_string(dir.join("truth.jsonl")).unwrap();
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let ball = (!v["ball"].is_null())
                .then(|| (v["distance"].as_f64().unwrap(), v["bearing"].as_f64().unwrap()));
            Truth { file: v["file"].as_str().unwrap().to_string(), ball }
        })
        .collect()
}

fn agent() -> VisionAgent {
    let CameraModel::Pinhole(camera) =
        CameraModel::from_file(repo("configs/vision/camera.toml")).unwrap()
    else {
        panic!("the shipped camera is a pinhole camera");
    };
    let colors = ColorTable::from_file(repo("configs/vision/colors.toml")).unwrap();
    VisionAgent::new(camera, &colors, BALL_RADIUS)
}

/// The worst errors over one light's frames.
#[derive(Debug, Default)]
struct Errors {
    balls: usize,
    empty: usize,
    worst_range: f64,
    worst_bearing_deg: f64,
    failures: Vec<String>,
}

fn measure(light: &str) -> Errors {
    let dir = repo("crates/mrt-perception/tests/frames/mujoco").join(light);
    let mut agent = agent();
    let mut e = Errors::default();
    for t in truths(&dir) {
        let image = load_image(&dir.join(&t.file)).unwrap();
        let pan = agent.camera().pan;
        let seen = agent.look(&image, 0.0, pan).unwrap().ball;
        match (t.ball, seen) {
            (None, None) => e.empty += 1,
            (None, Some(b)) => e.failures.push(format!("{}: a ball where none is: {b:?}", t.file)),
            (Some((d, _)), None) => {
                e.failures.push(format!("{}: the ball at {d:.2} m missed", t.file))
            }
            (Some((d, bearing)), Some(b)) => {
                e.balls += 1;
                let range = (b.distance - d).abs() / d;
                let off = mrt_core::angle_diff(b.bearing, bearing).abs().to_degrees();
                e.worst_range = e.worst_range.max(range);
                e.worst_bearing_deg = e.worst_bearing_deg.max(off);
                if range > 0.05 || off > 1.5 {
                    e.failures.push(format!(
                        "{}: the ball at {d:.2} m seen at {:.2} m ({:+.1} %), {off:.2}° off",
                        t.file,
                        b.distance,
                        100.0 * (b.distance - d) / d
                    ));
                }
            }
        }
    }
    e
}

fn check(light: &str) {
    let e = measure(light);
    assert!(e.balls >= 10 && e.empty >= 2, "{light}: too few frames: {e:?}");
    assert!(e.failures.is_empty(), "{light}: {:#?}", e.failures);
}

#[test]
fn the_ball_is_found_at_its_range_and_bearing_under_a_bright_stadium_light() {
    check("bright");
}

#[test]
fn the_ball_is_found_at_its_range_and_bearing_under_half_the_light() {
    check("half");
}

#[test]
fn the_ball_is_found_at_its_range_and_bearing_under_a_warm_white_light() {
    check("warm");
}

#[test]
fn the_ball_is_found_at_its_range_and_bearing_under_a_low_side_light_with_hard_shadows() {
    check("side");
}
