//! hairtrace: physically based hair and fur rendering.
//!
//! The crate is layered one way only (docs/architecture.md; `tests/pipeline/architecture.rs`
//! checks it): [`math`] and [`bsdf`] know nothing of ray tracing; [`embree`] wraps Embree
//! and knows nothing of shading; [`image`] reads and writes pictures through OpenImageIO;
//! [`scene`] is the scene as data plus the tracer; [`render`] makes images of it;
//! [`description`] reads scene files and builds the demos; [`capi`] is a thin C shell
//! over the same Rust API. Conventions (frames, units, signs): docs/conventions.md.

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
mod validate;

pub use bsdf::{BsdfEval, BsdfSample, HairBsdf, HairParams, HairPoint, LocalBsdf};
pub use error::{Error, Result};

/// The crate version, as the C ABI reports it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
