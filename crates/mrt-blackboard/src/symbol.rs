//! Blackboard symbols (ISocRob-2000 report §3.1): dotted ASCII names whose first two levels have a
//! built-in meaning.
//!
//! - level 1, the **scope**: `local` (this robot only), `*` (shared with all robots) or `n`,
//!   a robot's ID (that robot's variable, shared with all robots);
//! - level 2, the **kind**: `var` (the latest value) or `talk` (a FIFO queue of values);
//! - then at least one more level, by convention the µAgent, an optional `config`, an
//!   optional sub-module and the variable: `local.var.machine.config.def.near-ball`.
//!
//! Levels are non-empty and made of ASCII letters, digits, `_` and `-`; a symbol is at most
//! [`MAX_SYMBOL_LEN`] bytes.

use std::fmt;

/// The longest symbol accepted, bytes.
pub const MAX_SYMBOL_LEN: usize = 200;

/// Who a symbol belongs to and who sees it (level 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Scope {
    /// `local`: this robot only; never leaves it.
    Local,
    /// `*`: one variable shared by all robots.
    All,
    /// `n`: robot `n`'s variable, shared with all robots.
    Robot(u32),
}

impl Scope {
    /// Whether changes travel to the other robots.
    pub fn is_shared(self) -> bool {
        !matches!(self, Scope::Local)
    }
}

impl fmt::Display for Scope {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Scope::Local => f.write_str("local"),
            Scope::All => f.write_str("*"),
            Scope::Robot(n) => write!(f, "{n}"),
        }
    }
}

/// What a symbol binds (level 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Kind {
    /// `var`: one value, the latest set.
    Var,
    /// `talk`: a FIFO queue of values.
    Talk,
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Kind::Var => "var",
            Kind::Talk => "talk",
        })
    }
}

/// Why a text is not a symbol.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SymbolError {
    /// Longer than [`MAX_SYMBOL_LEN`].
    #[error("a symbol is at most {MAX_SYMBOL_LEN} bytes, this one has {0}")]
    TooLong(usize),
    /// Fewer than three levels.
    #[error("`{0}`: a symbol has a scope, a kind and a name (`local.var.name`)")]
    TooShort(String),
    /// Level 1 is not `local`, `*` or a robot ID.
    #[error("`{0}`: the scope (level 1) must be `local`, `*` or a robot ID")]
    BadScope(String),
    /// Level 2 is not `var` or `talk`.
    #[error("`{0}`: the kind (level 2) must be `var` or `talk`")]
    BadKind(String),
    /// An empty level or a character outside `[A-Za-z0-9_-]`.
    #[error("`{0}`: levels are non-empty and use only letters, digits, `_` and `-`")]
    BadLevel(String),
}

/// A parsed symbol: scope, kind and the rest of the name.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Symbol {
    scope: Scope,
    kind: Kind,
    name: String,
}

fn level_ok(level: &str) -> bool {
    !level.is_empty() && level.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

impl Symbol {
    /// Parses `text` (see the module doc).
    pub fn parse(text: &str) -> Result<Symbol, SymbolError> {
        if text.len() > MAX_SYMBOL_LEN {
            return Err(SymbolError::TooLong(text.len()));
        }
        let shown = || text.to_string();
        let mut levels = text.splitn(3, '.');
        let (Some(scope), Some(kind), Some(name)) = (levels.next(), levels.next(), levels.next())
        else {
            return Err(SymbolError::TooShort(shown()));
        };
        let scope = match scope {
            "local" => Scope::Local,
            "*" => Scope::All,
            // Robot IDs in their one spelling: no sign, no leading zero.
            n if !n.is_empty()
                && n.bytes().all(|b| b.is_ascii_digit())
                && (n == "0" || !n.starts_with('0')) =>
            {
                Scope::Robot(n.parse().map_err(|_| SymbolError::BadScope(shown()))?)
            }
            _ => return Err(SymbolError::BadScope(shown())),
        };
        let kind = match kind {
            "var" => Kind::Var,
            "talk" => Kind::Talk,
            _ => return Err(SymbolError::BadKind(shown())),
        };
        if !name.split('.').all(level_ok) {
            return Err(SymbolError::BadLevel(shown()));
        }
        Ok(Symbol { scope, kind, name: name.to_string() })
    }

    /// Level 1.
    pub fn scope(&self) -> Scope {
        self.scope
    }

    /// Level 2.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// Levels 3 and on (`machine.config.def.near-ball`).
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl fmt::Display for Symbol {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}.{}.{}", self.scope, self.kind, self.name)
    }
}

impl std::str::FromStr for Symbol {
    type Err = SymbolError;
    fn from_str(s: &str) -> Result<Self, SymbolError> {
        Symbol::parse(s)
    }
}

/// Which symbols a watch covers: one symbol, or every symbol under a prefix (`local.var.*`,
/// `*.*`, `2.var.machine.*`).
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Pattern {
    text: String,
    prefix: bool,
}

impl Pattern {
    /// Parses a pattern: a symbol, or one to three levels followed by `.*`.
    pub fn parse(text: &str) -> Result<Pattern, SymbolError> {
        if let Some(prefix) = text.strip_suffix(".*") {
            if prefix.len() > MAX_SYMBOL_LEN {
                return Err(SymbolError::TooLong(text.len()));
            }
            // Check the prefix's levels as a symbol would have them.
            let probe = match prefix.split('.').count() {
                1 => format!("{prefix}.var.x"),
                2 => format!("{prefix}.x"),
                _ => prefix.to_string(),
            };
            Symbol::parse(&probe).map_err(|e| match e {
                SymbolError::BadScope(_) => SymbolError::BadScope(text.to_string()),
                SymbolError::BadKind(_) => SymbolError::BadKind(text.to_string()),
                _ => SymbolError::BadLevel(text.to_string()),
            })?;
            return Ok(Pattern { text: format!("{prefix}."), prefix: true });
        }
        Symbol::parse(text)?;
        Ok(Pattern { text: text.to_string(), prefix: false })
    }

    /// Whether `symbol` (its text) is covered.
    pub fn matches(&self, symbol: &str) -> bool {
        if self.prefix {
            symbol.starts_with(&self.text)
        } else {
            symbol == self.text
        }
    }
}

impl fmt::Display for Pattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.prefix {
            write!(f, "{}*", self.text)
        } else {
            f.write_str(&self.text)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_seeds_example_and_the_three_scopes() {
        let s = Symbol::parse("local.var.machine.config.def.near-ball").unwrap();
        assert_eq!(
            (s.scope(), s.kind(), s.name()),
            (Scope::Local, Kind::Var, "machine.config.def.near-ball")
        );
        assert_eq!(s.to_string(), "local.var.machine.config.def.near-ball");
        assert_eq!(Symbol::parse("*.var.team.cost").unwrap().scope(), Scope::All);
        let n = Symbol::parse("3.talk.coord.offers").unwrap();
        assert_eq!((n.scope(), n.kind()), (Scope::Robot(3), Kind::Talk));
        assert!(n.scope().is_shared() && !Scope::Local.is_shared());
    }

    #[test]
    fn malformed_symbols_say_what_is_wrong() {
        assert!(matches!(Symbol::parse("local.var"), Err(SymbolError::TooShort(_))));
        assert!(matches!(Symbol::parse("team.var.x"), Err(SymbolError::BadScope(_))));
        assert!(matches!(Symbol::parse("-1.var.x"), Err(SymbolError::BadScope(_))));
        assert!(matches!(Symbol::parse("07.var.x"), Err(SymbolError::BadScope(_))));
        assert!(matches!(Symbol::parse("99999999999.var.x"), Err(SymbolError::BadScope(_))));
        assert!(matches!(Symbol::parse("local.val.x"), Err(SymbolError::BadKind(_))));
        assert!(matches!(Symbol::parse("local.var.a..b"), Err(SymbolError::BadLevel(_))));
        assert!(matches!(Symbol::parse("local.var.a b"), Err(SymbolError::BadLevel(_))));
        assert!(matches!(Symbol::parse("local.var.é"), Err(SymbolError::BadLevel(_))));
        let long = format!("local.var.{}", "x".repeat(MAX_SYMBOL_LEN));
        assert!(matches!(Symbol::parse(&long), Err(SymbolError::TooLong(_))));
        let e = Symbol::parse("local.val.x").unwrap_err().to_string();
        assert!(e.contains("`local.val.x`") && e.contains("var"), "{e}");
    }

    #[test]
    fn patterns_cover_one_symbol_or_a_subtree() {
        let all = Pattern::parse("local.*").unwrap();
        assert!(all.matches("local.var.x") && all.matches("local.talk.y"));
        assert!(!all.matches("localx.var.x") && !all.matches("*.var.x"));
        let vars = Pattern::parse("*.var.*").unwrap();
        assert!(vars.matches("*.var.team.cost") && !vars.matches("*.talk.a"));
        let one = Pattern::parse("2.var.machine.role").unwrap();
        assert!(one.matches("2.var.machine.role") && !one.matches("2.var.machine.role2"));
        assert_eq!(vars.to_string(), "*.var.*");
        assert_eq!(Pattern::parse("2.var.machine.*").unwrap().to_string(), "2.var.machine.*");
        for bad in ["*", ".*", "x.*", "local.foo.*", "local.var..*", "local.var"] {
            assert!(Pattern::parse(bad).is_err(), "{bad}");
        }
    }

    proptest! {
        #[test]
        fn random_text_never_panics_and_parsed_symbols_print_back(text in "\\PC{0,80}") {
            if let Ok(s) = Symbol::parse(&text) {
                prop_assert_eq!(s.to_string(), text.clone());
            }
            let _ = Pattern::parse(&text);
        }

        #[test]
        fn well_formed_symbols_parse(scope in "(local|\\*|[0-9]{1,3})", kind in "(var|talk)",
                                     name in "[a-z][a-z0-9_-]{0,8}(\\.[a-z0-9_-]{1,8}){0,3}") {
            let scope = if scope.len() > 1 { scope.trim_start_matches('0').to_string() } else { scope };
            let scope = if scope.is_empty() { "0".to_string() } else { scope };
            let text = format!("{scope}.{kind}.{name}");
            let s = Symbol::parse(&text).unwrap();
            prop_assert_eq!(s.name(), name.as_str());
        }
    }
}
