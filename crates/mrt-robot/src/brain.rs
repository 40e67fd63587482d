//! The [`Brain`] of a robot: what turns its world snapshot into a command each cycle (a
//! behavior stack: Lua HFSM and HBM, Mr. BRIAN, hand-written Rust), and [`BrainMember`], which
//! puts any `Send` brain on the bus.

use mrt_dcdt::{Context, Inputs, Member, MemberError, RequestType};
use mrt_msgs::{BehaviorStatus, RobotCommand, WorldSnapshot};

/// What drives one robot: a behavior stack (Lua HFSM and HBM, Mr. BRIAN, ...).
pub trait Brain {
    /// One control cycle.
    fn cycle(&mut self, world: &WorldSnapshot) -> RobotCommand;

    /// What went wrong since the last call (a script error with its file and line, ...): the
    /// match books it against the robot. The robot went on (or stood still) regardless.
    fn take_faults(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// How active each of its behaviors was in the last cycle, 0 to 1, for monitors
    /// ([`BehaviorStatus::activations`]); empty when the brain has no such notion.
    fn activations(&self) -> Vec<(String, f64)> {
        Vec::new()
    }
}

/// Runs any `Send` [`Brain`] as a behavior Member: world snapshot in, command out, and the
/// brain's faults as a [`BehaviorStatus`] for the robot's fault book.
pub struct BrainMember {
    brain: Box<dyn Brain + Send>,
    world: Option<WorldSnapshot>,
    inputs: Inputs<BrainMember>,
}

impl BrainMember {
    /// A Member around `brain`.
    pub fn new(brain: Box<dyn Brain + Send>) -> Self {
        let inputs = Inputs::new()
            .on::<WorldSnapshot>(RequestType::Local, |b: &mut Self, w| b.world = Some(w.clone()));
        Self { brain, world: None, inputs }
    }
}

impl Member for BrainMember {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        if let Some(w) = &self.world {
            ctx.publish(self.brain.cycle(w));
        }
        // What went wrong, for the fault book (one fault per faulty cycle, named by its first
        // error, as a behavior Member reports), and the behaviors' activations for monitors.
        let errors = self.brain.take_faults();
        let activations = self.brain.activations();
        if !errors.is_empty() || !activations.is_empty() {
            ctx.publish(BehaviorStatus { errors, activations, ..BehaviorStatus::default() });
        }
        Ok(())
    }
}
