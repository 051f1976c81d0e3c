//! The fixers, one small unit each, and the one table that registers them by code. A fixer
//! reads one finding and the document, and proposes the edits that repair it (or nothing,
//! when this finding cannot be repaired safely in this document). Fixers never call each
//! other or the planner; the planner merges what they propose.

use crate::asset::tape::Node;
use crate::asset::Asset;
use crate::diagnostics::{Code, Diagnostic, Safety};
use crate::edit::Edit;
use crate::migrate::plan::Primitives;
use std::collections::HashMap;
use std::sync::OnceLock;

/// What a fixer proposes: a title saying what it does, and the edits.
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal {
    pub title: String,
    pub edits: Vec<Edit>,
}

/// What fixers read while one document's fixes are planned: the document, and what the fixes
/// of many findings would otherwise each work out again from the whole document (a document
/// may have thousands of findings of one code). Each is worked out on first use, once per plan,
/// whichever thread of the pool proposes first.
pub struct Planning<'a> {
    pub asset: &'a Asset,
    /// The primitives that use each material (a draft sheen's upgrade is planned as migrate
    /// plans it, which asks).
    pub primitives: Primitives<'a>,
    /// The document's prune: one proposal repairs every UNUSED_OBJECT finding.
    pub(super) prune: OnceLock<Option<Proposal>>,
    /// Each material's draft-sheen upgrade, by material index: the draft's findings in one
    /// material (one per draft property) are repaired by the one upgrade, which plans the
    /// material as migrate does.
    pub(super) upgrades: std::sync::Mutex<HashMap<usize, Option<Proposal>>>,
}

impl<'a> Planning<'a> {
    pub fn new(asset: &'a Asset) -> Planning<'a> {
        Planning {
            asset,
            primitives: Primitives::new(asset.root()),
            prune: OnceLock::new(),
            upgrades: Default::default(),
        }
    }
}

/// A fixer: the code it repairs, how safe its fix is, and the function that plans it.
pub struct Fixer {
    pub code: &'static Code,
    pub safety: Safety,
    /// What its fix does, for the codes table and the docs.
    pub about: &'static str,
    pub propose: fn(&Planning, &Diagnostic) -> Option<Proposal>,
}

/// Every fixer, by code (each code once).
pub const FIXERS: &[Fixer] = &[
    super::declare::UNDECLARED,
    super::declare::REQUIRED_NOT_USED,
    super::declare::SHEEN_UNUSED,
    super::declare::FUZZ_UNUSED,
    super::fuzz_roughness::EXPLICIT_DEFAULT,
    super::texture::SHEEN_WITHOUT_EFFECT,
    super::texture::FUZZ_WITHOUT_EFFECT,
    super::clamp::OUT_OF_RANGE,
    super::legacy::UPGRADE,
    super::texcoord::TEXCOORD,
    super::tidy::ALPHA_CUTOFF_IGNORED,
    super::tidy::DUPLICATE_DECLARATION,
    super::tidy::EMPTY,
    super::tidy::DEFAULT_MATRIX,
    super::buffer_view_target::TARGET,
    super::prune::UNUSED,
    super::byte_order_mark::BYTE_ORDER_MARK,
    super::container::EXTRA_DATA,
    super::container::UNALIGNED,
    super::container::PADDING,
    super::container::LENGTH,
];

/// The fixer of `code`, if it has one.
pub fn fixer_for(code: &str) -> Option<&'static Fixer> {
    FIXERS.iter().find(|f| f.code.name == code)
}

/// The last reference token of `pointer`, unescaped.
pub(super) fn last_token(pointer: &str) -> Option<std::borrow::Cow<'_, str>> {
    let (_, last) = pointer.rsplit_once('/')?;
    Some(crate::asset::pointer::unescape(last))
}

/// The pointer of the value that holds the one `pointer` names.
pub(super) fn parent(pointer: &str) -> &str {
    pointer.rsplit_once('/').map_or("", |(p, _)| p)
}

/// The string at `pointer` in `root`.
pub(super) fn string_at(root: Node, pointer: &str) -> Option<String> {
    root.pointer(pointer)?.as_str().map(|s| s.into_owned())
}
