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

use crate::error::BrianError;
use crate::expr::{parse_definitions, parse_expr, Expr, RawExpr};
use crate::lexer::{tokenize, Cursor, Span, Tok};
use crate::set::{FuzzySet, FuzzyValue};
use crate::shapes::{barycenter, defuzzify, parse_associations, parse_shapes, resolve, Shape};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The default CANDO threshold (§10.4.4): a behavior runs when its CANDO value is above it.
pub const DEFAULT_THRESHOLD: f64 = 0.49;
/// A WANT value must exceed this to give a weight; below, the behavior's weight is 0.
pub const WANT_THRESHOLD: f64 = 0.49;
/// A rule whose precondition reliability is below this proposes nothing (§10.3.7).
pub const MIN_RELIABILITY: f64 = 0.1;

/// How proposals of the same (action, label) are combined (§10.3.8, §10.4.9: the
/// `float_composer`), after each is weighted by its behavior's weight ([`WeightComposer`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Composer {
    /// The maximum (formula 10.3, `max_float_composer`): the default.
    #[default]
    Max,
    /// The mean (`average_float_composer` of §10.4.9).
    Average,
    /// The minimum (`min_float_composer` of §10.4.9).
    Min,
}

/// How one proposal is weighted by its behavior's weight (the WANT value; §10.4.9, the
/// `weight_composer`). A behavior of weight 0, or a rule that does not fire, proposes nothing
/// whichever is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WeightComposer {
    /// The value times the weight (`mult_weight_composer`): the default.
    #[default]
    Mult,
    /// The larger of the value and the weight (`max_weight_composer`).
    Max,
    /// The smaller of the value and the weight (`min_weight_composer`).
    Min,
}

impl WeightComposer {
    /// Proposal `value` weighted by `weight`.
    pub fn apply(self, value: f64, weight: f64) -> f64 {
        match self {
            WeightComposer::Mult => value * weight,
            WeightComposer::Max => value.max(weight),
            WeightComposer::Min => value.min(weight),
        }
    }
}

/// How the proposals of the running behaviors become the outputs (§10.2.4): "Both the
/// approaches are implemented in Mr. BRIAN and it is possible to select the best one for the
/// application". `engine.txt`: `composition weighted` or `composition argmax`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Composition {
    /// Formula 10.3: every running behavior's proposals, each weighted by its behavior's
    /// weight ([`WeightComposer`]) and combined per label ([`Composer`]): the default, as in
    /// RoboCup.
    #[default]
    Weighted,
    /// Formula 10.5: for each output, only the proposals of the behavior with the largest
    /// μC · μW (CANDO value × weight) among the behaviors that propose a label of it (after
    /// `&DEL`); ties go to the behavior that runs first (lower level, then name). Opposite
    /// wishes are never averaged, at the price of pursuing one goal at a time.
    Argmax,
}

/// Which reading of reliability the engine follows: the manual's (the default) or the
/// original C++ engine's, for configurations tuned on it (`engine.txt`: `semantics manual` or
/// `semantics original`; `mrt brian eval --semantics`).
///
/// | | [`Semantics::Manual`] | [`Semantics::Original`] |
/// |---|---|---|
/// | a behavior runs when | CANDO value above the threshold (§10.3.6) | and CANDO reliability above the threshold |
/// | its weight is its WANT value when | the value is above 0.49 | and the reliability is above 0.49 |
/// | a rule proposes | precondition value × reliability, nothing under reliability 0.1 (§10.3.7) | the precondition value, whatever its reliability |
///
/// The original program filters CANDO and WANT with a filter of membership *and*
/// reliability, and its rules propose the precondition's membership: reliability decides
/// whether a behavior counts, not how much. The manual (§10.3.7) makes it scale each proposal.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Semantics {
    /// As the manual describes (§10.3.6, §10.3.7): the default.
    #[default]
    Manual,
    /// As the original C++ engine measured: CANDO and WANT gated on reliability, rules blind
    /// to it.
    Original,
}

/// One (action, label) accumulator: enough for every composer and both compositions: the
/// sums of every proposal, and those of the best behavior proposing here (formula 10.5).
#[derive(Clone, Copy, Debug, Default)]
struct Acc {
    all: Sums,
    best: Sums,
    /// The best behavior's μC · μW.
    score: f64,
    /// The best behavior (its index in run order).
    by: usize,
}

impl Acc {
    fn add(&mut self, v: f64, score: f64, by: usize) {
        self.all.add(v);
        if self.best.n == 0 || score > self.score {
            self.best = Sums::default();
            self.score = score;
            self.by = by;
        }
        if self.by == by {
            self.best.add(v);
        }
    }

    /// Adds what a higher level proposed: ties keep the lower level's behavior.
    fn merge(&mut self, o: &Acc) {
        self.all.merge(&o.all);
        if o.best.n > 0 && (self.best.n == 0 || o.score > self.score) {
            self.best = o.best;
            self.score = o.score;
            self.by = o.by;
        }
    }
}

/// Sums of the weighted proposals of one (action, label).
#[derive(Clone, Copy, Debug)]
struct Sums {
    max: f64,
    min: f64,
    sum: f64,
    n: u32,
}

impl Default for Sums {
    fn default() -> Self {
        Sums { max: 0.0, min: f64::INFINITY, sum: 0.0, n: 0 }
    }
}

impl Sums {
    fn add(&mut self, v: f64) {
        self.max = self.max.max(v);
        self.min = self.min.min(v);
        self.sum += v;
        self.n += 1;
    }

    fn merge(&mut self, o: &Sums) {
        self.max = self.max.max(o.max);
        self.min = self.min.min(o.min);
        self.sum += o.sum;
        self.n += o.n;
    }

    fn weight(&self, c: Composer) -> f64 {
        match c {
            _ if self.n == 0 => 0.0,
            Composer::Max => self.max,
            Composer::Average => self.sum / f64::from(self.n),
            Composer::Min => self.min,
        }
    }
}

impl Composer {
    /// Combines weighted proposals of one (action, label); 0 when there are none.
    pub fn combine(self, weighted: &[f64]) -> f64 {
        let mut acc = Sums::default();
        weighted.iter().for_each(|v| acc.add(*v));
        acc.weight(self)
    }
}

/// The file names of a configuration directory.
#[derive(Clone, Debug)]
pub struct BrianFiles {
    /// Input shapes (`shape_ctof.txt`).
    pub shape_ctof: PathBuf,
    /// Crisp data → shape (`ctof.txt`).
    pub ctof: PathBuf,
    /// Predicates (`Predicate.ini`).
    pub predicates: PathBuf,
    /// Predicate actions (`PredicateActions.ini`); may be absent.
    pub predicate_actions: PathBuf,
    /// Activation conditions (`Cando.ini`).
    pub cando: PathBuf,
    /// Motivations (`want.txt`).
    pub want: PathBuf,
    /// Behavior list (`behavior.txt`).
    pub behaviors: PathBuf,
    /// Output shapes (`s_shape.txt`).
    pub s_shape: PathBuf,
    /// Action → output shape (`s_ftoc.txt`).
    pub s_ftoc: PathBuf,
    /// The engine's settings (`engine.txt`, [`crate::engine`]); may be absent.
    pub engine: PathBuf,
}

impl BrianFiles {
    /// The standard names inside `dir`.
    pub fn in_dir(dir: impl AsRef<Path>) -> Self {
        let d = dir.as_ref();
        Self {
            shape_ctof: d.join("shape_ctof.txt"),
            ctof: d.join("ctof.txt"),
            predicates: d.join("Predicate.ini"),
            predicate_actions: d.join("PredicateActions.ini"),
            cando: d.join("Cando.ini"),
            want: d.join("want.txt"),
            behaviors: d.join("behavior.txt"),
            s_shape: d.join("s_shape.txt"),
            s_ftoc: d.join("s_ftoc.txt"),
            engine: d.join("engine.txt"),
        }
    }
}

/// Reads a file as UTF-8 text; invalid UTF-8 is an error at the line and column of the first
/// invalid byte.
fn read(path: &Path) -> Result<String, BrianError> {
    let bytes = mrt_core::read_bounded(path, mrt_core::MAX_SCRIPT_BYTES)
        .map_err(|source| BrianError::Io { file: path.to_path_buf(), source })?;
    crate::lexer::utf8(without_bom(bytes), path)
}

/// `bytes` without the byte-order mark some editors write at the start of a UTF-8 file.
fn without_bom(mut bytes: Vec<u8>) -> Vec<u8> {
    if bytes.starts_with(b"\xef\xbb\xbf") {
        bytes.drain(..3);
    }
    bytes
}

/// Where a configuration's files come from: the disk, or memory ([`BrianSources`]).
trait Source {
    /// The text of a file (UTF-8 checked, errors located).
    fn read(&self, path: &Path) -> Result<String, BrianError>;
    /// Whether an optional file is there.
    fn exists(&self, path: &Path) -> bool;
    /// The root every rule file must lie in (the disk's: `base` canonicalized).
    fn root(&self, base: &Path) -> Result<PathBuf, BrianError>;
    /// The checked file a `behavior.txt` line names (see [`rule_file`]).
    fn rule_file(
        &self,
        root: &Path,
        base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError>;
}

/// The files of a directory on disk.
struct Disk;

impl Source for Disk {
    fn read(&self, path: &Path) -> Result<String, BrianError> {
        read(path)
    }

    fn exists(&self, path: &Path) -> bool {
        path.exists()
    }

    fn root(&self, base: &Path) -> Result<PathBuf, BrianError> {
        base.canonicalize().map_err(|source| BrianError::Io { file: base.to_path_buf(), source })
    }

    fn rule_file(
        &self,
        root: &Path,
        base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError> {
        rule_file(root, base, list, b)
    }
}

/// A configuration held in memory: each file's bytes under its name in the configuration
/// directory (`shape_ctof.txt`, `ctof.txt`, `Predicate.ini`, `PredicateActions.ini` (optional),
/// `Cando.ini`, `want.txt`, `behavior.txt`, `s_shape.txt`, `s_ftoc.txt`) and each rule file
/// under the path `behavior.txt` gives it (`behaviors/GoToBall.rul`). For tools, tests and
/// fuzzers that have no directory; [`Brian::from_sources`] loads it exactly as
/// [`Brian::from_dir`] loads a directory holding the same files.
///
/// ```
/// use mrt_fuzzy::brian::{Brian, BrianSources};
///
/// let mut files = BrianSources::new();
/// files.insert("shape_ctof.txt", "(Distance (TOL (NEAR 10 50)) (TOR (FAR 10 50)))");
/// files.insert("ctof.txt", "(TargetDistance Distance)");
/// files.insert("Predicate.ini", "Far = (D TargetDistance FAR);");
/// files.insert("s_shape.txt", "(SPEED (SNG (SLOW 10)) (SNG (FAST 100)))");
/// files.insert("s_ftoc.txt", "(Speed SPEED)");
/// files.insert("behavior.txt", "(level 1 Go behaviors/Go.rul)");
/// files.insert("Cando.ini", "Go = (P Far);");
/// files.insert("want.txt", "Go = (P Far);");
/// files.insert("behaviors/Go.rul", "(Far) => (Speed FAST);");
/// let mut brian = Brian::from_sources(&files)?;
/// let commands = brian.run(&[("TargetDistance", 100.0, 1.0)]);
/// assert_eq!(commands["Speed"], 100.0);
/// # Ok::<(), mrt_fuzzy::BrianError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct BrianSources {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl BrianSources {
    /// No files.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) the file `name`, a path relative to the configuration directory.
    pub fn insert(&mut self, name: impl Into<PathBuf>, bytes: impl Into<Vec<u8>>) {
        self.files.insert(name.into(), bytes.into());
    }

    /// Removes the file `name`, returning its bytes.
    pub fn remove(&mut self, name: impl AsRef<Path>) -> Option<Vec<u8>> {
        self.files.remove(name.as_ref())
    }

    /// The file `name`'s bytes.
    pub fn get(&self, name: impl AsRef<Path>) -> Option<&[u8]> {
        self.files.get(name.as_ref()).map(Vec::as_slice)
    }

    /// The files' names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &Path> {
        self.files.keys().map(PathBuf::as_path)
    }

    /// Reads every regular file of a configuration directory and of its subdirectories (at
    /// most [`SOURCES_DEPTH`] deep; links are not followed) into memory.
    pub fn read_dir(dir: impl AsRef<Path>) -> Result<BrianSources, BrianError> {
        let mut out = BrianSources::new();
        out.read_under(dir.as_ref(), Path::new(""), 0)?;
        Ok(out)
    }

    fn read_under(&mut self, dir: &Path, rel: &Path, depth: usize) -> Result<(), BrianError> {
        let io = |file: &Path| {
            let file = file.to_path_buf();
            move |source| BrianError::Io { file, source }
        };
        for entry in std::fs::read_dir(dir).map_err(io(dir))? {
            let entry = entry.map_err(io(dir))?;
            let path = entry.path();
            let kind = entry.file_type().map_err(io(&path))?;
            let name = rel.join(entry.file_name());
            if kind.is_file() {
                let bytes =
                    mrt_core::read_bounded(&path, mrt_core::MAX_SCRIPT_BYTES).map_err(io(&path))?;
                self.files.insert(name, bytes);
            } else if kind.is_dir() && depth < SOURCES_DEPTH {
                self.read_under(&path, &name, depth + 1)?;
            }
        }
        Ok(())
    }
}

/// How deep [`BrianSources::read_dir`] descends into subdirectories.
pub const SOURCES_DEPTH: usize = 8;

impl Source for BrianSources {
    fn read(&self, path: &Path) -> Result<String, BrianError> {
        match self.files.get(path) {
            Some(bytes) => crate::lexer::utf8(bytes.clone(), path),
            None => Err(BrianError::Io {
                file: path.to_path_buf(),
                source: std::io::ErrorKind::NotFound.into(),
            }),
        }
    }

    fn exists(&self, path: &Path) -> bool {
        self.files.contains_key(path)
    }

    fn root(&self, _base: &Path) -> Result<PathBuf, BrianError> {
        Ok(PathBuf::new())
    }

    /// The path as written, `.` and `..` taken lexically; leaving the configuration (`..` past
    /// its top, an absolute path) is an error, as on disk.
    fn rule_file(
        &self,
        _root: &Path,
        _base: &Path,
        list: &Path,
        b: &Listed,
    ) -> Result<PathBuf, BrianError> {
        use std::path::Component;
        let mut name = PathBuf::new();
        let mut inside = true;
        for part in Path::new(&b.path).components() {
            match part {
                Component::Normal(p) => name.push(p),
                Component::CurDir => {}
                Component::ParentDir => inside &= name.pop(),
                Component::RootDir | Component::Prefix(_) => inside = false,
            }
        }
        if !inside {
            return Err(BrianError::at(
                list,
                b.path_span,
                format!(
                    "the rule file `{}` of behavior `{}` is outside the configuration directory: \
                     rule files must be inside it",
                    b.path, b.name
                ),
            ));
        }
        if !self.files.contains_key(&name) {
            return Err(BrianError::at(
                list,
                b.path_span,
                format!(
                    "cannot open the rule file `{}` of behavior `{}`: {}",
                    b.path,
                    b.name,
                    std::io::Error::from(std::io::ErrorKind::NotFound)
                ),
            ));
        }
        Ok(name)
    }
}

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

/// Name → index tables of what is defined so far, so that every reference resolves in
/// constant time: loading is linear in the size of the configuration (it once was
/// quadratic: 200 000 definitions never finished).
#[derive(Clone, Debug, Default)]
struct Index {
    /// Crisp input name → its index in the inputs.
    inputs: HashMap<String, usize>,
    /// For each input, its shape's label → the label's position in the shape.
    labels: Vec<Arc<HashMap<String, usize>>>,
    /// Predicate name → index, for those defined so far.
    predicates: HashMap<String, usize>,
    /// Predicate action name → index, for those defined so far.
    predicate_actions: HashMap<String, usize>,
}

#[derive(Clone, Copy)]
struct Names<'a> {
    inputs: &'a [Input],
    index: &'a Index,
    file: &'a Path,
}

impl Names<'_> {
    fn resolve(&self, e: &RawExpr) -> Result<Expr, BrianError> {
        Ok(match e {
            RawExpr::And(a, b) => Expr::And(Box::new(self.resolve(a)?), Box::new(self.resolve(b)?)),
            RawExpr::Or(a, b) => Expr::Or(Box::new(self.resolve(a)?), Box::new(self.resolve(b)?)),
            RawExpr::Not(a) => Expr::Not(Box::new(self.resolve(a)?)),
            RawExpr::Data(d, l, span, label_span) => {
                let found = self
                    .index
                    .inputs
                    .get(d.as_str())
                    .and_then(|&i| Some((self.inputs.get(i)?, self.index.labels.get(i)?)));
                let Some((input, labels)) = found else {
                    return Err(BrianError::at(
                        self.file,
                        *span,
                        format!("unknown datum `{d}` (not in ctof.txt)"),
                    ));
                };
                let Some(&k) = labels.get(l.as_str()) else {
                    let known: Vec<&str> =
                        input.shape.sets.iter().map(|(l, _)| l.as_str()).collect();
                    return Err(BrianError::at(
                        self.file,
                        *label_span,
                        format!(
                            "`{d}` (shape `{}`) has no label `{l}` (labels: {})",
                            input.shape.name,
                            known.join(", ")
                        ),
                    ));
                };
                Expr::Data(input.offset + k)
            }
            RawExpr::Pred(n, span) => {
                if let Some(&i) = self.index.predicates.get(n.as_str()) {
                    Expr::Pred(i)
                } else if let Some(&i) = self.index.predicate_actions.get(n.as_str()) {
                    Expr::Action(i)
                } else {
                    return Err(BrianError::at(
                        self.file,
                        *span,
                        format!("unknown predicate `{n}` (predicates must be defined before use)"),
                    ));
                }
            }
        })
    }
}

/// The output actions of `s_ftoc.txt` with name and label tables, for the rule parser.
struct Outputs<'a> {
    actions: &'a [Action],
    /// Action name → index.
    by_name: HashMap<&'a str, usize>,
    /// For each action, label → position.
    labels: Vec<HashMap<&'a str, usize>>,
}

impl<'a> Outputs<'a> {
    fn new(actions: &'a [Action]) -> Self {
        Outputs {
            actions,
            by_name: actions.iter().enumerate().map(|(i, a)| (a.name.as_str(), i)).collect(),
            labels: actions
                .iter()
                .map(|a| a.labels.iter().enumerate().map(|(k, (l, _))| (l.as_str(), k)).collect())
                .collect(),
        }
    }
}

fn parse_file<T>(
    src: &dyn Source,
    path: &Path,
    f: impl FnOnce(&mut Cursor<'_>) -> Result<T, BrianError>,
) -> Result<T, BrianError> {
    parse_text(&src.read(path)?, path, f)
}

fn parse_text<T>(
    text: &str,
    path: &Path,
    f: impl FnOnce(&mut Cursor<'_>) -> Result<T, BrianError>,
) -> Result<T, BrianError> {
    let toks = tokenize(text, path)?;
    let mut c = Cursor::new(&toks, path, text);
    f(&mut c)
}

/// The highest level of `behavior.txt`: far beyond any hierarchy, and every level up to it is
/// a whole number an `f64` holds exactly (a larger one was silently read as `i64::MAX`).
pub const MAX_LEVEL: i64 = u32::MAX as i64;

/// One line of `behavior.txt`.
struct Listed {
    name: String,
    level: i64,
    path: String,
    /// Where the name is written.
    span: Span,
    /// Where the path is written.
    path_span: Span,
}

/// The rule file a `behavior.txt` line names, canonicalized, when it lies inside the
/// configuration directory `root` (canonical). Outside, or unreadable, it is an error at the
/// path in `behavior.txt` that never shows the file's content (otherwise any file of
/// the machine could be named, and its first token printed).
fn rule_file(root: &Path, base: &Path, list: &Path, b: &Listed) -> Result<PathBuf, BrianError> {
    let canon = base.join(&b.path).canonicalize().map_err(|e| {
        BrianError::at(
            list,
            b.path_span,
            format!("cannot open the rule file `{}` of behavior `{}`: {e}", b.path, b.name),
        )
    })?;
    if !canon.starts_with(root) {
        return Err(BrianError::at(
            list,
            b.path_span,
            format!(
                "the rule file `{}` of behavior `{}` is outside the configuration directory {}: \
                 rule files must be inside it",
                b.path,
                b.name,
                root.display()
            ),
        ));
    }
    Ok(canon)
}

impl Brian {
    /// Loads the standard files of a configuration directory.
    pub fn from_dir(dir: impl AsRef<Path>) -> Result<Brian, BrianError> {
        Brian::from_files(&BrianFiles::in_dir(dir.as_ref()), dir.as_ref())
    }

    /// Loads from explicit file paths (the manual's `Brian(...)` constructor); behavior paths
    /// in the behavior list are relative to `base`, and must lead (after following links)
    /// to files inside `base`.
    ///
    /// Loading takes time linear in the size of the files.
    pub fn from_files(files: &BrianFiles, base: &Path) -> Result<Brian, BrianError> {
        Brian::load(&Disk, files, base)
    }

    /// Loads a configuration held in memory (see [`BrianSources`]): the same checks and the
    /// same errors as [`Brian::from_dir`] on a directory holding these files, with file names
    /// relative to the configuration.
    pub fn from_sources(sources: &BrianSources) -> Result<Brian, BrianError> {
        let base = Path::new("");
        Brian::load(sources, &BrianFiles::in_dir(base), base)
    }

    fn load(src: &dyn Source, files: &BrianFiles, base: &Path) -> Result<Brian, BrianError> {
        let read = |path: &Path| src.read(path);
        let shapes = parse_shapes(&read(&files.shape_ctof)?, &files.shape_ctof)?;
        let assocs = parse_associations(&read(&files.ctof)?, &files.ctof)?;
        let idx = resolve(&assocs, &shapes, &files.ctof)?;
        let shape_labels: Vec<Arc<HashMap<String, usize>>> = shapes
            .iter()
            .map(|s| {
                Arc::new(s.sets.iter().enumerate().map(|(k, (l, _))| (l.clone(), k)).collect())
            })
            .collect();
        let mut index = Index::default();
        let mut inputs = Vec::new();
        let mut offset = 0;
        for (a, i) in assocs.iter().zip(idx) {
            let shape = shapes[i].clone();
            let n = shape.sets.len();
            index.inputs.insert(a.name.clone(), inputs.len());
            index.labels.push(shape_labels[i].clone());
            inputs.push(Input { name: a.name.clone(), shape, offset, now: None, previous: None });
            offset += n;
        }
        let fuzzy_data_len = offset;

        let mut warnings = Vec::new();
        let used_shapes: HashSet<&str> = assocs.iter().map(|a| a.shape.as_str()).collect();
        for shape in shapes.iter().filter(|s| !used_shapes.contains(s.name.as_str())) {
            warnings.push(warning(
                &files.shape_ctof,
                shape.span,
                &format!("shape `{}` is not used in ctof.txt", shape.name),
            ));
        }
        let mut pred_spans = Vec::new();
        let mut pact_spans = Vec::new();
        let mut predicates: Vec<(String, Expr)> = Vec::new();
        for (name, span, raw) in parse_file(src, &files.predicates, parse_definitions)? {
            pred_spans.push(span);
            let e =
                Names { inputs: &inputs, index: &index, file: &files.predicates }.resolve(&raw)?;
            index.predicates.insert(name.clone(), predicates.len());
            predicates.push((name, e));
        }
        let engine = if src.exists(&files.engine) {
            crate::engine::parse_engine(&read(&files.engine)?, &files.engine)?
        } else {
            crate::engine::EngineSettings::default()
        };
        let mut predicate_actions: Vec<(String, Expr)> = Vec::new();
        if src.exists(&files.predicate_actions) {
            for (name, span, raw) in parse_file(src, &files.predicate_actions, parse_definitions)? {
                if index.predicates.contains_key(&name) {
                    return Err(BrianError::at(
                        &files.predicate_actions,
                        span,
                        format!("`{name}` is already a predicate"),
                    ));
                }
                let e = Names { inputs: &inputs, index: &index, file: &files.predicate_actions }
                    .resolve(&raw)?;
                pact_spans.push(span);
                index.predicate_actions.insert(name.clone(), predicate_actions.len());
                predicate_actions.push((name, e));
            }
        }

        // Outputs.
        let s_shapes = parse_shapes(&read(&files.s_shape)?, &files.s_shape)?;
        let s_assocs = parse_associations(&read(&files.s_ftoc)?, &files.s_ftoc)?;
        let s_idx = resolve(&s_assocs, &s_shapes, &files.s_ftoc)?;
        let mut actions = Vec::new();
        let mut offset = 0;
        for (a, i) in s_assocs.iter().zip(s_idx) {
            let shape = &s_shapes[i];
            let circular = a.name.contains("Angle");
            let (labels, barycenter) = output_labels(shape, circular, &files.s_shape)?;
            // Formula 10.6 sums weight × singleton (weights at most 1), formula 10.7 area ×
            // centroid: the sum must stay a number, or the command would be infinite or NaN.
            let sum: f64 = if barycenter {
                let moments = shape.sets.iter().flat_map(|(_, set)| {
                    crate::shapes::clipped_areas(set, 1.0).map(|(x, area)| area + (x * area).abs())
                });
                moments.sum()
            } else {
                labels.iter().map(|(_, v)| v.abs()).sum()
            };
            if !sum.is_finite() {
                return Err(BrianError::at(
                    &files.s_shape,
                    s_shapes[i].span,
                    format!(
                        "the {} of output shape `{}` are too large: their sum is not a finite number",
                        if barycenter { "sets" } else { "singletons" },
                        s_shapes[i].name
                    ),
                ));
            }
            let proposed = index.inputs.get(&format!("Proposed{}", a.name)).copied();
            let n = labels.len();
            actions.push(Action {
                name: a.name.clone(),
                labels,
                sets: shape.sets.clone(),
                barycenter,
                circular,
                proposed,
                offset,
            });
            offset += n;
        }
        let outputs = Outputs::new(&actions);

        let names = Names { inputs: &inputs, index: &index, file: &files.cando };
        let cando = parse_file(src, &files.cando, parse_definitions)?;
        let want = parse_file(src, &files.want, parse_definitions)?;
        // Names are unique in each file (parse_definitions refuses duplicates).
        let cando_of: HashMap<&str, &RawExpr> =
            cando.iter().map(|(n, _, raw)| (n.as_str(), raw)).collect();
        let want_of: HashMap<&str, &RawExpr> =
            want.iter().map(|(n, _, raw)| (n.as_str(), raw)).collect();
        let root = src.root(base)?;
        let listed = parse_file(src, &files.behaviors, parse_behavior_list)?;
        let mut seen: HashSet<&str> = HashSet::with_capacity(listed.len());
        // Behaviors often share a rule file: each file is read and resolved once.
        let mut rule_files: HashMap<PathBuf, Vec<Rule>> = HashMap::new();
        // Path as written → the checked file it leads to.
        let mut checked: HashMap<&str, PathBuf> = HashMap::new();
        let mut behaviors = Vec::with_capacity(listed.len());
        for b in &listed {
            if !seen.insert(b.name.as_str()) {
                return Err(BrianError::at(
                    &files.behaviors,
                    b.span,
                    format!("behavior `{}` is listed twice", b.name),
                ));
            }
            let code = match b.path.strip_prefix(CODE_PREFIX) {
                Some("") => {
                    return Err(BrianError::at(
                        &files.behaviors,
                        b.path_span,
                        format!(
                            "the name of the code behavior of `{}` after `{CODE_PREFIX}` \
                             (`{CODE_PREFIX}<name>`, registered with Brian::register_behavior)",
                            b.name
                        ),
                    ))
                }
                Some(name) => Some(CodeSlot { name: name.to_string(), behavior: None }),
                None => None,
            };
            let rules = if code.is_some() {
                Vec::new()
            } else {
                let canon = match checked.get(b.path.as_str()) {
                    Some(canon) => canon.clone(),
                    None => {
                        let canon = src.rule_file(&root, base, &files.behaviors, b)?;
                        checked.insert(b.path.as_str(), canon.clone());
                        canon
                    }
                };
                match rule_files.get(&canon) {
                    Some(rules) => rules.clone(),
                    None => {
                        // Read the checked file; report places under the path as written.
                        let rul = base.join(&b.path);
                        let text = read(&canon).map_err(|e| match e {
                            BrianError::Io { source, .. } => {
                                BrianError::Io { file: rul.clone(), source }
                            }
                            BrianError::At { line, column, message, .. } => {
                                BrianError::At { file: rul.clone(), line, column, message }
                            }
                            other => other,
                        })?;
                        let rules = parse_text(&text, &rul, |c| {
                            parse_rules(c, &Names { file: &rul, ..names }, &outputs)
                        })?;
                        rule_files.insert(canon, rules.clone());
                        rules
                    }
                }
            };
            let cando = match cando_of.get(b.name.as_str()) {
                Some(raw) => Some(Names { file: &files.cando, ..names }.resolve(raw)?),
                None => None,
            };
            let want = match want_of.get(b.name.as_str()) {
                Some(raw) => Some(Names { file: &files.want, ..names }.resolve(raw)?),
                None => None,
            };
            behaviors.push(Behavior {
                name: b.name.clone(),
                span: b.span,
                level: b.level,
                cando,
                want,
                rules,
                code,
            });
        }
        for (file, defs) in [(&files.cando, &cando), (&files.want, &want)] {
            if let Some((n, span, _)) = defs.iter().find(|(n, _, _)| !seen.contains(n.as_str())) {
                return Err(BrianError::at(
                    file,
                    *span,
                    format!("`{n}` is not a behavior of behavior.txt"),
                ));
            }
        }
        drop(seen);
        behaviors.sort_by(|a, b| (a.level, &a.name).cmp(&(b.level, &b.name)));

        // Definitions nobody uses are legal but usually a mistake: warn.
        let mut used_p = vec![false; predicates.len()];
        let mut used_a = vec![false; predicate_actions.len()];
        let exprs = predicates
            .iter()
            .map(|(_, e)| e)
            .chain(predicate_actions.iter().map(|(_, e)| e))
            .chain(behaviors.iter().flat_map(|b| b.cando.iter().chain(b.want.iter())))
            .chain(behaviors.iter().flat_map(|b| b.rules.iter().map(|r| &r.precondition)));
        for e in exprs {
            mark_used(e, &mut used_p, &mut used_a);
        }
        for (i, (name, _)) in predicates.iter().enumerate().filter(|(i, _)| !used_p[*i]) {
            warnings.push(warning(
                &files.predicates,
                pred_spans[i],
                &format!("predicate `{name}` is never used"),
            ));
        }
        for (i, (name, _)) in predicate_actions.iter().enumerate().filter(|(i, _)| !used_a[*i]) {
            warnings.push(warning(
                &files.predicate_actions,
                pact_spans[i],
                &format!("predicate action `{name}` is never used"),
            ));
        }
        for b in behaviors.iter().filter(|b| b.cando.is_none()) {
            let what = format!(
                "behavior `{}` has no CANDO entry in {}: it never runs",
                b.name,
                files.cando.display()
            );
            warnings.push(warning(&files.behaviors, b.span, &what));
        }
        for b in behaviors.iter().filter(|b| b.want.is_none()) {
            let what = format!(
                "behavior `{}` has no WANT entry in {}: its weight is 0 and it proposes nothing",
                b.name,
                files.want.display()
            );
            warnings.push(warning(&files.behaviors, b.span, &what));
        }

        for b in &behaviors {
            if let Some(code) = &b.code {
                let what = format!(
                    "behavior `{}` is written in code (`{CODE_PREFIX}{}`): it proposes nothing \
                     until a program registers it (Brian::register_behavior(\"{}\", ...))",
                    b.name, code.name, code.name
                );
                warnings.push(warning(&files.behaviors, b.span, &what));
            }
        }

        let slots = actions.iter().map(|a| a.labels.len()).sum();
        let mut is_proposed = vec![false; inputs.len()];
        for p in actions.iter().filter_map(|a| a.proposed) {
            if let Some(flag) = is_proposed.get_mut(p) {
                *flag = true;
            }
        }
        let feedback =
            inputs.iter().map(|i| outputs.by_name.get(i.name.as_str()).copied()).collect();
        drop(outputs);
        let mut sorted: Vec<(Arc<str>, usize)> =
            actions.iter().enumerate().map(|(i, a)| (Arc::from(a.name.as_str()), i)).collect();
        sorted.sort();
        Ok(Brian {
            tracing: false,
            traced: Vec::new(),
            sorted_names: sorted.into(),
            shared_outputs: Arc::new(vec![None; actions.len()]),
            feedback,
            warnings,
            names: index,
            cando_filter: None,
            composition: engine.composition.unwrap_or_default(),
            semantics: engine.semantics.unwrap_or_default(),
            code_out: Vec::new(),
            activity: vec![None; behaviors.len()],
            is_proposed,
            outputs: vec![None; actions.len()],
            composer: engine.composer.unwrap_or_default(),
            weight_composer: engine.weight_composer.unwrap_or_default(),
            data: vec![FuzzyValue::MISSING; fuzzy_data_len],
            pred_values: vec![FuzzyValue::MISSING; predicates.len()],
            act_values: vec![FuzzyValue::MISSING; predicate_actions.len()],
            lower: vec![Acc::default(); slots],
            level_acc: vec![Acc::default(); slots],
            inputs,
            predicates,
            predicate_actions,
            behaviors,
            actions,
            threshold: engine.threshold.unwrap_or(DEFAULT_THRESHOLD),
        })
    }

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

    /// The slot of a crisp input, for [`set_input`](Self::set_input).
    pub fn input_slot(&self, name: &str) -> Option<usize> {
        self.names.inputs.get(name).copied()
    }

    /// Sets an input for the next [`step`](Self::step). Reliability is clamped to `[0, 1]`; a
    /// NaN reliability counts as 0 (the datum is not trusted at all).
    pub fn set_input(&mut self, slot: usize, value: f64, reliability: f64) {
        let reliability = if reliability.is_nan() { 0.0 } else { reliability.clamp(0.0, 1.0) };
        if let Some(i) = self.inputs.get_mut(slot) {
            i.now = Some((value, reliability));
        }
    }

    /// Forgets every input set since the last step (missing inputs read as value 0,
    /// reliability 1, or as the previous cycle's output of the same name).
    pub fn clear_inputs(&mut self) {
        self.inputs.iter_mut().for_each(|i| i.now = None);
    }

    /// The output action names, in `s_ftoc.txt` order (the order of [`output`](Self::output)).
    pub fn output_names(&self) -> impl Iterator<Item = &str> {
        self.actions.iter().map(|a| a.name.as_str())
    }

    /// Output `i` of the last step; `None` when every weight of that action was 0.
    pub fn output(&self, i: usize) -> Option<f64> {
        self.outputs.get(i).copied().flatten()
    }

    /// Runs one cycle on the inputs set with [`set_input`](Self::set_input), then clears them.
    /// Allocates nothing.
    pub fn step(&mut self) {
        self.cycle();
        self.clear_inputs();
    }

    /// Runs one cycle on `(name, value, reliability)` inputs. Unknown names are ignored; a
    /// missing input reads as value 0, reliability 1 for every label, unless the previous
    /// cycle produced an output of that name (then that value with reliability 1). A NaN value
    /// belongs to no fuzzy set.
    pub fn run(&mut self, inputs: &[(&str, f64, f64)]) -> Commands {
        self.clear_inputs();
        for (name, v, r) in inputs {
            if let Some(slot) = self.input_slot(name) {
                self.set_input(slot, *v, *r);
            }
        }
        self.step();
        // Reuses the shared buffer when no caller still holds the previous cycle's commands.
        Arc::make_mut(&mut self.shared_outputs).copy_from_slice(&self.outputs);
        Commands { names: self.sorted_names.clone(), values: self.shared_outputs.clone() }
    }

    fn fuzzify(&mut self, slot: usize) {
        let input = &self.inputs[slot];
        let crisp = input.now.or(input.previous.map(|v| (v, 1.0)));
        for (k, (_, set)) in input.shape.sets.iter().enumerate() {
            self.data[input.offset + k] = match crisp {
                Some((v, r)) => FuzzyValue::new(set.membership(v), r),
                None => FuzzyValue::MISSING,
            };
        }
    }

    fn cycle(&mut self) {
        self.traced.clear();
        for slot in 0..self.inputs.len() {
            if self.is_proposed[slot] {
                self.inputs[slot].now = None;
                self.inputs[slot].previous = None;
            }
            self.fuzzify(slot);
        }
        for i in 0..self.predicates.len() {
            self.pred_values[i] = self.predicates[i].1.eval(&self.data, &self.pred_values, &[]);
        }
        self.lower.iter_mut().for_each(|v| *v = Acc::default());
        let mut b = 0;
        let mut first = true;
        while b < self.behaviors.len() {
            let level = self.behaviors[b].level;
            if !first {
                self.feed_proposals();
            }
            first = false;
            for i in 0..self.predicate_actions.len() {
                self.act_values[i] = self.predicate_actions[i].1.eval(
                    &self.data,
                    &self.pred_values,
                    &self.act_values,
                );
            }
            self.level_acc.iter_mut().for_each(|v| *v = Acc::default());
            while b < self.behaviors.len() && self.behaviors[b].level == level {
                self.run_behavior(b);
                b += 1;
            }
            for (l, v) in self.lower.iter_mut().zip(&self.level_acc) {
                l.merge(v);
            }
        }
        for (ai, a) in self.actions.iter().enumerate() {
            self.outputs[ai] = self.crisp(a, self.composer, self.composition);
        }
        // The previous cycle's outputs come back as inputs of the same name (§10.5).
        for (input, fb) in self.inputs.iter_mut().zip(&self.feedback) {
            input.previous = fb.and_then(|ai| self.outputs[ai]);
        }
    }

    /// Defuzzifies one action from the accumulated proposals.
    fn crisp(&self, a: &Action, c: Composer, composition: Composition) -> Option<f64> {
        let w = &self.lower[a.offset..a.offset + a.labels.len()];
        // Formula 10.5: the behavior of largest μC · μW among those proposing for this action
        // (ties: the first to run).
        let mut best: Option<(f64, usize)> = None;
        if composition == Composition::Argmax {
            for acc in w.iter().filter(|acc| acc.best.n > 0) {
                if best.is_none_or(|(s, by)| acc.score > s || (acc.score == s && acc.by < by)) {
                    best = Some((acc.score, acc.by));
                }
            }
        }
        let weight = |acc: &Acc| match best {
            None => acc.all.weight(c),
            Some((_, by)) if acc.best.n > 0 && acc.by == by => acc.best.weight(c),
            Some(_) => 0.0,
        };
        if a.barycenter {
            barycenter(a.sets.iter().zip(w).map(|((_, s), w)| (s, weight(w))), a.circular)
        } else {
            defuzzify(a.labels.iter().zip(w).map(|((_, s), w)| (*s, weight(w))), a.circular)
        }
    }

    /// Defuzzifies what the lower levels propose into `Proposed<Action>` data and fuzzifies it.
    fn feed_proposals(&mut self) {
        for ai in 0..self.actions.len() {
            let a = &self.actions[ai];
            let Some(slot) = a.proposed else { continue };
            // What lower levels propose is composed by max per label, whatever
            // composer and composition the outputs use.
            let crisp = self.crisp(a, Composer::Max, Composition::Weighted);
            self.inputs[slot].now = crisp.map(|v| (v, 1.0));
            self.fuzzify(slot);
        }
    }

    fn run_behavior(&mut self, b: usize) {
        let beh = &self.behaviors[b];
        // No CANDO entry reads as missing, (0, 1): the behavior never runs (the checker warns).
        let cando = beh.cando.as_ref().map_or(FuzzyValue::MISSING, |e| {
            e.eval(&self.data, &self.pred_values, &self.act_values)
        });
        let passes = match &self.cando_filter {
            Some(filter) => filter.0.can_do(&beh.name, cando),
            None => ThresholdFilter { threshold: self.threshold }.can_do(&beh.name, cando),
        };
        // The original engine also gates CANDO and WANT on their reliability (Semantics).
        let original = self.semantics == Semantics::Original;
        if !passes || (original && cando.reliability <= self.threshold) {
            self.activity[b] = None;
            return;
        }
        let want = beh.want.as_ref().map_or(FuzzyValue::MISSING, |e| {
            e.eval(&self.data, &self.pred_values, &self.act_values)
        });
        self.activity[b] = Some((cando, want));
        let reliable = !original || want.reliability > WANT_THRESHOLD;
        let weight = if want.value > WANT_THRESHOLD && reliable { want.value } else { 0.0 };
        // μC · μW, by which formula 10.5 chooses.
        let score = cando.value * weight;
        if self.behaviors[b].code.is_some() {
            self.run_code(b, weight, score);
            return;
        }
        for r in 0..self.behaviors[b].rules.len() {
            let rule = &self.behaviors[b].rules[r];
            let p = rule.precondition.eval(&self.data, &self.pred_values, &self.act_values);
            let value = match self.semantics {
                Semantics::Manual if p.reliability < MIN_RELIABILITY => continue,
                Semantics::Manual => p.value * p.reliability,
                Semantics::Original => p.value,
            };
            for k in 0..rule.actions.len() {
                let act = self.behaviors[b].rules[r].actions[k];
                self.apply(b, act, value, weight, score);
            }
        }
    }

    /// Runs a code behavior: its proposals are applied as a rule's.
    fn run_code(&mut self, b: usize, weight: f64, score: f64) {
        let code = self.behaviors[b].code.as_ref().and_then(|c| c.behavior.clone());
        let Some(code) = code else { return };
        let mut out = std::mem::take(&mut self.code_out);
        out.clear();
        code.0.run(
            &Situation { brian: self, behavior: b },
            &mut Proposals { brian: self, out: &mut out },
        );
        for &(act, value) in &out {
            self.apply(b, act, value, weight, score);
        }
        self.code_out = out;
    }

    /// One action of behavior `b`, from a rule of value `value` (or a code behavior), the
    /// behavior weighing `weight` with μC · μW = `score`.
    fn apply(&mut self, b: usize, act: RuleAction, value: f64, weight: f64, score: f64) {
        match act {
            // A rule that does not fire (value 0), or a behavior of weight 0, proposes
            // nothing: it must not count in the average composer's mean.
            RuleAction::Propose(slot) if weight * value > 0.0 => {
                let weighted = self.weight_composer.apply(value, weight);
                self.level_acc[slot].add(weighted, score, b);
                if self.tracing {
                    // Actions are in offset order: the last one starting at or before `slot`
                    // holds it.
                    let ai = self.actions.partition_point(|a| a.offset <= slot).saturating_sub(1);
                    let label = slot - self.actions[ai].offset;
                    self.traced.push((b, ai, Some(label), Some(weighted)));
                }
            }
            RuleAction::Propose(_) => {}
            // `&DEL` applies when the rule fires (value > 0), whatever the behavior's weight:
            // a running behavior (CANDO above the threshold) may suppress lower levels even
            // while its WANT gives its own proposals no weight. This is what the shared
            // conformance data (brian40-hier) require.
            RuleAction::Delete { action, label } if value > 0.0 => {
                if self.tracing {
                    self.traced.push((b, action, label, None));
                }
                let a = &self.actions[action];
                match label {
                    Some(k) => self.lower[a.offset + k] = Acc::default(),
                    None => self.lower[a.offset..a.offset + a.labels.len()]
                        .iter_mut()
                        .for_each(|v| *v = Acc::default()),
                }
            }
            RuleAction::Delete { .. } => {}
        }
    }
}

/// The labels of an output shape with their singletons, and whether the shape is defuzzified
/// by barycenter (§10.3.9, §10.4.6): a shape of singletons only (SNG) by formula 10.6, a shape
/// of polygons only (TRI, DIV, TRA, REC) by formula 10.7, each label's singleton then being
/// its set's barycenter at full height. A shape that mixes them, or that holds TOL or TOR
/// (their area is infinite), is refused at the shape's name.
fn output_labels(
    shape: &Shape,
    circular: bool,
    file: &Path,
) -> Result<(Vec<(String, f64)>, bool), BrianError> {
    let polygon = |set: &FuzzySet| crate::shapes::is_polygon(set);
    let barycenter = shape.sets.first().is_some_and(|(_, set)| polygon(set));
    let mut labels = Vec::with_capacity(shape.sets.len());
    for (label, set) in &shape.sets {
        let err = |what: String| BrianError::at(file, shape.span, what);
        let id = set.identifier();
        match (set, barycenter) {
            (FuzzySet::Sng { a }, false) => labels.push((label.clone(), *a)),
            (FuzzySet::Tol { .. } | FuzzySet::Tor { .. }, _) => {
                return Err(err(format!(
                    "output shape `{}` set `{label}` is {id}, open on one side: defuzzification \
                     uses singletons (SNG, formula 10.6) or polygons of finite area (TRI, DIV, \
                     TRA, REC: barycenter, formula 10.7)",
                    shape.name
                )))
            }
            (_, true) if polygon(set) => {
                let Some(centroid) = crate::shapes::barycenter([(set, 1.0)], circular) else {
                    return Err(err(format!(
                        "output shape `{}` set `{label}` ({id} {:?}) has no barycenter: \
                         barycenter defuzzification needs polygons of some width and of finite \
                         size (or use SNG)",
                        shape.name,
                        set.params()
                    )));
                };
                labels.push((label.clone(), centroid));
            }
            _ => {
                let (first, kind) = if barycenter {
                    ("polygons (TRI, DIV, TRA, REC: barycenter, formula 10.7)", id)
                } else {
                    ("singletons (SNG, formula 10.6)", id)
                };
                return Err(err(format!(
                    "output shape `{}` mixes {first} with set `{label}` ({kind}): one shape is \
                     defuzzified one way, all SNG or all polygons",
                    shape.name
                )));
            }
        }
    }
    Ok((labels, barycenter))
}

fn warning(file: &Path, span: Span, what: &str) -> String {
    format!(
        "warning in file {0} at line {1}: {what}\n  --> {0}:{1}:{2}",
        file.display(),
        span.line,
        span.column
    )
}

fn mark_used(e: &Expr, preds: &mut [bool], acts: &mut [bool]) {
    match e {
        Expr::And(a, b) | Expr::Or(a, b) => {
            mark_used(a, preds, acts);
            mark_used(b, preds, acts);
        }
        Expr::Not(a) => mark_used(a, preds, acts),
        Expr::Pred(i) => preds[*i] = true,
        Expr::Action(i) => acts[*i] = true,
        Expr::Data(_) => {}
    }
}

/// `(level <n> <name> <path>)` lines.
fn parse_behavior_list(c: &mut Cursor<'_>) -> Result<Vec<Listed>, BrianError> {
    let mut out = Vec::new();
    while !c.at_end() {
        c.punct(Tok::Open, "`(` to start a behavior line")?;
        let (kw, span) = c.word("`level`")?;
        if kw != "level" {
            return Err(BrianError::at(c.file(), span, format!("expected `level`, found `{kw}`")));
        }
        let lspan = c.span();
        let level = c.number("the level number")?;
        // Compared as f64: `MAX_LEVEL` is exact in an f64, and a NaN fails the test.
        if !(level.fract() == 0.0 && (1.0..=MAX_LEVEL as f64).contains(&level)) {
            return Err(BrianError::at(
                c.file(),
                lspan,
                format!("the level must be a whole number from 1 to {MAX_LEVEL}, found {level}"),
            ));
        }
        let (name, nspan) = c.word("the behavior name")?;
        let path_span = c.span();
        let (path, _) = c.word("the path of the behavior's rule file")?;
        c.punct(Tok::Close, "`)` to close the behavior line")?;
        // In range and whole: the conversion is exact.
        out.push(Listed { name, level: level as i64, path, span: nspan, path_span });
    }
    Ok(out)
}

/// `<precondition> => <action>+ ;` rules.
fn parse_rules(
    c: &mut Cursor<'_>,
    names: &Names<'_>,
    outputs: &Outputs<'_>,
) -> Result<Vec<Rule>, BrianError> {
    let mut rules = Vec::new();
    while !c.at_end() {
        let raw = parse_expr(c)?;
        let precondition = names.resolve(&raw)?;
        c.punct(Tok::Eq, "`=>` after the precondition")?;
        match c.peek() {
            Some(Tok::Word(w)) if w == ">" => {
                c.word("`>`")?;
            }
            _ => return Err(c.expected("`=>` after the precondition")),
        }
        let mut acts = Vec::new();
        while c.peek() == Some(&Tok::Open) {
            // `(` followed by something that is not an action starts the next rule: the `;`
            // of this one is missing.
            let is_action = matches!(c.peek_at(1), Some(Tok::Word(w)) if w.starts_with("&DEL.") || outputs.by_name.contains_key(w.as_str()));
            if !acts.is_empty() && !is_action {
                return Err(c.expected("`;` at the end of the rule"));
            }
            c.punct(Tok::Open, "`(`")?;
            let (name, span) = c.word("an action name or &DEL.<action>")?;
            let (label, lspan) = c.word("a label")?;
            c.punct(Tok::Close, "`)` to close the action")?;
            let (target, delete) = match name.strip_prefix("&DEL.") {
                Some(t) => (t, true),
                None => (name.as_str(), false),
            };
            let found = outputs
                .by_name
                .get(target)
                .and_then(|&ai| Some((ai, outputs.actions.get(ai)?, outputs.labels.get(ai)?)));
            let Some((ai, a, labels)) = found else {
                return Err(BrianError::at(
                    c.file(),
                    span,
                    format!("unknown action `{target}` (not in s_ftoc.txt)"),
                ));
            };
            let k = labels.get(label.as_str()).copied();
            acts.push(match (delete, k) {
                (true, _) if label == "ANY" => RuleAction::Delete { action: ai, label: None },
                (true, Some(k)) => RuleAction::Delete { action: ai, label: Some(k) },
                (false, Some(k)) => RuleAction::Propose(a.offset + k),
                (_, None) => {
                    let known: Vec<&str> = a.labels.iter().map(|(l, _)| l.as_str()).collect();
                    return Err(BrianError::at(
                        c.file(),
                        lspan,
                        format!(
                            "action `{target}` has no label `{label}` (labels: {})",
                            known.join(", ")
                        ),
                    ));
                }
            });
        }
        if acts.is_empty() {
            return Err(c.expected("an action `(<action> <label>)` after `=>`"));
        }
        c.punct(Tok::Semi, "`;` at the end of the rule")?;
        rules.push(Rule { precondition, actions: acts });
    }
    Ok(rules)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn soup() -> impl Strategy<Value = String> {
        proptest::collection::vec(
            prop_oneof![
                Just("("),
                Just(")"),
                Just("AND"),
                Just("OR"),
                Just("NOT"),
                Just("D"),
                Just("P"),
                Just("level"),
                Just("1"),
                Just("-2.5"),
                Just("A"),
                Just("B"),
                Just("=>"),
                Just("="),
                Just(">"),
                Just(";"),
                Just("&DEL.Out"),
                Just("ANY"),
                Just("Out"),
                Just("HIGH"),
                Just("#x\n"),
                Just("\n"),
                Just(" ")
            ],
            0..48,
        )
        .prop_map(|v| v.concat())
    }

    fn try_all(text: &str) {
        let file = Path::new("x");
        let Ok(toks) = tokenize(text, file) else { return };
        let index = Index::default();
        let names = Names { inputs: &[], index: &index, file };
        let actions = [Action {
            name: "Out".into(),
            labels: vec![("HIGH".into(), 1.0)],
            sets: vec![("HIGH".into(), FuzzySet::Sng { a: 1.0 })],
            barycenter: false,
            circular: false,
            proposed: None,
            offset: 0,
        }];
        let _ = parse_rules(&mut Cursor::new(&toks, file, text), &names, &Outputs::new(&actions));
        let _ = parse_behavior_list(&mut Cursor::new(&toks, file, text));
        let _ = parse_definitions(&mut Cursor::new(&toks, file, text));
    }

    proptest! {
        #[test]
        fn rule_definition_and_behavior_parsers_never_panic_on_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
            try_all(&String::from_utf8_lossy(&bytes));
        }

        #[test]
        fn rule_definition_and_behavior_parsers_never_panic_on_token_soup(text in soup()) {
            try_all(&text);
        }
    }

    /// §10.4.9's other composers on the same proposals: GoToTarget (weight 0.67) FAST 0.56 and
    /// 0.478, SLOW 0.968; AvoidObstacle (weight 1) SLOW 0.354. By hand:
    /// - `max_weight_composer` (max of value and weight) with the average: FAST
    ///   (0.67 + 0.67) / 2 = 0.67; SLOW (0.968 + 1) / 2 = 0.984.
    /// - `min_weight_composer` (min of value and weight) with the average: FAST
    ///   (0.56 + 0.478) / 2 = 0.519; SLOW (0.67 + 0.354) / 2 = 0.512.
    /// - `mult_weight_composer` with `min_float_composer`: FAST min(0.3752, 0.32026) =
    ///   0.32026; SLOW min(0.64856, 0.354) = 0.354.
    #[test]
    fn manual_weight_and_float_composers() {
        let (go, avoid) = (0.67, 1.0);
        let composed = |w: WeightComposer, f: Composer| {
            let fast = f.combine(&[w.apply(0.56, go), w.apply(0.478, go)]);
            let slow = f.combine(&[w.apply(0.968, go), w.apply(0.354, avoid)]);
            (fast, slow)
        };
        let close =
            |(a, b): (f64, f64), (c, d): (f64, f64)| (a - c).abs() < 1e-9 && (b - d).abs() < 1e-9;
        assert!(close(composed(WeightComposer::Max, Composer::Average), (0.67, 0.984)));
        assert!(close(composed(WeightComposer::Min, Composer::Average), (0.519, 0.512)));
        assert!(close(composed(WeightComposer::Mult, Composer::Min), (0.32026, 0.354)));
        assert!(close(composed(WeightComposer::Mult, Composer::Average), (0.34773, 0.50128)));
        assert_eq!(Composer::Min.combine(&[]), 0.0, "no proposal: 0, not infinity");
    }

    /// §10.4.9 with `mult_weight_composer` and `average_float_composer`: GoToTarget (weight
    /// 0.67) proposes FAST 0.56 and 0.478, SLOW 0.968; AvoidObstacle (weight 1) SLOW 0.354.
    /// The manual prints the first FAST proposal as 0.57 but its weighted value as 0.3752,
    /// which is 0.56 × 0.67 (0.57 × 0.67 = 0.3819): the proposal was 0.56. Then
    /// FAST = (0.3752 + 0.32026) / 2 = 0.34773 and SLOW = (0.64856 + 0.354) / 2 = 0.50128.
    #[test]
    fn manual_average_composition_with_the_typo_fixed() {
        let fast = Composer::Average.combine(&[0.56 * 0.67, 0.478 * 0.67]);
        let slow = Composer::Average.combine(&[0.968 * 0.67, 0.354 * 1.0]);
        assert!((fast - 0.34773).abs() < 1e-9, "{fast}");
        assert!((slow - 0.50128).abs() < 1e-9, "{slow}");
        let with_typo = Composer::Average.combine(&[0.57 * 0.67, 0.478 * 0.67]);
        assert!((with_typo - 0.34773).abs() > 1e-3, "0.57 would not give the manual's result");
        // The default composer takes the maximum (formula 10.3).
        assert!((Composer::Max.combine(&[0.968 * 0.67, 0.354]) - 0.64856).abs() < 1e-9);
        assert_eq!(Composer::Max.combine(&[]), 0.0);
    }
}
