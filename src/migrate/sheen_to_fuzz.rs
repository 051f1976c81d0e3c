//! Ratified sheen → fuzz, keeping the sheen unchanged as the fallback for loaders without fuzz.
//!
//! Sheen's colour is both the lobe's colour and its strength: the base is attenuated by
//! max3(sheenColor). Fuzz separates the two, so with w = max3(sheenColorFactor):
//! fuzzFactor = w and fuzzColorFactor = sheenColorFactor / w give the same lobe colour
//! (fuzzColor · w = sheenColor) and the same attenuation. w = 0 is a switched-off sheen: nothing
//! is added. fuzzRoughnessFactor is always written (the draft's default is ambiguous) and comes
//! from [`roughness::map`]. The roughness texture is carried as it is (both read alpha); a
//! draft sheen's, which lived in the green channel of metallicRoughness, is baked into alpha.
//!
//! A sheen colour texture becomes the fuzz colour texture as it is (fast mode): the lobe stays
//! exact texel by texel, but the attenuation now follows w, not the per-texel maximum of the
//! sheen colour. `--report` measures that difference by decoding the texture. `--exact` bakes
//! instead a fuzzTexture holding the per-texel max3 of the linear sheen colour and a
//! fuzzColorTexture holding the colour normalised by it (factors become the identity), so lobe
//! and attenuation both match texel by texel up to quantisation, which is reported.

use super::material::{MaterialCx, MaterialPlan};
use super::measure;
use super::note::{Conversion, Note, Skip};
use super::roughness::{self, Direction, RoughnessMapping};
use super::textures::{Contents, TextureBake};
use crate::asset::json_text::push_quoted;
use crate::bake::Channel;
use crate::edit::Edit;
use crate::layers::{self, max3};
use crate::shading::layering;
use serde_json::Value;

pub use super::material::{Read, Sheen, SheenSource};

/// The KHR_materials_fuzz object that stands for `sheen`, as compact text
/// ([`write_compact`](crate::edit::splice::write_compact)), or `None` when the sheen is off. Keys follow the draft's parameter
/// table. With `strength_texture`, the fuzzTexture slot reads it (the exact mode, whose bake
/// fills it).
pub fn fuzz_for(
    sheen: &Sheen,
    strength_texture: Option<&Read>,
    mapping: RoughnessMapping,
) -> Option<String> {
    let w = max3(sheen.color);
    if !w.is_finite() || w <= 0.0 {
        return None;
    }
    let strongest = (0..3)
        .find(|i| sheen.color[*i] == w)
        .expect("w is one of the components");
    // Written as text as it is made: no object is built, and a plan keeps the text (a
    // library's 20,000 fuzz objects as values took a third of its migration's memory).
    let mut fuzz = String::with_capacity(192);
    fuzz.push('{');
    let key = |fuzz: &mut String, key: &str| {
        if fuzz.len() > 1 {
            fuzz.push(',');
        }
        push_quoted(fuzz, key);
        fuzz.push(':');
    };
    key(&mut fuzz, "fuzzFactor");
    sheen.color_values[strongest].write_compact(&mut fuzz);
    if let Some(texture) = strength_texture {
        key(&mut fuzz, "fuzzTexture");
        texture.write_compact(&mut fuzz);
    }
    key(&mut fuzz, "fuzzColorFactor");
    fuzz.push('[');
    for i in 0..3 {
        if i > 0 {
            fuzz.push(',');
        }
        let normalised = sheen.color[i] / w;
        push_number_like(
            &sheen.color_values[i],
            sheen.color[i],
            normalised,
            &mut fuzz,
        );
    }
    fuzz.push(']');
    if let Some(texture) = &sheen.color_texture {
        key(&mut fuzz, "fuzzColorTexture");
        texture.write_compact(&mut fuzz);
    }
    let r = roughness::written(roughness::map(
        sheen.roughness,
        Direction::SheenToFuzz,
        mapping,
    ));
    key(&mut fuzz, "fuzzRoughnessFactor");
    push_number_like(&sheen.roughness_value, sheen.roughness, r, &mut fuzz);
    if let Some(texture) = &sheen.roughness_texture {
        key(&mut fuzz, "fuzzRoughnessTexture");
        texture.write_compact(&mut fuzz);
    }
    fuzz.push('}');
    Some(fuzz)
}

/// Writes, as [`crate::edit::splice::write_compact`] writes it, `original` when it reads as `value` (its text kept,
/// as velvet writes it), else `value` rounded; `original` reads as `reads_as`.
fn push_number_like(original: &Read, reads_as: f64, value: f64, out: &mut String) {
    if reads_as == value {
        original.write_compact(out);
    } else {
        crate::edit::splice::push_written_f64(value, out);
    }
}

/// The bakes of the exact mode: fuzzTexture = max3 of the linear sheen colour, fuzzColorTexture
/// = the sheen colour normalised by it, both from the sheen colour texture.
fn exact_bakes(
    cx: &MaterialCx,
    sheen: &Sheen,
    texture: &Value,
) -> Result<Vec<TextureBake>, String> {
    let w = max3(sheen.color);
    let strength = cx.texture_bake(
        layers::FUZZ,
        "fuzzTexture",
        "fuzzFactor",
        vec![w],
        texture,
        Contents::SheenStrength { color: sheen.color },
    )?;
    let colour = cx.texture_bake(
        layers::FUZZ,
        "fuzzColorTexture",
        "fuzzColorFactor",
        sheen.color.iter().map(|c| c / w).collect(),
        texture,
        Contents::SheenNormalised { color: sheen.color },
    )?;
    Ok(vec![strength, colour])
}

/// Adds the fuzz that stands for `sheen` to the material, with its notes.
pub fn convert(cx: &MaterialCx, sheen: &Sheen, plan: &mut MaterialPlan) {
    let w = max3(sheen.color);
    if !w.is_finite() || w <= 0.0 {
        plan.skip(Skip::SheenOff, Note::SheenOff);
        return;
    }
    let mut exact = None;
    if let (true, Some(texture)) = (cx.options.exact, &sheen.color_texture) {
        match exact_bakes(cx, sheen, &texture.to_value()) {
            Ok(bakes) => exact = Some(bakes),
            Err(reason) => plan.notes.push(Note::ExactNotBaked { reason }),
        }
    }
    // A roughness texture is carried as it is only when the mapping is the identity and it
    // holds roughness in alpha; otherwise the fuzz gets a baked one holding
    // mapping(factor × texel) in alpha (a draft sheen's green channel moves there too).
    let mut mapping = cx.options.roughness;
    let mut carried = std::borrow::Cow::Borrowed(sheen);
    let mut roughness_bake = None;
    if let Some(texture) = &sheen.roughness_texture {
        if mapping != RoughnessMapping::Identity && cx.options.fast {
            plan.notes.push(Note::RoughnessTextureFast {
                mapping: mapping.name(),
            });
            mapping = RoughnessMapping::Identity;
        }
        let alpha = sheen.roughness_channel == Channel::A;
        if !alpha || mapping != RoughnessMapping::Identity {
            let curve = (mapping != RoughnessMapping::Identity)
                .then(|| roughness::curve(Direction::SheenToFuzz, mapping));
            match cx.texture_bake(
                layers::FUZZ,
                "fuzzRoughnessTexture",
                "fuzzRoughnessFactor",
                vec![sheen.roughness],
                &texture.to_value(),
                Contents::Roughness {
                    channel: sheen.roughness_channel,
                    factor: sheen.roughness,
                    curve,
                },
            ) {
                Ok(bake) => roughness_bake = Some(bake),
                Err(reason) if alpha => {
                    // The texture can still be carried as it is, with the identity.
                    plan.notes.push(Note::RoughnessNotMapped { reason });
                    mapping = RoughnessMapping::Identity;
                }
                Err(reason) => {
                    plan.notes.push(Note::TextureDropped {
                        property: "fuzzRoughnessTexture".into(),
                        reason,
                    });
                    carried.to_mut().roughness_texture = None;
                }
            }
        }
    }
    let strength_texture = exact.as_ref().and(sheen.color_texture.as_ref());
    let Some(fuzz) = fuzz_for(&carried, strength_texture, mapping) else {
        plan.skip(Skip::SheenOff, Note::SheenOff);
        return;
    };
    plan.edits
        .push(Edit::set_text(cx.extension_pointer(layers::FUZZ), fuzz));
    plan.conversions.push(Conversion::SheenToFuzz);
    if cx.has_extension(layers::CLEARCOAT) {
        plan.notes.push(Note::ClearcoatOrder { fallback: false });
    }
    let best = roughness::map(sheen.roughness, Direction::SheenToFuzz, mapping);
    if roughness_bake.is_none() && best < roughness::ROUGHNESS_FLOOR {
        plan.notes.push(Note::RoughnessFloor {
            property: "fuzzRoughnessFactor".into(),
            best,
            written: roughness::ROUGHNESS_FLOOR,
        });
    }
    if let Some(bake) = roughness_bake {
        plan.bakes.push(bake);
    }
    if let Some(bakes) = exact {
        plan.bakes.extend(bakes);
        plan.notes.push(Note::ExactBaked);
    } else if let Some(texture) = &sheen.color_texture {
        plan.notes.push(Note::ColorTextureAsIs { w });
        if cx.options.report {
            plan.notes.push(
                match measure::attenuation(cx.asset, &texture.to_value(), sheen.color, w) {
                    Ok(m) => Note::AttenuationMeasured {
                        image: m.image,
                        texels: m.texels,
                        w,
                        max: m.max,
                        mean: m.mean,
                    },
                    Err(reason) => Note::MeasureFailed { reason },
                },
            );
        }
    }
    if cx.options.report {
        let fuzz_roughness = roughness::map(sheen.roughness, Direction::SheenToFuzz, mapping);
        let sheen_params = layering::SheenParams {
            color_max3: w,
            roughness: sheen.roughness,
        };
        let fuzz_params = layering::FuzzParams {
            weight: w,
            roughness: fuzz_roughness,
        };
        let comparison = layering::sheen_to_fuzz_attenuation_difference(sheen_params, fuzz_params);
        let matched = crate::shading::mapping::layer_match(sheen_params, fuzz_params);
        plan.notes.push(Note::LayerDifference {
            mapping: mapping.name(),
            sheen_roughness: sheen.roughness,
            fuzz_roughness,
            max_difference: comparison.max_difference,
            at_mu: comparison.at_mu,
            reflectance_max: matched.max,
            reflectance_rms: matched.rms,
            poor_match: matched.poor_match,
            fuzz_model: comparison.fuzz_reflectance,
            clamped: comparison.clamps.clamped,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn fuzz_text(sheen: Value) -> Option<String> {
        fuzz_for(&Sheen::read(&sheen), None, RoughnessMapping::Identity)
    }

    /// The fuzz object's text, read.
    fn fuzz_value(sheen: &Value) -> Value {
        let text = fuzz_for(&Sheen::read(sheen), None, RoughnessMapping::Identity).unwrap();
        serde_json::from_str(&text).unwrap()
    }

    #[test]
    fn colour_splits_into_strength_and_normalised_colour() {
        let sheen: Value = serde_json::from_str(
            r#"{"sheenColorFactor":[0.9,0.45,0],"sheenRoughnessFactor":0.25}"#,
        )
        .unwrap();
        assert_eq!(
            fuzz_text(sheen).unwrap(),
            r#"{"fuzzFactor":0.9,"fuzzColorFactor":[1.0,0.5,0],"fuzzRoughnessFactor":0.25}"#
        );
    }

    #[test]
    fn full_strength_keeps_the_colour_text_and_the_floored_roughness_default_is_written() {
        let sheen: Value = serde_json::from_str(r#"{"sheenColorFactor":[1,0,0.75]}"#).unwrap();
        assert_eq!(
            fuzz_text(sheen).unwrap(),
            r#"{"fuzzFactor":1,"fuzzColorFactor":[1,0,0.75],"fuzzRoughnessFactor":0.07}"#
        );
    }

    #[test]
    fn switched_off_sheen_gives_no_fuzz() {
        assert_eq!(
            fuzz_text(json!({"sheenColorFactor": [0.0, 0.0, 0.0], "sheenRoughnessFactor": 0.5})),
            None
        );
        assert_eq!(
            fuzz_text(json!({"sheenRoughnessFactor": 0.5})),
            None,
            "the default colour is black"
        );
    }

    #[test]
    fn textures_are_carried_with_their_extensions() {
        let tex = json!({"index": 2, "texCoord": 1, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0]}}});
        let sheen = json!({"sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": tex, "sheenRoughnessTexture": tex});
        let fuzz = fuzz_value(&sheen);
        assert_eq!(fuzz["fuzzColorTexture"], tex);
        assert_eq!(fuzz["fuzzRoughnessTexture"], tex);
        assert_eq!(
            fuzz.as_object().unwrap().keys().collect::<Vec<_>>(),
            [
                "fuzzFactor",
                "fuzzColorFactor",
                "fuzzColorTexture",
                "fuzzRoughnessFactor",
                "fuzzRoughnessTexture"
            ]
        );
    }

    #[test]
    fn lobe_colour_is_preserved_exactly_enough() {
        for c in [
            [0.9, 0.7, 0.6],
            [0.05, 0.17, 0.5],
            [1e-6, 0.0, 3e-7],
            [0.12, 0.12, 0.13],
        ] {
            let fuzz = fuzz_value(&json!({ "sheenColorFactor": c }));
            let w = fuzz["fuzzFactor"].as_f64().unwrap();
            for i in 0..3 {
                let colour = fuzz["fuzzColorFactor"][i].as_f64().unwrap();
                assert!(colour <= 1.0);
                // Both numbers are written to six decimals (`edit::splice::DECIMALS`), each
                // off by at most 5e-7, and neither above 1.
                assert!((colour * w - c[i]).abs() <= 1e-6, "{c:?}");
            }
        }
    }
}
