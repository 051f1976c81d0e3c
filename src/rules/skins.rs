//! Skins, as far as the JSON tells (the Khronos glTF-Validator's skin checks, with its codes,
//! severities and pointers; the spec's "Skins" section). The matrices' values are binary data
//! and are not read here.
//!
//! - NODE_SKINNED_MESH_NON_ROOT (information): a skinned node with a parent, whose transform
//!   does not move a skinned mesh.
//! - NODE_SKINNED_MESH_PARENT_TRANSFORMS (warning): such a parent, or an ancestor, has a
//!   transform, which will be ignored.
//! - INVALID_IBM_ACCESSOR_COUNT (error): fewer inverse bind matrices than joints.
//! - SKIN_IBM_INVALID_FORMAT (error): inverse bind matrices that are not float MAT4.
//! - SKIN_NO_COMMON_ROOT (error): joints that do not share one root node; at `joints`.
//! - SKIN_SKELETON_INVALID (error): a `skeleton` that is not an ancestor (or itself one) of every
//!   joint.
//! - NODE_SKIN_NO_SCENE (error): a skinned node in a scene that does not hold its joints.

use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const NODE_SKINNED_MESH_NON_ROOT: Code = Code::new(
    "NODE_SKINNED_MESH_NON_ROOT",
    Severity::Info,
    "A node with a skinned mesh is the child of another node; parent transforms do not affect a skinned mesh.",
);
pub const NODE_SKINNED_MESH_PARENT_TRANSFORMS: Code = Code::new(
    "NODE_SKINNED_MESH_PARENT_TRANSFORMS",
    Severity::Warning,
    "A node with a skinned mesh has ancestors with transforms, which do not affect a skinned mesh.",
);
pub const INVALID_IBM_ACCESSOR_COUNT: Code = Code::new(
    "INVALID_IBM_ACCESSOR_COUNT",
    Severity::Error,
    "A skin's inverseBindMatrices accessor has fewer elements than the skin has joints.",
);
pub const SKIN_IBM_INVALID_FORMAT: Code = Code::new(
    "SKIN_IBM_INVALID_FORMAT",
    Severity::Error,
    "A skin's inverseBindMatrices accessor does not hold float MAT4 matrices.",
);
pub const SKIN_NO_COMMON_ROOT: Code = Code::new(
    "SKIN_NO_COMMON_ROOT",
    Severity::Error,
    "A skin's joints do not have a common root node.",
);
pub const SKIN_SKELETON_INVALID: Code = Code::new(
    "SKIN_SKELETON_INVALID",
    Severity::Error,
    "A skin's skeleton node is not a common root of its joints.",
);
pub const NODE_SKIN_NO_SCENE: Code = Code::new(
    "NODE_SKIN_NO_SCENE",
    Severity::Error,
    "A node with a skinned mesh is in a scene that does not contain its skin's joints.",
);

pub struct Skins;

/// The node hierarchy as parents: each node's first parent, in document order, and each
/// node's root.
struct Hierarchy<'a> {
    nodes: Vec<Node<'a>>,
    parent: Vec<Option<usize>>,
    /// The root of each node's tree; `None` for a node on or below a loop.
    roots: Vec<Option<usize>>,
}

impl<'a> Hierarchy<'a> {
    fn read(json: Node<'a>) -> Hierarchy<'a> {
        let nodes: Vec<Node> = elements(json.get("nodes")).collect();
        let mut parent = vec![None; nodes.len()];
        for (p, node) in nodes.iter().enumerate() {
            for child in elements(node.get("children")) {
                if let Some(slot) = child
                    .as_u64()
                    .and_then(|c| usize::try_from(c).ok())
                    .and_then(|c| parent.get_mut(c))
                {
                    slot.get_or_insert(p);
                }
            }
        }
        let roots = roots_of(&parent);
        Hierarchy {
            nodes,
            parent,
            roots,
        }
    }

    fn node(&self, index: Option<Node>) -> Option<usize> {
        let i = usize::try_from(index?.as_u64()?).ok()?;
        (i < self.nodes.len()).then_some(i)
    }

    /// `node`'s ancestors, nearest first; the walk stops at a loop (the node tree rule's).
    fn ancestors(&self, node: usize) -> impl Iterator<Item = usize> + '_ {
        let mut at = Some(node);
        let mut steps = 0;
        std::iter::from_fn(move || {
            let next = self.parent[at?]?;
            steps += 1;
            if steps > self.nodes.len() {
                return None;
            }
            at = Some(next);
            Some(next)
        })
    }

    /// The root of `node`'s tree; `None` on a loop.
    fn root(&self, node: usize) -> Option<usize> {
        self.roots[node]
    }
}

/// Each node's root, every node walked up once: a node's walk stops at the first node whose
/// root is known and hands that root to every node it passed (asking each joint for its root
/// would walk a deep chain once per joint). A walk longer than the node count is a loop, and
/// every node on it gets `None`.
fn roots_of(parent: &[Option<usize>]) -> Vec<Option<usize>> {
    let mut known: Vec<Option<Option<usize>>> = vec![None; parent.len()];
    let mut walked = Vec::new();
    for start in 0..parent.len() {
        let mut at = start;
        let root = loop {
            if let Some(root) = known[at] {
                break root;
            }
            if walked.len() > parent.len() {
                break None;
            }
            walked.push(at);
            match parent[at] {
                None => break Some(at),
                Some(up) => at = up,
            }
        };
        for node in walked.drain(..) {
            known[node] = Some(root);
        }
    }
    known.into_iter().map(Option::flatten).collect()
}

impl Rule for Skins {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["nodes", "skins", "scenes", "accessors", "meshes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &NODE_SKINNED_MESH_NON_ROOT,
            &NODE_SKINNED_MESH_PARENT_TRANSFORMS,
            &INVALID_IBM_ACCESSOR_COUNT,
            &SKIN_IBM_INVALID_FORMAT,
            &SKIN_NO_COMMON_ROOT,
            &SKIN_SKELETON_INVALID,
            &NODE_SKIN_NO_SCENE,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        // Most documents have no skin at all.
        if json.members_named("skin").next().is_none() && json.get("skins").is_none() {
            return;
        }
        let tree = Hierarchy::read(json);
        let skins: Vec<Node> = elements(json.get("skins")).collect();
        // Each skin's joints' common root, where they have one.
        let mut joint_roots: Vec<Option<usize>> = Vec::with_capacity(skins.len());
        let accessors = json.get("accessors");
        for (s, skin) in skins.iter().enumerate() {
            let at = format!("/skins/{s}");
            let joints: Vec<Option<usize>> = elements(skin.get("joints"))
                .map(|j| tree.node(Some(j)))
                .collect();
            let roots: Option<Vec<usize>> = joints
                .iter()
                .map(|j| j.and_then(|j| tree.root(j)))
                .collect();
            let common = roots.and_then(|roots| {
                let first = *roots.first()?;
                roots.iter().all(|r| *r == first).then_some(first)
            });
            if common.is_none() && !joints.is_empty() {
                out.push(Diagnostic::new(
                    &SKIN_NO_COMMON_ROOT,
                    format!("{at}/joints"),
                    "the joints do not have a common root node",
                ));
            }
            joint_roots.push(common);
            if let Some(skeleton) = tree.node(skin.get("skeleton")) {
                let covers = |joint: usize| {
                    joint == skeleton || tree.ancestors(joint).any(|a| a == skeleton)
                };
                if !joints.iter().flatten().all(|j| covers(*j)) {
                    out.push(Diagnostic::new(
                        &SKIN_SKELETON_INVALID,
                        format!("{at}/skeleton"),
                        format!("node {skeleton} is not an ancestor of every joint"),
                    ));
                }
            }
            let Some(index) = skin.get("inverseBindMatrices").and_then(|a| a.as_u64()) else {
                continue;
            };
            let Some(accessor) = usize::try_from(index)
                .ok()
                .and_then(|a| accessors?.get(a))
                .filter(|a| a.is_object())
            else {
                continue; // a dangling index is the references rule's finding
            };
            let mat4 = accessor.get("type").is_none_or(|t| t.is_str("MAT4"))
                && accessor
                    .get("componentType")
                    .is_none_or(|c| c.as_u64() == Some(5126));
            if !mat4 {
                out.push(Diagnostic::new(
                    &SKIN_IBM_INVALID_FORMAT,
                    format!("{at}/inverseBindMatrices"),
                    "inverse bind matrices must be float MAT4",
                ));
            }
            if let Some(count) = accessor.get("count").and_then(|c| c.as_u64()) {
                if count < joints.len() as u64 {
                    out.push(Diagnostic::new(
                        &INVALID_IBM_ACCESSOR_COUNT,
                        format!("{at}/inverseBindMatrices"),
                        format!(
                            "accessor {index} holds {count} matrices; the skin's {} joints need at least {}",
                            joints.len(),
                            joints.len()
                        ),
                    ));
                }
            }
        }
        let scenes: Vec<Vec<usize>> = elements(json.get("scenes"))
            .map(|s| {
                elements(s.get("nodes"))
                    .filter_map(|n| tree.node(Some(n)))
                    .collect()
            })
            .collect();
        let transformed = |n: usize| {
            ["translation", "rotation", "scale", "matrix"]
                .iter()
                .any(|k| tree.nodes[n].get(*k).is_some())
        };
        for (i, node) in tree.nodes.iter().enumerate() {
            let Some(skin) = node
                .get("skin")
                .and_then(|s| s.as_u64())
                .and_then(|s| usize::try_from(s).ok())
            else {
                continue;
            };
            if node.get("mesh").is_none() {
                continue;
            }
            if let Some(parent) = tree.parent[i] {
                out.push(Diagnostic::new(
                    &NODE_SKINNED_MESH_NON_ROOT,
                    format!("/nodes/{i}"),
                    format!(
                        "node {i} draws a skinned mesh but has a parent (node {parent}); the parent's transform does not move a skinned mesh"
                    ),
                ));
                if tree.ancestors(i).any(transformed) {
                    out.push(Diagnostic::new(
                        &NODE_SKINNED_MESH_PARENT_TRANSFORMS,
                        format!("/nodes/{i}"),
                        "an ancestor of the node has a transform, which does not move its skinned mesh",
                    ));
                }
            }
            let (Some(Some(joints_root)), Some(root)) = (joint_roots.get(skin), tree.root(i))
            else {
                continue;
            };
            if scenes
                .iter()
                .any(|scene| scene.contains(&root) && !scene.contains(joints_root))
            {
                out.push(Diagnostic::new(
                    &NODE_SKIN_NO_SCENE,
                    format!("/nodes/{i}"),
                    format!("a scene draws node {i} without its skin's joints (rooted at node {joints_root})"),
                ));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Skins, text)
    }

    /// Roots through a chain, a branch and a loop: 0 ← 1 ← 2 and 0 ← 3; 4 ⇄ 5 with 6 below 5.
    #[test]
    fn roots_are_found_once_a_node_and_a_loop_has_none() {
        let parent = [None, Some(0), Some(1), Some(0), Some(5), Some(4), Some(5)];
        assert_eq!(
            roots_of(&parent),
            [Some(0), Some(0), Some(0), Some(0), None, None, None]
        );
        // A 100,000-node chain, each node's root found in one pass.
        let chain: Vec<Option<usize>> = (0..100_000usize).map(|i| i.checked_sub(1)).collect();
        assert!(roots_of(&chain).iter().all(|r| *r == Some(0)));
    }

    #[test]
    fn skins_whose_joints_skeleton_or_scene_do_not_hold_together_are_found() {
        let text = r#"{"asset":{"version":"2.0"},
            "scenes":[{"nodes":[4,3]}],
            "nodes":[{"children":[1]},{},{},{"translation":[1,0,0],"children":[5]},{},{"skin":0,"mesh":0}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
            "accessors":[{"componentType":5126,"count":1,"type":"MAT3"}],
            "skins":[{"joints":[0,1],"skeleton":1,"inverseBindMatrices":0},{"joints":[1,2]},{"joints":[7]}]}"#;
        assert_eq!(
            found(text),
            [
                "SKIN_SKELETON_INVALID /skins/0/skeleton",
                "SKIN_IBM_INVALID_FORMAT /skins/0/inverseBindMatrices",
                "INVALID_IBM_ACCESSOR_COUNT /skins/0/inverseBindMatrices",
                "SKIN_NO_COMMON_ROOT /skins/1/joints",
                "SKIN_NO_COMMON_ROOT /skins/2/joints",
                "NODE_SKINNED_MESH_NON_ROOT /nodes/5",
                "NODE_SKINNED_MESH_PARENT_TRANSFORMS /nodes/5",
                "NODE_SKIN_NO_SCENE /nodes/5",
            ]
        );
    }
}
