//! SCARE's promises, as properties on random teams:
//!
//! - every robot that heard the same reports computes the same allocation, whatever order it
//!   heard them in;
//! - cardinality holds: one goalkeeper at most, and only the goalkeeper keeps goal; at most
//!   one robot plays the ball (BringBall or PassageToMate's passer); a schema is given whole
//!   or not at all;
//! - every robot gets an activity (Support is the default);
//! - reports with odd numbers (another table, wrong lengths, not a number) never make a
//!   coordinator panic.

#![allow(clippy::unwrap_used)]

use mrt_msgs::ScareReport;
use mrt_team::scare::soccer::{ids, table, Coordinator, Situation};
use mrt_team::scare::{allocate, Agent, Params};
use proptest::prelude::*;

fn field_xy() -> impl Strategy<Value = (f64, f64)> {
    (-9.0..9.0f64, -6.0..6.0f64)
}

/// Robot positions, the ball (or none), opponents.
type Team = (Vec<(f64, f64)>, Option<(f64, f64)>, Vec<(f64, f64)>);

/// A team of 2 to 5 robots (robot 1 keeps goal), the ball (or none) and some opponents.
fn team() -> impl Strategy<Value = Team> {
    (
        prop::collection::vec(field_xy(), 2..6),
        prop::option::weighted(0.85, field_xy()),
        prop::collection::vec(field_xy(), 0..5),
    )
}

fn situation(
    i: usize,
    pos: &[(f64, f64)],
    ball: Option<(f64, f64)>,
    opponents: &[(f64, f64)],
) -> Situation {
    Situation {
        me: (pos[i].0, pos[i].1, 0.0),
        keeper: i == 0,
        ball,
        mates: (0..pos.len()).filter(|j| *j != i).map(|j| (j as u32 + 1, pos[j], j == 0)).collect(),
        opponents: opponents.to_vec(),
        half_length: 9.0,
        goal_half_width: 1.0,
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn every_robot_allocates_the_same_and_cardinality_holds((pos, ball, opponents) in team(), rotate in 0usize..6) {
        let t = table();
        let agents: Vec<Agent> = (0..pos.len())
            .map(|i| Agent::new(i as u32 + 1, situation(i, &pos, ball, &opponents).attitudes()))
            .collect();
        // The team's opportunities: the lowest-numbered robot's.
        let opportunity = situation(0, &pos, ball, &opponents).opportunity(1);
        let a = allocate(&t, &opportunity, &agents, &Params::default());
        let mut heard = agents.clone();
        heard.rotate_left(rotate % agents.len());
        heard.reverse();
        prop_assert_eq!(&a, &allocate(&t, &opportunity, &heard, &Params::default()));

        prop_assert_eq!(a.assignments.len(), pos.len());
        prop_assert!(a.assignments.iter().all(|(_, x)| x.is_some()), "{:?}", a);
        prop_assert!(a.doing(ids::GOALIE).iter().all(|id| *id == 1));
        let on_ball = a.doing(ids::BRING_BALL).len()
            + a.assignments.iter().filter(|(_, x)| x.is_some_and(|x| x.activity == ids::PASSAGE && x.functionality == 0)).count();
        prop_assert!(on_ball <= 1, "{:?}", a.names(&t));
        for schema in [ids::PASSAGE, ids::DOUBLING] {
            let n = a.doing(schema).len();
            prop_assert!(n == 0 || n == t.list()[schema].functionalities.len(), "{:?}", a.names(&t));
        }
        // A known ball is always brought by someone when a field player exists.
        if ball.is_some() && pos.len() > 1 {
            prop_assert_eq!(on_ball, 1, "{:?}", a.names(&t));
        }
    }

    #[test]
    fn odd_reports_are_ignored_never_a_panic(
        attitudes in prop::collection::vec(prop_oneof![Just(f32::NAN), Just(f32::INFINITY), -2.0..2.0f32], 0..12),
        opportunity in prop::collection::vec(prop_oneof![Just(f32::NAN), -2.0..2.0f32], 0..9),
        doing in prop::option::of((any::<u16>(), any::<u8>())),
        same_table in any::<bool>(),
        id in 0u32..8,
    ) {
        let mut me = Coordinator::new(2);
        let fingerprint = table().fingerprint();
        let report = ScareReport {
            table: if same_table { fingerprint } else { fingerprint ^ 1 },
            attitudes,
            opportunity,
            doing,
        };
        let sit = situation(1, &[(-8.0, 0.0), (0.0, 0.0), (1.0, 0.5)], Some((0.5, 0.0)), &[]);
        let c = me.cycle(1.0, &sit, &[(id, &report)], 0.0);
        // This robot always gets its job.
        prop_assert!(!c.job.activity.is_empty());
        prop_assert_eq!(c.report.attitudes.len(), table().slots());
    }
}

/// A robot that loses contact with its team allocates for itself alone: with the ball known it
/// brings it; then it hears a teammate nearer the ball and hands BringBall over.
#[test]
fn alone_a_robot_brings_the_ball_and_hands_it_over_when_it_hears_a_nearer_mate() {
    let pos = [(-8.0, 0.0), (-3.0, 0.0), (0.9, 0.0)];
    let ball = Some((1.0, 0.0));
    let mut two = Coordinator::new(2);
    let alone = two.cycle(0.0, &situation(1, &pos, ball, &[]), &[], 0.0);
    assert_eq!(alone.job.activity, "BringBall");
    let mut three = Coordinator::new(3);
    let r3 = three.cycle(0.0, &situation(2, &pos, ball, &[]), &[], 0.0).report;
    let together = two.cycle(0.1, &situation(1, &pos, ball, &[]), &[(3, &r3)], 0.0);
    assert_eq!(together.allocation.doing(ids::BRING_BALL), vec![3]);
    assert_ne!(together.job.activity, "BringBall");
    assert!(together.job.position.is_some(), "{:?}", together.job);
}

/// The monitor: a BringBall that does not reach the ball within its 12 s fails, and the
/// robot leaves the job to a teammate for the cool-down.
#[test]
fn a_robot_that_cannot_reach_the_ball_in_time_leaves_bringball_to_a_mate() {
    // Robot 2 is nearest, but the ball sits in front of it (it never gets behind it: the
    // robots stand still here).
    let pos = [(-8.0, 0.0), (2.0, 0.0), (-4.0, 2.0)];
    let ball = Some((1.0, 0.0));
    let mut two = Coordinator::new(2);
    let mut three = Coordinator::new(3);
    let mut r3 = three.cycle(0.0, &situation(2, &pos, ball, &[]), &[], 0.0).report;
    let mut first = None;
    for k in 0..200 {
        let now = f64::from(k) * 0.1;
        let c = two.cycle(now, &situation(1, &pos, ball, &[]), &[(3, &r3)], 0.0);
        r3 = three.cycle(now, &situation(2, &pos, ball, &[]), &[(2, &c.report)], 0.0).report;
        if c.job.activity != "BringBall" && first.is_none() && now > 1.0 {
            first = Some(now);
        }
    }
    let handed = first.unwrap();
    assert!((12.0..13.0).contains(&handed), "handed over at {handed} s");
    assert_eq!(two.outcomes().1, 1, "one failure booked");
}

/// The cool-down after a failure hands the activity to a teammate; a robot alone (or whose
/// teammates cannot take it) goes on with it at once instead of walking off to a position.
#[test]
fn a_robot_alone_keeps_bringball_after_a_failure() {
    let pos = [(-8.0, 0.0), (2.0, 0.0)];
    let ball = Some((1.0, 0.0));
    let mut two = Coordinator::new(2);
    for k in 0..300 {
        let now = f64::from(k) * 0.1;
        let c = two.cycle(now, &situation(1, &pos, ball, &[]), &[], 0.0);
        assert_eq!(c.job.activity, "BringBall", "at {now} s");
    }
    // ReachBall timed out twice (at 12 s and 24 s), and both were booked.
    assert_eq!(two.outcomes().1, 2);
}
