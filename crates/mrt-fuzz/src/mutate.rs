//! Structure-aware mutation of text and binary inputs.
//!
//! A [`Mutator`] knows the target's dictionary (the words of its seed files and the grammar's
//! keywords) and applies one to [`MAX_STACK`] stacked mutations to a seed: bit and byte
//! flips, little-endian integers set to extremes, insertion, deletion and duplication of
//! ranges, splices with another seed, numbers replaced by extremes (0, -1, 1e308, NaN, 2^63,
//! huge counts), words replaced by dictionary words, truncation, invalid UTF-8, repeated,
//! deleted and swapped lines, and deep nesting of the brackets the formats use. Inputs never
//! grow past the mutator's size limit.

use rand::Rng;
use std::collections::BTreeSet;

/// Most mutations stacked on one input.
pub const MAX_STACK: u32 = 6;

/// Numbers that break parsers: zeros and signs, the edges of the integer types, floats that
/// overflow, underflow or are not numbers, huge counts.
pub const EXTREME_NUMBERS: &[&str] = &[
    "0",
    "-0",
    "-1",
    "1",
    "0.0",
    "1e308",
    "-1e308",
    "1e309",
    "1.7976931348623157e308",
    "5e-324",
    "1e-320",
    "NaN",
    "nan",
    "-nan",
    "inf",
    "-inf",
    "Infinity",
    "127",
    "128",
    "255",
    "256",
    "32767",
    "65535",
    "65536",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967295",
    "4294967296",
    "9007199254740993",
    "9223372036854775807",
    "9223372036854775808",
    "-9223372036854775808",
    "-9223372036854775809",
    "18446744073709551615",
    "18446744073709551616",
    "340282366920938463463374607431768211456",
    "1000000000",
    "100000000000",
    "99999999999999999999999999999",
    "0x10",
    "1_000",
    "+5",
    ".5",
    "5.",
    "1e",
    "--1",
];

/// Byte sequences that are not UTF-8: a lone continuation byte, truncated sequences, an
/// overlong encoding, a surrogate, bytes never valid.
pub const INVALID_UTF8: &[&[u8]] = &[
    b"\x80",
    b"\xff",
    b"\xfe",
    b"\xc3",
    b"\xe2\x82",
    b"\xf0\x9f\x98",
    b"\xc0\x80",
    b"\xed\xa0\x80",
    b"\xf4\x90\x80\x80",
];

/// Bytes worth setting: control characters, separators, quotes and brackets of the formats.
const INTERESTING_BYTES: &[u8] = b"\0\t\n\r \"#'()*+,-./0123456789:;<=>[\\]{}|~\x7f\x80\xff";

/// Openers and closers of nested structures (brackets, Lua's, JSON's, TOML's).
const NESTINGS: &[(&str, &str)] = &[
    ("(", ")"),
    ("(NOT ", ")"),
    ("(AND (P X) ", ")"),
    ("[", "]"),
    ("{", "}"),
    ("{\"a\":", "}"),
    ("[[", "]]"),
    ("a={", "}"),
    ("(function() return ", " end)()"),
    ("-(", ")"),
    ("not ", ""),
];

/// Integers written little-endian at random offsets of binary inputs.
const INTERESTING_INTS: &[u64] = &[
    0,
    1,
    0x7f,
    0x80,
    0xff,
    0x100,
    0x7fff,
    0x8000,
    0xffff,
    0x1_0000,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    0x1_0000_0000,
    0x7fff_ffff_ffff_ffff,
    0x8000_0000_0000_0000,
    u64::MAX,
    16 << 20,
    (16 << 20) + 1,
];

/// Mutates seeds of one target.
#[derive(Clone, Debug)]
pub struct Mutator {
    dictionary: Vec<Vec<u8>>,
    max_len: usize,
}

impl Mutator {
    /// A mutator whose dictionary holds `keywords` and every word of the `seeds` (runs of
    /// letters, digits, `_`, `.`, `-`, `:`, `&` and `*`, up to 64 bytes), and whose outputs
    /// are at most `max_len` bytes.
    pub fn new<'a>(
        seeds: impl IntoIterator<Item = &'a [u8]>,
        keywords: &[&str],
        max_len: usize,
    ) -> Mutator {
        let mut words: BTreeSet<Vec<u8>> = keywords.iter().map(|k| k.as_bytes().to_vec()).collect();
        for seed in seeds {
            for w in seed.split(|b| !is_word_byte(*b)).filter(|w| !w.is_empty() && w.len() <= 64) {
                words.insert(w.to_vec());
            }
        }
        Mutator { dictionary: words.into_iter().collect(), max_len: max_len.max(1) }
    }

    /// The longest output.
    pub fn max_len(&self) -> usize {
        self.max_len
    }

    /// The dictionary's size.
    pub fn dictionary_len(&self) -> usize {
        self.dictionary.len()
    }

    /// A mutant of `seed`: one to [`MAX_STACK`] mutations; `other` is a second seed to splice
    /// from.
    pub fn mutate(&self, rng: &mut impl Rng, seed: &[u8], other: &[u8]) -> Vec<u8> {
        let mut data = seed.to_vec();
        data.truncate(self.max_len);
        let n = 1 + rng.random_range(0..MAX_STACK).min(rng.random_range(0..MAX_STACK));
        for _ in 0..n {
            self.mutate_once(rng, &mut data, other);
            data.truncate(self.max_len);
        }
        data
    }

    fn mutate_once(&self, rng: &mut impl Rng, data: &mut Vec<u8>, other: &[u8]) {
        match rng.random_range(0..20u32) {
            0 => flip_bit(rng, data),
            1 => set_byte(rng, data),
            2 => set_int(rng, data),
            3 => {
                let at = pos(rng, data.len() + 1);
                let len = rng.random_range(1..=16);
                let bytes: Vec<u8> = (0..len).map(|_| rng.random()).collect();
                insert(data, at, &bytes, self.max_len);
            }
            4 => delete_range(rng, data),
            5 => self.duplicate_range(rng, data),
            6 => self.splice(rng, data, other),
            7 | 8 => self.replace_number(rng, data),
            9 => self.replace_word(rng, data),
            10 => {
                let at = pos(rng, data.len() + 1);
                if let Some(w) = pick(rng, &self.dictionary) {
                    let w = w.clone();
                    insert(data, at, &w, self.max_len);
                }
            }
            11 => data.truncate(pos(rng, data.len() + 1)),
            12 => {
                let at = pos(rng, data.len() + 1);
                let bad = INVALID_UTF8[rng.random_range(0..INVALID_UTF8.len())];
                insert(data, at, bad, self.max_len);
            }
            13 => self.repeat_line(rng, data),
            14 => delete_line(rng, data),
            15 => swap_lines(rng, data),
            16 => self.nest(rng, data),
            17 => {
                // A huge count: a long run of one byte (digits, spaces, brackets, newlines).
                let at = pos(rng, data.len() + 1);
                let byte = INTERESTING_BYTES[rng.random_range(0..INTERESTING_BYTES.len())];
                let len = rng.random_range(1..=self.max_len.min(4096));
                insert(data, at, &vec![byte; len], self.max_len);
            }
            18 => {
                let at = pos(rng, data.len() + 1);
                let n = EXTREME_NUMBERS[rng.random_range(0..EXTREME_NUMBERS.len())];
                insert(data, at, n.as_bytes(), self.max_len);
            }
            _ => {
                // Strip or add line ends and comments.
                let at = pos(rng, data.len() + 1);
                let what: &[u8] = match rng.random_range(0..5) {
                    0 => b"\r\n",
                    1 => b"\n",
                    2 => b"#",
                    3 => b"--",
                    _ => b"\"",
                };
                insert(data, at, what, self.max_len);
            }
        }
    }

    fn duplicate_range(&self, rng: &mut impl Rng, data: &mut Vec<u8>) {
        if data.is_empty() {
            return;
        }
        let (start, end) = range(rng, data.len());
        let piece = data[start..end].to_vec();
        let at = pos(rng, data.len() + 1);
        insert(data, at, &piece, self.max_len);
    }

    fn splice(&self, rng: &mut impl Rng, data: &mut Vec<u8>, other: &[u8]) {
        if other.is_empty() {
            return;
        }
        let (start, end) = range(rng, other.len());
        let piece = &other[start..end];
        if rng.random_bool(0.5) || data.is_empty() {
            let at = pos(rng, data.len() + 1);
            insert(data, at, piece, self.max_len);
        } else {
            // Keep a head of this seed and continue with a tail of the other.
            let cut = pos(rng, data.len() + 1);
            data.truncate(cut);
            let room = self.max_len.saturating_sub(data.len());
            data.extend_from_slice(&other[start..other.len().min(start + room)]);
        }
    }

    fn replace_number(&self, rng: &mut impl Rng, data: &mut Vec<u8>) {
        let numbers = number_spans(data);
        let new = EXTREME_NUMBERS[rng.random_range(0..EXTREME_NUMBERS.len())].as_bytes();
        match pick(rng, &numbers) {
            Some(&(s, e)) => replace(data, s, e, new, self.max_len),
            None => {
                let at = pos(rng, data.len() + 1);
                insert(data, at, new, self.max_len);
            }
        }
    }

    fn replace_word(&self, rng: &mut impl Rng, data: &mut Vec<u8>) {
        let words = word_spans(data);
        let (Some(&(s, e)), Some(w)) = (pick(rng, &words), pick(rng, &self.dictionary)) else {
            return;
        };
        let w = w.clone();
        replace(data, s, e, &w, self.max_len);
    }

    fn repeat_line(&self, rng: &mut impl Rng, data: &mut Vec<u8>) {
        let lines = line_spans(data);
        let Some(&(s, e)) = pick(rng, &lines) else { return };
        let mut line = data[s..e].to_vec();
        if line.last() != Some(&b'\n') {
            line.push(b'\n');
        }
        let times = [1usize, 2, 10, 100, 1000][rng.random_range(0..5)];
        let room = self.max_len.saturating_sub(data.len()) / line.len().max(1);
        let piece = line.repeat(times.min(room));
        insert(data, e, &piece, self.max_len);
    }

    fn nest(&self, rng: &mut impl Rng, data: &mut Vec<u8>) {
        let (open, close) = NESTINGS[rng.random_range(0..NESTINGS.len())];
        let depth = [2usize, 10, 100, 1000, 10_000, 100_000][rng.random_range(0..6)];
        let unit = open.len() + close.len();
        let depth = depth.min(self.max_len.saturating_sub(data.len()) / unit.max(1));
        if depth == 0 {
            return;
        }
        let (start, end) = if data.is_empty() { (0, 0) } else { range(rng, data.len()) };
        let mut out = Vec::with_capacity(data.len() + depth * unit);
        out.extend_from_slice(&data[..start]);
        out.extend_from_slice(&open.as_bytes().repeat(depth));
        out.extend_from_slice(&data[start..end]);
        // Sometimes leave the nesting unclosed.
        if rng.random_bool(0.8) {
            out.extend_from_slice(&close.as_bytes().repeat(depth));
        }
        out.extend_from_slice(&data[end..]);
        *data = out;
    }
}

fn is_word_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || matches!(b, b'_' | b'.' | b'-' | b':' | b'&' | b'*')
}

fn is_number_start(b: u8) -> bool {
    b.is_ascii_digit() || b == b'-' || b == b'+' || b == b'.'
}

fn is_number_byte(b: u8) -> bool {
    b.is_ascii_digit() || matches!(b, b'.' | b'e' | b'E' | b'-' | b'+')
}

/// The spans (start, end) of numbers: runs of number bytes holding a digit, not glued to the
/// end of a word (`x1` is a name).
fn number_spans(data: &[u8]) -> Vec<(usize, usize)> {
    runs(data, is_number_start, is_number_byte, |b| b.is_ascii_alphanumeric() || b == b'_')
        .into_iter()
        .filter(|&(s, e)| data[s..e].iter().any(u8::is_ascii_digit))
        .collect()
}

/// The spans of words.
fn word_spans(data: &[u8]) -> Vec<(usize, usize)> {
    runs(data, is_word_byte, is_word_byte, is_word_byte)
}

/// Runs that begin with a `start` byte not after a `glued` byte and go on with `rest` bytes.
fn runs(
    data: &[u8],
    start: fn(u8) -> bool,
    rest: fn(u8) -> bool,
    glued: fn(u8) -> bool,
) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < data.len() {
        if start(data[i]) && (i == 0 || !glued(data[i - 1])) {
            let mut j = i + 1;
            while j < data.len() && rest(data[j]) {
                j += 1;
            }
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

fn line_spans(data: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut s = 0;
    for (i, b) in data.iter().enumerate() {
        if *b == b'\n' {
            out.push((s, i + 1));
            s = i + 1;
        }
    }
    if s < data.len() {
        out.push((s, data.len()));
    }
    out
}

fn delete_range(rng: &mut impl Rng, data: &mut Vec<u8>) {
    if !data.is_empty() {
        let (s, e) = range(rng, data.len());
        data.drain(s..e);
    }
}

fn delete_line(rng: &mut impl Rng, data: &mut Vec<u8>) {
    let lines = line_spans(data);
    if let Some(&(s, e)) = pick(rng, &lines) {
        data.drain(s..e);
    }
}

fn swap_lines(rng: &mut impl Rng, data: &mut Vec<u8>) {
    let lines = line_spans(data);
    if lines.len() < 2 {
        return;
    }
    let a = rng.random_range(0..lines.len() - 1);
    let b = rng.random_range(a + 1..lines.len());
    let ((s1, e1), (s2, e2)) = (lines[a], lines[b]);
    let mut out = Vec::with_capacity(data.len());
    out.extend_from_slice(&data[..s1]);
    out.extend_from_slice(&data[s2..e2]);
    out.extend_from_slice(&data[e1..s2]);
    out.extend_from_slice(&data[s1..e1]);
    out.extend_from_slice(&data[e2..]);
    *data = out;
}

fn pick<'a, T>(rng: &mut impl Rng, items: &'a [T]) -> Option<&'a T> {
    (!items.is_empty()).then(|| &items[rng.random_range(0..items.len())])
}

/// A position below `n` (0 when `n` is 0).
fn pos(rng: &mut impl Rng, n: usize) -> usize {
    if n == 0 {
        0
    } else {
        rng.random_range(0..n)
    }
}

/// A non-empty range of `0..len` (`len` > 0), short more often than long.
fn range(rng: &mut impl Rng, len: usize) -> (usize, usize) {
    let start = rng.random_range(0..len);
    let max = len - start;
    let short = rng.random_range(1..=max.min(32));
    let span = if rng.random_bool(0.8) { short } else { rng.random_range(1..=max) };
    (start, start + span)
}

fn insert(data: &mut Vec<u8>, at: usize, bytes: &[u8], max_len: usize) {
    let room = max_len.saturating_sub(data.len());
    let bytes = &bytes[..bytes.len().min(room)];
    let at = at.min(data.len());
    data.splice(at..at, bytes.iter().copied());
}

fn replace(data: &mut Vec<u8>, s: usize, e: usize, bytes: &[u8], max_len: usize) {
    let room = max_len.saturating_sub(data.len() - (e - s));
    data.splice(s..e, bytes[..bytes.len().min(room)].iter().copied());
}

fn flip_bit(rng: &mut impl Rng, data: &mut [u8]) {
    if !data.is_empty() {
        let i = rng.random_range(0..data.len());
        data[i] ^= 1 << rng.random_range(0..8);
    }
}

fn set_byte(rng: &mut impl Rng, data: &mut [u8]) {
    if !data.is_empty() {
        let i = rng.random_range(0..data.len());
        data[i] = if rng.random_bool(0.5) {
            INTERESTING_BYTES[rng.random_range(0..INTERESTING_BYTES.len())]
        } else {
            rng.random()
        };
    }
}

fn set_int(rng: &mut impl Rng, data: &mut [u8]) {
    let width = [1usize, 2, 4, 8][rng.random_range(0..4)];
    if data.len() < width {
        return;
    }
    // Aligned more often than not: binary headers are.
    let mut at = rng.random_range(0..=data.len() - width);
    if rng.random_bool(0.7) {
        at -= at % width;
    }
    let mut v = INTERESTING_INTS[rng.random_range(0..INTERESTING_INTS.len())];
    if rng.random_bool(0.2) {
        v = v.wrapping_neg();
    }
    data[at..at + width].copy_from_slice(&v.to_le_bytes()[..width]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn mutants_are_deterministic_and_bounded() {
        let seed = b"(Distance (TRA (NEAR 40 60 100 120)))\nPostOffice: PMQ\n".as_slice();
        let m = Mutator::new([seed], &["TRI"], 256);
        let run = |s: u64| {
            let mut rng = ChaCha8Rng::seed_from_u64(s);
            (0..2000).map(|_| m.mutate(&mut rng, seed, b"other 1 2 3")).collect::<Vec<_>>()
        };
        let (a, b) = (run(7), run(7));
        assert_eq!(a, b);
        assert!(a.iter().all(|x| x.len() <= 256));
        assert!(a.iter().filter(|x| x.as_slice() != seed).count() > 1900);
        assert!(a.iter().any(|x| std::str::from_utf8(x).is_err()), "some invalid UTF-8");
        assert!(a.iter().any(|x| x.windows(5).any(|w| w == b"1e308")), "some extremes");
    }

    #[test]
    fn numbers_and_words_are_found() {
        let d = b"a 12 -3.5e2 x1 (b.c 7)";
        assert_eq!(number_spans(d), vec![(2, 4), (5, 11), (20, 21)]);
        assert_eq!(word_spans(d).len(), 6);
        assert_eq!(line_spans(b"a\nb\nc"), vec![(0, 2), (2, 4), (4, 5)]);
    }

    #[test]
    fn empty_inputs_do_not_panic() {
        let m = Mutator::new([b"".as_slice()], &[], 64);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..5000 {
            assert!(m.mutate(&mut rng, b"", b"").len() <= 64);
        }
    }
}

/// Structure-aware mutation of a JSON document: the seed is parsed, one to three of its
/// values are changed (a number to an extreme, a string to an empty, long or odd one, an
/// array's elements repeated up to a thousand times or dropped, a key removed or a foreign
/// one added, a value's type changed), and the document written back, so that the input stays
/// JSON and reaches what reads it. `None` when the seed is not JSON.
pub fn mutate_json(rng: &mut impl Rng, seed: &[u8]) -> Option<Vec<u8>> {
    let mut value: serde_json::Value = serde_json::from_slice(seed).ok()?;
    for _ in 0..rng.random_range(1..=3) {
        let n = count_nodes(&value);
        let target = rng.random_range(0..n);
        let mut seen = 0;
        mutate_node(rng, &mut value, target, &mut seen);
    }
    serde_json::to_vec(&value).ok()
}

fn count_nodes(v: &serde_json::Value) -> usize {
    1 + match v {
        serde_json::Value::Array(a) => a.iter().map(count_nodes).sum(),
        serde_json::Value::Object(o) => o.values().map(count_nodes).sum(),
        _ => 0,
    }
}

/// JSON numbers at the edges: what `f64`, `i64` and `u64` hold, and a little past.
fn extreme_json_number(rng: &mut impl Rng) -> serde_json::Value {
    use serde_json::json;
    match rng.random_range(0..14) {
        0 => json!(0),
        1 => json!(-1),
        2 => json!(1e308),
        3 => json!(-1e308),
        4 => json!(f64::MIN_POSITIVE),
        5 => json!(5e-324),
        6 => json!(u64::MAX),
        7 => json!(i64::MIN),
        8 => json!(i64::MAX),
        9 => json!(u32::MAX),
        10 => json!(1e19),
        11 => json!(-1e19),
        12 => json!(0.5),
        _ => json!(1_000_000_000),
    }
}

fn mutate_node(
    rng: &mut impl Rng,
    v: &mut serde_json::Value,
    target: usize,
    seen: &mut usize,
) -> bool {
    use serde_json::Value;
    if *seen == target {
        change(rng, v);
        return true;
    }
    *seen += 1;
    match v {
        Value::Array(a) => a.iter_mut().any(|x| mutate_node(rng, x, target, seen)),
        Value::Object(o) => o.values_mut().any(|x| mutate_node(rng, x, target, seen)),
        _ => false,
    }
}

fn change(rng: &mut impl Rng, v: &mut serde_json::Value) {
    use serde_json::Value;
    match v {
        Value::Number(_) if rng.random_bool(0.8) => *v = extreme_json_number(rng),
        Value::String(s) if rng.random_bool(0.8) => {
            *s = match rng.random_range(0..5) {
                0 => String::new(),
                1 => "x".repeat(10_000),
                2 => "\u{202e}\u{0}\n\"".to_string(),
                3 => s.to_uppercase(),
                _ => s.to_lowercase(),
            };
        }
        Value::Array(a) if !a.is_empty() && rng.random_bool(0.8) => {
            if rng.random_bool(0.5) {
                let times = [2usize, 10, 100, 1000][rng.random_range(0..4)];
                let i = rng.random_range(0..a.len());
                let item = a[i].clone();
                a.extend(std::iter::repeat_n(item, times));
            } else {
                a.truncate(rng.random_range(0..a.len()));
            }
        }
        Value::Object(o) if !o.is_empty() && rng.random_bool(0.8) => {
            if rng.random_bool(0.6) {
                let i = rng.random_range(0..o.len());
                if let Some(k) = o.keys().nth(i).cloned() {
                    o.remove(&k);
                }
            } else {
                o.insert("unknown_key".to_string(), Value::Bool(true));
            }
        }
        _ => {
            *v = match rng.random_range(0..6) {
                0 => Value::Null,
                1 => Value::Bool(true),
                2 => extreme_json_number(rng),
                3 => Value::String("PLAYING".to_string()),
                4 => Value::Array(Vec::new()),
                _ => Value::Object(serde_json::Map::new()),
            };
        }
    }
}

#[cfg(test)]
mod json_tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn json_mutants_stay_json_and_change() {
        let seed = br#"{"lps": [{"rho": 3.0, "theta": 1.0}], "role": "attacker", "mates": []}"#;
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mutants: Vec<Vec<u8>> = (0..500).filter_map(|_| mutate_json(&mut rng, seed)).collect();
        assert_eq!(mutants.len(), 500);
        assert!(mutants.iter().all(|m| serde_json::from_slice::<serde_json::Value>(m).is_ok()));
        assert!(mutants.iter().filter(|m| m.as_slice() != seed.as_slice()).count() > 400);
        assert!(mutate_json(&mut rng, b"not json").is_none());
    }
}

/// Structure-aware mutation of a TOML document, as [`mutate_json`] does for JSON: integers
/// and floats to extremes (NaN and infinities included, which TOML can write), booleans
/// flipped, arrays repeated or cut, keys removed or foreign ones added, a value's type
/// changed. `None` when the seed is not TOML.
pub fn mutate_toml(rng: &mut impl Rng, seed: &[u8]) -> Option<Vec<u8>> {
    let text = std::str::from_utf8(seed).ok()?;
    let mut table: toml::Table = text.parse().ok()?;
    for _ in 0..rng.random_range(1..=3) {
        let n = table.values().map(count_toml).sum::<usize>().max(1);
        let target = rng.random_range(0..n);
        let mut seen = 0;
        for (_, v) in table.iter_mut() {
            if mutate_toml_node(rng, v, target, &mut seen) {
                break;
            }
        }
    }
    toml::to_string(&table).ok().map(String::into_bytes)
}

fn count_toml(v: &toml::Value) -> usize {
    1 + match v {
        toml::Value::Array(a) => a.iter().map(count_toml).sum(),
        toml::Value::Table(t) => t.values().map(count_toml).sum(),
        _ => 0,
    }
}

fn mutate_toml_node(
    rng: &mut impl Rng,
    v: &mut toml::Value,
    target: usize,
    seen: &mut usize,
) -> bool {
    use toml::Value;
    if *seen == target {
        change_toml(rng, v);
        return true;
    }
    *seen += 1;
    match v {
        Value::Array(a) => a.iter_mut().any(|x| mutate_toml_node(rng, x, target, seen)),
        Value::Table(t) => t.iter_mut().any(|(_, x)| mutate_toml_node(rng, x, target, seen)),
        _ => false,
    }
}

const TOML_FLOATS: [f64; 14] = [
    0.0,
    -0.0,
    -1.0,
    1e-9,
    5e-324,
    1e308,
    -1e308,
    f64::MAX,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e19,
    0.5,
    1e9,
];
const TOML_INTS: [i64; 10] =
    [0, -1, 1, i64::MAX, i64::MIN, u32::MAX as i64, 1 << 53, 1_000_000_000, 255, 65536];

fn change_toml(rng: &mut impl Rng, v: &mut toml::Value) {
    use toml::Value;
    let float = |rng: &mut dyn rand::RngCore| TOML_FLOATS[rng.random_range(0..TOML_FLOATS.len())];
    let int = |rng: &mut dyn rand::RngCore| TOML_INTS[rng.random_range(0..TOML_INTS.len())];
    match v {
        Value::Float(f) if rng.random_bool(0.8) => *f = float(rng),
        Value::Integer(i) if rng.random_bool(0.8) => *i = int(rng),
        Value::Boolean(b) if rng.random_bool(0.8) => *b = !*b,
        Value::Array(a) if !a.is_empty() && rng.random_bool(0.8) => {
            if rng.random_bool(0.5) {
                let times = [2usize, 10, 100, 1000][rng.random_range(0..4)];
                let item = a[rng.random_range(0..a.len())].clone();
                a.extend(std::iter::repeat_n(item, times));
            } else {
                a.truncate(rng.random_range(0..a.len()));
            }
        }
        Value::Table(t) if !t.is_empty() && rng.random_bool(0.8) => {
            if rng.random_bool(0.6) {
                let i = rng.random_range(0..t.len());
                if let Some(k) = t.keys().nth(i).cloned() {
                    t.remove(&k);
                }
            } else {
                t.insert("unknown_key".to_string(), Value::Boolean(true));
            }
        }
        _ => {
            *v = match rng.random_range(0..5) {
                0 => Value::Float(float(rng)),
                1 => Value::Integer(int(rng)),
                2 => Value::String(String::new()),
                3 => Value::Boolean(false),
                _ => Value::Array(Vec::new()),
            };
        }
    }
}

#[cfg(test)]
mod toml_tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn toml_mutants_stay_toml_and_change() {
        let seed = b"[field]\nlength = 18.0\nwidth = 12.0\n[match]\nrobots = 4\nhalves = [1, 2]\n";
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mutants: Vec<Vec<u8>> = (0..500).filter_map(|_| mutate_toml(&mut rng, seed)).collect();
        assert_eq!(mutants.len(), 500);
        assert!(mutants
            .iter()
            .all(|m| std::str::from_utf8(m).unwrap().parse::<toml::Table>().is_ok()));
        assert!(mutants.iter().filter(|m| m.as_slice() != seed.as_slice()).count() > 400);
    }
}
