//! Team ISocRob (ISocRob-2000 report §3.2): robots whose Machine µAgent ([`mrt_team::isocrob`]) reads
//! its parameters from the blackboard (`configs/isocrob/config.dat`, compiled in), talks to its
//! teammates only through the blackboard (each posts its `should_I_go` heuristic as
//! `*.var.machine.heuristic.<robot>`, carried by the [`Proxy`](mrt_blackboard::Proxy) Member),
//! and fires the kicker through `local.var.kicker.kick`, which the Kicker µAgent watches.
//!
//! What the Machine posts for a person to watch with `mrt bb watch` (the seed's Monitor
//! µAgent printed the same): `local.var.machine.mode`, `.role`, `.state`, `.slg`, and its
//! heuristic as the teammates read it, `*.var.machine.heuristic.<robot>`.
//!
//! The predicates come from the robot's world snapshot, never from the simulator:
//! - `ffb()`: the ball was seen within `seen-ball` seconds (the front camera's LPS ball);
//! - `ffog()`: the opponent's goal centre lies within `facing` of straight ahead (the world
//!   model's LPS net, placed by the pose estimate when not in sight); in FACE_GOAL, with the
//!   ball also within `ahead` of the kicker (a robot facing the goal with the ball beside it
//!   goes on round: RUN_AND_KICK would push the ball off sideways);
//! - `fnb()`: the ball is seen, nearer than `att.near-ball` and before the kicker (in
//!   FACE_GOAL, which goes round the ball, near is enough);
//! - `r(360)`: the search turned the robot round once (its estimated heading, unwrapped);
//! - `rp()`: the robot is within `reached` of its home posture;
//! - `kb()`: the Kicker's pulse ended in the last cycle;
//! - `slg()`: [`should_i_go`] on the heuristics heard within `heard` seconds.
//!
//! The seed's robots "stand still" in SHOULD_I_GO; these walk to their home posture meanwhile,
//! facing the ball, so that a robot that is not going for the ball stays in the game. The
//! home postures follow the team's ball: the attackers `att.support` ahead of it in their
//! lanes, the defender `def.guard` of the way out from its goal towards it.

use crate::brain::Brain;
use crate::error::RobotError;
use crate::stacks::{drive_to, walk_to_kickoff, Geometry};
use mrt_blackboard::config::load_text;
use mrt_blackboard::{Blackboard, Pattern};
use mrt_core::frames::{seconds_from_millis, Framed};
use mrt_core::{normalize_angle, Pose2};
use mrt_msgs::robot::{lps, GameState, RobotCommand, Target, WorldSnapshot};
use mrt_team::isocrob::{
    heuristic, keeper, should_i_go, Attacker, AttackerState, KeeperBall, KeeperParams, Mode,
    Predicates, Role,
};
use std::path::Path;

/// The team's configuration, compiled in (`configs/isocrob/config.dat`).
pub const CONFIG: &str = include_str!("../../../configs/isocrob/config.dat");

/// The prefix of the heuristics the robots post; the robot's number follows.
pub const HEURISTIC: &str = "*.var.machine.heuristic.";

/// `fnb()` needs the near ball within this bearing, rad: before the kicker, not beside it
/// (except in FACE_GOAL, which goes round the ball).
const NEAR_FRONT: f64 = 0.6;

/// Where a robot that is not going for the ball should look (its heading, rad, team frame):
/// at the ball when its camera saw it within `recent` seconds, else towards where the team
/// believes the ball is (MAP's team ball), else up the field. Not at the LPS ball's stale
/// place: that one is dead-reckoned in the robot's frame and turns with the robot, so a robot
/// that faced it kept whatever way it faced, and a goalkeeper looked along its goal line for
/// seconds while the shot came (with the 40° front camera, before this).
fn look_at_ball(w: &WorldSnapshot, recent: f64) -> f64 {
    let me = w.my_pos.pose.inner;
    let ball = w.lps[lps::BALL];
    if ball.reliability > 0.0 && ball.seen_ago <= recent {
        me.theta + ball.theta
    } else {
        team_ball_heading(w).unwrap_or(0.0)
    }
}

/// The heading (rad, team frame) from the robot to where its team believes the ball is
/// (MAP's team ball), when the team has one.
fn team_ball_heading(w: &WorldSnapshot) -> Option<f64> {
    let (me, ball) = (w.my_pos.pose.inner, w.global_ball);
    (ball.quality > 0.0).then(|| (ball.pose.inner.y - me.y).atan2(ball.pose.inner.x - me.x))
}

/// [`drive_to`] at up to 1.5 m/s.
fn go(me: Pose2, target: (f64, f64), face: f64, c: &mut RobotCommand) {
    drive_to(me, target, face, 1.5, c);
}

/// One ISocRob robot: the Machine µAgent and the Kicker µAgent on a shared blackboard.
pub struct IsocrobBrain {
    /// The robot's number on the blackboard (its Agora's id).
    id: u32,
    role: Role,
    /// Among the field players of its team, which one (0, 1, ...): spreads the homes.
    index: usize,
    bb: Blackboard,
    attacker: Attacker,
    /// The heading when the search started and how far it has turned since, rad.
    search: Option<(f64, f64)>,
    /// When the kicker's valve opened, s (the Kicker µAgent).
    pulse_from: Option<f64>,
    /// Whether the valve closed in the last cycle (`kb()` for this one).
    kicked: bool,
    /// The teammates' heuristics: `*.var.machine.heuristic.*`.
    shared: Pattern,
    faults: Vec<String>,
}

/// The Machine's parameters, read from the blackboard every cycle (a person may change them
/// while the robot runs).
#[derive(Clone, Copy, Debug)]
struct Params {
    near_ball: f64,
    k1: f64,
    facing: f64,
    seen_ball: f64,
    kick_distance: f64,
    kick_reach: f64,
    behind: f64,
    orbit: f64,
    ahead: f64,
    guard: f64,
    support: f64,
    heard: f64,
    home_x: f64,
    home_spread: f64,
    reached: f64,
    search_speed: f64,
    keeper: KeeperParams,
    pulse: f64,
}

impl IsocrobBrain {
    /// Robot `id` (its number on the blackboard) of the team, playing `role`; `index` orders
    /// the field players. Loads the team's configuration onto `bb`.
    pub fn new(
        id: u32,
        role: Role,
        index: usize,
        bb: Blackboard,
    ) -> Result<IsocrobBrain, RobotError> {
        load_text(&bb, CONFIG, Path::new("configs/isocrob/config.dat"))?;
        bb.set("local.var.machine.role", role.name())?;
        Ok(IsocrobBrain {
            id,
            role,
            index,
            bb,
            attacker: Attacker::default(),
            search: None,
            pulse_from: None,
            kicked: false,
            shared: Pattern::parse("*.var.machine.heuristic.*")?,
            faults: Vec::new(),
        })
    }

    /// The state of the attacker's machine.
    pub fn state(&self) -> AttackerState {
        self.attacker.state()
    }

    fn float(&self, name: &str, default: f64) -> f64 {
        self.bb.get::<f64>(&format!("local.var.machine.config.{name}")).unwrap_or(default)
    }

    fn params(&self) -> Params {
        let d = KeeperParams::default();
        let home = if self.role == Role::Defender { "def.home-x" } else { "att.home-x" };
        Params {
            near_ball: self.float("att.near-ball", 0.5),
            k1: self.float("k1", -0.5),
            facing: self.float("facing", 0.25),
            seen_ball: self.float("seen-ball", 0.3),
            kick_distance: self.float("kick-distance", 5.0),
            kick_reach: self.float("kick-reach", 0.7),
            behind: self.float("behind", 0.35),
            orbit: self.float("orbit", 0.0),
            ahead: self.float("ahead", 0.0),
            guard: self.float("def.guard", 0.0),
            support: self.float("att.support", 0.0),
            heard: self.float("heard", 1.0),
            home_x: self.float(home, -1.0),
            home_spread: self.float("home-spread", 2.5),
            reached: self.float("reached", 0.3),
            search_speed: self.float("search-speed", 1.5),
            keeper: KeeperParams {
                axis: self.float("gk.axis", d.axis),
                reach: self.float("gk.reach", d.reach),
                home_after: self.float("gk.home-after", d.home_after),
                danger_time: self.float("gk.danger-time", d.danger_time),
            },
            pulse: seconds_from_millis(
                self.bb.get::<i64>("local.var.kicker.config.pulse").unwrap_or(125) as f64,
            ),
        }
    }

    /// Posts a value for the monitor; a blackboard that refuses it is a fault, not a stop.
    fn post(&mut self, symbol: &str, value: impl Into<mrt_blackboard::Value>) {
        if let Err(e) = self.bb.set(symbol, value) {
            self.faults.push(format!("blackboard {symbol}: {e}"));
        }
    }

    /// The teammates' heuristics heard within `heard` seconds.
    fn heard(&self, heard: f64) -> Vec<(u32, f64)> {
        let now = self.bb.now().as_secs_f64();
        self.bb
            .list(Some(&self.shared))
            .into_iter()
            .filter_map(|(symbol, value)| {
                let id = symbol.strip_prefix(HEURISTIC)?.parse::<u32>().ok()?;
                let v = value?;
                let h = match v.value {
                    mrt_blackboard::Value::Float(h) => h,
                    _ => return None,
                };
                (now - v.time.as_secs_f64() <= heard).then_some((id, h))
            })
            .collect()
    }

    /// The Kicker µAgent (ISocRob-2000 report §3.2.4): when `local.var.kicker.kick` is set it opens
    /// the valve for the configured pulse (the kick command held that long) and clears the
    /// variable. Returns whether the pulse ended in this cycle (`kb()`).
    fn kicker(&mut self, now: f64, pulse: f64, cmd: &mut RobotCommand) -> bool {
        if self.pulse_from.is_none() && self.bb.get::<bool>("local.var.kicker.kick") == Ok(true) {
            self.pulse_from = Some(now);
            self.post("local.var.kicker.kick", false);
        }
        match self.pulse_from {
            Some(from) if now - from < pulse => {
                cmd.kick = Some(1);
                false
            }
            Some(_) => {
                self.pulse_from = None;
                true
            }
            None => false,
        }
    }

    fn field_player(&mut self, w: &WorldSnapshot, p: &Params, kicked: bool) -> RobotCommand {
        let me = w.my_pos.pose.inner;
        let ball = w.lps[lps::BALL];
        let net = w.lps[lps::NET1];
        let ffb = ball.reliability > 0.0 && ball.seen_ago <= p.seen_ball;
        let ffog = net.theta.abs() <= p.facing && net.rho > 0.0;
        // Near, and before the kicker; while going round the ball (FACE_GOAL) near is enough.
        let near = ffb && ball.rho <= p.near_ball;
        let fnb = near
            && (ball.theta.abs() < NEAR_FRONT || self.attacker.state() == AttackerState::FaceGoal);
        let h = heuristic(ffb.then_some(ball.rho), ffog, p.k1);
        self.post(&format!("{HEURISTIC}{}", self.id), h);
        let slg = should_i_go(self.id, h, &self.heard(p.heard));
        self.post("local.var.machine.slg", slg);
        // The home posture: attackers spread across the field, the defender back.
        let side = if self.index % 2 == 0 { 1.0 } else { -1.0 };
        let lane = side * p.home_spread * (self.index / 2 + 1) as f64 / 2.0;
        let mut home = (p.home_x, lane);
        // Home postures that follow the ball the team believes in (MAP's team ball):
        let hl = w.field.half_length;
        let team_ball = w.global_ball;
        let team_ball =
            (team_ball.quality > 0.0).then_some((team_ball.pose.inner.x, team_ball.pose.inner.y));
        match (self.role, team_ball) {
            // an attacker with `att.support`: that far ahead of the ball (behind it when
            // negative), in its lane, to take up what comes loose;
            (Role::Attacker, Some((bx, _))) if p.support != 0.0 => {
                home.0 = (bx + p.support).clamp(1.0 - hl, hl - 1.0);
            }
            // the defender with `def.guard`: between the ball and its own goal, on the line
            // from the goal's centre to the ball, that fraction of the way out (≥ 1.5 m).
            (Role::Defender, Some((bx, by))) if p.guard > 0.0 => {
                let (dx, dy) = (bx + hl, by);
                let d = dx.hypot(dy);
                if d > 1.5 {
                    let out = (p.guard * d).max(1.5) / d;
                    home = (out * dx - hl, out * dy);
                }
            }
            _ => {}
        }
        let rp = (me.x - home.0).hypot(me.y - home.1) <= p.reached;
        // r(360): the heading turned since the search began.
        let rotated = match (self.attacker.state(), &mut self.search) {
            (AttackerState::SearchBall, Some((last, turned))) => {
                *turned += normalize_angle(me.theta - *last).abs();
                *last = me.theta;
                *turned >= std::f64::consts::TAU
            }
            _ => false,
        };
        // FACE_GOAL ends facing the goal with the ball before the kicker, not beside it.
        let ffog = ffog
            && (p.ahead <= 0.0
                || self.attacker.state() != AttackerState::FaceGoal
                || ball.theta.abs() < p.ahead);
        let pred = Predicates { ffb, ffog, fnb, rotated, rp, kb: kicked, slg };
        let state = self.attacker.step(&pred);
        self.search = match (state, self.search) {
            (AttackerState::SearchBall, Some(s)) => Some(s),
            (AttackerState::SearchBall, None) => Some((me.theta, 0.0)),
            _ => None,
        };
        self.post("local.var.machine.state", state.name());
        let field = Geometry::of(&w.field);
        let towards_ball = me.theta + ball.theta;
        let ball_at = Geometry::ball_at(me, &ball);
        let mut c = RobotCommand { needs: vec![(lps::BALL, 1.0)], ..RobotCommand::default() };
        match state {
            // ET_go_home(), also while another robot goes for the ball (module doc).
            AttackerState::Home | AttackerState::ShouldIGo => {
                let face = look_at_ball(w, p.seen_ball);
                c.target = Some(Target {
                    pose: Framed::new(Pose2::new(home.0, home.1, face)),
                    avoid: true,
                    plan: false,
                });
            }
            // move_close2ball(): straight at the ball, turning to it.
            AttackerState::ApproachBall => go(me, ball_at, towards_ball, &mut c),
            // The arc round the ball until the robot faces the goal with the ball before it:
            // round the ball at `orbit` from it to the posture behind it on the line from the
            // goal, facing the ball all the way (a robot with no dribbler cannot turn holding
            // it, and a front camera that looks away from the ball loses it). Behind the ball,
            // facing it is facing the goal.
            // With `orbit` 0: straight to the posture, facing the goal, stepping round the
            // ball when on its wrong side.
            AttackerState::FaceGoal => {
                let behind = field.behind_ball(ball_at, p.behind);
                let (to, face) = if p.orbit > 0.0 {
                    (Geometry::orbit(me, ball_at, behind, p.orbit), towards_ball)
                } else {
                    (Geometry::step_round(me, ball_at, behind), behind.theta)
                };
                go(me, to, face, &mut c);
            }
            // push_ball(): through the ball towards the goal; kick_ball() when the goal is
            // near enough and the ball lies before the kicker.
            AttackerState::RunAndKick => {
                let shot = field.behind_ball(ball_at, p.behind).theta;
                let through = (ball_at.0 + 0.2 * shot.cos(), ball_at.1 + 0.2 * shot.sin());
                go(me, through, shot, &mut c);
                let goal = (field.half_length - me.x).hypot(me.y);
                let lined_up = normalize_angle(me.theta - shot).abs() < p.facing;
                // One request a kick: none while the valve is open.
                let idle = self.pulse_from.is_none();
                // The kicker reaches the ball only when it touches the robot's front: a pulse
                // fired at a ball farther away misses it, and the solenoid then recharges.
                let reach = ball.rho <= p.kick_reach;
                if idle && goal <= p.kick_distance && reach && ball.theta.abs() < 0.3 && lined_up {
                    self.post("local.var.kicker.kick", true);
                }
            }
            // rotate2find_ball(): the shorter way round to where the team believes the ball
            // is (the teammates' sightings, MAP's team ball), to the left when it has none.
            AttackerState::SearchBall => {
                let turn =
                    team_ball_heading(w).map_or(1.0, |h| normalize_angle(h - me.theta).signum());
                c.twist.omega = turn * p.search_speed;
            }
        }
        c
    }

    fn goalkeeper(&mut self, w: &WorldSnapshot, p: &Params) -> RobotCommand {
        let ball = w.lps[lps::BALL];
        let me = w.my_pos.pose.inner;
        let hl = w.field.half_length;
        let seen = (ball.reliability > 0.0).then(|| KeeperBall {
            at: Geometry::ball_at(me, &ball),
            velocity: (w.ball_vel.inner.x, w.ball_vel.inner.y),
            seen_ago: ball.seen_ago,
        });
        let (mode, y) = keeper(seen, hl, &p.keeper);
        self.post("local.var.machine.state", mode.name());
        let face = look_at_ball(w, p.seen_ball);
        RobotCommand {
            target: Some(Target {
                pose: Framed::new(Pose2::new(-hl + p.keeper.axis, y, face)),
                avoid: false,
                plan: false,
            }),
            needs: vec![(lps::BALL, 1.0)],
            ..RobotCommand::default()
        }
    }
}

impl Brain for IsocrobBrain {
    fn cycle(&mut self, w: &WorldSnapshot) -> RobotCommand {
        let mode = match w.game_state {
            GameState::Initial => Mode::None,
            GameState::Ready | GameState::Set => Mode::Setup,
            GameState::Playing => Mode::Play,
            GameState::Finished => Mode::Pause,
        };
        self.post("local.var.machine.mode", mode.name());
        let p = self.params();
        if mode != Mode::Play {
            // Setup: to the kickoff posture; none and pause: still. The machine starts again.
            self.attacker = Attacker::default();
            self.search = None;
            self.kicked = false;
            return walk_to_kickoff(w).unwrap_or_default();
        }
        // The Machine, then the Kicker: a kick the Machine asks for now fires in this cycle;
        // the end of the pulse is the Machine's `kb()` in the next.
        let mut c = match self.role {
            Role::Goalkeeper => self.goalkeeper(w, &p),
            Role::Attacker | Role::Defender => self.field_player(w, &p, self.kicked),
        };
        self.kicked = self.kicker(w.time.as_secs_f64(), p.pulse, &mut c);
        c
    }

    fn take_faults(&mut self) -> Vec<String> {
        std::mem::take(&mut self.faults)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::{SimClock, Time};
    use mrt_msgs::robot::Lpo;
    use std::sync::Arc;

    /// A playing robot at `me` (team frame, m) that sees the ball at `ball` (m), at `time`.
    fn world(time: f64, me: Pose2, ball: (f64, f64)) -> WorldSnapshot {
        let mut w = WorldSnapshot {
            game_state: GameState::Playing,
            time: Time::from_secs_f64(time),
            ..WorldSnapshot::default()
        };
        w.my_pos.pose = Framed::new(me);
        w.my_pos.quality = 0.9;
        let lpo = |(x, y): (f64, f64)| {
            let (dx, dy) = (x - me.x, y - me.y);
            Lpo {
                rho: dx.hypot(dy),
                theta: normalize_angle(dy.atan2(dx) - me.theta),
                reliability: 1.0,
                seen_ago: 0.0,
            }
        };
        w.lps[lps::BALL] = lpo(ball);
        w.lps[lps::NET1] = lpo((w.field.half_length, 0.0));
        w
    }

    /// A robot not going for the ball looks at it while its camera has it, then where the
    /// team believes it is, then up the field; never at the stale, dead-reckoned LPS ball.
    #[test]
    fn a_robot_looks_at_the_ball_it_saw_then_the_team_ball_then_up_the_field() {
        let me = Pose2::new(-8.6, 0.0, 1.8);
        let mut w = world(10.0, me, (-6.6, 2.0));
        let at_ball = std::f64::consts::FRAC_PI_4; // (−6.6, 2) from (−8.6, 0): 45°
        assert!((normalize_angle(look_at_ball(&w, 0.8)) - at_ball).abs() < 1e-9);
        // Not seen for 5 s: the LPS ball turned with the robot and says "straight ahead".
        w.lps[lps::BALL] = Lpo { rho: 1.05, theta: -0.01, reliability: 0.01, seen_ago: 5.0 };
        assert_eq!(look_at_ball(&w, 0.8), 0.0, "no team ball: up the field");
        w.global_ball.quality = 0.5;
        w.global_ball.pose = Framed::new(Pose2::new(-4.6, -4.0, 0.0));
        let team = -std::f64::consts::FRAC_PI_4;
        assert!((look_at_ball(&w, 0.8) - team).abs() < 1e-9, "towards the team ball");
    }

    fn board(id: u32, clock: &Arc<SimClock>) -> Blackboard {
        Blackboard::new(id, clock.clone())
    }

    /// Two attackers that hear each other only through their blackboards (what the Proxy
    /// carries, applied by hand): the one nearer the ball goes for it, the other waits in
    /// SHOULD_I_GO; when the ball rolls to the other, they swap.
    #[test]
    fn the_robot_nearer_the_ball_goes_and_the_other_waits() {
        let clock = Arc::new(SimClock::new());
        let (bb2, bb3) = (board(2, &clock), board(3, &clock));
        let (out2, out3) = (bb2.outbox(), bb3.outbox());
        let mut r2 = IsocrobBrain::new(2, Role::Attacker, 1, bb2.clone()).unwrap();
        let mut r3 = IsocrobBrain::new(3, Role::Attacker, 2, bb3.clone()).unwrap();
        let (me2, me3) = (Pose2::new(-2.0, 1.0, 0.0), Pose2::new(-2.0, -1.5, 0.0));
        let mut cycle = |t: f64, ball: (f64, f64)| {
            clock.set(Time::from_secs_f64(t));
            r2.cycle(&world(t, me2, ball));
            r3.cycle(&world(t, me3, ball));
            // The Proxy's job: each robot's shared changes to the other.
            out2.try_iter().for_each(|u| bb3.apply(&u).unwrap());
            out3.try_iter().for_each(|u| bb2.apply(&u).unwrap());
            (r2.state(), r3.state())
        };
        // The ball 1.1 m before robot 2, 3.3 m from robot 3. In the first cycle each hears
        // nobody yet and goes; from the second, robot 3 knows it is the farther.
        cycle(0.0, (-0.9, 1.0));
        let (s2, s3) = cycle(0.1, (-0.9, 1.0));
        assert_eq!((s2, s3), (AttackerState::ApproachBall, AttackerState::ShouldIGo));
        // Eq 19: 1.1 m, less k₁ = 0.5 m for facing the opponent's goal.
        let h2 = bb3.get::<f64>("*.var.machine.heuristic.2").unwrap();
        assert!((h2 - 0.6).abs() < 1e-9, "{h2}");
        assert_eq!(bb3.get::<bool>("local.var.machine.slg"), Ok(false));
        // The ball rolls to robot 3's side.
        cycle(0.2, (-0.9, -1.5));
        let (s2, s3) = cycle(0.3, (-0.9, -1.5));
        assert_eq!((s2, s3), (AttackerState::ShouldIGo, AttackerState::ApproachBall));
        // A teammate not heard for longer than `heard` (1 s) is not a rival.
        clock.set(Time::from_secs_f64(2.0));
        r2.cycle(&world(2.0, me2, (-0.9, -1.5)));
        assert_eq!(r2.state(), AttackerState::ApproachBall);
    }

    /// The Kicker µAgent: the Machine sets `local.var.kicker.kick`; the kick command is held
    /// for the 125 ms pulse, the variable is cleared, and `kb()` holds when the pulse ends.
    #[test]
    fn the_kicker_holds_the_valve_open_for_its_pulse() {
        let clock = Arc::new(SimClock::new());
        let bb = board(2, &clock);
        let mut r = IsocrobBrain::new(2, Role::Attacker, 1, bb.clone()).unwrap();
        let mut cmd = RobotCommand::default();
        assert!(!r.kicker(1.0, 0.125, &mut cmd) && cmd.kick.is_none(), "nothing asked");
        bb.set("local.var.kicker.kick", true).unwrap();
        assert!(!r.kicker(1.0, 0.125, &mut cmd));
        assert_eq!(cmd.kick, Some(1));
        assert_eq!(bb.get::<bool>("local.var.kicker.kick"), Ok(false), "cleared");
        let mut cmd = RobotCommand::default();
        assert!(!r.kicker(1.1, 0.125, &mut cmd) && cmd.kick == Some(1), "still open");
        let mut cmd = RobotCommand::default();
        assert!(r.kicker(1.2, 0.125, &mut cmd), "kb(): the pulse ended");
        assert!(cmd.kick.is_none());
    }

    /// Lined up 2 m before the opponent's goal with the ball at its kicker, an attacker runs
    /// and kicks: RUN_AND_KICK, and the kick command in the same cycle.
    #[test]
    fn an_attacker_lined_up_before_the_goal_kicks() {
        let clock = Arc::new(SimClock::new());
        let mut r = IsocrobBrain::new(2, Role::Attacker, 1, board(2, &clock)).unwrap();
        let me = Pose2::new(7.0, 0.0, 0.0);
        let w = world(0.0, me, (7.35, 0.0));
        r.cycle(&w); // APPROACH_BALL → FACE_GOAL (near, before it)
        r.cycle(&w); // FACE_GOAL → RUN_AND_KICK (facing the goal)
        assert_eq!(r.state(), AttackerState::RunAndKick);
        let c = r.cycle(&w);
        assert_eq!(c.kick, Some(1), "{c:?}");
        assert!(c.twist.vx > 0.0);
    }

    /// Attacker 2 of its team with the Machine's parameter `name` set to `value` on its
    /// blackboard (over `config.dat`'s).
    fn attacker_with(name: &str, value: f64) -> IsocrobBrain {
        robot_with(Role::Attacker, 1, name, value).0
    }

    /// Robot 2 of its team playing `role` as field player `index`, with the Machine's
    /// parameter `name` set to `value`, and its blackboard.
    fn robot_with(role: Role, index: usize, name: &str, value: f64) -> (IsocrobBrain, Blackboard) {
        let bb = board(2, &Arc::new(SimClock::new()));
        let r = IsocrobBrain::new(2, role, index, bb.clone()).unwrap();
        bb.set(&format!("local.var.machine.config.{name}"), value).unwrap();
        (r, bb)
    }

    /// With `kick-reach` at the kicker's reach (0.45 m), in RUN_AND_KICK with the ball 0.65 m
    /// ahead (near, but beyond that reach) the attacker pushes on without firing: a pulse
    /// then would miss the ball and leave the solenoid recharging when the ball does reach
    /// the kicker.
    #[test]
    fn an_attacker_kicks_only_a_ball_within_the_kickers_reach() {
        let mut r = attacker_with("kick-reach", 0.45);
        let me = Pose2::new(7.0, 0.0, 0.0);
        let far = world(0.0, me, (7.65, 0.0));
        r.cycle(&far); // APPROACH_BALL → FACE_GOAL (near, before it)
        r.cycle(&far); // FACE_GOAL → RUN_AND_KICK (facing the goal)
        assert_eq!(r.state(), AttackerState::RunAndKick);
        let c = r.cycle(&far);
        assert_eq!((c.kick, r.state()), (None, AttackerState::RunAndKick), "{c:?}");
        assert!(c.twist.vx > 0.0, "pushes on: {c:?}");
        let c = r.cycle(&world(0.1, me, (7.4, 0.0)));
        assert_eq!(c.kick, Some(1), "within reach: {c:?}");
    }

    /// With `orbit` 0.6 m, FACE_GOAL goes round the ball facing it: a robot beside the ball
    /// heads for a point on the circle round it (not straight for the posture behind it)
    /// and turns to the ball, which stays before its camera.
    #[test]
    fn face_goal_goes_round_the_ball_facing_it() {
        let mut r = attacker_with("orbit", 0.6);
        // The ball 0.6 m to the robot's left; the robot faces up the field, the goal ahead.
        let me = Pose2::new(0.0, 0.0, 0.0);
        let w = world(0.0, me, (0.0, 0.6));
        r.cycle(&w); // APPROACH_BALL: not yet before it, so no FACE_GOAL
        let mut w = w;
        w.my_pos.pose.inner.theta = std::f64::consts::FRAC_PI_2;
        w.lps[lps::BALL].theta = 0.0;
        w.lps[lps::NET1].theta -= std::f64::consts::FRAC_PI_2;
        r.cycle(&w); // facing the ball: FACE_GOAL
        assert_eq!(r.state(), AttackerState::FaceGoal);
        let c = r.cycle(&w);
        assert_eq!(r.state(), AttackerState::FaceGoal);
        assert!(c.twist.omega.abs() < 1e-9, "keeps facing the ball: {c:?}");
        // By hand: the posture is 0.35 m behind the ball, at about (−0.349, 0.623) m; the
        // robot is at −90° about the ball and the posture at about 176°, the shorter way
        // clockwise. The waypoint is 0.6 rad on, at −124° on the 0.6 m circle: (−0.339,
        // 0.105) m, in the robot's frame (facing +y) 0.105 m ahead and 0.339 m to its left.
        assert!(c.twist.vy > 0.0 && c.twist.vx > 0.0, "{c:?}");
        assert!((c.twist.vx / c.twist.vy - 0.105 / 0.339).abs() < 0.02, "{c:?}");
    }

    /// With `ahead` 0.3 rad, FACE_GOAL hands over to RUN_AND_KICK only when the robot faces
    /// the goal with the ball before its kicker: facing the goal with the ball 0.5 rad to the
    /// side it goes on round; without `ahead` it would run with the ball beside it and push
    /// it off sideways.
    #[test]
    fn face_goal_runs_only_with_the_ball_before_the_kicker() {
        let me = Pose2::new(0.0, 0.0, 0.0);
        let beside = (0.4 * 0.5f64.cos(), 0.4 * 0.5f64.sin());
        let mut plain = attacker_with("ahead", 0.0);
        plain.cycle(&world(0.0, me, beside)); // APPROACH_BALL → FACE_GOAL (near, within 0.6)
        plain.cycle(&world(0.1, me, beside));
        assert_eq!(plain.state(), AttackerState::RunAndKick, "the seed's ffog alone");
        let mut r = attacker_with("ahead", 0.3);
        r.cycle(&world(0.0, me, beside));
        r.cycle(&world(0.1, me, beside));
        assert_eq!(r.state(), AttackerState::FaceGoal, "the ball beside the kicker");
        r.cycle(&world(0.2, me, (0.4, 0.04)));
        assert_eq!(r.state(), AttackerState::RunAndKick, "the ball before it");
    }

    /// A robot of the team that waits in SHOULD_I_GO (a teammate posted a better heuristic)
    /// while the team believes the ball is at (−3, 3) m, and where it heads.
    fn waiting_at(role: Role, index: usize, name: &str, value: f64) -> Pose2 {
        let (mut r, bb) = robot_with(role, index, name, value);
        bb.set(&format!("{HEURISTIC}9"), -10.0).unwrap();
        let mut w = world(0.0, Pose2::new(-1.0, -3.0, 0.0), (-3.0, 3.0));
        w.global_ball.pose = Framed::new(Pose2::new(-3.0, 3.0, 0.0));
        w.global_ball.quality = 0.5;
        r.cycle(&w);
        let c = r.cycle(&w);
        assert_eq!(r.state(), AttackerState::ShouldIGo);
        c.target.unwrap().pose.inner
    }

    /// With `def.guard` 0.33, the defender waits on the line from the centre of its own goal
    /// (−9, 0) m to the ball, a third of the way out: by hand, (−9, 0) + 0.33·(6, 3) =
    /// (−7.02, 0.99) m. Without it, at its fixed home (−5 m, in its lane).
    #[test]
    fn the_defender_guards_the_line_from_its_goal_to_the_ball() {
        let t = waiting_at(Role::Defender, 0, "def.guard", 0.33);
        assert!((t.x + 7.02).abs() < 1e-9 && (t.y - 0.99).abs() < 1e-9, "{t:?}");
        let t = waiting_at(Role::Defender, 0, "def.guard", 0.0);
        assert!((t.x + 5.0).abs() < 1e-9 && (t.y - 1.25).abs() < 1e-9, "{t:?}");
    }

    /// With `att.support` 2 m, an attacker not going for the ball waits 2 m ahead of where
    /// the team believes it is (x = −3 + 2 = −1 m), in its lane (index 1: 1.25 m to the right);
    /// with −1.5 m, 1.5 m behind it.
    #[test]
    fn an_attacker_waits_ahead_of_the_ball_to_support() {
        let t = waiting_at(Role::Attacker, 1, "att.support", 2.0);
        assert!((t.x + 1.0).abs() < 1e-9 && (t.y + 1.25).abs() < 1e-9, "{t:?}");
        let t = waiting_at(Role::Attacker, 1, "att.support", -1.5);
        assert!((t.x + 4.5).abs() < 1e-9 && (t.y + 1.25).abs() < 1e-9, "{t:?}");
    }

    /// The goalkeeper stands on its axis (0.4 m before its goal line) in front of the ball,
    /// and posts its mode.
    #[test]
    fn the_goalkeeper_stands_before_the_ball_on_its_axis() {
        let clock = Arc::new(SimClock::new());
        let bb = board(1, &clock);
        let mut r = IsocrobBrain::new(1, Role::Goalkeeper, 0, bb.clone()).unwrap();
        let me = Pose2::new(-8.6, 0.0, 0.0);
        let c = r.cycle(&world(0.0, me, (-5.0, 0.5)));
        let t = c.target.unwrap().pose.inner;
        assert!((t.x + 8.6).abs() < 1e-9 && (t.y - 0.5).abs() < 1e-9, "{t:?}");
        assert_eq!(bb.get::<String>("local.var.machine.state").unwrap(), "FOLLOW");
        assert_eq!(bb.get::<String>("local.var.machine.role").unwrap(), "goalkeeper");
    }
}
