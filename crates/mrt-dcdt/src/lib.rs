//! # mrt-dcdt: the DCDT publish/subscribe middleware
//!
//! DCDT (Device Communities Development Toolkit, MRT manual chapter 3) is the bus every MRT
//! module talks over. An [`Agora`] hosts [`Member`]s; Members exchange messages through the
//! Agora's [`PostOffice`] by subscribing to message types and sharing messages, without
//! knowing who produces or consumes them. Several Agoras in one process form a community
//! ([`InnerLinkManager`]), which is how a test or the simulator emulates several robots.
//!
//! ```
//! use mrt_dcdt::prelude::*;
//! use mrt_core::SimClock;
//! use serde::{Deserialize, Serialize};
//! use std::time::Duration;
//!
//! #[derive(Serialize, Deserialize)]
//! struct Ping(u32);
//! impl Message for Ping {
//!     const TYPE: MsgType = MsgType(1);
//!     const NAME: &'static str = "Ping";
//! }
//!
//! struct Producer(u32);
//! impl Member for Producer {
//!     fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
//!         self.0 += 1;
//!         ctx.publish(Ping(self.0));
//!         Ok(())
//!     }
//! }
//!
//! #[derive(Default)]
//! struct Consumer(Vec<u32>);
//! impl Member for Consumer {
//!     fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
//!         ctx.subscribe_to::<Ping>(RequestType::All);
//!         Ok(())
//!     }
//!     fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
//!         while let Some(msg) = ctx.receive_msg() {
//!             self.0.push(msg.get::<Ping>()?.0);
//!         }
//!         if self.0.len() == 3 {
//!             ctx.shutdown();
//!         }
//!         Ok(())
//!     }
//! }
//!
//! // Deterministic, simulated time: the same trace on every run.
//! let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(1));
//! let mut agora = exec.agora_builder(1).build()?;
//! let p = agora.add_member(Producer(0), Activation::Periodic(Duration::from_millis(10)));
//! let c = agora.add_member(Consumer::default(), Activation::OnMessage);
//! agora.activate_member(p)?;
//! agora.activate_member(c)?;
//! exec.add_agora(agora)?;
//! exec.run_for(Duration::from_secs(1));
//! let report = exec.finish().remove(0);
//! assert_eq!(report.exit, ExitReason::Shutdown);
//! assert_eq!(report.member(c).map(|m| m.cycles), Some(3));
//! # Ok::<(), mrt_dcdt::DcdtError>(())
//! ```
//!
//! The same Agora runs in real time, each Member on its own thread, with
//! [`Agora::lets_work`].
//!
//! | seed name (MRT manual ch. 3) | Rust |
//! |---|---|
//! | `DCDT_Agora`, STANDALONE / NETWORK | [`Agora::standalone`], [`Agora::from_config`], [`AgoraMode`] |
//! | `AddMember`, `ActivateMember`, `LetsWork`, `Shutdown` | [`Agora::add_member`], [`Agora::activate_member`], [`Agora::lets_work`], [`Endpoint::shutdown`] |
//! | `DCDT_Member`: `Init`, `DoYourJob`, `Close` | [`Member`] |
//! | periodic / cyclic / message-driven Member | [`Activation`] |
//! | `TERMINATING` and other states | [`MemberState`] |
//! | `SubscribeMsgType`, `UnSubscribeMsgType`, `UnSubscribeAll` | [`Endpoint::subscribe`], [`Endpoint::unsubscribe`], [`Endpoint::unsubscribe_all`] |
//! | `DCDT_LOCAL_MSG`, `DCDT_REMOTE_MSG`, `DCDT_ALL_MSG` | [`RequestType`] |
//! | a Member's message queue (§3.1), bounded per subscription | [`MailboxBounds`], [`MailboxReport`] in [`MemberReport`] |
//! | `CreateMsg`, `ShareMsg`, `ReceiveMsg`, `RemoveCurrMsg` | [`Endpoint::create_msg`], [`Endpoint::share_msg`], [`Endpoint::receive_msg`], [`Endpoint::remove_curr_msg`] |
//! | `DCDT_Msg`, header, payload | [`Msg`], [`MsgHeader`], [`Payload`]; typed: [`Message`], [`Endpoint::publish`], [`Msg::get`] |
//! | PostOffice policies `SLWB`, `SLWDWCV`, `SLWSM` | [`PolicyKind`] (plus the default `PMQ`) |
//! | InnerLinkManager | [`InnerLinkManager`] |
//! | Agora configuration file (§3.3.1) | [`config::AgoraConfig`] |
//! | XML self-describing message (§3.2) | `describe::SelfDescribing`, any message's form generated from its type by `describe::describe` (feature `describe`) |
//!
//! Start with [`Agora`], [`Member`] and [`Context`]; for simulation, [`SteppedExecutor`].
#![deny(missing_docs)]

mod agora;
pub mod config;
#[cfg(feature = "describe")]
pub mod describe;
mod egress;
mod endpoint;
mod error;
mod executor;
mod frame;
mod inputs;
mod member;
mod msg;
pub mod outlet;
mod parcel;
mod policy;
mod pool;
mod postoffice;
mod shared;
mod waker;
pub mod wire;

pub use agora::{Agora, AgoraBuilder, AgoraMode, ShutdownHandle};
pub use config::PolicyKind;
pub use endpoint::{Context, Endpoint, MsgBuilder};
pub use error::DcdtError;
pub use executor::{ExitReason, RunReport, SteppedExecutor, ThreadedExecutor};
pub use inputs::Inputs;
pub use member::{
    Activation, Member, MemberError, MemberReport, MemberState, BASE_BACKOFF, MAX_BACKOFF,
};
pub use mrt_core::{AgoraId, MemberId, MsgType, Time};
pub use msg::{
    DeliveryWarranty, Message, Msg, MsgHeader, MsgRef, Payload, RawPayload, RESERVED_TYPES_START,
};
pub use outlet::{AgoraPort, Outlet};
pub use policy::{
    MailboxBounds, MailboxReport, RequestType, DEFAULT_MAILBOX_CAPACITY, DEFAULT_RELIABLE_LIMIT,
};
pub use postoffice::{InnerLinkManager, PostOffice, PostOfficeStats};

/// The names a Member implementation needs, for `use mrt_dcdt::prelude::*`.
pub mod prelude {
    pub use crate::{
        Activation, Agora, Context, DeliveryWarranty, Endpoint, ExitReason, Member, MemberError,
        MemberState, Message, MsgRef, MsgType, PolicyKind, RequestType, SteppedExecutor,
    };
}
