//! # mrt-script: Lua behaviors for MRT robots
//!
//! ThinkingCap (TeamChaos, seed 001 §3) writes behaviors as Lua scripts so a team can change a
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
//!
//! The robot API `chaos.*` is in [`chaos`]; HFSMs and the fuzzy HBM/CDB behaviors come next.
#![deny(missing_docs)]

mod cap;
pub mod chaos;
pub mod hbm;
pub mod hfsm;
pub mod member;
mod runtime;
mod script;
mod watch;

pub use cap::{Cycle, ThinkingCap};
pub use runtime::{LuaRuntime, Sandbox};
pub use script::{LoadStrategy, Script, ScriptError};
pub use watch::{Change, Compiled, ScriptWatcher};
