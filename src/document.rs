//! A glTF document's parts as every command reads them, through any [`JsonView`] (the index or
//! a value): arrays that may be absent, the materials, the texture-coordinate set a textureInfo
//! really uses, the images a texture may be drawn from. Rules, bakes, migrations and outputs
//! all read these; none of them owns them.

use crate::asset::pointer;
use crate::asset::tape::{JsonView, Node};

/// The object at the position `index` names in `array`, when `index` is an index and the
/// element there is an object: how a reference from one part of a document to another is
/// followed.
pub fn element_at<'a>(array: Option<Node<'a>>, index: Option<Node<'a>>) -> Option<Node<'a>> {
    let i = usize::try_from(index?.as_u64()?).ok()?;
    array?.as_array()?.get(i).filter(|o| o.is_object())
}

/// Whether the document's `extensionsUsed` names `extension`.
pub fn declares(json: Node<'_>, extension: &str) -> bool {
    elements(json.get("extensionsUsed")).any(|e| e.is_str(extension))
}

/// The elements of an array that may be absent or not an array (then there are none).
pub fn elements(array: Option<Node<'_>>) -> impl Iterator<Item = Node<'_>> {
    array
        .and_then(|a| a.as_array())
        .into_iter()
        .flat_map(|a| a.iter())
}

/// The materials array's elements.
pub fn materials(json: Node<'_>) -> impl Iterator<Item = Node<'_>> {
    elements(json.get("materials"))
}

/// The texCoord set a textureInfo really uses: KHR_texture_transform may override it.
pub fn effective_tex_coord<'a>(texture_info: impl JsonView<'a>) -> u64 {
    texture_info
        .member("extensions")
        .and_then(|e| e.member(crate::layers::TEXTURE_TRANSFORM))
        .and_then(|t| t.member("texCoord"))
        .and_then(JsonView::unsigned)
        .or_else(|| texture_info.member("texCoord").and_then(JsonView::unsigned))
        .unwrap_or(0)
}

/// The images a texture may be drawn from: `source` and the sources of image-format extensions
/// (EXT_texture_webp, KHR_texture_basisu, …), each with its pointer.
pub fn texture_sources<'a>(
    texture: impl JsonView<'a>,
    texture_pointer: &str,
) -> Vec<(Option<u64>, String)> {
    let mut out = Vec::new();
    if let Some(source) = texture.member("source") {
        out.push((source.unsigned(), format!("{texture_pointer}/source")));
    }
    if let Some(exts) = texture.member("extensions").and_then(JsonView::members) {
        for (name, ext) in exts {
            if let Some(source) = ext.member("source") {
                out.push((
                    source.unsigned(),
                    format!(
                        "{texture_pointer}/extensions/{}/source",
                        pointer::escape(&name)
                    ),
                ));
            }
        }
    }
    out
}
