//! The pre-ratification sheen draft used sheenFactor, sheenColor and sheenTexture (with the
//! roughness taken from the material). Ratified loaders ignore those properties, so such a
//! material shows no sheen; `velvet migrate` upgrades it.

use super::{Context, Rule};
use crate::asset::pointer;
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const SHEEN_LEGACY_DRAFT: Code = Code::new(
    "KHR_MATERIALS_SHEEN_LEGACY_DRAFT",
    Severity::Warning,
    "A property of the pre-ratification sheen draft (sheenFactor, sheenColor, sheenTexture); ratified loaders ignore it.",
)
.fixable(crate::diagnostics::Safety::Unsafe);

pub use crate::layers::LEGACY_PROPERTIES;

pub struct LegacySheen;

impl Rule for LegacySheen {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[&SHEEN_LEGACY_DRAFT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for layer in cx.layer_objects().filter(|l| l.extension == layers::SHEEN) {
            // Written once per layer that has a finding, and joined rather than formatted: a
            // draft-era library has thousands.
            let mut layer_pointer = None;
            for name in LEGACY_PROPERTIES {
                if layer.value.get(name).is_some() {
                    let at = layer_pointer.get_or_insert_with(|| layer.pointer());
                    out.push(Diagnostic::new(
                        &SHEEN_LEGACY_DRAFT,
                        pointer::join(at, name),
                        [
                            name,
                            " belongs to the pre-ratification KHR_materials_sheen draft and is ignored by ratified loaders; `velvet migrate` upgrades it",
                        ]
                        .concat(),
                    ));
                }
            }
        }
    }
}
