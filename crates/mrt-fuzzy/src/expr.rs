//! The predicate grammar shared by `Predicate.ini`, `PredicateActions.ini`, `Cando.ini`,
//! `want.txt` and rule preconditions (MRT manual §10.4.2, §10.4.4, §10.4.7):
//!
//! ```text
//! <predicate> = (AND <predicate> <predicate>) | (OR <predicate> <predicate>)
//!             | (NOT <predicate>) | (D <data> <label>) | (P <predicate_name>)
//!             | (<predicate_name>)          # as in rule preconditions
//!             | (<data> <label>)            # "you can drop the operator" (§10.4.2)
//! ```

use crate::error::BrianError;
use crate::lexer::{Cursor, Span, Tok};
use crate::set::FuzzyValue;
use std::collections::HashMap;

/// A predicate as written, names not yet resolved.
#[derive(Clone, Debug, PartialEq)]
pub enum RawExpr {
    /// `(AND a b)`
    And(Box<RawExpr>, Box<RawExpr>),
    /// `(OR a b)`
    Or(Box<RawExpr>, Box<RawExpr>),
    /// `(NOT a)`
    Not(Box<RawExpr>),
    /// `(D data label)`: the names and where each is written.
    Data(String, String, Span, Span),
    /// `(P name)` or `(name)`
    Pred(String, Span),
}

/// How deeply predicates may nest. Far beyond any real rule; it keeps a hostile file from
/// overflowing the stack of the parser and of the evaluator.
pub const MAX_DEPTH: usize = 200;

/// Parses one parenthesized predicate.
pub fn parse_expr(c: &mut Cursor<'_>) -> Result<RawExpr, BrianError> {
    parse_nested(c, 0)
}

fn parse_nested(c: &mut Cursor<'_>, depth: usize) -> Result<RawExpr, BrianError> {
    if depth >= MAX_DEPTH {
        return Err(BrianError::at(
            c.file(),
            c.span(),
            format!("predicates nest deeper than {MAX_DEPTH} levels"),
        ));
    }
    c.punct(Tok::Open, "`(` to start a predicate")?;
    let (head, span) = c.word("AND, OR, NOT, D, P or a predicate name")?;
    let e = match head.as_str() {
        "AND" | "OR" => {
            let a = parse_nested(c, depth + 1)?;
            let b = parse_nested(c, depth + 1)?;
            if head == "AND" {
                RawExpr::And(Box::new(a), Box::new(b))
            } else {
                RawExpr::Or(Box::new(a), Box::new(b))
            }
        }
        "NOT" => RawExpr::Not(Box::new(parse_nested(c, depth + 1)?)),
        "D" => {
            let (data, dspan) = c.word("a datum name after D")?;
            let (label, lspan) = c.word(&format!("a label of `{data}`"))?;
            RawExpr::Data(data, label, dspan, lspan)
        }
        "P" => {
            let (name, pspan) = c.word("a predicate name after P")?;
            RawExpr::Pred(name, pspan)
        }
        _ => match c.peek() {
            Some(Tok::Word(_)) => {
                let (label, lspan) = c.word("a label")?;
                RawExpr::Data(head, label, span, lspan)
            }
            _ => RawExpr::Pred(head, span),
        },
    };
    c.punct(Tok::Close, "`)` to close the predicate")?;
    Ok(e)
}

/// A resolved predicate: names replaced by indices.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// AND = (min, min).
    And(Box<Expr>, Box<Expr>),
    /// OR = (max, max).
    Or(Box<Expr>, Box<Expr>),
    /// NOT = (1 − value, same reliability).
    Not(Box<Expr>),
    /// A fuzzy datum: index into the fuzzy data table.
    Data(usize),
    /// A predicate of `Predicate.ini`, by index.
    Pred(usize),
    /// A predicate action of `PredicateActions.ini`, by index.
    Action(usize),
}

impl Expr {
    /// Evaluates against the fuzzy data, predicate and predicate-action values. No allocation.
    pub fn eval(
        &self,
        data: &[FuzzyValue],
        preds: &[FuzzyValue],
        acts: &[FuzzyValue],
    ) -> FuzzyValue {
        match self {
            Expr::And(a, b) => a.eval(data, preds, acts).and(b.eval(data, preds, acts)),
            Expr::Or(a, b) => a.eval(data, preds, acts).or(b.eval(data, preds, acts)),
            Expr::Not(a) => !a.eval(data, preds, acts),
            Expr::Data(i) => data.get(*i).copied().unwrap_or(FuzzyValue::MISSING),
            Expr::Pred(i) => preds.get(*i).copied().unwrap_or(FuzzyValue::MISSING),
            Expr::Action(i) => acts.get(*i).copied().unwrap_or(FuzzyValue::MISSING),
        }
    }
}

/// Parses a definitions file: `Name = <predicate>;` lines.
pub fn parse_definitions(c: &mut Cursor<'_>) -> Result<Vec<(String, Span, RawExpr)>, BrianError> {
    let mut out: Vec<(String, Span, RawExpr)> = Vec::new();
    // Name → where it was defined: the duplicate check takes constant time.
    let mut defined: HashMap<String, Span> = HashMap::new();
    while !c.at_end() {
        let (name, span) = c.word("a name at the start of a definition")?;
        c.punct(Tok::Eq, &format!("`=` after `{name}`"))?;
        let e = parse_expr(c)?;
        c.punct(Tok::Semi, &format!("`;` at the end of the definition of `{name}`"))?;
        if let Some(prev) = defined.get(&name) {
            return Err(BrianError::at(
                c.file(),
                span,
                format!("`{name}` is already defined at line {}", prev.line),
            ));
        }
        defined.insert(name.clone(), span);
        out.push((name, span, e));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lexer::tokenize;
    use std::path::Path;

    #[test]
    fn deep_nesting_is_an_error_not_a_stack_overflow() {
        let text = format!("X = {}(A){};", "(NOT ".repeat(100_000), ")".repeat(100_000));
        let toks = tokenize(&text, Path::new("p")).unwrap();
        let e = parse_definitions(&mut Cursor::new(&toks, Path::new("p"), &text)).unwrap_err();
        assert!(e.to_string().contains("nest deeper than 200"), "{e}");
        let ok = format!("X = {}(A){};", "(NOT ".repeat(150), ")".repeat(150));
        let toks = tokenize(&ok, Path::new("p")).unwrap();
        assert!(parse_definitions(&mut Cursor::new(&toks, Path::new("p"), &ok)).is_ok());
    }
}
