//! velvet: validate, migrate and bake glTF 2.0 assets that use KHR_materials_sheen and
//! KHR_materials_fuzz.
//!
//! The flow is one way: load ([`asset`]) → validate ([`validate`], [`rules`]) → report
//! ([`report`]), and [`fix`] repairs what it can of the findings; [`migrate`] and [`bake`]
//! plan and apply edits, and share [`output`] for where their outputs go; [`preview`] draws
//! contact sheets of what a migration does to each material. [`command`] runs each of them as
//! the command line does, on one spine; the binary in `main.rs` only parses arguments into its
//! requests and maps the status a command returns to the exit code.

pub mod asset;
pub mod bake;
#[cfg(feature = "bench")]
pub mod bench;
pub mod cli_docs;
pub mod command;
pub mod config;
pub mod diagnostics;
pub mod document;
pub mod edit;
pub mod fix;
pub mod layers;
pub mod migrate;
pub mod output;
pub mod preview;
pub mod progress;
pub mod report;
pub mod rules;
pub mod shading;
pub mod validate;
