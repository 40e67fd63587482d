//! Blackboard values (ISocRob-2000 report §3.1): `Int`, `Float`, `Bool` and `String`, and their one
//! text form, shared by the configuration files and the relay: the type's name, a space, the
//! literal — `Int -3`, `Float 0.8`, `Bool true`, `String "a \"quoted\" word"`.
//!
//! Literals: `Int` a signed 64-bit decimal; `Float` a finite decimal (`1`, `-0.25`, `1e-3`);
//! `Bool` `true` or `false`; `String` between double quotes, with the escapes `\"`, `\\`,
//! `\n`, `\r` and `\t` (so that a value always fits on one line).

use std::fmt;

/// A value's type.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum ValueType {
    /// 64-bit signed integer.
    Int,
    /// 64-bit float, finite.
    Float,
    /// `true` or `false`.
    Bool,
    /// UTF-8 text.
    String,
}

impl ValueType {
    /// The type named `name` (`Int`, `Float`, `Bool`, `String`; case-sensitive, as in the seed).
    pub fn parse(name: &str) -> Option<ValueType> {
        match name {
            "Int" => Some(ValueType::Int),
            "Float" => Some(ValueType::Float),
            "Bool" => Some(ValueType::Bool),
            "String" => Some(ValueType::String),
            _ => None,
        }
    }
}

impl fmt::Display for ValueType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ValueType::Int => "Int",
            ValueType::Float => "Float",
            ValueType::Bool => "Bool",
            ValueType::String => "String",
        })
    }
}

/// A blackboard value.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Value {
    /// An integer.
    Int(i64),
    /// A float (finite).
    Float(f64),
    /// A truth value.
    Bool(bool),
    /// Text.
    String(String),
}

/// Why a text is not a value.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ValueError {
    /// Not one of the four type names.
    #[error("unknown type `{0}` (Int, Float, Bool or String)")]
    UnknownType(String),
    /// No literal after the type.
    #[error("a {0} value is missing")]
    Missing(ValueType),
    /// The literal does not fit the type.
    #[error("`{text}` is not a {ty}{why}")]
    Bad {
        /// The type.
        ty: ValueType,
        /// The literal.
        text: String,
        /// More detail, if any (starts with `: `).
        why: &'static str,
    },
    /// Something after the literal.
    #[error("unexpected `{0}` after the value")]
    Trailing(String),
}

impl Value {
    /// The value's type.
    pub fn value_type(&self) -> ValueType {
        match self {
            Value::Int(_) => ValueType::Int,
            Value::Float(_) => ValueType::Float,
            Value::Bool(_) => ValueType::Bool,
            Value::String(_) => ValueType::String,
        }
    }

    /// Parses a literal of type `ty` at the start of `text` (after optional spaces). Returns
    /// the value and the rest of `text` after the literal.
    pub fn parse_literal(ty: ValueType, text: &str) -> Result<(Value, &str), ValueError> {
        let text = text.trim_start();
        if text.is_empty() {
            return Err(ValueError::Missing(ty));
        }
        if ty == ValueType::String {
            return parse_quoted(text);
        }
        let end = text.find(char::is_whitespace).unwrap_or(text.len());
        let (word, rest) = text.split_at(end);
        let bad = |why| ValueError::Bad { ty, text: word.chars().take(40).collect(), why };
        let value = match ty {
            ValueType::Int => Value::Int(word.parse().map_err(|_| bad(""))?),
            ValueType::Float => {
                let f: f64 = word.parse().map_err(|_| bad(""))?;
                if !f.is_finite() {
                    return Err(bad(": floats are finite"));
                }
                Value::Float(f)
            }
            ValueType::Bool => match word {
                "true" => Value::Bool(true),
                "false" => Value::Bool(false),
                _ => return Err(bad(": `true` or `false`")),
            },
            ValueType::String => return parse_quoted(text),
        };
        Ok((value, rest))
    }

    /// Parses the whole text form `Type literal` (nothing may follow).
    pub fn parse_typed(text: &str) -> Result<Value, ValueError> {
        let text = text.trim_start();
        let end = text.find(char::is_whitespace).unwrap_or(text.len());
        let (name, rest) = text.split_at(end);
        let ty = ValueType::parse(name)
            .ok_or_else(|| ValueError::UnknownType(name.chars().take(40).collect()))?;
        let (value, rest) = Value::parse_literal(ty, rest)?;
        if !rest.trim().is_empty() {
            return Err(ValueError::Trailing(rest.trim().chars().take(40).collect()));
        }
        Ok(value)
    }

    /// The text form: `Type literal`.
    pub fn to_typed_text(&self) -> String {
        format!("{} {self}", self.value_type())
    }
}

/// A double-quoted string with escapes at the start of `text`.
fn parse_quoted(text: &str) -> Result<(Value, &str), ValueError> {
    let bad =
        |why| ValueError::Bad { ty: ValueType::String, text: text.chars().take(40).collect(), why };
    let Some(body) = text.strip_prefix('"') else {
        return Err(bad(": strings are written between double quotes"));
    };
    let mut out = String::new();
    let mut chars = body.char_indices();
    while let Some((i, c)) = chars.next() {
        match c {
            '"' => return Ok((Value::String(out), &body[i + 1..])),
            '\\' => match chars.next() {
                Some((_, '"')) => out.push('"'),
                Some((_, '\\')) => out.push('\\'),
                Some((_, 'n')) => out.push('\n'),
                Some((_, 't')) => out.push('\t'),
                Some((_, 'r')) => out.push('\r'),
                _ => return Err(bad(": the escapes are \\\" \\\\ \\n \\r \\t")),
            },
            '\n' | '\r' => return Err(bad(": a string ends on its line")),
            c => out.push(c),
        }
    }
    Err(bad(": the closing quote is missing"))
}

impl fmt::Display for Value {
    /// The literal (strings quoted and escaped).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Int(i) => write!(f, "{i}"),
            // `{:?}` keeps a decimal point or exponent, so `1.0` stays a float when read back.
            Value::Float(x) => write!(f, "{x:?}"),
            Value::Bool(b) => write!(f, "{b}"),
            Value::String(s) => {
                f.write_str("\"")?;
                for c in s.chars() {
                    match c {
                        '"' => f.write_str("\\\"")?,
                        '\\' => f.write_str("\\\\")?,
                        '\n' => f.write_str("\\n")?,
                        '\t' => f.write_str("\\t")?,
                        '\r' => f.write_str("\\r")?,
                        c => write!(f, "{c}")?,
                    }
                }
                f.write_str("\"")
            }
        }
    }
}

impl From<i64> for Value {
    fn from(v: i64) -> Value {
        Value::Int(v)
    }
}

impl From<i32> for Value {
    fn from(v: i32) -> Value {
        Value::Int(i64::from(v))
    }
}

impl From<f64> for Value {
    fn from(v: f64) -> Value {
        Value::Float(v)
    }
}

impl From<bool> for Value {
    fn from(v: bool) -> Value {
        Value::Bool(v)
    }
}

impl From<&str> for Value {
    fn from(v: &str) -> Value {
        Value::String(v.to_string())
    }
}

impl From<String> for Value {
    fn from(v: String) -> Value {
        Value::String(v)
    }
}

/// A Rust type a blackboard value can be read as ([`crate::Blackboard::get`]).
pub trait FromValue: Sized {
    /// The type a stored value must have.
    const TYPE: ValueType;
    /// The value, if it has this type (an `Int` is also read as an `f64`).
    fn from_value(v: &Value) -> Option<Self>;
}

impl FromValue for i64 {
    const TYPE: ValueType = ValueType::Int;
    fn from_value(v: &Value) -> Option<i64> {
        match v {
            Value::Int(i) => Some(*i),
            _ => None,
        }
    }
}

impl FromValue for f64 {
    const TYPE: ValueType = ValueType::Float;
    fn from_value(v: &Value) -> Option<f64> {
        match v {
            Value::Float(x) => Some(*x),
            Value::Int(i) => Some(*i as f64),
            _ => None,
        }
    }
}

impl FromValue for bool {
    const TYPE: ValueType = ValueType::Bool;
    fn from_value(v: &Value) -> Option<bool> {
        match v {
            Value::Bool(b) => Some(*b),
            _ => None,
        }
    }
}

impl FromValue for String {
    const TYPE: ValueType = ValueType::String;
    fn from_value(v: &Value) -> Option<String> {
        match v {
            Value::String(s) => Some(s.clone()),
            _ => None,
        }
    }
}

impl FromValue for Value {
    const TYPE: ValueType = ValueType::String; // unused: any type is accepted
    fn from_value(v: &Value) -> Option<Value> {
        Some(v.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn each_type_reads_and_prints_its_literal() {
        assert_eq!(Value::parse_typed("Int -3").unwrap(), Value::Int(-3));
        assert_eq!(Value::parse_typed("Float 0.8").unwrap(), Value::Float(0.8));
        assert_eq!(Value::parse_typed("Float 1").unwrap().to_typed_text(), "Float 1.0");
        assert_eq!(Value::parse_typed("Bool true").unwrap(), Value::Bool(true));
        let s = Value::parse_typed(r#"String "a \"b\" \\ c""#).unwrap();
        assert_eq!(s, Value::String(r#"a "b" \ c"#.into()));
        assert_eq!(s.to_typed_text(), r#"String "a \"b\" \\ c""#);
        assert_eq!(Value::from("two\nlines").to_string(), r#""two\nlines""#);
    }

    #[test]
    fn bad_literals_say_why() {
        let e = |t: &str| Value::parse_typed(t).unwrap_err().to_string();
        assert_eq!(e("Integer 3"), "unknown type `Integer` (Int, Float, Bool or String)");
        assert_eq!(e("Int"), "a Int value is missing");
        assert_eq!(e("Int 3.5"), "`3.5` is not a Int");
        assert_eq!(e("Float NaN"), "`NaN` is not a Float: floats are finite");
        assert_eq!(e("Bool yes"), "`yes` is not a Bool: `true` or `false`");
        assert!(e("String hello").contains("double quotes"));
        assert!(e(r#"String "open"#).contains("closing quote"));
        assert_eq!(e("Int 3 4"), "unexpected `4` after the value");
    }

    #[test]
    fn typed_reads_are_strict_except_int_as_float() {
        assert_eq!(f64::from_value(&Value::Int(2)), Some(2.0));
        assert_eq!(i64::from_value(&Value::Float(2.0)), None);
        assert_eq!(bool::from_value(&Value::Int(1)), None);
        assert_eq!(String::from_value(&Value::from("x")), Some("x".into()));
    }

    proptest! {
        #[test]
        fn random_text_never_panics(text in "\\PC{0,60}") {
            let _ = Value::parse_typed(&text);
            for ty in [ValueType::Int, ValueType::Float, ValueType::Bool, ValueType::String] {
                let _ = Value::parse_literal(ty, &text);
            }
        }

        #[test]
        fn every_value_reads_back_from_its_text(i in any::<i64>(), x in -1e300f64..1e300,
                                                b in any::<bool>(), s in "\\PC{0,30}") {
            for v in [Value::Int(i), Value::Float(x), Value::Bool(b), Value::String(s.clone())] {
                let back = Value::parse_typed(&v.to_typed_text()).unwrap();
                prop_assert_eq!(back, v);
            }
        }
    }
}
