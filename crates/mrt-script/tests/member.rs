//! The behavior Members on the bus: a world publisher, the Attacker HFSM Member and a motor
//! that records the commands, on the deterministic stepped executor.

#![allow(clippy::unwrap_used)]

use mrt_core::SimClock;
use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType, SteppedExecutor};
use mrt_msgs::robot::{lps, Lpo, RobotCommand, WorldSnapshot};
use mrt_script::member::{BehaviorMember, BehaviorStatus, DEFAULT_PERIOD};
use std::sync::{Arc, Mutex};
use std::time::Duration;

const DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../behaviors/teamchaos");

/// Publishes a world with the ball 2 m away, straight ahead, then at the side from 1 s on.
struct World;
impl Member for World {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut w = WorldSnapshot { time: ctx.now(), ..Default::default() };
        let theta = if ctx.now().as_secs_f64() < 1.0 { 0.0 } else { 1.2 };
        w.lps[lps::BALL] = Lpo { rho: 2.0, theta, reliability: 0.9, seen_ago: 0.0 };
        ctx.publish(w);
        Ok(())
    }
}

type Log = Arc<Mutex<Vec<(RobotCommand, BehaviorStatus)>>>;

/// Records each command with the status published next to it.
struct Motor(Log, Option<RobotCommand>);
impl Member for Motor {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<RobotCommand>(RequestType::All);
        ctx.subscribe_to::<BehaviorStatus>(RequestType::All);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if let Ok(c) = m.get::<RobotCommand>() {
                self.1 = Some(c.clone());
            } else if let (Ok(s), Some(c)) = (m.get::<BehaviorStatus>(), self.1.take()) {
                self.0.lock().map_err(|_| "poisoned")?.push((c, s.clone()));
            }
        }
        Ok(())
    }
}

#[test]
fn the_attacker_member_reads_the_world_and_drives_the_motor() {
    let log: Log = Arc::default();
    let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(10));
    let mut robot = exec.agora_builder(1).build().unwrap();
    let attacker = BehaviorMember::hfsm(DIR, format!("{DIR}/attacker.hfsm.lua"));
    let ids = [
        robot.add_member(World, Activation::Periodic(Duration::from_millis(50))),
        robot.add_member(attacker, Activation::Periodic(DEFAULT_PERIOD)),
        robot.add_member(Motor(log.clone(), None), Activation::OnMessage),
    ];
    for id in ids {
        robot.activate_member(id).unwrap();
    }
    exec.add_agora(robot).unwrap();
    exec.run_for(Duration::from_millis(2000));
    exec.finish();
    let log = log.lock().unwrap();
    assert!(log.len() >= 15, "about one command per 100 ms: {}", log.len());
    assert!(log.iter().all(|(_, s)| s.errors.is_empty()), "{:?}", log.last());
    // Ball ahead: the attacker walks to it; ball at the side (1.2 rad > 0.8): it faces it again.
    let at = |path: &str| log.iter().position(|(_, s)| s.path == path);
    let going = at("Attacker/GoToBall").unwrap();
    assert!(log[going + 1].0.vlin() > 100.0, "{:?}", log[going + 1]);
    let facing = log.iter().rposition(|(_, s)| s.path == "Attacker/FaceBall").unwrap();
    assert!(facing > going);
    assert!(log[facing].0.vrot() > 0.0, "ball on the left: turn left, {:?}", log[facing].0);
}

#[test]
fn a_member_whose_files_do_not_load_fails_init_without_stopping_the_others() {
    let log: Log = Arc::default();
    let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(10));
    let mut robot = exec.agora_builder(1).build().unwrap();
    let broken = BehaviorMember::hbm(DIR, "no-such-behavior");
    let ids = [
        robot.add_member(World, Activation::Periodic(Duration::from_millis(50))),
        robot.add_member(broken, Activation::Periodic(DEFAULT_PERIOD)),
        robot
            .add_member(BehaviorMember::hbm(DIR, "faceball"), Activation::Periodic(DEFAULT_PERIOD)),
        robot.add_member(Motor(log.clone(), None), Activation::OnMessage),
    ];
    for id in ids {
        robot.activate_member(id).unwrap();
    }
    exec.add_agora(robot).unwrap();
    exec.run_for(Duration::from_millis(500));
    let report = exec.finish();
    assert!(!log.lock().unwrap().is_empty(), "faceball kept running");
    assert!(format!("{report:?}").contains("no-such-behavior"), "{report:?}");
}

/// Collects the HFSM shapes published (`HfsmStructure`), with their time.
struct Shapes(Arc<Mutex<Vec<(f64, mrt_msgs::HfsmStructure)>>>);
impl Member for Shapes {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<mrt_msgs::HfsmStructure>(RequestType::All);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let s = m.get::<mrt_msgs::HfsmStructure>()?.clone();
            self.0.lock().map_err(|_| "poisoned")?.push((m.creation_time().as_secs_f64(), s));
        }
        Ok(())
    }
}

/// The HFSM Member tells its machine's shape for monitors (ThinkingCap/TeamChaos report §4.1, §5.1) in its first
/// cycle and then every `STRUCTURE_EVERY` cycles, not every cycle.
#[test]
fn the_hfsm_member_tells_its_shape_rarely() {
    let shapes = Arc::default();
    let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(10));
    let mut robot = exec.agora_builder(1).build().unwrap();
    let attacker = BehaviorMember::hfsm(DIR, format!("{DIR}/attacker.hfsm.lua"));
    let ids = [
        robot.add_member(World, Activation::Periodic(Duration::from_millis(50))),
        robot.add_member(attacker, Activation::Periodic(DEFAULT_PERIOD)),
        robot.add_member(Shapes(Arc::clone(&shapes)), Activation::OnMessage),
    ];
    for id in ids {
        robot.activate_member(id).unwrap();
    }
    exec.add_agora(robot).unwrap();
    exec.run_for(Duration::from_millis(12_000));
    exec.finish();
    let shapes = shapes.lock().unwrap();
    assert_eq!(
        shapes.len(),
        2,
        "at the start and 10 s later: {:?}",
        shapes.iter().map(|s| s.0).collect::<Vec<_>>()
    );
    let s = &shapes[0].1;
    assert_eq!(s.root, "Attacker");
    let states: Vec<&str> = s.machines[0].states.iter().map(|st| st.name.as_str()).collect();
    assert!(states.contains(&"GoToBall") && states.contains(&"FaceBall"), "{states:?}");
    assert_eq!(shapes[1].1, *s);
}
