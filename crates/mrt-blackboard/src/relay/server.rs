//! The relay's server: its listener, its clients' threads, its limits and counts.

use super::*;

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

pub(super) fn count(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

pub(super) fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // Every critical section below is a few assignments: a poisoned lock is still consistent.
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The push budget of all clients together: a token bucket refilled at
/// [`RelayConfig::max_pushes_per_second`], holding at most one second's worth.
pub(super) struct Bucket {
    tokens: f64,
    last: Instant,
}

/// Wrong tokens per source address: how many since when.
#[derive(Default)]
pub(super) struct AuthBook {
    failures: HashMap<IpAddr, (u32, Instant)>,
}

impl AuthBook {
    pub(super) fn locked(&mut self, ip: IpAddr, cfg: &RelayConfig) -> bool {
        match self.failures.get(&ip) {
            Some(&(_, since)) if since.elapsed() >= cfg.auth_window => {
                self.failures.remove(&ip);
                false
            }
            Some(&(n, _)) => n >= cfg.max_auth_failures,
            None => false,
        }
    }

    pub(super) fn fail(&mut self, ip: IpAddr, cfg: &RelayConfig) {
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
pub(super) struct Shared {
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
    pub(super) fn new(bb: Blackboard, cfg: RelayConfig) -> Shared {
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
    pub(super) fn admit(&self, ip: IpAddr) -> Result<(), Refusal> {
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

    pub(super) fn leave(&self, ip: IpAddr) {
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
    pub(super) fn take_pushes(&self, wanted: usize) -> usize {
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

    pub(super) fn shutdown(&mut self) {
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

pub(super) fn accept_loop(listener: &TcpListener, shared: &Arc<Shared>) {
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
pub(super) struct Client<'a> {
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

pub(super) enum Flow {
    Continue,
    Close,
}

impl<'a> Client<'a> {
    pub(super) fn new(stream: TcpStream, ip: IpAddr, shared: &'a Shared) -> Client<'a> {
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

    pub(super) fn serve(&mut self) -> std::io::Result<()> {
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
    pub(super) fn close(&mut self) {
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
    pub(super) fn send(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        let sent = self.stream.write_all(bytes);
        if let Err(e) = &sent {
            if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) {
                count(&self.shared.stats.not_reading);
            }
        }
        sent
    }

    pub(super) fn reply(&mut self, line: &str) -> std::io::Result<()> {
        // One write per line (with TCP_NODELAY): a line never waits for an acknowledgement.
        let mut bytes = Vec::with_capacity(line.len() + 1);
        bytes.extend_from_slice(line.as_bytes());
        bytes.push(b'\n');
        self.send(&bytes)
    }

    pub(super) fn handle(&mut self, raw: &[u8]) -> std::io::Result<Flow> {
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

    pub(super) fn authenticate(&mut self, given: &str) -> Result<(String, Flow), Refusal> {
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

    pub(super) fn serve_request(&mut self, r: Request) -> Result<(String, Flow), Refusal> {
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
    pub(super) fn list_page(&self, p: Option<&Pattern>, after: Option<&str>) -> (String, bool) {
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
    pub(super) fn describe(&self, symbol: &str, s: &Stamped) -> String {
        let age = self.bb.now().saturating_since(s.time).as_millis();
        format!("{symbol} {} {age}", s.value.to_typed_text())
    }

    /// Queues a changed symbol for a push (once), or drops it (counted) when the queue is full.
    pub(super) fn defer(&mut self, symbol: Arc<str>) {
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
    pub(super) fn push_watches(&mut self) -> std::io::Result<()> {
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
