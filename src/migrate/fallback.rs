//! Fuzz → a fallback KHR_materials_sheen for loaders without fuzz (and, with
//! `--refresh-fallback`, the same sheen regenerated where one is already there).
//!
//! sheenColorFactor = fuzzColorFactor × fuzzFactor (what the fuzz lobe shows);
//! sheenRoughnessFactor comes from fuzzRoughnessFactor through [`roughness::map`], or from the
//! draft table's default 0.5 when the fuzz leaves it out (said so). A fuzz colour texture alone
//! is carried as the sheen colour texture (both sRGB, both scaled by the factor: exact); a fuzz
//! roughness texture likewise (both alpha). A fuzz intensity texture is baked into the colour:
//! the new sheenColorTexture holds fuzzColorFactor × fuzzFactor × fuzzColorTexture ×
//! fuzzTexture.r per texel (sheenColorFactor the identity). When the two textures use different
//! texCoord sets or transforms they cannot be combined, and when an image cannot be baked
//! (unreadable, KTX2): the colour falls back to the factors, reported.
//!
//! Sheen only adds light, while fuzz blends towards its colour: dark fuzz over a bright base
//! darkens it, which no sheen can show. Per unit of layer reflectance the fallback is brighter
//! by fuzzFactor × (1 − max3(fuzzColor)) × max3(baseColor); that is reported when it exceeds
//! [`DARK_FUZZ_THRESHOLD`]. Black fuzz would give a switched-off sheen, which is no fallback
//! (and contradicts the active fuzz): none is written, said so.

use super::material::{number_like, MaterialCx, MaterialPlan};
use super::note::{Conversion, Note, Skip};
use super::roughness::{self, Direction, RoughnessMapping};
use super::textures::{self, texture_index, Contents, TextureBake};
use crate::asset::pointer;
use crate::bake::Channel;
use crate::document::effective_tex_coord;
use crate::edit::Edit;
use crate::layers::{self, max3, FuzzView};
use serde_json::{Map, Value};

pub use super::note::DARK_FUZZ_THRESHOLD;

/// The properties a fallback sheen has, in the spec's order; refreshing sets or removes each.
const SHEEN_PROPERTIES: [&str; 4] = [
    "sheenColorFactor",
    "sheenColorTexture",
    "sheenRoughnessFactor",
    "sheenRoughnessTexture",
];

/// `value` written with the text of the first of `originals` that already holds it.
fn number_from(originals: &[Option<&Value>], value: f64) -> Value {
    originals
        .iter()
        .flatten()
        .find(|v| v.as_f64() == Some(value))
        .map_or_else(|| number_like(None, value), |v| (*v).clone())
}

/// Why two textureInfos cannot be combined texel by texel into one texture, if they cannot.
fn incompatible(a: &Value, b: &Value) -> Option<String> {
    let (set_a, set_b) = (effective_tex_coord(a), effective_tex_coord(b));
    if set_a != set_b {
        return Some(format!("texCoord {set_a} and {set_b}"));
    }
    let transform = |t: &Value| {
        t.pointer(&format!("/extensions/{}", layers::TEXTURE_TRANSFORM))
            .cloned()
    };
    if !same_json(
        &transform(a).unwrap_or(Value::Null),
        &transform(b).unwrap_or(Value::Null),
    ) {
        return Some(format!("different {} values", layers::TEXTURE_TRANSFORM));
    }
    None
}

/// Relative difference under which two numbers count as the same value: the rounding of the
/// divisions and products a round trip sheen → fuzz → sheen makes (a few ulps), far below
/// anything visible.
const SAME_VALUE_TOLERANCE: f64 = 1e-12;

/// JSON equality where numbers compare by value (1 equals 1.0, and values within
/// `SAME_VALUE_TOLERANCE` of each other are equal), so that refreshing a fallback made by
/// velvet itself finds it up to date.
pub fn same_json(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => match (x.as_f64(), y.as_f64()) {
            (Some(x), Some(y)) => {
                (x - y).abs() <= SAME_VALUE_TOLERANCE * x.abs().max(y.abs()).max(1.0)
            }
            _ => x == y,
        },
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same_json(x, y))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len()
                && x.iter()
                    .all(|(k, v)| y.get(k).is_some_and(|w| same_json(v, w)))
        }
        _ => a == b,
    }
}

/// The sheen that stands for `fuzz` on `cx`'s material, what the user should know, and the
/// textures to bake for it.
pub fn sheen_for(
    cx: &MaterialCx,
    fuzz: &Value,
) -> (Map<String, Value>, Vec<Note>, Vec<TextureBake>) {
    let view = FuzzView::read(fuzz).expect("the planner passes objects only");
    let mut notes = Vec::new();
    let factor_raw = fuzz.get("fuzzFactor");
    let color_raw = fuzz.get("fuzzColorFactor").and_then(Value::as_array);
    let color: Vec<Value> = (0..3)
        .map(|i| {
            let value = (view.color_factor[i] * view.factor).clamp(0.0, 1.0);
            number_from(&[color_raw.and_then(|c| c.get(i)), factor_raw], value)
        })
        .collect();
    let roughness_raw = fuzz
        .get("fuzzRoughnessFactor")
        .filter(|v| v.as_f64().is_some());
    if view.roughness_factor.is_none() {
        notes.push(Note::FuzzRoughnessDefault {
            assumed: layers::FUZZ_ROUGHNESS_DEFAULT_TABLE,
        });
    }
    // A fuzz roughness texture can be carried as it is only with the identity; with the
    // fitted mapping the fallback gets a baked one holding r(factor × texel) (factor 1).
    let fuzz_roughness = view.roughness_or_table_default();
    let roughness_texture = fuzz.get("fuzzRoughnessTexture").filter(|v| v.is_object());
    let mut mapping = cx.options.roughness;
    let mut roughness_bakes = Vec::new();
    if let (Some(texture), false) = (roughness_texture, mapping == RoughnessMapping::Identity) {
        if cx.options.fast {
            notes.push(Note::RoughnessTextureFast {
                mapping: mapping.name(),
            });
            mapping = RoughnessMapping::Identity;
        } else {
            match cx.texture_bake(
                layers::SHEEN,
                "sheenRoughnessTexture",
                "sheenRoughnessFactor",
                vec![fuzz_roughness],
                texture,
                Contents::Roughness {
                    channel: Channel::A,
                    factor: fuzz_roughness,
                    curve: Some(roughness::curve(Direction::FuzzToSheen, mapping)),
                },
            ) {
                Ok(bake) => roughness_bakes.push(bake),
                Err(reason) => {
                    notes.push(Note::RoughnessNotMapped { reason });
                    mapping = RoughnessMapping::Identity;
                }
            }
        }
    }
    let best = roughness::map(fuzz_roughness, Direction::FuzzToSheen, mapping);
    let roughness = roughness::written(best);
    if roughness_bakes.is_empty() && best < roughness::ROUGHNESS_FLOOR {
        notes.push(Note::RoughnessFloor {
            property: "sheenRoughnessFactor".into(),
            best,
            written: roughness,
        });
    }

    let mut sheen = Map::new();
    sheen.insert("sheenColorFactor".into(), Value::Array(color));
    let intensity_texture = fuzz.get("fuzzTexture").filter(|v| v.is_object());
    let color_texture = fuzz.get("fuzzColorTexture").filter(|v| v.is_object());
    let mut bakes = roughness_bakes;
    // The colour the lobe shows, which a baked texture holds in place of the factor.
    let lobe: [f64; 3] = std::array::from_fn(|i| view.color_factor[i] * view.factor);
    let mut bake_colour = |template: &Value, contents, what: &str, notes: &mut Vec<Note>| match cx
        .texture_bake(
            layers::SHEEN,
            "sheenColorTexture",
            "sheenColorFactor",
            lobe.to_vec(),
            template,
            contents,
        ) {
        Ok(bake) => {
            bakes.push(bake);
            notes.push(Note::FallbackTextureBaked {
                sources: what.into(),
            });
            true
        }
        Err(reason) => {
            notes.push(Note::FuzzTextureNotBaked {
                texture: what.into(),
                reason,
            });
            false
        }
    };
    match (intensity_texture, color_texture) {
        (None, Some(texture)) => {
            sheen.insert("sheenColorTexture".into(), texture.clone());
        }
        (Some(intensity), None) => {
            if bake_colour(
                intensity,
                Contents::IntensityAsColor { color: lobe },
                "fuzzTexture",
                &mut notes,
            ) {
                sheen.insert("sheenColorTexture".into(), intensity.clone());
            }
        }
        (Some(intensity), Some(colour)) => match incompatible(intensity, colour) {
            Some(reason) => notes.push(Note::FuzzTexturesIncompatible { reason }),
            None => {
                let intensity_image = texture_index(intensity)
                    .ok_or_else(|| "fuzzTexture has no valid index".to_string())
                    .and_then(|t| textures::sources(cx.asset, t))
                    .and_then(|sources| match sources.as_slice() {
                        [(_, image)] => Ok(*image),
                        _ => Err("fuzzTexture has more than one source image".to_string()),
                    });
                let what = "fuzzColorTexture × fuzzTexture";
                match intensity_image {
                    Ok(intensity_image) => {
                        if bake_colour(
                            colour,
                            Contents::ColorTimesIntensity {
                                color: lobe,
                                intensity_image,
                            },
                            what,
                            &mut notes,
                        ) {
                            sheen.insert("sheenColorTexture".into(), colour.clone());
                        }
                    }
                    Err(reason) => notes.push(Note::FuzzTextureNotBaked {
                        texture: what.into(),
                        reason,
                    }),
                }
            }
        },
        (None, None) => {}
    }
    sheen.insert(
        "sheenRoughnessFactor".into(),
        number_like(roughness_raw, roughness),
    );
    if let Some(texture) = fuzz.get("fuzzRoughnessTexture").filter(|v| v.is_object()) {
        sheen.insert("sheenRoughnessTexture".into(), texture.clone());
    }

    if cx.has_extension(layers::CLEARCOAT) {
        notes.push(Note::ClearcoatOrder { fallback: true });
    }
    if view.is_on() {
        let base = cx
            .material
            .pointer("/pbrMetallicRoughness/baseColorFactor")
            .and_then(|a| a.as_array())
            .filter(|a| a.len() == 4)
            .and_then(|a| {
                Some([
                    a.get(0)?.as_f64()?,
                    a.get(1)?.as_f64()?,
                    a.get(2)?.as_f64()?,
                ])
            })
            .unwrap_or([1.0; 3]);
        let (fuzz_max, base_max) = (max3(view.color_factor), max3(base));
        let difference = view.factor * (1.0 - fuzz_max).max(0.0) * base_max;
        if difference > DARK_FUZZ_THRESHOLD {
            notes.push(Note::DarkFuzz {
                difference,
                fuzz_color_max: fuzz_max,
                base_color_max: base_max,
            });
        }
    }
    (sheen, notes, bakes)
}

/// True when a sheen with these properties is switched off (sheenColorFactor all zero).
fn switched_off(sheen: &Map<String, Value>) -> bool {
    sheen["sheenColorFactor"]
        .as_array()
        .is_some_and(|c| c.iter().all(|v| v.as_f64() == Some(0.0)))
}

/// Adds a fallback sheen to a material that has fuzz only.
pub fn add(cx: &MaterialCx, fuzz: &Value, plan: &mut MaterialPlan) {
    if !FuzzView::read(fuzz).is_some_and(|f| f.is_on()) {
        plan.skip(Skip::FuzzOff, Note::FuzzOff);
        return;
    }
    let (sheen, notes, bakes) = sheen_for(cx, fuzz);
    if switched_off(&sheen) {
        // A switched-off sheen next to an active fuzz is no fallback, and contradicts it: no
        // sheen is written, so nothing is baked for it either.
        plan.notes.extend(
            notes
                .into_iter()
                .filter(|n| !matches!(n, Note::FallbackTextureBaked { .. })),
        );
        plan.skip(Skip::BlackFuzz, Note::BlackFuzz);
        return;
    }
    plan.notes.extend(notes);
    plan.bakes.extend(bakes);
    plan.edits.push(Edit::set(
        cx.extension_pointer(layers::SHEEN),
        Value::Object(sheen),
    ));
    plan.conversions.push(Conversion::FallbackSheen);
}

/// Regenerates the sheen of a material that has both: each property is set when it differs
/// and removed when the fuzz gives none; the sheen's other members (extras, extensions) stay.
pub fn refresh(cx: &MaterialCx, sheen: &Value, fuzz: &Value, plan: &mut MaterialPlan) {
    let (target, notes, bakes) = sheen_for(cx, fuzz);
    plan.notes.extend(notes);
    if switched_off(&target) && FuzzView::read(fuzz).is_some_and(|f| f.is_on()) {
        plan.skip(Skip::BlackFuzz, Note::BlackFuzz);
        return;
    }
    let base = cx.extension_pointer(layers::SHEEN);
    let mut edits = Vec::new();
    for property in crate::layers::legacy_properties(sheen) {
        edits.push(Edit::remove(pointer::join(&base, property)));
    }
    for property in SHEEN_PROPERTIES {
        // An absent factor stands for its default: a sheen that leaves out a roughness of 0
        // already says what the fuzz gives.
        let default = match property {
            "sheenColorFactor" => Some(serde_json::json!(layers::SHEEN_COLOR_DEFAULT)),
            "sheenRoughnessFactor" => Some(serde_json::json!(layers::SHEEN_ROUGHNESS_DEFAULT)),
            _ => None,
        };
        let now = sheen.get(property).cloned().or(default);
        match (now.as_ref(), target.get(property)) {
            (Some(now), Some(wanted)) if same_json(now, wanted) => {}
            (_, Some(wanted)) => {
                edits.push(Edit::set(pointer::join(&base, property), wanted.clone()))
            }
            // Only textures are ever absent from the target, and they have no default.
            (Some(_), None) => edits.push(Edit::remove(pointer::join(&base, property))),
            (None, None) => {}
        }
    }
    if edits.is_empty() {
        plan.skip(Skip::FallbackUpToDate, Note::FallbackUpToDate);
    } else {
        plan.edits.extend(edits);
        plan.bakes.extend(bakes);
        plan.conversions.push(Conversion::RefreshedFallback);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn numbers_compare_by_value_and_objects_ignore_key_order() {
        let a: Value = serde_json::from_str(r#"{"x":[1,0.50],"y":{"k":2}}"#).unwrap();
        let b: Value = serde_json::from_str(r#"{"y":{"k":2.0},"x":[1.0,0.5]}"#).unwrap();
        assert!(same_json(&a, &b));
        assert!(!same_json(&a, &json!({"x": [1, 0.5], "y": {"k": 3}})));
        assert!(!same_json(&json!([1, 2]), &json!([1, 2, 3])));
        // A round trip through fuzz: 0.45 / 0.72 × 0.72 is 0.44999999999999996.
        assert_eq!(0.45 / 0.72 * 0.72, 0.449_999_999_999_999_96);
        assert!(same_json(&json!(0.45 / 0.72 * 0.72), &json!(0.45)));
        assert!(!same_json(&json!(0.1), &json!(0.1 + 1e-9)));
    }

    #[test]
    fn textures_combine_only_with_the_same_set_and_transform() {
        let plain = json!({"index": 0});
        let set1 = json!({"index": 1, "texCoord": 1});
        let moved =
            json!({"index": 1, "extensions": {"KHR_texture_transform": {"offset": [0.5, 0]}}});
        let moved_to_set1 =
            json!({"index": 1, "extensions": {"KHR_texture_transform": {"texCoord": 1}}});
        assert_eq!(
            incompatible(&plain, &json!({"index": 3, "texCoord": 0})),
            None
        );
        assert_eq!(
            incompatible(&plain, &set1).as_deref(),
            Some("texCoord 0 and 1")
        );
        assert_eq!(
            incompatible(&plain, &moved).as_deref(),
            Some("different KHR_texture_transform values")
        );
        // The transform's texCoord overrides the textureInfo's.
        assert_eq!(
            incompatible(&plain, &moved_to_set1).as_deref(),
            Some("texCoord 0 and 1")
        );
    }
}
