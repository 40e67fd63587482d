//! The simulator's files import each other in one direction: config → world →
//! referee → sensor → game → metrics, sensor → indoor, drivers → devices → bus → remote, plot,
//! soak, survey. A module (`src/x.rs` and the files under `src/x/`) that names `crate::y`
//! depends on `y`; this test fails on any import circle, with the circle.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::Path;

/// Each top-level module's files: `src/x.rs` and everything under `src/x/`.
fn module_texts(src: &Path) -> BTreeMap<String, String> {
    let mut texts: BTreeMap<String, String> = BTreeMap::new();
    let mut dirs = vec![src.to_path_buf()];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(src).unwrap();
            let top = relative.components().next().unwrap().as_os_str().to_string_lossy();
            let name = top.trim_end_matches(".rs").to_string();
            if name == "lib" {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            texts.entry(name).or_default().push_str(&text);
        }
    }
    texts
}

fn imports() -> BTreeMap<String, Vec<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut graph = BTreeMap::new();
    for (name, text) in module_texts(&src) {
        let mut deps: Vec<String> = text
            .match_indices("crate::")
            .map(|(i, _)| {
                text[i + 7..].chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect()
            })
            .filter(|d: &String| !d.is_empty() && *d != name)
            .collect();
        deps.sort();
        deps.dedup();
        graph.insert(name, deps);
    }
    graph
}

/// A circle through `node`, if any (depth-first search).
fn circle(
    graph: &BTreeMap<String, Vec<String>>,
    node: &str,
    path: &mut Vec<String>,
) -> Option<Vec<String>> {
    if let Some(i) = path.iter().position(|n| n == node) {
        let mut c = path[i..].to_vec();
        c.push(node.to_string());
        return Some(c);
    }
    path.push(node.to_string());
    for d in graph.get(node).into_iter().flatten() {
        if let Some(c) = circle(graph, d, path) {
            return Some(c);
        }
    }
    path.pop();
    None
}

#[test]
fn the_simulators_files_import_each_other_in_one_direction() {
    let graph = imports();
    assert!(graph.contains_key("game") && graph.contains_key("bus"), "{graph:?}");
    for node in graph.keys() {
        if let Some(c) = circle(&graph, node, &mut Vec::new()) {
            panic!("import circle: {}", c.join(" → "));
        }
    }
    // The world knows nothing of the match; the pitch nothing of the robots' wiring.
    assert!(graph["world"].iter().all(|d| d == "config"), "{:?}", graph["world"]);
    assert!(!graph["game"].contains(&"bus".to_string()), "{:?}", graph["game"]);
}
