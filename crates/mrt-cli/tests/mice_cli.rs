//! `mrt sim --calibrate-mice` and `mrt mice calibrate LOG`:
//! the simulator's rig recovers its mounting, its log gives the same calibration through
//! `mrt mice calibrate`, and a broken log is named by file, line and column.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::process::Command;

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("mrt-mice-{}-{name}", std::process::id()))
}

#[test]
fn the_rig_recovers_the_mounting_and_its_log_calibrates_the_same() {
    let log = temp("rig.csv");
    let out = mrt()
        .args(["sim", "--calibrate-mice", "--seed", "4", "--json", "--mice-log"])
        .arg(&log)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rig: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(rig["within_tolerances"], true, "{rig:#}");
    // The estimates against the simulated mounting (SI units): the stated tolerances.
    for mouse in ["left", "right"] {
        let (est, truth) = (&rig["calibration"][mouse], &rig["simulated"][mouse]);
        let k = rig["expected_resolution"][mouse].as_f64().unwrap();
        assert!((est["resolution"]["value"].as_f64().unwrap() / k - 1.0).abs() < 0.01, "{rig:#}");
        for axis in ["x", "y"] {
            let e = est[axis]["value"].as_f64().unwrap() - truth[axis].as_f64().unwrap();
            assert!(e.abs() < 0.002, "{mouse} {axis}: {e} m");
        }
        let e = est["sigma"]["value"].as_f64().unwrap() - truth["sigma"].as_f64().unwrap();
        assert!(e.abs() < 0.5f64.to_radians(), "{mouse} σ: {e} rad");
        assert!(est["resolution"]["std_error"].as_f64().unwrap() > 0.0);
    }
    // The log it wrote, calibrated by `mrt mice calibrate`: the same numbers.
    let out = mrt().args(["mice", "calibrate", "--json"]).arg(&log).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let cal: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(cal, rig["calibration"]);
    // And as a table.
    let out = mrt().args(["mice", "calibrate"]).arg(&log).output().unwrap();
    let _ = std::fs::remove_file(&log);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("10 straight runs of 500 mm, 5 turns of 360°"), "{text}");
    for row in ["resolution (counts/mm)", "σ, orientation (°)", "D (mm)", "δ (°)", " ± "] {
        assert!(text.contains(row), "{row}: {text}");
    }
}

#[test]
fn a_broken_log_is_named_by_file_line_and_column() {
    let log = temp("bad.csv");
    std::fs::write(&log, "kind,run,mouse,x,y\nstraight,1,left,10,20\nstraight,1,rihgt,10,20\n")
        .unwrap();
    let out = mrt().args(["mice", "calibrate"]).arg(&log).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let at = format!("{}:3:12: unknown mouse `rihgt`", log.display());
    assert!(err.contains(&at), "{err}");
    // Well formed, but one straight run: too few for a standard error.
    std::fs::write(
        &log,
        "kind,run,mouse,x,y\nstraight,1,left,10,20\nstraight,1,right,10,20\n\
         turn,1,l,5,5\nturn,1,r,5,5\nturn,2,l,5,5\nturn,2,r,5,5\n",
    )
    .unwrap();
    let out = mrt().args(["mice", "calibrate"]).arg(&log).output().unwrap();
    let _ = std::fs::remove_file(&log);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("1 straight run(s): the calibration needs at least 2"), "{err}");
    let out = mrt().args(["mice", "calibrate", "/nonexistent/mice.csv"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/mice.csv"));
}
