//! The parsers of a configuration's own grammars: the behavior list (`behavior.txt`), the rule
//! files (`*.rul`), and the resolution of the names an expression uses ([`Names`]) through the
//! tables of what is defined so far ([`Index`]).

use super::files::Source;
use super::{Action, Input, Rule, RuleAction, MAX_LEVEL};
use crate::error::BrianError;
use crate::expr::{parse_expr, Expr, RawExpr};
use crate::lexer::{tokenize, Cursor, Span, Tok};
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// Name → index tables of what is defined so far, so that every reference resolves in
/// constant time: loading is linear in the size of the configuration (it once was
/// quadratic: 200 000 definitions never finished).
#[derive(Clone, Debug, Default)]
pub(super) struct Index {
    /// Crisp input name → its index in the inputs.
    pub(super) inputs: HashMap<String, usize>,
    /// For each input, its shape's label → the label's position in the shape.
    pub(super) labels: Vec<Arc<HashMap<String, usize>>>,
    /// Predicate name → index, for those defined so far.
    pub(super) predicates: HashMap<String, usize>,
    /// Predicate action name → index, for those defined so far.
    pub(super) predicate_actions: HashMap<String, usize>,
}

/// The names an expression of `file` may use: the inputs and what [`Index`] holds.
#[derive(Clone, Copy)]
pub(super) struct Names<'a> {
    /// The crisp inputs of `ctof.txt`.
    pub(super) inputs: &'a [Input],
    /// What is defined so far.
    pub(super) index: &'a Index,
    /// The file the expressions are read from, for errors.
    pub(super) file: &'a Path,
}

impl Names<'_> {
    /// `e` with every name replaced by its index; an unknown name is an error at its place.
    pub(super) fn resolve(&self, e: &RawExpr) -> Result<Expr, BrianError> {
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
pub(super) struct Outputs<'a> {
    actions: &'a [Action],
    /// Action name → index.
    pub(super) by_name: HashMap<&'a str, usize>,
    /// For each action, label → position.
    labels: Vec<HashMap<&'a str, usize>>,
}

impl<'a> Outputs<'a> {
    /// The tables of `actions`.
    pub(super) fn new(actions: &'a [Action]) -> Self {
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

/// Tokenizes the file `path` of `src` and parses it with `f`.
pub(super) fn parse_file<T>(
    src: &dyn Source,
    path: &Path,
    f: impl FnOnce(&mut Cursor<'_>) -> Result<T, BrianError>,
) -> Result<T, BrianError> {
    parse_text(&src.read(path)?, path, f)
}

/// Tokenizes `text`, read from `path`, and parses it with `f`.
pub(super) fn parse_text<T>(
    text: &str,
    path: &Path,
    f: impl FnOnce(&mut Cursor<'_>) -> Result<T, BrianError>,
) -> Result<T, BrianError> {
    let toks = tokenize(text, path)?;
    let mut c = Cursor::new(&toks, path, text);
    f(&mut c)
}

/// One line of `behavior.txt`.
pub(super) struct Listed {
    /// The behavior's name.
    pub(super) name: String,
    /// Its level.
    pub(super) level: i64,
    /// Its rule file, or `code:<name>`, as written.
    pub(super) path: String,
    /// Where the name is written.
    pub(super) span: Span,
    /// Where the path is written.
    pub(super) path_span: Span,
}

/// `(level <n> <name> <path>)` lines.
pub(super) fn parse_behavior_list(c: &mut Cursor<'_>) -> Result<Vec<Listed>, BrianError> {
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
pub(super) fn parse_rules(
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
