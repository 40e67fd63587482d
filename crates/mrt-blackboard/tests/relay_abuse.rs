//! A relay that serves under abuse: a hostile tester locked every client
//! out with 32 clients trickling one byte every 2 s, grew the blackboard to 343 MB with a
//! million `SETV`s of new names and got a 192 MB `LSTV` reply, drove the relay to 2 cores and
//! 1 GB with 31 clients watching at `REFR 10`, authenticated with an empty token, could not
//! use a token with a space, and guessed tokens as fast as it could connect. Each test below
//! reproduces one of those on loopback and pins what the relay does now. Every wait is bounded
//! and no test asserts how fast anything is (only lower bounds on deliberate delays).
#![allow(clippy::unwrap_used)]

use mrt_blackboard::relay::{ClientError, RelayConfig, RelayError};
use mrt_blackboard::{BbLimits, Blackboard, Relay, RelayClient};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

fn board(limits: BbLimits) -> Blackboard {
    Blackboard::with_limits(1, Arc::new(mrt_core::WallClock::new()), limits)
}

fn start(bb: &Blackboard, cfg: RelayConfig) -> Relay {
    let cfg = RelayConfig { addr: SocketAddr::from(([127, 0, 0, 1], 0)), ..cfg };
    Relay::start(bb.clone(), cfg).unwrap()
}

fn raw(addr: SocketAddr) -> (BufReader<TcpStream>, TcpStream) {
    let s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    (BufReader::new(s.try_clone().unwrap()), s)
}

fn line(r: &mut BufReader<TcpStream>) -> String {
    let mut l = String::new();
    let _ = r.read_line(&mut l);
    l.trim_end().to_string()
}

/// Waits (at most 20 s) until `f` holds.
fn eventually(what: &str, mut f: impl FnMut() -> bool) {
    let end = Instant::now() + Duration::from_secs(20);
    while !f() {
        assert!(Instant::now() < end, "never happened: {what}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Bullet 1: clients trickling one byte at a time held every slot for as long as they liked.
/// Now a line must end within `line_timeout` of its first byte: the tricklers are told
/// `ERR 408` and closed, and a fresh client is served. One address cannot take every slot.
#[test]
fn trickling_clients_are_dropped_and_a_fresh_client_is_served() {
    let bb = board(BbLimits::default());
    let cfg = RelayConfig {
        max_clients: 4,
        line_timeout: Duration::from_millis(300),
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    let addr = relay.local_addr();
    let tricklers: Vec<_> = (0..4).map(|_| raw(addr)).collect();
    eventually("4 clients served", || relay.clients() == 4);
    let (mut r, _w) = raw(addr);
    assert_eq!(line(&mut r), "ERR 503 too many clients", "the slots are taken");
    // Each trickler sends one byte every 50 ms, a line that never ends.
    let threads: Vec<_> = tricklers
        .iter()
        .map(|(_, w)| {
            let mut w = w.try_clone().unwrap();
            std::thread::spawn(move || {
                let end = Instant::now() + Duration::from_secs(30);
                while Instant::now() < end && w.write_all(b"G").is_ok() {
                    std::thread::sleep(Duration::from_millis(50));
                }
            })
        })
        .collect();
    for (mut r, _) in tricklers {
        assert_eq!(line(&mut r), "ERR 408 a request line must end within 0.3 s of its first byte");
        let mut rest = Vec::new();
        let _ = r.read_to_end(&mut rest);
    }
    for t in threads {
        t.join().unwrap();
    }
    assert_eq!(relay.stats().too_slow.load(Ordering::Relaxed), 4);
    // Their places are free: a fresh client is served.
    let mut c = RelayClient::connect(addr, None).unwrap();
    assert_eq!(c.request("LSTW").unwrap(), "LSTW 0");
}

/// Silent connections held every place: 64 idle loopback connections (the per-address limit,
/// which every local program shares) locked every local client out for the 10 min idle
/// timeout. Now loopback is limited per client: a connection must send its first request
/// within `first_request_timeout`, and the per-address limit applies to remote addresses only.
#[test]
fn silent_local_connections_cannot_lock_local_clients_out() {
    let bb = board(BbLimits::default());
    let cfg = RelayConfig {
        max_clients: 8,
        max_clients_per_address: 2,
        first_request_timeout: Duration::from_millis(300),
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    let addr = relay.local_addr();
    // More loopback clients than one address's share are served.
    let mut talking: Vec<RelayClient> =
        (0..3).map(|_| RelayClient::connect(addr, None).unwrap()).collect();
    for c in &mut talking {
        assert_eq!(c.request("LSTW").unwrap(), "LSTW 0");
    }
    // Five silent ones fill the rest; a ninth is refused while they hold their places.
    let silent: Vec<_> = (0..5).map(|_| raw(addr)).collect();
    eventually("8 clients served", || relay.clients() == 8);
    let (mut r, _w) = raw(addr);
    assert_eq!(line(&mut r), "ERR 503 too many clients");
    // The silent ones are closed at the first-request deadline; the talking ones stay.
    for (mut r, _) in silent {
        assert_eq!(line(&mut r), "ERR 408 no request within 0.3 s of connecting");
    }
    eventually("the silent clients are gone", || relay.clients() == 3);
    let mut fresh = RelayClient::connect(addr, None).unwrap();
    assert_eq!(fresh.request("LSTW").unwrap(), "LSTW 0");
    for c in &mut talking {
        assert_eq!(c.request("LSTW").unwrap(), "LSTW 0", "a client that spoke is not closed");
    }
}

/// Bullet 2: a million `SETV`s of new names took 343 MB and `LSTV` answered with a 192 MB
/// line. Now new symbols, string values and replies are capped, each refusal a clear `ERR`;
/// `LSTV` past the reply size is refused and pages instead.
#[test]
fn symbols_values_and_replies_are_capped() {
    let limits =
        BbLimits { max_symbols: 60, max_guest_symbols: 40, max_string: 64, ..BbLimits::default() };
    let bb = board(limits);
    let relay = start(&bb, RelayConfig { max_reply: 256, ..RelayConfig::default() });
    let mut c = RelayClient::connect(relay.local_addr(), None).unwrap();
    let at = format!("relay at {}: ", relay.local_addr());
    for i in 0..40 {
        c.request(&format!("SETV local.var.flood.s{i:02} Int {i}")).unwrap();
    }
    let e = c.request("SETV local.var.flood.s40 Int 40").unwrap_err().to_string();
    assert_eq!(
        e,
        format!("{at}ERR 507 the blackboard is full: `local.var.flood.s40` does not fit (at most 40 symbols from a guest)")
    );
    assert_eq!(bb.len(), 40);
    // The robot's own Members still have room.
    bb.set("local.var.own", 1).unwrap();
    // A value past `max_string`: refused, the connection stays.
    let e =
        c.request(&format!("SETV local.var.flood.s00 String \"{}\"", "x".repeat(65))).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("{at}ERR 413 `local.var.flood.s00`: a string is at most 64 bytes, this one has 65")
    );
    assert!(c
        .request("GETV local.var.flood.s00")
        .unwrap()
        .starts_with("GETV local.var.flood.s00 Int 0 "));
    // 41 symbols of ~19 bytes do not fit in a reply of 256 bytes.
    let e = c.request("LSTV local.*").unwrap_err().to_string();
    assert_eq!(
        e,
        format!("{at}ERR 413 the symbols do not fit in one reply of 256 bytes: page them with LSTV local.* - and then LSTV local.* <last symbol received>")
    );
    // A narrower pattern still gets the old one-line answer.
    assert_eq!(c.request("LSTV local.var.own").unwrap(), "LSTV 1 local.var.own");
    // Paging: every symbol once, in order, each page within the reply size.
    let (mut all, mut after, mut pages) = (Vec::<String>::new(), "-".to_string(), 0);
    loop {
        let page = c.request(&format!("LSTV * {after}")).unwrap();
        assert!(page.len() + 3 <= 256, "{page}");
        let words: Vec<&str> = page.split(' ').collect();
        let n: usize = words[1].parse().unwrap();
        assert_eq!(words.len(), n + 2);
        if n == 0 {
            break;
        }
        all.extend(words[2..].iter().map(|s| s.to_string()));
        after = all.last().unwrap().clone();
        pages += 1;
    }
    assert!(pages >= 3, "{pages}");
    let mut sorted = all.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!((all.len(), sorted), (41, all));
}

/// Bullet 3: 31 clients with overlapping watches at `REFR 10` took 2 cores and 1 GB. Now the
/// refresh period has a floor, watches are capped per client and in total, and each client
/// gets at most `max_pushes` lines a period (the rest wait, up to `max_deferred`, then are
/// dropped and counted).
#[test]
fn watches_and_pushes_are_budgeted() {
    let bb = board(BbLimits::default());
    for i in 0..22 {
        bb.set(&format!("local.var.s{i:02}"), i).unwrap();
    }
    let cfg = RelayConfig {
        max_total_watches: 3,
        max_pushes: 5,
        max_deferred: 10,
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    let addr = relay.local_addr();
    let at = format!("relay at {addr}: ");
    let mut a = RelayClient::connect(addr, None).unwrap();
    assert_eq!(a.request("REFR 10").unwrap(), "REFR 100", "the shortest period is 100 ms");
    a.request("ADDW local.*").unwrap();
    let mut b = RelayClient::connect(addr, None).unwrap();
    b.request("ADDW *.var.x").unwrap();
    b.request("ADDW *.var.z").unwrap();
    let e = b.request("ADDW *.var.y").unwrap_err().to_string();
    assert_eq!(e, format!("{at}ERR 429 the relay holds at most 3 watches of all clients"));
    // 22 symbols to push: 10 wait (5 a period), 12 are dropped and counted.
    let mut got = Vec::new();
    for _ in 0..10 {
        got.push(a.next_push().unwrap().split(' ').nth(1).unwrap().to_string());
    }
    let want: Vec<String> = (0..10).map(|i| format!("local.var.s{i:02}")).collect();
    assert_eq!(got, want, "each symbol once, in order");
    assert_eq!(relay.stats().push_dropped.load(Ordering::Relaxed), 12);
    // A dropped symbol is pushed when it changes again.
    bb.set("local.var.s15", 150).unwrap();
    assert!(a.next_push().unwrap().starts_with("WATCH local.var.s15 Int 150 "));
    // Watches are given back when a client leaves.
    a.request("QUIT").unwrap();
    drop(a);
    eventually("a's watches given back", || relay.watches() == 2);
    assert_eq!(b.request("ADDW *.var.y").unwrap(), "ADDW *.var.y");
}

/// Bullet 3 (buffers): a client that watches a lot and never reads used to leave the relay
/// writing into a full socket. Now it is dropped after `write_timeout` (counted), and its
/// place is free again.
#[test]
fn a_client_that_does_not_read_is_dropped() {
    let bb = board(BbLimits::default());
    let big = "x".repeat(1000);
    for i in 0..400 {
        bb.set(&format!("local.var.s{i:03}"), big.as_str()).unwrap();
    }
    let cfg = RelayConfig {
        write_timeout: Duration::from_millis(200),
        max_pushes_per_second: 1_000_000,
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    let (_r, mut w) = raw(relay.local_addr());
    w.write_all(b"REFR 100\nADDW local.*\n").unwrap();
    // Change everything, again and again, until the relay gives up on the client.
    let end = Instant::now() + Duration::from_secs(60);
    let mut n = 0;
    while relay.stats().not_reading.load(Ordering::Relaxed) == 0 {
        assert!(Instant::now() < end, "the relay kept writing to a client that never reads");
        n += 1;
        for i in 0..400 {
            bb.set(&format!("local.var.s{i:03}"), format!("{n}{big}").as_str()).unwrap();
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    eventually("its place given back", || relay.clients() == 0);
    let mut c = RelayClient::connect(relay.local_addr(), None).unwrap();
    assert_eq!(c.request("LSTW").unwrap(), "LSTW 0");
}

/// Bullets 4 and 5: an empty token passed the check for listening beyond loopback, and a
/// token with a space could never authenticate (`AUTH` takes one word). Both are refused at
/// startup now, by the client too; an empty `AUTH` never authenticates.
#[test]
fn unusable_tokens_are_refused_at_startup_and_an_empty_auth_never_passes() {
    let bb = board(BbLimits::default());
    let open = RelayConfig { addr: SocketAddr::from(([0, 0, 0, 0], 0)), ..RelayConfig::default() };
    for (token, why) in [
        ("", "it is empty"),
        ("two words", "it has a space or a control character (AUTH takes one word)"),
        ("tab\there", "it has a space or a control character (AUTH takes one word)"),
    ] {
        for addr in [open.addr, SocketAddr::from(([127, 0, 0, 1], 0))] {
            let cfg = RelayConfig { addr, token: Some(token.into()), ..RelayConfig::default() };
            let e = Relay::start(bb.clone(), cfg).err().unwrap();
            assert!(matches!(e, RelayError::BadToken(_)), "{e}");
            assert_eq!(e.to_string(), format!("the relay's shared token is unusable: {why}"));
        }
    }
    let relay = start(&bb, RelayConfig { token: Some("s3cret".into()), ..RelayConfig::default() });
    let (mut r, mut w) = raw(relay.local_addr());
    for empty in ["AUTH\n", "AUTH \n", "AUTH  \r\n"] {
        w.write_all(empty.as_bytes()).unwrap();
        assert_eq!(line(&mut r), "ERR 400 AUTH takes one argument");
    }
    w.write_all(b"GETV local.var.x\n").unwrap();
    assert_eq!(line(&mut r), "ERR 401 send AUTH <token> first", "still not authorised");
    let e = RelayClient::connect(relay.local_addr(), Some("")).err().unwrap();
    assert!(matches!(e, ClientError::BadToken("it is empty")), "{e}");
    let mut c = RelayClient::connect(relay.local_addr(), Some("s3cret")).unwrap();
    assert_eq!(c.request("LSTW").unwrap(), "LSTW 0");
}

/// Bullet 6: wrong `AUTH`s were answered at once, as fast as one could connect. Now each is
/// answered after `auth_delay` and ends its connection; after `max_auth_failures` from one
/// address, that address's `AUTH`s are refused unchecked (even the right token) until
/// `auth_window` has passed. A client that never authenticates is closed after
/// `auth_timeout`.
#[test]
fn wrong_tokens_are_slowed_down_and_then_locked_out() {
    let bb = board(BbLimits::default());
    let cfg = RelayConfig {
        token: Some("s3cret".into()),
        auth_delay: Duration::from_millis(200),
        max_auth_failures: 3,
        auth_window: Duration::from_secs(3600),
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    for _ in 0..3 {
        let (mut r, mut w) = raw(relay.local_addr());
        let t0 = Instant::now();
        w.write_all(b"AUTH guess\n").unwrap();
        assert_eq!(line(&mut r), "ERR 401 wrong token");
        assert!(t0.elapsed() >= Duration::from_millis(200), "answered after the delay");
        assert_eq!(line(&mut r), "", "then closed");
    }
    assert_eq!(relay.stats().auth_failures.load(Ordering::Relaxed), 3);
    let (mut r, mut w) = raw(relay.local_addr());
    w.write_all(b"AUTH s3cret\n").unwrap();
    assert_eq!(line(&mut r), "ERR 429 too many wrong tokens from 127.0.0.1: try again later");
    assert_eq!(line(&mut r), "", "then closed");
    assert_eq!(relay.stats().auth_locked.load(Ordering::Relaxed), 1);
    // Connected, silent, never authenticated: closed.
    let cfg = RelayConfig {
        token: Some("s3cret".into()),
        auth_timeout: Duration::from_millis(300),
        ..RelayConfig::default()
    };
    let relay = start(&bb, cfg);
    let (mut r, _w) = raw(relay.local_addr());
    assert_eq!(line(&mut r), "ERR 401 no AUTH <token> within 0.3 s");
}
