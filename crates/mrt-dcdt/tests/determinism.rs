//! The stepped executor is deterministic: two Agoras (two robots), periodic producers at
//! different rates, cyclic and on-message Members relaying messages between them, on a
//! simulated clock. Every run gives the same message trace, message for message.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::InnerLinkManager;

/// Relays every `Count` it receives from another Agora as a `Status` naming it.
struct Relay;
impl Member for Relay {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Count>(RequestType::Remote);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive::<Count>() {
            let c = m.get::<Count>()?;
            ctx.publish(Status(format!("relayed {} from {}", c.0, m.agora_id())));
        }
        Ok(())
    }
}

fn trace(policy: PolicyKind) -> Vec<Seen> {
    let log = log();
    let ilm = InnerLinkManager::new();
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let mut r1 = exec.agora_builder(1).policy(policy).inner_link(&ilm).build().unwrap();
    let mut r2 = exec.agora_builder(2).policy(policy).inner_link(&ilm).build().unwrap();
    let mut fast = Producer::new(0);
    fast.status_every = 3;
    let ids1 = [
        r1.add_member(fast, Activation::Periodic(7 * MS)),
        r1.add_member(
            Recorder::new(
                "r1-all",
                &[(Count::TYPE, RequestType::All), (Status::TYPE, RequestType::All)],
                &log,
            ),
            Activation::OnMessage,
        ),
        r1.add_member(
            Recorder::new("r1-polled", &[(Status::TYPE, RequestType::Remote)], &log),
            Activation::Periodic(25 * MS),
        ),
    ];
    let ids2 = [
        r2.add_member(
            Recorder::new("r2-first", &[(Count::TYPE, RequestType::All)], &log),
            Activation::OnMessage,
        ),
        r2.add_member(Producer::new(0), Activation::Periodic(11 * MS)),
        r2.add_member(Relay, Activation::OnMessage),
        r2.add_member(
            Recorder::new("r2-cyclic", &[(Status::TYPE, RequestType::Local)], &log),
            Activation::Cyclic,
        ),
    ];
    for id in ids1 {
        r1.activate_member(id).unwrap();
    }
    for id in ids2 {
        r2.activate_member(id).unwrap();
    }
    exec.add_agora(r1).unwrap();
    exec.add_agora(r2).unwrap();
    exec.run_for(std::time::Duration::from_millis(300));
    let reports = exec.finish();
    assert!(reports.iter().all(|r| r.exit == ExitReason::TimeLimit));
    let out = log.lock().unwrap().clone();
    out
}

#[test]
fn stepped_runs_give_identical_traces() {
    for policy in PolicyKind::ALL {
        let first = trace(policy);
        // Not trivially equal: 300 ms of a 7 ms and an 11 ms producer and their relays.
        assert!(first.len() > 100, "{policy}: {} messages", first.len());
        for _ in 0..3 {
            assert_eq!(trace(policy), first, "{policy}: a rerun differs");
        }
    }
}

#[test]
fn trace_content_follows_the_schedule() {
    let t = trace(PolicyKind::Pmq);
    // The 7 ms producer of robot 1 publishes at 0, 7, 14, ... 294 ms: 43 counts.
    let r1_counts = t
        .iter()
        .filter(|s| s.receiver == "r1-all" && s.from_agora == 1 && s.what.starts_with("Count"))
        .count();
    assert_eq!(r1_counts, 43);
    // Robot 2's 11 ms producer runs at 0, 11, ..., 297 ms: 28 counts, seen by r1-all as remote.
    let r2_counts = t
        .iter()
        .filter(|s| s.receiver == "r1-all" && s.from_agora == 2)
        .filter(|s| s.what.starts_with("Count"))
        .count();
    assert_eq!(r2_counts, 28);
    // r2-first runs before robot 2's relay and producer in the order: it sees robot 1's counts
    // in the tick they are created (robot 1 steps first) ...
    let first = t.iter().find(|s| s.receiver == "r2-first" && s.from_agora == 1).unwrap();
    assert_eq!(first.at_ns, first.created_ns);
    // ... and its own robot's counts one tick (1 ms) later, since the producer comes after it.
    let own = t.iter().find(|s| s.receiver == "r2-first" && s.from_agora == 2).unwrap();
    assert_eq!(own.at_ns, own.created_ns + 1_000_000);
    // Every count of robot 1 is relayed by robot 2 and seen by robot 2's cyclic recorder.
    let relayed = t
        .iter()
        .filter(|s| s.receiver == "r2-cyclic" && s.what.starts_with("Status(relayed"))
        .count();
    assert_eq!(relayed, 43);
}
