//! # mrt-sim: the embedded default world
//!
//! A simulated Middle Size League soccer match in which every robot runs the real MRT stack.
//! The physics is `rapier2d` seen from above ([`world`]); the rules are a referee
//! ([`referee`]); robots see through an object sensor that reports what a camera would
//! detect ([`sensor`]).
//!
//! ```
//! use mrt_sim::config::SimConfig;
//! use mrt_sim::world::{Drive, World};
//!
//! let mut world = World::new(&SimConfig::default(), 1);
//! world.place_robot(0, mrt_core::Pose2::new(0.0, 0.0, 0.0));
//! world.drive(0, Drive { forward: 1.0, left: 0.0, turn: 0.0 });
//! for _ in 0..100 {
//!     world.step(); // 10 ms each
//! }
//! assert!(world.robot(0).unwrap().x > 0.2);
//! ```
#![deny(missing_docs)]

pub mod bus;
pub mod config;
pub mod drivers;
pub mod game;
pub mod referee;
pub mod sensor;
pub mod teams;
pub mod world;
