//! The tokenizer shared by every Mr. BRIAN file: parentheses, `=`, `;`, names and numbers,
//! with `#` comments to the end of the line and 1-based line/column positions.

use crate::error::BrianError;
use std::path::Path;

/// Where a token starts: 1-based line and column (in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Span {
    /// Line, from 1.
    pub line: usize,
    /// Column, from 1, in characters.
    pub column: usize,
}

/// A token of a Mr. BRIAN file.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// `(`
    Open,
    /// `)`
    Close,
    /// `=`
    Eq,
    /// `;`
    Semi,
    /// A number: `[-+]?digits(.digits)?`.
    Num(f64),
    /// Any other run of characters that are not blanks, parentheses, `=`, `;` or `#`.
    Word(String),
}

impl Tok {
    /// How the token reads in an error message.
    pub fn describe(&self) -> String {
        match self {
            Tok::Open => "`(`".into(),
            Tok::Close => "`)`".into(),
            Tok::Eq => "`=`".into(),
            Tok::Semi => "`;`".into(),
            Tok::Num(n) => format!("the number `{n}`"),
            Tok::Word(w) => format!("`{w}`"),
        }
    }
}

fn is_number(w: &str) -> bool {
    let digits = w.strip_prefix(['-', '+']).unwrap_or(w);
    let (int, frac) = match digits.split_once('.') {
        Some((i, f)) => (i, Some(f)),
        None => (digits, None),
    };
    !int.is_empty()
        && int.bytes().all(|b| b.is_ascii_digit())
        && frac.is_none_or(|f| !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()))
}

/// Splits `text` into tokens with their positions. Fails on a number too large for an `f64`
/// (it would become infinite).
pub fn tokenize(text: &str, file: &Path) -> Result<Vec<(Tok, Span)>, BrianError> {
    let mut out = Vec::new();
    for (li, line) in text.lines().enumerate() {
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            let span = Span { line: li + 1, column: i + 1 };
            match c {
                '#' => break,
                c if c.is_whitespace() || c == '\u{feff}' => i += 1,
                '(' | ')' | '=' | ';' => {
                    out.push((
                        match c {
                            '(' => Tok::Open,
                            ')' => Tok::Close,
                            '=' => Tok::Eq,
                            _ => Tok::Semi,
                        },
                        span,
                    ));
                    i += 1;
                }
                _ => {
                    let start = i;
                    while i < chars.len()
                        && !chars[i].is_whitespace()
                        && !matches!(chars[i], '(' | ')' | '=' | ';' | '#')
                    {
                        i += 1;
                    }
                    let word: String = chars[start..i].iter().collect();
                    if is_number(&word) {
                        let n = word.parse::<f64>().ok().filter(|n| n.is_finite()).ok_or_else(
                            || {
                                BrianError::at(
                                    file,
                                    span,
                                    format!("`{word}` is too large for a number"),
                                )
                            },
                        )?;
                        out.push((Tok::Num(n), span));
                    } else {
                        out.push((Tok::Word(word), span));
                    }
                }
            }
        }
    }
    Ok(out)
}

/// A cursor over tokens that reports what it expected, with the position.
pub struct Cursor<'a> {
    toks: &'a [(Tok, Span)],
    pos: usize,
    file: &'a Path,
    end: Span,
}

impl<'a> Cursor<'a> {
    /// A cursor at the first token; `text` gives the end-of-file position.
    pub fn new(toks: &'a [(Tok, Span)], file: &'a Path, text: &str) -> Self {
        let lines = text.lines().count().max(1);
        let last = text.lines().last().map_or(0, |l| l.chars().count());
        Self { toks, pos: 0, file, end: Span { line: lines, column: last + 1 } }
    }

    /// Whether every token was read.
    pub fn at_end(&self) -> bool {
        self.pos >= self.toks.len()
    }

    /// The next token, without taking it.
    pub fn peek(&self) -> Option<&'a Tok> {
        self.toks.get(self.pos).map(|(t, _)| t)
    }

    /// The token `n` places after the next one (`peek_at(0)` is [`peek`](Self::peek)).
    pub fn peek_at(&self, n: usize) -> Option<&'a Tok> {
        self.toks.get(self.pos + n).map(|(t, _)| t)
    }

    /// Where the next token is (or the end of the file).
    pub fn span(&self) -> Span {
        self.toks.get(self.pos).map_or(self.end, |(_, s)| *s)
    }

    /// An error at the next token: "expected X, found Y".
    pub fn expected(&self, what: &str) -> BrianError {
        let found = self.peek().map_or_else(|| "end of file".to_string(), Tok::describe);
        BrianError::at(self.file, self.span(), format!("expected {what}, found {found}"))
    }

    /// Takes a specific punctuation token.
    pub fn punct(&mut self, tok: Tok, what: &str) -> Result<Span, BrianError> {
        if self.peek() == Some(&tok) {
            let s = self.span();
            self.pos += 1;
            Ok(s)
        } else {
            Err(self.expected(what))
        }
    }

    /// Takes a name.
    pub fn word(&mut self, what: &str) -> Result<(String, Span), BrianError> {
        match self.peek() {
            Some(Tok::Word(w)) => {
                let s = self.span();
                self.pos += 1;
                Ok((w.clone(), s))
            }
            _ => Err(self.expected(what)),
        }
    }

    /// Takes a number.
    pub fn number(&mut self, what: &str) -> Result<f64, BrianError> {
        match self.peek() {
            Some(Tok::Num(n)) => {
                self.pos += 1;
                Ok(*n)
            }
            _ => Err(self.expected(what)),
        }
    }

    /// The file name, for errors.
    pub fn file(&self) -> &'a Path {
        self.file
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_positions_and_comments() {
        let t = tokenize("(Distance # the shape\n (TRA (NEAREST 0 0.1 -40 +60)))", Path::new("f"))
            .unwrap();
        assert_eq!(t[0], (Tok::Open, Span { line: 1, column: 1 }));
        assert_eq!(t[1], (Tok::Word("Distance".into()), Span { line: 1, column: 2 }));
        assert_eq!(t[2], (Tok::Open, Span { line: 2, column: 2 }));
        assert_eq!(t[3].0, Tok::Word("TRA".into()));
        assert_eq!(t[6].0, Tok::Num(0.0));
        assert_eq!(t[7].0, Tok::Num(0.1));
        assert_eq!(t[8].0, Tok::Num(-40.0));
        assert_eq!(t[9].0, Tok::Num(60.0));
        assert_eq!(t.len(), 13);
    }

    #[test]
    fn a_number_too_large_is_an_error_with_its_place() {
        let text = format!("(S (SNG (A 1{})))", "0".repeat(400));
        let e = tokenize(&text, Path::new("f")).unwrap_err().to_string();
        assert!(e.starts_with("error in file f at line 1: `1000") && e.ends_with("f:1:12"), "{e}");
    }

    #[test]
    fn numbers_follow_the_grammar_exactly() {
        for ok in ["0", "12", "-3", "+4", "1.5", "-0.25"] {
            assert!(is_number(ok), "{ok}");
        }
        for not in ["1.", ".5", "1e3", "--1", "-", "1.2.3", "inf", "NaN", "0x1"] {
            assert!(!is_number(not), "{not}");
        }
    }
}
