//! SCARE's sequencing sub-module (MRT manual ch. 11): "the sequencing sub-module decomposes
//! the assigned task into simpler subtasks, schedules their execution, and monitors the
//! environment to react to unexpected events".
//!
//! A [`Sequencer`] walks one activity's sub-tasks ([`SubTask`]: a name and a time limit) in
//! order. Each cycle the caller, which knows what the sub-task means (Team Milan's
//! [`soccer`](super::soccer) module, the Roby-style path-point mission of `mrt-sim`'s
//! indoor world), judges the current sub-task with a [`Verdict`]; the sequencer is its
//! *monitor*: success moves to the next sub-task (the last one's success ends the activity),
//! failure or an exceeded time limit ends it as [`Progress::Failed`], with the cause, so
//! that the caller re-allocates or asks SPIKE for a new plan (the manual's Roby: a
//! ReachPathPoint that times out is aborted and the planner is asked for a new path).
//!
//! ```
//! use mrt_team::scare::sequencer::{Cause, Progress, Sequencer, SubTask, Verdict};
//!
//! let mut s = Sequencer::new(vec![SubTask::new("ReachBall", 5.0), SubTask::new("Kick", 1.0)], 0.0);
//! assert_eq!(s.tick(0.1, Verdict::Running), Progress::Running { step: 0 });
//! assert_eq!(s.tick(2.0, Verdict::Success), Progress::Advanced { step: 1 });
//! assert_eq!(s.current().map(|t| t.name.as_str()), Some("Kick"));
//! // The kick's second is up at 3.0 s.
//! assert_eq!(s.tick(3.5, Verdict::Running), Progress::Failed { step: 1, cause: Cause::Timeout });
//! ```

/// One sub-task: what the robot's behaviors pursue for a while.
#[derive(Clone, Debug, PartialEq)]
pub struct SubTask {
    /// Its name, e.g. `ReachBall` (published with the goals so behaviors and monitors read
    /// it).
    pub name: String,
    /// Seconds it may take; infinite for no limit. Not a number is read as no limit.
    pub timeout: f64,
}

impl SubTask {
    /// A sub-task that must succeed within `timeout` seconds.
    pub fn new(name: &str, timeout: f64) -> SubTask {
        SubTask { name: name.to_string(), timeout }
    }
}

/// How the caller judges the current sub-task this cycle (its success and failure
/// conditions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Neither succeeded nor failed yet.
    Running,
    /// Its success condition holds.
    Success,
    /// Its failure condition holds.
    Failure,
}

/// Why an activity failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// The sub-task's failure condition held.
    Failure,
    /// The sub-task exceeded its time limit.
    Timeout,
}

/// What the monitor made of a cycle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// Sub-task `step` goes on.
    Running {
        /// The current sub-task.
        step: usize,
    },
    /// The previous sub-task succeeded; `step` starts now.
    Advanced {
        /// The new current sub-task.
        step: usize,
    },
    /// The last sub-task succeeded: the activity is done.
    Done,
    /// Sub-task `step` failed: the activity is aborted.
    Failed {
        /// The sub-task that failed.
        step: usize,
        /// Its failure condition, or its time limit.
        cause: Cause,
    },
}

/// One activity's sub-tasks in order, the current one and since when it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Sequencer {
    steps: Vec<SubTask>,
    step: usize,
    since: f64,
    ended: Option<Progress>,
}

impl Sequencer {
    /// Starts the first of `steps` at `now` (s). With no step the activity is done at once.
    pub fn new(steps: Vec<SubTask>, now: f64) -> Sequencer {
        let ended = steps.is_empty().then_some(Progress::Done);
        Sequencer { steps, step: 0, since: now, ended }
    }

    /// The current sub-task (`None` once the activity ended).
    pub fn current(&self) -> Option<&SubTask> {
        if self.ended.is_some() {
            return None;
        }
        self.steps.get(self.step)
    }

    /// The index of the current (or last) sub-task.
    pub fn step(&self) -> usize {
        self.step
    }

    /// Seconds the current sub-task has run at `now`.
    pub fn elapsed(&self, now: f64) -> f64 {
        (now - self.since).max(0.0)
    }

    /// How the activity ended, once it did.
    pub fn ended(&self) -> Option<Progress> {
        self.ended
    }

    /// Starts the sequence again from its first sub-task.
    pub fn restart(&mut self, now: f64) {
        *self = Sequencer::new(std::mem::take(&mut self.steps), now);
    }

    /// The monitor: applies this cycle's verdict on the current sub-task at `now` (s). Once
    /// the activity ended, every tick repeats how.
    pub fn tick(&mut self, now: f64, verdict: Verdict) -> Progress {
        if let Some(end) = self.ended {
            return end;
        }
        let step = self.step;
        let progress = match verdict {
            Verdict::Failure => Progress::Failed { step, cause: Cause::Failure },
            Verdict::Success if step + 1 >= self.steps.len() => Progress::Done,
            Verdict::Success => {
                self.step += 1;
                self.since = now;
                return Progress::Advanced { step: self.step };
            }
            Verdict::Running => {
                let limit = self.steps.get(step).map_or(f64::INFINITY, |s| s.timeout);
                if limit.is_finite() && self.elapsed(now) > limit {
                    Progress::Failed { step, cause: Cause::Timeout }
                } else {
                    return Progress::Running { step };
                }
            }
        };
        self.ended = Some(progress);
        progress
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The manual's Roby mission: a chain of ReachPathPoint jobs completes; one that times
    /// out is reported so the caller asks for a new plan.
    #[test]
    fn a_chain_of_path_points_completes_and_a_timeout_is_reported() {
        let points = |now| {
            Sequencer::new(
                (0..3).map(|i| SubTask::new(&format!("ReachPathPoint{i}"), 10.0)).collect(),
                now,
            )
        };
        let mut s = points(0.0);
        assert_eq!(s.tick(1.0, Verdict::Success), Progress::Advanced { step: 1 });
        assert_eq!(s.tick(9.0, Verdict::Running), Progress::Running { step: 1 });
        assert_eq!(s.tick(10.0, Verdict::Success), Progress::Advanced { step: 2 });
        assert_eq!(s.tick(12.0, Verdict::Success), Progress::Done);
        assert_eq!(s.current(), None);
        assert_eq!(s.tick(13.0, Verdict::Failure), Progress::Done, "ended stays ended");

        let mut s = points(0.0);
        assert_eq!(s.tick(5.0, Verdict::Success), Progress::Advanced { step: 1 });
        // Its 10 s count from 5.0, when it started.
        assert_eq!(s.tick(15.0, Verdict::Running), Progress::Running { step: 1 });
        assert_eq!(
            s.tick(15.1, Verdict::Running),
            Progress::Failed { step: 1, cause: Cause::Timeout }
        );
        s.restart(16.0);
        assert_eq!(s.current().map(|t| t.name.as_str()), Some("ReachPathPoint0"));
        assert_eq!(
            s.tick(16.5, Verdict::Failure),
            Progress::Failed { step: 0, cause: Cause::Failure }
        );
    }

    #[test]
    fn no_steps_is_done_and_odd_limits_mean_no_limit() {
        let mut s = Sequencer::new(Vec::new(), 0.0);
        assert_eq!(s.tick(1.0, Verdict::Running), Progress::Done);
        let mut s = Sequencer::new(vec![SubTask::new("Wait", f64::NAN)], 0.0);
        assert_eq!(s.tick(1e9, Verdict::Running), Progress::Running { step: 0 });
        // A clock that goes back does not make time negative.
        assert_eq!(s.elapsed(-5.0), 0.0);
    }
}
