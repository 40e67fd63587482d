//! Facts the message catalogue defines are defined nowhere else: no crate of the workspace
//! declares a camera sighting index of its own (they are `mrt_msgs::sighting`'s).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
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

#[test]
fn sighting_indices_are_declared_only_in_the_catalogue() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let names = [
        "BALL",
        "EAST_NET",
        "WEST_NET",
        "NE_CORNER",
        "SE_CORNER",
        "NW_CORNER",
        "SW_CORNER",
        "NORTH_HALFWAY",
        "SOUTH_HALFWAY",
    ];
    let mut files = Vec::new();
    for krate in std::fs::read_dir(&crates).unwrap().flatten() {
        if krate.file_name() != "mrt-msgs" {
            sources(&krate.path(), &mut files);
        }
    }
    assert!(files.len() > 50, "the workspace's sources were not found under {crates:?}");
    let mut found = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim_start();
            let declared = names.iter().any(|name| {
                ["const ", "pub const ", "pub(crate) const "]
                    .iter()
                    .any(|p| line.starts_with(&format!("{p}{name}: usize")))
            });
            if declared {
                found.push(format!("{}:{}: {line}", file.display(), n + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "sighting indices declared outside mrt_msgs::sighting:\n{}",
        found.join("\n")
    );
}
