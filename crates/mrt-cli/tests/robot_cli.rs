//! `mrt robot --config FILE`: the entry point of a robot on any world of the device protocol
//! (the distributed match and the MuJoCo world start their robots with it; `sim_cli.rs` plays
//! such a match). Here: the shipped robot file reads, and a
//! bad file is refused with its file, line and column before anything starts.
#![cfg(feature = "net")]
#![allow(clippy::unwrap_used)]

use mrt_robot::config::RobotFile;
use std::process::Command;

fn shipped() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/robot/robot.toml")
}

#[test]
fn the_shipped_robot_file_describes_a_chaos_field_player_on_a_world() {
    let f = RobotFile::from_file(shipped()).unwrap();
    let spec = f.spec().unwrap();
    assert_eq!((spec.robot, spec.keeper, spec.stack.name()), (1, false, "chaos"));
    assert_eq!((f.devices.kind.as_str(), f.devices.world.as_deref()), ("world", Some("sim")));
    // Its values are the defaults, written out.
    let defaults = RobotFile::default();
    assert_eq!(
        (&f.body, &f.sensors, &f.field),
        (&defaults.body, &defaults.sensors, &defaults.field)
    );
    assert!((f.guidance.half_cone - defaults.guidance.half_cone).abs() < 1e-4);
}

fn robot(file: &std::path::Path) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["robot", "--config"])
        .arg(file)
        .output()
        .unwrap();
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn a_bad_robot_file_is_refused_with_its_place() {
    let dir = std::env::temp_dir().join(format!("mrt-robot-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, "[robot]\nid = 1\n\n[body]\nradius = \"big\"\n").unwrap();
    let (ok, err) = robot(&bad);
    assert!(!ok && err.contains("bad.toml:5:10"), "{err}");
    std::fs::write(&bad, "[devices]\nkind = \"usb\"\n").unwrap();
    let (ok, err) = robot(&bad);
    assert!(!ok && err.contains("devices.kind = \"usb\"") && err.contains("Devices"), "{err}");
    std::fs::write(&bad, "[devices]\nworld = \"w\"\nnet = \"missing.cfg\"\n").unwrap();
    let (ok, err) = robot(&bad);
    assert!(!ok && err.contains("missing.cfg"), "{err}");
    std::fs::write(&bad, "[devices]\nkind = \"world\"\n").unwrap();
    let (ok, err) = robot(&bad);
    assert!(!ok && err.contains("devices.world is missing"), "{err}");
    std::fs::write(&bad, "[devices]\nworld = \"No Name\"\n").unwrap();
    let (ok, err) = robot(&bad);
    assert!(!ok && err.contains("bad.toml: devices") && err.contains("is not a name"), "{err}");
    let (ok, err) = robot(&dir.join("none.toml"));
    assert!(!ok && err.contains("none.toml"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
