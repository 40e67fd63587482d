//! ThinkingCap behaviors: one HFSM cycle of the seed's Attacker (goal ≤ 2 µs), a full robot
//! cycle (Attacker HFSM + the fuzzy go2ball it selects), a fuzzy HBM behavior alone, and the
//! time from a file change on disk to the new version running (goal ≤ 5 ms, 300 lines),
//! through the `notify` watcher.
//!
//! Run: `cargo bench -p mrt-script --bench behaviors`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use mrt_core::Time;
use mrt_msgs::robot::{lps, Lpo, WorldSnapshot};
use mrt_script::chaos::{self, RobotIo};
use mrt_script::hfsm::Hfsm;
use mrt_script::{LuaRuntime, Sandbox, ThinkingCap};
use std::cell::RefCell;
use std::fmt::Write as _;
use std::rc::Rc;
use std::time::{Duration, Instant};

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../behaviors/teamchaos");

/// The ball 2 m ahead, the opponent's net far behind it: the Attacker sits in GoToBall.
fn world() -> WorldSnapshot {
    let mut w = WorldSnapshot { time: Time::from_millis(100), ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: 2.0, theta: 0.05, reliability: 0.9, seen_ago: 0.0 };
    w.lps[lps::NET1] = Lpo { rho: 6.0, theta: 0.1, reliability: 0.8, seen_ago: 0.0 };
    w.my_pos.quality = 0.9;
    w
}

fn bench(c: &mut Criterion) {
    // HFSM step alone: transitions of Attacker (and Score when inside) + the state's code.
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    chaos::install(&rt, io.clone()).unwrap();
    let mut hfsm = Hfsm::from_file(&rt, format!("{DIR}/attacker.hfsm.lua"), io.clone()).unwrap();
    io.borrow_mut().new_cycle(world());
    hfsm.step(&rt).unwrap();
    hfsm.step(&rt).unwrap();
    assert_eq!(hfsm.path(), "Attacker/GoToBall");
    let w = world();
    // The world snapshot is built outside the timed part (the world model's work); the swap
    // into the robot io is timed.
    c.bench_function("hfsm_cycle_attacker", |b| {
        b.iter_batched(
            || w.clone(),
            |w| {
                io.borrow_mut().new_cycle(w);
                hfsm.step(&rt).unwrap()
            },
            BatchSize::SmallInput,
        )
    });

    // A full cycle: HFSM, then the fuzzy go2ball it selected (rules, blending, centroid).
    let mut cap =
        ThinkingCap::with_hfsm(DIR, format!("{DIR}/attacker.hfsm.lua"), Sandbox::default())
            .unwrap();
    cap.cycle(world());
    assert_eq!(cap.cycle(world()).behavior.as_deref(), Some("go2ball"));
    c.bench_function("robot_cycle_attacker_go2ball", |b| {
        b.iter_batched(|| w.clone(), |w| cap.cycle(w), BatchSize::SmallInput)
    });

    let mut gk = ThinkingCap::with_behavior(DIR, "gkcutb", Sandbox::default()).unwrap();
    c.bench_function("hbm_cycle_gkcutb", |b| {
        b.iter_batched(|| w.clone(), |w| gk.cycle(w), BatchSize::SmallInput)
    });

    // From a file change on disk to the new version running: write the file, then run cycles
    // until the watcher has delivered the change and the new version answered.
    let dir = std::env::temp_dir().join(format!("mrt-behaviors-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let body = |k: u64| {
        let mut s = String::new();
        for i in 0..99 {
            let _ = writeln!(s, "local function f{i}(x)\n  return x * {i} + 1\nend");
        }
        let _ = writeln!(s, "chaos.setVlin({k})");
        s
    };
    let path = dir.join("edited.lua");
    std::fs::write(&path, body(0)).unwrap();
    let mut cap = ThinkingCap::with_behavior(&dir, "edited", Sandbox::default()).unwrap();
    cap.watch(&dir).unwrap();
    let mut k = 0;
    c.bench_function("file_change_to_new_version_running_300_lines", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                k += 1;
                let start = Instant::now();
                std::fs::write(&path, body(k)).unwrap();
                loop {
                    let cycle = cap.cycle(WorldSnapshot::default());
                    if cycle.command.vlin() == k as f64 {
                        break;
                    }
                    assert!(
                        start.elapsed() < Duration::from_secs(2),
                        "edit {k}: the change never arrived"
                    );
                }
                total += start.elapsed();
            }
            total
        })
    });
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
