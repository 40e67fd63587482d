//! Two behaviors propose opposite values for the same output — the manual's
//! *AvoidObstaclesFromLeft* / *AvoidObstaclesFromRight* case (§10.2.4). What the engine gives
//! is checked against a hand computation of the manual's composition (formula 10.3 with the
//! singleton defuzzification of formula 10.6), written out here independently of the engine.
//! The `brian` module documentation ("Opposite proposals") explains the results.

#![allow(clippy::unwrap_used)]

use mrt_fuzzy::brian::Brian;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Inputs `L` and `R` in [0, 1] are the truth of `ObstacleLeft` and `ObstacleRight` (TOR 0 1).
/// `FromLeft` (CANDO and WANT `ObstacleLeft`) turns right and heads east; `FromRight` (CANDO and
/// WANT `ObstacleRight`) turns left and heads west. `Turn`: LEFT +30, RIGHT −30 (deg/s);
/// `SpeedAngle` (an angle: its name says so): EAST 90°, WEST 270°. Both behaviors at `levels`.
fn config(levels: (u32, u32)) -> PathBuf {
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let d = std::env::temp_dir().join(format!("mrt-opposite-{}-{n}", std::process::id()));
    std::fs::create_dir_all(d.join("b")).unwrap();
    let list = format!(
        "(level {} FromLeft b/FromLeft.rul)\n(level {} FromRight b/FromRight.rul)",
        levels.0, levels.1
    );
    for (f, t) in [
        ("shape_ctof.txt", "(S (TOR (HIGH 0 1)))"),
        ("ctof.txt", "(L S)\n(R S)"),
        ("Predicate.ini", "ObstacleLeft = (D L HIGH);\nObstacleRight = (D R HIGH);"),
        ("Cando.ini", "FromLeft = (P ObstacleLeft);\nFromRight = (P ObstacleRight);"),
        ("want.txt", "FromLeft = (P ObstacleLeft);\nFromRight = (P ObstacleRight);"),
        ("behavior.txt", list.as_str()),
        ("b/FromLeft.rul", "(ObstacleLeft) => (Turn RIGHT) (SpeedAngle EAST);"),
        ("b/FromRight.rul", "(ObstacleRight) => (Turn LEFT) (SpeedAngle WEST);"),
        (
            "s_shape.txt",
            "(TURN (SNG (LEFT 30)) (SNG (RIGHT -30)))\n(HEADING (SNG (EAST 90)) (SNG (WEST 270)))",
        ),
        ("s_ftoc.txt", "(Turn TURN)\n(SpeedAngle HEADING)"),
    ] {
        std::fs::write(d.join(f), t).unwrap();
    }
    d
}

fn run(levels: (u32, u32), l: f64, r: f64) -> (Option<f64>, Option<f64>) {
    let dir = config(levels);
    let mut b = Brian::from_dir(&dir).unwrap();
    let c = b.run(&[("L", l, 1.0), ("R", r, 1.0)]);
    std::fs::remove_dir_all(&dir).unwrap();
    (c.get("Turn").copied(), c.get("SpeedAngle").copied())
}

/// The manual by hand. Each behavior's single rule fires with the precondition's value times
/// its reliability (1 here): μ = L for `FromLeft`, R for `FromRight`; its WANT is the same
/// predicate, so its weight is μ_W = L (or R); formula 10.3 weighs each proposed singleton by
/// max_i(μ_W · μ) = L² (RIGHT, EAST) and R² (LEFT, WEST), and divides by the sum of weights.
fn manual(l: f64, r: f64) -> (f64, f64) {
    let (w_right, w_left) = (l * l, r * r);
    let turn = (w_right * -30.0 + w_left * 30.0) / (w_right + w_left);
    let heading = (w_right * 90.0 + w_left * 270.0) / (w_right + w_left);
    (turn, heading)
}

#[test]
fn unequal_opposite_proposals_give_the_weighted_mean() {
    // L = 0.8, R = 0.6: weights 0.64 and 0.36.
    let (turn, heading) = run((1, 1), 0.8, 0.6);
    let (m_turn, m_heading) = manual(0.8, 0.6);
    // (−30·0.64 + 30·0.36) / 1.00 = −8.4: a gentle right turn, as the manual computes.
    assert!((m_turn - -8.4).abs() < 1e-12);
    assert!((turn.unwrap() - m_turn).abs() < 1e-12, "{turn:?} vs {m_turn}");
    // The manual's arithmetic mean of the headings, (90·0.64 + 270·0.36) / 1 = 154.8°, points
    // somewhere neither behavior wanted. This engine averages angles on the circle (outputs
    // whose name contains `Angle`): 0.64 × the unit vector at 90° plus 0.36 × the one at 270°
    // is 0.28 × the unit vector at 90°: the stronger wish, EAST, exactly.
    assert!((m_heading - 154.8).abs() < 1e-9);
    assert!((heading.unwrap() - 90.0).abs() < 1e-9, "{heading:?}");
}

#[test]
fn equal_opposite_proposals_cancel() {
    // L = R = 0.7: both weights 0.49.
    let (turn, heading) = run((1, 1), 0.7, 0.7);
    let (m_turn, m_heading) = manual(0.7, 0.7);
    // Manual and engine: 0 deg/s, straight on, into the obstacle both behaviors avoid.
    assert!(m_turn.abs() < 1e-12);
    assert!(turn.unwrap().abs() < 1e-12, "{turn:?}");
    // The manual's arithmetic mean heads 180°, a direction nobody proposed; on the circle the
    // two wishes cancel exactly, the mean direction is undefined, and the engine says 0°.
    assert!((m_heading - 180.0).abs() < 1e-12);
    assert_eq!(heading, Some(0.0));
}

#[test]
fn levels_do_not_change_the_result_without_del() {
    // A higher level does not override a lower one by itself: it would have to `&DEL` the
    // lower level's proposals. Without it, the proposals of all levels are composed together.
    assert_eq!(run((1, 2), 0.8, 0.6), run((1, 1), 0.8, 0.6));
    assert_eq!(run((2, 1), 0.8, 0.6), run((1, 1), 0.8, 0.6));
}

/// Formula 10.5 (`composition argmax`) on the same wishes: only the behavior of larger
/// μC · μW acts. L = 0.8, R = 0.6: FromLeft scores 0.8 × 0.8 = 0.64 against 0.6 × 0.6 = 0.36,
/// so Turn is RIGHT, −30 (the weighted mean gives (0.64 × −30 + 0.36 × 30) / 1 = −8.4), and the
/// heading EAST, 90°. Equal wishes (0.7 each) tie: the first behavior to run, FromLeft (same
/// level, name order), acts alone: −30 and 90°, not the cancelled 0 of the mean.
#[test]
fn argmax_composition_takes_one_side() {
    for (l, r, weighted_turn) in [(0.8, 0.6, -8.4), (0.7, 0.7, 0.0)] {
        let dir = config((1, 1));
        let mut b = Brian::from_dir(&dir).unwrap();
        let c = b.run(&[("L", l, 1.0), ("R", r, 1.0)]);
        assert!((c["Turn"] - weighted_turn).abs() < 1e-6, "{c:?}");
        b.set_composition(mrt_fuzzy::brian::Composition::Argmax);
        let c = b.run(&[("L", l, 1.0), ("R", r, 1.0)]);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!((c["Turn"] + 30.0).abs() < 1e-6, "{c:?}");
        assert!((c["SpeedAngle"] - 90.0).abs() < 1e-6, "{c:?}");
    }
}
