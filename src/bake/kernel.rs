//! The pixel kernel: applies one [`Recipe`] to decoded images and yields the output pixels
//! with per-channel statistics (texels clamped, largest quantisation error in codes).
//!
//! Each output channel is compiled to the cheapest program that gives the exact f64 result:
//! - a copy (codes moved unchanged; 8-bit codes widened ×257 into a 16-bit output);
//! - a constant, when the value reads no texel;
//! - a lookup table over every input code, when the value reads one channel of one image of
//!   the output's size: the table entry for code c is the exact f64 computation for c, so the
//!   table path equals the per-texel computation by construction (8-bit inputs always; 16-bit
//!   inputs when the image has at least as many texels as the table has entries);
//! - a per-texel f64 evaluation otherwise (two-source products, maxima, ratios, resampling).
//!
//! Images of another size than the base are sampled bilinearly in linear values at the base's
//! texel centres, clamped to the edge: that is what a renderer's bilinear filter gives where the
//! two textures are sampled at the same UV, and it keeps the base's copied channels bit-exact.
//!
//! Rows are processed in bands in parallel (rayon). Alpha is never premultiplied: every channel
//! is computed from its own codes only.

use std::collections::HashMap;

use rayon::prelude::*;

use super::pixels::{Depth, Layout, Pixels, Samples};
use super::recipe::{
    Channel, ChannelRecipe, ImageId, OutputLayout, Recipe, Texel, Transfer, Value,
};
use super::srgb;

/// How the kernel runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct KernelOptions {
    /// Evaluate every texel in f64 instead of using lookup tables (for comparison; the results
    /// are identical).
    pub exact: bool,
    /// Measure the largest quantisation error of table channels (costs a histogram pass).
    pub measure: bool,
}

/// What happened in one output channel.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelStats {
    /// The glTF channel the stored channel holds (grey is reported as red).
    pub channel: Channel,
    /// Whether the channel was computed (false: copied codes).
    pub computed: bool,
    /// Texels whose value fell outside [0, 1] and were clamped.
    pub clamped: u64,
    /// Largest |code − exact value × max code| over the texels, in codes; `None` when not
    /// measured. Copies are exact (0).
    pub max_error: Option<f64>,
}

/// Per-channel statistics of one output, in stored channel order.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct KernelStats {
    /// One entry per stored output channel.
    pub channels: Vec<ChannelStats>,
}

impl KernelStats {
    /// Texels clamped over all channels.
    pub fn clamped(&self) -> u64 {
        self.channels.iter().map(|c| c.clamped).sum()
    }

    /// The largest measured error over all channels, if any channel was measured.
    pub fn max_error(&self) -> Option<f64> {
        self.channels
            .iter()
            .filter_map(|c| c.max_error)
            .reduce(f64::max)
    }
}

/// A recipe that cannot run on the images given.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KernelError {
    /// The recipe reads an image that was not supplied.
    #[error("{0} is not decoded")]
    MissingImage(ImageId),
    /// The run was asked to stop while the texels were computed; the output is incomplete.
    #[error("{}", crate::asset::limits::STOPPED)]
    Stopped,
}

use crate::asset::limits::stop_requested;

/// `Err(Stopped)` when the run was asked to stop while `out` was computed: its bands skipped
/// since then leave it incomplete.
fn unless_stopped<T>(out: T) -> Result<T, KernelError> {
    if stop_requested() {
        Err(KernelError::Stopped)
    } else {
        Ok(out)
    }
}

/// Applies `recipe` to `images` (which must hold every image the recipe reads).
pub fn apply(
    recipe: &Recipe,
    images: &HashMap<ImageId, Pixels>,
    options: KernelOptions,
) -> Result<(Pixels, KernelStats), KernelError> {
    let plan = Plan::compile(recipe, images, options)?;
    unless_stopped(match plan.depth {
        Depth::Eight => plan.run::<u8>(),
        Depth::Sixteen => plan.run::<u16>(),
    })
}

/// Applies a recipe that reads only its base image, taking the image: when the output keeps
/// the image's layout and depth and every channel is a copy, a constant or an unmeasured table
/// (the fused case), the codes are rewritten where they lie, so no second buffer is allocated.
/// Otherwise this is [`apply`].
pub fn apply_owned(
    recipe: &Recipe,
    image: Pixels,
    options: KernelOptions,
) -> Result<(Pixels, KernelStats), KernelError> {
    let base = recipe.base();
    let images = HashMap::from([(base, image)]);
    let in_place = {
        let plan = Plan::compile(recipe, &images, options)?;
        let image = &images[&base];
        match plan.fused() {
            Some(f) if plan.layout == image.layout() && plan.depth == image.depth() => {
                let stats = plan
                    .programs
                    .iter()
                    .map(|(channel, program)| {
                        finish_stats(*channel, program, Acc::default(), plan.pixels())
                    })
                    .collect();
                Some((f.tables, f.offsets, stats))
            }
            _ => None,
        }
    };
    let Some((tables, offsets, stats)) = in_place else {
        return apply(recipe, &images, options);
    };
    let image = images.into_values().next().expect("the base image");
    let (width, height, layout) = (image.width(), image.height(), image.layout());
    let Samples::U8(mut codes) = image.into_samples() else {
        unreachable!("the fused case is 8-bit")
    };
    run_in_place(&mut codes, &tables, &offsets);
    let pixels =
        Pixels::new(width, height, layout, Samples::U8(codes)).expect("the buffer keeps its size");
    unless_stopped((pixels, KernelStats { channels: stats }))
}

/// The fused pass over a buffer whose pixels it rewrites (output layout = input layout).
fn run_in_place(codes: &mut [u8], tables: &[[u8; 256]], offsets: &[usize]) {
    fn pass<const N: usize>(codes: &mut [u8], tables: &[[u8; 256]], offsets: &[usize]) {
        let tables: [[u8; 256]; N] = std::array::from_fn(|c| tables[c]);
        let offsets: [usize; N] = std::array::from_fn(|c| offsets[c]);
        let own = offsets.iter().enumerate().all(|(c, &o)| o == c);
        codes.par_chunks_mut(N * 65536).for_each(|band| {
            // A band takes well under a millisecond: a stop is seen at once.
            if stop_requested() {
                return;
            }
            for p in band.chunks_exact_mut(N) {
                // Every source code of the pixel is read before any is written.
                let src: [u8; N] = std::array::from_fn(|c| p[c]);
                for c in 0..N {
                    let from = if own { c } else { offsets[c] };
                    p[c] = tables[c][usize::from(src[from])];
                }
            }
        });
    }
    match tables.len() {
        1 => pass::<1>(codes, tables, offsets),
        2 => pass::<2>(codes, tables, offsets),
        3 => pass::<3>(codes, tables, offsets),
        4 => pass::<4>(codes, tables, offsets),
        _ => unreachable!("layouts have 1 to 4 channels"),
    }
}

/// The output layout, size and depth `recipe` gives on `images`, without computing pixels.
pub fn output_shape(
    recipe: &Recipe,
    images: &HashMap<ImageId, Pixels>,
) -> Result<(u32, u32, Layout, Depth), KernelError> {
    let plan = Plan::compile(recipe, images, KernelOptions::default())?;
    Ok((plan.width, plan.height, plan.layout, plan.depth))
}

/// An output code type.
trait Code: Copy + Default + Send + Sync + 'static {
    fn from_code(code: u32) -> Self;
    /// The buffer as bytes, for 8-bit codes.
    fn bytes_mut(codes: &mut [Self]) -> Option<&mut [u8]>;
    /// The buffer as [`Samples`].
    fn into_samples(codes: Vec<Self>) -> Samples;
}

impl Code for u8 {
    fn from_code(code: u32) -> Self {
        code as u8
    }

    fn bytes_mut(codes: &mut [Self]) -> Option<&mut [u8]> {
        Some(codes)
    }

    fn into_samples(codes: Vec<Self>) -> Samples {
        Samples::U8(codes)
    }
}

impl Code for u16 {
    fn from_code(code: u32) -> Self {
        code as u16
    }

    fn bytes_mut(_: &mut [Self]) -> Option<&mut [u8]> {
        None
    }

    fn into_samples(codes: Vec<Self>) -> Samples {
        Samples::U16(codes)
    }
}

/// One stored channel of a source image.
#[derive(Clone, Copy)]
struct Src<'a> {
    pixels: &'a Pixels,
    offset: usize,
}

impl Src<'_> {
    fn stride(&self) -> usize {
        self.pixels.layout().channels()
    }
}

/// Bilinear sampling positions of a source of another size.
struct Resample {
    /// Per output column: left and right source column, weight of the right one.
    xs: Vec<(usize, usize, f64)>,
    /// Per output row: upper and lower source row, weight of the lower one.
    ys: Vec<(usize, usize, f64)>,
}

impl Resample {
    fn axis(out: u32, src: u32) -> Vec<(usize, usize, f64)> {
        let last = src.saturating_sub(1) as f64;
        (0..out)
            .map(|i| {
                let u =
                    ((f64::from(i) + 0.5) * f64::from(src) / f64::from(out) - 0.5).clamp(0.0, last);
                let i0 = u.floor();
                let i1 = (i0 + 1.0).min(last);
                (i0 as usize, i1 as usize, u - i0)
            })
            .collect()
    }
}

/// A texel read by a per-texel program.
struct Slot<'a> {
    texel: Texel,
    src: Src<'a>,
    decode: &'static [f64],
    resample: Option<Resample>,
}

impl Slot<'_> {
    fn value(&self, x: usize, y: usize, out_width: usize) -> f64 {
        let samples = self.src.pixels.samples();
        let stride = self.src.stride();
        let code = |px: usize| samples.code(px * stride + self.src.offset) as usize;
        match &self.resample {
            None => self.decode[code(y * out_width + x)],
            Some(r) => {
                let w = self.src.pixels.width() as usize;
                let (x0, x1, fx) = r.xs[x];
                let (y0, y1, fy) = r.ys[y];
                let at = |xx: usize, yy: usize| self.decode[code(yy * w + xx)];
                let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
                let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }
}

/// A value with its texels replaced by slot numbers, for per-texel evaluation.
enum Node<'a> {
    Const(f64),
    Slot(usize),
    Product(Vec<Node<'a>>),
    Max(Vec<Node<'a>>),
    Ratio(Box<Node<'a>>, Box<Node<'a>>, f64),
    Curve(&'a super::recipe::Curve, Box<Node<'a>>),
}

impl<'a> Node<'a> {
    fn compile(value: &'a Value, slots: &[Slot<'_>]) -> Node<'a> {
        let all = |terms: &'a [Value]| terms.iter().map(|t| Node::compile(t, slots)).collect();
        match value {
            Value::Const(k) => Node::Const(k.get()),
            Value::Texel(t) => Node::Slot(
                slots
                    .iter()
                    .position(|s| s.texel == *t)
                    .expect("a slot per texel"),
            ),
            Value::Product(terms) => Node::Product(all(terms)),
            Value::Max(terms) => Node::Max(all(terms)),
            Value::Ratio { num, den, if_zero } => Node::Ratio(
                Box::new(Node::compile(num, slots)),
                Box::new(Node::compile(den, slots)),
                if_zero.get(),
            ),
            Value::Curve(c, v) => Node::Curve(c, Box::new(Node::compile(v, slots))),
        }
    }

    /// The same arithmetic as [`Value::eval`], in the same order.
    fn eval(&self, values: &[f64]) -> f64 {
        match self {
            Node::Const(k) => *k,
            Node::Slot(i) => values[*i],
            Node::Product(terms) => terms.iter().fold(1.0, |acc, t| acc * t.eval(values)),
            Node::Max(terms) => terms
                .iter()
                .map(|t| t.eval(values))
                .fold(f64::NEG_INFINITY, f64::max),
            Node::Ratio(num, den, if_zero) => {
                let d = den.eval(values);
                if d == 0.0 {
                    *if_zero
                } else {
                    num.eval(values) / d
                }
            }
            Node::Curve(c, v) => c.eval(v.eval(values)),
        }
    }
}

enum Program<'a> {
    Copy {
        src: Src<'a>,
    },
    Const {
        code: u32,
        error: f64,
        clamped: bool,
    },
    Lut {
        src: Src<'a>,
        table: Vec<u16>,
        /// Per input code: |code − exact|, and whether the value was clamped.
        error: Vec<f64>,
        clamped: Vec<bool>,
        histogram: bool,
    },
    General {
        slots: Vec<Slot<'a>>,
        value: Value,
        transfer: Transfer,
    },
}

struct Plan<'a> {
    width: u32,
    height: u32,
    layout: Layout,
    depth: Depth,
    programs: Vec<(Channel, Program<'a>)>,
}

fn decode_table(depth: Depth, transfer: Transfer) -> &'static [f64] {
    match (depth, transfer) {
        (Depth::Eight, Transfer::Srgb) => srgb::decode_table_8(),
        (Depth::Eight, Transfer::Linear) => srgb::linear_table_8(),
        (Depth::Sixteen, Transfer::Srgb) => srgb::decode_table_16(),
        (Depth::Sixteen, Transfer::Linear) => srgb::linear_table_16(),
    }
}

fn encode(value: f64, transfer: Transfer) -> f64 {
    match transfer {
        Transfer::Linear => value,
        Transfer::Srgb => srgb::encode(value),
    }
}

/// The exact result of a computed channel for a raw linear value: (code, |code − exact|,
/// clamped).
fn quantise(raw: f64, transfer: Transfer, max: u32) -> (u32, f64, bool) {
    let clamped = !(0.0..=1.0).contains(&raw);
    let encoded = encode(raw.clamp(0.0, 1.0), transfer);
    let code = srgb::quantise(encoded, max);
    (
        code,
        (f64::from(code) - encoded * f64::from(max)).abs(),
        clamped,
    )
}

fn get(images: &HashMap<ImageId, Pixels>, id: ImageId) -> Result<&Pixels, KernelError> {
    images.get(&id).ok_or(KernelError::MissingImage(id))
}

/// Rewrites texels to the stored channel they read: green and blue of grey images read red,
/// alpha of images without alpha is the constant 1.
fn normalise_value(value: &Value, images: &HashMap<ImageId, Pixels>) -> Result<Value, KernelError> {
    Ok(match value {
        Value::Const(_) => value.clone(),
        Value::Texel(t) => {
            let p = get(images, t.image)?;
            match (p.layout().has_colour(), p.layout().has_alpha(), t.channel) {
                (_, false, Channel::A) => Value::Const(super::recipe::Factor::ONE),
                (false, _, Channel::G | Channel::B) => {
                    Value::texel(t.image, Channel::R, t.transfer)
                }
                _ => value.clone(),
            }
        }
        Value::Product(terms) => {
            let terms = terms
                .iter()
                .map(|t| normalise_value(t, images))
                .collect::<Result<Vec<_>, _>>()?;
            Value::product(terms.clone()).unwrap_or(Value::Product(terms))
        }
        Value::Max(terms) => {
            let terms = terms
                .iter()
                .map(|t| normalise_value(t, images))
                .collect::<Result<Vec<_>, _>>()?;
            Value::max(terms.clone()).unwrap_or(Value::Max(terms))
        }
        Value::Ratio { num, den, if_zero } => Value::ratio(
            normalise_value(num, images)?,
            normalise_value(den, images)?,
            *if_zero,
        ),
        Value::Curve(c, v) => Value::curve(c.clone(), normalise_value(v, images)?),
    })
}

fn normalise_channel(
    recipe: ChannelRecipe,
    images: &HashMap<ImageId, Pixels>,
) -> Result<ChannelRecipe, KernelError> {
    Ok(match recipe {
        ChannelRecipe::Copy(image, channel) => {
            let p = get(images, image)?;
            match (p.layout().has_colour(), p.layout().has_alpha(), channel) {
                (_, false, Channel::A) => ChannelRecipe::Computed {
                    value: Value::Const(super::recipe::Factor::ONE),
                    transfer: Transfer::Linear,
                },
                (false, _, Channel::G | Channel::B) => ChannelRecipe::Copy(image, Channel::R),
                _ => ChannelRecipe::Copy(image, channel),
            }
        }
        ChannelRecipe::Computed { value, transfer } => {
            ChannelRecipe::computed(normalise_value(&value, images)?, transfer)
        }
    })
}

impl<'a> Plan<'a> {
    fn compile(
        recipe: &Recipe,
        images: &'a HashMap<ImageId, Pixels>,
        options: KernelOptions,
    ) -> Result<Plan<'a>, KernelError> {
        let base = get(images, recipe.base())?;
        let resolved = Channel::ALL
            .iter()
            .map(|&c| normalise_channel(recipe.resolved(c), images))
            .collect::<Result<Vec<_>, _>>()?;
        let layout = match recipe.layout() {
            OutputLayout::Fixed(layout) => layout,
            OutputLayout::Auto => {
                let colour = base.layout().has_colour()
                    || resolved[0] != resolved[1]
                    || resolved[1] != resolved[2];
                let alpha = base.layout().has_alpha() || recipe.channel(Channel::A).is_some();
                Layout::from_parts(colour, alpha)
            }
        };
        let stored = layout.stored_channels();
        let mut depth = base.depth();
        for &c in stored {
            for image in resolved[c as usize].images() {
                depth = depth.max(get(images, image)?.depth());
            }
        }
        let (width, height) = (base.width(), base.height());
        let same_size = |p: &Pixels| p.width() == width && p.height() == height;
        let max = depth.max_code();
        let mut programs = Vec::with_capacity(stored.len());
        for &channel in stored {
            let program = match resolved[channel as usize].clone() {
                ChannelRecipe::Copy(image, c) if same_size(get(images, image)?) => {
                    let pixels = get(images, image)?;
                    let offset = pixels.layout().storage_index(c).expect("normalised");
                    Program::Copy {
                        src: Src { pixels, offset },
                    }
                }
                ChannelRecipe::Copy(image, c) => {
                    // A copy from an image of another size is a resampled linear read.
                    Self::computed(
                        Value::texel(image, c, Transfer::Linear),
                        Transfer::Linear,
                        images,
                        (width, height),
                        max,
                        options,
                    )?
                }
                ChannelRecipe::Computed { value, transfer } => {
                    Self::computed(value, transfer, images, (width, height), max, options)?
                }
            };
            programs.push((channel, program));
        }
        Ok(Plan {
            width,
            height,
            layout,
            depth,
            programs,
        })
    }

    fn computed(
        value: Value,
        transfer: Transfer,
        images: &'a HashMap<ImageId, Pixels>,
        (width, height): (u32, u32),
        max: u32,
        options: KernelOptions,
    ) -> Result<Program<'a>, KernelError> {
        let texels = value.texels();
        if texels.is_empty() {
            let (code, error, clamped) = quantise(value.eval(&mut |_| 0.0), transfer, max);
            return Ok(Program::Const {
                code,
                error,
                clamped,
            });
        }
        let mut slots = Vec::with_capacity(texels.len());
        for texel in texels {
            let pixels = get(images, texel.image)?;
            let offset = pixels
                .layout()
                .storage_index(texel.channel)
                .expect("normalised");
            let resample =
                (pixels.width() != width || pixels.height() != height).then(|| Resample {
                    xs: Resample::axis(width, pixels.width()),
                    ys: Resample::axis(height, pixels.height()),
                });
            slots.push(Slot {
                texel,
                src: Src { pixels, offset },
                decode: decode_table(pixels.depth(), texel.transfer),
                resample,
            });
        }
        let table_pays = |p: &Pixels| match p.depth() {
            Depth::Eight => true,
            Depth::Sixteen => p.pixel_count() >= 65536,
        };
        if !options.exact
            && slots.len() == 1
            && slots[0].resample.is_none()
            && table_pays(slots[0].src.pixels)
        {
            let slot = slots.pop().expect("one slot");
            let n = slot.decode.len();
            let mut table = Vec::with_capacity(n);
            let mut error = Vec::with_capacity(n);
            let mut clamped = Vec::with_capacity(n);
            for &linear in slot.decode {
                let (code, e, c) = quantise(value.eval(&mut |_| linear), transfer, max);
                table.push(code as u16);
                error.push(e);
                clamped.push(c);
            }
            let histogram = options.measure || clamped.iter().any(|&c| c);
            return Ok(Program::Lut {
                src: slot.src,
                table,
                error,
                clamped,
                histogram,
            });
        }
        Ok(Program::General {
            slots,
            value,
            transfer,
        })
    }

    fn run<O: Code>(self) -> (Pixels, KernelStats) {
        let n = self.layout.channels();
        let width = self.width as usize;
        let row = width * n;
        let total = row * self.height as usize;
        let mut out = vec![O::default(); total];
        // Bands of about 64K texels keep a band's input and output in cache.
        let rows_per_band = (65536 / width.max(1)).max(1);
        let band_len = (rows_per_band * row).max(1);
        let max = self.depth.max_code();
        let fused = self.fused();
        let accs: Vec<Vec<Acc>> =
            if let (Some(fused), Some(bytes)) = (&fused, O::bytes_mut(&mut out)) {
                run_fused(fused, bytes, band_len, n);
                vec![]
            } else {
                // Tables in the output's code type, converted once.
                let tables: Vec<Vec<O>> = self
                    .programs
                    .iter()
                    .map(|(_, p)| match p {
                        Program::Lut { table, .. } => {
                            table.iter().map(|&c| O::from_code(u32::from(c))).collect()
                        }
                        _ => Vec::new(),
                    })
                    .collect();
                out.par_chunks_mut(band_len)
                    .enumerate()
                    .map(|(b, band)| {
                        if stop_requested() {
                            return self.programs.iter().map(|_| Acc::default()).collect();
                        }
                        let first_pixel = b * rows_per_band * width;
                        self.programs
                            .iter()
                            .zip(&tables)
                            .enumerate()
                            .map(|(s, ((_, program), table))| {
                                run_program(program, table, band, first_pixel, s, n, width, max)
                            })
                            .collect()
                    })
                    .collect()
            };
        let stats = self
            .programs
            .iter()
            .enumerate()
            .map(|(s, (channel, program))| {
                let mut acc = Acc::default();
                for band in &accs {
                    acc.merge(&band[s]);
                }
                finish_stats(*channel, program, acc, self.pixels())
            })
            .collect();
        let samples = O::into_samples(out);
        let pixels = Pixels::new(self.width, self.height, self.layout, samples)
            .expect("the output buffer matches its size");
        (pixels, KernelStats { channels: stats })
    }

    /// The single-pass form of an 8-bit output whose channels are all copies, constants or
    /// unmeasured tables reading one 8-bit image of the output's size: one 256-entry table per
    /// output channel (a copy is the identity table) and the stored channel each one reads.
    fn fused(&self) -> Option<Fused<'a>> {
        if self.depth != Depth::Eight {
            return None;
        }
        let mut source: Option<&'a Pixels> = None;
        let mut tables = Vec::with_capacity(self.programs.len());
        let mut offsets = Vec::with_capacity(self.programs.len());
        for (_, program) in &self.programs {
            let (src, table): (Option<&Src<'a>>, [u8; 256]) = match program {
                Program::Copy { src } => (Some(src), std::array::from_fn(|c| c as u8)),
                Program::Lut {
                    src,
                    table,
                    histogram: false,
                    ..
                } => (Some(src), std::array::from_fn(|c| table[c] as u8)),
                Program::Const { code, .. } => (None, [*code as u8; 256]),
                _ => return None,
            };
            match src {
                Some(src) => {
                    match source {
                        Some(p) if !std::ptr::eq(p, src.pixels) => return None,
                        _ => source = Some(src.pixels),
                    }
                    if src.pixels.depth() != Depth::Eight {
                        return None;
                    }
                    offsets.push(src.offset);
                }
                None => offsets.push(0),
            }
            tables.push(table);
        }
        let pixels = source?;
        let Samples::U8(codes) = pixels.samples() else {
            return None;
        };
        Some(Fused {
            codes,
            stride: pixels.layout().channels(),
            tables,
            offsets,
        })
    }

    fn pixels(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }
}

/// See [`Plan::fused`].
struct Fused<'a> {
    codes: &'a [u8],
    stride: usize,
    tables: Vec<[u8; 256]>,
    offsets: Vec<usize>,
}

/// One pass over the pixels, every output channel through its table.
fn run_fused(fused: &Fused<'_>, out: &mut [u8], band_len: usize, n: usize) {
    fn pass<const N: usize, const S: usize>(fused: &Fused<'_>, out: &mut [u8], band_len: usize) {
        let tables: [[u8; 256]; N] = std::array::from_fn(|c| fused.tables[c]);
        let offsets: [usize; N] = std::array::from_fn(|c| fused.offsets[c]);
        let pixels_per_band = band_len / N;
        out.par_chunks_mut(band_len)
            .enumerate()
            .for_each(|(b, band)| {
                if stop_requested() {
                    return;
                }
                let first = b * pixels_per_band;
                let src = &fused.codes[first * S..(first + band.len() / N) * S];
                let pairs = band.chunks_exact_mut(N).zip(src.chunks_exact(S));
                if offsets.iter().enumerate().all(|(c, &o)| o == c) {
                    // Each channel reads its own: constant offsets unroll cleanly.
                    for (d, p) in pairs {
                        for c in 0..N {
                            d[c] = tables[c][usize::from(p[c])];
                        }
                    }
                } else {
                    for (d, p) in pairs {
                        for c in 0..N {
                            d[c] = tables[c][usize::from(p[offsets[c]])];
                        }
                    }
                }
            });
    }
    match (n, fused.stride) {
        (4, 4) => pass::<4, 4>(fused, out, band_len),
        (3, 3) => pass::<3, 3>(fused, out, band_len),
        (4, 3) => pass::<4, 3>(fused, out, band_len),
        (3, 4) => pass::<3, 4>(fused, out, band_len),
        (1, 1) => pass::<1, 1>(fused, out, band_len),
        (2, 2) => pass::<2, 2>(fused, out, band_len),
        (3, 1) => pass::<3, 1>(fused, out, band_len),
        (4, 2) => pass::<4, 2>(fused, out, band_len),
        (2, 1) => pass::<2, 1>(fused, out, band_len),
        (1, 4) => pass::<1, 4>(fused, out, band_len),
        (1, 3) => pass::<1, 3>(fused, out, band_len),
        (1, 2) => pass::<1, 2>(fused, out, band_len),
        (4, 1) => pass::<4, 1>(fused, out, band_len),
        (2, 4) => pass::<2, 4>(fused, out, band_len),
        (2, 3) => pass::<2, 3>(fused, out, band_len),
        (3, 2) => pass::<3, 2>(fused, out, band_len),
        _ => unreachable!("layouts have 1 to 4 channels"),
    }
}

/// Per-band accumulation of one channel's statistics.
#[derive(Default)]
struct Acc {
    clamped: u64,
    max_error: f64,
    histogram: Vec<u64>,
}

impl Acc {
    fn merge(&mut self, other: &Acc) {
        self.clamped += other.clamped;
        self.max_error = self.max_error.max(other.max_error);
        if self.histogram.is_empty() {
            self.histogram = other.histogram.clone();
        } else {
            for (a, b) in self.histogram.iter_mut().zip(&other.histogram) {
                *a += b;
            }
        }
    }
}

fn finish_stats(channel: Channel, program: &Program<'_>, acc: Acc, pixels: u64) -> ChannelStats {
    match program {
        Program::Copy { .. } => ChannelStats {
            channel,
            computed: false,
            clamped: 0,
            max_error: Some(0.0),
        },
        Program::Const { error, clamped, .. } => ChannelStats {
            channel,
            computed: true,
            clamped: if *clamped { pixels } else { 0 },
            max_error: Some(if pixels == 0 { 0.0 } else { *error }),
        },
        Program::Lut {
            error,
            clamped,
            histogram,
            ..
        } => {
            if !*histogram {
                return ChannelStats {
                    channel,
                    computed: true,
                    clamped: 0,
                    max_error: None,
                };
            }
            let mut count = 0;
            let mut max_error = 0.0f64;
            for (code, &hits) in acc.histogram.iter().enumerate() {
                if hits > 0 {
                    if clamped[code] {
                        count += hits;
                    }
                    max_error = max_error.max(error[code]);
                }
            }
            ChannelStats {
                channel,
                computed: true,
                clamped: count,
                max_error: Some(max_error),
            }
        }
        Program::General { .. } => ChannelStats {
            channel,
            computed: true,
            clamped: acc.clamped,
            max_error: Some(acc.max_error),
        },
    }
}

fn widen<O: Code>(code: u32, from: Depth, to_max: u32) -> O {
    match (from, to_max) {
        (Depth::Eight, 65535) => O::from_code(code * 257),
        _ => O::from_code(code),
    }
}

/// Runs one channel's program over a band (`band` holds whole output pixels of `n` channels,
/// starting at pixel `first`), writing stored channel `s`.
#[allow(clippy::too_many_arguments)]
fn run_program<O: Code>(
    program: &Program<'_>,
    table: &[O],
    band: &mut [O],
    first: usize,
    s: usize,
    n: usize,
    width: usize,
    max: u32,
) -> Acc {
    let count = band.len() / n;
    let mut acc = Acc::default();
    match program {
        Program::Copy { src } => {
            let stride = src.stride();
            let depth = src.pixels.depth();
            match src.pixels.samples() {
                Samples::U8(codes) => {
                    let codes = &codes[first * stride..(first + count) * stride];
                    for (d, c) in band.chunks_exact_mut(n).zip(codes.chunks_exact(stride)) {
                        d[s] = widen(u32::from(c[src.offset]), depth, max);
                    }
                }
                Samples::U16(codes) => {
                    let codes = &codes[first * stride..(first + count) * stride];
                    for (d, c) in band.chunks_exact_mut(n).zip(codes.chunks_exact(stride)) {
                        d[s] = O::from_code(u32::from(c[src.offset]));
                    }
                }
            }
        }
        Program::Const { code, .. } => {
            let code = O::from_code(*code);
            for d in band.chunks_exact_mut(n) {
                d[s] = code;
            }
        }
        Program::Lut { src, histogram, .. } => {
            let stride = src.stride();
            if *histogram {
                acc.histogram = vec![0; table.len()];
            }
            match src.pixels.samples() {
                Samples::U8(codes) => {
                    let codes = &codes[first * stride..(first + count) * stride];
                    let table: &[O; 256] = table.try_into().expect("256 entries");
                    lut_band(
                        band,
                        codes,
                        stride,
                        src.offset,
                        s,
                        n,
                        table,
                        &mut acc.histogram,
                    );
                }
                Samples::U16(codes) => {
                    let codes = &codes[first * stride..(first + count) * stride];
                    let table: &[O; 65536] = table.try_into().expect("65536 entries");
                    lut_band(
                        band,
                        codes,
                        stride,
                        src.offset,
                        s,
                        n,
                        table,
                        &mut acc.histogram,
                    );
                }
            }
        }
        Program::General {
            slots,
            value,
            transfer,
        } => {
            let node = Node::compile(value, slots);
            let mut values = vec![0.0; slots.len()];
            for (i, d) in band.chunks_exact_mut(n).enumerate() {
                let pixel = first + i;
                let (x, y) = (pixel % width, pixel / width);
                for (v, slot) in values.iter_mut().zip(slots) {
                    *v = slot.value(x, y, width);
                }
                let (code, error, clamped) = quantise(node.eval(&values), *transfer, max);
                d[s] = O::from_code(code);
                acc.clamped += u64::from(clamped);
                acc.max_error = acc.max_error.max(error);
            }
        }
    }
    acc
}

/// The table loop. Tables are fixed-size arrays indexed by a code of the same width, so the
/// index needs no bounds check.
#[allow(clippy::too_many_arguments)]
fn lut_band<I, O, const N: usize>(
    band: &mut [O],
    codes: &[I],
    stride: usize,
    offset: usize,
    s: usize,
    n: usize,
    table: &[O; N],
    histogram: &mut [u64],
) where
    I: Copy + Into<usize>,
    O: Code,
{
    let pairs = band.chunks_exact_mut(n).zip(codes.chunks_exact(stride));
    if histogram.is_empty() {
        for (d, c) in pairs {
            d[s] = table[c[offset].into()];
        }
    } else {
        for (d, c) in pairs {
            let code: usize = c[offset].into();
            d[s] = table[code];
            histogram[code] += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::recipe::{Curve, Factor};

    const IMG: ImageId = ImageId(0);
    const OTHER: ImageId = ImageId(1);

    /// The exact computation, written out independently of the kernel: decode, scale, clamp,
    /// encode, round to the nearest code (ties to even).
    fn reference(code: u32, max: u32, factor: f64, transfer: Transfer) -> u32 {
        let v = f64::from(code) / f64::from(max);
        let linear = match transfer {
            Transfer::Linear => v,
            Transfer::Srgb if v <= 0.04045 => v / 12.92,
            Transfer::Srgb => ((v + 0.055) / 1.055).powf(2.4),
        };
        let l = (factor * linear).clamp(0.0, 1.0);
        let e = match transfer {
            Transfer::Linear => l,
            Transfer::Srgb if l <= 0.0031308 => l * 12.92,
            Transfer::Srgb => 1.055 * l.powf(1.0 / 2.4) - 0.055,
        };
        (e * f64::from(max)).round_ties_even() as u32
    }

    const FACTORS: [f64; 8] = [0.0, 1.0, 0.5, 1.0 / 255.0, 0.999, 0.25, 0.7316, 0.0031308];

    /// Every 8-bit code once: R = G = B = c, A = 255 - c.
    fn all_codes_8() -> Pixels {
        let codes = (0..=255u8).flat_map(|c| [c, c, c, 255 - c]).collect();
        Pixels::new(256, 1, Layout::Rgba, Samples::U8(codes)).unwrap()
    }

    /// Every 16-bit code once (256 × 256): R = G = B = c, A = 65535 - c.
    fn all_codes_16() -> Pixels {
        let codes = (0..=65535u16).flat_map(|c| [c, c, c, 65535 - c]).collect();
        Pixels::new(256, 256, Layout::Rgba, Samples::U16(codes)).unwrap()
    }

    fn scaled(channel: Channel, factor: f64, transfer: Transfer) -> ChannelRecipe {
        // Built by hand so that factor 1 goes through the computed path too.
        ChannelRecipe::Computed {
            value: Value::Product(vec![
                Value::Const(Factor::new(factor).unwrap()),
                Value::texel(IMG, channel, transfer),
            ]),
            transfer,
        }
    }

    fn colour_and_alpha(colour: f64, alpha: f64) -> Recipe {
        Recipe::new(IMG)
            .with(Channel::R, scaled(Channel::R, colour, Transfer::Srgb))
            .with(Channel::G, scaled(Channel::G, colour, Transfer::Srgb))
            .with(Channel::B, scaled(Channel::B, colour, Transfer::Srgb))
            .with(Channel::A, scaled(Channel::A, alpha, Transfer::Linear))
    }

    fn one(image: Pixels) -> HashMap<ImageId, Pixels> {
        HashMap::from([(IMG, image)])
    }

    /// Applies a recipe measured and unmeasured (the unmeasured table path runs in one fused
    /// pass), checks both give the same pixels, and returns the measured run.
    fn run(
        recipe: &Recipe,
        images: &HashMap<ImageId, Pixels>,
        exact: bool,
    ) -> (Pixels, KernelStats) {
        let measure = |measure| apply(recipe, images, KernelOptions { exact, measure }).unwrap();
        let (measured, plain) = (measure(true), measure(false));
        assert_eq!(measured.0, plain.0, "measured and unmeasured runs agree");
        measured
    }

    fn codes(p: &Pixels) -> Vec<u32> {
        (0..p.samples().len())
            .map(|i| p.samples().code(i))
            .collect()
    }

    #[test]
    fn the_8_bit_table_and_exact_paths_equal_the_reference_for_every_code_and_factor() {
        let images = one(all_codes_8());
        for factor in FACTORS {
            let recipe = colour_and_alpha(factor, factor);
            for exact in [false, true] {
                let (out, stats) = run(&recipe, &images, exact);
                assert_eq!(out.layout(), Layout::Rgba);
                assert_eq!(out.depth(), Depth::Eight);
                for c in 0..=255u32 {
                    let px = codes(&out)[c as usize * 4..c as usize * 4 + 4].to_vec();
                    let colour = reference(c, 255, factor, Transfer::Srgb);
                    let alpha = reference(255 - c, 255, factor, Transfer::Linear);
                    assert_eq!(
                        px,
                        vec![colour, colour, colour, alpha],
                        "code {c} factor {factor} exact {exact}"
                    );
                }
                assert_eq!(stats.clamped(), 0);
                assert!(stats.max_error().unwrap() <= 0.5, "{stats:?}");
            }
        }
    }

    #[test]
    fn one_8_bit_image_runs_in_one_fused_pass_unless_measured() {
        let images = one(all_codes_8());
        let recipe = colour_and_alpha(0.5, 0.5);
        let compile = |options| Plan::compile(&recipe, &images, options).unwrap();
        assert!(compile(KernelOptions::default()).fused().is_some());
        let measured = KernelOptions {
            measure: true,
            ..KernelOptions::default()
        };
        assert!(compile(measured).fused().is_none());
        let exact = KernelOptions {
            exact: true,
            ..KernelOptions::default()
        };
        assert!(compile(exact).fused().is_none());
    }

    #[test]
    fn applying_to_an_owned_image_gives_the_same_pixels_and_stats() {
        let recipes = [
            colour_and_alpha(0.5, 0.25),
            Recipe::new(IMG).with(Channel::A, ChannelRecipe::Copy(IMG, Channel::G)),
            colour_and_alpha(2.0, 1.0),
        ];
        for image in [all_codes_8(), all_codes_16()] {
            for recipe in &recipes {
                for options in [
                    KernelOptions::default(),
                    KernelOptions {
                        exact: false,
                        measure: true,
                    },
                ] {
                    let shared = apply(recipe, &one(image.clone()), options).unwrap();
                    let owned = apply_owned(recipe, image.clone(), options).unwrap();
                    assert_eq!(shared, owned);
                }
            }
        }
        let grey = Pixels::new(2, 1, Layout::Grey, Samples::U8(vec![100, 200])).unwrap();
        let recipe = Recipe::new(IMG).with(Channel::A, ChannelRecipe::Copy(IMG, Channel::R));
        let (out, _) = apply_owned(&recipe, grey, KernelOptions::default()).unwrap();
        assert_eq!(
            out.layout(),
            Layout::GreyAlpha,
            "a new layout is not done in place"
        );
        assert_eq!(codes(&out), vec![100, 100, 200, 200]);
    }

    #[test]
    fn the_16_bit_table_and_exact_paths_equal_the_reference_for_every_code() {
        let images = one(all_codes_16());
        for factor in [0.0, 1.0, 0.5, 0.999, 1.0 / 65535.0] {
            let recipe = colour_and_alpha(factor, factor);
            let (table, _) = run(&recipe, &images, false);
            let (exact, _) = run(&recipe, &images, true);
            assert_eq!(table, exact, "factor {factor}");
            assert_eq!(table.depth(), Depth::Sixteen);
            let got = codes(&table);
            for c in 0..=65535u32 {
                let i = c as usize * 4;
                assert_eq!(
                    got[i],
                    reference(c, 65535, factor, Transfer::Srgb),
                    "code {c}"
                );
                assert_eq!(
                    got[i + 3],
                    reference(65535 - c, 65535, factor, Transfer::Linear)
                );
            }
        }
    }

    #[test]
    fn factor_1_leaves_every_code_unchanged_and_factor_0_gives_exact_zeros() {
        for image in [all_codes_8(), all_codes_16()] {
            let images = one(image.clone());
            for exact in [false, true] {
                let (out, _) = run(&colour_and_alpha(1.0, 1.0), &images, exact);
                assert_eq!(out, image);
                let (out, _) = run(&colour_and_alpha(0.0, 0.0), &images, exact);
                assert!(codes(&out).iter().all(|&c| c == 0));
            }
        }
    }

    #[test]
    fn codes_either_side_of_the_srgb_threshold_scale_by_their_own_segment() {
        // 8-bit codes 10 (0.0392, toe) and 11 (0.0431, power segment) with factor 0.5:
        // 10: 0.5 * 0.0392/12.92 = 0.001518 (toe again) -> 0.01961 * 255 = 5.0 -> 5;
        // 11: 0.5 * 0.003347 = 0.001673 (toe) -> 0.02162 * 255 = 5.51 -> 6.
        let image =
            Pixels::new(2, 1, Layout::Rgb, Samples::U8(vec![10, 10, 10, 11, 11, 11])).unwrap();
        let recipe = colour_and_alpha(0.5, 1.0);
        let (out, _) = run(&recipe, &one(image), false);
        assert_eq!(codes(&out), vec![5, 5, 5, 255, 6, 6, 6, 255]);
        assert_eq!(
            out.layout(),
            Layout::Rgba,
            "setting alpha adds an alpha channel"
        );
        assert_eq!(reference(10, 255, 0.5, Transfer::Srgb), 5);
        assert_eq!(reference(11, 255, 0.5, Transfer::Srgb), 6);
    }

    #[test]
    fn alpha_is_never_premultiplied() {
        // Transparent texels keep their colour, and scaling alpha leaves colour alone.
        let image = Pixels::new(
            2,
            1,
            Layout::Rgba,
            Samples::U8(vec![200, 100, 50, 0, 200, 100, 50, 128]),
        )
        .unwrap();
        let images = one(image);
        let (out, _) = run(&colour_and_alpha(1.0, 0.5), &images, false);
        assert_eq!(codes(&out), vec![200, 100, 50, 0, 200, 100, 50, 64]);
        let (out, _) = run(&colour_and_alpha(0.5, 1.0), &images, false);
        let half = |c| reference(c, 255, 0.5, Transfer::Srgb);
        assert_eq!(
            codes(&out),
            vec![
                half(200),
                half(100),
                half(50),
                0,
                half(200),
                half(100),
                half(50),
                128
            ]
        );
    }

    #[test]
    fn channels_the_recipe_does_not_touch_stay_bit_exact() {
        let image = all_codes_16();
        let recipe = Recipe::new(IMG).with(Channel::A, scaled(Channel::A, 0.3, Transfer::Linear));
        let (out, stats) = run(&recipe, &one(image.clone()), false);
        let (a, b) = (codes(&out), codes(&image));
        for i in 0..65536 {
            assert_eq!(a[i * 4..i * 4 + 3], b[i * 4..i * 4 + 3]);
        }
        assert!(!stats.channels[0].computed);
        assert!(stats.channels[3].computed);
    }

    #[test]
    fn green_moves_to_alpha_bit_exact() {
        let image = Pixels::new(2, 1, Layout::Rgb, Samples::U8(vec![1, 2, 3, 4, 5, 6])).unwrap();
        let recipe = Recipe::new(IMG).with(Channel::A, ChannelRecipe::Copy(IMG, Channel::G));
        let (out, _) = run(&recipe, &one(image), false);
        assert_eq!(out.layout(), Layout::Rgba);
        assert_eq!(codes(&out), vec![1, 2, 3, 2, 4, 5, 6, 5]);
    }

    #[test]
    fn grey_images_stay_grey_for_grey_factors_and_become_rgb_for_coloured_ones() {
        let image = Pixels::new(2, 1, Layout::Grey, Samples::U8(vec![100, 200])).unwrap();
        let images = one(image);
        let (out, _) = run(
            &colour_and_alpha(0.5, 1.0).with(Channel::A, ChannelRecipe::Copy(IMG, Channel::A)),
            &images,
            false,
        );
        assert_eq!(out.layout(), Layout::Grey);
        let half = |c| reference(c, 255, 0.5, Transfer::Srgb);
        assert_eq!(codes(&out), vec![half(100), half(200)]);
        let recipe = Recipe::new(IMG)
            .with(Channel::R, scaled(Channel::R, 0.5, Transfer::Srgb))
            .with(Channel::G, scaled(Channel::G, 0.25, Transfer::Srgb))
            .with(Channel::B, scaled(Channel::B, 0.5, Transfer::Srgb));
        let (out, _) = run(&recipe, &images, false);
        assert_eq!(out.layout(), Layout::Rgb);
        let quarter = |c| reference(c, 255, 0.25, Transfer::Srgb);
        assert_eq!(
            codes(&out),
            vec![
                half(100),
                quarter(100),
                half(100),
                half(200),
                quarter(200),
                half(200)
            ]
        );
    }

    #[test]
    fn out_of_range_factors_clamp_and_are_counted() {
        let images = one(all_codes_8());
        let recipe = Recipe::new(IMG).with(Channel::A, scaled(Channel::A, 2.0, Transfer::Linear));
        for exact in [false, true] {
            // Alpha codes 255 - c for c in 0..=255: 2a/255 > 1 for a >= 128, i.e. 128 texels.
            let options = KernelOptions {
                exact,
                measure: false,
            };
            let (out, stats) = apply(&recipe, &images, options).unwrap();
            assert_eq!(stats.clamped(), 128);
            assert_eq!(stats.channels[3].clamped, 128);
            assert_eq!(out.code(0, 0, Channel::A), 255);
            assert_eq!(out.code(255, 0, Channel::A), 0);
            assert_eq!(out.code(200, 0, Channel::A), 110);
        }
        let recipe = Recipe::new(IMG).with(Channel::A, scaled(Channel::A, -0.5, Transfer::Linear));
        let (out, stats) = run(&recipe, &images, false);
        assert_eq!(stats.clamped(), 255, "every non-zero alpha goes negative");
        assert!((0..256).all(|x| out.code(x, 0, Channel::A) == 0));
    }

    #[test]
    fn two_sources_of_equal_size_multiply_texel_by_texel() {
        let colour = Pixels::new(
            2,
            1,
            Layout::Rgb,
            Samples::U8(vec![255, 128, 0, 64, 64, 64]),
        )
        .unwrap();
        let intensity = Pixels::new(2, 1, Layout::Grey, Samples::U8(vec![255, 51])).unwrap();
        let images = HashMap::from([(IMG, colour), (OTHER, intensity)]);
        let k = Factor::new(0.5).unwrap();
        let channel = |c| {
            ChannelRecipe::computed(
                Value::product(vec![
                    Value::Const(k),
                    Value::texel(IMG, c, Transfer::Srgb),
                    Value::texel(OTHER, Channel::R, Transfer::Linear),
                ])
                .unwrap(),
                Transfer::Srgb,
            )
        };
        let recipe = Recipe::new(IMG)
            .with(Channel::R, channel(Channel::R))
            .with(Channel::G, channel(Channel::G))
            .with(Channel::B, channel(Channel::B));
        let (out, stats) = run(&recipe, &images, false);
        let expect = |c: u32, i: f64| reference(c, 255, 0.5 * i, Transfer::Srgb);
        let i1 = 51.0 / 255.0;
        assert_eq!(
            codes(&out),
            vec![
                expect(255, 1.0),
                expect(128, 1.0),
                0,
                expect(64, i1),
                expect(64, i1),
                expect(64, i1)
            ]
        );
        assert!(stats.max_error().unwrap() <= 0.5);
    }

    #[test]
    fn a_second_source_of_another_size_is_sampled_bilinearly_at_the_base_texel_centres() {
        // Base 4x1, intensity 2x1 holding linear 0 and 1: the base's texel centres fall at
        // intensity coordinates -0.25, 0.25, 0.75, 1.25 -> clamped weights 0, 0.25, 0.75, 1.
        let base = Pixels::new(4, 1, Layout::Grey, Samples::U8(vec![255; 4])).unwrap();
        let intensity = Pixels::new(2, 1, Layout::Grey, Samples::U8(vec![0, 255])).unwrap();
        let images = HashMap::from([(IMG, base), (OTHER, intensity)]);
        let value = Value::product(vec![
            Value::texel(IMG, Channel::R, Transfer::Linear),
            Value::texel(OTHER, Channel::R, Transfer::Linear),
        ])
        .unwrap();
        let recipe = Recipe::new(IMG).with(
            Channel::R,
            ChannelRecipe::computed(value.clone(), Transfer::Linear),
        );
        let recipe = recipe
            .with(
                Channel::G,
                ChannelRecipe::computed(value.clone(), Transfer::Linear),
            )
            .with(Channel::B, ChannelRecipe::computed(value, Transfer::Linear));
        let (out, _) = run(&recipe, &images, false);
        assert_eq!(
            (out.width(), out.height(), out.layout()),
            (4, 1, Layout::Grey)
        );
        // 0.25 * 255 = 63.75 -> 64; 0.75 * 255 = 191.25 -> 191.
        assert_eq!(codes(&out), vec![0, 64, 191, 255]);
    }

    #[test]
    fn an_8_bit_base_copied_into_a_16_bit_output_keeps_its_values() {
        let base = Pixels::new(1, 1, Layout::Rgba, Samples::U8(vec![10, 20, 30, 40])).unwrap();
        let rough = Pixels::new(1, 1, Layout::Grey, Samples::U16(vec![65535])).unwrap();
        let images = HashMap::from([(IMG, base), (OTHER, rough)]);
        let recipe = Recipe::new(IMG).with(
            Channel::A,
            ChannelRecipe::computed(
                Value::product(vec![
                    Value::texel(IMG, Channel::A, Transfer::Linear),
                    Value::texel(OTHER, Channel::R, Transfer::Linear),
                ])
                .unwrap(),
                Transfer::Linear,
            ),
        );
        let (out, _) = run(&recipe, &images, false);
        assert_eq!(out.depth(), Depth::Sixteen);
        assert_eq!(codes(&out), vec![10 * 257, 20 * 257, 30 * 257, 40 * 257]);
    }

    #[test]
    fn a_curve_is_applied_to_the_scaled_value() {
        let images = one(all_codes_8());
        let curve = Curve::sampled(
            "square",
            &(0..=64)
                .map(|i| (f64::from(i) / 64.0).powi(2))
                .collect::<Vec<_>>(),
        )
        .unwrap();
        let value = Value::curve(
            curve.clone(),
            Value::scaled(
                Value::texel(IMG, Channel::A, Transfer::Linear),
                Factor::new(0.8).unwrap(),
            ),
        );
        let recipe =
            Recipe::new(IMG).with(Channel::A, ChannelRecipe::computed(value, Transfer::Linear));
        let (table, _) = run(&recipe, &images, false);
        let (exact, _) = run(&recipe, &images, true);
        assert_eq!(table, exact);
        for a in 0..=255u32 {
            let want = (curve.eval(0.8 * f64::from(a) / 255.0) * 255.0).round_ties_even() as u32;
            assert_eq!(table.code(255 - a, 0, Channel::A), want, "alpha {a}");
        }
    }

    #[test]
    fn the_maximum_and_the_normalised_colour_of_an_rgb_texel() {
        // The per-texel maximum of the linear colour (red channel, linear) and the colour
        // divided by it (sRGB); a black texel gets the `if_zero` value.
        let image =
            Pixels::new(2, 1, Layout::Rgb, Samples::U8(vec![255, 128, 0, 0, 0, 0])).unwrap();
        let images = one(image);
        let lin = |c| Value::texel(IMG, c, Transfer::Srgb);
        let max = Value::max(vec![lin(Channel::R), lin(Channel::G), lin(Channel::B)]).unwrap();
        let recipe = Recipe::new(IMG)
            .with_layout(OutputLayout::Fixed(Layout::Grey))
            .with(
                Channel::R,
                ChannelRecipe::computed(max.clone(), Transfer::Linear),
            );
        let (out, _) = run(&recipe, &images, false);
        assert_eq!(codes(&out), vec![255, 0]);
        let norm = |c| {
            ChannelRecipe::computed(
                Value::ratio(lin(c), max.clone(), Factor::ONE),
                Transfer::Srgb,
            )
        };
        let recipe = Recipe::new(IMG)
            .with(Channel::R, norm(Channel::R))
            .with(Channel::G, norm(Channel::G))
            .with(Channel::B, norm(Channel::B));
        let (out, _) = run(&recipe, &images, false);
        assert_eq!(codes(&out), vec![255, 128, 0, 255, 255, 255]);
    }

    #[test]
    fn a_recipe_reading_an_image_not_supplied_is_an_error() {
        let recipe = Recipe::new(IMG).with(Channel::A, ChannelRecipe::Copy(OTHER, Channel::R));
        let err = apply(&recipe, &one(all_codes_8()), KernelOptions::default()).unwrap_err();
        assert_eq!(err, KernelError::MissingImage(OTHER));
    }
}
