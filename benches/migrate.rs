//! Benchmarks of `velvet migrate` on generated inputs: one .gltf with 20,000 materials, and a
//! folder tree of 500 files (400 .gltf, 100 .glb) with 12 materials each. The materials mix
//! every conversion: ratified sheen (factors, and textures in fast mode), fuzz without a
//! fallback, the legacy sheen draft, switched-off layers and plain materials.
//!
//! Run: `cargo bench --bench migrate` (see docs/performance.md).

use criterion::{criterion_group, criterion_main, Criterion};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Duration;
use velvet::command::migrate::{self as migrating, Request};
use velvet::migrate::Options;
use velvet::output::paths::Destination;

/// Material `i` of a generated asset: the kind cycles so that every conversion is exercised.
fn material(i: usize) -> Value {
    let t = (i % 97) as f64 / 97.0;
    let name = format!("material {i}");
    match i % 10 {
        0..=3 => {
            json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1.0], "roughnessFactor": 0.8},
            "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.9 * t, 0.5, 0.25 + 0.5 * t], "sheenRoughnessFactor": t}}})
        }
        4 | 5 => {
            json!({"name": name, "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.8, 0.6], "sheenRoughnessFactor": 0.5,
            "sheenColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {"scale": [30.0, -30.0]}}},
            "sheenRoughnessTexture": {"index": 1}}}})
        }
        6 | 7 => {
            json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1.0]},
            "extensions": {"KHR_materials_fuzz": {"fuzzFactor": t, "fuzzColorFactor": [1.0, t, 0.5], "fuzzRoughnessFactor": 0.7}}})
        }
        8 => json!({"name": name, "pbrMetallicRoughness": {"roughnessFactor": 0.6},
            "extensions": {"KHR_materials_sheen": {"sheenFactor": 1.5, "sheenColor": [0.5, 0.6, t]}}}),
        _ => {
            json!({"name": name, "pbrMetallicRoughness": {"roughnessFactor": t}, "extras": {"id": i}})
        }
    }
}

/// A .gltf document with `count` materials, pretty-printed as exporters write it.
fn document(count: usize, offset: usize) -> String {
    let doc = json!({
        "asset": {"version": "2.0", "generator": "velvet bench"},
        "extensionsUsed": ["KHR_texture_transform", "KHR_materials_sheen", "KHR_materials_fuzz"],
        "textures": [{"source": 0}, {"source": 1}],
        "images": [{"uri": "sheen.png"}, {"uri": "roughness.png"}],
        "materials": (offset..offset + count).map(material).collect::<Vec<_>>(),
    });
    serde_json::to_string_pretty(&doc).unwrap()
}

/// Writes the 20,000-material file into `dir`; returns its path.
fn big_file(dir: &Path) -> PathBuf {
    let path = dir.join("big.gltf");
    std::fs::write(&path, document(20_000, 0)).unwrap();
    path
}

/// Writes the 500-file tree under `dir/tree` (25 folders of 20 files, every fifth a .glb);
/// returns the tree's root.
fn many_files(dir: &Path) -> PathBuf {
    let root = dir.join("tree");
    for f in 0..500 {
        let folder = root.join(format!("set{:02}", f / 20));
        std::fs::create_dir_all(&folder).unwrap();
        let text = document(12, f * 12);
        if f % 5 == 4 {
            let glb = velvet::asset::glb::join(text.as_bytes(), Some(&[0u8; 1024]));
            std::fs::write(folder.join(format!("asset{f:03}.glb")), glb).unwrap();
        } else {
            std::fs::write(folder.join(format!("asset{f:03}.gltf")), text).unwrap();
        }
    }
    root
}

fn run(input: &Path, out: &Path) -> migrating::RunReport {
    let request = Request {
        inputs: vec![input.to_path_buf()],
        destination: Destination::Dir(out.to_path_buf()),
        options: Options::default(),
        dry_run: false,
        progress: false,
    };
    let report = migrating::run(&request).unwrap();
    assert!(!report.failed());
    report
}

fn benches(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let big = big_file(dir.path());
    let tree = many_files(dir.path());
    let out = dir.path().join("out");

    let report = run(&big, &out);
    assert!(
        report.summary.materials_migrated > 17_000,
        "{:?}",
        report.summary
    );
    let report = run(&tree, &out);
    assert_eq!(report.summary.totals.files, 500);

    let mut group = c.benchmark_group("migrate");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    group.bench_function("one file, 20000 materials", |b| b.iter(|| run(&big, &out)));
    group.bench_function("500 files, 12 materials each", |b| {
        b.iter(|| run(&tree, &out))
    });
    group.finish();
}

criterion_group!(migrate_benches, benches);
criterion_main!(migrate_benches);
