//! The stepped executor: deterministic, simulated-time scheduling of several Agoras.

use super::{ExitReason, RunReport};
use crate::agora::{Agora, AgoraBuilder};
use crate::error::DcdtError;
use crate::member::{Activation, Runner, Step};
use mrt_core::{AgoraId, Clock, SimClock, Time};
use std::sync::Arc;
use std::time::Duration;

struct Entry {
    agora: Agora,
    runners: Vec<Runner>,
    exit: Option<ExitReason>,
    /// Whether its Members ran `init` (on the first step after the Agora was added).
    started: bool,
}

/// Runs every Member of several Agoras on one thread, one at a time in a fixed order, on a
/// [`SimClock`]: the same inputs give the same message trace on every run, as fast as the
/// CPU allows. The simulator drives robots with it.
///
/// Each [`step`](Self::step) is one tick at the current simulated time: Agoras in the order
/// they were added, Members in the order they were added to their Agora. A periodic Member
/// runs when its deadline has come, a cyclic one every tick, an on-message one when its
/// mailbox is not empty. A message shared during a tick is seen in the same tick by Members
/// later in the order and in the next tick by those earlier. Then the clock advances by the
/// tick. On the first step every Member runs `init` before any job.
///
/// ```
/// use mrt_dcdt::prelude::*;
/// use mrt_core::SimClock;
/// use std::time::Duration;
///
/// struct Tick(u32);
/// impl Member for Tick {
///     fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
///         self.0 += 1;
///         Ok(())
///     }
/// }
///
/// let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(1));
/// let mut robot = exec.agora_builder(1).build()?;
/// let t = robot.add_member(Tick(0), Activation::Periodic(Duration::from_millis(10)));
/// robot.activate_member(t)?;
/// exec.add_agora(robot)?;
/// exec.run_for(Duration::from_millis(100)); // 100 simulated ms, no real waiting
/// let reports = exec.finish();
/// assert_eq!(reports[0].members[0].cycles, 10); // at 0, 10, ..., 90 ms
/// # Ok::<(), mrt_dcdt::DcdtError>(())
/// ```
pub struct SteppedExecutor {
    clock: SimClock,
    tick: Duration,
    entries: Vec<Entry>,
}

impl SteppedExecutor {
    /// An executor on `clock`, advancing it by `tick` per step.
    pub fn new(clock: SimClock, tick: Duration) -> Self {
        Self { clock, tick: tick.max(Duration::from_nanos(1)), entries: Vec::new() }
    }

    /// The simulated clock.
    pub fn clock(&self) -> &SimClock {
        &self.clock
    }

    /// The current simulated time.
    pub fn now(&self) -> Time {
        self.clock.now()
    }

    /// The tick.
    pub fn tick(&self) -> Duration {
        self.tick
    }

    /// A builder for an Agora already on this executor's clock.
    pub fn agora_builder(&self, id: impl Into<AgoraId>) -> AgoraBuilder {
        Agora::builder(id).clock(Arc::new(self.clock.clone()))
    }

    /// Adds an Agora; its activated Members run from the next step. Its clock must be a
    /// simulated clock, normally this executor's (see [`agora_builder`](Self::agora_builder)).
    pub fn add_agora(&mut self, mut agora: Agora) -> Result<(), DcdtError> {
        if !agora.clock().is_simulated() {
            return Err(DcdtError::ClockMismatch {
                agora: agora.id(),
                reason: "the stepped executor needs an Agora on a simulated clock \
                         (build it with SteppedExecutor::agora_builder)",
            });
        }
        let runners = agora.take_runners();
        self.entries.push(Entry { agora, runners, exit: None, started: false });
        Ok(())
    }

    /// The Agoras, in the order they were added.
    pub fn agoras(&self) -> impl Iterator<Item = &Agora> {
        self.entries.iter().map(|e| &e.agora)
    }

    /// `true` while some Agora still has Members running.
    pub fn is_running(&self) -> bool {
        self.entries.iter().any(|e| e.exit.is_none())
    }

    fn dispatch_all(entries: &[Entry]) {
        for e in entries {
            e.agora.shared.post_office.policy.dispatch();
        }
    }

    /// Runs `init` of the Members of every Agora added since the last tick, now, without
    /// running any job or moving the clock (the next [`step`](Self::step) does it otherwise).
    /// For a robot whose subscriptions must be known to the network before its first cycle.
    pub fn start(&mut self) {
        let now = self.clock.now();
        for i in 0..self.entries.len() {
            if !self.entries[i].started {
                self.entries[i].started = true;
                for r in &mut self.entries[i].runners {
                    r.next_due = now;
                    r.init_if_needed();
                }
                Self::dispatch_all(&self.entries);
            }
        }
    }

    /// One tick. Returns `false` once every Agora has ended.
    pub fn step(&mut self) -> bool {
        let now = self.clock.now();
        // Members of newly added Agoras run `init` before any job of this tick.
        self.start();
        for i in 0..self.entries.len() {
            if self.entries[i].exit.is_some() {
                continue;
            }
            for j in 0..self.entries[i].runners.len() {
                let r = &mut self.entries[i].runners[j];
                if r.endpoint.shared.is_shutting_down() {
                    break;
                }
                if r.is_closed() || now < r.resume_at || !r.init_if_needed() {
                    continue;
                }
                if r.terminate_requested() {
                    r.close();
                    continue;
                }
                let due = match r.activation {
                    Activation::Periodic(_) => now >= r.next_due,
                    Activation::Cyclic => true,
                    Activation::OnMessage => r.has_mail(),
                };
                if !due {
                    continue;
                }
                match r.step() {
                    Step::Ran => r.schedule_next(now),
                    Step::Backoff => {}
                    Step::Terminate => r.close(),
                }
                Self::dispatch_all(&self.entries);
            }
            let e = &mut self.entries[i];
            if e.agora.shared.is_shutting_down() {
                e.exit = Some(ExitReason::Shutdown);
            } else if e.runners.iter().all(Runner::is_closed) {
                e.exit = Some(ExitReason::AllTerminated);
            }
            if e.exit.is_some() {
                e.runners.iter_mut().filter(|r| !r.is_closed()).for_each(Runner::close);
            }
        }
        self.clock.advance(self.tick);
        self.is_running()
    }

    /// Steps until `d` more simulated time has passed or every Agora ended. Returns
    /// [`is_running`](Self::is_running).
    pub fn run_for(&mut self, d: Duration) -> bool {
        let end = self.clock.now() + d;
        while self.clock.now() < end && self.step() {}
        self.is_running()
    }

    /// Closes every Member still running and reports, one [`RunReport`] per Agora.
    pub fn finish(mut self) -> Vec<RunReport> {
        self.entries
            .iter_mut()
            .map(|e| {
                for r in e.runners.iter_mut().filter(|r| !r.is_closed()) {
                    r.close();
                }
                RunReport {
                    agora: e.agora.id(),
                    exit: e.exit.unwrap_or(ExitReason::TimeLimit),
                    members: e.runners.iter().map(Runner::report).collect(),
                }
            })
            .collect()
    }
}
