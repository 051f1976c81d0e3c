//! A node's own properties, beyond their schema (the Khronos glTF-Validator's node checks, with
//! its codes and pointers; the spec's "Transformations" and "Skins" sections):
//!
//! - ROTATION_NON_UNIT (error): a rotation quaternion whose length is not 1 (within 0.00769,
//!   the Khronos validator's tolerance: a little more than signed 8-bit quantization loses).
//! - NODE_MATRIX_NON_TRS (error): a matrix that no translation, rotation and scale make (its last
//!   row not 0, 0, 0, 1, its 3×3 part singular or sheared), which the spec requires.
//! - NODE_MATRIX_DEFAULT (info): a matrix that is the identity, the default it need not state;
//!   its fix removes it.
//! - NODE_WEIGHTS_INVALID (error): `weights` not one per morph target of the node's mesh.
//! - NODE_SKIN_WITH_NON_SKINNED_MESH (error): a skin on a node whose mesh has no JOINTS_n.
//! - NODE_SKINNED_MESH_WITHOUT_SKIN (warning): a mesh with JOINTS_n on a node without a skin.
//! - NODE_SKINNED_MESH_LOCAL_TRANSFORMS (warning): a skinned node with a transform of its own,
//!   which does not move a skinned mesh.

use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ROTATION_NON_UNIT: Code = Code::new(
    "ROTATION_NON_UNIT",
    Severity::Error,
    "A node's rotation quaternion is not of unit length.",
);
pub const NODE_MATRIX_NON_TRS: Code = Code::new(
    "NODE_MATRIX_NON_TRS",
    Severity::Error,
    "A node's matrix cannot be decomposed into translation, rotation and scale.",
);
pub const NODE_MATRIX_DEFAULT: Code = Code::new(
    "NODE_MATRIX_DEFAULT",
    Severity::Info,
    "A node's matrix is the identity, which is the default: it need not be given.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const NODE_WEIGHTS_INVALID: Code = Code::new(
    "NODE_WEIGHTS_INVALID",
    Severity::Error,
    "A node's weights are not one per morph target of its mesh.",
);
pub const NODE_SKIN_WITH_NON_SKINNED_MESH: Code = Code::new(
    "NODE_SKIN_WITH_NON_SKINNED_MESH",
    Severity::Error,
    "A node has a skin, but its mesh has no joints data.",
);
pub const NODE_SKINNED_MESH_WITHOUT_SKIN: Code = Code::new(
    "NODE_SKINNED_MESH_WITHOUT_SKIN",
    Severity::Warning,
    "A node draws a mesh with joints data but has no skin.",
);
pub const NODE_SKINNED_MESH_LOCAL_TRANSFORMS: Code = Code::new(
    "NODE_SKINNED_MESH_LOCAL_TRANSFORMS",
    Severity::Warning,
    "A node with a skinned mesh has a transform of its own, which does not affect the mesh.",
);

/// How far from 1 a unit quaternion's length may be.
const UNIT_TOLERANCE: f64 = super::data::UNIT_LENGTH_VEC4;
/// How far from orthogonal (relative to their lengths) a matrix's scaled axes may be.
const SHEAR_TOLERANCE: f64 = 1e-4;

/// The identity matrix, a node's default.
const IDENTITY: [f64; 16] = [
    1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
];

/// Whether a column-major 4×4 matrix is a composition of translation, rotation and scale.
pub fn is_trs(m: &[f64; 16]) -> bool {
    let last_row = [m[3], m[7], m[11], m[15]];
    if last_row != [0.0, 0.0, 0.0, 1.0] {
        return false;
    }
    let axis = |c: usize| [m[4 * c], m[4 * c + 1], m[4 * c + 2]];
    let (x, y, z) = (axis(0), axis(1), axis(2));
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let length = |a: [f64; 3]| dot(a, a).sqrt();
    let (lx, ly, lz) = (length(x), length(y), length(z));
    if lx == 0.0 || ly == 0.0 || lz == 0.0 {
        return false;
    }
    let sheared = |a, b, la: f64, lb: f64| (dot(a, b) / (la * lb)).abs() > SHEAR_TOLERANCE;
    !(sheared(x, y, lx, ly) || sheared(x, z, lx, lz) || sheared(y, z, ly, lz))
}

fn numbers<const N: usize>(value: Option<Node>) -> Option<[f64; N]> {
    let array = value?.as_array()?;
    if array.len() != N {
        return None;
    }
    let mut out = [0.0; N];
    for (slot, element) in out.iter_mut().zip(array.iter()) {
        *slot = element.as_f64()?;
    }
    Some(out)
}

pub struct Nodes;

impl Rule for Nodes {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["nodes", "meshes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ROTATION_NON_UNIT,
            &NODE_MATRIX_NON_TRS,
            &NODE_MATRIX_DEFAULT,
            &NODE_WEIGHTS_INVALID,
            &NODE_SKIN_WITH_NON_SKINNED_MESH,
            &NODE_SKINNED_MESH_WITHOUT_SKIN,
            &NODE_SKINNED_MESH_LOCAL_TRANSFORMS,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let meshes = json.get("meshes");
        for (i, node) in elements(json.get("nodes")).enumerate() {
            let at = format!("/nodes/{i}");
            if let Some(q) = numbers::<4>(node.get("rotation")) {
                let length = q.iter().map(|c| c * c).sum::<f64>().sqrt();
                if (length - 1.0).abs() > UNIT_TOLERANCE {
                    out.push(Diagnostic::new(
                        &ROTATION_NON_UNIT,
                        format!("{at}/rotation"),
                        format!("the rotation quaternion has length {length}, not 1"),
                    ));
                }
            }
            if let Some(m) = numbers::<16>(node.get("matrix")) {
                if m == IDENTITY {
                    out.push(Diagnostic::new(
                        &NODE_MATRIX_DEFAULT,
                        format!("{at}/matrix"),
                        "the matrix is the identity, the default: it need not be given",
                    ));
                } else if !is_trs(&m) {
                    out.push(Diagnostic::new(
                        &NODE_MATRIX_NON_TRS,
                        format!("{at}/matrix"),
                        "the matrix cannot be decomposed into translation, rotation and scale",
                    ));
                }
            }
            let mesh = super::element_at(meshes, node.get("mesh"));
            let Some(mesh) = mesh else {
                continue;
            };
            let primitives: Vec<Node> = elements(mesh.get("primitives")).collect();
            if let Some(weights) = node.get("weights").and_then(|w| w.as_array()) {
                let targets = primitives
                    .first()
                    .and_then(|p| p.get("targets"))
                    .and_then(|t| t.as_array())
                    .map_or(0, |t| t.len());
                if weights.len() != targets {
                    out.push(Diagnostic::new(
                        &NODE_WEIGHTS_INVALID,
                        format!("{at}/weights"),
                        format!(
                            "{} weights for the mesh's {targets} morph targets",
                            weights.len()
                        ),
                    ));
                }
            }
            let skinned_mesh = primitives.iter().any(|p| {
                p.get("attributes")
                    .and_then(|a| a.as_object())
                    .is_some_and(|a| a.keys().any(|k| k.starts_with("JOINTS_")))
            });
            let has_skin = node.get("skin").is_some();
            if has_skin && !skinned_mesh {
                out.push(Diagnostic::new(
                    &NODE_SKIN_WITH_NON_SKINNED_MESH,
                    at.clone(),
                    "the node has a skin, but its mesh has no JOINTS_n attributes",
                ));
            } else if !has_skin && skinned_mesh {
                out.push(Diagnostic::new(
                    &NODE_SKINNED_MESH_WITHOUT_SKIN,
                    at.clone(),
                    "the node's mesh has JOINTS_n attributes, but the node has no skin",
                ));
            }
            if has_skin
                && skinned_mesh
                && ["translation", "rotation", "scale", "matrix"]
                    .iter()
                    .any(|k| node.get(*k).is_some())
            {
                out.push(Diagnostic::new(
                    &NODE_SKINNED_MESH_LOCAL_TRANSFORMS,
                    at,
                    "the node's own transform does not move its skinned mesh",
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Nodes, text)
    }

    #[test]
    fn node_transforms_weights_and_skins_that_do_not_fit_are_found() {
        let text = r#"{"asset":{"version":"2.0"},
            "meshes":[{"primitives":[{"attributes":{"POSITION":0},"targets":[{"POSITION":0}]}]},
                      {"primitives":[{"attributes":{"POSITION":0,"JOINTS_0":0,"WEIGHTS_0":0}}]}],
            "nodes":[{"rotation":[1,1,1,1]},{"rotation":[0,0,0.7071068,0.7071068]},
                     {"matrix":[1,1,1,1,1,1,1,1,1,1,1,1,1,1,1,1]},
                     {"matrix":[2,0,0,0,0,0,3,0,0,-1,0,0,5,6,7,1]},
                     {"mesh":0,"weights":[0.5,0.5],"skin":0},
                     {"mesh":1},{"mesh":1,"skin":0,"translation":[1,2,3]},
                     {"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1.0]}]}"#;
        assert_eq!(
            found(text),
            [
                "ROTATION_NON_UNIT /nodes/0/rotation",
                "NODE_MATRIX_NON_TRS /nodes/2/matrix",
                "NODE_WEIGHTS_INVALID /nodes/4/weights",
                "NODE_SKIN_WITH_NON_SKINNED_MESH /nodes/4",
                "NODE_SKINNED_MESH_WITHOUT_SKIN /nodes/5",
                "NODE_SKINNED_MESH_LOCAL_TRANSFORMS /nodes/6",
                "NODE_MATRIX_DEFAULT /nodes/7/matrix",
            ]
        );
    }

    #[test]
    fn a_sheared_or_flattened_matrix_is_not_trs() {
        let identity = [
            1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ];
        assert!(is_trs(&identity));
        let mut sheared = identity;
        sheared[4] = 0.5;
        assert!(!is_trs(&sheared));
        let mut flat = identity;
        flat[10] = 0.0;
        assert!(!is_trs(&flat));
        let mut mirrored = identity;
        mirrored[0] = -2.0;
        assert!(is_trs(&mirrored));
    }
}
