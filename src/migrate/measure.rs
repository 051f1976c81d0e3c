//! `--report` measurements that need texel values: the attenuation difference of fast mode.
//!
//! With the sheen colour texture carried as the fuzz colour texture, the fuzz attenuates the
//! base by w everywhere, where the sheen attenuated it by max3(sheenColorFactor · texel). Over
//! every texel of the texture's image (its own resolution, whatever the UV mapping), this
//! measures |w − max3(factor · linear(texel))|: its maximum and its mean. Images are decoded
//! only here, and only when the user asked for the report.

use crate::asset::Asset;
use crate::document::texture_sources;
use crate::layers::{max3, Transfer};
use serde_json::Value;

/// The attenuation difference over one image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attenuation {
    pub image: usize,
    pub texels: u64,
    pub max: f64,
    pub mean: f64,
}

/// Measures the attenuation difference of a sheen colour texture (`texture_info`) scaled by
/// `factor`, against the fuzz strength `w`. The first of the texture's sources that decodes is
/// used.
pub fn attenuation(
    asset: &Asset,
    texture_info: &Value,
    factor: [f64; 3],
    w: f64,
) -> Result<Attenuation, String> {
    let index = texture_info
        .get("index")
        .and_then(Value::as_u64)
        .ok_or("the texture has no valid index")?;
    let texture = asset
        .root()
        .get("textures")
        .and_then(|t| t.get(index as usize))
        .ok_or_else(|| format!("texture {index} does not exist"))?;
    let mut last_error = format!("texture {index} has no image source");
    for (source, _) in texture_sources(texture, &format!("/textures/{index}")) {
        let Some(image) = source else { continue };
        let measured = asset.decode_image_with(image as usize, 1, 12, |decoded| {
            over_texels(image as usize, &decoded.to_rgb32f(), factor, w)
        });
        match measured {
            Ok(measured) => return Ok(measured),
            Err(d) => last_error = d.message,
        }
    }
    Err(last_error)
}

/// The measurement over decoded texels (stored values in [0, 1], sRGB-encoded).
pub fn over_texels(
    image: usize,
    texels: &image::Rgb32FImage,
    factor: [f64; 3],
    w: f64,
) -> Attenuation {
    let (mut max, mut sum, mut count) = (0.0f64, 0.0f64, 0u64);
    for pixel in texels.pixels() {
        let linear: [f64; 3] =
            std::array::from_fn(|c| factor[c] * Transfer::Srgb.to_linear(f64::from(pixel.0[c])));
        let difference = (w - max3(linear)).abs();
        max = max.max(difference);
        sum += difference;
        count += 1;
    }
    Attenuation {
        image,
        texels: count,
        max,
        mean: if count == 0 { 0.0 } else { sum / count as f64 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_texels_match_and_black_ones_differ_by_w() {
        let img = image::Rgb32FImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                image::Rgb([1.0, 1.0, 1.0])
            } else {
                image::Rgb([0.0, 0.0, 0.0])
            }
        });
        let m = over_texels(3, &img, [0.8, 0.4, 0.2], 0.8);
        assert_eq!((m.image, m.texels), (3, 2));
        assert!((m.max - 0.8).abs() < 1e-12, "{m:?}");
        assert!((m.mean - 0.4).abs() < 1e-12, "{m:?}");
    }

    #[test]
    fn texels_are_decoded_from_srgb_before_scaling() {
        // Stored 0.5 is linear 0.2140…; the maximum channel after the factor decides.
        let img = image::Rgb32FImage::from_pixel(1, 1, image::Rgb([0.5, 1.0, 0.0]));
        let m = over_texels(0, &img, [1.0, 0.1, 1.0], 1.0);
        assert!(
            (m.max - (1.0 - 0.214_041_140_482_232_5)).abs() < 1e-7,
            "{m:?}"
        );
    }
}
