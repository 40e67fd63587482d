//! # 07 — Planning a path with SPIKE
//!
//! What you learn: how to plan a path with SPIKE (MRT manual ch. 9, `mrt_plan::spike`) on a
//! map of fixed objects, with moving objects added for one plan, and how to tell that a path
//! must be planned again. This is the manual's FollowMe application (§2.3) in small: a guide
//! robot in a building of two rooms joined by a door.
//! Each plan builds its own lazy quadtree, so planning again costs as much as the first plan.
//!
//! The map is `configs/plan/room-with-door.toml`: two rooms of 5 m × 6 m, a 0.9 m door, a
//! pillar and a table. The robot (0.3 m radius, 0.1 m of safety) goes from the left room to
//! the right one. Then a visitor stops in the doorway: the old path is blocked, and no new
//! one exists until the visitor moves on. When the visitor stands on the path in the right
//! room instead, the old path is blocked and the new one goes round the visitor.
//!
//! Run: `cargo run -p mrt-examples --example 07_planning_a_path`.

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_core::Point2;
use mrt_plan::spike::{Plan, PlanMap, Shape, Spike, SpikeParams};
use mrt_plan::PlanError;

/// The map file, as shipped.
pub const MAP: &str = include_str!("../configs/plan/room-with-door.toml");

/// What happened in each situation: its name and the plan, or why there is none.
pub struct Outcome {
    /// The situation.
    pub situation: &'static str,
    /// The plan, or SPIKE's error.
    pub plan: Result<Plan, PlanError>,
    /// Whether the first plan is blocked by this situation's visitor.
    pub first_blocked: bool,
}

/// Plans the three situations; prints them when `print`.
pub fn run(print: bool) -> Result<Vec<Outcome>, String> {
    let map = PlanMap::from_toml(MAP, "room-with-door.toml").map_err(|e| e.to_string())?;
    let params = SpikeParams { robot_radius: 0.3, ..SpikeParams::default() };
    let spike = Spike::new(map, params).map_err(|e| e.to_string())?;
    let (from, to) = (Point2::new(-4.0, -2.0), Point2::new(4.0, -2.0));
    let first = spike.plan(from, to).map_err(|e| e.to_string())?;
    let visitor = |x: f64, y: f64| vec![Shape::Disc { centre: Point2::new(x, y), radius: 0.25 }];
    let mut out = Vec::new();
    for (situation, people) in [
        ("the building empty", Vec::new()),
        ("a visitor stopped in the doorway", visitor(0.0, 1.0)),
        ("the visitor on the way in the right room", visitor(2.7, -1.7)),
    ] {
        let plan = spike.plan_among(from, to, &people);
        let first_blocked = first.is_blocked_by(&people, spike.clearance());
        if print {
            println!("{situation}:");
            match &plan {
                Ok(p) => {
                    let corners: Vec<String> =
                        p.waypoints.iter().map(|w| format!("({:.2}, {:.2})", w.x, w.y)).collect();
                    println!("  {:.2} m through {}", p.length, corners.join(" -> "));
                    println!("  {} poses, {} cells made", p.poses.len(), p.cells);
                }
                Err(e) => println!("  {e}"),
            }
            println!(
                "  the first path is {}",
                if first_blocked { "blocked" } else { "still clear" }
            );
        }
        out.push(Outcome { situation, plan, first_blocked });
    }
    Ok(out)
}

/// Runs the example and prints what it planned.
pub fn main() -> Result<(), String> {
    run(true).map(|_| ())
}
