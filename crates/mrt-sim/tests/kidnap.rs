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

/// Every robot is carried twice a match (once a half); with MUREA each is found again, most
/// within a few seconds, over several seeds, and the pooled metrics say so.
#[test]
fn kidnapped_robots_find_themselves_again() {
    kidnapped_robots_find_themselves_again_with(Localizer::Murea);
}

/// The same with ThinkingCap's fuzzy grid (GM) watching the EKF instead of MUREA.
#[test]
fn kidnapped_robots_find_themselves_again_with_the_fuzzy_grid() {
    kidnapped_robots_find_themselves_again_with(Localizer::Gm);
}

/// The seeds of the kidnap matches.
const SEEDS: [u64; 2] = [2, 3];

/// A carry must be recovered from within this long (s); one carried less than this before
/// the final whistle is not judged.
const RECOVERY: f64 = 20.0;

fn kidnapped_robots_find_themselves_again_with(localizer: Localizer) {
    let cfg = config(1, localizer);
    let robots = 2 * cfg.rules.team_size;
    let mut book = MetricsBook::default();
    let (mut carries, mut late, mut quick) = (0, 0, 0);
    for seed in SEEDS {
        let r =
            mrt_sim::play(&cfg, seed, (Stack::Milan, Stack::Chaos), None, false, |_| {}).unwrap();
        assert!(r.kidnaps.len() >= robots * 2 - 1, "seed {seed}: {} kidnaps", r.kidnaps.len());
        for k in &r.kidnaps {
            if k.at + RECOVERY > r.duration {
                late += 1;
                continue;
            }
            // A robot carried to where it sees few landmarks takes several seconds (`mrt sim
            // --percepts oracle --kidnap 1 --half 40 --metrics`), never the whole bound.
            let after = k
                .recovered_after
                .unwrap_or_else(|| panic!("seed {seed}: never found again: {k:?}"));
            assert!(after < RECOVERY, "seed {seed}: {k:?}");
            quick += usize::from(after < 10.0);
        }
        carries += r.kidnaps.len();
        book.add(&r);
    }
    // Most are found within 10 s, and the median within 2 s.
    let judged = carries - late;
    assert!(judged >= robots * SEEDS.len(), "{late} of {carries} carries in the last {RECOVERY} s");
    assert!(quick * 10 >= judged * 9, "{quick} of {judged} carries found within 10 s");
    let m = book.metrics();
    assert_eq!(m.kidnap.count as usize, carries);
    assert!(m.kidnap.recovered as usize + late >= carries, "{m:?}");
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
