//! `mrt robot` on the devices of a world written in another language (docs/devices.md): the
//! Python stub world of `python/mrt_world` drives one robot process for 100 steps over zenoh,
//! with hostile messages between the steps; every step is answered, every bad message is
//! dropped, the match ends with the robot's bye.
//!
//! The interpreter is `$MRT_PYTHON` (`.ci/run` makes one with `python/requirements.txt`), else
//! `python3`. Where it has no zenoh, the test says plainly that it was skipped.
#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn python() -> Command {
    let mut cmd = Command::new(std::env::var("MRT_PYTHON").unwrap_or_else(|_| "python3".into()));
    cmd.current_dir(repo()).env("PYTHONPATH", repo().join("python"));
    cmd
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// A scratch directory `case` with the shipped world robot file pointed at `endpoint`, and
/// `mrt robot` started on it.
fn robot_on(case: &str, endpoint: &str) -> (PathBuf, std::process::Child) {
    let dir = std::env::temp_dir().join(format!("mrt-world-{case}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("robot.toml");
    let shipped = std::fs::read_to_string(repo().join("configs/robot/world.toml")).unwrap();
    let text = shipped.replace("tcp/127.0.0.1:7470", endpoint);
    assert!(text.contains(endpoint), "the shipped world robot file names an endpoint");
    std::fs::write(&file, text).unwrap();
    let robot = Command::new(env!("CARGO_BIN_EXE_mrt"))
        .args(["robot", "--config"])
        .arg(&file)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    (dir, robot)
}

#[test]
fn a_python_world_drives_a_robot_process_for_100_steps_and_its_bad_messages_are_dropped() {
    match python().args(["-c", "import zenoh, mrt_world"]).output() {
        Ok(out) if out.status.success() => {}
        Ok(out) => {
            let err = String::from_utf8_lossy(&out.stderr);
            let why = err.lines().last().unwrap_or("").to_string();
            eprintln!("skipped: the Python world, no zenoh for Python here ({why})");
            return;
        }
        Err(e) => {
            eprintln!("skipped: the Python world, no Python here ({e})");
            return;
        }
    }
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let world = python()
        .args(["-m", "mrt_world.stub", "--world", "stub", "--robot", "home-1", "--steps", "100"])
        .args(["--listen", &endpoint, "--image", "jpeg", "--hostile", "--timeout", "60"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (dir, robot) = robot_on("cli", &endpoint);
    let world = world.wait_with_output().unwrap();
    let robot = robot.wait_with_output().unwrap();
    let world_err = String::from_utf8_lossy(&world.stderr);
    let robot_err = String::from_utf8_lossy(&robot.stderr);
    assert!(world.status.success(), "the world: {world_err}\nthe robot: {robot_err}");
    assert!(robot.status.success(), "the robot: {robot_err}");
    let summary: serde_json::Value = serde_json::from_slice(world.stdout.trim_ascii())
        .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&world.stdout)));
    assert_eq!(summary["steps"], 100);
    assert_eq!(summary["answered"]["home-1"], 100, "{summary}");
    assert_eq!(summary["byes"]["home-1"], true, "{summary}");
    assert!(robot_err.contains("home-1: 100 steps"), "{robot_err}");
    // The robot counted every hostile message the stub sent as dropped.
    let dropped = robot_err.lines().find(|l| l.contains("dropped {")).unwrap_or_default();
    let counts: serde_json::Value =
        serde_json::from_str(&dropped[dropped.find('{').unwrap_or(0)..]).unwrap();
    let total: u64 = counts.as_object().unwrap().values().map(|v| v.as_u64().unwrap()).sum();
    assert!(total >= 8, "the hostile messages were counted: {dropped}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_python_worlds_own_tests_pass() {
    let probe = python().args(["-c", "import zenoh, jsonschema, numpy, PIL"]).output();
    if !probe.as_ref().is_ok_and(|o| o.status.success()) {
        eprintln!("skipped: python/mrt_world's tests, python/requirements.txt is not installed");
        return;
    }
    let out = python()
        .args(["-m", "unittest", "discover", "-s", "tests"])
        .current_dir(repo().join("python"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("skipped"), "with the requirements installed, nothing is skipped: {err}");
}

/// A robot whose world disappears mid-match (its process killed) ends within a couple of
/// seconds, saying so, instead of waiting out its silence: the world holds a liveliness token
/// while it runs.
#[test]
fn a_robot_ends_soon_after_its_world_is_gone() {
    if !python().args(["-c", "import zenoh, mrt_world"]).output().is_ok_and(|o| o.status.success())
    {
        eprintln!("skipped: the Python world, no zenoh for Python here");
        return;
    }
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let mut world = python()
        .args(["-m", "mrt_world.stub", "--world", "stub", "--robot", "home-1"])
        .args(["--steps", "100000", "--listen", &endpoint, "--timeout", "60"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let (dir, robot) = robot_on("gone", &endpoint);
    // Let the match run a while, then kill the world.
    std::thread::sleep(std::time::Duration::from_secs(6));
    world.kill().unwrap();
    let killed = std::time::Instant::now();
    let _ = world.wait();
    let out = robot.wait_with_output().unwrap();
    let took = killed.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(took < std::time::Duration::from_secs(5), "{took:?}: {err}");
    assert!(!out.status.success() && err.contains("went away"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
