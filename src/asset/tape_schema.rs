//! The read model as jsonschema sees it: [`TapeJson`] lets the schema checks validate values
//! straight from the index ([`super::tape`]), so that no `serde_json::Value` of the document
//! is built to check it. Numbers answer as serde_json's (with `arbitrary_precision`) would, so
//! that a schema gives the same verdict on the index as on a `Value`; a unit test holds the two
//! to the same errors on the core and layer schemas.

use super::tape::{self, Kind, Node};
use jsonschema::json::{self, JsonNumber, NodeIdentity};
use jsonschema::types::JsonType;
use serde_json::Value;
use std::borrow::Cow;

/// The index, as a JSON representation jsonschema validates.
pub struct TapeJson;

/// A number's text, read on demand.
#[derive(Clone, Copy)]
pub struct Number<'a>(&'a str);

impl json::Json for TapeJson {
    type Node<'a> = Node<'a>;
    type PreparedKey = String;
    type StringBuffer = (String, tape::Tape);

    fn prepare_key(key: &str) -> String {
        key.to_owned()
    }

    fn with_string_node<T>(
        buffer: &mut (String, tape::Tape),
        string: &str,
        f: impl FnOnce(Node<'_>) -> T,
    ) -> T {
        buffer.0 = serde_json::to_string(string).expect("a string serialises");
        buffer.1 = tape::Tape::build(&buffer.0).expect("a serialised string indexes");
        f(buffer.1.root(&buffer.0))
    }
}

impl JsonNumber for Number<'_> {
    fn as_u64(&self) -> Option<u64> {
        self.0.parse().ok()
    }
    fn as_i64(&self) -> Option<i64> {
        self.0.parse().ok()
    }
    fn as_f64(&self) -> Option<f64> {
        self.0.parse().ok().filter(|f: &f64| f.is_finite())
    }
    fn as_str(&self) -> Cow<'_, str> {
        Cow::Borrowed(self.0)
    }
    fn to_number(&self) -> Cow<'_, serde_json::Number> {
        Cow::Owned(serde_json::from_str(self.0).expect("the index holds valid numbers"))
    }
    /// As jsonschema decides it for a serde_json number: an integer in 64 bits, or a finite
    /// value without a fraction.
    fn is_integer(&self) -> bool {
        self.as_u64().is_some()
            || self.as_i64().is_some()
            || self.as_f64().is_some_and(|f| f.fract() == 0.0)
    }
}

impl<'a> json::Node<'a, TapeJson> for Node<'a> {
    type Object = tape::Object<'a>;
    type Array = tape::Array<'a>;
    type Number = Number<'a>;

    fn as_object(&self) -> Option<tape::Object<'a>> {
        Node::as_object(self)
    }
    fn as_array(&self) -> Option<tape::Array<'a>> {
        Node::as_array(self)
    }
    fn as_string(&self) -> Option<Cow<'a, str>> {
        Node::as_str(self)
    }
    fn as_number(&self) -> Option<Number<'a>> {
        (self.kind() == Kind::Number).then(|| Number(self.raw()))
    }
    fn as_boolean(&self) -> Option<bool> {
        Node::as_bool(self)
    }
    fn is_null(&self) -> bool {
        Node::is_null(self)
    }
    /// A number past f64's range (`1e400`, which reads as infinity) is, where a schema asks
    /// for a number, no number: the schema checks report it as out of range. Only a text with
    /// an exponent or of 300 characters can be one, so most numbers are not parsed here.
    fn is_number(&self) -> bool {
        Node::is_number(self) && {
            let text = self.raw();
            !(text.len() >= 300 || text.bytes().any(|b| b == b'e' || b == b'E'))
                || text.parse::<f64>().is_ok_and(f64::is_finite)
        }
    }
    fn json_type(&self) -> JsonType {
        match self.kind() {
            Kind::Null => JsonType::Null,
            Kind::Bool => JsonType::Boolean,
            Kind::Number => JsonType::Number,
            Kind::String => JsonType::String,
            Kind::Array => JsonType::Array,
            Kind::Object => JsonType::Object,
        }
    }
    fn to_value(&self) -> Cow<'a, Value> {
        Cow::Owned(Node::to_value(self))
    }
    /// An array or object an error names is read into a value only when the error's instance
    /// is asked for: jsonschema makes the error of a failed `uniqueItems` (or `maxItems`) with
    /// its instance, and a list of millions of node indices took some 240 bytes an element.
    fn lazy_value(&self) -> jsonschema_value::LazyInstance<'a> {
        match self.kind() {
            Kind::Array | Kind::Object => jsonschema_value::LazyInstance::Deferred {
                bytes: self.raw().as_bytes(),
                tag: 0,
                make: |bytes, _| serde_json::from_slice(bytes).unwrap_or(Value::Null),
                cell: std::sync::OnceLock::new(),
            },
            _ => jsonschema_value::LazyInstance::Ready(Cow::Owned(Node::to_value(self))),
        }
    }
    fn identity(&self) -> Option<NodeIdentity> {
        Some(NodeIdentity::tagged(self.document_address(), self.id()))
    }
}

impl<'a> json::Object<'a, TapeJson> for tape::Object<'a> {
    type Node = Node<'a>;
    type MemberName = Cow<'a, str>;
    type MembersIter = tape::Members<'a>;

    fn len(&self) -> usize {
        tape::Object::len(self)
    }
    fn get(&self, key: &String) -> Option<Node<'a>> {
        tape::Object::get(self, key)
    }
    fn members(&self) -> tape::Members<'a> {
        self.iter()
    }
}

impl<'a> json::Array<'a, TapeJson> for tape::Array<'a> {
    type Node = Node<'a>;
    type ElementsIter = tape::Elements<'a>;

    fn len(&self) -> usize {
        tape::Array::len(self)
    }
    fn elements(&self) -> tape::Elements<'a> {
        self.iter()
    }

    /// `uniqueItems`. jsonschema's own check reads every element into a `Value` first, some
    /// 240 bytes an element: a 62 MB list of node indices took 7 GB. glTF's unique lists are
    /// of integers (node, joint and attribute indices) or strings (extension names); a list of
    /// integers that fit 64 bits is compared by their values here, 8 bytes an element, and
    /// any other list as jsonschema compares it.
    fn is_unique(&self) -> bool {
        match integers(self) {
            Some((mut unsigned, mut negative)) => {
                unsigned.sort_unstable();
                negative.sort_unstable();
                !(unsigned.windows(2).any(|w| w[0] == w[1])
                    || negative.windows(2).any(|w| w[0] == w[1]))
            }
            None => {
                let values: Vec<Value> = self.iter().map(|e| e.to_value()).collect();
                json::unique::is_unique(&values)
            }
        }
    }
}

/// The elements of `array` as integers, the non-negative ones and the negative ones apart (a
/// negative i64 equals no u64); `None` unless every element is an integer written as one
/// (`1.0` and `1e2` are left to jsonschema) that fits 64 bits. Stops early at two equal
/// neighbours (`[0, 0, …]`), answering with just them.
fn integers(array: &tape::Array<'_>) -> Option<(Vec<u64>, Vec<i64>)> {
    let mut unsigned = Vec::with_capacity(array.len());
    let mut negative = Vec::new();
    let mut previous: Option<&str> = None;
    for element in array.iter() {
        if element.kind() != Kind::Number {
            return None;
        }
        let text = element.raw();
        if previous == Some(text) {
            return Some((vec![0, 0], Vec::new()));
        }
        previous = Some(text);
        match text.parse::<u64>() {
            Ok(u) => unsigned.push(u),
            Err(_) => negative.push(text.parse::<i64>().ok().filter(|i| *i < 0)?),
        }
    }
    Some((unsigned, negative))
}
