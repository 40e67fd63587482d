//! What several test files share.

#![allow(clippy::unwrap_used, dead_code)]

use std::path::Path;

/// A Mr. BRIAN configuration of one behavior (`Go`: slow when near, fast when far).
pub const ONE_BEHAVIOR: [(&str, &str); 9] = [
    ("shape_ctof.txt", "(Dist (TOL (NEAR 10 20)) (TOR (FAR 10 20)))"),
    ("ctof.txt", "(D Dist)"),
    ("Predicate.ini", "Near = (D D NEAR);\nFar = (D D FAR);"),
    ("Cando.ini", "Go = (OR (P Near) (P Far));"),
    ("want.txt", "Go = (OR (P Near) (P Far));"),
    ("behavior.txt", "(level 1 Go behaviors/Go.rul)"),
    ("behaviors/Go.rul", "(Near) => (Speed SLOW);\n(Far) => (Speed FAST);"),
    ("s_shape.txt", "(SPEED (SNG (SLOW 10)) (SNG (FAST 100)))"),
    ("s_ftoc.txt", "(Speed SPEED)"),
];

/// Writes [`ONE_BEHAVIOR`] into `dir` (created).
pub fn write_one_behavior(dir: &Path) {
    std::fs::create_dir_all(dir.join("behaviors")).unwrap();
    for (f, t) in ONE_BEHAVIOR {
        std::fs::write(dir.join(f), t).unwrap();
    }
}
