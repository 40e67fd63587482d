//! `mrt brian check|eval|plot` on the brian40 configurations (`configs/brian/brian40`, flat,
//! and `brian40-hier`, with a level-2 behavior).

#![allow(clippy::unwrap_used, clippy::print_stderr)]

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// Runs `mrt brian eval DIR [--trace]` with `input` on stdin.
fn eval(dir: &std::path::Path, trace: bool, input: &[u8]) -> std::process::Output {
    let mut cmd = mrt();
    cmd.args(["brian", "eval"]).arg(dir);
    if trace {
        cmd.arg("--trace");
    }
    let mut child =
        cmd.stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

fn bench(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian").join(name)
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

#[test]
fn check_is_silent_on_a_good_configuration_and_names_the_place_of_an_error() {
    let dir = bench("brian40-hier");
    let out = mrt().args(["brian", "check"]).arg(&dir).output().unwrap();
    assert!(out.status.success());
    assert!(out.stdout.is_empty() && out.stderr.is_empty());

    let broken = std::env::temp_dir().join(format!("mrt-brian-check-{}", std::process::id()));
    copy_dir(&dir, &broken);
    let rul = broken.join("behaviors/ApproachBall.rul");
    let text = std::fs::read_to_string(&rul)
        .unwrap()
        .replace("(BallClose) => (SpeedModule SLOW);", "(BallClose) => (SpeedModule SLOWW);");
    std::fs::write(&rul, text).unwrap();
    let out = mrt().args(["brian", "check"]).arg(&broken).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error in file "), "{err}");
    assert!(
        err.contains("ApproachBall.rul at line 2: action `SpeedModule` has no label `SLOWW`"),
        "{err}"
    );
    assert!(err.trim_end().ends_with("ApproachBall.rul:2:29"), "{err}");
    std::fs::remove_dir_all(&broken).unwrap();
}

#[test]
fn eval_reads_json_lines_and_matches_the_expected_commands() {
    let dir = bench("brian40");
    let cycles: Vec<String> = std::fs::read_to_string(dir.join("cycles.jsonl"))
        .unwrap()
        .lines()
        .take(20)
        .map(String::from)
        .collect();
    let expected: Vec<serde_json::Value> = std::fs::read_to_string(dir.join("expected.jsonl"))
        .unwrap()
        .lines()
        .take(20)
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let out = eval(&dir, true, cycles.join("\n").as_bytes());
    assert!(out.status.success());
    let got: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(got.len(), 20);
    for (g, e) in got.iter().zip(&expected) {
        for (k, v) in e.as_object().unwrap() {
            let (g, v) = (g[k].as_f64().unwrap(), v.as_f64().unwrap());
            let d = if k.contains("Angle") {
                (g - v).rem_euclid(360.0).min((v - g).rem_euclid(360.0))
            } else {
                (g - v).abs()
            };
            assert!(d < 1e-3, "{k}: {g} vs {v}");
        }
        assert!(g["_trace"]["predicates"]["BallSeen"].is_array());
        assert!(g["_trace"]["behaviors"]["SearchBall"]["active"].is_boolean());
        let proposals = g["_trace"]["proposals"].as_array().unwrap();
        assert!(proposals.iter().all(|p| p["behavior"].is_string() && p["action"].is_string()));
    }
    // A malformed line is an error naming the line, not a panic.
    let out = eval(&dir, false, b"{\"BallDistance\": 10}\n{\"BallDistance\": \"far\"}\n");
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("input line 2"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn plot_draws_every_shape() {
    let dir = bench("brian40-hier");
    let svg = std::env::temp_dir().join(format!("mrt-brian-plot-{}.svg", std::process::id()));
    let out = mrt().args(["brian", "plot"]).arg(&dir).arg("--out").arg(&svg).output().unwrap();
    assert!(out.status.success());
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"));
    for name in [
        "BALLDIST",
        "OBSTDIST",
        "ANGLE",
        "PSPEED",
        "PHEADING",
        "SpeedModule",
        "SpeedAngle",
        "FRONTRIGHT",
        "AHEAD_B",
    ] {
        assert!(text.contains(name), "{name} missing");
    }
    assert_eq!(text.matches("<polyline").count(), 4 + 3 + 6 + 6 + 3 + 4, "one curve per input set");
    std::fs::remove_file(&svg).unwrap();
}

/// The shipped harvester configuration (in the repository, so never skipped).
#[test]
fn check_eval_and_plot_work_on_the_shipped_harvester() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian/harvester");
    let out = mrt().args(["brian", "check"]).arg(&dir).output().unwrap();
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = eval(
        &dir,
        true,
        b"{\"TargetDistance\": 300, \"TargetAngle\": 0, \"BatteryLevel\": 100, \"HomeDistance\": 400, \"HomeAngle\": 180}\n",
    );
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Target far straight ahead: go FAST (75 cm/s), heading 0 (ahead).
    assert_eq!(v["SpeedModule"].as_f64(), Some(75.0));
    assert_eq!(v["SpeedAngle"].as_f64(), Some(0.0));
    assert_eq!(v["_trace"]["behaviors"]["GoToTarget"]["active"], serde_json::Value::Bool(true));
    // GoToTarget proposes FAST for a far target, at full weight.
    let fast = v["_trace"]["proposals"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| {
            p["behavior"] == "GoToTarget" && p["action"] == "SpeedModule" && p["label"] == "FAST"
        })
        .cloned();
    assert!(fast.is_some_and(|p| p["value"].as_f64().unwrap() > 0.9), "{v}");
    let svg = std::env::temp_dir().join(format!("mrt-harvester-{}.svg", std::process::id()));
    assert!(mrt()
        .args(["brian", "plot"])
        .arg(&dir)
        .arg("--out")
        .arg(&svg)
        .output()
        .unwrap()
        .status
        .success());
    assert!(std::fs::read_to_string(&svg).unwrap().contains("TargetDistance"));
    std::fs::remove_file(&svg).unwrap();
}

/// `mrt brian check` said only "stream did not contain valid UTF-8" for a file with
/// a bad byte, and a `behavior.txt` naming a file outside the directory printed that file's
/// first token.
#[test]
fn check_reports_bad_utf8_at_its_place_and_refuses_foreign_rule_files() {
    let dir = bench("brian40-hier");
    let broken = std::env::temp_dir().join(format!("mrt-brian-issue17-{}", std::process::id()));
    copy_dir(&dir, &broken);
    let rul = broken.join("behaviors/ApproachBall.rul");
    let mut bytes = std::fs::read(&rul).unwrap();
    bytes.splice(0..0, b"\n\n   \xFF".iter().copied());
    std::fs::write(&rul, bytes).unwrap();
    let out = mrt().args(["brian", "check"]).arg(&broken).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(err.contains("ApproachBall.rul at line 3: invalid UTF-8 (byte 0xFF)"), "{err}");
    assert!(err.trim_end().ends_with("ApproachBall.rul:3:4"), "{err}");

    let secret = broken.with_extension("secret");
    std::fs::write(&secret, "TOP-SECRET first token").unwrap();
    let list = broken.join("behavior.txt");
    let text = std::fs::read_to_string(&list).unwrap();
    let text = text.replacen("behaviors/ApproachBall.rul", secret.to_str().unwrap(), 1);
    std::fs::write(&list, text).unwrap();
    let out = mrt().args(["brian", "check"]).arg(&broken).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("is outside the configuration directory") && !err.contains("TOP-SECRET"),
        "{err}"
    );
    std::fs::remove_file(&secret).unwrap();
    std::fs::remove_dir_all(&broken).unwrap();
}

/// `mrt brian eval --semantics original|manual`: the worked example of
/// `crates/mrt-fuzzy/tests/composition.rs`. Dist (80, reliability 0.4), Obst 30: the manual's
/// semantics give (0.49 × 20 + 0.256 × 80) / 0.746 = 40.589812; the original engine's do not
/// run Go (its CANDO reliability 0.4 is not above 0.49), leaving Avoid's SLOW: 20.
#[test]
fn eval_semantics_original_and_manual() {
    let dir = std::env::temp_dir().join(format!("mrt-brian-semantics-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("behaviors")).unwrap();
    for (name, text) in [
        ("shape_ctof.txt", "(DIST (TOL (NEAR 0 100)) (TOR (FAR 0 100)))"),
        ("ctof.txt", "(Dist DIST)\n(Obst DIST)"),
        ("Predicate.ini", "Far = (D Dist FAR);\nNear = (D Dist NEAR);\nBlocked = (D Obst NEAR);"),
        ("Cando.ini", "Go = (P Far);\nAvoid = (P Blocked);"),
        ("want.txt", "Go = (P Far);\nAvoid = (P Blocked);"),
        ("behavior.txt", "(level 1 Go behaviors/Go.rul)\n(level 1 Avoid behaviors/Avoid.rul)"),
        ("behaviors/Go.rul", "(Far) => (Speed FAST);\n(Near) => (Speed SLOW);"),
        ("behaviors/Avoid.rul", "(Blocked) => (Speed SLOW);"),
        ("s_shape.txt", "(SPEED (SNG (SLOW 20)) (SNG (FAST 80)))"),
        ("s_ftoc.txt", "(Speed SPEED)"),
    ] {
        std::fs::write(dir.join(name), text).unwrap();
    }
    let speed = |semantics: Option<&str>| {
        let mut cmd = mrt();
        cmd.args(["brian", "eval"]).arg(&dir);
        if let Some(s) = semantics {
            cmd.args(["--semantics", s]);
        }
        let mut child = cmd.stdin(Stdio::piped()).stdout(Stdio::piped()).spawn().unwrap();
        child.stdin.take().unwrap().write_all(b"{\"Dist\": [80, 0.4], \"Obst\": 30}\n").unwrap();
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success());
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["Speed"].as_f64().unwrap()
    };
    assert!((speed(None) - 30.28 / 0.746).abs() < 1e-6);
    assert!((speed(Some("manual")) - 30.28 / 0.746).abs() < 1e-6);
    assert!((speed(Some("original")) - 20.0).abs() < 1e-6);
    // engine.txt may choose it; the command line wins.
    std::fs::write(dir.join("engine.txt"), "semantics original\n").unwrap();
    assert!((speed(None) - 20.0).abs() < 1e-6);
    assert!((speed(Some("manual")) - 30.28 / 0.746).abs() < 1e-6);
    let bad = mrt().args(["brian", "eval"]).arg(&dir).args(["--semantics", "c++"]).output();
    assert!(!bad.unwrap().status.success());
    std::fs::remove_dir_all(&dir).unwrap();
}
