//! Compact JSON text as velvet writes it: no whitespace, numbers as velvet writes them,
//! strings quoted as velvet quotes them. It is the text a plan holds for a value set as text
//! (a conversion's layer object), written from a value, from the index with no value made, and
//! number by number as a conversion computes them; the splicer lays it out in the file's
//! layout from that text ([`Layout::write_text`]).

use super::layout::Layout;
use super::numbers::{
    rounding, with_written_number, write_rounded, written_f64, Rounding, StackText,
};
use crate::asset::json_text::push_quoted;
use crate::asset::tape::{Kind, Node};
use serde_json::Value;

/// Writes `value` as compact JSON text (no whitespace), its numbers as velvet writes them
/// and its strings quoted as velvet quotes them: the text of an [`SetValue::Text`].
///
/// [`SetValue::Text`]: crate::edit::SetValue::Text
pub fn write_compact(value: &Value, out: &mut String) {
    Layout::compact().write(value, "", true, out);
}

/// [`write_compact`] of the value `node` holds, read from the index: what
/// `write_compact(&node.to_value())` writes, with no value made (a textureInfo a conversion
/// carries into its layer object, by the ten thousand). A key written twice is written once, at
/// its first place with its last value, as the value holds it.
pub fn write_compact_node(node: Node, out: &mut String) {
    match node.kind() {
        Kind::Object => match node.as_object().filter(|o| !o.is_empty()) {
            Some(object) => {
                out.push('{');
                for (i, (key, member)) in object.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    push_quoted(out, &key);
                    out.push(':');
                    write_compact_node(member, out);
                }
                out.push('}');
            }
            None => out.push_str("{}"),
        },
        Kind::Array => match node.as_array().filter(|a| !a.is_empty()) {
            Some(items) => {
                out.push('[');
                for (i, item) in items.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    write_compact_node(item, out);
                }
                out.push(']');
            }
            None => out.push_str("[]"),
        },
        Kind::String => push_quoted(out, &node.as_str().unwrap_or_default()),
        // serde_json reads an exponent as `e` with its sign (`1E5` holds `1e+5`): such a number
        // is written as the value holds it.
        Kind::Number if node.raw().bytes().any(|b| b == b'e' || b == b'E') => {
            write_compact(&node.to_value(), out)
        }
        Kind::Number => with_written_number(node.raw(), |text| out.push_str(text)),
        Kind::Bool | Kind::Null => out.push_str(node.raw()),
    }
}

/// Writes the text of [`written_f64`]`(x)` as [`write_compact`] writes it, with no value
/// made: the numbers a conversion computes (a sheen's fuzz colour, three by the twenty
/// thousand in a library) go straight into its layer object's text.
pub fn push_written_f64(x: f64, out: &mut String) {
    if !x.is_finite() || x.abs() >= 1e9 {
        return write_compact(&written_f64(x), out); // not finite, or large: the general way
    }
    match rounding(x) {
        // What `Value::from` holds: serde_json's own writing of an f64.
        Rounding::Same => push_serde_f64(x, out),
        Rounding::Zero => out.push('0'),
        Rounding::To(rounded) => {
            let mut text = StackText::new();
            write_rounded(rounded, &mut text);
            out.push_str(text.as_str());
        }
    }
}

/// serde_json's writing of a finite `x` (the text `Value::from(x)` holds), made on the stack
/// by its own formatter.
fn push_serde_f64(x: f64, out: &mut String) {
    use serde_json::ser::Formatter;
    const ROOM: usize = 40;
    let mut buffer = [0u8; ROOM];
    let mut rest: &mut [u8] = &mut buffer;
    let formatted = serde_json::ser::CompactFormatter
        .write_f64(&mut rest, x)
        .is_ok();
    let len = ROOM - rest.len();
    match std::str::from_utf8(&buffer[..len]) {
        Ok(text) if formatted => out.push_str(text),
        _ => out.push_str(&Value::from(x).to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Compact text written from the index is what the value read from it gives: escapes,
    /// exponent spellings, long decimals, empty and nested containers, a key written twice.
    #[test]
    fn compact_text_from_the_index_is_the_texts_value_written() {
        for text in [
            r#"{"index": 2, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0], "offset": [], "rotation": 1E-1}}, "extras": {}}"#,
            r#"{"s": "a \"q\" \\ \u00e9 \u0001 é", "t": true, "f": false, "n": null, "x": [0.12345678, -0, 7.5e-8, 1.0, 1e9, 2E+3, 1e5, 1.50]}"#,
            r#"{"k": 1, "j": 2, "k": 3}"#,
            r#"[]"#,
            r#"{}"#,
            r#""plain""#,
            r#"0.7499999999999999"#,
        ] {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            let node = tape.root(text);
            let mut from_node = String::new();
            write_compact_node(node, &mut from_node);
            let mut from_value = String::new();
            write_compact(&node.to_value(), &mut from_value);
            assert_eq!(from_node, from_value, "{text}");
        }
    }
}
