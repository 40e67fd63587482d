//! MAP's anchoring of the other robots (`mrt_world::anchor`), once per camera frame on every
//! robot: seven robots walking about, all seen in every frame (the most a 4-a-side robot can
//! see), against their seven anchors — association (Kuhn–Munkres), tracking, fading. Also the
//! case of a crowd: 7 anchors and 12 percepts (a robot seen twice, phantoms).
//!
//! Run: `cargo bench -p mrt-world --bench anchor`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_msgs::Marker;
use mrt_world::anchor::{Anchors, RobotPercept};
use nalgebra::Matrix2;

/// Robot `k`'s place at `t`: circles of different radii and speeds round the field.
fn place(k: usize, t: f64) -> (f64, f64) {
    let kf = k as f64;
    let (r, w) = (1.0 + 0.5 * kf, 0.3 + 0.05 * kf);
    (r * (w * t + kf).cos() - 3.0 + kf, r * (w * t + kf).sin())
}

fn frame(t: f64, robots: usize) -> Vec<RobotPercept> {
    let r = Matrix2::from_diagonal_element(0.05 * 0.05);
    (0..robots)
        .map(|k| RobotPercept {
            at: place(k % 7, t),
            r,
            marker: Some(if k % 2 == 0 { Marker::Magenta } else { Marker::Cyan }),
        })
        .collect()
}

fn anchoring(c: &mut Criterion) {
    for (name, robots) in [("7_robots", 7), ("12_percepts_7_robots", 12)] {
        // Steady state: the anchors settled over 5 s of frames first.
        let mut anchors = Anchors::default();
        let mut t = 0.0;
        while t < 5.0 {
            anchors.update(t, &frame(t, robots));
            t += 0.1;
        }
        // Then one frame per iteration, 0.1 s apart, on the same anchors (the frame is made
        // inside the timing: seven sines and cosines and a small vector, ~0.1 µs).
        c.bench_function(&format!("anchor/frame_{name}"), |b| {
            b.iter(|| {
                t += 0.1;
                anchors.update(black_box(t), black_box(&frame(t, robots)));
            })
        });
        assert!(anchors.anchors().len() <= robots + 2, "{}", anchors.anchors().len());
    }
}

criterion_group!(benches, anchoring);
criterion_main!(benches);
