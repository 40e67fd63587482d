//! The MuJoCo world (`worlds/mujoco/`) against the `mrt` binary: its own Python tests pass, and
//! `mrt vision detect` with the shipped camera and colour files finds the ball in frames
//! MuJoCo renders afresh under each of its four lights, from seeds no tuning saw, within 5 % of
//! its floor distance and 1.5° of its bearing, and no ball in frames without one.
//!
//! The interpreter is `$MRT_PYTHON` (`.ci/run` makes one with `worlds/mujoco/requirements.txt`),
//! else `python3`. Where it has no MuJoCo, or MuJoCo cannot render offscreen here (no EGL),
//! each test says plainly that it was skipped.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn python() -> String {
    std::env::var("MRT_PYTHON").unwrap_or_else(|_| "python3".into())
}

/// A Python command in the repository's root, headless through EGL unless told otherwise.
fn py(args: &[&str]) -> Command {
    let mut cmd = Command::new(python());
    cmd.args(args).current_dir(repo());
    if std::env::var_os("MUJOCO_GL").is_none() {
        cmd.env("MUJOCO_GL", "egl");
    }
    cmd
}

/// Why MuJoCo cannot render here, if it cannot.
fn unavailable() -> Option<String> {
    let probe = "import mujoco; m = mujoco.MjModel.from_xml_string(\
        '<mujoco><worldbody><geom size=\"1\"/></worldbody></mujoco>'); \
        r = mujoco.Renderer(m, 8, 8); r.update_scene(mujoco.MjData(m)); r.render()";
    match py(&["-c", probe]).output() {
        Ok(out) if out.status.success() => None,
        Ok(out) => {
            let err = String::from_utf8_lossy(&out.stderr);
            Some(err.lines().last().unwrap_or("").to_string())
        }
        Err(e) => Some(format!("no {}: {e}", python())),
    }
}

#[test]
fn the_mujoco_worlds_own_tests_pass() {
    if let Some(why) = unavailable() {
        eprintln!("skipped: the MuJoCo world's tests, MuJoCo cannot render here ({why})");
        return;
    }
    let out = py(&["-m", "unittest", "discover", "-s", "worlds/mujoco/tests"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("skipped"), "rendering works here, nothing may be skipped: {err}");
}

#[test]
fn the_vision_finds_the_ball_in_fresh_mujoco_frames_under_four_lights() {
    if let Some(why) = unavailable() {
        eprintln!("skipped: fresh MuJoCo frames, MuJoCo cannot render here ({why})");
        return;
    }
    let tmp = std::env::temp_dir().join(format!("mrt-mujoco-frames-{}", std::process::id()));
    let mut failures = Vec::new();
    for (k, light) in ["bright", "half", "warm", "side"].into_iter().enumerate() {
        let dir = tmp.join(light);
        let seed = (9001 + k).to_string();
        let scene = format!("scenes/{light}.xml");
        let out = py(&[
            "worlds/mujoco/render_frames.py",
            "dataset",
            "--scene",
            &scene,
            "--camera",
            "configs/vision/camera.toml",
            "--count",
            "8",
            "--empty",
            "1",
            "--robots",
            "2",
            "--seed",
            &seed,
            "--out",
            dir.to_str().unwrap(),
        ])
        .output()
        .unwrap();
        assert!(out.status.success(), "{light}: {}", String::from_utf8_lossy(&out.stderr));
        let truth = std::fs::read_to_string(dir.join("truth.jsonl")).unwrap();
        let truth: Vec<serde_json::Value> =
            truth.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
        let detect = Command::new(env!("CARGO_BIN_EXE_mrt"))
            .args(["vision", "detect", "--camera", "configs/vision/camera.toml"])
            .args(["--colors", "configs/vision/colors.toml"])
            .args(truth.iter().map(|t| dir.join(t["file"].as_str().unwrap())))
            .current_dir(repo())
            .output()
            .unwrap();
        assert!(detect.status.success(), "{}", String::from_utf8_lossy(&detect.stderr));
        let seen = String::from_utf8_lossy(&detect.stdout);
        assert_eq!(seen.lines().count(), truth.len(), "{seen}");
        for (t, line) in truth.iter().zip(seen.lines()) {
            let v: serde_json::Value = serde_json::from_str(line).unwrap();
            let objects = v["objects"].as_array().cloned().unwrap_or_default();
            let ball = objects.iter().find(|o| o["class"] == "ball");
            let file = format!("{light}/{}", t["file"].as_str().unwrap());
            match (t["ball"].is_null(), ball) {
                (true, None) => {}
                (true, Some(b)) => failures.push(format!("{file}: a ball where none is: {b}")),
                (false, None) => failures.push(format!("{file}: the ball missed")),
                (false, Some(b)) => {
                    let d = t["distance"].as_f64().unwrap();
                    let bearing = t["bearing"].as_f64().unwrap().to_degrees();
                    let seen_d = b["distance_m"].as_f64().unwrap();
                    let off = (b["bearing_deg"].as_f64().unwrap() - bearing).abs();
                    if (seen_d - d).abs() > 0.05 * d || off > 1.5 {
                        failures.push(format!("{file}: {d:.2} m seen at {seen_d:.2} m, {off:.2}°"));
                    }
                }
            }
        }
    }
    std::fs::remove_dir_all(&tmp).ok();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// `mrt world mujoco`: the world and a robot process on its devices play a few seconds of the
/// empty-goal scenario; every step is answered, the robot says goodbye and the report has the
/// team's shots and possession. The recording
/// holds the world's truth and the robot's messages, on the topics the web monitor reads.
#[test]
fn a_robot_process_plays_a_few_seconds_in_the_mujoco_world() {
    if let Some(why) = unavailable() {
        eprintln!("skipped: a robot in the MuJoCo world, MuJoCo cannot render here ({why})");
        return;
    }
    let zenoh = py(&["-c", "import zenoh"]).output();
    if !zenoh.as_ref().is_ok_and(|o| o.status.success()) {
        eprintln!("skipped: a robot in the MuJoCo world, no zenoh for Python here");
        return;
    }
    let record = std::env::temp_dir().join(format!("mrt-mujoco-{}.mcap", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["world", "mujoco", "--scenario", "empty-goal", "--seed", "5", "--steps", "40"])
        .arg("--record")
        .arg(&record)
        .arg("--python")
        .arg(python())
        .current_dir(repo())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("MuJoCo empty-goal: home (milan)"), "{text}");
    let report: serde_json::Value =
        serde_json::from_str(text.lines().last().unwrap_or("")).unwrap();
    let steps = report["steps"].as_u64().unwrap();
    assert!(steps >= 40, "{report}");
    assert_eq!(report["answered"]["home-1"].as_u64(), Some(steps), "{report}");
    assert_eq!(report["missing"]["home-1"].as_u64(), Some(0), "{report}");
    assert_eq!(report["byes"]["home-1"], true, "{report}");
    // The team's line, as `mrt sim` prints it, from the world's statistics.
    let team = text.lines().nth(1).unwrap_or("");
    assert!(team.trim_start().starts_with("milan") && team.contains("possession"), "{text}");
    for key in ["shots", "on_target", "possession_steps"] {
        assert!(report["stats"]["home"][key].is_u64(), "{key}: {report}");
    }
    let listing = Command::new(env!("CARGO_BIN_EXE_mrt")).arg("replay").arg(&record).output();
    std::fs::remove_file(&record).ok();
    let listing = String::from_utf8_lossy(&listing.unwrap().stdout).into_owned();
    let count = |topic: &str| {
        let line = listing.lines().find(|l| l.split_whitespace().next() == Some(topic));
        let words: Vec<&str> = line.map(|l| l.split_whitespace().collect()).unwrap_or_default();
        words.get(2).and_then(|n| n.parse::<u64>().ok()).unwrap_or(0)
    };
    assert_eq!(count("/match"), 1, "{listing}");
    for topic in ["/truth", "/home/0/WorldSnapshot", "/home/0/Localization"] {
        assert!(count(topic) >= 40, "{topic}: {listing}");
    }
}
