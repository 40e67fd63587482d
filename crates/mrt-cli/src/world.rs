//! `mrt robot --config FILE` with `[devices] kind = "world"`: the robot program on the
//! devices of a world that speaks the device protocol over zenoh (docs/devices.md): the
//! command's arguments ([`RobotArgs`]), its recording, and the robot's run. `mrt sim
//! --distributed` (`distributed`) starts such robots and reads what they write to their logs
//! ([`PHASES`], [`FIRST_ANSWER`]).

use anyhow::{anyhow, bail, Context as _, Result};
use mrt_core::AgoraId;
use mrt_dcdt::config::AgoraConfig;
use mrt_dcdt::Message as _;
use mrt_devices::Keys;
use mrt_monitor::{Recorder, SharedRecorder, Tap};
use mrt_msgs::MateReport;
use mrt_net::{NetConfig, RawPort};
use mrt_robot::config::RobotFile;
use mrt_robot::members::behaviors_dir;
use mrt_robot::remote::RemoteRobot;
use mrt_robot::world::{WorldMail, WorldPort, WorldRobot};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, TrySendError};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// `mrt robot --config FILE`: one robot's Agora on its configured devices.
#[derive(clap::Args)]
pub struct RobotArgs {
    /// The robot file (TOML; see configs/robot/robot.toml): which robot, its stack, body,
    /// sensors, field, guidance and devices.
    #[arg(long)]
    pub config: PathBuf,
    /// Record every message of the robot's Agora into this MCAP file (topics
    /// `/<prefix>/<type>`, the robot's clock), finished when the robot ends.
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// With --record: the topics' prefix, e.g. `home/1` (default: the robot's name in its
    /// devices, else `robot-<id>`). `home/k` and `away/k` are what the web monitor matches
    /// with the truth's robots.
    #[arg(long, value_name = "PREFIX", requires = "record")]
    pub record_as: Option<String>,
}

/// A Member added to a robot's Agora beside its own (`RemoteRobot::with_members`).
type Extra = Box<dyn mrt_dcdt::Member>;

impl RobotArgs {
    /// The recorder of `--record` (none without it) and the Members to add to the robot's
    /// Agora for it: its tap, recording under `--record-as` or `default`.
    pub(crate) fn recording(&self, default: &str) -> Result<(Option<SharedRecorder>, Vec<Extra>)> {
        let Some(path) = &self.record else { return Ok((None, Vec::new())) };
        let rec = Recorder::create(path)?.shared();
        let prefix = self.record_as.clone().unwrap_or_else(|| default.to_string());
        let tap: Extra = Box::new(Tap::new(prefix, rec.clone()));
        Ok((Some(rec), vec![tap]))
    }
}

/// Finishes the recording of `mrt robot --record`, and says what it holds.
pub(crate) fn finish_recording(rec: Option<SharedRecorder>, path: Option<&Path>) -> Result<()> {
    if let (Some(rec), Some(path)) = (rec, path) {
        let s = Recorder::finish_shared(rec)?;
        eprintln!(
            "recorded {} messages on {} topics into {}",
            s.messages,
            s.channels,
            path.display()
        );
    }
    Ok(())
}

/// `mrt robot --config FILE`: one robot's Agora on the devices its file names, until its
/// world ends the match.
pub fn robot(args: &RobotArgs) -> Result<()> {
    let started = Instant::now();
    let file = RobotFile::from_file(&args.config).map_err(|e| anyhow!("{e}"))?;
    if file.devices.kind != "world" {
        bail!(
            "{}: devices.kind = \"{}\": this mrt drives worlds of the device protocol \
             (kind = \"world\", docs/devices.md); a robot with its own hardware implements \
             mrt_robot::devices::Devices (see ARCHITECTURE.md)",
            args.config.display(),
            file.devices.kind.escape_debug()
        );
    }
    on_world(args, &file, started)
}

/// A robot that hears nothing from its world for this long gives up.
const SILENCE: Duration = Duration::from_secs(30);
/// How long a robot waits for its teammates to join the team's network.
const TEAM: Duration = Duration::from_secs(120);
/// What a robot writes to its log when it is ready to play.
pub(crate) const PHASES: &str = "phases: ";
/// What a robot writes to its log when it answers for the first time.
pub(crate) const FIRST_ANSWER: &str = "first answer ";
/// Messages from the world waiting for the robot (a lock-step world has one at a time).
const QUEUE: usize = 64;
/// zenoh's default multicast scouting group, where a world with no `connect` is found.
const SCOUTING: &str = "224.0.0.224:7446";

struct Port(RawPort);

impl WorldPort for Port {
    fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), mrt_robot::RobotError> {
        self.0.put(key, bytes).map_err(|e| mrt_robot::RobotError::World(e.to_string()))
    }
}

/// Runs the robot of `file` (read from `path`) on its world until the world's end. The vision
/// µAgent runs when `[vision] enabled` says so (a world that sends images needs it; one that
/// sends an object sensor's frames does not).
fn on_world(args: &RobotArgs, file: &RobotFile, started: Instant) -> Result<()> {
    let path = args.config.as_path();
    let here = path.parent().unwrap_or(Path::new("."));
    let at = |e: String| anyhow!("{}: {e}", path.display());
    let cfg = file.config().map_err(|e| at(e.to_string()))?;
    let spec = file.spec().map_err(|e| at(e.to_string()))?;
    let d = &file.devices;
    let world = d.world.as_deref().ok_or_else(|| at("devices.world is missing".into()))?;
    let name = d.name.clone().unwrap_or_else(|| format!("robot-{}", file.robot.id));
    let keys = Keys::new(world, &name).map_err(|e| at(format!("devices: {e}")))?;
    let net = d
        .net
        .as_ref()
        .map(|p| AgoraConfig::from_file(here.join(p)).map_err(|e| anyhow!("{e}")))
        .transpose()?;
    let behaviors = file.robot.behaviors.as_ref().map(|p| here.join(p));
    let dir = behaviors_dir(&[spec.stack], behaviors.as_deref()).map_err(|e| anyhow!("{e}"))?;
    let (rec, extra) = args.recording(&name)?;
    let mut remote = RemoteRobot::with_members(&cfg, spec, &dir, net.clone(), extra)
        .map_err(|e| anyhow!("{e}"))?;
    let linked = Instant::now();
    // The team's network, when there is one; without it no teammate is waited for.
    let _team = match (&net, remote.agora()) {
        (Some(_), Some(agora)) => {
            let link = mrt_net::connect(agora)?;
            // Ready once every teammate hears this robot's reports: the first report goes
            // out in the first step, and a report sent before a teammate listens is lost.
            let mates: Vec<AgoraId> = remote.mate_agoras().into_iter().map(AgoraId).collect();
            let heard = |l: &mrt_net::NetLink| {
                mates.iter().all(|m| l.subscribers(MateReport::TYPE).contains(m))
            };
            if !link.wait_until(TEAM, heard) {
                bail!(
                    "robot {name}: teammates {mates:?} not all on the team's network after \
                     {TEAM:?} (found: {:?})",
                    link.agoras()
                );
            }
            let online = link.presence();
            remote.set_presence(move |j| online.contains(AgoraId(j + 1)));
            Some(link)
        }
        _ => {
            remote.set_presence(|_| false);
            None
        }
    };
    let session = NetConfig {
        listen: Vec::new(),
        connect: d.connect.clone(),
        multicast: d.connect.is_empty().then(|| SCOUTING.to_string()),
        gossip: false,
        bridge: false,
    };
    let port = RawPort::open(&session)
        .with_context(|| format!("cannot open a zenoh session to world {world}"))?;
    let (tx, rx) = sync_channel(QUEUE);
    let full = Arc::new(AtomicBool::new(false));
    let mailer = |wrap: fn(Vec<u8>) -> WorldMail| {
        let (tx, full) = (tx.clone(), full.clone());
        move |_: &str, bytes: Vec<u8>| {
            if let Err(TrySendError::Full(_)) = tx.try_send(wrap(bytes)) {
                if !full.swap(true, Ordering::Relaxed) {
                    eprintln!("the world sends faster than the robot runs: messages dropped");
                }
            }
        }
    };
    let _senses = port.subscribe(&keys.sense(), mailer(WorldMail::Sense))?;
    let _end = port.subscribe(&keys.end(), mailer(WorldMail::End))?;
    // A world that holds its liveliness token and loses it is gone: end at once.
    let gone = tx.clone();
    let _world = port.watch_tokens(&keys.world_alive(), move |_, here| {
        if !here {
            let _ = gone.try_send(WorldMail::Gone);
        }
    })?;
    let _alive = port.declare_token(&keys.alive())?;
    eprintln!("robot {name}: listening to world {world} ({})", keys.sense());
    eprintln!(
        "robot {name}: {PHASES}behaviors loaded and linked {:.3} s, ready {:.3} s after start",
        (linked - started).as_secs_f64(),
        started.elapsed().as_secs_f64()
    );
    let robot = WorldRobot::new(remote, cfg.base, keys);
    let run =
        robot.run(&rx, &Port(port.clone()), SILENCE).map_err(|e| anyhow!("robot {name}: {e}"))?;
    if let (Some(f), Some(t)) = (run.robot.first_frame, run.robot.first_answer) {
        eprintln!(
            "robot {name}: {FIRST_ANSWER}{:.3} s after start (first frame {:.3} s)",
            (t - started).as_secs_f64(),
            (f - started).as_secs_f64()
        );
    }
    // Let the last word leave before the session closes.
    std::thread::sleep(Duration::from_millis(300));
    let dropped = serde_json::to_string(&run.bye.dropped).unwrap_or_default();
    eprintln!(
        "robot {name}: {} steps, teammates late in {}, {} Member faults; dropped {dropped}",
        run.robot.cycles,
        run.robot.late_mates,
        run.bye.faults.len(),
    );
    for f in &run.bye.faults {
        eprintln!("robot {name}: {} ×{}: {}", f.name, f.count, f.error.escape_debug());
    }
    finish_recording(rec, args.record.as_deref())
}
