//! Rendering a scene into the host's buffer, and writing images, through the C ABI.

use super::scene::{HtScene, scene_mut};
use super::settings::{HtSettings, read_settings};
use super::{
    Failure, HtStatus, Span, boundary, check_disjoint, host_slice, host_slice_mut, non_null,
    non_null_mut, read_path,
};
use crate::error::invalid_arg;
use crate::image::{WriteOptions, write_image};
use crate::render::settings::RenderSettings;
use crate::render::{Aovs, NoProgress, Progress, RenderStatus};
use crate::scene::{NoStages, Stage, StageProgress};
use std::cell::Cell;
use std::ffi::{c_char, c_void};
use std::sync::atomic::{AtomicU32, Ordering};

/// Told how far a render has got: `done` of `total` pixels, counted over the render's
/// passes of 8 spp (`total` is the pixels times the passes `spp` allows; a render that a
/// noise target or a time budget stops ends below it), `done` never decreasing from call to
/// call. A render with a callback goes in rounds of 1, 1, 2, 4... passes (fewer where a
/// noise target or a time budget stops it). It is called when a 16 x 16 tile finishes a
/// round and, while pixels take long (many samples), also every 20 ms or so of work with an
/// unchanged `done`, so that it can cancel any render promptly. Return false to cancel: no
/// new sample starts, the round of unfinished tiles is dropped (their pixels keep the
/// rounds they finished), and `ht_render_with` returns `HT_ERR_CANCELLED`.
///
/// Called from the render's worker threads (not necessarily the one that called
/// `ht_render_with`), but never two calls at once, so `user` needs no locking against itself.
/// Inside it, `ht_progress_noise()` tells the render's estimated noise so far. The
/// callback must return normally: a C++ exception or a longjmp out of it is undefined
/// behaviour (catch inside and return false instead).
pub type HtProgressFn =
    Option<unsafe extern "C" fn(done: u64, total: u64, user: *mut c_void) -> bool>;

/// The host's callback as a [`Progress`] sink.
struct HostProgress {
    callback: unsafe extern "C" fn(u64, u64, *mut c_void) -> bool,
    user: *mut c_void,
    /// The estimated noise after the last pass, as f32 bits; [`NO_NOISE`] before one.
    noise: AtomicU32,
}

/// What [`ht_progress_noise`] returns without an estimate.
const NO_NOISE: f32 = -1.0;

thread_local! {
    /// The noise of the render whose progress callback this thread is running, while it
    /// runs it: [`ht_progress_noise`]'s answer.
    static CALLBACK_NOISE: Cell<f32> = const { Cell::new(NO_NOISE) };
}

/// The estimated noise of the render whose progress callback calls this (the RMSE of its
/// pixels relative to the image's mean, as `noise_target` measures it) after its last
/// finished pass. -1 outside a progress callback, and inside one before the render has an
/// estimate: until two passes have finished, or always for a render with neither a
/// `noise_target` nor a `time_budget` (which estimates no noise).
#[unsafe(no_mangle)]
pub extern "C" fn ht_progress_noise() -> f32 {
    CALLBACK_NOISE.with(Cell::get)
}

// SAFETY: the renderer never calls `update` from two threads at once (the Progress
// contract), and `user` is only handed back to the host's callback in those calls, as
// HtProgressFn documents.
unsafe impl Sync for HostProgress {}

impl Progress for HostProgress {
    fn update(&self, done: u64, total: u64) -> bool {
        let noise = f32::from_bits(self.noise.load(Ordering::Relaxed));
        let before = CALLBACK_NOISE.replace(noise);
        // SAFETY: the host's function pointer and its own user pointer.
        let going_on = unsafe { (self.callback)(done, total, self.user) };
        CALLBACK_NOISE.set(before);
        going_on
    }

    fn pass(&self, _samples_per_pixel: u32, noise: Option<f32>) {
        let noise = noise.unwrap_or(NO_NOISE);
        self.noise.store(noise.to_bits(), Ordering::Relaxed);
    }

    /// A cancelled render leaves the passes each pixel finished, as `HtProgressFn` says.
    fn keeps_passes(&self) -> bool {
        true
    }
}

/// Told how far the build of a scene's BVH has got: `fraction` in [0, 1], never
/// decreasing from call to call. Return false to cancel the build. Called from Embree's
/// worker threads, never two calls at once; it must return normally (as `HtProgressFn`).
pub type HtBuildProgressFn = Option<unsafe extern "C" fn(fraction: f64, user: *mut c_void) -> bool>;

/// The host's build callback as a [`StageProgress`] sink: the BVH stage is the only one a
/// scene of the C ABI builds (files are read and curves converted when they are added).
struct HostBuildProgress {
    callback: unsafe extern "C" fn(f64, *mut c_void) -> bool,
    user: *mut c_void,
}

// SAFETY: the stage runner makes the calls one at a time (HtBuildProgressFn's contract),
// and `user` is only handed back to the host's callback in those calls.
unsafe impl Sync for HostBuildProgress {}

impl StageProgress for HostBuildProgress {
    fn update(&self, stage: Stage, fraction: f64) -> bool {
        // SAFETY: the host's function pointer and its own user pointer.
        stage != Stage::Bvh || unsafe { (self.callback)(fraction, self.user) }
    }
}

/// Builds now what `ht_render_with` with `settings` would build first: the Embree scene
/// (and, for `HT_CURVE_AUTO` curves, their shapes for this camera and image height),
/// telling `progress` (may be NULL) how far the BVH build has got. A 10^6-strand groom
/// takes tens of seconds here; a render with the same view then starts at once.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene` or `settings` NULL); `HT_ERR_INVALID_ARG` (settings
/// out of range, a scene with no light, or no camera and no geometry to frame);
/// `HT_ERR_EMBREE` (the build failed); `HT_ERR_CANCELLED` (`progress` returned false: the
/// scene is left unbuilt, and the next build or render starts over).
///
/// One thread at a time per scene (the scene is not thread safe); `settings` may be read by
/// other threads meanwhile.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread (the whole call uses it);
/// `settings` is NULL or a live handle from `ht_settings_new`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_scene_build_with(
    scene: *mut HtScene,
    settings: *const HtSettings,
    progress: HtBuildProgressFn,
    user: *mut c_void,
) -> HtStatus {
    boundary(|| build(scene, &read_settings(settings)?, progress, user))
}

fn build(
    scene: *mut HtScene,
    settings: &RenderSettings,
    progress: HtBuildProgressFn,
    user: *mut c_void,
) -> Result<(), Failure> {
    let scene = scene_mut(scene)?;
    let host;
    let sink: &dyn StageProgress = match progress {
        Some(callback) => {
            host = HostBuildProgress { callback, user };
            &host
        }
        None => &NoStages,
    };
    scene.check_framed()?;
    scene.scene.build_for(settings, sink)?;
    Ok(())
}

/// Renders `scene` with `settings` into `rgb`: linear float RGB, interleaved, rows from the
/// top, `rgb_len` = 3 floats per pixel of the crop window (width * height * 3 without a
/// crop) owned by the host, telling `progress` (may be NULL) with `user`.
///
/// The first render builds the Embree scene (its time is part of the call, silent:
/// `ht_scene_build_with` reports it); later ones reuse it until geometry is added, or until
/// a view needs other shapes for `HT_CURVE_AUTO` curves. On `HT_ERR_CANCELLED`, `rgb` holds
/// the pixels finished before the callback said stop and 0 elsewhere; on other errors
/// every buffer is left untouched.
///
/// It also writes the AOVs (arbitrary output variables, for compositing and denoising)
/// whose buffers are not NULL; NULL means not wanted, and costs nothing. `pixel_count` is
/// the crop window's pixel count (width * height without a crop), and each buffer holds
/// that many pixels, rows from the top, in memory of its own:
///
/// - `albedo`: 3 floats per pixel, the mean reflectance colour (hair colour, diffuse
///   albedo, linear RGB in [0, 1]) of the surfaces the pixel's camera rays hit first;
///   escaped rays count as 0. What denoisers take as their albedo guide.
/// - `depth`: 1 float per pixel, the distance from the camera (world units, along the
///   ray) to the nearest first hit among the pixel's samples; 0 where nothing was hit.
/// - `strand_id`: 1 float per pixel, the index of the strand in its curve geometry (in
///   the order the host gave the strands; exact up to 2^24) of that nearest hit; -1 where
///   it is not hair or nothing was hit. Nearest rather than averaged: an average of ids is
///   no id.
///
/// On `HT_ERR_CANCELLED` the AOVs, like `rgb`, hold the passes each pixel finished and the
/// values of "nothing hit" elsewhere.
///
/// Statuses: `HT_ERR_NULL_ARG` (`scene`, `settings` or `rgb` NULL); `HT_ERR_INVALID_ARG`
/// (settings out of range, `rgb_len` or `pixel_count` not what the window needs, a buffer
/// misaligned, any two buffers overlapping, a scene with no light, or no camera and no
/// geometry to frame); `HT_ERR_EMBREE` (the scene build failed); `HT_ERR_CANCELLED` (the
/// progress callback returned false).
///
/// One thread at a time per scene; `settings` may be read by other threads meanwhile, not
/// set. Blocks until the image is done or cancelled, rendering on worker threads it joins
/// before it returns.
///
/// # Safety
/// `scene` is NULL or a live handle not in use on another thread (the whole call uses it);
/// `settings` is NULL or a live handle from `ht_settings_new`, not set during the call;
/// each non-NULL buffer holds the floats its length says, writable, and nothing else reads
/// or writes it during the call.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)] // the C signature: one argument per buffer
pub unsafe extern "C" fn ht_render_with(
    scene: *mut HtScene,
    settings: *const HtSettings,
    progress: HtProgressFn,
    user: *mut c_void,
    rgb: *mut f32,
    rgb_len: usize,
    albedo: *mut f32,
    depth: *mut f32,
    strand_id: *mut f32,
    pixel_count: usize,
) -> HtStatus {
    boundary(|| {
        let rust = read_settings(settings)?;
        let span = Span::of("settings", settings, 1);
        let buffers = (rgb, rgb_len, albedo, depth, strand_id, pixel_count);
        render_into(scene, &rust, span, progress, user, buffers)
    })
}

/// The buffers a host lends a render, unchecked: rgb and its length, the albedo, depth and
/// strand-id AOVs (each may be NULL) and the pixel count.
type HostBuffers = (*mut f32, usize, *mut f32, *mut f32, *mut f32, usize);

/// Checks the host's buffers against `settings` (valid), renders, telling `progress`
/// (may be NULL), and copies the film out.
fn render_into(
    scene: *mut HtScene,
    settings: &RenderSettings,
    settings_span: Span,
    progress: HtProgressFn,
    user: *mut c_void,
    (rgb, rgb_len, albedo, depth, strand_id, pixel_count): HostBuffers,
) -> Result<(), Failure> {
    let host;
    let progress: &dyn Progress = match progress {
        Some(callback) => {
            host = HostProgress {
                callback,
                user,
                noise: AtomicU32::new(NO_NOISE.to_bits()),
            };
            &host
        }
        None => &NoProgress,
    };
    let scene = scene_mut(scene)?;
    // The crop window's size (the full frame without one).
    let [x0, y0, x1, y1] = settings.window();
    let (w, h) = (x1 - x0, y1 - y0);
    // At most 2^15 x 2^15 x 3 (validated): no overflow.
    let pixels = w as usize * h as usize;
    let want = 3 * pixels;
    if rgb_len != want {
        return Err(invalid_arg!("rgb_len = {rgb_len}: must be 3 * {w} * {h} = {want}").into());
    }
    let rgb = host_slice_mut(non_null_mut(rgb, "rgb")?, rgb_len, "rgb")?;
    if pixel_count != pixels {
        return Err(
            invalid_arg!("pixel_count = {pixel_count}: must be {w} * {h} = {pixels}").into(),
        );
    }
    let albedo = optional_slice(albedo, 3 * pixels, "albedo")?;
    let depth = optional_slice(depth, pixels, "depth")?;
    let strand_id = optional_slice(strand_id, pixels, "strand_id")?;
    let span = |name, b: &Option<&mut [f32]>| {
        b.as_ref()
            .map_or(Span::of(name, std::ptr::null::<f32>(), 0), |b| {
                Span::of(name, b.as_ptr(), b.len())
            })
    };
    check_disjoint(
        &[
            Span::of("rgb", rgb.as_ptr(), rgb.len()),
            span("albedo", &albedo),
            span("depth", &depth),
            span("strand_id", &strand_id),
        ],
        &[settings_span],
    )?;
    let aovs = Aovs {
        albedo: albedo.is_some(),
        depth: depth.is_some(),
        strand_id: strand_id.is_some(),
    };
    scene.check_framed()?;
    let out = scene.scene.render_with(settings, aovs, progress)?;
    let film = &out.film;
    rgb.copy_from_slice(film.rgb());
    for (host, aov) in [
        (albedo, film.albedo()),
        (depth, film.depth()),
        (strand_id, film.strand_id()),
    ] {
        if let (Some(host), Some(aov)) = (host, aov) {
            host.copy_from_slice(aov);
        }
    }
    match out.status {
        RenderStatus::Complete => Ok(()),
        RenderStatus::Cancelled => Err(Failure(
            HtStatus::HT_ERR_CANCELLED,
            "render cancelled by the progress callback".into(),
        )),
    }
}

/// An AOV buffer of `len` floats the host lends, or None where it passed NULL (not
/// wanted).
fn optional_slice<'a>(
    ptr: *mut f32,
    len: usize,
    name: &str,
) -> Result<Option<&'a mut [f32]>, Failure> {
    (!ptr.is_null())
        .then(|| host_slice_mut(ptr, len, name))
        .transpose()
}

/// Writes `pixels` (width * height * channels linear floats, interleaved, rows from the
/// top; channels 1 grey, 2 grey + alpha, 3 RGB or 4 RGBA with premultiplied alpha) through
/// OpenImageIO. The extension picks the format: `.exr` stores 32-bit floats as they are;
/// `.png`, `.jpg`, `.tif` store 8-bit sRGB (clamped to [0, 1]). NaN or infinite pixels are
/// refused rather than written. The first image call of a process loads OpenImageIO,
/// through the image shim installed beside the library (docs/c-abi.md, section 10).
///
/// `pixels_len` is the length of `pixels` in floats and must equal
/// `width * height * channels` (computed without overflow).
///
/// Statuses: `HT_ERR_NULL_ARG` (`path` or `pixels` NULL); `HT_ERR_INVALID_ARG` (empty or
/// non-UTF-8 path, a size of 0, channels not in 1..=4, `pixels_len` not the size,
/// `pixels` misaligned, NaN or infinite pixels); `HT_ERR_IMAGE` (an unknown extension, a
/// format that cannot hold the channels, OpenImageIO could not write the file, e.g.
/// into a folder that does not exist, or the image shim was not found).
/// Any thread; touches no handle.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string; `pixels` is NULL or points to `pixels_len`
/// readable floats that stay unchanged during the call.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn ht_image_write(
    path: *const c_char,
    width: u32,
    height: u32,
    channels: u32,
    pixels: *const f32,
    pixels_len: usize,
) -> HtStatus {
    boundary(|| {
        let path = read_path(path, "path")?;
        let (w, h, c) = (width as usize, height as usize, channels as usize);
        let want = w.checked_mul(h).and_then(|n| n.checked_mul(c));
        if want != Some(pixels_len) {
            return Err(invalid_arg!(
                "pixels_len = {pixels_len}: must be width * height * channels = {width} * \
                 {height} * {channels}{}",
                want.map_or(" (which overflows)".into(), |n| format!(" = {n}"))
            )
            .into());
        }
        let pixels = host_slice(non_null(pixels, "pixels")?, pixels_len, "pixels")?;
        write_image(&path, w, h, c, pixels, &WriteOptions::default())?;
        Ok(())
    })
}
