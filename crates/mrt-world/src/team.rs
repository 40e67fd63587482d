//! The team side of the world state (ISocRob seed `003` §3.1: each robot shares what it knows
//! with its teammates; TeamChaos seed `001` §2.1: the global ball): teammates' poses from their
//! [`MateReport`]s, the team ball fused from everyone's, the anchored robots of unknown team
//! that stand where a teammate says it is made teammates, and the robots teammates see that
//! this robot does not.

use mrt_core::Pose2;
use mrt_msgs::{AnchoredRobot, Estimate, Mate, MateReport, RobotClass, SharedRobot, WorldSnapshot};

/// A teammate's ball counts this much of its own quality: a second-hand sighting, one cycle
/// old, is trusted a little less than one's own.
pub const SHARED_BALL: f64 = 0.9;

/// A teammate's ball is one cycle old: the ball may have rolled this far meanwhile, mm (added
/// to its uncertainty).
pub const SHARED_DRIFT: f64 = 50.0;

/// Two estimates of the ball are of the same ball when they are within this many standard
/// deviations of each other (their variances summed).
pub const SAME_BALL: f64 = 3.0;

/// A robot whose own ball estimate is at least this good (a sighting of this frame has 1)
/// keeps it: the team ball fills in for the robots that do not see the ball.
pub const SEES_BALL: f64 = 0.99;

/// The standard deviation (mm) of a ball estimate that gives none: read from its quality (a
/// fresh sighting, quality 1, 100 mm; ten times that at quality 0.1).
pub fn sigma_from_quality(quality: f64) -> f64 {
    100.0 / quality.clamp(0.01, 1.0)
}

/// One ball estimate in the team's fusion (team frame, mm).
#[derive(Clone, Copy, Debug)]
struct Sighting {
    x: f64,
    y: f64,
    sigma: f64,
    quality: f64,
}

impl Sighting {
    fn new(e: &Estimate, sigma: Option<f64>, quality: f64) -> Option<Sighting> {
        let sigma = sigma.filter(|s| s.is_finite() && *s > 0.0);
        let ok = e.pose.x.is_finite() && e.pose.y.is_finite() && quality.is_finite();
        (ok && quality > 0.0).then(|| Sighting {
            x: e.pose.x,
            y: e.pose.y,
            sigma: sigma.unwrap_or_else(|| sigma_from_quality(e.quality)),
            quality: quality.min(1.0),
        })
    }

    /// Its weight in the fused estimate: its quality over its variance.
    fn weight(&self) -> f64 {
        self.quality / (self.sigma * self.sigma)
    }

    fn agrees(&self, other: &Sighting) -> bool {
        let d2 = (self.x - other.x).powi(2) + (self.y - other.y).powi(2);
        d2 <= SAME_BALL * SAME_BALL * (self.sigma.powi(2) + other.sigma.powi(2))
    }
}

/// The team side of the world state (TeamChaos' global ball, seed `001` §2.1; MAP's team
/// level): `w.mates` from the teammates' reports (in their order), and the **team ball**: the
/// robot's own ball estimate (`own_sigma`, mm, its uncertainty; `None` reads it from the
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
    let x = members.iter().map(|s| s.weight() * s.x).sum::<f64>() / total;
    let y = members.iter().map(|s| s.weight() * s.y).sum::<f64>() / total;
    let quality = members.iter().map(|s| s.quality).fold(0.0, f64::max);
    w.global_ball = Estimate { pose: Pose2::new(x, y, 0.0), quality };
}

/// A robot of unknown team anchored within this distance (mm), or three of its standard
/// deviations if more, of where a teammate reports being is that teammate.
pub const SAME_ROBOT: f64 = 500.0;

/// MAP's classifier specialised by the team (research note MODULES.md §3: "a track's concept
/// can be specialised later"): an anchored Robot whose marker was never seen, standing where a
/// teammate's report puts it, becomes a Teammate.
fn recognize_mates(w: &mut WorldSnapshot) {
    let mates = &w.mates;
    for r in w.robots.iter_mut().filter(|r| r.class == RobotClass::Robot) {
        let gate = SAME_ROBOT.max(3.0 * r.sigma);
        if mates
            .iter()
            .any(|m| m.at.quality > 0.0 && (m.at.pose.x - r.x).hypot(m.at.pose.y - r.y) <= gate)
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

/// MAP's team level (research note MODULES.md §3: a teammate is an intelligent sensor whose
/// instances go into the local fusion): a robot a teammate sees this frame and this robot does
/// not is added to its anchored robots, [`SHARED_BALL`] as reliable and [`SHARED_DRIFT`] less
/// sure. One this robot anchors too (within [`SAME_ROBOT`] or three standard deviations) is not
/// added twice, but a class the teammate knows specialises an own anchor of unknown team. A
/// shared robot where this robot stands (the teammate sees it) is left out, as is a second
/// teammate's report of one already adopted.
fn adopt_shared_robots(w: &mut WorldSnapshot, shared: &[(u32, usize, SharedRobot)]) {
    let me = w.my_pos;
    let first_adopted = w.robots.len();
    for &(mate, k, s) in shared {
        let finite = s.x.is_finite() && s.y.is_finite() && s.sigma.is_finite();
        if !finite || s.sigma < 0.0 {
            continue;
        }
        let sigma = s.sigma + SHARED_DRIFT;
        if me.quality > 0.0 && (me.pose.x - s.x).hypot(me.pose.y - s.y) <= SAME_ROBOT {
            continue;
        }
        // Squared distances against squared gates: no root per pair.
        let same = |r: &AnchoredRobot| {
            let gate2 = (SAME_ROBOT * SAME_ROBOT).max(9.0 * (r.sigma * r.sigma + sigma * sigma));
            (r.x - s.x).powi(2) + (r.y - s.y).powi(2) <= gate2
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
        let (dx, dy) = (s.x - me.pose.x, s.y - me.pose.y);
        w.robots.push(AnchoredRobot {
            id: SHARED_ID | (mate.min(0x7F_FFFF) << 8) | (k.min(255) as u32),
            class: s.class,
            x: s.x,
            y: s.y,
            vx: 0.0,
            vy: 0.0,
            sigma,
            rho: dx.hypot(dy),
            theta: mrt_core::normalize_angle(dy.atan2(dx) - me.pose.theta),
            reliability: SHARED_BALL,
            seen_ago: SHARED_AGE,
        });
    }
    w.robots.sort_by(|a, b| a.rho.total_cmp(&b.rho));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(id: u32, ball: (f64, f64), quality: f64, sigma: f64) -> MateReport {
        MateReport {
            id,
            keeper: id == 0,
            pose: Estimate { pose: Pose2::new(-1000.0 * f64::from(id), 0.0, 0.0), quality: 0.9 },
            ball: Estimate { pose: Pose2::new(ball.0, ball.1, 0.0), quality },
            ball_sigma: sigma,
            robots: Vec::new(),
            booking: Default::default(),
            role: String::new(),
            scare: Default::default(),
        }
    }

    fn seeing(x: f64, y: f64, quality: f64) -> WorldSnapshot {
        WorldSnapshot {
            global_ball: Estimate { pose: Pose2::new(x, y, 0.0), quality },
            ..Default::default()
        }
    }

    #[test]
    fn a_robot_of_unknown_team_where_a_teammate_says_it_is_becomes_that_teammate() {
        use mrt_msgs::AnchoredRobot;
        let robot = |x: f64, class| AnchoredRobot {
            x,
            class,
            sigma: 100.0,
            reliability: 1.0,
            ..Default::default()
        };
        let mut w = WorldSnapshot {
            robots: vec![
                robot(-2300.0, RobotClass::Robot), // 300 mm from teammate 2 at −2000
                robot(-1000.0, RobotClass::Opponent), // its marker said opponent: it stays so
                robot(3000.0, RobotClass::Robot),  // nobody reports being there
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
        let shared = |class, x: f64, y: f64, sigma| SharedRobot { class, x, y, sigma };
        let mut w = WorldSnapshot {
            my_pos: Estimate { pose: Pose2::new(0.0, 0.0, 0.0), quality: 0.9 },
            robots: vec![AnchoredRobot {
                id: 3,
                class: RobotClass::Robot,
                x: 2000.0,
                sigma: 100.0,
                rho: 2000.0,
                reliability: 1.0,
                ..Default::default()
            }],
            ..Default::default()
        };
        let mut one = report(1, (0.0, 0.0), 0.0, 0.0);
        one.robots = vec![
            shared(RobotClass::Opponent, 2050.0, 30.0, 100.0), // own anchor 3: now an opponent
            shared(RobotClass::Teammate, 0.0, 100.0, 80.0),    // this robot itself
            shared(RobotClass::Opponent, -3000.0, 2000.0, 150.0), // unseen here: adopted
        ];
        let mut two = report(2, (0.0, 0.0), 0.0, 0.0);
        two.robots = vec![
            shared(RobotClass::Opponent, -3100.0, 2050.0, 150.0), // the same, told twice
            shared(RobotClass::Opponent, f64::NAN, 0.0, 100.0),   // not a place
        ];
        merge_team(&mut w, None, &[one, two]);
        assert_eq!(w.robots.len(), 2, "{:?}", w.robots);
        let (own, adopted) = (&w.robots[0], &w.robots[1]);
        assert_eq!((own.id, own.class), (3, RobotClass::Opponent));
        assert_eq!(adopted.id, SHARED_ID | (1 << 8) | 2);
        assert_eq!(adopted.class, RobotClass::Opponent);
        assert_eq!((adopted.x, adopted.y, adopted.sigma), (-3000.0, 2000.0, 150.0 + SHARED_DRIFT));
        assert_eq!((adopted.reliability, adopted.seen_ago), (SHARED_BALL, SHARED_AGE));
        // Distance and bearing from this robot: √(3000² + 2000²), atan2(2000, −3000).
        assert!((adopted.rho - 3605.551).abs() < 1e-3);
        assert!((adopted.theta - 2000f64.atan2(-3000.0)).abs() < 1e-12);
        // What this robot tells its team: only what it sees itself this frame (the adopted
        // robot is a cycle old: hearsay does not circulate).
        let mine = MateReport::of(5, false, &w);
        assert_eq!(mine.robots.len(), 1, "{mine:?}");
        assert_eq!((mine.robots[0].x, mine.robots[0].class), (2000.0, RobotClass::Opponent));
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
        assert_eq!(w.mates[1].at.pose.x, -2000.0);
        assert_eq!(w.global_ball.quality, 0.0, "nobody saw the ball");
    }

    #[test]
    fn agreeing_estimates_fuse_by_inverse_variance() {
        // Own, remembered from the last frame: (1000, 0), σ 100 mm, quality 0.95: weight
        // 0.95 / 100² = 9.5e-5. Mate 2: (1200, 0), σ 150 + 50 (one cycle's drift) = 200 mm,
        // quality 1 × 0.9: weight 0.9 / 200² = 2.25e-5. They agree: 200 mm apart, within
        // 3 × √(100² + 200²) = 671. Fused x = (9.5e-5 × 1000 + 2.25e-5 × 1200) / 1.175e-4
        // = 1038.30 mm, quality max(0.95, 0.9).
        let mut w = seeing(1000.0, 0.0, 0.95);
        merge_team(&mut w, Some(100.0), &[report(2, (1200.0, 0.0), 1.0, 150.0)]);
        assert!((w.global_ball.pose.x - 1038.2979).abs() < 1e-3, "{:?}", w.global_ball);
        assert_eq!((w.global_ball.pose.y, w.global_ball.quality), (0.0, 0.95));
    }

    #[test]
    fn a_robot_that_sees_the_ball_keeps_its_own() {
        let mut w = seeing(1000.0, 0.0, 1.0);
        merge_team(&mut w, Some(100.0), &[report(2, (1200.0, 0.0), 1.0, 150.0)]);
        assert_eq!((w.global_ball.pose.x, w.global_ball.quality), (1000.0, 1.0));
        assert_eq!(w.mates.len(), 1, "the mates are listed all the same");
    }

    #[test]
    fn a_robot_that_does_not_see_the_ball_gets_its_teams() {
        // Two mates, (2000, 500) and (2100, 500), σ 100 + 50 each, quality 0.8 × 0.9 = 0.72:
        // equal weights, the mean (2050, 500), quality 0.72.
        let mut w = WorldSnapshot::default();
        let reports =
            [report(1, (2000.0, 500.0), 0.8, 100.0), report(3, (2100.0, 500.0), 0.8, 100.0)];
        merge_team(&mut w, None, &reports);
        let b = w.global_ball;
        assert!((b.pose.x - 2050.0).abs() < 1e-9 && (b.pose.y - 500.0).abs() < 1e-9, "{b:?}");
        assert!((b.quality - 0.72).abs() < 1e-12);
    }

    #[test]
    fn an_estimate_the_others_contradict_is_left_out() {
        // Own (0, 0) σ 100 and mate 1 (100, 0) σ 100 (+50) agree; mate 2 (5000, 3000) σ 100
        // (+50), a robot that is lost, agrees with nobody: the gathering of two wins.
        // Weights: own 0.95e-4, mate 1 0.9 / 150² = 4e-5: x = 4e-5 × 100 / 1.35e-4 = 29.63.
        let mut w = seeing(0.0, 0.0, 0.95);
        let reports =
            [report(1, (100.0, 0.0), 1.0, 100.0), report(2, (5000.0, 3000.0), 1.0, 100.0)];
        merge_team(&mut w, Some(100.0), &reports);
        assert!((w.global_ball.pose.x - 29.6296).abs() < 1e-3, "{:?}", w.global_ball);
        assert_eq!(w.global_ball.pose.y, 0.0);
    }

    #[test]
    fn a_sharp_own_sighting_outweighs_a_vague_contradiction() {
        // Own: σ 50 mm, quality 0.95 (weight 3.8e-4). A far mate says (4000, 0) with σ 1000 + 50 and quality
        // 0.5 × 0.9 (weight 4.1e-7): they do not agree (4000 > 3 × √(50² + 1050²) = 3154);
        // own wins alone.
        let mut w = seeing(0.0, 0.0, 0.95);
        merge_team(&mut w, Some(50.0), &[report(4, (4000.0, 0.0), 0.5, 1000.0)]);
        assert_eq!((w.global_ball.pose.x, w.global_ball.quality), (0.0, 0.95));
    }

    #[test]
    fn without_sigmas_the_quality_sets_the_weights() {
        // Old reports give no σ: 100 / quality. Own quality 0.5: σ 200, weight 0.5 / 4e4 =
        // 1.25e-5; mate quality 1 → σ 100 + 50, quality 0.9, weight 4e-5.
        // x = (1.25e-5 × 0 + 4e-5 × 300) / 5.25e-5 = 228.57; the best quality, 0.9.
        let mut w = seeing(0.0, 0.0, 0.5);
        merge_team(&mut w, None, &[report(5, (300.0, 0.0), 1.0, 0.0)]);
        assert!((w.global_ball.pose.x - 228.5714).abs() < 1e-3, "{:?}", w.global_ball);
        assert!((w.global_ball.quality - 0.9).abs() < 1e-12);
        // The report carries the robot's own sighting, not the merged one, and its σ.
        let r = MateReport::of(7, false, &w).with_ball_sigma(80.0);
        assert_eq!((r.id, r.ball.quality, r.ball_sigma), (7, w.global_ball.quality, 80.0));
    }

    #[test]
    fn non_finite_reports_are_ignored() {
        let mut w = seeing(10.0, 0.0, 0.95);
        let bad = [report(1, (f64::NAN, 0.0), 1.0, 100.0), report(2, (0.0, 0.0), f64::NAN, 1.0)];
        merge_team(&mut w, Some(100.0), &bad);
        assert_eq!((w.global_ball.pose.x, w.global_ball.quality), (10.0, 0.95));
    }
}
