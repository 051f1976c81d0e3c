//! Sheen and fuzz shading maths (f64): the Charlie sheen BRDF of KHR_materials_sheen
//! ([`charlie`]), its directional albedo E(μ, r) by three methods behind one function
//! ([`sheen_albedo`]: quadrature in [`albedo`], tables in [`table`], a closed-form fit in [`fit`]),
//! the layering of sheen and fuzz over a base ([`layering`]). With the `bench` feature, the
//! speed-against-error report (`accuracy`, drawn by `plot`, run by `velvet bench` through
//! `bench`): developer tooling, outside the default library and binary.

#[cfg(feature = "bench")]
pub mod accuracy;
pub mod albedo;
mod albedo_table32;
#[cfg(feature = "bench")]
pub mod bench;
pub mod charlie;
pub mod fit;
pub mod fuzz;
mod fuzz_table;
pub mod layering;
pub mod mapping;
mod mapping_table;
#[cfg(feature = "bench")]
pub mod plot;
pub mod quadrature;
pub mod table;

pub use albedo::AlbedoMethod;
pub use fuzz::{fuzz_reflectance, ReflectanceMethod};

/// E(μ, r) of the Charlie sheen BRDF: the fraction of light at view cosine μ that the sheen layer
/// reflects, for sheen roughness r. μ and r are clamped into [0, 1] and μ is floored at
/// [`charlie::MU_MIN`]. For small r at grazing μ the result exceeds 1 (see [`albedo`]).
pub fn sheen_albedo(mu: f64, r: f64, method: AlbedoMethod) -> f64 {
    match method {
        AlbedoMethod::Quadrature => {
            albedo::albedo_quadrature(mu, r, charlie::Visibility::Charlie, albedo::QUADRATURE_TOL)
                .value
        }
        AlbedoMethod::Lut16 => table::lut16().lookup(mu, r),
        AlbedoMethod::Lut32 => table::lut32().lookup(mu, r),
        AlbedoMethod::Fit => fit::albedo_fit(mu, r),
    }
}
