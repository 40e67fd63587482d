//! The relay over real TCP on loopback: every command, watches pushed at the refresh rate, a
//! Python socket client, and bad clients (garbage, a 10 MB line, a thousand connections at
//! once) that get errors or are refused while the robot's blackboard keeps its pace.
#![allow(clippy::unwrap_used)]

use mrt_blackboard::relay::{ClientError, RelayConfig};
use mrt_blackboard::{Blackboard, Relay, RelayClient};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

fn relay(cfg: RelayConfig) -> (Blackboard, Relay) {
    let bb = Blackboard::new(1, Arc::new(mrt_core::WallClock::new()));
    bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
    bb.set("local.var.machine.role", "defender").unwrap();
    let cfg = RelayConfig { addr: SocketAddr::from(([127, 0, 0, 1], 0)), ..cfg };
    let r = Relay::start(bb.clone(), cfg).unwrap();
    (bb, r)
}

fn raw(addr: SocketAddr) -> (BufReader<TcpStream>, TcpStream) {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    (BufReader::new(s.try_clone().unwrap()), s)
}

fn line(r: &mut BufReader<TcpStream>) -> String {
    let mut l = String::new();
    r.read_line(&mut l).unwrap();
    l.trim_end().to_string()
}

#[test]
fn every_command_answers_and_watches_are_pushed() {
    let (bb, relay) = relay(RelayConfig::default());
    let mut c = RelayClient::connect(relay.local_addr(), None).unwrap();
    let got = c.request("GETV local.var.machine.config.def.near-ball").unwrap();
    assert!(got.starts_with("GETV local.var.machine.config.def.near-ball Float 0.8 "), "{got}");
    assert_eq!(
        c.request("SETV local.var.machine.role String \"keeper\"").unwrap(),
        "SETV local.var.machine.role"
    );
    assert_eq!(bb.get::<String>("local.var.machine.role").unwrap(), "keeper");
    let e = c.request("SETV local.var.machine.role Int 3").unwrap_err().to_string();
    assert_eq!(e, "relay: ERR 409 `local.var.machine.role` holds a String, not a Int");
    let e = c.request("GETV local.var.nothing").unwrap_err().to_string();
    assert_eq!(e, "relay: ERR 404 unknown symbol local.var.nothing");
    assert_eq!(
        c.request("LSTV local.*").unwrap(),
        "LSTV 2 local.var.machine.config.def.near-ball local.var.machine.role"
    );
    assert_eq!(c.request("REFR 20").unwrap(), "REFR 20");
    assert_eq!(c.request("ADDW local.var.machine.*").unwrap(), "ADDW local.var.machine.*");
    assert_eq!(c.request("ADDW *.var.team.cost").unwrap(), "ADDW *.var.team.cost");
    assert_eq!(c.request("LSTW").unwrap(), "LSTW 2 local.var.machine.* *.var.team.cost");
    // First push: every watched value; then only what changed.
    let mut first = vec![c.next_push().unwrap(), c.next_push().unwrap()];
    first.sort();
    assert!(
        first[0].starts_with("WATCH local.var.machine.config.def.near-ball Float 0.8 "),
        "{first:?}"
    );
    assert!(first[1].starts_with("WATCH local.var.machine.role String \"keeper\" "), "{first:?}");
    bb.set("*.var.team.cost", 1.5).unwrap();
    assert!(c.next_push().unwrap().starts_with("WATCH *.var.team.cost Float 1.5 "));
    assert_eq!(c.request("DELW *.var.team.cost").unwrap(), "DELW *.var.team.cost");
    assert_eq!(
        c.request("DELW *.var.team.cost").unwrap_err().to_string(),
        "relay: ERR 404 not watched: *.var.team.cost"
    );
    assert_eq!(c.request("CLRW").unwrap(), "CLRW 1");
    assert_eq!(c.request("QUIT").unwrap(), "QUIT");
    assert!(matches!(c.request("LSTW"), Err(ClientError::Closed | ClientError::Io { .. })));
    assert_eq!(relay.stats().ok.load(Ordering::Relaxed), 10);
    assert_eq!(relay.stats().errors.load(Ordering::Relaxed), 3);
}

#[test]
fn a_python_socket_client_talks_to_the_relay() {
    let (bb, relay) = relay(RelayConfig::default());
    let script = r#"
import socket, sys
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])))
f = s.makefile("rw", newline="\n")
for req in ["SETV *.var.team.formation String \"diamond\"", "GETV *.var.team.formation", "BOGUS", "QUIT"]:
    f.write(req + "\n"); f.flush()
    print(f.readline().strip())
"#;
    let out = std::process::Command::new("python3")
        .arg("-c")
        .arg(script)
        .arg(relay.local_addr().port().to_string())
        .output();
    let Ok(out) = out else {
        eprintln!("SKIPPED: python3 is not installed; the Rust client tests cover the protocol");
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(lines[0], "OK SETV *.var.team.formation");
    assert!(
        lines[1].starts_with("OK GETV *.var.team.formation String \"diamond\" "),
        "{}",
        lines[1]
    );
    assert_eq!(lines[2], "ERR 400 unknown command `BOGUS`");
    assert_eq!(lines[3], "OK QUIT");
    assert_eq!(bb.get::<String>("*.var.team.formation").unwrap(), "diamond");
}

#[test]
fn garbage_and_huge_lines_get_errors_and_others_are_served() {
    let (_bb, relay) = relay(RelayConfig::default());
    let (mut r, mut w) = raw(relay.local_addr());
    w.write_all(b"\xff\xfe\x00garbage\n").unwrap();
    assert_eq!(line(&mut r), "ERR 400 a request is UTF-8 text");
    w.write_all(b"GETV local.var.machine.role\n").unwrap();
    assert!(line(&mut r).starts_with("OK GETV"), "still served after garbage");
    // 10 MB without a newline: refused at the line limit, then closed.
    let (mut r2, mut w2) = raw(relay.local_addr());
    let big = vec![b'A'; 10 * 1024 * 1024];
    let _ = w2.write_all(&big); // the relay may close before all of it is sent
    assert_eq!(line(&mut r2), "ERR 413 a request line is at most 4096 bytes");
    let mut rest = Vec::new();
    let _ = r2.read_to_end(&mut rest);
    assert!(rest.is_empty(), "closed after the error");
    // The first client is unharmed.
    w.write_all(b"LSTW\n").unwrap();
    assert_eq!(line(&mut r), "OK LSTW 0");
}

#[test]
fn a_thousand_connections_at_once_are_refused_beyond_the_limit_and_the_robot_keeps_its_pace() {
    let (bb, relay) = relay(RelayConfig { max_clients: 16, ..RelayConfig::default() });
    // The robot: a Member setting and reading its blackboard every millisecond.
    let running = Arc::new(AtomicBool::new(true));
    let cycles = Arc::new(AtomicU64::new(0));
    let robot = {
        let (bb, running, cycles) = (bb.clone(), running.clone(), cycles.clone());
        std::thread::spawn(move || {
            while running.load(Ordering::Relaxed) {
                let n = cycles.fetch_add(1, Ordering::Relaxed);
                bb.set("local.var.machine.cycle", n as i64).unwrap();
                bb.get::<i64>("local.var.machine.cycle").unwrap();
                std::thread::sleep(Duration::from_millis(1));
            }
        })
    };
    let start = std::time::Instant::now();
    let mut conns = Vec::new();
    for _ in 0..1000 {
        match TcpStream::connect(relay.local_addr()) {
            Ok(s) => conns.push(s),
            Err(e) => {
                eprintln!("stopped opening connections at {}: {e}", conns.len());
                break;
            }
        }
    }
    assert!(conns.len() >= 500, "{}", conns.len());
    // Every connection beyond the first 16 is told so and closed.
    let mut refused = 0;
    for s in conns.iter_mut().skip(16) {
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut r = BufReader::new(s.try_clone().unwrap());
        if line(&mut r) == "ERR 503 too many clients" {
            refused += 1;
        }
    }
    assert_eq!(refused, conns.len() - 16);
    assert_eq!(relay.stats().refused.load(Ordering::Relaxed), refused as u64);
    // The 16 served ones still answer.
    let (mut r, mut w) =
        (BufReader::new(conns[3].try_clone().unwrap()), conns[3].try_clone().unwrap());
    w.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    w.write_all(b"GETV local.var.machine.role\n").unwrap();
    assert!(line(&mut r).starts_with("OK GETV"));
    let elapsed = start.elapsed();
    running.store(false, Ordering::Relaxed);
    robot.join().unwrap();
    // The robot thread sleeps 1 ms a cycle: it got through at least a third of the cycles it
    // would have done alone (a loose bound: this checks that it was never blocked, not speed).
    let expected = elapsed.as_secs_f64() * 1000.0;
    let done = cycles.load(Ordering::Relaxed) as f64;
    assert!(done > expected / 3.0, "{done} cycles in {elapsed:?}");
    drop(conns);
    // Slots free again: a new client is served.
    std::thread::sleep(Duration::from_millis(300));
    let mut c = RelayClient::connect(relay.local_addr(), None).unwrap();
    assert!(c.request("LSTW").is_ok());
}

#[test]
fn beyond_loopback_a_token_is_required() {
    let bb = Blackboard::new(1, Arc::new(mrt_core::WallClock::new()));
    let open = RelayConfig { addr: SocketAddr::from(([0, 0, 0, 0], 0)), ..RelayConfig::default() };
    let e = Relay::start(bb.clone(), open.clone()).err().unwrap().to_string();
    assert!(e.contains("give it a shared token"), "{e}");
    let relay = Relay::start(bb, RelayConfig { token: Some("s3cret".into()), ..open }).unwrap();
    let addr = SocketAddr::from(([127, 0, 0, 1], relay.local_addr().port()));
    let (mut r, mut w) = raw(addr);
    w.write_all(b"GETV local.var.x\n").unwrap();
    assert_eq!(line(&mut r), "ERR 401 send AUTH <token> first");
    w.write_all(b"AUTH wrong\n").unwrap();
    assert_eq!(line(&mut r), "ERR 401 wrong token");
    assert_eq!(line(&mut r), "", "closed after a wrong token");
    let mut c = RelayClient::connect(addr, Some("s3cret")).unwrap();
    assert_eq!(c.request("LSTW").unwrap(), "LSTW 0");
}
