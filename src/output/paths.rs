//! Where outputs go, and what must follow them, for `velvet migrate` and `velvet bake` alike.
//!
//! [`jobs`] pairs every input file with its output: `-o` for one input, `--out-dir` mirroring
//! each input folder's tree, or `--in-place`. It refuses, before anything is read or written,
//! an output that is an input (unless in place), two inputs written to one output, and `-o`
//! with another container than the input's.
//!
//! [`relocate`] keeps an output in another folder loadable and self-contained: each resource a
//! relative URI names is copied (a copy-on-write clone where the filesystem can make one, never
//! a hard link: see [`crate::edit::write::copy_atomic`]) to the same relative place next to
//! the output and its URI kept, so no output URI leaves its folder and the output tree can be
//! moved as a whole. A URI that climbs out of the input's folder cannot be kept so:
//! the file fails, naming it. `--rewrite-uris` (the old behaviour) rewrites each URI to lead
//! back to the input's folder instead. An absolute path or a `file:` URI fails the file as
//! `../` does (with `--rewrite-uris` it is kept as it is); `data:` URIs and URIs with another
//! scheme need neither.
//!
//! [`check_links`] refuses, before anything of the asset is read, a resource that reaches
//! outside the input's folder through a symbolic link: it would otherwise be read, baked or
//! copied into the output.
//!
//! A relocation says what it did as [`RelocationNote`]s, plain facts that each command words
//! its own way.

use super::UsageError;
use crate::asset::tape::JsonView;
use crate::asset::{discover, resource, Asset};
use crate::edit::Edit;
use percent_encoding::{utf8_percent_encode, AsciiSet, NON_ALPHANUMERIC};
use serde::Serialize;
use serde_json::Value;
use std::borrow::Cow;
use std::collections::HashMap;
use std::io;
use std::path::{Component, Path, PathBuf};

/// Where migrated or baked files are written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Destination {
    /// Nowhere (a dry run only).
    None,
    /// Over each input.
    InPlace,
    /// One output file for one input file.
    File(PathBuf),
    /// A folder that mirrors the inputs' trees.
    Dir(PathBuf),
}

impl Destination {
    /// The destination the command line names, the same for every file command: `-o FILE`,
    /// else `--out-dir DIR`, else `--in-place`, else none (a dry run or a check; a real run
    /// without one is refused as [`super::UsageError::NoDestination`]).
    pub fn from_flags(output: Option<PathBuf>, out_dir: Option<PathBuf>, in_place: bool) -> Self {
        match (output, out_dir, in_place) {
            (Some(file), _, _) => Destination::File(file),
            (_, Some(dir), _) => Destination::Dir(dir),
            (_, _, true) => Destination::InPlace,
            _ => Destination::None,
        }
    }
}

/// One input and where its output goes (`None` in a dry run without a destination).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Job {
    pub input: PathBuf,
    pub output: Option<PathBuf>,
}

/// The absolute path a path names, with links resolved as far as the path exists (the rest is
/// appended lexically), so that two spellings of one file compare equal.
pub fn identity(path: &Path) -> PathBuf {
    if let Ok(canonical) = path.canonicalize() {
        return canonical;
    }
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    while let (Some(parent), Some(name)) = (existing.parent(), existing.file_name()) {
        rest.push(name.to_os_string());
        existing = parent;
        if let Ok(canonical) = existing.canonicalize() {
            return rest.iter().rev().fold(canonical, |p, n| p.join(n));
        }
    }
    absolute
}

fn container_extension(path: &Path) -> Option<&'static str> {
    match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
        "gltf" => Some("gltf"),
        "glb" => Some("glb"),
        _ => None,
    }
}

/// Folders that could not be walked, with their error.
pub type WalkErrors = Vec<(PathBuf, io::Error)>;

/// Pairs every input file (folders walked; with a shard, that shard's files) with its output,
/// or refuses the request. Folders that cannot be read are returned with their error.
pub fn jobs(
    inputs: &[PathBuf],
    destination: &Destination,
    dry_run: bool,
    shard: Option<discover::Shard>,
) -> Result<(Vec<Job>, WalkErrors), UsageError> {
    if inputs.is_empty() {
        return Err(UsageError::NoInputs);
    }
    if *destination == Destination::None && !dry_run {
        return Err(UsageError::NoDestination);
    }
    if let Destination::File(output) = destination {
        if inputs.len() != 1 {
            return Err(UsageError::OutputForMany(inputs.len()));
        }
        if inputs[0].is_dir() {
            return Err(UsageError::OutputForFolder(inputs[0].display().to_string()));
        }
        if let Some(extension) = container_extension(&inputs[0]) {
            if container_extension(output) != Some(extension) {
                return Err(UsageError::ContainerMismatch {
                    input: inputs[0].display().to_string(),
                    output: output.display().to_string(),
                    container: if extension == "glb" { "GLB" } else { ".gltf" },
                    extension,
                });
            }
        }
    }
    let mut jobs = Vec::new();
    let (found, walk_errors) = discover::find(inputs, shard);
    let mut in_place_targets = std::collections::HashSet::new();
    for discover::Found { path: file, input } in found {
        let input = &inputs[input];
        let file = match destination {
            Destination::InPlace => match link_target_in_place(&file, input)? {
                // A link and its target both found (or two links to one file): the file is
                // migrated once.
                Some(target) if !in_place_targets.insert(identity(&target)) => continue,
                Some(target) => target,
                None if !in_place_targets.insert(identity(&file)) => continue,
                None => file,
            },
            _ => file,
        };
        let output = match destination {
            Destination::None => None,
            Destination::InPlace => Some(file.clone()),
            Destination::File(output) => Some(output.clone()),
            Destination::Dir(dir) => Some(match file.strip_prefix(input) {
                Ok(relative) if !relative.as_os_str().is_empty() => dir.join(relative),
                _ => dir.join(file.file_name().unwrap_or(file.as_os_str())),
            }),
        };
        jobs.push(Job {
            input: file,
            output,
        });
    }
    if *destination != Destination::InPlace {
        let inputs: HashMap<PathBuf, &Path> = jobs
            .iter()
            .map(|j| (identity(&j.input), j.input.as_path()))
            .collect();
        for job in &jobs {
            let Some(output) = &job.output else { continue };
            if let Some(input) = inputs.get(&identity(output)) {
                return Err(UsageError::OutputIsInput {
                    output: output.display().to_string(),
                    input: input.display().to_string(),
                });
            }
        }
    }
    let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
    for job in &jobs {
        let Some(output) = &job.output else { continue };
        if let Some(first) = seen.insert(identity(output), &job.input) {
            return Err(UsageError::OutputCollision {
                output: output.display().to_string(),
                first: first.display().to_string(),
                second: job.input.display().to_string(),
            });
        }
    }
    Ok((jobs, walk_errors))
}

/// For `--in-place`: the file a symbolic link `file` leads to, which is migrated in its place so
/// that the link stays a link (renaming an output over the link would replace it with a
/// regular file and leave its target as it was). `None` when `file` is not a link, or one that
/// leads nowhere (the loader reports it). The target must lie inside the folder the file was
/// found under (for a file named alone, its folder): `--in-place` writes nowhere else.
fn link_target_in_place(file: &Path, input: &Path) -> Result<Option<PathBuf>, UsageError> {
    let is_link = std::fs::symlink_metadata(file).is_ok_and(|m| m.is_symlink());
    if !is_link {
        return Ok(None);
    }
    let Ok(target) = file.canonicalize() else {
        return Ok(None);
    };
    let root = if input.is_dir() {
        input
    } else {
        folder_of(input)
    };
    let inside = root
        .canonicalize()
        .is_ok_and(|root| target.starts_with(root));
    if !inside {
        return Err(UsageError::LinkOutside {
            link: file.display().to_string(),
            target: target.display().to_string(),
            root: root.display().to_string(),
        });
    }
    Ok(Some(target))
}

/// A resource to copy next to an output.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ResourceCopy {
    pub uri: String,
    pub from: PathBuf,
    pub to: PathBuf,
}

/// What a relocation has to say about an output's resources.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RelocationNote {
    /// Relative URIs rewritten so that the output finds the input's resources.
    UrisRewritten { count: usize, leaves_folder: bool },
    /// Resources copied next to the output.
    ResourcesCopied { count: usize },
    /// A resource to copy is missing; its URI is left as it was.
    ResourceMissing { uri: String },
}

/// What an output in another folder needs: URI rewrites (as edits), copies, and notes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Relocation {
    pub edits: Vec<Edit>,
    pub copies: Vec<ResourceCopy>,
    pub notes: Vec<RelocationNote>,
}

/// Characters a path segment of a URI keeps as they are (RFC 3986 unreserved and sub-delims,
/// with ':' and '@'); everything else is percent-encoded.
const SEGMENT: &AsciiSet = &NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~')
    .remove(b'!')
    .remove(b'$')
    .remove(b'&')
    .remove(b'\'')
    .remove(b'(')
    .remove(b')')
    .remove(b'*')
    .remove(b'+')
    .remove(b',')
    .remove(b';')
    .remove(b'=')
    .remove(b':')
    .remove(b'@');

/// The relative URI prefix that leads from folder `from` to folder `to` ("" when they are the
/// same, else ending in '/'), or `None` when no relative path joins them (other drives).
pub fn relative_prefix(from: &Path, to: &Path) -> Option<String> {
    let (from, to) = (identity(from), identity(to));
    let from: Vec<Component> = from.components().collect();
    let to: Vec<Component> = to.components().collect();
    if from.first() != to.first() {
        return None;
    }
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    let mut prefix = "../".repeat(from.len() - common);
    for component in &to[common..] {
        let Component::Normal(name) = component else {
            return None;
        };
        prefix += &utf8_percent_encode(&name.to_string_lossy(), SEGMENT).to_string();
        prefix.push('/');
    }
    Some(prefix)
}

/// A URI that is a relative path (not data:, no scheme, not absolute).
fn is_relative_path(uri: &str) -> bool {
    if uri.starts_with("data:") || uri.starts_with('/') || uri.starts_with('\\') {
        return false;
    }
    match uri.split_once(':') {
        // A scheme (or a drive letter) comes before any '/', '?' or '#'.
        Some((scheme, _)) => scheme.contains(['/', '?', '#']),
        None => true,
    }
}

/// A URI that names a local file by an absolute path: `/…`, `\\…`, a drive letter (`C:/…`)
/// or a `file:` URI.
fn is_local_absolute(uri: &str) -> bool {
    let bytes = uri.as_bytes();
    let drive = bytes.len() >= 3
        && bytes[0].is_ascii_alphabetic()
        && bytes[1] == b':'
        && matches!(bytes[2], b'/' | b'\\');
    uri.starts_with('/')
        || uri.starts_with('\\')
        || drive
        || uri
            .get(..5)
            .is_some_and(|s| s.eq_ignore_ascii_case("file:"))
}

/// The folder a file lies in: its parent, or "." for a bare file name.
pub fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// The relative URIs (buffers and images) of a document, each once, in document order.
pub fn relative_uris<'a>(json: impl JsonView<'a>) -> Vec<Cow<'a, str>> {
    let mut out: Vec<Cow<'a, str>> = Vec::new();
    for kind in ["buffers", "images"] {
        let items = json.member(kind);
        for i in 0..items.and_then(JsonView::length).unwrap_or(0) {
            if let Some(uri) = items
                .and_then(|a| a.element(i))
                .and_then(|item| item.member("uri"))
                .and_then(JsonView::text)
                .filter(|u| is_relative_path(u))
            {
                if !out.contains(&uri) {
                    out.push(uri);
                }
            }
        }
    }
    out
}

/// Refuses an asset with a resource that a symbolic link leads out of the asset's folder
/// (unless `--allow-outside-uris` lets it read outside): the error names the URI and the link.
/// Resources that do not exist are left to the steps that read them.
pub fn check_links(asset: &Asset) -> Result<(), String> {
    if asset.options.allow_outside_uris {
        return Ok(());
    }
    let base = folder_of(&asset.path);
    let mut real_base: Option<PathBuf> = None;
    for uri in relative_uris(asset.root()) {
        let Ok(resource::Location::File(path)) = resource::resolve(&uri, base, "") else {
            continue;
        };
        let Ok(real) = path.canonicalize() else {
            continue;
        };
        let real_base = match &real_base {
            Some(b) => b,
            None => real_base.insert(
                base.canonicalize()
                    .map_err(|e| format!("cannot read folder {}: {e}", base.display()))?,
            ),
        };
        if !real.starts_with(real_base) {
            return Err(format!(
                "'{uri}' ({}) is a symbolic link, or passes through one, to a file outside the input's folder: nothing is read, baked or copied through it",
                path.display()
            ));
        }
    }
    Ok(())
}

/// What an output written to `output` needs so that `asset`'s relative resources still load:
/// copies next to it (the default), or with `rewrite_uris`, URIs that lead back.
pub fn relocate(asset: &Asset, output: &Path, rewrite_uris: bool) -> Result<Relocation, String> {
    let from_dir = folder_of(&asset.path);
    let to_dir = folder_of(output);
    let mut relocation = Relocation::default();
    if identity(from_dir) == identity(to_dir) {
        return Ok(relocation);
    }
    let mut prefix: Option<String> = None;
    let mut rewritten = 0;
    for kind in ["buffers", "images"] {
        let Some(items) = asset.root().get(kind).and_then(|a| a.as_array()) else {
            continue;
        };
        for (i, item) in items.iter().enumerate() {
            let Some(uri) = item.get("uri").and_then(|u| u.as_str()) else {
                continue;
            };
            let uri: &str = &uri;
            if !is_relative_path(uri) {
                // An absolute path or file: URI names a file on this machine, outside any
                // folder the output could be moved with: refused as a `../` URI is.
                if !rewrite_uris && is_local_absolute(uri) {
                    return Err(format!(
                        "'{uri}' names a file by its absolute place, so a self-contained output cannot keep it (--rewrite-uris keeps it as it is)"
                    ));
                }
                continue;
            }
            let pointer = format!("/{kind}/{i}/uri");
            if !rewrite_uris {
                let from = match resource::resolve(uri, from_dir, &pointer) {
                    Ok(resource::Location::File(from)) => from,
                    _ => {
                        return Err(format!(
                            "'{uri}' leads out of the input's folder, so a self-contained output cannot keep it (--rewrite-uris refers to it where it is)"
                        ))
                    }
                };
                if !from.is_file() {
                    relocation.notes.push(RelocationNote::ResourceMissing {
                        uri: uri.to_string(),
                    });
                } else if !relocation.copies.iter().any(|c| c.uri == uri) {
                    let relative = from.strip_prefix(from_dir).map_err(|_| {
                        format!("'{uri}' does not resolve inside {}", from_dir.display())
                    })?;
                    relocation.copies.push(ResourceCopy {
                        uri: uri.to_string(),
                        from: from.clone(),
                        to: to_dir.join(relative),
                    });
                }
                continue;
            }
            if prefix.is_none() {
                prefix = Some(relative_prefix(to_dir, from_dir).ok_or_else(|| {
                    format!(
                        "no relative path leads from {} to {}; leave out --rewrite-uris to copy the resources",
                        to_dir.display(),
                        from_dir.display()
                    )
                })?);
            }
            let prefix = prefix.as_deref().unwrap_or_default();
            relocation
                .edits
                .push(Edit::set(pointer, Value::String(format!("{prefix}{uri}"))));
            rewritten += 1;
        }
    }
    if rewritten > 0 {
        let leaves_folder = relocation.edits.iter().any(
            |e| matches!(e, Edit::Set { value, .. } if value.to_value().as_str().is_some_and(|u| u.starts_with("../"))),
        );
        relocation.notes.push(RelocationNote::UrisRewritten {
            count: rewritten,
            leaves_folder,
        });
    }
    if !relocation.copies.is_empty() {
        relocation.notes.push(RelocationNote::ResourcesCopied {
            count: relocation.copies.len(),
        });
    }
    Ok(relocation)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefixes_climb_then_descend_with_encoded_names() {
        let dir = tempfile::tempdir().unwrap();
        let base = dir.path();
        std::fs::create_dir_all(base.join("in/my chair")).unwrap();
        std::fs::create_dir_all(base.join("out/a")).unwrap();
        assert_eq!(
            relative_prefix(&base.join("out/a"), &base.join("in/my chair")).unwrap(),
            "../../in/my%20chair/"
        );
        assert_eq!(
            relative_prefix(&base.join("in"), &base.join("in/my chair")).unwrap(),
            "my%20chair/"
        );
        assert_eq!(
            relative_prefix(&base.join("in"), &base.join("in")).unwrap(),
            ""
        );
        // A folder that does not exist yet is placed lexically.
        assert_eq!(
            relative_prefix(&base.join("new/deep"), &base.join("in")).unwrap(),
            "../../in/"
        );
    }

    #[test]
    fn only_relative_paths_are_relocated() {
        for uri in ["a.bin", "tex/My%20Image.png", "../up.png", "./a:b.png"] {
            assert!(is_relative_path(uri), "{uri}");
        }
        for uri in [
            "data:application/octet-stream;base64,AA==",
            "https://x/y.png",
            "/abs/x.png",
            "C:/x.png",
            "file:///x",
            "a:b/c",
        ] {
            assert!(!is_relative_path(uri), "{uri}");
        }
    }
}
