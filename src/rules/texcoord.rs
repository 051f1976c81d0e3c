//! Texture coordinates: a sheen or fuzz texture read through `texCoord` N (or the N that
//! KHR_texture_transform substitutes) needs every mesh primitive drawn with that material to
//! carry TEXCOORD_N, or loaders sample garbage or refuse the mesh.

use super::{effective_tex_coord, slot_uses, Context, Rule, SlotUse};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};
use std::collections::HashMap;

pub const MESH_PRIMITIVE_TOO_FEW_TEXCOORDS: Code = Code::new(
    "MESH_PRIMITIVE_TOO_FEW_TEXCOORDS",
    Severity::Error,
    "A primitive uses a material whose sheen/fuzz texture reads TEXCOORD_N, which the primitive lacks.",
);

pub struct TexCoords;

impl Rule for TexCoords {
    fn codes(&self) -> &'static [&'static Code] {
        &[&MESH_PRIMITIVE_TOO_FEW_TEXCOORDS]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        // material index -> the TEXCOORD_N attributes its sheen/fuzz textures read, each with
        // its slot (named only in a finding).
        let mut needs: HashMap<u64, Vec<(String, SlotUse<Node>)>> = HashMap::new();
        for layer in cx.layer_objects() {
            for slot in slot_uses(&layer) {
                needs.entry(layer.material as u64).or_default().push((
                    format!("TEXCOORD_{}", effective_tex_coord(slot.value)),
                    slot,
                ));
            }
        }
        if needs.is_empty() {
            return;
        }
        for (m, mesh) in super::elements(json.get("meshes")).enumerate() {
            for (p, primitive) in super::elements(mesh.get("primitives")).enumerate() {
                let Some(material) = primitive.get("material").and_then(|v| v.as_u64()) else {
                    continue;
                };
                let Some(slots) = needs.get(&material) else {
                    continue;
                };
                let attributes = primitive.get("attributes").and_then(|a| a.as_object());
                for (attribute, slot) in slots {
                    if !attributes.is_some_and(|a| a.contains_key(attribute)) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_TOO_FEW_TEXCOORDS,
                            format!("/meshes/{m}/primitives/{p}/material"),
                            format!(
                                "material {material}'s {} reads {attribute}, which this primitive does not have",
                                slot.pointer()
                            ),
                        ));
                    }
                }
            }
        }
    }
}
