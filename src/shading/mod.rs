//! Sheen and fuzz shading maths (f64): the Charlie sheen BRDF of KHR_materials_sheen
//! ([`charlie`]), its directional albedo E(μ, r) by three methods behind one function
//! ([`sheen_albedo`]: quadrature in [`albedo`], tables in [`table`], a closed-form fit in [`fit`]),
//! the layering of sheen and fuzz over a base ([`layering`]). The speed-against-error reports
//! of these methods are developer tooling, in `crate::bench` behind the `bench` feature.

pub mod albedo;
mod albedo_table32;
pub mod charlie;
pub mod fit;
pub mod fuzz;
mod fuzz_table;
pub mod layering;
pub mod mapping;
mod mapping_table;
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

/// The source text of a generated n×n table file (`fuzz_table.rs`, `albedo_table32.rs`): the
/// module comment `doc` (whole `//!` lines), `SIZE`, and `VALUES` row by row under the comment
/// `values_doc`, each value written so that it reads back to the same f64.
#[cfg(test)]
pub(crate) fn square_table_source(
    doc: &str,
    size: usize,
    values_doc: &str,
    values: &[f64],
) -> String {
    let mut out = format!(
        "{doc}\n/// Nodes per axis.\npub const SIZE: usize = {size};\n\n/// {values_doc}\n\
         #[rustfmt::skip]\npub static VALUES: [f64; SIZE * SIZE] = [\n"
    );
    for row in values.chunks(size) {
        let line: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
        out.push_str(&format!("    {},\n", line.join(", ")));
    }
    out.push_str("];\n");
    out
}
