//! The sandboxed Lua state, its instruction budget and its memory limit.

use crate::script::ScriptError;
use mlua::{HookTriggers, Lua, LuaOptions, StdLib, VmState};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// Limits applied to every script call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sandbox {
    /// Lua VM instructions one call may execute (checked every 1000 instructions).
    pub instruction_budget: u64,
    /// Bytes the whole Lua state may allocate.
    pub memory_limit: usize,
}

impl Default for Sandbox {
    /// 10 million instructions per call (a few milliseconds), 32 MiB.
    fn default() -> Self {
        Self { instruction_budget: 10_000_000, memory_limit: 32 << 20 }
    }
}

/// Instructions between two budget checks.
const CHECK_EVERY: u32 = 1000;

/// A Lua state prepared for robot behaviors. One per behavior Member (a Lua state belongs to
/// one thread).
pub struct LuaRuntime {
    pub(crate) lua: Lua,
    sandbox: Sandbox,
    /// Instructions executed by the current call, in units of `CHECK_EVERY`.
    ticks: Arc<AtomicU64>,
    /// Where the last call ran past its budget: the script (its chunk name) and the line.
    overrun_at: Arc<Mutex<Option<(String, usize)>>>,
}

/// Globals removed from the base library: they reach files or load arbitrary code.
const REMOVED: [&str; 4] = ["dofile", "loadfile", "require", "collectgarbage"];

impl LuaRuntime {
    /// A sandboxed runtime with these limits.
    pub fn new(sandbox: Sandbox) -> Result<LuaRuntime, ScriptError> {
        let libs = StdLib::MATH | StdLib::STRING | StdLib::TABLE | StdLib::COROUTINE;
        let lua = Lua::new_with(libs, LuaOptions::default()).map_err(ScriptError::setup)?;
        let globals = lua.globals();
        for name in REMOVED {
            globals.set(name, mlua::Nil).map_err(ScriptError::setup)?;
        }
        // `load` stays for text chunks only: bytecode can crash the VM.
        lua.load(
            r#"local raw_load = load
               load = function(chunk, name, _mode, env) return raw_load(chunk, name, "t", env) end"#,
        )
        .set_name("=sandbox")
        .exec()
        .map_err(ScriptError::setup)?;
        lua.set_memory_limit(sandbox.memory_limit).map_err(ScriptError::setup)?;
        // Behaviors make short-lived garbage every cycle (tables, closures, strings): the
        // generational collector reclaims it in small steps, keeping the heap near its live size.
        lua.gc_set_mode(mlua::state::GcMode::Generational(mlua::state::GcGenParams::default()));
        let ticks = Arc::new(AtomicU64::new(0));
        let counter = ticks.clone();
        let overrun_at = Arc::new(Mutex::new(None));
        let position = overrun_at.clone();
        let limit = sandbox.instruction_budget / u64::from(CHECK_EVERY);
        lua.set_hook(HookTriggers::new().every_nth_instruction(CHECK_EVERY), move |_, debug| {
            if counter.fetch_add(1, Ordering::Relaxed) + 1 > limit {
                // The running function is the one that loops: note its script and line so
                // that the error names them, even inside a behavior `use`d by another.
                let source = debug.source();
                let file = source.source.as_deref().and_then(|s| s.strip_prefix('@'));
                *position.lock().unwrap_or_else(PoisonError::into_inner) =
                    file.map(|f| (f.to_string(), debug.current_line().unwrap_or(0)));
                Err(mlua::Error::runtime(BUDGET_EXCEEDED))
            } else {
                Ok(VmState::Continue)
            }
        })
        .map_err(ScriptError::setup)?;
        Ok(LuaRuntime { lua, sandbox, ticks, overrun_at })
    }

    /// The limits.
    pub fn sandbox(&self) -> Sandbox {
        self.sandbox
    }

    /// Starts a new call's budget.
    pub(crate) fn reset_budget(&self) {
        self.ticks.store(0, Ordering::Relaxed);
    }

    /// Where the last budget overrun happened (script, line), if in a script; cleared.
    pub(crate) fn take_overrun(&self) -> Option<(String, usize)> {
        self.overrun_at.lock().unwrap_or_else(PoisonError::into_inner).take()
    }

    /// Memory in use by the Lua state, in bytes.
    pub fn used_memory(&self) -> usize {
        self.lua.used_memory()
    }
}

/// The message a budget overrun raises inside Lua.
pub(crate) const BUDGET_EXCEEDED: &str = "instruction budget exceeded";
