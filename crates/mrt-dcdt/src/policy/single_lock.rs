//! The three single-lock policies of the manual: `SLWB`, `SLWDWCV` and `SLWSM`.
//!
//! One mutex guards the subscription table and every mailbox. They differ in what the
//! producer does under the lock (see the table in the parent module).

use super::Subscriptions;
use crate::config::PolicyKind;
use crate::msg::MsgRef;
use crate::waker::Waker;
use mrt_core::MsgType;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// A Member's mailbox under a single-lock policy.
#[derive(Default)]
struct Mailbox {
    /// FIFO buffer (`SLWB`, `SLWDWCV`).
    queue: VecDeque<MsgRef>,
    /// Latest message per type (`SLWSM`)...
    latest: FxHashMap<MsgType, MsgRef>,
    /// ...and the order in which types got a fresh message.
    fresh: VecDeque<MsgType>,
    waker: Arc<Waker>,
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
    state: Mutex<State>,
    /// `SLWDWCV`: signalled when `main` gets a message.
    cv: Condvar,
}

impl SingleLock {
    pub(crate) fn new(kind: PolicyKind) -> Self {
        Self { kind, state: Mutex::new(State::default()), cv: Condvar::new() }
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

    pub(crate) fn subscriptions(&self) -> Subscriptions {
        self.lock().subs.clone()
    }

    pub(crate) fn has_subscribers(&self, ty: MsgType, origin: u8) -> bool {
        self.lock().subs.matching(ty, origin).next().is_some()
    }

    pub(crate) fn deliver(
        &self,
        ty: MsgType,
        origin: u8,
        make: &mut dyn FnMut() -> MsgRef,
    ) -> usize {
        let mut guard = self.lock();
        let s = &mut *guard;
        let mut n = 0;
        let mut msg: Option<MsgRef> = None;
        if self.kind == PolicyKind::Slwdwcv {
            if s.subs.matching(ty, origin).next().is_some() {
                s.main.push_back((make(), origin));
                n = 1;
                self.cv.notify_one();
            }
            return n;
        }
        for member in s.subs.matching(ty, origin) {
            let m = msg.get_or_insert_with(&mut *make).clone();
            let Some(b) = s.boxes.get_mut(member) else {
                continue;
            };
            if self.kind == PolicyKind::Slwsm {
                if b.latest.insert(ty, m).is_none() {
                    b.fresh.push_back(ty);
                }
            } else {
                b.queue.push_back(m);
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
            b.queue.pop_front()
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
                    b.queue.push_back(msg.clone());
                    b.waker.wake();
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
