//! Members (MRT manual §3.1, §3.3.2): the units of work an Agora runs, and how they run.

use crate::endpoint::{Context, Endpoint};
use crate::policy::MailboxReport;
use mrt_core::{MemberId, MsgType, Time};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// The error a Member returns from `init` or `do_your_job`.
pub type MemberError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// A User Member: "an instance of an object derived from the DCDT Member class" (§3.1).
///
/// `init` runs once before the first job (and again after a crash), `do_your_job` runs as its
/// [`Activation`] says, `close` runs once at the end. Subscribe in `init` to be woken by
/// messages (the manual's "third kind of Member").
///
/// ```
/// use mrt_dcdt::{Context, Member, MemberError};
///
/// struct Counter(u32);
/// impl Member for Counter {
///     fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
///         self.0 += 1;
///         if self.0 == 3 {
///             ctx.terminate();
///         }
///         Ok(())
///     }
/// }
/// ```
pub trait Member: Send + 'static {
    /// A name for logs and reports (defaults to the Rust type name).
    fn name(&self) -> String {
        let full = std::any::type_name::<Self>();
        full.rsplit("::").next().unwrap_or(full).to_string()
    }

    /// Prepares the Member (`Init()`): subscribe here. An error is reported and `init` is
    /// retried with a backoff.
    fn init(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Ok(())
    }

    /// One activity cycle (`DoYourJob()`). An error is reported and counted; the Member keeps
    /// running. A panic is caught: the Member is reported, and restarted (`init` again) after
    /// a backoff while the rest of the Agora keeps running.
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError>;

    /// Cleans up (`Close()`), once, when the Member or the Agora terminates — provided `init`
    /// succeeded at least once (a Member that never initialized has nothing to close).
    fn close(&mut self, _ctx: &mut Context<'_>) {}
}

/// When a Member's `do_your_job` runs (§3.3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Activation {
    /// "Periodic Execution Member": every `period`.
    Periodic(Duration),
    /// "Cyclic Execution Member": again and again without delay.
    Cyclic,
    /// Woken when a message it subscribed to arrives. The threaded executor wakes it on
    /// arrival; the stepped executor runs it once in every tick that finds mail waiting.
    /// Either way, drain the mailbox in `do_your_job`.
    OnMessage,
}

/// The life of a Member (§3.3.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum MemberState {
    /// Added to the Agora (`AddMember`): its mailbox exists, it does not run.
    Added = 0,
    /// Activated (`ActivateMember`): it runs when the Agora works.
    Activated = 1,
    /// Running `init`.
    Initializing = 2,
    /// Between or in cycles.
    Running = 3,
    /// Crashed; waiting for its backoff to end before `init` runs again.
    Restarting = 4,
    /// `TERMINATING`: finishing; `close` runs next.
    Terminating = 5,
    /// Closed. It will not run again.
    Terminated = 6,
}

impl MemberState {
    fn from_u8(v: u8) -> MemberState {
        match v {
            0 => MemberState::Added,
            1 => MemberState::Activated,
            2 => MemberState::Initializing,
            3 => MemberState::Running,
            4 => MemberState::Restarting,
            5 => MemberState::Terminating,
            _ => MemberState::Terminated,
        }
    }
}

/// A Member's state, readable from other threads.
#[derive(Debug, Clone, Default)]
pub(crate) struct SharedState(Arc<AtomicU8>);

impl SharedState {
    pub(crate) fn get(&self) -> MemberState {
        MemberState::from_u8(self.0.load(Ordering::Acquire))
    }
    pub(crate) fn set(&self, s: MemberState) {
        self.0.store(s as u8, Ordering::Release)
    }
}

/// What happened to one Member during a run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemberReport {
    /// The Member's id.
    pub id: MemberId,
    /// Its name.
    pub name: String,
    /// Completed `do_your_job` calls.
    pub cycles: u64,
    /// `do_your_job` calls that returned an error.
    pub errors: u64,
    /// Panics caught (in `init` or `do_your_job`).
    pub panics: u64,
    /// Times `init` ran again after a crash or an `init` error.
    pub restarts: u64,
    /// Its state at the end.
    pub state: MemberState,
    /// The last failure (`init` error, job error or panic), for reports.
    pub last_error: Option<String>,
    /// Its subscriptions' buffers, in subscription order: bounds, and the messages their
    /// overflow policy dropped or refused ([`MailboxBounds`](crate::MailboxBounds)).
    pub mailboxes: Vec<MailboxReport>,
}

impl MemberReport {
    /// Best-effort messages dropped from its mailbox, all subscriptions together.
    pub fn dropped(&self) -> u64 {
        self.mailboxes.iter().map(|m| m.dropped).sum()
    }

    /// `Reliable` messages its mailbox refused, all subscriptions together.
    pub fn refused(&self) -> u64 {
        self.mailboxes.iter().map(|m| m.refused).sum()
    }

    /// The report of its subscription to `ty`, if it ever subscribed to it.
    pub fn mailbox(&self, ty: MsgType) -> Option<&MailboxReport> {
        self.mailboxes.iter().find(|m| m.msg_type == ty)
    }
}

/// First restart delay after a crash; doubles with every consecutive crash up to
/// [`MAX_BACKOFF`].
pub const BASE_BACKOFF: Duration = Duration::from_millis(10);
/// Longest restart delay.
pub const MAX_BACKOFF: Duration = Duration::from_secs(1);

/// Runs one Member: init, jobs, crash isolation with backoff, close. Both executors drive
/// Members through this, so they behave the same; only scheduling differs.
pub(crate) struct Runner {
    pub(crate) member: Box<dyn Member>,
    pub(crate) endpoint: Endpoint,
    pub(crate) activation: Activation,
    pub(crate) state: SharedState,
    pub(crate) name: String,
    needs_init: bool,
    /// `terminate` was called in `init`.
    terminate_in_init: bool,
    consecutive_failures: u32,
    /// Not before this time (after a crash).
    pub(crate) resume_at: Time,
    /// Next periodic deadline.
    pub(crate) next_due: Time,
    cycles: u64,
    errors: u64,
    panics: u64,
    restarts: u64,
    last_error: Option<String>,
}

/// What one call of [`Runner::step`] did.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Step {
    /// A job ran (or init and a job).
    Ran,
    /// The Member crashed or failed to init; it waits until `resume_at`.
    Backoff,
    /// The Member asked to terminate.
    Terminate,
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_string()
    }
}

impl Runner {
    pub(crate) fn new(
        member: Box<dyn Member>,
        endpoint: Endpoint,
        activation: Activation,
        state: SharedState,
    ) -> Self {
        let name = member.name();
        Self {
            member,
            endpoint,
            activation,
            state,
            name,
            needs_init: true,
            terminate_in_init: false,
            consecutive_failures: 0,
            resume_at: Time::ZERO,
            next_due: Time::ZERO,
            cycles: 0,
            errors: 0,
            panics: 0,
            restarts: 0,
            last_error: None,
        }
    }

    fn fail(&mut self, what: &str, reason: &str) {
        self.last_error = Some(format!("{what}: {reason}"));
        self.consecutive_failures += 1;
        let shift = (self.consecutive_failures - 1).min(16);
        let backoff = BASE_BACKOFF.saturating_mul(1u32 << shift).min(MAX_BACKOFF);
        let now = self.endpoint.now();
        self.resume_at = now + backoff;
        self.needs_init = true;
        self.state.set(MemberState::Restarting);
        tracing::error!(
            agora = %self.endpoint.agora_id(),
            member = %self.endpoint.member_id(),
            name = %self.name,
            %now,
            restart_in = ?backoff,
            "member {} {what}: {reason}; restarting it", self.name
        );
    }

    /// Runs `init` if it has not run since the start or the last crash. `false` when it
    /// failed: the Member backs off until `resume_at`.
    pub(crate) fn init_if_needed(&mut self) -> bool {
        if !self.needs_init {
            return true;
        }
        self.state.set(MemberState::Initializing);
        if self.cycles > 0 || self.consecutive_failures > 0 {
            self.restarts += 1;
        }
        let mut ctx =
            Context { endpoint: &mut self.endpoint, cycle: self.cycles, terminate: false };
        let member = &mut self.member;
        match catch_unwind(AssertUnwindSafe(|| member.init(&mut ctx))) {
            Ok(Ok(())) => {
                self.terminate_in_init |= ctx.terminate;
                self.needs_init = false;
                self.state.set(MemberState::Running);
                true
            }
            Ok(Err(e)) => {
                self.fail("failed to init", &e.to_string());
                false
            }
            Err(p) => {
                self.panics += 1;
                self.fail("panicked in init", &panic_message(&*p));
                false
            }
        }
    }

    /// Runs one `do_your_job` (after `init`, if needed), isolating panics.
    pub(crate) fn step(&mut self) -> Step {
        if !self.init_if_needed() {
            return Step::Backoff;
        }
        if self.terminate_in_init {
            return Step::Terminate;
        }
        let span = tracing::trace_span!("cycle", member = %self.name, cycle = self.cycles);
        let _enter = span.enter();
        let mut ctx =
            Context { endpoint: &mut self.endpoint, cycle: self.cycles, terminate: false };
        let member = &mut self.member;
        let result = catch_unwind(AssertUnwindSafe(|| {
            let r = member.do_your_job(&mut ctx);
            (r, ctx.terminate)
        }));
        match result {
            Ok((r, terminate)) => {
                self.cycles += 1;
                self.consecutive_failures = 0;
                if let Err(e) = r {
                    self.errors += 1;
                    self.last_error = Some(format!("job failed: {e}"));
                    tracing::warn!(member = %self.name, cycle = self.cycles, "member {} job failed: {e}", self.name);
                }
                if terminate {
                    Step::Terminate
                } else {
                    Step::Ran
                }
            }
            Err(p) => {
                self.panics += 1;
                self.fail("panicked", &panic_message(&*p));
                Step::Backoff
            }
        }
    }

    /// Runs `close` (isolating a panic) and marks the Member terminated.
    pub(crate) fn close(&mut self) {
        self.state.set(MemberState::Terminating);
        if !self.needs_init || self.cycles > 0 {
            let mut ctx =
                Context { endpoint: &mut self.endpoint, cycle: self.cycles, terminate: true };
            let member = &mut self.member;
            if let Err(p) = catch_unwind(AssertUnwindSafe(|| member.close(&mut ctx))) {
                self.panics += 1;
                tracing::error!(member = %self.name, "member {} panicked in close: {}", self.name, panic_message(&*p));
            }
        }
        self.endpoint.unsubscribe_all();
        self.endpoint.remove_curr_msg();
        self.state.set(MemberState::Terminated);
    }

    /// Advances the periodic deadline past `now`, skipping missed periods (no bursts).
    pub(crate) fn schedule_next(&mut self, now: Time) {
        if let Activation::Periodic(p) = self.activation {
            let p_ns = u64::try_from(p.as_nanos()).unwrap_or(u64::MAX).max(1);
            let mut next = self.next_due.as_nanos().saturating_add(p_ns);
            if next <= now.as_nanos() {
                let missed = (now.as_nanos() - next) / p_ns + 1;
                next = next.saturating_add(missed.saturating_mul(p_ns));
            }
            self.next_due = Time(next);
        }
    }

    /// The Member called `terminate` in `init`: it closes without running a job.
    pub(crate) fn terminate_requested(&self) -> bool {
        self.terminate_in_init
    }

    pub(crate) fn is_closed(&self) -> bool {
        self.state.get() == MemberState::Terminated
    }

    pub(crate) fn has_mail(&self) -> bool {
        self.endpoint.has_pending()
    }

    pub(crate) fn report(&self) -> MemberReport {
        MemberReport {
            id: self.endpoint.member_id(),
            name: self.name.clone(),
            cycles: self.cycles,
            errors: self.errors,
            panics: self.panics,
            restarts: self.restarts,
            state: self.state.get(),
            last_error: self.last_error.clone(),
            mailboxes: self.endpoint.mailbox_reports(),
        }
    }
}
