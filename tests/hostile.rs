//! Hostile and broken input: every loader limit and path rule with a crafted input, write
//! failures that must leave no partial output and the input untouched, a batch interrupted
//! in the middle of a write, files that vanish or dangle mid-run, and the inputs that fuzzing
//! found (fixtures/hostile, see docs/fuzzing.md).

use serde_json::{json, Value};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use velvet::asset::{self, glb, limits, LoadOptions};
use velvet::bake::codec::{self, CodecError};
use velvet::diagnostics::Settings;
use velvet::rules::schema::Schemas;
use velvet::validate::Validator;

// ---------------------------------------------------------------------------------------------
// Helpers

/// Counts the largest single allocation made on the current thread, so that a test can show
/// that a refusal came before any pixel buffer was allocated.
struct LargestAllocation;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

/// Bytes allocated now, and the most at any moment, over every thread of the process: read by
/// a test that runs alone in a process of its own ([`alone_in_a_process`]).
static HEAP_NOW: AtomicUsize = AtomicUsize::new(0);
static HEAP_PEAK: AtomicUsize = AtomicUsize::new(0);

fn heap_grew(by: usize) {
    let now = HEAP_NOW.fetch_add(by, Ordering::Relaxed) + by;
    HEAP_PEAK.fetch_max(now, Ordering::Relaxed);
}

unsafe impl GlobalAlloc for LargestAllocation {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(layout.size())));
        heap_grew(layout.size());
        System.alloc(layout)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        HEAP_NOW.fetch_sub(layout.size(), Ordering::Relaxed);
        System.dealloc(ptr, layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = LARGEST.try_with(|l| l.set(l.get().max(new_size)));
        if new_size >= layout.size() {
            heap_grew(new_size - layout.size());
        } else {
            HEAP_NOW.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        System.realloc(ptr, layout, new_size)
    }
}

/// Whether this is the process [`alone_in_a_process`] started; otherwise starts it (this test
/// binary, running test `name` alone) and asserts that the test passed there. The peak heap of
/// a process is a test's own only when no other test runs beside it.
fn alone_in_a_process(name: &str) -> bool {
    if std::env::var_os("VELVET_TEST_ALONE").is_some() {
        return true;
    }
    let out = Command::new(std::env::current_exe().unwrap())
        .args([name, "--exact", "--nocapture", "--test-threads=1"])
        .env("VELVET_TEST_ALONE", "1")
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && text.contains("1 passed"), "{text}");
    false
}

#[global_allocator]
static ALLOCATOR: LargestAllocation = LargestAllocation;

/// Runs `f` and returns its result with the largest allocation it made on this thread.
fn largest_allocation<T>(f: impl FnOnce() -> T) -> (T, usize) {
    LARGEST.with(|l| l.set(0));
    let out = f();
    (out, LARGEST.with(Cell::get))
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/hostile")
        .join(name)
}

fn velvet_env(args: &[&str], env: &[(&str, &str)]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .env_remove("VELVET_TEST_WRITE_FAULT")
        .envs(env.iter().copied())
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn velvet(args: &[&str]) -> (i32, String, String) {
    let (code, out, err) = velvet_env(args, &[]);
    (code.expect("velvet exited normally"), out, err)
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

fn write(path: &Path, bytes: impl AsRef<[u8]>) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

fn png(width: u32, height: u32, color: image::ExtendedColorType) -> Vec<u8> {
    let channels = color.channel_count() as usize;
    let data: Vec<u8> = (0..width as usize * height as usize * channels)
        .map(|i| (i * 37 % 251) as u8)
        .collect();
    let mut out = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut out),
        &data,
        width,
        height,
        color,
    )
    .unwrap();
    out
}

/// A document with one sheen material whose colour and roughness textures read image 0.
fn sheen_document(image_uri: &str) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [{"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.5, 0.5],
            "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": 0.5,
            "sheenRoughnessTexture": {"index": 0}
        }}}],
        "textures": [{"source": 0}],
        "images": [{"uri": image_uri}]
    })
}

fn codes(diagnostics: &[velvet::diagnostics::Diagnostic]) -> Vec<&str> {
    diagnostics.iter().map(|d| d.code).collect()
}

/// Every file under `root` with its bytes.
fn tree(root: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let meta = std::fs::symlink_metadata(&path).unwrap();
            if meta.is_dir() {
                stack.push(path);
            } else if meta.is_file() {
                out.insert(
                    path.strip_prefix(root).unwrap().to_path_buf(),
                    std::fs::read(&path).unwrap(),
                );
            }
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Limits

#[test]
fn a_document_over_the_size_limit_is_refused_naming_the_limit_and_its_flag() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = sheen_document("tex.png");
    doc["extras"] = json!({"padding": "x".repeat(5000)});
    let text = doc.to_string();
    let path = dir.path().join("big.gltf");
    write(&path, &text);
    let options = LoadOptions {
        max_document_bytes: 4096,
        ..LoadOptions::default()
    };
    let loaded = asset::load_with(&path, &options);
    assert!(loaded.asset.is_none());
    assert_eq!(codes(&loaded.diagnostics), ["DOCUMENT_TOO_LARGE"]);
    assert_eq!(
        loaded.diagnostics[0].message,
        format!(
            "the JSON document is {} bytes, over the limit of 4096 (raise it with --max-document-bytes)",
            text.len()
        )
    );
    // At the limit it loads.
    let at_limit = LoadOptions {
        max_document_bytes: text.len() as u64,
        ..LoadOptions::default()
    };
    assert!(asset::load_with(&path, &at_limit).asset.is_some());
    // In a GLB the JSON chunk counts (padded to 4 bytes), not the BIN chunk.
    let glb_bytes = glb::join(text.as_bytes(), Some(&vec![0u8; 10_000]));
    let loaded = asset::load_bytes_with(&dir.path().join("big.glb"), &glb_bytes, &options);
    assert_eq!(codes(&loaded.diagnostics), ["DOCUMENT_TOO_LARGE"]);
    let json_chunk = text.len().div_ceil(4) * 4;
    assert!(loaded.diagnostics[0]
        .message
        .starts_with(&format!("the JSON document is {json_chunk} bytes")));

    // On the command line: validate reports it for the file; migrate refuses it and writes
    // nothing; the flag raises the limit.
    let (status, out, _) = velvet(&["validate", "--max-document-bytes", "4096", s(&path)]);
    assert_eq!(status, 1, "{out}");
    assert!(out.contains("DOCUMENT_TOO_LARGE"), "{out}");
    assert!(out.contains("big.gltf"), "{out}");
    let output = dir.path().join("out.gltf");
    let (status, out, _) = velvet(&[
        "migrate",
        s(&path),
        "-o",
        s(&output),
        "--max-document-bytes",
        "4096",
    ]);
    assert_eq!(status, 1, "{out}");
    assert!(
        out.contains(&format!(
            "{} cannot be migrated: the JSON document is {} bytes, over the limit of 4096 (raise it with --max-document-bytes) (DOCUMENT_TOO_LARGE)",
            path.display(),
            text.len()
        )),
        "{out}"
    );
    assert!(!output.exists());
    let (status, out, _) = velvet(&["validate", "--max-document-bytes", "6000", s(&path)]);
    assert!(!out.contains("DOCUMENT_TOO_LARGE"), "{status} {out}");
}

/// The library reads a stream up to the document limit; the command refuses one named as an
/// input (see `a_fifo_or_device_named_as_input_is_a_usage_error_without_blocking`).
#[cfg(unix)]
#[test]
fn an_endless_stream_loaded_by_the_library_stops_at_the_document_limit() {
    let options = LoadOptions {
        max_document_bytes: 100_000,
        ..LoadOptions::default()
    };
    let loaded = asset::load_with(Path::new("/dev/zero"), &options);
    assert!(loaded.asset.is_none());
    assert_eq!(codes(&loaded.diagnostics), ["DOCUMENT_TOO_LARGE"]);
    assert!(
        loaded.diagnostics[0]
            .message
            .contains("the JSON document is 100004 bytes, over the limit of 100000"),
        "{:?}",
        loaded.diagnostics
    );
}

#[test]
fn deep_nesting_is_refused_at_the_limit_without_exhausting_the_stack() {
    let prefix = r#"{"asset":{"version":"2.0"},"extras":"#;
    let nested = |depth: usize| format!("{prefix}{}{}}}", "[".repeat(depth), "]".repeat(depth));
    let path = Path::new("memory/deep.gltf");
    // A hundred thousand levels: refused by the scan, before a recursive parser sees it.
    let loaded = asset::load_bytes(path, nested(100_000).as_bytes());
    assert!(loaded.asset.is_none());
    assert_eq!(codes(&loaded.diagnostics), ["JSON_TOO_DEEP"]);
    // The root object is level 1 and `extras` opens level 2, so the 64th '[' is level 65.
    let column = prefix.len() + 64;
    assert_eq!(
        loaded.diagnostics[0].message,
        format!("line 1, column {column}: the JSON nests deeper than 64 arrays and objects (raise the limit with --max-json-depth, at most 127)")
    );
    // 64 levels in all load under the default; 127 under the highest limit.
    assert!(asset::load_bytes(path, nested(63).as_bytes())
        .asset
        .is_some());
    assert_eq!(
        codes(&asset::load_bytes(path, nested(64).as_bytes()).diagnostics),
        ["JSON_TOO_DEEP"]
    );
    let highest = LoadOptions {
        max_json_depth: limits::JSON_DEPTH_CEILING,
        ..LoadOptions::default()
    };
    assert!(
        asset::load_bytes_with(path, nested(126).as_bytes(), &highest)
            .asset
            .is_some()
    );

    // Every rule, on a worker thread, over the deepest document the flag allows.
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("deep.gltf");
    write(&file, nested(126));
    let (status, out, _) = velvet(&["validate", "--max-json-depth", "127", s(&file)]);
    assert!(!out.contains("JSON_TOO_DEEP"), "{status} {out}");
    let (status, out, _) = velvet(&["validate", s(&file)]);
    assert_eq!(status, 1);
    assert!(out.contains("JSON_TOO_DEEP"), "{out}");
    let (status, _, err) = velvet(&["validate", "--max-json-depth", "128", s(&file)]);
    assert_eq!(status, 2, "{err}");
    assert!(err.contains("128 is not in 1..=127"), "{err}");
}

#[test]
fn glb_chunk_lengths_beyond_the_file_are_reported_not_followed() {
    let json = br#"{"asset":{"version":"2.0"}} "#;
    let mut bytes = b"glTF\x02\0\0\0\0\0\0\0".to_vec();
    bytes.extend_from_slice(&(json.len() as u32).to_le_bytes());
    bytes.extend_from_slice(b"JSON");
    bytes.extend_from_slice(json);
    bytes.extend_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    bytes.extend_from_slice(b"BIN\0");
    bytes.extend_from_slice(&[1, 2, 3, 4]);
    let len = bytes.len() as u32;
    bytes[8..12].copy_from_slice(&len.to_le_bytes());
    let loaded = asset::load_bytes(Path::new("memory/x.glb"), &bytes);
    assert_eq!(
        codes(&loaded.diagnostics),
        ["GLB_CHUNK_TOO_BIG", "GLB_UNEXPECTED_END_OF_CHUNK_DATA"]
    );
    assert_eq!(
        loaded.diagnostics[1].message,
        "chunk 1 at byte 48 declares 4294967280 bytes but only 4 remain in the file"
    );
    // A JSON chunk that claims the whole address space.
    let mut bytes = b"glTF\x02\0\0\0\x18\0\0\0".to_vec();
    bytes.extend_from_slice(&u32::MAX.to_le_bytes());
    bytes.extend_from_slice(b"JSON{}  ");
    let loaded = asset::load_bytes(Path::new("memory/x.glb"), &bytes);
    assert_eq!(
        codes(&loaded.diagnostics),
        [
            "GLB_CHUNK_LENGTH_UNALIGNED",
            "GLB_CHUNK_TOO_BIG",
            "GLB_UNEXPECTED_END_OF_CHUNK_DATA"
        ]
    );
}

#[test]
fn buffers_shorter_than_their_byte_length_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    // GLB: checked on load, from the BIN chunk in hand.
    let doc = json!({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 64}]});
    let bytes = glb::join(doc.to_string().as_bytes(), Some(&[0u8; 8]));
    let loaded = asset::load_bytes(&dir.path().join("short.glb"), &bytes);
    assert_eq!(codes(&loaded.diagnostics), ["BUFFER_BYTE_LENGTH_MISMATCH"]);
    assert_eq!(loaded.diagnostics[0].pointer, "/buffers/0");
    assert_eq!(
        loaded.diagnostics[0].message,
        "buffer 0 declares 64 bytes but the GLB's BIN chunk holds 8"
    );
    let without_bin = glb::join(doc.to_string().as_bytes(), None);
    let loaded = asset::load_bytes(&dir.path().join("short.glb"), &without_bin);
    assert_eq!(codes(&loaded.diagnostics), ["BUFFER_MISSING_GLB_DATA"]);
    assert_eq!(
        loaded.diagnostics[0].message,
        "buffer 0 has no uri and declares 64 bytes, but the GLB has no BIN chunk"
    );
    // A data: URI and a file: checked when read.
    write(&dir.path().join("short.bin"), [1u8, 2, 3]);
    let doc = json!({"asset": {"version": "2.0"}, "buffers": [
        {"byteLength": 10, "uri": "data:application/octet-stream;base64,AQID"},
        {"byteLength": 10, "uri": "short.bin"},
        {"byteLength": 3, "uri": "short.bin"}
    ]});
    let loaded = asset::load_bytes(&dir.path().join("a.gltf"), doc.to_string().as_bytes());
    let a = loaded.asset.unwrap();
    for i in [0, 1] {
        let err = a.buffer_bytes(i).unwrap_err();
        assert_eq!(
            (err.code, err.pointer.as_str(), err.message.as_str()),
            (
                "BUFFER_BYTE_LENGTH_MISMATCH",
                format!("/buffers/{i}").as_str(),
                format!("buffer {i} declares 10 bytes but its data holds 3").as_str()
            )
        );
    }
    assert_eq!(a.buffer_bytes(2).unwrap().as_ref(), [1, 2, 3]);

    // migrate does not rewrite a GLB whose buffer is short, and writes nothing.
    let input = dir.path().join("short.glb");
    write(&input, &bytes);
    let output = dir.path().join("out.glb");
    let (status, out, _) = velvet(&["migrate", s(&input), "-o", s(&output)]);
    assert_eq!(status, 1, "{out}");
    assert!(out.contains("(BUFFER_BYTE_LENGTH_MISMATCH)"), "{out}");
    assert!(!output.exists());
    assert_eq!(std::fs::read(&input).unwrap(), bytes);
}

#[test]
fn a_forged_100000_square_png_is_refused_before_any_pixel_buffer_is_allocated() {
    let bytes = std::fs::read(fixture("huge-100000x100000.png")).unwrap();
    let (result, largest) = largest_allocation(|| codec::decode(&bytes));
    match result {
        Err(CodecError::TooLarge { format, message }) => {
            assert_eq!(format, "PNG");
            assert_eq!(
                message,
                "the image declares 100000 × 100000 = 10000000000 pixels, over the limit of \
                 268435456 (raise it with --max-image-pixels); it was not decoded"
            );
        }
        other => panic!("expected TooLarge, got {other:?}"),
    }
    assert!(
        largest < 1 << 20,
        "{largest} bytes allocated at once while refusing"
    );

    // The asset's decoder (used by `migrate --report`) refuses it the same way.
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("huge.png"), &bytes);
    let path = dir.path().join("chair.gltf");
    write(&path, sheen_document("huge.png").to_string());
    let a = asset::load(&path).asset.unwrap();
    let (result, largest) = largest_allocation(|| a.decode_image(0));
    let err = result.unwrap_err();
    assert_eq!(
        (err.code, err.pointer.as_str()),
        ("IMAGE_TOO_LARGE", "/images/0")
    );
    assert!(
        err.message.contains("--max-image-pixels"),
        "{}",
        err.message
    );
    assert!(largest < 1 << 20, "{largest}");

    // `velvet bake` fails that file, names the image, the limit and the flag, and writes
    // nothing.
    let before = tree(dir.path());
    let output = dir.path().join("out/chair.gltf");
    let (status, out, _) = velvet(&["bake", s(&path), "-o", s(&output)]);
    assert_eq!(status, 1, "{out}");
    assert!(
        out.contains("FAILED: cannot bake image 0: sheenColor + sheenRoughness: image 0: PNG: the image declares 100000 × 100000 = 10000000000 pixels, over the limit of 268435456 (raise it with --max-image-pixels)"),
        "{out}"
    );
    assert_eq!(tree(dir.path()), before);
}

#[test]
fn the_pixel_limit_is_inclusive_and_raised_by_its_flag() {
    let dir = tempfile::tempdir().unwrap();
    write(
        &dir.path().join("tex.png"),
        png(4, 4, image::ExtendedColorType::Rgba8),
    );
    let path = dir.path().join("chair.gltf");
    write(&path, sheen_document("tex.png").to_string());
    let output = dir.path().join("out/chair.gltf");
    let (status, out, _) = velvet(&[
        "bake",
        s(&path),
        "-o",
        s(&output),
        "--max-image-pixels",
        "15",
    ]);
    assert_eq!(status, 1, "{out}");
    assert!(
        out.contains("4 × 4 = 16 pixels, over the limit of 15 (raise it with --max-image-pixels)"),
        "{out}"
    );
    assert!(!output.exists());
    let (status, out, _) = velvet(&[
        "bake",
        s(&path),
        "-o",
        s(&output),
        "--max-image-pixels",
        "16",
    ]);
    assert_eq!(status, 0, "{out}");
    assert!(output.exists());

    // migrate bakes the mapped roughness texture under the same limit.
    let migrated = dir.path().join("out/migrated.gltf");
    let (status, out, _) = velvet(&[
        "migrate",
        s(&path),
        "-o",
        s(&migrated),
        "--max-image-pixels",
        "15",
    ]);
    assert_eq!(status, 1, "{out}");
    assert!(
        out.contains("4 × 4 = 16 pixels, over the limit of 15 (raise it with --max-image-pixels)"),
        "{out}"
    );
    assert!(!migrated.exists());
    let (status, out, _) = velvet(&["migrate", s(&path), "-o", s(&migrated)]);
    assert_eq!(status, 0, "{out}");
}

#[test]
fn percent_encoded_data_uris_are_read_with_a_warning_and_malformed_ones_refused() {
    // RFC 2397's percent-encoded form is valid glTF: the image is read from it (its header is
    // checked) and the only finding is the warning that some loaders decode base64 alone.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("chair.gltf");
    let bytes = png(2, 2, image::ExtendedColorType::Rgba8);
    let encoded =
        percent_encoding::percent_encode(&bytes, percent_encoding::NON_ALPHANUMERIC).to_string();
    write(
        &path,
        sheen_document(&format!("data:image/png,{encoded}")).to_string(),
    );
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let report = validator.validate_file(&path);
    let found: Vec<_> = report
        .findings
        .iter()
        .map(|f| (f.diagnostic.code, f.diagnostic.pointer.as_str()))
        .collect();
    assert_eq!(found, [("DATA_URI_NOT_BASE64", "/images/0/uri")]);
    assert_eq!(report.counts.errors, 0);

    // A '%' without two hexadecimal digits decodes to nothing: refused, by validate and bake.
    write(
        &path,
        sheen_document("data:image/png,%89PNG%zz").to_string(),
    );
    let report = validator.validate_file(&path);
    let refused = "the data: URI's payload has a '%' not followed by two hexadecimal digits";
    let found: Vec<_> = report
        .findings
        .iter()
        .filter(|f| f.diagnostic.code == "INVALID_URI")
        .map(|f| (f.diagnostic.pointer.as_str(), f.diagnostic.message.as_str()))
        .collect();
    assert_eq!(found, [("/images/0/uri", refused)]);
    let output = dir.path().join("out.gltf");
    let (status, out, _) = velvet(&["bake", s(&path), "-o", s(&output)]);
    assert_eq!(status, 1, "{out}");
    assert!(out.contains(refused), "{out}");
    assert!(!output.exists());
}

// ---------------------------------------------------------------------------------------------
// Paths

/// root/assets/chair.gltf whose roughness texture is `uri`, and root/shared/rgb.png (no alpha).
fn chair_reading(root: &Path, uri: &str) -> PathBuf {
    write(
        &root.join("shared/rgb.png"),
        png(2, 2, image::ExtendedColorType::Rgb8),
    );
    let path = root.join("assets/chair.gltf");
    write(&path, sheen_document(uri).to_string());
    path
}

#[test]
fn uris_leaving_the_folder_are_read_only_with_the_flag() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().canonicalize().unwrap();
    let absolute = root.join("shared/rgb.png");
    let file_uri = format!("file://{}", absolute.display());
    for uri in [
        "../shared/rgb.png",
        absolute.to_str().unwrap(),
        file_uri.as_str(),
    ] {
        let path = chair_reading(&root, uri);
        let (status, out, _) = velvet(&["validate", "--format", "json", s(&path)]);
        assert_eq!(status, 1, "{uri}: {out}");
        let report: Value = serde_json::from_str(&out).unwrap();
        let messages: Vec<(&str, &str)> = report["issues"]["messages"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| (m["code"].as_str().unwrap(), m["pointer"].as_str().unwrap()))
            .collect();
        assert_eq!(messages, [("URI_NOT_FOLLOWED", "/images/0/uri")], "{uri}");
        assert!(out.contains("--allow-outside-uris reads it"), "{out}");
        // With the flag the image is read: its header has no alpha.
        let (_, out, _) = velvet(&[
            "validate",
            "--format",
            "json",
            "--allow-outside-uris",
            s(&path),
        ]);
        let report: Value = serde_json::from_str(&out).unwrap();
        let found: Vec<&str> = report["issues"]["messages"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["code"].as_str().unwrap())
            .collect();
        assert_eq!(
            found,
            ["KHR_MATERIALS_SHEEN_ROUGHNESS_TEXTURE_WITHOUT_ALPHA"],
            "{uri}"
        );
    }
    // Remote URLs are never fetched, flag or not: valid glTF, reported as not checked.
    let path = chair_reading(&root, "https://example.com/rgb.png");
    let (_, out, _) = velvet(&["validate", "--allow-outside-uris", s(&path)]);
    assert!(out.contains("warning NON_RELATIVE_URI"), "{out}");
}

#[test]
fn writing_never_follows_outside_uris_and_outputs_stay_in_the_out_dir() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    write(
        &root.join("shared/tex.png"),
        png(2, 2, image::ExtendedColorType::Rgba8),
    );
    write(&root.join("shared/mesh.bin"), [0u8; 12]);
    let mut doc = sheen_document("../shared/tex.png");
    // A name that would climb out of the output folder if it became a path.
    doc["images"][0]["name"] = json!("../../../escaped");
    doc["buffers"] = json!([{"byteLength": 12, "uri": "../shared/mesh.bin"}]);
    let input = root.join("assets/chair.gltf");
    write(&input, doc.to_string());
    let before = tree(root);
    let out_dir = root.join("out");

    let (status, out, _) = velvet(&[
        "bake",
        s(&root.join("assets")),
        "--out-dir",
        s(&out_dir),
        "--allow-outside-uris",
        "--rewrite-uris",
    ]);
    assert_eq!(status, 0, "{out}");
    let (status, out, _) = velvet(&[
        "migrate",
        s(&root.join("assets")),
        "--out-dir",
        s(&out_dir.join("migrated")),
        "--allow-outside-uris",
        "--rewrite-uris",
    ]);
    assert_eq!(status, 0, "{out}");

    // Nothing outside out/ changed or appeared; inside, only the outputs and baked images.
    let after = tree(root);
    for (path, bytes) in &before {
        assert_eq!(after.get(path), Some(bytes), "{} changed", path.display());
    }
    let new: Vec<&PathBuf> = after.keys().filter(|p| !before.contains_key(*p)).collect();
    assert_eq!(
        new,
        [
            // The name's separators became '_' and its leading dots went: the file stays in the
            // output folder, and is not hidden.
            Path::new("out/_.._.._escaped.sheenColor.sheenRoughness.672616e9c6e7.png"),
            Path::new("out/chair.gltf"),
            // migrate's fitted roughness bakes the mapped roughness texture beside its output.
            Path::new("out/migrated/_.._.._escaped.fuzzRoughness.665bcce6978c.png"),
            Path::new("out/migrated/chair.gltf"),
        ]
    );
    // The outside resources are referenced where they are, not copied next to the outputs.
    let baked: Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("chair.gltf")).unwrap()).unwrap();
    assert_eq!(baked["buffers"][0]["uri"], "../assets/../shared/mesh.bin");
    let migrated: Value =
        serde_json::from_slice(&std::fs::read(out_dir.join("migrated/chair.gltf")).unwrap())
            .unwrap();
    assert_eq!(
        migrated["images"][0]["uri"],
        "../../assets/../shared/tex.png"
    );
    // Both outputs load with the flag.
    for output in [
        out_dir.join("chair.gltf"),
        out_dir.join("migrated/chair.gltf"),
    ] {
        let (status, out, _) = velvet(&["validate", "--allow-outside-uris", s(&output)]);
        assert_eq!(status, 0, "{out}");
    }
}

/// An absolute path or a `file:` URI cannot be kept by a self-contained output any more than
/// `../` can: migrate and bake into another folder fail the file naming the URI, write
/// nothing, and with --rewrite-uris keep the URI as it is.
#[test]
fn absolute_and_file_uris_fail_a_self_contained_output_as_dot_dot_does() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path();
    let texture = root.join("shared/tex.png");
    write(&texture, png(2, 2, image::ExtendedColorType::Rgba8));
    let absolute = texture.to_str().unwrap().to_owned();
    for (name, uri) in [
        ("absolute", absolute.clone()),
        ("file-uri", format!("file://{absolute}")),
        ("dot-dot", "../shared/tex.png".to_owned()),
    ] {
        let input = root.join(format!("assets/{name}.gltf"));
        write(&input, sheen_document(&uri).to_string());
        for command in ["migrate", "bake"] {
            let out_dir = root.join(format!("out-{command}-{name}"));
            let (status, out, err) = velvet(&[
                command,
                s(&input),
                "--out-dir",
                s(&out_dir),
                "--allow-outside-uris",
            ]);
            assert_eq!(status, 1, "{command} {name}: {out}{err}");
            let why = if name == "dot-dot" {
                format!("'{uri}' leads out of the input's folder, so a self-contained output cannot keep it (--rewrite-uris refers to it where it is)")
            } else {
                format!("'{uri}' names a file by its absolute place, so a self-contained output cannot keep it (--rewrite-uris keeps it as it is)")
            };
            assert!(out.contains(&why), "{command} {name}: {out}");
            assert!(!out_dir.exists(), "{command} {name}");
        }
        if name != "dot-dot" {
            let out_dir = root.join(format!("out-rewrite-{name}"));
            let (status, out, err) = velvet(&[
                "migrate",
                s(&input),
                "--out-dir",
                s(&out_dir),
                "--allow-outside-uris",
                "--rewrite-uris",
            ]);
            assert_eq!(status, 0, "{name}: {out}{err}");
            let migrated: Value = serde_json::from_slice(
                &std::fs::read(out_dir.join(format!("{name}.gltf"))).unwrap(),
            )
            .unwrap();
            assert_eq!(migrated["images"][0]["uri"], json!(uri), "{name}");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Nothing lost

/// `count` sheen documents under `root/in`, and what an uninterrupted migration makes of them.
fn batch(root: &Path, count: usize) -> (PathBuf, BTreeMap<PathBuf, Vec<u8>>) {
    let input = root.join("in");
    for i in 0..count {
        let mut doc = sheen_document("tex.png");
        doc["materials"][0]["name"] = json!(format!("cloth {i}"));
        doc["extras"] = json!({"padding": "x".repeat(4000)});
        write(
            &input.join(format!("{i:03}.gltf")),
            serde_json::to_string_pretty(&doc).unwrap(),
        );
    }
    let reference = root.join("reference");
    let (status, out, _) = velvet(&["migrate", s(&input), "--out-dir", s(&reference)]);
    assert_eq!(status, 0, "{out}");
    let expected = tree(&reference);
    assert_eq!(expected.len(), count);
    std::fs::remove_dir_all(&reference).unwrap();
    (input, expected)
}

/// Splits a folder's files into complete outputs (checked against `expected`) and leftover
/// temporary files; anything else fails the test.
fn complete_outputs(
    dir: &Path,
    expected: &BTreeMap<PathBuf, Vec<u8>>,
) -> (Vec<PathBuf>, Vec<PathBuf>) {
    let (mut outputs, mut temporaries) = (Vec::new(), Vec::new());
    if !dir.exists() {
        return (outputs, temporaries);
    }
    for (path, bytes) in tree(dir) {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with(".velvet-") && name.ends_with(".tmp") {
            temporaries.push(path);
        } else {
            assert!(
                expected.get(&path) == Some(&bytes),
                "{} is not a complete output",
                path.display()
            );
            outputs.push(path);
        }
    }
    (outputs, temporaries)
}

#[test]
fn an_injected_write_error_leaves_no_partial_output_and_the_inputs_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let (input, expected) = batch(dir.path(), 6);
    let inputs_before = tree(&input);
    let out_dir = dir.path().join("out");
    let (status, out, _) = velvet_env(
        &["migrate", s(&input), "--out-dir", s(&out_dir)],
        &[("VELVET_TEST_WRITE_FAULT", "error:2")],
    );
    assert_eq!(status, Some(1), "{out}");
    let (outputs, temporaries) = complete_outputs(&out_dir, &expected);
    assert_eq!(outputs.len(), 2, "{out}");
    assert_eq!(
        temporaries,
        Vec::<PathBuf>::new(),
        "a failed write cleans up"
    );
    assert_eq!(out.matches(": injected write fault").count(), 4, "{out}");
    assert!(out.contains(", 4 failed"), "{out}");
    assert_eq!(tree(&input), inputs_before);

    // In place: every write fails, every input keeps its bytes.
    let (status, out, _) = velvet_env(
        &["migrate", s(&input), "--in-place"],
        &[("VELVET_TEST_WRITE_FAULT", "error:0")],
    );
    assert_eq!(status, Some(1), "{out}");
    assert_eq!(tree(&input), inputs_before);
}

#[test]
fn an_interrupted_batch_leaves_only_complete_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (input, expected) = batch(dir.path(), 12);
    let inputs_before = tree(&input);
    let out_dir = dir.path().join("out");
    // The process aborts halfway through its fourth write, as a kill would.
    let (status, out, _) = velvet_env(
        &["migrate", s(&input), "--out-dir", s(&out_dir)],
        &[("VELVET_TEST_WRITE_FAULT", "abort:3")],
    );
    assert_eq!(status, None, "killed by a signal: {out}");
    let (outputs, temporaries) = complete_outputs(&out_dir, &expected);
    assert!(outputs.len() <= 3, "{outputs:?}");
    assert!(
        !temporaries.is_empty(),
        "the interrupted write was mid-file"
    );
    assert_eq!(tree(&input), inputs_before);
    // A rerun completes the batch and removes the staging files the killed run left (its
    // process is gone).
    let (status, out, _) = velvet(&["migrate", s(&input), "--out-dir", s(&out_dir)]);
    assert_eq!(status, 0, "{out}");
    let (outputs, temporaries) = complete_outputs(&out_dir, &expected);
    assert_eq!(outputs.len(), 12);
    assert_eq!(temporaries, Vec::<PathBuf>::new());

    // In place: every input is its old bytes or its complete migration.
    let in_place = dir.path().join("in-place");
    std::fs::create_dir(&in_place).unwrap();
    for (path, bytes) in &inputs_before {
        write(&in_place.join(path), bytes);
    }
    let (status, _, _) = velvet(&["migrate", s(&in_place), "--in-place"]);
    assert_eq!(status, 0);
    let expected = tree(&in_place);
    let (status, _, _) = velvet_env(
        &["migrate", s(&input), "--in-place"],
        &[("VELVET_TEST_WRITE_FAULT", "abort:5")],
    );
    assert_eq!(status, None);
    let mut migrated = 0;
    for (path, bytes) in tree(&input) {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with(".velvet-") {
            continue;
        }
        if bytes != inputs_before[&path] {
            assert!(expected.get(&path) == Some(&bytes), "{}", path.display());
            migrated += 1;
        }
    }
    assert!(migrated <= 5, "{migrated}");
}

/// Runs `script` (sh) in a new user and mount namespace, where a tmpfs can be mounted without
/// privileges; `None` when this system does not allow that.
fn in_mount_namespace(script: &str, args: &[&str]) -> Option<std::process::Output> {
    let probe = Command::new("unshare")
        .args(["--user", "--map-root-user", "--mount", "true"])
        .output()
        .ok()?;
    if !probe.status.success() {
        return None;
    }
    Some(
        Command::new("unshare")
            .args([
                "--user",
                "--map-root-user",
                "--mount",
                "sh",
                "-c",
                script,
                "sh",
            ])
            .args(args)
            .env_remove("VELVET_TEST_WRITE_FAULT")
            .output()
            .unwrap(),
    )
}

#[test]
fn a_read_only_output_folder_fails_without_output() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = batch(dir.path(), 2);
    let inputs_before = tree(&input);
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    std::fs::set_permissions(&out_dir, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Permission bits do not stop a privileged user: then a read-only mount does.
    let privileged = std::fs::write(out_dir.join("probe"), b"").is_ok();
    let (status, out) = if !privileged {
        let (status, out, _) = velvet(&["migrate", s(&input), "--out-dir", s(&out_dir)]);
        (status, out)
    } else {
        std::fs::remove_file(out_dir.join("probe")).unwrap();
        let Some(output) = in_mount_namespace(
            r#"mount -t tmpfs -o ro tmpfs "$2" && "$1" migrate "$3" --out-dir "$2"; s=$?; ls -A "$2"; exit $s"#,
            &[env!("CARGO_BIN_EXE_velvet"), s(&out_dir), s(&input)],
        ) else {
            panic!("running privileged without user namespaces: no way to make a read-only folder");
        };
        (
            output.status.code().unwrap(),
            String::from_utf8_lossy(&output.stdout).into_owned(),
        )
    };
    std::fs::set_permissions(&out_dir, std::fs::Permissions::from_mode(0o755)).unwrap();
    assert_eq!(status, 1, "{out}");
    assert_eq!(out.matches("FAILED: cannot write").count(), 2, "{out}");
    assert!(
        out.contains("Permission denied") || out.contains("Read-only file system"),
        "{out}"
    );
    assert_eq!(tree(&out_dir).len(), 0);
    assert_eq!(tree(&input), inputs_before);
}

#[test]
fn a_full_disk_fails_without_partial_output_when_a_tiny_tmpfs_can_be_made() {
    let dir = tempfile::tempdir().unwrap();
    let (input, _) = batch(dir.path(), 1);
    let file = input.join("000.gltf");
    let mut doc: Value = serde_json::from_slice(&std::fs::read(&file).unwrap()).unwrap();
    doc["extras"]["padding"] = json!("x".repeat(64 * 1024));
    write(&file, serde_json::to_string_pretty(&doc).unwrap());
    let inputs_before = tree(&input);
    std::fs::create_dir(dir.path().join("out")).unwrap();
    let Some(output) = in_mount_namespace(
        r#"mount -t tmpfs -o size=16k tmpfs "$2" || exit 99; "$1" migrate "$3" --out-dir "$2"; s=$?; echo "files:"; ls -A "$2"; exit $s"#,
        &[
            env!("CARGO_BIN_EXE_velvet"),
            s(&dir.path().join("out")),
            s(&file),
        ],
    ) else {
        eprintln!("skipped: this system does not let an unprivileged user mount a tmpfs");
        return;
    };
    let stdout = String::from_utf8_lossy(&output.stdout);
    if output.status.code() == Some(99) {
        eprintln!("skipped: mounting a tmpfs failed: {stdout}");
        return;
    }
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    assert!(stdout.contains("No space left on device"), "{stdout}");
    let listing = stdout.rsplit("files:\n").next().unwrap();
    assert_eq!(listing, "", "the full folder is left empty");
    assert_eq!(tree(&input), inputs_before);
}

// ---------------------------------------------------------------------------------------------
// Under load

#[test]
fn files_that_vanish_or_dangle_get_a_clear_error_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("assets");
    for name in ["a.gltf", "b.gltf", "c.gltf"] {
        write(&folder.join(name), sheen_document("tex.png").to_string());
    }
    write(
        &folder.join("tex.png"),
        png(2, 2, image::ExtendedColorType::Rgba8),
    );
    std::os::unix::fs::symlink(folder.join("gone.gltf"), folder.join("dangling.gltf")).unwrap();
    // A link named like an asset is reported, not skipped.
    let (status, out, _) = velvet(&["validate", "--format", "json", s(&folder)]);
    assert_eq!(status, 1, "{out}");
    let reports: Value = serde_json::from_str(&out).unwrap();
    let summary: Vec<(String, Vec<String>)> = reports
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                Path::new(r["uri"].as_str().unwrap())
                    .file_name()
                    .unwrap()
                    .to_string_lossy()
                    .into_owned(),
                r["issues"]["messages"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .filter(|m| m["severity"] == 0)
                    .map(|m| m["code"].as_str().unwrap().to_owned())
                    .collect(),
            )
        })
        .collect();
    assert_eq!(
        summary,
        [
            ("a.gltf".to_owned(), vec![]),
            ("b.gltf".to_owned(), vec![]),
            ("c.gltf".to_owned(), vec![]),
            ("dangling.gltf".to_owned(), vec!["IO_ERROR".to_owned()]),
        ]
    );
    assert!(
        out.contains("dangling.gltf: No such file or directory"),
        "{out}"
    );

    // Files deleted or cut short between discovery and loading.
    let (files, errors) = velvet::asset::discover::collect(std::slice::from_ref(&folder));
    assert!(errors.is_empty());
    assert_eq!(files.len(), 4);
    std::fs::remove_file(folder.join("a.gltf")).unwrap();
    write(&folder.join("b.gltf"), br#"{"asset": {"vers"#);
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let found: Vec<(&str, String)> = files[..2]
        .iter()
        .map(|f| validator.validate_file(f))
        .map(|r| {
            let d = &r.findings[0].diagnostic;
            (d.code, d.message.clone())
        })
        .collect();
    assert_eq!(found[0].0, "IO_ERROR");
    assert_eq!(
        found[0].1,
        format!(
            "cannot read {}: No such file or directory (os error 2)",
            folder.join("a.gltf").display()
        )
    );
    assert_eq!(
        found[1],
        (
            "INVALID_JSON",
            "line 1, column 16: EOF while parsing a string".to_owned()
        )
    );

    // migrate: the dangling link fails, the others are migrated.
    let out_dir = dir.path().join("out");
    let (status, out, _) = velvet(&["migrate", s(&folder), "--out-dir", s(&out_dir)]);
    assert_eq!(status, 1, "{out}");
    assert!(
        out.contains("dangling.gltf cannot be migrated: cannot read"),
        "{out}"
    );
    assert!(
        out.contains("b.gltf cannot be migrated: line 1, column 16"),
        "{out}"
    );
    assert_eq!(
        tree(&out_dir).into_keys().collect::<Vec<_>>(),
        // c.gltf, the fuzz roughness texture its fitted mapping bakes (named with a hash of
        // its bytes), and the source texture, copied so that the output is self-contained.
        [
            PathBuf::from("c.gltf"),
            PathBuf::from("tex.fuzzRoughness.665bcce6978c.png"),
            PathBuf::from("tex.png")
        ]
    );
}

#[test]
fn a_resource_that_is_not_a_regular_file_is_not_read() {
    let dir = tempfile::tempdir().unwrap();
    // A link to a device outside the folder is refused before anything is opened.
    std::os::unix::fs::symlink("/dev/zero", dir.path().join("zero.bin")).unwrap();
    // A folder inside it is not a regular file.
    std::fs::create_dir(dir.path().join("folder.bin")).unwrap();
    let doc = json!({"asset": {"version": "2.0"}, "buffers": [
        {"byteLength": 4, "uri": "zero.bin"},
        {"byteLength": 4, "uri": "folder.bin"}
    ]});
    let path = dir.path().join("a.gltf");
    write(&path, doc.to_string());
    let a = asset::load(&path).asset.unwrap();
    let err = a.buffer_bytes(0).unwrap_err();
    assert_eq!(err.code, "URI_NOT_FOLLOWED");
    assert!(
        err.message
            .starts_with("'zero.bin' leads out of the asset's folder through a symbolic link"),
        "{}",
        err.message
    );
    let err = a.buffer_bytes(1).unwrap_err();
    assert_eq!(err.code, "IO_ERROR");
    assert!(
        err.message.ends_with("not a regular file"),
        "{}",
        err.message
    );
}

// ---------------------------------------------------------------------------------------------
// Inputs found by fuzzing (fixtures/hostile/<target>-*.gltf|glb; docs/fuzzing.md tells which
// run found each)

fn error_findings(report: &velvet::validate::FileReport) -> Vec<(&str, &str)> {
    report
        .findings
        .iter()
        .filter(|f| f.diagnostic.severity == velvet::diagnostics::Severity::Error)
        .map(|f| (f.diagnostic.code, f.diagnostic.pointer.as_str()))
        .collect()
}

#[test]
fn fuzz_data_joints_shorter_than_their_weights_are_read_no_further_than_their_end() {
    // The skinning check read the joints as far as the weights went, past the joints' bytes:
    // a panic. Now both are read as far as the shorter goes, and the unequal counts are the
    // primitive's finding.
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let report = validator.validate_file(&fixture("data-joints-shorter-than-weights.gltf"));
    assert_eq!(
        error_findings(&report),
        [(
            "MESH_PRIMITIVE_UNEQUAL_ACCESSOR_COUNT",
            "/meshes/0/primitives/0/attributes/JOINTS_0"
        )]
    );
}

#[test]
fn fuzz_validate_a_position_naming_no_accessor_is_a_dangling_reference() {
    // The gltf crate's core check looked the POSITION accessor up without checking the index.
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let report = validator.validate_file(&fixture("validate-dangling-position-accessor.gltf"));
    let positions: Vec<_> = error_findings(&report)
        .into_iter()
        .filter(|(_, p)| p.ends_with("/attributes/POSITION"))
        .collect();
    assert_eq!(
        positions,
        [
            (
                "UNRESOLVED_REFERENCE",
                "/meshes/0/primitives/0/attributes/POSITION"
            ),
            (
                "UNRESOLVED_REFERENCE",
                "/meshes/1/primitives/0/attributes/POSITION"
            ),
        ]
    );
    // Ten dangling references, the out-of-range sheen factor, and the missing .bin.
    assert_eq!(report.counts.errors, 12);
    // The smallest such document: that reference is its only fault.
    let loaded = asset::load_bytes(
        Path::new("memory/a.gltf"),
        br#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":5}}]}]}"#,
    );
    let report = validator.validate_loaded(Path::new("memory/a.gltf"), loaded);
    assert_eq!(
        error_findings(&report),
        [(
            "UNRESOLVED_REFERENCE",
            "/meshes/0/primitives/0/attributes/POSITION"
        )]
    );
    assert_eq!(
        report.findings[0].diagnostic.message,
        "POSITION names accessor 5, but the asset has 0 accessors"
    );
}

#[test]
fn bake_leaves_a_document_whose_arrays_are_not_arrays_of_objects() {
    let dir = tempfile::tempdir().unwrap();
    let rgba = png(2, 2, image::ExtendedColorType::Rgba8);
    for (key, value) in [
        ("buffers", json!([5])),
        ("buffers", json!({})),
        ("bufferViews", json!("x")),
        ("textures", json!([{"source": 0}, 7])),
    ] {
        let mut doc = sheen_document("unused");
        doc["images"] = json!([{"bufferView": 0, "mimeType": "image/png"}]);
        doc["bufferViews"] = json!([{"buffer": 0, "byteLength": rgba.len()}]);
        doc["buffers"] = json!([{"byteLength": rgba.len()}]);
        doc[key] = value;
        let input = dir.path().join(format!("{key}.glb"));
        write(&input, glb::join(doc.to_string().as_bytes(), Some(&rgba)));
        let output = dir.path().join(format!("{key}.out.glb"));
        let (status, out, _) = velvet(&["bake", s(&input), "-o", s(&output), "--verbose"]);
        assert_eq!(status, 0, "{out}");
        assert!(
            out.contains("nothing to bake, copied as it is (1 warning)"),
            "{out}"
        );
        assert!(
            out.contains(&format!(
                "warning /{key}: {key} is not an array of objects, as glTF requires; nothing is baked"
            )),
            "{out}"
        );
        assert_eq!(
            std::fs::read(&output).unwrap(),
            std::fs::read(&input).unwrap()
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Inputs read as a snapshot

/// A sheen document of about 2 MiB (large files were once mapped rather than read), its
/// materials named `cloth N`.
fn large_sheen_text() -> String {
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [],
    });
    for i in 0..400 {
        doc["materials"].as_array_mut().unwrap().push(json!({
            "name": format!("cloth {i} {}", "x".repeat(5000)),
            "extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [0.5, 0.25, 1.0],
                "sheenRoughnessFactor": 0.75
            }}
        }));
    }
    let text = serde_json::to_string_pretty(&doc).unwrap();
    assert!(text.len() > 2 << 20);
    text
}

/// Overwrites `len` bytes of `path` at `at` with `byte`, in place (no new file, same size), as
/// an editor or a sync client writing into the file would.
fn rewrite_in_place(path: &Path, at: u64, len: usize, byte: u8) {
    use std::io::{Seek, SeekFrom, Write};
    let mut file = std::fs::OpenOptions::new().write(true).open(path).unwrap();
    file.seek(SeekFrom::Start(at)).unwrap();
    file.write_all(&vec![byte; len]).unwrap();
    file.sync_all().unwrap();
}

/// An input another program rewrites in place between velvet reading it and writing its
/// migration (here with bytes that are not UTF-8, which once made velvet panic) is not written:
/// the migration fails naming the file, and the file keeps the other program's bytes.
#[test]
fn an_input_rewritten_during_migrate_in_place_fails_naming_it_without_a_write() {
    use velvet::migrate::apply::{execute, plan_file};
    use velvet::output::files::Claims;
    use velvet::output::paths::Job;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("large.gltf");
    write(&input, large_sheen_text());
    let job = Job {
        input: input.clone(),
        output: Some(input.clone()),
    };
    let mut plan = plan_file(&job, &velvet::migrate::Options::default()).unwrap();
    assert!(plan.changes());
    rewrite_in_place(&input, 100_000, 4096, 0xff);
    let rewritten = std::fs::read(&input).unwrap();
    let error = execute(&mut plan, &Claims::default()).unwrap_err();
    assert_eq!(
        error,
        format!(
            "{} changed while velvet worked on it (another program wrote it); nothing was \
             written for it",
            input.display()
        )
    );
    assert_eq!(std::fs::read(&input).unwrap(), rewritten);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// A file last written long before it was read gets no digest: its times alone tell a later
/// write, and an output to another folder is not written either.
#[test]
fn an_input_rewritten_after_it_was_read_is_caught_by_its_times_alone() {
    use velvet::migrate::apply::{execute, plan_file};
    use velvet::output::files::Claims;
    use velvet::output::paths::Job;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("old.gltf");
    write(&input, large_sheen_text());
    // Last written an hour ago: no digest is taken, the times decide.
    let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    std::fs::File::options()
        .write(true)
        .open(&input)
        .unwrap()
        .set_modified(hour_ago)
        .unwrap();
    let out = dir.path().join("out");
    let job = Job {
        input: input.clone(),
        output: Some(out.join("old.gltf")),
    };
    let mut plan = plan_file(&job, &velvet::migrate::Options::default()).unwrap();
    rewrite_in_place(&input, 100_000, 16, b' ');
    let error = execute(&mut plan, &Claims::default()).unwrap_err();
    assert!(
        error.starts_with(&format!(
            "{} changed while velvet worked on it",
            input.display()
        )),
        "{error}"
    );
    assert!(!out.join("old.gltf").exists());
}

// ---------------------------------------------------------------------------------------------
// No aliasing

/// A document whose sheen changes and whose buffer and image are files beside it.
fn document_with_resources(dir: &Path) -> PathBuf {
    write(&dir.join("geometry.bin"), [7u8; 64]);
    write(
        &dir.join("tex.png"),
        png(4, 4, image::ExtendedColorType::Rgba8),
    );
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "buffers": [{"uri": "geometry.bin", "byteLength": 64}],
        "images": [{"uri": "tex.png"}],
        "textures": [{"source": 0}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
            "extensions": {"KHR_materials_sheen": {
                "sheenColorFactor": [0.5, 0.25, 1.0],
                "sheenRoughnessFactor": 0.75
            }}
        }]
    });
    let path = dir.join("asset.gltf");
    write(&path, serde_json::to_string_pretty(&doc).unwrap());
    path
}

/// The resources an output in another folder needs are files of their own: no output resource
/// shares an inode with its input, and writing into one in place leaves the input as it was.
#[cfg(unix)]
#[test]
fn an_output_resource_never_shares_an_inode_with_its_input() {
    use std::io::Write;
    use std::os::unix::fs::MetadataExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    document_with_resources(&input);
    for command in ["migrate", "bake"] {
        let out = dir.path().join(format!("out-{command}"));
        let (status, stdout, stderr) = velvet(&[command, s(&input), "--out-dir", s(&out)]);
        assert_eq!(status, 0, "{stdout}{stderr}");
        for name in ["geometry.bin", "tex.png"] {
            let (from, to) = (input.join(name), out.join(name));
            let before = std::fs::read(&from).unwrap();
            assert_eq!(std::fs::read(&to).unwrap(), before, "{command} {name}");
            let meta = |p: &Path| std::fs::metadata(p).unwrap();
            assert_ne!(
                (meta(&from).dev(), meta(&from).ino()),
                (meta(&to).dev(), meta(&to).ino()),
                "{command} {name}"
            );
            assert_eq!(meta(&from).nlink(), 1, "{command} {name}");
            std::fs::OpenOptions::new()
                .write(true)
                .open(&to)
                .unwrap()
                .write_all(b"EDITED IN PLACE")
                .unwrap();
            assert_eq!(std::fs::read(&from).unwrap(), before, "{command} {name}");
        }
    }
}

/// `--in-place` on a symbolic link migrates the file it leads to and keeps the link; a folder
/// holding a link and its target migrates the file once; a link leading out of the folder
/// given is refused before anything is written (exit status 2).
#[cfg(unix)]
#[test]
fn in_place_on_a_link_migrates_its_target_and_keeps_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let reference = dir.path().join("reference");
    let reference_doc = document_with_resources(&reference);
    let (status, _, stderr) = velvet(&["migrate", "--in-place", s(&reference_doc)]);
    assert_eq!(status, 0, "{stderr}");
    let migrated = std::fs::read(&reference_doc).unwrap();

    let tree = dir.path().join("tree");
    let real = document_with_resources(&tree.join("real"));
    let original = std::fs::read(&real).unwrap();
    assert_ne!(original, migrated);
    let link = tree.join("link.gltf");
    std::os::unix::fs::symlink("real/asset.gltf", &link).unwrap();
    let (status, stdout, stderr) = velvet(&["migrate", "--in-place", s(&link)]);
    // A link named alone leads into its own folder's tree: accepted.
    assert_eq!(status, 0, "{stdout}{stderr}");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert_eq!(
        std::fs::read_link(&link).unwrap(),
        Path::new("real/asset.gltf")
    );
    assert_eq!(std::fs::read(&real).unwrap(), migrated);

    // The folder holding both: the one file is migrated once, no collision is claimed.
    std::fs::write(&real, &original).unwrap();
    let (status, stdout, stderr) = velvet(&["migrate", "--in-place", s(&tree)]);
    assert_eq!(status, 0, "{stdout}{stderr}");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert_eq!(std::fs::read(&real).unwrap(), migrated);

    // A link out of the folder given: refused, nothing written.
    let inner = tree.join("real");
    let outside = dir.path().join("outside");
    let outside_doc = document_with_resources(&outside);
    let before = std::fs::read(&outside_doc).unwrap();
    std::os::unix::fs::symlink(&outside_doc, inner.join("away.gltf")).unwrap();
    let (status, stdout, stderr) = velvet(&["migrate", "--in-place", s(&inner)]);
    assert_eq!(status, 2, "{stdout}{stderr}");
    assert_eq!(
        stderr,
        format!(
            "velvet: --in-place: {} is a symbolic link to {}, outside {}; velvet writes only \
             inside the folders it is given (name the target itself to migrate it)\n",
            inner.join("away.gltf").display(),
            outside_doc.canonicalize().unwrap().display(),
            inner.display()
        )
    );
    assert_eq!(std::fs::read(&outside_doc).unwrap(), before);
}

// ---------------------------------------------------------------------------------------------
// Output escapes what it did not write

/// An image URI that would start a GitHub workflow command on a line of its own, and a
/// material name that would retitle a terminal.
const INJECTED_URI: &str = "x\n::error file=README.md,line=1::INJECTED\n.png";
const INJECTED_NAME: &str = "\u{1b}]0;owned\u{7}cloth";

fn injecting_document(dir: &Path) -> PathBuf {
    let mut doc = sheen_document(INJECTED_URI);
    doc["materials"][0]["name"] = json!(INJECTED_NAME);
    let path = dir.join("inject.gltf");
    write(&path, serde_json::to_string_pretty(&doc).unwrap());
    path
}

/// Asserts that `output` holds no control character but newlines and that no line of it is a
/// workflow command other than velvet's own (`allowed` of them, none the injected one).
fn assert_inert(output: &str, allowed: usize, what: &str) {
    assert!(
        !output.chars().any(|c| c.is_control() && c != '\n'),
        "{what}: {output:?}"
    );
    let commands: Vec<&str> = output.lines().filter(|l| l.starts_with("::")).collect();
    assert_eq!(commands.len(), allowed, "{what}: {output}");
    assert!(
        !commands
            .iter()
            .any(|l| l.starts_with("::error file=README.md")),
        "{what}: {output}"
    );
}

/// A URI holding a newline and `::error` prints no workflow command, in any format or command,
/// and a name holding an escape sequence reaches no terminal: both are shown as escapes.
#[test]
fn a_uri_with_a_newline_and_error_prints_no_workflow_command() {
    let dir = tempfile::tempdir().unwrap();
    let path = injecting_document(dir.path());
    let shown_uri = "x\\u000a::error file=README.md,line=1::INJECTED\\u000a.png";

    let (status, out, err) = velvet(&["validate", s(&path)]);
    assert_eq!(status, 1, "{out}{err}");
    assert_inert(&out, 0, "validate text");
    assert_inert(&err, 0, "validate text, stderr");
    assert!(out.contains(shown_uri), "{out}");

    let (status, out, err) = velvet(&["validate", "--format", "github", s(&path)]);
    assert_eq!(status, 1, "{out}{err}");
    let findings = out.lines().count();
    assert!(findings >= 1);
    assert_inert(&out, findings, "validate github");
    assert!(out.contains(shown_uri), "{out}");

    for command in ["migrate", "bake"] {
        let (_, out, err) = velvet(&[command, "-v", "--dry-run", s(&path)]);
        assert_inert(&out, 0, command);
        assert_inert(&err, 0, command);
        let (_, out, err) = velvet(&[
            command,
            "-v",
            "--out-dir",
            s(&dir.path().join("o")),
            s(&path),
        ]);
        assert_inert(&out, 0, command);
        assert_inert(&err, 0, command);
        assert!(out.contains("::error file=README.md"), "{command}: {out}");
    }
    let (_, out, _) = velvet(&["migrate", "-v", "--dry-run", s(&path)]);
    assert!(out.contains("\"\\u001b]0;owned\\u0007cloth\""), "{out}");
}

// ---------------------------------------------------------------------------------------------
// The gate

/// Runs velvet with `args`, killing it after 20 s: (exit status, stdout, stderr), status
/// `None` when it had to be killed.
fn velvet_within_20s(args: &[&str]) -> (Option<i32>, String, String) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > std::time::Duration::from_secs(20) {
            child.kill().unwrap();
            child.wait().unwrap();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let (mut out, mut err) = (String::new(), String::new());
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (status, out, err)
}

/// A FIFO or a device named as an input is a usage error (exit status 2) naming it, at once:
/// nothing waits for a writer that never comes.
#[cfg(unix)]
#[test]
fn a_fifo_or_device_named_as_input_is_a_usage_error_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.gltf");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    for command in ["validate", "migrate", "bake"] {
        let mut args = vec![command, s(&fifo)];
        if command != "validate" {
            args.push("--dry-run");
        }
        let (status, out, err) = velvet_within_20s(&args);
        assert_eq!(status, Some(2), "{command}: {out}{err}");
        assert_eq!(
            err,
            format!(
                "velvet: {}: not a regular file or folder (a FIFO); velvet reads assets from \
                 files\n",
                fifo.display()
            ),
            "{command}"
        );
    }
    let (status, _, err) = velvet_within_20s(&["validate", "/dev/zero"]);
    assert_eq!(status, Some(2), "{err}");
    assert_eq!(
        err,
        "velvet: /dev/zero: not a regular file or folder (a character device); velvet reads \
         assets from files\n"
    );
}

/// A velvet.toml that excludes every file found, even one in a folder above the checkout, does
/// not let a run pass as "0 files checked": exit status 2, saying why.
#[test]
fn a_config_that_excludes_every_asset_found_fails_the_run_with_status_2() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("velvet.toml"), "exclude = [\"**\"]\n");
    let checkout = dir.path().join("checkout");
    write(
        &checkout.join("assets/a.gltf"),
        r#"{"asset":{"version":"2.0"}}"#,
    );
    let (status, out, err) = velvet(&["validate", s(&checkout.join("assets"))]);
    assert_eq!(status, 2, "{out}{err}");
    assert_eq!(out, "");
    assert_eq!(
        err,
        format!(
            "velvet: no asset left to check: 1 found, all excluded by the exclude patterns of \
             {}; a run that checks nothing fails\n",
            dir.path().join("velvet.toml").display()
        )
    );
    // Excluding some files is fine: the rest are checked.
    write(
        &dir.path().join("velvet.toml"),
        "exclude = [\"checkout/assets/b.gltf\"]\n",
    );
    write(
        &checkout.join("assets/b.gltf"),
        r#"{"asset":{"version":"2.0"}}"#,
    );
    let (status, out, err) = velvet(&["validate", s(&checkout.join("assets"))]);
    assert_eq!(status, 0, "{out}{err}");
    assert!(out.contains("1 file checked"), "{out}");
}

/// An asset whose path is longer than the system allows (over 4,096 bytes) is reported as an
/// IO_ERROR finding (exit status 1), not skipped by the folder scan.
#[cfg(unix)]
#[test]
fn an_overlong_path_is_a_finding_not_a_silent_skip() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("deep");
    write(&root.join("top.gltf"), r#"{"asset":{"version":"2.0"}}"#);
    // Made from inside, a folder at a time: no single path handed to the system is too long.
    let script = format!(
        "cd '{}' && n=$(printf 'd%.0s' $(seq 200)) && for i in $(seq 22); do mkdir $n && cd -P $n \
         || exit 1; done && printf '{{}}' > deep.gltf",
        root.display()
    );
    let made = Command::new("sh").args(["-c", &script]).status().unwrap();
    assert!(made.success());
    let (status, out, err) = velvet(&["validate", s(&root)]);
    assert_eq!(status, 1, "{out}{err}");
    let io_errors: Vec<&str> = out.lines().filter(|l| l.contains("IO_ERROR")).collect();
    assert_eq!(io_errors.len(), 1, "{out}");
    assert!(
        io_errors[0].ends_with("File name too long (os error 36)"),
        "{}",
        io_errors[0]
    );
    assert!(out.contains("2 files checked"), "{out}");
}

/// An index beyond 64 bits is judged as the number it is: 2^64 + 1 names no texture
/// (UNRESOLVED_REFERENCE, as the reference validator says), and migrate refuses to carry it
/// into a new layer rather than copy it in silence.
#[test]
fn an_index_of_two_to_the_64_plus_one_is_an_unresolved_reference() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge-index.gltf");
    let mut doc = sheen_document("tex.png");
    let text = serde_json::to_string_pretty(&doc).unwrap().replace(
        "\"sheenColorTexture\": {\n            \"index\": 0",
        "\"sheenColorTexture\": {\n            \"index\": 18446744073709551617",
    );
    assert!(text.contains("18446744073709551617"), "{text}");
    write(
        &dir.path().join("tex.png"),
        png(2, 2, image::ExtendedColorType::Rgba8),
    );
    write(&path, &text);
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let report = validator.validate_file(&path);
    assert_eq!(
        error_findings(&report),
        [(
            "UNRESOLVED_REFERENCE",
            "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index"
        )]
    );
    let unresolved = |report: &velvet::validate::FileReport| {
        report
            .findings
            .iter()
            .find(|f| f.diagnostic.code == "UNRESOLVED_REFERENCE")
            .map(|f| f.diagnostic.message.clone())
    };
    assert_eq!(
        unresolved(&report).unwrap(),
        "sheenColorTexture names texture 18446744073709551617, but the asset has 1 texture"
    );
    // The same at 1e30 and at a value just inside u64.
    for (index, expected) in [
        ("1e30", "1e30"),
        ("18446744073709551615", "18446744073709551615"),
    ] {
        write(&path, text.replace("18446744073709551617", index));
        let report = validator.validate_file(&path);
        assert_eq!(
            unresolved(&report).unwrap(),
            format!("sheenColorTexture names texture {expected}, but the asset has 1 texture")
        );
    }
    write(&path, &text);
    let out_dir = dir.path().join("out");
    let (status, out, err) = velvet(&["migrate", s(&path), "--out-dir", s(&out_dir)]);
    assert_eq!(status, 1, "{out}{err}");
    assert!(
        out.contains(
            "cannot be migrated: sheenColorTexture names texture 18446744073709551617, but the \
             asset has 1 texture (UNRESOLVED_REFERENCE at \
             /materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index)"
        ),
        "{out}"
    );
    assert!(!out_dir.join("huge-index.gltf").exists());
    doc["materials"][0]["extensions"]["KHR_materials_sheen"]["sheenColorTexture"]["index"] =
        json!(0);
    write(&path, serde_json::to_string_pretty(&doc).unwrap());
    assert!(error_findings(&validator.validate_file(&path)).is_empty());
}

#[test]
fn a_lone_surrogate_escape_is_invalid_json_at_its_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("surrogate.gltf");
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    // A leading surrogate with no trailing one, a trailing one alone, and a pair (valid).
    for (name, expected) in [
        (r#""\ud800""#, Some((2, 31))),
        (r#""ab\udc00""#, Some((2, 32))),
        (r#""\ud83d\ude00""#, None),
    ] {
        write(
            &path,
            format!(
                "{{\"asset\": {{\"version\": \"2.0\"}},\n  \"materials\":[{{\"name\":{name}}}]}}"
            ),
        );
        let report = validator.validate_file(&path);
        let found: Vec<_> = report
            .findings
            .iter()
            .map(|f| {
                let at = f.diagnostic.position.unwrap();
                (
                    f.diagnostic.code,
                    at.line,
                    at.column,
                    f.diagnostic.message.clone(),
                )
            })
            .collect();
        match expected {
            Some((line, column)) => assert_eq!(
                found,
                [(
                    "INVALID_JSON",
                    line,
                    column,
                    format!(
                        "line {line}, column {column}: a \\u escape of this string is half of \
                         a UTF-16 surrogate pair without its other half, which is no character"
                    )
                )],
                "{name}"
            ),
            None => assert!(found.is_empty(), "{name}: {found:?}"),
        }
    }
}

/// A list of a million equal node indices (2 MB) is one DUPLICATE_ELEMENTS finding, read with
/// a peak heap of a small multiple of its text: jsonschema's own uniqueItems check and its
/// error read every element into a value, some 240 bytes an element (a 62 MB list took 7 GB).
#[test]
fn a_million_equal_node_indices_are_one_finding_within_a_small_multiple_of_the_text() {
    const NAME: &str =
        "a_million_equal_node_indices_are_one_finding_within_a_small_multiple_of_the_text";
    if !alone_in_a_process(NAME) {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nodes.gltf");
    let list = vec!["0"; 1_000_000].join(",");
    let text = format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"scenes\":[{{\"nodes\":[{list}]}}],\"nodes\":[{{}}]}}"
    );
    write(&path, &text);
    let validator = Validator::new(Schemas::builtin(), Settings::default());
    let before = HEAP_NOW.load(Ordering::Relaxed);
    HEAP_PEAK.store(before, Ordering::Relaxed);
    let report = validator.validate_file(&path);
    let peak = HEAP_PEAK.load(Ordering::Relaxed) - before;
    assert_eq!(
        error_findings(&report),
        [("DUPLICATE_ELEMENTS", "/scenes/0/nodes/1")]
    );
    eprintln!("peak heap {peak} bytes for a text of {} bytes", text.len());
    assert!(
        peak < 20 * text.len(),
        "peak heap {peak} bytes for a text of {}",
        text.len()
    );
}

/// A PNG whose header reads but whose data is cut short, or whose data chunk fails its CRC,
/// cannot be baked: migrate's plan finds that (not the bake after it) and carries the roughness
/// texture as it is with the roughness copied, as it does for an image it cannot read at all;
/// the dry run says the same, and the file is written.
#[test]
fn a_truncated_or_damaged_png_is_carried_as_it_is_by_the_plan_not_a_failed_bake() {
    let good = png(64, 64, image::ExtendedColorType::Rgba8);
    let idat = good.windows(4).position(|w| w == b"IDAT").unwrap();
    let idat_len = u32::from_be_bytes(good[idat - 4..idat].try_into().unwrap()) as usize;
    let mut bad_crc = good.clone();
    bad_crc[idat + 4 + idat_len] ^= 0xff;
    let truncated = good[..good.len() / 2].to_vec();
    for (name, bytes, why) in [
        ("truncated", truncated, "unexpected end of file"),
        ("bad-crc", bad_crc, "CRC error"),
    ] {
        let dir = tempfile::tempdir().unwrap();
        write(&dir.path().join("t.png"), &bytes);
        let input = dir.path().join(format!("{name}.gltf"));
        write(
            &input,
            serde_json::to_string_pretty(&sheen_document("t.png")).unwrap(),
        );
        let (status, dry, err) = velvet(&["migrate", s(&input), "--dry-run", "-v"]);
        assert_eq!(status, 0, "{name}: {dry}{err}");
        let warning = "warning: the roughness texture cannot be baked through the roughness \
                       mapping (image 0 cannot be decoded: ";
        assert!(dry.contains(warning) && dry.contains(why), "{name}: {dry}");
        let out = dir.path().join("out");
        let (status, written, err) = velvet(&["migrate", s(&input), "--out-dir", s(&out), "-v"]);
        assert_eq!(status, 0, "{name}: {written}{err}");
        assert!(written.contains(warning), "{name}: {written}");
        let migrated: Value =
            serde_json::from_slice(&std::fs::read(out.join(format!("{name}.gltf"))).unwrap())
                .unwrap();
        let fuzz = &migrated["materials"][0]["extensions"]["KHR_materials_fuzz"];
        assert_eq!(fuzz["fuzzRoughnessTexture"], json!({"index": 0}), "{name}");
        assert_eq!(fuzz["fuzzRoughnessFactor"], json!(0.5), "{name}");
        assert_eq!(migrated["images"], json!([{"uri": "t.png"}]), "{name}");
        assert_eq!(std::fs::read(out.join("t.png")).unwrap(), bytes, "{name}");
    }
}

// ---------------------------------------------------------------------------------------------
// Interruption

/// A 64 × 64 RGBA texture whose texels depend on `seed`, so that no two are alike.
fn seeded_png(seed: usize) -> Vec<u8> {
    let data: Vec<u8> = (0..64 * 64 * 4)
        .map(|i| ((i * 31 + seed * 97) % 253) as u8)
        .collect();
    let mut out = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut out),
        &data,
        64,
        64,
        image::ExtendedColorType::Rgba8,
    )
    .unwrap();
    out
}

/// A sheen material whose colour and roughness textures read texture `texture`.
fn textured_sheen_material(texture: usize, roughness: f64) -> Value {
    json!({"extensions": {"KHR_materials_sheen": {
        "sheenColorFactor": [0.5, 0.4, 0.3],
        "sheenColorTexture": {"index": texture},
        "sheenRoughnessFactor": roughness,
        "sheenRoughnessTexture": {"index": texture}
    }}})
}

/// A folder of `files` documents, each with its own texture, and one library document of
/// `materials` materials, each with its own texture: work that bakes a new texture per
/// material in both commands.
fn interruptible_inputs(root: &Path, files: usize, materials: usize) -> (PathBuf, PathBuf) {
    let folder = root.join("folder");
    for i in 0..files {
        write(&folder.join(format!("t{i:02}.png")), seeded_png(i));
        let doc = json!({
            "asset": {"version": "2.0"},
            "extensionsUsed": ["KHR_materials_sheen"],
            "materials": [textured_sheen_material(0, 0.3 + i as f64 / 100.0)],
            "textures": [{"source": 0}],
            "images": [{"uri": format!("t{i:02}.png")}]
        });
        write(
            &folder.join(format!("d{i:02}.gltf")),
            serde_json::to_string_pretty(&doc).unwrap(),
        );
    }
    let library = root.join("library");
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [], "textures": [], "images": []
    });
    for i in 0..materials {
        write(&library.join(format!("m{i:02}.png")), seeded_png(100 + i));
        doc["materials"]
            .as_array_mut()
            .unwrap()
            .push(textured_sheen_material(i, 0.2 + i as f64 / 100.0));
        doc["textures"]
            .as_array_mut()
            .unwrap()
            .push(json!({"source": i}));
        doc["images"]
            .as_array_mut()
            .unwrap()
            .push(json!({"uri": format!("m{i:02}.png")}));
    }
    write(
        &library.join("library.gltf"),
        serde_json::to_string_pretty(&doc).unwrap(),
    );
    (folder, library)
}

/// The relative URIs a document names (its buffers' and images').
fn uris_of(document: &[u8]) -> Vec<String> {
    let doc: Value = serde_json::from_slice(document).unwrap();
    ["buffers", "images"]
        .iter()
        .flat_map(|kind| doc[*kind].as_array().cloned().unwrap_or_default())
        .filter_map(|item| item["uri"].as_str().map(str::to_string))
        .filter(|uri| !uri.starts_with("data:"))
        .collect()
}

/// Checks an output folder after a stopped run against the complete run's `expected`: every
/// file is one of the complete run's, byte for byte; every document there has every file it
/// names; every other file is named by a document there; no temporary file is left.
fn assert_only_finished_outputs(out: &Path, expected: &BTreeMap<PathBuf, Vec<u8>>, what: &str) {
    let found = if out.exists() {
        tree(out)
    } else {
        BTreeMap::new()
    };
    let mut named = std::collections::BTreeSet::new();
    for (path, bytes) in &found {
        let name = path.to_string_lossy();
        assert!(!name.contains(".velvet-"), "{what}: {name} left behind");
        assert_eq!(
            expected.get(path),
            Some(bytes),
            "{what}: {name} is not complete"
        );
        if name.ends_with(".gltf") {
            for uri in uris_of(bytes) {
                let resource = path.parent().unwrap().join(&uri);
                assert!(
                    found.contains_key(&resource),
                    "{what}: {name} names {uri}, which is missing"
                );
                named.insert(resource);
            }
        }
    }
    for path in found.keys() {
        if !path.to_string_lossy().ends_with(".gltf") {
            assert!(
                named.contains(path),
                "{what}: {} belongs to no finished document",
                path.display()
            );
        }
    }
}

/// SIGINT and SIGTERM at several moments of a migrate and a bake, of a folder of documents and
/// of one library document, leave only finished outputs, every file they name, and no
/// temporary file; a stopped run says what it finished on one line and exits 130 or 143.
#[cfg(unix)]
#[test]
fn sigint_and_sigterm_leave_only_finished_outputs_and_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let (folder, library) = interruptible_inputs(dir.path(), 16, 16);
    let mut stopped = 0;
    for command in ["migrate", "bake"] {
        for input in [&folder, &library] {
            let what = format!("{command} {}", input.display());
            let reference = dir.path().join("reference");
            let (status, out, err) = velvet(&[command, s(input), "--out-dir", s(&reference)]);
            assert_eq!(status, 0, "{what}: {out}{err}");
            let expected = tree(&reference);
            std::fs::remove_dir_all(&reference).unwrap();
            assert!(expected.len() > 16, "{what}: {expected:?}");
            for (k, (signal, delay_ms)) in [
                (libc::SIGINT, 20),
                (libc::SIGTERM, 60),
                (libc::SIGINT, 150),
                (libc::SIGTERM, 400),
            ]
            .into_iter()
            .enumerate()
            {
                let out_dir = dir.path().join(format!("out-{k}"));
                let (output, _) = velvet_signalled(
                    &[command, s(input), "--out-dir", s(&out_dir)],
                    signal,
                    delay_ms,
                );
                let err = String::from_utf8_lossy(&output.stderr);
                let what = format!("{what}, signal {signal} after {delay_ms} ms");
                match output.status.code() {
                    Some(0) => assert_eq!(tree(&out_dir), expected, "{what}"),
                    Some(code) => {
                        assert_eq!(code, 128 + signal, "{what}: {err}");
                        let name = signal_name(signal);
                        let line = err.lines().last().unwrap_or_default();
                        assert!(
                            line.starts_with(&format!("velvet: stopped by {name}: ")),
                            "{what}: {err}"
                        );
                        assert!(
                            line.contains(
                                " finished (their outputs are complete); nothing was \
                                           written for the other "
                            ),
                            "{what}: {err}"
                        );
                        assert_eq!(err.lines().count(), 1, "{what}: {err}");
                        assert_only_finished_outputs(&out_dir, &expected, &what);
                        stopped += 1;
                    }
                    None => {
                        // The signal came before velvet installed its handler, which it does
                        // before reading or writing anything: nothing may have been written.
                        use std::os::unix::process::ExitStatusExt;
                        assert_eq!(output.status.signal(), Some(signal), "{what}: {err}");
                        assert!(!out_dir.exists(), "{what}: written before the handler");
                    }
                }
                if out_dir.exists() {
                    std::fs::remove_dir_all(&out_dir).unwrap();
                }
            }
        }
    }
    assert!(
        stopped >= 4,
        "only {stopped} runs were stopped before they finished"
    );
}

// ---------------------------------------------------------------------------------------------
// Nothing dropped

/// A GLB chunk of a type the spec does not define (here 0x4B4E5558, "XUNK", 12 bytes) survives
/// migrate and bake byte for byte: it follows the BIN chunk in the output as it stood in the
/// input, and the header's length counts it.
#[test]
fn an_unknown_glb_chunk_survives_migrate_and_bake_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let rgba = png(2, 2, image::ExtendedColorType::Rgba8);
    let mut doc = sheen_document("unused");
    doc["images"] = json!([{"bufferView": 0, "mimeType": "image/png"}]);
    doc["bufferViews"] = json!([{"buffer": 0, "byteLength": rgba.len()}]);
    doc["buffers"] = json!([{"byteLength": rgba.len()}]);
    let mut chunk = Vec::new();
    chunk.extend_from_slice(&12u32.to_le_bytes());
    chunk.extend_from_slice(b"XUNK");
    chunk.extend_from_slice(b"kept as is!\x01");
    let mut bytes = glb::join(doc.to_string().as_bytes(), Some(&rgba));
    bytes.extend_from_slice(&chunk);
    let length = bytes.len() as u32;
    bytes[8..12].copy_from_slice(&length.to_le_bytes());
    let input = dir.path().join("unknown.glb");
    write(&input, &bytes);
    for (command, extra) in [
        ("migrate", None),
        ("bake", None),
        ("migrate", Some("--exact")),
    ] {
        let output = dir
            .path()
            .join(format!("{command}-{}.glb", extra.is_some()));
        let mut args = vec![command, s(&input), "-o", s(&output)];
        args.extend(extra);
        let (status, out, err) = velvet(&args);
        assert_eq!(status, 0, "{command}: {out}{err}");
        let written = std::fs::read(&output).unwrap();
        assert_ne!(written, bytes, "{command}: the output is a rewrite");
        assert!(written.ends_with(&chunk), "{command}: {out}");
        assert_eq!(
            u32::from_le_bytes(written[8..12].try_into().unwrap()) as usize,
            written.len()
        );
        let mut diagnostics = Vec::new();
        let parts = glb::split(&written, &mut diagnostics).unwrap();
        assert_eq!(parts.other, [chunk.as_slice()], "{command}");
        assert_eq!(codes(&diagnostics), ["GLB_UNKNOWN_CHUNK_TYPE"], "{command}");
    }
}

/// Two slots whose bakes come out identical (two source images with the same pixels) get one
/// new file, named by both images, in bake and in migrate.
#[test]
fn identical_baked_images_are_written_once() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    let texture = seeded_png(7);
    write(&input.join("a.png"), &texture);
    write(&input.join("b.png"), &texture);
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [textured_sheen_material(0, 0.5), textured_sheen_material(1, 0.5)],
        "textures": [{"source": 0}, {"source": 1}],
        "images": [{"uri": "a.png"}, {"uri": "b.png"}]
    });
    write(
        &input.join("pair.gltf"),
        serde_json::to_string_pretty(&doc).unwrap(),
    );
    for command in ["bake", "migrate"] {
        let out = dir.path().join(command);
        let (status, stdout, err) = velvet(&[command, s(&input), "--out-dir", s(&out)]);
        assert_eq!(status, 0, "{command}: {stdout}{err}");
        let written = tree(&out);
        let new: Vec<&PathBuf> = written
            .keys()
            .filter(|p| !["pair.gltf", "a.png", "b.png"].contains(&p.to_str().unwrap()))
            .collect();
        let output: Value = serde_json::from_slice(&written[Path::new("pair.gltf")]).unwrap();
        let uris: Vec<&str> = output["images"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|i| i["uri"].as_str())
            .filter(|u| *u != "a.png" && *u != "b.png")
            .collect();
        assert!(!uris.is_empty(), "{command}: {output}");
        // Every new image names the one file per distinct content.
        let distinct: std::collections::BTreeSet<&Vec<u8>> =
            new.iter().map(|p| &written[*p]).collect();
        assert_eq!(new.len(), distinct.len(), "{command}: {new:?}");
        for uri in &uris {
            assert!(written.contains_key(Path::new(uri)), "{command}: {uri}");
        }
        let named: std::collections::BTreeSet<&str> = uris.iter().copied().collect();
        assert_eq!(named.len(), new.len(), "{command}: {uris:?} {new:?}");
        assert!(uris.len() > named.len(), "{command}: {uris:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// Memory within a stated budget

/// CRC-32 (the PNG chunk checksum), bit by bit.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// A PNG whose header declares `width` × `height` 16-bit RGBA and whose data is one empty
/// IDAT: what a decoder learns before it allocates, and nothing to decode.
fn forged_16bit_rgba_png(width: u32, height: u32) -> Vec<u8> {
    png_of(
        width,
        height,
        16,
        6,
        &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
    )
}

/// A PNG of one IDAT chunk holding `zlib`, its header `width` × `height` at `bit_depth` and
/// `colour_type` (PNG's numbers: 2 RGB, 6 RGBA), each chunk with its CRC.
fn png_of(width: u32, height: u32, bit_depth: u8, colour_type: u8, zlib: &[u8]) -> Vec<u8> {
    let chunk = |kind: &[u8], data: &[u8]| {
        let mut out = (data.len() as u32).to_be_bytes().to_vec();
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        out.extend_from_slice(&body);
        out.extend_from_slice(&crc32(&body).to_be_bytes());
        out
    };
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[bit_depth, colour_type, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(chunk(b"IHDR", &ihdr));
    png.extend(chunk(b"IDAT", zlib));
    png.extend(chunk(b"IEND", &[]));
    png
}

/// A 16384² 16-bit RGBA PNG (within the pixel limit, which is inclusive) whose bake would need
/// about 6 GiB is refused before any pixel buffer exists when the memory budget is 2 GiB, with
/// a message naming --max-memory; the same budget in bytes is the same refusal.
#[test]
fn a_16384_square_16_bit_png_over_the_memory_budget_is_refused_before_decoding() {
    let png = forged_16bit_rgba_png(16384, 16384);
    let expected =
        "PNG: decoding the 16384 × 16384 image (8 bytes a pixel) needs about 6.0 GiB, over \
                    the memory budget of 2.0 GiB (raise it with --max-memory); it was not \
                    decoded";
    let (result, largest) =
        largest_allocation(|| codec::decode_within(&png, 16384 * 16384, 2 << 30));
    match result {
        Err(e @ CodecError::TooLarge { .. }) => assert_eq!(e.to_string(), expected),
        other => panic!("{:?}", other.map(|_| ())),
    }
    assert!(largest < 1 << 20, "largest allocation {largest} bytes");

    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("huge16.png"), &png);
    let input = dir.path().join("huge16.gltf");
    write(&input, sheen_document("huge16.png").to_string());
    for budget in ["2G", "2147483648"] {
        let output = dir.path().join("out.gltf");
        let (status, out, err) =
            velvet(&["bake", s(&input), "-o", s(&output), "--max-memory", budget]);
        assert_eq!(status, 1, "{out}{err}");
        assert!(out.contains(expected), "{out}");
        assert!(!output.exists());
    }
    let (status, _, err) = velvet(&["bake", s(&input), "--dry-run", "--max-memory", "lots"]);
    assert_eq!(status, 2, "{err}");
    assert!(err.contains("\"lots\" is not a byte count"), "{err}");
}

/// The memory budget holds for the decodes of a run together: a decode that fits the budget
/// alone waits while others hold too much of it, and goes on once they give it back. A 64²
/// RGBA image takes 48 KiB to bake; with 40,000 bytes of a 64 KiB budget held, its decode waits.
#[test]
fn decodes_side_by_side_share_one_memory_budget() {
    let png = png(64, 64, image::ExtendedColorType::Rgba8);
    let budget = 64 << 10;
    let held = limits::reserve("another decode", 40_000, budget).unwrap();
    let (done_tx, done_rx) = std::sync::mpsc::channel();
    let decoding = std::thread::spawn(move || {
        let decoded = codec::decode_within(&png, 1 << 20, budget).map(|(pixels, _)| pixels.width());
        done_tx.send(()).unwrap();
        decoded
    });
    assert!(
        done_rx
            .recv_timeout(std::time::Duration::from_millis(300))
            .is_err(),
        "the decode went on while the budget was held"
    );
    drop(held);
    done_rx
        .recv_timeout(std::time::Duration::from_secs(20))
        .expect("the decode goes on once the budget is given back");
    assert_eq!(decoding.join().unwrap().unwrap(), 64);
    // Over the budget alone, it is refused at once, naming the flag.
    let alone = limits::reserve("decoding a big image", budget + 1, budget)
        .err()
        .unwrap();
    assert_eq!(
        alone,
        "decoding a big image needs about 64.0 KiB, over the memory budget of 64.0 KiB (raise \
         it with --max-memory)"
    );
}

/// A GLB that would exceed the memory budget is refused before it is read (here a sparse file
/// of 200 MiB): an IO_ERROR naming --max-memory. validate holds it once, migrate (which keeps
/// the file's bytes beside its BIN chunk) twice.
#[test]
fn a_glb_larger_than_the_memory_budget_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sparse.glb");
    let json = br#"{"asset":{"version":"2.0"},"buffers":[{"byteLength":209715100}]}   "#;
    let mut head = Vec::new();
    head.extend_from_slice(b"glTF");
    head.extend_from_slice(&2u32.to_le_bytes());
    head.extend_from_slice(&(200u32 << 20).to_le_bytes());
    head.extend_from_slice(&(json.len() as u32).to_le_bytes());
    head.extend_from_slice(b"JSON");
    head.extend_from_slice(json);
    let bin_len = (200u32 << 20) - head.len() as u32 - 8;
    head.extend_from_slice(&bin_len.to_le_bytes());
    head.extend_from_slice(b"BIN\0");
    write(&path, &head);
    std::fs::File::options()
        .write(true)
        .open(&path)
        .unwrap()
        .set_len(200 << 20)
        .unwrap();
    // validate holds the file once (its BIN chunk is carved out of its bytes in place)...
    let (status, out, err) = velvet(&["validate", s(&path), "--max-memory", "100M"]);
    assert_eq!(status, 1, "{out}{err}");
    assert!(
        out.contains(&format!(
            "error IO_ERROR: reading {} (a GLB of 209715200 bytes) needs about 200.0 MiB, over \
             the memory budget of 100.0 MiB (raise it with --max-memory)",
            velvet::report::display_path(&path)
        )),
        "{out}"
    );
    // Within a budget of once its size, validate reads it.
    let (_, out, err) = velvet(&["validate", s(&path), "--max-memory", "300M"]);
    assert!(!out.contains("IO_ERROR"), "{out}{err}");
    // ...and migrate, which keeps the file's bytes beside the chunk, twice.
    let out_dir = dir.path().join("out");
    let (status, out, err) = velvet(&[
        "migrate",
        s(&path),
        "--out-dir",
        s(&out_dir),
        "--max-memory",
        "300M",
    ]);
    assert_eq!(status, 1, "{out}{err}");
    assert!(
        format!("{out}{err}").contains(
            "(a GLB of 209715200 bytes) needs about 400.0 MiB, over the memory budget of 300.0 MiB"
        ),
        "{out}{err}"
    );
}

/// `--files-from` and velvet.toml are read no further than their limits: an endless list is a
/// usage error at once, and a configuration over 1 MiB is refused naming the file.
#[cfg(unix)]
#[test]
fn an_endless_list_and_a_huge_configuration_are_refused_at_their_limits() {
    let (status, out, err) = velvet_within_20s(&["validate", "--files-from", "/dev/zero"]);
    assert_eq!(status, Some(2), "{out}{err}");
    assert_eq!(
        err,
        "velvet: --files-from /dev/zero: the list is longer than 67108864 bytes; velvet reads no \
         further (split it, or name folders)\n"
    );
    let dir = tempfile::tempdir().unwrap();
    let mut config = String::from("exclude = []\n");
    while config.len() <= 1 << 20 {
        config.push_str("# padding padding padding padding padding padding padding padding\n");
    }
    write(&dir.path().join("velvet.toml"), &config);
    write(&dir.path().join("a.gltf"), r#"{"asset":{"version":"2.0"}}"#);
    let (status, out, err) = velvet_within_20s(&["validate", s(dir.path())]);
    assert_eq!(status, Some(2), "{out}{err}");
    assert!(
        err.contains(&format!(
            "{}: the file is larger than 1048576 bytes, more than a configuration needs; velvet \
             reads no further",
            dir.path().join("velvet.toml").display()
        )),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// Nothing lost, third round: every command and every output path

/// Runs velvet with `args`, its standard output (or, `on_stderr`, its standard error) writing
/// into /dev/full, the other captured: (exit status, the captured stream).
#[cfg(unix)]
fn velvet_into_a_full_disk(args: &[&str], on_stderr: bool) -> (Option<i32>, String) {
    let full = || {
        std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    let mut command = Command::new(env!("CARGO_BIN_EXE_velvet"));
    command.args(args).stdin(std::process::Stdio::null());
    if on_stderr {
        command.stderr(full()).stdout(std::process::Stdio::piped());
    } else {
        command.stdout(full()).stderr(std::process::Stdio::piped());
    }
    let out = command.output().unwrap();
    let captured = if on_stderr { out.stdout } else { out.stderr };
    (
        out.status.code(),
        String::from_utf8_lossy(&captured).into_owned(),
    )
}

/// A report that cannot be written (standard output on a full disk) fails the run with exit
/// status 2 and says so on standard error, in every format and command that prints; a failed
/// write to standard error is status 2 too, not a panic; a closed pipe stays quiet.
#[cfg(unix)]
#[test]
fn a_failed_write_to_standard_output_or_error_is_status_2_never_0() {
    let dir = tempfile::tempdir().unwrap();
    let clean = dir.path().join("clean.gltf");
    write(&clean, r#"{"asset":{"version":"2.0"}}"#);
    let sheen = dir.path().join("sheen/asset.gltf");
    write(
        &sheen,
        serde_json::to_string_pretty(&sheen_document("tex.png")).unwrap(),
    );
    write(
        &dir.path().join("sheen/tex.png"),
        png(4, 4, image::ExtendedColorType::Rgb8),
    );
    let full = "velvet: cannot write to standard output: No space left on device (os error 28)\n";
    let runs: Vec<Vec<&str>> = vec![
        vec!["validate", "--format", "sarif", s(&clean)],
        vec!["validate", "--format", "json", s(&clean)],
        vec!["validate", "--format", "text", s(&clean)],
        vec!["migrate", "--dry-run", s(&sheen)],
        vec!["migrate", "--dry-run", "--format", "json", s(&sheen)],
        vec!["bake", "--dry-run", s(&sheen)],
        vec!["config", s(dir.path())],
        vec!["codes"],
        vec!["man"],
        vec!["--help"],
    ];
    for args in &runs {
        // Each run passes when its output can be written.
        let (status, out, err) = velvet(args);
        assert_eq!(status, 0, "{args:?}: {out}{err}");
        assert!(!out.is_empty(), "{args:?}");
        let (status, err) = velvet_into_a_full_disk(args, false);
        assert_eq!(status, Some(2), "{args:?}: {err}");
        assert_eq!(err, full, "{args:?}");
    }
    // Standard error on a full disk: the usage error cannot be said, the status still is.
    let missing = dir.path().join("missing.gltf");
    let (status, out) = velvet_into_a_full_disk(&["validate", s(&missing)], true);
    assert_eq!(status, Some(2), "{out}");
    let (status, out) = velvet_into_a_full_disk(
        &[
            "migrate",
            "--out-dir",
            s(&dir.path().join("o")),
            s(&missing),
        ],
        true,
    );
    assert_eq!((status, out.as_str()), (Some(2), ""));
    // A reader that stops reading is not a failure: no message, the run's own status.
    let mut child = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(["codes"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stderr), "");
}

/// The codes of `velvet codes` at `severity`, in its order.
fn codes_at(severity: &str) -> Vec<String> {
    let (status, out, _) = velvet(&["codes"]);
    assert_eq!(status, 0);
    out.lines()
        .filter_map(|l| {
            let mut words = l.split_whitespace();
            let (code, at) = (words.next()?, words.next()?);
            (at == severity).then(|| code.to_string())
        })
        .collect()
}

/// A velvet.toml (or the command line) whose `only` or `ignore` would leave out every error
/// code cannot make a file with errors pass: the errors are still reported and counted (exit
/// status 1), and a warning names the configuration and the codes it could not hide. Leaving
/// out some error codes is obeyed as before.
#[test]
fn a_configuration_that_would_hide_every_error_warns_and_its_errors_still_fail_the_run() {
    let dir = tempfile::tempdir().unwrap();
    // An undeclared sheen: UNDECLARED_EXTENSION, an error, and nothing else.
    let doc = dir.path().join("a.gltf");
    write(
        &doc,
        r#"{"asset":{"version":"2.0"},"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":0.5}}}]}"#,
    );
    let errors = codes_at("error");
    assert!(errors.contains(&"UNDECLARED_EXTENSION".to_string()));
    let hint = codes_at("hint")[0].clone();
    let config = dir.path().join("velvet.toml");
    let quoted = |codes: &[String]| {
        codes
            .iter()
            .map(|c| format!("\"{c}\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let warning = |by: &str| {
        format!(
            "velvet: warning: {by} leaves out every error code; a configuration cannot silence \
             every error, so these {} codes are still reported and fail the run: {}\n",
            errors.len(),
            errors.join(", ")
        )
    };
    for (toml, key) in [
        (format!("only = [\"{hint}\"]\n"), "only"),
        (format!("ignore = [{}]\n", quoted(&errors)), "ignore"),
    ] {
        write(&config, &toml);
        let (status, out, err) = velvet(&["validate", s(&doc)]);
        assert_eq!(status, 1, "{toml}: {out}{err}");
        assert!(out.contains("error UNDECLARED_EXTENSION"), "{toml}: {out}");
        assert!(
            out.ends_with(
                "1 file checked: 1 error, 0 warnings, 0 info, 0 hints; 1 fixable with --fix\n"
            ),
            "{toml}: {out}"
        );
        assert_eq!(
            err,
            warning(&format!("{} ({key})", config.display())),
            "{toml}"
        );
        // `velvet config` says it too, as a comment.
        let (status, out, _) = velvet(&["config", s(dir.path())]);
        assert_eq!(status, 0);
        assert!(
            out.starts_with(&format!(
                "# warning: {} ({key}) leaves out",
                config.display()
            )),
            "{out}"
        );
    }
    std::fs::remove_file(&config).unwrap();
    let (status, out, err) = velvet(&["validate", "--only", &hint, s(&doc)]);
    assert_eq!(status, 1, "{out}{err}");
    assert_eq!(err, warning("--only"));
    // One error code left out, another let through: obeyed, no warning.
    let (status, out, err) = velvet(&["validate", "--ignore", "UNDECLARED_EXTENSION", s(&doc)]);
    assert_eq!((status, err.as_str()), (0, ""), "{out}");
    let (status, out, err) = velvet(&["validate", "--only", "TYPE_MISMATCH", s(&doc)]);
    assert_eq!((status, err.as_str()), (0, ""), "{out}");
}

/// A file name that is not UTF-8 neither panics nor fails its file: migrate and bake write it,
/// and their JSON reports name it lossily (U+FFFD for the byte), exit status 0.
#[cfg(unix)]
#[test]
fn a_file_name_that_is_not_utf8_is_reported_lossily_without_a_panic() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    let name = std::ffi::OsStr::from_bytes(b"bad\xff.gltf");
    write(
        &input.join(name),
        serde_json::to_string_pretty(&sheen_document("tex.png")).unwrap(),
    );
    write(
        &input.join("tex.png"),
        png(4, 4, image::ExtendedColorType::Rgb8),
    );
    for command in ["migrate", "bake"] {
        let out_dir = dir.path().join(format!("out-{command}"));
        let (status, out, err) = velvet(&[
            command,
            "--format",
            "json",
            "--out-dir",
            s(&out_dir),
            s(&input),
        ]);
        assert_eq!(status, 0, "{command}: {out}{err}");
        let report: Value = serde_json::from_str(&out).unwrap();
        let file = &report["files"][0];
        assert_eq!(
            file["input"],
            json!(format!("{}/bad\u{fffd}.gltf", input.display())),
            "{command}: {out}"
        );
        assert_eq!(
            file["output"],
            json!(format!("{}/bad\u{fffd}.gltf", out_dir.display())),
            "{command}: {out}"
        );
        assert!(out_dir.join(name).is_file(), "{command}");
        let (status, out, err) = velvet(&[command, "--out-dir", s(&out_dir), s(&input)]);
        assert_eq!(status, 0, "{command}: {out}{err}");
        assert!(out.contains("bad\u{fffd}.gltf"), "{command}: {out}");
    }
}

/// An undeclared sheen, which `validate --fix` repairs by declaring it.
const FIXABLE: &str = r#"{"asset":{"version":"2.0"},"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":0.5}}}]}"#;
const FIXED: &str = r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_materials_sheen"],"materials":[{"extensions":{"KHR_materials_sheen":{"sheenRoughnessFactor":0.5}}}]}"#;

/// `validate --fix` keeps links as `migrate --in-place` does: a link's target is fixed and the
/// link stays a link (a folder holding both fixes the file once), and a link leading out of
/// the folder given is refused with exit status 2 before anything is written.
#[cfg(unix)]
#[test]
fn validate_fix_on_a_link_fixes_its_target_and_keeps_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let tree = dir.path().join("tree");
    let real = tree.join("real/asset.gltf");
    write(&real, FIXABLE);
    let link = tree.join("link.gltf");
    std::os::unix::fs::symlink("real/asset.gltf", &link).unwrap();
    let (status, out, err) = velvet(&["validate", "--fix", s(&link)]);
    assert_eq!(status, 0, "{out}{err}");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert_eq!(
        std::fs::read_link(&link).unwrap(),
        Path::new("real/asset.gltf")
    );
    assert_eq!(std::fs::read_to_string(&real).unwrap(), FIXED);

    // The folder holding both: fixed once, both reported clean, no file changed under a check.
    std::fs::write(&real, FIXABLE).unwrap();
    let (status, out, err) = velvet(&["validate", "--fix", s(&tree)]);
    assert_eq!(status, 0, "{out}{err}");
    assert!(out.contains("2 files checked: 0 errors"), "{out}");
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert_eq!(std::fs::read_to_string(&real).unwrap(), FIXED);

    // A link out of the folder given: refused, nothing written.
    let inner = tree.join("real");
    let outside = dir.path().join("outside/asset.gltf");
    write(&outside, FIXABLE);
    std::fs::write(&real, FIXABLE).unwrap();
    std::os::unix::fs::symlink(&outside, inner.join("away.gltf")).unwrap();
    let (status, out, err) = velvet(&["validate", "--fix", s(&inner)]);
    assert_eq!(status, 2, "{out}{err}");
    assert_eq!(
        err,
        format!(
            "velvet: --fix: {} is a symbolic link to {}, outside {}; velvet writes only inside \
             the folders it is given (name the target itself to fix it)\n",
            inner.join("away.gltf").display(),
            outside.canonicalize().unwrap().display(),
            inner.display()
        )
    );
    assert!(std::fs::symlink_metadata(inner.join("away.gltf"))
        .unwrap()
        .is_symlink());
    assert_eq!(std::fs::read_to_string(&outside).unwrap(), FIXABLE);
    assert_eq!(std::fs::read_to_string(&real).unwrap(), FIXABLE);
}

/// SIGINT and SIGTERM during `validate --fix` stop it as they stop migrate: the files fixed
/// stay fixed, the others are left as they were (no temporary file), one line says so and
/// the exit status is 130 or 143, never 0 for a run that did not finish.
#[cfg(unix)]
#[test]
fn validate_fix_answers_sigint_and_sigterm_as_migrate_does() {
    let dir = tempfile::tempdir().unwrap();
    let files = 3000;
    let mut stopped = 0;
    for (k, (signal, delay_ms)) in [
        (libc::SIGINT, 300),
        (libc::SIGTERM, 300),
        (libc::SIGINT, 800),
        (libc::SIGTERM, 800),
    ]
    .into_iter()
    .enumerate()
    {
        let folder = dir.path().join(format!("run-{k}"));
        for i in 0..files {
            write(&folder.join(format!("d{i:04}.gltf")), FIXABLE);
        }
        let (output, took) = velvet_signalled(&["validate", "--fix", s(&folder)], signal, delay_ms);
        let what = format!("signal {signal} after {delay_ms} ms");
        assert!(took < std::time::Duration::from_secs(5), "{what}");
        let err = String::from_utf8_lossy(&output.stderr);
        let mut fixed = 0;
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            assert!(
                name.ends_with(".gltf") && !name.starts_with('.'),
                "{what}: {name}"
            );
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(text == FIXABLE || text == FIXED, "{what}: {name}: {text}");
            fixed += usize::from(text == FIXED);
        }
        match output.status.code() {
            Some(0) => assert_eq!(fixed, files, "{what}"),
            code => {
                assert_eq!(code, Some(128 + signal), "{what}: {err}");
                let name = signal_name(signal);
                assert_eq!(
                    err,
                    format!(
                        "velvet: stopped by {name}: {fixed} of {files} files finished (their \
                         outputs are complete); nothing was written for the other {}\n",
                        files - fixed
                    ),
                    "{what}"
                );
                stopped += 1;
            }
        }
    }
    assert!(
        stopped >= 2,
        "only {stopped} runs were stopped before they finished"
    );
}

/// Every file under `root`, its path relative to it (links and special files included).
fn names_under(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries {
            let path = entry.unwrap().path();
            if std::fs::symlink_metadata(&path).unwrap().is_dir() {
                stack.push(path.clone());
            }
            out.push(
                path.strip_prefix(root)
                    .unwrap()
                    .to_string_lossy()
                    .into_owned(),
            );
        }
    }
    out.sort();
    out
}

/// A file-size limit (`ulimit -f`) does not kill velvet with SIGXFSZ mid-write: the write that
/// passes it fails with EFBIG, that file fails naming it (exit status 1), and no temporary file
/// is left behind, in migrate, bake and `validate --fix`.
#[cfg(unix)]
#[test]
fn a_file_size_limit_fails_the_file_cleanly_instead_of_killing_velvet() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    let mut doc = sheen_document("tex.png");
    doc["extras"] = json!({"padding": "x".repeat(20_000)});
    write(
        &input.join("big.gltf"),
        serde_json::to_string_pretty(&doc).unwrap(),
    );
    write(
        &input.join("tex.png"),
        png(4, 4, image::ExtendedColorType::Rgb8),
    );
    let limited = |args: &[&str]| {
        let mut command = Command::new(env!("CARGO_BIN_EXE_velvet"));
        command.args(args);
        // SAFETY: setrlimit is async-signal-safe; the child sets its own limit before exec.
        unsafe {
            command.pre_exec(|| {
                let limit = libc::rlimit {
                    rlim_cur: 8192,
                    rlim_max: 8192,
                };
                if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        command.output().unwrap()
    };
    for command in ["migrate", "bake"] {
        let out_dir = dir.path().join(format!("out-{command}"));
        let output = limited(&[command, "--out-dir", s(&out_dir), s(&input)]);
        let text = String::from_utf8_lossy(&output.stdout).into_owned()
            + &String::from_utf8_lossy(&output.stderr);
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(output.status.signal(), None, "{command}: {text}");
        assert_eq!(output.status.code(), Some(1), "{command}: {text}");
        assert!(
            text.contains("File too large (os error 27)"),
            "{command}: {text}"
        );
        assert!(!out_dir.join("big.gltf").exists(), "{command}");
        assert!(
            !names_under(&out_dir).iter().any(|n| n.contains(".velvet-")),
            "{command}: {:?}",
            names_under(&out_dir)
        );
    }
    let fixable = dir.path().join("fix/big.gltf");
    let mut doc: Value = serde_json::from_str(FIXABLE).unwrap();
    doc["extras"] = json!({"padding": "x".repeat(20_000)});
    let text = doc.to_string();
    write(&fixable, &text);
    let output = limited(&["validate", "--fix", s(&fixable)]);
    let report = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{report}");
    assert!(report.contains("File too large (os error 27)"), "{report}");
    assert_eq!(std::fs::read_to_string(&fixable).unwrap(), text);
    assert_eq!(names_under(&dir.path().join("fix")), ["big.gltf"]);
}

/// `--config FIFO` and `--files-from FIFO` do not wait for a writer that never comes: a FIFO
/// or a device given as a configuration is refused (exit status 2), a list in a FIFO no program
/// writes into is refused, and a list a program writes into a pipe is read as before.
#[cfg(unix)]
#[test]
fn a_fifo_given_as_configuration_or_list_is_refused_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let doc = dir.path().join("a.gltf");
    write(&doc, r#"{"asset":{"version":"2.0"}}"#);
    let fifo = dir.path().join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let (status, out, err) = velvet_within_20s(&["validate", "--config", s(&fifo), s(&doc)]);
    assert_eq!(status, Some(2), "{out}{err}");
    assert_eq!(
        err,
        format!(
            "velvet: {}: not a regular file (a FIFO); velvet reads a configuration from a file\n",
            fifo.display()
        )
    );
    let (status, _, err) = velvet_within_20s(&["config", "--config", "/dev/zero", s(&doc)]);
    assert_eq!(status, Some(2), "{err}");
    assert_eq!(
        err,
        "velvet: /dev/zero: not a regular file (a character device); velvet reads a \
         configuration from a file\n"
    );
    for command in ["validate", "migrate", "bake"] {
        let mut args = vec![command, "--files-from", s(&fifo)];
        if command != "validate" {
            args.push("--dry-run");
        }
        let (status, out, err) = velvet_within_20s(&args);
        assert_eq!(status, Some(2), "{command}: {out}{err}");
        assert!(
            err.ends_with(&format!(
                "velvet: --files-from {}: a FIFO no program is writing into; velvet does not \
                 wait for one (write the list to a file, or pipe it to --files-from -)\n",
                fifo.display()
            )),
            "{command}: {err}"
        );
    }
    // A list written into a pipe by another program (a shell's `<(git diff …)`) is read.
    let script = format!(
        "{} validate --files-from <(printf '%s\\n' {})",
        env!("CARGO_BIN_EXE_velvet"),
        s(&doc)
    );
    let out = Command::new("bash").args(["-c", &script]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("1 file checked"), "{text}");
}

/// Text velvet did not write reaches no terminal raw: `velvet preview` shows a material name
/// holding ESC, BEL or U+202E as escapes, and `velvet config` a folder name holding them.
#[cfg(unix)]
#[test]
fn preview_names_and_config_folders_are_escaped_on_the_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let mut doc = sheen_document("tex.png");
    doc["materials"][0]["name"] = json!("\u{1b}]0;owned\u{7}cl\u{202e}oth");
    let input = dir.path().join("in/a.gltf");
    write(&input, serde_json::to_string_pretty(&doc).unwrap());
    write(
        &dir.path().join("in/tex.png"),
        png(4, 4, image::ExtendedColorType::Rgb8),
    );
    let (status, out, err) = velvet(&["preview", "-o", s(&dir.path().join("p")), s(&input)]);
    assert_eq!(status, 0, "{out}{err}");
    assert_inert(&out, 0, "preview");
    assert_inert(&err, 0, "preview");
    assert!(!out.contains('\u{202e}'), "{out}");
    assert!(out.contains("\\u001b]0;owned\\u0007cl\\u202eoth"), "{out}");

    let folder = dir.path().join("odd\u{1b}]0;x\u{7}\nname");
    write(&folder.join("velvet.toml"), "max-issues = 3\n");
    write(&folder.join("a.gltf"), r#"{"asset":{"version":"2.0"}}"#);
    let (status, out, err) = velvet(&["config", s(&folder)]);
    assert_eq!(status, 0, "{err}");
    assert_inert(&out, 0, "config");
    assert!(
        out.starts_with(&format!(
            "# velvet.toml in force: {}/odd\\u001b]0;x\\u0007\\u000aname/velvet.toml\n",
            dir.path().display()
        )),
        "{out}"
    );
}

/// A real PNG of `width` × `height` 8-bit RGB texels all zero, of a few bytes per 258 of its
/// pixel data (deflate with fixed codes: one literal zero, then matches of 258 at distance 1),
/// made without holding its pixels: a 16384² one is 5 MB and decodes to 768 MiB.
fn zero_rgb_png(width: u32, height: u32) -> Vec<u8> {
    struct Bits {
        out: Vec<u8>,
        acc: u64,
        n: u32,
    }
    impl Bits {
        fn put(&mut self, value: u64, count: u32) {
            self.acc |= value << self.n;
            self.n += count;
            while self.n >= 8 {
                self.out.push(self.acc as u8);
                self.acc >>= 8;
                self.n -= 8;
            }
        }
        /// A Huffman code, which deflate stores from its most significant bit.
        fn code(&mut self, code: u64, count: u32) {
            let reversed = (0..count).fold(0, |r, i| (r << 1) | ((code >> i) & 1));
            self.put(reversed, count);
        }
    }
    let total = u64::from(height) * (1 + u64::from(width) * 3);
    let mut bits = Bits {
        out: vec![0x78, 0x01],
        acc: 0,
        n: 0,
    };
    bits.put(1, 1); // the last block
    bits.put(1, 2); // fixed codes
    bits.code(0x30, 8); // literal 0
    let mut left = total - 1;
    while left >= 258 {
        bits.code(0xC5, 8); // length 258 (symbol 285)
        bits.code(0, 5); // distance 1
        left -= 258;
    }
    for _ in 0..left {
        bits.code(0x30, 8);
    }
    bits.code(0, 7); // end of block
    bits.put(0, 7); // to a whole byte
    let mut zlib = bits.out;
    let adler = ((total % 65521) << 16) | 1;
    zlib.extend_from_slice(&(adler as u32).to_be_bytes());
    png_of(width, height, 8, 2, &zlib)
}

/// Runs velvet with `args`: (exit status, stdout, stderr, its peak resident memory in KiB).
/// The child is waited for with wait4(2), which alone gives its own resource usage.
#[cfg(unix)]
#[allow(clippy::zombie_processes)]
fn velvet_measured(args: &[&str]) -> (Option<i32>, String, String, u64) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reading = std::thread::spawn(move || {
        let mut text = String::new();
        stderr.read_to_string(&mut text).unwrap();
        text
    });
    let mut out = String::new();
    stdout.read_to_string(&mut out).unwrap();
    let err = reading.join().unwrap();
    let mut status = 0;
    // SAFETY: wait4 on the child's id, which it holds until this waits for it; the rusage
    // is written by the call.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        assert_eq!(
            libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage),
            child.id() as libc::pid_t
        );
        usage
    };
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    (code, out, err, usage.ru_maxrss as u64)
}

/// Every decode is held to `--max-memory`, in preview and `migrate --exact` as in bake: a 5 MB
/// all-zero 16384² RGB PNG (768 MiB decoded) under a budget of 1 GiB is refused before it is
/// decoded, naming the flag, the process staying far below the budget. Preview draws the
/// material from its factors and says why; migrate fails the file (exit status 1).
#[cfg(unix)]
#[test]
fn every_decode_is_held_to_the_memory_budget_in_preview_and_migrate_exact() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    write(&input.join("tex.png"), zero_rgb_png(16384, 16384));
    write(
        &input.join("a.gltf"),
        serde_json::to_string_pretty(&sheen_document("tex.png")).unwrap(),
    );
    let preview = dir.path().join("preview");
    let (status, out, err, peak) = velvet_measured(&[
        "preview",
        "--max-memory",
        "1G",
        "-o",
        s(&preview),
        s(&input),
    ]);
    assert_eq!(status, Some(0), "{out}{err}");
    assert!(peak < 256 * 1024, "preview took {peak} KiB");
    let index = std::fs::read_to_string(preview.join("index.html")).unwrap();
    assert!(
        index.contains(
            "sheenColorTexture not read (image 0: decoding the 16384 × 16384 image (3 bytes a pixel) needs \
             about 1.8 GiB, over the memory budget of 1.0 GiB (raise it with --max-memory); it \
             was not decoded): sheenColorFactor alone is used"
        ),
        "{index}"
    );
    let out_dir = dir.path().join("out");
    let (status, out, err, peak) = velvet_measured(&[
        "migrate",
        "--exact",
        "--max-memory",
        "1G",
        "--out-dir",
        s(&out_dir),
        s(&input),
    ]);
    assert_eq!(status, Some(1), "{out}{err}");
    assert!(peak < 256 * 1024, "migrate --exact took {peak} KiB");
    assert!(
        out.contains(
            "of image 0: image 0: PNG: decoding the 16384 × 16384 image (3 bytes a pixel) \
             needs about 2.2 GiB, over the memory budget of 1.0 GiB (raise it with \
             --max-memory); it was not decoded"
        ),
        "{out}"
    );
    assert!(!out_dir.join("a.gltf").exists());
}

/// Long work stops within a second of SIGTERM or SIGINT: `migrate --exact` of a 4096² texture
/// (seconds of decoding, baking and encoding) exits 143 or 130 at once, nothing written.
#[cfg(unix)]
#[test]
fn long_work_stops_within_a_second_of_a_signal() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in");
    write(&input.join("tex.png"), zero_rgb_png(4096, 4096));
    write(
        &input.join("a.gltf"),
        serde_json::to_string_pretty(&sheen_document("tex.png")).unwrap(),
    );
    for (k, (signal, delay_ms)) in [
        (libc::SIGTERM, 300),
        (libc::SIGINT, 1000),
        (libc::SIGTERM, 2000),
    ]
    .into_iter()
    .enumerate()
    {
        let out_dir = dir.path().join(format!("out-{k}"));
        let (output, took) = velvet_signalled(
            &["migrate", "--exact", "--out-dir", s(&out_dir), s(&input)],
            signal,
            delay_ms,
        );
        let err = String::from_utf8_lossy(&output.stderr);
        let what = format!("signal {signal} after {delay_ms} ms");
        assert_eq!(output.status.code(), Some(128 + signal), "{what}: {err}");
        assert!(took < std::time::Duration::from_secs(1), "{what}: {took:?}");
        assert!(
            err.ends_with("nothing was written for the other 1\n"),
            "{what}: {err}"
        );
        assert!(
            names_under(&out_dir).is_empty(),
            "{what}: {:?}",
            names_under(&out_dir)
        );
    }
}

/// An image's name becomes part of a new texture file's name, never a name the system refuses
/// or one that hides: a 5,000-byte name is cut (the file keeps 64 bytes of it), and `..` or
/// `.velvet-1-x.tmp` lose their leading dots, so that every new file is listed and no run
/// takes it for a temporary file.
#[test]
fn image_names_make_visible_files_of_a_legal_length() {
    let dir = tempfile::tempdir().unwrap();
    let long = "é".repeat(2500);
    for (k, name) in [long.as_str(), "..", ".velvet-1-x.tmp", "."]
        .into_iter()
        .enumerate()
    {
        let input = dir.path().join(format!("in-{k}"));
        let mut doc = sheen_document("tex.png");
        doc["images"][0]["name"] = json!(name);
        write(
            &input.join("a.gltf"),
            serde_json::to_string_pretty(&doc).unwrap(),
        );
        write(
            &input.join("tex.png"),
            png(4, 4, image::ExtendedColorType::Rgb8),
        );
        for command in ["bake", "migrate"] {
            let out_dir = dir.path().join(format!("out-{command}-{k}"));
            let mut args = vec![command, "--out-dir", s(&out_dir), s(&input)];
            if command == "migrate" {
                args.insert(1, "--exact");
            }
            let (status, out, err) = velvet(&args);
            let what = format!("{command}, image name of {} bytes: {name:.20}", name.len());
            assert_eq!(status, 0, "{what}: {out}{err}");
            let names = names_under(&out_dir);
            let new: Vec<&String> = names
                .iter()
                .filter(|n| !["a.gltf", "tex.png"].contains(&n.as_str()))
                .collect();
            assert!(!new.is_empty(), "{what}: {names:?}");
            for file in &new {
                assert!(!file.starts_with('.'), "{what}: {file}");
                assert!(file.len() <= 255, "{what}: {} bytes", file.len());
                assert!(file.ends_with(".png"), "{what}: {file}");
                if name == long {
                    assert!(
                        file.starts_with(&format!("{}.", "é".repeat(32))),
                        "{what}: {file}"
                    );
                }
            }
            let written = std::fs::read(out_dir.join("a.gltf")).unwrap();
            for uri in uris_of(&written) {
                let file = percent_encoding::percent_decode_str(&uri).decode_utf8_lossy();
                assert!(out_dir.join(&*file).is_file(), "{what}: {uri}");
            }
        }
    }
}

/// `bake --out-dir NEW file.glb` creates NEW, as migrate does: a GLB writes no texture file
/// beside it that would have made the folder first.
#[test]
fn bake_and_migrate_of_a_glb_create_a_new_out_dir() {
    let dir = tempfile::tempdir().unwrap();
    let image = png(4, 4, image::ExtendedColorType::Rgb8);
    let padded = image.len().div_ceil(4) * 4;
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_sheen"],
        "materials": [{"extensions": {"KHR_materials_sheen": {
            "sheenColorFactor": [0.5, 0.5, 0.5],
            "sheenColorTexture": {"index": 0},
            "sheenRoughnessFactor": 0.5
        }}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": 0, "mimeType": "image/png"}],
        "bufferViews": [{"buffer": 0, "byteLength": image.len()}],
        "buffers": [{"byteLength": padded}]
    });
    let mut bin = image.clone();
    bin.resize(padded, 0);
    let input = dir.path().join("one.glb");
    write(&input, glb::join(doc.to_string().as_bytes(), Some(&bin)));
    for command in ["bake", "migrate"] {
        let out_dir = dir.path().join(format!("new-{command}/deeper"));
        let (status, out, err) = velvet(&[command, "--out-dir", s(&out_dir), s(&input)]);
        assert_eq!(status, 0, "{command}: {out}{err}");
        assert_eq!(names_under(&out_dir), ["one.glb"], "{command}");
    }
}

/// A velvet.toml listing more than 1,000 exclude patterns is refused naming the limit (each file
/// found is matched against every pattern: 40,000 cost seconds a run), at once.
#[test]
fn an_exclude_list_over_its_limit_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    write(&dir.path().join("a.gltf"), r#"{"asset":{"version":"2.0"}}"#);
    let patterns = |n: usize| {
        (0..n)
            .map(|i| format!("\"d?{i}/[ab]*.gltf\""))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let config = dir.path().join("velvet.toml");
    write(&config, format!("exclude = [{}]\n", patterns(40_000)));
    let started = std::time::Instant::now();
    let (status, out, err) = velvet(&["validate", s(dir.path())]);
    assert!(started.elapsed() < std::time::Duration::from_secs(5));
    assert_eq!(status, 2, "{out}{err}");
    assert_eq!(
        err,
        format!(
            "velvet: {}: exclude: 40000 patterns, more than the 1000 velvet takes (each file \
             found is matched against every one); a folder's pattern (\"dir/**\") excludes all \
             below it\n",
            config.display()
        )
    );
    write(&config, format!("exclude = [{}]\n", patterns(1000)));
    let (status, out, err) = velvet(&["validate", s(dir.path())]);
    assert_eq!(status, 0, "{out}{err}");
}

/// A resource read for an output is held to what it was when its document was loaded, as the
/// document is: an image replaced (a new file renamed over it) or a buffer deleted between the
/// plan and the write fails the file naming the resource, nothing written for it (with and
/// without `--exact`).
#[test]
fn a_resource_replaced_or_deleted_during_a_run_fails_its_file_without_a_write() {
    use velvet::migrate::apply::{execute, plan_file};
    use velvet::output::files::Claims;
    use velvet::output::paths::Job;
    for exact in [false, true] {
        for deleted in [false, true] {
            let dir = tempfile::tempdir().unwrap();
            let input = document_with_resources(&dir.path().join("in"));
            let out = dir.path().join("out");
            let job = Job {
                input: input.clone(),
                output: Some(out.join("asset.gltf")),
            };
            let options = velvet::migrate::Options {
                exact,
                ..velvet::migrate::Options::default()
            };
            let mut plan = plan_file(&job, &options).unwrap();
            let (resource, error) = if deleted {
                let bin = dir.path().join("in/geometry.bin");
                std::fs::remove_file(&bin).unwrap();
                (bin, "cannot")
            } else {
                let png_path = dir.path().join("in/tex.png");
                let other = dir.path().join("in/other.png");
                write(&other, png(4, 4, image::ExtendedColorType::Rgb8));
                std::fs::rename(&other, &png_path).unwrap();
                (png_path, "changed while velvet worked on it")
            };
            let what = format!("exact {exact}, deleted {deleted}");
            let message = execute(&mut plan, &Claims::default()).unwrap_err();
            assert!(
                message.contains(&resource.display().to_string()) && message.contains(error),
                "{what}: {message}"
            );
            assert!(
                names_under(&out).is_empty(),
                "{what}: {:?}",
                names_under(&out)
            );
        }
    }
}

/// Runs velvet with `args`, sends it `signal` after `delay_ms` and waits for it: its output,
/// and the time from the signal to its exit.
#[cfg(unix)]
fn velvet_signalled(
    args: &[&str],
    signal: i32,
    delay_ms: u64,
) -> (std::process::Output, std::time::Duration) {
    let child = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(delay_ms));
    let sent = std::time::Instant::now();
    // SAFETY: kill(2) on the child's id, which it holds until it is waited for.
    unsafe { libc::kill(child.id() as libc::pid_t, signal) };
    let output = child.wait_with_output().unwrap();
    (output, sent.elapsed())
}

/// The name velvet's "stopped by" line gives `signal` (SIGINT or SIGTERM).
#[cfg(unix)]
fn signal_name(signal: i32) -> &'static str {
    if signal == libc::SIGINT {
        "SIGINT"
    } else {
        "SIGTERM"
    }
}
