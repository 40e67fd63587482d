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
use quick_xml::{Reader, Writer, XmlVersion};
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

mod serialize;
mod xml;

pub use serialize::{describe, DescribeError, MAX_DEPTH};
use xml::{escape, format_timestamp, xml_attr, Parser};

#[cfg(test)]
mod tests;

/// The forms generated from types ([`describe`]).
#[cfg(test)]
mod generated;
