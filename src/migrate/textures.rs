//! The textures a migration bakes: what each new texture holds ([`Contents`]), which slot it
//! fills ([`TextureBake`]), and the [`BakePlan`] they become, so that `velvet migrate` runs the
//! same engine and the same applier as `velvet bake` (one decode per image, one output per
//! distinct recipe, new images next to the output or in the GLB's BIN chunk, sources that
//! nothing reads any more dropped).
//!
//! A conversion that needs a bake writes the slot's textureInfo (a copy of the one it reads,
//! so texCoord and KHR_texture_transform come along) and pushes a [`TextureBake`]; the applier
//! then points that textureInfo at a new texture (the read texture's sampler and name, its
//! sources replaced) and sets the slot's factor to the identity, since the factor is baked in.
//! Planning reads image headers only (to refuse KTX2); pixels are decoded when the file is
//! written.

use crate::asset::Asset;
use crate::bake::codec::KTX2_REASON;
use crate::bake::plan::{BakePlan, OutputInfo, SlotPlan, SourcePlan};
use crate::bake::recipe::Value as Expr;
use crate::bake::Layout;
use crate::bake::{
    Channel, ChannelRecipe, Curve, Factor, ImageFormat, ImageId, OutputId, OutputLayout, Recipe,
    RecipeError, Transfer,
};
use serde::{Serialize, Serializer};
use serde_json::Value;

/// What a new texture holds, per texel `t` of the image it is made from (colours decoded from
/// sRGB, so every product below is on linear values).
#[derive(Debug, Clone, PartialEq)]
pub enum Contents {
    /// fuzzTexture (red, linear): max3(color · t.rgb), the sheen's per-texel strength.
    SheenStrength { color: [f64; 3] },
    /// fuzzColorTexture (RGB, sRGB): color · t.rgb / max3(color · t.rgb) (white where the
    /// maximum is 0, where the fuzz strength is 0 and the colour is never seen).
    SheenNormalised { color: [f64; 3] },
    /// sheenColorTexture (RGB, sRGB): color · t.rgb · i.r, the fuzz colour texture times the
    /// fuzz intensity texture's red channel (image `intensity_image`, sampled at the same
    /// coordinates; resampled when its size differs).
    ColorTimesIntensity {
        color: [f64; 3],
        intensity_image: usize,
    },
    /// sheenColorTexture (RGB, sRGB) from a fuzz intensity texture alone: color · t.r.
    IntensityAsColor { color: [f64; 3] },
    /// A roughness texture (alpha, linear): curve(factor · t.channel), the other channels kept.
    /// `channel` is alpha for sheen and fuzz roughness, green for a material's
    /// metallicRoughnessTexture; `curve` maps one layer's roughness to the other's.
    Roughness {
        channel: Channel,
        factor: f64,
        curve: Option<Curve>,
    },
}

fn rgb_text(c: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", c[0], c[1], c[2])
}

impl Contents {
    /// What the texture holds, in words (for dry runs and reports).
    pub fn describe(&self) -> String {
        match self {
            Contents::SheenStrength { color } => {
                format!("red = max3({} × sheen colour texel)", rgb_text(*color))
            }
            Contents::SheenNormalised { color } => format!(
                "RGB = {c} × sheen colour texel / max3({c} × sheen colour texel)",
                c = rgb_text(*color)
            ),
            Contents::ColorTimesIntensity {
                color,
                intensity_image,
            } => format!(
                "RGB = {} × fuzz colour texel × red of fuzz intensity image {intensity_image}",
                rgb_text(*color)
            ),
            Contents::IntensityAsColor { color } => {
                format!("RGB = {} × red of fuzz intensity texel", rgb_text(*color))
            }
            Contents::Roughness {
                channel,
                factor,
                curve,
            } => {
                let source = format!(
                    "{factor:?} × {} of the texel",
                    match channel {
                        Channel::R => "red",
                        Channel::G => "green",
                        Channel::B => "blue",
                        Channel::A => "alpha",
                    }
                );
                match curve {
                    Some(curve) => format!("alpha = {}({source})", curve.name()),
                    None => format!("alpha = {source}"),
                }
            }
        }
    }

    /// The recipe of the texture made from image `base`.
    pub fn recipe(&self, base: ImageId) -> Result<Recipe, RecipeError> {
        const RGB: [Channel; 3] = [Channel::R, Channel::G, Channel::B];
        let colour = |color: &[f64; 3], i: usize| -> Result<Expr, RecipeError> {
            Ok(Expr::scaled(
                Expr::texel(base, RGB[i], Transfer::Srgb),
                Factor::new(color[i])?,
            ))
        };
        let rgb_recipe = |values: [Expr; 3]| {
            values
                .into_iter()
                .zip(RGB)
                .fold(Recipe::new(base), |recipe, (value, channel)| {
                    recipe.with(channel, ChannelRecipe::computed(value, Transfer::Srgb))
                })
        };
        Ok(match self {
            Contents::SheenStrength { color } => {
                let strength =
                    Expr::max((0..3).map(|i| colour(color, i)).collect::<Result<_, _>>()?)?;
                Recipe::new(base)
                    .with_layout(OutputLayout::Fixed(Layout::Grey))
                    .with(
                        Channel::R,
                        ChannelRecipe::computed(strength, Transfer::Linear),
                    )
            }
            Contents::SheenNormalised { color } => {
                let strength =
                    Expr::max((0..3).map(|i| colour(color, i)).collect::<Result<_, _>>()?)?;
                let mut values = Vec::with_capacity(3);
                for i in 0..3 {
                    values.push(Expr::ratio(
                        colour(color, i)?,
                        strength.clone(),
                        Factor::ONE,
                    ));
                }
                rgb_recipe(values.try_into().expect("three channels"))
            }
            Contents::ColorTimesIntensity {
                color,
                intensity_image,
            } => {
                let intensity =
                    Expr::texel(ImageId(*intensity_image), Channel::R, Transfer::Linear);
                let mut values = Vec::with_capacity(3);
                for i in 0..3 {
                    values.push(Expr::product(vec![colour(color, i)?, intensity.clone()])?);
                }
                rgb_recipe(values.try_into().expect("three channels"))
            }
            Contents::IntensityAsColor { color } => {
                let intensity = Expr::texel(base, Channel::R, Transfer::Linear);
                let mut values = Vec::with_capacity(3);
                for &k in color {
                    values.push(Expr::scaled(intensity.clone(), Factor::new(k)?));
                }
                rgb_recipe(values.try_into().expect("three channels"))
            }
            Contents::Roughness {
                channel,
                factor,
                curve,
            } => {
                let scaled = Expr::scaled(
                    Expr::texel(base, *channel, Transfer::Linear),
                    Factor::new(*factor)?,
                );
                let value = match curve {
                    Some(curve) => Expr::curve(curve.clone(), scaled),
                    None => scaled,
                };
                Recipe::new(base).with(Channel::A, ChannelRecipe::computed(value, Transfer::Linear))
            }
        })
    }
}

impl Serialize for Contents {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.describe())
    }
}

/// One texture slot a migration fills with a baked texture.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TextureBake {
    pub material: usize,
    /// `KHR_materials_sheen` or `KHR_materials_fuzz`.
    pub extension: &'static str,
    /// Pointer to the extension object.
    pub layer_pointer: String,
    /// The slot's textureInfo key (`fuzzTexture`, `sheenColorTexture`, …).
    pub texture_key: &'static str,
    /// The slot's factor key, set to the identity once the texture holds the factor.
    pub factor_key: &'static str,
    /// The factor the slot would otherwise carry (one or three components), for reports.
    pub factor: Vec<f64>,
    /// The factor written once the texture is baked: `None` for the identity (the factor is
    /// baked in), a value when the texture is shared and the factor carries the material's
    /// part (see [`budget`](super::budget)).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub written_factor: Option<f64>,
    /// The texture read (its sampler, name and extensions are kept).
    pub texture: usize,
    /// The texture's sources: where it names each image, and the image.
    #[serde(skip)]
    pub sources: Vec<(String, usize)>,
    pub contents: Contents,
}

impl TextureBake {
    /// Pointer to the slot's textureInfo.
    pub fn texture_pointer(&self) -> String {
        format!("{}/{}", self.layer_pointer, self.texture_key)
    }

    /// The factor the slot holds once the texture is baked: the written factor, or the
    /// identity (`1.0`, or `[1.0, 1.0, 1.0]` for a colour) when the factor is baked in.
    pub fn factor_in_file(&self) -> Value {
        match self.written_factor {
            Some(w) => Value::from(w),
            None if self.factor.len() == 3 => serde_json::json!([1.0, 1.0, 1.0]),
            None => serde_json::json!(1.0),
        }
    }

    /// The short name of the slot (`fuzzTexture` → `fuzz`), which names the new images.
    pub fn label(&self) -> &'static str {
        self.texture_key
            .strip_suffix("Texture")
            .unwrap_or(self.texture_key)
    }
}

impl std::fmt::Display for TextureBake {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let images: Vec<String> = self.sources.iter().map(|(_, i)| i.to_string()).collect();
        let factor = match self.written_factor {
            Some(w) => format!("{} becomes {w}", self.factor_key),
            None => format!("{} becomes the identity", self.factor_key),
        };
        write!(
            f,
            "bake {} from texture {} (image {}): {}; {factor}",
            self.texture_pointer(),
            self.texture,
            images.join(", "),
            self.contents.describe(),
        )
    }
}

/// The images texture `index` reads, each with where the texture names it; `Err` says why the
/// texture cannot be baked (no such texture or image, an image that cannot be read or
/// decoded, no source, a KTX2 source).
pub fn sources(asset: &Asset, index: usize) -> Result<Vec<(String, usize)>, String> {
    let json = asset.root();
    let texture = json
        .get("textures")
        .and_then(|t| t.get(index))
        .ok_or_else(|| format!("texture {index} does not exist"))?;
    let image_count = json
        .get("images")
        .and_then(|i| i.as_array())
        .map_or(0, |i| i.len());
    let texture_pointer = format!("/textures/{index}");
    let mut out = Vec::new();
    for (image, pointer) in crate::document::texture_sources(texture, &texture_pointer) {
        let within = pointer[texture_pointer.len()..].to_owned();
        let image = match image {
            Some(i) if (i as usize) < image_count => i as usize,
            _ => {
                return Err(format!(
                    "texture {index} names no existing image at {pointer}"
                ))
            }
        };
        let header = asset
            .image_header(image)
            .map_err(|d| format!("image {image} cannot be read: {}", d.message))?;
        let ktx2 = header.format == ImageFormat::Ktx2
            || json
                .pointer(&format!("/images/{image}/mimeType"))
                .is_some_and(|m| m.is_str("image/ktx2"));
        if ktx2 {
            return Err(format!(
                "texture {index} has a KTX2 source (image {image}); {KTX2_REASON}"
            ));
        }
        asset.image_decodes(image).map_err(|why| {
            let prefix = format!("image {image}: ");
            let detail = why.strip_prefix(&prefix).unwrap_or(&why);
            format!("image {image} cannot be decoded: {detail}")
        })?;
        out.push((within, image));
    }
    if out.is_empty() {
        return Err(format!("texture {index} has no source image"));
    }
    Ok(out)
}

/// The texture index a textureInfo names, if it is a valid one.
pub fn texture_index(texture_info: &Value) -> Option<usize> {
    texture_info
        .get("index")
        .and_then(Value::as_u64)
        .map(|i| i as usize)
}

/// The bake plan of every texture bake of a document, in order: equal recipes share one output.
pub fn bake_plan<'a>(bakes: impl IntoIterator<Item = &'a TextureBake>) -> Result<BakePlan, String> {
    let mut plan = BakePlan::default();
    for bake in bakes {
        let mut sources = Vec::with_capacity(bake.sources.len());
        for (within, image) in &bake.sources {
            let recipe = bake
                .contents
                .recipe(ImageId(*image))
                .map_err(|e| format!("{}: {e}", bake.texture_pointer()))?;
            let id: OutputId = plan.recipes.insert(recipe);
            if id.0 == plan.outputs.len() {
                plan.outputs.push(OutputInfo {
                    image: *image,
                    labels: vec![bake.label()],
                });
            } else if !plan.outputs[id.0].labels.contains(&bake.label()) {
                plan.outputs[id.0].labels.push(bake.label());
            }
            sources.push(SourcePlan {
                within_texture: within.clone(),
                image: *image,
                output: id,
            });
        }
        plan.slots.push(SlotPlan {
            material: bake.material,
            extension: bake.extension,
            texture_key: bake.texture_key,
            factor_key: bake.factor_key,
            layer_pointer: bake.layer_pointer.clone(),
            texture: bake.texture,
            factor: bake.factor.clone(),
            written_factor: bake.written_factor.map(serde_json::Value::from),
            sources,
        });
    }
    Ok(plan)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bake(contents: Contents, key: &'static str) -> TextureBake {
        TextureBake {
            material: 0,
            extension: crate::layers::FUZZ,
            layer_pointer: "/materials/0/extensions/KHR_materials_fuzz".into(),
            texture_key: key,
            factor_key: "fuzzFactor",
            factor: vec![0.5],
            written_factor: None,
            texture: 0,
            sources: vec![("/source".into(), 3)],
            contents,
        }
    }

    #[test]
    fn equal_contents_share_one_output_and_gather_their_labels() {
        let roughness = Contents::Roughness {
            channel: Channel::G,
            factor: 0.5,
            curve: None,
        };
        let mut sheen = bake(roughness.clone(), "sheenRoughnessTexture");
        sheen.extension = crate::layers::SHEEN;
        let fuzz = bake(roughness, "fuzzRoughnessTexture");
        let strength = bake(
            Contents::SheenStrength {
                color: [0.5, 0.25, 0.0],
            },
            "fuzzTexture",
        );
        let plan = bake_plan([&sheen, &fuzz, &strength]).unwrap();
        assert_eq!(plan.recipes.len(), 2);
        assert_eq!(
            plan.outputs[0].labels,
            vec!["sheenRoughness", "fuzzRoughness"]
        );
        assert_eq!(plan.outputs[1].labels, vec!["fuzz"]);
        let outputs: Vec<usize> = plan.slots.iter().map(|s| s.sources[0].output.0).collect();
        assert_eq!(outputs, vec![0, 0, 1]);
    }

    #[test]
    fn a_strength_texture_is_one_grey_channel_and_a_roughness_move_writes_alpha_only() {
        let strength = Contents::SheenStrength {
            color: [1.0, 0.5, 0.25],
        }
        .recipe(ImageId(2))
        .unwrap();
        assert_eq!(strength.layout(), OutputLayout::Fixed(Layout::Grey));
        assert!(strength.channel(Channel::R).is_some());
        let moved = Contents::Roughness {
            channel: Channel::G,
            factor: 1.0,
            curve: None,
        }
        .recipe(ImageId(2))
        .unwrap();
        assert_eq!(
            moved.channel(Channel::A),
            Some(&ChannelRecipe::Copy(ImageId(2), Channel::G))
        );
        assert!(moved.channel(Channel::R).is_none() && moved.channel(Channel::G).is_none());
    }

    #[test]
    fn a_colour_factor_that_is_not_finite_is_refused() {
        let error = Contents::IntensityAsColor {
            color: [f64::NAN, 0.0, 0.0],
        }
        .recipe(ImageId(0))
        .unwrap_err();
        assert!(matches!(error, RecipeError::NotFinite { .. }));
    }
}
