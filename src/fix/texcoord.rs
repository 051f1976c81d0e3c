//! A texture that reads a texture coordinate set its primitive lacks, pointed at the highest
//! set the primitive has (TEXCOORD_0 when it has only that). Unsafe: the texture is now mapped
//! by other coordinates, which the finding implies but cannot choose for the artist. Where
//! KHR_texture_transform overrides texCoord, the override is set. The fix is checked like every
//! other: should another primitive of the material lack that set, it is refused.

use super::fixers::{Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::rules::texcoord::MESH_PRIMITIVE_TOO_FEW_TEXCOORDS;

/// The textureInfo the finding's message names ("material 0's /materials/0/…Texture reads
/// TEXCOORD_1, …").
fn texture_info(message: &str) -> Option<&str> {
    let (_, rest) = message.split_once("'s ")?;
    let (pointer, _) = rest.split_once(" reads ")?;
    pointer.starts_with("/materials/").then_some(pointer)
}

fn retarget(planning: &Planning, d: &Diagnostic) -> Option<Proposal> {
    let asset = planning.asset;
    let root = asset.root();
    let info = texture_info(&d.message)?;
    root.pointer(info)?.as_object()?;
    let primitive = d.pointer.strip_suffix("/material")?;
    let attributes = root.pointer(&format!("{primitive}/attributes"))?;
    let highest = attributes
        .as_object()?
        .keys()
        .filter_map(|k| k.strip_prefix("TEXCOORD_")?.parse::<u64>().ok())
        .max()?;
    let transform = format!("{info}/extensions/KHR_texture_transform");
    let at = match root.pointer(&format!("{transform}/texCoord")) {
        Some(_) => format!("{transform}/texCoord"),
        None => format!("{info}/texCoord"),
    };
    Some(Proposal {
        title: format!("read TEXCOORD_{highest}, which the primitive has"),
        edits: vec![Edit::set(at, serde_json::json!(highest))],
    })
}

pub const TEXCOORD: Fixer = Fixer {
    code: &MESH_PRIMITIVE_TOO_FEW_TEXCOORDS,
    safety: Safety::Unsafe,
    about: "points the texture at the highest texture coordinate set the primitive has",
    propose: retarget,
};

#[cfg(test)]
mod tests {
    #[test]
    fn the_texture_info_is_read_from_the_message() {
        assert_eq!(
            super::texture_info("material 0's /materials/0/extensions/KHR_materials_sheen/sheenColorTexture reads TEXCOORD_1, which this primitive does not have"),
            Some("/materials/0/extensions/KHR_materials_sheen/sheenColorTexture")
        );
    }
}
