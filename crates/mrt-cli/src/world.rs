//! `mrt robot --config FILE` with `[devices] kind = "world"`: the robot program on the
//! devices of a world that speaks the device protocol over zenoh (docs/devices.md).

use crate::distributed::RobotArgs;
use anyhow::{anyhow, bail, Context as _, Result};
use mrt_core::AgoraId;
use mrt_dcdt::config::AgoraConfig;
use mrt_dcdt::Message as _;
use mrt_devices::Keys;
use mrt_msgs::MateReport;
use mrt_net::{NetConfig, RawPort};
use mrt_robot::config::RobotFile;
use mrt_robot::members::behaviors_dir;
use mrt_robot::remote::RemoteRobot;
use mrt_robot::world::{WorldMail, WorldPort, WorldRobot};
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{sync_channel, TrySendError};
use std::sync::Arc;
use std::time::{Duration, Instant};

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
pub fn robot(args: &RobotArgs, file: &RobotFile, started: Instant) -> Result<()> {
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
    crate::distributed::finish_recording(rec, args.record.as_deref())
}
