//! The roughness mapping between the sheen and fuzz layers: for a sheen roughness r, the fuzz
//! roughness α(r) whose reflectance R(μ, α) is closest to the sheen albedo E(μ, r), and the
//! reverse r(α) for a fallback sheen; and the per-material comparison reports give.
//!
//! "Closest" is the cosine-weighted L2 distance over the view cosine,
//!
//!   rms(r, α) = sqrt( ∫₀¹ (E(μ, r) − R(μ, α))² μ dμ / ∫₀¹ μ dμ ),
//!
//! with the integral taken by a fixed rule ([`mu_rule`]: the 15-point Kronrod rule on [0, 0.1]
//! and on [0.1, 1], 30 nodes; the break resolves the steep rise of E at grazing views). The
//! cosine weight counts each view direction by the projected area it sees, so grazing angles,
//! where no α follows E (E exceeds 1 there for small r), count little. The colour and fuzz
//! weight do not move the optimum: migrate writes w = max3(sheenColor), and
//! |c·E − w·R| = w·|E − R|.
//!
//! α(r) = argmin over α ∈ [0, 1] of rms(r, α), and r(α) = argmin over r of rms(r, α) (a
//! separate minimisation: the reverse of a best fit is not the inverse of the forward one). Both
//! ship as 257-node tables (`mapping_table.rs`, nodes at j/256) read by linear interpolation,
//! so a bake curve sampled at the same nodes reproduces them exactly. The tables are generated
//! by velvet's own code ([`generate_tables`]): E and R by quadrature at the rule's nodes and at
//! 33 roughness values ([`ObjectiveSamples`]), each interpolated in roughness (Catmull–Rom)
//! between them, and the minimum found by Brent's method at every node. A test regenerates
//! them and fails when they drift; `VELVET_UPDATE_GOLDEN=1` rewrites the file.
//!
//! r(α) is not continuous: for α up to 0.25 the best sheen is none at all (r ≈ 0, E = 0: the
//! fuzz's reflectance is then mostly its multiple scattering at grazing views, which a sheen
//! lobe overshoots), above it a real lobe (r ≈ 0.14 and rising); at the jump both leave the same
//! rms. The dense table confines the jump to one cell of width 1/256, α ∈ [0.25, 0.254].
//!
//! The reference optimum ([`optimal_fuzz_roughness`], [`optimal_sheen_roughness`]) evaluates E
//! and R by quadrature at every step. The shipped tables differ from it by at most
//! [`FUZZ_FOR_SHEEN_DEVIATION`] and [`SHEEN_FOR_FUZZ_DEVIATION`] in roughness where the match
//! is good, and cost at most [`MAPPING_RMS_LOSS`] in rms anywhere (see the constants for the
//! measured figures). Below r = [`POOR_MATCH_BELOW`] no α matches E well, which the comparison
//! flags.
//!
//! Brent's minimiser is written here (forty lines) rather than taken from an optimisation
//! crate: one bounded 1-D minimum does not justify such a dependency.

use super::charlie::clamp01;
use super::fuzz::{catmull_rom, fuzz_reflectance, ReflectanceMethod};
use super::layering::{FuzzParams, FuzzReflectance, LayerReflectance, SheenAlbedo, SheenParams};
use super::mapping_table;
use super::quadrature::kronrod_15;
use super::{sheen_albedo, AlbedoMethod};
use rayon::prelude::*;

/// Nodes of the rule over μ.
pub const MU_NODES: usize = 30;

/// Where the rule over μ splits [0, 1].
pub const MU_BREAK: f64 = 0.1;

/// The rule over μ: (μ_k, W_k) with W_k = w_k·μ_k / Σ w·μ, so that Σ W_k·g(μ_k) is the
/// cosine-weighted mean of g. The 15-point Kronrod rule on [0, MU_BREAK] and on [MU_BREAK, 1].
pub fn mu_rule() -> [(f64, f64); MU_NODES] {
    let mut nodes = [(0.0, 0.0); MU_NODES];
    let low = kronrod_15(0.0, MU_BREAK);
    let high = kronrod_15(MU_BREAK, 1.0);
    for (slot, (mu, w)) in nodes.iter_mut().zip(low.iter().chain(&high)) {
        *slot = (*mu, w * mu);
    }
    let total: f64 = nodes.iter().map(|n| n.1).sum();
    for n in &mut nodes {
        n.1 /= total;
    }
    nodes
}

/// The cosine-weighted rms of a − b over the rule's nodes (both given at [`mu_rule`]'s μ_k).
pub fn weighted_rms(a: &[f64; MU_NODES], b: &[f64; MU_NODES]) -> f64 {
    mean_square(&mu_rule(), a, b).sqrt()
}

fn mean_square(rule: &[(f64, f64); MU_NODES], a: &[f64; MU_NODES], b: &[f64; MU_NODES]) -> f64 {
    rule.iter()
        .zip(a.iter().zip(b))
        .map(|((_, w), (a, b))| w * (a - b) * (a - b))
        .sum()
}

/// E(μ_k, r) at the rule's nodes, by quadrature.
pub fn sheen_at_nodes(r: f64) -> [f64; MU_NODES] {
    let rule = mu_rule();
    let v: Vec<f64> = rule
        .par_iter()
        .map(|&(mu, _)| sheen_albedo(mu, r, AlbedoMethod::Quadrature))
        .collect();
    std::array::from_fn(|k| v[k])
}

/// R(μ_k, α) at the rule's nodes, by quadrature.
pub fn fuzz_at_nodes(alpha: f64) -> [f64; MU_NODES] {
    let rule = mu_rule();
    let v: Vec<f64> = rule
        .par_iter()
        .map(|&(mu, _)| fuzz_reflectance(mu, alpha, ReflectanceMethod::Quadrature))
        .collect();
    std::array::from_fn(|k| v[k])
}

/// rms(r, α) with E and R by quadrature.
pub fn mapping_rms(r: f64, alpha: f64) -> f64 {
    weighted_rms(&sheen_at_nodes(r), &fuzz_at_nodes(alpha))
}

/// A best roughness and the cosine-weighted rms difference it leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optimum {
    /// The roughness (α for [`optimal_fuzz_roughness`], r for [`optimal_sheen_roughness`]).
    pub roughness: f64,
    /// rms(r, α) there.
    pub rms: f64,
}

/// Tolerance in roughness of the reference optimum (quadrature noise in E and R, at most
/// 1e-7, moves the minimum of the smooth objective by far less).
pub const OPTIMUM_TOL: f64 = 1e-5;

/// α(r) by minimising rms(r, ·) with E and R by quadrature at every step: the reference the
/// shipped table is measured against. A minimum on the edge of the search bracket widens the
/// search to the whole of [0, 1].
pub fn optimal_fuzz_roughness(r: f64) -> Optimum {
    let e = sheen_at_nodes(r);
    let rule = mu_rule();
    let start = fuzz_roughness_for_sheen(r);
    polish(|alpha| mean_square(&rule, &e, &fuzz_at_nodes(alpha)), start)
}

/// r(α) by minimising rms(·, α) with E and R by quadrature at every step.
pub fn optimal_sheen_roughness(alpha: f64) -> Optimum {
    let f = fuzz_at_nodes(alpha);
    let rule = mu_rule();
    let start = sheen_roughness_for_fuzz(alpha);
    polish(|r| mean_square(&rule, &sheen_at_nodes(r), &f), start)
}

/// The minimum of a costly mean square near `start`: Brent on start ± 0.05 (within [0, 1]),
/// then on [0, 1] from an 11-point scan if that minimum sits on an inner edge of the bracket.
fn polish(mut f: impl FnMut(f64) -> f64, start: f64) -> Optimum {
    const HALF_WIDTH: f64 = 0.05;
    let (lo, hi) = ((start - HALF_WIDTH).max(0.0), (start + HALF_WIDTH).min(1.0));
    let (x, fx) = bounded_minimum(&mut f, lo, hi, OPTIMUM_TOL);
    let on_inner_edge =
        (lo > 0.0 && x - lo < 2.0 * OPTIMUM_TOL) || (hi < 1.0 && hi - x < 2.0 * OPTIMUM_TOL);
    let (x, fx) = if on_inner_edge {
        scan_then_minimise(&mut f, 11, OPTIMUM_TOL)
    } else {
        (x, fx)
    };
    Optimum {
        roughness: x,
        rms: fx.max(0.0).sqrt(),
    }
}

/// The minimum of f on [0, 1]: the best of `n` evenly spaced points, then Brent between its
/// neighbours.
fn scan_then_minimise(f: &mut impl FnMut(f64) -> f64, n: usize, tol: f64) -> (f64, f64) {
    let step = 1.0 / (n - 1) as f64;
    let best = (0..n)
        .map(|i| (i, f(i as f64 * step)))
        .fold(
            (0, f64::INFINITY),
            |b, (i, v)| if v < b.1 { (i, v) } else { b },
        );
    let lo = best.0.saturating_sub(1) as f64 * step;
    let hi = ((best.0 + 1).min(n - 1)) as f64 * step;
    let (x, fx) = bounded_minimum(f, lo, hi, tol);
    if fx <= best.1 {
        (x, fx)
    } else {
        (best.0 as f64 * step, best.1)
    }
}

/// The minimum of f on [a, b] by Brent's method (golden section with parabolic steps; Brent,
/// "Algorithms for Minimization without Derivatives", 1973, procedure localmin), to tolerance
/// `tol` in x. Brent's method never evaluates the ends; they are compared at the close, so a
/// minimum on an end of the interval is found exactly.
fn bounded_minimum(f: &mut impl FnMut(f64) -> f64, a: f64, b: f64, tol: f64) -> (f64, f64) {
    let golden = 0.5 * (3.0 - 5f64.sqrt());
    let (mut a, mut b) = (a.min(b), a.max(b));
    let (a0, b0) = (a, b);
    let mut x = a + golden * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    loop {
        let m = 0.5 * (a + b);
        let tol1 = f64::EPSILON.sqrt() * x.abs() + tol / 3.0;
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol1 {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            let previous = e;
            e = d;
            if p.abs() < (0.5 * q * previous).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x < m { b - x } else { a - x };
            d = golden * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = f(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    for end in [a0, b0] {
        let fe = f(end);
        if fe < fx {
            (x, fx) = (end, fe);
        }
    }
    (x, fx)
}

/// Roughness values at which the objective is sampled: j/32.
pub const SAMPLE_NODES: usize = 33;

/// The roughness of sample j: j/(SAMPLE_NODES − 1).
pub fn sample_node(j: usize) -> f64 {
    j as f64 / (SAMPLE_NODES - 1) as f64
}

/// Nodes of the mapping tables: roughness j/256.
pub const NODES: usize = mapping_table::NODES;

/// The roughness of table node j: j/(NODES − 1).
pub fn node(j: usize) -> f64 {
    j as f64 / (NODES - 1) as f64
}

/// E and R by quadrature at the rule's μ nodes and [`SAMPLE_NODES`] roughness values each,
/// from which the objective is interpolated (Catmull–Rom) while the tables are generated. E is
/// sampled at r_j = (j/32)² and interpolated in √r: for small r, E rises steeply at grazing
/// views as r grows from 0 (E(μ, 0) = 0, E(0.05, 0.03) > 0.5), which a uniform grid in r
/// misses in its first cell. R is sampled at α_j = j/32.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectiveSamples {
    /// E(μ_k, r_j) in `sheen[j][k]`, r_j = (j/32)².
    pub sheen: Vec<[f64; MU_NODES]>,
    /// R(μ_k, α_j) in `fuzz[j][k]`, α_j = j/32.
    pub fuzz: Vec<[f64; MU_NODES]>,
}

impl ObjectiveSamples {
    /// Evaluates E and R at every node, in parallel.
    pub fn generate() -> Self {
        let rule = mu_rule();
        let grid = |f: &(dyn Fn(f64, f64) -> f64 + Sync)| -> Vec<[f64; MU_NODES]> {
            let flat: Vec<f64> = (0..SAMPLE_NODES * MU_NODES)
                .into_par_iter()
                .map(|i| f(rule[i % MU_NODES].0, sample_node(i / MU_NODES)))
                .collect();
            flat.chunks(MU_NODES)
                .map(|c| std::array::from_fn(|k| c[k]))
                .collect()
        };
        ObjectiveSamples {
            sheen: grid(&|mu, t| sheen_albedo(mu, t * t, AlbedoMethod::Quadrature)),
            fuzz: grid(&|mu, a| fuzz_reflectance(mu, a, ReflectanceMethod::Quadrature)),
        }
    }

    /// E(μ_k, r) interpolated in √r.
    pub fn sheen_at(&self, r: f64) -> [f64; MU_NODES] {
        let t = clamp01(r).sqrt();
        std::array::from_fn(|k| catmull_rom(SAMPLE_NODES, |j| self.sheen[j][k], t))
    }

    /// R(μ_k, α) interpolated in α.
    pub fn fuzz_at(&self, alpha: f64) -> [f64; MU_NODES] {
        std::array::from_fn(|k| catmull_rom(SAMPLE_NODES, |j| self.fuzz[j][k], alpha))
    }
}

/// The mapping tables: the optimum at every roughness node, each way.
#[derive(Clone, Debug, PartialEq)]
pub struct MappingTables {
    /// α(r_j) and the rms it leaves.
    pub fuzz_for_sheen: Vec<Optimum>,
    /// r(α_j) and the rms it leaves.
    pub sheen_for_fuzz: Vec<Optimum>,
}

/// Tolerance in roughness of the tables' minimisation (on the interpolated objective, which
/// is smooth, so it can be tight).
const TABLE_TOL: f64 = 1e-7;

/// The mapping tables from the objective samples: at each table node, the best of the 33
/// sample values of the other roughness, then Brent between that value's neighbours (ends
/// included). The sheen roughness is searched in √r, the variable its samples are even in.
pub fn generate_tables(samples: &ObjectiveSamples) -> MappingTables {
    let rule = mu_rule();
    let optimum = |mut f: Box<dyn FnMut(f64) -> f64 + '_>| {
        let (x, fx) = scan_then_minimise(&mut f, SAMPLE_NODES, TABLE_TOL);
        Optimum {
            roughness: x,
            rms: fx.max(0.0).sqrt(),
        }
    };
    let fuzz_for_sheen = (0..NODES)
        .into_par_iter()
        .map(|j| {
            let e = samples.sheen_at(node(j));
            optimum(Box::new(move |a| {
                mean_square(&rule, &e, &samples.fuzz_at(a))
            }))
        })
        .collect();
    let sheen_for_fuzz = (0..NODES)
        .into_par_iter()
        .map(|j| {
            let f = samples.fuzz_at(node(j));
            let best = optimum(Box::new(move |t| {
                mean_square(&rule, &samples.sheen_at(t * t), &f)
            }));
            Optimum {
                roughness: best.roughness * best.roughness,
                rms: best.rms,
            }
        })
        .collect();
    MappingTables {
        fuzz_for_sheen,
        sheen_for_fuzz,
    }
}

/// The source text of `mapping_table.rs` for the given tables.
pub fn tables_source(tables: &MappingTables) -> String {
    let list = |v: &[Optimum], pick: fn(&Optimum) -> f64| {
        v.iter()
            .map(|o| format!("    {:?},\n", pick(o)))
            .collect::<String>()
    };
    format!(
        "//! The sheen ↔ fuzz roughness mapping at its nodes (see `mapping.rs`), computed by\n\
         //! velvet's own code. Generated: `VELVET_UPDATE_GOLDEN=1 cargo test --lib\n\
         //! shading::mapping` rewrites this file, and that test fails when the code no longer\n\
         //! gives these values. Do not edit by hand.\n\n\
         /// Nodes: roughness j/(NODES − 1).\n\
         pub const NODES: usize = 257;\n\n\
         /// α(r_j): the fuzz roughness closest to a sheen of roughness r_j = j/256.\n\
         pub static FUZZ_FOR_SHEEN: [f64; NODES] = [\n{}];\n\n\
         /// The cosine-weighted rms of E(μ, r_j) − R(μ, α(r_j)).\n\
         pub static FUZZ_FOR_SHEEN_RMS: [f64; NODES] = [\n{}];\n\n\
         /// r(α_j): the sheen roughness closest to a fuzz of roughness α_j = j/256.\n\
         pub static SHEEN_FOR_FUZZ: [f64; NODES] = [\n{}];\n\n\
         /// The cosine-weighted rms of E(μ, r(α_j)) − R(μ, α_j).\n\
         pub static SHEEN_FOR_FUZZ_RMS: [f64; NODES] = [\n{}];\n",
        list(&tables.fuzz_for_sheen, |o| o.roughness),
        list(&tables.fuzz_for_sheen, |o| o.rms),
        list(&tables.sheen_for_fuzz, |o| o.roughness),
        list(&tables.sheen_for_fuzz, |o| o.rms),
    )
}

/// Linear interpolation of node values at x ∈ [0, 1] (clamped; NaN reads as 0), computed as
/// the bake engine's sampled curves compute it, so that a curve with these samples gives the
/// same numbers.
fn linear(values: &[f64], x: f64) -> f64 {
    let last = values.len() - 1;
    let t = clamp01(x) * last as f64;
    let i = (t.floor() as usize).min(last - 1);
    let frac = t - i as f64;
    let (a, b) = (values[i], values[i + 1]);
    if frac == 0.0 {
        a
    } else {
        a + (b - a) * frac
    }
}

/// α(r): the fuzz roughness whose reflectance is closest to the sheen albedo of roughness r
/// (cosine-weighted, see the module comment), from the 257-node table.
pub fn fuzz_roughness_for_sheen(r: f64) -> f64 {
    linear(&mapping_table::FUZZ_FOR_SHEEN, r)
}

/// r(α): the sheen roughness whose albedo is closest to the fuzz reflectance of roughness α,
/// from the 257-node table.
pub fn sheen_roughness_for_fuzz(alpha: f64) -> f64 {
    linear(&mapping_table::SHEEN_FOR_FUZZ, alpha)
}

/// α(r) at the table's nodes r_j = j/256 (what a bake curve samples).
pub fn fuzz_for_sheen_nodes() -> &'static [f64; NODES] {
    &mapping_table::FUZZ_FOR_SHEEN
}

/// r(α) at the table's nodes α_j = j/256.
pub fn sheen_for_fuzz_nodes() -> &'static [f64; NODES] {
    &mapping_table::SHEEN_FOR_FUZZ
}

/// The cosine-weighted rms the best α leaves at each node r_j (the floor of what any fuzz
/// roughness can do for that sheen).
pub fn fuzz_for_sheen_rms() -> &'static [f64; NODES] {
    &mapping_table::FUZZ_FOR_SHEEN_RMS
}

/// The cosine-weighted rms the best r leaves at each node α_j.
pub fn sheen_for_fuzz_rms() -> &'static [f64; NODES] {
    &mapping_table::SHEEN_FOR_FUZZ_RMS
}

/// Stated bound on |α(r) table − reference optimum| for r ≥ [`POOR_MATCH_BELOW`]. Measured by
/// `velvet bench accuracy`: 5.5e-4 (at r ≈ 0.264) over 58 values between table nodes. Below
/// r = 0.1 the optimum rises from 0 at r = 0 to 0.2 at r = 1/32 and the table deviates by up
/// to 0.034 in α, which costs at most 2e-4 in rms ([`MAPPING_RMS_LOSS`]).
pub const FUZZ_FOR_SHEEN_DEVIATION: f64 = 1e-3;

/// Stated bound on |r(α) table − reference optimum| where the best sheen is r ≥
/// [`POOR_MATCH_BELOW`] at both nodes around α. Measured by `velvet bench accuracy`: 1.2e-2 (at
/// α ≈ 0.779, where r(α) runs into r = 1 with a slope near 9, so a cell of 1/256 bends visibly)
/// over 48 values between nodes; elsewhere below 2e-3. The objective is flat there: the rms
/// loss is 3e-5.
pub const SHEEN_FOR_FUZZ_DEVIATION: f64 = 1.5e-2;

/// Stated bound on rms(table's roughness) − rms(optimum's), both directions, every roughness
/// but the one cell of r(α)'s jump: what the tables' deviation costs in the matched quantity.
/// Measured by `velvet bench accuracy`: 2.0e-4 for α(r), 3.3e-5 for r(α). In the jump's cell,
/// α ∈ (0.25, 0.2539), the table blends the two branches (r from 0 to 0.137) and loses up to
/// 0.031 in rms (0.087 against 0.056 at α = 0.251).
pub const MAPPING_RMS_LOSS: f64 = 5e-4;

/// Sheen roughness below which no fuzz roughness matches the sheen well: the best α still
/// leaves a cosine-weighted rms difference several times that at r ≥ 0.25, because E(μ, r) is
/// nearly 0 except at grazing views, where it rises above 1, while R cannot be both.
pub const POOR_MATCH_BELOW: f64 = 0.1;

/// How far a sheen layer's reflectance (weighted by its colour) is from a fuzz layer's
/// (weighted by its weight): |c·E(μ, r) − w·R(μ, α)| over μ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayerMatch {
    /// The largest difference over μ ∈ [0, 1] (the rule's nodes and both ends).
    pub max: f64,
    /// The μ where it occurs.
    pub at_mu: f64,
    /// The largest difference where μ ≥ 0.1 (grazing views excluded).
    pub max_ordinary: f64,
    /// The cosine-weighted rms difference (over the rule).
    pub rms: f64,
    /// r < [`POOR_MATCH_BELOW`]: no fuzz roughness matches this sheen well.
    pub poor_match: bool,
}

/// [`layer_match_with`] with E and R by quadrature: 32 evaluations of each, at the two
/// roughness values given only.
pub fn layer_match(sheen: SheenParams, fuzz: FuzzParams) -> LayerMatch {
    layer_match_with(
        sheen,
        fuzz,
        &SheenAlbedo(AlbedoMethod::Quadrature),
        &FuzzReflectance(ReflectanceMethod::Quadrature),
    )
}

/// Compares max3(sheenColor)·E(μ, r) with w·R(μ, α): the largest difference over μ (at the
/// rule's nodes and at μ = 0 and 1; at μ = 0 E is its value at the floor μ = 1e-4), the
/// largest where μ ≥ 0.1, and the cosine-weighted rms. Colour and weight are clamped into
/// [0, 1].
pub fn layer_match_with(
    sheen: SheenParams,
    fuzz: FuzzParams,
    sheen_reflectance: &(dyn LayerReflectance + Sync),
    fuzz_reflectance: &(dyn LayerReflectance + Sync),
) -> LayerMatch {
    let rule = mu_rule();
    let (c, w) = (clamp01(sheen.color_max3), clamp01(fuzz.weight));
    let mus: Vec<f64> = std::iter::once(0.0)
        .chain(rule.iter().map(|n| n.0))
        .chain(std::iter::once(1.0))
        .collect();
    let diffs: Vec<f64> = mus
        .par_iter()
        .map(|&mu| {
            let e = sheen_reflectance.reflectance(mu, sheen.roughness);
            let r = fuzz_reflectance.reflectance(mu, fuzz.roughness);
            (c * e - w * r).abs()
        })
        .collect();
    let (at, max) =
        diffs.iter().enumerate().fold(
            (0, f64::NEG_INFINITY),
            |b, (i, &d)| if d > b.1 { (i, d) } else { b },
        );
    let max_ordinary = mus
        .iter()
        .zip(&diffs)
        .filter(|(mu, _)| **mu >= 0.1)
        .map(|(_, d)| *d)
        .fold(0.0, f64::max);
    let ms: f64 = rule
        .iter()
        .zip(&diffs[1..=MU_NODES])
        .map(|((_, wk), d)| wk * d * d)
        .sum();
    LayerMatch {
        max,
        at_mu: mus[at],
        max_ordinary,
        rms: ms.sqrt(),
        poor_match: clamp01(sheen.roughness) < POOR_MATCH_BELOW,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_is_a_cosine_weighted_mean() {
        let rule = mu_rule();
        assert!((rule.iter().map(|n| n.1).sum::<f64>() - 1.0).abs() < 1e-15);
        // Mean of μ under the weight μ: ∫μ² / ∫μ = 2/3; of μ⁵: 2/7.
        let mean = |p: i32| rule.iter().map(|(mu, w)| w * mu.powi(p)).sum::<f64>();
        assert!((mean(1) - 2.0 / 3.0).abs() < 1e-14);
        assert!((mean(5) - 2.0 / 7.0).abs() < 1e-14);
        assert!(rule.iter().all(|n| n.0 > 0.0 && n.0 < 1.0 && n.1 > 0.0));
        assert!(rule.windows(2).all(|w| w[0].0 < w[1].0));
    }

    #[test]
    fn brent_finds_interior_and_end_minima() {
        let mut calls = 0;
        let (x, fx) = bounded_minimum(
            &mut |x: f64| {
                calls += 1;
                (x - 0.3137).powi(2) + 2.0
            },
            0.0,
            1.0,
            1e-9,
        );
        // Within 2·(√ε·|x| + tol/3), Brent's own bound.
        assert!((x - 0.3137).abs() < 2e-8 && (fx - 2.0).abs() < 1e-15, "{x}");
        assert!(calls < 30, "{calls} evaluations for a parabola");
        // A minimum on an end is found exactly.
        assert_eq!(bounded_minimum(&mut |x: f64| x, 0.0, 1.0, 1e-9), (0.0, 0.0));
        assert_eq!(
            bounded_minimum(&mut |x: f64| -x, 0.2, 0.7, 1e-9),
            (0.7, -0.7)
        );
        // A kinked function: |x − 0.6|.
        let (x, _) = bounded_minimum(&mut |x: f64| (x - 0.6).abs(), 0.0, 1.0, 1e-9);
        assert!((x - 0.6).abs() < 2e-8, "{x}");
        // The scan finds the lower of two minima.
        let two = |x: f64| ((x - 0.2).powi(2) + 0.1).min((x - 0.8).powi(2));
        let (x, _) = scan_then_minimise(&mut { two }, 11, 1e-9);
        assert!((x - 0.8).abs() < 2e-8, "{x}");
    }

    #[test]
    fn linear_lookup_is_exact_at_nodes_and_clamps() {
        let v = [0.0, 0.5, 0.6, 1.0];
        assert_eq!(linear(&v, 1.0 / 3.0), 0.5);
        assert_eq!(linear(&v, 1.0), 1.0);
        assert_eq!(linear(&v, -2.0), 0.0);
        assert_eq!(linear(&v, f64::NAN), 0.0);
        assert!((linear(&v, 0.5) - 0.55).abs() < 1e-15);
    }

    #[test]
    fn committed_tables_are_what_the_generator_gives() {
        let tables = generate_tables(&ObjectiveSamples::generate());
        if std::env::var_os("VELVET_UPDATE_GOLDEN").is_some() {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("src/shading/mapping_table.rs");
            std::fs::write(&path, tables_source(&tables)).unwrap();
            return;
        }
        let pairs = [
            (
                &tables.fuzz_for_sheen,
                &mapping_table::FUZZ_FOR_SHEEN,
                &mapping_table::FUZZ_FOR_SHEEN_RMS,
            ),
            (
                &tables.sheen_for_fuzz,
                &mapping_table::SHEEN_FOR_FUZZ,
                &mapping_table::SHEEN_FOR_FUZZ_RMS,
            ),
        ];
        for (fresh, roughness, rms) in pairs {
            for j in 0..NODES {
                // Quadrature values within 1e-7 (another libm may bisect differently) move the
                // minimum of the interpolated objective by far less than 1e-6.
                assert!(
                    (fresh[j].roughness - roughness[j]).abs() <= 1e-6
                        && (fresh[j].rms - rms[j]).abs() <= 1e-7,
                    "node {j}: generated {:?}, committed ({}, {}); regenerate with VELVET_UPDATE_GOLDEN=1",
                    fresh[j],
                    roughness[j],
                    rms[j]
                );
            }
        }
    }

    /// Table nodes are j/256; these lie between nodes, where linear interpolation is worst.
    const OFF_NODE: [f64; 3] = [0.1, 0.3, 0.77];

    #[test]
    fn the_fitted_mapping_is_within_the_stated_deviation_of_the_optimum() {
        for r in OFF_NODE {
            let best = optimal_fuzz_roughness(r);
            let table = fuzz_roughness_for_sheen(r);
            assert!(
                (table - best.roughness).abs() <= FUZZ_FOR_SHEEN_DEVIATION,
                "α({r}): table {table}, optimum {best:?}"
            );
            assert!(
                mapping_rms(r, table) <= best.rms + MAPPING_RMS_LOSS,
                "α({r})"
            );
        }
        // The reverse, where the best sheen is a real lobe (above the jump).
        for alpha in [0.3, 0.6, 0.77] {
            let best = optimal_sheen_roughness(alpha);
            let table = sheen_roughness_for_fuzz(alpha);
            assert!(
                (table - best.roughness).abs() <= SHEEN_FOR_FUZZ_DEVIATION,
                "r({alpha}): table {table}, optimum {best:?}"
            );
            assert!(
                mapping_rms(table, alpha) <= best.rms + MAPPING_RMS_LOSS,
                "r({alpha})"
            );
        }
    }

    #[test]
    fn below_the_jump_the_best_fallback_sheen_is_almost_none() {
        // r(α) ≈ 0 (below 1e-6) up to α = 0.25, then a lobe of r ≈ 0.14 and more.
        let below = sheen_roughness_for_fuzz(0.2);
        let above = sheen_roughness_for_fuzz(0.27);
        assert!(below < 1e-6 && above > 0.14, "{below} {above}");
        // The table's r leaves the optimum's rms to within 1e-4.
        let best = optimal_sheen_roughness(0.2);
        assert!(best.roughness < 0.01, "{best:?}");
        let table_rms = mapping_rms(below, 0.2);
        assert!(table_rms <= best.rms + 1e-4, "{table_rms} vs {best:?}");
        // Exactly one jump, from node 64 (α = 0.25) to 65: every other step between nodes is
        // below 0.04 (the steepest continuous part runs into r = 1 near α = 0.78).
        let nodes = sheen_for_fuzz_nodes();
        let steps: Vec<(usize, f64)> = nodes
            .windows(2)
            .enumerate()
            .map(|(j, w)| (j, (w[1] - w[0]).abs()))
            .filter(|s| s.1 > 0.04)
            .collect();
        assert_eq!(steps.len(), 1, "{steps:?}");
        assert_eq!(steps[0].0, 64);
    }

    #[test]
    fn the_fitted_mapping_cuts_the_attenuation_error_of_copying_the_roughness() {
        // Pinned comparison numbers, |E(μ, r) − R(μ, α)| with colour and weight 1, for copying
        // the roughness (α = r) and for α(r). Values from velvet's quadrature.
        let cases = [
            // (r, α, max over μ ≥ 0.1, cosine-weighted rms)
            (0.25, 0.25, 0.24924, 0.07300),
            (0.25, fuzz_roughness_for_sheen(0.25), 0.06495, 0.01660),
            (0.5, 0.5, 0.04553, 0.03319),
            (0.5, fuzz_roughness_for_sheen(0.5), 0.02324, 0.00949),
            (1.0, 1.0, 0.16863, 0.14606),
            (1.0, fuzz_roughness_for_sheen(1.0), 0.07727, 0.01567),
        ];
        for (r, alpha, max_ordinary, rms) in cases {
            let m = layer_match(
                SheenParams {
                    color_max3: 1.0,
                    roughness: r,
                },
                FuzzParams {
                    weight: 1.0,
                    roughness: alpha,
                },
            );
            assert!(
                (m.max_ordinary - max_ordinary).abs() < 1e-4 && (m.rms - rms).abs() < 1e-4,
                "r = {r}, α = {alpha}: {m:?}"
            );
            assert!(m.max >= m.max_ordinary && !m.poor_match);
        }
    }

    #[test]
    fn colour_and_weight_scale_the_comparison_and_small_r_is_flagged() {
        let at = |c: f64, r: f64, w: f64, alpha: f64| {
            layer_match(
                SheenParams {
                    color_max3: c,
                    roughness: r,
                },
                FuzzParams {
                    weight: w,
                    roughness: alpha,
                },
            )
        };
        // |c·E − w·R| = c·|E − R| when c = w.
        let full = at(1.0, 0.5, 1.0, 0.55);
        let scaled = at(0.8, 0.5, 0.8, 0.55);
        assert!((scaled.rms - 0.8 * full.rms).abs() < 1e-12);
        assert!((scaled.max - 0.8 * full.max).abs() < 1e-12);
        assert_eq!(scaled.at_mu, full.at_mu);
        // r below 0.1: flagged, and E's rise at grazing views dominates the maximum.
        let small = at(1.0, 0.05, 1.0, fuzz_roughness_for_sheen(0.05));
        assert!(
            small.poor_match && small.max > 1.0 && small.at_mu < 0.01,
            "{small:?}"
        );
        assert!(!at(1.0, POOR_MATCH_BELOW, 1.0, 0.3).poor_match);
    }

    /// A reflectance that is the same number everywhere.
    struct Constant(f64);

    impl LayerReflectance for Constant {
        fn name(&self) -> String {
            "constant".into()
        }
        fn reflectance(&self, _mu: f64, _roughness: f64) -> f64 {
            self.0
        }
    }

    #[test]
    fn comparison_of_constant_reflectances_is_their_difference() {
        let m = layer_match_with(
            SheenParams {
                color_max3: 1.0,
                roughness: 0.5,
            },
            FuzzParams {
                weight: 0.8,
                roughness: 0.5,
            },
            &Constant(0.4),
            &Constant(0.25),
        );
        // |1·0.4 − 0.8·0.25| = 0.2 at every μ.
        assert!((m.max - 0.2).abs() < 1e-15 && (m.max_ordinary - 0.2).abs() < 1e-15);
        assert!((m.rms - 0.2).abs() < 1e-15);
        assert_eq!(m.at_mu, 0.0);
    }

    #[test]
    fn no_sheen_below_0_1_is_matched_as_well_as_any_above_0_25() {
        // The best α's rms for 0 < r < 0.1 is at least twice the worst for r ≥ 0.25 (0.0173):
        // why the comparison flags r < POOR_MATCH_BELOW.
        let rms = fuzz_for_sheen_rms();
        let worst_matched = (0..NODES)
            .filter(|&j| node(j) >= 0.25)
            .map(|j| rms[j])
            .fold(0.0, f64::max);
        assert!(worst_matched < 0.018, "{worst_matched}");
        for j in (1..NODES).filter(|&j| node(j) < POOR_MATCH_BELOW) {
            assert!(rms[j] > 1.5 * worst_matched, "r = {}: {}", node(j), rms[j]);
        }
    }
}
