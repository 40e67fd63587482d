//! # mrt-sim: the embedded default world
//!
//! A simulated Middle Size League soccer match in which every robot runs the real MRT stack.
//! The physics is `rapier2d` seen from above ([`world`]); the rules are a referee
//! ([`referee`]: READY, SET, PLAYING, ...); robots see through camera images the simulator
//! renders ([`render`], read by the robot's vision), or through an object sensor that reports
//! what a camera would detect (`--percepts oracle`, the fast mode); they feel their motion
//! through optical mice and wheel encoders and hear through a sonar ring ([`sensor`]); each
//! robot's world state fuses odometry and sightings
//! into its own pose estimate (`mrt-world`'s [`WorldModel`](mrt_world::WorldModel)); between their
//! behaviors and their motors sits guidance ([`mrt_plan::guidance::Guidance`], see [`bus`]).
//!
//! ```
//! use mrt_sim::config::SimConfig;
//! use mrt_core::Twist;
//! use mrt_sim::world::World;
//!
//! let mut world = World::new(&SimConfig::default(), 1);
//! world.place_robot(0, mrt_core::Pose2::new(0.0, 0.0, 0.0));
//! world.drive(0, Twist { vx: 1.0, vy: 0.0, omega: 0.0 });
//! for _ in 0..100 {
//!     world.step(); // 10 ms each
//! }
//! assert!(world.robot(0).unwrap().x > 0.2);
//! ```
#![deny(missing_docs)]

pub mod bus;
pub mod config;
pub mod devices;
pub mod drivers;
pub mod error;
pub mod game;
pub mod indoor;
pub mod metrics;
pub mod mice_calibration;
pub mod plot;
pub mod referee;
pub mod remote;
pub mod render;
pub mod sensor;
pub mod soak;
pub mod survey;
pub mod world;

pub use error::SimError;

use mrt_robot::spec::Stack;
use std::path::Path;

/// Plays one match between two stacks (`home`, `away`), `cfg.rules.team_size` robots each,
/// from `seed`, each robot an Agora running the robot program ([`bus::BusMatch`]);
/// `behaviors` overrides the compiled-in TeamChaos files; `record` keeps the frames for
/// [`game::MatchReport::to_svg`]; `progress` gets the simulated time after each cycle.
pub fn play(
    cfg: &config::SimConfig,
    seed: u64,
    (home, away): (Stack, Stack),
    behaviors: Option<&Path>,
    record: bool,
    mut progress: impl FnMut(f64),
) -> Result<game::MatchReport, SimError> {
    let go_on = |t| {
        progress(t);
        true
    };
    play_recorded(cfg, seed, (home, away), behaviors, record, None, go_on)
}

/// [`play`], with every robot's messages and the truth written into `recorder` when given
/// ([`bus::BusMatch::recorded`]; `mrt sim --record`); `go_on` is called with the simulated
/// time after each cycle and ends the match early when it says `false` (Ctrl-C), so that the
/// recording can be finished ([`bus::BusMatch::play_while`]).
pub fn play_recorded(
    cfg: &config::SimConfig,
    seed: u64,
    (home, away): (Stack, Stack),
    behaviors: Option<&Path>,
    record: bool,
    recorder: Option<mrt_monitor::SharedRecorder>,
    go_on: impl FnMut(f64) -> bool,
) -> Result<game::MatchReport, SimError> {
    let mut m = bus::BusMatch::recorded(cfg, seed, home, Some(away), behaviors, recorder)?;
    m.record_frames(record);
    m.play_while(go_on)
}
