//! Watching script files for edits (`notify`), so a behavior changed on disk is reloaded at the
//! next cycle boundary without anyone asking — and compiled **off the control path**.
//!
//! The watcher watches each script's directory (editors often save by writing a new file and
//! renaming it over the old one, which a watch on the file itself would miss). When a watched
//! script is written, the watcher's own thread (notify's event thread) reads it and compiles
//! it with a private Lua state, so a syntax error is found and a good file is turned into
//! bytecode before the robot's control loop hears of it. The control loop then only swaps the
//! prepared bytecode in at a cycle boundary ([`Script::install`](crate::Script::install)),
//! which is much cheaper than compiling (see `docs/performance.md`).
//!
//! On Linux a file counts as written when it is closed after writing (or created, or renamed
//! into place), so a half-written file is not compiled; elsewhere every modification counts.

use crate::error::ScriptError;
use mlua::chunk::ChunkMode;
use notify::event::{AccessKind, AccessMode, CreateKind, ModifyKind, RenameMode};
use notify::{Event, EventKind, RecommendedWatcher, RecursiveMode, Watcher};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex};

/// A script compiled off the control path: its text and its bytecode. Only the watcher makes
/// these (the fields are private), so only bytecode of MRT's own compiler is ever loaded.
#[derive(Clone, Debug)]
pub struct Compiled {
    source: String,
    bytecode: Vec<u8>,
}

impl Compiled {
    /// The source text that was compiled.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Lua 5.4 bytecode of the chunk, with debug information (lines in errors).
    pub fn bytecode(&self) -> &[u8] {
        &self.bytecode
    }
}

/// One watched script that changed on disk.
#[derive(Debug)]
pub struct Change {
    /// The script's absolute path.
    pub path: PathBuf,
    /// The script's name as it was given to the watcher (what errors show).
    pub name: String,
    /// The compiled new version, or why it does not compile (or cannot be read).
    pub compiled: Result<Compiled, ScriptError>,
}

/// What is watched, shared with the event thread.
#[derive(Default)]
struct WatchList {
    /// Absolute path → name for errors.
    scripts: BTreeMap<PathBuf, String>,
    /// Absolute directory → the directory as given (its `.lua` files are watched).
    whole_dirs: BTreeMap<PathBuf, PathBuf>,
}

impl WatchList {
    /// The name of a watched script, `None` when the path is not watched.
    fn name_of(&self, p: &Path) -> Option<String> {
        if let Some(n) = self.scripts.get(p) {
            return Some(n.clone());
        }
        let given = self.whole_dirs.get(p.parent()?)?;
        if p.extension().is_some_and(|e| e == "lua") {
            return Some(given.join(p.file_name()?).display().to_string());
        }
        None
    }
}

/// Reports which watched scripts changed on disk, compiled.
pub struct ScriptWatcher {
    watcher: RecommendedWatcher,
    changes: Receiver<Change>,
    list: Arc<Mutex<WatchList>>,
    dirs: BTreeSet<PathBuf>,
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Whether the event says a file now holds its complete new content.
fn is_written(kind: &EventKind) -> bool {
    match kind {
        EventKind::Modify(ModifyKind::Name(
            RenameMode::To | RenameMode::Both | RenameMode::Any,
        )) => true,
        EventKind::Access(AccessKind::Close(AccessMode::Write)) => true,
        // Only Linux reports closes; elsewhere creation and modification are the best there
        // is. (On Linux a new file counts when it is closed after writing.)
        EventKind::Create(CreateKind::File | CreateKind::Any) | EventKind::Modify(_) => {
            !cfg!(target_os = "linux")
        }
        _ => false,
    }
}

thread_local! {
    /// The event thread's private Lua state, used only to compile (never to run) scripts.
    static COMPILER: mlua::Lua = mlua::Lua::new_with(mlua::StdLib::NONE, mlua::LuaOptions::default())
        .unwrap_or_else(|_| mlua::Lua::new());
}

/// Reads and compiles a script the way [`Script`](crate::Script) names it.
/// `None` for an empty file: events arrive after the fact, and a file read while an editor is
/// saving it again (truncated, not yet written) is empty; the save's own event follows. (A
/// behavior emptied on purpose is therefore not reloaded: delete its rules instead, or leave a
/// comment in it.)
pub(crate) fn compile_file(path: &Path, name: &str) -> Option<Result<Compiled, ScriptError>> {
    let source = match mrt_core::read_text(path, mrt_core::MAX_SCRIPT_BYTES) {
        Ok(s) if s.is_empty() => return None,
        Ok(s) => s,
        Err(source) => return Some(Err(ScriptError::Io { file: name.to_string(), source })),
    };
    Some(compile_source(name, source))
}

/// Compiles a script's text the way [`Script`](crate::Script) names it (`name` appears in
/// errors), with this thread's private compiler: call it off the control path. Text chunks
/// only: bytecode is refused, so only MRT's own compiler's output is ever loaded.
pub fn compile_source(name: &str, source: String) -> Result<Compiled, ScriptError> {
    COMPILER.with(|lua| {
        let f = lua
            .load(&source)
            .set_name(format!("@{name}"))
            .set_mode(ChunkMode::Text)
            .into_function()
            .map_err(|e| ScriptError::syntax(name, &e))?;
        Ok(Compiled { bytecode: f.dump(false), source })
    })
}

fn on_event(list: &Mutex<WatchList>, tx: &Sender<Change>, ev: notify::Result<Event>) {
    let Ok(ev) = ev else { return };
    if !is_written(&ev.kind) {
        return;
    }
    for p in ev.paths {
        let path = absolute(&p);
        let name = match list.lock() {
            Ok(l) => l.name_of(&path),
            Err(_) => None,
        };
        let Some(name) = name else { continue };
        if !path.is_file() {
            continue;
        }
        let Some(compiled) = compile_file(&path, &name) else { continue };
        if tx.send(Change { path, name, compiled }).is_err() {
            return;
        }
    }
}

impl ScriptWatcher {
    /// A watcher with nothing watched yet.
    pub fn new() -> Result<ScriptWatcher, ScriptError> {
        let (tx, changes) = channel();
        let list = Arc::new(Mutex::new(WatchList::default()));
        let shared = list.clone();
        let watcher = notify::recommended_watcher(move |ev| on_event(&shared, &tx, ev))
            .map_err(|e| ScriptError::Setup(format!("file watcher: {e}")))?;
        Ok(ScriptWatcher { watcher, changes, list, dirs: BTreeSet::new() })
    }

    fn watch_directory(&mut self, dir: &Path) -> Result<(), ScriptError> {
        if self.dirs.insert(dir.to_path_buf()) {
            self.watcher.watch(dir, RecursiveMode::NonRecursive).map_err(|e| ScriptError::Io {
                file: dir.display().to_string(),
                source: std::io::Error::other(e.to_string()),
            })?;
        }
        Ok(())
    }

    fn list(&self) -> Result<std::sync::MutexGuard<'_, WatchList>, ScriptError> {
        self.list.lock().map_err(|_| ScriptError::Setup("file watcher: poisoned".into()))
    }

    /// Starts watching a script file (named in errors as given here).
    pub fn watch(&mut self, script: impl AsRef<Path>) -> Result<(), ScriptError> {
        let file = absolute(script.as_ref());
        let dir = file.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        self.watch_directory(&dir)?;
        self.list()?.scripts.insert(file, script.as_ref().display().to_string());
        Ok(())
    }

    /// Starts watching every `.lua` file of a directory, including files created later.
    pub fn watch_dir(&mut self, dir: impl AsRef<Path>) -> Result<(), ScriptError> {
        let abs = absolute(dir.as_ref());
        self.watch_directory(&abs)?;
        self.list()?.whole_dirs.insert(abs, dir.as_ref().to_path_buf());
        Ok(())
    }

    /// The watched scripts changed since the last call, compiled (the latest version of each),
    /// without blocking.
    pub fn changes(&self) -> Vec<Change> {
        let mut latest: BTreeMap<PathBuf, Change> = BTreeMap::new();
        while let Ok(c) = self.changes.try_recv() {
            latest.insert(c.path.clone(), c);
        }
        latest.into_values().collect()
    }

    /// The watched scripts changed since the last call (each once), without blocking.
    pub fn changed(&self) -> Vec<PathBuf> {
        self.changes().into_iter().map(|c| c.path).collect()
    }
}
