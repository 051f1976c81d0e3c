//! Properties over random valid documents (proptest, 64 cases each so the suite stays fast):
//! sheen, fuzz, both, and legacy draft sheen materials, with and without textures, with and
//! without a clear coat, among unrelated JSON (unknown extensions, extras, numbers written in
//! every way JSON allows). Each property states what must hold for every such document:
//!
//! - migrate, then validate: no error (the input had none);
//! - migrate twice = migrate once (the second run writes the first's bytes);
//! - bake twice = bake once;
//! - migrate leaves every byte of the JSON it does not own as it was: with the sheen and fuzz
//!   objects and `extensionsUsed` set aside, the output's text equals the input's;
//! - a migration's edits spliced part by part (each part read back alone) give the text the
//!   whole edited document gives;
//! - under every migrate option, each number the plan sets (what the dry run, `--check` and the
//!   reports show) is the number the written file holds, and the preview's "as migrated" layer
//!   is the layer the written file holds;
//! - under every migrate option, the verdict migrate reports on each material is the verdict
//!   the preview of the same file labels and ranks its sheet by;
//! - the data rules read any accessor layout over any bytes (every component type and type,
//!   offsets, strides, sparse substitutions in and out of range) without a panic, and
//!   `--no-data` leaves out their findings and nothing else.

use base64::Engine;
use proptest::prelude::*;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use velvet::command::bake;
use velvet::command::migrate::{self as migrating, FileOutcome};
use velvet::diagnostics::{Settings, Severity};
use velvet::migrate::{self, Options};
use velvet::output::paths::Destination;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

const CASES: u32 = 64;

/// A 2×2 PNG as a data: URI; with `alpha`, RGBA (a roughness texture reads alpha).
fn png_uri(alpha: bool, seed: u8) -> String {
    let channels = if alpha { 4 } else { 3 };
    let data: Vec<u8> = (0..4 * channels)
        .map(|i| (i as u8).wrapping_mul(53).wrapping_add(seed))
        .collect();
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &data,
        2,
        2,
        if alpha {
            image::ExtendedColorType::Rgba8
        } else {
            image::ExtendedColorType::Rgb8
        },
    )
    .unwrap();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

/// A number in [0, 1]: the bounds exactly, or anything between.
fn unit() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), Just(1.0), Just(0.5), 0.0..=1.0f64]
}

fn colour() -> impl Strategy<Value = [f64; 3]> {
    [unit(), unit(), unit()]
}

/// A textureInfo for texture 0 (RGBA) or 1 (RGB); roughness slots need alpha, so take 0.
fn texture_info(alpha_needed: bool) -> impl Strategy<Value = Value> {
    let index = if alpha_needed {
        Just(0u64).boxed()
    } else {
        (0u64..=1).boxed()
    };
    (index, any::<bool>()).prop_map(|(index, transform)| {
        let mut info = json!({"index": index});
        if transform {
            info["extensions"] =
                json!({"KHR_texture_transform": {"scale": [2.0, 2.0], "offset": [0.5, 0.0]}});
        }
        info
    })
}

fn maybe(strategy: impl Strategy<Value = Value>) -> impl Strategy<Value = Option<Value>> {
    prop::option::of(strategy)
}

/// JSON that velvet does not own: numbers in odd spellings, strings, nested objects.
fn unrelated() -> impl Strategy<Value = Value> {
    let number = prop_oneof![
        Just("1e-7"),
        Just("0.30000000000000004"),
        Just("12345678901234567890123"),
        Just("-0.0"),
        Just("1E+2"),
        Just("0.50"),
        Just("7"),
    ]
    .prop_map(|text| serde_json::from_str::<Value>(text).unwrap());
    let leaf = prop_oneof![
        number,
        "[a-z ]{0,8}".prop_map(Value::String),
        any::<bool>().prop_map(Value::Bool),
        Just(Value::Null),
    ];
    leaf.prop_recursive(3, 12, 3, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..3).prop_map(Value::Array),
            prop::collection::vec(("[a-z]{1,6}", inner), 0..3)
                .prop_map(|entries| Value::Object(entries.into_iter().collect::<Map<_, _>>())),
        ]
    })
}

#[derive(Debug, Clone)]
enum Layers {
    Sheen,
    Fuzz,
    Both,
    Legacy,
}

fn sheen_object() -> impl Strategy<Value = Value> {
    (
        colour(),
        unit(),
        maybe(texture_info(false)),
        maybe(texture_info(true)),
    )
        .prop_map(|(c, r, color_tex, rough_tex)| {
            let mut sheen = json!({"sheenColorFactor": c, "sheenRoughnessFactor": r});
            if let Some(t) = color_tex {
                sheen["sheenColorTexture"] = t;
            }
            if let Some(t) = rough_tex {
                sheen["sheenRoughnessTexture"] = t;
            }
            sheen
        })
}

fn fuzz_object() -> impl Strategy<Value = Value> {
    (
        unit(),
        colour(),
        prop::option::of(unit()),
        maybe(texture_info(false)),
        maybe(texture_info(false)),
        maybe(texture_info(true)),
    )
        .prop_map(|(f, c, r, color_tex, fuzz_tex, rough_tex)| {
            let mut fuzz = json!({"fuzzFactor": f, "fuzzColorFactor": c});
            if let Some(r) = r {
                fuzz["fuzzRoughnessFactor"] = json!(r);
            }
            for (key, t) in [
                ("fuzzColorTexture", color_tex),
                ("fuzzTexture", fuzz_tex),
                ("fuzzRoughnessTexture", rough_tex),
            ] {
                if let Some(t) = t {
                    fuzz[key] = t;
                }
            }
            fuzz
        })
}

/// The pre-ratification draft: sheenFactor, sheenColor, sheenTexture; roughness from the
/// material's own.
fn legacy_object() -> impl Strategy<Value = Value> {
    (unit(), colour(), maybe(texture_info(false))).prop_map(|(f, c, t)| {
        let mut sheen = json!({"sheenFactor": f, "sheenColor": c});
        if let Some(t) = t {
            sheen["sheenTexture"] = t;
        }
        sheen
    })
}

fn material() -> impl Strategy<Value = Value> {
    let layers = prop_oneof![
        Just(Layers::Sheen),
        Just(Layers::Fuzz),
        Just(Layers::Both),
        Just(Layers::Legacy),
    ];
    (
        layers,
        sheen_object(),
        fuzz_object(),
        legacy_object(),
        prop::option::of(unit()),
        unit(),
        any::<bool>(),
        maybe(unrelated()),
        maybe(unrelated()),
    )
        .prop_map(
            |(layers, sheen, fuzz, legacy, clearcoat, roughness, mr_texture, extras, unknown)| {
                let mut extensions = Map::new();
                match layers {
                    Layers::Sheen => {
                        extensions.insert("KHR_materials_sheen".into(), sheen);
                    }
                    Layers::Fuzz => {
                        extensions.insert("KHR_materials_fuzz".into(), fuzz);
                    }
                    Layers::Both => {
                        extensions.insert("KHR_materials_fuzz".into(), fuzz);
                        extensions.insert("KHR_materials_sheen".into(), sheen);
                    }
                    Layers::Legacy => {
                        extensions.insert("KHR_materials_sheen".into(), legacy);
                    }
                }
                if let Some(c) = clearcoat {
                    extensions.insert(
                        "KHR_materials_clearcoat".into(),
                        json!({"clearcoatFactor": c}),
                    );
                }
                if let Some(u) = unknown {
                    extensions.insert("EXT_unknown_to_velvet".into(), json!({ "data": u }));
                }
                let mut pbr = json!({"roughnessFactor": roughness});
                if mr_texture {
                    pbr["metallicRoughnessTexture"] = json!({"index": 1});
                }
                let mut m = json!({"pbrMetallicRoughness": pbr, "extensions": extensions});
                if let Some(e) = extras {
                    m["extras"] = e;
                }
                m
            },
        )
}

fn document() -> impl Strategy<Value = Value> {
    (
        prop::collection::vec(material(), 1..4),
        maybe(unrelated()),
        any::<bool>(),
    )
        .prop_map(|(materials, extras, minified)| {
            let mut used = vec![
                "KHR_materials_sheen",
                "KHR_materials_fuzz",
                "KHR_texture_transform",
            ];
            if materials
                .iter()
                .any(|m| m["extensions"].get("KHR_materials_clearcoat").is_some())
            {
                used.push("KHR_materials_clearcoat");
            }
            if materials
                .iter()
                .any(|m| m["extensions"].get("EXT_unknown_to_velvet").is_some())
            {
                used.push("EXT_unknown_to_velvet");
            }
            let mut doc = json!({
                "asset": {"version": "2.0", "generator": "velvet properties"},
                "extensionsUsed": used,
                "materials": materials,
                "textures": [{"source": 0}, {"source": 1}],
                "images": [{"uri": png_uri(true, 7)}, {"uri": png_uri(false, 91)}],
                "scene": 0,
                "scenes": [{}],
            });
            if let Some(e) = extras {
                doc["extras"] = e;
            }
            // The style flag travels in the document's text; see `text`.
            doc["asset"]["minified"] = Value::Bool(minified);
            doc
        })
}

/// The document's text, minified or pretty as the generator chose.
fn text(doc: &Value) -> String {
    let mut doc = doc.clone();
    let minified = doc["asset"]
        .as_object_mut()
        .unwrap()
        .shift_remove("minified")
        .is_some_and(|m| m == true);
    if minified {
        doc.to_string()
    } else {
        serde_json::to_string_pretty(&doc).unwrap() + "\n"
    }
}

fn validation_errors(path: &Path) -> Vec<String> {
    let report = Validator::new(Schemas::builtin(), Settings::default()).validate_file(path);
    report
        .findings
        .iter()
        .filter(|f| f.diagnostic.severity == Severity::Error)
        .map(|f| {
            format!(
                "{} {}: {}",
                f.diagnostic.code, f.diagnostic.pointer, f.diagnostic.message
            )
        })
        .collect()
}

fn migrate_file(input: &Path, output: &Path) -> FileOutcome {
    let report = migrating::run(&migrating::Request {
        inputs: vec![input.to_path_buf()],
        destination: Destination::File(output.to_path_buf()),
        options: Options::default(),
        dry_run: false,
        progress: false,
    })
    .unwrap();
    report.files.into_iter().next().unwrap().outcome
}

fn bake_file(input: &Path, output: &Path) -> bake::Outcome {
    let results = bake::run(&bake::Request {
        inputs: vec![input.to_path_buf()],
        destination: Destination::File(output.to_path_buf()),
        dry_run: false,
        options: bake::Options::default(),
        progress: false,
    })
    .unwrap();
    results.into_iter().next().unwrap().outcome
}

/// A folder holding the document as `in.gltf`.
fn written(doc: &Value) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(&input, text(doc)).unwrap();
    (dir, input)
}

/// The document's text with what migrate owns set aside: the sheen and fuzz objects of every
/// material, and `extensionsUsed`.
fn unrelated_text(bytes: &[u8]) -> String {
    let mut doc: Value = serde_json::from_slice(bytes).unwrap();
    let root = doc.as_object_mut().unwrap();
    root.shift_remove("extensionsUsed");
    for m in root
        .get_mut("materials")
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
    {
        if let Some(ext) = m.get_mut("extensions").and_then(Value::as_object_mut) {
            ext.shift_remove("KHR_materials_sheen");
            ext.shift_remove("KHR_materials_fuzz");
        }
    }
    // Serialised, not compared as values: key order is part of what must be kept.
    doc.to_string()
}

/// `after` without the textures and images migrate appended for the textures it baked (the
/// mapped roughness, the fallback's colour × intensity): those are migrate's, like the layers.
fn baked_entries_removed(before: &[u8], after: &[u8]) -> Vec<u8> {
    let before: Value = serde_json::from_slice(before).unwrap();
    let mut after: Value = serde_json::from_slice(after).unwrap();
    let root = after.as_object_mut().unwrap();
    for key in ["textures", "images"] {
        match before.get(key).and_then(Value::as_array).map(Vec::len) {
            Some(n) => {
                if let Some(list) = root.get_mut(key).and_then(Value::as_array_mut) {
                    list.truncate(n);
                }
            }
            None => {
                root.shift_remove(key);
            }
        }
    }
    serde_json::to_vec(&after).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn migrated_documents_validate_without_error(doc in document()) {
        let (dir, input) = written(&doc);
        prop_assert_eq!(validation_errors(&input), Vec::<String>::new(), "the generated input is valid");
        let output = dir.path().join("out.gltf");
        let outcome = migrate_file(&input, &output);
        prop_assert!(
            matches!(outcome, FileOutcome::Changed | FileOutcome::Copied),
            "{:?}", outcome
        );
        prop_assert_eq!(validation_errors(&output), Vec::<String>::new());
    }

    #[test]
    fn migrating_twice_is_migrating_once(doc in document()) {
        let (dir, input) = written(&doc);
        let once = dir.path().join("once.gltf");
        let twice = dir.path().join("twice.gltf");
        migrate_file(&input, &once);
        let outcome = migrate_file(&once, &twice);
        prop_assert_eq!(outcome, FileOutcome::Copied);
        prop_assert!(std::fs::read(&once).unwrap() == std::fs::read(&twice).unwrap());
    }

    #[test]
    fn baking_twice_is_baking_once(doc in document()) {
        let (dir, input) = written(&doc);
        let once = dir.path().join("once.gltf");
        let twice = dir.path().join("twice.gltf");
        let first = bake_file(&input, &once);
        prop_assert!(matches!(first, bake::Outcome::Changed | bake::Outcome::Copied), "{:?}", first);
        prop_assert_eq!(bake_file(&once, &twice), bake::Outcome::Copied);
        prop_assert!(std::fs::read(&once).unwrap() == std::fs::read(&twice).unwrap());
        prop_assert_eq!(validation_errors(&twice), Vec::<String>::new());
    }

    #[test]
    fn migrate_keeps_the_json_it_does_not_own(doc in document()) {
        let (dir, input) = written(&doc);
        let output = dir.path().join("out.gltf");
        migrate_file(&input, &output);
        let before = std::fs::read(&input).unwrap();
        let after = baked_entries_removed(&before, &std::fs::read(&output).unwrap());
        prop_assert_eq!(unrelated_text(&before), unrelated_text(&after));
        // What migrate owns loads again too: the output is a document velvet reads.
        prop_assert!(velvet::asset::load(&output).asset.is_some());
    }

    #[test]
    fn edits_spliced_part_by_part_give_the_text_of_the_whole_edited_document(doc in document()) {
        let text = text(&doc);
        let loaded = velvet::asset::load_bytes(Path::new("doc.gltf"), text.as_bytes());
        let asset = loaded.asset.expect("a generated document loads");
        let plan = migrate::plan::plan_document(&asset, &Options::default());
        let edits: Vec<_> = plan.edits().cloned().collect();
        let spliced = velvet::edit::splice::splice_edits(&text, asset.root(), &edits)
            .unwrap()
            .map(|(out, _)| out.to_text());
        let mut whole = asset.root().to_value();
        velvet::edit::apply(&mut whole, &edits).unwrap();
        let rewritten = velvet::edit::splice::rewrite(&text, asset.root(), &whole);
        prop_assert!(spliced.is_some());
        prop_assert_eq!(spliced, rewritten);
    }
}

/// The migrate options a property is held to: the default, `--exact`, `--roughness-budget
/// exact`, `--fast` and `--roughness identity`.
fn migrate_options(which: usize) -> Options {
    match which {
        0 => Options::default(),
        1 => Options {
            exact: true,
            ..Options::default()
        },
        2 => Options {
            budget: migrate::budget::Budget::Exact,
            ..Options::default()
        },
        3 => Options {
            fast: true,
            ..Options::default()
        },
        _ => Options {
            roughness: migrate::roughness::RoughnessMapping::Identity,
            ..Options::default()
        },
    }
}

/// Every number below `value` (arrays of numbers whole), each with its pointer under `at`.
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

fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn the_plan_and_the_preview_show_the_numbers_the_written_file_holds(
        doc in document(),
        which in 0..5usize,
    ) {
        let options = migrate_options(which);
        let (dir, input) = written(&doc);
        let output = dir.path().join("out.gltf");
        let report = migrating::run(&migrating::Request {
            inputs: vec![input.clone()],
            destination: Destination::File(output.clone()),
            options: options.clone(),
            dry_run: false,
            progress: false,
        })
        .unwrap();
        let result = report.files.into_iter().next().unwrap();
        prop_assert!(
            matches!(result.outcome, FileOutcome::Changed | FileOutcome::Copied),
            "{:?}", result.outcome
        );
        let file: Value = serde_json::from_slice(&std::fs::read(&output).unwrap()).unwrap();
        for material in &result.detail.materials {
            for edit in &material.edits {
                let velvet::edit::Edit::Set { pointer, value } = edit else { continue };
                let mut planned = Vec::new();
                numbers_below(pointer, &value.to_value(), &mut planned);
                for (at, number) in planned {
                    // A textureInfo's index names the texture before the bake; the bake line
                    // of the plan says which texture it becomes.
                    if at.ends_with("Texture/index") {
                        continue;
                    }
                    prop_assert_eq!(file.pointer(&at), Some(&number), "option set {}: {}", which, at);
                }
            }
        }
        // The plan as migrate's spine completes it: judged, with the plans the default takes
        // for materials that would migrate visibly.
        let asset = velvet::asset::load(&input).asset.unwrap();
        let mut plan = migrate::plan::plan_document(&asset, &options);
        for m in velvet::preview::verdict::judge(&asset, &mut plan, &options) {
            let extensions = &file["materials"][m.index]["extensions"];
            match m.kind {
                velvet::preview::material::Kind::SheenToFuzz => {
                    let fuzz = &extensions["KHR_materials_fuzz"];
                    let written = m.factors.written_fuzz.unwrap();
                    prop_assert_eq!(Some(written.weight), fuzz["fuzzFactor"].as_f64());
                    prop_assert_eq!(Some(written.roughness), fuzz["fuzzRoughnessFactor"].as_f64());
                    prop_assert_eq!(written.color.to_vec(), numbers(&fuzz["fuzzColorFactor"]));
                }
                velvet::preview::material::Kind::FuzzFallback => {
                    let sheen = &extensions["KHR_materials_sheen"];
                    match m.factors.written_sheen {
                        Some(written) => {
                            prop_assert_eq!(Some(written.roughness), sheen["sheenRoughnessFactor"].as_f64());
                            prop_assert_eq!(written.color.to_vec(), numbers(&sheen["sheenColorFactor"]));
                        }
                        // A black fuzz gets no fallback (migrate skips it, and the preview
                        // shows none): the file has none either.
                        None => prop_assert!(sheen.is_null(), "{}", sheen),
                    }
                }
                velvet::preview::material::Kind::FuzzWithSheen => {}
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES))]

    #[test]
    fn migrate_reports_the_verdict_the_preview_labels_its_sheet_with(
        doc in document(),
        which in 0..5usize,
    ) {
        let options = migrate_options(which);
        let (_dir, input) = written(&doc);
        let report = migrating::run(&migrating::Request {
            inputs: vec![input.clone()],
            destination: Destination::None,
            options: options.clone(),
            dry_run: true,
            progress: false,
        })
        .unwrap();
        let result = report.files.into_iter().next().unwrap();
        let preview = velvet::preview::plan(&[input], &options);
        prop_assert!(preview.failures.is_empty(), "{:?}", preview.failures);
        for entry in &preview.entries {
            let planned = result
                .detail
                .materials
                .iter()
                .find(|m| m.index == entry.index)
                .and_then(|m| m.verdict);
            prop_assert_eq!(
                planned,
                Some(preview.sheets[entry.sheet].verdict),
                "option set {}, material {}", which, entry.index
            );
        }
        // Every material migrate measured is on a sheet.
        let measured = result.detail.materials.iter().filter(|m| m.verdict.is_some()).count();
        prop_assert_eq!(measured, preview.entries.len());
    }
}

/// Found by the properties above: glTF allows `extras` of any JSON type (an object is only
/// recommended), and the core structure check refused arrays and scalars.
#[test]
fn extras_of_every_json_type_are_valid() {
    for extras in [
        json!([1, "a"]),
        json!(7),
        json!("text"),
        json!(null),
        json!({"a": []}),
    ] {
        let doc = json!({
            "asset": {"version": "2.0", "extras": extras},
            "materials": [{"extras": extras}],
            "extras": extras,
        });
        let (_dir, input) = written(&doc);
        assert_eq!(validation_errors(&input), Vec::<String>::new(), "{extras}");
    }
}

/// An accessor over random bytes: any component type and type, maybe normalized, at any offset
/// and stride of a view that may or may not hold it, maybe with sparse substitutions whose
/// indices may be out of order or out of range, and maybe used as every kind of vertex data.
fn data_document() -> impl Strategy<Value = Value> {
    let component = prop::sample::select(vec![5120u64, 5121, 5122, 5123, 5125, 5126, 5124]);
    let kind = prop::sample::select(vec![
        "SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4",
    ]);
    (
        component,
        kind,
        1u64..40,
        0u64..24,
        prop::option::of(prop::sample::select(vec![4u64, 8, 12, 16, 20, 64])),
        any::<bool>(),
        prop::option::of((1u64..6, prop::sample::select(vec![5121u64, 5123, 5125]))),
        prop::collection::vec(any::<u8>(), 0..2048),
        any::<bool>(),
    )
        .prop_map(
            |(component, kind, count, offset, stride, normalized, sparse, bytes, bounds)| {
                let len = bytes.len() as u64;
                let mut view = json!({"buffer": 0, "byteLength": len});
                if let Some(stride) = stride {
                    view["byteStride"] = json!(stride);
                }
                let mut accessor = json!({"bufferView": 0, "byteOffset": offset,
                    "componentType": component, "count": count, "type": kind,
                    "normalized": normalized});
                if bounds {
                    accessor["min"] = json!([0]);
                    accessor["max"] = json!([1]);
                }
                if let Some((n, index_type)) = sparse {
                    accessor["sparse"] = json!({"count": n,
                        "indices": {"bufferView": 1, "componentType": index_type},
                        "values": {"bufferView": 1, "byteOffset": 4}});
                }
                let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
                let doc = json!({
                    "asset": {"version": "2.0"},
                    "buffers": [{"byteLength": len,
                        "uri": format!("data:application/octet-stream;base64,{data}")}],
                    "bufferViews": [view, {"buffer": 0, "byteLength": len}],
                    "accessors": [accessor],
                    "nodes": [{"mesh": 0, "skin": 0}, {}],
                    "skins": [{"joints": [1], "inverseBindMatrices": 0}],
                    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 0,
                        "TANGENT": 0, "COLOR_0": 0, "JOINTS_0": 0, "WEIGHTS_0": 0}, "indices": 0}]}],
                    "animations": [{"samplers": [{"input": 0, "output": 0}],
                        "channels": [{"sampler": 0, "target": {"node": 1, "path": "rotation"}}]}],
                });
                doc
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(CASES * 2))]

    /// The data rules read any accessor over any bytes without a panic, and `--no-data` leaves
    /// every one of their findings out and nothing else.
    #[test]
    fn any_accessor_over_any_bytes_is_read_without_a_panic(doc in data_document()) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("data.gltf");
        std::fs::write(&path, doc.to_string()).unwrap();
        let with = Validator::new(Schemas::builtin(), Settings::default()).validate_file(&path);
        let without = Validator::new(
            Schemas::builtin(),
            Settings { skip_data: true, ..Settings::default() },
        )
        .validate_file(&path);
        let data_code = |code: &str| {
            code.starts_with("ACCESSOR_")
                && !matches!(
                    code,
                    "ACCESSOR_NORMALIZED_INVALID"
                        | "ACCESSOR_MATRIX_ALIGNMENT"
                        | "ACCESSOR_SMALL_BYTESTRIDE"
                        | "ACCESSOR_OFFSET_ALIGNMENT"
                        | "ACCESSOR_TOTAL_OFFSET_ALIGNMENT"
                        | "ACCESSOR_TOO_LONG"
                        | "ACCESSOR_SPARSE_COUNT_OUT_OF_RANGE"
                        | "ACCESSOR_USAGE_OVERRIDE"
                )
        };
        let kept: Vec<String> = with
            .findings
            .iter()
            .map(|f| f.diagnostic.code.to_string())
            .filter(|c| !data_code(c))
            .collect();
        let without: Vec<String> = without.findings.iter().map(|f| f.diagnostic.code.to_string()).collect();
        prop_assert!(without.iter().all(|c| !data_code(c)), "{without:?}");
        prop_assert_eq!(kept, without);
    }
}
