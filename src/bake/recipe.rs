//! Bake recipes: what one output image holds, as a plain value.
//!
//! A [`Recipe`] names a base image (whose size, layout and file format the output keeps) and,
//! per glTF channel, either nothing (the base's channel is copied bit-exact), a copy of some
//! image's channel (a channel move such as green → alpha), or a computed linear value encoded
//! with the channel's transfer function. A computed [`Value`] is a small expression over texels
//! (an image channel decoded with its transfer function), constants, products, maxima, ratios
//! and sampled curves; that covers texture × factor, colour × intensity from two images, the
//! per-texel maximum of a colour and a colour normalised by it, and non-linear remappings.
//!
//! Recipes derive `Eq`, `Ord` and `Hash`: equal recipes share one output. The constructors keep
//! values canonical (constants folded, factor 1 and identity re-encodes dropped, product terms
//! sorted) so that recipes with the same meaning compare equal.

use std::fmt;
use std::sync::Arc;

/// Index of an image in the asset's `images` array.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ImageId(pub usize);

impl fmt::Display for ImageId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "image {}", self.0)
    }
}

/// A channel as glTF samples it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Channel {
    /// Red (the grey channel of a grey image).
    R = 0,
    /// Green (the grey channel of a grey image).
    G = 1,
    /// Blue (the grey channel of a grey image).
    B = 2,
    /// Alpha (opaque when the image has none).
    A = 3,
}

impl Channel {
    /// All four, in order.
    pub const ALL: [Channel; 4] = [Channel::R, Channel::G, Channel::B, Channel::A];
}

/// How a channel's codes map to linear values.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Transfer {
    /// code / max.
    Linear,
    /// The sRGB transfer function of code / max.
    Srgb,
}

/// A recipe that cannot be built.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RecipeError {
    /// A factor or curve sample that is NaN or infinite.
    #[error("{what} must be a finite number, got {value}")]
    NotFinite {
        /// What the number was for.
        what: &'static str,
        /// The number as given.
        value: String,
    },
    /// A curve with fewer than two samples.
    #[error("curve `{name}` needs at least two samples, got {count}")]
    CurveTooShort {
        /// The curve's name.
        name: String,
        /// Samples given.
        count: usize,
    },
    /// An operation with nothing to operate on.
    #[error("{0} needs at least one operand")]
    Empty(&'static str),
}

/// A finite number stored by its bits so that it can be compared and hashed; -0 is stored as 0.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Factor(u64);

impl Factor {
    /// Zero.
    pub const ZERO: Factor = Factor(0);
    /// One.
    pub const ONE: Factor = Factor(0x3ff0_0000_0000_0000);

    /// A finite number; NaN and infinities are refused.
    pub fn new(value: f64) -> Result<Factor, RecipeError> {
        if !value.is_finite() {
            return Err(RecipeError::NotFinite {
                what: "a factor",
                value: value.to_string(),
            });
        }
        // Adding 0.0 turns -0.0 into +0.0 and leaves every other value alone.
        Ok(Factor((value + 0.0).to_bits()))
    }

    /// The number.
    pub fn get(self) -> f64 {
        f64::from_bits(self.0)
    }
}

impl fmt::Debug for Factor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.get())
    }
}

impl fmt::Display for Factor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.get())
    }
}

/// A function on [0, 1] given by evenly spaced samples (the first at 0, the last at 1) and
/// linear interpolation between them; inputs outside [0, 1] are clamped to it. The name says
/// what it is (e.g. a fitted roughness mapping and its version); two curves are equal when names
/// and samples are.
#[derive(Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Curve {
    name: Arc<str>,
    samples: Arc<[u64]>,
}

impl Curve {
    /// A curve from at least two finite samples.
    pub fn sampled(name: &str, samples: &[f64]) -> Result<Curve, RecipeError> {
        if samples.len() < 2 {
            return Err(RecipeError::CurveTooShort {
                name: name.to_owned(),
                count: samples.len(),
            });
        }
        let bits = samples
            .iter()
            .map(|&s| Factor::new(s).map(|f| f.0))
            .collect::<Result<Arc<[u64]>, _>>()
            .map_err(|_| RecipeError::NotFinite {
                what: "a curve sample",
                value: format!("in curve `{name}`"),
            })?;
        Ok(Curve {
            name: name.into(),
            samples: bits,
        })
    }

    /// The curve's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// Always false: a curve has at least two samples.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The value at `x` (clamped to [0, 1]).
    pub fn eval(&self, x: f64) -> f64 {
        let last = self.samples.len() - 1;
        let t = x.clamp(0.0, 1.0) * last as f64;
        let i = (t.floor() as usize).min(last - 1);
        let frac = t - i as f64;
        let a = f64::from_bits(self.samples[i]);
        let b = f64::from_bits(self.samples[i + 1]);
        if frac == 0.0 {
            a
        } else {
            a + (b - a) * frac
        }
    }
}

impl fmt::Debug for Curve {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Curve({:?}, {} samples)", self.name, self.samples.len())
    }
}

/// One channel of one image, decoded to a linear value with a transfer function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Texel {
    /// The image read.
    pub image: ImageId,
    /// The channel read.
    pub channel: Channel,
    /// How its codes decode.
    pub transfer: Transfer,
}

/// A linear value computed per output texel. Build it with the constructors, which keep it
/// canonical.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Value {
    /// A constant.
    Const(Factor),
    /// A texel of an image. Images of another size than the recipe's base are sampled
    /// bilinearly (in linear values) at the base's texel centres, clamped to the edge.
    Texel(Texel),
    /// The product of the terms: the constant (if any) first, then the rest in order.
    Product(Vec<Value>),
    /// The largest of the terms.
    Max(Vec<Value>),
    /// `num / den`, or `if_zero` where `den` is 0.
    Ratio {
        /// Numerator.
        num: Box<Value>,
        /// Denominator.
        den: Box<Value>,
        /// The result where the denominator is 0.
        if_zero: Factor,
    },
    /// A curve applied to a value.
    Curve(Curve, Box<Value>),
}

impl Value {
    /// A texel of `image`'s `channel`, decoded with `transfer`.
    pub fn texel(image: ImageId, channel: Channel, transfer: Transfer) -> Value {
        Value::Texel(Texel {
            image,
            channel,
            transfer,
        })
    }

    /// A constant.
    pub fn constant(value: f64) -> Result<Value, RecipeError> {
        Ok(Value::Const(Factor::new(value)?))
    }

    /// `factor × value`.
    pub fn scaled(value: Value, factor: Factor) -> Value {
        Value::product(vec![Value::Const(factor), value]).expect("two operands")
    }

    /// The product of `terms`: nested products are flattened, constants multiplied into one
    /// (dropped when 1, the whole product is 0 when 0), the other terms sorted.
    pub fn product(terms: Vec<Value>) -> Result<Value, RecipeError> {
        if terms.is_empty() {
            return Err(RecipeError::Empty("a product"));
        }
        let mut constant = 1.0f64;
        let mut rest = Vec::new();
        let mut stack = terms;
        while let Some(term) = stack.pop() {
            match term {
                Value::Const(k) => constant *= k.get(),
                Value::Product(inner) => stack.extend(inner),
                other => rest.push(other),
            }
        }
        let constant = Factor::new(constant)?;
        if constant == Factor::ZERO || rest.is_empty() {
            return Ok(Value::Const(constant));
        }
        rest.sort();
        if constant != Factor::ONE {
            rest.insert(0, Value::Const(constant));
        }
        Ok(if rest.len() == 1 {
            rest.pop().expect("one term")
        } else {
            Value::Product(rest)
        })
    }

    /// The largest of `terms` (nested maxima flattened, duplicates removed, sorted).
    pub fn max(terms: Vec<Value>) -> Result<Value, RecipeError> {
        let mut flat = Vec::new();
        let mut stack = terms;
        while let Some(term) = stack.pop() {
            match term {
                Value::Max(inner) => stack.extend(inner),
                other => flat.push(other),
            }
        }
        flat.sort();
        flat.dedup();
        match flat.len() {
            0 => Err(RecipeError::Empty("a maximum")),
            1 => Ok(flat.pop().expect("one term")),
            _ => Ok(Value::Max(flat)),
        }
    }

    /// `num / den`, or `if_zero` where `den` is 0.
    pub fn ratio(num: Value, den: Value, if_zero: Factor) -> Value {
        Value::Ratio {
            num: Box::new(num),
            den: Box::new(den),
            if_zero,
        }
    }

    /// `curve(value)`.
    pub fn curve(curve: Curve, value: Value) -> Value {
        Value::Curve(curve, Box::new(value))
    }

    /// Every texel the value reads, in order of first appearance.
    pub fn texels(&self) -> Vec<Texel> {
        let mut out = Vec::new();
        self.collect_texels(&mut out);
        out
    }

    fn collect_texels(&self, out: &mut Vec<Texel>) {
        match self {
            Value::Const(_) => {}
            Value::Texel(t) => {
                if !out.contains(t) {
                    out.push(*t)
                }
            }
            Value::Product(terms) | Value::Max(terms) => {
                terms.iter().for_each(|t| t.collect_texels(out))
            }
            Value::Ratio { num, den, .. } => {
                num.collect_texels(out);
                den.collect_texels(out);
            }
            Value::Curve(_, v) => v.collect_texels(out),
        }
    }

    /// Evaluates the value with `texel` giving each texel's linear value.
    pub fn eval(&self, texel: &mut impl FnMut(&Texel) -> f64) -> f64 {
        match self {
            Value::Const(k) => k.get(),
            Value::Texel(t) => texel(t),
            Value::Product(terms) => terms.iter().fold(1.0, |acc, t| acc * t.eval(texel)),
            Value::Max(terms) => terms
                .iter()
                .map(|t| t.eval(texel))
                .fold(f64::NEG_INFINITY, f64::max),
            Value::Ratio { num, den, if_zero } => {
                let d = den.eval(texel);
                if d == 0.0 {
                    if_zero.get()
                } else {
                    num.eval(texel) / d
                }
            }
            Value::Curve(c, v) => c.eval(v.eval(texel)),
        }
    }

    /// Every constant factor in the value (for range checks).
    pub fn factors(&self) -> Vec<f64> {
        let mut out = Vec::new();
        self.collect_factors(&mut out);
        out
    }

    fn collect_factors(&self, out: &mut Vec<f64>) {
        match self {
            Value::Const(k) => out.push(k.get()),
            Value::Texel(_) => {}
            Value::Product(terms) | Value::Max(terms) => {
                terms.iter().for_each(|t| t.collect_factors(out))
            }
            Value::Ratio { num, den, if_zero } => {
                num.collect_factors(out);
                den.collect_factors(out);
                out.push(if_zero.get());
            }
            Value::Curve(_, v) => v.collect_factors(out),
        }
    }
}

/// What one output channel holds.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ChannelRecipe {
    /// A channel's codes, unchanged (bit-exact at equal depth; an 8-bit code c becomes 257·c in
    /// a 16-bit output, the same value).
    Copy(ImageId, Channel),
    /// A linear value, clamped to [0, 1] and encoded with `transfer` to the nearest code.
    Computed {
        /// The value.
        value: Value,
        /// The output channel's transfer function.
        transfer: Transfer,
    },
}

impl ChannelRecipe {
    /// A computed channel; `texel` re-encoded with its own transfer is the copy it equals.
    pub fn computed(value: Value, transfer: Transfer) -> ChannelRecipe {
        match value {
            Value::Texel(t) if t.transfer == transfer => ChannelRecipe::Copy(t.image, t.channel),
            value => ChannelRecipe::Computed { value, transfer },
        }
    }

    /// The images the channel reads.
    pub fn images(&self) -> Vec<ImageId> {
        match self {
            ChannelRecipe::Copy(image, _) => vec![*image],
            ChannelRecipe::Computed { value, .. } => {
                value.texels().into_iter().map(|t| t.image).collect()
            }
        }
    }
}

/// The channel layout of an output image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum OutputLayout {
    /// The base's layout, widened to colour when red, green and blue differ and to alpha when
    /// alpha is set.
    Auto,
    /// Exactly this layout; a grey output holds the red recipe.
    Fixed(super::pixels::Layout),
}

/// What one output image holds. Build with [`Recipe::new`] and [`Recipe::with`].
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Recipe {
    base: ImageId,
    layout: OutputLayout,
    channels: [Option<ChannelRecipe>; 4],
}

impl Recipe {
    /// A recipe that copies `base` as it is (each channel may then be replaced).
    pub fn new(base: ImageId) -> Recipe {
        Recipe {
            base,
            layout: OutputLayout::Auto,
            channels: [None, None, None, None],
        }
    }

    /// Replaces what `channel` holds. A copy of the base's own channel is the same as no
    /// replacement and is stored as none.
    pub fn with(mut self, channel: Channel, recipe: ChannelRecipe) -> Recipe {
        self.channels[channel as usize] = match recipe {
            ChannelRecipe::Copy(image, c) if image == self.base && c == channel => None,
            other => Some(other),
        };
        self
    }

    /// Fixes the output layout.
    pub fn with_layout(mut self, layout: OutputLayout) -> Recipe {
        self.layout = layout;
        self
    }

    /// The image whose size, layout and format the output keeps.
    pub fn base(&self) -> ImageId {
        self.base
    }

    /// The output layout rule.
    pub fn layout(&self) -> OutputLayout {
        self.layout
    }

    /// What `channel` holds: `None` means the base's channel copied.
    pub fn channel(&self, channel: Channel) -> Option<&ChannelRecipe> {
        self.channels[channel as usize].as_ref()
    }

    /// What `channel` holds, with the base's copy spelled out.
    pub fn resolved(&self, channel: Channel) -> ChannelRecipe {
        self.channel(channel)
            .cloned()
            .unwrap_or(ChannelRecipe::Copy(self.base, channel))
    }

    /// Whether the output would be the base unchanged.
    pub fn is_identity(&self) -> bool {
        self.layout == OutputLayout::Auto && self.channels.iter().all(Option::is_none)
    }

    /// Every image the recipe reads, base first, each once.
    pub fn images(&self) -> Vec<ImageId> {
        let mut out = vec![self.base];
        for c in self.channels.iter().flatten() {
            for image in c.images() {
                if !out.contains(&image) {
                    out.push(image);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tex(i: usize, c: Channel) -> Value {
        Value::texel(ImageId(i), c, Transfer::Srgb)
    }

    #[test]
    fn factor_refuses_nan_and_infinity_and_stores_minus_zero_as_zero() {
        assert!(Factor::new(f64::NAN).is_err());
        assert!(Factor::new(f64::INFINITY).is_err());
        assert_eq!(Factor::new(-0.0).unwrap(), Factor::ZERO);
        assert_eq!(Factor::new(1.0).unwrap(), Factor::ONE);
        assert_eq!(Factor::new(0.25).unwrap().get(), 0.25);
    }

    #[test]
    fn products_are_canonical() {
        let k = Factor::new(0.5).unwrap();
        let a = Value::product(vec![
            tex(1, Channel::R),
            Value::Const(k),
            tex(0, Channel::G),
        ]);
        let b = Value::product(vec![
            tex(0, Channel::G),
            tex(1, Channel::R),
            Value::Const(k),
        ]);
        assert_eq!(a, b);
        assert_eq!(
            a.unwrap(),
            Value::Product(vec![
                Value::Const(k),
                tex(0, Channel::G),
                tex(1, Channel::R)
            ])
        );
        assert_eq!(
            Value::scaled(tex(0, Channel::R), Factor::ONE),
            tex(0, Channel::R)
        );
        assert_eq!(
            Value::scaled(tex(0, Channel::R), Factor::ZERO),
            Value::Const(Factor::ZERO)
        );
        let nested = Value::product(vec![
            Value::scaled(tex(0, Channel::R), Factor::new(2.0).unwrap()),
            Value::Const(Factor::new(0.25).unwrap()),
        ])
        .unwrap();
        assert_eq!(nested, Value::scaled(tex(0, Channel::R), k));
    }

    #[test]
    fn a_texel_re_encoded_with_its_own_transfer_is_a_copy() {
        assert_eq!(
            ChannelRecipe::computed(tex(3, Channel::G), Transfer::Srgb),
            ChannelRecipe::Copy(ImageId(3), Channel::G)
        );
        assert!(matches!(
            ChannelRecipe::computed(tex(3, Channel::G), Transfer::Linear),
            ChannelRecipe::Computed { .. }
        ));
    }

    #[test]
    fn a_recipe_copying_its_base_is_the_identity_and_equal_recipes_hash_equal() {
        use std::collections::HashSet;
        let r =
            Recipe::new(ImageId(0)).with(Channel::A, ChannelRecipe::Copy(ImageId(0), Channel::A));
        assert!(r.is_identity());
        let k = Factor::new(0.5).unwrap();
        let make = || {
            Recipe::new(ImageId(0)).with(
                Channel::R,
                ChannelRecipe::computed(Value::scaled(tex(0, Channel::R), k), Transfer::Srgb),
            )
        };
        let set: HashSet<Recipe> = [make(), make()].into_iter().collect();
        assert_eq!(set.len(), 1);
        assert_eq!(make().images(), vec![ImageId(0)]);
    }

    #[test]
    fn curves_interpolate_clamp_and_compare_by_name_and_samples() {
        let c = Curve::sampled("square-ish", &[0.0, 0.25, 1.0]).unwrap();
        assert_eq!(c.eval(0.0), 0.0);
        assert_eq!(c.eval(0.5), 0.25);
        assert_eq!(c.eval(0.75), 0.625);
        assert_eq!(c.eval(1.0), 1.0);
        assert_eq!(c.eval(2.0), 1.0);
        assert_eq!(c.eval(-1.0), 0.0);
        assert_eq!(c, Curve::sampled("square-ish", &[0.0, 0.25, 1.0]).unwrap());
        assert_ne!(c, Curve::sampled("other", &[0.0, 0.25, 1.0]).unwrap());
        assert!(Curve::sampled("short", &[0.0]).is_err());
        assert!(Curve::sampled("nan", &[0.0, f64::NAN]).is_err());
    }

    #[test]
    fn max_and_ratio_evaluate_as_written() {
        let v = Value::ratio(
            tex(0, Channel::R),
            Value::max(vec![tex(0, Channel::R), tex(0, Channel::G)]).unwrap(),
            Factor::ONE,
        );
        let at =
            |r: f64, g: f64| v.eval(&mut |t: &Texel| if t.channel == Channel::R { r } else { g });
        assert_eq!(at(0.25, 0.5), 0.5);
        assert_eq!(at(0.5, 0.25), 1.0);
        assert_eq!(at(0.0, 0.0), 1.0);
    }
}
