//! The referee: game states, kickoffs, goals, a ball out of the field, halves and the
//! stuck-ball rule. Every kickoff (the first, after a goal, after half time) goes through
//! `READY`, in which the robots walk to the kickoff formation ([`Referee::kickoff_pose`]
//! tells each robot its place), then `SET`, then `PLAYING`. The half's clock runs on through
//! READY and SET, as in association football. It reads the [`World`], moves the ball and robots where the rules say, and
//! tells the robots the game state (what `chaos.getCurrentState()` returns).
//!
//! Teams: [`Team::Home`] defends the west goal (−x) in the first half and the east goal in the
//! second; robots `0..n` are home, `n..2n` away; robot 0 of each team is its goalkeeper.

use crate::config::READY_TOLERANCE;
use crate::world::World;
use mrt_core::Pose2;
use mrt_msgs::robot::GameState;
use std::f64::consts::PI;

/// A side of the match.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Team {
    /// The first team named (`--home`).
    Home,
    /// The second team (`--away`).
    Away,
}

impl Team {
    /// The other team.
    pub fn other(self) -> Team {
        match self {
            Team::Home => Team::Away,
            Team::Away => Team::Home,
        }
    }

    /// The marker colour its robots wear: magenta home, cyan away (the renderer paints it,
    /// the game controller tells each robot its own).
    pub fn marker(self) -> mrt_msgs::Marker {
        match self {
            Team::Home => mrt_msgs::Marker::Magenta,
            Team::Away => mrt_msgs::Marker::Cyan,
        }
    }

    /// 0 for home, 1 for away.
    pub fn index(self) -> usize {
        match self {
            Team::Home => 0,
            Team::Away => 1,
        }
    }
}

/// Something the referee decided.
#[derive(Clone, Debug, PartialEq)]
pub enum Call {
    /// A goal for this team.
    Goal(Team),
    /// The ball left the field at this point; it was put back.
    Out {
        /// Where it left.
        at: (f64, f64),
    },
    /// The ball had not moved for the stuck time; it was dropped at this point.
    Dropped {
        /// Where it went.
        at: (f64, f64),
    },
    /// The first half ended; teams change sides.
    HalfTime,
    /// The match is over.
    FullTime,
    /// READY ended: the robots that were not at their kickoff position by then were placed
    /// there; the game is in SET.
    Set {
        /// How many robots were placed.
        placed: usize,
    },
}

/// The referee's state.
#[derive(Clone, Debug)]
pub struct Referee {
    state: GameState,
    half: u8,
    half_started: f64,
    set_until: f64,
    ready_until: f64,
    /// Each robot's place in the current kickoff formation (field frame, m).
    formation: Vec<Pose2>,
    score: [u32; 2],
    team_size: usize,
    /// Where the ball was when it last moved more than the stuck distance, and when.
    anchor: ((f64, f64), f64),
}

impl Referee {
    /// A referee for teams of `team_size` robots; the game is in `INITIAL`.
    pub fn new(team_size: usize) -> Referee {
        Referee {
            state: GameState::Initial,
            half: 1,
            half_started: 0.0,
            set_until: 0.0,
            ready_until: 0.0,
            formation: Vec::new(),
            score: [0, 0],
            team_size,
            anchor: ((0.0, 0.0), 0.0),
        }
    }

    /// The game state the robots are told.
    pub fn state(&self) -> GameState {
        self.state
    }

    /// The half being played (1 or 2).
    pub fn half(&self) -> u8 {
        self.half
    }

    /// Goals of (home, away).
    pub fn score(&self) -> (u32, u32) {
        (self.score[0], self.score[1])
    }

    /// The team of robot `i`.
    pub fn team_of(&self, robot: usize) -> Team {
        if robot < self.team_size {
            Team::Home
        } else {
            Team::Away
        }
    }

    /// The direction (+1 east, −1 west) in which `team` attacks now.
    pub fn attack_direction(&self, team: Team) -> f64 {
        let home_east = if self.half == 1 { 1.0 } else { -1.0 };
        match team {
            Team::Home => home_east,
            Team::Away => -home_east,
        }
    }

    /// Where robot `robot` stands in the kickoff formation (field frame, m), while in READY.
    pub fn kickoff_pose(&self, robot: usize) -> Option<Pose2> {
        (self.state == GameState::Ready).then(|| self.formation.get(robot).copied()).flatten()
    }

    /// Starts the match: the robots enter on their side line (each team on its own half, the
    /// goalkeeper nearest its goal, facing the field), then READY for home's kickoff.
    pub fn start(&mut self, world: &mut World) {
        self.half_started = world.time();
        let cfg = world.config().clone();
        let (hl, hw) = (cfg.field.length / 2.0, cfg.field.width / 2.0);
        let n = self.team_size.max(1);
        // `validate` keeps 2r + 0.05 ≤ ENTRY_SPACING; max/min (not clamp) cannot panic even so.
        let step = ((hl - 1.0) / n as f64)
            .min(crate::config::ENTRY_SPACING)
            .max(2.0 * cfg.body.radius + 0.05);
        for i in 0..world.robot_count() {
            let t = self.team_of(i);
            let k = if t == Team::Home { i } else { i - self.team_size };
            let x = (hl - 0.5 - step * k as f64).max(cfg.body.radius);
            let x = -self.attack_direction(t) * x;
            world.place_robot(i, Pose2::new(x, -hw, std::f64::consts::FRAC_PI_2));
        }
        self.kickoff(world, Team::Home);
    }

    /// The ball on the centre spot and READY for a kickoff by `team`: the robots walk to the
    /// formation (goalkeeper on the goal line, the kicking team's first field player next to
    /// the ball, the others spread over their own half) for at most `rules.ready_duration`.
    pub fn kickoff(&mut self, world: &mut World, team: Team) {
        let cfg = world.config().clone();
        let (hl, r) = (cfg.field.length / 2.0, cfg.body.radius);
        world.place_ball(0.0, 0.0);
        self.formation = (0..world.robot_count())
            .map(|i| {
                let t = self.team_of(i);
                let k = if t == Team::Home { i } else { i - self.team_size };
                let dir = self.attack_direction(t);
                let (x, y) = if k == 0 {
                    (-dir * (hl - 0.5), 0.0)
                } else if k == 1 && t == team {
                    (-dir * (2.0 * r + cfg.ball.radius), 0.0)
                } else {
                    let lanes = (self.team_size.max(2) - 1) as f64;
                    let lane = (k - 1) as f64;
                    let y = (lane - (lanes - 1.0) / 2.0) * (cfg.field.width / (lanes + 1.0));
                    (-dir * (cfg.field.centre_circle_radius + 0.5 + lane * 0.8), y)
                };
                // Many robots on a small field: never behind the own goal line.
                // `validate` keeps hl − r − 0.1 > 0; max(0) keeps clamp from panicking even so.
                let lim = (hl - r - 0.1).max(0.0);
                let x = x.clamp(-lim, lim);
                Pose2::new(x, y, if dir > 0.0 { 0.0 } else { PI })
            })
            .collect();
        self.state = GameState::Ready;
        self.ready_until = world.time() + cfg.rules.ready_duration;
        self.anchor = ((0.0, 0.0), world.time());
        if cfg.rules.ready_duration <= 0.0 {
            self.end_ready(world);
        }
    }

    /// Whether robot `i` stands within [`READY_TOLERANCE`] of its place in the formation.
    fn in_place(&self, world: &World, i: usize) -> bool {
        match (world.robot(i), self.formation.get(i)) {
            (Some(p), Some(spot)) => (p.x - spot.x).hypot(p.y - spot.y) <= READY_TOLERANCE,
            _ => false,
        }
    }

    /// Ends READY: robots farther than [`READY_TOLERANCE`] from their place are put there,
    /// the ball back on the centre spot, SET for `rules.set_duration`. Returns how many robots
    /// were placed.
    fn end_ready(&mut self, world: &mut World) -> usize {
        let mut placed = 0;
        for i in 0..self.formation.len() {
            if !self.in_place(world, i) {
                world.place_robot(i, self.formation[i]);
                placed += 1;
            }
        }
        world.place_ball(0.0, 0.0);
        self.state = GameState::Set;
        self.set_until = world.time() + world.config().rules.set_duration;
        self.anchor = ((0.0, 0.0), world.time());
        placed
    }

    /// Applies the rules after a physics step. Returns what was decided, if anything.
    pub fn update(&mut self, world: &mut World) -> Option<Call> {
        let cfg = world.config().clone();
        let now = world.time();
        if matches!(self.state, GameState::Initial | GameState::Finished) {
            return None;
        }
        // The half's clock runs in READY and SET too.
        if now - self.half_started >= cfg.rules.half_duration - 1e-9 {
            if self.half == 1 {
                self.half = 2;
                self.half_started = now;
                self.kickoff(world, Team::Away);
                return Some(Call::HalfTime);
            }
            self.state = GameState::Finished;
            return Some(Call::FullTime);
        }
        match self.state {
            GameState::Ready => {
                let there = self.formation.iter().enumerate().all(|(i, spot)| {
                    world
                        .robot(i)
                        .is_some_and(|p| (p.x - spot.x).hypot(p.y - spot.y) <= READY_TOLERANCE)
                });
                if there || now + 1e-9 >= self.ready_until {
                    let placed = self.end_ready(world);
                    return Some(Call::Set { placed });
                }
                return None;
            }
            GameState::Set => {
                if now + 1e-9 >= self.set_until {
                    self.state = GameState::Playing;
                }
                return None;
            }
            _ => {}
        }
        let (bx, by) = world.ball();
        let (hl, hw) = (cfg.field.length / 2.0, cfg.field.width / 2.0);
        let r = cfg.ball.radius;
        // A goal: the whole ball over the goal line, between the posts.
        if bx.abs() > hl + r && by.abs() < cfg.field.goal_width / 2.0 {
            let scorer = if bx.signum() == self.attack_direction(Team::Home) {
                Team::Home
            } else {
                Team::Away
            };
            self.score[scorer.index()] += 1;
            self.kickoff(world, scorer.other());
            return Some(Call::Goal(scorer));
        }
        // Out: the whole ball over a line (and not in a goal). Put back 0.5 m inside.
        if bx.abs() > hl + r || by.abs() > hw + r {
            let (mx, my) = ((hl - 0.5).max(0.0), (hw - 0.5).max(0.0));
            let (x, y) = free_spot(world, (bx.clamp(-mx, mx), by.clamp(-my, my)), (mx, my));
            world.place_ball(x, y);
            self.anchor = ((x, y), now);
            return Some(Call::Out { at: (bx, by) });
        }
        // Stuck: the ball has not moved enough for too long.
        let ((ax, ay), since) = self.anchor;
        if (bx - ax).hypot(by - ay) > cfg.rules.stuck_distance {
            self.anchor = ((bx, by), now);
        } else if now - since >= cfg.rules.stuck_time {
            // The nearest of the four neutral points (quarter of the field) or the centre.
            let spots = [
                (0.0, 0.0),
                (hl / 2.0, hw / 2.0),
                (hl / 2.0, -hw / 2.0),
                (-hl / 2.0, hw / 2.0),
                (-hl / 2.0, -hw / 2.0),
            ];
            let at = spots
                .into_iter()
                .filter(|(x, y)| (x - bx).hypot(y - by) > 1.0)
                .min_by(|a, b| {
                    let da = (a.0 - bx).hypot(a.1 - by);
                    let db = (b.0 - bx).hypot(b.1 - by);
                    da.total_cmp(&db)
                })
                .unwrap_or((0.0, 0.0));
            let at = free_spot(world, at, (hl, hw));
            world.place_ball(at.0, at.1);
            self.anchor = (at, now);
            return Some(Call::Dropped { at });
        }
        None
    }
}

/// Where the referee puts the ball down near `at`: `at` itself when no robot's body is within
/// a ball's width of it, else the nearest free point on rings of 0.1 m steps around it (within
/// `half` of the centre each way); `at` when the field is too crowded for any.
fn free_spot(world: &World, at: (f64, f64), half: (f64, f64)) -> (f64, f64) {
    let cfg = world.config();
    let clear = cfg.body.radius + 2.0 * cfg.ball.radius;
    let free = |(x, y): (f64, f64)| {
        x.abs() <= half.0
            && y.abs() <= half.1
            && (0..world.robot_count())
                .filter_map(|i| world.robot(i))
                .all(|p| (p.x - x).hypot(p.y - y) >= clear)
    };
    if free(at) {
        return at;
    }
    (1..=40)
        .flat_map(|ring| {
            let d = 0.1 * f64::from(ring);
            (0..16).map(move |k| {
                let a = f64::from(k) * PI / 8.0;
                (at.0 + d * a.cos(), at.1 + d * a.sin())
            })
        })
        .find(|&p| free(p))
        .unwrap_or(at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::SimConfig;

    /// The rules without READY: robots are placed at once.
    fn setup() -> (World, Referee) {
        let mut cfg = SimConfig::default();
        cfg.rules.half_duration = 20.0;
        cfg.rules.ready_duration = 0.0;
        let mut w = World::new(&cfg, 8);
        let mut r = Referee::new(4);
        r.start(&mut w);
        (w, r)
    }

    fn run(w: &mut World, r: &mut Referee, seconds: f64) -> Vec<Call> {
        let steps = (seconds / w.config().rules.physics_step).round() as usize;
        (0..steps)
            .filter_map(|_| {
                w.step();
                r.update(w)
            })
            .collect()
    }

    #[test]
    fn kickoff_places_both_teams_in_their_halves_then_play_starts() {
        let (mut w, mut r) = setup();
        assert_eq!(r.state(), GameState::Set);
        for i in 0..4 {
            assert!(w.robot(i).unwrap().x < 0.0, "home robot {i} in the west half");
            assert!(w.robot(i + 4).unwrap().x > 0.0, "away robot {i} in the east half");
        }
        assert_eq!(w.robot(0).unwrap().x, -8.5, "home goalkeeper on its line");
        assert_eq!(w.ball(), (0.0, 0.0));
        run(&mut w, &mut r, 1.0);
        assert_eq!(r.state(), GameState::Playing);
    }

    /// Eleven a side on a small field: the kickoff lanes would reach past the goal line; every
    /// robot is still placed on the field, in its own half.
    #[test]
    fn many_robots_on_a_small_field_stay_on_it_at_kickoff() {
        let mut cfg = SimConfig::default();
        cfg.field.length = 8.0;
        cfg.field.width = 6.0;
        cfg.field.penalty_area_depth = 1.0;
        cfg.field.penalty_area_width = 3.0;
        cfg.rules.team_size = 11;
        cfg.rules.ready_duration = 0.0;
        cfg.validate().unwrap();
        let mut w = World::new(&cfg, 22);
        let mut r = Referee::new(11);
        r.start(&mut w);
        for i in 0..22 {
            let p = w.robot(i).unwrap();
            assert!(p.x.abs() < 4.0 && p.y.abs() < 3.0, "robot {i} at {p:?}");
            assert_eq!(p.x < 0.0, i < 11, "robot {i} in its own half: {p:?}");
        }
    }

    /// READY with nobody walking: the robots enter on their side lines (home west of the
    /// centre, away east, on y = −6 facing the field), each is told its place, and after
    /// `ready_duration` the referee places the ones not within 0.3 m of it: here all but one,
    /// which was put 0.2 m from its place by hand.
    #[test]
    fn ready_places_the_robots_that_did_not_walk_to_the_formation() {
        let mut cfg = SimConfig::default();
        cfg.rules.ready_duration = 5.0;
        let mut w = World::new(&cfg, 8);
        let mut r = Referee::new(4);
        r.start(&mut w);
        assert_eq!(r.state(), GameState::Ready);
        for i in 0..8 {
            let p = w.robot(i).unwrap();
            assert!((p.y + 6.0).abs() < 1e-3 && (p.x < 0.0) == (i < 4), "robot {i}: {p:?}");
        }
        // Home goalkeeper's place: its goal line, facing east; away's first field player is
        // not the kicker (home kicks off): 2.5 m into its half.
        assert_eq!(r.kickoff_pose(0), Some(Pose2::new(-8.5, 0.0, 0.0)));
        assert_eq!(r.kickoff_pose(1), Some(Pose2::new(-0.61, 0.0, 0.0)));
        let away1 = r.kickoff_pose(5).unwrap();
        assert!((away1.x - 2.5).abs() < 1e-9 && (away1.theta - PI).abs() < 1e-9, "{away1:?}");
        let near = r.kickoff_pose(2).unwrap();
        w.place_robot(2, Pose2::new(near.x + 0.2, near.y, 0.0));
        let calls = run(&mut w, &mut r, 4.9);
        assert!(calls.is_empty() && r.state() == GameState::Ready, "{calls:?}");
        let calls = run(&mut w, &mut r, 0.2);
        assert_eq!(calls, [Call::Set { placed: 7 }]);
        assert_eq!((r.state(), r.kickoff_pose(0)), (GameState::Set, None), "told only in READY");
        let p = w.robot(2).unwrap();
        assert!((p.x - near.x - 0.2).abs() < 0.01, "within 0.3 m: left where it was, {p:?}");
        assert!((w.robot(0).unwrap().x + 8.5).abs() < 1e-3, "the goalkeeper was placed");
    }

    /// READY ends as soon as every robot is within 0.3 m of its place: nobody is placed, SET
    /// follows, then play after `set_duration`.
    #[test]
    fn ready_ends_early_when_everyone_is_in_place() {
        let cfg = SimConfig::default();
        let mut w = World::new(&cfg, 8);
        let mut r = Referee::new(4);
        r.start(&mut w);
        for i in 0..8 {
            w.place_robot(i, r.kickoff_pose(i).unwrap());
        }
        assert_eq!(run(&mut w, &mut r, 0.01), [Call::Set { placed: 0 }]);
        assert_eq!(r.state(), GameState::Set);
        run(&mut w, &mut r, 1.0);
        assert_eq!(r.state(), GameState::Playing);
    }

    #[test]
    fn a_ball_in_the_east_goal_is_a_home_goal_and_away_kicks_off() {
        let (mut w, mut r) = setup();
        run(&mut w, &mut r, 1.0);
        w.place_ball(9.3, 0.2);
        let calls = run(&mut w, &mut r, 0.02);
        assert_eq!(calls, [Call::Goal(Team::Home)]);
        assert_eq!(r.score(), (1, 0));
        assert_eq!((r.state(), w.ball()), (GameState::Set, (0.0, 0.0)));
        // Away kicks off: its first field player stands next to the ball, on the east side.
        let p = w.robot(5).unwrap();
        assert!(p.x > 0.0 && p.x < 1.0 && p.y == 0.0, "{p:?}");
    }

    #[test]
    fn a_ball_over_the_side_line_is_put_back_inside() {
        let (mut w, mut r) = setup();
        run(&mut w, &mut r, 1.0);
        w.place_ball(3.0, 6.3);
        let calls = run(&mut w, &mut r, 0.02);
        assert!(matches!(calls.as_slice(), [Call::Out { .. }]), "{calls:?}");
        let (x, y) = w.ball();
        assert!((x - 3.0).abs() < 1e-3 && (y - 5.5).abs() < 1e-3, "({x}, {y})");
        // Beside the goal (over the goal line, outside the posts) is out, not a goal.
        w.place_ball(-9.3, 2.5);
        let calls = run(&mut w, &mut r, 0.02);
        assert!(matches!(calls.as_slice(), [Call::Out { .. }]), "{calls:?}");
        assert_eq!(r.score(), (0, 0));
    }

    #[test]
    fn the_ball_is_never_put_down_inside_a_robot() {
        let (mut w, mut r) = setup();
        run(&mut w, &mut r, 1.0);
        // A robot stands where the ball would go back after crossing the side line.
        w.place_robot(0, Pose2::new(3.0, 5.5, 0.0));
        w.place_ball(3.0, 6.3);
        let calls = run(&mut w, &mut r, 0.2);
        assert!(calls.iter().any(|c| matches!(c, Call::Out { .. })), "{calls:?}");
        let (bx, by) = w.ball();
        let me = w.robot(0).unwrap();
        let clear = w.config().body.radius + w.config().ball.radius;
        assert!((me.x - bx).hypot(me.y - by) > clear, "ball at ({bx}, {by}), robot at {me:?}");
        // Put down near where it would have gone, inside the lines.
        assert!((bx - 3.0).hypot(by - 5.5) < 1.0 && by <= 5.5 + 1e-9, "({bx}, {by})");
    }

    #[test]
    fn a_stuck_ball_is_dropped_at_a_neutral_point() {
        let (mut w, mut r) = setup();
        run(&mut w, &mut r, 1.0);
        w.place_ball(4.0, 2.0);
        let calls = run(&mut w, &mut r, 10.5);
        // The nearest neutral point, (4.5, 3.0), or beside it when a robot stands there.
        let [Call::Dropped { at }] = calls.as_slice() else { panic!("{calls:?}") };
        assert!((at.0 - 4.5).hypot(at.1 - 3.0) < 0.5, "{at:?}");
        let clear = w.config().body.radius + 2.0 * w.config().ball.radius - 1e-9;
        for i in 0..w.robot_count() {
            let p = w.robot(i).unwrap();
            assert!((p.x - at.0).hypot(p.y - at.1) >= clear, "robot {i} at {p:?}, ball at {at:?}");
        }
    }

    #[test]
    fn halves_change_sides_and_the_match_ends() {
        let (mut w, mut r) = setup();
        assert_eq!(r.attack_direction(Team::Home), 1.0);
        let calls = run(&mut w, &mut r, 21.5);
        assert!(calls.contains(&Call::HalfTime), "{calls:?}");
        assert_eq!((r.half(), r.attack_direction(Team::Home)), (2, -1.0));
        assert!(w.robot(0).unwrap().x > 8.0, "home goalkeeper now defends the east goal");
        let calls = run(&mut w, &mut r, 20.0);
        assert!(calls.contains(&Call::FullTime), "{calls:?}");
        assert_eq!(r.state(), GameState::Finished);
    }
}
