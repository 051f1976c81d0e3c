//! References: a sheen or fuzz texture index must name a texture, and that texture's source
//! (and any image-format extension's source) must name an image. A dangling index makes
//! loaders fail or silently drop the texture.

use super::{layer_objects, slot_uses, texture_sources, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use serde_json::Value;

pub const UNRESOLVED_REFERENCE: Code = Code::new(
    "UNRESOLVED_REFERENCE",
    Severity::Error,
    "An index names no object: a texture, an image, an accessor, a buffer, …",
);

pub struct References;

impl Rule for References {
    fn codes(&self) -> &'static [&'static Code] {
        &[&UNRESOLVED_REFERENCE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let count = |key: &str| json.get(key).and_then(Value::as_array).map_or(0, Vec::len) as u64;
        let (textures, images) = (count("textures"), count("images"));
        let mut checked_textures = std::collections::HashSet::new();
        for layer in layer_objects(json) {
            for slot in slot_uses(&layer) {
                let Some(index) = slot.texture.index else {
                    continue;
                };
                if index >= textures {
                    out.push(Diagnostic::new(
                        &UNRESOLVED_REFERENCE,
                        format!("{}/index", slot.pointer),
                        format!(
                            "{} names texture {index}, but the asset has {textures} textures",
                            slot.slot.texture
                        ),
                    ));
                    continue;
                }
                if !checked_textures.insert(index) {
                    continue;
                }
                let texture_pointer = format!("/textures/{index}");
                for (source, pointer) in
                    texture_sources(&json["textures"][index as usize], &texture_pointer)
                {
                    match source {
                        Some(image) if image < images => {}
                        Some(image) => out.push(Diagnostic::new(
                            &UNRESOLVED_REFERENCE,
                            pointer,
                            format!("texture {index} (used by {}) names image {image}, but the asset has {images} images", slot.slot.texture),
                        )),
                        None => {}
                    }
                }
            }
        }
    }
}
