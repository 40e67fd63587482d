//! The simulator's hot paths: one physics step with eight robots, one control cycle of a match
//! (eight object-sensor looks, eight brains, ten physics steps), and whole short matches: the
//! full-stack default (Milan on Mr. BRIAN against Chaos on Lua, each robot an Agora on the bus)
//! and the direct wiring. Speed as times real time = 60 s / the match's time.
//!
//! Run: `cargo bench -p mrt-sim`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_robot::stacks::{team, Stack};
use mrt_sim::config::SimConfig;
use mrt_sim::game::Match;
use mrt_sim::world::{Drive, World};
use mrt_sim::Wiring;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let cfg = SimConfig::default();
    let mut world = World::new(&cfg, 8);
    for i in 0..8 {
        world.place_robot(
            i,
            mrt_core::Pose2::new(-3.0 + i as f64, 0.5 * i as f64 - 2.0, 0.3 * i as f64),
        );
        world.drive(i, Drive { forward: 1.0, left: 0.0, turn: 0.5 });
    }
    c.bench_function("physics_step_8_robots", |b| b.iter(|| world.step()));

    let stacks = [
        ("chaser_vs_chaser", Stack::Chaser, Stack::Chaser),
        ("chaos_vs_chaser", Stack::Chaos, Stack::Chaser),
        ("milan_vs_chaos", Stack::Milan, Stack::Chaos),
    ];
    for (name, home, away) in stacks {
        let mut m = Match::new(
            &cfg,
            1,
            team(home, &cfg.robot().unwrap(), None).unwrap(),
            team(away, &cfg.robot().unwrap(), None).unwrap(),
        )
        .unwrap();
        c.bench_function(&format!("control_cycle_{name}"), |b| b.iter(|| m.cycle()));
    }

    let mut short = SimConfig::default();
    short.rules.half_duration = 30.0;
    let mut g = c.benchmark_group("match_2x30s");
    g.sample_size(10);
    g.bench_function("chaos_vs_chaser", |b| {
        b.iter(|| {
            let m = Match::new(
                &short,
                1,
                team(Stack::Chaos, &short.robot().unwrap(), None).unwrap(),
                team(Stack::Chaser, &short.robot().unwrap(), None).unwrap(),
            )
            .unwrap();
            m.play(f64::MAX, |_| {})
        })
    });
    g.bench_function("milan_vs_chaos_direct", |b| {
        b.iter(|| {
            let stacks = (Stack::Milan, Stack::Chaos);
            mrt_sim::play(&short, 1, stacks, Wiring::Direct, None, false, |_| {}).unwrap()
        })
    });
    g.bench_function("milan_vs_chaos_bus", |b| {
        b.iter(|| {
            let stacks = (Stack::Milan, Stack::Chaos);
            mrt_sim::play(&short, 1, stacks, Wiring::Bus, None, false, |_| {}).unwrap()
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
