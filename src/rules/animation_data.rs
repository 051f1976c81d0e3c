//! Animation keyframes, read from the data (the spec's "Animations": times are non-negative and
//! strictly increasing; rotations are unit quaternions), with the Khronos glTF-Validator's
//! codes and pointers:
//!
//! - ACCESSOR_ANIMATION_INPUT_NEGATIVE (error): a negative keyframe time; at the sampler's
//!   `input`.
//! - ACCESSOR_ANIMATION_INPUT_NON_INCREASING (error): a time not greater than the one before.
//! - ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION (error): a rotation keyframe
//!   (as a loader reads it, normalized integers converted) whose length is not 1 within the
//!   reference's tolerance; at the channel's `sampler`. Of a CUBICSPLINE sampler only the values
//!   are judged, not the tangents.
//!
//! Each kind is reported at most [`MAX_REPORTED`] times a sampler.

use super::accessor_bounds::MAX_REPORTED;
use super::data::{index_of, Elements, UNIT_LENGTH_VEC4};
use super::{elements, Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_ANIMATION_INPUT_NEGATIVE: Code = Code::new(
    "ACCESSOR_ANIMATION_INPUT_NEGATIVE",
    Severity::Error,
    "An animation input holds a negative time.",
);
pub const ACCESSOR_ANIMATION_INPUT_NON_INCREASING: Code = Code::new(
    "ACCESSOR_ANIMATION_INPUT_NON_INCREASING",
    Severity::Error,
    "An animation input's times do not strictly increase.",
);
pub const ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION: Code = Code::new(
    "ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION",
    Severity::Error,
    "A rotation keyframe is not a unit quaternion.",
);

pub struct AnimationData;

impl Rule for AnimationData {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ACCESSOR_ANIMATION_INPUT_NEGATIVE,
            &ACCESSOR_ANIMATION_INPUT_NON_INCREASING,
            &ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION,
        ]
    }

    fn reads(&self) -> super::Reads {
        super::data::DATA_READS
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        if !cx.reads_data() {
            return;
        }
        for (a, animation) in elements(cx.json().get("animations")).enumerate() {
            let samplers: Vec<_> = elements(animation.get("samplers")).collect();
            for (s, sampler) in samplers.iter().enumerate() {
                let Some(input) = index_of(sampler.get("input")).and_then(|i| Elements::of(cx, i))
                else {
                    continue;
                };
                if input.components != 1 {
                    continue;
                }
                let at = format!("/animations/{a}/samplers/{s}/input");
                let (mut negative, mut unordered) = (0, 0);
                let mut previous: Option<f64> = None;
                input.for_each(|i, value| {
                    let t = input.normalize(value[0]);
                    if t < 0.0 && negative < MAX_REPORTED {
                        negative += 1;
                        out.push(Diagnostic::new(
                            &ACCESSOR_ANIMATION_INPUT_NEGATIVE,
                            at.clone(),
                            format!("the time at index {i} is negative: {t}"),
                        ));
                    }
                    if let Some(before) = previous {
                        if t <= before && unordered < MAX_REPORTED {
                            unordered += 1;
                            out.push(Diagnostic::new(
                                &ACCESSOR_ANIMATION_INPUT_NON_INCREASING,
                                at.clone(),
                                format!("the time at index {i} is not greater than the one before: {t} <= {before}"),
                            ));
                        }
                    }
                    // A negative time is its own finding; the next is compared with 0, the
                    // earliest a time may be, as the Khronos validator compares it.
                    previous = Some(t.max(0.0));
                });
            }
            for (c, channel) in elements(animation.get("channels")).enumerate() {
                let rotation = channel
                    .get("target")
                    .and_then(|t| t.get("path"))
                    .is_some_and(|p| p.is_str("rotation"));
                let Some(sampler) = index_of(channel.get("sampler")).and_then(|s| samplers.get(s))
                else {
                    continue;
                };
                if !rotation {
                    continue;
                }
                let Some(output) =
                    index_of(sampler.get("output")).and_then(|o| Elements::of(cx, o))
                else {
                    continue;
                };
                if output.components != 4 {
                    continue;
                }
                let cubic = sampler
                    .get("interpolation")
                    .is_some_and(|i| i.is_str("CUBICSPLINE"));
                let at = format!("/animations/{a}/channels/{c}/sampler");
                let mut reported = 0;
                output.for_each(|i, q| {
                    // A cubic spline's keyframes are (in-tangent, value, out-tangent).
                    if cubic && i % 3 != 1 {
                        return;
                    }
                    let length = q
                        .iter()
                        .map(|v| output.normalize(*v).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    if (length - 1.0).abs() > UNIT_LENGTH_VEC4 && reported < MAX_REPORTED {
                        reported += 1;
                        out.push(Diagnostic::new(
                            &ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION,
                            at.clone(),
                            format!(
                                "the rotation at indices {}..{} is not of unit length: {length}",
                                i * 4,
                                i * 4 + 3
                            ),
                        ));
                    }
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    #[test]
    fn negative_unordered_times_and_non_unit_rotations_are_found() {
        let mut bytes = Vec::new();
        for t in [-1.0f32, 0.0, 0.0, 1.0] {
            bytes.extend_from_slice(&t.to_le_bytes());
        }
        for v in [
            0.0f32, 0.0, 0.0, 1.0, 0.5, 0.5, 0.5, 0.5, 0.1, 0.2, 0.3, 0.4, 0.0, 0.0, 0.0, 1.0,
        ] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"nodes":[{{}}],
            "buffers":[{{"byteLength":80,"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":16}},{{"buffer":0,"byteOffset":16,"byteLength":64}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"SCALAR","min":[-1],"max":[1]}},
                         {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC4"}}],
            "animations":[{{"samplers":[{{"input":0,"output":1}}],
                           "channels":[{{"sampler":0,"target":{{"node":0,"path":"rotation"}}}}]}}]}}"#
        );
        assert_eq!(
            crate::rules::findings_of(&AnimationData, &text),
            [
                "ACCESSOR_ANIMATION_INPUT_NEGATIVE /animations/0/samplers/0/input",
                "ACCESSOR_ANIMATION_INPUT_NON_INCREASING /animations/0/samplers/0/input",
                "ACCESSOR_ANIMATION_INPUT_NON_INCREASING /animations/0/samplers/0/input",
                "ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION /animations/0/channels/0/sampler",
            ]
        );
    }
}
