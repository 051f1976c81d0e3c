//! Planning `velvet bake` for one asset: which sheen and fuzz texture slots need baking, with
//! which recipe, and what the document will say afterwards — all as plain values, before any
//! pixel is decoded (only image headers are read, to spot KTX2 and grey images).
//!
//! Rules, per material and layer:
//! - A layer that is off (sheenColorFactor all zero, fuzzFactor zero) is left alone.
//! - A slot whose factor is the identity (1, or [1, 1, 1]) needs nothing.
//! - A factor outside [0, 1] is reported and baked only with `allow_out_of_range`.
//! - An absent fuzzRoughnessFactor is taken as the draft table's 0.5 (its schema says 0.0),
//!   and the plan says so.
//! - A texture with a KTX2 source (KHR_texture_basisu) is left as it was, with a warning: all of
//!   a texture's sources (`source`, EXT_texture_webp, …) are baked or none is.
//! - The slots of one material that read the same image in different channels (colour in RGB,
//!   roughness in alpha) share one recipe, so the image is baked once with both parts; slots
//!   whose channels clash get separate recipes. Equal recipes across materials share an output.

use serde::Serialize;
use serde_json::Value;

use super::engine::{OutputId, RecipeSet};
use super::recipe::{Channel, ChannelRecipe, Factor, ImageId, Recipe, Transfer, Value as Expr};
use crate::asset::resource::ImageFormat;
use crate::asset::Asset;
use crate::document::texture_sources;
use crate::layers::{self, Channels, Slot};
use crate::layers::{layer_objects, slot_uses};

/// Choices that change the plan.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PlanOptions {
    /// Bake factors outside [0, 1] (results are clamped and the clamping counted).
    pub allow_out_of_range: bool,
}

/// How much a note matters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// Something the user may want to know.
    Info,
    /// Something left undone or assumed.
    Warning,
}

/// A remark about one place in the document.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct Note {
    /// How much it matters.
    pub level: Level,
    /// JSON pointer to what it is about.
    pub pointer: String,
    /// What happened.
    pub message: String,
}

impl Note {
    fn new(level: Level, pointer: impl Into<String>, message: impl Into<String>) -> Note {
        Note {
            level,
            pointer: pointer.into(),
            message: message.into(),
        }
    }
}

/// One texture slot that will be baked.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlotPlan {
    /// The material's index.
    pub material: usize,
    /// `KHR_materials_sheen` or `KHR_materials_fuzz`.
    pub extension: &'static str,
    /// The slot's textureInfo key (e.g. `sheenColorTexture`).
    pub texture_key: &'static str,
    /// The slot's factor key (e.g. `sheenColorFactor`).
    pub factor_key: &'static str,
    /// Pointer to the extension object.
    pub layer_pointer: String,
    /// The texture the slot reads now.
    pub texture: usize,
    /// The factor baked into the texture (one or three components).
    pub factor: Vec<f64>,
    /// The factor written after the bake: `None` for the identity.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub written_factor: Option<Value>,
    /// Per source of the texture (pointer suffix within the texture, e.g. `/source`): the image
    /// read now and the output that replaces it.
    #[serde(skip)]
    pub sources: Vec<SourcePlan>,
}

impl SlotPlan {
    /// Pointer to the slot's textureInfo.
    pub fn texture_pointer(&self) -> String {
        format!("{}/{}", self.layer_pointer, self.texture_key)
    }

    /// Pointer to the slot's factor.
    pub fn factor_pointer(&self) -> String {
        format!("{}/{}", self.layer_pointer, self.factor_key)
    }

    /// The factor's identity value, as JSON: `1.0` or `[1.0, 1.0, 1.0]`.
    pub fn identity(&self) -> Value {
        if self.factor.len() == 3 {
            serde_json::json!([1.0, 1.0, 1.0])
        } else {
            serde_json::json!(1.0)
        }
    }
}

/// One source of a baked slot's texture.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourcePlan {
    /// Where the texture names the image, relative to the texture (`/source`,
    /// `/extensions/EXT_texture_webp/source`).
    pub within_texture: String,
    /// The image read now.
    pub image: usize,
    /// The output that replaces it.
    pub output: OutputId,
}

/// What an output is for, for naming and reports.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub struct OutputInfo {
    /// The image baked.
    pub image: usize,
    /// Short names of the slots it serves, in slot order (`sheenColor`, `sheenRoughness`, …).
    pub labels: Vec<&'static str>,
}

/// The plan for one asset.
#[derive(Clone, Debug, Default)]
pub struct BakePlan {
    /// The distinct recipes; an output's id indexes `outputs` too.
    pub recipes: RecipeSet,
    /// Per output: what it is for.
    pub outputs: Vec<OutputInfo>,
    /// The slots to bake, in document order.
    pub slots: Vec<SlotPlan>,
    /// Everything skipped or assumed.
    pub notes: Vec<Note>,
}

impl BakePlan {
    /// Whether the plan changes nothing.
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }
}

/// The short name of a slot (`sheenColorTexture` → `sheenColor`).
pub fn slot_label(slot: &Slot) -> &'static str {
    slot.texture.strip_suffix("Texture").unwrap_or(slot.texture)
}

/// The factor of a slot as written, or its default; `Err` with a message when malformed.
fn read_factor(layer: &Value, slot: &Slot) -> Result<(Vec<f64>, Option<&'static str>), String> {
    let value = layer.get(slot.factor);
    let default: Vec<f64> = match (slot.extension, slot.factor) {
        (layers::SHEEN, "sheenColorFactor") => layers::SHEEN_COLOR_DEFAULT.to_vec(),
        (layers::SHEEN, _) => vec![layers::SHEEN_ROUGHNESS_DEFAULT],
        (_, "fuzzFactor") => vec![layers::FUZZ_FACTOR_DEFAULT],
        (_, "fuzzColorFactor") => layers::FUZZ_COLOR_DEFAULT.to_vec(),
        _ => vec![layers::FUZZ_ROUGHNESS_DEFAULT_TABLE],
    };
    let Some(value) = value else {
        let assumed = (slot.factor == "fuzzRoughnessFactor").then_some(
            "fuzzRoughnessFactor is absent; the draft's table default 0.5 is baked (its schema \
             says 0.0)",
        );
        return Ok((default, assumed));
    };
    let numbers: Option<Vec<f64>> = match (slot.channels, value) {
        (Channels::Rgb, Value::Array(items)) if items.len() == 3 => {
            items.iter().map(Value::as_f64).collect()
        }
        (Channels::Rgb, _) => None,
        (_, v) => v.as_f64().map(|n| vec![n]),
    };
    match numbers {
        Some(n) if n.iter().all(|x| x.is_finite()) => Ok((n, None)),
        _ => Err(format!(
            "{} is not {}; the slot is left as it was",
            slot.factor,
            if slot.channels == Channels::Rgb {
                "an array of three numbers"
            } else {
                "a number"
            }
        )),
    }
}

/// Whether the layer object is switched on.
fn layer_is_on(extension: &str, layer: &Value) -> bool {
    if extension == layers::SHEEN {
        layers::SheenView::read(layer).is_some_and(|s| s.is_on())
    } else {
        layers::FuzzView::read(layer).is_some_and(|f| f.is_on())
    }
}

/// The channel overrides a slot needs on `image`.
fn overrides(
    slot: &Slot,
    factor: &[f64],
    image: ImageId,
    grey: bool,
) -> Vec<(Channel, ChannelRecipe)> {
    let scaled = |channel: Channel, k: f64, transfer: Transfer| {
        let k = Factor::new(k).expect("factors are checked finite");
        ChannelRecipe::computed(
            Expr::scaled(Expr::texel(image, channel, transfer), k),
            transfer,
        )
    };
    match slot.channels {
        Channels::Rgb => [Channel::R, Channel::G, Channel::B]
            .into_iter()
            .zip(factor)
            .map(|(c, &k)| (c, scaled(c, k, Transfer::Srgb)))
            .collect(),
        Channels::Alpha => vec![(Channel::A, scaled(Channel::A, factor[0], Transfer::Linear))],
        // A grey image stays grey: its red, green and blue are one channel.
        Channels::Red if grey => [Channel::R, Channel::G, Channel::B]
            .into_iter()
            .map(|c| (c, scaled(c, factor[0], Transfer::Linear)))
            .collect(),
        Channels::Red => vec![(Channel::R, scaled(Channel::R, factor[0], Transfer::Linear))],
    }
}

/// Recipes being gathered for one material and one image.
struct Group {
    image: usize,
    channels: [Option<ChannelRecipe>; 4],
    labels: Vec<&'static str>,
    /// (index into the plan's slots, index into that slot's sources)
    members: Vec<(usize, usize)>,
}

/// The top-level arrays a bake reads and extends: each, when present, must be an array of
/// objects. A document where one is not does not have glTF's structure (the core check reports
/// it); baking it would mean guessing where new images and bufferViews go.
const EDITED_ARRAYS: [&str; 4] = ["buffers", "bufferViews", "images", "textures"];

/// Plans the bake of one asset.
pub fn plan(asset: &Asset, options: PlanOptions) -> BakePlan {
    let json = asset.json();
    let mut out = BakePlan::default();
    for key in EDITED_ARRAYS {
        let Some(value) = json.get(key) else { continue };
        if !value
            .as_array()
            .is_some_and(|items| items.iter().all(Value::is_object))
        {
            out.notes.push(Note::new(
                Level::Warning,
                format!("/{key}"),
                format!("{key} is not an array of objects, as glTF requires; nothing is baked"),
            ));
            return out;
        }
    }
    let textures = json.get("textures").and_then(Value::as_array);
    let image_count = json
        .get("images")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let mut current_material = usize::MAX;
    let mut groups: Vec<Group> = Vec::new();
    let layer_list: Vec<_> = layer_objects(json).collect();
    for layer in &layer_list {
        if layer.material != current_material {
            flush(&mut groups, &mut out);
            current_material = layer.material;
        }
        let uses: Vec<_> = slot_uses(layer).collect();
        if uses.is_empty() {
            continue;
        }
        if !layer_is_on(layer.extension, layer.value) {
            out.notes.push(Note::new(
                Level::Info,
                layer.pointer(),
                format!(
                    "{} is switched off; its textures are left as they are",
                    layer.extension
                ),
            ));
            continue;
        }
        'slots: for slot_use in uses {
            let slot = slot_use.slot;
            let pointer = slot_use.pointer().clone();
            let (factor, assumed) = match read_factor(layer.value, slot) {
                Ok(f) => f,
                Err(message) => {
                    out.notes.push(Note::new(
                        Level::Warning,
                        format!("{}/{}", layer.pointer(), slot.factor),
                        message,
                    ));
                    continue;
                }
            };
            if factor.iter().all(|&k| k == 1.0) {
                continue;
            }
            if let Some(message) = assumed {
                out.notes.push(Note::new(
                    Level::Warning,
                    format!("{}/{}", layer.pointer(), slot.factor),
                    message,
                ));
            }
            if factor.iter().any(|k| !(0.0..=1.0).contains(k)) {
                if options.allow_out_of_range {
                    out.notes.push(Note::new(
                        Level::Warning,
                        format!("{}/{}", layer.pointer(), slot.factor),
                        format!(
                            "{} {factor:?} is outside [0, 1]; baked as asked, results clamped",
                            slot.factor
                        ),
                    ));
                } else {
                    out.notes.push(Note::new(
                        Level::Warning,
                        format!("{}/{}", layer.pointer(), slot.factor),
                        format!(
                            "{} {factor:?} is outside [0, 1] (the schema forbids it); the slot is \
                             left as it was (--allow-out-of-range bakes it, clamped)",
                            slot.factor
                        ),
                    ));
                    continue;
                }
            }
            let Some(texture_index) = slot_use.texture.index else {
                out.notes.push(Note::new(
                    Level::Warning,
                    &pointer,
                    "the textureInfo has no valid index; left as it was",
                ));
                continue;
            };
            let Some(texture) = textures.and_then(|t| t.get(texture_index as usize)) else {
                out.notes.push(Note::new(
                    Level::Warning,
                    format!("{pointer}/index"),
                    format!("texture {texture_index} does not exist; left as it was"),
                ));
                continue;
            };
            let texture_pointer = format!("/textures/{texture_index}");
            let mut sources = Vec::new();
            for (image, source_pointer) in texture_sources(texture, &texture_pointer) {
                let within = source_pointer[texture_pointer.len()..].to_owned();
                let Some(image) = image.filter(|&i| (i as usize) < image_count) else {
                    out.notes.push(Note::new(
                        Level::Warning,
                        &source_pointer,
                        format!(
                            "texture {texture_index} names no existing image; {} left as it was",
                            slot.texture
                        ),
                    ));
                    continue 'slots;
                };
                let image = image as usize;
                let header = asset.image_header(image).ok();
                let ktx2 = header.is_some_and(|h| h.format == ImageFormat::Ktx2)
                    || json
                        .pointer(&format!("/images/{image}/mimeType"))
                        .and_then(Value::as_str)
                        == Some("image/ktx2");
                if ktx2 {
                    out.notes.push(Note::new(
                        Level::Warning,
                        &pointer,
                        format!(
                            "texture {texture_index} has a KTX2 source (image {image}); {}; \
                             {} and its factor are left as they were",
                            super::codec::KTX2_REASON,
                            slot.texture
                        ),
                    ));
                    continue 'slots;
                }
                let grey = header.and_then(|h| h.channels).is_some_and(|c| c <= 2);
                sources.push((within, image, grey));
            }
            if sources.is_empty() {
                out.notes.push(Note::new(
                    Level::Warning,
                    &pointer,
                    format!("texture {texture_index} has no source image; left as it was"),
                ));
                continue;
            }
            let slot_index = out.slots.len();
            out.slots.push(SlotPlan {
                material: layer.material,
                extension: layer.extension,
                texture_key: slot.texture,
                factor_key: slot.factor,
                layer_pointer: layer.pointer().clone(),
                texture: texture_index as usize,
                factor: factor.clone(),
                written_factor: None,
                sources: Vec::new(),
            });
            for (k, (within, image, grey)) in sources.into_iter().enumerate() {
                let wanted = overrides(slot, &factor, ImageId(image), grey);
                let fits = |g: &Group| {
                    g.image == image
                        && wanted.iter().all(|(c, r)| match &g.channels[*c as usize] {
                            None => true,
                            Some(existing) => existing == r,
                        })
                };
                let group = match groups.iter().position(fits) {
                    Some(g) => g,
                    None => {
                        groups.push(Group {
                            image,
                            channels: [None, None, None, None],
                            labels: Vec::new(),
                            members: Vec::new(),
                        });
                        groups.len() - 1
                    }
                };
                let g = &mut groups[group];
                for (c, r) in wanted {
                    g.channels[c as usize] = Some(r);
                }
                if !g.labels.contains(&slot_label(slot)) {
                    g.labels.push(slot_label(slot));
                }
                g.members.push((slot_index, k));
                out.slots[slot_index].sources.push(SourcePlan {
                    within_texture: within,
                    image,
                    output: OutputId(usize::MAX),
                });
            }
        }
    }
    flush(&mut groups, &mut out);
    out
}

/// Turns one material's groups into recipes and points their slots at the outputs.
fn flush(groups: &mut Vec<Group>, out: &mut BakePlan) {
    for group in groups.drain(..) {
        let base = ImageId(group.image);
        let recipe = Channel::ALL.into_iter().fold(Recipe::new(base), |r, c| {
            match &group.channels[c as usize] {
                Some(cr) => r.with(c, cr.clone()),
                None => r,
            }
        });
        let id = out.recipes.insert(recipe);
        if id.0 == out.outputs.len() {
            out.outputs.push(OutputInfo {
                image: group.image,
                labels: group.labels.clone(),
            });
        }
        for (slot, k) in group.members {
            out.slots[slot].sources[k].output = id;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn plan_of(doc: Value) -> BakePlan {
        let text = serde_json::to_string(&doc).unwrap();
        let loaded =
            crate::asset::load_bytes(std::path::Path::new("memory/plan.gltf"), text.as_bytes());
        plan(&loaded.asset.unwrap(), PlanOptions::default())
    }

    fn doc(fuzz: Value) -> Value {
        json!({
            "asset": {"version": "2.0"},
            "materials": [{"extensions": {"KHR_materials_fuzz": fuzz}}],
            "textures": [{"source": 0}, {"source": 0}],
            "images": [{"uri": "missing.png"}]
        })
    }

    #[test]
    fn slots_clashing_on_one_channel_of_one_image_get_separate_recipes() {
        // fuzzTexture reads red linearly, fuzzColorTexture reads red as sRGB: one image, two
        // outputs. fuzzRoughnessTexture (alpha) joins the first that has room.
        let p = plan_of(doc(json!({
            "fuzzFactor": 0.5, "fuzzTexture": {"index": 0},
            "fuzzColorFactor": [0.5, 0.5, 0.5], "fuzzColorTexture": {"index": 1},
            "fuzzRoughnessFactor": 0.25, "fuzzRoughnessTexture": {"index": 1}
        })));
        assert_eq!(p.recipes.len(), 2);
        assert_eq!(p.outputs[0].labels, vec!["fuzz", "fuzzRoughness"]);
        assert_eq!(p.outputs[1].labels, vec!["fuzzColor"]);
        let outputs: Vec<OutputId> = p.slots.iter().map(|s| s.sources[0].output).collect();
        assert_eq!(outputs, vec![OutputId(0), OutputId(1), OutputId(0)]);
        let r = p.recipes.get(OutputId(0));
        assert!(r.channel(Channel::R).is_some() && r.channel(Channel::A).is_some());
        assert!(r.channel(Channel::G).is_none() && r.channel(Channel::B).is_none());
    }

    #[test]
    fn identity_factors_need_nothing_and_an_absent_fuzz_roughness_is_assumed_with_a_warning() {
        let p = plan_of(doc(json!({
            "fuzzFactor": 1.0, "fuzzTexture": {"index": 0},
            "fuzzRoughnessTexture": {"index": 1}
        })));
        assert_eq!(p.slots.len(), 1);
        assert_eq!(p.slots[0].texture_key, "fuzzRoughnessTexture");
        assert_eq!(p.slots[0].factor, vec![0.5]);
        assert_eq!(p.notes.len(), 1);
        assert_eq!(p.notes[0].level, Level::Warning);
        assert_eq!(
            p.notes[0].pointer,
            "/materials/0/extensions/KHR_materials_fuzz/fuzzRoughnessFactor"
        );
    }

    #[test]
    fn malformed_factors_and_dangling_textures_leave_the_slot_with_a_warning() {
        let p = plan_of(doc(json!({
            "fuzzFactor": 0.5, "fuzzTexture": {"index": 7},
            "fuzzColorFactor": "red", "fuzzColorTexture": {"index": 0}
        })));
        assert!(p.is_empty());
        let pointers: Vec<&str> = p.notes.iter().map(|n| n.pointer.as_str()).collect();
        assert_eq!(
            pointers,
            vec![
                "/materials/0/extensions/KHR_materials_fuzz/fuzzTexture/index",
                "/materials/0/extensions/KHR_materials_fuzz/fuzzColorFactor"
            ]
        );
    }
}
