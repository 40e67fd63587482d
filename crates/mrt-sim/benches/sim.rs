//! The simulator's hot paths: one physics step with eight robots, one control cycle of a match
//! (eight robot programs on the bus, ten physics steps), and whole short matches: the
//! full-stack default (Milan on Mr. BRIAN against Chaos on Lua), each robot an Agora running the
//! robot program on the bus. Speed as times real time = 60 s / the match's time.
//!
//! Run: `cargo bench -p mrt-sim`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_core::Twist;
use mrt_robot::spec::Stack;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::SimConfig;
use mrt_sim::world::World;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    // The object sensor's percepts (`--percepts oracle`): the cycle without rendering, as
    // measured before vision became the default; `vision_control_cycle` below with it.
    let cfg = SimConfig::oracle();
    let mut world = World::new(&cfg, 8);
    for i in 0..8 {
        world.place_robot(
            i,
            mrt_core::Pose2::new(-3.0 + i as f64, 0.5 * i as f64 - 2.0, 0.3 * i as f64),
        );
        world.drive(i, Twist::new(1.0, 0.0, 0.5));
    }
    c.bench_function("physics_step_8_robots", |b| b.iter(|| world.step()));

    let stacks = [
        ("chaser_vs_chaser", Stack::Chaser, Stack::Chaser),
        ("chaos_vs_chaser", Stack::Chaos, Stack::Chaser),
        ("milan_vs_chaos", Stack::Milan, Stack::Chaos),
    ];
    for (name, home, away) in stacks {
        let mut m = BusMatch::new(&cfg, 1, home, Some(away), None).unwrap();
        c.bench_function(&format!("control_cycle_{name}"), |b| b.iter(|| m.cycle().unwrap()));
    }

    let mut short = SimConfig::oracle();
    short.rules.half_duration = 30.0;
    let mut g = c.benchmark_group("match_2x30s");
    g.sample_size(10);
    g.bench_function("chaos_vs_chaser", |b| {
        b.iter(|| {
            let stacks = (Stack::Chaos, Stack::Chaser);
            mrt_sim::play(&short, 1, stacks, None, false, |_| {}).unwrap()
        })
    });
    g.bench_function("milan_vs_chaos_bus", |b| {
        b.iter(|| {
            let stacks = (Stack::Milan, Stack::Chaos);
            mrt_sim::play(&short, 1, stacks, None, false, |_| {}).unwrap()
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(Duration::from_millis(300)).measurement_time(Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
