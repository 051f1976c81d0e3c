//! A buffer view of vertex attributes or indices without a `target`, given the one its first
//! use implies: 34962 (ARRAY_BUFFER) for attributes, 34963 (ELEMENT_ARRAY_BUFFER) for indices.
//! Safe: the target only says how a loader may place the data it already reads this way (a
//! view also used the other way has BUFFER_VIEW_TARGET_OVERRIDE, and the check refuses a fix
//! that would bring one).

use super::fixers::{last_token, Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;

/// ARRAY_BUFFER and ELEMENT_ARRAY_BUFFER, as glTF numbers them.
const ARRAY_BUFFER: u64 = 34962;
const ELEMENT_ARRAY_BUFFER: u64 = 34963;

pub const TARGET: Fixer = Fixer {
    code: &crate::rules::buffer_views::BUFFER_VIEW_TARGET_MISSING,
    safety: Safety::Safe,
    about: "sets the buffer view's target its first use implies (34962 for attributes, 34963 for indices)",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        let root = asset.root();
        let accessor = root.pointer(&d.pointer)?.as_u64()?;
        let view = root
            .pointer(&format!("/accessors/{accessor}/bufferView"))?
            .as_u64()?;
        let target = if last_token(&d.pointer)? == "indices" {
            ELEMENT_ARRAY_BUFFER
        } else {
            ARRAY_BUFFER
        };
        let at = format!("/bufferViews/{view}");
        root.pointer(&at)?.as_object()?;
        Some(Proposal {
            title: format!("set buffer view {view}'s target to {target}"),
            edits: vec![Edit::set(format!("{at}/target"), serde_json::json!(target))],
        })
    },
};
