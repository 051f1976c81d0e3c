//! Declared extensions. Every extension object in the document must be named in
//! `extensionsUsed` (loaders that meet an undeclared extension may ignore it or refuse the
//! file); every name in `extensionsRequired` must also be in `extensionsUsed`. A declared sheen
//! or fuzz extension that no material uses is a warning: it makes loaders without it refuse or
//! warn for nothing.

use super::{layer_objects, Context, Rule};
use crate::asset::pointer;
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use serde_json::Value;
use std::collections::BTreeSet;

pub const UNDECLARED_EXTENSION: Code = Code::new(
    "UNDECLARED_EXTENSION",
    Severity::Error,
    "An extension object is used but its extension is not in extensionsUsed.",
);
pub const UNUSED_EXTENSION_REQUIRED: Code = Code::new(
    "UNUSED_EXTENSION_REQUIRED",
    Severity::Error,
    "An extension in extensionsRequired is missing from extensionsUsed.",
);
pub const SHEEN_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_SHEEN_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_sheen is in extensionsUsed but no material uses it.",
);
pub const FUZZ_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_FUZZ_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_fuzz is in extensionsUsed but no material uses it.",
);

pub struct Declaration;

fn names(json: &Value, key: &str) -> Vec<(usize, String)> {
    json.get(key)
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .enumerate()
                .filter_map(|(i, v)| Some((i, v.as_str()?.to_string())))
                .collect()
        })
        .unwrap_or_default()
}

impl Rule for Declaration {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &UNDECLARED_EXTENSION,
            &UNUSED_EXTENSION_REQUIRED,
            &SHEEN_DECLARED_UNUSED,
            &FUZZ_DECLARED_UNUSED,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let declared: BTreeSet<String> = names(json, "extensionsUsed")
            .into_iter()
            .map(|(_, n)| n)
            .collect();
        let mut reported = BTreeSet::new();
        let mut at = String::new();
        extension_objects(json, &mut at, &mut |pointer, name| {
            // One finding per extension: the first place it is used.
            if !declared.contains(name) && reported.insert(name.to_string()) {
                out.push(Diagnostic::new(
                    &UNDECLARED_EXTENSION,
                    pointer,
                    format!("{name} is used but not declared in extensionsUsed"),
                ));
            }
        });
        for (k, name) in names(json, "extensionsRequired") {
            if !declared.contains(&name) {
                out.push(Diagnostic::new(
                    &UNUSED_EXTENSION_REQUIRED,
                    format!("/extensionsRequired/{k}"),
                    format!("{name} is required but not in extensionsUsed"),
                ));
            }
        }
        let mut used = [false, false];
        for layer in layer_objects(json) {
            used[usize::from(layer.extension == layers::FUZZ)] = true;
        }
        for (k, name) in names(json, "extensionsUsed") {
            let (is_used, code) = match name.as_str() {
                layers::SHEEN => (used[0], &SHEEN_DECLARED_UNUSED),
                layers::FUZZ => (used[1], &FUZZ_DECLARED_UNUSED),
                _ => continue,
            };
            if !is_used {
                out.push(Diagnostic::new(
                    code,
                    format!("/extensionsUsed/{k}"),
                    format!("{name} is declared in extensionsUsed but no material uses it"),
                ));
            }
        }
    }
}

/// Calls `found` with the pointer and name of every extension object: every key of an
/// `extensions` object of a glTF property, including properties nested in extensions
/// (a KHR_texture_transform inside a sheen texture). `extras` hold application data, not glTF
/// properties, and are not searched.
fn extension_objects(value: &Value, at: &mut String, found: &mut dyn FnMut(&str, &str)) {
    let len = at.len();
    match value {
        Value::Object(map) => {
            for (key, child) in map {
                if key == "extras" {
                    continue;
                }
                at.push('/');
                at.push_str(&pointer::escape(key));
                if key == "extensions" {
                    if let Value::Object(exts) = child {
                        for (name, ext) in exts {
                            let inner = at.len();
                            at.push('/');
                            at.push_str(&pointer::escape(name));
                            found(at, name);
                            extension_objects(ext, at, found);
                            at.truncate(inner);
                        }
                    }
                } else {
                    extension_objects(child, at, found);
                }
                at.truncate(len);
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                at.push('/');
                at.push_str(&i.to_string());
                extension_objects(child, at, found);
                at.truncate(len);
            }
        }
        _ => {}
    }
}
