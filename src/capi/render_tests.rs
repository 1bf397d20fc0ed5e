//! Tests of rendering and image writing through the C ABI.

use super::HtStatus;
use super::render::*;
use super::settings::HtSettings;
use crate::capi::geometry::*;
use crate::capi::lights::*;
use crate::capi::scene::*;
use crate::capi::scene_tests::{Handles, fails, last_error, sized, small_fur, xyzr, xyzr_desc};
use crate::embree::{CurveBasis, CurveShape, Device, Geometry, SceneOptions};
use crate::image::read_image;
use crate::render::integrator::World;
use crate::render::renderer::render;
use crate::render::settings::PathSettings;
use crate::render::settings::RenderSettings;
use crate::render::{Aovs, NoProgress};
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;
use crate::scene::envmap::Environment;
use crate::scene::light::Light;
use crate::scene::material::{HairMaterial, Material};
use crate::scene::stages::NoStages;
use crate::scene::tracer::TracerBuilder;
use glam::Vec3;
use std::ffi::c_void;
use std::ptr::{null, null_mut};
use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

const EYE: [f32; 3] = [0.0, 0.0, 4.0];
const UP: [f32; 3] = [0.0, 1.0, 0.0];
const SKY: [f32; 3] = [0.3, 0.35, 0.4];
const SUN_DIR: [f32; 3] = [1.0, 1.0, 1.0];
const SUN: [f32; 3] = [2.0, 2.0, 1.8];
const SUN_RADIUS_DEG: f32 = 2.0;

pub(super) fn settings(size: u32) -> RenderSettings {
    RenderSettings {
        width: size,
        height: size,
        spp: 4,
        seed: 7,
        threads: Some(2),
        ..RenderSettings::default()
    }
}

/// `ht_render_with` with `s` behind its handle, set directly rather than by name so that
/// values `ht_settings_set` refuses reach the render's own checks; `aovs` are the albedo,
/// depth and strand-id buffers (NULL: not wanted), `progress` the callback and its user.
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn render_raw(
    scene: *mut HtScene,
    s: &RenderSettings,
    rgb: *mut f32,
    rgb_len: usize,
    aovs: [*mut f32; 3],
    pixel_count: usize,
    (progress, user): (HtProgressFn, *mut c_void),
) -> HtStatus {
    let handle = HtSettings { settings: *s };
    let [albedo, depth, strand_id] = aovs;
    unsafe {
        ht_render_with(
            scene,
            &handle,
            progress,
            user,
            rgb,
            rgb_len,
            albedo,
            depth,
            strand_id,
            pixel_count,
        )
    }
}

/// `ht_render_with` of `s` into `rgb_len` floats of `rgb`, without AOVs or a callback.
unsafe fn render_rgb(
    scene: *mut HtScene,
    s: &RenderSettings,
    rgb: *mut f32,
    rgb_len: usize,
) -> HtStatus {
    let none = [null_mut(); 3];
    unsafe {
        render_raw(
            scene,
            s,
            rgb,
            rgb_len,
            none,
            rgb_len / 3,
            (None, null_mut()),
        )
    }
}

/// The pixels of `s`'s crop window (the frame without one).
fn window_pixels(s: &RenderSettings) -> usize {
    let [x0, y0, x1, y1] = s.window();
    ((x1 - x0) * (y1 - y0)) as usize
}

/// The small fur ball with hair, sky and sun through the C functions.
pub(super) fn fur_scene(camera: bool) -> Handles {
    let h = Handles::new();
    let hair = h.hair_material();
    assert_eq!(
        h.add_strands(&small_fur(), hair),
        HtStatus::HT_OK,
        "{}",
        last_error()
    );
    light(&h, camera);
    h
}

/// Adds sky and sun, and the camera if asked.
pub(super) fn light(h: &Handles, camera: bool) {
    unsafe {
        assert_eq!(
            ht_scene_add_environment(h.scene, SKY.as_ptr()),
            HtStatus::HT_OK
        );
        let s = ht_scene_add_distant_light(h.scene, SUN_DIR.as_ptr(), SUN.as_ptr(), SUN_RADIUS_DEG);
        assert_eq!(s, HtStatus::HT_OK);
        if camera {
            let s =
                ht_scene_set_camera(h.scene, EYE.as_ptr(), [0.0; 3].as_ptr(), UP.as_ptr(), 40.0);
            assert_eq!(s, HtStatus::HT_OK);
        }
    }
}

pub(super) fn render_c(h: &Handles, s: &RenderSettings) -> (HtStatus, Vec<f32>) {
    render_reporting(h, s, (None, null_mut()))
}

/// [`render_c`], telling `progress` with its user pointer.
fn render_reporting(
    h: &Handles,
    s: &RenderSettings,
    progress: (HtProgressFn, *mut c_void),
) -> (HtStatus, Vec<f32>) {
    let pixels = window_pixels(s);
    let mut rgb = vec![-1.0f32; 3 * pixels];
    let none = [null_mut(); 3];
    let status = unsafe {
        render_raw(
            h.scene,
            s,
            rgb.as_mut_ptr(),
            rgb.len(),
            none,
            pixels,
            progress,
        )
    };
    (status, rgb)
}

/// Renders through `ht_render_with` with every AOV: rgb, albedo, depth, strand id.
pub(super) fn render_aovs_c(h: &Handles, s: &RenderSettings) -> [Vec<f32>; 4] {
    unsafe {
        let pixels = window_pixels(s);
        let mut out = [3, 3, 1, 1].map(|channels| vec![-2.0f32; channels * pixels]);
        let [rgb, albedo, depth, strand_id] = &mut out;
        let aovs = [albedo, depth, strand_id].map(|b| b.as_mut_ptr());
        let none = (None, null_mut());
        let status = render_raw(h.scene, s, rgb.as_mut_ptr(), rgb.len(), aovs, pixels, none);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        out
    }
}

pub(super) fn bits(rgb: &[f32]) -> Vec<u32> {
    rgb.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn c_render_matches_the_rust_api_bit_for_bit() {
    let h = fur_scene(true);
    let (status, rgb) = render_c(&h, &settings(32));
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());

    let device = Arc::new(Device::new(Some(2)).unwrap());
    let mut builder = TracerBuilder::new(device, SceneOptions::default()).unwrap();
    let curves = Curves::from_strands(&small_fur(), CurveBasis::BSpline, CurveShape::Round);
    builder.add_curves(curves.unwrap()).unwrap();
    let hair = HairMaterial::default().prepare().unwrap();
    let lights = vec![
        Light::Environment(Environment::uniform(Vec3::from(SKY)).unwrap()),
        Light::distant(SUN_DIR.into(), SUN.into(), SUN_RADIUS_DEG).unwrap(),
    ];
    let world = World::new(
        builder.build().unwrap(),
        vec![Material::Hair(Box::new(hair))],
        lights,
    )
    .unwrap();
    let camera = Camera::new(EYE.into(), Vec3::ZERO, UP.into(), 40.0, 1.0).unwrap();
    let rust = RenderSettings {
        width: 32,
        height: 32,
        spp: 4,
        seed: 7,
        threads: Some(2),
        ..RenderSettings::default()
    };
    let out = render(&world, &camera, &rust, Aovs::default(), &NoProgress).unwrap();
    assert_eq!(bits(&rgb), bits(out.film.rgb()));
    assert!(rgb.iter().any(|v| *v > 0.0));

    // The filter reaches the renderer: a box render is the Rust box render.
    let boxed = RenderSettings {
        filter: crate::render::settings::Filter::Box,
        ..settings(32)
    };
    let (status, box_rgb) = render_c(&h, &boxed);
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    let rust_box = RenderSettings {
        filter: crate::render::settings::Filter::Box,
        ..rust
    };
    let out = render(&world, &camera, &rust_box, Aovs::default(), &NoProgress).unwrap();
    assert_eq!(bits(&box_rgb), bits(out.film.rgb()));
    assert_ne!(bits(&box_rgb), bits(&rgb));

    // So do the fidelity knobs: each C render is the Rust render with the same path
    // settings, and a deep-bounce depth of max_depth is the exact image.
    let exact = RenderSettings {
        path: PathSettings {
            max_depth: 6,
            ..PathSettings::default()
        },
        ..settings(32)
    };
    let c_image = |s: RenderSettings| {
        let (status, rgb) = render_c(&h, &s);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        bits(&rgb)
    };
    let exact_rgb = c_image(exact);
    let default_threshold = PathSettings::default().light_threshold;
    for (deep_bounce_depth, lobe_cull, light_threshold) in [
        (6, 0.0, default_threshold),
        (1, 0.0, default_threshold),
        (0, 0.2, default_threshold),
        (6, 0.0, 0.0),
    ] {
        let path = PathSettings {
            max_depth: 6,
            deep_bounce_depth: (deep_bounce_depth > 0).then_some(deep_bounce_depth),
            lobe_cull,
            light_threshold,
            ..PathSettings::default()
        };
        let knob = RenderSettings { path, ..exact };
        let rust_knob = RenderSettings { path, ..rust };
        let out = render(&world, &camera, &rust_knob, Aovs::default(), &NoProgress).unwrap();
        let got = c_image(knob);
        assert_eq!(
            got,
            bits(out.film.rgb()),
            "{deep_bounce_depth}, {lobe_cull}, {light_threshold}"
        );
        assert_eq!(
            got == exact_rgb,
            deep_bounce_depth == 6 && light_threshold == default_threshold,
            "{deep_bounce_depth}, {lobe_cull}, {light_threshold}"
        );
    }
}

#[test]
fn shared_xyzr_points_render_like_a_copy_through_rebuilds() {
    unsafe {
        let strands = small_fur();
        let points = xyzr(&strands);
        let desc = xyzr_desc(&points, &strands.counts);
        let scenes = [ht_scene_add_curves_xyzr, ht_scene_add_curves_xyzr_shared].map(|add| {
            let h = Handles::new();
            let hair = h.hair_material();
            let s = add(h.scene, &desc, hair, &mut 0);
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            light(&h, true);
            h
        });
        let s = settings(24);
        let render_both = || {
            scenes.each_ref().map(|h| {
                let (status, rgb) = render_c(h, &s);
                assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
                bits(&rgb)
            })
        };
        // The points Embree reads in the shared scene's current build.
        let embree_points = || {
            let scene = scene_mut(scenes[1].scene).ok().unwrap();
            let (world, _) = scene.prepare(&sized(1, 1), &NoStages).unwrap();
            match world.tracer.scene().geometry(0) {
                Some(Geometry::Curves(c)) => c.vertices().as_ptr(),
                _ => panic!("curves expected"),
            }
        };
        let [copied, shared] = render_both();
        assert_eq!(copied, shared);
        assert!(copied.iter().any(|&v| f32::from_bits(v) > 0.0));
        assert_eq!(embree_points(), points.as_ptr());

        // A wall added later rebuilds the scene, which still reads the host's points.
        for h in &scenes {
            let wall = h.diffuse_material([0.9; 3]);
            assert_eq!(h.add_triangle(wall), HtStatus::HT_OK);
        }
        let [copied_wall, shared_wall] = render_both();
        assert_eq!(copied_wall, shared_wall);
        assert_ne!(copied_wall, copied);
        assert_eq!(embree_points(), points.as_ptr());
    }
}

#[test]
fn crops_reassemble_into_the_full_frame_bit_for_bit() {
    let h = fur_scene(true);
    let full_settings = settings(32);
    let full = render_aovs_c(&h, &full_settings);
    assert!(full[0].iter().any(|v| *v > 0.0));
    // Three windows that tile the frame, cutting through the renderer's 16 x 16 tiles.
    let mut assembled = full.clone().map(|buffer| vec![f32::NAN; buffer.len()]);
    for [x0, y0, x1, y1] in [[0, 0, 13, 21], [13, 0, 32, 21], [0, 21, 32, 32]] {
        let s = RenderSettings {
            crop: Some([x0, y0, x1, y1]),
            ..full_settings
        };
        let crop = render_aovs_c(&h, &s);
        for ((whole, piece), channels) in assembled.iter_mut().zip(&crop).zip([3, 3, 1, 1]) {
            let row = (x1 - x0) as usize * channels;
            for (y, piece_row) in (y0..y1).zip(piece.chunks_exact(row)) {
                let start = (y as usize * 32 + x0 as usize) * channels;
                whole[start..start + row].copy_from_slice(piece_row);
            }
        }
    }
    for (whole, pieces) in full.iter().zip(&assembled) {
        assert_eq!(bits(whole), bits(pieces));
    }
}

#[test]
fn aovs_report_the_first_hits_and_null_ones_are_skipped() {
    unsafe {
        let h = fur_scene(true);
        let s = settings(32);
        let [rgb, albedo, depth, strand_id] = render_aovs_c(&h, &s);
        assert_eq!(
            bits(&rgb),
            bits(&render_c(&h, &s).1),
            "AOVs change no pixel"
        );
        assert!(albedo.iter().all(|a| (0.0..=1.0).contains(a)), "{albedo:?}");
        let strands = small_fur().counts.len() as f32;
        for (d, id) in depth.iter().zip(&strand_id) {
            if *id >= 0.0 {
                assert!(d.is_finite() && *d > 0.0, "depth {d} of strand {id}");
                assert!(id.fract() == 0.0 && *id < strands, "{id}");
            } else {
                assert_eq!(*id, -1.0);
            }
        }
        let hair = strand_id.iter().filter(|id| **id >= 0.0).count();
        assert!(hair > 20, "{hair} hair pixels");
        // Pixels of sky alone hit nothing: depth 0, albedo 0.
        let sky = (depth.iter().zip(albedo.chunks_exact(3)))
            .filter(|(d, a)| **d == 0.0 && *a == [0.0; 3]);
        assert!(sky.count() > 20);

        // Only the depth: the other buffers may be NULL, and it is the same depth.
        let mut rgb_only = vec![0.0f32; rgb.len()];
        let mut depth_only = vec![0.0f32; depth.len()];
        let status = render_raw(
            h.scene,
            &s,
            rgb_only.as_mut_ptr(),
            rgb_only.len(),
            [null_mut(), depth_only.as_mut_ptr(), null_mut()],
            depth.len(),
            (None, null_mut()),
        );
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        assert_eq!(bits(&rgb_only), bits(&rgb));
        assert_eq!(bits(&depth_only), bits(&depth));
    }
}

#[test]
fn a_thin_lens_blurs_whichever_comes_first_lens_or_camera() {
    unsafe {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL, HT_OK};
        let s = settings(24);
        let h = fur_scene(true);
        let (status, pinhole) = render_c(&h, &s);
        assert_eq!(status, HT_OK, "{}", last_error());
        let set = |h: &Handles, aperture, focus| ht_scene_set_thin_lens(h.scene, aperture, focus);
        fails(set(&h, f32::NAN, 4.0), INVALID, "aperture_radius = NaN");
        fails(set(&h, -0.1, 4.0), INVALID, "aperture_radius = -0.1");
        fails(set(&h, 0.1, 0.0), INVALID, "focus_distance = 0");
        fails(set(&h, 0.1, f32::INFINITY), INVALID, "focus_distance = inf");
        fails(ht_scene_set_thin_lens(null_mut(), 0.1, 4.0), NULL, "scene");
        // Refused lenses leave the pinhole, and aperture 0 is one.
        assert_eq!(bits(&render_c(&h, &s).1), bits(&pinhole));
        assert_eq!(set(&h, 0.0, 4.0), HT_OK);
        assert_eq!(bits(&render_c(&h, &s).1), bits(&pinhole));

        // Focused far behind the fur, which blurs; the lens set before the camera holds too.
        assert_eq!(set(&h, 0.5, 10.0), HT_OK);
        let (status, blurred) = render_c(&h, &s);
        assert_eq!(status, HT_OK, "{}", last_error());
        assert!(blurred.iter().all(|v| v.is_finite()));
        assert_ne!(bits(&blurred), bits(&pinhole));
        let lens_first = Handles::new();
        let hair = lens_first.hair_material();
        assert_eq!(lens_first.add_strands(&small_fur(), hair), HT_OK);
        assert_eq!(set(&lens_first, 0.5, 10.0), HT_OK);
        light(&lens_first, true);
        assert_eq!(bits(&render_c(&lens_first, &s).1), bits(&blurred));
    }
}

extern "C" fn count_then_cancel(_done: u64, _total: u64, user: *mut c_void) -> bool {
    let calls = unsafe { &*user.cast::<AtomicU32>() };
    calls.fetch_add(1, Ordering::Relaxed) < 1
}

extern "C" fn count(done: u64, total: u64, user: *mut c_void) -> bool {
    assert!(done <= total);
    unsafe { &*user.cast::<AtomicU32>() }.fetch_add(1, Ordering::Relaxed);
    true
}

#[test]
fn the_callback_reports_progress_and_cancels() {
    let h = fur_scene(true);
    let calls = AtomicU32::new(0);
    let s = settings(64);
    let user = std::ptr::from_ref(&calls).cast_mut().cast();
    let (status, full) = render_reporting(&h, &s, (Some(count), user));
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    // 16 x 16 tiles: one call per tile, and more if a tile takes over 20 ms.
    assert!(calls.load(Ordering::Relaxed) >= 16);

    calls.store(0, Ordering::Relaxed);
    let (status, partial) = render_reporting(&h, &s, (Some(count_then_cancel), user));
    fails(
        status,
        HtStatus::HT_ERR_CANCELLED,
        "cancelled by the progress callback",
    );
    assert!(calls.load(Ordering::Relaxed) >= 2);
    // Finished tiles match the full render; the rest stayed black.
    let unfinished = partial.iter().filter(|v| **v == 0.0).count();
    assert!(unfinished >= partial.len() / 2, "{unfinished}");
    for (p, f) in partial.iter().zip(&full) {
        assert!(*p == 0.0 || p == f);
    }
}

#[test]
fn adding_geometry_or_lights_rebuilds_what_changed() {
    unsafe {
        let h = fur_scene(true);
        let s = settings(24);
        let (status, before) = render_c(&h, &s);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        assert_eq!(
            render_c(&h, &s).1,
            before,
            "a second render reuses the build"
        );

        // A white wall behind the fur, then a rect light: each render equals a scene
        // built with everything from the start.
        let wall = h.diffuse_material([0.9; 3]);
        assert_eq!(h.add_triangle(wall), HtStatus::HT_OK);
        let (status, with_wall) = render_c(&h, &s);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        assert_ne!(bits(&with_wall), bits(&before));
        let add_rect = |h: &Handles| {
            let (corner, u, v) = ([-1.0f32, 2.0, 2.0], [2.0f32, 0.0, 0.0], [0.0f32, 0.0, -2.0]);
            let s = ht_scene_add_rect_light(
                h.scene,
                corner.as_ptr(),
                u.as_ptr(),
                v.as_ptr(),
                [3.0f32; 3].as_ptr(),
                false,
            );
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        };
        add_rect(&h);
        let (status, with_rect) = render_c(&h, &s);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());

        let fresh = fur_scene(true);
        let wall = fresh.diffuse_material([0.9; 3]);
        assert_eq!(fresh.add_triangle(wall), HtStatus::HT_OK);
        assert_eq!(bits(&render_c(&fresh, &s).1), bits(&with_wall));
        add_rect(&fresh);
        assert_eq!(bits(&render_c(&fresh, &s).1), bits(&with_rect));
        assert_ne!(bits(&with_rect), bits(&with_wall));
    }
}

#[test]
fn without_a_camera_the_scene_is_framed() {
    let h = fur_scene(false);
    let (status, rgb) = render_c(&h, &settings(32));
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    assert!(rgb.iter().all(|v| v.is_finite()));
    // Pixels that see fur rather than only the sky gather around the image centre.
    let fur: Vec<(f32, f32)> = (0..32 * 32)
        .filter(|i| rgb[3 * i] != SKY[0])
        .map(|i| ((i % 32) as f32, (i / 32) as f32))
        .collect();
    assert!(fur.len() > 20, "{} fur pixels", fur.len());
    let n = fur.len() as f32;
    let centre = fur
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.0 / n, y + p.1 / n));
    assert!(
        (centre.0 - 15.5).abs() < 4.0 && (centre.1 - 15.5).abs() < 4.0,
        "{centre:?}"
    );
}

#[test]
fn bad_settings_and_incomplete_scenes_are_reported() {
    unsafe {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let h = fur_scene(true);
        let s = settings(8);
        let mut rgb = vec![0.0f32; 8 * 8 * 3];
        let (ptr, len) = (rgb.as_mut_ptr(), rgb.len());
        let none = [null_mut(); 3];
        let no_progress = (None, null_mut());
        let nowhere = |scene, s: *const HtSettings, rgb| {
            ht_render_with(
                scene,
                s,
                None,
                null_mut(),
                rgb,
                len,
                none[0],
                none[1],
                none[2],
                64,
            )
        };
        let good = HtSettings { settings: s };
        fails(nowhere(null_mut(), &good, ptr), NULL, "scene");
        fails(nowhere(h.scene, null(), ptr), NULL, "settings");
        fails(nowhere(h.scene, &good, null_mut()), NULL, "rgb");
        fails(
            render_rgb(h.scene, &s, ptr, len - 1),
            INVALID,
            "rgb_len = 191",
        );
        let zero = RenderSettings { width: 0, ..s };
        fails(render_rgb(h.scene, &zero, ptr, 0), INVALID, "width = 0");
        let path = |path: PathSettings| RenderSettings { path, ..s };
        let depth = path(PathSettings {
            max_depth: 0,
            ..s.path
        });
        fails(
            render_rgb(h.scene, &depth, ptr, len),
            INVALID,
            "max_depth = 0",
        );
        let spp = RenderSettings { spp: 0, ..s };
        fails(render_rgb(h.scene, &spp, ptr, len), INVALID, "spp = 0");
        let radius = RenderSettings {
            filter_radius: f32::NAN,
            ..s
        };
        fails(
            render_rgb(h.scene, &radius, ptr, len),
            INVALID,
            "filter_radius = NaN",
        );
        let deep = path(PathSettings {
            max_depth: 4,
            deep_bounce_depth: Some(5),
            ..s.path
        });
        fails(
            render_rgb(h.scene, &deep, ptr, len),
            INVALID,
            "deep_bounce_depth = 5: must be at most max_depth = 4",
        );
        let cull = path(PathSettings {
            lobe_cull: 1.0,
            ..s.path
        });
        fails(
            render_rgb(h.scene, &cull, ptr, len),
            INVALID,
            "lobe_cull = 1",
        );
        for bad in [-0.5, f32::NAN, f32::INFINITY] {
            let threshold = path(PathSettings {
                light_threshold: bad,
                ..s.path
            });
            fails(
                render_rgb(h.scene, &threshold, ptr, len),
                INVALID,
                "light_threshold",
            );
        }
        let aovs = |s: &RenderSettings, rgb_len, pixel_count| {
            render_raw(h.scene, s, ptr, rgb_len, none, pixel_count, no_progress)
        };
        fails(
            aovs(&s, len, 63),
            INVALID,
            "pixel_count = 63: must be 8 * 8 = 64",
        );
        // A 4 x 3 window: 12 pixels.
        let crop = RenderSettings {
            crop: Some([2, 1, 6, 4]),
            ..s
        };
        fails(
            aovs(&crop, len, 12),
            INVALID,
            "rgb_len = 192: must be 3 * 4 * 3 = 36",
        );
        fails(
            aovs(&crop, 36, 64),
            INVALID,
            "pixel_count = 64: must be 4 * 3 = 12",
        );
        let outside = RenderSettings {
            crop: Some([2, 1, 9, 4]),
            ..s
        };
        fails(aovs(&outside, 36, 12), INVALID, "crop = 2,1,9,4");
        let reversed = RenderSettings {
            crop: Some([6, 1, 6, 4]),
            ..s
        };
        fails(aovs(&reversed, 36, 12), INVALID, "crop = 6,1,6,4");
        assert!(
            rgb.iter().all(|v| *v == 0.0),
            "failed renders leave the buffer alone"
        );

        let dark = Handles::new();
        let hair = dark.hair_material();
        assert_eq!(dark.add_strands(&small_fur(), hair), HtStatus::HT_OK);
        fails(render_rgb(dark.scene, &s, ptr, len), INVALID, "no light");
        let empty = Handles::new();
        assert_eq!(
            ht_scene_add_environment(empty.scene, SKY.as_ptr()),
            HtStatus::HT_OK
        );
        fails(
            render_rgb(empty.scene, &s, ptr, len),
            INVALID,
            "ht_scene_set_camera",
        );
        // With a camera, an empty scene shows its environment.
        let z = [0.0f32, 0.0, -1.0];
        let set = ht_scene_set_camera(
            empty.scene,
            [0.0; 3].as_ptr(),
            z.as_ptr(),
            UP.as_ptr(),
            40.0,
        );
        assert_eq!(set, HtStatus::HT_OK);
        assert_eq!(
            render_rgb(empty.scene, &s, ptr, len),
            HtStatus::HT_OK,
            "{}",
            last_error()
        );
        for (v, sky) in rgb.iter().zip(SKY.iter().cycle()) {
            assert!((v - sky).abs() < 1e-6, "{v} {sky}");
        }
    }
}

#[test]
fn images_are_written_through_oiio() {
    unsafe {
        let dir = std::env::temp_dir().join(format!("ht-capi-render-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("ramp.exr");
        let path = std::ffi::CString::new(file.to_str().unwrap()).unwrap();
        let pixels: Vec<f32> = (0..4 * 2 * 3).map(|i| i as f32 / 8.0).collect();
        let s = ht_image_write(path.as_ptr(), 4, 2, 3, pixels.as_ptr(), pixels.len());
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let image = read_image(&file).unwrap();
        assert_eq!((image.width, image.height, image.channels), (4, 2, 3));
        assert_eq!(image.pixels, pixels);

        fails(
            ht_image_write(path.as_ptr(), 4, 2, 3, null(), 24),
            HtStatus::HT_ERR_NULL_ARG,
            "pixels",
        );
        fails(
            ht_image_write(null(), 4, 2, 3, pixels.as_ptr(), 24),
            HtStatus::HT_ERR_NULL_ARG,
            "path",
        );
        let bmp = std::ffi::CString::new(dir.join("x.bmp").to_str().unwrap()).unwrap();
        let s = ht_image_write(bmp.as_ptr(), 4, 2, 3, pixels.as_ptr(), 24);
        assert_ne!(s, HtStatus::HT_OK);
        assert!(last_error().contains("x.bmp"), "{}", last_error());
        let nan = [f32::NAN; 3];
        fails(
            ht_image_write(path.as_ptr(), 1, 1, 3, nan.as_ptr(), 3),
            HtStatus::HT_ERR_INVALID_ARG,
            "NaN",
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn auto_curves_render_as_ribbons_or_tubes_for_each_view() {
    let strands = small_fur();
    let points = xyzr(&strands);
    let [round, flat, auto] = [HT_CURVE_ROUND, HT_CURVE_FLAT, HT_CURVE_AUTO].map(|shape| {
        let h = Handles::new();
        let hair = h.hair_material();
        let desc = HtCurvesXyzr {
            shape,
            ..xyzr_desc(&points, &strands.counts)
        };
        let s = unsafe { ht_scene_add_curves_xyzr(h.scene, &desc, hair, &mut 0) };
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        light(&h, true);
        h
    });
    // The shapes of the last build (the scene's own camera and height keep it).
    let shapes = |h: &Handles| {
        let scene = scene_mut(h.scene).ok().unwrap();
        let world = scene.scene.world().expect("built");
        (world.tracer.scene().geometries().iter())
            .map(|g| match g {
                Geometry::Curves(c) => c.shape(),
                _ => panic!("curves only"),
            })
            .collect::<Vec<_>>()
    };
    let builds = |h: &Handles| h.scene().scene.builds();
    // Roots 0.008 wide, 3 to 5 units from an eye with a 40-degree view: a pixel wide at
    // 273 to 455 pixels of image height. At 32 every strand is a ribbon; at 1000 every
    // strand a tube (a 16-pixel crop keeps that render small); at 350, both.
    let small = settings(32);
    let tall = RenderSettings {
        width: 1000,
        height: 1000,
        crop: Some([492, 300, 508, 316]),
        ..settings(32)
    };
    let image = |h: &Handles, s: &RenderSettings| {
        let (status, rgb) = render_c(h, s);
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        bits(&rgb)
    };
    let auto_small = image(&auto, &small);
    assert_eq!(shapes(&auto), [CurveShape::Flat]);
    // Ribbons through fewer points (the level of detail): the flat image, but for the
    // pixels where a polyline moved within its tolerance.
    let mean = |v: &[u32]| v.iter().map(|&b| f64::from(f32::from_bits(b))).sum::<f64>();
    let (m_auto, m_flat) = (mean(&auto_small), mean(&image(&flat, &small)));
    assert!(
        (m_auto - m_flat).abs() < 0.02 * m_flat,
        "{m_auto} vs {m_flat}"
    );
    // More pixels make strands wider: built again, partly round, then all round.
    let (status, _) = render_c(&auto, &settings(350));
    assert_eq!(status, HtStatus::HT_OK);
    assert_eq!(shapes(&auto), [CurveShape::Round, CurveShape::Flat]);
    let auto_tall = image(&auto, &tall);
    assert_eq!(shapes(&auto), [CurveShape::Round]);
    assert_eq!(auto_tall, image(&round, &tall));
    assert!(auto_tall.iter().any(|&v| f32::from_bits(v) > 0.0));
    assert_eq!(builds(&auto), 3);
    // Back to the small view, whose pixels are larger: the tubes stay, with no build.
    assert_eq!(image(&auto, &small), image(&round, &small));
    assert_eq!(shapes(&auto), [CurveShape::Round]);
    assert_eq!(builds(&auto), 3);
}

unsafe extern "C" fn record_build(fraction: f64, user: *mut c_void) -> bool {
    // SAFETY: the test's Vec<f64>, used by one call at a time (HtBuildProgressFn).
    let calls = unsafe { &mut *user.cast::<Vec<f64>>() };
    calls.push(fraction);
    true
}

unsafe extern "C" fn cancel_build(fraction: f64, user: *mut c_void) -> bool {
    unsafe { record_build(fraction, user) };
    false
}

#[test]
fn scene_build_reports_its_progress_and_the_render_reuses_it() {
    let h = fur_scene(true);
    let s = settings(24);
    let tracer_of = |h: &Handles| {
        let scene = scene_mut(h.scene).ok().unwrap();
        scene.scene.world().map(|w| &raw const w.tracer)
    };
    let mut calls: Vec<f64> = Vec::new();
    let user = (&raw mut calls).cast::<c_void>();
    let status = unsafe {
        ht_scene_build_with(
            h.scene,
            &HtSettings { settings: s },
            Some(record_build),
            user,
        )
    };
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    assert!(calls.windows(2).all(|w| w[0] <= w[1]), "{calls:?}");
    assert_eq!(calls.last(), Some(&1.0), "{calls:?}");
    let built = tracer_of(&h).expect("built");
    let (status, rgb) = render_c(&h, &s);
    assert_eq!(status, HtStatus::HT_OK);
    assert!(rgb.iter().any(|&v| v > 0.0));
    // The render kept the build: same tracer, not a rebuilt one.
    let after = tracer_of(&h).unwrap();
    assert_eq!(unsafe { (*after).scene().raw() }, unsafe {
        (*built).scene().raw()
    });

    // A cancelled build leaves the scene unbuilt; the next render builds it.
    let h = fur_scene(true);
    let mut calls: Vec<f64> = Vec::new();
    let user = (&raw mut calls).cast::<c_void>();
    let status = unsafe {
        ht_scene_build_with(
            h.scene,
            &HtSettings { settings: s },
            Some(cancel_build),
            user,
        )
    };
    assert_eq!(status, HtStatus::HT_ERR_CANCELLED, "{}", last_error());
    assert_eq!(calls.len(), 1);
    assert!(tracer_of(&h).is_none());
    assert_eq!(render_c(&h, &s).0, HtStatus::HT_OK);
    // Bad settings are refused before anything is built.
    let bad = HtSettings {
        settings: RenderSettings { spp: 0, ..s },
    };
    assert_eq!(
        unsafe { ht_scene_build_with(h.scene, &bad, None, null_mut()) },
        HtStatus::HT_ERR_INVALID_ARG
    );
    assert!(last_error().contains("spp = 0"));
}
