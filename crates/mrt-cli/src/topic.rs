//! `mrt topic list|echo|hz --net FILE`, `mrt record --net FILE -o OUT.mcap` and `mrt monitor
//! --net FILE --serve`: the messages of robots running anywhere on the network, seen by an Agora of this process joined to their network (`mrt-net`, the same
//! discovery and links as the robots'), with a Member that subscribes to every catalogue type
//! (`RequestType::Remote`): the robots send a type to this Agora because it wants it, like to
//! any other (docs/monitor.md, "Topics on the network").

use anyhow::{anyhow, bail, Result};
use mrt_core::Time;
use mrt_dcdt::{Activation, Context, Member, MemberError, RequestType};
use mrt_monitor::catalogue::{self, Entry};
use mrt_monitor::serve::Server;
use mrt_monitor::{Recorder, Timeline};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// The network to join.
#[derive(clap::Args)]
pub struct NetArgs {
    /// The DCDT Agora configuration file (MRT manual §3.3.1) of the network to join:
    /// `mrt sim --distributed` prints the one of its match.
    #[arg(long, value_name = "FILE")]
    pub net: PathBuf,
    /// This Agora's id on the network (it must differ from every robot's).
    #[arg(long, default_value_t = 900)]
    pub id: u32,
}

/// `mrt topic`.
#[derive(clap::Subcommand)]
pub enum TopicCommand {
    /// The message types published on the network, by which Agoras, how many a second.
    List {
        #[command(flatten)]
        net: NetArgs,
        /// How long to listen, s.
        #[arg(long, default_value_t = 3.0)]
        seconds: f64,
    },
    /// Print the messages of one type as JSON Lines: `{"agora": ID, "time": S, "message": …}`.
    Echo {
        /// The message type, e.g. WorldSnapshot (`mrt topic list` names them).
        r#type: String,
        #[command(flatten)]
        net: NetArgs,
        /// Only the messages of this Agora (robot k of a distributed match is Agora k + 1).
        #[arg(long)]
        agora: Option<u32>,
        /// Stop after this many messages.
        #[arg(long)]
        count: Option<u64>,
        /// Stop after this long, s (default: until Ctrl-C or --count).
        #[arg(long)]
        seconds: Option<f64>,
    },
    /// Measure the rate of one type, per publishing Agora: messages a second and the mean,
    /// smallest and largest gap between two.
    Hz {
        /// The message type.
        r#type: String,
        #[command(flatten)]
        net: NetArgs,
        /// How long to listen, s.
        #[arg(long, default_value_t = 5.0)]
        seconds: f64,
    },
}

/// One message heard: its type, its Agora, its creation time (s, the publisher's clock) and
/// its JSON.
struct Heard {
    entry: &'static Entry,
    agora: u32,
    time: Time,
    json: Option<Vec<u8>>,
}

impl Heard {
    /// Its topic in a recording or the monitor: `/agora/<id>/<Type>`.
    fn topic(&self) -> String {
        format!("/agora/{}/{}", self.agora, self.entry.name)
    }
}

/// Subscribes to `types` from the other Agoras and hands every message to the channel.
struct Listener {
    types: Vec<&'static Entry>,
    json: bool,
    out: mpsc::Sender<Heard>,
}

impl Member for Listener {
    fn name(&self) -> String {
        "topic-listener".into()
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
            let json = if self.json { (entry.to_json)(&m).and_then(Result::ok) } else { None };
            let heard = Heard { entry, agora: m.agora_id().0, time: m.creation_time(), json };
            if self.out.send(heard).is_err() {
                return Ok(()); // the command is done listening
            }
        }
        Ok(())
    }
}

/// The catalogue entry named `name` (case-insensitive), or an error listing them all.
pub(crate) fn entry_named(name: &str) -> Result<&'static Entry> {
    catalogue::CATALOGUE.iter().find(|e| e.name.eq_ignore_ascii_case(name)).ok_or_else(|| {
        let names: Vec<&str> = catalogue::CATALOGUE.iter().map(|e| e.name).collect();
        anyhow!("no message type {name:?}: the types are {}", names.join(", "))
    })
}

/// Joins the network of `net` and listens to `types`; the Agora and its link live while the
/// returned guard does.
fn listen(
    net: &NetArgs,
    types: Vec<&'static Entry>,
    json: bool,
) -> Result<(mpsc::Receiver<Heard>, Joined)> {
    let mut agora = mrt_dcdt::Agora::from_config(&net.net, net.id)
        .map_err(|e| anyhow!("{}: {e}", net.net.display()))?;
    let (tx, rx) = mpsc::channel();
    let m = agora.add_member(Listener { types, json, out: tx }, Activation::OnMessage);
    agora.activate_member(m)?;
    let link = mrt_net::connect(&agora).map_err(|e| anyhow!("{}: {e}", net.net.display()))?;
    let stop = agora.shutdown_handle();
    let worker = std::thread::spawn(move || {
        if let Err(e) = agora.lets_work() {
            eprintln!("error: the listening Agora stopped: {e}");
        }
    });
    Ok((rx, Joined { link: Some(link), stop, worker: Some(worker) }))
}

/// The Agora joined to the network, working on a thread of its own: it stops, then leaves
/// the network, when this is dropped.
struct Joined {
    link: Option<mrt_net::NetLink>,
    stop: mrt_dcdt::ShutdownHandle,
    worker: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Joined {
    fn drop(&mut self) {
        self.stop.shutdown();
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
        self.link.take();
    }
}

/// Messages heard until `deadline` (or the channel ends), each handed to `f`; `f` returns
/// false to stop.
fn until(rx: &mpsc::Receiver<Heard>, deadline: Option<Instant>, mut f: impl FnMut(Heard) -> bool) {
    loop {
        let wait = deadline
            .map_or(Duration::from_secs(3600), |d| d.saturating_duration_since(Instant::now()));
        if wait.is_zero() {
            return;
        }
        match rx.recv_timeout(wait) {
            Ok(h) => {
                if !f(h) {
                    return;
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) if deadline.is_some() => return,
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => return,
        }
    }
}

fn deadline(seconds: f64, option: &str) -> Result<Instant> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0) {
        bail!("{option} must be more than 0 and at most 86400 s, not {seconds}");
    }
    Ok(Instant::now() + Duration::from_secs_f64(seconds))
}

/// Runs `mrt topic`.
pub fn run(command: &TopicCommand) -> Result<()> {
    match command {
        TopicCommand::List { net, seconds } => {
            let end = deadline(*seconds, "--seconds")?;
            let (rx, _joined) = listen(net, catalogue::CATALOGUE.iter().collect(), false)?;
            let mut seen: BTreeMap<&str, BTreeMap<u32, u64>> = BTreeMap::new();
            until(&rx, Some(end), |h| {
                *seen.entry(h.entry.name).or_default().entry(h.agora).or_default() += 1;
                true
            });
            if seen.is_empty() {
                outln!("nothing heard in {seconds} s on {}", net.net.display());
            }
            for (name, by) in &seen {
                let total: u64 = by.values().sum();
                let agoras: Vec<String> = by.keys().map(u32::to_string).collect();
                outln!(
                    "{name:<16} {:>7.1} msg/s  from Agoras {}",
                    total as f64 / seconds,
                    agoras.join(", ")
                );
            }
        }
        TopicCommand::Echo { r#type, net, agora, count, seconds } => {
            let entry = entry_named(r#type)?;
            let end = seconds.map(|s| deadline(s, "--seconds")).transpose()?;
            let (rx, _joined) = listen(net, vec![entry], true)?;
            let mut printed = 0u64;
            until(&rx, end, |h| {
                if agora.is_some_and(|a| a != h.agora) {
                    return true;
                }
                let message = h.json.as_deref().map_or("null".into(), String::from_utf8_lossy);
                let time = h.time.as_secs_f64();
                outln!(r#"{{"agora":{},"time":{time},"message":{message}}}"#, h.agora);
                printed += 1;
                count.is_none_or(|c| printed < c)
            });
        }
        TopicCommand::Hz { r#type, net, seconds } => {
            let entry = entry_named(r#type)?;
            let end = deadline(*seconds, "--seconds")?;
            let (rx, _joined) = listen(net, vec![entry], false)?;
            let mut arrivals: BTreeMap<u32, Vec<Instant>> = BTreeMap::new();
            until(&rx, Some(end), |h| {
                arrivals.entry(h.agora).or_default().push(Instant::now());
                true
            });
            if arrivals.is_empty() {
                outln!("no {} heard in {seconds} s", entry.name);
            }
            for (agora, times) in &arrivals {
                let gaps: Vec<f64> =
                    times.windows(2).map(|w| (w[1] - w[0]).as_secs_f64() * 1000.0).collect();
                let mean = gaps.iter().sum::<f64>() / gaps.len().max(1) as f64;
                let min = gaps.iter().copied().fold(f64::INFINITY, f64::min);
                let max = gaps.iter().copied().fold(0.0, f64::max);
                let rate = if mean > 0.0 { 1000.0 / mean } else { 0.0 };
                outln!(
                    "{} from Agora {agora}: {rate:.1} msg/s over {} messages; gap mean {mean:.1} ms, min {:.1} ms, max {max:.1} ms",
                    entry.name,
                    times.len(),
                    if min.is_finite() { min } else { 0.0 }
                );
            }
        }
    }
    Ok(())
}

/// `mrt record --net FILE -o OUT.mcap`.
#[derive(clap::Args)]
pub struct RecordArgs {
    #[command(flatten)]
    net: NetArgs,
    /// The MCAP file to write (topics `/agora/<id>/<Type>`, docs/monitor.md).
    #[arg(short, long, value_name = "OUT.mcap")]
    output: PathBuf,
    /// How long to record, s (the file is complete only when the time is up: Ctrl-C loses
    /// its index).
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
}

/// Records every catalogue message of the network's Agoras for `--seconds`.
pub fn record(args: &RecordArgs) -> Result<()> {
    let end = deadline(args.seconds, "--seconds")?;
    let mut rec = Recorder::create(&args.output)?;
    let (rx, _joined) = listen(&args.net, catalogue::CATALOGUE.iter().collect(), true)?;
    let mut failed = None;
    until(&rx, Some(end), |h| {
        let Some(json) = &h.json else {
            rec.failed();
            return true;
        };
        let written = rec
            .channel(&h.topic(), h.entry.name, h.entry.schema)
            .and_then(|c| rec.write(c, h.time, json));
        if let Err(e) = written {
            failed = Some(e);
        }
        failed.is_none()
    });
    if let Some(e) = failed {
        return Err(e.into());
    }
    let s = rec.finish()?;
    let size = std::fs::metadata(&args.output).map(|m| m.len()).unwrap_or(0);
    outln!(
        "recorded {} messages on {} topics in {} s into {} ({:.1} MB)",
        s.messages,
        s.channels,
        args.seconds,
        args.output.display(),
        size as f64 / 1e6
    );
    Ok(())
}

/// `mrt monitor --net FILE --serve ADDR`.
#[derive(clap::Args)]
pub struct MonitorArgs {
    #[command(flatten)]
    net: NetArgs,
    /// Where to serve the web monitor (loopback by default; port 0: any free port).
    #[arg(long, value_name = "ADDR", default_value = "127.0.0.1:8080")]
    serve: std::net::SocketAddr,
}

/// Serves the web monitor on what the network's Agoras publish, until Ctrl-C.
pub fn monitor(args: &MonitorArgs) -> Result<()> {
    let timeline = Timeline::new().shared();
    let title = format!("the network of {}", args.net.net.display());
    let server = Server::start(args.serve, timeline.clone(), &title)?;
    let (rx, _joined) = listen(&args.net, catalogue::CATALOGUE.iter().collect(), true)?;
    outln!("monitor: {}; Ctrl-C to stop", server.url());
    until(&rx, None, |h| {
        if let (Some(json), Ok(mut t)) = (&h.json, timeline.lock()) {
            t.ingest(&h.topic(), h.time, json);
        }
        true
    });
    Ok(())
}
