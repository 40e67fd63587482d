//! # mrt-team: team coordination
//!
//! How the robots of one team agree who does what, as plain libraries fed by the reports the
//! teammates send each other (`mrt_msgs::MateReport`) and their own clock:
//!
//! | seed name | Rust |
//! |---|---|
//! | TeamChaos' ball booking, a distributed mutual exclusion: `bookBall`, `releaseBookedBall`, `haveBookedBall` (ThinkingCap/TeamChaos report §3.3) | [`booking::BallBooking`] |
//! | the role the team agreed on: `getRole` (ThinkingCap/TeamChaos report §3.3, figure 8's roles) | [`roles::allocate`], [`roles::Role`] |
//!
//! | SCARE (MRT manual ch. 11): jobs and schemata, attitude and opportunity, the agenda, the allocation | [`scare::allocate`], [`scare::Activities`] |
//! | SCARE's sequencer and monitor | [`scare::sequencer::Sequencer`] |
//! | Team Milan's activities (BringBall, PassageToMate, Defense, ...) | [`scare::soccer`] |
//! | ISocRob's Machine µAgent: modes, roles, the attacker's state machine, the goalkeeper's modes, `should_I_go` (ISocRob-2000 report §3.2.2) | [`isocrob`] |
//!
//! ```
//! use mrt_team::booking::{BallBooking, BookingParams};
//!
//! // A robot that hears no teammate books for itself alone.
//! let mut me = BallBooking::new(3, BookingParams::default());
//! me.want(10.0, true);
//! me.update(10.0);
//! assert!(me.holds(10.0) && me.alone(10.0));
//! ```
//!
//! No feature flags, no errors: bad input (late, repeated or odd reports) is dropped and
//! counted.
#![deny(missing_docs)]

pub mod booking;
pub mod isocrob;
pub mod roles;
pub mod scare;
