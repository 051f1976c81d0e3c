//! A fuzz layer and its sheen fallback should look alike. With both on one material, the fuzz
//! roughness that matches the sheen's look is α(sheenRoughnessFactor), velvet's fitted mapping
//! (`shading::mapping`: the fuzz roughness whose reflectance is closest to the sheen's albedo over
//! the view angle). A fuzzRoughnessFactor far from it means loaders with and without
//! KHR_materials_fuzz show differently darkened bases and differently wide lobes. Info, never
//! more: the difference may be wanted.
//!
//! Far means more than [`THRESHOLD`] = 0.1 in fuzz roughness. Moving α 0.1 away from α(r) raises
//! the cosine-weighted rms difference between the sheen's albedo and the fuzz's reflectance from
//! 0.010–0.017 to 0.056–0.075 for r from 0.25 to 1: three to six times the best achievable, and
//! the size of the error of copying the roughness number across at r = 0.25 (0.073); a test pins
//! these figures.
//!
//! Checked on factors, so only when neither layer has a roughness texture: with one, the
//! roughness is factor × texel, and the fitted mapping is not linear, so a mapped texture (as
//! `velvet migrate` bakes it, with factor 1) cannot be judged by its factor. Also only when both
//! layers are on (a switched-off layer is the fallback rule's business) and fuzzRoughnessFactor
//! is written (its default is ambiguous, which another rule reports).
//!
//! Example: sheen r = 0.25 with fuzz α = 0.25 triggers (α(0.25) = 0.391); with α = 0.39 it does
//! not.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;
use crate::shading::mapping::{
    fuzz_roughness_for_sheen, sheen_roughness_for_fuzz, POOR_MATCH_BELOW,
};

pub const FUZZ_ROUGHNESS_FAR_FROM_FALLBACK: Code = Code::new(
    "KHR_MATERIALS_FUZZ_ROUGHNESS_FAR_FROM_FALLBACK",
    Severity::Info,
    "fuzzRoughnessFactor is more than 0.1 from α(sheenRoughnessFactor), the fuzz roughness that matches the sheen fallback's look.",
);

/// How far fuzzRoughnessFactor may be from α(sheenRoughnessFactor) before the rule speaks.
pub const THRESHOLD: f64 = 0.1;

pub struct FuzzRoughnessMapping;

impl Rule for FuzzRoughnessMapping {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&FUZZ_ROUGHNESS_FAR_FROM_FALLBACK]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for pair in cx.material_layers() {
            let i = pair.material;
            let (Some(fuzz), Some(sheen)) = (pair.fuzz, pair.sheen) else {
                continue;
            };
            let Some(alpha) = fuzz.roughness_factor else {
                continue;
            };
            if !(fuzz.is_on() && sheen.is_on())
                || fuzz.roughness_texture.is_some()
                || sheen.roughness_texture.is_some()
            {
                continue;
            }
            let r = sheen.roughness_factor;
            let matching = fuzz_roughness_for_sheen(r);
            let distance = (alpha - matching).abs();
            if distance > THRESHOLD {
                let fuzz_pointer = format!("/materials/{i}/extensions/{}", layers::FUZZ);
                let reverse = sheen_roughness_for_fuzz(alpha);
                let other_way = if reverse < POOR_MATCH_BELOW {
                    "no sheen lobe matches a fuzz this smooth".to_string()
                } else {
                    format!("a fallback matching this fuzz has sheenRoughnessFactor {reverse:.3}")
                };
                out.push(Diagnostic::new(
                    &FUZZ_ROUGHNESS_FAR_FROM_FALLBACK,
                    pointer::join(&fuzz_pointer, "fuzzRoughnessFactor"),
                    format!(
                        "fuzzRoughnessFactor {alpha} is {distance:.3} from {matching:.3}, the fuzz roughness that matches the sheen fallback's sheenRoughnessFactor {r}; loaders with and without fuzz will show different lobes ({other_way})"
                    ),
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shading::mapping::mapping_rms;

    fn findings(doc: serde_json::Value) -> Vec<String> {
        let text = serde_json::to_string(&doc).unwrap();
        let loaded =
            crate::asset::load_bytes(std::path::Path::new("memory/rule.gltf"), text.as_bytes());
        let asset = loaded.asset.unwrap();
        let schemas = crate::rules::schema::Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let mut out = Vec::new();
        FuzzRoughnessMapping.check(&cx, &mut out);
        out.into_iter().map(|d| d.pointer).collect()
    }

    #[test]
    fn a_roughness_texture_on_either_layer_leaves_the_factors_unjudged() {
        let material = |fuzz_texture: bool, sheen_texture: bool| {
            let mut fuzz = serde_json::json!({"fuzzFactor": 1.0, "fuzzRoughnessFactor": 1.0});
            let mut sheen = serde_json::json!({"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.25});
            if fuzz_texture {
                fuzz["fuzzRoughnessTexture"] = serde_json::json!({"index": 0});
            }
            if sheen_texture {
                sheen["sheenRoughnessTexture"] = serde_json::json!({"index": 0});
            }
            serde_json::json!({
                "asset": {"version": "2.0"},
                "materials": [{"extensions": {"KHR_materials_fuzz": fuzz, "KHR_materials_sheen": sheen}}],
                "textures": [{"source": 0}],
                "images": [{"uri": "missing.png"}]
            })
        };
        assert_eq!(
            findings(material(false, false)),
            ["/materials/0/extensions/KHR_materials_fuzz/fuzzRoughnessFactor"]
        );
        for (f, s) in [(true, false), (false, true), (true, true)] {
            assert!(findings(material(f, s)).is_empty(), "{f} {s}");
        }
    }

    #[test]
    fn the_threshold_marks_a_several_fold_loss_of_match() {
        // rms at α(r), and at α(r) ± 0.1 (clamped to 1), for r from 0.25 to 1.
        for r in [0.25, 0.5, 0.75, 1.0] {
            let best = fuzz_roughness_for_sheen(r);
            let at = mapping_rms(r, best);
            assert!((0.009..0.018).contains(&at), "r = {r}: {at}");
            for alpha in [best - THRESHOLD, (best + THRESHOLD).min(1.0)] {
                let off = mapping_rms(r, alpha);
                assert!(
                    (0.055..0.076).contains(&off) && off > 3.0 * at,
                    "r = {r}, α = {alpha}: {off} vs {at}"
                );
            }
        }
    }
}
