//! Values out of range, clamped: a material's number above the schema's maximum or below its
//! minimum is set to that bound (the finding names it), for the core's material properties and
//! every extension's that a schema judges. Unsafe: the value changes, though to
//! the one nearest what the file says that a loader may read. Only materials' numbers are
//! clamped (their factors); an index out of range names another object, and an exclusive bound
//! has no nearest value, so neither is fixed.

use super::fixers::{last_token, Fixer, Planning, Proposal};
use crate::diagnostics::{codes::VALUE_NOT_IN_RANGE, Diagnostic, Safety};
use crate::edit::Edit;

/// The bound a VALUE_NOT_IN_RANGE message names, for an inclusive bound: the core's and the
/// extensions' schema messages ("… is above the maximum 1") and the layer schemas' ("… is
/// greater than the maximum of 1"). An exclusive bound's message names none.
fn bound(message: &str) -> Option<f64> {
    const INCLUSIVE: [&str; 4] = [
        " is greater than the maximum of ",
        " is less than the minimum of ",
        " is above the maximum ",
        " is below the minimum ",
    ];
    let (_, bound) = INCLUSIVE.iter().find_map(|at| message.split_once(at))?;
    // A bound may be followed by more words (": an index is …").
    let number = bound.split([':', ' ']).next()?;
    number.parse::<f64>().ok().filter(|b| b.is_finite())
}

pub const OUT_OF_RANGE: Fixer = Fixer {
    code: &VALUE_NOT_IN_RANGE,
    safety: Safety::Unsafe,
    about: "clamps a material's number into its range",
    propose: |planning: &Planning, d: &Diagnostic| {
        let asset = planning.asset;
        if !d.pointer.starts_with("/materials/") || last_token(&d.pointer)? == "index" {
            return None;
        }
        asset.root().pointer(&d.pointer)?.as_f64()?;
        let to = bound(&d.message)?;
        let key = d
            .pointer
            .rsplit('/')
            .find(|t| crate::asset::pointer::array_index(t).is_none())
            .unwrap_or_default();
        Some(Proposal {
            title: format!("clamp {key} to {to}"),
            edits: vec![Edit::set(d.pointer.clone(), serde_json::json!(to))],
        })
    },
};

#[cfg(test)]
mod tests {
    #[test]
    fn the_bound_is_read_from_inclusive_messages_only() {
        assert_eq!(
            super::bound("1.5 is greater than the maximum of 1.0"),
            Some(1.0)
        );
        assert_eq!(super::bound("-2 is less than the minimum of 0"), Some(0.0));
        assert_eq!(
            super::bound("0 is less than or equal to the minimum of 0"),
            None
        );
        assert_eq!(super::bound("1.5 is above the maximum 1.0"), Some(1.0));
        assert_eq!(super::bound("-0.5 is below the minimum 0"), Some(0.0));
        assert_eq!(super::bound("0 is not above the exclusive minimum 0"), None);
    }
}
