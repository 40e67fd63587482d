//! Blackboard hot paths: `get` of a float, `set` without and with a watcher, and a relay
//! GETV round trip over TCP on loopback.
#![allow(missing_docs, clippy::unwrap_used)]
use criterion::{criterion_group, criterion_main, Criterion};
use mrt_blackboard::Blackboard;
use std::hint::black_box;
use std::sync::Arc;

fn board() -> Blackboard {
    let bb = Blackboard::new(1, Arc::new(mrt_core::WallClock::new()));
    // A blackboard of realistic size: 200 symbols.
    for i in 0..200 {
        bb.set(&format!("local.var.module{}.value{i}", i % 10), i as f64).unwrap();
    }
    bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
    bb
}

fn bench(c: &mut Criterion) {
    let bb = board();
    c.bench_function("get_f64", |b| {
        b.iter(|| bb.get::<f64>(black_box("local.var.machine.config.def.near-ball")))
    });
    c.bench_function("set_f64_no_watcher", |b| {
        let mut x = 0.0;
        b.iter(|| {
            x += 1.0;
            bb.set(black_box("local.var.machine.config.def.near-ball"), x)
        })
    });
    let watch = bb.watch("local.var.machine.*").unwrap();
    c.bench_function("set_f64_with_watcher", |b| {
        let mut x = 0.0;
        let mut n = 0u32;
        b.iter(|| {
            x += 1.0;
            n += 1;
            if n % 512 == 0 {
                // The watcher keeps up, as a Member reading every cycle does.
                black_box(watch.drain());
            }
            bb.set(black_box("local.var.machine.config.def.near-ball"), x)
        })
    });
    drop(watch);
    // The relay over TCP on loopback: one GETV request and its reply.
    let cfg = mrt_blackboard::RelayConfig {
        addr: std::net::SocketAddr::from(([127, 0, 0, 1], 0)),
        ..Default::default()
    };
    let relay = mrt_blackboard::Relay::start(bb.clone(), cfg).unwrap();
    let mut client = mrt_blackboard::RelayClient::connect(relay.local_addr(), None).unwrap();
    c.bench_function("relay_getv_round_trip", |b| {
        b.iter(|| client.request(black_box("GETV local.var.machine.config.def.near-ball")).unwrap())
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().warm_up_time(std::time::Duration::from_millis(500)).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
