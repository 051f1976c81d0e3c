//! Arbitrary bytes through `velvet validate`: load (as .glb when the bytes say so), every rule,
//! source positions, and every report format.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use velvet::report::{self, Format};

fuzz_target!(|data: &[u8]| {
    let path = Path::new("/nonexistent/fuzz.gltf");
    let loaded = velvet_fuzz::load("/nonexistent/fuzz.gltf", data);
    let report = velvet_fuzz::validator().validate_loaded(path, loaded);
    let reports = [report];
    for (no_fold, diff, fix_only) in [(false, false, false), (true, true, true)] {
        let options = report::Options {
            color: false,
            quiet: false,
            no_fold,
            diff,
            fix_only,
        };
        for format in [Format::Text, Format::Json, Format::Sarif, Format::Github] {
            let _ = report::render(format, &reports, &options);
        }
    }
});
