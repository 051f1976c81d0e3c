//! Buffer views over their buffers, and what uses them (the Khronos glTF-Validator's buffer
//! view link checks, with its codes and pointers); the data itself is not read here.
//!
//! - BUFFER_VIEW_TOO_LONG (error): a view past its buffer's byteLength (at `byteOffset` when
//!   the offset alone reaches the end, else at `byteLength`).
//! - BUFFER_VIEW_TOO_BIG_BYTE_STRIDE (error): a byteStride greater than the view's byteLength.
//! - BUFFER_VIEW_INVALID_BYTE_STRIDE (error): a byteStride on an index view (target 34963).
//! - BUFFER_VIEW_TARGET_OVERRIDE (error): a view used both for vertex attributes and for
//!   indices; its declared `target`, or else its first use, decides, and the use that
//!   contradicts it is reported, at the primitive's `indices` or attribute.
//! - BUFFER_VIEW_TARGET_MISSING (hint): a view holding vertex attributes or indices that
//!   declares no `target`, at its first use (the reference's hint and pointer); its fix sets
//!   the target that use implies.
//! - ANIMATION_SAMPLER_ACCESSOR_WITH_BYTESTRIDE, MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE,
//!   SKIN_IBM_ACCESSOR_WITH_BYTESTRIDE, IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE (errors): data that
//!   must be tightly packed in a view with a byteStride, at the reference to it.

use super::{elements, Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const BUFFER_VIEW_TOO_LONG: Code = Code::new(
    "BUFFER_VIEW_TOO_LONG",
    Severity::Error,
    "A buffer view runs past the end of its buffer.",
);
pub const BUFFER_VIEW_TOO_BIG_BYTE_STRIDE: Code = Code::new(
    "BUFFER_VIEW_TOO_BIG_BYTE_STRIDE",
    Severity::Error,
    "A buffer view's byteStride is greater than its byteLength.",
);
pub const BUFFER_VIEW_TARGET_OVERRIDE: Code = Code::new(
    "BUFFER_VIEW_TARGET_OVERRIDE",
    Severity::Error,
    "A buffer view is used both for vertex attributes and for indices.",
);
pub const BUFFER_VIEW_TARGET_MISSING: Code = Code::new(
    "BUFFER_VIEW_TARGET_MISSING",
    Severity::Hint,
    "A buffer view holding vertex attributes or indices declares no target (34962 or 34963), which loaders use to place it.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const ANIMATION_SAMPLER_ACCESSOR_WITH_BYTESTRIDE: Code = Code::new(
    "ANIMATION_SAMPLER_ACCESSOR_WITH_BYTESTRIDE",
    Severity::Error,
    "An animation sampler's accessor lies in a buffer view with byteStride; its data must be tightly packed.",
);
pub const MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE: Code = Code::new(
    "MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE",
    Severity::Error,
    "A primitive's indices lie in a buffer view with byteStride; indices must be tightly packed.",
);
pub const SKIN_IBM_ACCESSOR_WITH_BYTESTRIDE: Code = Code::new(
    "SKIN_IBM_ACCESSOR_WITH_BYTESTRIDE",
    Severity::Error,
    "A skin's inverse bind matrices lie in a buffer view with byteStride; they must be tightly packed.",
);
pub const IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE: Code = Code::new(
    "IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE",
    Severity::Error,
    "An image's buffer view has a byteStride.",
);

const ARRAY_BUFFER: u64 = 34962;
const ELEMENT_ARRAY_BUFFER: u64 = 34963;

pub struct BufferViews;

impl Rule for BufferViews {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &BUFFER_VIEW_TOO_LONG,
            &BUFFER_VIEW_TOO_BIG_BYTE_STRIDE,
            &super::accessors::BUFFER_VIEW_INVALID_BYTE_STRIDE,
            &BUFFER_VIEW_TARGET_OVERRIDE,
            &BUFFER_VIEW_TARGET_MISSING,
            &ANIMATION_SAMPLER_ACCESSOR_WITH_BYTESTRIDE,
            &MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE,
            &SKIN_IBM_ACCESSOR_WITH_BYTESTRIDE,
            &IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let buffers = json.get("buffers");
        let views = json.get("bufferViews");
        for (i, view) in elements(views).enumerate() {
            let at = format!("/bufferViews/{i}");
            let offset = match view.get("byteOffset") {
                None => Some(0),
                Some(o) => o.as_u64(),
            };
            let length = view.get("byteLength").and_then(|l| l.as_u64());
            if let (Some(buffer), Some(offset), Some(length)) = (
                super::element_at(buffers, view.get("buffer")),
                offset,
                length,
            ) {
                if let Some(buffer_length) = buffer.get("byteLength").and_then(|l| l.as_u64()) {
                    if offset >= buffer_length && length > 0 {
                        out.push(Diagnostic::new(
                            &BUFFER_VIEW_TOO_LONG,
                            format!("{at}/byteOffset"),
                            format!("byteOffset {offset} is at or past the buffer's byteLength {buffer_length}"),
                        ));
                    } else if offset.saturating_add(length) > buffer_length {
                        out.push(Diagnostic::new(
                            &BUFFER_VIEW_TOO_LONG,
                            format!("{at}/byteLength"),
                            format!("{length} bytes at offset {offset} run past the buffer's byteLength {buffer_length}"),
                        ));
                    }
                }
            }
            let stride = view.get("byteStride").and_then(|s| s.as_u64());
            if let (Some(stride), Some(length)) = (stride, length) {
                if stride > length {
                    out.push(Diagnostic::new(
                        &BUFFER_VIEW_TOO_BIG_BYTE_STRIDE,
                        format!("{at}/byteStride"),
                        format!("byteStride {stride} is greater than byteLength {length}"),
                    ));
                }
            }
            if stride.is_some()
                && view.get("target").and_then(|t| t.as_u64()) == Some(ELEMENT_ARRAY_BUFFER)
            {
                out.push(Diagnostic::new(
                    &super::accessors::BUFFER_VIEW_INVALID_BYTE_STRIDE,
                    format!("{at}/byteStride"),
                    "an index buffer view (target 34963) must have no byteStride",
                ));
            }
        }
        self.uses(json, out);
    }
}

impl BufferViews {
    /// The checks on what refers to buffer views: strides where data must be packed, and
    /// views used both for vertices and for indices.
    fn uses(&self, json: Node, out: &mut Vec<Diagnostic>) {
        let accessors = json.get("accessors");
        let views = json.get("bufferViews");
        // Each accessor's view, read once: a library's meshes use a few accessors thousands
        // of times over.
        let accessor_views: Vec<Option<usize>> = elements(accessors)
            .map(|accessor| {
                let view = accessor.as_object()?.get("bufferView")?;
                super::element_at(views, Some(view))?;
                usize::try_from(view.as_u64()?).ok()
            })
            .collect();
        let view_index = |accessor: Option<Node>| -> Option<usize> {
            let index = usize::try_from(accessor?.as_u64()?).ok()?;
            *accessor_views.get(index)?
        };
        let strided = |view: usize| {
            views
                .and_then(|v| v.get(view))
                .is_some_and(|v| v.get("byteStride").is_some())
        };
        let count = views.and_then(|v| v.as_array()).map_or(0, |v| v.len());
        // Each view's use: its declared target, else the first use found.
        let mut usage: Vec<Option<u64>> = (0..count)
            .map(|i| {
                views
                    .and_then(|v| v.get(i))
                    .and_then(|v| v.get("target"))
                    .and_then(|t| t.as_u64())
                    .filter(|t| matches!(*t, ARRAY_BUFFER | ELEMENT_ARRAY_BUFFER))
            })
            .collect();
        let undeclared: Vec<bool> = (0..count)
            .map(|i| {
                views
                    .and_then(|v| v.get(i))
                    .is_some_and(|v| v.get("target").is_none())
            })
            .collect();
        // The pointer of a use is written only for a finding: a library has tens of thousands.
        let mut used = |view: usize,
                        target: u64,
                        at: &dyn Fn() -> String,
                        out: &mut Vec<Diagnostic>| match usage[view] {
            None => {
                usage[view] = Some(target);
                if undeclared[view] {
                    out.push(Diagnostic::new(
                        &BUFFER_VIEW_TARGET_MISSING,
                        at(),
                        format!(
                            "buffer view {view} holds {} and declares no target; set {target}",
                            target_name(target)
                        ),
                    ));
                }
            }
            Some(first) if first != target => out.push(Diagnostic::new(
                &BUFFER_VIEW_TARGET_OVERRIDE,
                at(),
                format!(
                    "buffer view {view} holds {}, and is used here for {}",
                    target_name(first),
                    target_name(target)
                ),
            )),
            Some(_) => {}
        };
        // The keys of every primitive, found in the key table once.
        let [primitives_key, attributes_key, indices_key, targets_key] =
            ["primitives", "attributes", "indices", "targets"].map(|key| json.key_id(key));
        for (m, mesh) in elements(json.get("meshes")).enumerate() {
            for (p, primitive) in elements(mesh.get_by(primitives_key)).enumerate() {
                let at = || format!("/meshes/{m}/primitives/{p}");
                for (name, accessor) in primitive
                    .get_by(attributes_key)
                    .and_then(|a| a.as_object())
                    .into_iter()
                    .flat_map(|a| a.iter())
                {
                    if let Some(view) = view_index(Some(accessor)) {
                        let pointer = || format!("{}/attributes/{}", at(), pointer::escape(&name));
                        used(view, ARRAY_BUFFER, &pointer, out);
                    }
                }
                if let Some(view) = view_index(primitive.get_by(indices_key)) {
                    let pointer = || format!("{}/indices", at());
                    if strided(view) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE,
                            pointer(),
                            "the indices' buffer view has a byteStride; indices must be tightly packed",
                        ));
                    }
                    used(view, ELEMENT_ARRAY_BUFFER, &pointer, out);
                }
                for (t, target) in elements(primitive.get_by(targets_key)).enumerate() {
                    for (name, accessor) in target.as_object().into_iter().flat_map(|a| a.iter()) {
                        if let Some(view) = view_index(Some(accessor)) {
                            let pointer =
                                || format!("{}/targets/{t}/{}", at(), pointer::escape(&name));
                            used(view, ARRAY_BUFFER, &pointer, out);
                        }
                    }
                }
            }
        }
        for (a, animation) in elements(json.get("animations")).enumerate() {
            for (s, sampler) in elements(animation.get("samplers")).enumerate() {
                for key in ["input", "output"] {
                    if view_index(sampler.get(key)).is_some_and(strided) {
                        out.push(Diagnostic::new(
                            &ANIMATION_SAMPLER_ACCESSOR_WITH_BYTESTRIDE,
                            format!("/animations/{a}/samplers/{s}/{key}"),
                            format!("the {key} accessor's buffer view has a byteStride; animation data must be tightly packed"),
                        ));
                    }
                }
            }
        }
        for (s, skin) in elements(json.get("skins")).enumerate() {
            if view_index(skin.get("inverseBindMatrices")).is_some_and(strided) {
                out.push(Diagnostic::new(
                    &SKIN_IBM_ACCESSOR_WITH_BYTESTRIDE,
                    format!("/skins/{s}/inverseBindMatrices"),
                    "the inverse bind matrices' buffer view has a byteStride; they must be tightly packed",
                ));
            }
        }
        for (i, image) in elements(json.get("images")).enumerate() {
            let Some(view) = image.get("bufferView") else {
                continue;
            };
            if super::element_at(views, Some(view)).is_some_and(|v| v.get("byteStride").is_some()) {
                out.push(Diagnostic::new(
                    &IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE,
                    format!("/images/{i}/bufferView"),
                    "an image's buffer view must have no byteStride",
                ));
            }
        }
    }
}

fn target_name(target: u64) -> &'static str {
    if target == ELEMENT_ARRAY_BUFFER {
        "indices (ELEMENT_ARRAY_BUFFER)"
    } else {
        "vertex attributes (ARRAY_BUFFER)"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&BufferViews, text)
    }

    #[test]
    fn views_past_their_buffers_and_contradicting_uses_are_found() {
        let text = r#"{"asset":{"version":"2.0"},
            "buffers":[{"byteLength":64}],
            "bufferViews":[{"buffer":0,"byteLength":65},{"buffer":0,"byteOffset":64,"byteLength":4},
                {"buffer":0,"byteLength":8,"byteStride":12},{"buffer":0,"byteLength":8,"byteStride":4,"target":34963},
                {"buffer":0,"byteLength":64}],
            "accessors":[{"bufferView":4,"componentType":5126,"count":1,"type":"VEC3"},
                {"bufferView":4,"componentType":5123,"count":3,"type":"SCALAR"},
                {"bufferView":3,"componentType":5123,"count":1,"type":"SCALAR"}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1},
                                     {"attributes":{"POSITION":0},"indices":2}]}],
            "images":[{"bufferView":2,"mimeType":"image/png"}]}"#;
        assert_eq!(
            found(text),
            [
                "BUFFER_VIEW_TOO_LONG /bufferViews/0/byteLength",
                "BUFFER_VIEW_TOO_LONG /bufferViews/1/byteOffset",
                "BUFFER_VIEW_TOO_BIG_BYTE_STRIDE /bufferViews/2/byteStride",
                "BUFFER_VIEW_INVALID_BYTE_STRIDE /bufferViews/3/byteStride",
                // View 4 declares no target: its first use, POSITION, is noted, and decides.
                "BUFFER_VIEW_TARGET_MISSING /meshes/0/primitives/0/attributes/POSITION",
                "BUFFER_VIEW_TARGET_OVERRIDE /meshes/0/primitives/0/indices",
                "MESH_PRIMITIVE_INDICES_ACCESSOR_WITH_BYTESTRIDE /meshes/0/primitives/1/indices",
                "IMAGE_BUFFER_VIEW_WITH_BYTESTRIDE /images/0/bufferView",
            ]
        );
    }
}
