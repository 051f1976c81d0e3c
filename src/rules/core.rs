//! Core structure: the gltf crate's own validation of the whole document (indices in range,
//! required properties, enum values), run on `gltf::json::Root` directly so that an unknown
//! entry in extensionsRequired does not stop it. Its paths (`meshes[0].primitives[1].material`)
//! are turned into JSON pointers.

use super::{Context, Rule};
use crate::diagnostics::{codes, Code, Diagnostic, Severity};
use gltf::json::validation::{Error as CoreError, Validate};

pub const CORE_INVALID_VALUE: Code = Code::new(
    "CORE_INVALID_VALUE",
    Severity::Error,
    "The core glTF structure holds a value the glTF 2.0 schema does not allow.",
);
pub const CORE_STRUCTURE_INVALID: Code = Code::new(
    "CORE_STRUCTURE_INVALID",
    Severity::Error,
    "The document does not have the core glTF 2.0 structure (a property of the wrong type or shape).",
);

pub struct CoreStructure;

/// `meshes[0].primitives[1].attributes["TEXCOORD_0"]` → `/meshes/0/primitives/1/attributes/TEXCOORD_0`.
pub fn path_to_pointer(path: &str) -> String {
    let mut out = String::new();
    let mut rest = path;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("[\"") {
            let end = after.find("\"]").unwrap_or(after.len());
            out.push('/');
            out.push_str(&crate::asset::pointer::escape(&after[..end]));
            rest = after.get(end + 2..).unwrap_or("");
        } else if let Some(after) = rest.strip_prefix('[') {
            let end = after.find(']').unwrap_or(after.len());
            out.push('/');
            out.push_str(&after[..end]);
            rest = after.get(end + 1..).unwrap_or("");
        } else {
            let rest_trim = rest.strip_prefix('.').unwrap_or(rest);
            let end = rest_trim.find(['.', '[']).unwrap_or(rest_trim.len());
            out.push('/');
            out.push_str(&crate::asset::pointer::escape(&rest_trim[..end]));
            rest = &rest_trim[end..];
        }
    }
    out
}

impl Rule for CoreStructure {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &CORE_INVALID_VALUE,
            &super::references::UNRESOLVED_REFERENCE,
            &codes::UNDEFINED_PROPERTY,
            &CORE_STRUCTURE_INVALID,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let text = cx.asset.json_text.trim_end_matches(['\0', ' ']);
        let mut root: gltf::json::Root = match gltf::json::deserialize::from_str(text) {
            Ok(root) => root,
            Err(e) => {
                out.push(Diagnostic::new(
                    &CORE_STRUCTURE_INVALID,
                    "",
                    format!(
                        "line {}, column {}: {}",
                        e.line(),
                        e.column(),
                        e.to_string()
                            .rsplit_once(" at line ")
                            .map_or(e.to_string(), |(m, _)| m.to_string())
                    ),
                ));
                return;
            }
        };
        let dangling = take_dangling_positions(&mut root);
        root.validate(&root, gltf::json::Path::new, &mut |path, error| {
            let path = path();
            // A POSITION taken out above is reported missing by the crate: it names no object.
            let error = match error {
                CoreError::Missing if dangling.iter().any(|d| d == path.as_str()) => {
                    CoreError::IndexOutOfBounds
                }
                other => other,
            };
            // The crate rejects required extensions it does not implement; that is a loader's
            // capability, not a fault of the asset.
            if path.as_str().starts_with("extensionsRequired") {
                return;
            }
            let pointer = path_to_pointer(path.as_str());
            let (code, message) = match error {
                CoreError::IndexOutOfBounds => (
                    &super::references::UNRESOLVED_REFERENCE,
                    format!("{}: the index names no object", path.as_str()),
                ),
                CoreError::Missing => (
                    &codes::UNDEFINED_PROPERTY,
                    format!("{}: required by glTF 2.0 but missing", path.as_str()),
                ),
                CoreError::Invalid => (
                    &CORE_INVALID_VALUE,
                    format!("{}: not a value glTF 2.0 allows here", path.as_str()),
                ),
                CoreError::Oversize => (
                    &CORE_INVALID_VALUE,
                    format!("{}: too large for this platform", path.as_str()),
                ),
                // Only raised for extensionsRequired, which is skipped above.
                CoreError::Unsupported => return,
            };
            out.push(Diagnostic::new(code, pointer, message));
        });
    }
}

/// gltf-json 1.4 looks up a primitive's POSITION accessor without checking the index, and
/// panics when it names no accessor. Such attributes are taken out of the (local) document
/// before the crate's check; their paths are returned so that the check reports them as the
/// dangling references they are.
fn take_dangling_positions(root: &mut gltf::json::Root) -> Vec<String> {
    use gltf::json::{mesh::Semantic, validation::Checked};
    let accessors = root.accessors.len();
    let mut dangling = Vec::new();
    for (m, mesh) in root.meshes.iter_mut().enumerate() {
        for (p, primitive) in mesh.primitives.iter_mut().enumerate() {
            let key = Checked::Valid(Semantic::Positions);
            if primitive
                .attributes
                .get(&key)
                .is_some_and(|i| i.value() >= accessors)
            {
                primitive.attributes.remove(&key);
                dangling.push(format!(
                    "meshes[{m}].primitives[{p}].attributes[\"POSITION\"]"
                ));
            }
        }
    }
    dangling
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gltf_paths_become_pointers() {
        assert_eq!(
            path_to_pointer("meshes[0].primitives[12].material"),
            "/meshes/0/primitives/12/material"
        );
        assert_eq!(
            path_to_pointer("meshes[0].primitives[0].attributes[\"TEXCOORD_0\"]"),
            "/meshes/0/primitives/0/attributes/TEXCOORD_0"
        );
        assert_eq!(path_to_pointer("asset"), "/asset");
        assert_eq!(path_to_pointer(""), "");
    }
}
