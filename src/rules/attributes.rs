//! Attribute semantics: the spec names the semantics a primitive may use (POSITION, NORMAL,
//! TANGENT, TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n) and says that application-specific ones
//! MUST start with an underscore. Any other name is an error: loaders do not know what to bind
//! it to.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const MESH_PRIMITIVE_INVALID_ATTRIBUTE: Code = Code::new(
    "MESH_PRIMITIVE_INVALID_ATTRIBUTE",
    Severity::Error,
    "A primitive attribute whose name is neither a glTF semantic nor application-specific (starting with '_').",
);

/// True for the names glTF 2.0 allows as attribute semantics.
pub fn is_valid_semantic(name: &str) -> bool {
    if name.starts_with('_') || matches!(name, "POSITION" | "NORMAL" | "TANGENT") {
        return true;
    }
    ["TEXCOORD_", "COLOR_", "JOINTS_", "WEIGHTS_"]
        .iter()
        .filter_map(|prefix| name.strip_prefix(prefix))
        .any(|set| {
            !set.is_empty()
                && set.bytes().all(|b| b.is_ascii_digit())
                && (set == "0" || !set.starts_with('0'))
        })
}

pub struct Attributes;

impl Rule for Attributes {
    fn codes(&self) -> &'static [&'static Code] {
        &[&MESH_PRIMITIVE_INVALID_ATTRIBUTE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let meshes = cx.json().get("meshes").and_then(|m| m.as_array());
        for (m, mesh) in meshes.iter().flat_map(|a| a.iter()).enumerate() {
            let primitives = mesh.get("primitives").and_then(|p| p.as_array());
            for (p, primitive) in primitives.iter().flat_map(|a| a.iter()).enumerate() {
                let attributes = primitive.get("attributes").and_then(|a| a.as_object());
                for name in attributes.into_iter().flat_map(|a| a.keys()) {
                    if !is_valid_semantic(&name) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_INVALID_ATTRIBUTE,
                            format!(
                                "/meshes/{m}/primitives/{p}/attributes/{}",
                                pointer::escape(&name)
                            ),
                            format!(
                                "'{name}' is not a glTF attribute semantic; application-specific ones start with '_'"
                            ),
                        ));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn semantics_follow_the_spec_names() {
        for ok in [
            "POSITION",
            "NORMAL",
            "TANGENT",
            "TEXCOORD_0",
            "TEXCOORD_12",
            "COLOR_1",
            "JOINTS_0",
            "WEIGHTS_3",
            "_BATCHID",
            "_",
        ] {
            assert!(is_valid_semantic(ok), "{ok}");
        }
        for bad in [
            "position",
            "TEXCOORD",
            "TEXCOORD_",
            "TEXCOORD_01",
            "TEXCOORD_a",
            "COLOR_-1",
            "BATCHID",
            "",
        ] {
            assert!(!is_valid_semantic(bad), "{bad}");
        }
    }
}
