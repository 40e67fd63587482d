//! The ball booking (ThinkingCap/TeamChaos report §3.3) over a simulated network that loses, delays
//! and reorders reports, with robots that fall silent: two robots that hear each other never
//! hold the booking at once, a released or silent holder's booking passes on, and a claim
//! that is not affirmed lapses.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use mrt_msgs::BookingReport;
use mrt_team::booking::{BallBooking, BookingParams};
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const DT: f64 = 0.1;

/// A team of `n` robots (numbers 1..=n) on a network that loses each report with probability
/// `loss` and delays it uniformly up to `delay` s (so reports overtake each other).
struct Team {
    robots: Vec<BallBooking>,
    /// Reports on their way: (arrival time, to, from, report).
    wire: Vec<(f64, usize, usize, BookingReport)>,
    rng: ChaCha8Rng,
    loss: f64,
    delay: f64,
    /// Robots cut off (sending and receiving nothing) until this time.
    cut_until: Vec<f64>,
}

impl Team {
    fn new(n: usize, loss: f64, delay: f64, seed: u64) -> Team {
        Team {
            robots: (1..=n as u32)
                .map(|id| BallBooking::new(id, BookingParams::default()))
                .collect(),
            wire: Vec::new(),
            rng: ChaCha8Rng::seed_from_u64(seed),
            loss,
            delay,
            cut_until: vec![f64::NEG_INFINITY; n],
        }
    }

    /// One cycle at `now`: reports that arrived are received, every robot updates, then
    /// sends its report to every other.
    fn cycle(&mut self, now: f64) {
        let (due, later): (Vec<_>, Vec<_>) = self.wire.drain(..).partition(|m| m.0 <= now);
        self.wire = later;
        let mut due = due;
        due.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, to, from, report) in due {
            if self.cut_until[to] <= now {
                self.robots[to].receive(now, from as u32 + 1, &report);
            }
        }
        for r in &mut self.robots {
            r.update(now);
        }
        for from in 0..self.robots.len() {
            if self.cut_until[from] > now {
                continue;
            }
            let report = self.robots[from].report(now);
            for to in 0..self.robots.len() {
                if to != from && self.rng.random::<f64>() >= self.loss {
                    let at = now + self.rng.random::<f64>() * self.delay;
                    self.wire.push((at, to, from, report.clone()));
                }
            }
        }
    }

    fn holders(&self, now: f64) -> Vec<usize> {
        (0..self.robots.len()).filter(|&i| self.robots[i].holds(now)).collect()
    }

    /// Two holders at once are allowed only when they have heard nothing from each other
    /// for `silent` (cut off, each books alone).
    fn check_exclusive(&self, now: f64) -> Result<(), String> {
        let h = self.holders(now);
        for (k, &a) in h.iter().enumerate() {
            for &b in &h[k + 1..] {
                let (ia, ib) = (a as u32 + 1, b as u32 + 1);
                if self.robots[a].hears(ib, now) || self.robots[b].hears(ia, now) {
                    return Err(format!("robots {ia} and {ib} both hold at {now:.1} s"));
                }
            }
        }
        Ok(())
    }
}

#[test]
fn the_earlier_claim_holds_and_the_booking_passes_on_release() {
    let mut team = Team::new(3, 0.0, 0.0, 1);
    team.robots[1].want(0.0, true);
    team.robots[0].want(0.05, true);
    for k in 1..=5 {
        team.cycle(f64::from(k) * DT);
    }
    assert_eq!(team.holders(0.5), vec![1], "robot 2 asked first");
    team.robots[1].want(0.55, false);
    for k in 6..=10 {
        team.cycle(f64::from(k) * DT);
    }
    assert_eq!(team.holders(1.0), vec![0], "robot 1 was waiting");
}

/// The holder falls silent (a crashed robot): a waiting claimant gets the booking once it
/// has not heard it for `silent`, and the silent holder's own hold has ended by then.
#[test]
fn a_silent_holder_loses_the_booking_before_the_next_one_gets_it() {
    let mut team = Team::new(3, 0.0, 0.05, 2);
    team.robots[0].want(0.0, true);
    for k in 1..=5 {
        team.cycle(f64::from(k) * DT);
    }
    assert_eq!(team.holders(0.5), vec![0]);
    team.robots[2].want(0.5, true);
    // Robot 1 is cut off from 0.6 s: it still wants and affirms the ball.
    team.cut_until[0] = 100.0;
    let mut passed = None;
    for k in 6..=40 {
        let now = f64::from(k) * DT;
        team.robots[0].want(now, true);
        team.cycle(now);
        team.check_exclusive(now).unwrap();
        if passed.is_none() && team.robots[2].holds(now) {
            passed = Some(now);
        }
        if now > 1.65 {
            // Its last report to be heard left at 0.5 s; its lease ended by 1.5 s.
            assert!(!team.robots[0].holds(now) || team.robots[0].alone(now), "{now}");
        }
    }
    let passed = passed.expect("robot 3 never got the booking");
    assert!((1.5..=1.9).contains(&passed), "passed at {passed} s");
    // Cut off for good, robot 1 now books alone: each side believes itself alone.
    assert!(team.robots[0].alone(4.0) && team.robots[0].holds(4.0));
}

/// A claim stamped earlier than the holder's (a clock behind the others, or a report that
/// came late) waits for the holder's release instead of taking the booking from it.
#[test]
fn a_holder_is_not_preempted_by_an_earlier_stamped_claim() {
    let mut team = Team::new(3, 0.0, 0.0, 3);
    team.robots[0].want(1.0, true);
    for k in 11..=15 {
        team.cycle(f64::from(k) * DT);
    }
    assert_eq!(team.holders(1.5), vec![0]);
    // Robot 2's clock runs 2 s behind: its claim is stamped before robot 1's.
    let mut late = BallBooking::new(2, BookingParams::default());
    late.want(-0.4, true);
    team.robots[1] = late;
    for k in 16..=30 {
        let now = f64::from(k) * DT;
        team.robots[1].want(now - 2.0, true);
        team.cycle(now);
        assert_eq!(team.holders(now), vec![0], "{now}");
    }
    team.robots[0].want(3.05, false);
    for k in 31..=35 {
        team.cycle(f64::from(k) * DT);
    }
    assert_eq!(team.holders(3.5), vec![1]);
}

#[test]
fn a_claim_not_affirmed_lapses_and_odd_reports_are_dropped() {
    let mut a = BallBooking::new(1, BookingParams::default());
    a.want(0.0, true);
    a.update(0.0);
    assert!(a.holds(0.0));
    a.update(4.9);
    assert!(a.holds(4.9), "affirmed 4.9 s ago: still held");
    a.update(5.1);
    assert!(!a.holds(5.1) && !a.claims(), "5 s without bookBall: lapsed");
    let good = BookingReport { stamp: 1.0, claim: Some(0.5), grant: Some((2, 0.5)), echo: vec![] };
    a.receive(6.0, 2, &good);
    a.receive(6.0, 2, &good); // repeated
    a.receive(6.0, 2, &BookingReport { stamp: 0.9, ..good.clone() }); // late
    a.receive(6.0, 1, &good); // itself
    a.receive(6.0, 3, &BookingReport { stamp: f64::NAN, ..good.clone() });
    a.receive(6.0, 3, &BookingReport { claim: Some(f64::INFINITY), ..good.clone() });
    assert_eq!(a.dropped(), 5);
    assert!(a.hears(2, 6.0) && !a.hears(3, 6.0));
    // Reports from a flood of numbers: at most 32 teammates are kept.
    for id in 10..1000 {
        a.receive(6.0, id, &good);
    }
    assert_eq!(a.dropped(), 5 + 990 - 31);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Random wants and releases among 2–5 robots, up to 40 % of reports lost, up to 0.3 s of
    /// delay (reports overtake each other), robots cut off for a while: never two holders
    /// that hear each other, and the booking is held most of the time someone wants it.
    #[test]
    fn two_robots_that_hear_each_other_never_hold_at_once(
        n in 2usize..6,
        loss in 0.0..0.4f64,
        delay in 0.0..0.3f64,
        seed in any::<u64>(),
        cut in prop::option::of((0usize..5, 5.0..40.0f64, 0.5..4.0f64)),
    ) {
        let mut team = Team::new(n, loss, delay, seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        let mut wants = vec![false; n];
        let (mut wanted, mut held) = (0u32, 0u32);
        for k in 1..=600 {
            let now = f64::from(k) * DT;
            if let Some((who, from, length)) = cut {
                if who < n && (now - from).abs() < DT / 2.0 {
                    team.cut_until[who] = from + length;
                }
            }
            for (i, w) in wants.iter_mut().enumerate() {
                if rng.random::<f64>() < 0.03 {
                    *w = !*w;
                    if !*w {
                        team.robots[i].want(now, false);
                    }
                }
                if *w {
                    team.robots[i].want(now, true);
                }
            }
            team.cycle(now);
            if let Err(e) = team.check_exclusive(now) {
                return Err(TestCaseError::fail(e));
            }
            if wants.iter().any(|&w| w) {
                wanted += 1;
                held += u32::from(!team.holders(now).is_empty());
            }
        }
        // Liveness, loosely: with up to 40 % loss the booking is held at least a third of
        // the time someone wants it (hand-overs cost a few reports each).
        prop_assert!(wanted == 0 || f64::from(held) >= 0.33 * f64::from(wanted), "held {} of {}", held, wanted);
    }
}

proptest! {
    /// Reports off the network may hold anything: any stamp, claim, grant and echo from any
    /// number. The booking drops what it cannot use, never panics, and its answers stay
    /// answers (a robot that hears only odd reports holds its own claim alone).
    #[test]
    fn any_report_is_taken_or_dropped_never_a_panic(
        reports in prop::collection::vec(
            (any::<u32>(), any::<f64>(), prop::option::of(any::<f64>()),
             prop::option::of((any::<u32>(), any::<f64>())),
             prop::collection::vec((any::<u32>(), any::<f64>()), 0..8)),
            0..64),
        now in -1e9..1e9f64,
    ) {
        let mut me = BallBooking::new(7, BookingParams::default());
        me.want(now, true);
        for (from, stamp, claim, grant, echo) in reports {
            me.receive(now, from, &BookingReport { stamp, claim, grant, echo });
            me.update(now);
        }
        let report = me.report(now);
        prop_assert!(report.echo.len() <= mrt_team::booking::MAX_TEAMMATES);
        prop_assert!(me.claims());
        let _ = (me.holds(now), me.alone(now));
        me.want(now, false);
        me.update(now);
        prop_assert!(!me.holds(now));
    }
}
