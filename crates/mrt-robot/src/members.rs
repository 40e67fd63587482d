//! The robot program: the Members of one robot's cycle, put into its Agora by [`add_robot`]
//! (DCDT, MRT manual ch. 3; sensing, reasoning and acting modules over one bus, §2.1). The
//! simulator's in-process match, its distributed match and a real robot (`mrt robot`) all run
//! these Members; only the [`Devices`] behind the drivers differ.
//!
//! 1. **drivers** (periodic, one generic [`Member`] reading one device each): `odometry-<n>`
//!    publishes the mice's and the wheels' readings since the last cycle ([`Odometry`]),
//!    `camera-<n>` what the camera sees ([`CameraFrame`]: an image, or the simulator's object
//!    sensor's percepts), `game-controller-<n>` the referee's news ([`GameInfo`]),
//!    `sonars-<n>` the sonar ring ([`SonarScan`]);
//! 1. **`vision-<n>`** (periodic, when the robot's configuration has
//!    [`vision`](RobotConfig::vision)): the vision µAgent (ISocRob seed `003` §3.2.1) turns
//!    the camera's latest image into [`Percepts`];
//! 2. **`WorldState`** (periodic): fuses odometry, camera percepts, sonar echoes and game
//!    controller into the robot's own pose, LPS and anchored robots ([`WorldModel`]), takes
//!    its teammates' poses and the robots they see from their reports
//!    received over the bus, and publishes the [`WorldSnapshot`] and, for monitors, its
//!    [`Localization`](mrt_msgs::Localization); it also publishes a [`MateReport`] (its pose
//!    and its ball estimate) that the teammates' Agoras receive through their team's link — a
//!    `RequestType::Remote` subscription, so a robot never hears itself;
//! 3. **the behaviors**: a [`BehaviorMember`] running the TeamChaos HFSM or goalkeeper for the
//!    Chaos stack, or a [`BrainMember`] around any `Send` [`Brain`](crate::brain::Brain)
//!    (Milan, the baseline);
//! 4. **`gaze-<n>`** (periodic, when the robot's configuration has
//!    [`gaze`](RobotConfig::gaze)): the PAM's camera control (seed `001` §2.1) turns the
//!    camera's pan joint to the object the behaviors need most ([`Devices::set_pan`]);
//! 4. **`planner-<n>`** (SPIKE, MRT manual ch. 9, on message): plans a path for each
//!    [`PlanRequest`] round the robots the world model anchored ([`crate::planner`]);
//! 4. **`Guide`** (guidance, ISocRob §3.2.3, on message): turns the behaviors'
//!    [`RobotCommand`] into a [`MotorCommand`] with [`mrt_plan::guide::Guidance`]: velocity
//!    mode halted by the sonars, or position and potential-field modes to a target posture,
//!    or, for a target with `plan`, position mode along the planner's path, halted by the
//!    sonars; on a robot whose camera cannot pan, it turns the robot in place while the world
//!    model needs to localize ([`crate::look_around`]);
//! 5. **`Motor`** (the motor and kicker driver, on message): turns each [`MotorCommand`] into
//!    wheel duty cycles (the AIRBoard's processing side, [`Base::duties`]) and kicks;
//! 6. **`FaultBook`** (on message): books the behavior Member's script errors against the
//!    robot. A Member that fails to start, fails or panics is restarted by its executor and
//!    listed by [`member_faults`] when the robot stops.
//!
//! Body adaptation is the [`Commander`]'s: on the Chaos robots `WorldState` measures distances
//! from the robot's edge and `Guide` scales the behaviors' AIBO-sized set-points before
//! guiding them.

use crate::base::Base;
use crate::brain::BrainMember;
use crate::commander::Commander;
use crate::config::RobotConfig;
use crate::devices::{DeviceError, Devices, SharedDevices};
use crate::files::FilesDir;
use crate::isocrob::IsocrobBrain;
use crate::look_around::LookAround;
use crate::planner::{carrot, plans_for, same_goal, Planner, REPLAN};
use crate::stacks::{
    embedded_teamchaos, send_brain, Geometry, MilanBrain, Stack, CHAOS_KEEPER, CHAOS_PLAYER,
};
use mrt_blackboard::{Blackboard, Proxy};
use mrt_core::{Point2, Pose2};
use mrt_dcdt::{Activation, Agora, Context, Member, MemberError, Message, RequestType, RunReport};
use mrt_msgs::robot::{lps, Lpo};
use mrt_msgs::{
    BehaviorStatus, BookingReport, CameraFrame, GameInfo, GameState, MateReport, MemberFault,
    MotorCommand, Odometry, Percepts, RobotCommand, Sonar, SonarScan, WorldSnapshot,
};
use mrt_msgs::{PlanRequest, PlannedPath, Target};
use mrt_perception::vision::agent::VisionAgent;
use mrt_plan::guide::Guidance;
use mrt_script::member::BehaviorMember;
use mrt_team::booking::{BallBooking, BookingParams};
use mrt_team::isocrob::Role as IsocrobRole;
use mrt_team::roles::{allocate, Player, Role};
use mrt_team::scare::soccer::{Coordinator, Situation};

/// A team ball of at least this quality is known to the role allocation (the Lua players'
/// `ballKnown`).
const BALL_KNOWN: f64 = 0.2;
use mrt_world::gaze::Gaze;
use mrt_world::{merge_team, WorldModel};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::MutexGuard;

fn lock(d: &SharedDevices) -> Result<MutexGuard<'_, dyn Devices + 'static>, MemberError> {
    d.lock().map_err(|_| MemberError::from("the devices lock is poisoned"))
}

/// A driver Member (MRT manual §2.1: drivers apart from processing): each cycle it reads one
/// of the robot's devices and publishes what it read. The odometry, camera, game-controller and
/// sonar drivers are this one Member with a different reading.
pub(crate) struct Driver<M> {
    /// `odometry`, `camera`, `sonars`: the Member is named `<kind>-<robot>`.
    pub(crate) kind: &'static str,
    pub(crate) robot: usize,
    pub(crate) devices: SharedDevices,
    pub(crate) read: fn(&mut dyn Devices) -> Result<M, DeviceError>,
}

impl<M: Message> Member for Driver<M> {
    fn name(&self) -> String {
        format!("{}-{}", self.kind, self.robot)
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let reading = (self.read)(&mut *lock(&self.devices)?)?;
        ctx.publish(reading);
        Ok(())
    }
}

/// The world-state Member of one robot: odometry and camera frames into its [`WorldModel`],
/// teammates from their reports over the bus; publishes the [`WorldSnapshot`] and its own
/// [`MateReport`].
struct WorldState {
    robot: usize,
    keeper: bool,
    body: Commander,
    model: WorldModel,
    mates: BTreeMap<u32, MateReport>,
    /// The team's ball booking (TeamChaos seed `001` §3.3, [`mrt_team::booking`]): fed by the
    /// behaviors' `bookBall`/`releaseBookedBall` and the teammates' reports.
    booking: BallBooking,
    /// Teammates' booking reports received since the last frame.
    booking_news: Vec<(u32, BookingReport)>,
    /// The behaviors' latest `bookBall` (true) or `releaseBookedBall` (false) not yet applied.
    book: Option<bool>,
    /// The role the team agreed on at the last frame ([`mrt_team::roles`], `getRole`).
    role: Role,
    /// SCARE (MRT manual ch. 11, [`mrt_team::scare`]): the activity the team gives this
    /// robot, its sub-task and goal, into the snapshot's `job` for Team Milan's parametric
    /// behaviors (Team Milan only).
    scare: Option<Coordinator>,
}

impl Member for WorldState {
    fn name(&self) -> String {
        format!("world-state-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Odometry>(RequestType::Local);
        ctx.subscribe_to::<CameraFrame>(RequestType::Local);
        ctx.subscribe_to::<Percepts>(RequestType::Local);
        ctx.subscribe_to::<GameInfo>(RequestType::Local);
        ctx.subscribe_to::<SonarScan>(RequestType::Local);
        ctx.subscribe_to::<MateReport>(RequestType::Remote);
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut frame = None;
        while let Some(m) = ctx.receive_msg() {
            if let Ok(o) = m.get::<Odometry>() {
                self.model.odometry(o);
            } else if let Ok(f) = m.get::<CameraFrame>() {
                // A frame with an image is the vision µAgent's to read; its percepts follow.
                if f.image.is_none() {
                    frame = Some(m);
                }
            } else if m.is::<Percepts>() {
                frame = Some(m);
            } else if let Ok(g) = m.get::<GameInfo>() {
                self.model.game(*g);
            } else if let Ok(scan) = m.get::<SonarScan>() {
                // Read with the next frame (MAP's merger: echoes of robots out of view).
                self.model.sonars(scan);
            } else if let Ok(c) = m.get::<RobotCommand>() {
                self.book = c.book_ball.or(self.book);
            } else {
                let r = m.get::<MateReport>()?;
                self.booking_news.push((r.id, r.booking.clone()));
                self.mates.insert(r.id, r.clone());
            }
        }
        let Some(frame) = frame else { return Ok(()) };
        let mut w = match frame.get::<Percepts>() {
            Ok(p) => self.model.percepts(p),
            Err(_) => self.model.camera(frame.get::<CameraFrame>()?),
        };
        let id = u32::try_from(self.robot).unwrap_or(u32::MAX);
        // The ball's uncertainty in mm, as the reports and the team ball count it.
        let ball_sigma = self.model.ball_sigma().map(|s| s * 1000.0);
        let mut report =
            MateReport::of(id, self.keeper, &w).with_ball_sigma(ball_sigma.unwrap_or(0.0));
        // The ball booking on this frame's clock: the news, the behaviors' wish, the report.
        let now = w.time.as_secs_f64();
        for (from, b) in self.booking_news.drain(..) {
            self.booking.receive(now, from, &b);
        }
        if let Some(yes) = self.book.take() {
            self.booking.want(now, yes);
        }
        self.booking.update(now);
        report.booking = self.booking.report(now);
        w.ball_booked = self.booking.holds(now);
        // Teammates and their ball as the bus told them, not as the simulator knows them.
        merge_team(&mut w, ball_sigma, self.mates.values());
        // The roles, from the teammates heard lately (within the booking's `silent`: the
        // booking already keeps when each was last heard) and the team ball.
        let me = Player {
            id,
            at: (w.my_pos.pose.x, w.my_pos.pose.y),
            keeper: self.keeper,
            said: self.role,
        };
        let heard: Vec<&MateReport> =
            self.mates.values().filter(|r| self.booking.hears(r.id, now) && r.id != id).collect();
        let players: Vec<Player> = std::iter::once(me)
            .chain(heard.iter().map(|r| Player {
                id: r.id,
                at: (r.pose.pose.x, r.pose.pose.y),
                keeper: r.keeper,
                said: Role::from_name(&r.role).unwrap_or(Role::Defender),
            }))
            .collect();
        let ball = (w.global_ball.quality > BALL_KNOWN)
            .then_some((w.global_ball.pose.x, w.global_ball.pose.y));
        self.role = allocate(&players, ball).first().map_or(self.role, |r| r.1);
        report.role = self.role.name().to_string();
        w.role = self.role.name().to_string();
        // SCARE, on the same teammates and team ball.
        if let Some(scare) = &mut self.scare {
            let sit = situation(&w, self.keeper, ball, &heard);
            let shot = Geometry::of(&w.field).open_side(&w);
            let reports: Vec<_> = heard.iter().map(|r| (r.id, &r.scare)).collect();
            let cycle = scare.cycle(now, &sit, &reports, shot);
            report.scare = cycle.report;
            w.job = Some(cycle.job);
        }
        ctx.publish(report);
        ctx.publish(self.model.localization());
        self.body.perceive(&mut w);
        ctx.publish(w);
        Ok(())
    }
}

/// What SCARE's soccer activities read of a robot's beliefs: its pose, the team ball when
/// known, the teammates heard lately, the robots it anchored as opponents (or of unknown
/// team), the field.
fn situation(
    w: &WorldSnapshot,
    keeper: bool,
    ball: Option<(f64, f64)>,
    heard: &[&MateReport],
) -> Situation {
    Situation {
        me: (w.my_pos.pose.x, w.my_pos.pose.y, w.my_pos.pose.theta),
        keeper,
        ball,
        mates: heard.iter().map(|r| (r.id, (r.pose.pose.x, r.pose.pose.y), r.keeper)).collect(),
        opponents: w.opponents(WorldSnapshot::ANCHORED).map(|r| (r.x, r.y)).collect(),
        half_length: w.field.half_length,
        goal_half_width: w.field.goal_half_width,
    }
}

/// The vision µAgent of one robot (ISocRob seed `003` §3.2.1): the camera's latest image into
/// [`Percepts`]. An image the camera's geometry does not fit is counted, logged once, and
/// dropped.
struct Vision {
    robot: usize,
    agent: VisionAgent,
    refused: u64,
}

impl Member for Vision {
    fn name(&self) -> String {
        format!("vision-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<CameraFrame>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut latest = None;
        while let Some(m) = ctx.receive_msg() {
            if m.get::<CameraFrame>().is_ok_and(|f| f.image.is_some()) {
                latest = Some(m);
            }
        }
        let Some(m) = latest else { return Ok(()) };
        let frame = m.get::<CameraFrame>()?;
        let Some(image) = &frame.image else { return Ok(()) };
        // Where the pan joint was when the frame was taken (the gaze control turns it), or,
        // for a camera without a joint, where its camera file puts it.
        let pan = frame.pan.unwrap_or(self.agent.camera().pan);
        match self.agent.see_with_up(image, frame.up_image.as_ref(), frame.time, pan) {
            Ok(p) => {
                ctx.publish(p);
            }
            Err(e) => {
                self.refused += 1;
                if self.refused == 1 {
                    tracing::warn!(robot = self.robot, "vision: {e} (further ones are counted)");
                }
            }
        }
        Ok(())
    }
}

/// The PAM's gaze control of one robot (TeamChaos seed `001` §2.1, [`mrt_world::gaze`]): each
/// cycle, the behaviors' latest perceptual needs (with `trackLandMarks`, the least recently seen
/// landmark or net) and the latest LPS choose the object to look at, and the camera's pan joint
/// is turned towards it. A joint that refuses is counted and
/// logged once; the robot plays on with its camera where it is.
struct GazeControl {
    robot: usize,
    devices: SharedDevices,
    gaze: Gaze,
    period: f64,
    needs: Vec<(usize, f64)>,
    track_landmarks: bool,
    lps: Vec<Lpo>,
    refused: u64,
}

impl Member for GazeControl {
    fn name(&self) -> String {
        format!("gaze-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if let Ok(c) = m.get::<RobotCommand>() {
                self.needs.clone_from(&c.needs);
                self.track_landmarks = c.track_landmarks;
            } else {
                self.lps.clone_from(&m.get::<WorldSnapshot>()?.lps);
            }
        }
        // The behaviors' needs stand until their next command; `trackLandMarks` adds one
        // landmark, the least recently seen, as needed as what they need most (this cycle).
        let mut needs = self.needs.clone();
        if self.track_landmarks {
            let need = needs.iter().map(|n| n.1).fold(0.0, f64::max);
            let need = if need > 0.0 { need } else { 1.0 };
            let slots: [usize; lps::COUNT - lps::NET1] = std::array::from_fn(|i| lps::NET1 + i);
            needs.extend(self.gaze.landmark_need(&slots, need, &self.lps));
        }
        let aim = self.gaze.step(&needs, &self.lps, self.period);
        if let Err(e) = lock(&self.devices)?.set_pan(aim.pan) {
            self.refused += 1;
            if self.refused == 1 {
                tracing::warn!(robot = self.robot, "gaze: {e} (further ones are counted)");
            }
        }
        Ok(())
    }
}

/// Guidance of one robot: the behaviors' command through the Guidance µAgent with the latest
/// world state and sonar scan.
struct Guide {
    robot: usize,
    guidance: Guidance,
    world: WorldSnapshot,
    scan: SonarScan,
    /// The planner's latest path, and when it came (s, the world's clock).
    path: Option<(PlannedPath, f64)>,
    /// The goal last asked of the planner, and when.
    asked: Option<(Pose2, f64)>,
    /// Turning to look for landmarks when the world model needs to localize, on a robot
    /// whose camera cannot pan (`None` with a pan joint: the gaze looks instead).
    look: Option<LookAround>,
}

impl Guide {
    /// A target to reach along a planned path (`plan`): the planner is asked when its path
    /// is for another goal or a second old; meanwhile the command drives to the path's
    /// carrot in position mode, or, before any path, as the target says without planning.
    fn follow(&mut self, cmd: &mut RobotCommand, ctx: &mut Context<'_>) {
        let Some(target) = cmd.target.filter(|t| t.plan) else { return };
        let now = self.world.time.as_secs_f64();
        let to = target.pose;
        let current = self.path.as_ref().filter(|(p, _)| plans_for(p, to));
        let stale = current.is_none_or(|(_, at)| now - at >= REPLAN);
        let waiting =
            self.asked.is_some_and(|(goal, at)| same_goal(goal, to) && now - at < REPLAN / 2.0);
        if stale && !waiting {
            ctx.publish(PlanRequest { to });
            self.asked = Some((to, now));
        }
        let next = current.and_then(|(p, _)| carrot(&p.poses, self.world.my_pos.pose));
        cmd.target = Some(match next {
            Some(pose) => Target { pose, avoid: false, plan: false },
            None => Target { plan: false, ..target },
        });
    }
}

impl Member for Guide {
    fn name(&self) -> String {
        format!("guide-{}", self.robot)
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::Local);
        ctx.subscribe_to::<WorldSnapshot>(RequestType::Local);
        ctx.subscribe_to::<SonarScan>(RequestType::Local);
        ctx.subscribe_to::<PlannedPath>(RequestType::Local);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut last = None;
        while let Some(m) = ctx.receive_msg() {
            if let Ok(c) = m.get::<RobotCommand>() {
                last = Some(c.clone());
            } else if let Ok(w) = m.get::<WorldSnapshot>() {
                self.world.clone_from(w);
            } else if let Ok(p) = m.get::<PlannedPath>() {
                self.path = Some((p.clone(), self.world.time.as_secs_f64()));
            } else {
                self.scan.clone_from(m.get::<SonarScan>()?);
            }
        }
        if let Some(mut cmd) = last {
            let now = self.world.time.as_secs_f64();
            let (needs, played) =
                (self.world.needs_localization, self.world.game_state == GameState::Playing);
            if let Some(rate) = self.look.as_mut().and_then(|l| l.step(now, needs, played)) {
                cmd = RobotCommand { vrot: rate.to_degrees(), ..RobotCommand::default() };
            }
            let planned = cmd.target.is_some_and(|t| t.plan);
            self.follow(&mut cmd, ctx);
            let mut out = guide(&self.guidance, &cmd, &self.world, &self.scan.sonars);
            if planned {
                // Position mode along the path, halted by the sonars as velocity mode is.
                out = guide(&self.guidance, &out, &self.world, &self.scan.sonars);
            }
            ctx.publish(MotorCommand(out));
        }
        Ok(())
    }
}

/// The motor and kicker driver of one robot: commands become duty cycles for its motor
/// driver (the processing side of the AIRBoard), kick requests fire the kicker.
pub(crate) struct Motor {
    pub(crate) devices: SharedDevices,
    pub(crate) robot: usize,
    pub(crate) base: Base,
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

/// One robot of a match: which robot it is (0 .. 2 × team size: home, then away), whether it
/// keeps goal and which behavior stack drives it. Its Agora's id is `robot + 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RobotSpec {
    /// The robot.
    pub robot: usize,
    /// Keeps goal (robot 0 of each team).
    pub keeper: bool,
    /// Its number within its team (0: the goalkeeper).
    pub mate: usize,
    /// What drives it.
    pub stack: Stack,
}

impl RobotSpec {
    /// Robot `robot` of a match with `team_size` robots a side, the home team playing `home`
    /// and the away team `away`.
    pub fn of(robot: usize, team_size: usize, (home, away): (Stack, Stack)) -> RobotSpec {
        let n = team_size.max(1);
        RobotSpec {
            robot,
            keeper: robot % n == 0,
            mate: robot % n,
            stack: if robot < n { home } else { away },
        }
    }

    /// The id of the robot's Agora.
    pub fn agora_id(&self) -> Result<u32, String> {
        u32::try_from(self.robot + 1).map_err(|e| e.to_string())
    }
}

/// Puts one robot's Members into `agora`, activated: the drivers of its `devices`, its world
/// state, its behaviors (the stack of `spec`: the TeamChaos files of `behaviors` for the Chaos
/// stack), guidance, motor and fault book (module doc). The same robot code runs on a pitch
/// in this process (`mrt_sim::bus::BusMatch`), on a simulator in another one
/// ([`crate::remote::RemoteRobot`]) and on a real robot's devices.
pub fn add_robot(
    agora: &mut Agora,
    cfg: &RobotConfig,
    spec: &RobotSpec,
    behaviors: &Path,
    devices: SharedDevices,
) -> Result<(), String> {
    let RobotSpec { robot, keeper, mate, stack } = *spec;
    let (behavior, commander): (Box<dyn Member>, _) = match stack {
        Stack::Isocrob => {
            // The robot's blackboard, shared with its teammates' through the Proxy.
            let id = spec.agora_id()?;
            let bb = Blackboard::new(id, agora.clock().clone());
            let role = match mate {
                0 if keeper => IsocrobRole::Goalkeeper,
                1 => IsocrobRole::Defender,
                _ => IsocrobRole::Attacker,
            };
            let brain = IsocrobBrain::new(id, role, mate, bb.clone())?;
            // A team's own `config.dat` and `config-<robot>.dat` beside the built-in one (the
            // seed's way to configure robot by robot), when the behaviors directory has them.
            if !behaviors.as_os_str().is_empty() {
                mrt_blackboard::config::load_dir(&bb, behaviors).map_err(|e| e.to_string())?;
            }
            let proxy = agora.add_member(Proxy::new(bb), Activation::Periodic(cfg.period()));
            agora.activate_member(proxy).map_err(|e| e.to_string())?;
            (Box::new(BrainMember::new(Box::new(brain))) as Box<dyn Member>, Commander::PLAIN)
        }
        Stack::Chaos => (behavior_member(stack, keeper, Some(behaviors))?, Commander::chaos(cfg)),
        // The directory is TeamChaos': the other stacks run their compiled-in behaviors.
        other => (behavior_member(other, keeper, None)?, Commander::PLAIN),
    };
    // Team Milan's parametric behaviors read SCARE's job (MRT manual ch. 11); the others
    // coordinate their own way (TeamChaos: booking and roles).
    let scare = stack == Stack::Milan;
    add_cycle(agora, cfg, (robot, keeper, scare), behavior, commander, devices)
}

/// The behavior Member of a robot of `stack` (the goalkeeper when `keeper`): for Chaos, the
/// TeamChaos files of `behaviors` (the HBM goalkeeper or the HFSM field player; they are
/// required); for Milan, the Mr. BRIAN configuration of `behaviors`, or the compiled-in one
/// without; the Chaser's hand-written player. An ISocRob robot needs its blackboard and Proxy
/// ([`add_robot`] builds them).
pub fn behavior_member(
    stack: Stack,
    keeper: bool,
    behaviors: Option<&Path>,
) -> Result<Box<dyn Member>, String> {
    Ok(match (stack, behaviors) {
        (Stack::Chaos, Some(dir)) if keeper => Box::new(BehaviorMember::hbm(dir, CHAOS_KEEPER)),
        (Stack::Chaos, Some(dir)) => Box::new(BehaviorMember::hfsm(dir, dir.join(CHAOS_PLAYER))),
        (Stack::Chaos, None) => return Err("a Chaos robot needs its TeamChaos files".into()),
        (Stack::Milan, Some(dir)) => {
            Box::new(BrainMember::new(Box::new(MilanBrain::new(dir, keeper)?)))
        }
        (other, _) => Box::new(BrainMember::new(send_brain(other, keeper)?)),
    })
}

/// [`add_robot`] with any `Send` [`Brain`](crate::brain::Brain) as the behaviors (a team's
/// own Rust behaviors, a test's scripted player): the brain adapts itself to the body (its
/// Commander is [`Commander::PLAIN`]); its faults are booked by the fault book.
pub fn add_robot_with_brain(
    agora: &mut Agora,
    cfg: &RobotConfig,
    (robot, keeper): (usize, bool),
    brain: Box<dyn crate::brain::Brain + Send>,
    devices: SharedDevices,
) -> Result<(), String> {
    let behavior = Box::new(BrainMember::new(brain));
    add_cycle(agora, cfg, (robot, keeper, false), behavior, Commander::PLAIN, devices)
}

/// **The robot cycle**, defined once: the Members of robot `robot` in their order, each with
/// its activation (module doc). Every wiring runs it: the simulator's in-process match, its
/// distributed match and `mrt robot` on a real robot's devices. With `scare`, the world
/// state runs SCARE and puts the robot's job in its snapshots.
fn add_cycle(
    agora: &mut Agora,
    cfg: &RobotConfig,
    (robot, keeper, scare): (usize, bool, bool),
    behavior: Box<dyn Member>,
    commander: Commander,
    devices: SharedDevices,
) -> Result<(), String> {
    let every = Activation::Periodic(cfg.period());
    let dev = || devices.clone();
    let odometry: Driver<Odometry> =
        Driver { kind: "odometry", robot, devices: dev(), read: |d| d.odometry() };
    let camera: Driver<CameraFrame> =
        Driver { kind: "camera", robot, devices: dev(), read: |d| d.camera() };
    let game: Driver<GameInfo> =
        Driver { kind: "game-controller", robot, devices: dev(), read: |d| d.game() };
    let sonars: Driver<SonarScan> = Driver {
        kind: "sonars",
        robot,
        devices: dev(),
        read: |d| d.sonars().map(|sonars| SonarScan { sonars }),
    };
    let world = WorldState {
        robot,
        keeper,
        body: commander,
        model: cfg.world_model(),
        mates: BTreeMap::new(),
        booking: BallBooking::new(
            u32::try_from(robot).unwrap_or(u32::MAX),
            BookingParams::default(),
        ),
        booking_news: Vec::new(),
        book: None,
        role: if keeper { Role::Goalkeeper } else { Role::Defender },
        scare: scare.then(|| Coordinator::new(u32::try_from(robot).unwrap_or(u32::MAX))),
    };
    let guide = Guide {
        robot,
        guidance: cfg.guidance,
        world: WorldSnapshot::default(),
        scan: SonarScan::default(),
        path: None,
        asked: None,
        look: cfg.gaze.is_none().then(LookAround::default),
    };
    let mut ids = vec![agora.add_member(odometry, every), agora.add_member(camera, every)];
    if let Some(v) = &cfg.vision {
        let mut agent = VisionAgent::new(v.camera, &v.colors, cfg.ball_radius)
            .post_shape(v.posts)
            .goal_width(cfg.field.goal_width);
        if let Some(up) = v.up_camera {
            agent = agent.up_camera(up);
        }
        ids.push(agora.add_member(Vision { robot, agent, refused: 0 }, every));
    }
    ids.extend([
        agora.add_member(game, every),
        // The sonars before the world state, which reads their echoes with this cycle's frame
        // (still after the camera: the simulator's sensors draw in the order odometry,
        // camera, sonars).
        agora.add_member(sonars, every),
        agora.add_member(world, every),
        agora.add_boxed_member(behavior, every),
    ]);
    if let Some(g) = cfg.gaze {
        let gaze = GazeControl {
            robot,
            devices: dev(),
            gaze: Gaze::new(g),
            period: cfg.control_period,
            needs: Vec::new(),
            track_landmarks: false,
            lps: Vec::new(),
            refused: 0,
        };
        ids.push(agora.add_member(gaze, every));
    }
    ids.extend([
        agora.add_member(Planner::new(robot, cfg.radius), Activation::OnMessage),
        agora.add_member(guide, Activation::OnMessage),
        agora.add_member(Motor { devices: dev(), robot, base: cfg.base }, Activation::OnMessage),
        agora.add_member(FaultBook { devices, robot }, Activation::OnMessage),
    ]);
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

/// Guidance for one robot's cycle: the behaviors' command `cmd`, the world state the robot
/// believes (its pose, the ball where it is known) and its sonar ring.
pub fn guide(
    g: &Guidance,
    cmd: &RobotCommand,
    w: &WorldSnapshot,
    sonars: &[Sonar],
) -> RobotCommand {
    let ball = w.global_ball;
    let ball = (ball.quality >= 0.1).then(|| Point2::new(ball.pose.x, ball.pose.y));
    g.guide(cmd, &w.my_pos.pose, ball, sonars).command
}
