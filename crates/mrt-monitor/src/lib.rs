//! # mrt-monitor: seeing what the robots think
//!
//! The seeds' teams looked into their robots with monitors (ThinkingCap's HBM monitor, ThinkingCap/TeamChaos
//! report §4.1 and §5.1; ISocRob's Monitor, ISocRob-2000 report §3.2.7). This crate is MRT's: it listens
//! on the bus like any Member and never reaches into an engine's internals.
//!
//! - [`record`]: a [`Recorder`] writes messages into an [MCAP](https://mcap.dev) file, one
//!   channel per topic, each message JSON with a JSON schema per type (derived from the Rust
//!   types with `schemars`), log times on the clock of the bus (the simulated clock in
//!   `mrt sim`), zstd-compressed chunks. Foxglove, Lichtblick and the `mcap` libraries of
//!   other languages read it.
//! - [`tap`]: a [`Tap`] is a Member that records every catalogue message of its Agora
//!   (`mrt sim --record FILE.mcap` puts one in each robot).
//! - [`catalogue`]: the message types a tap knows, with their schemas.
//! - [`profile`]: a [`RecordProfile`]: every message with every digit (the default), or a
//!   compact file a user can mail (`mrt sim --record FILE --compact`: the bulky high-rate types
//!   at 2 Hz of the simulated clock, floats with 4 decimals).
//! - [`foxglove`]: Foxglove's well-known schemas beside MRT's own: the field and the truth as
//!   `foxglove.SceneUpdate` (`/field`, `/scene`), each robot's believed pose as a
//!   `foxglove.FrameTransform` (`/<robot>/pose`), errors and faults as `foxglove.Log` (`/log`).
//! - [`camera`]: camera images as Foxglove's `foxglove.CompressedImage` (JPEG), recorded at a
//!   chosen rate ([`Recorder::with_images`]).
//! - [`view`]: a [`Timeline`] of frames, each the simulator's truth and every robot's beliefs
//!   in the field frame, from a recording or live from a recorder's listener.
//! - [`accuracy`]: how far each robot's beliefs were from the truth in a recording that
//!   holds both, the same method for every world (`mrt replay FILE --accuracy`).
//! - `serve` (feature `serve`): the web monitor that draws a timeline in a browser
//!   (`mrt sim --serve`, `mrt replay FILE --serve`).
//!
//! ```
//! use mrt_core::Time;
//! use mrt_monitor::Recorder;
//! use mrt_msgs::GameInfo;
//!
//! let path = std::env::temp_dir().join(format!("mrt-monitor-doc-{}.mcap", std::process::id()));
//! let mut rec = Recorder::create(&path)?;
//! rec.record("/home/0/GameInfo", Time::from_secs_f64(0.1), &GameInfo::default())?;
//! let summary = rec.finish()?;
//! assert_eq!((summary.messages, summary.channels), (1, 1));
//! # std::fs::remove_file(&path).ok();
//! # Ok::<(), mrt_monitor::RecordError>(())
//! ```
#![deny(missing_docs)]

pub mod accuracy;
pub mod camera;
pub mod catalogue;
pub mod foxglove;
pub mod profile;
pub mod record;
pub mod replay;
#[cfg(feature = "serve")]
pub mod serve;
pub mod tap;
pub mod view;

pub use profile::RecordProfile;
pub use record::{RecordError, RecordSummary, Recorder, SharedRecorder};
pub use replay::{Damage, Recording, ReplayError};
pub use tap::Tap;
pub use view::{MatchInfo, SharedTimeline, Timeline, Truth};
