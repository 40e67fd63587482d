//! The threaded executor (`Agora::lets_work`): each Member on its own thread, end of run when
//! every Member terminated or on shutdown, every policy under real concurrency.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::{DcdtError, InnerLinkManager};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Receives `Count`s until it has seen `until`, then shuts the Agora down.
struct Collector {
    got: Arc<Mutex<Vec<u32>>>,
    until: u32,
    threads: Arc<Mutex<Vec<String>>>,
}
impl Member for Collector {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Count>(RequestType::All);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.threads.lock().unwrap().push(std::thread::current().name().unwrap_or("?").to_string());
        while let Some(m) = ctx.receive_msg() {
            let n = m.get::<Count>()?.0;
            self.got.lock().unwrap().push(n);
            if n == self.until {
                ctx.shutdown();
            }
        }
        Ok(())
    }
}

/// Never does anything by itself: its period is a minute. Shutdown must still end it at once.
struct Sleeper(Arc<Mutex<bool>>);
impl Member for Sleeper {
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Ok(())
    }
    fn close(&mut self, _ctx: &mut Context<'_>) {
        *self.0.lock().unwrap() = true;
    }
}

#[test]
fn every_policy_delivers_under_real_threads_and_shutdown_ends_everyone() {
    for policy in PolicyKind::ALL {
        let got = Arc::new(Mutex::new(Vec::new()));
        let threads = Arc::new(Mutex::new(Vec::new()));
        let closed = Arc::new(Mutex::new(false));
        let mut a = mrt_dcdt::Agora::builder(1).policy(policy).build().unwrap();
        let p = a.add_member(Producer::new(2000), Activation::Cyclic);
        let c = a.add_member(
            Collector { got: got.clone(), until: 2000, threads: threads.clone() },
            Activation::OnMessage,
        );
        let s =
            a.add_member(Sleeper(closed.clone()), Activation::Periodic(Duration::from_secs(60)));
        for id in [p, c, s] {
            a.activate_member(id).unwrap();
        }
        let start = Instant::now();
        let report = a.lets_work().unwrap();
        // Liveness, not performance: a minute-long period must not delay the shutdown.
        assert!(start.elapsed() < Duration::from_secs(20), "{policy}");
        assert_eq!(report.exit, ExitReason::Shutdown, "{policy}");
        assert!(*closed.lock().unwrap(), "{policy}: close ran");
        assert_eq!(report.member(s).unwrap().cycles, 1, "{policy}: ran once at start");
        let got = got.lock().unwrap();
        if policy == PolicyKind::Slwsm {
            // Latest-only: strictly increasing, ending with the last one.
            assert!(got.windows(2).all(|w| w[0] < w[1]), "{policy}");
            assert_eq!(got.last(), Some(&2000));
        } else {
            assert_eq!(*got, (1..=2000).collect::<Vec<_>>(), "{policy}");
        }
        assert!(
            threads.lock().unwrap().iter().all(|t| t == "mrt:Collector"),
            "{policy}: own thread"
        );
        assert!(report.members.iter().all(|m| m.state == MemberState::Terminated));
    }
}

#[test]
fn lets_work_returns_when_every_member_terminated() {
    let mut a = mrt_dcdt::Agora::standalone();
    let p1 = a.add_member(Producer::new(3), Activation::Periodic(Duration::from_millis(1)));
    let p2 = a.add_member(Producer::new(5), Activation::Cyclic);
    let idle = a.add_member(Producer::new(1), Activation::Cyclic); // added, never activated
    a.activate_member(p1).unwrap();
    a.activate_member(p2).unwrap();
    assert_eq!(a.member_state(p1).unwrap(), MemberState::Activated);
    assert_eq!(a.member_state(idle).unwrap(), MemberState::Added);
    assert_eq!(a.member_name(p1).unwrap(), "Producer");
    let report = a.lets_work().unwrap();
    assert_eq!(report.exit, ExitReason::AllTerminated);
    assert_eq!(report.members.len(), 2, "the inactive member did not run");
    assert_eq!(report.member(p1).unwrap().cycles, 3);
    assert_eq!(report.member(p2).unwrap().cycles, 5);
}

#[test]
fn ping_pong_between_two_agoras_on_threads() {
    /// Answers each remote Count n with Count n+1 up to `last`; the server serves once the
    /// other robot has subscribed.
    struct Player {
        got: Arc<Mutex<Vec<u32>>>,
        last: u32,
        serve: bool,
    }
    impl Member for Player {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.subscribe_to::<Count>(RequestType::Remote);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            if self.serve && ctx.has_subscribers(Count::TYPE) {
                self.serve = false;
                ctx.publish(Count(1));
            }
            while let Some(m) = ctx.receive_msg() {
                let n = m.get::<Count>()?.0;
                self.got.lock().unwrap().push(n);
                if n < self.last {
                    ctx.publish(Count(n + 1));
                }
                if n + 1 >= self.last {
                    ctx.terminate();
                }
            }
            Ok(())
        }
    }
    let got_a = Arc::new(Mutex::new(Vec::new()));
    let got_b = Arc::new(Mutex::new(Vec::new()));
    let ilm = InnerLinkManager::new();
    let mut a = mrt_dcdt::Agora::builder(1).inner_link(&ilm).build().unwrap();
    let mut b = mrt_dcdt::Agora::builder(2).inner_link(&ilm).build().unwrap();
    let pa =
        a.add_member(Player { got: got_a.clone(), last: 1000, serve: true }, Activation::Cyclic);
    let pb = b
        .add_member(Player { got: got_b.clone(), last: 1000, serve: false }, Activation::OnMessage);
    a.activate_member(pa).unwrap();
    b.activate_member(pb).unwrap();
    let tb = std::thread::spawn(move || b.lets_work());
    let ra = a.lets_work().unwrap();
    let rb = tb.join().unwrap().unwrap();
    assert_eq!(ra.exit, ExitReason::AllTerminated);
    assert_eq!(rb.exit, ExitReason::AllTerminated);
    // Each robot saw exactly the other's numbers, in order, each once.
    assert_eq!(*got_b.lock().unwrap(), (1..=999).step_by(2).collect::<Vec<_>>());
    assert_eq!(*got_a.lock().unwrap(), (2..=1000).step_by(2).collect::<Vec<_>>());
    assert_eq!(ra.member(pa).unwrap().errors + rb.member(pb).unwrap().errors, 0);
}

#[test]
fn executors_refuse_the_wrong_clock() {
    let a = mrt_dcdt::Agora::builder(1).clock(Arc::new(SimClock::new())).build().unwrap();
    assert!(matches!(a.lets_work(), Err(DcdtError::ClockMismatch { .. })));
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let err = exec.add_agora(mrt_dcdt::Agora::standalone()).unwrap_err();
    assert!(err.to_string().contains("simulated clock"), "{err}");
}

#[test]
fn one_community_cannot_have_two_agoras_with_one_id() {
    let ilm = InnerLinkManager::new();
    let _a = mrt_dcdt::Agora::builder(4).inner_link(&ilm).build().unwrap();
    assert!(matches!(
        mrt_dcdt::Agora::builder(4).inner_link(&ilm).build(),
        Err(DcdtError::DuplicateAgora(_))
    ));
    drop(_a);
    assert!(mrt_dcdt::Agora::builder(4).inner_link(&ilm).build().is_ok(), "a dropped Agora leaves");
}

#[test]
fn wait_msg_returns_only_with_a_message_or_at_its_timeout() {
    // A thread's park token can be left over from an earlier wake-up (a producer that saw the
    // consumer about to sleep): `wait_msg` used to return `false` at once then, long before its
    // timeout, and a caller took that for a lost message.
    let mut agora = mrt_dcdt::Agora::builder(1).build().unwrap();
    let mut ep = agora.endpoint();
    ep.subscribe_to::<Count>(RequestType::All);
    for round in 0..20u32 {
        let sender = agora.endpoint();
        std::thread::current().unpark(); // the stale token
        let s = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(2));
            sender.publish(Count(round));
        });
        assert!(
            ep.wait_msg(Duration::from_secs(10)),
            "round {round}: returned without the message"
        );
        assert_eq!(ep.receive_msg().unwrap().get::<Count>().unwrap().0, round);
        s.join().unwrap();
    }
    let t = Instant::now();
    std::thread::current().unpark();
    assert!(!ep.wait_msg(Duration::from_millis(20)));
    assert!(t.elapsed() >= Duration::from_millis(20), "{:?}", t.elapsed());
}

/// The waker's handshake (`PMQ` wakes without a fence after its `SeqCst` put): a ping-pong of
/// 20 000 round trips between an endpoint and an on-message Member, each side parking when it
/// has nothing to do, never loses a wake-up. A lost one would leave the Member asleep with a
/// message in its mailbox, and the endpoint's 5 s wait would come back empty.
#[test]
fn no_wake_up_is_lost_in_20_000_round_trips() {
    struct Echo;
    impl Member for Echo {
        fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            ctx.subscribe_to::<Count>(RequestType::Local);
            Ok(())
        }
        fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
            while let Some(m) = ctx.receive_msg() {
                let n = m.get::<Count>()?.0;
                ctx.publish(Status(n.to_string()));
            }
            Ok(())
        }
    }
    let mut agora = mrt_dcdt::Agora::builder(1).policy(PolicyKind::Pmq).build().unwrap();
    let echo = agora.add_member(Echo, Activation::OnMessage);
    agora.activate_member(echo).unwrap();
    let mut endpoint = agora.endpoint();
    endpoint.subscribe_to::<Status>(RequestType::Local);
    let stop = agora.shutdown_handle();
    let run = std::thread::spawn(move || agora.lets_work());
    while !endpoint.has_subscribers(Count::TYPE) {
        std::thread::sleep(Duration::from_millis(1));
    }
    for n in 0..20_000u32 {
        endpoint.publish(Count(n));
        let answer = loop {
            if let Some(m) = endpoint.receive_msg() {
                break m;
            }
            assert!(
                endpoint.wait_msg(Duration::from_secs(5)),
                "round trip {n}: a wake-up was lost"
            );
        };
        assert_eq!(answer.get::<Status>().unwrap().0, n.to_string());
    }
    stop.shutdown();
    let report = run.join().unwrap().unwrap();
    assert_eq!(report.member(echo).unwrap().errors, 0);
}
