//! A Member's trouble, from its executor's report: what a robot tells at the end of a match
//! (the device protocol's `bye`, the simulator's report).

use serde::{Deserialize, Serialize};

/// A Member of a robot's Agora that failed to start, failed jobs or panicked (each time it was
/// restarted), or whose mailbox lost messages, from its executor's report.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MemberFault {
    /// The Member's name.
    pub name: String,
    /// Errors, panics and restarts (at least 1).
    pub count: u64,
    /// Whether it never completed a cycle (it failed from the start).
    pub never_ran: bool,
    /// Its last error.
    pub error: String,
}
