//! `mrt world mujoco`: a match in the MuJoCo world (`worlds/mujoco/world.py`, Python), each
//! robot the unchanged robot program in a process of its own (`mrt robot --config FILE` on a
//! world's devices, docs/devices.md), each team on a DCDT network of its own for the
//! teammates' reports.

use crate::distributed::{team_net_file, Launch, PortPicker, Robots};
use anyhow::{anyhow, bail, Context as _, Result};
use mrt_core::{Pose2, Time};
use mrt_monitor::catalogue::schema_of;
use mrt_monitor::{MatchInfo, RecordProfile, RecordSummary, Recorder, Recording, Truth};
use mrt_msgs::GameState;
use mrt_perception::camera::OmniFile;
use mrt_robot::config::RobotFile;
use mrt_robot::spec::Stack;
use mrt_sim::game::TeamStats;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// The world's name in the device protocol's keys.
const WORLD: &str = "mujoco";

/// What is played.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Scenario {
    /// Two teams, two halves, the referee's kickoffs.
    Match,
    /// One robot of the home team at a random pose, the ball at a random spot, no opponents:
    /// it must score within 60 s of play.
    EmptyGoal,
}

/// `mrt world mujoco`.
#[derive(clap::Args)]
pub struct MujocoArgs {
    /// The home team's stack (chaos, milan, isocrob, chaser).
    #[arg(long, default_value = "milan")]
    pub home: String,
    /// The away team's stack.
    #[arg(long, default_value = "chaos")]
    pub away: String,
    /// Robots a team.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u64).range(1..=6))]
    pub robots: u64,
    /// The scene: lights and colours (relative to the world's directory, or a path).
    #[arg(long, default_value = "scenes/bright.xml")]
    pub scene: PathBuf,
    /// The seed of the world's random choices.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Seconds of play a half.
    #[arg(long, default_value_t = 300.0)]
    pub half: f64,
    /// What is played.
    #[arg(long, value_enum, default_value_t = Scenario::Match)]
    pub scenario: Scenario,
    /// Each robot's omnidirectional camera (an omni camera file), which the world renders
    /// beside its front camera (IANUS3's omnidirectional vision, MRT manual §12.5).
    #[arg(long, value_name = "FILE", default_value = "configs/vision/omni-ianus3.toml")]
    pub up_camera: PathBuf,
    /// Robots with the front camera only.
    #[arg(long)]
    pub no_up_camera: bool,
    /// The MuJoCo world's directory.
    #[arg(long, default_value = "worlds/mujoco")]
    pub dir: PathBuf,
    /// The Python that runs it (default: $MRT_PYTHON, else python3), with
    /// worlds/mujoco/requirements.txt and python/requirements.txt installed.
    #[arg(long)]
    pub python: Option<String>,
    /// Ends after this many steps whatever the game (0: when it is over).
    #[arg(long, default_value_t = 0)]
    pub steps: u64,
    /// Writes the world's truth, one JSON line a step (time, state, score, ball, robots).
    #[arg(long)]
    pub truth: Option<PathBuf>,
    /// Keeps each robot process's log in this directory, as `<robot name>.log` (default:
    /// thrown away with the match's temporary files, shown only when the world fails).
    #[arg(long, value_name = "DIR")]
    pub logs: Option<PathBuf>,
    /// Records the match into this MCAP file: MuJoCo's truth on `/truth` and every robot's
    /// messages on `/home/k/<type>` and `/away/k/<type>`, as `mrt sim --record` does, for
    /// `mrt replay FILE --serve`.
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// Saves the images the world sends the robots into this directory, as PNGs (what the
    /// robots see: `<robot>_<step>.png`, `_up` for the omnidirectional camera).
    #[arg(long, value_name = "DIR")]
    pub save_frames: Option<PathBuf>,
    /// Mice and encoders without the errors MRT's simulator gives them (by default the
    /// world adds the same noise and under-reading mice as `configs/sim/default.toml`).
    #[arg(long)]
    pub exact_odometry: bool,
    /// Never tell a robot where it was put down (at the start, after a goal): it must find
    /// itself from what it sees (MUREA, MRT manual ch. 7).
    #[arg(long)]
    pub unplaced: bool,
    /// With --save-frames: every K-th step.
    #[arg(long, value_name = "K", default_value_t = 10, requires = "save_frames")]
    pub frame_every: u64,
}

/// Robot `i`'s file: `name` in the world reached at `endpoint`, on its team's network `net`
/// (none for a team of one).
fn robot_file(
    i: usize,
    n: usize,
    stack: Stack,
    name: &str,
    endpoint: &str,
    net: Option<&Path>,
    up_camera: Option<&OmniFile>,
) -> String {
    let mut file = RobotFile::default();
    file.robot.id = i;
    file.robot.team_size = n;
    file.robot.stack = stack.name().into();
    file.body.base = "differential".into();
    file.vision.enabled = true;
    file.vision.up_camera = up_camera.cloned();
    file.devices.kind = "world".into();
    file.devices.world = Some(WORLD.into());
    file.devices.name = Some(name.into());
    file.devices.connect = vec![endpoint.into()];
    file.devices.net = net.map(Path::to_path_buf);
    let text = file.to_toml().unwrap_or_default();
    format!("# Robot {i} of a MuJoCo match (written by mrt world mujoco).\n{text}")
}

/// Plays the match: the world and one robot process per robot; prints the world's report.
pub fn play(args: &MujocoArgs) -> Result<()> {
    let parse = |s: &str| Stack::parse(s).map_err(|e| anyhow!("{e}"));
    let (home, away) = (parse(&args.home)?, parse(&args.away)?);
    let script = args.dir.join("world.py");
    if !script.is_file() {
        bail!("{}: no MuJoCo world here (--dir names worlds/mujoco)", script.display());
    }
    let n = usize::try_from(args.robots)?;
    let teams: Vec<(Stack, &str)> = match args.scenario {
        Scenario::Match => vec![(home, "home"), (away, "away")],
        Scenario::EmptyGoal => vec![(home, "home")],
    };
    let per_team = if args.scenario == Scenario::EmptyGoal { 1 } else { n };
    let up_camera =
        if args.no_up_camera { None } else { Some(OmniFile::from_file(&args.up_camera)?) };
    let dir = std::env::temp_dir().join(format!("mrt-mujoco-{}-{}", std::process::id(), args.seed));
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut procs = Robots { dir: dir.clone(), children: Vec::new() };
    let mut picker = PortPicker::new();
    let endpoint = format!("tcp/127.0.0.1:{}", picker.port()?);
    let count = teams.len() * per_team;
    let ports = (0..count).map(|_| picker.port()).collect::<Result<Vec<_>>>()?;
    let mut files = Vec::new();
    let mut names = Vec::new();
    for (t, (stack, side)) in teams.iter().enumerate() {
        let discovery = picker.port()?;
        for k in 0..per_team {
            let i = t * per_team + k;
            let net = dir.join(format!("robot-{i}.cfg"));
            if per_team > 1 {
                std::fs::write(
                    &net,
                    team_net_file(i, t * per_team..(t + 1) * per_team, discovery, &ports),
                )?;
            }
            let net = (per_team > 1).then_some(net.as_path());
            let file = dir.join(format!("robot-{i}.toml"));
            let name = format!("{side}-{}", k + 1);
            // The empty goal's one robot is a field player (robot 1 of a team of two whose
            // keeper is not there), not a goalkeeper.
            let (id, size) = if per_team == 1 { (1, 2) } else { (i, per_team) };
            std::fs::write(
                &file,
                robot_file(id, size, *stack, &name, &endpoint, net, up_camera.as_ref()),
            )?;
            files.push(file);
            names.push(name);
        }
    }
    let python = args
        .python
        .clone()
        .or_else(|| std::env::var("MRT_PYTHON").ok())
        .unwrap_or_else(|| "python3".into());
    let mut world = Command::new(&python);
    world
        .arg(&script)
        .arg("play")
        .arg("--scene")
        .arg(&args.scene)
        .args(["--camera", "configs/vision/camera.toml", "--world", WORLD, "--listen", &endpoint])
        .args(["--home", &per_team.to_string()])
        .args(["--away", &if args.scenario == Scenario::Match { n } else { 0 }.to_string()])
        .args(["--half", &args.half.to_string(), "--seed", &args.seed.to_string()])
        .args(["--steps", &args.steps.to_string()])
        .args(["--scenario", if args.scenario == Scenario::Match { "match" } else { "empty-goal" }])
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit());
    // A recording needs the truth: in the user's file, or one of the match's own.
    let truth =
        args.truth.clone().or_else(|| args.record.as_ref().map(|_| dir.join("truth.jsonl")));
    if let Some(t) = &truth {
        world.arg("--truth").arg(t);
    }
    if up_camera.is_some() {
        world.arg("--up-camera").arg(&args.up_camera);
    }
    if args.exact_odometry {
        world.arg("--exact-odometry");
    }
    if args.unplaced {
        world.arg("--no-placed");
    }
    if let Some(frames) = &args.save_frames {
        world.arg("--save-frames").arg(frames);
        world.args(["--frame-every", &args.frame_every.to_string()]);
    }
    if std::env::var_os("MUJOCO_GL").is_none() {
        world.env("MUJOCO_GL", "egl");
    }
    let world =
        world.spawn().with_context(|| format!("cannot start {python} {}", script.display()))?;
    let launch = Launch { exe: std::env::current_exe().context("cannot find the mrt executable")? };
    let recordings: Vec<PathBuf> =
        (0..files.len()).map(|i| dir.join(format!("robot-{i}.mcap"))).collect();
    for (i, file) in files.iter().enumerate() {
        let mut more = Vec::new();
        if args.record.is_some() {
            more.extend(["--record".into(), recordings[i].clone().into_os_string()]);
            more.extend(["--record-as".into(), topic_prefix(&names[i]).into()]);
        }
        let child = launch.robot_with(i, file, &procs.log(i), &more)?;
        procs.children.push((i, child));
    }
    let out = world.wait_with_output().context("the world did not end")?;
    procs.wait(Duration::from_secs(5));
    if let Some(logs) = &args.logs {
        std::fs::create_dir_all(logs)
            .with_context(|| format!("cannot create {}", logs.display()))?;
        for (i, name) in names.iter().enumerate() {
            let to = logs.join(format!("{name}.log"));
            std::fs::copy(procs.log(i), &to)
                .with_context(|| format!("cannot keep robot {name}'s log in {}", to.display()))?;
        }
    }
    if !out.status.success() {
        let tails: Vec<String> =
            (0..files.len()).map(|i| format!("robot {i}:\n{}", procs.tail(i))).collect();
        bail!("the MuJoCo world ended with {}\n{}", out.status, tails.join("\n"));
    }
    if let (Some(path), Some(truth)) = (&args.record, &truth) {
        let info = MatchInfo {
            home: home.name().into(),
            away: (args.scenario == Scenario::Match).then(|| away.name().into()),
            seed: args.seed,
            team_size: per_team,
            period: RobotFile::default()
                .config()
                .map_err(|e| anyhow!("{e}"))?
                .period()
                .as_secs_f64(),
            profile: RecordProfile::Full,
        };
        let s = record_match(path, &info, truth, &recordings, &names)?;
        eprintln!(
            "recorded {} messages on {} topics into {}",
            s.messages,
            s.channels,
            path.display()
        );
    }
    let report = String::from_utf8_lossy(&out.stdout);
    let line = report.lines().last().unwrap_or("").trim();
    let v: serde_json::Value = serde_json::from_str(line)
        .with_context(|| format!("the world's report is not JSON: {}", line.escape_debug()))?;
    outln!("{}", summary(&v, &teams));
    let names: Vec<&str> = teams.iter().map(|(s, _)| s.name()).collect();
    for line in crate::sim::team_lines(&names, &team_stats(&v)) {
        outln!("{line}");
    }
    outln!("{line}");
    Ok(())
}

/// One line a person reads: the score and the goals, the steps and the world's speed.
fn summary(v: &serde_json::Value, teams: &[(Stack, &str)]) -> String {
    let score = |side: &str| v["score"][side].as_u64().unwrap_or(0);
    let names: Vec<String> =
        teams.iter().map(|(s, side)| format!("{side} ({}) {}", s.name(), score(side))).collect();
    let goals: Vec<String> = v["goals"]
        .as_array()
        .into_iter()
        .flatten()
        .map(|g| {
            format!(
                "{} {:.1} s",
                g["team"].as_str().unwrap_or("?"),
                g["time"].as_f64().unwrap_or(0.0)
            )
        })
        .collect();
    format!(
        "MuJoCo {}: {}; goals: {}; {} steps, {:.1} s of play, {:.2}x real time, {:.0} ms a frame",
        v["scenario"].as_str().unwrap_or("match"),
        names.join(" : "),
        if goals.is_empty() { "none".into() } else { goals.join(", ") },
        v["steps"].as_u64().unwrap_or(0),
        v["play_time"].as_f64().unwrap_or(0.0),
        v["real_time_factor"].as_f64().unwrap_or(0.0),
        v["render_ms"].as_f64().unwrap_or(0.0),
    )
}

/// Each team's goals, shots and possession steps in the world's report (home's, then away's).
fn team_stats(v: &serde_json::Value) -> [TeamStats; 2] {
    let count = |v: &serde_json::Value| u32::try_from(v.as_u64().unwrap_or(0)).unwrap_or(u32::MAX);
    ["home", "away"].map(|side| {
        let s = &v["stats"][side];
        TeamStats {
            goals: count(&v["score"][side]),
            shots: count(&s["shots"]),
            shots_on_target: count(&s["on_target"]),
            possession_cycles: s["possession_steps"].as_u64().unwrap_or(0),
            ..TeamStats::default()
        }
    })
}

/// The recording's topic prefix of the robot the world names `name` (`home-1` → `home/0`):
/// what the web monitor matches with the truth's robots.
fn topic_prefix(name: &str) -> String {
    match name.rsplit_once('-') {
        Some((side, k)) => match k.parse::<usize>() {
            Ok(k) if k > 0 => format!("{side}/{}", k - 1),
            _ => name.to_string(),
        },
        None => name.to_string(),
    }
}

/// One line of the world's truth (`world.py --truth`) as the monitor's [`Truth`]: the robots
/// in the order of `names` (home's, then away's).
fn truth_of(line: &str, names: &[String]) -> Result<(Time, Truth)> {
    let v: serde_json::Value = serde_json::from_str(line)?;
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or(0.0);
    let pair = |v: &serde_json::Value, i: usize| (num(&v[i]), num(&v[i + 1]));
    let state = match v["state"].as_str().unwrap_or("") {
        "ready" => GameState::Ready,
        "set" => GameState::Set,
        "playing" => GameState::Playing,
        "finished" => GameState::Finished,
        _ => GameState::Initial,
    };
    let robots = names
        .iter()
        .map(|n| {
            let r = &v["robots"][n];
            Pose2::new(num(&r[0]), num(&r[1]), num(&r[2]))
        })
        .collect();
    let goals = |side: &str| u32::try_from(v["score"][side].as_u64().unwrap_or(0)).unwrap_or(0);
    let truth = Truth {
        ball: pair(&v["ball"], 0),
        ball_velocity: pair(&v["ball"], 2),
        robots,
        home: names.iter().filter(|n| n.starts_with("home")).count(),
        score: (goals("home"), goals("away")),
        state,
    };
    let t = v["time"].as_f64().filter(|t| t.is_finite() && *t >= 0.0);
    let t = t.ok_or_else(|| anyhow!("a truth line without a time: {}", v["time"]))?;
    Ok((Time::from_secs_f64(t), truth))
}

/// Writes the match's recording into `path`: `/match`, the truth of the file `truth` on
/// `/truth` and every robot's own recording, all in log-time order (at one instant the truth
/// first, then the robots in order). A robot whose recording is missing or damaged is left
/// out with a warning: the rest is still worth replaying.
fn record_match(
    path: &Path,
    info: &MatchInfo,
    truth: &Path,
    recordings: &[PathBuf],
    names: &[String],
) -> Result<RecordSummary> {
    // Topics (with their schemas) and messages, each message (time, source, topic, json).
    let mut topics: Vec<(String, String, Vec<u8>)> = Vec::new();
    let mut messages: Vec<(Time, usize, usize, Vec<u8>)> = Vec::new();
    let text = mrt_core::read_text(truth, mrt_core::MAX_LOG_BYTES)
        .with_context(|| format!("cannot read the world's truth {}", truth.display()))?;
    topics.push(("/truth".into(), "Truth".into(), serde_json::to_vec(&schema_of::<Truth>())?));
    for (i, line) in text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let (t, truth) =
            truth_of(line, names).with_context(|| format!("{}:{}", truth.display(), i + 1))?;
        messages.push((t, 0, 0, serde_json::to_vec(&truth)?));
    }
    for (source, file) in recordings.iter().enumerate() {
        let recording = match Recording::open(file) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("warning: robot {} left out of the recording: {e}", names[source]);
                continue;
            }
        };
        let mut index = std::collections::BTreeMap::new();
        let scanned = recording.scan(|e| {
            let topic = *index.entry(e.topic.to_string()).or_insert_with(|| {
                topics.push((e.topic.into(), e.schema.into(), e.schema_data.to_vec()));
                topics.len() - 1
            });
            messages.push((e.time, source + 1, topic, e.json.to_vec()));
        });
        if let Err(e) = scanned {
            eprintln!("warning: robot {}'s recording is damaged: {e}", names[source]);
        }
    }
    messages.sort_by_key(|&(t, source, _, _)| (t, source));
    let mut rec = Recorder::create(path)?;
    rec.record("/match", Time::ZERO, info)?;
    for (time, _, topic, json) in &messages {
        let (topic, schema, schema_data) = &topics[*topic];
        let e = mrt_monitor::replay::Entry { topic, schema, schema_data, time: *time, json };
        rec.copy(&e)?;
    }
    Ok(rec.finish()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_worlds_robot_names_become_the_monitors_prefixes() {
        assert_eq!(topic_prefix("home-1"), "home/0");
        assert_eq!(topic_prefix("away-3"), "away/2");
        // Names the world did not make this way are kept.
        for name in ["goalie", "home-0", "home-x", "a-b-c"] {
            assert_eq!(topic_prefix(name), name);
        }
    }

    #[test]
    fn the_worlds_statistics_become_each_teams_line() {
        let v: serde_json::Value = serde_json::from_str(
            r#"{"score": {"home": 2, "away": 0}, "stats": {
                "home": {"shots": 5, "on_target": 3, "possession_steps": 300},
                "away": {"shots": 1, "on_target": 0, "possession_steps": 100}}}"#,
        )
        .unwrap();
        let stats = team_stats(&v);
        assert_eq!((stats[0].goals, stats[0].shots, stats[0].shots_on_target), (2, 5, 3));
        assert_eq!((stats[1].shots, stats[1].possession_cycles), (1, 100));
        let lines = crate::sim::team_lines(&["milan", "chaos"], &stats);
        assert!(lines[0].contains("shots   5 (  3 on target)  possession  75.0 %"), "{lines:?}");
        assert!(lines[1].contains("possession  25.0 %"), "{lines:?}");
        // A report without statistics (an older world) counts nothing.
        let none = team_stats(&serde_json::json!({}));
        assert_eq!(none, [TeamStats::default(), TeamStats::default()]);
    }

    #[test]
    fn a_truth_line_becomes_the_monitors_truth() {
        let names = ["home-1".to_string(), "home-2".to_string(), "away-1".to_string()];
        let line = r#"{"time": 12.5, "state": "playing", "score": {"home": 2, "away": 1},
            "ball": [1.0, -2.0, 0.5, 0.25], "robots": {"away-1": [3.0, 4.0, -1.0],
            "home-1": [-1.0, 0.5, 0.1], "home-2": [0.0, 0.0, 3.0]}}"#;
        let (t, truth) = truth_of(line, &names).unwrap();
        assert_eq!(t, Time::from_secs_f64(12.5));
        assert_eq!(truth.ball, (1.0, -2.0));
        assert_eq!(truth.ball_velocity, (0.5, 0.25));
        assert_eq!(
            truth.robots,
            [Pose2::new(-1.0, 0.5, 0.1), Pose2::new(0.0, 0.0, 3.0), Pose2::new(3.0, 4.0, -1.0)]
        );
        assert_eq!((truth.home, truth.score, truth.state), (2, (2, 1), GameState::Playing));
        for bad in ["", "{", r#"{"time": -1}"#, r#"{"time": "x"}"#] {
            assert!(truth_of(bad, &names).is_err(), "{bad}");
        }
    }
}
