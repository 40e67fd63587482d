//! Drawing an HFSM as SVG: the 200-state machine of the tests (`mrt hfsm dot --svg` took 91 s
//! on such a machine with a general graph layout; the goal is under a second).

#![allow(clippy::unwrap_used, missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion};
use mrt_script::chaos::{install, RobotIo};
use mrt_script::hfsm::Hfsm;
use mrt_script::{LuaRuntime, Sandbox};
use std::cell::RefCell;
use std::rc::Rc;

fn drawing(c: &mut Criterion) {
    let rt = LuaRuntime::new(Sandbox::default()).unwrap();
    let io = Rc::new(RefCell::new(RobotIo::default()));
    install(&rt, io.clone()).unwrap();
    let source = include_str!("../tests/data/chain200.hfsm.lua");
    let hfsm = Hfsm::from_source(&rt, "chain200.hfsm.lua", source, io).unwrap();
    c.bench_function("hfsm_to_svg_200_states", |b| b.iter(|| hfsm.to_svg().len()));
}

criterion_group!(benches, drawing);
criterion_main!(benches);
