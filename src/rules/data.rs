//! Accessor data, read for the rules that judge values rather than JSON (the Khronos
//! glTF-Validator's DataError codes): each buffer is opened once per document, on the first
//! rule that asks for it ([`Buffers`]), and each accessor's bytes are read from it when a rule
//! asks for its elements ([`Elements`]): a buffer's file is never held whole, so that a
//! document's memory is its text and the accessors being checked, whatever its buffers weigh.
//! Bytes already in memory (a .glb's BIN chunk, a `data:` URI) are read where they lie.
//!
//! An accessor is decoded only when everything it names holds together: a valid component
//! type and type, a buffer view inside its buffer, the elements inside the view, sparse indices
//! and values inside theirs; and when its bytes are in the file as they are read (not behind
//! a meshopt compression extension, nor Draco's, whose accessors have no buffer view). Anything else is the JSON-level rules' finding (UNRESOLVED_REFERENCE,
//! ACCESSOR_TOO_LONG, BUFFER_VIEW_TOO_LONG, …) and its data is not judged.
//!
//! Values are read as they are stored (`normalized` has no effect on `min` and `max`, as the
//! spec says); [`Elements::normalize`] gives the value a loader sees where a check needs it.

use super::accessors::{component_size, components, element_layout};
use super::{elements, Context};
use crate::asset::tape::Node;
use crate::asset::BufferData;
use std::borrow::Cow;
use std::sync::OnceLock;

/// What the data checks read: accessors, their views and buffers, and what draws, skins and
/// animates them. A view's `target` is no part of it (BUFFER_VIEW_TARGET_MISSING's fix sets it),
/// so a trial of that fix does not read a document's data again.
pub const DATA_READS: super::Reads = super::Reads::Properties {
    properties: &[
        "accessors",
        "bufferViews",
        "buffers",
        "meshes",
        "nodes",
        "skins",
        "animations",
    ],
    except: &[("bufferViews", "target")],
};

/// The document's buffers, each opened on first use and kept for the other rules.
pub struct Buffers<'a> {
    slots: Vec<OnceLock<Option<BufferData<'a>>>>,
}

impl<'a> Buffers<'a> {
    pub fn new(count: usize) -> Buffers<'a> {
        Buffers {
            slots: (0..count).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Buffer `index`; `None` when it cannot be read or is shorter than its byteLength (the
    /// resource rules' findings).
    pub fn get(&self, asset: &'a crate::asset::Asset, index: usize) -> Option<&BufferData<'a>> {
        self.slots
            .get(index)?
            .get_or_init(|| asset.buffer_data(index).ok())
            .as_ref()
    }
}

/// How far from 1 a unit vector's length may be (a little more than signed 8-bit quantization
/// loses), as the Khronos validator allows: three components, and four.
pub const UNIT_LENGTH_VEC3: f64 = 0.00674;
pub const UNIT_LENGTH_VEC4: f64 = 0.00769;
/// How far from 1 a sum of weights may be, per two components beyond the second (a little
/// more than unsigned 8-bit quantization loses), as the Khronos validator allows.
pub const UNIT_SUM_STEP: f64 = 0.0039216;

/// The largest number of components an element has (MAT4).
pub const MAX_COMPONENTS: usize = 16;

/// Where an accessor's stored elements lie.
struct Strided<'a> {
    /// From the first element's first byte to the last element's last.
    bytes: Cow<'a, [u8]>,
    stride: usize,
    /// For matrices whose columns are padded to 4 bytes: (rows, bytes from column to column).
    columns: Option<(usize, usize)>,
}

/// A sparse accessor's substitutions: (element index, its values' place in `values`), sorted by
/// element index.
struct Sparse<'a> {
    substitutions: Vec<(usize, usize)>,
    values: Cow<'a, [u8]>,
}

/// An accessor's elements, ready to be read.
pub struct Elements<'a> {
    pub component_type: u64,
    pub components: usize,
    pub count: usize,
    pub normalized: bool,
    size: usize,
    base: Option<Strided<'a>>,
    sparse: Option<Sparse<'a>>,
}

/// The index `node` holds (of an accessor, a mesh, a skin, a sampler, …): an unsigned integer
/// that fits a `usize`.
pub fn index_of(node: Option<Node>) -> Option<usize> {
    usize::try_from(node?.as_u64()?).ok()
}

/// `length` bytes from `offset` in buffer view `view`, when the view lies inside its buffer
/// and holds them: a view that a meshopt extension decompresses into holds them only once
/// decoded (its buffer is a fallback, often zeros or absent), so its data is not judged.
fn view_part<'c>(
    cx: &'c Context,
    view: usize,
    offset: usize,
    length: usize,
) -> Option<Cow<'c, [u8]>> {
    let json = cx.json();
    let view = json.get("bufferViews")?.get(view)?;
    if let Some(extensions) = view.get("extensions") {
        if ["EXT_meshopt_compression", "KHR_meshopt_compression"]
            .iter()
            .any(|name| extensions.get(*name).is_some())
        {
            return None;
        }
    }
    let buffer = index_of(view.get("buffer"))?;
    let view_offset = byte_offset(view)?;
    let view_length = index_of(view.get("byteLength"))?;
    let data = cx.buffer(buffer)?;
    let view_end = view_offset.checked_add(view_length)?;
    if view_end > data.len() {
        return None;
    }
    let end = offset
        .checked_add(length)
        .filter(|end| *end <= view_length)?;
    data.read(view_offset + offset..view_offset + end)
}

impl<'a> Elements<'a> {
    /// Accessor `index`'s elements, or `None` when they cannot be read as the JSON says.
    pub fn of(cx: &'a Context, index: usize) -> Option<Elements<'a>> {
        let accessor = cx.json().get("accessors")?.get(index)?;
        let component_type = accessor.get("componentType")?.as_u64()?;
        let size = usize::try_from(component_size(component_type)?).ok()?;
        let kind = accessor.get("type")?.as_str()?;
        let components = usize::try_from(components(&kind)?).ok()?;
        let count = index_of(accessor.get("count")).filter(|c| *c >= 1)?;
        let normalized = accessor.get("normalized").and_then(|n| n.as_bool()) == Some(true);
        let base = match accessor.get("bufferView") {
            None => None,
            Some(view) => {
                let view = index_of(Some(view))?;
                let offset = byte_offset(accessor)?;
                let (element, packed) = element_layout(size as u64, &kind)?;
                let (element, packed) = (
                    usize::try_from(element).ok()?,
                    usize::try_from(packed).ok()?,
                );
                let stride = match cx
                    .json()
                    .get("bufferViews")
                    .and_then(|v| v.get(view))
                    .and_then(|v| v.get("byteStride"))
                {
                    None => packed,
                    Some(s) => index_of(Some(s)).filter(|s| *s >= element)?,
                };
                let needed = stride.checked_mul(count - 1)?.checked_add(element)?;
                let bytes = view_part(cx, view, offset, needed)?;
                let columns = (element != size * components).then(|| {
                    let rows = match components {
                        4 => 2,
                        9 => 3,
                        _ => 4,
                    };
                    (rows, (rows * size).next_multiple_of(4))
                });
                Some(Strided {
                    bytes,
                    stride,
                    columns,
                })
            }
        };
        let sparse = match accessor.get("sparse") {
            None => None,
            Some(sparse) => Some(Self::sparse(cx, sparse, size * components, count)?),
        };
        if base.is_none() && sparse.is_none() {
            // No data at all: the values come from elsewhere (an extension), not from the file.
            return None;
        }
        Some(Elements {
            component_type,
            components,
            count,
            normalized,
            size,
            base,
            sparse,
        })
    }

    fn sparse(cx: &'a Context, sparse: Node, element: usize, count: usize) -> Option<Sparse<'a>> {
        let n = index_of(sparse.get("count")).filter(|n| *n >= 1 && *n <= count)?;
        let indices = sparse.get("indices")?;
        let index_size = index_size(indices)?;
        let index_bytes = sparse_part(cx, indices, n.checked_mul(index_size)?)?;
        let values = sparse_part(cx, sparse.get("values")?, n.checked_mul(element)?)?;
        let mut substitutions = Vec::with_capacity(n);
        for (k, index) in read_indices(&index_bytes, index_size).enumerate() {
            let index = usize::try_from(index).ok().filter(|i| *i < count)?;
            substitutions.push((index, k * element));
        }
        // A later substitution of one element wins, as a loader applying them in order does:
        // the sort is stable, and readers take the last of an element's substitutions.
        substitutions.sort_by_key(|(index, _)| *index);
        Some(Sparse {
            substitutions,
            values,
        })
    }

    /// One stored component as a number.
    fn read(&self, bytes: &[u8]) -> f64 {
        match (self.component_type, bytes) {
            (5120, [b, ..]) => f64::from(*b as i8),
            (5121, [b, ..]) => f64::from(*b),
            (5122, [a, b, ..]) => f64::from(i16::from_le_bytes([*a, *b])),
            (5123, [a, b, ..]) => f64::from(u16::from_le_bytes([*a, *b])),
            (5125, [a, b, c, d, ..]) => f64::from(u32::from_le_bytes([*a, *b, *c, *d])),
            (5126, [a, b, c, d, ..]) => f64::from(f32::from_le_bytes([*a, *b, *c, *d])),
            _ => 0.0,
        }
    }

    /// The value a loader sees for stored value `value`: for a normalized integer accessor,
    /// the spec's conversion to [0, 1] or [-1, 1]; otherwise the value itself.
    pub fn normalize(&self, value: f64) -> f64 {
        if !self.normalized {
            return value;
        }
        match self.component_type {
            5120 => (value / 127.0).max(-1.0),
            5121 => value / 255.0,
            5122 => (value / 32767.0).max(-1.0),
            5123 => value / 65535.0,
            _ => value,
        }
    }

    /// Element `i`'s stored components (sparse substitutions applied) into `values`, which
    /// holds [`Elements::components`] of them; for reading several accessors side by side.
    pub fn element(&self, i: usize, values: &mut [f64]) {
        if let Some(sparse) = &self.sparse {
            // The last substitution of an element wins.
            let end = sparse
                .substitutions
                .partition_point(|(index, _)| *index <= i);
            if let Some(&(index, at)) = end.checked_sub(1).and_then(|k| sparse.substitutions.get(k))
            {
                if index == i {
                    for (c, slot) in values.iter_mut().enumerate() {
                        *slot = self.read(&sparse.values[at + c * self.size..]);
                    }
                    return;
                }
            }
        }
        match &self.base {
            Some(base) => self.read_stored(base, i, values),
            None => values.fill(0.0),
        }
    }

    fn read_stored(&self, base: &Strided, i: usize, values: &mut [f64]) {
        let start = i * base.stride;
        if let Some((rows, column)) = base.columns {
            for (c, slot) in values.iter_mut().enumerate() {
                let offset = (c / rows) * column + (c % rows) * self.size;
                *slot = self.read(&base.bytes[start + offset..]);
            }
            return;
        }
        // Packed components: the type chosen once an element, not once a component (most of
        // a data-heavy document's reading is float vectors and integer indices).
        let packed = &base.bytes[start..start + self.size * values.len()];
        match self.component_type {
            5126 => decode(packed, values, |b: [u8; 4]| f32::from_le_bytes(b).into()),
            5125 => decode(packed, values, |b: [u8; 4]| u32::from_le_bytes(b).into()),
            5123 => decode(packed, values, |b: [u8; 2]| u16::from_le_bytes(b).into()),
            5122 => decode(packed, values, |b: [u8; 2]| i16::from_le_bytes(b).into()),
            5121 => decode(packed, values, |b: [u8; 1]| b[0].into()),
            5120 => decode(packed, values, |b: [u8; 1]| (b[0] as i8).into()),
            _ => values.fill(0.0),
        }
    }

    /// The stored bytes of an accessor with no sparse substitutions and no padded columns,
    /// and the bytes from one element to the next: its values can be read as they lie,
    /// without the general reader's steps (the data checks' hottest loops).
    pub fn packed(&self) -> Option<(&[u8], usize)> {
        let base = self.base.as_ref()?;
        (self.sparse.is_none() && base.columns.is_none())
            .then(|| (base.bytes.as_ref(), base.stride))
    }

    /// The values of a scalar accessor of unsigned integers (indices) as they lie, when it is
    /// [`Elements::packed`].
    pub fn packed_unsigned(&self) -> Option<impl Iterator<Item = u64> + '_> {
        let (bytes, stride) = self.packed()?;
        let size = self.size;
        (self.components == 1 && matches!(self.component_type, 5121 | 5123 | 5125))
            .then(|| (0..self.count).map(move |i| unsigned_at(&bytes[i * stride..], size)))
    }

    /// [`Elements::packed`] for a float accessor.
    pub fn packed_floats(&self) -> Option<(&[u8], usize)> {
        self.packed().filter(|_| self.component_type == 5126)
    }

    /// Calls `visit` with each element's index and its stored components, in order, with the
    /// sparse substitutions applied.
    pub fn for_each(&self, mut visit: impl FnMut(usize, &[f64])) {
        let mut element = [0.0; MAX_COMPONENTS];
        let values = &mut element[..self.components];
        let mut next = 0;
        for i in 0..self.count {
            let mut substituted = None;
            if let Some(sparse) = &self.sparse {
                while let Some(&(index, at)) = sparse.substitutions.get(next) {
                    if index > i {
                        break;
                    }
                    if index == i {
                        substituted = Some(at);
                    }
                    next += 1;
                }
                if let Some(at) = substituted {
                    for (c, slot) in values.iter_mut().enumerate() {
                        *slot = self.read(&sparse.values[at + c * self.size..]);
                    }
                    visit(i, values);
                    continue;
                }
            }
            match &self.base {
                Some(base) => self.read_stored(base, i, values),
                None => values.fill(0.0),
            }
            visit(i, values);
        }
    }
}

/// Packed components of `N` bytes each into `values`, one `convert` each.
#[inline(always)]
fn decode<const N: usize>(packed: &[u8], values: &mut [f64], convert: impl Fn([u8; N]) -> f64) {
    for (slot, b) in values.iter_mut().zip(packed.chunks_exact(N)) {
        let mut bytes = [0; N];
        bytes.copy_from_slice(b);
        *slot = convert(bytes);
    }
}

/// Unsigned little-endian integers of `size` bytes (1, 2 or 4), one after the other.
fn read_indices(bytes: &[u8], size: usize) -> impl Iterator<Item = u64> + '_ {
    bytes
        .chunks_exact(size)
        .map(move |at| unsigned_at(at, size))
}

/// The unsigned little-endian integer of `size` bytes (1, 2 or 4) that `at` starts with.
#[inline(always)]
fn unsigned_at(at: &[u8], size: usize) -> u64 {
    match size {
        1 => u64::from(at[0]),
        2 => u64::from(u16::from_le_bytes([at[0], at[1]])),
        _ => u64::from(u32::from_le_bytes([at[0], at[1], at[2], at[3]])),
    }
}

/// Accessor `index`'s sparse indices as stored, with the accessor's count, when they can be
/// read; for the rule that judges them (decoding the elements refuses indices out of range).
pub fn sparse_indices(cx: &Context, index: usize) -> Option<(Vec<u64>, u64)> {
    let accessor = cx.json().get("accessors")?.get(index)?;
    let count = accessor.get("count")?.as_u64()?;
    let sparse = accessor.get("sparse")?;
    let n = index_of(sparse.get("count")).filter(|n| *n >= 1)?;
    let indices = sparse.get("indices")?;
    let size = index_size(indices)?;
    let bytes = sparse_part(cx, indices, n.checked_mul(size)?)?;
    Some((read_indices(&bytes, size).collect(), count))
}

/// The `byteOffset` of a view, an accessor or a sparse part: 0 when absent, `None` when it is
/// not an index.
fn byte_offset(holder: Node) -> Option<usize> {
    holder
        .get("byteOffset")
        .map_or(Some(0), |o| index_of(Some(o)))
}

/// The size in bytes of sparse `indices`' component type (unsigned byte, short or int).
fn index_size(indices: Node) -> Option<usize> {
    match indices.get("componentType")?.as_u64()? {
        5121 => Some(1),
        5123 => Some(2),
        5125 => Some(4),
        _ => None,
    }
}

/// The `length` bytes a sparse part (`indices` or `values`) names in its view.
fn sparse_part<'c>(cx: &'c Context, holder: Node, length: usize) -> Option<Cow<'c, [u8]>> {
    view_part(
        cx,
        index_of(holder.get("bufferView"))?,
        byte_offset(holder)?,
        length,
    )
}

/// The number of accessors of the document.
pub fn accessor_count(cx: &Context) -> usize {
    elements(cx.json().get("accessors")).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::asset::{load_bytes_with, LoadOptions};
    use base64::Engine;

    fn decoded(accessors: &str, views: &str, bytes: &[u8]) -> Vec<Vec<Vec<f64>>> {
        let data = base64::engine::general_purpose::STANDARD.encode(bytes);
        let uri = format!("data:application/octet-stream;base64,{data}");
        decoded_from(
            accessors,
            views,
            &uri,
            bytes.len(),
            std::path::Path::new("t.gltf"),
        )
    }

    /// The elements of every accessor of a document whose one buffer (`byte_length` long) is
    /// at `uri`, the document read as the file `path`.
    fn decoded_from(
        accessors: &str,
        views: &str,
        uri: &str,
        byte_length: usize,
        path: &std::path::Path,
    ) -> Vec<Vec<Vec<f64>>> {
        let text = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":{byte_length},"uri":"{uri}"}}],
            "bufferViews":{views},"accessors":{accessors}}}"#
        );
        let loaded = load_bytes_with(path, text.as_bytes(), &LoadOptions::default());
        let asset = loaded.asset.expect("the document parses");
        let schemas = super::super::schema::Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        (0..accessor_count(&cx))
            .map(|i| {
                let mut out = Vec::new();
                if let Some(e) = Elements::of(&cx, i) {
                    e.for_each(|_, v| out.push(v.to_vec()));
                }
                out
            })
            .collect()
    }

    #[test]
    fn elements_are_read_with_strides_padding_signs_and_sparse_substitutions() {
        let mut bytes = Vec::new();
        // View 0, stride 8: two float pairs (1, 2) and (3, 4), 4 bytes between them.
        for v in [1.0f32, 2.0, 9.0, 3.0, 4.0, 9.0] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        // View 1 (offset 24): a byte MAT2, columns padded to 4 bytes: [1, -2 | 3, -4].
        bytes.extend_from_slice(&[1, 0xFE, 0, 0, 3, 0xFC, 0, 0]);
        // View 2 (offset 32): sparse indices (u16) 2 then 0, values (u16) 70, 80.
        for v in [2u16, 0, 70, 80] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let views = r#"[{"buffer":0,"byteLength":24,"byteStride":12},{"buffer":0,"byteOffset":24,"byteLength":8},
            {"buffer":0,"byteOffset":32,"byteLength":4},{"buffer":0,"byteOffset":36,"byteLength":4}]"#;
        let accessors = r#"[
            {"bufferView":0,"componentType":5126,"count":2,"type":"VEC2"},
            {"bufferView":1,"componentType":5120,"count":1,"type":"MAT2"},
            {"componentType":5123,"count":3,"type":"SCALAR","sparse":{"count":2,
                "indices":{"bufferView":2,"componentType":5123},"values":{"bufferView":3}}},
            {"bufferView":0,"componentType":5126,"count":3,"type":"VEC2"}]"#;
        let found = decoded(accessors, views, &bytes);
        assert_eq!(found[0], [vec![1.0, 2.0], vec![3.0, 4.0]]);
        assert_eq!(found[1], [vec![1.0, -2.0, 3.0, -4.0]]);
        assert_eq!(found[2], [vec![80.0], vec![0.0], vec![70.0]]);
        // Three elements of stride 12 need 32 bytes; the view holds 24: not read.
        assert!(found[3].is_empty());
        // A view that meshopt decompresses into holds its bytes only once decoded.
        let compressed = r#"[{"buffer":0,"byteLength":24,"extensions":{"EXT_meshopt_compression":
            {"buffer":0,"byteLength":24,"byteStride":8,"count":3,"mode":"ATTRIBUTES"}}}]"#;
        let found = decoded(
            r#"[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC2"}]"#,
            compressed,
            &bytes,
        );
        assert!(found[0].is_empty());
    }

    #[test]
    fn a_buffer_file_is_read_an_accessor_at_a_time_as_a_data_uri_is_read_whole() {
        let mut bytes = Vec::new();
        for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
        let views = r#"[{"buffer":0,"byteLength":24},{"buffer":0,"byteOffset":8,"byteLength":16}]"#;
        let accessors = r#"[
            {"bufferView":0,"componentType":5126,"count":3,"type":"VEC2"},
            {"bufferView":1,"byteOffset":4,"componentType":5126,"count":3,"type":"SCALAR"},
            {"bufferView":1,"byteOffset":8,"componentType":5126,"count":3,"type":"SCALAR"}]"#;
        let dir = tempfile::tempdir().expect("a temporary folder");
        std::fs::write(dir.path().join("t.bin"), &bytes).expect("the buffer is written");
        let path = dir.path().join("t.gltf");
        let from_file = decoded_from(accessors, views, "t.bin", bytes.len(), &path);
        assert_eq!(from_file, decoded(accessors, views, &bytes));
        assert_eq!(
            from_file[0],
            [vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0, 6.0]]
        );
        assert_eq!(from_file[1], [vec![4.0], vec![5.0], vec![6.0]]);
        // Three floats from byte 8 of a 16-byte view run past it: not read.
        assert!(from_file[2].is_empty());
        // A file shorter than the buffer's byteLength is not read at all (BUFFER_BYTE_LENGTH_MISMATCH
        // is the resource rules' finding).
        std::fs::write(dir.path().join("t.bin"), &bytes[..20]).expect("the buffer is cut");
        let cut = decoded_from(accessors, views, "t.bin", bytes.len(), &path);
        assert!(cut.iter().all(|elements| elements.is_empty()));
    }

    #[test]
    fn a_file_cut_short_after_it_was_opened_gives_no_bytes_past_its_new_end() {
        let dir = tempfile::tempdir().expect("a temporary folder");
        let path = dir.path().join("b.bin");
        std::fs::write(&path, [7u8; 64]).expect("the buffer is written");
        let data = BufferData::File {
            file: std::fs::File::open(&path).expect("opened"),
            len: 64,
        };
        assert_eq!(data.read(60..64).as_deref(), Some(&[7u8; 4][..]));
        assert_eq!(data.read(60..65), None);
        std::fs::write(&path, [7u8; 32]).expect("the buffer is cut");
        assert_eq!(data.read(0..32).as_deref(), Some(&[7u8; 32][..]));
        assert_eq!(data.read(30..40), None);
    }
}
