//! The shipped TeamChaos behaviors (`behaviors/teamchaos`, ThinkingCap/TeamChaos report §4 and §5) driven with
//! scripted world snapshots: the seed's trackbnet1 example, the basic behaviors, the
//! goalkeeper hierarchy and the Attacker HFSM, with the expected commands worked out by hand
//! from the predicates of `hbm.lua` and the default control variables (Mamdani centroid).
//!
//! Default labels used below (the team's are these times [`GO`], [`TURN`], [`STRAFE`]): go STAY = TRI(−150, 0, 150), SLOW = TRI(0, 150, 300),
//! FAST = TOR(150, 300); turn RIGHT = TRI(−90, −45, 0), NONE = TRI(−45, 0, 45),
//! LEFT = TRI(0, 45, 90); strafe RIGHT = TRI(−200, −100, 0), NONE = TRI(−100, 0, 100),
//! LEFT = TRI(0, 100, 200). A symmetric label alone (at any degree) gives its peak: STAY 0,
//! SLOW 150, turn LEFT 45, strafe RIGHT −100; FAST alone gives 250 (centroid of the right
//! triangle 150..300).

#![allow(clippy::unwrap_used)]

use mrt_core::frames::{metres, pose_in_metres, pose_in_millimetres, Framed};
use mrt_core::{Pose2, Time};
use mrt_msgs::robot::{lps, Estimate, GameState, Lpo, WorldSnapshot};
use mrt_script::{Cycle, Sandbox, ScriptError, ThinkingCap};
use std::path::PathBuf;

/// The team's `hbm.lua` scales the control variables to a Middle Size robot's speeds
/// (`scale("go", 19.2)`, ...): the same labels as the defaults (the seed's, for a four-legged
/// robot), stretched by these factors.
/// Every hand computation below is done with the default labels, then scaled.
const GO: f64 = 19.2;
/// `turn`'s scale (°/s).
const TURN: f64 = 6.0;
/// `strafe`'s scale (mm/s).
const STRAFE: f64 = 19.2;

fn dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../behaviors/teamchaos"))
}

/// A scripted world: by default nothing seen, the robot at the centre spot facing the
/// opponent's net and well localized (quality 0.9). Its builders take the behaviors' units
/// (mm, rad), as the scripts read them, and keep the snapshot's metres.
#[derive(Clone)]
struct World(WorldSnapshot);

impl World {
    fn at(t_ms: u64) -> World {
        let mut w = WorldSnapshot { time: Time::from_millis(t_ms), ..Default::default() };
        w.my_pos.quality = 0.9;
        World(w)
    }

    /// The ball seen at `rho` mm, bearing `theta` rad (left positive).
    fn ball(mut self, rho: f64, theta: f64) -> World {
        self.0.lps[lps::BALL] = Lpo { rho: metres(rho), theta, reliability: 0.9, seen_ago: 0.0 };
        self
    }

    /// The ball not seen for `seen_ago` s, last at bearing `theta`.
    fn ball_lost(mut self, theta: f64, seen_ago: f64) -> World {
        self.0.lps[lps::BALL] = Lpo { rho: 1.5, theta, reliability: 0.0, seen_ago };
        self
    }

    /// The opponent's net seen at `rho` mm, bearing `theta`.
    fn net1(mut self, rho: f64, theta: f64) -> World {
        self.0.lps[lps::NET1] = Lpo { rho: metres(rho), theta, reliability: 0.9, seen_ago: 0.0 };
        self
    }

    /// Localized too poorly to aim by its pose (quality 0.5, under hbm.lua's `AIM_BY_POSE`
    /// 0.6): the robot aims by the net as its camera sees it, the seed's way.
    fn aims_by_camera(mut self) -> World {
        self.0.my_pos.quality = 0.5;
        self
    }

    /// No net seen for `s` seconds.
    fn nets_unseen(mut self, s: f64) -> World {
        for i in [lps::NET1, lps::NET2] {
            self.0.lps[i] = Lpo { rho: 0.0, theta: 0.0, reliability: 0.0, seen_ago: s };
        }
        self
    }

    /// The robot's global pose (mm, mm, rad) and localization quality.
    fn me(mut self, x: f64, y: f64, theta: f64, quality: f64) -> World {
        self.0.my_pos = Estimate { pose: team_mm(x, y, theta), quality };
        self
    }

    /// A teammate at (x, y) (mm), facing the opponent's net.
    fn mate(mut self, id: u32, x: f64, y: f64, keeper: bool) -> World {
        let at = Estimate { pose: team_mm(x, y, 0.0), quality: 0.9 };
        self.0.mates.push(mrt_msgs::robot::Mate { id, at, keeper });
        self
    }

    /// The game state.
    fn playing(mut self) -> World {
        self.0.game_state = mrt_msgs::robot::GameState::Playing;
        self
    }

    /// The ball's global position, quality 0.9.
    fn global_ball(mut self, x: f64, y: f64) -> World {
        self.0.global_ball = Estimate { pose: team_mm(x, y, 0.0), quality: 0.9 };
        self
    }
}

/// A team-frame pose given in the behaviors' millimetres.
fn team_mm(x: f64, y: f64, theta: f64) -> Framed<mrt_core::frames::Team, Pose2> {
    Framed::new(pose_in_metres(Pose2::new(x, y, theta)))
}

fn cap(behavior: &str) -> ThinkingCap {
    ThinkingCap::with_behavior(dir(), behavior, Sandbox::default()).unwrap()
}

/// One cycle of `behavior` on `w`, which must not fail.
fn run(behavior: &str, w: World) -> Cycle {
    let c = cap(behavior).cycle(w.0);
    assert!(c.errors.is_empty(), "{behavior}: {:?}", c.errors);
    assert_eq!(c.behavior.as_deref(), Some(behavior));
    c
}

#[track_caller]
fn close(got: f64, want: f64) {
    assert!((got - want).abs() < 1e-6, "got {got}, want {want}");
}

/// Mamdani centroid of a piecewise linear membership given by its breakpoints `(x, μ)`:
/// `∫xμ / ∫μ`, each linear piece contributing area h·(ya + yb)/2 and moment
/// h/6·(ya·(2a + b) + yb·(a + 2b)). Used to spell out the hand computations.
/// alignbnet1's strafe (default labels) with the aim `off` rad right of the ball, −0.2 <
/// `off` < −0.05: NONE = TRI(−100, 0, 100) clipped at netBehindBall = TRI(−0.2, 0, 0.2)(off),
/// LEFT = TRI(0, 100, 200) clipped at netRightOfBall = TOL(−0.4, −0.05)(off); their union's
/// centroid.
fn small_step_left(off: f64) -> f64 {
    let (right, behind) = ((-0.05 - off) / 0.35, 1.0 - off.abs() / 0.2);
    centroid(&[
        (-100.0, 0.0),
        (-100.0 + 100.0 * behind, behind),
        (100.0 - 100.0 * behind, behind),
        (100.0 - 100.0 * right, right),
        (200.0 - 100.0 * right, right),
        (200.0, 0.0),
    ])
}

/// The cycle asked guidance for the posture `(x, y, theta)` (mm, mm, rad), straight there
/// (position mode: no obstacle avoidance, no planning).
#[track_caller]
fn assert_target(c: &Cycle, (x, y, theta): (f64, f64, f64)) {
    let t = c.command.target.unwrap_or_else(|| panic!("no target: {:?}", c.command));
    let p = pose_in_millimetres(t.pose.inner);
    close(p.x, x);
    close(p.y, y);
    close(p.theta, theta);
    assert!(!t.avoid && !t.plan, "{t:?}");
}

fn centroid(points: &[(f64, f64)]) -> f64 {
    let (mut area, mut moment) = (0.0, 0.0);
    for w in points.windows(2) {
        let ((a, ya), (b, yb)) = (w[0], w[1]);
        let h = b - a;
        area += h * (ya + yb) / 2.0;
        moment += h / 6.0 * (ya * (2.0 * a + b) + yb * (a + 2.0 * b));
    }
    moment / area
}

#[test]
fn the_shipped_directory_loads_every_behavior_and_each_runs_cleanly() {
    let c = cap("trackbnet1");
    assert_eq!(
        c.hbm().names(),
        [
            "alignbnet1",
            "dokick",
            "faceball",
            "gkclearb",
            "gkcutb",
            "gkkeeparea",
            "gkkeepbarea",
            "gkkeepout",
            "gklocalize",
            "gkscanobj",
            "gktracklms",
            "go2ball",
            "goalkeeper",
            "gotopos",
            "lookball",
            "ready",
            "stand",
            "trackbnet1",
        ],
        "hbm.lua and attacker.hfsm.lua are not behaviors"
    );
    // Every behavior runs without error on an empty world and on a busy one.
    let busy = World::at(0)
        .ball(700.0, 0.3)
        .net1(3000.0, -0.2)
        .me(-8000.0, 300.0, 0.2, 0.7)
        .global_ball(-7400.0, 500.0);
    for name in c.hbm().names() {
        for w in [World(WorldSnapshot::default()), busy.clone()] {
            let c = run(&name, w);
            for v in [c.command.vlin(), c.command.vrot(), c.command.vlat()] {
                assert!(v.is_finite() && v.abs() <= 300.0 * GO, "{name}: {:?}", c.command);
            }
        }
    }
}

/// The seed's worked example (§4.1): "In a situation where the ball is at 400mm from the robot,
/// the truth-value of ballClose is 0.7, and these rules assert a value of needed of 1.0 for
/// the anchor BALL and of 0.7 for NET1." ballClose = TOL(250, 750)(400) = (750 − 400) / 500.
#[test]
fn trackbnet1_needs_the_ball_always_and_the_net_when_close() {
    let c = run("trackbnet1", World::at(0).ball(400.0, 0.0));
    assert!((c.command.need(lps::BALL) - 1.0).abs() < 1e-9);
    assert!((c.command.need(lps::NET1) - 0.7).abs() < 1e-9, "{:?}", c.command.needs);
    // It moves nothing.
    assert_eq!((c.command.vlin(), c.command.vrot(), c.command.vlat()), (0.0, 0.0, 0.0));
    // Ball at 1 m: not close, NET1 is not needed; at 200 mm fully close.
    let c = run("trackbnet1", World::at(0).ball(1000.0, 0.0));
    assert_eq!((c.command.need(lps::BALL), c.command.need(lps::NET1)), (1.0, 0.0));
    let c = run("trackbnet1", World::at(0).ball(200.0, 0.0));
    assert_eq!(c.command.need(lps::NET1), 1.0);
    // A ball not seen (reliability 0) is not close, whatever its last distance.
    let mut w = World::at(0).ball(400.0, 0.0);
    w.0.lps[lps::BALL].reliability = 0.0;
    assert_eq!(run("trackbnet1", w).command.need(lps::NET1), 0.0);
}

#[test]
fn faceball_turns_towards_the_ball() {
    // θ = 0.6: headedRight = TOR(0.05, 0.5)(0.6) = 1 → turn LEFT alone → +45 °/s.
    let c = run("faceball", World::at(0).ball(1500.0, 0.6));
    close(c.command.vrot(), 45.0 * TURN);
    close(c.command.vlin(), 0.0);
    close(c.command.vlat(), 0.0);
    assert_eq!(c.command.need(lps::BALL), 1.0);
    // θ = −0.6: turn RIGHT → −45.
    close(run("faceball", World::at(0).ball(1500.0, -0.6)).command.vrot(), -45.0 * TURN);
    // θ = 0: only NONE → 0.
    close(run("faceball", World::at(0).ball(1500.0, 0.0)).command.vrot(), 0.0);
    // θ = 0.2: LEFT = (0.2 − 0.05) / 0.45 = 1/3 and NONE = TRI(−0.3, 0, 0.3)(0.2) = 1/3.
    // NONE clipped at 1/3 is a trapezium −45..45 with top −30..30; LEFT clipped is 0..90 with
    // top 15..75; their max is 1/3 from −30 to 75 with ramps −45..−30 and 75..90: symmetric
    // about (−45 + 90) / 2 = 22.5.
    close(run("faceball", World::at(0).ball(1500.0, 0.2)).command.vrot(), 22.5 * TURN);
    close(run("faceball", World::at(0).ball(1500.0, -0.2)).command.vrot(), -22.5 * TURN);
}

#[test]
fn go2ball_goes_forward_when_the_ball_is_ahead_and_far_not_when_at_the_side() {
    // Ahead (θ 0) at 2 m: ballAhead 1, ballClose 0 → go FAST alone → 250; turn NONE → 0.
    let c = run("go2ball", World::at(0).ball(2000.0, 0.0));
    close(c.command.vlin(), 250.0 * GO);
    close(c.command.vrot(), 0.0);
    close(c.command.vlat(), 0.0);
    // At the side (θ 1.2): ballAhead 0 → go STAY → 0, turn LEFT → 45.
    let c = run("go2ball", World::at(0).ball(2000.0, 1.2));
    close(c.command.vlin(), 0.0);
    close(c.command.vrot(), 45.0 * TURN);
    // Ahead at 400 mm: ballClose 0.7 → FAST 0.3, SLOW 0.7. The max of SLOW clipped at 0.7 and
    // FAST clipped at 0.3 rises 0 → 0.7 over [0, 105], stays 0.7 to 195, follows SLOW down to
    // 0.3 at 255, then FAST's 0.3 to 300: centroid 22398.75 / 143.25 = 156.36.
    let c = run("go2ball", World::at(0).ball(400.0, 0.0));
    let want = centroid(&[(0.0, 0.0), (105.0, 0.7), (195.0, 0.7), (255.0, 0.3), (300.0, 0.3)]);
    close(want, 22398.75 / 143.25);
    close(c.command.vlin(), want * GO);
}

#[test]
fn dokick_kicks_when_the_ball_is_ahead_and_touching() {
    // 200 mm ahead: ballTouching = TOL(150, 350)(200) = 0.75 → FRONTKICK 0.75 ≥ 0.5 → kick 1;
    // go SLOW at NOT(0.75) = 0.25 → 150.
    let c = run("dokick", World::at(0).ball(200.0, 0.0));
    assert_eq!(c.command.kick, Some(1));
    close(c.command.vlin(), 150.0 * GO);
    // 1 m: not touching → no kick, SLOW 1 → 150.
    let c = run("dokick", World::at(0).ball(1000.0, 0.0));
    assert_eq!(c.command.kick, None);
    close(c.command.vlin(), 150.0 * GO);
    // 300 mm: touching (350 − 300) / 200 = 0.25 < 0.5 → no kick.
    assert_eq!(run("dokick", World::at(0).ball(300.0, 0.0)).command.kick, None);
    // 200 mm but off to the side (θ 1): not ahead → no kick, STAY, turn LEFT.
    let c = run("dokick", World::at(0).ball(200.0, 1.0));
    assert_eq!(c.command.kick, None);
    close(c.command.vlin(), 0.0);
    close(c.command.vrot(), 45.0 * TURN);
}

#[test]
fn alignbnet1_strafes_to_put_the_net_behind_the_ball() {
    // Net seen 0.5 rad left of the ball: netLeftOfBall = TOR(0.05, 0.4)(0.5) = 1 → strafe
    // RIGHT → −100; ball ahead → turn NONE → 0; go STAY → 0.
    let c = run("alignbnet1", World::at(0).aims_by_camera().ball(400.0, 0.0).net1(3000.0, 0.5));
    close(c.command.vlat(), -100.0 * STRAFE);
    close(c.command.vrot(), 0.0);
    close(c.command.vlin(), 0.0);
    assert_eq!((c.command.need(lps::BALL), c.command.need(lps::NET1)), (1.0, 1.0));
    // Net right of the ball → strafe LEFT → +100; behind it → NONE → 0.
    close(
        run("alignbnet1", World::at(0).aims_by_camera().ball(400.0, 0.1).net1(3000.0, -0.4))
            .command
            .vlat(),
        100.0 * STRAFE,
    );
    close(
        run("alignbnet1", World::at(0).aims_by_camera().ball(400.0, 0.0).net1(3000.0, 0.0))
            .command
            .vlat(),
        0.0,
    );
    // Net not seen: no strafe rule fires, vlat stays at its default 0.
    close(run("alignbnet1", World::at(0).aims_by_camera().ball(400.0, 0.0)).command.vlat(), 0.0);
}

/// A robot localized well (quality 0.9 ≥ `AIM_BY_POSE`) aims by its pose, not by a net its
/// camera sees off its middle (a net cut by the image's border). At (0, 1000) facing the net,
/// the net's middle (9000, 0) lies atan2(−1000, 9000) = −0.110 rad right, and so right of the
/// ball straight ahead: netRightOfBall = TOL(−0.4, −0.05)(−0.110) = 0.171 and netBehindBall =
/// TRI(−0.2, 0, 0.2)(−0.110) = 0.448, a small step to the left, whatever the camera says of
/// the net (0.5 rad left here, which alone would call for a step to the right, −100).
#[test]
fn a_well_localized_robot_aims_by_its_pose_not_by_a_net_seen_off_its_middle() {
    let w = World::at(0).me(0.0, 1000.0, 0.0, 0.9).ball(400.0, 0.0).net1(9000.0, 0.5);
    let c = run("alignbnet1", w.clone());
    let want = small_step_left((-1000.0f64).atan2(9000.0));
    assert!(want > 0.0 && want < 40.0, "{want}");
    close(c.command.vlat(), want * STRAFE);
    // The same robot lost (quality 0.5) follows its camera: the net left of the ball, a step
    // to the right.
    close(run("alignbnet1", w.aims_by_camera()).command.vlat(), -100.0 * STRAFE);
}

/// The aim moves away from the opponent's goalkeeper: with an opponent anchored at
/// (8700, 500), 300 mm before the middle of the net, the aim is the far side of the net,
/// 250 mm inside its post: (9000, −750). Seen from (0, 0) facing the net, that is
/// atan2(−750, 9000) = −0.083 rad right of the net's middle, where the ball lies: the aim is
/// right of the ball, netRightOfBall = TOL(−0.4, −0.05)(−0.083) = 0.095 and netBehindBall =
/// TRI(−0.2, 0, 0.2)(−0.083) = 0.58: a small step to the left (the near ball drifts right in
/// view faster than the far aim). Without the keeper the net's middle is behind the ball: no
/// step.
#[test]
fn alignbnet1_aims_at_the_side_of_the_net_away_from_its_keeper() {
    use mrt_msgs::{AnchoredRobot, RobotClass};
    let w = World::at(0).me(0.0, 0.0, 0.0, 0.9).ball(400.0, 0.0).net1(9000.0, 0.0);
    close(run("alignbnet1", w.clone()).command.vlat(), 0.0);
    let (x, y) = (8.7f64, 0.5f64);
    let mut guarded = w;
    guarded.0.robots.push(AnchoredRobot {
        id: 5,
        class: RobotClass::Opponent,
        at: Framed::new(mrt_core::Point2::new(x, y)),
        rho: x.hypot(y),
        theta: y.atan2(x),
        reliability: 0.9,
        at_sigma: 0.08,
        ..Default::default()
    });
    let c = run("alignbnet1", guarded);
    let want = small_step_left((-750.0f64).atan2(9000.0));
    assert!(want > 0.0 && want < 30.0, "{want}");
    close(c.command.vlat(), want * STRAFE);
}

/// Near our net (within `CLEAR_ZONE`, 3 m of its centre) the attacker clears the ball straight
/// away from our net instead of lining it up with the far net, whose spot behind the ball would
/// be in our goal. The ball at (−7500, 1500) is 2121 mm from our net's centre (−9000, 0); the
/// robot at (−8400, 600) is on the line from that centre through the ball, facing along it
/// (π/4), the ball 1273 mm straight ahead: the clearing direction passes behind the ball
/// (aimOffBall = 0, netBehindBall = 1): no step aside. The same scene 6 m up the field (ball
/// at (−1500, 1500), 7648 mm from our net) lines the ball up with the far net's middle
/// (9000, 0), atan2(−600, 11400) − π/4 = −0.838 rad: right of the ball, netRightOfBall = 1, a
/// step to the LEFT (+100).
#[test]
fn alignbnet1_clears_a_ball_near_our_net_straight_away_from_it() {
    use std::f64::consts::FRAC_PI_4;
    let scene = |dx: f64| {
        World::at(0)
            .me(-8400.0 + dx, 600.0, FRAC_PI_4, 0.9)
            .ball(900.0 * 2f64.sqrt(), 0.0)
            .global_ball(-7500.0 + dx, 1500.0)
            .net1(9000.0, 0.3)
    };
    let near = run("alignbnet1", scene(0.0)).command;
    close(near.vlat(), 0.0);
    close(near.vrot(), 0.0);
    close(run("alignbnet1", scene(6000.0)).command.vlat(), 100.0 * STRAFE);
}

#[test]
fn gkcutb_holds_the_goal_line_level_with_the_ball_and_clears_when_safe() {
    // The spot: 400 mm out of our goal line (x = −9000 + 400 = −8600), level with the ball
    // but within the posts (|y| ≤ 1000 − 100), facing the ball: a posture for guidance in
    // position mode (straight there, `avoid` false), not fuzzy velocities.
    // Robot at (−8600, −1500) facing +x, ball at (−5000, −1000): the spot is (−8600, −900),
    // facing atan2(−1000 + 1500, −5000 + 8600) = atan2(500, 3600).
    let w = World::at(0).me(-8600.0, -1500.0, 0.0, 0.9).global_ball(-5000.0, -1000.0);
    let c = run("gkcutb", w.ball(3635.0, 500.0f64.atan2(3600.0)));
    assert_target(&c, (-8600.0, -900.0, 500.0f64.atan2(3600.0)));
    assert_eq!(c.command.need(lps::BALL), 1.0);
    // The ball far out on the left (y = 3000): the spot stays at the post (y = 900).
    let w = World::at(0).me(-8600.0, 900.0, 0.0, 0.9).global_ball(-5000.0, 3000.0);
    let c = run("gkcutb", w.ball(4168.0, 2100.0f64.atan2(3600.0)));
    assert_target(&c, (-8600.0, 900.0, 2100.0f64.atan2(3600.0)));
    // 1000 mm out in front of the spot, ball straight ahead: back to (−8600, −900), facing 0.
    let w = World::at(0).me(-7600.0, -900.0, 0.0, 0.9).global_ball(-5000.0, -900.0);
    let c = run("gkcutb", w.ball(2600.0, 0.0));
    assert_target(&c, (-8600.0, -900.0, 0.0));
    assert_eq!(c.command.kick, None, "ball far: no kick");
    // Ball close (300 mm: ballClose = (750 − 300)/500 = 0.9) and heading 0 (freeToKick =
    // TOL(0.5, 1.2)(0) = 1): FRONTKICK 0.9 → kick 1.
    let w = World::at(0).me(-8500.0, 0.0, 0.0, 0.9).global_ball(-8200.0, 0.0);
    assert_eq!(run("gkcutb", w.clone().ball(300.0, 0.0)).command.kick, Some(1));
    // The same ball with the robot headed 2 rad (towards our own half): not safe, no kick.
    let w = World::at(0).me(-8500.0, 0.0, 2.0, 0.9).global_ball(-8200.0, 0.0);
    assert_eq!(run("gkcutb", w.ball(300.0, 0.0)).command.kick, None);
}

#[test]
fn goalkeeper_scans_for_a_lost_ball_turning_towards_where_it_was() {
    // Ball not seen (reliability 0), last seen to the right (θ −0.7), robot localized at its
    // goal: NOT(ballSeen) = 1 → gkscanobj → lookball (turn −50 °/s for 400 ms, then −75) and
    // gktracklms (track landmarks). Nothing else is used: no fuzzy output overrides lookball.
    let mut cap = cap("goalkeeper");
    let w = |t| World::at(t).me(-8500.0, 0.0, 0.0, 0.9).ball_lost(-0.7, 3.0);
    let c = cap.cycle(w(1000).0);
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!((c.command.vlin(), c.command.vrot(), c.command.vlat()), (0.0, -50.0, 0.0));
    assert!(c.command.track_landmarks);
    assert_eq!(c.command.need(lps::BALL), 1.0);
    let c = cap.cycle(w(1300).0);
    assert_eq!(c.command.vrot(), -50.0);
    let c = cap.cycle(w(1500).0);
    assert_eq!(c.command.vrot(), -75.0, "faster after 400 ms");
}

#[test]
fn goalkeeper_gets_out_of_its_net() {
    // x = −9200 is behind our goal line: inOwnNet = TOL(−9100, −8850)(−9200) = 1 → gkkeepout
    // alone (every other meta-rule has NOT(inOwnNet) = 0): go SLOW → 150 (forward), turn LEFT
    // → 45, strafe NONE → 0, landmarks and NET1 needed. Even with the ball in view.
    let c = run(
        "goalkeeper",
        World::at(0).me(-9200.0, 0.0, 0.0, 0.9).ball(1000.0, 0.0).global_ball(-8200.0, 0.0),
    );
    close(c.command.vlin(), 150.0 * GO);
    close(c.command.vrot(), 45.0 * TURN);
    close(c.command.vlat(), 0.0);
    assert_eq!(c.command.target, None);
    assert!(c.command.track_landmarks);
    assert_eq!(c.command.need(lps::NET1), 1.0);
    assert_eq!(c.command.kick, None);
}

#[test]
fn goalkeeper_clears_a_ball_in_the_penalty_area() {
    // Robot at x = −7700 facing +x, localized; ball seen 200 mm ahead, globally at x = −7500
    // (penalty area: TOL(−6750, −6250)(−7500) = 1) → gkclearb at 1. There ballAhead = 1,
    // ballClose = 1, freeToKick = 1 → dokick at 1 (go2ball at NOT(1) = 0, faceball 0,
    // alignbnet1 0): FRONTKICK at ballTouching = 0.75 → kick 1; go SLOW 0.25 → 150.
    let c = run(
        "goalkeeper",
        World::at(0).me(-7700.0, 0.0, 0.0, 0.9).ball(200.0, 0.0).global_ball(-7500.0, 0.0),
    );
    assert_eq!(c.command.kick, Some(1));
    close(c.command.vlin(), 150.0 * GO);
    close(c.command.vrot(), 0.0);
    close(c.command.vlat(), 0.0);
    assert_eq!(c.command.need(lps::BALL), 1.0);
    // The ball 1.5 m ahead, still in the area (x = −7200): too far to run out for
    // (TOL(800, 1500)(1500) = 0), so gkcutb holds the spot (−8600, 0), 100 mm ahead, facing
    // the ball; no kick. The keeper does not leave its goal for a ball it cannot reach first.
    let c = run(
        "goalkeeper",
        World::at(0).me(-8700.0, 0.0, 0.0, 0.9).ball(1500.0, 0.0).global_ball(-7200.0, 0.0),
    );
    assert_target(&c, (-8600.0, 0.0, 0.0));
    assert_eq!(c.command.kick, None);
}

#[test]
fn goalkeeper_cuts_the_ball_from_its_goal_area_and_localizes_when_lost() {
    // Robot at (−8500, 500); ball at (−4000, 1000), outside the penalty area → gkcutb at 1:
    // its spot (−8600, 900), facing the ball, atan2(500, 4500) = 0.11 (left).
    let theta = 500.0f64.atan2(4500.0);
    let c = run(
        "goalkeeper",
        World::at(0).me(-8500.0, 500.0, 0.0, 0.9).ball(4528.0, theta).global_ball(-4000.0, 1000.0),
    );
    assert_target(&c, (-8600.0, 900.0, theta));
    // The same with localization quality 0.2: wellLocalized = TOR(0.4, 0.8)(0.2) = 0, lost 1 →
    // gklocalize alone: stand still (STAY, NONE, NONE → 0, no posture), landmarks, both nets
    // at 0.6.
    let c = run(
        "goalkeeper",
        World::at(0).me(-8500.0, 500.0, 0.0, 0.2).ball(4528.0, theta).global_ball(-4000.0, 1000.0),
    );
    close(c.command.vlin(), 0.0);
    close(c.command.vrot(), 0.0);
    close(c.command.vlat(), 0.0);
    assert!(c.command.track_landmarks);
    assert_eq!((c.command.need(lps::NET1), c.command.need(lps::NET2)), (0.6, 0.6));
}

/// The seed's Attacker (§5.2, figures 10 and 11) through a scripted approach: face the ball,
/// walk to it, approach, kick, lose the alignment, realign, kick, the ball rolls away.
#[test]
fn the_attacker_hfsm_faces_walks_scores_and_follows_the_ball() {
    let mut cap =
        ThinkingCap::with_hfsm(dir(), dir().join("attacker.hfsm.lua"), Sandbox::default()).unwrap();
    assert_eq!(cap.hfsm().unwrap().root(), "Attacker");
    let aligned = 0.05; // |NET1.theta − BALL.theta| < 0.2 with the ball at θ 0
    let worlds = [
        // 0: ball far on the left: FaceBall (initial).
        World::at(0).ball(2000.0, 1.2).net1(5000.0, 0.9),
        // 1: still on the side: no transition.
        World::at(100).ball(2000.0, 1.0).net1(5000.0, 0.9),
        // 2: ahead (|θ| < 0.25): BallAhead → GoToBall.
        World::at(200).ball(2000.0, 0.0).net1(5000.0, aligned),
        // 3: localization quality 0.5 and no net seen for 6 s: GoToBall tracks landmarks and
        //    needs NET1 at 0.5.
        World::at(300).ball(2000.0, 0.0).me(0.0, 0.0, 0.0, 0.5).nets_unseen(6.0),
        // 4: 450 mm (< 500): NearBall → Score, entered at ApproachBall.
        World::at(400).ball(450.0, 0.0).net1(4000.0, 0.6).aims_by_camera(),
        // 5: 450 mm (< 600) and aligned: Kickable → DoKick.
        World::at(500).ball(450.0, 0.0).net1(4000.0, aligned).aims_by_camera(),
        // 6: alignment lost: LostAlignment → Align.
        World::at(600).ball(450.0, 0.0).net1(4000.0, 0.5).aims_by_camera(),
        // 7: aligned again, ball at 200 mm: Aligned → DoKick, which kicks.
        World::at(700).ball(200.0, 0.0).net1(4000.0, aligned).aims_by_camera(),
        // 8: the ball rolled to 1.2 m and the net is off: Score's BallAway (> 900) and DoKick's
        //    LostAlignment both pass; the enclosing meta-state's transition wins.
        World::at(800).ball(1200.0, 0.0).net1(4000.0, 0.5).aims_by_camera(),
        // 9: the ball far on the right (|θ| > 0.8): BallAside → FaceBall.
        World::at(900).ball(1200.0, -1.0).net1(4000.0, 0.5).aims_by_camera(),
    ];
    let cycles: Vec<Cycle> = worlds.iter().map(|w| cap.cycle(w.0.clone())).collect();
    for (k, c) in cycles.iter().enumerate() {
        assert!(c.errors.is_empty(), "cycle {k}: {:?}", c.errors);
    }
    let paths: Vec<&str> = cycles.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "Attacker/FaceBall",
            "Attacker/FaceBall",
            "Attacker/GoToBall",
            "Attacker/GoToBall",
            "Attacker/Score/ApproachBall",
            "Attacker/Score/DoKick",
            "Attacker/Score/Align",
            "Attacker/Score/DoKick",
            "Attacker/GoToBall",
            "Attacker/FaceBall",
        ]
    );
    let taken: Vec<Option<(&str, &str)>> = cycles
        .iter()
        .map(|c| c.taken.as_ref().map(|t| (t.machine.as_str(), t.name.as_str())))
        .collect();
    assert_eq!(
        taken,
        [
            None,
            None,
            Some(("Attacker", "BallAhead")),
            None,
            Some(("Attacker", "NearBall")),
            Some(("Score", "Kickable")),
            Some(("Score", "LostAlignment")),
            Some(("Score", "Aligned")),
            Some(("Attacker", "BallAway")),
            Some(("Attacker", "BallAside")),
        ]
    );
    for c in &cycles {
        assert_eq!(
            c.taken.as_ref().map(|t| t.path.as_str()),
            c.taken.as_ref().map(|_| c.path.as_str())
        );
    }
    let behaviors: Vec<&str> = cycles.iter().map(|c| c.behavior.as_deref().unwrap()).collect();
    assert_eq!(
        behaviors,
        [
            "faceball",
            "faceball",
            "go2ball",
            "go2ball",
            "go2ball",
            "dokick",
            "alignbnet1",
            "dokick",
            "go2ball",
            "faceball",
        ]
    );
    let cmd = |k: usize| &cycles[k].command;
    // 0: faceball, ball left (θ 1.2) → turn LEFT 45, no forward motion.
    close(cmd(0).vrot(), 45.0 * TURN);
    close(cmd(0).vlin(), 0.0);
    // 2: go2ball, ball ahead at 2 m → FAST 250; well localized → no landmark tracking.
    close(cmd(2).vlin(), 250.0 * GO);
    assert!(!cmd(2).track_landmarks);
    assert_eq!(cmd(2).need(lps::NET1), 0.0);
    // 3: quality 0.5 < 0.6 → trackLandMarks; nets unseen > 5 s → NET1 needed at 0.5.
    assert!(cmd(3).track_landmarks);
    assert_eq!(cmd(3).need(lps::NET1), 0.5);
    close(cmd(3).vlin(), 250.0 * GO);
    // 4: ApproachBall runs go2ball at 450 mm: ballClose = (750 − 450)/500 = 0.6 → SLOW 0.6,
    //    FAST 0.4: the max rises 0 → 0.6 over [0, 90], stays 0.6 to 210, follows SLOW down to
    //    0.4 at 240, then FAST's 0.4 to 300: centroid 22260 / 138 = 161.30. No landmarks.
    let want = centroid(&[(0.0, 0.0), (90.0, 0.6), (210.0, 0.6), (240.0, 0.4), (300.0, 0.4)]);
    close(want, 22260.0 / 138.0);
    close(cmd(4).vlin(), want * GO);
    assert!(!cmd(4).track_landmarks);
    // 5: dokick at 450 mm: not touching → no kick, SLOW → 150.
    assert_eq!(cmd(5).kick, None);
    close(cmd(5).vlin(), 150.0 * GO);
    // 6: alignbnet1, net 0.5 rad left of the ball → strafe RIGHT −100, no forward motion.
    close(cmd(6).vlat(), -100.0 * STRAFE);
    close(cmd(6).vlin(), 0.0);
    // 7: dokick at 200 mm → kick 1.
    assert_eq!(cmd(7).kick, Some(1));
    // 8: back in GoToBall, ball 1.2 m ahead → FAST 250.
    close(cmd(8).vlin(), 250.0 * GO);
    // 9: faceball, ball right → −45.
    close(cmd(9).vrot(), -45.0 * TURN);
}

#[test]
fn the_attacker_aligns_first_when_approaching_a_misaligned_ball() {
    let mut cap =
        ThinkingCap::with_hfsm(dir(), dir().join("attacker.hfsm.lua"), Sandbox::default()).unwrap();
    let worlds = [
        World::at(0).ball(2000.0, 0.0).net1(5000.0, 0.0).aims_by_camera(),
        World::at(100).ball(2000.0, 0.0).net1(5000.0, 0.0).aims_by_camera(),
        World::at(200).ball(480.0, 0.0).net1(5000.0, -0.5).aims_by_camera(),
        // 650 mm: the seed's Kickable needs < 600: stay in ApproachBall.
        World::at(300).ball(650.0, 0.0).net1(5000.0, -0.5).aims_by_camera(),
        // 550 mm, net 0.5 rad right of the ball: Misaligned → Align; strafe LEFT +100.
        World::at(400).ball(550.0, 0.0).net1(5000.0, -0.5).aims_by_camera(),
    ];
    let cycles: Vec<Cycle> = worlds.iter().map(|w| cap.cycle(w.0.clone())).collect();
    let paths: Vec<&str> = cycles.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(
        paths,
        [
            "Attacker/FaceBall",
            "Attacker/GoToBall",
            "Attacker/Score/ApproachBall",
            "Attacker/Score/ApproachBall",
            "Attacker/Score/Align",
        ]
    );
    assert_eq!(cycles[4].taken.as_ref().map(|t| t.name.as_str()), Some("Misaligned"));
    close(cycles[4].command.vlat(), 100.0 * STRAFE);
}

/// A fresh scratch directory for `test` holding copies of the shipped files `names` (the
/// shared predicates, a behavior...).
fn scratch_copy(test: &str, names: &[&str]) -> PathBuf {
    let to =
        std::env::temp_dir().join(format!("mrt-script-teamchaos-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&to);
    std::fs::create_dir_all(&to).unwrap();
    for n in names {
        std::fs::copy(dir().join(n), to.join(n)).unwrap();
    }
    to
}

/// What each label of the team's control variables asks the base for: `hbm.lua`'s scales are
/// the one place Chaos' AIBO-era speeds are adapted, so these are the set-points the robot
/// cycle hands to guidance. Every label but STAY and NONE asks for more than the Middle Size
/// base's top speed (1.2 m/s, 4 rad/s = 229 °/s), which guidance then drives at.
#[test]
fn the_labels_become_these_set_points_on_a_middle_size_base() {
    let tmp = scratch_copy("labels", &["hbm.lua"]);
    // (variable, label, the command field, the set-point: mm/s or °/s)
    let cases = [
        ("go", "FAST", 4800.0),
        ("go", "SLOW", 2880.0),
        ("go", "STAY", 0.0),
        ("go", "BACK", -4800.0),
        ("turn", "HARDLEFT", 450.0),
        ("turn", "LEFT", 270.0),
        ("turn", "RIGHT", -270.0),
        ("strafe", "LEFT", 1920.0),
        ("strafe", "NONE", 0.0),
    ];
    for (variable, label, want) in cases {
        let name = format!("{variable}_{label}").to_lowercase();
        std::fs::write(
            tmp.join(format!("{name}.lua")),
            format!("always(\"{variable}\", \"{label}\")"),
        )
        .unwrap();
        let mut cap = ThinkingCap::with_behavior(&tmp, &name, Sandbox::default()).unwrap();
        let c = cap.cycle(World::at(0).0);
        assert!(c.errors.is_empty(), "{name}: {:?}", c.errors);
        let got = match variable {
            "go" => c.command.vlin(),
            "turn" => c.command.vrot(),
            _ => c.command.vlat(),
        };
        assert!((got - want).abs() < 1e-6 * want.abs().max(1.0), "{name}: {got}, want {want}");
        if want != 0.0 {
            let top = if variable == "turn" { 4f64.to_degrees() } else { 1200.0 };
            assert!(got.abs() > top, "{name}: {got} is within the base's top speed {top}");
        }
    }
    std::fs::remove_dir_all(&tmp).unwrap();
}

#[test]
fn an_hfsm_naming_an_unknown_behavior_keeps_the_last_good_one_running() {
    let tmp = scratch_copy("nothere", &["hbm.lua", "go2ball.lua"]);
    let machine = tmp.join("m.hfsm.lua");
    std::fs::write(
        &machine,
        "machine \"M\" {\n\
         initial = \"Go\",\n\
         states = { Go = function()\n\
           if chaos.lps_getLpo(BALL).rho < 300 then\n\
             chaos.setBehavior(\"nothere\")\n\
           else\n\
             chaos.setBehavior(\"go2ball\")\n\
           end\n\
         end },\n\
         }\n",
    )
    .unwrap();
    let mut cap = ThinkingCap::with_hfsm(&tmp, &machine, Sandbox::default()).unwrap();
    // Ball 2 m ahead: go2ball → FAST 250.
    let c = cap.cycle(World::at(0).ball(2000.0, 0.0).0);
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!((c.path.as_str(), c.behavior.as_deref()), ("M/Go", Some("go2ball")));
    close(c.command.vlin(), 250.0 * GO);
    // Ball at 200 mm: the state asks for "nothere". The cycle reports it (file and line of
    // the call) and go2ball keeps running: ballClose(200) = 1 → SLOW alone → 150.
    let c = cap.cycle(World::at(100).ball(200.0, 0.0).0);
    assert_eq!(c.errors.len(), 1, "{:?}", c.errors);
    match &c.errors[0] {
        ScriptError::Runtime { file, line, message, .. } => {
            assert_eq!((file.as_str(), *line), (machine.display().to_string().as_str(), 5));
            assert!(
                message.contains("chaos.setBehavior: no behavior named 'nothere' (known: go2ball)"),
                "{message}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert_eq!((c.path.as_str(), c.behavior.as_deref()), ("M/Go", Some("go2ball")));
    close(c.command.vlin(), 150.0 * GO);
    // And back to normal.
    let c = cap.cycle(World::at(200).ball(2000.0, 0.0).0);
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    close(c.command.vlin(), 250.0 * GO);
    let _ = std::fs::remove_dir_all(&tmp);
}

/// Behaviors make garbage every cycle (fuzzy sets built on the fly, closures, strings): over
/// many cycles the heap stays near its live size. gkcutb builds three sets per cycle; with sets
/// as userdata and the incremental collector the heap had grown past 1 MB after 20,000 cycles
/// (and a long run crawled against the memory limit); it now stays under 256 KB.
#[test]
fn the_heap_stays_small_over_many_cycles() {
    let mut cap = ThinkingCap::with_behavior(dir(), "gkcutb", Sandbox::default()).unwrap();
    let mut w = WorldSnapshot { time: Time::from_millis(100), ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: 2.0, theta: 0.05, reliability: 0.9, seen_ago: 0.0 };
    let mut peak = 0;
    for _ in 0..20_000 {
        let c = cap.cycle(w.clone());
        assert!(c.errors.is_empty(), "{:?}", c.errors);
        peak = peak.max(cap.runtime().used_memory());
    }
    assert!(peak < 256 << 10, "peak Lua heap {peak} bytes");
}

/// An HFSM that runs away (an endless loop in a state) gets the safe command for that cycle
/// (stand still, no kick) and a budget error; the next cycle runs normally.
#[test]
fn a_runaway_hfsm_gets_the_safe_command_for_that_cycle() {
    let scratch = std::env::temp_dir().join(format!("mrt-runaway-hfsm-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    for f in ["hbm.lua", "go2ball.lua"] {
        std::fs::copy(dir().join(f), scratch.join(f)).unwrap();
    }
    let machine = scratch.join("spin.hfsm.lua");
    std::fs::write(
        &machine,
        "machine \"M\" { initial = \"Walk\", states = { Walk = function()\n  chaos.setBehavior(\"go2ball\")\n  if chaos.getCurrentState() == \"FINISHED\" then while true do end end\nend } }\n",
    )
    .unwrap();
    let sandbox = Sandbox { instruction_budget: 200_000, ..Sandbox::default() };
    let mut cap = ThinkingCap::with_hfsm(&scratch, &machine, sandbox).unwrap();
    let mut w = WorldSnapshot { game_state: GameState::Playing, ..Default::default() };
    w.lps[lps::BALL] = Lpo { rho: 2.0, theta: 0.0, reliability: 0.9, seen_ago: 0.0 };
    let walking = cap.cycle(w.clone());
    assert!(walking.errors.is_empty() && walking.command.vlin() > 200.0, "{walking:?}");
    let stuck = cap.cycle(WorldSnapshot { game_state: GameState::Finished, ..w.clone() });
    assert!(
        matches!(stuck.errors.first(), Some(ScriptError::Budget { line: 3, .. })),
        "{:?}",
        stuck.errors
    );
    assert_eq!((stuck.command.vlin(), stuck.command.vrot(), stuck.command.kick), (0.0, 0.0, None));
    assert_eq!(stuck.behavior, None);
    let again = cap.cycle(w);
    assert!(again.errors.is_empty() && again.command.vlin() > 200.0, "{again:?}");
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// A reload request reloads the machine even when only a file it includes changed: the
/// player machine includes the Attacker; a broken Attacker is reported with its own file and
/// line and the running machine stays; a good edit is swapped in.
#[test]
fn editing_an_included_machine_file_reloads_the_machine() {
    let scratch = std::env::temp_dir().join(format!("mrt-include-reload-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    for e in std::fs::read_dir(dir()).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "lua") {
            std::fs::copy(&p, scratch.join(p.file_name().unwrap())).unwrap();
        }
    }
    let mut cap =
        ThinkingCap::with_hfsm(&scratch, scratch.join("player.hfsm.lua"), Sandbox::default())
            .unwrap();
    let w = WorldSnapshot { game_state: GameState::Playing, ..Default::default() };
    assert!(cap.cycle(w.clone()).errors.is_empty());
    let attacker = scratch.join("attacker.hfsm.lua");
    let good = std::fs::read_to_string(&attacker).unwrap();
    std::fs::write(&attacker, format!("{good}\nmachine \"Broken\" {{")).unwrap();
    let (_, errors) = cap.reload_requested();
    let text = errors.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n");
    assert!(text.contains("attacker.hfsm.lua:"), "{text}");
    assert!(cap.cycle(w.clone()).errors.is_empty(), "the old machine keeps running");
    std::fs::write(
        &attacker,
        good.replace("math.abs(chaos.lps_getLpo(BALL).theta) < 0.25", "true"),
    )
    .unwrap();
    let (done, errors) = cap.reload_requested();
    assert!(
        errors.is_empty() && done.iter().any(|d| d.ends_with("player.hfsm.lua")),
        "{done:?} {errors:?}"
    );
    std::fs::remove_dir_all(&scratch).unwrap();
}

/// The shipped field player's machine (`player.hfsm.lua`).
fn player() -> ThinkingCap {
    ThinkingCap::with_hfsm(dir(), dir().join("player.hfsm.lua"), Sandbox::default()).unwrap()
}

/// The roles' scene at `t_ms`: playing, the robot at (−2000, 0) facing the opponent's net,
/// the ball 800 mm ahead at (−1200, 0), the goalkeeper teammate at (−8500, 0).
fn role_scene(t_ms: u64) -> World {
    World::at(t_ms)
        .playing()
        .me(-2000.0, 0.0, 0.0, 0.9)
        .ball(800.0, 0.0)
        .global_ball(-1200.0, 0.0)
        .net1(7800.0, 0.0)
        .mate(0, -8500.0, 0.0, true)
}

/// The field player's roles (ThinkingCap/TeamChaos report §5.1, figure 8). The robot stands at (−2000, 0) facing
/// the opponent's net; the ball is 800 mm ahead, at (−1200, 0). The goalkeeper at (−8500, 0)
/// is always left out of the ranking. The first cycle enters Wait, the second starts the game
/// (Search); from the third the role is played, and `gotopos` drives towards its spot:
/// - alone near the ball: rank 1 → GetBehind, then (800 mm ahead, 800 mm behind the ball on
///   its line to the net: aheadOfBall = −800 < −250) Behind → the seed's Attacker;
/// - a teammate at (−1000, 300), 361 mm from the ball: rank 2 → Support. The spot is 2 m
///   behind the ball and 1.5 m towards the middle (the ball is at y = 0, so +y): (−3200, 1500),
///   in the robot's frame 1200 mm back and 1500 mm left: go BACK alone (centroid of
///   TOL(−300, −150) on [−300, 300]: a right triangle from −300 to −150, centroid −250),
///   strafe LEFT alone (100), ball ahead: turn NONE (0);
/// - a second teammate at (−1500, −200), 361 mm from the ball: rank 3 → Defend. The spot is on
///   the line from our net (−9000, 0) to the ball, 0.4 × 7800 = 3120 mm out: (−5880, 0), 3880
///   mm behind the robot: go BACK (−250), strafe NONE (0).
#[test]
fn field_players_share_the_roles_by_their_distance_to_the_ball() {
    let base = role_scene;
    let run4 = |extra: &dyn Fn(World) -> World| {
        let mut cap = player();
        (0..4)
            .map(|k| {
                let c = cap.cycle(extra(base(k * 100)).0);
                assert!(c.errors.is_empty(), "{:?}", c.errors);
                c
            })
            .collect::<Vec<_>>()
    };
    // Behind the ball, the attacker-to-be waits for the ball booking (ThinkingCap/TeamChaos report §3.3): it
    // asks for it, and attacks once its world snapshot says it holds it.
    let unbooked = run4(&|w| w);
    let paths: Vec<&str> = unbooked.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(paths, ["Player/Wait", "Player/Search", "Player/GetBehind", "Player/GetBehind"]);
    assert_eq!(unbooked[3].command.book_ball, Some(true));
    let alone = run4(&|mut w| {
        w.0.ball_booked = true;
        w
    });
    let paths: Vec<&str> = alone.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(
        paths,
        ["Player/Wait", "Player/Search", "Player/GetBehind", "Player/Attack/FaceBall"]
    );
    assert_eq!(alone[3].command.book_ball, Some(true), "the Attacker keeps asking");

    let second = run4(&|w| w.mate(2, -1000.0, 300.0, false));
    assert_eq!(second[2].path, "Player/Support");
    assert_eq!(second[2].command.book_ball, Some(false), "a supporter gives the booking back");
    assert_eq!(second[2].behavior.as_deref(), Some("gotopos"));
    let c = &second[2].command;
    close(c.vlin(), -250.0 * GO);
    close(c.vlat(), 100.0 * STRAFE);
    close(c.vrot(), 0.0);

    let third = run4(&|w| w.mate(2, -1000.0, 300.0, false).mate(3, -1500.0, -200.0, false));
    assert_eq!(third[2].path, "Player/Defend");
    let c = &third[2].command;
    close(c.vlin(), -250.0 * GO);
    close(c.vlat(), 0.0);
}

/// The attacker-to-be hands over to the seed's Attacker once it is behind the ball (more than
/// 250 mm back along the ball's line to the net) and within 1.5 m of it. The ball is at
/// (−1200, 0), the net's middle straight ahead along +x; the robot 1200 mm from the ball:
/// - 300 mm back and 1162 mm aside, at (−1500, −1162): Behind → Attack/FaceBall;
/// - 200 mm back, at (−1400, −1183): still GetBehind;
/// - 1600 mm straight back, at (−2800, 0): too far, still GetBehind.
#[test]
fn the_attacker_takes_over_behind_the_ball_within_reach() {
    let path_at = |x: f64, y: f64| {
        let mut cap = player();
        let (dx, dy) = (-1200.0 - x, -y);
        let mut last = String::new();
        for k in 0..4 {
            let mut w = World::at(k * 100)
                .playing()
                .me(x, y, 0.0, 0.9)
                .ball(dx.hypot(dy), dy.atan2(dx))
                .global_ball(-1200.0, 0.0)
                .mate(0, -8500.0, 0.0, true);
            w.0.ball_booked = true;
            let c = cap.cycle(w.0);
            assert!(c.errors.is_empty(), "{:?}", c.errors);
            last = c.path;
        }
        last
    };
    assert_eq!(path_at(-1500.0, -1162.0), "Player/Attack/FaceBall");
    assert_eq!(path_at(-1400.0, -1183.0), "Player/GetBehind");
    assert_eq!(path_at(-2800.0, 0.0), "Player/GetBehind");
}

/// The Supporter and the Defender keep their roles while a teammate is within `HOLD` (400
/// mm) of their own distance to the ball, and swap once it is clearly nearer or farther. The
/// robot stands 800 mm from the ball, as in the test above; teammate A at (−1000, 300) is 361
/// mm from the ball (clearly nearer), teammate B moves:
/// - B 1000 mm from the ball (200 mm farther than the robot): rank 2, Support, cycle after
///   cycle. With the hold margins the wrong way round (Support → Defend when B is nearer
///   than the robot's distance + 400; Defend → Support when only A is nearer than its
///   distance − 400) both swaps held here and the robot changed roles at every cycle,
///   turning its spot back and forth (a trace of a vision match: 600 swaps a match);
/// - B 100 mm from the ball: rank 3, Defend;
/// - B back at 1000 mm: still within the hold, the robot stays Defend;
/// - B 1300 mm from the ball (500 mm farther): Support again.
#[test]
fn supporter_and_defender_hold_their_roles_within_the_margin() {
    let mut cap = player();
    let world = |t: u64, b_from_ball: f64| {
        role_scene(t).mate(2, -1000.0, 300.0, false).mate(3, -1200.0, -b_from_ball, false)
    };
    let mut t = 0;
    let mut play = |b_from_ball: f64, cycles: usize| {
        (0..cycles)
            .map(|_| {
                t += 100;
                let c = cap.cycle(world(t, b_from_ball).0);
                assert!(c.errors.is_empty(), "{:?}", c.errors);
                c.path
            })
            .collect::<Vec<_>>()
    };
    let start = play(1000.0, 8);
    assert_eq!(start[..2], ["Player/Wait", "Player/Search"]);
    assert!(start[2..].iter().all(|p| p == "Player/Support"), "{start:?}");
    assert!(play(100.0, 3).iter().all(|p| p == "Player/Defend"));
    let held = play(1000.0, 6);
    assert!(held.iter().all(|p| p == "Player/Defend"), "{held:?}");
    let back = play(1300.0, 2);
    assert_eq!(back.last().map(String::as_str), Some("Player/Support"), "{back:?}");
}

/// The supporter keeps `SUPPORT_FLOOR` (3 m) from our goal line: with the ball deep in our
/// half at (−7000, 1000), 2 m behind it would be x = −9000, on our goal line beside the keeper.
/// A teammate 300 mm from the ball is the attacker-to-be; the robot, 1803 mm from the ball, is
/// the Supporter, and its spot is (−6000, −500): 3 m out, 1.5 m towards the middle. Standing
/// there facing the ball (atan2(1500, −1000)), it stays: go STAY, strafe NONE, turn NONE, all
/// 0. Without the floor the spot would be (−8500, −500) (clamped into the field), 1387 mm
/// ahead along its heading: go FAST.
#[test]
fn the_supporter_stays_out_of_our_goal_mouth() {
    let mut cap = player();
    let cycles = (0..4)
        .map(|k| {
            let w = World::at(k * 100)
                .playing()
                .me(-6000.0, -500.0, 1500.0f64.atan2(-1000.0), 0.9)
                .ball(1000.0f64.hypot(1500.0), 0.0)
                .global_ball(-7000.0, 1000.0)
                .mate(0, -8500.0, 0.0, true)
                .mate(2, -7000.0, 1300.0, false);
            let c = cap.cycle(w.0);
            assert!(c.errors.is_empty(), "{:?}", c.errors);
            c
        })
        .collect::<Vec<_>>();
    let paths: Vec<&str> = cycles.iter().map(|c| c.path.as_str()).collect();
    assert_eq!(paths[2..], ["Player/Support", "Player/Support"], "{paths:?}");
    let c = &cycles[3].command;
    close(c.vlin(), 0.0);
    close(c.vlat(), 0.0);
    close(c.vrot(), 0.0);
}

/// The behaviors read the field from the world model (`getField`): on a 12 m field the
/// goalkeeper's own net is at x = −6000, so a keeper standing at x = −6050 is in it
/// (inOwnNet = TOL(−6100, −5850)(−6050) = 0.8 ≥ every other meta-rule's NOT(inOwnNet) = 0.2;
/// `gkkeepout` wins the blend: it turns LEFT and needs the net, as in
/// `goalkeeper_gets_out_of_its_net`), while on the default 18 m field the same robot is 3 m
/// out of its net and `gkkeepout` has no say (turn follows the ball straight ahead: 0).
#[test]
fn the_behaviors_play_on_the_field_the_world_model_describes() {
    let w = World::at(0).me(-6050.0, 0.0, 0.0, 0.9).ball(2000.0, 0.0).global_ball(-4000.0, 0.0);
    let mut small = w.clone();
    small.0.field.half_length = 6.0;
    let on_small = run("goalkeeper", small);
    let on_default = run("goalkeeper", w);
    assert!(on_small.command.vrot() > 20.0 && on_small.command.need(lps::NET1) > 0.7);
    assert!(on_default.command.vrot().abs() < 1e-9, "{:?}", on_default.command);
}

/// In READY the referee tells each robot its kickoff place (`getKickoffPose`): a field player
/// waits with the `ready` behavior and the goalkeeper's top behavior hands over to it; both
/// ask guidance for that posture (`setTarget`, round obstacles) instead of velocities. In SET
/// they stand.
#[test]
fn in_ready_the_players_and_the_goalkeeper_walk_to_their_kickoff_places() {
    let pose = mrt_core::frames::Framed::new(mrt_core::Pose2::new(-3.0, 1.2, 0.0));
    let ready = |mut w: World| {
        w.0.game_state = GameState::Ready;
        w.0.kickoff_pose = Some(pose);
        w
    };
    let want = Some(mrt_msgs::robot::Target { pose, avoid: true, plan: false });
    let mut player =
        ThinkingCap::with_hfsm(dir(), dir().join("player.hfsm.lua"), Sandbox::default()).unwrap();
    let c = player.cycle(ready(World::at(0).me(-5000.0, -5000.0, 1.57, 0.9).ball(4000.0, 0.5)).0);
    assert!(c.errors.is_empty(), "{:?}", c.errors);
    assert_eq!((c.path.as_str(), c.behavior.as_deref()), ("Player/Wait", Some("ready")));
    assert_eq!(c.command.target, want);
    assert_eq!(c.command.need(lps::BALL), 1.0);
    let keeper = run("goalkeeper", ready(World::at(0).me(-8000.0, -5000.0, 1.57, 0.9)));
    assert_eq!(keeper.command.target, want);
    let mut set = World::at(100).me(-3000.0, 1200.0, 0.0, 0.9).0;
    set.game_state = GameState::Set;
    let c = player.cycle(set);
    assert_eq!((c.behavior.as_deref(), c.command.target), (Some("stand"), None));
}
