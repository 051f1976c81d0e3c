//! Attribute semantics: the spec names the semantics a primitive may use (POSITION, NORMAL,
//! TANGENT, TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n) and says that application-specific ones
//! MUST start with an underscore. Any other name is an error: loaders do not know what to bind
//! it to. The same holds for a morph target's attributes, each of which displaces the base
//! attribute of its name (MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR where there is none), and
//! every primitive of a mesh has as many morph targets as the first
//! (MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT), and the sets of an indexed semantic are numbered
//! from 0 without gaps (MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY), as the Khronos
//! glTF-Validator checks.

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

pub const MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR: Code = Code::new(
    "MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR",
    Severity::Error,
    "A morph target displaces an attribute that its primitive does not define.",
);
pub const MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT: Code = Code::new(
    "MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT",
    Severity::Error,
    "The primitives of one mesh have different numbers of morph targets.",
);

pub const MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY: Code = Code::new(
    "MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY",
    Severity::Error,
    "A primitive's TEXCOORD_n, COLOR_n, JOINTS_n or WEIGHTS_n sets are not numbered from 0 without gaps.",
);

/// For a family of indexed semantics, the (highest set + 1, sets given) when the valid sets
/// of `names` are not 0, 1, …, n−1.
fn discontinuous<N: AsRef<str>>(family: &str, names: &[N]) -> Option<(usize, usize)> {
    let mut sets: Vec<usize> = names
        .iter()
        .map(AsRef::as_ref)
        .filter(|n| is_valid_semantic(n))
        .filter_map(|n| n.strip_prefix(family)?.strip_prefix('_')?.parse().ok())
        .collect();
    sets.sort_unstable();
    sets.dedup();
    let expected = sets.last().map_or(0, |last| last + 1);
    (expected != sets.len()).then_some((expected, sets.len()))
}

fn invalid(at: &str, name: &str, out: &mut Vec<Diagnostic>) {
    out.push(Diagnostic::new(
        &MESH_PRIMITIVE_INVALID_ATTRIBUTE,
        format!("{at}/{}", pointer::escape(name)),
        format!(
            "'{name}' is not a glTF attribute semantic; application-specific ones start with '_'"
        ),
    ));
}

pub struct Attributes;

impl Rule for Attributes {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["meshes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &MESH_PRIMITIVE_INVALID_ATTRIBUTE,
            &MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR,
            &MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT,
            &MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let meshes = cx.json().get("meshes").and_then(|m| m.as_array());
        for (m, mesh) in meshes.iter().flat_map(|a| a.iter()).enumerate() {
            let primitives = mesh.get("primitives").and_then(|p| p.as_array());
            let mut first_count = None;
            for (p, primitive) in primitives.iter().flat_map(|a| a.iter()).enumerate() {
                let attributes = primitive.get("attributes").and_then(|a| a.as_object());
                // Written only for a finding: most primitives have none.
                let at = || format!("/meshes/{m}/primitives/{p}");
                let base: Vec<_> = attributes.iter().flat_map(|a| a.keys()).collect();
                for name in &base {
                    if !is_valid_semantic(name) {
                        invalid(&format!("{}/attributes", at()), name, out);
                    }
                }
                for family in ["COLOR", "JOINTS", "TEXCOORD", "WEIGHTS"] {
                    if let Some((expected, provided)) = discontinuous(family, &base) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_INDEXED_SEMANTIC_CONTINUITY,
                            format!("{}/attributes", at()),
                            format!("the {family}_n sets must be numbered from 0 without gaps: {family}_0 to {family}_{} make {expected} sets, {provided} given", expected - 1),
                        ));
                    }
                }
                // A morph target's attributes displace the base attributes of the same name.
                let targets = primitive.get("targets").and_then(|t| t.as_array());
                for (t, target) in targets.iter().flat_map(|a| a.iter()).enumerate() {
                    for name in target.as_object().into_iter().flat_map(|o| o.keys()) {
                        let target_at = format!("{}/targets/{t}", at());
                        if !is_valid_semantic(&name) {
                            invalid(&target_at, &name, out);
                        }
                        if !base.contains(&name) {
                            out.push(Diagnostic::new(
                                &MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR,
                                format!("{target_at}/{}", pointer::escape(&name)),
                                format!("the morph target displaces '{name}', which the primitive's attributes do not define"),
                            ));
                        }
                    }
                }
                // Targets that are not a list of morph targets are the schema's findings, and
                // such a primitive is not compared (as the Khronos validator does).
                let Some(count) = (match targets {
                    None => Some(0),
                    Some(list) => (!list.is_empty()
                        && list
                            .iter()
                            .all(|t| t.as_object().is_some_and(|o| !o.is_empty())))
                    .then(|| list.len()),
                }) else {
                    continue;
                };
                match first_count {
                    None => first_count = Some(count),
                    Some(first) if first != count => out.push(Diagnostic::new(
                        &MESH_PRIMITIVES_UNEQUAL_TARGETS_COUNT,
                        if primitive.get("targets").is_some() {
                            format!("{}/targets", at())
                        } else {
                            at()
                        },
                        format!("the primitive has {count} morph targets, the mesh's first primitive {first}"),
                    )),
                    Some(_) => {}
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indexed_sets_count_from_zero_without_gaps() {
        assert_eq!(
            discontinuous("TEXCOORD", &["TEXCOORD_0", "TEXCOORD_1"]),
            None
        );
        assert_eq!(
            discontinuous("TEXCOORD", &["TEXCOORD_1", "TEXCOORD_00"]),
            Some((2, 1))
        );
        assert_eq!(
            discontinuous("COLOR", &["COLOR_0", "COLOR_2", "TEXCOORD_5"]),
            Some((3, 2))
        );
        assert_eq!(discontinuous("JOINTS", &["POSITION"]), None);
    }

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
