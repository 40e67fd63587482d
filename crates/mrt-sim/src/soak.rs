//! Soak campaigns: many matches on random valid configurations, and one robot for
//! a long simulated time with its memory watched. `mrt soak` runs them; the results and their
//! commands are in `docs/reliability.md`.
//!
//! A crash is a panic anywhere in a match (caught per match, so the campaign goes on and
//! names every crashing seed) or an error from the simulator; robots whose software fails
//! are faults the match reports, not crashes.

use crate::config::SimConfig;
use crate::error::SimError;
use mrt_robot::spec::Stack;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::panic::AssertUnwindSafe;

/// One match of a campaign: everything needed to play it again.
#[derive(Clone, Debug)]
pub struct SoakMatch {
    /// The match's seed (also the configuration's).
    pub seed: u64,
    /// The configuration drawn for it.
    pub cfg: SimConfig,
    /// Home and away stacks.
    pub stacks: (Stack, Stack),
}

impl SoakMatch {
    /// The match of a campaign numbered `seed`: a random valid configuration with halves of
    /// `half` simulated seconds at most, random stacks.
    pub fn draw(seed: u64, half: f64) -> SoakMatch {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let cfg = random_config(&mut rng, half);
        let stacks = [Stack::Chaos, Stack::Milan, Stack::Chaser];
        let home = stacks[rng.random_range(0..3)];
        let away = stacks[rng.random_range(0..3)];
        SoakMatch { seed, cfg, stacks: (home, away) }
    }

    /// Plays it; `Err` for a crash (a panic, with its message, or the simulator's error).
    pub fn play(&self) -> Result<crate::game::MatchReport, SimError> {
        let (home, away) = self.stacks;
        let run = || {
            crate::bus::BusMatch::new(&self.cfg, self.seed, home, Some(away), None)?.play(|_| {})
        };
        match std::panic::catch_unwind(AssertUnwindSafe(run)) {
            Ok(r) => r,
            Err(payload) => {
                Err(SimError::Match(format!("panic: {}", panic_message(payload.as_ref()))))
            }
        }
    }
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(not a string)".into())
}

/// A configuration drawn from plausible ranges (sizes of several leagues, light and heavy
/// robots, both bases, small and large teams), drawn again until it validates.
pub fn random_config(rng: &mut impl Rng, half: f64) -> SimConfig {
    for _ in 0..1000 {
        let mut c = SimConfig::default();
        let f = &mut c.field;
        f.length = rng.random_range(4.0..22.0);
        f.width = rng.random_range(3.0..14.0);
        f.border = rng.random_range(0.1..1.5);
        f.goal_width = rng.random_range(0.25..0.45) * f.width;
        f.goal_depth = rng.random_range(0.2..0.8);
        f.centre_circle_radius = rng.random_range(0.05..0.3) * f.width;
        f.penalty_area_depth = rng.random_range(0.05..0.3) * f.length / 2.0;
        f.penalty_area_width = (rng.random_range(1.05..2.0) * f.goal_width).min(f.width);
        let b = &mut c.ball;
        b.radius = rng.random_range(0.03..0.15);
        b.mass = rng.random_range(0.05..0.6);
        b.restitution = rng.random_range(0.2..0.9);
        let r = &mut c.body;
        r.base = if rng.random_bool(0.5) { "omni" } else { "differential" }.into();
        r.radius = rng.random_range(0.1..0.4);
        r.mass = rng.random_range(2.0..60.0);
        r.max_speed = rng.random_range(0.2..3.0);
        r.max_accel = rng.random_range(0.5..6.0);
        r.max_turn_rate = rng.random_range(0.5..8.0);
        r.kick_speed = rng.random_range(0.5..10.0);
        r.kick_reach = rng.random_range(0.02..0.3);
        r.kick_half_angle = rng.random_range(0.1..1.2);
        r.kick_recharge = rng.random_range(0.1..3.0);
        let m = &mut c.rules;
        m.team_size = rng.random_range(1..=6);
        m.half_duration = rng.random_range(1.0..=half.max(1.0));
        m.ready_duration = rng.random_range(0.0..5.0);
        m.set_duration = rng.random_range(0.0..1.5);
        // Both ways of seeing: rendered images and vision (the default), the object sensor.
        c.sensor.percepts = if rng.random_bool(0.5) {
            crate::config::PerceptSource::Vision
        } else {
            crate::config::PerceptSource::Oracle
        };
        if c.validate().is_ok() {
            return c;
        }
    }
    // (Not reached with these ranges; the default is valid.)
    SimConfig::default()
}

/// Memory of this process in use (resident set), in bytes, where the system tells
/// (Linux's `/proc/self/statm`); `None` elsewhere.
pub fn resident_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: u64 = text.split_whitespace().nth(1)?.parse().ok()?;
    Some(pages * 4096)
}

/// The least-squares slope of `(x, y)` points (`y` per unit of `x`); 0 for fewer than two.
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if points.len() < 2 {
        return 0.0;
    }
    let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (num, den) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + (x - mx) * (y - my), b + (x - mx) * (x - mx)));
    if den == 0.0 {
        0.0
    } else {
        num / den
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drawn_configurations_are_valid_and_reproducible() {
        for seed in 0..200 {
            let m = SoakMatch::draw(seed, 10.0);
            assert!(m.cfg.validate().is_ok(), "seed {seed}: {:?}", m.cfg.validate());
            assert!(m.cfg.rules.half_duration <= 10.0);
            let again = SoakMatch::draw(seed, 10.0);
            assert_eq!(m.cfg, again.cfg);
            assert_eq!(m.stacks, again.stacks);
        }
        // Not all alike: the campaign covers different fields, teams and bases.
        let sizes: std::collections::BTreeSet<usize> =
            (0..50).map(|s| SoakMatch::draw(s, 10.0).cfg.rules.team_size).collect();
        assert!(sizes.len() >= 4, "{sizes:?}");
    }

    #[test]
    fn a_few_soak_matches_play_without_a_crash() {
        for seed in 0..4 {
            let m = SoakMatch::draw(seed, 2.0);
            let r = m.play();
            assert!(r.is_ok(), "seed {seed}: {r:?}");
        }
    }

    #[test]
    fn slope_of_a_line_and_of_a_flat_series() {
        assert!((slope(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]) - 2.0).abs() < 1e-12);
        assert_eq!(slope(&[(0.0, 7.0), (1.0, 7.0), (5.0, 7.0)]), 0.0);
        assert_eq!(slope(&[(1.0, 2.0)]), 0.0);
    }

    #[test]
    fn this_process_has_a_resident_size_on_linux() {
        if cfg!(target_os = "linux") {
            assert!(resident_bytes().is_some_and(|b| b > 1 << 20));
        }
    }
}
