//! The document as loaded compared with the edited value ([`matches()`]), and the splices that
//! make one the other: a changed value replaces its span, a new key goes after the member that
//! precedes it in the edited document (first when none does), a new element after the last
//! element of its array, a removed member takes its separator with it. The loaded document is
//! read off the index as the comparison goes, never held as a whole; what is inserted is laid
//! out in the file's own layout ([`Layout`]).

use super::layout::{concat, one_line, Layout};
use super::read_back::{scalar_matches, Compare, Meant};
use super::Splice;
use crate::asset::json_text::push_quoted;
use crate::asset::tape::{Kind, Node};
use serde_json::{Map, Value};

pub(super) fn diff(text: &str, node: Node, after: &Value, layout: &Layout, out: &mut Vec<Splice>) {
    if matches(node, after, Compare::Exact) {
        return;
    }
    match (node.kind(), after) {
        (Kind::Object, Value::Object(a)) => diff_object(text, node, a, layout, out),
        (Kind::Array, Value::Array(a))
            if node.as_array().is_some_and(|items| a.len() >= items.len()) =>
        {
            let items = node.as_array().expect("an array");
            for (item, new) in items.iter().zip(a) {
                diff(text, item, new, layout, out);
            }
            if a.len() > items.len() {
                append(
                    text,
                    node,
                    items.iter().next_back().map(|i| i.span().end),
                    &a[items.len()..],
                    layout,
                    out,
                );
            }
        }
        _ => replace(text, node, after, layout, out),
    }
}

/// True when the value `node` is `value`.
pub(super) fn matches(node: Node, value: &Value, compare: Compare) -> bool {
    match (node.kind(), value) {
        (Kind::Object, Value::Object(map)) => {
            let Some(object) = node.as_object() else {
                return false;
            };
            // A key written twice never matches: the object is written anew.
            !object.has_duplicate_keys()
                && object.len() == map.len()
                && object.iter().all(|(key, member)| {
                    map.get(key.as_ref())
                        .is_some_and(|v| matches(member, v, compare))
                })
        }
        (Kind::Array, Value::Array(values)) => node.as_array().is_some_and(|items| {
            items.len() == values.len()
                && items
                    .iter()
                    .zip(values)
                    .all(|(item, v)| matches(item, v, compare))
        }),
        (Kind::Object | Kind::Array, _) => false,
        _ => scalar_matches(node.raw(), value, compare),
    }
}

/// Writes `after` over `span`: on one line where the old value was a one-line container, laid
/// out over lines (at the indentation of the line it starts on) where it was a scalar or a
/// multi-line container.
pub(super) fn replace(
    text: &str,
    node: Node,
    after: &Value,
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let was_one_line_container =
        matches!(node.kind(), Kind::Object | Kind::Array) && one_line(text, node);
    let span = node.span();
    out.push(Splice {
        start: span.start,
        end: span.end,
        text: layout.render(
            after,
            layout.line_indent(text, span.start),
            was_one_line_container,
        ),
    });
}

fn diff_object(
    text: &str,
    span: Node,
    after: &Map<String, Value>,
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(object) = span.as_object() else {
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    };
    if object.has_duplicate_keys() {
        // A key twice: the object is written anew, in place.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    // (where the key's opening quote stands, the value), and the keys decoded.
    let entries = object.entries();
    let members = member_starts(&entries);
    let keys: Vec<std::borrow::Cow<str>> = entries
        .iter()
        .map(|(k, _)| k.as_str().unwrap_or_default())
        .collect();
    let removed: Vec<bool> = keys
        .iter()
        .map(|k| !after.contains_key(k.as_ref()))
        .collect();
    let added: Vec<(&String, &Value)> = after
        .iter()
        .filter(|(k, _)| !keys.iter().any(|have| have == *k))
        .collect();
    let any_removed = removed.iter().any(|r| *r);
    if any_removed && (!added.is_empty() || removed.iter().all(|r| *r)) {
        // Members both leave and arrive, or all leave: the object is written anew, in place.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    for (i, ((_, value), key)) in members.iter().zip(&keys).enumerate() {
        if removed[i] {
            out.extend(removal(&members, i));
        } else {
            diff(text, *value, &after[key.as_ref()], layout, out);
        }
    }
    if added.is_empty() {
        return;
    }
    if members.is_empty() {
        // An empty object: written anew with its members.
        return replace(text, span, &Value::Object(after.clone()), layout, out);
    }
    // A new key goes after the member that precedes it in the edited document (the edit
    // applier puts `extensionsUsed` after `asset`, say), or first when none does.
    let position: std::collections::HashMap<&str, usize> = keys
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_ref(), i))
        .collect();
    let mut anchor: Option<usize> = None;
    let mut placed: Vec<(Option<usize>, &str, Meant)> = Vec::new();
    for (key, value) in after {
        match position.get(key.as_str()) {
            Some(i) => anchor = Some(*i),
            None => placed.push((anchor, key, Meant::Value(value))),
        }
    }
    insert_members(text, span, &members, &placed, layout, out);
}

/// An object's members as the splices cut them: (where the key's opening quote stands, the
/// value), from its entries (key, value).
pub(super) fn member_starts<'a>(entries: &[(Node<'a>, Node<'a>)]) -> Vec<(usize, Node<'a>)> {
    entries.iter().map(|(k, v)| (k.span().start, *v)).collect()
}

/// The splice that removes member `i` of an object with `members` (as (where the key starts,
/// the value)) with one separator; `None` for an only member (its object is written anew).
pub(super) fn removal(members: &[(usize, Node)], i: usize) -> Option<Splice> {
    let (start, end) = match (i, members.get(i + 1)) {
        // A member after the first takes the separator before it.
        (i, _) if i > 0 => (members[i - 1].1.span().end, members[i].1.span().end),
        // The first member takes the separator after it.
        (_, Some((next_key, _))) => (members[i].0, *next_key),
        (_, None) => return None,
    };
    Some(Splice {
        start,
        end,
        text: String::new(),
    })
}

/// Inserts new members into the object `span` (whose members are `members`, as (where the key
/// starts, the value)): each after the member its anchor names, or first without one, in the
/// order given, laid out as the object's own members are.
pub(super) fn insert_members(
    text: &str,
    span: Node,
    members: &[(usize, Node)],
    placed: &[(Option<usize>, &str, Meant)],
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(first) = members.first() else {
        return;
    };
    let layout = &layout.local(text, span.span().start, first.0);
    let inline = layout.unit.is_none() || one_line(text, span);
    let indent = layout.line_indent(text, first.0);
    // Between members: what the object's first two members have between them, or a comma
    // and a line break to the members' indentation.
    let between = match (inline, members.get(1)) {
        (true, Some((k, _))) => &text[first.1.span().end..*k],
        (true, None) => layout.inline_comma(),
        (false, _) => "",
    };
    let push_separator = |text: &mut String| {
        if inline {
            text.push_str(between);
        } else {
            text.push(',');
            text.push_str(layout.newline);
            text.push_str(indent);
        }
    };
    let push_member = |text: &mut String, key: &str, value: Meant| {
        push_quoted(text, key);
        text.push_str(&layout.colon);
        let inline = inline || layout.unit.is_none();
        match value {
            Meant::Value(value) => layout.write(value, indent, inline, text),
            Meant::Text(compact) => layout.write_text(compact, indent, inline, text),
        }
    };
    // Room for a layer object of a few members, so that writing one grows a string once at
    // most.
    const ROOM: usize = 256;
    let mut leading = String::new();
    let mut after_member: Vec<(usize, String)> = Vec::new();
    for &(anchor, key, value) in placed {
        match anchor {
            None => {
                leading.reserve(ROOM);
                push_member(&mut leading, key, value);
                push_separator(&mut leading);
            }
            Some(i) => {
                if !matches!(after_member.last(), Some((at, _)) if *at == i) {
                    after_member.push((i, String::with_capacity(ROOM)));
                }
                if let Some((_, insert)) = after_member.last_mut() {
                    push_separator(insert);
                    push_member(insert, key, value);
                }
            }
        }
    }
    if !leading.is_empty() {
        leading.shrink_to_fit();
        out.push(Splice {
            start: first.0,
            end: first.0,
            text: leading,
        });
    }
    for (i, mut insert) in after_member {
        // Kept to the end of the write, by the twenty thousand: cut to its length.
        insert.shrink_to_fit();
        let end = members[i].1.span().end;
        out.push(Splice {
            start: end,
            end,
            text: insert,
        });
    }
}

fn append(
    text: &str,
    span: Node,
    last_end: Option<usize>,
    items: &[Value],
    layout: &Layout,
    out: &mut Vec<Splice>,
) {
    let Some(last_end) = last_end else {
        // An empty array: written anew with its elements.
        let mut all = Vec::with_capacity(items.len());
        all.extend_from_slice(items);
        return replace(text, span, &Value::Array(all), layout, out);
    };
    let inline = layout.unit.is_none() || one_line(text, span);
    let Some(existing) = span.as_array() else {
        return;
    };
    let (Some(first), Some(last)) = (existing.get(0), existing.iter().next_back()) else {
        return;
    };
    let layout = &layout.local(text, span.span().start, first.span().start);
    let indent = layout.line_indent(text, last.span().start).to_string();
    let separator = if inline {
        existing
            .get(1)
            .map(|second| text[first.span().end..second.span().start].to_string())
            .unwrap_or_else(|| layout.inline_comma().to_string())
    } else {
        concat(&[",", layout.newline, &indent])
    };
    let mut insert = String::new();
    for item in items {
        insert.push_str(&separator);
        insert.push_str(&layout.render(item, &indent, inline));
    }
    out.push(Splice {
        start: last_end,
        end: last_end,
        text: insert,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::splice::reads_as_written;
    use crate::edit::splice::tests::spliced;

    /// Applies `edit` to the parsed `text` and splices the result back.
    fn edited(text: &str, edit: impl FnOnce(&mut Value)) -> String {
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = before.clone();
        edit(&mut after);
        let out = spliced(text, &after);
        let reread: Value = serde_json::from_str(&out).unwrap();
        assert_eq!(
            reread, after,
            "the spliced text reads back as the edited document"
        );
        assert!(reads_as_written(&out, &after));
        out
    }

    fn add_fuzz(doc: &mut Value) {
        doc["materials"][0]["extensions"]["KHR_materials_fuzz"] =
            serde_json::json!({"fuzzColorFactor": [0.5, 0.25, 1.0], "fuzzRoughnessFactor": 0.5});
    }

    #[test]
    fn a_key_goes_into_its_object_in_the_files_layout() {
        let text = "{\n\t\"materials\": [\n\t\t{\n\t\t\t\"extensions\": {\n\t\t\t\t\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1, 1]}\n\t\t\t}\n\t\t}\n\t]\n}";
        let out = edited(text, add_fuzz);
        assert_eq!(
            out,
            "{\n\t\"materials\": [\n\t\t{\n\t\t\t\"extensions\": {\n\t\t\t\t\"KHR_materials_sheen\": {\"sheenColorFactor\": [1, 1, 1]},\n\t\t\t\t\"KHR_materials_fuzz\": {\n\t\t\t\t\t\"fuzzColorFactor\": [0.5, 0.25, 1.0],\n\t\t\t\t\t\"fuzzRoughnessFactor\": 0.5\n\t\t\t\t}\n\t\t\t}\n\t\t}\n\t]\n}"
        );
    }

    #[test]
    fn a_minified_file_stays_minified_and_crlf_stays_crlf() {
        let text = r#"{"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":1E-1}}}]}"#;
        assert_eq!(
            edited(text, add_fuzz),
            r#"{"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":1E-1},"KHR_materials_fuzz":{"fuzzColorFactor":[0.5,0.25,1.0],"fuzzRoughnessFactor":0.5}}}]}"#
        );
        let text = "{\r\n  \"asset\": {\"version\": \"2.0\"},\r\n  \"extensionsUsed\": [\r\n    \"KHR_materials_sheen\"\r\n  ]\r\n}\r\n";
        let out = edited(text, |d| {
            d["extensionsUsed"]
                .as_array_mut()
                .unwrap()
                .push("KHR_materials_fuzz".into())
        });
        assert_eq!(
            out,
            "{\r\n  \"asset\": {\"version\": \"2.0\"},\r\n  \"extensionsUsed\": [\r\n    \"KHR_materials_sheen\",\r\n    \"KHR_materials_fuzz\"\r\n  ]\r\n}\r\n"
        );
    }

    #[test]
    fn one_line_objects_stay_on_one_line_and_untouched_spellings_stay() {
        let text = "{\n    \"a\": {\"x\": 1.0, \"y\": \"\\u00e9\"},\n    \"b\": 3E2\n}";
        let out = edited(text, |d| d["a"]["z"] = serde_json::json!([1, 2]));
        assert_eq!(
            out,
            "{\n    \"a\": {\"x\": 1.0, \"y\": \"\\u00e9\", \"z\": [1, 2]},\n    \"b\": 3E2\n}"
        );
    }

    #[test]
    fn a_changed_value_replaces_its_span_and_a_removed_member_takes_its_separator() {
        let text = "{\n  \"a\": 0.5,\n  \"b\": [1, 2],\n  \"c\": true\n}\n";
        let out = edited(text, |d| {
            d["a"] = serde_json::json!(0.25);
            d.as_object_mut().unwrap().remove("b");
        });
        assert_eq!(out, "{\n  \"a\": 0.25,\n  \"c\": true\n}\n");
        // A computed value with float noise is written rounded.
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = before.clone();
        after["a"] = serde_json::json!(0.7499999999999999);
        assert_eq!(
            spliced(text, &after),
            "{\n  \"a\": 0.75,\n  \"b\": [1, 2],\n  \"c\": true\n}\n"
        );
        let out = edited(text, |d| {
            d.as_object_mut().unwrap().remove("a");
        });
        assert_eq!(out, "{\n  \"b\": [1, 2],\n  \"c\": true\n}\n");
    }

    #[test]
    fn a_new_key_follows_the_key_before_it_in_the_edited_document() {
        let text = "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"materials\": []\n}\n";
        let before: Value = serde_json::from_str(text).unwrap();
        let mut after = serde_json::Map::new();
        after.insert("first".into(), serde_json::json!(1));
        after.insert("asset".into(), before["asset"].clone());
        after.insert(
            "extensionsUsed".into(),
            serde_json::json!(["KHR_materials_fuzz"]),
        );
        after.insert("materials".into(), serde_json::json!([]));
        assert_eq!(
            spliced(text, &Value::Object(after)),
            "{\n  \"first\": 1,\n  \"asset\": {\"version\": \"2.0\"},\n  \"extensionsUsed\": [\n    \"KHR_materials_fuzz\"\n  ],\n  \"materials\": []\n}\n"
        );
    }

    #[test]
    fn an_unchanged_document_is_the_same_text() {
        let text = "{ \"a\" :[ 1 ,2 ] ,\"b\":{} }";
        assert_eq!(edited(text, |_| {}), text);
    }
}
