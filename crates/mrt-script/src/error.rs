//! What can go wrong with a behavior script: [`ScriptError`]. Every text a script chooses
//! (an error message, a traceback, a `print` line) is clipped to [`MAX_TEXT`] bytes.

/// Longest text (bytes) of one `print` line, an error message or a traceback; longer ones
/// are clipped with a note of how much was cut.
pub const MAX_TEXT: usize = 1024;

/// What went wrong with a script. The robot keeps its last good behavior in every case.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScriptError {
    /// The script does not compile.
    #[error("{file}:{line}: {message}")]
    Syntax {
        /// The script.
        file: String,
        /// Line of the error (0 when Lua did not say).
        line: usize,
        /// Lua's explanation.
        message: String,
    },
    /// The script raised an error while running (including a chaos API called with wrong
    /// arguments).
    #[error("{file}:{line}: runtime error: {message}")]
    Runtime {
        /// The script where it happened (the innermost script frame; a behavior `use`d by
        /// another names its own file).
        file: String,
        /// The line (0 when Lua did not say).
        line: usize,
        /// Lua's explanation, with the API function that refused its arguments.
        message: String,
        /// Lua's stack traceback.
        traceback: String,
    },
    /// The call ran past its instruction budget (an endless loop?).
    #[error("{file}:{line}: aborted after {budget} instructions (instruction budget exceeded)")]
    Budget {
        /// The script that was running when the budget ran out (a behavior `use`d by another
        /// names its own file).
        file: String,
        /// The line it was running (0 when unknown).
        line: usize,
        /// The budget.
        budget: u64,
    },
    /// The watchdog stopped the behavior: its cycle did not end within the deadline (a C
    /// function or an API call that blocks, or anything else the budget does not see).
    #[error("{file}: stopped by the watchdog: the cycle did not end within {deadline_ms} ms")]
    Watchdog {
        /// The script (or the behavior Member) that was running.
        file: String,
        /// The deadline.
        deadline_ms: u64,
    },
    /// The robot was stopped: its behaviors ran away (budget or memory) or failed this many
    /// cycles in a row. It stands still, running no Lua, until its behaviors restart from
    /// their files (the [`Watchdog`](crate::Watchdog)'s back-off) or a file is reloaded.
    #[error("{file}: stopped after {cycles} cycles in a row {why}; the robot stands still until its behaviors restart from their files")]
    Stopped {
        /// The HFSM file or the behavior at the top.
        file: String,
        /// Failing cycles in a row.
        cycles: u32,
        /// How they failed: `running away` or `with errors`.
        why: &'static str,
    },
    /// The Lua state ran out of its memory limit.
    #[error("{file}: aborted: memory limit of {limit} bytes exceeded")]
    Memory {
        /// The script.
        file: String,
        /// The limit.
        limit: usize,
    },
    /// The script compiled but what it defines is wrong (an HFSM with an unknown state, a
    /// meta-state containing itself...).
    #[error("{file}:{line}: {message}")]
    Invalid {
        /// The script.
        file: String,
        /// The line of the definition (0 when unknown).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The script file could not be read.
    #[error("{file}: {source}")]
    Io {
        /// The script.
        file: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// The Lua state could not be prepared.
    #[error("cannot prepare the Lua runtime: {0}")]
    Setup(String),
}

impl ScriptError {
    /// The line the error names, when it names one.
    pub fn line(&self) -> Option<usize> {
        match self {
            ScriptError::Syntax { line, .. }
            | ScriptError::Runtime { line, .. }
            | ScriptError::Budget { line, .. }
            | ScriptError::Invalid { line, .. } => Some(*line).filter(|&l| l > 0),
            _ => None,
        }
    }

    pub(crate) fn setup(e: mlua::Error) -> ScriptError {
        ScriptError::Setup(e.to_string())
    }

    /// A compile error: `Syntax` with Lua's line when it is one.
    pub(crate) fn syntax(file: &str, e: &mlua::Error) -> ScriptError {
        match e {
            mlua::Error::SyntaxError { message, .. } => {
                let (line, msg) = split_position(message);
                ScriptError::Syntax { file: file.into(), line, message: clip(&msg, MAX_TEXT) }
            }
            other => ScriptError::Setup(clip(&format!("{file}: {other}"), MAX_TEXT)),
        }
    }
}

/// Lua's `name:LINE: message` as the line (0 when there is none) and the message.
pub(crate) fn split_position(message: &str) -> (usize, String) {
    let mut parts = message.splitn(3, ':');
    let (_, line, rest) = (parts.next(), parts.next(), parts.next());
    match (line.and_then(|l| l.trim().parse().ok()), rest) {
        (Some(l), Some(r)) => (l, r.trim().to_string()),
        _ => (0, message.to_string()),
    }
}

/// `text` cut to at most `max` bytes (on a character boundary), saying how much was cut.
pub(crate) fn clip(text: &str, max: usize) -> String {
    if text.len() <= max {
        return text.to_string();
    }
    let mut end = max;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}… [{} more bytes]", &text[..end], text.len() - end)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clip_keeps_short_texts_and_cuts_long_ones_on_a_boundary() {
        assert_eq!(clip("short", 10), "short");
        let long = "é".repeat(10); // 20 bytes
        let c = clip(&long, 5);
        assert!(c.starts_with("éé…") && c.ends_with("[16 more bytes]"), "{c}");
    }

    #[test]
    fn split_position_reads_the_line_or_keeps_the_whole_message() {
        assert_eq!(split_position("x.lua:12: oops"), (12, "oops".to_string()));
        assert_eq!(split_position("no position"), (0, "no position".to_string()));
    }
}
