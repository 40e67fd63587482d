//! Units are converted in one place: outside `mrt_core::frames` (its `MM_PER_M` and `MS_PER_S`,
//! and `metres`, `millimetres`, `millis`, `seconds_from_millis`, `pose_in_metres`, ...) no
//! source, test, benchmark or example of the workspace multiplies or divides by a literal
//! thousand (`x * 1000.0`, `x / 1e3`, `1000.0 * x`) or declares an `f64` of `1000.0`. A
//! thousand millimetres as a distance (`Pose2::new(1000.0, 0.0, 0.0)`) is not a conversion and
//! is not matched; a distance that looks like one would be listed in [`DISTANCES`]. A factor
//! that is not a unit's (three decimals of a rounding) is a named constant written `1e3`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

/// Lines the matcher flags that are distances in the millimetre world, not conversions:
/// (file from the workspace root, the line's trimmed text).
const DISTANCES: &[(&str, &str)] = &[];

/// The files that convert: the helpers themselves, and this test's own examples.
const EXEMPT: [&str; 2] =
    ["crates/mrt-core/src/frames.rs", "crates/mrt-core/tests/unit_literals.rs"];

/// Every `.rs` file under `dir` (none when `dir` does not exist).
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether a numeric literal, as written, is a thousand: `1000`, `1000.0`, `1_000`, `1e3`,
/// `1000u64`, ...
fn is_thousand(literal: &str) -> bool {
    let digits: String = literal.chars().filter(|&c| c != '_').collect();
    let suffixes = [
        "f32", "f64", "u8", "u16", "u32", "u64", "u128", "usize", "i8", "i16", "i32", "i64",
        "i128", "isize",
    ];
    let bare = suffixes.iter().find_map(|s| digits.strip_suffix(s)).unwrap_or(&digits);
    bare.parse::<f64>() == Ok(1000.0)
}

/// The numeric literals of `code` with their byte ranges.
fn literals(code: &str) -> Vec<(usize, usize)> {
    let bytes = code.as_bytes();
    let ident = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts =
            bytes[i].is_ascii_digit() && (i == 0 || !(ident(bytes[i - 1]) || bytes[i - 1] == b'.'));
        if !starts {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() {
            let b = bytes[i];
            let next = bytes.get(i + 1).copied();
            let exponent_sign = (b == b'+' || b == b'-')
                && matches!(bytes[i - 1], b'e' | b'E')
                && !code[start..i].starts_with("0x")
                && next.is_some_and(|n| n.is_ascii_digit());
            // `1000.0` and `1000.` are one literal; `1000.max(x)` and `0..1000` are not.
            let point = b == b'.'
                && !code[start..i].contains('.')
                && next.is_none_or(|n| n.is_ascii_digit() || !(ident(n) || n == b'.'));
            if ident(b) || exponent_sign || point {
                i += 1;
            } else {
                break;
            }
        }
        found.push((start, i));
    }
    found
}

/// Whether a line of code (its comment removed) multiplies or divides by a literal thousand,
/// or declares an `f64` of one.
fn converts(code: &str) -> bool {
    literals(code).into_iter().any(|(start, end)| {
        if !is_thousand(&code[start..end]) {
            return false;
        }
        let before = code[..start].trim_end();
        let before = before.strip_suffix('-').unwrap_or(before).trim_end();
        let scaled = before.ends_with('*')
            || before.ends_with('/')
            || before.ends_with("*=")
            || before.ends_with("/=");
        let scales = code[end..].trim_start().starts_with('*');
        let squeezed: String = before.chars().filter(|c| !c.is_whitespace()).collect();
        let declared = (squeezed.ends_with(":f64=") || squeezed.ends_with(":f32="))
            && !code[start..end].contains(['e', 'E']);
        scaled || scales || declared
    })
}

/// A line without its `//` comment.
fn code_of(line: &str) -> &str {
    line.find("//").map_or(line, |at| &line[..at])
}

#[test]
fn the_matcher_sees_every_spelling_of_a_thousand() {
    for line in [
        "let m = mm / 1000.0;",
        "let m = mm/1000.;",
        "let mm = m * 1_000.0;",
        "let mm = m * 1e3;",
        "x *= 1000.0;",
        "let ns = us * 1_000;",
        "let mm = 1000.0 * m;",
        "let mm = 1e3*m;",
        "let period = 1000 * MS;",
        "let y = x * -1000.0;",
        "const MM: f64 = 1000.0;",
        "pub const MM : f64 = 1_000.0;",
        "let k: f64 = 1000.0;",
        "let mm = m * 1000f64;",
    ] {
        assert!(converts(line), "not matched: {line}");
    }
    for line in [
        "Pose2::new(1000.0, 0.0, 0.0)",
        "goal_half_width: 1000.0,",
        "ahead.min(1000.0)",
        "for _ in 0..1000 {",
        "let ns = ms * 1_000_000;",
        "let s = n as f64 * 1e-9;",
        "let x = y * 10000.0;",
        "let x = y * 100.0;",
        "let x = w.1000 * 2.0;",
        "let k = (1000.0 / d).min(1.0);",
        "const DECIMALS: f64 = 1e3;",
        "let x = 1000.0 - 4000.0;",
    ] {
        assert!(!converts(line), "matched: {line}");
    }
    assert_eq!(code_of("let m = x; // x / 1000.0"), "let m = x; ");
    assert!(!converts(code_of("/// `x / 1000.0` in metres")));
}

#[test]
fn no_source_converts_units_with_a_literal_thousand() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    if let Ok(crates) = std::fs::read_dir(root.join("crates")) {
        for krate in crates.flatten() {
            for dir in ["src", "tests", "benches"] {
                sources(&krate.path().join(dir), &mut files);
            }
        }
    }
    sources(&root.join("examples"), &mut files);
    let relative = |file: &Path| file.strip_prefix(&root).unwrap_or(file).to_path_buf();
    assert!(
        files.iter().any(|f| relative(f) == Path::new("crates/mrt-core/src/lib.rs")),
        "the workspace's sources were not found under {root:?}"
    );
    let mut found = Vec::new();
    let mut allowed = vec![false; DISTANCES.len()];
    for file in &files {
        let rel = relative(file);
        if EXEMPT.iter().any(|e| rel == Path::new(e)) {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let code = code_of(line);
            if !converts(code) {
                continue;
            }
            let distance =
                DISTANCES.iter().position(|(f, l)| rel == Path::new(f) && line.trim() == *l);
            match distance {
                Some(k) => allowed[k] = true,
                None => found.push(format!("{}:{}: {}", rel.display(), n + 1, line.trim())),
            }
        }
    }
    assert!(
        found.is_empty(),
        "a literal thousand converts units outside mrt_core::frames; use its helpers \
         (metres, millimetres, point_in_metres, pose_in_metres, millis, seconds_from_millis, \
         MM_PER_M, MS_PER_S, ...) or, for a factor that is not a unit's, a named constant:\n{}",
        found.join("\n")
    );
    let stale: Vec<_> = DISTANCES
        .iter()
        .zip(&allowed)
        .filter(|((file, _), seen)| !**seen && root.join(file).exists())
        .map(|((file, line), _)| format!("{file}: {line}"))
        .collect();
    assert!(stale.is_empty(), "DISTANCES lists lines no longer there:\n{}", stale.join("\n"));
}
