//! Executors: who runs the Members, when, and on which thread.
//!
//! Scheduling sits behind this one seam. Both executors drive Members through the same runner
//! (init, jobs, panic isolation with backoff, close), so a Member behaves the same in both:
//!
//! - [`ThreadedExecutor`]: the manual's model, each activated Member on its own thread, in
//!   real time ([`Agora::lets_work`](crate::Agora::lets_work) uses it);
//! - [`SteppedExecutor`]: every Member of several Agoras, one at a time in a fixed order, on a
//!   [`SimClock`](mrt_core::SimClock), as fast as the CPU allows. Same inputs, same message
//!   trace, every run: this is what the simulator uses.

mod stepped;
mod threaded;

pub use stepped::SteppedExecutor;
pub use threaded::ThreadedExecutor;

use crate::member::MemberReport;
use mrt_core::{AgoraId, MemberId};

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExitReason {
    /// Every Member reached TERMINATING.
    AllTerminated,
    /// A Member or a [`ShutdownHandle`](crate::ShutdownHandle) called shutdown.
    Shutdown,
    /// A stepped run reached the time it was asked to run to; Members are still alive.
    TimeLimit,
}

/// What happened in a run of one Agora.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunReport {
    /// The Agora.
    pub agora: AgoraId,
    /// Why the run ended.
    pub exit: ExitReason,
    /// One entry per activated Member, in the order they were added.
    pub members: Vec<MemberReport>,
}

impl RunReport {
    /// The report of one Member.
    pub fn member(&self, id: MemberId) -> Option<&MemberReport> {
        self.members.iter().find(|m| m.id == id)
    }

    /// Best-effort messages dropped from the Members' mailboxes, all together (see
    /// [`MemberReport::mailboxes`] for who and which subscription).
    pub fn dropped(&self) -> u64 {
        self.members.iter().map(MemberReport::dropped).sum()
    }

    /// `Reliable` messages the Members' mailboxes refused, all together: not zero means a
    /// Member fell [`MailboxBounds::reliable_limit`](crate::MailboxBounds::reliable_limit)
    /// messages behind.
    pub fn refused(&self) -> u64 {
        self.members.iter().map(MemberReport::refused).sum()
    }
}
