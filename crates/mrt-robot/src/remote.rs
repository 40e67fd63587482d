//! The robot program on devices that are loaded from outside each cycle: one robot's Agora
//! with the Members of [`add_robot`] on [`LinkedDevices`], run one cycle per step its world
//! sends ([`RemoteRobot::cycle`]; the device protocol's robot, [`crate::world::WorldRobot`],
//! drives it).
//!
//! **Same match as one process.** Teammates' reports must arrive as they do on one bus, where
//! robot `i` hears in cycle `k` the reports its lower-numbered teammates sent in cycle `k` and
//! the others' of cycle `k − 1`. A [`RemoteRobot`] waits for exactly those reports (by their
//! creation time) before it runs a cycle. A teammate that stays silent (killed, far too slow)
//! or leaves the team's network is not waited for again until it speaks. The simulator's
//! side is `mrt_sim::remote::PitchWorld`.

use crate::config::RobotConfig;
use crate::devices::{Actuation, LinkedDevices, Loaded};
use crate::error::RobotError;
use crate::members::{add_robot, member_faults};
use crate::spec::RobotSpec;
use mrt_core::{SimClock, Time};
use mrt_dcdt::config::AgoraConfig;
use mrt_dcdt::{
    Activation, Agora, Endpoint, InnerLinkManager, Member, RequestType, SteppedExecutor,
};
use mrt_msgs::{MateReport, MemberFault};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

fn robot_index(id: u32) -> usize {
    usize::try_from(id).unwrap_or(usize::MAX)
}

/// One robot on devices loaded each cycle: its Agora with the Members of [`add_robot`] on a
/// [`SteppedExecutor`], and the runner's own endpoint for teammates' reports (module doc).
pub struct RemoteRobot {
    spec: RobotSpec,
    exec: SteppedExecutor,
    devices: Arc<Mutex<LinkedDevices>>,
    /// On a second Agora of the robot's in-process community, joined after the robot's:
    /// a teammate's report reaches the robot's Members before this endpoint sees it.
    inbox: Endpoint,
    _runner: Agora,
    /// Teammates (robot numbers), and the creation time of each one's latest report.
    mates: BTreeMap<u32, Option<Time>>,
    /// Teammates not waited for (silent once, until they speak again).
    absent: Vec<u32>,
    period: Duration,
    /// How long to wait for a teammate's report before running without it.
    mate_wait: Duration,
    /// Whether teammate `j` (robot index) is on the network at all (default: assumed).
    on_network: Box<dyn Fn(u32) -> bool + Send>,
    /// Whether this robot ran a cycle yet (a robot started mid-match has no reports from the
    /// previous cycle to wait for).
    ran: bool,
}

/// How a robot's match went, seen from the robot.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RobotRun {
    /// Cycles run.
    pub cycles: u64,
    /// Cycles in which some teammate's report came too late (the match may differ from the
    /// single-process one from then on).
    pub late_mates: u64,
    /// When the first step came.
    pub first_frame: Option<Instant>,
    /// When the robot sent its first answer (for a robot restarted mid-match: when it
    /// rejoined).
    pub first_answer: Option<Instant>,
}

impl RemoteRobot {
    /// Robot `spec` of a match played under `cfg`, its Agora configured by `net` (a NETWORK
    /// Agora: the caller links it, see [`RemoteRobot::agora`]), Chaos behaviors from
    /// `behaviors`. Its Members start (subscribe) at once.
    pub fn new(
        cfg: &RobotConfig,
        spec: RobotSpec,
        behaviors: &Path,
        net: Option<AgoraConfig>,
    ) -> Result<RemoteRobot, RobotError> {
        RemoteRobot::with_members(cfg, spec, behaviors, net, Vec::new())
    }

    /// [`RemoteRobot::new`] with `extra` Members on the robot's Agora beside its own, each
    /// run when a message reaches it (a recorder's tap, a probe).
    pub fn with_members(
        cfg: &RobotConfig,
        spec: RobotSpec,
        behaviors: &Path,
        net: Option<AgoraConfig>,
        extra: Vec<Box<dyn Member>>,
    ) -> Result<RemoteRobot, RobotError> {
        let period = cfg.period();
        let mut exec = SteppedExecutor::new(SimClock::new(), period);
        let community = InnerLinkManager::new();
        let mut builder = exec.agora_builder(spec.agora_id()?).inner_link(&community);
        if let Some(net) = net {
            builder = builder.config(net);
        }
        let mut agora = builder.build()?;
        let devices = Arc::new(Mutex::new(LinkedDevices::default()));
        add_robot(&mut agora, cfg, &spec, behaviors, devices.clone())?;
        for member in extra {
            let id = agora.add_boxed_member(member, Activation::OnMessage);
            agora.activate_member(id)?;
        }
        exec.add_agora(agora)?;
        let runner_id = 1000 + spec.agora_id()?;
        let mut runner = exec.agora_builder(runner_id).inner_link(&community).build()?;
        let inbox = runner.endpoint();
        inbox.subscribe_to::<MateReport>(RequestType::Remote);
        exec.start();
        let n = cfg.team_size.max(1);
        let first = spec.robot / n * n;
        let mates = (first..first + n)
            .filter(|&j| j != spec.robot)
            .filter_map(|j| u32::try_from(j).ok())
            .map(|j| (j, None))
            .collect();
        Ok(RemoteRobot {
            spec,
            exec,
            devices,
            inbox,
            _runner: runner,
            mates,
            absent: Vec::new(),
            period,
            mate_wait: Duration::from_secs(2),
            on_network: Box::new(|_| true),
            ran: false,
        })
    }

    /// The robot's Agora (to link it to its team's network).
    pub fn agora(&self) -> Option<&Agora> {
        self.exec.agoras().next()
    }

    /// The Agora ids of the robot's teammates.
    pub fn mate_agoras(&self) -> Vec<u32> {
        self.mates.keys().map(|j| j + 1).collect()
    }

    /// How long to wait for a teammate's report before running a cycle without it (default
    /// 2 s).
    pub fn set_mate_wait(&mut self, wait: Duration) {
        self.mate_wait = wait;
    }

    /// Tells which teammates (by robot index) are on the network at all: one whose process
    /// ended is not waited for (without this, for [`RemoteRobot::set_mate_wait`] each cycle
    /// until it is booked late).
    pub fn set_presence(&mut self, on_network: impl Fn(u32) -> bool + Send + 'static) {
        self.on_network = Box::new(on_network);
    }

    /// Notes a teammate's report: its creation time, and that the teammate speaks again.
    fn note(&mut self, m: &mrt_dcdt::MsgRef) {
        if let Ok(r) = m.get::<MateReport>() {
            if let Some(t) = self.mates.get_mut(&r.id) {
                *t = Some(m.header().creation_time);
                self.absent.retain(|&j| j != r.id);
            }
        }
    }

    /// Whether teammate `j`'s report that this robot would have on one bus at `now` is here:
    /// the report of this cycle from a lower-numbered teammate, of the previous cycle from a
    /// higher-numbered one (none in the first cycle). Absent teammates are not waited for.
    fn mate_ready(&self, j: u32, now: Time) -> bool {
        if self.absent.contains(&j) {
            return true;
        }
        let period = u64::try_from(self.period.as_nanos()).unwrap_or(u64::MAX);
        let needed = if robot_index(j) < self.spec.robot {
            now.as_nanos()
        } else if let (Some(t), true) = (now.as_nanos().checked_sub(period), self.ran) {
            t
        } else {
            // The first cycle of the match, or of this robot (started again mid-match): no
            // report of a previous cycle to wait for.
            return true;
        };
        self.mates.get(&j).copied().flatten().is_some_and(|t| t.as_nanos() >= needed)
    }

    fn mates_ready(&self, now: Time) -> bool {
        self.mates.keys().all(|&j| self.mate_ready(j, now))
    }

    /// Runs one control cycle on `input`'s readings at its time, after the teammates'
    /// reports due then (module doc), and says what the drivers did.
    pub fn cycle(&mut self, input: Cycle, run: &mut RobotRun) -> Result<Actuation, RobotError> {
        if input.at > self.exec.now() {
            self.exec.clock().set(input.at);
        }
        let now = self.exec.now();
        // A robot started in the middle of the match waits for no teammate in its first
        // cycle: their reports of this cycle may have left before it subscribed.
        let late_joiner = !self.ran && !input.first;
        if !late_joiner && !self.wait_for_mates(now) {
            run.late_mates += 1;
        }
        self.devices.lock().map_err(|_| RobotError::Poisoned("devices"))?.load(input.readings);
        self.exec.run_for(self.period);
        let act = self.devices.lock().map_err(|_| RobotError::Poisoned("devices"))?.take();
        self.ran = true;
        run.cycles += 1;
        Ok(act)
    }

    /// Waits for the teammates' reports due at `now`; `false` if some came too late (those
    /// teammates are not waited for again until they speak).
    fn wait_for_mates(&mut self, now: Time) -> bool {
        let start = Instant::now();
        loop {
            // A teammate off the network (its process ended) is absent until it speaks
            // again: started anew, it reports only once it has had a frame itself.
            let gone: Vec<u32> = self
                .mates
                .keys()
                .copied()
                .filter(|&j| !self.absent.contains(&j) && !(self.on_network)(j))
                .collect();
            self.absent.extend(gone);
            if self.mates_ready(now) {
                break;
            }
            if start.elapsed() > self.mate_wait {
                let late: Vec<u32> =
                    self.mates.keys().copied().filter(|&j| !self.mate_ready(j, now)).collect();
                tracing::warn!(
                    robot = self.spec.robot,
                    "reports of teammates {late:?} late at {now}"
                );
                self.absent.extend(late);
                return false;
            }
            self.inbox.wait_msg(Duration::from_millis(2));
            while let Some(m) = self.inbox.receive_msg() {
                self.note(&m);
            }
        }
        true
    }

    /// The match is over: the Members close; their faults (failed to start, failed jobs,
    /// panics, lost mail).
    pub fn finish(self) -> Result<Vec<MemberFault>, RobotError> {
        finish(&self.spec, self.exec)
    }
}

fn finish(spec: &RobotSpec, exec: SteppedExecutor) -> Result<Vec<MemberFault>, RobotError> {
    let id = spec.agora_id()?;
    let reports = exec.finish();
    Ok(reports.iter().filter(|r| r.agora.0 == id).flat_map(member_faults).collect())
}

/// One control cycle's input ([`RemoteRobot::cycle`]).
#[derive(Clone, Debug, Default)]
pub struct Cycle {
    /// The robot's clock in this cycle.
    pub at: Time,
    /// Whether it is the first cycle of the match (no teammate's report of an earlier one to
    /// wait for).
    pub first: bool,
    /// The devices' readings.
    pub readings: Loaded,
}
