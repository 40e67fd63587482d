//! The physical side of a match ([`Pitch`]): the world, the referee, the robots' sensors with
//! their random streams, and the book (statistics, trajectory hash, calls, frames, faults;
//! what the robots believed against the truth in `book.rs`), stepped in lockstep on simulated
//! time so that the same seed gives the same match.
//!
//! Every control period (100 ms by default) each robot's program runs on its devices (the
//! wirings `bus` and `remote` build on this); then the physics runs until the next control
//! period, with the referee watching every step.

use crate::config::{PerceptSource, SimConfig};
use crate::error::SimError;
use crate::referee::{Call, Referee, Team};
use crate::render::{CameraState, Renderer, Scene};
use crate::sensor::{self, sonar_ring, Odometer};
use crate::world::World;
use mrt_core::frames::millimetres;
use mrt_core::Pose2;
use mrt_core::Twist;
use mrt_msgs::robot::GameState;
use mrt_msgs::MotorCommand;
use mrt_msgs::Sonar;
use mrt_msgs::{CameraFrame, GameInfo, Odometry};
use mrt_perception::camera::CameraModel;
use mrt_robot::base::Base;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

mod book;
mod report;
pub use report::{
    BeliefSample, Frame, Kidnap, LocalizationErrors, MatchReport, RobotErrors, RobotFault,
    TeamStats, FALSELY_RELOCALIZED, KIDNAP_GAP, PHANTOM, RECOVERED,
};

/// The robots' cameras when they see through rendered images: the front camera's renderer,
/// the up camera's when the robots carry one, and each camera's state (its noise stream and
/// last frame).
#[derive(Debug)]
struct Eyes {
    front: Renderer,
    up: Option<Renderer>,
    states: Vec<CameraState>,
    up_states: Vec<CameraState>,
}

impl Eyes {
    fn new(cfg: &SimConfig, robots: usize, seed: u64) -> Result<Eyes, SimError> {
        let stream = |i: u64, salt: u64| {
            CameraState::new(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ i ^ salt)
        };
        let up = match &cfg.vision.up_camera {
            Some(f) => {
                let omni =
                    f.camera().map_err(|e| SimError::Config(format!("vision.up_camera: {e}")))?;
                Some(Renderer::with_camera(cfg, CameraModel::Omni(omni))?)
            }
            None => None,
        };
        let up_states = match up {
            Some(_) => (0..robots as u64).map(|i| stream(i, 0x7570_0000)).collect(),
            None => Vec::new(),
        };
        Ok(Eyes {
            front: Renderer::new(cfg)?,
            up,
            states: (0..robots as u64).map(|i| stream(i, 0)).collect(),
            up_states,
        })
    }
}

/// The physical side of a match, whatever drives the robots: the world, the referee, the
/// robots' eyes with their random streams, and the book (statistics, hash, calls, frames).
pub struct Pitch {
    cfg: SimConfig,
    base: Base,
    seed: u64,
    world: World,
    referee: Referee,
    odometers: Vec<Odometer>,
    rngs: Vec<ChaCha8Rng>,
    stats: [TeamStats; 2],
    hash: u64,
    calls: Vec<(f64, Call)>,
    shots: Vec<(f64, usize, (f64, f64))>,
    frames: Vec<Frame>,
    beliefs: Vec<BeliefSample>,
    record: bool,
    faults: Vec<RobotFault>,
    localization: LocalizationErrors,
    /// Kicks asked this cycle, fired when the physics runs.
    kicks: Vec<usize>,
    /// The simulated time at which each robot last believed it held the ball booking, and
    /// last was the attacker.
    booked_at: Vec<f64>,
    attacker_at: Vec<f64>,
    /// The same for a SCARE job that plays the ball.
    ball_job_at: Vec<f64>,
    /// The cameras' renderer and each robot's camera state, when percepts come from vision.
    eyes: Option<Eyes>,
    /// Each robot's camera pan joint, rad (the camera file's pan until a robot turns it).
    pans: Vec<f64>,
    /// Kidnaps still to come: `(simulated time, robot)`, latest first; and their random
    /// stream.
    kidnap_plan: Vec<(f64, usize)>,
    kidnap_rng: ChaCha8Rng,
    kidnaps: Vec<Kidnap>,
}

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

fn fnv(hash: u64, value: i64) -> u64 {
    value.to_le_bytes().iter().fold(hash, |h, b| (h ^ u64::from(*b)).wrapping_mul(FNV_PRIME))
}

/// Millimetres, for hashing.
fn mm(x: f64) -> i64 {
    millimetres(x).round() as i64
}

impl Pitch {
    /// A pitch with `home` and `away` robots (`away` is `cfg.rules.team_size` or 0: home alone
    /// on the field), kickoff done, all randomness drawn from `seed`.
    pub fn new(cfg: &SimConfig, seed: u64, home: usize, away: usize) -> Result<Pitch, SimError> {
        let n = cfg.rules.team_size;
        if home != n || (away != n && away != 0) {
            return Err(SimError::Match(format!(
                "each team needs {n} robots (home has {home}, away {away}; an empty away team \
                 plays alone on the field)"
            )));
        }
        cfg.validate()?;
        let robots = home + away;
        let mut world = World::new(cfg, robots);
        let mut referee = Referee::new(n);
        referee.start(&mut world);
        let rngs = (0..robots as u64)
            .map(|i| {
                ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15).wrapping_add(i))
            })
            .collect();
        // The robots' own mice and base, as their robot file describes them.
        let robot = cfg.robot()?;
        let (mice, base) = (robot.mice, robot.base);
        let mut kidnap_rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6B69_646E_6170_0001);
        let kidnap_plan = Self::plan_kidnaps(cfg, robots, &mut kidnap_rng);
        Ok(Pitch {
            cfg: cfg.clone(),
            base,
            seed,
            world,
            referee,
            odometers: (0..robots).map(|i| Odometer::new(i, mice, base)).collect(),
            rngs,
            stats: Default::default(),
            hash: FNV_OFFSET,
            calls: Vec::new(),
            shots: Vec::new(),
            frames: Vec::new(),
            beliefs: Vec::new(),
            record: false,
            faults: Vec::new(),
            localization: LocalizationErrors::default(),
            kicks: Vec::new(),
            booked_at: vec![f64::NEG_INFINITY; robots],
            attacker_at: vec![f64::NEG_INFINITY; robots],
            ball_job_at: vec![f64::NEG_INFINITY; robots],
            eyes: match cfg.sensor.percepts {
                PerceptSource::Oracle => None,
                PerceptSource::Vision => Some(Eyes::new(cfg, robots, seed)?),
            },
            pans: vec![cfg.vision.camera.camera().map_or(0.0, |c| c.pan); robots],
            kidnap_plan,
            kidnap_rng,
            kidnaps: Vec::new(),
        })
    }

    /// When each robot is kidnapped: `[rules] kidnaps` times in each half, uniformly in the
    /// half's clock (which runs in READY and SET too) after its READY and SET and before its
    /// last 5 s; latest first. A kidnap due outside play waits for play.
    fn plan_kidnaps(cfg: &SimConfig, robots: usize, rng: &mut ChaCha8Rng) -> Vec<(f64, usize)> {
        use rand::Rng;
        let half = cfg.rules.half_duration;
        let mut plan = Vec::new();
        for robot in 0..robots {
            for h in 0..2 {
                for _ in 0..cfg.rules.kidnaps {
                    let start = cfg.rules.ready_duration + cfg.rules.set_duration + 1.0;
                    let (a, b) = (f64::from(h) * half + start, f64::from(h + 1) * half - 5.0);
                    let at = if b > a { rng.random_range(a..b) } else { f64::from(h) * half };
                    plan.push((at, robot));
                }
            }
        }
        plan.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.cmp(&a.1)));
        plan
    }

    /// Carries the robots whose kidnap is due to random free spots: inside the field 1 m from
    /// its lines, 1 m from every other robot and the ball, 2 m from where it was.
    ///
    /// A robot carried less than [`KIDNAP_GAP`] ago waits until that long after its last
    /// carry: two kidnaps due while play was stopped would otherwise carry it twice in one
    /// cycle, and one a second after another gives it no time to find itself.
    fn kidnap_due(&mut self) {
        use rand::Rng;
        let now = self.world.time();
        while self.kidnap_plan.last().is_some_and(|&(at, _)| at <= now) {
            let Some((_, robot)) = self.kidnap_plan.pop() else { break };
            let last = self.kidnaps.iter().rev().find(|k| k.robot == robot).map(|k| k.at);
            if let Some(last) = last.filter(|&t| now - t < KIDNAP_GAP) {
                let at = last + KIDNAP_GAP;
                let i =
                    self.kidnap_plan.partition_point(|&(t, r)| t > at || (t == at && r > robot));
                self.kidnap_plan.insert(i, (at, robot));
                continue;
            }
            let Some(from) = self.world.robot(robot) else { continue };
            let (hl, hw) = (self.cfg.field.length / 2.0 - 1.0, self.cfg.field.width / 2.0 - 1.0);
            let ball = self.world.ball();
            let others: Vec<Pose2> = (0..self.world.robot_count())
                .filter(|&j| j != robot)
                .filter_map(|j| self.world.robot(j))
                .collect();
            let rng = &mut self.kidnap_rng;
            let spot = (0..100).find_map(|_| {
                let (x, y) = (rng.random_range(-hl..=hl), rng.random_range(-hw..=hw));
                let theta = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
                let free = others.iter().all(|o| (o.x - x).hypot(o.y - y) >= 1.0)
                    && (ball.0 - x).hypot(ball.1 - y) >= 1.0
                    && (from.x - x).hypot(from.y - y) >= 2.0;
                free.then(|| Pose2::new(x, y, theta))
            });
            if let Some(to) = spot {
                self.world.carry_robot(robot, to);
                self.kidnaps.push(Kidnap { robot, at: now, to, recovered_after: None });
            }
        }
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The world, to set up a scene (put a robot or the ball somewhere).
    pub fn world_mut(&mut self) -> &mut World {
        &mut self.world
    }

    /// The referee.
    pub fn referee(&self) -> &Referee {
        &self.referee
    }

    /// Whether the match is over.
    pub fn finished(&self) -> bool {
        self.referee.state() == GameState::Finished
    }

    /// Robot `i`'s odometry sensors since their last reading (first in a cycle: the sensors
    /// draw from the robot's random stream in the order odometry, camera, sonars).
    pub fn odometry(&mut self, i: usize) -> Odometry {
        let period = self.cfg.rules.control_period;
        self.odometers[i].read(&self.world, &self.cfg.odometry, period, &mut self.rngs[i])
    }

    /// What robot `i`'s mice and wheel encoders counted since its last reading, as the devices
    /// count it (the wheels' turns, rad): [`Pitch::odometry`] for a world of the device
    /// protocol.
    pub fn odometry_counts(&mut self, i: usize) -> crate::sensor::Counts {
        let period = self.cfg.rules.control_period;
        self.odometers[i].count(&self.world, &self.cfg.odometry, period, &mut self.rngs[i])
    }

    /// What robot `i`'s camera sees now: its image (vision percepts), or the object sensor's
    /// sightings (oracle percepts).
    pub fn camera(&mut self, i: usize) -> CameraFrame {
        let pan = self.pans.get(i).copied().unwrap_or(0.0);
        let Some(eyes) = &mut self.eyes else {
            let referee = &self.referee;
            let marker_of = |k: usize| referee.team_of(k).marker();
            let frame =
                sensor::look(&self.world, i, pan, &self.cfg.sensor, marker_of, &mut self.rngs[i]);
            return CameraFrame { pan: Some(pan), ..frame };
        };
        let scene = Scene {
            ball: Some(self.world.ball()),
            robots: (0..self.world.robot_count())
                .filter_map(|k| {
                    let home = self.referee.team_of(k) == Team::Home;
                    Some((self.world.robot(k)?, home))
                })
                .collect(),
        };
        let viewer = self.world.robot(i).unwrap_or_default();
        let time = self.world.time();
        let Some(state) = eyes.states.get_mut(i) else {
            return CameraFrame { time, ..Default::default() };
        };
        let image = eyes.front.render(&scene, viewer, pan, Some(i), state);
        let up_image = match (&eyes.up, eyes.up_states.get_mut(i)) {
            (Some(up), Some(state)) => Some(up.render(&scene, viewer, 0.0, Some(i), state)),
            _ => None,
        };
        CameraFrame { time, image: Some(image), pan: Some(pan), up_image, ..Default::default() }
    }

    /// Robot `i`'s camera pan joint now, rad.
    pub fn pan(&self, i: usize) -> Option<f64> {
        self.pans.get(i).copied()
    }

    /// Turns robot `i`'s camera pan joint to `pan` (rad from straight ahead, counter-clockwise;
    /// the joint turns within one cycle: its range and speed are the robot's gaze control's
    /// to keep). A pan that is not a finite number is refused.
    pub fn set_pan(&mut self, i: usize, pan: f64) -> Result<(), SimError> {
        if !pan.is_finite() {
            return Err(SimError::Match(format!("camera pan joint: {pan} rad is not an angle")));
        }
        let slot = self.pans.get_mut(i).ok_or_else(|| SimError::Match(format!("no robot {i}")))?;
        *slot = mrt_core::normalize_angle(pan);
        Ok(())
    }

    /// What the game controller tells robot `i` now (no randomness: read it at any time).
    pub fn game_info(&self, i: usize) -> GameInfo {
        sensor::game_info(&self.referee, i)
    }

    /// Robot `i`'s sonar ring listens once (after [`Pitch::camera`] in a cycle).
    pub fn sonar(&mut self, i: usize) -> Vec<Sonar> {
        sonar_ring(&self.world, i, &self.cfg.sonar, &mut self.rngs[i])
    }

    /// Books a fault of robot `i`'s software now (`count` of them, the first one's `message`).
    pub fn fault(&mut self, i: usize, count: u64, message: &str) {
        let now = self.world.time();
        self.fault_at(i, Some(now), count, message);
    }

    /// Books a fault of robot `i`'s software first seen at `first_at` (if known).
    pub fn fault_at(&mut self, i: usize, first_at: Option<f64>, count: u64, message: &str) {
        if let Some(f) = self.faults.iter_mut().find(|f| f.robot == i) {
            f.count += count;
            return;
        }
        tracing::warn!(robot = i, "robot {i}: {message}");
        self.faults.push(RobotFault { robot: i, first_at, count, message: message.to_string() });
        self.faults.sort_by_key(|f| f.robot);
    }

    /// The robots' base (kinematics and wheel limits).
    pub fn base(&self) -> Base {
        self.base
    }

    /// Sets robot `i`'s body velocity (what its motor driver achieved). Outside `READY` and
    /// `PLAYING` the robot is held still.
    pub fn drive(&mut self, i: usize, drive: Twist) {
        let moving = matches!(self.referee.state(), GameState::Ready | GameState::Playing);
        self.world.drive(i, if moving { drive } else { Twist::ZERO });
    }

    /// Fires robot `i`'s kicker (only while `PLAYING`) as the cycle's physics starts: every
    /// robot senses the same world in a cycle, whichever acted before it, so a match does not
    /// depend on the order in which robots run (in one process or in several; kicks of one
    /// cycle fire in the order asked). A kick that reaches the ball counts as a shot.
    pub fn kick(&mut self, i: usize) {
        if !self.kicks.contains(&i) {
            self.kicks.push(i);
        }
    }

    /// Whether robot `i`'s kick (the ball sent along its heading) heads into the goal that
    /// `team` attacks: the line from the ball along the heading crosses that goal line
    /// between the posts, less the ball's radius.
    fn on_target(&self, i: usize, team: Team) -> bool {
        let Some(pose) = self.world.robot(i) else { return false };
        let line = self.referee.attack_direction(team) * self.cfg.field.length / 2.0;
        let mouth = self.cfg.field.goal_width / 2.0 - self.cfg.ball.radius;
        heads_into_goal(self.world.ball(), pose.theta, line, mouth)
    }

    fn fire_kicks(&mut self) {
        for i in std::mem::take(&mut self.kicks) {
            if self.referee.state() == GameState::Playing && self.world.kick(i) {
                let team = self.referee.team_of(i);
                self.stats[team.index()].shots += 1;
                if self.on_target(i, team) {
                    self.stats[team.index()].shots_on_target += 1;
                }
                self.shots.push((self.world.time(), i, self.world.ball()));
            }
        }
    }

    /// Applies a motor command to robot `i` through its base's kinematics and motor duty
    /// cycles, as its driver would; a kick request fires the kicker.
    pub fn apply(&mut self, i: usize, cmd: &MotorCommand) {
        let drive = self.base.twist_for(&self.base.duties(&cmd.twist)).unwrap_or_default();
        self.drive(i, drive);
        if cmd.kick {
            self.kick(i);
        }
    }

    /// Books this control cycle, then runs the physics (with the referee) up to the next one.
    /// Returns the referee's calls.
    pub fn advance(&mut self) -> Vec<Call> {
        if self.referee.state() == GameState::Playing {
            self.kidnap_due();
        }
        self.account();
        self.fire_kicks();
        let steps =
            (self.cfg.rules.control_period / self.cfg.rules.physics_step).round().max(1.0) as usize;
        let mut calls = Vec::new();
        for _ in 0..steps {
            self.world.step();
            if let Some(call) = self.referee.update(&mut self.world) {
                if let Call::Goal(team) = call {
                    self.stats[team.index()].goals += 1;
                }
                self.calls.push((self.world.time(), call.clone()));
                calls.push(call);
                if self.finished() {
                    break;
                }
            }
        }
        calls
    }

    /// Possession, the trajectory hash and the recorded frame of this cycle.
    fn account(&mut self) {
        let ball = self.world.ball();
        let mut best: Option<(f64, Team)> = None;
        let mut robots = Vec::with_capacity(self.world.robot_count());
        self.hash = fnv(fnv(self.hash, mm(ball.0)), mm(ball.1));
        for i in 0..self.world.robot_count() {
            let Some(p) = self.world.robot(i) else { continue };
            self.hash = fnv(fnv(fnv(self.hash, mm(p.x)), mm(p.y)), mm(p.theta));
            let d = (p.x - ball.0).hypot(p.y - ball.1);
            if d < 1.0 && best.is_none_or(|(b, _)| d < b) {
                best = Some((d, self.referee.team_of(i)));
            }
            robots.push((p.x, p.y, p.theta));
        }
        if let Some((_, team)) = best {
            self.stats[team.index()].possession_cycles += 1;
        }
        if self.record {
            self.frames.push(Frame { time: self.world.time(), ball, robots });
        }
    }

    /// Keeps one [`Frame`] per control cycle, and every robot's belief at each estimate, for
    /// drawings.
    pub fn record_frames(&mut self, on: bool) {
        self.record = on;
    }

    /// The match's report.
    pub fn report(self) -> MatchReport {
        MatchReport {
            seed: self.seed,
            score: self.referee.score(),
            stats: self.stats,
            trajectory_hash: self.hash,
            duration: self.world.time(),
            calls: self.calls,
            shots: self.shots,
            frames: self.frames,
            beliefs: self.beliefs,
            faults: self.faults,
            localization: self.localization,
            kidnaps: self.kidnaps,
        }
    }
}

/// Whether a ball at `ball` sent along `heading` (rad) crosses the goal line `x = line`
/// within `mouth` of its centre (m).
fn heads_into_goal((bx, by): (f64, f64), heading: f64, line: f64, mouth: f64) -> bool {
    let (c, s) = (heading.cos(), heading.sin());
    if (line - bx) * c <= 0.0 || c.abs() < 1e-9 {
        return false;
    }
    (by + (line - bx) / c * s).abs() < mouth
}

#[cfg(test)]
mod shot_tests {
    use super::heads_into_goal;

    /// By hand, the east goal line at x = 9 m with a 0.89 m half mouth: from (5, 0) straight
    /// east, in; at 10° the ball crosses at y = 4·tan 10° = 0.705 m, in; at 15°, 1.07 m, wide;
    /// away from the goal, never; the west goal from (5, 0) heading west, in.
    #[test]
    fn a_shot_is_on_target_when_its_line_crosses_the_goal_mouth() {
        let deg = f64::to_radians;
        assert!(heads_into_goal((5.0, 0.0), 0.0, 9.0, 0.89));
        assert!(heads_into_goal((5.0, 0.0), deg(10.0), 9.0, 0.89));
        assert!(!heads_into_goal((5.0, 0.0), deg(15.0), 9.0, 0.89));
        assert!(!heads_into_goal((5.0, 0.0), deg(180.0), 9.0, 0.89));
        assert!(!heads_into_goal((5.0, 0.0), deg(90.0), 9.0, 0.89));
        assert!(heads_into_goal((5.0, 0.0), deg(180.0), -9.0, 0.89));
    }
}
