//! Switched-off layers with textures: sheen is off when sheenColorFactor is `[0, 0, 0]` (its
//! default) and fuzz when fuzzFactor is 0 (its default). Textures on such a layer have no
//! effect, which usually means a forgotten factor: exporters often write the texture and rely
//! on a default that turns the layer off.

use super::{slot_uses, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const SHEEN_TEXTURE_WITHOUT_EFFECT: Code = Code::new(
    "KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT",
    Severity::Warning,
    "A sheen texture on a layer switched off by sheenColorFactor [0,0,0] (the default).",
);
pub const FUZZ_TEXTURE_WITHOUT_EFFECT: Code = Code::new(
    "KHR_MATERIALS_FUZZ_TEXTURE_WITHOUT_EFFECT",
    Severity::Warning,
    "A fuzz texture on a layer switched off by fuzzFactor 0 (the default).",
);

pub struct DisabledLayer;

impl Rule for DisabledLayer {
    fn codes(&self) -> &'static [&'static Code] {
        &[&SHEEN_TEXTURE_WITHOUT_EFFECT, &FUZZ_TEXTURE_WITHOUT_EFFECT]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for read in cx.layers() {
            let layer = read.object;
            let (off, code, why) = match (read.sheen(), read.fuzz()) {
                (Some(view), _) => (
                    !view.is_on(),
                    &SHEEN_TEXTURE_WITHOUT_EFFECT,
                    "sheenColorFactor is [0, 0, 0]",
                ),
                (_, Some(view)) => (
                    !view.is_on(),
                    &FUZZ_TEXTURE_WITHOUT_EFFECT,
                    "fuzzFactor is 0",
                ),
                (None, None) => continue,
            };
            if !off {
                continue;
            }
            for slot in slot_uses(&layer) {
                let stated = layer.value.get(slot.slot.factor).is_some();
                out.push(Diagnostic::new(
                    code,
                    slot.pointer(),
                    format!(
                        "{} has no effect: {why}{}, which switches the layer off",
                        slot.slot.texture,
                        if stated { "" } else { " (the default)" }
                    ),
                ));
            }
        }
    }
}
