//! A .glb's container rebuilt: the header's length, each chunk's length and padding as the
//! GLB format lays them out, whatever the file had (bytes after the declared length, a length
//! not a multiple of 4, JSON padded with NUL bytes, a header length that is not the file's).
//! `--fix` rebuilds the container of every .glb it writes; these fixes ask for it where no
//! edit of the JSON chunk does. They have no edit of the JSON text: a consumer applying a
//! report's fixes frames the JSON chunk again, as the report says, and that is the fix.
//!
//! Safe where the bytes dropped or added are ones no loader reads (trailing bytes, padding);
//! unsafe for a header that declares more bytes than the file holds, since the file may have
//! been cut at a chunk's end and the rebuilt header no longer says so.

use super::fixers::{Fixer, Planning, Proposal};
use crate::asset::Container;
use crate::diagnostics::{codes, Diagnostic, Safety};

fn rebuild(planning: &Planning, _: &Diagnostic) -> Option<Proposal> {
    let asset = planning.asset;
    (asset.container == Container::Glb).then(|| Proposal {
        title: "rebuild the GLB container (header length, chunk lengths and padding)".to_string(),
        edits: Vec::new(),
    })
}

/// The codes a rebuilt container repairs.
pub const CODES: [&str; 4] = [
    codes::GLB_EXTRA_DATA.name,
    codes::GLB_CHUNK_LENGTH_UNALIGNED.name,
    codes::GLB_INVALID_PADDING.name,
    codes::GLB_LENGTH_MISMATCH.name,
];

pub const EXTRA_DATA: Fixer = Fixer {
    code: &codes::GLB_EXTRA_DATA,
    safety: Safety::Safe,
    about: "rebuilds the container without the bytes after its declared length",
    propose: rebuild,
};

pub const UNALIGNED: Fixer = Fixer {
    code: &codes::GLB_CHUNK_LENGTH_UNALIGNED,
    safety: Safety::Safe,
    about: "rebuilds the container with each chunk padded to a multiple of 4 bytes",
    propose: rebuild,
};

pub const PADDING: Fixer = Fixer {
    code: &codes::GLB_INVALID_PADDING,
    safety: Safety::Safe,
    about: "rebuilds the container with the JSON chunk padded with spaces",
    propose: rebuild,
};

pub const LENGTH: Fixer = Fixer {
    code: &codes::GLB_LENGTH_MISMATCH,
    safety: Safety::Unsafe,
    about: "rebuilds the container with the header's length the file's",
    propose: rebuild,
};
