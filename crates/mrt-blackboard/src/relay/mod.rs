//! The Relay (ISocRob-2000 report §3.2.6): a TCP server that lets a person watch and set a robot's
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

mod client;
mod protocol;
mod server;

pub use client::*;
pub use protocol::*;
pub use server::*;

#[cfg(test)]
mod tests;
