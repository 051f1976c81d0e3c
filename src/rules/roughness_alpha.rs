//! Roughness lives in alpha: sheenRoughnessTexture and fuzzRoughnessTexture are read from the
//! alpha channel. An image without one (JPEG; grey or RGB PNG without tRNS) reads as alpha 1, so
//! the roughness equals the factor everywhere — usually a texture exported into the wrong
//! channel. Judged from the image header alone; images that cannot be read are reported once.

use super::{slot_uses, texture_sources, Context, Rule};
use crate::diagnostics::{codes, Code, Diagnostic, Severity};
use crate::layers::{self, Channels};

pub const SHEEN_ROUGHNESS_WITHOUT_ALPHA: Code = Code::new(
    "KHR_MATERIALS_SHEEN_ROUGHNESS_TEXTURE_WITHOUT_ALPHA",
    Severity::Warning,
    "sheenRoughnessTexture's image has no alpha channel; roughness will equal the factor everywhere.",
);
pub const FUZZ_ROUGHNESS_WITHOUT_ALPHA: Code = Code::new(
    "KHR_MATERIALS_FUZZ_ROUGHNESS_TEXTURE_WITHOUT_ALPHA",
    Severity::Warning,
    "fuzzRoughnessTexture's image has no alpha channel; roughness will equal the factor everywhere.",
);

pub struct RoughnessAlpha;

impl Rule for RoughnessAlpha {
    /// An image's header is read from its file, data URI or buffer view.
    fn reads(&self) -> super::Reads {
        super::Reads::Properties {
            properties: &["materials", "textures", "images", "bufferViews", "buffers"],
            except: &[("bufferViews", "target")],
        }
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &SHEEN_ROUGHNESS_WITHOUT_ALPHA,
            &FUZZ_ROUGHNESS_WITHOUT_ALPHA,
            &codes::IO_ERROR,
            &codes::URI_NOT_FOLLOWED,
            &codes::INVALID_URI,
            &codes::BUFFER_VIEW_OUT_OF_RANGE,
            &codes::IMAGE_UNRECOGNIZED_FORMAT,
            &codes::IMAGE_DATA_INVALID,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let (textures, images) = (json.get("textures"), json.get("images"));
        for layer in cx.layer_objects() {
            for slot in slot_uses(&layer) {
                if slot.slot.channels != Channels::Alpha {
                    continue;
                }
                let Some(texture) = slot.texture.index.and_then(|t| textures?.get(t as usize))
                else {
                    continue; // dangling: the references rule reports it
                };
                let texture_pointer =
                    format!("/textures/{}", slot.texture.index.unwrap_or_default());
                for (image, _) in texture_sources(texture, &texture_pointer) {
                    let Some(image) =
                        image.filter(|i| images.and_then(|a| a.get(*i as usize)).is_some())
                    else {
                        continue;
                    };
                    match cx.asset.image_header(image as usize) {
                        Ok(header) if header.has_alpha == Some(false) => {
                            let code = if layer.extension == layers::SHEEN {
                                &SHEEN_ROUGHNESS_WITHOUT_ALPHA
                            } else {
                                &FUZZ_ROUGHNESS_WITHOUT_ALPHA
                            };
                            out.push(Diagnostic::new(
                                code,
                                slot.pointer(),
                                format!(
                                    "{} reads alpha, but image {image} ({}, {} channel{}) has none: roughness will equal the factor everywhere",
                                    slot.slot.texture,
                                    header.format.name(),
                                    header.channels.unwrap_or(0),
                                    if header.channels == Some(1) { "" } else { "s" }
                                ),
                            ));
                        }
                        // An unreadable image is the resources rule's finding.
                        Ok(_) | Err(_) => {}
                    }
                }
            }
        }
    }
}
