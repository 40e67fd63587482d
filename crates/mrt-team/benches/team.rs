//! The team coordination's cost per robot cycle: the ball booking (receive four teammates'
//! reports, update, report, holds) and the role allocation of five players. Both run in every
//! robot's world-state Member each cycle.
//!
//! Run: `cargo bench -p mrt-team --bench team`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_team::booking::{BallBooking, BookingParams};
use mrt_team::roles::{allocate, Player, Role};

fn bench(c: &mut Criterion) {
    // Five robots that have talked for a while; robot 1 holds the booking.
    let mut team: Vec<BallBooking> =
        (1..=5).map(|id| BallBooking::new(id, BookingParams::default())).collect();
    team[0].want(0.0, true);
    let mut now = 0.0;
    for _ in 0..20 {
        now += 0.1;
        for r in &mut team {
            r.update(now);
        }
        let reports: Vec<_> = team.iter().map(|r| r.report(now)).collect();
        for (i, r) in team.iter_mut().enumerate() {
            for (j, rep) in reports.iter().enumerate() {
                if i != j {
                    r.receive(now, j as u32 + 1, rep);
                }
            }
        }
    }
    assert!(team[0].holds(now));
    let reports: Vec<_> = team.iter().map(|r| r.report(now)).collect();
    let mut g = c.benchmark_group("team");
    g.bench_function("booking_cycle", |b| {
        let mut me = team[0].clone();
        let mut t = now;
        b.iter(|| {
            t += 0.1;
            for (j, rep) in reports.iter().enumerate().skip(1) {
                let rep = mrt_msgs::BookingReport { stamp: t, ..rep.clone() };
                me.receive(t, j as u32 + 1, &rep);
            }
            me.update(t);
            black_box((me.report(t), me.holds(t)))
        })
    });
    let players: Vec<Player> = (0..5)
        .map(|k| Player {
            id: k + 1,
            at: (f64::from(k) * 1000.0 - 4000.0, 500.0),
            keeper: k == 0,
            said: if k == 2 { Role::Attacker } else { Role::Defender },
        })
        .collect();
    g.bench_function("roles_five_players", |b| {
        b.iter(|| allocate(black_box(&players), Some((0.0, 0.0))))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
