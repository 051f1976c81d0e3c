//! Arbitrary bytes through `velvet validate --fix --unsafe-fixes`: every fix planned, tried on
//! the fixed text (a trial that takes from the file's report the findings of the rules the
//! edits leave alone, and re-judges only the elements they edit where a rule can), and
//! written. The report the run gives for the file as it is after the run must be what a
//! validation of the written file finds.
#![no_main]

use libfuzzer_sys::fuzz_target;
use velvet::diagnostics::Settings;
use velvet::fix::{Fixing, Mode};
use velvet::validate::FileReport;

/// Each finding as "CODE severity pointer message".
fn listed(report: &FileReport) -> Vec<String> {
    report
        .findings
        .iter()
        .map(|f| {
            let d = &f.diagnostic;
            format!("{} {:?} {} {}", d.code, d.severity, d.pointer, d.message)
        })
        .collect()
}

fuzz_target!(|data: &[u8]| {
    let path = velvet_fuzz::scratch_folder().join("fuzz.gltf");
    std::fs::write(&path, data).expect("the scratch file is written");
    let validator = velvet_fuzz::validator();
    let settings = Settings::default();
    let fixing = Fixing::new(
        validator,
        Mode {
            apply: true,
            diff: false,
            unsafe_fixes: true,
            edits: true,
        },
    );
    let after_run = fixing.check(&path, &settings);
    let written = validator.validate_file(&path);
    assert_eq!(listed(&after_run), listed(&written));
});
