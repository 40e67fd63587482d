//! The Relay (ISocRob `003` §3.2.6): a TCP server that lets a person watch and set a robot's
//! blackboard variables, one text line per request and one line per reply. The grammar and
//! the replies are in `docs/relay-protocol.md`; [`parse_request`] is its parser.
//!
//! Safety: the relay listens on 127.0.0.1 unless told otherwise, and any other address needs
//! a shared token (`AUTH <token>` first; [`check_token`] says which tokens are good). Every
//! limit is a [`RelayConfig`] field, listed with its default and what a client sees in the
//! protocol's *Limits* section: lines ([`RelayConfig::max_line`]) that must end within
//! [`RelayConfig::line_timeout`], clients at once in total and per address, watches per
//! client and in total, a shortest refresh period, pushes per period and per second, the
//! size of a reply, a client that does not read its replies, wrong tokens. Each client has its
//! own thread with a small stack; the robot's Members never wait for the relay beyond one
//! blackboard access, and what a client can make the relay do per second is bounded.

use crate::board::{BbError, Blackboard, Stamped};
use crate::symbol::Pattern;
use crate::value::Value;
use std::collections::{HashMap, HashSet, VecDeque};
use std::io::{BufRead, ErrorKind, Read, Write};
use std::net::{IpAddr, Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// The relay's TCP port in ISocRob.
pub const DEFAULT_PORT: u16 = 2001;

/// Longest shared token, bytes.
pub const MAX_TOKEN_LEN: usize = 256;

/// Stack of a client's thread, bytes: a client parses and formats lines, nothing deep.
pub const CLIENT_STACK: usize = 256 * 1024;

/// Longest a client's thread waits in a read before it looks at the stop flag again.
pub const STOP_POLL: Duration = Duration::from_millis(250);

/// Source addresses whose wrong tokens the relay remembers; past this, the ones whose window
/// has passed are forgotten, and then all of them.
pub const MAX_AUTH_ADDRESSES: usize = 4096;

/// How the relay listens and what it allows. Every limit of the relay is here.
#[derive(Clone, Debug)]
pub struct RelayConfig {
    /// Where to listen (default `127.0.0.1:2001`; port 0 picks a free one).
    pub addr: SocketAddr,
    /// The shared token clients must send first (`AUTH <token>`); required when `addr` is
    /// not a loopback address. It must pass [`check_token`].
    pub token: Option<String>,
    /// Clients served at once (default 256); one more is told `ERR 503` and closed.
    pub max_clients: usize,
    /// Clients served at once from one source address other than this machine's (default
    /// 64). On loopback every local program shares one address, so there the limit is per
    /// client: [`RelayConfig::max_clients`] and [`RelayConfig::first_request_timeout`].
    pub max_clients_per_address: usize,
    /// Longest request line, bytes, the newline included (default 4096).
    pub max_line: usize,
    /// A request line must end this long after its first byte arrived (default 10 s): a
    /// client that trickles bytes is told `ERR 408` and closed.
    pub line_timeout: Duration,
    /// With a token, a client must authenticate this long after connecting (default 10 s).
    pub auth_timeout: Duration,
    /// A client must send its first complete request this long after connecting (default
    /// 10 s): connections opened and left silent cannot hold the relay's places.
    pub first_request_timeout: Duration,
    /// A client that sends nothing for this long is closed (default 10 min).
    pub idle_timeout: Duration,
    /// A reply or push the client does not take within this (its socket stays full) drops
    /// the client (default 5 s): a client that does not read cannot make the relay buffer.
    pub write_timeout: Duration,
    /// Watches per client (default 256).
    pub max_watches: usize,
    /// Watches of all clients together (default 4096).
    pub max_total_watches: usize,
    /// Shortest refresh period (default 100 ms): `REFR` below it gets this period, and says so.
    pub min_refresh: Duration,
    /// `WATCH` lines one client is sent per period, at most (default 512).
    pub max_pushes: usize,
    /// `WATCH` lines all clients together are sent per second, at most (default 20000).
    pub max_pushes_per_second: usize,
    /// Changed symbols a client's pushes may wait for (default 4096): the changes over the
    /// push budgets wait for the next periods; past this many they are dropped and counted.
    pub max_deferred: usize,
    /// Longest reply line, bytes (default 65536): `LSTV` past it is refused, paged `LSTV`
    /// fills pages up to it.
    pub max_reply: usize,
    /// A wrong token is answered after this delay (default 1 s).
    pub auth_delay: Duration,
    /// Wrong tokens from one source address within [`RelayConfig::auth_window`] after which
    /// that address's `AUTH`s are refused unchecked until the window has passed (default 10).
    pub max_auth_failures: u32,
    /// See [`RelayConfig::max_auth_failures`] (default 60 s).
    pub auth_window: Duration,
}

impl Default for RelayConfig {
    fn default() -> Self {
        RelayConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], DEFAULT_PORT)),
            token: None,
            max_clients: 256,
            max_clients_per_address: 64,
            max_line: 4096,
            line_timeout: Duration::from_secs(10),
            auth_timeout: Duration::from_secs(10),
            first_request_timeout: Duration::from_secs(10),
            idle_timeout: Duration::from_secs(600),
            write_timeout: Duration::from_secs(5),
            max_watches: 256,
            max_total_watches: 4096,
            min_refresh: Duration::from_millis(100),
            max_pushes: 512,
            max_pushes_per_second: 20_000,
            max_deferred: 4096,
            max_reply: 65_536,
            auth_delay: Duration::from_secs(1),
            max_auth_failures: 10,
            auth_window: Duration::from_secs(60),
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
    /// The token cannot be used ([`check_token`]).
    #[error("the relay's shared token is unusable: {0}")]
    BadToken(&'static str),
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

/// Whether `token` can be a shared token: 1 to [`MAX_TOKEN_LEN`] bytes, no whitespace, no
/// control character (`AUTH` takes one word, so a token with a space could never be sent).
/// `Err` says why not.
pub fn check_token(token: &str) -> Result<(), &'static str> {
    if token.is_empty() {
        Err("it is empty")
    } else if token.len() > MAX_TOKEN_LEN {
        Err("it is longer than 256 bytes")
    } else if token.chars().any(|c| c.is_whitespace() || c.is_control()) {
        Err("it has a space or a control character (AUTH takes one word)")
    } else {
        Ok(())
    }
}

/// Compares without stopping at the first difference, so that the time an answer takes does
/// not tell how much of a guess was right.
fn same_token(given: &str, token: &str) -> bool {
    let (a, b) = (given.as_bytes(), token.as_bytes());
    let mut diff = u8::from(a.len() != b.len() || a.is_empty());
    for (i, x) in b.iter().enumerate() {
        diff |= x ^ a.get(i).copied().unwrap_or(0);
    }
    diff == 0
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
    /// `LSTV [<pattern>]` (an MRT addition: the symbols on the blackboard; `*` for all).
    Lstv(Option<Pattern>),
    /// `LSTV <pattern> <after>`: one page, the symbols after `<after>` (`-`: from the first).
    LstvPage(Option<Pattern>, Option<String>),
    /// `QUIT`.
    Quit,
}

/// A request that cannot be served: the code and reason of its `ERR` reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// 400 bad request, 401 not authorised, 404 unknown, 408 too slow or idle too long, 409
    /// conflicting type or kind, 413 too large, 429 too many (watches, wrong tokens), 503 too
    /// many clients, 507 the blackboard is full.
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

/// Shortest and longest refresh period a `REFR` may ask for, ms (the relay then applies
/// [`RelayConfig::min_refresh`]).
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
        "LSTV" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let any = |w: &str| if w == "*" { Ok(None) } else { pattern(w).map(Some) };
            match words.as_slice() {
                [] => Request::Lstv(None),
                [p] => Request::Lstv(any(p)?),
                [p, "-"] => Request::LstvPage(any(p)?, None),
                [p, after] => Request::LstvPage(any(p)?, Some((*after).to_string())),
                _ => return Err(Refusal::new(400, "LSTV takes a pattern and a symbol at most")),
            }
        }
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
    /// Clients refused (too many at once, in total or from their address).
    pub refused: AtomicU64,
    /// Requests served with `OK`.
    pub ok: AtomicU64,
    /// Requests answered with `ERR`.
    pub errors: AtomicU64,
    /// Clients closed because a request line did not end within
    /// [`RelayConfig::line_timeout`], or `AUTH` did not come within
    /// [`RelayConfig::auth_timeout`].
    pub too_slow: AtomicU64,
    /// Clients dropped because they did not take their replies or pushes
    /// ([`RelayConfig::write_timeout`]).
    pub not_reading: AtomicU64,
    /// `WATCH` lines sent.
    pub pushed: AtomicU64,
    /// Changes not pushed because a client had [`RelayConfig::max_deferred`] waiting.
    pub push_dropped: AtomicU64,
    /// Wrong tokens.
    pub auth_failures: AtomicU64,
    /// `AUTH`s refused unchecked (too many wrong tokens from their address).
    pub auth_locked: AtomicU64,
}

fn count(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // Every critical section below is a few assignments: a poisoned lock is still consistent.
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The push budget of all clients together: a token bucket refilled at
/// [`RelayConfig::max_pushes_per_second`], holding at most one second's worth.
struct Bucket {
    tokens: f64,
    last: Instant,
}

/// Wrong tokens per source address: how many since when.
#[derive(Default)]
struct AuthBook {
    failures: HashMap<IpAddr, (u32, Instant)>,
}

impl AuthBook {
    fn locked(&mut self, ip: IpAddr, cfg: &RelayConfig) -> bool {
        match self.failures.get(&ip) {
            Some(&(_, since)) if since.elapsed() >= cfg.auth_window => {
                self.failures.remove(&ip);
                false
            }
            Some(&(n, _)) => n >= cfg.max_auth_failures,
            None => false,
        }
    }

    fn fail(&mut self, ip: IpAddr, cfg: &RelayConfig) {
        if self.failures.len() >= MAX_AUTH_ADDRESSES && !self.failures.contains_key(&ip) {
            self.failures.retain(|_, (_, since)| since.elapsed() < cfg.auth_window);
            if self.failures.len() >= MAX_AUTH_ADDRESSES {
                self.failures.clear();
            }
        }
        self.failures.entry(ip).or_insert((0, Instant::now())).0 += 1;
    }
}

/// What the acceptor and the clients share.
struct Shared {
    bb: Blackboard,
    cfg: RelayConfig,
    stop: AtomicBool,
    stats: RelayStats,
    active: AtomicUsize,
    per_address: Mutex<HashMap<IpAddr, usize>>,
    watches: AtomicUsize,
    bucket: Mutex<Bucket>,
    auth: Mutex<AuthBook>,
}

impl Shared {
    fn new(bb: Blackboard, cfg: RelayConfig) -> Shared {
        let rate = cfg.max_pushes_per_second as f64;
        Shared {
            bb,
            cfg,
            stop: AtomicBool::new(false),
            stats: RelayStats::default(),
            active: AtomicUsize::new(0),
            per_address: Mutex::default(),
            watches: AtomicUsize::new(0),
            bucket: Mutex::new(Bucket { tokens: rate, last: Instant::now() }),
            auth: Mutex::default(),
        }
    }

    /// Takes a client's place, if one is free (in total and for its address).
    fn admit(&self, ip: IpAddr) -> Result<(), Refusal> {
        let mut per = lock(&self.per_address);
        if self.active.load(Ordering::SeqCst) >= self.cfg.max_clients {
            return Err(Refusal::new(503, "too many clients"));
        }
        let n = per.entry(ip).or_insert(0);
        if *n >= self.cfg.max_clients_per_address && !ip.is_loopback() {
            return Err(Refusal::new(503, format!("too many clients from {ip}")));
        }
        *n += 1;
        self.active.fetch_add(1, Ordering::SeqCst);
        Ok(())
    }

    fn leave(&self, ip: IpAddr) {
        let mut per = lock(&self.per_address);
        if let Some(n) = per.get_mut(&ip) {
            *n = n.saturating_sub(1);
            if *n == 0 {
                per.remove(&ip);
            }
        }
        self.active.fetch_sub(1, Ordering::SeqCst);
    }

    /// Up to `wanted` pushes from the budget of all clients.
    fn take_pushes(&self, wanted: usize) -> usize {
        let rate = self.cfg.max_pushes_per_second as f64;
        let mut b = lock(&self.bucket);
        let now = Instant::now();
        b.tokens = (b.tokens + now.duration_since(b.last).as_secs_f64() * rate).min(rate);
        b.last = now;
        let granted = (wanted as f64).min(b.tokens.floor()).max(0.0);
        b.tokens -= granted;
        granted as usize
    }
}

/// A running relay. Dropping it stops it.
pub struct Relay {
    addr: SocketAddr,
    shared: Arc<Shared>,
    acceptor: Option<JoinHandle<()>>,
}

impl Relay {
    /// Starts serving `bb` as `cfg` says.
    pub fn start(bb: Blackboard, cfg: RelayConfig) -> Result<Relay, RelayError> {
        match &cfg.token {
            Some(t) => check_token(t).map_err(RelayError::BadToken)?,
            None if !cfg.addr.ip().is_loopback() => {
                return Err(RelayError::TokenRequired(cfg.addr))
            }
            None => {}
        }
        let listener = TcpListener::bind(cfg.addr)
            .map_err(|source| RelayError::Bind { addr: cfg.addr, source })?;
        let addr =
            listener.local_addr().map_err(|source| RelayError::Bind { addr: cfg.addr, source })?;
        let shared = Arc::new(Shared::new(bb, cfg));
        let acceptor = {
            let shared = shared.clone();
            std::thread::Builder::new()
                .name("mrt-relay".into())
                .spawn(move || accept_loop(&listener, &shared))
                .map_err(|source| RelayError::Bind { addr, source })?
        };
        tracing::info!(%addr, "relay listening");
        Ok(Relay { addr, shared, acceptor: Some(acceptor) })
    }

    /// The address it listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// Its counters.
    pub fn stats(&self) -> &RelayStats {
        &self.shared.stats
    }

    /// Clients connected now.
    pub fn clients(&self) -> usize {
        self.shared.active.load(Ordering::SeqCst)
    }

    /// Watches of all clients now.
    pub fn watches(&self) -> usize {
        self.shared.watches.load(Ordering::SeqCst)
    }

    /// Stops accepting clients (the ones connected finish their current request and close).
    pub fn stop(mut self) {
        self.shutdown();
    }

    fn shutdown(&mut self) {
        self.shared.stop.store(true, Ordering::SeqCst);
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

fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
    for stream in listener.incoming() {
        if shared.stop.load(Ordering::SeqCst) {
            break;
        }
        let Ok(mut stream) = stream else { continue };
        let Ok(peer) = stream.peer_addr() else { continue };
        if let Err(refusal) = shared.admit(peer.ip()) {
            count(&shared.stats.refused);
            let _ = stream.set_write_timeout(Some(Duration::from_millis(100)));
            let _ = writeln!(stream, "{}", refusal.line());
            let _ = stream.shutdown(Shutdown::Both);
            continue;
        }
        count(&shared.stats.accepted);
        let client_shared = shared.clone();
        let spawned = std::thread::Builder::new()
            .name("mrt-relay-client".into())
            .stack_size(CLIENT_STACK)
            .spawn(move || {
                let mut client = Client::new(stream, peer.ip(), &client_shared);
                if let Err(e) = client.serve() {
                    tracing::debug!(%peer, "relay client: {e}");
                }
                client.close();
            });
        if spawned.is_err() {
            tracing::warn!("relay: cannot start a client thread");
            shared.leave(peer.ip());
        }
    }
}

/// One connected client.
struct Client<'a> {
    stream: TcpStream,
    ip: IpAddr,
    shared: &'a Shared,
    bb: &'a Blackboard,
    cfg: &'a RelayConfig,
    authorised: bool,
    refresh: Duration,
    watches: Vec<Pattern>,
    /// Watches added since the last push: their first push sends every value they cover.
    fresh: Vec<Pattern>,
    /// The blackboard's version at the last push.
    seen: u64,
    /// Changed symbols waiting for a push, oldest first, each once.
    deferred: VecDeque<Arc<str>>,
    waiting: HashSet<Arc<str>>,
    /// A wrong token was sent: the connection ends after the reply.
    rejected: bool,
    /// Its place among the clients is given back.
    left: bool,
}

enum Flow {
    Continue,
    Close,
}

impl<'a> Client<'a> {
    fn new(stream: TcpStream, ip: IpAddr, shared: &'a Shared) -> Client<'a> {
        Client {
            stream,
            ip,
            shared,
            bb: &shared.bb,
            cfg: &shared.cfg,
            authorised: shared.cfg.token.is_none(),
            refresh: Duration::from_millis(500).max(shared.cfg.min_refresh),
            watches: Vec::new(),
            fresh: Vec::new(),
            seen: shared.bb.version(),
            deferred: VecDeque::new(),
            waiting: HashSet::new(),
            rejected: false,
            left: false,
        }
    }

    fn serve(&mut self) -> std::io::Result<()> {
        self.stream.set_write_timeout(Some(self.cfg.write_timeout))?;
        self.stream.set_nodelay(true)?;
        let connected = Instant::now();
        let mut buf: Vec<u8> = Vec::with_capacity(256);
        let mut chunk = [0u8; 4096];
        let mut last_input = connected;
        // When the first byte of the unfinished line in `buf` arrived.
        let mut line_started: Option<Instant> = None;
        let mut next_push = connected + self.refresh;
        let mut requests: u64 = 0;
        while !self.shared.stop.load(Ordering::SeqCst) {
            let now = Instant::now();
            let mut until = (now + STOP_POLL).min(last_input + self.cfg.idle_timeout);
            if !self.watches.is_empty() {
                until = until.min(next_push);
            }
            if let Some(t) = line_started {
                until = until.min(t + self.cfg.line_timeout);
            }
            if !self.authorised {
                until = until.min(connected + self.cfg.auth_timeout);
            }
            if requests == 0 {
                until = until.min(connected + self.cfg.first_request_timeout);
            }
            let wait = until.saturating_duration_since(now).max(Duration::from_millis(1));
            self.stream.set_read_timeout(Some(wait))?;
            match self.stream.read(&mut chunk) {
                Ok(0) => return Ok(()),
                Ok(n) => {
                    let now = Instant::now();
                    last_input = now;
                    let ended = chunk[..n].contains(&b'\n');
                    buf.extend_from_slice(&chunk[..n]);
                    while let Some(end) = buf.iter().position(|&b| b == b'\n') {
                        let line: Vec<u8> = buf.drain(..=end).collect();
                        requests += 1;
                        if let Flow::Close = self.handle(&line[..line.len() - 1])? {
                            return Ok(());
                        }
                    }
                    line_started = match (buf.is_empty(), ended) {
                        (true, _) => None,
                        (false, true) => Some(now),
                        (false, false) => line_started.or(Some(now)),
                    };
                    if buf.len() >= self.cfg.max_line {
                        count(&self.shared.stats.errors);
                        let why = format!("a request line is at most {} bytes", self.cfg.max_line);
                        return self.reply(&Refusal::new(413, why).line());
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
            let now = Instant::now();
            if line_started.is_some_and(|t| now >= t + self.cfg.line_timeout) {
                count(&self.shared.stats.too_slow);
                let secs = self.cfg.line_timeout.as_secs_f64();
                let why = format!("a request line must end within {secs} s of its first byte");
                return self.reply(&Refusal::new(408, why).line());
            }
            if !self.authorised && now >= connected + self.cfg.auth_timeout {
                count(&self.shared.stats.too_slow);
                let secs = self.cfg.auth_timeout.as_secs_f64();
                let why = format!("no AUTH <token> within {secs} s");
                return self.reply(&Refusal::new(401, why).line());
            }
            if requests == 0 && now >= connected + self.cfg.first_request_timeout {
                count(&self.shared.stats.too_slow);
                let secs = self.cfg.first_request_timeout.as_secs_f64();
                let why = format!("no request within {secs} s of connecting");
                return self.reply(&Refusal::new(408, why).line());
            }
            if now >= last_input + self.cfg.idle_timeout {
                return self.reply(&Refusal::new(408, "idle for too long").line());
            }
            if now >= next_push {
                self.push_watches()?;
                next_push = Instant::now() + self.refresh;
            }
        }
        Ok(())
    }

    /// Gives its place and its watches back, then closes the connection (in this order, so
    /// that a client that sees the connection end finds the place free).
    fn close(&mut self) {
        if !self.left {
            self.left = true;
            self.shared.watches.fetch_sub(self.watches.len(), Ordering::SeqCst);
            self.watches.clear();
            self.shared.leave(self.ip);
        }
        let _ = self.stream.shutdown(Shutdown::Both);
    }

    /// Writes `bytes`; a client that does not take them within the write timeout is dropped
    /// (counted).
    fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let sent = self.stream.write_all(bytes);
        if let Err(e) = &sent {
            if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) {
                count(&self.shared.stats.not_reading);
            }
        }
        sent
    }

    fn reply(&mut self, line: &str) -> std::io::Result<()> {
        // One write per line (with TCP_NODELAY): a line never waits for an acknowledgement.
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.send(&bytes)
    }

    fn handle(&mut self, raw: &[u8]) -> std::io::Result<Flow> {
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
                count(&self.shared.stats.ok);
                self.reply(&line)?;
                Ok(flow)
            }
            Err(e) => {
                count(&self.shared.stats.errors);
                self.reply(&e.line())?;
                Ok(if self.rejected { Flow::Close } else { Flow::Continue })
            }
        }
    }

    fn authenticate(&mut self, given: &str) -> Result<(String, Flow), Refusal> {
        let Some(token) = self.cfg.token.as_deref() else {
            return Ok(("OK AUTH".into(), Flow::Continue));
        };
        if lock(&self.shared.auth).locked(self.ip, self.cfg) {
            count(&self.shared.stats.auth_locked);
            self.rejected = true;
            let why = format!("too many wrong tokens from {}: try again later", self.ip);
            return Err(Refusal::new(429, why));
        }
        if same_token(given, token) {
            self.authorised = true;
            return Ok(("OK AUTH".into(), Flow::Continue));
        }
        lock(&self.shared.auth).fail(self.ip, self.cfg);
        count(&self.shared.stats.auth_failures);
        // A wrong token is answered late, then ends the connection.
        std::thread::sleep(self.cfg.auth_delay);
        self.rejected = true;
        Err(Refusal::new(401, "wrong token"))
    }

    fn serve_request(&mut self, r: Request) -> Result<(String, Flow), Refusal> {
        if let Request::Auth(token) = &r {
            return self.authenticate(token);
        }
        if !self.authorised && r != Request::Quit {
            return Err(Refusal::new(401, "send AUTH <token> first"));
        }
        let ok = |s: String| Ok((s, Flow::Continue));
        match r {
            Request::Auth(_) => ok("OK AUTH".into()),
            Request::Quit => Ok(("OK QUIT".into(), Flow::Close)),
            Request::Refr(ms) => {
                self.refresh = Duration::from_millis(ms).max(self.cfg.min_refresh);
                ok(format!("OK REFR {}", self.refresh.as_millis()))
            }
            Request::Addw(p) => {
                if !self.watches.contains(&p) {
                    if self.watches.len() >= self.cfg.max_watches {
                        return Err(Refusal::new(
                            429,
                            format!("at most {} watches", self.cfg.max_watches),
                        ));
                    }
                    let max = self.cfg.max_total_watches;
                    let all = &self.shared.watches;
                    if all
                        .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                            (n < max).then_some(n + 1)
                        })
                        .is_err()
                    {
                        return Err(Refusal::new(
                            429,
                            format!("the relay holds at most {max} watches of all clients"),
                        ));
                    }
                    self.watches.push(p.clone());
                    self.fresh.push(p.clone());
                }
                ok(format!("OK ADDW {p}"))
            }
            Request::Delw(p) => {
                let before = self.watches.len();
                self.watches.retain(|w| *w != p);
                self.fresh.retain(|w| *w != p);
                if self.watches.len() == before {
                    return Err(Refusal::new(404, format!("not watched: {p}")));
                }
                self.shared.watches.fetch_sub(1, Ordering::SeqCst);
                ok(format!("OK DELW {p}"))
            }
            Request::Clrw => {
                let n = self.watches.len();
                self.shared.watches.fetch_sub(n, Ordering::SeqCst);
                self.watches.clear();
                self.fresh.clear();
                self.deferred.clear();
                self.waiting.clear();
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
            Request::Setv(symbol, value) => match self.bb.set_as_guest(&symbol, value) {
                Ok(()) => ok(format!("OK SETV {symbol}")),
                Err(e @ (BbError::Type { .. } | BbError::Kind { .. })) => {
                    Err(Refusal::new(409, e.to_string()))
                }
                Err(e @ BbError::TooLong { .. }) => Err(Refusal::new(413, e.to_string())),
                Err(e @ BbError::Full { .. }) => Err(Refusal::new(507, e.to_string())),
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
                let (line, more) = self.list_page(p.as_ref(), None);
                if more {
                    let shown = p.map_or_else(|| "*".to_string(), |p| p.to_string());
                    return Err(Refusal::new(
                        413,
                        format!(
                            "the symbols do not fit in one reply of {} bytes: page them with \
                             LSTV {shown} - and then LSTV {shown} <last symbol received>",
                            self.cfg.max_reply
                        ),
                    ));
                }
                ok(line)
            }
            Request::LstvPage(p, after) => ok(self.list_page(p.as_ref(), after.as_deref()).0),
        }
    }

    /// `OK LSTV <n> <symbol>…` with as many symbols as fit in a reply, and whether more follow.
    fn list_page(&self, p: Option<&Pattern>, after: Option<&str>) -> (String, bool) {
        let (symbols, _) = self.bb.symbols(p, after, usize::MAX);
        // Room for `OK LSTV <n>`: the count has at most 20 digits.
        let room = self.cfg.max_reply.saturating_sub("OK LSTV ".len() + 20);
        let (mut used, mut n) = (0, 0);
        for s in &symbols {
            if used + 1 + s.len() > room {
                break;
            }
            used += 1 + s.len();
            n += 1;
        }
        let mut line = String::with_capacity(used + 30);
        line.push_str(&format!("OK LSTV {n}"));
        for s in &symbols[..n] {
            line.push(' ');
            line.push_str(s);
        }
        (line, n < symbols.len())
    }

    /// `<symbol> <Type> <value> <age ms>`.
    fn describe(&self, symbol: &str, s: &Stamped) -> String {
        let age = self.bb.now().saturating_since(s.time).as_millis();
        format!("{symbol} {} {age}", s.value.to_typed_text())
    }

    /// Queues a changed symbol for a push (once), or drops it (counted) when the queue is full.
    fn defer(&mut self, symbol: Arc<str>) {
        if self.waiting.contains(&symbol) {
            return;
        }
        if self.deferred.len() >= self.cfg.max_deferred {
            count(&self.shared.stats.push_dropped);
            return;
        }
        self.waiting.insert(symbol.clone());
        self.deferred.push_back(symbol);
    }

    /// One `WATCH` line for each watched symbol changed since its last push, within the
    /// budgets; the rest wait for the next periods, in the order they changed.
    fn push_watches(&mut self) -> std::io::Result<()> {
        if self.watches.is_empty() {
            return Ok(());
        }
        let watches = &self.watches;
        let (version, changed) =
            self.bb.changed_since(self.seen, |s| watches.iter().any(|w| w.matches(s)));
        self.seen = version;
        let mut candidates: Vec<Arc<str>> = changed.into_iter().map(|(s, _)| s).collect();
        for p in std::mem::take(&mut self.fresh) {
            candidates.extend(self.bb.symbols(Some(&p), None, usize::MAX).0);
        }
        // Overlapping watches cover a symbol once.
        let mut once = HashSet::with_capacity(candidates.len());
        for symbol in candidates {
            if once.insert(symbol.clone()) {
                self.defer(symbol);
            }
        }
        let wanted = self.deferred.len().min(self.cfg.max_pushes);
        let granted = self.shared.take_pushes(wanted);
        let mut out = Vec::new();
        let mut sent = 0u64;
        for _ in 0..granted {
            let Some(symbol) = self.deferred.pop_front() else { break };
            self.waiting.remove(&symbol);
            if !self.watches.iter().any(|w| w.matches(&symbol)) {
                continue;
            }
            let Some(value) = self.bb.peek(&symbol) else { continue };
            out.extend_from_slice(b"WATCH ");
            out.extend_from_slice(self.describe(&symbol, &value).as_bytes());
            out.push(b'\n');
            sent += 1;
        }
        self.shared.stats.pushed.fetch_add(sent, Ordering::Relaxed);
        if out.is_empty() {
            return Ok(());
        }
        self.send(&out)
    }
}

impl Drop for Client<'_> {
    fn drop(&mut self) {
        self.close();
    }
}

/// Default [`ClientOptions::connect_timeout`].
pub const DEFAULT_CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// Default [`ClientOptions::reply_timeout`].
pub const DEFAULT_REPLY_TIMEOUT: Duration = Duration::from_secs(5);

/// Default [`ClientOptions::max_line`]: 1 MiB, far above what a relay sends (its replies are
/// at most [`RelayConfig::max_reply`] bytes).
pub const DEFAULT_CLIENT_MAX_LINE: usize = 1 << 20;

/// How long a [`RelayClient`] waits, and how long a line it accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClientOptions {
    /// Longest wait for the connection (default [`DEFAULT_CONNECT_TIMEOUT`]).
    pub connect_timeout: Duration,
    /// Longest wait for a reply to a request (default [`DEFAULT_REPLY_TIMEOUT`]).
    pub reply_timeout: Duration,
    /// Longest line accepted from the relay, bytes (default [`DEFAULT_CLIENT_MAX_LINE`]).
    pub max_line: usize,
}

impl Default for ClientOptions {
    fn default() -> Self {
        ClientOptions {
            connect_timeout: DEFAULT_CONNECT_TIMEOUT,
            reply_timeout: DEFAULT_REPLY_TIMEOUT,
            max_line: DEFAULT_CLIENT_MAX_LINE,
        }
    }
}

/// A relay client: one request at a time, `WATCH` pushes kept aside (`mrt bb` uses it).
pub struct RelayClient {
    addr: SocketAddr,
    options: ClientOptions,
    reader: std::io::BufReader<TcpStream>,
    writer: TcpStream,
    pushes: VecDeque<String>,
    /// The start of a line whose end has not arrived yet.
    partial: Vec<u8>,
}

/// A client's failure; each names the relay's address.
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
    /// No connection, or no reply, in time.
    #[error("relay at {addr}: no {what} within {} s", after.as_secs_f64())]
    Timeout {
        /// The relay's address.
        addr: SocketAddr,
        /// `connection` or `reply`.
        what: &'static str,
        /// The time waited.
        after: Duration,
    },
    /// A line from the relay longer than [`ClientOptions::max_line`].
    #[error("relay at {addr}: a line longer than {max} bytes")]
    LineTooLong {
        /// The relay's address.
        addr: SocketAddr,
        /// The limit, bytes.
        max: usize,
    },
    /// The token cannot be sent ([`check_token`]).
    #[error("the relay token is unusable: {0}")]
    BadToken(&'static str),
    /// The relay answered `ERR`.
    #[error("relay at {addr}: {reply}")]
    Refused {
        /// The relay's address.
        addr: SocketAddr,
        /// The `ERR` line.
        reply: String,
    },
    /// The relay closed the connection.
    #[error("the relay at {0} closed the connection")]
    Closed(SocketAddr),
}

fn timed_out(e: &std::io::Error) -> bool {
    matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut)
}

impl RelayClient {
    /// Connects to `addr` (and authenticates with `token`, if given), with the default
    /// [`ClientOptions`].
    pub fn connect(addr: SocketAddr, token: Option<&str>) -> Result<RelayClient, ClientError> {
        RelayClient::connect_with(addr, token, ClientOptions::default())
    }

    /// Connects to `addr` (and authenticates with `token`, if given), waiting as `options`
    /// says.
    pub fn connect_with(
        addr: SocketAddr,
        token: Option<&str>,
        options: ClientOptions,
    ) -> Result<RelayClient, ClientError> {
        if let Some(t) = token {
            check_token(t).map_err(ClientError::BadToken)?;
        }
        let io = |source| ClientError::Io { addr, source };
        let stream = TcpStream::connect_timeout(&addr, options.connect_timeout).map_err(|e| {
            if timed_out(&e) {
                ClientError::Timeout { addr, what: "connection", after: options.connect_timeout }
            } else {
                io(e)
            }
        })?;
        stream.set_nodelay(true).map_err(io)?;
        let writer = stream.try_clone().map_err(io)?;
        let mut c = RelayClient {
            addr,
            options,
            reader: std::io::BufReader::new(stream),
            writer,
            pushes: VecDeque::new(),
            partial: Vec::new(),
        };
        if let Some(t) = token {
            c.request(&format!("AUTH {t}"))?;
        }
        Ok(c)
    }

    /// The relay's address.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Sends one request line and returns the `OK` reply (without `OK `), waiting at most
    /// [`ClientOptions::reply_timeout`]; `WATCH` lines that arrive meanwhile are kept for
    /// [`RelayClient::next_push`].
    pub fn request(&mut self, line: &str) -> Result<String, ClientError> {
        let addr = self.addr;
        let io = |source| ClientError::Io { addr, source };
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.writer.set_write_timeout(Some(self.options.reply_timeout)).map_err(io)?;
        self.writer.write_all(&bytes).map_err(io)?;
        let deadline = Instant::now() + self.options.reply_timeout;
        loop {
            let reply = self.read_line(Some(deadline))?;
            if reply.starts_with("WATCH ") {
                self.pushes.push_back(reply);
            } else if let Some(ok) = reply.strip_prefix("OK") {
                return Ok(ok.trim_start().to_string());
            } else {
                return Err(ClientError::Refused { addr, reply });
            }
        }
    }

    /// The next `WATCH` line, waiting for it as long as it takes (a watched variable may stay
    /// unchanged for hours).
    pub fn next_push(&mut self) -> Result<String, ClientError> {
        if let Some(p) = self.pushes.pop_front() {
            return Ok(p);
        }
        self.read_line(None)
    }

    /// One line (without its end), at most [`ClientOptions::max_line`] bytes, by `deadline`.
    fn read_line(&mut self, deadline: Option<Instant>) -> Result<String, ClientError> {
        let addr = self.addr;
        let max = self.options.max_line;
        loop {
            let timeout = match deadline {
                Some(d) => {
                    let left = d.saturating_duration_since(Instant::now());
                    if left.is_zero() {
                        let after = self.options.reply_timeout;
                        return Err(ClientError::Timeout { addr, what: "reply", after });
                    }
                    Some(left)
                }
                None => None,
            };
            let io = |source| ClientError::Io { addr, source };
            self.reader.get_ref().set_read_timeout(timeout).map_err(io)?;
            let available = match self.reader.fill_buf() {
                Ok(b) => b,
                Err(e) if timed_out(&e) || e.kind() == ErrorKind::Interrupted => continue,
                Err(e) => return Err(io(e)),
            };
            if available.is_empty() {
                return Err(ClientError::Closed(addr));
            }
            let (taken, done) = match available.iter().position(|&b| b == b'\n') {
                Some(end) => (end + 1, true),
                None => (available.len(), false),
            };
            if self.partial.len() + taken > max + 1 {
                return Err(ClientError::LineTooLong { addr, max });
            }
            self.partial.extend_from_slice(&available[..taken]);
            self.reader.consume(taken);
            if done {
                let line = String::from_utf8_lossy(&self.partial).trim_end().to_string();
                self.partial.clear();
                return Ok(line);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A remote address gets at most its share of places; loopback, which every local program
    /// shares, only the total.
    #[test]
    fn the_per_address_limit_spares_loopback() {
        let cfg = RelayConfig { max_clients: 5, max_clients_per_address: 2, ..Default::default() };
        let shared = Shared::new(Blackboard::new(1, Arc::new(mrt_core::WallClock::new())), cfg);
        let remote: IpAddr = "192.0.2.7".parse().unwrap();
        assert!(shared.admit(remote).is_ok() && shared.admit(remote).is_ok());
        let refused = shared.admit(remote).unwrap_err();
        assert_eq!(refused.line(), "ERR 503 too many clients from 192.0.2.7");
        let local: IpAddr = "127.0.0.1".parse().unwrap();
        for _ in 0..3 {
            shared.admit(local).unwrap();
        }
        assert_eq!(shared.admit(local).unwrap_err().line(), "ERR 503 too many clients");
        shared.leave(remote);
        assert!(shared.admit(remote).is_ok(), "a place given back is taken again");
    }

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
        assert_eq!(p("LSTV *"), Request::Lstv(None));
        assert_eq!(p("LSTV * -"), Request::LstvPage(None, None));
        assert_eq!(
            p("LSTV local.* local.var.a"),
            Request::LstvPage(Some(Pattern::parse("local.*").unwrap()), Some("local.var.a".into()))
        );
    }

    #[test]
    fn tokens_are_one_word_and_compared_whole() {
        assert!(check_token("s3cret-ä").is_ok());
        assert_eq!(check_token(""), Err("it is empty"));
        assert!(check_token("a b").is_err() && check_token("a\u{1b}").is_err());
        assert!(check_token(&"x".repeat(MAX_TOKEN_LEN + 1)).is_err());
        assert!(same_token("s3cret", "s3cret"));
        for wrong in ["", "s3cre", "s3cret2", "S3cret"] {
            assert!(!same_token(wrong, "s3cret"), "{wrong}");
        }
        assert!(parse_request("LSTV a b c").is_err());
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
