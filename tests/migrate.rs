//! `velvet migrate` end to end: golden outputs and reports for every fixture in
//! fixtures/migrate (run with VELVET_BLESS=1 to rewrite them after a reviewed change), GLB
//! packing, byte identity when nothing changes, refused requests, a batch with failures, URI
//! relocation, validation after migration, and the command's exit statuses.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;
use velvet::asset::glb;
use velvet::command::migrate::{self as migrating, render, FileOutcome, Request};
use velvet::diagnostics::Severity;
use velvet::migrate::apply::{self, WriteStrategy};
use velvet::migrate::roughness::{self, Direction, RoughnessMapping};
use velvet::migrate::{self, Conversion, Note, Options, Skip};
use velvet::output::files::Claims;
use velvet::output::paths::{Destination, Job};
use velvet::output::summary::Detail;
use velvet::output::UsageError;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/migrate")
}

/// The input fixtures, sorted: every *.gltf that is not a golden output.
fn cases() -> Vec<PathBuf> {
    let mut cases: Vec<PathBuf> = std::fs::read_dir(fixtures())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "gltf")
                && !p.to_string_lossy().ends_with(".expected.gltf")
        })
        .collect();
    cases.sort();
    assert!(
        cases.len() >= 10,
        "fixtures/migrate holds the conversion cases"
    );
    cases
}

fn stem(path: &Path) -> String {
    path.file_stem().unwrap().to_string_lossy().into_owned()
}

/// The options a fixture runs with, from its optional `<case>.args` (one flag per line).
fn options_for(case: &Path) -> Options {
    let mut options = Options::default();
    if let Ok(text) = std::fs::read_to_string(case.with_extension("args")) {
        for flag in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
            match flag {
                "--report" => options.report = true,
                "--refresh-fallback" => options.refresh_fallback = true,
                "--copy-resources" => options.rewrite_uris = false,
                "--rewrite-uris" => options.rewrite_uris = true,
                "--roughness identity" => options.roughness = RoughnessMapping::Identity,
                other => panic!("{}: unknown flag {other}", case.display()),
            }
        }
    }
    options
}

/// Asserts that the file at `path` holds `expected`, showing both as text when not.
#[track_caller]
fn assert_file(path: &Path, expected: &[u8]) {
    let actual = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        actual == expected,
        "{} differs:\n--- expected\n{}\n--- actual\n{}",
        path.display(),
        String::from_utf8_lossy(expected),
        String::from_utf8_lossy(&actual)
    );
}

fn request(inputs: Vec<PathBuf>, destination: Destination, options: Options) -> Request {
    Request {
        inputs,
        destination,
        options,
        dry_run: false,
        progress: false,
    }
}

/// Migrates `input` into the file `output` with the default options.
fn migrate_to(input: &Path, output: &Path) -> migrating::RunReport {
    migrating::run(&request(
        vec![input.to_path_buf()],
        Destination::File(output.to_path_buf()),
        Options::default(),
    ))
    .unwrap()
}

fn blessing() -> bool {
    std::env::var_os("VELVET_BLESS").is_some()
}

/// Compares `actual` with the golden file at `path`, or writes it when blessing.
fn golden(path: &Path, actual: &[u8]) {
    if blessing() {
        std::fs::write(path, actual).unwrap();
        return;
    }
    let expected = std::fs::read(path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run with VELVET_BLESS=1 to create it)",
            path.display()
        )
    });
    assert!(
        expected == actual,
        "{} differs:\n--- expected\n{}\n--- actual\n{}",
        path.display(),
        String::from_utf8_lossy(&expected),
        String::from_utf8_lossy(actual)
    );
}

/// Migrates one fixture into a temporary folder; returns (folder, output path, result).
fn migrate_case(case: &Path) -> (tempfile::TempDir, PathBuf, migrating::FileResult) {
    migrate_case_with(case, options_for(case))
}

fn migrate_case_with(
    case: &Path,
    options: Options,
) -> (tempfile::TempDir, PathBuf, migrating::FileResult) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in").join(case.file_name().unwrap());
    std::fs::create_dir_all(input.parent().unwrap()).unwrap();
    std::fs::copy(case, &input).unwrap();
    let out_dir = dir.path().join("out");
    let report = migrating::run(&request(
        vec![input.parent().unwrap().to_path_buf()],
        Destination::Dir(out_dir.clone()),
        options,
    ))
    .unwrap();
    assert_eq!(report.files.len(), 1);
    let result = report.files.into_iter().next().unwrap();
    (dir, out_dir.join(case.file_name().unwrap()), result)
}

#[test]
fn every_fixture_gives_its_golden_output_and_report() {
    for case in cases() {
        let (_dir, output, mut result) = migrate_case(&case);
        let input_bytes = std::fs::read(&case).unwrap();
        let output_bytes =
            std::fs::read(&output).unwrap_or_else(|e| panic!("{}: no output: {e}", case.display()));
        let expected = case.with_extension("expected.gltf");
        if result.outcome == FileOutcome::Copied {
            assert_eq!(
                output_bytes,
                input_bytes,
                "{}: nothing to migrate, so the bytes are the input's",
                case.display()
            );
            assert!(
                !expected.exists() || blessing(),
                "{}: an unchanged case has no golden output",
                case.display()
            );
            if blessing() {
                let _ = std::fs::remove_file(&expected);
            }
        } else {
            assert_eq!(result.outcome, FileOutcome::Changed, "{}", case.display());
            golden(&expected, &output_bytes);
        }
        result.input = PathBuf::from(case.file_name().unwrap());
        result.output = None;
        golden(
            &case.with_extension("report.txt"),
            render::file_text(&result, true).as_bytes(),
        );
    }
}

#[test]
fn unchanged_files_are_the_cases_with_nothing_to_migrate() {
    let unchanged: Vec<String> = cases()
        .iter()
        .filter(|c| migrate_case(c).2.outcome == FileOutcome::Copied)
        .map(|c| stem(c))
        .collect();
    assert_eq!(unchanged, ["both", "excluded", "no-layers", "sheen-off"]);
}

#[test]
fn migrating_an_output_again_changes_nothing() {
    // The fitted mappings α(r) and r(α) are each optimal, not each other's inverse, so only the
    // identity promises that a refreshed fallback gives back the sheen it came from.
    for (mapping, refreshes) in [
        (RoughnessMapping::Fitted, &[false][..]),
        (RoughnessMapping::Identity, &[false, true][..]),
    ] {
        for case in cases() {
            let options = Options {
                roughness: mapping,
                ..options_for(&case)
            };
            again_changes_nothing(&case, options, refreshes);
        }
    }
}

fn has_sheen_below_floor(case: &Path) -> bool {
    let doc: Value = serde_json::from_slice(&std::fs::read(case).unwrap()).unwrap();
    doc["materials"].as_array().into_iter().flatten().any(|m| {
        let sheen = &m["extensions"]["KHR_materials_sheen"];
        sheen.is_object()
            && sheen["sheenRoughnessFactor"]
                .as_f64()
                .is_none_or(|r| r < roughness::ROUGHNESS_FLOOR)
    })
}

fn again_changes_nothing(case: &Path, first: Options, refreshes: &[bool]) {
    {
        let (_dir, output, _) = migrate_case_with(case, first.clone());
        for &refresh_fallback in refreshes {
            // Inputs whose own fallback is stale (both), or that keep draft properties beside
            // ratified ones (legacy), are what a refresh changes; a fallback whose colour
            // texture is baked from fuzz textures is baked anew by every refresh.
            if refresh_fallback
                && ["both", "legacy", "fuzz-textures"].contains(&stem(case).as_str())
            {
                continue;
            }
            // A sheen roughness below the floor (absent: the default 0) gives the fuzz the
            // floor, and a refresh then raises the sheen to it.
            if refresh_fallback && has_sheen_below_floor(case) {
                continue;
            }
            let options = Options {
                refresh_fallback,
                roughness: first.roughness,
                ..Options::default()
            };
            // Beside the first output, whose baked images it shares.
            let again = output.with_file_name(format!("again-{refresh_fallback}.gltf"));
            let report = migrating::run(&request(
                vec![output.clone()],
                Destination::File(again.clone()),
                options,
            ))
            .unwrap();
            assert_eq!(
                report.files[0].outcome,
                FileOutcome::Copied,
                "{} (refresh {refresh_fallback}, {:?})",
                case.display(),
                first.roughness
            );
            assert_file(&again, &std::fs::read(&output).unwrap());
        }
    }
}

fn errors(path: &Path) -> Vec<(String, String)> {
    let validator = Validator::new(Schemas::builtin(), velvet::diagnostics::Settings::default());
    let report = validator.validate_file(path);
    let mut errors: Vec<(String, String)> = report
        .findings
        .iter()
        .filter(|f| f.diagnostic.severity == Severity::Error)
        .map(|f| (f.diagnostic.code.to_string(), f.diagnostic.pointer.clone()))
        .collect();
    errors.sort();
    errors
}

#[test]
fn validation_after_migration_finds_no_new_error_in_any_fixture() {
    let mut clean_inputs = 0;
    for case in cases() {
        let (_dir, output, _) = migrate_case(&case);
        let before = errors(&case);
        let after = errors(&output);
        let new: Vec<_> = after.iter().filter(|e| !before.contains(e)).collect();
        assert!(
            new.is_empty(),
            "{}: migration added errors {new:?}",
            case.display()
        );
        if before.is_empty() {
            clean_inputs += 1;
            assert!(after.is_empty(), "{}", case.display());
        }
    }
    // The check is not vacuous: most fixtures are valid to begin with.
    assert!(clean_inputs >= 9, "{clean_inputs}");
}

#[test]
fn material_outcomes_name_conversions_and_skips() {
    let case = fixtures().join("legacy.gltf");
    let (_dir, _, result) = migrate_case(&case);
    let outcomes: Vec<(Vec<Conversion>, Option<Skip>)> = result
        .detail
        .materials
        .iter()
        .map(|m| (m.conversions.clone(), m.skipped))
        .collect();
    assert_eq!(
        outcomes,
        [
            (
                vec![Conversion::LegacyUpgrade, Conversion::SheenToFuzz],
                None
            ),
            (
                vec![Conversion::LegacyUpgrade, Conversion::SheenToFuzz],
                None
            ),
            (vec![Conversion::LegacyUpgrade], None),
            (vec![Conversion::SheenToFuzz], None),
            (
                vec![Conversion::LegacyUpgrade, Conversion::SheenToFuzz],
                None
            ),
        ]
    );
    assert!(result.detail.materials[0]
        .notes
        .contains(&Note::LegacyClamped {
            product: [1.6, 1.0, 0.4],
            clamped: [1.0, 1.0, 0.4]
        }));
    assert!(result.detail.materials[2].notes.contains(&Note::SheenOff));
}

#[test]
fn glb_in_gives_glb_out_with_padded_chunks_and_the_same_bin() {
    let dir = tempfile::tempdir().unwrap();
    // A GLB's JSON chunk carries no trailing newline (loaders take one for bad padding).
    let text = std::fs::read_to_string(fixtures().join("sheen-factors.gltf")).unwrap();
    let json = text.trim_end().as_bytes();
    let bin = [1u8, 2, 3, 4, 5];
    let input = dir.path().join("chair.glb");
    std::fs::write(&input, glb::join(json, Some(&bin))).unwrap();
    let output = dir.path().join("out.glb");
    let report = migrate_to(&input, &output);
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    let bytes = std::fs::read(&output).unwrap();
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len(),
        "header length"
    );
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert_eq!(json_len % 4, 0);
    let bin_len =
        u32::from_le_bytes(bytes[20 + json_len..24 + json_len].try_into().unwrap()) as usize;
    assert_eq!((bin_len, bytes.len()), (8, 20 + json_len + 8 + 8));
    let mut diagnostics = Vec::new();
    let parts = glb::split(&bytes, &mut diagnostics).unwrap();
    assert!(diagnostics.is_empty(), "{diagnostics:?}");
    let expected = std::fs::read_to_string(fixtures().join("sheen-factors.expected.gltf")).unwrap();
    assert_eq!(
        String::from_utf8_lossy(parts.json).trim_end_matches(' '),
        expected.trim_end()
    );
    assert_eq!(parts.bin.unwrap(), [1, 2, 3, 4, 5, 0, 0, 0]);
}

#[test]
fn glb_with_nothing_to_migrate_is_copied_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let json = std::fs::read(fixtures().join("sheen-off.gltf")).unwrap();
    let input = dir.path().join("off.glb");
    let original = glb::join(&json, Some(&[9, 9, 9, 9]));
    std::fs::write(&input, &original).unwrap();
    let output = dir.path().join("copy.glb");
    let report = migrating::run(&request(
        vec![input],
        Destination::File(output.clone()),
        Options::default(),
    ))
    .unwrap();
    assert_eq!(report.files[0].outcome, FileOutcome::Copied);
    assert_eq!(std::fs::read(&output).unwrap(), original);
}

#[test]
fn in_place_with_nothing_to_migrate_does_not_write() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("off.gltf");
    std::fs::copy(fixtures().join("sheen-off.gltf"), &input).unwrap();
    let old = std::time::SystemTime::UNIX_EPOCH + std::time::Duration::from_secs(1_000_000);
    std::fs::File::options()
        .write(true)
        .open(&input)
        .unwrap()
        .set_modified(old)
        .unwrap();
    let report = migrating::run(&request(
        vec![input.clone()],
        Destination::InPlace,
        Options::default(),
    ))
    .unwrap();
    assert_eq!(report.files[0].outcome, FileOutcome::Untouched);
    assert_eq!(
        std::fs::metadata(&input).unwrap().modified().unwrap(),
        old,
        "the file was not rewritten"
    );
    assert_eq!(
        std::fs::read(&input).unwrap(),
        std::fs::read(fixtures().join("sheen-off.gltf")).unwrap()
    );
}

#[test]
fn in_place_rewrites_the_input_with_its_migration() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sheen-factors.gltf");
    std::fs::copy(fixtures().join("sheen-factors.gltf"), &input).unwrap();
    let report = migrating::run(&request(
        vec![input.clone()],
        Destination::InPlace,
        Options::default(),
    ))
    .unwrap();
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    assert_file(
        &input,
        &std::fs::read(fixtures().join("sheen-factors.expected.gltf")).unwrap(),
    );
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "no temporary file is left: {names:?}");
}

/// Every file under `dir` with its bytes, sorted.
fn snapshot(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.push((path, bytes));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn refused_requests_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.gltf");
    let b = dir.path().join("sub/b.gltf");
    std::fs::create_dir_all(b.parent().unwrap()).unwrap();
    std::fs::copy(fixtures().join("sheen-factors.gltf"), &a).unwrap();
    std::fs::copy(fixtures().join("sheen-factors.gltf"), &b).unwrap();
    let before = snapshot(dir.path());
    let cases: Vec<(Request, UsageError)> = vec![
        (
            request(
                vec![a.clone()],
                Destination::File(dir.path().join("./a.gltf")),
                Options::default(),
            ),
            UsageError::OutputIsInput {
                output: dir.path().join("./a.gltf").display().to_string(),
                input: a.display().to_string(),
            },
        ),
        (
            request(
                vec![dir.path().join("sub")],
                Destination::Dir(dir.path().join("sub")),
                Options::default(),
            ),
            UsageError::OutputIsInput {
                output: b.display().to_string(),
                input: b.display().to_string(),
            },
        ),
        (
            request(
                vec![dir.path().to_path_buf()],
                Destination::Dir(dir.path().join("sub/..")),
                Options::default(),
            ),
            UsageError::OutputIsInput {
                output: dir.path().join("sub/../a.gltf").display().to_string(),
                input: a.display().to_string(),
            },
        ),
        (
            request(
                vec![a.clone(), b.clone()],
                Destination::File(dir.path().join("x.gltf")),
                Options::default(),
            ),
            UsageError::OutputForMany(2),
        ),
        (
            request(
                vec![dir.path().join("sub")],
                Destination::File(dir.path().join("x.gltf")),
                Options::default(),
            ),
            UsageError::OutputForFolder(dir.path().join("sub").display().to_string()),
        ),
        (
            request(
                vec![a.clone()],
                Destination::File(dir.path().join("x.glb")),
                Options::default(),
            ),
            UsageError::ContainerMismatch {
                input: a.display().to_string(),
                output: dir.path().join("x.glb").display().to_string(),
                container: ".gltf",
                extension: "gltf",
            },
        ),
        (
            request(
                vec![a.clone(), dir.path().join("sub/../a.gltf")],
                Destination::Dir(dir.path().join("out")),
                Options::default(),
            ),
            UsageError::OutputCollision {
                output: dir.path().join("out/a.gltf").display().to_string(),
                first: a.display().to_string(),
                second: dir.path().join("sub/../a.gltf").display().to_string(),
            },
        ),
        (
            request(vec![a.clone()], Destination::None, Options::default()),
            UsageError::NoDestination,
        ),
        (
            request(vec![], Destination::InPlace, Options::default()),
            UsageError::NoInputs,
        ),
    ];
    for (req, expected) in cases {
        assert_eq!(migrating::run(&req).unwrap_err(), expected);
    }
    assert_eq!(snapshot(dir.path()), before, "nothing was written");
}

#[test]
fn a_failing_file_does_not_stop_the_batch_and_leaves_outputs_and_inputs_intact() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("deep")).unwrap();
    let sheen = std::fs::read(fixtures().join("sheen-factors.gltf")).unwrap();
    std::fs::write(inputs.join("a.gltf"), &sheen).unwrap();
    std::fs::write(inputs.join("b.gltf"), &sheen[..sheen.len() / 2]).unwrap(); // truncated JSON
    std::fs::write(inputs.join("c.gltf"), &sheen).unwrap();
    std::fs::write(inputs.join("deep/d.gltf"), &sheen).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // An earlier run's output for b, which this run must not damage.
    std::fs::write(out.join("b.gltf"), b"earlier output").unwrap();
    // c's output cannot be written: a folder stands in its place.
    std::fs::create_dir_all(out.join("c.gltf/occupied")).unwrap();
    let inputs_before = snapshot(&inputs);

    let report = migrating::run(&request(
        vec![inputs.clone()],
        Destination::Dir(out.clone()),
        Options::default(),
    ))
    .unwrap();
    let outcomes: Vec<(String, bool)> = report
        .files
        .iter()
        .map(|f| {
            (
                f.input.strip_prefix(&inputs).unwrap().display().to_string(),
                matches!(f.outcome, FileOutcome::Failed { .. }),
            )
        })
        .collect();
    assert_eq!(
        outcomes,
        [
            ("a.gltf".into(), false),
            ("b.gltf".into(), true),
            ("c.gltf".into(), true),
            ("deep/d.gltf".into(), false)
        ]
    );
    let FileOutcome::Failed { error } = &report.files[1].outcome else {
        unreachable!()
    };
    assert!(
        error.contains("b.gltf") && error.contains("INVALID_JSON"),
        "{error}"
    );
    let FileOutcome::Failed { error } = &report.files[2].outcome else {
        unreachable!()
    };
    assert!(
        error.starts_with(&format!("cannot write {}", out.join("c.gltf").display())),
        "{error}"
    );
    assert!(report.failed());
    assert_eq!(
        (report.summary.totals.changed, report.summary.totals.failed),
        (2, 2)
    );

    let expected = std::fs::read(fixtures().join("sheen-factors.expected.gltf")).unwrap();
    assert_file(&out.join("a.gltf"), &expected);
    assert_file(&out.join("deep/d.gltf"), &expected);
    assert_file(&out.join("b.gltf"), b"earlier output");
    assert!(out.join("c.gltf/occupied").is_dir());
    assert_eq!(snapshot(&inputs), inputs_before, "inputs are untouched");
    let leftovers: Vec<_> = snapshot(&out)
        .into_iter()
        .filter(|(p, _)| p.to_string_lossy().contains(".velvet-"))
        .collect();
    assert!(
        leftovers.is_empty(),
        "no temporary files remain: {leftovers:?}"
    );
}

#[test]
fn in_place_batch_with_a_broken_file_migrates_the_others() {
    let dir = tempfile::tempdir().unwrap();
    let sheen = std::fs::read(fixtures().join("sheen-factors.gltf")).unwrap();
    std::fs::write(dir.path().join("a.gltf"), &sheen).unwrap();
    std::fs::write(dir.path().join("b.glb"), b"glTF\x02\0\0\0\x10\0\0\0").unwrap();
    let report = migrating::run(&request(
        vec![dir.path().to_path_buf()],
        Destination::InPlace,
        Options::default(),
    ))
    .unwrap();
    assert!(matches!(
        report.files[1].outcome,
        FileOutcome::Failed { .. }
    ));
    assert_file(
        &dir.path().join("a.gltf"),
        &std::fs::read(fixtures().join("sheen-factors.expected.gltf")).unwrap(),
    );
    assert_eq!(
        std::fs::read(dir.path().join("b.glb")).unwrap(),
        b"glTF\x02\0\0\0\x10\0\0\0"
    );
}

/// A .gltf with a buffer and an image beside it (one in a subfolder, one with a space).
fn asset_with_resources(dir: &Path) -> PathBuf {
    let folder = dir.join("assets/chair");
    std::fs::create_dir_all(folder.join("tex")).unwrap();
    std::fs::write(folder.join("chair.bin"), [0u8; 4]).unwrap();
    std::fs::write(folder.join("tex/My Sheen.png"), b"png bytes").unwrap();
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "buffers": [{"uri": "chair.bin", "byteLength": 4}],
        "images": [{"uri": "tex/My%20Sheen.png"}, {"uri": "data:image/png;base64,AAAA"}],
        "materials": [{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5]}}}]
    });
    let path = folder.join("chair.gltf");
    std::fs::write(&path, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    path
}

fn uris(path: &Path) -> Vec<String> {
    let json: Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
    ["/buffers/0/uri", "/images/0/uri", "/images/1/uri"]
        .iter()
        .map(|p| json.pointer(p).unwrap().as_str().unwrap().to_string())
        .collect()
}

#[test]
fn rewrite_uris_makes_outputs_in_another_folder_refer_to_the_inputs_resources() {
    let dir = tempfile::tempdir().unwrap();
    let input = asset_with_resources(dir.path());
    let out = dir.path().join("migrated");
    let options = Options {
        rewrite_uris: true,
        ..Options::default()
    };
    let report = migrating::run(&request(
        vec![dir.path().join("assets")],
        Destination::Dir(out.clone()),
        options,
    ))
    .unwrap();
    let output = out.join("chair/chair.gltf");
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    assert_eq!(
        uris(&output),
        [
            "../../assets/chair/chair.bin",
            "../../assets/chair/tex/My%20Sheen.png",
            "data:image/png;base64,AAAA"
        ]
    );
    assert!(report.files[0].detail.notes.contains(&Note::UrisRewritten {
        count: 2,
        leaves_folder: true
    }));
    // The rewritten URIs lead to the very files the input uses.
    let bin = output
        .parent()
        .unwrap()
        .join("../../assets/chair/chair.bin");
    assert_eq!(
        bin.canonicalize().unwrap(),
        input
            .parent()
            .unwrap()
            .join("chair.bin")
            .canonicalize()
            .unwrap()
    );
    let image = output
        .parent()
        .unwrap()
        .join("../../assets/chair/tex/My Sheen.png");
    assert_eq!(std::fs::read(image).unwrap(), b"png bytes");
}

#[test]
fn outputs_in_another_folder_keep_their_uris_and_get_copies_of_the_files() {
    let dir = tempfile::tempdir().unwrap();
    let input = asset_with_resources(dir.path());
    let output = dir.path().join("elsewhere/chair.gltf");
    let options = Options::default();
    let report = migrating::run(&request(
        vec![input],
        Destination::File(output.clone()),
        options,
    ))
    .unwrap();
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    assert_eq!(
        uris(&output),
        [
            "chair.bin",
            "tex/My%20Sheen.png",
            "data:image/png;base64,AAAA"
        ]
    );
    assert_eq!(
        std::fs::read(dir.path().join("elsewhere/chair.bin")).unwrap(),
        [0u8; 4]
    );
    assert_eq!(
        std::fs::read(dir.path().join("elsewhere/tex/My Sheen.png")).unwrap(),
        b"png bytes"
    );
    assert!(report.files[0]
        .detail
        .notes
        .contains(&Note::ResourcesCopied { count: 2 }));
}

#[test]
fn output_beside_the_input_keeps_uris_as_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let input = asset_with_resources(dir.path());
    let output = input.with_file_name("chair.fuzz.gltf");
    migrating::run(&request(
        vec![input],
        Destination::File(output.clone()),
        Options::default(),
    ))
    .unwrap();
    assert_eq!(
        uris(&output),
        [
            "chair.bin",
            "tex/My%20Sheen.png",
            "data:image/png;base64,AAAA"
        ]
    );
}

#[test]
fn textures_are_decoded_only_for_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64,bm90IGFuIGltYWdl"}],
        "materials": [{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenColorTexture": {"index": 0}}}}]
    });
    let input = dir.path().join("broken-image.gltf");
    std::fs::write(&input, json.to_string()).unwrap();
    let measured = |report: bool| {
        let mut req = request(
            vec![input.clone()],
            Destination::None,
            Options {
                report,
                ..Options::default()
            },
        );
        req.dry_run = true;
        migrating::run(&req).unwrap().files[0].detail.materials[0]
            .notes
            .clone()
    };
    let floor = Note::RoughnessFloor {
        property: "fuzzRoughnessFactor".into(),
        best: 0.0,
        written: roughness::ROUGHNESS_FLOOR,
    };
    assert_eq!(measured(false), [floor, Note::ColorTextureAsIs { w: 1.0 }]);
    let notes = measured(true);
    assert!(
        matches!(&notes[2], Note::MeasureFailed { reason } if reason.contains("image 0")),
        "{notes:?}"
    );
}

#[test]
fn dry_run_prints_the_plan_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sheen-factors.gltf");
    std::fs::copy(fixtures().join("sheen-factors.gltf"), &input).unwrap();
    let mut req = request(
        vec![input.clone()],
        Destination::Dir(dir.path().join("out")),
        Options::default(),
    );
    req.dry_run = true;
    let report = migrating::run(&req).unwrap();
    assert!(!dir.path().join("out").exists());
    assert_eq!(
        report.files[0].outcome,
        FileOutcome::Planned { changes: true }
    );
    let text = render::text(&report, Detail::Verbose);
    assert!(
        text.contains("  material 0 \"champagne\": sheen → fuzz; verdict close (ꟻLIP 0.165 in the furnace, 0.271 under the light)\n"),
        "{text}"
    );
    assert!(text.contains(
        "    set /materials/0/extensions/KHR_materials_fuzz = {\"fuzzFactor\":0.9,\"fuzzColorFactor\":[1.0,0.777778,0.666667],\"fuzzRoughnessFactor\":0.6236}\n"
    ), "{text}");
    assert!(
        text.contains("  declare KHR_materials_fuzz in /extensionsUsed\n"),
        "{text}"
    );
    assert!(text.ends_with("1 file: 1 would change, 0 unchanged, 0 failed; no texture to add\nmaterials: 3 migrated (3 sheen → fuzz); 0 skipped; 0 warnings\nverdicts: 0 same, 3 close, 0 visible\n"), "{text}");
    let json: Value = serde_json::from_str(&render::json(&report)).unwrap();
    assert_eq!(json["files"][0]["status"], "planned");
    assert_eq!(json["files"][0]["materials"][0]["edits"][0]["op"], "set");
    assert_eq!(
        json["files"][0]["edits"][0],
        serde_json::json!({"op": "declare-used", "extension": "KHR_materials_fuzz"})
    );
    assert_eq!(json["summary"]["conversions"]["sheen-to-fuzz"], 3);
    assert_eq!(
        json["files"][0]["materials"][1]["verdict"],
        serde_json::json!({"label": "close", "flip": 0.1112, "furnace": 0.1112, "light": 0.1448})
    );
    assert_eq!(
        json["summary"]["verdicts"],
        serde_json::json!({"same": 0, "close": 3, "visible": 0})
    );
}

fn velvet(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_command_exits_0_when_done_1_when_a_file_failed_2_on_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    let good = inputs.join("good.gltf");
    std::fs::copy(fixtures().join("fuzz-only.gltf"), &good).unwrap();
    let out = dir.path().join("out");
    let (code, stdout, _) = velvet(&[
        "migrate",
        good.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("materials: 4 migrated (4 fuzz → fallback sheen); 2 skipped (1 fuzz switched off, 1 black fuzz, which no sheen can show)"), "{stdout}");

    std::fs::write(inputs.join("bad.gltf"), "{").unwrap();
    let (code, stdout, _) = velvet(&[
        "migrate",
        inputs.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{stdout}");
    assert!(stdout.contains("bad.gltf: FAILED: "), "{stdout}");

    let (code, _, stderr) = velvet(&[
        "migrate",
        good.to_str().unwrap(),
        "-o",
        good.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("is the input"), "{stderr}");
    let (code, _, _) = velvet(&[
        "migrate",
        good.to_str().unwrap(),
        "-o",
        "x.gltf",
        "--in-place",
    ]);
    assert_eq!(code, 2, "clap refuses conflicting destinations");
    assert_eq!(
        std::fs::read(&good).unwrap(),
        std::fs::read(fixtures().join("fuzz-only.gltf")).unwrap()
    );
}

// ---- Textures baked by migrate (decoded and compared pixel by pixel) ----

/// The exact sRGB decode and encode (IEC 61966-2-1), written out here so that the tests do not
/// check velvet's functions against themselves.
fn srgb_decode(code: u8) -> f64 {
    let v = code as f64 / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn srgb_encode_code(linear: f64) -> u8 {
    let l = linear.clamp(0.0, 1.0);
    let v = if l <= 0.0031308 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0).round() as u8
}

fn linear_code(linear: f64) -> u8 {
    (linear.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn png_file(path: &Path, width: u32, height: u32, layout: image::ColorType, data: &[u8]) {
    image::save_buffer(path, data, width, height, layout).unwrap();
}

/// Writes `json` as `<dir>/<name>.gltf`, migrates it to `output` (relative to `dir`) and
/// returns the output's path, its document and the file's result.
fn migrate_document(
    dir: &Path,
    name: &str,
    json: Value,
    output: &str,
    options: Options,
) -> (PathBuf, Value, migrating::FileResult) {
    let input = dir.join(format!("{name}.gltf"));
    std::fs::write(&input, serde_json::to_vec_pretty(&json).unwrap()).unwrap();
    let output = dir.join(output);
    let report = migrating::run(&request(
        vec![input],
        Destination::File(output.clone()),
        options,
    ))
    .unwrap();
    let result = report.files.into_iter().next().unwrap();
    assert_eq!(result.outcome, FileOutcome::Changed, "{name}");
    let doc: Value = serde_json::from_slice(&std::fs::read(&output).unwrap()).unwrap();
    (output, doc, result)
}

/// The decoded RGBA8 pixels of the image that textureInfo `pointer` of the document at `gltf`
/// reads (a file next to it).
fn texture_pixels(gltf: &Path, pointer: &str) -> (image::ColorType, Vec<[u8; 4]>) {
    let doc: Value = serde_json::from_slice(&std::fs::read(gltf).unwrap()).unwrap();
    let texture = doc
        .pointer(&format!("{pointer}/index"))
        .unwrap()
        .as_u64()
        .unwrap();
    let image = doc["textures"][texture as usize]["source"]
        .as_u64()
        .unwrap();
    let uri = doc["images"][image as usize]["uri"].as_str().unwrap();
    let decoded = image::open(gltf.parent().unwrap().join(uri)).unwrap();
    let colour = decoded.color();
    let pixels = decoded.to_rgba8().pixels().map(|p| p.0).collect();
    (colour, pixels)
}

/// Sheen colour texels that cover black, the sRGB segment boundary (code 10 decodes below
/// 0.04045, 11 above), mid values, one channel dominant per texel, and white.
const SHEEN_TEXELS: [[u8; 3]; 8] = [
    [0, 0, 0],
    [10, 11, 0],
    [255, 128, 64],
    [64, 255, 128],
    [1, 2, 200],
    [200, 200, 200],
    [255, 255, 255],
    [37, 0, 90],
];

#[test]
fn exact_mode_bakes_the_sheen_strength_and_normalised_colour_texel_by_texel() {
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u8> = SHEEN_TEXELS.iter().flatten().copied().collect();
    png_file(
        &dir.path().join("sheen.png"),
        4,
        2,
        image::ColorType::Rgb8,
        &data,
    );
    let factor = [0.8, 0.6, 0.3];
    let (output, doc, result) = migrate_document(
        dir.path(),
        "exact",
        serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_sheen"],
            "materials": [{"extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": factor,
                "sheenColorTexture": {"index": 0},
                "sheenRoughnessFactor": 0.4
            }}}],
            "textures": [{"source": 0, "sampler": 0}],
            "samplers": [{"magFilter": 9729}],
            "images": [{"uri": "sheen.png"}]
        }),
        "out/exact.gltf",
        Options {
            exact: true,
            ..Options::default()
        },
    );
    assert!(result.detail.materials[0].notes.contains(&Note::ExactBaked));
    // Each baked image states its quantisation error: at most half a code.
    let errors_in_codes: Vec<(String, f64)> = result
        .detail
        .notes
        .iter()
        .filter_map(|n| match n {
            Note::BakeError {
                image, max_codes, ..
            } => Some((image.clone(), *max_codes)),
            _ => None,
        })
        .collect();
    assert_eq!(
        errors_in_codes
            .iter()
            .map(|e| e.0.as_str())
            .collect::<Vec<_>>(),
        ["sheen.fuzz", "sheen.fuzzColor"]
    );
    assert!(
        errors_in_codes.iter().all(|e| e.1 <= 0.5),
        "{errors_in_codes:?}"
    );
    let fuzz = &doc["materials"][0]["extensions"]["KHR_materials_fuzz"];
    assert_eq!(fuzz["fuzzFactor"], serde_json::json!(1.0));
    assert_eq!(fuzz["fuzzColorFactor"], serde_json::json!([1.0, 1.0, 1.0]));
    // The fitted mapping, the default, writes α(0.4) for the fuzz, to four decimals.
    assert_eq!(
        fuzz["fuzzRoughnessFactor"].as_f64(),
        Some(roughness::written(roughness::map(
            0.4,
            Direction::SheenToFuzz,
            RoughnessMapping::Fitted
        )))
    );
    assert_eq!(fuzz["fuzzRoughnessFactor"].to_string(), "0.4877");
    // The sheen fallback still reads the original texture, and the new textures keep its sampler.
    let sheen = &doc["materials"][0]["extensions"]["KHR_materials_sheen"];
    assert_eq!(sheen["sheenColorTexture"]["index"], 0);
    assert_eq!(doc["images"][0]["uri"], "sheen.png");
    for pointer in ["fuzzTexture", "fuzzColorTexture"] {
        let t = fuzz[pointer]["index"].as_u64().unwrap() as usize;
        assert_eq!(doc["textures"][t]["sampler"], 0, "{pointer}");
    }

    let base = "/materials/0/extensions/KHR_materials_fuzz";
    let (strength_type, strength) = texture_pixels(&output, &format!("{base}/fuzzTexture"));
    let (_, colour) = texture_pixels(&output, &format!("{base}/fuzzColorTexture"));
    assert_eq!(
        strength_type,
        image::ColorType::L8,
        "the strength is one grey channel"
    );
    let mut worst_lobe: f64 = 0.0;
    let mut worst_attenuation: f64 = 0.0;
    for (k, texel) in SHEEN_TEXELS.iter().enumerate() {
        let linear: [f64; 3] = std::array::from_fn(|i| factor[i] * srgb_decode(texel[i]));
        let w = linear.iter().cloned().fold(0.0, f64::max);
        assert_eq!(
            strength[k][0],
            linear_code(w),
            "strength of texel {k} {texel:?}"
        );
        for i in 0..3 {
            let expected = if w == 0.0 {
                255
            } else {
                srgb_encode_code(linear[i] / w)
            };
            assert_eq!(
                colour[k][i], expected,
                "colour channel {i} of texel {k} {texel:?}"
            );
            // The lobe the fuzz shows, from the stored codes, against the sheen's.
            let lobe = srgb_decode(colour[k][i]) * strength[k][0] as f64 / 255.0;
            worst_lobe = worst_lobe.max((lobe - linear[i]).abs());
        }
        worst_attenuation = worst_attenuation.max((strength[k][0] as f64 / 255.0 - w).abs());
    }
    // Quantisation alone: half a linear code for the strength; the lobe adds the colour's code.
    assert!(
        worst_attenuation <= 0.5 / 255.0 + 1e-12,
        "{worst_attenuation}"
    );
    assert!(worst_lobe < 0.01, "{worst_lobe}");
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));
}

#[test]
fn a_draft_sheen_roughness_moves_from_metallic_roughness_green_to_alpha() {
    let dir = tempfile::tempdir().unwrap();
    // Metallic in blue, roughness in green; red (occlusion) must stay bit-exact.
    let texels: [[u8; 3]; 4] = [[1, 0, 255], [2, 128, 0], [3, 255, 77], [4, 31, 9]];
    let data: Vec<u8> = texels.iter().flatten().copied().collect();
    png_file(
        &dir.path().join("mr.png"),
        2,
        2,
        image::ColorType::Rgb8,
        &data,
    );
    let legacy = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [{
            "pbrMetallicRoughness": {"roughnessFactor": 0.6, "metallicRoughnessTexture": {"index": 0}},
            "extensions": {"KHR_materials_sheen": {"sheenFactor": 0.5}}
        }],
        "textures": [{"source": 0}],
        "images": [{"uri": "mr.png"}]
    });
    let alpha_of = |output: &Path, layer: &str, slot: &str| -> Vec<u8> {
        let (kind, pixels) =
            texture_pixels(output, &format!("/materials/0/extensions/{layer}/{slot}"));
        assert_eq!(kind, image::ColorType::Rgba8);
        for (k, t) in texels.iter().enumerate() {
            assert_eq!(
                &pixels[k][..3],
                t,
                "RGB of texel {k} of {slot} is bit-exact"
            );
        }
        pixels.iter().map(|p| p[3]).collect()
    };
    // 0.6 × code never lands on a half code here, where rounding order would decide.
    let sheen_alpha: Vec<u8> = texels
        .iter()
        .map(|t| linear_code(0.6 * t[1] as f64 / 255.0))
        .collect();

    // Identity: sheen and fuzz read one texture holding 0.6 × green in alpha.
    let (output, doc, _) = migrate_document(
        dir.path(),
        "legacy",
        legacy.clone(),
        "identity.gltf",
        Options {
            roughness: RoughnessMapping::Identity,
            ..Options::default()
        },
    );
    let layers = &doc["materials"][0]["extensions"];
    assert_eq!(
        layers["KHR_materials_sheen"]["sheenRoughnessFactor"],
        serde_json::json!(1.0)
    );
    assert_eq!(
        layers["KHR_materials_fuzz"]["fuzzRoughnessFactor"],
        serde_json::json!(1.0)
    );
    assert_eq!(
        layers["KHR_materials_sheen"]["sheenRoughnessTexture"],
        layers["KHR_materials_fuzz"]["fuzzRoughnessTexture"],
        "sheen and fuzz share the one baked texture"
    );
    // The material's own metallicRoughness still reads the original.
    assert_eq!(
        doc["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"]["index"],
        0
    );
    assert_eq!(
        alpha_of(&output, "KHR_materials_sheen", "sheenRoughnessTexture"),
        sheen_alpha
    );
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));

    // Fitted (the default): the sheen keeps 0.6 × green; the fuzz gets α(0.6 × green), each
    // texel the nearest code to the mapping of its exact value.
    let (output, doc, _) = migrate_document(
        dir.path(),
        "legacy",
        legacy,
        "fitted.gltf",
        // The exact setting: the fuzz texture holds α(0.6 × green) itself, to the nearest code.
        Options {
            budget: migrate::budget::Budget::Exact,
            ..Options::default()
        },
    );
    let layers = &doc["materials"][0]["extensions"];
    assert_ne!(
        layers["KHR_materials_sheen"]["sheenRoughnessTexture"],
        layers["KHR_materials_fuzz"]["fuzzRoughnessTexture"]
    );
    assert_eq!(
        alpha_of(&output, "KHR_materials_sheen", "sheenRoughnessTexture"),
        sheen_alpha
    );
    let fuzz_alpha: Vec<u8> = texels
        .iter()
        .map(|t| {
            linear_code(roughness::map(
                0.6 * t[1] as f64 / 255.0,
                Direction::SheenToFuzz,
                RoughnessMapping::Fitted,
            ))
        })
        .collect();
    assert_eq!(
        alpha_of(&output, "KHR_materials_fuzz", "fuzzRoughnessTexture"),
        fuzz_alpha
    );
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));
}

#[test]
fn a_fallback_sheen_colour_is_baked_from_fuzz_colour_times_intensity() {
    let dir = tempfile::tempdir().unwrap();
    let colours: [[u8; 3]; 4] = [[255, 0, 0], [10, 11, 12], [128, 200, 255], [0, 0, 0]];
    let data: Vec<u8> = colours.iter().flatten().copied().collect();
    png_file(
        &dir.path().join("colour.png"),
        2,
        2,
        image::ColorType::Rgb8,
        &data,
    );
    let intensity = [255u8, 128, 0, 77];
    png_file(
        &dir.path().join("intensity.png"),
        2,
        2,
        image::ColorType::L8,
        &intensity,
    );
    let (output, doc, _) = migrate_document(
        dir.path(),
        "fuzz",
        serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_fuzz"],
            "materials": [{"extensions": {"KHR_materials_fuzz": {
                "fuzzFactor": 0.9,
                "fuzzTexture": {"index": 1},
                "fuzzColorFactor": [1.0, 0.5, 0.25],
                "fuzzColorTexture": {"index": 0},
                "fuzzRoughnessFactor": 0.3
            }}}],
            "textures": [{"source": 0}, {"source": 1}],
            "images": [{"uri": "colour.png"}, {"uri": "intensity.png"}]
        }),
        "fuzz.out.gltf",
        Options::default(),
    );
    let sheen = &doc["materials"][0]["extensions"]["KHR_materials_sheen"];
    assert_eq!(
        sheen["sheenColorFactor"],
        serde_json::json!([1.0, 1.0, 1.0])
    );
    let (_, pixels) = texture_pixels(
        &output,
        "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture",
    );
    let factor = [0.9, 0.45, 0.225];
    for k in 0..4 {
        for i in 0..3 {
            let linear = factor[i] * srgb_decode(colours[k][i]) * intensity[k] as f64 / 255.0;
            assert_eq!(
                pixels[k][i],
                srgb_encode_code(linear),
                "channel {i} of texel {k}"
            );
        }
    }
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));
}

#[test]
fn a_glb_keeps_baked_textures_in_its_bin_chunk() {
    let dir = tempfile::tempdir().unwrap();
    let mut png = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(
        &mut png,
        &[255, 0, 0, 128, 0, 0],
        2,
        1,
        image::ColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .unwrap();
    let png = png.into_inner();
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [{"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.25, 0.0], "sheenColorTexture": {"index": 0}
        }}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": 0, "mimeType": "image/png"}],
        "bufferViews": [{"buffer": 0, "byteLength": png.len()}],
        "buffers": [{"byteLength": png.len()}]
    });
    let input = dir.path().join("in.glb");
    std::fs::write(
        &input,
        glb::join(&serde_json::to_vec(&json).unwrap(), Some(&png)),
    )
    .unwrap();
    let output = dir.path().join("out.glb");
    let report = migrating::run(&request(
        vec![input],
        Destination::File(output.clone()),
        Options {
            exact: true,
            ..Options::default()
        },
    ))
    .unwrap();
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    let bytes = std::fs::read(&output).unwrap();
    let loaded = velvet::asset::load_bytes(&output, &bytes);
    let asset = loaded.asset.unwrap();
    let views = asset.json()["bufferViews"].as_array().unwrap();
    assert_eq!(views.len(), 3, "the source and the two baked images");
    for view in views {
        assert_eq!(view["byteOffset"].as_u64().unwrap_or(0) % 4, 0);
    }
    let images = asset.json()["images"].as_array().unwrap();
    assert!(images.iter().all(|i| i.get("uri").is_none()));
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));
}

#[test]
fn a_fallback_sheen_roughness_texture_holds_the_mapped_roughness_unless_fast() {
    let dir = tempfile::tempdir().unwrap();
    let alphas = [0u8, 26, 128, 255];
    let data: Vec<u8> = alphas.iter().flat_map(|&a| [200, 100, 50, a]).collect();
    png_file(
        &dir.path().join("rough.png"),
        2,
        2,
        image::ColorType::Rgba8,
        &data,
    );
    let fuzz = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_fuzz"],
        "materials": [{"extensions": {"KHR_materials_fuzz": {
            "fuzzFactor": 1.0,
            "fuzzColorFactor": [0.5, 0.5, 0.5],
            "fuzzRoughnessFactor": 0.8,
            "fuzzRoughnessTexture": {"index": 0}
        }}}],
        "textures": [{"source": 0}],
        "images": [{"uri": "rough.png"}]
    });
    let (output, doc, result) = migrate_document(
        dir.path(),
        "fuzz",
        fuzz.clone(),
        "fitted.gltf",
        Options::default(),
    );
    let sheen = &doc["materials"][0]["extensions"]["KHR_materials_sheen"];
    let factor = sheen["sheenRoughnessFactor"].as_f64().unwrap();
    assert_ne!(sheen["sheenRoughnessTexture"]["index"], 0);
    let (_, pixels) = texture_pixels(
        &output,
        "/materials/0/extensions/KHR_materials_sheen/sheenRoughnessTexture",
    );
    // The error a reader measures from the decoded output: factor × texel against the exact
    // mapping of the input's factor × texel, over the texels.
    let mut measured = 0.0f64;
    for (k, &a) in alphas.iter().enumerate() {
        assert_eq!(
            &pixels[k][..3],
            &[200, 100, 50],
            "RGB of texel {k} is bit-exact"
        );
        let exact = roughness::map(
            0.8 * a as f64 / 255.0,
            Direction::FuzzToSheen,
            RoughnessMapping::Fitted,
        );
        measured = measured.max((factor * pixels[k][3] as f64 / 255.0 - exact).abs());
    }
    let reported = result.detail.materials[0]
        .notes
        .iter()
        .find_map(|n| match n {
            Note::RoughnessPlan {
                max_error,
                factor: f,
                ..
            } => Some((*max_error, *f)),
            _ => None,
        })
        .expect("the plan is reported");
    assert_eq!(reported.1, factor, "the factor reported is the one written");
    assert!(
        (reported.0 - measured).abs() < 1e-12,
        "reported {} measured {measured}",
        reported.0
    );
    assert!(measured <= migrate::budget::DEFAULT_BUDGET);
    assert!(errors(&output).is_empty(), "{:?}", errors(&output));

    // --fast: the texture is carried as it is and the roughness copied, said so.
    let (_, doc, result) = migrate_document(
        dir.path(),
        "fuzz",
        fuzz,
        "fast.gltf",
        Options {
            fast: true,
            ..Options::default()
        },
    );
    let sheen = &doc["materials"][0]["extensions"]["KHR_materials_sheen"];
    assert_eq!(sheen["sheenRoughnessFactor"], serde_json::json!(0.8));
    assert_eq!(
        sheen["sheenRoughnessTexture"],
        serde_json::json!({"index": 0})
    );
    assert!(result.detail.materials[0]
        .notes
        .contains(&Note::RoughnessTextureFast { mapping: "fitted" }));
    assert_eq!(doc["images"].as_array().unwrap().len(), 1, "nothing baked");
}

/// Found by the property tests: black fuzz gets no fallback sheen, so nothing may be baked for
/// one (a bake aimed at the absent sheen added an image and made the file change).
#[test]
fn black_fuzz_with_an_intensity_texture_bakes_nothing_and_is_left_as_it_is() {
    let dir = tempfile::tempdir().unwrap();
    png_file(
        &dir.path().join("intensity.png"),
        2,
        1,
        image::ColorType::L8,
        &[0, 255],
    );
    let input = dir.path().join("black.gltf");
    std::fs::write(
        &input,
        serde_json::to_vec_pretty(&serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_fuzz"],
            "materials": [{"extensions": {"KHR_materials_fuzz": {
                "fuzzFactor": 1.0,
                "fuzzColorFactor": [0.0, 0.0, 0.0],
                "fuzzTexture": {"index": 0}
            }}}],
            "textures": [{"source": 0}],
            "images": [{"uri": "intensity.png"}]
        }))
        .unwrap(),
    )
    .unwrap();
    let output = dir.path().join("black.out.gltf");
    let report = migrate_to(&input, &output);
    let result = &report.files[0];
    assert_eq!(result.outcome, FileOutcome::Copied);
    assert_eq!(result.detail.materials[0].skipped, Some(Skip::BlackFuzz));
    assert!(result.detail.materials[0].bakes.is_empty());
    assert_eq!(
        result.detail.materials[0].notes,
        [
            Note::FuzzRoughnessDefault { assumed: 0.5 },
            Note::DarkFuzz {
                difference: 1.0,
                fuzz_color_max: 0.0,
                base_color_max: 1.0
            },
            Note::BlackFuzz
        ],
        "no note of a bake"
    );
    assert_eq!(
        std::fs::read(&output).unwrap(),
        std::fs::read(&input).unwrap()
    );
    let mut files: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    assert_eq!(files, ["black.gltf", "black.out.gltf", "intensity.png"]);
}

// ---- A library: reproducible, self-contained output; bare paths; links ----

/// Every file under `dir` (relative path → bytes).
fn tree(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).unwrap();
                out.insert(path.strip_prefix(dir).unwrap().to_path_buf(), bytes);
            }
        }
    }
    out
}

/// A folder of assets that share image names: in `lib/` and `lib/sub/`, six .gltf files each
/// reading a roughness texture `rough.png` (its own in each folder) with its own factor, so
/// their baked textures would collide on a name made from the image name alone.
fn library(root: &Path) -> PathBuf {
    let lib = root.join("lib");
    for (folder, seed) in [("", 0u8), ("sub", 40)] {
        let dir = lib.join(folder);
        std::fs::create_dir_all(&dir).unwrap();
        let data: Vec<u8> = (0..16u8)
            .flat_map(|i| [i * 9, 200, 50, i.wrapping_mul(17).wrapping_add(seed)])
            .collect();
        png_file(&dir.join("rough.png"), 4, 4, image::ColorType::Rgba8, &data);
        std::fs::write(dir.join("mesh.bin"), [7u8; 12]).unwrap();
        for k in 0..6 {
            let doc = serde_json::json!({
                "asset": {"version": "2.0"},
                "extensionsUsed": ["KHR_materials_sheen"],
                "buffers": [{"uri": "mesh.bin", "byteLength": 12}],
                "materials": [{"extensions": {"KHR_materials_sheen": {
                    "sheenColorFactor": [0.8, 0.6, 0.4],
                    "sheenRoughnessFactor": 0.3 + 0.1 * k as f64,
                    "sheenRoughnessTexture": {"index": 0}
                }}}],
                "textures": [{"source": 0}],
                "images": [{"uri": "rough.png"}]
            });
            std::fs::write(
                dir.join(format!("asset{k}.gltf")),
                serde_json::to_vec_pretty(&doc).unwrap(),
            )
            .unwrap();
        }
    }
    lib
}

fn velvet_in(dir: &Path, env: &[(&str, &str)], args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .current_dir(dir)
        .envs(env.iter().copied())
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn one_and_four_threads_give_byte_identical_trees() {
    let dir = tempfile::tempdir().unwrap();
    library(dir.path());
    for (threads, out) in [("1", "one"), ("4", "four")] {
        for (budget, dir_name) in [("0.01", out.to_string()), ("exact", format!("{out}-exact"))] {
            let (status, stdout, stderr) = velvet_in(
                dir.path(),
                &[("RAYON_NUM_THREADS", threads)],
                &[
                    "migrate",
                    "lib",
                    "--out-dir",
                    &dir_name,
                    "--roughness-budget",
                    budget,
                ],
            );
            assert_eq!(status, 0, "{stdout}{stderr}");
        }
    }
    for (a, b) in [("one", "four"), ("one-exact", "four-exact")] {
        let (a, b) = (tree(&dir.path().join(a)), tree(&dir.path().join(b)));
        assert_eq!(a.keys().collect::<Vec<_>>(), b.keys().collect::<Vec<_>>());
        assert!(a == b, "the trees hold the same bytes");
        // 12 documents, 2 copied sources, 2 copied buffers, and the baked textures.
        assert!(a.len() > 16, "{:?}", a.keys().collect::<Vec<_>>());
    }
}

#[test]
fn an_out_dir_tree_moved_elsewhere_validates_clean() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path());
    let out = dir.path().join("out");
    let report = migrating::run(&request(
        vec![lib],
        Destination::Dir(out.clone()),
        Options::default(),
    ))
    .unwrap();
    assert!(
        !report.failed(),
        "{}",
        render::text(&report, Detail::Verbose)
    );
    let moved = dir.path().join("far/away/moved");
    std::fs::create_dir_all(moved.parent().unwrap()).unwrap();
    std::fs::rename(&out, &moved).unwrap();
    let mut checked = 0;
    for (path, bytes) in tree(&moved) {
        if path.extension().is_some_and(|e| e == "gltf") {
            let doc: Value = serde_json::from_slice(&bytes).unwrap();
            for uri in ["/buffers/0/uri", "/images/0/uri", "/images/1/uri"] {
                if let Some(uri) = doc.pointer(uri).and_then(Value::as_str) {
                    assert!(!uri.contains(".."), "{}: {uri}", path.display());
                }
            }
            assert_eq!(errors(&moved.join(&path)), Vec::new(), "{}", path.display());
            checked += 1;
        }
    }
    assert_eq!(checked, 12);
}

#[test]
fn bare_relative_names_in_the_current_folder_work() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path());
    let (status, stdout, stderr) = velvet_in(
        &lib,
        &[],
        &["migrate", "asset0.gltf", "-o", "asset0.fuzz.gltf"],
    );
    assert_eq!(status, 0, "{stdout}{stderr}");
    let doc: Value =
        serde_json::from_slice(&std::fs::read(lib.join("asset0.fuzz.gltf")).unwrap()).unwrap();
    assert_eq!(doc["buffers"][0]["uri"], "mesh.bin");
    assert!(doc["materials"][0]["extensions"]["KHR_materials_fuzz"].is_object());
    assert_eq!(errors(&lib.join("asset0.fuzz.gltf")), Vec::new());
    // A bare output name in another folder's input works too.
    let (status, stdout, stderr) = velvet_in(
        dir.path(),
        &[],
        &["migrate", "lib/sub/asset1.gltf", "-o", "moved.gltf"],
    );
    assert_eq!(status, 0, "{stdout}{stderr}");
    assert_eq!(errors(&dir.path().join("moved.gltf")), Vec::new());
    assert_eq!(
        std::fs::read(dir.path().join("mesh.bin")).unwrap(),
        [7u8; 12]
    );
}

#[cfg(unix)]
#[test]
fn a_link_to_a_file_outside_the_input_folder_is_refused_and_nothing_of_it_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let lib = library(dir.path());
    // The secret is a valid PNG, so that a bake would happily read it.
    let secret: Vec<u8> = (0..16u8).flat_map(|i| [i, 1, 2, 251 - i]).collect();
    png_file(
        &dir.path().join("secret.png"),
        4,
        4,
        image::ColorType::Rgba8,
        &secret,
    );
    let secret_bytes = std::fs::read(dir.path().join("secret.png")).unwrap();
    std::fs::remove_file(lib.join("rough.png")).unwrap();
    std::os::unix::fs::symlink(dir.path().join("secret.png"), lib.join("rough.png")).unwrap();
    // A link that stays inside the folder is followed (and copied as a regular file).
    std::fs::rename(lib.join("mesh.bin"), lib.join("sub/real.bin")).unwrap();
    std::os::unix::fs::symlink("sub/real.bin", lib.join("mesh.bin")).unwrap();
    let out = dir.path().join("out");
    for fast in [false, true] {
        let report = migrating::run(&request(
            vec![lib.clone()],
            Destination::Dir(out.clone()),
            Options {
                fast,
                ..Options::default()
            },
        ))
        .unwrap();
        assert_eq!(
            report.summary.totals.failed,
            6,
            "{}",
            render::text(&report, Detail::Verbose)
        );
        for file in report
            .files
            .iter()
            .filter(|f| f.input.parent() == Some(&lib))
        {
            let FileOutcome::Failed { error } = &file.outcome else {
                panic!("{:?}", file.outcome)
            };
            assert!(
                error.contains("'rough.png'") && error.contains("outside the input's folder"),
                "{error}"
            );
        }
    }
    let written = tree(&out);
    assert!(written.keys().all(|p| p.starts_with("sub")), "{written:?}");
    for (path, bytes) in &written {
        assert_ne!(bytes, &secret_bytes, "{}", path.display());
        assert!(
            !std::fs::symlink_metadata(out.join(path))
                .unwrap()
                .file_type()
                .is_symlink(),
            "{}",
            path.display()
        );
    }
    // bake refuses it too.
    let (status, stdout, _) = velvet(&[
        "bake",
        lib.join("asset0.gltf").to_str().unwrap(),
        "-o",
        dir.path().join("baked/asset0.gltf").to_str().unwrap(),
    ]);
    assert_eq!(status, 1, "{stdout}");
    assert!(stdout.contains("'rough.png'"), "{stdout}");
    assert!(!dir.path().join("baked").exists() || tree(&dir.path().join("baked")).is_empty());
}

/// Three materials read one roughness texture (alpha 192–255, each code once) with nearby
/// factors: the default budget shares one fitted texture, a zero budget and the exact setting
/// bake one per material; in every case the error reported equals the error measured from the
/// decoded output.
#[test]
fn the_roughness_plan_shares_a_texture_within_the_budget_and_bakes_per_material_otherwise() {
    use migrate::budget::{Budget, TexturePlan, DEFAULT_BUDGET};
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u8> = (0..64u8).flat_map(|k| [10, 20, 30, 192 + k]).collect();
    png_file(
        &dir.path().join("rough.png"),
        8,
        8,
        image::ColorType::Rgba8,
        &data,
    );
    let factors = [0.30, 0.35, 0.40];
    let materials: Vec<Value> = factors
        .iter()
        .map(|f| {
            serde_json::json!({"extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [0.5, 0.5, 0.5],
                "sheenRoughnessFactor": f,
                "sheenRoughnessTexture": {"index": 0}
            }}})
        })
        .collect();
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": materials,
        "textures": [{"source": 0}],
        "images": [{"uri": "rough.png"}]
    });
    for (budget, added, plan, bound) in [
        (Budget::default(), 1, TexturePlan::Shared, DEFAULT_BUDGET),
        (Budget::Within(0.0), 3, TexturePlan::Exact, 0.5 / 255.0),
        (Budget::Exact, 3, TexturePlan::Exact, 0.5 / 255.0),
    ] {
        let (output, doc, result) = migrate_document(
            dir.path(),
            "cloth",
            json.clone(),
            &format!("{budget:?}.gltf"),
            Options {
                budget,
                ..Options::default()
            },
        );
        assert_eq!(result.detail.textures_added, added, "{budget:?}");
        assert_eq!(doc["images"].as_array().unwrap().len(), 1 + added);
        for (m, &f) in factors.iter().enumerate() {
            let (plan_of, reported) = result.detail.materials[m]
                .notes
                .iter()
                .find_map(|n| match n {
                    Note::RoughnessPlan {
                        plan, max_error, ..
                    } => Some((*plan, *max_error)),
                    _ => None,
                })
                .expect("every mapped texture's plan is reported");
            assert_eq!(plan_of, plan, "{budget:?} material {m}");
            let fuzz = &doc["materials"][m]["extensions"]["KHR_materials_fuzz"];
            let factor = fuzz["fuzzRoughnessFactor"].as_f64().unwrap();
            let (_, pixels) = texture_pixels(
                &output,
                &format!("/materials/{m}/extensions/KHR_materials_fuzz/fuzzRoughnessTexture"),
            );
            let measured = pixels
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let exact = roughness::map(
                        f * (192 + k) as f64 / 255.0,
                        Direction::SheenToFuzz,
                        RoughnessMapping::Fitted,
                    );
                    (factor * p[3] as f64 / 255.0 - exact).abs()
                })
                .fold(0.0, f64::max);
            assert!(
                (measured - reported).abs() < 1e-12,
                "{budget:?} material {m}: reported {reported}, measured {measured}"
            );
            assert!(
                measured <= bound + 1e-12,
                "{budget:?} material {m}: {measured}"
            );
        }
        assert!(errors(&output).is_empty(), "{:?}", errors(&output));
    }
}

/// A migration with bakes changes only the baked material, the declaration and the texture
/// lists: the other materials (their numbers as exported, `0.80000001192092896`), the meshes
/// and a texture the baked material's sheen and another material still name all come out as
/// they went in, and the output validates as the input does.
#[test]
fn a_migration_with_bakes_leaves_every_other_part_of_the_text_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let data: Vec<u8> = [0u8, 26, 128, 255]
        .iter()
        .flat_map(|&a| [200, 100, 50, a])
        .collect();
    png_file(
        &dir.path().join("rough.png"),
        2,
        2,
        image::ColorType::Rgba8,
        &data,
    );
    let other = "{\"name\": \"base\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.80000001192092896, 1E-1, 1, 1], \"baseColorTexture\": {\"index\": 0}}}";
    let mesh = "{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1}, \"material\": 1}]}";
    let text = format!(
        "{{\n\t\"asset\": {{\"version\": \"2.0\"}},\n\t\"materials\": [\n\t\t{other},\n\t\t{{\"extensions\": {{\"KHR_materials_sheen\": {{\"sheenColorFactor\": [1, 1, 1], \"sheenRoughnessFactor\": 0.5, \"sheenRoughnessTexture\": {{\"index\": 0}}}}}}}}\n\t],\n\t\"meshes\": [\n\t\t{mesh}\n\t],\n\t\"textures\": [{{\"source\": 0}}],\n\t\"images\": [{{\"uri\": \"rough.png\"}}],\n\t\"extensionsUsed\": [\"KHR_materials_sheen\"]\n}}"
    );
    let input = dir.path().join("chair.gltf");
    std::fs::write(&input, &text).unwrap();
    let output = dir.path().join("out/chair.gltf");
    let report = migrate_to(&input, &output);
    assert_eq!(report.files[0].outcome, FileOutcome::Changed);
    assert_eq!(report.files[0].detail.textures_added, 1);
    let written = std::fs::read_to_string(&output).unwrap();
    for kept in [other, mesh, "{\"source\": 0}", "{\"uri\": \"rough.png\"}"] {
        assert!(
            written.contains(kept),
            "{kept} is kept as written:\n{written}"
        );
    }
    let doc: Value = serde_json::from_str(&written).unwrap();
    let fuzz = &doc["materials"][1]["extensions"]["KHR_materials_fuzz"];
    assert_eq!(fuzz["fuzzRoughnessTexture"]["index"], 1);
    assert_eq!(doc["textures"][1]["source"], 1);
    assert_eq!(
        doc["materials"][1]["extensions"]["KHR_materials_sheen"]["sheenRoughnessTexture"],
        serde_json::json!({"index": 0})
    );
    assert_eq!(
        doc["extensionsUsed"],
        serde_json::json!(["KHR_materials_sheen", "KHR_materials_fuzz"])
    );
    // Tabs and one-line objects as the file writes them: no line but the baked material's,
    // the texture and image lists' and the declaration's changed.
    let before: Vec<&str> = text.lines().collect();
    let after: Vec<&str> = written.lines().collect();
    assert_eq!(after.len(), before.len(), "{written}");
    let changed: Vec<usize> = (0..before.len())
        .filter(|&i| after[i] != before[i])
        .collect();
    assert_eq!(changed, [4, 9, 10, 11], "{written}");
    // The mesh names no accessors (the scene is cut short): that finding, and no other.
    assert_eq!(errors(&output), errors(&input));
}

/// A document of `materials` sheen materials (each with a name of `pad` bytes), in two-space
/// layout: large enough for the command to map the file rather than read it.
fn large_sheen_document(materials: usize, pad: usize) -> String {
    let mut text = String::from(
        "{\n  \"asset\": {\n    \"version\": \"2.0\"\n  },\n  \"extensionsUsed\": [\n    \"KHR_materials_sheen\"\n  ],\n  \"materials\": [",
    );
    for i in 0..materials {
        if i > 0 {
            text.push(',');
        }
        text.push_str(&format!(
            "\n    {{\n      \"name\": \"m{i} {}\",\n      \"extensions\": {{\n        \"KHR_materials_sheen\": {{\n          \"sheenColorFactor\": [0.5, 0.25, 1.0],\n          \"sheenRoughnessFactor\": 0.75\n        }}\n      }}\n    }}",
            "x".repeat(pad)
        ));
    }
    text.push_str("\n  ]\n}\n");
    text
}

#[test]
fn a_large_file_is_migrated_in_place_as_the_library_migrates_its_bytes() {
    let text = large_sheen_document(800, 4000);
    assert!(text.len() as u64 > 2 << 20);
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("large.gltf");
    std::fs::write(&input, &text).unwrap();
    // The reference: the library migrating the same bytes, never mapped (the library maps
    // only once the command enables it).
    let reference_dir = tempfile::tempdir().unwrap();
    let reference = reference_dir.path().join("large.gltf");
    std::fs::write(&reference, &text).unwrap();
    let report = migrating::run(&request(
        vec![reference.clone()],
        Destination::InPlace,
        Options::default(),
    ))
    .unwrap();
    assert_eq!(report.files.len(), 1);
    let expected = std::fs::read(&reference).unwrap();
    assert_ne!(expected, text.as_bytes());

    let (status, _, stderr) = velvet(&["migrate", "-q", "--in-place", input.to_str().unwrap()]);
    assert_eq!(status, 0, "{stderr}");
    assert_file(&input, &expected);
    // Nothing but the output is left in the folder.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    // Every input byte is still there, in order.
    let mut rest = expected.iter();
    assert!(text.bytes().all(|b| rest.any(|&c| c == b)));
}

/// The numbers (and arrays of numbers) in `value`, each with its pointer below `at`.
fn numbers_below(at: &str, value: &Value, out: &mut Vec<(String, Value)>) {
    match value {
        Value::Object(members) => {
            for (key, member) in members {
                numbers_below(&format!("{at}/{key}"), member, out);
            }
        }
        Value::Array(items) if items.iter().all(Value::is_number) => {
            out.push((at.to_string(), value.clone()))
        }
        Value::Number(_) => out.push((at.to_string(), value.clone())),
        _ => {}
    }
}

#[test]
fn every_number_the_plan_sets_is_the_number_the_written_file_holds() {
    // The plan is what the dry run and --check print: a factor a bake settles (a shared
    // roughness texture's factor, the identity once a factor is baked in) must be the one in
    // the set the plan shows, not the factor before the bake.
    let option_sets = [
        Options::default(),
        Options {
            exact: true,
            ..Options::default()
        },
        Options {
            budget: migrate::budget::Budget::Exact,
            ..Options::default()
        },
        Options {
            fast: true,
            ..Options::default()
        },
    ];
    let mut compared = 0;
    let mut baked = 0;
    for case in cases() {
        for options in &option_sets {
            let options = Options {
                refresh_fallback: options_for(&case).refresh_fallback,
                ..options.clone()
            };
            let (_dir, output, result) = migrate_case_with(&case, options);
            if !output.exists() {
                continue;
            }
            let written: Value = serde_json::from_slice(&std::fs::read(&output).unwrap()).unwrap();
            for material in &result.detail.materials {
                baked += material.bakes.len();
                for edit in &material.edits {
                    let velvet::edit::Edit::Set { pointer, value } = edit else {
                        continue;
                    };
                    let mut numbers = Vec::new();
                    numbers_below(pointer, &value.to_value(), &mut numbers);
                    for (at, planned) in numbers {
                        // A textureInfo's index names the texture before the bake; the bake
                        // line of the plan says which texture it becomes.
                        if at.ends_with("Texture/index") {
                            continue;
                        }
                        assert_eq!(
                            written.pointer(&at),
                            Some(&planned),
                            "{}: {at}",
                            case.display()
                        );
                        compared += 1;
                    }
                }
            }
        }
    }
    assert!(compared > 200, "{compared} values compared");
    assert!(baked > 10, "{baked} bakes among them");
}

/// Writes `input` to `output` through migrate's one-file path, by the strategy the spine
/// chooses or, with `rewrite`, by the rewrite; returns the strategy that wrote it.
fn written_by(input: &Path, output: &Path, options: &Options, rewrite: bool) -> WriteStrategy {
    let job = Job {
        input: input.to_path_buf(),
        output: Some(output.to_path_buf()),
    };
    let mut plan = apply::plan_file(&job, options).unwrap();
    let (_, strategy) = apply::execute_by(&mut plan, &Claims::default(), rewrite)
        .unwrap_or_else(|e| panic!("{}: {e}", input.display()));
    strategy
}

#[test]
fn every_write_strategy_writes_the_document_the_rewrite_writes() {
    let dir = tempfile::tempdir().unwrap();
    // A roughness texture to bake: as files next to a .gltf the bake is applied to a part of
    // the document; embedded (--embed) the whole document is rewritten.
    let src = dir.path().join("src");
    std::fs::create_dir_all(&src).unwrap();
    let data: Vec<u8> = [0u8, 26, 128, 255]
        .iter()
        .flat_map(|&a| [200, 100, 50, a])
        .collect();
    png_file(&src.join("rough.png"), 2, 2, image::ColorType::Rgba8, &data);
    let baked = src.join("baked.gltf");
    std::fs::write(
        &baked,
        serde_json::to_string_pretty(&serde_json::json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_sheen"],
            "materials": [{"extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.5,
                "sheenRoughnessTexture": {"index": 0}
            }}}],
            "textures": [{"source": 0}],
            "images": [{"uri": "rough.png"}]
        }))
        .unwrap(),
    )
    .unwrap();
    let mut runs: Vec<(PathBuf, Options)> = cases()
        .into_iter()
        .map(|case| {
            let options = options_for(&case);
            (case, options)
        })
        .collect();
    runs.push((baked.clone(), Options::default()));
    runs.push((
        baked,
        Options {
            embed: true,
            ..Options::default()
        },
    ));
    let mut chosen = std::collections::BTreeSet::new();
    for (n, (input, options)) in runs.iter().enumerate() {
        let name = input.file_name().unwrap();
        let (by_choice, by_rewrite) = (
            dir.path().join(format!("{n}a")),
            dir.path().join(format!("{n}b")),
        );
        let strategy = written_by(input, &by_choice.join(name), options, false);
        assert_eq!(
            written_by(input, &by_rewrite.join(name), options, true),
            WriteStrategy::Rewrite
        );
        chosen.insert(format!("{strategy:?}"));
        let (a, b) = (tree(&by_choice), tree(&by_rewrite));
        assert_eq!(
            a.keys().collect::<Vec<_>>(),
            b.keys().collect::<Vec<_>>(),
            "{}: the same files",
            input.display()
        );
        for (path, bytes) in &a {
            if path.extension().is_some_and(|e| e == "gltf") {
                let doc: Value = serde_json::from_slice(bytes).unwrap();
                let rewritten: Value = serde_json::from_slice(&b[path]).unwrap();
                assert_eq!(doc, rewritten, "{} by {strategy:?}", input.display());
            } else {
                assert!(bytes == &b[path], "{}: {}", input.display(), path.display());
            }
        }
    }
    assert_eq!(
        chosen.into_iter().collect::<Vec<_>>(),
        ["BakePart", "Rewrite", "Splice"],
        "each strategy is chosen for one of the runs"
    );
}

/// A dry run's edits (each material's, then the file's, then the bakes') applied to the
/// input's JSON, in the order the report lists them.
fn dry_run_document(input: &Path, result: &migrating::FileResult) -> Value {
    let mut json: Value = serde_json::from_slice(&std::fs::read(input).unwrap()).unwrap();
    for m in &result.detail.materials {
        velvet::edit::apply(&mut json, &m.edits).unwrap();
    }
    velvet::edit::apply(&mut json, &result.detail.edits).unwrap();
    velvet::edit::apply(&mut json, &result.detail.bake_edits).unwrap();
    json
}

#[test]
fn a_dry_runs_edits_applied_to_the_input_give_the_written_document_bakes_included() {
    type Variant = (&'static str, fn(&mut Options));
    // `--embed` writes new images as data: URIs: its dry run bakes on the whole document, where
    // the others bake on the part a bake changes.
    let variants: [Variant; 4] = [
        ("default", |_| {}),
        ("exact", |o| o.exact = true),
        ("budget exact", |o| {
            o.budget = migrate::budget::Budget::Exact
        }),
        ("embed", |o| o.embed = true),
    ];
    let mut with_new_images = Vec::new();
    for case in cases() {
        for (label, set) in variants {
            let mut options = options_for(&case);
            set(&mut options);
            let dir = tempfile::tempdir().unwrap();
            let input = dir.path().join("in").join(case.file_name().unwrap());
            std::fs::create_dir_all(input.parent().unwrap()).unwrap();
            std::fs::copy(&case, &input).unwrap();
            let out_dir = dir.path().join("out");
            let mut run = request(
                vec![input.clone()],
                Destination::Dir(out_dir.clone()),
                options,
            );
            run.dry_run = true;
            let planned = migrating::run(&run).unwrap().files.remove(0);
            assert!(
                matches!(planned.outcome, FileOutcome::Planned { .. }),
                "{} ({label}): {:?}",
                stem(&case),
                planned.outcome
            );
            assert!(!out_dir.exists(), "a dry run writes nothing");
            run.dry_run = false;
            let written = migrating::run(&run).unwrap().files.remove(0);
            let output = out_dir.join(case.file_name().unwrap());
            let expected: Value = match written.outcome {
                FileOutcome::Changed | FileOutcome::Copied => {
                    serde_json::from_slice(&std::fs::read(&output).unwrap()).unwrap()
                }
                ref other => panic!("{} ({label}): {other:?}", stem(&case)),
            };
            assert_eq!(
                dry_run_document(&input, &planned),
                expected,
                "{} ({label})",
                stem(&case)
            );
            let new_images: Vec<String> = planned
                .detail
                .bake_edits
                .iter()
                .filter_map(|e| match e {
                    velvet::edit::Edit::Replace { pointer, value }
                        if pointer.starts_with("/images/") =>
                    {
                        value.get("uri").and_then(Value::as_str).map(str::to_owned)
                    }
                    _ => None,
                })
                .collect();
            for uri in new_images.iter().filter(|u| !u.starts_with("data:")) {
                assert!(out_dir.join(uri).is_file(), "{uri} is written as named");
            }
            if !new_images.is_empty() {
                with_new_images.push(format!("{} ({label}): {}", stem(&case), new_images.len()));
            }
        }
    }
    // The fixtures whose bakes add images, and how many each adds (legacy's roughness bake,
    // sheen-textures' mapped roughness, --exact's fuzz and fuzz colour textures, which the
    // default takes too where they bring a visible material to close).
    assert_eq!(
        with_new_images,
        [
            "fuzz-textures (default): 3",
            "fuzz-textures (exact): 3",
            "fuzz-textures (budget exact): 3",
            "fuzz-textures (embed): 3",
            "legacy-texcoord (default): 2",
            "legacy-texcoord (exact): 2",
            "legacy-texcoord (budget exact): 2",
            "legacy-texcoord (embed): 2",
            "legacy (default): 4",
            "legacy (exact): 4",
            "legacy (budget exact): 4",
            "legacy (embed): 4",
            "sheen-textures (default): 3",
            "sheen-textures (exact): 5",
            "sheen-textures (budget exact): 3",
            "sheen-textures (embed): 3",
        ]
    );
}

#[test]
fn a_visible_material_is_a_warning_naming_the_flags_that_bring_it_closer() {
    use velvet::migrate::verdict::{BeyondBudget, CloserBudget, Label};
    // With no budget to bake more, the cloth keeps its plan and is a warning.
    let (_dir, _output, result) = migrate_case_with(
        &fixtures().join("sheen-textures.gltf"),
        Options {
            closer_budget: CloserBudget(0),
            ..options_for(&fixtures().join("sheen-textures.gltf"))
        },
    );
    let cloth = &result.detail.materials[0];
    assert_eq!(cloth.name.as_deref(), Some("cloth"));
    assert_eq!(cloth.verdict.map(|v| v.label), Some(Label::Visible));
    let visible: Vec<&Note> = cloth
        .notes
        .iter()
        .filter(|n| matches!(n, Note::VisibleDifference { .. }))
        .collect();
    assert_eq!(visible.len(), 1);
    let Note::VisibleDifference {
        verdict,
        remedy,
        tried,
        beyond_budget,
    } = visible[0]
    else {
        unreachable!("filtered above")
    };
    assert_eq!(visible[0].level(), migrate::Level::Warning);
    assert_eq!(Some(*verdict), cloth.verdict);
    assert_eq!(
        tried,
        &[
            "--exact",
            "--roughness-budget exact",
            "--exact --roughness-budget exact"
        ]
        .map(String::from)
    );
    let remedy = remedy.as_ref().expect("--exact brings the cloth closer");
    assert_eq!(remedy.flags, "--exact");
    assert_eq!(remedy.verdict.label, Label::Close);
    // --exact bakes a fuzzTexture and a fuzzColorTexture from the 2×2 colour image (its
    // roughness bake is the one the plan has): (4 + 4) texels of 4 bytes.
    assert_eq!(*beyond_budget, Some(BeyondBudget { bytes: 32, left: 0 }));
    assert!(visible[0].message().contains(&format!(
        "--exact would bring it to {}, but its new textures (32 bytes uncompressed) pass what \
         is left of the --closer-budget (0 bytes), so the default does not take it",
        remedy.verdict.describe()
    )));
    // The tinted material is not visible, and has no such warning.
    let tinted = &result.detail.materials[1];
    assert_eq!(tinted.verdict.map(|v| v.label), Some(Label::Same));
    assert!(!tinted
        .notes
        .iter()
        .any(|n| matches!(n, Note::VisibleDifference { .. })));

    // The default budget takes the plan --exact gives: the cloth is close, and says why.
    let (_dir, _output, default) = migrate_case(&fixtures().join("sheen-textures.gltf"));
    let cloth_taken = &default.detail.materials[0];
    assert_eq!(cloth_taken.verdict, Some(remedy.verdict));
    assert!(cloth_taken.notes.contains(&Note::CloserPlanTaken {
        flags: "--exact".into(),
        before: *verdict,
        after: remedy.verdict,
        bytes: 32,
    }));
    assert!(cloth_taken.notes.contains(&Note::ExactBaked));
    assert!(!cloth_taken
        .notes
        .iter()
        .any(|n| matches!(n, Note::VisibleDifference { .. })));
}

#[test]
fn check_with_the_visible_gate_fails_on_visible_materials_only_from_the_flag_or_velvet_toml() {
    let dir = tempfile::tempdir().unwrap();
    for case in ["sheen-factors.gltf", "sheen-textures.gltf"] {
        std::fs::copy(fixtures().join(case), dir.path().join(case)).unwrap();
    }
    let path = |case: &str| dir.path().join(case).to_string_lossy().into_owned();
    // Without the gate, a file that would change fails the check.
    let (code, _, _) = velvet(&["migrate", "--check", "-q", &path("sheen-factors.gltf")]);
    assert_eq!(code, 1);
    // With it, appearance decides: three close materials pass, the visible cloth fails.
    let (code, _, err) = velvet(&[
        "migrate",
        "--check",
        "--fail-on-visible",
        "-q",
        &path("sheen-factors.gltf"),
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
    // With no budget to bake it closer, the cloth would migrate visibly and fails the gate;
    // with the default budget it is baked closer and passes.
    let (code, _, _) = velvet(&[
        "migrate",
        "--check",
        "--fail-on-visible",
        "-q",
        &path("sheen-textures.gltf"),
    ]);
    assert_eq!(code, 0);
    let (code, _, err) = velvet(&[
        "migrate",
        "--check",
        "--fail-on-visible",
        "--closer-budget",
        "0",
        "-q",
        &path("sheen-textures.gltf"),
    ]);
    assert_eq!(code, 1);
    assert_eq!(
        err,
        format!(
            "velvet: --check: {}: material 0 \"cloth\": visible (ꟻLIP 0.552 in the furnace, 0.414 under the light)\n",
            path("sheen-textures.gltf")
        )
    );
    // --fast still measures the verdict the gate reads.
    let (code, _, _) = velvet(&[
        "migrate",
        "--check",
        "--fail-on-visible",
        "--fast",
        "-q",
        &path("sheen-textures.gltf"),
    ]);
    assert_eq!(code, 1);
    // The velvet.toml key turns the gate on for the files below it.
    std::fs::write(dir.path().join("velvet.toml"), "fail-on-visible = true\n").unwrap();
    let (code, _, _) = velvet(&["migrate", "--check", "-q", &path("sheen-factors.gltf")]);
    assert_eq!(code, 0);
    let (code, _, _) = velvet(&[
        "migrate",
        "--check",
        "--closer-budget",
        "0",
        "-q",
        &path("sheen-textures.gltf"),
    ]);
    assert_eq!(code, 1);
    // The flag needs --check.
    let (code, _, _) = velvet(&[
        "migrate",
        "--fail-on-visible",
        "--dry-run",
        &path("sheen-factors.gltf"),
    ]);
    assert_eq!(code, 2);
}

#[test]
fn on_the_fixtures_the_default_is_never_visible_where_exact_is_close() {
    use velvet::migrate::verdict::Label;
    let labels = |options: Options| -> Vec<(String, usize, Label)> {
        let mut run = request(vec![fixtures()], Destination::None, options);
        run.dry_run = true;
        migrating::run(&run)
            .unwrap()
            .files
            .iter()
            .flat_map(|f| {
                f.detail
                    .materials
                    .iter()
                    // A draft sheen switched off is upgraded but shows nothing: no verdict.
                    .filter(|m| m.migrated() && m.verdict.is_some())
                    .map(|m| (stem(&f.input), m.index, m.verdict.unwrap().label))
            })
            .collect()
    };
    let default = labels(Options::default());
    let exact = labels(Options {
        exact: true,
        ..Options::default()
    });
    assert_eq!(default.len(), exact.len());
    let mut brought = Vec::new();
    for (d, e) in default.iter().zip(&exact) {
        assert_eq!((&d.0, d.1), (&e.0, e.1));
        assert!(
            !(d.2 == Label::Visible && e.2 < Label::Visible),
            "{} material {}: visible by default, {:?} with --exact",
            d.0,
            d.1,
            e.2
        );
        if e.2 == Label::Close && d.2 == Label::Close {
            brought.push(format!("{} {}", d.0, d.1));
        }
    }
    // The materials --exact brings to close are close by default too (the default takes its
    // plan for the three that would be visible), among the others close either way.
    // What stays visible by default is what no plan velvet offers brings closer.
    let visible: Vec<String> = default
        .iter()
        .filter(|d| d.2 == Label::Visible)
        .map(|d| format!("{} {}", d.0, d.1))
        .collect();
    assert_eq!(
        visible,
        ["fuzz-only 1", "fuzz-textures 0", "fuzz-textures 2"]
    );
    assert!(
        brought.contains(&"sheen-textures 0".to_string()),
        "{brought:?}"
    );
    assert!(brought.contains(&"legacy 0".to_string()), "{brought:?}");
    assert!(
        brought.contains(&"legacy-texcoord 0".to_string()),
        "{brought:?}"
    );
}
