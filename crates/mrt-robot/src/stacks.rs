//! The teams: which behavior stack drives which robot.
//!
//! - **Chaos**: TeamChaos' Lua stack (`behaviors/teamchaos`): the goalkeeper hierarchy of fuzzy
//!   behaviors for robot 0, the `player.hfsm.lua` machine (the seed's Attacker inside a game
//!   loop) for the field players. The files are compiled into the binary, so a match needs no
//!   setup; `--behaviors DIR` runs edited copies instead.
//! - **Milan**: the MRT manual's team on Mr. BRIAN (`configs/brian/milan`, compiled in):
//!   [`MilanBrain`] is the manual's Parser and Messenger around the engine.
//! - **ISocRob**: the Machine µAgent's roles on a blackboard shared through the Proxy
//!   ([`crate::isocrob::IsocrobBrain`], `configs/isocrob/config.dat`, compiled in).
//! - **Chaser**: the hand-written baseline player ([`Chaser`]).
//!
//! TeamChaos tuned its behaviors for AIBO walking speeds (about 0.3 m/s); on a Middle Size
//! League base its `hbm.lua` scales the speeds and the
//! [`Commander`](crate::commander::Commander) shifts the distances to the body.

use crate::brain::Brain;
use crate::config::RobotConfig;
use crate::error::RobotError;
use crate::files::FilesDir;
use crate::spec::Stack;
use mrt_core::frames::{millimetres, twist_from_setpoints};
use mrt_core::{Point2, Pose2, Twist};
use mrt_fuzzy::brian::Brian;
use mrt_msgs::robot::{lps, Field, GameState, Lpo, RobotCommand, Target, WorldSnapshot};
use mrt_plan::guidance::behind_ball;
use std::path::Path;

/// The TeamChaos behavior files, compiled in.
const TEAMCHAOS: &[(&str, &str)] = &[
    ("alignbnet1.lua", include_str!("../../../behaviors/teamchaos/alignbnet1.lua")),
    ("attacker.hfsm.lua", include_str!("../../../behaviors/teamchaos/attacker.hfsm.lua")),
    ("dokick.lua", include_str!("../../../behaviors/teamchaos/dokick.lua")),
    ("faceball.lua", include_str!("../../../behaviors/teamchaos/faceball.lua")),
    ("gkclearb.lua", include_str!("../../../behaviors/teamchaos/gkclearb.lua")),
    ("gkcutb.lua", include_str!("../../../behaviors/teamchaos/gkcutb.lua")),
    ("gkkeeparea.lua", include_str!("../../../behaviors/teamchaos/gkkeeparea.lua")),
    ("gkkeepbarea.lua", include_str!("../../../behaviors/teamchaos/gkkeepbarea.lua")),
    ("gkkeepout.lua", include_str!("../../../behaviors/teamchaos/gkkeepout.lua")),
    ("gklocalize.lua", include_str!("../../../behaviors/teamchaos/gklocalize.lua")),
    ("gkscanobj.lua", include_str!("../../../behaviors/teamchaos/gkscanobj.lua")),
    ("gktracklms.lua", include_str!("../../../behaviors/teamchaos/gktracklms.lua")),
    ("go2ball.lua", include_str!("../../../behaviors/teamchaos/go2ball.lua")),
    ("gotopos.lua", include_str!("../../../behaviors/teamchaos/gotopos.lua")),
    ("goalkeeper.lua", include_str!("../../../behaviors/teamchaos/goalkeeper.lua")),
    ("hbm.lua", include_str!("../../../behaviors/teamchaos/hbm.lua")),
    ("lookball.lua", include_str!("../../../behaviors/teamchaos/lookball.lua")),
    ("player.hfsm.lua", include_str!("../../../behaviors/teamchaos/player.hfsm.lua")),
    ("ready.lua", include_str!("../../../behaviors/teamchaos/ready.lua")),
    ("stand.lua", include_str!("../../../behaviors/teamchaos/stand.lua")),
    ("trackbnet1.lua", include_str!("../../../behaviors/teamchaos/trackbnet1.lua")),
];

/// Team Milan's Mr. BRIAN configuration, compiled in.
const MILAN: &[(&str, &str)] = &[
    ("Cando.ini", include_str!("../../../configs/brian/milan/Cando.ini")),
    ("Predicate.ini", include_str!("../../../configs/brian/milan/Predicate.ini")),
    ("PredicateActions.ini", include_str!("../../../configs/brian/milan/PredicateActions.ini")),
    ("behavior.txt", include_str!("../../../configs/brian/milan/behavior.txt")),
    (
        "behaviors/AvoidObstacle.rul",
        include_str!("../../../configs/brian/milan/behaviors/AvoidObstacle.rul"),
    ),
    ("behaviors/GoToBall.rul", include_str!("../../../configs/brian/milan/behaviors/GoToBall.rul")),
    (
        "behaviors/HoldPosition.rul",
        include_str!("../../../configs/brian/milan/behaviors/HoldPosition.rul"),
    ),
    ("behaviors/KeepGoal.rul", include_str!("../../../configs/brian/milan/behaviors/KeepGoal.rul")),
    ("behaviors/KickBall.rul", include_str!("../../../configs/brian/milan/behaviors/KickBall.rul")),
    (
        "behaviors/SearchBall.rul",
        include_str!("../../../configs/brian/milan/behaviors/SearchBall.rul"),
    ),
    ("ctof.txt", include_str!("../../../configs/brian/milan/ctof.txt")),
    ("s_ftoc.txt", include_str!("../../../configs/brian/milan/s_ftoc.txt")),
    ("s_shape.txt", include_str!("../../../configs/brian/milan/s_shape.txt")),
    ("shape_ctof.txt", include_str!("../../../configs/brian/milan/shape_ctof.txt")),
    ("want.txt", include_str!("../../../configs/brian/milan/want.txt")),
];

/// How far round the ball [`Geometry::orbit`] aims ahead of the robot, rad: small enough that
/// the chord to the waypoint stays well outside the ball's circle (at 0.6 rad it passes at
/// 96 % of the radius).
pub const ORBIT_STEP: f64 = 0.6;

/// The field as the teams need it, in the team frame (m), from the snapshot's field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    /// From the centre spot to a goal line.
    pub half_length: f64,
    /// From the middle of a goal to a post.
    pub goal_half_width: f64,
}

impl Geometry {
    /// The geometry of the field a world snapshot carries (the world model's map: behaviors
    /// never read a simulator's configuration).
    pub fn of(field: &Field) -> Geometry {
        Geometry { half_length: field.half_length, goal_half_width: field.goal_half_width }
    }

    /// Where the ball is in the team frame (m), from the robot's pose and its LPS ball.
    pub fn ball_at(me: Pose2, ball: &Lpo) -> (f64, f64) {
        let a = me.theta + ball.theta;
        (me.x + ball.rho * a.cos(), me.y + ball.rho * a.sin())
    }

    /// The posture `distance` m behind the ball on the line from the opponent's net, facing
    /// the net ([`behind_ball`]); with the ball on the net's centre, simply `distance` short of
    /// it, facing the net.
    pub fn behind_ball(&self, ball: (f64, f64), distance: f64) -> Pose2 {
        self.behind_ball_aiming(ball, 0.0, distance)
    }

    /// [`Geometry::behind_ball`] for a shot at `aim` m along the opponent's goal line (0:
    /// its centre).
    pub fn behind_ball_aiming(&self, ball: (f64, f64), aim: f64, distance: f64) -> Pose2 {
        let (b, goal) = (Point2::new(ball.0, ball.1), Point2::new(self.half_length, aim));
        behind_ball(b, goal, distance).unwrap_or(Pose2::new(ball.0 - distance, ball.1, 0.0))
    }

    /// Where to go to get `behind` the ball (a posture from [`Geometry::behind_ball`]): the
    /// posture's point itself, or, for a robot at `me` in front of the ball (ahead of it along
    /// the posture's heading), that point 0.6 m to the robot's side, so that it steps round
    /// the ball instead of driving back through it.
    pub fn step_round(me: Pose2, ball: (f64, f64), behind: Pose2) -> (f64, f64) {
        let (ux, uy) = (behind.theta.cos(), behind.theta.sin());
        let (rx, ry) = (ball.0 - me.x, ball.1 - me.y);
        let (mut px, mut py) = (behind.x, behind.y);
        if rx * ux + ry * uy < 0.0 {
            let side = if (me.x - ball.0) * uy - (me.y - ball.1) * ux > 0.0 { 1.0 } else { -1.0 };
            px += side * 0.6 * uy;
            py -= side * 0.6 * ux;
        }
        (px, py)
    }

    /// Where to go to reach `behind` (a posture from [`Geometry::behind_ball`]) round the
    /// ball, `radius` m from it: along that circle the shorter way, at most [`ORBIT_STEP`]
    /// ahead of the robot's own angle about the ball, and straight to the posture once the
    /// robot is within [`ORBIT_STEP`] of it. A robot that faces the ball on the way keeps it
    /// before its camera and never sweeps it along with its front (ISocRob's FACE_GOAL with a
    /// 63° front camera).
    pub fn orbit(me: Pose2, ball: (f64, f64), behind: Pose2, radius: f64) -> (f64, f64) {
        let mine = (me.y - ball.1).atan2(me.x - ball.0);
        let goal = (behind.y - ball.1).atan2(behind.x - ball.0);
        let turn = mrt_core::normalize_angle(goal - mine);
        if turn.abs() <= ORBIT_STEP {
            return (behind.x, behind.y);
        }
        let a = mine + ORBIT_STEP.copysign(turn);
        (ball.0 + radius * a.cos(), ball.1 + radius * a.sin())
    }

    /// Whether a ball at `b` (team frame, m) lies in a dead corner: within
    /// [`CORNER_DEPTH`] of the opponent's goal line and wide of a post by more than a ball's radius,
    /// where no shot at the net goes in.
    pub fn dead_corner(&self, (bx, by): (f64, f64)) -> bool {
        bx > self.half_length - CORNER_DEPTH && by.abs() > self.goal_half_width + 0.1
    }

    /// Where along the opponent's goal line to shoot (m from its centre): the open side,
    /// away from the robot the world model anchored nearest the goal's centre (within 1.5 m,
    /// not a teammate: the goalkeeper), two thirds of the way to the post; the centre when no
    /// such robot is known.
    pub fn open_side(&self, w: &WorldSnapshot) -> f64 {
        let keeper = w
            .opponents(WorldSnapshot::ANCHORED)
            .map(|r| (r, (r.at.inner.x - self.half_length).hypot(r.at.inner.y)))
            .filter(|(_, d)| *d < 1.5)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match keeper {
            Some((k, _)) if k.at.inner.y < 0.0 => 2.0 / 3.0 * self.goal_half_width,
            Some(_) => -2.0 / 3.0 * self.goal_half_width,
            None => 0.0,
        }
    }
}

/// The compiled-in TeamChaos files, as a directory while the handle (or a clone) lives.
pub fn embedded_teamchaos() -> Result<FilesDir, RobotError> {
    crate::files::embedded("teamchaos", TEAMCHAOS)
}

/// The compiled-in Team Milan configuration, as a directory while the handle lives.
pub fn embedded_milan() -> Result<FilesDir, RobotError> {
    crate::files::embedded("milan", MILAN)
}

/// The Chaos goalkeeper's behavior.
pub const CHAOS_KEEPER: &str = "goalkeeper";
/// The Chaos field players' machine file.
pub const CHAOS_PLAYER: &str = "player.hfsm.lua";

/// A robot driven by Mr. BRIAN: the manual's Parser turns the world snapshot into crisp
/// inputs `(name, value, reliability)`, the engine runs one cycle, the Messenger turns
/// `SpeedModule`/`SpeedAngle` (a holonomic direction of motion), `Rotation` and `Kick` into
/// the robot command.
pub struct MilanBrain {
    brian: Brian,
    keeper: bool,
    /// When the robot last saw the ball, or started (s of the snapshots' clock).
    ball_seen_at: Option<f64>,
}

/// How far behind the opponent's goal line (m) the point lies that a Milan robot lines the
/// ball up with for a shot.
pub const SHOOT_THROUGH: f64 = 0.5;

/// How deep (m) the dead corners by the opponent's goal line reach into the field.
pub const CORNER_DEPTH: f64 = 1.0;

/// How far in front of the opponent's goal line (m) a ball is dribbled out of a dead corner.
pub const CORNER_WAY_OUT: f64 = 1.5;

/// After this long (s) without the ball, more than one turn on the spot, a Milan robot that
/// no teammate tells where the ball is counts it as lost (`BallLost`).
pub const BALL_LOST_AFTER: f64 = 3.0;

/// Degrees in [0, 360) of an angle in radians.
fn deg360(a: f64) -> f64 {
    a.to_degrees().rem_euclid(360.0)
}

impl MilanBrain {
    /// The goalkeeper or a field player, on the configuration of `dir`.
    pub fn new(dir: &Path, keeper: bool) -> Result<MilanBrain, RobotError> {
        Ok(MilanBrain { brian: Brian::from_dir(dir)?, keeper, ball_seen_at: None })
    }

    /// The Parser: crisp inputs from the world snapshot, in the units of Mr. BRIAN's files
    /// (team frame; distances in mm, angles in degrees). The geometry is worked out in metres
    /// and each distance converted where it becomes an input.
    pub fn inputs(&self, w: &WorldSnapshot) -> Vec<(&'static str, f64, f64)> {
        let me = w.my_pos.pose.inner;
        let q = w.my_pos.quality;
        let field = Geometry::of(&w.field);
        let mut v = vec![("Keeper", f64::from(u8::from(self.keeper)), 1.0), ("Always", 1.0, 1.0)];
        v.push(("HeadingBearing", deg360(me.theta), q));
        // The centre spot, from where the robot believes it is: a search goes there, from
        // where every spot of the field is within a camera's reach.
        v.push(("CentreDistance", millimetres(me.x.hypot(me.y)), q));
        v.push(("CentreAngle", deg360((-me.y).atan2(-me.x) - me.theta), q));
        let now = w.time.as_secs_f64();
        let unseen = now - self.ball_seen_at.unwrap_or(now);
        let lost = unseen >= BALL_LOST_AFTER && w.global_ball.quality < 0.3;
        v.push(("BallLost", f64::from(u8::from(lost)), 1.0));
        // SCARE's job (MRT manual ch. 11 and §2.3: goals for the parametric behaviors). A
        // robot without one plays the ball, as the team did before SCARE.
        let job = w.job.as_ref();
        let flag = |b: bool| f64::from(u8::from(b));
        v.push(("PlayBall", flag(job.is_none_or(|j| j.aim.is_some())), 1.0));
        let ball = w.lps[lps::BALL];
        let ball_at = (ball.reliability >= 0.1).then(|| Geometry::ball_at(me, &ball));
        // A ball by the opponent's goal line wide of a post, where no shot goes in: it is
        // dribbled back out in front of the goal, not kicked (a kick would send it out).
        let corner = ball_at.is_some_and(|b| field.dead_corner(b));
        v.push(("KickAllowed", flag(job.is_none_or(|j| j.kick) && !corner), 1.0));
        v.push(("HoldPosition", flag(job.is_some_and(|j| j.position.is_some())), 1.0));
        if let Some(p) = job.and_then(|j| j.position) {
            let (dx, dy) = (p.inner.x - me.x, p.inner.y - me.y);
            v.push(("PositionDistance", millimetres(dx.hypot(dy)), q));
            v.push(("PositionAngle", deg360(dy.atan2(dx) - me.theta), q));
        }
        if let Some((bx, by)) = ball_at {
            let r = ball.reliability;
            v.push(("BallDistance", millimetres(ball.rho), r));
            v.push(("BallBearing", deg360(ball.theta), r));
            // The ball and the point 0.4 m behind it on the line from where it should go:
            // the job's aim (the net's open side, or a mate for a pass), or out of a dead
            // corner the spot in front of the goal.
            let aim = job
                .and_then(|j| j.aim)
                .map_or((field.half_length, field.open_side(w)), |a| (a.inner.x, a.inner.y));
            let aim = if corner { (field.half_length - CORNER_WAY_OUT, 0.0) } else { aim };
            let at_net = (aim.0 - field.half_length).abs() < 1e-3;
            // At the net the ball is lined up with a point behind the goal line, so that a
            // ball that stopped on the line itself is still pushed in, not along it.
            let through = if at_net { aim.0 + SHOOT_THROUGH } else { aim.0 };
            let spot = behind_ball(Point2::new(bx, by), Point2::new(through, aim.1), 0.4)
                .unwrap_or(Pose2::new(bx - 0.4, by, 0.0));
            // How far (degrees) the kick, along the robot's heading, would miss what it aims
            // at: the goal mouth less a ball's margin at each post for a shot at the net, a
            // 0.8 m wide target round a mate for a pass; 0 on target. In the own third any
            // kick that clears the ball forwards will do (from farther up, one that misses
            // the goal sends the ball out over its line).
            let miss = if at_net && bx < -field.half_length / 3.0 {
                0.0
            } else {
                let (mid, half) = if at_net {
                    let off = (field.goal_half_width - 0.25).max(0.0);
                    let lo = ((aim.1 - off).max(-off) - by).atan2(aim.0 - bx);
                    let hi = ((aim.1 + off).min(off) - by).atan2(aim.0 - bx);
                    (0.5 * (lo + hi), 0.5 * (hi - lo).abs())
                } else {
                    let d = (aim.0 - bx).hypot(aim.1 - by).max(1e-3);
                    ((aim.1 - by).atan2(aim.0 - bx), (0.4 / d).atan())
                };
                mrt_core::normalize_angle(me.theta - mid).abs() - half
            };
            v.push(("AimError", miss.max(0.0).to_degrees(), r));
            let (tx, ty) = Geometry::step_round(me, (bx, by), spot);
            let (dx, dy) = (tx - me.x, ty - me.y);
            v.push(("ApproachDistance", millimetres(dx.hypot(dy)), r));
            v.push(("ApproachAngle", deg360(dy.atan2(dx) - me.theta), r));
            let a = me.theta + ball.theta;
            let mis = mrt_core::normalize_angle(a - spot.theta).abs().to_degrees();
            v.push(("Misalignment", mis, r));
        }
        if self.keeper {
            // The keeper's spot: 0.3 m out of the goal line, level with the ball within the
            // posts (the middle of the goal when the ball is not seen); it faces the ball.
            let gw = field.goal_half_width;
            let y = ball_at.map_or(0.0, |b| b.1);
            let (kx, ky) = (-field.half_length + 0.3, y.clamp(-(gw - 0.1), gw - 0.1));
            let (dx, dy) = (kx - me.x, ky - me.y);
            v.push(("KeeperSpotDistance", millimetres(dx.hypot(dy)), q));
            v.push(("KeeperSpotAngle", deg360(dy.atan2(dx) - me.theta), q));
        }
        let nearest = w
            .mates
            .iter()
            .map(|m| (m.at.pose.inner.x - me.x, m.at.pose.inner.y - me.y))
            .min_by(|a, b| a.0.hypot(a.1).total_cmp(&b.0.hypot(b.1)));
        if let Some((dx, dy)) = nearest {
            v.push(("ObstacleDistance", millimetres(dx.hypot(dy)), 1.0));
            v.push(("ObstacleBearing", deg360(dy.atan2(dx) - me.theta), 1.0));
        }
        // The robots MAP anchored (MRT manual ch. 8): the nearest opponent, and the free
        // direction nearest to the opponent's net (where it is by the robot's own pose).
        if let Some(o) = w.nearest_opponent(WorldSnapshot::ANCHORED) {
            v.push(("OpponentDistance", millimetres(o.rho), o.reliability));
            v.push(("OpponentBearing", deg360(o.theta), o.reliability));
        }
        let net = (field.half_length - me.x, -me.y);
        let toward = net.1.atan2(net.0) - me.theta;
        if let Some(free) = w.free_direction(
            toward,
            WorldSnapshot::FREE_REACH,
            WorldSnapshot::FREE_CLEARANCE,
            WorldSnapshot::ANCHORED,
        ) {
            v.push(("FreeDirection", deg360(free), q));
        }
        v
    }
}

impl Brain for MilanBrain {
    fn cycle(&mut self, w: &WorldSnapshot) -> RobotCommand {
        // The game state is the Messenger's: in READY, walk to the kickoff position.
        if let Some(c) = walk_to_kickoff(w) {
            return c;
        }
        let now = w.time.as_secs_f64();
        if self.ball_seen_at.is_none() || w.lps[lps::BALL].reliability >= 0.1 {
            self.ball_seen_at = Some(now);
        }
        let inputs = self.inputs(w);
        let out = self.brian.run(&inputs);
        let mut c = RobotCommand::default();
        // Mr. BRIAN's outputs: SpeedModule mm/s, SpeedAngle degrees, Rotation degrees/s.
        let speed = out.get("SpeedModule").copied().unwrap_or(0.0);
        let dir = out.get("SpeedAngle").copied().unwrap_or(0.0).to_radians();
        let rotation = out.get("Rotation").copied().unwrap_or(0.0);
        c.twist = twist_from_setpoints(speed * dir.cos(), speed * dir.sin(), rotation);
        if out.get("Kick").is_some_and(|k| *k > 0.5) {
            c.kick = Some(1);
        }
        c.needs.push((lps::BALL, 1.0));
        c
    }

    /// Each Mr. BRIAN behavior's WANT when its CANDO let it run, 0 when it did not.
    fn activations(&self) -> Vec<(String, f64)> {
        let trace = self.brian.trace();
        trace
            .behaviors
            .iter()
            .map(|(name, _, activity)| (name.to_string(), activity.map_or(0.0, |(_, w)| w.value)))
            .collect()
    }
}

/// The brains of one team of `size` robots (robot 0 keeps goal) of a stack that runs as a
/// brain (Milan, the Chaser). TeamChaos and ISocRob run as Members of their own
/// (`members::add_robot`).
pub fn team(stack: Stack, cfg: &RobotConfig) -> Result<Vec<Box<dyn Brain + Send>>, RobotError> {
    (0..cfg.team_size).map(|i| send_brain(stack, i == 0)).collect()
}

/// The brain of a Milan or baseline robot (the goalkeeper when `keeper`).
pub fn send_brain(stack: Stack, keeper: bool) -> Result<Box<dyn Brain + Send>, RobotError> {
    match stack {
        Stack::Milan => Ok(Box::new(MilanBrain::new(&embedded_milan()?, keeper)?)),
        Stack::Chaser => Ok(Box::new(Chaser { keeper })),
        Stack::Chaos => Err(RobotError::StackWiring(
            "the Chaos stack runs as its behavior Member (members::add_robot)",
        )),
        Stack::Isocrob => Err(RobotError::StackWiring(
            "an ISocRob robot needs its blackboard and Proxy (members::add_robot)",
        )),
    }
}

/// A simple hand-written player, the baseline: it goes round to a point behind the ball on
/// the line from the opponent's net, then drives through the ball and kicks when it is lined
/// up with the net. The goalkeeper (`keeper`) stays on its goal line in front of the ball.
#[derive(Clone, Debug, Default)]
pub struct Chaser {
    /// Plays as goalkeeper.
    pub keeper: bool,
}

/// The hand-written players' fastest turn, rad/s (200°/s).
pub const MAX_TURN: f64 = 200.0 * std::f64::consts::PI / 180.0;

/// Velocities towards a target point `(tx, ty)` (team frame, m, as the world snapshot gives
/// positions), turning to `face` (rad): the holonomic base's forward and sideways components
/// at up to `max_speed` (m/s), slowing within `max_speed / 2` m of the point, and a turn of
/// 3 rad/s per radian off, at most [`MAX_TURN`]. The hand-written players' way to drive (the
/// Chaser, ISocRob's Machine).
pub fn drive_to(me: Pose2, (tx, ty): (f64, f64), face: f64, max_speed: f64, c: &mut RobotCommand) {
    let (dx, dy) = (tx - me.x, ty - me.y);
    let err = mrt_core::normalize_angle(face - me.theta);
    let omega = (err * 3.0).clamp(-MAX_TURN, MAX_TURN);
    // Move in the robot frame (holonomic base): forward and sideways components, m/s.
    let (s, co) = (me.theta.sin(), me.theta.cos());
    let (fw, left) = (dx * co + dy * s, -dx * s + dy * co);
    let d = dx.hypot(dy).max(1e-3);
    let speed = (d * 2.0).min(max_speed);
    c.twist = Twist::new(fw / d * speed, left / d * speed, omega);
}

impl Chaser {
    /// [`drive_to`] at up to 1.2 m/s.
    fn go(me: Pose2, target: (f64, f64), face: f64, c: &mut RobotCommand) {
        drive_to(me, target, face, 1.2, c);
    }
}

/// In READY, the command that walks to the kickoff position (guidance's potential-field mode,
/// round the other robots), watching the ball; `None` in the other states.
pub fn walk_to_kickoff(w: &WorldSnapshot) -> Option<RobotCommand> {
    let pose = w.kickoff_pose.filter(|_| w.game_state == GameState::Ready)?;
    Some(RobotCommand {
        target: Some(Target { pose, avoid: true, plan: false }),
        needs: vec![(lps::BALL, 1.0)],
        ..RobotCommand::default()
    })
}

impl Brain for Chaser {
    fn cycle(&mut self, w: &WorldSnapshot) -> RobotCommand {
        if let Some(c) = walk_to_kickoff(w) {
            return c;
        }
        let mut c = RobotCommand::default();
        let ball = w.lps[lps::BALL];
        c.needs.push((lps::BALL, 1.0));
        if ball.reliability < 0.2 {
            c.twist.omega = 60f64.to_radians(); // look around
            return c;
        }
        let me = w.my_pos.pose.inner;
        // Ball in the team frame (m); x towards the opponent's net at (half length, 0).
        let field = Geometry::of(&w.field);
        let (hl, gw) = (field.half_length, field.goal_half_width);
        let a = me.theta + ball.theta;
        let (bx, by) = Geometry::ball_at(me, &ball);
        if self.keeper {
            // `validate` keeps goals at least 0.2 m wide; max(0) keeps clamp from panicking.
            let lim = (gw - 0.1).max(0.0);
            let target = (-(hl - 0.3), by.clamp(-lim, lim));
            Chaser::go(me, target, a, &mut c);
        } else {
            let behind = field.behind_ball((bx, by), 0.5);
            let shot = behind.theta;
            let (ux, uy) = (shot.cos(), shot.sin());
            // Lined up: behind the ball, looking at the net.
            let (rx, ry) = (bx - me.x, by - me.y);
            let along = (rx * ux + ry * uy) / rx.hypot(ry).max(1e-3);
            let lined_up = along > 0.9 && ball.rho < 1.5;
            if lined_up {
                Chaser::go(me, (bx + 0.2 * ux, by + 0.2 * uy), shot, &mut c);
                if ball.rho < 0.45
                    && ball.theta.abs() < 0.3
                    && mrt_core::normalize_angle(me.theta - shot).abs() < 0.35
                {
                    c.kick = Some(1);
                }
            } else {
                // Go round: to a point behind the ball, stepping aside first when in front.
                Chaser::go(me, Geometry::step_round(me, (bx, by), behind), a, &mut c);
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::frames::Framed;
    use mrt_msgs::{AnchoredRobot, RobotClass};

    #[test]
    fn orbit_goes_round_the_ball_the_shorter_way_and_never_through_it() {
        use std::f64::consts::PI;
        let g = Geometry { half_length: 9.0, goal_half_width: 1.0 };
        let ball = (0.0, 0.0);
        let behind = g.behind_ball(ball, 0.35);
        assert!((behind.x + 0.35).abs() < 1e-12 && behind.y.abs() < 1e-12);
        // In front of the ball (between it and the opponent's net), a little to its left:
        // round by the left, 0.6 rad further about the ball, on the 0.6 m circle.
        let me = Pose2::new(0.6 * 0.1f64.cos(), 0.6 * 0.1f64.sin(), PI);
        let (x, y) = Geometry::orbit(me, ball, behind, 0.6);
        assert!((x.hypot(y) - 0.6).abs() < 1e-12);
        assert!((y.atan2(x) - 0.7).abs() < 1e-9, "{x} {y}");
        // Mirrored: round by the right.
        let me = Pose2::new(me.x, -me.y, PI);
        let (_, y) = Geometry::orbit(me, ball, behind, 0.6);
        assert!(y < 0.0);
        // Close to the posture's side of the ball: straight to the posture.
        let me = Pose2::new(-0.7, 0.2, 0.0);
        assert_eq!(Geometry::orbit(me, ball, behind, 0.6), (behind.x, behind.y));
        // Followed step by step from anywhere round the ball, the path reaches the posture
        // and never comes nearer the ball than 90 % of the radius.
        for k in 0..36 {
            let a = f64::from(k) * PI / 18.0;
            let mut me = Pose2::new(1.5 * a.cos(), 1.5 * a.sin(), 0.0);
            let mut nearest = f64::INFINITY;
            for _ in 0..2000 {
                let (tx, ty) = Geometry::orbit(me, ball, behind, 0.6);
                let (dx, dy) = (tx - me.x, ty - me.y);
                let d = dx.hypot(dy);
                if d < 1e-3 {
                    break;
                }
                let step = d.min(0.01);
                me = Pose2::new(me.x + dx / d * step, me.y + dy / d * step, 0.0);
                nearest = nearest.min(me.x.hypot(me.y));
            }
            assert!((me.x - behind.x).hypot(me.y - behind.y) < 1e-3, "from {a} rad: {me:?}");
            assert!(nearest > 0.9 * 0.35, "from {a} rad: {nearest} m from the ball");
        }
    }

    /// The Parser gives Mr. BRIAN the robots MAP anchored: the nearest opponent (a teammate
    /// nearer is skipped) and the free direction towards the opponent's net.
    #[test]
    fn milan_reads_the_nearest_opponent_and_the_free_direction() {
        let dir = embedded_milan().unwrap();
        let mut brain = MilanBrain::new(&dir, false).unwrap();
        let mut w = WorldSnapshot::default();
        // At (−3, 0) m facing the opponent's net (east, 12 m away).
        w.my_pos.pose = Framed::new(Pose2::new(-3.0, 0.0, 0.0));
        w.my_pos.quality = 0.9;
        let robot = |class, rho: f64, theta: f64| AnchoredRobot {
            class,
            rho,
            theta,
            reliability: 0.8,
            ..Default::default()
        };
        w.robots =
            vec![robot(RobotClass::Teammate, 0.6, 1.0), robot(RobotClass::Opponent, 0.95, 0.0)];
        let inputs = brain.inputs(&w);
        let get = |name: &str| inputs.iter().find(|(n, _, _)| *n == name).map(|(_, v, r)| (*v, *r));
        // Mr. BRIAN reads distances in mm.
        let (distance, reliability) = get("OpponentDistance").unwrap();
        assert!((distance - 950.0).abs() < 1e-9 && reliability == 0.8, "{distance}");
        assert_eq!(get("OpponentBearing"), Some((0.0, 0.8)));
        // The opponent 0.95 m straight ahead blocks |b| < 31.8° (0.95·sin b < 0.5); the
        // teammate 57° left (0.6 m) blocks 30° to 90° too: the first free bearing on the 5°
        // grid is 35° right.
        let (free, q) = get("FreeDirection").unwrap();
        assert!((free - 325.0).abs() < 1e-6 && q == 0.9, "{free}");
        // Nobody anchored: no opponent input, and the way to the net is free.
        w.robots.clear();
        let inputs = brain.inputs(&w);
        assert!(!inputs.iter().any(|(n, _, _)| *n == "OpponentDistance"));
        let free = inputs.iter().find(|(n, _, _)| *n == "FreeDirection").map(|(_, v, _)| *v);
        assert!(free.is_some_and(|f| f.abs() < 1e-9), "{free:?}");
        // Mr. BRIAN takes every input the Parser gives (they are in ctof.txt).
        let c = brain.cycle(&w);
        assert!(c.twist.vx.is_finite());
    }

    /// A field player that does not see the ball turns on the spot; once it has not seen it
    /// for 3 s and no teammate knows where it is, it walks to the centre spot while it turns,
    /// from where a camera reaches every spot of the field; there it turns on the spot again.
    #[test]
    fn milan_searches_for_a_lost_ball_on_its_way_to_the_centre() {
        use mrt_core::Time;
        use std::f64::consts::{FRAC_PI_2, PI};
        let dir = embedded_milan().unwrap();
        let mut brain = MilanBrain::new(&dir, false).unwrap();
        let mut w = WorldSnapshot { game_state: GameState::Playing, ..Default::default() };
        w.my_pos.quality = 0.9;
        // 6 m east of the centre, facing north: the centre is on its left.
        w.my_pos.pose = Framed::new(Pose2::new(6.0, 0.0, FRAC_PI_2));
        let at = |w: &mut WorldSnapshot, t: f64| w.time = Time::from_secs_f64(t);
        let c = brain.cycle(&w);
        assert!(
            c.twist.vx.hypot(c.twist.vy) < 0.05 && c.twist.omega > 100f64.to_radians(),
            "just lost: turns {c:?}"
        );
        at(&mut w, 3.5);
        let c = brain.cycle(&w);
        assert!(
            c.twist.vy > 0.5 && c.twist.vx.abs() < 0.1 && c.twist.omega > 100f64.to_radians(),
            "{c:?}"
        );
        // Facing the centre: ahead, still turning.
        w.my_pos.pose = Framed::new(Pose2::new(6.0, 0.0, PI));
        let c = brain.cycle(&w);
        assert!(
            c.twist.vx > 0.5 && c.twist.vy.abs() < 0.1 && c.twist.omega > 100f64.to_radians(),
            "{c:?}"
        );
        // A teammate knows where the ball is: no walk.
        w.global_ball.quality = 0.8;
        let c = brain.cycle(&w);
        assert!(c.twist.vx.hypot(c.twist.vy) < 0.05, "{c:?}");
        w.global_ball.quality = 0.0;
        // On the centre spot: it turns where it stands.
        w.my_pos.pose = Framed::new(Pose2::new(0.1, -0.1, 0.3));
        let c = brain.cycle(&w);
        assert!(
            c.twist.vx.hypot(c.twist.vy) < 0.05 && c.twist.omega > 100f64.to_radians(),
            "{c:?}"
        );
        // The ball seen again resets the clock.
        w.lps[lps::BALL] = Lpo { rho: 3.0, theta: 0.5, reliability: 0.9, seen_ago: 0.0 };
        at(&mut w, 4.0);
        brain.cycle(&w);
        w.lps[lps::BALL] = Lpo::default();
        at(&mut w, 5.0);
        w.my_pos.pose = Framed::new(Pose2::new(6.0, 0.0, PI));
        let c = brain.cycle(&w);
        assert!(c.twist.vx.hypot(c.twist.vy) < 0.05, "seen 1 s ago: {c:?}");
    }

    /// A ball by the opponent's goal line wide of a post is dribbled back out towards the
    /// spot in front of the goal, never kicked (no shot from there goes in; a kick sends it
    /// out); in front of the goal the robot may shoot again. A clearance that only needs to
    /// go forwards is for the own third: farther up, a kick must be on target.
    #[test]
    fn milan_dribbles_out_of_a_dead_corner_and_clears_only_from_its_own_third() {
        use std::f64::consts::{FRAC_PI_2, PI};
        let dir = embedded_milan().unwrap();
        let brain = MilanBrain::new(&dir, false).unwrap();
        let mut w = WorldSnapshot::default();
        w.field.half_length = 9.0;
        w.field.goal_half_width = 1.0;
        w.my_pos.quality = 0.9;
        let place = |w: &mut WorldSnapshot, me: Pose2, (bx, by): (f64, f64)| {
            w.my_pos.pose = Framed::new(me);
            let (dx, dy) = (bx - me.x, by - me.y);
            let theta = dy.atan2(dx) - me.theta;
            w.lps[lps::BALL] = Lpo { rho: dx.hypot(dy), theta, reliability: 0.9, seen_ago: 0.0 };
        };
        let get = |w: &WorldSnapshot, name: &str| {
            let inputs = brain.inputs(w);
            inputs.iter().find(|(n, _, _)| *n == name).map(|(_, v, _)| *v)
        };
        // The ball 1.6 m wide of the goal's centre, 0.4 m from the line; the robot behind it
        // on the line from the spot (7.5, 0), facing that spot: no kick, on target.
        let ball: (f64, f64) = (8.6, -1.6);
        let out = ball.1.atan2(ball.0 - 7.5); // from the spot out to the ball
        let me = Pose2::new(ball.0 + 0.4 * out.cos(), ball.1 + 0.4 * out.sin(), out + PI);
        place(&mut w, me, ball);
        assert_eq!(get(&w, "KickAllowed"), Some(0.0));
        assert!(get(&w, "AimError").is_some_and(|e| e < 1e-6), "{:?}", get(&w, "AimError"));
        assert!(get(&w, "Misalignment").is_some_and(|m| m < 1.0));
        // In front of the goal, and 1.2 m out from the line however wide: it may kick.
        for ball in [(8.6, -0.8), (7.7, -1.6)] {
            place(&mut w, Pose2::new(ball.0 - 0.4, ball.1, 0.0), ball);
            assert_eq!(get(&w, "KickAllowed"), Some(1.0), "{ball:?}");
        }
        // A ball stopped on the goal line inside the mouth: the robot is sent in front of
        // it (not along the line), to push it in.
        let ball = (9.0, -0.6);
        place(&mut w, Pose2::new(8.0, -1.0, 0.0), ball);
        let (d, a) = (get(&w, "ApproachDistance").unwrap(), get(&w, "ApproachAngle").unwrap());
        // Mr. BRIAN's units: mm and degrees.
        let (d, a) = (mrt_core::frames::metres(d), a.to_radians());
        let spot = (8.0 + d * a.cos(), -1.0 + d * a.sin());
        assert!(spot.0 < ball.0 - 0.25, "the spot {spot:?} is in front of the line");
        // Facing north with the ball ahead: in the own third a clearance, in the middle
        // third a kick that misses the goal by far.
        place(&mut w, Pose2::new(-5.0, 0.0, FRAC_PI_2), (-5.0, 0.4));
        assert_eq!(get(&w, "AimError"), Some(0.0));
        place(&mut w, Pose2::new(-2.0, 0.0, FRAC_PI_2), (-2.0, 0.4));
        assert!(get(&w, "AimError").is_some_and(|e| e > 60.0), "{:?}", get(&w, "AimError"));
    }

    /// Shot selection: the open side of the opponent's goal, away from its
    /// goalkeeper as the world model anchored it; the centre with no keeper known or with
    /// only a teammate there. Half width 1 m: two thirds is 0.667 m.
    #[test]
    fn milan_aims_at_the_side_of_the_goal_away_from_the_keeper() {
        let mut w = WorldSnapshot::default();
        w.field.half_length = 9.0;
        w.field.goal_half_width = 1.0;
        let field = Geometry::of(&w.field);
        assert_eq!(field.open_side(&w), 0.0);
        let keeper = |class, y: f64| AnchoredRobot {
            class,
            at: Framed::new(Point2::new(8.6, y)),
            reliability: 0.8,
            ..Default::default()
        };
        w.robots = vec![keeper(RobotClass::Opponent, -0.2)];
        assert!((field.open_side(&w) - 2.0 / 3.0).abs() < 1e-12);
        w.robots = vec![keeper(RobotClass::Robot, 0.15)];
        assert!((field.open_side(&w) + 2.0 / 3.0).abs() < 1e-12);
        w.robots = vec![keeper(RobotClass::Teammate, 0.15)];
        assert_eq!(field.open_side(&w), 0.0);
        // The approach spot lines the ball up with the aim: from a ball at (5, 0), the spot
        // 0.4 m behind it looks at (9, 0.667).
        let spot = field.behind_ball_aiming((5.0, 0.0), 2.0 / 3.0, 0.4);
        assert!((spot.theta - (2.0f64 / 3.0).atan2(4.0)).abs() < 1e-12, "{spot:?}");
    }
}
