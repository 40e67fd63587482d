//! Two Agoras in two processes over zenoh on loopback, against a plain zenoh
//! publisher/subscriber pair on the same sessions, in the same run, for 64-byte and 1 KiB
//! payloads, both with the QoS of a `Reliable` DCDT message (zenoh's congestion control
//! *block*, batched). The other process is `mrt-net-node --echo`. Each MRT iteration is
//! followed by an untimed raw one and the other way round ([`compare`]), so that the two
//! sides of a ratio are measured under the same load.
//!
//! - `round_trip`: one probe, wait for its echo (latency).
//! - `stream`: 1000 messages one way, then the receiver's single acknowledgement
//!   (throughput: how many messages a second one Agora delivers to another). The raw side
//!   counts in zenoh's receive callback.
//! - `stream_thread`: the same stream against zenoh's default subscriber, its FIFO channel
//!   received on a thread of the application's own, as a Member's thread receives its mailbox.
//! - `echo_window`: 100 probes in flight, then their 100 echoes (request/response throughput;
//!   here every message crosses a Member's thread on the far side, while the raw echo answers
//!   in zenoh's receive callback).
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mrt_dcdt::prelude::*;
use mrt_net::probe::{flood_payload, Echo, Flood, Probe};
use mrt_net::{NetConfig, NetLink};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};
use zenoh::Wait;

const WINDOW: u64 = 100;
const STREAM: u32 = 1000;

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn bench(c: &mut Criterion) {
    let (p1, p2) = (free_port(), free_port());
    let mut agora = mrt_dcdt::Agora::builder(1).build().unwrap();
    let mut ep = agora.endpoint();
    ep.subscribe_to::<Echo>(RequestType::Remote);
    let link = NetLink::attach(&agora, &NetConfig::loopback(p1, &[])).unwrap();
    let node = env!("CARGO_BIN_EXE_mrt-net-node");
    let (p1s, p2s) = (p1.to_string(), p2.to_string());
    let mut echo = Command::new(node)
        .args(["--id", "2", "--listen", &p2s, "--connect", &p1s, "--echo", "--seconds", "3600"])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut ready = String::new();
    BufReader::new(echo.stdout.take().unwrap()).read_line(&mut ready).unwrap();
    assert!(link.wait_until(Duration::from_secs(10), |l| l.remote_wants(Probe::TYPE)));
    // Raw zenoh on the same session.
    let session = link.session().clone();
    // Both paths with the QoS of a Reliable DCDT message: block when congested, batched.
    let raw_pub = session
        .declare_publisher("raw/ping")
        .congestion_control(zenoh::qos::CongestionControl::Block)
        .wait()
        .unwrap();
    let (tx, rx) = std::sync::mpsc::channel::<usize>();
    let _raw_sub = session
        .declare_subscriber("raw/pong")
        .callback(move |s| {
            let _ = tx.send(s.payload().len());
        })
        .wait()
        .unwrap();
    // Warm both paths up.
    loop {
        raw_pub.put(vec![0u8; 8]).wait().unwrap();
        if rx.recv_timeout(Duration::from_millis(100)).is_ok() {
            break;
        }
    }
    ep.publish_with(Probe(vec![0; 8]), DeliveryWarranty::Reliable, 0);
    assert!(ep.wait_msg(Duration::from_secs(5)) && ep.receive_msg().is_some(), "no echo");

    let stats = || link.stats();
    let mrt_round = |ep: &mut mrt_dcdt::Endpoint, payload: &[u8], n: u64| {
        for _ in 0..n {
            ep.publish_with(Probe(payload.to_vec()), DeliveryWarranty::Reliable, 0);
        }
        let mut got = 0;
        while got < n {
            while ep.receive_msg().is_some() {
                got += 1;
            }
            if got < n {
                assert!(
                    ep.wait_msg(Duration::from_secs(5)),
                    "echo lost: {got} of {n}, {:?}",
                    stats()
                );
            }
        }
    };
    let raw_round = |payload: &[u8], n: u64| {
        for _ in 0..n {
            raw_pub.put(payload.to_vec()).wait().unwrap();
        }
        for _ in 0..n {
            rx.recv_timeout(Duration::from_secs(5)).expect("echo lost");
        }
    };
    let mrt_stream = |ep: &mut mrt_dcdt::Endpoint, payload: &[u8]| {
        for _ in 0..STREAM {
            ep.publish_with(Flood(payload.to_vec()), DeliveryWarranty::Reliable, 0);
        }
        while ep.receive_msg().is_none() {
            assert!(ep.wait_msg(Duration::from_secs(5)), "no acknowledgement, {:?}", stats());
        }
    };
    // A raw stream on `key`: counted in the far side's receive callback (`raw/flood`) or on a
    // thread of its own behind zenoh's FIFO channel (`raw/flood_fifo`).
    let raw_publisher = |key: &'static str| {
        session
            .declare_publisher(key)
            .congestion_control(zenoh::qos::CongestionControl::Block)
            .wait()
            .unwrap()
    };
    let (raw_flood, raw_fifo) = (raw_publisher("raw/flood"), raw_publisher("raw/flood_fifo"));
    let raw_stream = |publisher: &zenoh::pubsub::Publisher<'_>, payload: &[u8]| {
        for _ in 0..STREAM {
            publisher.put(payload.to_vec()).wait().unwrap();
        }
        rx.recv_timeout(Duration::from_secs(5)).expect("no acknowledgement");
    };
    for size in [64usize, 1024] {
        let payload = vec![7u8; size];
        let flood = flood_payload(STREAM, size);
        let ep = std::cell::RefCell::new(&mut ep);
        compare(
            c,
            &format!("round_trip_{size}B"),
            size,
            1,
            &mut || mrt_round(&mut ep.borrow_mut(), &payload, 1),
            &mut || raw_round(&payload, 1),
        );
        compare(
            c,
            &format!("stream_{size}B"),
            size,
            STREAM.into(),
            &mut || mrt_stream(&mut ep.borrow_mut(), &flood),
            &mut || raw_stream(&raw_flood, &flood),
        );
        compare(
            c,
            &format!("stream_thread_{size}B"),
            size,
            STREAM.into(),
            &mut || mrt_stream(&mut ep.borrow_mut(), &flood),
            &mut || raw_stream(&raw_fifo, &flood),
        );
        compare(
            c,
            &format!("echo_window_{size}B"),
            size,
            WINDOW,
            &mut || mrt_round(&mut ep.borrow_mut(), &payload, WINDOW),
            &mut || raw_round(&payload, WINDOW),
        );
    }
    let _ = echo.kill();
    let _ = echo.wait();
    drop(agora);
}

/// One comparison: `mrt` and `zenoh` each timed with the other run (untimed) right after every
/// iteration, so that both see the same load on this machine over the same minutes (timed one
/// after the other, a drift in the machine's load showed up as a 15 % difference either way).
fn compare(
    c: &mut Criterion,
    group: &str,
    size: usize,
    elements: u64,
    mrt: &mut dyn FnMut(),
    raw: &mut dyn FnMut(),
) {
    fn timed_beside(iters: u64, timed: &mut dyn FnMut(), beside: &mut dyn FnMut()) -> Duration {
        let mut total = Duration::ZERO;
        for _ in 0..iters {
            let t = Instant::now();
            timed();
            total += t.elapsed();
            beside();
        }
        total
    }
    let mut g = c.benchmark_group(group);
    if elements > 1 {
        g.throughput(Throughput::Elements(elements));
    }
    g.bench_function(BenchmarkId::new("mrt", size), |b| {
        b.iter_custom(|n| timed_beside(n, &mut *mrt, &mut *raw))
    });
    g.bench_function(BenchmarkId::new("zenoh", size), |b| {
        b.iter_custom(|n| timed_beside(n, &mut *raw, &mut *mrt))
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).warm_up_time(Duration::from_millis(500)).measurement_time(Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
