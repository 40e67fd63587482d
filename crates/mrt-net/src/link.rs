//! One Agora on the network: the zenoh session, the Finder's liveliness tokens, the outlet
//! that sends what remote Members want, and the subscribers that deliver what local Members
//! want.

use crate::config::{NetConfig, NetError};
use arc_swap::ArcSwap;
use mrt_dcdt::{wire, Agora, AgoraId, AgoraPort, DeliveryWarranty, MsgRef, MsgType, Outlet};
use rustc_hash::{FxHashMap, FxHashSet, FxHasher};
use std::collections::{BTreeSet, VecDeque};
use std::hash::Hasher;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError, RwLock, Weak};
use std::thread::JoinHandle;
use std::time::Duration;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::qos::{CongestionControl, Priority};
use zenoh::sample::{Sample, SampleKind};
use zenoh::Wait;

/// The first level of every key: `mrt/m/<type>` messages, `mrt/agora/<id>` and
/// `mrt/want/<id>/<type>` liveliness tokens.
const ROOT: &str = "mrt";

/// How often the subscriptions of the Agora's Members are compared with what is declared.
const MAINTENANCE: Duration = Duration::from_millis(10);

/// Recently delivered frames remembered to drop duplicates.
const DEDUP_WINDOW: usize = 4096;

/// Bytes before the DCDT wire frame in every message on the network: see [`envelope`].
pub const ENVELOPE: usize = 16;

/// A message as it travels: the sending link's tag (from its zenoh session id) and the
/// link's sequence number, little-endian, then the DCDT wire frame (`mrt_dcdt::wire`). The
/// pair (tag, sequence) names one send: a copy that reaches an Agora by a second route (a
/// ring of bridges) is dropped as a duplicate, while two messages that happen to have the same
/// header and payload (sent within one clock tick) are two messages.
pub fn envelope(tag: u64, seq: u64, wire: &[u8]) -> Vec<u8> {
    let mut out = open_envelope(tag, seq, wire.len());
    out.extend_from_slice(wire);
    out
}

/// A buffer holding the envelope, with room for a frame of about `frame_len` bytes after it.
fn open_envelope(tag: u64, seq: u64, frame_len: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(ENVELOPE + frame_len);
    out.extend_from_slice(&tag.to_le_bytes());
    out.extend_from_slice(&seq.to_le_bytes());
    out
}

/// What the link did, counted since it was attached.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct NetStats {
    /// Messages sent out.
    pub sent: u64,
    /// Messages received and delivered to this Agora.
    pub delivered: u64,
    /// Frames dropped as malformed (bad frame, oversized).
    pub malformed: u64,
    /// Frames of a type nobody here subscribed to (a newer peer's type, or a subscription
    /// just withdrawn).
    pub unwanted: u64,
    /// Frames already delivered (a second route).
    pub duplicates: u64,
}

#[derive(Default)]
struct Counters {
    sent: AtomicU64,
    delivered: AtomicU64,
    malformed: AtomicU64,
    unwanted: AtomicU64,
    duplicates: AtomicU64,
}

#[derive(Default)]
struct Dedup {
    set: FxHashSet<u64>,
    order: VecDeque<u64>,
}

impl Dedup {
    /// Whether `key` was seen (and remembers it).
    fn seen(&mut self, key: u64) -> bool {
        if !self.set.insert(key) {
            return true;
        }
        self.order.push_back(key);
        if self.order.len() > DEDUP_WINDOW {
            if let Some(old) = self.order.pop_front() {
                self.set.remove(&old);
            }
        }
        false
    }
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// zenoh priority of a DCDT priority (crate doc).
fn priority(p: u8) -> Priority {
    match p {
        0 => Priority::Data,
        1..=63 => Priority::DataHigh,
        64..=127 => Priority::InteractiveLow,
        128..=191 => Priority::InteractiveHigh,
        _ => Priority::RealTime,
    }
}

/// zenoh congestion control and express flag of a delivery warranty (crate doc).
fn qos(w: DeliveryWarranty) -> (CongestionControl, bool) {
    match w {
        DeliveryWarranty::None => (CongestionControl::Drop, true),
        DeliveryWarranty::Retransmit => (CongestionControl::Drop, false),
        _ => (CongestionControl::Block, false),
    }
}

struct Shared {
    id: AgoraId,
    port: AgoraPort,
    session: zenoh::Session,
    /// Types some other Agora wants (union of `interest`).
    wanted: ArcSwap<FxHashSet<u32>>,
    /// Types each other Agora wants, from their tokens.
    interest: Mutex<FxHashMap<u32, FxHashSet<u32>>>,
    /// Agoras up, from their tokens.
    agoras: Mutex<BTreeSet<u32>>,
    /// Types this Agora subscribes to on the network now.
    subscribed: ArcSwap<FxHashSet<u32>>,
    publishers: RwLock<FxHashMap<(u32, u8, u8), Publisher<'static>>>,
    dedup: Mutex<Dedup>,
    counters: Counters,
    warned_unwanted: AtomicBool,
    warned_malformed: AtomicBool,
    /// This link's tag and next sequence number ([`envelope`]).
    tag: u64,
    seq: AtomicU64,
}

impl Shared {
    fn send(&self, msg: &MsgRef) {
        // The envelope, then the frame, written in one buffer that zenoh takes without a copy.
        let seq = self.seq.fetch_add(1, Ordering::Relaxed);
        let mut frame = open_envelope(self.tag, seq, wire::HEADER_LEN + msg.payload().len());
        if let Err(e) = wire::encode_into(msg, &mut frame) {
            tracing::warn!(agora = %self.id, "cannot encode a {} message: {e}", msg.msg_type());
            return;
        }
        let h = msg.header();
        let (cc, express) = qos(h.warranty);
        let key = (h.msg_type.0, h.priority, cc as u8);
        let publishers = self.publishers.read().unwrap_or_else(PoisonError::into_inner);
        let sent = match publishers.get(&key) {
            Some(p) => p.put(frame).wait(),
            None => {
                drop(publishers);
                let p = self
                    .session
                    .declare_publisher(format!("{ROOT}/m/{}", h.msg_type.0))
                    .priority(priority(h.priority))
                    .congestion_control(cc)
                    .express(express)
                    .wait();
                p.and_then(|p| {
                    let r = p.put(frame).wait();
                    self.publishers.write().unwrap_or_else(PoisonError::into_inner).insert(key, p);
                    r
                })
            }
        };
        match sent {
            Ok(()) => {
                self.counters.sent.fetch_add(1, Ordering::Relaxed);
            }
            Err(e) => tracing::warn!(agora = %self.id, "zenoh put failed: {e}"),
        }
    }

    fn on_frame(&self, bytes: &[u8]) {
        let (sent, frame) = bytes.split_at(bytes.len().min(ENVELOPE));
        let decoded = if sent.len() < ENVELOPE {
            Err(format!("{} bytes, shorter than the envelope", bytes.len()))
        } else {
            wire::decode(frame).map_err(|e| e.to_string())
        };
        let msg = match decoded {
            Ok(m) => m,
            Err(e) => {
                self.counters.malformed.fetch_add(1, Ordering::Relaxed);
                if !self.warned_malformed.swap(true, Ordering::Relaxed) {
                    tracing::warn!(agora = %self.id, "dropped a malformed frame: {e} (further ones are only counted)");
                }
                return;
            }
        };
        if msg.agora_id() == self.id {
            return; // our own, routed back
        }
        if !self.subscribed.load().contains(&msg.msg_type().0) {
            self.counters.unwanted.fetch_add(1, Ordering::Relaxed);
            if !self.warned_unwanted.swap(true, Ordering::Relaxed) {
                tracing::warn!(agora = %self.id, "ignored a message of type {} that no Member here subscribed to (a newer peer?)", msg.msg_type());
            }
            return;
        }
        let mut h = FxHasher::default();
        h.write(sent);
        if lock(&self.dedup).seen(h.finish()) {
            self.counters.duplicates.fetch_add(1, Ordering::Relaxed);
            return;
        }
        self.counters.delivered.fetch_add(1, Ordering::Relaxed);
        self.port.deliver(&msg);
    }

    /// A liveliness token appeared or went away.
    fn on_token(&self, sample: &Sample) {
        let key = sample.key_expr().as_str();
        let alive = sample.kind() == SampleKind::Put;
        let mut parts = key.split('/').skip(1);
        match (parts.next(), parts.next(), parts.next()) {
            (Some("agora"), Some(id), None) => {
                let Ok(id) = id.parse::<u32>() else { return };
                if id == self.id.0 {
                    return;
                }
                if alive {
                    lock(&self.agoras).insert(id);
                } else {
                    lock(&self.agoras).remove(&id);
                    lock(&self.interest).remove(&id);
                    self.recompute_wanted();
                }
            }
            (Some("want"), Some(id), Some(ty)) => {
                let (Ok(id), Ok(ty)) = (id.parse::<u32>(), ty.parse::<u32>()) else { return };
                if id == self.id.0 {
                    return;
                }
                {
                    let mut interest = lock(&self.interest);
                    let set = interest.entry(id).or_default();
                    if alive {
                        set.insert(ty);
                    } else {
                        set.remove(&ty);
                    }
                }
                self.recompute_wanted();
            }
            _ => {}
        }
    }

    fn recompute_wanted(&self) {
        let all: FxHashSet<u32> = lock(&self.interest).values().flatten().copied().collect();
        self.wanted.store(Arc::new(all));
    }
}

/// The outlet installed in the Agora.
struct ZenohOutlet(Arc<Shared>);

impl Outlet for ZenohOutlet {
    fn wants(&self, ty: MsgType) -> bool {
        self.0.wanted.load().contains(&ty.0)
    }

    fn send(&self, msg: &MsgRef) {
        self.0.send(msg);
    }
}

/// What the maintenance thread declared for the Agora's own subscriptions.
struct Declared {
    subscribers: FxHashMap<u32, Subscriber<()>>,
    tokens: FxHashMap<u32, LivelinessToken>,
}

/// Which Agoras are on the network now, by their liveliness tokens: an Agora whose process
/// ended leaves as soon as its session closes ([`NetLink::presence`]).
#[derive(Clone)]
pub struct NetPresence(Arc<Shared>);

impl NetPresence {
    /// Whether Agora `id` is on the network.
    pub fn contains(&self, id: AgoraId) -> bool {
        lock(&self.0.agoras).contains(&id.0)
    }
}

/// An Agora joined to the network. Dropping it leaves the network.
pub struct NetLink {
    shared: Arc<Shared>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    _agora_token: LivelinessToken,
    _finder: Subscriber<()>,
}

impl NetLink {
    /// Joins `agora` to the network `cfg` describes: opens the zenoh session, announces the
    /// Agora, watches the other Agoras' tokens, and from then on sends the messages others want
    /// and delivers the ones its Members want.
    pub fn attach(agora: &Agora, cfg: &NetConfig) -> Result<NetLink, NetError> {
        let session =
            zenoh::open(cfg.zenoh_config()?).wait().map_err(|e| NetError::Zenoh(e.to_string()))?;
        let z = |e: zenoh::Error| NetError::Zenoh(e.to_string());
        let port = agora.port();
        let id = port.id();
        let shared = Arc::new(Shared {
            id,
            port: port.clone(),
            session: session.clone(),
            wanted: ArcSwap::default(),
            interest: Mutex::default(),
            agoras: Mutex::default(),
            subscribed: ArcSwap::default(),
            publishers: RwLock::default(),
            dedup: Mutex::default(),
            counters: Counters::default(),
            warned_unwanted: AtomicBool::new(false),
            warned_malformed: AtomicBool::new(false),
            tag: {
                let mut h = FxHasher::default();
                h.write(session.zid().to_string().as_bytes());
                h.finish()
            },
            seq: AtomicU64::new(0),
        });
        let weak = Arc::downgrade(&shared);
        let finder = session
            .liveliness()
            .declare_subscriber(format!("{ROOT}/**"))
            .history(true)
            .callback(move |s: Sample| {
                if let Some(sh) = weak.upgrade() {
                    sh.on_token(&s);
                }
            })
            .wait()
            .map_err(z)?;
        let agora_token = session
            .liveliness()
            .declare_token(format!("{ROOT}/agora/{}", id.0))
            .wait()
            .map_err(z)?;
        port.set_outlet(Some(Box::new(ZenohOutlet(shared.clone()))));
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let (weak, stop) = (Arc::downgrade(&shared), stop.clone());
            std::thread::Builder::new()
                .name(format!("mrt-net-{}", id.0))
                .spawn(move || maintain(&weak, &stop))
                .map_err(|e| NetError::Zenoh(format!("cannot start the link thread: {e}")))?
        };
        let link = NetLink {
            shared,
            stop,
            thread: Some(thread),
            _agora_token: agora_token,
            _finder: finder,
        };
        Ok(link)
    }

    /// The other Agoras up on the network (the Finder's view).
    pub fn agoras(&self) -> Vec<AgoraId> {
        lock(&self.shared.agoras).iter().map(|&a| AgoraId(a)).collect()
    }

    /// A handle that tells, from any thread, whether an Agora is on the network now.
    pub fn presence(&self) -> NetPresence {
        NetPresence(self.shared.clone())
    }

    /// Whether some other Agora wants messages of `ty`.
    pub fn remote_wants(&self, ty: MsgType) -> bool {
        self.shared.wanted.load().contains(&ty.0)
    }

    /// The other Agoras whose Members subscribed to `ty` (the Finder's view), sorted.
    pub fn subscribers(&self, ty: MsgType) -> Vec<AgoraId> {
        let interest = lock(&self.shared.interest);
        let mut ids: Vec<AgoraId> =
            interest.iter().filter(|(_, t)| t.contains(&ty.0)).map(|(&a, _)| AgoraId(a)).collect();
        ids.sort();
        ids
    }

    /// Whether this Agora receives messages of `ty` from the network now.
    pub fn receives(&self, ty: MsgType) -> bool {
        self.shared.subscribed.load().contains(&ty.0)
    }

    /// The counters.
    pub fn stats(&self) -> NetStats {
        let c = &self.shared.counters;
        NetStats {
            sent: c.sent.load(Ordering::Relaxed),
            delivered: c.delivered.load(Ordering::Relaxed),
            malformed: c.malformed.load(Ordering::Relaxed),
            unwanted: c.unwanted.load(Ordering::Relaxed),
            duplicates: c.duplicates.load(Ordering::Relaxed),
        }
    }

    /// Waits until `ready` holds (checked every 5 ms) or `timeout` passes; returns whether it
    /// held. For start-up: discovery takes a few milliseconds on loopback.
    pub fn wait_until(&self, timeout: Duration, ready: impl Fn(&NetLink) -> bool) -> bool {
        let end = std::time::Instant::now() + timeout;
        loop {
            if ready(self) {
                return true;
            }
            if std::time::Instant::now() >= end {
                return false;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// The zenoh session (to publish raw frames in tests and benchmarks).
    pub fn session(&self) -> &zenoh::Session {
        &self.shared.session
    }

    /// A handle for plain zenoh payloads beside DCDT's frames, for programs that are not
    /// Agoras (`mrt edge`: messages as JSON for other languages).
    pub fn raw(&self) -> RawPort {
        RawPort(self.shared.session.clone())
    }
}

/// Plain zenoh puts and subscriptions on an Agora's session, outside DCDT's framing
/// ([`NetLink::raw`]). Keys under `mrt/m/` are DCDT's and refused here.
#[derive(Clone)]
pub struct RawPort(zenoh::Session);

/// A subscription of a [`RawPort`]: it lasts while this lives.
pub struct RawSubscription(#[allow(dead_code)] Subscriber<()>);

/// A liveliness token of a [`RawPort`]: it is on the network while this lives.
pub struct RawToken(#[allow(dead_code)] LivelinessToken);

impl RawPort {
    fn check(key: &str) -> Result<(), NetError> {
        if key.starts_with(&format!("{ROOT}/m/")) || key == format!("{ROOT}/m") {
            return Err(NetError::Zenoh(format!("{key}: keys under {ROOT}/m/ carry DCDT frames")));
        }
        Ok(())
    }

    /// A session of its own, not an Agora's, joined to the network `cfg` describes (a program
    /// that speaks plain zenoh only, such as a robot on a world's devices without teammates).
    pub fn open(cfg: &NetConfig) -> Result<RawPort, NetError> {
        zenoh::open(cfg.zenoh_config()?)
            .wait()
            .map(RawPort)
            .map_err(|e| NetError::Zenoh(e.to_string()))
    }

    /// Declares a liveliness token on `key`: others see it while the token lives and the
    /// session is up.
    pub fn declare_token(&self, key: &str) -> Result<RawToken, NetError> {
        Self::check(key)?;
        self.0
            .liveliness()
            .declare_token(key.to_string())
            .wait()
            .map(RawToken)
            .map_err(|e| NetError::Zenoh(e.to_string()))
    }

    /// Calls `f` with the key of every liveliness token matching `key_expr` that is on the
    /// network now or appears later (`true`), and of each one that goes away (`false`: its
    /// owner dropped it, or its session ended), on zenoh's receiving thread.
    pub fn watch_tokens(
        &self,
        key_expr: &str,
        f: impl Fn(&str, bool) + Send + Sync + 'static,
    ) -> Result<RawSubscription, NetError> {
        Self::check(key_expr)?;
        self.0
            .liveliness()
            .declare_subscriber(key_expr.to_string())
            .history(true)
            .callback(move |s: Sample| f(s.key_expr().as_str(), s.kind() == SampleKind::Put))
            .wait()
            .map(RawSubscription)
            .map_err(|e| NetError::Zenoh(e.to_string()))
    }

    /// Puts `bytes` on `key` (reliably: blocks when the link is congested).
    pub fn put(&self, key: &str, bytes: Vec<u8>) -> Result<(), NetError> {
        Self::check(key)?;
        self.0
            .put(key, bytes)
            .congestion_control(CongestionControl::Block)
            .wait()
            .map_err(|e| NetError::Zenoh(e.to_string()))
    }

    /// Calls `f` with the key and the payload of everything put on keys matching `key_expr`
    /// (a zenoh key expression, e.g. `mrt/json-in/*`), on zenoh's receiving thread.
    pub fn subscribe(
        &self,
        key_expr: &str,
        f: impl Fn(&str, Vec<u8>) + Send + Sync + 'static,
    ) -> Result<RawSubscription, NetError> {
        Self::check(key_expr)?;
        self.0
            .declare_subscriber(key_expr.to_string())
            .callback(move |s: Sample| {
                f(s.key_expr().as_str(), s.payload().to_bytes().into_owned())
            })
            .wait()
            .map(RawSubscription)
            .map_err(|e| NetError::Zenoh(e.to_string()))
    }
}

impl Drop for NetLink {
    fn drop(&mut self) {
        self.shared.port.set_outlet(None);
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
        let _ = self.shared.session.close().wait();
    }
}

/// Keeps the network subscriptions and want tokens equal to the Agora's remote interest.
fn maintain(shared: &Weak<Shared>, stop: &AtomicBool) {
    let mut declared = Declared { subscribers: FxHashMap::default(), tokens: FxHashMap::default() };
    while !stop.load(Ordering::Relaxed) {
        let Some(sh) = shared.upgrade() else { return };
        let now: FxHashSet<u32> = sh.port.remote_interest().into_iter().map(|t| t.0).collect();
        let before: FxHashSet<u32> = declared.subscribers.keys().copied().collect();
        if now != before {
            for ty in now.difference(&before) {
                let weak = Arc::downgrade(&sh);
                let sub = sh
                    .session
                    .declare_subscriber(format!("{ROOT}/m/{ty}"))
                    .callback(move |s: Sample| {
                        if let Some(sh) = weak.upgrade() {
                            sh.on_frame(&s.payload().to_bytes());
                        }
                    })
                    .wait();
                let token = sh
                    .session
                    .liveliness()
                    .declare_token(format!("{ROOT}/want/{}/{ty}", sh.id.0))
                    .wait();
                match (sub, token) {
                    (Ok(s), Ok(t)) => {
                        declared.subscribers.insert(*ty, s);
                        declared.tokens.insert(*ty, t);
                    }
                    (Err(e), _) | (_, Err(e)) => {
                        tracing::warn!(agora = %sh.id, "cannot subscribe to type {ty}: {e}");
                    }
                }
            }
            for ty in before.difference(&now) {
                declared.subscribers.remove(ty);
                declared.tokens.remove(ty);
            }
            sh.subscribed.store(Arc::new(declared.subscribers.keys().copied().collect()));
        }
        drop(sh);
        std::thread::sleep(MAINTENANCE);
    }
}
