//! The per-cycle cost of the two-mice odometry: one displacement from four readings, and the
//! §4.2 error reduction of inconsistent readings.
//!
//! Run: `cargo bench -p mrt-perception --bench odometry`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_perception::mice::{MiceOdometry, MiceReadings};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan");
    let mice = MiceOdometry::new(0.2, 1e-4).unwrap();
    let readings: MiceReadings = mice.readings_for(0.02, 0.005, 0.03);
    // Kept in the group "plan" under its old name, so that results compare with the runs made
    // when the odometry lived in mrt-plan.
    g.bench_function("mice_displacement", |b| {
        b.iter(|| mice.displacement(black_box(&readings)).unwrap())
    });
    // The left mouse under-read by a third: inconsistent, reduced.
    let short = MiceReadings::new(
        readings.x_left * 0.66,
        readings.y_left * 0.66,
        readings.x_right,
        readings.y_right,
    );
    g.bench_function("mice_reduce", |b| b.iter(|| mice.reduce(black_box(&short)).unwrap()));
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
