//! The sRGB transfer function, exactly as IEC 61966-2-1 writes it (piecewise: a linear toe and a
//! 2.4 power segment), evaluated in f64, plus the decode tables that the kernel indexes by code.
//!
//! The two segment thresholds are the standard's own constants: 0.04045 on the encoded side and
//! 0.0031308 on the linear side. They are not exact images of each other (0.04045 / 12.92 =
//! 0.00313080495...), so the functions are used as written rather than derived from one another;
//! the tests pin both boundaries.

use std::sync::OnceLock;

/// Encoded-side threshold: at or below it `decode` uses the linear toe.
pub const DECODE_THRESHOLD: f64 = 0.04045;
/// Linear-side threshold: at or below it `encode` uses the linear toe.
pub const ENCODE_THRESHOLD: f64 = 0.0031308;

/// sRGB-encoded value in [0, 1] to linear light.
pub fn decode(v: f64) -> f64 {
    if v <= DECODE_THRESHOLD {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear light in [0, 1] to the sRGB-encoded value.
pub fn encode(l: f64) -> f64 {
    if l <= ENCODE_THRESHOLD {
        l * 12.92
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The nearest code (ties to even) of a normalised value for a channel whose largest code is
/// `max` (255 or 65535). The value is clamped to [0, 1] first.
pub fn quantise(v: f64, max: u32) -> u32 {
    let max_f = f64::from(max);
    // `as` saturates, and the clamp keeps NaN out of the product's reach.
    (v.clamp(0.0, 1.0) * max_f).round_ties_even() as u32
}

/// Linear light of every 8-bit sRGB code: `table[c] = decode(c / 255)`.
pub fn decode_table_8() -> &'static [f64; 256] {
    static TABLE: OnceLock<[f64; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|c| decode(c as f64 / 255.0)))
}

/// Linear light of every 16-bit sRGB code: `table[c] = decode(c / 65535)`. Built on first use.
pub fn decode_table_16() -> &'static [f64] {
    static TABLE: OnceLock<Box<[f64]>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=65535u32)
            .map(|c| decode(f64::from(c) / 65535.0))
            .collect()
    })
}

/// Normalised value of every 8-bit linear code: `table[c] = c / 255`.
pub fn linear_table_8() -> &'static [f64; 256] {
    static TABLE: OnceLock<[f64; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|c| c as f64 / 255.0))
}

/// Normalised value of every 16-bit linear code: `table[c] = c / 65535`. Built on first use.
pub fn linear_table_16() -> &'static [f64] {
    static TABLE: OnceLock<Box<[f64]>> = OnceLock::new();
    TABLE.get_or_init(|| (0..=65535u32).map(|c| f64::from(c) / 65535.0).collect())
}

/// The 8-bit sRGB code of linear light, `quantise(encode(l), 255)` with l clamped into [0, 1]
/// (NaN as 0), found among the 255 linear values where the code steps up instead of by a
/// power per value: a renderer encodes every pixel. The steps are located by bisection over
/// the f64 values of [0, 1] on `quantise(encode(·))` itself, so every value gives the code the
/// direct formula gives (the test checks each step and the values next to it). A value's
/// bucket of [`CODE_BUCKETS`] gives the code at the bucket's start, and at most a step or two
/// follow within a bucket (the toe's slope is 12.92 × 255 ≈ 3295 codes per unit).
pub fn encode_code_8(l: f64) -> u8 {
    if l.is_nan() || l <= 0.0 {
        return direct_code_8(0.0);
    }
    if l >= 1.0 {
        return direct_code_8(1.0);
    }
    let steps = code_steps_8();
    // l · 4096 is exact (a power of two), so the bucket starts at or below l.
    let mut code = usize::from(bucket_codes_8()[(l * CODE_BUCKETS as f64) as usize]);
    while code < steps.len() && steps[code] <= l {
        code += 1;
    }
    code as u8
}

/// The buckets of [`encode_code_8`] over [0, 1).
const CODE_BUCKETS: usize = 4096;

/// The code at the start b / [`CODE_BUCKETS`] of each bucket.
fn bucket_codes_8() -> &'static [u8; CODE_BUCKETS] {
    static CODES: OnceLock<[u8; CODE_BUCKETS]> = OnceLock::new();
    CODES.get_or_init(|| {
        let steps = code_steps_8();
        std::array::from_fn(|b| {
            let start = b as f64 / CODE_BUCKETS as f64;
            steps.partition_point(|&t| t <= start) as u8
        })
    })
}

fn direct_code_8(l: f64) -> u8 {
    quantise(encode(l.clamp(0.0, 1.0)), 255) as u8
}

/// For each code k = 1..=255, the smallest linear value in [0, 1] whose code is at least k.
fn code_steps_8() -> &'static [f64; 255] {
    static STEPS: OnceLock<[f64; 255]> = OnceLock::new();
    STEPS.get_or_init(|| {
        std::array::from_fn(|i| {
            let k = i as u8 + 1;
            // Non-negative f64 values are ordered as their bit patterns.
            let (mut below, mut at) = (0.0f64.to_bits(), 1.0f64.to_bits());
            while at - below > 1 {
                let mid = below + (at - below) / 2;
                if direct_code_8(f64::from_bits(mid)) >= k {
                    at = mid;
                } else {
                    below = mid;
                }
            }
            f64::from_bits(at)
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_code_steps_give_the_direct_formulas_code_everywhere() {
        let next = |x: f64, n: i64| f64::from_bits((x.to_bits() as i64 + n) as u64);
        // At every step and the four f64 values either side of it.
        for &t in code_steps_8() {
            for n in -4..=4 {
                let x = next(t, n);
                assert_eq!(encode_code_8(x), direct_code_8(x), "{x:e}");
            }
        }
        // A dense sweep, the ends, the toe's threshold and values outside [0, 1].
        let mut x = 0.0;
        while x <= 1.0 {
            assert_eq!(encode_code_8(x), direct_code_8(x), "{x:e}");
            x += 1.0 / 1_048_576.0 + x * 1e-5;
        }
        for x in [0.0, -0.0, 1.0, ENCODE_THRESHOLD, -1.0, 2.0, f64::INFINITY] {
            assert_eq!(encode_code_8(x), direct_code_8(x), "{x:e}");
        }
        assert_eq!(encode_code_8(f64::NAN), 0);
        assert_eq!(encode_code_8(0.5), 188);
    }

    #[test]
    fn decode_uses_the_toe_up_to_and_including_0_04045() {
        assert_eq!(decode(DECODE_THRESHOLD), 0.04045 / 12.92);
        let above = f64::from_bits(DECODE_THRESHOLD.to_bits() + 1);
        assert_eq!(decode(above), ((above + 0.055) / 1.055).powf(2.4));
        // The standard's rounded constants leave a step of +2.33e-9 between the segments, far
        // below a 16-bit code (1.5e-5), so no code can land on the other side of it.
        let step = decode(above) - decode(DECODE_THRESHOLD);
        assert!((2.32e-9..2.34e-9).contains(&step), "step {step}");
    }

    #[test]
    fn encode_uses_the_toe_up_to_and_including_0_0031308() {
        assert_eq!(encode(ENCODE_THRESHOLD), 0.0031308 * 12.92);
        let above = f64::from_bits(ENCODE_THRESHOLD.to_bits() + 1);
        assert_eq!(encode(above), 1.055 * above.powf(1.0 / 2.4) - 0.055);
        // The step here is -2.85e-8 (the power segment starts slightly lower).
        let step = encode(above) - encode(ENCODE_THRESHOLD);
        assert!((-2.86e-8..-2.84e-8).contains(&step), "step {step}");
    }

    #[test]
    fn zero_and_one_are_fixed_points() {
        assert_eq!(decode(0.0), 0.0);
        assert_eq!(encode(0.0), 0.0);
        assert!((decode(1.0) - 1.0).abs() < 1e-15);
        assert!((encode(1.0) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn every_8_and_16_bit_code_round_trips_through_linear() {
        for c in 0..=255u32 {
            assert_eq!(quantise(encode(decode_table_8()[c as usize]), 255), c);
        }
        let table = decode_table_16();
        for c in 0..=65535u32 {
            assert_eq!(quantise(encode(table[c as usize]), 65535), c, "code {c}");
        }
    }

    #[test]
    fn the_codes_either_side_of_the_threshold_use_their_own_segment() {
        // 8-bit: 10/255 = 0.0392 is on the toe, 11/255 = 0.0431 on the power segment.
        assert_eq!(decode_table_8()[10], (10.0 / 255.0) / 12.92);
        assert_eq!(
            decode_table_8()[11],
            ((11.0f64 / 255.0 + 0.055) / 1.055).powf(2.4)
        );
        // 16-bit: 2650/65535 = 0.040436 toe, 2651/65535 = 0.040452 power.
        assert_eq!(decode_table_16()[2650], (2650.0 / 65535.0) / 12.92);
        assert_eq!(
            decode_table_16()[2651],
            ((2651.0f64 / 65535.0 + 0.055) / 1.055).powf(2.4)
        );
    }

    #[test]
    fn quantise_rounds_to_nearest_with_ties_to_even_and_clamps() {
        // With max = 4 the products are exact, so these are true ties.
        assert_eq!(quantise(0.125, 4), 0); // 0.5 -> 0
        assert_eq!(quantise(0.375, 4), 2); // 1.5 -> 2
        assert_eq!(quantise(0.625, 4), 2); // 2.5 -> 2
        assert_eq!(quantise(-0.25, 255), 0);
        assert_eq!(quantise(1.75, 65535), 65535);
        assert_eq!(quantise(f64::NAN, 255), 0);
    }
}
