//! Validation rules. Each rule is one unit in its own file: the codes it emits (name, default
//! severity, doc line), what it checks and why, and a test with a fixture that triggers it and a
//! twin that does not. [`REGISTRY`] is the one place rules are listed; `velvet codes`, the
//! table in docs/codes.md and report rule lists are generated from it.
//!
//! Rules read the asset and push diagnostics; they never change anything.

pub mod asset_version;
pub mod attributes;
pub mod clearcoat;
pub mod core;
pub mod declaration;
pub mod disabled_layer;
pub mod exclusions;
pub mod fallback;
pub mod fuzz_roughness_default;
pub mod fuzz_roughness_mapping;
pub mod image_size;
pub mod legacy_sheen;
pub mod placement;
pub mod references;
pub mod resources;
pub mod roughness_alpha;
pub mod schema;
pub mod texcoord;

use crate::asset::{pointer, Asset};
use crate::diagnostics::{Code, Diagnostic};
use crate::layers::{self, Slot, TextureRef};
use serde_json::Value;

/// What a rule sees: the asset and the schemas compiled for this run.
pub struct Context<'a> {
    pub asset: &'a Asset,
    pub schemas: &'a schema::Schemas,
}

impl Context<'_> {
    pub fn json(&self) -> &Value {
        &self.asset.json
    }
}

/// A validation rule.
pub trait Rule: Sync {
    /// The codes this rule may emit.
    fn codes(&self) -> &'static [&'static Code];
    /// Checks the asset, pushing what it finds.
    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>);
}

/// Every rule, in the order their findings are reported.
pub static REGISTRY: &[&dyn Rule] = &[
    &core::CoreStructure,
    &schema::SchemaCheck,
    &asset_version::AssetVersion,
    &declaration::Declaration,
    &placement::Placement,
    &exclusions::Exclusions,
    &references::References,
    &attributes::Attributes,
    &resources::Resources,
    &texcoord::TexCoords,
    &disabled_layer::DisabledLayer,
    &roughness_alpha::RoughnessAlpha,
    &image_size::ImageSize,
    &fallback::Fallback,
    &fuzz_roughness_mapping::FuzzRoughnessMapping,
    &fuzz_roughness_default::FuzzRoughnessDefault,
    &legacy_sheen::LegacySheen,
    &clearcoat::Clearcoat,
];

/// Every code velvet can emit, loader and schema codes first, then the rules' codes in
/// registry order. Each name appears once.
pub fn all_codes() -> Vec<&'static Code> {
    let mut out: Vec<&'static Code> = Vec::new();
    for code in crate::diagnostics::codes::LOADER
        .iter()
        .chain(crate::diagnostics::codes::SCHEMA)
        .copied()
        .chain(REGISTRY.iter().flat_map(|r| r.codes().iter().copied()))
    {
        if !out.iter().any(|c| c.name == code.name) {
            out.push(code);
        }
    }
    out
}

/// Looks a code up by name.
pub fn find_code(name: &str) -> Option<&'static Code> {
    all_codes().into_iter().find(|c| c.name == name)
}

/// One sheen or fuzz object on a material.
pub struct LayerObject<'a> {
    pub material: usize,
    pub extension: &'static str,
    pub value: &'a Value,
    /// Pointer to the extension object.
    pub pointer: String,
}

/// Every KHR_materials_sheen and KHR_materials_fuzz object in `materials[*].extensions`.
pub fn layer_objects(json: &Value) -> impl Iterator<Item = LayerObject<'_>> {
    layers::materials(json)
        .iter()
        .enumerate()
        .flat_map(|(i, material)| {
            [layers::SHEEN, layers::FUZZ]
                .into_iter()
                .filter_map(move |ext| {
                    let value = layers::extensions(material)?.get(ext)?;
                    Some(LayerObject {
                        material: i,
                        extension: ext,
                        value,
                        pointer: format!("/materials/{i}/extensions/{ext}"),
                    })
                })
        })
}

/// A texture slot that is present on a layer object.
pub struct SlotUse<'a> {
    pub slot: &'static Slot,
    pub texture: TextureRef,
    pub value: &'a Value,
    pub pointer: String,
}

/// The texture slots a layer object fills.
pub fn slot_uses<'a>(layer: &'a LayerObject<'a>) -> impl Iterator<Item = SlotUse<'a>> + 'a {
    layers::slots_of(layer.extension).filter_map(move |slot| {
        let value = layer.value.get(slot.texture)?;
        Some(SlotUse {
            slot,
            texture: TextureRef::read(value)?,
            value,
            pointer: pointer::join(&layer.pointer, slot.texture),
        })
    })
}

pub use crate::layers::as_index;

/// The texCoord set a textureInfo really uses: KHR_texture_transform may override it.
pub fn effective_tex_coord(texture_info: &Value) -> u64 {
    texture_info
        .pointer(&format!(
            "/extensions/{}/texCoord",
            layers::TEXTURE_TRANSFORM
        ))
        .and_then(Value::as_u64)
        .or_else(|| texture_info.get("texCoord").and_then(Value::as_u64))
        .unwrap_or(0)
}

/// The images a texture may be drawn from: `source` and the sources of image-format extensions
/// (EXT_texture_webp, KHR_texture_basisu, …), each with its pointer.
pub fn texture_sources(texture: &Value, texture_pointer: &str) -> Vec<(Option<u64>, String)> {
    let mut out = Vec::new();
    if let Some(source) = texture.get("source") {
        out.push((source.as_u64(), format!("{texture_pointer}/source")));
    }
    if let Some(exts) = texture.get("extensions").and_then(Value::as_object) {
        for (name, ext) in exts {
            if let Some(source) = ext.get("source") {
                out.push((
                    source.as_u64(),
                    format!(
                        "{texture_pointer}/extensions/{}/source",
                        pointer::escape(name)
                    ),
                ));
            }
        }
    }
    out
}
