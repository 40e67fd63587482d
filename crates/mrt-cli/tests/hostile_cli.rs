//! Hostile behaviors and interrupted runs: `mrt sim --behaviors DIR` with a
//! behavior that tries to hang, hoard or lie finishes its match and reports the robot; no run
//! leaves files behind, whether it ends, fails or is interrupted.

#![allow(clippy::unwrap_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn mrt() -> Command {
    Command::new(env!("CARGO_BIN_EXE_mrt"))
}

/// A copy of the shipped TeamChaos behaviors with `file` replaced by `text`.
fn hostile_copy(case: &str, file: &str, text: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../behaviors/teamchaos");
    let dir = std::env::temp_dir().join(format!("mrt-hostile-{}-{case}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
        }
    }
    std::fs::write(dir.join(file), text).unwrap();
    dir
}

/// The compiled-in behaviors' directories process `pid` wrote.
fn embedded_dirs_of(pid: u32) -> Vec<PathBuf> {
    let prefix = format!("mrt-teamchaos-{pid}-");
    std::fs::read_dir(std::env::temp_dir())
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with(&prefix)))
        .collect()
}

#[test]
fn a_hostile_behavior_stops_its_robot_and_the_match_goes_on() {
    let cases = [
        ("coroutine", "goalkeeper.lua", "coroutine.wrap(function() while true do end end)()"),
        ("pcall", "ready.lua", "while true do pcall(function() while true do end end) end"),
        ("gc", "goalkeeper.lua", "setmetatable({}, {__gc = function() while true do end end})"),
        ("pattern", "goalkeeper.lua", "local r = string.find(string.rep('a', 1e5), '.-.-.-.-b')"),
        (
            "hoard",
            "goalkeeper.lua",
            "for i = 1, 1e6 do chaos.setGlobal('k'..i, STRING, string.rep('x', 1e6)) end",
        ),
        ("print", "goalkeeper.lua", "print('milan 0 : 99 chaos (away)') chaos.setVlin(0/0)"),
        ("error", "goalkeeper.lua", "error(string.rep('E', 1e6))"),
        ("escapes", "goalkeeper.lua", r#"error("\27[2J\27[Hmatch OK: no faults")"#),
        ("rep", "goalkeeper.lua", "local s = string.rep('', math.maxinteger)"),
        (
            "insert",
            "goalkeeper.lua",
            "table.insert(setmetatable({}, {__len = function() return math.maxinteger - 1 end}), 1, 0)",
        ),
        (
            "find",
            "goalkeeper.lua",
            "local h = string.rep('a', 9e6) for i = 1, 1e9 do string.find(h, 'aab', 1, true) end",
        ),
        // At the top of the HBM file, run when every robot loads its behaviors.
        ("top", "hbm.lua", "string.rep('', math.maxinteger, '')"),
    ];
    for (case, file, text) in cases {
        let dir = hostile_copy(case, file, text);
        let out = mrt()
            .args(["sim", "--half", "5", "--home", "chaos", "--away", "chaser", "--behaviors"])
            .arg(&dir)
            .output()
            .unwrap();
        let (stdout, stderr) =
            (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
        assert!(out.status.success(), "{case}: {stderr}");
        assert!(stdout.contains("10 s of play simulated"), "{case}: the match finished: {stdout}");
        assert!(stdout.contains("faulted"), "{case}: the robot is reported: {stdout}");
        if case == "top" {
            assert!(stdout.contains("failed to init"), "{case}: as a load error: {stdout}");
        }
        assert!(!stdout.contains("0 : 99"), "{case}: a script prints nothing on stdout: {stdout}");
        assert!(stdout.len() < 16 * 1024, "{case}: {} bytes of report", stdout.len());
        // A script's text is shown, never obeyed by the terminal.
        assert!(!stdout.contains('\u{1b}') && !stderr.contains('\u{1b}'), "{case}: {stdout}");
        if case == "escapes" {
            assert!(stdout.contains("\\u{1b}[2J"), "{case}: the escape is shown: {stdout}");
        }
        assert!(stderr.len() < 4 << 20, "{case}: {} bytes of log", stderr.len());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

/// `mrt behave` and `mrt hfsm dot` protect themselves as a match does: a call the budget pays
/// for ends in an error, a file of 20 000 nested machines is refused, and neither hangs nor
/// aborts.
#[test]
fn behave_and_hfsm_dot_end_with_an_error_on_hostile_files() {
    let dir = std::env::temp_dir().join(format!("mrt-hostile-offline-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("hbm.lua"), "").unwrap();
    std::fs::write(dir.join("rep.lua"), "local s = string.rep('', math.maxinteger)").unwrap();
    let chain = "for i = 1, 20000 do\n\
                   local inner = i < 20000 and meta('M' .. (i + 1)) or true\n\
                   machine('M' .. i) { initial = 's', states = { s = inner } }\n\
                 end";
    std::fs::write(dir.join("deep.hfsm.lua"), chain).unwrap();
    for args in [
        vec!["behave".to_string(), dir.join("rep.lua").display().to_string()],
        vec!["behave".to_string(), dir.join("deep.hfsm.lua").display().to_string()],
        vec![
            "hfsm".to_string(),
            "dot".to_string(),
            dir.join("deep.hfsm.lua").display().to_string(),
        ],
    ] {
        let started = Instant::now();
        let out = mrt().args(&args).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: an error, not a crash: {stderr}");
        assert!(started.elapsed() < Duration::from_secs(20), "{args:?}: {:?}", started.elapsed());
        let expected = if args[1].ends_with("rep.lua") { "string.rep" } else { "256 machines" };
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_run_leaves_no_files_behind() {
    let child = mrt()
        .args(["sim", "--half", "2", "--home", "chaos", "--away", "milan"])
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    assert!(embedded_dirs_of(pid).is_empty(), "{:?}", embedded_dirs_of(pid));
}

/// Ctrl-C, a `kill` and a closed terminal end a match the same way: exit status 130, the
/// compiled-in behaviors' directory removed.
#[test]
fn an_interrupted_run_leaves_no_files_behind() {
    for signal in ["-INT", "-TERM", "-HUP"] {
        let mut child = mrt()
            .args(["sim", "--half", "3000", "--home", "chaos", "--away", "chaser"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let pid = child.id();
        let started = Instant::now();
        let spawned = std::time::SystemTime::now() - Duration::from_millis(50);
        // The directory this process wrote (an earlier process of the same id may have left
        // one).
        let written = |p: &PathBuf| {
            std::fs::metadata(p).and_then(|m| m.modified()).is_ok_and(|t| t >= spawned)
        };
        while !embedded_dirs_of(pid).iter().any(written) {
            assert!(started.elapsed() < Duration::from_secs(60), "the match never started");
            std::thread::sleep(Duration::from_millis(20));
        }
        let kill = Command::new("kill").args([signal, &pid.to_string()]).status().unwrap();
        assert!(kill.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(130), "{signal}: {status:?}");
        assert!(embedded_dirs_of(pid).is_empty(), "{signal}: {:?}", embedded_dirs_of(pid));
    }
}
