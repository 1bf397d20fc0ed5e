//! Embree geometries (curves and triangle meshes) over buffers that Embree reads in place.
//!
//! Every buffer is handed to Embree with `rtcSetSharedGeometryBuffer`, so Embree never keeps
//! a second copy. A [`SharedBuffer`] either owns its memory (converted data, written once by
//! us straight into the buffer Embree reads, or a `Vec` given away) or shares memory someone
//! else owns: an `Arc<[T]>` it keeps alive, or a host's array under the contract of
//! [`SharedBuffer::from_raw_parts`]. A host that already holds float4 xyzr control points
//! thus has none of them copied. The geometry holds its buffers, so they live exactly as
//! long as Embree may read them.

use std::ffi::c_void;
use std::ops::Range;
use std::ptr::NonNull;
use std::sync::{Arc, OnceLock};

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::order::{centroid, median_split};
use super::{Device, sys};
use crate::error::invalid_arg;
use crate::math::time_step;
pub use crate::math::{CurveBasis, CurveShape};
use crate::{Error, Result, threads};

fn curve_type(basis: CurveBasis, shape: CurveShape) -> sys::RTCGeometryType {
    use sys::RTCGeometryType as T;
    match (shape, basis) {
        (CurveShape::Round, CurveBasis::Linear) => T::RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE,
        (CurveShape::Round, CurveBasis::Bezier) => T::RTC_GEOMETRY_TYPE_ROUND_BEZIER_CURVE,
        (CurveShape::Round, CurveBasis::BSpline) => T::RTC_GEOMETRY_TYPE_ROUND_BSPLINE_CURVE,
        (CurveShape::Round, CurveBasis::CatmullRom) => T::RTC_GEOMETRY_TYPE_ROUND_CATMULL_ROM_CURVE,
        (CurveShape::Flat, CurveBasis::Linear) => T::RTC_GEOMETRY_TYPE_FLAT_LINEAR_CURVE,
        (CurveShape::Flat, CurveBasis::Bezier) => T::RTC_GEOMETRY_TYPE_FLAT_BEZIER_CURVE,
        (CurveShape::Flat, CurveBasis::BSpline) => T::RTC_GEOMETRY_TYPE_FLAT_BSPLINE_CURVE,
        (CurveShape::Flat, CurveBasis::CatmullRom) => T::RTC_GEOMETRY_TYPE_FLAT_CATMULL_ROM_CURVE,
    }
}

/// Bytes Embree reads from the start of the last element of a shared buffer: it loads
/// elements with 16-byte SSE instructions (its `checkPadding16` probes the 4 bytes at offset
/// 12 of the last element when a vertex buffer is set), so a 12-byte float3 needs 4 more
/// bytes after it, while an element of 16 bytes or more needs none.
const EMBREE_LOAD_BYTES: usize = 16;

/// A buffer Embree reads in place, padded at the end as Embree requires.
///
/// Owned buffers append padding elements that are real, initialised elements of the `Vec`
/// (zeros), so Embree never reads past memory Rust owns. A caller that reserves
/// `padding_for::<T>()` spare elements before handing its `Vec` over avoids the one
/// reallocation this may cost. Shared buffers (from an `Arc<[T]>`, or
/// [`Self::from_raw_parts`]) take no padding, so their elements must be at least 16 bytes
/// (float4) and 4-byte aligned, checked at compile time: Embree's widest read then stays
/// inside the last element. Cloning a shared buffer shares the same memory again.
#[derive(Debug, Clone)]
pub struct SharedBuffer<T> {
    storage: Storage<T>,
    len: usize,
}

#[derive(Debug, Clone)]
enum Storage<T> {
    /// `len` elements, then the padding.
    Owned(Vec<T>),
    /// Kept alive by the reference count; a slice behind an `Arc` never moves or changes.
    Arc(Arc<[T]>),
    /// An owned buffer, padding and all, moved behind an `Arc` so that clones share it
    /// ([`SharedBuffer::into_shared`]).
    Kept(Arc<Vec<T>>),
    /// Someone else's memory, valid under the contract of [`SharedBuffer::from_raw_parts`].
    Borrowed(NonNull<T>),
}

// SAFETY: owned and `Arc` storage are `Send` and `Sync` for such `T`; borrowed memory is
// only read, and `from_raw_parts`' contract keeps it valid and unmodified for as long as
// any clone of the buffer lives, whichever thread that is on.
unsafe impl<T: Send + Sync> Send for SharedBuffer<T> {}
// SAFETY: as above; nothing mutates a buffer through `&self`.
unsafe impl<T: Send + Sync> Sync for SharedBuffer<T> {}

/// Spare elements a [`SharedBuffer`] of `T` appends.
pub const fn padding_for<T>() -> usize {
    EMBREE_LOAD_BYTES.div_ceil(size_of::<T>())
}

impl<T: Copy + Default> SharedBuffer<T> {
    pub fn new(mut data: Vec<T>) -> Self {
        let len = data.len();
        // Exact: `resize` alone may double the capacity of a full `Vec`.
        data.reserve_exact(padding_for::<T>());
        data.resize(len + padding_for::<T>(), T::default());
        SharedBuffer {
            storage: Storage::Owned(data),
            len,
        }
    }
}

impl<T: Copy + Default> From<Vec<T>> for SharedBuffer<T> {
    fn from(data: Vec<T>) -> Self {
        SharedBuffer::new(data)
    }
}

/// Shares the slice, no copy: the buffer keeps one reference to it.
impl<T> From<Arc<[T]>> for SharedBuffer<T> {
    fn from(data: Arc<[T]>) -> Self {
        let () = SharedBuffer::<T>::SHAREABLE;
        SharedBuffer {
            len: data.len(),
            storage: Storage::Arc(data),
        }
    }
}

impl<T> SharedBuffer<T> {
    /// Evaluated (at compile time) by the constructors that share memory without padding:
    /// Embree requires 4-byte alignment and reads 16 bytes from the last element's start.
    const SHAREABLE: () = assert!(
        size_of::<T>() >= EMBREE_LOAD_BYTES && align_of::<T>() >= 4,
        "memory shared with Embree without padding needs elements of >= 16 bytes, 4-aligned"
    );

    /// Shares `len` elements at `ptr`, owned by someone else (a C host): no copy, no padding.
    ///
    /// # Safety
    /// As for [`std::slice::from_raw_parts`]: `ptr` is aligned for `T` and points to `len`
    /// initialised elements, at most `isize::MAX` bytes. Those stay valid for reads and are
    /// neither modified nor freed until this buffer and every clone of it are dropped,
    /// with the geometries and scenes built from them. Embree needs no more: it requires
    /// 4-byte alignment and reads at most 16 bytes from the start of the last element, both
    /// guaranteed by the compile-time check on `T` (no padding past the `len` elements).
    pub unsafe fn from_raw_parts(ptr: NonNull<T>, len: usize) -> Self {
        let () = Self::SHAREABLE;
        SharedBuffer {
            storage: Storage::Borrowed(ptr),
            len,
        }
    }

    /// The elements, without the padding.
    pub(crate) fn as_slice(&self) -> &[T] {
        match &self.storage {
            Storage::Owned(data) => &data[..self.len],
            Storage::Kept(data) => &data[..self.len],
            Storage::Arc(data) => data,
            // SAFETY: the contract of `from_raw_parts`: aligned, `len` initialised elements,
            // unmodified while `self` lives.
            Storage::Borrowed(ptr) => unsafe { std::slice::from_raw_parts(ptr.as_ptr(), self.len) },
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the buffer's memory is hairtrace's own, shared by [`Self::into_shared`] or
    /// not (rather than an `Arc` a caller made, or a host's).
    pub fn is_ours(&self) -> bool {
        matches!(self.storage, Storage::Owned(_) | Storage::Kept(_))
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The same buffer, its clones sharing its elements rather than copying them: an
    /// owned one moved behind an `Arc` (no copy), a shared one as it is.
    pub fn into_shared(self) -> Self {
        let storage = match self.storage {
            Storage::Owned(data) => Storage::Kept(Arc::new(data)),
            shared => shared,
        };
        SharedBuffer {
            storage,
            len: self.len,
        }
    }

    /// Heap bytes this buffer allocated, padding and spare capacity included: for memory
    /// it keeps with others ([`Self::into_shared`]), its share, so that the holders' bytes
    /// add up to it; 0 for memory a caller shares (an `Arc` it made, a host's), which
    /// that caller accounts for.
    pub fn heap_bytes(&self) -> usize {
        match &self.storage {
            Storage::Owned(data) => data.capacity() * size_of::<T>(),
            Storage::Kept(data) => data.capacity() * size_of::<T>() / Arc::strong_count(data),
            Storage::Arc(_) | Storage::Borrowed(_) => 0,
        }
    }

    /// The address Embree reads: the shared memory itself when the buffer is shared.
    fn as_ptr(&self) -> *const T {
        self.as_slice().as_ptr()
    }
}

/// Equal elements (padding and storage aside).
impl<T: PartialEq> PartialEq for SharedBuffer<T> {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

/// One reference to an Embree geometry, released when dropped.
#[derive(Debug)]
pub(super) struct RawGeometry(NonNull<sys::RTCGeometryTy>);

// SAFETY: Embree geometries may be used from any thread; after commit hairtrace only reads
// them (rtcInterpolate), which Embree allows concurrently.
unsafe impl Send for RawGeometry {}
// SAFETY: as above.
unsafe impl Sync for RawGeometry {}

impl RawGeometry {
    pub(super) fn new(device: &Device, kind: sys::RTCGeometryType) -> Result<Self> {
        // SAFETY: live device; an unsupported type returns null and records an error.
        let raw = unsafe { sys::rtcNewGeometry(device.raw(), kind) };
        match NonNull::new(raw) {
            Some(raw) => Ok(RawGeometry(raw)),
            None => Err(device.check().err().unwrap_or_else(|| Error::Embree {
                code: sys::RTCError::RTC_ERROR_UNKNOWN.0,
                message: format!("rtcNewGeometry({kind:?}) returned null"),
            })),
        }
    }

    /// Binds `buffer` (elements of `stride` bytes) to `kind`, slot 0.
    ///
    /// # Safety
    /// `buffer` must outlive every use of this geometry by Embree; the caller stores it
    /// next to the handle, which is released first.
    unsafe fn share<T>(
        &self,
        kind: sys::RTCBufferType,
        format: sys::RTCFormat,
        buffer: &SharedBuffer<T>,
    ) {
        // SAFETY: the caller's contract; the whole buffer.
        unsafe { self.share_range(kind, format, buffer, 0, 0..buffer.len()) }
    }

    /// Binds each of `steps` (elements of `format`) as the vertices of its time step (its
    /// slot of the vertex buffer), after telling Embree how many there are.
    ///
    /// # Safety
    /// As for [`Self::share`], for every buffer; at most [`MAX_TIME_STEPS`] of them.
    unsafe fn share_steps<T>(&self, format: sys::RTCFormat, steps: &[SharedBuffer<T>]) {
        // SAFETY: live geometry, not yet committed; the count is checked by the caller.
        unsafe { sys::rtcSetGeometryTimeStepCount(self.0.as_ptr(), steps.len() as u32) };
        for (slot, step) in (0u32..).zip(steps) {
            // SAFETY: the caller's contract, for this buffer.
            unsafe {
                self.share_range(
                    sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
                    format,
                    step,
                    slot,
                    0..step.len(),
                )
            }
        }
    }

    /// Binds the elements `range` of `buffer` to `kind`, slot `slot`.
    ///
    /// # Safety
    /// As for [`Self::share`]; `range` lies inside the buffer.
    unsafe fn share_range<T>(
        &self,
        kind: sys::RTCBufferType,
        format: sys::RTCFormat,
        buffer: &SharedBuffer<T>,
        slot: u32,
        range: Range<usize>,
    ) {
        debug_assert!(range.start <= range.end && range.end <= buffer.len());
        // SAFETY: live geometry; offset and count describe initialised elements inside the
        // buffer, readable as Embree requires (padded, or of 16 bytes each, and an element
        // past the range is still inside the buffer or its padding), which the caller
        // keeps alive.
        unsafe {
            sys::rtcSetSharedGeometryBuffer(
                self.0.as_ptr(),
                kind,
                slot,
                format,
                buffer.as_ptr().cast::<c_void>(),
                range.start * size_of::<T>(),
                size_of::<T>(),
                range.len(),
            );
        }
    }

    /// Quads per segment of a flat cubic curve (Embree records an error for other kinds).
    fn set_ribbon_quads(&self, quads: u32) {
        // SAFETY: live geometry, not yet committed into a scene.
        unsafe { sys::rtcSetGeometryTessellationRate(self.0.as_ptr(), quads as f32) };
    }

    /// Sets the mask, commits the geometry and reports any error Embree recorded.
    pub(super) fn commit(&self, device: &Device, mask: u32) -> Result<()> {
        // SAFETY: live geometry whose buffers are set.
        unsafe {
            sys::rtcSetGeometryMask(self.0.as_ptr(), mask);
            sys::rtcCommitGeometry(self.0.as_ptr());
        }
        device.check()
    }

    pub(super) fn raw(&self) -> sys::RTCGeometry {
        self.0.as_ptr()
    }
}

impl Drop for RawGeometry {
    fn drop(&mut self) {
        // SAFETY: we own one reference; a scene that holds the geometry keeps its own.
        unsafe { sys::rtcReleaseGeometry(self.0.as_ptr()) };
    }
}

/// A curve interpolated at a parameter: position, radius and their derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Point on the axis.
    pub p: [f32; 3],
    pub radius: f32,
    /// First and second derivatives of the axis point with respect to the segment
    /// parameter u.
    pub dp_du: [f32; 3],
    pub d2p_du2: [f32; 3],
}

impl CurvePoint {
    /// The point a fraction `f` of the way from `self` to `other`.
    fn lerp(&self, other: &CurvePoint, f: f32) -> CurvePoint {
        let mix = |a: [f32; 3], b: [f32; 3]| std::array::from_fn(|i| a[i] + f * (b[i] - a[i]));
        CurvePoint {
            p: mix(self.p, other.p),
            radius: self.radius + f * (other.radius - self.radius),
            dp_du: mix(self.dp_du, other.dp_du),
            d2p_du2: mix(self.d2p_du2, other.d2p_du2),
        }
    }
}

/// The most time steps of one geometry (Embree's limit).
pub const MAX_TIME_STEPS: usize = sys::RTC_MAX_TIME_STEP_COUNT as usize;

/// Refuses time steps (each a buffer of `what`) Embree would not take: none, more than
/// [`MAX_TIME_STEPS`], or steps of other lengths than the first's.
fn check_steps<T>(steps: &[SharedBuffer<T>], what: &str) -> Result<()> {
    if !(1..=MAX_TIME_STEPS).contains(&steps.len()) {
        return Err(invalid_arg!(
            "{} time steps: Embree takes 1 to {MAX_TIME_STEPS}",
            steps.len()
        ));
    }
    match steps.iter().position(|s| s.len() != steps[0].len()) {
        Some(k) => Err(invalid_arg!(
            "time step {k} has {} {what}, time step 0 {}",
            steps[k].len(),
            steps[0].len()
        )),
        None => Ok(()),
    }
}

/// Element `i` of time steps `steps` (checked by [`check_steps`]) at `time` (a fraction of
/// the shutter), read by `read`: the blend of the two steps around it
/// (`math::time_steps`). `None` when `i` is out of range.
fn at_time<T>(
    steps: &[SharedBuffer<T>],
    i: usize,
    time: f32,
    read: impl Fn(&T) -> Vec4,
) -> Option<Vec4> {
    let (step, f) = time_step(time, steps.len());
    let a = read(steps[step].as_slice().get(i)?);
    if f == 0.0 {
        return Some(a);
    }
    let b = read(&steps[step + 1].as_slice()[i]);
    Some(a + f * (b - a))
}

/// Geometries of at least this many segments may be cut into parts of at most
/// [`PART_SEGMENTS`] ([`CurveGeometry::in_parts`]), which a scene builds as one small
/// Embree scene each, when a ray first reaches it (`lazy.rs`, [`Parts`]). On the bench
/// scalp at 10^6 strands x 16 segments a 1080p x 1 spp frame then takes 0.4x the time of
/// one geometry's, and rays 1.3x-1.6x longer (docs/large-grooms.md).
pub(crate) const PARTS_FROM_SEGMENTS: usize = 1 << 18;

/// The most segments of one part. Parts are built as rays reach them (`lazy.rs`): the
/// smaller they are, the fewer segments a render builds that its rays do not need, and
/// a part this small builds on one thread while another thread builds another. On the
/// bench scalp at 10^6 strands and 1080p x 1 spp, from 2^14 down to 2^10 segments the
/// frame took 0.45x the time (43% of the segments built instead of 80%) and rays traced
/// as fast; 2^9 traced slower (docs/large-grooms.md).
pub(crate) const PART_SEGMENTS: usize = 1 << 10;

/// A large curve geometry cut into compact parts by median splits of its segments'
/// centres ([`median_split`]). Embree's hair builder fetches every segment's control
/// points through the index buffer at each level of the tree it builds; over a whole
/// large groom those fetches miss the cache, within a part they hit it. The index buffer
/// Embree reads is in part order, each part a range of it; hits and the exclusion filter
/// translate back through `segments`, so no primitive id outside this module is
/// Embree's: strands stay contiguous runs of segments for the strand table, the
/// exclusion ranges and `rtcInterpolate` (on the geometry's own handle).
#[derive(Debug)]
struct Parts {
    /// Read by Embree only, through the parts' handles (`SceneBuilder`'s).
    indices: SharedBuffer<u32>,
    /// The segment, in the geometry's own order, at each position of the part order.
    segments: Box<[u32]>,
    ranges: Box<[Range<u32>]>,
    /// Each part's bounds ([`hull_bounds`]), in the order of `ranges`.
    bounds: Box<[Bounds]>,
}

/// Lower and upper corners of a box.
pub(super) type Bounds = ([f32; 3], [f32; 3]);

impl Parts {
    /// Parts of the segments `indices` over the control points of every time step in
    /// `steps`: cut by the first step's centres, each bounded over all of them.
    fn new(
        basis: CurveBasis,
        steps: &[SharedBuffer<[f32; 4]>],
        indices: &SharedBuffer<u32>,
    ) -> Result<Self> {
        let (points, first) = (steps[0].as_slice(), indices.as_slice());
        let span = basis.points_per_segment();
        let (segments, ranges) = median_split(first.len(), PART_SEGMENTS, |s| {
            let f = first[s] as usize;
            centroid(&points[f..f + span])
        })?;
        // Every control point is read for them: in parallel.
        let (ordered, bounds) = threads::scoped(0, || {
            let ordered: Vec<u32> = segments.par_iter().map(|&s| first[s as usize]).collect();
            let bounds = (ranges.par_iter())
                .map(|r| {
                    let firsts = &ordered[r.start as usize..r.end as usize];
                    (steps.iter())
                        .map(|step| hull_bounds(basis, step.as_slice(), firsts))
                        .reduce(|(lo, hi), (l, h)| {
                            (
                                std::array::from_fn(|i| lo[i].min(l[i])),
                                std::array::from_fn(|i| hi[i].max(h[i])),
                            )
                        })
                        .unwrap_or(([0.0; 3], [0.0; 3]))
                })
                .collect();
            (ordered, bounds)
        })?;
        Ok(Parts {
            indices: SharedBuffer::new(ordered),
            segments: segments.into_boxed_slice(),
            ranges: ranges.into_boxed_slice(),
            bounds,
        })
    }
}

/// Bounds that hold every surface point of the segments starting at `firsts`: what a
/// part's scene is entered by before it is built (`lazy.rs`). Each segment lies in the
/// convex hull of its Bezier control points (a B-spline's or a Catmull-Rom's converted:
/// much tighter than the hull of the points a B-spline segment reads, which spans three
/// segments), within its largest Bezier radius of that hull, round or flat; a margin of
/// 1e-5 of the coordinates covers Embree's rounding.
fn hull_bounds(basis: CurveBasis, points: &[[f32; 4]], firsts: &[u32]) -> Bounds {
    let span = basis.points_per_segment();
    let (mut lo, mut hi) = (Vec4::splat(f32::INFINITY), Vec4::splat(f32::NEG_INFINITY));
    let mut radius = 0.0f32;
    for (k, &first) in firsts.iter().enumerate() {
        if let Some(&ahead) = firsts.get(k + PREFETCH_AHEAD) {
            prefetch(&points[ahead as usize..]);
        }
        // A linear segment reads two points: the others stand in for what it does not read.
        let p = |i: usize| Vec4::from_array(points[first as usize + i.min(span - 1)]);
        let hull = basis.bezier_form::<Vec4, f32>([p(0), p(1), p(2), p(3)]);
        for h in hull {
            lo = lo.min(h);
            hi = hi.max(h);
            radius = radius.max(h.w.abs());
        }
    }
    let (lo, hi) = (lo.truncate(), hi.truncate());
    let margin = radius + 1e-5 * lo.abs().max(hi.abs()).max_element();
    ((lo - margin).to_array(), (hi + margin).to_array())
}

/// Segments ahead whose control points [`hull_bounds`] asks for before it reads them: a
/// part's segments lie apart in the points, so each read would otherwise wait on memory.
const PREFETCH_AHEAD: usize = 16;

/// Asks the CPU to bring the cache line that `points` starts with (a hint, no effect on
/// what is computed).
fn prefetch<T>(points: &[T]) {
    // SAFETY: SSE is in every x86-64 CPU, and a prefetch reads nothing and cannot fault.
    #[cfg(target_arch = "x86_64")]
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(points.as_ptr().cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = points;
}

/// Ray-facing quads per segment in which Embree intersects a flat cubic curve unless told
/// otherwise (`rtcSetGeometryTessellationRate`).
pub const DEFAULT_RIBBON_QUADS: u32 = 4;
/// The most quads per segment Embree cuts a flat cubic curve into: it clamps a higher rate.
pub const MAX_RIBBON_QUADS: u32 = 16;

/// Curves: one Embree curve geometry and the buffers it reads.
#[derive(Debug)]
pub struct CurveGeometry {
    // Field order matters: the handle is released before the buffers it reads are freed
    // (the parts' handles belong to the scene, released before its geometries).
    /// The segments in their own order: what `rtcInterpolate` reads, and what a scene
    /// attaches when the geometry has no parts.
    raw: RawGeometry,
    basis: CurveBasis,
    shape: CurveShape,
    mask: u32,
    /// Quads per segment of a flat cubic curve, its parts' too ([`Self::with_ribbon_quads`]).
    ribbon_quads: u32,
    /// The control points at each time step, spread evenly over the shutter: one for a
    /// geometry that does not move.
    steps: Box<[SharedBuffer<[f32; 4]>]>,
    indices: SharedBuffer<u32>,
    parts: Option<Arc<Parts>>,
}

/// The parts curves were cut into, with their bounds, kept with the curves for the next
/// geometry over them (a C scene's rebuild, `Curves::shared`). They are a pure function
/// of the points and the index buffer, which never change, and cutting and bounding them
/// again took 1.06 s of a 1.14 s rebuild at 10^6 strands (docs/large-grooms.md). Clones
/// share it; it is equal to any other, since it caches and does not describe.
#[derive(Debug, Clone, Default)]
pub struct PartsCache(Arc<OnceLock<Arc<Parts>>>);

impl PartialEq for PartsCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl CurveGeometry {
    /// A curve geometry that does not move: [`Self::in_motion`] of one time step.
    #[cfg(test)]
    pub fn new(
        device: &Device,
        basis: CurveBasis,
        shape: CurveShape,
        vertices: SharedBuffer<[f32; 4]>,
        indices: SharedBuffer<u32>,
        mask: u32,
    ) -> Result<Self> {
        Self::in_motion(device, basis, shape, vec![vertices], indices, mask)
    }

    /// Builds and commits a curve geometry. `steps` hold the (x, y, z, radius) control
    /// points at each of 1 to [`MAX_TIME_STEPS`] time steps spread evenly over the shutter
    /// (`math::time_steps`; one for curves that do not move), every step as many points,
    /// laid out alike; `indices` hold the first control point of each segment. Every
    /// segment must fit in the vertex buffer (checked: Embree itself would read out of
    /// bounds).
    pub fn in_motion(
        device: &Device,
        basis: CurveBasis,
        shape: CurveShape,
        steps: Vec<SharedBuffer<[f32; 4]>>,
        indices: SharedBuffer<u32>,
        mask: u32,
    ) -> Result<Self> {
        check_steps(&steps, "control points")?;
        let span = basis.points_per_segment() as u64;
        let count = steps[0].len() as u64;
        if let Some(i) = indices
            .as_slice()
            .iter()
            .position(|&first| u64::from(first) + span > count)
        {
            return Err(invalid_arg!(
                "curve segment {i} starts at control point {} but a {basis:?} segment reads \
                 {span} points and there are only {count}",
                indices.as_slice()[i]
            ));
        }
        if count > u64::from(u32::MAX) {
            return Err(invalid_arg!(
                "{count} control points: Embree indexes at most {}",
                u32::MAX
            ));
        }
        // Embree's aligned 16-byte loads crash on misaligned points (a Vec's come from malloc).
        if let Some(step) = steps
            .iter()
            .find(|s| s.as_ptr() as usize % EMBREE_LOAD_BYTES != 0)
        {
            let at = step.as_ptr();
            return Err(invalid_arg!("points at {at:?} are not aligned to 16 bytes"));
        }
        let raw = RawGeometry::new(device, curve_type(basis, shape))?;
        // SAFETY: the buffers move into the returned value next to `raw`, which is dropped
        // before them; the step count is checked above.
        unsafe {
            raw.share_steps(sys::RTCFormat::RTC_FORMAT_FLOAT4, &steps);
            raw.share(
                sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
                sys::RTCFormat::RTC_FORMAT_UINT,
                &indices,
            );
        }
        raw.commit(device, mask)?;
        Ok(CurveGeometry {
            raw,
            basis,
            shape,
            mask,
            ribbon_quads: DEFAULT_RIBBON_QUADS,
            steps: steps.into_boxed_slice(),
            indices,
            parts: None,
        })
    }

    /// The same flat cubic curves intersected as `quads` ray-facing quads per segment
    /// (1 to [`MAX_RIBBON_QUADS`]), where the default's chords would cut the curve's bends
    /// short by more than a view allows (`scene::ribbons`). Refused for other curves, which
    /// Embree does not cut into quads.
    pub fn with_ribbon_quads(mut self, device: &Device, quads: u32) -> Result<Self> {
        if self.shape != CurveShape::Flat || self.basis == CurveBasis::Linear {
            return Err(invalid_arg!(
                "{quads} quads per segment: only flat cubic curves are cut into quads, these \
                 are {:?} {:?}",
                self.shape,
                self.basis
            ));
        }
        if !(1..=MAX_RIBBON_QUADS).contains(&quads) {
            return Err(invalid_arg!(
                "{quads} quads per segment: Embree takes 1 to {MAX_RIBBON_QUADS}"
            ));
        }
        self.ribbon_quads = quads;
        self.raw.set_ribbon_quads(quads);
        self.raw.commit(device, self.mask)?;
        Ok(self)
    }

    /// The same geometry, cut into parts that a scene builds as scenes of their own when
    /// it has at least [`PARTS_FROM_SEGMENTS`] segments (else unchanged): the parts
    /// `cache` holds, or new ones it then keeps. `cache` is that of the curves this
    /// geometry reads (`Curves::into_parts`), or a new one.
    pub fn in_parts(mut self, cache: &PartsCache) -> Result<Self> {
        if self.indices.len() < PARTS_FROM_SEGMENTS {
            return Ok(self);
        }
        let cached = (cache.0.get()).filter(|p| p.segments.len() == self.indices.len());
        let parts = match cached {
            Some(parts) => parts.clone(),
            None => {
                let parts = Arc::new(Parts::new(self.basis, &self.steps, &self.indices)?);
                // Already set (another build got there first): as good as this one.
                let _ = cache.0.set(parts.clone());
                parts
            }
        };
        self.parts = Some(parts);
        Ok(self)
    }

    pub fn basis(&self) -> CurveBasis {
        self.basis
    }

    pub fn shape(&self) -> CurveShape {
        self.shape
    }

    /// The geometry mask its handles carry.
    pub(super) fn mask(&self) -> u32 {
        self.mask
    }

    /// Control points (x, y, z, radius), as Embree reads them: the first time step's.
    #[cfg(test)]
    pub fn vertices(&self) -> &[[f32; 4]] {
        self.steps[0].as_slice()
    }

    /// The control points at each time step, from the first.
    pub fn steps(&self) -> impl Iterator<Item = &[[f32; 4]]> {
        self.steps.iter().map(SharedBuffer::as_slice)
    }

    /// Control point `i` at `time` (a fraction of the shutter, `math::time_steps`): the
    /// blend of its two time steps around it. `None` when `i` is out of range.
    pub fn point_at(&self, i: usize, time: f32) -> Option<Vec4> {
        at_time(&self.steps, i, time, |p| Vec4::from_array(*p))
    }

    /// First control point of each segment (primitive).
    pub fn indices(&self) -> &[u32] {
        self.indices.as_slice()
    }

    /// Curve segments: Embree's primitives.
    pub fn segment_count(&self) -> usize {
        self.indices.len()
    }

    /// Bytes of the buffers hairtrace holds for this geometry (Embree's own memory is
    /// reported by [`super::MemoryMonitor`]).
    #[cfg(any(test, feature = "bench-internals"))]
    pub fn heap_bytes(&self) -> usize {
        let parts = self.parts.as_ref().map_or(0, |p| {
            p.indices.heap_bytes()
                + size_of_val(&*p.segments)
                + size_of_val(&*p.ranges)
                + size_of_val(&*p.bounds)
        });
        let steps: usize = self.steps.iter().map(SharedBuffer::heap_bytes).sum();
        steps + self.indices.heap_bytes() + parts
    }

    /// The parts a scene builds as scenes of their own ([`PARTS_FROM_SEGMENTS`]), as
    /// ranges of Embree's primitive order; `None` for a geometry built whole.
    pub(crate) fn parts(&self) -> Option<&[Range<u32>]> {
        self.parts.as_ref().map(|p| &*p.ranges)
    }

    /// The segment, in this geometry's order, that Embree calls `prim` in the part
    /// starting at `part_start`; `None` for an id Embree never returns.
    pub(super) fn own_segment(&self, part_start: u32, prim: u32) -> Option<u32> {
        let at = part_start.checked_add(prim)?;
        self.parts.as_ref()?.segments.get(at as usize).copied()
    }

    /// The bounds of each of [`Self::parts`], in their order (`Parts::new`).
    pub(super) fn part_bounds(&self) -> Option<&[Bounds]> {
        self.parts.as_ref().map(|p| &*p.bounds)
    }

    /// A committed handle on the segments of `part` (one of [`Self::parts`]): the same
    /// control points, that range of the part-ordered index buffer.
    ///
    /// # Safety
    /// The handle reads this geometry's buffers: it must be released before `self` is
    /// dropped.
    pub(super) unsafe fn part_geometry(
        &self,
        device: &Device,
        part: &Range<u32>,
    ) -> Result<RawGeometry> {
        let Some(parts) = &self.parts else {
            return Err(invalid_arg!("a curve geometry without parts"));
        };
        let range = part.start as usize..part.end as usize;
        if range.is_empty() || range.end > parts.segments.len() {
            return Err(invalid_arg!(
                "part {part:?} of {} segments",
                parts.segments.len()
            ));
        }
        let raw = RawGeometry::new(device, curve_type(self.basis, self.shape))?;
        // SAFETY: the buffers belong to `self`, which the caller keeps alive for as long as
        // the handle; the range lies inside the index buffer (checked).
        unsafe {
            raw.share_steps(sys::RTCFormat::RTC_FORMAT_FLOAT4, &self.steps);
            raw.share_range(
                sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
                sys::RTCFormat::RTC_FORMAT_UINT,
                &parts.indices,
                0,
                range,
            );
        }
        if self.ribbon_quads != DEFAULT_RIBBON_QUADS {
            raw.set_ribbon_quads(self.ribbon_quads);
        }
        raw.commit(device, self.mask)?;
        Ok(raw)
    }

    /// The curve of segment `prim` at parameter `u` in [0, 1] and at `time` (a fraction of
    /// the shutter): the blend of the curves at the two time steps around it
    /// (`math::time_steps`), each a lerp for linear curves and `rtcInterpolate` for cubic
    /// ones, so it is exactly the curve Embree intersects. `None` when `prim` is out of
    /// range.
    pub fn interpolate(&self, prim: u32, u: f32, time: f32) -> Option<CurvePoint> {
        let (step, f) = time_step(time, self.steps.len());
        let a = self.interpolate_step(prim, u, step)?;
        if f == 0.0 {
            return Some(a);
        }
        Some(a.lerp(&self.interpolate_step(prim, u, step + 1)?, f))
    }

    /// [`Self::interpolate`] at time step `step` (< the step count).
    fn interpolate_step(&self, prim: u32, u: f32, step: usize) -> Option<CurvePoint> {
        let &first = self.indices().get(prim as usize)?;
        if self.basis == CurveBasis::Linear {
            // A straight segment needs no call into Embree: its point and radius are a
            // lerp of the two control points (both inside the buffer: checked in `new`).
            let v = self.steps[step].as_slice();
            let (a, b) = (v[first as usize], v[first as usize + 1]);
            let u = u.clamp(0.0, 1.0);
            let lerp = |i: usize| a[i] + u * (b[i] - a[i]);
            return Some(CurvePoint {
                p: [lerp(0), lerp(1), lerp(2)],
                radius: lerp(3),
                dp_du: [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                d2p_du2: [0.0; 3],
            });
        }
        // rtcInterpolate writes with 16-byte stores: aligned, padded outputs.
        #[repr(C, align(16))]
        struct Out([f32; 4]);
        let mut p = Out([0.0; 4]);
        let mut dp = Out([0.0; 4]);
        let mut ddp = Out([0.0; 4]);
        let args = sys::RTCInterpolateArguments {
            geometry: self.raw.raw(),
            primID: prim,
            u: u.clamp(0.0, 1.0),
            v: 0.0,
            bufferType: sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
            bufferSlot: step as u32,
            P: p.0.as_mut_ptr(),
            dPdu: dp.0.as_mut_ptr(),
            ddPdudu: ddp.0.as_mut_ptr(),
            valueCount: 4,
            ..Default::default()
        };
        // SAFETY: committed geometry, primitive in range (checked above), outputs of four
        // floats aligned to 16 bytes (dPdv and the mixed derivatives stay null: a curve has
        // no v); the call does no error checks but reads only
        // the segment's control points, all inside the vertex buffer (checked in `new`).
        unsafe { sys::rtcInterpolate(&args) };
        let [x, y, z, r] = p.0;
        Some(CurvePoint {
            p: [x, y, z],
            radius: r,
            dp_du: [dp.0[0], dp.0[1], dp.0[2]],
            d2p_du2: [ddp.0[0], ddp.0[1], ddp.0[2]],
        })
    }

    /// The handle a scene attaches when the geometry has no parts.
    pub(super) fn raw(&self) -> sys::RTCGeometry {
        self.raw.raw()
    }
}

/// A triangle mesh: one Embree triangle geometry and the buffers it reads.
#[derive(Debug)]
pub struct TriangleGeometry {
    raw: RawGeometry,
    /// The vertices at each time step, spread evenly over the shutter: one for a mesh that
    /// does not deform.
    steps: Box<[SharedBuffer<[f32; 3]>]>,
    triangles: SharedBuffer<[u32; 3]>,
}

impl TriangleGeometry {
    /// Builds and commits a triangle geometry whose vertices at each of 1 to
    /// [`MAX_TIME_STEPS`] time steps spread evenly over the shutter (`math::time_steps`;
    /// one for a mesh that stays put) are `steps`, every step as many; every index must
    /// name a vertex (checked).
    pub fn in_motion(
        device: &Device,
        steps: Vec<SharedBuffer<[f32; 3]>>,
        triangles: SharedBuffer<[u32; 3]>,
        mask: u32,
    ) -> Result<Self> {
        check_steps(&steps, "vertices")?;
        let count = steps[0].len();
        if let Some(i) = triangles
            .as_slice()
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= count))
        {
            return Err(invalid_arg!(
                "triangle {i} = {:?} names a vertex beyond the {count} given",
                triangles.as_slice()[i]
            ));
        }
        let raw = RawGeometry::new(device, sys::RTCGeometryType::RTC_GEOMETRY_TYPE_TRIANGLE)?;
        // SAFETY: the buffers move into the returned value next to `raw`, dropped first;
        // the step count is checked above.
        unsafe {
            raw.share_steps(sys::RTCFormat::RTC_FORMAT_FLOAT3, &steps);
            raw.share(
                sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
                sys::RTCFormat::RTC_FORMAT_UINT3,
                &triangles,
            );
        }
        raw.commit(device, mask)?;
        Ok(TriangleGeometry {
            raw,
            steps: steps.into_boxed_slice(),
            triangles,
        })
    }

    /// Vertex `i` at `time` (a fraction of the shutter): the blend of its two time steps
    /// around it. `None` when `i` is out of range.
    pub fn vertex_at(&self, i: usize, time: f32) -> Option<Vec3> {
        at_time(&self.steps, i, time, |p| Vec3::from_array(*p).extend(0.0)).map(Vec4::truncate)
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        self.triangles.as_slice()
    }

    #[cfg(any(test, feature = "bench-internals"))]
    pub fn heap_bytes(&self) -> usize {
        let steps: usize = self.steps.iter().map(SharedBuffer::heap_bytes).sum();
        steps + self.triangles.heap_bytes()
    }

    pub(super) fn raw(&self) -> sys::RTCGeometry {
        self.raw.raw()
    }
}

/// A geometry of either kind, as a scene holds it.
#[derive(Debug)]
pub enum Geometry {
    Curves(CurveGeometry),
    Triangles(TriangleGeometry),
}

impl Geometry {
    pub(super) fn raw(&self) -> sys::RTCGeometry {
        match self {
            Geometry::Curves(c) => c.raw(),
            Geometry::Triangles(t) => t.raw(),
        }
    }

    #[cfg(any(test, feature = "bench-internals"))]
    pub fn heap_bytes(&self) -> usize {
        match self {
            Geometry::Curves(c) => c.heap_bytes(),
            Geometry::Triangles(t) => t.heap_bytes(),
        }
    }
}

impl From<CurveGeometry> for Geometry {
    fn from(c: CurveGeometry) -> Self {
        Geometry::Curves(c)
    }
}

impl From<TriangleGeometry> for Geometry {
    fn from(t: TriangleGeometry) -> Self {
        Geometry::Triangles(t)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Round curves of `basis` over `points` and `indices`, cut into parts.
    pub(crate) fn round_in_parts(
        device: &Device,
        basis: CurveBasis,
        points: Vec<[f32; 4]>,
        indices: Vec<u32>,
    ) -> CurveGeometry {
        CurveGeometry::new(
            device,
            basis,
            CurveShape::Round,
            points.into(),
            indices.into(),
            1,
        )
        .unwrap()
        .in_parts(&PartsCache::default())
        .unwrap()
    }

    #[test]
    fn shared_buffers_are_padded_with_zeros() {
        let b = SharedBuffer::new(vec![[1.0f32; 3]; 5]);
        assert_eq!(b.len(), 5);
        assert_eq!(b.as_slice(), &[[1.0; 3]; 5]);
        let Storage::Owned(data) = &b.storage else {
            panic!("a Vec is owned")
        };
        assert_eq!(data[5..], [[0.0; 3]; 2]);
        // A full Vec grows by the padding only.
        assert_eq!(b.heap_bytes(), (5 + 2) * 12);
        assert_eq!(padding_for::<[f32; 4]>(), 1);
        assert_eq!(padding_for::<u32>(), 4);
    }

    /// A buffer made shared keeps its memory, padding and all, and its clones read it.
    #[test]
    fn shared_buffers_keep_their_memory_for_their_clones() {
        let owned = SharedBuffer::new(vec![7u32; 5]);
        let at = owned.as_ptr();
        let shared = owned.into_shared();
        let clone = shared.clone();
        assert_eq!((shared.as_ptr(), clone.as_ptr()), (at, at));
        assert_eq!(clone.as_slice(), &[7; 5]);
        let Storage::Kept(data) = &clone.storage else {
            panic!("kept behind an Arc")
        };
        assert_eq!(data[5..], [0; 4]);
        assert!(clone.is_ours());
        assert_eq!(shared.heap_bytes() + clone.heap_bytes(), (5 + 4) * 4);
        drop(shared);
        assert_eq!(clone.heap_bytes(), (5 + 4) * 4);
        assert_eq!(clone.into_shared().as_ptr(), at);
    }

    /// The vertex buffer Embree holds for `c`.
    fn embree_vertices(c: &CurveGeometry) -> *const [f32; 4] {
        let vertex = sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX;
        // SAFETY: live geometry with a vertex buffer in slot 0.
        unsafe { sys::rtcGetGeometryBufferData(c.raw(), vertex, 0) }
            .cast_const()
            .cast()
    }

    #[test]
    fn shared_vertices_are_read_in_place() {
        let device = Device::new(Some(1)).unwrap();
        // The host's points start 16 bytes into its array.
        let host: Vec<[f32; 4]> = (0..5).map(|i| [i as f32 * 0.1, 0.0, 0.0, 0.1]).collect();
        let points = NonNull::from(&host[1..]).cast::<[f32; 4]>();
        let arc: Arc<[[f32; 4]]> = (0..4).map(|i| [i as f32, 0.0, 0.0, 0.1]).collect();
        // SAFETY: 4 points from `host[1]`, which outlives the geometry and is not modified.
        let borrowed = unsafe { SharedBuffer::from_raw_parts(points, 4) };
        for vertices in [borrowed, SharedBuffer::from(arc.clone())] {
            let ptr = vertices.as_ptr();
            assert_eq!(vertices.clone().as_ptr(), ptr, "clones share the memory");
            assert_eq!(vertices.heap_bytes(), 0);
            let indices = SharedBuffer::new(vec![0, 1, 2]);
            let ours = indices.heap_bytes();
            let (linear, round) = (CurveBasis::Linear, CurveShape::Round);
            let c = CurveGeometry::new(&device, linear, round, vertices, indices, 1).unwrap();
            assert_eq!(embree_vertices(&c), ptr);
            assert_eq!(c.heap_bytes(), ours);
            assert_eq!(c.interpolate(2, 1.0, 0.0).unwrap().p[0], c.vertices()[3][0]);
        }
        let floats = NonNull::from(&host[1..]).cast::<f32>();
        for offset in [1, 2, 3] {
            // SAFETY: 12 floats in `host[1..]`, which outlives the call; 4, 8 or 12 bytes off
            // a 16-byte boundary, refused before Embree's aligned loads.
            let points = unsafe { SharedBuffer::from_raw_parts(floats.add(offset).cast(), 3) };
            let (l, r, i) = (CurveBasis::Linear, CurveShape::Round, vec![0, 1]);
            let err = CurveGeometry::new(&device, l, r, points, i.into(), 1).unwrap_err();
            assert!(err.to_string().contains("not aligned to 16 bytes"), "{err}");
        }
    }

    /// Float4 control points need no padding: Embree builds (compact BVHs too, which read
    /// the vertex buffer while tracing), traces and interpolates every basis and shape with
    /// the last point right before an unreadable page.
    #[cfg(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ))]
    mod unpadded {
        use super::*;
        use crate::embree::{Ray, SceneBuilder, SceneOptions};
        use glam::Vec3;

        /// Memory whose last bytes are followed by an unreadable page: a read past them faults.
        struct Guarded {
            map: *mut c_void,
            bytes: usize,
            data: NonNull<[f32; 4]>,
        }

        unsafe extern "C" {
            fn mmap(
                addr: *mut c_void,
                len: usize,
                prot: i32,
                flags: i32,
                fd: i32,
                off: i64,
            ) -> *mut c_void;
            fn mprotect(addr: *mut c_void, len: usize, prot: i32) -> i32;
            fn munmap(addr: *mut c_void, len: usize) -> i32;
        }

        impl Guarded {
            /// A multiple of every page size these targets use.
            const GUARD: usize = 1 << 16;

            fn new(points: &[[f32; 4]]) -> Self {
                let size = size_of_val(points);
                let bytes = size.next_multiple_of(Self::GUARD) + Self::GUARD;
                let (read_write, private_anonymous) = (1 | 2, 0x02 | 0x20);
                // SAFETY: a fresh anonymous mapping; checked below.
                let map = unsafe {
                    mmap(
                        std::ptr::null_mut(),
                        bytes,
                        read_write,
                        private_anonymous,
                        -1,
                        0,
                    )
                };
                assert_ne!(map as isize, -1, "mmap failed");
                // SAFETY: the last GUARD bytes of our mapping (page aligned) become unreadable;
                // the points are copied to end exactly where they start.
                unsafe {
                    assert_eq!(mprotect(map.add(bytes - Self::GUARD), Self::GUARD, 0), 0);
                    let data = map.add(bytes - Self::GUARD - size).cast::<[f32; 4]>();
                    data.copy_from_nonoverlapping(points.as_ptr(), points.len());
                    Guarded {
                        map,
                        bytes,
                        data: NonNull::new_unchecked(data),
                    }
                }
            }
        }

        impl Drop for Guarded {
            fn drop(&mut self) {
                // SAFETY: our mapping, no longer read (the scenes are dropped first).
                unsafe { munmap(self.map, self.bytes) };
            }
        }

        #[test]
        fn unpadded_float4_points_are_read_within_bounds() {
            let device = Arc::new(Device::new(Some(2)).unwrap());
            let points: Vec<[f32; 4]> = (0..7).map(|i| [i as f32, 0.0, 0.0, 0.2]).collect();
            let guarded = Guarded::new(&points);
            // Both BVHs: the compact one's leaves read the points at each query, the
            // other's copy them at the build.
            let cases = CurveBasis::ALL
                .into_iter()
                .flat_map(|b| CurveShape::ALL.map(|s| (b, s)))
                .flat_map(|(b, s)| [(b, s, 0), (b, s, usize::MAX)]);
            for (basis, shape, compact_from_segments) in cases {
                let segments = basis.segments_for(points.len()).unwrap();
                let stride = basis.segment_stride() as u32;
                let indices = (0..segments as u32).map(|i| i * stride).collect();
                let options = SceneOptions {
                    compact_from_segments,
                    ..SceneOptions::default()
                };
                let mut scene = SceneBuilder::new(device.clone(), options).unwrap();
                // SAFETY: `guarded` outlives the scene and is not modified.
                let vertices = unsafe { SharedBuffer::from_raw_parts(guarded.data, points.len()) };
                let geometry = CurveGeometry::new(
                    &device,
                    basis,
                    shape,
                    vertices,
                    SharedBuffer::new(indices),
                    1,
                )
                .unwrap();
                let last = geometry.interpolate(segments as u32 - 1, 1.0, 0.0).unwrap();
                assert!(last.p.iter().all(|v| v.is_finite()), "{basis:?}");
                scene.attach(geometry).unwrap();
                let scene = scene.commit(&|_| true).unwrap();
                // SAFETY: a committed scene.
                let flags = unsafe { sys::rtcGetSceneFlags(scene.raw()) };
                let compact = sys::RTCSceneFlags::RTC_SCENE_FLAG_COMPACT;
                assert_eq!(flags.0 & compact.0 != 0, compact_from_segments == 0);
                // Rays across the whole strand, up to its tip: every segment is traced.
                let (lo, hi) = scene.bounds();
                let hits = (0..=32)
                    .map(|k| lo[0] + (hi[0] - lo[0]) * k as f32 / 32.0)
                    .filter(|&x| {
                        let ray = Ray::new(Vec3::new(x, 0.0, 5.0), -Vec3::Z);
                        scene.intersect(&ray, None).is_some()
                    })
                    .count();
                assert!(hits > 16, "{basis:?} {shape:?}: {hits} hits");
            }
        }
    }

    /// Parts a cache keeps serve the next geometry over the same curves (a C scene's
    /// rebuild) as they are, and are the parts that geometry would cut itself.
    #[test]
    fn a_cache_gives_the_next_geometry_the_same_parts() {
        let device = Device::new(Some(2)).unwrap();
        // Single-segment strands on a scrambled grid, PARTS_FROM_SEGMENTS of them.
        let n = PARTS_FROM_SEGMENTS as u32;
        let points: Vec<[f32; 4]> = (0..n)
            .flat_map(|s| {
                let cell = (s.wrapping_mul(40503) % n) as f32;
                [0.0, 1.0].map(|y| [cell % 512.0, y, (cell / 512.0).floor(), 0.01])
            })
            .collect();
        let indices: Vec<u32> = (0..n).map(|s| 2 * s).collect();
        let (points, indices) = (
            SharedBuffer::new(points).into_shared(),
            SharedBuffer::new(indices).into_shared(),
        );
        let cut = |cache: &PartsCache| {
            let (linear, round) = (CurveBasis::Linear, CurveShape::Round);
            CurveGeometry::new(&device, linear, round, points.clone(), indices.clone(), 1)
                .and_then(|g| g.in_parts(cache))
                .unwrap()
        };
        let cache = PartsCache::default();
        let (first, again) = (cut(&cache), cut(&cache.clone()));
        let parts = |g: &CurveGeometry| g.parts.clone().expect("in parts");
        assert!(Arc::ptr_eq(&parts(&first), &parts(&again)));
        let fresh = cut(&PartsCache::default());
        assert!(!Arc::ptr_eq(&parts(&fresh), &parts(&again)));
        assert_eq!(fresh.parts(), again.parts());
        assert_eq!(fresh.part_bounds(), again.part_bounds());
        assert_eq!(parts(&fresh).segments, parts(&again).segments);
        assert_eq!(parts(&fresh).indices, parts(&again).indices);
    }

    /// A geometry of `PARTS_FROM_SEGMENTS` segments or more is built in parts, each a
    /// scene of its own, yet every hit and every exclusion names segments in the
    /// geometry's own order: each hit lies on the segment it names, and excluding that
    /// segment lets the ray through to the strand behind.
    #[test]
    fn segments_built_in_parts_keep_their_own_numbers() {
        use crate::embree::{Exclude, Ray, SceneBuilder, SceneOptions};
        use glam::Vec3;
        let device = Arc::new(Device::new(Some(2)).unwrap());
        // 256 x 256 vertical strands 0.1 apart, numbered in a scrambled order, 4 segments
        // each.
        let (side, segments, radius) = (256u32, 4u32, 0.01f32);
        let strands = side * side;
        let foot = |s: u32| {
            let cell = (s * 40503) % strands;
            Vec3::new((cell % side) as f32 * 0.1, 0.0, (cell / side) as f32 * 0.1)
        };
        for basis in [CurveBasis::Linear, CurveBasis::CatmullRom] {
            let ends = u32::from(basis != CurveBasis::Linear);
            let per_strand = segments + 1 + 2 * ends;
            let mut points = Vec::new();
            for s in 0..strands {
                for k in 0..per_strand {
                    let y = (k.saturating_sub(ends).min(segments)) as f32 / segments as f32;
                    let p = foot(s) + Vec3::Y * y;
                    points.push([p.x, p.y, p.z, radius]);
                }
            }
            let indices: Vec<u32> = (0..strands)
                .flat_map(|s| (0..segments).map(move |j| s * per_strand + j))
                .collect();
            assert!(indices.len() >= PARTS_FROM_SEGMENTS);
            let geometry = round_in_parts(&device, basis, points, indices);
            let parts = geometry.parts().unwrap();
            assert_eq!(parts.len(), geometry.indices().len() / PART_SEGMENTS);
            assert!(parts.iter().all(|p| p.len() <= PART_SEGMENTS));
            let part_count = parts.len();
            let mut scene = SceneBuilder::new(device.clone(), SceneOptions::default()).unwrap();
            scene.attach(geometry).unwrap();
            let scene = scene.commit(&|_| true).unwrap();
            let Some(Geometry::Curves(geometry)) = scene.geometry(0) else {
                panic!("curves")
            };
            // No part is built before a ray reaches it.
            assert_eq!(scene.parts_built().built, 0, "{basis:?}");
            let mut checked = 0;
            for column in 0..side {
                for j in 0..segments {
                    let (x, y) = (column as f32 * 0.1, (j as f32 + 0.3) / segments as f32);
                    let ray = Ray::new(Vec3::new(x, y, -1.0), Vec3::Z);
                    let hit = scene.intersect(&ray, None).unwrap();
                    let on = geometry.interpolate(hit.prim_id, hit.u, 0.0).unwrap();
                    let at = ray.point_at(hit.t);
                    assert!((Vec3::from(on.p) - at).length() < 2.0 * radius, "{basis:?}");
                    let strand = hit.prim_id / segments;
                    assert_eq!((foot(strand).x, foot(strand).z), (x, 0.0), "{basis:?}");
                    assert_eq!(hit.prim_id % segments, j, "{basis:?}");
                    let exclude = Exclude {
                        geom_id: 0,
                        first_prim: hit.prim_id,
                        last_prim: hit.prim_id,
                        max_t: f32::INFINITY,
                    };
                    let behind = scene.intersect(&ray, Some(&exclude)).unwrap();
                    assert_eq!(foot(behind.prim_id / segments).z, 0.1, "{basis:?}");
                    checked += 1;
                }
            }
            assert_eq!(checked, side * segments);
            // The rays reached the first two rows of strands: the parts of the others
            // were never built.
            let built = scene.parts_built();
            assert!(built.built > 0 && built.built < part_count / 2, "{built:?}");
            assert!(scene.check_parts().is_ok());
        }
        // A smaller geometry is traced in its own order.
        let v = SharedBuffer::new(vec![[0.0, 0.0, 0.0, 0.1]; 2]);
        let (linear, round) = (CurveBasis::Linear, CurveShape::Round);
        let small = CurveGeometry::new(&device, linear, round, v, vec![0].into(), 1).unwrap();
        let small = small.in_parts(&PartsCache::default()).unwrap();
        assert!(small.parts().is_none());
    }

    /// Curves in motion are met where the ray's time puts them, whole and in parts (whose
    /// bounds must then hold every time step), and interpolated there: 512 x 512 vertical
    /// one-segment strands that move 3 along z over the shutter, far past where they start.
    #[test]
    fn curves_in_motion_are_met_where_the_rays_time_puts_them() {
        use crate::embree::{Ray, SceneBuilder, SceneOptions};
        use glam::Vec3;
        let device = Arc::new(Device::new(Some(2)).unwrap());
        let (side, radius, travel) = (512u32, 0.01f32, 3.0f32);
        for (basis, parts) in [
            (CurveBasis::Linear, false),
            (CurveBasis::Linear, true),
            (CurveBasis::CatmullRom, true),
            (CurveBasis::Bezier, false),
        ] {
            let span = basis.points_per_segment() as u32;
            let strand = |dz: f32| -> Vec<[f32; 4]> {
                (0..side * side)
                    .flat_map(|s| {
                        let (x, z) = ((s % side) as f32 * 0.1, (s / side) as f32 * 0.1 + dz);
                        (0..span).map(move |k| [x, k as f32 / (span - 1) as f32, z, radius])
                    })
                    .collect()
            };
            let steps = vec![strand(0.0).into(), strand(travel).into()];
            let indices: Vec<u32> = (0..side * side).map(|s| s * span).collect();
            let geometry = CurveGeometry::in_motion(
                &device,
                basis,
                CurveShape::Round,
                steps,
                indices.into(),
                1,
            )
            .unwrap();
            let geometry = match parts {
                true => geometry.in_parts(&PartsCache::default()).unwrap(),
                false => geometry,
            };
            assert_eq!(geometry.parts().is_some(), parts);
            let mut scene = SceneBuilder::new(device.clone(), SceneOptions::default()).unwrap();
            scene.attach(geometry).unwrap();
            let scene = scene.commit(&|_| true).unwrap();
            let Some(Geometry::Curves(geometry)) = scene.geometry(0) else {
                panic!("curves")
            };
            for time in [0.0, 0.25, 1.0] {
                for column in [0, 17, side - 1] {
                    let ray = Ray {
                        time,
                        ..Ray::new(Vec3::new(column as f32 * 0.1, 0.5, -1.0), Vec3::Z)
                    };
                    let hit = scene.intersect(&ray, None).unwrap();
                    let z = travel * time;
                    let at = ray.point_at(hit.t);
                    assert!((at.z - z).abs() < 2.0 * radius, "{basis:?} at {time}: {at}");
                    assert_eq!(hit.prim_id, column, "{basis:?} at {time}");
                    let on = geometry.interpolate(hit.prim_id, hit.u, time).unwrap();
                    assert!((Vec3::from(on.p) - at).length() < 2.0 * radius, "{basis:?}");
                    let p = geometry
                        .point_at(column as usize * span as usize, time)
                        .unwrap();
                    assert!((p.z - z).abs() < 1e-5, "{basis:?} at {time}: {p}");
                }
            }
        }
    }

    /// Time steps of other point counts, or none, or more than Embree takes, are refused.
    #[test]
    fn time_steps_must_match() {
        let device = Device::new(Some(1)).unwrap();
        let make = |steps: Vec<SharedBuffer<[f32; 4]>>| {
            let (linear, round) = (CurveBasis::Linear, CurveShape::Round);
            CurveGeometry::in_motion(&device, linear, round, steps, vec![0].into(), 1)
                .unwrap_err()
                .to_string()
        };
        let two = || SharedBuffer::new(vec![[0.0, 0.0, 0.0, 0.1]; 2]);
        let three = SharedBuffer::new(vec![[0.0, 0.0, 0.0, 0.1]; 3]);
        let e = make(vec![two(), three]);
        assert!(
            e.contains("time step 1 has 3 control points, time step 0 2"),
            "{e}"
        );
        assert!(make(Vec::new()).contains("0 time steps"));
        let e = make((0..=MAX_TIME_STEPS).map(|_| two()).collect());
        assert!(e.contains("time steps: Embree takes 1 to"), "{e}");
    }

    /// A part's bounds hold every point of its segments' surfaces, Catmull-Rom's bulges
    /// past their control points included: a ray is let into a part wherever it could
    /// hit it.
    #[test]
    fn part_bounds_hold_every_point_of_their_segments() {
        use glam::Vec3;
        let device = Device::new(Some(1)).unwrap();
        let radius = 0.01;
        for basis in CurveBasis::ALL {
            // Zigzag strands: x runs 0, 1, 1, 0, 0, 1, 1, ... along y, so a Catmull-Rom
            // segment between two points at x = 1 bulges past x = 1.
            let per_strand = 67;
            let segments = basis.segments_for(per_strand).unwrap();
            let strands = PARTS_FROM_SEGMENTS.div_ceil(segments);
            let points: Vec<[f32; 4]> = (0..strands * per_strand)
                .map(|i| {
                    let (s, k) = (i / per_strand, i % per_strand);
                    let x = if (k + 1) % 4 < 2 { 0.0 } else { 1.0 };
                    [x, k as f32 * 0.1, s as f32 * 0.05, radius]
                })
                .collect();
            let stride = basis.segment_stride();
            let indices: Vec<u32> = (0..strands)
                .flat_map(|s| (0..segments).map(move |j| (s * per_strand + j * stride) as u32))
                .collect();
            let geometry = round_in_parts(&device, basis, points, indices);
            let parts = geometry.parts.as_ref().unwrap();
            let mut widest = 0.0f32;
            let bounds = geometry.part_bounds().unwrap();
            for (range, &(lo, hi)) in geometry.parts().unwrap().iter().zip(bounds) {
                let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
                for at in range.clone().step_by(7) {
                    let segment = parts.segments[at as usize];
                    for k in 0..=16 {
                        let c = geometry.interpolate(segment, k as f32 / 16.0, 0.0).unwrap();
                        let (p, r) = (Vec3::from(c.p), Vec3::splat(c.radius));
                        assert!(
                            (p - r).cmpge(lo).all() && (p + r).cmple(hi).all(),
                            "{basis:?}"
                        );
                        widest = widest.max(c.p[0]);
                    }
                }
            }
            if basis == CurveBasis::CatmullRom {
                assert!(widest > 1.05, "no bulge to hold: {widest}");
            }
        }
    }

    #[test]
    fn out_of_range_indices_are_refused() {
        let device = Device::new(Some(1)).unwrap();
        let v = SharedBuffer::new(vec![[0.0, 0.0, 0.0, 0.1]; 4]);
        let i = SharedBuffer::new(vec![0, 1]);
        let err = CurveGeometry::new(&device, CurveBasis::BSpline, CurveShape::Round, v, i, 1)
            .unwrap_err();
        assert!(err.to_string().contains("segment 1"), "{err}");
        let v = SharedBuffer::new(vec![[0.0; 3]; 3]);
        let t = SharedBuffer::new(vec![[0, 1, 3]]);
        let err = TriangleGeometry::in_motion(&device, vec![v], t, 1).unwrap_err();
        assert!(err.to_string().contains("triangle 0"), "{err}");
    }

    #[test]
    fn interpolate_matches_the_control_points() {
        let device = Device::new(Some(1)).unwrap();
        let pts = vec![[0.0, 0.0, 0.0, 0.1], [2.0, 0.0, 0.0, 0.3]];
        let c = CurveGeometry::new(
            &device,
            CurveBasis::Linear,
            CurveShape::Round,
            SharedBuffer::new(pts),
            SharedBuffer::new(vec![0]),
            1,
        )
        .unwrap();
        let mid = c.interpolate(0, 0.5, 0.0).unwrap();
        assert_eq!(mid.p, [1.0, 0.0, 0.0]);
        assert!((mid.radius - 0.2).abs() < 1e-6);
        assert_eq!(mid.dp_du, [2.0, 0.0, 0.0]);
        assert_eq!(mid.d2p_du2, [0.0; 3]);
        assert!(c.interpolate(1, 0.5, 0.0).is_none());
    }
}
