//! `mrt soak`: short campaigns through the binary (the long ones are in docs/reliability.md).

#![allow(clippy::unwrap_used)]

use std::process::Command;

fn soak(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_mrt")).arg("soak").args(args).output().unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_short_campaign_of_random_matches_has_no_crash() {
    let (ok, out, err) = soak(&["matches", "--count", "6", "--half", "2", "--seed", "40"]);
    assert!(ok, "{out}{err}");
    assert!(out.starts_with("6 matches (seeds 40..=45)") && out.contains(": 0 crashes"), "{out}");
}

#[test]
fn one_robot_is_watched_minute_by_minute() {
    let (ok, out, err) = soak(&["hour", "--minutes", "2"]);
    assert!(ok, "{out}{err}");
    assert!(out.starts_with("one chaos robot alone, 2 simulated minutes"), "{out}");
    if cfg!(target_os = "linux") {
        assert!(out.contains("minute   0.0:") && out.contains("KiB per simulated minute"), "{out}");
    }
}

#[test]
fn counts_are_range_checked() {
    let (ok, _, err) = soak(&["matches", "--count", "0"]);
    assert!(!ok && err.contains("--count must be 1 to 1000000, not 0"), "{err}");
    let (ok, _, err) = soak(&["matches", "--seed", "18446744073709551615", "--count", "2"]);
    assert!(!ok && err.contains("runs past the largest seed"), "{err}");
    let (ok, _, err) = soak(&["hour", "--minutes", "0"]);
    assert!(!ok && err.contains("--minutes must be 1 to 1440, not 0"), "{err}");
}
