//! The fuzz roughness default, written out: an active fuzz layer without fuzzRoughnessFactor
//! gets the value velvet assumes (the draft's table, 0.5), so that every reader reads what
//! velvet reads. Safe: velvet's own reading of the file, and its migration, do not change.

use super::fixers::{Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::layers;
use crate::rules::fuzz_roughness_default::FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS;

pub const EXPLICIT_DEFAULT: Fixer = Fixer {
    code: &FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS,
    safety: Safety::Safe,
    about: "writes fuzzRoughnessFactor 0.5, the value velvet assumes",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        let layer = asset.root().pointer(&d.pointer)?.as_object()?;
        if layer.get("fuzzRoughnessFactor").is_some() {
            return None;
        }
        Some(Proposal {
            title: format!(
                "write fuzzRoughnessFactor {} (the value velvet assumes)",
                layers::FUZZ_ROUGHNESS_DEFAULT_TABLE
            ),
            edits: vec![Edit::set(
                format!("{}/fuzzRoughnessFactor", d.pointer),
                serde_json::json!(layers::FUZZ_ROUGHNESS_DEFAULT_TABLE),
            )],
        })
    },
};
