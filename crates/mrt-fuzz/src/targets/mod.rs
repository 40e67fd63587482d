//! The fuzz targets: one per parser of MRT, each with its seed corpus (the shipped files) and
//! a harness that runs an input the way MRT runs the file it stands for.

use crate::FuzzError;
use std::path::{Path, PathBuf};

mod devices;
mod files;
mod lua;
mod recording;
mod wire;

/// One input of the seed corpus.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Seed {
    /// What the input is, for the harness: the file it came from, relative to its corpus
    /// directory (`harvester/ctof.txt`, `go2ball.lua`), or the kind of a built-in seed.
    pub slot: String,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

impl Seed {
    /// A seed.
    pub fn new(slot: impl Into<String>, bytes: impl Into<Vec<u8>>) -> Seed {
        Seed { slot: slot.into(), bytes: bytes.into() }
    }
}

/// Runs inputs. A harness may keep state between executions (a Lua runtime, say) as long as
/// that state cannot hide a bug; it is built on the thread that runs it.
pub trait Harness {
    /// Runs `input`, a mutant of `seed`; `true` when the parser accepted it (and the harness
    /// went on to use what it read). A panic is a bug of the parser (or of the harness's
    /// checks of what the parser documents).
    fn exec(&mut self, seed: &Seed, input: &[u8]) -> bool;
}

/// A format's own mutation: the seed's bytes to a mutant, or `None` (not of the format).
pub type Structured = fn(&mut rand_chacha::ChaCha8Rng, &[u8]) -> Option<Vec<u8>>;

/// A fuzz target.
pub struct Target {
    /// Its name on the command line.
    pub name: &'static str,
    /// What it runs, one line.
    pub about: &'static str,
    /// Words of the format worth inserting (the seeds' own words are added).
    pub keywords: &'static [&'static str],
    /// A mutation of the format's own, used for half of the inputs besides the byte-level
    /// ones: the seed's bytes to a mutant, or `None` to fall back to the byte level.
    pub structured: Option<Structured>,
    /// Reads the seed corpus under the repository root.
    pub seeds: fn(&Path) -> Result<Vec<Seed>, FuzzError>,
    /// Builds a harness (the repository root is where it finds the files it needs besides the
    /// input).
    pub harness: fn(&Path) -> Result<Box<dyn Harness>, FuzzError>,
}

impl std::fmt::Debug for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Target").field("name", &self.name).finish_non_exhaustive()
    }
}

/// Every target, in the order `mrt-fuzz run all` runs them.
pub static TARGETS: &[Target] = &[
    files::DCDT_CONFIG,
    wire::WIRE,
    wire::XML,
    files::BRIAN,
    files::SIM_CONFIG,
    files::ROBOT_FILE,
    files::VISION_FILES,
    files::PLAN_MAP,
    files::MICE_LOG,
    files::BB_CONFIG,
    files::RELAY_LINE,
    lua::LUA_SCRIPT,
    lua::HBM,
    lua::HFSM,
    lua::WORLD,
    recording::MCAP,
    devices::DEVICES,
    devices::ANSWERS,
];

/// The target of that name.
pub fn find(name: &str) -> Option<&'static Target> {
    TARGETS.iter().find(|t| t.name == name)
}

/// The repository this crate was built in (its shipped files are the default corpus).
pub fn default_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every regular file under `dir` (recursively, sorted) whose name `keep` accepts, as seeds
/// named by their path relative to `dir` (with `/`).
pub(crate) fn files_under(dir: &Path, keep: fn(&str) -> bool) -> Result<Vec<Seed>, FuzzError> {
    let mut out = Vec::new();
    walk(dir, dir, keep, &mut out, 0)?;
    out.sort_by(|a, b| a.slot.cmp(&b.slot));
    Ok(out)
}

fn walk(
    top: &Path,
    dir: &Path,
    keep: fn(&str) -> bool,
    out: &mut Vec<Seed>,
    depth: usize,
) -> Result<(), FuzzError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| FuzzError::Io { path, source }
    };
    for entry in std::fs::read_dir(dir).map_err(io(dir))? {
        let entry = entry.map_err(io(dir))?;
        let path = entry.path();
        let kind = entry.file_type().map_err(io(&path))?;
        if kind.is_dir() && depth < 8 {
            walk(top, &path, keep, out, depth + 1)?;
        } else if kind.is_file() {
            let rel = path.strip_prefix(top).unwrap_or(&path);
            let slot = rel.iter().map(|c| c.to_string_lossy()).collect::<Vec<_>>().join("/");
            if keep(&slot) {
                let bytes = std::fs::read(&path).map_err(io(&path))?;
                out.push(Seed::new(slot, bytes));
            }
        }
    }
    Ok(())
}
