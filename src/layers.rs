//! The two material layers as velvet sees them: extension names, parameter defaults, the
//! texture slots with the channels and colour space each reads, and lenient typed views of a
//! material's sheen and fuzz objects (lenient: a schema-invalid value reads as absent, the
//! schema check reports it).

use crate::asset::tape::JsonView;

pub const SHEEN: &str = "KHR_materials_sheen";
pub const FUZZ: &str = "KHR_materials_fuzz";
pub const SPEC_GLOSS: &str = "KHR_materials_pbrSpecularGlossiness";
pub const UNLIT: &str = "KHR_materials_unlit";
pub const CLEARCOAT: &str = "KHR_materials_clearcoat";
pub const TEXTURE_TRANSFORM: &str = "KHR_texture_transform";

pub const SHEEN_COLOR_DEFAULT: [f64; 3] = [0.0, 0.0, 0.0];
pub const SHEEN_ROUGHNESS_DEFAULT: f64 = 0.0;
pub const FUZZ_FACTOR_DEFAULT: f64 = 0.0;
pub const FUZZ_COLOR_DEFAULT: [f64; 3] = [1.0, 1.0, 1.0];
/// The fuzz draft's parameter table says 0.5; its JSON schema says 0.0. Where velvet needs a
/// value it takes the table's, says so, and writes the value explicitly.
pub const FUZZ_ROUGHNESS_DEFAULT_TABLE: f64 = 0.5;
pub const FUZZ_ROUGHNESS_DEFAULT_SCHEMA: f64 = 0.0;

/// The channels of a texture that a slot reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channels {
    Rgb,
    Red,
    Alpha,
}

/// How a slot's texel values are encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Transfer {
    Srgb,
    Linear,
}

impl Transfer {
    /// A stored texel value in [0, 1] as a linear value: the sRGB decoding curve (IEC 61966-2-1,
    /// linear segment below 0.04045) or the value itself.
    pub fn to_linear(self, encoded: f64) -> f64 {
        match self {
            Transfer::Linear => encoded,
            Transfer::Srgb if encoded <= 0.04045 => encoded / 12.92,
            Transfer::Srgb => ((encoded + 0.055) / 1.055).powf(2.4),
        }
    }
}

/// One texture slot of one extension, with the factor that scales it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    pub extension: &'static str,
    pub texture: &'static str,
    pub factor: &'static str,
    pub channels: Channels,
    pub transfer: Transfer,
}

pub const SLOTS: [Slot; 5] = [
    Slot {
        extension: SHEEN,
        texture: "sheenColorTexture",
        factor: "sheenColorFactor",
        channels: Channels::Rgb,
        transfer: Transfer::Srgb,
    },
    Slot {
        extension: SHEEN,
        texture: "sheenRoughnessTexture",
        factor: "sheenRoughnessFactor",
        channels: Channels::Alpha,
        transfer: Transfer::Linear,
    },
    Slot {
        extension: FUZZ,
        texture: "fuzzTexture",
        factor: "fuzzFactor",
        channels: Channels::Red,
        transfer: Transfer::Linear,
    },
    Slot {
        extension: FUZZ,
        texture: "fuzzColorTexture",
        factor: "fuzzColorFactor",
        channels: Channels::Rgb,
        transfer: Transfer::Srgb,
    },
    Slot {
        extension: FUZZ,
        texture: "fuzzRoughnessTexture",
        factor: "fuzzRoughnessFactor",
        channels: Channels::Alpha,
        transfer: Transfer::Linear,
    },
];

/// The slots of one extension.
pub fn slots_of(extension: &str) -> impl Iterator<Item = &'static Slot> + '_ {
    SLOTS.iter().filter(move |s| s.extension == extension)
}

/// A textureInfo as far as velvet needs it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TextureRef {
    /// `None` when `index` is missing or not a non-negative integer.
    pub index: Option<u64>,
    pub tex_coord: u64,
}

/// A glTF index: a non-negative integer, also when written with a zero fraction (`1.0`), which
/// JSON Schema counts as an integer. Indices are judged as numbers of any size: one beyond 64
/// bits (`18446744073709551617`, `1e30`) is `u64::MAX`, which no array reaches, so it resolves
/// to nothing, as it would at its own size; it is not taken for a missing index.
pub fn as_index<'a>(value: impl JsonView<'a>) -> Option<u64> {
    value.unsigned().or_else(|| {
        value
            .number()
            .filter(|n| *n >= 0.0 && (n.fract() == 0.0 || n.is_infinite()))
            // `as` saturates: an integer beyond u64 becomes u64::MAX.
            .map(|n| n as u64)
    })
}

impl TextureRef {
    pub fn read<'a>(value: impl JsonView<'a>) -> Option<TextureRef> {
        if !value.object() {
            return None;
        }
        Some(TextureRef {
            index: value.member("index").and_then(as_index),
            tex_coord: value.member("texCoord").and_then(as_index).unwrap_or(0),
        })
    }
}

fn number<'a>(obj: impl JsonView<'a>, key: &str) -> Option<f64> {
    obj.member(key)?.number()
}

fn rgb<'a>(obj: impl JsonView<'a>, key: &str) -> Option<[f64; 3]> {
    rgb_of(obj.member(key)?)
}

/// Three numbers, as a colour factor holds them.
pub fn rgb_of<'a>(arr: impl JsonView<'a>) -> Option<[f64; 3]> {
    if arr.length()? != 3 {
        return None;
    }
    let c = |i| arr.element(i).and_then(JsonView::number);
    Some([c(0)?, c(1)?, c(2)?])
}

/// The largest of three components.
pub fn max3(c: [f64; 3]) -> f64 {
    c[0].max(c[1]).max(c[2])
}

/// A material's KHR_materials_sheen, with defaults applied.
#[derive(Debug, Clone, PartialEq)]
pub struct SheenView {
    pub color_factor: [f64; 3],
    pub roughness_factor: f64,
    pub color_texture: Option<TextureRef>,
    pub roughness_texture: Option<TextureRef>,
}

impl SheenView {
    pub fn read<'a>(obj: impl JsonView<'a>) -> Option<SheenView> {
        if !obj.object() {
            return None;
        }
        Some(SheenView {
            color_factor: rgb(obj, "sheenColorFactor").unwrap_or(SHEEN_COLOR_DEFAULT),
            roughness_factor: number(obj, "sheenRoughnessFactor")
                .unwrap_or(SHEEN_ROUGHNESS_DEFAULT),
            color_texture: obj.member("sheenColorTexture").and_then(TextureRef::read),
            roughness_texture: obj
                .member("sheenRoughnessTexture")
                .and_then(TextureRef::read),
        })
    }

    /// The spec: "If sheenColorFactor is zero, the whole sheen layer is disabled."
    pub fn is_on(&self) -> bool {
        max3(self.color_factor) > 0.0
    }
}

/// A material's KHR_materials_fuzz, with defaults applied. `roughness_factor` is `None` when
/// absent, because the draft's default is ambiguous.
#[derive(Debug, Clone, PartialEq)]
pub struct FuzzView {
    pub factor: f64,
    pub color_factor: [f64; 3],
    pub roughness_factor: Option<f64>,
    pub texture: Option<TextureRef>,
    pub color_texture: Option<TextureRef>,
    pub roughness_texture: Option<TextureRef>,
}

impl FuzzView {
    pub fn read<'a>(obj: impl JsonView<'a>) -> Option<FuzzView> {
        if !obj.object() {
            return None;
        }
        Some(FuzzView {
            factor: number(obj, "fuzzFactor").unwrap_or(FUZZ_FACTOR_DEFAULT),
            color_factor: rgb(obj, "fuzzColorFactor").unwrap_or(FUZZ_COLOR_DEFAULT),
            roughness_factor: number(obj, "fuzzRoughnessFactor"),
            texture: obj.member("fuzzTexture").and_then(TextureRef::read),
            color_texture: obj.member("fuzzColorTexture").and_then(TextureRef::read),
            roughness_texture: obj
                .member("fuzzRoughnessTexture")
                .and_then(TextureRef::read),
        })
    }

    /// The draft: "If fuzzFactor is zero, the entire fuzz layer is disabled."
    pub fn is_on(&self) -> bool {
        self.factor > 0.0
    }

    /// The roughness velvet assumes: the written value, else the spec table's 0.5.
    pub fn roughness_or_table_default(&self) -> f64 {
        self.roughness_factor
            .unwrap_or(FUZZ_ROUGHNESS_DEFAULT_TABLE)
    }
}

/// A material's `extensions` object, if any.
pub fn extensions(
    material: &serde_json::Value,
) -> Option<&serde_json::Map<String, serde_json::Value>> {
    material.get("extensions")?.as_object()
}

/// The materials array (empty when absent or not an array).
pub fn materials(json: &serde_json::Value) -> &[serde_json::Value] {
    json.get("materials")
        .and_then(serde_json::Value::as_array)
        .map_or(&[], Vec::as_slice)
}

/// The properties of the pre-ratification sheen draft, which ratified loaders ignore.
pub const LEGACY_PROPERTIES: [&str; 3] = ["sheenFactor", "sheenColor", "sheenTexture"];

/// The draft properties present on a sheen object, read as a value or through the index.
pub fn legacy_properties<'a>(sheen: impl JsonView<'a>) -> Vec<&'static str> {
    LEGACY_PROPERTIES
        .into_iter()
        .filter(|p| sheen.member(p).is_some())
        .collect()
}

/// One sheen or fuzz object on a material.
#[derive(Clone, Copy)]
pub struct LayerObject<J> {
    pub material: usize,
    pub extension: &'static str,
    pub value: J,
    /// The material's `extensions` object, which holds `value`.
    pub extensions: J,
}

impl<J> LayerObject<J> {
    /// Pointer to the extension object.
    pub fn pointer(&self) -> String {
        format!("/materials/{}/extensions/{}", self.material, self.extension)
    }
}

/// Every KHR_materials_sheen and KHR_materials_fuzz object in `materials[*].extensions`.
pub fn layer_objects<'a, J: JsonView<'a>>(json: J) -> impl Iterator<Item = LayerObject<J>> + 'a {
    let materials = json.member("materials");
    let count = materials.and_then(JsonView::length).unwrap_or(0);
    (0..count).flat_map(move |i| {
        let extensions = materials
            .and_then(|m| m.element(i))
            .and_then(|m| m.member("extensions"));
        [SHEEN, FUZZ].into_iter().filter_map(move |ext| {
            let extensions = extensions?;
            let value = extensions.member(ext)?;
            Some(LayerObject {
                material: i,
                extension: ext,
                value,
                extensions,
            })
        })
    })
}

/// A texture slot that is present on a layer object.
pub struct SlotUse<J> {
    pub slot: &'static Slot,
    pub texture: TextureRef,
    pub value: J,
    material: usize,
}

impl<J> SlotUse<J> {
    /// Pointer to the textureInfo.
    pub fn pointer(&self) -> String {
        slot_pointer(self.material, self.slot)
    }
}

/// Pointer to the textureInfo of `slot` on material `material`.
pub fn slot_pointer(material: usize, slot: &Slot) -> String {
    format!(
        "/materials/{material}/extensions/{}/{}",
        slot.extension, slot.texture
    )
}

/// The texture slots a layer object fills.
pub fn slot_uses<'a, J: JsonView<'a>>(
    layer: &LayerObject<J>,
) -> impl Iterator<Item = SlotUse<J>> + 'a {
    let (value, material) = (layer.value, layer.material);
    slots_of(layer.extension).filter_map(move |slot| {
        let info = value.member(slot.texture)?;
        Some(SlotUse {
            slot,
            texture: TextureRef::read(info)?,
            value: info,
            material,
        })
    })
}

#[cfg(test)]
mod transfer_tests {
    use super::Transfer;

    #[test]
    fn srgb_decoding_pins_its_ends_and_the_segment_threshold() {
        assert_eq!(Transfer::Srgb.to_linear(0.0), 0.0);
        assert!((Transfer::Srgb.to_linear(1.0) - 1.0).abs() < 1e-15);
        // The two pieces meet at 0.04045 (to within the standard's rounding).
        let below = Transfer::Srgb.to_linear(0.04045);
        let above = ((0.04045f64 + 0.055) / 1.055).powf(2.4);
        assert!((below - 0.04045 / 12.92).abs() < 1e-18 && (below - above).abs() < 1e-7);
        assert!((Transfer::Srgb.to_linear(0.5) - 0.214_041_140_482_232_5).abs() < 1e-12);
        assert_eq!(Transfer::Linear.to_linear(0.25), 0.25);
    }
}
