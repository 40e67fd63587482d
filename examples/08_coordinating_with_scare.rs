//! # 08 — Coordinating a team with SCARE
//!
//! What you learn: how robots agree who does what with SCARE (MRT manual ch. 11,
//! `mrt_team::scare`) without a leader: each robot rates its own *attitudes*, tells its
//! teammates, and every robot computes the same allocation of the team's *activities* from
//! the same reports. Then how the sequencer and monitor drive one job's sub-tasks.
//!
//! Four robots of Team Milan (robot 1 keeps goal) see the ball near the centre, an opponent
//! right in front of it, and a teammate free far ahead. The team gives the ball's nearest
//! robot and the free one a PassageToMate schema (passer and receiver), keeps its goalkeeper,
//! and sends the last robot to defend. Every robot prints the same allocation. Then the
//! opponent leaves: there is nothing to pass round, and the nearest robot simply brings the
//! ball (BringBall, the same group as the passage: never both at once). It stands behind the
//! ball on the line to the net, so its monitor moves it straight on from ReachBall to Shoot.
//!
//! Run: `cargo run -p mrt-examples --example 08_coordinating_with_scare`.

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_msgs::ScareReport;
use mrt_team::scare::soccer::{Coordinator, Situation};

/// Where the four robots stand (team frame, m; robot 1 keeps goal).
pub const ROBOTS: [(f64, f64); 4] = [(-8.5, 0.0), (-1.5, 0.0), (2.5, 2.0), (-5.0, -1.5)];
/// The ball.
pub const BALL: (f64, f64) = (-1.0, 0.0);

/// What robot `i` believes: the same ball and opponents for all, its teammates where they are.
fn situation(i: usize, opponents: &[(f64, f64)]) -> Situation {
    Situation {
        me: (ROBOTS[i].0, ROBOTS[i].1, 0.0),
        keeper: i == 0,
        ball: Some(BALL),
        mates: (0..ROBOTS.len())
            .filter(|j| *j != i)
            .map(|j| (j as u32 + 1, ROBOTS[j], j == 0))
            .collect(),
        opponents: opponents.to_vec(),
        half_length: 9.0,
        goal_half_width: 1.0,
    }
}

/// Two rounds of reports among the four robots with `opponents` on the field; each robot's
/// view of who does what after the second round, `(robot, [(robot, activity)])`, and robot
/// 2's job.
pub fn run(opponents: &[(f64, f64)], print: bool) -> (Vec<Vec<(u32, String)>>, String) {
    let mut robots: Vec<Coordinator> = (1..=4).map(Coordinator::new).collect();
    let mut reports: Vec<ScareReport> = vec![ScareReport::default(); 4];
    let mut views = Vec::new();
    let mut job_of_2 = String::new();
    for round in 0..2 {
        let mut next = Vec::new();
        views.clear();
        for (i, robot) in robots.iter_mut().enumerate() {
            // Each robot hears the other three's latest reports (none before the first).
            let heard: Vec<(u32, &ScareReport)> = (0..4)
                .filter(|j| *j != i && round > 0)
                .map(|j| (j as u32 + 1, &reports[j]))
                .collect();
            let cycle = robot.cycle(0.1 * f64::from(round), &situation(i, opponents), &heard, 0.0);
            let table = mrt_team::scare::soccer::table();
            let view: Vec<(u32, String)> = cycle
                .allocation
                .names(&table)
                .into_iter()
                .map(|(r, name)| (r, name.to_string()))
                .collect();
            if i == 1 {
                let j = &cycle.job;
                job_of_2 = if j.functionality == j.activity {
                    format!("{}, sub-task {}", j.activity, j.subtask)
                } else {
                    format!("{} ({}), sub-task {}", j.activity, j.functionality, j.subtask)
                };
            }
            views.push(view);
            next.push(cycle.report);
        }
        reports = next;
    }
    if print {
        for (i, v) in views.iter().enumerate() {
            let line: Vec<String> = v.iter().map(|(r, a)| format!("{r}: {a}")).collect();
            println!("robot {} allocates  {}", i + 1, line.join(", "));
        }
        println!("robot 2's job: {job_of_2}");
    }
    (views, job_of_2)
}

/// Runs the example: with the opponent blocking the ball, then without it.
pub fn main() {
    println!("An opponent stands in front of the ball, robot 3 is free far ahead:");
    run(&[(-0.2, 0.0)], true);
    println!("\nThe opponent has gone:");
    run(&[], true);
}
