//! Integration tests for `velvet validate`: every code has a fixture pair under
//! fixtures/validate/<CODE>/ (triggers + clean twin) with golden expected findings beside them;
//! GLB twins give the same findings as their .gltf; the command's formats and exit codes.
//!
//! Set VELVET_UPDATE_GOLDEN=1 to rewrite the golden files after a deliberate change.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use velvet::diagnostics::Settings;
use velvet::rules::all_codes;
use velvet::rules::schema::Schemas;
use velvet::validate::{FileReport, Validator};

const FIXTURES: &str = "fixtures/validate";

fn validator_for(case: &Path) -> Validator {
    let schema_dir = case.join("schema");
    let schemas = if schema_dir.is_dir() {
        Schemas::with_overrides(&schema_dir).unwrap()
    } else {
        Schemas::builtin()
    };
    let mut load = velvet::asset::LoadOptions::default();
    // A case may lower a loader limit (limits.json) so that its trigger stays small.
    if let Ok(text) = std::fs::read_to_string(case.join("limits.json")) {
        let limits: Value = serde_json::from_str(&text).unwrap();
        if let Some(bytes) = limits["max_document_bytes"].as_u64() {
            load.max_document_bytes = bytes;
        }
    }
    Validator::new(schemas, Settings::default()).with_load_options(load)
}

fn findings(report: &FileReport) -> Value {
    Value::Array(
        report
            .findings
            .iter()
            .map(|f| {
                let d = &f.diagnostic;
                json!({"code": d.code, "severity": d.severity.as_str(), "pointer": d.pointer, "message": d.message})
            })
            .collect(),
    )
}

fn input(case: &Path, stem: &str) -> PathBuf {
    ["gltf", "glb"]
        .iter()
        .map(|ext| case.join(format!("{stem}.{ext}")))
        .find(|p| p.exists())
        .unwrap_or_else(|| panic!("{} has no {stem}.gltf or {stem}.glb", case.display()))
}

fn check_golden(case: &Path, stem: &str, actual: &Value) {
    let golden = case.join(format!("{stem}.expected.json"));
    if std::env::var_os("VELVET_UPDATE_GOLDEN").is_some() {
        std::fs::write(
            &golden,
            serde_json::to_string_pretty(actual).unwrap() + "\n",
        )
        .unwrap();
    }
    let expected: Value = serde_json::from_str(
        &std::fs::read_to_string(&golden).unwrap_or_else(|e| panic!("{}: {e}", golden.display())),
    )
    .unwrap();
    assert_eq!(
        actual,
        &expected,
        "{} differs from its golden findings",
        golden.display()
    );
}

fn cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(FIXTURES)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .collect();
    cases.sort();
    cases
}

#[test]
fn every_code_has_a_fixture_that_triggers_it_and_a_clean_twin_that_does_not() {
    for case in cases() {
        let code = case.file_name().unwrap().to_str().unwrap().to_string();
        let validator = validator_for(&case);
        for (stem, should_contain) in [("triggers", true), ("clean", false)] {
            let report = validator.validate_file(&input(&case, stem));
            let actual = findings(&report);
            check_golden(&case, stem, &actual);
            let has = report.findings.iter().any(|f| f.diagnostic.code == code);
            assert_eq!(
                has,
                should_contain,
                "{code}: {stem} {}",
                if should_contain {
                    "does not trigger it"
                } else {
                    "triggers it"
                }
            );
        }
        let clean = validator.validate_file(&input(&case, "clean"));
        assert_eq!(
            clean.counts.errors,
            0,
            "{code}: the clean twin has errors: {:?}",
            findings(&clean)
        );
    }
}

#[test]
fn every_registered_code_has_a_fixture_folder() {
    let folders: Vec<String> = cases()
        .iter()
        .map(|c| c.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    // A code about the run rather than a file has no asset to trigger it; tests/ci.rs runs it.
    let missing: Vec<&str> = all_codes()
        .iter()
        .filter(|c| {
            !velvet::diagnostics::codes::RUN
                .iter()
                .any(|r| r.name == c.name)
        })
        .map(|c| c.name)
        .filter(|n| !folders.iter().any(|f| f == n))
        .collect();
    assert!(missing.is_empty(), "codes without a fixture: {missing:?}");
}

/// Packs a .gltf fixture into a .glb beside copies of its resources.
fn as_glb(gltf: &Path, dir: &Path) -> PathBuf {
    for entry in std::fs::read_dir(gltf.parent().unwrap()).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, dir.join(path.file_name().unwrap())).unwrap();
        }
    }
    let text = std::fs::read(gltf).unwrap();
    let out = dir.join(gltf.with_extension("glb").file_name().unwrap());
    std::fs::write(&out, velvet::asset::glb::join(&text, None)).unwrap();
    out
}

#[test]
fn glb_twins_report_the_same_codes_and_pointers_as_their_gltf() {
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let key = |r: &FileReport| -> Vec<(String, String)> {
        r.findings
            .iter()
            .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
            .collect()
    };
    for code in [
        "KHR_MATERIALS_SHEEN_ROUGHNESS_TEXTURE_WITHOUT_ALPHA",
        "UNRESOLVED_REFERENCE",
        "MESH_PRIMITIVE_TOO_FEW_TEXCOORDS",
        "KHR_MATERIALS_FUZZ_FALLBACK_CONTRADICTS",
        "UNEXPECTED_PROPERTY",
        "VALUE_NOT_IN_RANGE",
    ] {
        let gltf = Path::new(FIXTURES).join(code).join("triggers.gltf");
        let dir = tempfile::tempdir().unwrap();
        let glb = as_glb(&gltf, dir.path());
        let from_gltf = validator.validate_file(&gltf);
        let from_glb = validator.validate_file(&glb);
        assert!(!key(&from_gltf).is_empty());
        // A .glb that names files beside it is the one difference: URI_GLB, an info.
        let glb_keys: Vec<_> = key(&from_glb)
            .into_iter()
            .filter(|(c, _)| c != "URI_GLB")
            .collect();
        assert_eq!(glb_keys, key(&from_gltf), "{code}");
        // Positions in a GLB are byte offsets into the file, past the 20-byte headers.
        let first = from_glb
            .findings
            .iter()
            .find(|f| f.diagnostic.code != "URI_GLB")
            .unwrap();
        if let Some(p) = first.position {
            let text = std::fs::read(&glb).unwrap();
            assert_eq!(
                text[from_glb.json_offset + p.offset],
                std::fs::read(&gltf).unwrap()[p.offset]
            );
        }
    }
}

fn velvet(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8(out.stderr).unwrap(),
    )
}

#[test]
fn exit_status_follows_fail_on() {
    let hint_only = "fixtures/validate/KHR_MATERIALS_FUZZ_WITHOUT_FALLBACK/triggers.gltf";
    let warning = "fixtures/validate/KHR_MATERIALS_SHEEN_LEGACY_DRAFT/triggers.gltf";
    let error = "fixtures/validate/UNDECLARED_EXTENSION/triggers.gltf";
    assert_eq!(velvet(&["validate", hint_only]).0, 0);
    assert_eq!(velvet(&["validate", warning]).0, 0);
    assert_eq!(velvet(&["validate", "--fail-on", "warning", warning]).0, 1);
    assert_eq!(velvet(&["validate", error]).0, 1);
    assert_eq!(
        velvet(&["validate", "--ignore", "UNDECLARED_EXTENSION", error]).0,
        0
    );
    assert_eq!(
        velvet(&[
            "validate",
            "--fail-on",
            "info",
            "fixtures/validate/KHR_MATERIALS_SHEEN_UNDER_CLEARCOAT/triggers.gltf"
        ])
        .0,
        1
    );
}

#[test]
fn usage_errors_exit_2_with_a_message() {
    let (status, _, err) = velvet(&["validate", "--ignore", "NO_SUCH_CODE", "fixtures"]);
    assert_eq!(status, 2);
    assert!(err.contains("NO_SUCH_CODE"), "{err}");
    assert_eq!(velvet(&["validate"]).0, 2);
    let (status, _, err) = velvet(&["validate", "--schema-dir", "no/such/dir", "fixtures"]);
    assert_eq!(status, 2);
    assert!(err.contains("no/such/dir"), "{err}");
}

#[test]
fn text_output_places_findings_at_line_and_column() {
    let (status, out, _) = velvet(&[
        "validate",
        "fixtures/validate/VALUE_NOT_IN_RANGE/triggers.gltf",
    ]);
    assert_eq!(status, 1);
    let expected = "fixtures/validate/VALUE_NOT_IN_RANGE/triggers.gltf:15:13: error VALUE_NOT_IN_RANGE: 1.5 is greater than the maximum of 1.0\n    at /materials/0/extensions/KHR_materials_sheen/sheenColorFactor/0\n    fix (unsafe, --fix --unsafe-fixes): clamp sheenColorFactor to 1\n1 file checked: 1 error, 0 warnings, 0 info, 0 hints; 1 fixable with --fix --unsafe-fixes\n";
    assert_eq!(out, expected);
}

#[test]
fn json_output_has_the_khronos_report_shape_and_truncates() {
    let (_, out, _) = velvet(&[
        "validate",
        "--format",
        "json",
        "--max-issues",
        "1",
        "fixtures/validate/UNEXPECTED_PROPERTY/triggers.gltf",
    ]);
    let report: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(
        report["uri"],
        "fixtures/validate/UNEXPECTED_PROPERTY/triggers.gltf"
    );
    assert_eq!(report["mimeType"], "model/gltf+json");
    assert_eq!(report["issues"]["numWarnings"], 4);
    assert_eq!(report["issues"]["truncated"], true);
    assert_eq!(
        report["issues"]["messages"],
        json!([{"code": "UNEXPECTED_PROPERTY", "message": "unexpected property 'sheenColour'", "severity": 1,
                "pointer": "/materials/0/extensions/KHR_materials_sheen/sheenColour"}])
    );
    assert_eq!(report["info"]["sheenMaterialCount"], 1);
    assert_eq!(
        report["info"]["extensionsUsed"],
        json!([
            "KHR_materials_pbrSpecularGlossiness",
            "KHR_materials_sheen",
            "KHR_materials_variants"
        ])
    );
}

#[test]
fn several_files_give_an_array_or_json_lines() {
    let a = "fixtures/validate/TYPE_MISMATCH/clean.gltf";
    let b = "fixtures/validate/INVALID_JSON/triggers.gltf";
    let (status, out, _) = velvet(&["validate", "--format", "json", a, b]);
    assert_eq!(status, 1);
    let reports: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(reports.as_array().unwrap().len(), 2);
    assert_eq!(reports[1]["issues"]["messages"][0]["code"], "INVALID_JSON");
    assert!(
        reports[1].get("info").is_none(),
        "an unparsable file has no info"
    );
    let (_, out, _) = velvet(&["validate", "--format", "jsonl", a, b]);
    let lines: Vec<Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0]["issues"]["numErrors"], 0);
}

#[test]
fn folders_are_searched_recursively_and_a_missing_path_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("a/b")).unwrap();
    std::fs::copy(
        "fixtures/validate/TYPE_MISMATCH/clean.gltf",
        dir.path().join("a/b/one.GLTF"),
    )
    .unwrap();
    std::fs::copy(
        "fixtures/validate/GLB_INVALID_MAGIC/clean.glb",
        dir.path().join("a/two.glb"),
    )
    .unwrap();
    std::fs::write(dir.path().join("a/notes.txt"), "not an asset").unwrap();
    let (status, out, _) = velvet(&[
        "validate",
        "--format",
        "jsonl",
        dir.path().to_str().unwrap(),
    ]);
    assert_eq!(status, 0);
    let lines: Vec<Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let uris: Vec<String> = lines
        .iter()
        .map(|l| {
            l["uri"]
                .as_str()
                .unwrap()
                .rsplit('/')
                .next()
                .unwrap()
                .to_string()
        })
        .collect();
    assert_eq!(uris, ["one.GLTF", "two.glb"]);
    assert_eq!(lines[0]["issues"]["numErrors"], 0);
    assert_eq!(lines[1]["issues"]["numErrors"], 0);
    // A path that does not exist stops the run before anything is read, naming the path.
    let missing = dir.path().join("missing.gltf");
    let (status, out, err) = velvet(&[
        "validate",
        dir.path().to_str().unwrap(),
        missing.to_str().unwrap(),
    ]);
    assert_eq!(status, 2);
    assert_eq!(out, "");
    assert_eq!(
        err,
        format!("velvet: {}: no such file or folder\n", missing.display())
    );
}

#[test]
fn codes_command_lists_every_registered_code_once() {
    let (status, out, _) = velvet(&["codes"]);
    assert_eq!(status, 0);
    let header: Vec<&str> = out.lines().next().unwrap().split_whitespace().collect();
    assert_eq!(header, ["code", "severity", "fix", "meaning"]);
    let names: Vec<&str> = out
        .lines()
        .skip(1)
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    let registry: Vec<&str> = all_codes().iter().map(|c| c.name).collect();
    assert_eq!(names, registry);
    let line = out
        .lines()
        .find(|l| l.starts_with("KHR_MATERIALS_FUZZ_ROUGHNESS_DEFAULT_AMBIGUOUS "))
        .unwrap();
    assert_eq!(line.split_whitespace().nth(1), Some("hint"), "{line}");
}

#[test]
fn codes_table_in_the_docs_is_the_registry() {
    let readme = std::fs::read_to_string("docs/codes.md").unwrap();
    let start = readme
        .find("<!-- codes:start -->\n")
        .expect("docs/codes.md has the codes table markers")
        + "<!-- codes:start -->\n".len();
    let end = readme.find("<!-- codes:end -->").unwrap();
    let (_, table, _) = velvet(&["codes", "--format", "markdown"]);
    assert_eq!(
        &readme[start..end],
        table,
        "regenerate with `velvet codes --format markdown`"
    );
}

// ---------------------------------------------------------------------------------------------
// The core check: valid glTF that a stricter typed model refused

/// A PNG, a lossless WebP and a KTX2 header of 2×2 pixels, written into `dir`.
fn write_images(dir: &Path) {
    use image::ImageEncoder;
    let pixels = [200u8; 2 * 2 * 3];
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&pixels, 2, 2, image::ExtendedColorType::Rgb8)
        .unwrap();
    std::fs::write(dir.join("a.png"), png).unwrap();
    let mut webp = Vec::new();
    image::codecs::webp::WebPEncoder::new_lossless(&mut webp)
        .write_image(&pixels, 2, 2, image::ExtendedColorType::Rgb8)
        .unwrap();
    std::fs::write(dir.join("a.webp"), webp).unwrap();
    // KTX2: identifier, then vkFormat, typeSize, pixelWidth, pixelHeight (the header is all
    // velvet reads).
    let mut ktx2 = b"\xABKTX 20\xBB\r\n\x1A\n".to_vec();
    for word in [0u32, 1, 2, 2] {
        ktx2.extend_from_slice(&word.to_le_bytes());
    }
    ktx2.resize(80, 0);
    std::fs::write(dir.join("a.ktx2"), ktx2).unwrap();
    // Formats velvet does not read: their headers are not velvet's to judge.
    std::fs::write(dir.join("a.dds"), b"DDS \x7c\0\0\0").unwrap();
    std::fs::write(dir.join("a.avif"), b"\0\0\0\x1cftypavif").unwrap();
}

fn all_findings(path: &Path) -> Vec<String> {
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    validator
        .validate_file(path)
        .findings
        .iter()
        .map(|f| format!("{} {}", f.diagnostic.code, f.diagnostic.pointer))
        .collect()
}

#[test]
fn valid_gltf_that_a_typed_model_refused_is_clean() {
    let dir = tempfile::tempdir().unwrap();
    write_images(dir.path());
    let asset = json!({"version": "2.0"});
    let cases = [
        (
            // (A primitive without POSITION is valid too, and a warning, as in the Khronos
            // validator: fixtures/validate/MESH_PRIMITIVE_NO_POSITION.)
            "an accessor without bufferView (zero-filled)",
            json!({"asset": asset,
                "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}]}),
        ),
        (
            "a texture whose image comes from EXT_texture_webp",
            json!({"asset": asset,
                "extensionsUsed": ["EXT_texture_webp"], "extensionsRequired": ["EXT_texture_webp"],
                "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
                "textures": [{"extensions": {"EXT_texture_webp": {"source": 0}}}],
                "images": [{"uri": "a.webp"}]}),
        ),
        (
            "a texture whose image comes from KHR_texture_basisu",
            json!({"asset": asset,
                "extensionsUsed": ["KHR_texture_basisu"], "extensionsRequired": ["KHR_texture_basisu"],
                "materials": [{"emissiveTexture": {"index": 0}}],
                "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
                "images": [{"uri": "a.ktx2", "mimeType": "image/ktx2"}]}),
        ),
        (
            "an animation channel target without node",
            json!({"asset": asset,
                "accessors": [{"componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
                              {"componentType": 5126, "count": 2, "type": "VEC4"}],
                "animations": [{"channels": [{"sampler": 0, "target": {"path": "rotation"}}],
                                "samplers": [{"input": 0, "output": 1}]}]}),
        ),
        (
            "integers written as 1.0",
            json!({"asset": asset, "scene": 0.0, "scenes": [{"nodes": [0.0]}], "nodes": [{"mesh": 0.0}],
                "accessors": [{"componentType": 5126.0, "count": 3.0, "type": "VEC3"}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0.0}, "mode": 4.0}]}],
                "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0.0, "texCoord": 0.0}}}],
                "textures": [{"source": 0.0}], "images": [{"uri": "a.png"}]}),
        ),
        (
            "images in formats that extensions bring (DDS with its mimeType, AVIF by its name)",
            json!({"asset": asset,
                "extensionsUsed": ["MSFT_texture_dds", "EXT_texture_avif"],
                "materials": [{"normalTexture": {"index": 0}, "emissiveTexture": {"index": 1}}],
                "textures": [{"extensions": {"MSFT_texture_dds": {"source": 0}}},
                             {"extensions": {"EXT_texture_avif": {"source": 1}}}],
                "images": [{"uri": "a.dds", "mimeType": "image/vnd-ms.dds"}, {"uri": "a.avif"}]}),
        ),
        (
            "a scene without nodes",
            json!({"asset": asset, "scene": 0, "scenes": [{"name": "empty"}]}),
        ),
    ];
    for (what, doc) in cases {
        let path = dir.path().join("case.gltf");
        std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
        assert_eq!(all_findings(&path), Vec::<String>::new(), "{what}");
    }
}

#[test]
fn every_missing_resource_is_one_file_not_found_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let doc = json!({"asset": {"version": "2.0"},
        "buffers": [{"byteLength": 12, "uri": "mesh.bin"}],
        "images": [{"uri": "a.png"}, {"uri": "b%20c.jpg"}],
        "textures": [{"source": 0}, {"source": 1}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                       "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1],
                           "sheenColorTexture": {"index": 1}, "sheenRoughnessFactor": 0.5,
                           "sheenRoughnessTexture": {"index": 1}}}}],
        "extensionsUsed": ["KHR_materials_sheen"]});
    let path = dir.path().join("lfs-less.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    assert_eq!(
        all_findings(&path),
        [
            "FILE_NOT_FOUND /buffers/0/uri",
            "FILE_NOT_FOUND /images/0/uri",
            "FILE_NOT_FOUND /images/1/uri"
        ]
    );
}

#[test]
fn links_are_judged_by_where_they_lead_a_linked_folder_on_the_way_included() {
    let dir = tempfile::tempdir().unwrap();
    let outside = dir.path().join("secret");
    std::fs::create_dir(&outside).unwrap();
    write_images(&outside);
    let assets = dir.path().join("assets");
    std::fs::create_dir_all(assets.join("own")).unwrap();
    write_images(&assets.join("own"));
    // A file link out, a folder on the way out, a link that stays inside, and the asset's
    // folder itself reached through a link.
    std::os::unix::fs::symlink(outside.join("a.png"), assets.join("fabric.png")).unwrap();
    std::os::unix::fs::symlink(&outside, assets.join("tex")).unwrap();
    std::os::unix::fs::symlink(assets.join("own/a.png"), assets.join("alias.png")).unwrap();
    std::os::unix::fs::symlink(&assets, dir.path().join("via")).unwrap();
    let doc = json!({"asset": {"version": "2.0"},
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 2}}},
                      {"pbrMetallicRoughness": {"baseColorTexture": {"index": 3}}}],
        "textures": [{"source": 0}, {"source": 1}, {"source": 2}, {"source": 3}],
        "images": [
        {"uri": "fabric.png"}, {"uri": "tex/a.png"}, {"uri": "alias.png"}, {"uri": "own/a.png"}
    ]});
    let path = assets.join("links.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    let expected = [
        "URI_NOT_FOLLOWED /images/0/uri",
        "URI_NOT_FOLLOWED /images/1/uri",
    ];
    assert_eq!(all_findings(&path), expected);
    assert_eq!(
        all_findings(&dir.path().join("via").join("links.gltf")),
        expected
    );
    let (status, out, _) = velvet(&["validate", "--allow-outside-uris", path.to_str().unwrap()]);
    assert_eq!(
        (status, out.contains("URI_NOT_FOLLOWED")),
        (0, false),
        "{out}"
    );
}

#[test]
fn a_git_lfs_pointer_is_named_with_the_command_that_fetches_it() {
    let (status, out, _) = velvet(&[
        "validate",
        "fixtures/validate/GIT_LFS_POINTER/triggers.gltf",
    ]);
    assert_eq!(status, 1);
    assert!(
        out.contains("error GIT_LFS_POINTER: 'pointer.png' is a Git LFS pointer file, not its content: fetch it with `git lfs pull`"),
        "{out}"
    );
}

#[test]
fn no_data_and_data_false_leave_out_the_checks_that_read_accessor_data() {
    let trigger = "fixtures/validate/ACCESSOR_MIN_MISMATCH/triggers.gltf";
    let (status, out, _) = velvet(&["validate", "--format", "jsonl", trigger]);
    assert_eq!(status, 1, "{out}");
    assert!(out.contains("\"ACCESSOR_MIN_MISMATCH\""), "{out}");
    let (status, out, _) = velvet(&["validate", "--format", "jsonl", "--no-data", trigger]);
    assert_eq!(status, 0, "{out}");
    let report: Value = serde_json::from_str(out.trim()).unwrap();
    assert_eq!(report["issues"]["messages"], json!([]));
    // The same from velvet.toml, which `velvet config` shows.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(trigger, dir.path().join("a.gltf")).unwrap();
    std::fs::write(dir.path().join("velvet.toml"), "data = false\n").unwrap();
    let file = dir.path().join("a.gltf");
    let (status, out, _) = velvet(&["validate", file.to_str().unwrap()]);
    assert_eq!(status, 0, "{out}");
    let (_, shown, _) = velvet(&["config", file.to_str().unwrap()]);
    assert!(
        shown.contains("data = false  # velvet.toml (accessor data and image bytes not read)"),
        "{shown}"
    );
}

#[test]
fn a_header_only_glb_is_an_error_and_trailing_bytes_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let header_only = dir.path().join("header.glb");
    std::fs::write(&header_only, b"glTF\x02\0\0\0\x0c\0\0\0").unwrap();
    let (status, out, _) = velvet(&["validate", header_only.to_str().unwrap()]);
    assert_eq!(status, 1);
    assert!(
        out.contains(
            "error GLB_LENGTH_TOO_SMALL: the GLB header declares 12 bytes, leaving no room for a chunk"
        ),
        "{out}"
    );
    let (status, out, _) = velvet(&["validate", "fixtures/validate/GLB_EXTRA_DATA/triggers.glb"]);
    assert_eq!(status, 0, "{out}");
    assert!(
        out.contains("warning GLB_EXTRA_DATA: the file has 8 bytes after the 84 its GLB header declares; they are ignored"),
        "{out}"
    );
}

// ---------------------------------------------------------------------------------------------
// The issue cap and the JSON shape

#[test]
fn a_capped_run_fails_on_errors_it_does_not_list_and_lists_errors_first() {
    let mixed = "fixtures/ci/project/assets/mixed.gltf";
    let (status, out, _) = velvet(&["validate", "--max-issues", "1", mixed]);
    assert_eq!(status, 1, "{out}");
    let first = out.lines().next().unwrap();
    assert!(first.contains(": error "), "{out}");
    assert!(
        out.contains(&format!("{mixed}: 5 more issues not shown (--max-issues)")),
        "{out}"
    );
    assert!(
        out.ends_with(
            "1 file checked: 2 errors, 1 warning, 1 info, 2 hints; 2 fixable with --fix (1 more with --unsafe-fixes)\n"
        ),
        "{out}"
    );
    let (_, out, _) = velvet(&["validate", "--format", "json", "--max-issues", "2", mixed]);
    let report: Value = serde_json::from_str(&out).unwrap();
    let severities: Vec<&Value> = report["issues"]["messages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| &m["severity"])
        .collect();
    assert_eq!(severities, [&json!(0), &json!(0)]);
    assert_eq!(report["issues"]["numErrors"], 2);
    assert_eq!(report["issues"]["truncated"], true);
}

#[test]
fn json_shape_follows_the_arguments_not_the_number_of_files() {
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.gltf");
    std::fs::copy("fixtures/validate/TYPE_MISMATCH/clean.gltf", &one).unwrap();
    let json_of = |args: &[&str]| -> Value {
        let mut all = vec!["validate", "--format", "json"];
        all.extend_from_slice(args);
        serde_json::from_str(&velvet(&all).1).unwrap()
    };
    let file = json_of(&[one.to_str().unwrap()]);
    assert!(file.is_object(), "{file}");
    let folder = json_of(&[dir.path().to_str().unwrap()]);
    assert_eq!(folder.as_array().map(Vec::len), Some(1), "{folder}");
    let both = json_of(&[one.to_str().unwrap(), one.to_str().unwrap()]);
    assert_eq!(both.as_array().map(Vec::len), Some(2), "{both}");
    let sharded = json_of(&["--shard", "1/1", one.to_str().unwrap()]);
    assert_eq!(sharded.as_array().map(Vec::len), Some(1), "{sharded}");
}

#[test]
fn invalid_json_is_placed_at_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.gltf");
    std::fs::write(
        &path,
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"nodes\": [,]\n}\n",
    )
    .unwrap();
    let (status, out, _) = velvet(&["validate", path.to_str().unwrap()]);
    assert_eq!(status, 1);
    let first = out.lines().next().unwrap();
    assert!(
        first.ends_with("broken.gltf:3:13: error INVALID_JSON: line 3, column 13: expected value"),
        "{out}"
    );
}

/// A file large enough for the command to map it rather than read it is reported as a read
/// one is: the finding in its last material, at its line and column.
#[test]
fn a_large_file_reports_its_last_material_at_its_line_and_column() {
    let materials = 600;
    let mut text = String::from(
        "{\n  \"asset\": {\"version\": \"2.0\"},\n  \"extensionsUsed\": [\"KHR_materials_sheen\"],\n  \"materials\": [",
    );
    for i in 0..materials {
        let roughness = if i + 1 == materials { "1.5" } else { "0.75" };
        text.push_str(&format!(
            "{}\n    {{\"name\": \"m{i} {}\", \"extensions\": {{\"KHR_materials_sheen\": {{\"sheenColorFactor\": [0.5, 0.25, 1.0], \"sheenRoughnessFactor\": {roughness}}}}}}}",
            if i > 0 { "," } else { "" },
            "x".repeat(4000)
        ));
    }
    text.push_str("\n  ]\n}\n");
    assert!(text.len() as u64 > 2 << 20);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("large.gltf");
    std::fs::write(&path, &text).unwrap();
    let at = text.rfind("1.5").unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let column = at - text[..at].rfind('\n').unwrap();
    let (status, out, _) = velvet(&["validate", "-q", path.to_str().unwrap()]);
    assert_eq!(status, 1);
    assert_eq!(
        out,
        format!(
            "{}:{line}:{column}: error VALUE_NOT_IN_RANGE: 1.5 is greater than the maximum of \
             1.0\n    at /materials/{}/extensions/KHR_materials_sheen/sheenRoughnessFactor\n    \
             fix (unsafe, --fix --unsafe-fixes): clamp sheenRoughnessFactor to 1\n",
            path.display(),
            materials - 1
        )
    );
}

/// Sets the value at `pointer` in `doc`, making the objects on the way.
fn set(doc: &mut Value, pointer: &str, value: Value) {
    let mut at = doc;
    let tokens: Vec<&str> = pointer.split('/').skip(1).collect();
    for (i, token) in tokens.iter().enumerate() {
        let last = i + 1 == tokens.len();
        at = match at {
            Value::Array(items) => {
                let index: usize = token.parse().unwrap();
                if index == items.len() {
                    items.push(json!({}));
                }
                &mut items[index]
            }
            Value::Object(map) => {
                if last {
                    map.insert(token.to_string(), value);
                    return;
                }
                map.entry(token.to_string()).or_insert_with(|| json!({}))
            }
            other => panic!("{pointer}: {other} holds no members"),
        };
        if last {
            *at = value;
            return;
        }
    }
}

/// A valid document every extension case adds its objects to: a scene whose node draws a mesh
/// with a material, a texture, an animation, and a buffer file (data.bin, written beside it)
/// that holds the accessors and images, none of which velvet reads.
fn extension_base() -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3}, "material": 0, "mode": 0}]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": 1, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 1, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 24, "componentType": 5126, "count": 1, "type": "VEC4"},
            {"bufferView": 0, "byteOffset": 40, "componentType": 5126, "count": 1, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": 1, "type": "SCALAR", "min": [0], "max": [0]},
            {"bufferView": 2, "byteOffset": 4, "componentType": 5126, "count": 1, "type": "VEC3"}
        ],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                        "samplers": [{"input": 4, "output": 5}]}],
        "bufferViews": [{"buffer": 0, "byteLength": 48, "byteStride": 16}, {"buffer": 0, "byteOffset": 48, "byteLength": 16},
                        {"buffer": 0, "byteOffset": 64, "byteLength": 16}],
        "buffers": [{"byteLength": 80, "uri": "data.bin"}]
    })
}

/// One extension's case: the objects it adds (pointer, value), and the one value that puts it
/// out of its schema (pointer, value or `None` to remove it) with the code and pointer of the
/// finding that gives.
struct ExtensionCase {
    extension: &'static str,
    objects: Vec<(&'static str, Value)>,
    bad: (&'static str, Option<Value>),
    expected: (&'static str, &'static str),
}

fn extension_cases() -> Vec<ExtensionCase> {
    let case = |extension, objects, bad, expected| ExtensionCase {
        extension,
        objects,
        bad,
        expected,
    };
    let material = |extension: &'static str, object: Value, property: &'static str, bad: Value| {
        let pointer: &'static str =
            Box::leak(format!("/materials/0/extensions/{extension}/{property}").into_boxed_str());
        case(
            extension,
            vec![(
                Box::leak(format!("/materials/0/extensions/{extension}").into_boxed_str()) as &str,
                object,
            )],
            (pointer, Some(bad)),
            ("VALUE_NOT_IN_RANGE", pointer),
        )
    };
    let meshopt = |extension: &'static str| {
        let view: &'static str =
            Box::leak(format!("/bufferViews/3/extensions/{extension}").into_boxed_str());
        let stride: &'static str = Box::leak(format!("{view}/byteStride").into_boxed_str());
        case(
            extension,
            vec![
                // The fallback buffer has no uri: valid in a .gltf.
                ("/buffers/1", json!({"byteLength": 64})),
                (
                    Box::leak(format!("/buffers/1/extensions/{extension}").into_boxed_str())
                        as &str,
                    json!({"fallback": true}),
                ),
                ("/bufferViews/3", json!({"buffer": 1, "byteLength": 64})),
                (
                    view,
                    json!({"buffer": 0, "byteLength": 16, "byteStride": 4, "count": 4, "mode": "ATTRIBUTES"}),
                ),
            ],
            (stride, Some(json!(300))),
            ("VALUE_NOT_IN_RANGE", stride),
        )
    };
    let node_flag = |extension: &'static str, flag: &'static str| {
        let pointer: &'static str =
            Box::leak(format!("/nodes/0/extensions/{extension}/{flag}").into_boxed_str());
        case(
            extension,
            vec![(
                Box::leak(format!("/nodes/0/extensions/{extension}").into_boxed_str()) as &str,
                json!({ flag: false }),
            )],
            (pointer, Some(json!("no"))),
            ("TYPE_MISMATCH", pointer),
        )
    };
    // A texture extension's image is the second, of the media type the extension brings.
    let texture_source = |extension: &'static str, mime: &str| {
        let pointer: &'static str =
            Box::leak(format!("/textures/0/extensions/{extension}/source").into_boxed_str());
        case(
            extension,
            vec![
                (
                    "/images",
                    json!([{"bufferView": 1, "mimeType": "image/png"}, {"bufferView": 1, "mimeType": mime}]),
                ),
                (
                    Box::leak(format!("/textures/0/extensions/{extension}").into_boxed_str())
                        as &str,
                    json!({ "source": 1 }),
                ),
            ],
            (pointer, Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", pointer),
        )
    };
    vec![
        case(
            "EXT_lights_ies",
            vec![
                ("/extensions/EXT_lights_ies", json!({"lights": [{"uri": "lamp.ies"}]})),
                ("/nodes/0/extensions/EXT_lights_ies", json!({"light": 0, "multiplier": 2, "color": [1, 0.5, 0]})),
            ],
            ("/nodes/0/extensions/EXT_lights_ies/multiplier", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/nodes/0/extensions/EXT_lights_ies/multiplier"),
        ),
        case(
            "EXT_lights_image_based",
            vec![
                (
                    "/extensions/EXT_lights_image_based",
                    json!({"lights": [{"irradianceCoefficients": vec![json!([0, 0, 0]); 9],
                                       "specularImages": [[0, 0, 0, 0, 0, 0]], "specularImageSize": 256}]}),
                ),
                ("/scenes/0/extensions/EXT_lights_image_based", json!({"light": 0})),
            ],
            ("/extensions/EXT_lights_image_based/lights/0/intensity", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/extensions/EXT_lights_image_based/lights/0/intensity"),
        ),
        case(
            "EXT_mesh_gpu_instancing",
            vec![("/nodes/0/extensions/EXT_mesh_gpu_instancing", json!({"attributes": {"TRANSLATION": 0}}))],
            ("/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes/TRANSLATION", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/nodes/0/extensions/EXT_mesh_gpu_instancing/attributes/TRANSLATION"),
        ),
        case(
            "EXT_mesh_manifold",
            vec![("/meshes/0/extensions/EXT_mesh_manifold", json!({"manifoldPrimitive": {"attributes": {"POSITION": 0}}}))],
            ("/meshes/0/extensions/EXT_mesh_manifold/mergeIndices", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/meshes/0/extensions/EXT_mesh_manifold/mergeIndices"),
        ),
        case(
            "EXT_mesh_primitive_edge_visibility",
            vec![(
                "/meshes/0/primitives/0/extensions/EXT_mesh_primitive_edge_visibility",
                json!({"visibility": 4, "lineStrings": [{"indices": 4}]}),
            )],
            ("/meshes/0/primitives/0/extensions/EXT_mesh_primitive_edge_visibility/lineStrings/0/indices", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/meshes/0/primitives/0/extensions/EXT_mesh_primitive_edge_visibility/lineStrings/0/indices"),
        ),
        case(
            "EXT_mesh_primitive_restart",
            vec![("/meshes/0/extensions/EXT_mesh_primitive_restart", json!({"primitiveGroups": [{"primitives": [0], "indices": 4}]}))],
            ("/meshes/0/extensions/EXT_mesh_primitive_restart/primitiveGroups/0/indices", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/meshes/0/extensions/EXT_mesh_primitive_restart/primitiveGroups/0/indices"),
        ),
        meshopt("EXT_meshopt_compression"),
        texture_source("EXT_texture_astc", "image/ktx2"),
        texture_source("EXT_texture_webp", "image/webp"),
        case(
            "KHR_animation_pointer",
            vec![
                ("/animations/0/channels/0/target", json!({"path": "pointer"})),
                ("/animations/0/channels/0/target/extensions/KHR_animation_pointer", json!({"pointer": "/nodes/0/translation"})),
            ],
            ("/animations/0/channels/0/target/extensions/KHR_animation_pointer/pointer", Some(json!("nodes/0/translation"))),
            ("PATTERN_MISMATCH", "/animations/0/channels/0/target/extensions/KHR_animation_pointer/pointer"),
        ),
        case(
            "KHR_draco_mesh_compression",
            vec![("/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression", json!({"bufferView": 0, "attributes": {"POSITION": 0}}))],
            ("/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView"),
        ),
        case(
            "KHR_gaussian_splatting",
            vec![("/meshes/0/primitives/0/extensions/KHR_gaussian_splatting", json!({"kernel": "ellipse", "colorSpace": "srgb_rec709_display"}))],
            ("/meshes/0/primitives/0/extensions/KHR_gaussian_splatting/kernel", None),
            ("UNDEFINED_PROPERTY", "/meshes/0/primitives/0/extensions/KHR_gaussian_splatting"),
        ),
        case(
            "KHR_lights_punctual",
            vec![
                ("/extensions/KHR_lights_punctual", json!({"lights": [{"type": "spot", "intensity": 3, "spot": {"innerConeAngle": 0.1, "outerConeAngle": 0.5}}]})),
                ("/nodes/0/extensions/KHR_lights_punctual", json!({"light": 0})),
            ],
            ("/extensions/KHR_lights_punctual/lights/0/spot/outerConeAngle", Some(json!(2))),
            ("VALUE_NOT_IN_RANGE", "/extensions/KHR_lights_punctual/lights/0/spot/outerConeAngle"),
        ),
        material("KHR_materials_anisotropy", json!({"anisotropyStrength": 0.5, "anisotropyRotation": 1}), "anisotropyStrength", json!(1.5)),
        material("KHR_materials_clearcoat", json!({"clearcoatFactor": 1, "clearcoatTexture": {"index": 0}}), "clearcoatRoughnessFactor", json!(-0.5)),
        material("KHR_materials_diffuse_transmission", json!({"diffuseTransmissionFactor": 0.25}), "diffuseTransmissionFactor", json!(2)),
        // Dispersion acts in a volume, which lets light in through transmission.
        case(
            "KHR_materials_dispersion",
            vec![
                (
                    "/extensionsUsed",
                    json!(["KHR_materials_dispersion", "KHR_materials_volume", "KHR_materials_transmission"]),
                ),
                ("/materials/0/extensions/KHR_materials_dispersion", json!({"dispersion": 0.1})),
                ("/materials/0/extensions/KHR_materials_volume", json!({})),
                ("/materials/0/extensions/KHR_materials_transmission", json!({})),
            ],
            ("/materials/0/extensions/KHR_materials_dispersion/dispersion", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/materials/0/extensions/KHR_materials_dispersion/dispersion"),
        ),
        // A strength multiplies an emissive factor that is not black.
        case(
            "KHR_materials_emissive_strength",
            vec![
                ("/materials/0/emissiveFactor", json!([1, 1, 1])),
                ("/materials/0/extensions/KHR_materials_emissive_strength", json!({"emissiveStrength": 5})),
            ],
            ("/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength"),
        ),
        material("KHR_materials_ior", json!({"ior": 1.4}), "ior", json!(0.5)),
        material("KHR_materials_iridescence", json!({"iridescenceFactor": 1, "iridescenceIor": 1.3}), "iridescenceIor", json!(0.9)),
        material(
            "KHR_materials_pbrSpecularGlossiness",
            json!({"diffuseFactor": [0.5, 0.4, 0.3, 1], "diffuseTexture": {"index": 0}, "specularFactor": [0.04, 0.04, 0.04], "glossinessFactor": 0.3, "specularGlossinessTexture": {"index": 0}}),
            "glossinessFactor",
            json!(1.5),
        ),
        material("KHR_materials_specular", json!({"specularFactor": 0.5, "specularColorFactor": [1, 1, 1]}), "specularFactor", json!(1.5)),
        material("KHR_materials_transmission", json!({"transmissionFactor": 0.5}), "transmissionFactor", json!(1.5)),
        case(
            "KHR_materials_unlit",
            vec![("/materials/0/extensions/KHR_materials_unlit", json!({}))],
            ("/materials/0/extensions/KHR_materials_unlit", Some(json!(1))),
            ("TYPE_MISMATCH", "/materials/0/extensions/KHR_materials_unlit"),
        ),
        case(
            "KHR_materials_variants",
            vec![
                ("/extensions/KHR_materials_variants", json!({"variants": [{"name": "red"}]})),
                ("/meshes/0/primitives/0/extensions/KHR_materials_variants", json!({"mappings": [{"material": 0, "variants": [0]}]})),
            ],
            ("/meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/0/variants", None),
            ("UNDEFINED_PROPERTY", "/meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/0"),
        ),
        // A volume lets light in through transmission.
        case(
            "KHR_materials_volume",
            vec![
                ("/extensionsUsed", json!(["KHR_materials_volume", "KHR_materials_transmission"])),
                ("/materials/0/extensions/KHR_materials_volume", json!({"thicknessFactor": 1, "attenuationDistance": 2})),
                ("/materials/0/extensions/KHR_materials_transmission", json!({})),
            ],
            ("/materials/0/extensions/KHR_materials_volume/thicknessFactor", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/materials/0/extensions/KHR_materials_volume/thicknessFactor"),
        ),
        meshopt("KHR_meshopt_compression"),
        node_flag("KHR_node_hoverability", "hoverable"),
        node_flag("KHR_node_selectability", "selectable"),
        node_flag("KHR_node_visibility", "visible"),
        texture_source("KHR_texture_basisu", "image/ktx2"),
        case(
            "KHR_texture_transform",
            vec![(
                "/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform",
                json!({"offset": [0, 1], "rotation": 1.5, "scale": [2, 2], "texCoord": 0}),
            )],
            ("/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/texCoord", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/texCoord"),
        ),
        case(
            "KHR_xmp_json_ld",
            vec![
                ("/extensions/KHR_xmp_json_ld", json!({"packets": [{"@context": {"dc": "http://purl.org/dc/elements/1.1/"}, "dc:title": "chair"}]})),
                ("/asset/extensions/KHR_xmp_json_ld", json!({"packet": 0})),
                ("/materials/0/extensions/KHR_xmp_json_ld", json!({"packet": 0})),
            ],
            ("/materials/0/extensions/KHR_xmp_json_ld/packet", Some(json!(-1))),
            ("VALUE_NOT_IN_RANGE", "/materials/0/extensions/KHR_xmp_json_ld/packet"),
        ),
    ]
}

/// The 80 bytes of [`extension_base`]'s buffer: a vertex at the origin with a normal
/// (0, 0, 1), a tangent (1, 0, 0, 1) and texture coordinates (0, 0); image bytes; a keyframe
/// at time 0 moving to the origin.
fn extension_base_data() -> Vec<u8> {
    let floats: [f32; 12] = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let mut bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
    bytes.resize(80, 0);
    bytes
}

/// Writes `doc` as a .gltf beside [`extension_base_data`] (data.bin), and validates it.
fn validate_doc(validator: &Validator, dir: &Path, name: &str, doc: &Value) -> FileReport {
    std::fs::write(dir.join("data.bin"), extension_base_data()).unwrap();
    let path = dir.join(format!("{name}.gltf"));
    std::fs::write(&path, serde_json::to_string_pretty(doc).unwrap()).unwrap();
    validator.validate_file(&path)
}

#[test]
fn every_published_extension_is_judged_by_its_schema_valid_uses_clean_one_bad_value_one_finding() {
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let dir = tempfile::tempdir().unwrap();
    let cases = extension_cases();
    // Every extension whose schemas velvet ships has its case.
    let mut folders: Vec<String> = std::fs::read_dir("schema/extensions")
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    folders.sort();
    let mut covered: Vec<String> = cases.iter().map(|c| c.extension.to_string()).collect();
    covered.sort();
    assert_eq!(covered, folders);
    for case in &cases {
        let mut doc = extension_base();
        set(&mut doc, "/extensionsUsed", json!([case.extension]));
        for (pointer, value) in &case.objects {
            set(&mut doc, pointer, value.clone());
        }
        let valid = validate_doc(&validator, dir.path(), case.extension, &doc);
        let above_info: Vec<(String, String)> = valid
            .findings
            .iter()
            .filter(|f| f.diagnostic.severity < velvet::diagnostics::Severity::Info)
            .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
            .collect();
        assert_eq!(
            above_info,
            [],
            "{}: the valid use has findings",
            case.extension
        );

        let (pointer, bad) = &case.bad;
        match bad {
            Some(value) => set(&mut doc, pointer, value.clone()),
            None => {
                let (parent, key) = pointer.rsplit_once('/').unwrap();
                doc.pointer_mut(parent)
                    .and_then(Value::as_object_mut)
                    .unwrap()
                    .remove(key);
            }
        }
        let invalid = validate_doc(&validator, dir.path(), case.extension, &doc);
        let schema_findings: Vec<(String, String)> = invalid
            .findings
            .iter()
            .filter(|f| {
                velvet::diagnostics::codes::SCHEMA
                    .iter()
                    .any(|c| c.name == f.diagnostic.code)
                    || ["PATTERN_MISMATCH", "EMPTY_ENTITY", "ONE_OF_MISMATCH"]
                        .contains(&f.diagnostic.code)
            })
            .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
            .collect();
        assert_eq!(
            schema_findings,
            [(case.expected.0.to_string(), case.expected.1.to_string())],
            "{}: the value out of its schema",
            case.extension
        );
    }
}

#[test]
fn a_number_past_the_range_of_f64_is_out_of_range_where_a_number_is_asked_and_nowhere_else() {
    // 1e400 reads as infinity in f64: valid JSON, never an error of the parser's own, and out
    // of range wherever the schema asks for a number (once, though the sheen roughness fails
    // both its type and its maximum); in extras it is free.
    let text = r#"{
  "asset": {"version": "2.0"},
  "extensionsUsed": ["KHR_materials_sheen"],
  "nodes": [{"translation": [1e400, 0, -1E+400]}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 1, "znear": 1e400}}],
  "materials": [{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 1e400}}}],
  "extras": {"far": 1e400}
}"#;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("far.gltf");
    std::fs::write(&path, text).unwrap();
    let report = Validator::new(Schemas::builtin(), Settings::default()).validate_file(&path);
    let found: Vec<(String, String)> = report
        .findings
        .iter()
        .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
        .collect();
    let expected: Vec<(String, String)> = [
        "/nodes/0/translation/0",
        "/nodes/0/translation/2",
        "/cameras/0/perspective/znear",
        "/materials/0/extensions/KHR_materials_sheen/sheenRoughnessFactor",
    ]
    .iter()
    .map(|p| ("VALUE_NOT_IN_RANGE".to_string(), p.to_string()))
    .collect();
    let mut sorted = found.clone();
    sorted.sort();
    let mut expected_sorted = expected;
    expected_sorted.sort();
    assert_eq!(sorted, expected_sorted, "{found:?}");
}

/// The code and pointer of every finding on `doc`, written as chair.gltf in a fresh folder.
fn codes_and_pointers_of(doc: &Value) -> Vec<(String, String)> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chair.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    Validator::new(Schemas::builtin(), Settings::default())
        .validate_file(&path)
        .findings
        .iter()
        .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
        .collect()
}

#[test]
fn every_texture_of_a_material_needs_its_texcoord_set_as_texture_transform_says() {
    // A primitive with TEXCOORD_0 only, drawn with material 0, whose textures read: the base
    // colour set 1 (missing), the normal texture set 1 but KHR_texture_transform's texCoord 0
    // (present), a clearcoat texture set 0 but KHR_texture_transform's texCoord 2 (missing).
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_clearcoat", "KHR_texture_transform"],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3}, "material": 0, "mode": 0}]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 1}},
            "normalTexture": {"index": 0, "texCoord": 1, "extensions": {"KHR_texture_transform": {"texCoord": 0}}},
            "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1,
                "clearcoatTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": 2}}}}}
        }],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR4nGNgYGD4DwABBAEAWB0S5wAAAABJRU5ErkJggg=="}],
        "accessors": [
            {"componentType": 5126, "count": 1, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]},
            {"componentType": 5126, "count": 1, "type": "VEC3"},
            {"componentType": 5126, "count": 1, "type": "VEC4"},
            {"componentType": 5126, "count": 1, "type": "VEC2"}
        ]
    });
    let at = "/meshes/0/primitives/0/material".to_string();
    assert_eq!(
        codes_and_pointers_of(&doc),
        [
            ("MESH_PRIMITIVE_TOO_FEW_TEXCOORDS".to_string(), at.clone()),
            ("MESH_PRIMITIVE_TOO_FEW_TEXCOORDS".to_string(), at)
        ]
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chair.gltf");
    std::fs::write(&path, doc.to_string()).unwrap();
    let messages: Vec<String> = Validator::new(Schemas::builtin(), Settings::default())
        .validate_file(&path)
        .findings
        .iter()
        .map(|f| f.diagnostic.message.clone())
        .collect();
    assert_eq!(
        messages,
        [
            "material 0's /materials/0/pbrMetallicRoughness/baseColorTexture reads TEXCOORD_1, which this primitive does not have",
            "material 0's /materials/0/extensions/KHR_materials_clearcoat/clearcoatTexture reads TEXCOORD_2, which this primitive does not have",
        ]
    );
}

#[test]
fn only_a_glbs_first_buffer_needs_the_bin_chunk() {
    // Buffer 1 has no uri: nothing reads it (or an extension fills it). Valid in a .gltf and in
    // a .glb; only buffer 0 of a .glb without a BIN chunk lacks its data.
    let doc = json!({
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": 4}, {"byteLength": 8}]
    });
    let text = doc.to_string();
    let dir = tempfile::tempdir().unwrap();
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let codes_of = |name: &str, bytes: Vec<u8>| -> Vec<(String, String)> {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        validator
            .validate_file(&path)
            .findings
            .iter()
            .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
            .collect()
    };
    assert_eq!(codes_of("buffers.gltf", text.clone().into_bytes()), []);
    assert_eq!(
        codes_of(
            "with_bin.glb",
            velvet::asset::glb::join(text.as_bytes(), Some(&[0u8; 4]))
        ),
        []
    );
    assert_eq!(
        codes_of(
            "without_bin.glb",
            velvet::asset::glb::join(text.as_bytes(), None)
        ),
        [(
            "BUFFER_MISSING_GLB_DATA".to_string(),
            "/buffers/0".to_string()
        )]
    );
}
