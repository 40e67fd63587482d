//! Bad inputs never panic and have documented effects: NaN belongs to no fuzzy set; ±∞ belong
//! to the open sides (TOL/TOR); unknown names are ignored; reliability is clamped to [0, 1];
//! a missing input reads as value 0, reliability 1 (§10.3.6).

#![allow(clippy::unwrap_used)]

mod common;

use mrt_fuzzy::brian::Brian;
use std::path::PathBuf;

fn config() -> PathBuf {
    let d = std::env::temp_dir().join(format!(
        "mrt-fuzzy-robust-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    common::write_one_behavior(&d);
    d
}

#[test]
fn bad_numbers_and_names_never_panic() {
    let dir = config();
    let mut b = Brian::from_dir(&dir).unwrap();
    // Near: the robot slows down.
    assert_eq!(b.run(&[("D", 5.0, 1.0)]).get("Speed"), Some(&10.0));
    // NaN is in no set: nothing is proposed, the action is absent.
    assert_eq!(b.run(&[("D", f64::NAN, 1.0)]).get("Speed"), None);
    // +∞ is FAR, −∞ is NEAR.
    assert_eq!(b.run(&[("D", f64::INFINITY, 1.0)]).get("Speed"), Some(&100.0));
    assert_eq!(b.run(&[("D", f64::NEG_INFINITY, 1.0)]).get("Speed"), Some(&10.0));
    // Reliability outside [0, 1] is clamped; NaN reliability proposes nothing.
    assert_eq!(b.run(&[("D", 30.0, 7.0)]).get("Speed"), Some(&100.0));
    assert_eq!(b.run(&[("D", 30.0, f64::NAN)]).get("Speed"), None);
    // Unknown names are ignored; a missing input reads as (0, 1): nothing can run.
    assert_eq!(b.run(&[("Nope", 1.0, 1.0)]).get("Speed"), None);
    assert!(b.run(&[]).is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn unused_definitions_are_warnings_with_their_place() {
    let dir = config();
    std::fs::write(
        dir.join("shape_ctof.txt"),
        "(Dist (TOL (NEAR 10 20)) (TOR (FAR 10 20)))\n(Spare (SNG (X 1)))",
    )
    .unwrap();
    std::fs::write(
        dir.join("Predicate.ini"),
        "Near = (D D NEAR);\nFar = (D D FAR);\nLonely = (NOT (P Far));",
    )
    .unwrap();
    let b = Brian::from_dir(&dir).unwrap();
    let w = b.warnings();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("shape_ctof.txt at line 2: shape `Spare` is not used in ctof.txt\n  --> ")
            && w[0].ends_with("shape_ctof.txt:2:2"),
        "{}",
        w[0]
    );
    assert!(
        w[1].contains("Predicate.ini at line 3: predicate `Lonely` is never used\n  --> ")
            && w[1].ends_with("Predicate.ini:3:1"),
        "{}",
        w[1]
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// §10.5: the previous cycle's outputs come back as inputs under the output's name with
/// reliability 1, unless the new cycle supplies that name.
#[test]
fn previous_outputs_feed_back_as_inputs() {
    let dir = config();
    std::fs::write(
        dir.join("shape_ctof.txt"),
        "(Dist (TOL (NEAR 10 20)) (TOR (FAR 10 20)))\n(Sp (TOL (LOW 20 30)))",
    )
    .unwrap();
    std::fs::write(dir.join("ctof.txt"), "(D Dist)\n(Speed Sp)").unwrap();
    std::fs::write(
        dir.join("Predicate.ini"),
        "Near = (D D NEAR);\nFar = (D D FAR);\nWasSlow = (D Speed LOW);",
    )
    .unwrap();
    std::fs::write(dir.join("want.txt"), "Go = (OR (P Near) (OR (P Far) (P WasSlow)));").unwrap();
    let mut b = Brian::from_dir(&dir).unwrap();
    let was_slow = |b: &Brian| {
        b.trace()
            .predicates
            .iter()
            .find(|(n, _)| *n == "WasSlow")
            .map(|(_, v)| (v.value, v.reliability))
    };
    assert_eq!(b.run(&[("D", 5.0, 1.0)]).get("Speed"), Some(&10.0));
    assert_eq!(was_slow(&b), Some((0.0, 1.0)), "first cycle: no previous output, Speed missing");
    b.run(&[("D", 50.0, 1.0)]);
    assert_eq!(was_slow(&b), Some((1.0, 1.0)), "previous Speed 10 is LOW");
    b.run(&[("D", 50.0, 1.0), ("Speed", 100.0, 0.5)]);
    assert_eq!(was_slow(&b), Some((0.0, 0.5)), "a supplied Speed wins over the previous output");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A behavior without CANDO never runs, one without WANT has weight 0: both are warned about,
/// at the behavior's line of `behavior.txt`.
#[test]
fn behaviors_without_cando_or_want_are_warned_about() {
    let dir = config();
    std::fs::write(
        dir.join("behavior.txt"),
        "(level 1 Go behaviors/Go.rul)\n(level 1 Idle behaviors/Go.rul)",
    )
    .unwrap();
    let mut b = Brian::from_dir(&dir).unwrap();
    let w = b.warnings().to_vec();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(
        w[0].contains("behavior `Idle` has no CANDO entry") && w[0].ends_with("behavior.txt:2:10"),
        "{}",
        w[0]
    );
    assert!(
        w[1].contains("behavior `Idle` has no WANT entry") && w[1].ends_with("behavior.txt:2:10"),
        "{}",
        w[1]
    );
    // Idle never runs: the commands are Go's alone.
    assert_eq!(b.run(&[("D", 5.0, 1.0)]).get("Speed"), Some(&10.0));
    assert!(b.trace().behaviors.iter().any(|(n, _, a)| *n == "Idle" && a.is_none()));
    std::fs::remove_dir_all(&dir).unwrap();
}
