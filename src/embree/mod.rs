//! Safe layer over Embree, the ray tracing kernels that intersect the hair curves.
//!
//! [`sys`] is the raw bindgen output; [`Device`] owns an Embree device; [`SceneBuilder`]
//! attaches [`CurveGeometry`] and [`TriangleGeometry`] and commits into a [`Scene`], which
//! answers closest-hit and occlusion queries ([`Ray`], [`RayHit`], [`Exclude`]). This module
//! knows nothing of shading: it hands back hit records and leaves the rest to the renderer.
//!
//! Embree 3 (Debian) and Embree 4 differ in the ray query calls (`rtcIntersect1` and
//! `rtcOccluded1` arguments, intersect context versus arguments, default geometry mask).
//! Those differences live in `compat.rs` (under `cfg(embree3)` / `cfg(embree4)`, set by
//! `build.rs` from the installed header); every other file stays version-agnostic.

mod compat;
mod device;
mod geometry;
mod memory;
mod query;
mod scene;
pub mod sys;

pub use device::Device;
pub use geometry::{
    CurveBasis, CurveGeometry, CurvePoint, CurveShape, Geometry, SharedBuffer, TriangleGeometry,
    padding_for,
};
pub use memory::MemoryMonitor;
pub use query::{Exclude, Ray, RayHit};
pub use scene::{BuildQuality, Scene, SceneBuilder, SceneOptions};

/// The Embree version hairtrace was built against, as `major.minor.patch`, read from the
/// installed `rtcore_config.h` at build time.
pub fn version() -> &'static str {
    env!("HT_EMBREE_VERSION")
}
