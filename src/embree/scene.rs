//! Embree scenes: a builder that attaches geometries, and the committed, immutable scene
//! that render threads query concurrently.
//!
//! The split is the type-level form of Embree's rule that a scene may only be queried after
//! `rtcCommitScene` and must not change while queries run: [`SceneBuilder::commit`] consumes
//! the builder and returns a [`Scene`] that is `Sync` and has no mutating methods.

use std::ptr::NonNull;
use std::sync::Arc;

use super::compat::FILTER_SCENE_FLAG;
use super::geometry::Geometry;
use super::{Device, sys};
use crate::error::invalid_arg;
use crate::{Error, Result};

/// How a scene is built. Embree's build quality stays at its default (binned SAH): Low,
/// High and `RTC_SCENE_FLAG_ROBUST` measured within 3% of it on fur grooms, so they are
/// not offered (neither do Embree's `hair_accel` layouts beat its own choice: see
/// docs/large-grooms.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneOptions {
    /// `RTC_SCENE_FLAG_COMPACT`: a BVH whose curve leaves index into the vertex buffers
    /// instead of copying the control points (Curve8i leaves, about 28 against 92 bytes per
    /// segment). Default on.
    pub compact: bool,
}

/// Compact by default: on the bench scalp it builds with 20% less CPU time and 43% less
/// peak memory (docs/large-grooms.md); it is what lets 10^7 strands fit on a 24 GiB
/// machine.
pub const DEFAULT_COMPACT: bool = true;

impl Default for SceneOptions {
    fn default() -> Self {
        SceneOptions {
            compact: DEFAULT_COMPACT,
        }
    }
}

/// One reference to an Embree scene, released when dropped.
#[derive(Debug)]
struct RawScene(NonNull<sys::RTCSceneTy>);

// SAFETY: Embree scenes may be used from any thread; mutation happens only through
// `SceneBuilder` (owned, not shared), queries only on a committed `Scene`, which Embree
// allows from many threads at once.
unsafe impl Send for RawScene {}
// SAFETY: as above.
unsafe impl Sync for RawScene {}

impl Drop for RawScene {
    fn drop(&mut self) {
        // SAFETY: we own one reference.
        unsafe { sys::rtcReleaseScene(self.0.as_ptr()) };
    }
}

/// A scene being assembled. Geometries get consecutive ids from 0 in attach order.
#[derive(Debug)]
pub struct SceneBuilder {
    // Released before the geometries (field order), which are released before their buffers.
    raw: RawScene,
    geometries: Vec<Geometry>,
    device: Arc<Device>,
}

impl SceneBuilder {
    pub fn new(device: Arc<Device>, options: SceneOptions) -> Result<Self> {
        // SAFETY: live device.
        let raw = unsafe { sys::rtcNewScene(device.raw()) };
        let Some(raw) = NonNull::new(raw) else {
            return Err(device.check().err().unwrap_or_else(|| Error::Embree {
                code: sys::RTCError::RTC_ERROR_UNKNOWN.0,
                message: "rtcNewScene returned null".into(),
            }));
        };
        let raw = RawScene(raw);
        let mut flags = FILTER_SCENE_FLAG;
        if options.compact {
            flags |= sys::RTCSceneFlags::RTC_SCENE_FLAG_COMPACT;
        }
        // SAFETY: live scene, valid flags.
        unsafe { sys::rtcSetSceneFlags(raw.0.as_ptr(), flags) };
        device.check()?;
        Ok(SceneBuilder {
            raw,
            geometries: Vec::new(),
            device,
        })
    }

    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }

    /// Attaches a committed geometry and returns its id (the `geom_id` of its hits).
    pub fn attach(&mut self, geometry: impl Into<Geometry>) -> Result<u32> {
        let geometry = geometry.into();
        let id = u32::try_from(self.geometries.len())
            .ok()
            .filter(|&id| id != u32::MAX)
            .ok_or_else(|| invalid_arg!("too many geometries in one scene"))?;
        // SAFETY: live scene and geometry; the id is unused (ids are consecutive). The scene
        // retains the geometry, and we keep ours (and its buffers) until the scene is gone.
        unsafe { sys::rtcAttachGeometryByID(self.raw.0.as_ptr(), geometry.raw(), id) };
        self.device.check()?;
        self.geometries.push(geometry);
        Ok(id)
    }

    /// Builds the BVH (Embree's build uses the device's worker threads), telling `progress` how far the build has got (0 to 1). Embree may
    /// call it from several build threads at once and out of order; `false` cancels the
    /// build, which then fails with Embree's `RTC_ERROR_CANCELLED` (see [`is_cancelled`]).
    /// The monitor's signature is the same in Embree 3 and 4.
    pub(crate) fn commit(self, progress: &BuildMonitor<'_>) -> Result<Scene> {
        let scene = self.raw.0.as_ptr();
        self.device.count_build();
        let user = (&raw const progress).cast_mut().cast::<std::ffi::c_void>();
        // SAFETY: live scene; `user` points at `progress`, which outlives the commit, and
        // the monitor is removed before this function returns.
        unsafe {
            sys::rtcSetSceneProgressMonitorFunction(scene, Some(monitor), user);
            sys::rtcCommitScene(scene);
            sys::rtcSetSceneProgressMonitorFunction(scene, None, std::ptr::null_mut());
        }
        self.device.check()?;
        Ok(Scene {
            raw: self.raw,
            geometries: self.geometries,
            _device: self.device,
        })
    }
}

/// What a commit reports to (`SceneBuilder::commit`): the fraction built, `false` to cancel.
pub type BuildMonitor<'a> = dyn Fn(f64) -> bool + Sync + 'a;

/// Embree's progress callback: forwards to the [`BuildMonitor`] behind `user`. A panic in
/// it must not unwind into Embree, so it cancels the build instead.
unsafe extern "C" fn monitor(user: *mut std::ffi::c_void, fraction: f64) -> bool {
    // SAFETY: `commit` passes a pointer to a live `&BuildMonitor` for the commit.
    let progress = unsafe { *user.cast::<&BuildMonitor<'_>>() };
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| progress(fraction))).unwrap_or(false)
}

/// Whether `e` is the error of a build that its progress callback cancelled.
pub fn is_cancelled(e: &Error) -> bool {
    matches!(e, Error::Embree { code, .. } if *code == sys::RTCError::RTC_ERROR_CANCELLED.0)
}

/// The error a cancelled build stage reports, the same as Embree's own.
pub fn cancelled() -> Error {
    Error::Embree {
        code: sys::RTCError::RTC_ERROR_CANCELLED.0,
        message: "cancelled".into(),
    }
}

/// A committed scene: immutable, queried from any number of threads (see `query.rs`).
#[derive(Debug)]
pub struct Scene {
    raw: RawScene,
    geometries: Vec<Geometry>,
    /// Held so that the device outlives every scene made on it.
    _device: Arc<Device>,
}

impl Scene {
    /// The geometry with the id its attachment returned.
    pub fn geometry(&self, id: u32) -> Option<&Geometry> {
        self.geometries.get(id as usize)
    }

    pub fn geometries(&self) -> &[Geometry] {
        &self.geometries
    }

    /// Bytes of the buffers hairtrace holds for the geometries (not Embree's BVH).
    #[cfg(any(test, feature = "bench-internals"))]
    pub fn heap_bytes(&self) -> usize {
        self.geometries.iter().map(Geometry::heap_bytes).sum()
    }

    /// Axis-aligned bounds (lower, upper) of everything in the scene, radii included.
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut b = sys::RTCBounds::default();
        // SAFETY: committed scene, valid output (RTCBounds is 16-byte aligned by bindgen).
        unsafe { sys::rtcGetSceneBounds(self.raw.0.as_ptr(), &mut b) };
        (
            [b.lower_x, b.lower_y, b.lower_z],
            [b.upper_x, b.upper_y, b.upper_z],
        )
    }

    /// The raw handle. Valid while `self` lives; do not release or modify it.
    pub(crate) fn raw(&self) -> sys::RTCScene {
        self.raw.0.as_ptr()
    }

    /// The raw handle, for the groom benchmark's direct Embree calls only.
    #[cfg(feature = "bench-internals")]
    pub fn raw_handle(&self) -> sys::RTCScene {
        self.raw()
    }
}
