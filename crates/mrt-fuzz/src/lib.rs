//! # mrt-fuzz: a fuzz harness on stable Rust for every MRT parser
//!
//! Fuzzing beyond proptest. Every file format MRT reads from outside has a
//! [`targets::Target`] here: DCDT Agora configuration files, DCDT wire frames, the
//! self-describing XML message, Mr. BRIAN configuration files (each file kind), the
//! simulator's TOML, the blackboard's `config.dat`, the relay's request lines, Lua behavior
//! scripts, HBM behaviors, HFSM files, and the world snapshots `mrt behave` reads. The seed
//! corpus is the files MRT ships (`configs/`, `behaviors/teamchaos/`, the relay protocol's
//! examples) plus a frame of every standard message. Inputs are the seeds after a few
//! structure-aware mutations ([`mutate::Mutator`]: numbers replaced by extremes, words from the
//! format's dictionary, lines repeated, deep nesting, invalid UTF-8, splices, bit flips...).
//!
//! Each execution runs under `catch_unwind` ([`engine::run`]): executions, panics, distinct
//! panic sites and executions that allocate without bound are counted, every failing input is
//! saved, and input `k` of a run depends only on the seed, so a run is the same every time
//! and any of its inputs can be made again alone. Without libFuzzer there is no coverage
//! feedback: the mutations are what finds the corners. A harness also checks what the parser
//! documents (a canonical form reads back, a decoded frame re-encodes to the same bytes), and
//! a broken promise is a panic like any other.
//!
//! ```
//! use mrt_fuzz::engine::{run, RunOptions};
//! use mrt_fuzz::targets::{default_root, find};
//!
//! let target = find("dcdt-config").expect("a target of that name");
//! let report = run(target, &RunOptions::new(default_root(), 200, 7))?;
//! assert_eq!(report.execs, 200);
//! assert!(report.clean(), "{:?}", report.sites);
//! # Ok::<(), mrt_fuzz::FuzzError>(())
//! ```
//!
//! From the command line: `mrt-fuzz list`, `mrt-fuzz run all --execs 1000000 --seed 1`
//! (release build; crashes go to `fuzz-crashes/<target>/`), `mrt-fuzz repro TARGET FILE`,
//! `mrt-fuzz input TARGET K --seed S --out FILE`. Results and commands: `docs/reliability.md`.
#![deny(missing_docs)]

pub mod engine;
pub mod mutate;
pub mod targets;

use std::path::PathBuf;

/// What can stop a fuzzing run (a panic of a target is not an error: it is counted).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FuzzError {
    /// A file of the corpus or a crash file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A target found no seed.
    #[error("target `{target}` has no seed (is the repository root right?)")]
    NoSeeds {
        /// The target.
        target: String,
    },
    /// No target of that name.
    #[error("no target `{0}` (mrt-fuzz list shows them)")]
    UnknownTarget(String),
    /// No seed of that slot.
    #[error("target `{target}` has no seed `{slot}`")]
    Slot {
        /// The target.
        target: String,
        /// The slot asked for.
        slot: String,
    },
    /// A harness could not be set up.
    #[error("target `{target}`: {message}")]
    Harness {
        /// The target.
        target: String,
        /// What went wrong.
        message: String,
    },
}
