//! Texture coordinates: a sheen or fuzz texture read through `texCoord` N (or the N that
//! KHR_texture_transform substitutes) needs every mesh primitive drawn with that material to
//! carry TEXCOORD_N, or loaders sample garbage or refuse the mesh.

use super::{effective_tex_coord, slot_pointer, slot_uses, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers::Slot;
use std::borrow::Cow;

pub const MESH_PRIMITIVE_TOO_FEW_TEXCOORDS: Code = Code::new(
    "MESH_PRIMITIVE_TOO_FEW_TEXCOORDS",
    Severity::Error,
    "A primitive uses a material whose sheen/fuzz texture reads TEXCOORD_N, which the primitive lacks.",
);

pub struct TexCoords;

impl Rule for TexCoords {
    /// Among the dearest rules on a large document: every primitive of every mesh.
    fn cost(&self) -> u32 {
        2
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&MESH_PRIMITIVE_TOO_FEW_TEXCOORDS]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        // Each sheen/fuzz texture slot with the TEXCOORD set it reads, in material order (the
        // order the layers come in), so that a primitive's material finds its slots by a
        // binary search: a large document has a material per primitive.
        let needs: Vec<(usize, u64, &'static Slot)> = cx
            .layer_objects()
            .flat_map(|layer| slot_uses(&layer))
            .map(|slot| (slot.material, effective_tex_coord(slot.value), slot.slot))
            .collect();
        if needs.is_empty() {
            return;
        }
        // Attribute names by set, written once each.
        let mut names: Vec<String> = Vec::new();
        for (m, mesh) in super::elements(json.get("meshes")).enumerate() {
            for (p, primitive) in super::elements(mesh.get("primitives")).enumerate() {
                let Some(material) = primitive.get("material").and_then(|v| v.as_u64()) else {
                    continue;
                };
                let Ok(material) = usize::try_from(material) else {
                    continue;
                };
                let first = needs.partition_point(|(of, _, _)| *of < material);
                let slots = needs[first..]
                    .iter()
                    .take_while(|(of, _, _)| *of == material);
                let attributes = primitive.get("attributes").and_then(|a| a.as_object());
                for (_, set, slot) in slots {
                    let attribute = attribute_name(&mut names, *set);
                    if !attributes.is_some_and(|a| a.contains_key(&attribute)) {
                        out.push(Diagnostic::new(
                            &MESH_PRIMITIVE_TOO_FEW_TEXCOORDS,
                            format!("/meshes/{m}/primitives/{p}/material"),
                            format!(
                                "material {material}'s {} reads {attribute}, which this primitive does not have",
                                slot_pointer(material, slot)
                            ),
                        ));
                    }
                }
            }
        }
    }
}

/// `TEXCOORD_{set}`, from `names` (indexed by set) once it has been written; a set past the
/// few a mesh has is written on each call rather than kept.
fn attribute_name(names: &mut Vec<String>, set: u64) -> Cow<'_, str> {
    const KEPT: u64 = 16;
    if set >= KEPT {
        return Cow::Owned(format!("TEXCOORD_{set}"));
    }
    while names.len() as u64 <= set {
        names.push(format!("TEXCOORD_{}", names.len()));
    }
    Cow::Borrowed(&names[set as usize])
}
