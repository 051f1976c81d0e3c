//! What each accessor is used for, as the Khronos glTF-Validator links a document, with its
//! code and pointer:
//!
//! - ACCESSOR_USAGE_OVERRIDE (error): an accessor used for two kinds of data (a primitive's
//!   vertex attribute and its indices, an animation's input and output, inverse bind matrices),
//!   at each use after the first that differs from the first.
//!
//! The uses are taken in the reference's order: meshes (each primitive's attributes, then its
//! indices, then its morph targets), skins' inverse bind matrices, then animation samplers
//! (input, then output). An index that names no accessor is UNRESOLVED_REFERENCE's finding.

use super::data::index_of;
use super::{elements, Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{KeyId, Node};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_USAGE_OVERRIDE: Code = Code::new(
    "ACCESSOR_USAGE_OVERRIDE",
    Severity::Error,
    "An accessor is used for two kinds of data (vertex attributes and indices, an animation's input and output, …).",
);

pub struct AccessorUsage;

/// A kind of data an accessor holds.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Usage {
    VertexAttribute,
    PrimitiveIndices,
    InverseBindMatrices,
    AnimationInput,
    AnimationOutput,
}

impl Usage {
    fn words(self) -> &'static str {
        match self {
            Usage::VertexAttribute => "a vertex attribute",
            Usage::PrimitiveIndices => "a primitive's indices",
            Usage::InverseBindMatrices => "a skin's inverse bind matrices",
            Usage::AnimationInput => "an animation's input (keyframe times)",
            Usage::AnimationOutput => "an animation's output (keyframe values)",
        }
    }
}

/// Each accessor's first use (its kind and where), and the findings of uses that differ.
struct Uses {
    first: Vec<Option<(Usage, String)>>,
    out: Vec<Diagnostic>,
}

impl Uses {
    /// Records a use of `accessor` as `usage` at the place `at` makes: a place is written
    /// only for a first use or a finding (a library's primitives are tens of thousands of uses
    /// of a few accessors).
    fn set(&mut self, accessor: Option<usize>, usage: Usage, at: impl FnOnce() -> String) {
        let Some(index) = accessor else {
            return;
        };
        let Some(slot) = self.first.get_mut(index) else {
            return;
        };
        match slot {
            None => *slot = Some((usage, at())),
            Some((initial, first_at)) if *initial != usage => {
                let message = format!(
                    "accessor {index} is used here as {}, and first as {} (at {first_at})",
                    usage.words(),
                    initial.words()
                );
                self.out
                    .push(Diagnostic::new(&ACCESSOR_USAGE_OVERRIDE, at(), message));
            }
            Some(_) => {}
        }
    }
}

impl Rule for AccessorUsage {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["accessors", "meshes", "skins", "animations"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&ACCESSOR_USAGE_OVERRIDE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let mut uses = Uses {
            first: vec![None; super::data::accessor_count(cx)],
            out: Vec::new(),
        };
        if uses.first.is_empty() {
            return;
        }
        // Keys numbered once: a lookup by number compares numbers.
        let (attributes_key, indices_key, targets_key) = (
            json.key_id("attributes"),
            json.key_id("indices"),
            json.key_id("targets"),
        );
        for (m, mesh) in elements(json.get("meshes")).enumerate() {
            for (p, primitive) in elements(mesh.get("primitives")).enumerate() {
                let at = || format!("/meshes/{m}/primitives/{p}");
                let attributes =
                    |uses: &mut Uses, holder: Option<Node>, within: &dyn Fn() -> String| {
                        for (name, accessor) in holder
                            .and_then(|a| a.as_object())
                            .into_iter()
                            .flat_map(|a| a.iter())
                        {
                            uses.set(index_of(Some(accessor)), Usage::VertexAttribute, || {
                                format!("{}/{}", within(), pointer::escape(&name))
                            });
                        }
                    };
                attributes(&mut uses, member(primitive, attributes_key), &|| {
                    format!("{}/attributes", at())
                });
                uses.set(
                    index_of(member(primitive, indices_key)),
                    Usage::PrimitiveIndices,
                    || format!("{}/indices", at()),
                );
                for (t, target) in elements(member(primitive, targets_key)).enumerate() {
                    attributes(&mut uses, Some(target), &|| format!("{}/targets/{t}", at()));
                }
            }
        }
        for (s, skin) in elements(json.get("skins")).enumerate() {
            uses.set(
                index_of(skin.get("inverseBindMatrices")),
                Usage::InverseBindMatrices,
                || format!("/skins/{s}/inverseBindMatrices"),
            );
        }
        for (a, animation) in elements(json.get("animations")).enumerate() {
            for (s, sampler) in elements(animation.get("samplers")).enumerate() {
                let at = || format!("/animations/{a}/samplers/{s}");
                uses.set(
                    index_of(sampler.get("input")),
                    Usage::AnimationInput,
                    || format!("{}/input", at()),
                );
                uses.set(
                    index_of(sampler.get("output")),
                    Usage::AnimationOutput,
                    || format!("{}/output", at()),
                );
            }
        }
        out.append(&mut uses.out);
    }
}

/// `holder`'s member numbered `key`, when `holder` is an object.
fn member(holder: Node<'_>, key: Option<KeyId>) -> Option<Node<'_>> {
    holder.as_object()?.get_id(key?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(rest: &str) -> Vec<String> {
        let accessor = r#"{"componentType":5126,"count":1,"type":"SCALAR"}"#;
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"accessors":[{accessor},{accessor},{accessor},{accessor},{accessor}],{rest}}}"#
        );
        crate::rules::findings_of(&AccessorUsage, &text)
    }

    #[test]
    fn an_accessor_used_for_two_kinds_of_data_is_found_at_each_later_use_of_another_kind() {
        assert_eq!(
            found(
                r#""meshes":[{"primitives":[
                    {"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":0,"targets":[{"POSITION":1}]},
                    {"attributes":{"POSITION":0},"indices":2}]}],
                "skins":[{"joints":[0],"inverseBindMatrices":2}],
                "animations":[{"samplers":[{"input":3,"output":3},{"input":3,"output":9}],
                    "channels":[]}]"#
            ),
            [
                "ACCESSOR_USAGE_OVERRIDE /meshes/0/primitives/0/indices",
                "ACCESSOR_USAGE_OVERRIDE /skins/0/inverseBindMatrices",
                "ACCESSOR_USAGE_OVERRIDE /animations/0/samplers/0/output",
            ]
        );
    }

    #[test]
    fn an_accessor_shared_by_uses_of_one_kind_is_not_found() {
        assert!(found(
            r#""meshes":[{"primitives":[
                {"attributes":{"POSITION":0,"NORMAL":0},"indices":1,"targets":[{"POSITION":2}]},
                {"attributes":{"POSITION":0,"POSITION_X":2},"indices":1}]}],
            "animations":[{"samplers":[{"input":3,"output":4},{"input":3,"output":4}],"channels":[]}]"#
        )
        .is_empty());
    }
}
