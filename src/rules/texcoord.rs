//! Texture coordinates: a sheen or fuzz texture read through `texCoord` N (or the N that
//! KHR_texture_transform substitutes) needs every mesh primitive drawn with that material to
//! carry TEXCOORD_N, or loaders sample garbage or refuse the mesh.

use super::{effective_tex_coord, layer_objects, slot_uses, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use serde_json::Value;
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
        // material index -> texCoord sets its sheen/fuzz textures read, with the slot pointer.
        let mut needs: HashMap<u64, Vec<(u64, String)>> = HashMap::new();
        for layer in layer_objects(json) {
            for slot in slot_uses(&layer) {
                needs
                    .entry(layer.material as u64)
                    .or_default()
                    .push((effective_tex_coord(slot.value), slot.pointer));
            }
        }
        if needs.is_empty() {
            return;
        }
        let meshes = json
            .get("meshes")
            .and_then(Value::as_array)
            .map_or(&[][..], Vec::as_slice);
        for (m, mesh) in meshes.iter().enumerate() {
            let primitives = mesh
                .get("primitives")
                .and_then(Value::as_array)
                .map_or(&[][..], Vec::as_slice);
            for (p, primitive) in primitives.iter().enumerate() {
                let Some(material) = primitive.get("material").and_then(Value::as_u64) else {
                    continue;
                };
                let Some(slots) = needs.get(&material) else {
                    continue;
                };
                let attributes = primitive.get("attributes").and_then(Value::as_object);
                for (set, slot_pointer) in slots {
                    let attribute = format!("TEXCOORD_{set}");
                    if !attributes.is_some_and(|a| a.contains_key(&attribute)) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_TOO_FEW_TEXCOORDS,
                            format!("/meshes/{m}/primitives/{p}/material"),
                            format!("material {material}'s {slot_pointer} reads {attribute}, which this primitive does not have"),
                        ));
                    }
                }
            }
        }
    }
}
