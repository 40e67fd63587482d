//! # mrt-blackboard: the ISocRob blackboard
//!
//! A robot's blackboard (ISocRob-2000 report §3.1) is a set of symbol/value bindings that its modules
//! share, and that robots share with each other. Symbols are dotted ASCII names whose first
//! level is the scope — `local` (this robot), `*` (all robots) or a robot's ID — and whose
//! second is the kind: `var` (the latest value) or `talk` (a FIFO queue) ([`symbol`]). Values
//! are `Int`, `Float`, `Bool` or `String` ([`value`]), each stamped with the time it was set
//! on this robot's clock. Watchers receive changes ([`Blackboard::watch`]); initial values
//! come from `config.dat` and `config-<id>.dat` ([`config`]); the [`Proxy`] Member carries
//! shared changes between robots over the DCDT bus; the [`Relay`] lets a person watch and set
//! variables over TCP (`docs/relay-protocol.md`, `mrt bb`).
//!
//! ```
//! use mrt_blackboard::Blackboard;
//! use std::sync::Arc;
//!
//! let bb = Blackboard::new(1, Arc::new(mrt_core::SimClock::new()));
//! let roles = bb.watch("local.var.machine.*").unwrap();
//! bb.set("local.var.machine.config.def.near-ball", 0.8).unwrap();
//! bb.set("local.var.machine.role", "defender").unwrap();
//! assert_eq!(bb.get::<f64>("local.var.machine.config.def.near-ball").unwrap(), 0.8);
//! assert_eq!(roles.drain().len(), 2);
//! // The type is fixed by the first set.
//! assert!(bb.set("local.var.machine.role", 3).is_err());
//! ```
#![deny(missing_docs)]

pub mod board;
pub mod config;
pub mod proxy;
pub mod relay;
pub mod symbol;
pub mod value;

pub use board::{BbError, BbLimits, Blackboard, Change, Stamped, Update, Watch};
pub use proxy::{BbUpdate, Proxy};
pub use relay::{Relay, RelayClient, RelayConfig};
pub use symbol::{Kind, Pattern, Scope, Symbol, SymbolError};
pub use value::{FromValue, Value, ValueType};
