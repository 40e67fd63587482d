//! The slow tier: full matches (2 × 5 min, four robots a side, each robot an Agora on the
//! bus), which CI runs once in release: `cargo test --release -p mrt-sim --test full_match --
//! --ignored`. Over several seeds, Milan on Mr. BRIAN against Chaos on Lua finish their
//! matches, both teams shoot on target, every kickoff goes through READY with the robots
//! walking to their places, the coordinations hold, and the same seed reproduces a match
//! exactly (the same score and trajectory hash). These matches see through the object sensor
//! (`mrt sim --percepts oracle`); `tests/invariants.rs` checks what holds every cycle in
//! shorter matches, and `tests/matches.rs` plays through vision.

#![allow(clippy::unwrap_used)]

use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::game::MatchReport;
use mrt_sim::play;
use mrt_sim::referee::Call;

/// The seeds of the slow tier.
const SEEDS: [u64; 2] = [1, 2];

fn full_match(seed: u64, stacks: (Stack, Stack)) -> MatchReport {
    play(&SimConfig::oracle(), seed, stacks, None, false, |_| {}).unwrap()
}

#[test]
#[ignore = "slow tier (full matches): cargo test --release -- --ignored"]
fn full_matches_finish_and_reproduce_their_trajectory_hash() {
    let stacks = (Stack::Milan, Stack::Chaos);
    let again = full_match(SEEDS[0], stacks);
    let (mut on_target, mut shots) = ([0, 0], [0, 0]);
    for seed in SEEDS {
        let a = full_match(seed, stacks);
        if seed == SEEDS[0] {
            assert_eq!((a.score, a.trajectory_hash), (again.score, again.trajectory_hash));
            assert_eq!(a.stats, again.stats);
        }
        one_full_match(&a);
        for (team, s) in a.stats.iter().enumerate() {
            on_target[team] += s.shots_on_target;
            shots[team] += s.shots;
        }
    }
    // Both teams play: each moves to the ball and kicks it, some shots into the goal mouth,
    // not all.
    for team in 0..2 {
        assert!(on_target[team] > 0 && on_target[team] < shots[team], "{on_target:?} of {shots:?}");
    }
}

/// What holds in every full match of Milan against Chaos.
fn one_full_match(a: &MatchReport) {
    assert!((a.duration - 600.0).abs() < 0.011, "two halves of 300 s: {}", a.duration);
    assert_eq!(a.calls.last().map(|(_, c)| c), Some(&Call::FullTime));
    assert!(a.calls.iter().any(|(_, c)| *c == Call::HalfTime));
    // Every kickoff went through READY, and the robots walked to their places: the referee
    // placed at most two of the eight at any kickoff (the start, each goal, half time).
    let placed: Vec<usize> = a
        .calls
        .iter()
        .filter_map(|(_, c)| if let Call::Set { placed } = c { Some(*placed) } else { None })
        .collect();
    let kickoffs = 2 + (a.score.0 + a.score.1) as usize;
    assert_eq!(placed.len(), kickoffs, "{:?}", a.calls);
    assert!(placed.iter().all(|&p| p <= 2), "placed by the referee (of 8): {placed:?}");
    assert!(a.stats[0].possession_cycles > 0 && a.stats[1].possession_cycles > 0);
    // Chaos' attackers book the ball (ThinkingCap/TeamChaos report §3.3) through the team's reports on
    // the bus: often, and never two at once. Milan does not book.
    assert!(a.stats[1].booked_cycles > 1000, "{:?}", a.stats[1]);
    assert_eq!(a.stats[1].booking_conflicts, 0);
    assert_eq!(a.stats[0].booked_cycles, 0);
    // Every robot's world model allocates the roles (getRole) from its teammates' reports:
    // one attacker a cycle, but for the cycles in which two allocated from reports a cycle
    // apart (a few in a thousand).
    for s in &a.stats {
        assert!(s.attacker_cycles > 3000, "{s:?}");
        assert!(s.attacker_conflicts * 100 < s.attacker_cycles, "{s:?}");
    }
    // Milan's robots run SCARE (MRT manual ch. 11) and allocate its activities from each
    // other's reports: one robot on the ball a cycle (BringBall or a passer), but for the
    // cycles in which two allocated from reports a cycle apart (a few in a thousand; the
    // booking is the strict mutual exclusion). Chaos coordinates by booking and roles,
    // without SCARE.
    assert!(a.stats[0].ball_job_cycles > 3000, "{:?}", a.stats[0]);
    assert!(a.stats[0].ball_job_conflicts * 100 < a.stats[0].ball_job_cycles, "{:?}", a.stats[0]);
    assert_eq!(a.stats[1].ball_job_cycles, 0);
    assert!(a.faults.is_empty(), "{:?}", a.faults);
}

/// Team ISocRob (ISocRob-2000 report §3.2.2) plays whole matches against the baseline: its
/// robots talk only through their blackboards (the heuristics of `should_I_go` carried by the
/// Proxy), no Member of theirs fails, they shoot on target and score over the seeds (the
/// series are in docs/teams.md), and the same seed gives the same match.
#[test]
#[ignore = "slow tier (full matches): cargo test --release -- --ignored"]
fn team_isocrob_plays_matches_on_its_blackboards() {
    let stacks = (Stack::Isocrob, Stack::Chaser);
    let again = full_match(SEEDS[0], stacks);
    let mut goals = 0;
    for seed in SEEDS {
        let a = full_match(seed, stacks);
        if seed == SEEDS[0] {
            assert_eq!((a.score, a.trajectory_hash), (again.score, again.trajectory_hash));
        }
        assert!(a.faults.iter().all(|f| f.robot >= 4), "{:?}", a.faults);
        let s = &a.stats[0];
        assert!(s.shots_on_target > 0 && s.possession_cycles > 0, "seed {seed}: {s:?}");
        goals += a.score.0;
    }
    assert!(goals > 0, "ISocRob scored no goal in {} matches", SEEDS.len());
}
