//! A byte-order mark before the JSON text, which glTF forbids (BOM_PRESENT), removed. Safe: a
//! loader that reads the file at all reads the same JSON. Its fix has no edit of the JSON text:
//! the planner marks it ([`super::Fix::drops_byte_order_mark`]), the file is written without
//! the mark, and the reports give an edit of the bytes before the text.

use super::fixers::{Fixer, Planning, Proposal};
use crate::diagnostics::{codes::BOM_PRESENT, Diagnostic, Safety};

pub const BYTE_ORDER_MARK: Fixer = Fixer {
    code: &BOM_PRESENT,
    safety: Safety::Safe,
    about: "removes the byte-order mark before the JSON text",
    propose: |planning: &Planning, _: &Diagnostic| {
        let asset = planning.asset;
        asset.byte_order_mark.then(|| Proposal {
            title: "remove the byte-order mark".to_string(),
            edits: Vec::new(),
        })
    },
};
