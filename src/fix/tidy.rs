//! Properties that say nothing, removed (safe: a conforming loader reads the asset as before):
//!
//! - an `alphaCutoff` on a material whose alphaMode is not MASK, which the spec says is
//!   ignored (MATERIAL_ALPHA_CUTOFF_INVALID_MODE);
//! - an element given twice in a list that is a set (DUPLICATE_ELEMENTS): an extension in
//!   `extensionsUsed` or `extensionsRequired`, a node in a scene's `nodes` or a node's
//!   `children`; the second goes. A skin's `joints` stays: vertices name joints by place;
//! - a node's identity `matrix`, the default (NODE_MATRIX_DEFAULT);
//! - an empty array or object that a property holds (EMPTY_ENTITY): `"extensionsUsed": []`,
//!   `"extensions": {}`. An empty element of an array stays (removing it would renumber the
//!   others), and so does one the schema requires (the fixed file would lack it, an error, and
//!   the check refuses the fix).

use super::fixers::{last_token, parent, Fixer, Planning, Proposal};
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;

pub const ALPHA_CUTOFF_IGNORED: Fixer = Fixer {
    code: &crate::rules::materials::MATERIAL_ALPHA_CUTOFF_INVALID_MODE,
    safety: Safety::Safe,
    about: "removes the alphaCutoff that no alphaMode reads",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        (last_token(&d.pointer)? == "alphaCutoff").then_some(())?;
        asset.root().pointer(&d.pointer)?.as_f64()?;
        Some(Proposal {
            title: "remove alphaCutoff, which only alphaMode MASK reads".to_string(),
            edits: vec![Edit::remove(d.pointer.clone())],
        })
    },
};

pub const DUPLICATE_DECLARATION: Fixer = Fixer {
    code: &crate::rules::core::DUPLICATE_ELEMENTS,
    safety: Safety::Safe,
    about: "removes the second of an element given twice in extensionsUsed, extensionsRequired, a scene's nodes or a node's children",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        let list = parent(&d.pointer);
        let tokens: Vec<&str> = list.split('/').collect();
        let a_set = matches!(
            tokens[..],
            ["", "extensionsUsed" | "extensionsRequired"]
                | ["", "scenes", _, "nodes"]
                | ["", "nodes", _, "children"]
        );
        if !a_set {
            return None;
        }
        let value = asset.root().pointer(&d.pointer)?;
        let name = match value.as_str() {
            Some(name) => name.into_owned(),
            None => format!("node {}", value.as_u64()?),
        };
        let key = tokens[tokens.len() - 1];
        Some(Proposal {
            title: format!("remove the second {name} from {key}"),
            edits: vec![Edit::remove(d.pointer.clone())],
        })
    },
};

pub const EMPTY: Fixer = Fixer {
    code: &crate::rules::core::EMPTY_ENTITY,
    safety: Safety::Safe,
    about: "removes an empty array or object held by a property",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        let key = last_token(&d.pointer)?;
        if crate::asset::pointer::array_index(&key).is_some() {
            return None;
        }
        let value = asset.root().pointer(&d.pointer)?;
        let empty = value.as_array().is_some_and(|a| a.is_empty())
            || value.as_object().is_some_and(|o| o.is_empty());
        empty.then(|| Proposal {
            title: format!("remove the empty {key}"),
            edits: vec![Edit::remove(d.pointer.clone())],
        })
    },
};

pub const DEFAULT_MATRIX: Fixer = Fixer {
    code: &crate::rules::nodes::NODE_MATRIX_DEFAULT,
    safety: Safety::Safe,
    about: "removes a node's identity matrix, the default",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        (last_token(&d.pointer)? == "matrix").then_some(())?;
        asset.root().pointer(&d.pointer)?.as_array()?;
        Some(Proposal {
            title: "remove the identity matrix, the default".to_string(),
            edits: vec![Edit::remove(d.pointer.clone())],
        })
    },
};
