//! What a robot's behaviors read and write each cycle (ThinkingCap report §3.3): a typed
//! [`WorldSnapshot`] (local perceptual space, global state, team, game state) and a
//! [`RobotCommand`] (velocities, kick, perceptual needs, behavior selection). The world model
//! fills the snapshot; behaviors (Lua or fuzzy) fill the command. Both are SI (m, rad, s) and
//! every position is framed; the behaviors' millimetres and degrees are converted where the
//! behavior APIs read and write them (`mrt_core::frames`).

use mrt_core::frames::{setpoints_of, Framed, Team};
use mrt_core::{Point2, Pose2, Time, Twist, Vec2};
use serde::{Deserialize, Serialize};

/// Indices of the local perceptual space (LPS) objects (`BALL`, `NET1`, ... of chaoslib).
pub mod lps {
    /// The ball.
    pub const BALL: usize = 0;
    /// The opponent's net (the one to score in).
    pub const NET1: usize = 1;
    /// Our own net.
    pub const NET2: usize = 2;
    /// First landmark; landmarks are `LANDMARK0 .. LANDMARK0 + LANDMARKS`.
    pub const LANDMARK0: usize = 3;
    /// Number of landmarks.
    pub const LANDMARKS: usize = 6;
    /// Number of LPS slots.
    pub const COUNT: usize = LANDMARK0 + LANDMARKS;
}

/// A local perceptual object (LPO): an object anchored in the robot's frame, as a distance
/// and a bearing.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Lpo {
    /// Distance from the robot's centre, m.
    pub rho: f64,
    /// Bearing, radians, counter-clockwise (left) positive, 0 straight ahead.
    pub theta: f64,
    /// How much the anchor is to be trusted, 0 (lost) to 1.
    pub reliability: f64,
    /// Seconds since it was last perceived.
    pub seen_ago: f64,
}

/// A global estimate: a pose on the field, in the team frame, and its quality, 0 (unknown) to
/// 1.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Estimate {
    /// The pose in the team frame: metres from the centre spot, x towards the opponent's
    /// net, heading in radians (for the ball, `theta` is unused).
    pub pose: Framed<Team, Pose2>,
    /// Quality, 0 to 1.
    pub quality: f64,
}

/// A teammate as this robot believes it to be.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Mate {
    /// The teammate's player number.
    pub id: u32,
    /// Where it is.
    pub at: Estimate,
    /// Whether it keeps goal (role negotiation leaves the goalkeeper out).
    pub keeper: bool,
}

/// What kind of robot an anchor is: MAP's conceptual model, Robot ▸ {Teammate, Opponent}
/// (MRT manual ch. 8). A robot whose marker was never seen and who is where no teammate says
/// it is stays a generic Robot.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobotClass {
    /// A robot of unknown team.
    #[default]
    Robot,
    /// One of ours.
    Teammate,
    /// One of theirs.
    Opponent,
}

impl RobotClass {
    /// The name scripts see: `robot`, `teammate`, `opponent`.
    pub fn name(self) -> &'static str {
        match self {
            RobotClass::Robot => "robot",
            RobotClass::Teammate => "teammate",
            RobotClass::Opponent => "opponent",
        }
    }
}

/// Another robot anchored by the world model (MAP's anchors, MRT manual ch. 8; TeamChaos'
/// perceptual anchoring, ThinkingCap/TeamChaos report §2.1): a track with an identity that lasts while the robot
/// is seen, is predicted while it is not, and fades.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AnchoredRobot {
    /// The anchor's identity: the same robot keeps it from frame to frame.
    pub id: u32,
    /// Teammate, opponent or unknown.
    pub class: RobotClass,
    /// Its centre in the team frame, m (x towards the opponent's net).
    #[cfg_attr(feature = "schema", schemars(with = "[f64; 2]"))]
    pub at: Framed<Team, Point2>,
    /// Its velocity in the team frame, m/s.
    #[cfg_attr(feature = "schema", schemars(with = "[f64; 2]"))]
    pub velocity: Framed<Team, Vec2>,
    /// One standard deviation of its place, m.
    pub at_sigma: f64,
    /// Distance from this robot's centre to its centre, m (as an [`Lpo`]).
    pub rho: f64,
    /// Its bearing, rad, counter-clockwise positive, 0 straight ahead.
    pub theta: f64,
    /// How much the anchor is to be trusted, 0 to 1: 1 when seen this frame, fading while
    /// unseen.
    pub reliability: f64,
    /// Seconds since it was last perceived.
    pub seen_ago: f64,
}

/// The field as the world model's map knows it (`getField`), in metres: behaviors read their
/// geometry from here instead of assuming one field size.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Field {
    /// From the centre spot to a goal line.
    pub half_length: f64,
    /// From the centre line to a side line.
    pub half_width: f64,
    /// From the middle of a goal to a post.
    pub goal_half_width: f64,
    /// From the goal line to the penalty area's line.
    pub penalty_area_depth: f64,
}

impl Default for Field {
    /// The Middle Size League field of the seeds' time: 18 m x 12 m, goals 2 m wide.
    fn default() -> Self {
        Field { half_length: 9.0, half_width: 6.0, goal_half_width: 1.0, penalty_area_depth: 2.25 }
    }
}

/// The game state set by the referee (`getCurrentState()`).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum GameState {
    /// Before the game.
    #[default]
    Initial,
    /// Robots walk to their kickoff positions.
    Ready,
    /// Robots wait for the kickoff.
    Set,
    /// The game runs.
    Playing,
    /// The half or the game is over.
    Finished,
}

impl GameState {
    /// The name scripts see: `INITIAL`, `READY`, `SET`, `PLAYING`, `FINISHED`.
    pub fn name(self) -> &'static str {
        match self {
            GameState::Initial => "INITIAL",
            GameState::Ready => "READY",
            GameState::Set => "SET",
            GameState::Playing => "PLAYING",
            GameState::Finished => "FINISHED",
        }
    }
}

/// Everything a behavior may read in one cycle.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WorldSnapshot {
    /// When the snapshot was taken.
    pub time: Time,
    /// The LPS, indexed by [`lps`] constants ([`lps::COUNT`] entries).
    pub lps: Vec<Lpo>,
    /// The robot's own global pose (`gsGetMyPos`).
    pub my_pos: Estimate,
    /// The ball's velocity in the team frame, m/s (`getBallVel`).
    #[cfg_attr(feature = "schema", schemars(with = "[f64; 2]"))]
    pub ball_vel: Framed<Team, Vec2>,
    /// The ball's global position (`getGlobalBall`).
    pub global_ball: Estimate,
    /// Teammates (`getMates`).
    pub mates: Vec<Mate>,
    /// Other robots anchored by the world model, teammates and opponents (`getRobots`),
    /// nearest first.
    pub robots: Vec<AnchoredRobot>,
    /// The current role (`getRole`), e.g. `attacker`.
    pub role: String,
    /// Whether this robot holds the ball booking (`haveBookedBall`).
    pub ball_booked: bool,
    /// The game state (`getCurrentState`).
    pub game_state: GameState,
    /// The field (`getField`).
    pub field: Field,
    /// In `READY`: where the referee's kickoff formation wants this robot (team frame,
    /// metres, heading in radians; `getKickoffPose` gives it in mm). `None` in the other
    /// states.
    pub kickoff_pose: Option<Framed<Team, Pose2>>,
    /// Whether the world model needs to localize the robot: the landmarks it sees have
    /// disagreed with its pose for a while (ThinkingCap/TeamChaos report §2.1: a perceptual need for
    /// landmarks; `mrt_world::WorldModel::needs_localization`).
    pub needs_localization: bool,
    /// The SCARE activity this robot was given, its current sub-task and the goal the
    /// sub-task sets (MRT manual ch. 11: "parametric modules ... use coordination information
    /// introduced in MAP by SCARE"); `None` when the robot runs no SCARE.
    pub job: Option<ScareJob>,
}

/// A robot's SCARE activity as its behaviors read it (MRT manual ch. 11, §2.3): names, and
/// the goal of the current sub-task in the team frame (m).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ScareJob {
    /// The activity, e.g. `BringBall`, `PassageToMate`.
    pub activity: String,
    /// In a schema, the robot's functionality (e.g. `receiver`); a job's own name otherwise.
    pub functionality: String,
    /// The current sub-task, e.g. `ReachBall`.
    pub subtask: String,
    /// Where to stand (facing the ball), for position goals.
    #[cfg_attr(feature = "schema", schemars(with = "Option<[f64; 2]>"))]
    pub position: Option<Framed<Team, Point2>>,
    /// Where to play the ball (the net, or a mate), for ball goals.
    #[cfg_attr(feature = "schema", schemars(with = "Option<[f64; 2]>"))]
    pub aim: Option<Framed<Team, Point2>>,
    /// Whether the sub-task kicks the ball (a shot or a pass), not only reaches it.
    pub kick: bool,
}

impl Default for WorldSnapshot {
    /// Nothing seen, nothing known.
    fn default() -> Self {
        Self {
            time: Time::ZERO,
            lps: vec![Lpo::default(); lps::COUNT],
            my_pos: Estimate::default(),
            ball_vel: Framed::new(Vec2::zeros()),
            global_ball: Estimate::default(),
            mates: Vec::new(),
            robots: Vec::new(),
            role: String::new(),
            ball_booked: false,
            game_state: GameState::default(),
            field: Field::default(),
            kickoff_pose: None,
            needs_localization: false,
            job: None,
        }
    }
}

impl WorldSnapshot {
    /// The reliability an anchored robot needs to count for the behaviors' default queries
    /// (`getNearestOpponent`, `getFreeDirection`, Team Milan's inputs): about 1.7 s unseen.
    pub const ANCHORED: f64 = 0.3;
    /// How far ahead the behaviors' free direction looks unless told, m.
    pub const FREE_REACH: f64 = 2.0;
    /// Half the width of the corridor the behaviors' free direction keeps free unless told,
    /// m: two Middle Size robots' radii.
    pub const FREE_CLEARANCE: f64 = 0.5;

    /// The nearest robot that is not known to be a teammate, with at least `min_reliability`
    /// (`getNearestOpponent`): an opponent, or a robot of unknown team (a careful player
    /// treats a robot it cannot place as an opponent).
    pub fn nearest_opponent(&self, min_reliability: f64) -> Option<&AnchoredRobot> {
        self.opponents(min_reliability).min_by(|a, b| a.rho.total_cmp(&b.rho))
    }

    /// The anchored robots not known to be teammates, with at least `min_reliability`:
    /// opponents, and robots of unknown team (treated as opponents).
    pub fn opponents(&self, min_reliability: f64) -> impl Iterator<Item = &AnchoredRobot> {
        self.robots
            .iter()
            .filter(move |r| r.class != RobotClass::Teammate && r.reliability >= min_reliability)
    }

    /// The free direction nearest to `desired` (rad, robot frame; `getFreeDirection`): the
    /// bearing of a corridor `2·clearance` wide (m: this robot's radius plus another's) and
    /// `reach` long (m) in which no anchored robot of at least `min_reliability` stands.
    /// Bearings are tried every 5° outwards from `desired`, left before right; `None` when
    /// every one is blocked.
    pub fn free_direction(
        &self,
        desired: f64,
        reach: f64,
        clearance: f64,
        min_reliability: f64,
    ) -> Option<f64> {
        const STEP: f64 = std::f64::consts::PI / 36.0;
        let blocks = |bearing: f64| {
            self.robots.iter().filter(|r| r.reliability >= min_reliability).any(|r| {
                let (s, c) = (r.theta - bearing).sin_cos();
                let (along, lateral) = (r.rho * c, (r.rho * s).abs());
                along > 0.0 && along < reach + clearance && lateral < clearance
            })
        };
        (0..=36)
            .flat_map(|k| [k, -k])
            .map(|k| mrt_core::normalize_angle(desired + f64::from(k) * STEP))
            .find(|&b| !blocks(b))
    }
}

/// Everything a behavior may ask for in one cycle. Fields not set keep their defaults
/// (standing still, no kick, no needs). SI like the rest of the bus: the behaviors' own units
/// (`setVlin` in mm/s, `setVrot` in degrees/s, `setTarget` in mm) are converted where they
/// are written ([`mrt_core::frames::twist_from_setpoints`]).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RobotCommand {
    /// The velocity to drive, robot frame: m/s forward and to the left, rad/s
    /// counter-clockwise (`setVlin`, `setVlat`, `setVrot`).
    pub twist: Twist,
    /// A kicking routine to perform (`setKick`).
    pub kick: Option<i64>,
    /// Perceptual needs `(LPS index, necessity)` (`setNeeded`); the largest wins per index.
    pub needs: Vec<(usize, f64)>,
    /// Whether localization landmarks are needed (`trackLandMarks`).
    pub track_landmarks: bool,
    /// The behavior to run next (`setBehavior`).
    pub behavior: Option<String>,
    /// A booking request: `Some(true)` book the ball, `Some(false)` release it.
    pub book_ball: Option<bool>,
    /// A posture for guidance to reach instead of the velocity above (`setTarget`).
    pub target: Option<Target>,
}

/// A posture handed to guidance (ISocRob-2000 report §3.2.3): instead of velocities, the
/// behavior says where to be and guidance drives there, in position mode or, with `avoid`, in
/// potential-field mode around what the sonars see.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Target {
    /// Where to be, team frame: metres, heading in radians.
    pub pose: Framed<Team, Pose2>,
    /// Go round obstacles (potential-field mode) rather than straight (position mode).
    pub avoid: bool,
    /// Go along a path the planner (SPIKE) plans round the robots the world model anchored,
    /// in position mode from pose to pose, the sonars halting the robot as in velocity mode
    /// (`avoid` is then used only until the first path comes).
    pub plan: bool,
}

impl RobotCommand {
    /// The forward velocity in the behaviors' unit, mm/s (what `setVlin` took).
    pub fn vlin(&self) -> f64 {
        setpoints_of(self.twist).0
    }

    /// The leftward velocity in the behaviors' unit, mm/s (what `setVlat` took).
    pub fn vlat(&self) -> f64 {
        setpoints_of(self.twist).1
    }

    /// The turn rate in the behaviors' unit, degrees/s counter-clockwise (what `setVrot`
    /// took).
    pub fn vrot(&self) -> f64 {
        setpoints_of(self.twist).2
    }

    /// The necessity asserted for an LPS index this cycle (0 when none), combined by max.
    pub fn need(&self, index: usize) -> f64 {
        self.needs.iter().filter(|(i, _)| *i == index).map(|(_, v)| *v).fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_mean_nothing_seen_and_standing_still() {
        let w = WorldSnapshot::default();
        assert_eq!(w.lps.len(), lps::COUNT);
        assert_eq!(w.lps[lps::BALL].reliability, 0.0);
        let mut c = RobotCommand::default();
        assert_eq!((c.twist, c.kick, c.need(lps::BALL)), (Twist::ZERO, None, 0.0));
        c.needs.push((lps::NET1, 0.7));
        c.needs.push((lps::NET1, 0.4));
        assert_eq!(c.need(lps::NET1), 0.7, "needs combine by max");
        assert_eq!(GameState::Playing.name(), "PLAYING");
    }

    fn robot(class: RobotClass, rho: f64, theta: f64, reliability: f64) -> AnchoredRobot {
        AnchoredRobot { class, rho, theta, reliability, ..Default::default() }
    }

    #[test]
    fn the_nearest_opponent_skips_teammates_and_faded_anchors() {
        let mut w = WorldSnapshot::default();
        assert!(w.nearest_opponent(0.0).is_none());
        w.robots = vec![
            robot(RobotClass::Teammate, 0.5, 0.0, 1.0),
            robot(RobotClass::Opponent, 3.0, 0.5, 1.0),
            robot(RobotClass::Robot, 2.0, -0.5, 0.2),
        ];
        assert_eq!(w.nearest_opponent(0.0).map(|r| r.rho), Some(2.0), "unknown team counts");
        assert_eq!(w.nearest_opponent(0.5).map(|r| r.rho), Some(3.0));
    }

    #[test]
    fn the_free_direction_goes_round_a_robot_in_the_way() {
        let mut w = WorldSnapshot::default();
        // Nothing in the way: the desired bearing itself.
        assert_eq!(w.free_direction(0.3, 2.0, 0.5, 0.5), Some(0.3));
        // A robot 1 m straight ahead, corridor half-width 0.45 m: blocked while
        // |sin(b)| < 0.45, i.e. |b| < 26.7°; the first free bearing on the 5° grid is 30°,
        // left first.
        w.robots = vec![robot(RobotClass::Opponent, 1.0, 0.0, 1.0)];
        let b = w.free_direction(0.0, 2.0, 0.45, 0.5).unwrap();
        assert!((b - 30f64.to_radians()).abs() < 1e-9, "{b}");
        // A second robot on the left at 35°, 1.2 m (1.2·sin 5° = 0.105 m off the 30° line)
        // pushes it to the right.
        w.robots.push(robot(RobotClass::Robot, 1.2, 35f64.to_radians(), 1.0));
        let b = w.free_direction(0.0, 2.0, 0.45, 0.5).unwrap();
        assert!((b + 30f64.to_radians()).abs() < 1e-9, "{b}");
        // Robots behind, beyond the reach or faded do not block.
        w.robots = vec![
            robot(RobotClass::Opponent, 1.0, std::f64::consts::PI, 1.0),
            robot(RobotClass::Opponent, 3.0, 0.0, 1.0),
            robot(RobotClass::Opponent, 1.0, 0.0, 0.1),
        ];
        assert_eq!(w.free_direction(0.0, 2.0, 0.5, 0.5), Some(0.0));
        // Surrounded: none.
        w.robots = (0..12)
            .map(|k| {
                robot(RobotClass::Opponent, 0.4, f64::from(k) * std::f64::consts::FRAC_PI_6, 1.0)
            })
            .collect();
        assert_eq!(w.free_direction(0.0, 2.0, 0.5, 0.5), None);
    }
}
