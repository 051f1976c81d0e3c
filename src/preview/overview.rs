//! The overview of a preview run (`overview.png`): a histogram of the plan's verdict (its
//! ꟻLIP in the furnace) over the sheets drawn, with the "same" and "close" thresholds marked
//! and the bars coloured by verdict; under it a histogram of the same measure over every sheet
//! of the run, drawn or not (what `--worst` ranks by, known before anything is drawn), the
//! sheets drawn in colour and the others in grey; and beside them the sheets the plan's
//! verdict ranks worst, in the index's order, each as its comparison at full size (headings
//! and the middle swatch's furnace and light rows, [`sheet::comparison_strip`]) under its
//! verdict and title. It is the one picture of a library: how many materials a migration
//! moves, and which most.

use super::font::{self, LINE_HEIGHT};
use super::sheet::{self, Canvas, Label as Verdict, CLOSE_FLIP, SAME_FLIP};

/// The sheets shown beside the histogram.
pub const WORST_SHOWN: usize = 4;
/// Histogram bins, each BIN wide, from 0; the last also holds everything above.
const BINS: usize = 40;
const BIN: f64 = 0.02;
const BAR_W: usize = 12;
const PLOT_H: usize = 240;
const MARGIN: usize = 12;
const TEXT: [u8; 3] = [235, 235, 235];
const DIM: [u8; 3] = [150, 150, 150];

/// One of the worst sheets: its ꟻLIP, its place in the plan, its verdict and title, and its
/// comparison strip.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    pub flip: f64,
    pub sheet: usize,
    pub verdict: crate::migrate::verdict::Verdict,
    pub title: String,
    pub rgb: Vec<u8>,
    pub width: usize,
    pub height: usize,
}

/// Keeps the [`WORST_SHOWN`] sheets whose plan's verdict has the largest ꟻLIP (ties: the
/// earlier sheet; the plan's ranking, so the index's order), whatever order they are offered
/// in.
#[derive(Default)]
pub struct WorstSheets(std::sync::Mutex<Vec<Worst>>);

impl WorstSheets {
    /// Offers a drawn sheet (the `sheet`-th of the plan).
    pub fn offer(&self, sheet_index: usize, drawn: &sheet::Sheet) {
        let flip = drawn.summary.verdict.flip;
        let mut worst = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let ranks_after = |w: &Worst| (w.flip, std::cmp::Reverse(w.sheet));
        let full = worst.len() >= WORST_SHOWN;
        if full
            && worst
                .last()
                .is_some_and(|last| ranks_after(last) >= (flip, std::cmp::Reverse(sheet_index)))
        {
            return;
        }
        let (rgb, width, height) = sheet::comparison_strip(drawn);
        worst.push(Worst {
            flip,
            sheet: sheet_index,
            verdict: drawn.summary.verdict,
            title: drawn.summary.title.clone(),
            rgb,
            width,
            height,
        });
        worst.sort_by(|a, b| b.flip.total_cmp(&a.flip).then(a.sheet.cmp(&b.sheet)));
        worst.truncate(WORST_SHOWN);
    }

    pub fn into_inner(self) -> Vec<Worst> {
        self.0.into_inner().unwrap_or_else(|e| e.into_inner())
    }
}

/// How many of `flips` fall in each bin of the histogram ([`BIN`] wide from 0, the last bin
/// holding everything above).
pub fn histogram(flips: &[f64]) -> [usize; BINS] {
    let mut counts = [0usize; BINS];
    for &f in flips {
        let bin = ((f / BIN).floor().max(0.0) as usize).min(BINS - 1);
        counts[bin] += 1;
    }
    counts
}

/// The histogram of the plan's measure over every sheet: the bin width (the smallest of 1, 2
/// and 5 × 10ᵏ, at least 0.001, for which [`BINS`] bins reach the largest measure) and, per
/// bin, how many sheets were drawn and how many were not. `metrics` is one (measure, drawn)
/// per sheet.
pub fn metric_histogram(metrics: &[(f64, bool)]) -> (f64, [[usize; 2]; BINS]) {
    let top = metrics
        .iter()
        .map(|m| m.0)
        .filter(|m| m.is_finite())
        .fold(0.0f64, f64::max);
    let width = (-3..=1)
        .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
        .find(|w| w * BINS as f64 > top)
        .unwrap_or(1.0);
    let mut counts = [[0usize; 2]; BINS];
    for &(m, drawn) in metrics {
        let m = if m.is_finite() { m } else { 0.0 };
        let bin = ((m / width).floor().max(0.0) as usize).min(BINS - 1);
        counts[bin][usize::from(!drawn)] += 1;
    }
    (width, counts)
}

/// How many of `flips` are same, close and visible.
pub fn verdict_counts(flips: &[f64]) -> [usize; 3] {
    let mut counts = [0; 3];
    for &f in flips {
        counts[match Verdict::from_flip(f) {
            Verdict::Same => 0,
            Verdict::Close => 1,
            Verdict::Visible => 2,
        }] += 1;
    }
    counts
}

/// The overview picture's PNG bytes: the histogram of `flips` (one per sheet drawn), the
/// histogram of the plan's measure over every sheet (`metrics`: one (measure, drawn) per
/// sheet), and `worst`.
pub fn png(flips: &[f64], metrics: &[(f64, bool)], worst: &[Worst]) -> Vec<u8> {
    let counts = histogram(flips);
    let tallest = counts.iter().copied().max().unwrap_or(0).max(1);
    let (metric_bin, metric_counts) = metric_histogram(metrics);
    let metric_tallest = metric_counts
        .iter()
        .map(|[d, u]| d + u)
        .max()
        .unwrap_or(0)
        .max(1);
    let plot_w = BINS * BAR_W;
    let left = MARGIN + font::width("100000") + 8;
    let thumbs_w = worst.iter().map(|w| w.width).max().unwrap_or(0);
    let thumbs_h: usize = worst
        .iter()
        .map(|w| w.height + (1 + title_lines(w, thumbs_w).len()) * LINE_HEIGHT + 2 * MARGIN)
        .sum();
    let width = left + plot_w + 3 * MARGIN + thumbs_w + MARGIN;
    let plot_top = MARGIN + 4 * LINE_HEIGHT;
    let axis = plot_top + PLOT_H;
    let metric_top = axis + 6 * LINE_HEIGHT;
    let metric_axis = metric_top + PLOT_H;
    let height = (metric_axis + 3 * LINE_HEIGHT + MARGIN).max(MARGIN + thumbs_h + MARGIN);
    let background = sheet::background_code();
    let mut c = Canvas::new(width, height, [background; 3]);
    let [same, close, visible] = verdict_counts(flips);
    let drawn = metrics.iter().filter(|m| m.1).count();
    c.text(
        MARGIN,
        MARGIN,
        &format!(
            "{} sheets drawn: {same} same to the eye, {close} close, {visible} visible difference",
            flips.len()
        ),
        TEXT,
    );
    c.text(
        MARGIN,
        MARGIN + LINE_HEIGHT,
        "the plan's ꟻLIP in the furnace, authored against migrated",
        DIM,
    );
    let colour = |v: Verdict| match v {
        Verdict::Same => [90, 170, 110],
        Verdict::Close => [200, 170, 80],
        Verdict::Visible => [210, 80, 80],
    };
    for (i, &n) in counts.iter().enumerate() {
        let h = (n * PLOT_H).div_ceil(tallest);
        let mid = (i as f64 + 0.5) * BIN;
        c.fill(
            left + i * BAR_W + 1,
            axis - h,
            BAR_W - 2,
            h,
            colour(Verdict::from_flip(mid)),
        );
    }
    axes(&mut c, left, plot_top, tallest);
    // The thresholds, their labels on lines of their own so that they never overlap.
    for (k, (threshold, label)) in [(SAME_FLIP, "same"), (CLOSE_FLIP, "close")]
        .into_iter()
        .enumerate()
    {
        let x = left + (threshold / BIN * BAR_W as f64).round() as usize;
        for y in (plot_top..axis).step_by(4) {
            c.fill(x, y, 1, 2, TEXT);
        }
        let y = plot_top - (2 - k) * LINE_HEIGHT;
        c.text(x + 3, y, &format!("{label} ≤ {threshold:.2}"), DIM);
    }
    ticks(&mut c, left, axis, BIN);

    // The plan's measure over every sheet.
    c.text(
        MARGIN,
        metric_top - 3 * LINE_HEIGHT,
        &format!(
            "all {} sheets by the plan's verdict: {drawn} drawn (colour), {} not drawn (grey)",
            metrics.len(),
            metrics.len() - drawn
        ),
        TEXT,
    );
    c.text(
        MARGIN,
        metric_top - 2 * LINE_HEIGHT,
        "ꟻLIP in the furnace on the plan's small renders, authored against migrated",
        DIM,
    );
    for (i, &[d, u]) in metric_counts.iter().enumerate() {
        let total = d + u;
        let h = (total * PLOT_H).div_ceil(metric_tallest);
        let hd = (d * PLOT_H).div_ceil(metric_tallest).min(h);
        let x = left + i * BAR_W + 1;
        c.fill(x, metric_axis - h, BAR_W - 2, h - hd, [110, 110, 110]);
        c.fill(x, metric_axis - hd, BAR_W - 2, hd, [110, 160, 220]);
    }
    axes(&mut c, left, metric_top, metric_tallest);
    ticks(&mut c, left, metric_axis, metric_bin);

    // The worst sheets.
    let x0 = left + plot_w + 3 * MARGIN;
    let mut y = MARGIN;
    for (k, w) in worst.iter().enumerate() {
        let label = format!(
            "{}. {}: ꟻLIP {:.3} in the furnace, {:.3} under the light",
            k + 1,
            w.verdict.label.as_str(),
            w.verdict.furnace,
            w.verdict.light
        );
        c.text(x0, y, &label, colour(w.verdict.label));
        y += LINE_HEIGHT;
        for line in title_lines(w, thumbs_w) {
            c.text(x0, y, &line, DIM);
            y += LINE_HEIGHT;
        }
        y += MARGIN / 2;
        for row in 0..w.height {
            for col in 0..w.width {
                let i = 3 * (row * w.width + col);
                c.set(x0 + col, y + row, [w.rgb[i], w.rgb[i + 1], w.rgb[i + 2]]);
            }
        }
        y += w.height + MARGIN + MARGIN / 2;
    }
    sheet::rgb_png(&c.rgb, c.width, c.height)
}

/// The lines of a worst sheet's title over a strip `width` wide: at most two, the second cut
/// with "…" when the title goes on.
fn title_lines(w: &Worst, width: usize) -> Vec<String> {
    let mut lines = font::wrap(&w.title, width);
    if lines.len() > 2 {
        lines.truncate(2);
        lines[1].push('…');
    }
    lines
}

/// A plot's two axes and its count labels (the tallest bar's count at the top, 0 at the foot).
fn axes(c: &mut Canvas, left: usize, top: usize, tallest: usize) {
    let axis = top + PLOT_H;
    c.fill(left, axis, BINS * BAR_W, 1, DIM);
    c.fill(left - 1, top, 1, PLOT_H, DIM);
    c.text(MARGIN, top, &tallest.to_string(), DIM);
    c.text(MARGIN, axis - LINE_HEIGHT, "0", DIM);
}

/// Five ticks under a plot of bins `bin` wide, at every eighth bin; the last one, at the
/// plot's right end, reads "≥" since the last bin holds everything above, and is drawn
/// right-aligned so that it stays inside the plot's width.
fn ticks(c: &mut Canvas, left: usize, axis: usize, bin: f64) {
    let digits = if bin >= 0.05 {
        1
    } else if bin >= 0.005 {
        2
    } else {
        3
    };
    for k in 0..=4 {
        let bins = k * BINS / 4;
        let x = left + bins * BAR_W;
        c.fill(x.min(left + BINS * BAR_W - 1), axis, 1, 4, DIM);
        let value = bins as f64 * bin;
        let (label, lx) = if k == 4 {
            let label = format!("≥ {:.*}", digits, value - bin);
            let lx = (left + BINS * BAR_W).saturating_sub(font::width(&label));
            (label, lx)
        } else {
            let label = format!("{value:.digits$}");
            (label.clone(), x.saturating_sub(font::width(&label) / 2))
        };
        c.text(lx, axis + 6, &label, DIM);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drawn(flip: f64) -> sheet::Sheet {
        sheet::Sheet {
            width: 6,
            height: 6,
            rgb: vec![128; 108],
            headings_top: 0,
            grid_top: 0,
            swatches: 0,
            summary: sheet::Summary {
                title: format!("flip {flip}"),
                kind: "",
                columns: Vec::new(),
                figures: Vec::new(),
                max_codes: [0; 2],
                flip: [flip, 0.0],
                verdict: crate::migrate::verdict::Verdict::new(flip, 0.0),
                poor_match: false,
                notes: Vec::new(),
            },
        }
    }

    #[test]
    fn the_worst_sheets_are_the_largest_flips_whatever_the_order_offered() {
        let flips = [0.1, 0.5, 0.3, 0.5, 0.05, 0.7, 0.2];
        let kept = |order: &[usize]| {
            let worst = WorstSheets::default();
            for &i in order {
                worst.offer(i, &drawn(flips[i]));
            }
            worst
                .into_inner()
                .iter()
                .map(|w| w.sheet)
                .collect::<Vec<_>>()
        };
        // Ties (0.5 twice) go to the earlier sheet.
        assert_eq!(kept(&[0, 1, 2, 3, 4, 5, 6]), [5, 1, 3, 2]);
        assert_eq!(kept(&[6, 5, 4, 3, 2, 1, 0]), [5, 1, 3, 2]);
    }

    #[test]
    fn the_plan_measure_histogram_covers_every_sheet_and_splits_drawn_from_not() {
        // Largest 0.093: 40 bins of 0.005 reach 0.2 (of 0.002 only 0.08).
        let metrics = [
            (0.093, true),
            (0.0925, true),
            (0.051, true),
            (0.0499, false),
            (0.0, false),
            (0.0049, false),
            (f64::NAN, false),
        ];
        let (width, counts) = metric_histogram(&metrics);
        assert_eq!(width, 0.005);
        assert_eq!(counts[18], [2, 0]);
        assert_eq!(counts[10], [1, 0]);
        assert_eq!(counts[9], [0, 1]);
        assert_eq!(counts[0], [0, 3]);
        let total: usize = counts.iter().map(|[d, u]| d + u).sum();
        assert_eq!(total, metrics.len());
        // Everything at 0 (no sheen–fuzz pair) or no sheet at all: the finest bins, 0.001.
        let (width, counts) = metric_histogram(&[(0.0, true), (0.0, false)]);
        assert_eq!((width, counts[0]), (0.001, [1, 1]));
        assert_eq!(metric_histogram(&[]).0, 0.001);
    }

    #[test]
    fn the_overview_counts_each_verdict_and_draws_each_bar_in_its_colour() {
        let flips = [0.05, 0.15, 0.3, 0.31];
        assert_eq!(verdict_counts(&flips), [1, 1, 2]);
        let counts = histogram(&flips);
        // 0.3 and 0.31 share bin 15 ([0.30, 0.32)).
        assert_eq!(
            (
                counts[2],
                counts[7],
                counts[15],
                counts.iter().sum::<usize>()
            ),
            (1, 1, 2, 4)
        );
        let metrics = [(0.01, true), (0.002, false)];
        let image = image::load_from_memory(&png(&flips, &metrics, &[]))
            .unwrap()
            .to_rgb8();
        // Each bar's foot, in the middle of its bin: the verdict's colour above, blue for a
        // drawn sheet and grey for one not drawn below (bins of 0.001 there).
        let left = MARGIN + font::width("100000") + 8;
        let axis = MARGIN + 4 * LINE_HEIGHT + PLOT_H;
        let metric_axis = axis + 6 * LINE_HEIGHT + PLOT_H;
        let foot = |bin: usize, axis: usize| {
            image
                .get_pixel((left + bin * BAR_W + BAR_W / 2) as u32, (axis - 1) as u32)
                .0
        };
        assert_eq!(foot(2, axis), [90, 170, 110]);
        assert_eq!(foot(7, axis), [200, 170, 80]);
        assert_eq!(foot(15, axis), [210, 80, 80]);
        assert_eq!(foot(10, metric_axis), [110, 160, 220]);
        assert_eq!(foot(2, metric_axis), [110, 110, 110]);
        let background = [sheet::background_code(); 3];
        assert_eq!(
            (foot(14, axis), foot(5, metric_axis)),
            (background, background)
        );
    }
}
