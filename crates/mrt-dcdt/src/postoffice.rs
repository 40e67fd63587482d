//! The PostOffice of an Agora (MRT manual §3.1) and the InnerLinkManager that joins several
//! Agoras of one process.

use crate::config::PolicyKind;
use crate::msg::MsgRef;
use crate::parcel::{InlineMsg, Make};
use crate::policy::{MailboxBounds, MailboxReport, Policy, RequestType, LOCAL, REMOTE};
use crate::waker::Waker;
use arc_swap::ArcSwap;
use mrt_core::{AgoraId, MemberId, MsgType};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Counters of a PostOffice, for monitoring.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PostOfficeStats {
    /// Messages shared by this Agora's Members that no Member anywhere subscribed to (these are
    /// not even allocated). Delivered messages are not counted: that would put an atomic
    /// read-modify-write on every message's path.
    pub unsubscribed: u64,
}

/// "Members of the Agora can exchange messages through the PostOffice, using a typical
/// publish/subscribe approach" (§3.1). One per Agora; its [`PolicyKind`] comes from the
/// configuration file.
///
/// Members use it through their [`Context`](crate::Context) (`subscribe`, `share_msg`,
/// `receive_msg`, ...); this type exposes what tools need: the policy, statistics and the
/// subscription table.
pub struct PostOffice {
    agora: AgoraId,
    kind: PolicyKind,
    bounds: MailboxBounds,
    pub(crate) policy: Policy,
    unsubscribed: AtomicU64,
}

impl PostOffice {
    pub(crate) fn new(agora: AgoraId, kind: PolicyKind, bounds: MailboxBounds) -> Self {
        Self {
            agora,
            kind,
            bounds,
            policy: Policy::new(kind, bounds),
            unsubscribed: AtomicU64::new(0),
        }
    }

    /// The Agora this PostOffice belongs to.
    pub fn agora_id(&self) -> AgoraId {
        self.agora
    }

    /// The policy in use.
    pub fn policy(&self) -> PolicyKind {
        self.kind
    }

    /// The bounds of a subscription's buffer when its Member gives none
    /// ([`Endpoint::subscribe_bounded`](crate::Endpoint::subscribe_bounded) does).
    pub fn mailbox_bounds(&self) -> MailboxBounds {
        self.bounds
    }

    /// Counters since the Agora was created.
    pub fn stats(&self) -> PostOfficeStats {
        PostOfficeStats { unsubscribed: self.unsubscribed.load(Ordering::Relaxed) }
    }

    /// The subscriptions of one type: which Members, and for which [`RequestType`].
    pub fn subscribers(&self, ty: MsgType) -> Vec<(MemberId, RequestType)> {
        let subs = self.policy.subscriptions();
        subs.iter()
            .filter(|(t, _)| *t == ty)
            .flat_map(|(_, s)| s.iter().map(|(m, mask)| (MemberId(*m as u32), request_type(*mask))))
            .collect()
    }

    /// The message types some Member here subscribed to from other Agoras (`Remote` or `All`).
    pub fn remote_interest(&self) -> Vec<MsgType> {
        let subs = self.policy.subscriptions();
        subs.iter()
            .filter(|(_, s)| s.iter().any(|&(_, mask)| mask & REMOTE != 0))
            .map(|(t, _)| t)
            .collect()
    }

    /// Messages waiting in a Member's mailbox, all its subscriptions together. Under `PMQ`
    /// this includes the (at most one per subscription) messages its endpoint has taken out to
    /// put them in arrival order.
    pub fn pending(&self, member: MemberId) -> usize {
        self.policy.pending(member.0 as usize)
    }

    /// What each of a Member's subscription buffers did so far (bounds, messages dropped or
    /// refused by the overflow policy of [`MailboxBounds`]), in subscription order; also in
    /// every [`MemberReport`](crate::MemberReport).
    pub fn mailbox_reports(&self, member: MemberId) -> Vec<MailboxReport> {
        self.policy.reports(member.0 as usize)
    }

    pub(crate) fn register(&self, member: MemberId, waker: Arc<Waker>) {
        self.policy.register(member.0 as usize, waker)
    }

    fn origin(&self, from: AgoraId) -> u8 {
        if from == self.agora {
            LOCAL
        } else {
            REMOTE
        }
    }

    #[inline]
    pub(crate) fn count_shared(&self, delivered: usize) {
        if delivered == 0 {
            self.unsubscribed.fetch_add(1, Ordering::Relaxed);
        }
    }
}

fn request_type(mask: u8) -> RequestType {
    match mask {
        LOCAL => RequestType::Local,
        REMOTE => RequestType::Remote,
        _ => RequestType::All,
    }
}

/// The set of PostOffices a message is shared with: the creating Agora's own, plus every other
/// Agora of the process joined by an [`InnerLinkManager`].
#[derive(Clone)]
pub(crate) enum Route {
    Alone(Arc<PostOffice>),
    Community(InnerLinkManager),
}

impl Route {
    /// Whether a message of `ty` created in `from` would reach anybody.
    pub(crate) fn has_subscribers(&self, from: AgoraId, ty: MsgType) -> bool {
        match self {
            Route::Alone(po) => po.policy.has_subscribers(ty, po.origin(from)),
            Route::Community(c) => c
                .post_offices
                .load()
                .iter()
                .any(|po| po.policy.has_subscribers(ty, po.origin(from))),
        }
    }

    /// The types some Member of the route subscribed to from other Agoras.
    pub(crate) fn remote_interest(&self) -> Vec<MsgType> {
        match self {
            Route::Alone(po) => po.remote_interest(),
            Route::Community(c) => {
                c.post_offices.load().iter().flat_map(|po| po.remote_interest()).collect()
            }
        }
    }

    /// Shares a message created in `from` with every matching subscriber; `make` builds it
    /// once, and only if somebody subscribed. Returns the number of mailboxes reached.
    #[inline]
    pub(crate) fn share(&self, from: AgoraId, ty: MsgType, make: &mut dyn Make) -> usize {
        match self {
            Route::Alone(po) => po.policy.deliver(ty, po.origin(from), make),
            Route::Community(c) => {
                let list = c.post_offices.load();
                let mut once = BuiltOnce { make, shared: None, inline: None };
                list.iter().map(|po| po.policy.deliver(ty, po.origin(from), &mut once)).sum()
            }
        }
    }
}

/// A message built once for the PostOffices of a community, in whichever form each asks.
struct BuiltOnce<'a> {
    make: &'a mut dyn Make,
    shared: Option<MsgRef>,
    inline: Option<Option<InlineMsg>>,
}

impl Make for BuiltOnce<'_> {
    fn shared(&mut self) -> MsgRef {
        self.shared.get_or_insert_with(|| self.make.shared()).clone()
    }
    fn inline(&mut self) -> Option<InlineMsg> {
        *self.inline.get_or_insert_with(|| self.make.inline())
    }
}

/// Joins several Agoras of one process so their Members exchange messages without copies or
/// serialization (the manual's *InnerLinkManager*, §3.1 and figure 3.2). This is how a test or
/// the simulator emulates several robots in one process.
///
/// For a receiving Member, a message is `Local` when it was created in its own Agora and
/// `Remote` when another Agora created it; [`RequestType`] filters on that.
///
/// ```
/// use mrt_dcdt::{Agora, InnerLinkManager};
/// let ilm = InnerLinkManager::new();
/// let robot1 = Agora::builder(1).inner_link(&ilm).build()?;
/// let robot2 = Agora::builder(2).inner_link(&ilm).build()?;
/// assert_eq!(ilm.agoras(), vec![robot1.id(), robot2.id()]);
/// # Ok::<(), mrt_dcdt::DcdtError>(())
/// ```
#[derive(Clone, Default)]
pub struct InnerLinkManager {
    post_offices: Arc<ArcSwap<Vec<Arc<PostOffice>>>>,
}

impl InnerLinkManager {
    /// An empty community.
    pub fn new() -> Self {
        Self::default()
    }

    /// The ids of the joined Agoras, in joining order.
    pub fn agoras(&self) -> Vec<AgoraId> {
        self.post_offices.load().iter().map(|p| p.agora).collect()
    }

    pub(crate) fn join(&self, po: Arc<PostOffice>) -> Result<(), crate::DcdtError> {
        let mut duplicate = false;
        self.post_offices.rcu(|list| {
            duplicate = list.iter().any(|p| p.agora == po.agora);
            let mut next = (**list).clone();
            if !duplicate {
                next.push(po.clone());
            }
            next
        });
        if duplicate {
            return Err(crate::DcdtError::DuplicateAgora(po.agora));
        }
        Ok(())
    }

    pub(crate) fn leave(&self, agora: AgoraId) {
        self.post_offices
            .rcu(|list| list.iter().filter(|p| p.agora != agora).cloned().collect::<Vec<_>>());
    }
}
