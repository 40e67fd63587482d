//! `PMQ`, MRT's default policy: per-Member lock-free queues and a lock-free subscription
//! snapshot.
//!
//! Producers read an immutable table (`ArcSwap`, no lock, no contention between producers)
//! and push a reference into each subscriber's `SegQueue`. Subscribing rebuilds the table
//! under a writer mutex: subscriptions change rarely, messages flow constantly.

use super::Subscriptions;
use crate::msg::MsgRef;
use crate::waker::Waker;
use arc_swap::ArcSwap;
use crossbeam_queue::SegQueue;
use mrt_core::MsgType;
use rustc_hash::FxHashMap;
use std::sync::{Arc, Mutex};

/// One Member's mailbox. Endpoints keep an `Arc` to their own, so receiving reads no table.
#[derive(Default)]
pub(crate) struct Mailbox {
    queue: SegQueue<MsgRef>,
    waker: Arc<Waker>,
}

impl Mailbox {
    #[inline]
    fn push(&self, msg: MsgRef) {
        self.queue.push(msg);
        self.waker.wake();
    }

    #[inline]
    pub(crate) fn pop(&self) -> Option<MsgRef> {
        self.queue.pop()
    }

    #[inline]
    pub(crate) fn has_pending(&self) -> bool {
        !self.queue.is_empty()
    }
}

/// What producers read: type → (origin mask, mailbox).
#[derive(Default)]
struct Table {
    by_type: FxHashMap<MsgType, Vec<(u8, Arc<Mailbox>)>>,
}

#[derive(Default)]
struct Writer {
    subs: Subscriptions,
    boxes: Vec<Arc<Mailbox>>,
}

#[derive(Default)]
pub(crate) struct Pmq {
    table: ArcSwap<Table>,
    /// Mailboxes by member index, for the consumer side (changes only on registration).
    boxes: ArcSwap<Vec<Arc<Mailbox>>>,
    writer: Mutex<Writer>,
}

impl Pmq {
    fn with_writer(&self, f: impl FnOnce(&mut Writer)) {
        let mut w = self.writer.lock().unwrap_or_else(|e| e.into_inner());
        f(&mut w);
        let mut table = Table::default();
        for (ty, subs) in w.subs.iter() {
            let entry = subs
                .iter()
                .filter_map(|(m, mask)| w.boxes.get(*m).map(|b| (*mask, b.clone())))
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
            w.boxes[member] = Arc::new(Mailbox { queue: SegQueue::new(), waker });
        })
    }

    pub(crate) fn update(&self, f: impl FnOnce(&mut Subscriptions)) {
        self.with_writer(|w| f(&mut w.subs))
    }

    pub(crate) fn subscriptions(&self) -> Subscriptions {
        self.writer.lock().unwrap_or_else(|e| e.into_inner()).subs.clone()
    }

    pub(crate) fn has_subscribers(&self, ty: MsgType, origin: u8) -> bool {
        self.table.load().by_type.get(&ty).is_some_and(|s| s.iter().any(|(m, _)| m & origin != 0))
    }

    #[inline]
    pub(crate) fn deliver(
        &self,
        ty: MsgType,
        origin: u8,
        make: &mut dyn FnMut() -> MsgRef,
    ) -> usize {
        let table = self.table.load();
        let Some(subs) = table.by_type.get(&ty) else {
            return 0;
        };
        // The last matching mailbox gets the reference itself, the others a clone: one
        // reference-count increment per extra subscriber, none for a single one.
        let mut matching = subs.iter().filter(|(mask, _)| mask & origin != 0).map(|(_, b)| b);
        let Some(mut target) = matching.next() else {
            return 0;
        };
        let msg = make();
        let mut n = 1;
        for next in matching {
            target.push(msg.clone());
            target = next;
            n += 1;
        }
        target.push(msg);
        n
    }

    pub(crate) fn mailbox(&self, member: usize) -> Option<Arc<Mailbox>> {
        self.boxes.load().get(member).cloned()
    }

    pub(crate) fn pop(&self, member: usize) -> Option<MsgRef> {
        self.boxes.load().get(member)?.queue.pop()
    }

    pub(crate) fn has_pending(&self, member: usize) -> bool {
        self.boxes.load().get(member).is_some_and(|b| !b.queue.is_empty())
    }

    pub(crate) fn pending(&self, member: usize) -> usize {
        self.mailbox(member).map_or(0, |b| b.queue.len())
    }
}
