//! The threaded executor: each activated Member on its own thread, in real time (§3.1: "each
//! Member corresponds to a particular thread").

use super::{ExitReason, RunReport};
use crate::agora::Agora;
use crate::error::DcdtError;
use crate::member::{Activation, MemberReport, Runner, Step};
use crate::shared::AgoraShared;
use mrt_core::Time;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread;

// `Agora::lets_work` lives with the executor it hands the Agora to: executors know the Agora,
// the Agora knows no executor.
impl Agora {
    /// Runs every activated Member, each on its own thread, until every Member terminated or
    /// one called `shutdown` (`LetsWork()`). Needs a real-time clock.
    pub fn lets_work(self) -> Result<RunReport, DcdtError> {
        ThreadedExecutor::new().run(self)
    }
}

/// Runs each activated Member of one Agora on its own thread until every Member terminated or
/// shutdown was called. All Members run `init` before any runs its first job, so a producer's
/// first message is not lost to a consumer that has not subscribed yet.
///
/// Periodic Members sleep until their next deadline (a missed deadline is skipped, not made
/// up in a burst); cyclic Members run back to back; on-message Members yield briefly (and
/// spin before that when the Agora has fewer Members than the machine has cores, so that a
/// spinning Member never takes its producer's core), then park until a message arrives. A
/// `SLWDWCV` PostOffice gets its dispatcher thread (the manual's *MsgManager*).
#[derive(Debug, Default)]
pub struct ThreadedExecutor {
    _private: (),
}

impl ThreadedExecutor {
    /// A threaded executor.
    pub fn new() -> Self {
        Self::default()
    }

    /// Runs the Agora to its end (what [`Agora::lets_work`] does).
    pub fn run(&self, mut agora: Agora) -> Result<RunReport, DcdtError> {
        let shared = agora.shared.clone();
        if shared.clock.is_simulated() {
            return Err(DcdtError::ClockMismatch {
                agora: shared.id,
                reason: "the threaded executor runs in real time and needs a wall clock; run a \
                         simulated clock with the SteppedExecutor",
            });
        }
        let runners = agora.take_runners();
        let gate = StartGate::new(runners.len());
        // Waiting Members spin before they sleep only if they leave a core for a producer.
        let spin = crate::waker::should_spin(runners.len());
        let stop_dispatcher = AtomicBool::new(false);
        let mut spawn_error = None;
        let mut reports = Vec::new();
        thread::scope(|s| {
            let po = &shared.post_office;
            let stop = &stop_dispatcher;
            let dispatcher = if po.policy.needs_dispatcher() {
                thread::Builder::new()
                    .name("mrt:MsgManager".into())
                    .spawn_scoped(s, move || po.policy.run_dispatcher(stop))
                    .map_err(|e| {
                        spawn_error =
                            Some(DcdtError::Spawn { what: "MsgManager".into(), source: e })
                    })
                    .ok()
            } else {
                None
            };
            let mut handles = Vec::new();
            for runner in runners {
                if spawn_error.is_some() {
                    reports.push(runner.report());
                    continue;
                }
                let name = runner.name.clone();
                let (shared, gate) = (&shared, &gate);
                match thread::Builder::new()
                    .name(format!("mrt:{name}"))
                    .spawn_scoped(s, move || run_member(runner, shared, gate, spin))
                {
                    Ok(h) => handles.push(h),
                    Err(e) => {
                        spawn_error =
                            Some(DcdtError::Spawn { what: format!("member {name}"), source: e })
                    }
                }
            }
            if spawn_error.is_some() {
                shared.request_shutdown(None);
                gate.open();
            }
            for h in handles {
                match h.join() {
                    Ok(report) => reports.push(report),
                    Err(_) => {
                        tracing::error!(agora = %shared.id, "a member thread died outside its member")
                    }
                }
            }
            stop.store(true, Ordering::Release);
            po.policy.stop_dispatcher();
            if let Some(d) = dispatcher {
                let _ = d.join();
            }
        });
        if let Some(e) = spawn_error {
            return Err(e);
        }
        reports.sort_by_key(|r| r.id);
        let exit = if shared.is_shutting_down() {
            ExitReason::Shutdown
        } else {
            ExitReason::AllTerminated
        };
        Ok(RunReport { agora: shared.id, exit, members: reports })
    }
}

fn run_member(
    mut r: Runner,
    shared: &Arc<AgoraShared>,
    gate: &StartGate,
    spin: bool,
) -> MemberReport {
    let waker = shared.waker(r.endpoint.member_id());
    if let Some(w) = &waker {
        w.bind_current();
    }
    let clock = &shared.clock;
    r.init_if_needed();
    gate.arrive();
    r.next_due = clock.now();
    // The clock is read only where a deadline matters: an on-message Member woken by a
    // stream of messages goes straight from one job to the next.
    while !shared.is_shutting_down() && !r.terminate_requested() {
        if r.resume_at != Time::ZERO {
            let now = clock.now();
            if r.resume_at > now {
                thread::park_timeout(r.resume_at - now);
                continue;
            }
            r.resume_at = Time::ZERO;
        }
        match r.activation {
            Activation::Periodic(_) => {
                let now = clock.now();
                if now < r.next_due {
                    thread::park_timeout(r.next_due - now);
                    continue;
                }
            }
            Activation::OnMessage if !r.has_mail() => {
                if r.init_if_needed() {
                    if let Some(w) = &waker {
                        w.wait(None, spin, &|| r.has_mail() || shared.is_shutting_down());
                    }
                }
                continue;
            }
            Activation::Cyclic => thread::yield_now(),
            Activation::OnMessage => {}
        }
        match r.step() {
            Step::Ran if matches!(r.activation, Activation::Periodic(_)) => {
                r.schedule_next(clock.now())
            }
            Step::Ran => {}
            Step::Backoff => {}
            Step::Terminate => break,
        }
    }
    r.close();
    r.report()
}

/// Holds every Member thread until all have run `init` (or the start was abandoned).
struct StartGate {
    remaining: Mutex<usize>,
    cv: Condvar,
}

impl StartGate {
    fn new(n: usize) -> Self {
        Self { remaining: Mutex::new(n), cv: Condvar::new() }
    }

    fn arrive(&self) {
        let mut r = self.remaining.lock().unwrap_or_else(|e| e.into_inner());
        *r = r.saturating_sub(1);
        if *r == 0 {
            self.cv.notify_all();
        }
        while *r > 0 {
            r = self.cv.wait(r).unwrap_or_else(|e| e.into_inner());
        }
    }

    fn open(&self) {
        *self.remaining.lock().unwrap_or_else(|e| e.into_inner()) = 0;
        self.cv.notify_all();
    }
}
