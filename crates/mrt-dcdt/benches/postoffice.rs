//! PostOffice benchmarks: one-way latency (ping-pong / 2) and throughput 1→1 and 1→4, for
//! every policy, with a plain crossbeam-channel baseline in the same run.
//!
//! Run: `cargo bench -p mrt-dcdt --bench postoffice`. Results go to `docs/performance.md`.
//!
//! Setup, the same for MRT and the baseline: the producer is the benchmark thread; consumers
//! are threads woken by messages (MRT: on-message Members of an Agora running `lets_work`;
//! baseline: threads blocked in `Receiver::recv`). The payload is a 16-byte struct.
#![allow(missing_docs, clippy::unwrap_used, clippy::expect_used)]

use criterion::measurement::WallTime;
use criterion::{
    criterion_group, criterion_main, BenchmarkGroup, BenchmarkId, Criterion, Throughput,
};
use crossbeam_channel::{unbounded, Receiver, Sender};
use mrt_dcdt::prelude::*;
use mrt_dcdt::{Endpoint, MailboxBounds, ShutdownHandle};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

#[derive(Clone, Copy, Serialize, Deserialize)]
struct Sample {
    seq: u64,
    value: f64,
}
impl Message for Sample {
    const TYPE: MsgType = MsgType(1);
    const NAME: &'static str = "Sample";
}

#[derive(Clone, Copy, Serialize, Deserialize)]
struct Echo {
    seq: u64,
    value: f64,
}
impl Message for Echo {
    const TYPE: MsgType = MsgType(2);
    const NAME: &'static str = "Echo";
}

/// Members that finished `init` (subscribed) in the Agora being started.
static READY: AtomicUsize = AtomicUsize::new(0);

/// Answers each Sample with an Echo.
struct Ponger;
impl Member for Ponger {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Sample>(RequestType::All);
        READY.fetch_add(1, Ordering::AcqRel);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let s = m.get::<Sample>()?;
            ctx.publish(Echo { seq: s.seq, value: s.value });
        }
        Ok(())
    }
}

/// Records the highest sequence number seen. Its buffer holds a whole batch (a preallocated
/// ring of `BATCH` slots under PMQ), so that, like the unbounded baseline, it never loses a
/// message however far behind it falls within a batch (`Running` reports any loss).
struct Sink(Arc<AtomicU64>);
impl Member for Sink {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_bounded(Sample::TYPE, RequestType::All, MailboxBounds::new(BATCH as usize))?;
        READY.fetch_add(1, Ordering::AcqRel);
        Ok(())
    }
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut last = 0;
        while let Some(m) = ctx.receive_msg() {
            last = m.get::<Sample>()?.seq;
        }
        self.0.store(last, Ordering::Release);
        Ok(())
    }
}

struct Running {
    policy: PolicyKind,
    endpoint: Endpoint,
    stop: ShutdownHandle,
    thread: Option<JoinHandle<mrt_dcdt::RunReport>>,
}

impl Running {
    fn start(policy: PolicyKind, members: Vec<Box<dyn Member>>) -> Self {
        READY.store(0, Ordering::Release);
        let count = members.len();
        let mut agora = Agora::builder(1).policy(policy).build().unwrap();
        for m in members {
            let id = agora.add_boxed_member(m, Activation::OnMessage);
            agora.activate_member(id).unwrap();
        }
        let endpoint = agora.endpoint();
        let stop = agora.shutdown_handle();
        let thread = Some(std::thread::spawn(move || agora.lets_work().unwrap()));
        // Let every Member run init and subscribe. (Waiting for the first subscriber only, as
        // before, let a batch go out before a slow-starting consumer subscribed: it then never
        // saw that batch's last message and the run hung.)
        while READY.load(Ordering::Acquire) < count {
            std::thread::sleep(Duration::from_millis(1));
        }
        Self { policy, endpoint, stop, thread }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        self.stop.shutdown();
        if let Some(t) = self.thread.take() {
            // A throughput figure counts messages published: say if the consumers lost some
            // to their mailbox bounds (none may be lost for the figure to stand).
            let report = t.join().unwrap();
            if report.dropped() + report.refused() > 0 {
                eprintln!(
                    "{}: the consumers' mailboxes dropped {} and refused {} messages",
                    self.policy,
                    report.dropped(),
                    report.refused()
                );
            }
        }
    }
}

fn latency(c: &mut Criterion) {
    let mut g = c.benchmark_group("latency_one_way");
    for policy in PolicyKind::ALL {
        let mut run = Running::start(policy, vec![Box::new(Ponger)]);
        run.endpoint.subscribe_to::<Echo>(RequestType::All);
        g.bench_function(BenchmarkId::new("mrt", policy.name()), |b| {
            b.iter_custom(|iters| {
                let start = Instant::now();
                for seq in 0..iters {
                    run.endpoint.publish(Sample { seq, value: 1.0 });
                    loop {
                        if let Some(m) = run.endpoint.receive_msg() {
                            if m.get::<Echo>().ok().map(|e| e.seq) == Some(seq) {
                                break;
                            }
                        } else {
                            run.endpoint.wait_msg(Duration::from_millis(100));
                        }
                    }
                }
                start.elapsed() / 2
            })
        });
    }
    // Baseline: the same ping-pong over two crossbeam channels.
    let (to_pong, pong_rx): (Sender<Sample>, Receiver<Sample>) = unbounded();
    let (to_ping, ping_rx): (Sender<Echo>, Receiver<Echo>) = unbounded();
    let ponger = std::thread::spawn(move || {
        while let Ok(s) = pong_rx.recv() {
            if to_ping.send(Echo { seq: s.seq, value: s.value }).is_err() {
                break;
            }
        }
    });
    g.bench_function(BenchmarkId::new("crossbeam", "channel"), |b| {
        b.iter_custom(|iters| {
            let start = Instant::now();
            for seq in 0..iters {
                to_pong.send(Sample { seq, value: 1.0 }).unwrap();
                let e = ping_rx.recv().unwrap();
                assert_eq!(e.seq, seq);
            }
            start.elapsed() / 2
        })
    });
    drop(to_pong);
    ponger.join().unwrap();
    g.finish();
}

const BATCH: u64 = 100_000;

fn wait_all(seen: &[Arc<AtomicU64>], last: u64) {
    for s in seen {
        while s.load(Ordering::Acquire) < last {
            std::hint::spin_loop();
        }
    }
}

fn throughput(c: &mut Criterion) {
    for fanout in [1usize, 4] {
        let mut g = c.benchmark_group(format!("throughput_1to{fanout}"));
        g.throughput(Throughput::Elements(BATCH));
        for policy in PolicyKind::ALL {
            let seen: Vec<Arc<AtomicU64>> =
                (0..fanout).map(|_| Arc::new(AtomicU64::new(0))).collect();
            let run = Running::start(
                policy,
                seen.iter().map(|s| Box::new(Sink(s.clone())) as Box<dyn Member>).collect(),
            );
            let mut next = 1u64;
            g.bench_function(BenchmarkId::new("mrt", policy.name()), |b| {
                b.iter_custom(|iters| {
                    let start = Instant::now();
                    for _ in 0..iters {
                        for _ in 0..BATCH {
                            run.endpoint.publish(Sample { seq: next, value: 0.5 });
                            next += 1;
                        }
                        wait_all(&seen, next - 1);
                    }
                    start.elapsed()
                })
            });
        }
        // Baseline: one unbounded crossbeam channel per consumer; the producer sends a copy
        // into each.
        crossbeam_baseline(&mut g, "channel", fanout, |seq| Sample { seq, value: 0.5 }, |m| m.seq);
        // Second baseline: the same channels carrying what a bus must pass, one shared,
        // reference-counted message per publish (`Arc`), as DCDT shares a message among its
        // subscribers.
        crossbeam_baseline(
            &mut g,
            "shared",
            fanout,
            |seq| Arc::new(Sample { seq, value: 0.5 }),
            |m| m.seq,
        );
        g.finish();
    }
}

/// A crossbeam baseline of throughput: one unbounded channel per consumer (a thread blocked in
/// `recv`); each publish builds one value with `make` and sends a clone into every channel.
fn crossbeam_baseline<T: Clone + Send + 'static>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    fanout: usize,
    make: impl Fn(u64) -> T,
    seq: fn(&T) -> u64,
) {
    let seen: Vec<Arc<AtomicU64>> = (0..fanout).map(|_| Arc::new(AtomicU64::new(0))).collect();
    let mut senders = Vec::new();
    let mut threads = Vec::new();
    for s in &seen {
        let (tx, rx) = unbounded::<T>();
        senders.push(tx);
        let s = s.clone();
        threads.push(std::thread::spawn(move || {
            while let Ok(m) = rx.recv() {
                s.store(seq(&m), Ordering::Release);
            }
        }));
    }
    let mut next = 1u64;
    g.bench_function(BenchmarkId::new("crossbeam", name), |b| {
        b.iter_custom(|iters| {
            let start = Instant::now();
            for _ in 0..iters {
                for _ in 0..BATCH {
                    let m = make(next);
                    for tx in &senders {
                        tx.send(m.clone()).unwrap();
                    }
                    next += 1;
                }
                wait_all(&seen, next - 1);
            }
            start.elapsed()
        })
    });
    drop(senders);
    for t in threads {
        t.join().unwrap();
    }
}

fn unsubscribed(c: &mut Criterion) {
    let mut agora = Agora::standalone();
    let endpoint = agora.endpoint();
    let mut seq = 0;
    c.bench_function("publish_with_no_subscriber", |b| {
        b.iter(|| {
            seq += 1;
            endpoint.publish(Sample { seq, value: 0.0 })
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    targets = latency, throughput, unsubscribed
}
criterion_main!(benches);
