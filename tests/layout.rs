//! Format-preserving edits: `velvet migrate` on one document written in many layouts. Every
//! input byte comes out in order (migrating sheen to fuzz only inserts), what is inserted
//! follows the file's own layout, and the output validates.

use std::path::Path;
use std::process::Command;
use velvet::diagnostics::{Settings, Severity};
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

/// True when every byte of `input` appears in `output` in the same order.
fn is_subsequence(input: &[u8], output: &[u8]) -> bool {
    let mut rest = output.iter();
    input.iter().all(|b| rest.any(|o| o == b))
}

/// The bytes `output` holds beyond `input` (the inserted text), in order.
fn inserted(input: &[u8], output: &[u8]) -> String {
    let mut extra = Vec::new();
    let mut i = 0;
    for &b in output {
        if i < input.len() && input[i] == b {
            i += 1;
        } else {
            extra.push(b);
        }
    }
    String::from_utf8(extra).unwrap()
}

fn migrate(dir: &Path, name: &str, text: &str) -> (Vec<u8>, Vec<u8>) {
    let input = dir.join(name);
    std::fs::write(&input, text).unwrap();
    let output = dir.join(format!("out-{name}"));
    let out = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(["migrate", "--fast", "-q"])
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let report = validator.validate_file(&output);
    let errors: Vec<_> = report
        .findings
        .iter()
        .filter(|f| f.diagnostic.severity == Severity::Error)
        .map(|f| (f.diagnostic.code, f.diagnostic.pointer.clone()))
        .collect();
    assert!(errors.is_empty(), "{name}: {errors:?}");
    (text.as_bytes().to_vec(), std::fs::read(&output).unwrap())
}

// Exporters write floats with all their digits (0.800000011920929); the sheen stays as the
// fallback, so those bytes must survive the migration as they are.
const SHEEN: &str = r#""KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.800000011920929, 0.25], "sheenRoughnessFactor": 5E-1}"#;

/// A layout case: the file's name, its text, and what every inserted line must satisfy.
type LayoutCase = (&'static str, String, fn(&str) -> bool);

#[test]
fn migrate_keeps_every_byte_and_follows_each_layout() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<LayoutCase> = vec![
        (
            "tabs.gltf",
            format!("{{\n\t\"asset\": {{\n\t\t\"version\": \"2.0\"\n\t}},\n\t\"extensionsUsed\": [\n\t\t\"KHR_materials_sheen\"\n\t],\n\t\"materials\": [\n\t\t{{\n\t\t\t\"name\": \"caf\\u00e9\",\n\t\t\t\"extensions\": {{\n\t\t\t\t{SHEEN}\n\t\t\t}}\n\t\t}}\n\t]\n}}\n"),
            |ins| ins.lines().skip(1).all(|l| l.starts_with('\t') && !l.starts_with(" ")),
        ),
        (
            "two-spaces.gltf",
            format!("{{\n  \"asset\": {{\n    \"version\": \"2.0\"\n  }},\n  \"extensionsUsed\": [\n    \"KHR_materials_sheen\"\n  ],\n  \"materials\": [\n    {{\n      \"extensions\": {{\n        {SHEEN}\n      }}\n    }}\n  ]\n}}\n"),
            |ins| ins.contains("\n          \"fuzzColorFactor\"") && !ins.contains('\t'),
        ),
        (
            "four-spaces-no-final-newline.gltf",
            format!("{{\n    \"asset\": {{\n        \"version\": \"2.0\"\n    }},\n    \"extensionsUsed\": [\n        \"KHR_materials_sheen\"\n    ],\n    \"materials\": [\n        {{\n            \"extensions\": {{\n                {SHEEN}\n            }}\n        }}\n    ]\n}}"),
            |ins| ins.contains("\n                    \"fuzzColorFactor\"") && !ins.ends_with('\n'),
        ),
        (
            "one-line-objects.gltf",
            format!("{{\n  \"asset\": {{\"version\": \"2.0\"}},\n  \"extensionsUsed\": [\"KHR_materials_sheen\"],\n  \"materials\": [\n    {{\"extensions\": {{{SHEEN}}}}}\n  ]\n}}\n"),
            |ins| !ins.contains('\n'),
        ),
        (
            "minified.gltf",
            r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_sheen"],"materials":[{"extensions":{"KHR_materials_sheen":{"sheenColorFactor":[1.0,0.5,0.25],"sheenRoughnessFactor":5E-1}}}]}"#.to_string(),
            |ins| !ins.contains('\n') && !ins.contains(": ") && !ins.contains(", "),
        ),
        (
            "crlf.gltf",
            format!("{{\r\n  \"asset\": {{\r\n    \"version\": \"2.0\"\r\n  }},\r\n  \"extensionsUsed\": [\r\n    \"KHR_materials_sheen\"\r\n  ],\r\n  \"materials\": [\r\n    {{\r\n      \"extensions\": {{\r\n        {SHEEN}\r\n      }}\r\n    }}\r\n  ]\r\n}}\r\n"),
            |ins| ins.matches('\n').count() == ins.matches("\r\n").count() && ins.contains("\r\n"),
        ),
    ];
    for (name, text, follows_layout) in cases {
        let (input, output) = migrate(dir.path(), name, &text);
        assert!(
            is_subsequence(&input, &output),
            "{name}: an input byte was lost or moved"
        );
        let ins = inserted(&input, &output);
        assert!(ins.contains("\"KHR_materials_fuzz\""), "{name}: {ins}");
        assert!(follows_layout(&ins), "{name}: inserted text {ins:?}");
        // Untouched spellings stay: the exponent and the unicode escape.
        let out = String::from_utf8(output).unwrap();
        assert!(out.contains("5E-1"), "{name}");
    }
}

#[test]
fn a_file_with_nothing_to_migrate_is_left_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let text = "{\r\n\t\"asset\": {\"version\": \"2.0\"},  \"extras\": {\"n\": 1E2}\r\n}";
    let input = dir.path().join("plain.gltf");
    std::fs::write(&input, text).unwrap();
    let output = dir.path().join("out.gltf");
    let status = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(["migrate", "-q"])
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(std::fs::read(&output).unwrap(), text.as_bytes());
}
