//! The shading of one sphere: glTF 2.0's metallic-roughness base under a sheen or a fuzz layer,
//! lit by a white furnace or by one directional light with a dim ambient, in f64 linear light.
//!
//! The base is the glTF 2.0 specification's BRDF (Appendix B): f = mix(dielectric, metal,
//! metallic) with dielectric = mix(ρ/π, f_spec, F(0.04)) and metal = f_spec·F(ρ), where ρ is the
//! base colour, F(f0) = f0 + (1 − f0)(1 − |V·H|)⁵ (Schlick), f_spec = D·ν with the
//! Trowbridge-Reitz/GGX D and the height-correlated Smith visibility ν, α = roughness². The
//! BRDF is affine in ρ, f = ρ·A + B per channel, and velvet shades it as such. α is clamped to at
//! least [`MIN_ALPHA`] (the spec asks for a small positive value: D is a delta at α = 0); at
//! that α the furnace albedo is within 1e-6 of the mirror's and a point light's highlight is
//! smaller than a pixel, so a smoother base shows as a mirror of the furnace and no highlight.
//!
//! Per look, what depends on the view cosine μ alone is sampled once at [`CURVE_NODES`] view
//! cosines μ_i = (i/64)² (dense towards grazing, where E rises steeply) and read back by
//! Catmull–Rom interpolation in √μ: the layer's directional reflectance (E(μ, r) of the Charlie
//! sheen or R(μ, α) of the fuzz layer, both by velvet's quadrature) and the base's response in
//! the furnace (its directional albedo under the layer's attenuation, the integrals of A and B
//! below). Per pixel the rest is exact. The reflectance nodes are integrated to the tolerance
//! [`CURVE_TOL`], not the reports' 1e-7: they are within [`CURVE_NODE_BOUND`] of the exact
//! values (test `reflectance_curve_nodes_are_within_their_stated_error`), far below what the
//! interpolation between them adds (1.2e-4, below) and below half a code of 8-bit sRGB at any
//! level (3e-4 at black), at about 60 % of the cost.
//!
//! The layering is the specs':
//! - sheen (KHR_materials_sheen, albedo scaling with both terms):
//!   f = sheenColor·f_sheen + f_base·min(1 − max3(sheenColor)·E(μv), 1 − max3(sheenColor)·E(μl));
//! - fuzz (KHR_materials_fuzz): fuzzColor·w·f_fuzz + f_base·(1 − w·R(μv)), the attenuation a
//!   function of the view alone as the draft writes it.
//!
//! Every attenuation goes through `shading::layering` (clamped into [0, 1]). In the furnace (a
//! uniform white environment of radiance 1) the lobe gives colour·E (or colour·w·R) and the base
//! gives ∫ f_base(v, l)·a(μv, μl)·μl dω_l over the light hemisphere, with the attenuation a inside
//! the integral (for the sheen it depends on μl too). That integral is computed per look at each
//! curve node by a fixed midpoint rule, in two parts:
//! - the diffuse part (1 − metallic)(1 − F(0.04))·ρ/π over light directions, μl = t² on
//!   [`DIFFUSE_STEPS`] steps in t (dense at grazing light, where the sheen's E(μl) is steep) and
//!   [`AZIMUTH_STEPS`] in the azimuth over [0, π] (the view lies in a plane of symmetry);
//! - the specular part over half-vectors, which the GGX distribution's own inverse cumulative
//!   (cos²θh = (1 − u)/(1 + (α² − 1)u)) spreads so that D cancels: the integrand ν·μl·4(V·H)/(N·H)
//!   is bounded at any α, on [`SPECULAR_STEPS`] steps in u and [`AZIMUTH_STEPS`] in the azimuth.
//!
//! Measured against the same rules with 8× the steps in each dimension (the test
//! `base_furnace_quadrature_is_within_its_stated_error`: metallic 0, 0.5 and 1, roughness 0.05
//! to 1, μv from 0.016 to 1, with and without a sheen of r = 0.07, whose E exceeds 1 at
//! grazing), the curve values are within [`BASE_FURNACE_TOL`]: the largest difference is 1.6e-3,
//! at μv = 0.016 (metallic 1, roughness 0.3, where L meets the horizon across the lobe), and
//! below 6e-4 for μv ≥ 0.1. The interpolation between nodes adds at most 1.2e-4 for μ ≥ 0.05
//! (`base_furnace_interpolation_is_within_its_stated_error`). The rules' sample points and
//! weights are built once per base (65 nodes × (96 + 96) × 24 samples, [`BaseRule`]) and kept
//! for the few bases last used; a look with a sheen then only evaluates its attenuation at
//! them. Without a layer or under the fuzz layer (whose attenuation depends on the view alone)
//! the base's albedo is computed once per (metallic, roughness) and shared by the looks that
//! have that base. Under the directional light (irradiance [`SUN_IRRADIANCE`] from
//! [`SUN_DIRECTION`], plus the furnace scaled by [`AMBIENT`]) the lobe is the Charlie sheen
//! D·V·NdotL (`shading::charlie`) or the fuzz model's single plus multiple scattering
//! (`shading::fuzz`), and the base f_base·NdotL, evaluated exactly per pixel, times the
//! attenuation at (μv, μl). Linear values above 1 (a sheen whose E exceeds 1, a specular
//! highlight) are left as they are: the sheet marks them.

use crate::shading::albedo::albedo_quadrature;
use crate::shading::charlie::{clamp01, sheen_brdf_cos, Visibility};
use crate::shading::fuzz::{
    catmull_rom, multiple_scattering_cos, reflectance_quadrature, single_scattering_cos, Scattering,
};
use crate::shading::layering::{fuzz_base_attenuation, max3, sheen_base_attenuation};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex, OnceLock};

/// View cosines sampled per look: μ_i = (i / (CURVE_NODES − 1))².
pub const CURVE_NODES: usize = 65;
/// The absolute tolerance the reflectance curve's nodes are integrated to.
pub const CURVE_TOL: f64 = 1e-5;
/// The stated bound on a reflectance node's error at [`CURVE_TOL`], against the quadrature at
/// 1e-9 (measured: at most 1.2e-6 for the sheen over every node at r = 0.07, 0.3 and 0.7, and
/// 5.5e-7 for the sheen and 5.1e-8 for the fuzz layer over the test's nodes and roughness).
pub const CURVE_NODE_BOUND: f64 = 1e-5;
/// Midpoint steps in t (μl = t²) of the base's diffuse furnace integral.
pub const DIFFUSE_STEPS: usize = 96;
/// Midpoint steps in the GGX distribution's cumulative of the base's specular furnace integral.
pub const SPECULAR_STEPS: usize = 96;
/// Midpoint steps in the azimuth over [0, π] of both furnace integrals.
pub const AZIMUTH_STEPS: usize = 24;
/// The stated error of the base's furnace curve values (see the module comment).
pub const BASE_FURNACE_TOL: f64 = 2e-3;
/// The smallest GGX α (roughness²) the base is shaded with.
pub const MIN_ALPHA: f64 = 1e-3;
/// The dielectric's reflectance at normal incidence (ior 1.5).
const DIELECTRIC_F0: f64 = 0.04;
/// Radiance of the dim ambient (a uniform white environment) under the directional light.
pub const AMBIENT: f64 = 0.12;
/// Irradiance of the directional light at normal incidence: a white Lambertian facing it
/// reflects 0.8.
pub const SUN_IRRADIANCE: f64 = 0.8 * PI;
/// Direction towards the directional light in view space (x right, y up, z towards the
/// viewer), unit length: up and to the left, 45° off the view axis.
pub const SUN_DIRECTION: [f64; 3] = [-0.5, 0.5, std::f64::consts::FRAC_1_SQRT_2];

/// The layer over the base, with its values at one texel (factor × texture value).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Layer {
    /// No layer: the base alone.
    None,
    /// KHR_materials_sheen: colour and roughness r.
    Sheen { color: [f64; 3], roughness: f64 },
    /// KHR_materials_fuzz: colour, weight w and roughness α.
    Fuzz {
        color: [f64; 3],
        weight: f64,
        roughness: f64,
    },
}

/// A material as one sphere shows it: a metallic-roughness base (glTF 2.0) and a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// The base colour, linear.
    pub base: [f64; 3],
    /// metallicFactor (times the texture's mean), in [0, 1].
    pub base_metallic: f64,
    /// roughnessFactor (times the texture's mean), in [0, 1]; α = roughness².
    pub base_roughness: f64,
    pub layer: Layer,
}

/// How finely a look is sampled: as a sheet draws it, or as the plan's verdict measures it.
///
/// The verdict measures every material of a library, so its curves are cheaper: the layer's
/// reflectance at [`VERDICT_CURVE_NODES`] view cosines, read from a grid over roughness
/// ([`VERDICT_ROUGHNESS_STEPS`] + 1 columns, each computed once per process by the same
/// quadrature as a sheet's nodes, on first use) by Catmull–Rom interpolation in roughness, and
/// the base's furnace integrals on [`VERDICT_STEPS`]. Every value is a function of the look
/// alone (a column is the same whichever task computes it first), so the verdict does not
/// depend on the thread count or on which materials were measured before.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quality {
    /// The sheet's curves: [`CURVE_NODES`] nodes by quadrature, the furnace on [`Steps::default`].
    Sheet,
    /// The verdict's curves (see the type's comment).
    Verdict,
}

/// View cosines sampled per look for the verdict.
pub const VERDICT_CURVE_NODES: usize = 17;
/// Roughness steps of the verdict's reflectance grid: columns at r = j / steps.
pub const VERDICT_ROUGHNESS_STEPS: usize = 64;
/// The base's furnace integrals for the verdict.
pub const VERDICT_STEPS: Steps = Steps {
    diffuse: 24,
    specular: 24,
    azimuth: 8,
};

impl Quality {
    /// How many view cosines a look's curves are sampled at.
    pub fn nodes(self) -> usize {
        match self {
            Quality::Sheet => CURVE_NODES,
            Quality::Verdict => VERDICT_CURVE_NODES,
        }
    }

    fn steps(self) -> Steps {
        match self {
            Quality::Sheet => Steps::default(),
            Quality::Verdict => VERDICT_STEPS,
        }
    }
}

/// Which directional reflectance a grid column holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Reflectance {
    Sheen,
    Fuzz,
}

/// The verdict's reflectance curve at `roughness`: the grid's columns (each computed once per
/// process, on first use) interpolated in roughness.
fn grid_curve(kind: Reflectance, roughness: f64) -> Vec<f64> {
    type Columns = Vec<OnceLock<Vec<f64>>>;
    static GRID: OnceLock<[Columns; 2]> = OnceLock::new();
    let grid = GRID.get_or_init(|| {
        std::array::from_fn(|_| {
            (0..=VERDICT_ROUGHNESS_STEPS)
                .map(|_| OnceLock::new())
                .collect()
        })
    });
    let columns = &grid[kind as usize];
    let nodes = VERDICT_CURVE_NODES;
    let column = |j: usize| {
        columns[j].get_or_init(|| {
            let r = j as f64 / VERDICT_ROUGHNESS_STEPS as f64;
            (0..nodes)
                .map(|i| match kind {
                    Reflectance::Sheen => sheen_node(node_mu(i, nodes), r, CURVE_TOL),
                    Reflectance::Fuzz => fuzz_node(node_mu(i, nodes), r, CURVE_TOL),
                })
                .collect()
        })
    };
    let r = clamp01(roughness);
    (0..nodes)
        .map(|i| catmull_rom(VERDICT_ROUGHNESS_STEPS + 1, |j| column(j)[i], r).max(0.0))
        .collect()
}

/// The two lights of a contact sheet.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Light {
    /// A uniform white environment of radiance 1: the layers' directional albedo alone decides
    /// the picture.
    Furnace,
    /// One directional light with a dim ambient.
    Directional,
}

/// A look with its view-cosine curves sampled.
#[derive(Clone, Debug)]
pub struct Shaded {
    look: Look,
    quality: Quality,
    /// The layer's directional reflectance at the curve nodes (E or R; 0 without a layer).
    reflectance: Vec<f64>,
    /// The base's furnace response at the curve nodes: ∫ A·a·μl dω and ∫ B·a·μl dω (the base
    /// colour's coefficient and the constant), attenuation a inside.
    base_furnace: Vec<[f64; 2]>,
}

fn node_mu(i: usize, nodes: usize) -> f64 {
    let t = i as f64 / (nodes - 1) as f64;
    t * t
}

/// E(μ, r) of the Charlie sheen by quadrature to `tol`.
fn sheen_node(mu: f64, roughness: f64, tol: f64) -> f64 {
    albedo_quadrature(mu, roughness, Visibility::Charlie, tol).value
}

/// R(μ, α) of the fuzz layer by quadrature to `tol`.
fn fuzz_node(mu: f64, roughness: f64, tol: f64) -> f64 {
    reflectance_quadrature(mu, roughness, Scattering::Total, tol).value
}

impl Shaded {
    /// Samples the look's curves (in parallel over the nodes; each node is computed alone, so
    /// the values do not depend on the thread count).
    pub fn new(look: Look) -> Shaded {
        Shaded::with_quality(look, Quality::Sheet)
    }

    /// Samples the look's curves at `quality`.
    pub fn with_quality(look: Look, quality: Quality) -> Shaded {
        // A switched-off layer is no layer (the specs: sheenColorFactor zero or fuzzFactor zero
        // disables the layer), so it shows the base exactly as a material without one.
        let layer = match look.layer {
            Layer::Sheen { color, .. }
                if max3(color).partial_cmp(&0.0) != Some(Ordering::Greater) =>
            {
                Layer::None
            }
            Layer::Fuzz { weight, .. } if weight.partial_cmp(&0.0) != Some(Ordering::Greater) => {
                Layer::None
            }
            other => other,
        };
        let look = Look { layer, ..look };
        let nodes = quality.nodes();
        let reflectance: Vec<f64> = match (look.layer, quality) {
            (Layer::None, _) => vec![0.0; nodes],
            (Layer::Sheen { roughness, .. }, Quality::Verdict) => {
                grid_curve(Reflectance::Sheen, roughness)
            }
            (Layer::Fuzz { roughness, .. }, Quality::Verdict) => {
                grid_curve(Reflectance::Fuzz, roughness)
            }
            (Layer::Sheen { roughness, .. }, Quality::Sheet) => (0..nodes)
                .into_par_iter()
                .map(|i| sheen_node(node_mu(i, nodes), roughness, CURVE_TOL))
                .collect(),
            (Layer::Fuzz { roughness, .. }, Quality::Sheet) => (0..nodes)
                .into_par_iter()
                .map(|i| fuzz_node(node_mu(i, nodes), roughness, CURVE_TOL))
                .collect(),
        };
        let mut shaded = Shaded {
            look,
            quality,
            reflectance,
            base_furnace: Vec::new(),
        };
        let (metallic, alpha) = base_params(&look);
        shaded.base_furnace = match look.layer {
            // The attenuation depends on the view alone: it scales the base's albedo.
            Layer::None | Layer::Fuzz { .. } => base_albedo_curve(metallic, alpha, quality)
                .iter()
                .enumerate()
                .map(|(i, terms)| {
                    let av = shaded.attenuation_at(node_mu(i, nodes));
                    terms.map(|v| v * av)
                })
                .collect(),
            Layer::Sheen { .. } => {
                let rules = base_rules(metallic, alpha, quality);
                (0..nodes)
                    .into_par_iter()
                    .map(|i| {
                        let av = shaded.attenuation_at(node_mu(i, nodes));
                        rules[i].integrate(&|mu_l| av.min(shaded.attenuation_at(mu_l)))
                    })
                    .collect()
            }
        };
        shaded
    }

    /// The look this was sampled for.
    pub fn look(&self) -> Look {
        self.look
    }

    /// The layer's directional reflectance at view cosine μ (interpolated).
    pub fn reflectance_at(&self, mu: f64) -> f64 {
        let nodes = self.quality.nodes();
        catmull_rom(nodes, |k| self.reflectance[k], clamp01(mu).sqrt()).max(0.0)
    }

    /// The base attenuation for one cosine: 1 − max3(sheenColor)·E(μ) or 1 − w·R(μ), clamped
    /// into [0, 1] by `shading::layering`; 1 without a layer.
    pub fn attenuation_at(&self, mu: f64) -> f64 {
        match self.look.layer {
            Layer::None => 1.0,
            Layer::Sheen { color, .. } => {
                sheen_base_attenuation(max3(color), self.reflectance_at(mu)).factor
            }
            Layer::Fuzz { weight, .. } => {
                fuzz_base_attenuation(weight, self.reflectance_at(mu)).factor
            }
        }
    }

    /// The lobe's colour: sheenColor, or fuzzColor·w.
    fn lobe_color(&self) -> [f64; 3] {
        match self.look.layer {
            Layer::None => [0.0; 3],
            Layer::Sheen { color, .. } => color.map(clamp01),
            Layer::Fuzz { color, weight, .. } => color.map(|c| clamp01(c) * clamp01(weight)),
        }
    }

    /// The base's radiance in the white furnace at view cosine μ (under the layer's
    /// attenuation).
    pub fn base_furnace(&self, mu: f64) -> [f64; 3] {
        let x = clamp01(mu).sqrt();
        let nodes = self.quality.nodes();
        let scale = catmull_rom(nodes, |k| self.base_furnace[k][0], x).max(0.0);
        let offset = catmull_rom(nodes, |k| self.base_furnace[k][1], x).max(0.0);
        self.look.base.map(|b| clamp01(b) * scale + offset)
    }

    /// Radiance towards the viewer in the white furnace at view cosine μ.
    pub fn furnace(&self, mu: f64) -> [f64; 3] {
        let base = self.base_furnace(mu);
        let lobe = self.reflectance_at(mu);
        let c = self.lobe_color();
        std::array::from_fn(|k| c[k] * lobe + base[k])
    }

    /// Radiance towards the viewer (along +z) at a point of normal `n` under `light`.
    pub fn radiance(&self, n: [f64; 3], light: Light) -> [f64; 3] {
        let mu_v = clamp01(n[2]);
        let furnace = self.furnace(mu_v);
        if light == Light::Furnace {
            return furnace;
        }
        let l = SUN_DIRECTION;
        let mu_l = dot(n, l);
        let ambient = furnace.map(|v| AMBIENT * v);
        if mu_l <= 0.0 {
            return ambient;
        }
        let h = normalize([l[0], l[1], l[2] + 1.0]);
        let (lobe, attenuation) = match self.look.layer {
            Layer::None => (0.0, 1.0),
            Layer::Sheen { roughness, .. } => {
                let lobe = sheen_brdf_cos(mu_v, mu_l, dot(n, h), roughness, Visibility::Charlie);
                (
                    lobe,
                    self.attenuation_at(mu_v).min(self.attenuation_at(mu_l)),
                )
            }
            Layer::Fuzz { roughness, .. } => {
                let phi = azimuth(n, [0.0, 0.0, 1.0], l);
                let lobe = single_scattering_cos(mu_v, mu_l, phi, roughness)
                    + multiple_scattering_cos(mu_v, mu_l, roughness);
                (lobe, self.attenuation_at(mu_v))
            }
        };
        let (metallic, alpha) = base_params(&self.look);
        // V = +z: V·H is H's z.
        let (a, b) = base_brdf(mu_v, mu_l, dot(n, h), h[2], metallic, alpha);
        let c = self.lobe_color();
        std::array::from_fn(|k| {
            let f_base = clamp01(self.look.base[k]) * a + b;
            ambient[k] + SUN_IRRADIANCE * (c[k] * lobe + f_base * mu_l * attenuation)
        })
    }
}

/// The base's metallic (clamped into [0, 1]) and GGX α (roughness², at least [`MIN_ALPHA`]).
fn base_params(look: &Look) -> (f64, f64) {
    let r = clamp01(look.base_roughness);
    (clamp01(look.base_metallic), (r * r).max(MIN_ALPHA))
}

/// Schlick's Fresnel weight (1 − |V·H|)⁵.
fn schlick_weight(v_dot_h: f64) -> f64 {
    (1.0 - clamp01(v_dot_h.abs())).powi(5)
}

/// The Trowbridge-Reitz/GGX distribution D at N·H for α.
pub fn ggx_d(n_dot_h: f64, alpha: f64) -> f64 {
    if n_dot_h <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    a2 / (PI * d * d)
}

/// The height-correlated Smith visibility ν = G / (4·|N·L|·|N·V|) (glTF 2.0, Appendix B), 0
/// where both cosines vanish.
pub fn smith_visibility(mu_v: f64, mu_l: f64, alpha: f64) -> f64 {
    let a2 = alpha * alpha;
    let (v, l) = (mu_v.abs(), mu_l.abs());
    let den = v * (a2 + (1.0 - a2) * l * l).sqrt() + l * (a2 + (1.0 - a2) * v * v).sqrt();
    if den > 0.0 {
        0.5 / den
    } else {
        0.0
    }
}

/// The metallic-roughness BRDF at one pair of directions as (A, B) with f = baseColor·A + B per
/// channel: A = (1 − m)(1 − F(0.04))/π + m(1 − w)·D·ν, B = ((1 − m)F(0.04) + m·w)·D·ν, w the
/// Schlick weight. Zero where the light or the view lies below the surface or V·H ≤ 0.
pub fn base_brdf(
    mu_v: f64,
    mu_l: f64,
    n_dot_h: f64,
    v_dot_h: f64,
    metallic: f64,
    alpha: f64,
) -> (f64, f64) {
    if mu_l <= 0.0 || mu_v < 0.0 || v_dot_h <= 0.0 {
        return (0.0, 0.0);
    }
    let w = schlick_weight(v_dot_h);
    let f_dielectric = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * w;
    let spec = ggx_d(n_dot_h, alpha) * smith_visibility(mu_v, mu_l, alpha);
    (
        (1.0 - metallic) * (1.0 - f_dielectric) / PI + metallic * (1.0 - w) * spec,
        ((1.0 - metallic) * f_dielectric + metallic * w) * spec,
    )
}

/// The base's directional albedo terms (no attenuation) at the curve nodes for (metallic, α):
/// its [`base_rules`] integrated with no attenuation. They are a function of those two numbers
/// alone, so they are computed once per process and shared by every look with that base
/// (which task computes them first does not change them).
fn base_albedo_curve(metallic: f64, alpha: f64, quality: Quality) -> Arc<Vec<[f64; 2]>> {
    type Curves = HashMap<(u64, u64, Quality), Arc<Vec<[f64; 2]>>>;
    static KNOWN: OnceLock<Mutex<Curves>> = OnceLock::new();
    let known = KNOWN.get_or_init(|| Mutex::new(HashMap::new()));
    let key = (metallic.to_bits(), alpha.to_bits(), quality);
    if let Some(curve) = known.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Arc::clone(curve);
    }
    let curve: Arc<Vec<[f64; 2]>> = Arc::new(
        base_rules(metallic, alpha, quality)
            .par_iter()
            .map(|rule| rule.integrate(&|_| 1.0))
            .collect(),
    );
    known
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, Arc::clone(&curve));
    curve
}

/// The step counts of the base's furnace integrals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Steps {
    pub diffuse: usize,
    pub specular: usize,
    pub azimuth: usize,
}

impl Default for Steps {
    fn default() -> Self {
        Steps {
            diffuse: DIFFUSE_STEPS,
            specular: SPECULAR_STEPS,
            azimuth: AZIMUTH_STEPS,
        }
    }
}

/// The base's furnace response at view cosine `mu_v`: [∫ A·a(μl)·μl dω, ∫ B·a(μl)·μl dω] over
/// the light hemisphere, `attenuation` giving a(μl) for this view, by the midpoint rules of the
/// module comment. The view lies in the xz plane, so the azimuth runs over [0, π], doubled.
pub fn base_furnace_terms(
    mu_v: f64,
    metallic: f64,
    alpha: f64,
    attenuation: &dyn Fn(f64) -> f64,
    steps: Steps,
) -> [f64; 2] {
    BaseRule::new(mu_v, metallic, alpha, steps).integrate(attenuation)
}

/// One diffuse sample of a [`BaseRule`]: a light cosine and its weight before the attenuation.
#[derive(Clone, Copy, Debug)]
struct DiffuseSample {
    mu_l: f64,
    /// (1 − m)/π · Σ_φ (1 − F) · 2 · (π/N) · μl.
    weight: f64,
    t: f64,
}

/// One specular sample of a [`BaseRule`]: a light cosine, ν·μl·4(V·H)/(N·H), and its A and B
/// coefficients.
#[derive(Clone, Copy, Debug)]
struct SpecularSample {
    mu_l: f64,
    weight: f64,
    coef_a: f64,
    coef_b: f64,
}

/// A ring of specular samples (one step in u) and its step widths.
#[derive(Clone, Debug)]
struct SpecularRing {
    du: f64,
    d_phi: f64,
    samples: Vec<SpecularSample>,
}

/// The base's furnace integrals at one view cosine with everything but the layer's attenuation
/// evaluated: the sample points and weights of the midpoint rules. The attenuation a(μl) is
/// the only part that depends on the layer, so the rule is built once per base and view and
/// integrated for each layer over that base; [`BaseRule::integrate`] performs the same
/// operations in the same order as evaluating the rules directly, so its values do not
/// depend on whether a rule was shared.
#[derive(Clone, Debug)]
pub struct BaseRule {
    diffuse: Vec<DiffuseSample>,
    dt: f64,
    specular: Vec<SpecularRing>,
}

impl BaseRule {
    /// The rule at view cosine `mu_v` for a base of `metallic` and GGX `alpha`.
    pub fn new(mu_v: f64, metallic: f64, alpha: f64, steps: Steps) -> BaseRule {
        let mu_v = clamp01(mu_v);
        let sin_v = (1.0 - mu_v * mu_v).max(0.0).sqrt();
        let azimuths: Vec<(f64, f64)> = (0..steps.azimuth)
            .map(|k| {
                let phi = (k as f64 + 0.5) / steps.azimuth as f64 * PI;
                (phi.cos(), phi.sin())
            })
            .collect();

        // Diffuse: (1 − m)(1 − F(0.04))/π over light directions, μl = t², dω = 2t dt dφ (×2).
        let dt = 1.0 / steps.diffuse as f64;
        let mut diffuse = Vec::new();
        if metallic < 1.0 {
            for j in 0..steps.diffuse {
                let t = (j as f64 + 0.5) * dt;
                let mu_l = t * t;
                let sin_l = (1.0 - mu_l * mu_l).max(0.0).sqrt();
                let mut ring = 0.0;
                for &(cos_phi, _) in &azimuths {
                    // V·H = √((1 + V·L)/2).
                    let v_dot_l = sin_v * sin_l * cos_phi + mu_v * mu_l;
                    let v_dot_h = (0.5 * (1.0 + v_dot_l)).max(0.0).sqrt();
                    let f = DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * schlick_weight(v_dot_h);
                    ring += 1.0 - f;
                }
                let weight =
                    (1.0 - metallic) / PI * ring * 2.0 * (PI / steps.azimuth as f64) * mu_l;
                diffuse.push(DiffuseSample { mu_l, weight, t });
            }
        }

        // Specular over half-vectors H with density D(H)·(N·H):
        // ∫ g dω_l = ∫∫ g·4(V·H)/(D·N·H) du dφ/2π, cos²θh = (1 − u)/(1 + (α² − 1)u). The steps
        // run in s with 1 − u = (1 − s)², du = 2(1 − s) ds, dense where u nears 1 (the
        // distribution's tail, where L reaches the horizon). On each ring of H the azimuths
        // that send L above the horizon are an interval [0, φmax] (μl = 2(V·H)(N·H) − μv > 0
        // ⟺ cos φ > c0, below), and the azimuth's midpoints cover that interval alone: no step
        // in the integrand.
        let a2 = alpha * alpha;
        let ds = 1.0 / steps.specular as f64;
        let mut specular = Vec::new();
        for j in 0..steps.specular {
            let s = (j as f64 + 0.5) * ds;
            let one_minus_u = (1.0 - s) * (1.0 - s);
            let u = 1.0 - one_minus_u;
            let du = 2.0 * (1.0 - s) * ds;
            let cos2 = (one_minus_u / (1.0 + (a2 - 1.0) * u)).clamp(0.0, 1.0);
            let n_dot_h = cos2.sqrt();
            let sin_h = (1.0 - cos2).sqrt();
            if n_dot_h <= 0.0 {
                continue;
            }
            let across = sin_v * sin_h;
            let need = mu_v * (0.5 / n_dot_h - n_dot_h);
            let phi_max = if across > 1e-12 {
                (need / across).clamp(-1.0, 1.0).acos()
            } else if need < 0.0 {
                PI
            } else {
                0.0
            };
            if phi_max <= 0.0 {
                continue;
            }
            let d_phi = phi_max / steps.azimuth as f64;
            let mut samples = Vec::with_capacity(steps.azimuth);
            for k in 0..steps.azimuth {
                let phi = (k as f64 + 0.5) * d_phi;
                let v_dot_h = across * phi.cos() + mu_v * n_dot_h;
                let mu_l = 2.0 * v_dot_h * n_dot_h - mu_v;
                if v_dot_h <= 0.0 || mu_l <= 0.0 {
                    continue;
                }
                let w = schlick_weight(v_dot_h);
                samples.push(SpecularSample {
                    mu_l,
                    weight: smith_visibility(mu_v, mu_l, alpha) * mu_l * 4.0 * v_dot_h / n_dot_h,
                    coef_a: metallic * (1.0 - w),
                    coef_b: (1.0 - metallic) * (DIELECTRIC_F0 + (1.0 - DIELECTRIC_F0) * w)
                        + metallic * w,
                });
            }
            specular.push(SpecularRing { du, d_phi, samples });
        }
        BaseRule {
            diffuse,
            dt,
            specular,
        }
    }

    /// [∫ A·a(μl)·μl dω, ∫ B·a(μl)·μl dω] with `attenuation` giving a(μl).
    pub fn integrate(&self, attenuation: &dyn Fn(f64) -> f64) -> [f64; 2] {
        let (mut sum_a, mut sum_b) = (0.0, 0.0);
        for d in &self.diffuse {
            sum_a += d.weight * attenuation(d.mu_l) * 2.0 * d.t * self.dt;
        }
        for ring in &self.specular {
            for p in &ring.samples {
                let g = p.weight * attenuation(p.mu_l) * ring.du * ring.d_phi / PI;
                sum_a += p.coef_a * g;
                sum_b += p.coef_b * g;
            }
        }
        [sum_a, sum_b]
    }
}

/// How many bases' rules [`base_rules`] keeps: a sheet's looks share one base, and each of the
/// threads drawing sheets at once needs its own (a rule set is about 5 MB).
const KEPT_BASE_RULES: usize = 4;

/// The rules at every curve node for (metallic, α): built once and shared while among the
/// [`KEPT_BASE_RULES`] most recently used. A rule is a function of those two numbers alone, so
/// which task builds it does not change a value.
fn base_rules(metallic: f64, alpha: f64, quality: Quality) -> Arc<Vec<BaseRule>> {
    type Kept = Vec<((u64, u64, Quality), Arc<Vec<BaseRule>>)>;
    static KEPT: OnceLock<Mutex<Kept>> = OnceLock::new();
    let kept = KEPT.get_or_init(|| Mutex::new(Vec::new()));
    let key = (metallic.to_bits(), alpha.to_bits(), quality);
    {
        let mut kept = kept.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(at) = kept.iter().position(|(k, _)| *k == key) {
            let entry = kept.remove(at);
            let rules = Arc::clone(&entry.1);
            kept.push(entry);
            return rules;
        }
    }
    let rules: Arc<Vec<BaseRule>> = Arc::new(
        (0..quality.nodes())
            .into_par_iter()
            .map(|i| {
                BaseRule::new(
                    node_mu(i, quality.nodes()),
                    metallic,
                    alpha,
                    quality.steps(),
                )
            })
            .collect(),
    );
    let mut kept = kept.lock().unwrap_or_else(|e| e.into_inner());
    if !kept.iter().any(|(k, _)| *k == key) {
        if kept.len() == KEPT_BASE_RULES {
            kept.remove(0);
        }
        kept.push((key, Arc::clone(&rules)));
    }
    rules
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    a.map(|v| v / n)
}

/// The azimuth between the view `v` and the light `l` around the normal `n` (0: the light on
/// the viewer's side). Where either lies along the normal the azimuth does not matter: 0.
fn azimuth(n: [f64; 3], v: [f64; 3], l: [f64; 3]) -> f64 {
    let (cv, cl) = (dot(n, v), dot(n, l));
    let vt: [f64; 3] = std::array::from_fn(|k| v[k] - cv * n[k]);
    let lt: [f64; 3] = std::array::from_fn(|k| l[k] - cl * n[k]);
    let (nv, nl) = (dot(vt, vt).sqrt(), dot(lt, lt).sqrt());
    if nv < 1e-12 || nl < 1e-12 {
        return 0.0;
    }
    (dot(vt, lt) / (nv * nl)).clamp(-1.0, 1.0).acos()
}

/// Subsamples per pixel side for the sphere's edge coverage.
const EDGE_SUBSAMPLES: usize = 4;

/// The unit normal seen at the centre of pixel (x, y) of a sphere drawn in a `size`×`size`
/// square (orthographic view along −z, y up), or `None` when the centre lies off the sphere.
pub fn pixel_normal(size: usize, x: usize, y: usize) -> Option<[f64; 3]> {
    let s = size as f64;
    let px = (x as f64 + 0.5) / s * 2.0 - 1.0;
    let py = 1.0 - (y as f64 + 0.5) / s * 2.0;
    let r2 = px * px + py * py;
    (r2 < 1.0).then(|| [px, py, (1.0 - r2).sqrt()])
}

/// The fraction of pixel (x, y) the sphere covers, from EDGE_SUBSAMPLES² sample points.
fn coverage(size: usize, x: usize, y: usize) -> f64 {
    let s = size as f64;
    let n = EDGE_SUBSAMPLES;
    let mut inside = 0;
    for j in 0..n {
        for i in 0..n {
            let px = (x as f64 + (i as f64 + 0.5) / n as f64) / s * 2.0 - 1.0;
            let py = 1.0 - (y as f64 + (j as f64 + 0.5) / n as f64) / s * 2.0;
            inside += usize::from(px * px + py * py < 1.0);
        }
    }
    inside as f64 / (n * n) as f64
}

/// Per pixel of a sphere of `size` pixels a side: the normal it is shaded with and the fraction
/// of it the sphere covers (0: off the sphere). Pixels whose centre lies off the sphere but
/// which it partly covers are shaded at the nearest point of the sphere just inside the
/// silhouette.
fn pixel_geometry(size: usize) -> Vec<([f64; 3], f64)> {
    let mut out = Vec::with_capacity(size * size);
    for y in 0..size {
        for x in 0..size {
            let c = coverage(size, x, y);
            let n = pixel_normal(size, x, y).unwrap_or_else(|| {
                let s = size as f64;
                let px = (x as f64 + 0.5) / s * 2.0 - 1.0;
                let py = 1.0 - (y as f64 + 0.5) / s * 2.0;
                let r = (px * px + py * py).sqrt();
                let k = 0.999 / r;
                let (px, py) = (px * k, py * k);
                [px, py, (1.0 - px * px - py * py).max(0.0).sqrt()]
            });
            out.push((n, c));
        }
    }
    out
}

/// [`pixel_geometry`] of `size`, computed once per size: every sphere of a sheet has the same
/// outline.
fn geometry_of(size: usize) -> Arc<Vec<([f64; 3], f64)>> {
    type Geometry = Arc<Vec<([f64; 3], f64)>>;
    static KNOWN: OnceLock<Mutex<HashMap<usize, Geometry>>> = OnceLock::new();
    let known = KNOWN.get_or_init(|| Mutex::new(HashMap::new()));
    let mut known = known.lock().unwrap_or_else(|e| e.into_inner());
    Arc::clone(
        known
            .entry(size)
            .or_insert_with(|| Arc::new(pixel_geometry(size))),
    )
}

/// A sphere image: linear radiance and coverage per pixel, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub size: usize,
    pub radiance: Vec<[f64; 3]>,
    pub coverage: Vec<f64>,
}

/// Renders `shaded` as a sphere of `size`×`size` pixels under `light` (see [`pixel_geometry`]
/// for the pixels on its outline).
pub fn render_sphere(shaded: &Shaded, light: Light, size: usize) -> Sphere {
    let geometry = geometry_of(size);
    Sphere {
        size,
        radiance: geometry
            .iter()
            .map(|&(n, c)| {
                if c > 0.0 {
                    shaded.radiance(n, light)
                } else {
                    [0.0; 3]
                }
            })
            .collect(),
        coverage: geometry.iter().map(|g| g.1).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn look(base: [f64; 3], metallic: f64, roughness: f64, layer: Layer) -> Look {
        Look {
            base,
            base_metallic: metallic,
            base_roughness: roughness,
            layer,
        }
    }

    #[test]
    fn no_layer_is_the_base_brdf_in_the_furnace_and_under_the_light() {
        let s = Shaded::new(look([0.2, 0.5, 0.8], 0.3, 0.6, Layer::None));
        for mu in [0.0, 0.3, 1.0] {
            assert_eq!(s.furnace(mu), s.base_furnace(mu));
        }
        // Facing the light: N = L, H halfway between L and V = +z.
        let n = SUN_DIRECTION;
        let h = normalize([n[0], n[1], n[2] + 1.0]);
        let (a, b) = base_brdf(n[2], 1.0, dot(n, h), h[2], 0.3, 0.36);
        let got = s.radiance(n, Light::Directional);
        let furnace = s.furnace(n[2]);
        for k in 0..3 {
            let want = AMBIENT * furnace[k] + SUN_IRRADIANCE * (s.look.base[k] * a + b);
            assert!((got[k] - want).abs() < 1e-12);
        }
    }

    #[test]
    fn fuzz_furnace_is_the_draft_formula() {
        let base = [0.5, 0.25, 0.1];
        let layer = Layer::Fuzz {
            color: [1.0, 0.5, 0.0],
            weight: 0.8,
            roughness: 0.5,
        };
        let s = Shaded::new(look(base, 0.0, 0.7, layer));
        let bare = Shaded::new(look(base, 0.0, 0.7, Layer::None));
        // At curve nodes (μ = 1/4, 9/16, 1) the values are the quadrature's (at the curve's
        // tolerance); between them (μ = 1/2) the interpolation is within 1e-4.
        for (mu, tol) in [(0.25, 1e-12), (0.5625, 1e-12), (1.0, 1e-12), (0.5, 1e-4)] {
            let r = fuzz_node(mu, 0.5, CURVE_TOL);
            let got = s.furnace(mu);
            let under = bare.furnace(mu);
            for k in 0..3 {
                let c = [1.0, 0.5, 0.0][k];
                let want = c * 0.8 * r + under[k] * (1.0 - 0.8 * r);
                assert!((got[k] - want).abs() < tol, "μ={mu}: {got:?}");
            }
        }
    }

    #[test]
    fn a_metal_reflects_its_colour_and_a_dielectric_diffuses_it() {
        let colour = [0.9, 0.6, 0.2];
        let metal = Shaded::new(look(colour, 1.0, 0.1, Layer::None));
        let dielectric = Shaded::new(look(colour, 0.0, 0.1, Layer::None));
        // At normal incidence a smooth metal's albedo is its colour (F(V·H ≈ 1) = f0) within
        // 5e-3; a smooth dielectric's is 0.04 of specular plus the Fresnel-weighted diffuse
        // colour, 0.04 + ρ·(1 − F̄) with the hemisphere's mean F̄ between 0.04 and 0.1.
        let m = metal.furnace(1.0);
        let d = dielectric.furnace(1.0);
        for k in 0..3 {
            assert!((m[k] - colour[k]).abs() < 5e-3, "metal {m:?}");
            let diffuse = d[k] - 0.04;
            assert!(
                diffuse > colour[k] * 0.9 - 5e-3 && diffuse < colour[k] * 0.96 + 5e-3,
                "dielectric {d:?}"
            );
        }
        // Under the light the metal's highlight is far brighter than the dielectric's.
        let h = normalize([SUN_DIRECTION[0], SUN_DIRECTION[1], SUN_DIRECTION[2] + 1.0]);
        let mh = metal.radiance(h, Light::Directional);
        let dh = dielectric.radiance(h, Light::Directional);
        assert!(mh[0] > 10.0 * dh[0], "{mh:?} vs {dh:?}");
    }

    #[test]
    fn a_rough_dielectric_is_not_lambert() {
        let s = Shaded::new(look([0.5; 3], 0.0, 1.0, Layer::None));
        // A Lambertian of albedo 0.5 would show 0.5 at every view. The Fresnel weight takes
        // from the diffuse at the centre (0.5·0.960 + 0.012 specular = 0.492), the specular
        // lobe adds towards the rim (0.533 at μ = 0.05).
        let centre = s.furnace(1.0)[0];
        let rim = s.furnace(0.05)[0];
        assert!((centre - 0.4922).abs() < 1e-3, "{centre}");
        assert!((rim - 0.533).abs() < 2e-3, "{rim}");
    }

    #[test]
    fn zero_roughness_and_grazing_views_give_finite_values() {
        for metallic in [0.0, 1.0] {
            for layer in [
                Layer::None,
                Layer::Sheen {
                    color: [1.0; 3],
                    roughness: 0.07,
                },
                Layer::Fuzz {
                    color: [1.0; 3],
                    weight: 1.0,
                    roughness: 0.3,
                },
            ] {
                let s = Shaded::new(look([0.7, 0.2, 0.1], metallic, 0.0, layer));
                for mu in [0.0, 1e-12, 1e-6, 0.01, 0.5, 1.0] {
                    let f = s.furnace(mu);
                    assert!(f.iter().all(|v| v.is_finite() && *v >= 0.0), "{f:?}");
                    let sin = (1.0 - mu * mu).sqrt();
                    for phi in [0.0, 1.0, 2.5, 4.0] {
                        let n = [sin * f64::cos(phi), sin * f64::sin(phi), mu];
                        let r = s.radiance(n, Light::Directional);
                        assert!(r.iter().all(|v| v.is_finite() && *v >= 0.0), "{r:?}");
                    }
                }
                // A mirror metal reflects the white furnace as its colour at normal incidence.
                if metallic == 1.0 && layer == Layer::None {
                    let f = s.furnace(1.0);
                    assert!((f[0] - 0.7).abs() < 1e-3, "{f:?}");
                }
            }
        }
        // The directional light at exactly the mirror direction of a smooth base: large, finite.
        let s = Shaded::new(look([1.0; 3], 1.0, 0.0, Layer::None));
        let h = normalize([SUN_DIRECTION[0], SUN_DIRECTION[1], SUN_DIRECTION[2] + 1.0]);
        let r = s.radiance(h, Light::Directional);
        assert!(r[0].is_finite() && r[0] > 1.0);
    }

    #[test]
    fn reflectance_curve_nodes_are_within_their_stated_error() {
        // Against the same quadrature at 1e-9, over the roughness range's ends and the hard
        // corner (small roughness at grazing views, where E exceeds 1), at the grazing nodes
        // and every fourth one.
        let nodes: Vec<usize> = (0..6).chain((8..CURVE_NODES).step_by(8)).collect();
        let mut worst: [f64; 2] = [0.0; 2];
        for roughness in [0.0, 0.02, 0.07, 0.3, 0.7, 1.0] {
            for &i in &nodes {
                let mu = node_mu(i, CURVE_NODES);
                let e = sheen_node(mu, roughness, CURVE_TOL) - sheen_node(mu, roughness, 1e-9);
                let r = fuzz_node(mu, roughness, CURVE_TOL) - fuzz_node(mu, roughness, 1e-9);
                worst = [worst[0].max(e.abs()), worst[1].max(r.abs())];
            }
        }
        eprintln!(
            "largest node error: sheen {:.2e}, fuzz {:.2e}",
            worst[0], worst[1]
        );
        assert!(
            worst[0] <= CURVE_NODE_BOUND && worst[1] <= CURVE_NODE_BOUND,
            "{worst:?}"
        );
    }

    #[test]
    fn base_furnace_quadrature_is_within_its_stated_error() {
        // The same rules with 8× the steps in each dimension.
        let fine = Steps {
            diffuse: DIFFUSE_STEPS * 8,
            specular: SPECULAR_STEPS * 8,
            azimuth: AZIMUTH_STEPS * 8,
        };
        let sheen = Shaded::new(look(
            [0.5; 3],
            0.0,
            1.0,
            Layer::Sheen {
                color: [1.0; 3],
                roughness: 0.07,
            },
        ));
        let mut worst: f64 = 0.0;
        for (metallic, roughness) in [
            (0.0, 1.0f64),
            (0.0, 0.05),
            (1.0, 0.3),
            (1.0, 0.05),
            (0.5, 0.6),
        ] {
            let alpha = (roughness * roughness).max(MIN_ALPHA);
            for mu in [0.016, 0.1, 0.4, 1.0] {
                let av = sheen.attenuation_at(mu);
                let sheen_att = |mu_l: f64| av.min(sheen.attenuation_at(mu_l));
                for att in [&(|_: f64| 1.0) as &dyn Fn(f64) -> f64, &sheen_att] {
                    let got = base_furnace_terms(mu, metallic, alpha, att, Steps::default());
                    let want = base_furnace_terms(mu, metallic, alpha, att, fine);
                    for k in 0..2 {
                        worst = worst.max((got[k] - want[k]).abs());
                    }
                }
            }
        }
        eprintln!("largest difference from 8× the steps: {worst:.2e}");
        assert!(worst < BASE_FURNACE_TOL, "{worst}");
    }

    #[test]
    fn base_furnace_interpolation_is_within_its_stated_error() {
        // Halfway between curve nodes (in √μ), for μ ≥ 0.05: the interpolated curves against
        // the quadrature at that μ.
        let mut worst: f64 = 0.0;
        for (metallic, roughness) in [(0.0, 1.0f64), (0.0, 0.05), (1.0, 0.3), (1.0, 0.05)] {
            for layer in [
                Layer::None,
                Layer::Sheen {
                    color: [1.0; 3],
                    roughness: 0.3,
                },
            ] {
                let s = Shaded::new(look([1.0, 0.0, 0.0], metallic, roughness, layer));
                let alpha = (roughness * roughness).max(MIN_ALPHA);
                for i in 14..CURVE_NODES - 1 {
                    let x = (i as f64 + 0.5) / (CURVE_NODES - 1) as f64;
                    let mu = x * x;
                    let av = s.attenuation_at(mu);
                    let att = |mu_l: f64| match layer {
                        Layer::Sheen { .. } => av.min(s.attenuation_at(mu_l)),
                        _ => av,
                    };
                    let [a, b] = base_furnace_terms(mu, metallic, alpha, &att, Steps::default());
                    let got = s.base_furnace(mu);
                    worst = worst.max((got[0] - (a + b)).abs()).max((got[1] - b).abs());
                }
            }
        }
        eprintln!("largest interpolation error for μ ≥ 0.05: {worst:.2e}");
        assert!(worst < 1e-3, "{worst}");
    }

    #[test]
    fn azimuth_is_zero_on_the_viewers_side_and_pi_opposite() {
        let n = [0.0, 0.0, 1.0];
        let v = normalize([1.0, 0.0, 1.0]);
        assert!(azimuth(n, v, normalize([1.0, 0.0, 2.0])).abs() < 1e-12);
        assert!((azimuth(n, v, normalize([-1.0, 0.0, 2.0])) - PI).abs() < 1e-12);
        assert_eq!(azimuth(n, n, v), 0.0);
    }

    #[test]
    fn coverage_is_full_inside_and_empty_outside() {
        assert_eq!(coverage(32, 16, 16), 1.0);
        assert_eq!(coverage(32, 0, 0), 0.0);
        let edge = coverage(32, 16, 0);
        assert!(edge > 0.0 && edge <= 1.0);
    }
}
