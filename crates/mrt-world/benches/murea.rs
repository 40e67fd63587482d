//! MUREA's cost:
//! one frame of a robot on the MSL field that sees 6 landmarks and 16 field-line points, with
//! noise of a third of the tolerances, localized globally (the whole field, every heading) and
//! in tracking mode (±0.5 m, ±0.3 rad round a prediction), under several cell budgets and
//! timeouts, and the world model's relocalizer finding the robot from that frame alone;
//! ThinkingCap's fuzzy grid (GM) on the same frame; ISocRob's Hough self mode. The position
//! error of each setting is printed once before it is timed.
//!
//! Run: `cargo bench -p mrt-world --bench murea`.
#![allow(missing_docs, clippy::unwrap_used, clippy::print_stdout)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_core::{normalize_angle, Pose2};
use mrt_world::field::FieldMap;
use mrt_world::murea::{Kind, Map, Murea, Perception};
use mrt_world::relocalize::Relocalizer;

/// What a robot at `pose` sees: the goals and posts within 9 m and points of the lines
/// within 5 m, each off by a third of its tolerances in turn.
fn frame(field: &FieldMap, pose: Pose2) -> Vec<Perception> {
    let mut out = Vec::new();
    let mut see = |kind: Kind, x: f64, y: f64| {
        let (dx, dy) = (x - pose.x, y - pose.y);
        let range = dx.hypot(dy);
        let bearing = normalize_angle(dy.atan2(dx) - pose.theta);
        let wobble = [0.33, -0.33, 0.2, -0.1][out.len() % 4];
        let p = Perception::point(kind, range, bearing);
        out.push(Perception {
            range: Some(range + wobble * p.range_tolerance),
            bearing: Some(bearing - wobble * p.bearing_tolerance),
            ..p
        });
    };
    for k in 1..mrt_msgs::FIELD_OBJECTS {
        let at = field.object(k).unwrap();
        if (at.x - pose.x).hypot(at.y - pose.y) < 9.0 {
            see(Kind::of_object(field, k, true).unwrap(), at.x, at.y);
        }
    }
    let mut lines = 0;
    for s in field.lines() {
        for k in 0..20 {
            let p = s.a + (s.b - s.a) * (f64::from(k) + 0.5) / 20.0;
            if (p.x - pose.x).hypot(p.y - pose.y) < 5.0 && lines < 16 {
                see(Kind::LINE, p.x, p.y);
                lines += 1;
            }
        }
    }
    out
}

fn bench(c: &mut Criterion) {
    let field = FieldMap::default();
    let truth = Pose2::new(-3.1, 1.7, 0.6);
    let seen = frame(&field, truth);
    let mut g = c.benchmark_group("murea");
    for cells in [5_000, 20_000, 200_000] {
        let mut murea = Murea::new(Map::field(&field, true));
        murea.budget.cells = cells;
        let fix = murea.localize(&seen, murea.whole_field());
        let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
        let turn = normalize_angle(fix.pose.theta - truth.theta).abs().to_degrees();
        println!(
            "global, budget {cells} cells: {} perceptions, error {err:.3} m {turn:.2}°, {} cells, \
             timed out {}",
            seen.len(),
            fix.cells,
            fix.timed_out
        );
        g.bench_function(format!("global_{cells}_cells"), |b| {
            b.iter(|| murea.localize(black_box(&seen), murea.whole_field()))
        });
    }
    let mut murea = Murea::new(Map::field(&field, true));
    murea.ambiguity = 1.0;
    let fix = murea.localize(&seen, murea.whole_field());
    let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
    println!("global, no alternatives: error {err:.3} m, {} cells", fix.cells);
    g.bench_function("global_no_alternatives", |b| {
        b.iter(|| murea.localize(black_box(&seen), murea.whole_field()))
    });
    // Anytime: the answer under a wall-clock timeout (the manual's parameter). The error at
    // each timeout is printed once; the time measured is the timeout or the whole search.
    for ms in [1u64, 2, 4] {
        let mut murea = Murea::new(Map::field(&field, true));
        murea.budget.timeout = Some(std::time::Duration::from_millis(ms));
        let fix = murea.localize(&seen, murea.whole_field());
        let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
        println!(
            "global, timeout {ms} ms: error {err:.3} m, cell {:.2} m × {:.1}°, {} cells, timed out {}",
            fix.cell.0,
            fix.cell.2.to_degrees(),
            fix.cells,
            fix.timed_out
        );
        g.bench_function(format!("global_timeout_{ms}ms"), |b| {
            b.iter(|| murea.localize(black_box(&seen), murea.whole_field()))
        });
    }
    let murea = Murea::new(Map::field(&field, true));
    let area = Murea::around(Pose2::new(-3.3, 1.5, 0.7), 0.5, 0.3);
    let fix = murea.localize(&seen, area);
    let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
    println!("tracking: error {err:.3} m, {} cells", fix.cells);
    g.bench_function("tracking", |b| b.iter(|| murea.localize(black_box(&seen), area)));
    // The world model's relocalizer on the same frame with its tracker 6 m off: the coarse
    // global search on the goals and posts, then the fine one round it with the lines.
    let wrong = Pose2::new(3.0, -2.0, 2.0);
    let fresh = Relocalizer::new(&field);
    let mut r = fresh.clone();
    let fix = r.frame(0.0, seen.clone(), wrong).unwrap();
    let err = (fix.pose.x - truth.x).hypot(fix.pose.y - truth.y);
    let turn = normalize_angle(fix.pose.theta - truth.theta).abs().to_degrees();
    println!("relocalizer: error {err:.3} m {turn:.2}°, fine search {} cells", fix.cells);
    g.bench_function("relocalizer_kidnapped", |b| {
        b.iter_batched(
            || (fresh.clone(), seen.clone()),
            |(mut r, seen)| r.frame(0.0, seen, wrong),
            criterion::BatchSize::SmallInput,
        )
    });
    g.finish();

    // ThinkingCap's fuzzy grid (mrt_world::gm) on the same frame (it reads the goals and
    // posts, not the lines): one frame from "anywhere", one frame that agrees with the belief,
    // one control cycle's odometry, and the estimate.
    use mrt_world::gm::FuzzyGrid;
    let mut g = c.benchmark_group("gm");
    let anywhere = FuzzyGrid::field(&field);
    let mut found = anywhere.clone();
    found.observe(&seen);
    let e = found.estimate();
    let err = (e.pose.x - truth.x).hypot(e.pose.y - truth.y);
    let turn = normalize_angle(e.pose.theta - truth.theta).abs().to_degrees();
    let (nx, ny, nk) = found.shape();
    println!("gm: {nx} × {ny} cells × {nk} headings, one frame: error {err:.3} m {turn:.2}°");
    g.bench_function("observe_from_anywhere", |b| {
        b.iter_batched(
            || anywhere.clone(),
            |mut grid| grid.observe(black_box(&seen)),
            criterion::BatchSize::LargeInput,
        )
    });
    g.bench_function("observe_tracking", |b| {
        b.iter_batched(
            || found.clone(),
            |mut grid| grid.observe(black_box(&seen)),
            criterion::BatchSize::LargeInput,
        )
    });
    let mut moving = found.clone();
    g.bench_function("predict_one_cycle", |b| {
        b.iter(|| moving.predict(black_box(Pose2::new(0.02, 0.0, 0.01))))
    });
    g.bench_function("estimate", |b| b.iter(|| black_box(&found).estimate()));
    g.finish();

    // ISocRob's self mode (mrt_world::hough): the field-line points within 4 m of a robot near
    // the west penalty area, every 10 cm, through the Hough transform and the matching.
    use mrt_world::hough::{hough_lines, self_localize, HoughParams};
    let at = Pose2::new(-6.0, 1.5, 2.6);
    let (sin, cos) = at.theta.sin_cos();
    let mut points = Vec::new();
    for seg in field.lines() {
        let n = (seg.length() / 0.1) as usize;
        for k in 0..=n {
            let p = seg.a + (seg.b - seg.a) * (k as f64 / n as f64);
            let (dx, dy) = (p.x - at.x, p.y - at.y);
            if dx.hypot(dy) <= 4.0 {
                points.push(mrt_core::Point2::new(cos * dx + sin * dy, -sin * dx + cos * dy));
            }
        }
    }
    let params = HoughParams::default();
    let mut g = c.benchmark_group("hough");
    g.bench_function("hough_lines", |b| b.iter(|| hough_lines(black_box(&points), &params)));
    let lines = hough_lines(&points, &params);
    println!("hough: {} points, {} lines", points.len(), lines.len());
    g.bench_function("hough_self_localize", |b| {
        b.iter(|| self_localize(&field, black_box(&points), &lines, &params))
    });
    // The lines as MUREA perceptions beside the goals and posts, against the
    // same goals and posts with 16 line points: one global search each.
    let landmarks: Vec<Perception> =
        frame(&field, at).into_iter().filter(|p| p.kind != Kind::LINE).collect();
    let with_points = frame(&field, at);
    let mut with_lines = landmarks.clone();
    with_lines.extend(lines.iter().map(|l| l.perception(&params)));
    let murea = Murea::new(Map::field(&field, true));
    for (name, seen) in [("murea_line_points", &with_points), ("murea_hough_lines", &with_lines)] {
        let fix = murea.localize(seen, murea.whole_field());
        let err = (fix.pose.x - at.x).hypot(fix.pose.y - at.y);
        let turn = normalize_angle(fix.pose.theta - at.theta).abs().to_degrees();
        println!(
            "{name}: {} perceptions, error {err:.3} m {turn:.2}°, {} cells",
            seen.len(),
            fix.cells
        );
        g.bench_function(name, |b| b.iter(|| murea.localize(black_box(seen), murea.whole_field())));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
