//! The bodies of velvet's file commands that run over many files on top of the engines:
//! `velvet bake` ([`bake`]), which plans and applies bakes with the bake engine and writes its
//! outputs through [`crate::output`]. The engines below (bake, edit, asset) know nothing of
//! commands, destinations or reports.

pub mod bake;
