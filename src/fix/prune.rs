//! Unused textures, images and samplers removed, as `gltf-transform prune` removes them, and
//! every index after a removed element renumbered. One fix repairs every UNUSED_OBJECT finding
//! of a document: removals renumber each other's references, so they are planned together
//! (each finding's fixer proposes the same edits, and the planner makes them one fix). An
//! image or sampler that only removed textures refer to goes with them. Unsafe: an extension
//! velvet does not know, or an application's `extras`, may name an element by its index.

use super::fixers::{Fixer, Planning, Proposal};
use crate::asset::tape::Node;
use crate::asset::Asset;
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::rules::references::{index_sites, PRUNED};

/// Whether `at` lies within an element of [`PRUNED`] that `gone` says goes.
fn within_gone(at: &str, gone: &[Vec<bool>]) -> bool {
    PRUNED.iter().enumerate().any(|(k, array)| {
        at.strip_prefix(array)
            .and_then(|rest| rest.strip_prefix('/'))
            .and_then(|rest| rest.split('/').next()?.parse::<usize>().ok())
            .is_some_and(|i| gone[k].get(i).copied().unwrap_or(false))
    })
}

/// For each array of [`PRUNED`], which elements go: those nothing refers to, then those only
/// elements that go refer to, until nothing more goes.
fn removed(root: Node, sites: &[(String, &'static str, u64)]) -> Vec<Vec<bool>> {
    let len = |array: &str| {
        root.pointer(array)
            .and_then(|a| a.as_array())
            .map_or(0, |a| a.len())
    };
    let mut gone: Vec<Vec<bool>> = PRUNED.iter().map(|a| vec![false; len(a)]).collect();
    loop {
        let mut used: Vec<Vec<bool>> = gone.iter().map(|g| vec![false; g.len()]).collect();
        for (at, target, index) in sites {
            // A reference from an element that goes does not keep anything.
            if within_gone(at, &gone) {
                continue;
            }
            if let Some(k) = PRUNED.iter().position(|a| a == target) {
                if let Some(slot) = usize::try_from(*index)
                    .ok()
                    .and_then(|i| used[k].get_mut(i))
                {
                    *slot = true;
                }
            }
        }
        let mut more = false;
        for (g, u) in gone.iter_mut().zip(&used) {
            for (gone, used) in g.iter_mut().zip(u) {
                if !*gone && !*used {
                    *gone = true;
                    more = true;
                }
            }
        }
        if !more {
            return gone;
        }
    }
}

fn prune(planning: &Planning, d: &Diagnostic) -> Option<Proposal> {
    PRUNED
        .iter()
        .any(|a| {
            d.pointer
                .strip_prefix(a)
                .is_some_and(|r| r.starts_with('/'))
        })
        .then_some(())?;
    planning
        .prune
        .get_or_init(|| prune_document(planning.asset))
        .clone()
}

/// The removals of every unused element of [`PRUNED`], and the renumbering they need.
fn prune_document(asset: &Asset) -> Option<Proposal> {
    let root = asset.root();
    let sites = index_sites(root);
    let gone = removed(root, &sites);
    let mut edits = Vec::new();
    for (at, target, index) in &sites {
        let Some(k) = PRUNED.iter().position(|a| a == target) else {
            continue;
        };
        let Ok(index) = usize::try_from(*index) else {
            continue;
        };
        if within_gone(at, &gone) || index >= gone[k].len() {
            continue;
        }
        let before = gone[k][..index].iter().filter(|g| **g).count();
        if before > 0 {
            edits.push(Edit::set(at.clone(), serde_json::json!(index - before)));
        }
    }
    let mut named = Vec::new();
    for (array, g) in PRUNED.iter().zip(&gone) {
        let list: Vec<String> = (0..g.len())
            .filter(|&i| g[i])
            .map(|i| i.to_string())
            .collect();
        if !list.is_empty() {
            named.push(format!("{} {}", &array[1..], list.join(", ")));
        }
        for i in (0..g.len()).filter(|&i| g[i]) {
            edits.push(Edit::remove(format!("{array}/{i}")));
        }
    }
    (!named.is_empty()).then(|| Proposal {
        title: format!("remove the unused {}", named.join("; ")),
        edits,
    })
}

pub const UNUSED: Fixer = Fixer {
    code: &crate::rules::references::UNUSED_OBJECT,
    safety: Safety::Unsafe,
    about: "removes every unused texture, image and sampler (and the images and samplers only they used), renumbering the references",
    propose: prune,
};
