//! The watchdog: a behavior's cycle under a deadline, outside Lua.
//!
//! The instruction budget stops what runs as Lua and pays for the libraries' C functions. A
//! Rust function added to the robot API that blocks, anything we did not think of, is the
//! watchdog's: the [`ThinkingCap`] runs on a worker thread of its own, and each cycle is one
//! round trip that must end within the deadline, as the seeds' robots had a fixed control
//! cycle (ThinkingCap report §3.2: 100 ms). A cycle that does not end in time gives the safe
//! command (stand still) and a [`ScriptError::Watchdog`]; the worker is told to abort (its
//! next budget check fails) and is left behind.
//!
//! A stopped robot (by the deadline, by its behaviors running away or failing cycle after
//! cycle, [`ScriptError::Stopped`], or by a worker that keeps panicking) stands still and
//! **restarts from its files** after a back-off counted in cycles: [`RESTART_AFTER`] cycles,
//! doubling with each stop that follows a restart within [`HEALTHY_CYCLES`], up to
//! [`MAX_BACKOFF`]; a reload request restarts it at once. Until it has run [`HEALTHY_CYCLES`]
//! cycles, a restarted robot is on probation: one cycle that fails (an error, a runaway)
//! stops it again, so that a hostile behavior costs one cycle per restart. A restart waits for the thread left
//! behind to end, so a robot never has more than one such thread. Each stop and restart is
//! logged once with its cause. A worker that panics is reported and restarted at once
//! ([`MAX_RESTARTS`] times in a row, then with the back-off). The robot's other Members, and
//! other robots, go on at their own pace throughout.
//!
//! On a simulated clock the budget is the deadline that counts: a cycle takes no simulated
//! time, and the wall-clock deadline is only a backstop ([`SIMULATED_DEADLINE`]) for what the
//! budget does not see, long enough that a busy machine never reaches it, so the same seed
//! gives the same match however loaded the machine is. When every cycle ends in time the
//! results are exactly those of the [`ThinkingCap`] run in place.
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
use crate::error::ScriptError;
use crate::runtime::Interrupt;
use crate::watch::Change;
use mrt_msgs::robot::{RobotCommand, WorldSnapshot};
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The default deadline of one cycle: far above what a cycle within its instruction budget
/// takes (a few milliseconds), short enough that a stuck behavior costs its match little.
pub const DEFAULT_DEADLINE: Duration = Duration::from_millis(250);

/// The deadline of one cycle on a simulated clock: only a backstop (module docs).
pub const SIMULATED_DEADLINE: Duration = Duration::from_secs(5);

/// How long loading the behaviors (compiling every file, running their top level) may take.
pub const LOAD_DEADLINE: Duration = Duration::from_secs(10);

/// Worker panics in a row restarted at once; more wait for the back-off.
pub const MAX_RESTARTS: u32 = 3;

/// Cycles a stopped robot stands still before its first restart (2 s of the seeds' 100 ms
/// cycle).
pub const RESTART_AFTER: u32 = 20;

/// The longest back-off, in cycles (2 min of 100 ms cycles).
pub const MAX_BACKOFF: u32 = 1200;

/// Cycles a restarted robot must run without a stop for its back-off to start over.
pub const HEALTHY_CYCLES: u32 = 600;

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
    thread: JoinHandle<()>,
}

/// A stopped robot's wait for its restart.
#[derive(Debug)]
struct Stop {
    /// Cycles left before the restart.
    wait: u32,
    /// The back-off it started with.
    backoff: u32,
    /// Whether the wait for the thread left behind was reported.
    reported_wait: bool,
}

/// A [`ThinkingCap`] on a worker thread, each cycle under a deadline (see the module docs).
pub struct Watchdog {
    name: String,
    make: Factory,
    deadline: Duration,
    worker: Option<Worker>,
    seq: u64,
    /// Worker panics in a row.
    panics: u32,
    /// Set while the robot is stopped.
    stop: Option<Stop>,
    /// Stops since the robot last ran [`HEALTHY_CYCLES`] cycles without one.
    stops: u32,
    /// Cycles run since the last (re)start.
    running: u32,
    /// The thread of a worker left behind (interrupted, its call may still run).
    behind: Option<JoinHandle<()>>,
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
        let mut behind = None;
        let worker = spawn(name, &make, &mut behind)?;
        Ok(Watchdog {
            name: name.to_string(),
            make,
            deadline,
            worker: Some(worker),
            seq: 0,
            panics: 0,
            stop: None,
            stops: 0,
            running: 0,
            behind,
        })
    }

    /// Whether the robot is stopped: cycles give the safe command until its restart (module
    /// docs) or [`Watchdog::reload_requested`].
    pub fn stopped(&self) -> bool {
        self.worker.is_none()
    }

    /// Cycles left before a stopped robot restarts (`None` while it runs).
    pub fn restart_in(&self) -> Option<u32> {
        self.stop.as_ref().map(|s| s.wait)
    }

    /// The deadline of one cycle.
    pub fn deadline(&self) -> Duration {
        self.deadline
    }

    /// Asks for the edited files at the next cycle boundary; a stopped robot restarts now
    /// from the files (its Lua globals start anew), or, while the thread of its stopped
    /// worker is still in a call, at the first cycle after that call ends. Returns the error
    /// of a fresh worker that does not load.
    pub fn reload_requested(&mut self) -> Result<(), ScriptError> {
        if let Some(w) = &self.worker {
            if w.jobs.send(Job::Reload).is_ok() {
                return Ok(());
            }
        }
        self.stops = 0;
        self.panics = 0;
        if self.behind_runs() {
            // Restarts at the first cycle after the stopped call ends.
            if let Some(stop) = &mut self.stop {
                stop.wait = 0;
            }
            return Ok(());
        }
        self.restart().map(|_| ())
    }

    /// Installs a script compiled off the control path and already written into the
    /// behavior directory (a behavior sent to the robot, `mrt behave push`), now, between two
    /// cycles, within the deadline: what was swapped in, or why nothing was (the running
    /// version stays, exactly as with a local hot reload). A stopped robot restarts from the
    /// files instead, as with [`Watchdog::reload_requested`].
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
        let mut restarted = Vec::new();
        if self.worker.is_none() {
            match self.wait_for_restart() {
                Ok(true) => restarted.push(self.name.clone()),
                Ok(false) => return safe(Vec::new()),
                Err(e) => return safe(vec![e]),
            }
        }
        let mut cycle = match self.round_trip(|seq| Job::Cycle(seq, Box::new(world))) {
            Ok(Done::Cycle(c)) => *c,
            Ok(Done::Installed(_)) => safe(Vec::new()),
            Err(errors) => safe(errors),
        };
        if cycle.errors.iter().any(|e| matches!(e, ScriptError::Stopped { .. })) {
            // The behaviors are broken, not unlucky: a fresh start from the files later.
            self.worker = None;
            self.stopped_now("its behaviors kept failing");
        } else if self.stops > 0 && self.running < HEALTHY_CYCLES && !cycle.errors.is_empty() {
            // On probation after a restart: one failing cycle stops it again.
            self.worker = None;
            self.stopped_now("its behaviors failed again after a restart");
        }
        self.running = self.running.saturating_add(1);
        if self.running >= HEALTHY_CYCLES {
            self.stops = 0;
        }
        restarted.append(&mut cycle.reloaded);
        cycle.reloaded = restarted;
        cycle
    }

    /// Counts one cycle of a stopped robot's wait; restarts it when the wait is over and the
    /// thread it left behind has ended. Whether it restarted.
    fn wait_for_restart(&mut self) -> Result<bool, ScriptError> {
        let behind_runs = self.behind_runs();
        let Some(stop) = &mut self.stop else { return Ok(false) };
        if stop.wait > 0 {
            stop.wait -= 1;
            return Ok(false);
        }
        if behind_runs {
            if !std::mem::replace(&mut stop.reported_wait, true) {
                tracing::warn!(behavior = %self.name, "restart waits for the stopped call to end");
            }
            return Ok(false);
        }
        let backoff = stop.backoff;
        match self.restart() {
            Ok(true) => {
                tracing::info!(behavior = %self.name, after_cycles = backoff, "restarted from its files");
                Ok(true)
            }
            Ok(false) => Ok(false),
            Err(e) => Err(e),
        }
    }

    /// Whether the thread of a worker left behind still runs (its interrupted call has not
    /// ended yet).
    fn behind_runs(&self) -> bool {
        self.behind.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// A fresh worker from the files, unless the thread left behind still runs (then `false`);
    /// a worker that does not load schedules the next try.
    fn restart(&mut self) -> Result<bool, ScriptError> {
        if self.behind_runs() {
            return Ok(false);
        }
        self.behind = None;
        match spawn(&self.name, &self.make, &mut self.behind) {
            Ok(w) => {
                self.worker = Some(w);
                self.stop = None;
                self.running = 0;
                Ok(true)
            }
            Err(e) => {
                self.stopped_now("its behaviors did not load");
                Err(e)
            }
        }
    }

    /// Enters the stopped state: the safe command until the back-off has passed.
    fn stopped_now(&mut self, cause: &str) {
        self.stops = self.stops.saturating_add(1);
        let backoff = RESTART_AFTER.saturating_mul(1 << (self.stops - 1).min(16)).min(MAX_BACKOFF);
        self.stop = Some(Stop { wait: backoff, backoff, reported_wait: false });
        tracing::error!(behavior = %self.name, cause, restart_in_cycles = backoff, "stopped");
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
                self.panics = 0;
                Ok(done)
            }
            Err(RecvTimeoutError::Timeout) => {
                // Abort what runs (at its next budget check) and leave the worker behind: it
                // ends by itself when its call returns and finds no one listening.
                if let Some(w) = self.worker.take() {
                    w.interrupt.interrupt();
                    self.behind = Some(w.thread);
                }
                let deadline_ms = u64::try_from(self.deadline.as_millis()).unwrap_or(u64::MAX);
                self.stopped_now("a cycle overran the deadline");
                Err(vec![ScriptError::Watchdog { file: self.name.clone(), deadline_ms }])
            }
            Err(RecvTimeoutError::Disconnected) => {
                // The worker panicked: isolated (its thread is gone), reported, restarted.
                self.panics += 1;
                let mut errors = vec![ScriptError::Setup(format!(
                    "{}: the behavior's thread stopped (a panic); restart {} of {MAX_RESTARTS}",
                    self.name, self.panics
                ))];
                self.worker = None;
                if self.panics <= MAX_RESTARTS {
                    match spawn(&self.name, &self.make, &mut self.behind) {
                        Ok(w) => self.worker = Some(w),
                        Err(e) => errors.push(e),
                    }
                }
                if self.worker.is_none() {
                    self.stopped_now("its thread kept panicking");
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

/// Starts a worker and waits for its behaviors to load; one that overruns the load deadline
/// is interrupted and left `behind`.
fn spawn(
    name: &str,
    make: &Factory,
    behind: &mut Option<JoinHandle<()>>,
) -> Result<Worker, ScriptError> {
    let (jobs, job_rx) = channel::<Job>();
    let (reply_tx, replies) = channel::<Reply>();
    let (ready_tx, ready_rx) = channel::<Result<(), ScriptError>>();
    let interrupt = Interrupt::default();
    let (make, obeyed) = (make.clone(), interrupt.clone());
    let thread = std::thread::Builder::new()
        .name(format!("lua:{name}"))
        .spawn(move || {
            // The runtime the factory makes obeys this handle, its loading included.
            obeyed.obeyed_by_next_runtime();
            let made = make();
            Interrupt::forget_next();
            let mut cap = match made {
                Ok(c) => {
                    let _ = ready_tx.send(Ok(()));
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
        Ok(Ok(())) => Ok(Worker { jobs, replies, interrupt, thread }),
        Ok(Err(e)) => Err(e),
        Err(RecvTimeoutError::Timeout) => {
            interrupt.interrupt();
            *behind = Some(thread);
            Err(ScriptError::Watchdog {
                file: name.to_string(),
                deadline_ms: u64::try_from(LOAD_DEADLINE.as_millis()).unwrap_or(u64::MAX),
            })
        }
        Err(RecvTimeoutError::Disconnected) => {
            Err(ScriptError::Setup(format!("{name}: the Lua thread stopped while loading")))
        }
    }
}
