//! An applier of report fixes written apart from velvet, as a consumer of ruff's or eslint's
//! fixes applies them: every edit of a JSON report (or of a SARIF log) in one pass, in order of
//! place, none overlapping another; for a .glb, to the text of its JSON chunk, framed again.
//! [`check`] holds the result to the bytes `velvet validate --fix --unsafe-fixes` writes.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// The files below `dir` (sorted, folders walked in order) that `keep` maps to a path, as it
/// maps them.
pub fn files_under(
    dir: &Path,
    keep: &dyn Fn(&Path) -> Option<std::path::PathBuf>,
) -> Vec<std::path::PathBuf> {
    let mut entries: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    let mut out = Vec::new();
    for path in entries {
        if path.is_dir() {
            out.extend(files_under(&path, keep));
        } else if let Some(kept) = keep(&path) {
            out.push(kept);
        }
    }
    out
}

/// One replacement: bytes `start..end` of the text become `text`.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct Edit {
    pub start: usize,
    pub end: usize,
    pub text: String,
}

fn velvet(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_velvet"))
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .args(args)
        .output()
        .unwrap()
}

impl Edit {
    /// One text edit of a JSON report's fix.
    pub fn of_json_edit(e: &Value) -> Edit {
        Edit {
            start: e["location"]["offset"].as_u64().unwrap() as usize,
            end: e["endLocation"]["offset"].as_u64().unwrap() as usize,
            text: e["content"].as_str().unwrap().to_string(),
        }
    }
}

/// Every edit of every fix a JSON report gives with its messages.
pub fn json_edits(report: &Value) -> Vec<Edit> {
    report["issues"]["messages"]
        .as_array()
        .into_iter()
        .flatten()
        .flat_map(|m| m["fix"]["edits"].as_array().into_iter().flatten())
        .map(Edit::of_json_edit)
        .collect()
}

/// Every replacement of every fix of a SARIF log's results.
pub fn sarif_edits(log: &Value) -> Vec<Edit> {
    let mut out = Vec::new();
    for result in log["runs"][0]["results"].as_array().into_iter().flatten() {
        for fix in result["fixes"].as_array().into_iter().flatten() {
            assert!(
                matches!(
                    fix["properties"]["applicability"].as_str(),
                    Some("safe" | "unsafe")
                ),
                "a SARIF fix says whether it is safe: {fix}"
            );
            for change in fix["artifactChanges"].as_array().unwrap() {
                for r in change["replacements"].as_array().unwrap() {
                    let region = &r["deletedRegion"];
                    let start = region["byteOffset"].as_u64().unwrap() as usize;
                    out.push(Edit {
                        start,
                        end: start + region["byteLength"].as_u64().unwrap() as usize,
                        text: r["insertedContent"]["text"]
                            .as_str()
                            .unwrap_or_default()
                            .to_string(),
                    });
                }
            }
        }
    }
    out
}

/// `source` with `edits` made in one pass; `Err` naming two edits that overlap or insert at
/// one place (their order would be a guess).
pub fn apply(source: &[u8], mut edits: Vec<Edit>) -> Result<Vec<u8>, String> {
    edits.sort();
    for pair in edits.windows(2) {
        let (a, b) = (&pair[0], &pair[1]);
        if a.end > b.start || (a.start == a.end && a.start == b.start) {
            return Err(format!("overlapping edits: {a:?} and {b:?}"));
        }
    }
    let mut out = Vec::new();
    let mut at = 0;
    for e in edits {
        if e.end < e.start || e.end > source.len() {
            return Err(format!("an edit outside the text: {e:?}"));
        }
        out.extend_from_slice(&source[at..e.start]);
        out.extend_from_slice(e.text.as_bytes());
        at = e.end;
    }
    out.extend_from_slice(&source[at..]);
    Ok(out)
}

/// A .glb's JSON chunk's text, without its padding.
pub fn glb_json(bytes: &[u8]) -> &[u8] {
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let chunk = &bytes[20..20 + length];
    let end = chunk
        .iter()
        .rposition(|&b| b != b' ' && b != 0)
        .map_or(0, |i| i + 1);
    &chunk[..end]
}

/// `Ok` when `bytes` are a GLB laid out as the format says: the header's length the file's,
/// every chunk's length a multiple of 4 and within the file, the JSON chunk padded with spaces.
pub fn well_framed(bytes: &[u8]) -> Result<(), String> {
    let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    if bytes.len() < 20 || &bytes[..4] != b"glTF" || u32_at(8) != bytes.len() {
        return Err(format!(
            "a GLB whose header does not fit its {} bytes",
            bytes.len()
        ));
    }
    let mut at = 12;
    while at < bytes.len() {
        let length = u32_at(at);
        if length % 4 != 0 || at + 8 + length > bytes.len() {
            return Err(format!("a chunk at byte {at} of length {length}"));
        }
        if &bytes[at + 4..at + 8] == b"JSON" && bytes[at + 8..at + 8 + length].ends_with(&[0]) {
            return Err("a JSON chunk padded with NUL bytes".to_string());
        }
        at += 8 + length;
    }
    Ok(())
}

/// What a file's edits give, applied to the text they are of.
fn applied(file: &[u8], glb: bool, edits: Vec<Edit>) -> Result<Vec<u8>, String> {
    if glb {
        apply(glb_json(file), edits)
    } else {
        apply(file, edits)
    }
}

/// Whether `path`'s report edits reproduce `--fix --unsafe-fixes`: `Ok(false)` when its report
/// carries no edits, `Ok(true)` when the JSON report's and the SARIF log's edits, each applied
/// in one pass, give the bytes (of a .glb, the JSON chunk's text) that --fix writes; `Err`
/// saying how they differ otherwise. The file is copied alone into a temporary folder first.
pub fn check(path: &Path) -> Result<bool, String> {
    let dir = tempfile::tempdir().unwrap();
    let name = path.file_name().unwrap().to_str().unwrap().to_string();
    let copy = dir.path().join(&name);
    std::fs::copy(path, &copy).unwrap();
    // A copy of a read-only file is read-only, and --fix refuses to replace it.
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&copy, std::fs::Permissions::from_mode(0o644)).unwrap();
    let glb = name.ends_with(".glb");
    let source = std::fs::read(&copy).unwrap();
    let report: Value = serde_json::from_slice(
        &velvet(dir.path(), &["validate", "--format", "json", &name]).stdout,
    )
    .map_err(|e| format!("{}: the JSON report does not parse: {e}", path.display()))?;
    let from_json = json_edits(&report);
    let has_fixes = report["issues"]["messages"]
        .as_array()
        .into_iter()
        .flatten()
        .any(|m| m["fix"].is_object());
    // A .glb's container fixes have no edits: framing the chunk again is the fix.
    if from_json.is_empty() && !(glb && has_fixes) {
        return Ok(false);
    }
    let log: Value = serde_json::from_slice(
        &velvet(dir.path(), &["validate", "--format", "sarif", &name]).stdout,
    )
    .map_err(|e| format!("{}: the SARIF log does not parse: {e}", path.display()))?;
    let from_sarif = sarif_edits(&log);
    velvet(dir.path(), &["validate", "--fix", "--unsafe-fixes", &name]);
    let written = std::fs::read(&copy).unwrap();
    if glb {
        well_framed(&written).map_err(|e| format!("{}: --fix wrote {e}", path.display()))?;
    }
    let want: &[u8] = if glb { glb_json(&written) } else { &written };
    for (what, edits) in [("JSON report", from_json), ("SARIF log", from_sarif)] {
        let got =
            applied(&source, glb, edits).map_err(|e| format!("{}: {what}: {e}", path.display()))?;
        if got != want {
            return Err(format!(
                "{}: the {what}'s edits give\n{}\nbut --fix --unsafe-fixes writes\n{}",
                path.display(),
                String::from_utf8_lossy(&got),
                String::from_utf8_lossy(want)
            ));
        }
    }
    Ok(true)
}
