//! `mrt sim --distributed`: the simulator in this process as a world of the device protocol
//! (docs/devices.md, `mrt_sim::remote`), each robot in a process of its own (`mrt robot
//! --config FILE`, the entry point that plays on MuJoCo or on a real robot's bridge, with a
//! robot file written for it), over zenoh on loopback.
//!
//! The robots run the same robot program as in one process (`mrt-robot`); only their devices
//! differ. Each team is a DCDT network of its own for the teammates' reports: for team `t`
//! this process writes one MRT-manual §3.3.1 file per robot into a temporary directory, with
//! the team's discovery port on the network line and static `ip link` lines to teammates, so
//! no robot depends on multicast and no robot hears the other team.

use crate::world::{FIRST_ANSWER, PHASES};
use anyhow::{anyhow, bail, Context as _, Result};
use mrt_net::{NetConfig, RawPort};
use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::game::MatchReport;
use mrt_sim::remote::{robot_name, Patience, PitchWorld, WorldPort, WORLD};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// How long robots may take to start (load behaviors, join the network).
const START: Duration = Duration::from_secs(120);

/// Picks the loopback ports of one match: free now, distinct, and outside the system's
/// ephemeral range. A port the system handed out for `:0` could be handed out again, to an
/// outgoing connection of another robot or another match, before the robot it was meant for
/// has started listening on it (the likely cause of a robot that once ended before a CI match,
/// its log lost in a backtrace); ports below the ephemeral range are taken only by name.
pub(crate) struct PortPicker {
    next: u32,
    low: u32,
    span: u32,
    taken: Vec<u16>,
}

impl PortPicker {
    /// Starts at a place that differs between processes, so two matches at once rarely
    /// probe the same ports.
    pub(crate) fn new() -> Self {
        let (low, high) = below_ephemeral();
        let span = high - low;
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let next = (std::process::id().wrapping_mul(2_654_435_761) ^ nanos) % span;
        Self { next, low, span, taken: Vec::new() }
    }

    /// The next port that both TCP and UDP can bind on loopback.
    pub(crate) fn port(&mut self) -> Result<u16> {
        for _ in 0..self.span {
            let port = (self.low + self.next % self.span) as u16;
            self.next = self.next.wrapping_add(1);
            let free = std::net::TcpListener::bind(("127.0.0.1", port)).is_ok()
                && std::net::UdpSocket::bind(("127.0.0.1", port)).is_ok();
            if free && !self.taken.contains(&port) {
                self.taken.push(port);
                return Ok(port);
            }
        }
        bail!("no free loopback port in {}..{}", self.low, self.low + self.span)
    }
}

/// Ports from 20000 up to the start of the ephemeral range (Linux's from
/// `/proc/sys/net/ipv4/ip_local_port_range`, 32768 by default; other systems start theirs at
/// 49152).
fn below_ephemeral() -> (u32, u32) {
    let first = std::fs::read_to_string("/proc/sys/net/ipv4/ip_local_port_range")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u32>().ok())
        .unwrap_or(32768);
    if first >= 21_000 {
        (20_000, first)
    } else {
        // An unusual range reaching below 21000: above it is what is left.
        (50_000, 60_000)
    }
}

/// The robot processes and their directory; killed and removed on drop.
pub(crate) struct Robots {
    pub(crate) dir: PathBuf,
    pub(crate) children: Vec<(usize, Child)>,
}

impl Robots {
    pub(crate) fn log(&self, robot: usize) -> PathBuf {
        self.dir.join(format!("robot-{robot}.log"))
    }

    /// A robot's log for error messages: from its `Error:` line if it has one (robots run
    /// without backtraces, but an error's causes follow it), else its last lines.
    pub(crate) fn tail(&self, robot: usize) -> String {
        let text = std::fs::read_to_string(self.log(robot)).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        let from = lines
            .iter()
            .rposition(|l| l.starts_with("Error:"))
            .unwrap_or(lines.len().saturating_sub(8));
        lines[from..lines.len().min(from + 12)].join("\n")
    }

    /// A robot process that ended already, with its status.
    pub(crate) fn exited(&mut self) -> Option<(usize, std::process::ExitStatus)> {
        self.children
            .iter_mut()
            .find_map(|(i, c)| c.try_wait().ok().flatten().map(|status| (*i, status)))
    }

    /// Waits up to `grace` for every robot to end by itself.
    pub(crate) fn wait(&mut self, grace: Duration) {
        let end = Instant::now() + grace;
        while Instant::now() < end
            && self.children.iter_mut().any(|(_, c)| matches!(c.try_wait(), Ok(None)))
        {
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

impl Drop for Robots {
    fn drop(&mut self) {
        for (_, c) in &mut self.children {
            let _ = c.kill();
            let _ = c.wait();
        }
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// The §3.3.1 file of robot `i` of the team of robots `team`: the team's discovery port and
/// a static link to every teammate (a full mesh on loopback, and on loopback with static links
/// only, mrt-net does not scout: no socket is bound beyond 127.0.0.1). Each end of a pair
/// connects to the other, so a robot that starts again reaches every teammate at once instead
/// of waiting for a teammate's next connection retry.
pub(crate) fn team_net_file(
    i: usize,
    team: std::ops::Range<usize>,
    discovery: u16,
    ports: &[u16],
) -> String {
    let mut text = format!(
        "# Robot {i}'s team network (written by mrt for its match).\n\
         127.0.0.1 224.0.0.224 {discovery}\n"
    );
    for j in team.filter(|&j| j != i) {
        text.push_str(&format!("ip link 0 127.0.0.1 {} 127.0.0.1 {}\n", ports[i], ports[j]));
    }
    text
}

/// The §3.3.1 file of a monitor joining a distributed match (`mrt topic`): static links from
/// `port` to every robot's port, on a discovery port of its own (no scouting on loopback).
fn monitor_net_file(port: u16, discovery: u16, ports: &[u16]) -> String {
    let mut text = format!(
        "# A monitor of a distributed match (written by mrt sim --distributed): mrt topic\n\
         # list|echo|hz --net THIS_FILE. Static links to every robot's Agora.\n\
         127.0.0.1 224.0.0.224 {discovery}\n"
    );
    for &p in ports {
        text.push_str(&format!("ip link 0 127.0.0.1 {port} 127.0.0.1 {p}\n"));
    }
    text
}

/// What the simulator puts, on its zenoh session.
struct Post(RawPort);

impl WorldPort for Post {
    fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), mrt_robot::RobotError> {
        self.0.put(key, bytes).map_err(|e| mrt_robot::RobotError::World(e.to_string()))
    }
}

/// Plays one match with every robot in a process of its own, the simulator a world of the
/// device protocol listening on loopback; `progress` gets the simulated time after each
/// cycle; `restart` kills a robot's process mid-match and starts it again.
pub fn play(
    cfg: &SimConfig,
    seed: u64,
    (home, away): (Stack, Stack),
    behaviors: Option<&Path>,
    record: bool,
    restart: Option<Restart>,
    progress: impl FnMut(f64),
) -> Result<(MatchReport, Option<Rejoined>)> {
    let n = cfg.rules.team_size;
    if let Some(r) = restart {
        if r.robot >= 2 * n {
            bail!("--restart-robot {}: a match has robots 0 to {}", r.robot, 2 * n - 1);
        }
    }
    let robots = 2 * n;
    mrt_robot::files::remove_orphans("distributed");
    let dir = std::env::temp_dir().join(format!("mrt-distributed-{}-{seed}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut procs = Robots { dir: dir.clone(), children: Vec::new() };
    let mut picker = PortPicker::new();
    let endpoint = format!("tcp/127.0.0.1:{}", picker.port()?);
    let ports = (0..robots).map(|_| picker.port()).collect::<Result<Vec<_>>>()?;
    // The simulator's side: a zenoh session listening for the robots, its mail, its world.
    let session = NetConfig {
        listen: vec![endpoint.clone()],
        connect: Vec::new(),
        multicast: None,
        gossip: false,
        bridge: false,
    };
    let port = RawPort::open(&session).context("cannot open the simulator's zenoh session")?;
    // Held while the simulator runs: its robots end as soon as it is gone.
    let _alive = port.declare_token(&mrt_devices::world_alive(WORLD))?;
    let (tx, mail) = std::sync::mpsc::channel();
    // The match's token: robots take only this run's `sense` and `end`, so a program on the
    // network that does not follow the match cannot guess what to forge.
    let run = {
        use std::hash::{BuildHasher, Hasher};
        let mut h = std::collections::hash_map::RandomState::new().build_hasher();
        h.write_u64(seed);
        h.write_u128(
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos()),
        );
        format!("{:016x}", h.finish())
    };
    let mut world = PitchWorld::new(
        cfg,
        seed,
        2,
        &run,
        Box::new(Post(port.clone())),
        mail,
        Patience::default(),
    )
    .map_err(|e| anyhow!("{e}"))?;
    world.record_frames(record);
    let _mail = world
        .subscriptions()
        .iter()
        .map(|keys| {
            let tx = Mutex::new(tx.clone());
            port.subscribe(keys, move |key, bytes| {
                if let Ok(tx) = tx.lock() {
                    let _ = tx.send((key.to_string(), bytes));
                }
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    drop(tx);
    // The robots on the network now, by their liveliness tokens; one whose token went away
    // (its process ended) is not waited for.
    let alive_keys: Vec<String> = world.robots().iter().map(|k| k.alive()).collect();
    let alive = Arc::new(Mutex::new(BTreeSet::new()));
    let presence = world.presence();
    let _tokens = {
        let (alive, keys) = (alive.clone(), alive_keys.clone());
        port.watch_tokens(&format!("mrt/devices/1/{WORLD}/*/alive"), move |key, here| {
            let Some(i) = keys.iter().position(|k| k == key) else { return };
            if let Ok(mut a) = alive.lock() {
                if here {
                    a.insert(i);
                } else {
                    a.remove(&i);
                    presence.mark_gone(i);
                }
            }
        })?
    };
    let mut files = Vec::new();
    for t in 0..2 {
        let discovery = picker.port()?;
        let stack = if t == 0 { home } else { away };
        for i in t * n..(t + 1) * n {
            let net = (n > 1).then(|| dir.join(format!("robot-{i}.cfg")));
            if let Some(net) = &net {
                std::fs::write(net, team_net_file(i, t * n..(t + 1) * n, discovery, &ports))?;
            }
            let file = dir.join(format!("robot-{i}.toml"));
            std::fs::write(
                &file,
                robot_file(cfg, i, stack, behaviors, &endpoint, net.as_deref())?,
            )?;
            files.push(file);
        }
    }
    // A network file for monitors (`mrt topic ... --net FILE`): static links to every robot.
    let monitor = dir.join("monitor.cfg");
    std::fs::write(&monitor, monitor_net_file(picker.port()?, picker.port()?, &ports))?;
    eprintln!("network of this match: {} (mrt topic list --net FILE)", monitor.display());
    let launch = Launch { exe: std::env::current_exe().context("cannot find the mrt executable")? };
    for (i, file) in files.iter().enumerate() {
        let child = launch.robot(i, file, &procs.log(i))?;
        procs.children.push((i, child));
    }
    // Every robot listens, and has its teammates on its team's network: the match can start.
    let start = Instant::now();
    while alive.lock().map_or(0, |a| a.len()) < robots {
        if let Some((i, status)) = procs.exited() {
            bail!("robot {i} ended before the match ({status}):\n{}", procs.tail(i));
        }
        if start.elapsed() > START {
            let ready = alive.lock().map(|a| a.clone()).unwrap_or_default();
            let missing = (0..robots).find(|i| !ready.contains(i)).unwrap_or(0);
            bail!(
                "robots {:?} were not ready after {START:?}; robot {missing}'s log:\n{}",
                (0..robots).filter(|i| !ready.contains(i)).collect::<Vec<_>>(),
                procs.tail(missing)
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let mut progress = progress;
    let mut restarted: Option<(Instant, PathBuf)> = None;
    let mut failed_restart = None;
    let presence = world.presence();
    let report = world
        .play(|t| {
            progress(t);
            let Some(r) = restart else { return };
            if restarted.is_some() || failed_restart.is_some() || t < r.at {
                return;
            }
            // Kill the robot's process and start it again at once, as a crash and a
            // supervisor's restart would.
            let log = procs.dir.join(format!("robot-{}.restart.log", r.robot));
            if let Some((_, c)) = procs.children.iter_mut().find(|(i, _)| *i == r.robot) {
                let _ = c.kill();
                let _ = c.wait();
            }
            presence.mark_gone(r.robot);
            match launch.robot(r.robot, &files[r.robot], &log) {
                Ok(child) => {
                    restarted = Some((Instant::now(), log));
                    procs.children.push((r.robot, child));
                }
                Err(e) => failed_restart = Some(e),
            }
        })
        .map_err(|e| anyhow!("{e}"))?;
    procs.wait(Duration::from_secs(5));
    if let Some(e) = failed_restart {
        return Err(e.context("cannot restart the robot"));
    }
    let rejoined = match (restart, restarted) {
        (Some(r), Some((_, log))) => {
            let text = std::fs::read_to_string(&log).unwrap_or_default();
            let after = text.lines().find_map(|l| {
                l.split_once(FIRST_ANSWER)
                    .and_then(|(_, rest)| rest.split_whitespace().next()?.parse().ok())
            });
            let phases: Vec<&str> = text
                .lines()
                .filter_map(|l| l.split_once(PHASES).or_else(|| l.split_once(FIRST_ANSWER)))
                .map(|(_, rest)| rest)
                .collect();
            let phases = phases.join("; ");
            Some(Rejoined {
                robot: r.robot,
                at: r.at,
                after: after.map(Duration::from_secs_f64),
                phases,
            })
        }
        _ => None,
    };
    Ok((report, rejoined))
}

/// How the robot processes are started (also again, mid-match): `mrt robot --config FILE`,
/// each with the robot file this match wrote for it.
pub(crate) struct Launch {
    pub(crate) exe: PathBuf,
}

impl Launch {
    pub(crate) fn robot(&self, i: usize, file: &Path, log: &Path) -> Result<Child> {
        self.robot_with(i, file, log, &[])
    }

    /// [`Launch::robot`] with more of `mrt robot`'s arguments (`--record FILE`).
    pub(crate) fn robot_with(
        &self,
        i: usize,
        file: &Path,
        log: &Path,
        more: &[std::ffi::OsString],
    ) -> Result<Child> {
        let log = std::fs::File::create(log)?;
        Command::new(&self.exe)
            .arg("robot")
            .arg("--config")
            .arg(file)
            .args(more)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log)
            // The log is for people: the error and its causes, not a backtrace.
            .env("RUST_BACKTRACE", "0")
            .env("RUST_LIB_BACKTRACE", "0")
            .spawn()
            .with_context(|| format!("cannot start robot {i}"))
    }
}

/// Robot `i`'s file in this match: the world's robot (`SimConfig::robot_file`), its stack,
/// the behaviors, its devices the simulator's at `endpoint`, its team's network `net` (none
/// for a team of one).
fn robot_file(
    cfg: &SimConfig,
    i: usize,
    stack: Stack,
    behaviors: Option<&Path>,
    endpoint: &str,
    net: Option<&Path>,
) -> Result<String> {
    let mut file = cfg.robot_file(i, stack.name());
    // The robot resolves relative paths against its file's directory: give it absolute ones.
    file.robot.behaviors = behaviors.map(std::path::absolute).transpose()?;
    file.devices.kind = "world".into();
    file.devices.world = Some(WORLD.into());
    file.devices.name = Some(robot_name(i, cfg.rules.team_size));
    file.devices.connect = vec![endpoint.into()];
    file.devices.net = net.map(Path::to_path_buf);
    let text = file.to_toml().map_err(|e| anyhow!("{e}"))?;
    Ok(format!("# Robot {i} of a distributed match (written by mrt sim --distributed).\n{text}"))
}

/// A robot process to kill and start again during the match.
#[derive(Clone, Copy, Debug)]
pub struct Restart {
    /// The robot.
    pub robot: usize,
    /// When, in simulated seconds from the kickoff.
    pub at: f64,
}

/// What became of the restarted robot.
#[derive(Clone, Debug)]
pub struct Rejoined {
    /// The robot.
    pub robot: usize,
    /// When it was killed and started again, simulated seconds.
    pub at: f64,
    /// From its start to its first answer to the simulator (`None`: it never answered).
    pub after: Option<Duration>,
    /// Where the time went, as the robot wrote it (`behaviors loaded and linked 0.2 s, ready 0.4 s after start`).
    pub phases: String,
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_dcdt::config::AgoraConfig;

    #[test]
    fn team_files_make_a_full_mesh_on_loopback() {
        let ports = [7000, 7001, 7002, 7003];
        let net = |i| {
            let text = team_net_file(i, 1..4, 9000, &ports);
            let cfg = AgoraConfig::parse(&text, "robot.cfg").unwrap();
            NetConfig::from_agora_config(&cfg).unwrap()
        };
        // Each robot links to every teammate, and to nobody of the other team.
        assert_eq!(net(3).connect, ["tcp/127.0.0.1:7001", "tcp/127.0.0.1:7002"]);
        assert!(net(3).listen.contains(&"tcp/127.0.0.1:7003".to_string()));
        assert_eq!(net(2).connect, ["tcp/127.0.0.1:7001", "tcp/127.0.0.1:7003"]);
        // Loopback only: no multicast scouting, whose sockets bind 0.0.0.0.
        assert_eq!(net(3).multicast, None);
        let n = net(2);
        assert!(n.listen.iter().chain(&n.connect).all(|e| e.starts_with("tcp/127.0.0.1:")));
    }
}
