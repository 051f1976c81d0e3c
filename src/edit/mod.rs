//! Edit plans and their applier, shared by the commands that change documents (migrate, bake).
//!
//! An [`Edit`] is a plain value — set a value at a JSON pointer, remove one, declare an
//! extension in `extensionsUsed` — so a plan can be compared, printed for a dry run and tested
//! before anything is applied. [`apply`] executes a plan on a document without disturbing what
//! the plan does not name: keys keep their places (a replaced key stays where it was, a new key
//! goes last, a removed key closes the gap without moving its neighbours) and untouched numbers
//! keep their text.

pub mod splice;
pub mod write;

use crate::asset::pointer;
use serde::Serialize;
use serde_json::{Map, Value};
use std::fmt;

/// One change to a glTF document.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "op", rename_all = "kebab-case")]
pub enum Edit {
    /// Sets the value at `pointer`. Missing objects on the way are created; an array index may
    /// name an existing element (replaced) or the end of the array (appended, also as `-`).
    Set { pointer: String, value: SetValue },
    /// Sets the value at `pointer` exactly as given: its numbers keep their spelling, where
    /// [`Edit::Set`] writes them as velvet writes numbers. For a part of the document read
    /// from it and changed in place (what a bake applied), whose numbers the change left alone.
    Replace { pointer: String, value: Value },
    /// Removes the value at `pointer` (an absent value is not an error: the plan's intent holds).
    Remove { pointer: String },
    /// Adds `extension` to `extensionsUsed` unless it is there; creates the array after `asset`
    /// when the document has none.
    DeclareUsed { extension: String },
}

/// The value an [`Edit::Set`] sets: a value with its numbers as velvet writes them, or that
/// value's text, compact, as a conversion writes its layer object. A plan keeps its edits to
/// the end of the run (for its report), and a migration adds a layer object to every material:
/// as text, the library's 20,000 take a tenth of the memory, and the splicer lays the text out
/// without reading it into a value. Either reads, prints and compares as its value.
#[derive(Debug, Clone)]
pub enum SetValue {
    Value(Value),
    /// Compact JSON text (no whitespace) whose numbers are as velvet writes them and whose
    /// strings are quoted as velvet quotes them ([`splice::write_compact`] writes it).
    Text(Box<str>),
}

impl SetValue {
    /// The value; a text is read (it is JSON that velvet wrote).
    pub fn to_value(&self) -> std::borrow::Cow<'_, Value> {
        use std::borrow::Cow;
        match self {
            SetValue::Value(value) => Cow::Borrowed(value),
            SetValue::Text(text) => Cow::Owned(value_of_text(text)),
        }
    }
}

/// The value a [`SetValue::Text`] holds. The text is written by `splice::write_compact`, which
/// writes JSON; a text that did not read would be a fault of that writer, and reads as null.
pub(crate) fn value_of_text(text: &str) -> Value {
    serde_json::from_str(text).unwrap_or_default()
}

impl PartialEq for SetValue {
    fn eq(&self, other: &SetValue) -> bool {
        match (self, other) {
            (SetValue::Text(a), SetValue::Text(b)) if a == b => true,
            _ => self.to_value() == other.to_value(),
        }
    }
}

impl Serialize for SetValue {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_value().serialize(s)
    }
}

impl fmt::Display for SetValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.to_value().fmt(f)
    }
}

impl Edit {
    /// Sets `value`, its numbers as velvet writes them ([`splice::written`]): a plan holds,
    /// and a dry run shows, what the file will hold.
    pub fn set(pointer: impl Into<String>, value: Value) -> Edit {
        Edit::Set {
            pointer: pointer.into(),
            value: SetValue::Value(splice::written(value)),
        }
    }

    /// Sets the value `text` holds: compact JSON as [`splice::write_compact`] writes it (a
    /// conversion writes its layer object so, with no value made).
    pub fn set_text(pointer: impl Into<String>, text: String) -> Edit {
        Edit::Set {
            pointer: pointer.into(),
            value: SetValue::Text(text.into_boxed_str()),
        }
    }

    /// The same edit at `pointer`: an edit of a part of the document, given from the part's
    /// own root. A declaration, which has no pointer, is itself.
    pub fn at(&self, pointer: &str) -> Edit {
        match self {
            Edit::Set { value, .. } => Edit::Set {
                pointer: pointer.to_string(),
                value: value.clone(),
            },
            Edit::Replace { value, .. } => Edit::replace(pointer, value.clone()),
            Edit::Remove { .. } => Edit::remove(pointer),
            Edit::DeclareUsed { .. } => self.clone(),
        }
    }

    pub fn replace(pointer: impl Into<String>, value: Value) -> Edit {
        Edit::Replace {
            pointer: pointer.into(),
            value,
        }
    }

    pub fn remove(pointer: impl Into<String>) -> Edit {
        Edit::Remove {
            pointer: pointer.into(),
        }
    }

    pub fn declare_used(extension: impl Into<String>) -> Edit {
        Edit::DeclareUsed {
            extension: extension.into(),
        }
    }
}

impl fmt::Display for Edit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Edit::Set { pointer, value } => write!(f, "set {pointer} = {value}"),
            Edit::Replace { pointer, value } => write!(f, "replace {pointer} = {value}"),
            Edit::Remove { pointer } => write!(f, "remove {pointer}"),
            Edit::DeclareUsed { extension } => write!(f, "declare {extension} in /extensionsUsed"),
        }
    }
}

/// Why an edit could not be applied.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EditError {
    #[error("{pointer}: the document root cannot be replaced by an edit")]
    Root { pointer: String },
    #[error("{pointer}: '{token}' leads into a {kind}, which holds no members")]
    NotAContainer {
        pointer: String,
        token: String,
        kind: &'static str,
    },
    #[error("{pointer}: '{token}' is not an index of an array of {len}")]
    BadIndex {
        pointer: String,
        token: String,
        len: usize,
    },
    #[error("/extensionsUsed is not an array")]
    ExtensionsUsedNotArray,
}

/// Applies `edits` in order; `Ok(true)` when the document changed (an edit that sets a value
/// already there, removes an absent one or declares a declared extension changes nothing). On
/// error the document may hold the edits before the failing one: callers discard it.
pub fn apply(json: &mut Value, edits: &[Edit]) -> Result<bool, EditError> {
    let mut changed = false;
    for edit in edits {
        changed |= match edit {
            Edit::Set { pointer, value } => set(
                json,
                pointer,
                splice::written(value.to_value().into_owned()),
            )?,
            Edit::Replace { pointer, value } => set(json, pointer, value.clone())?,
            Edit::Remove { pointer } => remove(json, pointer)?,
            Edit::DeclareUsed { extension } => declare_used(json, extension)?,
        };
    }
    Ok(changed)
}

fn kind_of(value: &Value) -> &'static str {
    match value {
        Value::Null => "null",
        Value::Bool(_) => "boolean",
        Value::Number(_) => "number",
        Value::String(_) => "string",
        Value::Array(_) => "array",
        Value::Object(_) => "object",
    }
}

/// Index of `token` in an array of `len`; `append` allows `len` and `-` (the end).
fn array_index(token: &str, len: usize, append: bool, path: &str) -> Result<usize, EditError> {
    let bad = || EditError::BadIndex {
        pointer: path.to_string(),
        token: token.to_string(),
        len,
    };
    if token == "-" {
        return if append { Ok(len) } else { Err(bad()) };
    }
    // RFC 6901: no leading zeros, no sign.
    let index = crate::asset::pointer::array_index(token).ok_or_else(bad)?;
    if index < len || (append && index == len) {
        Ok(index)
    } else {
        Err(bad())
    }
}

/// The container that holds the last token of `path`, creating missing objects on the way.
fn parent_mut<'a>(
    json: &'a mut Value,
    path: &str,
    tokens: &[String],
) -> Result<&'a mut Value, EditError> {
    let mut current = json;
    for token in tokens {
        current = match current {
            Value::Object(map) => map
                .entry(token.clone())
                .or_insert_with(|| Value::Object(Map::new())),
            Value::Array(items) => {
                let index = array_index(token, items.len(), false, path)?;
                &mut items[index]
            }
            other => {
                return Err(EditError::NotAContainer {
                    pointer: path.to_string(),
                    token: token.clone(),
                    kind: kind_of(other),
                })
            }
        };
    }
    Ok(current)
}

fn set(json: &mut Value, path: &str, value: Value) -> Result<bool, EditError> {
    let tokens = pointer::tokens(path);
    let Some((last, parents)) = tokens.split_last() else {
        return Err(EditError::Root {
            pointer: path.to_string(),
        });
    };
    match parent_mut(json, path, parents)? {
        // `insert` on an existing key keeps its place (the map preserves order).
        Value::Object(map) => {
            let changed = map.get(last) != Some(&value);
            map.insert(last.clone(), value);
            Ok(changed)
        }
        Value::Array(items) => {
            let index = array_index(last, items.len(), true, path)?;
            if index == items.len() {
                items.push(value);
                Ok(true)
            } else {
                let changed = items[index] != value;
                items[index] = value;
                Ok(changed)
            }
        }
        other => Err(EditError::NotAContainer {
            pointer: path.to_string(),
            token: last.clone(),
            kind: kind_of(other),
        }),
    }
}

fn remove(json: &mut Value, path: &str) -> Result<bool, EditError> {
    let tokens = pointer::tokens(path);
    let Some((last, parents)) = tokens.split_last() else {
        return Err(EditError::Root {
            pointer: path.to_string(),
        });
    };
    // The parent, found token by token as `Value::pointer_mut` finds it (an array index
    // without a sign or leading zeros), without writing its pointer and splitting it again.
    let mut parent = json;
    for token in parents {
        let child = match parent {
            Value::Object(map) => map.get_mut(token.as_str()),
            Value::Array(items) => pointer::array_index(token).and_then(move |i| items.get_mut(i)),
            _ => None,
        };
        let Some(child) = child else {
            return Ok(false);
        };
        parent = child;
    }
    Ok(match parent {
        // shift_remove: `remove` would move the last key into the gap.
        Value::Object(map) => map.shift_remove(last).is_some(),
        Value::Array(items) => match array_index(last, items.len(), false, path) {
            Ok(index) => {
                items.remove(index);
                true
            }
            Err(_) => false,
        },
        _ => false,
    })
}

fn declare_used(json: &mut Value, extension: &str) -> Result<bool, EditError> {
    let Value::Object(root) = json else {
        return Err(EditError::NotAContainer {
            pointer: "/extensionsUsed".into(),
            token: "extensionsUsed".into(),
            kind: kind_of(json),
        });
    };
    match root.get_mut("extensionsUsed") {
        Some(Value::Array(used)) => {
            if used.iter().any(|e| e.as_str() == Some(extension)) {
                return Ok(false);
            }
            used.push(Value::String(extension.to_string()));
            Ok(true)
        }
        Some(_) => Err(EditError::ExtensionsUsedNotArray),
        None => {
            // Where glTF writers put it: right after `asset` (or first when there is none).
            let at = root.keys().position(|k| k == "asset").map_or(0, |i| i + 1);
            root.shift_insert(
                at,
                "extensionsUsed".to_string(),
                Value::Array(vec![Value::String(extension.to_string())]),
            );
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn doc(text: &str) -> Value {
        serde_json::from_str(text).unwrap()
    }

    fn text(v: &Value) -> String {
        serde_json::to_string(v).unwrap()
    }

    /// A value set as its text reads, prints, serialises and compares as the value set as a
    /// value, and applies as it does.
    #[test]
    fn a_value_set_as_text_is_the_value_set_as_a_value() {
        let value =
            json!({"fuzzFactor": 0.75, "fuzzColorFactor": [1.0, 0.5, 0], "t": {"index": 2}});
        let as_value = Edit::set("/materials/0/x", value.clone());
        let as_text = Edit::set_text("/materials/0/x", text(&value));
        assert_eq!(as_text, as_value);
        assert_eq!(as_text.to_string(), as_value.to_string());
        assert_eq!(
            as_text.to_string(),
            r#"set /materials/0/x = {"fuzzFactor":0.75,"fuzzColorFactor":[1.0,0.5,0],"t":{"index":2}}"#
        );
        assert_eq!(
            serde_json::to_string_pretty(&as_text).unwrap(),
            serde_json::to_string_pretty(&as_value).unwrap()
        );
        assert_ne!(
            as_text,
            Edit::set("/materials/0/x", json!({"fuzzFactor": 0.75}))
        );
        let mut a = doc(r#"{"materials":[{}]}"#);
        let mut b = a.clone();
        assert!(apply(&mut a, &[as_text]).unwrap());
        assert!(apply(&mut b, &[as_value]).unwrap());
        assert_eq!(text(&a), text(&b));
    }

    #[test]
    fn set_replaces_in_place_appends_new_keys_and_creates_objects() {
        let mut v = doc(r#"{"a":1,"b":{"x":0.50},"c":[1,2]}"#);
        apply(
            &mut v,
            &[
                Edit::set("/a", json!(2)),
                Edit::set("/b/y", json!([1.0])),
                Edit::set("/d/e/f", json!("new")),
                Edit::set("/c/1", json!(3)),
                Edit::set("/c/2", json!(4)),
                Edit::set("/c/-", json!(5)),
            ],
        )
        .unwrap();
        assert_eq!(
            text(&v),
            r#"{"a":2,"b":{"x":0.50,"y":[1.0]},"c":[1,3,4,5],"d":{"e":{"f":"new"}}}"#
        );
    }

    #[test]
    fn remove_keeps_the_order_of_the_other_keys_and_ignores_absent_values() {
        let mut v = doc(r#"{"a":1,"b":2,"c":3,"d":[0,1,2]}"#);
        apply(
            &mut v,
            &[
                Edit::remove("/b"),
                Edit::remove("/zz/y"),
                Edit::remove("/d/0"),
                Edit::remove("/d/9"),
            ],
        )
        .unwrap();
        assert_eq!(text(&v), r#"{"a":1,"c":3,"d":[1,2]}"#);
    }

    #[test]
    fn remove_reaches_its_parent_through_arrays_only_by_plain_indices_and_escaped_keys() {
        // As a JSON pointer reads them: no sign, no leading zero; `~1` a slash, `~0` a tilde.
        let mut v = doc(r#"{"a":[{"x":1},{"x":2,"y":3}],"k/~":{"m":1,"n":2}}"#);
        let changed = apply(
            &mut v,
            &[
                Edit::remove("/a/01/x"),
                Edit::remove("/a/+1/x"),
                Edit::remove("/a/-/x"),
                Edit::remove("/a/0/x/deeper"),
            ],
        )
        .unwrap();
        assert!(!changed);
        apply(&mut v, &[Edit::remove("/a/1/x"), Edit::remove("/k~1~0/m")]).unwrap();
        assert_eq!(text(&v), r#"{"a":[{"x":1},{"y":3}],"k/~":{"n":2}}"#);
    }

    #[test]
    fn escaped_tokens_name_keys_with_slash_and_tilde() {
        let mut v = doc(r#"{"a/b":{"~":1}}"#);
        apply(
            &mut v,
            &[
                Edit::set("/a~1b/~0", json!(2)),
                Edit::set("/a~1b/x~1y", json!(3)),
            ],
        )
        .unwrap();
        assert_eq!(text(&v), r#"{"a/b":{"~":2,"x/y":3}}"#);
    }

    #[test]
    fn declare_used_appends_once_or_creates_the_array_after_asset() {
        let mut v = doc(r#"{"asset":{"version":"2.0"},"extensionsUsed":["A"]}"#);
        apply(
            &mut v,
            &[
                Edit::declare_used("B"),
                Edit::declare_used("A"),
                Edit::declare_used("B"),
            ],
        )
        .unwrap();
        assert_eq!(
            text(&v),
            r#"{"asset":{"version":"2.0"},"extensionsUsed":["A","B"]}"#
        );
        let mut v = doc(r#"{"asset":{"version":"2.0"},"materials":[]}"#);
        apply(&mut v, &[Edit::declare_used("B")]).unwrap();
        assert_eq!(
            text(&v),
            r#"{"asset":{"version":"2.0"},"extensionsUsed":["B"],"materials":[]}"#
        );
    }

    #[test]
    fn apply_tells_whether_the_document_changed() {
        let mut v = doc(r#"{"asset":{},"extensionsUsed":["A"],"a":{"x":1.0},"l":[1]}"#);
        let no_ops = [
            Edit::set("/a/x", json!(1.0)),
            Edit::set("/l/0", json!(1)),
            Edit::remove("/a/missing"),
            Edit::remove("/l/4"),
            Edit::declare_used("A"),
        ];
        assert!(!apply(&mut v, &no_ops).unwrap());
        for edit in [
            Edit::set("/a/x", json!(1)),
            Edit::set("/l/-", json!(2)),
            Edit::remove("/l/0"),
            Edit::declare_used("B"),
        ] {
            assert!(
                apply(&mut v, std::slice::from_ref(&edit)).unwrap(),
                "{edit}"
            );
        }
        assert_eq!(
            text(&v),
            r#"{"asset":{},"extensionsUsed":["A","B"],"a":{"x":1},"l":[2]}"#
        );
    }

    #[test]
    fn faults_name_the_pointer() {
        let mut v = doc(r#"{"a":[1],"n":3,"extensionsUsed":{}}"#);
        assert_eq!(
            apply(&mut v, &[Edit::set("/a/5", json!(0))]).unwrap_err(),
            EditError::BadIndex {
                pointer: "/a/5".into(),
                token: "5".into(),
                len: 1
            }
        );
        assert_eq!(
            apply(&mut v, &[Edit::set("/a/01", json!(0))]).unwrap_err(),
            EditError::BadIndex {
                pointer: "/a/01".into(),
                token: "01".into(),
                len: 1
            }
        );
        assert_eq!(
            apply(&mut v, &[Edit::set("/n/x", json!(0))]).unwrap_err(),
            EditError::NotAContainer {
                pointer: "/n/x".into(),
                token: "x".into(),
                kind: "number"
            }
        );
        assert_eq!(
            apply(&mut v, &[Edit::set("", json!(0))]).unwrap_err(),
            EditError::Root { pointer: "".into() }
        );
        assert_eq!(
            apply(&mut v, &[Edit::declare_used("X")]).unwrap_err(),
            EditError::ExtensionsUsedNotArray
        );
    }

    #[test]
    fn edits_print_as_one_line_each_and_serialise_with_their_op() {
        let e = Edit::set("/materials/0/x", json!([1.0, 0.5]));
        assert_eq!(e.to_string(), "set /materials/0/x = [1.0,0.5]");
        assert_eq!(Edit::remove("/a").to_string(), "remove /a");
        assert_eq!(
            Edit::declare_used("KHR_materials_fuzz").to_string(),
            "declare KHR_materials_fuzz in /extensionsUsed"
        );
        assert_eq!(
            text(&serde_json::to_value(&e).unwrap()),
            r#"{"op":"set","pointer":"/materials/0/x","value":[1.0,0.5]}"#
        );
    }
}
