//! Mesh data, read from the accessors a primitive draws (the spec's "Meshes" and "Skins"),
//! with the Khronos glTF-Validator's codes and pointers, each at the attribute or `indices`:
//!
//! - ACCESSOR_INDEX_OOB (error): an index past the primitive's vertices.
//! - ACCESSOR_INDEX_PRIMITIVE_RESTART (error): an index equal to its type's largest value, which
//!   some APIs take as a primitive restart.
//! - ACCESSOR_INDEX_TRIANGLE_DEGENERATE (information): triangles that name a vertex twice, counted
//!   once a primitive.
//! - ACCESSOR_VECTOR3_NON_UNIT (error): a NORMAL, or a TANGENT's xyz, not of unit length.
//! - ACCESSOR_INVALID_SIGN (error): a TANGENT's w other than 1 or -1.
//! - ACCESSOR_NON_CLAMPED (error): a float COLOR_n component outside 0..1.
//! - ACCESSOR_WEIGHTS_NEGATIVE (error), ACCESSOR_WEIGHTS_NON_NORMALIZED (error): a negative
//!   weight; a vertex whose weights, over every WEIGHTS_n, do not sum to 1.
//! - ACCESSOR_JOINTS_INDEX_OOB (error): a weighted joint past the joints of a skin that draws
//!   the mesh; ACCESSOR_JOINTS_INDEX_DUPLICATE (error): a joint weighted twice for one vertex;
//!   ACCESSOR_JOINTS_USED_ZERO_WEIGHT (warning): a non-zero joint with zero weight.
//!
//! Tolerances are the reference's (see `rules/data.rs`). Each kind is reported at most
//! [`MAX_REPORTED`] times an accessor use.

use super::accessor_bounds::MAX_REPORTED;
use super::data::{index_of, Elements, UNIT_LENGTH_VEC3, UNIT_SUM_STEP};
use super::{elements, Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::KeyId;
use crate::diagnostics::{Code, Diagnostic, Severity};
use std::collections::HashMap;

pub const ACCESSOR_INDEX_OOB: Code = Code::new(
    "ACCESSOR_INDEX_OOB",
    Severity::Error,
    "A primitive's index names a vertex the primitive does not have.",
);
pub const ACCESSOR_INDEX_PRIMITIVE_RESTART: Code = Code::new(
    "ACCESSOR_INDEX_PRIMITIVE_RESTART",
    Severity::Error,
    "A primitive's index is its type's largest value, which some graphics APIs read as a primitive restart.",
);
pub const ACCESSOR_INDEX_TRIANGLE_DEGENERATE: Code = Code::new(
    "ACCESSOR_INDEX_TRIANGLE_DEGENERATE",
    Severity::Info,
    "A primitive's triangles name a vertex twice: they are drawn as nothing.",
);
pub const ACCESSOR_VECTOR3_NON_UNIT: Code = Code::new(
    "ACCESSOR_VECTOR3_NON_UNIT",
    Severity::Error,
    "A normal, or a tangent's xyz, is not of unit length.",
);
pub const ACCESSOR_INVALID_SIGN: Code = Code::new(
    "ACCESSOR_INVALID_SIGN",
    Severity::Error,
    "A tangent's w is neither 1 nor -1.",
);
pub const ACCESSOR_NON_CLAMPED: Code = Code::new(
    "ACCESSOR_NON_CLAMPED",
    Severity::Error,
    "A vertex colour component lies outside 0..1.",
);
pub const ACCESSOR_WEIGHTS_NEGATIVE: Code = Code::new(
    "ACCESSOR_WEIGHTS_NEGATIVE",
    Severity::Error,
    "A joint weight is negative.",
);
pub const ACCESSOR_WEIGHTS_NON_NORMALIZED: Code = Code::new(
    "ACCESSOR_WEIGHTS_NON_NORMALIZED",
    Severity::Error,
    "A vertex's joint weights do not sum to 1.",
);
pub const ACCESSOR_JOINTS_INDEX_OOB: Code = Code::new(
    "ACCESSOR_JOINTS_INDEX_OOB",
    Severity::Error,
    "A weighted joint index is past the joints of a skin that draws the mesh.",
);
pub const ACCESSOR_JOINTS_INDEX_DUPLICATE: Code = Code::new(
    "ACCESSOR_JOINTS_INDEX_DUPLICATE",
    Severity::Error,
    "A vertex weights one joint twice.",
);
pub const ACCESSOR_JOINTS_USED_ZERO_WEIGHT: Code = Code::new(
    "ACCESSOR_JOINTS_USED_ZERO_WEIGHT",
    Severity::Warning,
    "A vertex names a non-zero joint with zero weight.",
);

pub struct VertexData;

/// Findings of one kind at one place, counted so that each stops at [`MAX_REPORTED`]; the
/// places are one primitive's.
struct Capped<'o> {
    out: &'o mut Vec<Diagnostic>,
    counts: Vec<(&'static str, String, usize)>,
}

impl Capped<'_> {
    fn push(&mut self, code: &'static Code, at: &str, message: impl FnOnce() -> String) {
        let slot = match self
            .counts
            .iter()
            .position(|(c, a, _)| *c == code.name && a == at)
        {
            Some(slot) => slot,
            None => {
                self.counts.push((code.name, at.to_string(), 0));
                self.counts.len() - 1
            }
        };
        if self.counts[slot].2 < MAX_REPORTED {
            self.counts[slot].2 += 1;
            self.out.push(Diagnostic::new(code, at, message()));
        }
    }
}

impl Rule for VertexData {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ACCESSOR_INDEX_OOB,
            &ACCESSOR_INDEX_PRIMITIVE_RESTART,
            &ACCESSOR_INDEX_TRIANGLE_DEGENERATE,
            &ACCESSOR_VECTOR3_NON_UNIT,
            &ACCESSOR_INVALID_SIGN,
            &ACCESSOR_NON_CLAMPED,
            &ACCESSOR_WEIGHTS_NEGATIVE,
            &ACCESSOR_WEIGHTS_NON_NORMALIZED,
            &ACCESSOR_JOINTS_INDEX_OOB,
            &ACCESSOR_JOINTS_INDEX_DUPLICATE,
            &ACCESSOR_JOINTS_USED_ZERO_WEIGHT,
        ]
    }

    /// It reads every primitive's data.
    fn cost(&self) -> u32 {
        3
    }

    fn reads(&self) -> super::Reads {
        super::data::DATA_READS
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        use rayon::prelude::*;
        if !cx.reads_data() {
            return;
        }
        let json = cx.json();
        let Some(meshes) = json.get("meshes") else {
            return;
        };
        let joint_limits = joint_limits(cx);
        // Which accessors each primitive judges is settled first, in document order: an
        // accessor's values are judged once for each kind of use, at its first use, as the
        // Khronos validator does (a colour accessor shared by COLOR_0 and COLOR_1 is one
        // finding). The primitives are then read side by side (a document's weight is often in
        // a few large meshes), their findings joined in document order.
        let mut judged: std::collections::HashSet<(&str, usize)> = std::collections::HashSet::new();
        let mut uses = Vec::new();
        // The keys of every primitive, found in the key table once.
        let [primitives_key, attributes_key, indices_key, normal_key, tangent_key] =
            ["primitives", "attributes", "indices", "NORMAL", "TANGENT"].map(|k| json.key_id(k));
        let [weights_key, joints_key] = ["WEIGHTS_0", "JOINTS_0"].map(|k| json.key_id(k));
        for (m, mesh) in elements(Some(meshes)).enumerate() {
            for (p, primitive) in elements(mesh.get_by(primitives_key)).enumerate() {
                let Some(attributes) = primitive.get_by(attributes_key).and_then(|a| a.as_object())
                else {
                    continue;
                };
                let mut first = |kind: &'static str, key: Option<KeyId>| {
                    index_of(key.and_then(|key| attributes.get_id(key)))
                        .filter(|&index| judged.insert((kind, index)))
                };
                let normal = first("normal", normal_key);
                let tangent = first("tangent", tangent_key);
                let colors: Vec<(String, usize)> = attributes
                    .iter_keyed()
                    .filter(|(_, name, _)| name.starts_with("COLOR_"))
                    .filter_map(|(key, name, _)| {
                        first("color", Some(key)).map(|i| (name.into_owned(), i))
                    })
                    .collect();
                // A primitive with no indices, no data it is the first to use and no skinning
                // has nothing to judge here (a library's primitives mostly share a few
                // accessors).
                let skinned =
                    attributes.contains_id(weights_key) || attributes.contains_id(joints_key);
                if primitive.get_by(indices_key).is_none()
                    && normal.is_none()
                    && tangent.is_none()
                    && colors.is_empty()
                    && !skinned
                {
                    continue;
                }
                uses.push(PrimitiveUses {
                    mesh: m,
                    at: format!("/meshes/{m}/primitives/{p}"),
                    primitive,
                    attributes,
                    normal,
                    tangent,
                    colors,
                });
            }
        }
        let found: Vec<Vec<Diagnostic>> = uses
            .par_iter()
            .map(|uses| {
                let mut out = Vec::new();
                let limit = joint_limits.get(&uses.mesh).copied();
                check_primitive(cx, uses, limit, &mut out);
                out
            })
            .collect();
        out.extend(found.into_iter().flatten());
    }
}

/// One primitive, with the accessors it is the first to use for each kind of check.
struct PrimitiveUses<'a> {
    mesh: usize,
    /// The primitive's pointer.
    at: String,
    primitive: crate::asset::tape::Node<'a>,
    attributes: crate::asset::tape::Object<'a>,
    normal: Option<usize>,
    tangent: Option<usize>,
    /// Each COLOR_n attribute's name and accessor.
    colors: Vec<(String, usize)>,
}

/// One primitive's data: its indices, the normals, tangents and colours it is the first to
/// use, its weights and joints. `limit`: the fewest joints of a skin that draws its mesh.
fn check_primitive(
    cx: &Context,
    uses: &PrimitiveUses,
    limit: Option<(usize, usize)>,
    out: &mut Vec<Diagnostic>,
) {
    let (primitive, attributes, at) = (uses.primitive, uses.attributes, uses.at.as_str());
    let mut capped = Capped {
        out,
        counts: Vec::new(),
    };
    let vertices = index_of(attributes.get("POSITION"))
        .and_then(|i| cx.json().get("accessors")?.get(i)?.get("count")?.as_u64());
    if let (Some(indices), Some(vertices)) = (
        index_of(primitive.get("indices")).and_then(|i| Elements::of(cx, i)),
        vertices,
    ) {
        let mode = primitive.get("mode").map_or(Some(4), |m| m.as_u64());
        check_indices(
            &indices,
            vertices,
            mode,
            &format!("{at}/indices"),
            &mut capped,
        );
    }
    let read = |index: Option<usize>| index.and_then(|i| Elements::of(cx, i));
    if let Some(normals) = read(uses.normal).filter(|e| e.components == 3) {
        check_directions(&normals, &format!("{at}/attributes/NORMAL"), &mut capped);
    }
    if let Some(tangents) = read(uses.tangent).filter(|e| e.components == 4) {
        check_directions(&tangents, &format!("{at}/attributes/TANGENT"), &mut capped);
    }
    for (name, index) in &uses.colors {
        let Some(colors) = read(Some(*index)).filter(|e| e.component_type == 5126) else {
            continue;
        };
        let at = format!("{at}/attributes/{}", pointer::escape(name));
        let n = colors.components;
        colors.for_each(|i, v| {
            for (c, &value) in v.iter().enumerate() {
                if !(0.0..=1.0).contains(&value) {
                    capped.push(&ACCESSOR_NON_CLAMPED, &at, || {
                        format!(
                            "the value at index {} is not within 0..1: {value}",
                            i * n + c
                        )
                    });
                }
            }
        });
    }
    check_skinning(cx, attributes, at, limit, &mut capped);
}

/// Indices against the primitive's vertices and the restart value of their type, and for
/// triangles, the triangles that name a vertex twice (drawn as nothing).
fn check_indices(
    indices: &Elements,
    vertices: u64,
    mode: Option<u64>,
    at: &str,
    capped: &mut Capped,
) {
    if indices.components != 1 {
        return;
    }
    let restart = match indices.component_type {
        5121 => u64::from(u8::MAX),
        5123 => u64::from(u16::MAX),
        5125 => u64::from(u32::MAX),
        _ => return,
    };
    let mut judge = IndexJudge {
        vertices,
        restart,
        triangles: mode == Some(4),
        corner: [0; 3],
        degenerate: 0,
        at,
        capped,
    };
    match indices.packed_unsigned() {
        // Indices as they lie, read as integers (a document's indices are often most of its
        // values).
        Some(values) => {
            for (i, index) in values.enumerate() {
                judge.index(i, index);
            }
        }
        // Unsigned integers of at most 32 bits: exact as doubles.
        None => indices.for_each(|i, v| judge.index(i, v[0] as u64)),
    }
    if judge.degenerate > 0 {
        let (degenerate, all) = (judge.degenerate, indices.count / 3);
        capped.push(&ACCESSOR_INDEX_TRIANGLE_DEGENERATE, at, || {
            format!(
                "{degenerate} of the {all} triangles name a vertex twice and are drawn as nothing"
            )
        });
    }
}

/// The walk over a primitive's indices, one at a time.
struct IndexJudge<'c, 'o> {
    vertices: u64,
    restart: u64,
    triangles: bool,
    /// The current triangle's corners.
    corner: [u64; 3],
    /// Triangles that name a vertex twice, so far.
    degenerate: usize,
    at: &'c str,
    capped: &'c mut Capped<'o>,
}

impl IndexJudge<'_, '_> {
    #[inline(always)]
    fn index(&mut self, i: usize, index: u64) {
        if self.triangles {
            let corner = &mut self.corner;
            corner[i % 3] = index;
            if i % 3 == 2
                && (corner[0] == corner[1] || corner[1] == corner[2] || corner[0] == corner[2])
            {
                self.degenerate += 1;
            }
        }
        if index == self.restart {
            self.capped
                .push(&ACCESSOR_INDEX_PRIMITIVE_RESTART, self.at, || {
                    format!("the index at {i} is {index}, the primitive restart value of its type")
                });
        } else if index >= self.vertices {
            // The last vertex as the reference's message gives it (-1 for a primitive with no
            // vertices).
            let last = self.vertices as f64 - 1.0;
            self.capped.push(&ACCESSOR_INDEX_OOB, self.at, || {
                format!("the index at {i} is {index}, past the primitive's last vertex ({last})")
            });
        }
    }
}

/// Normals (three components) or tangents (four, whose w is checked too) against unit length,
/// read as they lie when they are plain floats.
fn check_directions(elements: &Elements, at: &str, capped: &mut Capped) {
    let n = elements.components;
    match elements.packed_floats() {
        Some((bytes, stride)) => {
            let mut v = [0.0; 4];
            for i in 0..elements.count {
                let element = &bytes[i * stride..i * stride + 4 * n];
                for (slot, b) in v.iter_mut().zip(element.chunks_exact(4)) {
                    *slot = f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
                }
                check_direction(elements, i, &v[..n], at, capped);
            }
        }
        None => elements.for_each(|i, v| check_direction(elements, i, v, at, capped)),
    }
}

#[inline(always)]
fn check_direction(elements: &Elements, i: usize, v: &[f64], at: &str, capped: &mut Capped) {
    if let [_, _, _, w] = *v {
        let w = elements.normalize(w);
        if w != 1.0 && w != -1.0 {
            capped.push(&ACCESSOR_INVALID_SIGN, at, || {
                format!(
                    "the tangent at indices {}..{} has w {w}; it must be 1 or -1",
                    i * 4,
                    i * 4 + 3
                )
            });
        }
    }
    unit_length(elements, i, &v[..3], v.len(), at, capped);
}

/// A vector's length (its first three components, as a loader reads them) against 1.
#[inline(always)]
fn unit_length(
    elements: &Elements,
    i: usize,
    v: &[f64],
    stride: usize,
    at: &str,
    capped: &mut Capped,
) {
    // Compared squared: the root is taken only for a finding's message.
    let squared: f64 = if elements.normalized {
        v[..3].iter().map(|c| elements.normalize(*c).powi(2)).sum()
    } else {
        v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    };
    let (low, high) = (
        (1.0 - UNIT_LENGTH_VEC3).powi(2),
        (1.0 + UNIT_LENGTH_VEC3).powi(2),
    );
    // A NaN component is ACCESSOR_INVALID_FLOAT's finding.
    if !squared.is_nan() && !(low..=high).contains(&squared) {
        let length = squared.sqrt();
        capped.push(&ACCESSOR_VECTOR3_NON_UNIT, at, || {
            format!(
                "the vector at indices {}..{} is not of unit length: {length}",
                i * stride,
                i * stride + 2
            )
        });
    }
}

/// For each mesh, the smallest number of joints of the skins that draw it, with that skin.
fn joint_limits(cx: &Context) -> HashMap<usize, (usize, usize)> {
    let json = cx.json();
    let skins = json.get("skins");
    let mut limits: HashMap<usize, (usize, usize)> = HashMap::new();
    for node in elements(json.get("nodes")) {
        let (Some(mesh), Some(skin)) = (index_of(node.get("mesh")), index_of(node.get("skin")))
        else {
            continue;
        };
        let Some(joints) = skins
            .and_then(|s| s.get(skin))
            .and_then(|s| s.get("joints"))
            .and_then(|j| j.as_array())
        else {
            continue;
        };
        let limit = (joints.len(), skin);
        limits
            .entry(mesh)
            .and_modify(|least| *least = (*least).min(limit))
            .or_insert(limit);
    }
    limits
}

/// Weights and joints, set by set and vertex by vertex.
fn check_skinning(
    cx: &Context,
    attributes: crate::asset::tape::Object,
    at: &str,
    limit: Option<(usize, usize)>,
    capped: &mut Capped,
) {
    let mut sets = Vec::new();
    for set in 0.. {
        let weights = attributes.get(&format!("WEIGHTS_{set}"));
        let joints = attributes.get(&format!("JOINTS_{set}"));
        if weights.is_none() && joints.is_none() {
            break;
        }
        let weights = index_of(weights)
            .and_then(|i| Elements::of(cx, i))
            .filter(|e| e.components == 4);
        let joints = index_of(joints)
            .and_then(|i| Elements::of(cx, i))
            .filter(|e| e.components == 4);
        let pointers = (
            format!("{at}/attributes/WEIGHTS_{set}"),
            format!("{at}/attributes/JOINTS_{set}"),
        );
        sets.push((pointers, weights, joints));
    }
    if sets.is_empty() {
        return;
    }
    // Elements read side by side: as many as the shortest accessor holds (accessors of one
    // primitive with unequal counts are MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT; a weights
    // accessor longer than its joints must not be read past the joints' end).
    let count = sets
        .iter()
        .flat_map(|(_, w, j)| [w.as_ref(), j.as_ref()])
        .flatten()
        .map(|e| e.count)
        .min()
        .unwrap_or(0);
    let components = sets.len() * 4;
    let tolerance = UNIT_SUM_STEP * ((components - 1) / 2) as f64;
    let (mut weight, mut joint) = ([0.0; 4], [0.0; 4]);
    let mut used: Vec<f64> = Vec::with_capacity(components);
    for i in 0..count {
        let mut sum = 0.0;
        let mut complete = true;
        used.clear();
        for ((weights_at, joints_at), weights, joints) in &sets {
            let Some(weights) = weights else {
                complete = false;
                continue;
            };
            weights.element(i, &mut weight);
            for (c, w) in weight.iter_mut().enumerate() {
                *w = weights.normalize(*w);
                if *w < 0.0 {
                    let value = *w;
                    capped.push(&ACCESSOR_WEIGHTS_NEGATIVE, weights_at, || {
                        format!(
                            "the weight at index {} (component {c}) is negative: {value}",
                            i * 4 + c
                        )
                    });
                    // Reported on its own, and left out of the sum, as the reference does.
                    continue;
                }
                sum += *w;
            }
            let Some(joints) = joints else {
                continue;
            };
            joints.element(i, &mut joint);
            for c in 0..4 {
                let j = joint[c];
                if weight[c] == 0.0 {
                    if j != 0.0 {
                        capped.push(&ACCESSOR_JOINTS_USED_ZERO_WEIGHT, joints_at, || {
                            format!(
                                "the joint at index {} (component {c}) is {j} with zero weight",
                                i * 4 + c
                            )
                        });
                    }
                    continue;
                }
                if let Some((joints_count, skin)) = limit {
                    if j >= joints_count as f64 {
                        capped.push(&ACCESSOR_JOINTS_INDEX_OOB, joints_at, || {
                            format!(
                                "the joint at index {} (component {c}) is {j}, past the last joint ({}) of skin {skin}",
                                i * 4 + c,
                                joints_count.saturating_sub(1)
                            )
                        });
                    }
                }
                if used.contains(&j) {
                    capped.push(&ACCESSOR_JOINTS_INDEX_DUPLICATE, joints_at, || {
                        format!("the joint at index {} (component {c}) is {j}, already weighted for this vertex", i * 4 + c)
                    });
                } else {
                    used.push(j);
                }
            }
        }
        if complete && (sum - 1.0).abs() > tolerance {
            for ((weights_at, _), _, _) in &sets {
                capped.push(&ACCESSOR_WEIGHTS_NON_NORMALIZED, weights_at, || {
                    format!(
                        "the weights at indices {}..{} sum to {sum}, not 1",
                        i * 4,
                        i * 4 + 3
                    )
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    fn document(values: &[(&str, u64, &str, Vec<f32>)], primitive: &str, extra: &str) -> String {
        document_with_meshes(
            values,
            &format!(r#"[{{"primitives":[{primitive}]}}]"#),
            extra,
        )
    }

    fn document_with_meshes(
        values: &[(&str, u64, &str, Vec<f32>)],
        meshes: &str,
        extra: &str,
    ) -> String {
        let mut bytes = Vec::new();
        let mut views = Vec::new();
        let mut accessors = Vec::new();
        for (i, (kind, component, _, data)) in values.iter().enumerate() {
            let start = bytes.len();
            for v in data {
                match component {
                    5126 => bytes.extend_from_slice(&v.to_le_bytes()),
                    5123 => bytes.extend_from_slice(&(*v as u16).to_le_bytes()),
                    _ => bytes.push(*v as u8),
                }
            }
            while bytes.len() % 4 != 0 {
                bytes.push(0);
            }
            let per = match *kind {
                "SCALAR" => 1,
                "VEC3" => 3,
                _ => 4,
            };
            views.push(format!(
                r#"{{"buffer":0,"byteOffset":{start},"byteLength":{}}}"#,
                bytes.len() - start
            ));
            let bounds = if values[i].2 == "POSITION" {
                r#","min":[0,0,0],"max":[1,1,1]"#
            } else {
                ""
            };
            accessors.push(format!(
                r#"{{"bufferView":{i},"componentType":{component},"count":{},"type":"{kind}"{bounds}}}"#,
                data.len() / per
            ));
        }
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{}],"accessors":[{}],"meshes":{meshes}{extra}}}"#,
            bytes.len(),
            views.join(","),
            accessors.join(",")
        )
    }

    #[test]
    fn indices_normals_tangents_and_colours_are_judged_by_their_values() {
        let text = document(
            &[
                ("VEC3", 5126, "POSITION", vec![0.0; 9]),
                ("SCALAR", 5121, "indices", vec![0.0, 1.0, 3.0, 255.0]),
                (
                    "VEC3",
                    5126,
                    "NORMAL",
                    vec![0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 0.0],
                ),
                (
                    "VEC4",
                    5126,
                    "TANGENT",
                    vec![1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, -1.0],
                ),
                (
                    "VEC4",
                    5126,
                    "COLOR_0",
                    vec![0.0, 0.5, 1.5, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                ),
            ],
            r#"{"attributes":{"POSITION":0,"NORMAL":2,"TANGENT":3,"COLOR_0":4},"indices":1}"#,
            "",
        );
        assert_eq!(
            crate::rules::findings_of(&VertexData, &text),
            [
                "ACCESSOR_INDEX_OOB /meshes/0/primitives/0/indices",
                "ACCESSOR_INDEX_PRIMITIVE_RESTART /meshes/0/primitives/0/indices",
                "ACCESSOR_VECTOR3_NON_UNIT /meshes/0/primitives/0/attributes/NORMAL",
                "ACCESSOR_INVALID_SIGN /meshes/0/primitives/0/attributes/TANGENT",
                "ACCESSOR_VECTOR3_NON_UNIT /meshes/0/primitives/0/attributes/TANGENT",
                "ACCESSOR_NON_CLAMPED /meshes/0/primitives/0/attributes/COLOR_0",
            ]
        );
    }

    #[test]
    fn weights_and_joints_are_judged_vertex_by_vertex() {
        let text = document(
            &[
                ("VEC3", 5126, "POSITION", vec![0.0; 9]),
                (
                    "VEC4",
                    5126,
                    "WEIGHTS_0",
                    vec![1.0, 0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 0.0, 0.5, 0.5, -0.5, 0.5],
                ),
                (
                    "VEC4",
                    5123,
                    "JOINTS_0",
                    vec![0.0, 4.0, 0.0, 0.0, 1.0, 2.0, 9.0, 0.0, 1.0, 1.0, 2.0, 0.0],
                ),
            ],
            r#"{"attributes":{"POSITION":0,"WEIGHTS_0":1,"JOINTS_0":2}}"#,
            r#","nodes":[{"mesh":0,"skin":0},{},{},{}],"skins":[{"joints":[1,2,3]}]"#,
        );
        assert_eq!(
            crate::rules::findings_of(&VertexData, &text),
            [
                "ACCESSOR_JOINTS_USED_ZERO_WEIGHT /meshes/0/primitives/0/attributes/JOINTS_0",
                "ACCESSOR_JOINTS_INDEX_OOB /meshes/0/primitives/0/attributes/JOINTS_0",
                "ACCESSOR_WEIGHTS_NON_NORMALIZED /meshes/0/primitives/0/attributes/WEIGHTS_0",
                "ACCESSOR_WEIGHTS_NEGATIVE /meshes/0/primitives/0/attributes/WEIGHTS_0",
                "ACCESSOR_JOINTS_INDEX_DUPLICATE /meshes/0/primitives/0/attributes/JOINTS_0",
                "ACCESSOR_WEIGHTS_NON_NORMALIZED /meshes/0/primitives/0/attributes/WEIGHTS_0",
            ]
        );
    }

    /// Every finding (code, pointer, message) of a primitive whose indices, normals and
    /// tangents hold `indices`, `normals` and `tangents`: stored in buffer views (`sparse`
    /// false: read as they lie), or as sparse substitutions of every element of accessors
    /// without a view (read by the general reader).
    fn findings_read(
        index_type: u64,
        indices: &[u32],
        normals: &[f32],
        tangents: &[f32],
        sparse: bool,
    ) -> Vec<String> {
        let mut bytes: Vec<u8> = Vec::new();
        let (mut views, mut accessors) = (Vec::new(), Vec::new());
        let mut view = |bytes: &mut Vec<u8>, part: &[u8]| {
            let start = bytes.len();
            bytes.extend_from_slice(part);
            bytes.resize(bytes.len().next_multiple_of(4), 0);
            views.push(format!(
                r#"{{"buffer":0,"byteOffset":{start},"byteLength":{}}}"#,
                part.len()
            ));
            views.len() - 1
        };
        let index_bytes: Vec<u8> = indices
            .iter()
            .flat_map(|&i| match index_type {
                5121 => vec![i as u8],
                5123 => (i as u16).to_le_bytes().to_vec(),
                _ => i.to_le_bytes().to_vec(),
            })
            .collect();
        let floats =
            |values: &[f32]| -> Vec<u8> { values.iter().flat_map(|v| v.to_le_bytes()).collect() };
        let positions = view(&mut bytes, &floats(&[0.0; 12]));
        accessors.push(format!(
            r#"{{"bufferView":{positions},"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[0,0,0]}}"#
        ));
        for (component, kind, count, part) in [
            (index_type, "SCALAR", indices.len(), index_bytes),
            (5126, "VEC3", normals.len() / 3, floats(normals)),
            (5126, "VEC4", tangents.len() / 4, floats(tangents)),
        ] {
            let data = view(&mut bytes, &part);
            accessors.push(if sparse {
                let every: Vec<u8> = (0..count as u32).flat_map(|i| i.to_le_bytes()).collect();
                let at = view(&mut bytes, &every);
                format!(
                    r#"{{"componentType":{component},"count":{count},"type":"{kind}","sparse":{{"count":{count},
                    "indices":{{"bufferView":{at},"componentType":5125}},"values":{{"bufferView":{data}}}}}}}"#
                )
            } else {
                format!(
                    r#"{{"bufferView":{data},"componentType":{component},"count":{count},"type":"{kind}"}}"#
                )
            });
        }
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{}],"accessors":[{}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":2,"TANGENT":3}},"indices":1}}]}}]}}"#,
            bytes.len(),
            views.join(","),
            accessors.join(",")
        );
        crate::rules::findings_with_messages_of(&VertexData, &text)
    }

    #[test]
    fn indices_and_directions_read_as_they_lie_give_the_general_readers_findings() {
        // Four vertices; indices in range, past it, degenerate and at each type's restart
        // value; normals and tangents of unit length, short, long, NaN, and w of 1, -1, 0, 2.
        let normals = [
            0.0,
            0.0,
            1.0,
            0.6,
            0.8,
            0.0,
            0.5,
            0.0,
            0.0,
            2.0,
            0.0,
            0.0,
            f32::NAN,
            0.0,
            1.0,
        ];
        let tangents = [
            1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, 0.3, 0.0, 0.0, 2.0,
        ];
        let mut codes = std::collections::BTreeSet::new();
        for (index_type, restart) in [(5121, 255), (5123, 65_535), (5125, u32::MAX)] {
            let indices = [0, 1, 2, 2, 2, 3, 0, 4, restart, 1, 3, 7];
            let fast = findings_read(index_type, &indices, &normals, &tangents, false);
            let general = findings_read(index_type, &indices, &normals, &tangents, true);
            assert_eq!(fast, general, "indices of type {index_type}");
            codes.extend(
                fast.iter()
                    .map(|f| f.split(' ').next().unwrap_or_default().to_string()),
            );
            assert!(
                fast.iter().any(|f| f.ends_with(&format!(
                    "the index at 8 is {restart}, the primitive restart value of its type"
                ))),
                "{fast:?}"
            );
        }
        assert_eq!(
            codes.into_iter().collect::<Vec<_>>(),
            [
                "ACCESSOR_INDEX_OOB",
                "ACCESSOR_INDEX_PRIMITIVE_RESTART",
                "ACCESSOR_INDEX_TRIANGLE_DEGENERATE",
                "ACCESSOR_INVALID_SIGN",
                "ACCESSOR_VECTOR3_NON_UNIT",
            ]
        );
    }

    #[test]
    fn primitives_read_side_by_side_report_in_document_order_each_accessor_at_its_first_use() {
        // Mesh 0 and mesh 1 each have a normal that is too long; they share a colour
        // accessor with a value above 1, judged at its first use (mesh 0) only; mesh 1's
        // index 5 is past its three vertices.
        let values = [
            ("VEC3", 5126, "POSITION", vec![0.0; 9]),
            (
                "VEC3",
                5126,
                "NORMAL",
                vec![0.0, 0.0, 2.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0],
            ),
            (
                "VEC3",
                5126,
                "NORMAL",
                vec![0.0, 0.0, 1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 1.0],
            ),
            (
                "VEC4",
                5126,
                "COLOR_0",
                vec![1.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            ),
            ("SCALAR", 5121, "indices", vec![0.0, 1.0, 5.0]),
        ];
        let text = document_with_meshes(
            &values,
            r#"[{"primitives":[{"attributes":{"POSITION":0,"NORMAL":1,"COLOR_0":3}}]},
                {"primitives":[{"attributes":{"POSITION":0,"NORMAL":2,"COLOR_0":3},"indices":4}]}]"#,
            "",
        );
        assert_eq!(
            crate::rules::findings_of(&VertexData, &text),
            [
                "ACCESSOR_VECTOR3_NON_UNIT /meshes/0/primitives/0/attributes/NORMAL",
                "ACCESSOR_NON_CLAMPED /meshes/0/primitives/0/attributes/COLOR_0",
                "ACCESSOR_INDEX_OOB /meshes/1/primitives/0/indices",
                "ACCESSOR_VECTOR3_NON_UNIT /meshes/1/primitives/0/attributes/NORMAL",
            ]
        );
    }
}
