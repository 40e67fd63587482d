//! `mrt soak`: the soak campaigns of `docs/reliability.md`.
//!
//! - `mrt soak matches --count 1000`: matches on random valid configurations, stacks and
//!   wirings (`mrt_sim::soak::SoakMatch`), several at a time; every crash is listed with the
//!   command that plays it again.
//! - `mrt soak hour`: one Chaos robot alone on the field for a simulated hour, on the bus, with
//!   this process's resident memory sampled every simulated minute.

use anyhow::{anyhow, bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mrt_robot::spec::Stack;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::SimConfig;
use mrt_sim::soak::{resident_bytes, slope, SoakMatch};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// The campaigns.
#[derive(clap::Subcommand)]
pub enum SoakCommand {
    /// Matches on random valid configurations; 0 crashes expected.
    Matches {
        /// How many matches.
        #[arg(long, default_value_t = 1000)]
        count: u64,
        /// The first match's seed (match k has seed + k).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The longest half, simulated seconds.
        #[arg(long, default_value_t = 20.0)]
        half: f64,
        /// Matches played at a time (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
    },
    /// One robot for a simulated hour, its memory sampled each simulated minute.
    Hour {
        /// Simulated minutes.
        #[arg(long, default_value_t = 60)]
        minutes: u32,
        /// The robot's stack.
        #[arg(long, default_value = "chaos")]
        stack: String,
    },
}

/// Runs a campaign.
pub fn run(command: &SoakCommand) -> Result<()> {
    match command {
        SoakCommand::Matches { count, seed, half, jobs } => matches(*count, *seed, *half, *jobs),
        SoakCommand::Hour { minutes, stack } => hour(*minutes, stack),
    }
}

fn bar(len: u64, template: &str) -> Result<ProgressBar> {
    Ok(ProgressBar::new(len).with_style(
        ProgressStyle::with_template(template).map_err(|e| anyhow!("{e}"))?.progress_chars("=> "),
    ))
}

fn matches(count: u64, seed: u64, half: f64, jobs: Option<usize>) -> Result<()> {
    if !(1..=1_000_000).contains(&count) {
        bail!("--count must be 1 to 1000000, not {count}");
    }
    if seed.checked_add(count - 1).is_none() {
        bail!("--seed {seed} with --count {count} runs past the largest seed");
    }
    if !(half.is_finite() && (1.0..=3600.0).contains(&half)) {
        bail!("--half must be 1 to 3600 s, not {half}");
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    let jobs = jobs.unwrap_or(cores).clamp(1, 64).min(usize::try_from(count).unwrap_or(1));
    let progress = bar(count, "{spinner} soak {pos}/{len} [{bar:40}] ({elapsed}, eta {eta})")?;
    let next = AtomicU64::new(0);
    let crashes = Mutex::new(Vec::new());
    let totals = Mutex::new((0.0_f64, 0_usize, 0_u64)); // simulated s, robot faults, robots
    let started = Instant::now();
    // A panic is caught per match and reported; keep the default hook from printing each.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= count {
                    break;
                }
                let m = SoakMatch::draw(seed + k, half);
                match m.play() {
                    Ok(r) => {
                        if let Ok(mut t) = totals.lock() {
                            t.0 += r.duration;
                            t.1 += r.faults.len();
                            t.2 += 2 * m.cfg.rules.team_size as u64;
                        }
                    }
                    Err(e) => {
                        if let Ok(mut c) = crashes.lock() {
                            c.push((m.seed, e));
                        }
                    }
                }
                progress.inc(1);
            });
        }
    });
    std::panic::set_hook(hook);
    progress.finish_and_clear();
    let crashes = crashes.into_inner().map_err(|_| anyhow!("a soak thread failed"))?;
    let (simulated, faults, robots) =
        totals.into_inner().map_err(|_| anyhow!("a soak thread failed"))?;
    outln!(
        "{count} matches (seeds {seed}..={}), random valid configurations, stacks and wirings, \
         {jobs} at a time: {} crashes",
        seed + count - 1,
        crashes.len()
    );
    outln!(
        "  {simulated:.0} s simulated with {robots} robots in {:.1} s; {faults} robots reported \
         faulty by their matches (software faults, not crashes)",
        started.elapsed().as_secs_f64()
    );
    for (s, e) in &crashes {
        outln!("  crash, seed {s}: {e}\n    again: mrt soak matches --count 1 --seed {s} --half {half}");
    }
    if !crashes.is_empty() {
        bail!("{} of {count} matches crashed", crashes.len());
    }
    Ok(())
}

fn hour(minutes: u32, stack: &str) -> Result<()> {
    if !(1..=24 * 60).contains(&minutes) {
        bail!("--minutes must be 1 to 1440, not {minutes}");
    }
    let stack = Stack::parse(stack).map_err(|e| anyhow!("--stack: {e}"))?;
    let mut cfg = SimConfig::default();
    cfg.rules.team_size = 1;
    cfg.rules.half_duration = f64::from(minutes) * 30.0;
    cfg.validate().map_err(|e| anyhow!("{e}"))?;
    let m = BusMatch::new(&cfg, 1, stack, None, None).map_err(|e| anyhow!("{e}"))?;
    let progress =
        bar(u64::from(minutes), "{spinner} simulated minute {pos}/{len} [{bar:40}] ({elapsed})")?;
    let mut samples: Vec<(f64, f64)> = Vec::new();
    let mut next_minute = 0.0;
    let started = Instant::now();
    let report = m
        .play(|t| {
            if t >= next_minute {
                if let Some(b) = resident_bytes() {
                    samples.push((t / 60.0, b as f64));
                }
                next_minute += 60.0;
                progress.set_position((t / 60.0) as u64);
            }
        })
        .map_err(|e| anyhow!("{e}"))?;
    progress.finish_and_clear();
    let wall = started.elapsed().as_secs_f64();
    outln!(
        "one {} robot alone, {:.0} simulated minutes in {wall:.1} s; {} faults",
        stack.name(),
        report.duration / 60.0,
        report.faults.len()
    );
    if samples.is_empty() {
        outln!("  (this system does not tell a process's memory: not measured)");
        return Ok(());
    }
    let mib = |b: f64| b / f64::from(1 << 20);
    for (minute, bytes) in samples.iter().step_by(5) {
        outln!("  minute {minute:>5.1}: {:>7.1} MiB resident", mib(*bytes));
    }
    // Growth after warm-up: the second half of the run.
    let late: Vec<(f64, f64)> = samples[samples.len() / 2..].to_vec();
    let per_minute = slope(&late);
    let (first, last) = (samples[0].1, samples[samples.len() - 1].1);
    outln!(
        "  first {:.1} MiB, last {:.1} MiB; second half: {:+.1} KiB per simulated minute",
        mib(first),
        mib(last),
        per_minute / 1024.0
    );
    Ok(())
}
