//! `mrt plan path`: the JSON it promises, the SVG, a map file, and clear
//! errors for bad arguments.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::Path;
use std::process::Command;

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap().parent().unwrap()
}

#[test]
fn a_path_across_the_field_round_robots_as_json() {
    let out = mrt()
        .args(["plan", "path", "--from", "-7.5,-0.5", "--to", "7.5,0.5", "--json"])
        .args(["--obstacles", "-4,0.5,0.25;-0.5,0.2,0.25;2.5,0.9,0.25"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let length = json["length_m"].as_f64().unwrap();
    let waypoints = json["waypoints"].as_array().unwrap();
    assert!(json["time_us"].as_f64().unwrap() > 0.0);
    assert_eq!(waypoints.first().unwrap(), &serde_json::json!([-7.5, -0.5]));
    assert_eq!(waypoints.last().unwrap(), &serde_json::json!([7.5, 0.5]));
    // The straight line is 15.03 m; the robots cost a little more.
    assert!(length > 15.03 && length < 15.03 * 1.05, "{length}");
    // Each corner keeps 0.35 m from each robot.
    for w in waypoints {
        let (x, y) = (w[0].as_f64().unwrap(), w[1].as_f64().unwrap());
        for (cx, cy) in [(-4.0, 0.5), (-0.5, 0.2), (2.5, 0.9)] {
            assert!((x - cx).hypot(y - cy) >= 0.25 + 0.35 - 1e-9, "{w}");
        }
    }
    let poses = json["poses"].as_array().unwrap();
    assert!(poses.len() as f64 >= length / 0.25, "{} poses", poses.len());
}

#[test]
fn a_map_file_with_a_door_and_a_drawing() {
    let svg = std::env::temp_dir().join(format!("mrt-plan-{}.svg", std::process::id()));
    let out = mrt()
        .current_dir(root())
        .args(["plan", "path", "--map", "configs/plan/room-with-door.toml", "--from=-4,-2"])
        .args(["--to=4,-2", "--robot-radius", "0.3", "--svg"])
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("path ") && text.contains(" -> "), "{text}");
    let drawing = std::fs::read_to_string(&svg).unwrap();
    let _ = std::fs::remove_file(&svg);
    assert!(drawing.starts_with("<svg") && drawing.contains("<polyline"), "{drawing}");
    // A robot of 0.5 m radius does not fit the 0.9 m door.
    let out = mrt()
        .current_dir(root())
        .args(["plan", "path", "--map", "configs/plan/room-with-door.toml", "--from=-4,-2"])
        .args(["--to=4,-2", "--robot-radius", "0.5"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("no path"), "{:?}", out);
}

#[test]
fn bad_arguments_are_clear_errors() {
    for (args, says) in [
        (vec!["--from", "1", "--to", "2,2"], "--from `1`: expected 2"),
        (vec!["--from", "1,x", "--to", "2,2"], "--from `1,x`"),
        (vec!["--from", "0,0", "--to", "inf,2"], "--to `inf,2`: expected 2 finite numbers"),
        (vec!["--from", "0,0", "--to", "2,2", "--field", "18"], "--field `18`"),
        (
            vec!["--from", "0,0", "--to", "2,2", "--obstacles", "1,1,-1"],
            "the radius must not be negative",
        ),
        (vec!["--from", "0,0", "--to", "2,2", "--accuracy", "0"], "invalid parameter `accuracy`"),
        (
            vec!["--from", "0,0", "--to", "2,2", "--map", "/nonexistent/m.toml"],
            "/nonexistent/m.toml",
        ),
    ] {
        let out = mrt().args(["plan", "path"]).args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}
