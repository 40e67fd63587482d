//! Hostile scripts: every way a tester slipped the sandbox's budget, its memory
//! limit or its output is a clear error now, and the runtime stays usable after it.

#![allow(clippy::unwrap_used)]

use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError};

/// How long a budgeted call may take here, s. Each ends in well under a second, which a test
/// machine under load may stretch several times; the work refused would take minutes to
/// hours (a quadratic search of megabytes, an endless loop).
const PROMPT: f64 = 10.0;

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
            matches!(e, ScriptError::Runtime { .. }) && e.to_string().contains("needs up to"),
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

/// A C call whose work its arguments decide is paid for from the budget or refused before it
/// runs: none of these may take longer than a fraction of a second.
#[test]
fn library_calls_with_unbounded_work_are_refused_before_they_run() {
    let rt = rt();
    for (name, src) in [
        ("rep.lua", "return string.rep('', math.maxinteger)"),
        ("rep_sep.lua", "return string.rep('', math.maxinteger, '')"),
        ("rep_str.lua", "return ('x'):rep('9223372036854775807')"),
        ("rep_float.lua", "return string.rep('', 2^62)"),
        (
            "insert.lua",
            "local t = setmetatable({}, {__len = function() return math.maxinteger - 1 end}) \
             table.insert(t, 1, 0)",
        ),
        (
            "remove.lua",
            "local t = setmetatable({}, {__len = function() return math.maxinteger - 1 end}) \
             table.remove(t, 1)",
        ),
        (
            "sort.lua",
            "local t = setmetatable({}, {__len = function() return 2^31 - 2 end}) table.sort(t)",
        ),
        ("unpack.lua", "return table.unpack({}, 1, 1e8)"),
        ("concat.lua", "return table.concat({}, '', 1, math.maxinteger)"),
        ("move.lua", "table.move({}, 1, 1e15, 1, {})"),
        ("move_str.lua", "table.move({}, '1', '1e15', 1, {})"),
        (
            "reader.lua",
            "local big = string.rep('-', 1 << 20) local n = 0 \
             return load(function() n = n + 1 if n < 100 then return big end end)",
        ),
    ] {
        let started = std::time::Instant::now();
        let e = run(&rt, name, src).unwrap_err();
        assert!(started.elapsed().as_secs_f64() < PROMPT, "{name}: {:?}", started.elapsed());
        assert!(
            matches!(e, ScriptError::Runtime { .. } | ScriptError::Budget { .. }),
            "{name}: {e}"
        );
        assert!(e.to_string().contains("steps") || e.to_string().contains("budget"), "{name}: {e}");
        assert!(e.to_string().starts_with(name), "the script is named: {e}");
        still_works(&rt);
    }
}

/// The same calls in a loop, each small enough to pass alone: they add up to the budget.
#[test]
fn library_calls_in_a_loop_spend_the_budget() {
    let rt = rt();
    for (name, src) in [
        ("rep_loop.lua", "while true do local s = string.rep('', 1e4) end"),
        (
            "upper_loop.lua",
            "local s = string.rep('aaaaaaaaaa', 1e5) while true do local u = s:upper() end",
        ),
        (
            "format_loop.lua",
            "local s = string.rep('aaaaaaaaaa', 1e5) while true do local u = ('%s'):format(s) end",
        ),
        (
            "sort_loop.lua",
            "local t = {} for i = 1, 2e4 do t[i] = -i end while true do table.sort(t) end",
        ),
        ("load_loop.lua", "local s = 'return 1' .. string.rep(' ', 1e5) while true do load(s) end"),
        (
            "find_loop.lua",
            "local h = string.rep('a', 1e5) while true do string.find(h, 'b', 1, true) end",
        ),
        (
            "concat_loop.lua",
            "local t = {} for i = 1, 1e4 do t[i] = 'x' end while true do table.concat(t) end",
        ),
    ] {
        let started = std::time::Instant::now();
        assert_budget(&rt, name, src);
        assert!(started.elapsed().as_secs_f64() < PROMPT, "{name}: {:?}", started.elapsed());
    }
}

/// `..` copies its strings inside one VM instruction: it is paid by the bytes it allocates,
/// and once the budget is spent the next large string is refused, so the call ends at once.
#[test]
fn concatenation_is_paid_by_the_bytes_it_allocates() {
    let rt = rt();
    for (name, src) in [
        // 2 MB a copy, four instructions an iteration: minutes on the instruction count alone.
        (
            "double.lua",
            "local s = 'x' for i = 1, 20 do s = s .. s end while true do local t = s .. s end",
        ),
        // Quadratic: each iteration copies everything so far.
        ("append.lua", "local s = '' while true do s = s .. 'x' end"),
        // The same inside a protected call and a coroutine.
        (
            "pcall_concat.lua",
            "local s = string.rep('x', 1e5) \
             while true do pcall(function() while true do local t = s .. s .. s end end) end",
        ),
        (
            "coroutine_concat.lua",
            "local s = string.rep('x', 1e5) \
             coroutine.wrap(function() while true do local t = s .. s end end)()",
        ),
    ] {
        let started = std::time::Instant::now();
        assert_budget(&rt, name, src);
        assert!(started.elapsed().as_secs_f64() < PROMPT, "{name}: {:?}", started.elapsed());
    }
    // The refusal belongs to the spent call: a script with a long text compiles and runs after.
    let long = format!("return #'{}'", "y".repeat(300_000));
    assert_eq!(run(&rt, "long.lua", &long).unwrap().as_i64(), Some(300_000));
}

/// A plain find (or a pattern without special characters) is linear: a haystack of megabytes
/// and a needle of megabytes is one quick call, with Lua's results.
#[test]
fn a_plain_find_is_linear_and_gives_luas_positions() {
    // A budget that pays for searching 13 MB (an instruction a byte).
    let rt = LuaRuntime::new(Sandbox { instruction_budget: 50_000_000, memory_limit: 32 << 20 })
        .unwrap();
    let started = std::time::Instant::now();
    let v = run(
        &rt,
        "find.lua",
        "local hay = string.rep('a', 9e6) local needle = string.rep('a', 4e6) .. 'b' \
         return tostring(string.find(hay, needle, 1, true)) .. ' ' .. tostring(hay:find(needle))",
    )
    .unwrap();
    assert_eq!(v.as_string().unwrap().to_str().unwrap(), "nil nil");
    assert!(started.elapsed().as_secs_f64() < PROMPT, "{:?}", started.elapsed());
    let v = run(
        &rt,
        "positions.lua",
        "local s = 'hello world' \
         local a, b = s:find('o', 6, true) local c, d = s:find('', 12) local e = s:find('', 13) \
         local f, g = s:find('wor', -5) local h, i = string.find(12345, 34) \
         return table.concat({a, b, c, d, tostring(e), f, g, h, i}, ',')",
    )
    .unwrap();
    assert_eq!(v.as_string().unwrap().to_str().unwrap(), "8,8,12,11,nil,7,9,3,4");
    // One result for a miss, as Lua gives.
    let v = run(&rt, "miss.lua", "return select('#', ('abc'):find('x', 1, true))").unwrap();
    assert_eq!(v.as_i64(), Some(1));
    let e = run(&rt, "bad.lua", "return string.find({}, 'x', 1, true)").unwrap_err();
    assert!(e.to_string().contains("bad argument #1 to 'find'"), "{e}");
}

/// A bad argument to a library function the sandbox wraps is blamed on the script's line, as
/// Lua would, never on the wrapper.
#[test]
fn a_bad_argument_to_a_wrapped_function_names_the_scripts_line() {
    let rt = rt();
    for src in ["local x = 1\nlocal s = ('%d'):format(nil)", "local x = 1\nstring.rep()"] {
        let e = run(&rt, "args.lua", src).unwrap_err();
        match &e {
            ScriptError::Runtime { file, line, message, .. } => {
                assert_eq!((file.as_str(), *line), ("args.lua", 2), "{e}");
                assert!(message.starts_with("bad argument"), "{e}");
            }
            other => panic!("{other}"),
        }
        assert!(!e.to_string().contains("sandbox"), "{e}");
    }
}

/// `load` cannot make an error name another file, and a reader's pieces still load.
#[test]
fn a_loaded_chunk_cannot_pass_for_a_file() {
    let rt = rt();
    for (name, src) in [
        ("at.lua", "load('error(\"boom\")', '@goalkeeper.lua')()"),
        ("eq.lua", "load('error(\"boom\")', '=goalkeeper.lua')()"),
        ("code.lua", "load('@goalkeeper.lua')()"),
    ] {
        let e = run(&rt, name, src).unwrap_err();
        assert!(!e.to_string().starts_with("goalkeeper.lua"), "{name}: {e}");
    }
    let v = run(
        &rt,
        "reader_ok.lua",
        "local parts, n = {'return ', '4', '2'}, 0 \
         return load(function() n = n + 1 return parts[n] end)()",
    )
    .unwrap();
    assert_eq!(v.as_i64(), Some(42));
    let v = run(&rt, "reader_bad.lua", "return select(2, load(function() return {} end))").unwrap();
    assert!(v.as_string().unwrap().to_str().unwrap().contains("must return a string"));
    // A reader that raises: `load` returns the error, as Lua's does.
    let v = run(&rt, "reader_err.lua", "return select(2, load(function() error('no more') end))")
        .unwrap();
    assert!(v.as_string().unwrap().to_str().unwrap().contains("no more"));
    // A reader that runs away is the call's end, not `load`'s result.
    assert_budget(&rt, "reader_loop.lua", "load(function() while true do end end)");
}

#[test]
fn ordinary_library_calls_still_work() {
    let rt = rt();
    let v = run(
        &rt,
        "lib.lua",
        "local t = {3, 1, 2} table.sort(t) table.insert(t, 1, 0) table.insert(t, 9) \
         local r = table.remove(t, 1) local u = {table.unpack(t, 1, 2)} \
         local s = table.concat(t, ',') .. ';' .. ('ab'):rep(3, '-') .. ';' .. ('%d|%s'):format(r, 'x') \
         .. ';' .. ('Hello'):upper():lower():reverse() .. ';' .. #u .. ';' .. string.byte('A') \
         .. ';' .. table.pack(1, 2, 3).n \
         return s",
    )
    .unwrap();
    assert_eq!(v.as_string().unwrap().to_str().unwrap(), "1,2,3,9;ab-ab-ab;0|x;olleh;2;65;3");
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
    let e = run(&rt, "big.lua", "error(string.rep(string.rep('E', 1000), 1000))").unwrap_err();
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
