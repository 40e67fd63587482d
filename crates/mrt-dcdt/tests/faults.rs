//! Fault isolation: a Member that panics is caught, reported and restarted (`init` again)
//! with a growing backoff, while the other Members keep their rate.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Panics in every 3rd job; counts its inits.
struct Flaky {
    jobs: u32,
    inits: Arc<AtomicU32>,
}
impl Member for Flaky {
    fn init(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inits.fetch_add(1, Ordering::SeqCst);
        Ok(())
    }
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.jobs += 1;
        if self.jobs % 3 == 0 {
            panic!("flaky member fell over at job {}", self.jobs);
        }
        Ok(())
    }
}

/// Always panics.
struct Broken;
impl Member for Broken {
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        panic!("broken member");
    }
}

/// Fails to init twice, then works.
struct SlowStart(u32);
impl Member for SlowStart {
    fn init(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.0 += 1;
        if self.0 < 3 {
            return Err(format!("device not ready (attempt {})", self.0).into());
        }
        Ok(())
    }
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Ok(())
    }
}

/// Returns an error from every job: reported and counted, not restarted.
struct Grumpy;
impl Member for Grumpy {
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Err("sensor value out of range".into())
    }
}

#[test]
fn stepped_panicking_member_restarts_with_backoff_and_others_keep_their_rate() {
    let inits = Arc::new(AtomicU32::new(0));
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let mut a = exec.agora_builder(1).build().unwrap();
    let steady = a.add_member(Producer::new(0), Activation::Periodic(10 * MS));
    let flaky =
        a.add_member(Flaky { jobs: 0, inits: inits.clone() }, Activation::Periodic(10 * MS));
    let broken = a.add_member(Broken, Activation::Cyclic);
    let slow = a.add_member(SlowStart(0), Activation::Periodic(10 * MS));
    let grumpy = a.add_member(Grumpy, Activation::Periodic(100 * MS));
    for id in [steady, flaky, broken, slow, grumpy] {
        a.activate_member(id).unwrap();
    }
    exec.add_agora(a).unwrap();
    exec.run_for(Duration::from_secs(2));
    let report = exec.finish().remove(0);

    // The steady producer ran at 0, 10, ..., 1990 ms: exactly 200 cycles, crashes elsewhere
    // notwithstanding.
    assert_eq!(report.member(steady).unwrap().cycles, 200);
    assert_eq!(report.member(steady).unwrap().panics, 0);

    // Flaky: ok at 0 and 10 ms, panics at 20; backs off 10 ms (a success in between resets
    // the backoff), inits again and runs at 30, 40, panics at 50... Panics at 20 + 30k ms for
    // k = 0..=65 (66 panics), and the other 134 of the 200 slots are good cycles.
    let f = report.member(flaky).unwrap();
    assert_eq!((f.panics, f.restarts, f.cycles), (66, 66, 134), "{f:?}");
    assert_eq!(inits.load(Ordering::SeqCst), 67);

    // Broken panics every time: backoff doubles 10, 20, 40, ... up to 1 s, so in 2 s it is
    // restarted only a handful of times instead of 2000.
    // Crashes at 0, 10, 30, 70, 150, 310, 630, 1270 ms (each after 10·2^k ms), then 2270 > 2000.
    let b = report.member(broken).unwrap();
    assert_eq!(b.panics, 8, "{b:?}");
    assert_eq!(b.cycles, 0);

    // SlowStart: init fails at 0 ms and 10 ms (backoff 10, then 20), succeeds at 30 ms; then it
    // runs every 10 ms from 30 to 1990: 197 cycles.
    let s = report.member(slow).unwrap();
    assert_eq!(s.restarts, 2);
    assert_eq!(s.cycles, 197);

    // Errors are counted, the Member keeps running.
    let g = report.member(grumpy).unwrap();
    assert_eq!((g.cycles, g.errors, g.restarts), (20, 20, 0));
    assert!(report.members.iter().all(|m| m.state == MemberState::Terminated));
}

#[test]
fn threaded_panicking_member_is_isolated_and_the_agora_keeps_running() {
    let log = log();
    let mut a = mrt_dcdt::Agora::standalone();
    let inits = Arc::new(AtomicU32::new(0));
    let producer = a.add_member(Producer::new(200), Activation::Periodic(Duration::from_millis(1)));
    let flaky = a.add_member(
        Flaky { jobs: 0, inits: inits.clone() },
        Activation::Periodic(Duration::from_millis(1)),
    );
    let rec = a.add_member(
        Recorder::new("rec", &[(Count::TYPE, RequestType::All)], &log),
        Activation::OnMessage,
    );
    for id in [producer, flaky, rec] {
        a.activate_member(id).unwrap();
    }
    let stop = a.shutdown_handle();
    // Stop once the producer has published all 200 counts and the recorder has them.
    let watcher = {
        let log = log.clone();
        std::thread::spawn(move || {
            let deadline = std::time::Instant::now() + Duration::from_secs(30);
            while log.lock().unwrap().len() < 200 && std::time::Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(5));
            }
            stop.shutdown();
        })
    };
    let report = a.lets_work().unwrap();
    watcher.join().unwrap();
    assert_eq!(report.exit, ExitReason::Shutdown);
    // Every message arrived, in order, although a neighbour kept crashing.
    let got = whats(&log, "rec");
    assert_eq!(got.len(), 200);
    assert_eq!(got[199], "Count(200)");
    let f = report.member(flaky).unwrap();
    assert!(f.panics >= 1, "{f:?}");
    assert_eq!(inits.load(Ordering::SeqCst) as u64, 1 + f.restarts);
    assert_eq!(report.member(producer).unwrap().cycles, 200);
}
