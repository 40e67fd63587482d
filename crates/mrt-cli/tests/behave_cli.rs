//! `mrt behave` and `mrt hfsm dot` on the shipped TeamChaos behaviors.

#![allow(clippy::unwrap_used)]

use std::path::PathBuf;
use std::process::Command;

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

fn teamchaos(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../behaviors/teamchaos").join(file)
}

fn lines(out: &std::process::Output) -> Vec<serde_json::Value> {
    let text = String::from_utf8(out.stdout.clone()).unwrap();
    text.lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

#[test]
fn behave_runs_the_attacker_through_a_scripted_world() {
    let out = mrt()
        .arg("behave")
        .arg(teamchaos("attacker.hfsm.lua"))
        .arg("--world")
        .arg(teamchaos("worlds/attacker_run.json"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cycles = lines(&out);
    let paths: Vec<&str> = cycles.iter().map(|c| c["path"].as_str().unwrap()).collect();
    assert_eq!(
        paths,
        [
            "Attacker/FaceBall",
            "Attacker/GoToBall",
            "Attacker/GoToBall",
            "Attacker/Score/ApproachBall",
            "Attacker/Score/DoKick",
            "Attacker/Score/DoKick"
        ]
    );
    assert_eq!(cycles[1]["transition"], "BallAhead");
    assert_eq!(cycles[1]["command"]["track_landmarks"], true, "quality 0.5 < 0.6");
    assert_eq!(cycles[5]["command"]["kick"], 1, "ball at 200 mm, ahead: FRONTKICK");
    assert_eq!(cycles[3]["time_ms"], 300.0);
}

#[test]
fn behave_without_a_world_sees_nothing_and_the_goalkeeper_scans() {
    let out = mrt()
        .arg("behave")
        .arg(teamchaos("goalkeeper.lua"))
        .args(["--cycles", "3"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cycles = lines(&out);
    assert_eq!(cycles.len(), 3);
    // Ball not seen: gkscanobj -> lookball turns (50 deg/s in its first 400 ms) and the
    // landmarks are tracked.
    let omega = cycles[0]["command"]["twist"]["omega"].as_f64().unwrap_or_default();
    assert!((omega - 50f64.to_radians()).abs() < 1e-12, "{omega} rad/s");
    assert_eq!(cycles[0]["command"]["track_landmarks"], true);
}

#[test]
fn behave_reports_script_errors_and_exits_non_zero() {
    let dir = std::env::temp_dir().join(format!("mrt-behave-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("bad.lua"), "local x = 1\nchaos.setVlin('fast')\n").unwrap();
    let out = mrt().arg("behave").arg(dir.join("bad.lua")).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.lua:2: runtime error") && err.contains("setVlin"), "{err}");
    assert_eq!(lines(&out)[0]["command"]["twist"]["vx"], 0.0, "the safe command: stand still");
    std::fs::write(dir.join("broken.lua"), "if then\n").unwrap();
    let out = mrt().arg("behave").arg(dir.join("broken.lua")).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken.lua:1:"));
    let out = mrt()
        .arg("behave")
        .arg(dir.join("bad.lua"))
        .args(["--world", "/nonexistent.json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn hfsm_dot_writes_dot_and_svg() {
    let dir = std::env::temp_dir().join(format!("mrt-hfsm-dot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (dot, svg) = (dir.join("attacker.dot"), dir.join("attacker.svg"));
    let out = mrt()
        .args(["hfsm", "dot"])
        .arg(teamchaos("attacker.hfsm.lua"))
        .arg("--dot")
        .arg(&dot)
        .arg("--svg")
        .arg(&svg)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let dot = std::fs::read_to_string(dot).unwrap();
    for needle in ["cluster_Score", "\"Attacker/Score\" -> \"Score/ApproachBall\"", "Kickable [1]"]
    {
        assert!(dot.contains(needle), "{needle} in\n{dot}");
    }
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.contains("<svg") && svg.contains("DoKick") && svg.contains("BallAway"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--cycles 18446744073709551615` panicked (capacity overflow) and
/// `--cycles 100000000` aborted allocating 23 GB, every world being made before the first
/// cycle. Counts are range-checked, and cycles are streamed: the largest count allowed prints
/// its first cycles at once (the child is then stopped).
#[test]
fn behave_counts_are_range_checked_and_cycles_are_streamed() {
    use std::io::BufRead as _;
    for (arg, value, says) in [
        ("--cycles", "18446744073709551615", "--cycles must be 1 to 1000000000"),
        ("--cycles", "0", "--cycles must be 1 to 1000000000, not 0"),
        ("--period-ms", "0", "--period-ms must be 1 to 3600000, not 0"),
    ] {
        let out = mrt()
            .arg("behave")
            .arg(teamchaos("goalkeeper.lua"))
            .args([arg, value])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains(says) && !err.contains("panicked"), "{err}");
    }
    let mut child = mrt()
        .arg("behave")
        .arg(teamchaos("goalkeeper.lua"))
        .args(["--cycles", "1000000000"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    for k in 0..3 {
        let line: serde_json::Value =
            serde_json::from_str(&lines.next().unwrap().unwrap()).unwrap();
        assert_eq!(line["cycle"], k);
    }
    child.kill().unwrap();
    child.wait().unwrap();
}
