//! Arbitrary text, indexed by velvet's read model and parsed by serde_json: both accept the
//! same texts, and read the same values from them (keys in the same order, duplicates as
//! serde_json's map keeps them, numbers as serde_json reads them); a lookup by key finds what
//! iteration gives for it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use serde_json::Value;
use velvet::asset::tape::{Kind, Node, Tape};

/// The value as the index's own accessors read it (not through `Node::to_value`).
fn read(node: Node) -> Value {
    match node.kind() {
        Kind::Null => Value::Null,
        Kind::Bool => Value::Bool(node.as_bool().expect("a boolean")),
        Kind::Number => {
            let n: serde_json::Number = serde_json::from_str(node.raw()).expect("a number");
            assert_eq!(node.as_f64(), n.as_f64());
            assert_eq!(node.as_u64(), n.as_u64());
            assert_eq!(node.as_i64(), n.as_i64());
            Value::Number(n)
        }
        Kind::String => Value::String(node.as_str().expect("a string").into_owned()),
        Kind::Array => Value::Array(node.as_array().expect("an array").iter().map(read).collect()),
        Kind::Object => {
            let object = node.as_object().expect("an object");
            // A lookup by key finds the value iteration gives that key.
            for (key, value) in object.iter() {
                assert_eq!(object.get(&key).map(|v| v.span()), Some(value.span()));
                assert!(object.contains_key(&key));
            }
            let members: serde_json::Map<String, Value> =
                object.iter().map(|(k, v)| (k.into_owned(), read(v))).collect();
            assert_eq!(object.len(), members.len());
            Value::Object(members)
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let ours = Tape::build(text);
    let theirs = serde_json::from_str::<Value>(text);
    match (ours, theirs) {
        (Ok(tape), Ok(value)) => {
            let read = read(tape.root(text));
            assert_eq!(read, value);
            assert_eq!(
                serde_json::to_string(&read).unwrap(),
                serde_json::to_string(&value).unwrap()
            );
        }
        (Err(_), Err(_)) => {}
        (ours, theirs) => panic!(
            "the index {} {text:?}, serde_json {} it",
            if ours.is_ok() { "accepts" } else { "refuses" },
            if theirs.is_ok() { "accepts" } else { "refuses" }
        ),
    }
});
