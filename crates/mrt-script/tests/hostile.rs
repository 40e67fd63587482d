//! Hostile scripts: every way a tester slipped the sandbox's budget, its memory
//! limit or its output is a clear error now, and the runtime stays usable after it.

#![allow(clippy::unwrap_used)]

use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError};

fn rt() -> LuaRuntime {
    LuaRuntime::new(Sandbox { instruction_budget: 1_000_000, memory_limit: 8 << 20 }).unwrap()
}

fn run(rt: &LuaRuntime, name: &str, src: &str) -> Result<mlua::Value, ScriptError> {
    Script::from_source(rt, name, src, LoadStrategy::Compiled)?.call::<mlua::Value>(rt)
}

/// The runtime still runs an ordinary script after the hostile one.
fn still_works(rt: &LuaRuntime) {
    let v = run(rt, "ok.lua", "local s = 0 for i = 1, 100 do s = s + i end return s").unwrap();
    assert_eq!(v.as_i64(), Some(5050));
}

fn assert_budget(rt: &LuaRuntime, name: &str, src: &str) {
    let e = run(rt, name, src).unwrap_err();
    assert!(matches!(e, ScriptError::Budget { budget: 1_000_000, .. }), "{name}: {e}");
    still_works(rt);
}

#[test]
fn a_loop_inside_a_coroutine_is_metered() {
    let rt = rt();
    assert_budget(&rt, "wrap.lua", "coroutine.wrap(function() while true do end end)()");
    assert_budget(
        &rt,
        "resume.lua",
        "local co = coroutine.create(function() while true do end end) coroutine.resume(co)",
    );
    // A coroutine in a coroutine.
    assert_budget(
        &rt,
        "nested.lua",
        "coroutine.wrap(function() coroutine.wrap(function() while true do end end)() end)()",
    );
}

#[test]
fn pcall_and_xpcall_cannot_catch_an_overrun() {
    let rt = rt();
    assert_budget(&rt, "pcall.lua", "while true do pcall(function() while true do end end) end");
    assert_budget(
        &rt,
        "xpcall.lua",
        "while true do xpcall(function() while true do end end, function(m) return 'fake' end) end",
    );
    assert_budget(
        &rt,
        "resume_loop.lua",
        "while true do coroutine.resume(coroutine.create(function() while true do end end)) end",
    );
    // A message handler that replaces the text does not hide what happened.
    let e = run(
        &rt,
        "renamed.lua",
        "xpcall(function() while true do end end, function() error('x') end)",
    )
    .unwrap_err();
    assert!(matches!(e, ScriptError::Budget { .. }), "{e}");
    // pcall still catches ordinary errors.
    let v = run(&rt, "ordinary.lua", "local ok, m = pcall(error, 'boom') return tostring(ok) .. m")
        .unwrap();
    assert_eq!(v.as_string().unwrap().to_str().unwrap(), "falseboom");
}

#[test]
fn finalizers_are_refused() {
    let rt = rt();
    let e = run(&rt, "gc.lua", "setmetatable({}, {__gc = function() while true do end end})")
        .unwrap_err();
    assert!(e.to_string().contains("finalizers (__gc) are not available"), "{e}");
    // Other metatables are fine.
    let v = run(&rt, "mt.lua", "return setmetatable({}, {__index = function() return 7 end}).x")
        .unwrap();
    assert_eq!(v.as_i64(), Some(7));
    // Closing the state runs no script code.
    drop(rt);
}

#[test]
fn pathological_patterns_are_refused_before_they_run() {
    let rt = rt();
    for (name, src) in [
        ("find.lua", "local r = string.find(string.rep('a', 1e5), '.-.-.-.-.-b') return r"),
        ("match.lua", "local r = (string.rep('a', 1e5)):match('a*a*a*a*b') return r"),
        ("gsub.lua", "local r = string.gsub(string.rep('a', 1e5), 'a-a-a-b', '') return r"),
        ("gmatch.lua", "for w in string.gmatch(string.rep('a', 1e5), '.-.-.-b') do end"),
        (
            "optional.lua",
            "local r = string.find(string.rep('a', 40), string.rep('a?', 40) .. string.rep('a', 40)) return r",
        ),
    ] {
        let e = run(&rt, name, src).unwrap_err();
        assert!(
            matches!(e, ScriptError::Runtime { .. }) && e.to_string().contains("may take up to"),
            "{name}: {e}"
        );
        // The error names the script's line, not the sandbox's wrapper.
        assert!(e.to_string().starts_with(&format!("{name}:1: ")), "{e}");
    }
    still_works(&rt);
    // Ordinary uses pass, and a plain find is never refused.
    let v = run(
        &rt,
        "ordinary.lua",
        "local s = '  role=attacker;  ' local r = s:match('role=(.-);') \
         local n = select(2, ('a b c'):gsub('%s+', ' ')) \
         return r .. n .. tostring(string.find(string.rep('a', 1e5), '.-.-b', 1, true))",
    )
    .unwrap();
    assert_eq!(v.as_string().unwrap().to_str().unwrap(), "attacker2nil");
}

#[test]
fn table_move_over_a_huge_range_is_refused() {
    let rt = rt();
    let e = run(&rt, "move.lua", "table.move({}, 1, 1e15, 1, {})").unwrap_err();
    assert!(e.to_string().contains("table.move"), "{e}");
    let v = run(&rt, "move_ok.lua", "return #table.move({1, 2, 3}, 1, 3, 2)").unwrap();
    assert_eq!(v.as_i64(), Some(4));
}

#[test]
fn a_huge_error_message_is_clipped() {
    let rt = rt();
    let e = run(&rt, "big.lua", "error(string.rep('E', 1e6))").unwrap_err();
    let text = e.to_string();
    assert!(text.len() < 8 * 1024, "{} bytes", text.len());
    assert!(text.contains("more bytes]"), "says it was clipped: {}", &text[..text.len().min(300)]);
    if let ScriptError::Runtime { traceback, .. } = &e {
        assert!(traceback.len() < 8 * 1024);
    }
}

#[test]
fn print_goes_to_the_log_not_to_stdout() {
    // The binary's stdout is a machine-readable stream (`mrt behave`): `print` must not
    // reach it. A script that prints a fake score only writes a log line.
    let rt = rt();
    let v =
        run(&rt, "print.lua", "print('score', 1, nil) for i = 1, 1000 do print(i) end return 1")
            .unwrap();
    assert_eq!(v.as_i64(), Some(1));
}

#[test]
fn load_sees_the_sandbox_globals() {
    let rt = rt();
    let v = run(&rt, "load.lua", "return load('return math.pi')()").unwrap();
    assert_eq!(v.as_f64(), Some(std::f64::consts::PI));
    // An explicit environment is still honoured, nil included.
    let v = run(&rt, "env.lua", "return load('return x', 'c', 't', {x = 5})()").unwrap();
    assert_eq!(v.as_i64(), Some(5));
    let e = run(&rt, "nil_env.lua", "return load('return math.pi', 'c', 't', nil)()").unwrap_err();
    assert!(e.to_string().contains("_ENV"), "{e}");
    // And still no bytecode.
    let v = run(&rt, "bin.lua", "return select(2, load(string.dump(function() end)))").unwrap();
    assert!(v.as_string().unwrap().to_str().unwrap().contains("binary"));
}

#[test]
fn the_watchdog_handle_interrupts_a_lua_loop_even_under_pcall() {
    let rt = rt();
    let handle = rt.interrupt_handle();
    handle.interrupt();
    let e = run(&rt, "stopped.lua", "while true do pcall(function() while true do end end) end")
        .unwrap_err();
    assert!(matches!(e, ScriptError::Watchdog { .. }), "{e}");
    assert!(rt.interrupted());
}
