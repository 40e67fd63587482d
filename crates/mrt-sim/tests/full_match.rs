//! A full match (2 × 5 min, four robots a side, Milan on Mr. BRIAN at home against Chaos on
//! Lua, each robot an Agora on the bus) finishes, both teams shoot on target, and the same seed
//! reproduces it exactly: the same score and the same trajectory hash. Before every kickoff
//! the robots walk to the formation in READY themselves. These matches see through the object
//! sensor (`mrt sim --percepts oracle`, seven times faster); `mrt sim` plays through rendered
//! images and vision by default (`tests/matches.rs` plays that, and `docs/performance.md`
//! holds its 20-match series).

#![allow(clippy::unwrap_used)]

use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::game::MatchReport;
use mrt_sim::play;
use mrt_sim::referee::Call;

fn default_match(seed: u64) -> MatchReport {
    let cfg = SimConfig::oracle();
    play(&cfg, seed, (Stack::Milan, Stack::Chaos), None, false, |_| {}).unwrap()
}

#[test]
fn a_full_match_finishes_and_reproduces_its_trajectory_hash() {
    let (a, b) = (default_match(1), default_match(1));
    assert!((a.duration - 600.0).abs() < 0.011, "two halves of 300 s: {}", a.duration);
    assert_eq!(a.calls.last().map(|(_, c)| c), Some(&Call::FullTime));
    assert!(a.calls.iter().any(|(_, c)| *c == Call::HalfTime));
    assert_eq!((a.score, a.trajectory_hash), (b.score, b.trajectory_hash));
    assert_eq!(a.stats, b.stats);
    // Both teams play: each moves to the ball and kicks it on target (below). Whether one
    // match has goals is its seed's chance; each team scoring is tests/matches.rs's, and a
    // series' goals are in docs/teams.md.
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
    // Some shots head into the goal mouth, not all.
    for s in &a.stats {
        assert!(s.shots_on_target > 0 && s.shots_on_target < s.shots, "{s:?}");
    }
    // Chaos' attackers book the ball (ThinkingCap/TeamChaos report §3.3) through the team's reports on
    // the bus: often, and never two at once. Milan does not book.
    assert!(a.stats[1].booked_cycles > 1000, "{:?}", a.stats[1]);
    assert_eq!(a.stats[1].booking_conflicts, 0);
    assert_eq!(a.stats[0].booked_cycles, 0);
    // Every robot's world model allocates the roles (getRole) from its teammates' reports:
    // one attacker a cycle, but for the cycles in which two allocated from reports a cycle
    // apart (about 20 of 6000 each).
    for s in &a.stats {
        assert!(s.attacker_cycles > 3000, "{s:?}");
        assert!(s.attacker_conflicts * 100 < s.attacker_cycles, "{s:?}");
    }
    // Milan's robots run SCARE (MRT manual ch. 11) and allocate its activities from each
    // other's reports: one robot on the ball a cycle (BringBall or a passer), but for the
    // cycles in which two allocated from reports a cycle apart (seed 1: 22 of 5850; the
    // booking is the strict mutual exclusion). Chaos coordinates by booking and roles,
    // without SCARE.
    assert!(a.stats[0].ball_job_cycles > 3000, "{:?}", a.stats[0]);
    assert!(a.stats[0].ball_job_conflicts * 100 < a.stats[0].ball_job_cycles, "{:?}", a.stats[0]);
    assert_eq!(a.stats[1].ball_job_cycles, 0);
    assert!(a.faults.is_empty(), "{:?}", a.faults);
}

/// Team ISocRob (ISocRob-2000 report §3.2.2) plays a whole match against the baseline: its robots talk
/// only through their blackboards (the heuristics of `should_I_go` carried by the Proxy), no
/// Member of theirs fails, they shoot on target and score (seed 5, oracle: 4 : 0; the series
/// are in docs/teams.md), and the same seed gives the same match.
#[test]
fn team_isocrob_plays_a_match_on_its_blackboards() {
    let cfg = SimConfig::oracle();
    let game = || play(&cfg, 5, (Stack::Isocrob, Stack::Chaser), None, false, |_| {}).unwrap();
    let (a, b) = (game(), game());
    assert_eq!((a.score, a.trajectory_hash), (b.score, b.trajectory_hash));
    assert!(a.faults.iter().all(|f| f.robot >= 4), "{:?}", a.faults);
    let s = &a.stats[0];
    assert!(s.shots_on_target > 0 && s.possession_cycles > 0, "{s:?}");
    assert!(a.score.0 > 0, "{:?}", a.score);
}
