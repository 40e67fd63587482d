//! The compiled-in TeamChaos behaviors and Team Milan configuration, written to a directory of
//! this process while some match uses them, so that a match needs no setup.
//!
//! The directory is removed when the last [`FilesDir`] handle on it is dropped: when the run
//! ends, also on an error (the handles unwind with it) and, through [`remove_embedded_dirs`]
//! from the binary's Ctrl-C handler, on an interrupt. A run no longer leaves
//! `/tmp/mrt-teamchaos-<pid>` behind.

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
pub(crate) fn embedded(name: &'static str, files: &[(&str, &str)]) -> Result<FilesDir, String> {
    let mut live = LIVE.lock().unwrap_or_else(PoisonError::into_inner);
    live.retain(|(_, w)| w.strong_count() > 0);
    if let Some(w) = live.iter().find(|(n, _)| *n == name).and_then(|(_, w)| w.upgrade()) {
        return Ok(FilesDir { path: w.0.clone(), _written: Some(w) });
    }
    let n = COUNT.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("mrt-{name}-{}-{n}", std::process::id()));
    // A directory left by an earlier process with the same id must not add stale files.
    if dir.exists() {
        std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let written = Arc::new(Written(dir.clone()));
    for (file, text) in files {
        let path = dir.join(file);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
        }
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    live.push((name, Arc::downgrade(&written)));
    Ok(FilesDir { path: dir, _written: Some(written) })
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
