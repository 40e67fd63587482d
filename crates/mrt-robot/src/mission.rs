//! A robot that follows a list of path points through a building: the manual's Roby and
//! FollowMe applications (MRT manual §2.3), the indoor world's robot program
//! (`mrt sim --world indoor`, docs/indoor.md).
//!
//! The mission ([`Mission`], a TOML file) is a start pose and path points. Each point is one
//! *ReachPathPoint* job with a time limit, run by SCARE's sequencer
//! ([`mrt_team::scare::sequencer`]): reaching the point within its tolerance is the job's
//! success, its time limit passing is a failure. [`Roby`] does each cycle what the manual's
//! Members did:
//!
//! 1. **Where am I**: dead reckoning on the two mice (MRT manual ch. 4, with the §4.2
//!    reduction; the wheels when the mice cannot be trusted) from the start pose, corrected
//!    twice a second by the sonars: the pose near the dead-reckoned one (±0.18 m, ±0.09 rad)
//!    whose echoes lie nearest the map's walls, jambs and furniture, each echo anywhere across
//!    its beam (a likelihood field on the map's clearance). MUREA (ch. 7) is not used here:
//!    its evidence for a point is a disc inside the tolerance sector, and a sonar's echo is
//!    an arc as wide as its beam. The robot is told nothing but its start.
//! 2. **What is in the way**: every sonar echo within [`ECHO_RANGE`] that the map does not
//!    explain (farther than [`EXPLAINED`] from every wall, door jamb and piece of furniture)
//!    marks a cell of [`ECHO_CELL`] as occupied: a closed door, a person. A cell that a
//!    sonar later sees through is free again (a person walked on); one not seen for
//!    [`ECHO_MEMORY`] is forgotten.
//! 3. **How do I get there**: SPIKE (ch. 9) plans on the building's map with the occupied
//!    cells as moving obstacles. It plans again when a cell comes nearer the path than the
//!    robot's clearance, and when a job times out (the manual's Roby: "a ReachPathPoint that
//!    times out is aborted and the planner is asked for a new path"). A job that times out
//!    [`ATTEMPTS`] times is given up and the mission goes on with the next point.
//! 4. **Go**: guidance's position mode towards a pose [`LOOKAHEAD`] ahead on the path, its
//!    velocity mode's sonar guard halting the robot when something is right in front.
//!
//! Metres, radians, seconds; the building's frame.
//!
//! ```
//! use mrt_robot::mission::{Mission, Roby, RobyBody};
//! use mrt_plan::spike::PlanMap;
//!
//! let map = PlanMap::from_toml("[area]\nmin = [0, 0]\nmax = [6, 4]\n", "room.toml")?;
//! let mission = Mission::from_toml(
//!     "start = [1.0, 1.0, 0.0]\n[[point]]\nat = [5.0, 3.0]\ntimeout_s = 20.0\n",
//!     "mission.toml",
//! )?;
//! let mice = mrt_perception::mice::MiceOdometry::new(0.2, 0.003)?;
//! let roby = Roby::new(map, mission, RobyBody::new(mice))?;
//! assert_eq!(roby.pose().x, 1.0);
//! assert!(!roby.finished());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::base::Base;
use crate::devices::SharedDevices;
use crate::error::RobotError;
use crate::members::{Driver, Motor};
use crate::planner::carrot_at;
use mrt_core::{FileError, Point2, Pose2};
use mrt_dcdt::{Activation, Agora, Context, Inputs, Member, MemberError, RequestType};
use mrt_msgs::{MotorCommand, Odometry, SonarScan};
use mrt_perception::mice::{update_pose, MiceOdometry};
use mrt_plan::guidance::{PositionMode, PositionParams, Sonar, VelocityGuard};
use mrt_plan::kinematics::Twist;
use mrt_plan::spike::{Plan, PlanMap, Shape, Spike, SpikeParams};
use mrt_plan::PlanError;
use mrt_team::scare::sequencer::{Progress, Sequencer, SubTask, Verdict};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Sonar echoes farther than this are not marked, m from the robot's centre.
pub const ECHO_RANGE: f64 = 2.0;
/// An echo this near a known obstacle of the map is the map's, m.
pub const EXPLAINED: f64 = 0.25;
/// The side of an occupied cell, m; each is a disc of half its diagonal for SPIKE.
pub const ECHO_CELL: f64 = 0.2;
/// An occupied cell not seen again for this long is forgotten, s.
pub const ECHO_MEMORY: f64 = 60.0;
/// The most occupied cells kept (the oldest go first).
pub const MAX_ECHOES: usize = 400;
/// The sonars are matched to the map this often, s.
pub const FIX_PERIOD: f64 = 0.5;
/// Sonar echoes farther than this are not used for a fix, m.
pub const SONAR_FIX_RANGE: f64 = 2.5;
/// A fix needs this many echoes at least...
pub const FIX_ECHOES: usize = 6;
/// ... and must put this fraction of them on the map (a closed door or a person is not on it).
pub const FIX_QUALITY: f64 = 0.6;
/// ... and cost at most this fraction of the dead-reckoned pose's cost.
pub const FIX_GAIN: f64 = 0.7;
/// An echo's distance to the map counts at most this much, m (an echo off the map is one
/// outlier, not a pull).
pub const FIT_CAP: f64 = 0.15;
/// Guidance drives towards the path's pose this far ahead of the robot, m.
pub const LOOKAHEAD: f64 = 0.35;
/// Times one path point is tried (each with a new plan) before it is given up.
pub const ATTEMPTS: u32 = 3;
/// A path point farther than this may not be given, m.
const MAX_COORD: f64 = 1.0e4;

/// One path point: a ReachPathPoint job.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathPoint {
    /// Where, m.
    pub at: Point2,
    /// How long reaching it may take, s.
    pub timeout: f64,
}

/// A mission file (module doc; `configs/worlds/indoor/mission.toml`).
#[derive(Clone, Debug, PartialEq)]
pub struct Mission {
    /// Where the robot starts.
    pub start: Pose2,
    /// A point is reached within this distance, m.
    pub tolerance: f64,
    /// The points, in order.
    pub points: Vec<PathPoint>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MissionFile {
    start: [f64; 3],
    #[serde(default = "default_tolerance")]
    tolerance: f64,
    #[serde(default)]
    point: Vec<PointFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointFile {
    at: [f64; 2],
    timeout_s: f64,
}

fn default_tolerance() -> f64 {
    0.25
}

impl Mission {
    /// Reads a mission from the TOML `text` of `file` (the name errors give).
    ///
    /// # Errors
    /// [`FileError::Parse`] (with line and column) for malformed TOML or an unknown key;
    /// [`FileError::Invalid`] for no point, a number that is not finite or beyond 10 km, a
    /// tolerance or time limit that is not positive.
    pub fn from_toml(text: &str, file: &str) -> Result<Mission, FileError> {
        let parsed: MissionFile = toml::from_str(text)
            .map_err(|e| FileError::parse(file, text, e.span().map(|s| s.start), e.message()))?;
        let invalid = |message: String| FileError::Invalid { file: file.to_string(), message };
        let near = |v: f64| v.is_finite() && v.abs() <= MAX_COORD;
        if !parsed.start.iter().all(|&v| near(v)) {
            return Err(invalid("start: a number is not finite or beyond 10 km".into()));
        }
        if !(parsed.tolerance.is_finite() && parsed.tolerance > 0.0) {
            return Err(invalid(format!("tolerance {} must be > 0", parsed.tolerance)));
        }
        if parsed.point.is_empty() {
            return Err(invalid("no [[point]]: a mission needs one at least".into()));
        }
        let mut points = Vec::with_capacity(parsed.point.len());
        for (k, p) in parsed.point.into_iter().enumerate() {
            if !p.at.iter().all(|&v| near(v)) {
                return Err(invalid(format!("point {}: not finite or beyond 10 km", k + 1)));
            }
            if !(p.timeout_s.is_finite() && p.timeout_s > 0.0) {
                return Err(invalid(format!("point {}: timeout_s must be > 0", k + 1)));
            }
            points.push(PathPoint { at: Point2::new(p.at[0], p.at[1]), timeout: p.timeout_s });
        }
        let [x, y, heading] = parsed.start;
        Ok(Mission {
            start: Pose2::new(x, y, heading.to_radians()),
            tolerance: parsed.tolerance,
            points,
        })
    }

    /// Reads a mission file ([`Mission::from_toml`]).
    ///
    /// # Errors
    /// [`FileError::Io`] when it cannot be read, else as [`Mission::from_toml`].
    pub fn from_file(path: impl AsRef<std::path::Path>) -> Result<Mission, FileError> {
        let (text, file) = FileError::read(path.as_ref())?;
        Mission::from_toml(&text, &file)
    }
}

/// The robot Roby drives: its size, its mice, its guidance.
#[derive(Clone, Copy, Debug)]
pub struct RobyBody {
    /// Its radius, m.
    pub radius: f64,
    /// How far it keeps from obstacles besides, m.
    pub safety: f64,
    /// Its two mice.
    pub mice: MiceOdometry,
    /// Position mode's parameters (top speed, steering...).
    pub position: PositionParams,
    /// The sonar guard.
    pub guard: VelocityGuard,
    /// Half the width of a sonar's beam, rad: an echo comes from anywhere across it.
    pub half_beam: f64,
}

impl RobyBody {
    /// An MRT robot with `mice`: 0.25 m, 0.1 m safety, holonomic at up to 0.8 m/s, beams
    /// 0.4 rad wide, the sonar guard halting it when something is within 0.35 m of its
    /// centre (10 cm of its edge) within ±20° of where it goes: indoors the planner keeps it
    /// off the walls, and a door's jambs pass closer than the soccer robots' 0.5 m.
    pub fn new(mice: MiceOdometry) -> RobyBody {
        let guard = VelocityGuard::new(0.35, 0.35).unwrap_or_default();
        RobyBody {
            radius: 0.25,
            safety: 0.1,
            mice,
            position: PositionParams { max_speed: 0.8, ..PositionParams::default() },
            guard,
            half_beam: 0.2,
        }
    }
}

/// What happened during the mission, for the report and the plot.
#[derive(Clone, Debug, PartialEq)]
pub enum MissionEvent {
    /// A path to point `point` was planned, `length` m long; `why`: the first plan of the
    /// job, the way blocked, or a time-out.
    Planned {
        /// When, s.
        time: f64,
        /// The point's index.
        point: usize,
        /// The path's length, m.
        length: f64,
        /// Why it was planned.
        why: Replan,
    },
    /// No way to point `point` was found (tried again the next cycle).
    NoPath {
        /// When, s.
        time: f64,
        /// The point's index.
        point: usize,
    },
    /// Point `point` was reached.
    Reached {
        /// When, s.
        time: f64,
        /// The point's index.
        point: usize,
    },
    /// Point `point` was given up after [`ATTEMPTS`] time-outs.
    GaveUp {
        /// When, s.
        time: f64,
        /// The point's index.
        point: usize,
    },
}

/// Why a path was planned.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Replan {
    /// The job's first plan.
    New,
    /// Occupied cells came too near the path (a closed door, a person).
    Blocked,
    /// The job's time limit passed.
    Timeout,
}

/// The mission's robot program (module doc).
#[derive(Debug)]
pub struct Roby {
    spike: Spike,
    /// When the sonars were last matched to the map, s.
    last_fix: f64,
    /// Corrections the sonars gave.
    fixes: u64,
    mission: Mission,
    body: RobyBody,
    position: PositionMode,
    sequencer: Sequencer,
    /// The index of the sequencer's first job among the mission's points.
    offset: usize,
    pose: Pose2,
    plan: Option<Plan>,
    /// Occupied cells (by their integer coordinates) and when each was last heard.
    echoes: BTreeMap<(i64, i64), f64>,
    attempts: u32,
    /// The next plan's reason, when one is due.
    due: Option<Replan>,
    events: Vec<MissionEvent>,
    finished: bool,
}

impl Roby {
    /// The program for `mission` in the building `map`, on `body`, started at time 0.
    ///
    /// # Errors
    /// [`PlanError::InvalidParameter`] for a body SPIKE or guidance refuses.
    pub fn new(map: PlanMap, mission: Mission, body: RobyBody) -> Result<Roby, PlanError> {
        let params = SpikeParams {
            robot_radius: body.radius,
            safety: body.safety,
            accuracy: 0.02,
            resolution: 0.25,
        };
        let spike = Spike::new(map, params)?;
        let position = PositionMode::new(body.position)?;
        let jobs = jobs(&mission.points, 0);
        Ok(Roby {
            spike,
            last_fix: f64::NEG_INFINITY,
            fixes: 0,
            pose: mission.start,
            mission,
            body,
            position,
            sequencer: Sequencer::new(jobs, 0.0),
            offset: 0,
            plan: None,
            echoes: BTreeMap::new(),
            attempts: 0,
            due: Some(Replan::New),
            events: Vec::new(),
            finished: false,
        })
    }

    /// Where the robot believes it is.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// Whether every point was reached or given up.
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// The index of the point it is heading for (`None` when finished).
    pub fn point(&self) -> Option<usize> {
        (!self.finished).then(|| self.offset + self.sequencer.step())
    }

    /// What happened so far.
    pub fn events(&self) -> &[MissionEvent] {
        &self.events
    }

    /// The path it follows.
    pub fn path(&self) -> Option<&Plan> {
        self.plan.as_ref()
    }

    /// The centres of the occupied cells it believes in.
    pub fn occupied(&self) -> Vec<Point2> {
        self.echoes.keys().map(|&k| cell_centre(k)).collect()
    }

    /// The mission.
    pub fn mission(&self) -> &Mission {
        &self.mission
    }

    /// One cycle at time `now` (s): this cycle's odometry and sonar ring in, the velocity to
    /// drive at out (robot frame; zero once finished).
    pub fn step(&mut self, now: f64, odometry: &Odometry, sonars: &[Sonar]) -> Twist {
        let d = self.body.mice.motion(&odometry.mice).map_or(odometry.wheels, |(d, _)| d);
        if d.dx.is_finite() && d.dy.is_finite() && d.dtheta.is_finite() {
            self.pose = update_pose(&self.pose, &d);
        }
        self.localize(now, sonars);
        self.hear(now, sonars);
        if self.finished {
            return Twist::ZERO;
        }
        let k = self.offset + self.sequencer.step();
        let Some(goal) = self.mission.points.get(k).map(|p| p.at) else {
            self.finished = true;
            return Twist::ZERO;
        };
        let reached =
            self.pose.position().coords.metric_distance(&goal.coords) <= self.mission.tolerance;
        let verdict = if reached { Verdict::Success } else { Verdict::Running };
        match self.sequencer.tick(now, verdict) {
            Progress::Done => {
                self.events.push(MissionEvent::Reached { time: now, point: k });
                self.finished = true;
                return Twist::ZERO;
            }
            Progress::Advanced { .. } => {
                self.events.push(MissionEvent::Reached { time: now, point: k });
                self.next_job();
                return Twist::ZERO;
            }
            Progress::Failed { .. } => {
                self.attempts += 1;
                if self.attempts >= ATTEMPTS {
                    self.events.push(MissionEvent::GaveUp { time: now, point: k });
                    self.skip(now);
                    return Twist::ZERO;
                }
                // The job again, with a new plan (the sequencer's own restart would go back
                // to its first job).
                self.offset = k;
                self.sequencer = Sequencer::new(jobs(&self.mission.points, k), now);
                self.due = Some(Replan::Timeout);
            }
            Progress::Running { .. } => {}
        }
        self.follow(now, k, goal, sonars)
    }

    /// Plans when due or blocked, then drives along the path.
    fn follow(&mut self, now: f64, k: usize, goal: Point2, sonars: &[Sonar]) -> Twist {
        let occupied = self.obstacles();
        let clearance = self.spike.clearance();
        if self.due.is_none()
            && self.plan.as_ref().is_some_and(|p| p.is_blocked_by(&occupied, clearance))
        {
            self.due = Some(Replan::Blocked);
        }
        if let Some(why) = self.due {
            match self.spike.plan_among(self.pose.position(), goal, &occupied) {
                Ok(plan) => {
                    self.events.push(MissionEvent::Planned {
                        time: now,
                        point: k,
                        length: plan.length,
                        why,
                    });
                    self.plan = Some(plan);
                    self.due = None;
                }
                Err(_) => {
                    let again = matches!(self.events.last(), Some(MissionEvent::NoPath { point, .. }) if *point == k);
                    if !again {
                        self.events.push(MissionEvent::NoPath { time: now, point: k });
                    }
                    // Shut in by what it heard: keep only this second's echoes (a person
                    // who walked on, a misplaced echo, go; a closed door in view stays).
                    self.echoes.retain(|_, &mut seen| now - seen < 1.0);
                    self.plan = None;
                    return Twist::ZERO;
                }
            }
        }
        let ahead = |p: &Plan| carrot_at(&p.poses, self.pose, LOOKAHEAD);
        let Some(carrot) = self.plan.as_ref().and_then(ahead) else {
            return Twist::ZERO;
        };
        let heading = (carrot.y - self.pose.y).atan2(carrot.x - self.pose.x);
        let target = Pose2::new(carrot.x, carrot.y, heading);
        let twist = self.position.command(&self.pose, &target).twist;
        self.body.guard.apply(&twist, sonars).twist
    }

    /// The next job: a new plan, a new count of attempts.
    fn next_job(&mut self) {
        self.attempts = 0;
        self.plan = None;
        self.due = Some(Replan::New);
    }

    /// Gives the current point up and goes on with the next one (or ends the mission).
    fn skip(&mut self, now: f64) {
        self.offset += self.sequencer.step() + 1;
        if self.offset >= self.mission.points.len() {
            self.finished = true;
            return;
        }
        self.sequencer = Sequencer::new(jobs(&self.mission.points, self.offset), now);
        self.next_job();
    }

    /// The occupied cells as SPIKE's moving obstacles.
    fn obstacles(&self) -> Vec<Shape> {
        let radius = ECHO_CELL * std::f64::consts::FRAC_1_SQRT_2;
        self.echoes.keys().map(|&k| Shape::Disc { centre: cell_centre(k), radius }).collect()
    }

    /// Matches the sonar echoes to the map every [`FIX_PERIOD`] (module doc, 1.): the pose
    /// round the dead-reckoned one whose echoes lie nearest the walls, jambs and furniture.
    fn localize(&mut self, now: f64, sonars: &[Sonar]) {
        if now - self.last_fix < FIX_PERIOD {
            return;
        }
        self.last_fix = now;
        let echoes: Vec<(f64, f64)> = sonars
            .iter()
            .filter(|s| s.range.is_finite() && s.range <= SONAR_FIX_RANGE && s.bearing.is_finite())
            .map(|s| (s.range, s.bearing))
            .collect();
        if echoes.len() < FIX_ECHOES {
            return;
        }
        let start = self.pose;
        // The echoes' misfit (σ 5 cm each), plus how far the pose moved from the dead
        // reckoning (σ 10 cm, 0.05 rad): a maximum a posteriori pose, so that a few echoes
        // cannot pull it where the odometry says it is not.
        let total = |f: &Fit, at: Pose2| {
            let (dx, dy) = (at.x - start.x, at.y - start.y);
            let dt = mrt_core::normalize_angle(at.theta - start.theta);
            f.cost / (0.05 * 0.05) + (dx * dx + dy * dy) / (0.1 * 0.1) + dt * dt / (0.05 * 0.05)
        };
        let here = self.fit(start, &echoes);
        let mut best = (here, start, total(&here, start));
        // Coarse, then fine round the best.
        for (step, turn, n) in [(0.05, 0.025, 3i32), (0.02, 0.01, 1), (0.01, 0.005, 1)] {
            let centre = best.1;
            for (i, j, k) in grid(n) {
                let at = Pose2::new(
                    centre.x + step * f64::from(i),
                    centre.y + step * f64::from(j),
                    centre.theta + turn * f64::from(k),
                );
                let f = self.fit(at, &echoes);
                let t = total(&f, at);
                if t < best.2 {
                    best = (f, at, t);
                }
            }
        }
        let (fit, at, _) = best;
        let n = echoes.len() as f64;
        if fit.explained as f64 >= FIX_QUALITY * n && fit.cost < FIX_GAIN * here.cost {
            self.pose = at;
            self.fixes += 1;
        }
    }

    /// How well the `echoes` (range, bearing) fit the map from `pose`: each is nearest the
    /// map somewhere across its beam ([`RobyBody::half_beam`]).
    fn fit(&self, pose: Pose2, echoes: &[(f64, f64)]) -> Fit {
        let map = self.spike.map();
        let hb = self.body.half_beam;
        let mut fit = Fit { cost: 0.0, explained: 0 };
        for &(r, b) in echoes {
            let off = (-2..=2)
                .map(|i| {
                    let a = pose.theta + b + 0.5 * hb * f64::from(i);
                    map.clearance(Point2::new(pose.x + r * a.cos(), pose.y + r * a.sin())).abs()
                })
                .fold(f64::INFINITY, f64::min);
            if off <= 0.05 + 0.02 * r {
                fit.explained += 1;
            }
            fit.cost += off.min(FIT_CAP).powi(2);
        }
        fit
    }

    /// How often the sonars corrected the dead reckoning.
    pub fn fixes(&self) -> u64 {
        self.fixes
    }

    /// Marks the cells of the echoes the map does not explain, frees those a sonar sees
    /// through, forgets old ones.
    fn hear(&mut self, now: f64, sonars: &[Sonar]) {
        let pose = self.pose;
        for s in sonars {
            let range = if s.range.is_finite() { s.range } else { ECHO_RANGE + ECHO_CELL };
            let bearing = pose.theta + s.bearing;
            // Free: the cells this beam saw through, short of its echo (the echo is the
            // nearest thing across the whole beam; the beam's edges are left out, a cell
            // there may lie half outside it).
            let half = 0.75 * self.body.half_beam;
            self.echoes.retain(|&k, _| {
                let c = cell_centre(k);
                let (dx, dy) = (c.x - pose.x, c.y - pose.y);
                let off = mrt_core::normalize_angle(dy.atan2(dx) - bearing).abs();
                !(off < half && dx.hypot(dy) < range.min(ECHO_RANGE) - ECHO_CELL)
            });
            if !(s.range.is_finite() && s.range <= ECHO_RANGE) {
                continue;
            }
            // The echo comes from somewhere across the beam: the map explains it when some
            // point of the arc at its range lies near a wall, a jamb or furniture.
            let on_arc =
                |a: f64| Point2::new(pose.x + s.range * a.cos(), pose.y + s.range * a.sin());
            let map = self.spike.map();
            let explained = (-2..=2)
                .map(|i| bearing + f64::from(i) * 0.5 * self.body.half_beam)
                .any(|a| map.clearance(on_arc(a)) <= EXPLAINED);
            if !explained {
                let at = on_arc(bearing);
                let key = ((at.x / ECHO_CELL).floor() as i64, (at.y / ECHO_CELL).floor() as i64);
                self.echoes.insert(key, now);
            }
        }
        self.echoes.retain(|_, &mut seen| now - seen <= ECHO_MEMORY);
        while self.echoes.len() > MAX_ECHOES {
            let oldest = self.echoes.iter().min_by(|a, b| a.1.total_cmp(b.1)).map(|(&k, _)| k);
            match oldest {
                Some(k) => self.echoes.remove(&k),
                None => break,
            };
        }
    }
}

/// The indoor robot's program on the bus: Roby as a Member (`roby-<robot>`) between the
/// robot's drivers, the same [`Devices`](crate::devices::Devices) interface the soccer robots
/// use. Each cycle it takes the cycle's [`Odometry`] and [`SonarScan`] and publishes the
/// velocity as a [`MotorCommand`] (the behaviors' units: mm/s and deg/s).
pub struct RobyMember {
    robot: usize,
    roby: Arc<Mutex<Roby>>,
    /// This cycle's odometry and sonar scan, as they come.
    odometry: Option<Odometry>,
    scan: Option<SonarScan>,
    inputs: Inputs<RobyMember>,
}

impl RobyMember {
    /// The Member of robot `robot`, sharing `roby` with whoever watches it (a monitor, the
    /// simulator's report).
    pub fn new(robot: usize, roby: Arc<Mutex<Roby>>) -> RobyMember {
        let inputs = Inputs::<Self>::new()
            .on::<Odometry>(RequestType::Local, |r, o| r.odometry = Some(*o))
            .on::<SonarScan>(RequestType::Local, |r, s| r.scan = Some(s.clone()));
        RobyMember { robot, roby, odometry: None, scan: None, inputs }
    }
}

impl Member for RobyMember {
    fn name(&self) -> String {
        format!("roby-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.subscribe(ctx);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inputs.clone().drain(self, ctx)?;
        let (Some(odometry), Some(scan)) = (self.odometry.take(), self.scan.take()) else {
            return Ok(());
        };
        let now = ctx.now().as_secs_f64();
        let twist = self
            .roby
            .lock()
            .map_err(|_| MemberError::from("Roby's lock is poisoned"))?
            .step(now, &odometry, &scan.sonars);
        ctx.publish(MotorCommand { twist, kick: false });
        Ok(())
    }
}

/// Puts robot `robot`'s indoor program into `agora`: the odometry and sonar drivers of
/// `devices`, [`RobyMember`] on `roby`, and the motor driver for `base`, every `period`.
pub fn add_roby(
    agora: &mut Agora,
    (robot, period, base): (usize, Duration, Base),
    roby: Arc<Mutex<Roby>>,
    devices: SharedDevices,
) -> Result<(), RobotError> {
    let every = Activation::Periodic(period);
    let odometry: Driver<Odometry> =
        Driver { kind: "odometry", robot, devices: devices.clone(), read: |d| d.odometry() };
    let sonars: Driver<SonarScan> = Driver {
        kind: "sonars",
        robot,
        devices: devices.clone(),
        read: |d| d.sonars().map(|sonars| SonarScan { sonars }),
    };
    let ids = [
        agora.add_member(odometry, every),
        agora.add_member(sonars, every),
        agora.add_member(RobyMember::new(robot, roby), every),
        agora.add_member(Motor::new(devices, robot, base), Activation::OnMessage),
    ];
    for m in ids {
        agora.activate_member(m)?;
    }
    Ok(())
}

/// How well echoes fit the map ([`Roby::fit`]).
#[derive(Clone, Copy, Debug)]
struct Fit {
    /// The sum of each echo's squared distance to the map, capped at [`FIT_CAP`], m².
    cost: f64,
    /// Echoes within their tolerance of the map.
    explained: usize,
}

/// `(i, j, k)` for each of `i`, `j` and `k` from `-n` to `n`, the θ step `k` half as wide.
fn grid(n: i32) -> impl Iterator<Item = (i32, i32, i32)> {
    (-n..=n).flat_map(move |i| (-n..=n).flat_map(move |j| (-n..=n).map(move |k| (i, j, k))))
}

/// The centre of occupied cell `k`.
fn cell_centre((i, j): (i64, i64)) -> Point2 {
    Point2::new((i as f64 + 0.5) * ECHO_CELL, (j as f64 + 0.5) * ECHO_CELL)
}

/// The ReachPathPoint jobs of `points` from index `from` on.
fn jobs(points: &[PathPoint], from: usize) -> Vec<SubTask> {
    let named =
        |(k, p): (usize, &PathPoint)| SubTask::new(&format!("ReachPathPoint{k}"), p.timeout);
    points.iter().enumerate().skip(from).map(named).collect()
}
