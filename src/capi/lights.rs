//! Lights through the C ABI: uniform or mapped environments, distant and rect lights.

use super::scene::{HtScene, scene_mut};
use super::{Failure, HtStatus, boundary, read_path, read_vec3};
use crate::description::{EnvironmentSource, LightDesc};
use std::ffi::c_char;

/// Adds a light to the scene (files read now); `light` runs inside the boundary.
fn add_light(
    scene: *mut HtScene,
    light: impl FnOnce() -> std::result::Result<LightDesc, Failure>,
) -> HtStatus {
    boundary(|| {
        let scene = scene_mut(scene)?;
        scene.scene.add_light(&light()?)?;
        Ok(())
    })
}

/// Adds an environment of the same linear RGB `radiance` (finite, >= 0) from every
/// direction.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `radiance` NULL); `HT_ERR_INVALID_ARG` (a NaN,
/// infinite or negative channel, a misaligned array). Nothing is added on failure.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; every `float[3]` argument
/// is NULL or points to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_environment(
    scene: *mut HtScene,
    radiance: *const f32,
) -> HtStatus {
    add_light(scene, || {
        Ok(LightDesc::Environment {
            source: EnvironmentSource::Uniform(read_vec3(radiance, "radiance")?.to_array()),
            rotation_deg: 0.0,
            scale: 1.0,
        })
    })
}

/// Adds a lat-long environment map read through OpenImageIO (EXR, HDR, ...: linear
/// radiance), turned by `rotation_deg` about +y and its radiance multiplied by `scale`
/// (finite, >= 0). It is importance sampled. The file is read during the call.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `path` NULL); `HT_ERR_IO` (the file is missing
/// or unreadable); `HT_ERR_IMAGE` (OpenImageIO cannot decode it); `HT_ERR_INVALID_ARG`
/// (an empty or non-UTF-8 path, NaN or negative pixels, a rotation or scale out of range).
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; `path` is NULL or a
/// NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_environment_map(
    scene: *mut HtScene,
    path: *const c_char,
    rotation_deg: f32,
    scale: f32,
) -> HtStatus {
    add_light(scene, || {
        Ok(LightDesc::Environment {
            source: EnvironmentSource::Map(read_path(path, "path")?),
            rotation_deg,
            scale,
        })
    })
}

/// Adds a light at infinity: `direction` (world frame) points toward it (any finite,
/// non-zero length), it delivers linear RGB `irradiance` (finite, >= 0) to a surface
/// facing it, and is seen as a disc of `angular_radius_deg` degrees in [0, 90) (0: a
/// point, with hard shadows).
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `direction` or `irradiance` NULL);
/// `HT_ERR_INVALID_ARG` (a zero or non-finite direction, a NaN, infinite or negative
/// value, an angle out of range, a misaligned array). Nothing is added on failure.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; every `float[3]` argument
/// is NULL or points to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_distant_light(
    scene: *mut HtScene,
    direction: *const f32,
    irradiance: *const f32,
    angular_radius_deg: f32,
) -> HtStatus {
    add_light(scene, || {
        Ok(LightDesc::Distant {
            direction: read_vec3(direction, "direction")?.to_array(),
            irradiance: read_vec3(irradiance, "irradiance")?.to_array(),
            angular_radius_deg,
        })
    })
}

/// Adds a parallelogram light with corners `corner`, `corner + edge_u`, `corner + edge_v`
/// and `corner + edge_u + edge_v`, emitting linear RGB `radiance` (>= 0) toward
/// `edge_u x edge_v`, or to both sides if `two_sided`. World units; every coordinate
/// finite and within +-1e15.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or an array NULL); `HT_ERR_INVALID_ARG` (a NaN,
/// infinite, negative or out-of-range value, edges zero or parallel, a misaligned array).
/// Nothing is added on failure.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread; every `float[3]` argument
/// is NULL or points to 3 readable floats.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_add_rect_light(
    scene: *mut HtScene,
    corner: *const f32,
    edge_u: *const f32,
    edge_v: *const f32,
    radiance: *const f32,
    two_sided: bool,
) -> HtStatus {
    add_light(scene, || {
        Ok(LightDesc::Rect {
            corner: read_vec3(corner, "corner")?.to_array(),
            edge_u: read_vec3(edge_u, "edge_u")?.to_array(),
            edge_v: read_vec3(edge_v, "edge_v")?.to_array(),
            radiance: read_vec3(radiance, "radiance")?.to_array(),
            two_sided,
        })
    })
}
