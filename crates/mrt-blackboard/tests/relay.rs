//! The relay over real TCP on loopback: every command, watches pushed at the refresh rate, a
//! Python socket client, and bad clients (garbage, a 10 MB line, a thousand connections at
//! once) that get errors or are refused while a robot (an Agora using the blackboard every
//! millisecond) keeps its cycle rate.
#![allow(clippy::unwrap_used)]

use mrt_blackboard::relay::{ClientError, RelayConfig};
use mrt_blackboard::{Blackboard, Proxy, Relay, RelayClient};
use mrt_dcdt::{Activation, Agora, Context, Member, MemberError, ShutdownHandle};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

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
    let at = format!("relay at {}: ", relay.local_addr());
    let e = c.request("SETV local.var.machine.role Int 3").unwrap_err().to_string();
    assert_eq!(e, format!("{at}ERR 409 `local.var.machine.role` holds a String, not a Int"));
    let e = c.request("GETV local.var.nothing").unwrap_err().to_string();
    assert_eq!(e, format!("{at}ERR 404 unknown symbol local.var.nothing"));
    assert_eq!(
        c.request("LSTV local.*").unwrap(),
        "LSTV 2 local.var.machine.config.def.near-ball local.var.machine.role"
    );
    // Below the shortest period (100 ms by default), REFR gets the shortest and says so.
    assert_eq!(c.request("REFR 20").unwrap(), "REFR 100");
    assert_eq!(c.request("REFR 150").unwrap(), "REFR 150");
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
        format!("{at}ERR 404 not watched: *.var.team.cost")
    );
    assert_eq!(c.request("CLRW").unwrap(), "CLRW 1");
    assert_eq!(c.request("QUIT").unwrap(), "QUIT");
    assert!(matches!(c.request("LSTW"), Err(ClientError::Closed(_) | ClientError::Io { .. })));
    assert_eq!(relay.stats().ok.load(Ordering::Relaxed), 11);
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

/// Uses the blackboard every millisecond, as a robot's behavior would.
struct Pace {
    bb: Blackboard,
    cycles: Arc<AtomicU64>,
}

impl Member for Pace {
    fn do_your_job(&mut self, _: &mut Context<'_>) -> Result<(), MemberError> {
        let n = self.cycles.fetch_add(1, Ordering::Relaxed) + 1;
        self.bb.set("local.var.machine.cycle", n as i64)?;
        self.bb.get::<i64>("local.var.machine.cycle")?;
        Ok(())
    }
}

/// A robot: an Agora on its own threads (`lets_work`) with the blackboard's Proxy and a
/// Member running every millisecond.
struct Robot {
    cycles: Arc<AtomicU64>,
    stop: ShutdownHandle,
    thread: std::thread::JoinHandle<()>,
}

impl Robot {
    fn start(bb: &Blackboard) -> Robot {
        let mut agora = Agora::builder(1).build().unwrap();
        let cycles = Arc::new(AtomicU64::new(0));
        let every_ms = Activation::Periodic(Duration::from_millis(1));
        let pace = agora.add_member(Pace { bb: bb.clone(), cycles: cycles.clone() }, every_ms);
        let proxy = agora.add_member(Proxy::new(bb.clone()), every_ms);
        agora.activate_member(pace).unwrap();
        agora.activate_member(proxy).unwrap();
        let stop = agora.shutdown_handle();
        let thread = std::thread::spawn(move || {
            agora.lets_work().unwrap();
        });
        Robot { cycles, stop, thread }
    }

    /// Cycles per second while `f` runs.
    fn rate_during(&self, f: impl FnOnce()) -> f64 {
        let (n0, t0) = (self.cycles.load(Ordering::Relaxed), Instant::now());
        f();
        (self.cycles.load(Ordering::Relaxed) - n0) as f64 / t0.elapsed().as_secs_f64()
    }

    fn stop(self) {
        self.stop.shutdown();
        self.thread.join().unwrap();
    }
}

#[test]
fn garbage_a_huge_line_and_a_thousand_connections_leave_the_robot_at_its_cycle_rate() {
    let (bb, relay) = relay(RelayConfig { max_clients: 16, ..RelayConfig::default() });
    let robot = Robot::start(&bb);
    std::thread::sleep(Duration::from_millis(100));
    let quiet = robot.rate_during(|| std::thread::sleep(Duration::from_millis(500)));
    let mut conns = Vec::new();
    let abused = robot.rate_during(|| {
        // A thousand connections at once.
        for _ in 0..1000 {
            match TcpStream::connect(relay.local_addr()) {
                Ok(s) => conns.push(s),
                Err(e) => {
                    eprintln!("stopped opening connections at {}: {e}", conns.len());
                    break;
                }
            }
        }
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
        // Garbage, then a 10 MB line, from two of the served clients.
        let (mut r, mut w) = (BufReader::new(conns[0].try_clone().unwrap()), &conns[0]);
        w.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        w.write_all(b"\x00\x01 GETV\xff\n").unwrap();
        assert!(line(&mut r).starts_with("ERR 400"));
        let (mut r, mut w) = (BufReader::new(conns[1].try_clone().unwrap()), &conns[1]);
        w.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let _ = w.write_all(&vec![b'A'; 10 * 1024 * 1024]); // closed before the end of it
        assert!(line(&mut r).starts_with("ERR 413"));
    });
    assert!(conns.len() >= 500, "{}", conns.len());
    // The 16 served ones still answer, with the robot's latest cycle.
    let (mut r, mut w) =
        (BufReader::new(conns[3].try_clone().unwrap()), conns[3].try_clone().unwrap());
    w.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    w.write_all(b"GETV local.var.machine.cycle\n").unwrap();
    assert!(line(&mut r).starts_with("OK GETV local.var.machine.cycle Int "));
    // Measured here: 990-1000 cycles/s quiet and under abuse alike. Half is the bound: a robot
    // blocked by the relay, even briefly, falls far below it; a busy test machine does not.
    eprintln!("robot: {quiet:.0} cycles/s quiet, {abused:.0} cycles/s while the relay was abused");
    assert!(abused >= 0.5 * quiet, "{abused:.0} cycles/s under abuse, {quiet:.0} quiet");
    robot.stop();
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
