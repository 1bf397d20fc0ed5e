//! Safe layer over Embree, the ray tracing kernels that intersect the hair curves.
//!
//! [`sys`](crate::embree::sys) is the raw bindgen output;
//! [`Device`](crate::embree::Device) owns an Embree device;
//! [`SceneBuilder`](crate::embree::SceneBuilder) attaches
//! [`CurveGeometry`](crate::embree::CurveGeometry) and
//! [`TriangleGeometry`](crate::embree::TriangleGeometry) and commits into a
//! [`Scene`](crate::embree::Scene), which answers closest-hit and occlusion queries
//! ([`Ray`](crate::embree::Ray), [`RayHit`](crate::embree::RayHit),
//! [`Exclude`](crate::embree::Exclude)). This module
//! knows nothing of shading: it hands back hit records and leaves the rest to the renderer.
//!
//! Embree 3 (Debian) and Embree 4 differ in the ray query calls (`rtcIntersect1` and
//! `rtcOccluded1` arguments, intersect context versus arguments, default geometry mask).
//! Those differences live in `compat.rs` (under `cfg(embree3)` / `cfg(embree4)`, set by
//! `build.rs` from the installed header); every other file stays version-agnostic.

mod abi_check;
mod compat;
mod device;
mod geometry;
mod isa;
mod memory;
mod query;
mod scene;
pub mod sys;

pub use device::Device;
pub use geometry::{
    CurveBasis, CurveGeometry, CurvePoint, CurveShape, Geometry, SharedBuffer, TriangleGeometry,
    padding_for,
};
pub use isa::Isa;
pub use memory::MemoryMonitor;
pub use query::{Exclude, Ray, RayHit};
pub use scene::{BuildMonitor, Scene, SceneBuilder, SceneOptions, cancelled, is_cancelled};

/// The Embree version hairtrace was built against, as `major.minor.patch`, read from the
/// installed `rtcore_config.h` at build time.
pub fn version() -> &'static str {
    env!("HT_EMBREE_VERSION")
}
