//! Measures what each sheet's comparison (the authored column against the migrated one) gives
//! under candidate verdict metrics, for calibrating the preview's verdict on real assets:
//! prints one CSV row per sheet and light.
//!
//!     cargo run --release --example verdict_calibration -- FILES_OR_FOLDERS... > rows.csv
//!     cargo run --release --example verdict_calibration -- --sweep > sweep.csv

use velvet::preview::material::columns;
use velvet::preview::shade::{render_sphere, Light, Shaded};
use velvet::preview::sheet::{sphere_codes_clamped, SPHERE};

fn sweep_document() -> String {
    let mut materials = Vec::new();
    for i in 0..=10 {
        let r = 0.03 + 0.97 * f64::from(i) / 10.0;
        // Dielectric bases of three colours (fabric-like roughness 0.8), and a metal.
        for (base, metallic) in [(0.1, 0.0), (0.5, 0.0), (1.0, 0.0), (0.5, 1.0)] {
            for c in [[1.0, 1.0, 1.0], [0.9, 0.3, 0.5], [0.2, 0.2, 0.2]] {
                let pbr = format!(
                    r#""pbrMetallicRoughness": {{"baseColorFactor": [{base}, {base}, {base}, 1], "metallicFactor": {metallic}, "roughnessFactor": 0.8}}"#
                );
                materials.push(format!(
                    r#"{{"name": "sheen r {r:.3} c {:.1} base {base} metal {metallic}", {pbr}, "extensions": {{"KHR_materials_sheen": {{"sheenColorFactor": [{}, {}, {}], "sheenRoughnessFactor": {r}}}}}}}"#,
                    c[1], c[0], c[1], c[2]
                ));
                materials.push(format!(
                    r#"{{"name": "fuzz a {r:.3} c {:.1} base {base} metal {metallic}", {pbr}, "extensions": {{"KHR_materials_fuzz": {{"fuzzFactor": 1, "fuzzColorFactor": [{}, {}, {}], "fuzzRoughnessFactor": {r}}}}}}}"#,
                    c[1], c[0], c[1], c[2]
                ));
            }
        }
    }
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_fuzz"], "materials": [{}]}}"#,
        materials.join(",")
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = tempfile::tempdir().unwrap();
    let inputs: Vec<std::path::PathBuf> = if args.first().map(String::as_str) == Some("--sweep") {
        let path = dir.path().join("sweep.gltf");
        std::fs::write(&path, sweep_document()).unwrap();
        vec![path]
    } else {
        args.iter().map(Into::into).collect()
    };
    let plan = velvet::preview::plan(&inputs, &velvet::migrate::Options::default());
    println!("sheet,light,swatch,plan_flip,max_codes,share_over_10,flip_mean,flip_p50,flip_p95,flip_p99,flip_max");
    for s in &plan.sheets {
        let m = &s.material;
        for swatch in &m.swatches {
            let cols = columns(m, swatch);
            for light in [Light::Furnace, Light::Directional] {
                let codes: Vec<Vec<[u8; 3]>> = cols[..2]
                    .iter()
                    .map(|c| {
                        sphere_codes_clamped(&render_sphere(&Shaded::new(c.look), light, SPHERE))
                    })
                    .collect();
                let flat = |c: &Vec<[u8; 3]>| c.iter().flatten().copied().collect::<Vec<u8>>();
                let a = nv_flip::FlipImageRgb8::with_data(
                    SPHERE as u32,
                    SPHERE as u32,
                    &flat(&codes[0]),
                );
                let b = nv_flip::FlipImageRgb8::with_data(
                    SPHERE as u32,
                    SPHERE as u32,
                    &flat(&codes[1]),
                );
                let error = nv_flip::flip(a, b, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
                let values = error.to_vec();
                // Pixels on the sphere only.
                let sphere = render_sphere(&Shaded::new(cols[0].look), light, SPHERE);
                let mut on: Vec<f32> = values
                    .iter()
                    .zip(&sphere.coverage)
                    .filter(|(_, c)| **c > 0.5)
                    .map(|(v, _)| *v)
                    .collect();
                on.sort_by(f32::total_cmp);
                let q = |p: f64| on[((on.len() - 1) as f64 * p).round() as usize];
                let mean = on.iter().sum::<f32>() / on.len() as f32;
                let diffs: Vec<u8> = codes[0]
                    .iter()
                    .zip(&codes[1])
                    .map(|(x, y)| (0..3).map(|k| x[k].abs_diff(y[k])).max().unwrap())
                    .collect();
                let max_codes = diffs.iter().max().unwrap();
                let over = diffs.iter().filter(|d| **d > 10).count() as f64 / on.len() as f64;
                println!(
                    "\"{}\",{:?},{},{:.4},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.4}",
                    s.title.replace('"', "'"),
                    light,
                    swatch.label,
                    s.verdict.flip,
                    max_codes,
                    over,
                    mean,
                    q(0.5),
                    q(0.95),
                    q(0.99),
                    on[on.len() - 1]
                );
            }
        }
    }
}
