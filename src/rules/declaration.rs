//! Declared extensions. Every extension object in the document must be named in
//! `extensionsUsed` (loaders that meet an undeclared extension may ignore it or refuse the
//! file); every name in `extensionsRequired` must also be in `extensionsUsed`. A declared sheen
//! or fuzz extension that no material uses is a warning: it makes loaders without it refuse or
//! warn for nothing.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{KeyId, Kind, Node};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use std::collections::BTreeSet;

pub const UNDECLARED_EXTENSION: Code = Code::new(
    "UNDECLARED_EXTENSION",
    Severity::Error,
    "An extension object is used but its extension is not in extensionsUsed.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const UNUSED_EXTENSION_REQUIRED: Code = Code::new(
    "UNUSED_EXTENSION_REQUIRED",
    Severity::Error,
    "An extension in extensionsRequired is missing from extensionsUsed.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const SHEEN_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_SHEEN_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_sheen is in extensionsUsed but no material uses it.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const FUZZ_DECLARED_UNUSED: Code = Code::new(
    "KHR_MATERIALS_FUZZ_DECLARED_UNUSED",
    Severity::Warning,
    "KHR_materials_fuzz is in extensionsUsed but no material uses it.",
)
.fixable(crate::diagnostics::Safety::Safe);

pub struct Declaration;

fn names(json: Node, key: &str) -> Vec<(usize, String)> {
    json.get(key)
        .and_then(|a| a.as_array())
        .map(|a| {
            a.iter()
                .enumerate()
                .filter_map(|(i, v)| Some((i, v.as_str()?.to_string())))
                .collect()
        })
        .unwrap_or_default()
}

impl Rule for Declaration {
    /// The names of the extension objects, where the first of each stands, and the two lists.
    fn reads(&self) -> super::Reads {
        super::Reads::Extensions
    }

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
        undeclared(json, &declared, out);
        check_lists(json, &declared, cx.layer_extensions_present(), out);
    }
}

/// One finding per extension used but not declared, at the first place it is used.
fn undeclared(json: Node, declared: &BTreeSet<String>, out: &mut Vec<Diagnostic>) {
    // Every name in every `extensions` object (extras included, so a superset of what the walk
    // visits): when all are declared there is nothing to report, and no walk to do.
    // The first few distinct names are judged once each, by their key numbers: a library
    // writes the same one or two on each of thousands of materials.
    let mut judged: Vec<(KeyId, bool)> = Vec::new();
    let mut is_declared = |id: KeyId, name: &str| {
        if let Some(&(_, known)) = judged.iter().find(|(seen, _)| *seen == id) {
            return known;
        }
        let known = declared.contains(name);
        if judged.len() < 32 {
            judged.push((id, known));
        }
        known
    };
    let all_declared = json.members_named("extensions").all(|exts| {
        exts.as_object().is_none_or(|o| {
            o.iter_keyed()
                .all(|(id, name, _)| is_declared(id, name.as_ref()))
        })
    });
    if all_declared {
        return;
    }
    let mut reported = BTreeSet::new();
    extension_objects(json, &mut Vec::new(), &mut |path, name| {
        if !declared.contains(name) && reported.insert(name.to_string()) {
            let at: String = path
                .iter()
                .map(|t| format!("/{}", pointer::escape(t)))
                .collect();
            out.push(Diagnostic::new(
                &UNDECLARED_EXTENSION,
                at,
                format!("{name} is used but not declared in extensionsUsed"),
            ));
        }
    });
}

/// The findings about extensionsUsed and extensionsRequired themselves; `used` says whether
/// any material has a sheen, and a fuzz, object.
fn check_lists(
    json: Node,
    declared: &BTreeSet<String>,
    used: [bool; 2],
    out: &mut Vec<Diagnostic>,
) {
    for (k, name) in names(json, "extensionsRequired") {
        if !declared.contains(&name) {
            out.push(Diagnostic::new(
                &UNUSED_EXTENSION_REQUIRED,
                format!("/extensionsRequired/{k}"),
                format!("{name} is required but not in extensionsUsed"),
            ));
        }
    }
    for (k, name) in names(json, "extensionsUsed") {
        let (is_used, code) = match name.as_str() {
            layers::SHEEN => (used[0], &SHEEN_DECLARED_UNUSED),
            layers::FUZZ => (used[1], &FUZZ_DECLARED_UNUSED),
            _ => continue,
        };
        // The layers found on materials answer at once; an object elsewhere (misplaced on
        // pbrMetallicRoughness, say) is a use too, found by the walk the fixes share.
        if !is_used && !is_used_anywhere(json, &name) {
            out.push(Diagnostic::new(
                code,
                format!("/extensionsUsed/{k}"),
                format!("{name} is declared in extensionsUsed but no material uses it"),
            ));
        }
    }
}

/// Whether any extension object of the document is named `name`, wherever it stands: the one
/// notion of "used" that the declaration rules and their fixes share (an extension object on
/// the wrong kind of object is UNEXPECTED_EXTENSION_OBJECT, but still needs its declaration).
pub fn is_used_anywhere(json: Node, name: &str) -> bool {
    // No `extensions` object anywhere (extras included, a superset of what the walk visits)
    // has the name: then no walk is needed.
    if !json
        .members_named("extensions")
        .any(|extensions| extensions.get(name).is_some())
    {
        return false;
    }
    let mut used = false;
    extension_objects(json, &mut Vec::new(), &mut |_, found| used |= found == name);
    used
}

/// Calls `found` with the path and name of every extension object: every key of an
/// `extensions` object of a glTF property, including properties nested in extensions
/// (a KHR_texture_transform inside a sheen texture). `extras` hold application data, not glTF
/// properties, and are not searched. The path is kept as tokens (array indices as text) and
/// made a pointer only for what is reported.
fn extension_objects<'a>(
    value: Node<'a>,
    path: &mut Vec<std::borrow::Cow<'a, str>>,
    found: &mut dyn FnMut(&[std::borrow::Cow<'a, str>], &str),
) {
    match value.kind() {
        Kind::Object => {
            for (key, child) in value.as_object().into_iter().flat_map(|o| o.iter()) {
                if key == "extras" {
                    continue;
                }
                let is_extensions = key == "extensions";
                path.push(key);
                if is_extensions {
                    for (name, ext) in child.as_object().into_iter().flat_map(|o| o.iter()) {
                        path.push(name.clone());
                        found(path.as_slice(), &name);
                        extension_objects(ext, path, found);
                        path.pop();
                    }
                } else if child.is_object() || child.is_array() {
                    extension_objects(child, path, found);
                }
                path.pop();
            }
        }
        Kind::Array => {
            for (i, child) in value
                .as_array()
                .into_iter()
                .flat_map(|a| a.iter())
                .enumerate()
            {
                if child.is_object() || child.is_array() {
                    path.push(i.to_string().into());
                    extension_objects(child, path, found);
                    path.pop();
                }
            }
        }
        _ => {}
    }
}
