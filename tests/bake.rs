//! `velvet bake` end to end: generated assets (.gltf with image files, GLB with images in the
//! BIN chunk) are baked, and the outputs are checked by their JSON, by decoded pixels against
//! independently computed values, and by loading and validating them again.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};
use velvet::asset;
use velvet::bake::codec::{self, EncodeOptions, OutputFormat};
use velvet::bake::plan::PlanOptions;
use velvet::bake::{Layout, Pixels, Samples};
use velvet::command::bake::{self as command, Options, Outcome, Request};
use velvet::output::paths::Destination;
use velvet::output::UsageError;

// ---------------------------------------------------------------------------------------------
// Helpers

fn srgb_decode(v: f64) -> f64 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn srgb_encode(l: f64) -> f64 {
    if l <= 0.0031308 {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The exact result for an 8-bit code scaled by `k` in sRGB.
fn colour(code: u8, k: f64) -> u8 {
    let l = (k * srgb_decode(f64::from(code) / 255.0)).clamp(0.0, 1.0);
    (srgb_encode(l) * 255.0).round_ties_even() as u8
}

/// The exact result for an 8-bit code scaled by `k` linearly.
fn linear(code: u8, k: f64) -> u8 {
    ((k * f64::from(code) / 255.0).clamp(0.0, 1.0) * 255.0).round_ties_even() as u8
}

/// A 4×4 RGBA image whose codes differ per texel and channel.
fn rgba(seed: u8) -> Vec<u8> {
    (0..64u32)
        .map(|i| (i * 37 + u32::from(seed) * 11) as u8)
        .collect()
}

fn png(layout: Layout, codes: Vec<u8>) -> Vec<u8> {
    let n = codes.len() / layout.channels();
    let side = (n as f64).sqrt() as u32;
    let p = Pixels::new(side, side, layout, Samples::U8(codes)).unwrap();
    codec::encode(&p, OutputFormat::Png, EncodeOptions::default()).unwrap()
}

/// The one file in `dir` named `<stem>.<hash>.<ext>`, whose hash is that of its bytes (new
/// image names follow from their content).
#[track_caller]
fn named(dir: &Path, stem: &str, ext: &str) -> String {
    let found: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| {
            n.strip_prefix(stem)
                .and_then(|rest| rest.strip_prefix('.'))
                .and_then(|rest| rest.strip_suffix(ext))
                .and_then(|rest| rest.strip_suffix('.'))
                .is_some_and(|hash| hash.len() == 12 && hash.bytes().all(|b| b.is_ascii_hexdigit()))
        })
        .collect();
    assert_eq!(
        found.len(),
        1,
        "{stem}.*.{ext} in {}: {found:?}",
        dir.display()
    );
    let bytes = std::fs::read(dir.join(&found[0])).unwrap();
    assert_eq!(
        found[0],
        format!("{stem}.{}.{ext}", velvet::bake::apply::content_hash(&bytes))
    );
    found.into_iter().next().unwrap()
}

fn decode(bytes: &[u8]) -> Pixels {
    codec::decode(bytes).unwrap().0
}

fn codes8(p: &Pixels) -> Vec<u8> {
    match p.samples() {
        Samples::U8(v) => v.clone(),
        Samples::U16(_) => panic!("expected 8-bit codes"),
    }
}

fn write_json(path: &Path, json: &Value) {
    std::fs::write(path, serde_json::to_vec_pretty(json).unwrap()).unwrap();
}

fn read_json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Builds a GLB whose images (encoded bytes) are bufferViews in the BIN chunk, each starting
/// 4-byte aligned; `json`'s `images` entries get their bufferView and mimeType.
fn glb(mut json: Value, images: &[Vec<u8>]) -> Vec<u8> {
    let mut bin = Vec::new();
    let mut views = Vec::new();
    for (i, bytes) in images.iter().enumerate() {
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend_from_slice(bytes);
        json["images"][i]["bufferView"] = json!(i);
        json["images"][i]["mimeType"] = json!("image/png");
    }
    json["bufferViews"] = Value::Array(views);
    json["buffers"] = json!([{"byteLength": bin.len()}]);
    asset::glb::join(&serde_json::to_vec(&json).unwrap(), Some(&bin))
}

fn request(inputs: Vec<PathBuf>, destination: Destination, options: Options) -> Request {
    Request {
        inputs,
        destination,
        dry_run: false,
        options,
        progress: false,
    }
}

fn run_one(input: &Path, output: &Path, options: Options) -> command::FileResult {
    let results = command::run(&request(
        vec![input.to_path_buf()],
        Destination::File(output.to_path_buf()),
        options,
    ))
    .unwrap();
    assert_eq!(results.len(), 1);
    results.into_iter().next().unwrap()
}

/// Validation errors of a file (none expected after a bake of a valid input).
fn validation_errors(path: &Path) -> Vec<String> {
    let validator = velvet::validate::Validator::new(
        velvet::rules::schema::Schemas::builtin(),
        velvet::diagnostics::Settings::default(),
    );
    let report = validator.validate_file(path);
    report
        .findings
        .iter()
        .filter(|f| f.diagnostic.severity == velvet::diagnostics::Severity::Error)
        .map(|f| {
            format!(
                "{} {}: {}",
                f.diagnostic.code, f.diagnostic.pointer, f.diagnostic.message
            )
        })
        .collect()
}

fn asset_json(materials: Value, textures: Value, images: Value) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": materials,
        "textures": textures,
        "images": images
    })
}

// ---------------------------------------------------------------------------------------------
// .gltf

#[test]
fn gltf_colour_and_roughness_of_one_image_are_baked_once_into_one_file() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("fabric.png"), png(Layout::Rgba, rgba(1))).unwrap();
    let doc = asset_json(
        json!([{"name": "velvet", "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.25, 1.0],
            "sheenColorTexture": {"index": 0, "texCoord": 1,
                "extensions": {"KHR_texture_transform": {"scale": [2.0, 2.0]}}},
            "sheenRoughnessFactor": 0.6,
            "sheenRoughnessTexture": {"index": 0}
        }}}]),
        json!([{"sampler": 0, "source": 0, "name": "fabricTex"}]),
        json!([{"uri": "fabric.png", "name": "fabric"}]),
    );
    let mut doc = doc;
    doc["samplers"] = json!([{"magFilter": 9729}]);
    doc["extensionsUsed"] = json!(["KHR_materials_sheen", "KHR_texture_transform"]);
    write_json(&input, &doc);
    let before = std::fs::read(&input).unwrap();
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let output = out_dir.join("baked.gltf");
    let result = run_one(&input, &output, Options::default());
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    assert_eq!(
        std::fs::read(&input).unwrap(),
        before,
        "the input is untouched"
    );

    let out = read_json(&output);
    assert_eq!(
        out["materials"][0]["extensions"]["KHR_materials_sheen"],
        json!({
            "sheenColorFactor": [1.0, 1.0, 1.0],
            "sheenColorTexture": {"index": 0, "texCoord": 1,
                "extensions": {"KHR_texture_transform": {"scale": [2.0, 2.0]}}},
            "sheenRoughnessFactor": 1.0,
            "sheenRoughnessTexture": {"index": 0}
        })
    );
    assert_eq!(
        out["textures"],
        json!([{"sampler": 0, "source": 0, "name": "fabricTex"}])
    );
    assert_eq!(
        out["images"],
        json!([{"name": "fabric.sheenColor.sheenRoughness", "uri": named(&out_dir, "fabric.sheenColor.sheenRoughness", "png")}])
    );
    assert_eq!(result.detail.dropped_images, vec![0]);

    let baked = decode(
        &std::fs::read(out_dir.join(named(&out_dir, "fabric.sheenColor.sheenRoughness", "png")))
            .unwrap(),
    );
    assert_eq!(
        (baked.width(), baked.height(), baked.layout()),
        (4, 4, Layout::Rgba)
    );
    let source = rgba(1);
    let expected: Vec<u8> = source
        .chunks(4)
        .flat_map(|p| {
            [
                colour(p[0], 0.5),
                colour(p[1], 0.25),
                p[2],
                linear(p[3], 0.6),
            ]
        })
        .collect();
    assert_eq!(codes8(&baked), expected);
    assert_eq!(validation_errors(&output), Vec::<String>::new());
}

#[test]
fn a_gltf_written_to_another_folder_keeps_its_other_resources_reachable() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("base.png"), png(Layout::Rgb, vec![9; 48])).unwrap();
    std::fs::write(
        dir.path().join("sheen.png"),
        png(Layout::Rgb, rgba(2)[..48].to_vec()),
    )
    .unwrap();
    write_json(
        &input,
        &asset_json(
            json!([{
                "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                "extensions": {"KHR_materials_sheen": {
                    "sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 1}}}
            }]),
            json!([{"source": 0}, {"source": 1}]),
            json!([{"uri": "base.png"}, {"uri": "sheen.png"}]),
        ),
    );
    let output = dir.path().join("deeper").join("out.gltf");
    let result = run_one(&input, &output, Options::default());
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    let out = read_json(&output);
    assert_eq!(
        out["images"],
        json!([{"uri": "base.png"}, {"name": "sheen.sheenColor", "uri": named(&dir.path().join("deeper"), "sheen.sheenColor", "png")}])
    );
    assert_eq!(out["textures"], json!([{"source": 0}, {"source": 1}]));
    assert_eq!(validation_errors(&output), Vec::<String>::new());
    let loaded = asset::load(&output).asset.unwrap();
    let baked = decode(&loaded.image_bytes(1).unwrap());
    let expected: Vec<u8> = rgba(2)[..48].iter().map(|&c| colour(c, 0.5)).collect();
    assert_eq!(codes8(&baked), expected);
    // The base colour image is copied beside the output (the output is self-contained), and
    // the replaced sheen source, which nothing reads any more, is not.
    let base = std::fs::read(output.parent().unwrap().join("base.png")).unwrap();
    assert_eq!(decode(&base).layout(), Layout::Rgb);
    assert!(!output.parent().unwrap().join("sheen.png").exists());
}

#[test]
fn materials_sharing_a_combination_share_one_output_and_a_new_combination_gets_its_own() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("t.png"), png(Layout::Rgba, rgba(3))).unwrap();
    let sheen = |k: f64| {
        json!({"extensions": {"KHR_materials_sheen": {
        "sheenColorFactor": [k, k, k], "sheenColorTexture": {"index": 0}}}})
    };
    write_json(
        &input,
        &asset_json(
            json!([sheen(0.5), sheen(0.5), sheen(0.75)]),
            json!([{"source": 0}]),
            json!([{"uri": "t.png"}]),
        ),
    );
    let output = dir.path().join("out.gltf");
    let result = run_one(
        &input,
        &output,
        Options {
            embed: true,
            ..Options::default()
        },
    );
    assert_eq!(result.detail.outputs.len(), 2);
    let out = read_json(&output);
    let index = |m: usize| {
        out["materials"][m]["extensions"]["KHR_materials_sheen"]["sheenColorTexture"]["index"]
            .clone()
    };
    assert_eq!(index(0), index(1));
    assert_ne!(index(0), index(2));
    assert_eq!(out["textures"], json!([{"source": 0}, {"source": 1}]));
    let images = out["images"].as_array().unwrap();
    assert_eq!(
        images.len(),
        2,
        "the source image is dropped, two outputs stay"
    );
    assert!(images.iter().all(|i| i["uri"]
        .as_str()
        .unwrap()
        .starts_with("data:image/png;base64,")));
    let loaded = asset::load(&output).asset.unwrap();
    for (image, k) in [(0, 0.5), (1, 0.75)] {
        let baked = decode(&loaded.image_bytes(image).unwrap());
        let expected: Vec<u8> = rgba(3)
            .chunks(4)
            .flat_map(|p| [colour(p[0], k), colour(p[1], k), colour(p[2], k), p[3]])
            .collect();
        assert_eq!(codes8(&baked), expected, "image {image}");
    }
    let files: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(files.len(), 3, "embedding writes no image files: {files:?}");
    assert_eq!(validation_errors(&output), Vec::<String>::new());
}

#[test]
fn a_file_with_nothing_to_bake_is_copied_byte_for_byte_and_not_written_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("t.png"), png(Layout::Rgb, vec![1; 48])).unwrap();
    let text = "{\"asset\":{\"version\":\"2.0\"},\"materials\":[{\"extensions\":{\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,1.0,1e0],\"sheenColorTexture\":{\"index\":0}}}}],\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"t.png\"}],\"extensionsUsed\":[\"KHR_materials_sheen\"]}";
    std::fs::write(&input, text).unwrap();
    let output = dir.path().join("out.gltf");
    let result = run_one(&input, &output, Options::default());
    assert_eq!(result.outcome, Outcome::Copied);
    assert_eq!(std::fs::read_to_string(&output).unwrap(), text);
    let results = command::run(&request(
        vec![input.clone()],
        Destination::InPlace,
        Options::default(),
    ))
    .unwrap();
    assert_eq!(results[0].outcome, Outcome::Untouched);
    assert_eq!(std::fs::read_to_string(&input).unwrap(), text);
}

// ---------------------------------------------------------------------------------------------
// GLB

#[test]
fn glb_images_go_to_aligned_buffer_views_and_a_dropped_source_leaves_the_bin() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.glb");
    let base = png(Layout::Rgb, vec![200; 48]);
    let sheen = png(Layout::Rgba, rgba(4));
    let json = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_fuzz"],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
             "extensions": {
                "KHR_materials_sheen": {"sheenColorFactor": [0.8, 0.6, 0.4], "sheenColorTexture": {"index": 1}},
                "KHR_materials_fuzz": {"fuzzFactor": 0.5, "fuzzTexture": {"index": 0},
                                       "fuzzRoughnessFactor": 0.3, "fuzzRoughnessTexture": {"index": 1}}
             }}
        ],
        "textures": [{"source": 0}, {"source": 1}],
        "images": [{"name": "base"}, {"name": "sheen"}]
    });
    std::fs::write(&input, glb(json, &[base.clone(), sheen.clone()])).unwrap();
    let output = dir.path().join("out.glb");
    let result = run_one(
        &input,
        &output,
        Options {
            report: true,
            ..Options::default()
        },
    );
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    // Image 0 stays (base colour still reads it); image 1 only fed sheen and fuzz roughness.
    assert_eq!(result.detail.dropped_images, vec![1]);
    assert!(
        result.detail.dropped_bin_bytes >= sheen.len() - 3,
        "{}",
        result.detail.dropped_bin_bytes
    );
    assert!(result
        .detail
        .outputs
        .iter()
        .all(|o| o.max_error.is_some_and(|e| e <= 0.5)));
    let stored: Vec<(Option<usize>, &str)> = result
        .detail
        .outputs
        .iter()
        .map(|o| (o.image, o.stored.as_str()))
        .collect();
    assert_eq!(
        stored,
        vec![(Some(1), "bufferView 1"), (Some(2), "bufferView 2")]
    );

    let loaded = asset::load(&output);
    assert!(loaded.diagnostics.is_empty(), "{:?}", loaded.diagnostics);
    let asset = loaded.asset.unwrap();
    let out = asset.json();
    let ext = &out["materials"][0]["extensions"];
    // Texture 0 stays for the base colour; the old texture 1 is replaced by one new texture
    // (index 1) that sheen colour and fuzz roughness share, and fuzzTexture gets its own (2).
    assert_eq!(
        ext["KHR_materials_sheen"],
        json!({"sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": {"index": 1}})
    );
    assert_eq!(
        ext["KHR_materials_fuzz"],
        json!({"fuzzFactor": 1.0, "fuzzTexture": {"index": 2},
               "fuzzRoughnessFactor": 1.0, "fuzzRoughnessTexture": {"index": 1}})
    );
    assert_eq!(
        out["textures"],
        json!([{"source": 0}, {"source": 1}, {"source": 2}])
    );
    // Views start 4-byte aligned, and the BIN holds exactly the kept and new images.
    let views = out["bufferViews"].as_array().unwrap();
    assert_eq!(views.len(), 3);
    for v in views {
        assert_eq!(v["byteOffset"].as_u64().unwrap() % 4, 0, "{v}");
    }
    let bin = asset.bin.as_ref().unwrap();
    let declared = out["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert!(declared <= bin.len() && bin.len() - declared < 4);
    let last = &views[2];
    assert_eq!(
        last["byteOffset"].as_u64().unwrap() + last["byteLength"].as_u64().unwrap(),
        declared as u64,
        "nothing is left of the dropped image"
    );
    assert_eq!(asset.image_bytes(0).unwrap().as_ref(), base.as_slice());
    // fuzzTexture reads red of image 0 (RGB): red scaled, green and blue kept.
    let fuzz = decode(&asset.image_bytes(2).unwrap());
    assert_eq!(codes8(&fuzz), [linear(200, 0.5), 200, 200].repeat(16));
    // Sheen colour (RGB) and fuzz roughness (A) read image 1 in one material: one output.
    let both = decode(&asset.image_bytes(1).unwrap());
    let expected: Vec<u8> = rgba(4)
        .chunks(4)
        .flat_map(|p| {
            [
                colour(p[0], 0.8),
                colour(p[1], 0.6),
                colour(p[2], 0.4),
                linear(p[3], 0.3),
            ]
        })
        .collect();
    assert_eq!(codes8(&both), expected);
    assert_eq!(validation_errors(&output), Vec::<String>::new());
}

#[test]
fn glb_uniform_output_collapses_into_a_factor_and_its_source_is_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.glb");
    let json = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [{"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": 0.25}}}],
        "textures": [{"source": 0}],
        "images": [{}]
    });
    std::fs::write(&input, glb(json, &[png(Layout::Rgb, vec![255; 48])])).unwrap();
    let output = dir.path().join("out.glb");
    let options = Options {
        collapse_uniform: true,
        ..Options::default()
    };
    let result = run_one(&input, &output, options);
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    let asset = asset::load(&output).asset.unwrap();
    // Written rounded to six decimals (velvet's stated precision for the numbers it writes).
    let expected = (srgb_decode(f64::from(colour(255, 0.5)) / 255.0) * 1e6).round() / 1e6;
    assert_eq!(
        asset.json()["materials"][0]["extensions"]["KHR_materials_sheen"],
        json!({"sheenColorFactor": [expected, expected, expected], "sheenRoughnessFactor": 0.25})
    );
    for key in ["textures", "images", "bufferViews", "buffers"] {
        assert!(asset.json().get(key).is_none(), "{key} is gone");
    }
    assert!(asset.bin.is_none(), "an empty BIN chunk is not written");
    assert_eq!(validation_errors(&output), Vec::<String>::new());
}

// ---------------------------------------------------------------------------------------------
// Slots left alone, formats, planning notes

#[test]
fn out_of_range_factors_are_reported_and_baked_clamped_only_when_allowed() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("t.png"), png(Layout::Rgba, rgba(5))).unwrap();
    write_json(
        &input,
        &asset_json(
            json!([{"extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [1.0, 1.0, 1.0],
                "sheenRoughnessFactor": 2.0, "sheenRoughnessTexture": {"index": 0}}}}]),
            json!([{"source": 0}]),
            json!([{"uri": "t.png"}]),
        ),
    );
    let output = dir.path().join("out.gltf");
    let refused = run_one(&input, &output, Options::default());
    assert_eq!(refused.outcome, Outcome::Copied);
    assert!(refused
        .detail
        .notes
        .iter()
        .any(|n| n.message.contains("outside [0, 1]")
            && n.pointer == "/materials/0/extensions/KHR_materials_sheen/sheenRoughnessFactor"));
    let options = Options {
        plan: PlanOptions {
            allow_out_of_range: true,
        },
        ..Options::default()
    };
    let baked = run_one(&input, &output, options);
    assert_eq!(baked.outcome, Outcome::Changed);
    let alphas: Vec<u8> = rgba(5).chunks(4).map(|p| p[3]).collect();
    let clamped = alphas
        .iter()
        .filter(|&&a| 2.0 * f64::from(a) / 255.0 > 1.0)
        .count() as u64;
    assert!(clamped > 0);
    assert_eq!(baked.detail.outputs[0].clamped, clamped);
    let out = read_json(&output);
    let image =
        decode(&std::fs::read(dir.path().join(out["images"][0]["uri"].as_str().unwrap())).unwrap());
    let got: Vec<u8> = codes8(&image).chunks(4).map(|p| p[3]).collect();
    assert_eq!(
        got,
        alphas.iter().map(|&a| linear(a, 2.0)).collect::<Vec<_>>()
    );
}

#[test]
fn ktx2_textures_are_left_alone_with_a_warning_and_switched_off_layers_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    let mut ktx2 = b"\xabKTX 20\xbb\r\n\x1a\n".to_vec();
    ktx2.extend(4u32.to_le_bytes().repeat(4));
    ktx2.extend([0; 32]);
    std::fs::write(dir.path().join("t.ktx2"), ktx2).unwrap();
    std::fs::write(dir.path().join("t.png"), png(Layout::Rgb, vec![50; 48])).unwrap();
    let mut doc = asset_json(
        json!([
            {"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 0}}}},
            {"extensions": {"KHR_materials_sheen": {"sheenRoughnessFactor": 0.5, "sheenRoughnessTexture": {"index": 1}}}}
        ]),
        json!([{"extensions": {"KHR_texture_basisu": {"source": 0}}}, {"source": 1}]),
        json!([{"uri": "t.ktx2", "mimeType": "image/ktx2"}, {"uri": "t.png"}]),
    );
    doc["extensionsUsed"] = json!(["KHR_materials_sheen", "KHR_texture_basisu"]);
    doc["extensionsRequired"] = json!(["KHR_texture_basisu"]);
    write_json(&input, &doc);
    let results = command::run(&Request {
        dry_run: true,
        ..request(vec![input.clone()], Destination::None, Options::default())
    })
    .unwrap();
    let r = &results[0];
    assert_eq!(r.outcome, Outcome::Planned { changes: false });
    assert!(r.detail.slots.is_empty());
    let messages: Vec<(&str, &str)> = r
        .detail
        .notes
        .iter()
        .map(|n| (n.pointer.as_str(), n.message.as_str()))
        .collect();
    assert!(
        messages.iter().any(|(p, m)| *p
            == "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture"
            && m.contains("KTX2")),
        "{messages:?}"
    );
    assert!(
        messages
            .iter()
            .any(|(p, m)| *p == "/materials/1/extensions/KHR_materials_sheen"
                && m.contains("switched off")),
        "{messages:?}"
    );
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "a dry run writes nothing");
}

#[test]
fn jpeg_becomes_lossless_png_unless_kept_and_webp_stays_webp_with_its_fallback() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    let flat = Pixels::new(8, 8, Layout::Rgb, Samples::U8(vec![128; 192])).unwrap();
    let jpeg = codec::encode(&flat, OutputFormat::Jpeg, EncodeOptions::default()).unwrap();
    let webp_pixels = Pixels::new(4, 4, Layout::Rgba, Samples::U8(rgba(6))).unwrap();
    let webp = codec::encode(
        &webp_pixels,
        OutputFormat::WebpLossless,
        EncodeOptions::default(),
    )
    .unwrap();
    std::fs::write(dir.path().join("a.jpg"), &jpeg).unwrap();
    std::fs::write(dir.path().join("b.webp"), &webp).unwrap();
    std::fs::write(dir.path().join("b.png"), png(Layout::Rgba, rgba(6))).unwrap();
    let mut doc = asset_json(
        json!([{"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": 0.5, "sheenRoughnessTexture": {"index": 1}}}}]),
        json!([{"source": 0}, {"source": 2, "extensions": {"EXT_texture_webp": {"source": 1}}}]),
        json!([{"uri": "a.jpg"}, {"uri": "b.webp"}, {"uri": "b.png"}]),
    );
    doc["extensionsUsed"] = json!(["KHR_materials_sheen", "EXT_texture_webp"]);
    write_json(&input, &doc);
    let output = dir.path().join("out.gltf");
    let result = run_one(&input, &output, Options::default());
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    let out = read_json(&output);
    assert_eq!(
        out["images"],
        json!([
            {"name": "a.sheenColor", "uri": named(dir.path(), "a.sheenColor", "png")},
            {"name": "b.sheenRoughness", "uri": named(dir.path(), "b.sheenRoughness", "png")},
            {"name": "b.sheenRoughness", "uri": named(dir.path(), "b.sheenRoughness", "webp")}
        ])
    );
    assert_eq!(
        out["textures"],
        json!([{"source": 0}, {"source": 1, "extensions": {"EXT_texture_webp": {"source": 2}}}])
    );
    let read = |stem: &str, ext: &str| {
        codec::decode(&std::fs::read(dir.path().join(named(dir.path(), stem, ext))).unwrap())
            .unwrap()
    };
    let (webp_out, format) = read("b.sheenRoughness", "webp");
    assert_eq!(format, codec::ImageFormat::Webp);
    let expected: Vec<u8> = rgba(6)
        .chunks(4)
        .flat_map(|p| [p[0], p[1], p[2], linear(p[3], 0.5)])
        .collect();
    assert_eq!(codes8(&webp_out), expected, "lossless");
    assert_eq!(codes8(&read("b.sheenRoughness", "png").0), expected);
    let (png_out, format) = read("a.sheenColor", "png");
    assert_eq!(format, codec::ImageFormat::Png);
    let jpeg_codes = codes8(&decode(&jpeg));
    assert_eq!(
        codes8(&png_out),
        jpeg_codes
            .iter()
            .map(|&c| colour(c, 0.5))
            .collect::<Vec<_>>()
    );

    let kept = dir.path().join("kept.gltf");
    let options = Options {
        keep_format: true,
        ..Options::default()
    };
    run_one(&input, &kept, options);
    let out = read_json(&kept);
    assert_eq!(
        out["images"][0]["uri"],
        json!(named(dir.path(), "a.sheenColor", "jpg"))
    );
}

#[test]
fn sixteen_bit_images_are_baked_at_sixteen_bits() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    let codes: Vec<u16> = (0..16u32)
        .flat_map(|i| [(i * 4099) as u16, 65535 - (i * 4099) as u16])
        .collect();
    let p = Pixels::new(4, 4, Layout::GreyAlpha, Samples::U16(codes.clone())).unwrap();
    std::fs::write(
        dir.path().join("r.png"),
        codec::encode(&p, OutputFormat::Png, EncodeOptions::default()).unwrap(),
    )
    .unwrap();
    let mut doc = asset_json(
        json!([{"extensions": {"KHR_materials_fuzz": {"fuzzFactor": 0.5, "fuzzTexture": {"index": 0}}}}]),
        json!([{"source": 0}]),
        json!([{"uri": "r.png"}]),
    );
    doc["extensionsUsed"] = json!(["KHR_materials_fuzz"]);
    write_json(&input, &doc);
    let output = dir.path().join("out.gltf");
    let result = run_one(&input, &output, Options::default());
    assert_eq!(result.outcome, Outcome::Changed, "{result:?}");
    let out = read_json(&output);
    let baked =
        decode(&std::fs::read(dir.path().join(out["images"][0]["uri"].as_str().unwrap())).unwrap());
    assert_eq!(baked.layout(), Layout::GreyAlpha, "a grey image stays grey");
    let expected: Vec<u16> = codes
        .chunks(2)
        .flat_map(|p| {
            [
                ((0.5 * f64::from(p[0]) / 65535.0) * 65535.0).round_ties_even() as u16,
                p[1],
            ]
        })
        .collect();
    assert_eq!(baked.samples(), &Samples::U16(expected));
}

// ---------------------------------------------------------------------------------------------
// Requests and batches

#[test]
fn bad_requests_are_refused_before_anything_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.gltf");
    let b = dir.path().join("b.gltf");
    let r = |inputs: Vec<PathBuf>, destination| {
        command::run(&request(inputs, destination, Options::default()))
    };
    assert_eq!(
        r(vec![a.clone()], Destination::File(a.clone())).unwrap_err(),
        UsageError::OutputIsInput {
            output: a.display().to_string(),
            input: a.display().to_string()
        }
    );
    assert_eq!(
        r(
            vec![a.clone(), b.clone()],
            Destination::File(dir.path().join("c.gltf"))
        )
        .unwrap_err(),
        UsageError::OutputForMany(2)
    );
    assert!(matches!(
        r(vec![a.clone()], Destination::File(dir.path().join("c.glb"))).unwrap_err(),
        UsageError::ContainerMismatch { .. }
    ));
    assert_eq!(
        r(vec![a], Destination::None).unwrap_err(),
        UsageError::NoDestination
    );
}

#[test]
fn one_failing_file_does_not_stop_the_others_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let inputs = dir.path().join("in");
    std::fs::create_dir_all(inputs.join("sub")).unwrap();
    std::fs::write(inputs.join("t.png"), png(Layout::Rgb, vec![77; 48])).unwrap();
    std::fs::write(
        inputs.join("sub/broken.png"),
        b"\x89PNG\r\n\x1a\nnot really",
    )
    .unwrap();
    let doc = |uri: &str| {
        asset_json(
            json!([{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 0}}}}]),
            json!([{"source": 0}]),
            json!([{"uri": uri}]),
        )
    };
    write_json(&inputs.join("good.gltf"), &doc("t.png"));
    write_json(&inputs.join("sub/bad.gltf"), &doc("broken.png"));
    let out = dir.path().join("out");
    let results = command::run(&request(
        vec![inputs.clone()],
        Destination::Dir(out.clone()),
        Options::default(),
    ))
    .unwrap();
    assert_eq!(results.len(), 2);
    let bad = results
        .iter()
        .find(|r| r.input.ends_with("bad.gltf"))
        .unwrap();
    let Outcome::Failed { error } = &bad.outcome else {
        panic!("{bad:?}")
    };
    assert!(
        error.contains("image 0") && error.contains("PNG"),
        "{error}"
    );
    assert!(!out.join("sub/bad.gltf").exists());
    let good = results
        .iter()
        .find(|r| r.input.ends_with("good.gltf"))
        .unwrap();
    assert_eq!(good.outcome, Outcome::Changed);
    assert!(out.join("good.gltf").exists());
    named(&out, "t.sheenColor", "png");
    assert_eq!(
        validation_errors(&out.join("good.gltf")),
        Vec::<String>::new()
    );
    assert_eq!(command::summary(&results).totals.failed, 1);
}

#[test]
fn the_binary_maps_outcomes_to_exit_codes() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.gltf");
    std::fs::write(dir.path().join("t.png"), png(Layout::Rgb, vec![77; 48])).unwrap();
    write_json(
        &input,
        &asset_json(
            json!([{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5], "sheenColorTexture": {"index": 0}}}}]),
            json!([{"source": 0}]),
            json!([{"uri": "t.png"}]),
        ),
    );
    let velvet = env!("CARGO_BIN_EXE_velvet");
    let status = |args: &[&str]| {
        std::process::Command::new(velvet)
            .args(args)
            .output()
            .unwrap()
    };
    let input_s = input.to_str().unwrap();
    let ok = status(&[
        "bake",
        input_s,
        "-o",
        dir.path().join("out.gltf").to_str().unwrap(),
    ]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stdout)
    );
    assert!(String::from_utf8_lossy(&ok.stdout).contains("1 baked"));
    assert_eq!(
        status(&["bake", input_s, "-o", input_s]).status.code(),
        Some(2)
    );
    assert_eq!(status(&["bake", input_s]).status.code(), Some(2));
    std::fs::write(dir.path().join("t.png"), b"broken").unwrap();
    let failed = status(&[
        "bake",
        input_s,
        "-o",
        dir.path().join("again.gltf").to_str().unwrap(),
    ]);
    assert_eq!(failed.status.code(), Some(1));
}
