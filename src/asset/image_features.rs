//! What an image's header says that glTF does not support, judged as the Khronos validator's
//! IMAGE_FEATURES_UNSUPPORTED judges it: colour information other than sRGB's, pixels that are
//! not square, animation. Only header bytes are read, never pixels.
//!
//! - PNG: the chunks before the first IDAT, their CRCs unchecked. An iCCP chunk is an embedded
//!   colour profile. A gAMA chunk sets the transfer function: sRGB's (45455, gamma × 100000)
//!   and linear (100000) are supported, any other value is not; the values are compared
//!   exactly. A cHRM chunk sets the primaries: supported only when all eight of its values are
//!   sRGB's exactly. An sRGB chunk sets both to sRGB, over whatever came before it. Once the
//!   transfer function or the primaries are set (by sRGB, iCCP or an earlier gAMA or cHRM), a
//!   later gAMA or cHRM does not change them; a later iCCP does. A pHYs chunk whose pixels per
//!   unit differ on x and y is non-square pixels, whatever its unit. A gAMA, cHRM, sRGB or
//!   pHYs chunk of another length than its own (4, 32, 1, 9 bytes) is passed over, and so is
//!   an animation (APNG's acTL): the reference does not look for one.
//! - WebP: the flags of a first chunk that is VP8X: an ICC profile, animation.
//! - JPEG and KTX2: nothing.

use std::io::{Read, Seek};

/// gAMA's value for sRGB: 1 / 2.2, times 100000.
const SRGB_GAMMA: u32 = 45_455;
/// gAMA's value for a linear transfer function.
const LINEAR_GAMMA: u32 = 100_000;
/// cHRM's values for sRGB, times 100000: the white point's x and y, then red's, green's and
/// blue's.
const SRGB_CHROMATICITIES: [u32; 8] = [
    31_270, 32_900, 64_000, 33_000, 30_000, 60_000, 15_000, 6_000,
];

const PNG_SIGNATURE_LEN: u64 = 8;
/// VP8X's flag bits (its first data byte).
const VP8X_ICC_PROFILE: u8 = 0x20;
const VP8X_ANIMATION: u8 = 0x02;

/// What an image's header holds that glTF does not support; the default is none of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ImageFeatures {
    /// An embedded ICC profile in force: a PNG iCCP chunk no later sRGB chunk overrides, or a
    /// WebP's VP8X ICC flag.
    pub icc_profile: bool,
    /// A PNG gAMA value (gamma × 100000) that is neither sRGB's nor linear.
    pub gamma: Option<u32>,
    /// A PNG cHRM chunk with primaries or a white point other than sRGB's.
    pub chromaticities: bool,
    /// A PNG pHYs chunk's pixels per unit on x and y, when they differ.
    pub pixels_per_unit: Option<(u32, u32)>,
    /// A WebP's VP8X animation flag.
    pub animation: bool,
}

impl ImageFeatures {
    /// True when the header holds any of them.
    pub fn any(&self) -> bool {
        *self != ImageFeatures::default()
    }

    /// Each one the header holds, in words.
    pub fn describe(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.icc_profile {
            out.push("an embedded ICC colour profile".to_string());
        }
        if let Some(gamma) = self.gamma {
            out.push(format!(
                "a gAMA chunk of {gamma} (gamma × 100000; sRGB's is {SRGB_GAMMA}, linear {LINEAR_GAMMA})"
            ));
        }
        if self.chromaticities {
            out.push("cHRM chromaticities other than sRGB's".to_string());
        }
        if let Some((x, y)) = self.pixels_per_unit {
            out.push(format!(
                "non-square pixels (pHYs: {x} pixels a unit across, {y} down)"
            ));
        }
        if self.animation {
            out.push("animation".to_string());
        }
        out
    }
}

/// A PNG's transfer function as its chunks set it.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Transfer {
    Unset,
    /// sRGB's or linear.
    Supported,
    Profile,
    Gamma(u32),
}

/// A PNG's primaries as its chunks set them.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Primaries {
    Unset,
    Srgb,
    Profile,
    Custom,
}

/// The features of the PNG that `reader` holds from its start, from its chunks before the
/// first IDAT. Reads each chunk's length and type and, for gAMA, cHRM, sRGB and pHYs, its few
/// bytes of data; seeks past every other. Data that ends, or a read that fails, ends the walk
/// with what was found: the header's decoder reports the damage.
pub fn png<R: Read + Seek>(reader: &mut R) -> ImageFeatures {
    let mut transfer = Transfer::Unset;
    let mut primaries = Primaries::Unset;
    let mut pixels_per_unit = None;
    if reader
        .seek(std::io::SeekFrom::Start(PNG_SIGNATURE_LEN))
        .is_err()
    {
        return ImageFeatures::default();
    }
    // A chunk: its data's length (4 bytes, big-endian), its type (4), its data, a CRC (4).
    let mut head = [0u8; 8];
    let mut data = [0u8; 32];
    while reader.read_exact(&mut head).is_ok() {
        let len = u32::from_be_bytes([head[0], head[1], head[2], head[3]]);
        let kind = [head[4], head[5], head[6], head[7]];
        let own_len = match &kind {
            b"IDAT" => break,
            b"gAMA" => 4,
            b"cHRM" => 32,
            b"sRGB" => 1,
            b"pHYs" => 9,
            _ => 0,
        };
        let mut skip = i64::from(len) + 4; // the data and the CRC
        if own_len > 0 && len == own_len {
            let body = &mut data[..own_len as usize];
            if reader.read_exact(body).is_err() {
                break;
            }
            skip = 4;
            let word =
                |i: usize| u32::from_be_bytes([body[i], body[i + 1], body[i + 2], body[i + 3]]);
            match &kind {
                b"gAMA" if transfer == Transfer::Unset => {
                    transfer = match word(0) {
                        SRGB_GAMMA | LINEAR_GAMMA => Transfer::Supported,
                        gamma => Transfer::Gamma(gamma),
                    };
                }
                b"cHRM" if primaries == Primaries::Unset => {
                    let srgb = (0..8).all(|i| word(4 * i) == SRGB_CHROMATICITIES[i]);
                    primaries = if srgb {
                        Primaries::Srgb
                    } else {
                        Primaries::Custom
                    };
                }
                b"sRGB" => {
                    transfer = Transfer::Supported;
                    primaries = Primaries::Srgb;
                }
                b"pHYs" => {
                    let (x, y) = (word(0), word(4));
                    if x != y && pixels_per_unit.is_none() {
                        pixels_per_unit = Some((x, y));
                    }
                }
                _ => {}
            }
        } else if &kind == b"iCCP" {
            transfer = Transfer::Profile;
            primaries = Primaries::Profile;
        }
        if reader.seek_relative(skip).is_err() {
            break;
        }
    }
    ImageFeatures {
        icc_profile: transfer == Transfer::Profile || primaries == Primaries::Profile,
        gamma: match transfer {
            Transfer::Gamma(gamma) => Some(gamma),
            _ => None,
        },
        chromaticities: primaries == Primaries::Custom,
        pixels_per_unit,
        animation: false,
    }
}

/// The features of the WebP whose first bytes are `head` (its RIFF header and at least the
/// first chunk's header and first data byte): a VP8X first chunk's ICC and animation flags.
pub fn webp(head: &[u8]) -> ImageFeatures {
    // "RIFF", the size, "WEBP" (12 bytes); the first chunk's type (4) and size (4); its data.
    let flags = match (head.get(12..16), head.get(20)) {
        (Some(b"VP8X"), Some(&flags)) => flags,
        _ => return ImageFeatures::default(),
    };
    ImageFeatures {
        icc_profile: flags & VP8X_ICC_PROFILE != 0,
        animation: flags & VP8X_ANIMATION != 0,
        ..ImageFeatures::default()
    }
}

/// A PNG chunk of `kind` holding `data`, its CRC-32 (ISO 3309) computed bit by bit: for tests
/// that build PNGs with chunks an encoder does not write.
#[cfg(test)]
pub(crate) fn png_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
    let mut typed = kind.to_vec();
    typed.extend_from_slice(data);
    let mut crc = !0u32;
    for &byte in &typed {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    let mut out = (data.len() as u32).to_be_bytes().to_vec();
    out.extend_from_slice(&typed);
    out.extend_from_slice(&(!crc).to_be_bytes());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Cursor;

    /// A 1 × 1 RGBA PNG with `chunks` between its IHDR and its IDAT, and `after` between its
    /// IDAT and its IEND.
    fn png_around(chunks: &[Vec<u8>], after: &[Vec<u8>]) -> Vec<u8> {
        let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
        out.extend(png_chunk(b"IHDR", &[0, 0, 0, 1, 0, 0, 0, 1, 8, 6, 0, 0, 0]));
        out.extend(chunks.concat());
        // One filter byte and a black, opaque pixel, deflated.
        let idat = [
            0x78, 0x9c, 0x63, 0x60, 0x60, 0x60, 0xf8, 0x0f, 0x00, 0x01, 0x04, 0x01, 0x00,
        ];
        out.extend(png_chunk(b"IDAT", &idat));
        out.extend(after.concat());
        out.extend(png_chunk(b"IEND", &[]));
        out
    }

    fn png_with(chunks: &[Vec<u8>]) -> Vec<u8> {
        png_around(chunks, &[])
    }

    fn features(bytes: &[u8]) -> ImageFeatures {
        png(&mut Cursor::new(bytes))
    }

    fn gama(value: u32) -> Vec<u8> {
        png_chunk(b"gAMA", &value.to_be_bytes())
    }

    fn chrm(values: [u32; 8]) -> Vec<u8> {
        png_chunk(b"cHRM", &values.map(u32::to_be_bytes).concat())
    }

    fn phys(x: u32, y: u32, unit: u8) -> Vec<u8> {
        let mut data = [x.to_be_bytes(), y.to_be_bytes()].concat();
        data.push(unit);
        png_chunk(b"pHYs", &data)
    }

    fn srgb() -> Vec<u8> {
        png_chunk(b"sRGB", &[0])
    }

    fn iccp() -> Vec<u8> {
        png_chunk(b"iCCP", b"profile\0\0\x78\x9c\x03\x00\x00\x00\x00\x01")
    }

    const CUSTOM_PRIMARIES: [u32; 8] = [
        31_270, 32_900, 70_800, 29_200, 17_000, 79_700, 13_100, 4_600,
    ];

    #[test]
    fn a_png_without_colour_or_pixel_chunks_has_no_features() {
        assert!(!features(&png_with(&[])).any());
    }

    #[test]
    fn gamma_is_supported_only_at_srgb_s_45455_and_linear_100000_exactly() {
        for (value, custom) in [
            (45_454, true),
            (45_455, false),
            (45_456, true),
            (99_999, true),
            (100_000, false),
            (100_001, true),
            (50_000, true),
            (0, true),
        ] {
            let found = features(&png_with(&[gama(value)]));
            assert_eq!(found.gamma, custom.then_some(value), "gAMA {value}");
            assert_eq!(found.any(), custom, "gAMA {value}");
        }
    }

    #[test]
    fn chromaticities_are_srgb_s_only_when_all_eight_values_match_exactly() {
        assert!(!features(&png_with(&[chrm(SRGB_CHROMATICITIES)])).any());
        for i in 0..8 {
            for delta in [1, -1] {
                let mut values = SRGB_CHROMATICITIES;
                values[i] = values[i].checked_add_signed(delta).unwrap();
                let found = features(&png_with(&[chrm(values)]));
                assert!(found.chromaticities, "value {i} off by {delta}");
                assert_eq!(found.gamma, None);
            }
        }
        assert!(features(&png_with(&[chrm(CUSTOM_PRIMARIES)])).chromaticities);
    }

    #[test]
    fn pixels_are_square_when_x_and_y_pixels_per_unit_are_equal_whatever_the_unit() {
        for unit in [0, 1] {
            assert!(!features(&png_with(&[phys(2835, 2835, unit)])).any());
            assert_eq!(
                features(&png_with(&[phys(2835, 2834, unit)])).pixels_per_unit,
                Some((2835, 2834))
            );
            assert_eq!(
                features(&png_with(&[phys(1, 2, unit)])).pixels_per_unit,
                Some((1, 2))
            );
        }
    }

    #[test]
    fn an_iccp_chunk_is_a_profile() {
        let found = features(&png_with(&[iccp()]));
        assert!(found.icc_profile);
        assert_eq!((found.gamma, found.chromaticities), (None, false));
        // The profile is set: gAMA and cHRM after it are not read.
        let found = features(&png_with(&[iccp(), gama(50_000), chrm(CUSTOM_PRIMARIES)]));
        assert_eq!(
            (found.icc_profile, found.gamma, found.chromaticities),
            (true, None, false)
        );
    }

    #[test]
    fn an_srgb_chunk_before_gama_and_chrm_leaves_them_unread() {
        let found = features(&png_with(&[srgb(), gama(50_000), chrm(CUSTOM_PRIMARIES)]));
        assert!(!found.any(), "{found:?}");
    }

    #[test]
    fn an_srgb_chunk_after_gama_chrm_or_iccp_overrides_them() {
        for before in [gama(50_000), chrm(CUSTOM_PRIMARIES), iccp()] {
            assert!(!features(&png_with(&[before.clone(), srgb()])).any());
            assert!(features(&png_with(&[before])).any());
        }
        assert!(!features(&png_with(&[gama(50_000), chrm(CUSTOM_PRIMARIES), srgb()])).any());
    }

    #[test]
    fn an_iccp_chunk_after_srgb_is_a_profile_again() {
        assert!(features(&png_with(&[srgb(), iccp()])).icc_profile);
    }

    #[test]
    fn the_first_gama_and_the_first_chrm_decide() {
        assert!(!features(&png_with(&[gama(45_455), gama(50_000)])).any());
        assert_eq!(
            features(&png_with(&[gama(50_000), gama(45_455)])).gamma,
            Some(50_000)
        );
        assert!(!features(&png_with(&[
            chrm(SRGB_CHROMATICITIES),
            chrm(CUSTOM_PRIMARIES)
        ]))
        .any());
        // Gamma and primaries are set apart: a gAMA does not settle the primaries.
        let found = features(&png_with(&[gama(100_000), chrm(CUSTOM_PRIMARIES)]));
        assert_eq!((found.gamma, found.chromaticities), (None, true));
    }

    #[test]
    fn chunks_after_the_first_idat_are_not_read() {
        let found = features(&png_around(
            &[],
            &[iccp(), gama(50_000), chrm(CUSTOM_PRIMARIES), phys(1, 2, 0)],
        ));
        assert!(!found.any(), "{found:?}");
    }

    #[test]
    fn chunks_of_another_length_than_their_own_are_passed_over() {
        let found = features(&png_with(&[
            png_chunk(b"sRGB", &[0, 0]),
            png_chunk(b"gAMA", &[0, 0, 0xC3, 0x50, 0]),
            png_chunk(b"cHRM", &[0; 31]),
            png_chunk(b"pHYs", &[0, 0, 0, 1, 0, 0, 0, 2]),
        ]));
        assert!(!found.any(), "{found:?}");
        // The malformed sRGB chunk set nothing: a well-formed gAMA after it is read.
        let found = features(&png_with(&[png_chunk(b"sRGB", &[]), gama(50_000)]));
        assert_eq!(found.gamma, Some(50_000));
    }

    #[test]
    fn cut_or_lying_chunks_end_the_walk_with_what_was_found() {
        let whole = png_with(&[phys(1, 2, 0), gama(50_000)]);
        // Cut inside the gAMA chunk's data: the pHYs before it is kept.
        let gama_at = whole.windows(4).position(|w| w == b"gAMA").unwrap();
        let found = features(&whole[..gama_at + 6]);
        assert_eq!((found.pixels_per_unit, found.gamma), (Some((1, 2)), None));
        // A length past the end of the data.
        let mut lying = png_with(&[]);
        lying.truncate(33);
        lying.extend_from_slice(&[0xFF, 0xFF, 0xFF, 0xFF]);
        lying.extend_from_slice(b"gAMA");
        assert!(!features(&lying).any());
        lying[33..37].copy_from_slice(&[0xFF; 4]);
        lying[37..41].copy_from_slice(b"iCCP");
        assert!(features(&lying).icc_profile);
        for cut in [0, 4, 8, 12, 20, 33] {
            assert!(!features(&whole[..cut]).any(), "cut at {cut}");
        }
    }

    /// A WebP's first bytes with a VP8X first chunk of `flags` over a 1 × 1 canvas.
    fn vp8x(flags: u8) -> Vec<u8> {
        let mut out = b"RIFF\0\0\0\0WEBPVP8X\x0a\0\0\0".to_vec();
        out.extend_from_slice(&[flags, 0, 0, 0, 0, 0, 0, 0, 0, 0]);
        out
    }

    #[test]
    fn a_webp_s_vp8x_flags_tell_animation_and_an_icc_profile() {
        assert_eq!(
            webp(&vp8x(0x02)),
            ImageFeatures {
                animation: true,
                ..ImageFeatures::default()
            }
        );
        assert_eq!(
            webp(&vp8x(0x20)),
            ImageFeatures {
                icc_profile: true,
                ..ImageFeatures::default()
            }
        );
        // Alpha, EXIF and XMP are supported.
        assert!(!webp(&vp8x(0x10 | 0x08 | 0x04)).any());
        // A simple (VP8L) WebP has no flags; a header cut before them tells nothing.
        assert!(!webp(b"RIFF\x1c\0\0\0WEBPVP8L\x0f\0\0\0\x2f\0\0\0\0").any());
        assert!(!webp(&vp8x(0x22)[..20]).any());
    }

    #[test]
    fn descriptions_name_each_feature() {
        let all = ImageFeatures {
            icc_profile: true,
            gamma: Some(50_000),
            chromaticities: true,
            pixels_per_unit: Some((1, 2)),
            animation: true,
        };
        assert_eq!(
            all.describe(),
            [
                "an embedded ICC colour profile",
                "a gAMA chunk of 50000 (gamma × 100000; sRGB's is 45455, linear 100000)",
                "cHRM chromaticities other than sRGB's",
                "non-square pixels (pHYs: 1 pixels a unit across, 2 down)",
                "animation",
            ]
        );
        assert!(ImageFeatures::default().describe().is_empty());
    }

    fn riff_chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
        let mut out = kind.to_vec();
        out.extend_from_slice(&(data.len() as u32).to_le_bytes());
        out.extend_from_slice(data);
        if data.len() % 2 == 1 {
            out.push(0);
        }
        out
    }

    fn webp_file(chunks: &[Vec<u8>]) -> Vec<u8> {
        let body = [b"WEBP".to_vec(), chunks.concat()].concat();
        [
            b"RIFF".to_vec(),
            (body.len() as u32).to_le_bytes().to_vec(),
            body,
        ]
        .concat()
    }

    /// The VP8L data of a 1 × 1 lossless WebP.
    const LOSSLESS: [u8; 15] = [
        0x2f, 0xff, 0xc0, 0x1f, 0x00, 0x07, 0x10, 0xfd, 0x8f, 0xfe, 0x07, 0x22, 0xa2, 0xff, 0x01,
    ];

    /// A 1 × 1 animated WebP: VP8X with its animation flag, ANIM, one ANMF frame (its place,
    /// size less one and duration, then the frame's VP8L chunk).
    fn animated_webp() -> Vec<u8> {
        let mut frame = vec![0u8; 12];
        frame.extend_from_slice(&[100, 0, 0, 0]);
        frame.extend(riff_chunk(b"VP8L", &LOSSLESS));
        webp_file(&[
            riff_chunk(b"VP8X", &[0x02, 0, 0, 0, 0, 0, 0, 0, 0, 0]),
            riff_chunk(b"ANIM", &[0; 6]),
            riff_chunk(b"ANMF", &frame),
        ])
    }

    #[test]
    fn read_header_carries_the_features_png_and_webp_tell_and_jpeg_and_ktx2_tell_none() {
        use crate::asset::resource::{read_header, ImageFormat};
        let read =
            |bytes: Vec<u8>| read_header(Cursor::new(bytes), "/images/0", "image 0").unwrap();
        let header = read(png_with(&[srgb(), phys(2, 1, 0)]));
        assert_eq!(
            (header.format, header.width, header.height),
            (ImageFormat::Png, 1, 1)
        );
        assert_eq!(header.features.pixels_per_unit, Some((2, 1)));
        let clean = png_with(&[
            srgb(),
            gama(45_455),
            chrm(SRGB_CHROMATICITIES),
            phys(3, 3, 1),
        ]);
        assert!(!read(clean).features.any());
        let header = read(animated_webp());
        assert_eq!((header.format, header.width), (ImageFormat::Webp, 1));
        assert!(header.features.animation);
        let still = webp_file(&[
            riff_chunk(b"VP8X", &[0x10, 0, 0, 0, 0, 0, 0, 0, 0, 0]),
            riff_chunk(b"VP8L", &LOSSLESS),
        ]);
        assert!(!read(still).features.any());
        assert!(!read(webp_file(&[riff_chunk(b"VP8L", &LOSSLESS)]))
            .features
            .any());
        let mut jpeg = Vec::new();
        image::ImageEncoder::write_image(
            image::codecs::jpeg::JpegEncoder::new(&mut jpeg),
            &[0, 0, 0],
            1,
            1,
            image::ExtendedColorType::Rgb8,
        )
        .unwrap();
        assert!(!read(jpeg).features.any());
        let mut ktx2 = b"\xABKTX 20\xBB\r\n\x1A\n".to_vec();
        ktx2.extend_from_slice(&[0; 8]);
        ktx2.extend_from_slice(&[1, 0, 0, 0, 1, 0, 0, 0]);
        assert!(!read(ktx2).features.any());
        // A damaged header is the decoder's finding, whatever the walk found.
        let mut cut = png_with(&[iccp()]);
        cut.truncate(cut.windows(4).position(|w| w == b"IDAT").unwrap());
        let err = read_header(Cursor::new(cut), "/images/0", "image 0").unwrap_err();
        assert_eq!(err.code, "IMAGE_UNEXPECTED_EOS");
    }
}
