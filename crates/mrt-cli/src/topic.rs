//! `mrt topic list|echo|hz --net FILE`, `mrt record --net FILE -o OUT.mcap` and `mrt monitor
//! --net FILE --serve`: the messages of robots running anywhere on the network, seen by an Agora of this process joined to their network (`mrt-net`, the same
//! discovery and links as the robots'), with a Member that subscribes to every catalogue type
//! (`RequestType::Remote`): the robots send a type to this Agora because it wants it, like to
//! any other (docs/monitor.md, "Topics on the network").

use crate::interrupt;
use anyhow::{anyhow, bail, Result};
use mrt_core::frames::{millis, MS_PER_S};
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
    /// Measure the rate of one type, per publishing Agora: messages a second, the mean,
    /// smallest and largest gap between two, and the delay (docs/monitor.md, "Topics on the
    /// network"). Ctrl-C ends it early with what was heard so far.
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

/// Messages heard until `deadline`, Ctrl-C in a command that finishes itself
/// ([`interrupt::finish_on_ctrl_c`]) or the channel's end, each handed to `f`; `f` returns
/// false to stop.
fn until(rx: &mpsc::Receiver<Heard>, deadline: Option<Instant>, mut f: impl FnMut(Heard) -> bool) {
    /// How long a wait lasts at most before Ctrl-C is looked at again.
    const POLL: Duration = Duration::from_millis(100);
    while !interrupt::interrupted() {
        let wait = deadline.map_or(POLL, |d| d.saturating_duration_since(Instant::now()));
        if wait.is_zero() {
            return;
        }
        match rx.recv_timeout(wait.min(POLL)) {
            Ok(h) => {
                if !f(h) {
                    return;
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            Err(mpsc::RecvTimeoutError::Disconnected) => return,
        }
    }
}

/// The instant `seconds` from now, for an `option` that must be in (0, 86400] s.
pub(crate) fn deadline(seconds: f64, option: &str) -> Result<Instant> {
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
            interrupt::finish_on_ctrl_c();
            let (rx, _joined) = listen(net, vec![entry], false)?;
            let start = Instant::now();
            let mut heard: BTreeMap<u32, Vec<(f64, f64)>> = BTreeMap::new();
            until(&rx, Some(end), |h| {
                let arrival = start.elapsed().as_secs_f64();
                heard.entry(h.agora).or_default().push((arrival, h.time.as_secs_f64()));
                true
            });
            if heard.is_empty() {
                outln!("no {} heard in {:.1} s", entry.name, start.elapsed().as_secs_f64());
            }
            for (agora, times) in &heard {
                outln!("{} from Agora {agora}: {}", entry.name, Rate::of(times));
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
    /// How long to record at most, s. Ctrl-C ends the recording earlier, with a complete file
    /// (its summary and index written); a second Ctrl-C quits at once.
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
}

/// Records every catalogue message of the network's Agoras for `--seconds` or until Ctrl-C.
pub fn record(args: &RecordArgs) -> Result<()> {
    let end = deadline(args.seconds, "--seconds")?;
    let mut rec = Recorder::create(&args.output)?;
    interrupt::finish_on_ctrl_c();
    let (rx, _joined) = listen(&args.net, catalogue::CATALOGUE.iter().collect(), true)?;
    let start = Instant::now();
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
        "recorded {} messages on {} topics in {:.1} s into {} ({:.1} MB)",
        s.messages,
        s.channels,
        start.elapsed().as_secs_f64(),
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

/// What `mrt topic hz` says of one Agora's messages of a type, from each message's arrival
/// (s since listening began, this process's clock) and creation time (s, the publisher's
/// clock).
///
/// Every Agora's clock has an origin of its own (`WallClock` starts with its Agora), so a
/// message's delay cannot be read off its two times directly. The difference of the two,
/// arrival minus creation, is the delay plus an unknown constant offset between the clocks;
/// the quickest message's difference is taken as the offset, and each message's delay is
/// given **beyond the quickest one's**: the delay's spread, which is what grows when a link
/// or a subscriber falls behind. When the publisher's clock does not run at real time (a
/// simulated clock, e.g. `mrt sim --distributed` stepping faster than real time), the offset
/// is not constant and no delay is given.
#[derive(Clone, Debug, PartialEq)]
struct Rate {
    messages: usize,
    /// Messages a second, from the mean gap.
    rate: f64,
    /// Mean, smallest and largest gap between two arrivals, ms.
    gaps: (f64, f64, f64),
    /// Delay beyond the quickest message's, ms: mean, 95th percentile, largest.
    delay: Option<(f64, f64, f64)>,
    /// How fast the publisher's clock ran against this process's, when it was measured.
    clock_rate: Option<f64>,
}

impl Rate {
    /// How far the publisher's clock may run from real time for delays to be given.
    const REAL_TIME: f64 = 0.05;

    fn of(times: &[(f64, f64)]) -> Rate {
        let gaps: Vec<f64> = times.windows(2).map(|w| millis(w[1].0 - w[0].0)).collect();
        let mean = gaps.iter().sum::<f64>() / gaps.len().max(1) as f64;
        let min = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        let max = gaps.iter().copied().fold(0.0, f64::max);
        let rate = if mean > 0.0 { MS_PER_S / mean } else { 0.0 };
        let (first, last) = (times.first(), times.last());
        let clock_rate = match (first, last) {
            (Some(a), Some(b)) if b.0 - a.0 > 0.0 && times.len() >= 3 => {
                Some((b.1 - a.1) / (b.0 - a.0))
            }
            _ => None,
        };
        let delay = clock_rate.filter(|r| (r - 1.0).abs() <= Rate::REAL_TIME).map(|_| {
            let offsets: Vec<f64> =
                times.iter().map(|(arrival, created)| arrival - created).collect();
            let quickest = offsets.iter().copied().fold(f64::INFINITY, f64::min);
            let mut delays: Vec<f64> = offsets.iter().map(|o| millis(o - quickest)).collect();
            delays.sort_by(f64::total_cmp);
            let mean = delays.iter().sum::<f64>() / delays.len() as f64;
            let p95 = delays[((delays.len() - 1) as f64 * 0.95).round() as usize];
            (mean, p95, delays.last().copied().unwrap_or(0.0))
        });
        Rate {
            messages: times.len(),
            rate,
            gaps: (mean, if min.is_finite() { min } else { 0.0 }, max),
            delay,
            clock_rate,
        }
    }
}

impl std::fmt::Display for Rate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (mean, min, max) = self.gaps;
        write!(
            f,
            "{:.1} msg/s over {} messages; gap mean {mean:.1} ms, min {min:.1} ms, max {max:.1} ms",
            self.rate, self.messages
        )?;
        match (self.delay, self.clock_rate) {
            (Some((mean, p95, max)), _) => write!(
                f,
                "; delay beyond the quickest message mean {mean:.2} ms, 95% {p95:.2} ms, max {max:.2} ms"
            ),
            (None, Some(r)) => {
                write!(f, "; no delay: the publisher's clock runs at {r:.2}× real time")
            }
            (None, None) => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Messages created every 100 ms on a clock 7 s ahead of ours, arriving 1 ms after
    /// creation except the third, 4 ms: the delay beyond the quickest is 0, 0, 3, 0, 0 ms.
    #[test]
    fn hz_gives_the_rate_the_gaps_and_the_delay_beyond_the_quickest_message() {
        let times: Vec<(f64, f64)> = (0..5)
            .map(|i| {
                let created = 7.0 + 0.1 * i as f64;
                let late = if i == 2 { 0.004 } else { 0.001 };
                (created - 7.0 + late, created)
            })
            .collect();
        let r = Rate::of(&times);
        assert_eq!(r.messages, 5);
        assert!((r.rate - 10.0).abs() < 1e-9, "{r:?}");
        let (mean, min, max) = r.gaps;
        assert!(
            (mean - 100.0).abs() < 1e-9 && (min - 97.0).abs() < 1e-9 && (max - 103.0).abs() < 1e-9
        );
        let (mean, p95, max) = r.delay.unwrap();
        assert!((mean - 0.6).abs() < 1e-9 && (p95 - 3.0).abs() < 1e-9 && (max - 3.0).abs() < 1e-9);
        let line = r.to_string();
        assert!(
            line.contains("10.0 msg/s over 5 messages") && line.contains("max 3.00 ms"),
            "{line}"
        );
    }

    /// A publisher whose clock runs twice as fast as ours (a simulation ahead of real time):
    /// the rate is measured, the delay is not.
    #[test]
    fn hz_gives_no_delay_when_the_publisher_s_clock_is_not_real_time() {
        let times: Vec<(f64, f64)> = (0..10).map(|i| (0.1 * i as f64, 0.2 * i as f64)).collect();
        let r = Rate::of(&times);
        assert_eq!(r.delay, None);
        assert!((r.clock_rate.unwrap() - 2.0).abs() < 1e-9);
        assert!(r.to_string().contains("runs at 2.00× real time"), "{r}");
        assert_eq!(Rate::of(&[(0.5, 3.0)]).delay, None, "one message has no delay");
    }
}
