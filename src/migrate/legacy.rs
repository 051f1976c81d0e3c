//! The pre-ratification sheen draft → ratified sheen, before it goes on to fuzz.
//!
//! The draft had sheenFactor (default 1), sheenColor (default white) and sheenTexture (colour
//! and intensity), and took the sheen roughness from the material's roughness. So:
//! sheenColorFactor = sheenColor × sheenFactor, clamped to [0, 1] (reported when clamped);
//! sheenRoughnessFactor = pbrMetallicRoughness.roughnessFactor (default 1); sheenTexture →
//! sheenColorTexture (its RGB; the alpha intensity would need a bake, reported). A material
//! roughness that comes from a metallicRoughnessTexture lives in its green channel, where the
//! ratified sheen reads alpha: green × roughnessFactor is baked into the alpha of a new
//! sheenRoughnessTexture (the other channels kept), or, where the image cannot be baked, the
//! factor stands alone (reported).
//!
//! A draft object that also holds ratified properties is not rewritten: ratified loaders read
//! the ratified ones, and those are what gets migrated.

use super::material::{number_like, texture_unusable, MaterialCx, MaterialPlan};
use super::material::{Read, Sheen};
use super::note::{Conversion, Note};
use super::textures::Contents;
use crate::asset::pointer;
use crate::bake::Channel;
use crate::edit::Edit;
use crate::layers;
use serde_json::Value;

const RATIFIED_PROPERTIES: [&str; 4] = [
    "sheenColorFactor",
    "sheenColorTexture",
    "sheenRoughnessFactor",
    "sheenRoughnessTexture",
];

pub use crate::layers::legacy_properties;

fn rgb(value: Option<&Value>) -> Option<[f64; 3]> {
    match value?.as_array()?.as_slice() {
        [r, g, b] => Some([r.as_f64()?, g.as_f64()?, b.as_f64()?]),
        _ => None,
    }
}

/// Upgrades a draft sheen on `cx`'s material: pushes the edits and notes to `plan` and returns
/// the ratified sheen it becomes. `None` when there is nothing to upgrade (no draft property,
/// or ratified ones beside them).
pub fn upgrade(cx: &MaterialCx, sheen: &Value, plan: &mut MaterialPlan) -> Option<Sheen<'static>> {
    let legacy = legacy_properties(sheen);
    if legacy.is_empty() {
        return None;
    }
    if RATIFIED_PROPERTIES.iter().any(|p| sheen.get(p).is_some()) {
        plan.notes.push(Note::LegacyMixed {
            properties: legacy.iter().map(|p| p.to_string()).collect(),
        });
        return None;
    }
    let base = cx.extension_pointer(layers::SHEEN);
    let factor_value = sheen.get("sheenFactor").filter(|v| v.as_f64().is_some());
    let factor = factor_value.and_then(Value::as_f64).unwrap_or(1.0);
    let color_raw = sheen.get("sheenColor").filter(|v| rgb(Some(v)).is_some());
    let color = rgb(color_raw).unwrap_or([1.0; 3]);
    let product: [f64; 3] = std::array::from_fn(|i| color[i] * factor);
    let clamped: [f64; 3] = std::array::from_fn(|i| product[i].clamp(0.0, 1.0));
    if clamped != product {
        plan.notes.push(Note::LegacyClamped { product, clamped });
    }
    let color_values: [Value; 3] = std::array::from_fn(|i| {
        // The draft's own numbers when sheenFactor leaves them as they are.
        let original = color_raw.and_then(|c| c.get(i)).or(if color_raw.is_none() {
            factor_value
        } else {
            None
        });
        number_like(original, clamped[i])
    });

    let pbr = cx
        .material
        .get("pbrMetallicRoughness")
        .map(|p| p.to_value());
    let pbr = pbr.as_ref();
    let roughness_raw = pbr
        .and_then(|p| p.get("roughnessFactor"))
        .filter(|v| v.as_f64().is_some());
    let roughness = roughness_raw.and_then(Value::as_f64).unwrap_or(1.0);
    let mut roughness_texture = None;
    if let Some(texture) = pbr.and_then(|p| p.get("metallicRoughnessTexture")) {
        let bake = cx.texture_bake(
            layers::SHEEN,
            "sheenRoughnessTexture",
            "sheenRoughnessFactor",
            vec![roughness],
            texture,
            Contents::Roughness {
                channel: Channel::G,
                factor: roughness,
                curve: None,
            },
        );
        match bake {
            Ok(bake) => {
                plan.bakes.push(bake);
                plan.notes.push(Note::LegacyRoughnessBaked {
                    roughness_factor: roughness,
                });
                roughness_texture = Some(texture.clone());
            }
            Err(reason) => plan.notes.push(Note::LegacyRoughnessTexture {
                texture: texture.clone(),
                reason,
            }),
        }
    }

    let mut color_texture = None;
    if let Some(texture) = sheen.get("sheenTexture") {
        let problem = if texture.is_object() {
            texture_unusable(cx, texture)
        } else {
            Some("it is not a textureInfo object".to_string())
        };
        match problem {
            None => {
                color_texture = Some(texture.clone());
                plan.notes.push(Note::LegacyTextureIntensity);
            }
            Some(reason) => plan.notes.push(Note::TextureDropped {
                property: "sheenTexture".into(),
                reason,
            }),
        }
    }

    for property in &legacy {
        plan.edits
            .push(Edit::remove(pointer::join(&base, property)));
    }
    let roughness_value = number_like(roughness_raw, roughness);
    plan.edits.push(Edit::set(
        pointer::join(&base, "sheenColorFactor"),
        Value::Array(color_values.to_vec()),
    ));
    if let Some(texture) = &color_texture {
        plan.edits.push(Edit::set(
            pointer::join(&base, "sheenColorTexture"),
            texture.clone(),
        ));
    }
    plan.edits.push(Edit::set(
        pointer::join(&base, "sheenRoughnessFactor"),
        roughness_value.clone(),
    ));
    if let Some(texture) = &roughness_texture {
        plan.edits.push(Edit::set(
            pointer::join(&base, "sheenRoughnessTexture"),
            texture.clone(),
        ));
    }
    let upgraded = Sheen {
        color: clamped,
        color_values: color_values.map(Read::Value),
        roughness,
        roughness_value: Read::Value(roughness_value),
        color_texture: color_texture.map(Read::Value),
        roughness_texture: roughness_texture.map(Read::Value),
        roughness_channel: Channel::G,
    };
    plan.conversions.push(Conversion::LegacyUpgrade);
    Some(upgraded)
}
