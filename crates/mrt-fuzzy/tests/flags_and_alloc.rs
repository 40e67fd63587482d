//! §10.5 (manual §10.4.10): boolean flags and the ManualMove switch, and a state kept across
//! cycles through an output fed back as an input; plus: a warmed-up cycle through the slot API
//! allocates nothing.

#![allow(clippy::unwrap_used)]

use mrt_fuzzy::brian::Brian;
use std::path::PathBuf;

fn config(test: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mrt-flags-{test}-{}", std::process::id()));
    std::fs::create_dir_all(d.join("b")).unwrap();
    for (f, t) in [
        // The manual's STATUS shape and Auto predicate; `Armed` is a flag output fed back.
        ("shape_ctof.txt", "(STATUS (SNG (MANUAL 0.0)) (SNG (AUTO 1.0)))\n(FLAGIN (SNG (TRUE 1.0)))\n(JOY (TOR (PUSHED 0 1)))"),
        ("ctof.txt", "(Status STATUS)\n(Armed FLAGIN)\n(Joystick JOY)"),
        ("Predicate.ini", "Auto = (D Status AUTO);\nArmed = (D Armed TRUE);\nPushed = (D Joystick PUSHED);"),
        ("Cando.ini", "Patrol = (P Auto);\nManualMove = (NOT (P Auto));"),
        ("want.txt", "Patrol = (P Auto);\nManualMove = (NOT (P Auto));"),
        ("behavior.txt", "(level 1 ManualMove b/ManualMove.rul)\n(level 1 Patrol b/Patrol.rul)"),
        ("b/ManualMove.rul", "(Pushed) => (Speed FAST);\n(NOT (Pushed)) => (Speed HALT);"),
        // Patrol arms the flag once the joystick was pushed, and drives slowly once armed.
        ("b/Patrol.rul", "(Pushed) => (Armed TRUE);\n(Armed) => (Speed SLOW) (Armed TRUE);"),
        ("s_shape.txt", "(SPEED (SNG (HALT 0)) (SNG (SLOW 20)) (SNG (FAST 100)))\n(FLAG (SNG (TRUE 1.0)))"),
        ("s_ftoc.txt", "(Speed SPEED)\n(Armed FLAG)"),
    ] {
        std::fs::write(d.join(f), t).unwrap();
    }
    d
}

#[test]
fn manual_move_switch_and_a_flag_that_keeps_state() {
    let dir = config("switch");
    let mut b = Brian::from_dir(&dir).unwrap();
    // Status MANUAL: only ManualMove runs; the joystick drives.
    let c = b.run(&[("Status", 0.0, 1.0), ("Joystick", 1.0, 1.0)]);
    assert_eq!(c.get("Speed"), Some(&100.0));
    assert_eq!(c.get("Armed"), None, "Patrol idle: the flag is absent, not 0");
    // Status AUTO: Patrol runs; pushing the joystick arms the flag (value 1)...
    let c = b.run(&[("Status", 1.0, 1.0), ("Joystick", 1.0, 1.0)]);
    assert_eq!((c.get("Armed"), c.get("Speed")), (Some(&1.0), None));
    // ...which comes back as an input: armed, Patrol drives slowly and keeps the flag, with the
    // joystick released.
    for _ in 0..3 {
        let c = b.run(&[("Status", 1.0, 1.0)]);
        assert_eq!((c.get("Armed"), c.get("Speed")), (Some(&1.0), Some(&20.0)));
    }
    // A missing Status reads as (0, 1): not Auto, so ManualMove takes over and stops.
    let c = b.run(&[]);
    assert_eq!(c.get("Speed"), Some(&0.0));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn run_allocates_nothing_once_warmed_up_when_its_result_is_dropped() {
    let dir = config("run-alloc");
    let mut b = Brian::from_dir(&dir).unwrap();
    for _ in 0..3 {
        drop(b.run(&[("Status", 1.0, 1.0), ("Joystick", 1.0, 0.8)]));
    }
    let mut speed = 0.0;
    let info = allocation_counter::measure(|| {
        for i in 0..100 {
            let c = b.run(&[("Status", f64::from(i % 2), 1.0), ("Joystick", 0.5, 0.8)]);
            speed += c.get("Speed").copied().unwrap_or(0.0);
        }
    });
    assert_eq!(info.count_total, 0, "{info:?}");
    assert!(speed > 0.0);
    // A kept result never changes under its holder.
    let kept = b.run(&[("Status", 0.0, 1.0), ("Joystick", 1.0, 1.0)]);
    let before = kept.to_map();
    b.run(&[("Status", 0.0, 1.0), ("Joystick", 0.0, 1.0)]);
    assert_eq!(kept.to_map(), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_warmed_up_cycle_allocates_nothing() {
    let dir = config("alloc");
    let mut b = Brian::from_dir(&dir).unwrap();
    let (status, joy) = (b.input_slot("Status").unwrap(), b.input_slot("Joystick").unwrap());
    for _ in 0..3 {
        b.set_input(status, 1.0, 1.0);
        b.set_input(joy, 1.0, 0.8);
        b.step();
    }
    let mut twin = b.clone();
    let info = allocation_counter::measure(|| {
        for i in 0..100 {
            b.set_input(status, f64::from(i % 2), 1.0);
            b.set_input(joy, 0.5, 0.8);
            b.step();
        }
    });
    assert_eq!(info.count_total, 0, "{info:?}");
    // The same cycles through the allocating convenience API give the same commands.
    let mut last = Default::default();
    for i in 0..100 {
        last = twin.run(&[("Status", f64::from(i % 2), 1.0), ("Joystick", 0.5, 0.8)]).to_map();
    }
    let slots: Vec<(String, f64)> = b
        .output_names()
        .enumerate()
        .filter_map(|(k, n)| b.output(k).map(|v| (n.to_string(), v)))
        .collect();
    assert_eq!(slots, last.into_iter().collect::<Vec<_>>());
    std::fs::remove_dir_all(&dir).unwrap();
}
