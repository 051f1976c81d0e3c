//! Arbitrary bytes as a .gltf file: load, then read every buffer and image it names.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let loaded = velvet_fuzz::load("/nonexistent/fuzz.gltf", data);
    if let Some(asset) = &loaded.asset {
        velvet_fuzz::touch_resources(asset);
    }
});
