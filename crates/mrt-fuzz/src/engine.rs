//! The fuzzing loop: inputs from the seed, executions under `catch_unwind`, panics counted by
//! site and saved.
//!
//! Input `k` of a run depends only on the run's seed, the target's name and `k` (each
//! execution has its own ChaCha stream), so any input of a run can be made again without the
//! ones before it ([`Fuzzer::input`], `mrt-fuzz input`). Executions run on a worker thread of
//! their own with an 8 MiB stack, as the main thread of a program has, whoever calls.

use crate::mutate::Mutator;
use crate::targets::{Harness, Seed, Target};
use crate::FuzzError;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::cell::RefCell;
use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::Once;
use std::time::{Duration, Instant};

/// The stack of the thread executions run on.
pub const STACK_SIZE: usize = 8 << 20;

/// An execution that allocates more than this at once (bytes) is an unbounded allocation: it
/// is counted and saved like a panic.
pub const DEFAULT_ALLOC_LIMIT: u64 = 256 << 20;

/// How a run goes.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Executions.
    pub execs: u64,
    /// The first execution's index (to make a part of a longer run again).
    pub start: u64,
    /// The seed every input derives from.
    pub seed: u64,
    /// Where panicking inputs are saved (`<dir>/<target>/...`); `None`: not saved.
    pub crash_dir: Option<PathBuf>,
    /// The repository whose shipped files are the seed corpus.
    pub root: PathBuf,
    /// Largest input, bytes.
    pub max_len: usize,
    /// Peak bytes one execution may hold before it counts as an unbounded allocation.
    pub alloc_limit: u64,
    /// Draw a progress bar.
    pub progress: bool,
}

impl RunOptions {
    /// `execs` executions from seed `seed` on the shipped files of `root`, crashes not saved,
    /// no progress bar.
    pub fn new(root: impl Into<PathBuf>, execs: u64, seed: u64) -> RunOptions {
        RunOptions {
            execs,
            start: 0,
            seed,
            crash_dir: None,
            root: root.into(),
            max_len: 64 << 10,
            alloc_limit: DEFAULT_ALLOC_LIMIT,
            progress: false,
        }
    }
}

/// A panic (or an unbounded allocation) at one site.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Site {
    /// How many executions ended there.
    pub count: u64,
    /// The message of the first.
    pub message: String,
    /// The first execution that ended there.
    pub first_exec: u64,
    /// Whether the first input panics again when run alone in a fresh harness (a target that
    /// keeps state between executions may depend on the ones before).
    pub reproduces_alone: bool,
}

/// An execution longer than this counts as a hang (no input of a parser should take it).
pub const HANG: Duration = Duration::from_secs(1);

/// What a run found.
#[derive(Clone, Debug)]
pub struct Report {
    /// The target.
    pub target: String,
    /// Executions done.
    pub execs: u64,
    /// Executions whose input the parser accepted (the harness went on to use it).
    pub accepted: u64,
    /// Executions that panicked.
    pub panics: u64,
    /// Executions that held more than the allocation limit.
    pub big_allocations: u64,
    /// Distinct sites (`file:line:column`, or `allocation` for unbounded allocations).
    pub sites: BTreeMap<String, Site>,
    /// Inputs saved.
    pub saved: Vec<PathBuf>,
    /// Seeds of the corpus.
    pub seeds: usize,
    /// Wall-clock time of the run.
    pub duration: Duration,
    /// The slowest execution and its index.
    pub slowest: (Duration, u64),
    /// Executions that took longer than [`HANG`] (their inputs are saved like failures').
    pub hangs: u64,
    /// The largest peak allocation of one execution, bytes.
    pub peak_bytes: u64,
}

impl Report {
    /// Executions per second.
    pub fn rate(&self) -> f64 {
        self.execs as f64 / self.duration.as_secs_f64().max(1e-9)
    }

    /// No panic, no unbounded allocation.
    pub fn clean(&self) -> bool {
        self.panics == 0 && self.big_allocations == 0
    }
}

thread_local! {
    /// Set on the worker thread: panics there are recorded, not printed.
    static CAPTURE: RefCell<Option<Option<(String, String)>>> = const { RefCell::new(None) };
}

/// Installs (once per process) a panic hook that records the site and message of panics on
/// fuzzing threads and leaves every other thread's panics to the previous hook.
fn install_hook() {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let captured = CAPTURE.with(|c| {
                let mut c = c.borrow_mut();
                let slot = c.as_mut()?;
                let site = info.location().map_or_else(
                    || "unknown".to_string(),
                    |l| format!("{}:{}:{}", l.file(), l.line(), l.column()),
                );
                let payload = info.payload();
                let message = payload
                    .downcast_ref::<&str>()
                    .map(|s| (*s).to_string())
                    .or_else(|| payload.downcast_ref::<String>().cloned())
                    .unwrap_or_default();
                slot.get_or_insert((site, message));
                Some(())
            });
            if captured.is_none() {
                previous(info);
            }
        }));
    });
}

/// One target's seeds, mutator and stream of inputs.
pub struct Fuzzer {
    target: &'static Target,
    seeds: Vec<Seed>,
    mutator: Mutator,
    seed: u64,
}

impl Fuzzer {
    /// Reads the target's seed corpus under `root`.
    pub fn new(
        target: &'static Target,
        root: &Path,
        seed: u64,
        max_len: usize,
    ) -> Result<Fuzzer, FuzzError> {
        let seeds = (target.seeds)(root)?;
        if seeds.is_empty() {
            return Err(FuzzError::NoSeeds { target: target.name.to_string() });
        }
        let mutator =
            Mutator::new(seeds.iter().map(|s| s.bytes.as_slice()), target.keywords, max_len);
        Ok(Fuzzer { target, seeds, mutator, seed })
    }

    /// The corpus.
    pub fn seeds(&self) -> &[Seed] {
        &self.seeds
    }

    /// Input `k`: the seed it mutates (index) and its bytes. One input in 64 is a seed as is;
    /// half of the others come from the target's own structured mutation, if it has one.
    pub fn input(&self, k: u64) -> (usize, Vec<u8>) {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed ^ fnv(self.target.name.as_bytes()));
        rng.set_stream(k);
        let i = rng.random_range(0..self.seeds.len());
        let seed = &self.seeds[i].bytes;
        if rng.random_range(0..64) == 0 {
            return (i, seed.clone());
        }
        if let Some(structured) = self.target.structured {
            if rng.random_bool(0.5) {
                if let Some(mutant) = structured(&mut rng, seed) {
                    return (i, mutant);
                }
            }
        }
        let other = &self.seeds[rng.random_range(0..self.seeds.len())].bytes;
        (i, self.mutator.mutate(&mut rng, seed, other))
    }
}

/// FNV-1a, to give each target its own streams.
fn fnv(bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(*b)).wrapping_mul(0x100_0000_01b3))
}

/// What one execution did.
enum Outcome {
    Fine { peak: u64, accepted: bool },
    Panicked { site: String, message: String },
    BigAllocation { peak: u64 },
}

fn execute(harness: &mut dyn Harness, seed: &Seed, input: &[u8], alloc_limit: u64) -> Outcome {
    CAPTURE.with(|c| *c.borrow_mut() = Some(None));
    let mut result = Ok(false);
    let info = allocation_counter::measure(|| {
        result = catch_unwind(AssertUnwindSafe(|| harness.exec(seed, input)));
    });
    let captured = CAPTURE.with(|c| c.borrow_mut().take()).flatten();
    match result {
        Err(_) => {
            let (site, message) =
                captured.unwrap_or_else(|| ("unknown".to_string(), String::new()));
            Outcome::Panicked { site, message }
        }
        Ok(_) if info.bytes_max > alloc_limit => Outcome::BigAllocation { peak: info.bytes_max },
        Ok(accepted) => Outcome::Fine { peak: info.bytes_max, accepted },
    }
}

/// Runs `target` as `opts` say, on a worker thread; returns what it found.
pub fn run(target: &'static Target, opts: &RunOptions) -> Result<Report, FuzzError> {
    let opts = opts.clone();
    std::thread::Builder::new()
        .name(format!("mrt-fuzz:{}", target.name))
        .stack_size(STACK_SIZE)
        .spawn(move || run_here(target, &opts))
        .map_err(|source| FuzzError::Io { path: PathBuf::from("<thread>"), source })?
        .join()
        .map_err(|_| FuzzError::Harness {
            target: target.name.to_string(),
            message: "the fuzzing thread panicked outside an execution".to_string(),
        })?
}

fn run_here(target: &'static Target, opts: &RunOptions) -> Result<Report, FuzzError> {
    install_hook();
    let fuzzer = Fuzzer::new(target, &opts.root, opts.seed, opts.max_len)?;
    let mut harness = (target.harness)(&opts.root)?;
    let bar = progress_bar(target.name, opts);
    let mut report = Report {
        target: target.name.to_string(),
        execs: 0,
        accepted: 0,
        panics: 0,
        big_allocations: 0,
        sites: BTreeMap::new(),
        saved: Vec::new(),
        seeds: fuzzer.seeds.len(),
        duration: Duration::ZERO,
        slowest: (Duration::ZERO, 0),
        hangs: 0,
        peak_bytes: 0,
    };
    let started = Instant::now();
    for k in opts.start..opts.start.saturating_add(opts.execs) {
        let (i, input) = fuzzer.input(k);
        let seed = &fuzzer.seeds[i];
        let t0 = Instant::now();
        let outcome = execute(harness.as_mut(), seed, &input, opts.alloc_limit);
        let took = t0.elapsed();
        if took > report.slowest.0 {
            report.slowest = (took, k);
        }
        if took > HANG {
            report.hangs += 1;
            if let Some(dir) = &opts.crash_dir {
                report.saved.push(save(dir, target, seed, k, opts.seed, &input)?);
            }
        }
        report.execs += 1;
        let (site, message) = match outcome {
            Outcome::Fine { peak, accepted } => {
                report.peak_bytes = report.peak_bytes.max(peak);
                report.accepted += u64::from(accepted);
                if report.execs % 1024 == 0 {
                    if let Some(b) = &bar {
                        b.set_position(report.execs);
                    }
                }
                continue;
            }
            Outcome::Panicked { site, message } => {
                report.panics += 1;
                (site, message)
            }
            Outcome::BigAllocation { peak } => {
                report.big_allocations += 1;
                report.peak_bytes = report.peak_bytes.max(peak);
                ("allocation".to_string(), format!("{peak} bytes held at once"))
            }
        };
        if let Some(dir) = &opts.crash_dir {
            report.saved.push(save(dir, target, seed, k, opts.seed, &input)?);
        }
        if let Some(b) = &bar {
            b.set_message(format!("{} panics at {} sites", report.panics, report.sites.len() + 1));
        }
        if let Some(s) = report.sites.get_mut(&site) {
            s.count += 1;
            continue;
        }
        // A new site: does the input fail alone, in a fresh harness?
        let mut fresh = (target.harness)(&opts.root)?;
        let again = execute(fresh.as_mut(), seed, &input, opts.alloc_limit);
        let reproduces_alone = !matches!(again, Outcome::Fine { .. });
        report.sites.insert(site, Site { count: 1, message, first_exec: k, reproduces_alone });
    }
    report.duration = started.elapsed();
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    Ok(report)
}

fn progress_bar(name: &str, opts: &RunOptions) -> Option<indicatif::ProgressBar> {
    if !opts.progress {
        return None;
    }
    let bar = indicatif::ProgressBar::new(opts.execs);
    let style = indicatif::ProgressStyle::with_template(
        "{prefix:>14} {bar:30} {pos}/{len} execs {per_sec} eta {eta} {msg}",
    )
    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_prefix(name.to_string());
    Some(bar)
}

/// Saves a failing input as `<dir>/<target>/<slot>-s<seed>-e<exec>.bin` (the slot's `/`
/// written `__`), the name `mrt-fuzz repro` reads back.
fn save(
    dir: &Path,
    target: &Target,
    seed: &Seed,
    k: u64,
    run_seed: u64,
    input: &[u8],
) -> Result<PathBuf, FuzzError> {
    let dir = dir.join(target.name);
    std::fs::create_dir_all(&dir).map_err(|source| FuzzError::Io { path: dir.clone(), source })?;
    let slot = seed.slot.replace(['/', '\\'], "__");
    let path = dir.join(format!("{slot}-s{run_seed}-e{k}.bin"));
    std::fs::write(&path, input).map_err(|source| FuzzError::Io { path: path.clone(), source })?;
    Ok(path)
}

/// The slot a saved input's file name names (see [`run`]'s saving).
pub fn slot_of_saved(path: &Path) -> Option<String> {
    let name = path.file_name()?.to_str()?;
    let stem = name.strip_suffix(".bin")?;
    let cut = stem.rfind("-s")?;
    Some(stem[..cut].replace("__", "/"))
}

/// Runs one input against the seed of slot `slot` in a fresh harness, on a worker thread:
/// `Ok(None)` when it runs cleanly, `Ok(Some((site, message)))` when it panics.
pub fn reproduce(
    target: &'static Target,
    root: &Path,
    slot: &str,
    input: Vec<u8>,
) -> Result<Option<(String, String)>, FuzzError> {
    let (root, slot) = (root.to_path_buf(), slot.to_string());
    std::thread::Builder::new()
        .stack_size(STACK_SIZE)
        .spawn(move || {
            install_hook();
            let seeds = (target.seeds)(&root)?;
            let seed = seeds.iter().find(|s| s.slot == slot).ok_or_else(|| FuzzError::Slot {
                target: target.name.to_string(),
                slot: slot.clone(),
            })?;
            let mut harness = (target.harness)(&root)?;
            Ok(match execute(harness.as_mut(), seed, &input, DEFAULT_ALLOC_LIMIT) {
                Outcome::Fine { .. } => None,
                Outcome::Panicked { site, message } => Some((site, message)),
                Outcome::BigAllocation { peak } => {
                    Some(("allocation".to_string(), format!("{peak} bytes held at once")))
                }
            })
        })
        .map_err(|source| FuzzError::Io { path: PathBuf::from("<thread>"), source })?
        .join()
        .map_err(|_| FuzzError::Harness {
            target: target.name.to_string(),
            message: "the thread panicked outside the execution".to_string(),
        })?
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saved_names_give_the_slot_back() {
        let p = Path::new("/tmp/x/brian/harvester__behaviors__GoToHome.rul-s7-e12.bin");
        assert_eq!(slot_of_saved(p).as_deref(), Some("harvester/behaviors/GoToHome.rul"));
    }
}
