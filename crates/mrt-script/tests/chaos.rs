//! The `chaos.*` robot API (ThinkingCap report §3.3) and the report's `lookball` behavior
//! (§4.3). The snapshot is in metres; the scripts read millimetres.

#![allow(clippy::unwrap_used)]

use mrt_core::frames::{twist_from_setpoints, Framed};
use mrt_core::{Pose2, Time};
use mrt_msgs::robot::{lps, Estimate, GameState, Lpo, Mate, WorldSnapshot};
use mrt_script::chaos::{install, GlobalValue, RobotIo};
use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError};
use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

fn setup() -> (LuaRuntime, Rc<RefCell<RobotIo>>) {
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    (rt, io)
}

fn world_with_ball(theta: f64, t_ms: u64) -> WorldSnapshot {
    let mut w = WorldSnapshot { time: Time::from_millis(t_ms), ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: 0.4, theta, reliability: 0.9, seen_ago: 0.0 };
    w
}

#[test]
fn lookball_turns_towards_where_the_ball_was_and_speeds_up_after_400_ms() {
    let (rt, io) = setup();
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../behaviors/teamchaos/lookball.lua");
    let s = Script::from_file(&rt, &path, LoadStrategy::Compiled).unwrap();
    // First tick: the ball was last seen to the right (theta < 0): turn right, slowly.
    io.borrow_mut().begin_cycle(world_with_ball(-0.5, 1000), "lookball");
    s.call::<()>(&rt).unwrap();
    {
        let io = io.borrow();
        assert_eq!((io.command.vlin(), io.command.vrot(), io.command.vlat()), (0.0, -50.0, 0.0));
        assert_eq!(io.command.need(lps::BALL), 1.0);
        assert_eq!(io.global("BALL_DIRECTION"), Some(&GlobalValue::Integer(-1)));
    }
    // 300 ms later, still the same behavior: the direction stays (the ball is now to the left,
    // but isNew is 0, so the stored direction is used), still slow.
    io.borrow_mut().begin_cycle(world_with_ball(0.8, 1300), "lookball");
    s.call::<()>(&rt).unwrap();
    assert_eq!(io.borrow().command.vrot(), -50.0);
    // 500 ms after it started: faster.
    io.borrow_mut().begin_cycle(world_with_ball(0.8, 1500), "lookball");
    s.call::<()>(&rt).unwrap();
    assert_eq!(io.borrow().command.vrot(), -75.0);
    // Another behavior ran in between: lookball is new again and re-reads the direction.
    io.borrow_mut().begin_cycle(world_with_ball(0.8, 1600), "go2ball");
    io.borrow_mut().begin_cycle(world_with_ball(0.8, 1700), "lookball");
    s.call::<()>(&rt).unwrap();
    assert_eq!(io.borrow().command.vrot(), 50.0);
}

#[test]
fn every_data_access_function_reads_the_snapshot() {
    let (rt, io) = setup();
    let mut w = world_with_ball(0.25, 42);
    w.my_pos = Estimate { pose: Framed::new(Pose2::new(1.0, -0.5, 0.5)), quality: 0.8 };
    w.global_ball = Estimate { pose: Framed::new(Pose2::new(2.0, 0.3, 0.0)), quality: 0.6 };
    w.ball_vel = Framed::new(mrt_core::Vec2::new(0.1, -0.02));
    w.mates = vec![Mate {
        id: 3,
        at: Estimate { pose: Framed::new(Pose2::new(-0.1, 0.05, 1.0)), quality: 0.5 },
        keeper: true,
    }];
    w.field.half_length = 6.0;
    w.role = "attacker".into();
    w.ball_booked = true;
    w.game_state = GameState::Playing;
    io.borrow_mut().begin_cycle(w, "probe");
    let probe = r#"
        local b, p, v, g, m = chaos.lps_getLpo(BALL), chaos.gsGetMyPos(), chaos.getBallVel(), chaos.getGlobalBall(), chaos.getMates()
        return string.format("%g %g %g %g|%g %g %g %g|%g %g|%g %g %g|%d %g %g|%s %s %s|%d %s",
            b.rho, b.theta, b.reliability, b.seen_ago, p.x, p.y, p.theta, p.quality, v.x, v.y,
            g.x, g.y, g.quality, m[1].id, m[1].x, m[1].quality, chaos.getRole().name,
            tostring(chaos.haveBookedBall().booked), chaos.getCurrentState(),
            chaos.getBehaviorInfo().isNew, tostring(NET1 == 1 and LANDMARK0 == 3))
            .. string.format("|%s %g %g %g %g", tostring(m[1].keeper), chaos.getField().half_length,
                chaos.getField().half_width, chaos.getField().goal_half_width,
                chaos.getField().penalty_area_depth)"#;
    let s = Script::from_source(&rt, "probe.lua", probe, LoadStrategy::Compiled).unwrap();
    assert_eq!(
        s.call::<String>(&rt).unwrap(),
        "400 0.25 0.9 0|1000 -500 0.5 0.8|100 -20|2000 300 0.6|3 -100 0.5|attacker true PLAYING|1 true\
         |true 6000 6000 1000 2250"
    );
}

/// The robots MAP anchored: `getRobots`, `getNearestOpponent`,
/// `getFreeDirection`, read from the snapshot's anchors.
#[test]
fn behaviors_read_the_anchored_robots_the_nearest_opponent_and_a_free_direction() {
    use mrt_msgs::{AnchoredRobot, RobotClass};
    let (rt, io) = setup();
    let mut w = world_with_ball(0.0, 100);
    // The opponent's net straight ahead; a teammate 0.8 m ahead in the way, an opponent 1.5 m
    // away on the left at 40°, and an old robot of unknown team behind.
    w.lps[lps::NET1] = Lpo { rho: 5.0, theta: 0.0, reliability: 1.0, seen_ago: 0.0 };
    let robot = |id, class, rho: f64, theta: f64, reliability| AnchoredRobot {
        id,
        class,
        at: Framed::new(mrt_core::Point2::new(rho * f64::cos(theta), rho * f64::sin(theta))),
        rho,
        theta,
        reliability,
        at_sigma: 0.08,
        ..Default::default()
    };
    w.robots = vec![
        robot(4, RobotClass::Teammate, 0.8, 0.0, 1.0),
        robot(7, RobotClass::Opponent, 1.5, 40f64.to_radians(), 0.9),
        robot(9, RobotClass::Robot, 1.2, 3.0, 0.2),
    ];
    io.borrow_mut().begin_cycle(w, "probe");
    let probe = r#"
        local r, o = chaos.getRobots(), chaos.getNearestOpponent()
        local weak = chaos.getNearestOpponent(0.1)
        local free = chaos.getFreeDirection()
        local wide = chaos.getFreeDirection(0, 2000, 5000)
        return string.format("%d %s %g|%d %s %g %g|%d|%.0f|%.0f", #r, r[1].class, r[2].reliability,
            o.id, o.class, o.rho, o.sigma, weak.id, math.deg(free), math.deg(wide))"#;
    let s = Script::from_source(&rt, "probe.lua", probe, LoadStrategy::Compiled).unwrap();
    // The free direction: straight ahead is the teammate (800 mm, inside 500 mm of the line
    // for |b| < 38.7°); 40° is the opponent's; the first free bearing going out 5° at a time,
    // left first, is −40° (800·sin 40° = 514 > 500, the opponent 80° off). A 10 m wide
    // corridor is blocked by anything ahead of it: the first bearing with both the teammate
    // and the opponent behind is −95° (the robot of unknown team is too faded to count).
    assert_eq!(s.call::<String>(&rt).unwrap(), "3 teammate 0.9|7 opponent 1500 80|9|-40|-95");
    let bad = Script::from_source(
        &rt,
        "bad.lua",
        "return chaos.getFreeDirection(0/0)",
        LoadStrategy::Compiled,
    )
    .unwrap();
    assert!(bad.call::<Option<f64>>(&rt).is_err(), "not a number: a Lua error");
}

#[test]
fn control_coordination_and_persistence_write_the_command() {
    let (rt, io) = setup();
    io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
    let s = Script::from_source(
        &rt,
        "ctl.lua",
        r#"chaos.setVlin(120) chaos.setVrot(-30) chaos.setVlat(5) chaos.setKick(2)
           chaos.setNeeded(NET1, 0.7) chaos.setNeeded(NET1, 0.4) chaos.setNeeded(BALL, 3)
           chaos.trackLandMarks() chaos.setBehavior("go2ball") chaos.bookBall()
           chaos.setGlobal("n", INTEGER, 7) chaos.setGlobal("f", FLOAT, 2.5) chaos.setGlobal("s", STRING, "hi")
           return chaos.getGlobal("n") + chaos.getGlobal("f"), chaos.getGlobal("s"), chaos.getGlobal("none")"#,
        LoadStrategy::Compiled,
    )
    .unwrap();
    let (sum, text, none): (f64, String, Option<i64>) = s.call(&rt).unwrap();
    assert_eq!((sum, text.as_str(), none), (9.5, "hi", None));
    let io = io.borrow();
    let c = &io.command;
    // The Lua API's mm/s and degrees/s, in the command's SI units.
    assert_eq!((c.twist, c.kick), (twist_from_setpoints(120.0, 5.0, -30.0), Some(2)));
    assert_eq!((c.need(lps::NET1), c.need(lps::BALL)), (0.7, 1.0), "max per object; clamped to 1");
    assert!(c.track_landmarks);
    assert_eq!((c.behavior.as_deref(), c.book_ball), (Some("go2ball"), Some(true)));
}

#[test]
fn wrong_arguments_are_lua_errors_naming_the_script_line_and_function_not_panics() {
    let (rt, io) = setup();
    io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
    for (src, needle) in [
        ("chaos.setVlin('fast')", "(calling field 'setVlin')"),
        ("chaos.lps_getLpo(99)", "no LPS object at index 99"),
        ("chaos.setNeeded(-1, 1)", "no LPS object at index -1"),
        ("chaos.setGlobal('k', INTEGER, 'text')", "does not match"),
        ("chaos.setGlobal('k', 9, 1)", "does not match"),
        ("chaos.nothere()", "nothere"),
    ] {
        let src = format!("local x = 1\n{src}");
        let s = Script::from_source(&rt, "bad.lua", &src, LoadStrategy::Compiled).unwrap();
        let e = s.call::<()>(&rt).unwrap_err();
        assert!(matches!(e, ScriptError::Runtime { .. }), "{src}: {e}");
        let text = e.to_string();
        assert!(
            text.starts_with("bad.lua:2: runtime error") && text.contains(needle),
            "{src}: {text}"
        );
    }
}

/// `getKickoffPose` gives the referee's place in READY (nil otherwise); `setTarget` hands
/// guidance a posture, avoiding obstacles unless told not to; bad numbers are Lua errors.
#[test]
fn kickoff_pose_and_targets() {
    use mrt_msgs::robot::Target;
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    let run = |world: WorldSnapshot, code: &str| {
        io.borrow_mut().begin_cycle(world, "t");
        let r = Script::from_source(&rt, "t.lua", code, LoadStrategy::Compiled)
            .unwrap()
            .call::<()>(&rt);
        (r, io.borrow().command.target)
    };
    let go = "local p = chaos.getKickoffPose() if p then chaos.setTarget(p.x, p.y, p.theta) end";
    let ready = WorldSnapshot {
        game_state: GameState::Ready,
        kickoff_pose: Some(Framed::new(Pose2::new(-4.0, 1.5, 0.5))),
        ..Default::default()
    };
    let (r, target) = run(ready, go);
    r.unwrap();
    assert_eq!(
        target,
        Some(Target { pose: Framed::new(Pose2::new(-4.0, 1.5, 0.5)), avoid: true, plan: false })
    );
    let (r, target) = run(WorldSnapshot::default(), go);
    r.unwrap();
    assert_eq!(target, None, "no kickoff pose outside READY");
    let (r, target) = run(WorldSnapshot::default(), "chaos.setTarget(100, 200, 0, false, true)");
    r.unwrap();
    assert_eq!(
        target,
        Some(Target { pose: Framed::new(Pose2::new(0.1, 0.2, 0.0)), avoid: false, plan: true }),
        "a target reached along a planned path"
    );
    let (r, target) = run(WorldSnapshot::default(), "chaos.setTarget(100, 200, 0, false)");
    r.unwrap();
    assert_eq!(
        target,
        Some(Target { pose: Framed::new(Pose2::new(0.1, 0.2, 0.0)), avoid: false, plan: false })
    );
    let (r, _) = run(WorldSnapshot::default(), "chaos.setTarget(0/0, 0, 0)");
    assert!(r.unwrap_err().to_string().contains("setTarget needs finite numbers"));
}

#[test]
fn a_set_point_that_is_not_finite_is_a_reported_fault() {
    let (rt, io) = setup();
    for call in [
        "chaos.setVlin(0/0)",
        "chaos.setVrot(math.huge)",
        "chaos.setVlat(-math.huge)",
        "chaos.setNeeded(BALL, 0/0)",
    ] {
        io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
        let s = Script::from_source(&rt, "nan.lua", call, LoadStrategy::Compiled).unwrap();
        let e = s.call::<()>(&rt).unwrap_err();
        assert!(
            matches!(e, ScriptError::Runtime { .. }) && e.to_string().contains("finite number"),
            "{call}: {e}"
        );
        let c = &io.borrow().command;
        assert!(c.vlin().is_finite() && c.vrot().is_finite() && c.vlat().is_finite());
        assert!(c.needs.is_empty());
    }
}

/// A huge finite speed means what any speed beyond the base's top speed means: it is taken
/// as MAX_SETPOINT, with its sign, and never overflows on its way to the wheels. A target
/// farther than MAX_TARGET is the script's error.
#[test]
fn a_huge_set_point_is_clamped_and_a_target_beyond_reach_refused() {
    use mrt_script::chaos::{MAX_SETPOINT, MAX_TARGET};
    let (rt, io) = setup();
    io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
    let src = "chaos.setVlin(1e308) chaos.setVrot(-1.7e308) chaos.setVlat(3 * 10^6)";
    let s = Script::from_source(&rt, "huge.lua", src, LoadStrategy::Compiled).unwrap();
    s.call::<()>(&rt).unwrap();
    let c = io.borrow().command.clone();
    assert_eq!(c.twist, twist_from_setpoints(MAX_SETPOINT, MAX_SETPOINT, -MAX_SETPOINT));
    assert!((c.twist.vx * 4.8).is_finite(), "a scaled set-point stays finite");
    for call in ["chaos.setTarget(1e308, 0, 0)", "chaos.setTarget(0, -2e9, 0)"] {
        io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
        let s = Script::from_source(&rt, "far.lua", call, LoadStrategy::Compiled).unwrap();
        let e = s.call::<()>(&rt).unwrap_err().to_string();
        assert!(e.contains(&format!("{MAX_TARGET:e}")), "{call}: {e}");
        assert_eq!(io.borrow().command.target, None, "{call}");
    }
}

#[test]
fn needs_keep_one_entry_per_object_however_often_they_are_set() {
    let (rt, io) = setup();
    io.borrow_mut().begin_cycle(WorldSnapshot::default(), "b");
    let s = Script::from_source(
        &rt,
        "needs.lua",
        "for i = 1, 100000 do chaos.setNeeded(BALL, (i % 10) / 10) end chaos.setNeeded(NET1, 0.2)",
        LoadStrategy::Compiled,
    )
    .unwrap();
    s.call::<()>(&rt).unwrap();
    let io = io.borrow();
    assert_eq!(io.command.needs.len(), 2);
    assert_eq!(io.command.need(lps::BALL), 0.9);
    assert_eq!(io.command.need(lps::NET1), 0.2);
}

#[test]
fn set_global_counts_against_the_memory_limit() {
    // The tester's loop of 1 MB strings reached 2.4 GB outside Lua's limit (a budget that
    // pays for making them, so that memory is what ends the call).
    let rt =
        LuaRuntime::new(Sandbox { instruction_budget: 50_000_000, memory_limit: 8 << 20 }).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    let s = Script::from_source(
        &rt,
        "hoard.lua",
        "local mb = string.rep('x', 1 << 20) \
         for i = 1, 10000 do chaos.setGlobal('k' .. i, STRING, mb .. i) end",
        LoadStrategy::Compiled,
    )
    .unwrap();
    let e = s.call::<()>(&rt).unwrap_err();
    assert!(matches!(e, ScriptError::Memory { limit, .. } if limit == 8 << 20), "{e}");
    // Fewer than 8 of them were kept; overwriting one does not grow the total.
    assert!(io.borrow().global("k8").is_none());
    let again = Script::from_source(
        &rt,
        "again.lua",
        "for i = 1, 1000 do chaos.setGlobal('k1', STRING, string.rep('y', 1000)) end",
        LoadStrategy::Compiled,
    )
    .unwrap();
    again.call::<()>(&rt).unwrap();
    assert_eq!(io.borrow().global("k1"), Some(&GlobalValue::String("y".repeat(1000))));
}
