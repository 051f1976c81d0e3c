//! Layer order with a clear coat: sheen lies under KHR_materials_clearcoat, fuzz over it. The
//! same material converted from one to the other changes its look where the coat is strong.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};
use crate::layers;

pub const SHEEN_UNDER_CLEARCOAT: Code = Code::new(
    "KHR_MATERIALS_SHEEN_UNDER_CLEARCOAT",
    Severity::Info,
    "Sheen with KHR_materials_clearcoat: the coat lies over the sheen.",
);
pub const FUZZ_OVER_CLEARCOAT: Code = Code::new(
    "KHR_MATERIALS_FUZZ_OVER_CLEARCOAT",
    Severity::Info,
    "Fuzz with KHR_materials_clearcoat: the fuzz lies over the coat (sheen lay under it).",
);

pub struct Clearcoat;

impl Rule for Clearcoat {
    fn codes(&self) -> &'static [&'static Code] {
        &[&SHEEN_UNDER_CLEARCOAT, &FUZZ_OVER_CLEARCOAT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for layer in cx.layer_objects() {
            if layer.extensions.get(layers::CLEARCOAT).is_none() {
                continue;
            }
            let (code, message) = if layer.extension == layers::SHEEN {
                (
                    &SHEEN_UNDER_CLEARCOAT,
                    "the clear coat lies over this sheen layer",
                )
            } else {
                (
                    &FUZZ_OVER_CLEARCOAT,
                    "this fuzz layer lies over the clear coat (a sheen layer would lie under it)",
                )
            };
            out.push(Diagnostic::new(code, layer.pointer(), message));
        }
    }
}
