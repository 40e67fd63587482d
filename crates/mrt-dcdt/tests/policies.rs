//! Every PostOffice policy, in the deterministic stepped executor: delivery order, the
//! single-message semantics of SLWSM, Local/Remote/All across Agoras, unsubscribing, and the
//! life of a shared message.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::InnerLinkManager;
use std::sync::atomic::{AtomicUsize, Ordering};

fn run_one_agora(policy: PolicyKind, consumer: Activation) -> Log {
    let log = log();
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let mut a = exec.agora_builder(1).policy(policy).build().unwrap();
    let mut producer = Producer::new(5);
    producer.status_every = 2;
    let p = a.add_member(producer, Activation::Periodic(10 * MS));
    // The consumer runs every 50 ms, so several messages queue up between its cycles.
    let c = a.add_member(
        Recorder::new(
            "c",
            &[(Count::TYPE, RequestType::All), (Status::TYPE, RequestType::All)],
            &log,
        ),
        consumer,
    );
    a.activate_member(p).unwrap();
    a.activate_member(c).unwrap();
    exec.add_agora(a).unwrap();
    exec.run_for(200 * MS);
    exec.finish();
    log
}

#[test]
fn queueing_policies_deliver_every_message_in_order() {
    for policy in [PolicyKind::Slwb, PolicyKind::Slwdwcv, PolicyKind::Pmq] {
        let log = run_one_agora(policy, Activation::Periodic(50 * MS));
        assert_eq!(
            whats(&log, "c"),
            [
                "Count(1)",
                "Count(2)",
                "Status(at 2)",
                "Count(3)",
                "Count(4)",
                "Status(at 4)",
                "Count(5)"
            ],
            "{policy}"
        );
    }
}

#[test]
fn slwsm_keeps_only_the_latest_message_of_each_type() {
    let log = run_one_agora(PolicyKind::Slwsm, Activation::Periodic(50 * MS));
    // Cycle at t=0 sees Count(1) (the producer ran first in the same tick). At t=50 the
    // producer has published Count(2..=5) and Status(at 2), Status(at 4): only the latest of
    // each type is kept, in the order the types first got a fresh message.
    assert_eq!(whats(&log, "c"), ["Count(1)", "Count(5)", "Status(at 4)"]);
}

#[test]
fn on_message_consumer_is_woken_for_every_message() {
    for policy in PolicyKind::ALL {
        let log = run_one_agora(policy, Activation::OnMessage);
        let got = whats(&log, "c");
        assert_eq!(got.len(), 7, "{policy}: {got:?}");
        let times: Vec<u64> = log.lock().unwrap().iter().map(|s| s.at_ns).collect();
        // Woken in the same tick the message was created.
        let created: Vec<u64> = log.lock().unwrap().iter().map(|s| s.created_ns).collect();
        assert_eq!(times, created, "{policy}");
    }
}

/// Two robots in one process: Local, Remote and All subscriptions see what they should.
#[test]
fn local_remote_and_all_across_agoras() {
    for policy in PolicyKind::ALL {
        let log = log();
        let ilm = InnerLinkManager::new();
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let mut r1 = exec.agora_builder(1).policy(policy).inner_link(&ilm).build().unwrap();
        let mut r2 = exec.agora_builder(2).policy(policy).inner_link(&ilm).build().unwrap();
        let p1 = r1.add_member(Producer::new(1), Activation::Cyclic);
        let p2 = r2.add_member(Producer::new(2), Activation::Cyclic);
        let mut ids = vec![];
        for (name, req) in [
            ("local", RequestType::Local),
            ("remote", RequestType::Remote),
            ("all", RequestType::All),
        ] {
            ids.push(r1.add_member(
                Recorder::new(name, &[(Count::TYPE, req)], &log),
                Activation::OnMessage,
            ));
        }
        r1.activate_member(p1).unwrap();
        r2.activate_member(p2).unwrap();
        for id in ids {
            r1.activate_member(id).unwrap();
        }
        exec.add_agora(r1).unwrap();
        exec.add_agora(r2).unwrap();
        exec.run_for(10 * MS);
        exec.finish();
        let from = |name: &str| -> Vec<(u32, String)> {
            log.lock()
                .unwrap()
                .iter()
                .filter(|s| s.receiver == name)
                .map(|s| (s.from_agora, s.what.clone()))
                .collect()
        };
        assert_eq!(from("local"), [(1, "Count(1)".to_string())], "{policy}");
        assert_eq!(
            from("remote"),
            [(2, "Count(1)".to_string()), (2, "Count(2)".to_string())],
            "{policy}"
        );
        let mut all = from("all");
        all.sort();
        assert_eq!(all.len(), 3, "{policy}: {all:?}");
    }
}

#[test]
fn unsubscribe_and_unsubscribe_all_stop_delivery() {
    for policy in PolicyKind::ALL {
        let mut a = mrt_dcdt::Agora::builder(1).policy(policy).build().unwrap();
        let mut tx = a.endpoint();
        let mut rx = a.endpoint();
        rx.subscribe_to::<Count>(RequestType::All);
        rx.subscribe_to::<Status>(RequestType::Local);
        assert_eq!(
            a.post_office().subscribers(Count::TYPE),
            vec![(rx.member_id(), RequestType::All)]
        );
        assert_eq!(tx.publish(Count(1)), 1);
        rx.unsubscribe(Count::TYPE, RequestType::Local);
        assert_eq!(
            a.post_office().subscribers(Count::TYPE),
            vec![(rx.member_id(), RequestType::Remote)]
        );
        assert_eq!(tx.publish(Count(2)), 0, "{policy}: local half removed");
        assert_eq!(tx.publish(Status("s".into())), 1);
        rx.unsubscribe_all();
        assert_eq!(tx.publish(Status("t".into())), 0);
        assert_eq!(a.post_office().policy(), policy);
        let mut got = vec![];
        while let Some(m) = rx.receive_msg() {
            got.push(describe(&m));
        }
        // SLWDWCV hands messages over through its dispatcher, which only an executor runs.
        if policy != PolicyKind::Slwdwcv {
            assert_eq!(got, ["Count(1)", "Status(s)"], "{policy}");
        }
        assert!(tx.receive_msg().is_none());
    }
}

static DROPS: AtomicUsize = AtomicUsize::new(0);

#[derive(serde::Serialize, serde::Deserialize)]
struct Tracked(u8);
impl Drop for Tracked {
    fn drop(&mut self) {
        DROPS.fetch_add(1, Ordering::SeqCst);
    }
}
impl Message for Tracked {
    const TYPE: MsgType = MsgType(99);
    const NAME: &'static str = "Tracked";
}

/// One allocation is shared by every subscriber and freed when the last one is done with it.
#[test]
fn a_message_is_shared_not_copied_and_freed_by_the_last_reader() {
    let mut a = mrt_dcdt::Agora::builder(1).policy(PolicyKind::Slwb).build().unwrap();
    let tx = a.endpoint();
    let mut r1 = a.endpoint();
    let mut r2 = a.endpoint();
    r1.subscribe_to::<Tracked>(RequestType::All);
    r2.subscribe_to::<Tracked>(RequestType::All);
    let before = DROPS.load(Ordering::SeqCst);
    assert_eq!(tx.publish(Tracked(5)), 2);
    let m1 = r1.receive_msg().unwrap();
    let m2 = r2.receive_msg().unwrap();
    assert!(std::ptr::eq(m1.get::<Tracked>().unwrap(), m2.get::<Tracked>().unwrap()));
    drop(m1);
    r1.remove_curr_msg();
    drop(m2);
    assert_eq!(DROPS.load(Ordering::SeqCst), before, "r2 still holds it as its current message");
    r2.remove_curr_msg();
    assert_eq!(DROPS.load(Ordering::SeqCst), before + 1);
}

/// Under PMQ a small plain message travels by value inside each mailbox slot (`parcel`): every
/// reader gets an equal value under the publisher's header, in a block of its own. A message
/// that owns memory is shared: both readers read one allocation.
#[test]
fn small_plain_messages_are_copied_and_others_shared() {
    let clock = SimClock::new();
    let mut a =
        mrt_dcdt::Agora::builder(1).clock(std::sync::Arc::new(clock.clone())).build().unwrap();
    let tx = a.endpoint();
    let mut r1 = a.endpoint();
    r1.subscribe_to::<Count>(RequestType::All);
    clock.advance(std::time::Duration::from_millis(250));
    assert_eq!(tx.publish_with(Count(7), DeliveryWarranty::Reliable, 200), 1);
    let m = r1.receive_msg().unwrap();
    assert_eq!(m.get::<Count>().unwrap(), &Count(7));
    let h = m.header();
    assert_eq!((h.msg_type, h.member_id, h.agora_id), (Count::TYPE, tx.member_id(), a.id()));
    assert_eq!((h.warranty, h.priority), (DeliveryWarranty::Reliable, 200));
    assert_eq!(h.creation_time, mrt_core::Time::from_secs_f64(0.25));

    let mut r2 = a.endpoint();
    r2.subscribe_to::<Count>(RequestType::All);
    assert_eq!(tx.publish(Count(8)), 2);
    let (m1, m2) = (r1.receive_msg().unwrap(), r2.receive_msg().unwrap());
    let (c1, c2) = (m1.get::<Count>().unwrap(), m2.get::<Count>().unwrap());
    assert_eq!((c1, c2), (&Count(8), &Count(8)));
    assert!(!std::ptr::eq(c1, c2));

    r1.subscribe_to::<Status>(RequestType::All);
    r2.subscribe_to::<Status>(RequestType::All);
    assert_eq!(tx.publish(Status("kick".into())), 2);
    let (m1, m2) = (r1.receive_msg().unwrap(), r2.receive_msg().unwrap());
    assert!(std::ptr::eq(m1.get::<Status>().unwrap(), m2.get::<Status>().unwrap()));
}

/// In a community of Agoras under different policies, one publish reaches every subscriber
/// with an equal value and the same header, whether its PostOffice takes it by value (PMQ) or
/// shared (the single-lock policies), in either order of the Agoras.
#[test]
fn mixed_policies_in_a_community_read_the_same_message() {
    for (first, second) in
        [(PolicyKind::Pmq, PolicyKind::Slwb), (PolicyKind::Slwb, PolicyKind::Pmq)]
    {
        let ilm = InnerLinkManager::new();
        let mut a1 = mrt_dcdt::Agora::builder(1).policy(first).inner_link(&ilm).build().unwrap();
        let mut a2 = mrt_dcdt::Agora::builder(2).policy(second).inner_link(&ilm).build().unwrap();
        let tx = a1.endpoint();
        let mut r1 = a1.endpoint();
        let mut r2 = a2.endpoint();
        r1.subscribe_to::<Count>(RequestType::All);
        r2.subscribe_to::<Count>(RequestType::All);
        assert_eq!(tx.publish_with(Count(3), DeliveryWarranty::Retransmit, 5), 2);
        let (m1, m2) = (r1.receive_msg().unwrap(), r2.receive_msg().unwrap());
        assert_eq!(m1.get::<Count>().unwrap(), &Count(3), "{first} then {second}");
        assert_eq!(m2.get::<Count>().unwrap(), &Count(3), "{first} then {second}");
        assert_eq!(m1.header(), m2.header());
        assert_eq!(m1.header().warranty, DeliveryWarranty::Retransmit);
    }
}

/// Sharing a type nobody subscribed to allocates nothing and is not an error.
#[test]
fn publishing_to_nobody_is_cheap_and_not_an_error() {
    let a = {
        let mut a = mrt_dcdt::Agora::builder(1).build().unwrap();
        let tx = a.endpoint();
        assert!(!tx.has_subscribers(Count::TYPE));
        for i in 0..1000 {
            assert_eq!(tx.publish(Count(i)), 0);
        }
        a
    };
    let stats = a.post_office().stats();
    assert_eq!(stats.unsubscribed, 1000);
}

/// Raw messages: the manual's CreateMsg / ShareMsg / ReceiveMsg, including an event message
/// with an empty payload.
#[test]
fn raw_messages_and_events() {
    let mut a = mrt_dcdt::Agora::builder(3).build().unwrap();
    let tx = a.endpoint();
    let mut rx = a.endpoint();
    rx.subscribe(MsgType(500), RequestType::All);
    rx.subscribe(MsgType(501), RequestType::All);
    let mut m = tx.create_msg_with(MsgType(500), DeliveryWarranty::Reliable).with_priority(9);
    m.payload_mut().extend_from_slice(b"hello");
    assert_eq!(tx.share_msg(m), 1);
    assert_eq!(tx.share_msg(tx.create_msg(MsgType(501))), 1);
    let got = rx.receive_msg().unwrap();
    assert_eq!(got.bytes(), Some(&b"hello"[..]));
    assert_eq!(got.payload_len(), 5);
    assert_eq!(got.header().priority, 9);
    assert_eq!(got.header().warranty, DeliveryWarranty::Reliable);
    assert_eq!(got.agora_id().0, 3);
    assert_eq!(got.member_id(), tx.member_id());
    assert!(rx.current_msg().is_some());
    rx.remove_curr_msg();
    assert!(rx.current_msg().is_none());
    let event = rx.receive_msg().unwrap();
    assert_eq!(event.msg_type(), MsgType(501));
    assert!(event.payload().is_empty());
    // A raw message read as the wrong Rust type is an error, not a panic.
    assert!(event.get::<Count>().is_err());
}
