//! Dropping what a bake left unreferenced: textures that no textureInfo names any more, images
//! that no remaining texture names, and bufferViews that nothing names — with every reference
//! renumbered and, in a GLB, the dropped bytes cut out of the BIN chunk.
//!
//! Only the candidates the caller names are considered (the textures and images a bake
//! replaced), and a candidate is kept when anything still refers to it. References are found
//! by glTF's naming conventions, which every ratified extension follows: a textureInfo is an
//! object under a key ending in `Texture` with an integer `index`; images are named by a
//! texture's `source` and its extensions' `source`; a bufferView is named by any `bufferView`
//! key. An extension that names images or textures otherwise is not seen.

use std::collections::BTreeSet;

use serde_json::Value;

use crate::asset::pointer;
use crate::asset::tape::JsonView;
use crate::document::texture_sources;

/// What was dropped (indices before dropping).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Dropped {
    /// Textures removed.
    pub textures: Vec<usize>,
    /// Images removed.
    pub images: Vec<usize>,
    /// BufferViews removed.
    pub buffer_views: Vec<usize>,
    /// Bytes cut from the BIN chunk.
    pub bin_bytes: usize,
}

/// Every (pointer, index) naming a texture: the `index` of an object under a key ending in
/// `Texture`. Read from a document or from its index alike (migrate's bake part asks the
/// loaded text which replaced textures are named outside it, by this same convention).
pub(crate) fn texture_refs<'a>(json: impl JsonView<'a>) -> Vec<(String, usize)> {
    fn walk<'a>(
        value: impl JsonView<'a>,
        at: &mut String,
        key: &str,
        out: &mut Vec<(String, usize)>,
    ) {
        if let Some(members) = value.members() {
            if key.ends_with("Texture") {
                if let Some(i) = value.member("index").and_then(JsonView::unsigned) {
                    out.push((format!("{at}/index"), i as usize));
                }
            }
            for (k, v) in members {
                let len = at.len();
                at.push('/');
                pointer::push_escaped(at, &k);
                walk(v, at, &k, out);
                at.truncate(len);
            }
        } else if let Some(len) = value.length() {
            for (i, v) in (0..len).filter_map(|i| Some((i, value.element(i)?))) {
                let end = at.len();
                at.push('/');
                at.push_str(&i.to_string());
                walk(v, at, key, out);
                at.truncate(end);
            }
        }
    }
    let mut out = Vec::new();
    walk(json, &mut String::new(), "", &mut out);
    out
}

/// Every (pointer, index) naming an image.
fn image_refs(json: &Value) -> Vec<(String, usize)> {
    let textures = json.get("textures").and_then(Value::as_array);
    textures
        .into_iter()
        .flatten()
        .enumerate()
        .flat_map(|(i, t)| texture_sources(t, &format!("/textures/{i}")))
        .filter_map(|(index, p)| Some((p, index? as usize)))
        .collect()
}

/// Every (pointer, index) naming a bufferView.
fn buffer_view_refs(json: &Value) -> Vec<(String, usize)> {
    fn walk(value: &Value, at: &str, out: &mut Vec<(String, usize)>) {
        match value {
            Value::Object(map) => {
                for (k, v) in map {
                    let here = pointer::join(at, k);
                    match (k.as_str(), v.as_u64()) {
                        ("bufferView", Some(i)) => out.push((here, i as usize)),
                        _ => walk(v, &here, out),
                    }
                }
            }
            Value::Array(items) => {
                for (i, v) in items.iter().enumerate() {
                    walk(v, &format!("{at}/{i}"), out);
                }
            }
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(json, "", &mut out);
    out
}

/// Removes the `drop` elements of the top-level array `key` and renumbers `refs` to it. The
/// key is removed when the array becomes empty (glTF arrays may not be empty).
fn remove_and_renumber(
    json: &mut Value,
    key: &str,
    drop: &BTreeSet<usize>,
    refs: &[(String, usize)],
) {
    if drop.is_empty() {
        return;
    }
    let len = json.get(key).and_then(Value::as_array).map_or(0, Vec::len);
    let mut new_index = vec![None; len];
    let mut next = 0;
    for (i, slot) in new_index.iter_mut().enumerate() {
        if !drop.contains(&i) {
            *slot = Some(next);
            next += 1;
        }
    }
    for (p, old) in refs {
        if let (Some(Some(new)), Some(target)) = (new_index.get(*old), json.pointer_mut(p)) {
            if new != old {
                *target = Value::from(*new);
            }
        }
    }
    let root = json.as_object_mut().expect("the document is an object");
    if next == 0 {
        root.shift_remove(key);
    } else if let Some(Value::Array(items)) = root.get_mut(key) {
        let mut i = 0;
        items.retain(|_| {
            let keep = !drop.contains(&i);
            i += 1;
            keep
        });
    }
}

/// Drops the candidate textures and images nothing references any more (and their
/// bufferViews), renumbers references, and cuts dropped bufferViews' bytes from `bin` (the
/// GLB BIN chunk, buffer 0) when given.
pub fn prune(
    json: &mut Value,
    bin: Option<&mut Vec<u8>>,
    textures: &BTreeSet<usize>,
    images: &BTreeSet<usize>,
) -> Dropped {
    let mut dropped = Dropped::default();
    let t_refs = texture_refs(&*json);
    let drop_textures: BTreeSet<usize> = textures
        .iter()
        .copied()
        .filter(|t| !t_refs.iter().any(|(_, i)| i == t))
        .collect();
    // Images named by textures that stay.
    let i_refs = image_refs(json);
    let still_named = |image: &usize| {
        i_refs.iter().any(|(p, i)| {
            i == image && {
                let texture: usize = p["/textures/".len()..]
                    .split('/')
                    .next()
                    .and_then(|s| s.parse().ok())
                    .unwrap_or(usize::MAX);
                !drop_textures.contains(&texture)
            }
        })
    };
    let drop_images: BTreeSet<usize> = images.iter().copied().filter(|i| !still_named(i)).collect();
    // BufferViews of dropped images that nothing else names.
    let v_refs = buffer_view_refs(json);
    let mut drop_views = BTreeSet::new();
    for &image in &drop_images {
        let Some(view) = json
            .pointer(&format!("/images/{image}/bufferView"))
            .and_then(Value::as_u64)
        else {
            continue;
        };
        let own = format!("/images/{image}/bufferView");
        let elsewhere = v_refs.iter().any(|(p, v)| {
            *v == view as usize
                && *p != own
                && !drop_images
                    .iter()
                    .any(|d| *p == format!("/images/{d}/bufferView"))
        });
        if !elsewhere {
            drop_views.insert(view as usize);
        }
    }
    if let Some(bin) = bin {
        dropped.bin_bytes = compact_bin(json, bin, &drop_views);
    }
    remove_and_renumber(json, "textures", &drop_textures, &t_refs);
    let i_refs = image_refs(json);
    remove_and_renumber(json, "images", &drop_images, &i_refs);
    let v_refs = buffer_view_refs(json);
    remove_and_renumber(json, "bufferViews", &drop_views, &v_refs);
    dropped.textures = drop_textures.into_iter().collect();
    dropped.images = drop_images.into_iter().collect();
    dropped.buffer_views = drop_views.into_iter().collect();
    dropped
}

fn view_range(view: &Value) -> Option<(usize, usize, usize)> {
    let buffer = view.get("buffer")?.as_u64()? as usize;
    let offset = view.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let length = view.get("byteLength")?.as_u64()? as usize;
    Some((buffer, offset, offset + length))
}

/// Cuts the bytes of `drop` views (of buffer 0) that no kept view overlaps out of `bin`, in
/// 4-byte-aligned runs so every later offset moves by a multiple of 4 and keeps its alignment
/// (a run with nothing kept after it takes the chunk's tail with it); shifts the later views
/// and updates buffer 0's byteLength. Returns the bytes cut.
fn compact_bin(json: &mut Value, bin: &mut Vec<u8>, drop: &BTreeSet<usize>) -> usize {
    let views = json
        .get("bufferViews")
        .and_then(Value::as_array)
        .cloned()
        .unwrap_or_default();
    let mut cut: Vec<(usize, usize)> = Vec::new();
    for &d in drop {
        let Some((0, start, end)) = views.get(d).and_then(view_range) else {
            continue;
        };
        cut.push((start, end));
    }
    // Subtract every kept view's range.
    for (i, view) in views.iter().enumerate() {
        if drop.contains(&i) {
            continue;
        }
        let Some((0, ks, ke)) = view_range(view) else {
            continue;
        };
        cut = cut
            .into_iter()
            .flat_map(|(s, e)| {
                if ke <= s || ks >= e {
                    vec![(s, e)]
                } else {
                    [(s, ks.max(s)), (ke.min(e), e)]
                        .into_iter()
                        .filter(|(a, b)| a < b)
                        .collect()
                }
            })
            .collect();
    }
    // Where kept data starts after a run decides how its end aligns: with nothing kept after
    // it, the run goes to the end of the chunk.
    let kept_starts: Vec<usize> = views
        .iter()
        .enumerate()
        .filter(|(i, _)| !drop.contains(i))
        .filter_map(|(_, v)| view_range(v))
        .filter(|(buffer, _, _)| *buffer == 0)
        .map(|(_, start, _)| start)
        .collect();
    let mut cut: Vec<(usize, usize)> = cut
        .into_iter()
        .map(|(s, e)| {
            let end = if kept_starts.iter().any(|&k| k >= e) {
                (e.min(bin.len()) / 4) * 4
            } else {
                bin.len()
            };
            (s.div_ceil(4) * 4, end)
        })
        .filter(|(s, e)| s < e)
        .collect();
    cut.sort();
    // Merge overlaps.
    let mut merged: Vec<(usize, usize)> = Vec::new();
    for (s, e) in cut {
        match merged.last_mut() {
            Some(last) if s <= last.1 => last.1 = last.1.max(e),
            _ => merged.push((s, e)),
        }
    }
    if merged.is_empty() {
        return 0;
    }
    let shift = |offset: usize| -> usize {
        merged
            .iter()
            .filter(|(_, e)| *e <= offset)
            .map(|(s, e)| e - s)
            .sum()
    };
    // Move the kept runs down where they lie (no second buffer).
    let mut write = merged[0].0;
    for (k, &(_, e)) in merged.iter().enumerate() {
        let next = merged.get(k + 1).map_or(bin.len(), |m| m.0);
        bin.copy_within(e..next, write);
        write += next - e;
    }
    let removed = bin.len() - write;
    bin.truncate(write);
    if let Some(Value::Array(views)) = json.get_mut("bufferViews") {
        for (i, view) in views.iter_mut().enumerate() {
            if drop.contains(&i) {
                continue;
            }
            if let Some((0, start, _)) = view_range(view) {
                let moved = shift(start);
                if moved > 0 {
                    view["byteOffset"] = Value::from(start - moved);
                }
            }
        }
    }
    if let Some(length) = json.pointer_mut("/buffers/0/byteLength") {
        let old = length.as_u64().unwrap_or(0) as usize;
        *length = Value::from(old.saturating_sub(removed));
    }
    removed
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn an_unreferenced_texture_and_image_are_dropped_and_references_renumbered() {
        let mut doc = json!({
            "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 2}},
                           "extensions": {"X_ext": {"someTexture": {"index": 0}}}}],
            "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
            "images": [{"uri": "a.png"}, {"uri": "b.png"}, {"uri": "c.png"}]
        });
        let dropped = prune(
            &mut doc,
            None,
            &BTreeSet::from([0, 1]),
            &BTreeSet::from([0, 1]),
        );
        assert_eq!(dropped.textures, vec![1]);
        assert_eq!(dropped.images, vec![1]);
        assert_eq!(
            doc,
            json!({
                "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 1}},
                               "extensions": {"X_ext": {"someTexture": {"index": 0}}}}],
                "textures": [{"source": 0}, {"source": 1}],
                "images": [{"uri": "a.png"}, {"uri": "c.png"}]
            })
        );
    }

    #[test]
    fn an_image_still_named_by_another_texture_or_a_webp_source_stays() {
        let mut doc = json!({
            "materials": [{"occlusionTexture": {"index": 1}}],
            "textures": [{"source": 0}, {"extensions": {"EXT_texture_webp": {"source": 0}}}],
            "images": [{"uri": "a.webp"}]
        });
        let dropped = prune(&mut doc, None, &BTreeSet::from([0]), &BTreeSet::from([0]));
        assert_eq!(dropped.textures, vec![0]);
        assert!(dropped.images.is_empty());
        assert_eq!(
            doc["textures"],
            json!([{"extensions": {"EXT_texture_webp": {"source": 0}}}])
        );
        assert_eq!(doc["materials"][0]["occlusionTexture"]["index"], json!(0));
    }

    #[test]
    fn dropped_image_bytes_leave_the_bin_and_later_views_move_by_multiples_of_4() {
        // View 0: accessor data 0..6; view 1: the image 8..18; view 2: accessor data 20..24.
        let mut bin: Vec<u8> = (0..24).collect();
        let mut doc = json!({
            "buffers": [{"byteLength": 24}],
            "bufferViews": [
                {"buffer": 0, "byteLength": 6},
                {"buffer": 0, "byteOffset": 8, "byteLength": 10},
                {"buffer": 0, "byteOffset": 20, "byteLength": 4}
            ],
            "accessors": [{"bufferView": 0}, {"bufferView": 2}],
            "textures": [{"source": 0}],
            "images": [{"bufferView": 1, "mimeType": "image/png"}]
        });
        let dropped = prune(
            &mut doc,
            Some(&mut bin),
            &BTreeSet::from([0]),
            &BTreeSet::from([0]),
        );
        assert_eq!(dropped.buffer_views, vec![1]);
        // 8..18 aligned inward is 8..16: eight bytes go, two padding bytes stay.
        assert_eq!(dropped.bin_bytes, 8);
        assert_eq!(
            bin,
            [0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23]
        );
        assert_eq!(
            doc,
            json!({
                "buffers": [{"byteLength": 16}],
                "bufferViews": [
                    {"buffer": 0, "byteLength": 6},
                    {"buffer": 0, "byteOffset": 12, "byteLength": 4}
                ],
                "accessors": [{"bufferView": 0}, {"bufferView": 1}]
            })
        );
        assert_eq!(&bin[12..16], &[20, 21, 22, 23]);
    }

    #[test]
    fn a_buffer_view_shared_with_an_accessor_is_kept() {
        let mut bin = vec![0u8; 8];
        let mut doc = json!({
            "buffers": [{"byteLength": 8}],
            "bufferViews": [{"buffer": 0, "byteLength": 8}],
            "accessors": [{"bufferView": 0}],
            "textures": [{"source": 0}],
            "images": [{"bufferView": 0, "mimeType": "image/png"}]
        });
        let dropped = prune(
            &mut doc,
            Some(&mut bin),
            &BTreeSet::from([0]),
            &BTreeSet::from([0]),
        );
        assert_eq!(
            (dropped.images, dropped.buffer_views, dropped.bin_bytes),
            (vec![0], vec![], 0)
        );
        assert_eq!(bin.len(), 8);
        assert!(doc.get("images").is_none() && doc.get("textures").is_none());
    }
}
