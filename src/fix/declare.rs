//! Declarations: declare an extension that is used (UNDECLARED_EXTENSION) or required
//! (UNUSED_EXTENSION_REQUIRED) in extensionsUsed, and remove a sheen or fuzz declaration no
//! material uses. Neither changes what a loader renders: a loader that knows the extension
//! reads its objects declared or not, and a declaration without objects gives it nothing to
//! read. A declaration that is also required is left alone (removing it would let loaders
//! without the extension load the file, which they refuse today).

use super::fixers::{last_token, string_at, Fixer, Planning, Proposal};
use crate::asset::Asset;
use crate::diagnostics::{Diagnostic, Safety};
use crate::edit::Edit;
use crate::rules::declaration;

/// extensionsUsed must be absent or an array for a name to be added to it.
fn declarable(asset: &Asset) -> bool {
    asset
        .root()
        .get("extensionsUsed")
        .is_none_or(|v| v.as_array().is_some())
}

fn declare(asset: &Asset, name: &str) -> Option<Proposal> {
    (declarable(asset) && !name.is_empty()).then(|| Proposal {
        title: format!("declare {name} in extensionsUsed"),
        edits: vec![Edit::declare_used(name)],
    })
}

pub const UNDECLARED: Fixer = Fixer {
    code: &declaration::UNDECLARED_EXTENSION,
    safety: Safety::Safe,
    about: "adds the extension to extensionsUsed",
    propose: |planning: &Planning, d: &Diagnostic| {
        declare(planning.asset, &last_token(&d.pointer)?)
    },
};

pub const REQUIRED_NOT_USED: Fixer = Fixer {
    code: &declaration::UNUSED_EXTENSION_REQUIRED,
    safety: Safety::Safe,
    about: "adds the required extension to extensionsUsed",
    propose: |planning: &Planning, d: &Diagnostic| {
        declare(
            planning.asset,
            &string_at(planning.asset.root(), &d.pointer)?,
        )
    },
};

/// Removes the unused declaration at `d.pointer` (`/extensionsUsed/K`), unless the extension
/// is also required or used anywhere (the rule's own notion of used).
fn remove_unused(planning: &Planning, d: &Diagnostic) -> Option<Proposal> {
    let asset = planning.asset;
    let root = asset.root();
    let name = string_at(root, &d.pointer)?;
    let required = crate::document::elements(root.get("extensionsRequired"))
        .any(|r| r.as_str().is_some_and(|r| r == name));
    let used = declaration::is_used_anywhere(root, &name);
    (!required && !used && d.pointer.starts_with("/extensionsUsed/")).then(|| Proposal {
        title: format!("remove {name} from extensionsUsed"),
        edits: vec![Edit::remove(d.pointer.clone())],
    })
}

pub const SHEEN_UNUSED: Fixer = Fixer {
    code: &declaration::SHEEN_DECLARED_UNUSED,
    safety: Safety::Safe,
    about: "removes the declaration (kept when the extension is also required)",
    propose: remove_unused,
};

pub const FUZZ_UNUSED: Fixer = Fixer {
    code: &declaration::FUZZ_DECLARED_UNUSED,
    safety: Safety::Safe,
    about: "removes the declaration (kept when the extension is also required)",
    propose: remove_unused,
};
