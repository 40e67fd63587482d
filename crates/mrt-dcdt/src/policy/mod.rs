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
//! | `PMQ` (default) | **P**er-**M**ember **Q**ueues: the subscription table is an immutable snapshot swapped on (rare) changes, read without locks; each Member has a lock-free queue | every message, in order |

mod pmq;
mod single_lock;

pub(crate) use pmq::Pmq;
pub(crate) use single_lock::SingleLock;

use crate::config::PolicyKind;
use crate::msg::MsgRef;
use crate::waker::Waker;
use mrt_core::MsgType;
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

/// Where a Member's messages wait: its own queue under `PMQ`, a slot index otherwise.
pub(crate) enum MailboxRef {
    Pmq(Arc<pmq::Mailbox>),
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
    pub(crate) fn new(kind: PolicyKind) -> Self {
        match kind {
            PolicyKind::Pmq => Policy::Pmq(Pmq::default()),
            other => Policy::SingleLock(SingleLock::new(other)),
        }
    }

    pub(crate) fn register(&self, member: usize, waker: Arc<Waker>) {
        each!(self, p => p.register(member, waker))
    }
    pub(crate) fn subscribe(&self, member: usize, ty: MsgType, mask: u8) {
        each!(self, p => p.update(|s| s.subscribe(member, ty, mask)))
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
    pub(crate) fn deliver(
        &self,
        ty: MsgType,
        origin: u8,
        make: &mut dyn FnMut() -> MsgRef,
    ) -> usize {
        each!(self, p => p.deliver(ty, origin, make))
    }
    /// A handle on one Member's mailbox, for its endpoint to receive without looking it up.
    pub(crate) fn mailbox(&self, member: usize) -> MailboxRef {
        match self {
            Policy::Pmq(p) => p.mailbox(member).map_or(MailboxRef::Index(member), MailboxRef::Pmq),
            Policy::SingleLock(_) => MailboxRef::Index(member),
        }
    }
    pub(crate) fn pop(&self, mailbox: &MailboxRef) -> Option<MsgRef> {
        match (self, mailbox) {
            (_, MailboxRef::Pmq(b)) => b.pop(),
            (Policy::SingleLock(p), MailboxRef::Index(i)) => p.pop(*i),
            (Policy::Pmq(p), MailboxRef::Index(i)) => p.pop(*i),
        }
    }
    pub(crate) fn has_pending(&self, mailbox: &MailboxRef) -> bool {
        match (self, mailbox) {
            (_, MailboxRef::Pmq(b)) => b.has_pending(),
            (Policy::SingleLock(p), MailboxRef::Index(i)) => p.has_pending(*i),
            (Policy::Pmq(p), MailboxRef::Index(i)) => p.has_pending(*i),
        }
    }
    pub(crate) fn pending(&self, member: usize) -> usize {
        each!(self, p => p.pending(member))
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
