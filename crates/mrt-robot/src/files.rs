//! The compiled-in TeamChaos behaviors and Team Milan configuration, written to a directory of
//! this process while some match uses them, so that a match needs no setup.
//!
//! The directory is removed when the last [`FilesDir`] handle on it is dropped: when the run
//! ends, also on an error (the handles unwind with it) and, through [`remove_embedded_dirs`]
//! from the binary's Ctrl-C handler, on an interrupt. A process killed outright (SIGKILL)
//! leaves its directory; the next process to write one removes those of processes no
//! longer running.

use crate::error::RobotError;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError, Weak};

/// A directory of behavior or configuration files: the user's own (never removed), or
/// compiled-in files written for this process (removed with the last handle).
#[derive(Clone, Debug)]
pub struct FilesDir {
    path: PathBuf,
    _written: Option<Arc<Written>>,
}

impl FilesDir {
    /// The user's directory, used as it is.
    pub fn user(path: impl Into<PathBuf>) -> FilesDir {
        FilesDir { path: path.into(), _written: None }
    }

    /// Where the files are.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl std::ops::Deref for FilesDir {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

impl AsRef<Path> for FilesDir {
    fn as_ref(&self) -> &Path {
        &self.path
    }
}

/// A written directory; removes itself when dropped.
#[derive(Debug)]
struct Written(PathBuf);

impl Drop for Written {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The written directories alive, by name, to share them and to clean up on Ctrl-C.
static LIVE: Mutex<Vec<(&'static str, Weak<Written>)>> = Mutex::new(Vec::new());

/// Tells apart the directories one process writes in turn.
static COUNT: AtomicU64 = AtomicU64::new(0);

/// The compiled-in `files` as a directory (written now unless a live handle already has it).
pub(crate) fn embedded(name: &'static str, files: &[(&str, &str)]) -> Result<FilesDir, RobotError> {
    let mut live = LIVE.lock().unwrap_or_else(PoisonError::into_inner);
    live.retain(|(_, w)| w.strong_count() > 0);
    if let Some(w) = live.iter().find(|(n, _)| *n == name).and_then(|(_, w)| w.upgrade()) {
        return Ok(FilesDir { path: w.0.clone(), _written: Some(w) });
    }
    let n = COUNT.fetch_add(1, Ordering::Relaxed);
    remove_orphans(name);
    let dir = std::env::temp_dir().join(format!("mrt-{name}-{}-{n}", std::process::id()));
    // A directory left by an earlier process with the same id must not add stale files.
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .map_err(|source| RobotError::Io { path: dir.clone(), source })?;
    }
    let written = Arc::new(Written(dir.clone()));
    for (file, text) in files {
        let path = dir.join(file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)
                .map_err(|source| RobotError::Io { path: parent.to_path_buf(), source })?;
        }
        std::fs::write(&path, text)
            .map_err(|source| RobotError::Io { path: path.clone(), source })?;
    }
    live.push((name, Arc::downgrade(&written)));
    Ok(FilesDir { path: dir, _written: Some(written) })
}

/// Removes the directories `mrt-<name>-<pid>-<n>` in the temporary directory that processes
/// no longer running left behind (killed with SIGKILL, which no handler sees). Only where
/// `/proc` tells which processes run.
pub fn remove_orphans(name: &str) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let prefix = format!("mrt-{name}-");
    let Ok(entries) = std::fs::read_dir(std::env::temp_dir()) else { return };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else { continue };
        let Some((pid, n)) = rest.split_once('-') else { continue };
        let ours = pid.parse::<u32>().is_ok() && n.parse::<u64>().is_ok();
        if ours && !proc.join(pid).exists() {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// Removes every compiled-in directory this process has written and still uses: for a
/// Ctrl-C handler that is about to exit the process (the handles are not dropped then).
pub fn remove_embedded_dirs() {
    let live = LIVE.lock().unwrap_or_else(PoisonError::into_inner);
    for (_, w) in live.iter() {
        if let Some(w) = w.upgrade() {
            let _ = std::fs::remove_dir_all(&w.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Writing a directory removes those left by processes that no longer run, and only
    /// those: not a running process's, not one of another name or form.
    #[test]
    fn writing_a_directory_removes_those_dead_processes_left() {
        if !Path::new("/proc/self").exists() {
            return;
        }
        let tmp = std::env::temp_dir();
        // No process has an id above the kernel's pid_max (at most 2^22).
        let dead = tmp.join("mrt-unit-orphans-999999999-0");
        let alive = tmp.join(format!("mrt-unit-orphans-{}-77", std::process::id()));
        let other = tmp.join("mrt-unit-orphans-notapid-0");
        for d in [&dead, &alive, &other] {
            std::fs::create_dir_all(d.join("sub")).unwrap();
        }
        let written = embedded("unit-orphans", &[("a.txt", "A")]).unwrap();
        assert!(!dead.exists(), "a dead process's directory is removed");
        assert!(alive.exists() && other.exists(), "the others are kept");
        for d in [&alive, &other] {
            std::fs::remove_dir_all(d).unwrap();
        }
        drop(written);
    }

    #[test]
    fn the_directory_lives_as_long_as_a_handle_and_is_shared_meanwhile() {
        let files = [("a.txt", "A"), ("sub/b.txt", "B")];
        let first = embedded("unit-test", &files).unwrap();
        let path = first.path().to_path_buf();
        assert_eq!(std::fs::read_to_string(path.join("sub/b.txt")).unwrap(), "B");
        let second = embedded("unit-test", &files).unwrap();
        assert_eq!(second.path(), path, "shared while alive");
        drop(first);
        assert!(path.exists(), "a handle is still alive");
        drop(second);
        assert!(!path.exists(), "removed with the last handle");
        let again = embedded("unit-test", &files).unwrap();
        assert_ne!(again.path(), path, "written anew");
        // (`remove_embedded_dirs` is tested through the binary: here it would pull the files
        // from under the matches other tests of this process play.)
    }

    #[test]
    fn a_users_directory_is_never_removed() {
        let dir = std::env::temp_dir().join(format!("mrt-user-dir-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        drop(FilesDir::user(&dir));
        assert!(dir.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
