//! # mrt-core: the types every MRT crate shares
//!
//! MRT (Modular Robotic Toolkit) is built of small modules that talk over one message bus
//! (DCDT, MRT manual chapter 3). This crate holds what all of them agree on:
//!
//! - **identifiers** of the DCDT vocabulary: [`AgoraId`], [`MemberId`], [`MsgType`], and the
//!   [`Message`] trait that makes a Rust type a message;
//! - **time**: the [`Clock`] trait with a [`WallClock`] for real robots and a manually advanced
//!   [`SimClock`] for the simulator. Everything in DCDT reads time only through a `Clock`, so a
//!   simulated match runs as fast as the CPU allows and is reproducible;
//! - **frames and units** ([`frames`]): field, team and robot frames as types
//!   ([`frames::Framed`]), their named conversions, and the one millimetre factor of the edges;
//! - **2D geometry** on top of `nalgebra`: [`Vec2`], [`Point2`], [`Pose2`] and angle helpers
//!   ([`normalize_angle`], [`angle_diff`]).
//!
//! ```
//! use mrt_core::{Clock, Pose2, SimClock, Time, Vec2};
//! use std::f64::consts::FRAC_PI_2;
//! use std::time::Duration;
//!
//! // A simulated clock only moves when told to.
//! let clock = SimClock::new();
//! clock.advance(Duration::from_millis(20));
//! assert_eq!(clock.now(), Time::from_millis(20));
//!
//! // A robot at (1, 0) facing +y sees a point 2 m ahead at (1, 2) in the field frame.
//! let robot = Pose2::new(1.0, 0.0, FRAC_PI_2);
//! let p = robot.transform_point(Vec2::new(2.0, 0.0).into());
//! assert!((p.x - 1.0).abs() < 1e-12 && (p.y - 2.0).abs() < 1e-12);
//! ```
//!
//! | seed name (MRT manual ch. 3) | Rust type |
//! |---|---|
//! | Agora ID | [`AgoraId`] |
//! | Member ID | [`MemberId`] |
//! | Message type | [`MsgType`] |
//! | `DCDT_TIME` | [`Time`] |
//! | a typed DCDT message (§3.2) | [`Message`] (the standard ones: crate `mrt-msgs`) |
#![deny(missing_docs)]

mod file_error;
pub mod frames;
mod geometry;
mod ids;
mod message;
mod read;
mod text;
mod time;

pub use file_error::{line_column, FileError};
pub use geometry::{
    angle_diff, arc_displacement, arc_velocity, normalize_angle, normalize_angle_positive,
    ring_runs, sinc, Point2, Pose2, Twist, Vec2,
};
pub use ids::{AgoraId, MemberId, MsgType};
pub use message::{Message, RESERVED_TYPES_START};
pub use read::{read_bounded, read_text, MAX_CONFIG_BYTES, MAX_LOG_BYTES, MAX_SCRIPT_BYTES};
pub use text::printable;
pub use time::{Clock, SharedClock, SimClock, Time, WallClock};

/// The names most MRT code needs, for `use mrt_core::prelude::*`.
pub mod prelude {
    pub use crate::{
        AgoraId, Clock, MemberId, MsgType, Point2, Pose2, SharedClock, SimClock, Time, Twist, Vec2,
        WallClock,
    };
}
