//! Skins, as far as the JSON tells: a skinned mesh on a node with a parent (the parent's
//! transform does not move a skinned mesh, which surprises authors: a warning, as in the Khronos
//! validator), and an inverseBindMatrices accessor with fewer elements than the skin has joints
//! (the spec's MUST; the matrices' values are binary data, left to a binary-data validator).

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const NODE_SKINNED_MESH_NON_ROOT: Code = Code::new(
    "NODE_SKINNED_MESH_NON_ROOT",
    Severity::Warning,
    "A node with a skinned mesh is the child of another node; parent transforms do not affect a skinned mesh.",
);
pub const INVALID_IBM_ACCESSOR_COUNT: Code = Code::new(
    "INVALID_IBM_ACCESSOR_COUNT",
    Severity::Error,
    "A skin's inverseBindMatrices accessor has fewer elements than the skin has joints.",
);

pub struct Skins;

impl Rule for Skins {
    fn codes(&self) -> &'static [&'static Code] {
        &[&NODE_SKINNED_MESH_NON_ROOT, &INVALID_IBM_ACCESSOR_COUNT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        // Most documents have no skin at all.
        if json.members_named("skin").next().is_none() && json.get("skins").is_none() {
            return;
        }
        let nodes: Vec<_> = super::elements(json.get("nodes")).collect();
        let mut has_parent = vec![false; nodes.len()];
        for node in &nodes {
            for child in super::elements(node.get("children")) {
                if let Some(slot) = child
                    .as_u64()
                    .and_then(|c| usize::try_from(c).ok())
                    .and_then(|c| has_parent.get_mut(c))
                {
                    *slot = true;
                }
            }
        }
        for (i, node) in nodes.iter().enumerate() {
            if has_parent[i] && node.get("skin").is_some() && node.get("mesh").is_some() {
                out.push(Diagnostic::new(
                    &NODE_SKINNED_MESH_NON_ROOT,
                    format!("/nodes/{i}"),
                    format!(
                        "node {i} draws a skinned mesh but has a parent; the parent's transform does not move a skinned mesh"
                    ),
                ));
            }
        }
        let accessors = json.get("accessors");
        for (s, skin) in super::elements(json.get("skins")).enumerate() {
            let Some(joints) = skin.get("joints").and_then(|j| j.as_array()) else {
                continue;
            };
            let Some(accessor) = skin.get("inverseBindMatrices").and_then(|a| a.as_u64()) else {
                continue;
            };
            let Some(count) = usize::try_from(accessor)
                .ok()
                .and_then(|a| accessors?.get(a))
                .and_then(|a| a.get("count"))
                .and_then(|c| c.as_u64())
            else {
                continue; // a dangling index is the references rule's finding
            };
            if count < joints.len() as u64 {
                out.push(Diagnostic::new(
                    &INVALID_IBM_ACCESSOR_COUNT,
                    format!("/skins/{s}/inverseBindMatrices"),
                    format!(
                        "accessor {accessor} holds {count} matrices; the skin's {} joints need at least {}",
                        joints.len(),
                        joints.len()
                    ),
                ));
            }
        }
    }
}
