//! The team side of the world state (ISocRob-2000 report §3.1: each robot shares what it
//! knows with its teammates; ThinkingCap report §2.1: the global ball): teammates' poses from their
//! [`MateReport`]s, the team ball fused from everyone's, the anchored robots of unknown team
//! that stand where a teammate says it is made teammates, and the robots teammates see that
//! this robot does not. Team frame, metres.

use mrt_core::frames::Framed;
use mrt_core::{Point2, Pose2};
use mrt_msgs::{AnchoredRobot, Estimate, Mate, MateReport, RobotClass, SharedRobot, WorldSnapshot};

/// A teammate's ball counts this much of its own quality: a second-hand sighting, one cycle
/// old, is trusted a little less than one's own.
pub const SHARED_BALL: f64 = 0.9;

/// A teammate's ball is one cycle old: the ball may have rolled this far meanwhile, m (added
/// to its uncertainty).
pub const SHARED_DRIFT: f64 = 0.05;

/// Two estimates of the ball are of the same ball when they are within this many standard
/// deviations of each other (their variances summed).
pub const SAME_BALL: f64 = 3.0;

/// A robot whose own ball estimate is at least this good (a sighting of this frame has 1)
/// keeps it: the team ball fills in for the robots that do not see the ball.
pub const SEES_BALL: f64 = 0.99;

/// The standard deviation (m) of a ball estimate that gives none: read from its quality (a
/// fresh sighting, quality 1, 0.1 m; ten times that at quality 0.1).
pub fn sigma_from_quality(quality: f64) -> f64 {
    0.1 / quality.clamp(0.01, 1.0)
}

/// One ball estimate in the team's fusion (team frame, m).
#[derive(Clone, Copy, Debug)]
struct Sighting {
    at: Point2,
    sigma: f64,
    quality: f64,
}

impl Sighting {
    fn new(e: &Estimate, sigma: Option<f64>, quality: f64) -> Option<Sighting> {
        let sigma = sigma.filter(|s| s.is_finite() && *s > 0.0);
        let at = e.pose.inner.position();
        let ok = at.x.is_finite() && at.y.is_finite() && quality.is_finite();
        (ok && quality > 0.0).then(|| Sighting {
            at,
            sigma: sigma.unwrap_or_else(|| sigma_from_quality(e.quality)),
            quality: quality.min(1.0),
        })
    }

    /// Its weight in the fused estimate: its quality over its variance.
    fn weight(&self) -> f64 {
        self.quality / (self.sigma * self.sigma)
    }

    fn agrees(&self, other: &Sighting) -> bool {
        let d2 = (self.at - other.at).norm_squared();
        d2 <= SAME_BALL * SAME_BALL * (self.sigma.powi(2) + other.sigma.powi(2))
    }
}

/// The team side of the world state (ThinkingCap's global ball, report §2.1; MAP's team
/// level): `w.mates` from the teammates' reports (in their order), and the **team ball**: the
/// robot's own ball estimate (`own_sigma`, m, its uncertainty; `None` reads it from the
/// quality) fused with its teammates'.
///
/// The fusion: every estimate (a teammate's with [`SHARED_BALL`] of its quality and
/// [`SHARED_DRIFT`] more uncertainty) gathers those that agree with it (within [`SAME_BALL`]
/// standard deviations); the largest gathering by weight (quality over variance) wins, an
/// estimate that disagrees with it (a false sighting, a robot that is lost) is left out, and
/// the team ball is the gathering's inverse-variance weighted mean, with the best quality in
/// it. A robot that sees the ball this frame ([`SEES_BALL`]) keeps its own estimate; one that
/// does not gets where its team thinks it is, its own fading memory counting with the rest.
/// The LPS stays what the robot itself perceived.
pub fn merge_team<'a>(
    w: &mut WorldSnapshot,
    own_sigma: Option<f64>,
    reports: impl IntoIterator<Item = &'a MateReport>,
) {
    w.mates.clear();
    // A robot that sees the ball now trusts its own eyes: the ball it is about to play is the
    // one it sees, not an average with teammates further away.
    let sees = w.global_ball.quality >= SEES_BALL;
    let mut all: Vec<Sighting> = Vec::new();
    all.extend(Sighting::new(&w.global_ball, own_sigma, w.global_ball.quality));
    let own = !all.is_empty();
    let mut shared: Vec<(u32, usize, SharedRobot)> = Vec::new();
    for r in reports {
        w.mates.push(Mate { id: r.id, at: r.pose, keeper: r.keeper });
        shared.extend(r.robots.iter().enumerate().map(|(k, s)| (r.id, k, *s)));
        if sees {
            continue;
        }
        let given = (r.ball_sigma > 0.0).then_some(r.ball_sigma);
        let sigma = given.unwrap_or_else(|| sigma_from_quality(r.ball.quality)) + SHARED_DRIFT;
        all.extend(Sighting::new(&r.ball, Some(sigma), r.ball.quality * SHARED_BALL));
    }
    recognize_mates(w);
    adopt_shared_robots(w, &shared);
    let gathering =
        |seed: &Sighting| -> Vec<&Sighting> { all.iter().filter(|s| seed.agrees(s)).collect() };
    // The heaviest gathering; on a tie the first (one's own).
    let mut best: Option<(Vec<&Sighting>, f64)> = None;
    for seed in &all {
        let members = gathering(seed);
        let weight: f64 = members.iter().map(|s| s.weight()).sum();
        if best.as_ref().is_none_or(|(_, w)| weight > *w) {
            best = Some((members, weight));
        }
    }
    let Some((members, total)) = best else {
        return;
    };
    if own && members.len() == 1 && std::ptr::eq(members[0], &all[0]) {
        return; // only its own: nothing to fuse
    }
    if !(total.is_finite() && total > 0.0) {
        return;
    }
    let x = members.iter().map(|s| s.weight() * s.at.x).sum::<f64>() / total;
    let y = members.iter().map(|s| s.weight() * s.at.y).sum::<f64>() / total;
    let quality = members.iter().map(|s| s.quality).fold(0.0, f64::max);
    w.global_ball = Estimate { pose: Framed::new(Pose2::new(x, y, 0.0)), quality };
}

/// A robot of unknown team anchored within this distance (m), or three of its standard
/// deviations if more, of where a teammate reports being is that teammate.
pub const SAME_ROBOT: f64 = 0.5;

/// MAP's classifier specialised by the team (a track's concept can be specialised later, MRT
/// manual ch. 8): an anchored Robot whose marker was never seen, standing where a
/// teammate's report puts it, becomes a Teammate.
fn recognize_mates(w: &mut WorldSnapshot) {
    let mates = &w.mates;
    for r in w.robots.iter_mut().filter(|r| r.class == RobotClass::Robot) {
        let gate = SAME_ROBOT.max(3.0 * r.at_sigma);
        let at = r.at.inner;
        if mates
            .iter()
            .any(|m| m.at.quality > 0.0 && (m.at.pose.inner.position() - at).norm() <= gate)
        {
            r.class = RobotClass::Teammate;
        }
    }
}

/// Identities of the robots adopted from teammates' reports have this bit set (then the
/// teammate's number times 256 plus the robot's place in its report): never an own anchor's.
pub const SHARED_ID: u32 = 1 << 31;

/// How old a teammate's sighting is when it arrives, s (one control cycle): a shared robot's
/// `seen_ago`.
pub const SHARED_AGE: f64 = 0.1;

/// MAP's team level (MRT manual ch. 8: a teammate is an intelligent sensor whose instances go
/// into the local fusion): a robot a teammate sees this frame and this robot does
/// not is added to its anchored robots, [`SHARED_BALL`] as reliable and [`SHARED_DRIFT`] less
/// sure. One this robot anchors too (within [`SAME_ROBOT`] or three standard deviations) is not
/// added twice, but a class the teammate knows specialises an own anchor of unknown team. A
/// shared robot where this robot stands (the teammate sees it) is left out, as is a second
/// teammate's report of one already adopted.
fn adopt_shared_robots(w: &mut WorldSnapshot, shared: &[(u32, usize, SharedRobot)]) {
    let (me, quality) = (w.my_pos.pose.inner, w.my_pos.quality);
    let first_adopted = w.robots.len();
    for &(mate, k, s) in shared {
        let at = s.at.inner;
        let finite = at.x.is_finite() && at.y.is_finite() && s.at_sigma.is_finite();
        if !finite || s.at_sigma < 0.0 {
            continue;
        }
        let sigma = s.at_sigma + SHARED_DRIFT;
        if quality > 0.0 && (me.position() - at).norm() <= SAME_ROBOT {
            continue;
        }
        // Squared distances against squared gates: no root per pair.
        let same = |r: &AnchoredRobot| {
            let gate2 =
                (SAME_ROBOT * SAME_ROBOT).max(9.0 * (r.at_sigma * r.at_sigma + sigma * sigma));
            (r.at.inner - at).norm_squared() <= gate2
        };
        if let Some(r) = w.robots[..first_adopted].iter_mut().find(|r| same(r)) {
            if r.class == RobotClass::Robot {
                r.class = s.class;
            }
            continue;
        }
        if w.robots[first_adopted..].iter().any(same) {
            continue;
        }
        let (dx, dy) = (at.x - me.x, at.y - me.y);
        w.robots.push(AnchoredRobot {
            id: SHARED_ID | (mate.min(0x7F_FFFF) << 8) | (k.min(255) as u32),
            class: s.class,
            at: s.at,
            velocity: Framed::default(),
            at_sigma: sigma,
            rho: dx.hypot(dy),
            theta: mrt_core::normalize_angle(dy.atan2(dx) - me.theta),
            reliability: SHARED_BALL,
            seen_ago: SHARED_AGE,
        });
    }
    w.robots.sort_by(|a, b| a.rho.total_cmp(&b.rho));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn estimate(x: f64, y: f64, quality: f64) -> Estimate {
        Estimate { pose: Framed::new(Pose2::new(x, y, 0.0)), quality }
    }

    fn report(id: u32, ball: (f64, f64), quality: f64, sigma: f64) -> MateReport {
        MateReport {
            id,
            keeper: id == 0,
            pose: estimate(-f64::from(id), 0.0, 0.9),
            ball: estimate(ball.0, ball.1, quality),
            ball_sigma: sigma,
            robots: Vec::new(),
            booking: Default::default(),
            role: String::new(),
            scare: Default::default(),
        }
    }

    fn seeing(x: f64, y: f64, quality: f64) -> WorldSnapshot {
        WorldSnapshot { global_ball: estimate(x, y, quality), ..Default::default() }
    }

    fn ball(w: &WorldSnapshot) -> (f64, f64) {
        (w.global_ball.pose.inner.x, w.global_ball.pose.inner.y)
    }

    #[test]
    fn a_robot_of_unknown_team_where_a_teammate_says_it_is_becomes_that_teammate() {
        let robot = |x: f64, class| AnchoredRobot {
            at: Framed::new(Point2::new(x, 0.0)),
            class,
            at_sigma: 0.1,
            reliability: 1.0,
            ..Default::default()
        };
        let mut w = WorldSnapshot {
            robots: vec![
                robot(-2.3, RobotClass::Robot),    // 0.3 m from teammate 2 at −2
                robot(-1.0, RobotClass::Opponent), // its marker said opponent: it stays so
                robot(3.0, RobotClass::Robot),     // nobody reports being there
            ],
            ..Default::default()
        };
        merge_team(
            &mut w,
            None,
            &[report(1, (0.0, 0.0), 0.0, 0.0), report(2, (0.0, 0.0), 0.0, 0.0)],
        );
        let classes: Vec<RobotClass> = w.robots.iter().map(|r| r.class).collect();
        assert_eq!(classes, [RobotClass::Teammate, RobotClass::Opponent, RobotClass::Robot]);
    }

    /// MAP's team level: the robots teammates see fill in what this robot does not see.
    #[test]
    fn robots_teammates_see_are_adopted_once_and_specialise_own_anchors() {
        let shared = |class, x: f64, y: f64, at_sigma| SharedRobot {
            class,
            at: Framed::new(Point2::new(x, y)),
            at_sigma,
        };
        let mut w = WorldSnapshot {
            my_pos: estimate(0.0, 0.0, 0.9),
            robots: vec![AnchoredRobot {
                id: 3,
                class: RobotClass::Robot,
                at: Framed::new(Point2::new(2.0, 0.0)),
                at_sigma: 0.1,
                rho: 2.0,
                reliability: 1.0,
                ..Default::default()
            }],
            ..Default::default()
        };
        let mut one = report(1, (0.0, 0.0), 0.0, 0.0);
        one.robots = vec![
            shared(RobotClass::Opponent, 2.05, 0.03, 0.1), // own anchor 3: now an opponent
            shared(RobotClass::Teammate, 0.0, 0.1, 0.08),  // this robot itself
            shared(RobotClass::Opponent, -3.0, 2.0, 0.15), // unseen here: adopted
        ];
        let mut two = report(2, (0.0, 0.0), 0.0, 0.0);
        two.robots = vec![
            shared(RobotClass::Opponent, -3.1, 2.05, 0.15), // the same, told twice
            shared(RobotClass::Opponent, f64::NAN, 0.0, 0.1), // not a place
        ];
        merge_team(&mut w, None, &[one, two]);
        assert_eq!(w.robots.len(), 2, "{:?}", w.robots);
        let (own, adopted) = (&w.robots[0], &w.robots[1]);
        assert_eq!((own.id, own.class), (3, RobotClass::Opponent));
        assert_eq!(adopted.id, SHARED_ID | (1 << 8) | 2);
        assert_eq!(adopted.class, RobotClass::Opponent);
        assert_eq!(adopted.at.inner, Point2::new(-3.0, 2.0));
        assert_eq!(adopted.at_sigma, 0.15 + SHARED_DRIFT);
        assert_eq!((adopted.reliability, adopted.seen_ago), (SHARED_BALL, SHARED_AGE));
        // Distance and bearing from this robot: √(3² + 2²), atan2(2, −3).
        assert!((adopted.rho - 3.605551).abs() < 1e-6);
        assert!((adopted.theta - 2f64.atan2(-3.0)).abs() < 1e-12);
        // What this robot tells its team: only what it sees itself this frame (the adopted
        // robot is a cycle old: hearsay does not circulate).
        let mine = MateReport::of(5, false, &w);
        assert_eq!(mine.robots.len(), 1, "{mine:?}");
        assert_eq!((mine.robots[0].at.inner.x, mine.robots[0].class), (2.0, RobotClass::Opponent));
    }

    #[test]
    fn teammates_are_listed_in_their_order() {
        let mut w = WorldSnapshot::default();
        let reports = [report(0, (0.0, 0.0), 0.0, 0.0), report(2, (0.0, 0.0), 0.0, 0.0)];
        merge_team(&mut w, None, &reports);
        assert_eq!(
            w.mates.iter().map(|m| (m.id, m.keeper)).collect::<Vec<_>>(),
            [(0, true), (2, false)]
        );
        assert_eq!(w.mates[1].at.pose.inner.x, -2.0);
        assert_eq!(w.global_ball.quality, 0.0, "nobody saw the ball");
    }

    #[test]
    fn agreeing_estimates_fuse_by_inverse_variance() {
        // Own, remembered from the last frame: (1, 0), σ 0.1 m, quality 0.95: weight
        // 0.95 / 0.1² = 95. Mate 2: (1.2, 0), σ 0.15 + 0.05 (one cycle's drift) = 0.2 m,
        // quality 1 × 0.9: weight 0.9 / 0.2² = 22.5. They agree: 0.2 m apart, within
        // 3 × √(0.1² + 0.2²) = 0.671. Fused x = (95 × 1 + 22.5 × 1.2) / 117.5 = 1.0382979 m,
        // quality max(0.95, 0.9).
        let mut w = seeing(1.0, 0.0, 0.95);
        merge_team(&mut w, Some(0.1), &[report(2, (1.2, 0.0), 1.0, 0.15)]);
        assert!((ball(&w).0 - 1.0382979).abs() < 1e-6, "{:?}", w.global_ball);
        assert_eq!((ball(&w).1, w.global_ball.quality), (0.0, 0.95));
    }

    #[test]
    fn a_robot_that_sees_the_ball_keeps_its_own() {
        let mut w = seeing(1.0, 0.0, 1.0);
        merge_team(&mut w, Some(0.1), &[report(2, (1.2, 0.0), 1.0, 0.15)]);
        assert_eq!((ball(&w).0, w.global_ball.quality), (1.0, 1.0));
        assert_eq!(w.mates.len(), 1, "the mates are listed all the same");
    }

    #[test]
    fn a_robot_that_does_not_see_the_ball_gets_its_teams() {
        // Two mates, (2, 0.5) and (2.1, 0.5), σ 0.1 + 0.05 each, quality 0.8 × 0.9 = 0.72:
        // equal weights, the mean (2.05, 0.5), quality 0.72.
        let mut w = WorldSnapshot::default();
        let reports = [report(1, (2.0, 0.5), 0.8, 0.1), report(3, (2.1, 0.5), 0.8, 0.1)];
        merge_team(&mut w, None, &reports);
        let (x, y) = ball(&w);
        assert!((x - 2.05).abs() < 1e-9 && (y - 0.5).abs() < 1e-9, "{:?}", w.global_ball);
        assert!((w.global_ball.quality - 0.72).abs() < 1e-12);
    }

    #[test]
    fn an_estimate_the_others_contradict_is_left_out() {
        // Own (0, 0) σ 0.1 and mate 1 (0.1, 0) σ 0.1 (+0.05) agree; mate 2 (5, 3) σ 0.1
        // (+0.05), a robot that is lost, agrees with nobody: the gathering of two wins.
        // Weights: own 95, mate 1 0.9 / 0.15² = 40: x = 40 × 0.1 / 135 = 0.0296296.
        let mut w = seeing(0.0, 0.0, 0.95);
        let reports = [report(1, (0.1, 0.0), 1.0, 0.1), report(2, (5.0, 3.0), 1.0, 0.1)];
        merge_team(&mut w, Some(0.1), &reports);
        assert!((ball(&w).0 - 0.0296296).abs() < 1e-6, "{:?}", w.global_ball);
        assert_eq!(ball(&w).1, 0.0);
    }

    #[test]
    fn a_sharp_own_sighting_outweighs_a_vague_contradiction() {
        // Own: σ 0.05 m, quality 0.95 (weight 380). A far mate says (4, 0) with σ 1 + 0.05 and
        // quality 0.5 × 0.9 (weight 0.41): they do not agree (4 > 3 × √(0.05² + 1.05²) =
        // 3.154); own wins alone.
        let mut w = seeing(0.0, 0.0, 0.95);
        merge_team(&mut w, Some(0.05), &[report(4, (4.0, 0.0), 0.5, 1.0)]);
        assert_eq!((ball(&w).0, w.global_ball.quality), (0.0, 0.95));
    }

    #[test]
    fn without_sigmas_the_quality_sets_the_weights() {
        // Old reports give no σ: 0.1 / quality. Own quality 0.5: σ 0.2, weight 0.5 / 0.04 =
        // 12.5; mate quality 1 → σ 0.1 + 0.05, quality 0.9, weight 40.
        // x = (12.5 × 0 + 40 × 0.3) / 52.5 = 0.228571; the best quality, 0.9.
        let mut w = seeing(0.0, 0.0, 0.5);
        merge_team(&mut w, None, &[report(5, (0.3, 0.0), 1.0, 0.0)]);
        assert!((ball(&w).0 - 0.228571).abs() < 1e-6, "{:?}", w.global_ball);
        assert!((w.global_ball.quality - 0.9).abs() < 1e-12);
        // The report carries the robot's own sighting, not the merged one, and its σ.
        let r = MateReport::of(7, false, &w).with_ball_sigma(0.08);
        assert_eq!((r.id, r.ball.quality, r.ball_sigma), (7, w.global_ball.quality, 0.08));
    }

    #[test]
    fn non_finite_reports_are_ignored() {
        let mut w = seeing(0.01, 0.0, 0.95);
        let bad = [report(1, (f64::NAN, 0.0), 1.0, 0.1), report(2, (0.0, 0.0), f64::NAN, 1.0)];
        merge_team(&mut w, Some(0.1), &bad);
        assert_eq!((ball(&w).0, w.global_ball.quality), (0.01, 0.95));
    }
}
