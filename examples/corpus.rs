//! Generates the benchmark corpus: one .gltf with many sheen/fuzz materials, and a folder of
//! small .gltf files; or a library asset for migrating at scale. Used by `benches/` (through
//! `#[path]`) and from the command line:
//!
//!     cargo run --release --example corpus -- OUT_DIR [MATERIALS] [FILES]
//!     cargo run --release --example corpus -- --library OUT_DIR [LOWEST_ALPHA]
//!     cargo run --release --example corpus -- --minified-library OUT_DIR [LOWEST_ALPHA]
//!     cargo run --release --example corpus -- --data-library OUT_DIR [MESHES]
//!
//! `--library` writes OUT_DIR/library.gltf (about 10 MB: 20,000 ratified sheen materials, every
//! factor different, the odd ones with a sheen roughness texture drawn from 4 shared 256² PNGs,
//! OUT_DIR/fabric0.png … fabric3.png, whose alpha holds every code from LOWEST_ALPHA, default
//! 0, to 255) and its mesh buffer. `--minified-library` writes the same library with its JSON on
//! one line (about 5 MB), the layout in which a finding's column is counted along the whole text.
//!
//! `--data-library` writes OUT_DIR/data.gltf and data.bin, a document whose weight is in its
//! data, valid throughout: MESHES (default 16) skinned grids of 210 × 210 vertices (positions
//! with their exact bounds, unit normals and tangents, texture coordinates, joints and weights,
//! 32-bit indices), a skin of 16 joints with identity inverse bind matrices, and an animation of
//! 10,000 keyframes a joint (rotations of unit length, times increasing); about 5 MB a mesh.
//!
//! writes OUT_DIR/large.gltf (MATERIALS materials, default 20000) and OUT_DIR/small/ (FILES
//! files, default 500). The materials cycle through the shapes real assets have: ratified sheen
//! with and without textures, fuzz with a sheen fallback, fuzz alone, a legacy draft sheen, and
//! a few deliberate faults so the rules have work to report.

#![allow(dead_code)]

use serde_json::{json, Value};
use std::path::Path;

/// Material number `i` of the generated corpus.
pub fn material(i: usize) -> Value {
    let c = (i % 97) as f64 / 96.0;
    let r = (i % 13) as f64 / 12.0;
    match i % 6 {
        0 => json!({"name": format!("sheen{i}"), "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [c, 0.5 * c, 0.25], "sheenRoughnessFactor": r}}}),
        1 => json!({"name": format!("sheenTex{i}"), "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [1.0, 1.0, 1.0], "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": r, "sheenRoughnessTexture": {"index": 0}}}}),
        2 => json!({"name": format!("fuzz{i}"), "extensions": {
            "KHR_materials_fuzz": {"fuzzFactor": 1.0, "fuzzColorFactor": [c, c, c], "fuzzRoughnessFactor": r},
            "KHR_materials_sheen": {"sheenColorFactor": [c, c, c], "sheenRoughnessFactor": r}}}),
        3 => json!({"name": format!("fuzzOnly{i}"), "extensions": {
            "KHR_materials_fuzz": {"fuzzFactor": 0.5, "fuzzColorFactor": [0.1, 0.1, 0.1]}}}),
        4 => json!({"name": format!("legacy{i}"), "pbrMetallicRoughness": {"roughnessFactor": r},
            "extensions": {"KHR_materials_sheen": {"sheenFactor": 1.0, "sheenColor": [c, c, 1.0]}}}),
        _ => json!({"name": format!("faulty{i}"), "extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [1.5, 0.0], "sheenRoughnessFactor": "rough", "sheenColorTexture": {"index": 7}}}}),
    }
}

/// A document with `count` generated materials and one mesh per material.
pub fn document(count: usize) -> Value {
    let materials: Vec<Value> = (0..count).map(material).collect();
    let meshes: Vec<Value> = (0..count)
        .map(|i| json!({"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": i}]}))
        .collect();
    json!({
        "asset": {"version": "2.0", "generator": "velvet benchmark corpus"},
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_fuzz"],
        "materials": materials,
        "meshes": meshes,
        "textures": [{"source": 0}],
        "images": [{"uri": "sheen.png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"}
        ],
        "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        "buffers": [{"byteLength": 60, "uri": "mesh.bin"}]
    })
}

/// A 1×1 RGBA PNG for the shared texture.
pub fn png() -> Vec<u8> {
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &[200, 150, 100, 128],
        1,
        1,
        image::ExtendedColorType::Rgba8,
    )
    .expect("encoding a 1x1 PNG cannot fail");
    bytes
}

/// Writes `large.gltf` with `materials` materials and `small/` with `files` files of 6
/// materials each into `dir`.
pub fn write(dir: &Path, materials: usize, files: usize) -> std::io::Result<()> {
    std::fs::create_dir_all(dir.join("small"))?;
    std::fs::write(
        dir.join("large.gltf"),
        serde_json::to_vec_pretty(&document(materials))?,
    )?;
    std::fs::write(dir.join("sheen.png"), png())?;
    std::fs::write(dir.join("small/sheen.png"), png())?;
    for f in 0..files {
        std::fs::write(
            dir.join(format!("small/asset{f:04}.gltf")),
            serde_json::to_vec_pretty(&document(6))?,
        )?;
    }
    Ok(())
}

/// The number of shared roughness textures of the library.
pub const LIBRARY_TEXTURES: usize = 4;

/// Material `i` of the library: a ratified sheen whose colour and roughness differ from every
/// other material's; odd materials read roughness texture `i / 2 % 4`.
pub fn library_material(i: usize, count: usize) -> Value {
    let t = i as f64 / count as f64;
    let mut sheen = json!({
        "sheenColorFactor": [0.2 + 0.7 * t, 0.5, 0.9 - 0.6 * t],
        "sheenRoughnessFactor": 0.12 + 0.85 * t
    });
    if i % 2 == 1 {
        sheen["sheenRoughnessTexture"] = json!({"index": i / 2 % LIBRARY_TEXTURES});
    }
    json!({"name": format!("cloth{i}"), "extensions": {"KHR_materials_sheen": sheen}})
}

/// The library document: `count` materials, one mesh per material.
pub fn library_document(count: usize) -> Value {
    let mut doc = document(0);
    doc["asset"]["generator"] = json!("velvet library corpus");
    doc["extensionsUsed"] = json!(["KHR_materials_sheen"]);
    doc["materials"] = (0..count).map(|i| library_material(i, count)).collect();
    doc["meshes"] = (0..count)
        .map(|i| json!({"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": i}]}))
        .collect();
    doc["textures"] = (0..LIBRARY_TEXTURES)
        .map(|k| json!({"source": k}))
        .collect();
    doc["images"] = (0..LIBRARY_TEXTURES)
        .map(|k| json!({"uri": format!("fabric{k}.png")}))
        .collect();
    doc
}

/// A 256×256 RGBA PNG whose alpha holds a different pattern per `k` and every code from
/// `lowest` to 255.
pub fn fabric_png(k: usize, lowest: u8) -> Vec<u8> {
    let span = 256 - usize::from(lowest);
    let mut pixels = Vec::with_capacity(256 * 256 * 4);
    for y in 0..256usize {
        for x in 0..256usize {
            let alpha = usize::from(lowest) + (x + (y * (2 * k + 1)) + 37 * k) % span;
            pixels.extend([x as u8, y as u8, (128 + 40 * k) as u8, alpha as u8]);
        }
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &pixels,
        256,
        256,
        image::ExtendedColorType::Rgba8,
    )
    .expect("encoding a PNG in memory cannot fail");
    bytes
}

/// Writes the library (`materials` materials) into `dir`, pretty-printed.
pub fn write_library(dir: &Path, materials: usize, lowest_alpha: u8) -> std::io::Result<()> {
    write_library_laid_out(dir, materials, lowest_alpha, false)
}

/// Writes the library (`materials` materials) into `dir`, pretty-printed or on one line.
pub fn write_library_laid_out(
    dir: &Path,
    materials: usize,
    lowest_alpha: u8,
    minified: bool,
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let document = library_document(materials);
    let text = if minified {
        serde_json::to_vec(&document)?
    } else {
        serde_json::to_vec_pretty(&document)?
    };
    std::fs::write(dir.join("library.gltf"), text)?;
    std::fs::write(dir.join("mesh.bin"), [0u8; 60])?;
    for k in 0..LIBRARY_TEXTURES {
        std::fs::write(
            dir.join(format!("fabric{k}.png")),
            fabric_png(k, lowest_alpha),
        )?;
    }
    Ok(())
}

/// Appends `values` to `bin` as little-endian f32, padded to 4 bytes, and returns the buffer
/// view (offset, length) they take.
fn push_f32(bin: &mut Vec<u8>, values: &[f32]) -> (usize, usize) {
    let start = bin.len();
    for v in values {
        bin.extend_from_slice(&v.to_le_bytes());
    }
    (start, bin.len() - start)
}

/// Writes OUT_DIR/data.gltf and data.bin: see the module comment.
pub fn write_data_library(dir: &Path, meshes: usize) -> std::io::Result<()> {
    const SIDE: usize = 210;
    const JOINTS: usize = 16;
    const KEYS: usize = 10_000;
    std::fs::create_dir_all(dir)?;
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    // One buffer view an accessor: no byteStride needed, and each view holds one kind of data.
    let mut add = |bin: &mut Vec<u8>,
                   (offset, length): (usize, usize),
                   accessor: Value,
                   target: Option<u32>| {
        let mut view = json!({"buffer": 0, "byteOffset": offset, "byteLength": length});
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        views.push(view);
        let mut accessor = accessor;
        accessor["bufferView"] = json!(views.len() - 1);
        accessors.push(accessor);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        accessors.len() - 1
    };
    let vertices = SIDE * SIDE;
    let mut mesh_list = Vec::new();
    for m in 0..meshes {
        let (mut positions, mut normals, mut tangents, mut uvs, mut weights) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut joints: Vec<u8> = Vec::new();
        for y in 0..SIDE {
            for x in 0..SIDE {
                let (u, v) = (x as f32 / (SIDE - 1) as f32, y as f32 / (SIDE - 1) as f32);
                positions.extend_from_slice(&[u + m as f32, v, 0.0]);
                normals.extend_from_slice(&[0.0, 0.0, 1.0]);
                tangents.extend_from_slice(&[1.0, 0.0, 0.0, 1.0]);
                uvs.extend_from_slice(&[u, v]);
                let j = ((x * JOINTS) / SIDE) as u8;
                joints.extend_from_slice(&[j, (j + 1) % JOINTS as u8, 0, 0]);
                weights.extend_from_slice(&[0.75, 0.25, 0.0, 0.0]);
            }
        }
        let mut indices: Vec<u32> = Vec::new();
        for y in 0..SIDE - 1 {
            for x in 0..SIDE - 1 {
                let i = (y * SIDE + x) as u32;
                let s = SIDE as u32;
                indices.extend_from_slice(&[i, i + 1, i + s, i + 1, i + s + 1, i + s]);
            }
        }
        let bound = |c: usize, f: fn(f32, f32) -> f32, start: f32| {
            positions
                .iter()
                .skip(c)
                .step_by(3)
                .fold(start, |a, b| f(a, *b))
        };
        let min: Vec<f32> = (0..3).map(|c| bound(c, f32::min, f32::INFINITY)).collect();
        let max: Vec<f32> = (0..3)
            .map(|c| bound(c, f32::max, f32::NEG_INFINITY))
            .collect();
        let position = {
            let at = push_f32(&mut bin, &positions);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": vertices, "type": "VEC3", "min": min, "max": max}),
                Some(34962),
            )
        };
        let normal = {
            let at = push_f32(&mut bin, &normals);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": vertices, "type": "VEC3"}),
                Some(34962),
            )
        };
        let tangent = {
            let at = push_f32(&mut bin, &tangents);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": vertices, "type": "VEC4"}),
                Some(34962),
            )
        };
        let uv = {
            let at = push_f32(&mut bin, &uvs);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": vertices, "type": "VEC2"}),
                Some(34962),
            )
        };
        let joint = {
            let start = bin.len();
            bin.extend_from_slice(&joints);
            add(
                &mut bin,
                (start, joints.len()),
                json!({"componentType": 5121, "count": vertices, "type": "VEC4"}),
                Some(34962),
            )
        };
        let weight = {
            let at = push_f32(&mut bin, &weights);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": vertices, "type": "VEC4"}),
                Some(34962),
            )
        };
        let index = {
            let start = bin.len();
            for i in &indices {
                bin.extend_from_slice(&i.to_le_bytes());
            }
            add(
                &mut bin,
                (start, indices.len() * 4),
                json!({"componentType": 5125, "count": indices.len(), "type": "SCALAR"}),
                Some(34963),
            )
        };
        mesh_list.push(json!({"primitives": [{"attributes": {
            "POSITION": position, "NORMAL": normal, "TANGENT": tangent, "TEXCOORD_0": uv,
            "JOINTS_0": joint, "WEIGHTS_0": weight}, "indices": index}]}));
    }
    let identity: Vec<f32> = (0..JOINTS)
        .flat_map(|_| {
            [
                1.0, 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1.,
            ]
        })
        .collect();
    let ibm = {
        let at = push_f32(&mut bin, &identity);
        add(
            &mut bin,
            at,
            json!({"componentType": 5126, "count": JOINTS, "type": "MAT4"}),
            None,
        )
    };
    let times: Vec<f32> = (0..KEYS).map(|k| k as f32 / 30.0).collect();
    let input = {
        let at = push_f32(&mut bin, &times);
        add(
            &mut bin,
            at,
            json!({"componentType": 5126, "count": KEYS, "type": "SCALAR",
            "min": [times[0]], "max": [times[KEYS - 1]]}),
            None,
        )
    };
    let mut channels = Vec::new();
    let mut samplers = Vec::new();
    for j in 0..JOINTS {
        let rotations: Vec<f32> = (0..KEYS)
            .flat_map(|k| {
                let half = (k as f32 * 0.01 + j as f32) * 0.5;
                [0.0, half.sin(), 0.0, half.cos()]
            })
            .collect();
        let output = {
            let at = push_f32(&mut bin, &rotations);
            add(
                &mut bin,
                at,
                json!({"componentType": 5126, "count": KEYS, "type": "VEC4"}),
                None,
            )
        };
        samplers.push(json!({"input": input, "output": output}));
        channels.push(json!({"sampler": j, "target": {"node": j + 1, "path": "rotation"}}));
    }
    // Node 0 holds the joints 1..=16 as children; the skinned meshes hang off the root too.
    let mut nodes = vec![json!({"name": "joints", "children": (1..=JOINTS).collect::<Vec<_>>()})];
    nodes.extend((0..JOINTS).map(|j| json!({"name": format!("joint{j}")})));
    let mesh_nodes: Vec<usize> = (0..meshes).map(|m| nodes.len() + m).collect();
    nodes.extend((0..meshes).map(|m| json!({"mesh": m, "skin": 0})));
    let mut roots = vec![0];
    roots.extend(mesh_nodes);
    let doc = json!({
        "asset": {"version": "2.0", "generator": "velvet corpus --data-library"},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": mesh_list,
        "skins": [{"joints": (1..=JOINTS).collect::<Vec<_>>(), "inverseBindMatrices": ibm, "skeleton": 0}],
        "animations": [{"channels": channels, "samplers": samplers}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len(), "uri": "data.bin"}],
    });
    std::fs::write(dir.join("data.bin"), &bin)?;
    std::fs::write(dir.join("data.gltf"), serde_json::to_string_pretty(&doc)?)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--data-library") {
        let Some(dir) = args.get(1) else {
            eprintln!("usage: corpus --data-library OUT_DIR [MESHES]");
            std::process::exit(2);
        };
        let meshes = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(16);
        if let Err(e) = write_data_library(Path::new(dir), meshes) {
            eprintln!("corpus: cannot write {dir}: {e}");
            std::process::exit(1);
        }
        return;
    }
    if let Some(mode @ ("--library" | "--minified-library")) = args.first().map(String::as_str) {
        let Some(dir) = args.get(1) else {
            eprintln!("usage: corpus {mode} OUT_DIR [LOWEST_ALPHA]");
            std::process::exit(2);
        };
        let lowest = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(0);
        let minified = mode == "--minified-library";
        if let Err(e) = write_library_laid_out(Path::new(dir), 20_000, lowest, minified) {
            eprintln!("corpus: cannot write {dir}: {e}");
            std::process::exit(1);
        }
        return;
    }
    let Some(dir) = args.first() else {
        eprintln!("usage: corpus OUT_DIR [MATERIALS] [FILES]");
        std::process::exit(2);
    };
    let materials = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20_000);
    let files = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(500);
    if let Err(e) = write(Path::new(dir), materials, files) {
        eprintln!("corpus: cannot write {dir}: {e}");
        std::process::exit(1);
    }
}
