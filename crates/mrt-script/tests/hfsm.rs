//! Hierarchical finite state machines (ThinkingCap/TeamChaos report §5.1) with small inline machines: entering
//! through nested meta-states, transition priorities (meta-states first), enter/exit hooks,
//! string and function tests with fuzzy results, `hfsm.*` seen by scripts, reuse of a
//! meta-state, load-time and runtime errors, reload, and Graphviz output.

#![allow(clippy::unwrap_used)]

use mrt_core::frames::metres;
use mrt_core::Time;
use mrt_msgs::robot::{lps, Lpo, WorldSnapshot};
use mrt_script::chaos::{install, GlobalValue, RobotIo};
use mrt_script::hfsm::{Hfsm, Taken};
use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError};
use std::cell::RefCell;
use std::rc::Rc;

/// A sandboxed runtime with `chaos` installed.
fn setup() -> (LuaRuntime, Rc<RefCell<RobotIo>>) {
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    (rt, io)
}

/// Loads `source` as `test.hfsm.lua`.
fn load(source: &str) -> (LuaRuntime, Rc<RefCell<RobotIo>>, Hfsm) {
    let (rt, io) = setup();
    let h = Hfsm::from_source(&rt, "test.hfsm.lua", source, io.clone()).unwrap();
    (rt, io, h)
}

/// The load error of `source`.
fn load_err(source: &str) -> ScriptError {
    let (rt, io) = setup();
    match Hfsm::from_source(&rt, "bad.hfsm.lua", source, io) {
        Ok(_) => panic!("loaded:\n{source}"),
        Err(e) => e,
    }
}

/// A world at `t_ms` with the ball at `rho` mm straight ahead.
fn world(t_ms: u64, rho: f64) -> WorldSnapshot {
    let mut w = WorldSnapshot { time: Time::from_millis(t_ms), ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: metres(rho), theta: 0.0, reliability: 0.9, seen_ago: 0.0 };
    w
}

/// One cycle: a new world, then a step.
fn step(
    rt: &LuaRuntime,
    io: &Rc<RefCell<RobotIo>>,
    h: &mut Hfsm,
    w: WorldSnapshot,
) -> Result<Option<Taken>, ScriptError> {
    io.borrow_mut().new_cycle(w);
    h.step(rt)
}

/// Evaluates a Lua expression in the runtime the machine runs in (its globals included).
fn eval<R: mlua::FromLuaMulti>(rt: &LuaRuntime, expr: &str) -> R {
    Script::from_source(rt, "probe.lua", &format!("return {expr}"), LoadStrategy::Compiled)
        .unwrap()
        .call(rt)
        .unwrap()
}

/// The hook log a machine kept in the Lua global `LOG`, joined by spaces.
fn log(rt: &LuaRuntime) -> String {
    eval(rt, "table.concat(LOG or {}, ' ')")
}

/// Clears `LOG`.
fn clear_log(rt: &LuaRuntime) {
    Script::from_source(rt, "clear.lua", "LOG = {}", LoadStrategy::Compiled)
        .unwrap()
        .call::<()>(rt)
        .unwrap();
}

fn taken_name(t: &Option<Taken>) -> Option<(&str, &str, &str)> {
    t.as_ref().map(|t| (t.machine.as_str(), t.name.as_str(), t.path.as_str()))
}

/// Hooks for each state: `enter`/`exit` append `+Name`/`-Name` to LOG, `run` appends `Name`.
const LOGGED: &str = r#"
LOG = {}
local function note(s) return function() LOG[#LOG + 1] = s end end
local function st(name) return { run = note(name), enter = note("+" .. name), exit = note("-" .. name) } end
local function ms(name, machine) return { meta = machine, enter = note("+" .. name), exit = note("-" .. name) } end
"#;

#[test]
fn the_initial_state_is_entered_through_nested_meta_states() {
    let src = format!(
        r#"{LOGGED}
        machine "Top" {{ initial = "Meta", states = {{ Meta = ms("Meta", "Mid"), Other = st("Other") }} }}
        machine "Mid" {{ initial = "Deeper", states = {{ Deeper = ms("Deeper", "Leafs"), Side = st("Side") }} }}
        machine "Leafs" {{ initial = "Inner", states = {{ Inner = st("Inner"), Else = st("Else") }} }}
        "#
    );
    let (rt, io, mut h) = load(&src);
    assert_eq!(h.root(), "Top");
    assert_eq!(h.machine_names(), ["Top", "Mid", "Leafs"]);
    assert_eq!(h.path(), "", "nothing active before the first step");
    // The first step enters Top's initial state Meta, then Mid's initial Deeper, then Leafs'
    // initial Inner (enter hooks outermost first), takes no transition, and runs Inner.
    assert_eq!(step(&rt, &io, &mut h, world(0, 1000.0)).unwrap(), None);
    assert_eq!(h.path(), "Top/Meta/Deeper/Inner");
    assert_eq!(log(&rt), "+Meta +Deeper +Inner Inner");
    // Later steps only run the leaf.
    step(&rt, &io, &mut h, world(100, 1000.0)).unwrap();
    assert_eq!(log(&rt), "+Meta +Deeper +Inner Inner Inner");
}

#[test]
fn the_root_is_the_first_machine_no_other_uses() {
    // Sub is defined first but used by Main: Main is the root.
    let (rt, io, mut h) = load(
        r#"machine "Sub" { initial = "S", states = { S = true } }
           machine "Main" { initial = "M", states = { M = meta "Sub" } }"#,
    );
    assert_eq!(h.root(), "Main");
    assert_eq!(h.machine_names(), ["Main", "Sub"]);
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    assert_eq!(h.path(), "Main/M/S");
}

#[test]
fn transitions_are_checked_by_priority_then_file_order() {
    // Four transitions from A all pass. Priorities 2, 1, 1, 5: the two at priority 1 come
    // first, and of those the one written first (ToC) wins. With ToC gone, ToD wins (file
    // order among equals); with a negative priority, that one beats everything.
    let src = |extra: &str| {
        format!(
            r#"machine "P" {{
              initial = "A",
              states = {{ A = true, B = true, C = true, D = true, E = true }},
              transitions = {{
                {{ name = "ToB", from = "A", to = "B", priority = 2, test = "true" }},
                {{ name = "ToC", from = "A", to = "C", priority = 1, test = "GO_C" }},
                {{ name = "ToD", from = "A", to = "D", priority = 1, test = "true" }},
                {{ name = "ToE", from = "A", to = "E", priority = 5, test = "true" }},
                {extra}
              }},
            }}
            GO_C = true"#
        )
    };
    let (rt, io, mut h) = load(&src(""));
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    assert_eq!(h.path(), "P/A");
    let t = step(&rt, &io, &mut h, world(100, 0.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("P", "ToC", "P/C")));

    let (rt, io, mut h) = load(&src("").replace("GO_C = true", "GO_C = false"));
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    let t = step(&rt, &io, &mut h, world(100, 0.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("P", "ToD", "P/D")));

    // Default priority 0 is checked before 1; an unnamed transition is called `from->to`.
    let (rt, io, mut h) = load(&src(r#"{ from = "A", to = "E", test = "true" }"#));
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    let t = step(&rt, &io, &mut h, world(100, 0.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("P", "A->E", "P/E")));

    let (rt, io, mut h) =
        load(&src(r#"{ name = "First", from = "A", to = "B", priority = -1, test = "true" }"#));
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    let t = step(&rt, &io, &mut h, world(100, 0.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("P", "First", "P/B")));
}

#[test]
fn at_most_one_transition_per_cycle() {
    // A -> B -> C both always pass: one hop per step.
    let (rt, io, mut h) = load(
        r#"machine "Chain" { initial = "A", states = { A = true, B = true, C = true },
             transitions = { { from = "A", to = "B", test = "true" }, { from = "B", to = "C", test = "true" } } }"#,
    );
    let mut paths = Vec::new();
    for k in 0..4 {
        step(&rt, &io, &mut h, world(k * 100, 0.0)).unwrap();
        paths.push(h.path());
    }
    assert_eq!(paths, ["Chain/A", "Chain/B", "Chain/C", "Chain/C"]);
}

#[test]
fn the_enclosing_meta_states_transitions_win_over_the_inner_states() {
    // In Outer/M/X both Outer's M->Out and Inner's X->Y pass in the same cycle: the seed says
    // transitions from meta-states are checked first, so M->Out is taken and X->Y is not.
    let src = format!(
        r#"{LOGGED}
        machine "Outer" {{
          initial = "M",
          states = {{ M = ms("M", "Inner"), Out = st("Out") }},
          transitions = {{ {{ name = "Leave", from = "M", to = "Out", priority = 9, test = "chaos.lps_getLpo(BALL).rho > 1000" }} }},
        }}
        machine "Inner" {{
          initial = "X",
          states = {{ X = st("X"), Y = st("Y") }},
          transitions = {{ {{ name = "Hop", from = "X", to = "Y", priority = -9, test = "chaos.lps_getLpo(BALL).rho > 500" }} }},
        }}"#
    );
    let (rt, io, mut h) = load(&src);
    step(&rt, &io, &mut h, world(0, 100.0)).unwrap();
    assert_eq!(h.path(), "Outer/M/X");
    clear_log(&rt);
    // rho 2000: both tests pass; the enclosing one wins despite its larger priority number.
    let t = step(&rt, &io, &mut h, world(100, 2000.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("Outer", "Leave", "Outer/Out")));
    // Exit hooks innermost first, then the new state's enter hook, then its code.
    assert_eq!(log(&rt), "-X -M +Out Out");

    // Only the inner test passes (rho 700): the inner transition is taken.
    let (rt, io, mut h) = load(&src);
    step(&rt, &io, &mut h, world(0, 100.0)).unwrap();
    clear_log(&rt);
    let t = step(&rt, &io, &mut h, world(100, 700.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("Inner", "Hop", "Outer/M/Y")));
    assert_eq!(log(&rt), "-X +Y Y", "the meta-state M is neither left nor re-entered");
    // From inside Y, the meta-state's transition still applies.
    let t = step(&rt, &io, &mut h, world(200, 2000.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("Outer", "Leave", "Outer/Out")));
}

#[test]
fn enter_and_exit_hooks_run_in_order_into_and_out_of_meta_states() {
    let src = format!(
        r#"{LOGGED}
        machine "Top" {{
          initial = "A",
          states = {{ A = st("A"), M = ms("M", "Sub") }},
          transitions = {{
            {{ name = "In", from = "A", to = "M", test = "STEP == 'in'" }},
            {{ name = "Out", from = "M", to = "A", test = "STEP == 'out'" }},
            {{ name = "Again", from = "M", to = "M", test = "STEP == 'again'" }},
          }},
        }}
        machine "Sub" {{
          initial = "X",
          states = {{ X = st("X"), N = ms("N", "Leaf") }},
          transitions = {{ {{ name = "Down", from = "X", to = "N", test = "STEP == 'down'" }} }},
        }}
        machine "Leaf" {{ initial = "L", states = {{ L = st("L") }} }}"#
    );
    let (rt, io, mut h) = load(&src);
    let mut t_ms = 0;
    let mut run = |h: &mut Hfsm, what: &str| {
        Script::from_source(&rt, "set.lua", &format!("STEP = '{what}'"), LoadStrategy::Compiled)
            .unwrap()
            .call::<()>(&rt)
            .unwrap();
        clear_log(&rt);
        t_ms += 100;
        step(&rt, &io, h, world(t_ms, 0.0)).unwrap();
        (h.path(), log(&rt))
    };
    assert_eq!(run(&mut h, "none"), ("Top/A".into(), "+A A".into()));
    assert_eq!(run(&mut h, "in"), ("Top/M/X".into(), "-A +M +X X".into()));
    assert_eq!(run(&mut h, "down"), ("Top/M/N/L".into(), "-X +N +L L".into()));
    // Leaving M from three levels down: exit hooks innermost first.
    assert_eq!(run(&mut h, "out"), ("Top/A".into(), "-L -N -M +A A".into()));
    assert_eq!(run(&mut h, "in"), ("Top/M/X".into(), "-A +M +X X".into()));
    // A self-transition of a meta-state leaves it and enters it again, at its initial state.
    assert_eq!(run(&mut h, "down"), ("Top/M/N/L".into(), "-X +N +L L".into()));
    assert_eq!(run(&mut h, "again"), ("Top/M/X".into(), "-L -N -M +M +X X".into()));
}

#[test]
fn string_predicates_and_functions_as_tests_with_fuzzy_results() {
    // A test passes on true, on an integer >= 1, or on a float >= 0.5 (a fuzzy truth value);
    // false, nil, 0, 0.4 or a string do not.
    let cases: [(&str, bool); 12] = [
        ("true", true),
        ("false", false),
        ("nil", false),
        ("0.6", true),
        ("0.5", true),
        ("0.4", false),
        ("0.49999", false),
        ("1", true),
        ("0", false),
        ("'yes'", false),
        ("function() return 0.6 end", true),
        ("function() return 0.4 end", false),
    ];
    for (test, passes) in cases {
        let test_lua =
            if test.starts_with("function") { test.to_string() } else { format!("{test:?}") };
        let src = format!(
            r#"machine "F" {{ initial = "A", states = {{ A = true, B = true }},
                 transitions = {{ {{ name = "T", from = "A", to = "B", test = {test_lua} }} }} }}"#
        );
        let (rt, io, mut h) = load(&src);
        step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
        let t = step(&rt, &io, &mut h, world(100, 0.0)).unwrap();
        assert_eq!(t.is_some(), passes, "test {test}");
        assert_eq!(h.path(), if passes { "F/B" } else { "F/A" }, "test {test}");
    }
    // A predicate reading the world: a fuzzy "ball close" TOL-like ramp from 250 to 750 mm,
    // written in Lua: at 400 mm it is (750 - 400) / 500 = 0.7 (passes), at 600 mm 0.3 (not).
    let src = r#"
        local function close()
          local rho = chaos.lps_getLpo(BALL).rho
          return math.max(0, math.min(1, (750 - rho) / 500))
        end
        machine "F" { initial = "Far", states = { Far = true, Near = true },
          transitions = { { name = "Close", from = "Far", to = "Near", test = close } } }"#;
    let (rt, io, mut h) = load(src);
    step(&rt, &io, &mut h, world(0, 600.0)).unwrap();
    assert_eq!(step(&rt, &io, &mut h, world(100, 600.0)).unwrap(), None);
    let t = step(&rt, &io, &mut h, world(200, 400.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("F", "Close", "F/Near")));
}

#[test]
fn scripts_see_the_path_the_state_and_the_time_in_the_state() {
    let src = r#"
      local function record()
        chaos.setGlobal("path", STRING, hfsm.path())
        chaos.setGlobal("state", STRING, hfsm.state())
        chaos.setGlobal("time", FLOAT, hfsm.time())
      end
      machine "Top" { initial = "Wait", states = { Wait = record, Go = meta "Sub" },
        transitions = { { name = "Start", from = "Wait", to = "Go", test = "chaos.lps_getLpo(BALL).rho > 1000" } } }
      machine "Sub" { initial = "Run", states = { Run = record } }"#;
    let (rt, io, mut h) = load(src);
    let seen = |io: &Rc<RefCell<RobotIo>>| {
        let io = io.borrow();
        let s = |k: &str| match io.global(k) {
            Some(GlobalValue::String(s)) => s.clone(),
            other => panic!("{k}: {other:?}"),
        };
        let t = match io.global("time") {
            Some(GlobalValue::Float(t)) => *t,
            other => panic!("time: {other:?}"),
        };
        (s("path"), s("state"), t)
    };
    // Entered Wait at 1000 ms: 0 ms in the state.
    step(&rt, &io, &mut h, world(1000, 0.0)).unwrap();
    assert_eq!(seen(&io), ("Top/Wait".into(), "Wait".into(), 0.0));
    // 1250 ms: 250 ms in Wait.
    step(&rt, &io, &mut h, world(1250, 0.0)).unwrap();
    assert_eq!(seen(&io), ("Top/Wait".into(), "Wait".into(), 250.0));
    assert!((h.time_in_state(Time::from_millis(1300)) - 300.0).abs() < 1e-9);
    // 1400 ms: the transition enters Go/Run, whose clock starts at 1400.
    step(&rt, &io, &mut h, world(1400, 2000.0)).unwrap();
    assert_eq!(seen(&io), ("Top/Go/Run".into(), "Run".into(), 0.0));
    // 1900 ms: 500 ms in Run.
    step(&rt, &io, &mut h, world(1900, 2000.0)).unwrap();
    assert_eq!(seen(&io), ("Top/Go/Run".into(), "Run".into(), 500.0));
    assert_eq!(h.path(), "Top/Go/Run");
    // The same functions in a plain script of the runtime.
    assert_eq!(eval::<String>(&rt, "hfsm.path() .. ' ' .. hfsm.state()"), "Top/Go/Run Run");
}

#[test]
fn a_meta_state_machine_is_reused_from_two_places() {
    // Score is one machine used by the states Attack and Counter; each entry starts it at its
    // initial state, and its own transitions work in both places.
    let src = format!(
        r#"{LOGGED}
        machine "Game" {{
          initial = "Attack",
          states = {{ Attack = ms("Attack", "Score"), Counter = ms("Counter", "Score") }},
          transitions = {{
            {{ name = "Swap", from = "Attack", to = "Counter", test = "chaos.lps_getLpo(BALL).rho > 5000" }},
          }},
        }}
        machine "Score" {{
          initial = "Approach",
          states = {{ Approach = st("Approach"), Kick = st("Kick") }},
          transitions = {{ {{ name = "Kickable", from = "Approach", to = "Kick", test = "chaos.lps_getLpo(BALL).rho < 600" }} }},
        }}"#
    );
    let (rt, io, mut h) = load(&src);
    assert_eq!(h.root(), "Game");
    let mut paths = Vec::new();
    let mut taken = Vec::new();
    for (k, rho) in [1000.0, 500.0, 9000.0, 1000.0, 300.0].into_iter().enumerate() {
        let t = step(&rt, &io, &mut h, world(k as u64 * 100, rho)).unwrap();
        paths.push(h.path());
        taken.push(t.map(|t| format!("{}.{}", t.machine, t.name)));
    }
    assert_eq!(
        paths,
        [
            "Game/Attack/Approach",
            "Game/Attack/Kick",
            "Game/Counter/Approach", // re-entered at its initial state from the other place
            "Game/Counter/Approach",
            "Game/Counter/Kick",
        ]
    );
    assert_eq!(
        taken,
        [
            None,
            Some("Score.Kickable".into()),
            Some("Game.Swap".into()),
            None,
            Some("Score.Kickable".into())
        ]
    );
    assert_eq!(
        log(&rt),
        "+Attack +Approach Approach -Approach +Kick Kick -Kick -Attack +Counter +Approach \
         Approach Approach -Approach +Kick Kick"
    );
}

/// The message of an `Invalid` error, checking its file and line.
fn invalid(e: &ScriptError, want_line: usize) -> String {
    match e {
        ScriptError::Invalid { file, line, message } => {
            assert_eq!((file.as_str(), *line), ("bad.hfsm.lua", want_line), "{e}");
            assert_eq!(e.to_string(), format!("bad.hfsm.lua:{want_line}: {message}"));
            message.clone()
        }
        other => panic!("not Invalid: {other:?}"),
    }
}

#[test]
fn a_meta_state_containing_itself_is_refused_with_the_chain() {
    // Directly: Loop's state L is Loop itself. The line is that of `machine "Loop"`.
    let e = load_err(
        "machine \"Top\" { initial = \"A\", states = { A = meta \"Loop\" } }\n\
         machine \"Loop\" { initial = \"L\", states = { L = meta \"Loop\" } }",
    );
    assert_eq!(invalid(&e, 2), "meta-state machine 'Loop' contains itself: Loop -> Loop");
    // Through another machine: Top -> A -> B -> A.
    let e = load_err(
        "machine \"Top\" { initial = \"S\", states = { S = meta \"A\" } }\n\
         machine \"A\" { initial = \"X\", states = { X = meta \"B\" } }\n\
         machine \"B\" { initial = \"Y\", states = { Y = true, Z = meta \"A\" } }",
    );
    assert_eq!(invalid(&e, 2), "meta-state machine 'A' contains itself: A -> B -> A");
    // Three machines in a ring, none of them a root.
    let e = load_err(
        "machine \"P\" { initial = \"a\", states = { a = meta \"Q\" } }\n\
         machine \"Q\" { initial = \"b\", states = { b = meta \"R\" } }\n\
         machine \"R\" { initial = \"c\", states = { c = meta \"P\" } }",
    );
    assert_eq!(invalid(&e, 1), "meta-state machine 'P' contains itself: P -> Q -> R -> P");
}

#[test]
fn definition_errors_are_refused_at_load_with_the_reason() {
    // A transition to an unknown state.
    let e = load_err(
        "-- line 1\nmachine \"M\" { initial = \"A\", states = { A = true, B = true },\n\
         transitions = { { name = \"Go\", from = \"A\", to = \"Nowhere\", test = \"true\" } } }",
    );
    assert_eq!(
        invalid(&e, 2),
        "machine 'M': transition 'Go' names unknown state 'Nowhere' (states: A, B)"
    );
    // From an unknown state.
    let e = load_err(
        "machine \"M\" { initial = \"A\", states = { A = true },\n\
         transitions = { { from = \"Ghost\", to = \"A\", test = \"true\" } } }",
    );
    assert_eq!(
        invalid(&e, 1),
        "machine 'M': transition 'Ghost->A' names unknown state 'Ghost' (states: A)"
    );
    // An unknown initial state.
    let e = load_err("machine \"M\" { initial = \"Start\", states = { A = true, B = true } }");
    assert_eq!(
        invalid(&e, 1),
        "machine 'M': initial state 'Start' is not one of its states (A, B)"
    );
    // No initial state, no states.
    let e = load_err("machine \"M\" { states = { A = true } }");
    assert_eq!(invalid(&e, 1), "machine 'M': has no initial state");
    let e = load_err("machine \"M\" { initial = \"A\", states = {} }");
    assert_eq!(invalid(&e, 1), "machine 'M': has no states");
    // A meta-state naming an undefined machine.
    let e = load_err("\n\nmachine \"M\" { initial = \"A\", states = { A = meta \"Missing\" } }");
    assert_eq!(
        invalid(&e, 3),
        "machine 'M': meta-state 'A' uses machine 'Missing', which is not defined"
    );
    // A state of the wrong kind.
    let e = load_err("machine \"M\" { initial = \"A\", states = { A = 42 } }");
    assert!(invalid(&e, 1).contains("state 'A' must be a function"), "{e}");
    // A transition without a test.
    let e = load_err(
        "machine \"M\" { initial = \"A\", states = { A = true }, transitions = { { name = \"T\", from = \"A\", to = \"A\" } } }",
    );
    assert!(invalid(&e, 1).contains("transition 'T' has no test"), "{e}");
    // A machine defined twice: the second definition's line.
    let e = load_err(
        "machine \"M\" { initial = \"A\", states = { A = true } }\n\
         machine \"M\" { initial = \"A\", states = { A = true } }",
    );
    assert_eq!(invalid(&e, 2), "machine 'M' is defined twice");
    // A file with no machine at all.
    let e = load_err("local x = 1 -- nothing here");
    assert_eq!(invalid(&e, 0), "no machine defined (write `machine \"Name\" { ... }`)");
}

#[test]
fn a_syntax_error_in_a_string_test_is_refused_at_load() {
    let e = load_err(
        "machine \"M\" { initial = \"A\", states = { A = true, B = true },\n\
         transitions = { { name = \"Broken\", from = \"A\", to = \"B\", test = \"chaos.lps_getLpo(BALL).rho <\" } } }",
    );
    let msg = invalid(&e, 1);
    assert!(
        msg.starts_with(
            "machine 'M': transition 'Broken': bad test `chaos.lps_getLpo(BALL).rho <`: "
        ),
        "{msg}"
    );
    assert!(msg.contains("unexpected symbol"), "{msg}");
    // A syntax error in the file itself is a Syntax error at its line.
    let e = load_err(
        "machine \"M\" {\n initial = \"A\",\n states = { A = function() return end end },\n}",
    );
    match &e {
        ScriptError::Syntax { file, line, .. } => {
            assert_eq!((file.as_str(), *line), ("bad.hfsm.lua", 3), "{e}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn a_runtime_error_in_state_code_names_the_file_and_line_and_the_next_step_works() {
    let src = "machine \"M\" {\n\
               initial = \"A\",\n\
               states = { A = function()\n\
                 if chaos.lps_getLpo(BALL).rho > 1000 then error('ball too far') end\n\
                 chaos.setVlin(chaos.lps_getLpo(BALL).rho)\n\
               end },\n\
               }";
    let (rt, io, mut h) = load(src);
    step(&rt, &io, &mut h, world(0, 300.0)).unwrap();
    assert_eq!(io.borrow().command.vlin(), 300.0);
    let e = step(&rt, &io, &mut h, world(100, 2000.0)).unwrap_err();
    match &e {
        ScriptError::Runtime { file, line, message, .. } => {
            assert_eq!((file.as_str(), *line), ("test.hfsm.lua", 4), "{e}");
            assert_eq!(message, "ball too far");
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().starts_with("test.hfsm.lua:4: runtime error: ball too far"), "{e}");
    // The machine is still in A and the next step runs normally.
    step(&rt, &io, &mut h, world(200, 500.0)).unwrap();
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("M/A", 500.0));

    // An endless loop in a test is stopped by the budget; the next step works.
    let (rt, io) = {
        let rt =
            LuaRuntime::new(Sandbox { instruction_budget: 100_000, ..Default::default() }).unwrap();
        let io = Rc::new(RefCell::new(RobotIo::default()));
        install(&rt, io.clone()).unwrap();
        (rt, io)
    };
    let mut h = Hfsm::from_source(
        &rt,
        "spin.hfsm.lua",
        r#"machine "S" { initial = "A", states = { A = true, B = true },
             transitions = { { from = "A", to = "B", test = function()
               while chaos.lps_getLpo(BALL).rho > 1000 do end return true end } } }"#,
        io.clone(),
    )
    .unwrap();
    step(&rt, &io, &mut h, world(0, 2000.0)).unwrap();
    let e = step(&rt, &io, &mut h, world(100, 2000.0)).unwrap_err();
    assert!(matches!(e, ScriptError::Budget { budget: 100_000, line: 3, .. }), "{e}");
    assert!(e.to_string().starts_with("spin.hfsm.lua:3: aborted"), "{e}");
    assert_eq!(h.path(), "S/A");
    let t = step(&rt, &io, &mut h, world(200, 100.0)).unwrap();
    assert_eq!(taken_name(&t), Some(("S", "A->B", "S/B")));
}

#[test]
fn a_runtime_error_in_a_string_test_names_the_transition() {
    // `nothing.x` indexes a nil global.
    let (rt, io, mut h) = load(
        r#"machine "M" { initial = "A", states = { A = true, B = true },
             transitions = { { name = "Bad", from = "A", to = "B", test = "nothing.x > 1" } } }"#,
    );
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    let e = step(&rt, &io, &mut h, world(100, 0.0)).unwrap_err();
    assert!(matches!(e, ScriptError::Runtime { .. }), "{e:?}");
    let text = e.to_string();
    assert!(text.contains("test.hfsm.lua") && text.contains("Bad"), "{text}");
    assert!(text.contains("attempt to index a nil value"), "{text}");
    assert_eq!(h.path(), "M/A");
}

const V1: &str = r#"
machine "Top" { initial = "Wait", states = { Wait = function() chaos.setVlin(1) end, Play = meta "Sub" },
  transitions = { { name = "Start", from = "Wait", to = "Play", test = "chaos.lps_getLpo(BALL).rho > 1000" } } }
machine "Sub" { initial = "A", states = { A = function() chaos.setVlin(10) end, B = function() chaos.setVlin(20) end },
  transitions = { { name = "Next", from = "A", to = "B", test = "chaos.lps_getLpo(BALL).rho < 100" } } }
"#;

#[test]
fn reload_keeps_the_active_path_while_its_states_exist() {
    let (rt, io, mut h) = load(V1);
    step(&rt, &io, &mut h, world(0, 500.0)).unwrap();
    step(&rt, &io, &mut h, world(100, 2000.0)).unwrap();
    step(&rt, &io, &mut h, world(200, 50.0)).unwrap();
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("Top/Play/B", 20.0));

    // New code in B (vlin 21), a new state C: the path stays, the new code runs.
    let v2 = V1
        .replace("chaos.setVlin(20)", "chaos.setVlin(21)")
        .replace("B = function()", "C = true, B = function()");
    h.reload_source(&rt, &v2).unwrap();
    assert_eq!(h.path(), "Top/Play/B");
    assert_eq!(step(&rt, &io, &mut h, world(300, 500.0)).unwrap(), None);
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("Top/Play/B", 21.0));
    // The time in the state is kept: B was entered at 200 ms.
    assert!((h.time_in_state(Time::from_millis(350)) - 150.0).abs() < 1e-9);

    // A bad reload (syntax error, or a definition error) leaves the running machine alone.
    let e = h.reload_source(&rt, "machine \"Top\" {").unwrap_err();
    assert!(matches!(e, ScriptError::Syntax { .. }), "{e}");
    let e = h.reload_source(&rt, &v2.replace("initial = \"A\"", "initial = \"Q\"")).unwrap_err();
    assert!(e.to_string().contains("initial state 'Q'"), "{e}");
    step(&rt, &io, &mut h, world(400, 500.0)).unwrap();
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("Top/Play/B", 21.0));

    // A reload without state B: the machine starts over from the root's initial state.
    let v3 = V1
        .replace(", B = function() chaos.setVlin(20) end", "")
        .replace("to = \"B\"", "to = \"A\"");
    h.reload_source(&rt, &v3).unwrap();
    let t = step(&rt, &io, &mut h, world(500, 500.0)).unwrap();
    assert_eq!(t, None);
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("Top/Wait", 1.0));
}

#[test]
fn to_dot_draws_every_state_and_transition() {
    let src = r#"
      machine "Attacker" { initial = "FaceBall",
        states = { FaceBall = true, GoToBall = true, Score = meta "Score" },
        transitions = {
          { name = "BallAhead", from = "FaceBall", to = "GoToBall", test = "math.abs(chaos.lps_getLpo(BALL).theta) < 0.25" },
          { name = "NearBall", from = "GoToBall", to = "Score", priority = 1, test = function() return true end },
          { name = "BallAway", from = "Score", to = "GoToBall", priority = 2.5, test = "false" },
        } }
      machine "Score" { initial = "Approach", states = { Approach = true, Kick = true },
        transitions = { { from = "Approach", to = "Kick", test = "true" } } }"#;
    let (_rt, _io, h) = load(src);
    for clusters in [true, false] {
        let dot = h.to_dot(clusters);
        assert!(dot.starts_with("digraph hfsm {") && dot.trim_end().ends_with('}'), "{dot}");
        for node in [
            "\"Attacker/FaceBall\" [shape=box",
            "\"Attacker/GoToBall\" [shape=box",
            "\"Attacker/Score\" [shape=box3d, style=rounded, label=\"Score\\n[Score]\"]",
            "\"Score/Approach\" [shape=box",
            "\"Score/Kick\" [shape=box",
        ] {
            assert!(dot.contains(node), "{clusters}: no {node} in\n{dot}");
        }
        for edge in [
            "\"Attacker/FaceBall\" -> \"Attacker/GoToBall\" [label=\"BallAhead [0]\\nmath.abs(chaos.lps_getLpo(BALL).theta) < 0.25\"];",
            "\"Attacker/GoToBall\" -> \"Attacker/Score\" [label=\"NearBall [1]\\nfunction (line 6)\"];",
            "\"Attacker/Score\" -> \"Attacker/GoToBall\" [label=\"BallAway [2.5]\\nfalse\"];",
            "\"Score/Approach\" -> \"Score/Kick\" [label=\"Approach->Kick [0]\\ntrue\"];",
            // The meta-state points to the initial state of the machine it runs.
            "\"Attacker/Score\" -> \"Score/Approach\" [style=dashed",
            // Each machine's entry arrow; the root is marked.
            "\"Attacker/^\" -> \"Attacker/FaceBall\";",
            "\"Score/^\" -> \"Score/Approach\";",
            "\"Attacker/^\" [shape=point, width=0.15, label=\"Attacker (root)\"]",
            "\"Score/^\" [shape=point, width=0.15, label=\"Score\"]",
        ] {
            assert!(dot.contains(edge), "{clusters}: no {edge} in\n{dot}");
        }
        assert_eq!(dot.contains("subgraph \"cluster_Attacker\""), clusters);
        assert_eq!(dot.contains("subgraph \"cluster_Score\""), clusters);
        assert_eq!(dot.matches('{').count(), dot.matches('}').count(), "{dot}");
    }
}

/// The machine's shape as a bus message (`HfsmStructure`, for monitors): the root first, the
/// same states, meta-states and labelled transitions the dot drawing has.
#[test]
fn the_structure_has_what_the_drawing_has() {
    let src = r#"
      machine "Score" { initial = "Approach", states = { Approach = true, Kick = true },
        transitions = { { from = "Approach", to = "Kick", test = "true" } } }
      machine "Attacker" { initial = "FaceBall",
        states = { FaceBall = true, Score = meta "Score" },
        transitions = {
          { name = "NearBall", from = "FaceBall", to = "Score", priority = 1, test = "false" },
        } }"#;
    let (_rt, _io, h) = load(src);
    let s = h.structure();
    assert_eq!(s.root, "Attacker");
    let names: Vec<&str> = s.machines.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["Attacker", "Score"], "the root first");
    let attacker = &s.machines[0];
    assert_eq!(attacker.initial, "FaceBall");
    let score = attacker.states.iter().find(|st| st.name == "Score").unwrap();
    assert_eq!(score.runs.as_deref(), Some("Score"));
    let t = &attacker.transitions[0];
    assert_eq!(
        (t.name.as_str(), t.from.as_str(), t.to.as_str()),
        ("NearBall", "FaceBall", "Score")
    );
    assert_eq!((t.priority, t.test.as_str()), (1.0, "false"));
    let inner = &s.machines[1];
    assert_eq!(inner.transitions[0].name, "Approach->Kick");
    assert!(inner.states.iter().all(|st| st.runs.is_none()));
    let dot = h.to_dot(true);
    for m in &s.machines {
        for st in &m.states {
            assert!(dot.contains(&format!("\"{}/{}\"", m.name, st.name)), "{}", st.name);
        }
    }
}

/// A runtime error in a string test is attributed to the machine file, at the line of the
/// machine's definition (string tests have no lines of their own), not to the internal
/// dispatcher that runs the tests.
#[test]
fn a_runtime_error_in_a_string_test_is_attributed_to_the_machine_file() {
    let (rt, io, mut h) = load(
        r#"machine "M" { initial = "A", states = { A = true, B = true },
             transitions = { { name = "Bad", from = "A", to = "B", test = "nothing.x > 1" } } }"#,
    );
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    let e = step(&rt, &io, &mut h, world(100, 0.0)).unwrap_err();
    match &e {
        ScriptError::Runtime { file, line, message, .. } => {
            // A string test is compiled so that Lua's position is the machine's line.
            assert_eq!((file.as_str(), *line), ("test.hfsm.lua", 1), "{e:?}");
            assert!(message.contains("'nothing'"), "{e:?}");
        }
        other => panic!("{other:?}"),
    }
}

/// When the enter hook of a meta-state fails, the step returns the error, and the next step
/// finishes entering the meta-state: its initial state becomes active and runs.
#[test]
fn a_failing_enter_hook_of_a_meta_state_does_not_leave_the_machine_without_a_leaf() {
    let (rt, io, mut h) = load(
        r#"FAILS = 1
        machine "T" { initial = "A",
          states = { A = true, M = { meta = "S", enter = function()
            if FAILS > 0 then FAILS = FAILS - 1 error("enter failed") end end } },
          transitions = { { name = "In", from = "A", to = "M", test = "true" } } }
        machine "S" { initial = "X", states = { X = function() chaos.setVlin(7) end } }"#,
    );
    step(&rt, &io, &mut h, world(0, 0.0)).unwrap();
    assert_eq!(h.path(), "T/A");
    let e = step(&rt, &io, &mut h, world(100, 0.0)).unwrap_err();
    assert!(e.to_string().contains("enter failed"), "{e}");
    // The hook succeeds from now on: the next step must reach M's initial state X and run it.
    step(&rt, &io, &mut h, world(200, 0.0)).unwrap();
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("T/M/X", 7.0));
}

/// `include "x.hfsm.lua"` reuses the machines of another file of the same directory without
/// copying them; an error in an included machine names the included file; only plain names of
/// `.hfsm.lua` files are accepted, each file is read once.
#[test]
fn include_reuses_machines_from_another_file() {
    let dir = std::env::temp_dir().join(format!("mrt-hfsm-include-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("inner.hfsm.lua"),
        "machine \"Inner\" { initial = \"X\", states = { X = function() chaos.setVlin(3) end } }\n",
    )
    .unwrap();
    let main = dir.join("main.hfsm.lua");
    std::fs::write(
        &main,
        "include \"inner.hfsm.lua\"\ninclude \"inner.hfsm.lua\"\nmachine \"Top\" { initial = \"M\", states = { M = meta \"Inner\" } }\n",
    )
    .unwrap();
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    let mut h = Hfsm::from_file(&rt, &main, io.clone()).unwrap();
    assert_eq!(h.root(), "Top", "the including machine is the root");
    io.borrow_mut().new_cycle(WorldSnapshot::default());
    h.step(&rt).unwrap();
    assert_eq!((h.path().as_str(), io.borrow().command.vlin()), ("Top/M/X", 3.0));
    // An error inside the included file names that file and its line.
    std::fs::write(
        dir.join("inner.hfsm.lua"),
        "\nmachine \"Inner\" { initial = \"Nope\", states = { X = true } }\n",
    )
    .unwrap();
    let e = Hfsm::from_file(&rt, &main, io.clone()).unwrap_err().to_string();
    assert!(e.contains("inner.hfsm.lua:2:") && e.contains("Nope"), "{e}");
    for bad in ["../x.hfsm.lua", "/etc/passwd", "other.lua"] {
        std::fs::write(&main, format!("include \"{bad}\"\n")).unwrap();
        let e = Hfsm::from_file(&rt, &main, io.clone()).unwrap_err().to_string();
        assert!(e.contains("plain name"), "{bad}: {e}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_large_machine_is_drawn_whole_as_well_formed_svg() {
    let (_rt, _io, h) = load(include_str!("data/chain200.hfsm.lua"));
    let svg = h.to_svg();
    // Every state and every transition is drawn, once.
    assert_eq!(svg.matches(r#"<g class="state">"#).count(), 200 + 2);
    let transitions = 1 + 198 + 198 / 10 + 2;
    assert_eq!(svg.matches(r#"<g class="transition">"#).count(), transitions);
    assert!(svg.contains(">S198<") && svg.contains(">M [Inner]<") && svg.contains("Big (root)"));
    // Well-formed: every element closed, in order.
    let mut reader = quick_xml::Reader::from_str(&svg);
    let mut depth = 0usize;
    loop {
        match reader.read_event().unwrap() {
            quick_xml::events::Event::Start(_) => depth += 1,
            quick_xml::events::Event::End(_) => depth -= 1,
            quick_xml::events::Event::Eof => break,
            _ => {}
        }
    }
    assert_eq!(depth, 0);
}

#[test]
fn state_names_are_escaped_in_the_drawing() {
    let (_rt, _io, h) = load(
        r#"machine "M<&>" { initial = "a<b", states = { ["a<b"] = function() end, ["c&d"] = function() end },
           transitions = { { name = "x\"y", from = "a<b", to = "c&d", test = "true" } } }"#,
    );
    let svg = h.to_svg();
    assert!(svg.contains("a&lt;b") && svg.contains("c&amp;d") && svg.contains("M&lt;&amp;&gt;"));
    assert!(!svg.contains("a<b"));
}

/// A chain of `n` machines, each a meta-state of the next, written as the Lua loop a hostile
/// file would use.
fn chain(n: usize) -> String {
    format!(
        "for i = 1, {n} do\n\
           local inner = i < {n} and meta('M' .. (i + 1)) or true\n\
           machine('M' .. i) {{ initial = 's', states = {{ s = inner }} }}\n\
         end"
    )
}

#[test]
fn deep_and_huge_machines_are_refused_before_anything_deep_is_walked() {
    use mrt_script::hfsm::{MAX_MACHINES, MAX_NESTING, MAX_STATES, MAX_TRANSITIONS};
    // Run on a thread with a small stack: a walk as deep as the file would overflow it.
    let refused = std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(|| {
            let many = load_err(&chain(20_000)).to_string();
            let deep = load_err(&chain(MAX_NESTING + 1)).to_string();
            (many, deep)
        })
        .unwrap()
        .join()
        .unwrap();
    assert!(refused.0.contains(&format!("more than {MAX_MACHINES} machines")), "{}", refused.0);
    assert!(refused.1.contains(&format!("nested more than {MAX_NESTING}")), "{}", refused.1);
    assert!(refused.1.contains("M1 -> M2 -> M3"), "names the chain: {}", refused.1);
    // At the limit it loads and enters every level.
    let (rt, _io, mut h) = load(&chain(MAX_NESTING));
    h.step(&rt).unwrap();
    assert_eq!(h.path().matches('/').count(), MAX_NESTING);

    let states = |n: usize| {
        format!(
            "local s = {{}} for i = 1, {n} do s['s' .. i] = true end\n\
             machine 'Big' {{ initial = 's1', states = s }}"
        )
    };
    let e = load_err(&states(MAX_STATES + 1)).to_string();
    assert!(e.contains(&format!("more than {MAX_STATES} states")), "{e}");
    let e = load_err(&format!(
        "local t = {{}} for i = 1, {} do t[i] = {{ from = 'a', to = 'b', test = 'false' }} end\n\
         machine 'T' {{ initial = 'a', states = {{ a = true, b = true }}, transitions = t }}",
        MAX_TRANSITIONS + 1
    ))
    .to_string();
    assert!(e.contains(&format!("more than {MAX_TRANSITIONS} transitions")), "{e}");
}

#[test]
fn a_machine_at_the_size_limits_loads_quickly() {
    // Every state with transitions to its neighbours: no work grows with states × transitions.
    let n = mrt_script::hfsm::MAX_STATES;
    let source = format!(
        "local s, t = {{}}, {{}} for i = 1, {n} do s['s' .. i] = true\n\
           t[#t + 1] = {{ from = 's' .. i, to = 's' .. (i % {n} + 1), test = 'false' }}\n\
           t[#t + 1] = {{ from = 's' .. i, to = 's1', test = function() return false end }}\n\
         end\n\
         machine 'Big' {{ initial = 's1', states = s, transitions = t }}"
    );
    let started = std::time::Instant::now();
    let (rt, _io, mut h) = load(&source);
    h.step(&rt).unwrap();
    assert_eq!(h.path(), "Big/s1");
    assert!(started.elapsed().as_secs_f64() < 3.0, "{:?}", started.elapsed());
}
