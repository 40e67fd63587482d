//! From the manual's Agora configuration file (§3.3.1) to zenoh endpoints.

use mrt_dcdt::config::{AgoraConfig, Channel, ChannelMode};
use std::net::IpAddr;

/// How an Agora joins the network.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NetConfig {
    /// zenoh endpoints to listen on (`tcp/127.0.0.1:7447`).
    pub listen: Vec<String>,
    /// zenoh endpoints to connect to.
    pub connect: Vec<String>,
    /// Multicast scouting group (`224.0.0.224:7446`); `None`: no multicast scouting.
    pub multicast: Option<String>,
    /// Whether peers learn of each other through the peers they know (gossip) and connect to
    /// them directly. Off for static links across networks that cannot reach each other.
    pub gossip: bool,
    /// A bridge: forwards what it receives (a zenoh router).
    pub bridge: bool,
}

/// Why the network cannot be joined.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum NetError {
    /// A `ser` channel's device field is not `<path>[,baudrate=<n>][,connect]`.
    #[error("serial channel `{device}`: {reason}")]
    Serial {
        /// The device field as written.
        device: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The Agora was not built from a configuration file.
    #[error("Agora {0} is STANDALONE: build it with Agora::from_config(file, id) to put it on a network")]
    Standalone(u32),
    /// zenoh refused the configuration or could not open the session.
    #[error("zenoh: {0}")]
    Zenoh(String),
}

/// The baud rate of a serial line unless its device field says otherwise.
pub const DEFAULT_BAUD_RATE: u32 = 115_200;

/// The baud rates a serial line's device field may give (what serial drivers offer).
pub const BAUD_RATES: std::ops::RangeInclusive<u32> = 50..=4_000_000;

/// zenoh's endpoint for a `ser` line's device field `<path>[,baudrate=<n>][,connect]`, and
/// whether this end opens the line (`connect`) or waits for the other end to open it (the
/// default). A serial line joins exactly two Agoras; zenoh needs one end of it to listen and
/// the other to connect, which the manual's line does not say: write `connect` on one end.
fn serial_endpoint(device: &str) -> Result<(String, bool), NetError> {
    let bad = |reason: String| NetError::Serial { device: device.to_string(), reason };
    let mut fields = device.split(',');
    let path = fields.next().unwrap_or_default();
    if path.is_empty() {
        return Err(bad("no device path before the options".into()));
    }
    let (mut baud, mut connect) = (DEFAULT_BAUD_RATE, false);
    for option in fields {
        match option.split_once('=') {
            None if option == "connect" => connect = true,
            None if option == "listen" => connect = false,
            Some(("baudrate", n)) => {
                let (low, high) = (BAUD_RATES.start(), BAUD_RATES.end());
                baud = n.parse().ok().filter(|b| BAUD_RATES.contains(b)).ok_or_else(|| {
                    bad(format!("baudrate `{n}` is not a rate of {low} to {high}"))
                })?
            }
            _ => {
                return Err(bad(format!(
                    "unknown option `{option}` (known: baudrate=<n>, connect, listen)"
                )))
            }
        }
    }
    Ok((format!("serial/{path}#baudrate={baud}"), connect))
}

fn endpoint(ip: IpAddr, port: u16) -> String {
    match ip {
        IpAddr::V4(v4) => format!("tcp/{v4}:{port}"),
        IpAddr::V6(v6) => format!("tcp/[{v6}]:{port}"),
    }
}

/// Whether the file's Agora lives on loopback and talks only to loopback peers, all named by
/// static `ip` lines (at least one; a `ser` line leaves the machine).
fn loopback_only(cfg: &AgoraConfig) -> bool {
    cfg.local_ip.is_loopback()
        && !cfg.channels.is_empty()
        && cfg.channels.iter().all(|c| match c {
            Channel::Ip { local_addr, remote_addr, .. } => {
                local_addr.is_loopback() && remote_addr.is_loopback()
            }
            Channel::Serial { .. } => false,
        })
}

impl NetConfig {
    /// The endpoints of a configuration file (module table in the crate doc).
    pub fn from_agora_config(cfg: &AgoraConfig) -> Result<NetConfig, NetError> {
        // The network line's port is the discovery port (§3.3.1): the Agora itself listens
        // on an ephemeral port that scouting advertises, so that several Agoras of one
        // machine can share the line. `ip` channels add their fixed ports.
        let mut net = NetConfig {
            listen: vec![endpoint(cfg.local_ip, 0)],
            connect: Vec::new(),
            multicast: Some(match cfg.multicast {
                IpAddr::V4(m) => format!("{m}:{}", cfg.port),
                IpAddr::V6(m) => format!("[{m}]:{}", cfg.port),
            }),
            gossip: true,
            bridge: false,
        };
        for c in &cfg.channels {
            match c {
                Channel::Ip { mode, local_addr, local_port, remote_addr, remote_port, .. } => {
                    let l = endpoint(*local_addr, *local_port);
                    if !net.listen.contains(&l) {
                        net.listen.push(l);
                    }
                    net.connect.push(endpoint(*remote_addr, *remote_port));
                    net.bridge |= *mode == ChannelMode::Bridge;
                }
                Channel::Serial { mode, device, .. } => {
                    let (e, connect) = serial_endpoint(device)?;
                    if connect {
                        net.connect.push(e);
                    } else {
                        net.listen.push(e);
                    }
                    net.bridge |= *mode == ChannelMode::Bridge;
                }
            }
        }
        // Static links are for networks that cannot see each other: the named peers only.
        if !net.connect.is_empty() {
            net.gossip = false;
        }
        // On loopback with static links to loopback only (the distributed simulator's robots),
        // every peer is named and nothing beyond this machine may be reached: no scouting.
        // zenoh's scouting binds UDP sockets on every interface (0.0.0.0) and joins the group
        // on the LAN's interfaces, which a loopback-only Agora must not do.
        if loopback_only(cfg) {
            net.multicast = None;
        }
        Ok(net)
    }

    /// An Agora on this machine listening on `port` and connecting to `peers` (ports), without
    /// multicast or gossip: tests, benchmarks and the distributed simulator.
    pub fn loopback(port: u16, peers: &[u16]) -> NetConfig {
        NetConfig {
            listen: vec![format!("tcp/127.0.0.1:{port}")],
            connect: peers.iter().map(|p| format!("tcp/127.0.0.1:{p}")).collect(),
            multicast: None,
            gossip: false,
            bridge: false,
        }
    }

    /// The zenoh configuration (peer, or router for a bridge; endpoints; scouting).
    pub fn zenoh_config(&self) -> Result<zenoh::Config, NetError> {
        let mut c = zenoh::Config::default();
        let json = |v: &Vec<String>| {
            let items: Vec<String> = v.iter().map(|e| format!("\"{e}\"")).collect();
            format!("[{}]", items.join(","))
        };
        let set = |c: &mut zenoh::Config, k: &str, v: &str| {
            c.insert_json5(k, v).map_err(|e| NetError::Zenoh(format!("{k} = {v}: {e}")))
        };
        set(&mut c, "mode", if self.bridge { "\"router\"" } else { "\"peer\"" })?;
        set(&mut c, "listen/endpoints", &json(&self.listen))?;
        set(&mut c, "connect/endpoints", &json(&self.connect))?;
        set(
            &mut c,
            "scouting/multicast/enabled",
            if self.multicast.is_some() { "true" } else { "false" },
        )?;
        if let Some(m) = &self.multicast {
            set(&mut c, "scouting/multicast/address", &format!("\"{m}\""))?;
        }
        set(&mut c, "scouting/gossip/enabled", if self.gossip { "true" } else { "false" })?;
        // Opening a peer session waits until every static peer is connected and has sent its
        // declarations, for at most `scouting/delay` (500 ms by default). When two peers dial
        // each other at once (a robot that starts again beside teammates that keep retrying
        // it), zenoh keeps one of the two links and the wait runs to its end although both are
        // connected. 100 ms bounds that; a program that must not lose its first messages
        // waits for its receivers' interest instead (`NetLink::wait_until`).
        if self.multicast.is_none() {
            set(&mut c, "scouting/delay", "100")?;
        }
        // Keep trying the static peers: a restarted robot is found again.
        set(&mut c, "connect/timeout_ms", "-1")?;
        set(
            &mut c,
            "connect/retry",
            "{period_init_ms: 100, period_max_ms: 500, period_increase_factor: 2}",
        )?;
        // The end that opens a serial line sends one greeting and waits for the answer; if the
        // other end was not listening yet, only zenoh's open timeout (10 s by default) ends the
        // wait and lets the retry greet again. Agoras start in any order: retry every second.
        if self.connect.iter().any(|e| e.starts_with("serial/")) {
            set(&mut c, "transport/unicast/open_timeout", "1000")?;
        }
        // A robot needs latency more than big batches. When zenoh sees back-pressure it holds a
        // partial batch for up to `time_limit` ms hoping it fills, and its timer (tokio's, 1 ms
        // resolution) made that hold 1-2 ms at the end of every burst. At 0 a batch leaves as
        // soon as the link is free; messages still batch while it is busy (the round trip nearly
        // halves, and the 64 B stream nearly doubles its rate).
        set(&mut c, "transport/link/tx/queue/batching/time_limit", "0")?;
        set(&mut c, "connect/exit_on_failure", "false")?;
        set(&mut c, "listen/exit_on_failure", "true")?;
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_manual_example_becomes_endpoints() {
        let text = "192.168.0.1 225.0.0.1 2003\n\
                    PostOffice: SLWB\n\
                    ip link 0 192.168.0.1 3000 192.168.1.1 3000\n";
        let cfg = AgoraConfig::parse(text, "dcdt.cfg").unwrap();
        let net = NetConfig::from_agora_config(&cfg).unwrap();
        assert_eq!(net.listen, ["tcp/192.168.0.1:0", "tcp/192.168.0.1:3000"]);
        assert_eq!(net.connect, ["tcp/192.168.1.1:3000"]);
        assert_eq!(net.multicast.as_deref(), Some("225.0.0.1:2003"));
        assert!(!net.bridge && !net.gossip);
        net.zenoh_config().unwrap();
        let bridge = AgoraConfig::parse(
            "10.0.0.1 224.0.0.5 2003\nip bridge 1 10.0.0.1 3001 10.0.1.1 3001\n",
            "b.cfg",
        )
        .unwrap();
        assert!(NetConfig::from_agora_config(&bridge).unwrap().bridge);
        let lan = AgoraConfig::parse("10.0.0.1 224.0.0.5 2003\n", "lan.cfg").unwrap();
        let lan = NetConfig::from_agora_config(&lan).unwrap();
        assert!(lan.gossip && lan.connect.is_empty(), "discovery on the LAN");
    }

    /// The distributed simulator's robots (loopback, static links to loopback
    /// peers) scouted by multicast, which binds UDP sockets on 0.0.0.0. They do not scout any
    /// more; an Agora on loopback without static links still discovers its peers by scouting,
    /// and so does one whose links leave the machine.
    #[test]
    fn batches_are_not_held_back_to_fill() {
        let c = NetConfig::loopback(7447, &[]).zenoh_config().unwrap();
        assert_eq!(c.get_json("transport/link/tx/queue/batching/time_limit").unwrap(), "0");
        assert_eq!(c.get_json("transport/link/tx/queue/batching/enabled").unwrap(), "true");
    }

    #[test]
    fn loopback_with_static_loopback_links_does_not_scout() {
        let net = |text: &str| {
            NetConfig::from_agora_config(&AgoraConfig::parse(text, "l.cfg").unwrap()).unwrap()
        };
        let robot = net("127.0.0.1 224.0.0.224 9000\nip link 0 127.0.0.1 7001 127.0.0.1 7100\n");
        assert_eq!(robot.multicast, None);
        assert_eq!(robot.listen, ["tcp/127.0.0.1:0", "tcp/127.0.0.1:7001"]);
        assert_eq!(robot.connect, ["tcp/127.0.0.1:7100"]);
        let c = robot.zenoh_config().unwrap();
        assert_eq!(c.get_json("scouting/multicast/enabled").unwrap(), "false");
        let same_machine = net("127.0.0.1 224.0.0.224 7446\n");
        assert_eq!(same_machine.multicast.as_deref(), Some("224.0.0.224:7446"));
        let leaves = net("127.0.0.1 224.0.0.224 9000\nip link 0 127.0.0.1 7001 10.0.0.2 7100\n");
        assert!(leaves.multicast.is_some());
        let lan = net("10.0.0.1 224.0.0.224 9000\nip link 0 127.0.0.1 7001 127.0.0.1 7100\n");
        assert!(lan.multicast.is_some());
    }

    fn serial(device: &str) -> Result<NetConfig, NetError> {
        let text = format!("10.0.0.1 224.0.0.5 2003\nser link 0 {device}\n");
        NetConfig::from_agora_config(&AgoraConfig::parse(&text, "s.cfg").unwrap())
    }

    #[test]
    fn a_baud_rate_outside_what_drivers_offer_is_refused() {
        for bad in ["0", "49", "4000001", "99999999999999999999", "-1", "fast", ""] {
            let e = serial(&format!("/dev/ttyS0,baudrate={bad}")).unwrap_err().to_string();
            assert!(e.contains("is not a rate of 50 to 4000000"), "{bad}: {e}");
        }
        for good in ["50", "9600", "4000000"] {
            assert!(serial(&format!("/dev/ttyS0,baudrate={good}")).is_ok(), "{good}");
        }
    }

    #[test]
    fn a_serial_line_listens_at_one_end_and_connects_at_the_other() {
        let waits = serial("/dev/ttyS0").unwrap();
        assert_eq!(waits.listen, ["tcp/10.0.0.1:0", "serial//dev/ttyS0#baudrate=115200"]);
        assert!(waits.connect.is_empty() && waits.gossip);
        let opens = serial("/dev/ttyUSB1,baudrate=57600,connect").unwrap();
        assert_eq!(opens.connect, ["serial//dev/ttyUSB1#baudrate=57600"]);
        assert!(!opens.gossip, "a static link: the named peer only");
        opens.zenoh_config().unwrap();
        waits.zenoh_config().unwrap();
        for (bad, says) in [
            ("/dev/ttyS0,baudrate=fast", "`fast` is not a rate of 50 to 4000000"),
            ("/dev/ttyS0,parity=odd", "unknown option `parity=odd`"),
            (",connect", "no device path"),
        ] {
            let e = serial(bad).unwrap_err().to_string();
            assert!(e.contains(bad) && e.contains(says), "{e}");
        }
    }
}
