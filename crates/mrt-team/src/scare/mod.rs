//! SCARE, *Scare Coordinates Agents in Robotic Environments* (MRT manual ch. 11): who does
//! which activity, decided by every robot identically from data the team shares, then each
//! robot's activity decomposed into sub-tasks and watched.
//!
//! The manual gives the parts and their names and only sketches how they work; what it
//! leaves open (how the agenda is ordered, how robots are given activities, the settings)
//! is this module's design. This module is the coordination sub-module:
//!
//! - **Activities** ([`Activity`]): a *job* is done by one robot or several
//!   ([`Activity::job`], with a cardinality `card_min..=card_max`); a *schema* is done by
//!   several robots together, each covering one of its *functionalities*
//!   ([`Activity::schema`]: PassageToMate needs a passer and a receiver).
//! - Each robot rates its **attitude** for each functionality (how suited it is, `0..=1`; 0:
//!   it cannot) and the team rates each activity's **opportunity** (how useful it is now,
//!   `0..=1`). Robots tell each other their attitudes; the opportunities every robot uses are
//!   those of one robot (the caller's choice: Team Milan takes the lowest-numbered robot
//!   heard), so that all allocate from the same numbers.
//! - **The agenda** ([`agenda`]): the activities whose opportunity reaches
//!   [`Params::admit`] (a fuzzy truth ≥ 0.5, a design choice), by priority, then
//!   opportunity, then their order in the table. *Design choice*: the manual says
//!   "multi-objective analysis" without a method; a fixed priority with the opportunity as
//!   the second key is what a team can read and tune.
//! - **The allocation** ([`allocate`]): the agenda is walked twice. The first pass gives each
//!   admitted job its `card_min` best free robots (a job that cannot have them is skipped)
//!   and each schema the best cover of all its functionalities by free robots of non-zero
//!   attitude (a maximum-weight matching, Kuhn–Munkres, from `pathfinding`; a schema that
//!   cannot be covered is skipped); the second pass fills jobs up to `card_max`, in agenda
//!   order. Robots left over get the table's default activity. Activities of one *group* are
//!   alternatives ([`Activity::in_group`]): the first of a group given robots skips the
//!   others (a passage and a plain BringBall both play the ball). A robot's current activity
//!   counts [`Params::hysteresis`] more, so that two robots rated 0.50 and 0.52 do not swap
//!   back and forth. Robots are taken in number order and ties go to the lower number: the
//!   result depends on the data, not on the order they arrived in.
//! - **Connectivity**: the caller passes the robots it heard lately. A robot that hears no
//!   teammate allocates for itself alone: it takes the first activity of the agenda it can
//!   do ("the policy changes with the information that can be exchanged").
//!
//! The sequencing sub-module is [`sequencer`]; Team Milan's activities are [`soccer`].
//!
//! ```
//! use mrt_team::scare::{allocate, Activities, Activity, Agent, Params};
//!
//! let table = Activities::new(vec![
//!     Activity::job("Goalie", 1, 1, 3),
//!     Activity::job("BringBall", 1, 1, 2),
//!     Activity::job("Defense", 0, 2, 1),
//! ]);
//! // Attitudes per slot: Goalie, BringBall, Defense.
//! let agents = [
//!     Agent::new(1, vec![1.0, 0.0, 0.0]),
//!     Agent::new(2, vec![0.0, 0.9, 0.4]),
//!     Agent::new(3, vec![0.0, 0.5, 0.6]),
//! ];
//! let a = allocate(&table, &[1.0, 1.0, 1.0], &agents, &Params::default());
//! assert_eq!(a.names(&table), vec![(1, "Goalie"), (2, "BringBall"), (3, "Defense")]);
//! ```

pub mod sequencer;
pub mod soccer;

use pathfinding::kuhn_munkres::kuhn_munkres;
use pathfinding::matrix::Matrix;

/// One activity of the table (MRT manual ch. 11: a job or a schema).
#[derive(Clone, Debug, PartialEq)]
pub struct Activity {
    /// Its name, e.g. `BringBall`.
    pub name: String,
    /// A schema's functionalities (its roles, e.g. `passer`, `receiver`); a job has one,
    /// named after the job.
    pub functionalities: Vec<String>,
    /// Whether it is a schema (every functionality covered by its own robot, or none).
    pub schema: bool,
    /// A job's fewest robots: with fewer free robots able to do it, it is skipped.
    pub card_min: usize,
    /// A job's most robots.
    pub card_max: usize,
    /// Higher first on the agenda.
    pub priority: u8,
    /// Activities of one group are alternatives (two ways of doing one thing: PassageToMate
    /// and BringBall both play the ball): once one of them is given, the others of the group
    /// are skipped. `None`: in no group.
    pub group: Option<String>,
}

impl Activity {
    /// A job for `card_min..=card_max` robots.
    pub fn job(name: &str, card_min: usize, card_max: usize, priority: u8) -> Activity {
        Activity {
            name: name.to_string(),
            functionalities: vec![name.to_string()],
            schema: false,
            card_min,
            card_max: card_max.max(card_min),
            priority,
            group: None,
        }
    }

    /// A schema with one robot for each of its `functionalities`.
    pub fn schema(name: &str, functionalities: &[&str], priority: u8) -> Activity {
        Activity {
            name: name.to_string(),
            functionalities: functionalities.iter().map(|f| f.to_string()).collect(),
            schema: true,
            card_min: functionalities.len(),
            card_max: functionalities.len(),
            priority,
            group: None,
        }
    }

    /// The same activity in group `group` (see [`Activity::group`]).
    pub fn in_group(mut self, group: &str) -> Activity {
        self.group = Some(group.to_string());
        self
    }
}

/// The activity table every robot of a team shares: the activities, where each one's
/// functionalities start in a flat attitude vector, and the default activity for robots left
/// over.
#[derive(Clone, Debug, PartialEq)]
pub struct Activities {
    list: Vec<Activity>,
    /// `offsets[a]`: the slot of activity `a`'s first functionality.
    offsets: Vec<usize>,
    slots: usize,
    default: Option<usize>,
}

impl Activities {
    /// The table of `list`, with no default activity.
    pub fn new(list: Vec<Activity>) -> Activities {
        let mut offsets = Vec::with_capacity(list.len());
        let mut slots = 0;
        for a in &list {
            offsets.push(slots);
            slots += a.functionalities.len();
        }
        Activities { list, offsets, slots, default: None }
    }

    /// The same table where robots left over take the job named `name` (when there is one).
    pub fn with_default(mut self, name: &str) -> Activities {
        self.default = self.find(name);
        self
    }

    /// The activities, in table order.
    pub fn list(&self) -> &[Activity] {
        &self.list
    }

    /// The index of the activity named `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.list.iter().position(|a| a.name == name)
    }

    /// How many (activity, functionality) slots an attitude vector has.
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// The slot of functionality `f` of activity `a` in an attitude vector.
    pub fn slot(&self, a: usize, f: usize) -> Option<usize> {
        let act = self.list.get(a)?;
        (f < act.functionalities.len()).then(|| self.offsets[a] + f)
    }

    /// A short fingerprint of the table (FNV-1a over names, functionalities, cardinalities
    /// and priorities): teammates whose reports carry another one run another table, and
    /// their attitudes cannot be read slot by slot.
    pub fn fingerprint(&self) -> u32 {
        let mut h: u32 = 0x811c_9dc5;
        let mut eat = |bytes: &[u8]| {
            for b in bytes {
                h ^= u32::from(*b);
                h = h.wrapping_mul(0x0100_0193);
            }
        };
        for a in &self.list {
            eat(a.name.as_bytes());
            for f in &a.functionalities {
                eat(&[0]);
                eat(f.as_bytes());
            }
            eat(&[1, u8::from(a.schema), a.card_min as u8, a.card_max as u8, a.priority]);
            eat(a.group.as_deref().unwrap_or("").as_bytes());
        }
        h
    }
}

/// What a robot does: an activity and, in a schema, which of its functionalities.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Assignment {
    /// Index in the [`Activities`] table.
    pub activity: usize,
    /// Index in the activity's functionalities (0 for a job).
    pub functionality: usize,
}

/// One robot as the allocation sees it: its number, its attitude for every slot of the table
/// ([`Activities::slot`]) and what it is doing now (for the hysteresis).
#[derive(Clone, Debug, PartialEq)]
pub struct Agent {
    /// Its number.
    pub id: u32,
    /// Its attitude per slot, `0..=1`; 0 (or less, or not a number, or missing): it cannot.
    pub attitudes: Vec<f64>,
    /// What it does now, as it said.
    pub doing: Option<Assignment>,
}

impl Agent {
    /// A robot doing nothing yet.
    pub fn new(id: u32, attitudes: Vec<f64>) -> Agent {
        Agent { id, attitudes, doing: None }
    }

    /// The same robot, doing `doing`.
    pub fn doing(mut self, doing: Option<Assignment>) -> Agent {
        self.doing = doing;
        self
    }
}

/// The allocation's settings (design choices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    /// An activity whose opportunity is below this is not on the agenda (0.5: the
    /// opportunity is more true than false).
    pub admit: f64,
    /// How much more a robot's current activity counts.
    pub hysteresis: f64,
}

impl Default for Params {
    fn default() -> Params {
        Params { admit: 0.5, hysteresis: 0.1 }
    }
}

/// The result of [`allocate`]: every robot's activity, in robot-number order (`None`: left
/// over with no default), and the agenda it was computed from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Allocation {
    /// `(robot, what it does)`, by robot number.
    pub assignments: Vec<(u32, Option<Assignment>)>,
    /// The admitted activities, in agenda order.
    pub agenda: Vec<usize>,
}

impl Allocation {
    /// What robot `id` does.
    pub fn of(&self, id: u32) -> Option<Assignment> {
        self.assignments.iter().find(|(r, _)| *r == id).and_then(|(_, a)| *a)
    }

    /// The robots doing activity `a`.
    pub fn doing(&self, a: usize) -> Vec<u32> {
        self.assignments
            .iter()
            .filter(|(_, x)| x.is_some_and(|x| x.activity == a))
            .map(|(r, _)| *r)
            .collect()
    }

    /// `(robot, activity name)` for each robot with an activity (for tests and logs).
    pub fn names<'t>(&self, table: &'t Activities) -> Vec<(u32, &'t str)> {
        self.assignments
            .iter()
            .filter_map(|(r, a)| Some((*r, table.list.get(a.as_ref()?.activity)?.name.as_str())))
            .collect()
    }
}

/// The agenda: the activities with an opportunity of at least `params.admit`, by priority
/// (higher first), then opportunity (higher first), then table order. A missing or
/// non-finite opportunity is 0.
pub fn agenda(table: &Activities, opportunity: &[f64], params: &Params) -> Vec<usize> {
    let opp = |a: usize| opportunity.get(a).copied().filter(|o| o.is_finite()).unwrap_or(0.0);
    let mut agenda: Vec<usize> =
        (0..table.list.len()).filter(|a| opp(*a) >= params.admit).collect();
    agenda.sort_by(|a, b| {
        table.list[*b]
            .priority
            .cmp(&table.list[*a].priority)
            .then(opp(*b).total_cmp(&opp(*a)))
            .then(a.cmp(b))
    });
    agenda
}

/// Who does what (module doc): identical on every robot given the same `opportunity`
/// (per activity) and `agents` in any order.
pub fn allocate(
    table: &Activities,
    opportunity: &[f64],
    agents: &[Agent],
    params: &Params,
) -> Allocation {
    let agenda = agenda(table, opportunity, params);
    let mut agents: Vec<&Agent> = agents.iter().collect();
    agents.sort_by_key(|a| a.id);
    agents.dedup_by_key(|a| a.id);
    let n = agents.len();
    let mut given: Vec<Option<Assignment>> = vec![None; n];
    // A robot's score for a slot: its attitude, plus the hysteresis for what it does now;
    // `None` when it cannot.
    let score = |i: usize, a: usize, f: usize| -> Option<f64> {
        let s = table.slot(a, f)?;
        let att = agents[i].attitudes.get(s).copied().filter(|v| v.is_finite() && *v > 0.0)?;
        let here = Assignment { activity: a, functionality: f };
        Some(att.min(1.0) + if agents[i].doing == Some(here) { params.hysteresis } else { 0.0 })
    };
    // The free robots able to do job `a`, best first, ties to the lower number.
    let candidates = |given: &[Option<Assignment>], a: usize| -> Vec<usize> {
        let mut c: Vec<(usize, f64)> = (0..n)
            .filter(|i| given[*i].is_none())
            .filter_map(|i| Some((i, score(i, a, 0)?)))
            .collect();
        c.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        c.into_iter().map(|(i, _)| i).collect()
    };
    let mut admitted = Vec::new();
    // Each group and the activity of it that was given robots first.
    let mut owners: Vec<(&str, usize)> = Vec::new();
    let taken_by_other = |owners: &[(&str, usize)], a: usize| {
        table.list[a].group.as_deref().is_some_and(|g| owners.iter().any(|o| o.0 == g && o.1 != a))
    };
    for &a in &agenda {
        let act = &table.list[a];
        if taken_by_other(&owners, a) {
            continue;
        }
        if act.schema {
            let Some(cover) = cover_schema(act, &given, n, |i, f| score(i, a, f)) else {
                continue;
            };
            for (f, i) in cover.into_iter().enumerate() {
                given[i] = Some(Assignment { activity: a, functionality: f });
            }
        } else {
            let c = candidates(&given, a);
            if c.len() < act.card_min {
                continue;
            }
            for &i in c.iter().take(act.card_min) {
                given[i] = Some(Assignment { activity: a, functionality: 0 });
            }
            admitted.push(a);
            if act.card_min == 0 {
                // No robot yet: the group stays open until the second pass gives it some.
                continue;
            }
        }
        owners.extend(act.group.as_deref().map(|g| (g, a)));
    }
    for a in admitted {
        if taken_by_other(&owners, a) {
            continue;
        }
        let act = &table.list[a];
        let have = given.iter().filter(|g| g.is_some_and(|g| g.activity == a)).count();
        let more = candidates(&given, a).into_iter().take(act.card_max.saturating_sub(have));
        let mut any = have > 0;
        for i in more {
            given[i] = Some(Assignment { activity: a, functionality: 0 });
            any = true;
        }
        if any {
            owners.extend(act.group.as_deref().map(|g| (g, a)));
        }
    }
    if let Some(d) = table.default {
        for g in given.iter_mut().filter(|g| g.is_none()) {
            *g = Some(Assignment { activity: d, functionality: 0 });
        }
    }
    Allocation { assignments: agents.iter().map(|a| a.id).zip(given).collect(), agenda }
}

/// The best cover of a schema's functionalities by free robots (a robot each), maximizing
/// the summed scores; `None` when some functionality has no free robot able to do it.
fn cover_schema(
    act: &Activity,
    given: &[Option<Assignment>],
    n: usize,
    score: impl Fn(usize, usize) -> Option<f64>,
) -> Option<Vec<usize>> {
    let free: Vec<usize> = (0..n).filter(|i| given[*i].is_none()).collect();
    let k = act.functionalities.len();
    if k == 0 || free.len() < k {
        return None;
    }
    // Integer weights (Kuhn–Munkres needs a total order): scores in millionths; a robot that
    // cannot do a functionality weighs far below any cover that avoids it.
    const CANNOT: i64 = -1_000_000_000;
    let weights = Matrix::from_fn(k, free.len(), |(f, j)| {
        score(free[j], f).map_or(CANNOT, |s| (s * 1e6).round() as i64)
    });
    let (_, cols) = kuhn_munkres(&weights);
    let cover: Vec<usize> = cols.iter().map(|&j| free[j]).collect();
    cover.iter().enumerate().all(|(f, &i)| score(i, f).is_some()).then_some(cover)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A test table of three jobs: Goalie (1..1, only the keeper can), BringBall (1..1),
    /// Defense (0..2).
    fn three() -> Activities {
        Activities::new(vec![
            Activity::job("Goalie", 1, 1, 3),
            Activity::job("BringBall", 1, 1, 2),
            Activity::job("Defense", 0, 2, 1),
        ])
    }

    #[test]
    fn cardinality_and_priority_give_the_expected_allocation() {
        let t = three();
        let agents = [
            Agent::new(1, vec![1.0, 0.0, 0.0]),
            Agent::new(2, vec![0.0, 0.3, 0.8]),
            Agent::new(3, vec![0.0, 0.7, 0.5]),
            Agent::new(4, vec![0.0, 0.6, 0.9]),
        ];
        let a = allocate(&t, &[1.0; 3], &agents, &Params::default());
        // The keeper keeps goal; the best at BringBall brings it, although 4 is better at
        // Defense than 3 is at BringBall; Defense takes the other two (card_max 2).
        assert_eq!(
            a.names(&t),
            vec![(1, "Goalie"), (2, "Defense"), (3, "BringBall"), (4, "Defense")]
        );
        assert_eq!(a.agenda, vec![0, 1, 2]);
        // A third defender would be one too many: the last robot is left over (no default).
        let five: Vec<Agent> =
            agents.iter().cloned().chain([Agent::new(5, vec![0.0, 0.1, 0.2])]).collect();
        let a = allocate(&t, &[1.0; 3], &five, &Params::default());
        assert_eq!(a.of(5), None);
        assert_eq!(a.doing(2), vec![2, 4]);
        // With a default job, it takes that.
        let t = Activities::new(vec![
            Activity::job("Goalie", 1, 1, 3),
            Activity::job("BringBall", 1, 1, 2),
            Activity::job("Defense", 0, 2, 1),
            Activity::job("Support", 0, 9, 0),
        ])
        .with_default("Support");
        let five: Vec<Agent> = five
            .into_iter()
            .map(|mut a| {
                a.attitudes.push(0.0);
                a
            })
            .collect();
        let a = allocate(&t, &[1.0, 1.0, 1.0, 0.0], &five, &Params::default());
        assert_eq!(a.names(&t)[4], (5, "Support"));
    }

    #[test]
    fn a_job_short_of_its_minimum_is_skipped_and_its_robots_stay_free() {
        let t =
            Activities::new(vec![Activity::job("Pair", 2, 2, 2), Activity::job("Solo", 1, 1, 1)]);
        // Only robot 1 can do Pair: it is skipped, and robot 1 is free for Solo.
        let agents = [Agent::new(1, vec![0.9, 0.5]), Agent::new(2, vec![0.0, 0.4])];
        let a = allocate(&t, &[1.0, 1.0], &agents, &Params::default());
        assert_eq!(a.names(&t), vec![(1, "Solo")]);
        assert_eq!(a.of(2), None);
    }

    #[test]
    fn a_schema_is_given_only_when_every_functionality_is_covered() {
        let t = Activities::new(vec![
            Activity::schema("PassageToMate", &["passer", "receiver"], 2),
            Activity::job("BringBall", 1, 1, 1),
        ]);
        // Slots: passer, receiver, BringBall. Only one robot free: no passage.
        let one = [Agent::new(7, vec![0.9, 0.8, 0.6])];
        let a = allocate(&t, &[1.0, 1.0], &one, &Params::default());
        assert_eq!(a.names(&t), vec![(7, "BringBall")]);
        // Two robots, but nobody can receive: no passage either.
        let two = [Agent::new(1, vec![0.9, 0.0, 0.6]), Agent::new(2, vec![0.5, 0.0, 0.4])];
        let a = allocate(&t, &[1.0, 1.0], &two, &Params::default());
        assert_eq!(a.names(&t), vec![(1, "BringBall")]);
        // Robot 1 passes better, but robot 2 can only pass: the best cover makes 1 the
        // receiver (0.4 + 0.6 against nothing), not the greedy pick of the best passer.
        let two = [Agent::new(1, vec![0.9, 0.6, 0.5]), Agent::new(2, vec![0.4, 0.0, 0.3])];
        let a = allocate(&t, &[1.0, 1.0], &two, &Params::default());
        assert_eq!(a.of(2), Some(Assignment { activity: 0, functionality: 0 }));
        assert_eq!(a.of(1), Some(Assignment { activity: 0, functionality: 1 }));
    }

    #[test]
    fn activities_of_one_group_are_alternatives() {
        let t = Activities::new(vec![
            Activity::schema("PassageToMate", &["passer", "receiver"], 2).in_group("ball"),
            Activity::job("BringBall", 1, 1, 1).in_group("ball"),
            Activity::job("Support", 0, 9, 0),
        ]);
        // Slots: passer, receiver, BringBall, Support.
        let agents = [
            Agent::new(1, vec![0.9, 0.2, 0.9, 0.3]),
            Agent::new(2, vec![0.1, 0.8, 0.5, 0.3]),
            Agent::new(3, vec![0.0, 0.0, 0.7, 0.3]),
        ];
        let a = allocate(&t, &[1.0, 1.0, 1.0], &agents, &Params::default());
        // The passage is given; robot 3 would bring the ball, but that is the passage's
        // purpose: it supports.
        assert_eq!(a.names(&t), vec![(1, "PassageToMate"), (2, "PassageToMate"), (3, "Support")]);
        // Without a receiver the passage is skipped and BringBall is open again.
        let agents =
            [Agent::new(1, vec![0.9, 0.0, 0.9, 0.3]), Agent::new(3, vec![0.0, 0.0, 0.7, 0.3])];
        let a = allocate(&t, &[1.0, 1.0, 1.0], &agents, &Params::default());
        assert_eq!(a.names(&t), vec![(1, "BringBall"), (3, "Support")]);
        // A job of the group with no minimum does not close the group before it has robots
        // (Press would otherwise shut BringBall out in the first pass and take robot 2 in the
        // second), and once BringBall has its robot the others of the group get none.
        let t = Activities::new(vec![
            Activity::job("Press", 0, 1, 3).in_group("ball"),
            Activity::job("BringBall", 1, 1, 2).in_group("ball"),
            Activity::job("Chase", 0, 1, 1).in_group("ball"),
        ]);
        let agents = [Agent::new(1, vec![0.2, 0.9, 0.5]), Agent::new(2, vec![0.8, 0.3, 0.9])];
        let a = allocate(&t, &[1.0, 1.0, 1.0], &agents, &Params::default());
        assert_eq!(a.names(&t), vec![(1, "BringBall")]);
    }

    #[test]
    fn every_robot_computes_the_same_allocation_whatever_order_it_heard_them_in() {
        let t = three();
        let agents = vec![
            Agent::new(4, vec![0.0, 0.6, 0.6]),
            Agent::new(2, vec![0.0, 0.6, 0.6]),
            Agent::new(1, vec![1.0, 0.0, 0.0]),
            Agent::new(3, vec![0.0, 0.6, 0.6]),
        ];
        let mut rev = agents.clone();
        rev.reverse();
        let (a, b) = (
            allocate(&t, &[1.0; 3], &agents, &Params::default()),
            allocate(&t, &[1.0; 3], &rev, &Params::default()),
        );
        assert_eq!(a, b);
        // All tied: the lowest number brings the ball.
        assert_eq!(a.doing(1), vec![2]);
    }

    #[test]
    fn hysteresis_keeps_the_current_holder_against_a_small_gain() {
        let t = three();
        let bring = Some(Assignment { activity: 1, functionality: 0 });
        let agents =
            [Agent::new(2, vec![0.0, 0.50, 0.5]).doing(bring), Agent::new(3, vec![0.0, 0.52, 0.5])];
        let a = allocate(&t, &[1.0; 3], &agents, &Params::default());
        assert_eq!(a.doing(1), vec![2], "0.52 against 0.50 + 0.1: no flip");
        let agents =
            [Agent::new(2, vec![0.0, 0.50, 0.5]).doing(bring), Agent::new(3, vec![0.0, 0.65, 0.5])];
        let a = allocate(&t, &[1.0; 3], &agents, &Params::default());
        assert_eq!(a.doing(1), vec![3], "a gain above the hysteresis moves the job");
    }

    #[test]
    fn a_robot_alone_takes_the_first_activity_it_can_do() {
        let t = three();
        let me = [Agent::new(3, vec![0.0, 0.4, 0.9])];
        let a = allocate(&t, &[1.0; 3], &me, &Params::default());
        assert_eq!(a.names(&t), vec![(3, "BringBall")]);
        // Below the admission threshold, BringBall is not on the agenda.
        let a = allocate(&t, &[1.0, 0.3, 1.0], &me, &Params::default());
        assert_eq!(a.names(&t), vec![(3, "Defense")]);
        assert_eq!(a.agenda, vec![0, 2]);
    }

    #[test]
    fn odd_numbers_are_read_as_cannot() {
        let t = three();
        let agents = [
            Agent::new(1, vec![f64::NAN, 2.0, -1.0]),
            Agent::new(2, vec![]),
            Agent::new(3, vec![0.0, f64::INFINITY, 0.0]),
            Agent::new(2, vec![0.0, 0.5, 0.0]),
        ];
        let a = allocate(&t, &[f64::NAN, 1.0, 1.0], &agents, &Params::default());
        // 2 is clamped to 1 (it can); NaN, infinity and -1 cannot; the duplicate 2 is dropped.
        assert_eq!(a.names(&t), vec![(1, "BringBall")]);
        assert_eq!(a.agenda, vec![1, 2]);
        assert_eq!(a.assignments.len(), 3);
    }

    #[test]
    fn the_fingerprint_tells_tables_apart() {
        let a = three();
        let mut b = three();
        assert_eq!(a.fingerprint(), b.fingerprint());
        b = Activities::new(vec![
            Activity::job("Goalie", 1, 1, 3),
            Activity::job("BringBall", 1, 2, 2),
        ]);
        assert_ne!(a.fingerprint(), b.fingerprint());
        assert_eq!(a.slot(2, 0), Some(2));
        assert_eq!(a.slot(2, 1), None);
        assert_eq!(a.slot(9, 0), None);
    }
}
