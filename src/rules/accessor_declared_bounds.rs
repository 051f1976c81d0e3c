//! An accessor's `min` and `max` as the JSON declares them, before any data is read (the spec:
//! both have one value a component, "treated as having the same data type as accessor's
//! componentType"), with the Khronos glTF-Validator's codes and pointers, at `min` or `max`:
//!
//! - ARRAY_LENGTH_NOT_IN_LIST (error): not one value a component of the accessor's type
//!   (a VEC3's `min` of two values). Lengths the schema already refuses (none, more than 16)
//!   are the schema's finding.
//! - ARRAY_TYPE_MISMATCH (error): an integer accessor's bound that is not a whole number.
//! - INVALID_GL_VALUE (error): an integer accessor's bound outside its component type's range
//!   (an unsigned byte's `min` of -1).
//!
//! A bound with any of these faults is no bound for the data checks either (the reference
//! drops it): [`declared_bound`] gives a bound only when it holds together.

use super::accessors::components;
use super::{elements, Context, Rule};
use crate::asset::tape::Node;
use crate::diagnostics::{codes::ARRAY_LENGTH_NOT_IN_LIST, Code, Diagnostic, Severity};

pub const INVALID_GL_VALUE: Code = Code::new(
    "INVALID_GL_VALUE",
    Severity::Error,
    "An integer accessor's min or max lies outside its component type's range.",
);

pub struct AccessorDeclaredBounds;

/// An integer component type's name (with its article) and range.
fn integer_range(component_type: u64) -> Option<(&'static str, f64, f64)> {
    Some(match component_type {
        5120 => ("a byte", -128.0, 127.0),
        5121 => ("an unsigned byte", 0.0, 255.0),
        5122 => ("a short", -32768.0, 32767.0),
        5123 => ("an unsigned short", 0.0, 65535.0),
        5125 => ("an unsigned int", 0.0, 4_294_967_295.0),
        _ => return None,
    })
}

/// What can be wrong with one value of an integer accessor's bound.
enum IntegerFault {
    /// Not a whole number: ARRAY_TYPE_MISMATCH.
    NotWhole,
    /// Outside the component type's range: INVALID_GL_VALUE.
    OutOfRange,
}

/// What is wrong with `value` as a bound of an integer accessor whose component type holds
/// `low..=high`, if anything.
fn integer_fault(value: f64, low: f64, high: f64) -> Option<IntegerFault> {
    if value.fract() != 0.0 || !value.is_finite() {
        Some(IntegerFault::NotWhole)
    } else if value < low || value > high {
        Some(IntegerFault::OutOfRange)
    } else {
        None
    }
}

/// What is wrong with one of `accessor`'s bounds (`key`: "min" or "max"), pushed to `out`;
/// nothing when it is absent, not an array of numbers (the schema's finding) or sound.
fn check_bound(accessor: Node, key: &str, at: &str, out: &mut Vec<Diagnostic>) {
    let Some(values) = accessor.get(key).and_then(|b| b.as_array()) else {
        return;
    };
    let component_type = accessor.get("componentType").and_then(|c| c.as_u64());
    let kind = accessor.get("type").and_then(|t| t.as_str());
    let (Some(component_type), Some(kind)) = (component_type, kind) else {
        return;
    };
    let Some(n) = components(&kind).and_then(|n| usize::try_from(n).ok()) else {
        return;
    };
    let range = integer_range(component_type);
    if component_type != 5126 && range.is_none() {
        return;
    }
    let pointer = format!("{at}/{key}");
    let length = values.len();
    if length != n {
        if (1..=16).contains(&length) {
            out.push(Diagnostic::new(
                &ARRAY_LENGTH_NOT_IN_LIST,
                pointer,
                format!(
                    "{key} has {length} value{}; a {kind} accessor's {key} has {n}, one a component",
                    if length == 1 { "" } else { "s" }
                ),
            ));
        }
        return;
    }
    let Some((name, low, high)) = range else {
        return;
    };
    for value in values.iter().filter_map(|v| v.as_f64()) {
        let (code, message) = match integer_fault(value, low, high) {
            None => continue,
            Some(IntegerFault::NotWhole) => (
                &super::core::ARRAY_TYPE_MISMATCH,
                format!("{key} holds {value}, not a whole number: the bounds of {name} accessor are integers"),
            ),
            Some(IntegerFault::OutOfRange) => (
                &INVALID_GL_VALUE,
                format!("{key} holds {value}, outside the range of {name}, {low}..{high}"),
            ),
        };
        out.push(Diagnostic::new(code, pointer.clone(), message));
    }
}

/// `accessor`'s `key` bound ("min" or "max") as the data checks read it: one number a
/// component of `components`, whole and in range for an integer accessor; `None` otherwise.
pub fn declared_bound(accessor: Node, key: &str, components: usize) -> Option<Vec<f64>> {
    let values: Vec<f64> = accessor
        .get(key)?
        .as_array()?
        .iter()
        .map(|v| v.as_f64())
        .collect::<Option<_>>()?;
    if values.len() != components {
        return None;
    }
    let component_type = accessor.get("componentType").and_then(|c| c.as_u64())?;
    if let Some((_, low, high)) = integer_range(component_type) {
        if values
            .iter()
            .any(|&v| integer_fault(v, low, high).is_some())
        {
            return None;
        }
    }
    Some(values)
}

impl Rule for AccessorDeclaredBounds {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["accessors", "extensionsUsed"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ARRAY_LENGTH_NOT_IN_LIST,
            &super::core::ARRAY_TYPE_MISMATCH,
            &INVALID_GL_VALUE,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for (i, accessor) in elements(cx.json().get("accessors")).enumerate() {
            let at = format!("/accessors/{i}");
            check_bound(accessor, "min", &at, out);
            check_bound(accessor, "max", &at, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(accessors: &str) -> Vec<String> {
        let text = format!(r#"{{"asset":{{"version":"2.0"}},"accessors":{accessors}}}"#);
        crate::rules::findings_of(&AccessorDeclaredBounds, &text)
    }

    #[test]
    fn bounds_of_the_wrong_length_fraction_or_range_are_found_at_the_bound() {
        assert_eq!(
            found(
                r#"[{"componentType":5121,"count":1,"type":"SCALAR","min":[-1],"max":[256]},
                    {"componentType":5123,"count":1,"type":"VEC2","min":[0.5,1],"max":[1,65535]},
                    {"componentType":5126,"count":1,"type":"VEC3","min":[0,0],"max":[1,1,1]},
                    {"componentType":5125,"count":1,"type":"SCALAR","min":[0],"max":[4294967296]},
                    {"componentType":5120,"count":1,"type":"VEC2","min":[-128,-129],"max":[127,127]}]"#
            ),
            [
                "INVALID_GL_VALUE /accessors/0/min",
                "INVALID_GL_VALUE /accessors/0/max",
                "ARRAY_TYPE_MISMATCH /accessors/1/min",
                "ARRAY_LENGTH_NOT_IN_LIST /accessors/2/min",
                "INVALID_GL_VALUE /accessors/3/max",
                "INVALID_GL_VALUE /accessors/4/min",
            ]
        );
    }

    #[test]
    fn sound_bounds_and_those_the_schema_judges_are_not_found_here() {
        assert!(found(
            r#"[{"componentType":5121,"count":1,"type":"VEC2","min":[0,0],"max":[255,255.0]},
                {"componentType":5126,"count":1,"type":"SCALAR","min":[-1e30],"max":[0.5]},
                {"componentType":5122,"count":1,"type":"SCALAR","min":[],"max":["7"]},
                {"componentType":5125,"count":1,"type":"VEC5","min":[-1]},
                {"componentType":5124,"count":1,"type":"SCALAR","min":[0.5]}]"#
        )
        .is_empty());
    }

    #[test]
    fn a_bound_is_read_for_the_data_only_when_it_holds_together() {
        let text = r#"{"asset":{"version":"2.0"},"accessors":[
            {"componentType":5121,"type":"VEC2","min":[0,3],"max":[255,256]},
            {"componentType":5126,"type":"VEC2","min":[0.5,-2],"max":[1]}]}"#;
        let asset = crate::asset::load_bytes(std::path::Path::new("t.gltf"), text.as_bytes())
            .asset
            .expect("the document parses");
        let accessors = asset.root().get("accessors").expect("accessors");
        let (byte, float) = (
            accessors.get(0).expect("accessor 0"),
            accessors.get(1).expect("accessor 1"),
        );
        assert_eq!(declared_bound(byte, "min", 2), Some(vec![0.0, 3.0]));
        assert_eq!(declared_bound(byte, "max", 2), None);
        assert_eq!(declared_bound(float, "min", 2), Some(vec![0.5, -2.0]));
        assert_eq!(declared_bound(float, "max", 2), None);
    }
}
