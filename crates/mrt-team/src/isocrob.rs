//! ISocRob's Machine µAgent (ISocRob-2000 report §3.2.2): the team's organizational mode, the robots'
//! roles, the attacker's state machine with its predicates, the goalkeeper's three modes, and
//! `should_I_go`, the heuristic that lets one robot only go for the ball.
//!
//! Everything here is plain logic on predicates and numbers, so that it can be tested state by
//! state; `mrt_robot::isocrob` reads the predicates from the robot's world snapshot, posts the
//! heuristic on the shared blackboard and turns the states into motion.
//!
//! **The heuristic** (eq 19): a robot that sees the ball with its front camera posts
//! `h = d_ball + k₁·f_other` (its distance to the ball, m, made smaller by `k₁ < 0` when it also
//! faces the opponent's goal); `should_I_go()` holds for the robot with the least value. The
//! seed posts 1000 when the ball is not seen: with distances in millimetres, as the robots'
//! world model kept them, a robot 1.2 m from the ball posts 1200 and loses to one that does not
//! see it at all. Here a robot that does not see the ball posts [`NO_BALL`], which is never the
//! least of two values where one robot sees the ball, and `should_I_go()` is false for a robot
//! that does not see the ball, whatever the others post (test
//! `not_seeing_the_ball_never_wins`).
//!
//! ```
//! use mrt_team::isocrob::{heuristic, should_i_go, NO_BALL};
//! // Robot 2 is 1.5 m from the ball facing the opponent's goal, robot 3 is 1.2 m away facing
//! // elsewhere, robot 4 does not see the ball (k₁ = −0.5 m).
//! let (h2, h3, h4) = (heuristic(Some(1.5), true, -0.5), heuristic(Some(1.2), false, -0.5),
//!     heuristic(None, true, -0.5));
//! assert_eq!((h2, h3, h4), (1.0, 1.2, NO_BALL));
//! assert!(should_i_go(2, h2, &[(3, h3), (4, h4)]));
//! assert!(!should_i_go(3, h3, &[(2, h2), (4, h4)]));
//! assert!(!should_i_go(4, h4, &[]), "not seeing the ball never wins, even alone");
//! ```

/// The organizational mode of the team (ISocRob-2000 report §3.2.2): what the whole team is doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Mode {
    /// Idle: waiting for an organizational change (the program just started).
    None,
    /// Playing against the opponent's goal.
    Play,
    /// Play suspended.
    Pause,
    /// Moving to given positions, before the game starts.
    Setup,
    /// Ad hoc tests of parts of the code.
    Test,
}

impl Mode {
    /// The name the Machine posts on the blackboard (`local.var.machine.mode`).
    pub fn name(self) -> &'static str {
        match self {
            Mode::None => "none",
            Mode::Play => "play",
            Mode::Pause => "pause",
            Mode::Setup => "setup",
            Mode::Test => "test",
        }
    }
}

/// A robot's role in the play mode (ISocRob-2000 report §3.2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Role {
    /// Moves across its goal to stand in front of the ball ([`keeper()`]).
    Goalkeeper,
    /// Goes for the ball and leads it to the opponent's goal ([`Attacker`]).
    Attacker,
    /// The attacker's machine with its home in its own half. (The seed's defender "was unable
    /// to work"; this one is the attacker kept back.)
    Defender,
}

impl Role {
    /// Parses the blackboard's spelling (`goalkeeper`, `attacker`, `defender`).
    pub fn parse(s: &str) -> Option<Role> {
        match s {
            "goalkeeper" => Some(Role::Goalkeeper),
            "attacker" => Some(Role::Attacker),
            "defender" => Some(Role::Defender),
            _ => None,
        }
    }

    /// The blackboard's spelling.
    pub fn name(self) -> &'static str {
        match self {
            Role::Goalkeeper => "goalkeeper",
            Role::Attacker => "attacker",
            Role::Defender => "defender",
        }
    }
}

/// What a robot that does not see the ball posts as its heuristic: larger than any distance on
/// a field, so it never wins against a robot that sees the ball (module doc).
pub const NO_BALL: f64 = 1.0e6;

/// The cost of approaching the ball, eq 19: `d_ball + k₁·f_other` when the front camera sees
/// the ball at `ball` m (`None`: not seen), [`NO_BALL`] otherwise. `facing_goal` is
/// `front_found_other_goal()`; `k1` (m, negative) what facing it is worth.
pub fn heuristic(ball: Option<f64>, facing_goal: bool, k1: f64) -> f64 {
    match ball {
        Some(d) if d.is_finite() => (d + if facing_goal { k1 } else { 0.0 }).max(0.0),
        _ => NO_BALL,
    }
}

/// `should_I_go()`: whether robot `me`, whose heuristic is `mine`, holds the least value among
/// itself and the teammates' `others` (`(robot, value)`), ties going to the lower robot
/// number, and sees the ball (`mine` below [`NO_BALL`]). Values that are not numbers are
/// ignored. Every robot that computes this from the same values agrees on one robot at most.
pub fn should_i_go(me: u32, mine: f64, others: &[(u32, f64)]) -> bool {
    if mine.is_nan() || mine >= NO_BALL {
        return false;
    }
    others
        .iter()
        .filter(|(id, h)| *id != me && h.is_finite())
        .all(|&(id, h)| mine < h || (mine == h && me < id))
}

/// The attacker's predicates for one cycle (ISocRob-2000 report §3.2.2, the names of figure 7).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Predicates {
    /// `ffb()`, `front_found_ball()`: the front camera sees the ball.
    pub ffb: bool,
    /// `ffog()`, `front_found_other_goal()`: the front camera sees the opponent's goal, ahead.
    pub ffog: bool,
    /// `fnb()`, `front_near_ball()`: the ball is nearer than the configured threshold.
    pub fnb: bool,
    /// `r(360)`, `rotated()`: the search has turned the robot round once.
    pub rotated: bool,
    /// `rp()`, `reached_posture()`: the robot stands at its home posture.
    pub rp: bool,
    /// `kb()`, `kicked_ball()`: the kicker fired.
    pub kb: bool,
    /// `slg()`, `should_I_go()` ([`should_i_go`]).
    pub slg: bool,
}

/// The states of the attacker's machine (ISocRob-2000 report figure 7), each with the function it runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AttackerState {
    /// `ET_go_home()`: to the home posture, watching for the ball.
    Home,
    /// Another robot is better placed: wait (facing the ball) until that changes.
    ShouldIGo,
    /// `move_close2ball()`: to the ball seen by the front camera. The initial state.
    ApproachBall,
    /// An arc round the ball, holding it, until the robot faces the opponent's goal.
    FaceGoal,
    /// `push_ball()`, and `kick_ball()` when the goal is near enough.
    RunAndKick,
    /// `rotate2find_ball()`: turns round once looking for the ball.
    SearchBall,
}

impl AttackerState {
    /// The seed's name (`local.var.machine.state` on the blackboard).
    pub fn name(self) -> &'static str {
        match self {
            AttackerState::Home => "HOME",
            AttackerState::ShouldIGo => "SHOULD_I_GO",
            AttackerState::ApproachBall => "APPROACH_BALL",
            AttackerState::FaceGoal => "FACE_GOAL",
            AttackerState::RunAndKick => "RUN_AND_KICK",
            AttackerState::SearchBall => "SEARCH_BALL",
        }
    }
}

/// The attacker role's state machine (ISocRob-2000 report figure 7). The figure itself is not in the
/// seed's text; these transitions follow the states' and predicates' descriptions there, and
/// a state stays as it is when no condition holds (as the figure's caption says):
///
/// | state | condition | next |
/// |---|---|---|
/// | APPROACH_BALL | `¬ffb` | SEARCH_BALL |
/// | | `¬slg` | SHOULD_I_GO |
/// | | `fnb` | FACE_GOAL |
/// | FACE_GOAL | `¬fnb` | APPROACH_BALL |
/// | | `ffog` | RUN_AND_KICK |
/// | RUN_AND_KICK | `kb` or `¬fnb` | APPROACH_BALL |
/// | | `¬ffog` | FACE_GOAL |
/// | SHOULD_I_GO | `ffb ∧ slg` | APPROACH_BALL |
/// | | `¬ffb` | SEARCH_BALL |
/// | SEARCH_BALL | `ffb` | SHOULD_I_GO |
/// | | `r(360)` | HOME |
/// | HOME | `ffb` | SHOULD_I_GO |
/// | | `rp` | SEARCH_BALL |
///
/// Conditions are read top down; the first that holds wins. A robot that holds the ball
/// (FACE_GOAL, RUN_AND_KICK) keeps it while the ball stays near, whatever `slg` says: the
/// heuristic of a robot dribbling away from the goal is not a reason to drop the ball.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Attacker {
    state: AttackerState,
}

impl Default for Attacker {
    fn default() -> Self {
        Attacker { state: AttackerState::ApproachBall }
    }
}

impl Attacker {
    /// The current state.
    pub fn state(&self) -> AttackerState {
        self.state
    }

    /// One cycle: the transition the predicates `p` call for (the table above). Returns the
    /// new state.
    pub fn step(&mut self, p: &Predicates) -> AttackerState {
        use AttackerState as S;
        self.state = match self.state {
            S::ApproachBall if !p.ffb => S::SearchBall,
            S::ApproachBall if !p.slg => S::ShouldIGo,
            S::ApproachBall if p.fnb => S::FaceGoal,
            S::FaceGoal if !p.fnb => S::ApproachBall,
            S::FaceGoal if p.ffog => S::RunAndKick,
            S::RunAndKick if p.kb || !p.fnb => S::ApproachBall,
            S::RunAndKick if !p.ffog => S::FaceGoal,
            S::ShouldIGo if p.ffb && p.slg => S::ApproachBall,
            S::ShouldIGo if !p.ffb => S::SearchBall,
            S::SearchBall if p.ffb => S::ShouldIGo,
            S::SearchBall if p.rotated => S::Home,
            S::Home if p.ffb => S::ShouldIGo,
            S::Home if p.rp => S::SearchBall,
            same => same,
        };
        self.state
    }
}

/// The goalkeeper's modes (ISocRob-2000 report §3.2.2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KeeperMode {
    /// Follows the ball's position along its movement axis.
    Follow,
    /// Moves to where the ball's path crosses its movement axis.
    Intercept,
    /// Goes to its home position, the middle of the goal area.
    Home,
}

impl KeeperMode {
    /// The seed's name (`local.var.machine.state`).
    pub fn name(self) -> &'static str {
        match self {
            KeeperMode::Follow => "FOLLOW",
            KeeperMode::Intercept => "INTERCEPT",
            KeeperMode::Home => "HOME",
        }
    }
}

/// The goalkeeper's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeeperParams {
    /// Where its movement axis crosses the field, m from its own goal line.
    pub axis: f64,
    /// How far either way of the goal's centre it moves, m.
    pub reach: f64,
    /// How long the ball may stay unseen before it goes home, s (a ball briefly hidden).
    pub home_after: f64,
    /// The ball is a danger (INTERCEPT) when its path reaches the axis within this time, s.
    pub danger_time: f64,
}

impl Default for KeeperParams {
    fn default() -> Self {
        KeeperParams { axis: 0.4, reach: 0.9, home_after: 2.0, danger_time: 2.0 }
    }
}

/// The ball as the goalkeeper sees it, in its team's frame (m, m/s: x from the own goal's
/// centre towards the opponent's, the own goal line at `x = −half_length`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeeperBall {
    /// Where the ball is.
    pub at: (f64, f64),
    /// How fast it moves.
    pub velocity: (f64, f64),
    /// How long ago it was last seen, s.
    pub seen_ago: f64,
}

/// The goalkeeper's decision (ISocRob-2000 report §3.2.2): HOME when the ball is in the opponent's half
/// or unseen for longer than [`KeeperParams::home_after`]; otherwise INTERCEPT when the ball
/// rolls towards the goal and reaches the movement axis within
/// [`KeeperParams::danger_time`] between the goal's ends, FOLLOW when not. Returns the mode
/// and the place on the axis to go to (`y`, m, within the reach).
pub fn keeper(ball: Option<KeeperBall>, half_length: f64, p: &KeeperParams) -> (KeeperMode, f64) {
    let Some(b) = ball.filter(|b| b.seen_ago <= p.home_after && b.at.0 < 0.0) else {
        return (KeeperMode::Home, 0.0);
    };
    let axis_x = -half_length + p.axis;
    let (vx, vy) = b.velocity;
    if vx < 0.0 && b.at.0 > axis_x {
        let t = (axis_x - b.at.0) / vx;
        let y = b.at.1 + vy * t;
        if t <= p.danger_time && y.abs() <= p.reach + 0.3 {
            return (KeeperMode::Intercept, y.clamp(-p.reach, p.reach));
        }
    }
    (KeeperMode::Follow, b.at.1.clamp(-p.reach, p.reach))
}

#[cfg(test)]
mod tests {
    use super::*;
    use AttackerState as S;

    fn p() -> Predicates {
        Predicates::default()
    }

    /// Every row of the attacker's table, one at a time, from each state.
    #[test]
    fn the_attacker_machine_state_by_state() {
        let at = |state| Attacker { state };
        let step = |state, p: Predicates| at(state).step(&p);
        let seen = Predicates { ffb: true, slg: true, ..p() };
        // APPROACH_BALL (the initial state).
        assert_eq!(Attacker::default().state(), S::ApproachBall);
        assert_eq!(step(S::ApproachBall, p()), S::SearchBall, "ball lost");
        assert_eq!(step(S::ApproachBall, Predicates { slg: false, ..seen }), S::ShouldIGo);
        assert_eq!(step(S::ApproachBall, Predicates { fnb: true, ..seen }), S::FaceGoal);
        assert_eq!(step(S::ApproachBall, seen), S::ApproachBall, "still on its way");
        // FACE_GOAL.
        let near = Predicates { fnb: true, ..seen };
        assert_eq!(step(S::FaceGoal, seen), S::ApproachBall, "the ball got away");
        assert_eq!(step(S::FaceGoal, Predicates { ffog: true, ..near }), S::RunAndKick);
        assert_eq!(step(S::FaceGoal, near), S::FaceGoal);
        assert_eq!(step(S::FaceGoal, Predicates { slg: false, ..near }), S::FaceGoal, "keeps it");
        // RUN_AND_KICK.
        let lined = Predicates { ffog: true, ..near };
        assert_eq!(step(S::RunAndKick, Predicates { kb: true, ..lined }), S::ApproachBall);
        assert_eq!(step(S::RunAndKick, Predicates { fnb: false, ..lined }), S::ApproachBall);
        assert_eq!(step(S::RunAndKick, near), S::FaceGoal, "turned away from the goal");
        assert_eq!(step(S::RunAndKick, lined), S::RunAndKick);
        // SHOULD_I_GO.
        assert_eq!(step(S::ShouldIGo, seen), S::ApproachBall, "now the best placed");
        assert_eq!(step(S::ShouldIGo, Predicates { slg: false, ..seen }), S::ShouldIGo);
        assert_eq!(step(S::ShouldIGo, p()), S::SearchBall);
        // SEARCH_BALL.
        assert_eq!(step(S::SearchBall, Predicates { ffb: true, ..p() }), S::ShouldIGo);
        assert_eq!(step(S::SearchBall, Predicates { rotated: true, ..p() }), S::Home);
        assert_eq!(step(S::SearchBall, p()), S::SearchBall);
        // HOME.
        assert_eq!(step(S::Home, Predicates { ffb: true, rp: true, ..p() }), S::ShouldIGo);
        assert_eq!(step(S::Home, Predicates { rp: true, ..p() }), S::SearchBall);
        assert_eq!(step(S::Home, p()), S::Home, "still on its way home");
    }

    /// A whole attack: the robot sees the ball, is the best placed, reaches it, turns with it
    /// to face the goal, runs and kicks, then goes for the ball again.
    #[test]
    fn an_attack_from_approach_to_kick() {
        let mut a = Attacker::default();
        let seen = Predicates { ffb: true, slg: true, ..p() };
        let near = Predicates { fnb: true, ..seen };
        let path = [
            (seen, S::ApproachBall),
            (near, S::FaceGoal),
            (near, S::FaceGoal),
            (Predicates { ffog: true, ..near }, S::RunAndKick),
            (Predicates { ffog: true, kb: true, ..near }, S::ApproachBall),
        ];
        for (i, (pred, want)) in path.iter().enumerate() {
            assert_eq!(a.step(pred), *want, "step {i}");
        }
    }

    #[test]
    fn the_heuristic_of_eq_19() {
        // d_ball + k1·f_other, k1 < 0: facing the goal is worth 0.5 m here.
        assert_eq!(heuristic(Some(2.0), false, -0.5), 2.0);
        assert_eq!(heuristic(Some(2.0), true, -0.5), 1.5);
        // Never negative: a robot on the ball facing the goal posts 0.
        assert_eq!(heuristic(Some(0.3), true, -0.5), 0.0);
        assert_eq!(heuristic(None, true, -0.5), NO_BALL);
        assert_eq!(heuristic(Some(f64::NAN), false, -0.5), NO_BALL);
    }

    /// The seed's sentinel (1000) loses to a robot more than a metre from the ball when
    /// distances are in millimetres; [`NO_BALL`] never wins, and a robot that does not see the
    /// ball never goes, even when no teammate sees it either.
    #[test]
    fn not_seeing_the_ball_never_wins() {
        let far = heuristic(Some(17.0), false, -0.5); // across the whole field
        assert!(NO_BALL > far);
        assert!(should_i_go(2, far, &[(1, NO_BALL), (3, NO_BALL)]));
        assert!(!should_i_go(1, NO_BALL, &[(2, far), (3, NO_BALL)]));
        assert!(!should_i_go(1, NO_BALL, &[(3, NO_BALL)]));
        assert!(!should_i_go(1, NO_BALL, &[]));
        // Ties go to the lower number; a teammate's value that is not a number is ignored.
        assert!(should_i_go(2, 1.0, &[(3, 1.0)]) && !should_i_go(3, 1.0, &[(2, 1.0)]));
        assert!(should_i_go(3, 1.0, &[(2, f64::NAN)]));
        // Its own value among the others is not a rival.
        assert!(should_i_go(3, 1.0, &[(3, 0.5)]));
    }

    #[test]
    fn the_keeper_goes_home_follows_or_intercepts() {
        let params = KeeperParams::default();
        let hl = 9.0;
        let ball = |at, velocity, seen_ago| Some(KeeperBall { at, velocity, seen_ago });
        // Unseen, seen too long ago, or in the opponent's half: home.
        assert_eq!(keeper(None, hl, &params), (KeeperMode::Home, 0.0));
        assert_eq!(keeper(ball((-5.0, 1.0), (0.0, 0.0), 2.5), hl, &params).0, KeeperMode::Home);
        assert_eq!(keeper(ball((2.0, 0.5), (-3.0, 0.0), 0.0), hl, &params).0, KeeperMode::Home);
        // Lying still in its half, 2 m to the left: it follows, as far as its reach.
        assert_eq!(
            keeper(ball((-5.0, 2.0), (0.0, 0.0), 0.0), hl, &params),
            (KeeperMode::Follow, 0.9)
        );
        assert_eq!(
            keeper(ball((-5.0, 0.3), (0.0, 0.0), 0.0), hl, &params),
            (KeeperMode::Follow, 0.3)
        );
        // Rolling at the goal: from (−5, 1) at (−3, −0.5) m/s it reaches the axis (x = −8.6)
        // in 1.2 s, at y = 1 − 0.6 = 0.4.
        let (mode, y) = keeper(ball((-5.0, 1.0), (-3.0, -0.5), 0.0), hl, &params);
        assert_eq!(mode, KeeperMode::Intercept);
        assert!((y - 0.4).abs() < 1e-12, "{y}");
        // Too slow to be a danger within 2 s (3.6 m at 1 m/s): it follows.
        assert_eq!(keeper(ball((-5.0, 1.0), (-1.0, 0.0), 0.0), hl, &params).0, KeeperMode::Follow);
        // Rolling wide of the goal: follows.
        assert_eq!(keeper(ball((-5.0, 1.0), (-3.0, 3.0), 0.0), hl, &params).0, KeeperMode::Follow);
    }
}
