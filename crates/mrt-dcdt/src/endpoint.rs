//! The Member-facing PostOffice API: [`Endpoint`] (usable from any thread) and [`Context`]
//! (what a running [`Member`](crate::Member) gets each cycle).
//!
//! Method names follow the manual (§3.3.2): `subscribe` (`SubscribeMsgType`), `unsubscribe`,
//! `unsubscribe_all`, `create_msg`, `share_msg`, `receive_msg`, `remove_curr_msg`.

use crate::error::DcdtError;
use crate::msg::{DeliveryWarranty, Message, Msg, MsgHeader, MsgRef, RawPayload};
use crate::parcel::{InlineMsg, Make, Parcel};
use crate::policy::{MailboxBounds, MailboxRef, RequestType};
use crate::pool::MsgPool;
use crate::shared::AgoraShared;
use mrt_core::{AgoraId, MemberId, MsgType, Time};
use std::ops::{Deref, DerefMut};
use std::sync::Arc;

/// A raw message being filled in, from [`Endpoint::create_msg`]. Share it with
/// [`Endpoint::share_msg`].
#[derive(Debug)]
pub struct MsgBuilder {
    header: MsgHeader,
    payload: Vec<u8>,
}

impl MsgBuilder {
    /// The payload bytes, to fill in.
    pub fn payload_mut(&mut self) -> &mut Vec<u8> {
        &mut self.payload
    }
    /// Replaces the payload.
    pub fn with_payload(mut self, bytes: impl Into<Vec<u8>>) -> Self {
        self.payload = bytes.into();
        self
    }
    /// Sets the priority (0 lowest, 255 highest).
    pub fn with_priority(mut self, priority: u8) -> Self {
        self.header.priority = priority;
        self
    }
    /// The header as it will be sent.
    pub fn header(&self) -> &MsgHeader {
        &self.header
    }
}

/// A Member's handle on its Agora's PostOffice.
///
/// An endpoint belongs to one thread at a time (it is `Send`, not `Sync`): it recycles the
/// blocks of the messages it published (see `pool`). Another thread gets its own endpoint.
///
/// Running Members get one through their [`Context`]. Code that is not a Member (a driver
/// thread, a test, the simulator feeding sensor data) gets its own from
/// [`Agora::endpoint`](crate::Agora::endpoint) and uses it from any thread.
pub struct Endpoint {
    pub(crate) shared: Arc<AgoraShared>,
    pub(crate) member: MemberId,
    mailbox: MailboxRef,
    current: Option<MsgRef>,
    pool: MsgPool,
}

impl Endpoint {
    pub(crate) fn new(shared: Arc<AgoraShared>, member: MemberId) -> Self {
        let mailbox = shared.post_office.policy.mailbox(member.0 as usize);
        Self { shared, member, mailbox, current: None, pool: MsgPool::default() }
    }

    /// This endpoint's Member id.
    pub fn member_id(&self) -> MemberId {
        self.member
    }

    /// The Agora's id.
    pub fn agora_id(&self) -> AgoraId {
        self.shared.id
    }

    /// The current time on the Agora's clock.
    pub fn now(&self) -> Time {
        self.shared.clock.now()
    }

    /// Whether the Agora's clock is simulated (it advances only when its world steps it), so
    /// that wall-clock time says nothing about the robot's cycle.
    pub fn clock_is_simulated(&self) -> bool {
        self.shared.clock.is_simulated()
    }

    fn index(&self) -> usize {
        self.member.0 as usize
    }

    /// Subscribes to a message type (`SubscribeMsgType`). Subscribing twice with different
    /// request types subscribes to both.
    pub fn subscribe(&self, ty: MsgType, req: RequestType) {
        self.shared.post_office.policy.subscribe(self.index(), ty, req.mask(), None)
    }

    /// Subscribes with this subscription's own buffer bounds instead of the Agora's
    /// ([`MailboxBounds`], with its overflow policy). The bounds are fixed when the buffer is
    /// created, at the first subscription to `ty`; later calls (and a subscription again after
    /// `unsubscribe`, which keeps the buffer and the messages waiting in it) keep them.
    /// Fails, subscribing nothing, unless `1 <= capacity <= reliable_limit`.
    pub fn subscribe_bounded(
        &self,
        ty: MsgType,
        req: RequestType,
        bounds: MailboxBounds,
    ) -> Result<(), DcdtError> {
        let bounds = bounds.check(self.shared.id)?;
        self.shared.post_office.policy.subscribe(self.index(), ty, req.mask(), Some(bounds));
        Ok(())
    }

    /// Subscribes to the typed message `T`.
    pub fn subscribe_to<T: Message>(&self, req: RequestType) {
        self.subscribe(T::TYPE, req)
    }

    /// Unsubscribes from a message type (`UnSubscribeMsgType`); `RequestType::All` removes the
    /// whole subscription, `Local` or `Remote` only that half of it.
    pub fn unsubscribe(&self, ty: MsgType, req: RequestType) {
        self.shared.post_office.policy.unsubscribe(self.index(), ty, req.mask())
    }

    /// Unsubscribes from every type (`UnSubscribeAll`).
    pub fn unsubscribe_all(&self) {
        self.shared.post_office.policy.unsubscribe_all(self.index())
    }

    fn header(&self, ty: MsgType, warranty: DeliveryWarranty, priority: u8) -> MsgHeader {
        MsgHeader {
            msg_type: ty,
            member_id: self.member,
            agora_id: self.shared.id,
            priority,
            warranty,
            creation_time: self.shared.clock.now(),
        }
    }

    /// Whether a message of `ty` shared now would reach any Member, in this Agora or (for a
    /// community) another. Lets a producer skip work nobody would read.
    pub fn has_subscribers(&self, ty: MsgType) -> bool {
        self.shared.route.has_subscribers(self.shared.id, ty) || self.shared.outlet.wants(ty)
    }

    /// Creates a raw message of `ty` with delivery warranty `None` (`CreateMsg(type)`).
    pub fn create_msg(&self, ty: MsgType) -> MsgBuilder {
        self.create_msg_with(ty, DeliveryWarranty::None)
    }

    /// Creates a raw message with a delivery warranty (`CreateMsg(type, warranty)`).
    pub fn create_msg_with(&self, ty: MsgType, warranty: DeliveryWarranty) -> MsgBuilder {
        MsgBuilder { header: self.header(ty, warranty, 0), payload: Vec::new() }
    }

    /// Shares a raw message with every subscriber of its type (`ShareMsg`); returns how many
    /// mailboxes it reached (under `SLWDWCV`: how many PostOffices queued it for their
    /// dispatcher). Nobody subscribed is not an error.
    pub fn share_msg(&self, msg: MsgBuilder) -> usize {
        let MsgBuilder { header, payload } = msg;
        let mut payload = Some(payload);
        self.route(header.msg_type, &mut || {
            Msg::new(header, RawPayload::new(payload.take().unwrap_or_default())).into_ref()
        })
    }

    /// Publishes a typed message with warranty `None` and priority 0; returns how many
    /// mailboxes it reached, as [`share_msg`](Self::share_msg). When nobody subscribed,
    /// nothing is allocated.
    #[inline]
    pub fn publish<T: Message>(&self, value: T) -> usize {
        self.publish_with(value, DeliveryWarranty::None, 0)
    }

    /// Publishes a typed message with a warranty and a priority.
    pub fn publish_with<T: Message>(
        &self,
        value: T,
        warranty: DeliveryWarranty,
        priority: u8,
    ) -> usize {
        let mut publish =
            Publish { endpoint: self, value: Some(value), inlined: None, warranty, priority };
        self.route(T::TYPE, &mut publish)
    }

    /// Shares an already built message as it is (its header is kept: a message relayed from
    /// elsewhere keeps its origin). Returns how many mailboxes it reached.
    pub fn share_ref(&self, msg: &MsgRef) -> usize {
        let origin = msg.agora_id();
        let n = self.shared.route.share(origin, msg.msg_type(), &mut || msg.clone());
        self.shared.post_office.count_shared(n);
        n
    }

    #[inline]
    fn route(&self, ty: MsgType, make: &mut dyn Make) -> usize {
        let Some(outlet) = self.shared.outlet.for_type(ty) else {
            let n = self.shared.route.share(self.shared.id, ty, make);
            self.shared.post_office.count_shared(n);
            return n;
        };
        // Somebody elsewhere wants it: build it even if nobody here does, and send it out
        // after the local delivery.
        let mut built: Option<MsgRef> = None;
        let n = self
            .shared
            .route
            .share(self.shared.id, ty, &mut || built.get_or_insert_with(|| make.shared()).clone());
        let msg = built.get_or_insert_with(|| make.shared());
        outlet.send(msg);
        n
    }

    /// Takes the next message from this Member's mailbox (`ReceiveMsg`); it also becomes the
    /// current message until the next call or [`remove_curr_msg`](Self::remove_curr_msg).
    pub fn receive_msg(&mut self) -> Option<MsgRef> {
        self.current = self.shared.post_office.policy.pop(&mut self.mailbox, &self.pool);
        self.current.clone()
    }

    /// The current message: the last one [`receive_msg`](Self::receive_msg) returned.
    pub fn current_msg(&self) -> Option<&MsgRef> {
        self.current.as_ref()
    }

    /// Lets go of the current message (`RemoveCurrMsg`); it is freed when no other Member
    /// holds it.
    pub fn remove_curr_msg(&mut self) {
        self.current = None;
    }

    /// Receives the next message if it is a `T`; messages of other types before it are
    /// skipped and dropped. A convenience for Members that subscribe to one type.
    pub fn receive<T: Message>(&mut self) -> Option<MsgRef> {
        while let Some(m) = self.receive_msg() {
            if m.is::<T>() {
                return Some(m);
            }
        }
        None
    }

    /// Whether a message is waiting (cheaper than [`pending`](Self::pending)).
    #[inline]
    pub fn has_pending(&self) -> bool {
        self.shared.post_office.policy.has_pending(&self.mailbox)
    }

    /// Number of messages waiting in the mailbox.
    pub fn pending(&self) -> usize {
        self.shared.post_office.policy.pending(self.index())
    }

    /// What each of this endpoint's subscription buffers did so far: bounds, messages dropped
    /// or refused by the overflow policy ([`MailboxBounds`]).
    pub fn mailbox_reports(&self) -> Vec<crate::MailboxReport> {
        self.shared.post_office.policy.reports(self.index())
    }

    /// Blocks the calling thread until a message is waiting, `timeout` passes or the Agora
    /// shuts down (for endpoints used outside an executor; Members are woken by their
    /// executor); returns whether a message is waiting. The first thread that waits on an
    /// endpoint is the one its arrivals wake: keep an endpoint on one thread.
    pub fn wait_msg(&self, timeout: std::time::Duration) -> bool {
        let waker = self.shared.waker(self.member);
        if let Some(w) = &waker {
            w.bind_current();
            w.wait(Some(timeout), true, &|| self.has_pending() || self.shared.is_shutting_down());
        }
        self.has_pending()
    }

    /// Asks the whole Agora to shut down (`Shutdown()`): every Member ends within its current
    /// cycle and `lets_work` returns.
    pub fn shutdown(&self) {
        self.shared.request_shutdown(Some(self.member));
    }
}

/// One typed publish: builds the header when somebody subscribed, and gives the value by value
/// when it can travel so (see `parcel`), else a shared message from the endpoint's pool.
struct Publish<'a, T> {
    endpoint: &'a Endpoint,
    /// The value, until it is built into a message.
    value: Option<T>,
    /// The value by value, once built so (several PostOffices may ask for it).
    inlined: Option<InlineMsg>,
    warranty: DeliveryWarranty,
    priority: u8,
}

impl<T: Message> Publish<'_, T> {
    fn header(&self) -> MsgHeader {
        let shared = &self.endpoint.shared;
        MsgHeader {
            msg_type: T::TYPE,
            member_id: self.endpoint.member,
            agora_id: shared.id,
            priority: self.priority,
            warranty: self.warranty,
            creation_time: shared.clock.now(),
        }
    }
}

impl<T: Message> Make for Publish<'_, T> {
    #[inline]
    fn shared(&mut self) -> MsgRef {
        if let Some(v) = self.value.take() {
            return self.endpoint.pool.make(self.header(), v);
        }
        if let Some(inline) = self.inlined {
            // A PostOffice that shares after others took the value by value.
            return Parcel::Inline(inline).open(&self.endpoint.pool);
        }
        // Every route builds its message at most once; never reached.
        Msg::new(self.header(), RawPayload::new(Vec::new())).into_ref()
    }

    #[inline]
    fn inline(&mut self) -> Option<InlineMsg> {
        if !InlineMsg::fits::<T>() || self.inlined.is_some() {
            return self.inlined;
        }
        let header = self.header();
        match InlineMsg::new(header, self.value.take()?) {
            Ok(inline) => {
                self.inlined = Some(inline);
                self.inlined
            }
            Err(value) => {
                self.value = Some(value);
                None
            }
        }
    }
}

/// What a running [`Member`](crate::Member) gets in `init`, `do_your_job` and `close`: its
/// [`Endpoint`] (through `Deref`) plus the cycle count and the right to terminate itself.
pub struct Context<'a> {
    pub(crate) endpoint: &'a mut Endpoint,
    pub(crate) cycle: u64,
    pub(crate) terminate: bool,
}

impl Context<'_> {
    /// How many times `do_your_job` ran before this call (the manual's `DoYourJob(int)`
    /// argument).
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Puts this Member in the TERMINATING state: `close` runs after this cycle and the
    /// Member does not run again. The Agora ends when every Member terminated.
    pub fn terminate(&mut self) {
        self.terminate = true;
    }
}

impl Deref for Context<'_> {
    type Target = Endpoint;
    fn deref(&self) -> &Endpoint {
        self.endpoint
    }
}

impl DerefMut for Context<'_> {
    fn deref_mut(&mut self) -> &mut Endpoint {
        self.endpoint
    }
}
