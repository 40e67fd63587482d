//! Mr. BRIAN's composition and defuzzification beyond the defaults, each on
//! a worked example computed by hand in the test's comment (MRT manual §10.2.4, §10.3.6–10.3.9,
//! §10.4.6, §10.4.9).
//!
//! Every test runs the configuration [`base`]: two level-1 behaviors over two inputs whose
//! shapes are straight lines, so that every fuzzy value is easy to compute.
//!
//! - `Dist` and `Obst` use DIST: NEAR = TOL (0 100) is 1 − x/100 and FAR = TOR (0 100) is
//!   x/100 on [0, 100].
//! - Predicates: Far = Dist FAR, Near = Dist NEAR, Blocked = Obst NEAR.
//! - Go: CANDO = WANT = Far; rules `(Far) => (Speed FAST)`, `(Near) => (Speed SLOW)`.
//! - Avoid: CANDO = WANT = Blocked; rule `(Blocked) => (Speed SLOW)`.
//!
//! At Dist = 80, Obst = 30 (reliability 1): Far 0.8, Near 0.2, Blocked 0.7. Both behaviors run
//! (0.8 and 0.7 above 0.49) with weights 0.8 and 0.7; with `mult_weight_composer` Go proposes
//! FAST 0.8 × 0.8 = 0.64 and SLOW 0.2 × 0.8 = 0.16, Avoid SLOW 0.7 × 0.7 = 0.49; the default
//! `max_float_composer` gives FAST 0.64, SLOW 0.49.
#![allow(clippy::unwrap_used)]

use mrt_fuzzy::brian::{
    Brian, BrianSources, CandoFilter, CodeBehavior, Composition, Proposals, Semantics, Situation,
    ThresholdFilter,
};
use mrt_fuzzy::{BrianError, FuzzyValue};

/// The configuration of the module doc, with `s_shape` as the output shape of Speed.
fn base(s_shape: &str) -> BrianSources {
    let mut files = BrianSources::new();
    for (name, text) in [
        ("shape_ctof.txt", "(DIST (TOL (NEAR 0 100)) (TOR (FAR 0 100)))"),
        ("ctof.txt", "(Dist DIST)\n(Obst DIST)"),
        ("Predicate.ini", "Far = (D Dist FAR);\nNear = (D Dist NEAR);\nBlocked = (D Obst NEAR);"),
        ("Cando.ini", "Go = (P Far);\nAvoid = (P Blocked);"),
        ("want.txt", "Go = (P Far);\nAvoid = (P Blocked);"),
        ("behavior.txt", "(level 1 Go behaviors/Go.rul)\n(level 1 Avoid behaviors/Avoid.rul)"),
        ("behaviors/Go.rul", "(Far) => (Speed FAST);\n(Near) => (Speed SLOW);"),
        ("behaviors/Avoid.rul", "(Blocked) => (Speed SLOW);"),
        ("s_ftoc.txt", "(Speed SPEED)"),
    ] {
        files.insert(name, text);
    }
    files.insert("s_shape.txt", s_shape);
    files
}

/// Singleton outputs: SLOW 20, FAST 80.
const SINGLETONS: &str = "(SPEED (SNG (SLOW 20)) (SNG (FAST 80)))";
/// Polygon outputs: SLOW = TRA (0 10 30 40), FAST = TRI (60 80 100).
const POLYGONS: &str = "(SPEED\n (TRA (SLOW 0 10 30 40))\n (TRI (FAST 60 80 100)))";

fn speed(brian: &mut Brian, dist: (f64, f64), obst: (f64, f64)) -> f64 {
    let out = brian.run(&[("Dist", dist.0, dist.1), ("Obst", obst.0, obst.1)]);
    *out.get("Speed").unwrap()
}

fn assert_close(got: f64, want: f64) {
    assert!((got - want).abs() < 1e-6, "got {got}, want {want}");
}

/// §10.3.9 and §10.4.6, barycenter defuzzification (formula 10.7 corrected: see
/// `mrt_fuzzy::shapes::barycenter`), chosen by the output shape: all its sets are polygons.
///
/// FAST 0.64 and SLOW 0.49 (module doc). SLOW = TRA (0 10 30 40) clipped at 0.49 rises to
/// 0.49 at 4.9 and falls from 35.1: area 0.49 × (40 + 30.2) / 2 = 17.199, centroid 20 (it is
/// symmetric). FAST = TRI (60 80 100) clipped at 0.64: top from 72.8 to 87.2, area 0.64 ×
/// (40 + 14.4) / 2 = 17.408, centroid 80. Barycenter (17.199 × 20 + 17.408 × 80) / (17.199 +
/// 17.408) = (343.98 + 1392.64) / 34.607 = 50.181177…
///
/// With singletons SLOW 20 and FAST 80 (formula 10.6): (0.49 × 20 + 0.64 × 80) / 1.13 =
/// 61 / 1.13 = 53.982301….
#[test]
fn barycenter_defuzzification_of_polygon_outputs() {
    let mut brian = Brian::from_sources(&base(POLYGONS)).unwrap();
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 1736.62 / 34.607);
    let sets: Vec<_> = brian.output_sets().collect();
    assert_eq!(sets[0].1[1].1.identifier(), "TRI");
    // Each polygon label's singleton is its set's barycenter at full height.
    let singletons: Vec<_> = brian.output_singletons().collect();
    assert_close(singletons[0].1[0].1, 20.0);
    assert_close(singletons[0].1[1].1, 80.0);

    let mut brian = Brian::from_sources(&base(SINGLETONS)).unwrap();
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
}

/// A shape is defuzzified one way: SNG mixed with polygons, open sets (TOL, TOR) and sets of
/// no width are refused at the shape's name, with file, line and column.
#[test]
fn output_shapes_that_cannot_be_defuzzified_are_refused_where_they_are() {
    let cases = [
        (
            "\n(SPEED (SNG (SLOW 20)) (TRI (FAST 60 80 100)))",
            "mixes singletons (SNG, formula 10.6) with set `FAST` (TRI)",
        ),
        (
            "(SPEED (TRI (SLOW 0 10 20))\n  (SNG (FAST 80)))",
            "mixes polygons (TRI, DIV, TRA, REC: barycenter, formula 10.7) with set `FAST` (SNG)",
        ),
        ("\n(SPEED (TRI (SLOW 0 10 20)) (TOR (FAST 60 80)))", "is TOR, open on one side"),
        ("\n(SPEED (TRI (SLOW 10 10 10)) (TRI (FAST 60 80 100)))", "has no barycenter"),
    ];
    for (shape, what) in cases {
        let e = Brian::from_sources(&base(shape)).unwrap_err().to_string();
        assert!(e.contains(what), "{shape}: {e}");
        let line = if shape.starts_with('\n') { 2 } else { 1 };
        assert!(e.ends_with(&format!("s_shape.txt:{line}:2")), "{shape}: {e}");
    }
}

/// §10.2.4, formula 10.5: for each output, only the actions of the behavior of largest
/// μC · μW. Singletons SLOW 20, FAST 80.
///
/// - Dist 80, Obst 30: Go scores 0.8 × 0.8 = 0.64, Avoid 0.7 × 0.7 = 0.49. Go alone: FAST
///   0.64, SLOW 0.16, so (0.16 × 20 + 0.64 × 80) / 0.8 = 54.4 / 0.8 = 68. The weighted
///   composition (formula 10.3) gives 61 / 1.13 = 53.982301 (module doc).
/// - Dist 80, Obst 10: Blocked 0.9, Avoid scores 0.81 > 0.64. Avoid alone: SLOW 0.81, so 20.
///   Weighted: SLOW max(0.16, 0.81) = 0.81, FAST 0.64, so (16.2 + 51.2) / 1.45 = 46.482759.
#[test]
fn argmax_composition_of_formula_10_5() {
    let mut brian = Brian::from_sources(&base(SINGLETONS)).unwrap();
    assert_eq!(brian.composition(), Composition::Weighted, "the default");
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
    assert_close(speed(&mut brian, (80.0, 1.0), (10.0, 1.0)), 67.4 / 1.45);
    brian.set_composition(Composition::Argmax);
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 68.0);
    assert_close(speed(&mut brian, (80.0, 1.0), (10.0, 1.0)), 20.0);

    // Chosen in engine.txt.
    let mut files = base(SINGLETONS);
    files.insert("engine.txt", "composition argmax   # formula 10.5\n");
    let mut brian = Brian::from_sources(&files).unwrap();
    assert_eq!(brian.composition(), Composition::Argmax);
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 68.0);

    // A mistake is placed.
    files.insert("engine.txt", "\ncomposition vectorial\n");
    let e = Brian::from_sources(&files).unwrap_err().to_string();
    assert!(e.contains("at line 2: one of weighted, argmax, not `vectorial`"), "{e}");
    assert!(e.ends_with("engine.txt:2:13"), "{e}");
}

/// `semantics original`: CANDO and WANT gated on reliability, rules blind to it.
/// Singletons SLOW 20, FAST 80; Obst 30 (Blocked 0.7, reliability 1): Avoid proposes SLOW 0.49
/// in both semantics.
///
/// Dist (80, 0.4): Far (0.8, 0.4), Near (0.2, 0.4).
/// - Manual: Go runs (0.8 > 0.49), weight 0.8; its rules propose 0.8 × 0.4 = 0.32 and
///   0.2 × 0.4 = 0.08, weighted FAST 0.256 and SLOW 0.064. SLOW max(0.064, 0.49) = 0.49:
///   (0.49 × 20 + 0.256 × 80) / 0.746 = 30.28 / 0.746 = 40.589812.
/// - Original: Go's CANDO reliability 0.4 is not above 0.49: Go does not run. 20.
///
/// Dist (80, 0.6):
/// - Manual: FAST 0.8 × 0.6 × 0.8 = 0.384, SLOW 0.49: (9.8 + 30.72) / 0.874 = 46.361556.
/// - Original: Go runs (0.6 > 0.49) with weight 0.8 (WANT reliability 0.6 > 0.49), its rules
///   propose 0.8 and 0.2 whatever the reliability: FAST 0.64, SLOW 0.49: 61 / 1.13 =
///   53.982301, as with reliability 1.
///
/// With the threshold at 0.3 and Dist (80, 0.4), Go runs in both; in the original its WANT
/// reliability 0.4 is not above 0.49, so its weight is 0 and it proposes nothing: 20; the
/// manual gives 40.589812 as above.
#[test]
fn original_semantics_gate_cando_and_want_on_reliability() {
    let mut files = base(SINGLETONS);
    let mut manual = Brian::from_sources(&files).unwrap();
    assert_eq!(manual.semantics(), Semantics::Manual, "the default");
    files.insert("engine.txt", "semantics original\n");
    let mut original = Brian::from_sources(&files).unwrap();
    assert_eq!(original.semantics(), Semantics::Original);

    assert_close(speed(&mut manual, (80.0, 0.4), (30.0, 1.0)), 30.28 / 0.746);
    assert_close(speed(&mut original, (80.0, 0.4), (30.0, 1.0)), 20.0);
    assert_close(speed(&mut manual, (80.0, 0.6), (30.0, 1.0)), 40.52 / 0.874);
    assert_close(speed(&mut original, (80.0, 0.6), (30.0, 1.0)), 61.0 / 1.13);
    // Reliability 1: both agree.
    assert_close(speed(&mut manual, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
    assert_close(speed(&mut original, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);

    for brian in [&mut manual, &mut original] {
        brian.set_threshold(0.3);
    }
    assert_close(speed(&mut manual, (80.0, 0.4), (30.0, 1.0)), 30.28 / 0.746);
    assert_close(speed(&mut original, (80.0, 0.4), (30.0, 1.0)), 20.0);
    let go = original.trace().behaviors.iter().find(|b| b.0 == "Go").unwrap().2;
    assert!(go.is_some(), "Go runs, with weight 0");

    // Settable through the API too.
    original.set_semantics(Semantics::Manual);
    assert_close(speed(&mut original, (80.0, 0.4), (30.0, 1.0)), 30.28 / 0.746);
}

/// Avoid's rule `(Blocked) => (Speed SLOW);` written in Rust: SLOW with the rule's value,
/// Blocked's value × reliability.
struct AvoidInCode;

impl CodeBehavior for AvoidInCode {
    fn run(&self, situation: &Situation<'_>, out: &mut Proposals<'_>) {
        assert_eq!(situation.behavior(), "Avoid");
        if let Some(blocked) = situation.predicate("Blocked") {
            let same = situation.datum("Obst", "NEAR");
            assert_eq!(same, Some(blocked));
            let _ = out.propose("Speed", "SLOW", blocked.value * blocked.reliability);
        }
    }
}

/// A level-2 behavior in code: deletes every Speed proposal of level 1 (`&DEL.Speed ANY`) and
/// proposes SLOW with value 1.
struct Brake;

impl CodeBehavior for Brake {
    fn run(&self, _situation: &Situation<'_>, out: &mut Proposals<'_>) {
        let _ = out.delete("Speed", None);
        let _ = out.propose("Speed", "SLOW", 1.0);
        assert!(out.propose("Speed", "REVERSE", 1.0).is_err());
        assert!(out.propose("Steer", "LEFT", 1.0).is_err());
    }
}

/// Code behaviors (§10.3.6–10.3.7), listed as `code:<name>` in `behavior.txt`.
///
/// - Avoid in code proposes what its rule file proposed: Dist 80, Obst 30 give 61 / 1.13 =
///   53.982301 as in the module doc.
/// - Not registered, it proposes nothing (the loader warns): Go alone, FAST 0.64, SLOW 0.16:
///   (3.2 + 51.2) / 0.8 = 68.
/// - Brake (level 2, CANDO = WANT = Blocked 0.7) deletes level 1's Speed and proposes SLOW
///   1 × 0.7: Speed 20, whatever level 1 wished.
#[test]
fn behaviors_written_in_code() {
    let mut files = base(SINGLETONS);
    files.insert("behavior.txt", "(level 1 Go behaviors/Go.rul)\n(level 1 Avoid code:Avoid)");
    let mut brian = Brian::from_sources(&files).unwrap();
    assert!(brian.warnings().iter().any(|w| w.contains("behavior `Avoid` is written in code")));
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 68.0);
    assert_eq!(brian.register_behavior("Avoid", AvoidInCode).unwrap(), 1);
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
    let e = brian.register_behavior("Kick", Brake).unwrap_err();
    assert!(matches!(e, BrianError::NoCodeBehavior { ref name } if name == "Kick"), "{e}");

    files.insert(
        "behavior.txt",
        "(level 1 Go behaviors/Go.rul)\n(level 1 Avoid behaviors/Avoid.rul)\n\
         (level 2 Brake code:Brake)",
    );
    files.insert("Cando.ini", "Go = (P Far);\nAvoid = (P Blocked);\nBrake = (P Blocked);");
    files.insert("want.txt", "Go = (P Far);\nAvoid = (P Blocked);\nBrake = (P Blocked);");
    let mut brian = Brian::from_sources(&files).unwrap();
    brian.register_behavior("Brake", Brake).unwrap();
    brian.set_tracing(true);
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 20.0);
    let trace = brian.trace();
    let brake: Vec<_> = trace.proposals.iter().filter(|p| p.behavior == "Brake").collect();
    assert_eq!(brake.len(), 2, "{brake:?}");
    assert_eq!((brake[0].label, brake[0].value), (None, None), "the deletion");
    assert_close(brake[1].value.unwrap(), 0.7);

    // A code name that is missing is an error at its place.
    files.insert("behavior.txt", "(level 1 Go behaviors/Go.rul)\n(level 1  Avoid code:)");
    let e = Brian::from_sources(&files).unwrap_err().to_string();
    assert!(e.contains("the name of the code behavior of `Avoid` after `code:`"), "{e}");
    assert!(e.ends_with("behavior.txt:2:17"), "{e}");
}

/// A CANDO filter of the program's (§10.3.6, `can_do_filter`): a behavior runs when its CANDO
/// value is at least 0.75. Dist 80, Obst 30: Go (0.8) runs, Avoid (0.7) does not: Go alone,
/// (3.2 + 51.2) / 0.8 = 68. `set_threshold` brings the threshold filter back: 53.982301.
#[test]
fn a_pluggable_cando_filter() {
    struct AtLeast(f64);
    impl CandoFilter for AtLeast {
        fn can_do(&self, _behavior: &str, cando: FuzzyValue) -> bool {
            cando.value >= self.0
        }
    }
    let mut brian = Brian::from_sources(&base(SINGLETONS)).unwrap();
    assert!(!brian.has_cando_filter());
    brian.set_cando_filter(AtLeast(0.75));
    assert!(brian.has_cando_filter());
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 68.0);
    let avoid = brian.trace().behaviors.iter().find(|b| b.0 == "Avoid").unwrap().2;
    assert_eq!(avoid, None, "Avoid did not run");
    brian.set_threshold(0.49);
    assert!(!brian.has_cando_filter());
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
    // The threshold filter as a plugged filter gives the same.
    brian.set_cando_filter(ThresholdFilter { threshold: 0.49 });
    assert_close(speed(&mut brian, (80.0, 1.0), (30.0, 1.0)), 61.0 / 1.13);
}
