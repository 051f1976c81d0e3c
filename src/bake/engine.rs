//! Runs many recipes at once: equal recipes share one output, each source image is fetched and
//! decoded once per run however many recipes read it, and work runs in parallel (rayon).
//!
//! Scheduling: recipes are grouped into connected components by the images they share. A
//! component is the unit of work: its images are decoded, its recipes applied and encoded, and
//! its decoded pixels dropped before the worker takes the next component. So the memory in use
//! is about the decoded images of the components in flight (one per worker, more only when a
//! worker waiting inside a component's parallel kernel picks up another), not the sum of all
//! images. An image that one recipe alone reads is handed to that recipe, whose kernel then
//! rewrites it in place when it can (same layout and depth, table channels), so the common
//! single-texture bake holds one decoded buffer, not two. Encoded outputs are returned to the
//! caller, who writes them.

use std::borrow::Cow;
use std::collections::HashMap;

use rayon::prelude::*;

use super::codec::{self, CodecError, EncodeOptions, ImageFormat, OutputFormat};
use super::kernel::{self, KernelError, KernelOptions, KernelStats};
use super::pixels::{Depth, Layout, Pixels};
use super::recipe::{ImageId, Recipe};

/// Where the engine gets an image's encoded bytes (an asset's URI, data: URI or bufferView).
pub trait ImageSource: Sync {
    /// The encoded bytes of `image`, or a message saying why they cannot be had.
    fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String>;
}

impl<F> ImageSource for F
where
    F: Fn(ImageId) -> Result<Vec<u8>, String> + Sync,
{
    fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String> {
        self(image).map(Cow::Owned)
    }
}

/// An asset serves its images by index: from a URI, a `data:` URI or a bufferView.
impl ImageSource for crate::asset::Asset {
    fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String> {
        crate::asset::Asset::image_bytes(self, image.0).map_err(|d| d.message)
    }
}

impl ImageSource for HashMap<ImageId, Vec<u8>> {
    fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String> {
        self.get(&image)
            .map(|b| Cow::Borrowed(b.as_slice()))
            .ok_or_else(|| "no such image".to_owned())
    }
}

/// Index of a distinct recipe in a [`RecipeSet`], and of its result.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct OutputId(pub usize);

/// Distinct recipes in insertion order: inserting an equal recipe again returns the first one's
/// id.
#[derive(Clone, Debug, Default)]
pub struct RecipeSet {
    recipes: Vec<Recipe>,
    index: HashMap<Recipe, OutputId>,
}

impl RecipeSet {
    /// An empty set.
    pub fn new() -> RecipeSet {
        RecipeSet::default()
    }

    /// Adds `recipe` unless an equal one is present; returns the id of its output.
    pub fn insert(&mut self, recipe: Recipe) -> OutputId {
        if let Some(&id) = self.index.get(&recipe) {
            return id;
        }
        let id = OutputId(self.recipes.len());
        self.index.insert(recipe.clone(), id);
        self.recipes.push(recipe);
        id
    }

    /// The recipe of an output.
    pub fn get(&self, id: OutputId) -> &Recipe {
        &self.recipes[id.0]
    }

    /// The distinct recipes, indexed by `OutputId`.
    pub fn recipes(&self) -> &[Recipe] {
        &self.recipes
    }

    /// Number of distinct recipes.
    pub fn len(&self) -> usize {
        self.recipes.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.recipes.is_empty()
    }

    /// Every image some recipe reads, sorted, each once.
    pub fn images(&self) -> Vec<ImageId> {
        let mut all: Vec<ImageId> = self.recipes.iter().flat_map(Recipe::images).collect();
        all.sort();
        all.dedup();
        all
    }
}

/// How a run behaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BakeOptions {
    /// Keep JPEG sources as JPEG (lossy) instead of writing PNG.
    pub keep_format: bool,
    /// Do not encode outputs whose texels are all equal; report their codes instead.
    pub collapse_uniform: bool,
    /// Kernel choices (exact path, error measurement).
    pub kernel: KernelOptions,
    /// Encoder settings.
    pub encode: EncodeOptions,
    /// Images whose header declares more pixels are refused before decoding.
    pub max_image_pixels: MaxImagePixels,
    /// Images whose decoding would need more memory are refused before decoding.
    pub max_memory: MaxMemory,
}

/// The memory budget for decoding (see [`crate::asset::limits::default_max_memory`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaxMemory(pub u64);

impl Default for MaxMemory {
    fn default() -> Self {
        MaxMemory(crate::asset::limits::default_max_memory())
    }
}

/// The pixel limit for decoding (see [`crate::asset::limits`]); defaults to the loader's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaxImagePixels(pub u64);

impl Default for MaxImagePixels {
    fn default() -> Self {
        MaxImagePixels(crate::asset::limits::DEFAULT_MAX_IMAGE_PIXELS)
    }
}

/// One output of a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Baked {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Channel layout.
    pub layout: Layout,
    /// Bits per channel.
    pub depth: Depth,
    /// The format of the recipe's base image.
    pub source_format: ImageFormat,
    /// The encoded image, or `None` when it was collapsed (see `uniform`).
    pub encoded: Option<(OutputFormat, Vec<u8>)>,
    /// The codes (per stored channel) when every texel is equal and `collapse_uniform` is set.
    pub uniform: Option<Vec<u32>>,
    /// Where a [`Sink`] already wrote the encoded image (then `encoded` is `None`).
    pub stored: Option<StoredFile>,
    /// Per-channel statistics.
    pub stats: KernelStats,
}

/// An output a [`Sink`] wrote as a file as soon as it was encoded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StoredFile {
    /// The file name, next to the output document.
    pub name: String,
    /// The encoded format.
    pub format: OutputFormat,
    /// The encoded size in bytes.
    pub bytes: usize,
}

/// Takes each output as soon as it is encoded (from any worker thread), typically to write it
/// and drop its bytes, so that a run holds the encoded images in flight only, not all of them.
/// It may move `encoded` out and set `stored`; an `Err` fails that output.
pub type Sink<'a> = &'a (dyn Fn(OutputId, &mut Baked) -> Result<(), String> + Sync);

/// Why one output could not be made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BakeError {
    /// The bytes of an image could not be had.
    #[error("{image}: {message}")]
    Source {
        /// The image.
        image: ImageId,
        /// Why.
        message: String,
    },
    /// An image could not be decoded (or is KTX2, which is not baked).
    #[error("{image}: {error}")]
    Decode {
        /// The image.
        image: ImageId,
        /// Why.
        error: CodecError,
    },
    /// The recipe does not fit the images.
    #[error(transparent)]
    Kernel(#[from] KernelError),
    /// The output could not be encoded.
    #[error(transparent)]
    Encode(CodecError),
    /// The sink could not store the output.
    #[error("{0}")]
    Store(String),
}

impl BakeError {
    /// Whether the failure is a KTX2 image, which callers report as a warning and leave alone.
    pub fn is_unsupported_format(&self) -> bool {
        matches!(
            self,
            BakeError::Decode {
                error: CodecError::Unsupported { .. },
                ..
            }
        )
    }
}

/// Groups recipe indices into components that share images (union-find over images).
fn components(recipes: &[Recipe]) -> Vec<Vec<usize>> {
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut parent: Vec<usize> = (0..recipes.len()).collect();
    let mut owner: HashMap<ImageId, usize> = HashMap::new();
    for (i, recipe) in recipes.iter().enumerate() {
        for image in recipe.images() {
            match owner.get(&image) {
                Some(&j) => {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    parent[a.max(b)] = a.min(b);
                }
                None => {
                    owner.insert(image, i);
                }
            }
        }
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    for i in 0..recipes.len() {
        let root = find(&mut parent, i);
        groups.entry(root).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = groups.into_values().collect();
    out.sort();
    out
}

/// Bakes every recipe of `set`; the results are indexed by [`OutputId`].
pub fn bake(
    set: &RecipeSet,
    source: &dyn ImageSource,
    options: &BakeOptions,
) -> Vec<Result<Baked, BakeError>> {
    bake_into(set, source, options, None)
}

/// [`bake`], handing each output to `sink` as soon as it is encoded.
pub fn bake_into(
    set: &RecipeSet,
    source: &dyn ImageSource,
    options: &BakeOptions,
    sink: Option<Sink>,
) -> Vec<Result<Baked, BakeError>> {
    let recipes = set.recipes();
    let done: Vec<Vec<(usize, Result<Baked, BakeError>)>> = components(recipes)
        .into_par_iter()
        .with_max_len(1)
        .map(|component| bake_component(recipes, &component, source, options, sink))
        .collect();
    let mut results: Vec<Option<Result<Baked, BakeError>>> = vec![None; recipes.len()];
    for (i, result) in done.into_iter().flatten() {
        results[i] = Some(result);
    }
    results
        .into_iter()
        .map(|r| r.expect("every recipe is in one component"))
        .collect()
}

type Decoded = Result<(Pixels, ImageFormat), BakeError>;

fn decode_image(source: &dyn ImageSource, image: ImageId, options: &BakeOptions) -> Decoded {
    let bytes = source
        .image_bytes(image)
        .map_err(|message| BakeError::Source { image, message })?;
    codec::decode_within(&bytes, options.max_image_pixels.0, options.max_memory.0)
        .map_err(|error| BakeError::Decode { image, error })
}

fn bake_component(
    recipes: &[Recipe],
    component: &[usize],
    source: &dyn ImageSource,
    options: &BakeOptions,
    sink: Option<Sink>,
) -> Vec<(usize, Result<Baked, BakeError>)> {
    let mut images: Vec<ImageId> = component
        .iter()
        .flat_map(|&i| recipes[i].images())
        .collect();
    images.sort();
    images.dedup();
    let decoded: Vec<(ImageId, Decoded)> = images
        .par_iter()
        .map(|&image| (image, decode_image(source, image, options)))
        .collect();
    let mut pixels = HashMap::new();
    let mut formats = HashMap::new();
    let mut failures = HashMap::new();
    for (image, result) in decoded {
        match result {
            Ok((p, f)) => {
                pixels.insert(image, p);
                formats.insert(image, f);
            }
            Err(e) => {
                failures.insert(image, e);
            }
        }
    }
    // An image that one recipe alone reads is handed to it, so the kernel can rewrite it in
    // place instead of allocating an output beside it.
    let mut readers: HashMap<ImageId, usize> = HashMap::new();
    for &i in component {
        for image in recipes[i].images() {
            *readers.entry(image).or_default() += 1;
        }
    }
    let mut owned: HashMap<usize, Pixels> = HashMap::new();
    for &i in component {
        let images = recipes[i].images();
        if let [only] = images[..] {
            if readers[&only] == 1 {
                if let Some(p) = pixels.remove(&only) {
                    owned.insert(i, p);
                }
            }
        }
    }
    let mut work: Vec<(usize, Option<Pixels>)> =
        component.iter().map(|&i| (i, owned.remove(&i))).collect();
    work.par_drain(..)
        .map(|(i, own)| {
            let recipe = &recipes[i];
            let failed = recipe.images().into_iter().find_map(|im| failures.get(&im));
            let format = formats.get(&recipe.base()).copied();
            let result = match (failed, format) {
                (Some(e), _) => Err(e.clone()),
                (None, Some(format)) => bake_one(recipe, &pixels, own, format, options),
                (None, None) => unreachable!("a decoded image has a format"),
            };
            let result = match (result, sink) {
                (Ok(mut baked), Some(sink)) => match sink(OutputId(i), &mut baked) {
                    Ok(()) => Ok(baked),
                    Err(e) => Err(BakeError::Store(e)),
                },
                (result, _) => result,
            };
            (i, result)
        })
        .collect()
}

fn bake_one(
    recipe: &Recipe,
    images: &HashMap<ImageId, Pixels>,
    owned: Option<Pixels>,
    source_format: ImageFormat,
    options: &BakeOptions,
) -> Result<Baked, BakeError> {
    let (out, stats) = match owned {
        Some(image) => kernel::apply_owned(recipe, image, options.kernel)?,
        None => kernel::apply(recipe, images, options.kernel)?,
    };
    let uniform = if options.collapse_uniform {
        out.uniform()
    } else {
        None
    };
    let encoded = match uniform {
        Some(_) => None,
        None => {
            let format = codec::output_format(
                source_format,
                options.keep_format,
                out.layout(),
                out.depth(),
            );
            let bytes = codec::encode(&out, format, options.encode).map_err(BakeError::Encode)?;
            Some((format, bytes))
        }
    };
    Ok(Baked {
        width: out.width(),
        height: out.height(),
        layout: out.layout(),
        depth: out.depth(),
        source_format,
        encoded,
        uniform,
        stored: None,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::codec::EncodeOptions;
    use crate::bake::pixels::Samples;
    use crate::bake::recipe::{Channel, ChannelRecipe, Factor, Transfer, Value};
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Mutex;

    /// Serves encoded images and counts how often each is fetched.
    struct Counting {
        images: HashMap<ImageId, Vec<u8>>,
        fetches: Mutex<HashMap<ImageId, usize>>,
        total: AtomicUsize,
    }

    impl Counting {
        fn new(images: Vec<(usize, Vec<u8>)>) -> Counting {
            Counting {
                images: images.into_iter().map(|(i, b)| (ImageId(i), b)).collect(),
                fetches: Mutex::new(HashMap::new()),
                total: AtomicUsize::new(0),
            }
        }
    }

    impl ImageSource for Counting {
        fn image_bytes(&self, image: ImageId) -> Result<Cow<'_, [u8]>, String> {
            *self.fetches.lock().unwrap().entry(image).or_default() += 1;
            self.total.fetch_add(1, Ordering::Relaxed);
            self.images.image_bytes(image)
        }
    }

    fn png(layout: Layout, codes: Vec<u8>, width: u32) -> Vec<u8> {
        let height = (codes.len() / layout.channels()) as u32 / width;
        let p = Pixels::new(width, height, layout, Samples::U8(codes)).unwrap();
        codec::encode(&p, OutputFormat::Png, EncodeOptions::default()).unwrap()
    }

    fn colour_bake(image: usize, factor: f64) -> Recipe {
        let k = Factor::new(factor).unwrap();
        let mut r = Recipe::new(ImageId(image));
        for c in [Channel::R, Channel::G, Channel::B] {
            let v = Value::scaled(Value::texel(ImageId(image), c, Transfer::Srgb), k);
            r = r.with(c, ChannelRecipe::computed(v, Transfer::Srgb));
        }
        r
    }

    #[test]
    fn equal_recipes_share_one_output() {
        let mut set = RecipeSet::new();
        let a = set.insert(colour_bake(0, 0.5));
        let b = set.insert(colour_bake(1, 0.5));
        let c = set.insert(colour_bake(0, 0.5));
        assert_eq!((a, b, c), (OutputId(0), OutputId(1), OutputId(0)));
        assert_eq!(set.len(), 2);
        assert_eq!(set.images(), vec![ImageId(0), ImageId(1)]);
    }

    #[test]
    fn each_image_is_fetched_and_decoded_once_however_many_recipes_read_it() {
        let source = Counting::new(vec![
            (
                0,
                png(Layout::Rgba, vec![200, 100, 50, 255, 10, 20, 30, 40], 2),
            ),
            (1, png(Layout::Grey, vec![255, 0], 2)),
            (2, png(Layout::Rgb, vec![1, 2, 3, 4, 5, 6], 2)),
        ]);
        let mut set = RecipeSet::new();
        set.insert(colour_bake(0, 0.5));
        set.insert(colour_bake(0, 0.25));
        let roughness = Recipe::new(ImageId(0)).with(
            Channel::A,
            ChannelRecipe::computed(
                Value::product(vec![
                    Value::texel(ImageId(0), Channel::A, Transfer::Linear),
                    Value::texel(ImageId(1), Channel::R, Transfer::Linear),
                ])
                .unwrap(),
                Transfer::Linear,
            ),
        );
        set.insert(roughness);
        set.insert(colour_bake(2, 0.5));
        let results = bake(&set, &source, &BakeOptions::default());
        assert_eq!(results.len(), 4);
        assert!(results.iter().all(Result::is_ok));
        let fetches = source.fetches.lock().unwrap().clone();
        assert_eq!(
            fetches,
            HashMap::from([(ImageId(0), 1), (ImageId(1), 1), (ImageId(2), 1)])
        );
        // The roughness output: alpha 255 * 1 and 40 * 0.
        let (format, bytes) = results[2].as_ref().unwrap().encoded.clone().unwrap();
        assert_eq!(format, OutputFormat::Png);
        let (out, _) = codec::decode(&bytes).unwrap();
        assert_eq!(
            out.samples(),
            &Samples::U8(vec![200, 100, 50, 255, 10, 20, 30, 0])
        );
    }

    #[test]
    fn a_failing_image_fails_only_the_recipes_that_read_it() {
        let mut ktx2 = b"\xabKTX 20\xbb\r\n\x1a\n".to_vec();
        ktx2.extend([0; 32]);
        let source = Counting::new(vec![
            (0, png(Layout::Rgb, vec![1, 2, 3], 1)),
            (1, ktx2),
            (2, b"not an image".to_vec()),
        ]);
        let mut set = RecipeSet::new();
        set.insert(colour_bake(0, 0.5));
        set.insert(colour_bake(1, 0.5));
        set.insert(colour_bake(2, 0.5));
        set.insert(colour_bake(3, 0.5));
        let results = bake(&set, &source, &BakeOptions::default());
        assert!(results[0].is_ok());
        let ktx = results[1].as_ref().unwrap_err();
        assert!(ktx.is_unsupported_format());
        assert!(
            ktx.to_string()
                .starts_with("image 1: KTX2 images cannot be baked"),
            "{ktx}"
        );
        let bad = results[2].as_ref().unwrap_err();
        assert!(!bad.is_unsupported_format());
        assert_eq!(
            bad.to_string(),
            "image 2: not a PNG, JPEG, WebP or KTX2 image (starts with 6e 6f 74 20 61 6e 20 69)"
        );
        assert_eq!(
            results[3].as_ref().unwrap_err().to_string(),
            "image 3: no such image"
        );
    }

    #[test]
    fn uniform_outputs_are_collapsed_only_when_asked() {
        let source = Counting::new(vec![(
            0,
            png(Layout::Rgb, vec![200, 100, 50, 200, 100, 50], 2),
        )]);
        let mut set = RecipeSet::new();
        set.insert(colour_bake(0, 0.5));
        let kept = bake(&set, &source, &BakeOptions::default());
        assert!(kept[0].as_ref().unwrap().encoded.is_some());
        assert_eq!(kept[0].as_ref().unwrap().uniform, None);
        let options = BakeOptions {
            collapse_uniform: true,
            ..BakeOptions::default()
        };
        let collapsed = bake(&set, &source, &options);
        let baked = collapsed[0].as_ref().unwrap();
        assert_eq!(baked.encoded, None);
        let half = |c: f64| {
            crate::bake::srgb::quantise(
                crate::bake::srgb::encode(0.5 * crate::bake::srgb::decode(c / 255.0)),
                255,
            )
        };
        assert_eq!(
            baked.uniform,
            Some(vec![half(200.0), half(100.0), half(50.0)])
        );
    }

    #[test]
    fn jpeg_sources_become_png_unless_the_format_is_kept() {
        let p = Pixels::new(8, 8, Layout::Rgb, Samples::U8(vec![128; 192])).unwrap();
        let jpeg = codec::encode(&p, OutputFormat::Jpeg, EncodeOptions::default()).unwrap();
        let source = Counting::new(vec![(0, jpeg)]);
        let mut set = RecipeSet::new();
        set.insert(colour_bake(0, 0.5));
        let png_out = bake(&set, &source, &BakeOptions::default());
        let baked = png_out[0].as_ref().unwrap();
        assert_eq!(baked.source_format, ImageFormat::Jpeg);
        assert_eq!(baked.encoded.as_ref().unwrap().0, OutputFormat::Png);
        let options = BakeOptions {
            keep_format: true,
            ..BakeOptions::default()
        };
        let kept = bake(&set, &source, &options);
        assert_eq!(
            kept[0].as_ref().unwrap().encoded.as_ref().unwrap().0,
            OutputFormat::Jpeg
        );
    }

    #[test]
    fn components_group_recipes_that_share_images() {
        let pair = |a: usize, b: usize| {
            Recipe::new(ImageId(a)).with(Channel::A, ChannelRecipe::Copy(ImageId(b), Channel::R))
        };
        let recipes = vec![pair(0, 1), pair(2, 3), pair(1, 4), pair(5, 5), pair(4, 2)];
        assert_eq!(components(&recipes), vec![vec![0, 1, 2, 4], vec![3]]);
    }
}
