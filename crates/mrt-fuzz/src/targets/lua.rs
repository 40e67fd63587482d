//! Lua: behavior scripts, HBM behavior directories, HFSM files, and the world snapshots
//! `mrt behave` feeds them.
//!
//! A Lua state costs far more to build than most inputs cost to run, so the harnesses keep one
//! for [`RENEW_EVERY`] executions. What an input leaves in it (globals) can only make a later
//! input fail differently, never hide a panic of the Rust side; the engine runs every new
//! panic site's input again alone in a fresh harness and reports whether it reproduces.

use super::{files_under, Harness, Seed, Target};
use crate::FuzzError;
use mrt_core::{Pose2, Time};
use mrt_msgs::robot::{lps, Estimate, GameState, Lpo, Mate, WorldSnapshot};
use mrt_script::chaos::{self, RobotIo};
use mrt_script::hbm::Hbm;
use mrt_script::hfsm::Hfsm;
use mrt_script::offline::{cycle_line, parse_worlds, world_at};
use mrt_script::{LoadStrategy, LuaRuntime, Sandbox, Script, ThinkingCap};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::rc::Rc;

/// Executions a Lua state serves before a fresh one is built.
pub const RENEW_EVERY: u32 = 32;

/// The limits of the fuzzing runtimes: small, so that runaway inputs end fast.
pub const FUZZ_SANDBOX: Sandbox = Sandbox { instruction_budget: 200_000, memory_limit: 16 << 20 };

const LUA_WORDS: &[&str] = &[
    "chaos",
    "lps_getLpo",
    "gsGetMyPos",
    "setVlin",
    "setVrot",
    "setVlat",
    "setKick",
    "setNeeded",
    "setBehavior",
    "setGlobal",
    "getGlobal",
    "getMates",
    "getField",
    "getRole",
    "rule",
    "always",
    "need",
    "use",
    "variable",
    "AND",
    "OR",
    "NOT",
    "TRI",
    "TRA",
    "TOL",
    "TOR",
    "REC",
    "SNG",
    "DIV",
    "machine",
    "state",
    "meta",
    "transition",
    "BALL",
    "NET1",
    "NET2",
    "function",
    "end",
    "local",
    "return",
    "while",
    "true",
    "do",
    "repeat",
    "until",
    "goto",
    "for",
    "in",
    "pairs",
    "ipairs",
    "setmetatable",
    "__index",
    "__gc",
    "pcall",
    "error",
    "coroutine.wrap",
    "string.rep",
    "string.format",
    "table.concat",
    "load",
    "math.huge",
    "0/0",
    "...",
    "#",
    "..",
    "[[",
    "]]",
    "--[[",
    "{",
    "}",
    "nil",
    // Constructions a hostile behavior used: huge repeat counts, lengths through `__len`,
    // C functions in loops, readers, chunk names, deep meta-state chains, labels built by
    // hand, set-points at the edge of `f64`.
    "math.maxinteger",
    "math.mininteger",
    "string.rep('', math.maxinteger)",
    "string.rep('x', 1e7, ',')",
    "setmetatable({}, {__len = function() return math.maxinteger - 1 end})",
    "table.insert(t, 1, 0)",
    "table.remove(t, 1)",
    "table.sort(t)",
    "table.unpack(t, 1, 1e8)",
    "table.concat(t, '', 1, math.maxinteger)",
    "table.move(t, 1, 1e15, 2)",
    "string.find(s, s, 1, true)",
    "string.gsub(s, '.-.-.-b', '%0%0')",
    "load(function() return string.rep('-', 1e6) end)",
    "load(code, '@goalkeeper.lua')",
    "for i = 1, 20000 do machine('M' .. i) { initial = 's', states = { s = meta('M' .. (i + 1)) } } end",
    "for i = 1, 5000 do s['s' .. i] = true end",
    "{0, 0/0, 0/0, 0/0}",
    "{1e308, -1e308, 0, 1}",
    "{3, 2, 1, 0}",
    "scale(\"go\", 1e300)",
    "chaos.setVlin(1e308)",
    "chaos.setVrot(-1e308)",
    "chaos.setTarget(1e300, 1e300, 0)",
    "while true do end",
];

fn teamchaos(root: &Path) -> PathBuf {
    root.join("behaviors/teamchaos")
}

fn lua_seeds(root: &Path, keep: fn(&str) -> bool) -> Result<Vec<Seed>, FuzzError> {
    files_under(&teamchaos(root), keep)
}

fn setup_error(target: &str, e: impl std::fmt::Display) -> FuzzError {
    FuzzError::Harness { target: target.to_string(), message: e.to_string() }
}

/// A sandboxed runtime with `chaos` installed, renewed every [`RENEW_EVERY`] uses.
struct Runtime {
    rt: LuaRuntime,
    io: Rc<RefCell<RobotIo>>,
    uses: u32,
}

impl Runtime {
    fn new() -> Option<Runtime> {
        let rt = LuaRuntime::new(FUZZ_SANDBOX).ok()?;
        let io = Rc::new(RefCell::new(RobotIo::default()));
        chaos::install(&rt, io.clone()).ok()?;
        Some(Runtime { rt, io, uses: 0 })
    }

    /// The runtime for the next execution.
    fn next(slot: &mut Option<Runtime>) -> Option<&mut Runtime> {
        if slot.as_ref().is_none_or(|r| r.uses >= RENEW_EVERY) {
            *slot = Runtime::new();
        }
        let r = slot.as_mut()?;
        r.uses += 1;
        r.io.borrow_mut().new_cycle(sample_world(0));
        Some(r)
    }
}

/// A world with something in it: the ball ahead, a net, a mate, a kickoff pose.
fn sample_world(cycle: u32) -> WorldSnapshot {
    let mut w = WorldSnapshot {
        time: Time::from_secs_f64(0.1 * f64::from(cycle)),
        game_state: GameState::Playing,
        role: "attacker".to_string(),
        kickoff_pose: Some(mrt_core::frames::Framed::new(Pose2::new(-1.0, 0.0, 0.0))),
        ..WorldSnapshot::default()
    };
    w.lps[lps::BALL] = Lpo { rho: 0.9, theta: 0.3, reliability: 0.9, seen_ago: 0.0 };
    w.lps[lps::NET1] = Lpo { rho: 4.0, theta: -0.2, reliability: 0.7, seen_ago: 0.5 };
    w.mates.push(Mate { id: 2, at: Estimate::default(), keeper: true });
    w
}

/// Behavior scripts: compile and call.
pub(super) const LUA_SCRIPT: Target = Target {
    name: "lua-script",
    about: "Lua behavior scripts (behaviors/teamchaos/*.lua): Script::from_source and two calls in a small sandbox with chaos.* installed",
    keywords: LUA_WORDS,
    structured: None,
    seeds: |root| lua_seeds(root, |s| s.ends_with(".lua")),
    harness: |_| Ok(Box::new(Scripts { runtime: None })),
};

struct Scripts {
    runtime: Option<Runtime>,
}

impl Harness for Scripts {
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool {
        // `Script::from_file` reads the file as UTF-8 text.
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Some(r) = Runtime::next(&mut self.runtime) else { return false };
        let Ok(script) = Script::from_source(&r.rt, &seed.slot, text, LoadStrategy::Compiled)
        else {
            return false;
        };
        for _ in 0..2 {
            let _ = script.call::<()>(&r.rt);
        }
        true
    }
}

/// HBM behavior directories.
pub(super) const HBM: Target = Target {
    name: "hbm",
    about: "HBM behaviors (hbm.lua and each behavior of behaviors/teamchaos): Hbm::from_sources, then the behavior run for two cycles",
    keywords: LUA_WORDS,
    structured: None,
    seeds: |root| lua_seeds(root, |s| s.ends_with(".lua") && !s.ends_with(".hfsm.lua")),
    harness: |root| {
        let files = lua_seeds(root, |s| s.ends_with(".lua") && !s.ends_with(".hfsm.lua"))?;
        let text = |s: Seed| (s.slot, String::from_utf8_lossy(&s.bytes).into_owned());
        let mut setup = None;
        let mut behaviors = Vec::new();
        for (slot, t) in files.into_iter().map(text) {
            match slot.strip_suffix(".lua") {
                Some("hbm") => setup = Some(t),
                Some(name) => behaviors.push((name.to_string(), t)),
                None => {}
            }
        }
        let setup = setup.ok_or_else(|| setup_error("hbm", "no hbm.lua in behaviors/teamchaos"))?;
        Ok(Box::new(HbmFiles { setup, behaviors, runtime: None }))
    },
};

struct HbmFiles {
    /// The shipped `hbm.lua`.
    setup: String,
    /// The shipped behaviors, (name, text).
    behaviors: Vec<(String, String)>,
    runtime: Option<Runtime>,
}

impl Harness for HbmFiles {
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool {
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Some(r) = Runtime::next(&mut self.runtime) else { return false };
        let shipped = |name: &str| {
            self.behaviors.iter().find(|(n, _)| n == name).map_or("", |(_, t)| t.as_str())
        };
        // A mutated hbm.lua runs with go2ball; a mutated behavior with the shipped hbm.lua.
        let (setup, name, behavior) = match seed.slot.strip_suffix(".lua") {
            Some("hbm") => (text, "go2ball", shipped("go2ball")),
            Some(name) => (self.setup.as_str(), name, text),
            None => return false,
        };
        // The behavior, and the shipped ones its text names (those it may `use`).
        let mut files: Vec<(&str, &str)> = vec![(name, behavior)];
        for (n, t) in &self.behaviors {
            if n != name && behavior.contains(&format!("\"{n}\"")) {
                files.push((n.as_str(), t.as_str()));
            }
        }
        let Ok(hbm) = Hbm::from_sources(&r.rt, Some(setup), &files, r.io.clone()) else {
            return false;
        };
        for cycle in 0..2 {
            r.io.borrow_mut().new_cycle(sample_world(cycle));
            r.io.borrow_mut().activate(name);
            let _ = hbm.run(&r.rt, name);
            let _ = hbm.degrees("go");
        }
        true
    }
}

/// HFSM files.
pub(super) const HFSM: Target = Target {
    name: "hfsm",
    about: "HFSM files (behaviors/teamchaos/*.hfsm.lua): Hfsm::from_source, five steps, dot and SVG drawings",
    keywords: LUA_WORDS,
    structured: None,
    seeds: |root| lua_seeds(root, |s| s.ends_with(".hfsm.lua")),
    harness: |_| Ok(Box::new(Machines { runtime: None })),
};

struct Machines {
    runtime: Option<Runtime>,
}

impl Harness for Machines {
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool {
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Some(r) = Runtime::next(&mut self.runtime) else { return false };
        let Ok(mut hfsm) = Hfsm::from_source(&r.rt, &seed.slot, text, r.io.clone()) else {
            return false;
        };
        for cycle in 0..5 {
            r.io.borrow_mut().new_cycle(sample_world(cycle));
            let _ = hfsm.step(&r.rt);
            let _ = hfsm.path();
        }
        let _ = hfsm.to_dot(true);
        let _ = hfsm.to_svg();
        true
    }
}

/// World snapshots as `mrt behave --world` reads them.
pub(super) const WORLD: Target = Target {
    name: "world",
    about: "world snapshots as mrt behave reads them (JSON → WorldSnapshot, one or an array), then run through the Attacker's ThinkingCap cycles",
    keywords: &["lps", "rho", "theta", "reliability", "seen_ago", "my_pos", "pose", "quality", "ball_vel", "global_ball", "mates", "id", "at", "velocity", "at_sigma", "robots", "keeper", "role", "ball_booked", "game_state", "field", "half_length", "half_width", "goal_half_width", "penalty_area_depth", "kickoff_pose", "time", "x", "y", "null", "true", "false", "[]", "{}", "\"PLAYING\"", "\"Playing\"", ":", ","],
    structured: Some(crate::mutate::mutate_json),
    seeds: |root| {
        let mut seeds = files_under(&teamchaos(root).join("worlds"), |s| s.ends_with(".json"))?;
        let json = |w: &WorldSnapshot| serde_json::to_string_pretty(w).unwrap_or_default();
        seeds.push(Seed::new("default", json(&WorldSnapshot::default())));
        seeds.push(Seed::new("sample", json(&sample_world(3))));
        Ok(seeds)
    },
    harness: |root| {
        let dir = teamchaos(root);
        let cap = attacker(&dir).map_err(|e| setup_error("world", e))?;
        Ok(Box::new(Worlds { dir, cap, uses: 0 }))
    },
};

/// The most worlds of one input run as cycles.
const MAX_WORLD_CYCLES: usize = 4;

fn attacker(dir: &Path) -> Result<ThinkingCap, mrt_script::ScriptError> {
    ThinkingCap::with_hfsm(dir, dir.join("attacker.hfsm.lua"), FUZZ_SANDBOX)
}

struct Worlds {
    dir: PathBuf,
    cap: ThinkingCap,
    uses: u32,
}

impl Harness for Worlds {
    fn exec(&mut self, _seed: &Seed, input: &[u8]) -> bool {
        // `mrt behave` reads the file as UTF-8 text.
        let Ok(text) = std::str::from_utf8(input) else { return false };
        let Ok(worlds) = parse_worlds(text) else { return false };
        self.uses += 1;
        if self.uses > 8 * RENEW_EVERY || self.cap.stopped() {
            let Ok(cap) = attacker(&self.dir) else { return false };
            self.cap = cap;
            self.uses = 0;
        }
        // As `mrt behave` runs them, one world a cycle, at most a few.
        let cycles = worlds.len().min(MAX_WORLD_CYCLES) as u64;
        for k in 0..cycles {
            let w = world_at(&worlds, k, 100);
            let time = w.time;
            let c = self.cap.cycle(w);
            let _ = cycle_line(k, time, &c);
        }
        true
    }
}
