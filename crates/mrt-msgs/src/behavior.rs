//! What the behavior Members say and hear besides the command (ThinkingCap, ThinkingCap/TeamChaos report §3.2:
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

/// An edited behavior file sent to a running robot (ThinkingCap/TeamChaos report §3.2: a behavior with no syntax
/// errors "can be sent to the robot at any time, without the need of stopping or rebooting
/// it"). The robot whose Agora is `robot` compiles it off its control path, writes it into its
/// behavior directory and swaps it in at a cycle boundary, or keeps its running version, and
/// answers with a [`BehaviorPushReply`] either way (`mrt behave push`).
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BehaviorPush {
    /// The Agora of the robot it is for (the others ignore it).
    pub robot: u32,
    /// The sender's number for this request, repeated in the reply.
    pub request: u64,
    /// The file's name in the robot's behavior directory (`attacker.lua`,
    /// `player.hfsm.lua`, `hbm.lua`): a bare name ending in `.lua`, no directories.
    pub file: String,
    /// The file's new text.
    pub source: String,
}

/// A robot's answer to a [`BehaviorPush`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BehaviorPushReply {
    /// The robot's Agora.
    pub robot: u32,
    /// The request answered.
    pub request: u64,
    /// The file, as the request named it.
    pub file: String,
    /// Whether the new version runs from the next cycle on. When not, the robot keeps its
    /// running version and `error` says why.
    pub installed: bool,
    /// What was swapped in (behavior names, `hbm`, the HFSM file).
    pub reloaded: Vec<String>,
    /// Why the file was refused, as a local hot reload reports it (`file:line: message`).
    pub error: Option<String>,
    /// The line of the error, when it has one.
    pub line: Option<u32>,
}

/// The shape of a behavior Member's HFSM, for monitors that draw it (ThinkingCap/TeamChaos report
/// §4.1 and §5.1: the HFSM editor's and monitor's view of the machines): its machines, each
/// with its states and labelled transitions. Published when the machine is loaded or
/// reloaded, and again now and then for monitors that join late; never each cycle. Together
/// with [`BehaviorStatus::path`] (`Root/State/Inner`) it says where in the drawing the robot
/// is.
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HfsmStructure {
    /// The file it was loaded from.
    pub file: String,
    /// The root machine's name (the first element of every active path).
    pub root: String,
    /// Every machine of the file, the root first.
    pub machines: Vec<HfsmMachine>,
}

/// One machine of an [`HfsmStructure`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HfsmMachine {
    /// Its name.
    pub name: String,
    /// The state it starts in.
    pub initial: String,
    /// Its states, in file order.
    pub states: Vec<HfsmState>,
    /// Its transitions, in the order they are checked.
    pub transitions: Vec<HfsmTransition>,
}

/// One state of an [`HfsmMachine`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HfsmState {
    /// Its name (an element of the active path).
    pub name: String,
    /// For a meta-state, the machine it runs (whose states are its children).
    pub runs: Option<String>,
}

/// One transition of an [`HfsmMachine`].
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HfsmTransition {
    /// Its name (`from->to` when the file gave none).
    pub name: String,
    /// The state it leaves.
    pub from: String,
    /// The state it enters.
    pub to: String,
    /// Its priority (smaller is checked first).
    pub priority: f64,
    /// Its test as drawings show it: the predicate's text, or `function (line N)`.
    pub test: String,
}
