//! # 02 — Two Agoras in one process
//!
//! What you learn: several Agoras (two robots) joined by an `InnerLinkManager` in one
//! process, and how `RequestType::Local` and `RequestType::Remote` subscriptions tell a
//! robot's own messages from its teammates'. It runs on the **stepped executor** and a
//! simulated clock: 100 ms of robot time pass in microseconds, and the output is the same
//! on every run.
//!
//! Run: `cargo run -p mrt-examples --example 02_two_agoras` (or `mrt demo two-agoras`).

#![allow(clippy::print_stdout)] // examples talk to the user

use mrt_core::SimClock;
use mrt_dcdt::prelude::*;
use mrt_dcdt::{DcdtError, InnerLinkManager};
use serde::{Deserialize, Serialize};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A robot saw the ball at `distance` metres.
#[derive(Debug, Serialize, Deserialize)]
pub struct BallSeen {
    /// Metres from the robot.
    pub distance: f32,
}

impl Message for BallSeen {
    const TYPE: MsgType = MsgType(2);
    const NAME: &'static str = "BallSeen";
}

/// A camera stand-in: reports the ball every period.
pub struct Camera {
    distance: f32,
}

impl Member for Camera {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.distance -= 0.1;
        ctx.publish(BallSeen { distance: self.distance });
        Ok(())
    }
}

/// Logs the ball sightings it subscribed to, with the Agora they came from.
pub struct Listener {
    label: &'static str,
    request: RequestType,
    heard: Arc<Mutex<Vec<u32>>>,
    verbose: bool,
}

impl Member for Listener {
    fn name(&self) -> String {
        self.label.to_string()
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<BallSeen>(self.request);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(msg) = ctx.receive_msg() {
            let ball = msg.get::<BallSeen>()?;
            if self.verbose {
                println!(
                    "[{}] {} of {} hears: ball at {:.1} m, seen by {}",
                    ctx.now(),
                    self.label,
                    ctx.agora_id(),
                    ball.distance,
                    msg.agora_id()
                );
            }
            self.heard.lock().map_err(|_| "log poisoned")?.push(msg.agora_id().0);
        }
        Ok(())
    }
}

/// Which Agora each of robot 1's listeners heard, message by message.
#[derive(Debug, Default)]
pub struct Heard {
    /// The `Local` listener: robot 1's own camera only.
    pub own: Vec<u32>,
    /// The `Remote` listener: the teammate's camera only.
    pub teammates: Vec<u32>,
}

/// Runs both robots for `duration` of simulated time.
pub fn run(duration: Duration, verbose: bool) -> Result<Heard, DcdtError> {
    let ilm = InnerLinkManager::new();
    let mut exec = SteppedExecutor::new(SimClock::new(), Duration::from_millis(1));
    let mut robot1 = exec.agora_builder(1).inner_link(&ilm).build()?;
    let mut robot2 = exec.agora_builder(2).inner_link(&ilm).build()?;

    let own = Arc::new(Mutex::new(Vec::new()));
    let teammates = Arc::new(Mutex::new(Vec::new()));
    let ids = [
        robot1
            .add_member(Camera { distance: 3.0 }, Activation::Periodic(Duration::from_millis(20))),
        robot1.add_member(
            Listener {
                label: "own-ball",
                request: RequestType::Local,
                heard: own.clone(),
                verbose,
            },
            Activation::OnMessage,
        ),
        robot1.add_member(
            Listener {
                label: "mates-ball",
                request: RequestType::Remote,
                heard: teammates.clone(),
                verbose,
            },
            Activation::OnMessage,
        ),
    ];
    for id in ids {
        robot1.activate_member(id)?;
    }
    let cam2 = robot2
        .add_member(Camera { distance: 5.0 }, Activation::Periodic(Duration::from_millis(30)));
    robot2.activate_member(cam2)?;

    exec.add_agora(robot1)?;
    exec.add_agora(robot2)?;
    exec.run_for(duration);
    exec.finish();

    let take = |v: &Arc<Mutex<Vec<u32>>>| v.lock().map(|g| g.clone()).unwrap_or_default();
    Ok(Heard { own: take(&own), teammates: take(&teammates) })
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
    let heard = run(Duration::from_millis(100), true)?;
    println!(
        "\nrobot 1 heard {} of its own sightings (Local) and {} of its teammate's (Remote)",
        heard.own.len(),
        heard.teammates.len()
    );
    Ok(())
}
