//! What the behavior Members say and hear besides the command (ThinkingCap, seed `001` §3.2:
//! behaviors changed while the robot runs).

use serde::{Deserialize, Serialize};

/// What a behavior Member did in its last cycle, for monitors.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BehaviorStatus {
    /// The HFSM's active path (`Attacker/Score/Align`), empty for an HBM Member.
    pub path: String,
    /// The behavior that ran.
    pub behavior: Option<String>,
    /// Files reloaded before this cycle.
    pub reloaded: Vec<String>,
    /// Errors of this cycle (the robot went on regardless).
    pub errors: Vec<String>,
    /// How active each behavior was this cycle, 0 to 1, for a monitor's bars: Mr. BRIAN's
    /// behaviors by their WANT when their CANDO let them run, 0 otherwise (MRT manual
    /// §10.3.6). Empty when the engine reports none.
    #[serde(default)]
    pub activations: Vec<(String, f64)>,
}

/// Asks behavior Members to reload their changed scripts at the next cycle boundary.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReloadRequest;
