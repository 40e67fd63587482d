//! A full default match (2 × 5 min, four robots a side, Chaos against the baseline) finishes,
//! and the same seed reproduces it exactly: the same score and the same trajectory hash.

#![allow(clippy::unwrap_used)]

use mrt_sim::config::SimConfig;
use mrt_sim::game::{Match, MatchReport};
use mrt_sim::referee::Call;
use mrt_sim::teams::{team, Stack};

fn play(seed: u64) -> MatchReport {
    let cfg = SimConfig::default();
    let home = team(Stack::Chaos, &cfg, None).unwrap();
    let away = team(Stack::Chaser, &cfg, None).unwrap();
    Match::new(&cfg, seed, home, away).unwrap().play(f64::MAX, |_| {})
}

#[test]
fn a_full_match_finishes_and_reproduces_its_trajectory_hash() {
    let (a, b) = (play(11), play(11));
    assert!((a.duration - 600.0).abs() < 0.011, "two halves of 300 s: {}", a.duration);
    assert_eq!(a.calls.last().map(|(_, c)| c), Some(&Call::FullTime));
    assert!(a.calls.iter().any(|(_, c)| *c == Call::HalfTime));
    assert_eq!((a.score, a.trajectory_hash), (b.score, b.trajectory_hash));
    assert_eq!(a.stats, b.stats);
    // Both teams play: each moves to the ball and kicks it.
    assert!(a.stats[0].shots > 0 && a.stats[1].shots > 0, "{:?}", a.stats);
    assert!(a.stats[0].possession_cycles > 0 && a.stats[1].possession_cycles > 0);
}
