//! # 01 — Hello, Agora
//!
//! What you learn: an Agora hosting two Members on their own threads — a **periodic** producer
//! and an **on-message** consumer woken by each message — a typed message, and a clean
//! shutdown requested by a Member.
//!
//! Run: `cargo run -p mrt-examples --example 01_hello_agora` (or `mrt demo`).

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_dcdt::prelude::*;
use mrt_dcdt::{DcdtError, RunReport};
use serde::{Deserialize, Serialize};
use std::time::Duration;

/// The message: a numbered greeting. Its type id is declared once, here.
#[derive(Debug, Serialize, Deserialize)]
pub struct Greeting {
    /// Sequence number, from 1.
    pub n: u32,
    /// The text.
    pub text: String,
}

impl Message for Greeting {
    const TYPE: MsgType = MsgType(1);
    const NAME: &'static str = "Greeting";
}

/// Publishes `count` greetings, one per period, then terminates.
pub struct Greeter {
    sent: u32,
    count: u32,
    verbose: bool,
}

impl Member for Greeter {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.sent += 1;
        let reached = ctx.publish(Greeting { n: self.sent, text: format!("hello #{}", self.sent) });
        if self.verbose {
            println!(
                "[{}] Greeter   sent greeting {} to {reached} subscriber(s)",
                ctx.now(),
                self.sent
            );
        }
        if self.sent == self.count {
            ctx.terminate(); // TERMINATING: close() runs, this Member is done
        }
        Ok(())
    }
}

/// Subscribes to greetings in `init`, and is woken for each one; shuts the Agora down after
/// the last.
pub struct Listener {
    expected: u32,
    verbose: bool,
}

impl Member for Listener {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Greeting>(RequestType::All);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(msg) = ctx.receive_msg() {
            let g = msg.get::<Greeting>()?; // typed: no cast, no copy
            let latency = ctx.now() - msg.creation_time();
            if self.verbose {
                println!(
                    "[{}] Listener  got \"{}\" from {} of {} ({:?} after it was created)",
                    ctx.now(),
                    g.text,
                    msg.member_id(),
                    msg.agora_id(),
                    latency
                );
            }
            if g.n == self.expected {
                ctx.shutdown(); // every Member ends within its current cycle
            }
        }
        Ok(())
    }

    fn close(&mut self, _ctx: &mut Context<'_>) {
        if self.verbose {
            println!("Listener  closing");
        }
    }
}

/// Builds the Agora and lets it work until the Listener shuts it down.
pub fn run(count: u32, period: Duration, verbose: bool) -> Result<RunReport, DcdtError> {
    let mut agora = Agora::standalone();
    let greeter =
        agora.add_member(Greeter { sent: 0, count, verbose }, Activation::Periodic(period));
    let listener = agora.add_member(Listener { expected: count, verbose }, Activation::OnMessage);
    agora.activate_member(greeter)?;
    agora.activate_member(listener)?;
    agora.lets_work() // blocks until shutdown or every Member terminated
}

/// Entry point of the example.
pub fn main() -> Result<(), DcdtError> {
    // Show what MRT reports (crashes, restarts) through `tracing`; RUST_LOG overrides.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env()
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .try_init();
    let report = run(10, Duration::from_millis(100), true)?;
    println!("\nthe Agora stopped: {:?}", report.exit);
    for m in &report.members {
        println!(
            "  {:<9} {} cycles, {} panics, final state {:?}",
            m.name, m.cycles, m.panics, m.state
        );
    }
    Ok(())
}
