//! Material properties and extensions that say nothing, or contradict one another, beyond what
//! their schemas say (the Khronos glTF-Validator's semantic checks, with its codes):
//!
//! - MATERIAL_ALPHA_CUTOFF_INVALID_MODE (warning): `alphaCutoff` on a material whose alphaMode
//!   is not MASK (the spec: "ignored for other modes"); at the cutoff.
//! - KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR (warning): an emissiveStrength where the
//!   emissive factor is zero or absent (its default is black).
//! - KHR_MATERIALS_VOLUME_NO_TRANSMISSION (warning): a volume without KHR_materials_transmission
//!   or KHR_materials_diffuse_transmission, through which light could enter it.
//! - KHR_MATERIALS_VOLUME_DOUBLE_SIDED (warning): a volume with a thickness on a double-sided
//!   material (the volume extension's spec: the material must not be double-sided).
//! - KHR_MATERIALS_DISPERSION_NO_VOLUME (warning): dispersion without a volume to act in.
//! - MULTIPLE_EXTENSIONS (warning): KHR_materials_unlit or KHR_materials_pbrSpecularGlossiness,
//!   which each define the whole material, beside another material extension; at each of them.
//! - KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD and
//!   KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD (warnings): a texture read in the
//!   normal texture's tangent space through another texture coordinate set.

use super::{materials, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const MATERIAL_ALPHA_CUTOFF_INVALID_MODE: Code = Code::new(
    "MATERIAL_ALPHA_CUTOFF_INVALID_MODE",
    Severity::Warning,
    "A material's alphaCutoff is ignored: its alphaMode is not MASK.",
)
.fixable(crate::diagnostics::Safety::Safe);
pub const KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR: Code = Code::new(
    "KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR",
    Severity::Warning,
    "KHR_materials_emissive_strength has no effect: the material's emissiveFactor is zero or undefined.",
);
pub const KHR_MATERIALS_VOLUME_NO_TRANSMISSION: Code = Code::new(
    "KHR_MATERIALS_VOLUME_NO_TRANSMISSION",
    Severity::Warning,
    "KHR_materials_volume without KHR_materials_transmission or KHR_materials_diffuse_transmission: no light enters the volume.",
);
pub const KHR_MATERIALS_VOLUME_DOUBLE_SIDED: Code = Code::new(
    "KHR_MATERIALS_VOLUME_DOUBLE_SIDED",
    Severity::Warning,
    "KHR_materials_volume on a double-sided material; a volume needs a closed, single-sided surface.",
);
pub const KHR_MATERIALS_DISPERSION_NO_VOLUME: Code = Code::new(
    "KHR_MATERIALS_DISPERSION_NO_VOLUME",
    Severity::Warning,
    "KHR_materials_dispersion without KHR_materials_volume: there is no volume to disperse light in.",
);
pub const KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD: Code = Code::new(
    "KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD",
    Severity::Warning,
    "A clearcoat normal texture reads another texture coordinate set than the normal texture; the two share one tangent space.",
);
pub const KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD: Code = Code::new(
    "KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD",
    Severity::Warning,
    "An anisotropy texture reads another texture coordinate set than the normal texture; the two share one tangent space.",
);
pub const MULTIPLE_EXTENSIONS: Code = Code::new(
    "MULTIPLE_EXTENSIONS",
    Severity::Warning,
    "KHR_materials_unlit or KHR_materials_pbrSpecularGlossiness beside another material extension, which it leaves without effect.",
);

/// The material extensions that each define the whole material.
const WHOLE_MATERIAL: [&str; 2] = ["KHR_materials_unlit", "KHR_materials_pbrSpecularGlossiness"];

pub struct Materials;

impl Rule for Materials {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &MATERIAL_ALPHA_CUTOFF_INVALID_MODE,
            &KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR,
            &KHR_MATERIALS_VOLUME_NO_TRANSMISSION,
            &KHR_MATERIALS_VOLUME_DOUBLE_SIDED,
            &KHR_MATERIALS_DISPERSION_NO_VOLUME,
            &MULTIPLE_EXTENSIONS,
            &KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD,
            &KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        tangent_space_sets(cx, out);
        for (i, material) in materials(cx.json()).enumerate() {
            if !material.is_object() {
                continue;
            }
            // Written only for a finding: most materials have none.
            let at = || format!("/materials/{i}");
            if material.get("alphaCutoff").is_some()
                && !material.get("alphaMode").is_some_and(|m| m.is_str("MASK"))
            {
                out.push(Diagnostic::new(
                    &MATERIAL_ALPHA_CUTOFF_INVALID_MODE,
                    format!("{}/alphaCutoff", at()),
                    "alphaCutoff is ignored: the alphaMode is not MASK",
                ));
            }
            let Some(extensions) = material.get("extensions").and_then(|e| e.as_object()) else {
                continue;
            };
            let has = |name: &str| extensions.contains_key(name);
            let ext_at = |name: &str| format!("{}/extensions/{name}", at());
            // An emissiveStrength that is absent (its default, 1) or out of range (the
            // schema's finding) is left alone, as the Khronos validator leaves it.
            let strength = extensions
                .get("KHR_materials_emissive_strength")
                .and_then(|e| e.get("emissiveStrength"))
                .and_then(|s| s.as_f64())
                .filter(|s| *s >= 0.0);
            if strength.is_some() && is_black(material.get("emissiveFactor")) {
                out.push(Diagnostic::new(
                    &KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR,
                    ext_at("KHR_materials_emissive_strength"),
                    "emissiveStrength has no effect: emissiveFactor is zero or undefined",
                ));
            }
            if has("KHR_materials_volume") {
                // Any extension that says it transmits light counts: a vendor's may let it in.
                if !extensions.keys().any(|k| k.contains("transmission")) {
                    out.push(Diagnostic::new(
                        &KHR_MATERIALS_VOLUME_NO_TRANSMISSION,
                        ext_at("KHR_materials_volume"),
                        "the volume has no KHR_materials_transmission or KHR_materials_diffuse_transmission to let light in",
                    ));
                }
                // A volume of thickness 0 (the default) is thin-walled: it needs no closed
                // surface, and the Khronos validator says nothing of it.
                let thickness = extensions
                    .get("KHR_materials_volume")
                    .and_then(|v| v.get("thicknessFactor"))
                    .and_then(|t| t.as_f64())
                    .unwrap_or(0.0);
                if thickness > 0.0
                    && material.get("doubleSided").and_then(|d| d.as_bool()) == Some(true)
                {
                    out.push(Diagnostic::new(
                        &KHR_MATERIALS_VOLUME_DOUBLE_SIDED,
                        ext_at("KHR_materials_volume"),
                        "a volume on a double-sided material: the volume needs a single-sided surface",
                    ));
                }
            }
            if has("KHR_materials_dispersion") && !has("KHR_materials_volume") {
                out.push(Diagnostic::new(
                    &KHR_MATERIALS_DISPERSION_NO_VOLUME,
                    ext_at("KHR_materials_dispersion"),
                    "dispersion needs KHR_materials_volume",
                ));
            }
            let material_extensions = extensions
                .keys()
                .filter(|k| k.starts_with("KHR_materials_"))
                .count();
            for whole in WHOLE_MATERIAL {
                if has(whole) && material_extensions > 1 {
                    out.push(Diagnostic::new(
                        &MULTIPLE_EXTENSIONS,
                        ext_at(whole),
                        format!("{whole} defines the whole material; the other material extensions beside it have no effect"),
                    ));
                }
            }
        }
    }
}

/// The textures read in the normal texture's tangent space, each with its code.
/// KHR_materials_anisotropy's direction texture, read in the normal texture's tangent space.
pub const ANISOTROPY_TEXTURE: &str = "/extensions/KHR_materials_anisotropy/anisotropyTexture";

const TANGENT_SPACE_TEXTURES: [(&str, &Code); 2] = [
    (
        "/extensions/KHR_materials_clearcoat/clearcoatNormalTexture",
        &KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD,
    ),
    (
        ANISOTROPY_TEXTURE,
        &KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD,
    ),
];

/// Textures that share the normal texture's tangent space but read another texture
/// coordinate set (KHR_texture_transform's `texCoord` counted).
fn tangent_space_sets(cx: &Context, out: &mut Vec<Diagnostic>) {
    for (m, textures) in cx.material_textures().iter().enumerate() {
        let set_of = |pointer: &str| {
            textures
                .iter()
                .find(|t| t.pointer == pointer)
                .map(|t| t.set)
        };
        let Some(normal) = set_of("/normalTexture") else {
            continue;
        };
        for (pointer, code) in TANGENT_SPACE_TEXTURES {
            if let Some(set) = set_of(pointer).filter(|set| *set != normal) {
                out.push(Diagnostic::new(
                    code,
                    format!("/materials/{m}{pointer}"),
                    format!("the texture reads TEXCOORD_{set}, the normal texture TEXCOORD_{normal}; they share one tangent space"),
                ));
            }
        }
    }
}

/// Whether an emissiveFactor is black: absent (its default) or all zeros.
fn is_black(factor: Option<Node>) -> bool {
    match factor.and_then(|f| f.as_array()) {
        None => factor.is_none(),
        Some(values) => values.iter().all(|v| v.as_f64() == Some(0.0)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Materials, text)
    }

    #[test]
    fn textures_sharing_the_tangent_space_read_the_normal_textures_set() {
        let text = r#"{"asset":{"version":"2.0"},"textures":[{}],"materials":[
            {"normalTexture":{"index":0},"extensions":{
                "KHR_materials_clearcoat":{"clearcoatNormalTexture":{"index":0,"texCoord":1}},
                "KHR_materials_anisotropy":{"anisotropyTexture":{"index":0,"texCoord":1,
                    "extensions":{"KHR_texture_transform":{"texCoord":0}}}}}},
            {"normalTexture":{"index":0},"extensions":{
                "KHR_materials_anisotropy":{"anisotropyTexture":{"index":0,"texCoord":1}}}}]}"#;
        assert_eq!(
            found(text),
            [
                "KHR_MATERIALS_CLEARCOAT_CLEARCOAT_NORMAL_TEXTURE_TEXCOORD /materials/0/extensions/KHR_materials_clearcoat/clearcoatNormalTexture",
                "KHR_MATERIALS_ANISOTROPY_ANISOTROPY_TEXTURE_TEXCOORD /materials/1/extensions/KHR_materials_anisotropy/anisotropyTexture"
            ]
        );
    }

    #[test]
    fn contradicting_material_properties_are_found() {
        let text = r#"{"asset":{"version":"2.0"},"materials":[
            {"alphaCutoff":0.5},
            {"alphaMode":"MASK","alphaCutoff":0.5,"emissiveFactor":[1,0,0],
             "extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":2}}},
            {"emissiveFactor":[0,0,0],"doubleSided":true,
             "extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":3},"KHR_materials_volume":{"thicknessFactor":1},"KHR_materials_unlit":{}}},
            {"doubleSided":true,"extensions":{"KHR_materials_emissive_strength":{},"KHR_materials_volume":{},"EXT_transmission_x":{}}},
            {"extensions":{"KHR_materials_dispersion":{},"KHR_materials_transmission":{}}}]}"#;
        assert_eq!(
            found(text),
            [
                "MATERIAL_ALPHA_CUTOFF_INVALID_MODE /materials/0/alphaCutoff",
                "KHR_MATERIALS_EMISSIVE_STRENGTH_ZERO_FACTOR /materials/2/extensions/KHR_materials_emissive_strength",
                "KHR_MATERIALS_VOLUME_NO_TRANSMISSION /materials/2/extensions/KHR_materials_volume",
                "KHR_MATERIALS_VOLUME_DOUBLE_SIDED /materials/2/extensions/KHR_materials_volume",
                "MULTIPLE_EXTENSIONS /materials/2/extensions/KHR_materials_unlit",
                "KHR_MATERIALS_DISPERSION_NO_VOLUME /materials/4/extensions/KHR_materials_dispersion",
            ]
        );
    }
}
