//! Times `velvet preview`'s steps for one asset: `cargo run --release --example preview_timing
//! -- FILE.gltf`. Each step is run five times and the fastest time printed.

use std::time::{Duration, Instant};
use velvet::preview::{material, shade, sheet};

fn fastest(mut f: impl FnMut()) -> Duration {
    (0..5)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed()
        })
        .min()
        .expect("five runs")
}

fn main() {
    let Some(path) = std::env::args().nth(1) else {
        eprintln!("usage: preview_timing FILE.gltf");
        std::process::exit(2);
    };
    let Some(asset) = velvet::asset::load(path.as_ref()).asset else {
        eprintln!("{path}: cannot be loaded");
        std::process::exit(1);
    };
    let options = velvet::migrate::Options::default();
    let plan = velvet::migrate::plan_document(&asset, &options);
    let materials = material::materials(&asset, &plan, options.roughness);
    println!(
        "{} material(s) to preview, {} thread(s)",
        materials.len(),
        rayon::current_num_threads()
    );
    for m in &materials {
        let cols = material::columns(m, &m.factors);
        let curves = fastest(|| {
            for c in &cols {
                std::hint::black_box(shade::Shaded::new(c.look));
            }
        });
        let sheet_time = fastest(|| {
            std::hint::black_box(sheet::to_png(&sheet::render("timing", m)));
        });
        println!(
            "material {} ({} swatch(es), {} columns): curves {:.1} ms, whole sheet with PNG {:.1} ms",
            m.index,
            m.swatches.len(),
            cols.len(),
            curves.as_secs_f64() * 1e3,
            sheet_time.as_secs_f64() * 1e3
        );
    }
}
