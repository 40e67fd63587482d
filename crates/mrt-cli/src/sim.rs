//! `mrt sim`: a simulated match (or a series of them) on the embedded default world.

use anyhow::{anyhow, Context as _, Result};
use indicatif::{ProgressBar, ProgressStyle};
use mrt_monitor::serve::Server;
use mrt_monitor::{RecordProfile, Recorder, SharedRecorder, SharedTimeline, Timeline};
use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::game::{MatchReport, TeamStats};
use mrt_sim::metrics::MetricsBook;
use mrt_sim::play_recorded;
use std::path::PathBuf;

mod report;
pub(crate) use report::team_lines;

/// What `mrt sim` was asked (its command-line options).
#[derive(clap::Args)]
pub struct SimArgs {
    /// Simulator configuration (TOML; see configs/sim/default.toml). Default: built in.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Seed of all randomness: the same seed gives the same match. A series uses seed,
    /// seed + 1, ..., which must not pass 18446744073709551615.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The home team's stack: milan (Mr. BRIAN fuzzy behaviors), chaos (TeamChaos' Lua
    /// state machines and fuzzy behaviors), isocrob (ISocRob's role state machines on a shared
    /// blackboard) or chaser (a hand-written baseline).
    #[arg(long, default_value = "milan")]
    pub home: String,
    /// The away team's stack (same choices).
    #[arg(long, default_value = "chaos")]
    pub away: String,
    /// Play this many matches, 1 to 1 000 000 (seeds seed, seed+1, ...) on all cores and
    /// report win/draw/loss with confidence intervals.
    #[arg(long, default_value_t = 1)]
    pub matches: u64,
    /// Draw the match (field, trajectories, shots) to this SVG file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// With --plot: draw robot N's belief over time instead (where it believed it was over
    /// where it was, the ball as it saw it with the velocity it estimated, the moments it was
    /// carried). Robots are numbered from 0: home's, then away's.
    #[arg(long, value_name = "N", requires = "plot")]
    pub belief: Option<usize>,
    /// With --belief: only the simulated seconds FROM:TO (e.g. 120:180). Default: the whole
    /// match.
    #[arg(long, value_name = "FROM:TO", requires = "belief", value_parser = parse_window)]
    pub window: Option<(f64, f64)>,
    /// Run at wall-clock speed, for watching.
    #[arg(long)]
    pub realtime: bool,
    /// Length of a half in seconds (default from the configuration: 300).
    #[arg(long)]
    pub half: Option<f64>,
    /// Run the TeamChaos behaviors of this directory instead of the built-in ones; for
    /// isocrob, its `config.dat` and `config-<robot>.dat` (where there) override the built-in
    /// `configs/isocrob/config.dat`.
    #[arg(long)]
    pub behaviors: Option<PathBuf>,
    /// Run each robot's Agora in a process of its own, talking to the simulator and its
    /// teammates over zenoh on loopback (the same match as in one process; see
    /// docs/network.md).
    #[arg(long)]
    pub distributed: bool,
    /// With --distributed: kill this robot's process mid-match and start it again at once
    /// (a crash and a supervisor's restart); the report says when it answered again.
    #[arg(long, requires = "distributed")]
    pub restart_robot: Option<usize>,
    /// When to restart it, in simulated seconds from the kickoff (default: half the first
    /// half).
    #[arg(long, requires = "restart_robot")]
    pub restart_at: Option<f64>,
    /// Measure: play `--matches` full matches (3 if not given) one after the other on one
    /// core, headless, and report how many times faster than real time they ran.
    #[arg(long)]
    pub bench: bool,
    /// Where the robots' percepts come from: oracle (the object sensor: fast, for long
    /// series) or vision (every camera renders images, the robots' vision µAgent finds the
    /// ball and the goals in them). Default: the configuration's `[sensor] percepts`.
    #[arg(long, value_enum)]
    pub percepts: Option<PerceptsArg>,
    /// Which estimator keeps each robot's pose: murea (the EKF tracks, MUREA finds the robot
    /// again when it is lost), gm (the EKF tracks, ThinkingCap's fuzzy grid follows and moves
    /// it when sure it is elsewhere) or ekf (the EKF alone). Default: the configuration's
    /// `[localization] localizer`.
    #[arg(long)]
    pub localizer: Option<mrt_robot::config::Localizer>,
    /// Carry each robot this many times per half (0 to 100), at random moments of play, to a
    /// random free spot without telling it (the kidnapped robot); the report says how soon
    /// each found itself again. Default: the configuration's `[rules] kidnaps`.
    #[arg(long)]
    pub kidnap: Option<u32>,
    /// Write what the robots believed against the truth (localization, ball, kidnaps; keys in
    /// docs/localization.md) to this JSON file, over the match or the whole series.
    #[arg(long)]
    pub metrics: Option<PathBuf>,
    /// Record every robot's bus messages and the simulator's truth into this MCAP file (JSON
    /// messages with a JSON schema per type; topics in docs/monitor.md): open it in Foxglove
    /// or Lichtblick, or read it with any `mcap` library. One in-process match.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// With --record: a file a user can mail (the default match in 16.0 MB instead of
    /// 106.5): every topic, but the world snapshots, percepts, mate reports, localization,
    /// sonars and odometry at 2 Hz of the simulated clock and the scene at 5 Hz, and every
    /// float with 4 decimals (0.1 mm in metres). Enough for the web monitor and Foxglove;
    /// `mrt replay --robot` cannot re-run behaviors on it exactly (docs/monitor.md).
    #[arg(long, requires = "record")]
    pub compact: bool,
    /// Serve the web monitor while the match plays and after it ends (until Ctrl-C): open
    /// the printed address in a browser to watch the field, each robot's beliefs against the
    /// truth, and to pause, step and scrub. ADDR defaults to 127.0.0.1:8080 (loopback only);
    /// with --realtime the match plays at wall-clock speed. One in-process match.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8080")]
    pub serve: Option<std::net::SocketAddr>,
    /// With --record or --serve: keep this many camera images a second of each robot (JPEG,
    /// Foxglove's `foxglove.CompressedImage` on `/<robot>/camera`, about 5 KB each), for
    /// Foxglove and the web monitor. Only cameras that render images have them (not
    /// `--percepts oracle`). Default: none.
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub images: u32,
    /// Which embedded world: soccer (a match) or indoor (one robot follows path points
    /// through a building where a door closes and a person walks; the MRT manual's Roby,
    /// docs/indoor.md).
    #[arg(long, value_enum, default_value = "soccer")]
    pub world: WorldKind,
    /// Instead of a match: drive one robot through the two-mice calibration procedure (MRT
    /// manual §4.2: ten straight runs of 500 mm, five turns of 360° in place), its mice
    /// mounted anywhere and as noisy as the configuration says, calibrate them from their
    /// counts and print the estimates beside the simulated mounting (docs/mice.md).
    #[arg(long)]
    pub calibrate_mice: bool,
    /// With --calibrate-mice: write the readings' log (CSV, docs/mice.md) to this file, for
    /// `mrt mice calibrate`.
    #[arg(long, value_name = "FILE", requires = "calibrate_mice")]
    pub mice_log: Option<PathBuf>,
    /// With --calibrate-mice: print JSON (SI units).
    #[arg(long, requires = "calibrate_mice")]
    pub json: bool,
}

/// `--world`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum WorldKind {
    /// The robot-soccer match.
    Soccer,
    /// The building of `configs/worlds/indoor/`.
    Indoor,
}

/// `--percepts` (the command line's name for `mrt_sim::config::PerceptSource`).
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum PerceptsArg {
    /// The object sensor.
    Oracle,
    /// Rendered images through the vision µAgent.
    Vision,
}

fn config(args: &SimArgs) -> Result<SimConfig> {
    let mut cfg = match &args.config {
        Some(p) => SimConfig::from_file(p).map_err(|e| anyhow!("{e}"))?,
        None => SimConfig::default(),
    };
    if let Some(h) = args.half {
        cfg.rules.half_duration = h;
    }
    if let Some(p) = args.percepts {
        cfg.sensor.percepts = match p {
            PerceptsArg::Oracle => mrt_sim::config::PerceptSource::Oracle,
            PerceptsArg::Vision => mrt_sim::config::PerceptSource::Vision,
        };
    }
    if let Some(l) = args.localizer {
        cfg.localization.localizer = l;
    }
    if let Some(k) = args.kidnap {
        cfg.rules.kidnaps = k;
    }
    cfg.validate().map_err(|e| anyhow!("{e}"))?;
    Ok(cfg)
}

fn play_one(
    cfg: &SimConfig,
    seed: u64,
    stacks: (Stack, Stack),
    args: &SimArgs,
    record: bool,
    timeline: Option<&SharedTimeline>,
    progress: impl FnMut(f64),
) -> Result<(MatchReport, Vec<String>)> {
    if args.distributed {
        #[cfg(feature = "net")]
        {
            let restart = match args.restart_robot {
                Some(robot) => {
                    let at = args.restart_at.unwrap_or(cfg.rules.half_duration / 2.0);
                    if !(at.is_finite() && at >= 0.0) {
                        anyhow::bail!("--restart-at must be a time in the match, not {at}");
                    }
                    Some(crate::distributed::Restart { robot, at })
                }
                None => None,
            };
            let behaviors = args.behaviors.as_deref();
            let (report, rejoined) =
                crate::distributed::play(cfg, seed, stacks, behaviors, record, restart, progress)?;
            let notes = rejoined
                .map(|r| match r.after {
                    Some(d) => format!(
                        "robot {} killed at {:.1} s of play and started again: answering {:.2} s \
                         after its restart (goal: 1 s or less; {})",
                        r.robot,
                        r.at,
                        d.as_secs_f64(),
                        r.phases
                    ),
                    None => format!(
                        "robot {} killed at {:.1} s of play and started again: it never answered",
                        r.robot, r.at
                    ),
                })
                .into_iter()
                .collect();
            return Ok((report, notes));
        }
        #[cfg(not(feature = "net"))]
        anyhow::bail!(
            "this mrt was built without networking: build it with the default features \
             (cargo run --release -p mrt-cli -- sim --distributed)"
        );
    }
    let recorder = recorder(args, cfg, timeline)?;
    let behaviors = args.behaviors.as_deref();
    if args.record.is_some() {
        // A recording is finished, with its summary and index, when Ctrl-C ends the match.
        crate::interrupt::finish_on_ctrl_c();
    }
    let mut progress = progress;
    let mut played = 0.0;
    let go_on = |t: f64| {
        progress(t);
        played = t;
        !crate::interrupt::interrupted()
    };
    let report = play_recorded(cfg, seed, stacks, behaviors, record, recorder.clone(), go_on)
        .map_err(|e| anyhow!("{e}"))?;
    let mut notes = Vec::new();
    if crate::interrupt::interrupted() {
        notes.push(format!(
            "interrupted after {played:.1} s of play: the report and the recording cover that much"
        ));
    }
    let finished = recorder.map(Recorder::finish_shared).transpose()?;
    if let Some(t) = timeline {
        t.lock().map_err(|_| anyhow!("the monitor's timeline lock is poisoned"))?.finish();
    }
    if let (Some(s), Some(path)) = (finished, &args.record) {
        let size = std::fs::metadata(path).map(|m| m.len()).unwrap_or(0);
        let failed = if s.failed > 0 { format!(", {} left out", s.failed) } else { String::new() };
        let failed = if s.decimated > 0 {
            format!("{failed}, {} more left out by --compact", s.decimated)
        } else {
            failed
        };
        notes.push(format!(
            "recorded {} messages on {} topics into {} ({:.1} MB{failed})",
            s.messages,
            s.channels,
            path.display(),
            size as f64 / 1e6
        ));
    }
    Ok((report, notes))
}

/// The recorder of `--record` (into its file) and `--serve` (into the monitor's `timeline`),
/// keeping `--images` camera images; `None` when neither was asked for.
fn recorder(
    args: &SimArgs,
    cfg: &SimConfig,
    timeline: Option<&SharedTimeline>,
) -> Result<Option<SharedRecorder>> {
    if args.record.is_none() && timeline.is_none() {
        return Ok(None);
    }
    let mut rec = match &args.record {
        Some(path) => {
            let profile = if args.compact { RecordProfile::Compact } else { RecordProfile::Full };
            Recorder::create_with(path, profile)?
        }
        None => Recorder::unwritten(),
    };
    if args.images > 0 {
        // Every n-th image of a camera that renders one each control cycle.
        let per_second = 1.0 / cfg.robot().map_err(|e| anyhow!("{e}"))?.period().as_secs_f64();
        rec = rec.with_images(((per_second / f64::from(args.images)).round() as u32).max(1));
    }
    if let Some(timeline) = timeline.cloned() {
        rec = rec.listen(Box::new(move |topic, time, json| {
            if let Ok(mut t) = timeline.lock() {
                t.ingest(topic, time, json);
            }
        }));
    }
    Ok(Some(rec.shared()))
}

/// How the robots were wired, for the report.
fn wiring_name(args: &SimArgs) -> &'static str {
    if args.distributed {
        "each robot an Agora in its own process, over zenoh"
    } else {
        "each robot an Agora on the bus"
    }
}

/// `--window FROM:TO`: two times in seconds, `FROM` ≤ `TO`.
fn parse_window(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = s.split_once(':').ok_or("expected FROM:TO in seconds, e.g. 120:180")?;
    let num = |t: &str| {
        t.trim().parse::<f64>().ok().filter(|v| v.is_finite()).ok_or(format!("`{t}` is not a time"))
    };
    let (from, to) = (num(a)?, num(b)?);
    if from > to {
        return Err(format!("{from} comes after {to}"));
    }
    Ok((from, to))
}

/// The most matches of a series or a benchmark.
pub const MAX_MATCHES: u64 = 1_000_000;

/// Checks `--matches` and `--seed`: a series' seeds `seed ..= seed + n − 1` must exist (they
/// wrapped around to 0 before).
fn check_counts(args: &SimArgs) -> Result<()> {
    if !(1..=MAX_MATCHES).contains(&args.matches) {
        anyhow::bail!("--matches must be 1 to {MAX_MATCHES}, not {}", args.matches);
    }
    if args.belief.is_some() && args.matches > 1 {
        anyhow::bail!("--belief draws one match: leave out --matches");
    }
    let n = if args.bench && args.matches == 1 { 3 } else { args.matches };
    if args.seed.checked_add(n - 1).is_none() {
        anyhow::bail!(
            "--seed {} with {n} matches: the last seed would pass {} (use --seed {} or less)",
            args.seed,
            u64::MAX,
            u64::MAX - (n - 1)
        );
    }
    Ok(())
}

/// Runs `mrt sim`.
pub fn run(args: &SimArgs) -> Result<()> {
    check_counts(args)?;
    let cfg = config(args)?;
    if args.calibrate_mice {
        return crate::mice::sim(&cfg, args.seed, args.json, args.mice_log.as_deref());
    }
    if args.world == WorldKind::Indoor {
        return indoor(args, &cfg);
    }
    let stacks = (
        Stack::parse(&args.home).map_err(|e| anyhow!("--home: {e}"))?,
        Stack::parse(&args.away).map_err(|e| anyhow!("--away: {e}"))?,
    );
    let reads_behaviors = |s: Stack| matches!(s, Stack::Chaos | Stack::Isocrob);
    if args.behaviors.is_some() && !reads_behaviors(stacks.0) && !reads_behaviors(stacks.1) {
        anyhow::bail!(
            "--behaviors DIR is read by the chaos and isocrob stacks, and this match has neither \
             (--home {}, --away {}); Milan's Mr. BRIAN files are built into mrt",
            stacks.0.name(),
            stacks.1.name()
        );
    }
    if args.images > 0 && args.record.is_none() && args.serve.is_none() {
        anyhow::bail!("--images keeps camera images in a recording or the monitor: add --record FILE or --serve");
    }
    for (given, name) in [(args.record.is_some(), "--record"), (args.serve.is_some(), "--serve")] {
        if given && (args.matches > 1 || args.distributed || args.bench) {
            anyhow::bail!(
                "{name} takes one in-process match: leave out --matches, --distributed and --bench"
            );
        }
    }
    if args.bench {
        return bench(args, &cfg, stacks);
    }
    if args.matches > 1 {
        if args.distributed {
            anyhow::bail!("--distributed plays one match at a time: use --bench for several");
        }
        return series(args, &cfg, stacks);
    }
    one_match(args, &cfg, stacks)
}

/// One match with a progress bar (and the monitor, with `--serve`), then its report.
fn one_match(args: &SimArgs, cfg: &SimConfig, stacks: (Stack, Stack)) -> Result<()> {
    let robots = 2 * cfg.rules.team_size;
    if let Some(n) = args.belief.filter(|&n| n >= robots) {
        anyhow::bail!("--belief {n}: the match has robots 0 to {}", robots - 1);
    }
    let length = 2.0 * cfg.rules.half_duration;
    let bar = ProgressBar::new(length.ceil() as u64).with_style(
        ProgressStyle::with_template(
            "{spinner} match time {pos}/{len} s [{bar:40}] {msg} ({elapsed})",
        )
        .map_err(|e| anyhow!("{e}"))?
        .progress_chars("=> "),
    );
    let timeline = args.serve.map(|_| Timeline::new().shared());
    let server = match (args.serve, &timeline) {
        (Some(addr), Some(t)) => {
            let title = format!("{} v {}, seed {}", stacks.0.name(), stacks.1.name(), args.seed);
            let server = Server::start(addr, t.clone(), &title)?;
            outln!("monitor: {}", server.url());
            Some(server)
        }
        _ => None,
    };
    let started = std::time::Instant::now();
    let realtime = args.realtime;
    let plot = args.plot.is_some();
    let (report, notes) = play_one(cfg, args.seed, stacks, args, plot, timeline.as_ref(), |t| {
        bar.set_position(t as u64);
        if realtime {
            let ahead = t - started.elapsed().as_secs_f64();
            if ahead > 0.0 {
                std::thread::sleep(std::time::Duration::from_secs_f64(ahead));
            }
        }
    })?;
    bar.finish_and_clear();
    let names = (stacks.0.name(), stacks.1.name());
    report::score(&report, names);
    let mut book = MetricsBook::default();
    book.add(&report);
    report::estimates(&book.metrics());
    write_metrics(args, &book)?;
    report::incidents(&report, cfg.rules.team_size, names);
    let seeing = match cfg.sensor.percepts {
        mrt_sim::config::PerceptSource::Vision => "seeing through its camera images",
        mrt_sim::config::PerceptSource::Oracle => "seeing through the object sensor",
    };
    outln!(
        "  {:.0} s of play simulated in {:.1} s ({}, {seeing}); trajectory hash {:016x}",
        report.duration,
        started.elapsed().as_secs_f64(),
        wiring_name(args),
        report.trajectory_hash
    );
    for note in notes {
        outln!("  {note}");
    }
    if let Some(p) = &args.plot {
        let svg = match args.belief {
            Some(n) => report.belief_svg(cfg, n, args.window.unwrap_or((0.0, f64::INFINITY))),
            None => report.to_svg(cfg, names),
        };
        std::fs::write(p, svg).with_context(|| format!("cannot write {}", p.display()))?;
        outln!("  drawing: {}", p.display());
    }
    if let Some(server) = server {
        outln!("monitor: the match stays at {} to replay; Ctrl-C to stop", server.url());
        crate::wait_for_ctrl_c();
    }
    Ok(())
}

/// `--metrics FILE`: the book as JSON.
fn write_metrics(args: &SimArgs, book: &MetricsBook) -> Result<()> {
    let Some(path) = &args.metrics else { return Ok(()) };
    let json = serde_json::to_string_pretty(&book.metrics())?;
    std::fs::write(path, json + "\n")
        .with_context(|| format!("cannot write {}", path.display()))?;
    outln!("  metrics: {}", path.display());
    Ok(())
}

/// `mrt sim --bench`: full matches one after the other, speed as times real time.
fn bench(args: &SimArgs, cfg: &SimConfig, stacks: (Stack, Stack)) -> Result<()> {
    let n = if args.matches > 1 { args.matches } else { 3 };
    let capacity = usize::try_from(n).unwrap_or(usize::MAX);
    let wiring = wiring_name(args);
    outln!(
        "{n} matches of 2 x {:.0} s, {} v {}, {} ({wiring}), one core:",
        cfg.rules.half_duration,
        cfg.rules.team_size,
        cfg.rules.team_size,
        format_args!("{} vs {}", stacks.0.name(), stacks.1.name()),
    );
    let bar = ProgressBar::new(n);
    let mut speeds = Vec::with_capacity(capacity);
    for k in 0..n {
        // check_counts: no overflow.
        let seed = args.seed.saturating_add(k);
        let started = std::time::Instant::now();
        let (r, _) = play_one(cfg, seed, stacks, args, false, None, |_| {})?;
        let wall = started.elapsed().as_secs_f64();
        speeds.push(r.duration / wall.max(1e-9));
        bar.suspend(|| {
            outln!(
                "  seed {seed}: {:.0} s simulated in {wall:.2} s: {:.0}x real time",
                r.duration,
                r.duration / wall.max(1e-9)
            )
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    speeds.sort_by(f64::total_cmp);
    let median = speeds[speeds.len() / 2];
    outln!(
        "  median {median:.0}x real time (goal: at least 100x): {}",
        if median >= 100.0 { "met" } else { "not met" }
    );
    Ok(())
}

/// Wilson score interval (95 %) of `k` successes in `n` trials, in percent.
fn wilson(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (0.0, 100.0);
    }
    let (n, p, z) = (n as f64, k as f64 / n as f64, 1.96_f64);
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / (1.0 + z * z / n);
    (100.0 * (centre - half).max(0.0), 100.0 * (centre + half).min(1.0))
}

fn series(args: &SimArgs, cfg: &SimConfig, stacks: (Stack, Stack)) -> Result<()> {
    let matches = usize::try_from(args.matches)?;
    let threads = std::thread::available_parallelism().map_or(1, usize::from).min(matches);
    let bar = ProgressBar::new(args.matches).with_style(
        ProgressStyle::with_template(
            "{spinner} matches {pos}/{len} [{bar:40}] ({elapsed}, eta {eta})",
        )
        .map_err(|e| anyhow!("{e}"))?
        .progress_chars("=> "),
    );
    // check_counts: seed + matches − 1 does not overflow.
    let seeds: Vec<u64> = (0..args.matches).map(|k| args.seed.saturating_add(k)).collect();
    let results = std::sync::Mutex::new(Vec::new());
    let book = std::sync::Mutex::new(MetricsBook::default());
    std::thread::scope(|s| {
        for chunk in seeds.chunks(seeds.len().div_ceil(threads)) {
            let (bar, results, book) = (&bar, &results, &book);
            s.spawn(move || {
                for &seed in chunk {
                    let r = play_one(cfg, seed, stacks, args, false, None, |_| {}).map(|(r, _)| r);
                    if let (Ok(r), Ok(mut book)) = (&r, book.lock()) {
                        book.add(r);
                    }
                    if let Ok(mut v) = results.lock() {
                        v.push(r.map(|r| (seed, r.score, r.stats)));
                    }
                    bar.inc(1);
                }
            });
        }
    });
    bar.finish_and_clear();
    let results = results.into_inner().map_err(|_| anyhow!("a match thread failed"))?;
    let mut scores = Vec::new();
    let mut stats = [TeamStats::default(), TeamStats::default()];
    for r in results {
        let (seed, score, s) = r?;
        for (total, one) in stats.iter_mut().zip(&s) {
            total.shots += one.shots;
            total.shots_on_target += one.shots_on_target;
            total.possession_cycles += one.possession_cycles;
        }
        scores.push((seed, score));
    }
    scores.sort();
    let n = scores.len();
    let wins = scores.iter().filter(|(_, (h, a))| h > a).count();
    let draws = scores.iter().filter(|(_, (h, a))| h == a).count();
    let losses = n - wins - draws;
    let (h, a) = (stacks.0.name(), stacks.1.name());
    outln!(
        "{n} matches, {h} (home) against {a} (away), seeds {}..={}",
        args.seed,
        args.seed.saturating_add((n as u64).saturating_sub(1))
    );
    for (label, k) in [("wins", wins), ("draws", draws), ("losses", losses)] {
        let (lo, hi) = wilson(k, n);
        outln!(
            "  {label:<7}{k:>4}  ({:>5.1} %, 95 % CI {lo:.1}–{hi:.1} %)",
            100.0 * k as f64 / n as f64
        );
    }
    let goals: (u32, u32) = scores.iter().fold((0, 0), |acc, (_, (x, y))| (acc.0 + x, acc.1 + y));
    outln!(
        "  goals {} : {} (mean {:.2} : {:.2})",
        goals.0,
        goals.1,
        goals.0 as f64 / n as f64,
        goals.1 as f64 / n as f64
    );
    let possession = (stats[0].possession_cycles + stats[1].possession_cycles).max(1) as f64;
    for (name, s) in [(h, &stats[0]), (a, &stats[1])] {
        outln!(
            "  {name:<8} shots {:>5} ({:>4} on target, {:.1} a match)  possession {:>5.1} %",
            s.shots,
            s.shots_on_target,
            f64::from(s.shots_on_target) / n.max(1) as f64,
            100.0 * s.possession_cycles as f64 / possession
        );
    }
    let book = book.into_inner().map_err(|_| anyhow!("a match thread failed"))?;
    write_metrics(args, &book)
}

/// `mrt sim --world indoor`: the path-point mission in the embedded building.
fn indoor(args: &SimArgs, cfg: &SimConfig) -> Result<()> {
    let soccer_only = [
        (args.matches > 1, "--matches"),
        (args.distributed, "--distributed"),
        (args.bench, "--bench"),
        (args.belief.is_some(), "--belief"),
        (args.metrics.is_some(), "--metrics"),
        (args.kidnap.is_some(), "--kidnap"),
        (args.behaviors.is_some(), "--behaviors"),
    ];
    if let Some((_, flag)) = soccer_only.iter().find(|(given, _)| *given) {
        anyhow::bail!("{flag} is for the soccer world, not --world indoor");
    }
    let (map, mission, events) = mrt_sim::indoor::embedded().map_err(|e| anyhow!("{e}"))?;
    let bar = ProgressBar::new(events.duration.ceil() as u64).with_style(
        ProgressStyle::with_template("{spinner} mission time {pos}/{len} s [{bar:40}] ({elapsed})")
            .map_err(|e| anyhow!("{e}"))?
            .progress_chars("=> "),
    );
    let started = std::time::Instant::now();
    let realtime = args.realtime;
    let report = mrt_sim::indoor::run_mission(cfg, args.seed, (&map, &mission, &events), |t| {
        bar.set_position(t as u64);
        if realtime {
            let ahead = t - started.elapsed().as_secs_f64();
            if ahead > 0.0 {
                std::thread::sleep(std::time::Duration::from_secs_f64(ahead));
            }
        }
    })
    .map_err(|e| anyhow!("{e}"))?;
    bar.finish_and_clear();
    use mrt_robot::mission::MissionEvent;
    outln!(
        "indoor world, seed {}: {} of {} path points in {:.1} s{}",
        report.seed,
        report.reached(),
        report.points.len(),
        report.duration,
        if report.finished { "" } else { " (time up)" }
    );
    for e in &report.events {
        match e {
            MissionEvent::Reached { time, point } => {
                let at = report.points[*point];
                outln!("  {time:6.1} s  reached point {} ({:.1}, {:.1})", point + 1, at.x, at.y);
            }
            MissionEvent::GaveUp { time, point } => {
                outln!("  {time:6.1} s  gave point {} up after three time-outs", point + 1);
            }
            MissionEvent::NoPath { time, point } => {
                outln!("  {time:6.1} s  no way to point {} (waits)", point + 1);
            }
            MissionEvent::Planned { .. } => {}
        }
    }
    outln!(
        "  re-planned {} times (the way blocked or a job timed out); the sonars corrected the dead reckoning {} times; belief {:.2} m from the truth at the end",
        report.replans(),
        report.fixes,
        report.final_error
    );
    for f in &report.faults {
        outln!("  fault: {}", mrt_core::printable(&f.to_string()));
    }
    if let Some(path) = &args.plot {
        std::fs::write(path, mrt_sim::plot::indoor(&map, &report))
            .with_context(|| format!("writing {}", path.display()))?;
        outln!("  plot: {}", path.display());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wilson interval, by hand: 5 of 10 at 95 % gives 23.7 %–76.3 %.
    #[test]
    fn wilson_interval_by_hand() {
        let (lo, hi) = wilson(5, 10);
        assert!((lo - 23.66).abs() < 0.05 && (hi - 76.34).abs() < 0.05, "{lo} {hi}");
        assert_eq!(wilson(0, 0), (0.0, 100.0));
    }
}
