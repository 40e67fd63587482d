//! The Relay (ISocRob `003` §3.2.6): a TCP server that lets a person watch and set a robot's
//! blackboard variables, one text line per request and one line per reply. The grammar and
//! the replies are in `docs/relay-protocol.md`; [`parse_request`] is its parser.
//!
//! Safety: the relay listens on 127.0.0.1 unless told otherwise, and any other address needs
//! a shared token (`AUTH <token>` first). Lines are at most [`RelayConfig::max_line`] bytes,
//! at most [`RelayConfig::max_clients`] clients are served at once (more are told `ERR 503`
//! and closed), each with at most [`RelayConfig::max_watches`] watches; a client silent for
//! [`RelayConfig::idle_timeout`] is closed. Each client has its own thread; the robot's
//! Members never wait for the relay beyond one blackboard access.

use crate::board::{BbError, Blackboard, Stamped};
use crate::symbol::Pattern;
use crate::value::Value;
use std::collections::HashMap;
use std::io::{ErrorKind, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The relay's TCP port in ISocRob.
pub const DEFAULT_PORT: u16 = 2001;

/// How the relay listens and what it allows.
#[derive(Clone, Debug)]
pub struct RelayConfig {
    /// Where to listen (default `127.0.0.1:2001`; port 0 picks a free one).
    pub addr: SocketAddr,
    /// The shared token clients must send first (`AUTH <token>`); required when `addr` is
    /// not a loopback address.
    pub token: Option<String>,
    /// Clients served at once.
    pub max_clients: usize,
    /// Longest request line, bytes (the newline included).
    pub max_line: usize,
    /// Watches per client.
    pub max_watches: usize,
    /// A client that sends nothing for this long is closed.
    pub idle_timeout: Duration,
}

impl Default for RelayConfig {
    fn default() -> Self {
        RelayConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], DEFAULT_PORT)),
            token: None,
            max_clients: 32,
            max_line: 4096,
            max_watches: 256,
            idle_timeout: Duration::from_secs(600),
        }
    }
}

/// Why the relay cannot start.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RelayError {
    /// Listening beyond this machine without a token.
    #[error("the relay listens on {0}, beyond this machine: give it a shared token")]
    TokenRequired(SocketAddr),
    /// The socket could not be opened.
    #[error("the relay cannot listen on {addr}: {source}")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
}

/// One request, as [`parse_request`] reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// `AUTH <token>`.
    Auth(String),
    /// `REFR <milliseconds>`: the period of watch pushes.
    Refr(u64),
    /// `ADDW <pattern>`.
    Addw(Pattern),
    /// `DELW <pattern>`.
    Delw(Pattern),
    /// `CLRW`.
    Clrw,
    /// `LSTW`.
    Lstw,
    /// `SETV <symbol> <Type> <value>`.
    Setv(String, Value),
    /// `GETV <symbol>`.
    Getv(String),
    /// `LSTV [<pattern>]` (an MRT addition: the symbols on the blackboard).
    Lstv(Option<Pattern>),
    /// `QUIT`.
    Quit,
}

/// A request that cannot be served: the code and reason of its `ERR` reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// 400 bad request, 401 not authorised, 404 unknown, 408 idle too long, 409 conflicting
    /// type or kind, 413 line too long, 429 too many watches, 503 too many clients.
    pub code: u16,
    /// Why, one line.
    pub reason: String,
}

impl Refusal {
    fn new(code: u16, reason: impl Into<String>) -> Refusal {
        let reason: String = reason.into();
        Refusal { code, reason: reason.replace(['\n', '\r'], " ") }
    }

    /// The reply line, without the newline.
    pub fn line(&self) -> String {
        format!("ERR {} {}", self.code, self.reason)
    }
}

/// Shortest and longest refresh period, ms.
pub const REFRESH_RANGE: (u64, u64) = (10, 60_000);

/// Parses one request line (without its newline; a trailing `\r` is ignored). `Ok(None)` for
/// a blank line, which the relay ignores.
pub fn parse_request(line: &str) -> Result<Option<Request>, Refusal> {
    let line = line.strip_suffix('\r').unwrap_or(line).trim();
    if line.is_empty() {
        return Ok(None);
    }
    let (word, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
    let rest = rest.trim();
    let pattern = |text: &str| Pattern::parse(text).map_err(|e| Refusal::new(400, e.to_string()));
    let one_arg = |name: &str| {
        if rest.is_empty() || rest.contains(char::is_whitespace) {
            Err(Refusal::new(400, format!("{name} takes one argument")))
        } else {
            Ok(rest)
        }
    };
    let no_arg = |name: &str, r: Request| {
        if rest.is_empty() {
            Ok(r)
        } else {
            Err(Refusal::new(400, format!("{name} takes no argument")))
        }
    };
    let request = match word.to_ascii_uppercase().as_str() {
        "AUTH" => Request::Auth(one_arg("AUTH")?.to_string()),
        "REFR" => {
            let ms: u64 = one_arg("REFR")?
                .parse()
                .map_err(|_| Refusal::new(400, "REFR takes a period in milliseconds"))?;
            if !(REFRESH_RANGE.0..=REFRESH_RANGE.1).contains(&ms) {
                return Err(Refusal::new(400, "the refresh period is 10 to 60000 ms"));
            }
            Request::Refr(ms)
        }
        "ADDW" => Request::Addw(pattern(one_arg("ADDW")?)?),
        "DELW" => Request::Delw(pattern(one_arg("DELW")?)?),
        "CLRW" => no_arg("CLRW", Request::Clrw)?,
        "LSTW" => no_arg("LSTW", Request::Lstw)?,
        "QUIT" => no_arg("QUIT", Request::Quit)?,
        "GETV" => {
            let symbol = one_arg("GETV")?;
            crate::Symbol::parse(symbol).map_err(|e| Refusal::new(400, e.to_string()))?;
            Request::Getv(symbol.to_string())
        }
        "LSTV" if rest.is_empty() => Request::Lstv(None),
        "LSTV" => Request::Lstv(Some(pattern(one_arg("LSTV")?)?)),
        "SETV" => {
            let (symbol, value) = rest
                .split_once(char::is_whitespace)
                .ok_or_else(|| Refusal::new(400, "SETV takes a symbol, a type and a value"))?;
            crate::Symbol::parse(symbol).map_err(|e| Refusal::new(400, e.to_string()))?;
            let value = Value::parse_typed(value).map_err(|e| Refusal::new(400, e.to_string()))?;
            Request::Setv(symbol.to_string(), value)
        }
        _ => {
            let shown: String = word.chars().take(20).collect();
            return Err(Refusal::new(400, format!("unknown command `{shown}`")));
        }
    };
    Ok(Some(request))
}

/// What the relay has done, counted since it started.
#[derive(Debug, Default)]
pub struct RelayStats {
    /// Clients accepted.
    pub accepted: AtomicU64,
    /// Clients refused (too many at once).
    pub refused: AtomicU64,
    /// Requests served with `OK`.
    pub ok: AtomicU64,
    /// Requests answered with `ERR`.
    pub errors: AtomicU64,
}

/// A running relay. Dropping it stops it.
pub struct Relay {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    stats: Arc<RelayStats>,
    acceptor: Option<JoinHandle<()>>,
}

impl Relay {
    /// Starts serving `bb` as `cfg` says.
    pub fn start(bb: Blackboard, cfg: RelayConfig) -> Result<Relay, RelayError> {
        if !cfg.addr.ip().is_loopback() && cfg.token.is_none() {
            return Err(RelayError::TokenRequired(cfg.addr));
        }
        let listener = TcpListener::bind(cfg.addr)
            .map_err(|source| RelayError::Bind { addr: cfg.addr, source })?;
        let addr =
            listener.local_addr().map_err(|source| RelayError::Bind { addr: cfg.addr, source })?;
        let stop = Arc::new(AtomicBool::new(false));
        let stats = Arc::new(RelayStats::default());
        let acceptor = {
            let (stop, stats) = (stop.clone(), stats.clone());
            std::thread::Builder::new()
                .name("mrt-relay".into())
                .spawn(move || accept_loop(&listener, &bb, &cfg, &stop, &stats))
                .map_err(|source| RelayError::Bind { addr, source })?
        };
        tracing::info!(%addr, "relay listening");
        Ok(Relay { addr, stop, stats, acceptor: Some(acceptor) })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Its counters.
    pub fn stats(&self) -> &RelayStats {
        &self.stats
    }

    /// Stops accepting clients (the ones connected finish their current request and close).
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        // Wake the acceptor up.
        let _ = TcpStream::connect_timeout(&self.addr, Duration::from_millis(200));
        if let Some(h) = self.acceptor.take() {
            let _ = h.join();
        }
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.shutdown();
    }
}

fn accept_loop(
    listener: &TcpListener,
    bb: &Blackboard,
    cfg: &RelayConfig,
    stop: &Arc<AtomicBool>,
    stats: &Arc<RelayStats>,
) {
    let active = Arc::new(AtomicUsize::new(0));
    for stream in listener.incoming() {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let Ok(mut stream) = stream else { continue };
        if active.load(Ordering::SeqCst) >= cfg.max_clients {
            stats.refused.fetch_add(1, Ordering::Relaxed);
            let _ = stream.set_write_timeout(Some(Duration::from_millis(100)));
            let _ = writeln!(stream, "{}", Refusal::new(503, "too many clients").line());
            let _ = stream.shutdown(Shutdown::Both);
            continue;
        }
        stats.accepted.fetch_add(1, Ordering::Relaxed);
        active.fetch_add(1, Ordering::SeqCst);
        let (bb, cfg, stop, stats, active) =
            (bb.clone(), cfg.clone(), stop.clone(), stats.clone(), active.clone());
        let spawned =
            std::thread::Builder::new().name("mrt-relay-client".into()).spawn(move || {
                let _ = Client::new(stream, &bb, &cfg).serve(&stop, &stats);
                active.fetch_sub(1, Ordering::SeqCst);
            });
        if spawned.is_err() {
            tracing::warn!("relay: cannot start a client thread");
        }
    }
}

/// One connected client.
struct Client<'a> {
    stream: TcpStream,
    bb: &'a Blackboard,
    cfg: &'a RelayConfig,
    authorised: bool,
    refresh: Duration,
    watches: Vec<Pattern>,
    /// The stamp of each watched symbol last pushed.
    pushed: HashMap<Arc<str>, mrt_core::Time>,
    /// A wrong token was sent: the connection ends after the reply.
    rejected: bool,
}

enum Flow {
    Continue,
    Close,
}

impl<'a> Client<'a> {
    fn new(stream: TcpStream, bb: &'a Blackboard, cfg: &'a RelayConfig) -> Client<'a> {
        Client {
            stream,
            bb,
            cfg,
            authorised: cfg.token.is_none(),
            refresh: Duration::from_millis(500),
            watches: Vec::new(),
            pushed: HashMap::new(),
            rejected: false,
        }
    }

    fn serve(mut self, stop: &AtomicBool, stats: &RelayStats) -> std::io::Result<()> {
        self.stream.set_write_timeout(Some(Duration::from_secs(5)))?;
        self.stream.set_nodelay(true)?;
        let mut buf: Vec<u8> = Vec::with_capacity(256);
        let mut chunk = [0u8; 4096];
        let mut last_input = Instant::now();
        let mut next_push = Instant::now() + self.refresh;
        while !stop.load(Ordering::SeqCst) {
            let wait = next_push.saturating_duration_since(Instant::now());
            self.stream.set_read_timeout(Some(
                wait.clamp(Duration::from_millis(5), Duration::from_millis(100)),
            ))?;
            match self.stream.read(&mut chunk) {
                Ok(0) => return Ok(()),
                Ok(n) => {
                    last_input = Instant::now();
                    buf.extend_from_slice(&chunk[..n]);
                    while let Some(end) = buf.iter().position(|&b| b == b'\n') {
                        let line: Vec<u8> = buf.drain(..=end).collect();
                        if let Flow::Close = self.handle(&line[..line.len() - 1], stats)? {
                            return self.close();
                        }
                    }
                    if buf.len() >= self.cfg.max_line {
                        stats.errors.fetch_add(1, Ordering::Relaxed);
                        let why = format!("a request line is at most {} bytes", self.cfg.max_line);
                        self.reply(&Refusal::new(413, why).line())?;
                        return self.close();
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
            if last_input.elapsed() >= self.cfg.idle_timeout {
                let _ = self.reply(&Refusal::new(408, "idle for too long").line());
                return self.close();
            }
            if Instant::now() >= next_push {
                self.push_watches()?;
                next_push = Instant::now() + self.refresh;
            }
        }
        self.close()
    }

    fn close(&mut self) -> std::io::Result<()> {
        let _ = self.stream.shutdown(Shutdown::Both);
        Ok(())
    }

    fn reply(&mut self, line: &str) -> std::io::Result<()> {
        // One write per line (with TCP_NODELAY): a line never waits for an acknowledgement.
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.stream.write_all(&bytes)
    }

    fn handle(&mut self, raw: &[u8], stats: &RelayStats) -> std::io::Result<Flow> {
        let outcome = match std::str::from_utf8(raw) {
            Err(_) => Err(Refusal::new(400, "a request is UTF-8 text")),
            Ok(text) => match parse_request(text) {
                Ok(None) => return Ok(Flow::Continue),
                Ok(Some(r)) => self.serve_request(r),
                Err(e) => Err(e),
            },
        };
        match outcome {
            Ok((line, flow)) => {
                stats.ok.fetch_add(1, Ordering::Relaxed);
                self.reply(&line)?;
                Ok(flow)
            }
            Err(e) => {
                stats.errors.fetch_add(1, Ordering::Relaxed);
                self.reply(&e.line())?;
                Ok(if self.rejected { Flow::Close } else { Flow::Continue })
            }
        }
    }

    fn serve_request(&mut self, r: Request) -> Result<(String, Flow), Refusal> {
        if let Request::Auth(token) = &r {
            return if self.cfg.token.as_deref().is_none_or(|t| t == token) {
                self.authorised = true;
                Ok(("OK AUTH".into(), Flow::Continue))
            } else {
                // A wrong token ends the connection.
                self.rejected = true;
                Err(Refusal::new(401, "wrong token"))
            };
        }
        if !self.authorised && r != Request::Quit {
            return Err(Refusal::new(401, "send AUTH <token> first"));
        }
        let ok = |s: String| Ok((s, Flow::Continue));
        match r {
            Request::Auth(_) => ok("OK AUTH".into()),
            Request::Quit => Ok(("OK QUIT".into(), Flow::Close)),
            Request::Refr(ms) => {
                self.refresh = Duration::from_millis(ms);
                ok(format!("OK REFR {ms}"))
            }
            Request::Addw(p) => {
                if !self.watches.contains(&p) {
                    if self.watches.len() >= self.cfg.max_watches {
                        return Err(Refusal::new(
                            429,
                            format!("at most {} watches", self.cfg.max_watches),
                        ));
                    }
                    self.watches.push(p.clone());
                }
                ok(format!("OK ADDW {p}"))
            }
            Request::Delw(p) => {
                let before = self.watches.len();
                self.watches.retain(|w| *w != p);
                if self.watches.len() == before {
                    return Err(Refusal::new(404, format!("not watched: {p}")));
                }
                ok(format!("OK DELW {p}"))
            }
            Request::Clrw => {
                let n = self.watches.len();
                self.watches.clear();
                self.pushed.clear();
                ok(format!("OK CLRW {n}"))
            }
            Request::Lstw => {
                let mut line = format!("OK LSTW {}", self.watches.len());
                for w in &self.watches {
                    line.push(' ');
                    line.push_str(&w.to_string());
                }
                ok(line)
            }
            Request::Setv(symbol, value) => match self.bb.set(&symbol, value) {
                Ok(()) => ok(format!("OK SETV {symbol}")),
                Err(e @ (BbError::Type { .. } | BbError::Kind { .. })) => {
                    Err(Refusal::new(409, e.to_string()))
                }
                Err(e) => Err(Refusal::new(400, e.to_string())),
            },
            Request::Getv(symbol) => match self.bb.get_stamped(&symbol) {
                Ok(s) => ok(format!("OK GETV {}", self.describe(&symbol, &s))),
                Err(BbError::Unknown(_)) => {
                    Err(Refusal::new(404, format!("unknown symbol {symbol}")))
                }
                Err(e) => Err(Refusal::new(409, e.to_string())),
            },
            Request::Lstv(p) => {
                let list = self.bb.list(p.as_ref());
                let mut line = format!("OK LSTV {}", list.len());
                for (s, _) in list {
                    line.push(' ');
                    line.push_str(&s);
                }
                ok(line)
            }
        }
    }

    /// `<symbol> <Type> <value> <age ms>`.
    fn describe(&self, symbol: &str, s: &Stamped) -> String {
        let age = self.bb.now().saturating_since(s.time).as_millis();
        format!("{symbol} {} {age}", s.value.to_typed_text())
    }

    /// One `WATCH` line for each watched symbol changed since its last push.
    fn push_watches(&mut self) -> std::io::Result<()> {
        if self.watches.is_empty() {
            return Ok(());
        }
        let mut lines = Vec::new();
        for w in &self.watches {
            for (symbol, value) in self.bb.list(Some(w)) {
                let Some(value) = value else { continue };
                if self.pushed.get(&symbol) == Some(&value.time) {
                    continue;
                }
                lines.push(format!("WATCH {}", self.describe(&symbol, &value)));
                self.pushed.insert(symbol, value.time);
            }
        }
        for l in lines {
            self.reply(&l)?;
        }
        Ok(())
    }
}

/// A relay client: one request at a time, `WATCH` pushes kept aside (`mrt bb` uses it).
pub struct RelayClient {
    reader: std::io::BufReader<TcpStream>,
    writer: TcpStream,
    pushes: std::collections::VecDeque<String>,
}

/// A client's failure.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ClientError {
    /// The connection failed.
    #[error("relay at {addr}: {source}")]
    Io {
        /// The relay's address.
        addr: SocketAddr,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The relay answered `ERR`.
    #[error("relay: {0}")]
    Refused(String),
    /// The relay closed the connection.
    #[error("the relay closed the connection")]
    Closed,
}

impl RelayClient {
    /// Connects to `addr` (and authenticates with `token`, if given).
    pub fn connect(addr: SocketAddr, token: Option<&str>) -> Result<RelayClient, ClientError> {
        let io = |source| ClientError::Io { addr, source };
        let stream = TcpStream::connect_timeout(&addr, Duration::from_secs(3)).map_err(io)?;
        stream.set_nodelay(true).map_err(io)?;
        let writer = stream.try_clone().map_err(io)?;
        let mut c = RelayClient {
            reader: std::io::BufReader::new(stream),
            writer,
            pushes: Default::default(),
        };
        if let Some(t) = token {
            c.request(&format!("AUTH {t}"))?;
        }
        Ok(c)
    }

    /// Sends one request line and returns the `OK` reply (without `OK `); `WATCH` lines that
    /// arrive meanwhile are kept for [`RelayClient::next_push`].
    pub fn request(&mut self, line: &str) -> Result<String, ClientError> {
        let addr = self.writer.peer_addr().map_err(|source| ClientError::Io {
            addr: SocketAddr::from(([0, 0, 0, 0], 0)),
            source,
        })?;
        let io = |source| ClientError::Io { addr, source };
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.writer.write_all(&bytes).map_err(io)?;
        loop {
            let reply = self.read_line()?;
            if reply.starts_with("WATCH ") {
                self.pushes.push_back(reply);
            } else if let Some(ok) = reply.strip_prefix("OK") {
                return Ok(ok.trim_start().to_string());
            } else {
                return Err(ClientError::Refused(reply));
            }
        }
    }

    /// The next `WATCH` line (waiting for it).
    pub fn next_push(&mut self) -> Result<String, ClientError> {
        if let Some(p) = self.pushes.pop_front() {
            return Ok(p);
        }
        self.read_line()
    }

    fn read_line(&mut self) -> Result<String, ClientError> {
        use std::io::BufRead;
        let mut line = String::new();
        let n = self.reader.read_line(&mut line).map_err(|source| ClientError::Io {
            addr: SocketAddr::from(([0, 0, 0, 0], 0)),
            source,
        })?;
        if n == 0 {
            return Err(ClientError::Closed);
        }
        Ok(line.trim_end().to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn every_command_parses() {
        let p = |l: &str| parse_request(l).unwrap().unwrap();
        assert_eq!(p("REFR 250"), Request::Refr(250));
        assert_eq!(
            p("ADDW local.var.machine.*"),
            Request::Addw(Pattern::parse("local.var.machine.*").unwrap())
        );
        assert_eq!(p("DELW *.var.x"), Request::Delw(Pattern::parse("*.var.x").unwrap()));
        assert_eq!(p("clrw\r"), Request::Clrw);
        assert_eq!(p("LSTW"), Request::Lstw);
        assert_eq!(
            p("SETV local.var.a String \"two words\""),
            Request::Setv("local.var.a".into(), Value::String("two words".into()))
        );
        assert_eq!(p("GETV 2.var.machine.role"), Request::Getv("2.var.machine.role".into()));
        assert_eq!(p("LSTV"), Request::Lstv(None));
        assert_eq!(p("QUIT"), Request::Quit);
        assert_eq!(p("AUTH s3cret"), Request::Auth("s3cret".into()));
        assert_eq!(parse_request("   ").unwrap(), None);
    }

    #[test]
    fn bad_requests_are_refused_with_a_reason() {
        let e = |l: &str| parse_request(l).unwrap_err().line();
        assert_eq!(e("HELO"), "ERR 400 unknown command `HELO`");
        assert_eq!(e("REFR 5"), "ERR 400 the refresh period is 10 to 60000 ms");
        assert_eq!(e("REFR fast"), "ERR 400 REFR takes a period in milliseconds");
        assert_eq!(e("ADDW"), "ERR 400 ADDW takes one argument");
        assert_eq!(e("CLRW now"), "ERR 400 CLRW takes no argument");
        assert_eq!(e("SETV local.var.a"), "ERR 400 SETV takes a symbol, a type and a value");
        assert_eq!(e("SETV local.var.a Int x"), "ERR 400 `x` is not a Int");
        assert!(e("GETV local.vr.a").starts_with("ERR 400 `local.vr.a`"));
    }

    proptest! {
        #[test]
        fn random_lines_never_panic(line in "\\PC{0,80}") {
            let _ = parse_request(&line);
        }

        #[test]
        fn random_commands_never_panic(cmd in "(REFR|ADDW|DELW|CLRW|LSTW|SETV|GETV|LSTV|QUIT|AUTH)", rest in "[ -~]{0,60}") {
            let _ = parse_request(&format!("{cmd} {rest}"));
        }
    }
}
