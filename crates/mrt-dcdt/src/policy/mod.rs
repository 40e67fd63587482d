//! PostOffice policies: how messages get from a producer to the subscribers' mailboxes.
//!
//! The MRT manual names three policies in the Agora configuration file (§3.3.1) without
//! describing them; MRT implements each as a real, different strategy, and adds a faster one
//! as the default (numbers in `docs/performance.md`):
//!
//! | config name | strategy | a subscriber sees |
//! |---|---|---|
//! | `SLWB` | **S**ingle **L**ock **W**ith **B**uffer: one mutex guards the subscription table and every Member's FIFO buffer; the producer writes into each buffer itself | every message, in order |
//! | `SLWDWCV` | **S**ingle **L**ock **W**ith **D**ispatcher **W**ith **C**ondition **V**ariable: the producer appends to one main queue under the lock and signals a condition variable; a dispatcher (the manual's *MsgManager* system Member) moves messages to the Members' buffers | every message, in order, one hand-off later |
//! | `SLWSM` | **S**ingle **L**ock **W**ith **S**ingle **M**essage: one mutex; each Member keeps only the latest message of each type | the latest message of each type; older unread ones are overwritten |
//! | `PMQ` (default) | **P**er-**M**ember **Q**ueues: the subscription table is an immutable snapshot swapped on (rare) changes, read without locks; each subscription has a preallocated lock-free ring | every message, in order |
//!
//! Under `SLWB`, `SLWDWCV` and `PMQ` every subscription's buffer is bounded by
//! [`MailboxBounds`]; what a full one does is its overflow policy (see there). `SLWSM` keeps one
//! message per type by definition.

mod pmq;
mod single_lock;

pub(crate) use pmq::Pmq;
pub(crate) use single_lock::SingleLock;

use crate::config::PolicyKind;
use crate::error::DcdtError;
use crate::msg::MsgRef;
use crate::parcel::Make;
use crate::pool::MsgPool;
use crate::waker::Waker;
use mrt_core::{AgoraId, MsgType};
use rustc_hash::FxHashMap;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Which messages a subscription asks for (`DCDT_RequestType`, §3.3.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RequestType {
    /// `DCDT_LOCAL_MSG`: messages created in this Agora.
    Local,
    /// `DCDT_REMOTE_MSG`: messages created in another Agora.
    Remote,
    /// `DCDT_ALL_MSG` (the default): both.
    #[default]
    All,
}

impl RequestType {
    pub(crate) fn mask(self) -> u8 {
        match self {
            RequestType::Local => LOCAL,
            RequestType::Remote => REMOTE,
            RequestType::All => LOCAL | REMOTE,
        }
    }
}

/// Messages one subscription buffers by default: [`MailboxBounds::capacity`].
pub const DEFAULT_MAILBOX_CAPACITY: usize = 2048;
/// Messages one subscription holds at most when they are `Reliable`, by default:
/// [`MailboxBounds::reliable_limit`].
pub const DEFAULT_RELIABLE_LIMIT: usize = 16 * DEFAULT_MAILBOX_CAPACITY;

/// How many messages one subscription's buffer (a Member's mailbox for one message type) holds
/// while they wait for the Member to receive them, and so how much memory a slow Member can
/// make the bus keep. Set per Agora ([`AgoraBuilder::mailbox_bounds`](crate::AgoraBuilder::mailbox_bounds))
/// or per subscription ([`Endpoint::subscribe_bounded`](crate::Endpoint::subscribe_bounded)).
///
/// **Overflow policy** (policies `PMQ`, `SLWB`, `SLWDWCV`), when a message arrives for a
/// subscription that already holds `capacity` messages:
///
/// - *best-effort* messages ([`DeliveryWarranty::None`](crate::DeliveryWarranty::None) and
///   `Retransmit`): the **oldest** waiting message of the subscription is dropped to make room,
///   and counted ([`MailboxReport::dropped`]). A robot wants the freshest sensor reading, not
///   the one from a second ago.
/// - once a subscription has received a [`DeliveryWarranty::Reliable`](crate::DeliveryWarranty::Reliable)
///   message, it **never drops**: messages beyond `capacity` wait in an overflow queue,
///   allocated only then, up to `reliable_limit` messages in all. The producer is not blocked:
///   under the [`SteppedExecutor`](crate::SteppedExecutor) every Member shares one thread, so a
///   producer waiting for its consumer would wait forever, and a Member must behave the same
///   under both executors. Past `reliable_limit` a `Reliable` message is **refused** for that
///   subscription (not delivered, counted in [`MailboxReport::refused`], logged as an error
///   once per subscription, and not counted in `publish`'s return value), and a best-effort one
///   is dropped (counted). A subscriber that far behind is a fault to fix, not a load to absorb.
///
/// Order is kept: a Member receives the messages of all its subscriptions in the order they
/// arrived, minus those dropped.
///
/// ```
/// use mrt_dcdt::{Agora, MailboxBounds};
/// let robot = Agora::builder(1).mailbox_bounds(MailboxBounds::new(256)).build()?;
/// assert_eq!(robot.post_office().mailbox_bounds().capacity, 256);
/// # Ok::<(), mrt_dcdt::DcdtError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MailboxBounds {
    /// Messages a subscription buffers before its overflow policy applies (at least 1;
    /// default [`DEFAULT_MAILBOX_CAPACITY`]). Under `PMQ` this is a ring allocated once, when
    /// the Member subscribes: 32 bytes a message, 64 KiB by default.
    pub capacity: usize,
    /// Messages a subscription that carries `Reliable` messages holds at most (at least
    /// `capacity`; default [`DEFAULT_RELIABLE_LIMIT`]).
    pub reliable_limit: usize,
}

impl Default for MailboxBounds {
    fn default() -> Self {
        Self { capacity: DEFAULT_MAILBOX_CAPACITY, reliable_limit: DEFAULT_RELIABLE_LIMIT }
    }
}

impl MailboxBounds {
    /// `capacity` messages, and 16 times as many for `Reliable` messages.
    pub fn new(capacity: usize) -> Self {
        Self { capacity, reliable_limit: capacity.saturating_mul(16) }
    }

    /// The same, with another limit for `Reliable` messages.
    pub fn with_reliable_limit(mut self, reliable_limit: usize) -> Self {
        self.reliable_limit = reliable_limit;
        self
    }

    /// Checks `1 <= capacity <= reliable_limit`.
    pub(crate) fn check(self, agora: AgoraId) -> Result<Self, DcdtError> {
        if self.capacity == 0 || self.reliable_limit < self.capacity {
            return Err(DcdtError::MailboxBounds {
                agora,
                capacity: self.capacity,
                reliable_limit: self.reliable_limit,
            });
        }
        Ok(self)
    }
}

/// What one subscription's buffer did: its bounds and the messages its overflow policy lost
/// (see [`MailboxBounds`]). Part of every [`MemberReport`](crate::MemberReport).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MailboxReport {
    /// The subscribed message type.
    pub msg_type: MsgType,
    /// Its [`MailboxBounds::capacity`] (1 under `SLWSM`, which keeps the latest message only).
    pub capacity: usize,
    /// Its [`MailboxBounds::reliable_limit`].
    pub reliable_limit: usize,
    /// Best-effort messages dropped because the Member was `capacity` messages behind (under
    /// `SLWSM`: unread messages replaced by a newer one of their type).
    pub dropped: u64,
    /// `Reliable` messages not delivered because the Member was `reliable_limit` messages
    /// behind: an error.
    pub refused: u64,
}

/// Origin bit of a message as seen by a receiving PostOffice.
pub(crate) const LOCAL: u8 = 1;
/// Origin bit of a message created in another Agora.
pub(crate) const REMOTE: u8 = 2;

/// The subscription table: for each type, who subscribed and to which origins.
/// Member indices are `MemberId.0`.
#[derive(Clone, Debug, Default)]
pub(crate) struct Subscriptions {
    by_type: FxHashMap<MsgType, Vec<(usize, u8)>>,
}

impl Subscriptions {
    pub(crate) fn subscribe(&mut self, member: usize, ty: MsgType, mask: u8) {
        let subs = self.by_type.entry(ty).or_default();
        match subs.iter_mut().find(|(m, _)| *m == member) {
            Some((_, existing)) => *existing |= mask,
            None => subs.push((member, mask)),
        }
    }

    pub(crate) fn unsubscribe(&mut self, member: usize, ty: MsgType, mask: u8) {
        if let Some(subs) = self.by_type.get_mut(&ty) {
            for (_, m) in subs.iter_mut().filter(|(m, _)| *m == member) {
                *m &= !mask;
            }
            subs.retain(|(_, m)| *m != 0);
            if subs.is_empty() {
                self.by_type.remove(&ty);
            }
        }
    }

    pub(crate) fn unsubscribe_all(&mut self, member: usize) {
        self.by_type.retain(|_, subs| {
            subs.retain(|(m, _)| *m != member);
            !subs.is_empty()
        });
    }

    /// Subscribers of `ty` whose request matches `origin`, in subscription order.
    pub(crate) fn matching(&self, ty: MsgType, origin: u8) -> impl Iterator<Item = usize> + '_ {
        self.by_type
            .get(&ty)
            .into_iter()
            .flatten()
            .filter(move |(_, m)| m & origin != 0)
            .map(|(member, _)| *member)
    }

    pub(crate) fn iter(&self) -> impl Iterator<Item = (MsgType, &[(usize, u8)])> {
        self.by_type.iter().map(|(t, s)| (*t, s.as_slice()))
    }
}

/// Where a Member's messages wait: its mailbox's reader under `PMQ`, a slot index otherwise.
pub(crate) enum MailboxRef {
    Pmq(pmq::Reader),
    Index(usize),
}

/// The policy behind a PostOffice, chosen by configuration.
pub(crate) enum Policy {
    SingleLock(SingleLock),
    Pmq(Pmq),
}

macro_rules! each {
    ($self:ident, $p:ident => $e:expr) => {
        match $self {
            Policy::SingleLock($p) => $e,
            Policy::Pmq($p) => $e,
        }
    };
}

impl Policy {
    pub(crate) fn new(kind: PolicyKind, bounds: MailboxBounds) -> Self {
        match kind {
            PolicyKind::Pmq => Policy::Pmq(Pmq::new(bounds)),
            other => Policy::SingleLock(SingleLock::new(other, bounds)),
        }
    }

    pub(crate) fn register(&self, member: usize, waker: Arc<Waker>) {
        each!(self, p => p.register(member, waker))
    }
    /// Subscribes; `bounds` (else the PostOffice's) bound the subscription's buffer when it is
    /// created, i.e. at the Member's first subscription to `ty`.
    pub(crate) fn subscribe(
        &self,
        member: usize,
        ty: MsgType,
        mask: u8,
        bounds: Option<MailboxBounds>,
    ) {
        each!(self, p => p.subscribe(member, ty, mask, bounds))
    }
    pub(crate) fn unsubscribe(&self, member: usize, ty: MsgType, mask: u8) {
        each!(self, p => p.update(|s| s.unsubscribe(member, ty, mask)))
    }
    pub(crate) fn unsubscribe_all(&self, member: usize) {
        each!(self, p => p.update(|s| s.unsubscribe_all(member)))
    }
    pub(crate) fn has_subscribers(&self, ty: MsgType, origin: u8) -> bool {
        each!(self, p => p.has_subscribers(ty, origin))
    }
    /// Delivers `msg` (built on demand by `make`) to matching subscribers; returns how many.
    #[inline]
    pub(crate) fn deliver(&self, ty: MsgType, origin: u8, make: &mut dyn Make) -> usize {
        each!(self, p => p.deliver(ty, origin, make))
    }
    /// A handle on one Member's mailbox, for its endpoint to receive without looking it up.
    pub(crate) fn mailbox(&self, member: usize) -> MailboxRef {
        match self {
            Policy::Pmq(p) => p.reader(member).map_or(MailboxRef::Index(member), MailboxRef::Pmq),
            Policy::SingleLock(_) => MailboxRef::Index(member),
        }
    }
    /// The next message; one that travelled by value is put into a block of `pool` (the
    /// receiving endpoint's, see `parcel`).
    pub(crate) fn pop(&self, mailbox: &mut MailboxRef, pool: &MsgPool) -> Option<MsgRef> {
        match (self, mailbox) {
            (_, MailboxRef::Pmq(r)) => r.pop().map(|p| p.open(pool)),
            (Policy::SingleLock(p), MailboxRef::Index(i)) => p.pop(*i),
            // A PMQ endpoint always has a reader: its mailbox is registered before it exists.
            (Policy::Pmq(_), MailboxRef::Index(_)) => None,
        }
    }
    pub(crate) fn has_pending(&self, mailbox: &MailboxRef) -> bool {
        match (self, mailbox) {
            (_, MailboxRef::Pmq(r)) => r.has_pending(),
            (Policy::SingleLock(p), MailboxRef::Index(i)) => p.has_pending(*i),
            (Policy::Pmq(_), MailboxRef::Index(_)) => false,
        }
    }
    pub(crate) fn pending(&self, member: usize) -> usize {
        each!(self, p => p.pending(member))
    }
    /// What each of a Member's subscription buffers did, in subscription order.
    pub(crate) fn reports(&self, member: usize) -> Vec<MailboxReport> {
        each!(self, p => p.reports(member))
    }
    /// Whether a dispatcher must run ([`PolicyKind::Slwdwcv`]).
    pub(crate) fn needs_dispatcher(&self) -> bool {
        matches!(self, Policy::SingleLock(p) if p.needs_dispatcher())
    }
    /// Moves queued messages to the Members' buffers once; returns how many.
    pub(crate) fn dispatch(&self) -> usize {
        match self {
            Policy::SingleLock(p) => p.dispatch(),
            Policy::Pmq(_) => 0,
        }
    }
    /// The dispatcher thread's loop, until `stop` is set and [`Policy::stop_dispatcher`] called.
    pub(crate) fn run_dispatcher(&self, stop: &AtomicBool) {
        if let Policy::SingleLock(p) = self {
            p.run_dispatcher(stop)
        }
    }
    pub(crate) fn stop_dispatcher(&self) {
        if let Policy::SingleLock(p) = self {
            p.stop_dispatcher()
        }
    }
    pub(crate) fn subscriptions(&self) -> Subscriptions {
        each!(self, p => p.subscriptions())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subscriptions_merge_and_split_request_types() {
        let mut s = Subscriptions::default();
        let t = MsgType(1);
        s.subscribe(0, t, RequestType::Local.mask());
        s.subscribe(0, t, RequestType::Remote.mask());
        s.subscribe(1, t, RequestType::Remote.mask());
        assert_eq!(s.matching(t, LOCAL).collect::<Vec<_>>(), vec![0]);
        assert_eq!(s.matching(t, REMOTE).collect::<Vec<_>>(), vec![0, 1]);
        s.unsubscribe(0, t, RequestType::Remote.mask());
        assert_eq!(s.matching(t, REMOTE).collect::<Vec<_>>(), vec![1]);
        assert_eq!(s.matching(t, LOCAL).collect::<Vec<_>>(), vec![0]);
        s.unsubscribe_all(0);
        assert_eq!(s.matching(t, LOCAL).count(), 0);
        s.unsubscribe(1, t, RequestType::All.mask());
        assert_eq!(s.iter().count(), 0, "empty entries are removed");
    }
}
