//! The simulator as a world of the device protocol (docs/devices.md): the wiring of
//! `mrt sim --distributed`, where each robot runs in an executor (process, machine) of its own
//! as `mrt robot` does on any world, MuJoCo's included. There is one device link, not two.
//!
//! A robot runs exactly the robot program of `mrt-robot`
//! ([`WorldRobot`](mrt_robot::world::WorldRobot) around the Members of
//! [`add_robot`](mrt_robot::members::add_robot)). Each control cycle the simulator
//! ([`PitchWorld`]) puts one `sense` per robot (its odometry counts, camera frame, game
//! controller and sonar ring, read in that order as the drivers would), each robot runs one
//! cycle on it and answers with an `act` (its body twist, whether it kicked, its camera's pan,
//! the faults its fault book noted); when every robot answered, the simulator applies the
//! answers in robot order and runs the physics up to the next cycle. At the end each robot
//! closes its Members and sends their faults in its `bye`.
//!
//! **Same match as one process.** The readings travel bit for bit ([`mrt_devices::world`]),
//! and every robot senses the world of the cycle's start (kicks fire when the physics runs,
//! [`Pitch::kick`]), so the robots of a cycle may run in any order — but teammates' reports
//! must arrive as they do on one bus, where robot `i` hears in cycle `k` the reports its
//! lower-numbered teammates sent in cycle `k` and the others' of cycle `k − 1`.
//! [`RemoteRobot`](mrt_robot::remote::RemoteRobot) waits for exactly those reports before it
//! runs a cycle. With every robot answering in time the match is the single-process one, hash
//! for hash; a robot that stays silent (killed, far too slow) is booked, left standing while it
//! is silent, and waited for only briefly until it speaks again: from then on the matches
//! differ.
//!
//! The transport is the caller's: [`WorldPort`] for what the simulator puts, a channel of
//! `(key, bytes)` for what its robots put (zenoh in `mrt sim --distributed`). Teammates'
//! reports travel on each team's own DCDT network, as on a real field.

use crate::bus::book_fault;
use crate::config::SimConfig;
use crate::error::SimError;
use crate::game::{MatchReport, Pitch};
use crate::referee::Call;
use mrt_core::Twist;
use mrt_devices::messages::{Bye, End};
use mrt_devices::world::{self as wire, Answer, Answers};
use mrt_devices::{Act, Keys, Sense, PROTOCOL};
use mrt_msgs::MemberFault;
use mrt_robot::base::Base;
pub use mrt_robot::world::WorldPort;
use std::collections::BTreeMap;
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long the simulator waits for the robots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patience {
    /// For every robot's answer to a cycle (a robot that misses it is booked as silent).
    pub cycle: Duration,
    /// For a robot that was silent, in each later cycle until it answers again.
    pub silent: Duration,
    /// Before a step's `sense` is put again for a robot that has not answered it (a lost
    /// message).
    pub resend: Duration,
    /// For the robots' last words after the end.
    pub end: Duration,
}

impl Default for Patience {
    fn default() -> Self {
        Patience {
            cycle: Duration::from_secs(5),
            silent: Duration::from_millis(20),
            resend: Duration::from_secs(1),
            end: Duration::from_secs(5),
        }
    }
}

/// How long (world time, s) a robot's last answer holds: after that without a new one its
/// wheels stop (the device protocol's safe command).
pub const HOLD: f64 = 0.5;

/// The simulator's name in the device protocol's keys.
pub const WORLD: &str = "sim";

/// Robot `i`'s name in a match of `team_size` robots a side: `home-1` … `home-n`, then
/// `away-1` … (the names `mrt world mujoco` gives too).
pub fn robot_name(i: usize, team_size: usize) -> String {
    let n = team_size.max(1);
    format!("{}-{}", if i < n { "home" } else { "away" }, i % n + 1)
}

/// Which robots are known to be gone (their process ended, their link closed): the
/// simulator waits for their answers only as long as for a silent robot's
/// ([`Patience::silent`]) until they speak again. Shared with whoever
/// watches the robots (a supervisor, the network's liveliness), see [`PitchWorld::presence`].
#[derive(Clone, Debug)]
pub struct Presence(Arc<Vec<std::sync::atomic::AtomicBool>>);

impl Presence {
    fn new(robots: usize) -> Presence {
        Presence(Arc::new((0..robots).map(|_| std::sync::atomic::AtomicBool::new(false)).collect()))
    }

    /// Robot `i` is gone: its answers get the short patience until it answers again.
    pub fn mark_gone(&self, i: usize) {
        if let Some(g) = self.0.get(i) {
            g.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }

    /// Whether robot `i` is marked gone.
    pub fn is_gone(&self, i: usize) -> bool {
        self.0.get(i).is_some_and(|g| g.load(std::sync::atomic::Ordering::Relaxed))
    }

    fn back(&self, i: usize) {
        if let Some(g) = self.0.get(i) {
            g.store(false, std::sync::atomic::Ordering::Relaxed);
        }
    }
}

/// The simulator's side: the pitch as a world of the device protocol (module doc).
pub struct PitchWorld {
    pitch: Pitch,
    answers: Answers,
    post: Box<dyn WorldPort + Send>,
    mail: Receiver<(String, Vec<u8>)>,
    base: Base,
    period_ns: u64,
    cycle: u64,
    silent: Vec<bool>,
    /// The step each robot last answered.
    answered: Vec<Option<u64>>,
    patience: Patience,
    gone: Presence,
}

impl PitchWorld {
    /// A match from `seed` (`teams`: 2, or 1 for the home team alone on the field) in run
    /// `run` (an id of 1–64 of `a–z 0–9 - _`): senses go out through `post`, the robots'
    /// messages come in on `mail` as `(key, bytes)` (subscribe it to
    /// [`PitchWorld::subscriptions`]).
    pub fn new(
        cfg: &SimConfig,
        seed: u64,
        teams: usize,
        run: &str,
        post: Box<dyn WorldPort + Send>,
        mail: Receiver<(String, Vec<u8>)>,
        patience: Patience,
    ) -> Result<PitchWorld, SimError> {
        let n = cfg.rules.team_size;
        if !(1..=2).contains(&teams) {
            return Err(SimError::Match(format!("a match has one or two teams, not {teams}")));
        }
        let pitch = Pitch::new(cfg, seed, n, if teams == 2 { n } else { 0 })?;
        let base = Base::parse(&cfg.body.base)?;
        let robots = n * teams;
        let names: Vec<String> = (0..robots).map(|i| robot_name(i, n)).collect();
        let answers = Answers::new(WORLD, run, &names, base.wheels())?;
        let period_ns = (cfg.rules.control_period * 1e9).round() as u64;
        Ok(PitchWorld {
            pitch,
            answers,
            post,
            mail,
            base,
            period_ns,
            cycle: 0,
            silent: vec![false; robots],
            answered: vec![None; robots],
            patience,
            gone: Presence::new(robots),
        })
    }

    /// The key expressions of everything the robots send (their `act`s and `bye`s).
    pub fn subscriptions(&self) -> [String; 2] {
        self.answers.subscriptions()
    }

    /// The robots' keys, in robot order.
    pub fn robots(&self) -> &[Keys] {
        self.answers.robots()
    }

    /// The handle that marks robots gone (a robot's process ended): the simulator waits for
    /// them [`Patience::silent`] from the next cycle on, instead of [`Patience::cycle`] once.
    pub fn presence(&self) -> Presence {
        self.gone.clone()
    }

    /// Keeps one frame per control cycle for drawings.
    pub fn record_frames(&mut self, on: bool) {
        self.pitch.record_frames(on);
    }

    /// Whether the match is over.
    pub fn finished(&self) -> bool {
        self.pitch.finished()
    }

    /// Simulated time, s.
    pub fn time(&self) -> f64 {
        self.pitch.world().time()
    }

    /// Robot `i`'s `sense` of this cycle, read from the pitch as its drivers would read it.
    fn sense(&mut self, i: usize, time: f64) -> Result<Vec<u8>, SimError> {
        let counts = self.pitch.odometry_counts(i);
        let (camera, up_camera) = wire::camera(&self.pitch.camera(i));
        let game = wire::game(&self.pitch.game_info(i));
        let sonars = wire::sonars(&self.pitch.sonar(i));
        let keys = self.answers.keys(i).ok_or_else(|| SimError::Match(format!("no robot {i}")))?;
        let placed = counts.placed.map(|p| p.inner);
        let sense = Sense {
            protocol: PROTOCOL,
            world: WORLD.into(),
            run: self.run().into(),
            robot: keys.robot().into(),
            step: self.cycle,
            time,
            odometry: Some(wire::odometry(&counts.mice, Some(counts.wheel_turns), placed.as_ref())),
            camera: Some(camera),
            up_camera,
            sonars: Some(sonars),
            game,
        };
        Ok(serde_json::to_vec(&sense)?)
    }

    fn run(&self) -> &str {
        self.answers.run()
    }

    fn put_sense(&self, i: usize, bytes: &[u8]) -> Result<(), SimError> {
        let key = self
            .answers
            .keys(i)
            .map(Keys::sense)
            .ok_or_else(|| SimError::Match(format!("no robot {i}")))?;
        Ok(self.post.put(&key, bytes.to_vec())?)
    }

    /// One control cycle: every robot's sense out, every robot's answer in (or its silence
    /// booked), the answers applied in robot order, the physics up to the next cycle. Returns
    /// the referee's calls.
    pub fn cycle(&mut self) -> Result<Vec<Call>, SimError> {
        let k = self.cycle;
        // The clock of step k, as the robot's clock reads it back (to the nanosecond).
        let time = k.saturating_mul(self.period_ns) as f64 / 1e9;
        let senses =
            (0..self.silent.len()).map(|i| self.sense(i, time)).collect::<Result<Vec<_>, _>>()?;
        for (i, bytes) in senses.iter().enumerate() {
            self.put_sense(i, bytes)?;
        }
        let acts = self.gather(k, &senses)?;
        for (i, act) in acts.into_iter().enumerate() {
            let Some(act) = act else {
                if !self.silent[i] {
                    self.silent[i] = true;
                    self.pitch.fault(i, 1, &format!("robot process silent from cycle {k}"));
                }
                // The safe command: a robot without an answer for HOLD stands still.
                let since = self.answered[i].map_or(k.saturating_add(1), |a| k.saturating_sub(a));
                if since as f64 * self.period_ns as f64 / 1e9 > HOLD + 1e-9 {
                    self.pitch.drive(i, Twist::ZERO);
                }
                continue;
            };
            self.silent[i] = false;
            self.answered[i] = Some(k);
            self.gone.back(i);
            self.apply(i, &act);
        }
        self.cycle += 1;
        Ok(self.pitch.advance())
    }

    /// What robot `i` answered: its body's velocity (the twist its wheels give), its kick,
    /// its camera's pan, its faults.
    fn apply(&mut self, i: usize, act: &Act) {
        let twist = match (&act.twist, &act.wheels) {
            (Some(t), _) => Some(Ok(*t)),
            (None, Some(w)) => Some(self.base.twist_of(w).map_err(|e| e.to_string())),
            (None, None) => None,
        };
        match twist {
            Some(Ok(t)) => self.pitch.drive(i, t),
            Some(Err(e)) => self.pitch.fault(i, 1, &format!("motor driver: {e}")),
            None => {}
        }
        if act.kick {
            self.pitch.kick(i);
        }
        if let Some(pan) = act.pan {
            if let Err(e) = self.pitch.set_pan(i, pan) {
                self.pitch.fault(i, 1, &e.to_string());
            }
        }
        for f in &act.faults {
            self.pitch.fault(i, 1, f);
        }
    }

    /// Every robot's answer to step `k`, waiting as [`Patience`] says (and putting a sense
    /// again after [`Patience::resend`]).
    fn gather(&mut self, k: u64, senses: &[Vec<u8>]) -> Result<Vec<Option<Act>>, SimError> {
        let mut acts: Vec<Option<Act>> = vec![None; senses.len()];
        let start = Instant::now();
        let mut resent = vec![start; senses.len()];
        loop {
            let waited = start.elapsed();
            let missing: Vec<usize> = (0..acts.len()).filter(|&i| acts[i].is_none()).collect();
            // A robot silent before, or known gone, gets the short patience: a restarted
            // one is heard again as soon as it answers in time.
            let patience = |i: usize| {
                let short = self.silent[i] || self.gone.is_gone(i);
                if short {
                    self.patience.silent
                } else {
                    self.patience.cycle
                }
            };
            let Some(wake) = missing.iter().map(|&i| patience(i)).filter(|&p| waited < p).max()
            else {
                return Ok(acts);
            };
            for &i in &missing {
                if resent[i].elapsed() >= self.patience.resend && waited < patience(i) {
                    self.put_sense(i, &senses[i])?;
                    resent[i] = Instant::now();
                }
            }
            let left = wake.saturating_sub(waited).min(self.patience.resend);
            match self.mail.recv_timeout(left) {
                Ok((key, bytes)) => {
                    if let Some(Answer::Act(i, act)) = self.answers.take(&key, &bytes, Some(k)) {
                        acts[i] = Some(act);
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(SimError::Match("the robots' mail closed".into()))
                }
            }
        }
    }

    /// Ends the match, gathers the robots' last words and returns the report.
    pub fn finish(mut self) -> Result<MatchReport, SimError> {
        let end = End {
            protocol: PROTOCOL,
            world: WORLD.into(),
            run: self.run().into(),
            steps: self.cycle,
        };
        if let Some(key) = self.answers.keys(0).map(Keys::end) {
            let bytes = serde_json::to_vec(&end)?;
            self.post.put(&key, bytes)?;
        }
        let mut byes: BTreeMap<usize, Bye> = BTreeMap::new();
        let start = Instant::now();
        while byes.len() < self.silent.len() {
            let Some(left) = self.patience.end.checked_sub(start.elapsed()) else { break };
            match self.mail.recv_timeout(left) {
                Ok((key, bytes)) => {
                    if let Some(Answer::Bye(i, bye)) = self.answers.take(&key, &bytes, None) {
                        byes.insert(i, bye);
                    }
                }
                Err(RecvTimeoutError::Timeout) => break,
                Err(RecvTimeoutError::Disconnected) => break,
            }
        }
        for (i, bye) in &byes {
            for f in &bye.faults {
                let fault = MemberFault {
                    name: f.name.clone(),
                    count: f.count,
                    never_ran: f.never_ran,
                    error: f.error.clone(),
                };
                book_fault(&fault, &mut self.pitch, *i);
            }
        }
        for i in (0..self.silent.len()).filter(|i| !byes.contains_key(i)) {
            self.pitch.fault(i, 1, "robot process did not answer the end of the match");
        }
        let dropped = self.answers.dropped();
        if dropped.total() > 0 {
            tracing::warn!("the simulator dropped robots' messages it could not use: {dropped:?}");
        }
        Ok(self.pitch.report())
    }

    /// Plays until the end, calling `progress` with the simulated time after each cycle.
    pub fn play(mut self, mut progress: impl FnMut(f64)) -> Result<MatchReport, SimError> {
        while !self.finished() {
            self.cycle()?;
            progress(self.time());
        }
        self.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::BusMatch;
    use crate::config::short;
    use mrt_dcdt::{Agora, AgoraPort, MsgRef, MsgType, Outlet};
    use mrt_robot::remote::RemoteRobot;
    use mrt_robot::spec::RobotSpec;
    use mrt_robot::spec::Stack;
    use mrt_robot::world::{WorldMail, WorldRobot, WorldRun};
    use mrt_robot::RobotError;
    use std::path::Path;
    use std::sync::mpsc::{channel, Sender};
    use std::sync::Mutex;

    /// An in-process stand-in for one team's network: what an Agora shares goes to every other
    /// Agora of the net whose Members want its type from elsewhere (what mrt-net does over
    /// zenoh).
    #[derive(Clone, Default)]
    struct Net(Arc<Mutex<Vec<AgoraPort>>>);

    struct NetOutlet(Net, mrt_core::AgoraId);

    impl Outlet for NetOutlet {
        fn wants(&self, ty: MsgType) -> bool {
            let ports = self.0 .0.lock().unwrap();
            ports.iter().any(|p| p.id() != self.1 && p.remote_interest().contains(&ty))
        }
        fn send(&self, msg: &MsgRef) {
            let ports: Vec<AgoraPort> = self.0 .0.lock().unwrap().clone();
            for p in ports.iter().filter(|p| p.id() != self.1) {
                if p.remote_interest().contains(&msg.msg_type()) {
                    p.deliver(msg);
                }
            }
        }
    }

    impl Net {
        fn join(&self, agora: &Agora) {
            let port = agora.port();
            port.set_outlet(Some(Box::new(NetOutlet(self.clone(), port.id()))));
            self.0.lock().unwrap().push(port);
        }
    }

    /// An in-process stand-in for zenoh between the world and its robots: a put on a robot's
    /// sense key (or the world's end key) reaches that robot (all robots), a robot's put
    /// reaches the world.
    #[derive(Clone, Default)]
    struct Hub(Arc<Mutex<Vec<Robot>>>);

    /// A robot's keys and its mailbox.
    type Robot = (Keys, Sender<WorldMail>);

    impl WorldPort for Hub {
        fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), RobotError> {
            for (keys, tx) in self.0.lock().unwrap().iter() {
                if keys.sense() == key {
                    let _ = tx.send(WorldMail::Sense(bytes.clone()));
                } else if keys.end() == key {
                    let _ = tx.send(WorldMail::End(bytes.clone()));
                }
            }
            Ok(())
        }
    }

    /// What a robot puts, to the world.
    struct ToWorld(Sender<(String, Vec<u8>)>);

    impl WorldPort for ToWorld {
        fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), RobotError> {
            self.0.send((key.to_string(), bytes)).map_err(|e| RobotError::World(e.to_string()))
        }
    }

    struct Field {
        nets: [Net; 2],
        hub: Hub,
        to_world: Sender<(String, Vec<u8>)>,
    }

    /// The simulator of a match, each team on a network of its own.
    fn pitch(cfg: &SimConfig, seed: u64, patience: Patience) -> (Field, PitchWorld) {
        let (to_world, mail) = channel();
        let hub = Hub::default();
        let world =
            PitchWorld::new(cfg, seed, 2, "test-run", Box::new(hub.clone()), mail, patience)
                .unwrap();
        (Field { nets: Default::default(), hub, to_world }, world)
    }

    /// A robot on its team's network, running (until the end or `silence`) on a thread.
    fn start_robot(
        cfg: &SimConfig,
        field: &Field,
        spec: RobotSpec,
        behaviors: &Path,
        silence: Duration,
    ) -> std::thread::JoinHandle<Result<WorldRun, RobotError>> {
        let n = cfg.rules.team_size;
        let team = spec.robot / n.max(1);
        let robot_cfg = cfg.robot().unwrap();
        let remote = RemoteRobot::new(&robot_cfg, spec, behaviors, None).unwrap();
        field.nets[team].join(remote.agora().unwrap());
        let keys = Keys::new(WORLD, &robot_name(spec.robot, n)).unwrap();
        let (tx, rx) = channel();
        field.hub.0.lock().unwrap().push((keys.clone(), tx));
        let robot = WorldRobot::new(remote, robot_cfg.base, keys);
        let port = ToWorld(field.to_world.clone());
        std::thread::spawn(move || robot.run(&rx, &port, silence))
    }

    /// Patience for tests where robots stay silent: 200 ms a cycle, 300 ms for last words.
    fn short_patience() -> Patience {
        let patience = Patience { cycle: Duration::from_millis(200), ..Patience::default() };
        Patience { end: Duration::from_millis(300), ..patience }
    }

    /// The simulator and each robot in executors of their own (threads here, processes in
    /// `mrt sim --distributed`), each team on a network of its own, the devices over the
    /// device protocol: the same match as one bus, hash for hash, teammates' reports included.
    #[test]
    fn robots_on_the_device_protocol_play_the_single_process_match() {
        let cfg = short(6.0, 3);
        let stacks = (Stack::Chaos, Stack::Milan);
        let dir = mrt_robot::members::behaviors_dir(&[Stack::Chaos], None).unwrap();
        let (field, world) = pitch(&cfg, 5, Patience::default());
        let robots: Vec<_> = (0..6)
            .map(|i| {
                let spec = RobotSpec::of(i, 3, stacks);
                start_robot(&cfg, &field, spec, &dir, Duration::from_secs(20))
            })
            .collect();
        let distributed = world.play(|_| {}).unwrap();
        let runs: Vec<WorldRun> = robots.into_iter().map(|h| h.join().unwrap().unwrap()).collect();
        assert!(runs.iter().all(|r| r.robot.cycles == 120 && r.robot.late_mates == 0), "{runs:?}");
        assert!(runs.iter().all(|r| r.bye.dropped.total() == 0), "{runs:?}");
        let bus =
            BusMatch::new(&cfg, 5, stacks.0, Some(stacks.1), None).unwrap().play(|_| {}).unwrap();
        // The play's statistics; what the robots believed (booking, roles) is watched on the
        // single bus only.
        let play = |r: &crate::game::MatchReport| {
            r.stats
                .iter()
                .map(|s| (s.goals, s.shots, s.shots_on_target, s.possession_cycles))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            (distributed.score, distributed.trajectory_hash, play(&distributed)),
            (bus.score, bus.trajectory_hash, play(&bus))
        );
        assert!(distributed.faults.is_empty(), "{:?}", distributed.faults);
    }

    /// With rendered images (`[sensor] percepts = "vision"`) the frames carry the images, each
    /// robot's vision reads them, and the match is still the one of a single bus.
    #[test]
    fn rendered_images_travel_too() {
        let mut cfg = short(2.0, 1);
        cfg.sensor.percepts = crate::config::PerceptSource::Vision;
        let stacks = (Stack::Milan, Stack::Chaser);
        let (field, world) = pitch(&cfg, 9, Patience::default());
        let robots: Vec<_> = (0..2)
            .map(|i| {
                let spec = RobotSpec::of(i, 1, stacks);
                start_robot(&cfg, &field, spec, Path::new(""), Duration::from_secs(20))
            })
            .collect();
        let distributed = world.play(|_| {}).unwrap();
        for h in robots {
            assert_eq!(h.join().unwrap().unwrap().robot.cycles, 40);
        }
        let bus =
            BusMatch::new(&cfg, 9, stacks.0, Some(stacks.1), None).unwrap().play(|_| {}).unwrap();
        assert_eq!(distributed.trajectory_hash, bus.trajectory_hash);
    }

    /// A robot that never answers is booked once and the match goes on without waiting for it
    /// every cycle; the others play on and hear the end.
    #[test]
    fn a_silent_robot_is_booked_and_the_match_goes_on() {
        let cfg = short(2.0, 1);
        let (field, world) = pitch(&cfg, 1, short_patience());
        // Only the home robot runs.
        let spec = RobotSpec::of(0, 1, (Stack::Chaser, Stack::Chaser));
        let home = start_robot(&cfg, &field, spec, Path::new(""), Duration::from_secs(20));
        let started = Instant::now();
        let report = world.play(|_| {}).unwrap();
        assert!(started.elapsed() < Duration::from_secs(10), "not 200 ms every cycle");
        assert_eq!(home.join().unwrap().unwrap().robot.cycles, 40);
        assert_eq!(report.faults.len(), 1, "{:?}", report.faults);
        assert_eq!(report.faults[0].robot, 1);
        assert!(report.faults[0].message.contains("silent from cycle 0"), "{:?}", report.faults);
        assert!((report.duration - 4.0).abs() < 0.011);
    }

    /// A robot whose teammate never runs waits for its reports once, then plays every cycle
    /// without it and hears the end.
    #[test]
    fn a_teammate_that_never_speaks_is_not_waited_for_and_the_end_is_heard() {
        let cfg = short(0.5, 2);
        let patience = Patience { cycle: Duration::from_secs(3), ..short_patience() };
        let (field, world) = pitch(&cfg, 1, patience);
        let spec = RobotSpec::of(0, 2, (Stack::Chaser, Stack::Chaser));
        let home = start_robot(&cfg, &field, spec, Path::new(""), Duration::from_secs(5));
        world.play(|_| {}).unwrap();
        let run = home.join().unwrap().expect("the robot heard the end");
        // Late in cycle 1 (its teammate's report of cycle 0 never came), never again.
        assert_eq!((run.robot.cycles, run.robot.late_mates), (10, 1), "{run:?}");
    }

    /// A robot's last answer holds for half a second of world time; after that without an
    /// answer its wheels stop (the protocol's safe command).
    #[test]
    fn a_robot_without_an_answer_for_half_a_second_stands_still() {
        let cfg = short(5.0, 1);
        let (field, mut world) =
            pitch(&cfg, 1, Patience { cycle: Duration::from_millis(50), ..short_patience() });
        let key = world.robots()[0].act();
        let drive = |w: &PitchWorld| w.pitch.world().drive_setpoint(0).vx;
        // Answer every step with a drive forward until the referee lets the robots move.
        let mut k = 0;
        while drive(&world) == 0.0 {
            assert!(k < 100, "the robot never moved");
            let mut act = act_of("home-1", k);
            act.twist = Some(Twist::new(0.5, 0.0, 0.0));
            field.to_world.send((key.clone(), serde_json::to_vec(&act).unwrap())).unwrap();
            world.cycle().unwrap();
            k += 1;
        }
        // Silent: 0.5 s (five cycles) on the last set-point, then still.
        for _ in 0..5 {
            world.cycle().unwrap();
            assert_eq!(drive(&world), 0.5);
        }
        world.cycle().unwrap();
        assert_eq!(drive(&world), 0.0);
    }

    fn act_of(robot: &str, step: u64) -> Act {
        Act {
            protocol: PROTOCOL,
            world: WORLD.into(),
            run: "test-run".into(),
            robot: robot.into(),
            step,
            ..Act::default()
        }
    }

    /// What a robot sends that the world cannot use is counted and dropped; its last good
    /// answer holds and nothing stops the match.
    #[test]
    fn robots_messages_the_world_cannot_use_are_dropped() {
        let cfg = short(0.3, 1);
        let (field, mut world) = pitch(&cfg, 1, short_patience());
        let act_key = world.robots()[0].act();
        for bytes in [&b"{oops"[..], br#"{"protocol": 7}"#, &[0xff; 64][..]] {
            field.to_world.send((act_key.clone(), bytes.to_vec())).unwrap();
        }
        field.to_world.send(("mrt/devices/1/sim/nobody/act".into(), b"{}".to_vec())).unwrap();
        while !world.finished() {
            world.cycle().unwrap();
        }
        let dropped = world.answers.dropped();
        assert_eq!((dropped.malformed, dropped.protocol, dropped.stranger), (2, 1, 1));
        let report = world.finish().unwrap();
        assert_eq!(report.faults.len(), 2, "both robots silent: {:?}", report.faults);
    }
}
