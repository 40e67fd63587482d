//! The team coordination's cost per robot cycle: the ball booking (receive four teammates'
//! reports, update, report, holds), the role allocation of five players, and SCARE (Team
//! Milan's allocation of seven activities, two of them schemata, to five robots; and a whole
//! coordinator cycle: attitudes, opportunities, allocation, sequencer, report). All run in
//! every robot's world-state Member each cycle.
//!
//! Run: `cargo bench -p mrt-team --bench team`.
#![allow(missing_docs, clippy::unwrap_used)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mrt_team::booking::{BallBooking, BookingParams};
use mrt_team::roles::{allocate, Player, Role};
use mrt_team::scare::soccer::{table, Coordinator, Situation};
use mrt_team::scare::{self, Agent, Params};

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
            at: (f64::from(k) - 4.0, 0.5),
            keeper: k == 0,
            said: if k == 2 { Role::Attacker } else { Role::Defender },
        })
        .collect();
    g.bench_function("roles_five_players", |b| {
        b.iter(|| allocate(black_box(&players), Some((0.0, 0.0))))
    });
    // SCARE: five robots of Team Milan with the ball ahead, a blocking opponent and an open
    // mate (so that the PassageToMate schema is on the agenda and covered).
    let pos = [(-8.5, 0.0), (-1.5, 0.0), (2.0, 2.0), (-4.0, -1.0), (-2.0, 2.5)];
    let situation = |i: usize| Situation {
        me: (pos[i].0, pos[i].1, 0.0),
        keeper: i == 0,
        ball: Some((-1.0, 0.0)),
        mates: (0..5).filter(|j| *j != i).map(|j| (j as u32 + 1, pos[j], j == 0)).collect(),
        opponents: vec![(-0.2, 0.0), (4.0, -2.5), (-3.0, 3.0)],
        half_length: 9.0,
        goal_half_width: 1.0,
    };
    let t = table();
    let agents: Vec<Agent> =
        (0..5).map(|i| Agent::new(i as u32 + 1, situation(i).attitudes())).collect();
    let opportunity = situation(1).opportunity(2);
    let a = scare::allocate(&t, &opportunity, &agents, &Params::default());
    assert_eq!(a.names(&t)[1], (2, "PassageToMate"), "{:?}", a.names(&t));
    g.bench_function("scare_allocate_five_robots", |b| {
        b.iter(|| {
            scare::allocate(&t, black_box(&opportunity), black_box(&agents), &Params::default())
        })
    });
    let reports: Vec<_> = (0..5)
        .map(|i| {
            let mut c = Coordinator::new(i as u32 + 1);
            (i as u32 + 1, c.cycle(0.0, &situation(i), &[], 0.0).report)
        })
        .collect();
    let heard: Vec<_> = reports.iter().skip(2).map(|(id, r)| (*id, r)).collect();
    g.bench_function("scare_coordinator_cycle", |b| {
        let mut me = Coordinator::new(2);
        let sit = situation(1);
        let mut now = 0.0;
        b.iter(|| {
            now += 0.1;
            black_box(me.cycle(now, &sit, black_box(&heard), 0.0))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
