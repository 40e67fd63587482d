//! Waking a Member's thread when a message arrives for it, cheaply.
//!
//! The producer side costs a fence and one relaxed load when the consumer is awake (one plain
//! load after a `SeqCst` put: [`Waker::wake_after_seqcst_put`]); the consumer announces
//! that it is about to sleep, re-checks its mailbox, and parks (Dekker-style handshake with
//! `SeqCst` fences, so no wake-up is ever lost). `std::thread::park` keeps a token, so an
//! `unpark` that races ahead of `park` is not lost either.

use std::sync::atomic::{fence, AtomicBool, Ordering};
use std::sync::OnceLock;
use std::thread::Thread;
use std::time::{Duration, Instant};

/// Busy-wait rounds before a sleep (1, 2, 4 ... 64 pause instructions each, about 500 in all).
const SPIN_ROUNDS: u32 = 48;
/// `yield_now` rounds after the spinning, before the sleep.
const YIELD_ROUNDS: u32 = 16;

/// Whether threads that wait for messages should spin before they sleep: only when `threads`
/// of them leave a core free for a producer. With more threads than cores, spinning steals the
/// producer's time: on a 2-core machine, four consumers that skip the spin read one
/// producer's messages faster than four that spin.
pub(crate) fn should_spin(threads: usize) -> bool {
    std::thread::available_parallelism().map_or(1, |n| n.get()) > threads
}

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

    /// [`Waker::wake`] without its fence, for a producer whose put was a sequentially
    /// consistent read-modify-write on a location that the consumer's `has_work` reads with a
    /// sequentially consistent load (the `PMQ` rings: the tail's `SeqCst` compare-exchange, the
    /// spill flag's `SeqCst` store). In the single total order of `SeqCst` operations, either
    /// the consumer's `sleeping` store comes before this load (then it is seen, and the
    /// consumer is woken) or after it, and then the put came before the consumer's re-check
    /// (then the consumer sees the work and does not sleep). On x86 this saves a full fence per
    /// message: the load is a plain one.
    #[inline]
    pub(crate) fn wake_after_seqcst_put(&self) {
        if self.sleeping.load(Ordering::SeqCst) {
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
    /// Yields briefly first, and with `spin` spins before that: a message that arrives within
    /// microseconds is picked up without a system call on either side. Spinning only pays
    /// when the producer has a core of its own; when the waiting threads outnumber the cores,
    /// a spinning consumer takes the core its producer needs (see [`should_spin`]).
    pub(crate) fn wait(&self, timeout: Option<Duration>, spin: bool, has_work: &dyn Fn() -> bool) {
        let spins = if spin { SPIN_ROUNDS } else { 0 };
        for i in 0..spins + YIELD_ROUNDS {
            if has_work() {
                return;
            }
            if i < spins {
                for _ in 0..(1u32 << (i / 8).min(6)) {
                    std::hint::spin_loop();
                }
            } else {
                std::thread::yield_now();
            }
        }
        // `SeqCst` store and fence: the fence pairs with `wake`'s, the store with
        // `wake_after_seqcst_put`'s load.
        self.sleeping.store(true, Ordering::SeqCst);
        fence(Ordering::SeqCst);
        // `park` may return with no work: an `unpark` meant for an earlier sleep (a producer
        // that saw `sleeping` just before we woke and left its token behind) or a spurious
        // wake-up. Sleep again until there is work or the time is up.
        let deadline = timeout.map(|t| Instant::now() + t);
        while !has_work() {
            match deadline {
                Some(d) => match d.checked_duration_since(Instant::now()) {
                    Some(left) if !left.is_zero() => std::thread::park_timeout(left),
                    _ => break,
                },
                None => std::thread::park(),
            }
        }
        self.sleeping.store(false, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;

    #[test]
    fn a_stale_unpark_token_does_not_end_the_wait_early() {
        let waker = Arc::new(Waker::default());
        waker.bind_current();
        let work = Arc::new(AtomicBool::new(false));
        // A token left behind by an earlier wake-up: the first park returns at once.
        std::thread::current().unpark();
        let producer = {
            let (waker, work) = (waker.clone(), work.clone());
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(30));
                work.store(true, Ordering::SeqCst);
                waker.wake();
            })
        };
        waker.wait(Some(Duration::from_secs(10)), true, &|| work.load(Ordering::SeqCst));
        assert!(work.load(Ordering::SeqCst), "woke before the work arrived");
        producer.join().unwrap();
    }

    #[test]
    fn waiting_threads_spin_only_when_they_leave_a_core_free() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert!(should_spin(cores - 1), "{cores} cores, {} waiting threads", cores - 1);
        assert!(!should_spin(cores), "as many waiting threads as cores");
        assert!(!should_spin(usize::MAX));
    }

    #[test]
    fn a_wait_with_a_timeout_and_no_work_returns_after_it() {
        let waker = Waker::default();
        waker.bind_current();
        std::thread::current().unpark();
        let t = Instant::now();
        waker.wait(Some(Duration::from_millis(20)), false, &|| false);
        assert!(t.elapsed() >= Duration::from_millis(20), "{:?}", t.elapsed());
    }
}
