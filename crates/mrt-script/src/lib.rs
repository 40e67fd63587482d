//! # mrt-script: Lua behaviors for MRT robots
//!
//! ThinkingCap (the ThinkingCap/TeamChaos report §3) writes behaviors as Lua scripts so a team can change a
//! running robot's behavior in seconds. This crate holds the runtime they run in (on `mlua` with
//! a vendored Lua 5.4, no system Lua needed):
//!
//! - a **sandbox** ([`LuaRuntime`]): scripts see only `math`, `string`, `table`, `coroutine`
//!   and the base functions that cannot reach outside (no `io`, `os`, `require`, `debug`,
//!   `dofile`, `loadfile`; `load` takes text chunks only);
//! - an **instruction budget** per call and a **memory limit**: a runaway loop or a memory bomb
//!   aborts that call with an error naming the script, and the runtime stays usable;
//! - the three **loading strategies** of §3.2 ([`LoadStrategy`]): reload from the file at each
//!   call, keep the source in memory, keep the compiled chunk in memory (default);
//! - **hot reload** ([`ScriptWatcher`] on `notify`, [`Script::reload_if_changed`],
//!   [`Script::reload`] for an explicit request): a changed file is compiled first; a file with an error is rejected with `file:line: message` and the old
//!   version keeps running. Lua globals (the scripts' persistent state) survive a reload.
//!
//! ```
//! use mrt_script::{LuaRuntime, LoadStrategy, Sandbox, Script};
//!
//! let rt = LuaRuntime::new(Sandbox::default())?;
//! let script = Script::from_source(&rt, "lookball.lua", "ticks = (ticks or 0) + 1 return ticks", LoadStrategy::Compiled)?;
//! assert_eq!(script.call::<i64>(&rt)?, 1);
//! assert_eq!(script.call::<i64>(&rt)?, 2); // globals persist between calls
//! # Ok::<(), mrt_script::ScriptError>(())
//! ```
//!
//! | seed name (ThinkingCap) | Rust |
//! |---|---|
//! | Lua interpreter embedded in the robot | [`LuaRuntime`] |
//! | a behavior script | [`Script`] |
//! | loading strategies: file each call / source in memory / compiled in memory (§3.2) | [`LoadStrategy`] |
//! | chaoslib, the robot API (§3.3) | [`chaos`] |
//! | HBM behaviors: fuzzy rules, perceptual rules, meta-rules, CDB (§4.1) | [`hbm`] (on [`mrt_fuzzy::hbm`]) |
//! | HFSM: states, meta-states, prioritized transitions (§5.1) | [`hfsm`] |
//! | the high-level object running HFSM and HBM every 100 ms (§2.2, §3.2) | [`ThinkingCap`], [`member::BehaviorMember`] |
//! | sending an edited behavior to the running robot (§3.1) | [`ScriptWatcher`] (compiles off the control path), [`member::ReloadRequest`] |
//!
//! The user guide is `docs/behaviors.md`; the seed's behaviors ship in `behaviors/teamchaos/`.
#![deny(missing_docs)]

pub mod blackboard;
mod cap;
pub mod chaos;
mod error;
pub mod hbm;
pub mod hfsm;
pub mod member;
pub mod offline;
pub mod push;
mod runtime;
mod script;
mod watch;
mod watchdog;

pub use cap::{Cycle, ThinkingCap, FAULT_LIMIT, RUNAWAY_LIMIT};
pub use error::{ScriptError, MAX_TEXT};
pub use runtime::{Interrupt, LuaRuntime, Sandbox, PRINT_LINES_PER_CALL, STEP_BYTES};
pub use script::{LoadStrategy, Script};
pub use watch::{compile_source, Change, Compiled, ScriptWatcher};
pub use watchdog::{
    Watchdog, DEFAULT_DEADLINE, HEALTHY_CYCLES, LOAD_DEADLINE, MAX_BACKOFF, MAX_RESTARTS,
    RESTART_AFTER, SIMULATED_DEADLINE,
};
