//! Geometry through the C ABI: curves from host arrays (copied, or float4 xyzr points
//! shared in place), `.hair` and USD files (as stills, or at a frame over the shutter of
//! the host's settings), and triangle meshes from arrays or files; curves and meshes at
//! several time steps move over the shutter.

use super::scene::{HtScene, add_with_id};
use super::settings::{HtSettings, read_settings};
use super::{Failure, HtStatus, host_slice, non_null_mut, read_host, read_path};
use crate::description::{GroomDesc, GroomSource, MeshDesc, MeshSource};
use crate::embree::{CurveBasis, MAX_TIME_STEPS, SharedBuffer};
use crate::error::{Result, invalid_arg};
use crate::formats::hair::Thickness;
use crate::incremental::ControlPoints;
use crate::render::settings::RenderSettings;
use crate::scene::{GroomShape, Mesh, Strands};
use std::ffi::c_char;
use std::ptr::NonNull;

impl HtScene {
    /// Adds the groom shaded by material `material_id` (hair); returns its first geometry
    /// id and how many it made.
    fn add_groom(&mut self, groom: GroomDesc, material_id: u32) -> Result<(u32, u32)> {
        let groom = GroomDesc {
            material: self.check_material(material_id, true)?,
            ..groom
        };
        let (name, first) = self.next_geometry();
        let count = self.scene.add_groom(&name, &groom)?;
        self.added(count)?;
        Ok((first, count as u32))
    }

    /// [`Self::add_groom`], an animated file's time steps read over the shutter of
    /// `settings` (None: closed): the scene reads them over its own settings', which a C
    /// scene otherwise never uses (its builds and renders take settings of their own).
    fn add_groom_over(
        &mut self,
        groom: GroomDesc,
        material_id: u32,
        settings: Option<RenderSettings>,
    ) -> Result<(u32, u32)> {
        let own = self.scene.settings;
        self.scene.settings = settings.unwrap_or_default();
        let added = self.add_groom(groom, material_id);
        self.scene.settings = own;
        added
    }

    /// Adds the mesh shaded by material `material_id` (diffuse); returns its geometry id.
    fn add_mesh(&mut self, source: MeshSource, material_id: u32) -> Result<u32> {
        let material = self.check_material(material_id, false)?;
        let (name, id) = self.next_geometry();
        self.scene
            .add_mesh(&name, &MeshDesc::new(source, &material))?;
        self.added(1)?;
        Ok(id)
    }
}

/// A groom of `source` drawn through `basis` as `shape`, for [`HtScene::add_groom`].
fn groom(source: GroomSource, basis: Option<CurveBasis>, shape: GroomShape) -> GroomDesc {
    GroomDesc {
        basis,
        shape,
        ..GroomDesc::new(source, "")
    }
}

/// The basis of a curve geometry: one of the `HT_CURVE_*` basis constants.
pub type HtCurveBasis = u32;
/// Straight segments between consecutive points.
pub const HT_CURVE_LINEAR: HtCurveBasis = 0;
/// Cubic Bezier.
pub const HT_CURVE_BEZIER: HtCurveBasis = 1;
/// Uniform cubic B-spline.
pub const HT_CURVE_BSPLINE: HtCurveBasis = 2;
/// Catmull-Rom spline.
pub const HT_CURVE_CATMULL_ROM: HtCurveBasis = 3;

/// The surface Embree builds around a curve: one of `HT_CURVE_ROUND`, `HT_CURVE_FLAT`,
/// `HT_CURVE_AUTO`.
pub type HtCurveShape = u32;
/// A true tube: the reference, and what close-ups need.
pub const HT_CURVE_ROUND: HtCurveShape = 0;
/// A ribbon facing the ray: faster, approximate up close.
pub const HT_CURVE_FLAT: HtCurveShape = 1;
/// Per strand, at a build: a ribbon where the strand is at most one pixel wide from the
/// camera, a tube elsewhere. On the bench scenes it renders 1.15-1.5x as fast as round
/// tubes, at an error within the noise of a render (docs/measurements.md, "Curve shapes"). A later
/// render keeps the build while no pixel is smaller where the strands are than at that
/// build (farther, a wider view, fewer pixels); a nearer or finer view builds again.
pub const HT_CURVE_AUTO: HtCurveShape = 2;

/// Strands as polylines, copied by `ht_scene_add_curves`: the host may free its arrays
/// when the call returns.
///
/// Every basis draws each strand from its first point (root) to its last (tip), one curve
/// segment per polyline segment: linear joins the points, Catmull-Rom passes through them,
/// B-spline smooths between root and tip, Bezier is the Catmull-Rom curve in Bezier form.
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HtCurves {
    /// Number of strands, >= 1.
    pub strand_count: usize,
    /// Points of each strand (each >= 2), `strand_count` values adding up to `point_count`.
    pub point_counts: *const u32,
    /// Points of all strands.
    pub point_count: usize,
    /// x, y, z of every point (world units, finite, within +-1e15), strand after strand:
    /// `3 * point_count` floats.
    pub points: *const f32,
    /// Fiber radius (not diameter) at every point, finite and > 0: `point_count` floats;
    /// or NULL.
    pub radii: *const f32,
    /// Fiber radius (not diameter) of every point when `radii` is NULL, > 0.
    pub radius: f32,
    /// Linear RGB reflectance at every point (`3 * point_count` floats, each in [0, 1]; 0
    /// is taken as 1e-4, the darkest colour a finite absorption makes), used by hair
    /// materials with `use_vertex_colors`; or NULL.
    pub colors: *const f32,
    pub basis: HtCurveBasis,
    pub shape: HtCurveShape,
}

/// Control points already laid out for the basis, as float4 (x, y, z, radius), for hosts
/// that hold that layout. `ht_scene_add_curves_xyzr` copies them, and the host may free its
/// arrays when the call returns; `ht_scene_add_curves_xyzr_shared` reads `points` in place
/// for the life of the scene (see there).
///
/// A strand of n control points has n - 1 linear segments, n - 3 B-spline or Catmull-Rom
/// segments (the curve runs between the second and the second-to-last point), or (n - 1) / 3
/// Bezier segments (n = 3k + 1, consecutive segments sharing end points).
#[repr(C)]
#[derive(Debug, Clone, Copy)]
pub struct HtCurvesXyzr {
    /// Number of strands, >= 1.
    pub strand_count: usize,
    /// Control points of each strand, `strand_count` values adding up to `point_count`.
    pub point_counts: *const u32,
    /// Control points of all strands.
    pub point_count: usize,
    /// x, y, z (world units, within +-1e15), radius (not diameter, >= 0) of every control
    /// point, all finite: `4 * point_count` floats.
    pub points: *const f32,
    /// Linear RGB reflectance (each in [0, 1], as in `HtCurves`) at every segment end,
    /// segments + 1 per strand, strand after strand; or NULL.
    pub colors: *const f32,
    pub basis: HtCurveBasis,
    pub shape: HtCurveShape,
}

/// The alignment of the control points Embree reads in place: it loads each float4 with
/// one aligned 16-byte load.
const EMBREE_VERTEX_ALIGN: usize = 16;

fn curve_basis(basis: HtCurveBasis) -> Result<CurveBasis> {
    Ok(match basis {
        HT_CURVE_LINEAR => CurveBasis::Linear,
        HT_CURVE_BEZIER => CurveBasis::Bezier,
        HT_CURVE_BSPLINE => CurveBasis::BSpline,
        HT_CURVE_CATMULL_ROM => CurveBasis::CatmullRom,
        _ => {
            return Err(invalid_arg!(
                "basis = {basis}: not an HT_CURVE_* basis (0 to 3)"
            ));
        }
    })
}

fn curve_shape(shape: HtCurveShape) -> Result<GroomShape> {
    Ok(match shape {
        HT_CURVE_ROUND => GroomShape::Round,
        HT_CURVE_FLAT => GroomShape::Flat,
        HT_CURVE_AUTO => GroomShape::Auto,
        _ => {
            return Err(invalid_arg!(
                "shape = {shape}: not HT_CURVE_ROUND (0), HT_CURVE_FLAT (1) or HT_CURVE_AUTO (2)"
            ));
        }
    })
}

fn check_strand_count(n: usize) -> Result<()> {
    if n == 0 {
        return Err(invalid_arg!(
            "desc->strand_count = 0: at least one strand is needed"
        ));
    }
    Ok(())
}

/// `n` host float triples (3 n floats).
fn host_triples<'a>(
    ptr: *const f32,
    n: usize,
    name: &str,
) -> std::result::Result<&'a [[f32; 3]], Failure> {
    host_slice(ptr.cast(), n, name)
}

/// Adds strands given as polylines (copied: see `HtCurves`), shaded by the hair material
/// `material_id`; writes the geometry id (0, 1, ... over curves and meshes, in the order
/// they are added) to `geom_id`. `desc->radii` and `desc->colors` may be NULL.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `desc`, `geom_id` or a required array NULL);
/// `HT_ERR_INVALID_ARG` (no strand, a strand of fewer points than its basis needs, counts
/// that do not add up, a NaN, infinite or out-of-range value, an unknown basis or shape,
/// a misaligned or oversized array, a material that is not hair). Nothing is added on
/// failure, and `*geom_id` is written on `HT_OK` only.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `desc` is NULL or points
/// to a readable struct whose non-NULL arrays hold the counts it gives; `geom_id` is NULL
/// or points to a writable `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_curves(
    scene: *mut HtScene,
    desc: *const HtCurves,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let d = read_host(desc, "desc")?;
        scene.check_material(material_id, true)?;
        let (basis, shape) = (curve_basis(d.basis)?, curve_shape(d.shape)?);
        check_strand_count(d.strand_count)?;
        let counts = host_slice(d.point_counts, d.strand_count, "desc->point_counts")?;
        let points = host_triples(d.points, d.point_count, "desc->points")?;
        let radii = if d.radii.is_null() {
            if !(d.radius.is_finite() && d.radius > 0.0) {
                return Err(invalid_arg!(
                    "desc->radius = {}: must be finite and > 0 when desc->radii is NULL",
                    d.radius
                )
                .into());
            }
            vec![d.radius; d.point_count]
        } else {
            host_slice(d.radii, d.point_count, "desc->radii")?.to_vec()
        };
        let colors = (!d.colors.is_null())
            .then(|| host_triples(d.colors, d.point_count, "desc->colors").map(<[_]>::to_vec))
            .transpose()?;
        let strands = Strands {
            points: points.to_vec(),
            radii,
            counts: counts.to_vec(),
            colors,
        };
        let source = GroomSource::Strands(strands);
        Ok(scene
            .add_groom(groom(source, Some(basis), shape), material_id)?
            .0)
    })
}

/// Adds strands of float4 control points laid out for the basis (copied: see
/// `HtCurvesXyzr`, any 4-byte alignment), shaded by the hair material `material_id`;
/// writes the geometry id. `desc->colors` may be NULL.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `desc`, `geom_id` or a required array NULL);
/// `HT_ERR_INVALID_ARG` (no strand, a strand of fewer points than its basis needs, counts
/// that do not add up, a NaN, infinite or out-of-range value, an unknown basis or shape,
/// a misaligned or oversized array, a material that is not hair). Nothing is added on
/// failure, and `*geom_id` is written on `HT_OK` only.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `desc` is NULL or points
/// to a readable struct whose non-NULL arrays hold the counts it gives; `geom_id` is NULL
/// or points to a writable `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_curves_xyzr(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let still = LaterSteps::STILL;
    add_curves_xyzr(scene, desc, still, material_id, geom_id, |points| {
        Ok(points.to_vec().into())
    })
}

/// As `ht_scene_add_curves_xyzr`, but `desc->points` is shared, not copied: Embree reads
/// the host's array in place, through every render and every rebuild after later
/// additions, and the scene never holds a copy of it. The host keeps those
/// `4 * point_count` floats allocated and unchanged until `ht_scene_free` returns; writing
/// to them or freeing them earlier is undefined behaviour. `points` must be aligned to 16
/// bytes, as Embree loads each float4 with one aligned load (`malloc` and `aligned_alloc`
/// give such memory; a float array at an odd offset does not). No padding is needed past the
/// last point: Embree reads at most the 16 bytes of a float4 from its start). The small
/// per-strand data are still built and kept by the scene: `point_counts` and `colors` are
/// read during the call only, and the index buffer takes 4 bytes per segment.
///
/// Statuses: as `ht_scene_add_curves_xyzr`; `desc->points` not aligned to 16 bytes is
/// `HT_ERR_INVALID_ARG` (use `ht_scene_add_curves_xyzr`, which copies, for such memory).
///
/// One thread at a time per scene; no thread may write `desc->points` while the scene
/// lives.
///
/// # Safety
/// As `ht_scene_add_curves_xyzr`, and `desc->points` stays allocated and unchanged until
/// `ht_scene_free` returns.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_curves_xyzr_shared(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let still = LaterSteps::STILL;
    add_curves_xyzr(scene, desc, still, material_id, geom_id, |points| {
        if points.as_ptr() as usize % EMBREE_VERTEX_ALIGN != 0 {
            return Err(invalid_arg!(
                "desc->points = {:?} is not aligned to {EMBREE_VERTEX_ALIGN} bytes: shared \
                 points are read by Embree with aligned 16-byte loads (copy them with \
                 ht_scene_add_curves_xyzr instead)",
                points.as_ptr()
            )
            .into());
        }
        // SAFETY: `points` is the host's checked array (aligned, in bounds); the host keeps it
        // valid and unchanged until ht_scene_free (the documented contract), and the scene
        // is the last owner of every clone of this buffer.
        Ok(unsafe { SharedBuffer::from_raw_parts(NonNull::from(points).cast(), points.len()) })
    })
}

/// The most time steps of strands in motion: Embree's limit.
pub const HT_MAX_TIME_STEPS: usize = 129;
const _: () = assert!(HT_MAX_TIME_STEPS == MAX_TIME_STEPS);

/// Adds strands of float4 control points laid out for the basis that move over the
/// shutter (copied, as `ht_scene_add_curves_xyzr`), shaded by the hair material
/// `material_id`; writes the geometry id. `desc->points` are the control points at the
/// first of `later_step_count + 1` time steps spread evenly over the shutter (the settings
/// `shutter_open` and `shutter_close`: the first step where it opens, the last where it
/// closes; docs/c-abi.md); `later_points[k]` points to the `4 * desc->point_count` floats
/// of the same control points at step k + 1, laid out alike. Between two steps a point
/// moves in a straight line. With `later_step_count` 0 (`later_points` may then be NULL)
/// this is `ht_scene_add_curves_xyzr`.
///
/// Statuses: as `ht_scene_add_curves_xyzr`, and `HT_ERR_NULL_ARG` for `later_points` or
/// one of its pointers NULL when it is read; `HT_ERR_INVALID_ARG` for more than
/// `HT_MAX_TIME_STEPS - 1` later steps, or a NaN, infinite or out-of-range value at a
/// step (the message names the step).
///
/// # Safety
/// As `ht_scene_add_curves_xyzr`, and `later_points` is NULL or points to
/// `later_step_count` pointers, each NULL or to `4 * desc->point_count` readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_curves_xyzr_motion(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    later_points: *const *const f32,
    later_step_count: usize,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let later = LaterSteps {
        points: later_points,
        count: later_step_count,
        name: "later_points",
    };
    add_curves_xyzr(scene, desc, later, material_id, geom_id, |points| {
        Ok(points.to_vec().into())
    })
}

/// The host's arrays (control points or vertices) at the time steps after the first: the
/// C arguments `later_*` and `later_step_count`.
struct LaterSteps {
    points: *const *const f32,
    count: usize,
    /// The C argument's name, for messages: `later_points` or `later_positions`.
    name: &'static str,
}

impl LaterSteps {
    /// No later step: strands or a mesh that stay put.
    const STILL: LaterSteps = LaterSteps {
        points: std::ptr::null(),
        count: 0,
        name: "later_points",
    };

    /// The array of each later step, `len` elements of `T`, checked as `host_slice` checks
    /// (the message names `name[k]`); more than `HT_MAX_TIME_STEPS - 1` are refused.
    fn arrays<'h, T>(&self, len: usize) -> std::result::Result<Vec<&'h [T]>, Failure> {
        if self.count >= HT_MAX_TIME_STEPS {
            return Err(invalid_arg!(
                "later_step_count = {}: at most {} (HT_MAX_TIME_STEPS - 1)",
                self.count,
                HT_MAX_TIME_STEPS - 1
            )
            .into());
        }
        let steps = host_slice(self.points, self.count, self.name)?;
        (steps.iter().enumerate())
            .map(|(k, &p)| host_slice(p.cast(), len, &format!("{}[{k}]", self.name)))
            .collect()
    }
}

/// The body of the `ht_scene_add_curves_xyzr` entry points; `vertices` turns each checked
/// host array of control points (one per time step) into a buffer Embree reads.
fn add_curves_xyzr(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    later: LaterSteps,
    material_id: u32,
    geom_id: *mut u32,
    vertices: impl Fn(&[[f32; 4]]) -> std::result::Result<SharedBuffer<[f32; 4]>, Failure>,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let d = read_host(desc, "desc")?;
        scene.check_material(material_id, true)?;
        let (basis, shape) = (curve_basis(d.basis)?, curve_shape(d.shape)?);
        check_strand_count(d.strand_count)?;
        let counts = host_slice(d.point_counts, d.strand_count, "desc->point_counts")?;
        let points: &[[f32; 4]] = host_slice(d.points.cast(), d.point_count, "desc->points")?;
        let colors = if d.colors.is_null() {
            None
        } else {
            // One colour per segment end: the strand counts say how many to read.
            let mut ends = 0usize;
            for (s, &n) in counts.iter().enumerate() {
                let segments = basis.segments_for(n as usize).ok_or_else(|| {
                    invalid_arg!(
                        "desc->point_counts[{s}] = {n}: not a whole number of {basis:?} segments"
                    )
                })?;
                ends += segments + 1;
            }
            Some(host_triples(d.colors, ends, "desc->colors")?.to_vec())
        };
        let later_steps = (later.arrays(d.point_count)?.into_iter())
            .map(&vertices)
            .collect::<std::result::Result<_, Failure>>()?;
        let material = scene.check_material(material_id, true)?;
        let points = ControlPoints {
            points: vertices(points)?,
            later_steps,
            counts: counts.to_vec(),
            colors,
            basis,
        };
        let (name, id) = scene.next_geometry();
        (scene.scene).add_control_points(&name, points, shape, &material)?;
        scene.added(1)?;
        Ok(id)
    })
}

/// Adds the strands of a Cem Yuksel `.hair` file (read during the call) as polylines for
/// `basis`, shaded by the hair material `material_id`; writes the geometry id. The file's
/// thickness is a diameter unless `thickness_is_radius`. A file that `hairtrace convert`
/// wrote says its up axis and unit in its header, and is turned and scaled into +y up
/// metres as a scene file reads it (docs/formats.md).
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `path` or `geom_id` NULL); `HT_ERR_IO` (the file
/// is missing or unreadable); `HT_ERR_INVALID_ARG` (an empty or non-UTF-8 path, a
/// malformed file, values out of range, an unknown basis or shape, a material that is
/// not hair).
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `path` is NULL or a
/// NUL-terminated string; `geom_id` is NULL or points to a writable `uint32_t`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_hair_file(
    scene: *mut HtScene,
    path: *const c_char,
    thickness_is_radius: bool,
    basis: HtCurveBasis,
    shape: HtCurveShape,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let file = HairFile {
        thickness_is_radius,
        basis,
        shape,
    };
    add_hair_file(scene, path, None, file, material_id, geom_id)
}

/// As `ht_scene_add_hair_file`, read at frame `frame` of an animation: a file whose name
/// has a run of # (`groom.####.hair`) is a sequence of per-frame files, and the call reads
/// the file of that frame (`groom.0012.hair` at frame 12; a whole frame >= 0, whose file
/// must exist); any other file is the same at every frame. With `settings` (NULL: a closed
/// shutter) whose shutter is open (`shutter_open` < `shutter_close`), a sequence moves over
/// it: its strands hold time steps read where the shutter opens, where it closes and
/// evenly between, as many as take in every whole frame inside, a step between two frames
/// blending their files linearly (docs/formats.md, "Motion blur"), as a scene file with
/// those `[render]` settings reads it. Render with the same shutter.
///
/// Statuses: those of `ht_scene_add_hair_file`; `HT_ERR_INVALID_ARG` also for a frame that
/// is not finite or, for a sequence, not a whole number >= 0, a file of the sequence that
/// does not exist, files the shutter spans that hold different strands or points (the
/// message names both), and `settings` that do not hold together (as `ht_render_with`
/// refuses them).
///
/// # Safety
/// As `ht_scene_add_hair_file`, and `settings` is NULL or a live handle that no other
/// thread sets during the call.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature of ht_scene_add_hair_file, and the frame
pub unsafe extern "C" fn ht_scene_add_hair_file_at(
    scene: *mut HtScene,
    path: *const c_char,
    frame: f64,
    settings: *const HtSettings,
    thickness_is_radius: bool,
    basis: HtCurveBasis,
    shape: HtCurveShape,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let file = HairFile {
        thickness_is_radius,
        basis,
        shape,
    };
    let at = Some(Frame { frame, settings });
    add_hair_file(scene, path, at, file, material_id, geom_id)
}

/// How a C host draws a `.hair` file's strands.
struct HairFile {
    thickness_is_radius: bool,
    basis: HtCurveBasis,
    shape: HtCurveShape,
}

/// The body of the `ht_scene_add_hair_file` entry points.
fn add_hair_file(
    scene: *mut HtScene,
    path: *const c_char,
    at: Option<Frame>,
    file: HairFile,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let path = read_path(path, "path")?;
        scene.check_material(material_id, true)?;
        let (basis, shape) = (curve_basis(file.basis)?, curve_shape(file.shape)?);
        let thickness = if file.thickness_is_radius {
            Thickness::Radius
        } else {
            Thickness::Diameter
        };
        let (frame, settings) = read_frame(at)?;
        // Read as a scene file reads it: in the units its header says, if it says them.
        let source = GroomSource::File {
            path,
            thickness,
            frame,
        };
        let groom = groom(source, Some(basis), shape);
        Ok(scene.add_groom_over(groom, material_id, settings)?.0)
    })
}

/// Adds every BasisCurves prim of a USD stage (.usd, .usda, .usdc or .usdz, read and
/// composed during the call; see docs/formats.md) as its own curve geometry, laid out by the
/// prim's `type`, `basis` and `wrap`, in world space, shaded by the hair material
/// `material_id`. Writes the first geometry id to `first_geom_id` (the others follow it)
/// and the number of geometries added (0 for a stage without BasisCurves) to `geom_count`.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `path`, `first_geom_id` or `geom_count` NULL);
/// `HT_ERR_IO` (the file is missing or unreadable); `HT_ERR_INVALID_ARG` (an empty or
/// non-UTF-8 path, a file that is not a USD stage or fails to compose, a prim the reader
/// refuses, an unknown shape, a material that is not hair). Nothing is added on error.
///
/// Crate files (.usdc, and those inside a .usdz) are checked before they are parsed, so a
/// corrupt or hostile file gives `HT_ERR_INVALID_ARG` rather than a huge allocation
/// (docs/formats.md, "Limits").
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `path` is NULL or a
/// NUL-terminated string; `first_geom_id` and `geom_count` are NULL or point to writable
/// `uint32_t`s.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_usd_file(
    scene: *mut HtScene,
    path: *const c_char,
    shape: HtCurveShape,
    material_id: u32,
    first_geom_id: *mut u32,
    geom_count: *mut u32,
) -> HtStatus {
    let ids = (first_geom_id, geom_count);
    add_usd_file(scene, path, None, shape, material_id, ids)
}

/// As `ht_scene_add_usd_file`, read at frame `frame` of the stage's animation: every
/// attribute at that frame's time code (frame x `timeCodesPerSecond` / `framesPerSecond`),
/// interpolated between time samples as USD defines (docs/formats.md, "Animation"); a path
/// whose file name has a run of # names a sequence of per-frame stages, of which the
/// frame's is read. With `settings` (NULL: a closed shutter) whose shutter is open
/// (`shutter_open` < `shutter_close`), an animated stage moves over it: each prim's curves
/// hold time steps read where the shutter opens, where it closes and evenly between, as
/// many as take in every time sample inside (docs/formats.md, "Motion blur"), as a scene
/// file with those `[render]` settings reads it. Render with the same shutter.
///
/// Statuses: those of `ht_scene_add_usd_file`; `HT_ERR_INVALID_ARG` also for a frame that
/// is not finite or lies outside the stage's animation, a sample the reader refuses (the
/// message names the prim and the frame), a prim whose counts change inside the shutter,
/// and `settings` that do not hold together (as `ht_render_with` refuses them).
///
/// # Safety
/// As `ht_scene_add_usd_file`, and `settings` is NULL or a live handle that no other
/// thread sets during the call.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature of ht_scene_add_usd_file, and the frame
pub unsafe extern "C" fn ht_scene_add_usd_file_at(
    scene: *mut HtScene,
    path: *const c_char,
    frame: f64,
    settings: *const HtSettings,
    shape: HtCurveShape,
    material_id: u32,
    first_geom_id: *mut u32,
    geom_count: *mut u32,
) -> HtStatus {
    let (at, ids) = (Some(Frame { frame, settings }), (first_geom_id, geom_count));
    add_usd_file(scene, path, at, shape, material_id, ids)
}

/// The body of the `ht_scene_add_usd_file` entry points; `ids` are the out-parameters
/// `first_geom_id` and `geom_count`.
fn add_usd_file(
    scene: *mut HtScene,
    path: *const c_char,
    at: Option<Frame>,
    shape: HtCurveShape,
    material_id: u32,
    (first_geom_id, geom_count): (*mut u32, *mut u32),
) -> HtStatus {
    add_with_id(scene, first_geom_id, "first_geom_id", |scene| {
        let count_out = non_null_mut(geom_count, "geom_count")?;
        let path = read_path(path, "path")?;
        scene.check_material(material_id, true)?;
        let shape = curve_shape(shape)?;
        let (frame, settings) = read_frame(at)?;
        let source = GroomSource::File {
            path,
            thickness: Thickness::Diameter,
            frame,
        };
        let (first, count) =
            scene.add_groom_over(groom(source, None, shape), material_id, settings)?;
        // SAFETY: non-NULL (checked), the host's uint32_t.
        unsafe { count_out.write(count) };
        Ok(first)
    })
}

/// The C arguments `frame` and `settings` of the `_at` entry points.
struct Frame {
    frame: f64,
    settings: *const HtSettings,
}

/// The frame a C host reads an animated file at (None: as a still, each attribute's
/// default value, else its first time sample), and the settings whose shutter its time
/// steps span (None: closed).
fn read_frame(
    at: Option<Frame>,
) -> std::result::Result<(Option<f64>, Option<RenderSettings>), Failure> {
    let Some(Frame { frame, settings }) = at else {
        return Ok((None, None));
    };
    if !frame.is_finite() {
        return Err(invalid_arg!("frame = {frame}: must be finite").into());
    }
    let settings = (!settings.is_null())
        .then(|| read_settings(settings))
        .transpose()?;
    Ok((Some(frame), settings))
}

/// Adds a triangle mesh (copied), shaded by the diffuse material `material_id`:
/// `positions` and `normals` hold 3 floats per vertex (`normals` may be NULL: flat
/// shading), `indices` 3 vertex indices per triangle, counter-clockwise seen from the
/// front. Positions are world units (finite, within +-1e15), normals finite. Writes the
/// geometry id.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `positions`, `indices` or `geom_id` NULL);
/// `HT_ERR_INVALID_ARG` (no vertex or no triangle, an index past the vertices, a NaN,
/// infinite or out-of-range value, a misaligned or oversized array, a material that is
/// not diffuse).
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `positions` and
/// `normals` are NULL or hold `3 * vertex_count` readable floats, `indices`
/// `3 * triangle_count` readable `uint32_t`; `geom_id` is NULL or writable.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature: one argument per array
pub unsafe extern "C" fn ht_scene_add_mesh(
    scene: *mut HtScene,
    vertex_count: usize,
    positions: *const f32,
    normals: *const f32,
    triangle_count: usize,
    indices: *const u32,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let vertices = Vertices {
        count: vertex_count,
        positions,
        later: LaterSteps::STILL,
        normals,
    };
    add_triangles(
        scene,
        vertices,
        triangle_count,
        indices,
        material_id,
        geom_id,
    )
}

/// Adds a triangle mesh that deforms over the shutter (copied), shaded by the diffuse
/// material `material_id`: `positions` holds its vertices (3 floats each) at the first of
/// `later_step_count + 1` time steps spread evenly over the shutter (the settings
/// `shutter_open` and `shutter_close`, as for `ht_scene_add_curves_xyzr_motion`), and
/// `later_positions[k]` the `3 * vertex_count` floats of the same vertices at step k + 1;
/// `indices` holds 3 vertex indices per triangle, the same at every step. Between two steps
/// a vertex moves in a straight line. A deforming mesh has no vertex normals: its geometric
/// normal at each ray's time shades it. With `later_step_count` 0 (`later_positions` may
/// then be NULL) this is `ht_scene_add_mesh` without normals. Writes the geometry id.
///
/// Statuses: as `ht_scene_add_mesh`, and `HT_ERR_NULL_ARG` for `later_positions` or one of
/// its pointers NULL when it is read; `HT_ERR_INVALID_ARG` for more than
/// `HT_MAX_TIME_STEPS - 1` later steps, or a NaN, infinite or out-of-range value at a step
/// (the message names the step).
///
/// # Safety
/// As `ht_scene_add_mesh`, and `later_positions` is NULL or points to `later_step_count`
/// pointers, each NULL or to `3 * vertex_count` readable floats.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature: one argument per array
pub unsafe extern "C" fn ht_scene_add_mesh_motion(
    scene: *mut HtScene,
    vertex_count: usize,
    positions: *const f32,
    later_positions: *const *const f32,
    later_step_count: usize,
    triangle_count: usize,
    indices: *const u32,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    let vertices = Vertices {
        count: vertex_count,
        positions,
        later: LaterSteps {
            points: later_positions,
            count: later_step_count,
            name: "later_positions",
        },
        normals: std::ptr::null(),
    };
    add_triangles(
        scene,
        vertices,
        triangle_count,
        indices,
        material_id,
        geom_id,
    )
}

/// A C host's mesh vertices: their positions at each time step and their normals.
struct Vertices {
    count: usize,
    positions: *const f32,
    later: LaterSteps,
    normals: *const f32,
}

/// The body of `ht_scene_add_mesh` and `ht_scene_add_mesh_motion`.
fn add_triangles(
    scene: *mut HtScene,
    vertices: Vertices,
    triangle_count: usize,
    indices: *const u32,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        scene.check_material(material_id, false)?;
        let vertex_count = vertices.count;
        if vertex_count == 0 || triangle_count == 0 {
            return Err(invalid_arg!(
                "vertex_count = {vertex_count}, triangle_count = {triangle_count}: a mesh needs \
                 at least one triangle"
            )
            .into());
        }
        let positions = host_triples(vertices.positions, vertex_count, "positions")?.to_vec();
        let normals = (!vertices.normals.is_null())
            .then(|| host_triples(vertices.normals, vertex_count, "normals").map(<[_]>::to_vec))
            .transpose()?;
        let later: Vec<&[[f32; 3]]> = vertices.later.arrays(vertex_count)?;
        let triangles: &[[u32; 3]] = host_slice(indices.cast(), triangle_count, "indices")?;
        let mesh = Mesh {
            positions,
            triangles: triangles.to_vec(),
            normals,
            later_positions: later.into_iter().map(<[_]>::to_vec).collect(),
        };
        mesh.validate()?;
        Ok(scene.add_mesh(MeshSource::Triangles(mesh), material_id)?)
    })
}

/// Adds the mesh of an `.obj` or `.ply` file (by extension), shaded by the diffuse
/// material `material_id`; writes the geometry id. The file is read during the call.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `path` or `geom_id` NULL); `HT_ERR_IO` (the file
/// is missing or unreadable); `HT_ERR_INVALID_ARG` (an empty or non-UTF-8 path, another
/// extension, a malformed file, no triangle, values out of range, a material that is not
/// diffuse).
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `path` is NULL or a
/// NUL-terminated string; `geom_id` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_mesh_file(
    scene: *mut HtScene,
    path: *const c_char,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let path = read_path(path, "path")?;
        Ok(scene.add_mesh(MeshSource::File(path), material_id)?)
    })
}
