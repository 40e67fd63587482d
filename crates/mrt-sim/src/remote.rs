//! The simulator and its robots in separate executors (processes, or machines) that talk over
//! the bus: the distributed wiring of `mrt sim --distributed`.
//!
//! A robot runs exactly the robot program of `mrt-robot` ([`add_robot`](mrt_robot::members::add_robot));
//! only its devices differ: [`LinkedDevices`](mrt_robot::devices::LinkedDevices) instead of the
//! pitch. The simulator ([`PitchServer`]) publishes one
//! [`DeviceFrame`] per robot and control cycle (its odometry, camera frame and sonar ring, read
//! in that order as the drivers would), each robot ([`RemoteRobot`](mrt_robot::remote::RemoteRobot)) runs one cycle on it and
//! answers with a [`DeviceAct`] (the duty cycles its motor driver set, whether it kicked, the
//! faults its fault book noted); when every robot answered, the simulator applies them in robot
//! order and runs the physics up to the next cycle. At the final whistle ([`FinalWhistle`])
//! each robot closes its Members and sends their faults ([`RobotEnd`]).
//!
//! **Same match as one process.** Every robot senses the world of the cycle's start (kicks
//! fire when the physics runs, [`Pitch::kick`]), so the robots of a cycle may run in any order
//! — but teammates' reports must arrive as they do on one bus, where robot `i` hears in cycle
//! `k` the reports its lower-numbered teammates sent in cycle `k` and the others' of cycle
//! `k − 1`. A `RemoteRobot` waits for exactly those reports (by their creation time) before it
//! runs a cycle. With every robot answering in time the match is the single-process one, hash
//! for hash; a robot that stays silent (killed, far too slow) is booked, left standing while it
//! is silent, and not waited for again until it speaks: from then on the matches differ.
//!
//! The network is not here: each team's Agora of the simulator and each robot's Agora are
//! given a link by the caller (`mrt-net` over zenoh in `mrt sim --distributed`). Each team is a
//! network of its own, as on a real field, so a robot never hears the other team.

use crate::bus::book_fault;
use crate::config::SimConfig;
use crate::game::{MatchReport, Pitch};
use crate::referee::Call;
use mrt_dcdt::{Agora, DeliveryWarranty, Endpoint, RequestType};
use mrt_robot::base::Base;
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

pub use mrt_msgs::{DeviceAct, DeviceFrame, FinalWhistle, RobotEnd};

/// How long the simulator waits for the robots.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patience {
    /// For every robot's answer to a cycle (a robot that misses it is booked as silent).
    pub cycle: Duration,
    /// For a robot that was silent, in each later cycle until it answers again.
    pub silent: Duration,
    /// For the robots' last words after the final whistle.
    pub end: Duration,
}

impl Default for Patience {
    fn default() -> Self {
        Patience {
            cycle: Duration::from_secs(5),
            silent: Duration::from_millis(20),
            end: Duration::from_secs(5),
        }
    }
}

/// The simulator's side: the pitch, and one endpoint on each team's Agora (module doc).
pub struct PitchServer {
    pitch: Arc<Mutex<Pitch>>,
    /// One per team (home, away), with the team's Agora kept alive.
    teams: Vec<(Agora, Endpoint)>,
    base: Base,
    robots: usize,
    team_size: usize,
    cycle: u64,
    silent: Vec<bool>,
    patience: Patience,
    gone: Presence,
}

/// Which robots are known to be gone (their process ended, their link closed): the
/// simulator waits for their answers only as long as for a silent robot's
/// ([`Patience::silent`]) until they speak again. Shared with whoever
/// watches the robots (a supervisor, the network's liveliness), see [`PitchServer::presence`].
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

fn lock(p: &Arc<Mutex<Pitch>>) -> Result<std::sync::MutexGuard<'_, Pitch>, String> {
    p.lock().map_err(|_| "the pitch lock is poisoned".to_string())
}

fn robot_index(id: u32) -> usize {
    usize::try_from(id).unwrap_or(usize::MAX)
}

impl PitchServer {
    /// A match from `seed` whose robots are reached through `teams`' Agoras (home, then away;
    /// one Agora only: home alone on the field). Each Agora must be linked to the network of
    /// its team's robots by the caller.
    pub fn new(
        cfg: &SimConfig,
        seed: u64,
        teams: Vec<Agora>,
        patience: Patience,
    ) -> Result<PitchServer, String> {
        let n = cfg.rules.team_size;
        if teams.is_empty() || teams.len() > 2 {
            return Err(format!("a match has one or two teams, not {}", teams.len()));
        }
        let pitch = Pitch::new(cfg, seed, n, if teams.len() == 2 { n } else { 0 })?;
        let base = Base::parse(&cfg.robot.base)?;
        let pitch = Arc::new(Mutex::new(pitch));
        let robots = n * teams.len();
        let teams = teams
            .into_iter()
            .map(|mut agora| {
                let ep = agora.endpoint();
                ep.subscribe_to::<DeviceAct>(RequestType::Remote);
                ep.subscribe_to::<RobotEnd>(RequestType::Remote);
                (agora, ep)
            })
            .collect();
        Ok(PitchServer {
            pitch,
            teams,
            base,
            robots,
            team_size: n,
            cycle: 0,
            silent: vec![false; robots],
            patience,
            gone: Presence::new(robots),
        })
    }

    /// The handle that marks robots gone (a robot's process ended): the simulator waits for
    /// them [`Patience::silent`] from the next cycle on, instead of [`Patience::cycle`] once.
    pub fn presence(&self) -> Presence {
        self.gone.clone()
    }

    /// The robots of the match.
    pub fn robots(&self) -> usize {
        self.robots
    }

    /// Keeps one frame per control cycle for drawings.
    pub fn record_frames(&mut self, on: bool) {
        if let Ok(mut p) = self.pitch.lock() {
            p.record_frames(on);
        }
    }

    /// Whether the match is over.
    pub fn finished(&self) -> Result<bool, String> {
        Ok(lock(&self.pitch)?.finished())
    }

    /// Simulated time, s.
    pub fn time(&self) -> Result<f64, String> {
        Ok(lock(&self.pitch)?.world().time())
    }

    fn team_of(&self, robot: usize) -> usize {
        robot / self.team_size.max(1)
    }

    /// One control cycle: every robot's frame out, every robot's answer in (or its silence
    /// booked), the answers applied in robot order, the physics up to the next cycle. Returns
    /// the referee's calls.
    pub fn cycle(&mut self) -> Result<Vec<Call>, String> {
        let k = self.cycle;
        {
            let not_awaited: Vec<u32> = (0..self.robots())
                .filter(|&i| self.silent[i] || self.gone.is_gone(i))
                .filter_map(|i| u32::try_from(i).ok())
                .collect();
            let mut pitch = lock(&self.pitch)?;
            for i in 0..self.robots() {
                let frame = DeviceFrame {
                    robot: u32::try_from(i).map_err(|e| e.to_string())?,
                    cycle: k,
                    odometry: pitch.odometry(i),
                    camera: pitch.camera(i),
                    game: pitch.game_info(i),
                    sonars: pitch.sonar(i),
                    not_awaited: not_awaited.clone(),
                };
                let (_, ep) = &self.teams[self.team_of(i)];
                ep.publish_with(frame, DeliveryWarranty::Reliable, 128);
            }
        }
        let acts = self.gather(k)?;
        let mut pitch = lock(&self.pitch)?;
        for (i, act) in acts.into_iter().enumerate() {
            let Some(act) = act else {
                if !self.silent[i] {
                    self.silent[i] = true;
                    pitch.fault(i, 1, &format!("robot process silent from cycle {k}"));
                }
                continue;
            };
            self.silent[i] = false;
            self.gone.back(i);
            if let Some(duty) = &act.duty {
                // What the robot's SimulatedAirboard does in one process.
                match self.base.twist_for(duty) {
                    Ok(twist) => pitch.drive(i, twist.into()),
                    Err(e) => pitch.fault(i, 1, &format!("motor driver: {e}")),
                }
            }
            if act.kick {
                pitch.kick(i);
            }
            if let Some(pan) = act.pan {
                if let Err(e) = pitch.set_pan(i, pan) {
                    pitch.fault(i, 1, &e);
                }
            }
            for f in &act.faults {
                pitch.fault(i, 1, f);
            }
        }
        self.cycle += 1;
        Ok(pitch.advance())
    }

    /// Every robot's answer to cycle `k`, waiting as [`Patience`] says.
    fn gather(&mut self, k: u64) -> Result<Vec<Option<DeviceAct>>, String> {
        let mut acts: Vec<Option<DeviceAct>> = vec![None; self.robots()];
        let start = Instant::now();
        loop {
            for (_, ep) in &mut self.teams {
                while let Some(m) = ep.receive_msg() {
                    let Ok(act) = m.get::<DeviceAct>() else { continue };
                    let i = robot_index(act.robot);
                    if act.cycle == k && i < acts.len() {
                        acts[i] = Some(act.clone());
                    }
                }
            }
            let waited = start.elapsed();
            let missing: Vec<usize> = (0..acts.len()).filter(|&i| acts[i].is_none()).collect();
            // A robot silent before, or known gone, gets the short patience: a restarted
            // one is heard again as soon as it answers in time.
            let patient = |i: &usize| {
                let short = self.silent[*i] || self.gone.is_gone(*i);
                waited < if short { self.patience.silent } else { self.patience.cycle }
            };
            if !missing.iter().any(patient) {
                return Ok(acts);
            }
            // Wait on the team of the first robot still awaited.
            let (_, ep) = &self.teams[self.team_of(missing[0])];
            ep.wait_msg(Duration::from_millis(2));
        }
    }

    /// Blows the final whistle, gathers the robots' last words and returns the report.
    pub fn finish(mut self) -> Result<MatchReport, String> {
        let whistle = FinalWhistle { cycles: self.cycle };
        for (_, ep) in &self.teams {
            ep.publish_with(whistle, DeliveryWarranty::Reliable, 128);
        }
        let mut ends: BTreeMap<usize, RobotEnd> = BTreeMap::new();
        let start = Instant::now();
        while ends.len() < self.robots() && start.elapsed() < self.patience.end {
            for (_, ep) in &mut self.teams {
                while let Some(m) = ep.receive_msg() {
                    if let Ok(end) = m.get::<RobotEnd>() {
                        ends.insert(robot_index(end.robot), end.clone());
                    }
                }
            }
            if let Some((_, ep)) = self.teams.first() {
                ep.wait_msg(Duration::from_millis(5));
            }
        }
        let mut pitch = lock(&self.pitch)?;
        for (i, end) in &ends {
            for f in &end.faults {
                book_fault(f, &mut pitch, *i);
            }
        }
        for i in (0..self.silent.len()).filter(|i| !ends.contains_key(i)) {
            pitch.fault(i, 1, "robot process did not answer the final whistle");
        }
        drop(pitch);
        let pitch = Arc::try_unwrap(self.pitch).map_err(|_| "the pitch is still shared")?;
        Ok(pitch.into_inner().map_err(|_| "the pitch lock is poisoned")?.report())
    }

    /// Plays until the end, calling `progress` with the simulated time after each cycle.
    pub fn play(mut self, mut progress: impl FnMut(f64)) -> Result<MatchReport, String> {
        while !self.finished()? {
            self.cycle()?;
            progress(self.time()?);
        }
        self.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bus::BusMatch;
    use crate::config::short;
    use mrt_dcdt::{AgoraPort, MsgRef, MsgType, Outlet};
    use mrt_robot::members::RobotSpec;
    use mrt_robot::remote::RemoteRobot;
    use mrt_robot::remote::RobotRun;
    use mrt_robot::stacks::Stack;
    use std::path::Path;

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

    /// The simulator of a match, each team on a network of its own.
    fn pitch(cfg: &SimConfig, seed: u64, patience: Patience) -> ([Net; 2], PitchServer) {
        let nets = [Net::default(), Net::default()];
        let mut teams = Vec::new();
        for (t, net) in nets.iter().enumerate() {
            let agora = Agora::builder(200 + t as u32).build().unwrap();
            net.join(&agora);
            teams.push(agora);
        }
        (nets, PitchServer::new(cfg, seed, teams, patience).unwrap())
    }

    /// A robot on its team's network, running (until the whistle or `silence`) on a thread.
    fn start_robot(
        cfg: &SimConfig,
        nets: &[Net; 2],
        spec: RobotSpec,
        behaviors: &Path,
        silence: Duration,
    ) -> std::thread::JoinHandle<Result<RobotRun, String>> {
        let team = spec.robot / cfg.rules.team_size.max(1);
        let robot = RemoteRobot::new(&cfg.robot().unwrap(), spec, behaviors, None).unwrap();
        nets[team].join(robot.agora().unwrap());
        robot.open();
        std::thread::spawn(move || robot.run(silence))
    }

    /// Patience for tests where robots stay silent: 200 ms a cycle, 300 ms for last words.
    fn short_patience() -> Patience {
        let patience = Patience { cycle: Duration::from_millis(200), ..Patience::default() };
        Patience { end: Duration::from_millis(300), ..patience }
    }

    /// The simulator and each robot in executors of their own (threads here, processes in
    /// `mrt sim --distributed`), each team on a network of its own: the same match as one bus,
    /// hash for hash, teammates' reports included.
    #[test]
    fn robots_in_their_own_executors_play_the_single_process_match() {
        let cfg = short(6.0, 3);
        let stacks = (Stack::Chaos, Stack::Milan);
        let dir = mrt_robot::members::behaviors_dir(&[Stack::Chaos], None).unwrap();
        let (nets, server) = pitch(&cfg, 5, Patience::default());
        let robots: Vec<_> = (0..6)
            .map(|i| {
                start_robot(&cfg, &nets, RobotSpec::of(i, 3, stacks), &dir, Duration::from_secs(20))
            })
            .collect();
        let distributed = server.play(|_| {}).unwrap();
        let runs: Vec<RobotRun> = robots.into_iter().map(|h| h.join().unwrap().unwrap()).collect();
        assert!(runs.iter().all(|r| r.cycles == 120 && r.late_mates == 0), "{runs:?}");
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

    /// A robot that never answers is booked once and the match goes on without waiting for it
    /// every cycle; the others play on.
    #[test]
    fn a_silent_robot_is_booked_and_the_match_goes_on() {
        let cfg = short(2.0, 1);
        let (nets, server) = pitch(&cfg, 1, short_patience());
        // Only the home robot runs.
        let spec = RobotSpec::of(0, 1, (Stack::Chaser, Stack::Chaser));
        let home = start_robot(&cfg, &nets, spec, Path::new(""), Duration::from_secs(20));
        let started = Instant::now();
        let report = server.play(|_| {}).unwrap();
        assert!(started.elapsed() < Duration::from_secs(10), "not 200 ms every cycle");
        assert_eq!(home.join().unwrap().unwrap().cycles, 40);
        assert_eq!(report.faults.len(), 1, "{:?}", report.faults);
        assert_eq!(report.faults[0].robot, 1);
        assert!(report.faults[0].message.contains("silent from cycle 0"), "{:?}", report.faults);
        assert!((report.duration - 4.0).abs() < 0.011);
    }

    /// What comes while a robot waits for a late teammate (the simulator stopped waiting for
    /// this robot's answer and went on) is kept for the next round, not lost: here the whole
    /// match ends while robot 0 waits for its silent teammate, and it still hears the whistle.
    #[test]
    fn a_teammate_the_simulator_gave_up_on_is_not_waited_for_and_the_whistle_is_heard() {
        let cfg = short(0.5, 2);
        let (nets, server) = pitch(&cfg, 1, short_patience());
        // Robot 0 runs, its teammate robot 1 never does. The simulator books robot 1 silent in
        // cycle 0 and says so in every frame after: robot 0 does not wait for its reports
        // either (it waited 2 s from cycle 1 on, long past this 10-cycle match), plays every
        // cycle and hears the final whistle.
        let spec = RobotSpec::of(0, 2, (Stack::Chaser, Stack::Chaser));
        let home = start_robot(&cfg, &nets, spec, Path::new(""), Duration::from_secs(3));
        server.play(|_| {}).unwrap();
        let run = home.join().unwrap().expect("the robot heard the final whistle");
        assert_eq!((run.cycles, run.late_mates), (10, 0), "{run:?}");
    }
}
