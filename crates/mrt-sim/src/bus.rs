//! Robots as Agoras on the bus (DCDT, MRT manual ch. 3): the simulator's default wiring.
//!
//! Each robot is one [`Agora`] with eight Members, all on the simulated clock
//! of one [`SteppedExecutor`] so that the match stays deterministic:
//!
//! 1. **`OdometryDriver`** (periodic): publishes the two optical mice's and the wheels'
//!    readings since the last cycle ([`Odometry`]);
//! 2. **`CameraDriver`** (periodic): publishes what the object sensor sees, as distance and
//!    bearing, with the game controller's news ([`CameraFrame`]);
//! 3. **`WorldState`** (periodic): fuses both into the robot's own pose and LPS
//!    ([`WorldModel`]: an EKF predicted by the mice, or the wheels, and corrected by the
//!    landmarks), takes its teammates' poses from their reports received over the bus, and
//!    publishes the [`WorldSnapshot`]; it also publishes a [`MateReport`] (its pose and its
//!    ball estimate) that the teammates' Agoras receive through their team's
//!    `InnerLinkManager` — a `RequestType::Remote` subscription, so a robot never hears
//!    itself.
//! 4. **`Sonars`** (the sonar ring's driver, periodic): publishes a [`SonarScan`];
//! 5. **the behaviors**: a [`BehaviorMember`] running the TeamChaos HFSM or goalkeeper for the
//!    Chaos stack, or a [`BrainMember`] around any `Send` [`Brain`] (Milan, the baseline);
//! 6. **`Guide`** (guidance, ISocRob §3.2.3, on message): turns the behaviors'
//!    [`RobotCommand`] into a [`MotorCommand`] with [`mrt_plan::guide::Guidance`]: velocity
//!    mode halted by the sonars, or position and potential-field modes to a target posture;
//! 7. **`Motor`** (the motor and kicker driver, on message): turns each [`MotorCommand`] into
//!    wheel set-points and kicks;
//! 8. **`FaultBook`** (on message): books the behavior Member's script errors against the
//!    robot. A Member that fails to start, fails or panics is restarted by its executor and
//!    booked too when the match ends: the match goes on, the robot stands still meanwhile, and
//!    [`MatchReport::faults`] says which file and line.
//!
//! Body adaptation belongs to the drivers, as the seed's Commander Module did for its legs: on
//! the Chaos robots `WorldState` measures distances from the robot's edge and `Guide` scales the
//! behaviors' AIBO-sized set-points before guiding them (see [`crate::teams`]).

use crate::devices::{Devices, PitchDevices, SharedDevices};
use crate::drivers::Base;
use crate::embedded::FilesDir;
use crate::game::{guide, Brain, MatchReport, Pitch};
use crate::referee::Call;
use crate::teams::{embedded_teamchaos, send_brain, Body, Stack, CHAOS_KEEPER, CHAOS_PLAYER};
use mrt_core::SimClock;
use mrt_dcdt::{
    Activation, Agora, Context, InnerLinkManager, Member, MemberError, RequestType, RunReport,
    SteppedExecutor,
};
use mrt_msgs::robot::{RobotCommand, WorldSnapshot};
use mrt_msgs::{CameraFrame, Odometry};
use mrt_plan::guide::Guidance;
use mrt_script::member::{BehaviorMember, BehaviorStatus};
use mrt_world::{merge_team, WorldModel};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

pub use mrt_msgs::{MateReport, MemberFault, MotorCommand, SonarScan};

type Shared = Arc<Mutex<Pitch>>;

fn lock_pitch(p: &Shared) -> Result<MutexGuard<'_, Pitch>, String> {
    p.lock().map_err(|_| "the pitch lock is poisoned".to_string())
}

fn lock(d: &SharedDevices) -> Result<MutexGuard<'_, dyn Devices + 'static>, MemberError> {
    d.lock().map_err(|_| MemberError::from("the devices lock is poisoned"))
}

/// The odometry driver of one robot: the mice and the wheels since the last cycle.
struct OdometryDriver {
    devices: SharedDevices,
    robot: usize,
}

impl Member for OdometryDriver {
    fn name(&self) -> String {
        format!("odometry-{}", self.robot)
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let odometry = lock(&self.devices)?.odometry()?;
        ctx.publish(odometry);
        Ok(())
    }
}

/// The camera driver of one robot (the object sensor), with the game controller's news.
struct CameraDriver {
    devices: SharedDevices,
    robot: usize,
}

impl Member for CameraDriver {
    fn name(&self) -> String {
        format!("camera-{}", self.robot)
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let frame = lock(&self.devices)?.camera()?;
        ctx.publish(frame);
        Ok(())
    }
}

/// The world-state Member of one robot: odometry and camera frames into its [`WorldModel`],
/// teammates from their reports over the bus; publishes the [`WorldSnapshot`] and its own
/// [`MateReport`].
struct WorldState {
    robot: usize,
    keeper: bool,
    body: Body,
    model: WorldModel,
    mates: BTreeMap<u32, MateReport>,
}

impl Member for WorldState {
    fn name(&self) -> String {
        format!("world-state-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Odometry>(RequestType::Local);
        ctx.subscribe_to::<CameraFrame>(RequestType::Local);
        ctx.subscribe_to::<MateReport>(RequestType::Remote);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut frame = None;
        while let Some(m) = ctx.receive_msg() {
            if let Ok(o) = m.get::<Odometry>() {
                self.model.odometry(o);
            } else if let Ok(f) = m.get::<CameraFrame>() {
                frame = Some(f.clone());
            } else {
                let r = m.get::<MateReport>()?;
                self.mates.insert(r.id, *r);
            }
        }
        let Some(frame) = frame else { return Ok(()) };
        let mut w = self.model.camera(&frame);
        let id = u32::try_from(self.robot).unwrap_or(u32::MAX);
        let report = MateReport::of(id, self.keeper, &w);
        // Teammates and their ball as the bus told them, not as the simulator knows them.
        merge_team(&mut w, self.mates.values());
        ctx.publish(report);
        self.body.perceive(&mut w);
        ctx.publish(w);
        Ok(())
    }
}

/// The sonar ring's driver of one robot.
struct Sonars {
    devices: SharedDevices,
    robot: usize,
}

impl Member for Sonars {
    fn name(&self) -> String {
        format!("sonars-{}", self.robot)
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let sonars = lock(&self.devices)?.sonars()?;
        ctx.publish(SonarScan { sonars });
        Ok(())
    }
}

/// Guidance of one robot: the behaviors' command, adapted to the body, through the Guidance
/// µAgent with the latest world state and sonar scan.
struct Guide {
    robot: usize,
    body: Body,
    guidance: Guidance,
    world: WorldSnapshot,
    scan: SonarScan,
}

impl Member for Guide {
    fn name(&self) -> String {
        format!("guide-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Local);
        ctx.subscribe_to::<SonarScan>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut last = None;
        while let Some(m) = ctx.receive_msg() {
            if let Ok(c) = m.get::<RobotCommand>() {
                last = Some(c.clone());
            } else if let Ok(w) = m.get::<WorldSnapshot>() {
                self.world.clone_from(w);
            } else {
                self.scan.clone_from(m.get::<SonarScan>()?);
            }
        }
        if let Some(mut cmd) = last {
            self.body.act(&mut cmd);
            ctx.publish(MotorCommand(guide(&self.guidance, &cmd, &self.world, &self.scan.sonars)));
        }
        Ok(())
    }
}

/// The motor and kicker driver of one robot: commands become duty cycles for its motor
/// driver (the processing side of the AIRBoard), kick requests fire the kicker.
struct Motor {
    devices: SharedDevices,
    robot: usize,
    base: Base,
}

impl Member for Motor {
    fn name(&self) -> String {
        format!("motor-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<MotorCommand>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut last = None;
        while let Some(m) = ctx.receive_msg() {
            last = Some(m.get::<MotorCommand>()?.0.clone());
        }
        if let Some(cmd) = last {
            let mut devices = lock(&self.devices)?;
            devices.set_duty(&self.base.duties(&cmd))?;
            if cmd.kick.is_some() {
                devices.kick()?;
            }
        }
        Ok(())
    }
}

/// Books a robot's script errors (its behavior Member's `BehaviorStatus`) against the robot,
/// as a referee's assistant would note a robot that stopped.
struct FaultBook {
    devices: SharedDevices,
    robot: usize,
}

impl Member for FaultBook {
    fn name(&self) -> String {
        format!("faults-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<BehaviorStatus>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if let Some(e) = m.get::<BehaviorStatus>()?.errors.first() {
                lock(&self.devices)?.fault(e)?;
            }
        }
        Ok(())
    }
}

/// Runs any `Send` [`Brain`] as a behavior Member: world snapshot in, command out.
pub struct BrainMember {
    brain: Box<dyn Brain + Send>,
    world: Option<WorldSnapshot>,
}

impl BrainMember {
    /// A Member around `brain`.
    pub fn new(brain: Box<dyn Brain + Send>) -> Self {
        Self { brain, world: None }
    }
}

impl Member for BrainMember {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            self.world = Some(m.get::<WorldSnapshot>()?.clone());
        }
        if let Some(w) = &self.world {
            ctx.publish(self.brain.cycle(w));
        }
        Ok(())
    }
}

/// One robot of a match: which robot it is (0 .. 2 × team size: home, then away), whether it
/// keeps goal and which behavior stack drives it. Its Agora's id is `robot + 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RobotSpec {
    /// The robot.
    pub robot: usize,
    /// Keeps goal (robot 0 of each team).
    pub keeper: bool,
    /// What drives it.
    pub stack: Stack,
}

impl RobotSpec {
    /// Robot `robot` of a match with `team_size` robots a side, the home team playing `home`
    /// and the away team `away`.
    pub fn of(robot: usize, team_size: usize, (home, away): (Stack, Stack)) -> RobotSpec {
        let n = team_size.max(1);
        RobotSpec { robot, keeper: robot % n == 0, stack: if robot < n { home } else { away } }
    }

    /// The id of the robot's Agora.
    pub fn agora_id(&self) -> Result<u32, String> {
        u32::try_from(self.robot + 1).map_err(|e| e.to_string())
    }
}

/// Puts one robot's Members into `agora`, activated: the drivers of its `devices`, its world
/// state, its behaviors (the TeamChaos files of `behaviors` for the Chaos stack), guidance,
/// motor and fault book (module doc). The same robot code runs on a pitch in this process
/// ([`BusMatch`]) and on a simulator in another one ([`crate::remote::RemoteRobot`]).
pub fn add_robot(
    agora: &mut Agora,
    cfg: &crate::config::SimConfig,
    spec: &RobotSpec,
    behaviors: &Path,
    devices: SharedDevices,
) -> Result<(), String> {
    let RobotSpec { robot, keeper, stack } = *spec;
    let period = Duration::from_secs_f64(cfg.rules.control_period);
    let every = Activation::Periodic(period);
    let body = if stack == Stack::Chaos { Body::chaos(cfg) } else { Body::PLAIN };
    let model = cfg.world_model()?;
    let base = Base::parse(&cfg.robot.base)?;
    let dev = || devices.clone();
    let mut ids = vec![
        agora.add_member(OdometryDriver { devices: dev(), robot }, every),
        agora.add_member(CameraDriver { devices: dev(), robot }, every),
        agora.add_member(WorldState { robot, keeper, body, model, mates: BTreeMap::new() }, every),
        agora.add_member(Sonars { devices: dev(), robot }, every),
    ];
    ids.push(match stack {
        Stack::Chaos if keeper => {
            agora.add_member(BehaviorMember::hbm(behaviors, CHAOS_KEEPER), every)
        }
        Stack::Chaos => {
            agora.add_member(BehaviorMember::hfsm(behaviors, behaviors.join(CHAOS_PLAYER)), every)
        }
        other => agora.add_member(BrainMember::new(send_brain(other, keeper, cfg)?), every),
    });
    let guidance = cfg.guidance()?;
    let scan = SonarScan::default();
    let guide = Guide { robot, body, guidance, world: WorldSnapshot::default(), scan };
    ids.push(agora.add_member(guide, Activation::OnMessage));
    ids.push(agora.add_member(Motor { devices: dev(), robot, base }, Activation::OnMessage));
    ids.push(agora.add_member(FaultBook { devices, robot }, Activation::OnMessage));
    for m in ids {
        agora.activate_member(m).map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// The TeamChaos files robots of `stacks` run: `behaviors`, or the compiled-in ones when the
/// Chaos stack plays (nothing otherwise).
/// Keep the handle while the robots may read them: compiled-in files are removed with it.
pub fn behaviors_dir(stacks: &[Stack], behaviors: Option<&Path>) -> Result<FilesDir, String> {
    match behaviors {
        Some(d) => Ok(FilesDir::user(d)),
        None if stacks.contains(&Stack::Chaos) => embedded_teamchaos(),
        None => Ok(FilesDir::user(PathBuf::new())),
    }
}

/// The faulty Members of one Agora's report: failed starts, jobs and panics, and mailboxes
/// that lost messages (their bus bounds dropped or refused some: a Member that fell thousands
/// of messages behind).
pub fn member_faults(report: &RunReport) -> Vec<MemberFault> {
    report
        .members
        .iter()
        .flat_map(|m| {
            let failed = m.last_error.clone().map(|error| MemberFault {
                name: m.name.clone(),
                count: m.errors + m.panics + m.restarts.max(1),
                never_ran: m.cycles == 0,
                error,
            });
            let lost =
                m.mailboxes.iter().filter(|b| b.dropped + b.refused > 0).map(|b| MemberFault {
                    name: m.name.clone(),
                    count: b.dropped + b.refused,
                    never_ran: false,
                    error: format!(
                        "its mailbox for {} dropped {} and refused {} messages (capacity {})",
                        b.msg_type, b.dropped, b.refused, b.capacity
                    ),
                });
            failed.into_iter().chain(lost)
        })
        .collect()
}

/// Books a Member's fault against robot `robot`.
pub fn book_fault(fault: &MemberFault, pitch: &mut Pitch, robot: usize) {
    let first_at = fault.never_ran.then_some(0.0);
    pitch.fault_at(
        robot,
        first_at,
        fault.count,
        &format!("member {}: {}", fault.name, fault.error),
    );
}

/// A match whose robots are Agoras on the bus.
pub struct BusMatch {
    pitch: Shared,
    exec: SteppedExecutor,
    period: Duration,
    /// Each team's community of Agoras (home, then away).
    links: Vec<InnerLinkManager>,
    /// The behavior files, kept while the robots may reload them.
    _files: FilesDir,
}

impl BusMatch {
    /// A match between two stacks, `team_size` robots each (robot 0 keeps goal), or home alone
    /// when `away` is `None`. `behaviors` overrides the compiled-in TeamChaos files.
    pub fn new(
        cfg: &crate::config::SimConfig,
        seed: u64,
        home: Stack,
        away: Option<Stack>,
        behaviors: Option<&Path>,
    ) -> Result<BusMatch, String> {
        let n = cfg.rules.team_size;
        let pitch = Pitch::new(cfg, seed, n, if away.is_some() { n } else { 0 })?;
        let pitch = Arc::new(Mutex::new(pitch));
        let period = Duration::from_secs_f64(cfg.rules.control_period);
        let mut exec = SteppedExecutor::new(SimClock::new(), period);
        let stacks: Vec<Stack> = [Some(home), away].into_iter().flatten().collect();
        let dir = behaviors_dir(&stacks, behaviors)?;
        let mut links = Vec::new();
        for _ in &stacks {
            let team_link = InnerLinkManager::new();
            links.push(team_link.clone());
            for _ in 0..n {
                let robot = exec.agoras().count();
                let spec = RobotSpec::of(robot, n, (home, away.unwrap_or(home)));
                let mut agora = exec
                    .agora_builder(spec.agora_id()?)
                    .inner_link(&team_link)
                    .build()
                    .map_err(|e| e.to_string())?;
                let devices = Arc::new(Mutex::new(PitchDevices::new(pitch.clone(), robot)?));
                add_robot(&mut agora, cfg, &spec, &dir, devices)?;
                exec.add_agora(agora).map_err(|e| e.to_string())?;
            }
        }
        Ok(BusMatch { pitch, exec, period, links, _files: dir })
    }

    /// A team's community of Agoras (0 home, 1 away), to attach monitors to.
    pub fn team_link(&self, team: usize) -> Option<&InnerLinkManager> {
        self.links.get(team)
    }

    /// The executor, to add monitoring Agoras.
    pub fn executor(&mut self) -> &mut SteppedExecutor {
        &mut self.exec
    }

    /// Keeps one frame per control cycle for drawings.
    pub fn record_frames(&mut self, on: bool) {
        if let Ok(mut p) = self.pitch.lock() {
            p.record_frames(on);
        }
    }

    /// One control cycle: every Agora runs (eyes, behaviors, motors), then the physics runs
    /// up to the next cycle. Returns the referee's calls.
    pub fn cycle(&mut self) -> Result<Vec<Call>, String> {
        self.exec.run_for(self.period);
        let mut p = self.pitch.lock().map_err(|_| "the pitch lock is poisoned".to_string())?;
        Ok(p.advance())
    }

    /// Plays until the end, calling `progress` with the simulated time after each cycle.
    pub fn play(mut self, mut progress: impl FnMut(f64)) -> Result<MatchReport, String> {
        while !lock_pitch(&self.pitch)?.finished() {
            self.cycle()?;
            progress(lock_pitch(&self.pitch)?.world().time());
        }
        // Members that failed to start, failed jobs or panicked (each was restarted).
        let reports = self.exec.finish();
        {
            let mut pitch = lock_pitch(&self.pitch)?;
            for r in &reports {
                let robot = usize::try_from(r.agora.0).unwrap_or(usize::MAX).wrapping_sub(1);
                if robot < pitch.world().robot_count() {
                    // (not a monitoring Agora)
                    member_faults(r).iter().for_each(|f| book_fault(f, &mut pitch, robot));
                }
            }
        }
        let pitch =
            Arc::try_unwrap(self.pitch).map_err(|_| "the pitch is still shared".to_string())?;
        Ok(pitch.into_inner().map_err(|_| "the pitch lock is poisoned".to_string())?.report())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::short;

    #[test]
    fn a_bus_match_is_deterministic_and_both_stacks_play() {
        let cfg = short(20.0, 2);
        let play = || {
            BusMatch::new(&cfg, 4, Stack::Chaos, Some(Stack::Chaser), None)
                .unwrap()
                .play(|_| {})
                .unwrap()
        };
        let (a, b) = (play(), play());
        assert_eq!((a.score, a.trajectory_hash, &a.stats), (b.score, b.trajectory_hash, &b.stats));
        assert!((a.duration - 40.0).abs() < 0.011, "{}", a.duration);
        assert!(
            a.stats[0].possession_cycles > 0 && a.stats[1].possession_cycles > 0,
            "{:?}",
            a.stats
        );
    }

    /// A Member whose mailbox lost messages is booked like a failing one, with the type and
    /// the counts; one whose mailboxes lost nothing is not.
    #[test]
    fn a_mailbox_that_lost_messages_is_a_member_fault() {
        use mrt_dcdt::{ExitReason, MailboxReport, MemberReport, MemberState, MsgType};
        let member = |name: &str, dropped, refused| MemberReport {
            id: mrt_dcdt::MemberId(0),
            name: name.into(),
            cycles: 10,
            errors: 0,
            panics: 0,
            restarts: 0,
            state: MemberState::Terminated,
            last_error: None,
            mailboxes: vec![MailboxReport {
                msg_type: MsgType(7),
                capacity: 4096,
                reliable_limit: 65_536,
                dropped,
                refused,
            }],
        };
        let report = RunReport {
            agora: mrt_dcdt::AgoraId(1),
            exit: ExitReason::TimeLimit,
            members: vec![member("Fine", 0, 0), member("Slow", 3, 1)],
        };
        let faults = member_faults(&report);
        assert_eq!(faults.len(), 1, "{faults:?}");
        assert_eq!((faults[0].name.as_str(), faults[0].count), ("Slow", 4));
        assert!(faults[0].error.contains("dropped 3 and refused 1"), "{}", faults[0].error);
    }

    /// The same robot code gives the same match whether the brains run as Members on the bus
    /// or are called directly (teammates' reports included: the direct wiring hands them over
    /// with the bus's timing).
    #[test]
    fn the_bus_and_the_direct_wiring_play_the_same_match() {
        let cfg = short(15.0, 2);
        let bus = BusMatch::new(&cfg, 9, Stack::Chaos, Some(Stack::Chaser), None)
            .unwrap()
            .play(|_| {})
            .unwrap();
        let home = crate::teams::team(Stack::Chaos, &cfg, None).unwrap();
        let away = crate::teams::team(Stack::Chaser, &cfg, None).unwrap();
        let direct = crate::game::Match::new(&cfg, 9, home, away).unwrap().play(f64::MAX, |_| {});
        assert_eq!((bus.score, bus.trajectory_hash), (direct.score, direct.trajectory_hash));
    }

    /// Bad behavior files never stop a match: a file that does not compile stops the robots
    /// that load it (they stand still), a behavior that runs away is cut off by its budget;
    /// both are reported with the file and line, on the bus and in the direct wiring.
    #[test]
    fn broken_or_runaway_behaviors_stop_their_robot_and_are_reported() {
        let tmp = std::env::temp_dir().join(format!("mrt-sim-broken-{}", std::process::id()));
        let src = embedded_teamchaos().unwrap();
        let copy = |to: &Path| {
            std::fs::create_dir_all(to).unwrap();
            for e in std::fs::read_dir(&src).unwrap() {
                let p = e.unwrap().path();
                std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
            }
        };
        let cfg = short(5.0, 2);
        // 1. A syntax error in go2ball.lua (line 11): no Chaos robot can load its behaviors.
        let broken = tmp.join("broken");
        copy(&broken);
        let go2ball = broken.join("go2ball.lua");
        let text = std::fs::read_to_string(&go2ball).unwrap();
        std::fs::write(&go2ball, format!("{}rule(ballSeen(, 'go')\n", text)).unwrap();
        let line = text.lines().count() + 1;
        let want = format!("go2ball.lua:{line}:");
        let bus = BusMatch::new(&cfg, 1, Stack::Chaos, Some(Stack::Chaser), Some(&broken))
            .unwrap()
            .play(|_| {})
            .unwrap();
        let home = crate::teams::team(Stack::Chaos, &cfg, Some(&broken)).unwrap();
        let away = crate::teams::team(Stack::Chaser, &cfg, None).unwrap();
        let direct = crate::game::Match::new(&cfg, 1, home, away).unwrap().play(f64::MAX, |_| {});
        for r in [&bus, &direct] {
            assert!((r.duration - 10.0).abs() < 0.011, "the match went on: {}", r.duration);
            let robots: Vec<usize> = r.faults.iter().map(|f| f.robot).collect();
            assert_eq!(robots, [0, 1], "{:?}", r.faults);
            assert!(r.faults.iter().all(|f| f.message.contains(&want)), "{:?}", r.faults);
            assert!(r.faults.iter().all(|f| f.first_at == Some(0.0)), "from the start");
            assert_eq!(r.stats[0].shots, 0, "stopped robots do not play");
        }
        // 2. A goalkeeper behavior that never ends: the budget cuts it off every cycle.
        let looping = tmp.join("looping");
        copy(&looping);
        let keeper = looping.join("goalkeeper.lua");
        let text = std::fs::read_to_string(&keeper).unwrap();
        std::fs::write(&keeper, format!("while true do end\n{text}")).unwrap();
        let bus = BusMatch::new(&cfg, 1, Stack::Chaos, Some(Stack::Chaser), Some(&looping))
            .unwrap()
            .play(|_| {})
            .unwrap();
        assert!((bus.duration - 10.0).abs() < 0.011);
        let keeper = bus.faults.iter().find(|f| f.robot == 0);
        assert!(
            keeper.is_some_and(|f| f.message.contains("goalkeeper.lua:1: aborted after")
                && f.message.contains("instruction budget")
                && f.count > 1),
            "{:?}",
            bus.faults
        );
        std::fs::remove_dir_all(&tmp).unwrap();
    }

    #[test]
    fn the_chaos_team_alone_on_the_bus_scores_within_two_minutes() {
        let cfg = short(120.0, 2);
        let report =
            BusMatch::new(&cfg, 3, Stack::Chaos, None, None).unwrap().play(|_| {}).unwrap();
        let first = report.calls.iter().find(|(_, c)| matches!(c, Call::Goal(_)));
        assert!(first.is_some_and(|(t, _)| *t <= 120.0), "{:?}", report.calls);
    }

    /// Teammates know each other only through the bus: a MateReport crosses the team's
    /// InnerLinkManager (Remote subscription), never to the other team, and never to an Agora
    /// on no link.
    #[test]
    fn teammates_hear_each_other_over_the_bus() {
        struct Listen(Arc<Mutex<std::collections::BTreeSet<u32>>>);
        impl Member for Listen {
            fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
                ctx.subscribe_to::<MateReport>(RequestType::Remote);
                Ok(())
            }
            fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
                while let Some(m) = ctx.receive_msg() {
                    let id = m.get::<MateReport>()?.id;
                    self.0.lock().map_err(|_| "poisoned")?.insert(id);
                }
                Ok(())
            }
        }
        let cfg = short(5.0, 2);
        let mut m = BusMatch::new(&cfg, 1, Stack::Chaser, Some(Stack::Chaser), None).unwrap();
        let period = m.period;
        let (on_home, alone) = (Arc::default(), Arc::default());
        for (id, link, heard) in [(98, m.team_link(0).cloned(), &on_home), (99, None, &alone)] {
            let mut b = m.executor().agora_builder(id);
            if let Some(l) = &link {
                b = b.inner_link(l);
            }
            let mut agora = b.build().unwrap();
            let member = agora.add_member(Listen(Arc::clone(heard)), Activation::Periodic(period));
            agora.activate_member(member).unwrap();
            m.executor().add_agora(agora).unwrap();
        }
        for _ in 0..5 {
            m.cycle().unwrap();
        }
        let ids: Vec<u32> = on_home.lock().unwrap().iter().copied().collect();
        assert_eq!(ids, [0, 1], "the home robots' reports, not the away team's (2, 3)");
        assert!(alone.lock().unwrap().is_empty(), "not on any team's link");
    }
}
