//! Team Milan's SCARE activities (MRT manual §2.3 and ch. 12: "several jobs
//! (RecoverWanderingBall, BringBall, Defense, etc.) and schemata (DefensiveDoubling,
//! PassageToMate, Blocking, etc.)"): the table, how a robot rates its attitudes, how the team
//! rates opportunities, each activity's sub-tasks, and the goal each sub-task gives Mr.
//! BRIAN's parametric behaviors.
//!
//! Everything is in the team frame (m, x towards the opponent's net at `(half_length, 0)`),
//! read from a [`Situation`]: what one robot believes. The numbers (distances, priorities,
//! time limits) are design choices tuned on the simulated pitch (`docs/teams.md`).
//!
//! | activity | kind | robots | opportunity | attitude |
//! |---|---|---|---|---|
//! | Goalie | job | 1 | always | the goalkeeper only |
//! | PassageToMate | schema: passer, receiver | 2 | the ball carrier's way is blocked and a mate is open ahead | passer: as BringBall; receiver: open and ahead of the ball |
//! | BringBall | job | 1 | the ball is known | near the ball, on its own side of it |
//! | RecoverWanderingBall | job | 1–2 | the ball is not known | any field player |
//! | DefensiveDoubling | schema: block, cover | 2 | the ball in the own third | near the blocking and the covering spot |
//! | Defense | job | 0–1 | the ball is known | near the spot between the ball and the own goal |
//! | Support | job (default) | any | always | any field player |

use super::sequencer::{Progress, Sequencer, SubTask, Verdict};
use super::{allocate, Activities, Activity, Agent, Allocation, Assignment, Params};
use mrt_core::frames::Framed;
use mrt_core::Point2;
use mrt_msgs::{ScareJob, ScareReport};

/// Indices of Team Milan's activities in [`table`].
pub mod ids {
    /// Goalie.
    pub const GOALIE: usize = 0;
    /// PassageToMate (functionalities: passer 0, receiver 1).
    pub const PASSAGE: usize = 1;
    /// BringBall.
    pub const BRING_BALL: usize = 2;
    /// RecoverWanderingBall.
    pub const RECOVER: usize = 3;
    /// DefensiveDoubling (functionalities: block 0, cover 1).
    pub const DOUBLING: usize = 4;
    /// Defense.
    pub const DEFENSE: usize = 5;
    /// Support (the default).
    pub const SUPPORT: usize = 6;
    /// How many activities the table has.
    pub const COUNT: usize = 7;
}

/// Team Milan's activity table (module doc).
pub fn table() -> Activities {
    Activities::new(vec![
        Activity::job("Goalie", 1, 1, 6),
        Activity::schema("PassageToMate", &["passer", "receiver"], 5).in_group("ball"),
        Activity::job("BringBall", 1, 1, 4).in_group("ball"),
        Activity::job("RecoverWanderingBall", 1, 2, 4),
        Activity::schema("DefensiveDoubling", &["block", "cover"], 3),
        Activity::job("Defense", 0, 1, 2),
        Activity::job("Support", 0, 16, 0),
    ])
    .with_default("Support")
}

/// What one robot believes, as the soccer activities read it (team frame, m, rad).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Situation {
    /// Its own pose: x, y, heading.
    pub me: (f64, f64, f64),
    /// Whether it keeps goal.
    pub keeper: bool,
    /// The team ball, when known.
    pub ball: Option<(f64, f64)>,
    /// Its teammates heard lately: number, position, and whether it keeps goal.
    pub mates: Vec<(u32, (f64, f64), bool)>,
    /// The opponents (and robots of unknown team) it anchored.
    pub opponents: Vec<(f64, f64)>,
    /// From the centre spot to a goal line.
    pub half_length: f64,
    /// From the middle of a goal to a post.
    pub goal_half_width: f64,
}

/// An opponent this near the ball, ahead of the robot that carries it, blocks its way.
const BLOCKED: f64 = 1.2;
/// A receiver this far ahead of the ball, with no opponent within [`OPEN`], is worth a pass.
const AHEAD: f64 = 1.5;
/// No opponent within this of a receiver.
const OPEN: f64 = 1.5;
/// Attitudes fall to a half at this cost, m.
const HALF_AT: f64 = 3.0;

fn dist(a: (f64, f64), b: (f64, f64)) -> f64 {
    (a.0 - b.0).hypot(a.1 - b.1)
}

/// Near 1 at no cost, ½ at [`HALF_AT`].
fn closeness(cost: f64) -> f64 {
    if cost.is_finite() {
        1.0 / (1.0 + cost.max(0.0) / HALF_AT)
    } else {
        0.0
    }
}

impl Situation {
    fn pos(&self) -> (f64, f64) {
        (self.me.0, self.me.1)
    }

    /// How far a robot at `p` is from being behind the ball, ready to play it towards the
    /// opponent's net: its distance to the ball, plus the way round when it stands ahead of
    /// the ball.
    fn ball_cost(&self, p: (f64, f64), ball: (f64, f64)) -> f64 {
        let ahead = (p.0 - ball.0).max(0.0);
        dist(p, ball) + ahead.min(1.0)
    }

    /// The robot of the team (itself or a mate) nearest the ball by [`ball_cost`], by
    /// number on a tie: who carries the ball.
    fn carrier(&self, me: u32, ball: (f64, f64)) -> (u32, (f64, f64)) {
        self.field_players(me)
            .min_by(|a, b| {
                self.ball_cost(a.1, ball).total_cmp(&self.ball_cost(b.1, ball)).then(a.0.cmp(&b.0))
            })
            .unwrap_or((me, self.pos()))
    }

    /// The team's field players: itself (unless it keeps goal) and its mates that do not.
    fn field_players(&self, me: u32) -> impl Iterator<Item = (u32, (f64, f64))> + '_ {
        let mine = (!self.keeper).then_some((me, self.pos()));
        mine.into_iter().chain(self.mates.iter().filter(|m| !m.2).map(|m| (m.0, m.1)))
    }

    /// The nearest opponent's distance from `p` (infinite with none anchored).
    fn nearest_opponent(&self, p: (f64, f64)) -> f64 {
        self.opponents.iter().map(|o| dist(*o, p)).fold(f64::INFINITY, f64::min)
    }

    /// Whether a robot at `p` is open for a pass of the ball: well ahead of it, no opponent
    /// near.
    fn open_ahead(&self, p: (f64, f64), ball: (f64, f64)) -> bool {
        p.0 > ball.0 + AHEAD && self.nearest_opponent(p) > OPEN
    }

    /// Where Defense stands: on the line from the ball to the middle of the own goal, a third
    /// of the way from the goal, at least 1.5 m out of it.
    pub fn defense_spot(&self, ball: (f64, f64)) -> (f64, f64) {
        let goal = (-self.half_length, 0.0);
        let d = dist(ball, goal);
        let out = (d / 3.0).max(1.5).min(d);
        if d < 1e-3 {
            return (goal.0 + 1.5, 0.0);
        }
        (goal.0 + (ball.0 - goal.0) * out / d, (ball.1 - goal.1) * out / d)
    }

    /// Where DefensiveDoubling's `block` stands: 1 m from the ball towards the own goal.
    pub fn block_spot(&self, ball: (f64, f64)) -> (f64, f64) {
        let goal = (-self.half_length, 0.0);
        let d = dist(ball, goal).max(1e-3);
        let k = (1.0 / d).min(1.0);
        (ball.0 + (goal.0 - ball.0) * k, ball.1 + (goal.1 - ball.1) * k)
    }

    /// Where DefensiveDoubling's `cover` stands: 1.2 m out of the own goal, on the ball's
    /// side of it, within the posts.
    pub fn cover_spot(&self, ball: (f64, f64)) -> (f64, f64) {
        let y = ball.1.clamp(-self.goal_half_width, self.goal_half_width) / 2.0;
        (-self.half_length + 1.2, y)
    }

    /// Where Support stands: 2 m ahead of the ball (at most 2 m short of the opponent's goal
    /// line), 1 m to the side of it towards the middle of the field: ready for a pass or a
    /// loose ball upfield (ahead of the ball rather than behind it: tuned on the pitch against
    /// the Chaser).
    pub fn support_spot(&self, ball: (f64, f64)) -> (f64, f64) {
        let side = if ball.1 > 0.0 { -1.0 } else { 1.0 };
        ((ball.0 + 2.0).min(self.half_length - 2.0), ball.1 + side)
    }

    /// Where a receiver goes: its own position moved forward to 2 m ahead of the ball when
    /// it is not that far ahead, away from the touch lines.
    pub fn receive_spot(&self, ball: (f64, f64)) -> (f64, f64) {
        let (x, y) = self.pos();
        (x.max(ball.0 + 2.0).min(self.half_length - 1.0), y.clamp(-2.5, 2.5))
    }

    /// The opportunity of each activity of [`table`], as robot `me` rates it.
    pub fn opportunity(&self, me: u32) -> Vec<f64> {
        let mut o = vec![0.0; ids::COUNT];
        o[ids::GOALIE] = 1.0;
        o[ids::SUPPORT] = 1.0;
        let Some(ball) = self.ball else {
            o[ids::RECOVER] = 1.0;
            return o;
        };
        o[ids::BRING_BALL] = 1.0;
        o[ids::DEFENSE] = 1.0;
        if ball.0 < -self.half_length / 3.0 {
            o[ids::DOUBLING] = 1.0;
        }
        let (carrier, at) = self.carrier(me, ball);
        let blocked = self
            .opponents
            .iter()
            .any(|op| dist(*op, ball) < BLOCKED && op.0 > ball.0 && op.0 > at.0);
        let open = self.field_players(me).any(|(id, p)| id != carrier && self.open_ahead(p, ball));
        if blocked && open && ball.0 < self.half_length - 2.0 {
            o[ids::PASSAGE] = 1.0;
        }
        o
    }

    /// This robot's attitude for every slot of [`table`] (in slot order: Goalie, passer,
    /// receiver, BringBall, RecoverWanderingBall, block, cover, Defense, Support).
    pub fn attitudes(&self) -> Vec<f64> {
        if self.keeper {
            return vec![1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        }
        let me = self.pos();
        let (bring, receive, block, cover, defense) = match self.ball {
            Some(ball) => (
                closeness(self.ball_cost(me, ball)),
                if self.open_ahead(me, ball) {
                    closeness(dist(me, self.receive_spot(ball)))
                } else {
                    0.0
                },
                closeness(dist(me, self.block_spot(ball))),
                closeness(dist(me, self.cover_spot(ball))),
                closeness(dist(me, self.defense_spot(ball))),
            ),
            None => (0.0, 0.0, 0.0, 0.0, 0.0),
        };
        vec![0.0, bring, receive, bring, 0.5, block, cover, defense, 0.3]
    }
}

/// The sub-tasks of one assignment (for the [`Sequencer`]).
pub fn subtasks(a: Assignment) -> Vec<SubTask> {
    match (a.activity, a.functionality) {
        (ids::BRING_BALL, _) => vec![SubTask::new("ReachBall", 12.0), SubTask::new("Shoot", 3.0)],
        (ids::PASSAGE, 0) => vec![SubTask::new("ReachBall", 8.0), SubTask::new("Pass", 3.0)],
        (ids::PASSAGE, _) => vec![SubTask::new("GetOpen", 8.0), SubTask::new("Receive", 4.0)],
        (ids::RECOVER, _) => vec![SubTask::new("SearchBall", f64::INFINITY)],
        (ids::GOALIE, _) => vec![SubTask::new("KeepGoal", f64::INFINITY)],
        _ => vec![SubTask::new("HoldPosition", f64::INFINITY)],
    }
}

/// What a sub-task asks of Mr. BRIAN's parametric behaviors (the goals SCARE puts in MAP,
/// manual §2.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Goal {
    /// Keep goal.
    Keep,
    /// Look for the ball.
    Search,
    /// Go behind the ball and play it towards `aim` (a point: the net, or a mate).
    PlayBall {
        /// Where the ball should go.
        aim: (f64, f64),
        /// Kick it (true) or only get behind it.
        kick: bool,
    },
    /// Stand at a point, facing the ball.
    Position {
        /// Where.
        at: (f64, f64),
    },
}

impl Situation {
    /// The goal of sub-task `step` of assignment `a` for this robot; `mates` locate the
    /// receiver of a pass (`receiver`: its number). `shot` is where along the opponent's
    /// goal line to shoot (m from its centre).
    pub fn goal(&self, a: Assignment, step: usize, receiver: Option<u32>, shot: f64) -> Goal {
        let Some(ball) = self.ball else {
            return if a.activity == ids::GOALIE { Goal::Keep } else { Goal::Search };
        };
        let net = (self.half_length, shot);
        match (a.activity, a.functionality) {
            (ids::GOALIE, _) => Goal::Keep,
            (ids::RECOVER, _) => Goal::Search,
            (ids::BRING_BALL, _) => Goal::PlayBall { aim: net, kick: step >= 1 },
            (ids::PASSAGE, 0) => {
                let mate = receiver.and_then(|r| self.mates.iter().find(|m| m.0 == r));
                match mate {
                    Some((_, at, _)) => Goal::PlayBall { aim: *at, kick: step >= 1 },
                    None => Goal::PlayBall { aim: net, kick: step >= 1 },
                }
            }
            (ids::PASSAGE, _) => Goal::Position { at: self.receive_spot(ball) },
            (ids::DOUBLING, 0) => Goal::Position { at: self.block_spot(ball) },
            (ids::DOUBLING, _) => Goal::Position { at: self.cover_spot(ball) },
            (ids::DEFENSE, _) => Goal::Position { at: self.defense_spot(ball) },
            _ => Goal::Position { at: self.support_spot(ball) },
        }
    }
}

/// Seconds a robot stays off an activity it failed at, so that the allocation hands it to
/// another robot (the monitor's "re-allocate").
pub const COOL_DOWN: f64 = 2.0;

/// One robot's SCARE, cycle after cycle: its attitudes and opportunities into its report,
/// the allocation from its own report and its teammates', the sequencer and monitor of what
/// it was given, and the goal for its behaviors.
#[derive(Clone, Debug)]
pub struct Coordinator {
    id: u32,
    table: Activities,
    fingerprint: u32,
    params: Params,
    doing: Option<Assignment>,
    sequencer: Option<Sequencer>,
    /// Per activity: until when (s) this robot rates itself 0 for it, after a failure.
    off_until: Vec<f64>,
    /// Teammates' reports that could not be read (another table, wrong lengths).
    ignored: u64,
    /// Activities this robot failed at, and finished.
    failures: u64,
    done: u64,
}

/// What one cycle of a [`Coordinator`] gives: the report for the teammates, the job for
/// the behaviors, and the allocation it came from.
#[derive(Clone, Debug)]
pub struct Cycle {
    /// This robot's report (for its `MateReport`).
    pub report: ScareReport,
    /// What its behaviors pursue.
    pub job: ScareJob,
    /// Everyone's activity, as this robot computed it.
    pub allocation: Allocation,
}

impl Coordinator {
    /// Robot `id`'s coordinator on Team Milan's [`table`].
    pub fn new(id: u32) -> Coordinator {
        let table = table();
        let n = table.list().len();
        Coordinator {
            id,
            fingerprint: table.fingerprint(),
            table,
            params: Params::default(),
            doing: None,
            sequencer: None,
            off_until: vec![f64::NEG_INFINITY; n],
            ignored: 0,
            failures: 0,
            done: 0,
        }
    }

    /// Teammates' reports that could not be read (another activity table, wrong lengths).
    pub fn ignored(&self) -> u64 {
        self.ignored
    }

    /// Activities this robot finished (`done`) and failed at (`failures`, each followed by
    /// [`COOL_DOWN`] off that activity).
    pub fn outcomes(&self) -> (u64, u64) {
        (self.done, self.failures)
    }

    /// One cycle at `now` (s): `sit` is what this robot believes, `heard` the SCARE reports
    /// of the teammates heard lately (a robot that hears nobody allocates for itself alone),
    /// `shot` where along the opponent's goal line to shoot (m from its centre).
    pub fn cycle(
        &mut self,
        now: f64,
        sit: &Situation,
        heard: &[(u32, &ScareReport)],
        shot: f64,
    ) -> Cycle {
        let mut attitudes = sit.attitudes();
        for (a, until) in self.off_until.iter().enumerate() {
            if now < *until {
                for f in 0..self.table.list()[a].functionalities.len() {
                    if let Some(v) = self.table.slot(a, f).and_then(|s| attitudes.get_mut(s)) {
                        *v = 0.0;
                    }
                }
            }
        }
        let opportunity = sit.opportunity(self.id);
        let mut agents = vec![Agent::new(self.id, attitudes.clone()).doing(self.doing)];
        let mut leader = (self.id, opportunity.clone());
        let n = self.table.list().len();
        for (id, r) in heard {
            if *id == self.id
                || r.table != self.fingerprint
                || r.attitudes.len() != self.table.slots()
                || r.opportunity.len() != n
            {
                self.ignored += u64::from(*id != self.id);
                continue;
            }
            let doing =
                r.doing.map(|(a, f)| Assignment { activity: a.into(), functionality: f.into() });
            agents.push(
                Agent::new(*id, r.attitudes.iter().map(|v| f64::from(*v)).collect()).doing(doing),
            );
            if *id < leader.0 {
                leader = (*id, r.opportunity.iter().map(|v| f64::from(*v)).collect());
            }
        }
        let mut allocation = allocate(&self.table, &leader.1, &agents, &self.params);
        // The cool-down hands a failed activity to a teammate; when none takes it (a robot
        // alone, or none able), this robot tries again at once rather than leave it undone.
        let untaken = (0..n).any(|a| {
            self.off_until.get(a).is_some_and(|until| now < *until)
                && allocation.agenda.contains(&a)
                && allocation.doing(a).is_empty()
        });
        if untaken {
            agents[0] = Agent::new(self.id, sit.attitudes()).doing(self.doing);
            allocation = allocate(&self.table, &leader.1, &agents, &self.params);
        }
        let given = allocation.of(self.id);
        if given != self.doing || self.sequencer.is_none() {
            self.doing = given;
            self.sequencer = given.map(|a| Sequencer::new(subtasks(a), now));
        }
        let receiver = allocation
            .assignments
            .iter()
            .find(|(_, a)| *a == Some(Assignment { activity: ids::PASSAGE, functionality: 1 }))
            .map(|(id, _)| *id);
        let job = match (given, self.sequencer.as_mut()) {
            (Some(a), Some(seq)) => {
                let goal = sit.goal(a, seq.step(), receiver, shot);
                let verdict = judge(sit, seq.current().map_or("", |t| t.name.as_str()), goal);
                match seq.tick(now, verdict) {
                    Progress::Done => {
                        self.done += 1;
                        seq.restart(now);
                    }
                    Progress::Failed { .. } => {
                        self.failures += 1;
                        if let Some(until) = self.off_until.get_mut(a.activity) {
                            *until = now + COOL_DOWN;
                        }
                        seq.restart(now);
                    }
                    Progress::Running { .. } | Progress::Advanced { .. } => {}
                }
                let goal = sit.goal(a, seq.step(), receiver, shot);
                job_of(&self.table, a, seq, goal)
            }
            _ => ScareJob::default(),
        };
        let report = ScareReport {
            table: self.fingerprint,
            attitudes: attitudes.iter().map(|v| *v as f32).collect(),
            opportunity: opportunity.iter().map(|v| *v as f32).collect(),
            doing: self.doing.map(|a| (a.activity as u16, a.functionality as u8)),
        };
        Cycle { report, job, allocation }
    }
}

/// The job a robot's behaviors read: names, sub-task and goal.
fn job_of(table: &Activities, a: Assignment, seq: &Sequencer, goal: Goal) -> ScareJob {
    let Some(act) = table.list().get(a.activity) else { return ScareJob::default() };
    let mut job = ScareJob {
        activity: act.name.clone(),
        functionality: act.functionalities.get(a.functionality).cloned().unwrap_or_default(),
        subtask: seq.current().map(|t| t.name.clone()).unwrap_or_default(),
        ..ScareJob::default()
    };
    let point = |(x, y): (f64, f64)| Framed::new(Point2::new(x, y));
    match goal {
        Goal::PlayBall { aim, kick } => {
            job.aim = Some(point(aim));
            job.kick = kick;
        }
        Goal::Position { at } => job.position = Some(point(at)),
        Goal::Keep | Goal::Search => {}
    }
    job
}

/// The monitor's success and failure conditions of Team Milan's sub-tasks.
fn judge(sit: &Situation, subtask: &str, goal: Goal) -> Verdict {
    let me = sit.pos();
    let Some(ball) = sit.ball else {
        // Searching succeeds by finding the ball; everything else needs it.
        return if matches!(subtask, "SearchBall" | "KeepGoal") {
            Verdict::Running
        } else {
            Verdict::Failure
        };
    };
    match (subtask, goal) {
        ("ReachBall", Goal::PlayBall { aim, .. }) => {
            // Within 0.7 m of the ball, on the line from the aim, within 25°.
            let (to_ball, to_aim) =
                ((ball.1 - me.1).atan2(ball.0 - me.0), (aim.1 - ball.1).atan2(aim.0 - ball.0));
            let off = (to_ball - to_aim + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            if dist(me, ball) < 0.7 && off.abs() < 25f64.to_radians() {
                Verdict::Success
            } else {
                Verdict::Running
            }
        }
        // The ball is off: kicked, or lost to someone.
        ("Shoot" | "Pass", _) if dist(me, ball) > 1.2 => Verdict::Success,
        ("GetOpen", Goal::Position { at }) if dist(me, at) < 0.4 => Verdict::Success,
        ("Receive", _) if dist(me, ball) < 0.7 => Verdict::Success,
        _ => Verdict::Running,
    }
}

#[cfg(test)]
mod tests {
    use super::super::{allocate, Agent, Params};
    use super::*;

    fn field() -> Situation {
        Situation { half_length: 9.0, goal_half_width: 1.0, ..Situation::default() }
    }

    /// Four robots, each rating its own attitudes from the same beliefs, allocate: keeper,
    /// the nearest to the ball brings it, the others defend and support.
    #[test]
    fn a_team_of_four_allocates_goalie_bringball_defense_support() {
        let ball = Some((1.0, 0.5));
        let pos = [(-8.5, 0.0), (0.0, 0.0), (-4.0, -1.0), (3.0, 2.0)];
        let sit = |i: usize| {
            let mut s = field();
            s.me = (pos[i].0, pos[i].1, 0.0);
            s.keeper = i == 0;
            s.ball = ball;
            s.mates = (0..4).filter(|j| *j != i).map(|j| (j as u32 + 1, pos[j], j == 0)).collect();
            s
        };
        let t = table();
        assert_eq!(t.slots(), sit(1).attitudes().len());
        assert_eq!(t.list().len(), ids::COUNT);
        assert_eq!(t.find("Support"), Some(ids::SUPPORT));
        let agents: Vec<Agent> =
            (0..4).map(|i| Agent::new(i as u32 + 1, sit(i).attitudes())).collect();
        let a = allocate(&t, &sit(0).opportunity(1), &agents, &Params::default());
        assert_eq!(
            a.names(&t),
            vec![(1, "Goalie"), (2, "BringBall"), (3, "Defense"), (4, "Support")]
        );
        // Robot 2 is on the ball's own side: its goal is to play it to the net and, in its
        // second sub-task, to kick.
        let g = sit(1).goal(a.of(2).unwrap(), 1, None, 0.0);
        assert_eq!(g, Goal::PlayBall { aim: (9.0, 0.0), kick: true });
        // Defense stands on the ball–goal line, a third of the way out.
        let Goal::Position { at } = sit(2).goal(a.of(3).unwrap(), 0, None, 0.0) else { panic!() };
        let (bx, by): (f64, f64) = (1.0 + 9.0, 0.5);
        let k = (bx.hypot(by) / 3.0) / bx.hypot(by);
        assert!((at.0 - (-9.0 + bx * k)).abs() < 1e-6 && (at.1 - by * k).abs() < 1e-6, "{at:?}");
    }

    #[test]
    fn a_blocked_carrier_with_an_open_mate_makes_a_passage() {
        let mut s = field();
        s.me = (-1.5, 0.0, 0.0);
        s.ball = Some((-1.0, 0.0));
        s.mates = vec![(3, (2.0, 2.0), false)];
        s.opponents = vec![(-0.2, 0.0), (4.0, -2.5)];
        let o = s.opportunity(2);
        assert_eq!(o[ids::PASSAGE], 1.0, "{o:?}");
        // Robot 3 rates itself as receiver (open, ahead); robot 2 as passer.
        let mut r = s.clone();
        r.me = (2.0, 2.0, 0.0);
        r.mates = vec![(2, (-1.5, 0.0), false)];
        let agents = [Agent::new(2, s.attitudes()), Agent::new(3, r.attitudes())];
        let t = table();
        let a = allocate(&t, &o, &agents, &Params::default());
        assert_eq!(a.of(2), Some(Assignment { activity: ids::PASSAGE, functionality: 0 }));
        assert_eq!(a.of(3), Some(Assignment { activity: ids::PASSAGE, functionality: 1 }));
        // The passer aims at its receiver.
        let g = s.goal(a.of(2).unwrap(), 0, Some(3), 0.0);
        assert_eq!(g, Goal::PlayBall { aim: (2.0, 2.0), kick: false });
        // Without the blocking opponent there is no passage: robot 2 brings the ball.
        s.opponents.remove(0);
        assert_eq!(s.opportunity(2)[ids::PASSAGE], 0.0);
    }

    #[test]
    fn no_ball_means_search_and_the_own_third_means_doubling() {
        let mut s = field();
        let o = s.opportunity(1);
        assert_eq!((o[ids::RECOVER], o[ids::BRING_BALL]), (1.0, 0.0));
        assert_eq!(
            s.goal(Assignment { activity: ids::SUPPORT, functionality: 0 }, 0, None, 0.0),
            Goal::Search
        );
        s.ball = Some((-6.0, 1.0));
        assert_eq!(s.opportunity(1)[ids::DOUBLING], 1.0);
        // The block stands 1 m from the ball towards the own goal.
        let b = s.block_spot((-6.0, 1.0));
        assert!((dist(b, (-6.0, 1.0)) - 1.0).abs() < 1e-6);
        assert!(b.0 < -6.0);
    }
}
