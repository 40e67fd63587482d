//! Waking a Member's thread when a message arrives for it, cheaply.
//!
//! The producer side costs one relaxed load when the consumer is awake; the consumer announces
//! that it is about to sleep, re-checks its mailbox, and parks (Dekker-style handshake with
//! `SeqCst` fences, so no wake-up is ever lost). `std::thread::park` keeps a token, so an
//! `unpark` that races ahead of `park` is not lost either.

use std::sync::atomic::{fence, AtomicBool, Ordering};
use std::sync::OnceLock;
use std::thread::Thread;
use std::time::Duration;

/// Wakes one Member's thread.
#[derive(Debug, Default)]
pub(crate) struct Waker {
    thread: OnceLock<Thread>,
    sleeping: AtomicBool,
}

impl Waker {
    /// Binds the waker to the calling thread (first call wins; an Agora runs each Member on
    /// one thread for its whole life).
    pub(crate) fn bind_current(&self) {
        let _ = self.thread.set(std::thread::current());
    }

    /// Called by producers after a message was put in the mailbox.
    #[inline]
    pub(crate) fn wake(&self) {
        fence(Ordering::SeqCst);
        if self.sleeping.load(Ordering::Relaxed) {
            self.force_wake();
        }
    }

    /// Wakes the thread whatever it is doing (shutdown).
    pub(crate) fn force_wake(&self) {
        if let Some(t) = self.thread.get() {
            t.unpark();
        }
    }

    /// Sleeps until woken, `has_work` is true, or `timeout` passes (when given).
    /// Spins and yields briefly first: a message that arrives within microseconds is picked
    /// up without a system call on either side.
    pub(crate) fn wait(&self, timeout: Option<Duration>, has_work: &dyn Fn() -> bool) {
        for i in 0..64u32 {
            if has_work() {
                return;
            }
            if i < 48 {
                for _ in 0..(1u32 << (i / 8).min(6)) {
                    std::hint::spin_loop();
                }
            } else {
                std::thread::yield_now();
            }
        }
        self.sleeping.store(true, Ordering::Relaxed);
        fence(Ordering::SeqCst);
        if !has_work() {
            match timeout {
                Some(t) => std::thread::park_timeout(t),
                None => std::thread::park(),
            }
        }
        self.sleeping.store(false, Ordering::Relaxed);
    }
}
