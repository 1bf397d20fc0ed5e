//! Devices and scenes through the C ABI: materials, curves and meshes from host buffers or
//! files, lights and the camera, added one call at a time.
//!
//! `HtScene` is a shell over the library's [`Scene`], which keeps the geometry, decides
//! when to build and edits its build: the shell turns C ids into the scene's names
//! (material `id` is named by its number, geometry ids only count what was added).

use super::{Failure, HtStatus, boundary, free_handle, non_null_mut, read_path, read_vec3};
use crate::Scene;
use crate::description::{CameraDesc, MaterialDesc, PoseDesc};
use crate::embree::{Device, Isa};
use crate::error::{Result, invalid_arg};
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
    pub(super) scene: Scene,
    /// Material ids handed out: id `i` is the scene's material named `i`.
    pub(super) materials: u32,
    /// Geometry ids handed out (a USD stage takes one per prim).
    pub(super) geometries: u32,
}

impl HtScene {
    /// The scene's name of material `id`.
    pub(super) fn material_name(id: u32) -> String {
        id.to_string()
    }

    /// The material `id` for a geometry; hair goes on curves, diffuse on meshes.
    pub(super) fn check_material(&self, id: u32, on_curves: bool) -> Result<String> {
        let what = format!("material_id = {id}");
        if id >= self.materials {
            return Err(invalid_arg!(
                "{what}: the scene has {} materials",
                self.materials
            ));
        }
        let name = Self::material_name(id);
        let material = self
            .scene
            .material(&name)
            .expect("every id below the count");
        material.check_suits(&what, on_curves)?;
        Ok(name)
    }

    /// A new geometry's name, and the id of its first Embree geometry; `count` ids are
    /// taken once it is added ([`Self::added`]).
    pub(super) fn next_geometry(&self) -> (String, u32) {
        (format!("geometry[{}]", self.geometries), self.geometries)
    }

    /// Takes `count` geometry ids.
    pub(super) fn added(&mut self, count: usize) -> Result<()> {
        self.geometries = u32::try_from(count)
            .ok()
            .and_then(|n| self.geometries.checked_add(n))
            .ok_or_else(|| invalid_arg!("too many geometries"))?;
        Ok(())
    }

    /// Gives material `id` new parameters, of the same kind (hair or diffuse), without a
    /// new build.
    pub(super) fn set_material(&mut self, id: u32, material: &MaterialDesc) -> Result<()> {
        let what = format!("material_id = {id}");
        let name = Self::material_name(id);
        let old = (self.scene.material(&name))
            .ok_or_else(|| invalid_arg!("{what}: the scene has {} materials", self.materials))?;
        if std::mem::discriminant(old) != std::mem::discriminant(material) {
            let kind = if matches!(old, MaterialDesc::Hair(_)) {
                "hair"
            } else {
                "diffuse"
            };
            return Err(invalid_arg!(
                "{what} is a {kind} material, and a material keeps its kind: add a new one"
            ));
        }
        self.scene.set_material(&name, material)
    }

    /// Adds a material and returns its id.
    pub(super) fn add_material(&mut self, material: &MaterialDesc) -> Result<u32> {
        let id = self.materials;
        let next = id
            .checked_add(1)
            .ok_or_else(|| invalid_arg!("too many materials"))?;
        self.scene
            .set_material(&Self::material_name(id), material)?;
        self.materials = next;
        Ok(id)
    }

    /// Refuses a render that has nothing to frame, in the C ABI's words.
    pub(super) fn check_framed(&self) -> Result<()> {
        match self.scene.camera().eye.is_none() && self.geometries == 0 {
            true => Err(invalid_arg!(
                "the scene has no geometry to frame: set a camera with ht_scene_set_camera"
            )),
            false => Ok(()),
        }
    }
}

#[cfg(test)]
impl HtScene {
    /// Builds where needed for `settings`; the world and the camera of such a render.
    pub(crate) fn prepare(
        &mut self,
        settings: &crate::render::settings::RenderSettings,
        progress: &dyn crate::scene::StageProgress,
    ) -> Result<(&crate::render::integrator::World, crate::scene::Camera)> {
        self.check_framed()?;
        self.scene.build_for(settings, progress)?;
        let camera = self.scene.placed_camera(settings)?;
        Ok((self.scene.world().expect("built"), camera))
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
            scene: Scene::new(device.device.clone()),
            materials: 0,
            geometries: 0,
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
/// `(target - eye) x up`. Replaces any earlier camera, its motion too (the camera is
/// still until `ht_scene_set_camera_motion`), without a new build unless
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
    place_camera(scene, [eye, target, up], |camera, [eye, target, up]| {
        Ok(CameraDesc {
            eye: Some(eye),
            target: Some(target),
            up,
            fov_deg: fov_y_deg,
            shutter_close: None,
            ..camera.clone()
        })
    })
}

/// Reads a host's `eye`, `target` and `up` (each `float[3]`, named in errors) and sets the
/// scene's camera to what `place` makes of its camera with them.
fn place_camera(
    scene: *mut HtScene,
    [eye, target, up]: [*const f32; 3],
    place: impl FnOnce(&CameraDesc, [[f32; 3]; 3]) -> Result<CameraDesc>,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        let pose = [
            read_vec3(eye, "eye")?.to_array(),
            read_vec3(target, "target")?.to_array(),
            read_vec3(up, "up")?.to_array(),
        ];
        let camera = place(scene.scene.camera(), pose)?;
        Ok(scene.scene.set_camera(&camera)?)
    })
}

/// Moves the camera of `ht_scene_set_camera` over the shutter: `eye`, `target`, `up` and
/// `fov_y_deg` (as there) are its pose where the shutter closes, the one set there its
/// pose where it opens. A render with the shutter open (`shutter_open` < `shutter_close`)
/// takes each ray's pose at the ray's time: the eye and the image plane blended, the view
/// turned at a constant rate between the two (docs/architecture.md, "Motion"); with it
/// closed the camera stays where it opens. The thin lens of `ht_scene_set_thin_lens`
/// holds at both. Replaces any earlier closing pose; `ht_scene_set_camera` removes it.
/// `HT_CURVE_AUTO` curves seen by a moving camera keep their full detail (round).
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `eye`, `target` or `up` NULL);
/// `HT_ERR_INVALID_ARG` (a value out of range as for `ht_scene_set_camera`, or no camera
/// set with it: a framed camera does not move). On failure the camera is unchanged.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `eye`, `target` and
/// `up` are NULL or point to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_set_camera_motion(
    scene: *mut HtScene,
    eye: *const f32,
    target: *const f32,
    up: *const f32,
    fov_y_deg: f32,
) -> HtStatus {
    place_camera(scene, [eye, target, up], |camera, [eye, target, up]| {
        if camera.eye.is_none() {
            return Err(invalid_arg!(
                "no camera to move: set its pose at the shutter's opening with \
                 ht_scene_set_camera first"
            ));
        }
        let close = PoseDesc {
            eye: Some(eye),
            target: Some(target),
            up: Some(up),
            fov_deg: Some(fov_y_deg),
        };
        Ok(CameraDesc {
            shutter_close: Some(close),
            ..camera.clone()
        })
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
        let camera = CameraDesc {
            aperture_radius,
            focus_distance: Some(focus_distance),
            ..scene.scene.camera().clone()
        };
        Ok(scene.scene.set_camera(&camera)?)
    })
}
