//! No module of a workspace crate imports a module that imports it back, directly or through
//! others. Each crate under `crates/` is read as a graph of its top-level modules: module `x`
//! (`src/x.rs` and every file under `src/x/`) depends on `y` when one of its lines that is not
//! a comment (`//`, `///`, `//!`: doc links such as [`crate::y::Z`] are not imports) names
//! `crate::y`, also inside a group (`crate::{y::Z, w}`). The crate root (`lib.rs`, `main.rs`)
//! is not a module of the graph, nor are the binaries of `src/bin/` (crates of their own).
//! The test fails listing every circle, as `crate: a → b → a`.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level module → the modules it names.
type Graph = BTreeMap<String, BTreeSet<String>>;

/// The workspace's root (this crate is `crates/mrt-core`).
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every crate of `crates/` that has a `src/`, by name, with its `src/`.
fn crates() -> BTreeMap<String, PathBuf> {
    let mut out = BTreeMap::new();
    for entry in std::fs::read_dir(root().join("crates")).unwrap().flatten() {
        let src = entry.path().join("src");
        if src.is_dir() {
            out.insert(entry.file_name().to_string_lossy().into_owned(), src);
        }
    }
    out
}

/// Every `.rs` file under `dir`.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The text of `file` without its comment lines.
fn code(file: &Path) -> String {
    let text = std::fs::read_to_string(file).unwrap();
    text.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n")
}

/// The leading identifier of `s`.
fn ident(s: &str) -> String {
    s.trim_start().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect()
}

/// The first path segment of every `crate::` path of `code`: `crate::a::B` gives `a`,
/// `crate::{a::B, c}` gives `a` and `c`.
fn crate_paths(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    for (i, _) in code.match_indices("crate::") {
        // `crate::`, `$crate::`, not `other_crate::`.
        if code[..i].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_') {
            continue;
        }
        let rest = &code[i + "crate::".len()..];
        let Some(group) = rest.strip_prefix('{') else {
            out.push(ident(rest));
            continue;
        };
        // The group's items at depth 0, up to its closing brace.
        let (mut depth, mut start) = (0usize, 0usize);
        for (k, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    out.push(ident(&group[start..k]));
                    break;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    out.push(ident(&group[start..k]));
                    start = k + 1;
                }
                _ => {}
            }
        }
    }
    out.retain(|s| !s.is_empty());
    out
}

/// The module graph of the crate whose sources are in `src`.
fn graph(src: &Path) -> Graph {
    let mut files = Vec::new();
    sources(src, &mut files);
    let mut graph = Graph::new();
    for file in files {
        let relative = file.strip_prefix(src).unwrap();
        let top = relative.components().next().unwrap().as_os_str().to_string_lossy();
        let name = top.trim_end_matches(".rs").to_string();
        if ["lib", "main", "bin"].contains(&name.as_str()) {
            continue;
        }
        let deps = graph.entry(name.clone()).or_default();
        deps.extend(crate_paths(&code(&file)).into_iter().filter(|d| *d != name));
    }
    // Only modules are nodes: `crate::Foo` and `crate::prelude` name the root's items.
    let modules: BTreeSet<String> = graph.keys().cloned().collect();
    graph.values_mut().for_each(|deps| deps.retain(|d| modules.contains(d)));
    graph
}

/// Every elementary circle of `graph`, each once: started at its smallest module.
fn circles(graph: &Graph) -> Vec<Vec<String>> {
    fn walk(graph: &Graph, start: &str, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
        let last = path.last().cloned().unwrap();
        for next in &graph[&last] {
            if next == start {
                let mut circle = path.clone();
                circle.push(start.to_string());
                out.push(circle);
            } else if next.as_str() > start && !path.contains(next) {
                path.push(next.clone());
                walk(graph, start, path, out);
                path.pop();
            }
        }
    }
    let mut out = Vec::new();
    for start in graph.keys() {
        walk(graph, start, &mut vec![start.clone()], &mut out);
    }
    out
}

#[test]
fn no_module_imports_a_module_that_imports_it_back() {
    let crates = crates();
    assert!(crates.contains_key("mrt-core") && crates.len() > 10, "crates not found: {crates:?}");
    let graphs: BTreeMap<&String, Graph> = crates.iter().map(|(n, src)| (n, graph(src))).collect();
    let imports: usize = graphs.values().flat_map(|g| g.values()).map(BTreeSet::len).sum();
    assert!(imports > 100, "the scanner found only {imports} imports: {graphs:?}");
    let mut found = Vec::new();
    for (name, graph) in &graphs {
        for circle in circles(graph) {
            found.push(format!("{name}: {}", circle.join(" → ")));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

#[test]
fn the_scanner_reads_paths_and_groups_and_skips_comments() {
    assert_eq!(crate_paths("use crate::a::B;\nlet x = crate::c::f();"), ["a", "c"]);
    assert_eq!(crate_paths("use crate::{a::{B, C}, d, E};"), ["a", "d", "E"]);
    assert_eq!(crate_paths("use $crate::m::f;"), ["m"]);
    assert!(crate_paths("use other_crate::m;").is_empty());
    let mut g = Graph::new();
    for (a, b) in [("a", "b"), ("b", "c"), ("c", "a"), ("b", "a"), ("c", "d")] {
        g.entry(a.into()).or_default().insert(b.into());
        g.entry(b.into()).or_default();
    }
    assert_eq!(circles(&g), [vec!["a", "b", "a"], vec!["a", "b", "c", "a"]]);
    let dir = std::env::temp_dir().join(format!("mrt-layers-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("x")).unwrap();
    std::fs::write(dir.join("lib.rs"), "mod x; mod y;").unwrap();
    std::fs::write(dir.join("x/inner.rs"), "/// [`crate::y::Z`]\nuse crate::y::W;").unwrap();
    std::fs::write(dir.join("y.rs"), "//! See [`crate::x`].\npub struct W;").unwrap();
    let g = graph(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(g.len(), 2, "{g:?}");
    assert_eq!(g["x"].iter().collect::<Vec<_>>(), ["y"]);
    assert!(g["y"].is_empty(), "a doc link is not an import: {g:?}");
}
