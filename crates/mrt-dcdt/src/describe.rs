//! Self-describing messages (MRT manual §3.2).
//!
//! The manual: "our modules communicate through XML messages whose structure is defined by a
//! shared DTD. Each message contains some general information, such as the time-stamp, and a
//! list of objects characterized by a name and its membership class. For each object may be
//! defined a number of attributes, that are tuples of name, value, variability, and
//! reliability. In order to correctly parse the content of the messages, modules share a
//! common ontology that defines the semantic of the used symbols."
//!
//! In MRT such a message is the standard typed message [`SelfDescribing`]. On the bus it
//! travels like any other [`Message`] (postcard on the wire); its XML text form, described by
//! [`DTD`], is for tools and logs: [`SelfDescribing::to_xml`] writes it and
//! [`SelfDescribing::from_xml`] reads it back exactly (timestamps to the nanosecond, numbers
//! bit for bit).
//!
//! ```
//! use mrt_core::Time;
//! use mrt_dcdt::describe::{Attribute, Object, SelfDescribing};
//!
//! let msg = SelfDescribing::new(Time(12_500_000_000)).with_object(
//!     Object::new("ball", "Ball")
//!         .with(Attribute::number("distance", 2.4, 0.1, 0.9))
//!         .with(Attribute::symbol("colour", "orange", 0.0, 1.0)),
//! );
//! let xml = msg.to_xml();
//! println!("{xml}");
//! assert_eq!(
//!     xml,
//!     r#"<message timestamp="12.500000000">
//!   <object name="ball" class="Ball">
//!     <attribute name="distance" value="2.4" variability="0.1" reliability="0.9"/>
//!     <attribute name="colour" symbol="orange" variability="0" reliability="1"/>
//!   </object>
//! </message>"#
//! );
//! assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
//! # Ok::<(), mrt_dcdt::describe::XmlError>(())
//! ```
//!
//! # The form of a typed message
//!
//! Every typed message has a self-describing form, generated from its type: [`describe`] (and
//! [`SelfDescribing::of_message`], which names the form after the message type) takes any value
//! that implements `Serialize`, so the standard catalogue (`mrt-msgs`) needs no per-message
//! code. The rules:
//!
//! - **Objects.** The value is the first object, named by the caller ([`Message::NAME`] for
//!   `of_message`), of class its type's name. Each struct in it (a unit or tuple struct too)
//!   is an object of its own, after the objects before it depth first, named by its path from
//!   the message and of class its type's name: `ball`, `mates[2]`, `mates[2].at.pose`. A
//!   value that is not a struct (a number, a sequence, a map) is a first object of class
//!   `name`, a lone number or symbol being its attribute `value`.
//! - **Attributes.** The other fields are attributes of the nearest enclosing object, named by
//!   their path from it. A number (any integer or float, as an `f64`: integers beyond 2⁵³ are
//!   rounded) has a `value`; a bool (`true`, `false`), a string, a char and a unit enum
//!   variant (its serde name) have a `symbol`. `NaN`, `inf` and `-inf` are written as such and
//!   read back.
//! - **Absent values.** `None` and `()` are left out; `Some(v)` is `v`.
//! - **Sequences.** Elements of a sequence, tuple or array are indexed: `lps[0]`,
//!   `needs[0][1]`; an empty sequence leaves nothing. A sequence of bytes (`Vec<u8>`, `&[u8]`,
//!   `serde_bytes`) is a single attribute whose symbol is its size, e.g. `<921600 bytes>`: a
//!   camera image's content is left out. Tuples and arrays of `u8`, and sequences of
//!   `Option<u8>` or of newtypes of `u8`, stay numbers.
//! - **Enums with data, newtypes, maps.** A variant with data is an object whose class is the
//!   variant's name, with the variant's fields, or `0`, `1`, ... for a tuple or newtype
//!   variant. A newtype struct is its value (a struct in it takes the newtype's name as
//!   class). A map entry is named by its key, `f.key`, the key being a number or a symbol
//!   (any other key is a [`DescribeError::MapKey`]).
//! - **Variability and reliability.** By default an attribute has variability 0 and
//!   reliability 1. Numeric fields of a struct with the names of the shared ontology below set
//!   them for the struct's other attributes and for those of the objects nested in it (the
//!   nearest struct's field wins; the fields themselves keep 0 and 1):
//!
//!   | field | gives | to |
//!   |---|---|---|
//!   | `reliability`, `quality` | the reliability | every attribute |
//!   | `variability` | the variability | every numeric attribute |
//!   | `sigma` | the variability | the numeric attributes `x` and `y` (one standard deviation of a place) |
//!   | `f_sigma`, `sigma_f` | the variability | the numeric attributes of field `f`; with no field `f`, those named `f` (`sigma_xy`: `x` and `y`) |
//!
//!   Within one struct, a `f_sigma` rule wins over `sigma`, which wins over `variability`. A
//!   reliability is clamped to [0, 1] (NaN: 0), a variability made non-negative (NaN:
//!   infinite), so that the form always reads back. Symbols have variability 0. A `sigma`
//!   that is not a number (a pair such as `RobotSighting::sigma`) is an ordinary attribute.
//!
//! ```
//! use mrt_core::Time;
//! use mrt_dcdt::describe::{describe, SelfDescribing};
//! use serde::Serialize;
//!
//! #[derive(Serialize)]
//! enum Colour { Green, White }
//!
//! #[derive(Serialize)]
//! struct Anchor { distance: f64, bearing: f64, distance_sigma: f64, reliability: f64 }
//!
//! #[derive(Serialize)]
//! struct Percept {
//!     robot: u32,
//!     floor: Colour,
//!     wall: Anchor,
//!     ball: Option<Anchor>,
//!     landmarks: Vec<(f64, f64)>,
//!     image: Vec<u8>,
//! }
//!
//! let percept = Percept {
//!     robot: 2,
//!     floor: Colour::Green,
//!     wall: Anchor { distance: 2.4, bearing: 0.0, distance_sigma: 0.1, reliability: 0.9 },
//!     ball: None,
//!     landmarks: vec![(4.5, -0.25)],
//!     image: vec![0; 12],
//! };
//! let form = describe("percept", &percept, Time(12_500_000_000))?;
//! assert_eq!(
//!     form.to_xml(),
//!     r#"<message timestamp="12.500000000">
//!   <object name="percept" class="Percept">
//!     <attribute name="robot" value="2" variability="0" reliability="1"/>
//!     <attribute name="floor" symbol="Green" variability="0" reliability="1"/>
//!     <attribute name="landmarks[0][0]" value="4.5" variability="0" reliability="1"/>
//!     <attribute name="landmarks[0][1]" value="-0.25" variability="0" reliability="1"/>
//!     <attribute name="image" symbol="&lt;12 bytes&gt;" variability="0" reliability="1"/>
//!   </object>
//!   <object name="wall" class="Anchor">
//!     <attribute name="distance" value="2.4" variability="0.1" reliability="0.9"/>
//!     <attribute name="bearing" value="0" variability="0" reliability="0.9"/>
//!     <attribute name="distance_sigma" value="0.1" variability="0" reliability="1"/>
//!     <attribute name="reliability" value="0.9" variability="0" reliability="1"/>
//!   </object>
//! </message>"#
//! );
//! assert_eq!(SelfDescribing::from_xml(&form.to_xml())?, form);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::msg::{Message, RESERVED_TYPES_START};
use mrt_core::{MsgType, Time};
use quick_xml::errors::{Error as QxError, IllFormedError, SyntaxError};
use quick_xml::escape::EscapeError;
use quick_xml::events::attributes::{AttrError, Attribute as XmlAttr};
use quick_xml::events::{BytesEnd, BytesStart, Event};
use quick_xml::name::QName;
use quick_xml::{Reader, Writer};
use serde::{Deserialize, Serialize};
use std::borrow::Cow;
use std::fmt::Write as _;

/// The DTD of the XML form.
///
/// [`SelfDescribing::to_xml`] does not embed it; [`SelfDescribing::from_xml`] accepts (and
/// skips) a `<!DOCTYPE ...>` declaration, with or without this DTD as internal subset.
/// A DTD cannot say it, but each `<attribute>` carries exactly one of `value` (a number) and
/// `symbol` (a symbol of the shared ontology).
pub const DTD: &str = r#"<!ELEMENT message (object*)>
<!ATTLIST message
  timestamp CDATA #REQUIRED>
<!ELEMENT object (attribute*)>
<!ATTLIST object
  name CDATA #REQUIRED
  class CDATA #REQUIRED>
<!ELEMENT attribute EMPTY>
<!ATTLIST attribute
  name CDATA #REQUIRED
  value CDATA #IMPLIED
  symbol CDATA #IMPLIED
  variability CDATA #REQUIRED
  reliability CDATA #REQUIRED>
"#;

/// One self-describing message (§3.2): a time-stamp and a list of objects.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct SelfDescribing {
    /// When the described state was observed.
    pub timestamp: Time,
    /// The described objects, in order.
    pub objects: Vec<Object>,
}

impl Message for SelfDescribing {
    const TYPE: MsgType = MsgType(RESERVED_TYPES_START + 1);
    const NAME: &'static str = "SelfDescribing";
}

/// An object of a [`SelfDescribing`] message: a name, its membership class, and attributes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Object {
    /// The object's name, e.g. `"ball"`.
    pub name: String,
    /// The class the object belongs to, a symbol of the shared ontology, e.g. `"Ball"`.
    pub class: String,
    /// The object's attributes, in order.
    pub attributes: Vec<Attribute>,
}

/// An attribute of an [`Object`]: a tuple of name, value, variability and reliability.
///
/// [`SelfDescribing::from_xml`] accepts only a `variability` ≥ 0 (infinity included) and a
/// `reliability` in [0, 1]; the constructors do not check.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Attribute {
    /// The attribute's name, e.g. `"distance"`.
    pub name: String,
    /// The attribute's value.
    pub value: AttrValue,
    /// How much the value varies (e.g. a standard deviation, in the value's unit); ≥ 0.
    pub variability: f64,
    /// How far the value can be trusted, from 0 (not at all) to 1 (fully).
    pub reliability: f64,
}

/// The value of an [`Attribute`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum AttrValue {
    /// A number (`value="..."` in XML).
    Number(f64),
    /// A symbol of the shared ontology, e.g. `"yellow"` (`symbol="..."` in XML).
    Symbol(String),
}

/// Why [`SelfDescribing::from_xml`] rejected a text.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum XmlError {
    /// The text is not well-formed XML or does not follow [`DTD`] and the rules of the form.
    #[error("line {line}, column {column}: {message}")]
    Syntax {
        /// 1-based line of the offending markup.
        line: usize,
        /// 1-based column (in characters) of the offending markup.
        column: usize,
        /// What was expected, in lower case.
        message: String,
    },
}

impl SelfDescribing {
    /// An empty message stamped `timestamp`.
    pub fn new(timestamp: Time) -> Self {
        SelfDescribing { timestamp, objects: Vec::new() }
    }

    /// The message with `obj` appended to its objects.
    pub fn with_object(mut self, obj: Object) -> Self {
        self.objects.push(obj);
        self
    }

    /// The first object named `name`.
    pub fn object(&self, name: &str) -> Option<&Object> {
        self.objects.iter().find(|o| o.name == name)
    }

    /// The XML form, indented by 2 spaces, without XML declaration, DOCTYPE or final newline.
    ///
    /// The timestamp is written in seconds with 9 decimals, numbers with Rust's shortest
    /// round-trip formatting (`NaN`, `inf` and `-inf` for non-finite ones). In names, classes
    /// and symbols, `<`, `>`, `&`, `"` and control characters are escaped (the latter as
    /// character references); a NUL character, which XML cannot carry, is written as is.
    pub fn to_xml(&self) -> String {
        let mut writer = Writer::new_with_indent(Vec::new(), b' ', 2);
        // Writing into a `Vec` cannot fail.
        let _ = self.write_xml(&mut writer);
        match String::from_utf8(writer.into_inner()) {
            Ok(text) => text,
            Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
        }
    }

    fn write_xml(&self, w: &mut Writer<Vec<u8>>) -> std::io::Result<()> {
        let mut root = BytesStart::new("message");
        root.push_attribute(xml_attr("timestamp", format_timestamp(self.timestamp)));
        if self.objects.is_empty() {
            return w.write_event(Event::Empty(root));
        }
        w.write_event(Event::Start(root))?;
        for obj in &self.objects {
            let mut tag = BytesStart::new("object");
            tag.push_attribute(xml_attr("name", escape(&obj.name)));
            tag.push_attribute(xml_attr("class", escape(&obj.class)));
            if obj.attributes.is_empty() {
                w.write_event(Event::Empty(tag))?;
                continue;
            }
            w.write_event(Event::Start(tag))?;
            for attr in &obj.attributes {
                let mut tag = BytesStart::new("attribute");
                tag.push_attribute(xml_attr("name", escape(&attr.name)));
                match &attr.value {
                    AttrValue::Number(v) => tag.push_attribute(xml_attr("value", v.to_string())),
                    AttrValue::Symbol(s) => tag.push_attribute(xml_attr("symbol", escape(s))),
                }
                tag.push_attribute(xml_attr("variability", attr.variability.to_string()));
                tag.push_attribute(xml_attr("reliability", attr.reliability.to_string()));
                w.write_event(Event::Empty(tag))?;
            }
            w.write_event(Event::End(BytesEnd::new("object")))?;
        }
        w.write_event(Event::End(BytesEnd::new("message")))
    }

    /// Reads the XML form written by [`to_xml`](Self::to_xml).
    ///
    /// An XML declaration, a `<!DOCTYPE ...>`, comments, processing instructions and
    /// whitespace between elements are skipped; anything else that [`DTD`] does not allow is
    /// an error, as are a timestamp that is not non-negative seconds with at most 9 decimals,
    /// an attribute with neither or both of `value` and `symbol`, a negative variability and a
    /// reliability outside [0, 1]. Errors give the line and column of the offending element.
    pub fn from_xml(text: &str) -> Result<SelfDescribing, XmlError> {
        Parser::new(text).parse()
    }
}

impl Object {
    /// An object without attributes.
    pub fn new(name: impl Into<String>, class: impl Into<String>) -> Self {
        Object { name: name.into(), class: class.into(), attributes: Vec::new() }
    }

    /// The object with `attr` appended to its attributes.
    pub fn with(mut self, attr: Attribute) -> Self {
        self.attributes.push(attr);
        self
    }

    /// The first attribute named `name`.
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes.iter().find(|a| a.name == name)
    }
}

impl Attribute {
    /// A numeric attribute.
    pub fn number(name: impl Into<String>, value: f64, variability: f64, reliability: f64) -> Self {
        Attribute { name: name.into(), value: AttrValue::Number(value), variability, reliability }
    }

    /// A symbolic attribute: `value` is a symbol of the shared ontology.
    pub fn symbol(
        name: impl Into<String>,
        value: impl Into<String>,
        variability: f64,
        reliability: f64,
    ) -> Self {
        Attribute {
            name: name.into(),
            value: AttrValue::Symbol(value.into()),
            variability,
            reliability,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Writing

/// An XML attribute whose value is already escaped.
fn xml_attr(key: &str, escaped: String) -> XmlAttr<'_> {
    XmlAttr { key: QName(key.as_bytes()), value: Cow::Owned(escaped.into_bytes()) }
}

/// Escapes `s` for a double-quoted attribute value. Tabs, newlines and other control
/// characters become character references, so that they survive attribute-value
/// normalization.
fn escape(s: &str) -> String {
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

fn format_timestamp(t: Time) -> String {
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
fn line_column(text: &str, pos: u64) -> (usize, usize) {
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

struct Parser<'a> {
    text: &'a str,
    reader: Reader<&'a [u8]>,
}

impl<'a> Parser<'a> {
    fn new(text: &'a str) -> Self {
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
                SyntaxError::UnclosedPIOrXmlDecl => {
                    "expected `?>` to close the processing instruction, found end of input"
                        .to_owned()
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
                Event::Text(_) | Event::CData(_) => "text",
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
            let value = match attr.unescape_value() {
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

    fn parse(mut self) -> Result<SelfDescribing, XmlError> {
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

// ---------------------------------------------------------------------------------------------
// Generating the form of a typed message

/// Why [`describe`] could not give the self-describing form of a value.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DescribeError {
    /// A map key that is not a number or a symbol (a struct, a sequence, `None`): it cannot
    /// name an attribute.
    #[error("a map key must be a number or a symbol, found {found}")]
    MapKey {
        /// What the key is, e.g. `a struct`.
        found: &'static str,
    },
    /// The value nests deeper than [`MAX_DEPTH`] levels.
    #[error("the value nests deeper than {MAX_DEPTH} levels")]
    TooDeep,
    /// The value's `Serialize` implementation failed.
    #[error("the value could not be serialized: {0}")]
    Serialize(String),
}

impl serde::ser::Error for DescribeError {
    fn custom<M: std::fmt::Display>(msg: M) -> Self {
        DescribeError::Serialize(msg.to_string())
    }
}

/// How deeply a described value may nest (structs, sequences, maps, enums and options
/// together): deeper values are refused with [`DescribeError::TooDeep`] rather than risking the
/// stack.
pub const MAX_DEPTH: usize = 128;

/// The self-describing form of `value`, stamped `timestamp`, its first object named `name`.
///
/// The form is generated from the value's `Serialize` implementation, by the rules of the
/// [module documentation](self#the-form-of-a-typed-message); any value that serializes gives a
/// form that [`SelfDescribing::to_xml`] writes and [`SelfDescribing::from_xml`] reads back.
/// Errors: a map key that is not a number or a symbol, a value nested deeper than
/// [`MAX_DEPTH`], or a `Serialize` implementation that fails.
pub fn describe<T: Serialize + ?Sized>(
    name: &str,
    value: &T,
    timestamp: Time,
) -> Result<SelfDescribing, DescribeError> {
    let node = value.serialize(TreeSerializer { depth: 0 })?;
    let mut flat = Flattener { objects: Vec::new() };
    let root = Uncertainty { reliability: 1.0, rules: Vec::new() };
    match node {
        Node::Struct { class, fields } => flat.object(name, "", class, fields, &root)?,
        other => {
            flat.objects.push(Object::new(name, name));
            flat.walk(0, "", String::new(), "", other, &root, false)?;
        }
    }
    Ok(SelfDescribing { timestamp, objects: flat.objects })
}

impl SelfDescribing {
    /// The self-describing form of the bus message `msg` ([`describe`]), its first object
    /// named after the message type ([`Message::NAME`]).
    pub fn of_message<M: Message>(msg: &M, timestamp: Time) -> Result<Self, DescribeError> {
        describe(M::NAME, msg, timestamp)
    }
}

/// A serialized value before it is flattened into objects.
#[derive(Debug)]
enum Node {
    /// Any number (integers included).
    Number(f64),
    /// A `u8`: a number, unless it is an element of a byte sequence.
    Byte(u8),
    /// A bool, a string, a char or a unit enum variant.
    Symbol(String),
    /// A byte array, of this many bytes.
    Bytes(usize),
    /// `None` or `()`: left out.
    Absent,
    /// A struct, a unit or tuple struct, or an enum variant with data (`class`: the variant).
    Struct { class: String, fields: Vec<(String, Node)> },
    /// A sequence or a tuple.
    Seq(Vec<Node>),
    /// A map, its keys already turned into names.
    Map(Vec<(String, Node)>),
}

impl Node {
    fn kind(&self) -> &'static str {
        match self {
            Node::Number(_) | Node::Byte(_) => "a number",
            Node::Symbol(_) => "a symbol",
            Node::Bytes(_) => "bytes",
            Node::Absent => "nothing",
            Node::Struct { .. } => "a struct",
            Node::Seq(_) => "a sequence",
            Node::Map(_) => "a map",
        }
    }
}

/// Builds the [`Node`] tree of a value.
struct TreeSerializer {
    depth: usize,
}

impl TreeSerializer {
    fn deeper(&self) -> Result<TreeSerializer, DescribeError> {
        if self.depth >= MAX_DEPTH {
            return Err(DescribeError::TooDeep);
        }
        Ok(TreeSerializer { depth: self.depth + 1 })
    }
}

/// `node`, a number if it is a byte.
fn not_byte(node: Node) -> Node {
    match node {
        Node::Byte(b) => Node::Number(f64::from(b)),
        other => other,
    }
}

/// The elements of a sequence or a tuple; a sequence of `u8` is kept as bytes.
struct SeqBuilder {
    inner: TreeSerializer,
    items: Vec<Node>,
    bytes: Vec<u8>,
    /// Whether `u8` elements are kept as bytes (sequences, not tuples).
    byte_seq: bool,
}

impl SeqBuilder {
    fn new(inner: TreeSerializer, byte_seq: bool, len: Option<usize>) -> Self {
        let items = Vec::with_capacity(len.unwrap_or(0).min(64));
        SeqBuilder { inner, items, bytes: Vec::new(), byte_seq }
    }

    fn push<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), DescribeError> {
        let node = value.serialize(TreeSerializer { depth: self.inner.depth })?;
        match node {
            Node::Byte(b) if self.byte_seq && self.items.is_empty() => self.bytes.push(b),
            node => {
                // Not bytes after all: the bytes seen so far are numbers.
                self.items.extend(self.bytes.drain(..).map(|b| Node::Number(f64::from(b))));
                self.items.push(node);
            }
        }
        Ok(())
    }

    fn finish(self) -> Node {
        if self.items.is_empty() && !self.bytes.is_empty() {
            Node::Bytes(self.bytes.len())
        } else {
            Node::Seq(self.items)
        }
    }
}

/// The fields of a struct or of an enum variant with data.
struct StructBuilder {
    inner: TreeSerializer,
    class: String,
    fields: Vec<(String, Node)>,
}

impl StructBuilder {
    fn push<T: Serialize + ?Sized>(&mut self, key: String, value: &T) -> Result<(), DescribeError> {
        let node = value.serialize(TreeSerializer { depth: self.inner.depth })?;
        self.fields.push((key, node));
        Ok(())
    }

    fn finish(self) -> Node {
        Node::Struct { class: self.class, fields: self.fields }
    }
}

/// The entries of a map.
struct MapBuilder {
    inner: TreeSerializer,
    entries: Vec<(String, Node)>,
    key: Option<String>,
}

/// A map key as a name: a symbol as is, a number as written in the form.
fn key_name(node: Node) -> Result<String, DescribeError> {
    match node {
        Node::Symbol(s) => Ok(s),
        Node::Number(v) => Ok(v.to_string()),
        Node::Byte(b) => Ok(b.to_string()),
        other => Err(DescribeError::MapKey { found: other.kind() }),
    }
}

impl serde::Serializer for TreeSerializer {
    type Ok = Node;
    type Error = DescribeError;
    type SerializeSeq = SeqBuilder;
    type SerializeTuple = SeqBuilder;
    type SerializeTupleStruct = StructBuilder;
    type SerializeTupleVariant = StructBuilder;
    type SerializeMap = MapBuilder;
    type SerializeStruct = StructBuilder;
    type SerializeStructVariant = StructBuilder;

    fn serialize_bool(self, v: bool) -> Result<Node, DescribeError> {
        Ok(Node::Symbol(v.to_string()))
    }
    fn serialize_i8(self, v: i8) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    fn serialize_i16(self, v: i16) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    fn serialize_i32(self, v: i32) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    #[allow(clippy::cast_precision_loss)]
    fn serialize_i64(self, v: i64) -> Result<Node, DescribeError> {
        Ok(Node::Number(v as f64))
    }
    #[allow(clippy::cast_precision_loss)]
    fn serialize_i128(self, v: i128) -> Result<Node, DescribeError> {
        Ok(Node::Number(v as f64))
    }
    fn serialize_u8(self, v: u8) -> Result<Node, DescribeError> {
        Ok(Node::Byte(v))
    }
    fn serialize_u16(self, v: u16) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    fn serialize_u32(self, v: u32) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    #[allow(clippy::cast_precision_loss)]
    fn serialize_u64(self, v: u64) -> Result<Node, DescribeError> {
        Ok(Node::Number(v as f64))
    }
    #[allow(clippy::cast_precision_loss)]
    fn serialize_u128(self, v: u128) -> Result<Node, DescribeError> {
        Ok(Node::Number(v as f64))
    }
    fn serialize_f32(self, v: f32) -> Result<Node, DescribeError> {
        Ok(Node::Number(f64::from(v)))
    }
    fn serialize_f64(self, v: f64) -> Result<Node, DescribeError> {
        Ok(Node::Number(v))
    }
    fn serialize_char(self, v: char) -> Result<Node, DescribeError> {
        Ok(Node::Symbol(v.to_string()))
    }
    fn serialize_str(self, v: &str) -> Result<Node, DescribeError> {
        Ok(Node::Symbol(v.to_owned()))
    }
    fn serialize_bytes(self, v: &[u8]) -> Result<Node, DescribeError> {
        Ok(Node::Bytes(v.len()))
    }
    fn serialize_none(self) -> Result<Node, DescribeError> {
        Ok(Node::Absent)
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<Node, DescribeError> {
        // Only a bare `u8` is a byte: `Vec<Option<u8>>` is a sequence of numbers.
        Ok(not_byte(value.serialize(self.deeper()?)?))
    }
    fn serialize_unit(self) -> Result<Node, DescribeError> {
        Ok(Node::Absent)
    }
    fn serialize_unit_struct(self, name: &'static str) -> Result<Node, DescribeError> {
        Ok(Node::Struct { class: name.to_owned(), fields: Vec::new() })
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
    ) -> Result<Node, DescribeError> {
        Ok(Node::Symbol(variant.to_owned()))
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        name: &'static str,
        value: &T,
    ) -> Result<Node, DescribeError> {
        // A newtype is its value; a struct wrapped in it takes the newtype's name.
        match value.serialize(self.deeper()?)? {
            Node::Struct { fields, .. } => Ok(Node::Struct { class: name.to_owned(), fields }),
            other => Ok(not_byte(other)),
        }
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<Node, DescribeError> {
        let node = value.serialize(self.deeper()?)?;
        Ok(Node::Struct { class: variant.to_owned(), fields: vec![("0".to_owned(), node)] })
    }
    fn serialize_seq(self, len: Option<usize>) -> Result<SeqBuilder, DescribeError> {
        Ok(SeqBuilder::new(self.deeper()?, true, len))
    }
    fn serialize_tuple(self, len: usize) -> Result<SeqBuilder, DescribeError> {
        Ok(SeqBuilder::new(self.deeper()?, false, Some(len)))
    }
    fn serialize_tuple_struct(
        self,
        name: &'static str,
        len: usize,
    ) -> Result<StructBuilder, DescribeError> {
        let fields = Vec::with_capacity(len.min(64));
        Ok(StructBuilder { inner: self.deeper()?, class: name.to_owned(), fields })
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        len: usize,
    ) -> Result<StructBuilder, DescribeError> {
        let fields = Vec::with_capacity(len.min(64));
        Ok(StructBuilder { inner: self.deeper()?, class: variant.to_owned(), fields })
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<MapBuilder, DescribeError> {
        Ok(MapBuilder { inner: self.deeper()?, entries: Vec::new(), key: None })
    }
    fn serialize_struct(
        self,
        name: &'static str,
        len: usize,
    ) -> Result<StructBuilder, DescribeError> {
        let fields = Vec::with_capacity(len.min(64));
        Ok(StructBuilder { inner: self.deeper()?, class: name.to_owned(), fields })
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        variant: &'static str,
        len: usize,
    ) -> Result<StructBuilder, DescribeError> {
        let fields = Vec::with_capacity(len.min(64));
        Ok(StructBuilder { inner: self.deeper()?, class: variant.to_owned(), fields })
    }
}

impl serde::ser::SerializeSeq for SeqBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Self::Error> {
        self.push(value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeTuple for SeqBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Self::Error> {
        self.push(value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeTupleStruct for StructBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Self::Error> {
        self.push(self.fields.len().to_string(), value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeTupleVariant for StructBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Self::Error> {
        self.push(self.fields.len().to_string(), value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeStruct for StructBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Self::Error> {
        self.push(key.to_owned(), value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeStructVariant for StructBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Self::Error> {
        self.push(key.to_owned(), value)
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(self.finish())
    }
}

impl serde::ser::SerializeMap for MapBuilder {
    type Ok = Node;
    type Error = DescribeError;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Self::Error> {
        let node = key.serialize(TreeSerializer { depth: self.inner.depth })?;
        self.key = Some(key_name(node)?);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Self::Error> {
        let node = value.serialize(TreeSerializer { depth: self.inner.depth })?;
        let key = self.key.take().unwrap_or_default();
        self.entries.push((key, node));
        Ok(())
    }
    fn end(self) -> Result<Node, DescribeError> {
        Ok(Node::Map(self.entries))
    }
}

/// A rule giving a variability to numeric attributes, from a field of an enclosing object.
#[derive(Clone, Debug)]
enum VarRule {
    /// Every numeric attribute (`variability`; `<f>_sigma` below field `f`).
    All(f64),
    /// The attributes of field `.0` of the object that holds the rule and the objects below it
    /// (`<f>_sigma`, `sigma_<f>`).
    Field(String, f64),
    /// The attributes named one of `.0` (`sigma_<f>` when `f` is no field; `sigma`: `x` and
    /// `y`).
    Named(Vec<String>, f64),
}

/// What an object's attributes inherit: the reliability and the variability rules, nearest
/// first.
#[derive(Clone, Debug)]
struct Uncertainty {
    reliability: f64,
    rules: Vec<VarRule>,
}

impl Uncertainty {
    /// The variability of a numeric attribute of field `field`, whose last name is `leaf`.
    fn variability(&self, field: &str, leaf: &str) -> f64 {
        for rule in &self.rules {
            match rule {
                VarRule::All(v) => return *v,
                VarRule::Field(f, v) if f == field => return *v,
                VarRule::Named(names, v) if names.iter().any(|n| n == leaf) => return *v,
                _ => {}
            }
        }
        0.0
    }

    /// What the objects below field `field` inherit.
    fn below(&self, field: &str) -> Uncertainty {
        let rules = self
            .rules
            .iter()
            .filter_map(|rule| match rule {
                VarRule::Field(f, v) if f == field => Some(VarRule::All(*v)),
                VarRule::Field(..) => None,
                other => Some(other.clone()),
            })
            .collect();
        Uncertainty { reliability: self.reliability, rules }
    }
}

/// A reliability as the form allows it: in [0, 1], NaN (unknown) as 0.
fn sane_reliability(v: f64) -> f64 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(0.0, 1.0)
    }
}

/// A variability as the form allows it: non-negative, NaN (unknown) as infinite.
fn sane_variability(v: f64) -> f64 {
    if v.is_nan() {
        f64::INFINITY
    } else {
        v.abs()
    }
}

/// What a numeric field of a struct says about the uncertainty of the others, if anything.
enum Source {
    Reliability(f64),
    Variability(VarRule),
}

fn source(field: &str, value: f64, fields: &[(String, Node)]) -> Option<Source> {
    let var = sane_variability(value);
    let names = |list: &[&str]| list.iter().map(|&n| n.to_owned()).collect();
    let target = |f: &str| {
        if fields.iter().any(|(name, _)| name == f) {
            VarRule::Field(f.to_owned(), var)
        } else if f == "xy" {
            VarRule::Named(names(&["x", "y"]), var)
        } else {
            VarRule::Named(names(&[f]), var)
        }
    };
    match field {
        "reliability" | "quality" => Some(Source::Reliability(sane_reliability(value))),
        "variability" => Some(Source::Variability(VarRule::All(var))),
        "sigma" => Some(Source::Variability(VarRule::Named(names(&["x", "y"]), var))),
        _ => {
            let f = field.strip_prefix("sigma_").or_else(|| field.strip_suffix("_sigma"))?;
            (!f.is_empty()).then(|| Source::Variability(target(f)))
        }
    }
}

/// The name of an attribute without its indices and the path above it: `pose` for
/// `mates[2].pose[0]`.
fn leaf_name(path: &str) -> &str {
    let last = path.rsplit('.').next().unwrap_or(path);
    last.split('[').next().unwrap_or(last)
}

/// `path` followed by field or key `name`.
fn join(path: &str, name: &str) -> String {
    if path.is_empty() {
        name.to_owned()
    } else {
        format!("{path}.{name}")
    }
}

/// Flattens a [`Node`] tree into the objects of a form.
struct Flattener {
    objects: Vec<Object>,
}

impl Flattener {
    /// Appends the object `name` of class `class` and, after it, the objects nested in it,
    /// named from `path` (`""` for the message itself, `name` otherwise).
    fn object(
        &mut self,
        name: &str,
        path: &str,
        class: String,
        fields: Vec<(String, Node)>,
        inherited: &Uncertainty,
    ) -> Result<(), DescribeError> {
        let mut own = Uncertainty { reliability: inherited.reliability, rules: Vec::new() };
        let mut sources = Vec::new();
        for (name, node) in &fields {
            let value = match node {
                Node::Number(v) => *v,
                Node::Byte(b) => f64::from(*b),
                _ => continue,
            };
            match source(name, value, &fields) {
                Some(Source::Reliability(r)) => own.reliability = r,
                Some(Source::Variability(rule)) => own.rules.push(rule),
                None => continue,
            }
            sources.push(name.clone());
        }
        // The object's own rules first, the most specific first; then the inherited ones.
        own.rules.sort_by_key(|rule| match rule {
            VarRule::Field(..) => 0,
            VarRule::Named(..) => 1,
            VarRule::All(_) => 2,
        });
        own.rules.extend(inherited.rules.iter().cloned());
        let index = self.objects.len();
        self.objects.push(Object::new(name, class));
        for (field, node) in fields {
            let is_source = sources.contains(&field);
            self.walk(index, path, field.clone(), &field, node, &own, is_source)?;
        }
        Ok(())
    }

    /// Adds what `node` holds, reached by `rel` from object `index` (named `path`) through its
    /// field `field`: attributes to the object, objects after it.
    #[allow(clippy::too_many_arguments)]
    fn walk(
        &mut self,
        index: usize,
        path: &str,
        rel: String,
        field: &str,
        node: Node,
        unc: &Uncertainty,
        is_source: bool,
    ) -> Result<(), DescribeError> {
        let name = if rel.is_empty() { "value".to_owned() } else { rel.clone() };
        let attribute = match node {
            Node::Absent => return Ok(()),
            Node::Number(v) => number(name, v, field, unc, is_source),
            Node::Byte(b) => number(name, f64::from(b), field, unc, is_source),
            Node::Symbol(s) => Attribute::symbol(name, s, 0.0, unc.reliability),
            Node::Bytes(n) => Attribute::symbol(name, format!("<{n} bytes>"), 0.0, unc.reliability),
            Node::Seq(items) => {
                for (i, item) in items.into_iter().enumerate() {
                    self.walk(index, path, format!("{rel}[{i}]"), field, item, unc, false)?;
                }
                return Ok(());
            }
            Node::Map(entries) => {
                for (key, item) in entries {
                    self.walk(index, path, join(&rel, &key), field, item, unc, false)?;
                }
                return Ok(());
            }
            Node::Struct { class, fields } => {
                let below = unc.below(field);
                let name = join(path, &rel);
                return self.object(&name, &name, class, fields, &below);
            }
        };
        if let Some(object) = self.objects.get_mut(index) {
            object.attributes.push(attribute);
        }
        Ok(())
    }
}

/// A numeric attribute with its variability and reliability.
fn number(name: String, v: f64, field: &str, unc: &Uncertainty, is_source: bool) -> Attribute {
    if is_source {
        return Attribute::number(name, v, 0.0, 1.0);
    }
    let variability = unc.variability(field, leaf_name(&name));
    Attribute::number(name, v, variability, unc.reliability)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const EXAMPLE: &str = r#"<message timestamp="12.500000000">
  <object name="ball" class="Ball">
    <attribute name="distance" value="2.4" variability="0.1" reliability="0.9"/>
    <attribute name="colour" symbol="orange" variability="0" reliability="1"/>
  </object>
</message>"#;

    fn example() -> SelfDescribing {
        SelfDescribing::new(Time(12_500_000_000)).with_object(
            Object::new("ball", "Ball")
                .with(Attribute::number("distance", 2.4, 0.1, 0.9))
                .with(Attribute::symbol("colour", "orange", 0.0, 1.0)),
        )
    }

    /// The error message `from_xml` gives for `text`, which must be rejected.
    fn err(text: &str) -> String {
        match SelfDescribing::from_xml(text) {
            Ok(m) => panic!("accepted {text:?} as {m:?}"),
            Err(e) => e.to_string(),
        }
    }

    /// `EXAMPLE` with `from` (which must occur) replaced by `to`.
    fn example_with(from: &str, to: &str) -> String {
        assert!(EXAMPLE.contains(from), "{from:?} not in the example");
        EXAMPLE.replacen(from, to, 1)
    }

    #[test]
    fn hand_written_xml_parses_to_the_expected_message() -> Result<(), XmlError> {
        let expected = SelfDescribing {
            timestamp: Time(12_500_000_000),
            objects: vec![Object {
                name: "ball".to_owned(),
                class: "Ball".to_owned(),
                attributes: vec![
                    Attribute {
                        name: "distance".to_owned(),
                        value: AttrValue::Number(2.4),
                        variability: 0.1,
                        reliability: 0.9,
                    },
                    Attribute {
                        name: "colour".to_owned(),
                        value: AttrValue::Symbol("orange".to_owned()),
                        variability: 0.0,
                        reliability: 1.0,
                    },
                ],
            }],
        };
        assert_eq!(SelfDescribing::from_xml(EXAMPLE)?, expected);
        assert_eq!(example(), expected);
        Ok(())
    }

    #[test]
    fn to_xml_writes_the_exact_form() {
        assert_eq!(example().to_xml(), EXAMPLE);
    }

    #[test]
    fn module_doc_example() -> Result<(), XmlError> {
        // The module's doctest, with the scratch paths.
        let msg = example();
        let xml = msg.to_xml();
        assert_eq!(xml, EXAMPLE);
        assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
        Ok(())
    }

    #[test]
    fn empty_message_and_object_use_empty_elements() -> Result<(), XmlError> {
        let empty = SelfDescribing::default();
        assert_eq!(empty.to_xml(), r#"<message timestamp="0.000000000"/>"#);
        assert_eq!(SelfDescribing::from_xml(&empty.to_xml())?, empty);

        let msg = SelfDescribing::new(Time(1)).with_object(Object::new("a", "B"));
        let xml = msg.to_xml();
        assert_eq!(
            xml,
            "<message timestamp=\"0.000000001\">\n  <object name=\"a\" class=\"B\"/>\n</message>"
        );
        assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
        Ok(())
    }

    #[test]
    fn special_characters_are_escaped() -> Result<(), XmlError> {
        let msg = SelfDescribing::new(Time(0)).with_object(
            Object::new("a<b>&\"c'", "tab\there\nnew line")
                .with(Attribute::symbol("s", "x&y", 0.0, 1.0)),
        );
        let xml = msg.to_xml();
        assert_eq!(
            xml,
            "<message timestamp=\"0.000000000\">\n  \
             <object name=\"a&lt;b&gt;&amp;&quot;c'\" class=\"tab&#9;here&#10;new line\">\n    \
             <attribute name=\"s\" symbol=\"x&amp;y\" variability=\"0\" reliability=\"1\"/>\n  \
             </object>\n</message>"
        );
        assert_eq!(SelfDescribing::from_xml(&xml)?, msg);
        Ok(())
    }

    #[test]
    fn lookups_and_message_identity() {
        let msg = example();
        let ball = msg.object("ball");
        assert_eq!(ball.map(|o| o.class.as_str()), Some("Ball"));
        assert!(msg.object("goal").is_none());
        assert_eq!(
            ball.and_then(|o| o.attribute("colour")).map(|a| &a.value),
            Some(&AttrValue::Symbol("orange".to_owned()))
        );
        assert!(ball.and_then(|o| o.attribute("speed")).is_none());
        assert_eq!(SelfDescribing::TYPE, MsgType(0xFFFF_0001));
        assert_eq!(SelfDescribing::NAME, "SelfDescribing");
    }

    #[test]
    fn non_finite_numbers_round_trip() -> Result<(), XmlError> {
        let msg = SelfDescribing::new(Time(5)).with_object(
            Object::new("o", "C")
                .with(Attribute::number("nan", f64::NAN, f64::INFINITY, 0.5))
                .with(Attribute::number("inf", f64::INFINITY, 0.0, 0.5))
                .with(Attribute::number("-inf", f64::NEG_INFINITY, 0.0, 0.5)),
        );
        let xml = msg.to_xml();
        assert!(xml.contains(r#"value="NaN" variability="inf""#), "{xml}");
        assert!(xml.contains(r#"value="inf""#), "{xml}");
        assert!(xml.contains(r#"value="-inf""#), "{xml}");
        let back = SelfDescribing::from_xml(&xml)?;
        let attrs = &back.objects[0].attributes;
        assert!(matches!(attrs[0].value, AttrValue::Number(v) if v.is_nan()));
        assert_eq!(attrs[0].variability, f64::INFINITY);
        assert_eq!(attrs[1].value, AttrValue::Number(f64::INFINITY));
        assert_eq!(attrs[2].value, AttrValue::Number(f64::NEG_INFINITY));
        // Written by hand, too.
        let back = SelfDescribing::from_xml(&example_with(r#"value="2.4""#, r#"value="NaN""#))?;
        let value = &back.objects[0].attributes[0].value;
        assert!(matches!(value, AttrValue::Number(v) if v.is_nan()));
        Ok(())
    }

    #[test]
    fn timestamps_are_exact() -> Result<(), XmlError> {
        for (text, nanos) in [
            ("12.500000000", 12_500_000_000),
            ("12.5", 12_500_000_000),
            ("12", 12_000_000_000),
            ("0.000000001", 1),
            ("007.000000010", 7_000_000_010),
            (" 3.25 ", 3_250_000_000),
            ("18446744073.709551615", u64::MAX),
        ] {
            let xml = format!(r#"<message timestamp="{text}"/>"#);
            assert_eq!(SelfDescribing::from_xml(&xml)?.timestamp, Time(nanos), "{text}");
        }
        for nanos in [0, 1, 999_999_999, 1_000_000_000, 123_456_789_012_345_678, u64::MAX] {
            let msg = SelfDescribing::new(Time(nanos));
            assert_eq!(SelfDescribing::from_xml(&msg.to_xml())?, msg);
        }
        assert_eq!(
            SelfDescribing::new(Time(u64::MAX)).to_xml(),
            r#"<message timestamp="18446744073.709551615"/>"#
        );
        Ok(())
    }

    #[test]
    fn bad_timestamps_are_rejected() {
        for bad in [
            "-1.0",
            "+1.0",
            "1.5e3",
            "abc",
            "",
            "1.",
            ".5",
            "1.0000000001",
            "1,5",
            "NaN",
            "inf",
            "1 .5",
        ] {
            assert_eq!(
                err(&format!(r#"<message timestamp="{bad}"/>"#)),
                format!(
                    "line 1, column 1: <message>: expected `timestamp` as non-negative seconds \
                     with at most 9 decimals, found {bad:?}"
                ),
            );
        }
        for bad in ["18446744073.709551616", "99999999999999999999999"] {
            assert_eq!(
                err(&format!(r#"<message timestamp="{bad}"/>"#)),
                format!(
                    "line 1, column 1: <message>: expected `timestamp` of at most \
                     18446744073.709551615 seconds, found {bad:?}"
                ),
            );
        }
        assert_eq!(err("\n\n  <message/>"), "line 3, column 3: <message>: expected `timestamp`");
        assert_eq!(
            err(&example_with("timestamp=\"12.500000000\"", "timestamp=\"12.5x\"")),
            "line 1, column 1: <message>: expected `timestamp` as non-negative seconds with at \
             most 9 decimals, found \"12.5x\""
        );
    }

    #[test]
    fn missing_reliability() {
        assert_eq!(
            err(&example_with(r#" reliability="0.9""#, "")),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected `reliability`"
        );
    }

    #[test]
    fn reliability_out_of_range() {
        for bad in ["1.5", "-0.1", "NaN", "high"] {
            assert_eq!(
                err(&example_with(r#"reliability="1""#, &format!(r#"reliability="{bad}""#))),
                format!(
                    "line 4, column 5: attribute \"colour\" of object \"ball\": expected \
                     `reliability` between 0 and 1, found {bad:?}"
                )
            );
        }
    }

    #[test]
    fn variability_must_be_non_negative() {
        assert_eq!(
            err(&example_with(r#"variability="0.1""#, r#"variability="-0.1""#)),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected `variability` \
             to be a non-negative number, found \"-0.1\""
        );
        assert_eq!(
            err(&example_with(r#" variability="0.1""#, "")),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected `variability`"
        );
    }

    #[test]
    fn value_xor_symbol() {
        assert_eq!(
            err(&example_with(r#"value="2.4""#, r#"value="2.4" symbol="far""#)),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected `value` or \
             `symbol`, not both"
        );
        assert_eq!(
            err(&example_with(r#" value="2.4""#, "")),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected `value` or \
             `symbol`"
        );
        assert_eq!(
            err(&example_with(r#"value="2.4""#, r#"value="far""#)),
            "line 3, column 5: attribute \"distance\" of object \"ball\": expected a number in \
             `value`, found \"far\""
        );
    }

    #[test]
    fn missing_or_unknown_xml_attributes() {
        assert_eq!(
            err(&example_with(r#"<attribute name="distance""#, "<attribute")),
            "line 3, column 5: <attribute> of object \"ball\": expected `name`"
        );
        assert_eq!(
            err(&example_with(r#"name="ball" "#, "")),
            "line 2, column 3: <object>: expected `name`"
        );
        assert_eq!(
            err(&example_with(r#" class="Ball""#, "")),
            "line 2, column 3: object \"ball\": expected `class`"
        );
        assert_eq!(
            err(&example_with(r#"class="Ball""#, r#"class="Ball" colour="red""#)),
            "line 2, column 3: object \"ball\": expected only `name` and `class`, found `colour`"
        );
        assert_eq!(
            err(&example_with(r#"reliability="1""#, r#"reliability="1" unit="m""#)),
            "line 4, column 5: attribute \"colour\" of object \"ball\": expected only `name`, \
             `value`, `symbol`, `variability` and `reliability`, found `unit`"
        );
        assert_eq!(
            err(&example_with("<message ", "<message version=\"2\" ")),
            "line 1, column 1: <message>: expected only `timestamp`, found `version`"
        );
        assert_eq!(
            err(&example_with(r#"class="Ball""#, r#"class="Ball" name="bat""#)),
            "line 2, column 36: <object>: expected each attribute once, found a second `name`"
        );
    }

    #[test]
    fn unknown_elements() {
        assert_eq!(
            err(&example_with(
                r#"<attribute name="colour" symbol="orange" variability="0" reliability="1"/>"#,
                "<foo/>"
            )),
            "line 4, column 5: expected <attribute>, found <foo>"
        );
        assert_eq!(
            err(&example_with("<object", "<thing")),
            "line 2, column 3: expected <object>, found <thing>"
        );
        assert_eq!(
            err(r#"<msg timestamp="1"/>"#),
            "line 1, column 1: expected <message>, found <msg>"
        );
        assert_eq!(
            err(&format!("{EXAMPLE}\n<message timestamp=\"1\"/>")),
            "line 7, column 1: expected end of input, found <message>"
        );
        assert_eq!(
            err(&example_with("<attribute name=\"colour\"", "text <attribute name=\"colour\"")),
            "line 3, column 81: expected <attribute> or </object>, found text"
        );
    }

    #[test]
    fn malformed_xml() {
        // An unclosed tag: the input ends inside `<object ...`.
        let cut = EXAMPLE.find(" class").unwrap_or_default();
        assert_eq!(
            err(&EXAMPLE[..cut]),
            "line 2, column 3: expected `>` to close the tag, found end of input"
        );
        // Elements left open at the end of the input.
        let cut = EXAMPLE.rfind("\n</message>").unwrap_or_default();
        assert_eq!(
            err(&EXAMPLE[..cut]),
            "line 5, column 12: expected </message>, found end of input"
        );
        let cut = EXAMPLE.find("\n  </object>").unwrap_or_default();
        assert_eq!(
            err(&EXAMPLE[..cut]),
            "line 4, column 79: expected </object>, found end of input"
        );
        // A mismatched end tag.
        assert_eq!(
            err(&example_with("</object>", "</objet>")),
            "line 5, column 3: expected </object>, found </objet>"
        );
        assert_eq!(err(""), "line 1, column 1: expected <message>, found end of input");
        assert_eq!(err("hello"), "line 1, column 1: expected <message>, found text");
        assert_eq!(
            err(&example_with(r#"value="2.4""#, "value=2.4")),
            "line 3, column 38: <attribute> of object \"ball\": expected a quoted attribute \
             value, found an unquoted one"
        );
        assert_eq!(
            err(&example_with(r#"symbol="orange""#, r#"symbol="&orange;""#)),
            "line 4, column 5: <attribute> of object \"ball\": in `symbol`, expected a \
             predefined entity, found `&orange;`"
        );
        assert_eq!(
            err("<!-- open\n<message/>"),
            "line 1, column 1: expected `-->` to close the comment, found end of input"
        );
    }

    #[test]
    fn columns_count_characters() {
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
        assert_eq!(line_column("é\né€x", 8), (2, 3));
        assert_eq!(line_column("abc", 99), (1, 4));
        assert_eq!(line_column("", 0), (1, 1));
        assert_eq!(
            err("<message timestamp=\"1\">\n<!--é€--><obj/>"),
            "line 2, column 10: expected <object>, found <obj>"
        );
    }

    #[test]
    fn prolog_doctype_comments_and_open_attribute_elements_are_accepted() -> Result<(), XmlError> {
        let with_dtd = format!(
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE message [\n{DTD}]>\n\
             <!-- a comment -->\n{EXAMPLE}\n<!-- the end -->\n"
        );
        assert_eq!(SelfDescribing::from_xml(&with_dtd)?, example());
        let with_system = format!("<!DOCTYPE message SYSTEM \"describe.dtd\">{EXAMPLE}");
        assert_eq!(SelfDescribing::from_xml(&with_system)?, example());
        let open = example_with(
            r#"reliability="1"/>"#,
            "reliability=\"1\">\n      <!-- nothing -->\n    </attribute>",
        );
        assert_eq!(SelfDescribing::from_xml(&open)?, example());
        assert_eq!(
            err(&format!("{EXAMPLE}<!DOCTYPE message>")),
            "line 6, column 11: expected end of input, found a doctype"
        );
        assert_eq!(
            err(&example_with(r#"reliability="1"/>"#, r#"reliability="1">x</attribute>"#)),
            "line 4, column 78: expected </attribute>, found text"
        );
        Ok(())
    }

    #[test]
    fn postcard_round_trip() -> Result<(), postcard::Error> {
        let msg = example().with_object(
            Object::new("robot", "Robot").with(Attribute::number("x", -1e-300, 1e300, 0.0)),
        );
        let bytes = postcard::to_stdvec(&msg)?;
        let back: SelfDescribing = postcard::from_bytes(&bytes)?;
        assert_eq!(back, msg);
        Ok(())
    }

    fn text() -> impl Strategy<Value = String> {
        prop_oneof!["[a-zA-Z0-9 _<>&\"'\t\n\r=/;#\u{e9}\u{4e2d}\u{1F916}-]{0,12}", any::<String>(),]
    }

    fn number() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>().prop_filter("NaN is never equal", |v| !v.is_nan()),
            -1e6..1e6f64,
            prop::sample::select(vec![
                0.0,
                -0.0,
                -2.5,
                1e300,
                -1e300,
                5e-324,
                -5e-324,
                f64::MAX,
                f64::MIN,
                f64::MIN_POSITIVE,
                f64::EPSILON,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ]),
        ]
    }

    fn attribute() -> impl Strategy<Value = Attribute> {
        let value =
            prop_oneof![number().prop_map(AttrValue::Number), text().prop_map(AttrValue::Symbol)];
        let variability =
            prop_oneof![0.0..1e3f64, number().prop_map(f64::abs), Just(f64::INFINITY)];
        let reliability = prop_oneof![0.0..=1.0f64, Just(0.0), Just(1.0)];
        (text(), value, variability, reliability).prop_map(
            |(name, value, variability, reliability)| Attribute {
                name,
                value,
                variability,
                reliability,
            },
        )
    }

    fn message() -> impl Strategy<Value = SelfDescribing> {
        let object = (text(), text(), prop::collection::vec(attribute(), 0..4))
            .prop_map(|(name, class, attributes)| Object { name, class, attributes });
        (any::<u64>(), prop::collection::vec(object, 0..4))
            .prop_map(|(nanos, objects)| SelfDescribing { timestamp: Time(nanos), objects })
    }

    fn xml_like() -> impl Strategy<Value = String> {
        "(<|</|/>|>|=|\"|'| |\n|&|&amp;|&#|;|<!--|-->|<!DOCTYPE|<\\?|\\?>|]>|message|object\
         |attribute|name|class|value|symbol|variability|reliability|timestamp|[0-9.e+-]|é|x){0,60}"
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        #[test]
        fn xml_round_trip(m in message()) {
            let xml = m.to_xml();
            let back = SelfDescribing::from_xml(&xml)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
            prop_assert_eq!(back, m);
        }

        #[test]
        fn postcard_round_trip_any(m in message()) {
            let bytes = postcard::to_stdvec(&m).map_err(|e| TestCaseError::fail(e.to_string()))?;
            let back: SelfDescribing =
                postcard::from_bytes(&bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(back, m);
        }

        #[test]
        fn arbitrary_strings_never_panic(text in any::<String>()) {
            let _ = SelfDescribing::from_xml(&text);
        }

        #[test]
        fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..512)) {
            let _ = SelfDescribing::from_xml(&String::from_utf8_lossy(&bytes));
        }

        #[test]
        fn xml_like_text_never_panics(text in xml_like()) {
            let _ = SelfDescribing::from_xml(&text);
        }

        #[test]
        fn damaged_messages_never_panic(
            m in message(),
            cut in any::<prop::sample::Index>(),
            at in any::<prop::sample::Index>(),
            insert in "[<>/=\"'&;! a-z]{0,3}",
        ) {
            let xml = m.to_xml();
            let chars: Vec<char> = xml.chars().collect();
            let cut = cut.index(chars.len() + 1);
            let truncated: String = chars[..cut].iter().collect();
            let _ = SelfDescribing::from_xml(&truncated);
            let at = at.index(chars.len() + 1);
            let mut damaged: String = chars[..at].iter().collect();
            damaged.push_str(&insert);
            damaged.extend(&chars[at..]);
            let _ = SelfDescribing::from_xml(&damaged);
        }
    }
}

/// The forms generated from types ([`describe`]).
#[cfg(test)]
mod generated {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    /// Whether two forms are equal, a NaN equal to a NaN.
    fn same(a: &SelfDescribing, b: &SelfDescribing) -> bool {
        let number = |x: f64, y: f64| x == y || (x.is_nan() && y.is_nan());
        a.timestamp == b.timestamp
            && a.objects.len() == b.objects.len()
            && a.objects.iter().zip(&b.objects).all(|(o, p)| {
                o.name == p.name
                    && o.class == p.class
                    && o.attributes.len() == p.attributes.len()
                    && o.attributes.iter().zip(&p.attributes).all(|(x, y)| {
                        x.name == y.name
                            && number(x.variability, y.variability)
                            && number(x.reliability, y.reliability)
                            && match (&x.value, &y.value) {
                                (AttrValue::Number(u), AttrValue::Number(v)) => number(*u, *v),
                                (u, v) => u == v,
                            }
                    })
            })
    }

    /// The form of `value` as `name`, checked to read back from its XML.
    fn form<T: Serialize + ?Sized>(name: &str, value: &T) -> SelfDescribing {
        let form = match describe(name, value, Time(7)) {
            Ok(form) => form,
            Err(e) => panic!("{e}"),
        };
        let xml = form.to_xml();
        match SelfDescribing::from_xml(&xml) {
            Ok(back) => assert!(same(&back, &form), "{xml}"),
            Err(e) => panic!("{e}\n{xml}"),
        }
        form
    }

    /// `(name, value or symbol, variability, reliability)` of each attribute of object `name`.
    fn attrs(form: &SelfDescribing, name: &str) -> Vec<(String, String, f64, f64)> {
        let Some(object) = form.object(name) else { panic!("no object {name}") };
        object
            .attributes
            .iter()
            .map(|a| {
                let value = match &a.value {
                    AttrValue::Number(v) => v.to_string(),
                    AttrValue::Symbol(s) => format!("'{s}'"),
                };
                (a.name.clone(), value, a.variability, a.reliability)
            })
            .collect()
    }

    fn row(
        name: &str,
        value: &str,
        variability: f64,
        reliability: f64,
    ) -> (String, String, f64, f64) {
        (name.to_owned(), value.to_owned(), variability, reliability)
    }

    fn objects(form: &SelfDescribing) -> Vec<(&str, &str)> {
        form.objects.iter().map(|o| (o.name.as_str(), o.class.as_str())).collect()
    }

    #[derive(Serialize, Clone, Debug, Default)]
    struct Pose {
        x: f64,
        y: f64,
        theta: f64,
    }

    #[derive(Serialize, Clone, Debug)]
    enum Kind {
        Ball,
        Robot(u32),
        Post { east: bool, at: Pose },
        Pair(f32, i64),
    }

    #[derive(Serialize, Clone, Debug)]
    struct Thing {
        name: String,
        kind: Kind,
        pose: Pose,
        sigma: f64,
        quality: f64,
        tags: Vec<char>,
    }

    #[derive(Serialize, Clone, Debug)]
    struct Scene {
        time: u64,
        things: Vec<Thing>,
        grid: [u8; 3],
        image: Vec<u8>,
        table: BTreeMap<String, f64>,
        by_id: BTreeMap<u16, Pose>,
        pair: (i8, Option<bool>),
        unit: (),
        variability: f64,
        pose_sigma: f64,
        pose: Option<Pose>,
    }

    #[test]
    fn nested_structs_are_objects_named_by_path() {
        let thing = |name: &str, kind| Thing {
            name: name.to_owned(),
            kind,
            pose: Pose { x: 1.0, y: 2.0, theta: 0.5 },
            sigma: 0.25,
            quality: 0.75,
            tags: vec!['a', '<'],
        };
        let scene = Scene {
            time: 3,
            things: vec![
                thing("ball", Kind::Ball),
                thing("mate", Kind::Robot(4)),
                thing("post", Kind::Post { east: true, at: Pose::default() }),
                thing("pair", Kind::Pair(1.5, -2)),
            ],
            grid: [1, 2, 3],
            image: vec![9; 1_000_000],
            table: BTreeMap::from([("b".to_owned(), 2.0), ("a".to_owned(), 1.0)]),
            by_id: BTreeMap::from([(7, Pose::default())]),
            pair: (-1, None),
            unit: (),
            variability: 0.5,
            pose_sigma: 0.125,
            pose: Some(Pose { x: 3.0, y: 4.0, theta: -1.0 }),
        };
        let form = form("scene", &scene);
        assert_eq!(
            objects(&form),
            [
                ("scene", "Scene"),
                ("things[0]", "Thing"),
                ("things[0].pose", "Pose"),
                ("things[1]", "Thing"),
                ("things[1].kind", "Robot"),
                ("things[1].pose", "Pose"),
                ("things[2]", "Thing"),
                ("things[2].kind", "Post"),
                ("things[2].kind.at", "Pose"),
                ("things[2].pose", "Pose"),
                ("things[3]", "Thing"),
                ("things[3].kind", "Pair"),
                ("things[3].pose", "Pose"),
                ("by_id.7", "Pose"),
                ("pose", "Pose"),
            ]
        );
        // `variability` gives every other number of the scene 0.5 and reaches nested
        // objects; `pose_sigma` gives the field `pose` 0.125 instead.
        assert_eq!(
            attrs(&form, "scene"),
            [
                row("time", "3", 0.5, 1.0),
                row("grid[0]", "1", 0.5, 1.0),
                row("grid[1]", "2", 0.5, 1.0),
                row("grid[2]", "3", 0.5, 1.0),
                row("image", "'<1000000 bytes>'", 0.0, 1.0),
                row("table.a", "1", 0.5, 1.0),
                row("table.b", "2", 0.5, 1.0),
                row("pair[0]", "-1", 0.5, 1.0),
                row("variability", "0.5", 0.0, 1.0),
                row("pose_sigma", "0.125", 0.0, 1.0),
            ]
        );
        assert_eq!(
            attrs(&form, "pose"),
            [row("x", "3", 0.125, 1.0), row("y", "4", 0.125, 1.0), row("theta", "-1", 0.125, 1.0)]
        );
        assert_eq!(attrs(&form, "by_id.7")[0], row("x", "0", 0.5, 1.0));
        // `quality` is the reliability of a thing's attributes and of its pose's; `sigma` the
        // variability of the pose's x and y, the scene's `variability` that of the rest.
        assert_eq!(
            attrs(&form, "things[0]"),
            [
                row("name", "'ball'", 0.0, 0.75),
                row("kind", "'Ball'", 0.0, 0.75),
                row("sigma", "0.25", 0.0, 1.0),
                row("quality", "0.75", 0.0, 1.0),
                row("tags[0]", "'a'", 0.0, 0.75),
                row("tags[1]", "'<'", 0.0, 0.75),
            ]
        );
        assert_eq!(
            attrs(&form, "things[0].pose"),
            [row("x", "1", 0.25, 0.75), row("y", "2", 0.25, 0.75), row("theta", "0.5", 0.5, 0.75)]
        );
        // Variants with data.
        assert_eq!(attrs(&form, "things[1].kind"), [row("0", "4", 0.5, 0.75)]);
        assert_eq!(attrs(&form, "things[2].kind"), [row("east", "'true'", 0.0, 0.75)]);
        assert_eq!(
            attrs(&form, "things[3].kind"),
            [row("0", "1.5", 0.5, 0.75), row("1", "-2", 0.5, 0.75)]
        );
    }

    #[test]
    fn named_sigmas_reach_nested_attributes() {
        #[derive(Serialize)]
        struct Estimate {
            pose: Pose,
            sigma_xy: f64,
            sigma_theta: f64,
            quality: f64,
        }
        let form = form(
            "Estimate",
            &Estimate { pose: Pose::default(), sigma_xy: 0.1, sigma_theta: 0.05, quality: 0.5 },
        );
        assert_eq!(
            attrs(&form, "pose"),
            [row("x", "0", 0.1, 0.5), row("y", "0", 0.1, 0.5), row("theta", "0", 0.05, 0.5)]
        );
    }

    #[test]
    fn uncertainty_is_made_valid() {
        #[derive(Serialize)]
        struct Odd {
            v: f64,
            reliability: f64,
            variability: f64,
        }
        for (reliability, variability, r, v) in [
            (f64::NAN, f64::NAN, 0.0, f64::INFINITY),
            (2.0, -3.0, 1.0, 3.0),
            (-1.0, f64::NEG_INFINITY, 0.0, f64::INFINITY),
            (0.5, -0.0, 0.5, 0.0),
        ] {
            let form = form("odd", &Odd { v: f64::NAN, reliability, variability });
            let v_attr = &form.objects[0].attributes[0];
            assert_eq!((v_attr.variability, v_attr.reliability), (v, r));
            assert!(matches!(v_attr.value, AttrValue::Number(x) if x.is_nan()));
        }
        // Non-finite numbers as values read back.
        let form = form("numbers", &[f64::INFINITY, f64::NEG_INFINITY, f64::NAN, -0.0, 5e-324]);
        assert!(form.to_xml().contains(r#"name="[0]" value="inf""#), "{}", form.to_xml());
        assert!(form.to_xml().contains(r#"name="[1]" value="-inf""#));
        assert!(form.to_xml().contains(r#"name="[2]" value="NaN""#));
    }

    #[test]
    fn values_that_are_not_structs() {
        assert_eq!(attrs(&form("n", &2.5), "n"), [row("value", "2.5", 0.0, 1.0)]);
        assert_eq!(objects(&form("n", &2.5)), [("n", "n")]);
        assert_eq!(attrs(&form("s", "hi"), "s"), [row("value", "'hi'", 0.0, 1.0)]);
        assert!(attrs(&form("none", &None::<f64>), "none").is_empty());
        assert!(attrs(&form("empty", &Vec::<f64>::new()), "empty").is_empty());
        let seq = form("poses", &vec![Pose::default(); 2]);
        assert_eq!(objects(&seq), [("poses", "poses"), ("[0]", "Pose"), ("[1]", "Pose")]);
        let map = form("m", &BTreeMap::from([('k', Pose::default())]));
        assert_eq!(objects(&map), [("m", "m"), ("k", "Pose")]);
        assert_eq!(objects(&form("k", &Kind::Robot(1))), [("k", "Robot")]);
        #[derive(Serialize)]
        struct Unit;
        #[derive(Serialize)]
        struct Wrapper(Pose);
        #[derive(Serialize)]
        struct Meters(f64);
        #[derive(Serialize)]
        struct Pair(f64, Unit);
        assert_eq!(objects(&form("u", &Unit)), [("u", "Unit")]);
        assert_eq!(objects(&form("w", &Wrapper(Pose::default()))), [("w", "Wrapper")]);
        assert_eq!(attrs(&form("w", &Wrapper(Pose::default())), "w").len(), 3);
        assert_eq!(attrs(&form("m", &Meters(2.0)), "m"), [row("value", "2", 0.0, 1.0)]);
        assert_eq!(objects(&form("p", &Pair(1.0, Unit))), [("p", "Pair"), ("1", "Unit")]);
        // u128, i128, chars, bools.
        assert_eq!(
            attrs(&form("t", &(u128::MAX, i128::MIN, 'x', false)), "t"),
            [
                row("[0]", &(u128::MAX as f64).to_string(), 0.0, 1.0),
                row("[1]", &(i128::MIN as f64).to_string(), 0.0, 1.0),
                row("[2]", "'x'", 0.0, 1.0),
                row("[3]", "'false'", 0.0, 1.0),
            ]
        );
    }

    /// `serialize_bytes` (what `serde_bytes` calls) gives one attribute.
    struct Bytes(Vec<u8>);

    impl Serialize for Bytes {
        fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            s.serialize_bytes(&self.0)
        }
    }

    #[test]
    fn byte_arrays_are_one_attribute() {
        #[derive(Serialize)]
        struct Image {
            raw: Bytes,
            rgb: Vec<u8>,
            empty: Bytes,
            small: [u8; 2],
            mixed: Vec<Option<u8>>,
        }
        let image = Image {
            raw: Bytes(vec![1; 5]),
            rgb: vec![0; 921_600],
            empty: Bytes(Vec::new()),
            small: [7, 8],
            mixed: vec![None, Some(3)],
        };
        assert_eq!(
            attrs(&form("image", &image), "image"),
            [
                row("raw", "'<5 bytes>'", 0.0, 1.0),
                row("rgb", "'<921600 bytes>'", 0.0, 1.0),
                row("empty", "'<0 bytes>'", 0.0, 1.0),
                row("small[0]", "7", 0.0, 1.0),
                row("small[1]", "8", 0.0, 1.0),
                row("mixed[1]", "3", 0.0, 1.0),
            ]
        );
        // Optional bytes and newtypes of bytes are numbers.
        #[derive(Serialize)]
        struct Level(u8);
        assert_eq!(
            attrs(&form("v", &vec![Some(1), Some(2)]), "v"),
            [row("[0]", "1", 0.0, 1.0), row("[1]", "2", 0.0, 1.0)]
        );
        assert_eq!(attrs(&form("v", &vec![Level(3)]), "v"), [row("[0]", "3", 0.0, 1.0)]);
        // Bytes followed by something else are numbers after all.
        assert_eq!(attrs(&form("v", &vec![Some(4), None]), "v"), [row("[0]", "4", 0.0, 1.0)]);
    }

    #[test]
    fn errors_are_typed() {
        let bad_key = BTreeMap::from([((1, 2), 3.0)]);
        assert!(matches!(
            describe("m", &bad_key, Time(0)),
            Err(DescribeError::MapKey { found: "a sequence" })
        ));
        struct Failing;
        impl Serialize for Failing {
            fn serialize<S: serde::Serializer>(&self, _: S) -> Result<S::Ok, S::Error> {
                Err(serde::ser::Error::custom("no camera"))
            }
        }
        let err = describe("f", &vec![Failing], Time(0)).err().map(|e| e.to_string());
        assert_eq!(err.as_deref(), Some("the value could not be serialized: no camera"));
        #[derive(Serialize)]
        struct Chain(Option<Box<Chain>>);
        let mut chain = Chain(None);
        for _ in 0..MAX_DEPTH {
            chain = Chain(Some(Box::new(chain)));
        }
        assert!(matches!(describe("c", &chain, Time(0)), Err(DescribeError::TooDeep)));
        let mut shallow = Chain(None);
        for _ in 0..MAX_DEPTH / 3 {
            shallow = Chain(Some(Box::new(shallow)));
        }
        assert!(describe("c", &shallow, Time(0)).is_ok());
    }

    fn number() -> impl Strategy<Value = f64> {
        prop_oneof![
            any::<f64>(),
            -1e4..1e4f64,
            prop::sample::select(vec![0.0, -0.0, 1.0, f64::NAN, f64::INFINITY, f64::NEG_INFINITY]),
        ]
    }

    fn pose() -> impl Strategy<Value = Pose> {
        (number(), number(), number()).prop_map(|(x, y, theta)| Pose { x, y, theta })
    }

    fn kind() -> impl Strategy<Value = Kind> {
        prop_oneof![
            Just(Kind::Ball),
            any::<u32>().prop_map(Kind::Robot),
            (any::<bool>(), pose()).prop_map(|(east, at)| Kind::Post { east, at }),
            (any::<f32>(), any::<i64>()).prop_map(|(a, b)| Kind::Pair(a, b)),
        ]
    }

    fn thing() -> impl Strategy<Value = Thing> {
        (
            any::<String>(),
            kind(),
            pose(),
            number(),
            number(),
            prop::collection::vec(any::<char>(), 0..3),
        )
            .prop_map(|(name, kind, pose, sigma, quality, tags)| Thing {
                name,
                kind,
                pose,
                sigma,
                quality,
                tags,
            })
    }

    fn scene() -> impl Strategy<Value = Scene> {
        (
            (any::<u64>(), prop::collection::vec(thing(), 0..3), any::<[u8; 3]>()),
            prop::collection::vec(any::<u8>(), 0..40),
            prop::collection::btree_map(any::<String>(), number(), 0..3),
            prop::collection::btree_map(any::<u16>(), pose(), 0..3),
            (any::<i8>(), any::<Option<bool>>()),
            (number(), number(), prop::option::of(pose())),
        )
            .prop_map(|((time, things, grid), image, table, by_id, pair, rest)| Scene {
                time,
                things,
                grid,
                image,
                table,
                by_id,
                pair,
                unit: (),
                variability: rest.0,
                pose_sigma: rest.1,
                pose: rest.2,
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// Any value gives a form, whose XML reads back as the form.
        #[test]
        fn any_value_reads_back(scene in scene(), nanos in any::<u64>()) {
            let form = describe("scene", &scene, Time(nanos))
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let xml = form.to_xml();
            let back = SelfDescribing::from_xml(&xml)
                .map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
            prop_assert!(same(&back, &form), "{}", xml);
            prop_assert_eq!(form.objects.len(), 1 + scene.things.iter().map(|t| match t.kind {
                Kind::Ball => 2,
                Kind::Post { .. } => 4,
                _ => 3,
            }).sum::<usize>() + scene.by_id.len() + usize::from(scene.pose.is_some()));
        }

        #[test]
        fn any_thing_reads_back(things in prop::collection::vec(thing(), 0..4)) {
            let form = describe("things", &things, Time(1))
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            let back = SelfDescribing::from_xml(&form.to_xml())
                .map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert!(same(&back, &form));
        }
    }
}
