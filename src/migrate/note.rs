//! What a migration says: the conversions done on a material, why a material was skipped, and
//! the notes that tell a user what changed in appearance or could not be carried over.
//!
//! Notes are values with their data (numbers, names), so tests compare them exactly and the
//! JSON output carries the numbers; [`Note::message`] words them for people, in one place.

use crate::output::paths::RelocationNote;
use serde::Serialize;
use serde_json::Value;

/// Differences below this share of the layer's reflectance (about 2.5 steps of an 8-bit
/// channel) are not reported as dark fuzz.
pub const DARK_FUZZ_THRESHOLD: f64 = 0.01;

/// Which texture a mapped roughness slot reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum TexturePlan {
    /// One mapped texture per source texture; the factor carries the material's difference.
    Shared,
    /// A mapped texture shared by materials of nearby factors.
    Grouped,
    /// A bake for this material alone.
    Exact,
}

impl TexturePlan {
    pub fn describe(self) -> &'static str {
        match self {
            TexturePlan::Shared => "the source's one mapped texture, the factor carrying the rest",
            TexturePlan::Grouped => "a mapped texture shared with materials of nearby factors",
            TexturePlan::Exact => "a texture baked for this material",
        }
    }
}

/// A conversion applied to one material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Conversion {
    /// Draft sheen (sheenFactor, sheenColor, sheenTexture) rewritten as ratified sheen.
    LegacyUpgrade,
    /// Ratified sheen kept as the fallback and KHR_materials_fuzz added.
    SheenToFuzz,
    /// Fuzz without sheen: a fallback KHR_materials_sheen added.
    FallbackSheen,
    /// Fuzz and sheen: the sheen regenerated from the fuzz (--refresh-fallback).
    RefreshedFallback,
}

impl Conversion {
    pub fn as_str(self) -> &'static str {
        match self {
            Conversion::LegacyUpgrade => "legacy sheen → ratified sheen",
            Conversion::SheenToFuzz => "sheen → fuzz",
            Conversion::FallbackSheen => "fuzz → fallback sheen",
            Conversion::RefreshedFallback => "fallback sheen refreshed",
        }
    }
}

/// Why a material with sheen or fuzz was left as it was.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Skip {
    /// sheenColorFactor is [0, 0, 0]: the sheen layer is off, there is nothing to carry.
    SheenOff,
    /// fuzzFactor is 0: the fuzz layer is off, no fallback is needed.
    FuzzOff,
    /// Fuzz and sheen are both there (use --refresh-fallback to regenerate the sheen).
    BothPresent,
    /// --refresh-fallback found the sheen already equal to what the fuzz gives.
    FallbackUpToDate,
    /// The material uses KHR_materials_unlit, which excludes both layers.
    Unlit,
    /// The material uses KHR_materials_pbrSpecularGlossiness, which excludes both layers.
    SpecularGlossiness,
    /// The fuzz colour is black: no sheen can stand for it (sheen only adds light).
    BlackFuzz,
    /// A layer's value is not a JSON object.
    Malformed,
}

impl Skip {
    pub fn as_str(self) -> &'static str {
        match self {
            Skip::SheenOff => "sheen switched off",
            Skip::FuzzOff => "fuzz switched off",
            Skip::BothPresent => "fuzz and sheen already present",
            Skip::FallbackUpToDate => "fallback sheen already up to date",
            Skip::Unlit => "uses KHR_materials_unlit",
            Skip::SpecularGlossiness => "uses KHR_materials_pbrSpecularGlossiness",
            Skip::BlackFuzz => "black fuzz, which no sheen can show",
            Skip::Malformed => "layer is not a JSON object",
        }
    }
}

/// How much a note matters: `Warning` when appearance or data is not carried over exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    Info,
    Warning,
}

/// One thing a user should know about a material's or a file's migration.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "code", rename_all = "kebab-case")]
pub enum Note {
    /// The sheen layer is off; no fuzz is added.
    SheenOff,
    /// The fuzz layer is off; no fallback is added.
    FuzzOff,
    /// Both layers present and --refresh-fallback not given.
    BothPresent,
    /// --refresh-fallback: the sheen already is what the fuzz gives.
    FallbackUpToDate,
    /// Excluded by unlit or specular-glossiness.
    Excluded { extension: String },
    /// The layer is not a JSON object.
    Malformed { extension: String },
    /// Fast mode: the sheen colour texture became the fuzz colour texture as it is.
    ColorTextureAsIs { w: f64 },
    /// --report: the attenuation difference of fast mode, measured over the texture's texels.
    AttenuationMeasured {
        image: usize,
        texels: u64,
        w: f64,
        max: f64,
        mean: f64,
    },
    /// --report: how far the fuzz layer's base attenuation is from the sheen layer's, over
    /// view angles, at the material's factors (1 − max3·E against 1 − w·R).
    LayerDifference {
        mapping: &'static str,
        sheen_roughness: f64,
        fuzz_roughness: f64,
        max_difference: f64,
        at_mu: f64,
        /// max over μ of |max3(sheenColor)·E(μ, r) − w·R(μ, α)|.
        reflectance_max: f64,
        /// Its cosine-weighted rms over μ.
        reflectance_rms: f64,
        /// r < 0.1, where no fuzz roughness matches the sheen well.
        poor_match: bool,
        fuzz_model: String,
        clamped: u64,
    },
    /// --fast: a roughness texture keeps the identity mapping instead of a baked mapped one.
    RoughnessTextureFast { mapping: &'static str },
    /// The roughness texture could not be baked through the mapping: the identity is used.
    RoughnessNotMapped { reason: String },
    /// --report: the measurement could not be made.
    MeasureFailed { reason: String },
    /// Fuzz lies over a clear coat where sheen lay under it.
    ClearcoatOrder { fallback: bool },
    /// fuzzRoughnessFactor absent: the table default was used for the fallback.
    FuzzRoughnessDefault { assumed: f64 },
    /// A fuzz texture could not be baked into the sheen colour texture.
    FuzzTextureNotBaked { texture: String, reason: String },
    /// The fallback's sheen colour texture is baked from the fuzz textures.
    FallbackTextureBaked { sources: String },
    /// --exact: fuzzTexture and fuzzColorTexture are baked from the sheen colour texture.
    ExactBaked,
    /// --exact could not bake: the fast mode was used for this material.
    ExactNotBaked { reason: String },
    /// A baked texture's largest difference from the exact f64 value, in codes.
    BakeError {
        pointer: String,
        image: String,
        max_codes: f64,
        clamped: u64,
    },
    /// fuzzTexture and fuzzColorTexture cannot be combined into one texture.
    FuzzTexturesIncompatible { reason: String },
    /// Black fuzz on an active layer: a fallback sheen would be switched off.
    BlackFuzz,
    /// Dark fuzz over a bright base: the fallback sheen only adds light.
    DarkFuzz {
        difference: f64,
        fuzz_color_max: f64,
        base_color_max: f64,
    },
    /// Legacy sheenColor × sheenFactor left [0, 1] and was clamped.
    LegacyClamped {
        product: [f64; 3],
        clamped: [f64; 3],
    },
    /// Legacy sheen roughness followed a metallicRoughnessTexture (green), which could not be
    /// baked into the alpha channel a sheen roughness texture reads.
    LegacyRoughnessTexture { texture: Value, reason: String },
    /// Legacy sheen roughness followed a metallicRoughnessTexture: its green channel (times
    /// roughnessFactor) is baked into the alpha of a new sheenRoughnessTexture.
    LegacyRoughnessBaked { roughness_factor: f64 },
    /// Legacy sheenTexture's intensity (alpha) is not applied by sheenColorTexture.
    LegacyTextureIntensity,
    /// Legacy properties next to ratified ones: the ratified ones stand.
    LegacyMixed { properties: Vec<String> },
    /// A texture that could not be carried over.
    TextureDropped { property: String, reason: String },
    /// Relative URIs rewritten so that the output finds the input's resources.
    UrisRewritten { count: usize, leaves_folder: bool },
    /// Resources copied next to the output.
    ResourcesCopied { count: usize },
    /// A resource to copy is missing; its URI is left as it was.
    ResourceMissing { uri: String },
    /// The texture plan of a mapped roughness texture, with its measured worst-case error.
    RoughnessPlan {
        property: String,
        plan: TexturePlan,
        factor_key: String,
        factor: f64,
        max_error: f64,
        /// `None`: the exact setting.
        budget: Option<f64>,
    },
    /// The material as written looks visibly different from the material as authored (the
    /// plan's verdict is "visible"); `remedy` is the run that would bring it to a better label,
    /// when one would, and `tried` the flags measured.
    VisibleDifference {
        verdict: super::verdict::Verdict,
        remedy: Option<super::verdict::Remedy>,
        tried: Vec<String>,
        /// The remedy was not taken by default: its new textures pass the size budget.
        #[serde(skip_serializing_if = "Option::is_none")]
        beyond_budget: Option<super::verdict::BeyondBudget>,
    },
    /// The default took a plan with more bakes (what `flags` would plan) because it brings a
    /// "visible" material to a better verdict, within the size budget.
    CloserPlanTaken {
        flags: String,
        /// The verdict of the plan it replaced.
        before: super::verdict::Verdict,
        after: super::verdict::Verdict,
        /// The new textures' uncompressed size, in bytes.
        bytes: u64,
    },
    /// The best roughness lies below the floor renderers honour alike: the floor is written.
    RoughnessFloor {
        property: String,
        best: f64,
        written: f64,
    },
}

impl From<RelocationNote> for Note {
    fn from(note: RelocationNote) -> Note {
        match note {
            RelocationNote::UrisRewritten {
                count,
                leaves_folder,
            } => Note::UrisRewritten {
                count,
                leaves_folder,
            },
            RelocationNote::ResourcesCopied { count } => Note::ResourcesCopied { count },
            RelocationNote::ResourceMissing { uri } => Note::ResourceMissing { uri },
        }
    }
}

fn rgb(c: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", c[0], c[1], c[2])
}

impl Note {
    pub fn level(&self) -> Level {
        match self {
            Note::SheenOff
            | Note::FuzzOff
            | Note::BothPresent
            | Note::FallbackUpToDate
            | Note::ColorTextureAsIs { .. }
            | Note::AttenuationMeasured { .. }
            | Note::LayerDifference { .. }
            | Note::RoughnessTextureFast { .. }
            | Note::ClearcoatOrder { .. }
            | Note::FuzzRoughnessDefault { .. }
            | Note::ResourcesCopied { .. }
            | Note::FallbackTextureBaked { .. }
            | Note::ExactBaked
            | Note::BakeError { .. }
            | Note::LegacyRoughnessBaked { .. }
            | Note::CloserPlanTaken { .. }
            | Note::RoughnessFloor { .. } => Level::Info,
            Note::RoughnessPlan {
                max_error, budget, ..
            } => {
                if budget.is_some_and(|b| *max_error > b) {
                    Level::Warning
                } else {
                    Level::Info
                }
            }
            Note::UrisRewritten { leaves_folder, .. } => {
                if *leaves_folder {
                    Level::Warning
                } else {
                    Level::Info
                }
            }
            Note::Excluded { .. }
            | Note::Malformed { .. }
            | Note::MeasureFailed { .. }
            | Note::FuzzTextureNotBaked { .. }
            | Note::ExactNotBaked { .. }
            | Note::RoughnessNotMapped { .. }
            | Note::FuzzTexturesIncompatible { .. }
            | Note::DarkFuzz { .. }
            | Note::BlackFuzz
            | Note::LegacyClamped { .. }
            | Note::LegacyRoughnessTexture { .. }
            | Note::LegacyTextureIntensity
            | Note::LegacyMixed { .. }
            | Note::TextureDropped { .. }
            | Note::VisibleDifference { .. }
            | Note::ResourceMissing { .. } => Level::Warning,
        }
    }

    pub fn message(&self) -> String {
        match self {
            Note::SheenOff => "sheenColorFactor is [0, 0, 0]: the sheen layer is off, so no fuzz is added".into(),
            Note::FuzzOff => "fuzzFactor is 0: the fuzz layer is off, so no fallback sheen is added".into(),
            Note::BothPresent => {
                "already has KHR_materials_fuzz and a KHR_materials_sheen fallback: left alone (--refresh-fallback regenerates the sheen from the fuzz)".into()
            }
            Note::FallbackUpToDate => "the sheen fallback already is what the fuzz gives: nothing to refresh".into(),
            Note::Excluded { extension } => {
                format!("uses {extension}, which excludes sheen and fuzz: not migrated (remove one or the other)")
            }
            Note::Malformed { extension } => format!("{extension} is not a JSON object: not migrated (`velvet validate` reports it)"),
            Note::ColorTextureAsIs { w } => format!(
                "sheenColorTexture became fuzzColorTexture as it is: the lobe colour is exact, but the base is now attenuated by fuzzFactor {w:?} instead of the per-texel maximum of the sheen colour (--report measures the difference)"
            ),
            Note::AttenuationMeasured { image, texels, w, max, mean } => format!(
                "attenuation difference |{w:?} − max3(sheenColor)| over the {texels} texels of image {image}: max {max:.4}, mean {mean:.4}; {}",
                if *max <= DARK_FUZZ_THRESHOLD {
                    format!("within {} everywhere, not visible", DARK_FUZZ_THRESHOLD)
                } else {
                    format!("{:.4} over {} at worst (--exact bakes it away)", max - DARK_FUZZ_THRESHOLD, DARK_FUZZ_THRESHOLD)
                }
            ),
            Note::LayerDifference { mapping, sheen_roughness, fuzz_roughness, max_difference, at_mu, reflectance_max, reflectance_rms, poor_match, fuzz_model, clamped } => {
                let mut m = format!(
                    "layer difference ({mapping} roughness mapping, sheen {sheen_roughness:.4} → fuzz {fuzz_roughness:.4}, {fuzz_model}): |max3·E − w·R| over view angles max {reflectance_max:.4}, cosine-weighted rms {reflectance_rms:.4}; base attenuation differs by at most {max_difference:.4}, at view cosine {at_mu:.3}"
                );
                if *poor_match {
                    m += &format!("; a poor match: below sheen roughness {} no fuzz roughness matches a sheen well", crate::shading::mapping::POOR_MATCH_BELOW);
                } else {
                    m += "; the closest fuzz the fitted mapping finds (see docs/shading.md for its bounds)";
                }
                if *clamped > 0 {
                    m += &format!(" ({clamped} attenuations clamped at 0 where the albedo exceeds 1)");
                }
                m
            }
            Note::RoughnessTextureFast { mapping } => format!(
                "--fast: the roughness texture is carried as it is, so this material's roughness is copied (identity) instead of mapped ({mapping}), which would bake a new texture"
            ),
            Note::RoughnessNotMapped { reason } => format!(
                "the roughness texture cannot be baked through the roughness mapping ({reason}): it is carried as it is and the roughness copied (identity)"
            ),
            Note::MeasureFailed { reason } => format!("the attenuation difference could not be measured: {reason}"),
            Note::ClearcoatOrder { fallback: false } => {
                "the material has KHR_materials_clearcoat: the fuzz lies over the coat, while the sheen lay under it; the look changes where the coat is strong".into()
            }
            Note::ClearcoatOrder { fallback: true } => {
                "the material has KHR_materials_clearcoat: the fallback sheen lies under the coat, while the fuzz lies over it; the look differs where the coat is strong".into()
            }
            Note::FuzzRoughnessDefault { assumed } => format!(
                "fuzzRoughnessFactor is absent: the fallback uses the draft's table default {assumed:?} (its schema says {:?}); the fuzz is left as it is",
                crate::layers::FUZZ_ROUGHNESS_DEFAULT_SCHEMA
            ),
            Note::FuzzTextureNotBaked { texture, reason } => format!(
                "{texture} cannot be baked into the sheen colour texture (fuzzColor × fuzzIntensity): {reason}; the fallback sheen uses the factors instead"
            ),
            Note::FallbackTextureBaked { sources } => format!(
                "the fallback's sheenColorTexture is baked from {sources} (fuzzColor × fuzzIntensity, per texel) and sheenColorFactor is [1.0, 1.0, 1.0]"
            ),
            Note::ExactBaked => {
                "--exact: fuzzTexture (per-texel max3 of the linear sheen colour) and a normalised fuzzColorTexture are baked from sheenColorTexture, so lobe and base attenuation match texel by texel up to quantisation; fuzzFactor and fuzzColorFactor are the identity".into()
            }
            Note::ExactNotBaked { reason } => format!(
                "--exact cannot bake this material's textures ({reason}): sheenColorTexture became fuzzColorTexture as it is (the fast mode)"
            ),
            Note::BakeError { pointer, image, max_codes, clamped } => {
                let verdict = if *max_codes <= 0.5 + 1e-9 {
                    "within the half code rounding allows"
                } else {
                    "more than rounding alone (the texture is read through a curve or resampled)"
                };
                let mut m = format!("{pointer}: {image} differs from the exact f64 result by at most {max_codes:.3} codes, {verdict}");
                if *clamped > 0 {
                    m += &format!("; {clamped} values clamped to the channel's range");
                }
                m
            }
            Note::FuzzTexturesIncompatible { reason } => format!(
                "fuzzTexture and fuzzColorTexture cannot be combined into one sheen colour texture ({reason}): the fallback sheen uses the factors instead"
            ),
            Note::DarkFuzz { difference, fuzz_color_max, base_color_max } => format!(
                "the fuzz blends the base towards its colour (brightest channel {fuzz_color_max:?}), which darkens a base whose brightest channel is {base_color_max:?}; sheen only adds light, so loaders without fuzz show it brighter by up to {difference:.4} of the layer's reflectance, over the {} velvet reports from (from the factors; textures can make it larger)",
                DARK_FUZZ_THRESHOLD
            ),
            Note::BlackFuzz => {
                "the fuzz colour is black: a sheen of that colour is switched off, so no sheen can stand for it; no fallback is written (loaders without fuzz show no layer)".into()
            }
            Note::LegacyClamped { product, clamped } => format!(
                "sheenColor × sheenFactor = {} lies outside [0, 1]: sheenColorFactor is clamped to {}",
                rgb(*product),
                rgb(*clamped)
            ),
            Note::LegacyRoughnessTexture { texture, reason } => format!(
                "the draft sheen's roughness followed the material's roughness, which reads the green channel of metallicRoughnessTexture {texture}; sheenRoughnessTexture reads alpha, and the texture cannot be baked ({reason}): sheenRoughnessFactor is the roughnessFactor alone"
            ),
            Note::LegacyRoughnessBaked { roughness_factor } => format!(
                "the draft sheen's roughness followed the material's roughness: the green channel of its metallicRoughnessTexture × roughnessFactor {roughness_factor:?} is baked into the alpha of a new sheenRoughnessTexture (sheenRoughnessFactor 1.0)"
            ),
            Note::LegacyTextureIntensity => {
                "sheenTexture became sheenColorTexture: its colour (RGB) is carried, but the draft's intensity in its alpha channel is not applied (that needs a bake)".into()
            }
            Note::LegacyMixed { properties } => format!(
                "draft properties ({}) sit next to ratified ones: ratified loaders use the ratified ones, so those are migrated and the draft ones are left as they are",
                properties.join(", ")
            ),
            Note::TextureDropped { property, reason } => format!("{property} is not carried over: {reason}"),
            Note::UrisRewritten { count, leaves_folder } => {
                let mut m = format!("{count} relative URI{} rewritten so that the output finds the input's resources", if *count == 1 { "" } else { "s" });
                if *leaves_folder {
                    m += "; they lead out of the output's folder, which velvet itself does not follow (without --rewrite-uris the output gets its own copies)";
                }
                m
            }
            Note::ResourcesCopied { count } => format!("{count} resource{} copied next to the output", if *count == 1 { "" } else { "s" }),
            Note::ResourceMissing { uri } => format!("resource '{uri}' does not exist: not copied, its URI is left as it was"),
            Note::RoughnessPlan { property, plan, factor_key, factor, max_error, budget } => {
                let verdict = match budget {
                    Some(b) if max_error <= b => format!("within the budget {b}"),
                    Some(b) => format!("{:.4} over the budget {b}: no plan comes closer than this exact bake", max_error - b),
                    None => "exact to the nearest code, as asked".to_string(),
                };
                format!(
                    "{property}: {}, {factor_key} {factor}; largest roughness difference from the exact mapping {max_error:.4}, {verdict}",
                    plan.describe()
                )
            }
            Note::CloserPlanTaken { flags, before, after, bytes } => format!(
                "the plan with more bakes that {flags} gives is taken, as it brings this material from {} to {}; its new textures take {} uncompressed, within the --closer-budget",
                before.describe(),
                after.describe(),
                crate::output::summary::bytes(*bytes as usize)
            ),
            Note::VisibleDifference { verdict, remedy, tried, beyond_budget } => {
                let mut m = format!(
                    "the migrated material looks visibly different from the authored one: ꟻLIP {:.3} in the furnace (above {}), {:.3} under the light",
                    verdict.furnace,
                    super::verdict::CLOSE_FLIP,
                    verdict.light
                );
                match (remedy, tried.is_empty()) {
                    (Some(r), _) => {
                        m += &format!("; {} would bring it to {}", r.flags, r.verdict.describe());
                        if let Some(b) = beyond_budget {
                            m += &format!(
                                ", but its new textures ({} uncompressed) pass what is left of the --closer-budget ({}), so the default does not take it",
                                crate::output::summary::bytes(b.bytes as usize),
                                crate::output::summary::bytes(b.left as usize)
                            );
                        }
                    }
                    (None, true) => m += "; no other plan velvet offers changes this material (no texture to bake): look at the preview before trusting it",
                    (None, false) => m += &format!(
                        "; {} {}: look at the preview before trusting it",
                        match tried.len() {
                            1 => tried[0].clone(),
                            _ => format!("neither {}", tried.join(" nor ")),
                        },
                        match tried.len() {
                            1 => "would not bring it closer",
                            _ => "would bring it closer",
                        }
                    ),
                }
                m
            }
            Note::RoughnessFloor { property, best, written } => format!(
                "{property}: the best match, {best:.4}, lies below {written} (the floor renderers honour alike), so {written} is written: {:.4} rougher than the best match",
                written - best
            ),
        }
    }

    /// The note as JSON: its code and data, with `level` and `message` added.
    pub fn to_json(&self) -> Value {
        let mut value = serde_json::to_value(self).expect("notes serialise");
        if let Value::Object(map) = &mut value {
            map.insert(
                "level".into(),
                serde_json::to_value(self.level()).expect("levels serialise"),
            );
            map.insert("message".into(), Value::String(self.message()));
        }
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn notes_serialise_with_code_data_level_and_message() {
        let note = Note::DarkFuzz {
            difference: 0.5,
            fuzz_color_max: 0.5,
            base_color_max: 1.0,
        };
        let v = note.to_json();
        assert_eq!(v["code"], "dark-fuzz");
        assert_eq!(v["level"], "warning");
        assert_eq!(v["difference"].as_f64(), Some(0.5));
        assert!(v["message"]
            .as_str()
            .unwrap()
            .contains("brighter by up to 0.5000"));
        assert_eq!(Note::SheenOff.to_json()["code"], "sheen-off");
    }
}
