//! The examples of MRT manual §10.4 through the real loader ([`Brian::from_dir`]), on the
//! small configurations of `tests/data/` and on the harvester of `configs/brian/harvester`;
//! and the loader's error messages (file, line, column) for the mistakes the manual warns
//! about.

use mrt_fuzzy::brian::{Brian, BrianFiles};
use mrt_fuzzy::{BrianError, FuzzyValue};
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn harvester() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian/harvester")
}

/// The harvester's inputs for a far target straight ahead with full batteries, home behind
/// (value, reliability): it drives FAST towards NORTH.
const FAR_TARGET_AHEAD: [(&str, f64, f64); 6] = [
    ("TargetDistance", 300.0, 1.0),
    ("TargetAngle", 0.0, 1.0),
    ("BatteryLevel", 100.0, 1.0),
    ("GraspingObject", 0.0, 1.0),
    ("HomeDistance", 400.0, 1.0),
    ("HomeAngle", 180.0, 1.0),
];

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

fn predicate(brian: &Brian, name: &str) -> FuzzyValue {
    let trace = brian.trace();
    let found = trace.predicates.iter().find(|(n, _)| *n == name);
    found.map(|(_, v)| *v).unwrap_or_else(|| panic!("no predicate {name}"))
}

/// §10.4.2. The manual supposes the fuzzy data
///
/// ```text
/// <TargetDistance, NEAREST, 1, 0.4>
/// <TargetAngle, NORTH_1, 0.9, 0.7>
/// <TargetAngle, NORTH_2, 0, 1>
/// <TargetAngle, WEST, 0.1, 0.7>
/// ```
///
/// which the shapes give for `<TargetDistance, 20, 0.4>` (NEAREST is 1 on [0.1, 40]) and
/// `<TargetAngle, 33, 0.7>` (NORTH_1 falls from 1 at 30 to 0 at 60: 0.9; WEST rises from 0 at
/// 30 to 1 at 60: 0.1) — except NORTH_2: one crisp datum gives every label its reliability
/// (§10.3.1), so NORTH_2 is (0, 0.7), and it is kept in the list since its reliability is not 1
/// (the manual's own rule, §10.4.1). Hence:
///
/// - TargetNearest = (1, 0.4), as printed;
/// - TargetNorth = OR((0.9, 0.7), (0, 0.7)) = (0.9, 0.7). The manual prints (0.9, 1) because
///   its OR takes the maximum reliability with its hand-written NORTH_2 datum (0, 1), which no
///   single TargetAngle reading can produce;
/// - TargetNorthNearest = AND((0.9, ·), (1, 0.4)) = (0.9, 0.4), as printed (the reliability is
///   the minimum, 0.4, whichever TargetNorth's is). The manual's last line also names it
///   `NorthNearest` on the left and `TargetNorth` on the right: both typos.
#[test]
fn predicates_of_10_4_2() {
    let mut brian = Brian::from_dir(data("manual_10_4_2")).unwrap();
    assert!(brian.warnings().is_empty(), "{:?}", brian.warnings());
    let out =
        brian.run(&[("TargetDistance", 20.0, 0.4), ("TargetAngle", 33.0, 0.7), ("Bias", 1.0, 1.0)]);

    let nearest = predicate(&brian, "TargetNearest");
    assert_eq!(nearest, FuzzyValue::new(1.0, 0.4));

    let north = predicate(&brian, "TargetNorth");
    assert!(close(north.value, 0.9), "{north:?}");
    assert!(close(north.reliability, 0.7), "one crisp datum: NORTH_2 is (0, 0.7): {north:?}");
    // The manual's hand-written data: NORTH_2 = (0, 1) gives its (0.9, 1).
    let manual_north = FuzzyValue::new(0.9, 0.7).or(FuzzyValue::new(0.0, 1.0));
    assert_eq!(manual_north, FuzzyValue::new(0.9, 1.0));

    let north_nearest = predicate(&brian, "TargetNorthNearest");
    assert!(close(north_nearest.value, 0.9) && close(north_nearest.reliability, 0.4));
    assert_eq!(manual_north.and(nearest), FuzzyValue::new(0.9, 0.4), "same with the manual's data");

    // Through the rules (§10.3.7): a rule proposes value × reliability = 0.9 × 0.4 = 0.36.
    // `Value` weighs HIGH (1) by 0.9 × 0.4 against LOW (0) by (1 − 0.9) × 0.4: it is 0.9.
    // `Weighted` weighs HIGH by the proposal against LOW by 1 (rule `(Always)`): p / (p + 1).
    let value = out["Value"];
    assert!(close(value, 0.9), "{out:?}");
    let weighted = out["Weighted"];
    let proposal = weighted / (1.0 - weighted);
    assert!(close(proposal, 0.36), "proposal {proposal} from {out:?}");
}

/// A reliable NORTH_2 reading: the same predicates with the target just right of ahead.
#[test]
fn north_wraps_around_through_north_2() {
    let mut brian = Brian::from_dir(data("manual_10_4_2")).unwrap();
    // 327: NORTH_2 rises from 0 at 300 to 1 at 330: 0.9; NORTH_1 is 0 with the same reliability.
    brian.run(&[("TargetDistance", 20.0, 1.0), ("TargetAngle", 327.0, 1.0), ("Bias", 1.0, 1.0)]);
    let north = predicate(&brian, "TargetNorth");
    assert!(close(north.value, 0.9) && north.reliability == 1.0, "{north:?}");
    let nn = predicate(&brian, "TargetNorthNearest");
    assert!(close(nn.value, 0.9) && nn.reliability == 1.0, "{nn:?}");
}

#[test]
fn harvester_loads_without_warnings_and_drives() {
    let mut brian = Brian::from_dir(harvester()).unwrap();
    assert!(brian.warnings().is_empty(), "{:#?}", brian.warnings());
    let inputs: Vec<&str> = brian.input_names().collect();
    for name in [
        "TargetDistance",
        "TargetAngle",
        "HomeDistance",
        "HomeAngle",
        "ObstacleDistance",
        "ObstacleAngle",
        "BatteryLevel",
        "GraspingObject",
        "ProposedSpeedModule",
        "ProposedSpeedAngle",
    ] {
        assert!(inputs.contains(&name), "{name} missing from {inputs:?}");
    }
    assert_eq!(brian.output_names().collect::<Vec<_>>(), ["SpeedModule", "SpeedAngle"]);
    let behaviors: Vec<(&str, i64)> =
        brian.trace().behaviors.iter().map(|(n, l, _)| (*n, *l)).collect();
    assert_eq!(behaviors, [("GoToHome", 1), ("GoToTarget", 1), ("AvoidObstacle", 2)]);

    // §10.4.1's Distance shape, as printed.
    let (_, distance) = brian.input_shapes().find(|(n, _)| *n == "TargetDistance").unwrap();
    assert_eq!(distance.name, "Distance");
    let labels: Vec<&str> = distance.sets.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["NEAREST", "NEAR", "FAR"]);
    // §10.4.6's SPEEDMODULE, as printed.
    let speeds = brian.output_singletons().find(|(n, _)| *n == "SpeedModule").unwrap().1.to_vec();
    let want: Vec<(String, f64)> = [
        ("STEADY", 0.0),
        ("VERY_SLOW", 10.0),
        ("SLOW", 25.0),
        ("FAST", 75.0),
        ("VERY_FAST", 100.0),
    ]
    .iter()
    .map(|(l, v)| ((*l).to_string(), *v))
    .collect();
    assert_eq!(speeds, want);

    // A far target straight ahead, full batteries: FAST (75 cm/s) towards NORTH (0°).
    let out = brian.run(&FAR_TARGET_AHEAD);
    assert!(close(out["SpeedModule"], 75.0) && close(out["SpeedAngle"], 0.0), "{out:?}");
    // §10.4.4's CANDO: a far target with batteries half empty cannot be pursued.
    let out = brian.run(&[
        ("TargetDistance", 300.0, 1.0),
        ("TargetAngle", 0.0, 1.0),
        ("BatteryLevel", 50.0, 1.0),
        ("HomeDistance", 400.0, 1.0),
        ("HomeAngle", 180.0, 1.0),
    ]);
    assert!(out.is_empty(), "nobody wants to move: {out:?}");
    assert_eq!(brian.trace().behaviors[1].0, "GoToTarget");
    assert!(brian.trace().behaviors[1].2.is_none(), "GoToTarget's CANDO is 0");
}

/// Every file of the harvester starts with a comment saying what it is and which manual
/// section it follows.
#[test]
fn harvester_files_say_what_they_are() {
    let dir = harvester();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .chain(std::fs::read_dir(dir.join("behaviors")).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e != "md"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 13, "{files:?}");
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
        assert!(!header.is_empty(), "{} does not start with a comment", f.display());
        let header = header.join("\n");
        assert!(header.contains('§'), "{}: no manual section in {header:?}", f.display());
    }
}

/// Loads `manual_10_4_2` with the files of `tests/data/errors/<case>` put in place.
fn load_broken(case: &str) -> (PathBuf, BrianError) {
    let base = data("manual_10_4_2");
    let over = data("errors").join(case);
    assert!(over.is_dir(), "{}", over.display());
    let pick = |name: &str| {
        let p = over.join(name);
        if p.exists() {
            p
        } else {
            base.join(name)
        }
    };
    let files = BrianFiles {
        shape_ctof: pick("shape_ctof.txt"),
        ctof: pick("ctof.txt"),
        predicates: pick("Predicate.ini"),
        predicate_actions: pick("PredicateActions.ini"),
        cando: pick("Cando.ini"),
        want: pick("want.txt"),
        behaviors: pick("behavior.txt"),
        s_shape: pick("s_shape.txt"),
        s_ftoc: pick("s_ftoc.txt"),
        engine: pick("engine.txt"),
    };
    let root = if over.join("behavior.txt").exists() || over.join("behaviors").exists() {
        over.clone()
    } else {
        base
    };
    let err = Brian::from_files(&files, &root).expect_err(case);
    (over, err)
}

/// Checks the error's place and its exact text: the manual checker's line
/// `error in file <path> at line <l>: <message>`, then `  --> <path>:<l>:<c>`.
fn check(case: &str, file: &str, line: usize, column: usize, message: &str) {
    let (dir, err) = load_broken(case);
    let path = dir.join(file);
    match &err {
        BrianError::At { file: f, line: l, column: c, message: m } => {
            assert_eq!((f, *l, *c, m.as_str()), (&path, line, column, message), "{case}");
        }
        other => panic!("{case}: not an error at a place: {other:?}"),
    }
    assert_eq!(
        err.to_string(),
        format!(
            "error in file {0} at line {line}: {message}\n  --> {0}:{line}:{column}",
            path.display()
        ),
        "{case}"
    );
}

/// The checker example of §10.4.7: a rule without its `;`. At the end of the file the error
/// says so.
#[test]
fn error_rule_missing_semicolon_at_the_end() {
    check(
        "missing_semicolon_last",
        "behaviors/Probe.rul",
        4,
        27,
        "expected `;` at the end of the rule, found end of file",
    );
}

/// Without the `;`, the next rule starts where an action could: a `(` not followed by an action
/// name is the next rule, so the checker asks for the `;` there (the next rule's first token).
#[test]
fn error_rule_missing_semicolon_before_another_rule() {
    check(
        "missing_semicolon_middle",
        "behaviors/Probe.rul",
        3,
        1,
        "expected `;` at the end of the rule, found `(`",
    );
}

#[test]
fn error_unknown_predicate_in_a_rule() {
    check(
        "unknown_predicate",
        "behaviors/Probe.rul",
        4,
        16,
        "unknown predicate `TargetSouthNearest` (predicates must be defined before use)",
    );
}

#[test]
fn error_unknown_label_of_an_action() {
    check(
        "unknown_action_label",
        "behaviors/Probe.rul",
        2,
        48,
        "action `Weighted` has no label `MEDIUM` (labels: LOW, HIGH)",
    );
}

/// An unknown label of a fuzzy datum: the place is the label.
#[test]
fn error_unknown_label_of_a_datum() {
    check(
        "unknown_data_label",
        "Predicate.ini",
        2,
        35,
        "`TargetDistance` (shape `Distance`) has no label `NEARBY` (labels: NEAREST, NEAR, FAR)",
    );
}

/// §10.4.2: "define a predicate before using it into another predicate".
#[test]
fn error_predicate_used_before_its_definition() {
    check(
        "predicate_before_definition",
        "Predicate.ini",
        4,
        30,
        "unknown predicate `TargetNorth` (predicates must be defined before use)",
    );
}

#[test]
fn error_behavior_listed_twice() {
    check("behavior_twice", "behavior.txt", 4, 10, "behavior `Probe` is listed twice");
}

/// `engine.txt` (optional, [`mrt_fuzzy::engine`]) sets the threshold filter of §10.3.6 and the
/// float composer of §10.4.9 from the configuration. The harvester with a far target ahead
/// drives FAST (above); with `threshold_filter 1` no CANDO value can be above the threshold,
/// so no behavior runs and nothing is proposed. A mistake in the file is placed like any
/// other file's.
#[test]
fn engine_txt_sets_the_threshold_and_the_composer() {
    let dir = std::env::temp_dir().join(format!("mrt-engine-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("behaviors")).unwrap();
    for entry in std::fs::read_dir(harvester())
        .unwrap()
        .chain(std::fs::read_dir(harvester().join("behaviors")).unwrap())
    {
        let p = entry.unwrap().path();
        if p.is_file() {
            let rel = p.strip_prefix(harvester()).unwrap();
            std::fs::copy(&p, dir.join(rel)).unwrap();
        }
    }
    let drive = FAR_TARGET_AHEAD;
    let mut brian = Brian::from_dir(&dir).unwrap();
    assert_eq!((brian.threshold(), brian.composer()), (0.49, mrt_fuzzy::brian::Composer::Max));
    assert!(close(brian.run(&drive)["SpeedModule"], 75.0));
    std::fs::write(
        dir.join("engine.txt"),
        "# engine.txt\nthreshold_filter 1\nweight_composer min_weight_composer\nfloat_composer average_float_composer\n",
    )
    .unwrap();
    let mut brian = Brian::from_dir(&dir).unwrap();
    assert_eq!((brian.threshold(), brian.composer()), (1.0, mrt_fuzzy::brian::Composer::Average));
    assert_eq!(brian.weight_composer(), mrt_fuzzy::brian::WeightComposer::Min);
    assert!(brian.run(&drive).is_empty(), "no behavior is above a threshold of 1");
    std::fs::write(dir.join("engine.txt"), "threshold_filter 0.5\nfloat_composer min\n").unwrap();
    let err = Brian::from_dir(&dir).unwrap_err().to_string();
    assert!(err.contains("at line 2:") && err.ends_with("engine.txt:2:16"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
