//! What must hold in every match, whatever its seed and however well a team plays: checked
//! every control cycle over several seeds and every pairing of the stacks, not read off one
//! match's score.
//!
//! - No two robots are in each other's body, no robot is inside the ball, and the ball and
//!   the robots stay inside the walls.
//! - Every robot's belief of its own pose stays within a bound of the truth.
//! - The team coordinations hold: TeamChaos' ball booking never gives the ball to two robots
//!   (ThinkingCap/TeamChaos report §3.3); roles and SCARE's ball job are one robot's but for
//!   the cycles in which two allocated from reports a cycle apart (MRT manual ch. 11).
//! - No robot's software fails.

#![allow(clippy::unwrap_used)]

use mrt_robot::spec::Stack;
use mrt_sim::bus::BusMatch;
use mrt_sim::config::SimConfig;
use mrt_sim::metrics::MetricsBook;

/// The seeds: a few, so that a property is not one match's accident.
const SEEDS: [u64; 4] = [11, 23, 37, 41];

fn config() -> SimConfig {
    let mut cfg = SimConfig::oracle();
    cfg.rules.half_duration = 20.0;
    cfg
}

/// Plays `home` against `away` on `seed`, checking the bodies every cycle, and returns the
/// report.
fn play_checked(
    cfg: &SimConfig,
    seed: u64,
    home: Stack,
    away: Stack,
) -> mrt_sim::game::MatchReport {
    let mut m = BusMatch::new(cfg, seed, home, Some(away), None).unwrap();
    let r = cfg.body.radius;
    let ball_r = cfg.ball.radius;
    // Contacts resolve within a physics step: two bodies may overlap by what they close in
    // one step, two robots at top speed or a kicked ball.
    let step = cfg.rules.physics_step;
    let slack = 2.0 * cfg.body.max_speed * step;
    let ball_slack = cfg.body.kick_speed * step;
    // The walls stand `border` beyond the lines (the goals inside them): a body's centre
    // stays its radius inside.
    let wall_x = cfg.field.length / 2.0 + cfg.field.border + slack;
    let wall_y = cfg.field.width / 2.0 + cfg.field.border + slack;
    let mut cycles = 0;
    while !m.pitch().unwrap().finished() {
        m.cycle().unwrap();
        cycles += 1;
        let pitch = m.pitch().unwrap();
        let world = pitch.world();
        let t = world.time();
        let robots: Vec<_> = (0..world.robot_count()).map(|i| world.robot(i).unwrap()).collect();
        let ball = world.ball();
        for (i, a) in robots.iter().enumerate() {
            for (j, b) in robots.iter().enumerate().skip(i + 1) {
                let d = (a.x - b.x).hypot(a.y - b.y);
                assert!(
                    d >= 2.0 * r - slack,
                    "seed {seed}, {t:.1} s: robots {i} and {j} {d:.3} m apart"
                );
            }
            let d = (a.x - ball.0).hypot(a.y - ball.1);
            assert!(
                d >= r + ball_r - ball_slack,
                "seed {seed}, {t:.1} s: robot {i} in the ball ({d:.3} m)"
            );
            assert!(
                a.x.abs() <= wall_x - r && a.y.abs() <= wall_y - r,
                "seed {seed}, {t:.1} s: robot {i} out at {a:?}"
            );
        }
        assert!(
            ball.0.abs() <= wall_x - ball_r && ball.1.abs() <= wall_y - ball_r,
            "seed {seed}, {t:.1} s: the ball out at {ball:?}"
        );
    }
    let report = m.play(|_| {}).unwrap();
    assert!(cycles > 350, "seed {seed}: {cycles} cycles");
    report
}

fn holds_for(home: Stack, away: Stack) {
    let cfg = config();
    for seed in SEEDS {
        let rep = play_checked(&cfg, seed, home, away);
        assert!(rep.faults.is_empty(), "seed {seed}: {:?}", rep.faults);
        // Each robot knows where it is: half of its estimates within 25 cm, 95 % within 1 m
        // (the object sensor's noise, the mice's drift, the placements at each kickoff).
        let mut book = MetricsBook::default();
        book.add(&rep);
        let l = book.metrics().localization;
        let (median, p95) = (l.median_m.unwrap_or(f64::NAN), l.p95_m.unwrap_or(f64::NAN));
        assert!(l.samples > 1000, "seed {seed}: few estimates");
        assert!(
            median < 0.25 && p95 < 1.0,
            "seed {seed}: pose error median {median:.2} m, p95 {p95:.2} m"
        );
        for (team, (stack, s)) in [home, away].iter().zip(&rep.stats).enumerate() {
            assert_eq!(
                s.booking_conflicts, 0,
                "seed {seed}, team {team}: two robots booked the ball"
            );
            if *stack == Stack::Chaos {
                assert!(s.booked_cycles > 0, "seed {seed}: Chaos never booked the ball: {s:?}");
            } else {
                assert_eq!(s.booked_cycles, 0, "seed {seed}: only Chaos books: {s:?}");
            }
            assert!(
                s.attacker_conflicts * 50 <= s.attacker_cycles.max(50),
                "seed {seed}, team {team}: {s:?}"
            );
            assert!(
                s.ball_job_conflicts * 50 <= s.ball_job_cycles.max(50),
                "seed {seed}, team {team}: {s:?}"
            );
            if *stack == Stack::Milan {
                assert!(s.ball_job_cycles > 0, "seed {seed}: SCARE gave nobody the ball: {s:?}");
            }
        }
    }
}

#[test]
fn milan_against_chaos_keeps_the_invariants() {
    holds_for(Stack::Milan, Stack::Chaos);
}

#[test]
fn isocrob_against_the_chaser_keeps_the_invariants() {
    holds_for(Stack::Isocrob, Stack::Chaser);
}
