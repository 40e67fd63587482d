//! SPIKE's speed (the goal: a path on the 12 × 8 m and the 18 × 12 m fields, accurate
//! to 1 cm, in under 1 ms) against the `pathfinding` crate's A* on a 1 cm grid of the same
//! map (8-connected, Euclidean heuristic, the grid's free cells precomputed outside the
//! timing), on the same maps: each field with robots standing about as in a match, from one
//! penalty area to the other. Each setting's path length is printed once before it is timed,
//! beside the grid's.
//!
//! Run: `cargo bench -p mrt-plan --bench spike`.
#![allow(missing_docs, clippy::unwrap_used, clippy::print_stdout)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_core::Point2;
use mrt_plan::spike::{PlanMap, Shape, Spike, SpikeParams};
use pathfinding::prelude::astar;

/// The grid's cost of a step along an axis: costs are whole thousandths of a cell.
const STRAIGHT: u64 = 1000;

/// A map, its robots, the start and the goal.
struct Scene {
    name: &'static str,
    map: PlanMap,
    robots: Vec<Shape>,
    from: Point2,
    to: Point2,
}

fn scenes() -> Vec<Scene> {
    let robot = |x: f64, y: f64| Shape::Disc { centre: Point2::new(x, y), radius: 0.25 };
    vec![
        Scene {
            name: "field_12x8",
            map: PlanMap::soccer_field(12.0, 8.0).unwrap(),
            robots: vec![
                robot(-2.0, 0.3),
                robot(-0.5, -0.6),
                robot(0.8, 0.5),
                robot(2.5, -0.2),
                robot(3.5, 1.5),
            ],
            from: Point2::new(-4.8, -0.4),
            to: Point2::new(4.8, 0.6),
        },
        Scene {
            name: "field_18x12",
            map: PlanMap::soccer_field(18.0, 12.0).unwrap(),
            robots: vec![
                robot(-4.0, 0.5),
                robot(-2.0, -0.8),
                robot(-0.5, 0.2),
                robot(1.0, -0.4),
                robot(2.5, 0.9),
                robot(4.0, -0.3),
                robot(5.5, 0.4),
            ],
            from: Point2::new(-7.5, -0.5),
            to: Point2::new(7.5, 0.5),
        },
    ]
}

/// The map's free cells on a grid of `step` m: a cell is free when its centre keeps
/// `clearance` from every obstacle.
struct Grid {
    min: Point2,
    step: f64,
    nx: usize,
    ny: usize,
    free: Vec<bool>,
}

impl Grid {
    fn new(map: &PlanMap, robots: &[Shape], clearance: f64, step: f64) -> Grid {
        let nx = ((map.max.x - map.min.x) / step) as usize;
        let ny = ((map.max.y - map.min.y) / step) as usize;
        let mut free = vec![false; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let c = Point2::new(
                    map.min.x + (i as f64 + 0.5) * step,
                    map.min.y + (j as f64 + 0.5) * step,
                );
                let d = robots.iter().fold(map.clearance(c), |d, s| d.min(s.distance(c)));
                free[j * nx + i] = d >= clearance;
            }
        }
        Grid { min: map.min, step, nx, ny, free }
    }

    fn cell(&self, p: Point2) -> (usize, usize) {
        (((p.x - self.min.x) / self.step) as usize, ((p.y - self.min.y) / self.step) as usize)
    }

    /// A* from `from` to `to`: the path's length, m.
    fn astar(&self, from: Point2, to: Point2) -> Option<f64> {
        let (start, goal) = (self.cell(from), self.cell(to));
        let (nx, ny) = (self.nx as i64, self.ny as i64);
        // Costs in 1/1000 of a cell: STRAIGHT (1000) along an axis, 1414 diagonal.
        let result = astar(
            &start,
            |&(i, j)| {
                let mut next = Vec::with_capacity(8);
                for (di, dj, cost) in [
                    (1, 0, STRAIGHT),
                    (-1, 0, STRAIGHT),
                    (0, 1, STRAIGHT),
                    (0, -1, STRAIGHT),
                    (1, 1, 1414),
                    (1, -1, 1414),
                    (-1, 1, 1414),
                    (-1, -1, 1414),
                ] {
                    let (a, b) = (i as i64 + di, j as i64 + dj);
                    if a >= 0 && b >= 0 && a < nx && b < ny && self.free[(b * nx + a) as usize] {
                        next.push(((a as usize, b as usize), cost));
                    }
                }
                next
            },
            |&(i, j)| {
                let (di, dj) = (i.abs_diff(goal.0) as f64, j.abs_diff(goal.1) as f64);
                (STRAIGHT as f64 * di.hypot(dj)) as u64
            },
            |&c| c == goal,
        )?;
        Some(result.1 as f64 / STRAIGHT as f64 * self.step)
    }
}

fn bench(c: &mut Criterion) {
    let params = SpikeParams::default();
    let mut g = c.benchmark_group("spike");
    for scene in scenes() {
        let spike = Spike::new(scene.map.clone(), params).unwrap();
        let plan = spike.plan_among(scene.from, scene.to, &scene.robots).unwrap();
        let grid = Grid::new(&scene.map, &scene.robots, spike.clearance(), 0.01);
        let grid_length = grid.astar(scene.from, scene.to).unwrap();
        println!(
            "{}: SPIKE {:.3} m, {} corners, {} cells made, {} expanded; 1 cm grid A* {:.3} m",
            scene.name,
            plan.length,
            plan.waypoints.len(),
            plan.cells,
            plan.expanded,
            grid_length
        );
        g.bench_function(format!("{}/spike", scene.name), |b| {
            b.iter(|| spike.plan_among(black_box(scene.from), scene.to, &scene.robots).unwrap())
        });
        g.sample_size(10);
        g.bench_function(format!("{}/astar_1cm_grid", scene.name), |b| {
            b.iter(|| grid.astar(black_box(scene.from), scene.to).unwrap())
        });
        g.sample_size(100);
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
