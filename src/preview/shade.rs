//! The shading of one sphere: a Lambertian base under a sheen or a fuzz layer, lit by a white
//! furnace or by one directional light with a dim ambient, in f64 linear light.
//!
//! Per look, what depends on the view cosine μ alone is sampled once at [`CURVE_NODES`] view
//! cosines μ_i = (i/64)² (dense towards grazing, where E rises steeply) and read back by
//! Catmull–Rom interpolation in √μ: the layer's directional reflectance (E(μ, r) of the Charlie
//! sheen or R(μ, α) of the fuzz layer, both by velvet's quadrature) and, for the sheen, the
//! base's furnace factor below. Per pixel the rest is exact.
//!
//! The layering is the specs':
//! - sheen (KHR_materials_sheen, albedo scaling with both terms):
//!   f = sheenColor·f_sheen + f_base·min(1 − max3(sheenColor)·E(μv), 1 − max3(sheenColor)·E(μl));
//! - fuzz (KHR_materials_fuzz): fuzzColor·w·f_fuzz + f_base·(1 − w·R(μv)), the attenuation a
//!   function of the view alone as the draft writes it.
//!
//! Every attenuation goes through `shading::layering` (clamped into [0, 1]). In the furnace (a
//! uniform white environment of radiance 1) the lobe gives colour·E (or colour·w·R) and a base
//! of albedo ρ gives ρ·2∫₀¹ a(μv, μl)·μl dμl, integrated over μl = t² by the midpoint rule on
//! [`LIGHT_STEPS`] steps in t. Under the directional light (irradiance [`SUN_IRRADIANCE`] from
//! [`SUN_DIRECTION`], plus the furnace scaled by [`AMBIENT`]) the lobe is the Charlie sheen
//! D·V·NdotL (`shading::charlie`) or the fuzz model's single plus multiple scattering
//! (`shading::fuzz`), and the base ρ/π·NdotL times the attenuation at (μv, μl).

use crate::shading::charlie::{sheen_brdf_cos, Visibility};
use crate::shading::fuzz::{
    catmull_rom, multiple_scattering_cos, single_scattering_cos, ReflectanceMethod,
};
use crate::shading::layering::{fuzz_base_attenuation, max3, sheen_base_attenuation};
use crate::shading::{fuzz_reflectance, sheen_albedo, AlbedoMethod};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::f64::consts::PI;

/// View cosines sampled per look: μ_i = (i / (CURVE_NODES − 1))².
pub const CURVE_NODES: usize = 65;
/// Midpoint steps of the light-cosine integral of the sheen's base furnace factor.
pub const LIGHT_STEPS: usize = 2048;
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

/// A material as one sphere shows it: a Lambertian base of albedo `base` (linear) and a layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    pub base: [f64; 3],
    pub layer: Layer,
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
    /// The layer's directional reflectance at the curve nodes (E or R; 0 without a layer).
    reflectance: Vec<f64>,
    /// The base's furnace factor at the curve nodes (1 without a layer).
    base_furnace: Vec<f64>,
}

fn node_mu(i: usize) -> f64 {
    let t = i as f64 / (CURVE_NODES - 1) as f64;
    t * t
}

fn clamp01(x: f64) -> f64 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, 1.0)
    }
}

impl Shaded {
    /// Samples the look's curves (in parallel over the nodes; each node is computed alone, so
    /// the values do not depend on the thread count).
    pub fn new(look: Look) -> Shaded {
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
        let reflectance: Vec<f64> = match look.layer {
            Layer::None => vec![0.0; CURVE_NODES],
            Layer::Sheen { roughness, .. } => (0..CURVE_NODES)
                .into_par_iter()
                .map(|i| sheen_albedo(node_mu(i), roughness, AlbedoMethod::Quadrature))
                .collect(),
            Layer::Fuzz { roughness, .. } => (0..CURVE_NODES)
                .into_par_iter()
                .map(|i| fuzz_reflectance(node_mu(i), roughness, ReflectanceMethod::Quadrature))
                .collect(),
        };
        let mut shaded = Shaded {
            look,
            reflectance,
            base_furnace: Vec::new(),
        };
        shaded.base_furnace = match look.layer {
            Layer::None => vec![1.0; CURVE_NODES],
            Layer::Fuzz { .. } => (0..CURVE_NODES)
                .map(|i| shaded.attenuation_at(node_mu(i)))
                .collect(),
            Layer::Sheen { .. } => {
                // a(μl) at the midpoints t_k of [0, 1], μl = t_k², weight 4 t³ dt (∫ = 1).
                let steps: Vec<(f64, f64)> = (0..LIGHT_STEPS)
                    .map(|k| {
                        let t = (k as f64 + 0.5) / LIGHT_STEPS as f64;
                        (
                            shaded.attenuation_at(t * t),
                            4.0 * t * t * t / LIGHT_STEPS as f64,
                        )
                    })
                    .collect();
                (0..CURVE_NODES)
                    .map(|i| {
                        let av = shaded.attenuation_at(node_mu(i));
                        steps.iter().map(|&(al, w)| av.min(al) * w).sum()
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
        catmull_rom(CURVE_NODES, |k| self.reflectance[k], clamp01(mu).sqrt()).max(0.0)
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

    /// Radiance towards the viewer in the white furnace at view cosine μ.
    pub fn furnace(&self, mu: f64) -> [f64; 3] {
        let base_factor = if matches!(self.look.layer, Layer::None) {
            1.0
        } else {
            catmull_rom(CURVE_NODES, |k| self.base_furnace[k], clamp01(mu).sqrt())
        };
        let lobe = self.reflectance_at(mu);
        let c = self.lobe_color();
        std::array::from_fn(|k| c[k] * lobe + self.look.base[k] * base_factor)
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
        let (lobe, attenuation) = match self.look.layer {
            Layer::None => (0.0, 1.0),
            Layer::Sheen { roughness, .. } => {
                let h = normalize([l[0], l[1], l[2] + 1.0]);
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
        let c = self.lobe_color();
        std::array::from_fn(|k| {
            ambient[k]
                + SUN_IRRADIANCE * (c[k] * lobe + self.look.base[k] / PI * mu_l * attenuation)
        })
    }
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

/// A sphere image: linear radiance and coverage per pixel, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub size: usize,
    pub radiance: Vec<[f64; 3]>,
    pub coverage: Vec<f64>,
}

/// Renders `shaded` as a sphere of `size`×`size` pixels under `light`. Pixels whose centre lies
/// off the sphere but which it partly covers are shaded at the nearest point of the sphere
/// just inside the silhouette.
pub fn render_sphere(shaded: &Shaded, light: Light, size: usize) -> Sphere {
    let mut radiance = Vec::with_capacity(size * size);
    let mut cov = Vec::with_capacity(size * size);
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
            radiance.push(if c > 0.0 {
                shaded.radiance(n, light)
            } else {
                [0.0; 3]
            });
            cov.push(c);
        }
    }
    Sphere {
        size,
        radiance,
        coverage: cov,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_layer_is_the_base_in_the_furnace_and_lambert_under_the_light() {
        let s = Shaded::new(Look {
            base: [0.2, 0.5, 0.8],
            layer: Layer::None,
        });
        for mu in [0.0, 0.3, 1.0] {
            assert_eq!(s.furnace(mu), [0.2, 0.5, 0.8]);
        }
        let n = SUN_DIRECTION;
        let got = s.radiance(n, Light::Directional);
        for (g, b) in got.iter().zip(s.look.base) {
            let want = AMBIENT * b + 0.8 * b;
            assert!((g - want).abs() < 1e-12);
        }
    }

    #[test]
    fn fuzz_furnace_is_the_draft_formula() {
        let look = Look {
            base: [0.5, 0.25, 0.1],
            layer: Layer::Fuzz {
                color: [1.0, 0.5, 0.0],
                weight: 0.8,
                roughness: 0.5,
            },
        };
        let s = Shaded::new(look);
        // At curve nodes (μ = 1/4, 9/16, 1) the values are the quadrature's; between them
        // (μ = 1/2) the interpolation is within 1e-4.
        for (mu, tol) in [(0.25, 1e-12), (0.5625, 1e-12), (1.0, 1e-12), (0.5, 1e-4)] {
            let r = fuzz_reflectance(mu, 0.5, ReflectanceMethod::Quadrature);
            let got = s.furnace(mu);
            for k in 0..3 {
                let c = [1.0, 0.5, 0.0][k];
                let want = c * 0.8 * r + look.base[k] * (1.0 - 0.8 * r);
                assert!((got[k] - want).abs() < tol, "μ={mu}: {got:?}");
            }
        }
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
