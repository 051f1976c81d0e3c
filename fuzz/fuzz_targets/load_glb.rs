//! Arbitrary bytes as a .glb file: the chunk walk, then every buffer and image it names.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let loaded = velvet_fuzz::load("/nonexistent/fuzz.glb", data);
    if let Some(asset) = &loaded.asset {
        velvet_fuzz::touch_resources(asset);
    }
});
