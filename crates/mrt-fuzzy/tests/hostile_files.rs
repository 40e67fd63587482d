//! What `mrt brian check` did with hostile or huge Mr. BRIAN files.
//!
//! - Invalid UTF-8 was reported as an OS error without a place: it is now an error at the line
//!   and column of the first invalid byte.
//! - Checking definitions was quadratic (every name was looked up by scanning the names defined
//!   before it): 40 000 definitions took 1.9 s, 200 000 never finished. Every table is now a
//!   hash map; the test loads 200 000 predicates, 200 000 behaviors and their 400 000 CANDO and
//!   WANT definitions, which the quadratic checker could not.
//! - `behavior.txt` could name any file of the machine as a rule file, and the parse error
//!   printed that file's first token. Rule files must now lie (after following links) inside the
//!   configuration directory; otherwise the error names the path as written in `behavior.txt`
//!   and nothing of the file.
//! - `(level 99999999999999999999 ...)` was read as `i64::MAX`; numbers whose differences
//!   overflow (fuzzy set sides, output singletons) gave NaN or infinite commands. All are
//!   errors with file, line and column now.

#![allow(clippy::unwrap_used)]

mod common;

use mrt_fuzzy::brian::{Brian, MAX_LEVEL};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A fresh configuration directory (unique per test) with a one-behavior configuration.
fn config(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("mrt-fuzzy-issue17-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    common::write_one_behavior(&d);
    d
}

fn error(dir: &Path) -> String {
    Brian::from_dir(dir).unwrap_err().to_string()
}

#[test]
fn invalid_utf8_is_reported_at_its_line_and_column() {
    let dir = config("utf8");
    std::fs::write(dir.join("Predicate.ini"), b"Near = (D D NEAR);\nFar = (D D \xFFFAR);").unwrap();
    let e = error(&dir);
    let file = dir.join("Predicate.ini");
    assert_eq!(
        e,
        format!(
            "error in file {0} at line 2: invalid UTF-8 (byte 0xFF): Mr. BRIAN files are UTF-8 \
             text\n  --> {0}:2:12",
            file.display()
        )
    );
    // In a rule file too, named as behavior.txt names it.
    std::fs::write(dir.join("Predicate.ini"), "Near = (D D NEAR);\nFar = (D D FAR);").unwrap();
    std::fs::write(dir.join("behaviors/Go.rul"), b"(Near) => (Speed SLOW);\n\n  \xC0").unwrap();
    let e = error(&dir);
    assert!(e.contains("Go.rul at line 3: invalid UTF-8 (byte 0xC0)"), "{e}");
    assert!(e.ends_with("behaviors/Go.rul:3:3"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// 200 000 predicates (each using the one before) and 20 000 behaviors sharing one rule file,
/// each with a CANDO and a WANT: 260 000 definitions. The quadratic checker needed about
/// 2·10¹⁰ name comparisons for the predicates alone; this loads in about a second in a debug
/// build.
#[test]
fn two_hundred_thousand_definitions_load_in_linear_time() {
    const N: usize = 200_000;
    const BEHAVIORS: usize = 20_000;
    let dir = config("linear");
    let mut preds = String::from("Near = (D D NEAR);\nFar = (D D FAR);\nP0 = (P Near);\n");
    for i in 1..N {
        writeln!(preds, "P{i} = (OR (P P{}) (D D FAR));", i - 1).unwrap();
    }
    std::fs::write(dir.join("Predicate.ini"), preds).unwrap();
    let (mut list, mut cando, mut want) = (String::new(), String::new(), String::new());
    // The last predicate is the WANT of every behavior, so that every predicate is used.
    for i in 0..BEHAVIORS {
        writeln!(list, "(level {} B{i} behaviors/Go.rul)", 1 + i % 3).unwrap();
        writeln!(cando, "B{i} = (P P{});", i * (N / BEHAVIORS)).unwrap();
        writeln!(want, "B{i} = (P P{});", N - 1).unwrap();
    }
    std::fs::write(dir.join("behavior.txt"), list).unwrap();
    std::fs::write(dir.join("Cando.ini"), cando).unwrap();
    std::fs::write(dir.join("want.txt"), want).unwrap();
    let mut b = Brian::from_dir(&dir).unwrap();
    // Every predicate is used (by the next one, a CANDO or a WANT, or Go.rul): no warnings.
    assert!(b.warnings().is_empty(), "{:?}", &b.warnings()[..b.warnings().len().min(3)]);
    assert_eq!(b.run(&[("D", 5.0, 1.0)]).get("Speed"), Some(&10.0));

    // A duplicate at the very end is still found, with the line of the first definition.
    let mut preds = std::fs::read_to_string(dir.join("Predicate.ini")).unwrap();
    preds.push_str("P17 = (D D FAR);\n");
    std::fs::write(dir.join("Predicate.ini"), preds).unwrap();
    let e = error(&dir);
    assert!(e.contains(&format!("at line {}: `P17` is already defined at line 20", N + 3)), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn rule_files_outside_the_configuration_directory_are_refused_without_their_content() {
    let dir = config("outside");
    let outside =
        std::env::temp_dir().join(format!("mrt-fuzzy-issue17-secret-{}", std::process::id()));
    std::fs::write(&outside, "TOP-SECRET-TOKEN and more").unwrap();
    let cases = [
        outside.display().to_string(),
        format!("../{}", outside.file_name().unwrap().to_str().unwrap()),
        "behaviors/../../etc/passwd".to_string(),
    ];
    for path in &cases {
        std::fs::write(dir.join("behavior.txt"), format!("(level 1 Go {path})")).unwrap();
        let e = error(&dir);
        assert!(!e.contains("TOP-SECRET") && !e.contains("root:"), "{e}");
        assert!(e.contains("behavior.txt at line 1:"), "{e}");
        assert!(e.contains(&format!("the rule file `{path}` of behavior `Go`")), "{e}");
        assert!(
            e.contains("outside the configuration directory") || e.contains("cannot open"),
            "{e}"
        );
        assert!(e.ends_with("behavior.txt:1:13"), "{e}");
    }
    // A link inside the directory to a file outside is outside too.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(&outside, dir.join("behaviors/link.rul")).unwrap();
        std::fs::write(dir.join("behavior.txt"), "(level 1 Go behaviors/link.rul)").unwrap();
        let e = error(&dir);
        assert!(
            !e.contains("TOP-SECRET") && e.contains("outside the configuration directory"),
            "{e}"
        );
    }
    // A missing file: an error at the path, not an OS error without a place.
    std::fs::write(dir.join("behavior.txt"), "(level 1 Go behaviors/None.rul)").unwrap();
    let e = error(&dir);
    assert!(
        e.contains("cannot open the rule file `behaviors/None.rul`") && e.ends_with(":1:13"),
        "{e}"
    );
    // Inside, through `..` that comes back in: fine.
    std::fs::write(dir.join("behavior.txt"), "(level 1 Go behaviors/../behaviors/Go.rul)").unwrap();
    Brian::from_dir(&dir).unwrap();
    std::fs::remove_file(&outside).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn numbers_out_of_range_are_errors_with_their_place() {
    let dir = config("numbers");
    for (level, ok) in [
        ("99999999999999999999".to_string(), false),
        ((MAX_LEVEL + 1).to_string(), false),
        (MAX_LEVEL.to_string(), true),
        ("0".to_string(), false),
        ("2.5".to_string(), false),
    ] {
        std::fs::write(dir.join("behavior.txt"), format!("(level {level} Go behaviors/Go.rul)"))
            .unwrap();
        match Brian::from_dir(&dir) {
            Ok(_) => assert!(ok, "level {level} accepted"),
            Err(e) => {
                let e = e.to_string();
                assert!(!ok, "level {level}: {e}");
                assert!(
                    e.contains(&format!("the level must be a whole number from 1 to {MAX_LEVEL}")),
                    "{e}"
                );
                assert!(e.ends_with("behavior.txt:1:8"), "{e}");
            }
        }
    }
    std::fs::write(dir.join("behavior.txt"), "(level 1 Go behaviors/Go.rul)").unwrap();
    // A fuzzy set whose sides overflow to ∞ would give NaN memberships.
    let huge = format!("1{}", "0".repeat(307)); // 1e307
    std::fs::write(
        dir.join("shape_ctof.txt"),
        format!("(Dist (TOL (NEAR 10 20))\n (TOR (FAR -{huge}0 {huge}0)))"),
    )
    .unwrap();
    let e = error(&dir);
    assert!(e.contains("at line 2: the values of TOR `FAR` are too far apart"), "{e}");
    assert!(e.ends_with("shape_ctof.txt:2:8"), "{e}");
    std::fs::write(dir.join("shape_ctof.txt"), "(Dist (TOL (NEAR 10 20)) (TOR (FAR 10 20)))")
        .unwrap();
    // Output singletons whose weighted sum overflows would give an infinite command.
    std::fs::write(
        dir.join("s_shape.txt"),
        format!("(SPEED (SNG (SLOW {huge}0)) (SNG (FAST {huge}0)))"),
    )
    .unwrap();
    let e = error(&dir);
    assert!(e.contains("the singletons of output shape `SPEED` are too large"), "{e}");
    assert!(e.ends_with("s_shape.txt:1:2"), "{e}");
    // A number too large for an f64 at all.
    std::fs::write(dir.join("s_shape.txt"), format!("(SPEED (SNG (SLOW 1{huge}00)))")).unwrap();
    let e = error(&dir);
    assert!(e.contains("is too large for a number") && e.ends_with("s_shape.txt:1:19"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
