//! The overview of a preview run (`overview.png`): a histogram of the verdict's ꟻLIP over the
//! sheets drawn, with the "same" and "close" thresholds marked and the bars coloured by
//! verdict, and beside it the sheets with the largest ꟻLIP, scaled down, worst first. It is
//! the one picture of a library: how many materials a migration moves, and which most.

use super::font::{self, LINE_HEIGHT};
use super::sheet::{self, Canvas, Verdict, CLOSE_FLIP, SAME_FLIP};

/// The sheets shown beside the histogram.
pub const WORST_SHOWN: usize = 4;
/// Each is shown at 1 / THUMB_SCALE of its size.
pub const THUMB_SCALE: usize = 3;
/// Histogram bins, each BIN wide, from 0; the last also holds everything above.
const BINS: usize = 40;
const BIN: f64 = 0.02;
const BAR_W: usize = 12;
const PLOT_H: usize = 240;
const MARGIN: usize = 12;
const TEXT: [u8; 3] = [235, 235, 235];
const DIM: [u8; 3] = [150, 150, 150];

/// One of the worst sheets: its ꟻLIP, its place in the plan, its title and its thumbnail.
#[derive(Clone, Debug, PartialEq)]
pub struct Worst {
    pub flip: f64,
    pub sheet: usize,
    pub title: String,
    pub rgb: Vec<u8>,
    pub width: usize,
    pub height: usize,
}

/// Keeps the [`WORST_SHOWN`] sheets with the largest ꟻLIP (ties: the earlier sheet), whatever
/// order they are offered in.
#[derive(Default)]
pub struct WorstSheets(std::sync::Mutex<Vec<Worst>>);

impl WorstSheets {
    /// Offers a drawn sheet (the `sheet`-th of the plan).
    pub fn offer(&self, sheet_index: usize, drawn: &sheet::Sheet) {
        let flip = drawn.summary.flip[0];
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
        let (rgb, width, height) = sheet::thumbnail(drawn, THUMB_SCALE);
        worst.push(Worst {
            flip,
            sheet: sheet_index,
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

/// The overview picture's PNG bytes: the histogram of `flips` (one per sheet drawn) and `worst`.
pub fn png(flips: &[f64], worst: &[Worst]) -> Vec<u8> {
    let counts = histogram(flips);
    let tallest = counts.iter().copied().max().unwrap_or(0).max(1);
    let plot_w = BINS * BAR_W;
    let left = MARGIN + font::width("100%") + 8;
    let thumbs_w = worst.iter().map(|w| w.width).max().unwrap_or(0);
    let thumbs_h: usize = worst.iter().map(|w| w.height + 2 * LINE_HEIGHT + 8).sum();
    let width = left + plot_w + 2 * MARGIN + thumbs_w + MARGIN;
    let plot_top = MARGIN + 4 * LINE_HEIGHT;
    let height = (plot_top + PLOT_H + 4 * LINE_HEIGHT + MARGIN).max(MARGIN + thumbs_h + MARGIN);
    let background = sheet::background_code();
    let mut c = Canvas::new(width, height, [background; 3]);
    let (same, close, visible) =
        flips
            .iter()
            .fold((0, 0, 0), |(s, c, v), &f| match Verdict::from_flip(f) {
                Verdict::Same => (s + 1, c, v),
                Verdict::Close => (s, c + 1, v),
                Verdict::Visible => (s, c, v + 1),
            });
    c.text(
        MARGIN,
        MARGIN,
        &format!(
            "{} sheets: {same} same to the eye, {close} close, {visible} visible difference",
            flips.len()
        ),
        TEXT,
    );
    c.text(
        MARGIN,
        MARGIN + LINE_HEIGHT,
        "ꟻLIP in the furnace (99th percentile over the sphere), authored against migrated",
        DIM,
    );
    let colour = |v: Verdict| match v {
        Verdict::Same => [90, 170, 110],
        Verdict::Close => [200, 170, 80],
        Verdict::Visible => [210, 80, 80],
    };
    let axis = plot_top + PLOT_H;
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
    c.fill(left, axis, plot_w, 1, DIM);
    c.fill(left - 1, plot_top, 1, PLOT_H, DIM);
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
    for tick in [0.0, 0.2, 0.4, 0.6, 0.8] {
        let x = left + (tick / BIN * BAR_W as f64).round() as usize;
        c.fill(x, axis, 1, 4, DIM);
        let label = if tick >= 0.8 {
            "≥ 0.78".to_string()
        } else {
            format!("{tick:.1}")
        };
        c.text(
            x.saturating_sub(font::width(&label) / 2),
            axis + 6,
            &label,
            DIM,
        );
    }
    c.text(MARGIN, plot_top, &tallest.to_string(), DIM);
    c.text(MARGIN, axis - LINE_HEIGHT, "0", DIM);
    // The worst sheets.
    let x0 = left + plot_w + 2 * MARGIN;
    let mut y = MARGIN;
    for (k, w) in worst.iter().enumerate() {
        let label = format!("{}. ꟻLIP {:.3}", k + 1, w.flip);
        c.text(x0, y, &label, TEXT);
        let title = font::wrap(&w.title, thumbs_w).remove(0);
        c.text(x0, y + LINE_HEIGHT, &title, DIM);
        y += 2 * LINE_HEIGHT + 4;
        for row in 0..w.height {
            for col in 0..w.width {
                let i = 3 * (row * w.width + col);
                c.set(x0 + col, y + row, [w.rgb[i], w.rgb[i + 1], w.rgb[i + 2]]);
            }
        }
        y += w.height + 4;
    }
    sheet::rgb_png(&c.rgb, c.width, c.height)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drawn(flip: f64) -> sheet::Sheet {
        sheet::Sheet {
            width: 6,
            height: 6,
            rgb: vec![128; 108],
            summary: sheet::Summary {
                title: format!("flip {flip}"),
                kind: "",
                columns: Vec::new(),
                figures: Vec::new(),
                max_codes: [0; 2],
                flip: [flip, 0.0],
                verdict: Verdict::from_flip(flip),
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
    fn the_overview_counts_each_verdict() {
        let png = png(&[0.05, 0.15, 0.3, 0.31], &[]);
        let image = image::load_from_memory(&png).unwrap();
        assert!(image.width() as usize >= BINS * BAR_W);
        assert_eq!(
            (
                Verdict::from_flip(0.05),
                Verdict::from_flip(0.15),
                Verdict::from_flip(0.3)
            ),
            (Verdict::Same, Verdict::Close, Verdict::Visible)
        );
    }
}
