//! What the fuzz targets share: loading arbitrary bytes as an asset and touching every lazy
//! accessor the loader offers, under limits small enough that one input stays fast.

use std::path::Path;
use std::sync::OnceLock;
use velvet::asset::{self, Asset, LoadOptions};
use velvet::diagnostics::Settings;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

/// Limits for fuzzing: the defaults, but images of at most 64 × 64 pixels are decoded so that
/// a forged header costs microseconds, not the decoder's time on a real texture.
pub fn options() -> LoadOptions {
    LoadOptions {
        max_image_pixels: 64 * 64,
        ..LoadOptions::default()
    }
}

/// One validator for every input of a run (default settings, these limits): its schemas are
/// compiled once.
pub fn validator() -> &'static Validator {
    static VALIDATOR: OnceLock<Validator> = OnceLock::new();
    VALIDATOR.get_or_init(|| {
        Validator::new(Schemas::builtin(), Settings::default()).with_load_options(options())
    })
}

/// Loads `data` as a file at `path` (in a folder that does not exist: external URIs fail to
/// open, which is itself a path worth taking).
pub fn load(path: &str, data: &[u8]) -> asset::Loaded {
    asset::load_bytes_with(Path::new(path), data, &options())
}

/// Reads every buffer, image header and image through the asset's lazy accessors.
pub fn touch_resources(asset: &Asset) {
    let count = |key: &str| {
        asset
            .root()
            .get(key)
            .and_then(|a| a.as_array())
            .map_or(0, |a| a.len())
    };
    for i in 0..count("buffers").min(8) {
        let _ = asset.buffer_bytes(i);
    }
    for i in 0..count("images").min(8) {
        let _ = asset.image_header(i);
        let _ = asset.decode_image(i);
    }
}

/// A folder of this process's own for the targets that write files (removed by nobody: it
/// lives in the system's temporary folder, one small file per target).
pub fn scratch_folder() -> &'static Path {
    static FOLDER: OnceLock<std::path::PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let folder = std::env::temp_dir().join(format!("velvet-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&folder).expect("the scratch folder is made");
        folder
    })
}
