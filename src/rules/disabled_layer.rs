//! Textures without effect. On switched-off layers: sheen is off when sheenColorFactor is
//! `[0, 0, 0]` (its default) and fuzz when fuzzFactor is 0 (its default). On a sheen layer that
//! is on, a sheenRoughnessTexture whose sheenRoughnessFactor is 0 (its default): the spec
//! multiplies the texture's alpha by the factor, so the roughness is 0 wherever it is read.
//! Either usually means a forgotten factor: exporters often write the texture and rely on a
//! default that cancels it.

use super::{slot_uses, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const SHEEN_TEXTURE_WITHOUT_EFFECT: Code = Code::new(
    "KHR_MATERIALS_SHEEN_TEXTURE_WITHOUT_EFFECT",
    Severity::Warning,
    "A sheen texture without effect: on a layer switched off by sheenColorFactor [0,0,0] (the default), or a sheenRoughnessTexture scaled by sheenRoughnessFactor 0 (the default).",
)
.fixable(crate::diagnostics::Safety::Unsafe);
pub const FUZZ_TEXTURE_WITHOUT_EFFECT: Code = Code::new(
    "KHR_MATERIALS_FUZZ_TEXTURE_WITHOUT_EFFECT",
    Severity::Warning,
    "A fuzz texture on a layer switched off by fuzzFactor 0 (the default).",
)
.fixable(crate::diagnostics::Safety::Unsafe);

const ROUGHNESS_TEXTURE: &str = "sheenRoughnessTexture";

pub struct DisabledLayer;

impl Rule for DisabledLayer {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["materials"])
    }

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
                let roughness_cancelled = read.sheen().is_some_and(|s| s.roughness_factor == 0.0);
                for slot in slot_uses(&layer)
                    .filter(|s| roughness_cancelled && s.slot.texture == ROUGHNESS_TEXTURE)
                {
                    let stated = layer.value.get(slot.slot.factor).is_some();
                    out.push(Diagnostic::new(
                        &SHEEN_TEXTURE_WITHOUT_EFFECT,
                        slot.pointer(),
                        format!(
                            "{ROUGHNESS_TEXTURE} has no effect: {} is 0{}, which scales the texture to 0",
                            slot.slot.factor,
                            if stated { "" } else { " (the default)" }
                        ),
                    ));
                }
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
