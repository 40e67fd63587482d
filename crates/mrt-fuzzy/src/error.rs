//! The error type of `mrt-fuzzy`.

use crate::span::Span;
use std::path::{Path, PathBuf};

/// What can go wrong when loading Mr. BRIAN files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BrianError {
    /// A syntax or meaning error at a place in a file. Displayed as the manual's checker does
    /// (§10.4.7), `error in file <path> at line <n>: <what was expected>`, then a second line
    /// `  --> <path>:<line>:<column>` that editors and terminals can jump to.
    #[error("error in file {} at line {line}: {message}\n  --> {}:{line}:{column}", file.display(), file.display())]
    At {
        /// The file.
        file: PathBuf,
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// What was expected, or what is wrong.
        message: String,
    },
    /// [`crate::brian::Brian::register_behavior`] was given a name that no behavior of
    /// `behavior.txt` is written as (`code:<name>`).
    #[error("no behavior of behavior.txt is `code:{name}`: list one as `(level <n> <behavior> code:{name})`")]
    NoCodeBehavior {
        /// The name given.
        name: String,
    },
    /// A file could not be read.
    #[error("error in file {}: {source}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
}

impl BrianError {
    /// An error at `span` of `file`.
    pub fn at(file: &Path, span: Span, message: impl Into<String>) -> BrianError {
        BrianError::At {
            file: file.to_path_buf(),
            line: span.line,
            column: span.column,
            message: message.into(),
        }
    }
}
