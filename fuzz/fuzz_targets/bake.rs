//! Arbitrary documents through `velvet bake`, in memory: plan, bake (images from data: URIs or
//! a GLB's BIN chunk, up to 64 × 64 pixels), apply, and serialise.
#![no_main]

use libfuzzer_sys::fuzz_target;
use velvet::edit::write;
use velvet::bake::apply::{apply, ApplyOptions, Names};
use velvet::bake::engine::{bake, BakeOptions, MaxImagePixels};
use velvet::bake::plan::{plan, PlanOptions};

/// Every file name is free: nothing is written.
struct AnyName;

impl Names for AnyName {
    fn claim(&mut self, _name: &str, _bytes: &[u8]) -> bool {
        true
    }
}

fuzz_target!(|data: &[u8]| {
    let glb = data.starts_with(b"glTF");
    let path = if glb {
        "/nonexistent/fuzz.glb"
    } else {
        "/nonexistent/fuzz.gltf"
    };
    let loaded = velvet_fuzz::load(path, data);
    let Some(mut asset) = loaded.asset else {
        return;
    };
    // `velvet bake` does not bake a file the loader reports errors for.
    if loaded
        .diagnostics
        .iter()
        .any(|d| d.severity == velvet::diagnostics::Severity::Error)
    {
        return;
    }
    let plan = plan(
        &asset,
        PlanOptions {
            allow_out_of_range: data.len() % 2 == 0,
        },
    );
    if plan.is_empty() {
        return;
    }
    let options = BakeOptions {
        collapse_uniform: data.len() % 3 == 0,
        max_image_pixels: MaxImagePixels(64 * 64),
        ..BakeOptions::default()
    };
    let mut baked = Vec::new();
    for result in bake(&plan.recipes, &asset, &options) {
        match result {
            Ok(b) => baked.push(b),
            Err(_) => return,
        }
    }
    let bin = asset.bin.take();
    let json = asset.json().clone();
    let applied = apply(
        json,
        bin,
        asset.container,
        &plan,
        &mut baked,
        ApplyOptions {
            embed: data.len() % 5 == 0,
        },
        &mut AnyName,
    );
    let _ = write::to_bytes(&asset, &applied.json, applied.bin.as_deref());
});
