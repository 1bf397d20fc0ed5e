//! Devices and scenes through the C ABI: materials, curves and meshes from host buffers or
//! files, lights and the camera, added one call at a time.
//!
//! The scene keeps what the host added (curves already converted for Embree) and builds
//! the Embree scene on the first render, by the same assembly as scene files
//! (`description::assembly`), then reuses it: adding geometry rebuilds it on
//! the next render; adding a light, changing a material's parameters and a camera for
//! which the `auto` curves' shapes still hold keep it.

use super::{Failure, HtStatus, boundary, non_null_mut, read_path, read_vec3};
use crate::description::assembly::{Assembly, Shape};
use crate::embree::{CurveBasis, Device, Isa};
use crate::error::{Result, invalid_arg};
use crate::render::integrator::World;
use crate::render::settings::{CurveParts, RenderSettings};
use crate::scene::Strands;
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;
use crate::scene::detail_view::DetailView;
use crate::scene::framing::Framing;
use crate::scene::light::Light;
use crate::scene::material::Material;
use crate::scene::ribbons::GroomShape;
use crate::scene::stages::{StageProgress, StageRunner};
use crate::validate::{length, non_negative, positive};
use std::ffi::c_char;
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
/// later additions. Its first build (`ht_scene_build_with` or the first render) puts the
/// scene's curves in spatial order and shares their control points with Embree's
/// buffers, so a built scene holds one copy of them plus the BVH (an `auto` groom's
/// level-of-detail ribbons and round/flat shares are copies of their own), and a rebuild
/// neither sorts nor copies them again, nor cuts a large groom into parts again. Control
/// points added with `ht_scene_add_curves_xyzr_shared` are never copied. For the largest
/// grooms, share them (or add everything before the first render) and free the scene
/// when done.
pub struct HtScene {
    pub(super) device: Arc<Device>,
    pub(super) materials: Vec<Material>,
    pub(super) geometries: Vec<Geometry>,
    pub(super) lights: Vec<Light>,
    pub(super) camera: Option<Camera>,
    /// Aperture radius and focus distance of a thin lens, validated; kept apart from the
    /// camera so that either may be set first, and the framing camera gets it too.
    pub(super) lens: Option<(f32, f32)>,
    /// What a render without a camera frames, grown as geometry is added.
    pub(super) framing: Framing,
    /// The last build; None until the first render and after geometry is added.
    pub(super) world: Option<World>,
    /// The index in `geometries` of each Embree geometry of `world` (`auto` curves may
    /// make several).
    pub(super) built_from: Vec<usize>,
    /// Lights were added since `world` was built.
    pub(super) lights_changed: bool,
    /// The `curve_parts` setting `world` was built with: a render asking another builds
    /// again.
    pub(super) built_parts: CurveParts,
}

pub(super) struct Geometry {
    pub(super) shape: Shape,
    pub(super) material: u32,
}

impl HtScene {
    /// The material `id` for a geometry; hair goes on curves, diffuse on meshes.
    pub(super) fn check_material(&self, id: u32, on_curves: bool) -> Result<()> {
        self.material(id)?
            .check_suits(&format!("material_id = {id}"), on_curves)
    }

    fn material(&self, id: u32) -> Result<&Material> {
        self.materials.get(id as usize).ok_or_else(|| {
            invalid_arg!(
                "material_id = {id}: the scene has {} materials",
                self.materials.len()
            )
        })
    }

    /// Adds polyline strands converted for `basis` and `shape`, framed by their points.
    pub(super) fn add_strands(
        &mut self,
        strands: &Strands,
        basis: CurveBasis,
        shape: GroomShape,
        material: u32,
    ) -> Result<u32> {
        let curves = Curves::from_strands(strands, basis, shape.built())?;
        self.add_geometry(Shape::curves(curves, shape), material, |f| {
            f.add_strands(strands)
        })
    }

    /// Adds a geometry; the next render builds again. A mesh is framed by its vertices,
    /// curves by what `frame_curves` adds from the points the host gave (`Framing`). The
    /// scene keeps the curves [shared](Shape::shared), so that a build's copy costs none.
    pub(super) fn add_geometry(
        &mut self,
        shape: Shape,
        material: u32,
        frame_curves: impl FnOnce(&mut Framing),
    ) -> Result<u32> {
        let id = u32::try_from(self.geometries.len())
            .map_err(|_| invalid_arg!("too many geometries"))?;
        match &shape {
            Shape::Mesh(m) => self.framing.add_mesh(&m.positions),
            Shape::Curves(_) | Shape::AutoCurves(_) => frame_curves(&mut self.framing),
        }
        self.geometries.push(Geometry {
            shape: shape.shared(),
            material,
        });
        self.world = None;
        Ok(id)
    }

    /// Gives material `id` new parameters, of the same kind (hair or diffuse), without a
    /// new build: the built world's geometries that use it take it at once.
    pub(super) fn set_material(&mut self, id: u32, material: Material) -> Result<()> {
        let what = format!("material_id = {id}");
        let old = self.material(id)?;
        if std::mem::discriminant(old) != std::mem::discriminant(&material) {
            let kind = if matches!(old, Material::Hair(_)) {
                "hair"
            } else {
                "diffuse"
            };
            return Err(invalid_arg!(
                "{what} is a {kind} material, and a material keeps its kind: add a new one"
            ));
        }
        if let Some(world) = &mut self.world {
            for (embree_id, &g) in self.built_from.iter().enumerate() {
                if self.geometries[g].material == id {
                    world.set_material(embree_id as u32, material.clone())?;
                }
            }
        }
        self.materials[id as usize] = material;
        Ok(())
    }

    /// The host's camera, or the one that frames the geometry as added, for an image of
    /// `aspect` (width over height), with the host's lens.
    fn camera(&self, aspect: f32) -> Result<Camera> {
        let camera = match self.camera {
            Some(c) => c.with_aspect(aspect)?,
            None => self
                .framing
                .camera(aspect, Camera::DEFAULT_FOV_Y_DEG)
                .ok_or_else(|| {
                    invalid_arg!(
                        "the scene has no geometry to frame: set a camera with \
                         ht_scene_set_camera"
                    )
                })??,
        };
        match self.lens {
            Some((aperture_radius, focus_distance)) => {
                camera.with_thin_lens(aperture_radius, focus_distance)
            }
            None => Ok(camera),
        }
    }

    /// The world to render, built or updated as needed (the BVH build reporting to
    /// `progress`), and the camera for an image of `width` x `height` pixels. One build
    /// at most: the automatic camera is framed without one. A build is kept while nothing
    /// was added, the view still suits its `auto` curves' shapes (`Tracer::serves`) and
    /// `curve_parts` is unchanged; new lights are weighed again on it.
    pub(crate) fn prepare(
        &mut self,
        settings: &RenderSettings,
        progress: &dyn StageProgress,
    ) -> Result<(&World, Camera)> {
        let (width, height) = (settings.width, settings.height);
        if self.lights.is_empty() {
            return Err(invalid_arg!(
                "the scene has no light: add an environment, distant or rect light"
            ));
        }
        // A C host's device is its own (`ht_device_new_pinned`): a render cannot re-pin it.
        if let Some(isa) = settings.isa.filter(|&isa| Some(isa) != self.device.isa()) {
            return Err(invalid_arg!(
                "isa = {isa}: this scene's device runs {}; pin the device with \
                 ht_device_new_pinned(threads, \"{isa}\", ...) instead",
                self.device
                    .isa()
                    .map_or("the widest kernels this CPU runs".into(), |d| {
                        format!("{d} kernels")
                    })
            ));
        }
        let camera = self.camera(width as f32 / height as f32)?;
        let view = DetailView::new(camera, height, settings.lod_pixels);
        if (self.world.as_ref())
            .is_some_and(|w| !w.tracer.serves(&view) || self.built_parts != settings.curve_parts)
        {
            self.world = None;
        }
        match &mut self.world {
            Some(world) if self.lights_changed => world.set_lights(self.lights.clone())?,
            Some(_) => {}
            None => {
                let mut assembly = Assembly::keeping_curves();
                for g in &self.geometries {
                    let material = self.materials[g.material as usize].clone();
                    assembly.add(g.shape.clone(), material, "");
                }
                let built = assembly.build(
                    self.device.clone(),
                    self.lights.clone(),
                    &view,
                    settings,
                    &mut StageRunner::new(progress),
                )?;
                for (g, kept) in self.geometries.iter_mut().zip(built.curves) {
                    if let Some(curves) = kept {
                        g.shape.keep(curves);
                    }
                }
                self.world = Some(built.world);
                self.built_from = built.built_from;
                self.built_parts = settings.curve_parts;
            }
        }
        self.lights_changed = false;
        Ok((self.world.as_ref().expect("built above"), camera))
    }
}

/// The scene behind a handle.
pub(crate) fn scene_mut<'a>(scene: *mut HtScene) -> std::result::Result<&'a mut HtScene, Failure> {
    // SAFETY: non-NULL (checked); the host passes a live handle from ht_scene_new and no
    // other call uses it at the same time (documented on HtScene).
    Ok(unsafe { &mut *non_null_mut(scene, "scene")? })
}

/// Runs `add` on the scene and writes the id it returns to `out` (checked first).
pub(super) fn add_with_id(
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

/// Drops a boxed handle; NULL is nothing to free.
fn free_handle<T>(handle: *mut T) {
    if !handle.is_null() {
        // SAFETY: a handle from the matching ht_*_new, freed once (the host's promise).
        drop(unsafe { Box::from_raw(handle) });
    }
}

/// Creates a device with `threads` Embree worker threads (0: one per hardware thread),
/// which build the scenes made on it, and writes the handle to `*out`. Free it with
/// `ht_device_free`; scenes keep it alive as long as they need it. Thread safe.
///
/// Statuses: `HT_ERR_NULL_ARG` (`out` NULL); `HT_ERR_INVALID_ARG` (`out` misaligned);
/// `HT_ERR_EMBREE` (Embree could not start). `*out` is written on `HT_OK` only.
///
/// # Safety
/// `out` is NULL or points to a writable `HtDevice*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_device_new(threads: u32, out: *mut *mut HtDevice) -> HtStatus {
    // SAFETY: NULL is a valid `isa`; `out` is passed on under the caller's promise.
    unsafe { ht_device_new_pinned(threads, std::ptr::null(), out) }
}

/// As `ht_device_new`, with Embree's kernels pinned to the instruction set named by `isa`
/// ("sse2", "avx", "avx2" or "avx512"; NULL: not pinned, the widest this CPU runs).
/// Embree's kernels for different instruction sets round differently, so a frame whose
/// crop pieces render on different CPUs assembles bit for bit only when every piece pins
/// the same ISA. The device's pin is what its scenes render with: a build or render whose
/// settings name another `isa` is refused.
///
/// Statuses: those of `ht_device_new`, and `HT_ERR_INVALID_ARG` for another name or an
/// ISA this CPU cannot run.
///
/// Any thread: a device is thread safe.
///
/// # Safety
/// `isa` is NULL or a NUL-terminated string; `out` is NULL or points to a writable
/// `HtDevice*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_device_new_pinned(
    threads: u32,
    isa: *const c_char,
    out: *mut *mut HtDevice,
) -> HtStatus {
    boundary(|| {
        let out = non_null_mut(out, "out")?;
        let isa = if isa.is_null() {
            None
        } else {
            Some(Isa::named(&read_path(isa, "isa")?.to_string_lossy())?)
        };
        let threads = (threads > 0).then_some(threads as usize);
        let device = Arc::new(Device::pinned(threads, isa)?);
        super::shutdown::track(&device);
        let handle = Box::new(HtDevice { device });
        // SAFETY: non-NULL (checked), the host's HtDevice*.
        unsafe { out.write(Box::into_raw(handle)) };
        Ok(())
    })
}

/// Releases a device handle (NULL: nothing to do, `HT_OK`). Scenes made on it stay valid
/// and release the device with the last of them. Always `HT_OK`.
///
/// Any thread, once no other thread uses this handle (scenes may still hold the device).
///
/// # Safety
/// `device` is NULL or a handle from `ht_device_new` not yet freed; it is invalid after
/// the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_device_free(device: *mut HtDevice) -> HtStatus {
    boundary(|| {
        free_handle(device);
        Ok(())
    })
}

/// Creates an empty scene on `device` and writes the handle to `*out`. Free it with
/// `ht_scene_free`. The device handle may be freed before the scene.
///
/// Statuses: `HT_ERR_NULL_ARG` (`device` or `out` NULL); `HT_ERR_INVALID_ARG` (`out`
/// misaligned). `*out` is written on `HT_OK` only.
///
/// Any thread: the device may be shared; the new scene is used from one thread at a time.
///
/// # Safety
/// `device` is NULL or a live handle from `ht_device_new`; `out` is NULL or points to a
/// writable `HtScene*`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_new(device: *const HtDevice, out: *mut *mut HtScene) -> HtStatus {
    boundary(|| {
        // SAFETY: non-NULL and aligned (checked), a live handle from ht_device_new.
        let device = unsafe { &*non_null_mut(device.cast_mut(), "device")? };
        let out = non_null_mut(out, "out")?;
        let scene = Box::new(HtScene {
            device: device.device.clone(),
            materials: Vec::new(),
            geometries: Vec::new(),
            lights: Vec::new(),
            camera: None,
            lens: None,
            framing: Framing::default(),
            world: None,
            built_from: Vec::new(),
            built_parts: CurveParts::Auto,
            lights_changed: false,
        });
        // SAFETY: non-NULL (checked), the host's HtScene*.
        unsafe { out.write(Box::into_raw(scene)) };
        Ok(())
    })
}

/// Releases a scene and everything it holds, the Embree scene included (NULL: nothing to
/// do). After it returns, the host may free the points it shared with
/// `ht_scene_add_curves_xyzr_shared`. Always `HT_OK`.
///
/// # Safety
/// `scene` is NULL or a handle from `ht_scene_new` not yet freed and not in use on another
/// thread; it is invalid after the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_free(scene: *mut HtScene) -> HtStatus {
    boundary(|| {
        free_handle(scene);
        Ok(())
    })
}

/// Places the pinhole camera at `eye` looking at `target` (world units, each `float[3]`,
/// every coordinate finite and within +-1e15: Embree cannot trace rays beyond that), `up`
/// giving the image's upward direction (finite, not zero, not parallel to the view), with
/// a vertical field of view of `fov_y_deg` degrees in (0, 180). The image's x runs along
/// `(target - eye) x up`. Replaces any earlier camera, without a new build unless
/// `HT_CURVE_AUTO` curves need other shapes for it. Without one, renders frame the
/// geometry as added (the hair's points widened by their radii, else the meshes) from the
/// front (+z), a little to the right and above, as a scene file without a camera does.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `eye`, `target` or `up` NULL);
/// `HT_ERR_INVALID_ARG` (a value out of range, `eye == target`, `up` along the view, a
/// misaligned array). On failure the camera is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `eye`, `target` and
/// `up` are NULL or point to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_camera(
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
/// units, in [0, 1e15]; 0 is the pinhole again) focused at `focus_distance` (world units
/// along the view direction, in (0, 1e15]), so that what lies nearer or farther blurs.
/// Holds for the camera of `ht_scene_set_camera`, whether set before or after, and for the
/// camera that frames a scene without one. Replaces any earlier lens.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` NULL); `HT_ERR_INVALID_ARG` (NaN, infinite or out
/// of range). On failure the lens is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_thin_lens(
    scene: *mut HtScene,
    aperture_radius: f32,
    focus_distance: f32,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        // Checked here, with the C names, rather than at the next render.
        non_negative("aperture_radius", aperture_radius)?;
        positive("focus_distance", focus_distance)?;
        length("aperture_radius", aperture_radius)?;
        length("focus_distance", focus_distance)?;
        scene.lens = Some((aperture_radius, focus_distance));
        Ok(())
    })
}
