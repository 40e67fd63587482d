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
//!    [`vision`](RobotConfig::vision)): the vision µAgent (ISocRob-2000 report §3.2.1) turns
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
//!    [`gaze`](RobotConfig::gaze)): the PAM's camera control (ThinkingCap/TeamChaos report §2.1) turns the
//!    camera's pan joint to the object the behaviors need most ([`Devices::set_pan`]);
//! 4. **`planner-<n>`** (SPIKE, MRT manual ch. 9, on message): plans a path for each
//!    [`PlanRequest`] round the robots the world model anchored ([`crate::planner`]);
//! 4. **`guide-<n>`** (`GuidanceMember`; guidance, ISocRob §3.2.3, on message): turns the behaviors'
//!    [`RobotCommand`] into a [`MotorCommand`] with [`mrt_plan::guidance::Guidance`]: velocity
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
//! from the robot's edge (the team's `hbm.lua` scales its speeds).

use crate::base::Base;
use crate::brain::BrainMember;
use crate::commander::Commander;
use crate::config::RobotConfig;
use crate::devices::{DeviceError, Devices, SharedDevices};
use crate::error::RobotError;
use crate::files::FilesDir;
use crate::isocrob::IsocrobBrain;
use crate::look_around::LookAround;
use crate::planner::{carrot, plans_for, same_goal, Planner, REPLAN};
use crate::spec::{RobotSpec, Stack};
use crate::stacks::{
    embedded_teamchaos, send_brain, Geometry, MilanBrain, CHAOS_KEEPER, CHAOS_PLAYER,
};
use mrt_blackboard::{Blackboard, Proxy};
use mrt_core::Pose2;
use mrt_dcdt::{
    Activation, Agora, Context, Inputs, Member, MemberError, Message, MsgRef, RequestType,
    RunReport,
};
use mrt_msgs::robot::{lps, Lpo};
use mrt_msgs::{
    BehaviorStatus, BookingReport, CameraFrame, GameInfo, GameState, MateReport, MemberFault,
    MotorCommand, Odometry, Percepts, RobotCommand, SonarScan, WorldSnapshot,
};
use mrt_msgs::{PlanRequest, PlannedPath, Target};
use mrt_perception::vision::agent::VisionAgent;
use mrt_plan::guidance::Guidance;
use mrt_script::member::BehaviorMember;
use mrt_team::booking::{BallBooking, BookingParams};
use mrt_team::isocrob::Role as IsocrobRole;
use mrt_team::roles::{allocate, Player, Role};
use mrt_team::scare::soccer::{Coordinator, Situation};

use mrt_world::gaze::Gaze;
use mrt_world::{merge_team, WorldModel};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::MutexGuard;

fn lock(d: &SharedDevices) -> Result<MutexGuard<'_, dyn Devices + 'static>, MemberError> {
    d.lock().map_err(|_| MemberError::from("the devices lock is poisoned"))
}

mod driver;
mod fault_book;
mod gaze;
mod guidance;
mod motor;
mod vision;
mod world_state;

pub(crate) use driver::Driver;
use fault_book::FaultBook;
use gaze::GazeControl;
use guidance::GuidanceMember;
pub(crate) use motor::Motor;
use vision::Vision;
use world_state::WorldState;

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
) -> Result<(), RobotError> {
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
                mrt_blackboard::config::load_dir(&bb, behaviors)?;
            }
            let proxy = agora.add_member(Proxy::new(bb), Activation::Periodic(cfg.period()));
            agora.activate_member(proxy)?;
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
) -> Result<Box<dyn Member>, RobotError> {
    Ok(match (stack, behaviors) {
        (Stack::Chaos, Some(dir)) if keeper => Box::new(BehaviorMember::hbm(dir, CHAOS_KEEPER)),
        (Stack::Chaos, Some(dir)) => Box::new(BehaviorMember::hfsm(dir, dir.join(CHAOS_PLAYER))),
        (Stack::Chaos, None) => {
            return Err(RobotError::StackWiring("a Chaos robot needs its TeamChaos files"))
        }
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
) -> Result<(), RobotError> {
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
) -> Result<(), RobotError> {
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
        frame: None,
        inputs: WorldState::inputs(),
    };
    let guide = GuidanceMember {
        robot,
        guidance: cfg.guidance,
        world: WorldSnapshot::default(),
        scan: SonarScan::default(),
        path: None,
        asked: None,
        look: cfg.gaze.is_none().then(LookAround::default),
        command: None,
        inputs: GuidanceMember::inputs(),
    };
    let mut ids = vec![agora.add_member(odometry, every), agora.add_member(camera, every)];
    if let Some(v) = &cfg.vision {
        let mut agent = VisionAgent::new(v.camera, &v.colors, cfg.ball_radius)
            .post_shape(v.posts)
            .goal_width(cfg.field.goal_width);
        if let Some(up) = v.up_camera {
            agent = agent.up_camera(up);
        }
        ids.push(agora.add_member(Vision::new(robot, agent), every));
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
            inputs: GazeControl::inputs(),
        };
        ids.push(agora.add_member(gaze, every));
    }
    ids.extend([
        agora.add_member(Planner::new(robot, cfg.radius), Activation::OnMessage),
        agora.add_member(guide, Activation::OnMessage),
        agora.add_member(Motor::new(dev(), robot, cfg.base), Activation::OnMessage),
        agora.add_member(FaultBook::new(devices, robot), Activation::OnMessage),
    ]);
    for m in ids {
        agora.activate_member(m)?;
    }
    Ok(())
}

/// The TeamChaos files robots of `stacks` run: `behaviors`, or the compiled-in ones when the
/// Chaos stack plays (nothing otherwise).
/// Keep the handle while the robots may read them: compiled-in files are removed with it.
pub fn behaviors_dir(stacks: &[Stack], behaviors: Option<&Path>) -> Result<FilesDir, RobotError> {
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
