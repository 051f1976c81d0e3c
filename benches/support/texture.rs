//! The generated textures the bake benches measure on, shared by `bake` and `bake_corpus` so
//! that both speak of the same images.

use velvet::bake::{Layout, Pixels, Samples};

/// Width and height of every generated texture.
pub const SIDE: u32 = 2048;

/// A texture-like image: smooth gradients with a little noise (so PNG compresses it about as
/// well as a real albedo map), alpha a separate pattern.
pub fn texture(seed: u32) -> Pixels {
    let mut state = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
    let mut noise = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        (state % 9) as i32 - 4
    };
    let mut codes = Vec::with_capacity((SIDE * SIDE * 4) as usize);
    for y in 0..SIDE {
        for x in 0..SIDE {
            let base = [x / 8, y / 8, (x + y) / 16, 255 - (x ^ y) / 16];
            for (c, v) in base.into_iter().enumerate() {
                let v = (v + seed * 31 * (c as u32 + 1)) % 256;
                codes.push((v as i32 + noise()).clamp(0, 255) as u8);
            }
        }
    }
    Pixels::new(SIDE, SIDE, Layout::Rgba, Samples::U8(codes)).unwrap()
}
