//! The pre-ratification sheen draft, upgraded: sheenFactor, sheenColor and sheenTexture become
//! the ratified sheenColorFactor, sheenRoughnessFactor and sheenColorTexture, by migrate's own
//! upgrade (`crate::migrate::legacy`, reached through migrate's plan of the material). Unsafe:
//! ratified loaders, which ignored the draft, now show a sheen. Only the upgrade is taken (not
//! the conversion to fuzz that a migration goes on to), and only where it needs no texture
//! baked (a roughness read from a metallicRoughnessTexture is left to `velvet migrate`).

use super::fixers::{Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::layers;
use crate::migrate::plan::plan_material;
use crate::migrate::{Conversion, Options};
use crate::rules::legacy_sheen::SHEEN_LEGACY_DRAFT;

fn upgrade(planning: &Planning, d: &Diagnostic) -> Option<Proposal> {
    let asset = planning.asset;
    let index = d
        .pointer
        .strip_prefix("/materials/")?
        .split('/')
        .next()
        .and_then(crate::asset::pointer::array_index)?;
    let upgrades = || planning.upgrades.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(proposal) = upgrades().get(&index) {
        return proposal.clone();
    }
    let proposal = upgrade_material(asset, index, &planning.primitives);
    upgrades().insert(index, proposal.clone());
    proposal
}

/// The draft sheen of material `index` upgraded, if it needs no texture baked.
fn upgrade_material(
    asset: &crate::asset::Asset,
    index: usize,
    primitives: &crate::migrate::plan::Primitives,
) -> Option<Proposal> {
    let plan = plan_material(asset, index, &Options::default(), primitives)?;
    if !plan.conversions.contains(&Conversion::LegacyUpgrade) || !plan.bakes.is_empty() {
        return None;
    }
    let sheen = format!("/materials/{index}/extensions/{}/", layers::SHEEN);
    let edits: Vec<Edit> = plan
        .edits
        .into_iter()
        .filter(|e| match e {
            Edit::Set { pointer, .. }
            | Edit::Replace { pointer, .. }
            | Edit::Remove { pointer } => pointer.starts_with(&sheen),
            Edit::DeclareUsed { .. } => false,
        })
        .collect();
    (!edits.is_empty()).then(|| Proposal {
        title: "upgrade the draft sheen to the ratified KHR_materials_sheen".to_string(),
        edits,
    })
}

pub const UPGRADE: Fixer = Fixer {
    code: &SHEEN_LEGACY_DRAFT,
    safety: Safety::Unsafe,
    about: "upgrades the draft's properties to ratified sheen as `velvet migrate` does",
    propose: upgrade,
};
