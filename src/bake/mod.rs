//! Texture baking: recipes (what an output image holds), the pixel kernel (exact per channel and
//! transfer function, with lookup tables where they give the same result), image codecs, and the
//! engine that runs many recipes with one output per distinct recipe and one decode per source.
//!
//! The flow: callers (bake, migrate) plan [`Recipe`] values and insert them into a
//! [`RecipeSet`], which deduplicates them; [`bake`] fetches and decodes the images they read
//! through an [`ImageSource`], applies each recipe, and returns encoded outputs with statistics.
//! The recipe, kernel, codec and engine modules know nothing of glTF JSON; [`plan`], [`apply`]
//! and [`prune`] are their glTF side: plan (which slots need baking, with which recipes), apply
//! (new images and textures, factors, dropped sources). The `velvet bake` command over many
//! files is [`crate::command::bake`].

pub mod apply;
pub mod codec;
pub mod engine;
pub mod kernel;
pub mod pixels;
pub mod plan;
pub mod prune;
pub mod recipe;
pub mod srgb;

pub use codec::{CodecError, EncodeOptions, ImageFormat, OutputFormat, PngCompression};
pub use engine::{
    bake, bake_into, BakeError, BakeOptions, Baked, ImageSource, OutputId, RecipeSet, Sink,
    StoredFile,
};
pub use kernel::{ChannelStats, KernelOptions, KernelStats};
pub use pixels::{Depth, Layout, Pixels, Samples};
pub use recipe::{
    Channel, ChannelRecipe, Curve, Factor, ImageId, OutputLayout, Recipe, RecipeError, Texel,
    Transfer, Value,
};
