//! The tokenizer shared by every Mr. BRIAN file: parentheses, `=`, `;`, names and numbers,
//! with `#` comments to the end of the line and 1-based line/column positions.

use crate::error::BrianError;
pub use crate::span::Span;
use std::path::Path;

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

/// `bytes` as text, or an error at the line and column (1-based, in characters) of the first
/// byte that is not valid UTF-8, naming that byte.
pub fn utf8(bytes: Vec<u8>, file: &Path) -> Result<String, BrianError> {
    String::from_utf8(bytes).map_err(|e| {
        let err = e.utf8_error();
        let bytes = e.as_bytes();
        let good = bytes.get(..err.valid_up_to()).unwrap_or_default();
        // Everything before the bad byte is valid UTF-8: count lines and characters in it.
        let before = std::str::from_utf8(good).unwrap_or_default();
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        let what = match bytes.get(err.valid_up_to()) {
            Some(b) => format!("invalid UTF-8 (byte 0x{b:02X}): Mr. BRIAN files are UTF-8 text"),
            None => "invalid UTF-8: Mr. BRIAN files are UTF-8 text".to_string(),
        };
        BrianError::at(file, Span { line, column }, what)
    })
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

    /// Invalid UTF-8 was reported without its place.
    #[test]
    fn invalid_utf8_names_the_line_and_column_of_the_first_bad_byte() {
        let f = Path::new("f");
        let e = utf8(b"(A\n  (B \xC3\xA9\xFF x)".to_vec(), f).unwrap_err().to_string();
        // Line 2: two blanks, `(B `, `é` (one character, two bytes), then 0xFF: column 7.
        assert_eq!(
            e,
            "error in file f at line 2: invalid UTF-8 (byte 0xFF): Mr. BRIAN files are UTF-8 text\n  --> f:2:7"
        );
        let e = utf8(b"\xFE".to_vec(), f).unwrap_err().to_string();
        assert!(e.ends_with("f:1:1") && e.contains("0xFE"), "{e}");
        // A sequence cut short at the end of the file.
        let e = utf8(b"ab\n\xE2\x82".to_vec(), f).unwrap_err().to_string();
        assert!(e.ends_with("f:2:1") && e.contains("0xE2"), "{e}");
        assert_eq!(utf8("ok é".as_bytes().to_vec(), f).unwrap(), "ok é");
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
