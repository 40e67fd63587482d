//! A behavior script: loading strategies, calls with budgets, hot reload with fallback.

use crate::error::{clip, split_position, ScriptError, MAX_TEXT};
use crate::runtime::LuaRuntime;
use crate::watch::Compiled;
use mlua::chunk::ChunkMode;
use mlua::{FromLuaMulti, Function};
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

impl ScriptError {
    /// A Lua error of a call into `file` on `rt`: the runtime's meter tells an overrun, an
    /// interruption and a memory error from the script's own errors.
    pub(crate) fn from_lua(file: &str, rt: &LuaRuntime, e: mlua::Error) -> ScriptError {
        if let mlua::Error::SyntaxError { message, .. } = &e {
            // Lua says `[string "name"]:LINE: message` or `name:LINE: message`.
            let (line, msg) = split_position(message);
            return ScriptError::Syntax { file: file.into(), line, message: clip(&msg, MAX_TEXT) };
        }
        // An overrun is told by the meter, not by the error's text: a message handler may
        // have replaced the text on its way out.
        if rt.interrupted() {
            return ScriptError::Watchdog { file: file.into(), deadline_ms: 0 };
        }
        if rt.overran() {
            let (file, line) = rt.take_overrun().unwrap_or_else(|| (file.into(), 0));
            return ScriptError::Budget { file, line, budget: rt.sandbox().instruction_budget };
        }
        let text = e.to_string();
        if matches!(e, mlua::Error::MemoryError(_)) || text.contains("not enough memory") {
            return ScriptError::Memory { file: file.into(), limit: rt.sandbox().memory_limit };
        }
        runtime_error(file, &text)
    }
}

/// Splits Lua's runtime error text into the innermost script position, a clean message and
/// the traceback. Lua says `runtime error: name:LINE: message` for errors raised in Lua and
/// `bad argument #1: ...` (no position) for arguments a Rust function refused; the traceback
/// then names the function (`in field 'setVlin'`) and the script line that called it.
fn runtime_error(file: &str, text: &str) -> ScriptError {
    let (head, traceback) = match text.split_once("\nstack traceback:") {
        Some((h, t)) => (h, t.trim().to_string()),
        None => (text, String::new()),
    };
    let mut message = head;
    while let Some(rest) = message.strip_prefix("runtime error: ") {
        message = rest;
    }
    // An argument error raised inside the runtime's own wrappers names the script, not them.
    if let Some(rest) = message
        .strip_prefix(crate::runtime::PRELUDE_NAME)
        .and_then(|r| r.strip_prefix(':')?.split_once(':'))
        .filter(|(line, _)| line.parse::<usize>().is_ok())
        .map(|(_, rest)| rest.trim_start())
    {
        message = rest;
    }
    let mut position = script_position(message);
    if let Some((_, _, rest)) = &position {
        message = rest;
    }
    let mut message = message.trim().to_string();
    let frames: Vec<&str> = traceback.lines().map(str::trim).collect();
    if position.is_none() {
        position = frames.iter().find_map(|f| script_position(f));
    }
    if let Some(callee) = frames.first().and_then(|f| f.strip_prefix("[C]: in ")) {
        if message.starts_with("bad argument") {
            message = format!("{message} (calling {callee})");
        }
    }
    let (file, line) = match position {
        Some((f, l, _)) => (f.to_string(), l),
        None => (file.to_string(), 0),
    };
    // A script chooses its error text: keep what a person reads, not megabytes.
    let (message, traceback) = (clip(&message, MAX_TEXT), clip(&traceback, 4 * MAX_TEXT));
    ScriptError::Runtime { file, line, message, traceback }
}

/// `name:LINE: rest` at the start of `s` (name not `[C]`), as `(name, LINE, rest)`.
fn script_position(s: &str) -> Option<(&str, usize, &str)> {
    let (name, after) = s.split_once(':')?;
    let (line, rest) = after.split_once(':')?;
    let line = line.parse().ok()?;
    // `sandbox` is the runtime's own wrappers (`string.find`...): the script is further out.
    (!name.is_empty() && !name.starts_with('[') && name != crate::runtime::PRELUDE_NAME)
        .then_some((name, line, rest))
}

/// How a script is kept between calls (ThinkingCap §3.2; the seed measured 40 / 17 / 7 ms per
/// call on the AIBO for these three).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LoadStrategy {
    /// Read and compile the file at every call: edits apply at once, slowest.
    ReloadFromFile,
    /// Keep the source text; compile it at every call.
    Source,
    /// Keep the compiled chunk (default): fastest; edits apply through hot reload.
    #[default]
    Compiled,
}

/// A behavior script.
pub struct Script {
    name: String,
    path: Option<PathBuf>,
    strategy: LoadStrategy,
    source: RefCell<String>,
    compiled: RefCell<Function>,
    modified: RefCell<Option<SystemTime>>,
}

fn compile(rt: &LuaRuntime, name: &str, source: &str) -> Result<Function, ScriptError> {
    rt.lua
        .load(source)
        .set_name(format!("@{name}"))
        .set_mode(ChunkMode::Text)
        .into_function()
        .map_err(|e| ScriptError::from_lua(name, rt, e))
}

fn read(path: &Path) -> Result<String, ScriptError> {
    mrt_core::read_text(path, mrt_core::MAX_SCRIPT_BYTES)
        .map_err(|source| ScriptError::Io { file: path.display().to_string(), source })
}

/// A file's modification time (`None` when it cannot be read).
pub(crate) fn mtime(path: &Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

impl Script {
    /// Loads a script file. It must compile.
    pub fn from_file(
        rt: &LuaRuntime,
        path: impl AsRef<Path>,
        strategy: LoadStrategy,
    ) -> Result<Script, ScriptError> {
        let path = path.as_ref();
        let source = read(path)?;
        let name = path.display().to_string();
        let compiled = compile(rt, &name, &source)?;
        Ok(Script {
            name,
            path: Some(path.to_path_buf()),
            strategy,
            source: RefCell::new(source),
            compiled: RefCell::new(compiled),
            modified: RefCell::new(mtime(path)),
        })
    }

    /// A script from text (`name` appears in errors). `ReloadFromFile` acts as `Source` here.
    pub fn from_source(
        rt: &LuaRuntime,
        name: &str,
        source: &str,
        strategy: LoadStrategy,
    ) -> Result<Script, ScriptError> {
        let compiled = compile(rt, name, source)?;
        Ok(Script {
            name: name.to_string(),
            path: None,
            strategy,
            source: RefCell::new(source.to_string()),
            compiled: RefCell::new(compiled),
            modified: RefCell::new(None),
        })
    }

    /// The script's name (its path for files).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The loading strategy.
    pub fn strategy(&self) -> LoadStrategy {
        self.strategy
    }

    /// The compiled chunk (a cheap handle), for callers that run it inside another call.
    pub(crate) fn function(&self) -> Function {
        self.compiled.borrow().clone()
    }

    /// Runs the script once (one behavior tick) within the sandbox's budget, returning what
    /// the chunk returns. A failed call leaves the runtime and the script usable.
    pub fn call<R: FromLuaMulti>(&self, rt: &LuaRuntime) -> Result<R, ScriptError> {
        let _call = rt.start_call();
        let fresh = match (self.strategy, &self.path) {
            (LoadStrategy::ReloadFromFile, Some(p)) => Some(compile(rt, &self.name, &read(p)?)?),
            (LoadStrategy::Source, _) | (LoadStrategy::ReloadFromFile, None) => {
                Some(compile(rt, &self.name, &self.source.borrow())?)
            }
            (LoadStrategy::Compiled, _) => None,
        };
        let result = match fresh {
            Some(f) => f.call::<R>(()),
            // No clone of the kept function (a registry reference each time): call it in place.
            // Nothing a script can do reaches `reload_source` during the call.
            None => self.compiled.borrow().call::<R>(()),
        };
        result.map_err(|e| ScriptError::from_lua(&self.name, rt, e))
    }

    /// Replaces the script with `source` if it compiles; otherwise returns the error and keeps
    /// the running version. Lua globals (the behavior's state) are kept either way.
    pub fn reload_source(&self, rt: &LuaRuntime, source: &str) -> Result<(), ScriptError> {
        let f = compile(rt, &self.name, source)?;
        *self.compiled.borrow_mut() = f;
        *self.source.borrow_mut() = source.to_string();
        Ok(())
    }

    /// Swaps in a version compiled off the control path (by the [`ScriptWatcher`]'s thread).
    /// Loading bytecode is much cheaper than compiling text; the source is kept for the
    /// `Source` strategy. Lua globals are kept.
    ///
    /// [`ScriptWatcher`]: crate::ScriptWatcher
    pub fn install(&self, rt: &LuaRuntime, compiled: &Compiled) -> Result<(), ScriptError> {
        // Our own compiler's output, never a script's: binary chunks are allowed here only.
        let f = rt
            .lua
            .load(compiled.bytecode())
            .set_name(format!("@{}", self.name))
            .set_mode(ChunkMode::Binary)
            .into_function()
            .map_err(|e| ScriptError::from_lua(&self.name, rt, e))?;
        *self.compiled.borrow_mut() = f;
        compiled.source().clone_into(&mut self.source.borrow_mut());
        if let Some(path) = &self.path {
            *self.modified.borrow_mut() = mtime(path);
        }
        Ok(())
    }

    /// Reloads the file (an explicit reload request, e.g. a message on the bus).
    pub fn reload(&self, rt: &LuaRuntime) -> Result<(), ScriptError> {
        let Some(path) = &self.path else { return Ok(()) };
        let stamp = mtime(path);
        let source = read(path)?;
        // Remember the attempt even when it fails: a broken file is reported once, not at
        // every poll; the next save is tried again.
        *self.modified.borrow_mut() = stamp;
        self.reload_source(rt, &source)
    }

    /// Reloads the file if it changed since the last (attempted) load; `Ok(true)` when a new
    /// version was swapped in. Call it at a cycle boundary.
    pub fn reload_if_changed(&self, rt: &LuaRuntime) -> Result<bool, ScriptError> {
        let Some(path) = &self.path else { return Ok(false) };
        if mtime(path) == *self.modified.borrow() {
            return Ok(false);
        }
        self.reload(rt).map(|()| true)
    }
}
