//! Arbitrary documents through `velvet migrate`, in memory: plan every material, write the
//! edits as splices part by part (as a migration without bakes does), apply them to the whole
//! document and serialise in the input's style, and load the result again, which must parse
//! (velvet never writes a document it cannot read back). Where the part-by-part splices are
//! taken they must read as the whole-document result does.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use velvet::edit::write;
use velvet::migrate::{plan_document, Options};

fuzz_target!(|data: &[u8]| {
    let options = Options {
        report: data.first().is_some_and(|b| b & 1 == 1),
        refresh_fallback: data.first().is_some_and(|b| b & 2 == 2),
        load: velvet_fuzz::options(),
        ..Options::default()
    };
    let path = "/nonexistent/fuzz.gltf";
    let loaded = velvet_fuzz::load(path, data);
    let Some(mut asset) = loaded.asset else {
        return;
    };
    let plan = plan_document(&asset, &options);
    let edits: Vec<_> = plan.edits().cloned().collect();
    // The spliced bytes as an owned copy: the output borrows the asset, which is edited next.
    let spliced = write::spliced_bytes(&asset, &edits).map(|spliced| {
        spliced.map(|(output, changed)| {
            let bytes: Vec<u8> = match output {
                write::Output::Bytes(bytes) => bytes.into_owned(),
                write::Output::Spliced(spliced) => spliced.to_text().into_bytes(),
            };
            (bytes, changed)
        })
    });
    let Ok(true) = velvet::edit::apply(asset.json_mut(), &edits) else {
        return;
    };
    let bytes = write::to_bytes(&asset, asset.json(), asset.bin.as_deref());
    if let Ok(Some((spliced, true))) = spliced {
        let read = |bytes: &[u8]| {
            velvet::asset::load_bytes_with(Path::new(path), bytes, &options.load)
                .asset
                // Numbers as velvet writes them: a part the whole-document writer writes anew
                // rounds numbers the part-by-part writer copies.
                .map(|a| velvet::edit::splice::written(a.json().clone()))
        };
        let (part_by_part, whole) = (read(&spliced), read(&bytes));
        assert!(part_by_part.is_some(), "the spliced document does not load again");
        assert_eq!(part_by_part, whole, "part-by-part and whole-document edits disagree");
    }
    let again = velvet::asset::load_bytes_with(Path::new(path), &bytes, &options.load);
    let migrated = again.asset.unwrap_or_else(|| {
        panic!(
            "the migrated document does not load again: {:?}",
            again.diagnostics
        )
    });
    let _ = plan_document(&migrated, &options);
});
