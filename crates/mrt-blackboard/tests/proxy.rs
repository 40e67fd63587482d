//! Shared blackboard variables between robots: three robots' Agoras on one team link, each
//! with a blackboard and its Proxy Member, on a stepped simulated clock.
#![allow(clippy::unwrap_used)]

use mrt_blackboard::board::BbLimits;
use mrt_blackboard::{BbUpdate, Blackboard, Proxy, Update, Value};
use mrt_core::SimClock;
use mrt_dcdt::{Activation, Context, InnerLinkManager, Member, MemberError, SteppedExecutor};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Publishes the given updates once, as a robot running a newer or broken version might.
struct Injector(Vec<Update>);

impl Member for Injector {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for u in self.0.drain(..) {
            ctx.publish(BbUpdate(u));
        }
        Ok(())
    }
}

struct Team {
    exec: SteppedExecutor,
    boards: Vec<Blackboard>,
    rejected: Vec<Arc<AtomicU64>>,
    over_limit: Vec<Arc<AtomicU64>>,
}

fn team(robots: u32, inject: Vec<Update>) -> Team {
    team_with(robots, inject, BbLimits::default())
}

fn team_with(robots: u32, inject: Vec<Update>, limits: BbLimits) -> Team {
    let tick = Duration::from_millis(10);
    let mut exec = SteppedExecutor::new(SimClock::new(), tick);
    let link = InnerLinkManager::new();
    let (mut boards, mut rejected, mut over_limit) = (Vec::new(), Vec::new(), Vec::new());
    for id in 1..=robots {
        let mut agora = exec.agora_builder(id).inner_link(&link).build().unwrap();
        let bb = Blackboard::with_limits(id, agora.clock().clone(), limits);
        let proxy = Proxy::new(bb.clone());
        rejected.push(proxy.rejected());
        over_limit.push(proxy.over_limit());
        let m = agora.add_member(proxy, Activation::Periodic(tick));
        agora.activate_member(m).unwrap();
        exec.add_agora(agora).unwrap();
        boards.push(bb);
    }
    let mut agora = exec.agora_builder(99).inner_link(&link).build().unwrap();
    let m = agora.add_member(Injector(inject), Activation::Periodic(tick));
    agora.activate_member(m).unwrap();
    exec.add_agora(agora).unwrap();
    Team { exec, boards, rejected, over_limit }
}

#[test]
fn shared_variables_reach_every_robot_and_local_ones_stay_home() {
    let mut t = team(3, Vec::new());
    t.exec.run_for(Duration::from_millis(20));
    let [one, two, three] = [&t.boards[0], &t.boards[1], &t.boards[2]];
    one.set("*.var.team.formation", "diamond").unwrap();
    one.set("1.var.machine.cost", 3.5).unwrap();
    one.set("local.var.machine.secret", 7).unwrap();
    two.push("*.talk.coord.offers", 2).unwrap();
    t.exec.run_for(Duration::from_millis(30));
    for (bb, id) in [(two, 2), (three, 3)] {
        assert_eq!(bb.get::<String>("*.var.team.formation").unwrap(), "diamond", "robot {id}");
        let cost = bb.get_stamped("1.var.machine.cost").unwrap();
        assert_eq!((cost.value, cost.from), (Value::Float(3.5), Some(1)), "robot {id}");
        assert!(bb.get::<i64>("local.var.machine.secret").is_err(), "robot {id}");
    }
    // Stamped on arrival, on the receiver's clock: the set happened at 20 ms (before the
    // next step), the proxies carried it in the step at 20 ms or later.
    let sent = one.get_stamped("*.var.team.formation").unwrap().time;
    let got = two.get_stamped("*.var.team.formation").unwrap().time;
    assert_eq!(sent, mrt_core::Time::from_secs_f64(0.02));
    assert!(got >= sent && got <= mrt_core::Time::from_secs_f64(0.05), "{got}");
    // Talk queues too: each robot gets its own copy of the message.
    assert_eq!(one.pop("*.talk.coord.offers").unwrap().map(|s| s.value), Some(Value::Int(2)));
    assert_eq!(three.pop("*.talk.coord.offers").unwrap().map(|s| s.value), Some(Value::Int(2)));
    assert_eq!(
        two.pop("*.talk.coord.offers").unwrap().map(|s| s.value),
        Some(Value::Int(2)),
        "its own push"
    );
    // No echo: robot 1's change did not come back to it as a remote one.
    assert_eq!(one.get_stamped("*.var.team.formation").unwrap().from, None);
    assert!(t.rejected.iter().all(|r| r.load(Ordering::Relaxed) == 0));
}

#[test]
fn malformed_updates_are_counted_and_dropped() {
    let bad = vec![
        Update { from: 7, symbol: "not a symbol".into(), value: Value::Int(1) },
        Update { from: 7, symbol: "local.var.machine.role".into(), value: Value::Int(1) },
        Update { from: 7, symbol: "*.var.team.formation".into(), value: Value::Int(1) },
        Update { from: 7, symbol: "*.var.ok".into(), value: Value::Bool(true) },
    ];
    let mut t = team(2, bad);
    t.boards[0].set("*.var.team.formation", "diamond").unwrap();
    t.boards[1].set("*.var.team.formation", "diamond").unwrap();
    t.exec.run_for(Duration::from_millis(50));
    for (bb, rejected) in t.boards.iter().zip(&t.rejected) {
        // A wrong type for a known symbol, a local symbol, garbage: 3 dropped; the good one in.
        assert_eq!(rejected.load(Ordering::Relaxed), 3, "robot {}", bb.robot());
        assert!(bb.get::<bool>("*.var.ok").unwrap());
        assert_eq!(bb.get::<String>("*.var.team.formation").unwrap(), "diamond");
        assert!(bb.get::<i64>("local.var.machine.role").is_err());
    }
}

/// The limits of the relay hold for updates from the network too. A teammate (or
/// a forged frame) sending a string past `max_string` or more new symbols than a guest may
/// create has them counted and dropped; the robot's own sets still work.
#[test]
fn updates_past_the_limits_are_counted_and_dropped() {
    let limits =
        BbLimits { max_symbols: 8, max_guest_symbols: 4, max_string: 16, ..BbLimits::default() };
    let mut flood: Vec<Update> = (0..10)
        .map(|i| Update { from: 7, symbol: format!("7.var.flood{i}"), value: Value::Int(i) })
        .collect();
    flood.push(Update {
        from: 7,
        symbol: "*.var.big".into(),
        value: Value::String("x".repeat(17)),
    });
    let mut t = team_with(1, flood, limits);
    t.exec.run_for(Duration::from_millis(50));
    let bb = &t.boards[0];
    // 4 new symbols from a guest, then 6 refused, and the long string.
    assert_eq!(bb.len(), 4);
    assert_eq!(t.over_limit[0].load(Ordering::Relaxed), 7);
    assert_eq!(t.rejected[0].load(Ordering::Relaxed), 7);
    assert!(bb.get::<String>("*.var.big").is_err());
    // The robot's own Members still have room.
    for i in 0..4 {
        bb.set(&format!("local.var.own{i}"), i).unwrap();
    }
    assert!(bb.set("local.var.one-too-many", 0).is_err());
}
