//! The asset version: glTF 2.0 loaders read any 2.x asset and no other major version. The
//! schema checks the MAJOR.MINOR pattern; this rule reads the numbers. A minor version above 0
//! is a warning (a 2.0 loader may miss what it adds); `minVersion` above `version` is an error.

use super::{Context, Rule};
use crate::diagnostics::{Code, Diagnostic, Severity};

pub const UNKNOWN_ASSET_MAJOR_VERSION: Code = Code::new(
    "UNKNOWN_ASSET_MAJOR_VERSION",
    Severity::Error,
    "asset.version has a major version other than 2.",
);
pub const UNKNOWN_ASSET_MINOR_VERSION: Code = Code::new(
    "UNKNOWN_ASSET_MINOR_VERSION",
    Severity::Warning,
    "asset.version has a minor version newer than 2.0.",
);
pub const ASSET_MIN_VERSION_GREATER_THAN_VERSION: Code = Code::new(
    "ASSET_MIN_VERSION_GREATER_THAN_VERSION",
    Severity::Error,
    "asset.minVersion is greater than asset.version.",
);

pub struct AssetVersion;

/// MAJOR.MINOR as numbers; `None` for text the schema's pattern refuses.
fn parse(text: &str) -> Option<(u32, u32)> {
    let (major, minor) = text.split_once('.')?;
    let number = |s: &str| {
        (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
            .then(|| s.parse().ok())
            .flatten()
    };
    Some((number(major)?, number(minor)?))
}

impl Rule for AssetVersion {
    fn reads(&self) -> super::Reads {
        super::Reads::properties(&["asset"])
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &UNKNOWN_ASSET_MAJOR_VERSION,
            &UNKNOWN_ASSET_MINOR_VERSION,
            &ASSET_MIN_VERSION_GREATER_THAN_VERSION,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let text = |key: &str| cx.json().get("asset")?.get(key)?.as_str();
        let Some((major, minor)) = text("version").as_deref().and_then(parse) else {
            return;
        };
        if major != 2 {
            out.push(Diagnostic::new(
                &UNKNOWN_ASSET_MAJOR_VERSION,
                "/asset/version",
                format!(
                    "asset version {major}.{minor}: glTF 2.0 loaders read only major version 2"
                ),
            ));
        } else if minor > 0 {
            out.push(Diagnostic::new(
                &UNKNOWN_ASSET_MINOR_VERSION,
                "/asset/version",
                format!("asset version 2.{minor} is newer than glTF 2.0"),
            ));
        }
        if let Some((min_major, min_minor)) = text("minVersion").as_deref().and_then(parse) {
            if (min_major, min_minor) > (major, minor) {
                out.push(Diagnostic::new(
                    &ASSET_MIN_VERSION_GREATER_THAN_VERSION,
                    "/asset/minVersion",
                    format!(
                        "minVersion {min_major}.{min_minor} is greater than version {major}.{minor}"
                    ),
                ));
            }
        }
    }
}
