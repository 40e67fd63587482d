//! Colour vision's hot path on a synthetic 640×480 frame: green field, 3 px white
//! lines and centre circle, a yellow and a blue goal, an orange ball of radius 10 px, five black
//! robots of radius 22 px, Gaussian noise σ = 8 per channel. Measured: building the lookup table
//! (once per colour file), classifying the frame through it, and that plus the ball's blob;
//! and the whole vision µAgent on it (`VisionAgent::see`: classes, ball, goals, posts, lines,
//! robots, and where in the image each was found for monitors).
//!
//! Run: `cargo bench -p mrt-perception --bench vision`. Results go to `docs/performance.md`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use mrt_perception::camera::{Intrinsics, Pinhole};
use mrt_perception::vision::agent::VisionAgent;
use mrt_perception::vision::balance::BalancedLut;
use mrt_perception::vision::blobs::blobs;
use mrt_perception::vision::colors::{ColorClass, ColorTable, Lut};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const W: usize = 640;
const H: usize = 480;

/// The synthetic frame, RGB888.
fn frame() -> Vec<u8> {
    let mut img = vec![0u8; W * H * 3];
    let mut put = |x: usize, y: usize, c: [u8; 3]| {
        if x < W && y < H {
            img[(y * W + x) * 3..(y * W + x) * 3 + 3].copy_from_slice(&c);
        }
    };
    let dist = |x: usize, y: usize, cx: f64, cy: f64| (x as f64 - cx).hypot(y as f64 - cy);
    let robots = [(120.0, 200.0), (250.0, 330.0), (470.0, 150.0), (530.0, 360.0), (330.0, 90.0)];
    for y in 0..H {
        for x in 0..W {
            let mut c = [30, 140, 40]; // carpet
            let line = (98..101).contains(&y)
                || (378..381).contains(&y)
                || (319..322).contains(&x)
                || (dist(x, y, 320.0, 240.0) - 80.0).abs() < 1.5;
            if line {
                c = [245, 245, 245];
            }
            if x < 30 && (180..300).contains(&y) {
                c = [230, 200, 20];
            }
            if x >= W - 30 && (180..300).contains(&y) {
                c = [20, 60, 220];
            }
            if robots.iter().any(|&(rx, ry)| dist(x, y, rx, ry) <= 22.0) {
                c = [25, 25, 25];
            }
            if dist(x, y, 400.0, 260.0) <= 10.0 {
                c = [255, 120, 0];
            }
            put(x, y, c);
        }
    }
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for v in img.iter_mut() {
        let (u1, u2): (f64, f64) = (rng.random_range(f64::EPSILON..1.0), rng.random());
        let n = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos() * 8.0;
        *v = (f64::from(*v) + n).round().clamp(0.0, 255.0) as u8;
    }
    img
}

fn bench(c: &mut Criterion) {
    let colors = ColorTable::from_file(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../configs/vision/colors.toml"
    ))
    .unwrap();
    c.bench_function("lut_build", |b| b.iter(|| Lut::new(black_box(&colors))));
    let lut = Lut::new(&colors);
    let img = frame();
    let mut out = vec![0u8; W * H];
    let mut g = c.benchmark_group("frame_640x480");
    g.throughput(Throughput::Elements((W * H) as u64));
    g.bench_function("lut_classify", |b| b.iter(|| lut.classify(black_box(&img), &mut out)));
    // The frame's carpet (30, 140, 40) is not the colour file's (30, 130, 50): corrected.
    let mut balanced = BalancedLut::default();
    g.bench_function("lut_classify_balanced", |b| {
        b.iter(|| balanced.classify(&lut, black_box(&img), W, &mut out))
    });
    g.bench_function("lut_classify_and_ball_blob", |b| {
        b.iter(|| {
            lut.classify(black_box(&img), &mut out);
            blobs(&out, W as u32, H as u32, ColorClass::Ball, 3)
        })
    });
    let image = mrt_msgs::Image { width: W as u32, height: H as u32, rgb: img.clone() };
    let camera = Pinhole::new(Intrinsics::centred(W as u32, H as u32, 520.0), 0.45, 0.35);
    let mut agent = VisionAgent::new(camera, &colors, 0.11);
    g.bench_function("agent_see", |b| b.iter(|| agent.see(black_box(&image), 1.0, 0.0).unwrap()));
    g.finish();
    lit_frames(c, &colors);
}

/// The whole µAgent on MuJoCo's 320×240 frames of the shipped camera under each of the four
/// lights of `tests/frames/mujoco` (each frame white-balanced before it is classified).
fn lit_frames(c: &mut Criterion, colors: &ColorTable) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/frames/mujoco");
    let mut g = c.benchmark_group("mujoco_320x240");
    g.throughput(Throughput::Elements(320 * 240));
    let camera = Pinhole::new(Intrinsics::centred(320, 240, 260.0), 0.45, 20f64.to_radians());
    let frame = |light: &str| {
        let path = std::path::Path::new(dir).join(light).join("frame_0001.png");
        mrt_perception::source::load_image(&path).unwrap()
    };
    for light in ["bright", "half", "warm", "side"] {
        let image = frame(light);
        let mut agent = VisionAgent::new(camera, colors, 0.11);
        g.bench_function(format!("agent_see_{light}"), |b| {
            b.iter(|| agent.see(black_box(&image), 1.0, 0.0).unwrap())
        });
    }
    // Every image under another light than the last: the balanced table is built each time.
    let (half, warm) = (frame("half"), frame("warm"));
    let mut agent = VisionAgent::new(camera, colors, 0.11);
    g.bench_function("agent_see_light_changes", |b| {
        b.iter(|| {
            agent.see(black_box(&half), 1.0, 0.0).unwrap();
            agent.see(black_box(&warm), 1.0, 0.0).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
