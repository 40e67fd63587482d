//! Bounded memory on the bus: every subscription's buffer holds at most
//! `MailboxBounds::capacity` messages. A producer flooding a Member that never reads leaves at
//! most that many messages waiting; best-effort messages beyond it drop the oldest and are
//! counted in the `RunReport`, per Member and subscription; `Reliable` messages are not
//! dropped (they wait, up to `reliable_limit`, then are refused and counted); what is received
//! comes in the order it was sent. Counted in messages, under both executors, never timed.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::{DcdtError, Endpoint, MailboxBounds, MailboxReport, MemberId, RunReport};
use std::time::Duration;

/// The deaf Members' period.
const SECOND: Duration = Duration::from_secs(1);

const QUEUEING: [PolicyKind; 3] = [PolicyKind::Pmq, PolicyKind::Slwb, PolicyKind::Slwdwcv];

/// Publishes `per_tick` messages `Count(n)` each cycle (and a `Status` naming `n` after every
/// `status_every`-th, when not 0), with the given warranty.
struct Flood {
    n: u32,
    per_tick: u32,
    status_every: u32,
    warranty: DeliveryWarranty,
}

impl Flood {
    fn new(per_tick: u32, warranty: DeliveryWarranty) -> Self {
        Self { n: 0, per_tick, status_every: 0, warranty }
    }
}

impl Member for Flood {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for _ in 0..self.per_tick {
            self.n += 1;
            ctx.publish_with(Count(self.n), self.warranty, 0);
            if self.status_every > 0 && self.n % self.status_every == 0 {
                ctx.publish_with(Status(format!("at {}", self.n)), self.warranty, 0);
            }
        }
        Ok(())
    }
}

/// Subscribes (with its own bounds for `Status` when given) and never reads.
struct Deaf {
    status_bounds: Option<MailboxBounds>,
}

impl Member for Deaf {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Count>(RequestType::All);
        match self.status_bounds {
            Some(b) => ctx.subscribe_bounded(Status::TYPE, RequestType::All, b)?,
            None => ctx.subscribe_to::<Status>(RequestType::All),
        }
        Ok(())
    }
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Ok(())
    }
}

/// Reads nothing until its `wake_at`-th cycle, then drains its mailbox into the log.
struct Sleeper {
    cycle: u32,
    wake_at: u32,
    inner: Recorder,
}

impl Member for Sleeper {
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inner.init(ctx)
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.cycle += 1;
        if self.cycle >= self.wake_at {
            self.inner.do_your_job(ctx)?;
        }
        Ok(())
    }
}

/// One Agora of `policy` with `bounds`: `flood`, and a Recorder `s` of `subs` that sleeps
/// until its `wake_at`-th cycle. Returns the recorder's id.
fn flood_a_sleeper(
    exec: &mut SteppedExecutor,
    (policy, bounds): (PolicyKind, MailboxBounds),
    flood: Flood,
    (wake_at, subs): (u32, &[(MsgType, RequestType)]),
    log: &Log,
) -> MemberId {
    let mut a = exec.agora_builder(1).policy(policy).mailbox_bounds(bounds).build().unwrap();
    let p = a.add_member(flood, Activation::Cyclic);
    let s = a.add_member(
        Sleeper { cycle: 0, wake_at, inner: Recorder::new("s", subs, log) },
        Activation::Cyclic,
    );
    a.activate_member(p).unwrap();
    a.activate_member(s).unwrap();
    exec.add_agora(a).unwrap();
    s
}

fn counts(log: &Log, receiver: &str) -> Vec<u32> {
    whats(log, receiver)
        .iter()
        .filter_map(|w| w.strip_prefix("Count(")?.strip_suffix(')')?.parse().ok())
        .collect()
}

fn report_of(reports: &[RunReport], name: &str) -> mrt_dcdt::MemberReport {
    reports[0].members.iter().find(|m| m.name == name).unwrap().clone()
}

#[test]
fn a_flooded_member_that_never_reads_keeps_at_most_capacity_messages() {
    for policy in QUEUEING {
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let mut a = exec
            .agora_builder(1)
            .policy(policy)
            .mailbox_bounds(MailboxBounds::new(16))
            .build()
            .unwrap();
        let p = a.add_member(Flood::new(10, DeliveryWarranty::None), Activation::Cyclic);
        let d = a.add_member(Deaf { status_bounds: None }, Activation::Periodic(SECOND));
        a.activate_member(p).unwrap();
        a.activate_member(d).unwrap();
        exec.add_agora(a).unwrap();
        let mut most = 0;
        for _ in 0..100 {
            exec.step();
            let waiting = exec.agoras().next().unwrap().post_office().pending(d);
            most = most.max(waiting);
            assert!(waiting <= 16, "{policy}: {waiting} messages waiting");
        }
        assert_eq!(most, 16, "{policy}: the buffer fills up to its capacity");
        let reports = exec.finish();
        let deaf = report_of(&reports, "Deaf");
        // 1000 published, 16 kept.
        assert_eq!(
            deaf.mailboxes,
            vec![
                MailboxReport {
                    msg_type: Count::TYPE,
                    capacity: 16,
                    reliable_limit: 16 * 16,
                    dropped: 1000 - 16,
                    refused: 0
                },
                MailboxReport {
                    msg_type: Status::TYPE,
                    capacity: 16,
                    reliable_limit: 16 * 16,
                    dropped: 0,
                    refused: 0
                },
            ],
            "{policy}"
        );
        assert_eq!(reports[0].dropped(), 1000 - 16, "{policy}");
        assert_eq!(reports[0].refused(), 0, "{policy}");
    }
}

#[test]
fn drops_are_reported_per_member_and_subscription() {
    for policy in QUEUEING {
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let mut a = exec
            .agora_builder(1)
            .policy(policy)
            .mailbox_bounds(MailboxBounds::new(8))
            .build()
            .unwrap();
        let mut flood = Flood::new(5, DeliveryWarranty::None);
        flood.status_every = 5;
        let p = a.add_member(flood, Activation::Cyclic);
        let d1 = a.add_member(
            Deaf { status_bounds: Some(MailboxBounds::new(2)) },
            Activation::Periodic(SECOND),
        );
        let reader = a.add_member(
            Recorder::new("reader", &[(Count::TYPE, RequestType::All)], &log()),
            Activation::OnMessage,
        );
        for id in [p, d1, reader] {
            a.activate_member(id).unwrap();
        }
        exec.add_agora(a).unwrap();
        exec.run_for(20 * MS); // 100 Counts, 20 Status
        let reports = exec.finish();
        let deaf = report_of(&reports, "Deaf");
        assert_eq!(deaf.mailbox(Count::TYPE).map(|m| (m.capacity, m.dropped)), Some((8, 92)));
        assert_eq!(deaf.mailbox(Status::TYPE).map(|m| (m.capacity, m.dropped)), Some((2, 18)));
        assert_eq!(deaf.dropped(), 110, "{policy}");
        // The Member that keeps up lost nothing.
        let r = report_of(&reports, "reader");
        assert_eq!(r.dropped(), 0, "{policy}");
        assert_eq!(r.mailboxes.len(), 1, "{policy}");
        assert_eq!(reports[0].dropped(), 110, "{policy}");
    }
}

#[test]
fn after_drops_the_newest_messages_arrive_in_order_across_subscriptions() {
    for policy in QUEUEING {
        let log = log();
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let mut flood = Flood::new(3, DeliveryWarranty::None);
        flood.status_every = 2;
        let subs = [(Count::TYPE, RequestType::All), (Status::TYPE, RequestType::All)];
        let bounds = MailboxBounds::new(4);
        flood_a_sleeper(&mut exec, (policy, bounds), flood, (4, &subs), &log);
        // Ticks 0..3 send Counts 1..12 and Status at 2, 4, .., 12; the sleeper reads in tick 3,
        // after the producer: the 4 newest of each type are left, in the order they came.
        exec.run_for(4 * MS);
        exec.finish();
        let seen = whats(&log, "s");
        assert_eq!(
            seen,
            [
                "Status(at 6)",
                "Status(at 8)",
                "Count(9)",
                "Count(10)",
                "Status(at 10)",
                "Count(11)",
                "Count(12)",
                "Status(at 12)",
            ],
            "{policy}"
        );
    }
}

#[test]
fn reliable_messages_are_not_dropped_and_keep_their_order() {
    for policy in QUEUEING {
        let log = log();
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let mut flood = Flood::new(10, DeliveryWarranty::Reliable);
        flood.status_every = 4;
        let subs = [(Count::TYPE, RequestType::All), (Status::TYPE, RequestType::All)];
        let bounds = MailboxBounds::new(8).with_reliable_limit(1000);
        let s = flood_a_sleeper(&mut exec, (policy, bounds), flood, (30, &subs), &log);
        let mut most = 0;
        for _ in 0..29 {
            exec.step();
            most = most.max(exec.agoras().next().unwrap().post_office().pending(s));
        }
        assert!(most > 8, "{policy}: Reliable messages wait beyond the capacity ({most})");
        exec.run_for(MS); // the sleeper reads
        let reports = exec.finish();
        let got = counts(&log, "s");
        assert_eq!(got, (1..=300).collect::<Vec<_>>(), "{policy}: every one, in order");
        let seen = whats(&log, "s");
        let status_after =
            |n: u32| seen.iter().position(|w| *w == format!("Count({n})")).unwrap() + 1;
        assert_eq!(seen[status_after(4)], "Status(at 4)", "{policy}: order across types");
        let r = report_of(&reports, "s");
        assert_eq!((r.dropped(), r.refused()), (0, 0), "{policy}");
    }
}

#[test]
fn past_the_reliable_limit_messages_are_refused_and_reported() {
    for policy in QUEUEING {
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let bounds = MailboxBounds::new(4).with_reliable_limit(10);
        let mut a = exec.agora_builder(1).policy(policy).mailbox_bounds(bounds).build().unwrap();
        let p = a.add_member(Flood::new(5, DeliveryWarranty::Reliable), Activation::Cyclic);
        let d = a.add_member(Deaf { status_bounds: None }, Activation::Periodic(SECOND));
        a.activate_member(p).unwrap();
        a.activate_member(d).unwrap();
        exec.add_agora(a).unwrap();
        exec.run_for(6 * MS); // 30 Reliable Counts
        assert_eq!(exec.agoras().next().unwrap().post_office().pending(d), 10, "{policy}");
        let reports = exec.finish();
        let deaf = report_of(&reports, "Deaf");
        let count = deaf.mailbox(Count::TYPE).copied().unwrap();
        assert_eq!((count.dropped, count.refused), (0, 20), "{policy}");
        assert_eq!(reports[0].refused(), 20, "{policy}");
    }
}

#[test]
fn a_refused_message_is_not_counted_as_delivered() {
    let mut a = Agora::builder(1)
        .mailbox_bounds(MailboxBounds::new(1).with_reliable_limit(2))
        .build()
        .unwrap();
    let tx = a.endpoint();
    let rx = a.endpoint();
    rx.subscribe_to::<Count>(RequestType::All);
    let sent: Vec<usize> =
        (1..=4).map(|n| tx.publish_with(Count(n), DeliveryWarranty::Reliable, 0)).collect();
    assert_eq!(sent, [1, 1, 0, 0]);
    // Best-effort messages never fail to be delivered: the oldest makes room (here the lane
    // carried Reliable messages, so past its limit the new one is dropped instead).
    assert_eq!(tx.publish(Count(5)), 1);
    assert_eq!(rx.pending(), 2);
    let report = rx.mailbox_reports();
    assert_eq!((report[0].dropped, report[0].refused), (1, 2));
}

#[test]
fn slwsm_counts_the_messages_it_replaces_as_dropped() {
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let mut a = exec.agora_builder(1).policy(PolicyKind::Slwsm).build().unwrap();
    let p = a.add_member(Flood::new(3, DeliveryWarranty::None), Activation::Cyclic);
    let d = a.add_member(Deaf { status_bounds: None }, Activation::Periodic(SECOND));
    a.activate_member(p).unwrap();
    a.activate_member(d).unwrap();
    exec.add_agora(a).unwrap();
    exec.run_for(10 * MS);
    assert_eq!(exec.agoras().next().unwrap().post_office().pending(d), 1);
    let deaf = report_of(&exec.finish(), "Deaf");
    let count = deaf.mailbox(Count::TYPE).copied().unwrap();
    assert_eq!((count.capacity, count.dropped), (1, 29));
}

#[test]
fn bounds_that_cannot_work_are_typed_errors() {
    let zero = Agora::builder(3).mailbox_bounds(MailboxBounds::new(0)).build();
    assert!(matches!(zero, Err(DcdtError::MailboxBounds { capacity: 0, .. })));
    let below = MailboxBounds::new(8).with_reliable_limit(4);
    let mut a = Agora::builder(4).build().unwrap();
    let ep = a.endpoint();
    let err = ep.subscribe_bounded(Count::TYPE, RequestType::All, below).unwrap_err();
    assert!(err.to_string().contains("capacity 8 and reliable_limit 4"), "{err}");
    assert!(!ep.has_subscribers(Count::TYPE), "nothing was subscribed");
}

#[test]
fn the_default_bounds_are_documented_values() {
    let a = Agora::standalone();
    let b = a.post_office().mailbox_bounds();
    assert_eq!((b.capacity, b.reliable_limit), (2048, 32_768));
    assert_eq!(b, MailboxBounds::default());
    assert_eq!(b.capacity, mrt_dcdt::DEFAULT_MAILBOX_CAPACITY);
    assert_eq!(b.reliable_limit, mrt_dcdt::DEFAULT_RELIABLE_LIMIT);
}

/// Real threads: a producer thread floods an endpoint nobody reads. Whatever the scheduling,
/// the buffer never holds more than its capacity, and every message is either waiting or
/// counted as dropped.
#[test]
fn threads_flooding_an_unread_mailbox_keep_it_bounded() {
    for policy in QUEUEING {
        let mut a = Agora::builder(1)
            .policy(policy)
            .mailbox_bounds(MailboxBounds::new(64))
            .build()
            .unwrap();
        let rx = a.endpoint();
        rx.subscribe_to::<Count>(RequestType::All);
        let producers: Vec<_> = (0..2).map(|_| a.endpoint()).collect();
        let rx = std::thread::scope(|s| {
            for tx in producers {
                s.spawn(move || {
                    for n in 0..20_000 {
                        tx.publish(Count(n));
                    }
                });
            }
            let watcher = s.spawn(move || {
                for _ in 0..1000 {
                    assert!(rx.pending() <= 64, "{policy}");
                }
                rx
            });
            watcher.join().unwrap()
        });
        assert!(a.post_office().pending(rx.member_id()) <= 64, "{policy}");
        if policy == PolicyKind::Slwdwcv {
            // Nothing runs its dispatcher here: messages wait in its main queue instead.
            continue;
        }
        assert_eq!(rx.pending(), 64, "{policy}");
        assert_eq!(rx.mailbox_reports()[0].dropped, 40_000 - 64, "{policy}");
    }
}

/// Real threads: two producers send `Reliable` messages faster than a slow reader takes them;
/// the reader gets every one, each producer's in the order it sent them.
#[test]
fn threads_sending_reliable_messages_lose_none_and_keep_each_producers_order() {
    const N: u32 = 5_000;
    // A small ring, and room for every message beyond it: nothing may be refused.
    let bounds = MailboxBounds::new(16).with_reliable_limit(2 * N as usize);
    let mut a = Agora::builder(1).mailbox_bounds(bounds).build().unwrap();
    let mut rx = a.endpoint();
    rx.subscribe_to::<Count>(RequestType::All);
    rx.subscribe_to::<Status>(RequestType::All);
    let tx1 = a.endpoint();
    let tx2 = a.endpoint();
    let mut got = Vec::new();
    std::thread::scope(|s| {
        s.spawn(move || {
            for n in 0..N {
                tx1.publish_with(Count(n), DeliveryWarranty::Reliable, 0);
            }
        });
        s.spawn(move || {
            for n in 0..N {
                tx2.publish_with(Status(n.to_string()), DeliveryWarranty::Reliable, 0);
            }
        });
        // Until every message arrived or (a failure) some were lost.
        let lost = |rx: &Endpoint| -> u64 {
            rx.mailbox_reports().iter().map(|m| m.dropped + m.refused).sum()
        };
        while got.len() as u64 + lost(&rx) < 2 * u64::from(N) {
            match rx.receive_msg() {
                Some(m) => got.push(describe(&m)),
                None => std::thread::yield_now(),
            }
        }
    });
    let ones: Vec<String> = got.iter().filter(|w| w.starts_with("Count")).cloned().collect();
    let twos: Vec<String> = got.iter().filter(|w| w.starts_with("Status")).cloned().collect();
    assert_eq!(ones, (0..N).map(|n| format!("Count({n})")).collect::<Vec<_>>());
    assert_eq!(twos, (0..N).map(|n| format!("Status({n})")).collect::<Vec<_>>());
    let r = rx.mailbox_reports();
    assert_eq!(r.iter().map(|m| m.dropped + m.refused).sum::<u64>(), 0);
}

/// Sends 100 messages in its first job, then shuts the Agora down.
struct Burst;
impl Member for Burst {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for n in 0..100 {
            ctx.publish(Count(n));
        }
        ctx.shutdown();
        Ok(())
    }
}

/// The threaded executor's `RunReport` carries the same per-subscription counts.
#[test]
fn lets_work_reports_the_drops_of_each_member() {
    let mut a = Agora::builder(1).mailbox_bounds(MailboxBounds::new(8)).build().unwrap();
    let p = a.add_member(Burst, Activation::Cyclic);
    let d = a.add_member(
        Deaf { status_bounds: None },
        Activation::Periodic(std::time::Duration::from_secs(3600)),
    );
    a.activate_member(p).unwrap();
    a.activate_member(d).unwrap();
    let report = a.lets_work().unwrap();
    let deaf = report.member(d).unwrap();
    assert_eq!(deaf.mailbox(Count::TYPE).map(|m| (m.capacity, m.dropped)), Some((8, 92)));
    assert_eq!(report.dropped(), 92);
    assert_eq!(report.member(p).unwrap().mailboxes, vec![], "it subscribed to nothing");
}

/// A larger bound, with a Member thousands of messages behind: the bound holds, and the newest
/// messages come out in order.
#[test]
fn a_large_bound_holds_and_keeps_the_order() {
    for policy in QUEUEING {
        let log = log();
        let mut exec = SteppedExecutor::new(SimClock::new(), MS);
        let flood = Flood::new(500, DeliveryWarranty::None);
        let subs = [(Count::TYPE, RequestType::All)];
        let bounds = MailboxBounds::new(3000);
        let s = flood_a_sleeper(&mut exec, (policy, bounds), flood, (10, &subs), &log);
        for _ in 0..9 {
            exec.step();
            assert!(exec.agoras().next().unwrap().post_office().pending(s) <= 3000, "{policy}");
        }
        exec.step(); // 5000 sent; the sleeper reads
        let reports = exec.finish();
        assert_eq!(counts(&log, "s"), (2001..=5000).collect::<Vec<_>>(), "{policy}");
        assert_eq!(report_of(&reports, "s").dropped(), 2000, "{policy}");
    }
}

/// A second subscription added while messages of the first wait: everything still comes out
/// in the order it arrived (under PMQ, a Member with one subscription numbers nothing; the
/// messages from before the second one are older than all of its).
#[test]
fn a_subscription_added_while_messages_wait_keeps_the_arrival_order() {
    for policy in QUEUEING {
        if policy == PolicyKind::Slwdwcv {
            continue; // delivers only through a dispatcher, which nothing runs here
        }
        let mut a = Agora::builder(1).policy(policy).build().unwrap();
        let tx = a.endpoint();
        let mut rx = a.endpoint();
        rx.subscribe_to::<Count>(RequestType::All);
        for n in 1..=3 {
            tx.publish(Count(n));
        }
        rx.subscribe_to::<Status>(RequestType::All);
        tx.publish(Status("a".into()));
        tx.publish(Count(4));
        tx.publish(Status("b".into()));
        assert_eq!(rx.pending(), 6, "{policy}");
        let got: Vec<String> =
            std::iter::from_fn(|| rx.receive_msg()).map(|m| describe(&m)).collect();
        assert_eq!(
            got,
            ["Count(1)", "Count(2)", "Count(3)", "Status(a)", "Count(4)", "Status(b)"],
            "{policy}"
        );
    }
}
