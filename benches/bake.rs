//! Bake benchmarks on generated 2048×2048 RGBA PNGs.
//!
//! - `codec/decode+encode` against `bake/one-texture`: the cost of the bake over the codec work
//!   it cannot avoid (same image, same PNG settings).
//! - `kernel/table` and `kernel/exact`: the colour path alone (sRGB colour × factor, linear
//!   alpha × factor) per megapixel; the maximum error in codes of each path is printed before
//!   timing (against the exact f64 result rounded to the nearest code, and against the
//!   unrounded value).
//! - `bake/four-textures-twice`: four textures each baked twice (colour and roughness into
//!   separate outputs), the reference workload.
//!
//! Run: `cargo bench --bench bake` (add `-- --quick` for a shorter run).

use std::collections::HashMap;
use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use velvet::bake::codec::{self, EncodeOptions, OutputFormat};
use velvet::bake::kernel::{self, KernelOptions};
use velvet::bake::{
    bake, BakeOptions, Channel, ChannelRecipe, Factor, ImageId, Pixels, Recipe, RecipeSet,
    Transfer, Value,
};

#[path = "support/texture.rs"]
mod support;
use support::{texture, SIDE};

/// Inputs are written at zlib's default level, as exporters write them; outputs use the
/// bake's default (fast) compression, in the codec baseline and in the bake alike.
fn input_png(pixels: &Pixels) -> Vec<u8> {
    let options = EncodeOptions {
        png: velvet::bake::PngCompression::Default,
        ..EncodeOptions::default()
    };
    codec::encode(pixels, OutputFormat::Png, options).unwrap()
}

fn png(pixels: &Pixels) -> Vec<u8> {
    codec::encode(pixels, OutputFormat::Png, EncodeOptions::default()).unwrap()
}

fn scaled(image: ImageId, channel: Channel, factor: f64, transfer: Transfer) -> ChannelRecipe {
    let value = Value::scaled(
        Value::texel(image, channel, transfer),
        Factor::new(factor).unwrap(),
    );
    ChannelRecipe::computed(value, transfer)
}

fn colour(image: ImageId) -> Recipe {
    [Channel::R, Channel::G, Channel::B]
        .into_iter()
        .zip([0.8, 0.6, 0.35])
        .fold(Recipe::new(image), |r, (c, k)| {
            r.with(c, scaled(image, c, k, Transfer::Srgb))
        })
}

fn roughness(image: ImageId) -> Recipe {
    Recipe::new(image).with(Channel::A, scaled(image, Channel::A, 0.7, Transfer::Linear))
}

fn colour_and_roughness(image: ImageId) -> Recipe {
    roughness(image)
        .with(Channel::R, scaled(image, Channel::R, 0.8, Transfer::Srgb))
        .with(Channel::G, scaled(image, Channel::G, 0.6, Transfer::Srgb))
        .with(Channel::B, scaled(image, Channel::B, 0.35, Transfer::Srgb))
}

/// Largest |code − reference| and |code − unrounded value| over the image, for the recipe of
/// `colour_and_roughness`, computed here independently of the kernel.
fn errors(input: &Pixels, output: &Pixels) -> (u32, f64) {
    let decode = |v: f64| {
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    };
    let encode = |l: f64| {
        if l <= 0.0031308 {
            l * 12.92
        } else {
            1.055 * l.powf(1.0 / 2.4) - 0.055
        }
    };
    let (mut worst_code, mut worst_value) = (0u32, 0.0f64);
    for (i, k) in [(0usize, 0.8), (1, 0.6), (2, 0.35), (3, 0.7)] {
        for p in 0..input.pixel_count() {
            let c = f64::from(input.samples().code(p * 4 + i)) / 255.0;
            let ideal = if i == 3 { k * c } else { encode(k * decode(c)) } * 255.0;
            let got = output.samples().code(p * 4 + i);
            worst_code = worst_code.max(got.abs_diff(ideal.round_ties_even() as u32));
            worst_value = worst_value.max((f64::from(got) - ideal).abs());
        }
    }
    (worst_code, worst_value)
}

fn benches(c: &mut Criterion) {
    let pixels = texture(1);
    let bytes = input_png(&pixels);
    println!(
        "input: {SIDE}x{SIDE} RGBA8 PNG, {:.1} MiB encoded",
        bytes.len() as f64 / (1024.0 * 1024.0)
    );

    let images = HashMap::from([(ImageId(0), pixels.clone())]);
    let recipe = colour_and_roughness(ImageId(0));
    for (name, exact) in [("table", false), ("exact", true)] {
        let options = KernelOptions {
            exact,
            measure: false,
        };
        let (out, _) = kernel::apply(&recipe, &images, options).unwrap();
        let (code, value) = errors(&pixels, &out);
        println!(
            "kernel/{name}: max error {code} codes against the exact rounded result, \
             {value:.4} codes against the unrounded value"
        );
    }

    // Criterion times one group after another; on a shared machine the load drifts between
    // them. Alternating the two runs gives a comparison both sides of which saw the same load.
    let source = HashMap::from([(ImageId(0), bytes.clone())]);
    let mut one = RecipeSet::new();
    one.insert(recipe.clone());
    let (mut baked, mut plain) = (Vec::new(), Vec::new());
    for _ in 0..15 {
        let t = Instant::now();
        black_box(bake(&one, &source, &BakeOptions::default()));
        baked.push(t.elapsed());
        let t = Instant::now();
        let (p, _) = codec::decode(&bytes).unwrap();
        black_box(png(&p));
        plain.push(t.elapsed());
    }
    baked.sort();
    plain.sort();
    println!(
        "alternating, median of 15: bake {:.1} ms, decode+encode {:.1} ms: the bake costs {:+.1} %",
        baked[7].as_secs_f64() * 1e3,
        plain[7].as_secs_f64() * 1e3,
        (baked[7].as_secs_f64() / plain[7].as_secs_f64() - 1.0) * 100.0
    );

    let mut group = c.benchmark_group("codec");
    group.sample_size(10);
    group.bench_function("decode+encode", |b| {
        b.iter(|| {
            let (p, _) = codec::decode(black_box(&bytes)).unwrap();
            black_box(png(&p))
        })
    });
    group.finish();

    let mut group = c.benchmark_group("kernel");
    group.sample_size(10);
    group.throughput(Throughput::Elements(u64::from(SIDE * SIDE)));
    for (name, exact) in [("table", false), ("exact", true)] {
        let options = KernelOptions {
            exact,
            measure: false,
        };
        group.bench_function(name, |b| {
            b.iter(|| black_box(kernel::apply(&recipe, &images, options).unwrap()))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("bake");
    group.sample_size(10);
    group.bench_function("one-texture", |b| {
        b.iter(|| black_box(bake(&one, &source, &BakeOptions::default())))
    });
    let four: HashMap<ImageId, Vec<u8>> = (0..4)
        .map(|i| (ImageId(i), input_png(&texture(i as u32 + 1))))
        .collect();
    let mut set = RecipeSet::new();
    for i in 0..4 {
        set.insert(colour(ImageId(i)));
        set.insert(roughness(ImageId(i)));
    }
    group.bench_function("four-textures-twice", |b| {
        b.iter(|| black_box(bake(&set, &four, &BakeOptions::default())))
    });
    group.finish();
}

criterion_group!(bake_benches, benches);
criterion_main!(bake_benches);
