//! The Mr. BRIAN engine (MRT manual chapter 10): loads a configuration directory, then turns
//! crisp inputs into crisp commands every cycle.
//!
//! One cycle: fuzzify the inputs (`ctof.txt`) → predicates (`Predicate.ini`) → for each level in
//! increasing order: re-fuzzify what lower levels proposed as `Proposed<Action>` data and
//! evaluate `PredicateActions.ini`, then run the level's behaviors (alphabetically) that the
//! CANDO filter lets run (by default: CANDO above the threshold, [`ThresholdFilter`]; or a
//! [`CandoFilter`] of the program's), each rule proposing its actions with value =
//! precondition value × reliability (a [`CodeBehavior`] proposes its own), weighted once by the
//! behavior's WANT ([`WeightComposer`]); compose per (action, label) ([`Composer`], by default
//! the maximum); apply `&DEL` to lower levels → defuzzify each action (`s_ftoc.txt`): by
//! singletons (formula 10.6) or, for a shape of polygons, by barycenter (formula 10.7,
//! [`crate::shapes::barycenter`]). [`Composition::Argmax`] keeps, for each output, only the
//! best behavior's proposals (formula 10.5); [`Semantics::Original`] reads reliability as the
//! original C++ engine did.
//!
//! # Opposite proposals
//!
//! When two behaviors propose opposite values for the same output (the manual's
//! *AvoidObstaclesFromLeft* and *AvoidObstaclesFromRight* facing one obstacle, §10.2.4):
//!
//! - **The manual's composition** (formula 10.3, singletons by formula 10.6) is a weighted
//!   mean: each proposed singleton counts with max over behaviors of WANT × rule value. Unequal
//!   wishes give a value between the two, nearer the stronger (turn rates −30 and +30 with
//!   weights 0.64 and 0.36 give −8.4); equal wishes cancel (0: straight on, into the obstacle).
//!   The manual knows it ("the vectorial combination of two actions may produce undesired
//!   effects") and leaves it to the WANT conditions never to let incompatible behaviors run
//!   together, or to the alternative of formula 10.5 (take the best behavior's actions only).
//! - **This engine** computes the same weighted mean for every output (both behaviors' weights
//!   are applied once, proposals of the same label combined by [`Composer`]), with one
//!   difference: outputs whose name contains `Angle` are averaged on the circle. There the
//!   manual's arithmetic mean of 90° and 270° is 180°, a heading nobody proposed; the engine
//!   gives the stronger wish's heading when the weights differ and, when they cancel exactly
//!   (the mean direction is undefined), 0°. Levels do not change this: a higher level
//!   overrides a lower one only through `&DEL`; otherwise all levels' proposals are composed
//!   together. To avoid the mean: design the WANTs so that opposite behaviors do not run at
//!   once, let the higher one `&DEL` the other's action, or choose formula 10.5
//!   (`composition argmax` in `engine.txt`, [`Composition::Argmax`]): only the behavior of
//!   larger μC · μW acts (−30 with weights 0.64 against 0.36).
//!
//! `tests/opposite_proposals.rs` checks both cases against a hand computation.
//!
//! The engine's files: this one holds the [`Brian`] type and its settings, the code behaviors'
//! view of a cycle ([`Situation`], [`Proposals`]) and what a cycle hands out ([`Commands`],
//! [`Trace`]); `files.rs` where a configuration comes from ([`BrianFiles`], [`BrianSources`]),
//! `parse.rs` the behavior list and rule parsers, `load.rs` the loading ([`Brian::from_dir`]),
//! `cycle.rs` one cycle ([`Brian::step`], [`Brian::run`]). The composers are in `compose.rs`
//! of the crate, shared with `engine.txt`'s parser.

mod cycle;
mod files;
mod load;
mod parse;
#[cfg(test)]
mod tests;

pub use crate::compose::{Composer, Composition, Semantics, WeightComposer};
pub use files::{BrianFiles, BrianSources, SOURCES_DEPTH};

use crate::compose::Acc;
use crate::error::BrianError;
use crate::expr::Expr;
use crate::lexer::Span;
use crate::set::{FuzzySet, FuzzyValue};
use crate::shapes::Shape;
use parse::Index;
use std::collections::BTreeMap;
use std::sync::Arc;

/// The default CANDO threshold (§10.4.4): a behavior runs when its CANDO value is above it.
pub const DEFAULT_THRESHOLD: f64 = 0.49;
/// A WANT value must exceed this to give a weight; below, the behavior's weight is 0.
pub const WANT_THRESHOLD: f64 = 0.49;
/// A rule whose precondition reliability is below this proposes nothing (§10.3.7).
pub const MIN_RELIABILITY: f64 = 0.1;

/// The highest level of `behavior.txt`: far beyond any hierarchy, and every level up to it is
/// a whole number an `f64` holds exactly (a larger one was silently read as `i64::MAX`).
pub const MAX_LEVEL: i64 = u32::MAX as i64;

/// A crisp input of `ctof.txt`.
#[derive(Clone, Debug)]
struct Input {
    name: String,
    shape: Shape,
    /// First index of its labels in the fuzzy data table.
    offset: usize,
    /// This cycle's value and reliability.
    now: Option<(f64, f64)>,
    /// The previous cycle's output of the same name, if any.
    previous: Option<f64>,
}

/// An output action of `s_ftoc.txt`.
#[derive(Clone, Debug)]
struct Action {
    name: String,
    /// Each label with its singleton (for a polygon shape, its set's barycenter at height 1).
    labels: Vec<(String, f64)>,
    /// Each label's set, in label order.
    sets: Vec<(String, FuzzySet)>,
    /// Defuzzified by barycenter (polygon sets, formula 10.7) rather than by singletons (10.6).
    barycenter: bool,
    circular: bool,
    /// The input slot `Proposed<name>` that re-fuzzifies this action for higher levels.
    proposed: Option<usize>,
    /// First index in the (action, label) accumulators.
    offset: usize,
}

#[derive(Clone, Copy, Debug)]
enum RuleAction {
    Propose(usize),
    Delete { action: usize, label: Option<usize> },
}

#[derive(Clone, Debug)]
struct Rule {
    precondition: Expr,
    actions: Vec<RuleAction>,
}

#[derive(Clone, Debug)]
struct Behavior {
    name: String,
    /// Where `behavior.txt` lists it.
    span: Span,
    level: i64,
    cando: Option<Expr>,
    want: Option<Expr>,
    rules: Vec<Rule>,
    /// For a behavior written in Rust (`code:<name>` in `behavior.txt`): its name and, once
    /// registered, its code.
    code: Option<CodeSlot>,
}

/// A code behavior's place in the engine.
#[derive(Clone, Debug)]
struct CodeSlot {
    name: String,
    behavior: Option<Plugged<dyn CodeBehavior>>,
}

/// Code plugged into the engine, shared by clones of it.
struct Plugged<T: ?Sized>(Arc<T>);

impl<T: ?Sized> Clone for Plugged<T> {
    fn clone(&self) -> Self {
        Plugged(self.0.clone())
    }
}

impl<T: ?Sized> std::fmt::Debug for Plugged<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("<code>")
    }
}

/// The prefix that marks a behavior written in Rust in `behavior.txt`:
/// `(level 1 KeepClear code:KeepClear)` instead of the path of a `.rul` file.
pub const CODE_PREFIX: &str = "code:";

/// A behavior written in Rust instead of a `.rul` file (MRT manual §10.3.6–10.3.7: "the user
/// can also write his own behaviors and then put them into Mr. BRIAN with very little effort";
/// the original engine's abstract `behavior` class, of which `rules_behavior` is one kind).
///
/// `behavior.txt` lists it as `(level <n> <name> code:<code name>)`; its CANDO and WANT come
/// from `Cando.ini` and `want.txt` like any behavior's, and
/// [`Brian::register_behavior`]`(<code name>, ...)` gives its code. Whenever the CANDO filter
/// lets it run, [`run`](CodeBehavior::run) reads the cycle's predicates, predicate actions and
/// fuzzy data from the [`Situation`] and proposes actions (or `&DEL`s) through the
/// [`Proposals`]; the engine weighs and composes them as a rule's.
///
/// ```
/// use mrt_fuzzy::brian::{Brian, BrianSources, CodeBehavior, Proposals, Situation};
///
/// /// SLOW as much as an obstacle is near.
/// struct Avoid;
/// impl CodeBehavior for Avoid {
///     fn run(&self, situation: &Situation<'_>, out: &mut Proposals<'_>) {
///         if let Some(blocked) = situation.predicate("Blocked") {
///             let _ = out.propose("Speed", "SLOW", blocked.value);
///         }
///     }
/// }
///
/// let mut files = BrianSources::new();
/// files.insert("shape_ctof.txt", "(DIST (TOL (NEAR 0 100)))");
/// files.insert("ctof.txt", "(Obst DIST)");
/// files.insert("Predicate.ini", "Blocked = (D Obst NEAR);");
/// files.insert("Cando.ini", "Avoid = (P Blocked);");
/// files.insert("want.txt", "Avoid = (P Blocked);");
/// files.insert("behavior.txt", "(level 1 Avoid code:Avoid)");
/// files.insert("s_shape.txt", "(SPEED (SNG (SLOW 20)) (SNG (FAST 80)))");
/// files.insert("s_ftoc.txt", "(Speed SPEED)");
/// let mut brian = Brian::from_sources(&files)?;
/// brian.register_behavior("Avoid", Avoid)?;
/// assert_eq!(brian.run(&[("Obst", 30.0, 1.0)])["Speed"], 20.0);
/// # Ok::<(), mrt_fuzzy::BrianError>(())
/// ```
pub trait CodeBehavior: Send + Sync {
    /// One cycle of the behavior: read the situation, propose actions.
    fn run(&self, situation: &Situation<'_>, out: &mut Proposals<'_>);
}

/// The CANDO filter (§10.3.6, the original engine's abstract `can_do_filter`): which behaviors
/// run, from their activation conditions. The default is the threshold filter
/// ([`ThresholdFilter`], `threshold_filter` in `engine.txt`); [`Brian::set_cando_filter`]
/// plugs another.
pub trait CandoFilter: Send + Sync {
    /// Whether `behavior`, whose CANDO is `cando`, runs this cycle.
    fn can_do(&self, behavior: &str, cando: FuzzyValue) -> bool;
}

/// The threshold filter (§10.3.6, `threshold_filter`): a behavior runs when its CANDO value is
/// above the threshold (default [`DEFAULT_THRESHOLD`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThresholdFilter {
    /// The threshold.
    pub threshold: f64,
}

impl CandoFilter for ThresholdFilter {
    fn can_do(&self, _behavior: &str, cando: FuzzyValue) -> bool {
        cando.value > self.threshold
    }
}

/// What a [`CodeBehavior`] sees of the cycle: the predicates of `Predicate.ini`, the predicate
/// actions of `PredicateActions.ini` as evaluated for its level (what lower levels propose),
/// the fuzzy data, and its own CANDO and WANT.
pub struct Situation<'a> {
    brian: &'a Brian,
    behavior: usize,
}

impl Situation<'_> {
    /// The behavior's name in `behavior.txt`.
    pub fn behavior(&self) -> &str {
        &self.brian.behaviors[self.behavior].name
    }

    /// The behavior's level.
    pub fn level(&self) -> i64 {
        self.brian.behaviors[self.behavior].level
    }

    /// A predicate of `Predicate.ini` or a predicate action of `PredicateActions.ini`, by name.
    pub fn predicate(&self, name: &str) -> Option<FuzzyValue> {
        let b = self.brian;
        match b.names.predicates.get(name) {
            Some(&i) => b.pred_values.get(i).copied(),
            None => b.act_values.get(*b.names.predicate_actions.get(name)?).copied(),
        }
    }

    /// The fuzzy datum `(D <input> <label>)`.
    pub fn datum(&self, input: &str, label: &str) -> Option<FuzzyValue> {
        let b = self.brian;
        let i = *b.names.inputs.get(input)?;
        let k = *b.names.labels.get(i)?.get(label)?;
        b.data.get(b.inputs.get(i)?.offset + k).copied()
    }

    /// The behavior's (CANDO, WANT) this cycle.
    pub fn activity(&self) -> Option<Activity> {
        self.brian.activity.get(self.behavior).copied().flatten()
    }
}

/// Where a [`CodeBehavior`] puts its actions: proposals `(action, label, value)` as a rule's
/// `(<action> <label>)` with the rule's value, and deletions as `&DEL.<action> <label|ANY>`.
pub struct Proposals<'a> {
    brian: &'a Brian,
    out: &'a mut Vec<(RuleAction, f64)>,
}

/// A name a [`CodeBehavior`] used that the configuration does not have.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownName(pub String);

impl std::fmt::Display for UnknownName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for UnknownName {}

impl Proposals<'_> {
    fn action(&self, action: &str) -> Result<usize, UnknownName> {
        let names = &self.brian.sorted_names;
        names
            .binary_search_by(|(n, _)| (**n).cmp(action))
            .ok()
            .and_then(|i| names.get(i))
            .map(|(_, ai)| *ai)
            .ok_or_else(|| UnknownName(format!("unknown action `{action}` (not in s_ftoc.txt)")))
    }

    fn label(&self, ai: usize, label: &str) -> Result<usize, UnknownName> {
        let a = &self.brian.actions[ai];
        a.labels
            .iter()
            .position(|(l, _)| l == label)
            .ok_or_else(|| UnknownName(format!("action `{}` has no label `{label}`", a.name)))
    }

    /// Proposes `label` of `action` with `value` (clamped to [0, 1]; NaN counts as 0, which
    /// proposes nothing), as a rule whose precondition has that value.
    pub fn propose(&mut self, action: &str, label: &str, value: f64) -> Result<(), UnknownName> {
        let ai = self.action(action)?;
        let k = self.label(ai, label)?;
        let value = if value.is_nan() { 0.0 } else { value.clamp(0.0, 1.0) };
        self.out.push((RuleAction::Propose(self.brian.actions[ai].offset + k), value));
        Ok(())
    }

    /// Deletes what lower levels proposed for `label` of `action`, or for every label with
    /// `None` (`&DEL.<action> ANY`).
    pub fn delete(&mut self, action: &str, label: Option<&str>) -> Result<(), UnknownName> {
        let ai = self.action(action)?;
        let label = label.map(|l| self.label(ai, l)).transpose()?;
        self.out.push((RuleAction::Delete { action: ai, label }, 1.0));
        Ok(())
    }
}

/// A loaded Mr. BRIAN configuration, ready to run cycles.
///
/// ```no_run
/// use mrt_fuzzy::brian::Brian;
/// let mut brian = Brian::from_dir("configs/brian/harvester")?;
/// let commands = brian.run(&[("TargetDistance", 45.0, 1.0)]);
/// println!("{commands:?}");
/// # Ok::<(), mrt_fuzzy::BrianError>(())
/// ```
#[derive(Clone, Debug)]
pub struct Brian {
    inputs: Vec<Input>,
    data: Vec<FuzzyValue>,
    predicates: Vec<(String, Expr)>,
    predicate_actions: Vec<(String, Expr)>,
    behaviors: Vec<Behavior>,
    actions: Vec<Action>,
    threshold: f64,
    /// A CANDO filter plugged in place of the threshold filter.
    cando_filter: Option<Plugged<dyn CandoFilter>>,
    composer: Composer,
    weight_composer: WeightComposer,
    composition: Composition,
    semantics: Semantics,
    /// What a code behavior proposed, reused every cycle.
    code_out: Vec<(RuleAction, f64)>,
    pred_values: Vec<FuzzyValue>,
    act_values: Vec<FuzzyValue>,
    lower: Vec<Acc>,
    level_acc: Vec<Acc>,
    /// What the loader found suspicious but legal (unused definitions...).
    warnings: Vec<String>,
    /// Last cycle's (CANDO, WANT) of each behavior, in run order; `None` when it did not run.
    activity: Vec<Option<Activity>>,
    /// Whether proposals are recorded for [`Brian::trace`].
    tracing: bool,
    /// `(behavior, action, label or None for ANY, value or None for a deletion)`.
    traced: Vec<(usize, usize, Option<usize>, Option<f64>)>,
    /// Output names sorted, with their index, shared with every [`Commands`].
    sorted_names: Arc<[(Arc<str>, usize)]>,
    /// The outputs as last handed out by [`Brian::run`].
    shared_outputs: Arc<Vec<Option<f64>>>,
    /// For each input, the output of the same name that feeds it back (§10.5).
    feedback: Vec<Option<usize>>,
    /// Inputs that carry `Proposed<Action>` data (set by the engine, not by callers).
    is_proposed: Vec<bool>,
    /// Names of inputs (slots), labels, predicates and predicate actions.
    names: Index,
    outputs: Vec<Option<f64>>,
}

/// A behavior's (CANDO, WANT) in a cycle it ran.
pub type Activity = (FuzzyValue, FuzzyValue);

/// What one cycle computed; see [`Brian::trace`].
#[derive(Clone, Debug)]
pub struct Trace<'a> {
    /// Predicates of `Predicate.ini`, in file order.
    pub predicates: Vec<(&'a str, FuzzyValue)>,
    /// Predicate actions of `PredicateActions.ini`, in file order.
    pub predicate_actions: Vec<(&'a str, FuzzyValue)>,
    /// Behaviors in run order: name, level, and (CANDO, WANT) when it ran.
    pub behaviors: Vec<(&'a str, i64, Option<Activity>)>,
    /// Every proposal of the cycle, when tracing is on ([`Brian::set_tracing`]): behavior,
    /// action, label, and its weighted value (proposal value × reliability × weight); deletions
    /// (`&DEL`) appear with the label `&DEL ANY` or `&DEL <label>` and no value.
    pub proposals: Vec<TracedProposal<'a>>,
}

/// One proposal (or deletion) of a traced cycle.
#[derive(Clone, Debug, PartialEq)]
pub struct TracedProposal<'a> {
    /// The behavior.
    pub behavior: &'a str,
    /// The action.
    pub action: &'a str,
    /// The label (`None` with `delete` for `&DEL ... ANY`).
    pub label: Option<&'a str>,
    /// Weighted value; `None` for a deletion.
    pub value: Option<f64>,
}

/// The crisp commands of one cycle: action name → value, in name order. An action every
/// behavior left at weight 0 is absent.
///
/// Cheap to return: it shares the engine's buffers (reference counts, no copy). When the caller
/// has dropped the previous cycle's `Commands`, [`Brian::run`] reuses the buffer and allocates
/// nothing; a kept `Commands` is never changed under its holder.
#[derive(Clone)]
pub struct Commands {
    /// `(name, index into values)`, sorted by name.
    names: Arc<[(Arc<str>, usize)]>,
    values: Arc<Vec<Option<f64>>>,
}

impl Commands {
    /// The value of an action, if it was produced.
    pub fn get(&self, name: &str) -> Option<&f64> {
        let i = self.names.binary_search_by(|(n, _)| (**n).cmp(name)).ok()?;
        self.values.get(self.names[i].1)?.as_ref()
    }

    /// `(name, value)` of every produced action, in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, f64)> + '_ {
        self.names
            .iter()
            .filter_map(|(n, i)| self.values.get(*i).copied().flatten().map(|v| (&**n, v)))
    }

    /// How many actions were produced.
    pub fn len(&self) -> usize {
        self.iter().count()
    }

    /// Whether no action was produced.
    pub fn is_empty(&self) -> bool {
        self.iter().next().is_none()
    }

    /// As an owned map (allocates).
    pub fn to_map(&self) -> BTreeMap<String, f64> {
        self.iter().map(|(k, v)| (k.to_string(), v)).collect()
    }
}

impl std::ops::Index<&str> for Commands {
    type Output = f64;
    /// The value of a produced action. Panics when it was not produced: use
    /// [`get`](Commands::get) for input-driven code.
    fn index(&self, name: &str) -> &f64 {
        match self.get(name) {
            Some(v) => v,
            None => panic!("no command `{name}` in this cycle"),
        }
    }
}

impl std::fmt::Debug for Commands {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_map().entries(self.iter()).finish()
    }
}

impl Brian {
    /// Warnings from loading, in the checker's format: unused shapes, predicates and predicate
    /// actions, behaviors without WANT.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// Records every proposal and deletion for [`trace`](Self::trace) (off by default: it costs
    /// a little per proposal).
    pub fn set_tracing(&mut self, on: bool) {
        self.tracing = on;
    }

    /// Chooses the composer (default [`Composer::Max`]).
    pub fn set_composer(&mut self, c: Composer) {
        self.composer = c;
    }

    /// Sets the CANDO threshold (`threshold_filter`, default 0.49; `engine.txt` may set it),
    /// and brings the threshold filter back if another CANDO filter was plugged in.
    pub fn set_threshold(&mut self, t: f64) {
        self.threshold = t;
        self.cando_filter = None;
    }

    /// Plugs a CANDO filter in place of the threshold filter (§10.3.6, `can_do_filter`).
    /// Under [`Semantics::Original`] a behavior must still have a CANDO reliability above
    /// the threshold.
    pub fn set_cando_filter(&mut self, filter: impl CandoFilter + 'static) {
        self.cando_filter = Some(Plugged(Arc::new(filter)));
    }

    /// Whether a CANDO filter of the program's replaces the threshold filter.
    pub fn has_cando_filter(&self) -> bool {
        self.cando_filter.is_some()
    }

    /// Chooses how proposals become outputs (default [`Composition::Weighted`], formula
    /// 10.3; `engine.txt` may set it).
    pub fn set_composition(&mut self, c: Composition) {
        self.composition = c;
    }

    /// The composition.
    pub fn composition(&self) -> Composition {
        self.composition
    }

    /// Chooses the semantics of reliability (default [`Semantics::Manual`]; `engine.txt`
    /// may set it).
    pub fn set_semantics(&mut self, s: Semantics) {
        self.semantics = s;
    }

    /// The semantics of reliability.
    pub fn semantics(&self) -> Semantics {
        self.semantics
    }

    /// Gives the code of the behaviors that `behavior.txt` lists as `code:<name>` (see
    /// [`CodeBehavior`]); returns how many behaviors use it. A code behavior nobody registered
    /// proposes nothing; registering again replaces the code.
    ///
    /// # Errors
    /// [`BrianError::NoCodeBehavior`] when no behavior of `behavior.txt` is `code:<name>`.
    pub fn register_behavior(
        &mut self,
        name: &str,
        behavior: impl CodeBehavior + 'static,
    ) -> Result<usize, BrianError> {
        let code: Arc<dyn CodeBehavior> = Arc::new(behavior);
        let mut n = 0;
        for slot in self.behaviors.iter_mut().filter_map(|b| b.code.as_mut()) {
            if slot.name == name {
                slot.behavior = Some(Plugged(code.clone()));
                n += 1;
            }
        }
        if n == 0 {
            return Err(BrianError::NoCodeBehavior { name: name.to_string() });
        }
        Ok(n)
    }

    /// The CANDO threshold.
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// The composer.
    pub fn composer(&self) -> Composer {
        self.composer
    }

    /// Chooses the weight composer (default [`WeightComposer::Mult`]).
    pub fn set_weight_composer(&mut self, c: WeightComposer) {
        self.weight_composer = c;
    }

    /// The weight composer.
    pub fn weight_composer(&self) -> WeightComposer {
        self.weight_composer
    }

    /// The names of the crisp inputs (`ctof.txt`).
    pub fn input_names(&self) -> impl Iterator<Item = &str> {
        self.inputs.iter().map(|i| i.name.as_str())
    }

    /// What the last cycle computed, for debugging rules: every predicate, every predicate
    /// action (as evaluated for the highest level), and each behavior's CANDO and WANT (`None`
    /// when its CANDO was not above the threshold and it did not run).
    pub fn trace(&self) -> Trace<'_> {
        Trace {
            predicates: self
                .predicates
                .iter()
                .map(|(n, _)| n.as_str())
                .zip(self.pred_values.iter().copied())
                .collect(),
            predicate_actions: self
                .predicate_actions
                .iter()
                .map(|(n, _)| n.as_str())
                .zip(self.act_values.iter().copied())
                .collect(),
            proposals: self
                .traced
                .iter()
                .map(|&(b, a, l, value)| TracedProposal {
                    behavior: &self.behaviors[b].name,
                    action: &self.actions[a].name,
                    label: l.map(|l| self.actions[a].labels[l].0.as_str()),
                    value,
                })
                .collect(),
            behaviors: self
                .behaviors
                .iter()
                .map(|b| (b.name.as_str(), b.level))
                .zip(self.activity.iter().copied())
                .map(|((n, l), a)| (n, l, a))
                .collect(),
        }
    }

    /// The input shapes, with the crisp datum each one fuzzifies.
    pub fn input_shapes(&self) -> impl Iterator<Item = (&str, &Shape)> {
        self.inputs.iter().map(|i| (i.name.as_str(), &i.shape))
    }

    /// The output actions with their sets `(label, set)`: SNG for singleton defuzzification,
    /// TRI, DIV, TRA or REC for barycenter defuzzification (§10.4.6, formula 10.7).
    pub fn output_sets(&self) -> impl Iterator<Item = (&str, &[(String, FuzzySet)])> {
        self.actions.iter().map(|a| (a.name.as_str(), a.sets.as_slice()))
    }

    /// The output actions with their singletons `(label, value)`; for a shape of polygons
    /// (barycenter defuzzification), each set's barycenter at full height.
    pub fn output_singletons(&self) -> impl Iterator<Item = (&str, &[(String, f64)])> {
        self.actions.iter().map(|a| (a.name.as_str(), a.labels.as_slice()))
    }
}
