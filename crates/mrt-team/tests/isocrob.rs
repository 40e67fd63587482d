//! `should_I_go()` (ISocRob-2000 report §3.2.2): on any values the teammates post, at most one
//! robot of the team goes for the ball, and exactly one when any of them sees it.

use mrt_team::isocrob::{heuristic, should_i_go};
use proptest::prelude::*;

proptest! {
    #[test]
    fn one_robot_at_most_goes_for_the_ball(
        seen in proptest::collection::vec(
            (proptest::option::of(0.0..20.0f64), any::<bool>()), 1..7),
        k1 in -2.0..0.0f64,
    ) {
        let posted: Vec<(u32, f64)> = seen
            .iter()
            .enumerate()
            .map(|(i, &(d, facing))| (i as u32 + 1, heuristic(d, facing, k1)))
            .collect();
        let going = posted.iter().filter(|&&(id, h)| should_i_go(id, h, &posted)).count();
        let anyone_sees = seen.iter().any(|(d, _)| d.is_some());
        prop_assert_eq!(going, usize::from(anyone_sees), "{:?}", posted);
    }
}
