//! Embree scenes: a builder that attaches geometries, and the committed, immutable scene
//! that render threads query concurrently.
//!
//! The split is the type-level form of Embree's rule that a scene may only be queried after
//! `rtcCommitScene` and must not change while queries run: [`SceneBuilder::commit`] consumes
//! the builder and returns a [`Scene`] that is `Sync` and has no mutating methods.

use std::sync::Arc;

use super::compat::FILTER_SCENE_FLAG;
use super::geometry::Geometry;
use super::lazy::LazyPart;
use super::raw_scene::{RawScene, new_scene};
use super::{Device, sys};
use crate::error::invalid_arg;
use crate::{Error, Result};

/// How a scene is built. Embree's build quality stays at its default (binned SAH): Low,
/// High and `RTC_SCENE_FLAG_ROBUST` measured within 3% of it on fur grooms, so they are
/// not offered (neither do Embree's `hair_accel` layouts beat its own choice: see
/// docs/large-grooms.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SceneOptions {
    /// The fewest curve segments a BVH holds for it to be built with
    /// `RTC_SCENE_FLAG_COMPACT` ([`Self::compacts`]). Default [`COMPACT_FROM_SEGMENTS`].
    pub compact_from_segments: usize,
    /// When a curve geometry large enough for parts is built in them.
    pub parts: PartsRule,
}

/// When a curve geometry of at least `PARTS_FROM_SEGMENTS` segments is built in parts
/// (`CurveGeometry::in_parts`), which builds faster and traces a little slower.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartsRule {
    /// Every geometry whole.
    Never,
    /// Every such geometry in parts.
    Always,
    /// For a render of this many camera samples (pixels x spp of the whole frame): in
    /// parts when the geometry has at least [`AUTO_PARTS_FROM_SEGMENTS`] segments and more
    /// than [`PARTS_PER_SAMPLE`] segments per sample.
    ForSamples(u64),
}

/// The fewest curve segments for which a BVH is compact (`RTC_SCENE_FLAG_COMPACT`: BVH4OBB
/// with Curve8i leaves, which index the vertex buffers, against Embree's BVH8OBB with
/// Curve8v leaves, which copy the control points). Compact builds the 10^6-strand scalp
/// with 20% less CPU time and 43% less peak memory (what lets 10^7 strands fit on a 24
/// GiB machine), and traces 1.05x-1.14x slower (bench scenes, 2 threads, Xeon;
/// docs/large-grooms.md). From here the build's memory and time outweigh the rays'.
pub const COMPACT_FROM_SEGMENTS: usize = 1 << 20;

/// Segments per camera sample above which a large geometry is built in parts. On the
/// bench scalp at 10^6 strands parts save about 0.6 microseconds of build per segment and
/// cost about 0.2 of rendering per camera sample (2 threads, docs/large-grooms.md): they
/// pay while the render has fewer than about 3 samples per segment.
pub const PARTS_PER_SAMPLE: f64 = 1.0 / 3.0;

/// The fewest segments [`PartsRule::ForSamples`] builds in parts. Below about a million
/// segments one geometry builds fast enough (its build still fits the cache) that the
/// parts' slower rays and the part builds inside the render cost more than they save: on
/// the bench scalp at 4.8 x 10^5 segments and 32 spp the render took 1.3x as long in parts
/// and build plus render 1.02x-1.18x; at 1.05 x 10^6 segments build plus render took
/// 0.85x-0.89x (2 threads, docs/large-grooms.md).
pub const AUTO_PARTS_FROM_SEGMENTS: usize = 1 << 20;

/// Whole geometries: where the render is not known.
impl Default for SceneOptions {
    fn default() -> Self {
        SceneOptions {
            compact_from_segments: COMPACT_FROM_SEGMENTS,
            parts: PartsRule::Never,
        }
    }
}

impl SceneOptions {
    /// Whether a BVH over `segments` curve segments is compact.
    pub(crate) fn compacts(&self, segments: usize) -> bool {
        segments >= self.compact_from_segments
    }

    /// Embree's flags for a scene (a part's too) whose BVH holds `segments` curve segments.
    fn flags(&self, segments: usize) -> sys::RTCSceneFlags {
        let mut flags = FILTER_SCENE_FLAG;
        if self.compacts(segments) {
            flags |= sys::RTCSceneFlags::RTC_SCENE_FLAG_COMPACT;
        }
        flags
    }

    /// Whether a curve geometry of `segments` segments is built in parts.
    pub(crate) fn builds_in_parts(&self, segments: usize) -> bool {
        match self.parts {
            PartsRule::Never => false,
            PartsRule::Always => true,
            PartsRule::ForSamples(n) => {
                segments >= AUTO_PARTS_FROM_SEGMENTS
                    && segments as f64 > PARTS_PER_SAMPLE * n as f64
            }
        }
    }
}

/// What one geometry of Embree's top-level scene stands for: geometry `geometry` of the
/// scene, whole, or the part of it whose primitives start at `part_start`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Slot {
    pub(super) geometry: u32,
    pub(super) part_start: Option<u32>,
}

/// A scene being assembled. Geometries get consecutive ids from 0 in attach order.
#[derive(Debug)]
pub struct SceneBuilder {
    // Released before the parts and the geometries (field order), which are released
    // before their buffers.
    raw: RawScene,
    parts: Vec<LazyPart>,
    slots: Vec<Slot>,
    geometries: Vec<Geometry>,
    options: SceneOptions,
    device: Arc<Device>,
}

/// The id of the `n`-th geometry (from 0), refused where Embree's ids end (`u32::MAX`
/// means no geometry).
fn embree_id(n: usize) -> Result<u32> {
    u32::try_from(n)
        .ok()
        .filter(|&id| id != u32::MAX)
        .ok_or_else(|| invalid_arg!("too many geometries in one scene"))
}

/// Commits `scene`, telling `progress` how far its build has got.
fn commit_scene(device: &Device, scene: &RawScene, progress: &BuildMonitor<'_>) -> Result<()> {
    let scene = scene.raw();
    let user = (&raw const progress).cast_mut().cast::<std::ffi::c_void>();
    // SAFETY: live scene; `user` points at `progress`, which outlives the commit, and the
    // monitor is removed before this function returns.
    unsafe {
        sys::rtcSetSceneProgressMonitorFunction(scene, Some(monitor), user);
        sys::rtcCommitScene(scene);
        sys::rtcSetSceneProgressMonitorFunction(scene, None, std::ptr::null_mut());
    }
    device.check()
}

impl SceneBuilder {
    pub fn new(device: Arc<Device>, options: SceneOptions) -> Result<Self> {
        Ok(SceneBuilder {
            raw: new_scene(&device, options.flags(0))?,
            parts: Vec::new(),
            slots: Vec::new(),
            geometries: Vec::new(),
            options,
            device,
        })
    }

    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }

    pub fn options(&self) -> SceneOptions {
        self.options
    }

    /// Attaches a committed geometry and returns its id (the `geom_id` of its hits). A
    /// curve geometry with parts attaches a stand-in per part, whose scene of its own is
    /// built when a ray first reaches it (`lazy.rs`).
    pub fn attach(&mut self, geometry: impl Into<Geometry>) -> Result<u32> {
        let geometry = geometry.into();
        let id = embree_id(self.geometries.len())?;
        match &geometry {
            Geometry::Curves(c)
                if let (Some(parts), Some(bounds)) = (c.parts(), c.part_bounds()) =>
            {
                for (range, &bounds) in parts.iter().zip(bounds) {
                    // SAFETY: the part's handle is kept in `self.parts`, released before
                    // `self.geometries` (field order, here and in `Scene`).
                    let geometry = unsafe { c.part_geometry(&self.device, range) }?;
                    // A part is compact as its whole geometry would be.
                    let flags = self.options.flags(c.segment_count());
                    // SAFETY: as above: the part is released before the geometry.
                    let part =
                        unsafe { LazyPart::new(&self.device, geometry, bounds, flags, c.mask()) }?;
                    self.attach_raw(part.raw())?;
                    self.parts.push(part);
                    self.slots.push(Slot {
                        geometry: id,
                        part_start: Some(range.start),
                    });
                }
            }
            _ => {
                self.attach_raw(geometry.raw())?;
                self.slots.push(Slot {
                    geometry: id,
                    part_start: None,
                });
            }
        }
        self.geometries.push(geometry);
        Ok(id)
    }

    /// Attaches `raw` to the top-level scene under the next slot's id.
    fn attach_raw(&self, raw: sys::RTCGeometry) -> Result<()> {
        let slot = embree_id(self.slots.len())?;
        // SAFETY: live scene and geometry; the id is unused (slots are consecutive). The
        // scene retains the geometry, and we keep ours (and its buffers) until the scene is
        // gone.
        unsafe { sys::rtcAttachGeometryByID(self.raw.raw(), raw, slot) };
        self.device.check()
    }

    /// Builds the top level's BVH (Embree's build uses the device's worker threads),
    /// telling `progress` how far the build has got (0 to 1). Parts are built later, when
    /// a ray first reaches them. Embree may call `progress` from several build threads at
    /// once and out of order; `false` cancels the build, which then fails with Embree's
    /// `RTC_ERROR_CANCELLED` (see [`is_cancelled`]). The monitor's signature is the same in
    /// Embree 3 and 4.
    pub(crate) fn commit(self, progress: &BuildMonitor<'_>) -> Result<Scene> {
        self.device.count_build();
        // The top level's BVH holds the segments of the curves attached whole.
        let segments = self
            .slots
            .iter()
            .filter(|s| s.part_start.is_none())
            .filter_map(|s| match &self.geometries[s.geometry as usize] {
                Geometry::Curves(c) => Some(c.segment_count()),
                Geometry::Triangles(_) => None,
            })
            .sum();
        // SAFETY: live scene, not yet committed.
        unsafe { sys::rtcSetSceneFlags(self.raw.raw(), self.options.flags(segments)) };
        commit_scene(&self.device, &self.raw, progress)?;
        Ok(Scene {
            raw: self.raw,
            parts: self.parts,
            slots: self.slots,
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

/// Parts built so far ([`Scene::parts_built`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PartsBuilt {
    pub built: usize,
    pub seconds: f64,
}

/// A committed scene: immutable, queried from any number of threads (see `query.rs`).
#[derive(Debug)]
pub struct Scene {
    // Released before the parts and the geometries, as in `SceneBuilder`.
    raw: RawScene,
    parts: Vec<LazyPart>,
    slots: Vec<Slot>,
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

    /// The parts the geometries were cut into, each a scene of its own (`lazy.rs`).
    #[cfg(test)]
    pub(crate) fn part_count(&self) -> usize {
        self.parts.len()
    }

    /// The curve segments of every curve geometry: what its build cost scales with.
    pub(crate) fn curve_segments(&self) -> usize {
        self.geometries
            .iter()
            .map(|g| match g {
                Geometry::Curves(c) => c.segment_count(),
                Geometry::Triangles(_) => 0,
            })
            .sum()
    }

    /// How many parts have been built so far, and the seconds their builds took
    /// (summed over the threads that built them).
    pub(crate) fn parts_built(&self) -> PartsBuilt {
        let seconds: Vec<f64> = self
            .parts
            .iter()
            .filter_map(LazyPart::built_seconds)
            .collect();
        PartsBuilt {
            built: seconds.len(),
            seconds: seconds.iter().sum(),
        }
    }

    /// The error of a part whose build failed, through which rays then passed: a render
    /// that met one must fail with it.
    pub(crate) fn check_parts(&self) -> Result<()> {
        self.parts
            .iter()
            .find_map(LazyPart::error)
            .map_or(Ok(()), Err)
    }

    /// What Embree's top-level geometry `id` stands for.
    pub(super) fn slot(&self, id: u32) -> Option<Slot> {
        self.slots.get(id as usize).copied()
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
        unsafe { sys::rtcGetSceneBounds(self.raw.raw(), &mut b) };
        (
            [b.lower_x, b.lower_y, b.lower_z],
            [b.upper_x, b.upper_y, b.upper_z],
        )
    }

    /// The raw handle. Valid while `self` lives; do not release or modify it.
    pub(crate) fn raw(&self) -> sys::RTCScene {
        self.raw.raw()
    }

    /// The raw handle, for the groom benchmark's direct Embree calls only.
    #[cfg(feature = "bench-internals")]
    pub fn raw_handle(&self) -> sys::RTCScene {
        self.raw()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_geometry_is_built_in_parts_only_when_large_and_for_few_samples_per_segment() {
        let segments = AUTO_PARTS_FROM_SEGMENTS;
        let rule = |parts| SceneOptions {
            parts,
            ..SceneOptions::default()
        };
        let short = rule(PartsRule::ForSamples(segments as u64));
        let long = rule(PartsRule::ForSamples(4 * segments as u64));
        assert!(short.builds_in_parts(segments));
        assert!(!long.builds_in_parts(segments));
        assert!(rule(PartsRule::Always).builds_in_parts(segments));
        assert!(!rule(PartsRule::Never).builds_in_parts(segments));
        assert!(!SceneOptions::default().builds_in_parts(segments));
        // Below a million segments the rule keeps a geometry whole however few the samples.
        assert!(!rule(PartsRule::ForSamples(1)).builds_in_parts(segments - 1));
        assert!(rule(PartsRule::Always).builds_in_parts(segments - 1));
        assert!(!SceneOptions::default().compacts(COMPACT_FROM_SEGMENTS - 1));
        assert!(SceneOptions::default().compacts(COMPACT_FROM_SEGMENTS));
    }
}
