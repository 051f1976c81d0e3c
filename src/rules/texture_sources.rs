//! The image a texture samples, by the image's media type (its `mimeType`, else its data: URI's
//! type): a core `source` is PNG or JPEG (the spec's "Images"), an EXT_texture_webp `source`
//! WebP, a KHR_texture_basisu `source` KTX2. Any other is TEXTURE_INVALID_IMAGE_MIME_TYPE (an
//! error, as in the Khronos glTF-Validator), at the `source`. An image whose type the JSON does
//! not say is left to the image header check (IMAGE_MIME_TYPE_INVALID).

use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const TEXTURE_INVALID_IMAGE_MIME_TYPE: Code = Code::new(
    "TEXTURE_INVALID_IMAGE_MIME_TYPE",
    Severity::Error,
    "A texture's source image has a media type that source cannot take (core: PNG or JPEG; EXT_texture_webp: WebP; KHR_texture_basisu: KTX2).",
);

/// The media types each kind of `source` takes: the core's, then each extension's.
const SOURCES: &[(Option<&str>, &[&str])] = &[
    (None, &["image/jpeg", "image/png"]),
    (Some("EXT_texture_webp"), &["image/webp"]),
    (Some("KHR_texture_basisu"), &["image/ktx2"]),
];

/// The media type the JSON gives an image: its mimeType, else its data: URI's type.
fn media_type(image: Node) -> Option<String> {
    if let Some(mime) = image.get("mimeType").and_then(|m| m.as_str()) {
        return Some(mime.into_owned());
    }
    let uri = image.get("uri")?.as_str()?;
    let header = uri.strip_prefix("data:")?.split(',').next()?;
    let media_type = header.split(';').next()?;
    (!media_type.is_empty()).then(|| media_type.to_ascii_lowercase())
}

pub struct TextureSources;

impl Rule for TextureSources {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["textures", "images"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&TEXTURE_INVALID_IMAGE_MIME_TYPE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let Some(images) = json.get("images").and_then(|i| i.as_array()) else {
            return;
        };
        for (t, texture) in elements(json.get("textures")).enumerate() {
            for (extension, allowed) in SOURCES {
                let (holder, at) = match extension {
                    None => (Some(texture), format!("/textures/{t}/source")),
                    Some(name) => (
                        texture.get("extensions").and_then(|e| e.get(*name)),
                        format!("/textures/{t}/extensions/{name}/source"),
                    ),
                };
                let Some(image) = holder
                    .and_then(|h| h.get("source"))
                    .and_then(|s| s.as_u64())
                    .and_then(|s| usize::try_from(s).ok())
                    .and_then(|s| images.get(s))
                else {
                    continue;
                };
                let Some(mime) = media_type(image) else {
                    continue;
                };
                if !allowed.contains(&mime.as_str()) {
                    out.push(Diagnostic::new(
                        &TEXTURE_INVALID_IMAGE_MIME_TYPE,
                        at,
                        format!(
                            "the source image is {mime}; this source takes {}",
                            allowed.join(" or ")
                        ),
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_source_takes_its_own_media_types() {
        let text = r#"{"asset":{"version":"2.0"},"extensionsUsed":["EXT_texture_webp"],
            "images":[{"uri":"data:image/png;base64,AA=="},{"uri":"data:image/webp;base64,AA=="},
                      {"uri":"a.bin","mimeType":"image/webp"},{"uri":"b.png"}],
            "textures":[{"source":1,"extensions":{"EXT_texture_webp":{"source":0}}},
                        {"source":3,"extensions":{"EXT_texture_webp":{"source":2}}},{"source":0}]}"#;
        let found = crate::rules::findings_of(&TextureSources, text);
        assert_eq!(
            found,
            [
                "TEXTURE_INVALID_IMAGE_MIME_TYPE /textures/0/source",
                "TEXTURE_INVALID_IMAGE_MIME_TYPE /textures/0/extensions/EXT_texture_webp/source",
            ]
        );
    }
}
