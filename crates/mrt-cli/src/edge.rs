//! `mrt edge --net FILE`: the robots' messages for programs in other languages (MRT manual
//! §3.2: "modules communicate through XML messages whose structure is defined by a shared
//! DTD", so that a module need not share the robots' code to understand them).
//!
//! An Agora of this process joins the robots' network (as `mrt topic` does) and subscribes to
//! the chosen catalogue types. Every message it hears from Agora `A` is put on plain zenoh
//! as JSON on `mrt/json/<A>/<Type>` and as the manual's XML self-describing form on
//! `mrt/xml/<A>/<Type>`, which any zenoh client reads (`examples/python/edge_client.py`, with
//! PyPI's `eclipse-zenoh`). The other way, JSON put on `mrt/json-in/<Type>` is read as that
//! catalogue type and published on the robots' bus, as if one of their own Members had
//! published it (for instance a `BehaviorPush` for a robot); what does not read is counted
//! and dropped, with one warning a type.

use crate::topic::{deadline, entry_named, NetArgs};
use anyhow::{anyhow, bail, Result};
use mrt_dcdt::{Activation, Context, DeliveryWarranty, Member, MemberError, RequestType};
use mrt_monitor::catalogue::{self, Entry};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

/// The types sent out by default: what a program outside most wants to watch or answer.
pub const DEFAULT_TYPES: &[&str] = &[
    "WorldSnapshot",
    "RobotCommand",
    "BehaviorStatus",
    "BehaviorPushReply",
    "Localization",
    "GameInfo",
    "MateReport",
];

/// The largest JSON message taken in (a behavior file of 1 MiB, escaped).
pub const MAX_IN_BYTES: usize = 4 << 20;

/// `mrt edge`.
#[derive(clap::Args)]
pub struct EdgeArgs {
    #[command(flatten)]
    net: NetArgs,
    /// The catalogue types sent out, comma-separated (default: WorldSnapshot, RobotCommand,
    /// BehaviorStatus, BehaviorPushReply, Localization, GameInfo, MateReport).
    #[arg(long, value_delimiter = ',')]
    types: Vec<String>,
    /// Stop after this long, s (default: until Ctrl-C).
    #[arg(long)]
    seconds: Option<f64>,
}

/// What the edge did.
#[derive(Default)]
struct Counts {
    out: AtomicU64,
    dropped_out: AtomicU64,
    into_bus: AtomicU64,
    dropped_in: AtomicU64,
}

/// A message put on `mrt/json-in/<Type>`.
struct Inbound {
    entry: &'static Entry,
    json: Vec<u8>,
}

/// The edge's Member: the bus → zenoh as JSON and XML, zenoh's JSON → the bus.
struct Edge {
    types: Vec<&'static Entry>,
    raw: mrt_net::RawPort,
    inbound: mpsc::Receiver<Inbound>,
    counts: Arc<Counts>,
    warned: std::collections::BTreeSet<&'static str>,
}

impl Edge {
    fn warn_once(&mut self, name: &'static str, what: String) {
        if self.warned.insert(name) {
            eprintln!("edge: {what} (further ones of this type are only counted)");
        }
    }
}

impl Member for Edge {
    fn name(&self) -> String {
        "edge".into()
    }

    fn init(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        for e in &self.types {
            ctx.subscribe(e.ty, RequestType::Remote);
        }
        Ok(())
    }

    fn do_your_job(&mut self, ctx: &mut Context<'_>) -> Result<(), MemberError> {
        while let Some(m) = ctx.receive_msg() {
            let Some(entry) = catalogue::entry(m.msg_type()) else { continue };
            let agora = m.agora_id().0;
            let mut sent = false;
            if let Some(Ok(json)) = (entry.to_json)(&m) {
                sent = self.raw.put(&format!("mrt/json/{agora}/{}", entry.name), json).is_ok();
            }
            if let Some(Ok(xml)) = (entry.to_xml)(&m) {
                let key = format!("mrt/xml/{agora}/{}", entry.name);
                sent &= self.raw.put(&key, xml.into_bytes()).is_ok();
            }
            let count = if sent { &self.counts.out } else { &self.counts.dropped_out };
            count.fetch_add(1, Ordering::Relaxed);
        }
        while let Ok(msg) = self.inbound.try_recv() {
            match (msg.entry.publish_json)(ctx, &msg.json, DeliveryWarranty::Reliable) {
                Ok(()) => {
                    self.counts.into_bus.fetch_add(1, Ordering::Relaxed);
                }
                Err(e) => {
                    self.counts.dropped_in.fetch_add(1, Ordering::Relaxed);
                    self.warn_once(msg.entry.name, format!("dropped a {}: {e}", msg.entry.name));
                }
            }
        }
        Ok(())
    }
}

/// Runs `mrt edge`.
pub fn run(args: &EdgeArgs) -> Result<()> {
    let end = args.seconds.map(|s| deadline(s, "--seconds")).transpose()?;
    let names: Vec<String> = if args.types.is_empty() {
        DEFAULT_TYPES.iter().map(|s| s.to_string()).collect()
    } else {
        args.types.clone()
    };
    let types = names.iter().map(|n| entry_named(n)).collect::<Result<Vec<_>>>()?;
    let file = &args.net.net;
    let cfg = mrt_dcdt::config::AgoraConfig::from_file(file).map_err(|e| anyhow!("{e}"))?;
    let listen = mrt_net::NetConfig::from_agora_config(&cfg).map_err(|e| anyhow!("{e}"))?.listen;
    let mut agora = mrt_dcdt::Agora::from_config(file, args.net.id)
        .map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let link = mrt_net::connect(&agora).map_err(|e| anyhow!("{}: {e}", file.display()))?;
    let raw = link.raw();
    let counts = Arc::new(Counts::default());
    let (tx, inbound) = mpsc::sync_channel::<Inbound>(1024);
    let in_counts = counts.clone();
    let _inbound = raw.subscribe("mrt/json-in/*", move |key, json| {
        let name = key.rsplit('/').next().unwrap_or_default();
        match catalogue::CATALOGUE.iter().find(|e| e.name == name) {
            Some(entry) if json.len() <= MAX_IN_BYTES => {
                if tx.try_send(Inbound { entry, json }).is_err() {
                    in_counts.dropped_in.fetch_add(1, Ordering::Relaxed);
                }
            }
            _ => {
                in_counts.dropped_in.fetch_add(1, Ordering::Relaxed);
            }
        }
    })?;
    let edge = Edge { types, raw, inbound, counts: counts.clone(), warned: Default::default() };
    let m = agora.add_member(edge, Activation::Periodic(Duration::from_millis(5)));
    agora.activate_member(m)?;
    let stop = agora.shutdown_handle();
    let worker = std::thread::spawn(move || agora.lets_work());
    let fixed: Vec<&String> = listen.iter().filter(|e| !e.ends_with(":0")).collect();
    outln!(
        "edge ready: listening on {}; out: mrt/json/<agora>/<Type> and mrt/xml/<agora>/<Type> \
         ({}); in: mrt/json-in/<Type>",
        fixed.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", "),
        names.join(", ")
    );
    // Ctrl-C ends the edge with its counts said.
    crate::interrupt::finish_on_ctrl_c();
    while end.is_none_or(|e| Instant::now() < e) && !crate::interrupt::interrupted() {
        if worker.is_finished() {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    stop.shutdown();
    match worker.join() {
        Ok(Ok(_)) => {}
        Ok(Err(e)) => bail!("the edge's Agora stopped: {e}"),
        Err(_) => bail!("the edge's Agora stopped (a panic)"),
    }
    drop(link);
    eprintln!(
        "edge: {} messages out ({} not sent), {} in onto the bus ({} dropped)",
        counts.out.load(Ordering::Relaxed),
        counts.dropped_out.load(Ordering::Relaxed),
        counts.into_bus.load(Ordering::Relaxed),
        counts.dropped_in.load(Ordering::Relaxed)
    );
    Ok(())
}
