//! velvet: validate, migrate and bake glTF 2.0 assets that use KHR_materials_sheen and
//! KHR_materials_fuzz.

pub mod bake;
