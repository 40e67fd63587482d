//! The simulator's hot paths: one physics step with eight robots, one control cycle of a match
//! (eight object-sensor looks, eight brains, ten physics steps), and a whole short match.
//!
//! Run: `cargo bench -p mrt-sim`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_sim::config::SimConfig;
use mrt_sim::game::Match;
use mrt_sim::teams::{team, Stack};
use mrt_sim::world::{Drive, World};
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
    ];
    for (name, home, away) in stacks {
        let mut m =
            Match::new(&cfg, 1, team(home, &cfg, None).unwrap(), team(away, &cfg, None).unwrap())
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
                team(Stack::Chaos, &short, None).unwrap(),
                team(Stack::Chaser, &short, None).unwrap(),
            )
            .unwrap();
            m.play(f64::MAX, |_| {})
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
