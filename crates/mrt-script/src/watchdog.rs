//! The watchdog: a behavior's cycle under a deadline, outside Lua.
//!
//! The instruction budget stops what runs as Lua. A C function that runs long, a Rust function
//! added to the robot API that blocks, anything we did not think of, is the watchdog's: the
//! [`ThinkingCap`] runs on a worker thread of its own, and each cycle is one round trip that
//! must end within the deadline, as the seeds' robots had a fixed control cycle (seed 001
//! §3.2: 100 ms). A cycle that does not end in time gives the safe command (stand still) and a
//! [`ScriptError::Watchdog`]; the worker is told to abort (its next budget check fails) and is
//! left behind, and the robot is stopped, running no Lua, until a reload request starts a
//! fresh worker from the files. A worker that panics is reported and restarted
//! ([`MAX_RESTARTS`] times in a row at most). The robot's other Members, and other robots, go
//! on at their own pace throughout.
//!
//! When every cycle ends in time the results are exactly those of the [`ThinkingCap`] run in
//! place: a simulated match stays deterministic.
//!
//! ```
//! use mrt_script::{Sandbox, ThinkingCap, Watchdog};
//! use std::time::Duration;
//!
//! let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../behaviors/teamchaos");
//! let mut keeper = Watchdog::start("keeper", Duration::from_millis(250), move || {
//!     ThinkingCap::with_behavior(dir, "goalkeeper", Sandbox::default())
//! })?;
//! let cycle = keeper.cycle(Default::default());
//! assert!(cycle.errors.is_empty());
//! # Ok::<(), mrt_script::ScriptError>(())
//! ```

use crate::cap::{Cycle, ThinkingCap};
use crate::runtime::Interrupt;
use crate::script::ScriptError;
use crate::watch::Change;
use mrt_msgs::robot::{RobotCommand, WorldSnapshot};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The default deadline of one cycle: far above what a cycle within its instruction budget
/// takes (a few milliseconds), short enough that a stuck behavior costs its match little.
pub const DEFAULT_DEADLINE: Duration = Duration::from_millis(250);

/// How long loading the behaviors (compiling every file, running their top level) may take.
pub const LOAD_DEADLINE: Duration = Duration::from_secs(10);

/// Worker panics in a row after which the robot is stopped instead of restarted.
pub const MAX_RESTARTS: u32 = 3;

/// Builds the [`ThinkingCap`] on the worker thread (a Lua state stays on its thread).
type Factory = Arc<dyn Fn() -> Result<ThinkingCap, ScriptError> + Send + Sync>;

enum Job {
    Cycle(u64, Box<WorldSnapshot>),
    Reload,
    Install(u64, Box<Change>),
}

/// What the worker did for a job.
enum Done {
    /// A cycle's result and the reload report that came before it.
    Cycle(Box<Cycle>),
    /// What an install swapped in, or why it did not.
    Installed(Result<Vec<String>, ScriptError>),
}

struct Reply {
    seq: u64,
    done: Done,
}

struct Worker {
    jobs: Sender<Job>,
    replies: Receiver<Reply>,
    interrupt: Interrupt,
}

/// A [`ThinkingCap`] on a worker thread, each cycle under a deadline (see the module docs).
pub struct Watchdog {
    name: String,
    make: Factory,
    deadline: Duration,
    worker: Option<Worker>,
    seq: u64,
    /// Worker panics in a row.
    restarts: u32,
}

impl Watchdog {
    /// Starts the worker, which builds its [`ThinkingCap`] with `make`; returns the loading
    /// error, if any. `name` appears in errors.
    pub fn start(
        name: &str,
        deadline: Duration,
        make: impl Fn() -> Result<ThinkingCap, ScriptError> + Send + Sync + 'static,
    ) -> Result<Watchdog, ScriptError> {
        let make: Factory = Arc::new(make);
        let worker = spawn(name, &make)?;
        Ok(Watchdog {
            name: name.to_string(),
            make,
            deadline,
            worker: Some(worker),
            seq: 0,
            restarts: 0,
        })
    }

    /// Whether the robot is stopped (a cycle overran the deadline, or the worker kept
    /// panicking): cycles give the safe command until [`Watchdog::reload_requested`].
    pub fn stopped(&self) -> bool {
        self.worker.is_none()
    }

    /// The deadline of one cycle.
    pub fn deadline(&self) -> Duration {
        self.deadline
    }

    /// Asks for the edited files at the next cycle boundary; a stopped robot gets a fresh
    /// worker loaded from the files (its Lua globals start anew). Returns the error of a
    /// fresh worker that does not load.
    pub fn reload_requested(&mut self) -> Result<(), ScriptError> {
        if let Some(w) = &self.worker {
            if w.jobs.send(Job::Reload).is_ok() {
                return Ok(());
            }
        }
        self.restarts = 0;
        self.worker = Some(spawn(&self.name, &self.make)?);
        Ok(())
    }

    /// Installs a script compiled off the control path and already written into the
    /// behavior directory (a behavior sent to the robot, `mrt behave push`), now, between two
    /// cycles, within the deadline: what was swapped in, or why nothing was (the running
    /// version stays, exactly as with a local hot reload). A stopped robot gets a fresh
    /// worker loaded from the files instead, as with [`Watchdog::reload_requested`].
    pub fn install(&mut self, change: Change) -> Result<Vec<String>, ScriptError> {
        if self.worker.is_none() {
            let name = change.name.clone();
            self.reload_requested()?;
            return Ok(vec![name]);
        }
        match self.round_trip(|seq| Job::Install(seq, Box::new(change))) {
            Ok(Done::Installed(r)) => r,
            Ok(Done::Cycle(_)) => {
                Err(ScriptError::Setup(format!("{}: a cycle's reply to an install", self.name)))
            }
            Err(errors) => Err(errors.into_iter().next().unwrap_or_else(|| {
                ScriptError::Setup(format!("{}: the behavior's thread stopped", self.name))
            })),
        }
    }

    /// Runs one cycle on `world` within the deadline.
    pub fn cycle(&mut self, world: WorldSnapshot) -> Cycle {
        if self.worker.is_none() {
            return safe(Vec::new());
        }
        match self.round_trip(|seq| Job::Cycle(seq, Box::new(world))) {
            Ok(Done::Cycle(c)) => *c,
            Ok(Done::Installed(_)) => safe(Vec::new()),
            Err(errors) => safe(errors),
        }
    }

    /// Sends one job to the worker and waits for its reply within the deadline; a job that
    /// overruns it stops the robot, a worker that panicked is restarted (module docs). The
    /// errors say which.
    fn round_trip(&mut self, job: impl FnOnce(u64) -> Job) -> Result<Done, Vec<ScriptError>> {
        let Some(worker) = &self.worker else { return Err(Vec::new()) };
        self.seq += 1;
        let seq = self.seq;
        let sent = worker.jobs.send(job(seq)).is_ok();
        let until = Instant::now() + self.deadline;
        let outcome = loop {
            if !sent {
                break Err(RecvTimeoutError::Disconnected);
            }
            match worker.replies.recv_timeout(until.saturating_duration_since(Instant::now())) {
                Ok(r) if r.seq == seq => break Ok(r.done),
                Ok(_) => continue, // A reply to an earlier job: not ours.
                Err(e) => break Err(e),
            }
        };
        match outcome {
            Ok(done) => {
                self.restarts = 0;
                Ok(done)
            }
            Err(RecvTimeoutError::Timeout) => {
                // Abort what runs (at its next budget check) and leave the worker behind: it
                // ends by itself when its call returns and finds no one listening.
                worker.interrupt.interrupt();
                self.worker = None;
                let deadline_ms = u64::try_from(self.deadline.as_millis()).unwrap_or(u64::MAX);
                tracing::error!(behavior = %self.name, deadline_ms, "stopped by the watchdog");
                Err(vec![ScriptError::Watchdog { file: self.name.clone(), deadline_ms }])
            }
            Err(RecvTimeoutError::Disconnected) => {
                // The worker panicked: isolated (its thread is gone), reported, restarted.
                self.restarts += 1;
                let mut errors = vec![ScriptError::Setup(format!(
                    "{}: the behavior's thread stopped (a panic); restart {} of {MAX_RESTARTS}",
                    self.name, self.restarts
                ))];
                self.worker = None;
                if self.restarts <= MAX_RESTARTS {
                    match spawn(&self.name, &self.make) {
                        Ok(w) => self.worker = Some(w),
                        Err(e) => errors.push(e),
                    }
                }
                Err(errors)
            }
        }
    }
}

/// The safe cycle: stand still.
fn safe(errors: Vec<ScriptError>) -> Cycle {
    Cycle {
        command: RobotCommand::default(),
        path: String::new(),
        behavior: None,
        taken: None,
        reloaded: Vec::new(),
        errors,
        structure: None,
    }
}

/// Starts a worker and waits for its behaviors to load.
fn spawn(name: &str, make: &Factory) -> Result<Worker, ScriptError> {
    let (jobs, job_rx) = channel::<Job>();
    let (reply_tx, replies) = channel::<Reply>();
    let (ready_tx, ready_rx) = channel::<Result<Interrupt, ScriptError>>();
    let make = make.clone();
    std::thread::Builder::new()
        .name(format!("lua:{name}"))
        .spawn(move || {
            let mut cap = match make() {
                Ok(c) => {
                    let _ = ready_tx.send(Ok(c.runtime().interrupt_handle()));
                    c
                }
                Err(e) => {
                    let _ = ready_tx.send(Err(e));
                    return;
                }
            };
            let mut pending_reload = false;
            while let Ok(job) = job_rx.recv() {
                match job {
                    Job::Reload => pending_reload = true,
                    Job::Cycle(seq, world) => {
                        let (mut reloaded, mut errors) = (Vec::new(), Vec::new());
                        if std::mem::take(&mut pending_reload) {
                            (reloaded, errors) = cap.reload_requested();
                        }
                        let mut cycle = cap.cycle(*world);
                        reloaded.append(&mut cycle.reloaded);
                        errors.append(&mut cycle.errors);
                        (cycle.reloaded, cycle.errors) = (reloaded, errors);
                        if reply_tx.send(Reply { seq, done: Done::Cycle(Box::new(cycle)) }).is_err()
                        {
                            return;
                        }
                    }
                    Job::Install(seq, change) => {
                        let done = Done::Installed(cap.install(*change));
                        if reply_tx.send(Reply { seq, done }).is_err() {
                            return;
                        }
                    }
                }
            }
        })
        .map_err(|e| ScriptError::Setup(format!("{name}: cannot start the Lua thread: {e}")))?;
    match ready_rx.recv_timeout(LOAD_DEADLINE) {
        Ok(Ok(interrupt)) => Ok(Worker { jobs, replies, interrupt }),
        Ok(Err(e)) => Err(e),
        Err(RecvTimeoutError::Timeout) => Err(ScriptError::Watchdog {
            file: name.to_string(),
            deadline_ms: u64::try_from(LOAD_DEADLINE.as_millis()).unwrap_or(u64::MAX),
        }),
        Err(RecvTimeoutError::Disconnected) => {
            Err(ScriptError::Setup(format!("{name}: the Lua thread stopped while loading")))
        }
    }
}
