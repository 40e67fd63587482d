//! Watching script files for edits (`notify`), so a behavior changed on disk is reloaded at the
//! next cycle boundary without anyone asking.
//!
//! The watcher watches each script's directory (editors often save by writing a new file and
//! renaming it over the old one, which a watch on the file itself would miss) and reports the
//! watched scripts that were touched. Reloading stays the caller's move, at a cycle boundary:
//! [`Script::reload`](crate::Script::reload) compiles the new text and swaps it in only if it
//! compiles.

use crate::script::ScriptError;
use notify::{Event, RecommendedWatcher, RecursiveMode, Watcher};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver};

/// Reports which watched scripts changed on disk.
pub struct ScriptWatcher {
    watcher: RecommendedWatcher,
    events: Receiver<notify::Result<Event>>,
    scripts: BTreeSet<PathBuf>,
    dirs: BTreeSet<PathBuf>,
    /// Directories whose every `.lua` file counts as watched (new files included).
    whole_dirs: BTreeSet<PathBuf>,
}

fn absolute(path: &Path) -> PathBuf {
    std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())
}

impl ScriptWatcher {
    /// A watcher with nothing watched yet.
    pub fn new() -> Result<ScriptWatcher, ScriptError> {
        let (tx, events) = channel();
        let watcher = notify::recommended_watcher(tx)
            .map_err(|e| ScriptError::Setup(format!("file watcher: {e}")))?;
        Ok(ScriptWatcher {
            watcher,
            events,
            scripts: BTreeSet::new(),
            dirs: BTreeSet::new(),
            whole_dirs: BTreeSet::new(),
        })
    }

    /// Starts watching a script file.
    pub fn watch(&mut self, script: impl AsRef<Path>) -> Result<(), ScriptError> {
        let file = absolute(script.as_ref());
        let dir = file.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
        if self.dirs.insert(dir.clone()) {
            self.watcher.watch(&dir, RecursiveMode::NonRecursive).map_err(|e| ScriptError::Io {
                file: file.display().to_string(),
                source: std::io::Error::other(e.to_string()),
            })?;
        }
        self.scripts.insert(file);
        Ok(())
    }

    /// Starts watching every `.lua` file of a directory, including files created later.
    pub fn watch_dir(&mut self, dir: impl AsRef<Path>) -> Result<(), ScriptError> {
        let dir = absolute(dir.as_ref());
        if self.dirs.insert(dir.clone()) {
            self.watcher.watch(&dir, RecursiveMode::NonRecursive).map_err(|e| ScriptError::Io {
                file: dir.display().to_string(),
                source: std::io::Error::other(e.to_string()),
            })?;
        }
        self.whole_dirs.insert(dir);
        Ok(())
    }

    fn is_watched(&self, p: &Path) -> bool {
        self.scripts.contains(p)
            || (p.extension().is_some_and(|e| e == "lua")
                && p.parent().is_some_and(|d| self.whole_dirs.contains(d)))
    }

    /// The watched scripts touched since the last call (each once), without blocking.
    pub fn changed(&self) -> Vec<PathBuf> {
        let mut out = BTreeSet::new();
        while let Ok(ev) = self.events.try_recv() {
            let Ok(ev) = ev else { continue };
            if ev.kind.is_access() {
                continue;
            }
            for p in ev.paths {
                let p = absolute(&p);
                if self.is_watched(&p) {
                    out.insert(p);
                }
            }
        }
        out.into_iter().collect()
    }
}
