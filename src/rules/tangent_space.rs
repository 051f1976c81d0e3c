//! Tangent space: a normal texture (the core's `normalTexture`, or any extension's
//! `material.normalTextureInfo`, such as KHR_materials_clearcoat's `clearcoatNormalTexture`) is
//! read in the tangent space the primitive's NORMAL and TANGENT attributes give. Without them a
//! loader generates one, and loaders generate different ones (a warning, as in the Khronos
//! validator); sheen and fuzz assets are fabric and nearly always carry normal maps.
//!
//! KHR_materials_anisotropy's direction texture is read in the same tangent space.
//!
//! The clearcoat spec goes further: a primitive whose material has a clearcoat normal texture
//! MUST have NORMAL and TANGENT, or its material MUST have a normal texture (from which loaders
//! generate the tangents). Without either it is an error. Only the JSON is read.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const MESH_PRIMITIVE_GENERATED_TANGENT_SPACE: Code = Code::new(
    "MESH_PRIMITIVE_GENERATED_TANGENT_SPACE",
    Severity::Warning,
    "A primitive without NORMAL and TANGENT uses a material with a normal texture: loaders generate the tangent space, each its own way.",
);
pub const MESH_PRIMITIVE_NO_TANGENT_SPACE: Code = Code::new(
    "MESH_PRIMITIVE_NO_TANGENT_SPACE",
    Severity::Error,
    "A primitive without NORMAL and TANGENT uses a material whose extension needs a tangent space (clearcoatNormalTexture, anisotropyTexture) and that has no normalTexture to generate it from.",
);

pub struct TangentSpace;

impl Rule for TangentSpace {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials", "meshes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &MESH_PRIMITIVE_GENERATED_TANGENT_SPACE,
            &MESH_PRIMITIVE_NO_TANGENT_SPACE,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        if json.get("meshes").is_none() {
            return;
        }
        let textures = cx.material_textures();
        if !textures.iter().flatten().any(needs_tangents) {
            return;
        }
        for (m, p, primitive, material, reads) in cx.primitives_with_textures() {
            let Some(first) = reads.iter().find(|t| needs_tangents(t)).map(|t| &t.pointer) else {
                continue;
            };
            let attributes = primitive.get("attributes").and_then(|a| a.as_object());
            let has = |name: &str| attributes.is_some_and(|a| a.contains_key(name));
            if has("NORMAL") && has("TANGENT") {
                continue;
            }
            let at = format!("/meshes/{m}/primitives/{p}/material");
            if reads.iter().any(|t| t.pointer == "/normalTexture") {
                out.push(Diagnostic::new(
                    &MESH_PRIMITIVE_GENERATED_TANGENT_SPACE,
                    at,
                    format!(
                        "material {material} has a normal texture but this primitive has no {}: loaders generate the tangent space, and results differ",
                        missing(has("NORMAL"), has("TANGENT"))
                    ),
                ));
            } else {
                out.push(Diagnostic::new(
                    &MESH_PRIMITIVE_NO_TANGENT_SPACE,
                    at,
                    format!(
                        "material {material}'s /materials/{material}{first} needs a tangent space, but this primitive has no {} and the material no normalTexture to generate it from",
                        missing(has("NORMAL"), has("TANGENT"))
                    ),
                ));
            }
        }
    }
}

/// Whether a texture is read in tangent space: a normal texture, or KHR_materials_anisotropy's
/// direction texture.
fn needs_tangents(texture: &super::extensions::MaterialTexture) -> bool {
    texture.normal || texture.pointer == super::materials::ANISOTROPY_TEXTURE
}

/// The attributes of a tangent space a primitive lacks, for messages.
fn missing(normal: bool, tangent: bool) -> &'static str {
    match (normal, tangent) {
        (false, false) => "NORMAL and TANGENT",
        (false, true) => "NORMAL",
        _ => "TANGENT",
    }
}
