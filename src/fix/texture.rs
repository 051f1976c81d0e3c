//! Textures without effect, dropped: a sheen or fuzz texture on a layer its factor switches
//! off (or a sheenRoughnessTexture scaled by 0) contributes nothing, so the fix removes its
//! textureInfo. Unsafe because it changes the asset's meaning: whoever turns the layer on later
//! finds the texture gone (the texture and image objects stay in the document).

use super::fixers::{last_token, Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::rules::disabled_layer;

fn drop_texture(planning: &Planning, d: &Diagnostic) -> Option<Proposal> {
    let asset = planning.asset;
    asset.root().pointer(&d.pointer)?.as_object()?;
    let slot = last_token(&d.pointer)?;
    Some(Proposal {
        title: format!("remove {slot}, which has no effect"),
        edits: vec![Edit::remove(d.pointer.clone())],
    })
}

pub const SHEEN_WITHOUT_EFFECT: Fixer = Fixer {
    code: &disabled_layer::SHEEN_TEXTURE_WITHOUT_EFFECT,
    safety: Safety::Unsafe,
    about: "removes the texture from the layer",
    propose: drop_texture,
};

pub const FUZZ_WITHOUT_EFFECT: Fixer = Fixer {
    code: &disabled_layer::FUZZ_TEXTURE_WITHOUT_EFFECT,
    safety: Safety::Unsafe,
    about: "removes the texture from the layer",
    propose: drop_texture,
};
