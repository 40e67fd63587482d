//! The error of reading a configuration file, shared by MRT's TOML files (the simulator's world,
//! a robot's file): the file and, for a syntax error, the line and column, so that a user can go
//! straight to the place.

/// What went wrong reading a configuration file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// The file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The file is malformed or names an unknown field.
    #[error("{file}:{line}:{column}: {message}")]
    Parse {
        /// The file.
        file: String,
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A value is out of its range, or values do not fit together.
    #[error("{file}: {message}")]
    Invalid {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
}

impl FileError {
    /// Reads a configuration file for a parser (at most [`crate::MAX_CONFIG_BYTES`], a
    /// regular file, UTF-8, a byte-order mark left out: [`crate::read_text`]): its text and
    /// its name for error messages, or the [`FileError::Io`] that names it.
    pub fn read(path: &std::path::Path) -> Result<(String, String), FileError> {
        let file = path.display().to_string();
        match crate::read_text(path, crate::MAX_CONFIG_BYTES) {
            Ok(text) => Ok((text, file)),
            Err(source) => Err(FileError::Io { file, source }),
        }
    }

    /// A syntax error at byte `offset` of `text` (the start of the file when unknown).
    pub fn parse(file: &str, text: &str, offset: Option<usize>, message: &str) -> FileError {
        let (line, column) = line_column(text, offset.unwrap_or(0));
        FileError::Parse {
            file: file.to_string(),
            line,
            column,
            message: message.trim().to_string(),
        }
    }
}

/// Line and column (both from 1, the column in characters) of byte `offset` in `text`; an
/// offset past the end or inside a character counts as the end of the text.
///
/// ```
/// assert_eq!(mrt_core::line_column("ab\ncdé\nf", 7), (2, 4));
/// assert_eq!(mrt_core::line_column("ab", 99), (1, 3));
/// ```
pub fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_place() {
        let e = FileError::parse("a.toml", "x = 1\ny = ?\n", Some(10), " bad value\n");
        assert_eq!(e.to_string(), "a.toml:2:5: bad value");
        // Inside a multi-byte character: no panic, the end of the text.
        assert_eq!(line_column("é", 1), (1, 2));
        let missing = std::path::Path::new("/nonexistent/mrt/x.toml");
        assert!(FileError::read(missing)
            .unwrap_err()
            .to_string()
            .starts_with("/nonexistent/mrt/x.toml: "));
    }
}
