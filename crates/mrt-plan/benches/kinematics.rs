//! The per-cycle costs of `mrt-plan`: inverse kinematics plus limit for both bases, one
//! potential-field step among a few obstacles. (The two-mice displacement is benchmarked in
//! `mrt-perception`.)
//!
//! Run: `cargo bench -p mrt-plan --bench kinematics`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_core::Pose2;
use mrt_plan::guidance::{behind_ball, Obstacle, PositionParams, PotentialField, PotentialParams};
use mrt_plan::kinematics::{DiffDrive, Kinematics, Omni3, Twist};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan");
    // A twist above the top speed, so that limit scales.
    let twist = Twist::new(1.5, 0.4, 2.0);

    let ianus = DiffDrive::ianus3();
    g.bench_function("inverse_limit_diff_drive", |b| {
        b.iter(|| ianus.inverse(&ianus.limit(black_box(&twist))))
    });

    let triskar = Omni3::triskar();
    g.bench_function("inverse_limit_omni3", |b| {
        b.iter(|| triskar.inverse(&triskar.limit(black_box(&twist))))
    });

    // Five robots and the ball on the field; the target is behind the ball.
    let field = PotentialField::new(PositionParams::default(), PotentialParams::default()).unwrap();
    let ball = Obstacle::new(2.0, 0.5, 0.11);
    let obstacles = [
        ball,
        Obstacle::new(1.0, 0.0, 0.25),
        Obstacle::new(1.5, 1.2, 0.25),
        Obstacle::new(3.0, -0.5, 0.25),
        Obstacle::new(-1.0, 2.0, 0.25),
        Obstacle::new(4.0, 1.0, 0.25),
    ];
    let target = behind_ball(ball.center, mrt_core::Point2::new(9.0, 0.0), 0.6).unwrap();
    let pose = Pose2::new(0.0, 0.2, 0.1);
    g.bench_function("potential_field_step_6_obstacles", |b| {
        b.iter(|| field.command(black_box(&pose), black_box(&target), black_box(&obstacles)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
