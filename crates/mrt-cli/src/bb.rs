//! `mrt bb`: a blackboard with its relay (`serve`), and the relay's client (`get`, `set`,
//! `watch`, `list`). The protocol: `docs/relay-protocol.md`.

use anyhow::{anyhow, bail, Context as _, Result};
use clap::{Args, Subcommand};
use mrt_blackboard::relay::{ClientOptions, RelayClient, RelayConfig, DEFAULT_PORT};
use mrt_blackboard::{Blackboard, Relay};
use mrt_core::printable;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;

/// Where the relay is, and its token.
#[derive(Args)]
pub struct Target {
    /// The relay's address.
    #[arg(long, default_value_t = SocketAddr::from(([127, 0, 0, 1], DEFAULT_PORT)))]
    addr: SocketAddr,
    /// The relay's shared token (needed when it listens beyond this machine).
    #[arg(long, env = "MRT_RELAY_TOKEN", hide_env_values = true)]
    token: Option<String>,
    /// Longest wait for the connection and for each reply, seconds (a watch waits for
    /// changes as long as it takes).
    #[arg(long, default_value_t = 5.0, value_parser = seconds)]
    timeout: f64,
}

/// A positive, finite number of seconds.
fn seconds(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 && s <= 86_400.0 => Ok(s),
        _ => Err(format!("`{text}` is not a number of seconds between 0 and 86400")),
    }
}

/// `mrt bb` commands.
#[derive(Subcommand)]
pub enum BbCommand {
    /// Run a blackboard with its relay until interrupted (initial values from
    /// DIR/config.dat, then DIR/config-ROBOT.dat).
    Serve {
        #[command(flatten)]
        target: Target,
        /// Directory of config.dat and config-ROBOT.dat (ROBOT: the robot ID).
        #[arg(long)]
        config_dir: Option<PathBuf>,
        /// The robot's ID.
        #[arg(long, default_value_t = 1)]
        robot: u32,
        /// Share the `*` and robot-numbered variables with the other robots of the network
        /// this Agora configuration file describes (MRT manual §3.3.1, docs/network.md): the
        /// blackboard's Proxy runs in an Agora with id ROBOT on that network.
        #[arg(long)]
        net: Option<PathBuf>,
    },
    /// Print a variable: `<Type> <value>` and its age in ms.
    Get {
        /// The symbol (`local.var.machine.role`).
        symbol: String,
        #[command(flatten)]
        target: Target,
    },
    /// Set a variable: `mrt bb set local.var.machine.role String '"keeper"'`.
    Set {
        /// The symbol.
        symbol: String,
        /// Int, Float, Bool or String.
        value_type: String,
        /// The value (a String in double quotes).
        value: String,
        #[command(flatten)]
        target: Target,
    },
    /// Print changes of the variables the patterns cover (`local.var.machine.*`).
    Watch {
        /// Symbols or prefixes ending in `.*`.
        #[arg(required = true)]
        patterns: Vec<String>,
        /// Refresh period, 10 to 60000 ms.
        #[arg(long, default_value_t = 500)]
        refresh: u64,
        /// Stop after this many changes (at least 1).
        #[arg(long)]
        count: Option<usize>,
        #[command(flatten)]
        target: Target,
    },
    /// List the symbols on the blackboard (under a pattern) with their values.
    List {
        /// A pattern (`local.*`); all symbols without it.
        pattern: Option<String>,
        #[command(flatten)]
        target: Target,
    },
}

/// Puts the blackboard's Proxy on the network `file` describes (an Agora with id `robot`,
/// run on its own threads); the link lives as long as the returned value.
#[cfg(feature = "net")]
fn share(bb: &Blackboard, file: &std::path::Path, robot: u32) -> Result<mrt_net::NetLink> {
    use mrt_dcdt::{Activation, Agora};
    let mut agora = Agora::from_config(file, robot)?;
    let every = Activation::Periodic(std::time::Duration::from_millis(10));
    let proxy = agora.add_member(mrt_blackboard::Proxy::new(bb.clone()), every);
    agora.activate_member(proxy)?;
    let link = mrt_net::connect(&agora)?;
    std::thread::Builder::new().name("mrt-bb-proxy".into()).spawn(move || {
        if let Err(e) = agora.lets_work() {
            eprintln!("mrt bb serve: the blackboard's Agora stopped: {e}");
        }
    })?;
    Ok(link)
}

#[cfg(not(feature = "net"))]
fn share(_: &Blackboard, _: &std::path::Path, _: u32) -> Result<()> {
    bail!("--net: this mrt was built without networking (build it with the default features)")
}

fn connect(t: &Target) -> Result<RelayClient> {
    let wait = std::time::Duration::from_secs_f64(t.timeout);
    let options =
        ClientOptions { connect_timeout: wait, reply_timeout: wait, ..Default::default() };
    RelayClient::connect_with(t.addr, t.token.as_deref(), options).with_context(|| {
        format!("cannot reach the relay at {} (is `mrt bb serve` or a robot running?)", t.addr)
    })
}

/// Runs one `mrt bb` command. What comes from the relay, errors included, is printed with
/// its control characters escaped ([`printable`]).
pub fn run(command: BbCommand) -> Result<()> {
    run_command(command).map_err(|e| anyhow!(printable(&format!("{e:#}"))))
}

fn run_command(command: BbCommand) -> Result<()> {
    match command {
        BbCommand::Serve { target, config_dir, robot, net } => {
            let bb = Blackboard::new(robot, Arc::new(mrt_core::WallClock::new()));
            if let Some(dir) = &config_dir {
                let read = mrt_blackboard::config::load_dir(&bb, dir)?;
                if read.is_empty() {
                    bail!("{}: neither config.dat nor config-{robot}.dat is there", dir.display());
                }
                for f in read {
                    eprintln!("loaded {}", f.display());
                }
            }
            let cfg =
                RelayConfig { addr: target.addr, token: target.token, ..RelayConfig::default() };
            let _shared = match &net {
                Some(file) => Some(share(&bb, file, robot)?),
                None => None,
            };
            let relay = Relay::start(bb, cfg)?;
            outln!("relay of robot {robot} listening on {}", relay.local_addr());
            loop {
                std::thread::park();
            }
        }
        BbCommand::Get { symbol, target } => {
            let reply = connect(&target)?.request(&format!("GETV {symbol}"))?;
            let rest = reply.strip_prefix("GETV ").and_then(|r| r.strip_prefix(symbol.as_str()));
            outln!("{}", printable(rest.unwrap_or(&reply).trim()));
        }
        BbCommand::Set { symbol, value_type, value, target } => {
            connect(&target)?.request(&format!("SETV {symbol} {value_type} {value}"))?;
        }
        BbCommand::Watch { patterns, refresh, count, target } => {
            // Checked here, before connecting, with the relay's own limits.
            if !(10..=60_000).contains(&refresh) {
                bail!("--refresh must be 10 to 60000 ms, not {refresh}");
            }
            if count == Some(0) {
                bail!("--count must be at least 1 (without it, watch until interrupted)");
            }
            let mut c = connect(&target)?;
            c.request(&format!("REFR {refresh}"))?;
            for p in &patterns {
                c.request(&format!("ADDW {p}"))?;
            }
            let mut seen = 0;
            while count.is_none_or(|n| seen < n) {
                let line = c.next_push()?;
                outln!("{}", printable(line.strip_prefix("WATCH ").unwrap_or(&line)));
                seen += 1;
            }
        }
        BbCommand::List { pattern, target } => {
            let mut c = connect(&target)?;
            // Page by page (`LSTV <pattern> <after>`), so any number of symbols is listed
            // within the relay's reply size.
            let pattern = pattern.as_deref().unwrap_or("*");
            let mut after = "-".to_string();
            loop {
                let reply = c.request(&format!("LSTV {pattern} {after}"))?;
                let symbols: Vec<String> =
                    reply.split_whitespace().skip(2).map(str::to_string).collect();
                let Some(last) = symbols.last().cloned() else { break };
                for symbol in symbols {
                    let v = c.request(&format!("GETV {symbol}"));
                    let shown = match &v {
                        Ok(r) => r.strip_prefix("GETV ").unwrap_or(r).to_string(),
                        Err(_) => format!("{symbol} (talk queue)"),
                    };
                    outln!("{}", printable(&shown));
                }
                after = last;
            }
        }
    }
    Ok(())
}
