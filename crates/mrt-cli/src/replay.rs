//! `mrt replay FILE.mcap`: what a recording holds, or (`--serve`) the recording in the web
//! monitor (docs/monitor.md). Feeding it back into Members is still to come (issue 22).

use anyhow::Result;
use mrt_monitor::serve::Server;
use mrt_monitor::{Recording, Timeline};
use std::path::PathBuf;

/// `mrt replay`.
#[derive(clap::Args)]
pub struct ReplayArgs {
    /// The MCAP file (`mrt sim --record`, or another tool's: channels that are not JSON are
    /// listed as skipped).
    pub file: PathBuf,
    /// Print the topics as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Serve the recording in the web monitor (until Ctrl-C): the field, each robot's beliefs
    /// against the truth, a timeline to play, pause, step and scrub. ADDR defaults to
    /// 127.0.0.1:8080 (loopback only; port 0 takes any free port).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8080")]
    pub serve: Option<std::net::SocketAddr>,
}

/// Runs `mrt replay`: lists the recording's topics with their schemas, message counts and
/// time spans.
pub fn run(args: &ReplayArgs) -> Result<()> {
    let recording = Recording::open(&args.file)?;
    if let Some(addr) = args.serve {
        let timeline = Timeline::of_recording(&recording)?;
        let frames = timeline.end();
        if frames == 0 {
            anyhow::bail!("{}: no message the monitor can show", args.file.display());
        }
        let title = args.file.file_name().map_or_else(String::new, |n| n.to_string_lossy().into());
        let server = Server::start(addr, timeline.shared(), &title)?;
        outln!("monitor: {} ({frames} frames); Ctrl-C to stop", server.url());
        crate::wait_for_ctrl_c();
    }
    let topics = recording.topics()?;
    let secs = |t: mrt_core::Time| t.as_secs_f64();
    if args.json {
        let list: Vec<serde_json::Value> = topics
            .iter()
            .map(|t| {
                serde_json::json!({
                    "topic": t.topic, "schema": t.schema, "encoding": t.encoding,
                    "messages": t.count, "first_s": secs(t.first), "last_s": secs(t.last),
                    "readable": t.readable(),
                })
            })
            .collect();
        outln!("{}", serde_json::to_string_pretty(&list)?);
        return Ok(());
    }
    let messages: u64 = topics.iter().map(|t| t.count).sum();
    let first = topics.iter().map(|t| t.first).min().map_or(0.0, secs);
    let last = topics.iter().map(|t| t.last).max().map_or(0.0, secs);
    outln!(
        "{}: {messages} messages on {} topics, {first:.1} to {last:.1} s",
        args.file.display(),
        topics.len()
    );
    let width = topics.iter().map(|t| t.topic.chars().count()).max().unwrap_or(0);
    for t in &topics {
        let skipped = if t.readable() {
            String::new()
        } else {
            format!("  (skipped: {} messages, not JSON with a schema)", t.encoding)
        };
        outln!(
            "  {:<width$}  {:<16} {:>7} messages  {:>7.1} to {:>7.1} s{skipped}",
            t.topic,
            t.schema,
            t.count,
            secs(t.first),
            secs(t.last)
        );
    }
    Ok(())
}
