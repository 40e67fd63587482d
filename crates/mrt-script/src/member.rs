//! The behavior Members: ThinkingCap's HFSM and HBM on the DCDT bus (ThinkingCap/TeamChaos report §2.1).
//!
//! A [`BehaviorMember`] reads the latest [`WorldSnapshot`] from the bus, runs one cycle of an
//! HFSM (the "HFSM Member") or of one HBM behavior (the "HBM Member") per activation (every
//! 100 ms by default, as in the seed: [`DEFAULT_PERIOD`]), and publishes the [`RobotCommand`](mrt_msgs::robot::RobotCommand)
//! and a [`BehaviorStatus`] (active path, behavior, errors) for monitors, with the HFSM's
//! shape as an [`HfsmStructure`](mrt_msgs::HfsmStructure) when it is loaded or reloaded and
//! every 100 cycles (`STRUCTURE_EVERY`) (ThinkingCap/TeamChaos report §4.1, §5.1). A
//! [`ReloadRequest`] on the bus reloads the edited scripts at the next cycle boundary; a
//! [`BehaviorPush`] for this robot's Agora brings the edited file itself, like the seed's
//! editor sending a behavior to a running robot ([`crate::push`]): it is compiled off the
//! control path, written into the behavior directory and swapped in at a cycle boundary, and
//! a [`BehaviorPushReply`] says whether it runs or why the old version stays.
//!
//! A Lua state belongs to one thread, and Members may move between threads, so the scripts run
//! on a worker thread owned by the Member, under the [`Watchdog`]: each cycle is one
//! synchronous round trip (a few microseconds), so the stepped executor stays deterministic,
//! and a cycle that does not end within the deadline stops the behavior, not the robot, until
//! it restarts from its files. On a simulated clock the deadline is [`SIMULATED_DEADLINE`], a
//! backstop the instruction budget makes unreachable for a behavior of Lua code, so that a
//! busy machine cannot change a match.

use crate::cap::ThinkingCap;
use crate::push::Pusher;
use crate::runtime::Sandbox;
use crate::watchdog::{Watchdog, DEFAULT_DEADLINE, SIMULATED_DEADLINE};
use mrt_dcdt::{Context, Inputs, Member, MemberError, RequestType};
use mrt_msgs::robot::WorldSnapshot;
use std::path::PathBuf;
use std::time::Duration;

/// The seed's control period: "both a low-level and a high-level behavior are executed every
/// 100 ms" (§3.2).
pub const DEFAULT_PERIOD: Duration = Duration::from_millis(100);

pub use mrt_msgs::{BehaviorPush, BehaviorPushReply, BehaviorStatus, ReloadRequest};

/// What the Member runs.
#[derive(Clone, Debug)]
enum Top {
    Hfsm(PathBuf),
    Behavior(String),
}

/// An HFSM or HBM Member (see the module documentation).
pub struct BehaviorMember {
    name: String,
    dir: PathBuf,
    top: Top,
    sandbox: Sandbox,
    watch: bool,
    /// Set by [`BehaviorMember::with_deadline`]; by the clock otherwise.
    deadline: Option<Duration>,
    worker: Option<Watchdog>,
    world: WorldSnapshot,
    blackboard: Option<mrt_blackboard::Blackboard>,
    pusher: Option<Pusher>,
    /// A reload was asked for since the last cycle.
    reload: bool,
    /// Pushed behaviors received since the last cycle.
    pushes: Vec<BehaviorPush>,
    inputs: Inputs<BehaviorMember>,
}

impl BehaviorMember {
    /// The HFSM Member: runs the machine of `machine` over the behaviors of `dir`.
    pub fn hfsm(dir: impl Into<PathBuf>, machine: impl Into<PathBuf>) -> Self {
        Self::new(dir.into(), Top::Hfsm(machine.into()))
    }

    /// The HBM Member: runs behavior `behavior` of `dir` every cycle.
    pub fn hbm(dir: impl Into<PathBuf>, behavior: &str) -> Self {
        Self::new(dir.into(), Top::Behavior(behavior.to_string()))
    }

    fn new(dir: PathBuf, top: Top) -> Self {
        let name = match &top {
            Top::Hfsm(p) => format!("hfsm:{}", p.display()),
            Top::Behavior(b) => format!("hbm:{b}"),
        };
        Self {
            name,
            dir,
            top,
            sandbox: Sandbox::default(),
            watch: false,
            deadline: None,
            worker: None,
            world: WorldSnapshot::default(),
            blackboard: None,
            pusher: None,
            reload: false,
            pushes: Vec::new(),
            inputs: Self::inputs(),
        }
    }

    /// What the behaviors read: only this robot's own world (an Agora may share a link with
    /// teammates); reload requests and pushed behaviors from anywhere.
    fn inputs() -> Inputs<BehaviorMember> {
        Inputs::<Self>::new()
            .on::<WorldSnapshot>(RequestType::Local, |b, w| b.world.clone_from(w))
            .on::<ReloadRequest>(RequestType::All, |b, _| b.reload = true)
            .on_msg::<BehaviorPush>(RequestType::All, |b, m| match m.get::<BehaviorPush>() {
                Ok(push) => b.pushes.push(push.clone()),
                Err(e) => tracing::warn!(member = %b.name, "dropped a malformed push: {e}"),
            })
    }

    /// Sets the sandbox limits.
    pub fn with_sandbox(mut self, sandbox: Sandbox) -> Self {
        self.sandbox = sandbox;
        self
    }

    /// Binds `bb.*` in the behaviors to the robot's blackboard.
    pub fn with_blackboard(mut self, bb: mrt_blackboard::Blackboard) -> Self {
        self.blackboard = Some(bb);
        self
    }

    /// Also watches the files (`notify`): edits apply at the next cycle without a request.
    pub fn watching(mut self, watch: bool) -> Self {
        self.watch = watch;
        self
    }

    /// Sets the watchdog's deadline for one cycle ([`DEFAULT_DEADLINE`] by default,
    /// [`SIMULATED_DEADLINE`] on a simulated clock).
    pub fn with_deadline(mut self, deadline: Duration) -> Self {
        self.deadline = Some(deadline);
        self
    }

    fn spawn(&self, simulated: bool) -> Result<Watchdog, MemberError> {
        let (dir, top, sandbox, watch, bb) =
            (self.dir.clone(), self.top.clone(), self.sandbox, self.watch, self.blackboard.clone());
        let load = move || {
            let mut cap = match &top {
                Top::Hfsm(file) => ThinkingCap::load_hfsm(&dir, file, sandbox, bb.clone()),
                Top::Behavior(name) => ThinkingCap::load_behavior(&dir, name, sandbox, bb.clone()),
            }?;
            if watch {
                cap.watch(&dir)?;
            }
            Ok(cap)
        };
        let deadline = self.deadline.unwrap_or(match simulated {
            true => SIMULATED_DEADLINE,
            false => DEFAULT_DEADLINE,
        });
        Watchdog::start(&self.name, deadline, load).map_err(|e| e.to_string().into())
    }
}

impl Member for BehaviorMember {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        self.pusher = Some(Pusher::new(ctx.agora_id().0, self.dir.clone()));
        self.worker = Some(self.spawn(ctx.clock_is_simulated())?);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        let (Some(worker), Some(pusher)) = (&mut self.worker, &mut self.pusher) else {
            return Err("not initialized".into());
        };
        let (mut early, mut replies) = (Vec::new(), Vec::new());
        if std::mem::take(&mut self.reload) {
            if let Err(e) = worker.reload_requested() {
                early.push(e.to_string());
            }
        }
        for push in std::mem::take(&mut self.pushes) {
            replies.extend(pusher.receive(&push));
        }
        // Pushes compiled since the last cycle are swapped in at this boundary.
        for ready in pusher.ready() {
            let reply = pusher.settle(ready, |change| worker.install(change));
            match &reply.error {
                None => {
                    tracing::info!(member = %self.name, file = %reply.file, "pushed behavior installed")
                }
                Some(e) => tracing::warn!(member = %self.name, "pushed behavior refused: {e}"),
            }
            replies.push(reply);
        }
        for reply in replies {
            ctx.publish_with(reply, mrt_dcdt::DeliveryWarranty::Reliable, 0);
        }
        let c = worker.cycle(self.world.clone());
        let errors: Vec<String> =
            early.into_iter().chain(c.errors.iter().map(ToString::to_string)).collect();
        for e in &errors {
            tracing::warn!(member = %self.name, "{e}");
        }
        let status = BehaviorStatus {
            path: c.path,
            behavior: c.behavior,
            reloaded: c.reloaded,
            errors,
            activations: Vec::new(),
        };
        ctx.publish(c.command);
        ctx.publish(status);
        if let Some(structure) = c.structure {
            ctx.publish(structure);
        }
        Ok(())
    }

    fn close(&mut self, _ctx: &mut Context<'_>) {
        // The worker ends when its job channel closes.
        self.worker = None;
    }
}
