//! `velvet migrate`: sheen → fuzz with the sheen kept as the fallback, a fallback sheen for
//! fuzz, and the upgrade of the pre-ratification sheen draft.
//!
//! The flow is one way. [`plan`] decides, per material, which conversion applies and turns it
//! into [`Edit`]s and [`Note`]s (plain values: a dry run prints them, tests compare them);
//! [`crate::output::paths`] decides where each output goes and which relative URIs or resources
//! must follow it; [`apply`] executes a file's plan and writes it atomically; the `velvet migrate`
//! command (`crate::command::migrate`) runs many files on the spine every file command shares. Each conversion rule is one file: [`sheen_to_fuzz`],
//! [`fallback`], [`legacy`]. The roughness choice between the layers lives in [`roughness`]
//! alone. Textures that a conversion must bake are planned in [`textures`] and made by the bake
//! engine, then applied to the part of the document they change ([`bake_part`]).

pub mod apply;
pub mod bake_part;
pub mod budget;
pub mod fallback;
pub mod legacy;
pub mod material;
pub mod measure;
pub mod note;
pub mod plan;
pub mod roughness;
pub mod sheen_to_fuzz;
pub mod textures;
pub mod verdict;

pub use note::{Conversion, Level, Note, Skip};
pub use plan::{plan_document, DocumentPlan, MaterialPlan};

pub use crate::edit::Edit;

/// How materials are converted. The defaults are the fast, factor-only conversions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Options {
    /// Regenerate the sheen of materials that have both fuzz and sheen from their fuzz.
    pub refresh_fallback: bool,
    /// Decode sheen colour textures to measure what fast mode changes (and only then).
    pub report: bool,
    /// Bake textures so that lobe and attenuation match texel by texel.
    pub exact: bool,
    /// .gltf: store baked textures as `data:` URIs instead of files next to the output.
    pub embed: bool,
    /// How roughness is carried between the layers (fitted by appearance, or copied).
    pub roughness: roughness::RoughnessMapping,
    /// Never bake a texture only to map roughness: copy it (identity) where a texture would
    /// need the bake, and say so.
    pub fast: bool,
    /// An output in another folder refers back to the input's resources (URIs rewritten)
    /// instead of getting its own copies (the default: a self-contained output).
    pub rewrite_uris: bool,
    /// How close a shared mapped roughness texture must come to the exact one.
    pub budget: budget::Budget,
    /// Leave out the perceptual verdict ([`verdict`]), which the spine otherwise measures for
    /// every material right after planning: `--fast` and `--roughness identity` do, to stay
    /// the speed paths, unless a view needs it (`--fail-on-visible`, `--preview`).
    pub skip_verdict: bool,
    /// How many bytes of new textures (uncompressed, per file) the default may add to bring
    /// "visible" materials closer ([`verdict::CloserBudget`]).
    pub closer_budget: verdict::CloserBudget,
    /// Limits and URI policy for reading inputs and their resources.
    pub load: crate::asset::LoadOptions,
}
