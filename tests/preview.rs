//! `velvet preview`: the shading of the spheres against the specs' formulas integrated here,
//! the conversions a sheet shows, textures, determinism, and the command's outcomes. Inputs are
//! generated in temporary folders.

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::Command;
use velvet::preview::material::{self, columns, Kind};
use velvet::preview::shade::{pixel_normal, render_sphere, Layer, Light, Look, Shaded};
use velvet::preview::sheet::{self, encode, sphere_codes};
use velvet::shading::charlie::{charlie_d, charlie_lambda};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn gltf(materials: &str) -> String {
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_fuzz"], "materials": [{materials}]}}"#
    )
}

fn load(path: &Path) -> velvet::asset::Asset {
    velvet::asset::load(path)
        .asset
        .expect("the test asset loads")
}

/// The sheets' materials of `asset`, with what a default migration of it writes.
fn materials_of(asset: &velvet::asset::Asset) -> Vec<material::Material> {
    materials_with(asset, &velvet::migrate::Options::default())
}

fn materials_with(
    asset: &velvet::asset::Asset,
    options: &velvet::migrate::Options,
) -> Vec<material::Material> {
    let mut plan = velvet::migrate::plan_document(asset, options);
    velvet::preview::verdict::judge(asset, &mut plan, options)
}

/// Interior pixels (whole pixel on the sphere) of a sphere of `size`.
fn interior(size: usize) -> Vec<(usize, usize)> {
    let mut v = Vec::new();
    for y in 0..size {
        for x in 0..size {
            let s = size as f64;
            let corner_inside = |dx: f64, dy: f64| {
                let px = (x as f64 + dx) / s * 2.0 - 1.0;
                let py = 1.0 - (y as f64 + dy) / s * 2.0;
                px * px + py * py < 1.0
            };
            if corner_inside(0.0, 0.0)
                && corner_inside(1.0, 0.0)
                && corner_inside(0.0, 1.0)
                && corner_inside(1.0, 1.0)
            {
                v.push((x, y));
            }
        }
    }
    v
}

/// glTF 2.0's metallic-roughness BRDF (Appendix B) for one channel of base colour `rho`, with
/// N = +z, written out from the spec's formulas: mix(dielectric, metal, metallic).
fn gltf_brdf(v: [f64; 3], l: [f64; 3], rho: f64, metallic: f64, roughness: f64) -> f64 {
    if v[2] <= 0.0 || l[2] <= 0.0 {
        return 0.0;
    }
    let hs = [v[0] + l[0], v[1] + l[1], v[2] + l[2]];
    let len = (hs[0] * hs[0] + hs[1] * hs[1] + hs[2] * hs[2]).sqrt();
    let h = hs.map(|c| c / len);
    let (n_dot_v, n_dot_l, n_dot_h) = (v[2], l[2], h[2]);
    let v_dot_h = v[0] * h[0] + v[1] * h[1] + v[2] * h[2];
    let a2 = (roughness * roughness).powi(2);
    let d = a2 / (PI * (n_dot_h * n_dot_h * (a2 - 1.0) + 1.0).powi(2));
    let g = 2.0 * n_dot_l * n_dot_v
        / (n_dot_v * (a2 + (1.0 - a2) * n_dot_l * n_dot_l).sqrt()
            + n_dot_l * (a2 + (1.0 - a2) * n_dot_v * n_dot_v).sqrt());
    let specular = d * g / (4.0 * n_dot_v * n_dot_l);
    let fw = (1.0 - v_dot_h.abs()).powi(5);
    let dielectric_fresnel = 0.04 + 0.96 * fw;
    let dielectric = (1.0 - dielectric_fresnel) * rho / PI + dielectric_fresnel * specular;
    let metal = (rho + (1.0 - rho) * fw) * specular;
    (1.0 - metallic) * dielectric + metallic * metal
}

/// The light cosines of the rows of [`base_integrated_here`]'s grid: μl = cos θ at the
/// midpoints of `n` steps of θ over [0, π/2].
fn light_rows(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| ((i as f64 + 0.5) / n as f64 * PI / 2.0).cos())
        .collect()
}

/// ∫ f(v, l)·a(μl)·μl dω over the light hemisphere for the view of cosine `mu`, by the midpoint
/// rule in (θ, φ) (dω = sin θ dθ dφ), θ on the rows of [`light_rows`] and φ over the whole
/// circle in three times as many steps; `attenuation[i]` is a on the i-th row.
fn base_integrated_here(
    mu: f64,
    rho: f64,
    metallic: f64,
    roughness: f64,
    attenuation: &[f64],
) -> f64 {
    let (nt, nphi) = (attenuation.len(), 3 * attenuation.len());
    let v = [(1.0 - mu * mu).sqrt(), 0.0, mu];
    let d_theta = PI / 2.0 / nt as f64;
    let mut sum = 0.0;
    for (i, a) in attenuation.iter().enumerate() {
        let theta = (i as f64 + 0.5) * d_theta;
        let (sl, ml) = theta.sin_cos();
        let mut ring = 0.0;
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) / nphi as f64 * 2.0 * PI;
            let l = [sl * phi.cos(), sl * phi.sin(), ml];
            ring += gltf_brdf(v, l, rho, metallic, roughness);
        }
        sum += ring * (2.0 * PI / nphi as f64) * ml * a * sl * d_theta;
    }
    sum
}

#[test]
fn a_furnace_sphere_without_a_layer_shows_the_bases_directional_albedo() {
    // The base alone in a white furnace of radiance 1 reflects its directional albedo
    // ∫ f·μl dω, which the spec's BRDF gives and is integrated here on another grid: within
    // 2e-3 in linear value (both integrations' error), and 1 code once encoded.
    let base = [0.8, 0.35, 0.05];
    let size = 64;
    let ones = vec![1.0; 120];
    for (metallic, roughness) in [(0.0, 1.0), (0.0, 0.5), (1.0, 0.5), (1.0, 1.0)] {
        let look = Look {
            base,
            base_metallic: metallic,
            base_roughness: roughness,
            layer: Layer::None,
        };
        let shaded = Shaded::new(look);
        // The BRDF is affine in the colour: integrate it for colours 0 and 1, once per view.
        let here = |mu: f64| -> [f64; 3] {
            let [zero, one] =
                [0.0, 1.0].map(|rho| base_integrated_here(mu, rho, metallic, roughness, &ones));
            base.map(|b| zero + b * (one - zero))
        };
        for mu in [0.1, 0.3, 0.6, 0.9, 1.0] {
            let got = shaded.furnace(mu);
            let want = here(mu);
            for k in 0..3 {
                assert!(
                    (got[k] - want[k]).abs() < 2e-3,
                    "metallic {metallic}, roughness {roughness}, μ={mu}, channel {k}: {got:?} vs {want:?}"
                );
            }
        }
        let sphere = render_sphere(&shaded, Light::Furnace, size);
        let codes = sphere_codes(&sphere);
        let inside = interior(size);
        assert!(inside.len() > 2500);
        for &(x, y) in inside.iter().step_by(211) {
            let want = here(pixel_normal(size, x, y).unwrap()[2]).map(encode);
            let got = codes[y * size + x];
            for k in 0..3 {
                assert!(
                    got[k].abs_diff(want[k]) <= 1,
                    "pixel ({x}, {y}): {got:?} vs {want:?}"
                );
            }
        }
        // A switched-off sheen (sheenColorFactor zero) is the same picture.
        let off = render_sphere(
            &Shaded::new(Look {
                layer: Layer::Sheen {
                    color: [0.0; 3],
                    roughness: 0.5,
                },
                ..look
            }),
            Light::Furnace,
            size,
        );
        assert_eq!(sphere_codes(&off), codes);
    }
}

/// E(μ, r) = ∫ D·V·NdotL dω over the light hemisphere, by the midpoint rule in (t, φ) with
/// NdotL = t² (dNdotL = 2t dt) and φ over [0, π] doubled; D and λ are the spec's Charlie terms.
fn albedo_by_midpoints(mu: f64, r: f64) -> f64 {
    let (nt, nphi) = (200, 96);
    let sv = (1.0 - mu * mu).max(0.0).sqrt();
    let lambda_v = charlie_lambda(mu, r);
    let mut sum = 0.0;
    for i in 0..nt {
        let t = (i as f64 + 0.5) / nt as f64;
        let ml = t * t;
        let sl = (1.0 - ml * ml).max(0.0).sqrt();
        // V·NdotL with NdotL cancelled: 1 / ((1 + λv + λl)·4·μ).
        let vis = 1.0 / ((1.0 + lambda_v + charlie_lambda(ml, r)) * 4.0 * mu);
        let mut inner = 0.0;
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) / nphi as f64 * PI;
            let h = [sv + sl * phi.cos(), sl * phi.sin(), mu + ml];
            let n_dot_h = h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            inner += charlie_d(n_dot_h, r);
        }
        sum += inner * (PI / nphi as f64) * 2.0 * vis * 2.0 * t / nt as f64;
    }
    sum
}

#[test]
fn a_sheen_sphere_in_the_furnace_matches_the_layering_formula_integrated_here() {
    // Outgoing radiance in a white furnace of radiance 1 for a metallic-roughness base f_base
    // under a sheen (albedo scaling with both terms):
    //   L(μ) = sheenColor·E(μ) + ∫ f_base(v, l)·min(1 − m·E(μ), 1 − m·E(μl)) μl dω,
    //   m = max3(sheenColor), the attenuation inside the integral.
    let base = [0.45, 0.3, 0.2];
    let size = 128;
    for (color, r, metallic, roughness) in [
        ([0.9f64, 0.6, 0.3], 0.5f64, 0.0, 1.0),
        ([0.3, 0.8, 1.0], 0.3, 1.0, 0.5),
    ] {
        let m = color[0].max(color[1]).max(color[2]);
        let shaded = Shaded::new(Look {
            base,
            base_metallic: metallic,
            base_roughness: roughness,
            layer: Layer::Sheen {
                color,
                roughness: r,
            },
        });
        let codes = sphere_codes(&render_sphere(&shaded, Light::Furnace, size));
        // a(μl) on the light integral's rows.
        let light_attenuation: Vec<f64> = light_rows(240)
            .into_iter()
            .map(|ml| (1.0 - m * albedo_by_midpoints(ml, r)).clamp(0.0, 1.0))
            .collect();
        // Pixels along the row through the centre: view cosines from about 0.25 to 1.
        let y = size / 2;
        let mut checked = 0;
        for x in (size / 2..size).step_by(7) {
            let n = pixel_normal(size, x, y).unwrap();
            let mu = n[2];
            if mu < 0.25 {
                continue;
            }
            let e = albedo_by_midpoints(mu, r);
            let av = (1.0 - m * e).clamp(0.0, 1.0);
            let a: Vec<f64> = light_attenuation.iter().map(|al| av.min(*al)).collect();
            for k in 0..3 {
                let b = base_integrated_here(mu, base[k], metallic, roughness, &a);
                let want = encode(color[k] * e + b);
                let got = codes[y * size + x][k];
                assert!(
                    got.abs_diff(want) <= 1,
                    "r={r}, μ={mu:.3}, channel {k}: rendered {got}, integrated {want}"
                );
            }
            checked += 1;
        }
        assert!(checked >= 6, "{checked} view cosines checked");
    }
}

#[test]
fn the_fallback_of_a_black_fuzz_shows_no_layer() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "black.gltf",
        &gltf(
            r#"{"name": "black fuzz", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.5, 0.4, 1]},
               "extensions": {"KHR_materials_fuzz": {"fuzzFactor": 1, "fuzzColorFactor": [0, 0, 0], "fuzzRoughnessFactor": 0.5}}}"#,
        ),
    );
    let materials = materials_of(&load(&path));
    assert_eq!(materials.len(), 1);
    let m = &materials[0];
    assert_eq!(m.kind, Kind::FuzzFallback);
    let cols = columns(m, &m.factors);
    assert_eq!(cols.len(), 3);
    // No fallback is written, and the column says so.
    assert_eq!(
        (cols[1].title.as_str(), cols[1].detail.as_str()),
        ("no fuzz: sheen", "none written: base alone")
    );
    let bare = Shaded::new(Look {
        base: m.base,
        base_metallic: m.base_metallic,
        base_roughness: m.base_roughness,
        layer: Layer::None,
    });
    for light in [Light::Furnace, Light::Directional] {
        let want = sphere_codes(&render_sphere(&bare, light, 64));
        for c in &cols[1..] {
            let got = sphere_codes(&render_sphere(&Shaded::new(c.look), light, 64));
            assert_eq!(got, want, "{} {} under {light:?}", c.title, c.detail);
        }
        // The authored black fuzz does darken the base: it is not the bare base.
        let authored = sphere_codes(&render_sphere(&Shaded::new(cols[0].look), light, 64));
        assert_ne!(authored, want);
    }
}

#[test]
fn sheen_migrates_to_fuzz_with_the_fitted_and_the_copied_roughness() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "sheen.gltf",
        &gltf(
            r#"{"name": "cloth", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.0, 0.2, 1]},
               "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1.0, 0.0, 0.75], "sheenRoughnessFactor": 0.5}}}"#,
        ),
    );
    let m = &materials_of(&load(&path))[0];
    assert_eq!(m.kind, Kind::SheenToFuzz);
    let cols = columns(m, &m.factors);
    let alpha = velvet::shading::mapping::fuzz_roughness_for_sheen(0.5);
    assert!((alpha - 0.556).abs() < 1e-3, "α(0.5) = {alpha}");
    let fuzz = |roughness| Layer::Fuzz {
        color: [1.0, 0.0, 0.75],
        weight: 1.0,
        roughness,
    };
    // The migrated column is the file migrate writes: α(0.5) to four decimals.
    let written = velvet::migrate::roughness::written(alpha);
    assert_eq!(written, 0.5558);
    assert_eq!(cols[1].look.layer, fuzz(written));
    assert_eq!(cols[1].detail, "α 0.556 fitted");
    assert_eq!(cols[2].look.layer, fuzz(0.5));
    assert_eq!(cols[2].detail, "α 0.500 copied");
    // What a loader without fuzz sees: the sheen, kept.
    assert_eq!(cols[3].look, cols[0].look);
    let sheet = sheet::render("sheen.gltf", m);
    assert_eq!(sheet.rgb.len(), sheet.width * sheet.height * 3);
    // The report's figures for both mappings, with the values migrate --report gives.
    assert_eq!(sheet.summary.figures.len(), 2);
    let fitted = velvet::shading::mapping::layer_match(
        velvet::shading::layering::SheenParams {
            color_max3: 1.0,
            roughness: 0.5,
        },
        velvet::shading::layering::FuzzParams {
            weight: 1.0,
            roughness: alpha,
        },
    );
    assert!(
        sheet.summary.figures[0].contains(&format!("rms {:.4}", fitted.rms)),
        "{}",
        sheet.summary.figures[0]
    );
    assert!(sheet.summary.verdict_line().starts_with("verdict: "));
}

/// A 4×1 RGBA PNG as a data: URI.
fn png_data_uri(pixels: &[[u8; 4]]) -> String {
    use base64::Engine;
    let mut img = image::RgbaImage::new(pixels.len() as u32, 1);
    for (i, p) in pixels.iter().enumerate() {
        img.put_pixel(i as u32, 0, image::Rgba(*p));
    }
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .unwrap();
    format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bytes)
    )
}

#[test]
fn a_textured_layer_gives_three_swatches_and_a_missing_texture_leaves_the_factor() {
    let dir = tempfile::tempdir().unwrap();
    // Roughness (alpha) 0, 51, 102, …: 20 texels; nearest rank p5 = 0, p95 = the 19th.
    let rough: Vec<[u8; 4]> = (0..20).map(|i| [255, 255, 255, (i * 12) as u8]).collect();
    let text = format!(
        r#"{{"asset": {{"version": "2.0"}},
            "images": [{{"uri": "{}"}}, {{"uri": "missing.png"}}],
            "textures": [{{"source": 0}}, {{"source": 1}}],
            "materials": [{{"name": "textured",
              "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.5, 0.5, 1], "baseColorTexture": {{"index": 1}}}},
              "extensions": {{"KHR_materials_sheen": {{"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.5,
                  "sheenRoughnessTexture": {{"index": 0}}, "sheenColorTexture": {{"index": 1}}}}}}}}]}}"#,
        png_data_uri(&rough)
    );
    let path = write(dir.path(), "textured.gltf", &text);
    let m = &materials_of(&load(&path))[0];
    let labels: Vec<&str> = m.swatches.iter().map(|s| s.label).collect();
    assert_eq!(labels, ["p5", "mean", "p95"]);
    let r: Vec<f64> = m
        .swatches
        .iter()
        .map(|s| s.sheen.unwrap().roughness)
        .collect();
    assert_eq!(r[0], 0.0);
    assert!((r[1] - 0.5 * 114.0 / 255.0).abs() < 1e-12, "{}", r[1]);
    assert_eq!(r[2], 0.5 * 216.0 / 255.0);
    // The missing image: the colour and the base keep their factors, and the notes say so.
    for s in &m.swatches {
        assert_eq!(s.sheen.unwrap().color, [1.0; 3]);
    }
    assert_eq!(m.base, [0.5; 3]);
    // The fuzz colour texture migrate carries from the sheen reads the same missing image.
    assert_eq!(m.notes.len(), 4, "{:?}", m.notes);
    assert!(m.notes[2].starts_with("fuzzColorTexture not read"));
    // Every texture slot of the written layers is named, with its image (a data: URI by its
    // place) or the image it is baked from.
    assert_eq!(
        m.notes[3],
        "textures as written: sheenColorTexture texture 1 (missing.png); sheenRoughnessTexture \
         texture 0 (image 0); fuzzColorTexture texture 1 (missing.png); fuzzRoughnessTexture \
         baked from texture 0 (image 0)"
    );
    // The roughness texture is baked by the plan: at the codes the swatches read (p5 = 0,
    // p95 = 216), the migrated fuzz reads α(0.5 × texel) within the budget 0.01 (and the
    // four-decimal rounding of the factor).
    for (s, code) in [(&m.swatches[0], 0.0), (&m.swatches[2], 216.0)] {
        let exact = velvet::shading::mapping::fuzz_roughness_for_sheen(0.5 * code / 255.0);
        let read = s.written_fuzz.unwrap().roughness;
        assert!(
            (read - exact).abs() <= 0.01 + 5e-5,
            "{} reads {read}, α is {exact}",
            s.label
        );
    }
    assert!(m
        .notes
        .iter()
        .any(|n| n.starts_with("baseColorTexture not read")
            && n.contains("missing.png")
            && n.ends_with("the base is baseColorFactor alone")));
    assert!(m
        .notes
        .iter()
        .any(|n| n.starts_with("sheenColorTexture not read")
            && n.ends_with("sheenColorFactor alone is used")));
    let sheet = sheet::render("textured.gltf", m);
    // The sheet says what the inputs lacked, and how its rows read the textures.
    assert_eq!(sheet.summary.notes[..4], m.notes[..]);
    assert!(
        sheet.summary.notes[4].starts_with("the column headings give the values at the factors")
    );
    // The p5 row's sheen roughness is 0, whose E exceeds 1 at grazing views: the notes after
    // those say which columns have pixels above 1, marked.
    assert!(sheet.summary.notes.len() > 5);
    for n in &sheet.summary.notes[5..] {
        assert!(n.starts_with("column ") && n.contains("above 1"), "{n}");
    }
    // The headings and the verdict name the columns at the factors (r = 0.5).
    assert_eq!(sheet.summary.columns[0], "authored: sheen r 0.500");
    // Two lights for each of the three swatches.
    assert!(sheet.height > 6 * sheet::CELL);

    // The overview shows the sheet's comparison at full size: its two heading lines, then the
    // mean swatch's furnace and light rows (the second of p5, mean and p95), byte for byte.
    assert_eq!(sheet.swatches, 3);
    let (strip, width, height) = sheet::comparison_strip(&sheet);
    let row = 3 * sheet.width;
    let headings = 2 * velvet::preview::font::LINE_HEIGHT;
    assert_eq!((width, height), (sheet.width, headings + 2 * sheet::CELL));
    assert_eq!(
        strip[..row * headings],
        sheet.rgb[row * sheet.headings_top..row * (sheet.headings_top + headings)]
    );
    let mean_rows = sheet.grid_top + 2 * sheet::CELL;
    assert_eq!(
        strip[row * headings..],
        sheet.rgb[row * mean_rows..row * (mean_rows + 2 * sheet::CELL)]
    );
}

fn library(dir: &Path) {
    write(
        dir,
        "a.gltf",
        &gltf(
            r#"{"name": "sheen", "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.3, 0.4, 1]},
                "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.8, 0.7], "sheenRoughnessFactor": 0.35}}},
               {"name": "plain"},
               {"name": "fuzz", "extensions": {"KHR_materials_fuzz": {"fuzzFactor": 0.7, "fuzzColorFactor": [0.2, 0.9, 0.4], "fuzzRoughnessFactor": 0.6}}}"#,
        ),
    );
    std::fs::create_dir(dir.join("sub")).unwrap();
    write(
        &dir.join("sub"),
        "b.gltf",
        &gltf(
            r#"{"extensions": {"KHR_materials_fuzz": {"fuzzFactor": 1, "fuzzColorFactor": [1, 1, 1]},
                               "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.8}}}"#,
        ),
    );
    write(dir, "none.gltf", &gltf(r#"{"name": "no layer"}"#));
}

fn run(args: &[&Path], threads: &str) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_velvet"))
        .arg("preview")
        .args(args)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap()
}

fn folder_bytes(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    files.sort();
    files
}

#[test]
fn identical_inputs_give_identical_bytes_at_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    std::fs::create_dir(&lib).unwrap();
    library(&lib);
    let outs: Vec<PathBuf> = ["1", "2", "2"]
        .iter()
        .enumerate()
        .map(|(k, threads)| {
            let out = dir.path().join(format!("out{k}"));
            let o = run(&[&lib, Path::new("-o"), &out], threads);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            out
        })
        .collect();
    let first = folder_bytes(&outs[0]);
    let names: Vec<&str> = first.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "a-m0-sheen.png",
            "a-m2-fuzz.png",
            "index.html",
            "index.json",
            "overview.png",
            "sub_b-m0.png"
        ]
    );
    for out in &outs[1..] {
        assert_eq!(folder_bytes(out), first);
    }
    // The index links every sheet and lists the file without layers.
    let index = String::from_utf8(first[2].1.clone()).unwrap();
    for png in ["a-m0-sheen.png", "a-m2-fuzz.png", "sub_b-m0.png"] {
        assert!(index.contains(&format!("<img src=\"{png}\"")), "{png}");
    }
    assert!(index.contains("none.gltf"));
    // Each sheet is a PNG of the size the layout gives: 4 columns + the difference for the
    // sheen and for the fuzz with a sheen, 3 + 1 for the fuzz alone; one furnace and one light
    // row.
    for (name, columns) in [
        ("a-m0-sheen.png", 4),
        ("a-m2-fuzz.png", 3),
        ("sub_b-m0.png", 4),
    ] {
        let bytes = &first.iter().find(|(n, _)| n == name).unwrap().1;
        let img = image::load_from_memory(bytes).unwrap();
        assert_eq!(
            img.width() as usize,
            sheet::LABEL_W + sheet::CELL * (columns + 1) + 8,
            "{name}"
        );
        assert!(img.height() as usize > 2 * sheet::CELL);
    }
}

#[test]
fn bad_inputs_give_an_error_naming_the_file_and_a_non_zero_status() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let missing = dir.path().join("nope.gltf");
    let o = run(&[&missing, Path::new("-o"), &out], "1");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("nope.gltf: no such file or folder"));
    assert!(!out.exists());

    let broken = write(dir.path(), "broken.gltf", "{\"asset\": ");
    let good = write(
        dir.path(),
        "good.gltf",
        &gltf(
            r#"{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.5}}}"#,
        ),
    );
    let o = run(&[&broken, &good, Path::new("-o"), &out], "1");
    assert_eq!(o.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("broken.gltf"), "{stderr}");
    // The good file's sheet is still written, and the index lists the failure.
    assert!(out.join("good-m0.png").is_file());
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(index.contains("broken.gltf"));

    // An output folder that cannot be made: status 1, the path named.
    let blocker = write(dir.path(), "file", "x");
    let o = run(&[&good, Path::new("-o"), &blocker.join("out")], "1");
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot create the folder"));
}

#[test]
fn migrate_in_place_with_preview_shows_the_materials_as_they_were_before() {
    let dir = tempfile::tempdir().unwrap();
    let asset = write(
        dir.path(),
        "chair.gltf",
        &gltf(
            r#"{"name": "cloth", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 0.5, 0.5], "sheenRoughnessFactor": 0.4}}}"#,
        ),
    );
    let out = dir.path().join("sheets");
    let o = Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(["migrate", "--in-place", "-q", "--preview"])
        .arg(&out)
        .arg(&asset)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The file now has fuzz …
    assert!(std::fs::read_to_string(&asset)
        .unwrap()
        .contains("KHR_materials_fuzz"));
    // … and the sheet shows the sheen it had, migrated.
    assert!(out.join("chair-m0-cloth.png").is_file());
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        index.contains("sheen → fuzz: migrate adds KHR_materials_fuzz"),
        "{index}"
    );
}

#[test]
fn switched_off_layers_alone_get_no_sheet() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "off.gltf",
        &gltf(
            r#"{"extensions": {"KHR_materials_fuzz": {"fuzzFactor": 0, "fuzzColorFactor": [1, 1, 1]}}},
               {"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0, 0, 0], "sheenRoughnessFactor": 0.5}}},
               {"extensions": {"KHR_materials_unlit": {}, "KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1]}}},
               {"extensions": {"KHR_materials_fuzz": {"fuzzFactor": 0.5}}}"#,
        ),
    );
    let materials = materials_of(&load(&path));
    let indices: Vec<usize> = materials.iter().map(|m| m.index).collect();
    assert_eq!(indices, [3]);
    assert!(materials[0].fuzz_roughness_assumed);
    assert_eq!(materials[0].factors.fuzz.unwrap().roughness, 0.5);
}

/// Migrates `path` with `options` into a folder of `dir` and returns the written document.
fn migrated_file(dir: &Path, path: &Path, options: &velvet::migrate::Options) -> serde_json::Value {
    let out = dir.join(format!("out-{:?}", options.roughness));
    let report = velvet::command::migrate::run(&velvet::command::migrate::Request {
        inputs: vec![path.to_path_buf()],
        destination: velvet::output::paths::Destination::Dir(out.clone()),
        options: options.clone(),
        dry_run: false,
        progress: false,
    })
    .unwrap();
    assert_eq!(report.files.len(), 1);
    let written = out.join(path.file_name().unwrap());
    serde_json::from_slice(&std::fs::read(written).unwrap()).unwrap()
}

#[test]
fn the_migrated_column_is_the_fuzz_migrate_writes_for_each_roughness_option() {
    // A sheen roughness of 0 (its best fuzz match lies below the floor, so migrate writes
    // 0.07), a roughness texture migrate cannot read (it copies the roughness then), the
    // pre-ratification draft (upgraded first), and a plain sheen.
    let dir = tempfile::tempdir().unwrap();
    let text = r#"{"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_materials_sheen"],
        "images": [{"uri": "missing.png"}], "textures": [{"source": 0}],
        "materials": [
          {"name": "smooth", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.8, 0.2, 0.2], "sheenRoughnessFactor": 0.0}}},
          {"name": "unreadable", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5], "sheenRoughnessFactor": 0.6, "sheenRoughnessTexture": {"index": 0}}}},
          {"name": "draft", "pbrMetallicRoughness": {"roughnessFactor": 0.4}, "extensions": {"KHR_materials_sheen": {"sheenFactor": 0.5, "sheenColor": [1.0, 0.5, 0.2]}}},
          {"name": "cloth", "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.9, 0.9], "sheenRoughnessFactor": 0.5}}}
        ]}"#;
    let path = write(dir.path(), "cases.gltf", text);
    let asset = load(&path);
    let mut sheets = Vec::new();
    for mapping in [
        velvet::migrate::roughness::RoughnessMapping::Fitted,
        velvet::migrate::roughness::RoughnessMapping::Identity,
    ] {
        let options = velvet::migrate::Options {
            roughness: mapping,
            ..velvet::migrate::Options::default()
        };
        let file = migrated_file(dir.path(), &path, &options);
        let materials = materials_with(&asset, &options);
        assert_eq!(materials.len(), 4, "every case has a sheet, the draft too");
        for m in &materials {
            assert_eq!(m.kind, Kind::SheenToFuzz, "{:?}", m.name);
            let fuzz = &file["materials"][m.index]["extensions"]["KHR_materials_fuzz"];
            let number = |key: &str| fuzz[key].as_f64().unwrap();
            let written = m.factors.written_fuzz.expect("the plan writes a fuzz");
            assert_eq!(written.weight, number("fuzzFactor"), "{:?}", m.name);
            assert_eq!(
                written.roughness,
                number("fuzzRoughnessFactor"),
                "{:?}",
                m.name
            );
            let color: Vec<f64> = fuzz["fuzzColorFactor"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_f64().unwrap())
                .collect();
            assert_eq!(written.color.to_vec(), color, "{:?}", m.name);
            let cols = columns(m, &m.factors);
            assert_eq!(
                cols[1].look.layer,
                Layer::Fuzz {
                    color: written.color,
                    weight: written.weight,
                    roughness: written.roughness
                }
            );
        }
        let roughness = |i: usize| materials[i].factors.written_fuzz.unwrap().roughness;
        // The floor, whatever the mapping: a fitted α(0) lies below it, a copied 0 too.
        assert_eq!(roughness(0), 0.07);
        // The unreadable texture: the roughness is copied, whatever the mapping asked.
        assert_eq!(roughness(1), 0.6);
        assert!(materials[1]
            .notes
            .iter()
            .any(|n| n.starts_with("sheenRoughnessTexture not read")));
        // The draft, as migrate upgrades it: sheenColor × sheenFactor, the material's roughness.
        let draft = materials[2].factors.sheen.unwrap();
        assert_eq!(draft.color, [0.5, 0.25, 0.1]);
        assert_eq!(draft.roughness, 0.4);
        sheets.push(sheet::to_png(&sheet::render("cases.gltf", &materials[3])));
        let expected = match mapping {
            velvet::migrate::roughness::RoughnessMapping::Fitted => {
                velvet::migrate::roughness::written(
                    velvet::shading::mapping::fuzz_roughness_for_sheen(0.5),
                )
            }
            velvet::migrate::roughness::RoughnessMapping::Identity => 0.5,
        };
        assert_eq!(roughness(3), expected);
    }
    assert_ne!(
        sheets[0], sheets[1],
        "--roughness identity shows another sheet"
    );
}

// ---------------------------------------------------------------- a library: sharing, ranking

fn run_velvet(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_velvet"))
        .args(args)
        .output()
        .expect("run velvet")
}

/// A sheen material named `name` with colour `c` and roughness `r`.
fn sheen(name: &str, c: f64, r: f64) -> String {
    format!(
        r#"{{"name": "{name}", "extensions": {{"KHR_materials_sheen": {{"sheenColorFactor": [{c}, {c}, {c}], "sheenRoughnessFactor": {r}}}}}}}"#
    )
}

/// The sheets (PNG files other than overview.png) in `dir`, sorted.
fn pngs(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") && n != "overview.png")
        .collect();
    names.sort();
    names
}

#[test]
fn materials_with_the_same_values_share_one_sheet_which_lists_them() {
    let dir = tempfile::tempdir().unwrap();
    let materials = [
        sheen("first", 0.8, 0.4),
        sheen("other", 0.3, 0.9),
        sheen("second", 0.8, 0.4),
    ]
    .join(", ");
    let input = write(dir.path(), "shared.gltf", &gltf(&materials));
    let plan = velvet::preview::plan(
        std::slice::from_ref(&input),
        &velvet::migrate::Options::default(),
    );
    assert_eq!(plan.entries.len(), 3);
    assert_eq!(plan.sheets.len(), 2);
    assert_eq!(plan.entries[0].sheet, plan.entries[2].sheet);
    assert_ne!(plan.entries[0].sheet, plan.entries[1].sheet);
    let shared = &plan.sheets[plan.entries[0].sheet];
    assert_eq!(shared.entries, [0, 2]);
    assert_eq!(shared.name, "shared-m0-first.png");
    assert_eq!(
        shared.title,
        "shared.gltf: material 0 \"first\" and 1 other material with the same values"
    );
    let out = dir.path().join("out");
    let o = run_velvet(&[
        "preview",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(pngs(&out), ["shared-m0-first.png", "shared-m1-other.png"]);
    // The overview: the histogram of the two sheets' verdicts and both sheets beside it.
    let overview = image::open(out.join("overview.png")).unwrap();
    assert!(overview.width() > 480 && overview.height() > 300);
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        index.contains("<li>shared.gltf: material 2 &quot;second&quot;</li>"),
        "{index}"
    );
    let summary = format!(
        "3 material(s) on 2 sheet(s), 2 drawn; index: {}\n",
        out.join("index.html").display()
    );
    assert!(String::from_utf8_lossy(&o.stdout).ends_with(&summary));
}

#[test]
fn worst_n_draws_exactly_the_n_sheets_the_plans_verdict_ranks_highest() {
    let dir = tempfile::tempdir().unwrap();
    // Roughness from very low (held at migrate's floor: a large difference) to high.
    let roughness = [0.9, 0.02, 0.5, 0.05, 0.3, 0.7, 0.1, 0.2];
    let materials: Vec<String> = roughness
        .iter()
        .enumerate()
        .map(|(i, r)| sheen(&format!("s{i}"), 0.9, *r))
        .collect();
    let input = write(dir.path(), "ranked.gltf", &gltf(&materials.join(", ")));
    // The plan's verdict on each material, measured here from its own columns.
    let asset = load(&input);
    let mut by_metric: Vec<(f64, String)> = materials_of(&asset)
        .iter()
        .map(|m| {
            (
                velvet::preview::verdict::measure_pairs(&velvet::preview::verdict::pairs(m)).flip,
                format!("ranked-m{}-{}.png", m.index, m.name.as_deref().unwrap()),
            )
        })
        .collect();
    by_metric.sort_by(|a, b| b.0.total_cmp(&a.0));
    assert!(
        by_metric[2].0 > by_metric[3].0,
        "{by_metric:?}: no tie at the cut"
    );
    let mut worst: Vec<String> = by_metric[..3].iter().map(|(_, n)| n.clone()).collect();
    worst.sort();
    let out = dir.path().join("out");
    let o = run_velvet(&[
        "preview",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--worst",
        "3",
    ]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(pngs(&out), worst);
    // The index shows them worst first, and lists the five left undrawn.
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    let at = |name: &str| index.find(&format!("<img src=\"{name}\"")).unwrap();
    assert!(at(&by_metric[0].1) < at(&by_metric[1].1) && at(&by_metric[1].1) < at(&by_metric[2].1));
    assert!(
        index.contains("<p>5 sheet(s) rank below those drawn"),
        "{index}"
    );
}

#[test]
fn a_library_larger_than_a_page_gets_pages_linked_from_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let materials: Vec<String> = (0..velvet::preview::index::PAGE + 5)
        .map(|i| sheen(&format!("m{i}"), 0.9, 0.3 + 0.6 * i as f64 / 200.0))
        .collect();
    let input = write(dir.path(), "lib.gltf", &gltf(&materials.join(", ")));
    let plan = velvet::preview::plan(&[input], &velvet::migrate::Options::default());
    let written = velvet::preview::write(&plan, &dir.path().join("out"), None, false).unwrap();
    assert_eq!(written.drawn.len(), velvet::preview::index::PAGE + 5);
    let names: Vec<_> = written
        .pages
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["index.html", "index-2.html"]);
    let first = std::fs::read_to_string(&written.pages[0]).unwrap();
    assert!(first.contains("<a href=\"index-2.html\">2</a>"));
    let second = std::fs::read_to_string(&written.pages[1]).unwrap();
    assert_eq!(second.matches("<section class=").count(), 5);
    // Worst first across the pages.
    let metrics: Vec<f64> = written
        .drawn
        .iter()
        .map(|d| plan.sheets[d.sheet].verdict.flip)
        .collect();
    assert!(metrics.windows(2).all(|w| w[0] >= w[1]));
}

#[test]
fn an_interrupted_preview_leaves_the_sheets_written_so_far_and_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let materials: Vec<String> = (0..400)
        .map(|i| sheen(&format!("m{i}"), 0.9, 0.1 + 0.8 * i as f64 / 400.0))
        .collect();
    let input = write(dir.path(), "lib.gltf", &gltf(&materials.join(", ")));
    let mut stopped = 0;
    for (k, (signal, delay_ms)) in [(libc::SIGINT, 400), (libc::SIGTERM, 900)]
        .into_iter()
        .enumerate()
    {
        let out = dir.path().join(format!("out-{k}"));
        let child = Command::new(env!("CARGO_BIN_EXE_velvet"))
            .args([
                "preview",
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        // SAFETY: kill(2) on the child's id, which it holds until it is waited for.
        unsafe { libc::kill(child.id() as libc::pid_t, signal) };
        let output = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&output.stderr);
        let files: Vec<String> = std::fs::read_dir(&out)
            .map(|d| {
                d.map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        // Every file there is a complete sheet, index.json or (after a finished run) an index
        // page.
        for name in &files {
            let path = out.join(name);
            if name.ends_with(".png") {
                image::open(&path).unwrap_or_else(|e| panic!("{name} is not whole: {e}"));
            } else {
                assert!(
                    name == "index.json" || (name.starts_with("index") && name.ends_with(".html")),
                    "{name}"
                );
            }
        }
        match output.status.code() {
            Some(0) => assert_eq!(pngs(&out).len(), 400),
            Some(code) if err.contains("while planning: nothing written") => {
                // Stopped before a sheet was drawn: nothing at all.
                assert_eq!(code, 128 + signal, "{err}");
                assert_eq!(files, Vec::<String>::new());
                stopped += 1;
            }
            Some(code) => {
                assert_eq!(code, 128 + signal, "{err}");
                assert!(
                    err.starts_with("velvet: stopped by SIG")
                        && err.contains("sheets written (each complete), listed in index.json"),
                    "{err}"
                );
                assert!(
                    files
                        .iter()
                        .all(|n| (n.ends_with(".png") && n != "overview.png") || n == "index.json"),
                    "{files:?}"
                );
                // The index of a stopped run lists exactly the sheets it finished.
                let index = std::fs::read_to_string(out.join("index.json")).unwrap();
                assert_eq!(velvet::preview::index::listed_sheets(&index), pngs(&out));
                assert!(pngs(&out).len() < 400);
                stopped += 1;
            }
            None => panic!("killed by a signal: {err}"),
        }
    }
    assert!(stopped > 0, "no run was stopped before it finished");
}

#[test]
fn a_name_with_accents_and_arrows_is_drawn_with_those_glyphs_in_its_own_case() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "names.gltf",
        &gltf(&sheen("Velouté → Fuzz & co", 0.8, 0.5)),
    );
    let m = &materials_of(&load(&input))[0];
    let title = "names.gltf: material 0 \"Velouté → Fuzz & co\"";
    let sheet = sheet::render(title, m);
    assert_eq!(sheet.summary.title, title);
    // The title's line as the sheet has it, and the string drawn alone on the background.
    let margin = sheet::MARGIN;
    let rows = margin..margin + velvet::preview::font::LINE_HEIGHT;
    let bg = f32::from(sheet::background_code());
    let mut expected = vec![sheet::background_code(); 3 * sheet.width * rows.len()];
    velvet::preview::font::draw(title, margin, 0, |x, y, coverage| {
        if x < sheet.width && y < rows.len() {
            for k in 0..3 {
                let over = f32::from(sheet::TEXT[k]);
                expected[3 * (y * sheet.width + x) + k] =
                    (bg + (over - bg) * coverage).round() as u8;
            }
        }
    });
    let drawn = &sheet.rgb[3 * sheet.width * rows.start..3 * sheet.width * rows.end];
    assert!(
        drawn == &expected[..],
        "the title's line is the string's own rendering"
    );
    // The accent, the arrow and the capitals are their own glyphs: the plain ASCII spelling
    // draws another line.
    let plain = sheet::render("names.gltf: material 0 \"veloute -> fuzz & co\"", m);
    assert!(
        plain.rgb[3 * plain.width * rows.start..3 * plain.width * rows.end] != *drawn,
        "é, → and capitals differ from e, -> and lower case"
    );
}

#[test]
fn the_verdict_metric_is_0_for_identical_renders_and_grows_with_a_roughness_difference() {
    let furnace = |roughness: f64| {
        // A dielectric base of glTF's defaults but for its colour.
        let look = Look {
            base: [0.1; 3],
            base_metallic: 0.0,
            base_roughness: 1.0,
            layer: Layer::Sheen {
                color: [0.9; 3],
                roughness,
            },
        };
        render_sphere(&Shaded::new(look), Light::Furnace, sheet::SPHERE)
    };
    let reference = furnace(0.5);
    let on: Vec<bool> = reference.coverage.iter().map(|&c| c > 0.5).collect();
    let reference = sheet::sphere_codes_clamped(&reference);
    assert_eq!(sheet::flip_p99(&reference, &reference, &on), 0.0);
    let flips: Vec<f64> = [0.45, 0.4, 0.3, 0.2]
        .iter()
        .map(|&r| sheet::flip_p99(&reference, &sheet::sphere_codes_clamped(&furnace(r)), &on))
        .collect();
    assert!(flips[0] > 0.0, "{flips:?}");
    assert!(flips.windows(2).all(|w| w[1] > w[0]), "{flips:?}");
}

#[test]
fn the_verdict_sends_a_floored_fallback_to_look_and_passes_a_good_match() {
    let dir = tempfile::tempdir().unwrap();
    // Over a dark base, a sheen of roughness 0.03 migrates to a fuzz that cannot follow its
    // sharp rim; one of 0.7 migrates to its fitted match.
    let dark = |name: &str, r: f64| {
        sheen(name, 1.0, r).replacen(
            "{",
            r#"{"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.1, 1]}, "#,
            1,
        )
    };
    let input = write(
        dir.path(),
        "verdicts.gltf",
        &gltf(&[dark("rough", 0.7), dark("sharp", 0.03)].join(", ")),
    );
    let m = materials_of(&load(&input));
    let good = sheet::render("good", &m[0]).summary;
    let sharp = sheet::render("sharp", &m[1]).summary;
    assert_ne!(
        good.verdict.label,
        sheet::Label::Visible,
        "{}",
        good.verdict_line()
    );
    assert!(good.flip[0] <= sheet::CLOSE_FLIP);
    assert_eq!(
        sharp.verdict.label,
        sheet::Label::Visible,
        "{}",
        sharp.verdict_line()
    );
    assert!(sharp.flip[0] > sheet::CLOSE_FLIP);
}

/// A material with a sheen over the base `pbr` (the JSON of pbrMetallicRoughness, or none).
fn sheen_over(name: &str, pbr: &str, sheen_color: f64, sheen_roughness: f64) -> String {
    let pbr = if pbr.is_empty() {
        String::new()
    } else {
        format!(r#""pbrMetallicRoughness": {pbr}, "#)
    };
    format!(
        r#"{{"name": "{name}", {pbr}"extensions": {{"KHR_materials_sheen": {{"sheenColorFactor": [{c}, {c}, {c}], "sheenRoughnessFactor": {sheen_roughness}}}}}}}"#,
        c = sheen_color
    )
}

#[test]
fn the_base_reads_metallic_and_roughness_from_factors_defaults_and_texture_means() {
    let dir = tempfile::tempdir().unwrap();
    // Green (roughness) 128 and 64, blue (metallic) 255 and 0, linear: means 96/255 and 1/2.
    let mr = png_data_uri(&[[0, 128, 255, 255], [0, 64, 0, 255]]);
    let materials = [
        sheen_over(
            "metal",
            r#"{"baseColorFactor": [0.8, 0.6, 0.2, 1], "metallicFactor": 1, "roughnessFactor": 0.2}"#,
            0.5,
            0.5,
        ),
        sheen_over(
            "plastic",
            r#"{"baseColorFactor": [0.8, 0.6, 0.2, 1], "metallicFactor": 0, "roughnessFactor": 0.2}"#,
            0.5,
            0.5,
        ),
        sheen_over("defaults", "", 0.5, 0.5),
        sheen_over(
            "textured",
            r#"{"metallicFactor": 0.5, "roughnessFactor": 0.8, "metallicRoughnessTexture": {"index": 0}}"#,
            0.5,
            0.5,
        ),
        sheen_over(
            "missing",
            r#"{"metallicFactor": 0.25, "roughnessFactor": 0.75, "metallicRoughnessTexture": {"index": 1}}"#,
            0.5,
            0.5,
        ),
    ]
    .join(", ");
    let text = format!(
        r#"{{"asset": {{"version": "2.0"}}, "extensionsUsed": ["KHR_materials_sheen"],
            "images": [{{"uri": "{mr}"}}, {{"uri": "missing.png"}}],
            "textures": [{{"source": 0}}, {{"source": 1}}],
            "materials": [{materials}]}}"#
    );
    let path = write(dir.path(), "bases.gltf", &text);
    let m = materials_of(&load(&path));
    assert_eq!(m.len(), 5);
    let params: Vec<(f64, f64)> = m
        .iter()
        .map(|m| (m.base_metallic, m.base_roughness))
        .collect();
    assert_eq!(params[0], (1.0, 0.2));
    assert_eq!(params[1], (0.0, 0.2));
    // The glTF 2.0 schema's defaults.
    assert_eq!(params[2], (1.0, 1.0));
    assert!((params[3].0 - 0.25).abs() < 1e-12, "{:?}", params[3]);
    assert!(
        (params[3].1 - 0.8 * 96.0 / 255.0).abs() < 1e-12,
        "{:?}",
        params[3]
    );
    assert!(m[3].notes.is_empty(), "{:?}", m[3].notes);
    // A texture that cannot be read leaves the factors, and a note says so.
    assert_eq!(params[4], (0.25, 0.75));
    assert!(m[4]
        .notes
        .iter()
        .any(|n| n.starts_with("metallicRoughnessTexture not read")
            && n.contains("missing.png")
            && n.ends_with("the base is metallicFactor and roughnessFactor alone")));
    // The base is part of the appearance: the metal and the plastic do not share a sheet.
    assert_ne!(m[0].appearance(), m[1].appearance());
    // Their spheres differ, under both lights, in every column.
    let (metal, plastic) = (columns(&m[0], &m[0].factors), columns(&m[1], &m[1].factors));
    assert_eq!(metal.len(), plastic.len());
    for light in [Light::Furnace, Light::Directional] {
        for (a, b) in metal.iter().zip(&plastic) {
            let draw = |look| sphere_codes(&render_sphere(&Shaded::new(look), light, 48));
            assert_ne!(draw(a.look), draw(b.look), "{} under {light:?}", a.title);
        }
    }
}

#[test]
fn a_metal_base_reflects_its_colour_where_a_dielectric_diffuses_it() {
    let colour = [0.8, 0.6, 0.2];
    let bare = |metallic: f64| {
        Shaded::new(Look {
            base: colour,
            base_metallic: metallic,
            base_roughness: 0.2,
            layer: Layer::None,
        })
    };
    let (metal, dielectric) = (bare(1.0), bare(0.0));
    // Normal incidence, roughness 0.2: the metal's albedo is F(f0 = colour) ≈ colour, within
    // 5e-3 (Schlick's weight over the narrow lobe and the shadowing lose a little); the
    // dielectric's is 0.04 of white specular plus the colour times the Fresnel-weighted diffuse
    // 1 − F̄, F̄ the hemisphere's mean of F(0.04), between 0.04 and 0.1.
    let (m, d) = (metal.furnace(1.0), dielectric.furnace(1.0));
    let ones = vec![1.0; 400];
    let here: Vec<[f64; 2]> = (0..3)
        .map(|k| {
            [1.0, 0.0].map(|metallic| base_integrated_here(1.0, colour[k], metallic, 0.2, &ones))
        })
        .collect();
    for k in 0..3 {
        assert!((m[k] - colour[k]).abs() < 5e-3, "metal {m:?}");
        let diffuse = d[k] - 0.04;
        assert!(
            diffuse > 0.9 * colour[k] - 5e-3 && diffuse < 0.96 * colour[k] + 5e-3,
            "dielectric {d:?}"
        );
        // The same values from the spec's BRDF integrated here.
        for (i, shaded) in [&metal, &dielectric].into_iter().enumerate() {
            let got = shaded.furnace(1.0)[k];
            assert!((got - here[k][i]).abs() < 2e-3, "{got} vs {}", here[k][i]);
        }
    }
    // The blue channel, dark in the colour: the metal keeps it dark, the dielectric's white
    // specular adds to it at grazing views.
    assert!(metal.furnace(0.1)[2] < dielectric.furnace(0.1)[2] + 0.3);
    // Under the light the metal's highlight is far above the dielectric's.
    let l = velvet::preview::shade::SUN_DIRECTION;
    let h = {
        let s = [l[0], l[1], l[2] + 1.0];
        let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        s.map(|c| c / n)
    };
    let (mh, dh) = (
        metal.radiance(h, Light::Directional),
        dielectric.radiance(h, Light::Directional),
    );
    assert!(mh[0] > 5.0 * dh[0], "{mh:?} vs {dh:?}");
}

#[test]
fn smooth_bases_and_grazing_views_shade_without_nan() {
    for metallic in [0.0, 1.0] {
        for roughness in [0.0, 1e-9, 0.01] {
            let shaded = Shaded::new(Look {
                base: [0.9, 0.5, 0.1],
                base_metallic: metallic,
                base_roughness: roughness,
                layer: Layer::Sheen {
                    color: [1.0; 3],
                    roughness: 0.07,
                },
            });
            for light in [Light::Furnace, Light::Directional] {
                let sphere = render_sphere(&shaded, light, 96);
                assert!(sphere
                    .radiance
                    .iter()
                    .flatten()
                    .all(|v| v.is_finite() && *v >= 0.0));
            }
            for mu in [0.0, 1e-12, 1e-3] {
                assert!(shaded.furnace(mu).iter().all(|v| v.is_finite()));
            }
        }
    }
}

#[test]
fn a_sheen_above_one_at_grazing_views_is_marked_and_noted() {
    let dir = tempfile::tempdir().unwrap();
    // Sheen roughness 0.07, white: E(0.045, 0.07) ≈ 1.20, over a dark rough dielectric.
    let path = write(
        dir.path(),
        "bright.gltf",
        &gltf(&sheen_over(
            "bright rim",
            r#"{"baseColorFactor": [0.05, 0.05, 0.05, 1], "metallicFactor": 0, "roughnessFactor": 1}"#,
            1.0,
            0.07,
        )),
    );
    let m = &materials_of(&load(&path))[0];
    let cols = columns(m, &m.factors);
    let shaded = Shaded::new(cols[0].look);
    assert!(shaded.reflectance_at(0.045) > 1.15);
    let sphere = render_sphere(&shaded, Light::Furnace, sheet::SPHERE);
    let (count, top) = sheet::pixels_above_one(&sphere);
    assert!(count > 0 && top > 1.0, "{count} {top}");
    // Each pixel above 1 is drawn with the hatch; no other pixel has the hatch's magenta.
    let codes = sphere_codes(&sphere);
    let clamped = sheet::sphere_codes_clamped(&sphere);
    let mut marked = 0;
    for (i, rad) in sphere.radiance.iter().enumerate() {
        if sphere.coverage[i] > 0.0 && sheet::above_one(*rad) {
            assert!(sheet::MARK.contains(&codes[i]), "pixel {i}: {:?}", codes[i]);
            marked += 1;
        } else {
            assert_eq!(codes[i], clamped[i]);
            assert_ne!(codes[i], sheet::MARK[0]);
        }
    }
    assert_eq!(marked, count);
    // The sheet says so, for column 1 in the furnace.
    let sheet = sheet::render("bright.gltf", m);
    let note = sheet
        .summary
        .notes
        .iter()
        .find(|n| n.starts_with("column 1 (authored: sheen r 0.070) in the furnace: "))
        .unwrap_or_else(|| panic!("{:?}", sheet.summary.notes));
    assert!(
        note.contains(&format!("{count} pixel(s) above 1 in linear light"))
            && note.ends_with("they are drawn with a magenta and black hatch, not clipped"),
        "{note}"
    );
    // A base without a bright layer gets no such note.
    let dull = Shaded::new(Look {
        layer: Layer::None,
        ..cols[0].look
    });
    assert_eq!(
        sheet::pixels_above_one(&render_sphere(&dull, Light::Furnace, sheet::SPHERE)).0,
        0
    );
}

#[test]
fn migrate_preview_draws_the_plans_migrate_wrote_and_no_sheet_for_a_file_it_refused() {
    let dir = tempfile::tempdir().unwrap();
    let good = write(dir.path(), "good.gltf", &gltf(&sheen("cloth", 0.8, 0.5)));
    // A sheen colour texture naming a texture the asset lacks: migrate refuses the file.
    let refused = write(
        dir.path(),
        "dangling.gltf",
        &gltf(
            r#"{"extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 1, 1], "sheenColorTexture": {"index": 4}}}}"#,
        ),
    );
    let sheets = dir.path().join("sheets");
    let o = run_velvet(&[
        "migrate",
        good.to_str().unwrap(),
        refused.to_str().unwrap(),
        "--out-dir",
        dir.path().join("out").to_str().unwrap(),
        "--preview",
        sheets.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("velvet: preview: ")
            && err.contains("dangling.gltf")
            && err.contains("cannot be migrated"),
        "{err}"
    );
    assert_eq!(pngs(&sheets), ["good-m0-cloth.png"]);
}

#[test]
fn every_fixture_material_gets_from_the_preview_the_verdict_migrate_reports() {
    use velvet::command::migrate::{self as migrating, FileOutcome};
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/migrate");
    let report = migrating::run(&migrating::Request {
        inputs: vec![fixtures.clone()],
        destination: velvet::output::paths::Destination::None,
        options: velvet::migrate::Options::default(),
        dry_run: true,
        progress: false,
    })
    .unwrap();
    let preview = velvet::preview::plan(&[fixtures], &velvet::migrate::Options::default());
    let mut labels = Vec::new();
    for entry in &preview.entries {
        let file = report
            .files
            .iter()
            .find(|f| f.input == entry.file)
            .expect("migrate planned every file the preview read");
        assert!(matches!(file.outcome, FileOutcome::Planned { .. }));
        let planned = file
            .detail
            .materials
            .iter()
            .find(|m| m.index == entry.index)
            .and_then(|m| m.verdict)
            .expect("a verdict on every material a sheet shows");
        let sheet = &preview.sheets[entry.sheet];
        assert_eq!(planned, sheet.verdict, "{}", entry.title());
        // The sheet drawn says the plan's word.
        let drawn = sheet::render(&sheet.title, &sheet.material);
        assert_eq!(drawn.summary.verdict, planned, "{}", entry.title());
        labels.push(format!("{} {}", entry.title(), planned.label.as_str()));
    }
    assert_eq!(
        labels,
        [
            "both-refresh.expected.gltf: material 0 \"stale\" close",
            "both-refresh.expected.gltf: material 1 \"up to date\" close",
            "both-refresh.expected.gltf: material 2 \"legacy fallback\" visible",
            "both-refresh.gltf: material 0 \"stale\" visible",
            "both-refresh.gltf: material 1 \"up to date\" close",
            "both-refresh.gltf: material 2 \"legacy fallback\" visible",
            "both.gltf: material 0 \"both\" close",
            "clearcoat.expected.gltf: material 0 \"coated sheen\" close",
            "clearcoat.expected.gltf: material 1 \"coated fuzz\" close",
            "clearcoat.gltf: material 0 \"coated sheen\" close",
            "clearcoat.gltf: material 1 \"coated fuzz\" close",
            "fuzz-only.expected.gltf: material 0 \"half white\" close",
            "fuzz-only.expected.gltf: material 1 \"dark over bright\" visible",
            "fuzz-only.expected.gltf: material 2 \"no roughness\" close",
            "fuzz-only.expected.gltf: material 4 \"defaults\" close",
            "fuzz-only.expected.gltf: material 5 \"black\" visible",
            "fuzz-only.gltf: material 0 \"half white\" close",
            "fuzz-only.gltf: material 1 \"dark over bright\" visible",
            "fuzz-only.gltf: material 2 \"no roughness\" close",
            "fuzz-only.gltf: material 4 \"defaults\" close",
            "fuzz-only.gltf: material 5 \"black\" visible",
            "fuzz-textures.expected.gltf: material 0 \"colour and roughness textures\" visible",
            "fuzz-textures.expected.gltf: material 1 \"intensity texture\" visible",
            "fuzz-textures.expected.gltf: material 2 \"different sets\" visible",
            "fuzz-textures.expected.gltf: material 3 \"same set\" visible",
            "fuzz-textures.gltf: material 0 \"colour and roughness textures\" visible",
            "fuzz-textures.gltf: material 1 \"intensity texture\" close",
            "fuzz-textures.gltf: material 2 \"different sets\" visible",
            "fuzz-textures.gltf: material 3 \"same set\" close",
            "legacy-texcoord.expected.gltf: material 0 \"every primitive has TEXCOORD_1\" visible",
            "legacy-texcoord.expected.gltf: material 1 \"one primitive lacks TEXCOORD_1\" close",
            "legacy-texcoord.gltf: material 0 \"every primitive has TEXCOORD_1\" close",
            "legacy-texcoord.gltf: material 1 \"one primitive lacks TEXCOORD_1\" close",
            "legacy.expected.gltf: material 0 \"clamped\" visible",
            "legacy.expected.gltf: material 1 \"factor only\" close",
            "legacy.expected.gltf: material 3 \"mixed\" close",
            "legacy.expected.gltf: material 4 \"dangling texture\" close",
            "legacy.gltf: material 0 \"clamped\" close",
            "legacy.gltf: material 1 \"factor only\" close",
            "legacy.gltf: material 3 \"mixed\" close",
            "legacy.gltf: material 4 \"dangling texture\" close",
            "minified.expected.gltf: material 0 \"m\" same",
            "minified.gltf: material 0 \"m\" same",
            "sheen-factors.expected.gltf: material 0 \"champagne\" close",
            "sheen-factors.expected.gltf: material 1 \"navy\" close",
            "sheen-factors.expected.gltf: material 2 \"pale\" close",
            "sheen-factors.gltf: material 0 \"champagne\" close",
            "sheen-factors.gltf: material 1 \"navy\" close",
            "sheen-factors.gltf: material 2 \"pale\" close",
            "sheen-textures.expected.gltf: material 0 \"cloth\" visible",
            "sheen-textures.expected.gltf: material 1 \"tinted\" same",
            "sheen-textures.gltf: material 0 \"cloth\" close",
            "sheen-textures.gltf: material 1 \"tinted\" same",
            "undeclared.expected.gltf: material 0 \"m\" same",
            "undeclared.gltf: material 0 \"m\" same",
        ]
    );
}

#[test]
fn index_json_lists_every_material_with_its_verdict_and_a_rerun_removes_only_the_sheets_it_listed()
{
    let dir = tempfile::tempdir().unwrap();
    let roughness = [0.9, 0.02, 0.5, 0.3];
    let materials: Vec<String> = roughness
        .iter()
        .enumerate()
        .map(|(i, r)| sheen(&format!("s{i}"), 0.9, *r))
        .collect();
    let input = write(dir.path(), "ranked.gltf", &gltf(&materials.join(", ")));
    let out = dir.path().join("out");
    let plan = velvet::preview::plan(
        std::slice::from_ref(&input),
        &velvet::migrate::Options::default(),
    );
    let written = velvet::preview::write(&plan, &out, None, false).unwrap();
    assert_eq!(written.index_json, Some(out.join("index.json")));
    let index: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("index.json")).unwrap()).unwrap();
    let records = index["sheets"].as_array().unwrap();
    assert_eq!(records.len(), 4);
    // In the pages' order, each with its sheet, the plan's verdict and the values as written.
    for (record, sheet) in records.iter().zip(&plan.sheets) {
        let entry = &plan.entries[sheet.entries[0]];
        let fuzz = sheet.material.factors.written_fuzz.unwrap();
        let kept = sheet.material.factors.written_sheen.unwrap();
        assert_eq!(
            record,
            &serde_json::json!({
                "file": sheet.name,
                "asset": "ranked.gltf",
                "material": entry.index,
                "name": entry.name,
                "label": sheet.verdict.label.as_str(),
                "flip": sheet.verdict.flip,
                "furnace": sheet.verdict.furnace,
                "light": sheet.verdict.light,
                "drawn": true,
                "written": {
                    "sheen": {"color": kept.color, "roughness": kept.roughness},
                    "fuzz": {"weight": fuzz.weight, "color": fuzz.color, "roughness": fuzz.roughness},
                },
            })
        );
        assert!(out.join(&sheet.name).is_file());
    }
    let flips: Vec<f64> = records
        .iter()
        .map(|r| r["flip"].as_f64().unwrap())
        .collect();
    assert!(flips.windows(2).all(|w| w[0] >= w[1]), "{flips:?}");
    // A file velvet did not write stays; a rerun drawing the worst sheet alone removes the
    // three others, and lists them undrawn.
    std::fs::write(out.join("mine.png"), b"not velvet's").unwrap();
    let again = velvet::preview::write(&plan, &out, Some(1), false).unwrap();
    let mut removed: Vec<String> = again
        .removed
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    removed.sort();
    let mut others: Vec<String> = plan.sheets[1..].iter().map(|s| s.name.clone()).collect();
    others.sort();
    assert_eq!(removed, others);
    let mut left = vec![plan.sheets[0].name.clone(), "mine.png".to_string()];
    left.sort();
    assert_eq!(pngs(&out), left);
    let index = std::fs::read_to_string(out.join("index.json")).unwrap();
    assert_eq!(
        velvet::preview::index::listed_sheets(&index),
        [plan.sheets[0].name.clone()]
    );
    let drawn: Vec<bool> = serde_json::from_str::<serde_json::Value>(&index).unwrap()["sheets"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["drawn"].as_bool().unwrap())
        .collect();
    assert_eq!(drawn, [true, false, false, false]);
}

#[test]
fn with_fast_a_copied_roughness_texture_is_labelled_copied_not_fitted() {
    let dir = tempfile::tempdir().unwrap();
    let rough: Vec<[u8; 4]> = (0..4).map(|i| [255, 255, 255, (i * 60) as u8]).collect();
    let text = format!(
        r#"{{"asset": {{"version": "2.0"}},
            "images": [{{"uri": "{}"}}],
            "textures": [{{"source": 0}}],
            "materials": [{{"name": "textured",
              "extensions": {{"KHR_materials_sheen": {{"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": 0.5,
                  "sheenRoughnessTexture": {{"index": 0}}}}}}}}]}}"#,
        png_data_uri(&rough)
    );
    let path = write(dir.path(), "fast.gltf", &text);
    let asset = load(&path);
    let fast = &materials_with(
        &asset,
        &velvet::migrate::Options {
            fast: true,
            ..velvet::migrate::Options::default()
        },
    )[0];
    assert!(fast.roughness_copied_by_fast);
    assert_eq!(
        columns(fast, &fast.factors)[1].detail,
        "α 0.500 copied (--fast)"
    );
    let fitted = &materials_of(&asset)[0];
    assert!(!fitted.roughness_copied_by_fast);
    assert!(columns(fitted, &fitted.factors)[1]
        .detail
        .ends_with(" fitted"));
}

#[test]
fn the_index_page_shows_each_sheet_by_its_verdict_and_input_order_without_a_script() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = run_velvet(&["preview", "fixtures/migrate/", "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(!html.contains("<script"));
    let index: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("index.json")).unwrap()).unwrap();
    // Each drawn sheet's label, from index.json (a record per material; a sheet once).
    let mut labels: Vec<(String, String)> = Vec::new();
    for s in index["sheets"].as_array().unwrap() {
        let file = s["file"].as_str().unwrap().to_string();
        if s["drawn"] == true && !labels.iter().any(|(f, _)| *f == file) {
            labels.push((file, s["label"].as_str().unwrap().to_string()));
        }
    }
    // The page's sections, in order: their class is the label, and each shows its sheet.
    let sections: Vec<&str> = html.split("<section class=\"").skip(1).collect();
    assert_eq!(sections.len(), labels.len().min(100));
    for (section, (file, label)) in sections.iter().zip(&labels) {
        assert!(
            section.starts_with(&format!("{label}\" style=\"--input: ")),
            "{section}"
        );
        assert!(
            section.contains(&format!("<img src=\"{file}\"")),
            "{file}: {section}"
        );
    }
    for label in ["visible", "close", "same"] {
        let n = labels.iter().filter(|(_, l)| l == label).count();
        assert!(
            html.contains(&format!(
                "<label for=\"show-{label}\">{label} ({n})</label>"
            )),
            "{label}: {n}"
        );
        assert!(html.contains(&format!(
            "<input type=\"radio\" name=\"show\" id=\"show-{label}\">"
        )));
        assert!(html.contains(&format!(
            "#show-{label}:checked ~ .sheets section:not(.{label})"
        )));
    }
    assert!(html.contains("#order-input:checked ~ .sheets section { order: var(--input); }"));
}
