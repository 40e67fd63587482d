//! Mr. BRIAN cycle time on the configurations `configs/brian/brian40*`: brian40 flat (its 500
//! conformance cycles) and brian40-hier on `cycles-level2-active.jsonl` (the level-2 behavior
//! runs every cycle). One iteration = one full cycle: set the inputs, fuzzify, predicates,
//! behaviors, composition, defuzzification.
//!
//! Run: `cargo bench -p mrt-fuzzy --bench brian`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used, clippy::print_stderr)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_fuzzy::brian::Brian;
use std::path::PathBuf;
use std::time::Duration;

/// One cycle's inputs as (slot, value, reliability).
type Cycle = Vec<(usize, f64, f64)>;

/// Loads a configuration and its cycles.
fn load(dir: &str, cycles: &str) -> Option<(Brian, Vec<Cycle>)> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/brian").join(dir);
    if !d.exists() {
        eprintln!("skipped: {} is absent", d.display());
        return None;
    }
    let brian = Brian::from_dir(&d).unwrap();
    let text = std::fs::read_to_string(d.join(cycles)).unwrap();
    let cycles = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let m: serde_json::Map<String, serde_json::Value> = serde_json::from_str(l).unwrap();
            m.iter()
                .filter_map(|(k, v)| {
                    let slot = brian.input_slot(k)?;
                    Some(match v {
                        serde_json::Value::Array(a) => {
                            (slot, a[0].as_f64()?, a.get(1).and_then(|r| r.as_f64()).unwrap_or(1.0))
                        }
                        other => (slot, other.as_f64()?, 1.0),
                    })
                })
                .collect()
        })
        .collect();
    Some((brian, cycles))
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("brian_cycle");
    for (name, dir, cycles) in [
        ("brian40_flat", "brian40", "cycles.jsonl"),
        ("brian40_hier_all", "brian40-hier", "cycles.jsonl"),
        ("brian40_hier_level2_active", "brian40-hier", "cycles-level2-active.jsonl"),
    ] {
        let Some((mut brian, cycles)) = load(dir, cycles) else { continue };
        let mut i = 0;
        g.bench_function(name, |b| {
            b.iter(|| {
                for &(slot, v, r) in &cycles[i % cycles.len()] {
                    brian.set_input(slot, v, r);
                }
                i += 1;
                brian.step();
                brian.output(0)
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
