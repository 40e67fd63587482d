//! The blackboard itself: a thread-safe table of symbols, typed values with their time stamps,
//! watchers, and the outbox of shared changes for the [`crate::Proxy`].
//!
//! # Limits
//!
//! A blackboard holds at most [`BbLimits::max_symbols`] symbols and
//! [`BbLimits::max_bytes`] accounted bytes, and a `String` value is at most
//! [`BbLimits::max_string`] bytes; a set past a limit is refused ([`BbError::Full`],
//! [`BbError::TooLong`]) and changes nothing. *Guests* — the relay ([`Blackboard::set_as_guest`])
//! and other robots ([`Blackboard::apply`]) — create new symbols only while fewer than
//! [`BbLimits::max_guest_symbols`] exist, so that they cannot take the room the robot's own
//! Members need.

use crate::symbol::{Kind, Pattern, Symbol, SymbolError};
use crate::value::{FromValue, Value, ValueType};
use crossbeam_channel::{Receiver, Sender, TrySendError};
use mrt_core::{SharedClock, Time};
use rustc_hash::FxHashMap;
use std::collections::{BTreeMap, VecDeque};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, RwLock, Weak};
use std::time::Duration;

/// Values a `talk` queue keeps; pushing more drops the oldest.
pub const TALK_CAPACITY: usize = 256;

/// Changes a watcher may have waiting; more are dropped (and counted) until it reads.
pub const WATCH_CAPACITY: usize = 1024;

/// Shared changes waiting for the proxy; more are dropped (and counted).
pub const OUTBOX_CAPACITY: usize = 4096;

/// Default [`BbLimits::max_symbols`].
pub const DEFAULT_MAX_SYMBOLS: usize = 16_384;

/// Default [`BbLimits::max_guest_symbols`].
pub const DEFAULT_MAX_GUEST_SYMBOLS: usize = 8_192;

/// Default [`BbLimits::max_string`], bytes.
pub const DEFAULT_MAX_STRING: usize = 1_024;

/// Default [`BbLimits::max_bytes`]: 32 MiB.
pub const DEFAULT_MAX_BYTES: usize = 32 << 20;

/// Bytes accounted for each symbol besides its name (its slot, index entry and log entry).
pub const SYMBOL_OVERHEAD: usize = 128;

/// Bytes accounted for each value held besides a string's text (the value and its stamp).
pub const VALUE_OVERHEAD: usize = 48;

/// How much a blackboard holds. A set that would go past a limit is refused and changes
/// nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BbLimits {
    /// Symbols on the blackboard, at most (default [`DEFAULT_MAX_SYMBOLS`]).
    pub max_symbols: usize,
    /// A guest (the relay, another robot) creates a symbol only while fewer than this many
    /// exist (default [`DEFAULT_MAX_GUEST_SYMBOLS`]); it still sets the existing ones.
    pub max_guest_symbols: usize,
    /// Longest `String` value, bytes of UTF-8 (default [`DEFAULT_MAX_STRING`]).
    pub max_string: usize,
    /// Accounted bytes held, at most (default [`DEFAULT_MAX_BYTES`]): each symbol counts its
    /// name plus [`SYMBOL_OVERHEAD`], each value held (a `var`'s, every one waiting in a
    /// `talk` queue) [`VALUE_OVERHEAD`] plus a string's text.
    pub max_bytes: usize,
}

impl Default for BbLimits {
    fn default() -> Self {
        BbLimits {
            max_symbols: DEFAULT_MAX_SYMBOLS,
            max_guest_symbols: DEFAULT_MAX_GUEST_SYMBOLS,
            max_string: DEFAULT_MAX_STRING,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

fn value_bytes(v: &Value) -> usize {
    VALUE_OVERHEAD
        + match v {
            Value::String(s) => s.len(),
            _ => 0,
        }
}

/// A value with the time it was set, on this robot's clock (for a value received from
/// another robot: when it arrived, so that clock skew between robots does not matter).
#[derive(Clone, Debug, PartialEq)]
pub struct Stamped {
    /// The value.
    pub value: Value,
    /// When it was set or received.
    pub time: Time,
    /// The robot it came from, when it came over the network.
    pub from: Option<u32>,
}

/// A symbol with its latest value (a `talk` queue: its oldest waiting value, if any).
pub type Current = (Arc<str>, Option<Stamped>);

/// One change, as a watcher receives it.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    /// The symbol.
    pub symbol: Arc<str>,
    /// The new value (a `talk` symbol: the value pushed).
    pub value: Stamped,
}

/// A change of a shared (`*` or `n`) symbol, travelling between robots.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Update {
    /// The robot whose blackboard it was set on.
    pub from: u32,
    /// The symbol (text; checked by the receiver).
    pub symbol: String,
    /// The value.
    pub value: Value,
}

/// What went wrong with a blackboard operation.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BbError {
    /// Not a symbol.
    #[error(transparent)]
    Symbol(#[from] SymbolError),
    /// Nothing is bound to the symbol.
    #[error("`{0}` is not on the blackboard")]
    Unknown(String),
    /// The stored value has another type.
    #[error("`{symbol}` holds a {stored}, not a {wanted}")]
    Type {
        /// The symbol.
        symbol: String,
        /// The type stored.
        stored: ValueType,
        /// The type asked for or given.
        wanted: ValueType,
    },
    /// A `var` operation on a `talk` symbol or the other way round.
    #[error("`{symbol}` is a {kind} symbol")]
    Kind {
        /// The symbol.
        symbol: String,
        /// Its kind.
        kind: Kind,
    },
    /// A change from another robot for a `local` symbol.
    #[error("`{0}` is local: it does not travel between robots")]
    NotShared(String),
    /// A new symbol, or a value, past the blackboard's room ([`BbLimits`]).
    #[error("the blackboard is full: `{symbol}` does not fit ({what})")]
    Full {
        /// The symbol.
        symbol: String,
        /// Which limit, and its value.
        what: String,
    },
    /// A `String` value longer than [`BbLimits::max_string`].
    #[error("`{symbol}`: a string is at most {max} bytes, this one has {len}")]
    TooLong {
        /// The symbol.
        symbol: String,
        /// The string's length, bytes.
        len: usize,
        /// The limit, bytes.
        max: usize,
    },
}

enum Entry {
    Var(Stamped),
    Talk(VecDeque<Stamped>),
}

struct Slot {
    symbol: Arc<str>,
    ty: ValueType,
    entry: Entry,
    /// The table's version when this slot last changed (its key in [`Table::log`]).
    version: u64,
}

impl Slot {
    fn current(&self) -> Option<Stamped> {
        match &self.entry {
            Entry::Var(v) => Some(v.clone()),
            Entry::Talk(q) => q.front().cloned(),
        }
    }
}

#[derive(Default)]
struct Table {
    index: FxHashMap<Arc<str>, usize>,
    slots: Vec<Slot>,
    /// Accounted bytes held ([`BbLimits::max_bytes`]).
    bytes: usize,
    /// Counts changes (sets, pushes, pops).
    version: u64,
    /// Each slot under the version of its last change: the changes since a version are a
    /// range, whatever the number of symbols.
    log: BTreeMap<u64, usize>,
}

impl Table {
    fn touch(&mut self, i: usize) {
        self.version += 1;
        let v = self.version;
        if let Some(slot) = self.slots.get_mut(i) {
            self.log.remove(&slot.version);
            slot.version = v;
            self.log.insert(v, i);
        }
    }
}

/// Who sets a value: the robot itself, or a guest (relay client or other robot).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Origin {
    Own,
    Guest,
}

struct Watcher {
    id: u64,
    pattern: Pattern,
    tx: Sender<Change>,
}

struct Inner {
    robot: u32,
    clock: SharedClock,
    limits: BbLimits,
    table: RwLock<Table>,
    watchers: RwLock<Vec<Watcher>>,
    next_watch: AtomicU64,
    outbox: Mutex<Option<Sender<Update>>>,
    dropped: AtomicU64,
}

/// A robot's blackboard. Cloning gives another handle to the same blackboard.
///
/// ```
/// use mrt_blackboard::Blackboard;
/// let bb = Blackboard::new(1, std::sync::Arc::new(mrt_core::SimClock::new()));
/// bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
/// assert_eq!(bb.get::<f64>("local.var.machine.config.def.near-ball").unwrap(), 0.8);
/// ```
#[derive(Clone)]
pub struct Blackboard {
    inner: Arc<Inner>,
}

impl std::fmt::Debug for Blackboard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Blackboard").field("robot", &self.inner.robot).finish_non_exhaustive()
    }
}

fn read<T>(l: &RwLock<T>) -> std::sync::RwLockReadGuard<'_, T> {
    // A panic while holding the lock cannot leave the table half-changed (every change is
    // one assignment), so a poisoned lock is still good to use.
    l.read().unwrap_or_else(std::sync::PoisonError::into_inner)
}

fn write<T>(l: &RwLock<T>) -> std::sync::RwLockWriteGuard<'_, T> {
    l.write().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Blackboard {
    /// The blackboard of robot `robot`, stamping with `clock`, with the default [`BbLimits`].
    pub fn new(robot: u32, clock: SharedClock) -> Blackboard {
        Blackboard::with_limits(robot, clock, BbLimits::default())
    }

    /// The blackboard of robot `robot`, stamping with `clock`, holding at most `limits`.
    pub fn with_limits(robot: u32, clock: SharedClock, limits: BbLimits) -> Blackboard {
        Blackboard {
            inner: Arc::new(Inner {
                robot,
                clock,
                limits,
                table: RwLock::default(),
                watchers: RwLock::default(),
                next_watch: AtomicU64::new(0),
                outbox: Mutex::new(None),
                dropped: AtomicU64::new(0),
            }),
        }
    }

    /// This robot's ID.
    pub fn robot(&self) -> u32 {
        self.inner.robot
    }

    /// What it holds at most.
    pub fn limits(&self) -> BbLimits {
        self.inner.limits
    }

    /// Symbols on the blackboard.
    pub fn len(&self) -> usize {
        read(&self.inner.table).slots.len()
    }

    /// Whether no symbol is bound.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Accounted bytes held ([`BbLimits::max_bytes`]).
    pub fn bytes(&self) -> usize {
        read(&self.inner.table).bytes
    }

    /// The latest value of the `var` symbol `symbol`, as a `T`.
    pub fn get<T: FromValue>(&self, symbol: &str) -> Result<T, BbError> {
        let table = read(&self.inner.table);
        let slot = table
            .index
            .get(symbol)
            .and_then(|&i| table.slots.get(i))
            .ok_or_else(|| unknown(symbol))?;
        let Entry::Var(v) = &slot.entry else {
            return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Talk });
        };
        T::from_value(&v.value).ok_or_else(|| BbError::Type {
            symbol: symbol.to_string(),
            stored: slot.ty,
            wanted: T::TYPE,
        })
    }

    /// The latest value of the `var` symbol `symbol` with its time stamp.
    pub fn get_stamped(&self, symbol: &str) -> Result<Stamped, BbError> {
        let table = read(&self.inner.table);
        match table.index.get(symbol).and_then(|&i| table.slots.get(i)) {
            Some(Slot { entry: Entry::Var(v), .. }) => Ok(v.clone()),
            Some(_) => Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Talk }),
            None => Err(unknown(symbol)),
        }
    }

    /// Binds `value` to the `var` symbol `symbol`, stamped now. The first set fixes the
    /// symbol's type; later sets must keep it. A shared symbol's change goes to the proxy.
    pub fn set(&self, symbol: &str, value: impl Into<Value>) -> Result<(), BbError> {
        self.store(symbol, value.into(), None, Kind::Var, Origin::Own)
    }

    /// [`Blackboard::set`] for a guest (the relay): a new symbol only while fewer than
    /// [`BbLimits::max_guest_symbols`] exist.
    pub fn set_as_guest(&self, symbol: &str, value: impl Into<Value>) -> Result<(), BbError> {
        self.store(symbol, value.into(), None, Kind::Var, Origin::Guest)
    }

    /// Appends `value` to the `talk` queue `symbol`.
    pub fn push(&self, symbol: &str, value: impl Into<Value>) -> Result<(), BbError> {
        self.store(symbol, value.into(), None, Kind::Talk, Origin::Own)
    }

    /// Takes the oldest value of the `talk` queue `symbol` (`None` when it is empty).
    pub fn pop(&self, symbol: &str) -> Result<Option<Stamped>, BbError> {
        let mut table = write(&self.inner.table);
        let Some(&i) = table.index.get(symbol) else { return Err(unknown(symbol)) };
        let popped = match &mut table.slots[i].entry {
            Entry::Talk(q) => q.pop_front(),
            Entry::Var(_) => {
                return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Var })
            }
        };
        if let Some(p) = &popped {
            table.bytes = table.bytes.saturating_sub(value_bytes(&p.value));
            table.touch(i);
        }
        Ok(popped)
    }

    /// Applies a change received from another robot: checked like a local one and against
    /// the limits of a guest, stamped on this robot's clock, not sent on again.
    pub fn apply(&self, update: &Update) -> Result<(), BbError> {
        let parsed = Symbol::parse(&update.symbol)?;
        if !parsed.scope().is_shared() {
            return Err(BbError::NotShared(update.symbol.clone()));
        }
        let value = update.value.clone();
        self.store(&update.symbol, value, Some(update.from), parsed.kind(), Origin::Guest)
    }

    fn store(
        &self,
        symbol: &str,
        value: Value,
        from: Option<u32>,
        kind: Kind,
        origin: Origin,
    ) -> Result<(), BbError> {
        let limits = &self.inner.limits;
        if let Value::String(s) = &value {
            if s.len() > limits.max_string {
                return Err(BbError::TooLong {
                    symbol: shown(symbol),
                    len: s.len(),
                    max: limits.max_string,
                });
            }
        }
        let full = |what: String| BbError::Full { symbol: shown(symbol), what };
        if let Value::Float(x) = value {
            if !x.is_finite() {
                return Err(BbError::Type {
                    symbol: symbol.to_string(),
                    stored: ValueType::Float,
                    wanted: ValueType::Float,
                });
            }
        }
        let stamped = Stamped { value, time: self.inner.clock.now(), from };
        let ty = stamped.value.value_type();
        let (name, shared) = {
            let mut table = write(&self.inner.table);
            let i = match table.index.get(symbol) {
                Some(&i) => i,
                None => {
                    let parsed = Symbol::parse(symbol)?;
                    if parsed.kind() != kind {
                        return Err(BbError::Kind {
                            symbol: symbol.to_string(),
                            kind: parsed.kind(),
                        });
                    }
                    let cap = match origin {
                        Origin::Own => limits.max_symbols,
                        Origin::Guest => limits.max_guest_symbols.min(limits.max_symbols),
                    };
                    if table.slots.len() >= cap {
                        let who = if origin == Origin::Guest { " from a guest" } else { "" };
                        return Err(full(format!("at most {cap} symbols{who}")));
                    }
                    let add = SYMBOL_OVERHEAD + symbol.len();
                    if table.bytes + add + value_bytes(&stamped.value) > limits.max_bytes {
                        return Err(full(format!("at most {} bytes", limits.max_bytes)));
                    }
                    let name: Arc<str> = Arc::from(symbol);
                    let entry = match kind {
                        Kind::Var => Entry::Var(stamped.clone()),
                        Kind::Talk => Entry::Talk(VecDeque::new()),
                    };
                    table.bytes += add
                        + match kind {
                            Kind::Var => value_bytes(&stamped.value),
                            Kind::Talk => 0,
                        };
                    let i = table.slots.len();
                    table.slots.push(Slot { symbol: name.clone(), ty, entry, version: 0 });
                    table.index.insert(name, i);
                    i
                }
            };
            let held = table.bytes;
            let slot = &mut table.slots[i];
            if slot.ty != ty {
                return Err(BbError::Type {
                    symbol: symbol.to_string(),
                    stored: slot.ty,
                    wanted: ty,
                });
            }
            let new = value_bytes(&stamped.value);
            let over = |old: usize| held - old.min(held) + new > limits.max_bytes;
            let bytes = match &mut slot.entry {
                Entry::Var(v) if kind == Kind::Var => {
                    let old = value_bytes(&v.value);
                    if over(old) {
                        return Err(full(format!("at most {} bytes", limits.max_bytes)));
                    }
                    *v = stamped.clone();
                    held - old.min(held) + new
                }
                Entry::Talk(q) if kind == Kind::Talk => {
                    let old = if q.len() >= TALK_CAPACITY {
                        q.front().map_or(0, |f| value_bytes(&f.value))
                    } else {
                        0
                    };
                    if over(old) {
                        return Err(full(format!("at most {} bytes", limits.max_bytes)));
                    }
                    if q.len() >= TALK_CAPACITY {
                        q.pop_front();
                    }
                    q.push_back(stamped.clone());
                    held - old.min(held) + new
                }
                Entry::Var(_) => {
                    return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Var })
                }
                Entry::Talk(_) => {
                    return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Talk })
                }
            };
            let shared = from.is_none() && !symbol.starts_with("local.");
            let name = slot.symbol.clone();
            table.bytes = bytes;
            table.touch(i);
            (name, shared)
        };
        if shared {
            self.send_out(symbol, &stamped.value);
        }
        self.notify(&name, stamped);
        Ok(())
    }

    fn send_out(&self, symbol: &str, value: &Value) {
        let outbox = self.inner.outbox.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(tx) = outbox.as_ref() {
            let update =
                Update { from: self.inner.robot, symbol: symbol.to_string(), value: value.clone() };
            if tx.try_send(update).is_err() {
                self.inner.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    fn notify(&self, name: &Arc<str>, value: Stamped) {
        let watchers = read(&self.inner.watchers);
        for w in watchers.iter().filter(|w| w.pattern.matches(name)) {
            let change = Change { symbol: name.clone(), value: value.clone() };
            if let Err(TrySendError::Full(_)) = w.tx.try_send(change) {
                self.inner.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    /// Watches the symbols `pattern` covers (a symbol, or a prefix ending in `.*`): every
    /// later change arrives on the returned [`Watch`] until it is dropped.
    pub fn watch(&self, pattern: &str) -> Result<Watch, BbError> {
        let pattern = Pattern::parse(pattern)?;
        let (tx, rx) = crossbeam_channel::bounded(WATCH_CAPACITY);
        let id = self.inner.next_watch.fetch_add(1, Ordering::Relaxed);
        write(&self.inner.watchers).push(Watcher { id, pattern, tx });
        Ok(Watch { id, rx, board: Arc::downgrade(&self.inner) })
    }

    /// The symbols `pattern` covers (all of them for `None`), sorted, with the latest value of
    /// each `var` (a `talk` queue: its oldest waiting value, if any).
    pub fn list(&self, pattern: Option<&Pattern>) -> Vec<(Arc<str>, Option<Stamped>)> {
        let table = read(&self.inner.table);
        let mut out: Vec<_> = table
            .slots
            .iter()
            .filter(|s| pattern.is_none_or(|p| p.matches(&s.symbol)))
            .map(|s| (s.symbol.clone(), s.current()))
            .collect();
        out.sort_by(|a, b| a.0.cmp(&b.0));
        out
    }

    /// The symbols `pattern` covers (all for `None`) that sort after `after` (all for
    /// `None`), in order, at most `max` of them, and whether more follow.
    pub fn symbols(
        &self,
        pattern: Option<&Pattern>,
        after: Option<&str>,
        max: usize,
    ) -> (Vec<Arc<str>>, bool) {
        let mut out: Vec<Arc<str>> = {
            let table = read(&self.inner.table);
            table
                .slots
                .iter()
                .filter(|s| pattern.is_none_or(|p| p.matches(&s.symbol)))
                .filter(|s| after.is_none_or(|a| &*s.symbol > a))
                .map(|s| s.symbol.clone())
                .collect()
        };
        out.sort_unstable();
        let more = out.len() > max;
        out.truncate(max);
        (out, more)
    }

    /// The blackboard's version: it grows with every change.
    pub fn version(&self) -> u64 {
        read(&self.inner.table).version
    }

    /// The symbols changed after version `since` that `wanted` keeps, with their latest
    /// value (a `talk` queue: its oldest waiting value, if any), in the order they last
    /// changed, and the version they bring the caller to. The cost grows with the changes,
    /// not with the symbols on the blackboard.
    pub fn changed_since(
        &self,
        since: u64,
        mut wanted: impl FnMut(&str) -> bool,
    ) -> (u64, Vec<Current>) {
        let table = read(&self.inner.table);
        let out = table
            .log
            .range(since.saturating_add(1)..)
            .filter_map(|(_, &i)| table.slots.get(i))
            .filter(|s| wanted(&s.symbol))
            .map(|s| (s.symbol.clone(), s.current()))
            .collect();
        (table.version, out)
    }

    /// The latest value of `symbol` (a `talk` queue: its oldest waiting value), if any.
    pub fn peek(&self, symbol: &str) -> Option<Stamped> {
        let table = read(&self.inner.table);
        table.index.get(symbol).and_then(|&i| table.slots.get(i)).and_then(Slot::current)
    }

    /// The shared changes made here from now on, for the proxy to send (one receiver: a second
    /// call replaces the first).
    pub fn outbox(&self) -> Receiver<Update> {
        let (tx, rx) = crossbeam_channel::bounded(OUTBOX_CAPACITY);
        *self.inner.outbox.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(tx);
        rx
    }

    /// Changes dropped because a watcher or the proxy did not keep up.
    pub fn dropped(&self) -> u64 {
        self.inner.dropped.load(Ordering::Relaxed)
    }

    /// This robot's clock.
    pub fn now(&self) -> Time {
        self.inner.clock.now()
    }
}

/// A symbol as an error shows it: at most [`crate::symbol::MAX_SYMBOL_LEN`] characters.
fn shown(symbol: &str) -> String {
    symbol.chars().take(crate::symbol::MAX_SYMBOL_LEN).collect()
}

fn unknown(symbol: &str) -> BbError {
    BbError::Unknown(symbol.chars().take(crate::symbol::MAX_SYMBOL_LEN).collect())
}

/// The changes a watcher receives. Dropping it ends the watch.
#[derive(Debug)]
pub struct Watch {
    id: u64,
    rx: Receiver<Change>,
    board: Weak<Inner>,
}

impl Watch {
    /// The next change, if one is waiting.
    pub fn try_recv(&self) -> Option<Change> {
        self.rx.try_recv().ok()
    }

    /// The next change, waiting at most `timeout`.
    pub fn recv_timeout(&self, timeout: Duration) -> Option<Change> {
        self.rx.recv_timeout(timeout).ok()
    }

    /// Every change waiting now.
    pub fn drain(&self) -> Vec<Change> {
        self.rx.try_iter().collect()
    }
}

impl Drop for Watch {
    fn drop(&mut self) {
        if let Some(inner) = self.board.upgrade() {
            write(&inner.watchers).retain(|w| w.id != self.id);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::SimClock;

    fn board() -> (Blackboard, Arc<SimClock>) {
        let clock = Arc::new(SimClock::new());
        (Blackboard::new(2, clock.clone()), clock)
    }

    #[test]
    fn values_are_typed_stamped_and_keep_their_type() {
        let (bb, clock) = board();
        clock.set(Time::from_secs_f64(1.5));
        bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
        bb.set("local.var.machine.role", "attacker").unwrap();
        bb.set("local.var.kicker.kick", true).unwrap();
        bb.set("local.var.vision.balls", 3).unwrap();
        assert_eq!(bb.get::<f64>("local.var.machine.config.def.near-ball").unwrap(), 0.8);
        assert_eq!(bb.get::<String>("local.var.machine.role").unwrap(), "attacker");
        assert!(bb.get::<bool>("local.var.kicker.kick").unwrap());
        assert_eq!(bb.get::<i64>("local.var.vision.balls").unwrap(), 3);
        assert_eq!(bb.get::<f64>("local.var.vision.balls").unwrap(), 3.0, "Int reads as f64");
        let s = bb.get_stamped("local.var.machine.role").unwrap();
        assert_eq!((s.time, s.from), (Time::from_secs_f64(1.5), None));
        // The type stays what the first set made it.
        let e = bb.set("local.var.machine.role", 2).unwrap_err();
        assert_eq!(e.to_string(), "`local.var.machine.role` holds a String, not a Int");
        let e = bb.get::<bool>("local.var.machine.role").unwrap_err();
        assert!(matches!(
            e,
            BbError::Type { stored: ValueType::String, wanted: ValueType::Bool, .. }
        ));
        assert_eq!(
            bb.get::<i64>("local.var.nothing").unwrap_err(),
            BbError::Unknown("local.var.nothing".into())
        );
        assert!(matches!(bb.set("local.vra.x", 1), Err(BbError::Symbol(_))));
        assert!(matches!(bb.set("local.var.x", f64::NAN), Err(BbError::Type { .. })));
    }

    #[test]
    fn talk_symbols_are_fifo_queues() {
        let (bb, _) = board();
        bb.push("*.talk.coord.offers", 1).unwrap();
        bb.push("*.talk.coord.offers", 2).unwrap();
        assert_eq!(bb.pop("*.talk.coord.offers").unwrap().unwrap().value, Value::Int(1));
        assert_eq!(bb.pop("*.talk.coord.offers").unwrap().unwrap().value, Value::Int(2));
        assert_eq!(bb.pop("*.talk.coord.offers").unwrap(), None);
        assert!(matches!(
            bb.set("*.talk.coord.offers", 3),
            Err(BbError::Kind { kind: Kind::Talk, .. })
        ));
        assert!(matches!(bb.push("local.var.x", 3), Err(BbError::Kind { kind: Kind::Var, .. })));
        for i in 0..TALK_CAPACITY + 10 {
            bb.push("local.talk.q", i as i64).unwrap();
        }
        assert_eq!(
            bb.pop("local.talk.q").unwrap().unwrap().value,
            Value::Int(10),
            "oldest dropped"
        );
    }

    #[test]
    fn watchers_get_the_changes_they_cover_until_dropped() {
        let (bb, _) = board();
        let machine = bb.watch("local.var.machine.*").unwrap();
        let role = bb.watch("local.var.machine.role").unwrap();
        bb.set("local.var.machine.role", "defender").unwrap();
        bb.set("local.var.machine.state", 4).unwrap();
        bb.set("local.var.vision.balls", 1).unwrap();
        let got: Vec<_> = machine.drain().into_iter().map(|c| c.symbol.to_string()).collect();
        assert_eq!(got, ["local.var.machine.role", "local.var.machine.state"]);
        assert_eq!(role.drain().len(), 1);
        drop(role);
        bb.set("local.var.machine.role", "keeper").unwrap();
        assert_eq!(read(&bb.inner.watchers).len(), 1);
        // A watcher that never reads loses changes beyond its capacity; they are counted.
        for i in 0..(WATCH_CAPACITY + 5) as i64 {
            bb.set("local.var.machine.state", i).unwrap();
        }
        // 1 + 1029 changes for 1024 places.
        assert_eq!(bb.dropped(), 6, "1024 waiting, the rest dropped");
        assert!(bb.watch("local.*.x").is_err());
    }

    #[test]
    fn shared_changes_go_out_and_remote_ones_come_in_stamped_here() {
        let (bb, clock) = board();
        let out = bb.outbox();
        bb.set("local.var.a", 1).unwrap();
        bb.set("*.var.team.cost", 2.5).unwrap();
        bb.set("2.var.machine.role", "attacker").unwrap();
        let sent: Vec<_> = out.try_iter().map(|u| (u.from, u.symbol)).collect();
        assert_eq!(
            sent,
            [(2, "*.var.team.cost".to_string()), (2, "2.var.machine.role".to_string())]
        );
        clock.set(Time::from_secs_f64(9.0));
        let update =
            Update { from: 3, symbol: "3.var.machine.role".into(), value: "keeper".into() };
        bb.apply(&update).unwrap();
        let got = bb.get_stamped("3.var.machine.role").unwrap();
        assert_eq!((got.time, got.from), (Time::from_secs_f64(9.0), Some(3)));
        assert!(out.try_recv().is_err(), "a received change is not sent on again");
        let local = Update { from: 3, symbol: "local.var.a".into(), value: 5.into() };
        assert_eq!(bb.apply(&local), Err(BbError::NotShared("local.var.a".into())));
        let bad = Update { from: 3, symbol: "not a symbol".into(), value: 5.into() };
        assert!(bb.apply(&bad).is_err());
        assert_eq!(bb.get::<i64>("local.var.a").unwrap(), 1);
    }

    #[test]
    fn list_shows_symbols_sorted_under_a_pattern() {
        let (bb, _) = board();
        bb.set("local.var.b", 1).unwrap();
        bb.set("local.var.a", 2).unwrap();
        bb.set("*.var.c", 3).unwrap();
        let all: Vec<_> = bb.list(None).into_iter().map(|(s, _)| s.to_string()).collect();
        assert_eq!(all, ["*.var.c", "local.var.a", "local.var.b"]);
        let local = Pattern::parse("local.*").unwrap();
        assert_eq!(bb.list(Some(&local)).len(), 2);
    }

    fn limited(limits: BbLimits) -> Blackboard {
        Blackboard::with_limits(1, Arc::new(SimClock::new()), limits)
    }

    /// A million `SETV`s of new names took 343 MB. Now the symbols are capped, and
    /// guests (relay, other robots) stop earlier, leaving room for the robot's own Members.
    #[test]
    fn symbols_are_capped_and_guests_leave_room_for_the_robot() {
        let limits = BbLimits { max_symbols: 4, max_guest_symbols: 2, ..BbLimits::default() };
        let bb = limited(limits);
        bb.set_as_guest("local.var.g1", 1).unwrap();
        bb.set_as_guest("local.var.g2", 1).unwrap();
        let e = bb.set_as_guest("local.var.g3", 1).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the blackboard is full: `local.var.g3` does not fit (at most 2 symbols from a guest)"
        );
        let remote = Update { from: 2, symbol: "2.var.x".into(), value: 1.into() };
        assert!(matches!(bb.apply(&remote), Err(BbError::Full { .. })));
        bb.set_as_guest("local.var.g1", 2).unwrap(); // existing symbols are still set
        bb.set("local.var.own1", 1).unwrap();
        bb.push("local.talk.own2", 1).unwrap();
        assert!(matches!(bb.set("local.var.own3", 1), Err(BbError::Full { .. })));
        assert_eq!(bb.len(), 4);
        assert!(bb.get::<i64>("local.var.g3").is_err(), "a refused set changes nothing");
    }

    #[test]
    fn strings_are_capped() {
        let bb = limited(BbLimits { max_string: 8, ..BbLimits::default() });
        bb.set("local.var.s", "12345678").unwrap();
        let e = bb.set("local.var.s", "123456789").unwrap_err();
        assert_eq!(e.to_string(), "`local.var.s`: a string is at most 8 bytes, this one has 9");
        assert!(matches!(bb.push("local.talk.q", "x".repeat(9)), Err(BbError::TooLong { .. })));
        let remote = Update { from: 2, symbol: "*.var.s".into(), value: "y".repeat(9).into() };
        assert!(matches!(bb.apply(&remote), Err(BbError::TooLong { .. })));
        assert_eq!(bb.get::<String>("local.var.s").unwrap(), "12345678");
    }

    /// Talk queues are bounded each; the byte budget bounds them all together.
    #[test]
    fn the_byte_budget_bounds_talk_queues_and_frees_on_pop() {
        let max = 4 * (SYMBOL_OVERHEAD + 12) + 40 * (VALUE_OVERHEAD + 100);
        let bb = limited(BbLimits { max_bytes: max, ..BbLimits::default() });
        let s = "x".repeat(100);
        let mut pushed = 0;
        'fill: for q in 0..4 {
            for _ in 0..TALK_CAPACITY {
                match bb.push(&format!("local.talk.q{q}"), s.as_str()) {
                    Ok(()) => pushed += 1,
                    Err(BbError::Full { .. }) => break 'fill,
                    Err(e) => panic!("{e}"),
                }
            }
        }
        assert!((40..=43).contains(&pushed), "{pushed}");
        assert!(bb.bytes() <= max);
        assert!(matches!(bb.set("local.var.more", s.as_str()), Err(BbError::Full { .. })));
        bb.pop("local.talk.q0").unwrap().unwrap();
        bb.push("local.talk.q0", s.as_str()).unwrap();
        // A var replaced by a value of the same size fits again and again.
        let bb = limited(BbLimits {
            max_bytes: 2 * (SYMBOL_OVERHEAD + 20 + VALUE_OVERHEAD),
            ..BbLimits::default()
        });
        for i in 0..100 {
            bb.set("local.var.counter", i).unwrap();
        }
        assert_eq!(bb.bytes(), SYMBOL_OVERHEAD + "local.var.counter".len() + VALUE_OVERHEAD);
    }

    #[test]
    fn changes_since_a_version_are_the_ones_made_after_it() {
        let (bb, _) = board();
        bb.set("local.var.a", 1).unwrap();
        bb.set("local.var.b", 1).unwrap();
        let (v, all) = bb.changed_since(0, |_| true);
        assert_eq!(all.len(), 2);
        assert_eq!(v, bb.version());
        bb.set("local.var.b", 2).unwrap();
        bb.set("local.var.b", 3).unwrap();
        bb.set("*.var.c", 1).unwrap();
        let (_, changed) = bb.changed_since(v, |s| s.starts_with("local."));
        assert_eq!(changed.len(), 1, "b once, with its latest value; c filtered out");
        assert_eq!(changed[0].0.as_ref(), "local.var.b");
        assert_eq!(changed[0].1.as_ref().map(|s| s.value.clone()), Some(Value::Int(3)));
        let (syms, more) = bb.symbols(None, Some("local.var.a"), 10);
        assert_eq!((syms.len(), more), (1, false));
        let (syms, more) = bb.symbols(None, None, 2);
        assert_eq!(
            (syms.iter().map(|s| s.to_string()).collect::<Vec<_>>(), more),
            (vec!["*.var.c".to_string(), "local.var.a".to_string()], true)
        );
    }
}
