//! One material's contact sheet: the spheres of its columns (see `material.rs`) under the
//! white furnace and the directional light, one row pair per swatch, the difference between
//! the authored column and column 1 (|codes| per channel, times [`DIFF_GAIN`]), and the
//! report's figures with a verdict, printed in the built-in font. Values are composited over
//! the background in linear light, clamped into [0, 1], sRGB-encoded (`bake::srgb`) and
//! quantised to 8 bits at the end; the PNG encoding is deterministic.
//!
//! The figures are the ones `migrate --report` gives, from the same functions, at the
//! material's factors: `shading::mapping::layer_match_with` (|max3·E − w·R| over view angles,
//! its maximum and cosine-weighted rms) and `shading::layering::compare_base_attenuation` (the
//! largest base-attenuation difference and its view cosine), with E and R by quadrature as the
//! report has them.
//!
//! The label is the plan's verdict (`preview::verdict`, measured on small renders of the same
//! columns, written into migrate's plan), so a sheet never says another word than migrate's
//! report and the run's ranking; the sheet adds its own full-size ꟻLIP beside it, which may
//! differ a little from the plan's. The verdict is NVIDIA's ꟻLIP (Andersson et al. 2020, an
//! image-difference metric made for rendered images: per pixel an error in [0, 1] from colour
//! and edge differences as a viewer sees them, at a sheet's size ꟻLIP's default 67 pixels per
//! degree), between the authored column and
//! column 1 in the white furnace, pooled as the 99th percentile over the sphere's pixels (the
//! largest over the swatches): a change over at least 1 % of the sphere counts, a stray pixel
//! does not. At most [`SAME_FLIP`] is "same to the eye", at most [`CLOSE_FLIP`] "close", above
//! it "visible". The furnace is what the layers' energy decides; under the directional light
//! the Charlie sheen lobe and the fuzz lobe differ in shape for every pair, so its ꟻLIP is
//! printed beside the verdict but does not decide it. The thresholds were calibrated on the
//! public sample assets with `examples/verdict_calibration.rs` (docs/preview.md has the
//! figures): conversions the mapping matches well stay at or below 0.22 (0.04–0.13 over a
//! dark base, up to 0.214 for a white layer over a white base, where the layers' different
//! base attenuation moves a third of the sphere by 10–16 codes), while materials whose layer
//! really changes (the fallback sheen held at migrate's roughness floor over a dark base, a
//! dark fuzz colour whose fallback cannot darken the base alike, a broad change of energy)
//! reach 0.22–0.72. Over a bright base the furnace hides a sharp rim (everything is near
//! white there), which the light row shows. A sheen roughness below 0.1 (no fuzz roughness
//! matches it) is flagged beside it.

use super::font::{self, LINE_HEIGHT};
use super::material::{columns, layer_pair, Column, Kind, Material};
use super::shade::{render_sphere, Light, Look, Shaded, Sphere};
use crate::bake::srgb;
use crate::shading::charlie::clamp01;
use crate::shading::layering::{
    compare_base_attenuation, FuzzReflectance, LayerReflectance, SheenAlbedo,
};
use crate::shading::mapping::{layer_match_with, POOR_MATCH_BELOW};
use crate::shading::{AlbedoMethod, ReflectanceMethod};
use rayon::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

/// A layer reflectance that remembers its values: the report's comparisons of one sheet
/// evaluate the same (μ, roughness) more than once, and the sheets of a library share
/// roughness values (a sweep, a family of fabrics). One memo per layer serves the whole
/// process, emptied when it reaches [`MEMO_VALUES`] values. A value is a function of its
/// inputs alone, so which task computes it first, and whether it was remembered, does not
/// change it.
struct Memo<R> {
    inner: R,
    values: Mutex<HashMap<(u64, u64), f64>>,
}

/// The most values a [`Memo`] holds (about 5 MB): 97 view cosines each for some 2,000
/// roughness values.
const MEMO_VALUES: usize = 200_000;

impl<R: LayerReflectance> Memo<R> {
    fn new(inner: R) -> Self {
        Memo {
            inner,
            values: Mutex::new(HashMap::new()),
        }
    }
}

/// The process's memos of the report's E and R (quadrature at the report's tolerance).
fn figure_memos() -> &'static (Memo<SheenAlbedo>, Memo<FuzzReflectance>) {
    static MEMOS: OnceLock<(Memo<SheenAlbedo>, Memo<FuzzReflectance>)> = OnceLock::new();
    MEMOS.get_or_init(|| {
        (
            Memo::new(SheenAlbedo(AlbedoMethod::Quadrature)),
            Memo::new(FuzzReflectance(ReflectanceMethod::Quadrature)),
        )
    })
}

impl<R: LayerReflectance> LayerReflectance for Memo<R> {
    fn name(&self) -> String {
        self.inner.name()
    }

    fn reflectance(&self, mu: f64, roughness: f64) -> f64 {
        let key = (mu.to_bits(), roughness.to_bits());
        let known = self
            .values
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .get(&key)
            .copied();
        known.unwrap_or_else(|| {
            let v = self.inner.reflectance(mu, roughness);
            let mut values = self.values.lock().unwrap_or_else(|e| e.into_inner());
            if values.len() >= MEMO_VALUES {
                values.clear();
            }
            values.insert(key, v);
            v
        })
    }
}

/// Sphere diameter in pixels.
pub const SPHERE: usize = 96;
/// Width and height of one cell (a sphere and its padding).
pub const CELL: usize = 112;
/// Width of the row labels on the left.
pub const LABEL_W: usize = 72;
/// Space around the sheet's contents; the title starts here, at (MARGIN, MARGIN).
pub const MARGIN: usize = 8;
/// Gain of the difference image: a difference of one code shows as DIFF_GAIN codes.
pub const DIFF_GAIN: u32 = 8;
pub use crate::migrate::verdict::{Label, CLOSE_FLIP, SAME_FLIP};
/// Background behind the spheres, linear.
const BACKGROUND: f64 = 0.03;
/// The colour of the text (sRGB codes), drawn over [`background_code`].
pub const TEXT: [u8; 3] = [235, 235, 235];
const DIM_TEXT: [u8; 3] = [170, 170, 170];

/// The words of a sheet, for its index entry.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    pub title: String,
    pub kind: &'static str,
    pub columns: Vec<String>,
    /// The report's figures, one line per comparison.
    pub figures: Vec<String>,
    /// Largest difference between columns 0 and 1, in codes: furnace, directional light.
    pub max_codes: [u8; 2],
    /// ꟻLIP between columns 0 and 1 on this sheet's full-size spheres, the 99th percentile over
    /// the sphere (the largest over the swatches): furnace, directional light.
    pub flip: [f64; 2],
    /// The plan's verdict, which gives the sheet its label.
    pub verdict: crate::migrate::verdict::Verdict,
    /// The sheen roughness lies below 0.1, where no fuzz roughness matches it.
    pub poor_match: bool,
    pub notes: Vec<String>,
}

impl Summary {
    /// The verdict line as printed.
    pub fn verdict_line(&self) -> String {
        let mut line = format!(
            "verdict: {} ({} vs {}: ꟻLIP {:.3} in the furnace, where at most {SAME_FLIP:.2} is \
             the same and at most {CLOSE_FLIP:.2} close; {:.3} under the light, where the lobes' \
             shapes differ for every pair; on this sheet's full-size spheres ꟻLIP {:.3} and \
             {:.3}, at most {} codes apart in the furnace, {} under the light)",
            self.verdict.label.text(),
            self.columns[0],
            self.columns.get(1).map_or("", String::as_str),
            self.verdict.furnace,
            self.verdict.light,
            self.flip[0],
            self.flip[1],
            self.max_codes[0],
            self.max_codes[1]
        );
        if self.poor_match {
            line += &format!(
                "; sheen roughness below {POOR_MATCH_BELOW}: no fuzz roughness matches it well"
            );
        }
        line
    }
}

/// A rendered sheet: 8-bit sRGB pixels, row by row, and its words.
#[derive(Clone, Debug, PartialEq)]
pub struct Sheet {
    pub width: usize,
    pub height: usize,
    pub rgb: Vec<u8>,
    pub summary: Summary,
    /// Where the column headings start (two lines), on the sheet.
    pub headings_top: usize,
    /// Where the spheres' grid starts, on the sheet: per swatch a furnace row and a light row,
    /// each [`CELL`] high.
    pub grid_top: usize,
    /// How many swatches the grid has rows for.
    pub swatches: usize,
}

fn kind_text(kind: Kind) -> &'static str {
    match kind {
        Kind::SheenToFuzz => {
            "sheen → fuzz: migrate adds KHR_materials_fuzz and keeps the sheen as the fallback"
        }
        Kind::FuzzFallback => "fuzz: migrate adds a fallback sheen for loaders without fuzz",
        Kind::FuzzWithSheen => {
            "fuzz and sheen: migrate leaves both; --refresh-fallback would write the refreshed sheen"
        }
    }
}

/// The sheet's background around the cells, an sRGB code (each channel).
pub fn background_code() -> u8 {
    encode(BACKGROUND) / 2
}

/// The two colours of the hatch that marks a sphere pixel above 1 (sRGB codes): diagonal
/// stripes two pixels wide, magenta and black, so that the mark shows on any colour. A pixel
/// whose linear value exceeds 1 (a sheen whose E exceeds 1 at grazing views, a metal's
/// highlight) cannot be shown; it is drawn hatched instead of clipping silently, and a note
/// under the sheet gives their number per column and light. The difference image and the
/// verdict read the clamped values.
pub const MARK: [[u8; 3]; 2] = [[255, 0, 255], [0, 0, 0]];

/// Whether a pixel's linear value exceeds 1 in any channel (it cannot be shown: clamped, it
/// would clip silently).
pub fn above_one(radiance: [f64; 3]) -> bool {
    radiance.iter().any(|&v| v > 1.0)
}

/// The hatch colour at pixel `i` of a sphere of `size` pixels a side.
fn mark_at(size: usize, i: usize) -> [u8; 3] {
    let (x, y) = (i % size, i / size);
    MARK[((x + y) / 2) % 2]
}

/// 8-bit sRGB codes of a sphere composited over the background, clamped into [0, 1] (what the
/// difference image and the verdict read).
pub fn sphere_codes_clamped(sphere: &Sphere) -> Vec<[u8; 3]> {
    sphere
        .radiance
        .iter()
        .zip(&sphere.coverage)
        .map(|(rad, &c)| rad.map(|v| encode(c * clamp01(v) + (1.0 - c) * BACKGROUND)))
        .collect()
}

/// 8-bit sRGB codes of a sphere as drawn: composited over the background, and each pixel the
/// sphere covers whose linear value exceeds 1 in any channel marked with the [`MARK`] hatch.
pub fn sphere_codes(sphere: &Sphere) -> Vec<[u8; 3]> {
    marked(sphere, sphere_codes_clamped(sphere))
}

/// `codes` (the sphere's clamped codes) with the pixels above 1 marked.
fn marked(sphere: &Sphere, mut codes: Vec<[u8; 3]>) -> Vec<[u8; 3]> {
    for (i, (rad, &c)) in sphere.radiance.iter().zip(&sphere.coverage).enumerate() {
        if c > 0.0 && above_one(*rad) {
            codes[i] = mark_at(sphere.size, i);
        }
    }
    codes
}

/// How many pixels the sphere covers whose linear value exceeds 1, and the largest value.
pub fn pixels_above_one(sphere: &Sphere) -> (usize, f64) {
    sphere
        .radiance
        .iter()
        .zip(&sphere.coverage)
        .filter(|(rad, &c)| c > 0.0 && above_one(**rad))
        .fold((0, 1.0), |(n, top), (rad, _)| {
            (n + 1, rad.iter().fold(top, |t, &v| t.max(v)))
        })
}

/// The notes on the pixels above 1, one per column and light that has any: how many (over the
/// swatches' rows), the largest value, and that they are marked.
fn above_one_notes(
    rows: &[(usize, Light)],
    rendered: &[Vec<Sphere>],
    headed: &[Column],
    labels: &[&str],
) -> Vec<String> {
    let mut notes = Vec::new();
    for light in [Light::Furnace, Light::Directional] {
        for (j, column) in headed.iter().enumerate() {
            let mut total = 0;
            let mut top: f64 = 1.0;
            let mut per_row = Vec::new();
            for (r, &(s, l)) in rows.iter().enumerate() {
                if l != light {
                    continue;
                }
                let (n, t) = rendered[r].get(j).map_or((0, 1.0), pixels_above_one);
                total += n;
                top = top.max(t);
                per_row.push(format!("{} {n}", labels[s]));
            }
            if total == 0 {
                continue;
            }
            let light_words = match light {
                Light::Furnace => "in the furnace",
                Light::Directional => "under the light",
            };
            let rows_words = if per_row.len() > 1 {
                format!(" (rows {})", per_row.join(", "))
            } else {
                String::new()
            };
            notes.push(format!(
                "column {} ({} {}) {light_words}: {total} pixel(s) above 1 in linear light{rows_words}, \
                 up to {top:.3}; they are drawn with a magenta and black hatch, not clipped",
                j + 1,
                column.title,
                column.detail
            ));
        }
    }
    notes
}

/// Linear light in [0, 1] to an 8-bit sRGB code.
pub fn encode(linear: f64) -> u8 {
    srgb::encode_code_8(linear)
}

fn figure_lines(material: &Material) -> (Vec<String>, bool) {
    let cols = columns(material, &material.factors);
    let pairs: Vec<(usize, _)> = cols
        .iter()
        .enumerate()
        .skip(1)
        .filter_map(|(j, c)| layer_pair(&cols[0].look.layer, &c.look.layer).map(|p| (j, p)))
        .collect();
    // The comparisons share the authored layer (its E or R is computed once per view cosine),
    // and sheets share roughness values.
    let (sheen_memo, fuzz_memo) = figure_memos();
    let results: Vec<_> = pairs
        .par_iter()
        .map(|&(j, (sheen, fuzz))| {
            (
                j,
                sheen,
                fuzz,
                layer_match_with(sheen, fuzz, sheen_memo, fuzz_memo),
                compare_base_attenuation(sheen, fuzz, sheen_memo, fuzz_memo),
            )
        })
        .collect();
    let mut poor = false;
    let lines = results
        .into_iter()
        .map(|(j, sheen, fuzz, m, a)| {
            poor |= m.poor_match;
            let mut line = format!(
                "{} ({}): sheen {:.4} → fuzz {:.4}, max3(sheenColor) {:.3}, w {:.3}: \
                 |max3·E − w·R| over view angles max {:.4} at view cosine {:.3}, \
                 cosine-weighted rms {:.4}; base attenuation differs by at most {:.4}, at view \
                 cosine {:.3}",
                cols[j].title,
                cols[j].detail,
                sheen.roughness,
                fuzz.roughness,
                sheen.color_max3,
                fuzz.weight,
                m.max,
                m.at_mu,
                m.rms,
                a.max_difference,
                a.at_mu,
            );
            if a.clamps.clamped > 0 {
                line += &format!(
                    " ({} attenuations clamped at 0 where E exceeds 1)",
                    a.clamps.clamped
                );
            }
            line
        })
        .collect();
    (lines, poor)
}

/// Renders `material`'s sheet under `title` (the asset and the material or materials it shows).
pub fn render(title: &str, material: &Material) -> Sheet {
    // Every distinct look once, in parallel; the order of the list is fixed by the columns.
    let per_swatch: Vec<Vec<Column>> = material
        .swatches
        .iter()
        .map(|s| columns(material, s))
        .collect();
    let mut looks: Vec<Look> = Vec::new();
    for col in per_swatch.iter().flatten() {
        if !looks.contains(&col.look) {
            looks.push(col.look);
        }
    }
    let ((figures, poor_match), shaded) = rayon::join(
        || figure_lines(material),
        || {
            looks
                .par_iter()
                .map(|l| Shaded::new(*l))
                .collect::<Vec<Shaded>>()
        },
    );
    let find = |look: &Look| looks.iter().position(|l| l == look).expect("listed");
    // Rows: per swatch, the furnace and the light.
    let rows: Vec<(usize, Light)> = (0..material.swatches.len())
        .flat_map(|s| [(s, Light::Furnace), (s, Light::Directional)])
        .collect();
    let rendered: Vec<Vec<Sphere>> = rows
        .par_iter()
        .map(|&(s, light)| {
            per_swatch[s]
                .par_iter()
                .map(|c| render_sphere(&shaded[find(&c.look)], light, SPHERE))
                .collect()
        })
        .collect();
    // The difference image and the verdict read the values clamped; the spheres are drawn
    // with the pixels above 1 marked.
    let spheres: Vec<Vec<Vec<[u8; 3]>>> = rendered
        .iter()
        .map(|row| row.iter().map(sphere_codes_clamped).collect())
        .collect();
    let mut max_codes = [0u8; 2];
    let diffs: Vec<Vec<[u8; 3]>> = rows
        .iter()
        .zip(&spheres)
        .map(|(&(_, light), row)| {
            let slot = usize::from(light == Light::Directional);
            row[0]
                .iter()
                .zip(&row[1])
                .map(|(a, b)| {
                    std::array::from_fn(|k| {
                        let d = a[k].abs_diff(b[k]);
                        max_codes[slot] = max_codes[slot].max(d);
                        (u32::from(d) * DIFF_GAIN).min(255) as u8
                    })
                })
                .collect()
        })
        .collect();

    // ꟻLIP of column 1 against column 0, per row, over the sphere's pixels.
    // Coverage is the sphere's outline, the same for every look and light.
    let on_sphere: Vec<bool> = rendered[0][0].coverage.iter().map(|&c| c > 0.5).collect();
    let flips: Vec<f64> = spheres
        .par_iter()
        .map(|row| flip_p99(&row[0], &row[1], &on_sphere))
        .collect();
    let mut flip = [0.0f64; 2];
    for (&(_, light), f) in rows.iter().zip(&flips) {
        let slot = usize::from(light == Light::Directional);
        flip[slot] = flip[slot].max(*f);
    }
    let spheres: Vec<Vec<Vec<[u8; 3]>>> = rendered
        .iter()
        .zip(spheres)
        .map(|(row, codes)| row.iter().zip(codes).map(|(s, c)| marked(s, c)).collect())
        .collect();

    let ncols = per_swatch[0].len();
    // The headings name the values at the factors; textured rows scale them per swatch.
    let headed = columns(material, &material.factors);
    let mut notes = material.notes.clone();
    if material.swatches.len() > 1 {
        notes.push(
            "the column headings give the values at the factors; in rows p5, mean and p95 each \
             textured slot's factor is multiplied by its texture's 5th percentile, mean and 95th \
             percentile"
                .to_string(),
        );
    }
    let labels: Vec<&str> = material.swatches.iter().map(|s| s.label).collect();
    notes.extend(above_one_notes(&rows, &rendered, &headed, &labels));
    let title = title.to_string();
    let summary = Summary {
        title,
        kind: kind_text(material.kind),
        columns: headed
            .iter()
            .map(|c| format!("{} {}", c.title, c.detail))
            .collect(),
        figures,
        max_codes,
        flip,
        verdict: material
            .verdict
            .unwrap_or_else(|| super::verdict::measure_pairs(&super::verdict::pairs(material))),
        poor_match,
        notes,
    };

    // Layout.
    let width = LABEL_W + CELL * (ncols + 1) + MARGIN;
    let text_width = width - 2 * MARGIN;
    let mut text: Vec<(String, [u8; 3])> = Vec::new();
    for f in &summary.figures {
        for l in font::wrap(f, text_width) {
            text.push((l, TEXT));
        }
    }
    for l in font::wrap(&summary.verdict_line(), text_width) {
        text.push((l, TEXT));
    }
    for n in &summary.notes {
        for l in font::wrap(&format!("note: {n}"), text_width) {
            text.push((l, DIM_TEXT));
        }
    }
    let title_lines = font::wrap(&summary.title, text_width);
    let kind_lines = font::wrap(summary.kind, text_width);
    let header = MARGIN + LINE_HEIGHT * (title_lines.len() + kind_lines.len()) + 4;
    let grid_top = header + 2 * LINE_HEIGHT;
    let height = grid_top + CELL * rows.len() + MARGIN + LINE_HEIGHT * text.len() + MARGIN;
    let mut canvas = Canvas::new(width, height, [0; 3]);
    let bg = encode(BACKGROUND);
    canvas.fill(0, 0, width, height, [background_code(); 3]);

    let mut y = MARGIN;
    for l in &title_lines {
        canvas.text(MARGIN, y, l, TEXT);
        y += LINE_HEIGHT;
    }
    for l in &kind_lines {
        canvas.text(MARGIN, y, l, DIM_TEXT);
        y += LINE_HEIGHT;
    }
    let col_x = |j: usize| LABEL_W + CELL * j;
    let headings: Vec<(String, String)> = headed
        .iter()
        .map(|c| (c.title.clone(), c.detail.clone()))
        .chain(std::iter::once((
            format!("difference ×{DIFF_GAIN}"),
            "columns 1 and 2".to_string(),
        )))
        .collect();
    for (j, (a, b)) in headings.iter().enumerate() {
        for (k, t) in [a, b].into_iter().enumerate() {
            // A heading wider than its cell is cut to the cell.
            let t = font::wrap(t, CELL - 4).remove(0);
            let x = col_x(j) + (CELL - font::width(&t).min(CELL)) / 2;
            canvas.text(x, header + k * LINE_HEIGHT, &t, TEXT);
        }
    }
    let pad = (CELL - SPHERE) / 2;
    for (r, &(s, light)) in rows.iter().enumerate() {
        let top = grid_top + CELL * r;
        let name = match light {
            Light::Furnace => "furnace",
            Light::Directional => "light",
        };
        canvas.text(MARGIN, top + CELL / 2 - LINE_HEIGHT, name, TEXT);
        canvas.text(MARGIN, top + CELL / 2, material.swatches[s].label, DIM_TEXT);
        for (j, codes) in spheres[r].iter().enumerate() {
            canvas.fill(col_x(j) + 2, top + 2, CELL - 4, CELL - 4, [bg; 3]);
            canvas.blit(col_x(j) + pad, top + pad, SPHERE, codes);
        }
        canvas.blit(col_x(ncols) + pad, top + pad, SPHERE, &diffs[r]);
    }
    let mut y = grid_top + CELL * rows.len() + MARGIN;
    for (l, color) in &text {
        canvas.text(MARGIN, y, l, *color);
        y += LINE_HEIGHT;
    }
    Sheet {
        width,
        height,
        rgb: canvas.rgb,
        summary,
        headings_top: header,
        grid_top,
        swatches: material.swatches.len(),
    }
}

/// The ꟻLIP error of `test` against `reference` (square sRGB images, row by row), the 99th
/// percentile (nearest rank) over the pixels `on` marks; 0 for identical images.
pub fn flip_p99(reference: &[[u8; 3]], test: &[[u8; 3]], on: &[bool]) -> f64 {
    flip_p99_at(reference, test, on, nv_flip::DEFAULT_PIXELS_PER_DEGREE)
}

/// [`flip_p99`] at `pixels_per_degree` (the verdict's small spheres are seen at the angle a
/// sheet's are, so at fewer pixels per degree).
pub fn flip_p99_at(
    reference: &[[u8; 3]],
    test: &[[u8; 3]],
    on: &[bool],
    pixels_per_degree: f32,
) -> f64 {
    if reference == test {
        return 0.0;
    }
    let size = (reference.len() as f64).sqrt() as u32;
    let image = |codes: &[[u8; 3]]| {
        let flat: Vec<u8> = codes.iter().flatten().copied().collect();
        nv_flip::FlipImageRgb8::with_data(size, size, &flat)
    };
    let error = nv_flip::flip(image(reference), image(test), pixels_per_degree);
    let mut values: Vec<f32> = error
        .to_vec()
        .into_iter()
        .zip(on)
        .filter_map(|(v, &on)| on.then_some(v))
        .collect();
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f32::total_cmp);
    let rank = ((values.len() as f64) * 0.99).ceil() as usize;
    f64::from(values[rank.clamp(1, values.len()) - 1])
}

/// An 8-bit RGB image being drawn.
pub(super) struct Canvas {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) rgb: Vec<u8>,
}

impl Canvas {
    pub(super) fn new(width: usize, height: usize, color: [u8; 3]) -> Canvas {
        Canvas {
            width,
            height,
            rgb: color.repeat(width * height),
        }
    }

    pub(super) fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    pub(super) fn fill(&mut self, x: usize, y: usize, w: usize, h: usize, c: [u8; 3]) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.set(xx, yy, c);
            }
        }
    }

    fn blit(&mut self, x: usize, y: usize, size: usize, codes: &[[u8; 3]]) {
        for (i, c) in codes.iter().enumerate() {
            self.set(x + i % size, y + i / size, *c);
        }
    }

    /// Draws `text` with its line's top-left corner at (`x`, `y`), each pixel blended over
    /// what is there by the glyph's coverage.
    pub(super) fn text(&mut self, x: usize, y: usize, text: &str, c: [u8; 3]) {
        font::draw(text, x, y, |px, py, coverage| {
            if px < self.width && py < self.height {
                let i = 3 * (py * self.width + px);
                for (under, over) in self.rgb[i..i + 3].iter_mut().zip(c) {
                    let (u, o) = (f32::from(*under), f32::from(over));
                    *under = (u + (o - u) * coverage).round() as u8;
                }
            }
        });
    }
}

/// The sheet as PNG bytes (deterministic: fixed filter and compression).
pub fn to_png(sheet: &Sheet) -> Vec<u8> {
    rgb_png(&sheet.rgb, sheet.width, sheet.height)
}

/// 8-bit RGB pixels as PNG bytes (deterministic: fixed filter and compression). Deflate level
/// 2: a library's sheets are many, and against the fastest setting it writes a three-swatch
/// sheet in 324 instead of 585 KB for 12 ms more (24 ms and 305 KB at level 3, 59 ms and 293
/// KB at the default level).
pub fn rgb_png(rgb: &[u8], width: usize, height: usize) -> Vec<u8> {
    use image::codecs::png::{CompressionType, FilterType, PngEncoder};
    use image::ImageEncoder;
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Level(2), FilterType::Adaptive)
        .write_image(
            rgb,
            width as u32,
            height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .expect("encoding an in-memory RGB8 image of matching size cannot fail");
    out
}

/// The part of `sheet` that shows its comparison at full size, for the overview: the column
/// headings and the furnace and light rows of the middle swatch (the material's mean where its
/// textures give p5, mean and p95; its factors where it has none), each with its row labels.
/// Scaled down, a whole sheet's words and spheres were too small to read.
pub fn comparison_strip(sheet: &Sheet) -> (Vec<u8>, usize, usize) {
    let swatch = sheet.swatches.saturating_sub(1) / 2;
    let rows_top = sheet.grid_top + 2 * CELL * swatch;
    let row = 3 * sheet.width;
    let mut rgb = Vec::with_capacity(row * (2 * LINE_HEIGHT + 2 * CELL));
    for (top, height) in [(sheet.headings_top, 2 * LINE_HEIGHT), (rows_top, 2 * CELL)] {
        let end = (top + height).min(sheet.height);
        rgb.extend_from_slice(&sheet.rgb[row * top.min(end)..row * end]);
    }
    let height = rgb.len() / (3 * sheet.width);
    (rgb, sheet.width, height)
}
