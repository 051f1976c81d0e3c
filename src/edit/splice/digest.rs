//! The digest a part of the document is checked by as it reads back: what a value reads as
//! when velvet writes it, as one number. The value a plan meant and the text written feed the
//! same stream, one from the value, the other from the new text's index, so a part is checked
//! without rebuilding either side as a value, nor holding every part's value until the end.

use super::numbers::with_written_number;
use crate::asset::tape::{Kind, Node};
use serde_json::Value;

/// A digest of what a value reads as when velvet writes it: key order, decoded strings, and
/// numbers as [`number_text`] writes them. [`value_digest`] (what a unit is meant to hold) and
/// [`node_digest`] (what the written text holds) feed the same stream, so a unit is checked
/// without rebuilding either side as a value.
///
/// The hash is foldhash's fast one, with a fixed seed: the digest guards against velvet's own
/// mistakes, not against crafted input, and std's SipHash took a tenth of the check's time.
///
/// [`number_text`]: super::number_text
pub(super) struct Digest(foldhash::fast::FoldHasher<'static>);

impl Digest {
    pub(super) fn new() -> Digest {
        use std::hash::BuildHasher;
        Digest(foldhash::fast::FixedState::with_seed(0).build_hasher())
    }

    fn tag(&mut self, tag: u8) {
        std::hash::Hasher::write_u8(&mut self.0, tag);
    }

    /// A tagged, length-prefixed run of bytes, so that no two streams run together.
    fn text(&mut self, tag: u8, text: &str) {
        use std::hash::Hasher;
        self.0.write_u8(tag);
        self.0.write_usize(text.len());
        self.0.write(text.as_bytes());
    }

    pub(super) fn finish(&self) -> u64 {
        std::hash::Hasher::finish(&self.0)
    }
}

/// The [`Digest`] of `value` as velvet writes it.
pub(super) fn value_digest(value: &Value) -> u64 {
    let mut d = Digest::new();
    feed_value(&mut d, value);
    d.finish()
}

fn feed_value(d: &mut Digest, value: &Value) {
    match value {
        Value::Null => d.tag(b'n'),
        Value::Bool(b) => d.tag(if *b { b't' } else { b'f' }),
        Value::Number(n) => with_written_number(n.as_str(), |text| d.text(b'#', text)),
        Value::String(s) => d.text(b'"', s),
        Value::Array(items) => {
            d.tag(b'[');
            items.iter().for_each(|v| feed_value(d, v));
            d.tag(b']');
        }
        Value::Object(map) => {
            d.tag(b'{');
            for (k, v) in map {
                d.text(b':', k);
                feed_value(d, v);
            }
            d.tag(b'}');
        }
    }
}

/// The [`Digest`] of the value `node` indexes, read as a `Value` would read it (a key written
/// twice: at its first place, with its last value).
pub(super) fn node_digest(node: Node) -> u64 {
    let mut d = Digest::new();
    feed_node(&mut d, node);
    d.finish()
}

fn feed_node(d: &mut Digest, node: Node) {
    match node.kind() {
        Kind::Null => d.tag(b'n'),
        Kind::Bool => d.tag(if node.as_bool() == Some(true) {
            b't'
        } else {
            b'f'
        }),
        // Spelled as serde_json reads it (`1E-1` as `1e-1`), as the meant value holds it. A
        // number without an exponent it reads as written (its digits are kept, and an integer
        // it reads as one prints as written), so only an exponent takes the parse.
        Kind::Number => match node.raw() {
            raw if !raw.contains(['e', 'E']) => with_written_number(raw, |text| d.text(b'#', text)),
            raw => match raw.parse::<serde_json::Number>() {
                Ok(n) => with_written_number(n.as_str(), |text| d.text(b'#', text)),
                Err(_) => d.text(b'#', raw),
            },
        },
        Kind::String => d.text(b'"', &node.as_str().unwrap_or_default()),
        Kind::Array => {
            d.tag(b'[');
            node.as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .for_each(|v| feed_node(d, v));
            d.tag(b']');
        }
        Kind::Object => {
            d.tag(b'{');
            for (k, v) in node.as_object().into_iter().flat_map(|o| o.iter()) {
                d.text(b':', &k);
                feed_node(d, v);
            }
            d.tag(b'}');
        }
    }
}

/// Feeds `node` as [`feed_node`] does, with each of `sets` (tokens below `node`, value or
/// `None` for a removal) in its place: a set member or array element where it stands, a new
/// member after the object's members, in order, a removed one left out. Every set's path exists in `node`
/// up to its last token (see `members_set_in_place`, in `edits.rs`).
pub(super) fn feed_edited<T: AsRef<str>>(
    d: &mut Digest,
    node: Node,
    sets: &[(&[T], Option<&Value>)],
) {
    if sets.is_empty() {
        return feed_node(d, node);
    }
    let below = |token: &str| -> Vec<(&[T], Option<&Value>)> {
        sets.iter()
            .filter(|(t, _)| t.len() > 1 && t[0].as_ref() == token)
            .map(|(t, v)| (&t[1..], *v))
            .collect()
    };
    match node.kind() {
        Kind::Object => {
            let Some(object) = node.as_object() else {
                return feed_node(d, node);
            };
            d.tag(b'{');
            for (key, member) in object.iter() {
                match sets
                    .iter()
                    .find(|(t, _)| t.len() == 1 && t[0].as_ref() == key)
                {
                    Some((_, None)) => {} // removed
                    Some((_, Some(new))) => {
                        d.text(b':', &key);
                        feed_value(d, new);
                    }
                    None => {
                        d.text(b':', &key);
                        feed_edited(d, member, &below(&key));
                    }
                }
            }
            for (tokens, new) in sets {
                if let (1, Some(new)) = (tokens.len(), new) {
                    if !object.contains_key(tokens[0].as_ref()) {
                        d.text(b':', tokens[0].as_ref());
                        feed_value(d, new);
                    }
                }
            }
            d.tag(b'}');
        }
        Kind::Array => {
            d.tag(b'[');
            for (i, item) in node
                .as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .enumerate()
            {
                let token = i.to_string();
                match sets
                    .iter()
                    .find(|(t, _)| t.len() == 1 && t[0].as_ref() == token)
                {
                    Some((_, Some(new))) => feed_value(d, new),
                    _ => feed_edited(d, item, &below(&token)),
                }
            }
            d.tag(b']');
        }
        _ => feed_node(d, node),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_and_the_text_velvet_writes_for_it_have_one_digest_and_other_texts_another() {
        let digest_of_text = |text: &str| {
            let tape = crate::asset::tape::Tape::build(text).unwrap();
            node_digest(tape.root(text))
        };
        let spelled: Value = serde_json::from_str(r#"[1E-1, 2e+3]"#).unwrap();
        assert_eq!(
            value_digest(&spelled),
            digest_of_text("[\n  1E-1,\n  2e+3\n]"),
            "a number reads alike from the text and from the value read from it, whatever its spelling"
        );
        let meant = serde_json::json!({
            "name": "caf\u{e9} \"1\"",
            "f": [0.7499999999999999, 1.0, 2, 7.5e-8],
            "on": true,
            "none": null,
            "inner": {"k": -0.5}
        });
        let digest = value_digest(&meant);
        // As written: noise rounded, escapes of either spelling, any layout; a key written twice
        // reads as its last value at its first place.
        for text in [
            r#"{"name":"caf\u00e9 \"1\"","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":-0.5}}"#,
            "{\n  \"name\": \"café \\\"1\\\"\",\n  \"f\": [0.75, 1.0, 2, 0],\n  \"on\": true,\n  \"none\": null,\n  \"inner\": {\"k\": -0.5}\n}",
            r#"{"name":"x","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":-0.5},"name":"café \"1\""}"#,
        ] {
            assert_eq!(digest_of_text(text), digest, "{text}");
        }
        for other in [
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0.1],"on":true,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"f":[0.75,1.0,2,0],"name":"café \"1\"","on":true,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0],"on":false,"none":null,"inner":{"k":-0.5}}"#,
            r#"{"name":"café \"1\"","f":[0.75,1.0,2,0],"on":true,"none":null,"inner":{"k":"-0.5"}}"#,
            r#"{"name":"café \"1\"","f":[[0.75,1.0],2,0],"on":true,"none":null,"inner":{"k":-0.5}}"#,
        ] {
            assert_ne!(digest_of_text(other), digest, "{other}");
        }
    }
}
