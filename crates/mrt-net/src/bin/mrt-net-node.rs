//! `mrt-net-node`: one Agora on the network, for the multi-process tests and for trying links
//! by hand. It prints what happens, one line each: `up <ids>` when the Finder's view changes,
//! `got <agora> <seq>` per Ping received, `stats ...` at the end.
//!
//! ```text
//! mrt-net-node --id 1 --listen 7451 --send 100           # sends 100 Pings once somebody wants them
//! mrt-net-node --id 2 --listen 7452 --connect 7451 --recv
//! mrt-net-node --id 4 --listen 7454 --connect 7451 --send 10 --recv --want all   # own Pings too
//! mrt-net-node --id 3 --config configs/dcdt/same_machine.cfg --recv
//! mrt-net-node --id 9 --listen 7459 --connect 7451 --echo     # the benchmark's echo
//! ```
#![allow(clippy::print_stdout)]

use mrt_core::SimClock;
use mrt_dcdt::config::AgoraConfig;
use mrt_dcdt::prelude::*;
use mrt_net::probe::{Echo, Flood, FloodCounter, Ping, Probe};
use mrt_net::{NetConfig, NetLink};
use std::io::Write;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

struct Sender {
    left: Arc<AtomicU64>,
    seq: u64,
    period_ticks: u64,
    tick: u64,
}

impl Member for Sender {
    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        self.tick += 1;
        if self.tick % self.period_ticks != 0 || !ctx.has_subscribers(Ping::TYPE) {
            return Ok(());
        }
        if self.left.load(Ordering::Relaxed) > 0 {
            self.left.fetch_sub(1, Ordering::Relaxed);
            self.seq += 1;
            ctx.publish_with(Ping { seq: self.seq }, DeliveryWarranty::Reliable, 0);
        }
        Ok(())
    }
}

/// Prints every Ping it receives; subscribed as `--want local|remote|all` (default remote).
struct Receiver(RequestType);

impl Member for Receiver {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Ping>(self.0);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        let mut out = std::io::stdout().lock();
        while let Some(m) = ctx.receive_msg() {
            let p = m.get::<Ping>()?;
            let _ = writeln!(out, "got {} {}", m.agora_id().0, p.seq);
        }
        let _ = out.flush();
        Ok(())
    }
}

/// Sends every Probe back as an Echo, and one empty Echo per complete batch of Floods.
#[derive(Default)]
struct Echoer(FloodCounter);

impl Member for Echoer {
    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        ctx.subscribe_to::<Probe>(RequestType::Remote);
        ctx.subscribe_to::<Flood>(RequestType::Remote);
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            if m.msg_type() == Probe::TYPE {
                ctx.publish_with(Echo(m.get::<Probe>()?.0.clone()), DeliveryWarranty::Reliable, 0);
            } else if self.0.count(&m.get::<Flood>()?.0) {
                ctx.publish_with(Echo(Vec::new()), DeliveryWarranty::Reliable, 0);
            }
        }
        Ok(())
    }
}

/// The far side of the benchmark: an Agora echoing Probes and acknowledging batches of Floods
/// (threaded executor: a Member wakes as a message arrives), and plain zenoh subscribers doing
/// the same on `raw/ping` and `raw/flood` in zenoh's receive callback and on `raw/flood_fifo` on
/// a thread of their own (answers on `raw/pong`), on the same session.
fn echo(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    use zenoh::Wait;
    let mut agora = mrt_dcdt::Agora::builder(args.id).build()?;
    let m = agora.add_member(Echoer::default(), Activation::OnMessage);
    agora.activate_member(m)?;
    let link = NetLink::attach(&agora, &args.net)?;
    let session = link.session().clone();
    let z = |e: zenoh::Error| e.to_string();
    // The same QoS as a Reliable DCDT message: block when congested, batched.
    let publisher = session
        .declare_publisher("raw/pong")
        .congestion_control(zenoh::qos::CongestionControl::Block)
        .wait()
        .map_err(z)?;
    let publisher = Arc::new(publisher);
    let pong = publisher.clone();
    let _raw = session
        .declare_subscriber("raw/ping")
        .callback(move |s| {
            let _ = pong.put(s.payload().clone()).wait();
        })
        .wait()
        .map_err(z)?;
    let flood = FloodCounter::default();
    let ack = publisher.clone();
    let _raw_flood = session
        .declare_subscriber("raw/flood")
        .callback(move |s| {
            if flood.count(&s.payload().to_bytes()) {
                let _ = ack.put(Vec::new()).wait();
            }
        })
        .wait()
        .map_err(z)?;
    // zenoh's default subscriber: its FIFO channel, received on a thread of the application's
    // own (what a Member's thread does with its mailbox).
    let fifo = session.declare_subscriber("raw/flood_fifo").wait().map_err(z)?;
    std::thread::spawn(move || {
        let flood = FloodCounter::default();
        while let Ok(s) = fifo.recv() {
            if flood.count(&s.payload().to_bytes()) {
                let _ = publisher.put(Vec::new()).wait();
            }
        }
    });
    println!("echo ready");
    let stop = agora.shutdown_handle();
    let duration = args.duration;
    std::thread::spawn(move || {
        std::thread::sleep(duration);
        stop.shutdown();
    });
    agora.lets_work()?;
    Ok(())
}

struct Args {
    echo: bool,
    id: u32,
    net: NetConfig,
    send: u64,
    every_ms: u64,
    recv: bool,
    want: RequestType,
    duration: Duration,
}

fn parse() -> Result<Args, String> {
    let mut a = std::env::args().skip(1);
    let (mut id, mut listen, mut connect, mut config) = (None, None, Vec::new(), None);
    let (mut send, mut every_ms, mut recv, mut bridge, mut secs) = (0, 10, false, false, 10.0);
    let (mut echo, mut want) = (false, RequestType::Remote);
    let num = |v: Option<String>, what: &str| -> Result<u64, String> {
        v.ok_or(format!("{what} needs a value"))?.parse().map_err(|e| format!("{what}: {e}"))
    };
    while let Some(flag) = a.next() {
        match flag.as_str() {
            "--id" => id = Some(num(a.next(), "--id")? as u32),
            "--listen" => listen = Some(num(a.next(), "--listen")? as u16),
            "--connect" => connect.push(num(a.next(), "--connect")? as u16),
            "--config" => config = Some(a.next().ok_or("--config needs a file")?),
            "--send" => send = num(a.next(), "--send")?,
            "--every-ms" => every_ms = num(a.next(), "--every-ms")?.max(1),
            "--recv" => recv = true,
            "--want" => {
                want = match a.next().as_deref() {
                    Some("local") => RequestType::Local,
                    Some("remote") => RequestType::Remote,
                    Some("all") => RequestType::All,
                    other => return Err(format!("--want local|remote|all, not {other:?}")),
                }
            }
            "--bridge" => bridge = true,
            "--echo" => echo = true,
            "--seconds" => {
                secs = a
                    .next()
                    .ok_or("--seconds needs a value")?
                    .parse()
                    .map_err(|e| format!("--seconds: {e}"))?
            }
            other => return Err(format!("unknown option {other}")),
        }
    }
    let id = id.ok_or("--id is required")?;
    let mut net = match (config, listen) {
        (Some(file), _) => {
            let cfg = AgoraConfig::from_file(&file).map_err(|e| e.to_string())?;
            NetConfig::from_agora_config(&cfg).map_err(|e| e.to_string())?
        }
        (None, Some(port)) => NetConfig::loopback(port, &connect),
        (None, None) => return Err("--listen PORT or --config FILE is required".into()),
    };
    net.bridge |= bridge;
    Ok(Args { echo, id, net, send, every_ms, recv, want, duration: Duration::from_secs_f64(secs) })
}

fn main() {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("mrt-net-node: {e}");
            std::process::exit(2);
        }
    };
    let result = if args.echo { echo(&args) } else { run(&args) };
    if let Err(e) = result {
        eprintln!("mrt-net-node: {e}");
        std::process::exit(1);
    }
}

fn run(args: &Args) -> Result<(), Box<dyn std::error::Error>> {
    let tick = Duration::from_millis(1);
    let mut exec = SteppedExecutor::new(SimClock::new(), tick);
    let mut agora = exec.agora_builder(args.id).build()?;
    let left = Arc::new(AtomicU64::new(args.send));
    if args.send > 0 {
        let s = Sender { left: left.clone(), seq: 0, period_ticks: args.every_ms, tick: 0 };
        let m = agora.add_member(s, Activation::Periodic(tick));
        agora.activate_member(m)?;
    }
    if args.recv {
        let m = agora.add_member(Receiver(args.want), Activation::OnMessage);
        agora.activate_member(m)?;
    }
    let link = NetLink::attach(&agora, &args.net)?;
    exec.add_agora(agora)?;
    let start = Instant::now();
    let mut seen = Vec::new();
    let mut drained_at: Option<Instant> = None;
    while start.elapsed() < args.duration {
        exec.run_for(tick);
        let up = link.agoras();
        if up != seen {
            let ids: Vec<String> = up.iter().map(|a| a.0.to_string()).collect();
            println!("up {}", ids.join(" "));
            seen = up;
        }
        // A sender stops half a second after its last message.
        if args.send > 0 && !args.recv && left.load(Ordering::Relaxed) == 0 {
            let t = *drained_at.get_or_insert_with(Instant::now);
            if t.elapsed() > Duration::from_millis(500) {
                break;
            }
        }
        std::thread::sleep(tick);
    }
    let s = link.stats();
    println!(
        "stats sent={} delivered={} malformed={} unwanted={} duplicates={}",
        s.sent, s.delivered, s.malformed, s.unwanted, s.duplicates
    );
    Ok(())
}
