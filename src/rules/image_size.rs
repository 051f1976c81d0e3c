//! Images too large to bake: a sheen or fuzz texture whose image header declares more pixels
//! than `--max-image-pixels` would be refused by `velvet bake` and `velvet migrate --report`
//! before decoding (see [`crate::asset::limits`]). Validation reads the header only, and says
//! so here, so that a repository check finds the image before a bake run fails on it.
//! Images whose header cannot be read are left to the rules that need the header (they report
//! why); this rule does not repeat that.

use super::{slot_uses, texture_sources, Context, Rule};
use crate::diagnostics::{codes, Code, Diagnostic};
use std::collections::BTreeSet;

pub struct ImageSize;

impl Rule for ImageSize {
    /// An image's header is read from its file, data URI or buffer view.
    fn reads(&self) -> super::Reads {
        super::Reads::Properties {
            properties: &[
                "materials",
                "textures",
                "images",
                "bufferViews",
                "buffers",
                "extensionsUsed",
            ],
            except: &[("bufferViews", "target")],
        }
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&codes::IMAGE_TOO_LARGE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let mut textures = BTreeSet::new();
        for layer in cx.layer_objects() {
            textures.extend(slot_uses(&layer).filter_map(|slot| slot.texture.index));
        }
        let mut images = BTreeSet::new();
        let texture_list = json.get("textures");
        for index in textures {
            let Some(texture) = texture_list.and_then(|t| t.get(index as usize)) else {
                continue;
            };
            for (image, _) in texture_sources(texture, &format!("/textures/{index}")) {
                images.extend(image);
            }
        }
        let count = json
            .get("images")
            .and_then(|i| i.as_array())
            .map_or(0, |a| a.len());
        for image in images.into_iter().filter(|&i| (i as usize) < count) {
            let Ok(header) = cx.asset.image_header(image as usize) else {
                continue;
            };
            if let Some(message) = cx
                .asset
                .options
                .image_too_large(header.width, header.height)
            {
                out.push(Diagnostic::new(
                    &codes::IMAGE_TOO_LARGE,
                    format!("/images/{image}"),
                    format!("image {image}: {message}"),
                ));
            }
        }
    }
}
