//! Placement: KHR_materials_sheen and KHR_materials_fuzz are material extensions. The same
//! object anywhere else (under pbrMetallicRoughness, a texture, a node, the root) is ignored by
//! loaders, which is almost always an exporter bug.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{Kind, Node};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use std::fmt::Write;

pub const UNEXPECTED_EXTENSION_OBJECT: Code = Code::new(
    "UNEXPECTED_EXTENSION_OBJECT",
    Severity::Error,
    "A sheen or fuzz object stands somewhere other than a material's extensions.",
);

pub struct Placement;

impl Rule for Placement {
    fn codes(&self) -> &'static [&'static Code] {
        &[&UNEXPECTED_EXTENSION_OBJECT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        // When every sheen and fuzz key in the document is a material's layer, none is out of
        // place; the walk, which finds where one is, is needed only otherwise.
        let json = cx.json();
        let keys = [layers::SHEEN, layers::FUZZ]
            .iter()
            .map(|name| json.members_named(name).count())
            .sum::<usize>();
        if keys == cx.layer_objects().count() {
            return;
        }
        let mut path = String::new();
        walk(json, &mut path, 0, out);
    }
}

/// Whether `path` (the pointer of an object holding `extensions`) is `/materials/N`.
fn is_material(path: &str) -> bool {
    path.strip_prefix("/materials/")
        .is_some_and(|rest| !rest.is_empty() && rest.bytes().all(|b| b.is_ascii_digit()))
}

fn walk(value: Node, path: &mut String, depth: usize, out: &mut Vec<Diagnostic>) {
    // Extension objects are never deeper than this in any real asset; stop rather than recurse
    // without bound on hostile input.
    if depth > 64 {
        return;
    }
    match value.kind() {
        Kind::Object => {
            let Some(map) = value.as_object() else { return };
            if let Some(exts) = map.get("extensions").and_then(|e| e.as_object()) {
                for name in [layers::SHEEN, layers::FUZZ] {
                    if exts.contains_key(name) && !is_material(path) {
                        out.push(Diagnostic::new(
                            &UNEXPECTED_EXTENSION_OBJECT,
                            format!("{path}/extensions/{name}"),
                            format!("{name} is a material extension; here it has no effect"),
                        ));
                    }
                }
            }
            for (key, child) in map.iter() {
                if child.is_object() || child.is_array() {
                    let len = path.len();
                    path.push('/');
                    path.push_str(&pointer::escape(&key));
                    walk(child, path, depth + 1, out);
                    path.truncate(len);
                }
            }
        }
        Kind::Array => {
            let Some(items) = value.as_array() else {
                return;
            };
            for (i, child) in items.iter().enumerate() {
                if child.is_object() || child.is_array() {
                    let len = path.len();
                    let _ = write!(path, "/{i}");
                    walk(child, path, depth + 1, out);
                    path.truncate(len);
                }
            }
        }
        _ => {}
    }
}
