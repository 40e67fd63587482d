//! Re-running a robot's behaviors on the world snapshots it really had
//! (`mrt replay FILE --robot home/2 --behaviors DIR`): a behavior, edited or not, is fed the
//! snapshots of a recording one control cycle at a time, inside an Agora of its own on a
//! simulated clock, exactly as the robot's world state fed it, and its commands are kept to
//! compare with the recorded ones.

use crate::error::RobotError;
use crate::members::behavior_member;
use crate::spec::Stack;
use mrt_core::SimClock;
use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType, SteppedExecutor};
use mrt_msgs::{BehaviorStatus, RobotCommand, WorldSnapshot};
use std::collections::VecDeque;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// What the behavior did in one cycle of a re-run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rerun {
    /// Its command (`None`: it published none in that cycle).
    pub command: Option<RobotCommand>,
    /// The errors it reported in that cycle (a script error with its file and line).
    pub errors: Vec<String>,
}

/// Publishes one recorded snapshot a cycle, as the robot's world state did.
struct Feed(VecDeque<WorldSnapshot>);

impl Member for Feed {
    fn name(&self) -> String {
        "recorded-world-state".into()
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        if let Some(w) = self.0.pop_front() {
            ctx.publish(w);
        }
        Ok(())
    }
}

/// Keeps what the behavior published.
struct Collect(Arc<Mutex<Rerun>>);

impl Member for Collect {
    fn name(&self) -> String {
        "rerun-collector".into()
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        ctx.subscribe_to::<BehaviorStatus>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut out = self.0.lock().map_err(|_| "the re-run's lock is poisoned")?;
        while let Some(m) = ctx.receive_msg() {
            if let Ok(c) = m.get::<RobotCommand>() {
                out.command = Some(c.clone());
            } else if let Ok(s) = m.get::<BehaviorStatus>() {
                out.errors.extend(s.errors.iter().cloned());
            }
        }
        Ok(())
    }
}

/// A whole re-run: each cycle, and the behavior Member's faults (a start that failed, a
/// panic), as its Agora reported them at the end.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RerunReport {
    /// What it did, one entry per snapshot.
    pub cycles: Vec<Rerun>,
    /// The behavior Member's last error, when it had any (e.g. `failed to init: FILE:LINE:
    /// ...`).
    pub fault: Option<String>,
}

/// Runs the behavior Member of a `stack` robot (the goalkeeper when `keeper`; `behaviors` as
/// [`behavior_member`] reads it) on `snapshots`, one per `period`, and returns what it did in
/// each cycle, in order, with its faults. The behavior runs in its own Agora, after the snapshot's publisher,
/// like in the robot cycle.
pub fn rerun(
    stack: Stack,
    keeper: bool,
    behaviors: Option<&Path>,
    period: Duration,
    snapshots: Vec<WorldSnapshot>,
) -> Result<RerunReport, RobotError> {
    let cycles = snapshots.len();
    let mut exec = SteppedExecutor::new(SimClock::new(), period);
    let mut agora = exec.agora_builder(1).build()?;
    let every = Activation::Periodic(period);
    let seen = Arc::new(Mutex::new(Rerun::default()));
    let ids = [
        agora.add_member(Feed(snapshots.into()), every),
        agora.add_boxed_member(behavior_member(stack, keeper, behaviors)?, every),
        agora.add_member(Collect(seen.clone()), Activation::OnMessage),
    ];
    for id in ids {
        agora.activate_member(id)?;
    }
    exec.add_agora(agora)?;
    let mut out = Vec::with_capacity(cycles);
    for _ in 0..cycles {
        exec.run_for(period);
        let mut cycle = seen.lock().map_err(|_| RobotError::Poisoned("re-run's"))?;
        out.push(std::mem::take(&mut *cycle));
    }
    let fault = exec.finish().iter().flat_map(|r| &r.members).find_map(|m| m.last_error.clone());
    Ok(RerunReport { cycles: out, fault })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brain::Brain;
    use crate::stacks::Chaser;
    use mrt_msgs::{lps, GameState, Lpo};

    /// The Chaser re-run in its Agora commands exactly what the Chaser called directly
    /// commands on the same snapshots, one cycle each, in order.
    #[test]
    fn a_rerun_commands_what_the_brain_commands_on_the_same_snapshots() {
        let worlds: Vec<WorldSnapshot> = (0..6)
            .map(|k| {
                let mut w = WorldSnapshot { game_state: GameState::Playing, ..Default::default() };
                w.lps[lps::BALL] = Lpo {
                    rho: 0.5 + 0.3 * f64::from(k),
                    theta: 0.2 * f64::from(k) - 0.5,
                    reliability: 1.0,
                    seen_ago: 0.0,
                };
                w
            })
            .collect();
        let mut direct = Chaser { keeper: false };
        let expected: Vec<RobotCommand> = worlds.iter().map(|w| direct.cycle(w)).collect();
        let report = rerun(Stack::Chaser, false, None, Duration::from_millis(100), worlds).unwrap();
        assert_eq!(report.fault, None);
        assert_eq!(report.cycles.len(), 6);
        for (k, (cycle, want)) in report.cycles.iter().zip(&expected).enumerate() {
            assert_eq!(cycle.command.as_ref(), Some(want), "cycle {k}");
            assert!(cycle.errors.is_empty());
        }
        assert_ne!(expected[0], expected[5], "the snapshots ask for different commands");
    }

    /// An ISocRob robot needs its blackboard: it cannot be re-run alone, and says so.
    #[test]
    fn an_isocrob_robot_is_refused() {
        let e = rerun(Stack::Isocrob, false, None, Duration::from_millis(100), vec![]).unwrap_err();
        assert!(
            matches!(e, crate::RobotError::StackWiring(_)) && e.to_string().contains("blackboard"),
            "{e}"
        );
    }
}
