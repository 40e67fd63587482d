//! Generating the self-describing form of any `Serialize` value ([`describe`]): the value as a
//! tree, then flattened into objects and attributes.

use super::*;

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
/// [module documentation](crate::describe#the-form-of-a-typed-message); any value that serializes gives a
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
