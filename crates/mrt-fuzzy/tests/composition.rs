//! Issue 23, item 1: Mr. BRIAN's composition and defuzzification beyond the defaults, each on
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

use mrt_fuzzy::brian::{Brian, BrianSources};

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
