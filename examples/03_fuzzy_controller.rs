//! # 03 — A fuzzy controller: Mr. BRIAN drives the harvesting robot
//!
//! What you learn: how to load a Mr. BRIAN configuration directory (the manual's harvesting
//! robot of chapter 10, `configs/brian/harvester`), run one perception-action cycle on crisp
//! inputs `(name, value, reliability)` — what the manual's Parser produces — and read the crisp
//! commands — what its Messenger sends to the actuators. Along the way you see which behaviors
//! ran: CANDO says whether a behavior *can* run (above 0.49), WANT how much its proposals
//! weigh, and the level-2 behavior AvoidObstacle overrides what level 1 proposes.
//!
//! Run: `cargo run -p mrt-examples --example 03_fuzzy_controller`.

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_fuzzy::brian::{Brian, Commands, DEFAULT_THRESHOLD, WANT_THRESHOLD};
use mrt_fuzzy::BrianError;
use std::path::{Path, PathBuf};

/// The harvester configuration shipped with MRT.
pub fn config_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/brian/harvester")
}

/// One scripted situation: the crisp inputs of one cycle.
#[derive(Clone, Debug)]
pub struct Situation {
    /// What is going on.
    pub name: &'static str,
    /// `(input, value, reliability)`; an input left out reads as value 0, which every
    /// distance shape of the harvester treats as "not seen".
    pub inputs: Vec<(&'static str, f64, f64)>,
}

/// What Mr. BRIAN made of one situation.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The situation's name.
    pub situation: &'static str,
    /// The crisp commands: `SpeedModule` (cm/s) and `SpeedAngle` (degrees, 0 = ahead,
    /// 90 = left); an action nobody proposed is absent.
    pub commands: Commands,
    /// Each behavior, in the order they ran.
    pub behaviors: Vec<BehaviorState>,
}

/// What a behavior did in one cycle.
#[derive(Clone, Debug)]
pub struct BehaviorState {
    /// Its name in `behavior.txt`.
    pub name: String,
    /// Its level (1 runs first and has the lowest priority).
    pub level: i64,
    /// Its (CANDO, WANT) values when it ran; `None` when its CANDO was not above 0.49.
    pub ran: Option<(f64, f64)>,
}

/// Battery full, gripper empty, home base 4 m behind: the robot is free to harvest.
fn with_defaults(mut inputs: Vec<(&'static str, f64, f64)>) -> Vec<(&'static str, f64, f64)> {
    for default in [
        ("BatteryLevel", 100.0, 1.0),
        ("GraspingObject", 0.0, 1.0),
        ("HomeDistance", 400.0, 1.0),
        ("HomeAngle", 180.0, 1.0),
    ] {
        if !inputs.iter().any(|(n, _, _)| *n == default.0) {
            inputs.push(default);
        }
    }
    inputs
}

/// The scripted situations. Angles in degrees, counter-clockwise: 0 ahead, 90 left.
pub fn situations() -> Vec<Situation> {
    vec![
        Situation {
            name: "target far ahead",
            inputs: with_defaults(vec![("TargetDistance", 300.0, 1.0), ("TargetAngle", 0.0, 1.0)]),
        },
        Situation {
            name: "target near, to the left",
            inputs: with_defaults(vec![("TargetDistance", 70.0, 1.0), ("TargetAngle", 80.0, 1.0)]),
        },
        Situation {
            name: "obstacle ahead while going to the target",
            inputs: with_defaults(vec![
                ("TargetDistance", 300.0, 1.0),
                ("TargetAngle", 0.0, 1.0),
                ("ObstacleDistance", 50.0, 1.0),
                ("ObstacleAngle", 10.0, 1.0),
            ]),
        },
        Situation {
            name: "battery almost empty",
            inputs: with_defaults(vec![
                ("TargetDistance", 300.0, 1.0),
                ("TargetAngle", 0.0, 1.0),
                ("BatteryLevel", 10.0, 1.0),
                ("HomeDistance", 250.0, 1.0),
                ("HomeAngle", 200.0, 1.0),
            ]),
        },
    ]
}

/// A compass word for a heading in the robot frame.
fn direction(deg: f64) -> &'static str {
    const NAMES: [&str; 8] = [
        "ahead",
        "ahead-left",
        "left",
        "behind-left",
        "behind",
        "behind-right",
        "right",
        "ahead-right",
    ];
    NAMES[((deg.rem_euclid(360.0) + 22.5) / 45.0) as usize % 8]
}

/// Loads the configuration in `dir` and runs every situation, one cycle each (in order, on the
/// same engine: the harvester has no input named like an output, so cycles do not feed each
/// other). Prints each cycle when `verbose`.
pub fn run(dir: &Path, verbose: bool) -> Result<Vec<Outcome>, BrianError> {
    let mut brian = Brian::from_dir(dir)?;
    let mut outcomes = Vec::new();
    for s in situations() {
        // The Parser's job is done: one cycle of Mr. BRIAN turns inputs into commands.
        let commands = brian.run(&s.inputs);
        let behaviors = brian
            .trace()
            .behaviors
            .iter()
            .map(|(name, level, activity)| BehaviorState {
                name: (*name).to_string(),
                level: *level,
                ran: activity.map(|(cando, want)| (cando.value, want.value)),
            })
            .collect();
        let outcome = Outcome { situation: s.name, commands, behaviors };
        if verbose {
            print_outcome(&s, &outcome);
        }
        outcomes.push(outcome);
    }
    Ok(outcomes)
}

fn print_outcome(s: &Situation, o: &Outcome) {
    println!("== {}", s.name);
    let inputs: Vec<String> = s.inputs.iter().map(|(n, v, _)| format!("{n} {v}")).collect();
    println!("   inputs:    {}", inputs.join(", "));
    for BehaviorState { name, level, ran } in &o.behaviors {
        match ran {
            Some((cando, want)) => println!(
                "   level {level} {name:<13} runs: CANDO {cando:.2}, WANT {want:.2}{}",
                if *want > WANT_THRESHOLD { "" } else { " (not above 0.49: weight 0)" }
            ),
            None => {
                println!("   level {level} {name:<13} idle (CANDO not above {DEFAULT_THRESHOLD})")
            }
        }
    }
    // The Messenger's job: send these set-points to the actuators.
    match (o.commands.get("SpeedModule"), o.commands.get("SpeedAngle")) {
        (Some(speed), Some(angle)) => {
            println!(
                "   commands:  SpeedModule {speed:.1} cm/s, SpeedAngle {angle:.1}° ({})\n",
                direction(*angle)
            );
        }
        _ => println!("   commands:  {:?}\n", o.commands),
    }
}

/// Entry point of the example.
pub fn main() -> Result<(), BrianError> {
    let dir = config_dir();
    println!("Mr. BRIAN, harvester configuration {}\n", dir.display());
    run(&dir, true)?;
    Ok(())
}
