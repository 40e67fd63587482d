//! What a match reports ([`MatchReport`]): the score and each team's statistics, the
//! referee's calls, the trajectory hash, the robots' faults, what each robot believed against
//! the truth, and the kidnaps with how fast each robot found itself again.

use crate::referee::Call;
use mrt_core::Pose2;
use mrt_msgs::{BallBelief, RobotClass};

/// What went wrong with one robot's software during a match.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotFault {
    /// The robot (0 .. team size: home, then away).
    pub robot: usize,
    /// Simulated time of the first fault, s, when known (a Member that failed and was
    /// restarted is only known from its report at the end; one that never ran failed at 0).
    pub first_at: Option<f64>,
    /// How many faults (faulty cycles, failed starts, panics).
    pub count: u64,
    /// The first fault's message (which file and line, for script errors).
    pub message: String,
}

/// Per-team statistics.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TeamStats {
    /// Goals scored.
    pub goals: u32,
    /// Kicks that reached the ball.
    pub shots: u32,
    /// Shots that left the kicker heading into the opponent's goal mouth (the ball's path,
    /// unobstructed, would cross the goal line between the posts).
    pub shots_on_target: u32,
    /// Control cycles in which this team had the robot closest to the ball (within 1 m).
    pub possession_cycles: u64,
    /// Robot cycles in which one of its robots believed it held the ball booking (TeamChaos
    /// ThinkingCap/TeamChaos report §3.3, `mrt_team::booking`).
    pub booked_cycles: u64,
    /// Robot cycles in which a robot believed it held the booking while a teammate did too
    /// in the same cycle (the booking's promise: never).
    pub booking_conflicts: u64,
    /// Robot cycles in which a robot's world model gave it the attacker's role
    /// (`getRole`, `mrt_team::roles`).
    pub attacker_cycles: u64,
    /// Robot cycles in which a teammate was the attacker too in the same cycle (the two
    /// allocated from reports a cycle apart).
    pub attacker_conflicts: u64,
    /// Robot cycles in which SCARE gave a robot a job that plays the ball (BringBall,
    /// PassageToMate's passer: `mrt_team::scare::soccer`).
    pub ball_job_cycles: u64,
    /// Robot cycles in which a teammate had a ball-playing job too in the same cycle.
    pub ball_job_conflicts: u64,
}

/// One control cycle's positions, for drawings: ball, then every robot (m).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Simulated time, s.
    pub time: f64,
    /// Ball position.
    pub ball: (f64, f64),
    /// Robot poses `(x, y, heading)`.
    pub robots: Vec<(f64, f64, f64)>,
}

/// One robot's belief at one of its estimates, beside the truth (kept with the frames, for
/// drawing a robot's belief over time: [`MatchReport::belief_svg`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BeliefSample {
    /// The robot.
    pub robot: usize,
    /// Simulated time, s.
    pub time: f64,
    /// Where it believed it was (field frame, m, rad).
    pub estimate: Pose2,
    /// Where it was.
    pub truth: Pose2,
    /// Where it believed the ball was and how fast it rolled (m, m/s), when it saw the ball.
    pub ball: Option<BallBelief>,
    /// Where the ball was.
    pub true_ball: (f64, f64),
    /// The robots its world model anchored and saw in that frame (field frame, m), with the
    /// class it gave each.
    pub anchors: Vec<((f64, f64), RobotClass)>,
    /// Where the other robots were, and whether each is its teammate.
    pub others: Vec<((f64, f64), bool)>,
}

/// How a match ended.
#[derive(Clone, Debug)]
pub struct MatchReport {
    /// The seed.
    pub seed: u64,
    /// Goals of (home, away).
    pub score: (u32, u32),
    /// Statistics of (home, away).
    pub stats: [TeamStats; 2],
    /// FNV-1a hash of every control cycle's positions (mm): equal hashes, equal matches.
    pub trajectory_hash: u64,
    /// Simulated seconds.
    pub duration: f64,
    /// What the referee decided, with the time.
    pub calls: Vec<(f64, Call)>,
    /// Kicks that reached the ball: time, robot, where.
    pub shots: Vec<(f64, usize, (f64, f64))>,
    /// Positions, one frame per control cycle (empty unless recorded).
    pub frames: Vec<Frame>,
    /// Every robot's belief at each of its estimates, when frames were recorded.
    pub beliefs: Vec<BeliefSample>,
    /// Robots whose software failed during the match, by robot.
    pub faults: Vec<RobotFault>,
    /// How far each robot's own pose estimate was from the truth (every robot's
    /// `Localization` against where it was; empty when nobody watched).
    pub localization: LocalizationErrors,
    /// Every kidnap of the match ([`crate::config::MatchConfig::kidnaps`]), in time order.
    pub kidnaps: Vec<Kidnap>,
}

/// The robots' beliefs against the truth over a match: every robot's position error (m) and
/// heading error (rad), one sample per published estimate; the ball's position error (m) in
/// every estimate made while the robot saw it, and its velocity error (m/s) where the robot
/// estimated one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalizationErrors {
    /// Position errors, m.
    pub position: Vec<f64>,
    /// Heading errors (absolute), rad.
    pub heading: Vec<f64>,
    /// Ball position errors while seen, m.
    pub ball: Vec<f64>,
    /// Ball velocity errors while seen, m/s.
    pub ball_velocity: Vec<f64>,
    /// Global relocalizations (a robot's estimate put elsewhere by its relocalizer, MUREA's
    /// fix replacing the tracker's pose).
    pub relocalized: u64,
    /// Those of them that left the estimate more than [`FALSELY_RELOCALIZED`] from the truth.
    pub falsely_relocalized: u64,
    /// The other robots MAP anchored, against the truth.
    pub robots: RobotErrors,
    /// Each robot's count of relocalizations at its last estimate.
    pub(super) seen_relocalized: Vec<u64>,
}

/// The anchored robots (MAP, `mrt_world::anchor`) against the truth: every anchor a robot's
/// snapshot had seen in that frame, matched with the real robot nearest to it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotErrors {
    /// Distances from each anchor seen in its frame to the nearest other robot, m.
    pub position: Vec<f64>,
    /// Anchors whose class (teammate or opponent) is the nearest robot's team.
    pub class_right: u64,
    /// Anchors of the other team's class.
    pub class_wrong: u64,
    /// Anchors of unknown team.
    pub class_unknown: u64,
    /// Anchors with no robot within [`PHANTOM`]: seen where nobody is.
    pub phantoms: u64,
    /// Distances to the nearest robot of the anchors not seen in their frame but still
    /// reliable enough for the behaviors (`WorldSnapshot::ANCHORED`): the remembered ones, m.
    pub remembered: Vec<f64>,
    /// Those of them with no robot within [`PHANTOM`].
    pub remembered_phantoms: u64,
}

/// An anchor farther than this (m) from every other robot is a phantom.
pub const PHANTOM: f64 = 1.0;

/// A relocalization that leaves the estimate this far from the truth (m) was false.
pub const FALSELY_RELOCALIZED: f64 = 1.0;

/// A robot carried elsewhere without being told, and whether its own estimate found it again.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kidnap {
    /// The robot.
    pub robot: usize,
    /// Simulated time of the carry, s.
    pub at: f64,
    /// Where it was put down.
    pub to: Pose2,
    /// How long after the carry its estimate first came back within [`RECOVERED`] of the
    /// truth, s (`None`: not before the next carry or the end of the match).
    pub recovered_after: Option<f64>,
}

/// A kidnapped robot is recovered when its position estimate is this close to the truth (m).
pub const RECOVERED: f64 = 0.3;

/// The shortest time between two kidnaps of one robot, s: the time it is given to find
/// itself before it can be carried again.
pub const KIDNAP_GAP: f64 = 10.0;
