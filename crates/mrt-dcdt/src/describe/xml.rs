//! The XML text form of a self-describing message: writing it, and reading it back with every
//! error placed at its line and column.

use super::*;

// ---------------------------------------------------------------------------------------------
// Writing

/// An XML attribute whose value is already escaped.
pub(super) fn xml_attr(key: &str, escaped: String) -> XmlAttr<'_> {
    XmlAttr { key: QName(key.as_bytes()), value: Cow::Owned(escaped.into_bytes()) }
}

/// Escapes `s` for a double-quoted attribute value. Tabs, newlines and other control
/// characters become character references, so that they survive attribute-value
/// normalization.
pub(super) fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\0' => out.push(c),
            c if c.is_ascii_control() && c != '\u{7f}' => {
                let _ = write!(out, "&#{};", u32::from(c));
            }
            c => out.push(c),
        }
    }
    out
}

const NANOS_PER_SEC: u64 = 1_000_000_000;

pub(super) fn format_timestamp(t: Time) -> String {
    let n = t.as_nanos();
    format!("{}.{:09}", n / NANOS_PER_SEC, n % NANOS_PER_SEC)
}

// ---------------------------------------------------------------------------------------------
// Reading

fn is_xml_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n')
}

fn trim_xml_space(s: &str) -> &str {
    s.trim_matches(|c: char| c.is_ascii() && is_xml_space(c as u8))
}

/// Parses `{secs}` or `{secs}.{decimals}` (1 to 9 decimals) into nanoseconds, exactly.
fn parse_timestamp(s: &str) -> Result<Time, &'static str> {
    const MALFORMED: &str = "as non-negative seconds with at most 9 decimals";
    let s = trim_xml_space(s);
    let (secs, frac) = match s.split_once('.') {
        Some((secs, frac)) => (secs, Some(frac)),
        None => (s, None),
    };
    let all_digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
    if !all_digits(secs) {
        return Err(MALFORMED);
    }
    let mut nanos = 0u64;
    if let Some(frac) = frac {
        if !all_digits(frac) || frac.len() > 9 {
            return Err(MALFORMED);
        }
        for b in frac.bytes() {
            nanos = nanos * 10 + u64::from(b - b'0');
        }
        for _ in frac.len()..9 {
            nanos *= 10;
        }
    }
    const RANGE: &str = "of at most 18446744073.709551615 seconds";
    let secs: u64 = secs.parse().map_err(|_| RANGE)?;
    secs.checked_mul(NANOS_PER_SEC).and_then(|n| n.checked_add(nanos)).map(Time).ok_or(RANGE)
}

fn parse_number(s: &str) -> Option<f64> {
    trim_xml_space(s).parse().ok()
}

/// 1-based line and column (in characters) of byte `pos` of `text`.
pub(super) fn line_column(text: &str, pos: u64) -> (usize, usize) {
    let bytes = text.as_bytes();
    let pos = usize::try_from(pos).unwrap_or(usize::MAX).min(bytes.len());
    let before = bytes.get(..pos).unwrap_or(bytes);
    let line = 1 + before.iter().filter(|&&b| b == b'\n').count();
    let line_start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let column = 1 + before
        .get(line_start..)
        .unwrap_or_default()
        .iter()
        .filter(|&&b| b & 0xC0 != 0x80)
        .count();
    (line, column)
}

fn lossy(bytes: &[u8]) -> Cow<'_, str> {
    String::from_utf8_lossy(bytes)
}

/// A structural event: what is left once whitespace, comments and the like are skipped.
enum Item<'a> {
    Open(BytesStart<'a>, bool),
    Close(BytesEnd<'a>),
    Eof,
}

impl Item<'_> {
    /// How the item is named in "found ..." messages.
    fn describe(&self) -> String {
        match self {
            Item::Open(tag, _) => format!("<{}>", lossy(tag.name().as_ref())),
            Item::Close(tag) => format!("</{}>", lossy(tag.name().as_ref())),
            Item::Eof => "end of input".to_owned(),
        }
    }
}

/// The XML attributes of one element, unescaped.
struct Fields {
    pairs: Vec<(String, String)>,
}

impl Fields {
    fn take(&mut self, key: &str) -> Option<String> {
        let i = self.pairs.iter().position(|(k, _)| k == key)?;
        Some(self.pairs.remove(i).1)
    }

    /// The first key left over after all known keys were taken.
    fn unknown(&self) -> Option<&str> {
        self.pairs.first().map(|(k, _)| k.as_str())
    }
}

pub(super) struct Parser<'a> {
    text: &'a str,
    reader: Reader<&'a [u8]>,
}

impl<'a> Parser<'a> {
    pub(super) fn new(text: &'a str) -> Self {
        let mut reader = Reader::from_str(text);
        let config = reader.config_mut();
        config.check_end_names = true;
        config.expand_empty_elements = false;
        config.trim_text(false);
        Parser { text, reader }
    }

    fn error_at(&self, pos: u64, message: impl Into<String>) -> XmlError {
        let (line, column) = line_column(self.text, pos);
        XmlError::Syntax { line, column, message: message.into() }
    }

    /// An error of the XML reader itself, at the position it reports.
    fn reader_error(&self, e: &QxError) -> XmlError {
        let message = match e {
            QxError::Syntax(s) => match s {
                SyntaxError::InvalidBangMarkup => {
                    "expected a comment, cdata section or doctype after `<!`".to_owned()
                }
                SyntaxError::UnclosedPI => {
                    "expected `?>` to close the processing instruction, found end of input"
                        .to_owned()
                }
                SyntaxError::UnclosedXmlDecl => {
                    "expected `?>` to close the xml declaration, found end of input".to_owned()
                }
                SyntaxError::UnclosedSingleQuotedAttributeValue
                | SyntaxError::UnclosedDoubleQuotedAttributeValue => {
                    "expected a quote to close the attribute's value, found end of input".to_owned()
                }
                SyntaxError::UnclosedComment => {
                    "expected `-->` to close the comment, found end of input".to_owned()
                }
                SyntaxError::UnclosedDoctype => {
                    "expected `>` to close the doctype, found end of input".to_owned()
                }
                SyntaxError::UnclosedCData => {
                    "expected `]]>` to close the cdata section, found end of input".to_owned()
                }
                SyntaxError::UnclosedTag => {
                    "expected `>` to close the tag, found end of input".to_owned()
                }
            },
            QxError::IllFormed(f) => match f {
                IllFormedError::MismatchedEndTag { expected, found } => {
                    format!("expected </{expected}>, found </{found}>")
                }
                IllFormedError::UnmatchedEndTag(tag) => {
                    format!("expected a start tag before </{tag}>")
                }
                IllFormedError::MissingEndTag(tag) => {
                    format!("expected </{tag}>, found end of input")
                }
                IllFormedError::MissingDeclVersion(_) => {
                    "expected `version` first in the xml declaration".to_owned()
                }
                IllFormedError::UnknownVersion => {
                    "expected version 1.0 or 1.1 in the xml declaration".to_owned()
                }
                IllFormedError::UnclosedReference => {
                    "expected `;` to end the reference, found end of input".to_owned()
                }
                IllFormedError::MissingDoctypeName => "expected a name in the doctype".to_owned(),
                IllFormedError::DoubleHyphenInComment => {
                    "expected no `--` inside a comment".to_owned()
                }
            },
            other => format!("malformed xml: {}", other.to_string().to_lowercase()),
        };
        self.error_at(self.reader.error_position(), message)
    }

    /// The next structural item and its byte position, skipping whitespace, comments and
    /// processing instructions (and, in the prolog, the XML declaration and the DOCTYPE).
    /// `expected` says what is expected in place of anything else.
    fn next(&mut self, prolog: bool, expected: &str) -> Result<(u64, Item<'a>), XmlError> {
        loop {
            let pos = self.reader.buffer_position();
            let event = match self.reader.read_event() {
                Ok(event) => event,
                Err(e) => return Err(self.reader_error(&e)),
            };
            let found = match event {
                Event::Start(tag) => return Ok((pos, Item::Open(tag, false))),
                Event::Empty(tag) => return Ok((pos, Item::Open(tag, true))),
                Event::End(tag) => return Ok((pos, Item::Close(tag))),
                Event::Eof => return Ok((pos, Item::Eof)),
                Event::Comment(_) | Event::PI(_) => continue,
                Event::Decl(_) | Event::DocType(_) if prolog => continue,
                Event::Text(text) if text.iter().copied().all(is_xml_space) => continue,
                Event::Text(_) | Event::CData(_) | Event::GeneralRef(_) => "text",
                Event::Decl(_) => "an xml declaration",
                Event::DocType(_) => "a doctype",
            };
            return Err(self.error_at(pos, format!("expected {expected}, found {found}")));
        }
    }

    /// The XML attributes of the element `tag` at `pos`; `what` names it in errors.
    fn fields(&self, pos: u64, tag: &BytesStart<'_>, what: &str) -> Result<Fields, XmlError> {
        let mut pairs = Vec::new();
        for attr in tag.attributes() {
            let attr = attr.map_err(|e| self.attr_error(pos, tag, what, &e))?;
            let key = lossy(attr.key.as_ref()).into_owned();
            let value = match attr.normalized_value(XmlVersion::Implicit1_0) {
                Ok(value) => value.into_owned(),
                Err(e) => {
                    let problem = match &e {
                        QxError::Escape(EscapeError::UnrecognizedEntity(_, name)) => {
                            format!("a predefined entity, found `&{name};`")
                        }
                        QxError::Escape(EscapeError::UnterminatedEntity(_)) => {
                            "`;` to end the entity".to_owned()
                        }
                        QxError::Escape(EscapeError::InvalidCharRef(_)) => {
                            "a valid character reference".to_owned()
                        }
                        other => format!("valid text ({})", other.to_string().to_lowercase()),
                    };
                    return Err(
                        self.error_at(pos, format!("{what}: in `{key}`, expected {problem}"))
                    );
                }
            };
            pairs.push((key, value));
        }
        Ok(Fields { pairs })
    }

    fn attr_error(&self, pos: u64, tag: &BytesStart<'_>, what: &str, e: &AttrError) -> XmlError {
        // Positions of attribute errors count from the byte after `<`.
        let (at, message) = match e {
            AttrError::ExpectedEq(p) => (*p, "expected `=` after the attribute name".to_owned()),
            AttrError::ExpectedValue(p) => (*p, "expected a quoted attribute value".to_owned()),
            AttrError::UnquotedValue(p) => {
                (*p, "expected a quoted attribute value, found an unquoted one".to_owned())
            }
            AttrError::ExpectedQuote(p, q) => {
                (*p, format!("expected a closing `{}` after the attribute value", char::from(*q)))
            }
            AttrError::Duplicated(p, _) => {
                let content: &[u8] = tag;
                let key: Vec<u8> = content
                    .get(*p..)
                    .unwrap_or_default()
                    .iter()
                    .copied()
                    .take_while(|&b| !is_xml_space(b) && !matches!(b, b'=' | b'/' | b'>'))
                    .collect();
                (*p, format!("expected each attribute once, found a second `{}`", lossy(&key)))
            }
        };
        let at = pos.saturating_add(1).saturating_add(at as u64);
        self.error_at(at, format!("{what}: {message}"))
    }

    pub(super) fn parse(mut self) -> Result<SelfDescribing, XmlError> {
        let (pos, item) = self.next(true, "<message>")?;
        let (tag, empty) = match item {
            Item::Open(tag, empty) if tag.name().as_ref() == b"message" => (tag, empty),
            other => {
                let found = other.describe();
                return Err(self.error_at(pos, format!("expected <message>, found {found}")));
            }
        };
        let mut fields = self.fields(pos, &tag, "<message>")?;
        let timestamp = fields.take("timestamp");
        if let Some(key) = fields.unknown() {
            return Err(
                self.error_at(pos, format!("<message>: expected only `timestamp`, found `{key}`"))
            );
        }
        let Some(timestamp) = timestamp else {
            return Err(self.error_at(pos, "<message>: expected `timestamp`"));
        };
        let timestamp = parse_timestamp(&timestamp).map_err(|want| {
            self.error_at(
                pos,
                format!("<message>: expected `timestamp` {want}, found {timestamp:?}"),
            )
        })?;
        let mut msg = SelfDescribing::new(timestamp);
        if !empty {
            loop {
                let (pos, item) = self.next(false, "<object> or </message>")?;
                match item {
                    Item::Open(tag, empty) if tag.name().as_ref() == b"object" => {
                        let obj = self.object(pos, &tag, empty)?;
                        msg.objects.push(obj);
                    }
                    Item::Close(tag) if tag.name().as_ref() == b"message" => break,
                    Item::Open(..) => {
                        let found = item.describe();
                        return Err(self.error_at(pos, format!("expected <object>, found {found}")));
                    }
                    other => {
                        let found = other.describe();
                        return Err(
                            self.error_at(pos, format!("expected </message>, found {found}"))
                        );
                    }
                }
            }
        }
        let (pos, item) = self.next(false, "end of input")?;
        if let Item::Eof = item {
            return Ok(msg);
        }
        let found = item.describe();
        Err(self.error_at(pos, format!("expected end of input, found {found}")))
    }

    fn object(&mut self, pos: u64, tag: &BytesStart<'_>, empty: bool) -> Result<Object, XmlError> {
        let mut fields = self.fields(pos, tag, "<object>")?;
        let name = fields.take("name");
        let class = fields.take("class");
        let what = match &name {
            Some(name) => format!("object {name:?}"),
            None => "<object>".to_owned(),
        };
        if let Some(key) = fields.unknown() {
            return Err(self.error_at(
                pos,
                format!("{what}: expected only `name` and `class`, found `{key}`"),
            ));
        }
        let Some(name) = name else {
            return Err(self.error_at(pos, format!("{what}: expected `name`")));
        };
        let Some(class) = class else {
            return Err(self.error_at(pos, format!("{what}: expected `class`")));
        };
        let mut obj = Object::new(name, class);
        if empty {
            return Ok(obj);
        }
        loop {
            let (pos, item) = self.next(false, "<attribute> or </object>")?;
            match item {
                Item::Open(tag, empty) if tag.name().as_ref() == b"attribute" => {
                    let attr = self.attribute(pos, &tag, empty, &obj.name)?;
                    obj.attributes.push(attr);
                }
                Item::Close(tag) if tag.name().as_ref() == b"object" => return Ok(obj),
                Item::Open(..) => {
                    let found = item.describe();
                    return Err(self.error_at(pos, format!("expected <attribute>, found {found}")));
                }
                other => {
                    let found = other.describe();
                    return Err(self.error_at(pos, format!("expected </object>, found {found}")));
                }
            }
        }
    }

    fn attribute(
        &mut self,
        pos: u64,
        tag: &BytesStart<'_>,
        empty: bool,
        object: &str,
    ) -> Result<Attribute, XmlError> {
        let mut fields = self.fields(pos, tag, &format!("<attribute> of object {object:?}"))?;
        let name = fields.take("name");
        let value = fields.take("value");
        let symbol = fields.take("symbol");
        let variability = fields.take("variability");
        let reliability = fields.take("reliability");
        let what = match &name {
            Some(name) => format!("attribute {name:?} of object {object:?}"),
            None => format!("<attribute> of object {object:?}"),
        };
        let fail = |message: String| Err(self.error_at(pos, format!("{what}: {message}")));
        if let Some(key) = fields.unknown() {
            return fail(format!(
                "expected only `name`, `value`, `symbol`, `variability` and `reliability`, \
                 found `{key}`"
            ));
        }
        let Some(name) = name else {
            return fail("expected `name`".to_owned());
        };
        let value = match (value, symbol) {
            (Some(value), None) => match parse_number(&value) {
                Some(v) => AttrValue::Number(v),
                None => return fail(format!("expected a number in `value`, found {value:?}")),
            },
            (None, Some(symbol)) => AttrValue::Symbol(symbol),
            (Some(_), Some(_)) => return fail("expected `value` or `symbol`, not both".to_owned()),
            (None, None) => return fail("expected `value` or `symbol`".to_owned()),
        };
        let Some(variability_text) = variability else {
            return fail("expected `variability`".to_owned());
        };
        let variability = match parse_number(&variability_text) {
            Some(v) if v >= 0.0 => v,
            _ => {
                return fail(format!(
                    "expected `variability` to be a non-negative number, found {variability_text:?}"
                ))
            }
        };
        let Some(reliability_text) = reliability else {
            return fail("expected `reliability`".to_owned());
        };
        let reliability = match parse_number(&reliability_text) {
            Some(r) if (0.0..=1.0).contains(&r) => r,
            _ => {
                return fail(format!(
                    "expected `reliability` between 0 and 1, found {reliability_text:?}"
                ))
            }
        };
        let attr = Attribute { name, value, variability, reliability };
        if !empty {
            let (pos, item) = self.next(false, "</attribute>")?;
            match item {
                Item::Close(tag) if tag.name().as_ref() == b"attribute" => {}
                other => {
                    let found = other.describe();
                    return Err(self.error_at(pos, format!("expected </attribute>, found {found}")));
                }
            }
        }
        Ok(attr)
    }
}
