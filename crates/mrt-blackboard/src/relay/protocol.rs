//! The relay's line protocol: requests, refusals, tokens.

use super::*;

/// Whether `token` can be a shared token: 1 to [`MAX_TOKEN_LEN`] bytes, no whitespace, no
/// control character (`AUTH` takes one word, so a token with a space could never be sent).
/// `Err` says why not.
pub fn check_token(token: &str) -> Result<(), &'static str> {
    if token.is_empty() {
        Err("it is empty")
    } else if token.len() > MAX_TOKEN_LEN {
        Err("it is longer than 256 bytes")
    } else if token.chars().any(|c| c.is_whitespace() || c.is_control()) {
        Err("it has a space or a control character (AUTH takes one word)")
    } else {
        Ok(())
    }
}

/// Compares without stopping at the first difference, so that the time an answer takes does
/// not tell how much of a guess was right.
pub(super) fn same_token(given: &str, token: &str) -> bool {
    let (a, b) = (given.as_bytes(), token.as_bytes());
    let mut diff = u8::from(a.len() != b.len() || a.is_empty());
    for (i, x) in b.iter().enumerate() {
        diff |= x ^ a.get(i).copied().unwrap_or(0);
    }
    diff == 0
}

/// One request, as [`parse_request`] reads it.
#[derive(Clone, Debug, PartialEq)]
pub enum Request {
    /// `AUTH <token>`.
    Auth(String),
    /// `REFR <milliseconds>`: the period of watch pushes.
    Refr(u64),
    /// `ADDW <pattern>`.
    Addw(Pattern),
    /// `DELW <pattern>`.
    Delw(Pattern),
    /// `CLRW`.
    Clrw,
    /// `LSTW`.
    Lstw,
    /// `SETV <symbol> <Type> <value>`.
    Setv(String, Value),
    /// `GETV <symbol>`.
    Getv(String),
    /// `LSTV [<pattern>]` (an MRT addition: the symbols on the blackboard; `*` for all).
    Lstv(Option<Pattern>),
    /// `LSTV <pattern> <after>`: one page, the symbols after `<after>` (`-`: from the first).
    LstvPage(Option<Pattern>, Option<String>),
    /// `QUIT`.
    Quit,
}

/// A request that cannot be served: the code and reason of its `ERR` reply.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal {
    /// 400 bad request, 401 not authorised, 404 unknown, 408 too slow or idle too long, 409
    /// conflicting type or kind, 413 too large, 429 too many (watches, wrong tokens), 503 too
    /// many clients, 507 the blackboard is full.
    pub code: u16,
    /// Why, one line.
    pub reason: String,
}

impl Refusal {
    pub(super) fn new(code: u16, reason: impl Into<String>) -> Refusal {
        let reason: String = reason.into();
        Refusal { code, reason: reason.replace(['\n', '\r'], " ") }
    }

    /// The reply line, without the newline.
    pub fn line(&self) -> String {
        format!("ERR {} {}", self.code, self.reason)
    }
}

/// Shortest and longest refresh period a `REFR` may ask for, ms (the relay then applies
/// [`RelayConfig::min_refresh`]).
pub const REFRESH_RANGE: (u64, u64) = (10, 60_000);

/// Parses one request line (without its newline; a trailing `\r` is ignored). `Ok(None)` for
/// a blank line, which the relay ignores.
pub fn parse_request(line: &str) -> Result<Option<Request>, Refusal> {
    let line = line.strip_suffix('\r').unwrap_or(line).trim();
    if line.is_empty() {
        return Ok(None);
    }
    let (word, rest) = line.split_once(char::is_whitespace).unwrap_or((line, ""));
    let rest = rest.trim();
    let pattern = |text: &str| Pattern::parse(text).map_err(|e| Refusal::new(400, e.to_string()));
    let one_arg = |name: &str| {
        if rest.is_empty() || rest.contains(char::is_whitespace) {
            Err(Refusal::new(400, format!("{name} takes one argument")))
        } else {
            Ok(rest)
        }
    };
    let no_arg = |name: &str, r: Request| {
        if rest.is_empty() {
            Ok(r)
        } else {
            Err(Refusal::new(400, format!("{name} takes no argument")))
        }
    };
    let request = match word.to_ascii_uppercase().as_str() {
        "AUTH" => Request::Auth(one_arg("AUTH")?.to_string()),
        "REFR" => {
            let ms: u64 = one_arg("REFR")?
                .parse()
                .map_err(|_| Refusal::new(400, "REFR takes a period in milliseconds"))?;
            if !(REFRESH_RANGE.0..=REFRESH_RANGE.1).contains(&ms) {
                return Err(Refusal::new(400, "the refresh period is 10 to 60000 ms"));
            }
            Request::Refr(ms)
        }
        "ADDW" => Request::Addw(pattern(one_arg("ADDW")?)?),
        "DELW" => Request::Delw(pattern(one_arg("DELW")?)?),
        "CLRW" => no_arg("CLRW", Request::Clrw)?,
        "LSTW" => no_arg("LSTW", Request::Lstw)?,
        "QUIT" => no_arg("QUIT", Request::Quit)?,
        "GETV" => {
            let symbol = one_arg("GETV")?;
            crate::Symbol::parse(symbol).map_err(|e| Refusal::new(400, e.to_string()))?;
            Request::Getv(symbol.to_string())
        }
        "LSTV" => {
            let words: Vec<&str> = rest.split_whitespace().collect();
            let any = |w: &str| if w == "*" { Ok(None) } else { pattern(w).map(Some) };
            match words.as_slice() {
                [] => Request::Lstv(None),
                [p] => Request::Lstv(any(p)?),
                [p, "-"] => Request::LstvPage(any(p)?, None),
                [p, after] => Request::LstvPage(any(p)?, Some((*after).to_string())),
                _ => return Err(Refusal::new(400, "LSTV takes a pattern and a symbol at most")),
            }
        }
        "SETV" => {
            let (symbol, value) = rest
                .split_once(char::is_whitespace)
                .ok_or_else(|| Refusal::new(400, "SETV takes a symbol, a type and a value"))?;
            crate::Symbol::parse(symbol).map_err(|e| Refusal::new(400, e.to_string()))?;
            let value = Value::parse_typed(value).map_err(|e| Refusal::new(400, e.to_string()))?;
            Request::Setv(symbol.to_string(), value)
        }
        _ => {
            let shown: String = word.chars().take(20).collect();
            return Err(Refusal::new(400, format!("unknown command `{shown}`")));
        }
    };
    Ok(Some(request))
}
