//! The node hierarchy, as the Khronos glTF-Validator links it: nodes form a forest (the spec:
//! "the node hierarchy MUST be a set of disjoint strict trees"), and a scene lists only roots.
//!
//! - NODE_PARENT_OVERRIDE (error): a node listed as a child by a second parent, at the second
//!   listing (`/nodes/5/children/0`); the first parent, in document order, keeps it.
//! - NODE_LOOP (error): a node that can reach itself through `children`, at the node.
//! - SCENE_NON_ROOT_NODE (error): a scene lists a node that has a parent, at the listing.
//!
//! Indices that name no node are the references rule's findings and are skipped here.

use super::{elements, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const NODE_PARENT_OVERRIDE: Code = Code::new(
    "NODE_PARENT_OVERRIDE",
    Severity::Error,
    "A node is listed as a child of a second node; a node has at most one parent.",
);
pub const NODE_LOOP: Code = Code::new(
    "NODE_LOOP",
    Severity::Error,
    "A node is its own ancestor: following `children` from it leads back to it.",
);
pub const SCENE_NON_ROOT_NODE: Code = Code::new(
    "SCENE_NON_ROOT_NODE",
    Severity::Error,
    "A scene lists a node that is another node's child; a scene lists root nodes only.",
);

pub struct NodeTree;

impl Rule for NodeTree {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["nodes", "scenes"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&NODE_PARENT_OVERRIDE, &NODE_LOOP, &SCENE_NON_ROOT_NODE]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let Some(nodes) = json.get("nodes").and_then(|n| n.as_array()) else {
            return;
        };
        let count = nodes.len();
        // Each node's children that name a node, as read.
        let children: Vec<Vec<usize>> = nodes
            .iter()
            .map(|node| {
                elements(node.get("children"))
                    .filter_map(|c| c.as_u64())
                    .filter_map(|c| usize::try_from(c).ok())
                    .filter(|c| *c < count)
                    .collect()
            })
            .collect();
        let mut parent: Vec<Option<usize>> = vec![None; count];
        for (p, node) in nodes.iter().enumerate() {
            for (j, child) in elements(node.get("children")).enumerate() {
                let Some(c) = child.as_u64().and_then(|c| usize::try_from(c).ok()) else {
                    continue;
                };
                if c >= count {
                    continue;
                }
                match parent[c] {
                    None => parent[c] = Some(p),
                    Some(first) => out.push(Diagnostic::new(
                        &NODE_PARENT_OVERRIDE,
                        format!("/nodes/{p}/children/{j}"),
                        format!(
                            "node {c} is already a child of node {first}; a node has one parent"
                        ),
                    )),
                }
            }
        }
        for node in in_cycles(&children) {
            out.push(Diagnostic::new(
                &NODE_LOOP,
                format!("/nodes/{node}"),
                format!("node {node} is its own ancestor: its children lead back to it"),
            ));
        }
        for (s, scene) in elements(json.get("scenes")).enumerate() {
            for (j, listed) in elements(scene.get("nodes")).enumerate() {
                let Some(n) = listed.as_u64().and_then(|n| usize::try_from(n).ok()) else {
                    continue;
                };
                if let Some(Some(p)) = parent.get(n) {
                    out.push(Diagnostic::new(
                        &SCENE_NON_ROOT_NODE,
                        format!("/scenes/{s}/nodes/{j}"),
                        format!("node {n} is a child of node {p}; a scene lists root nodes only"),
                    ));
                }
            }
        }
    }
}

/// The nodes that lie on a cycle of the `children` graph, in ascending order: the members of
/// every strongly connected component of more than one node, and the nodes that list
/// themselves. Tarjan's algorithm, iterative, so that a hostile chain of a million nodes
/// cannot exhaust the stack.
fn in_cycles(children: &[Vec<usize>]) -> Vec<usize> {
    const UNSEEN: usize = usize::MAX;
    let n = children.len();
    let mut index = vec![UNSEEN; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut next = 0;
    let mut cyclic = vec![false; n];
    for start in 0..n {
        if index[start] != UNSEEN {
            continue;
        }
        // (node, how many of its children have been visited)
        let mut calls = vec![(start, 0usize)];
        index[start] = next;
        low[start] = next;
        next += 1;
        stack.push(start);
        on_stack[start] = true;
        while let Some(&mut (v, ref mut at)) = calls.last_mut() {
            if let Some(&w) = children[v].get(*at) {
                *at += 1;
                if index[w] == UNSEEN {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    calls.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            calls.pop();
            if let Some(&(u, _)) = calls.last() {
                low[u] = low[u].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                if component.len() > 1 || children[v].contains(&v) {
                    for w in component {
                        cyclic[w] = true;
                    }
                }
            }
        }
    }
    (0..n).filter(|v| cyclic[*v]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&NodeTree, text)
    }

    #[test]
    fn loops_second_parents_and_scenes_listing_children_are_found() {
        // 0 lists itself; 1 and 2 list each other; 3 → 4 → 5 → 4, where 5 is 4's second parent.
        let text = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0,1,3]}],
            "nodes":[{"children":[0]},{"children":[2]},{"children":[1]},{"children":[4]},{"children":[5]},{"children":[4]}]}"#;
        assert_eq!(
            found(text),
            [
                "NODE_PARENT_OVERRIDE /nodes/5/children/0",
                "NODE_LOOP /nodes/0",
                "NODE_LOOP /nodes/1",
                "NODE_LOOP /nodes/2",
                "NODE_LOOP /nodes/4",
                "NODE_LOOP /nodes/5",
                "SCENE_NON_ROOT_NODE /scenes/0/nodes/0",
                "SCENE_NON_ROOT_NODE /scenes/0/nodes/1",
            ]
        );
    }

    #[test]
    fn a_forest_with_scenes_of_roots_has_no_finding() {
        let text = r#"{"asset":{"version":"2.0"},"scenes":[{"nodes":[0,3]}],
            "nodes":[{"children":[1,2]},{},{"children":[9]},{}]}"#;
        assert_eq!(found(text), Vec::<String>::new());
    }

    #[test]
    fn a_long_chain_is_walked_without_recursion() {
        let n = 200_000;
        let children: Vec<Vec<usize>> = (0..n).map(|i| vec![(i + 1) % n]).collect();
        assert_eq!(in_cycles(&children).len(), n);
        let chain: Vec<Vec<usize>> = (0..n)
            .map(|i| if i + 1 < n { vec![i + 1] } else { vec![] })
            .collect();
        assert!(in_cycles(&chain).is_empty());
    }
}
