//! One material as a contact sheet shows it: its base colour, its sheen and fuzz values at each
//! swatch (the factors, or with textures the texture's 5th percentile, mean and 95th
//! percentile), and the columns a sheet compares — the material as authored, as migrated and
//! as a loader without KHR_materials_fuzz sees it.
//!
//! What migrate produces is read from its plan ([`crate::migrate::plan_document`], with the
//! options of the run): the plan's edits applied to the material give the layers the migrated
//! file holds (factors as written: rounded, floored, settled by the bakes), and a slot the plan
//! bakes reads the bake's own recipe evaluated on the source texture. The sheet's first
//! migrated column is that file; the next one shows the other roughness mapping (fitted or
//! copied), computed from the same function migrate writes through
//! ([`roughness::written`] of [`roughness::map`]). A black fuzz gives no fallback, which shows
//! the base alone. A material with the pre-ratification sheen draft is shown as migrate
//! upgrades it (the plan's ratified sheen stands for it as authored).
//!
//! Textures: a readable texture (PNG, JPEG, WebP, decoded to 8 bits per channel) is reduced to
//! its mean and its 5th and 95th percentiles (nearest rank; a colour texture is ranked by the
//! largest of its channels, and the percentile's colour is the mean of the texels at that
//! rank), in linear values. Each textured slot enters a swatch at its own percentile.
//!
//! The base is glTF 2.0's metallic-roughness material (shaded as such in `shade.rs`): the
//! base colour is baseColorFactor times the base colour texture's mean, and metallic and
//! roughness are metallicFactor and roughnessFactor (default 1 and 1) times the means of the
//! metallicRoughnessTexture's blue and green channels (linear). The base's textures enter as
//! their means in every swatch. A texture that cannot be read leaves its factor, and a note says
//! so.

use crate::asset::Asset;
use crate::bake::recipe::{Channel, ChannelRecipe, ImageId, Texel};
use crate::layers::{self, Channels, FuzzView, SheenView, Slot, Transfer};
use crate::migrate::roughness::{self, Direction, RoughnessMapping};
use crate::migrate::textures::TextureBake;
use crate::migrate::{Conversion, DocumentPlan, MaterialPlan};
use crate::shading::layering::{max3, FuzzParams, SheenParams};
use rayon::prelude::*;
use serde_json::Value;
use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

use super::shade::{Layer, Look};

/// A sheen's values at one swatch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SheenValues {
    pub color: [f64; 3],
    pub roughness: f64,
}

/// A fuzz layer's values at one swatch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FuzzValues {
    pub weight: f64,
    pub color: [f64; 3],
    pub roughness: f64,
}

/// The material's values at one swatch.
#[derive(Clone, Debug, PartialEq)]
pub struct Swatch {
    /// "factors", "p5", "mean" or "p95".
    pub label: &'static str,
    /// The layers as authored.
    pub sheen: Option<SheenValues>,
    pub fuzz: Option<FuzzValues>,
    /// The layers of the migrated file, as a reader computes them from what the plan writes.
    pub written_sheen: Option<SheenValues>,
    pub written_fuzz: Option<FuzzValues>,
}

/// Which conversion the material's sheet shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A sheen without fuzz: migrate adds a fuzz layer and keeps the sheen as the fallback.
    SheenToFuzz,
    /// A fuzz without sheen: migrate adds a fallback sheen.
    FuzzFallback,
    /// Both layers: migrate leaves them; the sheet also shows what a refreshed fallback would be.
    FuzzWithSheen,
}

/// A material ready to be previewed.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub index: usize,
    pub name: Option<String>,
    pub kind: Kind,
    /// The base colour, linear.
    pub base: [f64; 3],
    /// The base's metallicFactor, times the metallic-roughness texture's mean (blue) when it is
    /// readable, in [0, 1].
    pub base_metallic: f64,
    /// The base's roughnessFactor, times the metallic-roughness texture's mean (green) when it
    /// is readable, in [0, 1].
    pub base_roughness: f64,
    /// The values at the factors alone (what the figures are computed at).
    pub factors: Swatch,
    /// The swatches drawn: the factors alone, or P5, MEAN and P95 when a layer is textured.
    pub swatches: Vec<Swatch>,
    /// What the sheet must say about the inputs (textures not read, defaults assumed).
    pub notes: Vec<String>,
    /// fuzzRoughnessFactor was absent: the table default 0.5 is used.
    pub fuzz_roughness_assumed: bool,
    /// `--fast` copied the roughness (a roughness texture it would have baked mapped): the
    /// migrated column's roughness is copied, whatever the run's mapping.
    pub roughness_copied_by_fast: bool,
    /// The roughness mapping of the run the plan was made for; the sheet's other column
    /// shows the other one.
    pub mapping: RoughnessMapping,
    /// The plan's verdict on it (`preview::verdict`), once measured: the sheet's label and the
    /// run's ranking.
    pub verdict: Option<crate::migrate::verdict::Verdict>,
}

impl Material {
    /// Everything the material's sheet is drawn from but its index and name, as text (an f64
    /// is written as the shortest decimal that reads back as it, so equal texts are equal
    /// values): materials with equal texts draw equal sheets, and share one.
    pub fn appearance(&self) -> String {
        format!(
            "{:?}",
            (
                self.kind,
                self.base,
                self.base_metallic,
                self.base_roughness,
                &self.factors,
                &self.swatches,
                &self.notes,
                self.fuzz_roughness_assumed,
                self.roughness_copied_by_fast,
                self.mapping
            )
        )
    }
}

/// One column of a sheet: a label of two lines and the look it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    pub title: String,
    pub detail: String,
    pub look: Look,
}

/// A texture reduced to three values (linear; 3 channels for colour slots, 1 otherwise).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureStats {
    pub p5: Vec<f64>,
    pub mean: Vec<f64>,
    pub p95: Vec<f64>,
}

/// The materials of `asset` that have or get a sheen or fuzz layer, in document order, with
/// what `plan` (the migration of `asset` with the run's options; `mapping` is theirs) writes.
/// Materials that use KHR_materials_unlit or KHR_materials_pbrSpecularGlossiness (which
/// exclude both layers, so migrate leaves them), and a switched-off sheen or fuzz alone (to
/// which migrate adds nothing), are left out.
pub fn materials(asset: &Asset, plan: &DocumentPlan, mapping: RoughnessMapping) -> Vec<Material> {
    materials_with(asset, plan, mapping, &ImageCache::default())
}

/// [`materials`], the images' statistics read through `images` (shared by the reads of one
/// document). Only the materials `plan` holds are read: the planner plans every material with
/// a sheen or fuzz layer, and a plan of some materials alone gives those.
pub(super) fn materials_with(
    asset: &Asset,
    plan: &DocumentPlan,
    mapping: RoughnessMapping,
    images: &ImageCache,
) -> Vec<Material> {
    // Each material is read from the document's index into a value of its own: the whole
    // document is not built (for the 20,000-material library, that would double migrate's
    // memory).
    let all = asset.root().get("materials");
    plan.materials
        .par_iter()
        .filter_map(|p| {
            let material = all?.get(p.index)?.to_value();
            read(asset, p.index, &material, Some(p), mapping, images)
        })
        .collect()
}

/// `material` (the material at `index`) with the edits of its plan applied: the material the
/// migrated file holds. Declarations and edits outside the material are left out.
fn migrated(material: &Value, index: usize, plan: &MaterialPlan) -> Result<Value, String> {
    let prefix = format!("/materials/{index}");
    let edits: Vec<crate::edit::Edit> = plan
        .edits
        .iter()
        .filter_map(|edit| {
            let pointer = match edit {
                crate::edit::Edit::Set { pointer, .. }
                | crate::edit::Edit::Replace { pointer, .. }
                | crate::edit::Edit::Remove { pointer } => pointer,
                crate::edit::Edit::DeclareUsed { .. } => return None,
            };
            let within = pointer.strip_prefix(&prefix)?;
            (within.starts_with('/')).then(|| edit.at(within))
        })
        .collect();
    let mut out = material.clone();
    crate::edit::apply(&mut out, &edits).map_err(|e| e.to_string())?;
    Ok(out)
}

/// Each image's statistics per way of reading it, computed once however many materials (on
/// however many threads) read it: the first to ask computes them, the others wait for them.
#[derive(Default)]
pub(super) struct ImageCache {
    stats: std::sync::Mutex<HashMap<(usize, Read, Transfer), StatsCell>>,
}

/// One image's statistics for one way of reading it, once computed.
type StatsCell = Arc<OnceLock<Result<TextureStats, String>>>;

fn read(
    asset: &Asset,
    index: usize,
    material: &Value,
    plan: Option<&MaterialPlan>,
    mapping: RoughnessMapping,
    images: &ImageCache,
) -> Option<Material> {
    let mut notes = Vec::new();
    let written = match plan.map(|p| migrated(material, index, p)) {
        Some(Ok(written)) => written,
        Some(Err(e)) => {
            notes.push(format!(
                "the plan could not be applied ({e}): shown unmigrated"
            ));
            material.clone()
        }
        None => material.clone(),
    };
    let layer = |json: &Value, name: &str| -> Option<Value> {
        layers::extensions(json)
            .and_then(|e| e.get(name))
            .filter(|v| v.is_object())
            .cloned()
    };
    if layer(material, layers::UNLIT).is_some() || layer(material, layers::SPEC_GLOSS).is_some() {
        return None;
    }
    // A draft sheen is shown as migrate upgrades it: the sheen of the migrated file.
    let legacy = plan.is_some_and(|p| p.conversions.contains(&Conversion::LegacyUpgrade));
    if legacy {
        notes.push(
            "the pre-ratification sheen draft is shown as migrate upgrades it to ratified sheen"
                .into(),
        );
    }
    let sheen_json = layer(if legacy { &written } else { material }, layers::SHEEN);
    let fuzz_json = layer(material, layers::FUZZ);
    let written_sheen_json = layer(&written, layers::SHEEN);
    let written_fuzz_json = layer(&written, layers::FUZZ);
    let sheen = sheen_json.as_ref().and_then(SheenView::read);
    let fuzz = fuzz_json.as_ref().and_then(FuzzView::read);
    let kind = match (&sheen, &fuzz) {
        (Some(_), Some(_)) => Kind::FuzzWithSheen,
        (None, Some(f)) if f.is_on() => Kind::FuzzFallback,
        (Some(s), None) if s.is_on() => Kind::SheenToFuzz,
        _ => return None,
    };
    let written_sheen = written_sheen_json.as_ref().and_then(SheenView::read);
    let written_fuzz = written_fuzz_json.as_ref().and_then(FuzzView::read);
    let name = material
        .get("name")
        .and_then(Value::as_str)
        .map(str::to_owned);

    // The base: baseColorFactor (linear) times the base colour texture's mean when readable.
    let pbr = material.get("pbrMetallicRoughness");
    let mut base = pbr
        .and_then(|p| p.get("baseColorFactor"))
        .and_then(Value::as_array)
        .and_then(|a| match a.as_slice() {
            [r, g, b, ..] => Some([r.as_f64()?, g.as_f64()?, b.as_f64()?]),
            _ => None,
        })
        .unwrap_or([1.0; 3])
        .map(|v| v.clamp(0.0, 1.0));
    if let Some(info) = pbr.and_then(|p| p.get("baseColorTexture")) {
        match texture_stats(asset, info, Channels::Rgb, Transfer::Srgb, images) {
            Ok(s) => base = std::array::from_fn(|k| base[k] * s.mean[k]),
            Err(e) => notes.push(format!(
                "baseColorTexture not read ({e}): the base is baseColorFactor alone"
            )),
        }
    }
    // metallicFactor and roughnessFactor (glTF 2.0 defaults 1 and 1) times the means of the
    // metallic-roughness texture's blue and green channels (linear) when readable.
    let factor = |key: &str| {
        pbr.and_then(|p| p.get(key))
            .and_then(Value::as_f64)
            .unwrap_or(1.0)
            .clamp(0.0, 1.0)
    };
    let mut base_metallic = factor("metallicFactor");
    let mut base_roughness = factor("roughnessFactor");
    if let Some(info) = pbr.and_then(|p| p.get("metallicRoughnessTexture")) {
        let channel_means = image_index(asset, info).and_then(|image| {
            let mean = |channel| {
                image_stats(asset, image, Read::One(channel), Transfer::Linear, images)
                    .map(|s| s.mean[0])
            };
            Ok((mean(2)?, mean(1)?))
        });
        match channel_means {
            Ok((metallic, roughness)) => {
                base_metallic *= metallic;
                base_roughness *= roughness;
            }
            Err(e) => notes.push(format!(
                "metallicRoughnessTexture not read ({e}): the base is metallicFactor and \
                 roughnessFactor alone"
            )),
        }
    }

    let fuzz_roughness_assumed = fuzz.as_ref().is_some_and(|f| f.roughness_factor.is_none());
    if fuzz_roughness_assumed {
        notes.push(format!(
            "fuzzRoughnessFactor absent: the draft's table default {} is used",
            layers::FUZZ_ROUGHNESS_DEFAULT_TABLE
        ));
    }

    // The layer textures, each reduced to three values: as authored, and as the migrated file
    // reads them (a slot the plan bakes through the bake's recipe on its source).
    let bakes: &[TextureBake] = plan.map_or(&[], |p| p.bakes.as_slice());
    let mut textured: Vec<(&'static Slot, TextureStats)> = Vec::new();
    let mut written_textured: Vec<(&'static Slot, TextureStats)> = Vec::new();
    // Each texture slot of the written layers, with the image it reads or is baked from.
    let mut written_slots: Vec<String> = Vec::new();
    for (json, extension, in_written, baked) in [
        (&sheen_json, layers::SHEEN, false, legacy),
        (&fuzz_json, layers::FUZZ, false, false),
        (&written_sheen_json, layers::SHEEN, true, true),
        (&written_fuzz_json, layers::FUZZ, true, true),
    ] {
        let Some(json) = json else { continue };
        for slot in layers::slots_of(extension) {
            let Some(info) = json.get(slot.texture) else {
                continue;
            };
            let bake = bakes
                .iter()
                .find(|b| baked && b.extension == extension && b.texture_key == slot.texture);
            if in_written {
                let read = info.get("index").and_then(|i| i.as_u64());
                written_slots.push(match bake {
                    Some(bake) => format!(
                        "{} baked from {}",
                        slot.texture,
                        image_of(asset, Some(bake.texture as u64))
                    ),
                    None => format!("{} {}", slot.texture, image_of(asset, read)),
                });
            }
            let stats = match bake {
                Some(bake) => baked_stats(asset, bake, slot, images),
                None => texture_stats(asset, info, slot.channels, slot.transfer, images),
            };
            match stats {
                Ok(s) if in_written => written_textured.push((slot, s)),
                Ok(s) => textured.push((slot, s)),
                Err(e) => {
                    let note = format!(
                        "{} not read ({e}): {} alone is used",
                        slot.texture, slot.factor
                    );
                    if !notes.contains(&note) {
                        notes.push(note);
                    }
                }
            }
        }
    }
    if !written_slots.is_empty() {
        notes.push(format!("textures as written: {}", written_slots.join("; ")));
    }
    let views = Views {
        sheen: sheen.as_ref(),
        fuzz: fuzz.as_ref(),
        written_sheen: written_sheen.as_ref(),
        written_fuzz: written_fuzz.as_ref(),
    };
    let at = |pick: fn(&TextureStats) -> &Vec<f64>, label: &'static str| {
        let value = |list: &[(&'static Slot, TextureStats)], slot: &Slot| -> Option<Vec<f64>> {
            list.iter()
                .find(|(s, _)| s.texture == slot.texture)
                .map(|(_, s)| pick(s).clone())
        };
        swatch_values(label, &views, &|slot| value(&textured, slot), &|slot| {
            value(&written_textured, slot)
        })
    };
    let factors = swatch_values("factors", &views, &|_| None, &|_| None);
    let swatches = if textured.is_empty() && written_textured.is_empty() {
        vec![factors.clone()]
    } else {
        vec![
            at(|s| &s.p5, "p5"),
            at(|s| &s.mean, "mean"),
            at(|s| &s.p95, "p95"),
        ]
    };
    Some(Material {
        index,
        name,
        kind,
        base,
        base_metallic,
        base_roughness,
        factors,
        swatches,
        notes,
        fuzz_roughness_assumed,
        roughness_copied_by_fast: plan.is_some_and(|p| {
            p.notes
                .iter()
                .any(|n| matches!(n, crate::migrate::Note::RoughnessTextureFast { .. }))
        }),
        mapping,
        verdict: None,
    })
}

/// How a sheet names the image texture `texture` reads: its URI (or name), or "image N" for
/// one in a buffer view, or "texture N" when the texture names no image.
fn image_of(asset: &Asset, texture: Option<u64>) -> String {
    let root = asset.root();
    let Some(t) = texture else {
        return "(no texture index)".to_string();
    };
    let pointer = format!("/textures/{t}");
    let Some(node) = root.pointer(&pointer) else {
        return format!("texture {t}");
    };
    let image = crate::document::texture_sources(node, &pointer)
        .into_iter()
        .find_map(|(image, _)| image);
    let Some(i) = image else {
        return format!("texture {t}");
    };
    let image_node = root.pointer(&format!("/images/{i}"));
    let named = |key: &str| {
        image_node
            .and_then(|n| n.get(key))
            .and_then(|v| v.as_str().map(|s| s.into_owned()))
    };
    match named("uri")
        .filter(|u| !u.starts_with("data:"))
        .or_else(|| named("name"))
    {
        Some(name) => format!("texture {t} ({name})"),
        None => format!("texture {t} (image {i})"),
    }
}

/// The four layer views a swatch reads.
struct Views<'a> {
    sheen: Option<&'a SheenView>,
    fuzz: Option<&'a FuzzView>,
    written_sheen: Option<&'a SheenView>,
    written_fuzz: Option<&'a FuzzView>,
}

/// What a baked slot reads, reduced to three values: the bake's recipe (the one the bake
/// engine runs) evaluated on the source images' values at each percentile. A recipe that
/// reads red, green and blue of its base reads them at the base's colour percentiles; any
/// other channel at that channel's own.
fn baked_stats(
    asset: &Asset,
    bake: &TextureBake,
    slot: &Slot,
    images: &ImageCache,
) -> Result<TextureStats, String> {
    let (_, base) = *bake
        .sources
        .first()
        .ok_or("the baked texture has no source image")?;
    let recipe = bake
        .contents
        .recipe(ImageId(base))
        .map_err(|e| e.to_string())?;
    let outputs: &[Channel] = match slot.channels {
        Channels::Rgb => &[Channel::R, Channel::G, Channel::B],
        Channels::Red => &[Channel::R],
        Channels::Alpha => &[Channel::A],
    };
    let channel_recipes: Vec<ChannelRecipe> = outputs.iter().map(|&c| recipe.resolved(c)).collect();
    let mut texels: Vec<Texel> = Vec::new();
    for r in &channel_recipes {
        match r {
            ChannelRecipe::Copy(image, channel) => texels.push(Texel {
                image: *image,
                channel: *channel,
                transfer: match slot.transfer {
                    Transfer::Srgb => crate::bake::Transfer::Srgb,
                    Transfer::Linear => crate::bake::Transfer::Linear,
                },
            }),
            ChannelRecipe::Computed { value, .. } => texels.extend(value.texels()),
        }
    }
    texels.sort();
    texels.dedup();
    let colour_of = |image: ImageId| {
        [Channel::R, Channel::G, Channel::B]
            .iter()
            .filter(|c| texels.iter().any(|t| t.image == image && t.channel == **c))
            .count()
            > 1
    };
    let mut read = Vec::with_capacity(texels.len());
    for t in &texels {
        let transfer = match t.transfer {
            crate::bake::Transfer::Srgb => Transfer::Srgb,
            crate::bake::Transfer::Linear => Transfer::Linear,
        };
        let (read_as, component) = if colour_of(t.image) && t.channel != Channel::A {
            (Read::Rgb, t.channel as usize)
        } else {
            (Read::One(t.channel as usize), 0)
        };
        read.push((
            *t,
            image_stats(asset, t.image.0, read_as, transfer, images)?,
            component,
        ));
    }
    let at = |pick: fn(&TextureStats) -> &Vec<f64>| -> Vec<f64> {
        let mut value_of = |texel: &Texel| {
            read.iter()
                .find(|(t, _, _)| t == texel)
                .map_or(0.0, |(_, s, k)| pick(s)[*k])
        };
        channel_recipes
            .iter()
            .map(|r| match r {
                ChannelRecipe::Copy(image, channel) => value_of(&Texel {
                    image: *image,
                    channel: *channel,
                    transfer: texels[0].transfer,
                }),
                ChannelRecipe::Computed { value, .. } => value.eval(&mut value_of).clamp(0.0, 1.0),
            })
            .collect()
    };
    Ok(TextureStats {
        p5: at(|s| &s.p5),
        mean: at(|s| &s.mean),
        p95: at(|s| &s.p95),
    })
}

/// The layers' values at one swatch: each factor times its texture's value there (`texel`
/// gives it for an authored slot and `written_texel` for a slot of the migrated file, `None`
/// when the slot has no readable texture).
fn swatch_values(
    label: &'static str,
    views: &Views,
    texel: &dyn Fn(&Slot) -> Option<Vec<f64>>,
    written_texel: &dyn Fn(&Slot) -> Option<Vec<f64>>,
) -> Swatch {
    let slot = |name: &str| {
        layers::SLOTS
            .iter()
            .find(|s| s.texture == name)
            .expect("a slot velvet knows")
    };
    let sheen_values = |s: &SheenView, texel: &dyn Fn(&Slot) -> Option<Vec<f64>>| {
        let scalar = |name: &str, factor: f64| texel(slot(name)).map_or(factor, |v| factor * v[0]);
        let color = |name: &str, factor: [f64; 3]| {
            texel(slot(name)).map_or(factor, |v| std::array::from_fn(|k| factor[k] * v[k]))
        };
        SheenValues {
            color: color("sheenColorTexture", s.color_factor),
            roughness: scalar("sheenRoughnessTexture", s.roughness_factor),
        }
    };
    let fuzz_values = |f: &FuzzView, texel: &dyn Fn(&Slot) -> Option<Vec<f64>>| {
        let scalar = |name: &str, factor: f64| texel(slot(name)).map_or(factor, |v| factor * v[0]);
        let color = |name: &str, factor: [f64; 3]| {
            texel(slot(name)).map_or(factor, |v| std::array::from_fn(|k| factor[k] * v[k]))
        };
        FuzzValues {
            weight: scalar("fuzzTexture", f.factor),
            color: color("fuzzColorTexture", f.color_factor),
            roughness: scalar("fuzzRoughnessTexture", f.roughness_or_table_default()),
        }
    };
    Swatch {
        label,
        sheen: views.sheen.map(|s| sheen_values(s, texel)),
        fuzz: views.fuzz.map(|f| fuzz_values(f, texel)),
        written_sheen: views.written_sheen.map(|s| sheen_values(s, written_texel)),
        written_fuzz: views.written_fuzz.map(|f| fuzz_values(f, written_texel)),
    }
}

/// The image a textureInfo's texture reads.
fn image_index(asset: &Asset, info: &Value) -> Result<usize, String> {
    let texture = info
        .get("index")
        .and_then(layers::as_index)
        .ok_or("no texture index")?;
    let source = asset
        .root()
        .pointer(&format!("/textures/{texture}/source"))
        .and_then(layers::as_index)
        .ok_or_else(|| format!("texture {texture} has no source image"))?;
    usize::try_from(source).map_err(|_| format!("image {source} does not exist"))
}

fn texture_stats(
    asset: &Asset,
    info: &Value,
    channels: Channels,
    transfer: Transfer,
    cache: &ImageCache,
) -> Result<TextureStats, String> {
    let image = image_index(asset, info)?;
    let read = match channels {
        Channels::Rgb => Read::Rgb,
        Channels::Red => Read::One(0),
        Channels::Alpha => Read::One(3),
    };
    image_stats(asset, image, read, transfer, cache)
}

/// Which values of an image a percentile ranks: its colour (by the largest channel), or one
/// channel (0 red … 3 alpha).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Read {
    Rgb,
    One(usize),
}

fn image_stats(
    asset: &Asset,
    image: usize,
    read: Read,
    transfer: Transfer,
    cache: &ImageCache,
) -> Result<TextureStats, String> {
    let cell = Arc::clone(
        cache
            .stats
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .entry((image, read, transfer))
            .or_default(),
    );
    cell.get_or_init(|| {
        // Nothing is decoded once the run is asked to stop.
        crate::output::interrupt::check()?;
        asset
            .decode_image_with(image, 1, 4, |img| stats_by(&img.to_rgba8(), read, transfer))
            .map_err(|d| d.message)
    })
    .clone()
}

/// The mean, 5th and 95th percentiles of the values a slot reads from `img` (see the module
/// comment), linear.
pub fn stats_of(img: &image::RgbaImage, channels: Channels, transfer: Transfer) -> TextureStats {
    let read = match channels {
        Channels::Rgb => Read::Rgb,
        Channels::Red => Read::One(0),
        Channels::Alpha => Read::One(3),
    };
    stats_by(img, read, transfer)
}

fn stats_by(img: &image::RgbaImage, read: Read, transfer: Transfer) -> TextureStats {
    let lin: [f64; 256] = std::array::from_fn(|c| transfer.to_linear(c as f64 / 255.0));
    let dims = if read == Read::Rgb { 3 } else { 1 };
    // Per rank (the largest channel's code, or the channel's code): texel count and sums.
    let mut count = [0u64; 256];
    let mut sums = vec![[0.0f64; 3]; 256];
    for (i, p) in img.pixels().enumerate() {
        // A stop (SIGINT, SIGTERM) ends a large image's pass early: the statistics are then
        // partial, and the callers, which check for the stop next, use none of them.
        if i % (1 << 16) == 0 && crate::output::interrupt::requested().is_some() {
            break;
        }
        let [r, g, b, a] = p.0;
        let (rank, values) = match read {
            Read::Rgb => (
                r.max(g).max(b),
                [lin[r as usize], lin[g as usize], lin[b as usize]],
            ),
            Read::One(k) => {
                let c = [r, g, b, a][k];
                (c, [lin[c as usize], 0.0, 0.0])
            }
        };
        count[rank as usize] += 1;
        for k in 0..3 {
            sums[rank as usize][k] += values[k];
        }
    }
    let total: u64 = count.iter().sum();
    if total == 0 {
        let one = vec![1.0; dims];
        return TextureStats {
            p5: one.clone(),
            mean: one.clone(),
            p95: one,
        };
    }
    let percentile = |q: f64| -> Vec<f64> {
        let need = ((q * total as f64).ceil() as u64).max(1);
        let mut seen = 0;
        for rank in 0..256 {
            seen += count[rank];
            if seen >= need {
                return (0..dims)
                    .map(|k| sums[rank][k] / count[rank] as f64)
                    .collect();
            }
        }
        unreachable!("the counts add up to the total")
    };
    let mean = (0..dims)
        .map(|k| sums.iter().map(|s| s[k]).sum::<f64>() / total as f64)
        .collect();
    TextureStats {
        p5: percentile(0.05),
        mean,
        p95: percentile(0.95),
    }
}

fn rough(x: f64) -> String {
    format!("{x:.3}")
}

/// The detail word for a roughness mapping.
fn mapping_word(mapping: RoughnessMapping) -> &'static str {
    match mapping {
        RoughnessMapping::Fitted => "fitted",
        RoughnessMapping::Identity => "copied",
    }
}

/// The mapping the sheet shows beside the run's.
fn other(mapping: RoughnessMapping) -> RoughnessMapping {
    match mapping {
        RoughnessMapping::Fitted => RoughnessMapping::Identity,
        RoughnessMapping::Identity => RoughnessMapping::Fitted,
    }
}

/// A roughness carried with `mapping` as migrate writes it (mapped, rounded, floored).
fn carried(roughness: f64, direction: Direction, mapping: RoughnessMapping) -> f64 {
    roughness::written(roughness::map(roughness, direction, mapping))
}

/// The columns of `material`'s sheet at one swatch: the material as authored first, then the
/// migrated file (the plan's values), the other roughness mapping, and what a loader without
/// KHR_materials_fuzz sees. Column 1 is the one the difference image and the verdict compare
/// with column 0.
pub fn columns(material: &Material, swatch: &Swatch) -> Vec<Column> {
    let (base, base_metallic, base_roughness) = (
        material.base,
        material.base_metallic,
        material.base_roughness,
    );
    let look = |layer| Look {
        base,
        base_metallic,
        base_roughness,
        layer,
    };
    let sheen_layer = |s: SheenValues| Layer::Sheen {
        color: s.color,
        roughness: s.roughness,
    };
    let fuzz_layer = |f: FuzzValues| Layer::Fuzz {
        color: f.color,
        weight: f.weight,
        roughness: f.roughness,
    };
    let mapping = material.mapping;
    match material.kind {
        Kind::SheenToFuzz => {
            let s = swatch.sheen.expect("a sheen material has sheen values");
            // Without a written fuzz (the plan could not be applied), the conversion's
            // factors: w = max3(sheenColorFactor), the colour divided by it.
            let w = max3(material.factors.sheen.expect("sheen").color).clamp(0.0, 1.0);
            let computed = |roughness| FuzzValues {
                weight: w,
                color: s.color.map(|c| if w > 0.0 { c / w } else { 0.0 }),
                roughness,
            };
            let migrated = swatch
                .written_fuzz
                .unwrap_or_else(|| computed(carried(s.roughness, Direction::SheenToFuzz, mapping)));
            let alternative = FuzzValues {
                roughness: carried(s.roughness, Direction::SheenToFuzz, other(mapping)),
                ..migrated
            };
            let kept = swatch.written_sheen.unwrap_or(s);
            vec![
                Column {
                    title: "authored: sheen".into(),
                    detail: format!("r {}", rough(s.roughness)),
                    look: look(sheen_layer(s)),
                },
                Column {
                    title: "migrated: fuzz".into(),
                    detail: match material.roughness_copied_by_fast {
                        true => format!("α {} copied (--fast)", rough(migrated.roughness)),
                        false => {
                            format!("α {} {}", rough(migrated.roughness), mapping_word(mapping))
                        }
                    },
                    look: look(fuzz_layer(migrated)),
                },
                Column {
                    title: format!("if {}: fuzz", mapping_word(other(mapping))),
                    detail: format!(
                        "α {} {}",
                        rough(alternative.roughness),
                        mapping_word(other(mapping))
                    ),
                    look: look(fuzz_layer(alternative)),
                },
                Column {
                    title: "no fuzz: sheen".into(),
                    detail: format!("kept, r {}", rough(kept.roughness)),
                    look: look(sheen_layer(kept)),
                },
            ]
        }
        Kind::FuzzFallback | Kind::FuzzWithSheen => {
            let f = swatch.fuzz.expect("a fuzz material has fuzz values");
            // The fallback's colour as migrate computes it; a black fuzz gets no fallback,
            // which shows as a switched-off sheen.
            let color = f
                .color
                .map(|c| (c * f.weight.clamp(0.0, 1.0)).clamp(0.0, 1.0));
            let fallback = |mapping| SheenValues {
                color,
                roughness: carried(f.roughness, Direction::FuzzToSheen, mapping),
            };
            let mut cols = vec![Column {
                title: "authored: fuzz".into(),
                detail: format!("α {}", rough(f.roughness)),
                look: look(fuzz_layer(f)),
            }];
            if material.kind == Kind::FuzzWithSheen {
                let in_file = swatch
                    .written_sheen
                    .or(swatch.sheen)
                    .expect("a material with both layers has sheen values");
                cols.push(Column {
                    title: "no fuzz: sheen".into(),
                    detail: format!("in file, r {}", rough(in_file.roughness)),
                    look: look(sheen_layer(in_file)),
                });
                for m in [mapping, other(mapping)] {
                    let s = fallback(m);
                    cols.push(Column {
                        title: "refreshed: sheen".into(),
                        detail: format!("r {} {}", rough(s.roughness), mapping_word(m)),
                        look: look(sheen_layer(s)),
                    });
                }
            } else {
                let migrated = swatch.written_sheen.unwrap_or_else(|| fallback(mapping));
                let alternative = SheenValues {
                    roughness: carried(f.roughness, Direction::FuzzToSheen, other(mapping)),
                    ..migrated
                };
                // A black fuzz gets no fallback: the column shows the base alone, and says so
                // rather than describe a sheen the file does not hold.
                let no_fallback = material.factors.written_sheen.is_none() && max3(color) <= 0.0;
                cols.push(Column {
                    title: "no fuzz: sheen".into(),
                    detail: match no_fallback {
                        true => "none written: base alone".into(),
                        false => {
                            format!("r {} {}", rough(migrated.roughness), mapping_word(mapping))
                        }
                    },
                    look: look(sheen_layer(migrated)),
                });
                cols.push(Column {
                    title: format!("if {}: sheen", mapping_word(other(mapping))),
                    detail: format!(
                        "r {} {}",
                        rough(alternative.roughness),
                        mapping_word(other(mapping))
                    ),
                    look: look(sheen_layer(alternative)),
                });
            }
            cols
        }
    }
}

/// A sheen layer and a fuzz layer of two columns, as the report's comparison takes them.
pub fn layer_pair(a: &Layer, b: &Layer) -> Option<(SheenParams, FuzzParams)> {
    let pair = |s: &Layer, f: &Layer| match (s, f) {
        (
            Layer::Sheen { color, roughness },
            Layer::Fuzz {
                weight,
                roughness: alpha,
                ..
            },
        ) => Some((
            SheenParams {
                color_max3: max3(*color),
                roughness: *roughness,
            },
            FuzzParams {
                weight: *weight,
                roughness: *alpha,
            },
        )),
        _ => None,
    };
    pair(a, b).or_else(|| pair(b, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: &[[u8; 4]]) -> image::RgbaImage {
        let mut img = image::RgbaImage::new(pixels.len() as u32, 1);
        for (i, p) in pixels.iter().enumerate() {
            img.put_pixel(i as u32, 0, image::Rgba(*p));
        }
        img
    }

    #[test]
    fn scalar_percentiles_are_nearest_rank_and_the_mean_is_exact() {
        // Alpha 0, 10, …, 190 (20 texels): p5 = the 1st value, p95 = the 19th.
        let px: Vec<[u8; 4]> = (0..20).map(|i| [0, 0, 0, (i * 10) as u8]).collect();
        let s = stats_of(&image(&px), Channels::Alpha, Transfer::Linear);
        assert_eq!(s.p5, vec![0.0]);
        assert_eq!(s.p95, vec![180.0 / 255.0]);
        assert!((s.mean[0] - 95.0 / 255.0).abs() < 1e-12);
    }

    #[test]
    fn colour_percentiles_rank_by_the_largest_channel_in_linear_values() {
        let mut px = vec![[255, 0, 0, 255]; 18];
        px.push([0, 0, 10, 255]);
        px.push([0, 0, 10, 255]);
        let s = stats_of(&image(&px), Channels::Rgb, Transfer::Srgb);
        let ten = Transfer::Srgb.to_linear(10.0 / 255.0);
        assert_eq!(s.p5, vec![0.0, 0.0, ten]);
        assert_eq!(s.p95, vec![1.0, 0.0, 0.0]);
        assert!((s.mean[0] - 0.9).abs() < 1e-12 && (s.mean[2] - 0.1 * ten).abs() < 1e-15);
    }

    #[test]
    fn black_fuzz_falls_back_to_a_switched_off_sheen() {
        let m = Material {
            index: 0,
            name: None,
            kind: Kind::FuzzFallback,
            base: [0.5; 3],
            base_metallic: 0.0,
            base_roughness: 1.0,
            factors: Swatch {
                label: "factors",
                sheen: None,
                fuzz: Some(FuzzValues {
                    weight: 1.0,
                    color: [0.0; 3],
                    roughness: 0.5,
                }),
                written_sheen: None,
                written_fuzz: None,
            },
            swatches: vec![],
            notes: vec![],
            fuzz_roughness_assumed: false,
            roughness_copied_by_fast: false,
            mapping: RoughnessMapping::Fitted,
            verdict: None,
        };
        let cols = columns(&m, &m.factors);
        assert_eq!(cols.len(), 3);
        for c in &cols[1..] {
            assert!(matches!(c.look.layer, Layer::Sheen { color, .. } if color == [0.0; 3]));
        }
    }
}
