//! Texture coordinates: a texture read through `texCoord` N (or the N that
//! KHR_texture_transform substitutes) needs every mesh primitive drawn with its material to carry
//! TEXCOORD_N, or loaders sample garbage or refuse the mesh. Every texture of the material counts:
//! the core's (baseColorTexture, normalTexture, …) and those of its extensions that have a schema
//! (clearcoat, sheen, fuzz, …), as [`super::Context::material_textures`] finds them.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use std::borrow::Cow;

pub const MESH_PRIMITIVE_TOO_FEW_TEXCOORDS: Code = Code::new(
    "MESH_PRIMITIVE_TOO_FEW_TEXCOORDS",
    Severity::Error,
    "A primitive uses a material with a texture (of the core or of an extension) that reads TEXCOORD_N, which the primitive lacks.",
)
.fixable(crate::diagnostics::Safety::Unsafe);

pub struct TexCoords;

impl Rule for TexCoords {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials", "meshes"])
    }

    /// Among the dearest rules on a large document: every primitive of every mesh.
    fn cost(&self) -> u32 {
        2
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&MESH_PRIMITIVE_TOO_FEW_TEXCOORDS]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        if json.get("meshes").is_none() {
            return;
        }
        let textures = cx.material_textures();
        if textures.iter().all(Vec::is_empty) {
            return;
        }
        // Attribute names by set, written once each.
        let mut names: Vec<String> = Vec::new();
        for (m, p, primitive, material, reads) in cx.primitives_with_textures() {
            let attributes = primitive.get("attributes").and_then(|a| a.as_object());
            for texture in reads {
                let attribute = attribute_name(&mut names, texture.set);
                if !attributes.is_some_and(|a| a.contains_key(&attribute)) {
                    out.push(Diagnostic::new(
                        &MESH_PRIMITIVE_TOO_FEW_TEXCOORDS,
                        format!("/meshes/{m}/primitives/{p}/material"),
                        format!(
                            "material {material}'s /materials/{material}{} reads {attribute}, which this primitive does not have",
                            texture.pointer
                        ),
                    ));
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
