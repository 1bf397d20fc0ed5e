//! hairtrace: physically based hair and fur rendering.
//!
//! The crate is layered one way only (docs/architecture.md; `tests/pipeline/architecture.rs`
//! checks it): [`math`] and [`bsdf`] know nothing of ray tracing; [`embree`] wraps Embree
//! and knows nothing of shading; [`image`] reads and writes pictures through OpenImageIO;
//! [`scene`] is the scene as data plus the tracer; [`mod@render`] makes images of it;
//! [`description`] is a scene as plain data, and the demos; [`farm`] splits a frame into
//! tiles and assembles it;
//! [`formats`] reads and writes every file format (TOML and pbrt scenes, USD and `.hair`
//! grooms, OBJ and PLY meshes); [`incremental`] holds [`Scene`], the one scene every host
//! edits and renders; [`capi`] is a thin C shell over it. Conventions (frames, units, signs): docs/conventions.md.
//!
//! The items re-exported here are the API a Rust host builds on: the hair BSDF alone
//! ([`HairBsdf`], [`HairParams`], [`LocalBsdf`]), or a whole render from a scene file or
//! a description built in code:
//!
//! ```no_run
//! use std::sync::Arc;
//! use hairtrace::{Aovs, Device, NoProgress, Scene, SceneDescription, write_image};
//! # fn main() -> hairtrace::Result<()> {
//! let desc = SceneDescription::load("scene.toml".as_ref())?;
//! let mut scene = Scene::from_description(&desc, Arc::new(Device::new(None)?))?;
//! let out = scene.render(Aovs::default(), &NoProgress)?;
//! let (w, h) = (scene.settings.width as usize, scene.settings.height as usize);
//! write_image("out.exr".as_ref(), w, h, 3, out.film.rgb(), &Default::default())?;
//! # Ok(()) }
//! ```
//!
//! Without the default `render` feature the crate is the BSDF alone ([`bsdf`], [`math`] and
//! the BSDF's C entry points): it builds and links without Embree and OpenImageIO.
//!
//! The entry points, each with an example on its page:
//! - the BSDF alone: [`HairBsdf`] (a path vertex: `at`, then `eval` and `sample`);
//! - a scene from a file: [`SceneDescription::load`], then [`Scene::from_description`];
//! - a scene in code: [`Scene::new`], then grooms, meshes, materials and lights by name,
//!   or [`description::demo`] (a description to change first);
//! - settings by name, as the TOML file, the CLI and the C ABI set them:
//!   [`RenderSettings::set`];
//! - renders: [`Scene::render`], [`Scene::render_with`] (other settings); the scene keeps
//!   its build and builds again only where it must ([`Scene::build_for`]): an edit of a
//!   material, a light or the camera needs none;
//! - images: [`write_image`], [`read_image`].
//!
//! The tracer, the film's accumulators and the integrator are the crate's own; their tests
//! live beside them (`src/<layer>/tests/`). The `bench-internals` feature opens the tracer
//! and Embree's raw bindings to the groom benchmark alone: it is not an API.

// The BSDF-only build compiles the lower layers without the render code that uses some of
// their helpers; the default build (every feature) still reports code nothing uses.
#![cfg_attr(not(feature = "render"), allow(dead_code))]

/// cbindgen:ignore
pub mod bsdf;
pub mod capi;
#[cfg(feature = "render")]
pub mod description;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod embree;
mod error;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod farm;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod formats;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod image;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod incremental;
/// cbindgen:ignore
pub mod math;
mod quiet_panic;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod render;
/// cbindgen:ignore
#[cfg(feature = "render")]
pub mod scene;
#[cfg(feature = "render")]
mod threads;
/// cbindgen:ignore
mod validate;

pub use bsdf::{
    ACROSS, AcrossEval, BsdfEval, BsdfSample, HairBsdf, HairParams, HairPoint, HuangBsdf,
    HuangField, HuangParams, HuangPoint, Lobes, LocalBsdf,
};
#[cfg(feature = "render")]
pub use description::SceneDescription;
#[cfg(feature = "render")]
pub use embree::Device;
pub use error::{Error, Result};
/// The vector types of the BSDF's and the scene's signatures, so that a host uses the very
/// version the crate was built with.
pub use glam;
#[cfg(feature = "render")]
pub use image::{read_image, write_image};
#[cfg(feature = "render")]
pub use incremental::Scene;
#[cfg(feature = "render")]
pub use render::settings::RenderSettings;
#[cfg(feature = "render")]
pub use render::{Aovs, NoProgress, PixelFilter, Progress, RenderOutput};

/// The crate version, as the C ABI reports it.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
