//! Where a token starts in a Mr. BRIAN file. Both the tokenizer (`lexer`) and the error type
//! (`error`) use it, so it lives apart from either: the tokenizer builds errors, the errors
//! know nothing of tokens.

/// Where a token starts: 1-based line and column (in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Span {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
}
