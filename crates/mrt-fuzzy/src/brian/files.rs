//! Where a configuration's files come from: their standard names ([`BrianFiles`]), the disk
//! ([`Disk`]) or memory ([`BrianSources`]), both read through [`Source`]; and the check that a
//! rule file named in `behavior.txt` lies inside the configuration.

use super::parse::Listed;
use crate::error::BrianError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The file names of a configuration directory.
#[derive(Clone, Debug)]
pub struct BrianFiles {
    /// Input shapes (`shape_ctof.txt`).
    pub shape_ctof: PathBuf,
    /// Crisp data → shape (`ctof.txt`).
    pub ctof: PathBuf,
    /// Predicates (`Predicate.ini`).
    pub predicates: PathBuf,
    /// Predicate actions (`PredicateActions.ini`); may be absent.
    pub predicate_actions: PathBuf,
    /// Activation conditions (`Cando.ini`).
    pub cando: PathBuf,
    /// Motivations (`want.txt`).
    pub want: PathBuf,
    /// Behavior list (`behavior.txt`).
    pub behaviors: PathBuf,
    /// Output shapes (`s_shape.txt`).
    pub s_shape: PathBuf,
    /// Action → output shape (`s_ftoc.txt`).
    pub s_ftoc: PathBuf,
    /// The engine's settings (`engine.txt`, [`crate::engine`]); may be absent.
    pub engine: PathBuf,
}

impl BrianFiles {
    /// The standard names inside `dir`.
    pub fn in_dir(dir: impl AsRef<Path>) -> Self {
        let d = dir.as_ref();
        Self {
            shape_ctof: d.join("shape_ctof.txt"),
            ctof: d.join("ctof.txt"),
            predicates: d.join("Predicate.ini"),
            predicate_actions: d.join("PredicateActions.ini"),
            cando: d.join("Cando.ini"),
            want: d.join("want.txt"),
            behaviors: d.join("behavior.txt"),
            s_shape: d.join("s_shape.txt"),
            s_ftoc: d.join("s_ftoc.txt"),
            engine: d.join("engine.txt"),
        }
    }
}

/// Reads a file as UTF-8 text; invalid UTF-8 is an error at the line and column of the first
/// invalid byte.
fn read(path: &Path) -> Result<String, BrianError> {
    let bytes = mrt_core::read_bounded(path, mrt_core::MAX_SCRIPT_BYTES)
        .map_err(|source| BrianError::Io { file: path.to_path_buf(), source })?;
    crate::lexer::utf8(without_bom(bytes), path)
}

/// `bytes` without the byte-order mark some editors write at the start of a UTF-8 file.
fn without_bom(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.starts_with(b"\xef\xbb\xbf") {
        bytes.drain(..3);
    }
    bytes
}

/// Where a configuration's files come from: the disk, or memory ([`BrianSources`]).
pub(super) trait Source {
    /// The text of a file (UTF-8 checked, errors located).
    fn read(&self, path: &Path) -> Result<String, BrianError>;
    /// Whether an optional file is there.
    fn exists(&self, path: &Path) -> bool;
    /// The root every rule file must lie in (the disk's: `base` canonicalized).
    fn root(&self, base: &Path) -> Result<PathBuf, BrianError>;
    /// The checked file a `behavior.txt` line names (see [`rule_file`]).
    fn rule_file(
        &self,
        root: &Path,
        base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError>;
}

/// The files of a directory on disk.
pub(super) struct Disk;

impl Source for Disk {
    fn read(&self, path: &Path) -> Result<String, BrianError> {
        read(path)
    }

    fn exists(&self, path: &Path) -> bool {
        path.exists()
    }

    fn root(&self, base: &Path) -> Result<PathBuf, BrianError> {
        base.canonicalize().map_err(|source| BrianError::Io { file: base.to_path_buf(), source })
    }

    fn rule_file(
        &self,
        root: &Path,
        base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError> {
        rule_file(root, base, list, b)
    }
}

/// A configuration held in memory: each file's bytes under its name in the configuration
/// directory (`shape_ctof.txt`, `ctof.txt`, `Predicate.ini`, `PredicateActions.ini` (optional),
/// `Cando.ini`, `want.txt`, `behavior.txt`, `s_shape.txt`, `s_ftoc.txt`) and each rule file
/// under the path `behavior.txt` gives it (`behaviors/GoToBall.rul`). For tools, tests and
/// fuzzers that have no directory; [`Brian::from_sources`](super::Brian::from_sources) loads
/// it exactly as [`Brian::from_dir`](super::Brian::from_dir) loads a directory holding the same
/// files.
///
/// ```
/// use mrt_fuzzy::brian::{Brian, BrianSources};
///
/// let mut files = BrianSources::new();
/// files.insert("shape_ctof.txt", "(Distance (TOL (NEAR 10 50)) (TOR (FAR 10 50)))");
/// files.insert("ctof.txt", "(TargetDistance Distance)");
/// files.insert("Predicate.ini", "Far = (D TargetDistance FAR);");
/// files.insert("s_shape.txt", "(SPEED (SNG (SLOW 10)) (SNG (FAST 100)))");
/// files.insert("s_ftoc.txt", "(Speed SPEED)");
/// files.insert("behavior.txt", "(level 1 Go behaviors/Go.rul)");
/// files.insert("Cando.ini", "Go = (P Far);");
/// files.insert("want.txt", "Go = (P Far);");
/// files.insert("behaviors/Go.rul", "(Far) => (Speed FAST);");
/// let mut brian = Brian::from_sources(&files)?;
/// let commands = brian.run(&[("TargetDistance", 100.0, 1.0)]);
/// assert_eq!(commands["Speed"], 100.0);
/// # Ok::<(), mrt_fuzzy::BrianError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct BrianSources {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl BrianSources {
    /// No files.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) the file `name`, a path relative to the configuration directory.
    pub fn insert(&mut self, name: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) {
        self.files.insert(name.into(), bytes.into());
    }

    /// Removes the file `name`, returning its bytes.
    pub fn remove(&mut self, name: impl AsRef<Path>) -> Option<Vec<u8>> {
        self.files.remove(name.as_ref())
    }

    /// The file `name`'s bytes.
    pub fn get(&self, name: impl AsRef<Path>) -> Option<&[u8]> {
        self.files.get(name.as_ref()).map(Vec::as_slice)
    }

    /// The files' names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &Path> {
        self.files.keys().map(PathBuf::as_path)
    }

    /// Reads every regular file of a configuration directory and of its subdirectories (at
    /// most [`SOURCES_DEPTH`] deep; links are not followed) into memory.
    pub fn read_dir(dir: impl AsRef<Path>) -> Result<BrianSources, BrianError> {
        let mut out = BrianSources::new();
        out.read_under(dir.as_ref(), Path::new(""), 0)?;
        Ok(out)
    }

    fn read_under(&mut self, dir: &Path, rel: &Path, depth: usize) -> Result<(), BrianError> {
        let io = |file: &Path| {
            let file = file.to_path_buf();
            move |source| BrianError::Io { file, source }
        };
        for entry in std::fs::read_dir(dir).map_err(io(dir))? {
            let entry = entry.map_err(io(dir))?;
            let path = entry.path();
            let kind = entry.file_type().map_err(io(&path))?;
            let name = rel.join(entry.file_name());
            if kind.is_file() {
                let bytes =
                    mrt_core::read_bounded(&path, mrt_core::MAX_SCRIPT_BYTES).map_err(io(&path))?;
                self.files.insert(name, bytes);
            } else if kind.is_dir() && depth < SOURCES_DEPTH {
                self.read_under(&path, &name, depth + 1)?;
            }
        }
        Ok(())
    }
}

/// How deep [`BrianSources::read_dir`] descends into subdirectories.
pub const SOURCES_DEPTH: usize = 8;

impl Source for BrianSources {
    fn read(&self, path: &Path) -> Result<String, BrianError> {
        match self.files.get(path) {
            Some(bytes) => crate::lexer::utf8(bytes.clone(), path),
            None => Err(BrianError::Io {
                file: path.to_path_buf(),
                source: std::io::ErrorKind::NotFound.into(),
            }),
        }
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(path)
    }

    fn root(&self, _base: &Path) -> Result<PathBuf, BrianError> {
        Ok(PathBuf::new())
    }

    /// The path as written, `.` and `..` taken lexically; leaving the configuration (`..` past
    /// its top, an absolute path) is an error, as on disk.
    fn rule_file(
        &self,
        _root: &Path,
        _base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError> {
        use std::path::Component;
        let mut name = PathBuf::new();
        let mut inside = true;
        for part in Path::new(&b.path).components() {
            match part {
                Component::Normal(p) => name.push(p),
                Component::CurDir => {}
                Component::ParentDir => inside &= name.pop(),
                Component::RootDir | Component::Prefix(_) => inside = false,
            }
        }
        if !inside {
            return Err(BrianError::at(
                list,
                b.path_span,
                format!(
                    "the rule file `{}` of behavior `{}` is outside the configuration directory: \
                     rule files must be inside it",
                    b.path, b.name
                ),
            ));
        }
        if !self.files.contains_key(&name) {
            return Err(BrianError::at(
                list,
                b.path_span,
                format!(
                    "cannot open the rule file `{}` of behavior `{}`: {}",
                    b.path,
                    b.name,
                    std::io::Error::from(std::io::ErrorKind::NotFound)
                ),
            ));
        }
        Ok(name)
    }
}

/// The rule file a `behavior.txt` line names, canonicalized, when it lies inside the
/// configuration directory `root` (canonical). Outside, or unreadable, it is an error at the
/// path in `behavior.txt` that never shows the file's content (otherwise any file of
/// the machine could be named, and its first token printed).
fn rule_file(root: &Path, base: &Path, list: &Path, b: &Listed) -> Result<PathBuf, BrianError> {
    let canon = base.join(&b.path).canonicalize().map_err(|e| {
        BrianError::at(
            list,
            b.path_span,
            format!("cannot open the rule file `{}` of behavior `{}`: {e}", b.path, b.name),
        )
    })?;
    if !canon.starts_with(root) {
        return Err(BrianError::at(
            list,
            b.path_span,
            format!(
                "the rule file `{}` of behavior `{}` is outside the configuration directory {}: \
                 rule files must be inside it",
                b.path,
                b.name,
                root.display()
            ),
        ));
    }
    Ok(canon)
}
