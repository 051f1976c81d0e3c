//! One material as a contact sheet shows it: its base colour, its sheen and fuzz values at each
//! swatch (the factors, or with textures the texture's 5th percentile, mean and 95th
//! percentile), and the columns a sheet compares — the material as authored, as migrated and
//! as a loader without KHR_materials_fuzz sees it.
//!
//! What migrate would produce is computed here from `shading::mapping` in one function,
//! [`columns`], rather than by running the migrate planner (whose per-material result is a set
//! of JSON edits, not values): it follows the planner's default (fast) conversions —
//! sheen → fuzz writes fuzzFactor w = max3(sheenColorFactor), fuzzColor = sheenColor / w (a
//! colour texture carried as it is, so the texel's colour divided by the factor's w) and
//! fuzzRoughness α(r) (fitted, the mapping applied to factor × texel as the bake does) or r
//! (copied); fuzz → fallback sheen writes sheenColor = fuzzColor × w (clamped into [0, 1]) and
//! sheenRoughness r(α) (fitted) or α (copied). A black fuzz gives a switched-off sheen, which
//! shows the base alone, as a loader without fuzz shows a material to which migrate adds no
//! fallback. A material that has both layers keeps its sheen (migrate leaves it).
//!
//! Textures: a readable texture (PNG, JPEG, WebP, decoded to 8 bits per channel) is reduced to
//! its mean and its 5th and 95th percentiles (nearest rank; a colour texture is ranked by the
//! largest of its channels, and the percentile's colour is the mean of the texels at that
//! rank), in linear values. Each textured slot enters a swatch at its own percentile. The base
//! colour texture enters as its mean. A texture that cannot be read leaves its factor, and a
//! note says so.

use crate::asset::Asset;
use crate::layers::{self, Channels, FuzzView, SheenView, Slot, Transfer};
use crate::shading::layering::{max3, FuzzParams, SheenParams};
use crate::shading::mapping::{fuzz_roughness_for_sheen, sheen_roughness_for_fuzz};
use serde_json::Value;

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
    /// "FACTORS", "P5", "MEAN" or "P95".
    pub label: &'static str,
    pub sheen: Option<SheenValues>,
    pub fuzz: Option<FuzzValues>,
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
    /// The Lambertian base albedo, linear.
    pub base: [f64; 3],
    /// The values at the factors alone (what the figures are computed at).
    pub factors: Swatch,
    /// The swatches drawn: the factors alone, or P5, MEAN and P95 when a layer is textured.
    pub swatches: Vec<Swatch>,
    /// What the sheet must say about the inputs (textures not read, defaults assumed).
    pub notes: Vec<String>,
    /// fuzzRoughnessFactor was absent: the table default 0.5 is used.
    pub fuzz_roughness_assumed: bool,
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

/// The materials of `asset` that have or get a sheen or fuzz layer, in document order.
/// Materials that use KHR_materials_unlit or KHR_materials_pbrSpecularGlossiness (which
/// exclude both layers, so migrate leaves them), and a switched-off sheen or fuzz alone (to
/// which migrate adds nothing), are left out.
pub fn materials(asset: &Asset) -> Vec<Material> {
    let mut images = ImageCache::default();
    layers::materials(asset.json())
        .iter()
        .enumerate()
        .filter_map(|(index, m)| read(asset, index, m, &mut images))
        .collect()
}

#[derive(Default)]
struct ImageCache {
    stats: Vec<(usize, Channels, Transfer, Result<TextureStats, String>)>,
}

fn read(
    asset: &Asset,
    index: usize,
    material: &Value,
    images: &mut ImageCache,
) -> Option<Material> {
    let ext = layers::extensions(material);
    let get = |name: &str| ext.and_then(|e| e.get(name)).filter(|v| v.is_object());
    if get(layers::UNLIT).is_some() || get(layers::SPEC_GLOSS).is_some() {
        return None;
    }
    let sheen_json = get(layers::SHEEN);
    let fuzz_json = get(layers::FUZZ);
    let sheen = sheen_json.and_then(SheenView::read);
    let fuzz = fuzz_json.and_then(FuzzView::read);
    let kind = match (&sheen, &fuzz) {
        (Some(_), Some(_)) => Kind::FuzzWithSheen,
        (None, Some(f)) if f.is_on() => Kind::FuzzFallback,
        (Some(s), None) if s.is_on() => Kind::SheenToFuzz,
        _ => return None,
    };
    let mut notes = Vec::new();
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

    let fuzz_roughness_assumed = fuzz.as_ref().is_some_and(|f| f.roughness_factor.is_none());
    if fuzz_roughness_assumed {
        notes.push(format!(
            "fuzzRoughnessFactor absent: the draft's table default {} is used",
            layers::FUZZ_ROUGHNESS_DEFAULT_TABLE
        ));
    }

    // The layer textures, each reduced to three values.
    let mut textured: Vec<(&'static str, TextureStats)> = Vec::new();
    for (json, extension) in [(sheen_json, layers::SHEEN), (fuzz_json, layers::FUZZ)] {
        let Some(json) = json else { continue };
        for slot in layers::slots_of(extension) {
            let Some(info) = json.get(slot.texture) else {
                continue;
            };
            match texture_stats(asset, info, slot.channels, slot.transfer, images) {
                Ok(s) => textured.push((slot.texture, s)),
                Err(e) => notes.push(format!(
                    "{} not read ({e}): {} alone is used",
                    slot.texture, slot.factor
                )),
            }
        }
    }
    let at = |pick: fn(&TextureStats) -> &Vec<f64>, label: &'static str| {
        let value = |slot: &Slot| -> Option<Vec<f64>> {
            textured
                .iter()
                .find(|(t, _)| *t == slot.texture)
                .map(|(_, s)| pick(s).clone())
        };
        swatch_values(label, sheen.as_ref(), fuzz.as_ref(), &value)
    };
    let factors = swatch_values("FACTORS", sheen.as_ref(), fuzz.as_ref(), &|_| None);
    let swatches = if textured.is_empty() {
        vec![factors.clone()]
    } else {
        vec![
            at(|s| &s.p5, "P5"),
            at(|s| &s.mean, "MEAN"),
            at(|s| &s.p95, "P95"),
        ]
    };
    Some(Material {
        index,
        name,
        kind,
        base,
        factors,
        swatches,
        notes,
        fuzz_roughness_assumed,
    })
}

/// The layers' values at one swatch: each factor times its texture's value there (`texel`
/// gives it for a slot, `None` when the slot has no readable texture).
fn swatch_values(
    label: &'static str,
    sheen: Option<&SheenView>,
    fuzz: Option<&FuzzView>,
    texel: &dyn Fn(&Slot) -> Option<Vec<f64>>,
) -> Swatch {
    let slot = |name: &str| {
        layers::SLOTS
            .iter()
            .find(|s| s.texture == name)
            .expect("a slot velvet knows")
    };
    let scalar = |name: &str, factor: f64| texel(slot(name)).map_or(factor, |v| factor * v[0]);
    let color = |name: &str, factor: [f64; 3]| {
        texel(slot(name)).map_or(factor, |v| std::array::from_fn(|k| factor[k] * v[k]))
    };
    Swatch {
        label,
        sheen: sheen.map(|s| SheenValues {
            color: color("sheenColorTexture", s.color_factor),
            roughness: scalar("sheenRoughnessTexture", s.roughness_factor),
        }),
        fuzz: fuzz.map(|f| FuzzValues {
            weight: scalar("fuzzTexture", f.factor),
            color: color("fuzzColorTexture", f.color_factor),
            roughness: scalar("fuzzRoughnessTexture", f.roughness_or_table_default()),
        }),
    }
}

/// The image a textureInfo's texture reads.
fn image_index(asset: &Asset, info: &Value) -> Result<usize, String> {
    let texture = info
        .get("index")
        .and_then(layers::as_index)
        .ok_or("no texture index")?;
    let source = asset
        .json()
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
    cache: &mut ImageCache,
) -> Result<TextureStats, String> {
    let image = image_index(asset, info)?;
    if let Some((_, _, _, s)) = cache
        .stats
        .iter()
        .find(|(i, c, t, _)| *i == image && *c == channels && *t == transfer)
    {
        return s.clone();
    }
    let stats = asset
        .decode_image(image)
        .map_err(|d| d.message)
        .map(|img| stats_of(&img.to_rgba8(), channels, transfer));
    cache.stats.push((image, channels, transfer, stats.clone()));
    stats
}

/// The mean, 5th and 95th percentiles of the values a slot reads from `img` (see the module
/// comment), linear.
pub fn stats_of(img: &image::RgbaImage, channels: Channels, transfer: Transfer) -> TextureStats {
    let lin: [f64; 256] = std::array::from_fn(|c| transfer.to_linear(c as f64 / 255.0));
    let dims = if channels == Channels::Rgb { 3 } else { 1 };
    // Per rank (the largest channel's code, or the channel's code): texel count and sums.
    let mut count = [0u64; 256];
    let mut sums = vec![[0.0f64; 3]; 256];
    for p in img.pixels() {
        let [r, g, b, a] = p.0;
        let (rank, values) = match channels {
            Channels::Rgb => (
                r.max(g).max(b),
                [lin[r as usize], lin[g as usize], lin[b as usize]],
            ),
            Channels::Red => (r, [lin[r as usize], 0.0, 0.0]),
            Channels::Alpha => (a, [lin[a as usize], 0.0, 0.0]),
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

/// The columns of `material`'s sheet at one swatch: the material as authored first, then what
/// migrate makes of it with the fitted and the copied roughness mapping, and what a loader
/// without KHR_materials_fuzz sees. Column 1 is the one the difference image and the verdict
/// compare with column 0.
pub fn columns(material: &Material, swatch: &Swatch) -> Vec<Column> {
    let base = material.base;
    let look = |layer| Look { base, layer };
    let sheen_layer = |s: SheenValues| Layer::Sheen {
        color: s.color,
        roughness: s.roughness,
    };
    let fuzz_layer = |f: FuzzValues| Layer::Fuzz {
        color: f.color,
        weight: f.weight,
        roughness: f.roughness,
    };
    match material.kind {
        Kind::SheenToFuzz => {
            let s = swatch.sheen.expect("a sheen material has sheen values");
            let w = max3(material.factors.sheen.expect("sheen").color).clamp(0.0, 1.0);
            let color = s.color.map(|c| if w > 0.0 { c / w } else { 0.0 });
            let fuzz = |roughness| FuzzValues {
                weight: w,
                color,
                roughness,
            };
            let fitted = fuzz_roughness_for_sheen(s.roughness);
            vec![
                Column {
                    title: "AUTHORED: SHEEN".into(),
                    detail: format!("R {}", rough(s.roughness)),
                    look: look(sheen_layer(s)),
                },
                Column {
                    title: "MIGRATED: FUZZ".into(),
                    detail: format!("A {} FITTED", rough(fitted)),
                    look: look(fuzz_layer(fuzz(fitted))),
                },
                Column {
                    title: "MIGRATED: FUZZ".into(),
                    detail: format!("A {} COPIED", rough(s.roughness)),
                    look: look(fuzz_layer(fuzz(s.roughness))),
                },
                Column {
                    title: "NO FUZZ: SHEEN".into(),
                    detail: format!("KEPT, R {}", rough(s.roughness)),
                    look: look(sheen_layer(s)),
                },
            ]
        }
        Kind::FuzzFallback | Kind::FuzzWithSheen => {
            let f = swatch.fuzz.expect("a fuzz material has fuzz values");
            let color = f
                .color
                .map(|c| (c * f.weight.clamp(0.0, 1.0)).clamp(0.0, 1.0));
            let fallback = |roughness| SheenValues { color, roughness };
            let fitted = sheen_roughness_for_fuzz(f.roughness);
            let mut cols = vec![Column {
                title: "AUTHORED: FUZZ".into(),
                detail: format!("A {}", rough(f.roughness)),
                look: look(fuzz_layer(f)),
            }];
            let prefix = if let (Kind::FuzzWithSheen, Some(s)) = (material.kind, swatch.sheen) {
                cols.push(Column {
                    title: "NO FUZZ: SHEEN".into(),
                    detail: format!("IN FILE, R {}", rough(s.roughness)),
                    look: look(sheen_layer(s)),
                });
                "REFRESHED"
            } else {
                "NO FUZZ"
            };
            cols.push(Column {
                title: format!("{prefix}: SHEEN"),
                detail: format!("R {} FITTED", rough(fitted)),
                look: look(sheen_layer(fallback(fitted))),
            });
            cols.push(Column {
                title: format!("{prefix}: SHEEN"),
                detail: format!("R {} COPIED", rough(f.roughness)),
                look: look(sheen_layer(fallback(f.roughness))),
            });
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
            factors: Swatch {
                label: "FACTORS",
                sheen: None,
                fuzz: Some(FuzzValues {
                    weight: 1.0,
                    color: [0.0; 3],
                    roughness: 0.5,
                }),
            },
            swatches: vec![],
            notes: vec![],
            fuzz_roughness_assumed: false,
        };
        let cols = columns(&m, &m.factors);
        assert_eq!(cols.len(), 3);
        for c in &cols[1..] {
            assert!(matches!(c.look.layer, Layer::Sheen { color, .. } if color == [0.0; 3]));
        }
    }
}
