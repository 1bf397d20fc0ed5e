//! hairtrace: physically based hair and fur rendering.
//!
//! The crate is layered one way only (see DESIGN.md): [`math`] and [`bsdf`] know nothing of
//! ray tracing; [`embree`] wraps Embree and knows nothing of shading; [`image`] writes
//! pictures through OpenImageIO; [`capi`] is a thin C shell over the same Rust API.

/// cbindgen:ignore
pub mod bsdf;
pub mod capi;
pub mod description;
/// cbindgen:ignore
pub mod embree;
mod error;
/// cbindgen:ignore
pub mod image;
/// cbindgen:ignore
pub mod math;
/// cbindgen:ignore
pub mod render;
/// cbindgen:ignore
pub mod scene;

pub use bsdf::{HairBsdf, HairEval, HairParams, HairPoint, HairSample};
pub use error::{Error, Result};

/// The crate version, as the C ABI reports it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
