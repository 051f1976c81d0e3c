//! Image codecs for baking: decodes PNG, JPEG and WebP (recognised by the asset module's
//! signature check) into [`Pixels`] (through the `image` crate) and encodes PNG at the pixels'
//! depth, lossless WebP, or JPEG. KTX2 (KHR_texture_basisu) is recognised and refused: its
//! payload is GPU block-compressed and supercompressed, and baking it would mean transcoding and
//! re-encoding, which would change texels the recipe does not touch.
//!
//! What decoding keeps: 8- and 16-bit PNG at their depth; PNG of 1, 2 or 4 bits and palette PNG
//! become 8-bit (grey, or RGB/RGBA when the palette has transparency); a tRNS colour key becomes
//! an alpha channel. JPEG decodes to 8-bit grey or RGB, WebP to 8-bit RGB or RGBA. Colour
//! profiles and gamma chunks are not applied: glTF defines the transfer function per slot.

use std::io::Cursor;

use image::codecs::jpeg::JpegEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::codecs::webp::WebPEncoder;
use image::{DynamicImage, ExtendedColorType, ImageDecoder, ImageEncoder, ImageReader, Limits};

use super::pixels::{Depth, Layout, Pixels, Samples};

/// The container formats, recognised by the asset module from an image's first bytes.
pub use crate::asset::resource::ImageFormat;

/// A format's name for messages.
pub fn format_name(format: ImageFormat) -> &'static str {
    match format {
        ImageFormat::Png => "PNG",
        ImageFormat::Jpeg => "JPEG",
        ImageFormat::Webp => "WebP",
        ImageFormat::Ktx2 => "KTX2",
    }
}

/// The format an output image is written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OutputFormat {
    /// PNG at the pixels' depth.
    Png,
    /// Baseline JPEG (only with `keep_format` for JPEG sources).
    Jpeg,
    /// Lossless WebP.
    WebpLossless,
}

impl OutputFormat {
    /// The glTF `mimeType`.
    pub fn mime_type(self) -> &'static str {
        match self {
            OutputFormat::Png => "image/png",
            OutputFormat::Jpeg => "image/jpeg",
            OutputFormat::WebpLossless => "image/webp",
        }
    }

    /// The file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            OutputFormat::Png => "png",
            OutputFormat::Jpeg => "jpg",
            OutputFormat::WebpLossless => "webp",
        }
    }
}

/// PNG compression effort. Fast (fdeflate) is the default: on 2048² textures it encodes about
/// 20× faster than the balanced zlib level, for files a few percent larger.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PngCompression {
    /// Quick and a little larger (the default).
    #[default]
    Fast,
    /// zlib's default level.
    Default,
    /// zlib's best level: slow and smallest.
    Best,
}

/// How outputs are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EncodeOptions {
    /// PNG compression effort.
    pub png: PngCompression,
    /// JPEG quality (1–100) when a JPEG is kept as JPEG.
    pub jpeg_quality: u8,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions {
            png: PngCompression::Fast,
            jpeg_quality: 95,
        }
    }
}

/// Why an image could not be decoded or encoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CodecError {
    /// Not a PNG, JPEG, WebP or KTX2 stream.
    #[error("not a PNG, JPEG, WebP or KTX2 image (starts with {0})")]
    Unrecognised(String),
    /// A format velvet recognises but does not bake.
    #[error("{format} images cannot be baked: {reason}")]
    Unsupported {
        /// The format.
        format: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// The stream is damaged or uses a feature the decoder lacks.
    #[error("cannot decode the {format} image: {message}")]
    Decode {
        /// The format.
        format: &'static str,
        /// The decoder's message.
        message: String,
    },
    /// The header declares more pixels than the limit; nothing was decoded.
    #[error("{format}: {message}")]
    TooLarge {
        /// The format.
        format: &'static str,
        /// What the header declares and the limit, with the flag that raises it.
        message: String,
    },
    /// The encoder failed.
    #[error("cannot encode a {format} image: {message}")]
    Encode {
        /// The format.
        format: &'static str,
        /// The encoder's message.
        message: String,
    },
}

/// Why KTX2 is refused, for messages and reports.
pub const KTX2_REASON: &str = "KTX2 / Basis Universal data is GPU block-compressed; baking it \
     would need transcoding and lossy re-encoding, so the slot is left as it is";

/// Decodes an image (PNG, JPEG or WebP) to pixels under the default pixel limit; KTX2 and
/// unknown data are refused.
pub fn decode(bytes: &[u8]) -> Result<(Pixels, ImageFormat), CodecError> {
    decode_limited(bytes, crate::asset::limits::DEFAULT_MAX_IMAGE_PIXELS)
}

/// Decodes an image whose header declares at most `max_pixels` pixels. The header is read
/// first and a larger image refused before any pixel buffer exists: a 100000 × 100000 PNG of
/// a few hundred bytes would otherwise ask for 40 GB.
pub fn decode_limited(bytes: &[u8], max_pixels: u64) -> Result<(Pixels, ImageFormat), CodecError> {
    decode_within(bytes, max_pixels, u64::MAX)
}

/// How many copies of a decoded image a bake holds at its peak: the decoder's buffer, velvet's
/// pixels made of it, and an output of the same size (measured: a 16-bit RGBA 16384² image of
/// 2 GiB took 6.3 GB to bake).
pub const DECODE_COPIES: u64 = 3;

/// Decodes as [`decode_limited`] does, and refuses, before anything is decoded, an image whose
/// decoding would need more than `max_memory` bytes: its width × height × bytes a pixel (from
/// the header's colour type) × [`DECODE_COPIES`].
pub fn decode_within(
    bytes: &[u8],
    max_pixels: u64,
    max_memory: u64,
) -> Result<(Pixels, ImageFormat), CodecError> {
    let format = ImageFormat::sniff(bytes).ok_or_else(|| {
        let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
        CodecError::Unrecognised(if head.is_empty() {
            "no bytes".to_owned()
        } else {
            head.join(" ")
        })
    })?;
    let image_format = match format {
        ImageFormat::Png => image::ImageFormat::Png,
        ImageFormat::Jpeg => image::ImageFormat::Jpeg,
        ImageFormat::Webp => image::ImageFormat::WebP,
        ImageFormat::Ktx2 => {
            return Err(CodecError::Unsupported {
                format: "KTX2",
                reason: KTX2_REASON,
            })
        }
    };
    let decode_error = |e: image::ImageError| CodecError::Decode {
        format: format_name(format),
        message: e.to_string(),
    };
    let (width, height) = ImageReader::with_format(Cursor::new(bytes), image_format)
        .into_dimensions()
        .map_err(decode_error)?;
    if let Some(message) = crate::asset::limits::image_too_large(width, height, max_pixels) {
        return Err(CodecError::TooLarge {
            format: format_name(format),
            message,
        });
    }
    let reader = ImageReader::with_format(
        crate::asset::limits::StoppableReader(Cursor::new(bytes)),
        image_format,
    );
    let mut decoder = reader.into_decoder().map_err(decode_error)?;
    let needed = u64::from(width)
        .saturating_mul(u64::from(height))
        .saturating_mul(u64::from(decoder.color_type().bytes_per_pixel()))
        .saturating_mul(DECODE_COPIES);
    let what = format!(
        "decoding the {width} × {height} image ({} bytes a pixel)",
        decoder.color_type().bytes_per_pixel()
    );
    // Held against the budget with every other decode of the run until this one returns.
    let _reserved =
        crate::asset::limits::reserve(&what, needed, max_memory).map_err(|message| {
            CodecError::TooLarge {
                format: format_name(format),
                message: format!("{message}; it was not decoded"),
            }
        })?;
    // Within the pixel limit, the allocation limit stops what the header did not tell (a
    // decoder's own buffers) from growing past what such an image needs.
    let mut limits = Limits::default();
    limits.max_alloc = Some(crate::asset::limits::max_decode_bytes(max_pixels));
    decoder.set_limits(limits).map_err(decode_error)?;
    let image = DynamicImage::from_decoder(decoder).map_err(decode_error)?;
    let (w, h) = (image.width(), image.height());
    let (layout, samples) = match image {
        DynamicImage::ImageLuma8(b) => (Layout::Grey, Samples::U8(b.into_raw())),
        DynamicImage::ImageLumaA8(b) => (Layout::GreyAlpha, Samples::U8(b.into_raw())),
        DynamicImage::ImageRgb8(b) => (Layout::Rgb, Samples::U8(b.into_raw())),
        DynamicImage::ImageRgba8(b) => (Layout::Rgba, Samples::U8(b.into_raw())),
        DynamicImage::ImageLuma16(b) => (Layout::Grey, Samples::U16(b.into_raw())),
        DynamicImage::ImageLumaA16(b) => (Layout::GreyAlpha, Samples::U16(b.into_raw())),
        DynamicImage::ImageRgb16(b) => (Layout::Rgb, Samples::U16(b.into_raw())),
        DynamicImage::ImageRgba16(b) => (Layout::Rgba, Samples::U16(b.into_raw())),
        other => {
            return Err(CodecError::Decode {
                format: format_name(format),
                message: format!("unexpected sample type {:?}", other.color()),
            })
        }
    };
    let pixels = Pixels::new(w, h, layout, samples).map_err(|e| CodecError::Decode {
        format: format_name(format),
        message: e.to_string(),
    })?;
    Ok((pixels, format))
}

/// The format an output takes for a source format: PNG stays PNG, WebP becomes lossless WebP,
/// JPEG becomes PNG (lossless) unless `keep_format`. A format that cannot hold the pixels
/// (16-bit in WebP or JPEG, alpha in JPEG) falls back to PNG.
pub fn output_format(
    source: ImageFormat,
    keep_format: bool,
    layout: Layout,
    depth: Depth,
) -> OutputFormat {
    let wanted = match source {
        ImageFormat::Webp => OutputFormat::WebpLossless,
        ImageFormat::Jpeg if keep_format => OutputFormat::Jpeg,
        _ => OutputFormat::Png,
    };
    match wanted {
        OutputFormat::WebpLossless if depth == Depth::Eight => wanted,
        OutputFormat::Jpeg if depth == Depth::Eight && !layout.has_alpha() => wanted,
        _ => OutputFormat::Png,
    }
}

fn color_type(layout: Layout, depth: Depth) -> ExtendedColorType {
    match (layout, depth) {
        (Layout::Grey, Depth::Eight) => ExtendedColorType::L8,
        (Layout::GreyAlpha, Depth::Eight) => ExtendedColorType::La8,
        (Layout::Rgb, Depth::Eight) => ExtendedColorType::Rgb8,
        (Layout::Rgba, Depth::Eight) => ExtendedColorType::Rgba8,
        (Layout::Grey, Depth::Sixteen) => ExtendedColorType::L16,
        (Layout::GreyAlpha, Depth::Sixteen) => ExtendedColorType::La16,
        (Layout::Rgb, Depth::Sixteen) => ExtendedColorType::Rgb16,
        (Layout::Rgba, Depth::Sixteen) => ExtendedColorType::Rgba16,
    }
}

/// Encodes pixels. PNG keeps the pixels' depth; WebP and JPEG need 8-bit pixels and JPEG no
/// alpha (see [`output_format`]).
pub fn encode(
    pixels: &Pixels,
    format: OutputFormat,
    options: EncodeOptions,
) -> Result<Vec<u8>, CodecError> {
    let name = match format {
        OutputFormat::Png => "PNG",
        OutputFormat::Jpeg => "JPEG",
        OutputFormat::WebpLossless => "WebP",
    };
    let encode_error = |e: image::ImageError| CodecError::Encode {
        format: name,
        message: e.to_string(),
    };
    let ct = color_type(pixels.layout(), pixels.depth());
    let (w, h) = (pixels.width(), pixels.height());
    // 16-bit codes go to the encoders as native-endian bytes.
    let wide;
    let bytes: &[u8] = match pixels.samples() {
        Samples::U8(v) => v,
        Samples::U16(v) => {
            wide = v.iter().flat_map(|c| c.to_ne_bytes()).collect::<Vec<u8>>();
            &wide
        }
    };
    let mut bytes_out = Vec::new();
    let mut out = crate::asset::limits::StoppableWriter(&mut bytes_out);
    match format {
        OutputFormat::Png => {
            let compression = match options.png {
                PngCompression::Fast => CompressionType::Fast,
                PngCompression::Default => CompressionType::Default,
                PngCompression::Best => CompressionType::Best,
            };
            PngEncoder::new_with_quality(&mut out, compression, FilterType::Adaptive)
                .write_image(bytes, w, h, ct)
                .map_err(encode_error)?;
        }
        OutputFormat::WebpLossless => {
            WebPEncoder::new_lossless(&mut out)
                .encode(bytes, w, h, ct)
                .map_err(encode_error)?;
        }
        OutputFormat::Jpeg => {
            JpegEncoder::new_with_quality(&mut out, options.jpeg_quality)
                .write_image(bytes, w, h, ct)
                .map_err(encode_error)?;
        }
    }
    Ok(bytes_out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bake::recipe::Channel;

    fn fixture(name: &str) -> Pixels {
        let path = format!("{}/fixtures/bake/{name}", env!("CARGO_MANIFEST_DIR"));
        let bytes = std::fs::read(&path).unwrap();
        let (pixels, format) = decode(&bytes).unwrap();
        assert_eq!(format, ImageFormat::Png);
        pixels
    }

    fn codes(p: &Pixels) -> Vec<u32> {
        (0..p.samples().len())
            .map(|i| p.samples().code(i))
            .collect()
    }

    fn sample_image(layout: Layout, depth: Depth) -> Pixels {
        let n = 5 * 3 * layout.channels();
        let samples = match depth {
            Depth::Eight => Samples::U8((0..n).map(|i| (i * 37 % 256) as u8).collect()),
            Depth::Sixteen => Samples::U16((0..n).map(|i| (i * 7919 % 65536) as u16).collect()),
        };
        Pixels::new(5, 3, layout, samples).unwrap()
    }

    const LAYOUTS: [Layout; 4] = [Layout::Grey, Layout::GreyAlpha, Layout::Rgb, Layout::Rgba];

    #[test]
    fn png_round_trips_every_layout_at_8_and_16_bits() {
        for layout in LAYOUTS {
            for depth in [Depth::Eight, Depth::Sixteen] {
                let image = sample_image(layout, depth);
                for png in [
                    PngCompression::Fast,
                    PngCompression::Default,
                    PngCompression::Best,
                ] {
                    let options = EncodeOptions {
                        png,
                        ..EncodeOptions::default()
                    };
                    let bytes = encode(&image, OutputFormat::Png, options).unwrap();
                    let (back, format) = decode(&bytes).unwrap();
                    assert_eq!(format, ImageFormat::Png);
                    assert_eq!(back, image, "{layout:?} {depth:?} {png:?}");
                }
            }
        }
    }

    #[test]
    fn lossless_webp_round_trips_8_bit_images() {
        for layout in [Layout::Rgb, Layout::Rgba] {
            let image = sample_image(layout, Depth::Eight);
            let bytes =
                encode(&image, OutputFormat::WebpLossless, EncodeOptions::default()).unwrap();
            assert_eq!(ImageFormat::sniff(&bytes), Some(ImageFormat::Webp));
            let (back, _) = decode(&bytes).unwrap();
            assert_eq!(back, image, "{layout:?}");
        }
    }

    #[test]
    fn jpeg_decodes_to_8_bit_rgb_or_grey() {
        for layout in [Layout::Grey, Layout::Rgb] {
            let image =
                Pixels::new(8, 8, layout, Samples::U8(vec![90; 64 * layout.channels()])).unwrap();
            let bytes = encode(&image, OutputFormat::Jpeg, EncodeOptions::default()).unwrap();
            let (back, format) = decode(&bytes).unwrap();
            assert_eq!(format, ImageFormat::Jpeg);
            assert_eq!((back.layout(), back.depth()), (layout, Depth::Eight));
            // A flat block survives JPEG to within a code.
            assert!(
                codes(&back).iter().all(|&c| c.abs_diff(90) <= 1),
                "{layout:?}"
            );
        }
    }

    #[test]
    fn palette_png_expands_to_rgb_or_rgba_with_its_transparency() {
        let p = fixture("palette_trns.png");
        assert_eq!((p.layout(), p.depth()), (Layout::Rgba, Depth::Eight));
        assert_eq!(
            codes(&p),
            vec![255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 255]
        );
        let p = fixture("palette_2bit.png");
        assert_eq!(p.layout(), Layout::Rgb);
        assert_eq!(
            codes(&p),
            vec![10, 20, 30, 40, 50, 60, 70, 80, 90, 40, 50, 60]
        );
    }

    #[test]
    fn low_bit_grey_png_scales_to_8_bits_and_a_colour_key_becomes_alpha() {
        let p = fixture("grey_1bit.png");
        assert_eq!((p.layout(), p.depth()), (Layout::Grey, Depth::Eight));
        assert_eq!(codes(&p), vec![255, 0, 255, 255, 0, 0, 0, 0]);
        let p = fixture("grey_4bit.png");
        assert_eq!(codes(&p), vec![0x33, 0xff]);
        let p = fixture("grey_trns.png");
        assert_eq!(p.layout(), Layout::GreyAlpha);
        assert_eq!(codes(&p), vec![0, 0, 100, 255]);
        assert_eq!(p.code(1, 0, Channel::A), 255);
    }

    #[test]
    fn ktx2_is_recognised_and_refused_with_its_reason() {
        let mut bytes = b"\xabKTX 20\xbb\r\n\x1a\n".to_vec();
        bytes.extend([0; 64]);
        assert_eq!(ImageFormat::sniff(&bytes), Some(ImageFormat::Ktx2));
        let err = decode(&bytes).unwrap_err();
        assert_eq!(
            err,
            CodecError::Unsupported {
                format: "KTX2",
                reason: KTX2_REASON
            }
        );
        assert!(err.to_string().starts_with("KTX2 images cannot be baked: "));
    }

    #[test]
    fn unknown_and_damaged_data_are_errors_not_panics() {
        assert_eq!(
            decode(b"GIF89a..").unwrap_err(),
            CodecError::Unrecognised("47 49 46 38 39 61 2e 2e".into())
        );
        assert_eq!(
            decode(b"").unwrap_err(),
            CodecError::Unrecognised("no bytes".into())
        );
        let image = sample_image(Layout::Rgba, Depth::Eight);
        let bytes = encode(&image, OutputFormat::Png, EncodeOptions::default()).unwrap();
        let err = decode(&bytes[..bytes.len() / 2]).unwrap_err();
        assert!(
            matches!(err, CodecError::Decode { format: "PNG", .. }),
            "{err:?}"
        );
    }

    #[test]
    fn output_formats_follow_the_source_unless_the_pixels_do_not_fit() {
        use OutputFormat::*;
        let f = output_format;
        assert_eq!(
            f(ImageFormat::Png, false, Layout::Rgba, Depth::Sixteen),
            Png
        );
        assert_eq!(f(ImageFormat::Jpeg, false, Layout::Rgb, Depth::Eight), Png);
        assert_eq!(f(ImageFormat::Jpeg, true, Layout::Rgb, Depth::Eight), Jpeg);
        assert_eq!(f(ImageFormat::Jpeg, true, Layout::Rgba, Depth::Eight), Png);
        assert_eq!(
            f(ImageFormat::Webp, false, Layout::Rgba, Depth::Eight),
            WebpLossless
        );
        assert_eq!(
            f(ImageFormat::Webp, false, Layout::Rgba, Depth::Sixteen),
            Png
        );
        assert_eq!(
            (Png.mime_type(), WebpLossless.extension()),
            ("image/png", "webp")
        );
    }
}
