//! velvet's closed-form fit of the Charlie sheen albedo: E(μ, r) ≈ exp(P(μ, r)), with P a
//! polynomial of degree 3 in μ and 4 in r (20 coefficients).
//!
//! The coefficients in [`FIT_COEFFICIENTS`] are the output of [`fit_coefficients`] on
//! [`training_samples`] (quadrature values on a 24×24 grid over the ordinary region μ ∈ [0.1, 1],
//! r ∈ [0.25, 1]); a test re-runs the fit and checks that the committed constants are what it
//! produces. The exponential keeps the fit positive and lets it follow E over its five decades in
//! the ordinary region; outside that region (μ < 0.1 or r < 0.25) it is an extrapolation that
//! stays finite but does not follow E's growth at grazing angles (see the accuracy report).
//!
//! The fit minimises the squared absolute error (Gauss–Newton, started from a log-linear fit
//! weighted by E). The linear least-squares steps use a Householder QR written here: a 576×20
//! solve does not justify a linear-algebra dependency.

use super::albedo::{albedo_quadrature, QUADRATURE_TOL};
use super::charlie::{clamp01, Visibility};
use rayon::prelude::*;

/// Degree of P in μ.
pub const FIT_DEGREE_MU: usize = 3;
/// Degree of P in r.
pub const FIT_DEGREE_R: usize = 4;
/// Number of coefficients of P.
pub const FIT_TERMS: usize = (FIT_DEGREE_MU + 1) * (FIT_DEGREE_R + 1);

/// The coefficients c[i·(FIT_DEGREE_R + 1) + j] of μ^i r^j in P, as produced by
/// [`fit_coefficients`]`(&`[`training_samples`]`())`.
pub const FIT_COEFFICIENTS: [f64; FIT_TERMS] = [
    1.0314817848056965e0,
    -6.697023308905767e0,
    1.1862915528353012e1,
    -7.877750985688899e0,
    1.5742269854351472e0,
    -1.3162419677974615e1,
    4.2243046666900646e1,
    -6.865178269462774e1,
    5.3334828737948285e1,
    -1.6173516220423114e1,
    2.795975441812682e0,
    8.595532367646795e0,
    -3.208703559324001e1,
    3.335998270222964e1,
    -1.116477332709561e1,
    -6.1359995776707805e0,
    5.171993569956837e0,
    1.5340666384686038e1,
    -2.594444134789158e1,
    1.0770259144031147e1,
];

/// E(μ, r) by the closed-form fit. μ and r are clamped into [0, 1].
pub fn albedo_fit(mu: f64, r: f64) -> f64 {
    eval(&FIT_COEFFICIENTS, clamp01(mu), clamp01(r))
}

/// exp(P(μ, r)) for coefficients `c`, by Horner's rule in both variables.
fn eval(c: &[f64; FIT_TERMS], mu: f64, r: f64) -> f64 {
    let mut p = 0.0;
    for i in (0..=FIT_DEGREE_MU).rev() {
        let row = &c[i * (FIT_DEGREE_R + 1)..(i + 1) * (FIT_DEGREE_R + 1)];
        let q = row.iter().rev().fold(0.0, |acc, &cj| acc * r + cj);
        p = p * mu + q;
    }
    p.exp()
}

/// The monomials μ^i r^j in coefficient order.
fn basis(mu: f64, r: f64) -> [f64; FIT_TERMS] {
    let mut out = [0.0; FIT_TERMS];
    for i in 0..=FIT_DEGREE_MU {
        for j in 0..=FIT_DEGREE_R {
            out[i * (FIT_DEGREE_R + 1) + j] = mu.powi(i as i32) * r.powi(j as i32);
        }
    }
    out
}

/// Samples per axis of the training grid.
pub const TRAINING_GRID: usize = 24;

/// (μ, r, E by quadrature) on the TRAINING_GRID × TRAINING_GRID uniform grid over
/// μ ∈ [0.1, 1], r ∈ [0.25, 1] (edges included).
pub fn training_samples() -> Vec<(f64, f64, f64)> {
    let n = TRAINING_GRID;
    (0..n * n)
        .into_par_iter()
        .map(|k| {
            let mu = 0.1 + 0.9 * (k % n) as f64 / (n - 1) as f64;
            let r = 0.25 + 0.75 * (k / n) as f64 / (n - 1) as f64;
            (
                mu,
                r,
                albedo_quadrature(mu, r, Visibility::Charlie, QUADRATURE_TOL).value,
            )
        })
        .collect()
}

/// Fits P to samples (μ, r, E): a log-linear least-squares start weighted by E, then
/// Gauss–Newton steps on the absolute error (halved while they do not reduce it).
pub fn fit_coefficients(samples: &[(f64, f64, f64)]) -> [f64; FIT_TERMS] {
    // Start: minimise Σ (E (P − ln E))², which is Σ (exp P − E)² to first order.
    let positive: Vec<_> = samples.iter().filter(|s| s.2 > 1e-300).collect();
    let rows: Vec<[f64; FIT_TERMS]> = positive
        .iter()
        .map(|s| scaled(basis(s.0, s.1), s.2))
        .collect();
    let rhs: Vec<f64> = positive.iter().map(|s| s.2 * s.2.ln()).collect();
    let mut c = to_array(&least_squares(&rows, &rhs));

    let sse = |c: &[f64; FIT_TERMS]| {
        samples
            .iter()
            .map(|s| (eval(c, s.0, s.1) - s.2).powi(2))
            .sum::<f64>()
    };
    let mut current = sse(&c);
    for _ in 0..100 {
        let jac: Vec<[f64; FIT_TERMS]> = samples
            .iter()
            .map(|s| scaled(basis(s.0, s.1), eval(&c, s.0, s.1)))
            .collect();
        let res: Vec<f64> = samples.iter().map(|s| s.2 - eval(&c, s.0, s.1)).collect();
        let step = least_squares(&jac, &res);
        let mut scale = 1.0;
        let improved = loop {
            let mut trial = c;
            for (t, d) in trial.iter_mut().zip(&step) {
                *t += scale * d;
            }
            let e = sse(&trial);
            if e < current {
                break Some((trial, e));
            }
            scale *= 0.5;
            if scale < 1e-6 {
                break None;
            }
        };
        match improved {
            Some((trial, e)) => {
                let converged = current - e <= 1e-15 * current;
                c = trial;
                current = e;
                if converged {
                    break;
                }
            }
            None => break,
        }
    }
    c
}

fn scaled(mut row: [f64; FIT_TERMS], s: f64) -> [f64; FIT_TERMS] {
    for v in &mut row {
        *v *= s;
    }
    row
}

fn to_array(v: &[f64]) -> [f64; FIT_TERMS] {
    let mut out = [0.0; FIT_TERMS];
    out.copy_from_slice(v);
    out
}

/// The x minimising |A x − b|₂ for a tall A (rows × FIT_TERMS) of full column rank, by
/// Householder QR.
fn least_squares(a: &[[f64; FIT_TERMS]], b: &[f64]) -> Vec<f64> {
    let m = a.len();
    let n = FIT_TERMS;
    assert!(m >= n && b.len() == m);
    let mut q: Vec<[f64; FIT_TERMS]> = a.to_vec();
    let mut y = b.to_vec();
    for k in 0..n {
        let norm = q[k..].iter().map(|row| row[k] * row[k]).sum::<f64>().sqrt();
        if norm == 0.0 {
            continue;
        }
        let alpha = if q[k][k] > 0.0 { -norm } else { norm };
        // The Householder vector v = x − α e₁ over rows k.., stored in place of column k.
        q[k][k] -= alpha;
        let vnorm2 = q[k..].iter().map(|row| row[k] * row[k]).sum::<f64>();
        for j in k + 1..n {
            let f = 2.0 * q[k..].iter().map(|row| row[k] * row[j]).sum::<f64>() / vnorm2;
            for row in q[k..].iter_mut() {
                row[j] -= f * row[k];
            }
        }
        let f = 2.0
            * q[k..]
                .iter()
                .zip(&y[k..])
                .map(|(row, yi)| row[k] * yi)
                .sum::<f64>()
            / vnorm2;
        for (row, yi) in q[k..].iter().zip(y[k..].iter_mut()) {
            *yi -= f * row[k];
        }
        q[k][k] = alpha;
    }
    // Back substitution with R (upper triangle of q).
    let mut x = vec![0.0; n];
    for k in (0..n).rev() {
        let s: f64 = (k + 1..n).map(|j| q[k][j] * x[j]).sum();
        x[k] = if q[k][k] == 0.0 {
            0.0
        } else {
            (y[k] - s) / q[k][k]
        };
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_recovers_an_exact_polynomial() {
        let truth: [f64; FIT_TERMS] = std::array::from_fn(|k| (k as f64 * 0.37).sin());
        let pts: Vec<(f64, f64)> = (0..30)
            .flat_map(|i| (0..30).map(move |j| (i as f64 / 29.0, j as f64 / 29.0)))
            .collect();
        let rows: Vec<_> = pts.iter().map(|p| basis(p.0, p.1)).collect();
        let rhs: Vec<f64> = rows
            .iter()
            .map(|b| b.iter().zip(&truth).map(|(x, c)| x * c).sum())
            .collect();
        let x = least_squares(&rows, &rhs);
        for (a, b) in x.iter().zip(&truth) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    #[test]
    fn fitter_recovers_an_exact_exp_polynomial() {
        let truth: [f64; FIT_TERMS] = std::array::from_fn(|k| 0.3 * ((k as f64) * 1.3).cos());
        let samples: Vec<_> = (0..20)
            .flat_map(|i| {
                (0..20).map(move |j| (0.1 + 0.9 * i as f64 / 19.0, 0.25 + 0.75 * j as f64 / 19.0))
            })
            .map(|(m, r)| (m, r, eval(&truth, m, r)))
            .collect();
        let c = fit_coefficients(&samples);
        for s in &samples {
            assert!((eval(&c, s.0, s.1) - s.2).abs() < 1e-10);
        }
    }

    #[test]
    fn committed_coefficients_are_what_the_fitter_produces() {
        let samples = training_samples();
        assert_eq!(samples.len(), TRAINING_GRID * TRAINING_GRID);
        let refit = fit_coefficients(&samples);
        for s in &samples {
            let (a, b) = (eval(&refit, s.0, s.1), albedo_fit(s.0, s.1));
            assert!(
                (a - b).abs() < 1e-9,
                "({}, {}): refit {a} vs committed {b}",
                s.0,
                s.1
            );
        }
    }

    #[test]
    fn horner_matches_the_monomial_sum() {
        let c: [f64; FIT_TERMS] = std::array::from_fn(|k| 0.1 * k as f64 - 1.0);
        let (mu, r) = (0.37, 0.81);
        let direct: f64 = basis(mu, r)
            .iter()
            .zip(&c)
            .map(|(b, c)| b * c)
            .sum::<f64>()
            .exp();
        assert!((eval(&c, mu, r) - direct).abs() < 1e-14 * direct);
    }
}
