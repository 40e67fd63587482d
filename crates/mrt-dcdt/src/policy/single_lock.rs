//! The three single-lock policies of the manual: `SLWB`, `SLWDWCV` and `SLWSM`.
//!
//! One mutex guards the subscription table and every mailbox. They differ in what the
//! producer does under the lock (see the table in the parent module).
//!
//! `SLWB` and `SLWDWCV` keep one FIFO per Member and count, per subscription, the messages of
//! its type waiting there; a full subscription applies the overflow policy of
//! [`MailboxBounds`] (dropping its oldest message means taking it out of the middle of the
//! FIFO: a scan, paid only on overflow).

use super::{MailboxBounds, MailboxReport, Subscriptions};
use crate::config::PolicyKind;
use crate::msg::{DeliveryWarranty, MsgRef};
use crate::parcel::Make;
use crate::waker::Waker;
use mrt_core::MsgType;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// The bookkeeping of one subscription's messages in a Member's FIFO.
struct Lane {
    ty: MsgType,
    bounds: MailboxBounds,
    /// Messages of `ty` waiting in the FIFO.
    waiting: usize,
    /// A `Reliable` message came: the lane never drops from then on.
    reliable: bool,
    dropped: u64,
    refused: u64,
}

/// A Member's mailbox under a single-lock policy.
#[derive(Default)]
struct Mailbox {
    /// FIFO buffer (`SLWB`, `SLWDWCV`).
    queue: VecDeque<MsgRef>,
    /// Latest message per type (`SLWSM`)...
    latest: FxHashMap<MsgType, MsgRef>,
    /// ...and the order in which types got a fresh message.
    fresh: VecDeque<MsgType>,
    /// One per type the Member ever subscribed to, in subscription order.
    lanes: Vec<Lane>,
    waker: Arc<Waker>,
}

impl Mailbox {
    /// Appends `msg` to the FIFO under the overflow policy; `false` when it was refused.
    fn enqueue(&mut self, msg: MsgRef) -> bool {
        let ty = msg.msg_type();
        let reliable = msg.header().warranty == DeliveryWarranty::Reliable;
        let Some(lane) = self.lanes.iter_mut().find(|l| l.ty == ty) else {
            // Every subscription has its lane; a message without one is not expected.
            self.queue.push_back(msg);
            return true;
        };
        lane.reliable |= reliable;
        if lane.waiting >= lane.bounds.capacity {
            if !lane.reliable {
                if let Some(i) = self.queue.iter().position(|m| m.msg_type() == ty) {
                    self.queue.remove(i);
                    lane.waiting -= 1;
                    lane.dropped += 1;
                }
            } else if lane.waiting >= lane.bounds.reliable_limit {
                if reliable {
                    lane.refused += 1;
                    if lane.refused == 1 {
                        tracing::error!(
                            msg_type = %ty,
                            limit = lane.bounds.reliable_limit,
                            "a mailbox refused a Reliable message: its subscriber is {} messages \
                             behind (counted in the run report; further refusals are only counted)",
                            lane.bounds.reliable_limit
                        );
                    }
                    return false;
                }
                lane.dropped += 1;
                return true;
            }
        }
        lane.waiting += 1;
        self.queue.push_back(msg);
        true
    }

    fn dequeue(&mut self) -> Option<MsgRef> {
        let msg = self.queue.pop_front()?;
        if let Some(lane) = self.lanes.iter_mut().find(|l| l.ty == msg.msg_type()) {
            lane.waiting = lane.waiting.saturating_sub(1);
        }
        Some(msg)
    }
}

#[derive(Default)]
struct State {
    subs: Subscriptions,
    boxes: Vec<Mailbox>,
    /// `SLWDWCV`: messages waiting for the dispatcher, with their origin bit.
    main: VecDeque<(MsgRef, u8)>,
}

pub(crate) struct SingleLock {
    kind: PolicyKind,
    bounds: MailboxBounds,
    state: Mutex<State>,
    /// `SLWDWCV`: signalled when `main` gets a message.
    cv: Condvar,
}

impl SingleLock {
    pub(crate) fn new(kind: PolicyKind, bounds: MailboxBounds) -> Self {
        Self { kind, bounds, state: Mutex::new(State::default()), cv: Condvar::new() }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic while holding the lock cannot leave the state half-updated in a way that
        // matters (every update is a push or a pop), so poisoning is ignored.
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(crate) fn register(&self, member: usize, waker: Arc<Waker>) {
        let mut s = self.lock();
        if s.boxes.len() <= member {
            s.boxes.resize_with(member + 1, Mailbox::default);
        }
        s.boxes[member].waker = waker;
    }

    pub(crate) fn update(&self, f: impl FnOnce(&mut Subscriptions)) {
        f(&mut self.lock().subs)
    }

    pub(crate) fn subscribe(
        &self,
        member: usize,
        ty: MsgType,
        mask: u8,
        bounds: Option<MailboxBounds>,
    ) {
        let mut s = self.lock();
        if let Some(b) = s.boxes.get_mut(member) {
            if !b.lanes.iter().any(|l| l.ty == ty) {
                b.lanes.push(Lane {
                    ty,
                    bounds: bounds.unwrap_or(self.bounds),
                    waiting: 0,
                    reliable: false,
                    dropped: 0,
                    refused: 0,
                });
            }
        }
        s.subs.subscribe(member, ty, mask);
    }

    pub(crate) fn reports(&self, member: usize) -> Vec<MailboxReport> {
        let s = self.lock();
        let slwsm = self.kind == PolicyKind::Slwsm;
        s.boxes.get(member).map_or_else(Vec::new, |b| {
            b.lanes
                .iter()
                .map(|l| MailboxReport {
                    msg_type: l.ty,
                    capacity: if slwsm { 1 } else { l.bounds.capacity },
                    reliable_limit: if slwsm { 1 } else { l.bounds.reliable_limit },
                    dropped: l.dropped,
                    refused: l.refused,
                })
                .collect()
        })
    }

    pub(crate) fn subscriptions(&self) -> Subscriptions {
        self.lock().subs.clone()
    }

    pub(crate) fn has_subscribers(&self, ty: MsgType, origin: u8) -> bool {
        self.lock().subs.matching(ty, origin).next().is_some()
    }

    pub(crate) fn deliver(&self, ty: MsgType, origin: u8, make: &mut dyn Make) -> usize {
        let mut guard = self.lock();
        let s = &mut *guard;
        let mut n = 0;
        let mut msg: Option<MsgRef> = None;
        if self.kind == PolicyKind::Slwdwcv {
            if s.subs.matching(ty, origin).next().is_some() {
                s.main.push_back((make.shared(), origin));
                n = 1;
                self.cv.notify_one();
            }
            return n;
        }
        for member in s.subs.matching(ty, origin) {
            let m = msg.get_or_insert_with(|| make.shared()).clone();
            let Some(b) = s.boxes.get_mut(member) else {
                continue;
            };
            if self.kind == PolicyKind::Slwsm {
                if b.latest.insert(ty, m).is_none() {
                    b.fresh.push_back(ty);
                } else if let Some(lane) = b.lanes.iter_mut().find(|l| l.ty == ty) {
                    lane.dropped += 1;
                }
            } else if !b.enqueue(m) {
                continue;
            }
            b.waker.wake();
            n += 1;
        }
        n
    }

    pub(crate) fn pop(&self, member: usize) -> Option<MsgRef> {
        let mut s = self.lock();
        let b = s.boxes.get_mut(member)?;
        if self.kind == PolicyKind::Slwsm {
            let ty = b.fresh.pop_front()?;
            b.latest.remove(&ty)
        } else {
            b.dequeue()
        }
    }

    pub(crate) fn pending(&self, member: usize) -> usize {
        let s = self.lock();
        s.boxes.get(member).map_or(0, |b| b.queue.len() + b.fresh.len())
    }

    pub(crate) fn has_pending(&self, member: usize) -> bool {
        self.pending(member) > 0
    }

    pub(crate) fn needs_dispatcher(&self) -> bool {
        self.kind == PolicyKind::Slwdwcv
    }

    pub(crate) fn dispatch(&self) -> usize {
        let mut guard = self.lock();
        Self::dispatch_locked(&mut guard)
    }

    fn dispatch_locked(s: &mut State) -> usize {
        let n = s.main.len();
        while let Some((msg, origin)) = s.main.pop_front() {
            let State { subs, boxes, .. } = &mut *s;
            for member in subs.matching(msg.msg_type(), origin) {
                if let Some(b) = boxes.get_mut(member) {
                    if b.enqueue(msg.clone()) {
                        b.waker.wake();
                    }
                }
            }
        }
        n
    }

    pub(crate) fn run_dispatcher(&self, stop: &AtomicBool) {
        let mut s = self.lock();
        loop {
            Self::dispatch_locked(&mut s);
            if stop.load(Ordering::Acquire) {
                return;
            }
            s = self.cv.wait(s).unwrap_or_else(|e| e.into_inner());
        }
    }

    pub(crate) fn stop_dispatcher(&self) {
        let _s = self.lock();
        self.cv.notify_all();
    }
}
