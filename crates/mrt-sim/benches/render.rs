//! Rendering benchmark: a robot's camera in a
//! busy scene (the ball, nine other robots, a goal in view), with and without the image
//! effects; the same scene through the omnidirectional up camera, and its up mode.
//!
//! Run: `cargo bench -p mrt-sim --bench render`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_core::Pose2;
use mrt_sim::config::SimConfig;
use mrt_sim::render::{CameraState, Renderer, Scene};
use std::hint::black_box;

fn scene() -> Scene {
    let mut robots: Vec<(Pose2, bool)> = (0..5)
        .map(|k| (Pose2::new(-2.0 + k as f64 * 1.8, -1.5 + (k % 2) as f64 * 2.5, 0.0), true))
        .collect();
    robots.extend(
        (0..5).map(|k| (Pose2::new(-1.0 + k as f64 * 2.0, 1.0 - (k % 3) as f64, 0.0), false)),
    );
    Scene { ball: Some((1.2, 0.3)), robots }
}

fn render(c: &mut Criterion) {
    let mut cfg = SimConfig::default();
    let scene = scene();
    let viewer = Pose2::new(-3.0, 0.0, 0.1);
    let mut g = c.benchmark_group("render_320x240");
    let plain = Renderer::new(&cfg).unwrap();
    let mut state = CameraState::new(1);
    g.bench_function("busy_scene", |b| {
        b.iter(|| plain.render(black_box(&scene), black_box(viewer), 0.0, None, &mut state))
    });
    let empty = Scene::default();
    g.bench_function("empty_field", |b| {
        b.iter(|| plain.render(black_box(&empty), black_box(viewer), 0.0, None, &mut state))
    });
    cfg.render.noise = 8.0;
    cfg.render.lighting = 0.2;
    cfg.render.motion_blur = 0.3;
    let effects = Renderer::new(&cfg).unwrap();
    g.bench_function("busy_scene_with_noise_lighting_blur", |b| {
        b.iter(|| effects.render(black_box(&scene), black_box(viewer), 0.0, None, &mut state))
    });
    g.finish();
    c.bench_function("renderer_new", |b| b.iter(|| Renderer::new(black_box(&cfg)).unwrap()));

    // ISocRob's up camera (configs/vision/omni.toml, 480×480) in the same scene, and its up
    // mode: the lookup table and the ball all around.
    use mrt_perception::camera::{CameraModel, OmniFile};
    use mrt_perception::vision::colors::{ColorTable, Lut};
    use mrt_perception::vision::up::find_ball_up;
    let plain = SimConfig::default();
    let omni = OmniFile::default().camera().unwrap();
    let up = Renderer::with_camera(&plain, CameraModel::Omni(omni)).unwrap();
    let mut g = c.benchmark_group("omni_480x480");
    g.bench_function("busy_scene", |b| {
        b.iter(|| up.render(black_box(&scene), black_box(viewer), 0.0, None, &mut state))
    });
    let image = up.render(&scene, viewer, 0.0, None, &mut state);
    let lut = Lut::new(&ColorTable::shipped());
    let mut classes = vec![0u8; image.rgb.len() / 3];
    g.bench_function("classify_and_find_ball_up", |b| {
        b.iter(|| {
            lut.classify(black_box(&image.rgb), &mut classes);
            find_ball_up(&classes, &omni, plain.ball.radius)
        })
    });
    g.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
