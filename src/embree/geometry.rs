//! Embree geometries (curves and triangle meshes) over buffers that hairtrace owns.
//!
//! Every buffer is handed to Embree with `rtcSetSharedGeometryBuffer`, so Embree never keeps
//! a second copy: a host that already holds float4 xyzr control points gives its `Vec` away
//! and no vertex is copied at all; converted data (see `scene::curves`) is written once, by
//! us, straight into the buffer Embree reads. The geometry owns its buffers, so they live
//! exactly as long as Embree may read them.

use std::ffi::c_void;
use std::ptr::NonNull;

use super::{Device, sys};
use crate::error::invalid_arg;
use crate::{Error, Result};

/// How the control points of a curve segment are interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveBasis {
    /// Straight segments between consecutive points (cones in round mode).
    Linear,
    /// Cubic Bezier: segments of 4 points, consecutive segments share their end point.
    Bezier,
    /// Uniform cubic B-spline: each segment reads 4 consecutive points, overlapping by 3.
    BSpline,
    /// Catmull-Rom: each segment reads 4 consecutive points and runs from the 2nd to the 3rd.
    CatmullRom,
}

/// The surface Embree builds around a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveShape {
    /// A true tube (swept sphere): the reference for close-ups.
    Round,
    /// A ribbon that always faces the ray: faster, approximate when seen up close.
    Flat,
}

impl CurveBasis {
    pub const ALL: [CurveBasis; 4] = [
        CurveBasis::Linear,
        CurveBasis::Bezier,
        CurveBasis::BSpline,
        CurveBasis::CatmullRom,
    ];

    /// Control points one segment reads, starting at its index.
    pub fn points_per_segment(self) -> usize {
        match self {
            CurveBasis::Linear => 2,
            _ => 4,
        }
    }

    /// Index distance between consecutive segments of one strand.
    pub fn segment_stride(self) -> usize {
        match self {
            CurveBasis::Bezier => 3,
            _ => 1,
        }
    }

    /// Number of segments a strand of `points` control points has, or `None` when that
    /// count is not a valid strand in this basis.
    pub fn segments_for(self, points: usize) -> Option<usize> {
        let order = self.points_per_segment();
        if points < order {
            return None;
        }
        let spare = points - order;
        let stride = self.segment_stride();
        (spare % stride == 0).then_some(spare / stride + 1)
    }
}

impl CurveShape {
    pub const ALL: [CurveShape; 2] = [CurveShape::Round, CurveShape::Flat];
}

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

/// Bytes Embree may read past the last element of a shared buffer: it loads elements with
/// 16-byte SSE instructions, so a 12-byte float3 needs 4 more bytes after it. 16 spare bytes
/// cover every element size.
const PADDING_BYTES: usize = 16;

/// A buffer Embree reads in place, padded at the end as Embree requires.
///
/// The padding elements are real, initialised elements of the `Vec` (zeros), so Embree
/// never reads past memory Rust owns. A caller that reserves `padding_for::<T>()` spare
/// elements before handing its `Vec` over avoids the one reallocation this may cost.
#[derive(Debug, Clone, PartialEq)]
pub struct SharedBuffer<T> {
    data: Vec<T>,
    len: usize,
}

/// Spare elements a [`SharedBuffer`] of `T` appends.
pub const fn padding_for<T>() -> usize {
    PADDING_BYTES.div_ceil(size_of::<T>())
}

impl<T: Copy + Default> SharedBuffer<T> {
    pub fn new(mut data: Vec<T>) -> Self {
        let len = data.len();
        data.resize(len + padding_for::<T>(), T::default());
        SharedBuffer { data, len }
    }

    /// The elements, without the padding.
    pub fn as_slice(&self) -> &[T] {
        &self.data[..self.len]
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Heap bytes held, padding and spare capacity included.
    pub fn heap_bytes(&self) -> usize {
        self.data.capacity() * size_of::<T>()
    }

    fn as_ptr(&self) -> *const c_void {
        self.data.as_ptr().cast()
    }
}

/// One reference to an Embree geometry, released when dropped.
#[derive(Debug)]
struct RawGeometry(NonNull<sys::RTCGeometryTy>);

// SAFETY: Embree geometries may be used from any thread; after commit hairtrace only reads
// them (rtcInterpolate), which Embree allows concurrently.
unsafe impl Send for RawGeometry {}
// SAFETY: as above.
unsafe impl Sync for RawGeometry {}

impl RawGeometry {
    fn new(device: &Device, kind: sys::RTCGeometryType) -> Result<Self> {
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
    unsafe fn share<T: Copy + Default>(
        &self,
        kind: sys::RTCBufferType,
        format: sys::RTCFormat,
        buffer: &SharedBuffer<T>,
    ) {
        // SAFETY: live geometry; pointer and count describe initialised memory of
        // `len + padding` elements, which the caller keeps alive.
        unsafe {
            sys::rtcSetSharedGeometryBuffer(
                self.0.as_ptr(),
                kind,
                0,
                format,
                buffer.as_ptr(),
                0,
                size_of::<T>(),
                buffer.len(),
            );
        }
    }

    /// Sets the mask, commits the geometry and reports any error Embree recorded.
    fn commit(&self, device: &Device, mask: u32) -> Result<()> {
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

/// Curves: one Embree curve geometry and the buffers it reads.
#[derive(Debug)]
pub struct CurveGeometry {
    // Field order matters: the handle is released before the buffers it reads are freed.
    raw: RawGeometry,
    basis: CurveBasis,
    shape: CurveShape,
    vertices: SharedBuffer<[f32; 4]>,
    indices: SharedBuffer<u32>,
}

impl CurveGeometry {
    /// Builds and commits a curve geometry. `vertices` are (x, y, z, radius) control points,
    /// `indices` hold the first control point of each segment. Every segment must fit in the
    /// vertex buffer (checked: Embree itself would read out of bounds).
    pub fn new(
        device: &Device,
        basis: CurveBasis,
        shape: CurveShape,
        vertices: SharedBuffer<[f32; 4]>,
        indices: SharedBuffer<u32>,
        mask: u32,
    ) -> Result<Self> {
        let span = basis.points_per_segment() as u64;
        let count = vertices.len() as u64;
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
        let raw = RawGeometry::new(device, curve_type(basis, shape))?;
        // SAFETY: both buffers move into the returned value next to `raw`, which is dropped
        // before them.
        unsafe {
            raw.share(
                sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
                sys::RTCFormat::RTC_FORMAT_FLOAT4,
                &vertices,
            );
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
            vertices,
            indices,
        })
    }

    pub fn basis(&self) -> CurveBasis {
        self.basis
    }

    pub fn shape(&self) -> CurveShape {
        self.shape
    }

    /// Control points (x, y, z, radius), as Embree reads them.
    pub fn vertices(&self) -> &[[f32; 4]] {
        self.vertices.as_slice()
    }

    /// First control point of each segment (primitive).
    pub fn indices(&self) -> &[u32] {
        self.indices.as_slice()
    }

    pub fn segment_count(&self) -> usize {
        self.indices.len()
    }

    /// Bytes of the buffers hairtrace holds for this geometry (Embree's own memory is
    /// reported by [`super::MemoryMonitor`]).
    pub fn heap_bytes(&self) -> usize {
        self.vertices.heap_bytes() + self.indices.heap_bytes()
    }

    /// The curve of segment `prim` at parameter `u` in [0, 1], through `rtcInterpolate`, so
    /// it is exactly the curve Embree intersects. `None` when `prim` is out of range.
    pub fn interpolate(&self, prim: u32, u: f32) -> Option<CurvePoint> {
        if prim as usize >= self.indices.len() {
            return None;
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
            bufferSlot: 0,
            P: p.0.as_mut_ptr(),
            dPdu: dp.0.as_mut_ptr(),
            // A linear curve has no second derivative, and Embree 3.13 returns a zero first
            // derivative for linear curves when the second is requested too.
            ddPdudu: if self.basis == CurveBasis::Linear {
                std::ptr::null_mut()
            } else {
                ddp.0.as_mut_ptr()
            },
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

    pub(super) fn raw(&self) -> sys::RTCGeometry {
        self.raw.raw()
    }
}

/// A triangle mesh: one Embree triangle geometry and the buffers it reads.
#[derive(Debug)]
pub struct TriangleGeometry {
    raw: RawGeometry,
    vertices: SharedBuffer<[f32; 3]>,
    triangles: SharedBuffer<[u32; 3]>,
}

impl TriangleGeometry {
    /// Builds and commits a triangle geometry; every index must name a vertex (checked).
    pub fn new(
        device: &Device,
        vertices: SharedBuffer<[f32; 3]>,
        triangles: SharedBuffer<[u32; 3]>,
        mask: u32,
    ) -> Result<Self> {
        let count = vertices.len();
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
        // SAFETY: both buffers move into the returned value next to `raw`, dropped first.
        unsafe {
            raw.share(
                sys::RTCBufferType::RTC_BUFFER_TYPE_VERTEX,
                sys::RTCFormat::RTC_FORMAT_FLOAT3,
                &vertices,
            );
            raw.share(
                sys::RTCBufferType::RTC_BUFFER_TYPE_INDEX,
                sys::RTCFormat::RTC_FORMAT_UINT3,
                &triangles,
            );
        }
        raw.commit(device, mask)?;
        Ok(TriangleGeometry {
            raw,
            vertices,
            triangles,
        })
    }

    pub fn vertices(&self) -> &[[f32; 3]] {
        self.vertices.as_slice()
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        self.triangles.as_slice()
    }

    pub fn heap_bytes(&self) -> usize {
        self.vertices.heap_bytes() + self.triangles.heap_bytes()
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
mod tests {
    use super::*;

    #[test]
    fn segments_per_basis() {
        assert_eq!(CurveBasis::Linear.segments_for(5), Some(4));
        assert_eq!(CurveBasis::Linear.segments_for(1), None);
        assert_eq!(CurveBasis::BSpline.segments_for(6), Some(3));
        assert_eq!(CurveBasis::CatmullRom.segments_for(3), None);
        assert_eq!(CurveBasis::Bezier.segments_for(7), Some(2));
        assert_eq!(CurveBasis::Bezier.segments_for(6), None);
    }

    #[test]
    fn shared_buffers_are_padded_with_zeros() {
        let b = SharedBuffer::new(vec![[1.0f32; 3]; 5]);
        assert_eq!(b.len(), 5);
        assert_eq!(b.as_slice(), &[[1.0; 3]; 5]);
        assert_eq!(b.data.len(), 5 + 2);
        assert_eq!(b.data[5..], [[0.0; 3]; 2]);
        assert_eq!(padding_for::<[f32; 4]>(), 1);
        assert_eq!(padding_for::<u32>(), 4);
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
        let err = TriangleGeometry::new(&device, v, t, 1).unwrap_err();
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
        let mid = c.interpolate(0, 0.5).unwrap();
        assert_eq!(mid.p, [1.0, 0.0, 0.0]);
        assert!((mid.radius - 0.2).abs() < 1e-6);
        assert_eq!(mid.dp_du, [2.0, 0.0, 0.0]);
        assert_eq!(mid.d2p_du2, [0.0; 3]);
        assert!(c.interpolate(1, 0.5).is_none());
    }
}
