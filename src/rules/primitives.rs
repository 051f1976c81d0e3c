//! Mesh primitives and the accessors they draw from, as the JSON describes them (the Khronos
//! glTF-Validator's mesh link checks, with its codes and pointers; the spec's "Meshes" section).
//! The data itself is not read here.
//!
//! - MESH_PRIMITIVE_NO_POSITION (warning): no POSITION attribute; at `attributes`.
//! - MESH_PRIMITIVE_TANGENT_WITHOUT_NORMAL (warning): TANGENT without NORMAL; at TANGENT.
//! - MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH (error): unequal numbers of JOINTS_n and WEIGHTS_n.
//! - MESH_PRIMITIVE_INCOMPATIBLE_MODE (warning): a vertex (or index) count the primitive's mode
//!   cannot draw whole (4 vertices as triangles); at the primitive.
//! - MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT (error): attributes of unequal counts; at the later.
//! - MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT (error): a vertex attribute of unsigned ints.
//! - MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT (error): a glTF semantic whose accessor
//!   has a type or component type the spec does not allow it (not judged where
//!   KHR_mesh_quantization is declared, which allows more).
//! - MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS (error): a POSITION accessor (base or
//!   morph target) without min and max, which the spec requires.
//! - MESH_PRIMITIVE_ACCESSOR_UNALIGNED (error): a vertex attribute's byteOffset not a multiple
//!   of 4.
//! - MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE (error): a buffer view without byteStride that
//!   holds the vertex attributes of more than one accessor; at each use after the first.
//! - MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT (error): indices that are not unsigned
//!   byte, short or int scalars.
//! - MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT (error): a morph target accessor whose
//!   count differs from the primitive's vertex count.
//! - MESH_INVALID_WEIGHTS_COUNT (error): a mesh's `weights` not one per morph target.

use super::{elements, Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const MESH_PRIMITIVE_NO_POSITION: Code = Code::new(
    "MESH_PRIMITIVE_NO_POSITION",
    Severity::Warning,
    "A primitive has no POSITION attribute.",
);
pub const MESH_PRIMITIVE_TANGENT_WITHOUT_NORMAL: Code = Code::new(
    "MESH_PRIMITIVE_TANGENT_WITHOUT_NORMAL",
    Severity::Warning,
    "A primitive has TANGENT without NORMAL; the tangents are not used.",
);
pub const MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH: Code = Code::new(
    "MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH",
    Severity::Error,
    "A primitive has unequal numbers of JOINTS_n and WEIGHTS_n attributes.",
);
pub const MESH_PRIMITIVE_INCOMPATIBLE_MODE: Code = Code::new(
    "MESH_PRIMITIVE_INCOMPATIBLE_MODE",
    Severity::Warning,
    "A primitive's vertex or index count does not fit its mode (triangles in threes, lines in twos).",
);
pub const MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT: Code = Code::new(
    "MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT",
    Severity::Error,
    "A primitive's attributes have accessors of unequal counts.",
);
pub const MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT: Code = Code::new(
    "MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT",
    Severity::Error,
    "A vertex attribute's accessor holds unsigned ints, which vertex attributes cannot.",
);
pub const MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT: Code = Code::new(
    "MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT",
    Severity::Error,
    "A vertex attribute's accessor has a type or component type its semantic does not allow (POSITION: float VEC3).",
);
pub const MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS: Code = Code::new(
    "MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS",
    Severity::Error,
    "A POSITION accessor has no min and max, which the spec requires.",
);
pub const MESH_PRIMITIVE_ACCESSOR_UNALIGNED: Code = Code::new(
    "MESH_PRIMITIVE_ACCESSOR_UNALIGNED",
    Severity::Error,
    "A vertex attribute's accessor has a byteOffset that is not a multiple of 4.",
);
pub const MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE: Code = Code::new(
    "MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE",
    Severity::Error,
    "A buffer view that holds vertex attributes of several accessors has no byteStride.",
);
pub const MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT: Code = Code::new(
    "MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT",
    Severity::Error,
    "A primitive's indices are not unsigned byte, short or int scalars.",
);
pub const MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT: Code = Code::new(
    "MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT",
    Severity::Error,
    "A morph target's accessor has another count than the primitive's vertices.",
);
pub const MESH_INVALID_WEIGHTS_COUNT: Code = Code::new(
    "MESH_INVALID_WEIGHTS_COUNT",
    Severity::Error,
    "A mesh's weights are not one per morph target.",
);

/// What this rule reads of an accessor.
struct AccessorView<'a> {
    component_type: Option<u64>,
    kind: Option<std::borrow::Cow<'a, str>>,
    count: Option<u64>,
    normalized: bool,
    byte_offset: u64,
    buffer_view: Option<usize>,
    bounded: bool,
}

impl<'a> AccessorView<'a> {
    fn read(accessor: Node<'a>) -> AccessorView<'a> {
        AccessorView {
            component_type: accessor.get("componentType").and_then(|c| c.as_u64()),
            kind: accessor.get("type").and_then(|t| t.as_str()),
            count: accessor.get("count").and_then(|c| c.as_u64()),
            normalized: accessor.get("normalized").and_then(|n| n.as_bool()) == Some(true),
            byte_offset: accessor
                .get("byteOffset")
                .and_then(|o| o.as_u64())
                .unwrap_or(0),
            buffer_view: accessor
                .get("bufferView")
                .and_then(|v| v.as_u64())
                .and_then(|v| usize::try_from(v).ok()),
            bounded: accessor.get("min").is_some() && accessor.get("max").is_some(),
        }
    }

    /// Whether it holds `kind` elements of one of the (component type, normalized) formats.
    fn is(&self, kinds: &[&str], formats: &[(u64, bool)]) -> bool {
        let (Some(kind), Some(component)) = (&self.kind, self.component_type) else {
            return true;
        };
        kinds.contains(&kind.as_ref())
            && formats
                .iter()
                .any(|(c, n)| *c == component && (*n == self.normalized || *c == FLOAT))
    }
}

const BYTE_N: (u64, bool) = (5120, true);
const UBYTE: (u64, bool) = (5121, false);
const UBYTE_N: (u64, bool) = (5121, true);
const SHORT_N: (u64, bool) = (5122, true);
const USHORT: (u64, bool) = (5123, false);
const USHORT_N: (u64, bool) = (5123, true);
const FLOAT: u64 = 5126;
const FLOATS: (u64, bool) = (FLOAT, false);

/// Whether an attribute's accessor has a format its semantic allows (the spec's table of
/// attributes); application-specific semantics allow any.
fn format_allowed(semantic: &str, accessor: &AccessorView) -> bool {
    let base = semantic.split('_').next().unwrap_or(semantic);
    match (semantic, base) {
        ("POSITION" | "NORMAL", _) => accessor.is(&["VEC3"], &[FLOATS]),
        ("TANGENT", _) => accessor.is(&["VEC4"], &[FLOATS]),
        (_, "TEXCOORD") => accessor.is(&["VEC2"], &[FLOATS, UBYTE_N, USHORT_N]),
        (_, "COLOR") => accessor.is(&["VEC3", "VEC4"], &[FLOATS, UBYTE_N, USHORT_N]),
        (_, "JOINTS") => accessor.is(&["VEC4"], &[UBYTE, USHORT]),
        (_, "WEIGHTS") => accessor.is(&["VEC4"], &[FLOATS, UBYTE_N, USHORT_N]),
        _ => {
            let _ = (BYTE_N, SHORT_N);
            true
        }
    }
}

/// Whether `count` vertices (or indices) can be drawn whole in `mode`.
fn fits_mode(mode: u64, count: u64) -> bool {
    match mode {
        0 => count >= 1,
        1 => count >= 2 && count.is_multiple_of(2),
        2 | 3 => count >= 2,
        4 => count >= 3 && count.is_multiple_of(3),
        5 | 6 => count >= 3,
        _ => true,
    }
}

pub struct Primitives;

impl Rule for Primitives {
    fn reads(&self) -> super::Reads {
        super::Reads::Properties {
            properties: &["meshes", "accessors", "bufferViews", "extensionsUsed"],
            except: &[("bufferViews", "target")],
        }
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &MESH_PRIMITIVE_NO_POSITION,
            &MESH_PRIMITIVE_TANGENT_WITHOUT_NORMAL,
            &MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH,
            &MESH_PRIMITIVE_INCOMPATIBLE_MODE,
            &MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT,
            &MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT,
            &MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT,
            &MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS,
            &MESH_PRIMITIVE_ACCESSOR_UNALIGNED,
            &MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE,
            &MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT,
            &MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT,
            &MESH_INVALID_WEIGHTS_COUNT,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let Some(meshes) = json.get("meshes") else {
            return;
        };
        let accessors: Vec<Option<AccessorView>> = elements(json.get("accessors"))
            .map(|a| a.is_object().then(|| AccessorView::read(a)))
            .collect();
        let accessor = |index: Node| -> Option<(usize, &AccessorView)> {
            let i = usize::try_from(index.as_u64()?).ok()?;
            Some((i, accessors.get(i)?.as_ref()?))
        };
        let strided: Vec<bool> = elements(json.get("bufferViews"))
            .map(|v| v.get("byteStride").is_some())
            .collect();
        let quantized = super::declares(json, "KHR_mesh_quantization");
        // The first accessor found holding vertex attributes in each buffer view.
        let mut first_in_view: Vec<Option<usize>> = vec![None; strided.len()];
        // Pointers are written only for findings: a library has tens of thousands of attributes.
        let mut vertex_attribute = |at: &dyn Fn() -> String,
                                    index: usize,
                                    view: &AccessorView,
                                    out: &mut Vec<Diagnostic>| {
            if view.component_type == Some(5125) {
                out.push(Diagnostic::new(
                    &MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT,
                    at(),
                    "a vertex attribute cannot hold unsigned ints",
                ));
            }
            let Some(bv) = view.buffer_view.filter(|v| *v < strided.len()) else {
                return;
            };
            if !view.byte_offset.is_multiple_of(4) {
                out.push(Diagnostic::new(
                    &MESH_PRIMITIVE_ACCESSOR_UNALIGNED,
                    at(),
                    format!(
                        "the accessor's byteOffset {} is not a multiple of 4",
                        view.byte_offset
                    ),
                ));
            }
            match first_in_view[bv] {
                    None => first_in_view[bv] = Some(index),
                    Some(first) if first != index && !strided[bv] => out.push(Diagnostic::new(
                        &MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE,
                        at(),
                        format!("buffer view {bv} holds the vertex attributes of accessors {first} and {index} but has no byteStride"),
                    )),
                    Some(_) => {}
                }
        };
        // The keys of every primitive, found in the key table once.
        let [primitives_key, attributes_key, targets_key, indices_key, mode_key] =
            ["primitives", "attributes", "targets", "indices", "mode"].map(|key| json.key_id(key));
        let [position, tangent, normal] =
            ["POSITION", "TANGENT", "NORMAL"].map(|key| json.key_id(key));
        for (m, mesh) in elements(Some(meshes)).enumerate() {
            let mut targets_count = None;
            for (p, primitive) in elements(mesh.get_by(primitives_key)).enumerate() {
                let at = || format!("/meshes/{m}/primitives/{p}");
                let Some(attributes) = primitive.get_by(attributes_key).and_then(|a| a.as_object())
                else {
                    continue;
                };
                if attributes.is_empty() {
                    continue;
                }
                if targets_count.is_none() {
                    targets_count = primitive
                        .get_by(targets_key)
                        .and_then(|t| t.as_array())
                        .map(|t| t.len());
                }
                if !attributes.contains_id(position) {
                    out.push(Diagnostic::new(
                        &MESH_PRIMITIVE_NO_POSITION,
                        format!("{}/attributes", at()),
                        "the primitive has no POSITION attribute",
                    ));
                }
                if attributes.contains_id(tangent) && !attributes.contains_id(normal) {
                    out.push(Diagnostic::new(
                        &MESH_PRIMITIVE_TANGENT_WITHOUT_NORMAL,
                        format!("{}/attributes/TANGENT", at()),
                        "TANGENT without NORMAL: the tangents are not used",
                    ));
                }
                let sets =
                    |prefix: &str| attributes.keys().filter(|k| k.starts_with(prefix)).count();
                let (joints, weights) = (sets("JOINTS_"), sets("WEIGHTS_"));
                if joints != weights {
                    out.push(Diagnostic::new(
                        &MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH,
                        format!("{}/attributes", at()),
                        format!("{joints} JOINTS_n and {weights} WEIGHTS_n attributes; they come in pairs"),
                    ));
                }
                let mut vertices: Option<u64> = None;
                for (name, index) in attributes.iter() {
                    let Some((i, view)) = accessor(index) else {
                        continue;
                    };
                    let attribute_at = || format!("{}/attributes/{}", at(), pointer::escape(&name));
                    if let Some(count) = view.count {
                        match vertices {
                            None => vertices = Some(count),
                            Some(first) if first != count => out.push(Diagnostic::new(
                                &MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT,
                                attribute_at(),
                                format!("the accessor holds {count} elements, the primitive's first attribute {first}"),
                            )),
                            Some(_) => {}
                        }
                    }
                    if !quantized
                        && view.component_type != Some(5125)
                        && !format_allowed(&name, view)
                    {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT,
                            attribute_at(),
                            format!(
                                "{name} cannot be held as {} of component type {}",
                                view.kind.as_deref().unwrap_or("?"),
                                view.component_type.unwrap_or(0)
                            ),
                        ));
                    }
                    if name == "POSITION" && !view.bounded {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS,
                            attribute_at(),
                            "a POSITION accessor must have min and max",
                        ));
                    }
                    vertex_attribute(&attribute_at, i, view, out);
                }
                let mut drawn = vertices;
                if let Some(indices) = primitive.get_by(indices_key) {
                    if let Some((_, view)) = accessor(indices) {
                        let scalar_uint = view.kind.as_deref().is_none_or(|k| k == "SCALAR")
                            && view
                                .component_type
                                .is_none_or(|c| matches!(c, 5121 | 5123 | 5125))
                            && !view.normalized;
                        if !scalar_uint {
                            out.push(Diagnostic::new(
                                &MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT,
                                format!("{}/indices", at()),
                                "indices must be unsigned byte, short or int scalars",
                            ));
                        }
                        drawn = view.count;
                    } else {
                        drawn = None;
                    }
                }
                let mode = primitive.get_by(mode_key).map_or(Some(4), |m| m.as_u64());
                if let (Some(mode), Some(count)) = (mode, drawn) {
                    if !fits_mode(mode, count) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_INCOMPATIBLE_MODE,
                            at(),
                            format!(
                                "{count} vertices or indices cannot be drawn whole in mode {mode}"
                            ),
                        ));
                    }
                }
                for (t, target) in elements(primitive.get_by(targets_key)).enumerate() {
                    for (name, index) in target.as_object().into_iter().flat_map(|o| o.iter()) {
                        let Some((i, view)) = accessor(index) else {
                            continue;
                        };
                        let target_at =
                            || format!("{}/targets/{t}/{}", at(), pointer::escape(&name));
                        if let (Some(count), Some(vertices)) = (view.count, vertices) {
                            if count != vertices {
                                out.push(Diagnostic::new(
                                    &MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT,
                                    target_at(),
                                    format!("the morph target's accessor holds {count} elements; the primitive has {vertices} vertices"),
                                ));
                            }
                        }
                        if name == "POSITION" && !view.bounded {
                            out.push(Diagnostic::new(
                                &MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS,
                                target_at(),
                                "a POSITION accessor must have min and max",
                            ));
                        }
                        vertex_attribute(&target_at, i, view, out);
                    }
                }
            }
            if let Some(weights) = mesh.get("weights").and_then(|w| w.as_array()) {
                let targets = targets_count.unwrap_or(0);
                if weights.len() != targets {
                    out.push(Diagnostic::new(
                        &MESH_INVALID_WEIGHTS_COUNT,
                        format!("/meshes/{m}/weights"),
                        format!("{} weights for {targets} morph targets", weights.len()),
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Primitives, text)
    }

    const ACCESSORS: &str = r#""bufferViews":[{"buffer":0,"byteLength":96}],
        "accessors":[
          {"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},
          {"componentType":5126,"count":4,"type":"VEC3"},
          {"componentType":5126,"count":3,"type":"VEC4"},
          {"componentType":5125,"count":3,"type":"SCALAR"},
          {"componentType":5126,"count":3,"type":"SCALAR"},
          {"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,1]},
          {"bufferView":0,"byteOffset":2,"componentType":5121,"count":3,"type":"VEC4","normalized":true}]"#;

    #[test]
    fn primitives_whose_attributes_do_not_fit_are_found_at_the_reference_validators_pointers() {
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},{ACCESSORS},"meshes":[
            {{"primitives":[{{"attributes":{{"NORMAL":0,"TANGENT":2,"JOINTS_0":2}}}}]}},
            {{"primitives":[{{"attributes":{{"POSITION":1,"_X":3}},"indices":4,"targets":[{{"POSITION":0}}]}}],"weights":[1,2]}},
            {{"primitives":[{{"attributes":{{"POSITION":5,"COLOR_0":6}},"mode":1}}]}}]}}"#
        );
        assert_eq!(
            found(&text),
            [
                "MESH_PRIMITIVE_NO_POSITION /meshes/0/primitives/0/attributes",
                "MESH_PRIMITIVE_JOINTS_WEIGHTS_MISMATCH /meshes/0/primitives/0/attributes",
                "MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_INVALID_FORMAT /meshes/0/primitives/0/attributes/JOINTS_0",
                "MESH_PRIMITIVE_POSITION_ACCESSOR_WITHOUT_BOUNDS /meshes/1/primitives/0/attributes/POSITION",
                "MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT /meshes/1/primitives/0/attributes/_X",
                "MESH_PRIMITIVE_ATTRIBUTES_ACCESSOR_UNSIGNED_INT /meshes/1/primitives/0/attributes/_X",
                "MESH_PRIMITIVE_INDICES_ACCESSOR_INVALID_FORMAT /meshes/1/primitives/0/indices",
                "MESH_PRIMITIVE_MORPH_TARGET_INVALID_ATTRIBUTE_COUNT /meshes/1/primitives/0/targets/0/POSITION",
                "MESH_INVALID_WEIGHTS_COUNT /meshes/1/weights",
                "MESH_PRIMITIVE_ACCESSOR_UNALIGNED /meshes/2/primitives/0/attributes/COLOR_0",
                "MESH_PRIMITIVE_ACCESSOR_WITHOUT_BYTESTRIDE /meshes/2/primitives/0/attributes/COLOR_0",
                "MESH_PRIMITIVE_INCOMPATIBLE_MODE /meshes/2/primitives/0",
            ]
        );
    }

    #[test]
    fn modes_take_their_vertices_in_their_own_groups() {
        assert!(fits_mode(4, 3) && fits_mode(4, 6) && !fits_mode(4, 4) && !fits_mode(4, 0));
        assert!(fits_mode(1, 2) && !fits_mode(1, 3));
        assert!(fits_mode(5, 3) && !fits_mode(6, 2) && fits_mode(0, 1));
    }
}
