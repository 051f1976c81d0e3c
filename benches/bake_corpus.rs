//! Writes the bake corpus: four generated 2048×2048 RGBA textures (PNG at zlib's default
//! level, like most exporters write) and `scene.gltf` / `scene.glb` whose eight materials bake
//! each texture twice — once as sheen colour (RGB × [0.8, 0.6, 0.4]) and once as sheen roughness
//! (alpha × 0.5) — so a bake makes eight outputs from four decodes.
//!
//! `cargo bench --bench bake_corpus -- DIR`, then time the command line, e.g.
//! `/usr/bin/time -v target/release/velvet bake DIR/scene.gltf -o OUT/scene.gltf`.

use serde_json::json;
use velvet::bake::codec::{self, EncodeOptions, OutputFormat, PngCompression};

#[path = "support/texture.rs"]
mod support;
use support::texture;

fn main() {
    let dir = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with("--"))
        .unwrap_or_else(|| "target/bake-corpus".to_owned());
    let dir = std::path::Path::new(&dir);
    std::fs::create_dir_all(dir).unwrap();
    let options = EncodeOptions {
        png: PngCompression::Default,
        ..EncodeOptions::default()
    };
    let mut images = Vec::new();
    let mut materials = Vec::new();
    let mut bin = Vec::new();
    let mut views = Vec::new();
    for i in 0..4u32 {
        let bytes = codec::encode(&texture(i + 1), OutputFormat::Png, options).unwrap();
        std::fs::write(dir.join(format!("t{i}.png")), &bytes).unwrap();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend_from_slice(&bytes);
        images.push(json!({"name": format!("t{i}"), "uri": format!("t{i}.png")}));
        materials.push(
            json!({"name": format!("colour{i}"), "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.8, 0.6, 0.4], "sheenColorTexture": {"index": i}}}}),
        );
        materials.push(
            json!({"name": format!("roughness{i}"), "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [1.0, 1.0, 1.0],
            "sheenRoughnessFactor": 0.5, "sheenRoughnessTexture": {"index": i}}}}),
        );
    }
    let textures: Vec<_> = (0..4).map(|i| json!({"source": i})).collect();
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": materials,
        "textures": textures,
        "images": images
    });
    std::fs::write(
        dir.join("scene.gltf"),
        serde_json::to_vec_pretty(&doc).unwrap(),
    )
    .unwrap();
    for (i, image) in doc["images"].as_array_mut().unwrap().iter_mut().enumerate() {
        *image = json!({"name": format!("t{i}"), "bufferView": i, "mimeType": "image/png"});
    }
    doc["bufferViews"] = json!(views);
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    let glb = velvet::asset::glb::join(&serde_json::to_vec(&doc).unwrap(), Some(&bin));
    std::fs::write(dir.join("scene.glb"), glb).unwrap();
    println!("wrote {}", dir.display());
}
