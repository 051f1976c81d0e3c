//! An accessor's values against its `min` and `max` (the spec: they "MUST match actual minimum
//! and maximum binary values stored in buffers"), read from the data, with the Khronos
//! glTF-Validator's codes and pointers:
//!
//! - ACCESSOR_MIN_MISMATCH, ACCESSOR_MAX_MISMATCH (errors): a component's declared bound is not
//!   its actual minimum or maximum; at `min/c` or `max/c`.
//! - ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND, _OUT_OF_MAX_BOUND (errors): how many values of a
//!   component lie beyond its declared bound; at the same place.
//! - ACCESSOR_INVALID_FLOAT (error): a float component that is NaN or infinite; at the
//!   accessor, one finding a value, at most [`MAX_REPORTED`] an accessor.
//!
//! Float accessors are compared in single precision, as their values are stored: a declared
//! 0.1 matches a stored 0.1f. Non-finite values take no part in the bounds.

use super::accessor_declared_bounds::declared_bound;
use super::data::{accessor_count, Elements, MAX_COMPONENTS};
use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const ACCESSOR_MIN_MISMATCH: Code = Code::new(
    "ACCESSOR_MIN_MISMATCH",
    Severity::Error,
    "An accessor's declared min is not the actual minimum of its data.",
);
pub const ACCESSOR_MAX_MISMATCH: Code = Code::new(
    "ACCESSOR_MAX_MISMATCH",
    Severity::Error,
    "An accessor's declared max is not the actual maximum of its data.",
);
pub const ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND: Code = Code::new(
    "ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND",
    Severity::Error,
    "An accessor holds values below its declared min.",
);
pub const ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND: Code = Code::new(
    "ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND",
    Severity::Error,
    "An accessor holds values above its declared max.",
);
pub const ACCESSOR_INVALID_FLOAT: Code = Code::new(
    "ACCESSOR_INVALID_FLOAT",
    Severity::Error,
    "A float accessor holds NaN or an infinity.",
);

/// Findings of one kind an accessor gives at most: a hostile buffer of a billion NaNs is a
/// thousand findings, not a billion.
pub const MAX_REPORTED: usize = 1000;

pub struct AccessorBounds;

/// What the walk of one accessor's values found, component by component.
struct Tally {
    low: [f64; MAX_COMPONENTS],
    high: [f64; MAX_COMPONENTS],
    below: [usize; MAX_COMPONENTS],
    above: [usize; MAX_COMPONENTS],
}

impl Rule for AccessorBounds {
    fn codes(&self) -> &'static [&'static Code] {
        &[
            &ACCESSOR_MIN_MISMATCH,
            &ACCESSOR_MAX_MISMATCH,
            &ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND,
            &ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND,
            &ACCESSOR_INVALID_FLOAT,
        ]
    }

    /// It reads every accessor's data.
    fn cost(&self) -> u32 {
        4
    }

    fn reads(&self) -> super::Reads {
        super::data::DATA_READS
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        use rayon::prelude::*;
        if !cx.reads_data() {
            return;
        }
        // Accessors are judged side by side (a document's weight is often in a few large
        // ones), their findings joined in accessor order.
        let found: Vec<Vec<Diagnostic>> = (0..accessor_count(cx))
            .into_par_iter()
            .map(|i| {
                let mut out = Vec::new();
                check_accessor(cx, i, &mut out);
                out
            })
            .collect();
        out.extend(found.into_iter().flatten());
    }
}

/// One accessor's values against its bounds.
fn check_accessor(cx: &Context, i: usize, out: &mut Vec<Diagnostic>) {
    let accessors = cx.json().get("accessors");
    let Some(accessor) = accessors.and_then(|a| a.get(i)) else {
        return;
    };
    let float = accessor.get("componentType").and_then(|c| c.as_u64()) == Some(5126);
    if accessor.get("min").is_none() && accessor.get("max").is_none() && !float {
        return;
    }
    let Some(elements) = Elements::of(cx, i) else {
        return;
    };
    let n = elements.components;
    // Declared bounds as the data holds them: single precision for floats. A bound of the
    // wrong length, or an integer one not whole or out of range, is the JSON's finding
    // (`accessor_declared_bounds`), and no bound here, as in the reference.
    let stored = |v: f64| if float { f64::from(v as f32) } else { v };
    let bound = |key: &str| {
        declared_bound(accessor, key, n).map(|b| b.into_iter().map(stored).collect::<Vec<_>>())
    };
    let (min, max) = (bound("min"), bound("max"));
    let mut tally = Tally {
        low: [f64::INFINITY; MAX_COMPONENTS],
        high: [f64::NEG_INFINITY; MAX_COMPONENTS],
        below: [0; MAX_COMPONENTS],
        above: [0; MAX_COMPONENTS],
    };
    let mut invalid = 0;
    // A value that is not finite: a finding (the first MAX_REPORTED of the accessor), and no
    // part of the bounds.
    let mut not_finite = |e: usize, c: usize, v: f64| {
        if invalid < MAX_REPORTED {
            out.push(Diagnostic::new(
                &ACCESSOR_INVALID_FLOAT,
                format!("/accessors/{i}"),
                format!("the value at index {} is {}", e * n + c, name_of(v)),
            ));
        }
        invalid += 1;
    };
    let packed = elements
        .packed_floats()
        .filter(|_| PACKED_WIDTHS.contains(&n));
    if let Some((bytes, stride)) = packed {
        // Floats as they lie, compared as single precision: a float converts to a double
        // exactly and in order, and the declared bounds are already single precision, so the
        // outcome is the general path's, at a fraction of its cost.
        let bound =
            |b: &Option<Vec<f64>>, c: usize, none: f32| b.as_ref().map_or(none, |b| b[c] as f32);
        let mut floats = FloatTally {
            floor: [f32::NEG_INFINITY; MAX_COMPONENTS],
            ceiling: [f32::INFINITY; MAX_COMPONENTS],
            low: [f32::INFINITY; MAX_COMPONENTS],
            high: [f32::NEG_INFINITY; MAX_COMPONENTS],
            below: [0; MAX_COMPONENTS],
            above: [0; MAX_COMPONENTS],
        };
        for c in 0..n {
            floats.floor[c] = bound(&min, c, f32::NEG_INFINITY);
            floats.ceiling[c] = bound(&max, c, f32::INFINITY);
        }
        let count = elements.count;
        match n {
            1 => floats.scan::<1>(bytes, stride, count, &mut not_finite),
            2 => floats.scan::<2>(bytes, stride, count, &mut not_finite),
            3 => floats.scan::<3>(bytes, stride, count, &mut not_finite),
            4 => floats.scan::<4>(bytes, stride, count, &mut not_finite),
            9 => floats.scan::<9>(bytes, stride, count, &mut not_finite),
            _ => floats.scan::<16>(bytes, stride, count, &mut not_finite),
        }
        for c in 0..n {
            tally.low[c] = f64::from(floats.low[c]);
            tally.high[c] = f64::from(floats.high[c]);
            tally.below[c] = floats.below[c];
            tally.above[c] = floats.above[c];
        }
    } else {
        elements.for_each(|e, values| {
            for (c, &v) in values.iter().enumerate() {
                if !v.is_finite() {
                    not_finite(e, c, v);
                    continue;
                }
                tally.low[c] = tally.low[c].min(v);
                tally.high[c] = tally.high[c].max(v);
                if min.as_ref().is_some_and(|m| v < m[c]) {
                    tally.below[c] += 1;
                }
                if max.as_ref().is_some_and(|m| v > m[c]) {
                    tally.above[c] += 1;
                }
            }
        });
    }
    for (key, declared, actual, beyond, mismatch, outside, word) in [
        (
            "min",
            &min,
            &tally.low,
            &tally.below,
            &ACCESSOR_MIN_MISMATCH,
            &ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND,
            "less",
        ),
        (
            "max",
            &max,
            &tally.high,
            &tally.above,
            &ACCESSOR_MAX_MISMATCH,
            &ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND,
            "greater",
        ),
    ] {
        let Some(declared) = declared else {
            continue;
        };
        for c in 0..n {
            let at = format!("/accessors/{i}/{key}/{c}");
            if actual[c].is_finite() && declared[c] != actual[c] {
                out.push(Diagnostic::new(
                    mismatch,
                    at.clone(),
                    format!(
                        "the declared {key} of this component, {}, is not the actual {key}, {}",
                        declared[c], actual[c]
                    ),
                ));
            }
            if beyond[c] > 0 {
                out.push(Diagnostic::new(
                    outside,
                    at,
                    format!(
                        "{} value(s) of this component are {word} than the declared {key}, {}",
                        beyond[c], declared[c]
                    ),
                ));
            }
        }
    }
}

/// The numbers of components [`FloatTally::scan`] is made for: every type's (SCALAR, VEC2,
/// VEC3, VEC4 and MAT2, MAT3, MAT4).
const PACKED_WIDTHS: [usize; 6] = [1, 2, 3, 4, 9, 16];

/// A float accessor's declared bounds, actual extremes and values beyond the bounds,
/// component by component, in single precision.
struct FloatTally {
    floor: [f32; MAX_COMPONENTS],
    ceiling: [f32; MAX_COMPONENTS],
    low: [f32; MAX_COMPONENTS],
    high: [f32; MAX_COMPONENTS],
    below: [usize; MAX_COMPONENTS],
    above: [usize; MAX_COMPONENTS],
}

impl FloatTally {
    /// The walk over `count` packed float elements of `N` components, `stride` bytes apart:
    /// the data checks' hottest loop, its width fixed when compiled so that the walk over an
    /// element's components is unrolled and unchecked.
    fn scan<const N: usize>(
        &mut self,
        bytes: &[u8],
        stride: usize,
        count: usize,
        not_finite: &mut impl FnMut(usize, usize, f64),
    ) {
        let floor: [f32; N] = std::array::from_fn(|c| self.floor[c]);
        let ceiling: [f32; N] = std::array::from_fn(|c| self.ceiling[c]);
        let (mut low, mut high) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
        let (mut below, mut above) = ([0usize; N], [0usize; N]);
        for e in 0..count {
            let element = &bytes[e * stride..e * stride + 4 * N];
            for c in 0..N {
                let b = &element[4 * c..4 * c + 4];
                let v = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
                if !v.is_finite() {
                    not_finite(e, c, f64::from(v));
                    continue;
                }
                low[c] = low[c].min(v);
                high[c] = high[c].max(v);
                below[c] += usize::from(v < floor[c]);
                above[c] += usize::from(v > ceiling[c]);
            }
        }
        self.low[..N].copy_from_slice(&low);
        self.high[..N].copy_from_slice(&high);
        self.below[..N].copy_from_slice(&below);
        self.above[..N].copy_from_slice(&above);
    }
}

fn name_of(v: f64) -> &'static str {
    if v.is_nan() {
        "NaN"
    } else if v > 0.0 {
        "infinity"
    } else {
        "-infinity"
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    fn found(accessors: &str, bytes: &[u8]) -> Vec<String> {
        let data = base64::engine::general_purpose::STANDARD.encode(bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":{}}}],"accessors":{accessors}}}"#,
            bytes.len(),
            bytes.len()
        );
        crate::rules::findings_of(&AccessorBounds, &text)
    }

    #[test]
    fn bounds_that_do_not_match_the_data_are_found_per_component() {
        let mut bytes = Vec::new();
        for v in [-1.0f32, 0.5, 0.1, 0.1, f32::NAN, 0.3] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        // Floats compared as stored: the declared 0.1 is the stored 0.1f.
        let accessors = r#"[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC2","min":[0,0.1],"max":[1,0.5]}]"#;
        assert_eq!(
            found(accessors, &bytes),
            [
                "ACCESSOR_INVALID_FLOAT /accessors/0",
                "ACCESSOR_MIN_MISMATCH /accessors/0/min/0",
                "ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND /accessors/0/min/0",
                "ACCESSOR_MAX_MISMATCH /accessors/0/max/0",
            ]
        );
    }

    #[test]
    fn every_non_finite_component_of_an_element_is_a_finding() {
        let mut bytes = Vec::new();
        for v in [f32::NEG_INFINITY, f32::NAN, f32::INFINITY] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let accessors = r#"[{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3"}]"#;
        assert_eq!(
            found(accessors, &bytes),
            ["ACCESSOR_INVALID_FLOAT /accessors/0"; 3]
        );
    }

    /// The findings, messages included, of `accessor`'s values under `bounds` (a JSON members
    /// text), read as they lie (`sparse` false) or through the general reader, with its first
    /// element substituted by itself.
    fn findings_read(
        values: &[f32],
        n: usize,
        stride: usize,
        bounds: &str,
        sparse: bool,
    ) -> Vec<String> {
        let count = values.len() / n;
        let mut bytes = Vec::new();
        for element in values.chunks(n) {
            for v in element {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
            bytes.resize(bytes.len() + stride - 4 * n, 0xAB);
        }
        let base_len = bytes.len();
        bytes.extend_from_slice(&0u32.to_le_bytes());
        for v in &values[..n] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let kind = match n {
            1 => "SCALAR",
            2 => "VEC2",
            3 => "VEC3",
            4 => "VEC4",
            9 => "MAT3",
            _ => "MAT4",
        };
        let sparse = if sparse {
            r#","sparse":{"count":1,"indices":{"bufferView":1,"componentType":5125},"values":{"bufferView":2}}"#
        } else {
            ""
        };
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{data}"}}],
            "bufferViews":[{{"buffer":0,"byteLength":{base_len},"byteStride":{stride}}},
                {{"buffer":0,"byteOffset":{base_len},"byteLength":4}},{{"buffer":0,"byteOffset":{},"byteLength":{}}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{count},"type":"{kind}"{bounds}{sparse}}}]}}"#,
            bytes.len(),
            base_len + 4,
            4 * n
        );
        crate::rules::findings_with_messages_of(&AccessorBounds, &text)
    }

    #[test]
    fn floats_read_as_they_lie_give_the_general_readers_findings() {
        // Values from a fixed sequence: ordinary ones, both zeros, extremes and non-finite
        // ones; bounds declared, absent, exact or off.
        let pool = [
            0.0f32,
            -0.0,
            1.0,
            -1.0,
            0.1,
            0.5,
            3.25e7,
            -7.5e-8,
            f32::MAX,
            f32::MIN,
            f32::MIN_POSITIVE,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            2.0,
            -0.25,
        ];
        let mut codes_seen = std::collections::BTreeMap::new();
        let mut state = 12345u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            pool[(state >> 28) as usize]
        };
        // Every width the walk is made for: SCALAR, VEC2, VEC3, VEC4 (and MAT2), MAT3, MAT4.
        for n in PACKED_WIDTHS {
            for count in [1, 2, 7] {
                let values: Vec<f32> = (0..n * count).map(|_| next()).collect();
                let finite: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
                let lowest = finite.iter().copied().fold(f32::INFINITY, f32::min);
                let list = |v: f32| vec![format!("{v:?}"); n].join(",").replace("inf", "1e39");
                for bounds in [
                    String::new(),
                    format!(r#","min":[{}],"max":[{}]"#, list(lowest), list(0.5)),
                    format!(r#","min":[{}]"#, list(-0.0)),
                ] {
                    for stride in [4 * n, 4 * n + 4] {
                        let fast = findings_read(&values, n, stride, &bounds, false);
                        let general = findings_read(&values, n, stride, &bounds, true);
                        assert_eq!(fast, general, "{n} components, {count} elements, {bounds}");
                        for finding in &fast {
                            let code = finding.split(' ').next().unwrap_or_default();
                            *codes_seen.entry(code.to_string()).or_insert(0) += 1;
                        }
                    }
                }
            }
        }
        // Every finding the rule makes was compared, not only clean accessors.
        let codes: Vec<&str> = codes_seen.keys().map(String::as_str).collect();
        assert_eq!(
            codes,
            [
                "ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND",
                "ACCESSOR_ELEMENT_OUT_OF_MIN_BOUND",
                "ACCESSOR_INVALID_FLOAT",
                "ACCESSOR_MAX_MISMATCH",
                "ACCESSOR_MIN_MISMATCH",
            ],
            "{codes_seen:?}"
        );
    }

    #[test]
    fn integer_bounds_are_exact_and_matching_bounds_are_clean() {
        let bytes = [0u8, 255, 7, 9];
        let exact = r#"[{"bufferView":0,"componentType":5121,"count":2,"type":"VEC2","min":[0,9],"max":[7,255]}]"#;
        assert_eq!(found(exact, &bytes), Vec::<String>::new());
        let off = r#"[{"bufferView":0,"componentType":5121,"count":2,"type":"VEC2","min":[0,9],"max":[7,254]}]"#;
        assert_eq!(
            found(off, &bytes),
            [
                "ACCESSOR_MAX_MISMATCH /accessors/0/max/1",
                "ACCESSOR_ELEMENT_OUT_OF_MAX_BOUND /accessors/0/max/1"
            ]
        );
    }
}
