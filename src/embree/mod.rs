//! Safe layer over Embree, the ray tracing kernels that intersect the hair curves.
//!
//! `sys` is the raw bindgen output, private to the crate (the `bench-internals` feature
//! makes it public for the groom benchmark's direct-Embree baseline; no host should use it);
//! [`Device`](crate::embree::Device) owns an Embree device; the crate's `SceneBuilder`
//! attaches curve and triangle geometries and commits into a `Scene`, which answers
//! closest-hit and occlusion queries (`Ray`, `RayHit`). The scene layer's tracer is the
//! only user of those; a host sees the device, the curve types and the ISA. This module
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
mod lazy;
mod memory;
mod order;
mod query;
mod raw_scene;
mod scene;
#[cfg(feature = "bench-internals")]
pub mod sys;
#[cfg(not(feature = "bench-internals"))]
mod sys;

pub use device::Device;
pub use geometry::{CurveBasis, CurveShape};
pub(crate) use geometry::{
    CurveGeometry, CurvePoint, DEFAULT_RIBBON_QUADS, MAX_RIBBON_QUADS, MAX_TIME_STEPS, PartsCache,
    TriangleGeometry, padding_for,
};
pub use isa::Isa;
pub use memory::MemoryMonitor;
pub(crate) use order::{centroid, morton_order};
pub(crate) use query::Exclude;
pub use scene::is_cancelled;
pub(crate) use scene::{SceneBuilder, cancelled};

// The groom bench (`benches/groom.rs`) traces through Embree directly beside the tracer; the
// `bench-internals` feature opens what it needs. No host should use them.
/// Control points a host shares with Embree rather than copies (`Scene::add_control_points`).
pub use geometry::SharedBuffer;
#[cfg(feature = "bench-internals")]
pub use scene::{PartsRule, Scene, SceneOptions};
#[cfg(not(feature = "bench-internals"))]
pub(crate) use scene::{PartsRule, Scene, SceneOptions};
#[cfg(feature = "bench-internals")]
pub use {geometry::Geometry, query::Ray, query::RayHit};
#[cfg(not(feature = "bench-internals"))]
pub(crate) use {geometry::Geometry, query::Ray, query::RayHit};

/// The Embree version hairtrace was built against, as `major.minor.patch`, read from the
/// installed `rtcore_config.h` at build time.
pub fn version() -> &'static str {
    env!("HT_EMBREE_VERSION")
}
