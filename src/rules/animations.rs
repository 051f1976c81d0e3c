//! Animation channels and samplers, as the JSON describes them (the Khronos glTF-Validator's
//! animation link checks, with its codes and pointers; the spec's "Animations" section). The
//! keyframe data itself is not read here.
//!
//! Samplers, at `samplers/i/input`:
//! - ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT (error): input not float scalars.
//! - ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS (error): input without min and max.
//! - ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS (error): a CUBICSPLINE input of fewer
//!   than 2 keyframes.
//!
//! Channels, at `channels/i/target` unless said:
//! - ANIMATION_DUPLICATE_TARGETS (error): two channels of one animation with the same node and
//!   path; at the first.
//! - ANIMATION_CHANNEL_TARGET_NODE_MATRIX (error): TRS animated on a node defined by a matrix.
//! - ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS (error): weights animated on a node whose
//!   mesh has no morph targets.
//! - ANIMATION_CHANNEL_TARGET_NODE_SKIN (warning): TRS animated on a skinned node, where it has
//!   no effect; at `path`.
//! - ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT and _INVALID_COUNT (errors): the output's
//!   type for the path, and one value per keyframe (times the morph targets for weights, times 3
//!   for CUBICSPLINE); at `channels/i/sampler`.
//! - KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE and _PATH (errors): a channel with
//!   KHR_animation_pointer must have no `node` and the path "pointer"; at the extension object.

use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT: Code = Code::new(
    "ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT",
    Severity::Error,
    "An animation sampler's input accessor does not hold float scalars.",
);
pub const ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS: Code = Code::new(
    "ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS",
    Severity::Error,
    "An animation sampler's input accessor has no min and max, which the spec requires.",
);
pub const ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS: Code = Code::new(
    "ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS",
    Severity::Error,
    "A CUBICSPLINE animation sampler has fewer than 2 keyframes.",
);
pub const ANIMATION_DUPLICATE_TARGETS: Code = Code::new(
    "ANIMATION_DUPLICATE_TARGETS",
    Severity::Error,
    "Two channels of one animation target the same node and path.",
);
pub const ANIMATION_CHANNEL_TARGET_NODE_MATRIX: Code = Code::new(
    "ANIMATION_CHANNEL_TARGET_NODE_MATRIX",
    Severity::Error,
    "An animation channel targets translation, rotation or scale of a node defined by a matrix.",
);
pub const ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS: Code = Code::new(
    "ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS",
    Severity::Error,
    "An animation channel targets the weights of a node whose mesh has no morph targets.",
);
pub const ANIMATION_CHANNEL_TARGET_NODE_SKIN: Code = Code::new(
    "ANIMATION_CHANNEL_TARGET_NODE_SKIN",
    Severity::Warning,
    "An animation channel targets translation, rotation or scale of a skinned node, where they have no effect.",
);
pub const ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT: Code = Code::new(
    "ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT",
    Severity::Error,
    "An animation sampler's output accessor has a type its channel's path does not allow.",
);
pub const ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_COUNT: Code = Code::new(
    "ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_COUNT",
    Severity::Error,
    "An animation sampler's output accessor does not hold one value per keyframe (per morph target, ×3 for CUBICSPLINE).",
);
pub const KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE: Code = Code::new(
    "KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE",
    Severity::Error,
    "A channel with KHR_animation_pointer also names a target node.",
);
pub const KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_PATH: Code = Code::new(
    "KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_PATH",
    Severity::Error,
    "A channel with KHR_animation_pointer has a target path other than 'pointer'.",
);

/// (type, component type, normalized) of an accessor, and its count and bounds.
struct Keyframes {
    kind: Option<String>,
    component_type: Option<u64>,
    normalized: bool,
    count: Option<u64>,
    bounded: bool,
}

fn keyframes(accessors: Option<Node>, index: Option<Node>) -> Option<Keyframes> {
    let accessor = super::element_at(accessors, index)?;
    Some(Keyframes {
        kind: accessor
            .get("type")
            .and_then(|t| t.as_str())
            .map(|t| t.into_owned()),
        component_type: accessor.get("componentType").and_then(|c| c.as_u64()),
        normalized: accessor.get("normalized").and_then(|n| n.as_bool()) == Some(true),
        count: accessor.get("count").and_then(|c| c.as_u64()),
        bounded: accessor.get("min").is_some() && accessor.get("max").is_some(),
    })
}

/// Whether output keyframes of this format can animate `path` (the spec's table).
fn output_allowed(path: &str, output: &Keyframes) -> Option<bool> {
    let kind = output.kind.as_deref()?;
    let component = output.component_type?;
    let float = component == 5126;
    let normalized_int = output.normalized && matches!(component, 5120..=5123);
    Some(match path {
        "translation" | "scale" => kind == "VEC3" && float,
        "rotation" => kind == "VEC4" && (float || normalized_int),
        "weights" => kind == "SCALAR" && (float || normalized_int),
        _ => return None,
    })
}

pub struct Animations;

impl Rule for Animations {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT,
            &ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS,
            &ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS,
            &ANIMATION_DUPLICATE_TARGETS,
            &ANIMATION_CHANNEL_TARGET_NODE_MATRIX,
            &ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS,
            &ANIMATION_CHANNEL_TARGET_NODE_SKIN,
            &ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT,
            &ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_COUNT,
            &KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE,
            &KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_PATH,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let Some(animations) = json.get("animations") else {
            return;
        };
        let accessors = json.get("accessors");
        let nodes = json.get("nodes");
        let meshes = json.get("meshes");
        // The number of morph targets of a node's mesh (its first primitive's).
        let morph_targets = |node: Node| -> Option<usize> {
            let mesh = usize::try_from(node.get("mesh")?.as_u64()?).ok()?;
            let mesh = meshes?.get(mesh)?;
            Some(
                elements(mesh.get("primitives"))
                    .next()
                    .and_then(|p| p.get("targets"))
                    .and_then(|t| t.as_array())
                    .map_or(0, |t| t.len()),
            )
        };
        for (a, animation) in elements(Some(animations)).enumerate() {
            let at = format!("/animations/{a}");
            let samplers: Vec<Node> = elements(animation.get("samplers")).collect();
            for (s, sampler) in samplers.iter().enumerate() {
                let Some(input) = keyframes(accessors, sampler.get("input")) else {
                    continue;
                };
                let input_at = format!("{at}/samplers/{s}/input");
                let float_scalars = input.kind.as_deref().is_none_or(|k| k == "SCALAR")
                    && input.component_type.is_none_or(|c| c == 5126);
                if !float_scalars {
                    out.push(Diagnostic::new(
                        &ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT,
                        input_at.clone(),
                        "keyframe times must be float scalars",
                    ));
                }
                if !input.bounded {
                    out.push(Diagnostic::new(
                        &ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS,
                        input_at.clone(),
                        "keyframe times must have min and max",
                    ));
                }
                let cubic = sampler
                    .get("interpolation")
                    .is_some_and(|i| i.is_str("CUBICSPLINE"));
                if cubic && input.count.is_some_and(|c| c < 2) {
                    out.push(Diagnostic::new(
                        &ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS,
                        input_at,
                        "a CUBICSPLINE sampler needs at least 2 keyframes",
                    ));
                }
            }
            let channels: Vec<Node> = elements(animation.get("channels")).collect();
            let targets: Vec<Option<(u64, String)>> = channels
                .iter()
                .map(|c| {
                    let target = c.get("target")?;
                    let node = target.get("node")?.as_u64()?;
                    let path = target.get("path")?.as_str()?.into_owned();
                    Some((node, path))
                })
                .collect();
            // Each channel's next channel with the same target, found in one pass from the end
            // (a scan of the later channels for each would be quadratic in a long animation).
            let mut later = std::collections::HashMap::new();
            let mut next_same: Vec<Option<usize>> = vec![None; targets.len()];
            for (c, target) in targets.iter().enumerate().rev() {
                if let Some(target) = target {
                    next_same[c] = later.insert(target, c);
                }
            }
            for (c, channel) in channels.iter().enumerate() {
                let channel_at = format!("{at}/channels/{c}");
                let Some(target) = channel.get("target").filter(|t| t.is_object()) else {
                    continue;
                };
                let path = target.get("path").and_then(|p| p.as_str());
                if let Some(pointer) = target
                    .get("extensions")
                    .and_then(|e| e.get("KHR_animation_pointer"))
                {
                    let ext_at = format!("{channel_at}/target/extensions/KHR_animation_pointer");
                    if pointer.is_object() {
                        if target.get("node").is_some() {
                            out.push(Diagnostic::new(
                                &KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE,
                                ext_at.clone(),
                                "a channel with KHR_animation_pointer must have no target node",
                            ));
                        }
                        if let Some(path) = &path {
                            if path != "pointer" {
                                out.push(Diagnostic::new(
                                    &KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_PATH,
                                    ext_at,
                                    format!("a channel with KHR_animation_pointer must have the path 'pointer', not '{path}'"),
                                ));
                            }
                        }
                    }
                    continue;
                }
                if let Some(other) = next_same[c] {
                    out.push(Diagnostic::new(
                        &ANIMATION_DUPLICATE_TARGETS,
                        format!("{channel_at}/target"),
                        format!("the channel has the same target as channel {other}"),
                    ));
                }
                let Some(path) = path else {
                    continue;
                };
                let trs = matches!(path.as_ref(), "translation" | "rotation" | "scale");
                let node = super::element_at(nodes, target.get("node"));
                let mut morphs = None;
                if let Some(node) = node {
                    if trs && node.get("matrix").is_some() {
                        out.push(Diagnostic::new(
                            &ANIMATION_CHANNEL_TARGET_NODE_MATRIX,
                            format!("{channel_at}/target"),
                            format!("the channel animates {path} of a node defined by a matrix"),
                        ));
                    }
                    if trs && node.get("skin").is_some() {
                        out.push(Diagnostic::new(
                            &ANIMATION_CHANNEL_TARGET_NODE_SKIN,
                            format!("{channel_at}/target/path"),
                            format!("{path} of a skinned node does not affect its mesh"),
                        ));
                    }
                    if path == "weights" {
                        morphs = morph_targets(node);
                        if morphs.unwrap_or(0) == 0 {
                            out.push(Diagnostic::new(
                                &ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS,
                                format!("{channel_at}/target"),
                                "the channel animates weights of a node whose mesh has no morph targets",
                            ));
                        }
                    }
                }
                let Some(sampler) = channel
                    .get("sampler")
                    .and_then(|s| s.as_u64())
                    .and_then(|s| usize::try_from(s).ok())
                    .and_then(|s| samplers.get(s))
                else {
                    continue;
                };
                let (Some(input), Some(output)) = (
                    keyframes(accessors, sampler.get("input")),
                    keyframes(accessors, sampler.get("output")),
                ) else {
                    continue;
                };
                let sampler_at = format!("{channel_at}/sampler");
                match output_allowed(&path, &output) {
                    Some(false) => out.push(Diagnostic::new(
                        &ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT,
                        sampler_at.clone(),
                        format!(
                            "output keyframes of type {} and component type {} cannot animate '{path}'",
                            output.kind.as_deref().unwrap_or("?"),
                            output.component_type.unwrap_or(0)
                        ),
                    )),
                    None => continue,
                    Some(true) => {}
                }
                let per_keyframe = if path == "weights" {
                    match morphs {
                        Some(m) if m > 0 => m as u64,
                        _ => continue,
                    }
                } else {
                    1
                };
                let cubic = sampler
                    .get("interpolation")
                    .is_some_and(|i| i.is_str("CUBICSPLINE"));
                if let (Some(keys), Some(values)) = (input.count, output.count) {
                    let expected = keys * per_keyframe * if cubic { 3 } else { 1 };
                    if values != expected {
                        out.push(Diagnostic::new(
                            &ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_COUNT,
                            sampler_at,
                            format!(
                                "the output accessor holds {values} values; {expected} expected"
                            ),
                        ));
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Animations, text)
    }

    #[test]
    fn channels_and_samplers_that_cannot_animate_are_found() {
        let text = r#"{"asset":{"version":"2.0"},
            "nodes":[{"matrix":[1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1]},{"skin":0,"mesh":0},{}],
            "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
            "accessors":[
              {"componentType":5126,"count":2,"type":"SCALAR","min":[0],"max":[1]},
              {"componentType":5126,"count":2,"type":"VEC3"},
              {"componentType":5125,"count":1,"type":"SCALAR"},
              {"componentType":5126,"count":3,"type":"VEC4"}],
            "animations":[
              {"samplers":[{"input":0,"output":1},{"input":2,"output":3,"interpolation":"CUBICSPLINE"}],
               "channels":[{"sampler":0,"target":{"node":0,"path":"scale"}},
                           {"sampler":0,"target":{"node":0,"path":"scale"}},
                           {"sampler":0,"target":{"node":1,"path":"translation"}},
                           {"sampler":0,"target":{"node":2,"path":"weights"}},
                           {"sampler":0,"target":{"node":2,"path":"rotation"}},
                           {"sampler":0,"target":{"node":2,"path":"pointer","extensions":{"KHR_animation_pointer":{"pointer":"/nodes/2/scale"}}}}]}]}"#;
        assert_eq!(
            found(text),
            [
                "ANIMATION_SAMPLER_INPUT_ACCESSOR_INVALID_FORMAT /animations/0/samplers/1/input",
                "ANIMATION_SAMPLER_INPUT_ACCESSOR_WITHOUT_BOUNDS /animations/0/samplers/1/input",
                "ANIMATION_SAMPLER_INPUT_ACCESSOR_TOO_FEW_ELEMENTS /animations/0/samplers/1/input",
                "ANIMATION_DUPLICATE_TARGETS /animations/0/channels/0/target",
                "ANIMATION_CHANNEL_TARGET_NODE_MATRIX /animations/0/channels/0/target",
                "ANIMATION_CHANNEL_TARGET_NODE_MATRIX /animations/0/channels/1/target",
                "ANIMATION_CHANNEL_TARGET_NODE_SKIN /animations/0/channels/2/target/path",
                "ANIMATION_CHANNEL_TARGET_NODE_WEIGHTS_NO_MORPHS /animations/0/channels/3/target",
                "ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT /animations/0/channels/3/sampler",
                "ANIMATION_SAMPLER_OUTPUT_ACCESSOR_INVALID_FORMAT /animations/0/channels/4/sampler",
                "KHR_ANIMATION_POINTER_ANIMATION_CHANNEL_TARGET_NODE /animations/0/channels/5/target/extensions/KHR_animation_pointer",
            ]
        );
    }
}
