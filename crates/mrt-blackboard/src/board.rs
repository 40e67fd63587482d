//! The blackboard itself: a thread-safe table of symbols, typed values with their time stamps,
//! watchers, and the outbox of shared changes for the [`crate::Proxy`].

use crate::symbol::{Kind, Pattern, Symbol, SymbolError};
use crate::value::{FromValue, Value, ValueType};
use crossbeam_channel::{Receiver, Sender, TrySendError};
use mrt_core::{SharedClock, Time};
use rustc_hash::FxHashMap;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, RwLock, Weak};
use std::time::Duration;

/// Values a `talk` queue keeps; pushing more drops the oldest.
pub const TALK_CAPACITY: usize = 256;

/// Changes a watcher may have waiting; more are dropped (and counted) until it reads.
pub const WATCH_CAPACITY: usize = 1024;

/// Shared changes waiting for the proxy; more are dropped (and counted).
pub const OUTBOX_CAPACITY: usize = 4096;

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
}

enum Entry {
    Var(Stamped),
    Talk(VecDeque<Stamped>),
}

struct Slot {
    symbol: Arc<str>,
    ty: ValueType,
    entry: Entry,
}

#[derive(Default)]
struct Table {
    index: FxHashMap<Arc<str>, usize>,
    slots: Vec<Slot>,
}

struct Watcher {
    id: u64,
    pattern: Pattern,
    tx: Sender<Change>,
}

struct Inner {
    robot: u32,
    clock: SharedClock,
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
    /// The blackboard of robot `robot`, stamping with `clock`.
    pub fn new(robot: u32, clock: SharedClock) -> Blackboard {
        Blackboard {
            inner: Arc::new(Inner {
                robot,
                clock,
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
        self.store(symbol, value.into(), None, Kind::Var)
    }

    /// Appends `value` to the `talk` queue `symbol`.
    pub fn push(&self, symbol: &str, value: impl Into<Value>) -> Result<(), BbError> {
        self.store(symbol, value.into(), None, Kind::Talk)
    }

    /// Takes the oldest value of the `talk` queue `symbol` (`None` when it is empty).
    pub fn pop(&self, symbol: &str) -> Result<Option<Stamped>, BbError> {
        let mut table = write(&self.inner.table);
        let Some(&i) = table.index.get(symbol) else { return Err(unknown(symbol)) };
        match &mut table.slots[i].entry {
            Entry::Talk(q) => Ok(q.pop_front()),
            Entry::Var(_) => Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Var }),
        }
    }

    /// Applies a change received from another robot: checked like a local one, stamped on
    /// this robot's clock, not sent on again.
    pub fn apply(&self, update: &Update) -> Result<(), BbError> {
        let parsed = Symbol::parse(&update.symbol)?;
        if !parsed.scope().is_shared() {
            return Err(BbError::NotShared(update.symbol.clone()));
        }
        self.store(&update.symbol, update.value.clone(), Some(update.from), parsed.kind())
    }

    fn store(
        &self,
        symbol: &str,
        value: Value,
        from: Option<u32>,
        kind: Kind,
    ) -> Result<(), BbError> {
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
                    let name: Arc<str> = Arc::from(symbol);
                    let entry = match kind {
                        Kind::Var => Entry::Var(stamped.clone()),
                        Kind::Talk => Entry::Talk(VecDeque::new()),
                    };
                    let i = table.slots.len();
                    table.slots.push(Slot { symbol: name.clone(), ty, entry });
                    table.index.insert(name, i);
                    i
                }
            };
            let slot = &mut table.slots[i];
            if slot.ty != ty {
                return Err(BbError::Type {
                    symbol: symbol.to_string(),
                    stored: slot.ty,
                    wanted: ty,
                });
            }
            match &mut slot.entry {
                Entry::Var(v) if kind == Kind::Var => *v = stamped.clone(),
                Entry::Talk(q) if kind == Kind::Talk => {
                    if q.len() >= TALK_CAPACITY {
                        q.pop_front();
                    }
                    q.push_back(stamped.clone());
                }
                Entry::Var(_) => {
                    return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Var })
                }
                Entry::Talk(_) => {
                    return Err(BbError::Kind { symbol: symbol.to_string(), kind: Kind::Talk })
                }
            }
            let shared = from.is_none() && !symbol.starts_with("local.");
            (slot.symbol.clone(), shared)
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
            .map(|s| {
                let v = match &s.entry {
                    Entry::Var(v) => Some(v.clone()),
                    Entry::Talk(q) => q.front().cloned(),
                };
                (s.symbol.clone(), v)
            })
            .collect();
        out.sort_by(|a, b| a.0.cmp(&b.0));
        out
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
}
