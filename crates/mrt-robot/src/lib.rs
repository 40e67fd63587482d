//! # mrt-robot: the robot program
//!
//! What runs on one robot, unchanged whether its hardware is real or simulated (MRT manual
//! §2.1: sensing, reasoning and acting modules over one bus; drivers apart from processing):
//!
//! - the **hardware interface** ([`devices::Devices`]: camera, mice and wheels, sonars,
//!   motors, kicker) and the **base** ([`base::Base`]: kinematics and the AIRBoard-style
//!   [`base::MotorDriver`], manual ch. 5);
//! - the **robot cycle**, defined once ([`members`]): the driver Members, the world state
//!   (`mrt-world`), the behaviors, the planner and guidance (`mrt-plan`, [`planner`]), the
//!   motor driver and the fault book,
//!   put into the robot's Agora by [`members::add_robot`];
//! - the **[`commander::Commander`]** (TeamChaos' Commander Module) that adapts a team's
//!   behaviors to the body, and the **behavior stacks** ([`stacks`]: TeamChaos on ThinkingCap,
//!   Team Milan on Mr. BRIAN, Team ISocRob's Machine on a blackboard ([`isocrob`]), the
//!   hand-written `Chaser`) behind the [`brain::Brain`] trait;
//! - the **[`config::RobotConfig`]**: what belongs to the robot (base, sensors, field, stack),
//!   apart from any simulator's world;
//! - the runner of a robot whose devices are reached over the bus ([`remote::RemoteRobot`]);
//! - [`rerun`]: a robot's behaviors re-run on the world snapshots a recording kept.
//!
//! It depends on no simulator: `cargo tree -p mrt-robot -e normal` has no physics engine and no
//! referee. The simulator (`mrt-sim`) is one implementation of [`devices::Devices`].
//!
//! ```
//! use mrt_msgs::{lps, Lpo, WorldSnapshot};
//! use mrt_robot::brain::Brain;
//! use mrt_robot::stacks::Chaser;
//!
//! // The baseline player sees the ball 1 m straight ahead: it goes for it.
//! let mut w = WorldSnapshot::default();
//! w.game_state = mrt_msgs::GameState::Playing;
//! w.lps[lps::BALL] = Lpo { rho: 1.0, theta: 0.0, reliability: 1.0, seen_ago: 0.0 };
//! let cmd = Chaser::default().cycle(&w);
//! assert!(cmd.twist.vx > 0.0, "{cmd:?}");
//! ```
#![deny(missing_docs)]

pub mod base;
pub mod brain;
pub mod commander;
pub mod config;
pub mod devices;
pub mod error;
pub mod files;
pub mod isocrob;
pub mod look_around;
pub mod members;
pub mod mission;
pub mod planner;
pub mod remote;
pub mod rerun;
pub mod spec;
pub mod stacks;
pub mod world;

pub use error::RobotError;
