//! Applying a bake plan to a document: new images (GLB: bufferViews appended to the BIN chunk,
//! 4-byte aligned; .gltf: files next to the output, or `data:` URIs when embedding), new
//! textures that keep the old ones' samplers, names and extensions with their sources replaced,
//! textureInfos pointed at them (texCoord and KHR_texture_transform untouched), factors set to
//! the identity explicitly, uniform outputs collapsed into factors when asked, and then the
//! replaced textures and images that nothing references any more dropped.
//!
//! This step decides file names but writes nothing: the caller gets the document, the BIN
//! chunk and the files to write, and says through [`Names`] which file names are free.

use std::collections::{BTreeSet, HashMap};

use base64::Engine;
use serde::Serialize;
use serde_json::{json, Value};

use super::codec::OutputFormat;
use super::engine::{Baked, OutputId};
use super::plan::{BakePlan, Level, Note, SlotPlan};
use super::prune::{prune, Dropped};
use super::recipe::Channel;
use super::srgb;
use crate::asset::Container;
use crate::layers::Channels;

/// How outputs are stored.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ApplyOptions {
    /// .gltf: store new images as `data:` URIs instead of files.
    pub embed: bool,
}

/// Which file names next to the output may be used.
pub trait Names {
    /// Whether `name` may hold `bytes`: nothing else claims it (the caller may also accept a
    /// file that already holds exactly these bytes). A `true` answer claims the name.
    fn claim(&mut self, name: &str, bytes: &[u8]) -> bool;
}

/// A new image file to write next to a .gltf output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NewFile {
    /// The file name (also the URI, percent-encoded).
    pub name: String,
    /// The encoded image.
    pub bytes: Vec<u8>,
}

/// What became of one output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct OutputReport {
    /// The output's id in the plan.
    #[serde(skip)]
    pub output: OutputId,
    /// The image baked.
    pub source_image: usize,
    /// What the output holds.
    pub name: String,
    /// The new image's index in the written document; `None` when collapsed into factors.
    pub image: Option<usize>,
    /// Where its bytes went (file name, `data:` or `bufferView`).
    pub stored: String,
    /// Size and format.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Bits per channel.
    pub bits: u32,
    /// `image/png`, `image/webp`, `image/jpeg`; `None` when collapsed.
    pub mime_type: Option<&'static str>,
    /// Encoded size in bytes.
    pub bytes: usize,
    /// Texels clamped (factors outside [0, 1]).
    pub clamped: u64,
    /// Largest quantisation error in codes, when measured.
    pub max_error: Option<f64>,
}

/// The edited asset.
#[derive(Clone, Debug)]
pub struct Applied {
    /// The new document.
    pub json: Value,
    /// The new BIN chunk (GLB).
    pub bin: Option<Vec<u8>>,
    /// Files to write next to the output (.gltf).
    pub files: Vec<NewFile>,
    /// One entry per output.
    pub outputs: Vec<OutputReport>,
    /// What was dropped.
    pub dropped: Dropped,
    /// Remarks made while applying.
    pub notes: Vec<Note>,
}

const PATH_SEGMENT: &percent_encoding::AsciiSet = &percent_encoding::NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~');

/// The name an image goes by: its `name`, else its URI's file stem, else `image<N>`
/// (`images` is the document's `images` array).
fn image_base_name(images: &Value, image: usize) -> String {
    let name = image_given_name(images, image);
    // A file name holds at most 255 bytes: the image's part of a new file's name is cut to
    // MAX_IMAGE_NAME_BYTES (at a character's boundary), leaving room for the slots, the hash
    // and the extension, so that a 5,000-byte image name cannot fail its file (ENAMETOOLONG).
    let mut end = name.len().min(MAX_IMAGE_NAME_BYTES);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    name[..end].to_owned()
}

/// The most bytes of an image's name a new file's name keeps.
const MAX_IMAGE_NAME_BYTES: usize = 64;

fn image_given_name(images: &Value, image: usize) -> String {
    let entry = &images[image];
    if let Some(name) = entry
        .get("name")
        .and_then(Value::as_str)
        .filter(|n| !n.is_empty())
    {
        return name.to_owned();
    }
    if let Some(uri) = entry
        .get("uri")
        .and_then(Value::as_str)
        .filter(|u| !u.starts_with("data:"))
    {
        let decoded = percent_encoding::percent_decode_str(uri).decode_utf8_lossy();
        let file = decoded.rsplit('/').next().unwrap_or("");
        let stem = file.rsplit_once('.').map_or(file, |(s, _)| s);
        if !stem.is_empty() {
            return stem.to_owned();
        }
    }
    format!("image{image}")
}

/// What an output is called (`<image>.<labels>`, e.g. `fabric.fuzzRoughness`): the source
/// image's name and the slots it serves, from the document's `images` array as loaded.
pub fn output_name(images: &Value, info: &super::plan::OutputInfo) -> String {
    format!(
        "{}.{}",
        image_base_name(images, info.image),
        info.labels.join(".")
    )
}

/// A 64-bit FNV-1a hash of `bytes` as 12 hex digits: part of a new file's name, so that the
/// name follows from what the file holds, never from which thread wrote first.
pub fn content_hash(bytes: &[u8]) -> String {
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{:012x}", hash >> 16)
}

/// The file names an output named `name` holding `bytes` tries, in order:
/// `<name>.<hash>.<ext>`, then `<name>.<hash>.<n>.<ext>` (n = 2, 3, …) should a name be
/// taken by other content.
pub fn file_candidates(
    name: &str,
    format: OutputFormat,
    bytes: &[u8],
) -> impl Iterator<Item = String> {
    let stem = format!("{}.{}", file_safe(name), content_hash(bytes));
    let ext = format.extension();
    (1..).map(move |n| {
        if n == 1 {
            format!("{stem}.{ext}")
        } else {
            format!("{stem}.{n}.{ext}")
        }
    })
}

/// The URI of a file next to the document.
pub fn file_uri(file: &str) -> String {
    percent_encoding::utf8_percent_encode(file, PATH_SEGMENT).to_string()
}

/// A file name made safe: path separators and control characters become '_', and leading
/// dots are dropped, so that no image name (`..`, `.velvet-1-x.tmp`) makes a hidden file, one a
/// folder listing leaves out or a later run takes for its own temporary file.
fn file_safe(name: &str) -> String {
    let safe: String = name
        .chars()
        .map(|c| {
            if c == '/' || c == '\\' || c.is_control() || c == ':' {
                '_'
            } else {
                c
            }
        })
        .collect();
    match safe.trim_start_matches('.') {
        "" => "image".to_string(),
        kept => kept.to_string(),
    }
}

/// The factor values a uniform output gives one slot, if every output of the slot is uniform
/// and they agree.
fn uniform_factor(slot: &SlotPlan, baked: &[Baked]) -> Option<Vec<f64>> {
    let mut agreed: Option<Vec<f64>> = None;
    for source in &slot.sources {
        let b = &baked[source.output.0];
        let codes = b.uniform.as_ref()?;
        let max = f64::from(b.depth.max_code());
        let code = |c: Channel| -> f64 {
            match b.layout.storage_index(c) {
                Some(i) => f64::from(codes[i]) / max,
                None => 1.0,
            }
        };
        let values: Vec<f64> = match crate::layers::SLOTS
            .iter()
            .find(|s| s.texture == slot.texture_key)
            .map(|s| s.channels)
        {
            Some(Channels::Rgb) => [Channel::R, Channel::G, Channel::B]
                .into_iter()
                .map(|c| srgb::decode(code(c)))
                .collect(),
            Some(Channels::Alpha) => vec![code(Channel::A)],
            _ => vec![code(Channel::R)],
        };
        match &agreed {
            Some(a) if *a != values => return None,
            _ => agreed = Some(values),
        }
    }
    agreed
}

fn factor_json(values: &[f64]) -> Value {
    if values.len() == 3 {
        json!(values)
    } else {
        json!(values[0])
    }
}

/// Applies `plan` with its bake results (`baked[id]` for each output id; their encoded bytes
/// are moved out) to a document (as loaded, or with its URIs already relocated) and its GLB
/// BIN chunk.
#[allow(clippy::too_many_arguments)]
pub fn apply(
    mut json: Value,
    mut bin: Option<Vec<u8>>,
    container: Container,
    plan: &BakePlan,
    baked: &mut [Baked],
    options: ApplyOptions,
    names: &mut dyn Names,
) -> Applied {
    // Names come from the images as loaded (only they are kept, not the whole document).
    let source_images = json.get("images").cloned().unwrap_or(Value::Null);
    let mut files = Vec::new();
    let mut notes = Vec::new();
    let bin_usable = bin_usable(&json, container);
    if let (true, Some(b)) = (bin_usable, bin.as_mut()) {
        // Drop the chunk's padding: appends start at the buffer's declared end.
        let declared = json
            .pointer("/buffers/0/byteLength")
            .and_then(Value::as_u64);
        if let Some(len) = declared {
            b.truncate(len as usize);
        }
    }
    let mut image_of: HashMap<OutputId, usize> = HashMap::new();
    let mut outputs: Vec<OutputReport> = baked
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let info = &plan.outputs[i];
            OutputReport {
                output: OutputId(i),
                source_image: info.image,
                name: output_name(&source_images, info),
                image: None,
                stored: "collapsed into factors".to_owned(),
                width: b.width,
                height: b.height,
                bits: b.depth.bits(),
                mime_type: None,
                bytes: 0,
                clamped: b.stats.clamped(),
                max_error: b.stats.max_error(),
            }
        })
        .collect();
    let mut new_texture_of: HashMap<(usize, Vec<(String, usize)>), usize> = HashMap::new();
    let mut replaced_textures = BTreeSet::new();
    let mut replaced_images = BTreeSet::new();

    for slot in &plan.slots {
        replaced_textures.insert(slot.texture);
        replaced_images.extend(slot.sources.iter().map(|s| s.image));
        if let Some(values) = uniform_factor(slot, baked) {
            if let Some(layer) = json
                .pointer_mut(&slot.layer_pointer)
                .and_then(Value::as_object_mut)
            {
                layer.shift_remove(slot.texture_key);
                layer.insert(slot.factor_key.to_owned(), factor_json(&values));
            }
            notes.push(Note {
                level: Level::Info,
                pointer: slot.texture_pointer(),
                message: format!(
                    "every texel of the baked {} is equal: the texture is dropped and {} = {}",
                    slot.texture_key,
                    slot.factor_key,
                    factor_json(&values)
                ),
            });
            continue;
        }
        // One new image per output, made when first needed.
        let mut sources = Vec::new();
        for source in &slot.sources {
            let id = source.output;
            let image = match image_of.get(&id) {
                Some(&i) => i,
                None if baked[id.0].stored.is_some() && !bin_usable && !options.embed => {
                    // Already written next to the output as it was encoded.
                    let stored = baked[id.0].stored.clone().expect("checked");
                    let report = &mut outputs[id.0];
                    let images = images_mut(&mut json);
                    images.push(json!({"name": report.name, "uri": file_uri(&stored.name)}));
                    let index = images.len() - 1;
                    report.stored = stored.name;
                    report.mime_type = Some(stored.format.mime_type());
                    report.bytes = stored.bytes;
                    report.image = Some(index);
                    image_of.insert(id, index);
                    index
                }
                None => {
                    // The bytes move into the document: each output is held once.
                    let (format, bytes) = baked[id.0]
                        .encoded
                        .take()
                        .expect("a non-uniform output is encoded or stored");
                    let size = bytes.len();
                    let report = &mut outputs[id.0];
                    let (index, stored) = add_image(
                        &mut json,
                        &mut bin,
                        container,
                        options.embed,
                        &report.name,
                        format,
                        bytes,
                        names,
                        &mut files,
                    );
                    report.stored = stored;
                    report.mime_type = Some(format.mime_type());
                    report.bytes = size;
                    report.image = Some(index);
                    image_of.insert(id, index);
                    index
                }
            };
            sources.push((source.within_texture.clone(), image));
        }
        let key = (slot.texture, sources.clone());
        let texture = match new_texture_of.get(&key) {
            Some(&t) => t,
            None => {
                let mut texture = json["textures"][slot.texture].clone();
                for (within, image) in &sources {
                    if let Some(v) = texture.pointer_mut(within) {
                        *v = Value::from(*image);
                    }
                }
                let list = json["textures"]
                    .as_array_mut()
                    .expect("textures is an array");
                list.push(texture);
                let index = list.len() - 1;
                new_texture_of.insert(key, index);
                index
            }
        };
        if let Some(info) = json.pointer_mut(&slot.texture_pointer()) {
            info["index"] = Value::from(texture);
        }
        if let Some(layer) = json
            .pointer_mut(&slot.layer_pointer)
            .and_then(Value::as_object_mut)
        {
            layer.insert(
                slot.factor_key.to_owned(),
                slot.written_factor
                    .clone()
                    .unwrap_or_else(|| slot.identity()),
            );
        }
    }
    let dropped = prune(
        &mut json,
        if bin_usable { bin.as_mut() } else { None },
        &replaced_textures,
        &replaced_images,
    );
    // Image and bufferView indices moved with the drop: report the final ones.
    for report in &mut outputs {
        if let Some(i) = report.image {
            let before = dropped.images.iter().filter(|&&d| d < i).count();
            report.image = Some(i - before);
            if let Some(view) = json
                .pointer(&format!("/images/{}/bufferView", i - before))
                .and_then(Value::as_u64)
            {
                report.stored = format!("bufferView {view}");
            }
        }
    }
    if let (true, Some(b)) = (bin_usable, bin.as_ref()) {
        if b.is_empty() {
            drop_empty_bin(&mut json);
            bin = None;
        } else if let Some(buffer) = json.pointer_mut("/buffers/0") {
            buffer["byteLength"] = Value::from(b.len());
        }
    }
    Applied {
        json,
        bin,
        files,
        outputs,
        dropped,
        notes,
    }
}

/// Whether a GLB stores new images in its BIN chunk: buffer 0 is the chunk unless it has a URI.
fn bin_usable(json: &Value, container: Container) -> bool {
    container == Container::Glb
        && json
            .pointer("/buffers/0")
            .is_none_or(|b| b.get("uri").is_none())
}

/// Adds one encoded image to a document and returns its index in `images` and where its bytes
/// went: in a GLB, a new bufferView at the 4-byte-aligned end of the BIN chunk (`bin`, created
/// with its buffer when absent); in a .gltf, a file next to the output (named by
/// [`file_candidates`]: the first name `names` accepts; returned in `files` for the caller to
/// write), or a `data:` URI when `embed` (or when a GLB's buffer 0 is not its BIN chunk).
#[allow(clippy::too_many_arguments)]
pub fn add_image(
    json: &mut Value,
    bin: &mut Option<Vec<u8>>,
    container: Container,
    embed: bool,
    name: &str,
    format: OutputFormat,
    bytes: Vec<u8>,
    names: &mut dyn Names,
    files: &mut Vec<NewFile>,
) -> (usize, String) {
    let glb = container == Container::Glb;
    let (entry, stored) = if bin_usable(json, container) {
        let data = bin.get_or_insert_with(Vec::new);
        while !data.len().is_multiple_of(4) {
            data.push(0);
        }
        let offset = data.len();
        data.extend_from_slice(&bytes);
        let end = data.len();
        let root = json.as_object_mut().expect("the document is an object");
        let buffers = root.entry("buffers").or_insert_with(|| json!([]));
        match buffers.as_array_mut().expect("buffers is an array") {
            list if list.is_empty() => list.push(json!({"byteLength": end})),
            list => list[0]["byteLength"] = Value::from(end),
        }
        let views = root
            .entry("bufferViews")
            .or_insert_with(|| json!([]))
            .as_array_mut()
            .expect("bufferViews is an array");
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bytes.len()}));
        let view = views.len() - 1;
        (
            json!({"name": name, "mimeType": format.mime_type(), "bufferView": view}),
            format!("bufferView {view}"),
        )
    } else if glb || embed {
        let data = base64::engine::general_purpose::STANDARD.encode(&bytes);
        (
            json!({"name": name, "uri": format!("data:{};base64,{data}", format.mime_type())}),
            "data: URI".to_owned(),
        )
    } else if let Some(same) = files.iter().find(|f| f.bytes == bytes) {
        // Identical bytes baked for another slot are one file: written once, named twice.
        let file = same.name.clone();
        (json!({"name": name, "uri": file_uri(&file)}), file)
    } else {
        let file = file_candidates(name, format, &bytes)
            .find(|candidate| names.claim(candidate, &bytes))
            .expect("some name is free");
        let uri = file_uri(&file);
        files.push(NewFile {
            name: file.clone(),
            bytes,
        });
        (json!({"name": name, "uri": uri}), file)
    };
    let images = images_mut(json);
    images.push(entry);
    (images.len() - 1, stored)
}

/// Removes buffer 0 (the GLB's BIN chunk) once nothing is left in it and no bufferView names
/// it (a buffer's byteLength must be at least 1), renumbering the other buffers' references.
fn drop_empty_bin(json: &mut Value) {
    fn buffer_refs(value: &mut Value, f: &mut dyn FnMut(&mut Value)) {
        match value {
            Value::Object(map) => {
                for (k, v) in map.iter_mut() {
                    if k == "buffer" && v.is_u64() {
                        f(v);
                    } else {
                        buffer_refs(v, f);
                    }
                }
            }
            Value::Array(items) => items.iter_mut().for_each(|v| buffer_refs(v, f)),
            _ => {}
        }
    }
    let mut named = false;
    buffer_refs(json, &mut |v| named |= v.as_u64() == Some(0));
    if named || json.pointer("/buffers/0").is_none() {
        return;
    }
    buffer_refs(json, &mut |v| *v = Value::from(v.as_u64().unwrap_or(1) - 1));
    let root = json.as_object_mut().expect("the document is an object");
    if let Some(Value::Array(buffers)) = root.get_mut("buffers") {
        buffers.remove(0);
        if buffers.is_empty() {
            root.shift_remove("buffers");
        }
    }
}
/// The document's `images` array, created when absent (the plan has checked that the document
/// is an object whose `images`, if any, is an array).
fn images_mut(json: &mut Value) -> &mut Vec<Value> {
    json.as_object_mut()
        .expect("the document is an object")
        .entry("images")
        .or_insert_with(|| json!([]))
        .as_array_mut()
        .expect("images is an array")
}
