//! The sandboxed Lua state, its instruction budget and its memory limit.
//!
//! The budget cannot be slipped: the count hook is global, so every coroutine is
//! metered too; once a call has spent its budget (or the watchdog has interrupted it) the
//! overrun is sticky until the next call, and `pcall`, `xpcall` and `coroutine.resume` pass it
//! on instead of catching it; `__gc` finalizers (which Lua runs with hooks off) are refused;
//! the C functions whose running time a script's arguments decide (Lua patterns,
//! `table.move`) refuse work beyond the budget; `print` writes to the robot's log, a bounded
//! number of lines per call; error texts are clipped. What none of this sees (a C function
//! that blocks) is the [`Watchdog`](crate::Watchdog)'s.

use crate::script::ScriptError;
use mlua::{HookTriggers, Lua, LuaOptions, MultiValue, StdLib, Value, VmState};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// Limits applied to every script call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sandbox {
    /// Lua VM instructions one call may execute (checked every 1000 instructions), in every
    /// coroutine of the call together. Also the most steps a pattern match may need in the
    /// worst case.
    pub instruction_budget: u64,
    /// Bytes the whole Lua state may allocate, values stored through the robot API
    /// (`chaos.setGlobal`) included.
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

/// Lines `print` writes to the log in one call; more are counted and dropped.
pub const PRINT_LINES_PER_CALL: usize = 20;

/// Longest text (bytes) of one `print` line, an error message or a traceback; longer ones
/// are clipped with a note of how much was cut.
pub const MAX_TEXT: usize = 1024;

/// Shared between the runtime, its hook and the watchdog.
#[derive(Debug, Default)]
pub(crate) struct Meter {
    /// Instructions executed by the current call, in units of `CHECK_EVERY`.
    ticks: AtomicU64,
    /// The budget, in units of `CHECK_EVERY`.
    limit: u64,
    /// Set by the watchdog: abort the running call at the next check.
    interrupted: AtomicBool,
    /// `print` lines written during the current call.
    printed: AtomicUsize,
}

impl Meter {
    /// The current call has spent its budget or was interrupted: nothing may catch that.
    fn spent(&self) -> bool {
        self.interrupted.load(Ordering::Relaxed) || self.ticks.load(Ordering::Relaxed) > self.limit
    }

    /// Instructions left to the current call.
    fn left(&self) -> u64 {
        self.limit.saturating_sub(self.ticks.load(Ordering::Relaxed)) * u64::from(CHECK_EVERY)
    }
}

/// Stops the call running in a [`LuaRuntime`] from another thread (the watchdog's handle).
#[derive(Clone, Debug)]
pub struct Interrupt(Arc<Meter>);

impl Interrupt {
    /// Aborts the running call at its next budget check (within 1000 VM instructions of Lua
    /// code; a C function in progress finishes first) and every call after it.
    pub fn interrupt(&self) {
        self.0.interrupted.store(true, Ordering::Relaxed);
    }
}

/// A Lua state prepared for robot behaviors. One per behavior Member (a Lua state belongs to
/// one thread).
pub struct LuaRuntime {
    pub(crate) lua: Lua,
    sandbox: Sandbox,
    meter: Arc<Meter>,
    /// Where the last call ran past its budget: the script (its chunk name) and the line.
    overrun_at: Arc<Mutex<Option<(String, usize)>>>,
}

/// Globals removed from the base library: they reach files or load arbitrary code.
const REMOVED: [&str; 4] = ["dofile", "loadfile", "require", "collectgarbage"];

/// The sandbox's own Lua, run once with the helpers below as arguments; every original it
/// wraps stays in a local of this chunk, out of the scripts' reach (no `debug` library).
const PRELUDE: &str = r##"
local spent, log, pattern_cost, move_cost = ...
local raw_pcall, raw_xpcall, raw_resume = pcall, xpcall, coroutine.resume
local raw_load, raw_setmetatable, rawget, select, tostring, error =
    load, setmetatable, rawget, select, tostring, error
local concat = table.concat

-- An overrun is the script's end, not an error its code may catch.
local function pass(ok, ...)
  if not ok and spent() then error((...), 0) end
  return ok, ...
end
pcall = function(...) return pass(raw_pcall(...)) end
xpcall = function(...) return pass(raw_xpcall(...)) end
coroutine.resume = function(...) return pass(raw_resume(...)) end

-- Finalizers run with the hook off (also when the state closes): none in behaviors.
setmetatable = function(t, mt)
  if mt ~= nil and type(mt) == "table" and rawget(mt, "__gc") ~= nil then
    error("setmetatable: finalizers (__gc) are not available to behaviors", 2)
  end
  return raw_setmetatable(t, mt)
end

-- Text chunks only (bytecode can crash the VM); without an env the chunk sees the globals.
load = function(chunk, name, _mode, ...)
  if select("#", ...) > 0 then return raw_load(chunk, name, "t", ...) end
  return raw_load(chunk, name, "t")
end

print = function(...)
  local n = select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = tostring((select(i, ...))) end
  log(concat(parts, "\t"))
end

-- Lua patterns backtrack: refuse a match whose worst case exceeds what the call has left.
local function guarded(name, f, plain_at)
  return function(s, p, ...)
    if not (plain_at and select(plain_at - 2, ...)) then pattern_cost(name, s, p) end
    return f(s, p, ...)
  end
end
string.find = guarded("string.find", string.find, 4)
string.match = guarded("string.match", string.match)
string.gmatch = guarded("string.gmatch", string.gmatch)
string.gsub = guarded("string.gsub", string.gsub)

local raw_move = table.move
table.move = function(a, f, e, t, ...)
  move_cost(f, e)
  return raw_move(a, f, e, t, ...)
end
"##;

impl LuaRuntime {
    /// A sandboxed runtime with these limits.
    pub fn new(sandbox: Sandbox) -> Result<LuaRuntime, ScriptError> {
        let libs = StdLib::MATH | StdLib::STRING | StdLib::TABLE | StdLib::COROUTINE;
        let lua = Lua::new_with(libs, LuaOptions::default()).map_err(ScriptError::setup)?;
        let globals = lua.globals();
        for name in REMOVED {
            globals.set(name, mlua::Nil).map_err(ScriptError::setup)?;
        }
        let meter = Arc::new(Meter {
            limit: sandbox.instruction_budget / u64::from(CHECK_EVERY),
            ..Meter::default()
        });
        let overrun_at = Arc::new(Mutex::new(None));
        install_prelude(&lua, &meter).map_err(ScriptError::setup)?;
        lua.set_memory_limit(sandbox.memory_limit).map_err(ScriptError::setup)?;
        // Behaviors make short-lived garbage every cycle (tables, closures, strings): the
        // generational collector reclaims it in small steps, keeping the heap near its live size.
        lua.gc_set_mode(mlua::state::GcMode::Generational(mlua::state::GcGenParams::default()));
        let (m, position) = (meter.clone(), overrun_at.clone());
        // A global hook: coroutines the scripts create inherit it (a thread hook would not
        // follow them).
        lua.set_global_hook(
            HookTriggers::new().every_nth_instruction(CHECK_EVERY),
            move |_, debug| {
                if m.interrupted.load(Ordering::Relaxed) {
                    return Err(mlua::Error::runtime(INTERRUPTED));
                }
                if m.ticks.fetch_add(1, Ordering::Relaxed) < m.limit {
                    return Ok(VmState::Continue);
                }
                // The running function is the one that loops: note its script and line so
                // that the error names them, even inside a behavior `use`d by another.
                let source = debug.source();
                let file = source.source.as_deref().and_then(|s| s.strip_prefix('@'));
                let mut at = position.lock().unwrap_or_else(PoisonError::into_inner);
                if at.is_none() {
                    *at = file.map(|f| (f.to_string(), debug.current_line().unwrap_or(0)));
                }
                Err(mlua::Error::runtime(BUDGET_EXCEEDED))
            },
        )
        .map_err(ScriptError::setup)?;
        Ok(LuaRuntime { lua, sandbox, meter, overrun_at })
    }

    /// The limits.
    pub fn sandbox(&self) -> Sandbox {
        self.sandbox
    }

    /// Starts a new call's budget.
    pub(crate) fn reset_budget(&self) {
        self.meter.ticks.store(0, Ordering::Relaxed);
        self.meter.printed.store(0, Ordering::Relaxed);
        self.overrun_at.lock().unwrap_or_else(PoisonError::into_inner).take();
    }

    /// Where the last budget overrun happened (script, line), if in a script; cleared.
    pub(crate) fn take_overrun(&self) -> Option<(String, usize)> {
        self.overrun_at.lock().unwrap_or_else(PoisonError::into_inner).take()
    }

    /// Whether the current call ran past its budget.
    pub(crate) fn overran(&self) -> bool {
        self.meter.ticks.load(Ordering::Relaxed) > self.meter.limit
    }

    /// The watchdog's handle on this runtime.
    pub fn interrupt_handle(&self) -> Interrupt {
        Interrupt(self.meter.clone())
    }

    /// Whether the watchdog interrupted this runtime (every call fails from then on).
    pub fn interrupted(&self) -> bool {
        self.meter.interrupted.load(Ordering::Relaxed)
    }

    /// Memory in use by the Lua state, in bytes.
    pub fn used_memory(&self) -> usize {
        self.lua.used_memory()
    }

    /// The Lua state, to extend the robot API with functions of your own. Rust functions
    /// added here are not metered by the instruction budget: only the
    /// [`Watchdog`](crate::Watchdog) stops one that blocks.
    pub fn lua(&self) -> &Lua {
        &self.lua
    }
}

fn install_prelude(lua: &Lua, meter: &Arc<Meter>) -> mlua::Result<()> {
    let m = meter.clone();
    let spent = lua.create_function(move |_, ()| Ok(m.spent()))?;
    let m = meter.clone();
    let log = lua.create_function(move |_, line: mlua::LuaString| {
        let n = m.printed.fetch_add(1, Ordering::Relaxed);
        if n < PRINT_LINES_PER_CALL {
            tracing::info!(target: "mrt_script::print", "{}", clip(&line.to_string_lossy(), MAX_TEXT));
        } else if n == PRINT_LINES_PER_CALL {
            tracing::warn!(target: "mrt_script::print", "more than {PRINT_LINES_PER_CALL} lines printed in one call: the rest of this call's are dropped");
        }
        Ok(())
    })?;
    let m = meter.clone();
    let pattern_cost = lua.create_function(move |_, (name, s, p): (String, Value, Value)| {
        let (Some(subject), Some(pattern)) = (text_len(&s), text_of(&p)) else {
            return Ok(()); // Not strings: the function itself reports the bad argument.
        };
        let steps = pattern_work(subject, &pattern);
        let left = m.left();
        if steps > left as f64 {
            return Err(mlua::Error::runtime(format!(
                "{name}: the pattern '{}' may take up to {steps:.1e} steps on a subject of \
                 {subject} bytes, more than the {left} this call has left (use a shorter \
                 subject, a simpler pattern or a plain find)",
                clip(&String::from_utf8_lossy(&pattern), 80)
            )));
        }
        Ok(())
    })?;
    let m = meter.clone();
    let move_cost = lua.create_function(move |_, (f, e): (Value, Value)| {
        if let (Some(f), Some(e)) = (int_of(&f), int_of(&e)) {
            let count = e.saturating_sub(f);
            if count > 0 && count as u64 > m.left() {
                return Err(mlua::Error::runtime(format!(
                    "table.move: {count} elements are more than the {} steps this call has left",
                    m.left()
                )));
            }
        }
        Ok(())
    })?;
    lua.load(PRELUDE).set_name("=sandbox").call::<()>(MultiValue::from_iter([
        Value::Function(spent),
        Value::Function(log),
        Value::Function(pattern_cost),
        Value::Function(move_cost),
    ]))
}

/// An integer argument as Lua reads one (a float with an integral value converts).
fn int_of(v: &Value) -> Option<i64> {
    match *v {
        Value::Integer(i) => Some(i),
        // Saturating: a float beyond i64 is refused by `table.move` itself.
        Value::Number(n) if n.is_finite() => Some(n as i64),
        _ => None,
    }
}

/// The byte length of a string argument (numbers are strings to the string library).
fn text_len(v: &Value) -> Option<usize> {
    match v {
        Value::String(s) => Some(s.as_bytes().len()),
        Value::Integer(_) | Value::Number(_) => Some(32),
        _ => None,
    }
}

fn text_of(v: &Value) -> Option<Vec<u8>> {
    match v {
        Value::String(s) => Some(s.as_bytes().to_vec()),
        Value::Integer(i) => Some(i.to_string().into_bytes()),
        Value::Number(n) => Some(n.to_string().into_bytes()),
        _ => None,
    }
}

/// An upper bound on the steps Lua's backtracking matcher may take for `pattern` over a
/// subject of `n` bytes, all start positions together: each `*`, `+`, `-` or `%b` item may
/// try every remaining position (a factor `n`), each `?` both ways (a factor 2), and an
/// unanchored pattern is tried at every start (a factor `n`).
pub(crate) fn pattern_work(n: usize, pattern: &[u8]) -> f64 {
    let n = (n as f64).max(1.0);
    let (mut i, mut work) = (0, 1.0_f64);
    if pattern.first() == Some(&b'^') {
        i = 1;
    } else {
        work = n;
    }
    while i < pattern.len() {
        // One single-character class (or a capture bracket, a %b or %f item).
        let item_end = match pattern[i] {
            b'%' => match pattern.get(i + 1) {
                Some(b'b') => {
                    work *= n;
                    i + 4
                }
                Some(b'f') => set_end(pattern, i + 2),
                _ => i + 2,
            },
            b'[' => set_end(pattern, i),
            b'(' | b')' => {
                i += 1;
                continue;
            }
            _ => i + 1,
        };
        i = item_end;
        match pattern.get(i) {
            Some(b'*' | b'+' | b'-') => {
                work *= n;
                i += 1;
            }
            Some(b'?') => {
                work *= 2.0;
                i += 1;
            }
            _ => {}
        }
    }
    work
}

/// The index after the set `[...]` starting at `start` (Lua's rules: a `]` right after `[` or
/// `[^` is a member, `%x` escapes).
fn set_end(p: &[u8], start: usize) -> usize {
    let mut i = start + 1;
    if p.get(i) == Some(&b'^') {
        i += 1;
    }
    let mut first = true;
    while i < p.len() {
        match p[i] {
            b']' if !first => return i + 1,
            b'%' => i += 2,
            _ => i += 1,
        }
        first = false;
    }
    p.len()
}

/// `text` cut to at most `max` bytes (on a character boundary), saying how much was cut.
pub(crate) fn clip(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}… [{} more bytes]", &text[..end], text.len() - end)
}

/// The chunk name of the sandbox's own Lua, as errors and tracebacks show it.
pub(crate) const PRELUDE_NAME: &str = "sandbox";

/// The message a budget overrun raises inside Lua.
pub(crate) const BUDGET_EXCEEDED: &str = "instruction budget exceeded";

/// The message the watchdog's interrupt raises inside Lua.
pub(crate) const INTERRUPTED: &str = "interrupted by the watchdog";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pattern_work_counts_backtracking_items() {
        assert_eq!(pattern_work(100, b"abc"), 100.0); // a literal, tried at every start
        assert_eq!(pattern_work(100, b"^abc"), 1.0);
        assert_eq!(pattern_work(100, b"a*b"), 100.0 * 100.0);
        assert_eq!(pattern_work(100, b"^%s*(.-)%s*$"), 1e6);
        assert_eq!(pattern_work(10, b"a?a?b"), 10.0 * 4.0);
        assert_eq!(pattern_work(10, b"%b()"), 100.0);
        assert_eq!(pattern_work(10, b"[%]*]*x"), 100.0, "a set with an escaped ] and a *");
        assert_eq!(pattern_work(10, b"[]]-"), 100.0, "a leading ] is a member");
        assert_eq!(pattern_work(10, b"%f[%w]%w+"), 100.0);
    }

    #[test]
    fn clip_keeps_short_texts_and_cuts_long_ones_on_a_boundary() {
        assert_eq!(clip("short", 10), "short");
        let long = "é".repeat(10); // 20 bytes
        let c = clip(&long, 5);
        assert!(c.starts_with("éé…") && c.ends_with("[16 more bytes]"), "{c}");
    }
}
