//! A client of the relay ([`RelayClient`]).

use super::*;

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

pub(super) fn timed_out(e: &std::io::Error) -> bool {
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
    pub(super) fn read_line(&mut self, deadline: Option<Instant>) -> Result<String, ClientError> {
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
