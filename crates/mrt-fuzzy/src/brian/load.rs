//! Loading a configuration (MRT manual §10.4): [`Brian::from_dir`], [`Brian::from_files`] and
//! [`Brian::from_sources`] read its files in one order, resolve every name, refuse what the
//! checker of §10.4.7 refuses and collect its warnings. Each step is a function of its own:
//! inputs, predicates, engine settings, predicate actions, outputs, behaviors, warnings, and
//! the engine assembled from them.

use super::files::{BrianFiles, BrianSources, Disk, Source};
use super::parse::{
    parse_behavior_list, parse_file, parse_rules, parse_text, Index, Listed, Names, Outputs,
};
use super::{Action, Behavior, Brian, CodeSlot, Input, Rule, CODE_PREFIX, DEFAULT_THRESHOLD};
use crate::compose::Acc;
use crate::engine::{parse_engine, EngineSettings};
use crate::error::BrianError;
use crate::expr::{parse_definitions, Expr, RawExpr};
use crate::lexer::Span;
use crate::set::{FuzzySet, FuzzyValue};
use crate::shapes::{parse_associations, parse_shapes, resolve, Shape};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The crisp inputs of `ctof.txt`, with their name tables.
struct Inputs {
    inputs: Vec<Input>,
    index: Index,
    /// How many fuzzy data the inputs' labels make.
    data_len: usize,
}

/// The definitions of `Predicate.ini` or `PredicateActions.ini`, resolved, in file order.
#[derive(Default)]
struct Definitions {
    defs: Vec<(String, Expr)>,
    /// Where each name is written.
    spans: Vec<Span>,
}

/// Everything a configuration's files define, checked: what [`Loaded::into_brian`] makes an
/// engine of.
struct Loaded {
    inputs: Inputs,
    predicates: Definitions,
    predicate_actions: Definitions,
    behaviors: Vec<Behavior>,
    actions: Vec<Action>,
    engine: EngineSettings,
    /// For each input, the output of the same name that feeds it back (§10.5).
    feedback: Vec<Option<usize>>,
    warnings: Vec<String>,
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

    /// Loads a configuration from `src`, step by step; the first error found is returned.
    fn load(src: &dyn Source, files: &BrianFiles, base: &Path) -> Result<Brian, BrianError> {
        let mut warnings = Vec::new();
        let mut inputs = load_inputs(src, files, &mut warnings)?;
        let predicates = load_predicates(src, files, &inputs.inputs, &mut inputs.index)?;
        let engine = load_engine(src, files)?;
        let predicate_actions =
            load_predicate_actions(src, files, &inputs.inputs, &mut inputs.index)?;
        let actions = load_actions(src, files, &inputs.index)?;
        let outputs = Outputs::new(&actions);
        let names = Names { inputs: &inputs.inputs, index: &inputs.index, file: &files.cando };
        let behaviors = load_behaviors(src, files, base, names, &outputs)?;
        warn_unused(files, &predicates, &predicate_actions, &behaviors, &mut warnings);
        warn_behaviors(files, &behaviors, &mut warnings);
        let feedback =
            inputs.inputs.iter().map(|i| outputs.by_name.get(i.name.as_str()).copied()).collect();
        drop(outputs);
        let loaded = Loaded {
            inputs,
            predicates,
            predicate_actions,
            behaviors,
            actions,
            engine,
            feedback,
            warnings,
        };
        Ok(loaded.into_brian())
    }
}

/// `shape_ctof.txt` and `ctof.txt`: the crisp inputs, each with its shape and the place of its
/// labels in the fuzzy data. A shape that no input uses is a warning.
fn load_inputs(
    src: &dyn Source,
    files: &BrianFiles,
    warnings: &mut Vec<String>,
) -> Result<Inputs, BrianError> {
    let shapes = parse_shapes(&src.read(&files.shape_ctof)?, &files.shape_ctof)?;
    let assocs = parse_associations(&src.read(&files.ctof)?, &files.ctof)?;
    let idx = resolve(&assocs, &shapes, &files.ctof)?;
    let shape_labels: Vec<Arc<HashMap<String, usize>>> = shapes
        .iter()
        .map(|s| Arc::new(s.sets.iter().enumerate().map(|(k, (l, _))| (l.clone(), k)).collect()))
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
    let used_shapes: HashSet<&str> = assocs.iter().map(|a| a.shape.as_str()).collect();
    for shape in shapes.iter().filter(|s| !used_shapes.contains(s.name.as_str())) {
        warnings.push(warning(
            &files.shape_ctof,
            shape.span,
            &format!("shape `{}` is not used in ctof.txt", shape.name),
        ));
    }
    Ok(Inputs { inputs, index, data_len: offset })
}

/// `Predicate.ini`: each predicate may use the inputs' data and the predicates before it.
fn load_predicates(
    src: &dyn Source,
    files: &BrianFiles,
    inputs: &[Input],
    index: &mut Index,
) -> Result<Definitions, BrianError> {
    let mut out = Definitions::default();
    for (name, span, raw) in parse_file(src, &files.predicates, parse_definitions)? {
        out.spans.push(span);
        let e = Names { inputs, index, file: &files.predicates }.resolve(&raw)?;
        index.predicates.insert(name.clone(), out.defs.len());
        out.defs.push((name, e));
    }
    Ok(out)
}

/// `engine.txt` when there is one; otherwise the manual's defaults.
fn load_engine(src: &dyn Source, files: &BrianFiles) -> Result<EngineSettings, BrianError> {
    if src.exists(&files.engine) {
        parse_engine(&src.read(&files.engine)?, &files.engine)
    } else {
        Ok(EngineSettings::default())
    }
}

/// `PredicateActions.ini` when there is one: each predicate action may use the data, every
/// predicate and the predicate actions before it; a predicate's name is refused.
fn load_predicate_actions(
    src: &dyn Source,
    files: &BrianFiles,
    inputs: &[Input],
    index: &mut Index,
) -> Result<Definitions, BrianError> {
    let mut out = Definitions::default();
    if !src.exists(&files.predicate_actions) {
        return Ok(out);
    }
    for (name, span, raw) in parse_file(src, &files.predicate_actions, parse_definitions)? {
        if index.predicates.contains_key(&name) {
            return Err(BrianError::at(
                &files.predicate_actions,
                span,
                format!("`{name}` is already a predicate"),
            ));
        }
        let e = Names { inputs, index, file: &files.predicate_actions }.resolve(&raw)?;
        out.spans.push(span);
        index.predicate_actions.insert(name.clone(), out.defs.len());
        out.defs.push((name, e));
    }
    Ok(out)
}

/// `s_shape.txt` and `s_ftoc.txt`: the output actions, each with its labels' singletons, how
/// it is defuzzified, and the `Proposed<Action>` input that shows it to higher levels.
fn load_actions(
    src: &dyn Source,
    files: &BrianFiles,
    index: &Index,
) -> Result<Vec<Action>, BrianError> {
    let s_shapes = parse_shapes(&src.read(&files.s_shape)?, &files.s_shape)?;
    let s_assocs = parse_associations(&src.read(&files.s_ftoc)?, &files.s_ftoc)?;
    let s_idx = resolve(&s_assocs, &s_shapes, &files.s_ftoc)?;
    let mut actions = Vec::new();
    let mut offset = 0;
    for (a, i) in s_assocs.iter().zip(s_idx) {
        let shape = &s_shapes[i];
        let circular = a.name.contains("Angle");
        let (labels, barycenter) = output_labels(shape, circular, &files.s_shape)?;
        check_finite(shape, &labels, barycenter, &files.s_shape)?;
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
    Ok(actions)
}

/// Formula 10.6 sums weight × singleton (weights at most 1), formula 10.7 area × centroid:
/// the sum over an output shape must stay a number, or the command would be infinite or NaN.
fn check_finite(
    shape: &Shape,
    labels: &[(String, f64)],
    barycenter: bool,
    file: &Path,
) -> Result<(), BrianError> {
    let sum: f64 = if barycenter {
        let moments = shape.sets.iter().flat_map(|(_, set)| {
            crate::shapes::clipped_areas(set, 1.0).map(|(x, area)| area + (x * area).abs())
        });
        moments.sum()
    } else {
        labels.iter().map(|(_, v)| v.abs()).sum()
    };
    if sum.is_finite() {
        return Ok(());
    }
    Err(BrianError::at(
        file,
        shape.span,
        format!(
            "the {} of output shape `{}` are too large: their sum is not a finite number",
            if barycenter { "sets" } else { "singletons" },
            shape.name
        ),
    ))
}

/// `Cando.ini`, `want.txt`, `behavior.txt` and the rule files: the behaviors, in run order
/// (level, then name). A behavior listed twice, or a CANDO or WANT of a behavior that is not
/// listed, is an error.
fn load_behaviors(
    src: &dyn Source,
    files: &BrianFiles,
    base: &Path,
    names: Names<'_>,
    outputs: &Outputs<'_>,
) -> Result<Vec<Behavior>, BrianError> {
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
    let mut rule_files = RuleFiles {
        src,
        list: &files.behaviors,
        base,
        root,
        names,
        outputs,
        checked: HashMap::new(),
        parsed: HashMap::new(),
    };
    let mut behaviors = Vec::with_capacity(listed.len());
    for b in &listed {
        if !seen.insert(b.name.as_str()) {
            return Err(BrianError::at(
                &files.behaviors,
                b.span,
                format!("behavior `{}` is listed twice", b.name),
            ));
        }
        let code = code_slot(b, &files.behaviors)?;
        let rules = if code.is_some() { Vec::new() } else { rule_files.rules(b)? };
        let condition = |of: &HashMap<&str, &RawExpr>, file: &Path| {
            of.get(b.name.as_str()).map(|raw| Names { file, ..names }.resolve(raw)).transpose()
        };
        let cando = condition(&cando_of, &files.cando)?;
        let want = condition(&want_of, &files.want)?;
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
    behaviors.sort_by(|a, b| (a.level, &a.name).cmp(&(b.level, &b.name)));
    Ok(behaviors)
}

/// The code behavior a `behavior.txt` line names (`code:<name>`), if it names one.
fn code_slot(b: &Listed, list: &Path) -> Result<Option<CodeSlot>, BrianError> {
    match b.path.strip_prefix(CODE_PREFIX) {
        Some("") => Err(BrianError::at(
            list,
            b.path_span,
            format!(
                "the name of the code behavior of `{}` after `{CODE_PREFIX}` \
                 (`{CODE_PREFIX}<name>`, registered with Brian::register_behavior)",
                b.name
            ),
        )),
        Some(name) => Ok(Some(CodeSlot { name: name.to_string(), behavior: None })),
        None => Ok(None),
    }
}

/// The rule files of `behavior.txt`: behaviors often share one, and each is checked, read
/// and resolved once.
struct RuleFiles<'a> {
    src: &'a dyn Source,
    /// `behavior.txt`.
    list: &'a Path,
    base: &'a Path,
    /// The directory every rule file must lie in.
    root: PathBuf,
    names: Names<'a>,
    outputs: &'a Outputs<'a>,
    /// Path as written → the checked file it leads to.
    checked: HashMap<&'a str, PathBuf>,
    /// Checked file → its rules.
    parsed: HashMap<PathBuf, Vec<Rule>>,
}

impl<'a> RuleFiles<'a> {
    /// The rules of the file that `b` names.
    fn rules(&mut self, b: &'a Listed) -> Result<Vec<Rule>, BrianError> {
        let canon = match self.checked.get(b.path.as_str()) {
            Some(canon) => canon.clone(),
            None => {
                let canon = self.src.rule_file(&self.root, self.base, self.list, b)?;
                self.checked.insert(b.path.as_str(), canon.clone());
                canon
            }
        };
        if let Some(rules) = self.parsed.get(&canon) {
            return Ok(rules.clone());
        }
        // Read the checked file; report places under the path as written.
        let rul = self.base.join(&b.path);
        let text = self.src.read(&canon).map_err(|e| match e {
            BrianError::Io { source, .. } => BrianError::Io { file: rul.clone(), source },
            BrianError::At { line, column, message, .. } => {
                BrianError::At { file: rul.clone(), line, column, message }
            }
            other => other,
        })?;
        let names = Names { file: &rul, ..self.names };
        let rules = parse_text(&text, &rul, |c| parse_rules(c, &names, self.outputs))?;
        self.parsed.insert(canon, rules.clone());
        Ok(rules)
    }
}

/// Definitions nobody uses are legal but usually a mistake: a warning for each predicate and
/// predicate action that no expression uses.
fn warn_unused(
    files: &BrianFiles,
    predicates: &Definitions,
    predicate_actions: &Definitions,
    behaviors: &[Behavior],
    warnings: &mut Vec<String>,
) {
    let mut used_p = vec![false; predicates.defs.len()];
    let mut used_a = vec![false; predicate_actions.defs.len()];
    let exprs = predicates
        .defs
        .iter()
        .map(|(_, e)| e)
        .chain(predicate_actions.defs.iter().map(|(_, e)| e))
        .chain(behaviors.iter().flat_map(|b| b.cando.iter().chain(b.want.iter())))
        .chain(behaviors.iter().flat_map(|b| b.rules.iter().map(|r| &r.precondition)));
    for e in exprs {
        mark_used(e, &mut used_p, &mut used_a);
    }
    for (i, (name, _)) in predicates.defs.iter().enumerate().filter(|(i, _)| !used_p[*i]) {
        warnings.push(warning(
            &files.predicates,
            predicates.spans[i],
            &format!("predicate `{name}` is never used"),
        ));
    }
    let unused_actions = predicate_actions.defs.iter().enumerate().filter(|(i, _)| !used_a[*i]);
    for (i, (name, _)) in unused_actions {
        warnings.push(warning(
            &files.predicate_actions,
            predicate_actions.spans[i],
            &format!("predicate action `{name}` is never used"),
        ));
    }
}

/// A warning for each behavior without CANDO (it never runs), without WANT (it proposes
/// nothing), or written in code (it proposes nothing until a program registers it).
fn warn_behaviors(files: &BrianFiles, behaviors: &[Behavior], warnings: &mut Vec<String>) {
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
    for b in behaviors {
        if let Some(code) = &b.code {
            let what = format!(
                "behavior `{}` is written in code (`{CODE_PREFIX}{}`): it proposes nothing \
                 until a program registers it (Brian::register_behavior(\"{}\", ...))",
                b.name, code.name, code.name
            );
            warnings.push(warning(&files.behaviors, b.span, &what));
        }
    }
}

impl Loaded {
    /// The engine, its buffers sized for the configuration and its settings from `engine.txt`.
    fn into_brian(self) -> Brian {
        let Loaded {
            inputs: Inputs { inputs, index, data_len },
            predicates,
            predicate_actions,
            behaviors,
            actions,
            engine,
            feedback,
            warnings,
        } = self;
        let slots = actions.iter().map(|a| a.labels.len()).sum();
        let mut is_proposed = vec![false; inputs.len()];
        for p in actions.iter().filter_map(|a| a.proposed) {
            if let Some(flag) = is_proposed.get_mut(p) {
                *flag = true;
            }
        }
        let mut sorted: Vec<(Arc<str>, usize)> =
            actions.iter().enumerate().map(|(i, a)| (Arc::from(a.name.as_str()), i)).collect();
        sorted.sort();
        Brian {
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
            data: vec![FuzzyValue::MISSING; data_len],
            pred_values: vec![FuzzyValue::MISSING; predicates.defs.len()],
            act_values: vec![FuzzyValue::MISSING; predicate_actions.defs.len()],
            lower: vec![Acc::default(); slots],
            level_acc: vec![Acc::default(); slots],
            inputs,
            predicates: predicates.defs,
            predicate_actions: predicate_actions.defs,
            behaviors,
            actions,
            threshold: engine.threshold.unwrap_or(DEFAULT_THRESHOLD),
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
