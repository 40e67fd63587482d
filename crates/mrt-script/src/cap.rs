//! One robot's behavioral layer as ThinkingCap runs it (ThinkingCap/TeamChaos report §2.1, §3.2): each cycle the
//! high-level HFSM chooses a low-level behavior (`chaos.setBehavior`), and the HBM runs it,
//! giving the robot command. Scripts edited on disk are reloaded at the next cycle boundary.
//!
//! Bad input never stops the robot's software: an HFSM that raises an error (or whose
//! `setBehavior` names no behavior) keeps the last good behavior for the cycle; an HFSM or a
//! behavior that runs away (instruction budget, memory limit), and a behavior that raises an
//! error, give the safe command (stand still) for the cycle; a file that no longer compiles
//! keeps its running version. The next cycle runs normally. Every error is reported in
//! [`Cycle::errors`].
//!
//! Behaviors that run away [`RUNAWAY_LIMIT`] cycles in a row, or fail for any reason
//! [`FAULT_LIMIT`] cycles in a row, are broken, not unlucky (the robot stood still in each of
//! those cycles anyway): the robot is **stopped** (the safe command, no Lua run, so a hostile
//! behavior costs its match nothing from then on) until a file is reloaded, and
//! [`ScriptError::Stopped`] says so once; under the [`Watchdog`](crate::Watchdog) it restarts
//! from its files after a back-off.

use crate::chaos::{self, RobotIo};
use crate::error::ScriptError;
use crate::hbm::Hbm;
use crate::hfsm::{Hfsm, Taken};
use crate::runtime::{LuaRuntime, Sandbox};
use crate::watch::ScriptWatcher;
use mrt_blackboard::Blackboard;
use mrt_msgs::robot::{RobotCommand, WorldSnapshot};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Runaway cycles (budget or memory overruns) in a row after which the robot is stopped (until
/// a behavior file is reloaded, or the [`Watchdog`](crate::Watchdog) restarts it).
pub const RUNAWAY_LIMIT: u32 = 3;

/// Failing cycles (any error of the HFSM or the behavior) in a row after which the robot is
/// stopped like a runaway: 2 s of the seed's 100 ms cycle.
pub const FAULT_LIMIT: u32 = 20;

/// What one cycle did.
#[derive(Debug)]
pub struct Cycle {
    /// The command for the robot.
    pub command: RobotCommand,
    /// The HFSM's active path after the cycle (empty without an HFSM).
    pub path: String,
    /// The behavior that ran.
    pub behavior: Option<String>,
    /// The HFSM transition taken, if any.
    pub taken: Option<Taken>,
    /// Files reloaded before the cycle (behavior names, `hbm`, or the HFSM file).
    pub reloaded: Vec<String>,
    /// What went wrong (the robot went on regardless).
    pub errors: Vec<ScriptError>,
    /// The HFSM's shape, for monitors (ThinkingCap/TeamChaos report §4.1, §5.1): in the first
    /// cycle, after the machine was reloaded, and every `STRUCTURE_EVERY` (100) cycles for
    /// monitors that join late; `None` otherwise and without an HFSM.
    pub structure: Option<mrt_msgs::HfsmStructure>,
}

/// Cycles between two [`Cycle::structure`]s of an unchanged machine (10 s of the seed's
/// 100 ms cycle).
pub const STRUCTURE_EVERY: u32 = 100;

/// Where the behavior to run comes from.
enum Top {
    Hfsm(Box<Hfsm>, PathBuf),
    Behavior(String),
}

/// An HFSM (or one fixed behavior) over a directory of HBM behaviors, in one Lua runtime.
pub struct ThinkingCap {
    rt: LuaRuntime,
    io: Rc<RefCell<RobotIo>>,
    hbm: Hbm,
    top: Top,
    last_good: Option<String>,
    watcher: Option<ScriptWatcher>,
    /// Runaway cycles in a row.
    runaways: u32,
    /// Failing cycles in a row (runaways included).
    failing: u32,
    /// Cycles until the HFSM's shape is told again (0: this cycle).
    structure_in: u32,
}

impl ThinkingCap {
    /// Loads the behaviors of `dir` and the HFSM file `machine`.
    pub fn with_hfsm(
        dir: impl AsRef<Path>,
        machine: impl AsRef<Path>,
        sandbox: Sandbox,
    ) -> Result<ThinkingCap, ScriptError> {
        Self::load_hfsm(dir, machine, sandbox, None)
    }

    /// Loads the behaviors of `dir` and runs `behavior` every cycle.
    pub fn with_behavior(
        dir: impl AsRef<Path>,
        behavior: &str,
        sandbox: Sandbox,
    ) -> Result<ThinkingCap, ScriptError> {
        Self::load_behavior(dir, behavior, sandbox, None)
    }

    /// [`ThinkingCap::with_hfsm`] with `bb.*` bound to the robot's `blackboard`, from the
    /// first line loaded (`hbm.lua` included).
    pub fn load_hfsm(
        dir: impl AsRef<Path>,
        machine: impl AsRef<Path>,
        sandbox: Sandbox,
        blackboard: Option<Blackboard>,
    ) -> Result<ThinkingCap, ScriptError> {
        let (rt, io, hbm) = Self::base(dir.as_ref(), sandbox, blackboard)?;
        let hfsm = Hfsm::from_file(&rt, machine.as_ref(), io.clone())?;
        let top =
            Top::Hfsm(Box::new(hfsm), std::path::absolute(machine.as_ref()).unwrap_or_default());
        Ok(Self::assemble(rt, io, hbm, top))
    }

    /// [`ThinkingCap::with_behavior`] with `bb.*` bound to the robot's `blackboard`.
    pub fn load_behavior(
        dir: impl AsRef<Path>,
        behavior: &str,
        sandbox: Sandbox,
        blackboard: Option<Blackboard>,
    ) -> Result<ThinkingCap, ScriptError> {
        let (rt, io, hbm) = Self::base(dir.as_ref(), sandbox, blackboard)?;
        if !hbm.contains(behavior) {
            return Err(ScriptError::Setup(format!(
                "no behavior named '{behavior}' in {} (known: {})",
                dir.as_ref().display(),
                hbm.names().join(", ")
            )));
        }
        let top = Top::Behavior(behavior.to_string());
        Ok(Self::assemble(rt, io, hbm, top))
    }

    /// A cap that has run nothing yet.
    fn assemble(rt: LuaRuntime, io: Rc<RefCell<RobotIo>>, hbm: Hbm, top: Top) -> ThinkingCap {
        let (last_good, watcher, runaways, failing) = (None, None, 0, 0);
        ThinkingCap { rt, io, hbm, top, last_good, watcher, runaways, failing, structure_in: 0 }
    }

    fn base(
        dir: &Path,
        sandbox: Sandbox,
        blackboard: Option<Blackboard>,
    ) -> Result<(LuaRuntime, Rc<RefCell<RobotIo>>, Hbm), ScriptError> {
        let rt = LuaRuntime::new(sandbox)?;
        let io = Rc::new(RefCell::new(RobotIo::default()));
        chaos::install(&rt, io.clone())?;
        if let Some(bb) = blackboard {
            crate::blackboard::install(&rt, bb)?;
        }
        let hbm = Hbm::load_dir(&rt, dir, io.clone())?;
        io.borrow_mut().known_behaviors = Some(hbm.names().into_iter().collect());
        Ok((rt, io, hbm))
    }

    /// Watches the behavior directory and the HFSM file: edits are picked up at the next
    /// cycle without polling the disk.
    pub fn watch(&mut self, dir: impl AsRef<Path>) -> Result<(), ScriptError> {
        let mut w = ScriptWatcher::new()?;
        w.watch_dir(dir)?;
        if let Top::Hfsm(_, path) = &self.top {
            w.watch(path)?;
        }
        self.watcher = Some(w);
        Ok(())
    }

    /// The Lua runtime (for tests and tools).
    pub fn runtime(&self) -> &LuaRuntime {
        &self.rt
    }

    /// The HBM behaviors.
    pub fn hbm(&self) -> &Hbm {
        &self.hbm
    }

    /// The HFSM, if one runs.
    pub fn hfsm(&self) -> Option<&Hfsm> {
        match &self.top {
            Top::Hfsm(h, _) => Some(h),
            Top::Behavior(_) => None,
        }
    }

    /// The robot state the scripts see (globals, last command).
    pub fn io(&self) -> std::cell::Ref<'_, RobotIo> {
        self.io.borrow()
    }

    /// Reloads every changed file now (what a watcher or a reload request on the bus does
    /// at the next cycle boundary). Returns what was reloaded and what was rejected.
    pub fn reload_changed(&mut self) -> (Vec<String>, Vec<ScriptError>) {
        let (done, errors) = self.hbm.reload_changed(&self.rt);
        self.after_hbm_change();
        self.reload_hfsm(&[], done, errors)
    }

    /// An explicit reload request: what changed, and the HFSM whatever its stamp says (the
    /// files it includes have no stamp of their own).
    pub fn reload_requested(&mut self) -> (Vec<String>, Vec<ScriptError>) {
        let (done, errors) = self.hbm.reload_changed(&self.rt);
        self.after_hbm_change();
        let machine: Vec<PathBuf> = match &self.top {
            Top::Hfsm(_, path) => vec![path.clone()],
            Top::Behavior(_) => Vec::new(),
        };
        self.reload_hfsm(&machine, done, errors)
    }

    /// Installs one script compiled off the control path (a behavior sent to the robot,
    /// `mrt behave push`), already written at `change.path` in the behavior directory: what
    /// was swapped in, or why nothing was (the running version stays). Call it at a cycle
    /// boundary.
    pub fn install(&mut self, change: crate::watch::Change) -> Result<Vec<String>, ScriptError> {
        let (done, mut errors) = self.apply(vec![change]);
        match errors.is_empty() {
            true => Ok(done),
            false => Err(errors.swap_remove(0)),
        }
    }

    /// Applies what the watcher compiled off the control path (see [`Hbm::apply`]).
    fn apply(&mut self, changes: Vec<crate::watch::Change>) -> (Vec<String>, Vec<ScriptError>) {
        let touched: Vec<PathBuf> = changes.iter().map(|c| c.path.clone()).collect();
        let machine = match &self.top {
            Top::Hfsm(_, path) => Some(path.clone()),
            Top::Behavior(_) => None,
        };
        let behaviors = changes
            .into_iter()
            .filter(|c| {
                Some(&c.path) != machine.as_ref()
                    && !c.path.to_string_lossy().ends_with(".hfsm.lua")
            })
            .collect();
        let (done, errors) = self.hbm.apply(&self.rt, behaviors);
        self.after_hbm_change();
        self.reload_hfsm(&touched, done, errors)
    }

    fn after_hbm_change(&mut self) {
        self.io.borrow_mut().known_behaviors = Some(self.hbm.names().into_iter().collect());
    }

    /// Whether the robot is stopped for running away (see the module documentation).
    pub fn stopped(&self) -> bool {
        self.runaways >= RUNAWAY_LIMIT || self.failing >= FAULT_LIMIT
    }

    /// What the top of the stack is called in errors (the HFSM file or the behavior).
    fn top_name(&self) -> String {
        match &self.top {
            Top::Hfsm(h, _) => h.file().to_string(),
            Top::Behavior(b) => b.clone(),
        }
    }

    fn reload_hfsm(
        &mut self,
        touched: &[PathBuf],
        mut done: Vec<String>,
        mut errors: Vec<ScriptError>,
    ) -> (Vec<String>, Vec<ScriptError>) {
        if let Top::Hfsm(h, path) = &mut self.top {
            // The machine file, or a machine file it may include, changed.
            let machine_touched = touched.iter().any(|p| {
                p == path
                    || p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.ends_with(".hfsm.lua"))
            });
            let attempt = if machine_touched {
                h.reload(&self.rt).map(|()| true)
            } else {
                h.reload_if_changed(&self.rt)
            };
            match attempt {
                Ok(true) => {
                    done.push(h.file().to_string());
                    self.structure_in = 0;
                }
                Ok(false) => {}
                Err(e) => errors.push(e),
            }
        }
        if !done.is_empty() {
            // An edited behavior gets a fresh start.
            (self.runaways, self.failing) = (0, 0);
        }
        (done, errors)
    }

    /// Runs one cycle on `world`.
    pub fn cycle(&mut self, world: WorldSnapshot) -> Cycle {
        let (mut reloaded, mut errors) = (Vec::new(), Vec::new());
        let changes = self.watcher.as_ref().map(ScriptWatcher::changes).unwrap_or_default();
        if !changes.is_empty() {
            (reloaded, errors) = self.apply(changes);
        }
        let rejected = errors.len();
        self.io.borrow_mut().new_cycle(world);
        let structure = self.structure();
        if self.stopped() {
            let command = RobotCommand::default();
            let path = self.hfsm().map(Hfsm::path).unwrap_or_default();
            let behavior = None;
            return Cycle { command, path, behavior, taken: None, reloaded, errors, structure };
        }
        let mut taken = None;
        let (chosen, path) = match &mut self.top {
            Top::Behavior(name) => (Some(name.clone()), String::new()),
            Top::Hfsm(h, _) => {
                let mut runaway = false;
                match h.step(&self.rt) {
                    Ok(t) => taken = t,
                    Err(e) => {
                        runaway =
                            matches!(e, ScriptError::Budget { .. } | ScriptError::Memory { .. });
                        errors.push(e);
                    }
                }
                let asked = self.io.borrow().command.behavior.clone();
                let chosen = if runaway { None } else { asked.or_else(|| self.last_good.clone()) };
                if runaway {
                    // A runaway machine gets the safe command for this cycle.
                    self.io.borrow_mut().command = RobotCommand::default();
                }
                (chosen, h.path())
            }
        };
        let mut behavior = None;
        if let Some(name) = chosen {
            self.io.borrow_mut().activate(&name);
            match self.hbm.run(&self.rt, &name) {
                Ok(()) => {
                    self.last_good = Some(name.clone());
                    behavior = Some(name);
                }
                Err(e) => {
                    errors.push(e);
                    self.io.borrow_mut().command = RobotCommand::default();
                }
            }
        }
        let mut command = self.io.borrow().command.clone();
        if command.behavior.is_none() {
            command.behavior = behavior.clone();
        }
        // What ran this cycle failed (a rejected reload is not the running behavior's fault).
        let failed = &errors[rejected..];
        let runaway = failed
            .iter()
            .any(|e| matches!(e, ScriptError::Budget { .. } | ScriptError::Memory { .. }));
        self.runaways = if runaway { self.runaways + 1 } else { 0 };
        self.failing = if failed.is_empty() { 0 } else { self.failing + 1 };
        if self.stopped() {
            let (cycles, why) = if self.runaways >= RUNAWAY_LIMIT {
                (self.runaways, "running away")
            } else {
                (self.failing, "with errors")
            };
            errors.push(ScriptError::Stopped { file: self.top_name(), cycles, why });
        }
        Cycle { command, path, behavior, taken, reloaded, errors, structure }
    }

    /// The HFSM's shape when it is due ([`Cycle::structure`]).
    fn structure(&mut self) -> Option<mrt_msgs::HfsmStructure> {
        let Top::Hfsm(h, _) = &self.top else { return None };
        let due = self.structure_in == 0;
        self.structure_in = if due { STRUCTURE_EVERY - 1 } else { self.structure_in - 1 };
        due.then(|| h.structure())
    }
}
