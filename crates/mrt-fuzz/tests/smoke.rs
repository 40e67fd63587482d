//! The short fuzzing run of the test suite: every target for a few thousand executions from a
//! fixed seed must not panic, and the engine itself counts, locates, saves and replays a
//! panic, the same way every time, leaving no file behind when nothing fails.

#![allow(clippy::unwrap_used)]

use mrt_fuzz::engine::{reproduce, run, slot_of_saved, Fuzzer, RunOptions};
use mrt_fuzz::targets::{default_root, find, Harness, Seed, Target, TARGETS};
use std::path::PathBuf;

/// Executions per target: a few seconds in a debug build for the slowest (Mr. BRIAN).
const EXECS: u64 = 2500;

fn smoke(name: &str) {
    let target = find(name).unwrap();
    let report = run(target, &RunOptions::new(default_root(), EXECS, 17)).unwrap();
    assert_eq!(report.execs, EXECS);
    assert!(report.clean(), "{name}: {:#?}", report.sites);
    assert!(report.accepted > 0, "{name}: no input got past the parser");
}

macro_rules! smoke_tests {
    ($($test:ident => $name:literal),* $(,)?) => {
        $(#[test] fn $test() { smoke($name); })*

        #[test]
        fn every_target_has_a_smoke_test() {
            let tested = [$($name),*];
            for t in TARGETS {
                assert!(tested.contains(&t.name), "no smoke test for {}", t.name);
            }
        }
    };
}

smoke_tests! {
    dcdt_config => "dcdt-config",
    wire => "wire",
    xml => "xml",
    brian => "brian",
    sim_config => "sim-config",
    robot_file => "robot-file",
    vision_files => "vision-files",
    plan_map => "plan-map",
    mice_log => "mice-log",
    bb_config => "bb-config",
    relay_line => "relay-line",
    lua_script => "lua-script",
    hbm => "hbm",
    hfsm => "hfsm",
    world => "world",
    mcap => "mcap",
    devices => "devices",
    device_answers => "device-answers",
}

/// A harness that panics on inputs holding `!`, and allocates 300 MiB on inputs holding `@`.
struct Picky;

impl Harness for Picky {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        if input.contains(&b'!') {
            panic!("a bang");
        }
        if input.contains(&b'@') {
            // Zeroed: the pages are never touched, only counted.
            let v = std::hint::black_box(vec![0u8; 300 << 20]);
            assert_eq!(v.len(), 300 << 20);
        }
        true
    }
}

static PICKY: Target = Target {
    name: "picky",
    about: "panics on !",
    keywords: &["!"],
    structured: None,
    seeds: |_| Ok(vec![Seed::new("a/b.txt", "hello world 12"), Seed::new("c", "x y")]),
    harness: |_| Ok(Box::new(Picky)),
};

struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn panics_are_counted_located_saved_and_replayed_the_same_every_time() {
    let dir = TempDir(std::env::temp_dir().join(format!("mrt-fuzz-test-{}", std::process::id())));
    let opts = RunOptions { crash_dir: Some(dir.0.clone()), ..RunOptions::new(".", 3000, 5) };
    let a = run(&PICKY, &opts).unwrap();
    let b = run(&PICKY, &RunOptions::new(".", 3000, 5)).unwrap();
    assert!(a.panics > 0 && a.big_allocations > 0, "{a:?}");
    assert_eq!(
        (a.panics, a.big_allocations, a.accepted),
        (b.panics, b.big_allocations, b.accepted)
    );
    assert_eq!(a.sites.len(), 2, "{:?}", a.sites);
    let (site, first) = a.sites.iter().find(|(s, _)| s.as_str() != "allocation").unwrap();
    assert!(site.contains("smoke.rs"), "{site}");
    assert_eq!(first.message, "a bang");
    assert!(first.reproduces_alone);
    assert_eq!(a.saved.len() as u64, a.panics + a.big_allocations);
    assert!(b.saved.is_empty(), "nothing saved without a crash directory");

    // A saved input names its slot, replays alone, and is input k of the run.
    let saved = a.saved.iter().find(|p| std::fs::read(p).unwrap().contains(&b'!')).unwrap();
    let slot = slot_of_saved(saved).unwrap();
    let bytes = std::fs::read(saved).unwrap();
    let (site_again, _) = reproduce(&PICKY, ".".as_ref(), &slot, bytes.clone()).unwrap().unwrap();
    assert_eq!(&site_again, site);
    let name = saved.file_name().unwrap().to_str().unwrap();
    let k: u64 = name.rsplit("-e").next().unwrap().trim_end_matches(".bin").parse().unwrap();
    let fuzzer = Fuzzer::new(&PICKY, ".".as_ref(), 5, 64 << 10).unwrap();
    assert_eq!(fuzzer.input(k).1, bytes);

    // A later part of the run on its own finds the same inputs.
    let part = run(&PICKY, &RunOptions { start: 1000, ..RunOptions::new(".", 2000, 5) }).unwrap();
    let rest = run(&PICKY, &RunOptions { start: 0, ..RunOptions::new(".", 1000, 5) }).unwrap();
    assert_eq!(part.panics + rest.panics, a.panics);
}
