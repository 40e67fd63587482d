//! The Lua runtime of ThinkingCap behaviors (ThinkingCap/TeamChaos report §3): sandbox, budgets, loading strategies
//! and hot reload with fallback.

#![allow(clippy::unwrap_used)]

use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ScriptError};
use std::path::PathBuf;

fn rt() -> LuaRuntime {
    LuaRuntime::new(Sandbox { instruction_budget: 1_000_000, memory_limit: 8 << 20 }).unwrap()
}

fn temp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mrt-script-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("{name}.lua"));
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn scripts_see_only_the_safe_libraries() {
    let rt = rt();
    let probe = "local names = {'io', 'os', 'require', 'debug', 'dofile', 'loadfile', 'package', \
                 'math', 'string', 'table', 'coroutine'}
                 local out = {}
                 for _, n in ipairs(names) do out[#out + 1] = n .. '=' .. type(_G[n]) end
                 return table.concat(out, ' ')";
    let s = Script::from_source(&rt, "probe.lua", probe, LoadStrategy::Compiled).unwrap();
    assert_eq!(
        s.call::<String>(&rt).unwrap(),
        "io=nil os=nil require=nil debug=nil dofile=nil loadfile=nil package=nil \
         math=table string=table table=table coroutine=table"
    );
    // `load` takes text only: precompiled bytecode (which can crash the VM) is refused.
    let bin = Script::from_source(
        &rt,
        "bin.lua",
        r#"local f, err = load("\27Lua\84\0", "x", "b") return tostring(f) .. " | " .. tostring(err)"#,
        LoadStrategy::Compiled,
    )
    .unwrap();
    let got = bin.call::<String>(&rt).unwrap();
    assert!(got.starts_with("nil | ") && got.contains("binary"), "{got}");
    // Text chunks still load.
    let text = Script::from_source(
        &rt,
        "text.lua",
        "return load('return 6 * 7')()",
        LoadStrategy::Compiled,
    )
    .unwrap();
    assert_eq!(text.call::<i64>(&rt).unwrap(), 42);
    // Calling what was removed is an ordinary runtime error naming the script.
    let s = Script::from_source(&rt, "evil.lua", "os.execute('rm -rf /')", LoadStrategy::Compiled)
        .unwrap();
    let e = s.call::<()>(&rt).unwrap_err();
    assert!(
        matches!(e, ScriptError::Runtime { .. })
            && e.to_string().starts_with("evil.lua:1: runtime error"),
        "{e}"
    );
}

#[test]
fn an_endless_loop_is_aborted_and_the_runtime_keeps_working() {
    let rt = rt();
    let spin =
        Script::from_source(&rt, "spin.lua", "while true do end", LoadStrategy::Compiled).unwrap();
    let e = spin.call::<()>(&rt).unwrap_err();
    assert!(matches!(e, ScriptError::Budget { budget: 1_000_000, .. }), "{e}");
    assert!(e.to_string().starts_with("spin.lua:1: aborted"), "{e}");
    // The budget is per call: the next call, and other scripts, run normally.
    let ok = Script::from_source(
        &rt,
        "ok.lua",
        "local s = 0 for i = 1, 1000 do s = s + i end return s",
        LoadStrategy::Compiled,
    )
    .unwrap();
    assert_eq!(ok.call::<i64>(&rt).unwrap(), 500_500);
    assert!(matches!(spin.call::<()>(&rt), Err(ScriptError::Budget { .. })));
}

#[test]
fn a_memory_bomb_is_aborted_and_the_runtime_keeps_working() {
    let rt = LuaRuntime::new(Sandbox { instruction_budget: u64::MAX / 2, memory_limit: 4 << 20 })
        .unwrap();
    let bomb = Script::from_source(
        &rt,
        "bomb.lua",
        "local t = {} for i = 1, 1e9 do t[i] = string.rep('x', 1000) .. i end",
        LoadStrategy::Compiled,
    )
    .unwrap();
    let e = bomb.call::<()>(&rt).unwrap_err();
    assert!(matches!(e, ScriptError::Memory { limit, .. } if limit == 4 << 20), "{e}");
    let ok = Script::from_source(&rt, "ok.lua", "return 1 + 1", LoadStrategy::Compiled).unwrap();
    assert_eq!(ok.call::<i64>(&rt).unwrap(), 2);
}

#[test]
fn syntax_errors_name_the_file_and_line() {
    let rt = rt();
    let e = Script::from_source(
        &rt,
        "behaviors/lookball.lua",
        "local x = 1\nif x then\n  x = \nend",
        LoadStrategy::Compiled,
    )
    .err()
    .unwrap();
    match &e {
        ScriptError::Syntax { file, line, .. } => {
            assert_eq!((file.as_str(), *line), ("behaviors/lookball.lua", 4))
        }
        other => panic!("{other:?}"),
    }
    assert!(e.to_string().starts_with("behaviors/lookball.lua:4: "), "{e}");
}

#[test]
fn the_three_loading_strategies_give_the_same_results() {
    let path = temp("strategies", "n = (n or 0) + 1 return n * 10");
    for strategy in [LoadStrategy::ReloadFromFile, LoadStrategy::Source, LoadStrategy::Compiled] {
        let rt = rt();
        let s = Script::from_file(&rt, &path, strategy).unwrap();
        assert_eq!(s.strategy(), strategy);
        let got: Vec<i64> = (0..3).map(|_| s.call(&rt).unwrap()).collect();
        assert_eq!(got, [10, 20, 30], "{strategy:?}");
    }
    // ReloadFromFile sees an edit at the next call without any reload request.
    let rt = rt();
    let s = Script::from_file(&rt, &path, LoadStrategy::ReloadFromFile).unwrap();
    assert_eq!(s.call::<i64>(&rt).unwrap(), 10);
    std::fs::write(&path, "return -1").unwrap();
    assert_eq!(s.call::<i64>(&rt).unwrap(), -1);
}

#[test]
fn hot_reload_swaps_a_good_edit_and_rejects_a_bad_one() {
    let path = temp("reload", "calls = (calls or 0) + 1 return 'v1'");
    let rt = rt();
    let s = Script::from_file(&rt, &path, LoadStrategy::Compiled).unwrap();
    assert_eq!(s.call::<String>(&rt).unwrap(), "v1");
    assert!(!s.reload_if_changed(&rt).unwrap(), "nothing changed yet");

    // A good edit is picked up at the next cycle boundary; the state (globals) survives.
    std::thread::sleep(std::time::Duration::from_millis(20)); // a distinct modification time
    std::fs::write(&path, "calls = (calls or 0) + 1 return 'v2 after ' .. calls").unwrap();
    assert!(s.reload_if_changed(&rt).unwrap());
    assert_eq!(s.call::<String>(&rt).unwrap(), "v2 after 2");

    // A broken edit is rejected with file:line, and v2 keeps running.
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(&path, "return 'v3' +").unwrap();
    let e = s.reload_if_changed(&rt).unwrap_err();
    assert!(e.to_string().starts_with(&format!("{}:1: ", path.display())), "{e}");
    assert_eq!(s.call::<String>(&rt).unwrap(), "v2 after 3");
    assert!(
        !s.reload_if_changed(&rt).unwrap(),
        "a broken file is reported once, not at every poll"
    );

    // Fixing the file recovers.
    std::thread::sleep(std::time::Duration::from_millis(20));
    std::fs::write(&path, "return 'v4'").unwrap();
    assert!(s.reload_if_changed(&rt).unwrap());
    assert_eq!(s.call::<String>(&rt).unwrap(), "v4");
    // An explicit reload request (e.g. a message on the bus) works too.
    assert!(s.reload(&rt).is_ok());
}

/// Saves as editors do: write a new file, rename it over the old one (never a half-written
/// script on disk).
fn save(path: &std::path::Path, text: &str) {
    let tmp = path.with_extension("lua.tmp");
    std::fs::write(&tmp, text).unwrap();
    std::fs::rename(&tmp, path).unwrap();
}

/// An edit on disk is reported by the watcher and swapped in at the next cycle boundary, while
/// the behavior runs; a bad edit is reported and the old version keeps running.
#[test]
fn the_watcher_reports_edits_and_the_loop_swaps_them_in() {
    let path = temp("watched", "return 'first'");
    let rt = rt();
    let s = Script::from_file(&rt, &path, LoadStrategy::Compiled).unwrap();
    let mut w = mrt_script::ScriptWatcher::new().unwrap();
    w.watch(&path).unwrap();
    save(&path, "return 'second'");
    // One "cycle" every 5 ms until the change arrives (liveness bound: 5 s).
    let mut outputs = Vec::new();
    for _ in 0..1000 {
        for changed in w.changed() {
            assert_eq!(changed, std::path::absolute(&path).unwrap());
            s.reload(&rt).unwrap();
        }
        outputs.push(s.call::<String>(&rt).unwrap());
        if outputs.last().is_some_and(|o| o == "second") {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert_eq!(outputs.last().map(String::as_str), Some("second"), "the edit was never picked up");
    assert!(outputs.iter().all(|o| o == "first" || o == "second"));
    // A bad edit: reported, rejected, the robot keeps "second".
    save(&path, "return 'third' ..");
    let mut rejected = false;
    for _ in 0..1000 {
        for _ in w.changed() {
            rejected |= s.reload(&rt).is_err();
        }
        assert_eq!(s.call::<String>(&rt).unwrap(), "second");
        if rejected {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(rejected, "the bad edit was never seen");
}

/// Waits (at most 5 s) for the watcher's next reported change.
fn next_change(w: &mrt_script::ScriptWatcher) -> mrt_script::Change {
    for _ in 0..1000 {
        if let Some(c) = w.changes().pop() {
            return c;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    panic!("no change reported in 5 s");
}

/// The watcher compiles an edited script on its own thread: the control loop receives
/// bytecode (or the syntax error, with its line) and only swaps it in. Both saving styles
/// count: writing in place and renaming a new file over the old one.
#[test]
fn edits_are_compiled_off_the_control_path() {
    let path = temp("offpath", "return 1");
    let rt = rt();
    let s = Script::from_file(&rt, &path, LoadStrategy::Compiled).unwrap();
    let mut w = mrt_script::ScriptWatcher::new().unwrap();
    w.watch(&path).unwrap();
    std::fs::write(&path, "return 2").unwrap(); // in place
    let change = next_change(&w);
    assert_eq!(change.name, path.display().to_string());
    let compiled = change.compiled.unwrap();
    assert!(compiled.bytecode().starts_with(b"\x1bLua"), "Lua bytecode");
    assert_eq!(compiled.source(), "return 2");
    assert_eq!(s.call::<i64>(&rt).unwrap(), 1, "nothing changes before the swap");
    s.install(&rt, &compiled).unwrap();
    assert_eq!(s.call::<i64>(&rt).unwrap(), 2);
    save(&path, "local x = 1\nreturn (x +"); // renamed over, broken on line 2
    match next_change(&w).compiled {
        Err(ScriptError::Syntax { file, line, .. }) => {
            assert_eq!((file, line), (path.display().to_string(), 2));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(s.call::<i64>(&rt).unwrap(), 2, "the running version stays");
    // Runtime errors of an installed version still name the file and line. (A rename save
    // may be reported twice: skip a late duplicate of the broken version.)
    std::fs::write(&path, "local t = nil\nreturn t.x").unwrap();
    let compiled = loop {
        match next_change(&w).compiled {
            Ok(c) => break c,
            Err(ScriptError::Syntax { line: 2, .. }) => continue,
            Err(other) => panic!("{other:?}"),
        }
    };
    assert_eq!(compiled.source(), "local t = nil\nreturn t.x");
    s.install(&rt, &compiled).unwrap();
    let e = s.call::<i64>(&rt).unwrap_err();
    assert!(e.to_string().starts_with(&format!("{}:2: runtime error", path.display())), "{e}");
}

/// An empty file is not a new version: the watcher sees files truncated by an editor that is
/// saving them again, and waits for the save's own event.
#[test]
fn an_emptied_file_is_not_reported_as_a_new_version() {
    let path = temp("emptied", "return 1");
    let mut w = mrt_script::ScriptWatcher::new().unwrap();
    w.watch(&path).unwrap();
    std::fs::write(&path, "").unwrap();
    std::thread::sleep(std::time::Duration::from_millis(200));
    assert!(w.changes().is_empty(), "nothing to compile yet");
    std::fs::write(&path, "return 3").unwrap();
    assert_eq!(next_change(&w).compiled.unwrap().source(), "return 3");
}
