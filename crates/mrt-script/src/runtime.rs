//! The sandboxed Lua state, its instruction budget and its memory limit.
//!
//! The budget cannot be slipped: the count hook is global, so every coroutine is
//! metered too; once a call has spent its budget (or the watchdog has interrupted it) the
//! overrun is sticky until the next call, and `pcall`, `xpcall` and `coroutine.resume` pass it
//! on instead of catching it; `__gc` finalizers (which Lua runs with hooks off) are refused;
//! `print` writes to the robot's log, a bounded number of lines per call; error texts are
//! clipped.
//!
//! Work done inside the libraries' C functions is paid for from the same budget, so that a
//! call's running time is bounded by its budget whatever it calls ([`STEP_BYTES`] bytes of
//! output or of scanned text count as one instruction):
//! - work that the arguments decide before it starts is charged first, and a call that would
//!   need more than the call has left is refused without running: Lua patterns at their worst
//!   case (`string.find`, `match`, `gmatch`, `gsub`), `string.rep`'s count, the elements
//!   `table.insert` and `table.remove` shift, `table.move`, `table.concat`, `table.unpack`,
//!   `table.sort` (2 n log n) — a table's length through `__len` included — and the
//!   text `load` compiles, a reader function's pieces included;
//! - a plain `string.find` (and one whose pattern has no special characters) runs in linear
//!   time, outside Lua's quadratic search, charged an instruction a byte searched;
//! - work in proportion to what a call returns (`string.format`, `sub`, `upper`, `byte`...)
//!   is charged when it returns;
//! - every byte the state allocates is charged too ([`STEP_BYTES`] an instruction), which
//!   meters `..` on long strings, and a call that has spent its budget cannot allocate a
//!   large block (the charging allocator, `alloc.rs`).
//!
//! A chunk name given to `load` names the chunk as a string, never as a file (an error cannot
//! blame another script). What none of this sees (a Rust function that blocks) is the
//! [`Watchdog`](crate::Watchdog)'s.

// The one module of the workspace with `unsafe`: a C allocator around Lua's.
#[allow(unsafe_code)]
mod alloc;

use crate::error::{clip, ScriptError, MAX_TEXT};
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
    /// A million instructions per call, 32 MiB. A million instructions take a few
    /// milliseconds, a few percent of a robot's cycle even on a slow board, so a runaway call
    /// costs its robot one cycle and the other robots nothing; TeamChaos' behaviors need a few
    /// thousand a cycle.
    fn default() -> Self {
        Self { instruction_budget: 1_000_000, memory_limit: 32 << 20 }
    }
}

/// Instructions between two budget checks.
const CHECK_EVERY: u32 = 1000;

/// Lines `print` writes to the log in one call; more are counted and dropped.
pub const PRINT_LINES_PER_CALL: usize = 20;

/// Bytes of a C function's output (or of text it scans) that cost one instruction of the
/// budget.
pub const STEP_BYTES: usize = 16;

/// Instructions of the budget one byte of text costs `load` to compile.
const LOAD_STEPS_PER_BYTE: u64 = 4;

/// Shared between the runtime, its hook and the watchdog.
#[derive(Debug, Default)]
pub(crate) struct Meter {
    /// Instructions executed by the current call, with the work charged for C functions.
    used: AtomicU64,
    /// The budget.
    limit: u64,
    /// Set by the watchdog: abort the running call at the next check.
    interrupted: Arc<AtomicBool>,
    /// `print` lines written during the current call.
    printed: AtomicUsize,
    /// Where the current call ran past its budget: the script (its chunk name) and the line.
    overrun_at: Mutex<Option<(String, usize)>>,
    /// Calls in progress ([`LuaRuntime::start_call`]).
    calls: AtomicUsize,
}

impl Meter {
    /// The current call has spent its budget or was interrupted: nothing may catch that.
    fn spent(&self) -> bool {
        self.interrupted.load(Ordering::Relaxed) || self.used.load(Ordering::Relaxed) > self.limit
    }

    /// Instructions left to the current call.
    fn left(&self) -> u64 {
        self.limit.saturating_sub(self.used.load(Ordering::Relaxed))
    }

    /// Pays `steps` for work about to be done (`what`, for the error), or refuses it
    /// unrun: as an overrun of the budget when the budget is nearly spent, as an error of its
    /// own when the work alone is more than a whole budget.
    fn charge(&self, lua: &Lua, steps: f64, what: impl FnOnce() -> String) -> mlua::Result<()> {
        if steps.is_nan() || steps > self.limit as f64 {
            return Err(mlua::Error::runtime(format!(
                "{} needs up to {steps:.1e} steps, more than a whole call's budget ({})",
                what(),
                self.limit
            )));
        }
        if steps > self.left() as f64 {
            return Err(self.overrun(lua));
        }
        self.spend(steps as u64);
        Ok(())
    }

    /// Ends the current call as an overrun of its budget, noting where the script was.
    fn overrun(&self, lua: &Lua) -> mlua::Error {
        self.used.store(self.limit.saturating_add(1), Ordering::Relaxed);
        let mut at = self.overrun_at.lock().unwrap_or_else(PoisonError::into_inner);
        if at.is_none() {
            // The innermost frame of a script file (the sandbox's wrappers are not files).
            *at = (1..64).find_map(|level| {
                lua.inspect_stack(level, |d| {
                    let source = d.source();
                    let file = source.source.as_deref()?.strip_prefix('@')?.to_string();
                    Some((file, d.current_line().unwrap_or(0)))
                })?
            });
        }
        mlua::Error::runtime(BUDGET_EXCEEDED)
    }

    /// Pays `steps` for work already done; an overrun is raised at the next budget check.
    pub(crate) fn spend(&self, steps: u64) {
        self.used.fetch_add(steps, Ordering::Relaxed);
    }

    /// A call is running and has spent its budget: it may not grow its memory much further.
    pub(crate) fn refuses_growth(&self) -> bool {
        self.calls.load(Ordering::Relaxed) > 0 && self.spent()
    }
}

/// A call in progress, from [`LuaRuntime::start_call`] until dropped.
pub(crate) struct Call<'a>(&'a Meter);

impl Drop for Call<'_> {
    fn drop(&mut self) {
        self.0.calls.fetch_sub(1, Ordering::Relaxed);
    }
}

/// Stops the call running in a [`LuaRuntime`] from another thread (the watchdog's handle).
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<AtomicBool>);

thread_local! {
    /// The handle the next runtime made on this thread obeys ([`Interrupt::for_next_runtime`]).
    static NEXT: std::cell::RefCell<Option<Interrupt>> = const { std::cell::RefCell::new(None) };
}

impl Interrupt {
    /// Makes the next [`LuaRuntime`] created on this thread obey this handle, so that loading
    /// behaviors (which makes the runtime and runs the scripts' top level) can be stopped
    /// before the runtime exists to give its own handle.
    pub fn obeyed_by_next_runtime(&self) {
        NEXT.with(|n| *n.borrow_mut() = Some(self.clone()));
    }

    /// Forgets a handle no runtime took up ([`Interrupt::obeyed_by_next_runtime`]).
    pub(crate) fn forget_next() {
        NEXT.with(|n| n.borrow_mut().take());
    }

    /// Aborts the running call at its next budget check (within 1000 VM instructions of Lua
    /// code; a C function in progress finishes first) and every call after it.
    pub fn interrupt(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// A Lua state prepared for robot behaviors. One per behavior Member (a Lua state belongs to
/// one thread).
pub struct LuaRuntime {
    pub(crate) lua: Lua,
    sandbox: Sandbox,
    meter: Arc<Meter>,
    /// The charging allocator, taken out when the runtime is dropped.
    allocator: Option<alloc::Installed>,
}

impl Drop for LuaRuntime {
    fn drop(&mut self) {
        if let Some(installed) = self.allocator.take() {
            alloc::uninstall(&self.lua, installed);
        }
    }
}

/// Globals removed from the base library: they reach files or load arbitrary code.
const REMOVED: [&str; 4] = ["dofile", "loadfile", "require", "collectgarbage"];

/// The sandbox's own Lua, run once with the helpers below as arguments; every original it
/// wraps stays in a local of this chunk, out of the scripts' reach (no `debug` library).
const PRELUDE: &str = r##"
local spent, log, charge, spend, pattern_cost, span_cost, find_plain, rep_cost = ...
local raw_pcall, raw_xpcall, raw_resume = pcall, xpcall, coroutine.resume
local raw_load, raw_setmetatable, rawget, select, tostring, type, error =
    load, setmetatable, rawget, select, tostring, type, error
local S, T = string, table
local concat, byte, sub = T.concat, S.byte, S.sub
-- Outputs shorter than this are paid for by the wrapper's own instructions.
local SMALL = 4096

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
-- A reader's pieces are gathered (and paid for) here; a chunk name is never a file's.
load = function(chunk, name, _mode, ...)
  if type(chunk) == "function" then
    local reader, parts = chunk, {}
    while true do
      -- As Lua's own `load`: an error in the reader is `load`'s result, not raised.
      local ok, piece = raw_pcall(reader)
      if not ok then
        if spent() then error(piece, 0) end
        return nil, piece
      end
      if piece == nil or piece == "" then break end
      if type(piece) ~= "string" then return nil, "reader function must return a string" end
      charge("load", #piece)
      parts[#parts + 1] = piece
    end
    chunk = concat(parts)
  elseif type(chunk) == "string" then
    charge("load", #chunk)
  end
  if name == nil then
    name = "=(load)"
  elseif type(name) == "string" then
    local first = byte(name, 1)
    if first == 64 or first == 61 then name = sub(name, 2) end -- '@' (a file), '=' (verbatim)
  end
  if select("#", ...) > 0 then return raw_load(chunk, name, "t", ...) end
  return raw_load(chunk, name, "t")
end

print = function(...)
  local n = select("#", ...)
  local parts = {}
  for i = 1, n do parts[i] = tostring((select(i, ...))) end
  log(concat(parts, "\t"))
end

-- The library's own functions, called by their names so that their errors name them.
local Sc, Tc = {}, {}
for k, v in next, S do Sc[k] = v end
for k, v in next, T do Tc[k] = v end

-- Work in proportion to what a call returned.
local function paid(r, ...)
  if type(r) == "string" and #r > SMALL then spend(#r) end
  return r, ...
end
local function counted(...)
  local n = select("#", ...)
  if n > SMALL then spend(n * 16) end
  return ...
end
S.format = function(...) return paid(Sc.format(...)) end
S.lower = function(...) return paid(Sc.lower(...)) end
S.upper = function(...) return paid(Sc.upper(...)) end
S.reverse = function(...) return paid(Sc.reverse(...)) end
S.sub = function(...) return paid(Sc.sub(...)) end
S.char = function(...) return paid(Sc.char(...)) end
S.pack = function(...) return paid(Sc.pack(...)) end
S.byte = function(...) return counted(Sc.byte(...)) end
S.unpack = function(...) return counted(Sc.unpack(...)) end
S.rep = function(s, n, sep)
  rep_cost(s, n, sep)
  return Sc.rep(s, n, sep)
end

-- Lua patterns backtrack: a match is paid for at its worst case, or refused. A find with a
-- plain pattern runs in linear time outside Lua.
S.find = function(s, p, init, plain, ...)
  local done, i, j = find_plain(s, p, init, plain)
  if done then
    if i then return i, j end
    return nil
  end
  pattern_cost("string.find", s, p)
  return Sc.find(s, p, init, plain, ...)
end
S.match = function(s, p, ...)
  pattern_cost("string.match", s, p)
  return Sc.match(s, p, ...)
end
S.gmatch = function(s, p, ...)
  pattern_cost("string.gmatch", s, p)
  return Sc.gmatch(s, p, ...)
end
S.gsub = function(s, p, ...)
  pattern_cost("string.gsub", s, p)
  return paid(Sc.gsub(s, p, ...))
end

-- Work that a table's length decides, which `__len` may make anything.
local function len(t)
  local kind = type(t)
  if kind == "table" or kind == "string" then return #t end
  return nil
end
T.insert = function(t, ...)
  if select("#", ...) >= 2 then span_cost("table.insert", (...), len(t)) end
  return Tc.insert(t, ...)
end
T.remove = function(t, ...)
  if select("#", ...) >= 1 then span_cost("table.remove", (...), len(t)) end
  return Tc.remove(t, ...)
end
T.move = function(a, f, e, t, ...)
  span_cost("table.move", f, e)
  return Tc.move(a, f, e, t, ...)
end
T.concat = function(t, sep, i, j)
  span_cost("table.concat", i or 1, j or len(t))
  return paid(Tc.concat(t, sep, i, j))
end
T.unpack = function(t, i, j)
  span_cost("table.unpack", i or 1, j or len(t))
  return Tc.unpack(t, i, j)
end
T.sort = function(t, ...)
  span_cost("table.sort", 1, len(t), true)
  return Tc.sort(t, ...)
end
T.pack = function(...) return Tc.pack(counted(...)) end
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
        let interrupted = NEXT.with(|n| n.borrow_mut().take()).unwrap_or_default().0;
        let meter =
            Arc::new(Meter { limit: sandbox.instruction_budget, interrupted, ..Meter::default() });
        install_prelude(&lua, &meter).map_err(ScriptError::setup)?;
        lua.set_memory_limit(sandbox.memory_limit).map_err(ScriptError::setup)?;
        let allocator = Some(alloc::install(&lua, meter.clone()).map_err(ScriptError::setup)?);
        // Behaviors make short-lived garbage every cycle (tables, closures, strings): the
        // generational collector reclaims it in small steps, keeping the heap near its live size.
        lua.gc_set_mode(mlua::state::GcMode::Generational(mlua::state::GcGenParams::default()));
        let m = meter.clone();
        // A global hook: coroutines the scripts create inherit it (a thread hook would not
        // follow them).
        lua.set_global_hook(
            HookTriggers::new().every_nth_instruction(CHECK_EVERY),
            move |_, debug| {
                if m.interrupted.load(Ordering::Relaxed) {
                    return Err(mlua::Error::runtime(INTERRUPTED));
                }
                if m.used.fetch_add(u64::from(CHECK_EVERY), Ordering::Relaxed) < m.limit {
                    return Ok(VmState::Continue);
                }
                // The running function is the one that loops: note its script and line so
                // that the error names them, even inside a behavior `use`d by another.
                let source = debug.source();
                let file = source.source.as_deref().and_then(|s| s.strip_prefix('@'));
                let mut at = m.overrun_at.lock().unwrap_or_else(PoisonError::into_inner);
                if at.is_none() {
                    *at = file.map(|f| (f.to_string(), debug.current_line().unwrap_or(0)));
                }
                Err(mlua::Error::runtime(BUDGET_EXCEEDED))
            },
        )
        .map_err(ScriptError::setup)?;
        Ok(LuaRuntime { lua, sandbox, meter, allocator })
    }

    /// The limits.
    pub fn sandbox(&self) -> Sandbox {
        self.sandbox
    }

    /// Starts a call with a fresh budget; the call lasts until the result is dropped.
    pub(crate) fn start_call(&self) -> Call<'_> {
        self.meter.used.store(0, Ordering::Relaxed);
        self.meter.printed.store(0, Ordering::Relaxed);
        self.meter.overrun_at.lock().unwrap_or_else(PoisonError::into_inner).take();
        self.meter.calls.fetch_add(1, Ordering::Relaxed);
        Call(&self.meter)
    }

    /// Where the last budget overrun happened (script, line), if in a script; cleared.
    pub(crate) fn take_overrun(&self) -> Option<(String, usize)> {
        self.meter.overrun_at.lock().unwrap_or_else(PoisonError::into_inner).take()
    }

    /// Whether the current call ran past its budget.
    pub(crate) fn overran(&self) -> bool {
        self.meter.used.load(Ordering::Relaxed) > self.meter.limit
    }

    /// The watchdog's handle on this runtime.
    pub fn interrupt_handle(&self) -> Interrupt {
        Interrupt(self.meter.interrupted.clone())
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
    // `load`'s text, before it is compiled.
    let m = meter.clone();
    let charge = lua.create_function(move |lua, (name, bytes): (String, u64)| {
        m.charge(lua, bytes as f64 * LOAD_STEPS_PER_BYTE as f64, || {
            format!("{name}: {bytes} bytes of text")
        })
    })?;
    // Bytes of output already made.
    let m = meter.clone();
    let spend = lua.create_function(move |_, bytes: u64| {
        m.spend(bytes / STEP_BYTES as u64);
        Ok(())
    })?;
    let m = meter.clone();
    let pattern_cost = lua.create_function(move |lua, (name, s, p): (String, Value, Value)| {
        let (Some(subject), Some(pattern)) = (text_of(lua, s), text_of(lua, p)) else {
            return Ok(()); // Not strings: the function itself reports the bad argument.
        };
        let (subject, pattern) = (subject.as_bytes().len(), pattern.as_bytes());
        let steps = pattern_work(subject, &pattern);
        m.charge(lua, steps, || {
            format!(
                "{name} (use a shorter subject, a simpler pattern or a plain find): the \
                 pattern '{}' on a subject of {subject} bytes",
                clip(&String::from_utf8_lossy(&pattern), 80),
            )
        })
    })?;
    // Elements `from..=to` visited (or sorted, n log n), `to` often a table's length.
    let m = meter.clone();
    let span_cost =
        lua.create_function(move |lua, (name, from, to, sort): (String, Value, Value, bool)| {
            let (Some(from), Some(to)) = (int_of(lua, from), int_of(lua, to)) else {
                return Ok(()); // The function itself reports the bad argument.
            };
            let n = (to as f64 - from as f64 + 1.0).max(0.0);
            // A comparison of the sort reads and writes elements: two instructions' worth.
            let steps = if sort && n > 1.0 { 2.0 * n * n.log2() } else { n };
            m.charge(lua, steps, || format!("{name}: {n:.0} elements"))
        })?;
    let m = meter.clone();
    let find_plain =
        lua.create_function(move |lua, (s, p, init, plain): (Value, Value, Value, Value)| {
            let none = (false, None, None);
            let (Some(s), Some(p)) = (text_of(lua, s), text_of(lua, p)) else {
                return Ok(none);
            };
            let (s, p) = (s.as_bytes(), p.as_bytes());
            let plain = !matches!(plain, Value::Nil | Value::Boolean(false));
            if !plain && p.iter().any(|c| b"^$*+?.([%-".contains(c)) {
                return Ok(none); // A pattern: Lua's matcher.
            }
            let init = match init {
                Value::Nil => 1,
                v => match int_of(lua, v) {
                    Some(i) => i,
                    None => return Ok(none), // Lua reports the bad argument.
                },
            };
            // A search's worst case costs about an instruction a byte (a periodic needle).
            let scanned = (s.len() + p.len()) as f64;
            m.charge(lua, scanned, || format!("string.find: {scanned} bytes to search"))?;
            Ok(match find_bytes(&s, &p, init) {
                Some((i, j)) => (true, Some(i), Some(j)),
                None => (true, None, None),
            })
        })?;
    let m = meter.clone();
    let rep_cost = lua.create_function(move |lua, (s, n, sep): (Value, Value, Value)| {
        let (Some(s), Some(n)) = (text_of(lua, s), int_of(lua, n)) else {
            return Ok(());
        };
        let sep = match sep {
            Value::Nil => 0,
            v => text_of(lua, v).map_or(0, |t| t.as_bytes().len()),
        };
        if n <= 0 {
            return Ok(());
        }
        let (count, n) = (n, n as f64);
        let bytes = n * s.as_bytes().len() as f64 + (n - 1.0) * sep as f64;
        // Lua copies piece by piece: an instruction a copy, and the bytes.
        m.charge(lua, n + bytes / STEP_BYTES as f64, || format!("string.rep: {count} copies"))
    })?;
    let helpers = [spent, log, charge, spend, pattern_cost, span_cost, find_plain, rep_cost];
    lua.load(PRELUDE)
        .set_name("=sandbox")
        .call::<()>(MultiValue::from_iter(helpers.into_iter().map(Value::Function)))
}

/// Lua's plain `string.find(s, p, init, true)`, in linear time: the 1-based first and last
/// positions of the first `p` in `s` from `init` (negative counts from the end).
pub(crate) fn find_bytes(s: &[u8], p: &[u8], init: i64) -> Option<(i64, i64)> {
    let len = s.len() as i64;
    let start = match init {
        i if i > 0 => i,
        0 => 1,
        i if i < -len => 1,
        i => len + i + 1,
    } - 1;
    if start > len {
        return None;
    }
    let at = memchr::memmem::find(&s[start as usize..], p)? as i64 + start;
    Some((at + 1, at + p.len() as i64))
}

/// An integer argument as Lua reads one (a float with an integral value, or a string of
/// one, converts); saturating beyond `i64`.
fn int_of(lua: &Lua, v: Value) -> Option<i64> {
    match v {
        Value::Integer(i) => Some(i),
        Value::Number(n) if n.is_finite() => Some(n as i64),
        Value::String(_) => match lua.coerce_number(v).ok()?? {
            n if n.is_finite() => Some(n as i64),
            _ => None,
        },
        _ => None,
    }
}

/// A string argument as the string library reads one (numbers are strings to it).
fn text_of(lua: &Lua, v: Value) -> Option<mlua::LuaString> {
    match v {
        Value::String(s) => Some(s),
        Value::Integer(_) | Value::Number(_) => lua.coerce_string(v).ok()?,
        _ => None,
    }
}

/// An upper bound on the steps Lua's backtracking matcher may take for `pattern` over a
/// subject of `n` bytes, all start positions together: each item is one step per attempt
/// (a factor of the number of items), each `*`, `+`, `-` or `%b` item may try every remaining
/// position (a factor `n`), each `?` both ways (a factor 2), and an unanchored pattern is
/// tried at every start (a factor `n`).
pub(crate) fn pattern_work(n: usize, pattern: &[u8]) -> f64 {
    let n = (n as f64).max(1.0);
    let (mut i, mut work, mut items) = (0, 1.0_f64, 0.0_f64);
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
        items += 1.0;
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
    work * items.max(1.0)
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
        // A literal is tried at every start, one step per character.
        assert_eq!(pattern_work(100, b"abc"), 300.0);
        assert_eq!(pattern_work(100, b"^abc"), 3.0);
        assert_eq!(pattern_work(100, b"a*b"), 100.0 * 100.0 * 2.0);
        assert_eq!(pattern_work(100, b"^%s*(.-)%s*$"), 4e6);
        assert_eq!(pattern_work(10, b"a?a?b"), 10.0 * 4.0 * 3.0);
        assert_eq!(pattern_work(10, b"%b()"), 100.0);
        assert_eq!(pattern_work(10, b"[%]*]*x"), 200.0, "a set with an escaped ] and a *");
        assert_eq!(pattern_work(10, b"[]]-"), 100.0, "a leading ] is a member");
        assert_eq!(pattern_work(10, b"%f[%w]%w+"), 200.0);
    }

    #[test]
    fn find_bytes_follows_lua_positions() {
        assert_eq!(find_bytes(b"hello", b"l", 1), Some((3, 3)));
        assert_eq!(find_bytes(b"hello", b"l", 4), Some((4, 4)));
        assert_eq!(find_bytes(b"hello", b"lo", -2), Some((4, 5)));
        assert_eq!(find_bytes(b"hello", b"h", -99), Some((1, 1)), "before the start is 1");
        assert_eq!(find_bytes(b"hello", b"h", 0), Some((1, 1)));
        assert_eq!(find_bytes(b"hello", b"", 6), Some((6, 5)), "an empty needle at the end");
        assert_eq!(find_bytes(b"hello", b"", 7), None, "past the end");
        assert_eq!(find_bytes(b"hello", b"x", 1), None);
        assert_eq!(find_bytes(b"hi", b"hello", 1), None);
        assert_eq!(find_bytes(b"abc", b"c", i64::MAX), None);
        assert_eq!(find_bytes(b"abc", b"a", i64::MIN), Some((1, 1)));
    }
}
