//! Robots as Agoras on the bus (DCDT, MRT manual ch. 3): the simulator's default wiring.
//!
//! Each robot is one [`Agora`](mrt_dcdt::Agora) running the robot program of `mrt-robot`
//! ([`add_robot`]: its drivers, world state, behaviors, guidance, motor driver and fault
//! book) on [`PitchDevices`], all on the simulated clock of one [`SteppedExecutor`] so that the
//! match stays deterministic. Teammates' `MateReport`s cross each team's
//! [`InnerLinkManager`]. Members that failed to start, failed or panicked are restarted by the
//! executor and booked against their robot when the match ends ([`MatchReport::faults`]).

use crate::config::SimConfig;
use crate::devices::PitchDevices;
use crate::error::SimError;
use crate::game::{MatchReport, Pitch};
use crate::referee::Call;
use mrt_core::SimClock;
use mrt_dcdt::{InnerLinkManager, SteppedExecutor};
use mrt_monitor::foxglove::{Bodies, FieldLines, SceneUpdate};
use mrt_monitor::profile::VIEW_PRECISION;
use mrt_monitor::{MatchInfo, RecordProfile, SharedRecorder, Tap, Truth};
use mrt_msgs::{Localization, MemberFault, WorldSnapshot};
use mrt_robot::brain::Brain;
use mrt_robot::config::RobotConfig;
use mrt_robot::devices::SharedDevices;
use mrt_robot::files::FilesDir;
use mrt_robot::members::{add_robot, add_robot_with_brain, behaviors_dir, member_faults};
use mrt_robot::spec::{RobotSpec, Stack};
use std::path::Path;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

type Shared = Arc<Mutex<Pitch>>;

fn lock_pitch(p: &Shared) -> Result<MutexGuard<'_, Pitch>, SimError> {
    p.lock().map_err(|_| SimError::Poisoned("pitch"))
}

/// Books a Member's fault against robot `robot`.
pub fn book_fault(fault: &MemberFault, pitch: &mut Pitch, robot: usize) {
    let first_at = fault.never_ran.then_some(0.0);
    pitch.fault_at(
        robot,
        first_at,
        fault.count,
        &format!("member {}: {}", fault.name, fault.error),
    );
}

/// The simulator's observer in each robot's Agora: it books every pose estimate the robot
/// publishes ([`Localization`]) against where the robot really is, and the robots its world
/// snapshots anchored against where they are ([`MatchReport::localization`]). It only reads
/// the robot's messages; nothing goes back.
struct EstimateWatch {
    pitch: Shared,
    robot: usize,
}

impl mrt_dcdt::Member for EstimateWatch {
    fn init(&mut self, ctx: &mut mrt_dcdt::Context<'_>) -> Result<(), mrt_dcdt::MemberError> {
        ctx.subscribe_to::<Localization>(mrt_dcdt::RequestType::Local);
        ctx.subscribe_to::<WorldSnapshot>(mrt_dcdt::RequestType::Local);
        Ok(())
    }

    fn do_your_job(
        &mut self,
        ctx: &mut mrt_dcdt::Context<'_>,
    ) -> Result<(), mrt_dcdt::MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if let Ok(w) = m.get::<WorldSnapshot>() {
                let mut pitch = lock_pitch(&self.pitch)?;
                pitch.book_robots(self.robot, &w.robots);
                let ball_job = w.job.as_ref().is_some_and(|j| j.aim.is_some());
                pitch.book_team_beliefs(self.robot, w.ball_booked, w.role == "attacker", ball_job);
                continue;
            }
            let estimate = m.get::<Localization>()?;
            lock_pitch(&self.pitch)?.book_estimate(self.robot, estimate);
        }
        Ok(())
    }
}

/// A match whose robots are Agoras on the bus.
pub struct BusMatch {
    pitch: Shared,
    exec: SteppedExecutor,
    period: Duration,
    /// Each team's community of Agoras (home, then away).
    links: Vec<InnerLinkManager>,
    /// The behavior files, kept while the robots may reload them.
    _files: FilesDir,
    /// Where every robot's messages and the truth are recorded, when they are.
    recorder: Option<SharedRecorder>,
}

/// The truth of `pitch` now ([`Truth`], recorded on `/truth`).
pub fn truth_of(pitch: &Pitch) -> Truth {
    let w = pitch.world();
    Truth {
        ball: w.ball(),
        ball_velocity: w.ball_velocity(),
        robots: (0..w.robot_count()).filter_map(|i| w.robot(i)).collect(),
        home: pitch.config().rules.team_size,
        score: pitch.referee().score(),
        state: pitch.referee().state(),
    }
}

impl BusMatch {
    /// A match between two stacks, `team_size` robots each (robot 0 keeps goal), or home alone
    /// when `away` is `None`. `behaviors` overrides the compiled-in TeamChaos files.
    pub fn new(
        cfg: &SimConfig,
        seed: u64,
        home: Stack,
        away: Option<Stack>,
        behaviors: Option<&Path>,
    ) -> Result<BusMatch, SimError> {
        BusMatch::recorded(cfg, seed, home, away, behaviors, None)
    }

    /// [`BusMatch::new`], with every robot's messages and the truth recorded into `recorder`
    /// (`mrt sim --record`): a [`Tap`] in each robot's Agora on the topics
    /// `/home/<k>/<type>` and `/away/<k>/<type>`, [`Truth`] each cycle on `/truth` and drawn
    /// for Foxglove on `/scene` (`foxglove.SceneUpdate`), and at its start which match it is
    /// ([`MatchInfo`], with the recorder's profile) on `/match` and the field's lines on
    /// `/field`.
    pub fn recorded(
        cfg: &SimConfig,
        seed: u64,
        home: Stack,
        away: Option<Stack>,
        behaviors: Option<&Path>,
        recorder: Option<SharedRecorder>,
    ) -> Result<BusMatch, SimError> {
        let n = cfg.rules.team_size;
        let stacks: Vec<Stack> = [Some(home), away].into_iter().flatten().collect();
        let dir = behaviors_dir(&stacks, behaviors)?;
        let files = dir.clone();
        let teams = (n, if away.is_some() { n } else { 0 });
        if let Some(rec) = &recorder {
            let info = MatchInfo {
                home: home.name().to_string(),
                away: away.map(|a| a.name().to_string()),
                seed,
                team_size: n,
                period: cfg.robot()?.period().as_secs_f64(),
                profile: RecordProfile::Full,
            };
            let mut rec = rec.lock().map_err(|_| SimError::Poisoned("recorder's"))?;
            let info = MatchInfo { profile: rec.profile(), ..info };
            rec.record("/match", mrt_core::Time::ZERO, &info)?;
            let f = &cfg.field;
            let lines = FieldLines {
                half_length: f.length / 2.0,
                half_width: f.width / 2.0,
                goal_half_width: f.goal_width / 2.0,
                goal_depth: f.goal_depth,
                penalty_area_depth: f.penalty_area_depth,
                penalty_area_half_width: f.penalty_area_width / 2.0,
                centre_circle_radius: f.centre_circle_radius,
            };
            let field = SceneUpdate::field(&lines, mrt_core::Time::ZERO);
            rec.record_rounded("/field", mrt_core::Time::ZERO, &field, VIEW_PRECISION)?;
        }
        BusMatch::build(cfg, seed, teams, files, recorder, |agora, robot_cfg, robot, devices| {
            let spec = RobotSpec::of(robot, n, (home, away.unwrap_or(home)));
            Ok(add_robot(agora, robot_cfg, &spec, &dir, devices)?)
        })
    }

    /// A match whose robots run the given brains (home's, then away's; robot 0 of each team
    /// keeps goal; an empty `away` leaves home alone on the field) in the same robot cycle as
    /// the stacks: a team's own Rust behaviors, or a test's scripted players.
    pub fn with_brains(
        cfg: &SimConfig,
        seed: u64,
        home: Vec<Box<dyn Brain + Send>>,
        away: Vec<Box<dyn Brain + Send>>,
    ) -> Result<BusMatch, SimError> {
        let teams = (home.len(), away.len());
        let n = cfg.rules.team_size.max(1);
        let mut brains = home.into_iter().chain(away);
        let files = FilesDir::user(std::path::PathBuf::new());
        BusMatch::build(cfg, seed, teams, files, None, |agora, robot_cfg, robot, devices| {
            let brain =
                brains.next().ok_or_else(|| SimError::Match("more robots than brains".into()))?;
            Ok(add_robot_with_brain(agora, robot_cfg, (robot, robot % n == 0), brain, devices)?)
        })
    }

    /// The pitch with `home` and `away` robots, each an Agora of the robot program that `add`
    /// puts in (robot number, its devices); each team on its own link.
    fn build(
        cfg: &SimConfig,
        seed: u64,
        (home, away): (usize, usize),
        files: FilesDir,
        recorder: Option<SharedRecorder>,
        mut add: impl FnMut(
            &mut mrt_dcdt::Agora,
            &RobotConfig,
            usize,
            SharedDevices,
        ) -> Result<(), SimError>,
    ) -> Result<BusMatch, SimError> {
        let robot_cfg = cfg.robot()?;
        let pitch = Arc::new(Mutex::new(Pitch::new(cfg, seed, home, away)?));
        let period = robot_cfg.period();
        let mut exec = SteppedExecutor::new(SimClock::new(), period);
        let mut links = Vec::new();
        for size in [home, away].into_iter().filter(|&n| n > 0) {
            let team_link = InnerLinkManager::new();
            links.push(team_link.clone());
            for _ in 0..size {
                let robot = exec.agoras().count();
                let id = u32::try_from(robot + 1)
                    .map_err(|_| SimError::Match(format!("robot {robot} has no Agora id")))?;
                let mut agora = exec.agora_builder(id).inner_link(&team_link).build()?;
                let devices = Arc::new(Mutex::new(PitchDevices::new(pitch.clone(), robot)?));
                add(&mut agora, &robot_cfg, robot, devices)?;
                let watch = EstimateWatch { pitch: pitch.clone(), robot };
                let watch = agora.add_member(watch, mrt_dcdt::Activation::OnMessage);
                agora.activate_member(watch)?;
                if let Some(rec) = &recorder {
                    let (team, k) =
                        if robot < home { ("home", robot) } else { ("away", robot - home) };
                    let tap = Tap::new(format!("{team}/{k}"), rec.clone());
                    let tap = agora.add_member(tap, mrt_dcdt::Activation::OnMessage);
                    agora.activate_member(tap)?;
                }
                exec.add_agora(agora)?;
            }
        }
        Ok(BusMatch { pitch, exec, period, links, _files: files, recorder })
    }

    /// The pitch (the world, the referee, the book), between cycles.
    pub fn pitch(&self) -> Result<MutexGuard<'_, Pitch>, SimError> {
        lock_pitch(&self.pitch)
    }

    /// A team's community of Agoras (0 home, 1 away), to attach monitors to.
    pub fn team_link(&self, team: usize) -> Option<&InnerLinkManager> {
        self.links.get(team)
    }

    /// The executor, to add monitoring Agoras.
    pub fn executor(&mut self) -> &mut SteppedExecutor {
        &mut self.exec
    }

    /// Keeps one frame per control cycle for drawings.
    pub fn record_frames(&mut self, on: bool) {
        if let Ok(mut p) = self.pitch.lock() {
            p.record_frames(on);
        }
    }

    /// One control cycle: every Agora runs (eyes, behaviors, motors), then the physics runs
    /// up to the next cycle. Returns the referee's calls.
    ///
    /// When recording, the truth is recorded first, at the time the robots' messages of this
    /// cycle carry: what was so when they looked.
    pub fn cycle(&mut self) -> Result<Vec<Call>, SimError> {
        if let Some(rec) = &self.recorder {
            let p = lock_pitch(&self.pitch)?;
            let time = mrt_core::Time::from_secs_f64(p.world().time());
            let mut rec = rec.lock().map_err(|_| SimError::Poisoned("recorder's"))?;
            let truth = truth_of(&p);
            rec.record("/truth", time, &truth)?;
            let c = p.config();
            let bodies = Bodies { robot_radius: c.body.radius, ball_radius: c.ball.radius };
            let scene = SceneUpdate::of_truth(&truth, &bodies, time);
            rec.record_rounded("/scene", time, &scene, VIEW_PRECISION)?;
        }
        self.exec.run_for(self.period);
        let mut p = self.pitch.lock().map_err(|_| SimError::Poisoned("pitch"))?;
        Ok(p.advance())
    }

    /// Plays until the end, calling `progress` with the simulated time after each cycle.
    pub fn play(self, progress: impl FnMut(f64)) -> Result<MatchReport, SimError> {
        self.play_until(f64::INFINITY, progress)
    }

    /// Plays until the end or until `max_seconds` of simulated time, calling `progress` with
    /// the simulated time after each cycle.
    pub fn play_until(
        self,
        max_seconds: f64,
        mut progress: impl FnMut(f64),
    ) -> Result<MatchReport, SimError> {
        self.play_while(|t| {
            progress(t);
            t < max_seconds
        })
    }

    /// Plays until the end, or until `go_on` (called with the simulated time after each
    /// cycle, and once before the first) says `false`: an interrupted match reports what was
    /// played.
    pub fn play_while(
        mut self,
        mut go_on: impl FnMut(f64) -> bool,
    ) -> Result<MatchReport, SimError> {
        let mut time = lock_pitch(&self.pitch)?.world().time();
        while go_on(time) && !lock_pitch(&self.pitch)?.finished() {
            self.cycle()?;
            time = lock_pitch(&self.pitch)?.world().time();
        }
        // Members that failed to start, failed jobs or panicked (each was restarted).
        let reports = self.exec.finish();
        {
            let mut pitch = lock_pitch(&self.pitch)?;
            for r in &reports {
                let robot = usize::try_from(r.agora.0).unwrap_or(usize::MAX).wrapping_sub(1);
                if robot < pitch.world().robot_count() {
                    // (not a monitoring Agora)
                    member_faults(r).iter().for_each(|f| book_fault(f, &mut pitch, robot));
                }
            }
        }
        let pitch = Arc::try_unwrap(self.pitch)
            .map_err(|_| SimError::Match("the pitch is still shared".into()))?;
        Ok(pitch.into_inner().map_err(|_| SimError::Poisoned("pitch"))?.report())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::short;
    use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType, RunReport};
    use mrt_msgs::MateReport;

    /// `mrt sim --record`: every robot's messages on `/home/<k>/<type>` and `/away/<k>/<type>`
    /// and the truth on `/truth`, each message JSON of its channel's schema, at times of the
    /// simulated clock; recording does not change the match.
    #[test]
    fn a_recorded_match_holds_every_robot_s_messages_and_the_truth() {
        let cfg = short(3.0, 2);
        let path = std::env::temp_dir().join(format!("mrt-sim-record-{}.mcap", std::process::id()));
        let rec = mrt_monitor::Recorder::create(&path).unwrap().shared();
        let m =
            BusMatch::recorded(&cfg, 4, Stack::Chaos, Some(Stack::Milan), None, Some(rec.clone()))
                .unwrap();
        let recorded = m.play(|_| {}).unwrap();
        let summary = mrt_monitor::Recorder::finish_shared(rec).unwrap();
        let plain = BusMatch::new(&cfg, 4, Stack::Chaos, Some(Stack::Milan), None)
            .unwrap()
            .play(|_| {})
            .unwrap();
        assert_eq!(recorded.trajectory_hash, plain.trajectory_hash);
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).ok();
        let mut topics = std::collections::BTreeMap::<String, (usize, u64)>::new();
        for m in mcap::MessageStream::new(&bytes).unwrap() {
            let m = m.unwrap();
            let schema = m.channel.schema.as_ref().unwrap();
            assert_eq!(
                (schema.encoding.as_str(), m.channel.message_encoding.as_str()),
                ("jsonschema", "json")
            );
            let value: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            let topic = &m.channel.topic;
            let own = ["/truth", "/match", "/scene", "/field", "/log"].contains(&topic.as_str())
                || (topic.ends_with("/pose") && schema.name == "foxglove.FrameTransform");
            assert!(own || topic.ends_with(&format!("/{}", schema.name)), "{topic}");
            if schema.name == "WorldSnapshot" {
                serde_json::from_value::<WorldSnapshot>(value).unwrap();
            } else if topic == "/truth" {
                assert_eq!(value["robots"].as_array().map(Vec::len), Some(4), "{value}");
            } else if topic == "/match" {
                let info: MatchInfo = serde_json::from_value(value).unwrap();
                assert_eq!((info.home.as_str(), info.away.as_deref()), ("chaos", Some("milan")));
                assert_eq!((info.seed, info.team_size, info.period), (4, 2, 0.1));
            }
            let e = topics.entry(topic.clone()).or_default();
            e.0 += 1;
            e.1 = e.1.max(m.log_time);
        }
        assert_eq!(summary.messages, topics.values().map(|t| t.0 as u64).sum::<u64>());
        // Both halves of 3 s at 10 Hz: 60 cycles, one truth and one snapshot per robot each.
        assert_eq!(topics["/truth"].0, 60);
        // Foxglove's views: the truth drawn each cycle, the field once, each believed pose.
        assert_eq!((topics["/scene"].0, topics["/field"].0), (60, 1));
        assert!(topics.contains_key("/away/1/pose"), "{:?}", topics.keys());
        for robot in ["home/0", "home/1", "away/0", "away/1"] {
            let snapshots = topics[&format!("/{robot}/WorldSnapshot")];
            assert_eq!(snapshots.0, 60, "{robot}");
            assert!(topics.contains_key(&format!("/{robot}/RobotCommand")), "{robot}");
            // On the simulated clock: the last snapshot at the time of the last truth.
            assert_eq!(topics["/truth"].1, snapshots.1, "{robot}");
        }
    }

    #[test]
    fn a_bus_match_is_deterministic_and_both_stacks_play() {
        let cfg = short(20.0, 2);
        let play = || {
            BusMatch::new(&cfg, 4, Stack::Chaos, Some(Stack::Chaser), None)
                .unwrap()
                .play(|_| {})
                .unwrap()
        };
        let (a, b) = (play(), play());
        assert_eq!((a.score, a.trajectory_hash, &a.stats), (b.score, b.trajectory_hash, &b.stats));
        assert!((a.duration - 40.0).abs() < 0.011, "{}", a.duration);
        assert!(
            a.stats[0].possession_cycles > 0 && a.stats[1].possession_cycles > 0,
            "{:?}",
            a.stats
        );
    }

    /// A Member whose mailbox lost messages is booked like a failing one, with the type and
    /// the counts; one whose mailboxes lost nothing is not.
    #[test]
    fn a_mailbox_that_lost_messages_is_a_member_fault() {
        use mrt_dcdt::{ExitReason, MailboxReport, MemberReport, MemberState, MsgType};
        let member = |name: &str, dropped, refused| MemberReport {
            id: mrt_dcdt::MemberId(0),
            name: name.into(),
            cycles: 10,
            errors: 0,
            panics: 0,
            restarts: 0,
            state: MemberState::Terminated,
            last_error: None,
            mailboxes: vec![MailboxReport {
                msg_type: MsgType(7),
                capacity: 4096,
                reliable_limit: 65_536,
                dropped,
                refused,
            }],
        };
        let report = RunReport {
            agora: mrt_dcdt::AgoraId(1),
            exit: ExitReason::TimeLimit,
            members: vec![member("Fine", 0, 0), member("Slow", 3, 1)],
        };
        let faults = member_faults(&report);
        assert_eq!(faults.len(), 1, "{faults:?}");
        assert_eq!((faults[0].name.as_str(), faults[0].count), ("Slow", 4));
        assert!(faults[0].error.contains("dropped 3 and refused 1"), "{}", faults[0].error);
    }

    /// Bad behavior files never stop a match: a file that does not compile stops the robots
    /// that load it (they stand still), a behavior that runs away is cut off by its budget;
    /// both are reported with the file and line.
    #[test]
    fn broken_or_runaway_behaviors_stop_their_robot_and_are_reported() {
        let tmp = std::env::temp_dir().join(format!("mrt-sim-broken-{}", std::process::id()));
        let src = mrt_robot::stacks::embedded_teamchaos().unwrap();
        let copy = |to: &Path| {
            std::fs::create_dir_all(to).unwrap();
            for e in std::fs::read_dir(&src).unwrap() {
                let p = e.unwrap().path();
                std::fs::copy(&p, to.join(p.file_name().unwrap())).unwrap();
            }
        };
        let cfg = short(5.0, 2);
        // 1. A syntax error in go2ball.lua (line 11): no Chaos robot can load its behaviors.
        let broken = tmp.join("broken");
        copy(&broken);
        let go2ball = broken.join("go2ball.lua");
        let text = std::fs::read_to_string(&go2ball).unwrap();
        std::fs::write(&go2ball, format!("{}rule(ballSeen(, 'go')\n", text)).unwrap();
        let line = text.lines().count() + 1;
        let want = format!("go2ball.lua:{line}:");
        let bus = BusMatch::new(&cfg, 1, Stack::Chaos, Some(Stack::Chaser), Some(&broken))
            .unwrap()
            .play(|_| {})
            .unwrap();
        assert!((bus.duration - 10.0).abs() < 0.011, "the match went on: {}", bus.duration);
        let robots: Vec<usize> = bus.faults.iter().map(|f| f.robot).collect();
        assert_eq!(robots, [0, 1], "{:?}", bus.faults);
        assert!(bus.faults.iter().all(|f| f.message.contains(&want)), "{:?}", bus.faults);
        assert!(bus.faults.iter().all(|f| f.first_at == Some(0.0)), "from the start");
        assert_eq!(bus.stats[0].shots, 0, "stopped robots do not play");
        // 2. A goalkeeper behavior that never ends: the budget cuts it off every cycle.
        let looping = tmp.join("looping");
        copy(&looping);
        let keeper = looping.join("goalkeeper.lua");
        let text = std::fs::read_to_string(&keeper).unwrap();
        std::fs::write(&keeper, format!("while true do end\n{text}")).unwrap();
        let bus = BusMatch::new(&cfg, 1, Stack::Chaos, Some(Stack::Chaser), Some(&looping))
            .unwrap()
            .play(|_| {})
            .unwrap();
        assert!((bus.duration - 10.0).abs() < 0.011);
        let keeper = bus.faults.iter().find(|f| f.robot == 0);
        assert!(
            keeper.is_some_and(|f| f.message.contains("goalkeeper.lua:1: aborted after")
                && f.message.contains("instruction budget")
                && f.count > 1),
            "{:?}",
            bus.faults
        );
        std::fs::remove_dir_all(&tmp).unwrap();
    }

    #[test]
    fn the_chaos_team_alone_on_the_bus_scores_within_two_minutes() {
        let cfg = short(120.0, 2);
        let report =
            BusMatch::new(&cfg, 3, Stack::Chaos, None, None).unwrap().play(|_| {}).unwrap();
        let first = report.calls.iter().find(|(_, c)| matches!(c, Call::Goal(_)));
        assert!(first.is_some_and(|(t, _)| *t <= 120.0), "{:?}", report.calls);
    }

    /// A Member that keeps every `MateReport` its Agora's links bring (Remote subscription).
    struct Listen(Arc<Mutex<Vec<MateReport>>>);

    impl Member for Listen {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.subscribe_to::<MateReport>(RequestType::Remote);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            while let Some(m) = ctx.receive_msg() {
                let r = m.get::<MateReport>()?.clone();
                self.0.lock().map_err(|_| "poisoned")?.push(r);
            }
            Ok(())
        }
    }

    /// Teammates know each other only through the bus: a MateReport crosses the team's
    /// InnerLinkManager (Remote subscription), never to the other team, and never to an Agora
    /// on no link.
    #[test]
    fn teammates_hear_each_other_over_the_bus() {
        let cfg = short(5.0, 2);
        let mut m = BusMatch::new(&cfg, 1, Stack::Chaser, Some(Stack::Chaser), None).unwrap();
        let period = m.period;
        let (on_home, alone): (Arc<Mutex<Vec<MateReport>>>, _) = (Arc::default(), Arc::default());
        for (id, link, heard) in [(98, m.team_link(0).cloned(), &on_home), (99, None, &alone)] {
            let mut b = m.executor().agora_builder(id);
            if let Some(l) = &link {
                b = b.inner_link(l);
            }
            let mut agora = b.build().unwrap();
            let member = agora.add_member(Listen(Arc::clone(heard)), Activation::Periodic(period));
            agora.activate_member(member).unwrap();
            m.executor().add_agora(agora).unwrap();
        }
        for _ in 0..5 {
            m.cycle().unwrap();
        }
        let heard: std::collections::BTreeSet<u32> =
            on_home.lock().unwrap().iter().map(|r| r.id).collect();
        let ids: Vec<u32> = heard.into_iter().collect();
        assert_eq!(ids, [0, 1], "the home robots' reports, not the away team's (2, 3)");
        assert!(alone.lock().unwrap().is_empty(), "not on any team's link");
    }

    /// What teammates tell each other is in the world model's SI units: every pose a report
    /// carries lies on the field (metres: within 12 m of the centre spot), and the ball's
    /// uncertainty, once a robot has seen the ball, is a few decimetres, not hundreds.
    #[test]
    fn team_reports_are_in_metres() {
        let cfg = short(5.0, 2);
        let mut m = BusMatch::new(&cfg, 1, Stack::Chaser, Some(Stack::Chaser), None).unwrap();
        let period = m.period;
        let heard: Arc<Mutex<Vec<MateReport>>> = Arc::default();
        let link = m.team_link(0).cloned().unwrap();
        let mut agora = m.executor().agora_builder(98).inner_link(&link).build().unwrap();
        let member = agora.add_member(Listen(Arc::clone(&heard)), Activation::Periodic(period));
        agora.activate_member(member).unwrap();
        m.executor().add_agora(agora).unwrap();
        for _ in 0..40 {
            m.cycle().unwrap();
        }
        let reports = heard.lock().unwrap();
        assert!(!reports.is_empty());
        for r in reports.iter() {
            let p = r.pose.pose.inner;
            assert!(p.x.hypot(p.y) < 12.0, "a pose off the field: {r:?}");
            assert!((0.0..2.0).contains(&r.ball_sigma), "ball sigma {} m: {r:?}", r.ball_sigma);
            for s in &r.robots {
                assert!(s.at.inner.x.hypot(s.at.inner.y) < 12.0 && s.at_sigma < 2.0, "{s:?}");
            }
        }
        assert!(reports.iter().any(|r| r.ball_sigma > 0.0), "nobody saw the ball in 4 s");
    }
}
