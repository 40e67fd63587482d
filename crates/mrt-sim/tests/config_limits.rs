//! A simulator configuration that passes validation must not panic later.
//!
//! `[body] radius = 0.6` passed `SimConfig::validate`, then the referee panicked at kickoff:
//! robots enter on their side line `2 × radius + 0.05` m apart but at most 1.2 m apart, and
//! `f64::clamp` panics when its minimum (1.25) exceeds its maximum. The same kind of derived
//! quantity hid behind other clamps: the kickoff line (`field.length / 2 − radius − 0.1`), the
//! goalkeepers' range between the posts (`goal_width / 2 − 0.1`, in both the Chaser and the
//! Milan stack). `validate` now checks each, with an error naming the field; one test per case
//! below, and a proptest: random configurations either fail validation with an error or play
//! a short match to the end.

#![allow(clippy::unwrap_used)]

use mrt_robot::spec::Stack;
use mrt_sim::config::SimConfig;
use mrt_sim::play;
use proptest::prelude::*;

fn refused(toml: &str, needle: &str) {
    let e = SimConfig::from_toml(toml, "case.toml").unwrap_err().to_string();
    assert!(e.starts_with("case.toml: ") && e.contains(needle), "{toml}: {e}");
}

/// Plays a short match (halves of `half` s) between the Milan stack and the Chaser.
fn plays(cfg: &mut SimConfig, half: f64) {
    cfg.rules.half_duration = half;
    let r = play(cfg, 7, (Stack::Milan, Stack::Chaser), None, false, |_| {});
    let r = r.unwrap();
    assert!((r.duration - 2.0 * half).abs() < 0.2, "{}", r.duration);
}

#[test]
fn a_robot_radius_of_0_6_is_refused_not_a_panic() {
    refused("[body]\nradius = 0.6\n", "body.radius must be at most 0.575 m");
    // The largest radius allowed plays.
    let mut cfg = SimConfig::from_toml("[body]\nradius = 0.575\n", "ok.toml").unwrap();
    plays(&mut cfg, 1.0);
}

#[test]
fn a_field_too_short_for_the_kickoff_is_refused() {
    refused(
        "[field]\nlength = 2.0\npenalty_area_depth = 0.5\ncentre_circle_radius = 0.5\n\
         [body]\nradius = 0.3\n",
        "field.length must be at least 2.220 m for robots of body.radius 0.3 m",
    );
    let mut cfg = SimConfig::from_toml(
        "[field]\nlength = 2.0\npenalty_area_depth = 0.5\ncentre_circle_radius = 0.5\n",
        "ok.toml",
    )
    .unwrap();
    plays(&mut cfg, 1.0);
}

#[test]
fn a_team_too_large_for_the_field_width_is_refused() {
    refused(
        "[rules]\nteam_size = 11\n[field]\nwidth = 4.0\npenalty_area_width = 3.0\n\
         centre_circle_radius = 1.0\n[body]\nradius = 0.2\n",
        "rules.team_size 11 does not fit across field.width 4 m",
    );
}

#[test]
fn goals_too_narrow_for_the_goalkeepers_or_the_ball_are_refused() {
    // 0.15 m: the goalkeepers' range between the posts, ±(0.075 − 0.1) m, panicked in clamp.
    refused("[field]\ngoal_width = 0.15\n", "field.goal_width must be at least 0.2 m");
    refused("[field]\ngoal_width = 0.5\n[ball]\nradius = 0.3\n", "wider than the ball");
    let mut cfg = SimConfig::from_toml("[field]\ngoal_width = 0.25\n", "ok.toml").unwrap();
    plays(&mut cfg, 1.0);
}

#[test]
fn a_penalty_area_narrower_than_its_goal_is_refused() {
    refused(
        "[field]\npenalty_area_width = 1.0\n",
        "field.penalty_area_width (1) must be at least field.goal_width (2)",
    );
}

#[test]
fn a_centre_circle_larger_than_the_field_is_refused() {
    refused(
        "[field]\ncentre_circle_radius = 6.0\n",
        "field.centre_circle_radius must be less than",
    );
}

#[test]
fn bodies_the_physics_cannot_hold_and_endless_halves_are_refused() {
    refused("[body]\nradius = 0.001\n", "body.radius and ball.radius must be 0.01 to 1 m");
    refused("[ball]\nradius = 1e-30\n", "body.radius and ball.radius must be 0.01 to 1 m");
    refused("[body]\nmass = 1e30\n", "body.mass and ball.mass must be at most");
    refused("[rules]\nhalf_duration = 1e12\n", "rules.half_duration must be at most 86400 s");
}

/// A value from `lo` to `hi`, now and then an edge.
fn around(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    prop_oneof![8 => lo..hi, 1 => Just(lo), 1 => Just(hi)]
}

prop_compose! {
    /// Mostly plausible values, some at or past their limits; sizes that depend on others
    /// (goal, penalty area, centre circle) drawn as fractions of them, so that about half the
    /// configurations are valid.
    fn any_config()(
        (length, width, border, goal, goal_depth) in
            (around(1.8, 25.0), around(1.8, 16.0), around(0.0, 2.0), around(0.0, 0.6), around(0.01, 1.5)),
        (centre, pa_depth, pa_width) in (around(0.0, 1.05), around(0.0, 1.0), around(0.9, 3.0)),
        (ball_radius, ball_mass, restitution) in (around(0.008, 0.3), around(0.01, 5.0), around(0.0, 1.0)),
        (radius, mass, speed, accel, turn) in
            (around(0.008, 0.6), around(0.5, 80.0), around(0.05, 4.0), around(0.05, 8.0), around(0.1, 10.0)),
        (kick_speed, reach, cone, recharge) in (around(0.0, 15.0), around(0.0, 0.5), around(0.0, 3.1), around(0.0, 3.0)),
        (team, step, period, ready, set) in
            (1usize..=11, around(0.004, 0.05), around(0.02, 0.3), around(0.0, 3.0), around(0.0, 1.0)),
        (stuck_time, stuck_distance, half) in (around(0.1, 3.0), around(0.001, 1.0), around(0.5, 1.5)),
    ) -> SimConfig {
        let mut c = SimConfig::default();
        (c.field.length, c.field.width, c.field.border, c.field.goal_depth) =
            (length, width, border, goal_depth);
        c.field.goal_width = goal * width;
        c.field.centre_circle_radius = centre * (length / 2.0).min(width / 2.0);
        c.field.penalty_area_depth = pa_depth * length / 2.0;
        c.field.penalty_area_width = (pa_width * c.field.goal_width).min(width);
        (c.ball.radius, c.ball.mass, c.ball.restitution) = (ball_radius, ball_mass, restitution);
        (c.body.radius, c.body.mass, c.body.max_speed, c.body.max_accel, c.body.max_turn_rate) =
            (radius, mass, speed, accel, turn);
        (c.body.kick_speed, c.body.kick_reach, c.body.kick_half_angle, c.body.kick_recharge) =
            (kick_speed, reach, cone, recharge);
        (c.rules.team_size, c.rules.physics_step, c.rules.control_period, c.rules.ready_duration, c.rules.set_duration) =
            (team, step, period, ready, set);
        (c.rules.stuck_time, c.rules.stuck_distance, c.rules.half_duration) = (stuck_time, stuck_distance, half);
        c
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Either an error from validation, or a match (two halves of at most 1.5 s) played to
    /// the end, with the Mr. BRIAN stack against the Chaser, without a panic.
    #[test]
    fn random_configurations_are_refused_or_play(cfg in any_config()) {
        if cfg.validate().is_ok() {
            let r = play(&cfg, 3, (Stack::Milan, Stack::Chaser), None, false, |_| {});
            prop_assert!(r.is_ok(), "{r:?}");
        }
    }
}
