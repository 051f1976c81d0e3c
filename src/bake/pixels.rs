//! Decoded images as the kernel sees them: a size, a channel layout (grey, grey+alpha, RGB,
//! RGBA), and 8- or 16-bit codes stored interleaved, row by row, alpha never premultiplied.
//!
//! Channels are addressed the way glTF samples them: red, green and blue of a grey image all
//! read its one grey channel, and the alpha of an image without alpha reads as opaque.

use super::recipe::Channel;

/// How many channels an image has and what they mean.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Layout {
    /// One grey channel.
    Grey,
    /// Grey then alpha.
    GreyAlpha,
    /// Red, green, blue.
    Rgb,
    /// Red, green, blue, alpha.
    Rgba,
}

impl Layout {
    /// Channels stored per pixel.
    pub fn channels(self) -> usize {
        match self {
            Layout::Grey => 1,
            Layout::GreyAlpha => 2,
            Layout::Rgb => 3,
            Layout::Rgba => 4,
        }
    }

    /// Whether the layout stores an alpha channel.
    pub fn has_alpha(self) -> bool {
        matches!(self, Layout::GreyAlpha | Layout::Rgba)
    }

    /// Whether the layout stores separate red, green and blue channels.
    pub fn has_colour(self) -> bool {
        matches!(self, Layout::Rgb | Layout::Rgba)
    }

    /// The layout with the given colour and alpha capabilities.
    pub fn from_parts(colour: bool, alpha: bool) -> Layout {
        match (colour, alpha) {
            (false, false) => Layout::Grey,
            (false, true) => Layout::GreyAlpha,
            (true, false) => Layout::Rgb,
            (true, true) => Layout::Rgba,
        }
    }

    /// Where a glTF channel is stored in a pixel, or `None` for the alpha of a layout without
    /// alpha (which reads as opaque).
    pub fn storage_index(self, channel: Channel) -> Option<usize> {
        match (self, channel) {
            (Layout::Grey | Layout::GreyAlpha, Channel::R | Channel::G | Channel::B) => Some(0),
            (Layout::GreyAlpha, Channel::A) => Some(1),
            (Layout::Rgb | Layout::Rgba, c @ (Channel::R | Channel::G | Channel::B)) => {
                Some(c as usize)
            }
            (Layout::Rgba, Channel::A) => Some(3),
            (Layout::Grey | Layout::Rgb, Channel::A) => None,
        }
    }

    /// The glTF channel that each stored channel holds (grey is read as red).
    pub fn stored_channels(self) -> &'static [Channel] {
        match self {
            Layout::Grey => &[Channel::R],
            Layout::GreyAlpha => &[Channel::R, Channel::A],
            Layout::Rgb => &[Channel::R, Channel::G, Channel::B],
            Layout::Rgba => &[Channel::R, Channel::G, Channel::B, Channel::A],
        }
    }
}

/// Bits per channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Depth {
    /// Codes 0..=255.
    Eight,
    /// Codes 0..=65535.
    Sixteen,
}

impl Depth {
    /// The largest code.
    pub fn max_code(self) -> u32 {
        match self {
            Depth::Eight => 255,
            Depth::Sixteen => 65535,
        }
    }

    /// Bits per channel as a number.
    pub fn bits(self) -> u32 {
        match self {
            Depth::Eight => 8,
            Depth::Sixteen => 16,
        }
    }
}

/// The codes of an image, interleaved per pixel.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Samples {
    /// 8-bit codes.
    U8(Vec<u8>),
    /// 16-bit codes.
    U16(Vec<u16>),
}

impl Samples {
    /// Number of codes stored.
    pub fn len(&self) -> usize {
        match self {
            Samples::U8(v) => v.len(),
            Samples::U16(v) => v.len(),
        }
    }

    /// Whether no code is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The depth of the codes.
    pub fn depth(&self) -> Depth {
        match self {
            Samples::U8(_) => Depth::Eight,
            Samples::U16(_) => Depth::Sixteen,
        }
    }

    /// The code at a flat index, widened.
    pub fn code(&self, index: usize) -> u32 {
        match self {
            Samples::U8(v) => u32::from(v[index]),
            Samples::U16(v) => u32::from(v[index]),
        }
    }
}

/// A decoded image.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pixels {
    width: u32,
    height: u32,
    layout: Layout,
    samples: Samples,
}

/// A buffer whose length does not match its size and layout.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("{len} codes cannot be a {width}x{height} {layout:?} image (expected {expected})")]
pub struct SizeMismatch {
    /// Width asked for.
    pub width: u32,
    /// Height asked for.
    pub height: u32,
    /// Layout asked for.
    pub layout: Layout,
    /// Codes supplied.
    pub len: usize,
    /// Codes the size and layout need.
    pub expected: usize,
}

impl Pixels {
    /// An image from its codes; the length must be `width * height * layout.channels()`.
    pub fn new(
        width: u32,
        height: u32,
        layout: Layout,
        samples: Samples,
    ) -> Result<Pixels, SizeMismatch> {
        let expected = width as usize * height as usize * layout.channels();
        if samples.len() != expected {
            return Err(SizeMismatch {
                width,
                height,
                layout,
                len: samples.len(),
                expected,
            });
        }
        Ok(Pixels {
            width,
            height,
            layout,
            samples,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Channel layout.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Bits per channel.
    pub fn depth(&self) -> Depth {
        self.samples.depth()
    }

    /// The codes.
    pub fn samples(&self) -> &Samples {
        &self.samples
    }

    /// The codes, owned.
    pub fn into_samples(self) -> Samples {
        self.samples
    }

    /// Number of pixels.
    pub fn pixel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The code of a glTF channel at a pixel; alpha of a layout without alpha reads as opaque.
    pub fn code(&self, x: u32, y: u32, channel: Channel) -> u32 {
        match self.layout.storage_index(channel) {
            Some(s) => {
                let pixel = y as usize * self.width as usize + x as usize;
                self.samples.code(pixel * self.layout.channels() + s)
            }
            None => self.depth().max_code(),
        }
    }

    /// The codes of the first pixel when every pixel holds the same codes (one per stored
    /// channel), else `None`. An empty image has no uniform value.
    pub fn uniform(&self) -> Option<Vec<u32>> {
        fn check<T: Copy + PartialEq + Into<u32>>(codes: &[T], n: usize) -> Option<Vec<u32>> {
            let first = codes.get(..n)?;
            codes
                .chunks_exact(n)
                .all(|p| p == first)
                .then(|| first.iter().map(|&c| c.into()).collect())
        }
        let n = self.layout.channels();
        match &self.samples {
            Samples::U8(v) => check(v, n),
            Samples::U16(v) => check(v, n),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grey_channels_read_as_red_green_and_blue_and_missing_alpha_is_opaque() {
        let p = Pixels::new(2, 1, Layout::Grey, Samples::U8(vec![10, 20])).unwrap();
        assert_eq!(p.code(1, 0, Channel::R), 20);
        assert_eq!(p.code(1, 0, Channel::G), 20);
        assert_eq!(p.code(1, 0, Channel::B), 20);
        assert_eq!(p.code(1, 0, Channel::A), 255);
        let p = Pixels::new(1, 1, Layout::Rgb, Samples::U16(vec![1, 2, 3])).unwrap();
        assert_eq!(p.code(0, 0, Channel::A), 65535);
        assert_eq!(p.code(0, 0, Channel::B), 3);
    }

    #[test]
    fn a_buffer_of_the_wrong_length_is_refused() {
        let err = Pixels::new(2, 2, Layout::Rgba, Samples::U8(vec![0; 15])).unwrap_err();
        assert_eq!(err.expected, 16);
        assert_eq!(err.len, 15);
    }

    #[test]
    fn uniform_reports_the_shared_codes_or_none() {
        let p = Pixels::new(2, 1, Layout::GreyAlpha, Samples::U8(vec![7, 9, 7, 9])).unwrap();
        assert_eq!(p.uniform(), Some(vec![7, 9]));
        let p = Pixels::new(2, 1, Layout::GreyAlpha, Samples::U8(vec![7, 9, 7, 8])).unwrap();
        assert_eq!(p.uniform(), None);
        let p = Pixels::new(0, 0, Layout::Rgb, Samples::U16(vec![])).unwrap();
        assert_eq!(p.uniform(), None);
    }
}
