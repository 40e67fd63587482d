//! Conformance on the Mr. BRIAN configurations `configs/brian/brian40` (flat) and
//! `brian40-hier` (with a level-2 behavior): every cycle of `cycles.jsonl`, in order, must give
//! the commands of `expected.jsonl` (1e-3, angles modulo 360).

#![allow(clippy::unwrap_used, clippy::print_stderr)]

use mrt_fuzzy::brian::Brian;
use serde_json::{Map, Value};
use std::path::PathBuf;

fn bench_dir(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian").join(name)
}

fn lines(path: PathBuf) -> Vec<Map<String, Value>> {
    std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str::<Map<String, Value>>(l).unwrap())
        .collect()
}

fn inputs(cycle: &Map<String, Value>) -> Vec<(String, f64, f64)> {
    cycle
        .iter()
        .map(|(k, v)| match v {
            Value::Array(a) => {
                (k.clone(), a[0].as_f64().unwrap(), a.get(1).and_then(Value::as_f64).unwrap_or(1.0))
            }
            other => (k.clone(), other.as_f64().unwrap(), 1.0),
        })
        .collect()
}

fn conformance(name: &str) {
    let dir = bench_dir(name);
    let mut brian = Brian::from_dir(&dir).unwrap();
    let cycles = lines(dir.join("cycles.jsonl"));
    let expected = lines(dir.join("expected.jsonl"));
    assert_eq!(cycles.len(), expected.len());
    let mut failures = Vec::new();
    for (i, (cycle, want)) in cycles.iter().zip(&expected).enumerate() {
        let owned = inputs(cycle);
        let args: Vec<(&str, f64, f64)> =
            owned.iter().map(|(k, v, r)| (k.as_str(), *v, *r)).collect();
        let got = brian.run(&args);
        let mut ok = got.len() == want.len();
        for (k, w) in want {
            let w = w.as_f64().unwrap();
            match got.get(k) {
                Some(g) if k.contains("Angle") => {
                    let d = (g - w).rem_euclid(360.0);
                    ok &= d.min(360.0 - d) < 1e-3;
                }
                Some(g) => ok &= (g - w).abs() < 1e-3,
                None => ok = false,
            }
        }
        if !ok {
            failures.push(format!(
                "cycle {i}: inputs {cycle:?}\n  got      {got:?}\n  expected {want:?}"
            ));
        }
    }
    let n = cycles.len();
    assert_eq!(n, 500, "{name}: the data has 500 cycles");
    assert!(
        failures.is_empty(),
        "{name}: {}/{n} cycles differ; first ones:\n{}",
        failures.len(),
        failures[..failures.len().min(5)].join("\n")
    );
}

#[test]
fn brian40_flat_matches_every_cycle() {
    conformance("brian40");
}

#[test]
fn brian40_hierarchical_matches_every_cycle() {
    conformance("brian40-hier");
}
