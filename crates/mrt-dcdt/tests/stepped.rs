//! Stepped-executor life cycle: Agoras added while running, terminating from `init`.

#![allow(clippy::unwrap_used)]

mod common;

use common::*;
use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Arc;

/// Counts its inits and closes; terminates in `init` when asked to.
struct Lifecycle {
    inits: Arc<AtomicU32>,
    closes: Arc<AtomicU32>,
    quit_in_init: bool,
}
impl Member for Lifecycle {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.inits.fetch_add(1, Ordering::SeqCst);
        if self.quit_in_init {
            ctx.terminate();
        }
        Ok(())
    }
    fn do_your_job(&mut self, _ctx: &mut Context<'_>) -> Result<(), MemberError> {
        Ok(())
    }
    fn close(&mut self, _ctx: &mut Context<'_>) {
        self.closes.fetch_add(1, Ordering::SeqCst);
    }
}

fn counters() -> (Arc<AtomicU32>, Arc<AtomicU32>) {
    (Arc::new(AtomicU32::new(0)), Arc::new(AtomicU32::new(0)))
}

#[test]
fn adding_an_agora_later_does_not_init_the_running_ones_again() {
    let (inits, closes) = counters();
    let mut exec = SteppedExecutor::new(SimClock::new(), MS);
    let mut a = exec.agora_builder(1).build().unwrap();
    let m = a.add_member(
        Lifecycle { inits: inits.clone(), closes: closes.clone(), quit_in_init: false },
        Activation::Periodic(10 * MS),
    );
    a.activate_member(m).unwrap();
    exec.add_agora(a).unwrap();
    exec.run_for(50 * MS);
    let mut b = exec.agora_builder(2).build().unwrap();
    let p = b.add_member(Producer::new(0), Activation::Periodic(10 * MS));
    b.activate_member(p).unwrap();
    exec.add_agora(b).unwrap();
    exec.run_for(50 * MS);
    let reports = exec.finish();
    assert_eq!(inits.load(Ordering::SeqCst), 1);
    assert_eq!(closes.load(Ordering::SeqCst), 1);
    assert_eq!(reports[0].members[0].cycles, 10);
    // The late Agora starts at 50 ms: runs at 50, 60, ..., 90.
    assert_eq!(reports[1].members[0].cycles, 5);
}

#[test]
fn terminate_in_init_closes_without_a_job() {
    for threaded in [false, true] {
        let (inits, closes) = counters();
        let member = Lifecycle { inits: inits.clone(), closes: closes.clone(), quit_in_init: true };
        let report = if threaded {
            let mut a = mrt_dcdt::Agora::standalone();
            let m = a.add_member(member, Activation::OnMessage);
            a.activate_member(m).unwrap();
            a.lets_work().unwrap()
        } else {
            let mut exec = SteppedExecutor::new(SimClock::new(), MS);
            let mut a = exec.agora_builder(1).build().unwrap();
            let m = a.add_member(member, Activation::OnMessage);
            a.activate_member(m).unwrap();
            exec.add_agora(a).unwrap();
            exec.run_for(10 * MS);
            assert!(!exec.is_running(), "the only Member terminated");
            exec.finish().remove(0)
        };
        assert_eq!(report.exit, ExitReason::AllTerminated, "threaded={threaded}");
        assert_eq!(report.members[0].cycles, 0);
        assert_eq!((inits.load(Ordering::SeqCst), closes.load(Ordering::SeqCst)), (1, 1));
    }
}
