//! KHR_lights_punctual, beyond its schema: a spot light's cone is described by its `spot`
//! object, which the schema cannot require of `type: "spot"` alone (the Khronos validator reports
//! its absence as UNDEFINED_PROPERTY, and so does velvet), and its outer cone must be wider than
//! its inner one (the spec: innerConeAngle < outerConeAngle).

use super::{Context, Rule};
use crate::diagnostics::{codes, Code, Diagnostic, Severity};

pub const KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES: Code = Code::new(
    "KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES",
    Severity::Error,
    "A spot light's outerConeAngle is less than or equal to its innerConeAngle (defaults π/4 and 0).",
);

/// The spec's defaults.
const INNER_CONE_ANGLE: f64 = 0.0;
const OUTER_CONE_ANGLE: f64 = std::f64::consts::FRAC_PI_4;

pub struct Lights;

impl Rule for Lights {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["extensions"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &codes::UNDEFINED_PROPERTY,
            &KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let Some(lights) = cx
            .json()
            .get("extensions")
            .and_then(|e| e.get("KHR_lights_punctual"))
            .and_then(|l| l.get("lights"))
        else {
            return;
        };
        for (i, light) in super::elements(Some(lights)).enumerate() {
            if !light.get("type").is_some_and(|t| t.is_str("spot")) {
                continue;
            }
            let at = format!("/extensions/KHR_lights_punctual/lights/{i}");
            let Some(spot) = light.get("spot") else {
                out.push(Diagnostic::new(
                    &codes::UNDEFINED_PROPERTY,
                    at,
                    "property 'spot' must be defined for a light of type 'spot'",
                ));
                continue;
            };
            // A value of the wrong type or range is the schema's finding.
            let angle = |name: &str, default: f64| match spot.get(name) {
                Some(value) => value.as_f64(),
                None => Some(default),
            };
            if let (Some(inner), Some(outer)) = (
                angle("innerConeAngle", INNER_CONE_ANGLE),
                angle("outerConeAngle", OUTER_CONE_ANGLE),
            ) {
                if outer <= inner {
                    out.push(Diagnostic::new(
                        &KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES,
                        // The Khronos validator places it at the outer angle, the one that must grow.
                        format!("{at}/spot/outerConeAngle"),
                        format!(
                            "outerConeAngle ({outer}) is less than or equal to innerConeAngle ({inner}): the cone has no falloff"
                        ),
                    ));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::{load_bytes_with, LoadOptions};

    fn findings(lights: &str) -> Vec<(&'static str, String)> {
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"extensions":{{"KHR_lights_punctual":{{"lights":{lights}}}}}}}"#
        );
        let loaded = load_bytes_with(
            std::path::Path::new("lights.gltf"),
            text.as_bytes(),
            &LoadOptions::default(),
        );
        let asset = loaded.asset.expect("the document parses");
        let schemas = super::super::schema::Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let mut out = Vec::new();
        Lights.check(&cx, &mut out);
        out.into_iter().map(|d| (d.code, d.pointer)).collect()
    }

    #[test]
    fn a_spot_light_needs_its_spot_object_and_a_wider_outer_cone() {
        assert_eq!(
            findings(
                r#"[{"type":"spot"},
                    {"type":"spot","spot":{"innerConeAngle":0.5,"outerConeAngle":0.5}},
                    {"type":"spot","spot":{"innerConeAngle":0.9}},
                    {"type":"spot","spot":{}},
                    {"type":"spot","spot":{"innerConeAngle":0.1,"outerConeAngle":0.2}},
                    {"type":"point"}]"#
            ),
            [
                (
                    "UNDEFINED_PROPERTY",
                    "/extensions/KHR_lights_punctual/lights/0".to_string()
                ),
                (
                    "KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES",
                    "/extensions/KHR_lights_punctual/lights/1/spot/outerConeAngle".to_string()
                ),
                (
                    "KHR_LIGHTS_PUNCTUAL_LIGHT_SPOT_ANGLES",
                    "/extensions/KHR_lights_punctual/lights/2/spot/outerConeAngle".to_string()
                ),
            ]
        );
    }
}
