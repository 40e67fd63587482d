//! Initial values from `config.dat` and `config-<id>.dat` (ISocRob-2000 report §3.1: "a set of
//! blackboard variables initial values (configuration parameters) from the files `config.dat`
//! and `config-n.dat`, by this order, where `n` is the robot's ID").
//!
//! # Format
//!
//! One binding per line: the symbol, its type and its value (the text form of
//! [`crate::value`]), separated by spaces or tabs. Blank lines and lines starting with `#`
//! are ignored, and so is a `#` comment after the value.
//!
//! ```text
//! # the defender's idea of a near ball, m
//! local.var.machine.config.def.near-ball   Float   0.8
//! local.var.machine.config.role            String  "defender"   # until the team decides
//! local.var.kicker.config.enabled          Bool    true
//! *.var.team.config.players                Int     4
//! ```
//!
//! A later binding of the same symbol replaces the earlier one (so `config-2.dat` overrides
//! `config.dat` for robot 2), and must keep its type. Only `var` symbols can be configured.
//! Any error stops the load and names the file, line and column.

use crate::board::{BbError, Blackboard};
use crate::symbol::{Kind, Symbol};
use crate::value::{Value, ValueType};
use std::path::{Path, PathBuf};

/// A configuration file that cannot be loaded.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A line is malformed.
    #[error("{file}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        file: PathBuf,
        /// Line, from 1.
        line: usize,
        /// Column (characters), from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
}

/// One parsed binding.
#[derive(Clone, Debug, PartialEq)]
pub struct Binding {
    /// The symbol.
    pub symbol: Symbol,
    /// Its initial value.
    pub value: Value,
    /// Line, from 1.
    pub line: usize,
}

/// Parses the text of a configuration file (`file` names it in errors).
pub fn parse(text: &str, file: &Path) -> Result<Vec<Binding>, ConfigError> {
    let mut out = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let err = |at: &str, message: String| ConfigError::Parse {
            file: file.to_path_buf(),
            line: n + 1,
            column: raw[..raw.len() - at.len()].chars().count() + 1,
            message,
        };
        let line = raw.trim_start();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let word = |s: &str| s.find(char::is_whitespace).unwrap_or(s.len());
        let (sym, rest) = line.split_at(word(line));
        let symbol = Symbol::parse(sym).map_err(|e| err(line, e.to_string()))?;
        if symbol.kind() != Kind::Var {
            return Err(err(line, format!("`{sym}`: only `var` symbols have initial values")));
        }
        let rest = rest.trim_start();
        let (ty, after) = rest.split_at(word(rest));
        if ty.is_empty() {
            return Err(err(rest, format!("`{sym}` needs a type and a value")));
        }
        let Some(ty_) = ValueType::parse(ty) else {
            return Err(err(rest, format!("unknown type `{ty}` (Int, Float, Bool or String)")));
        };
        let literal = after.trim_start();
        let (value, tail) =
            Value::parse_literal(ty_, literal).map_err(|e| err(literal, e.to_string()))?;
        let tail_t = tail.trim_start();
        if !tail_t.is_empty() && !tail_t.starts_with('#') {
            return Err(err(
                tail_t,
                format!(
                    "unexpected `{}` after the value",
                    tail_t.chars().take(20).collect::<String>()
                ),
            ));
        }
        out.push(Binding { symbol, value, line: n + 1 });
    }
    Ok(out)
}

/// Reads `file` and binds its values on `bb`. Returns how many bindings it had.
pub fn load_file(bb: &Blackboard, file: &Path) -> Result<usize, ConfigError> {
    let text = mrt_core::read_text(file, mrt_core::MAX_CONFIG_BYTES)
        .map_err(|source| ConfigError::Io { file: file.to_path_buf(), source })?;
    load_text(bb, &text, file)
}

/// Binds the values of a configuration file's `text` on `bb` (`file` names it in errors: a
/// file compiled into the program needs no copy on disk). Returns how many bindings it had.
pub fn load_text(bb: &Blackboard, text: &str, file: &Path) -> Result<usize, ConfigError> {
    let bindings = parse(text, file)?;
    for b in &bindings {
        bb.set(&b.symbol.to_string(), b.value.clone()).map_err(|e| ConfigError::Parse {
            file: file.to_path_buf(),
            line: b.line,
            column: 1,
            message: match e {
                BbError::Type { stored, wanted, .. } => {
                    format!("`{}` was a {stored} before, not a {wanted}", b.symbol)
                }
                other => other.to_string(),
            },
        })?;
    }
    Ok(bindings.len())
}

/// Loads `dir/config.dat`, then `dir/config-<robot>.dat`, the ones that exist (anything of
/// that name that is no regular file, a link to a device, is an error). Returns the files
/// read.
pub fn load_dir(bb: &Blackboard, dir: &Path) -> Result<Vec<PathBuf>, ConfigError> {
    let mut read = Vec::new();
    for name in ["config.dat".to_string(), format!("config-{}.dat", bb.robot())] {
        let file = dir.join(name);
        if file.exists() {
            load_file(bb, &file)?;
            read.push(file);
        }
    }
    Ok(read)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_core::SimClock;
    use proptest::prelude::*;
    use std::sync::Arc;

    fn bb(robot: u32) -> Blackboard {
        Blackboard::new(robot, Arc::new(SimClock::new()))
    }

    #[test]
    fn the_documented_example_loads() {
        let text = "# the defender's idea of a near ball, m\n\
            local.var.machine.config.def.near-ball   Float   0.8\n\
            local.var.machine.config.role            String  \"defender\"   # until the team decides\n\
            \n\
            local.var.kicker.config.enabled\tBool\ttrue\n\
            *.var.team.config.players                Int     4\n";
        let b = parse(text, Path::new("config.dat")).unwrap();
        assert_eq!(b.len(), 4);
        assert_eq!((b[0].value.clone(), b[0].line), (Value::Float(0.8), 2));
        assert_eq!(b[1].value, Value::String("defender".into()));
        assert_eq!(b[2].value, Value::Bool(true));
        assert_eq!(b[3].symbol.to_string(), "*.var.team.config.players");
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = |text: &str| parse(text, Path::new("c.dat")).unwrap_err().to_string();
        assert_eq!(
            e("\nlocal.vr.x Int 1"),
            "c.dat:2:1: `local.vr.x`: the kind (level 2) must be `var` or `talk`"
        );
        assert_eq!(
            e("local.var.x Integer 1"),
            "c.dat:1:13: unknown type `Integer` (Int, Float, Bool or String)"
        );
        assert_eq!(e("local.var.x  Int  1.5"), "c.dat:1:19: `1.5` is not a Int");
        assert_eq!(e("local.var.x Int 1 2"), "c.dat:1:19: unexpected `2` after the value");
        assert_eq!(e("local.var.x"), "c.dat:1:12: `local.var.x` needs a type and a value");
        assert_eq!(e("local.var.x Bool"), "c.dat:1:17: a Bool value is missing");
        assert_eq!(
            e("local.talk.q Int 1"),
            "c.dat:1:1: `local.talk.q`: only `var` symbols have initial values"
        );
        assert!(e("local.var.s String \"open").contains("c.dat:1:20: "));
        assert_eq!(e("local.var.s String \"a\"b"), "c.dat:1:23: unexpected `b` after the value");
    }

    #[test]
    fn the_robots_own_file_overrides_the_common_one() {
        let dir = std::env::temp_dir().join(format!("mrt-bb-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("config.dat"), "local.var.a Int 1\nlocal.var.b Int 2\n").unwrap();
        std::fs::write(dir.join("config-2.dat"), "local.var.b Int 20\n").unwrap();
        let two = bb(2);
        assert_eq!(load_dir(&two, &dir).unwrap().len(), 2);
        assert_eq!(
            (two.get::<i64>("local.var.a").unwrap(), two.get::<i64>("local.var.b").unwrap()),
            (1, 20)
        );
        let three = bb(3);
        assert_eq!(load_dir(&three, &dir).unwrap().len(), 1);
        assert_eq!(three.get::<i64>("local.var.b").unwrap(), 2);
        // A robot file that changes a type: file and line.
        std::fs::write(dir.join("config-4.dat"), "\nlocal.var.a Float 1.0\n").unwrap();
        let e = load_dir(&bb(4), &dir).unwrap_err().to_string();
        assert!(
            e.ends_with("config-4.dat:2:1: `local.var.a` was a Int before, not a Float"),
            "{e}"
        );
        let missing = load_file(&bb(1), &dir.join("nothere.dat")).unwrap_err().to_string();
        assert!(missing.contains("nothere.dat"), "{missing}");
        // A byte-order mark before the first line is no part of it.
        std::fs::write(dir.join("config-5.dat"), "\u{feff}local.var.c Int 7\n").unwrap();
        let five = bb(5);
        load_dir(&five, &dir).unwrap();
        assert_eq!(five.get::<i64>("local.var.c").unwrap(), 7);
        // A config.dat that is a link to a device is refused, not taken as absent.
        #[cfg(unix)]
        if Path::new("/dev/zero").exists() {
            std::os::unix::fs::symlink("/dev/zero", dir.join("config-6.dat")).unwrap();
            let e = load_dir(&bb(6), &dir).unwrap_err().to_string();
            assert!(e.contains("config-6.dat") && e.contains("not a regular file"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    proptest! {
        #[test]
        fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
            let text = String::from_utf8_lossy(&bytes);
            let _ = parse(&text, Path::new("fuzz.dat"));
        }

        #[test]
        fn random_lines_never_panic(text in "(local|\\*|2)\\.(var|talk)\\.[a-z.]{0,6}[ \t]+\\PC{0,30}") {
            let _ = parse(&text, Path::new("fuzz.dat"));
        }
    }
}
