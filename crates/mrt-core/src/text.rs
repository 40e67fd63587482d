//! Text from input (a file, a script's error, a network message) made safe to print on a
//! terminal.

/// `text` safe to print on a terminal: control characters (escape sequences, bells, NUL, C1
/// controls) and bidirectional overrides are shown as `\u{..}` instead of acting; line
/// breaks and tabs stay as they are.
///
/// ```
/// assert_eq!(mrt_core::printable("\u{1b}[2Jmatch OK"), "\\u{1b}[2Jmatch OK");
/// assert_eq!(mrt_core::printable("a\tb\nc"), "a\tb\nc");
/// ```
pub fn printable(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        let bidi = matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
        if (c.is_control() && c != '\n' && c != '\t') || bidi {
            out.push_str(&format!("\\u{{{:x}}}", u32::from(c)));
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_nul_bells_c1_controls_and_bidi_overrides_but_not_line_breaks() {
        assert_eq!(printable("a\0b\x07c\u{9b}d\u{202e}e"), "a\\u{0}b\\u{7}c\\u{9b}d\\u{202e}e");
        assert_eq!(printable("line 1\nline 2\r"), "line 1\nline 2\\u{d}");
        assert_eq!(printable("é ✓"), "é ✓");
    }
}
