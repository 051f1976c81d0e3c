//! Camera projections, beyond their schema (the spec's camera section and the Khronos
//! glTF-Validator's semantic checks):
//!
//! - CAMERA_XMAG_YMAG_ZERO (error): an orthographic `xmag` or `ymag` of 0 gives a singular
//!   projection matrix; at the value.
//! - CAMERA_XMAG_YMAG_NEGATIVE (warning): a negative one flips the image; at the value.
//! - CAMERA_ZFAR_LEQUAL_ZNEAR (error): `zfar` not beyond `znear`; at the projection object.
//! - CAMERA_YFOV_GEQUAL_PI (warning): a perspective `yfov` of π or more; at the projection object.
//!
//! - UNDEFINED_PROPERTY (error): a camera of type "perspective" or "orthographic" without
//!   that object, which the schema cannot require of the type.
//!
//! Values of the wrong type or range are the schema's findings and are skipped here.

use super::{elements, Context, Rule};
use crate::diagnostics::{codes, Code, Diagnostic, Severity};

pub const CAMERA_XMAG_YMAG_ZERO: Code = Code::new(
    "CAMERA_XMAG_YMAG_ZERO",
    Severity::Error,
    "An orthographic camera's xmag or ymag is 0: its projection matrix is singular.",
);
pub const CAMERA_XMAG_YMAG_NEGATIVE: Code = Code::new(
    "CAMERA_XMAG_YMAG_NEGATIVE",
    Severity::Warning,
    "An orthographic camera's xmag or ymag is negative: the image is flipped.",
);
pub const CAMERA_ZFAR_LEQUAL_ZNEAR: Code = Code::new(
    "CAMERA_ZFAR_LEQUAL_ZNEAR",
    Severity::Error,
    "A camera's zfar is less than or equal to its znear.",
);
pub const CAMERA_YFOV_GEQUAL_PI: Code = Code::new(
    "CAMERA_YFOV_GEQUAL_PI",
    Severity::Warning,
    "A perspective camera's yfov is π or more.",
);

pub struct Cameras;

impl Rule for Cameras {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["cameras"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &codes::UNDEFINED_PROPERTY,
            &CAMERA_XMAG_YMAG_ZERO,
            &CAMERA_XMAG_YMAG_NEGATIVE,
            &CAMERA_ZFAR_LEQUAL_ZNEAR,
            &CAMERA_YFOV_GEQUAL_PI,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        for (i, camera) in elements(cx.json().get("cameras")).enumerate() {
            // The schema cannot tie the projection object to `type`; the spec requires it.
            if let Some(kind) = camera.get("type").and_then(|t| t.as_str()) {
                if matches!(kind.as_ref(), "perspective" | "orthographic")
                    && camera.get(kind.as_ref()).is_none()
                {
                    out.push(Diagnostic::new(
                        &codes::UNDEFINED_PROPERTY,
                        format!("/cameras/{i}"),
                        format!("property '{kind}' must be defined for a camera of type '{kind}'"),
                    ));
                }
            }
            let number = |object: &crate::asset::tape::Node, key: &str| {
                object.get(key).and_then(|v| v.as_f64())
            };
            if let Some(ortho) = camera.get("orthographic").filter(|o| o.is_object()) {
                let at = format!("/cameras/{i}/orthographic");
                for key in ["xmag", "ymag"] {
                    match number(&ortho, key) {
                        Some(0.0) => out.push(Diagnostic::new(
                            &CAMERA_XMAG_YMAG_ZERO,
                            format!("{at}/{key}"),
                            format!("{key} is 0: the projection matrix is singular"),
                        )),
                        Some(v) if v < 0.0 => out.push(Diagnostic::new(
                            &CAMERA_XMAG_YMAG_NEGATIVE,
                            format!("{at}/{key}"),
                            format!("{key} is {v}: a negative magnification flips the image"),
                        )),
                        _ => {}
                    }
                }
                if let (Some(znear), Some(zfar)) = (number(&ortho, "znear"), number(&ortho, "zfar"))
                {
                    zfar_beyond_znear(znear, zfar, &at, out);
                }
            }
            if let Some(perspective) = camera.get("perspective").filter(|p| p.is_object()) {
                let at = format!("/cameras/{i}/perspective");
                if let (Some(znear), Some(zfar)) =
                    (number(&perspective, "znear"), number(&perspective, "zfar"))
                {
                    zfar_beyond_znear(znear, zfar, &at, out);
                }
                if let Some(yfov) = number(&perspective, "yfov") {
                    if yfov >= std::f64::consts::PI {
                        out.push(Diagnostic::new(
                            &CAMERA_YFOV_GEQUAL_PI,
                            at,
                            format!("yfov is {yfov}, π or more"),
                        ));
                    }
                }
            }
        }
    }
}

fn zfar_beyond_znear(znear: f64, zfar: f64, at: &str, out: &mut Vec<Diagnostic>) {
    if zfar <= znear {
        out.push(Diagnostic::new(
            &CAMERA_ZFAR_LEQUAL_ZNEAR,
            at,
            format!("zfar ({zfar}) is less than or equal to znear ({znear})"),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(text: &str) -> Vec<String> {
        crate::rules::findings_of(&Cameras, text)
    }

    #[test]
    fn degenerate_projections_are_found_at_the_reference_validators_pointers() {
        let text = r#"{"asset":{"version":"2.0"},"cameras":[
            {"type":"orthographic","orthographic":{"xmag":1,"ymag":0,"znear":0,"zfar":1}},
            {"type":"orthographic","orthographic":{"xmag":-1,"ymag":1,"znear":2,"zfar":2}},
            {"type":"perspective","perspective":{"yfov":3.2,"znear":1,"zfar":0.5}},
            {"type":"perspective","perspective":{"yfov":1,"znear":0.1}},
            {"type":"orthographic"}]}"#;
        assert_eq!(
            found(text),
            [
                "CAMERA_XMAG_YMAG_ZERO /cameras/0/orthographic/ymag",
                "CAMERA_XMAG_YMAG_NEGATIVE /cameras/1/orthographic/xmag",
                "CAMERA_ZFAR_LEQUAL_ZNEAR /cameras/1/orthographic",
                "CAMERA_ZFAR_LEQUAL_ZNEAR /cameras/2/perspective",
                "CAMERA_YFOV_GEQUAL_PI /cameras/2/perspective",
                "UNDEFINED_PROPERTY /cameras/4",
            ]
        );
    }
}
