//! `PMQ`, MRT's default policy: per-Member mailboxes of preallocated rings, one ring per
//! subscription, and a lock-free subscription snapshot.
//!
//! Producers read an immutable table (`ArcSwap`, no lock, no contention between producers)
//! and push a reference into the ring of each matching subscription (a *lane*). Subscribing
//! rebuilds the table under a writer mutex: subscriptions change rarely, messages flow
//! constantly.
//!
//! A lane is a bounded lock-free ring of [`MailboxBounds::capacity`] slots, allocated once,
//! when the Member first subscribes to the type (`crossbeam_queue::ArrayQueue`): no allocation
//! per message. When it is full the overflow policy of [`MailboxBounds`] applies: a lane that
//! only ever carried best-effort messages drops its oldest message (lock-free, one
//! `force_push`); a lane that carried a `Reliable` one never drops a `Reliable` message: the
//! excess waits in a *spill* queue under a mutex, allocated only then, up to
//! [`MailboxBounds::reliable_limit`], past which it refuses (counts, logs).
//!
//! A Member's lanes share one sequence counter: once it has two lanes or more, every message gets
//! the Member's next number when it is pushed, and the Member's endpoint takes the waiting
//! message with the lowest number, so a Member reads messages of all its subscriptions in the
//! order they arrived, as with one queue. (A Member with one lane needs no number.)

use super::{MailboxBounds, MailboxReport, Subscriptions};
use crate::msg::DeliveryWarranty;
use crate::parcel::{Make, Parcel};
use crate::waker::Waker;
use arc_swap::ArcSwap;
use crossbeam_queue::ArrayQueue;
use mrt_core::MsgType;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};

/// A message in a lane, with its number in the Member's arrival order.
type Entry = (u64, Parcel);

/// Where [`Lane::push`] put a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pushed {
    /// In the ring.
    Ring,
    /// In the spill queue, under its lock.
    Spill,
    /// Nowhere: a best-effort message dropped at the lane's `Reliable` limit (counted).
    Dropped,
    /// Nowhere: a `Reliable` message refused at the lane's limit (counted).
    Refused,
}

/// One subscription's buffer: a preallocated ring, and an overflow queue for the excess.
pub(crate) struct Lane {
    ty: MsgType,
    ring: ArrayQueue<Entry>,
    /// Set once a `Reliable` message entered (under the `spill` lock, so an overflowing
    /// producer never misses it): from then on the lane never drops a `Reliable` message.
    reliable: AtomicBool,
    /// `spill` is not empty: producers append there, to keep the lane's order (everything in
    /// the ring is older than everything in the spill).
    spilled: AtomicBool,
    spill: Mutex<VecDeque<Entry>>,
    /// The ring's size: messages held before the overflow policy applies.
    capacity: usize,
    /// The same for a lane that carried a `Reliable` message.
    reliable_limit: usize,
    dropped: AtomicU64,
    refused: AtomicU64,
}

impl Lane {
    fn new(ty: MsgType, bounds: MailboxBounds) -> Self {
        let capacity = bounds.capacity.max(1);
        Self {
            ty,
            ring: ArrayQueue::new(capacity),
            reliable: AtomicBool::new(false),
            spilled: AtomicBool::new(false),
            spill: Mutex::new(VecDeque::new()),
            capacity,
            reliable_limit: bounds.reliable_limit.max(capacity),
            dropped: AtomicU64::new(0),
            refused: AtomicU64::new(0),
        }
    }

    fn spill(&self) -> MutexGuard<'_, VecDeque<Entry>> {
        // Every update under this lock is a push or a pop: a panic cannot leave it half done.
        self.spill.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Puts a message in the lane, applying the overflow policy.
    #[inline]
    fn push(&self, entry: Entry) -> Pushed {
        if entry.1.warranty() == DeliveryWarranty::Reliable
            && !self.reliable.load(Ordering::Acquire)
        {
            let _spill = self.spill();
            self.reliable.store(true, Ordering::Release);
        }
        if self.spilled.load(Ordering::Acquire) {
            return self.push_spill(entry);
        }
        match self.ring.push(entry) {
            Ok(()) => Pushed::Ring,
            Err(entry) => self.push_spill(entry),
        }
    }

    /// The ring is full or the lane is spilled: the slow path, under the lock.
    #[cold]
    fn push_spill(&self, mut entry: Entry) -> Pushed {
        let mut spill = self.spill();
        if spill.is_empty() {
            // The Member may have caught up meanwhile.
            match self.ring.push(entry) {
                Ok(()) => return Pushed::Ring,
                Err(e) => entry = e,
            }
        }
        let reliable_lane = self.reliable.load(Ordering::Acquire);
        if !reliable_lane {
            // Best-effort lane (never spilled): the oldest message makes room, atomically. (No
            // `Reliable` message can be in the ring: its producer marks the lane under this
            // lock before pushing it.)
            if self.ring.force_push(entry).is_some() {
                self.dropped.fetch_add(1, Ordering::Relaxed);
            }
            return Pushed::Ring;
        }
        if reliable_lane && self.ring.len() + spill.len() >= self.reliable_limit {
            if entry.1.warranty() != DeliveryWarranty::Reliable {
                // A best-effort message in a lane that must not drop `Reliable` ones: the
                // newest goes.
                self.dropped.fetch_add(1, Ordering::Relaxed);
                return Pushed::Dropped;
            }
            let before = self.refused.fetch_add(1, Ordering::Relaxed);
            if before == 0 {
                tracing::error!(
                    msg_type = %self.ty,
                    limit = self.reliable_limit,
                    "a mailbox refused a Reliable message: its subscriber is {} messages \
                     behind (counted in the run report; further refusals are only counted)",
                    self.reliable_limit
                );
            }
            return Pushed::Refused;
        }
        spill.push_back(entry);
        // `SeqCst`: the put the waker's handshake relies on (`Mailbox::push`).
        self.spilled.store(true, Ordering::SeqCst);
        Pushed::Spill
    }

    #[inline]
    fn pop(&self) -> Option<Entry> {
        if let Some(e) = self.ring.pop() {
            return Some(e);
        }
        if !self.spilled.load(Ordering::Acquire) {
            return None;
        }
        let mut spill = self.spill();
        // Producers that found the lane spilled appended there; anything a concurrent producer
        // put in the ring meanwhile goes first (two producers' messages have no order).
        if let Some(e) = self.ring.pop() {
            return Some(e);
        }
        let e = spill.pop_front();
        if spill.is_empty() {
            self.spilled.store(false, Ordering::Release);
            // Give a large overflow's memory back: a spill is the exception, not the rule.
            if spill.capacity() > self.capacity {
                spill.shrink_to_fit();
            }
        }
        e
    }

    #[inline]
    fn has_pending(&self) -> bool {
        // `SeqCst` loads (the ring's `is_empty` too): the waker's handshake.
        !self.ring.is_empty() || self.spilled.load(Ordering::SeqCst)
    }

    fn len(&self) -> usize {
        let spilled = if self.spilled.load(Ordering::Acquire) { self.spill().len() } else { 0 };
        self.ring.len() + spilled
    }

    fn report(&self) -> MailboxReport {
        MailboxReport {
            msg_type: self.ty,
            capacity: self.capacity,
            reliable_limit: self.reliable_limit,
            dropped: self.dropped.load(Ordering::Relaxed),
            refused: self.refused.load(Ordering::Relaxed),
        }
    }
}

/// One Member's mailbox: its lanes (one per type it ever subscribed to), the counter that
/// orders their messages, and its waker.
#[derive(Default)]
pub(crate) struct Mailbox {
    next: AtomicU64,
    /// It has more than one lane: messages need arrival numbers.
    multi: AtomicBool,
    waker: Arc<Waker>,
    /// Lanes in creation order. Only grows: a lane stays after `unsubscribe`, so messages
    /// already waiting are still received, and a new subscription to the type reuses it.
    lanes: ArcSwap<Vec<Arc<Lane>>>,
    /// Bumped after `lanes` changed, so readers reload their copy only then.
    generation: AtomicUsize,
    /// Messages the endpoint took out of the lanes to compare their order (at most one per
    /// lane), counted as waiting.
    staged: AtomicUsize,
}

impl Mailbox {
    /// Delivers into one of its lanes and wakes the Member; `false` when the lane refused.
    #[inline]
    fn push(&self, lane: &Lane, msg: Parcel) -> bool {
        // Arrival numbers only order lanes against each other: a Member with one lane needs
        // none. Messages numbered 0 before its second lane came are older than all the new
        // lane's, and the merge takes the first lane on a tie.
        let seq = if self.multi.load(Ordering::Relaxed) {
            self.next.fetch_add(1, Ordering::Relaxed)
        } else {
            0
        };
        match lane.push((seq, msg)) {
            // Every put is a `SeqCst` read-modify-write or store that `has_pending` reads with
            // `SeqCst` (see `Lane::push`): no fence needed.
            Pushed::Ring | Pushed::Spill => self.waker.wake_after_seqcst_put(),
            Pushed::Dropped => {}
            Pushed::Refused => return false,
        }
        true
    }

    fn pending(&self) -> usize {
        self.lanes.load().iter().map(|l| l.len()).sum::<usize>()
            + self.staged.load(Ordering::Relaxed)
    }

    fn reports(&self) -> Vec<MailboxReport> {
        self.lanes.load().iter().map(|l| l.report()).collect()
    }
}

/// The consumer side of a mailbox, kept by the Member's endpoint.
pub(crate) struct Reader {
    mailbox: Arc<Mailbox>,
    lanes: Arc<Vec<Arc<Lane>>>,
    generation: usize,
    /// The head of each lane, taken out to compare arrival numbers (several lanes only).
    staged: Vec<Option<Entry>>,
}

impl Reader {
    fn new(mailbox: Arc<Mailbox>) -> Self {
        let generation = mailbox.generation.load(Ordering::Acquire);
        let lanes = mailbox.lanes.load_full();
        Self { staged: Vec::new(), mailbox, lanes, generation }
    }

    #[inline]
    fn refresh(&mut self) {
        let g = self.mailbox.generation.load(Ordering::Acquire);
        if g != self.generation {
            self.generation = g;
            self.lanes = self.mailbox.lanes.load_full();
        }
    }

    /// The waiting message that arrived first.
    #[inline]
    pub(crate) fn pop(&mut self) -> Option<Parcel> {
        self.refresh();
        if self.lanes.len() == 1 && self.staged.is_empty() {
            return self.lanes[0].pop().map(|(_, m)| m);
        }
        self.pop_merged()
    }

    fn pop_merged(&mut self) -> Option<Parcel> {
        if self.staged.len() < self.lanes.len() {
            self.staged.resize_with(self.lanes.len(), || None);
        }
        let mut first: Option<(usize, u64)> = None;
        for (i, (lane, slot)) in self.lanes.iter().zip(self.staged.iter_mut()).enumerate() {
            if slot.is_none() {
                *slot = lane.pop();
                if slot.is_some() {
                    self.mailbox.staged.fetch_add(1, Ordering::Relaxed);
                }
            }
            if let Some((seq, _)) = slot {
                if first.is_none_or(|(_, s)| *seq < s) {
                    first = Some((i, *seq));
                }
            }
        }
        let (i, _) = first?;
        let (_, msg) = self.staged.get_mut(i)?.take()?;
        self.mailbox.staged.fetch_sub(1, Ordering::Relaxed);
        Some(msg)
    }

    #[inline]
    pub(crate) fn has_pending(&self) -> bool {
        if self.staged.iter().any(Option::is_some) {
            return true;
        }
        if self.mailbox.generation.load(Ordering::Acquire) != self.generation {
            return self.mailbox.lanes.load().iter().any(|l| l.has_pending());
        }
        self.lanes.iter().any(|l| l.has_pending())
    }
}

/// A lane as producers see it in the table.
struct Target {
    mask: u8,
    lane: Arc<Lane>,
    mailbox: Arc<Mailbox>,
}

/// What producers read: type → subscribers.
#[derive(Default)]
struct Table {
    by_type: FxHashMap<MsgType, Vec<Target>>,
}

#[derive(Default)]
struct Writer {
    subs: Subscriptions,
    boxes: Vec<Arc<Mailbox>>,
}

pub(crate) struct Pmq {
    bounds: MailboxBounds,
    table: ArcSwap<Table>,
    /// Mailboxes by member index, for the consumer side (changes only on registration).
    boxes: ArcSwap<Vec<Arc<Mailbox>>>,
    writer: Mutex<Writer>,
}

impl Pmq {
    pub(crate) fn new(bounds: MailboxBounds) -> Self {
        Self {
            bounds,
            table: ArcSwap::default(),
            boxes: ArcSwap::default(),
            writer: Mutex::default(),
        }
    }

    fn with_writer(&self, f: impl FnOnce(&mut Writer)) {
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut w);
        let mut table = Table::default();
        for (ty, subs) in w.subs.iter() {
            let entry = subs
                .iter()
                .filter_map(|(m, mask)| {
                    let mailbox = w.boxes.get(*m)?;
                    let lane = mailbox.lanes.load().iter().find(|l| l.ty == ty).cloned()?;
                    Some(Target { mask: *mask, lane, mailbox: mailbox.clone() })
                })
                .collect();
            table.by_type.insert(ty, entry);
        }
        self.table.store(Arc::new(table));
        self.boxes.store(Arc::new(w.boxes.clone()));
    }

    pub(crate) fn register(&self, member: usize, waker: Arc<Waker>) {
        self.with_writer(|w| {
            if w.boxes.len() <= member {
                w.boxes.resize_with(member + 1, Default::default);
            }
            w.boxes[member] = Arc::new(Mailbox { waker, ..Mailbox::default() });
        })
    }

    pub(crate) fn update(&self, f: impl FnOnce(&mut Subscriptions)) {
        self.with_writer(|w| f(&mut w.subs))
    }

    /// Subscribes, creating the Member's lane for `ty` if it has none (with `bounds`, else the
    /// PostOffice's).
    pub(crate) fn subscribe(
        &self,
        member: usize,
        ty: MsgType,
        mask: u8,
        bounds: Option<MailboxBounds>,
    ) {
        self.with_writer(|w| {
            if let Some(mailbox) = w.boxes.get(member) {
                let lanes = mailbox.lanes.load();
                if !lanes.iter().any(|l| l.ty == ty) {
                    let mut next = (**lanes).clone();
                    next.push(Arc::new(Lane::new(ty, bounds.unwrap_or(self.bounds))));
                    // Before any producer can see the new lane (the table is stored below).
                    mailbox.multi.store(next.len() > 1, Ordering::Release);
                    mailbox.lanes.store(Arc::new(next));
                    mailbox.generation.fetch_add(1, Ordering::Release);
                }
            }
            w.subs.subscribe(member, ty, mask);
        })
    }

    pub(crate) fn subscriptions(&self) -> Subscriptions {
        self.writer.lock().unwrap_or_else(|e| e.into_inner()).subs.clone()
    }

    pub(crate) fn has_subscribers(&self, ty: MsgType, origin: u8) -> bool {
        self.table.load().by_type.get(&ty).is_some_and(|s| s.iter().any(|t| t.mask & origin != 0))
    }

    #[inline]
    pub(crate) fn deliver(&self, ty: MsgType, origin: u8, make: &mut dyn Make) -> usize {
        let table = self.table.load();
        let Some(subs) = table.by_type.get(&ty) else {
            return 0;
        };
        let mut matching = subs.iter().filter(|t| t.mask & origin != 0);
        let Some(mut target) = matching.next() else {
            return 0;
        };
        if let Some(value) = make.inline() {
            // A small plain message: a copy by value in each slot (see `parcel`).
            let mut n = usize::from(target.mailbox.push(&target.lane, Parcel::Inline(value)));
            for t in matching {
                n += usize::from(t.mailbox.push(&t.lane, Parcel::Inline(value)));
            }
            return n;
        }
        // Shared: the last matching mailbox gets the reference itself, the others a clone (one
        // reference-count increment per extra subscriber, none for a single one).
        let msg = make.shared();
        let mut n = 0;
        for next in matching {
            n += usize::from(target.mailbox.push(&target.lane, Parcel::Shared(msg.clone())));
            target = next;
        }
        n + usize::from(target.mailbox.push(&target.lane, Parcel::Shared(msg)))
    }

    /// The consumer side of a Member's mailbox, for its endpoint.
    pub(crate) fn reader(&self, member: usize) -> Option<Reader> {
        self.boxes.load().get(member).cloned().map(Reader::new)
    }

    pub(crate) fn pending(&self, member: usize) -> usize {
        self.boxes.load().get(member).map_or(0, |b| b.pending())
    }

    pub(crate) fn reports(&self, member: usize) -> Vec<MailboxReport> {
        self.boxes.load().get(member).map_or_else(Vec::new, |b| b.reports())
    }
}
