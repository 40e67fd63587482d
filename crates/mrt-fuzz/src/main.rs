//! `mrt-fuzz`: fuzz MRT's parsers from the shipped files. `mrt-fuzz list` names the targets;
//! `mrt-fuzz run TARGET|all --execs N --seed S` runs them and exits with status 1 if any input
//! panicked or allocated without bound (saved under `--crashes`).
// A command-line tool: its output is its job.
#![allow(clippy::print_stdout)]

use clap::{Parser, Subcommand};
use mrt_core::frames::millis;
use mrt_fuzz::engine::{self, Report, RunOptions};
use mrt_fuzz::targets::{self, Target, TARGETS};
use mrt_fuzz::FuzzError;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mrt-fuzz",
    about = "Fuzz MRT's parsers on stable Rust, the shipped files as seeds"
)]
struct Cli {
    /// The repository whose shipped files are the seed corpus.
    #[arg(long, global = true, default_value_os_t = targets::default_root())]
    root: PathBuf,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Lists the targets and their seed counts.
    List,
    /// Runs a target, or all of them one after the other.
    Run {
        /// A target name, or `all`.
        target: String,
        /// Executions per target.
        #[arg(long, default_value_t = 100_000)]
        execs: u64,
        /// The seed every input derives from.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The first execution's index (to make part of a longer run again).
        #[arg(long, default_value_t = 0)]
        start: u64,
        /// Where failing inputs are saved, one directory per target.
        #[arg(long, default_value = "fuzz-crashes")]
        crashes: PathBuf,
        /// Largest input, bytes.
        #[arg(long, default_value_t = 64 << 10)]
        max_len: usize,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Runs one saved input again, alone, against the seed its file name names.
    Repro {
        /// The target.
        target: String,
        /// A file saved by `run` (`<slot>-s<seed>-e<exec>.bin`).
        file: PathBuf,
        /// The slot, if the file name does not say.
        #[arg(long)]
        slot: Option<String>,
    },
    /// Writes input K of a run (seed S) to a file, with the slot it mutates.
    Input {
        /// The target.
        target: String,
        /// The execution's index.
        k: u64,
        /// The run's seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Largest input, bytes (as the run's).
        #[arg(long, default_value_t = 64 << 10)]
        max_len: usize,
        /// Where to write it.
        #[arg(long)]
        out: PathBuf,
    },
}

fn target(name: &str) -> Result<&'static Target, FuzzError> {
    targets::find(name).ok_or_else(|| FuzzError::UnknownTarget(name.to_string()))
}

fn print_report(r: &Report) {
    let secs = r.duration.as_secs_f64();
    println!(
        "{:<12} {:>9} execs {:>8.1} s {:>9.0}/s  seeds {:>3}  accepted {:>4.1}%  panics {}  sites {}  big allocations {}  over 1 s {}  slowest {:.1} ms (exec {})  peak {:.1} MiB",
        r.target,
        r.execs,
        secs,
        r.rate(),
        r.seeds,
        100.0 * r.accepted as f64 / r.execs.max(1) as f64,
        r.panics,
        r.sites.len(),
        r.big_allocations,
        r.hangs,
        millis(r.slowest.0.as_secs_f64()),
        r.slowest.1,
        r.peak_bytes as f64 / f64::from(1 << 20),
    );
    for (site, s) in &r.sites {
        let alone =
            if s.reproduces_alone { "reproduces alone" } else { "needs the executions before" };
        println!("    {} × {site}: {} (first: exec {}, {alone})", s.count, s.message, s.first_exec);
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::from(1),
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<bool, FuzzError> {
    match cli.command {
        Command::List => {
            for t in TARGETS {
                let seeds = (t.seeds)(&cli.root).map(|s| s.len()).unwrap_or(0);
                println!("{:<12} {seeds:>3} seeds  {}", t.name, t.about);
            }
            Ok(true)
        }
        Command::Run { target: name, execs, seed, start, crashes, max_len, quiet } => {
            let chosen: Vec<&'static Target> =
                if name == "all" { TARGETS.iter().collect() } else { vec![target(&name)?] };
            let mut clean = true;
            let mut total = std::time::Duration::ZERO;
            println!("mrt-fuzz run {name} --execs {execs} --seed {seed} (start {start})");
            for t in chosen {
                let opts = RunOptions {
                    start,
                    crash_dir: Some(crashes.clone()),
                    max_len,
                    progress: !quiet,
                    ..RunOptions::new(cli.root.clone(), execs, seed)
                };
                let report = engine::run(t, &opts)?;
                total += report.duration;
                print_report(&report);
                let _ = std::io::stdout().flush();
                clean &= report.clean();
            }
            println!(
                "total {:.1} s; {}",
                total.as_secs_f64(),
                if clean { "no panics" } else { "FAILURES (inputs saved)" }
            );
            Ok(clean)
        }
        Command::Repro { target: name, file, slot } => {
            let t = target(&name)?;
            let slot =
                slot.or_else(|| engine::slot_of_saved(&file)).ok_or_else(|| FuzzError::Slot {
                    target: name.clone(),
                    slot: format!("(none in the name {})", file.display()),
                })?;
            let input = std::fs::read(&file)
                .map_err(|source| FuzzError::Io { path: file.clone(), source })?;
            match engine::reproduce(t, &cli.root, &slot, input)? {
                None => {
                    println!("{name} {slot}: runs cleanly");
                    Ok(true)
                }
                Some((site, message)) => {
                    println!("{name} {slot}: panics at {site}: {message}");
                    Ok(false)
                }
            }
        }
        Command::Input { target: name, k, seed, max_len, out } => {
            let t = target(&name)?;
            let fuzzer = engine::Fuzzer::new(t, &cli.root, seed, max_len)?;
            let (i, bytes) = fuzzer.input(k);
            std::fs::write(&out, &bytes)
                .map_err(|source| FuzzError::Io { path: out.clone(), source })?;
            println!(
                "{name} input {k} (seed {seed}): {} bytes, a mutant of {}",
                bytes.len(),
                fuzzer.seeds()[i].slot
            );
            Ok(true)
        }
    }
}
