//! `mrt replay FILE.mcap`: what a recording holds; (`--serve`) the recording in the web
//! monitor; (`--robot R [--behaviors DIR]`) one robot's behaviors re-run on the world
//! snapshots it had, and where their commands differ from the recorded ones; (`--accuracy`)
//! how far each robot's beliefs were from the recorded truth (docs/monitor.md).

use anyhow::{anyhow, bail, Context as _, Result};
use mrt_core::Time;
use mrt_monitor::accuracy::Spread;
use mrt_monitor::serve::Server;
use mrt_monitor::MatchInfo;
use mrt_monitor::{Recording, Timeline};
use mrt_msgs::{MateReport, RobotCommand, WorldSnapshot};
use mrt_robot::files::FilesDir;
use mrt_robot::spec::Stack;
use mrt_robot::stacks::embedded_teamchaos;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;

/// `mrt replay`.
#[derive(clap::Args)]
pub struct ReplayArgs {
    /// The MCAP file (`mrt sim --record`, or another tool's: channels that are not JSON are
    /// listed as skipped).
    pub file: PathBuf,
    /// Print the topics as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Serve the recording in the web monitor (until Ctrl-C): the field, each robot's beliefs
    /// against the truth, a timeline to play, pause, step and scrub. ADDR defaults to
    /// 127.0.0.1:8080 (loopback only; port 0 takes any free port).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8080")]
    pub serve: Option<std::net::SocketAddr>,
    /// Re-run this robot's behaviors (e.g. home/2: robot 2 of the home team, 0 keeps goal)
    /// on the world snapshots it had in the recording, and print the cycles where their
    /// commands differ from the recorded ones.
    #[arg(long, value_name = "ROBOT")]
    pub robot: Option<String>,
    /// With --robot: the behaviors to re-run, e.g. an edited copy (TeamChaos files for a
    /// chaos robot, a Mr. BRIAN configuration for a milan one). Default: the compiled-in
    /// ones.
    #[arg(long, value_name = "DIR", requires = "robot")]
    pub behaviors: Option<PathBuf>,
    /// How far each robot's beliefs were from the recorded truth: position and heading at
    /// every Localization, the ball (and its velocity) while the robot saw it; mean, median
    /// and 95th percentile, per robot and for all (`--json` for a machine).
    #[arg(long, conflicts_with = "robot")]
    pub accuracy: bool,
    /// Write a clean copy of the recording into OUT: every message of a damaged file (cut
    /// short, or left by a process that was killed while it wrote) up to the damage, with
    /// its summary and index, for `mrt replay` and other MCAP tools.
    #[arg(long, value_name = "OUT", conflicts_with_all = ["serve", "robot", "accuracy"])]
    pub recover: Option<PathBuf>,
}

/// Runs `mrt replay`: lists the recording's topics with their schemas, message counts and
/// time spans.
pub fn run(args: &ReplayArgs) -> Result<()> {
    let (recording, damage) = Recording::open_salvaged(&args.file)?;
    if let Some(d) = &damage {
        eprintln!(
            "warning: {}: damaged after {} messages ({:.1} s): {}; reading what comes before{}",
            args.file.display(),
            d.kept,
            d.until.as_secs_f64(),
            mrt_core::printable(&d.why),
            if args.recover.is_none() { " (--recover OUT writes a clean copy)" } else { "" }
        );
    }
    if let Some(out) = &args.recover {
        return recover(&recording, out, damage.is_some());
    }
    if let Some(addr) = args.serve {
        let timeline = Timeline::of_recording(&recording)?;
        let frames = timeline.end();
        if frames == 0 {
            anyhow::bail!("{}: no message the monitor can show", args.file.display());
        }
        let title = args.file.file_name().map_or_else(String::new, |n| n.to_string_lossy().into());
        let server = Server::start(addr, timeline.shared(), &title)?;
        outln!("monitor: {} ({frames} frames); Ctrl-C to stop", server.url());
        crate::wait_for_ctrl_c();
    }
    if let Some(robot) = &args.robot {
        return rerun(args, &recording, robot);
    }
    if args.accuracy {
        return accuracy(args, &recording);
    }
    let topics = recording.topics()?;
    let secs = |t: mrt_core::Time| t.as_secs_f64();
    if args.json {
        let list: Vec<serde_json::Value> = topics
            .iter()
            .map(|t| {
                serde_json::json!({
                    "topic": t.topic, "schema": t.schema, "schema_encoding": t.schema_encoding, "encoding": t.encoding,
                    "messages": t.count, "first_s": secs(t.first), "last_s": secs(t.last),
                    "readable": t.readable(),
                })
            })
            .collect();
        outln!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    let messages: u64 = topics.iter().map(|t| t.count).sum();
    let first = topics.iter().map(|t| t.first).min().map_or(0.0, secs);
    let last = topics.iter().map(|t| t.last).max().map_or(0.0, secs);
    outln!(
        "{}: {messages} messages on {} topics, {first:.1} to {last:.1} s",
        args.file.display(),
        topics.len()
    );
    let width = topics.iter().map(|t| t.topic.chars().count()).max().unwrap_or(0);
    for t in &topics {
        let skipped = if t.readable() {
            String::new()
        } else {
            format!(
                "  (skipped: {} messages with a {} schema, not JSON with a JSON schema)",
                t.encoding,
                if t.schema_encoding.is_empty() { "missing" } else { &t.schema_encoding }
            )
        };
        outln!(
            "  {:<width$}  {:<16} {:>7} messages  {:>7.1} to {:>7.1} s{skipped}",
            t.topic,
            t.schema,
            t.count,
            secs(t.first),
            secs(t.last)
        );
    }
    Ok(())
}

/// `--recover OUT`: the readable messages of `recording` into a new, finished file.
fn recover(recording: &Recording, out: &std::path::Path, damaged: bool) -> Result<()> {
    let mut copy = mrt_monitor::Recorder::create(out)?;
    let mut failed = None;
    recording.scan(|e| {
        if failed.is_none() {
            failed = copy.copy(&e).err();
        }
    })?;
    if let Some(e) = failed {
        return Err(e).with_context(|| format!("cannot write {}", out.display()));
    }
    let s = copy.finish()?;
    let state = if damaged { "recovered" } else { "copied (the recording was intact)" };
    outln!("{state}: {} messages on {} topics into {}", s.messages, s.channels, out.display());
    Ok(())
}

/// `--accuracy`: each robot's beliefs against the recorded truth.
fn accuracy(args: &ReplayArgs, recording: &Recording) -> Result<()> {
    let list = mrt_monitor::accuracy::accuracy(recording)?;
    if list.is_empty() {
        bail!(
            "{}: no robot's Localization with a /truth of its instant (record a match with \
             mrt sim --record or mrt world mujoco --record)",
            args.file.display()
        );
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    let show = |s: Option<Spread>, scale: f64, unit: &str| {
        s.map_or("-".to_string(), |s| {
            format!("{:.2} / {:.2} / {:.2} {unit}", s.mean * scale, s.median * scale, s.p95 * scale)
        })
    };
    outln!("{}: beliefs against the truth, mean / median / p95", args.file.display());
    for a in &list {
        outln!(
            "  {:<8} position {}  heading {}  ball while seen {} ({} cycles)  ball velocity {}  \
             found itself {}",
            a.robot,
            show(a.position, 1.0, "m"),
            show(a.heading, 180.0 / std::f64::consts::PI, "°"),
            show(a.ball, 1.0, "m"),
            a.ball.map_or(0, |b| b.count),
            show(a.ball_velocity, 1.0, "m/s"),
            a.found_after.map_or("never".to_string(), |s| format!("after {s:.1} s")),
        );
    }
    Ok(())
}

/// How many differing cycles `--robot` prints (`--json` gives them all).
const SHOWN: usize = 20;

/// `--robot`: the robot's behaviors re-run on its recorded snapshots (module doc).
fn rerun(args: &ReplayArgs, recording: &Recording, robot: &str) -> Result<()> {
    let file = args.file.display();
    // One pass over the file for the three topics this needs.
    let [snapshots, commands, reports] =
        ["WorldSnapshot", "RobotCommand", "MateReport"].map(|t| format!("/{robot}/{t}"));
    let mut raw = recording.raw(&["/match", &snapshots, &commands, &reports])?;
    let mut take = |topic: &str| raw.remove(topic).unwrap_or_default();
    let info = recording
        .decode::<MatchInfo>("/match", take("/match"))?
        .into_iter()
        .next()
        .map(|(_, info)| info)
        .with_context(|| {
            format!(
                "{file}: no /match topic (which stacks played): record it with mrt sim --record"
            )
        })?;
    if info.profile == mrt_monitor::RecordProfile::Compact {
        bail!(
            "{file} is a compact recording (mrt sim --record --compact): it keeps {robot}'s \
             world snapshots at 2 Hz with rounded floats, not the ones its behaviors ran on each \
             cycle, so a re-run cannot reproduce its commands and every difference would \
             mislead. Record the match without --compact to re-run behaviors."
        );
    }
    let (team, k) = robot.split_once('/').unwrap_or((robot, ""));
    let k: usize = k.parse().map_err(|_| anyhow!("--robot {robot}: expected home/K or away/K"))?;
    let stack = match team {
        "home" => Some(info.home.as_str()),
        "away" => info.away.as_deref(),
        _ => None,
    };
    let stack =
        stack.with_context(|| format!("--robot {robot}: the recording has no such team"))?;
    if k >= info.team_size {
        bail!("--robot {robot}: a team has robots 0 to {}", info.team_size.saturating_sub(1));
    }
    let stack = Stack::parse(stack).map_err(|e| anyhow!("{file}: {e}"))?;
    if stack == Stack::Isocrob {
        bail!("--robot {robot}: ISocRob robots play through their shared blackboard; one cannot be re-run alone");
    }
    let snapshots = recording.decode::<WorldSnapshot>(&snapshots, take(&snapshots))?;
    if snapshots.is_empty() {
        bail!("{file}: no world snapshots of {robot}");
    }
    let recorded: BTreeMap<Time, RobotCommand> =
        recording.decode::<RobotCommand>(&commands, take(&commands))?.into_iter().collect();
    // The compiled-in TeamChaos files live while this handle does.
    let files = match (&args.behaviors, stack) {
        (Some(dir), _) => Some(FilesDir::user(dir)),
        (None, Stack::Chaos) => Some(embedded_teamchaos().map_err(|e| anyhow!("{e}"))?),
        (None, _) => None,
    };
    // The robot's own reports say whether it kept goal (the empty goal's one robot is a field
    // player); without them robot 0 of a team does.
    let reports = recording.decode::<MateReport>(&reports, take(&reports))?;
    let keeper = reports.first().map_or(k == 0, |(_, r)| r.keeper);
    let times: Vec<Time> = snapshots.iter().map(|(t, _)| *t).collect();
    let worlds = snapshots.into_iter().map(|(_, w)| w).collect();
    let period = Duration::from_secs_f64(info.period);
    let report =
        mrt_robot::rerun::rerun(stack, keeper, files.as_ref().map(FilesDir::path), period, worlds)
            .map_err(|e| anyhow!("{robot}: {e}"))?;
    let rerun = &report.cycles;
    let mut differing = Vec::new();
    let mut errors = Vec::new();
    for (time, cycle) in times.iter().zip(rerun) {
        errors.extend(cycle.errors.iter().map(|e| (time.as_secs_f64(), e.clone())));
        let fields = differences(recorded.get(time), cycle.command.as_ref());
        if !fields.is_empty() {
            differing.push((time.as_secs_f64(), fields));
        }
    }
    let behaviors = args.behaviors.as_ref().map_or("the compiled-in behaviors".into(), |d| {
        format!("the behaviors of {}", d.display())
    });
    let role = if keeper { "goalkeeper" } else { "field player" };
    if args.json {
        let v = serde_json::json!({
            "robot": robot, "stack": stack.name(), "keeper": keeper, "cycles": rerun.len(),
            "differing": differing.len(),
            "differences": differing.iter().map(|(t, f)| serde_json::json!({"t": t, "fields": f})).collect::<Vec<_>>(),
            "errors": errors.iter().map(|(t, e)| serde_json::json!({"t": t, "error": e})).collect::<Vec<_>>(),
            "fault": report.fault,
        });
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    outln!(
        "{robot} ({} {role}): {} world snapshots re-run with {behaviors}; its commands differ from the recording in {} cycles",
        stack.name(),
        rerun.len(),
        differing.len()
    );
    for (t, fields) in differing.iter().take(SHOWN) {
        outln!("  {t:>7.1} s  {}", fields.join("; "));
    }
    if differing.len() > SHOWN {
        outln!("  ... and {} more (--json lists them all)", differing.len() - SHOWN);
    }
    if let Some((t, first)) = errors.first() {
        outln!("  the behaviors reported {} errors, the first at {t:.1} s: {first}", errors.len());
    }
    if let Some(fault) = &report.fault {
        outln!("  the behavior Member faulted: {fault}");
    }
    Ok(())
}

/// What differs between the recorded command and the re-run's, field by field (SI, as
/// `RobotCommand` holds them: m/s, rad/s, m); nothing when both are absent or equal.
fn differences(recorded: Option<&RobotCommand>, rerun: Option<&RobotCommand>) -> Vec<String> {
    let (a, b) = match (recorded, rerun) {
        (None, None) => return Vec::new(),
        (Some(_), None) => return vec!["no command re-run".into()],
        (None, Some(_)) => return vec!["no command recorded".into()],
        (Some(a), Some(b)) => (a, b),
    };
    let mut out = Vec::new();
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-6 * (1.0 + x.abs().max(y.abs()));
    for (name, x, y, unit) in [
        ("vx", a.twist.vx, b.twist.vx, "m/s"),
        ("vy", a.twist.vy, b.twist.vy, "m/s"),
        ("omega", a.twist.omega, b.twist.omega, "rad/s"),
    ] {
        if !close(x, y) {
            out.push(format!("{name} {x:.4} → {y:.4} {unit}"));
        }
    }
    if a.kick != b.kick {
        out.push(format!("kick {:?} → {:?}", a.kick, b.kick));
    }
    if a.behavior != b.behavior {
        out.push(format!("behavior {:?} → {:?}", a.behavior, b.behavior));
    }
    if a.book_ball != b.book_ball {
        out.push(format!("book_ball {:?} → {:?}", a.book_ball, b.book_ball));
    }
    let pose = |t: &Option<mrt_msgs::Target>| {
        t.map(|t| (t.pose.inner.x, t.pose.inner.y, t.pose.inner.theta, t.avoid, t.plan))
    };
    match (pose(&a.target), pose(&b.target)) {
        (Some(p), Some(q))
            if close(p.0, q.0)
                && close(p.1, q.1)
                && close(p.2, q.2)
                && p.3 == q.3
                && p.4 == q.4 => {}
        (None, None) => {}
        (p, q) => out.push(format!("target {p:?} → {q:?}")),
    }
    if a.needs != b.needs || a.track_landmarks != b.track_landmarks {
        out.push(format!("needs {:?} → {:?}", a.needs, b.needs));
    }
    out
}
