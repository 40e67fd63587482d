//! Two Agoras, each with its own zenoh session, on loopback in one test process (as far as
//! zenoh is concerned they are two processes): discovery, interest-based sending, the three
//! subscription kinds, headers across, malformed frames.
#![allow(clippy::unwrap_used)]

use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::{AgoraId, MemberId, Time};
use mrt_net::{NetConfig, NetLink};
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Ping(u32);
impl Message for Ping {
    const TYPE: MsgType = MsgType(901);
    const NAME: &'static str = "Ping";
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
struct Unwanted(u32);
impl Message for Unwanted {
    const TYPE: MsgType = MsgType(902);
    const NAME: &'static str = "Unwanted";
}

struct Pinger(u32);
impl Member for Pinger {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.0 += 1;
        ctx.publish_with(Ping(self.0), DeliveryWarranty::Reliable, 200);
        ctx.publish(Unwanted(self.0));
        Ok(())
    }
}

type Log = Arc<Mutex<Vec<(u32, AgoraId, MemberId, u8)>>>;

struct Listener(Log, RequestType);
impl Member for Listener {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Ping>(self.1);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let p = m.get::<Ping>()?;
            self.0.lock().unwrap().push((
                p.0,
                m.agora_id(),
                m.header().member_id,
                m.header().priority,
            ));
        }
        Ok(())
    }
}

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

#[test]
fn messages_cross_between_two_sessions_only_where_wanted() {
    let tick = Duration::from_millis(10);
    let (p1, p2) = (free_port(), free_port());
    // Agora 1: a pinger (member 0) and a Local listener (member 1).
    let mut one = SteppedExecutor::new(SimClock::new(), tick);
    let mut a = one.agora_builder(1).build().unwrap();
    let local1: Log = Arc::default();
    let m = a.add_member(Pinger(0), Activation::Periodic(tick));
    a.activate_member(m).unwrap();
    let m = a.add_member(Listener(local1.clone(), RequestType::Local), Activation::OnMessage);
    a.activate_member(m).unwrap();
    let link1 = NetLink::attach(&a, &NetConfig::loopback(p1, &[])).unwrap();
    one.add_agora(a).unwrap();
    // Agora 2: Remote, Local and All listeners.
    let mut two = SteppedExecutor::new(SimClock::new(), tick);
    let mut b = two.agora_builder(2).build().unwrap();
    let (remote, local, all): (Log, Log, Log) = Default::default();
    for (log, kind) in
        [(&remote, RequestType::Remote), (&local, RequestType::Local), (&all, RequestType::All)]
    {
        let m = b.add_member(Listener(log.clone(), kind), Activation::OnMessage);
        b.activate_member(m).unwrap();
    }
    let link2 = NetLink::attach(&b, &NetConfig::loopback(p2, &[p1])).unwrap();
    two.add_agora(b).unwrap();
    two.run_for(tick); // the listeners subscribe
                       // Finder: each sees the other; 1 learns that 2 wants Ping (not Unwanted).
    assert!(
        link1.wait_until(Duration::from_secs(5), |l| l.agoras() == [AgoraId(2)]),
        "{:?}",
        link1.agoras()
    );
    assert!(link2.wait_until(Duration::from_secs(5), |l| l.agoras() == [AgoraId(1)]));
    assert!(link1.wait_until(Duration::from_secs(5), |l| l.remote_wants(Ping::TYPE)));
    assert!(!link1.remote_wants(Unwanted::TYPE));
    assert_eq!(
        (link1.subscribers(Ping::TYPE), link1.subscribers(Unwanted::TYPE)),
        (vec![AgoraId(2)], vec![])
    );
    assert!(
        link2.receives(Ping::TYPE) && !link1.receives(Ping::TYPE),
        "1 has only a Local listener"
    );
    for _ in 0..20 {
        one.run_for(tick);
        std::thread::sleep(Duration::from_millis(5));
        two.run_for(tick);
    }
    assert!(link2.wait_until(Duration::from_secs(5), |l| l.stats().delivered >= 20));
    two.run_for(tick);
    let got = remote.lock().unwrap().clone();
    assert_eq!(got.len(), 20, "{got:?}");
    assert_eq!(
        got.iter().map(|g| g.0).collect::<Vec<_>>(),
        (1..=20).collect::<Vec<_>>(),
        "in order (reliable)"
    );
    assert!(
        got.iter().all(|g| g.1 == AgoraId(1) && g.2 == MemberId(0) && g.3 == 200),
        "header across: {:?}",
        got[0]
    );
    assert_eq!(all.lock().unwrap().len(), 20, "All takes remote messages too");
    assert!(local.lock().unwrap().is_empty(), "Local never takes another Agora's messages");
    assert_eq!(local1.lock().unwrap().len(), 20, "the pinger's own Agora: Local");
    let s1 = link1.stats();
    assert_eq!(s1.sent, 20, "Pings only: nobody wants Unwanted {s1:?}");
    let s2 = link2.stats();
    assert_eq!((s2.delivered, s2.malformed, s2.unwanted, s2.duplicates), (20, 0, 0, 0));
}

#[test]
fn malformed_and_unknown_frames_are_counted_and_dropped() {
    let tick = Duration::from_millis(10);
    let port = free_port();
    let mut two = SteppedExecutor::new(SimClock::new(), tick);
    let mut b = two.agora_builder(2).build().unwrap();
    let log: Log = Arc::default();
    let m = b.add_member(Listener(log.clone(), RequestType::All), Activation::OnMessage);
    b.activate_member(m).unwrap();
    let link = NetLink::attach(&b, &NetConfig::loopback(port, &[])).unwrap();
    two.add_agora(b).unwrap();
    two.run_for(tick);
    assert!(link.wait_until(Duration::from_secs(5), |l| l.receives(Ping::TYPE)));
    // A raw zenoh peer sends garbage, an oversized announcement, and a good frame of a type
    // nobody here knows (a newer peer), then a good Ping.
    let mut cfg = NetConfig::loopback(free_port(), &[port]).zenoh_config().unwrap();
    cfg.insert_json5("mode", "\"peer\"").unwrap();
    use zenoh::Wait;
    let raw = zenoh::open(cfg).wait().unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let key = format!("mrt/m/{}", Ping::TYPE.0);
    raw.put(&key, b"garbage".to_vec()).wait().unwrap();
    let mut huge = mrt_dcdt::wire::MAGIC.to_vec();
    huge.extend_from_slice(&[1, 0, 0, 0]);
    huge.extend_from_slice(&Ping::TYPE.0.to_le_bytes());
    huge.extend_from_slice(&[0; 16]);
    huge.extend_from_slice(&u32::MAX.to_le_bytes());
    raw.put(&key, mrt_net::envelope(9, 0, &huge)).wait().unwrap();
    let stranger = mrt_dcdt::Msg::new(
        mrt_dcdt::MsgHeader {
            msg_type: MsgType(999),
            member_id: MemberId(0),
            agora_id: AgoraId(7),
            priority: 0,
            warranty: DeliveryWarranty::None,
            creation_time: Time(1),
        },
        mrt_dcdt::RawPayload::new(vec![1, 2, 3]),
    )
    .into_ref();
    let stranger_frame = mrt_dcdt::wire::encode(&stranger).unwrap();
    raw.put(&key, mrt_net::envelope(9, 1, &stranger_frame)).wait().unwrap();
    let ping = mrt_dcdt::Msg::new(
        mrt_dcdt::MsgHeader { msg_type: Ping::TYPE, ..*stranger.header() },
        mrt_dcdt::RawPayload::new(vec![42]),
    )
    .into_ref();
    let frame = mrt_net::envelope(9, 2, &mrt_dcdt::wire::encode(&ping).unwrap());
    raw.put(&key, frame.clone()).wait().unwrap();
    raw.put(&key, frame).wait().unwrap(); // the same send again: a duplicate
    assert!(link.wait_until(Duration::from_secs(5), |l| l.stats().delivered == 1
        && l.stats().duplicates == 1));
    two.run_for(tick);
    let s = link.stats();
    assert_eq!((s.malformed, s.unwanted), (2, 1), "{s:?}");
    assert_eq!(log.lock().unwrap().clone(), vec![(42, AgoraId(7), MemberId(0), 0)]);
    raw.close().wait().unwrap();
}

/// Two sends of the same message content (same header, same time on a clock that stands
/// still, same payload) are two messages, not a duplicate: a burst of 100 arrives whole.
#[test]
fn identical_messages_sent_twice_arrive_twice() {
    let tick = Duration::from_millis(10);
    let (p1, p2) = (free_port(), free_port());
    let mut two = SteppedExecutor::new(SimClock::new(), tick);
    let mut b = two.agora_builder(2).build().unwrap();
    let log: Log = Arc::default();
    let m = b.add_member(Listener(log.clone(), RequestType::Remote), Activation::OnMessage);
    b.activate_member(m).unwrap();
    let link2 = NetLink::attach(&b, &NetConfig::loopback(p2, &[p1])).unwrap();
    two.add_agora(b).unwrap();
    two.run_for(tick);
    let frozen = Arc::new(SimClock::new());
    let mut a = mrt_dcdt::Agora::builder(1).clock(frozen).build().unwrap();
    let ep = a.endpoint();
    let link1 = NetLink::attach(&a, &NetConfig::loopback(p1, &[])).unwrap();
    assert!(link1.wait_until(Duration::from_secs(5), |l| l.remote_wants(Ping::TYPE)));
    for _ in 0..100 {
        ep.publish_with(Ping(7), DeliveryWarranty::Reliable, 0);
    }
    assert!(
        link2.wait_until(Duration::from_secs(5), |l| l.stats().delivered == 100),
        "{:?}",
        link2.stats()
    );
    two.run_for(tick);
    assert_eq!(log.lock().unwrap().len(), 100);
    assert_eq!(link2.stats().duplicates, 0);
}
