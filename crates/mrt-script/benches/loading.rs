//! The three loading strategies of ThinkingCap §3.2 (the seed measured 40 / 17 / 7 ms per call on
//! the AIBO's 576 MHz MIPS) on a 300-line behavior script, and a minimal tick.
//!
//! Run: `cargo bench -p mrt-script --bench loading`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script};
use std::fmt::Write as _;
use std::time::Duration;

/// A 300-line behavior: 100 small helper functions and a body that calls a few of them.
fn behavior_300_lines() -> String {
    let mut s = String::new();
    for i in 0..100 {
        let _ = writeln!(s, "local function f{i}(x)\n  return x * {i} + 1\nend");
    }
    s.push_str("ticks = (ticks or 0) + 1\nreturn f1(ticks) + f2(ticks) + f99(ticks)\n");
    s
}

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("mrt-script-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("behavior.lua");
    std::fs::write(&path, behavior_300_lines()).unwrap();
    let mut g = c.benchmark_group("script_call_300_lines");
    for (name, strategy) in [
        ("reload_from_file", LoadStrategy::ReloadFromFile),
        ("source_in_memory", LoadStrategy::Source),
        ("compiled_in_memory", LoadStrategy::Compiled),
    ] {
        let rt = LuaRuntime::new(Sandbox::default()).unwrap();
        let s = Script::from_file(&rt, &path, strategy).unwrap();
        g.bench_function(name, |b| b.iter(|| s.call::<i64>(&rt).unwrap()));
    }
    g.finish();
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let tick = Script::from_source(
        &rt,
        "tick.lua",
        "local b = ball or 0 return b + 1",
        LoadStrategy::Compiled,
    )
    .unwrap();
    c.bench_function("script_tick_minimal", |b| b.iter(|| tick.call::<i64>(&rt).unwrap()));
    // A behavior tick with four robot-API calls.
    let rt4 = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = std::rc::Rc::new(std::cell::RefCell::new(mrt_script::chaos::RobotIo::default()));
    mrt_script::chaos::install(&rt4, io.clone()).unwrap();
    io.borrow_mut().begin_cycle(mrt_msgs::robot::WorldSnapshot::default(), "tick");
    let four = Script::from_source(
        &rt4,
        "four.lua",
        "local b = chaos.lps_getLpo(BALL) chaos.setVlin(0) chaos.setVrot(b.theta) chaos.setNeeded(BALL, 1.0)",
        LoadStrategy::Compiled,
    )
    .unwrap();
    c.bench_function("script_tick_four_api_calls", |b| {
        b.iter(|| {
            io.borrow_mut().command.needs.clear();
            four.call::<()>(&rt4).unwrap()
        })
    });
    // Hot reload: from a changed file to the new version ready (read + compile + swap).
    let s = Script::from_file(&rt, &path, LoadStrategy::Compiled).unwrap();
    c.bench_function("hot_reload_300_lines", |b| b.iter(|| s.reload(&rt).unwrap()));
    // What the control loop does when the watcher has compiled the file off the control path:
    // load the bytecode and swap it in.
    let compiled = {
        let mut w = mrt_script::ScriptWatcher::new().unwrap();
        w.watch(&path).unwrap();
        std::fs::write(&path, behavior_300_lines()).unwrap();
        let start = std::time::Instant::now();
        loop {
            if let Some(c) = w.changes().pop() {
                break c.compiled.unwrap();
            }
            assert!(start.elapsed() < Duration::from_secs(5), "no change reported");
            std::thread::sleep(Duration::from_millis(1));
        }
    };
    c.bench_function("install_precompiled_300_lines", |b| {
        b.iter(|| s.install(&rt, &compiled).unwrap())
    });
    let _ = std::fs::remove_dir_all(&dir);
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
