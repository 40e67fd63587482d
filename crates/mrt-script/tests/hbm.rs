//! The HBM rule language (ThinkingCap/TeamChaos report §4.1) on temporary behavior directories: fuzzy sets and
//! connectives, rules and control variables checked by hand (singleton variables), CDB blending
//! of sub-behaviors, perceptual needs, behaviors using themselves, errors with file and line,
//! hot reload with fallback, and runaway or hostile behaviors that must not stop the robot.

#![allow(clippy::unwrap_used)]

use mrt_core::frames::metres;
use mrt_core::Time;
use mrt_fuzzy::hbm::Defuzzification;
use mrt_msgs::robot::{lps, Lpo, RobotCommand, WorldSnapshot};
use mrt_script::chaos::{install, GlobalValue, RobotIo};
use mrt_script::hbm::Hbm;
use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError, ThinkingCap};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::time::Duration;

/// A behavior directory of its own under the system temp dir, removed when dropped (even when
/// the test fails).
struct Dir(PathBuf);

impl Dir {
    fn new(test: &str) -> Dir {
        let p = std::env::temp_dir().join(format!("mrt-script-hbm-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&p);
        std::fs::create_dir_all(&p).unwrap();
        Dir(p)
    }

    /// Writes `file` (e.g. `walker.lua`) and returns its path.
    fn write(&self, file: &str, text: &str) -> PathBuf {
        let p = self.0.join(file);
        std::fs::write(&p, text).unwrap();
        p
    }

    /// Rewrites `file` and moves its modification time one second past the previous one, so
    /// the edit is seen even within the file system's timestamp granularity.
    fn edit(&self, file: &str, text: &str) -> PathBuf {
        let p = self.0.join(file);
        let before = std::fs::metadata(&p).unwrap().modified().unwrap();
        std::fs::write(&p, text).unwrap();
        let f = std::fs::File::options().write(true).open(&p).unwrap();
        f.set_modified(before + Duration::from_secs(1)).unwrap();
        p
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Control variables in singleton mode, so outputs are weighted means of the label values:
/// `go` is (Σ degree·value) / Σ degree over STAY = 0, SLOW = 100, FAST = 300; `turn` over
/// RIGHT = −90, NONE = 0, LEFT = 90; `mood` drives no command (HAPPY stands for 10, the
/// centre of the core of TRI(5, 10, 10)). `strafe` and `kick` keep their defaults.
const SINGLETON_HBM: &str = r#"
variable { name = "go", command = "vlin", min = -300, max = 300, mode = "singleton",
  labels = { STAY = SNG(0), SLOW = SNG(100), FAST = SNG(300) } }
variable { name = "turn", command = "vrot", min = -90, max = 90, mode = "singleton",
  labels = { RIGHT = SNG(-90), NONE = SNG(0), LEFT = SNG(90) } }
variable { name = "mood", min = 0, max = 10, mode = "singleton",
  labels = { SAD = SNG(0), HAPPY = TRI(5, 10, 10) } }
"#;

fn runtime(sandbox: Sandbox) -> (LuaRuntime, Rc<RefCell<RobotIo>>) {
    let rt = LuaRuntime::new(sandbox).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    (rt, io)
}

/// Loads the behaviors of `dir` in a fresh runtime.
fn load(dir: &Dir) -> (LuaRuntime, Rc<RefCell<RobotIo>>, Hbm) {
    let (rt, io) = runtime(Sandbox::default());
    let hbm = Hbm::load_dir(&rt, dir.path(), io.clone()).unwrap();
    (rt, io, hbm)
}

/// Runs `name` on `world` and returns the command it produced.
fn run(
    rt: &LuaRuntime,
    io: &Rc<RefCell<RobotIo>>,
    hbm: &Hbm,
    name: &str,
    world: WorldSnapshot,
) -> Result<RobotCommand, ScriptError> {
    io.borrow_mut().begin_cycle(world, name);
    hbm.run(rt, name)?;
    Ok(io.borrow().command.clone())
}

/// A world with the ball at `rho` mm (the behaviors' unit) straight ahead.
fn ball_at(rho: f64, t_ms: u64) -> WorldSnapshot {
    let mut w = WorldSnapshot { time: Time::from_millis(t_ms), ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: metres(rho), theta: 0.0, reliability: 0.9, seen_ago: 0.0 };
    w
}

#[track_caller]
fn close(got: f64, want: f64) {
    assert!((got - want).abs() < 1e-9, "got {got}, want {want}");
}

/// The runtime error of a failed run, with its file name (not the directory) and line.
#[track_caller]
fn runtime_error(e: &ScriptError) -> (String, usize, String) {
    match e {
        ScriptError::Runtime { file, line, message, .. } => {
            let name = Path::new(file).file_name().unwrap().to_string_lossy().into_owned();
            (name, *line, message.clone())
        }
        other => panic!("not a runtime error: {other:?}"),
    }
}

#[test]
fn fuzzy_sets_and_connectives() {
    let dir = Dir::new("sets");
    dir.write("idle.lua", "");
    let (rt, _io, _hbm) = load(&dir);
    let values = Script::from_source(
        &rt,
        "probe.lua",
        r#"return {
          TRI(0, 1, 2)(0.5), TRI(0, 1, 2)(1), TRI(0, 1, 2)(1.5), TRI(0, 1, 2)(2), TRI(0, 1, 2)(-1),
          TRA(0, 1, 2, 4)(1.5), TRA(0, 1, 2, 4)(3),
          TOL(1, 3)(0), TOL(1, 3)(2.5), TOL(1, 3)(4),
          TOR(1, 3)(0), TOR(1, 3)(2.5), TOR(1, 3)(5),
          REC(1, 2)(1.5), REC(1, 2)(2.5),
          SNG(2)(2), SNG(2)(2.5),
          DIV(0, 1, 2, 3)(0.5), DIV(0, 1, 2, 3)(1.5), DIV(0, 1, 2, 3)(2.75),
          AND(0.3, 0.8), OR(0.3, 0.8), NOT(0.3), AND(), OR(), AND(true, 0.4), OR(false, 0),
          NOT(true), AND(1.7, 1), OR(-2), AND(0 / 0), AND(0.9, 0.6, 0.7), OR(0.1, 0.6, 0.2),
        }"#,
        LoadStrategy::Compiled,
    )
    .unwrap()
    .call::<Vec<f64>>(&rt)
    .unwrap();
    let want = [
        // TRI(0,1,2): rising 0→1 on [0,1], falling on [1,2].
        0.5, 1.0, 0.5, 0.0, 0.0, //
        // TRA(0,1,2,4): core [1,2], falls to 0 at 4: at 3 it is (4−3)/2.
        1.0, 0.5, //
        // TOL(1,3): 1 up to 1, 0 from 3: at 2.5 it is (3−2.5)/2.
        1.0, 0.25, 0.0, //
        // TOR(1,3): at 2.5 it is (2.5−1)/2.
        0.0, 0.75, 1.0, //
        1.0, 0.0, // REC
        1.0, 0.0, // SNG
        // DIV(0,1,2,3): 1 at 0 down to 0 at 1, 0 inside, up to 1 at 3: at 2.75 it is 0.75.
        0.5, 0.0, 0.75, //
        // AND = min, OR = max, NOT = 1 − x; empty AND is 1, empty OR 0; booleans are 0/1;
        // truth values are clamped to [0, 1] and NaN counts as 0.
        0.3, 0.8, 0.7, 1.0, 0.0, 0.4, 0.0, 0.0, 1.0, 0.0, 0.0, 0.6, 0.6,
    ];
    assert_eq!(values.len(), want.len());
    for (k, (g, w)) in values.iter().zip(want).enumerate() {
        assert!((g - w).abs() < 1e-12, "value {}: got {g}, want {w}", k + 1);
    }
    let shown: String = Script::from_source(
        &rt,
        "show.lua",
        "return tostring(TRI(0, 1, 2)) .. ' ' .. tostring(SNG(3))",
        LoadStrategy::Compiled,
    )
    .unwrap()
    .call(&rt)
    .unwrap();
    assert_eq!(shown, "TRI[0.0, 1.0, 2.0] SNG[3.0]");
}

#[test]
fn rules_assert_labels_and_drive_the_command() {
    let dir = Dir::new("rules");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write(
        "walk.lua",
        r#"chaos.setVlin(999)          -- overridden: go is asserted below
           chaos.setVlat(33)           -- kept: no rule asserts strafe
           rule(0.1, "go", "FAST")     -- joined with the next by max: FAST = 0.25
           rule(0.25, "go", "FAST")
           rule(0.75, "go", "SLOW")
           rule(true, "turn", "LEFT")
           rule(0.5, "turn", "NONE")
           rule(false, "turn", "RIGHT")
           always("mood", "HAPPY")
           rule(0.2, "mood", "SAD")
           rule(0.6, "kick", "HEADKICK")
           rule(0.4, "kick", "FRONTKICK")
           need(1, BALL)"#,
    );
    dir.write("still.lua", r#"always("go", "STAY") rule(0.3, "kick", "FRONTKICK")"#);
    let (rt, io, hbm) = load(&dir);
    assert_eq!(hbm.names(), ["still", "walk"], "hbm.lua is not a behavior");
    // hbm.lua redefined go and turn in place and added mood.
    let vars = hbm.variables();
    let names: Vec<&str> = vars.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names, ["go", "turn", "strafe", "kick", "mood"]);
    assert_eq!(vars[0].defuzzification, Defuzzification::Singleton);
    assert_eq!(vars[2].defuzzification, Defuzzification::Centroid);

    let c = run(&rt, &io, &hbm, "walk", ball_at(1000.0, 0)).unwrap();
    // go: FAST 0.25, SLOW 0.75 → (0.25·300 + 0.75·100) / (0.25 + 0.75) = 150.
    close(c.vlin(), 150.0);
    // turn: LEFT 1, NONE 0.5, RIGHT 0 → (1·90 + 0.5·0) / 1.5 = 60.
    close(c.vrot(), 60.0);
    assert_eq!(c.vlat(), 33.0, "strafe was not asserted: the direct setVlat stands");
    // kick (choice): HEADKICK 0.6 is the strongest and reaches 0.5 → kick 2.
    assert_eq!(c.kick, Some(2));
    assert_eq!(c.need(lps::BALL), 1.0);
    // mood drives nothing, but its degrees are there for monitors (labels sorted by name).
    assert_eq!(hbm.degrees("mood"), [("HAPPY".to_string(), 1.0), ("SAD".to_string(), 0.2)]);
    assert_eq!(
        hbm.degrees("go"),
        [("FAST".to_string(), 0.25), ("SLOW".to_string(), 0.75), ("STAY".to_string(), 0.0)]
    );
    assert!(hbm.degrees("nothing").is_empty());

    // Each run starts from nothing asserted: still gives go = 0 and no kick (FRONTKICK 0.3 <
    // 0.5); turn is not asserted, so vrot stays 0 (the command's default).
    let c = run(&rt, &io, &hbm, "still", ball_at(1000.0, 100)).unwrap();
    assert_eq!((c.vlin(), c.vrot(), c.vlat(), c.kick), (0.0, 0.0, 0.0, None));
    assert_eq!(hbm.degrees("mood"), [("HAPPY".to_string(), 0.0), ("SAD".to_string(), 0.0)]);
}

#[test]
fn default_variables_use_mamdani_centroids() {
    // Without hbm.lua the defaults apply. By hand, on go's range [−300, 300]:
    // - FAST = TOR(150, 300) alone: the right triangle from 150 (0) to 300 (1), centroid
    //   150 + 2/3·150 = 250;
    // - SLOW = TRI(0, 150, 300) clipped at 0.4: a symmetric trapezium, centroid 150;
    // - turn LEFT = TRI(0, 45, 90) alone: 45; strafe RIGHT = TRI(−200, −100, 0): −100.
    let dir = Dir::new("centroid");
    dir.write(
        "fast.lua",
        r#"always("go", "FAST") always("turn", "LEFT") always("strafe", "RIGHT")"#,
    );
    dir.write("slow.lua", r#"rule(0.4, "go", "SLOW")"#);
    let (rt, io, hbm) = load(&dir);
    let c = run(&rt, &io, &hbm, "fast", ball_at(1000.0, 0)).unwrap();
    close(c.vlin(), 250.0);
    close(c.vrot(), 45.0);
    close(c.vlat(), -100.0);
    let c = run(&rt, &io, &hbm, "slow", ball_at(1000.0, 0)).unwrap();
    close(c.vlin(), 150.0);
}

/// `scale` stretches a default variable (its range and every label) for a robot of other
/// speeds: FAST alone gives 250 · 4 = 1000 mm/s and turn LEFT 45 · 2 = 90 °/s. An edit of
/// hbm.lua runs it again on fresh defaults, not on the scaled ones. A factor that is not a
/// number > 0, or a variable that does not exist, fails the load naming hbm.lua.
#[test]
fn scale_stretches_a_default_variable_once_also_after_a_reload() {
    let dir = Dir::new("scale");
    dir.write("hbm.lua", r#"scale("go", 4) scale("turn", 2)"#);
    dir.write("fast.lua", r#"always("go", "FAST") always("turn", "LEFT")"#);
    let mut cap = ThinkingCap::with_behavior(dir.path(), "fast", Sandbox::default()).unwrap();
    let c = cap.cycle(ball_at(1000.0, 0)).command;
    close(c.vlin(), 1000.0);
    close(c.vrot(), 90.0);
    dir.edit("hbm.lua", "scale(\"go\", 4) scale(\"turn\", 2) -- edited\n");
    let (reloaded, errors) = cap.reload_changed();
    assert!(errors.is_empty() && reloaded.iter().any(|r| r == "hbm"), "{reloaded:?} {errors:?}");
    close(cap.cycle(ball_at(1000.0, 100)).command.vlin(), 1000.0);
    for (k, bad) in [
        r#"scale("go", 0)"#,
        r#"scale("go", -2)"#,
        r#"scale("speed", 2)"#,
        r#"scale("go", 1e300) scale("go", 1e300)"#,
    ]
    .into_iter()
    .enumerate()
    {
        let d = Dir::new(&format!("badscale{k}"));
        d.write("hbm.lua", bad);
        d.write("fast.lua", r#"always("go", "FAST")"#);
        let e = ThinkingCap::with_behavior(d.path(), "fast", Sandbox::default()).err().unwrap();
        let e = e.to_string();
        assert!(e.contains("hbm.lua:1: runtime error: scale('"), "{bad}: {e}");
    }
}

#[test]
fn cdb_blends_sub_behaviors_by_their_activation() {
    let dir = Dir::new("cdb");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write(
        "fast.lua",
        r#"always("go", "FAST") always("turn", "LEFT")
           chaos.setGlobal("fast_activation", FLOAT, hbm_activation())"#,
    );
    dir.write("slow.lua", r#"always("go", "SLOW") always("turn", "RIGHT")"#);
    dir.write("mix.lua", r#"use(0.3, "fast") use(0.7, "slow")"#);
    dir.write("outer.lua", r#"use(0.5, "mix")"#);
    dir.write("never.lua", r#"use(0, "boom") use(false, "boom") always("go", "STAY")"#);
    dir.write("boom.lua", r#"error("a behavior at activation 0 must not run")"#);
    let (rt, io, hbm) = load(&dir);
    let activation = |io: &Rc<RefCell<RobotIo>>| match io.borrow().global("fast_activation") {
        Some(GlobalValue::Float(a)) => *a,
        other => panic!("{other:?}"),
    };

    // Alone, at activation 1: go 300, turn 90.
    let c = run(&rt, &io, &hbm, "fast", ball_at(1000.0, 0)).unwrap();
    close(c.vlin(), 300.0);
    close(c.vrot(), 90.0);
    close(activation(&io), 1.0);

    // mix: FAST at 0.3, SLOW at 0.7 →
    //   go   = (0.3·300 + 0.7·100) / (0.3 + 0.7) = (90 + 70) / 1 = 160,
    //   turn = (0.3·90 + 0.7·(−90)) / 1 = −36.
    let c = run(&rt, &io, &hbm, "mix", ball_at(1000.0, 100)).unwrap();
    close(c.vlin(), 160.0);
    close(c.vrot(), -36.0);
    close(activation(&io), 0.3);

    // outer uses mix at 0.5: fast runs at min(0.3, 0.5) = 0.3, slow at min(0.7, 0.5) = 0.5 →
    //   go   = (0.3·300 + 0.5·100) / 0.8 = 140 / 0.8 = 175,
    //   turn = (0.3·90 − 0.5·90) / 0.8 = −18 / 0.8 = −22.5.
    let c = run(&rt, &io, &hbm, "outer", ball_at(1000.0, 200)).unwrap();
    close(c.vlin(), 175.0);
    close(c.vrot(), -22.5);

    // A behavior used at 0 (or false) is not run at all.
    let c = run(&rt, &io, &hbm, "never", ball_at(1000.0, 300)).unwrap();
    close(c.vlin(), 0.0);
}

#[test]
fn needs_are_clipped_by_activation_and_combined_by_max() {
    let dir = Dir::new("needs");
    dir.write("a.lua", "need(1, NET1) need(0.2, BALL)");
    dir.write("b.lua", r#"need(0.5, NET1) need(1, BALL) use(0.4, "c")"#);
    dir.write("c.lua", "need(1, NET2)");
    dir.write("top.lua", r#"use(0.3, "a") use(0.7, "b")"#);
    let (rt, io, hbm) = load(&dir);
    let c = run(&rt, &io, &hbm, "top", ball_at(1000.0, 0)).unwrap();
    // a runs at 0.3, b at 0.7, c (used by b at 0.4) at min(0.4, 0.7) = 0.4:
    //   NET1 = max(min(1, 0.3), min(0.5, 0.7)) = max(0.3, 0.5) = 0.5
    //   BALL = max(min(0.2, 0.3), min(1, 0.7)) = max(0.2, 0.7) = 0.7
    //   NET2 = min(1, 0.4) = 0.4; nothing else is needed.
    close(c.need(lps::NET1), 0.5);
    close(c.need(lps::BALL), 0.7);
    close(c.need(lps::NET2), 0.4);
    assert_eq!(c.need(lps::LANDMARK0), 0.0);
    assert_eq!(c.needs.len(), 3, "one entry per needed object: {:?}", c.needs);
    // At top level a need is not clipped.
    let c = run(&rt, &io, &hbm, "a", ball_at(1000.0, 100)).unwrap();
    assert_eq!((c.need(lps::NET1), c.need(lps::BALL)), (1.0, 0.2));
}

#[test]
fn a_behavior_using_itself_is_an_error_naming_the_chain() {
    let dir = Dir::new("selfuse");
    dir.write("selfish.lua", "always(\"go\", \"FAST\")\nuse(1, \"selfish\")");
    dir.write("ping.lua", "use(1, \"pong\")");
    dir.write("pong.lua", "-- pong\nuse(1, \"ping\")");
    dir.write("lonely.lua", "\n\nuse(0.5, \"ghost\")");
    dir.write("fine.lua", r#"always("go", "SLOW")"#);
    let (rt, io, hbm) = load(&dir);

    let e = run(&rt, &io, &hbm, "selfish", ball_at(1000.0, 0)).unwrap_err();
    let (file, line, message) = runtime_error(&e);
    assert_eq!((file.as_str(), line), ("selfish.lua", 2), "{e}");
    assert!(message.contains("use: behavior 'selfish' uses itself: selfish -> selfish"), "{e}");
    assert_eq!(io.borrow().command.vlin(), 0.0, "on error nothing fuzzy is written");

    // Through another behavior: the error is raised where pong uses ping again.
    let e = run(&rt, &io, &hbm, "ping", ball_at(1000.0, 100)).unwrap_err();
    let (file, line, message) = runtime_error(&e);
    assert_eq!((file.as_str(), line), ("pong.lua", 2), "{e}");
    assert!(message.contains("use: behavior 'ping' uses itself: ping -> pong -> ping"), "{e}");
    let e = run(&rt, &io, &hbm, "pong", ball_at(1000.0, 200)).unwrap_err();
    assert!(e.to_string().contains("uses itself: pong -> ping -> pong"), "{e}");

    // Using an unknown behavior names it and lists the known ones.
    let e = run(&rt, &io, &hbm, "lonely", ball_at(1000.0, 300)).unwrap_err();
    let (file, line, message) = runtime_error(&e);
    assert_eq!((file.as_str(), line), ("lonely.lua", 3), "{e}");
    assert!(
        message
            .contains("use: no behavior named 'ghost' (known: fine, lonely, ping, pong, selfish)"),
        "{e}"
    );

    // The hierarchy is usable again after the errors.
    let c = run(&rt, &io, &hbm, "fine", ball_at(1000.0, 400)).unwrap();
    close(c.vlin(), 150.0);
    // Running an unknown behavior at top level is an error too.
    let e = run(&rt, &io, &hbm, "ghost", ball_at(1000.0, 500)).unwrap_err();
    assert!(e.to_string().contains("no behavior named 'ghost'"), "{e}");
}

#[test]
fn bad_rules_and_arguments_are_errors_with_file_and_line_not_panics() {
    let dir = Dir::new("badargs");
    let cases: [(&str, &str); 22] = [
        (
            r#"rule(1, "speed", "FAST")"#,
            "no control variable 'speed' (known: go, turn, strafe, kick)",
        ),
        (
            r#"rule(1, "go", "WARP")"#,
            "control variable 'go' has no label 'WARP' (BACK, FAST, SLOW, SLOWBACK, STAY)",
        ),
        (r#"always("turn", "SIDEWAYS")"#, "control variable 'turn' has no label 'SIDEWAYS'"),
        (
            r#"rule("x", "go", "FAST")"#,
            "rule: a truth value must be a number or a boolean, not string",
        ),
        (
            r#"rule({}, "go", "FAST")"#,
            "rule: a truth value must be a number or a boolean, not table",
        ),
        (r#"rule(1, "go")"#, "bad argument #3"),
        (r#"need(1, "BALL")"#, "bad argument #2"),
        ("need(1, 99)", "need: no perceptual object 99 (0 to 8)"),
        (r#"need(nil, BALL)"#, "need: a truth value must be a number or a boolean, not nil"),
        (r#"use("yes", "fine")"#, "use: a truth value must be a number or a boolean, not string"),
        ("AND(0.5, {})", "AND: a truth value must be a number or a boolean, not table"),
        ("TRI(1, 2)", "TRI takes 3 numbers, got 2"),
        ("TRI('a', 1, 2)", "error converting Lua string to f64"),
        (
            "TRI(2, 1, 0)",
            "TRI[2.0, 1.0, 0.0]: parameters must be numbers within ±1e9, in increasing order",
        ),
        ("TOR(0, math.huge)", "parameters must be numbers within ±1e9, in increasing order"),
        ("TRI(0, 1, 2)('x')", "bad argument"),
        (
            r#"variable { name = "v", min = 1, max = 0, labels = { A = SNG(0) } }"#,
            "variable 'v': min 1 must be below max 0",
        ),
        (
            r#"variable { name = "v", min = -1e308, max = 0, labels = { A = SNG(0) } }"#,
            "both within ±1e9",
        ),
        // Labels built by hand as tables get the checks TRI and its kin make.
        (
            r#"variable { name = "v", min = 0, max = 1, labels = { A = {0, 0/0, 0/0, 0/0} } }"#,
            "TRI[NaN, NaN, NaN]: parameters must be numbers within ±1e9",
        ),
        (
            r#"variable { name = "v", min = 0, max = 1, labels = { A = {0, 3, 2, 1} } }"#,
            "TRI[3.0, 2.0, 1.0]: parameters must be numbers within ±1e9, in increasing order",
        ),
        (
            r#"variable { name = "v", min = 0, max = 1, labels = { A = {1, -1e308, 0, 0, 1e308} } }"#,
            "TRA[-1e308, 0.0, 0.0, 1e308]: parameters must be numbers within ±1e9",
        ),
        (
            r#"local l = {} for i = 1, 33 do l["L" .. i] = SNG(i) end variable { name = "v", min = 0, max = 100, labels = l }"#,
            "variable 'v' has more than 32 labels",
        ),
    ];
    for (k, (src, _)) in cases.iter().enumerate() {
        dir.write(
            &format!("bad{k:02}.lua"),
            &format!("local x = 1\n{src}\nalways(\"go\", \"FAST\")"),
        );
    }
    dir.write("fine.lua", r#"always("go", "FAST")"#);
    let (rt, io, hbm) = load(&dir);
    for (k, (src, needle)) in cases.iter().enumerate() {
        let name = format!("bad{k:02}");
        let e = run(&rt, &io, &hbm, &name, ball_at(1000.0, k as u64 * 100)).unwrap_err();
        let (file, line, message) = runtime_error(&e);
        assert_eq!((file.as_str(), line), (format!("{name}.lua").as_str(), 2), "{src}: {e}");
        assert!(message.contains(needle), "{src}: {e}");
        assert!(
            e.to_string().starts_with(&format!(
                "{}:2: runtime error",
                dir.path().join(format!("{name}.lua")).display()
            )),
            "{src}: {e}"
        );
    }
    // Still usable.
    let c = run(&rt, &io, &hbm, "fine", ball_at(1000.0, 9000)).unwrap();
    close(c.vlin(), 250.0);
}

#[test]
fn errors_in_hbm_lua_or_a_behavior_file_fail_the_load_naming_the_file() {
    // An unordered set in hbm.lua: a runtime error at its line.
    let dir = Dir::new("badsetup");
    let setup = dir.write("hbm.lua", "-- shared\nlocal NEAR = TRI(2, 1, 0)\n");
    dir.write("fine.lua", "");
    let (rt, io) = runtime(Sandbox::default());
    let e = Hbm::load_dir(&rt, dir.path(), io).err().unwrap();
    let (file, line, message) = runtime_error(&e);
    assert_eq!((file.as_str(), line), ("hbm.lua", 2), "{e}");
    assert!(message.contains("parameters must be numbers within ±1e9, in increasing order"), "{e}");
    assert!(e.to_string().starts_with(&format!("{}:2:", setup.display())), "{e}");

    // A behavior that does not compile.
    let dir = Dir::new("badsyntax");
    let bad = dir.write("broken.lua", "always(\"go\", \"FAST\")\nrule(1, \"go\"\n");
    let (rt, io) = runtime(Sandbox::default());
    let e = Hbm::load_dir(&rt, dir.path(), io).err().unwrap();
    assert!(matches!(e, ScriptError::Syntax { .. }), "{e:?}");
    assert!(e.to_string().starts_with(&format!("{}:", bad.display())), "{e}");

    // ThinkingCap refuses an unknown top behavior, listing the known ones.
    let dir = Dir::new("unknowntop");
    dir.write("a.lua", "");
    dir.write("b.lua", "");
    dir.write("m.hfsm.lua", "this is not a behavior and is not compiled as one");
    let e = ThinkingCap::with_behavior(dir.path(), "c", Sandbox::default()).err().unwrap();
    assert!(
        e.to_string().contains("no behavior named 'c'") && e.to_string().ends_with("(known: a, b)"),
        "{e}"
    );
}

/// The hand computations of SINGLETON_HBM: SLOW alone gives 100, FAST alone 300, STAY 0.
#[test]
fn hot_reload_swaps_good_edits_and_keeps_the_old_version_on_bad_ones() {
    let dir = Dir::new("reload");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("walker.lua", "-- v1\nalways(\"go\", \"SLOW\")\n");
    let mut cap = ThinkingCap::with_behavior(dir.path(), "walker", Sandbox::default()).unwrap();
    let mut t = 0;
    let mut cycle = |cap: &mut ThinkingCap| {
        t += 100;
        let c = cap.cycle(ball_at(1000.0, t));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        assert_eq!(c.behavior.as_deref(), Some("walker"));
        c.command.vlin()
    };
    assert_eq!((cycle(&mut cap), cycle(&mut cap)), (100.0, 100.0));
    let (reloaded, errors) = cap.reload_changed();
    assert!(
        reloaded.is_empty() && errors.is_empty(),
        "nothing changed yet: {reloaded:?} {errors:?}"
    );

    // A good edit: picked up at the next cycle.
    dir.edit("walker.lua", "-- v2\nalways(\"go\", \"FAST\")\n");
    let (reloaded, errors) = cap.reload_changed();
    assert_eq!((reloaded, errors.len()), (vec!["walker".to_string()], 0));
    assert_eq!(cycle(&mut cap), 300.0);

    // A bad edit (line 3 does not parse): reported with file:line, v2 keeps running.
    let path = dir.edit("walker.lua", "-- v3\nalways(\"go\", \"STAY\")\nrule(1, \"go\" \"SLOW\"\n");
    let (reloaded, errors) = cap.reload_changed();
    assert!(reloaded.is_empty(), "{reloaded:?}");
    assert_eq!(errors.len(), 1);
    match &errors[0] {
        ScriptError::Syntax { file, line, .. } => {
            assert_eq!((file.as_str(), *line), (path.display().to_string().as_str(), 3))
        }
        other => panic!("{other:?}"),
    }
    assert!(errors[0].to_string().starts_with(&format!("{}:3: ", path.display())));
    assert_eq!((cycle(&mut cap), cycle(&mut cap)), (300.0, 300.0));
    let (reloaded, errors) = cap.reload_changed();
    assert!(reloaded.is_empty() && errors.is_empty(), "reported once: {reloaded:?} {errors:?}");

    // A later good edit is picked up.
    dir.edit("walker.lua", "-- v4\nalways(\"go\", \"STAY\")\nrule(0.5, \"go\", \"SLOW\")\n");
    assert_eq!(cap.reload_changed().0, ["walker"]);
    // STAY 1, SLOW 0.5 → (1·0 + 0.5·100) / 1.5 = 33.33…
    close(cycle(&mut cap), 50.0 / 1.5);

    // Editing hbm.lua re-runs it: SLOW now stands for 160 → (0.5·160) / 1.5 = 53.33…
    dir.edit("hbm.lua", &SINGLETON_HBM.replace("SLOW = SNG(100)", "SLOW = SNG(160)"));
    assert_eq!(cap.reload_changed().0, ["hbm"]);
    close(cycle(&mut cap), 80.0 / 1.5);

    // A new behavior file is loaded; a new broken one is reported and not loaded.
    dir.write("runner.lua", r#"always("go", "FAST")"#);
    dir.write("limper.lua", "always(");
    let (reloaded, errors) = cap.reload_changed();
    assert_eq!(reloaded, ["runner"]);
    assert_eq!(errors.len(), 1);
    assert!(errors[0].to_string().contains("limper.lua:1:"), "{}", errors[0]);
    assert!(cap.hbm().contains("runner") && !cap.hbm().contains("limper"));
    close(cycle(&mut cap), 80.0 / 1.5);
}

#[test]
fn hbm_reload_changed_directly() {
    let dir = Dir::new("hbmreload");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("b.lua", r#"always("turn", "LEFT")"#);
    let (rt, io, mut hbm) = load(&dir);
    close(run(&rt, &io, &hbm, "b", ball_at(0.0, 0)).unwrap().vrot(), 90.0);
    dir.edit("b.lua", r#"always("turn", "RIGHT")"#);
    assert_eq!(hbm.reload_changed(&rt).0, ["b"]);
    close(run(&rt, &io, &hbm, "b", ball_at(0.0, 100)).unwrap().vrot(), -90.0);
    dir.edit("b.lua", r#"always("turn", "NONE""#);
    let (done, errors) = hbm.reload_changed(&rt);
    assert!(done.is_empty() && errors.len() == 1, "{done:?} {errors:?}");
    close(run(&rt, &io, &hbm, "b", ball_at(0.0, 200)).unwrap().vrot(), -90.0);
}

/// The watcher (`ThinkingCap::watch`) reports the edit; the cycle that reloads it already
/// runs the new version and says so in `Cycle::reloaded`; a bad edit shows in `Cycle::errors`.
#[test]
fn a_watched_directory_reloads_at_the_next_cycle() {
    let dir = Dir::new("watched");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("walker.lua", r#"always("go", "SLOW")"#);
    let mut cap = ThinkingCap::with_behavior(dir.path(), "walker", Sandbox::default()).unwrap();
    cap.watch(dir.path()).unwrap();
    assert_eq!(cap.cycle(ball_at(1000.0, 0)).command.vlin(), 100.0);
    dir.edit("walker.lua", r#"always("go", "FAST")"#);
    let mut seen = None;
    for k in 1..1000 {
        let c = cap.cycle(ball_at(1000.0, k * 100));
        if !c.reloaded.is_empty() {
            seen = Some(c);
            break;
        }
        assert_eq!(c.command.vlin(), 100.0);
        std::thread::sleep(Duration::from_millis(5));
    }
    let c = seen.expect("the edit was never picked up");
    assert_eq!(c.reloaded, ["walker"]);
    assert_eq!(c.command.vlin(), 300.0);

    let path = dir.edit("walker.lua", "always(\"go\",");
    let mut seen = None;
    for k in 1000..2000 {
        let c = cap.cycle(ball_at(1000.0, k * 100));
        assert_eq!(c.command.vlin(), 300.0, "the old version keeps running");
        if !c.errors.is_empty() {
            seen = Some(c);
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let c = seen.expect("the bad edit was never reported");
    assert!(
        c.errors[0].to_string().starts_with(&format!("{}:1: ", path.display())),
        "{:?}",
        c.errors
    );
}

#[test]
fn a_runaway_loop_gives_a_budget_error_and_a_stop_command_for_that_cycle() {
    let dir = Dir::new("runaway");
    dir.write("hbm.lua", SINGLETON_HBM);
    let spin = dir.write(
        "spin.lua",
        r#"always("go", "FAST")
           chaos.setVrot(42) chaos.setKick(1) chaos.setNeeded(BALL, 1)
           if chaos.lps_getLpo(BALL).rho > 1000 then while true do end end"#,
    );
    dir.write("outer.lua", r#"always("turn", "LEFT") use(1, "spin")"#);
    let sandbox = Sandbox { instruction_budget: 1_000_000, ..Default::default() };
    let mut cap = ThinkingCap::with_behavior(dir.path(), "spin", sandbox).unwrap();
    let c = cap.cycle(ball_at(500.0, 0));
    assert!(c.errors.is_empty());
    assert_eq!((c.command.vlin(), c.command.vrot(), c.command.kick), (300.0, 42.0, Some(1)));
    // The ball at 2 m: the loop runs away. Budget error; the robot gets the stop command.
    let c = cap.cycle(ball_at(2000.0, 100));
    assert_eq!(c.errors.len(), 1);
    match &c.errors[0] {
        ScriptError::Budget { file, line, budget } => assert_eq!(
            (file.as_str(), *line, *budget),
            (spin.display().to_string().as_str(), 3, 1_000_000)
        ),
        other => panic!("{other:?}"),
    }
    assert_eq!(c.command, RobotCommand::default(), "stop: all zeros, no kick, no needs");
    assert_eq!(c.behavior, None);
    // The next cycles run normally.
    for t in [200, 300] {
        let c = cap.cycle(ball_at(500.0, t));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        assert_eq!((c.command.vlin(), c.command.vrot()), (300.0, 42.0));
    }
    // The same inside a sub-behavior: the error names the sub-behavior's file and line.
    let mut cap = ThinkingCap::with_behavior(dir.path(), "outer", sandbox).unwrap();
    let c = cap.cycle(ball_at(2000.0, 0));
    assert!(matches!(c.errors[..], [ScriptError::Budget { line: 3, .. }]), "{:?}", c.errors);
    assert!(
        c.errors[0].to_string().starts_with(&format!("{}:3: aborted after", spin.display())),
        "{}",
        c.errors[0]
    );
    assert_eq!(c.command, RobotCommand::default());
    let c = cap.cycle(ball_at(500.0, 100));
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    // turn LEFT (90) from outer; spin's direct setVrot(42) is overridden by the asserted turn.
    assert_eq!((c.command.vlin(), c.command.vrot()), (300.0, 90.0));
}

#[test]
fn a_memory_bomb_gives_a_memory_error_and_a_stop_command_for_that_cycle() {
    let dir = Dir::new("bomb");
    dir.write("hbm.lua", SINGLETON_HBM);
    let bomb = dir.write(
        "bomb.lua",
        r#"always("go", "SLOW")
           if chaos.lps_getLpo(BALL).rho > 1000 then
             local t = {}
             for i = 1, 1e9 do t[i] = string.rep("x", 1000) .. i end
           end"#,
    );
    // A budget that pays for the strings, so that memory is what ends the call.
    let sandbox = Sandbox { instruction_budget: 100_000_000, memory_limit: 8 << 20 };
    let mut cap = ThinkingCap::with_behavior(dir.path(), "bomb", sandbox).unwrap();
    assert_eq!(cap.cycle(ball_at(500.0, 0)).command.vlin(), 100.0);
    let c = cap.cycle(ball_at(2000.0, 100));
    match &c.errors[..] {
        [ScriptError::Memory { file, limit }] => {
            assert_eq!((file.as_str(), *limit), (bomb.display().to_string().as_str(), 8 << 20))
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(c.command, RobotCommand::default());
    for t in 2..6 {
        let c = cap.cycle(ball_at(500.0, t * 100));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        assert_eq!(c.command.vlin(), 100.0);
    }
    assert!(cap.runtime().used_memory() < 8 << 20);
}

#[test]
fn os_io_and_require_are_not_reachable_from_a_behavior() {
    let dir = Dir::new("hostile");
    let cases = [
        (
            "evil_os",
            "os.execute('touch /tmp/mrt-owned')",
            "attempt to index a nil value (global 'os')",
        ),
        (
            "evil_io",
            "local f = io.open('/etc/passwd')",
            "attempt to index a nil value (global 'io')",
        ),
        (
            "evil_require",
            "local s = require('socket')",
            "attempt to call a nil value (global 'require')",
        ),
        ("evil_dofile", "dofile('/etc/passwd')", "attempt to call a nil value (global 'dofile')"),
        ("evil_debug", "debug.getinfo(1)", "attempt to index a nil value (global 'debug')"),
    ];
    for (name, src, _) in cases {
        dir.write(&format!("{name}.lua"), &format!("always(\"go\", \"FAST\")\n{src}\n"));
    }
    for (name, src, needle) in cases {
        let mut cap = ThinkingCap::with_behavior(dir.path(), name, Sandbox::default()).unwrap();
        let c = cap.cycle(ball_at(1000.0, 0));
        assert_eq!(c.errors.len(), 1, "{src}");
        let (file, line, message) = runtime_error(&c.errors[0]);
        assert_eq!((file.as_str(), line), (format!("{name}.lua").as_str(), 2), "{src}");
        assert_eq!(message, needle, "{src}");
        assert_eq!(c.command, RobotCommand::default(), "{src}");
    }
}

/// An edited hbm.lua that compiles but fails when re-run is reported and leaves the running
/// control variables alone (the old version keeps running): hbm.lua's singleton `go` stays.
///
/// By hand: SLOW 0.5 and FAST 0.5 give (0.5·100 + 0.5·300) / 1 = 200 in singleton mode. In
/// the default centroid mode, SLOW = TRI(0, 150, 300) and FAST = TOR(150, 300) clipped at 0.5
/// make a ramp from 0 to 0.5 over [0, 75] and a plateau at 0.5 over [75, 300]: area
/// 18.75 + 112.5 = 131.25, moment 18.75·50 + 112.5·187.5 = 22031.25, centroid 167.857.
#[test]
fn a_failing_hbm_lua_edit_keeps_the_old_variables() {
    let dir = Dir::new("badsetupedit");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("walker.lua", r#"rule(0.5, "go", "SLOW") rule(0.5, "go", "FAST")"#);
    let mut cap = ThinkingCap::with_behavior(dir.path(), "walker", Sandbox::default()).unwrap();
    close(cap.cycle(ball_at(1000.0, 0)).command.vlin(), 200.0);
    dir.edit("hbm.lua", &format!("error('not yet')\n{SINGLETON_HBM}"));
    let (reloaded, errors) = cap.reload_changed();
    assert!(reloaded.is_empty(), "{reloaded:?}");
    assert!(errors[0].to_string().contains("hbm.lua:1: runtime error: not yet"), "{errors:?}");
    // Observed: 167.857 (the default centroid variable).
    close(cap.cycle(ball_at(1000.0, 100)).command.vlin(), 200.0);
}

/// `getBehaviorInfo` inside a behavior run through `use` is that behavior's own: new the
/// first cycle it runs after a cycle without it, its timer from then, even though the top
/// behavior has been running all along (lookball under the goalkeeper relies on it).
#[test]
fn a_used_behavior_has_its_own_behavior_info() {
    let dir = Dir::new("usedinfo");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write(
        "inner.lua",
        "local i = chaos.getBehaviorInfo() chaos.setVlat(i.isNew) chaos.setKick(math.floor(i.timer))",
    );
    dir.write("outer.lua", r#"if chaos.lps_getLpo(BALL).rho < 1000 then use(1, "inner") end"#);
    let mut cap = ThinkingCap::with_behavior(dir.path(), "outer", Sandbox::default()).unwrap();
    let info = |cap: &mut ThinkingCap, rho: f64, t: u64| {
        let c = cap.cycle(ball_at(rho, t));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        (c.command.vlat(), c.command.kick)
    };
    assert_eq!(info(&mut cap, 2000.0, 0), (0.0, None), "inner not run");
    assert_eq!(info(&mut cap, 2000.0, 100), (0.0, None));
    // The outer behavior is 200 ms old, inner starts now: new, timer 0.
    assert_eq!(info(&mut cap, 500.0, 200), (1.0, Some(0)));
    assert_eq!(info(&mut cap, 500.0, 300), (0.0, Some(100)));
    assert_eq!(info(&mut cap, 500.0, 400), (0.0, Some(200)));
    // A cycle without it, then again: new again.
    info(&mut cap, 2000.0, 500);
    assert_eq!(info(&mut cap, 500.0, 600), (1.0, Some(0)));
}

#[test]
fn a_behavior_that_keeps_failing_is_stopped_until_a_file_is_reloaded() {
    // A hostile `error(string.rep("E", 4e6))`: every cycle pays for 4 MB of error text.
    let dir = Dir::new("failing");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("shout.lua", r#"always("go", "FAST") error(string.rep("E", 4e5))"#);
    let mut cap = ThinkingCap::with_behavior(dir.path(), "shout", Sandbox::default()).unwrap();
    for t in 1..mrt_script::FAULT_LIMIT {
        let c = cap.cycle(ball_at(500.0, u64::from(t) * 100));
        assert!(matches!(c.errors[..], [ScriptError::Runtime { .. }]), "{:?}", c.errors);
    }
    let c = cap.cycle(ball_at(500.0, 3000));
    assert!(
        matches!(
            c.errors[..],
            [
                ScriptError::Runtime { .. },
                ScriptError::Stopped { cycles: 20, why: "with errors", .. }
            ]
        ),
        "{:?}",
        c.errors
    );
    let c = cap.cycle(ball_at(500.0, 3100));
    assert!(c.errors.is_empty() && c.command == RobotCommand::default());
    // A cycle that works in between starts the count again.
    dir.edit(
        "shout.lua",
        r#"always("go", "FAST") if chaos.lps_getLpo(BALL).rho > 1000 then error("far") end"#,
    );
    assert!(cap.reload_changed().1.is_empty());
    for t in 0..100 {
        let rho = if t % 10 == 0 { 500.0 } else { 2000.0 };
        let c = cap.cycle(ball_at(rho, 4000 + t * 100));
        assert!(!c.errors.iter().any(|e| matches!(e, ScriptError::Stopped { .. })));
    }
    assert!(!cap.stopped());
}

#[test]
fn a_behavior_that_keeps_running_away_is_stopped_until_a_file_is_reloaded() {
    let dir = Dir::new("stopped");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("spin.lua", r#"always("go", "FAST") while true do end"#);
    let sandbox = Sandbox { instruction_budget: 1_000_000, ..Default::default() };
    let mut cap = ThinkingCap::with_behavior(dir.path(), "spin", sandbox).unwrap();
    for t in 1..mrt_script::RUNAWAY_LIMIT {
        let c = cap.cycle(ball_at(500.0, u64::from(t) * 100));
        assert!(matches!(c.errors[..], [ScriptError::Budget { .. }]), "{:?}", c.errors);
        assert!(!cap.stopped());
    }
    let c = cap.cycle(ball_at(500.0, 1000));
    assert!(
        matches!(
            c.errors[..],
            [ScriptError::Budget { .. }, ScriptError::Stopped { cycles: 3, .. }]
        ),
        "{:?}",
        c.errors
    );
    assert!(cap.stopped());
    // Stopped: the safe command, no error repeated, no Lua run (the budget is not spent).
    for t in 11..20 {
        let c = cap.cycle(ball_at(500.0, t * 100));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        assert_eq!(c.command, RobotCommand::default());
    }
    // A fixed behavior is reloaded: the robot runs again.
    dir.edit("spin.lua", r#"always("go", "FAST")"#);
    let (done, errors) = cap.reload_changed();
    assert!(errors.is_empty() && done.len() == 1, "{done:?} {errors:?}");
    let c = cap.cycle(ball_at(500.0, 3000));
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!(c.command.vlin(), 300.0);
}

/// A behavior directory whose `blocker` calls `block()`, a Rust function the factory adds to
/// the robot API: it sleeps while `hold` is set, where no instruction hook can see it.
fn blocking_robot(
    dir: &Dir,
    hold: std::sync::Arc<std::sync::atomic::AtomicBool>,
) -> impl Fn() -> Result<ThinkingCap, ScriptError> + Send + Sync + 'static {
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("blocker.lua", r#"always("go", "FAST") block()"#);
    let path = dir.path().to_path_buf();
    move || {
        let cap = ThinkingCap::with_behavior(&path, "blocker", Sandbox::default())?;
        let hold = hold.clone();
        let block = cap
            .runtime()
            .lua()
            .create_function(move |_, ()| {
                while hold.load(std::sync::atomic::Ordering::Relaxed) {
                    std::thread::sleep(Duration::from_millis(5));
                }
                Ok(())
            })
            .map_err(|e| ScriptError::Setup(e.to_string()))?;
        cap.runtime()
            .lua()
            .globals()
            .set("block", block)
            .map_err(|e| ScriptError::Setup(e.to_string()))?;
        Ok(cap)
    }
}

#[test]
fn the_watchdog_stops_a_behavior_that_blocks_where_the_hook_cannot_see() {
    use mrt_script::Watchdog;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    let dir = Dir::new("watchdog");
    let hold = Arc::new(AtomicBool::new(false));
    let deadline = Duration::from_millis(100);
    let mut robot =
        Watchdog::start("blocker", deadline, blocking_robot(&dir, hold.clone())).unwrap();
    // A teammate with an ordinary behavior, in a watchdog of its own.
    let mate_dir = Dir::new("watchdog-mate");
    mate_dir.write("hbm.lua", SINGLETON_HBM);
    mate_dir.write("walker.lua", r#"always("go", "SLOW")"#);
    let mate_path = mate_dir.path().to_path_buf();
    let mut mate = Watchdog::start("mate", deadline, move || {
        ThinkingCap::with_behavior(&mate_path, "walker", Sandbox::default())
    })
    .unwrap();
    let c = robot.cycle(ball_at(500.0, 0));
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!(c.command.vlin(), 300.0);

    // The behavior blocks (until the end of the test): the cycle ends at the deadline with the
    // safe command and the watchdog's error, and the robot is stopped.
    hold.store(true, Ordering::Relaxed);
    let started = std::time::Instant::now();
    let c = robot.cycle(ball_at(500.0, 100));
    let took = started.elapsed();
    assert!(took >= deadline, "{took:?}");
    assert!(
        matches!(&c.errors[..], [ScriptError::Watchdog { deadline_ms: 100, file }] if file == "blocker"),
        "{:?}",
        c.errors
    );
    assert_eq!(c.command, RobotCommand::default());
    assert!(robot.stopped());
    // Later cycles do not wait for it: the safe command at once, the error not repeated;
    // the teammate runs normally all the while.
    for t in 2..50 {
        let c = robot.cycle(ball_at(500.0, t * 100));
        assert!(c.errors.is_empty() && c.command == RobotCommand::default());
        let m = mate.cycle(ball_at(500.0, t * 100));
        assert!(m.errors.is_empty(), "{:?}", m.errors);
        assert_eq!(m.command.vlin(), 100.0);
    }
    // The back-off is over but the blocked call still runs: the restart waits for it. Once
    // it ends, the robot restarts from its files by itself, saying so once.
    hold.store(false, Ordering::Relaxed);
    let mut restarted = None;
    for t in 50..250 {
        let c = robot.cycle(ball_at(500.0, t * 100));
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        if c.command.vlin() == 300.0 {
            restarted = Some(c.reloaded);
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(restarted, Some(vec!["blocker".to_string()]));
    assert!(!robot.stopped());
    let c = robot.cycle(ball_at(500.0, 30_000));
    assert!(c.errors.is_empty() && c.reloaded.is_empty(), "{:?}", c.errors);
    assert_eq!(c.command.vlin(), 300.0);
}

/// Behaviors that keep failing stop the robot, which stands still for the back-off and then
/// restarts from its files: the edited file if it was fixed meanwhile, and a longer back-off
/// if it fails again. Counted in cycles, so a simulated match stays deterministic.
#[test]
fn a_stopped_robot_restarts_from_its_files_after_a_back_off() {
    use mrt_script::{Watchdog, FAULT_LIMIT, RESTART_AFTER};
    let dir = Dir::new("backoff");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("broken.lua", r#"always("go", "FAST") error("broken")"#);
    let path = dir.path().to_path_buf();
    let mut robot = Watchdog::start("broken", Duration::from_secs(5), move || {
        ThinkingCap::with_behavior(&path, "broken", Sandbox::default())
    })
    .unwrap();
    let mut t = 0;
    let mut cycle = |robot: &mut Watchdog| {
        t += 1;
        robot.cycle(ball_at(500.0, t * 100))
    };
    // Stopped after FAULT_LIMIT failing cycles, said once.
    for k in 1..=FAULT_LIMIT {
        let c = cycle(&mut robot);
        assert!(!c.errors.is_empty(), "cycle {k} fails");
    }
    assert!(robot.stopped());
    assert_eq!(robot.restart_in(), Some(RESTART_AFTER));
    for _ in 0..RESTART_AFTER {
        let c = cycle(&mut robot);
        assert!(c.errors.is_empty() && c.command == RobotCommand::default(), "{:?}", c.errors);
    }
    // Restarted: the same broken file fails again, which on probation stops it at once, and
    // the next back-off is twice as long.
    let c = cycle(&mut robot);
    assert_eq!(c.reloaded, vec!["broken".to_string()]);
    assert!(!c.errors.is_empty());
    assert!(robot.stopped());
    assert_eq!(robot.restart_in(), Some(2 * RESTART_AFTER));
    // Fixed during the wait: the restart runs the fixed file.
    dir.edit("broken.lua", r#"always("go", "FAST")"#);
    for _ in 0..2 * RESTART_AFTER {
        assert_eq!(cycle(&mut robot).command, RobotCommand::default());
    }
    let c = cycle(&mut robot);
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!(c.command.vlin(), 300.0);
    assert!(!robot.stopped());
}

#[test]
fn a_panicking_behavior_thread_is_reported_and_restarted() {
    use mrt_script::Watchdog;
    let dir = Dir::new("panics");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("bomb.lua", r#"always("go", "FAST") if boom then boom() end"#);
    let path = dir.path().to_path_buf();
    let armed = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let arm = armed.clone();
    let mut robot = Watchdog::start("bomb", Duration::from_secs(5), move || {
        let cap = ThinkingCap::with_behavior(&path, "bomb", Sandbox::default())?;
        // A faulty extension of the robot API panics on the first call after each start.
        let arm = arm.clone();
        let boom = cap
            .runtime()
            .lua()
            .create_function(move |_, ()| {
                if arm.swap(false, std::sync::atomic::Ordering::Relaxed) {
                    panic!("a bug in a Rust extension");
                }
                Ok(())
            })
            .map_err(|e| ScriptError::Setup(e.to_string()))?;
        cap.runtime()
            .lua()
            .globals()
            .set("boom", boom)
            .map_err(|e| ScriptError::Setup(e.to_string()))?;
        Ok(cap)
    })
    .unwrap();
    let c = robot.cycle(ball_at(500.0, 0));
    assert!(c.errors[0].to_string().contains("restart 1 of"), "{:?}", c.errors);
    assert_eq!(c.command, RobotCommand::default());
    assert!(!robot.stopped(), "restarted");
    let c = robot.cycle(ball_at(500.0, 100));
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!(c.command.vlin(), 300.0);
    assert!(!armed.load(std::sync::atomic::Ordering::Relaxed));
}

/// A restarted robot is on probation: the first cycle that runs away again stops it at once,
/// so that a hostile behavior costs one cycle per restart, not three.
#[test]
fn a_restarted_robot_that_runs_away_again_is_stopped_at_once() {
    use mrt_script::{Watchdog, RESTART_AFTER, RUNAWAY_LIMIT};
    let dir = Dir::new("probation");
    dir.write("hbm.lua", SINGLETON_HBM);
    dir.write("spin.lua", "while true do end");
    let path = dir.path().to_path_buf();
    let sandbox = Sandbox { instruction_budget: 100_000, ..Sandbox::default() };
    let mut robot = Watchdog::start("spin", Duration::from_secs(5), move || {
        ThinkingCap::with_behavior(&path, "spin", sandbox)
    })
    .unwrap();
    let mut t = 0;
    let mut cycle = |robot: &mut Watchdog| {
        t += 1;
        let c = robot.cycle(ball_at(500.0, t * 100));
        c.errors.iter().filter(|e| matches!(e, ScriptError::Budget { .. })).count()
    };
    let first: usize = (0..RUNAWAY_LIMIT).map(|_| cycle(&mut robot)).sum();
    assert!(robot.stopped());
    assert_eq!(first, RUNAWAY_LIMIT as usize);
    let again: usize = (0..=RESTART_AFTER).map(|_| cycle(&mut robot)).sum();
    // Restarted, ran away once, stopped again with twice the back-off.
    assert!(robot.stopped());
    assert_eq!(again, 1);
    assert_eq!(robot.restart_in(), Some(2 * RESTART_AFTER));
}
