//! References: every index in the document must name an object. glTF links its objects by
//! array index (a node's mesh, a primitive's accessors, a texture's image, …); an index past
//! the end of its array makes loaders fail or silently drop the object. The schemas only say
//! an index is a non-negative integer, so the range is checked here, for the core objects and
//! the extensions velvet knows (image-format extensions, lights, material variants, mesh
//! compression and instancing, and every `…Texture` of a material extension).
//!
//! The table [`LINKS`] is the one place an index is declared: a path pattern (`*` stands for
//! any array index or object key, `*Texture` for a key ending in "Texture") and the pointer of
//! the array it indexes, where `{0}` is the array index the first `*` matched.

use super::{as_index, Context, Rule};
use crate::asset::pointer;
use crate::asset::tape::{KeyId, Node};
use crate::diagnostics::{codes, Code, Diagnostic, Severity};
use std::borrow::Cow;

pub use codes::UNRESOLVED_REFERENCE;

pub const UNUSED_OBJECT: Code = Code::new(
    "UNUSED_OBJECT",
    Severity::Info,
    "A texture, image or sampler that nothing in the document refers to (the reference reports other objects too).",
)
.fixable(crate::diagnostics::Safety::Unsafe);

/// The arrays whose unused elements are reported: what a material's textures hold, which a
/// library's assets collect as they are edited (and `gltf-transform prune` removes).
pub const PRUNED: [&str; 3] = ["/textures", "/images", "/samplers"];

/// (where an index stands, the array it indexes).
pub const LINKS: &[(&str, &str)] = &[
    ("/scene", "/scenes"),
    ("/scenes/*/nodes/*", "/nodes"),
    ("/nodes/*/children/*", "/nodes"),
    ("/nodes/*/mesh", "/meshes"),
    ("/nodes/*/skin", "/skins"),
    ("/nodes/*/camera", "/cameras"),
    (
        "/nodes/*/extensions/KHR_lights_punctual/light",
        "/extensions/KHR_lights_punctual/lights",
    ),
    (
        "/nodes/*/extensions/EXT_mesh_gpu_instancing/attributes/*",
        "/accessors",
    ),
    ("/meshes/*/primitives/*/attributes/*", "/accessors"),
    ("/meshes/*/primitives/*/indices", "/accessors"),
    ("/meshes/*/primitives/*/material", "/materials"),
    ("/meshes/*/primitives/*/targets/*/*", "/accessors"),
    (
        "/meshes/*/primitives/*/extensions/KHR_materials_variants/mappings/*/material",
        "/materials",
    ),
    (
        "/meshes/*/primitives/*/extensions/KHR_materials_variants/mappings/*/variants/*",
        "/extensions/KHR_materials_variants/variants",
    ),
    (
        "/meshes/*/primitives/*/extensions/KHR_draco_mesh_compression/bufferView",
        "/bufferViews",
    ),
    ("/accessors/*/bufferView", "/bufferViews"),
    ("/accessors/*/sparse/indices/bufferView", "/bufferViews"),
    ("/accessors/*/sparse/values/bufferView", "/bufferViews"),
    ("/bufferViews/*/buffer", "/buffers"),
    (
        "/bufferViews/*/extensions/EXT_meshopt_compression/buffer",
        "/buffers",
    ),
    ("/images/*/bufferView", "/bufferViews"),
    ("/textures/*/sampler", "/samplers"),
    ("/textures/*/source", "/images"),
    ("/textures/*/extensions/EXT_texture_webp/source", "/images"),
    ("/textures/*/extensions/EXT_texture_avif/source", "/images"),
    (
        "/textures/*/extensions/KHR_texture_basisu/source",
        "/images",
    ),
    ("/textures/*/extensions/MSFT_texture_dds/source", "/images"),
    ("/skins/*/inverseBindMatrices", "/accessors"),
    ("/skins/*/skeleton", "/nodes"),
    ("/skins/*/joints/*", "/nodes"),
    (
        "/animations/*/channels/*/sampler",
        "/animations/{0}/samplers",
    ),
    ("/animations/*/channels/*/target/node", "/nodes"),
    ("/animations/*/samplers/*/input", "/accessors"),
    ("/animations/*/samplers/*/output", "/accessors"),
    (
        "/materials/*/pbrMetallicRoughness/baseColorTexture/index",
        "/textures",
    ),
    (
        "/materials/*/pbrMetallicRoughness/metallicRoughnessTexture/index",
        "/textures",
    ),
    ("/materials/*/normalTexture/index", "/textures"),
    ("/materials/*/occlusionTexture/index", "/textures"),
    ("/materials/*/emissiveTexture/index", "/textures"),
    ("/materials/*/extensions/*/*Texture/index", "/textures"),
];

/// Whether `pointer` stands where [`LINKS`] declares an index (`/nodes/3/mesh`).
pub fn is_index(pointer: &str) -> bool {
    let tokens: Vec<Cow<str>> = pointer.split('/').skip(1).map(pointer::unescape).collect();
    LINKS.iter().any(|(pattern, _)| {
        let segments: Vec<&str> = pattern.split('/').skip(1).collect();
        segments.len() == tokens.len()
            && segments
                .iter()
                .zip(&tokens)
                .all(|(segment, token)| match *segment {
                    "*" => true,
                    s if s.starts_with('*') => token.ends_with(&s[1..]),
                    s => s == token,
                })
    })
}

pub struct References;

impl Rule for References {
    /// The places the rule reads: each index of [`LINKS`], the elements of the arrays they
    /// index and of [`PRUNED`], and which root extensions the document has (an index into a
    /// root extension's array that the document lacks is a missing dependency).
    fn reads(&self) -> super::Reads {
        static ARRAYS: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
        static SITES: std::sync::OnceLock<Vec<&'static str>> = std::sync::OnceLock::new();
        let arrays = ARRAYS.get_or_init(|| {
            let mut arrays: Vec<&'static str> = LINKS
                .iter()
                .map(|(_, target)| match target.contains("{0}") {
                    // Made once per process, for as long as it runs.
                    true => &*target.replace("{0}", "*").leak(),
                    false => *target,
                })
                .chain(PRUNED)
                .chain(["/extensions"])
                .collect();
            arrays.sort();
            arrays.dedup();
            arrays
        });
        super::Reads::Places {
            values: SITES.get_or_init(|| LINKS.iter().map(|(site, _)| *site).collect()),
            elements: arrays,
        }
    }

    /// Among the dearest rules on a large document: it walks every value of the document.
    fn cost(&self) -> u32 {
        4
    }

    fn codes(&self) -> &'static [&'static Code] {
        &[
            &UNRESOLVED_REFERENCE,
            &super::core::UNSATISFIED_DEPENDENCY,
            &UNUSED_OBJECT,
        ]
    }

    fn check(&self, cx: &Context, out: &mut Vec<Diagnostic>) {
        let json = cx.json();
        let array_len = |target: &str| {
            json.pointer(target)
                .and_then(|a| a.as_array())
                .map_or(0, |a| a.len())
        };
        let targets = targets();
        // The fixed targets' lengths, each distinct array read once.
        let lengths: Vec<usize> = targets.arrays.iter().map(|a| array_len(a)).collect();
        let fixed_len: Vec<Option<usize>> = targets
            .fixed
            .iter()
            .map(|array| array.map(|a| lengths[a]))
            .collect();
        let steps = steps();
        // The document's number for each key the patterns name, found once: the walk then
        // compares numbers.
        let ids: Vec<Option<KeyId>> = steps.keys.iter().map(|key| json.key_id(key)).collect();
        let mut found: Vec<(usize, Diagnostic)> = Vec::new();
        // Which elements of each of PRUNED something refers to.
        let mut used: Vec<Vec<bool>> = targets
            .pruned
            .iter()
            .map(|&a| vec![false; lengths[a]])
            .collect();
        // For each link into a root extension the document lacks, that extension's name: the
        // objects that hold such an index depend on it (see below).
        let root_extensions = json.get("extensions");
        let missing_root: Vec<Option<&str>> = targets
            .root_extension
            .iter()
            .map(|name| name.filter(|name| root_extensions.and_then(|e| e.get(*name)).is_none()))
            .collect();
        let mut holders: Vec<(usize, String)> = Vec::new();
        let mut found_at = |reached: Reached, link: usize, path: &[Token], value: Node| {
            if reached == Reached::Holder {
                if missing_root[link].is_some() && value.is_object() {
                    holders.push((link, pointer_of(path)));
                }
                return;
            }
            let Some(index) = as_index(value) else {
                return; // not an index: the schema check reports the type
            };
            let target = LINKS[link].1;
            if let Some(k) = PRUNED.iter().position(|a| *a == target) {
                if let Some(slot) = usize::try_from(index).ok().and_then(|i| used[k].get_mut(i)) {
                    *slot = true;
                }
            }
            let (target, len) = match fixed_len[link] {
                Some(len) if index < len as u64 => return,
                Some(len) => (target.to_string(), len),
                None => {
                    // `{0}` is the array index the pattern's first `*` matched.
                    let first = path.get(1).map_or(String::new(), Token::text);
                    let target = target.replace("{0}", &first);
                    let len = array_len(&target);
                    (target, len)
                }
            };
            if index >= len as u64 {
                let at = pointer_of(path);
                // An index beyond 64 bits is named as written, not as the u64::MAX it is read as.
                let named = match index {
                    u64::MAX => value.raw().to_string(),
                    index => index.to_string(),
                };
                let message = unresolved_message(&at, &named, &target, len);
                found.push((link, Diagnostic::new(&UNRESOLVED_REFERENCE, at, message)));
            }
        };
        walk(json, &steps.root, &ids, &mut Vec::new(), &mut found_at);
        for (array, used) in PRUNED.iter().zip(&used) {
            for (i, _) in used.iter().enumerate().filter(|(_, u)| !**u) {
                let kind = array.trim_start_matches('/').trim_end_matches('s');
                out.push(Diagnostic::new(
                    &UNUSED_OBJECT,
                    format!("{array}/{i}"),
                    format!("{kind} {i} is not used: nothing in the document refers to it"),
                ));
            }
        }
        // Reported link by link, in the table's order, each in document order.
        found.sort_by_key(|(link, _)| *link);
        holders.sort_by_key(|(link, _)| *link);
        let mut found = found.into_iter().peekable();
        let mut holders = holders.into_iter().peekable();
        let mut dependent: Vec<String> = Vec::new();
        for (link, root) in missing_root.iter().enumerate() {
            let links_found = std::iter::from_fn(|| found.next_if(|(l, _)| *l == link));
            let links_holders = std::iter::from_fn(|| holders.next_if(|(l, _)| *l == link));
            // An object that holds an index into a root extension's array, in a document
            // without that root extension, is a missing dependency, as the Khronos validator
            // reports it: at the object (the node's light, the mapping), once, whether or not
            // it holds the index yet (an empty light object is also UNDEFINED_PROPERTY).
            let Some(root) = root else {
                out.extend(links_found.map(|(_, d)| d));
                continue;
            };
            links_found.for_each(drop);
            for (_, holder) in links_holders {
                if !dependent.contains(&holder) {
                    out.push(Diagnostic::new(
                        &super::core::UNSATISFIED_DEPENDENCY,
                        &holder,
                        format!("the document's root extensions must define {root}, on which this object depends"),
                    ));
                    dependent.push(holder);
                }
            }
        }
    }
}

/// The objects that hold the index at `site`: the pattern without its last name and the
/// wildcards after it (`/nodes/*/extensions/KHR_lights_punctual/light` → the light objects,
/// `…/mappings/*/variants/*` → the mappings).
fn holder_pattern(site: &str) -> &str {
    let mut holder = site;
    while let Some((parent, last)) = holder.rsplit_once('/') {
        holder = parent;
        if last != "*" {
            break;
        }
    }
    holder
}

/// The JSON pointer of a walked path.
fn pointer_of(path: &[Token]) -> String {
    let mut at = String::with_capacity(64);
    for token in path {
        at.push('/');
        match token {
            Token::Index(i) => {
                use std::fmt::Write;
                // Writing to a String cannot fail.
                let _ = write!(at, "{i}");
            }
            Token::Key(key) => pointer::push_escaped(&mut at, key),
        }
    }
    at
}

/// Every index [`LINKS`] declares in the document: its pointer, the array it indexes and the
/// index (indices that are not non-negative integers left out).
pub fn index_sites(json: Node) -> Vec<(String, &'static str, u64)> {
    let steps = steps();
    let ids: Vec<Option<KeyId>> = steps.keys.iter().map(|key| json.key_id(key)).collect();
    let mut sites = Vec::new();
    let mut found_at = |reached: Reached, link: usize, path: &[Token], value: Node| {
        let Some(index) = as_index(value).filter(|_| reached == Reached::Index) else {
            return;
        };
        sites.push((pointer_of(path), LINKS[link].1, index));
    };
    walk(json, &steps.root, &ids, &mut Vec::new(), &mut found_at);
    sites
}

/// "sheenColorTexture names texture 5, but the asset has 2 textures".
fn unresolved_message(at: &str, index: &str, target: &str, len: usize) -> String {
    let segments: Vec<&str> = at.rsplit('/').collect();
    let name = segments
        .iter()
        .find(|s| **s != "index" && s.parse::<usize>().is_err())
        .copied()
        .unwrap_or_default();
    let plural = target.rsplit('/').next().unwrap_or_default();
    let singular = plural
        .strip_suffix("es")
        .filter(|s| s.ends_with("sh"))
        .or_else(|| plural.strip_suffix('s'))
        .unwrap_or(plural);
    let holder = match target.strip_prefix("/animations/") {
        Some(rest) => format!("animation {}", rest.split('/').next().unwrap_or_default()),
        None => "the asset".to_string(),
    };
    let noun = if len == 1 { singular } else { plural };
    format!(
        "{} names {singular} {index}, but {holder} has {len} {noun}",
        pointer::unescape(name)
    )
}

/// One step of a path into the document.
#[derive(Clone)]
enum Token<'a> {
    Index(usize),
    Key(Cow<'a, str>),
}

impl Token<'_> {
    fn text(&self) -> String {
        match self {
            Token::Index(i) => i.to_string(),
            Token::Key(k) => k.to_string(),
        }
    }
}

/// What one segment of a pattern in [`LINKS`] matches.
enum Segment {
    /// The step's text, as a key; the number is its place in [`Steps::keys`].
    Key(usize),
    /// Any array index or object key (`*`).
    Any,
    /// Any key that ends so (`*Texture`).
    Suffix(&'static str),
}

/// One segment of the patterns in [`LINKS`], with the patterns that continue from it: the
/// table as a tree, so that one walk of the document serves every pattern.
struct Step {
    /// The segment as the pattern writes it.
    text: &'static str,
    segment: Segment,
    /// The pattern that ends here, by its place in [`LINKS`].
    link: Option<usize>,
    /// The patterns into a root extension's array whose indices the object here holds
    /// ([`holder_pattern`]).
    holds: Vec<usize>,
    next: Vec<Step>,
}

/// What a walk reached for a pattern of [`LINKS`]: the index itself, or the object that holds
/// it (for a pattern into a root extension's array).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Reached {
    Index,
    Holder,
}

/// [`LINKS`] as a tree, with the keys its segments name.
struct Steps {
    root: Vec<Step>,
    keys: Vec<&'static str>,
}

/// What each link of [`LINKS`] indexes, worked out once rather than on each document.
struct Targets {
    /// The arrays the links with a fixed target index, and [`PRUNED`]'s, each once.
    arrays: Vec<&'static str>,
    /// Each link's target in `arrays`; `None` for a target that names an index of its path
    /// (`{0}`).
    fixed: Vec<Option<usize>>,
    /// Each of [`PRUNED`] in `arrays`.
    pruned: [usize; PRUNED.len()],
    /// For each link into a root extension's array, that extension's name.
    root_extension: Vec<Option<&'static str>>,
}

fn targets() -> &'static Targets {
    static TARGETS: std::sync::OnceLock<Targets> = std::sync::OnceLock::new();
    TARGETS.get_or_init(|| {
        let mut arrays: Vec<&'static str> = Vec::new();
        let mut place = |array: &'static str| match arrays.iter().position(|a| *a == array) {
            Some(at) => at,
            None => {
                arrays.push(array);
                arrays.len() - 1
            }
        };
        let fixed = LINKS
            .iter()
            .map(|(_, target)| (!target.contains("{0}")).then(|| place(target)))
            .collect();
        let pruned = PRUNED.map(&mut place);
        let root_extension = LINKS
            .iter()
            .map(|(_, target)| {
                target
                    .strip_prefix("/extensions/")
                    .and_then(|rest| rest.split('/').next())
            })
            .collect();
        Targets {
            arrays,
            fixed,
            pruned,
            root_extension,
        }
    })
}

/// [`LINKS`] as a tree of steps, built once.
fn steps() -> &'static Steps {
    static STEPS: std::sync::OnceLock<Steps> = std::sync::OnceLock::new();
    STEPS.get_or_init(|| {
        let mut root: Vec<Step> = Vec::new();
        let mut keys: Vec<&'static str> = Vec::new();
        for (link, (pattern, target)) in LINKS.iter().enumerate() {
            let mut level = &mut root;
            let segments: Vec<&'static str> = pattern.split('/').skip(1).collect();
            let holder_len = target
                .starts_with("/extensions/")
                .then(|| holder_pattern(pattern).split('/').skip(1).count());
            for (i, &text) in segments.iter().enumerate() {
                let segment = match text.strip_prefix('*') {
                    Some("") => Segment::Any,
                    Some(suffix) => Segment::Suffix(suffix),
                    None => {
                        Segment::Key(keys.iter().position(|k| *k == text).unwrap_or_else(|| {
                            keys.push(text);
                            keys.len() - 1
                        }))
                    }
                };
                let at = match level.iter().position(|s| s.text == text) {
                    Some(at) => at,
                    None => {
                        level.push(Step {
                            text,
                            segment,
                            link: None,
                            holds: Vec::new(),
                            next: Vec::new(),
                        });
                        level.len() - 1
                    }
                };
                if i + 1 == segments.len() {
                    level[at].link = Some(link);
                }
                if Some(i + 1) == holder_len {
                    level[at].holds.push(link);
                }
                level = &mut level[at].next;
            }
        }
        Steps { root, keys }
    })
}

/// What a walk calls at each match: what it reached, the pattern, the path and the value.
type OnReached<'a> = dyn FnMut(Reached, usize, &[Token<'a>], Node<'a>) + 'a;

/// Calls `found` with what was reached (an index, or an object that holds one), the pattern, path
/// and value of every match of `steps` under `value`.
/// `ids` holds the document's number for each of [`Steps::keys`]. The path is kept as tokens
/// and turned into a pointer only for what is reported.
fn walk<'a>(
    value: Node<'a>,
    steps: &'static [Step],
    ids: &[Option<KeyId>],
    path: &mut Vec<Token<'a>>,
    found: &mut OnReached<'a>,
) {
    let mut visit =
        |step: &'static Step, token: Token<'a>, child: Node<'a>, path: &mut Vec<Token<'a>>| {
            path.push(token);
            for &link in &step.holds {
                found(Reached::Holder, link, path, child);
            }
            if let Some(link) = step.link {
                found(Reached::Index, link, path, child);
            }
            if !step.next.is_empty() {
                walk(child, &step.next, ids, path, found);
            }
            path.pop();
        };
    // Each pattern reports in document order; the patterns are put in the table's order
    // after the walk, so the steps of one level may be taken one after another.
    if let Some(array) = value.as_array() {
        for step in steps.iter().filter(|s| matches!(s.segment, Segment::Any)) {
            for (i, child) in array.iter().enumerate() {
                visit(step, Token::Index(i), child, path);
            }
        }
    } else if let Some(object) = value.as_object() {
        for step in steps {
            match step.segment {
                Segment::Key(i) => {
                    if let Some(child) = ids[i].and_then(|id| object.get_id(id)) {
                        visit(step, Token::Key(Cow::Borrowed(step.text)), child, path);
                    }
                }
                Segment::Any => {
                    for (key, child) in object.iter() {
                        visit(step, Token::Key(key), child, path);
                    }
                }
                Segment::Suffix(suffix) => {
                    for (key, child) in object.iter() {
                        if key.ends_with(suffix) {
                            visit(step, Token::Key(key), child, path);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{json, Value};

    fn found(doc: Value, unused: bool) -> Vec<String> {
        let asset =
            crate::asset::load_bytes(std::path::Path::new("t.gltf"), doc.to_string().as_bytes())
                .asset
                .unwrap();
        let schemas = crate::rules::schema::Schemas::builtin();
        let cx = Context::new(&asset, &schemas);
        let mut out = Vec::new();
        References.check(&cx, &mut out);
        out.into_iter()
            .filter(|d| (d.code == UNUSED_OBJECT.name) == unused)
            .map(|d| d.pointer)
            .collect()
    }

    fn unresolved(doc: Value) -> Vec<String> {
        found(doc, false)
    }

    #[test]
    fn textures_images_and_samplers_nothing_refers_to_are_unused() {
        // Texture 1 is unused, but its image and sampler are referred to (by it): only what
        // nothing refers to is reported, as the reference reports it.
        let doc = json!({
            "asset": {"version": "2.0"},
            "materials": [{"normalTexture": {"index": 0}},
                          {"extensions": {"KHR_materials_sheen": {"sheenColorTexture": {"index": 2}}}}],
            "textures": [{"source": 0}, {"source": 1, "sampler": 0},
                         {"extensions": {"EXT_texture_webp": {"source": 2}}}],
            "images": [{"uri": "a.png"}, {"uri": "b.png"}, {"uri": "c.webp"}, {"uri": "d.png"}],
            "samplers": [{}, {}]
        });
        assert_eq!(
            found(doc, true),
            ["/textures/1", "/images/3", "/samplers/1"]
        );
    }

    #[test]
    fn every_kind_of_index_is_checked_against_its_array() {
        let doc = json!({
            "asset": {"version": "2.0"},
            "scene": 1,
            "scenes": [{"nodes": [0, 2]}],
            "nodes": [{"mesh": 0, "children": [1]}, {"extensions": {"KHR_lights_punctual": {"light": 1}}}],
            "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point"}]}},
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 4}, "material": 0}]}],
            "accessors": [{"componentType": 5126, "count": 1, "type": "VEC3"}],
            "materials": [{"extensions": {"KHR_materials_clearcoat": {"clearcoatTexture": {"index": 2}}}}],
            "textures": [{"extensions": {"EXT_texture_webp": {"source": 1.0}}}],
            "images": [{"uri": "a.webp"}],
            "animations": [{"channels": [{"sampler": 1, "target": {"path": "rotation"}}],
                            "samplers": [{"input": 0, "output": 0}]}]
        });
        assert_eq!(
            unresolved(doc),
            vec![
                "/scene",
                "/scenes/0/nodes/1",
                "/nodes/1/extensions/KHR_lights_punctual/light",
                "/meshes/0/primitives/0/attributes/NORMAL",
                "/textures/0/extensions/EXT_texture_webp/source",
                "/animations/0/channels/0/sampler",
                "/materials/0/extensions/KHR_materials_clearcoat/clearcoatTexture/index",
            ]
        );
    }

    #[test]
    fn messages_name_the_property_the_kind_and_the_count() {
        assert_eq!(
            unresolved_message(
                "/materials/0/extensions/KHR_materials_sheen/sheenColorTexture/index",
                "5",
                "/textures",
                2
            ),
            "sheenColorTexture names texture 5, but the asset has 2 textures"
        );
        assert_eq!(
            unresolved_message("/nodes/3/mesh", "1", "/meshes", 1),
            "mesh names mesh 1, but the asset has 1 mesh"
        );
        assert_eq!(
            unresolved_message(
                "/animations/2/channels/0/sampler",
                "4",
                "/animations/2/samplers",
                0
            ),
            "sampler names sampler 4, but animation 2 has 0 samplers"
        );
        assert_eq!(
            unresolved_message("/scenes/0/nodes/1", "7", "/nodes", 3),
            "nodes names node 7, but the asset has 3 nodes"
        );
    }

    #[test]
    fn indices_in_range_and_absent_optional_ones_are_clean() {
        let doc = json!({
            "asset": {"version": "2.0"},
            "accessors": [{"componentType": 5126, "count": 1, "type": "SCALAR"}],
            "textures": [{"extensions": {"KHR_texture_basisu": {"source": 0}}}],
            "images": [{"uri": "a.ktx2"}],
            "animations": [{"channels": [{"sampler": 0.0, "target": {"path": "weights"}}],
                            "samplers": [{"input": 0, "output": 0}]}]
        });
        assert_eq!(unresolved(doc), Vec::<String>::new());
    }
}
