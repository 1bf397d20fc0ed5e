//! Devices and scenes through the C ABI: materials, curves and meshes from host buffers or
//! files, lights and the camera, added one call at a time.
//!
//! The scene keeps what the host added (curves already converted for Embree) and builds
//! the Embree scene on the first render, then reuses it: adding geometry rebuilds it on
//! the next render, adding a light only re-weights the lights.

use super::bsdf::HtHairParams;
use super::{
    Failure, HtStatus, boundary, host_slice, non_null, non_null_mut, read_path, read_vec3,
};
use crate::bsdf::diffuse::Diffuse;
use crate::embree::{CurveBasis, CurveShape, Device, SceneOptions, SharedBuffer};
use crate::error::{Result, invalid_arg};
use crate::render::integrator::World;
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;
use crate::scene::envmap::Environment;
use crate::scene::light::Light;
use crate::scene::material::{HairColor, HairMaterial, Material};
use crate::scene::mesh::Mesh;
use crate::scene::tracer::{Tracer, TracerBuilder};
use crate::scene::{Strands, Thickness, read_hair_file};
use std::ffi::c_char;
use std::ptr::NonNull;
use std::sync::Arc;

/// An Embree device: its thread pool builds the scenes made on it. Create one per
/// process and share it between scenes. Thread safe.
pub struct HtDevice {
    device: Arc<Device>,
}

/// A scene under construction and, after the first render, its built form. Not thread
/// safe: call the functions of one scene from one thread at a time (different scenes may
/// be used concurrently).
///
/// Memory: the scene keeps its own copy of every geometry, so that it can rebuild after
/// later additions, and a rendered scene holds a second copy in Embree's buffers plus the
/// BVH; control points added with `ht_scene_add_curves_xyzr_shared` are never copied, by
/// either. For the largest grooms, share them (or add everything before the first render)
/// and free the scene when done.
pub struct HtScene {
    device: Arc<Device>,
    materials: Vec<Material>,
    geometries: Vec<Geometry>,
    lights: Vec<Light>,
    camera: Option<Camera>,
    /// Aperture radius and focus distance of a thin lens, validated; kept apart from the
    /// camera so that either may be set first, and the framing camera gets it too.
    lens: Option<(f32, f32)>,
    /// The last build; None until the first render and after geometry is added.
    world: Option<World>,
    /// Lights were added since `world` was built.
    lights_changed: bool,
}

enum Shape {
    Curves(Curves),
    Mesh(Mesh),
}

struct Geometry {
    shape: Shape,
    material: u32,
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

/// The surface Embree builds around a curve: one of `HT_CURVE_ROUND`, `HT_CURVE_FLAT`.
pub type HtCurveShape = u32;
/// A true tube: the reference, and what close-ups need.
pub const HT_CURVE_ROUND: HtCurveShape = 0;
/// A ribbon facing the ray: faster, approximate up close.
pub const HT_CURVE_FLAT: HtCurveShape = 1;

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
    /// x, y, z of every point, strand after strand: `3 * point_count` floats.
    pub points: *const f32,
    /// Fiber radius (not diameter) at every point, > 0: `point_count` floats; or NULL.
    pub radii: *const f32,
    /// Fiber radius (not diameter) of every point when `radii` is NULL, > 0.
    pub radius: f32,
    /// Linear RGB at every point (`3 * point_count` floats, >= 0), used by hair materials
    /// with `use_vertex_colors`; or NULL.
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
    /// x, y, z, radius (not diameter, >= 0) of every control point: `4 * point_count`
    /// floats.
    pub points: *const f32,
    /// Linear RGB (>= 0) at every segment end, segments + 1 per strand, strand after
    /// strand; or NULL.
    pub colors: *const f32,
    pub basis: HtCurveBasis,
    pub shape: HtCurveShape,
}

/// How a hair material varies over the groom, deterministically from the seed, the
/// strand and the position along it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HtHairVariation {
    /// Per-strand spread of the absorption, in [0, 1]: sigma_a is scaled by a factor drawn
    /// from [1 - x, 1 + x].
    pub absorption_variation: f32,
    /// Per-strand spread of beta_m and beta_n, in [0, 1].
    pub roughness_variation: f32,
    /// Absorption at the tip relative to the root, > 0 (below 1: lighter tips).
    pub tip_absorption: f32,
    /// Take the absorption from the curves' per-point colours where they have them.
    pub use_vertex_colors: bool,
    /// Seed of the per-strand random choices.
    pub seed: u64,
}

impl HtScene {
    /// The material `id` for a geometry; hair goes on curves, diffuse on meshes.
    fn check_material(&self, id: u32, on_curves: bool) -> Result<()> {
        match (self.materials.get(id as usize), on_curves) {
            (None, _) => Err(invalid_arg!(
                "material_id = {id}: the scene has {} materials",
                self.materials.len()
            )),
            (Some(Material::Hair(_)), true) | (Some(Material::Diffuse(_)), false) => Ok(()),
            (Some(Material::Diffuse(_)), true) => Err(invalid_arg!(
                "material_id = {id} is a diffuse material; curves need a hair material"
            )),
            (Some(Material::Hair(_)), false) => Err(invalid_arg!(
                "material_id = {id} is a hair material; meshes need a diffuse material"
            )),
        }
    }

    fn add_geometry(&mut self, shape: Shape, material: u32) -> Result<u32> {
        let id = u32::try_from(self.geometries.len())
            .map_err(|_| invalid_arg!("too many geometries"))?;
        self.geometries.push(Geometry { shape, material });
        self.world = None;
        Ok(id)
    }

    fn build_tracer(&self) -> Result<Tracer> {
        let mut builder = TracerBuilder::new(self.device.clone(), SceneOptions::default())?;
        for g in &self.geometries {
            match &g.shape {
                Shape::Curves(c) => builder.add_curves(c.clone())?,
                Shape::Mesh(m) => builder.add_mesh(m.clone())?,
            };
        }
        builder.build()
    }

    /// The world to render, built or updated as needed, and the camera for an image of
    /// `aspect` (width over height).
    pub(crate) fn prepare(&mut self, aspect: f32) -> Result<(&World, Camera)> {
        if self.lights.is_empty() {
            return Err(invalid_arg!(
                "the scene has no light: add an environment, distant or rect light"
            ));
        }
        if self.world.is_none() || self.lights_changed {
            let tracer = match self.world.take() {
                Some(world) => world.tracer,
                None => self.build_tracer()?,
            };
            let materials = self
                .geometries
                .iter()
                .map(|g| self.materials[g.material as usize].clone())
                .collect();
            self.world = Some(World::new(tracer, materials, self.lights.clone())?);
            self.lights_changed = false;
        }
        let world = self.world.as_ref().expect("built above");
        let camera = match self.camera {
            Some(c) => c.with_aspect(aspect)?,
            None if self.geometries.is_empty() => {
                return Err(invalid_arg!(
                    "the scene has no geometry to frame: set a camera with ht_scene_set_camera"
                ));
            }
            None => {
                let (lo, hi) = world.tracer.scene().bounds();
                Camera::frame_bounds(lo.into(), hi.into(), aspect, Camera::DEFAULT_FOV_Y_DEG)?
            }
        };
        let camera = match self.lens {
            Some((aperture_radius, focus_distance)) => {
                camera.with_thin_lens(aperture_radius, focus_distance)?
            }
            None => camera,
        };
        Ok((world, camera))
    }
}

/// The scene behind a handle.
pub(crate) fn scene_mut<'a>(scene: *mut HtScene) -> std::result::Result<&'a mut HtScene, Failure> {
    // SAFETY: non-NULL (checked); the host passes a live handle from ht_scene_new and no
    // other call uses it at the same time (documented on HtScene).
    Ok(unsafe { &mut *non_null_mut(scene, "scene")? })
}

/// Runs `add` on the scene and writes the id it returns to `out` (checked first).
fn add_with_id(
    scene: *mut HtScene,
    out: *mut u32,
    out_name: &str,
    add: impl FnOnce(&mut HtScene) -> std::result::Result<u32, Failure>,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let out = non_null_mut(out, out_name)?;
        let id = add(scene)?;
        // SAFETY: non-NULL (checked), the host's uint32_t.
        unsafe { out.write(id) };
        Ok(())
    })
}

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

fn curve_shape(shape: HtCurveShape) -> Result<CurveShape> {
    Ok(match shape {
        HT_CURVE_ROUND => CurveShape::Round,
        HT_CURVE_FLAT => CurveShape::Flat,
        _ => {
            return Err(invalid_arg!(
                "shape = {shape}: not HT_CURVE_ROUND (0) or HT_CURVE_FLAT (1)"
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

/// Drops a boxed handle; NULL is nothing to free.
fn free_handle<T>(handle: *mut T) {
    if !handle.is_null() {
        // SAFETY: a handle from the matching ht_*_new, freed once (the host's promise).
        drop(unsafe { Box::from_raw(handle) });
    }
}

/// Creates a device with `threads` Embree worker threads (0: one per hardware thread).
/// Free it with `ht_device_free`; scenes keep it alive as long as they need it.
#[unsafe(no_mangle)]
pub extern "C" fn ht_device_new(threads: u32, out: *mut *mut HtDevice) -> HtStatus {
    boundary(|| {
        let out = non_null_mut(out, "out")?;
        let device = Device::new((threads > 0).then_some(threads as usize))?;
        let handle = Box::new(HtDevice {
            device: Arc::new(device),
        });
        // SAFETY: non-NULL (checked), the host's HtDevice*.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Releases a device handle (NULL: nothing to do). Scenes made on it stay valid.
#[unsafe(no_mangle)]
pub extern "C" fn ht_device_free(device: *mut HtDevice) -> HtStatus {
    boundary(|| {
        free_handle(device);
        Ok(())
    })
}

/// Creates an empty scene on `device`. Free it with `ht_scene_free`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_new(device: *const HtDevice, out: *mut *mut HtScene) -> HtStatus {
    boundary(|| {
        // SAFETY: non-NULL (checked), a live handle from ht_device_new.
        let device = unsafe { &*non_null(device, "device")? };
        let out = non_null_mut(out, "out")?;
        let scene = Box::new(HtScene {
            device: device.device.clone(),
            materials: Vec::new(),
            geometries: Vec::new(),
            lights: Vec::new(),
            camera: None,
            lens: None,
            world: None,
            lights_changed: false,
        });
        // SAFETY: non-NULL (checked), the host's HtScene*.
        unsafe { out.write(Box::into_raw(scene)) };
        Ok(())
    })
}

/// Releases a scene and everything it holds (NULL: nothing to do).
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_free(scene: *mut HtScene) -> HtStatus {
    boundary(|| {
        free_handle(scene);
        Ok(())
    })
}

/// No variation: every strand has the material's parameters, and seed 0.
#[unsafe(no_mangle)]
pub extern "C" fn ht_hair_variation_default() -> HtHairVariation {
    let m = HairMaterial::default();
    HtHairVariation {
        absorption_variation: m.absorption_variation,
        roughness_variation: m.roughness_variation,
        tip_absorption: m.tip_absorption,
        use_vertex_colors: m.use_vertex_colors,
        seed: m.seed,
    }
}

/// Adds a hair material with the same parameters on every strand; writes its id (0, 1, ...
/// in the order materials are added) to `material_id`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_hair_material(
    scene: *mut HtScene,
    params: *const HtHairParams,
    material_id: *mut u32,
) -> HtStatus {
    let none = ht_hair_variation_default();
    ht_scene_add_hair_material_varied(scene, params, &none, material_id)
}

/// Adds a hair material whose parameters vary over the groom as `variation` says.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_hair_material_varied(
    scene: *mut HtScene,
    params: *const HtHairParams,
    variation: *const HtHairVariation,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        // SAFETY: non-NULL (checked); the host's structs.
        let p = unsafe { *non_null(params, "params")? };
        let v = unsafe { *non_null(variation, "variation")? };
        let material = HairMaterial {
            color: HairColor::SigmaA(p.sigma_a),
            eta: p.eta,
            beta_m: p.beta_m,
            beta_n: p.beta_n,
            alpha: p.alpha,
            absorption_variation: v.absorption_variation,
            roughness_variation: v.roughness_variation,
            tip_absorption: v.tip_absorption,
            use_vertex_colors: v.use_vertex_colors,
            seed: v.seed,
        };
        let prepared = material.prepare()?;
        push_material(scene, Material::Hair(Box::new(prepared)))
    })
}

/// Adds a Lambertian material for meshes, with linear RGB `albedo` in [0, 1].
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_diffuse_material(
    scene: *mut HtScene,
    albedo: *const f32,
    material_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, material_id, "material_id", |scene| {
        let diffuse = Diffuse::new(read_vec3(albedo, "albedo")?)?;
        push_material(scene, Material::Diffuse(diffuse))
    })
}

fn push_material(scene: &mut HtScene, material: Material) -> std::result::Result<u32, Failure> {
    let id =
        u32::try_from(scene.materials.len()).map_err(|_| invalid_arg!("too many materials"))?;
    scene.materials.push(material);
    Ok(id)
}

/// Adds strands given as polylines (copied: see `HtCurves`), shaded by the hair material
/// `material_id`; writes the geometry id (0, 1, ... over curves and meshes, in the order
/// they are added) to `geom_id`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_curves(
    scene: *mut HtScene,
    desc: *const HtCurves,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        // SAFETY: non-NULL (checked); the host's struct.
        let d = unsafe { *non_null(desc, "desc")? };
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
        let curves = Curves::from_strands(&strands, basis, shape)?;
        Ok(scene.add_geometry(Shape::Curves(curves), material_id)?)
    })
}

/// Adds strands of float4 control points laid out for the basis (copied: see
/// `HtCurvesXyzr`), shaded by the hair material `material_id`; writes the geometry id.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_curves_xyzr(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_curves_xyzr(scene, desc, material_id, geom_id, |points| {
        points.to_vec().into()
    })
}

/// As `ht_scene_add_curves_xyzr`, but `desc->points` is shared, not copied: Embree reads
/// the host's array in place, through every render and every rebuild after later
/// additions, and the scene never holds a copy of it. The host keeps those
/// `4 * point_count` floats allocated and unchanged until `ht_scene_free` returns; writing
/// to them or freeing them earlier is undefined behaviour. `points` must be aligned to 4
/// bytes, like any float array (16-byte alignment is not needed, and no padding past the
/// last point: Embree reads at most the 16 bytes of a float4 from its start). The small
/// per-strand data are still built and kept by the scene: `point_counts` and `colors` are
/// read during the call only, and the index buffer takes 4 bytes per segment.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_curves_xyzr_shared(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_curves_xyzr(scene, desc, material_id, geom_id, |points| {
        // SAFETY: `points` is the host's checked array (aligned, in bounds); the host keeps it
        // valid and unchanged until ht_scene_free (the documented contract), and the scene
        // is the last owner of every clone of this buffer.
        unsafe { SharedBuffer::from_raw_parts(NonNull::from(points).cast(), points.len()) }
    })
}

/// The body of both `ht_scene_add_curves_xyzr` entry points; `vertices` turns the checked
/// host array of control points into the buffer Embree reads.
fn add_curves_xyzr(
    scene: *mut HtScene,
    desc: *const HtCurvesXyzr,
    material_id: u32,
    geom_id: *mut u32,
    vertices: impl FnOnce(&[[f32; 4]]) -> SharedBuffer<[f32; 4]>,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        // SAFETY: non-NULL (checked); the host's struct.
        let d = unsafe { *non_null(desc, "desc")? };
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
        let curves = Curves::from_control_points(vertices(points), counts, colors, basis, shape)?;
        Ok(scene.add_geometry(Shape::Curves(curves), material_id)?)
    })
}

/// Adds the strands of a Cem Yuksel `.hair` file as polylines for `basis`. The file's
/// thickness is a diameter unless `thickness_is_radius`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_hair_file(
    scene: *mut HtScene,
    path: *const c_char,
    thickness_is_radius: bool,
    basis: HtCurveBasis,
    shape: HtCurveShape,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let path = read_path(path, "path")?;
        scene.check_material(material_id, true)?;
        let (basis, shape) = (curve_basis(basis)?, curve_shape(shape)?);
        let thickness = if thickness_is_radius {
            Thickness::Radius
        } else {
            Thickness::Diameter
        };
        let strands = read_hair_file(&path, thickness)?;
        let curves = Curves::from_strands(&strands, basis, shape)?;
        Ok(scene.add_geometry(Shape::Curves(curves), material_id)?)
    })
}

/// Adds a triangle mesh (copied), shaded by the diffuse material `material_id`:
/// `positions` and `normals` hold 3 floats per vertex (`normals` may be NULL: flat
/// shading), `indices` 3 vertex indices per triangle, counter-clockwise seen from the
/// front. Writes the geometry id.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature: one argument per array
pub extern "C" fn ht_scene_add_mesh(
    scene: *mut HtScene,
    vertex_count: usize,
    positions: *const f32,
    normals: *const f32,
    triangle_count: usize,
    indices: *const u32,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        scene.check_material(material_id, false)?;
        if vertex_count == 0 || triangle_count == 0 {
            return Err(invalid_arg!(
                "vertex_count = {vertex_count}, triangle_count = {triangle_count}: a mesh needs \
                 at least one triangle"
            )
            .into());
        }
        let positions = host_triples(positions, vertex_count, "positions")?.to_vec();
        let normals = (!normals.is_null())
            .then(|| host_triples(normals, vertex_count, "normals").map(<[_]>::to_vec))
            .transpose()?;
        let triangles: &[[u32; 3]] = host_slice(indices.cast(), triangle_count, "indices")?;
        let mesh = Mesh::new(positions, triangles.to_vec(), normals)?;
        Ok(scene.add_geometry(Shape::Mesh(mesh), material_id)?)
    })
}

/// Adds the mesh of an `.obj` or `.ply` file (by extension), shaded by the diffuse
/// material `material_id`; writes the geometry id.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_mesh_file(
    scene: *mut HtScene,
    path: *const c_char,
    material_id: u32,
    geom_id: *mut u32,
) -> HtStatus {
    add_with_id(scene, geom_id, "geom_id", |scene| {
        let path = read_path(path, "path")?;
        scene.check_material(material_id, false)?;
        let mesh = Mesh::load(&path)?;
        Ok(scene.add_geometry(Shape::Mesh(mesh), material_id)?)
    })
}

/// Adds a light to the scene; `light` runs inside the boundary.
fn add_light(
    scene: *mut HtScene,
    light: impl FnOnce() -> std::result::Result<Light, Failure>,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        scene.lights.push(light()?);
        scene.lights_changed = true;
        Ok(())
    })
}

/// Adds an environment of the same linear RGB `radiance` (>= 0) from every direction.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_environment(scene: *mut HtScene, radiance: *const f32) -> HtStatus {
    add_light(scene, || {
        let env = Environment::uniform(read_vec3(radiance, "radiance")?)?;
        Ok(Light::Environment(env))
    })
}

/// Adds a lat-long environment map read through OpenImageIO (EXR, HDR, ...: linear
/// radiance), turned by `rotation_deg` about +y and its radiance multiplied by `scale`
/// (>= 0). It is importance sampled.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_environment_map(
    scene: *mut HtScene,
    path: *const c_char,
    rotation_deg: f32,
    scale: f32,
) -> HtStatus {
    add_light(scene, || {
        let path = read_path(path, "path")?;
        let env = Environment::from_file(&path)?
            .with_rotation(rotation_deg)?
            .with_scale(scale)?;
        Ok(Light::Environment(env))
    })
}

/// Adds a light at infinity: `direction` points toward it (any non-zero length), it
/// delivers linear RGB `irradiance` (>= 0) to a surface facing it, and is seen as a disc of
/// `angular_radius_deg` in [0, 90) (0: a point, with hard shadows).
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_distant_light(
    scene: *mut HtScene,
    direction: *const f32,
    irradiance: *const f32,
    angular_radius_deg: f32,
) -> HtStatus {
    add_light(scene, || {
        let light = Light::distant(
            read_vec3(direction, "direction")?,
            read_vec3(irradiance, "irradiance")?,
            angular_radius_deg.to_radians(),
        )?;
        Ok(light)
    })
}

/// Adds a parallelogram light with corners `corner`, `corner + edge_u`, `corner + edge_v`
/// and `corner + edge_u + edge_v`, emitting linear RGB `radiance` (>= 0) toward
/// `edge_u x edge_v`, or to both sides if `two_sided`.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_add_rect_light(
    scene: *mut HtScene,
    corner: *const f32,
    edge_u: *const f32,
    edge_v: *const f32,
    radiance: *const f32,
    two_sided: bool,
) -> HtStatus {
    add_light(scene, || {
        let light = Light::rect(
            read_vec3(corner, "corner")?,
            read_vec3(edge_u, "edge_u")?,
            read_vec3(edge_v, "edge_v")?,
            read_vec3(radiance, "radiance")?,
            two_sided,
        )?;
        Ok(light)
    })
}

/// Places the pinhole camera at `eye` looking at `target`, `up` giving the image's upward
/// direction (not parallel to the view), with a vertical field of view of `fov_y_deg` in
/// (0, 180). Replaces any earlier camera. Without one, renders frame the scene's bounds
/// from the front (+z), a little to the right and above.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_set_camera(
    scene: *mut HtScene,
    eye: *const f32,
    target: *const f32,
    up: *const f32,
    fov_y_deg: f32,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let camera = Camera::new(
            read_vec3(eye, "eye")?,
            read_vec3(target, "target")?,
            read_vec3(up, "up")?,
            fov_y_deg,
            1.0,
        )?;
        scene.camera = Some(camera);
        Ok(())
    })
}

/// Gives the camera a thin lens for depth of field: an aperture of `aperture_radius` (world
/// units, >= 0; 0 is the pinhole again) focused at `focus_distance` (world units along the
/// view direction, > 0), so that what lies nearer or farther blurs. Holds for the camera
/// of `ht_scene_set_camera`, whether set before or after, and for the camera that frames a
/// scene without one. Replaces any earlier lens.
#[unsafe(no_mangle)]
pub extern "C" fn ht_scene_set_thin_lens(
    scene: *mut HtScene,
    aperture_radius: f32,
    focus_distance: f32,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        // Checked here, with the C names, rather than at the next render.
        if !(aperture_radius.is_finite() && aperture_radius >= 0.0) {
            return Err(invalid_arg!(
                "aperture_radius = {aperture_radius}: must be finite and >= 0"
            )
            .into());
        }
        if !(focus_distance.is_finite() && focus_distance > 0.0) {
            return Err(
                invalid_arg!("focus_distance = {focus_distance}: must be finite and > 0").into(),
            );
        }
        scene.lens = Some((aperture_radius, focus_distance));
        Ok(())
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::capi::bsdf::ht_hair_params_default;
    use crate::capi::ht_last_error;
    use crate::embree::{MemoryMonitor, padding_for};
    use crate::scene::{FurBall, write_hair_file};
    use std::ffi::CStr;
    use std::ptr::{null, null_mut};

    pub(crate) fn last_error() -> String {
        unsafe { CStr::from_ptr(ht_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    /// Asserts `status` and that the message mentions `words`.
    #[track_caller]
    pub(crate) fn fails(status: HtStatus, want: HtStatus, words: &str) {
        assert_eq!(status, want, "{}", last_error());
        assert!(
            last_error().contains(words),
            "{:?} lacks {words:?}",
            last_error()
        );
    }

    /// A device and a scene, freed on drop.
    pub(crate) struct Handles {
        pub device: *mut HtDevice,
        pub scene: *mut HtScene,
    }

    impl Handles {
        pub(crate) fn new() -> Self {
            let (mut device, mut scene) = (null_mut(), null_mut());
            assert_eq!(ht_device_new(2, &mut device), HtStatus::HT_OK);
            assert_eq!(ht_scene_new(device, &mut scene), HtStatus::HT_OK);
            Handles { device, scene }
        }

        pub(crate) fn scene(&self) -> &HtScene {
            unsafe { &*self.scene }
        }

        pub(crate) fn hair_material(&self) -> u32 {
            let mut id = u32::MAX;
            let p = ht_hair_params_default();
            assert_eq!(
                ht_scene_add_hair_material(self.scene, &p, &mut id),
                HtStatus::HT_OK
            );
            id
        }

        pub(crate) fn diffuse_material(&self, albedo: [f32; 3]) -> u32 {
            let mut id = u32::MAX;
            let s = ht_scene_add_diffuse_material(self.scene, albedo.as_ptr(), &mut id);
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            id
        }

        /// Adds `strands` through `ht_scene_add_curves`.
        pub(crate) fn add_strands(&self, strands: &Strands, material: u32) -> HtStatus {
            let desc = curves_desc(strands);
            ht_scene_add_curves(self.scene, &desc, material, &mut 0)
        }

        /// Adds a single triangle in front of the origin.
        pub(crate) fn add_triangle(&self, material: u32) -> HtStatus {
            let positions = [-3.0f32, -3.0, -1.5, 3.0, -3.0, -1.5, 0.0, 3.0, -1.5];
            let indices = [0u32, 1, 2];
            let (p, i) = (positions.as_ptr(), indices.as_ptr());
            ht_scene_add_mesh(self.scene, 3, p, null(), 1, i, material, &mut 0)
        }
    }

    impl Drop for Handles {
        fn drop(&mut self) {
            assert_eq!(ht_scene_free(self.scene), HtStatus::HT_OK);
            assert_eq!(ht_device_free(self.device), HtStatus::HT_OK);
        }
    }

    /// `strands` as the C description, pointing into its arrays (B-spline, round).
    pub(crate) fn curves_desc(strands: &Strands) -> HtCurves {
        HtCurves {
            strand_count: strands.counts.len(),
            point_counts: strands.counts.as_ptr(),
            point_count: strands.points.len(),
            points: strands.points.as_ptr().cast(),
            radii: strands.radii.as_ptr(),
            radius: 0.0,
            colors: strands
                .colors
                .as_ref()
                .map_or(null(), |c| c.as_ptr().cast()),
            basis: HT_CURVE_BSPLINE,
            shape: HT_CURVE_ROUND,
        }
    }

    /// `strands` as float4 control points of linear curves.
    pub(crate) fn xyzr(strands: &Strands) -> Vec<[f32; 4]> {
        let radii = strands.radii.iter();
        let points = strands.points.iter().zip(radii);
        points.map(|(&[x, y, z], &r)| [x, y, z, r]).collect()
    }

    /// Linear round curves of `counts` strands over `points`.
    pub(crate) fn xyzr_desc(points: &[[f32; 4]], counts: &[u32]) -> HtCurvesXyzr {
        HtCurvesXyzr {
            strand_count: counts.len(),
            point_counts: counts.as_ptr(),
            point_count: points.len(),
            points: points.as_ptr().cast(),
            colors: null(),
            basis: HT_CURVE_LINEAR,
            shape: HT_CURVE_ROUND,
        }
    }

    pub(crate) fn small_fur() -> Strands {
        FurBall {
            strands: 300,
            segments: 8,
            ..FurBall::default()
        }
        .build()
        .unwrap()
    }

    #[test]
    fn null_handles_and_pointers_are_reported() {
        use HtStatus::{HT_ERR_NULL_ARG as NULL, HT_OK};
        assert_eq!(ht_device_free(null_mut()), HT_OK);
        assert_eq!(ht_scene_free(null_mut()), HT_OK);
        fails(ht_device_new(0, null_mut()), NULL, "out is NULL");
        fails(
            ht_scene_new(null(), &mut null_mut()),
            NULL,
            "device is NULL",
        );
        let h = Handles::new();
        fails(ht_scene_new(h.device, null_mut()), NULL, "out is NULL");
        let p = ht_hair_params_default();
        let mut id = 0;
        fails(
            ht_scene_add_hair_material(null_mut(), &p, &mut id),
            NULL,
            "scene",
        );
        fails(
            ht_scene_add_hair_material(h.scene, null(), &mut id),
            NULL,
            "params",
        );
        fails(
            ht_scene_add_hair_material(h.scene, &p, null_mut()),
            NULL,
            "material_id",
        );
        let none = ht_hair_variation_default();
        fails(
            ht_scene_add_hair_material_varied(h.scene, &p, null(), &mut id),
            NULL,
            "variation",
        );
        fails(
            ht_scene_add_diffuse_material(h.scene, null(), &mut id),
            NULL,
            "albedo",
        );
        let hair = h.hair_material();
        let strands = small_fur();
        let desc = curves_desc(&strands);
        fails(
            ht_scene_add_curves(h.scene, null(), hair, &mut id),
            NULL,
            "desc",
        );
        fails(
            ht_scene_add_curves(h.scene, &desc, hair, null_mut()),
            NULL,
            "geom_id",
        );
        let no_points = HtCurves {
            points: null(),
            ..desc
        };
        fails(
            ht_scene_add_curves(h.scene, &no_points, hair, &mut id),
            NULL,
            "desc->points",
        );
        let no_counts = HtCurves {
            point_counts: null(),
            ..desc
        };
        fails(
            ht_scene_add_curves(h.scene, &no_counts, hair, &mut id),
            NULL,
            "desc->point_counts",
        );
        fails(
            ht_scene_add_curves_xyzr(h.scene, null(), hair, &mut id),
            NULL,
            "desc",
        );
        fails(
            ht_scene_add_hair_file(h.scene, null(), false, 0, 0, hair, &mut id),
            NULL,
            "path",
        );
        let diffuse = h.diffuse_material([0.5; 3]);
        let v = [0.0f32, 1.0, 2.0];
        fails(
            ht_scene_add_mesh(
                h.scene,
                3,
                null(),
                null(),
                1,
                [0, 1, 2].as_ptr(),
                diffuse,
                &mut id,
            ),
            NULL,
            "positions",
        );
        fails(
            ht_scene_add_mesh(h.scene, 1, v.as_ptr(), null(), 1, null(), diffuse, &mut id),
            NULL,
            "indices",
        );
        fails(
            ht_scene_add_mesh_file(h.scene, null(), diffuse, &mut id),
            NULL,
            "path",
        );
        fails(ht_scene_add_environment(h.scene, null()), NULL, "radiance");
        fails(
            ht_scene_add_environment(null_mut(), v.as_ptr()),
            NULL,
            "scene",
        );
        fails(
            ht_scene_add_environment_map(h.scene, null(), 0.0, 1.0),
            NULL,
            "path",
        );
        fails(
            ht_scene_add_distant_light(h.scene, v.as_ptr(), null(), 0.0),
            NULL,
            "irradiance",
        );
        fails(
            ht_scene_add_rect_light(h.scene, v.as_ptr(), v.as_ptr(), null(), v.as_ptr(), false),
            NULL,
            "edge_v",
        );
        fails(
            ht_scene_set_camera(h.scene, v.as_ptr(), null(), v.as_ptr(), 40.0),
            NULL,
            "target",
        );
        // The variation-free path gives the same material as the explicit default.
        assert_eq!(
            ht_scene_add_hair_material_varied(h.scene, &p, &none, &mut id),
            HT_OK
        );
        assert_eq!(id, 2);
        assert!(h.scene().geometries.is_empty() && h.scene().lights.is_empty());
    }

    #[test]
    fn invalid_values_name_the_argument_and_add_nothing() {
        use HtStatus::HT_ERR_INVALID_ARG as INVALID;
        let h = Handles::new();
        let mut id = 0;
        let p = ht_hair_params_default();
        let bad = HtHairParams {
            beta_n: f32::NAN,
            ..p
        };
        fails(
            ht_scene_add_hair_material(h.scene, &bad, &mut id),
            INVALID,
            "beta_n",
        );
        let variation = HtHairVariation {
            absorption_variation: 2.0,
            ..ht_hair_variation_default()
        };
        fails(
            ht_scene_add_hair_material_varied(h.scene, &p, &variation, &mut id),
            INVALID,
            "absorption_variation",
        );
        let nan = [f32::NAN, 0.5, 0.5];
        fails(
            ht_scene_add_diffuse_material(h.scene, nan.as_ptr(), &mut id),
            INVALID,
            "albedo",
        );
        assert!(h.scene().materials.is_empty());

        let hair = h.hair_material();
        let diffuse = h.diffuse_material([0.8; 3]);
        let strands = small_fur();
        let desc = curves_desc(&strands);
        let add = |d: &HtCurves, m: u32| ht_scene_add_curves(h.scene, d, m, &mut 0);
        fails(add(&desc, 7), INVALID, "material_id = 7");
        fails(add(&desc, diffuse), INVALID, "diffuse material");
        fails(h.add_triangle(hair), INVALID, "hair material");
        fails(
            add(&HtCurves { basis: 4, ..desc }, hair),
            INVALID,
            "basis = 4",
        );
        fails(
            add(&HtCurves { shape: 9, ..desc }, hair),
            INVALID,
            "shape = 9",
        );
        fails(
            add(
                &HtCurves {
                    strand_count: 0,
                    ..desc
                },
                hair,
            ),
            INVALID,
            "strand_count",
        );
        fails(
            add(
                &HtCurves {
                    point_count: desc.point_count - 1,
                    ..desc
                },
                hair,
            ),
            INVALID,
            "counts add up",
        );
        let one_radius = HtCurves {
            radii: null(),
            radius: f32::NAN,
            ..desc
        };
        fails(add(&one_radius, hair), INVALID, "desc->radius = NaN");
        let mut broken = strands.clone();
        broken.points[5][1] = f32::INFINITY;
        fails(add(&curves_desc(&broken), hair), INVALID, "point 5");
        let misaligned = HtCurves {
            points: unsafe { desc.points.cast::<u8>().add(1).cast() },
            ..desc
        };
        fails(add(&misaligned, hair), INVALID, "aligned");

        let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let out_of_range = [0u32, 1, 3];
        let s = ht_scene_add_mesh(
            h.scene,
            3,
            positions.as_ptr(),
            null(),
            1,
            out_of_range.as_ptr(),
            diffuse,
            &mut id,
        );
        fails(s, INVALID, "triangle 0");
        let s = ht_scene_add_mesh(
            h.scene,
            3,
            positions.as_ptr(),
            null(),
            0,
            null(),
            diffuse,
            &mut id,
        );
        fails(s, INVALID, "at least one triangle");

        let not_utf8 = c"fur\xff.hair";
        let s = ht_scene_add_hair_file(h.scene, not_utf8.as_ptr(), false, 0, 0, hair, &mut id);
        fails(s, INVALID, "not valid UTF-8");
        let missing = c"/nonexistent/groom.hair";
        let s = ht_scene_add_hair_file(h.scene, missing.as_ptr(), false, 0, 0, hair, &mut id);
        fails(s, HtStatus::HT_ERR_IO, "/nonexistent/groom.hair");
        let s = ht_scene_add_mesh_file(h.scene, c"head.stl".as_ptr(), diffuse, &mut id);
        fails(s, INVALID, "head.stl");
        assert!(h.scene().geometries.is_empty());

        fails(
            ht_scene_add_environment(h.scene, nan.as_ptr()),
            INVALID,
            "radiance = [NaN",
        );
        let zero = [0.0f32; 3];
        let one = [1.0f32; 3];
        fails(
            ht_scene_add_distant_light(h.scene, zero.as_ptr(), one.as_ptr(), 1.0),
            INVALID,
            "direction",
        );
        fails(
            ht_scene_add_distant_light(h.scene, one.as_ptr(), one.as_ptr(), 90.0),
            INVALID,
            "angular radius",
        );
        fails(
            ht_scene_add_rect_light(
                h.scene,
                zero.as_ptr(),
                one.as_ptr(),
                one.as_ptr(),
                one.as_ptr(),
                true,
            ),
            INVALID,
            "parallel",
        );
        fails(
            ht_scene_add_environment_map(h.scene, c"/nonexistent/sky.exr".as_ptr(), 0.0, 1.0),
            HtStatus::HT_ERR_IMAGE,
            "sky.exr",
        );
        assert!(h.scene().lights.is_empty());
        let y = [0.0f32, 1.0, 0.0];
        fails(
            ht_scene_set_camera(h.scene, one.as_ptr(), zero.as_ptr(), y.as_ptr(), 0.0),
            INVALID,
            "fov",
        );
        fails(
            ht_scene_set_camera(h.scene, zero.as_ptr(), zero.as_ptr(), y.as_ptr(), 40.0),
            INVALID,
            "distinct",
        );
        assert!(h.scene().camera.is_none());
    }

    #[test]
    fn geometry_from_buffers_and_files_gets_consecutive_ids() {
        let h = Handles::new();
        let hair = h.hair_material();
        let diffuse = h.diffuse_material([0.5; 3]);
        let strands = small_fur();
        let mut id = u32::MAX;
        let desc = curves_desc(&strands);
        assert_eq!(
            ht_scene_add_curves(h.scene, &desc, hair, &mut id),
            HtStatus::HT_OK
        );
        assert_eq!(id, 0);

        // Two B-spline strands of 4 and 5 control points: 1 and 2 segments, 2 and 3
        // segment ends with a colour each.
        let xyzr: Vec<[f32; 4]> = (0..9).map(|i| [i as f32, 0.0, 0.0, 0.1]).collect();
        let counts = [4u32, 5];
        let colors = [[0.5f32; 3]; 5];
        let mut xyzr_desc = HtCurvesXyzr {
            strand_count: 2,
            point_counts: counts.as_ptr(),
            point_count: 9,
            points: xyzr.as_ptr().cast(),
            colors: colors.as_ptr().cast(),
            basis: HT_CURVE_BSPLINE,
            shape: HT_CURVE_FLAT,
        };
        let s = ht_scene_add_curves_xyzr(h.scene, &xyzr_desc, hair, &mut id);
        assert_eq!((s, id), (HtStatus::HT_OK, 1), "{}", last_error());
        let Shape::Curves(c) = &h.scene().geometries[1].shape else {
            panic!("curves expected");
        };
        assert_eq!((c.vertices(), c.indices()), (&xyzr[..], &[0u32, 4, 5][..]));
        assert_eq!(
            c.strands().color(&c.strands().locate(2).unwrap(), 1.0),
            Some([0.5; 3])
        );
        xyzr_desc.basis = HT_CURVE_BEZIER;
        fails(
            ht_scene_add_curves_xyzr(h.scene, &xyzr_desc, hair, &mut id),
            HtStatus::HT_ERR_INVALID_ARG,
            "point_counts[1] = 5",
        );

        let dir = std::env::temp_dir().join(format!("ht-capi-scene-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("fur.hair");
        write_hair_file(&file, &strands, Thickness::Radius).unwrap();
        let path = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
        let s = ht_scene_add_hair_file(
            h.scene,
            path.as_ptr(),
            true,
            HT_CURVE_LINEAR,
            HT_CURVE_ROUND,
            hair,
            &mut id,
        );
        assert_eq!((s, id), (HtStatus::HT_OK, 2), "{}", last_error());
        let obj = dir.join("tri.obj");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let path = std::ffi::CString::new(obj.to_str().unwrap()).unwrap();
        let s = ht_scene_add_mesh_file(h.scene, path.as_ptr(), diffuse, &mut id);
        assert_eq!((s, id), (HtStatus::HT_OK, 3), "{}", last_error());
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(h.add_triangle(diffuse), HtStatus::HT_OK);
        assert_eq!(h.scene().geometries.len(), 5);
    }

    #[test]
    fn shared_xyzr_points_are_checked_then_read_in_place() {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let h = Handles::new();
        let hair = h.hair_material();
        let strands = small_fur();
        let points = xyzr(&strands);
        // The host's points start 4 bytes into its array: aligned for floats, not to 16.
        let mut host = vec![0.0f32; 4 * points.len() + 1];
        host[1..].copy_from_slice(points.as_flattened());
        let desc = HtCurvesXyzr {
            points: host[1..].as_ptr(),
            ..xyzr_desc(&points, &strands.counts)
        };
        assert_ne!(desc.points as usize % 16, 0);
        let add = |d: &HtCurvesXyzr| ht_scene_add_curves_xyzr_shared(h.scene, d, hair, &mut 0);
        let s = ht_scene_add_curves_xyzr_shared(h.scene, null(), hair, &mut 0);
        fails(s, NULL, "desc is NULL");
        let no_points = HtCurvesXyzr {
            points: null(),
            ..desc
        };
        fails(add(&no_points), NULL, "desc->points is NULL");
        let misaligned = HtCurvesXyzr {
            points: unsafe { desc.points.cast::<u8>().add(2).cast() },
            ..desc
        };
        fails(add(&misaligned), INVALID, "not aligned to 4 bytes");
        let short = HtCurvesXyzr {
            point_count: desc.point_count - 1,
            ..desc
        };
        fails(add(&short), INVALID, "counts add up");
        assert!(h.scene().geometries.is_empty());

        assert_eq!(add(&desc), HtStatus::HT_OK, "{}", last_error());
        let Shape::Curves(c) = &h.scene().geometries[0].shape else {
            panic!("curves expected");
        };
        assert_eq!(c.vertices().as_ptr().cast(), desc.points);
        assert_eq!(c.vertices(), &points[..]);
        // Only the index buffer and the strand table are the scene's.
        let indices = (strands.segment_count() + padding_for::<u32>()) * 4;
        assert_eq!(c.heap_bytes(), indices + c.strands().heap_bytes());
    }

    /// Bytes hairtrace holds for a scene of curves: what it keeps to rebuild, and the built
    /// tracer.
    fn held_bytes(scene: &HtScene) -> usize {
        let kept: usize = (scene.geometries.iter())
            .map(|g| match &g.shape {
                Shape::Curves(c) => c.heap_bytes(),
                Shape::Mesh(_) => unreachable!("curves only"),
            })
            .sum();
        kept + scene.world.as_ref().map_or(0, |w| w.tracer.heap_bytes())
    }

    /// Memory of a built groom through each entry point: sharing saves the scene's copy of
    /// the control points and the tracer's, and Embree copies them in neither case.
    /// `--nocapture` prints bytes per segment.
    #[test]
    fn shared_xyzr_points_cost_neither_hairtrace_nor_embree_memory() {
        const STRANDS: usize = 10_000;
        let strands = FurBall {
            strands: STRANDS,
            segments: 16,
            ..FurBall::default()
        }
        .build()
        .unwrap();
        let points = xyzr(&strands);
        let desc = xyzr_desc(&points, &strands.counts);
        let [copied, shared] =
            [ht_scene_add_curves_xyzr, ht_scene_add_curves_xyzr_shared].map(|add| {
                let h = Handles::new();
                let monitor = MemoryMonitor::attach(h.scene().device.clone());
                let hair = h.hair_material();
                assert_eq!(add(h.scene, &desc, hair, &mut 0), HtStatus::HT_OK);
                let sky = [0.5f32; 3];
                assert_eq!(
                    ht_scene_add_environment(h.scene, sky.as_ptr()),
                    HtStatus::HT_OK
                );
                scene_mut(h.scene).ok().unwrap().prepare(1.0).unwrap();
                (held_bytes(h.scene()), monitor.current() as usize)
            });
        let segments = strands.segment_count() as f64;
        let per_segment = |(ours, embree): (usize, usize)| {
            let (o, e) = (ours as f64 / segments, embree as f64 / segments);
            format!("ours {o:.1} + Embree {e:.1} = {:.1} B/segment", o + e)
        };
        println!("{STRANDS} strands x 16 linear round segments");
        println!("copied: {}", per_segment(copied));
        println!("shared: {}", per_segment(shared));
        let vertex_bytes = (points.len() + padding_for::<[f32; 4]>()) * 16;
        assert_eq!(copied.0 - shared.0, 2 * vertex_bytes);
        // Embree's total varies by a few percent from build to build (its per-thread
        // allocation blocks), far less than a copy of the points would add.
        let embree = copied.1.abs_diff(shared.1);
        assert!(
            embree < vertex_bytes / 4,
            "Embree: {} vs {} bytes",
            copied.1,
            shared.1
        );
    }
}
