//! The kidnapped robot: robots carried elsewhere without being told find themselves
//! again from what they see; the carry is booked, never told to the robot.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use mrt_robot::config::Localizer;
use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::game::Pitch;
use mrt_sim::metrics::MetricsBook;

fn config(kidnaps: u32, localizer: Localizer) -> SimConfig {
    let mut cfg = SimConfig::oracle();
    cfg.rules.half_duration = 40.0;
    cfg.rules.kidnaps = kidnaps;
    cfg.localization.localizer = localizer;
    cfg
}

/// Every robot is carried twice a match (once a half); with MUREA each is found again within
/// a few seconds, and the pooled metrics say so.
#[test]
fn kidnapped_robots_find_themselves_again() {
    kidnapped_robots_find_themselves_again_with(Localizer::Murea);
}

/// The same with ThinkingCap's fuzzy grid (GM) watching the EKF instead of MUREA.
#[test]
fn kidnapped_robots_find_themselves_again_with_the_fuzzy_grid() {
    kidnapped_robots_find_themselves_again_with(Localizer::Gm);
}

fn kidnapped_robots_find_themselves_again_with(localizer: Localizer) {
    let cfg = config(1, localizer);
    // A robot carried less than the 10 s a recovery may take before the final whistle may
    // not be found before it: such a carry is not judged.
    let r = mrt_sim::play(&cfg, 2, (Stack::Milan, Stack::Chaos), None, false, |_| {}).unwrap();
    let robots = 2 * cfg.rules.team_size;
    assert!(r.kidnaps.len() >= robots * 2 - 1, "{} kidnaps", r.kidnaps.len());
    let judged = |k: &&mrt_sim::game::Kidnap| k.at + 10.0 <= r.duration;
    let late = r.kidnaps.iter().filter(|k| !judged(k)).count();
    assert!(
        r.kidnaps.len() - late >= robots,
        "{late} of {} carries in the last 10 s",
        r.kidnaps.len()
    );
    for k in r.kidnaps.iter().filter(judged) {
        let after = k.recovered_after.unwrap_or_else(|| panic!("never found again: {k:?}"));
        // A robot carried to where it sees few landmarks takes several seconds (`mrt sim
        // --percepts oracle --kidnap 1 --half 40 --metrics`); the median stays under 2 s.
        assert!(after < 10.0, "{k:?}");
    }
    let mut book = MetricsBook::default();
    book.add(&r);
    let m = book.metrics();
    assert_eq!(m.kidnap.count as usize, r.kidnaps.len());
    assert!(m.kidnap.recovered as usize + late >= r.kidnaps.len(), "{m:?}");
    assert!(m.kidnap.median_recovery_s.is_some_and(|t| t < 2.0), "{m:?}");
    // The global localizer found some of them (the EKF, matching named landmarks, the others),
    // never wrongly.
    let l = &m.localization;
    assert!(l.relocalized > 0 && l.falsely_relocalized == 0, "{l:?}");
}

/// The carry moves the robot and nothing else: its odometry reports no placement and no motion
/// for it; without kidnaps the plan is empty and the match is the same as before.
#[test]
fn a_carry_is_not_told_to_the_robot() {
    let cfg = config(0, Localizer::Murea);
    let mut pitch = Pitch::new(&cfg, 1, 4, 4).unwrap();
    pitch.odometry(2);
    let there = mrt_core::Pose2::new(3.0, 2.0, 1.0);
    pitch.world_mut().carry_robot(2, there);
    let o = pitch.odometry(2);
    assert_eq!(o.placed, None, "a carry is not a placement");
    let moved = o.mice.x_left.hypot(o.mice.y_left) + o.mice.x_right.hypot(o.mice.y_right);
    assert!(moved < 1e-9, "the mice felt the carry: {o:?}");
    assert_eq!(pitch.world().robot(2).map(|p| (p.x, p.y)), Some((3.0, 2.0)));
    assert_eq!(pitch.world().carried(2), 1);
}

/// Kidnaps that fall close together (here 6 a half in 30 s of play, and those due while play
/// is stopped fire together when it resumes) are spread out: one robot is never carried again
/// within [`mrt_sim::game::KIDNAP_GAP`] of its last carry, so each carry gives it time to find
/// itself.
#[test]
fn a_robot_is_not_carried_again_before_the_gap() {
    let mut cfg = config(6, Localizer::Murea);
    cfg.rules.half_duration = 30.0;
    let r = mrt_sim::play(&cfg, 2, (Stack::Milan, Stack::Chaos), None, false, |_| {}).unwrap();
    let robots = 2 * cfg.rules.team_size;
    // Without the gap each robot would be carried 12 times; with it, at most one carry in each
    // 10 s of the 60 s match.
    assert!(r.kidnaps.len() >= robots, "{} kidnaps", r.kidnaps.len());
    assert!(r.kidnaps.len() <= robots * 6, "{} kidnaps", r.kidnaps.len());
    for robot in 0..robots {
        let times: Vec<f64> = r.kidnaps.iter().filter(|k| k.robot == robot).map(|k| k.at).collect();
        assert!(
            times.windows(2).all(|w| w[1] - w[0] >= mrt_sim::game::KIDNAP_GAP - 1e-9),
            "{times:?}"
        );
    }
}
