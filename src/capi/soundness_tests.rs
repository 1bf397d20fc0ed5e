//! Each crash, hang or misleading answer the C ABI once gave after its set-up calls had
//! returned HT_OK, reproduced: each now gets a status and a message that names the problem.

use super::HtStatus::{HT_ERR_CANCELLED, HT_ERR_INVALID_ARG as INVALID, HT_ERR_IO, HT_OK};
use super::geometry::*;
use super::lights::*;
use super::materials::*;
use super::render::*;
use super::render_tests::{bits, fur_scene, light, render_c, render_raw, settings};
use super::scene::*;
use super::scene_tests::{Handles, fails, last_error, sized, small_fur, xyzr, xyzr_desc};
use super::settings::HtSettings;
use crate::capi::bsdf::ht_hair_params_default;
use crate::embree::Ray;
use crate::render::settings::RenderSettings;
use crate::scene::NoStages;
use glam::Vec3;
use std::ffi::{CString, c_void};
use std::ptr::{null, null_mut};
use std::time::Duration;

/// A float4 that starts on a 16-byte boundary, as Embree's shared points must.
#[derive(Clone, Copy, Default)]
#[repr(C, align(16))]
struct Aligned([f32; 4]);

/// `points` in 16-byte aligned memory with one spare float4 in front, so that the same
/// values can also be shown to the library 4, 8 or 12 bytes past a boundary.
fn aligned_copy(points: &[[f32; 4]]) -> Vec<Aligned> {
    let mut v = vec![Aligned::default(); points.len() + 1];
    for (d, p) in v[1..].iter_mut().zip(points) {
        d.0 = *p;
    }
    v
}

/// The same values starting `offset` bytes (a multiple of 4) before `host[1]`.
fn shifted(host: &mut [Aligned], offset: usize) -> *const f32 {
    let floats: &mut [f32] = as_floats(host);
    let n = floats.len() - 4;
    floats.copy_within(4.., 4 - offset / 4);
    floats[4 - offset / 4..][..n].as_ptr()
}

fn as_floats(host: &mut [Aligned]) -> &mut [f32] {
    // SAFETY: `Aligned` is four floats with no padding.
    unsafe { std::slice::from_raw_parts_mut(host.as_mut_ptr().cast(), 4 * host.len()) }
}

/// Shared points 4, 8 or 12 bytes past a 16-byte boundary crashed in rtcCommitScene
/// (Embree loads each float4 aligned); they are refused with the alignment needed, while
/// the copying call takes the same memory, commits and renders like aligned points.
#[test]
fn shared_points_off_16_bytes_are_refused_and_copies_of_them_render() {
    unsafe {
        let strands = small_fur();
        let points = xyzr(&strands);
        let reference = {
            let h = Handles::new();
            let hair = h.hair_material();
            let mut host = aligned_copy(&points);
            let desc = HtCurvesXyzr {
                points: host[1..].as_ptr().cast(),
                ..xyzr_desc(&points, &strands.counts)
            };
            let s = ht_scene_add_curves_xyzr_shared(h.scene, &desc, hair, &mut 0);
            assert_eq!(s, HT_OK, "{}", last_error());
            light(&h, true);
            let (status, rgb) = render_c(&h, &settings(16));
            assert_eq!(status, HT_OK, "{}", last_error());
            host.clear();
            bits(&rgb)
        };
        for offset in [4, 8, 12] {
            let h = Handles::new();
            let hair = h.hair_material();
            let mut host = aligned_copy(&points);
            let desc = HtCurvesXyzr {
                points: shifted(&mut host, offset),
                ..xyzr_desc(&points, &strands.counts)
            };
            assert_eq!(desc.points as usize % 16, 16 - offset);
            let s = ht_scene_add_curves_xyzr_shared(h.scene, &desc, hair, &mut 0);
            fails(s, INVALID, "not aligned to 16 bytes");
            assert!(h.scene().geometries == 0);
            let s = ht_scene_add_curves_xyzr(h.scene, &desc, hair, &mut 0);
            assert_eq!(s, HT_OK, "{}", last_error());
            light(&h, true);
            let (status, rgb) = render_c(&h, &settings(16));
            assert_eq!(status, HT_OK, "{}", last_error());
            assert_eq!(bits(&rgb), reference, "offset {offset}");
        }
    }
}

/// A camera at 1e19 or an aperture of 2e18 aborted inside the render (Embree's ray
/// validity assertion); such values, and geometry and lights as far out, are refused when
/// they are set, and the scene renders with what it had.
#[test]
fn coordinates_embree_cannot_trace_are_refused_when_set() {
    unsafe {
        let h = fur_scene(true);
        let far = [1e19f32, 0.0, 0.0];
        let (zero, up) = ([0.0f32; 3], [0.0f32, 1.0, 0.0]);
        let s = ht_scene_set_camera(h.scene, far.as_ptr(), zero.as_ptr(), up.as_ptr(), 40.0);
        fails(
            s,
            INVALID,
            "eye = [10000000000000000000, 0, 0]: every coordinate",
        );
        let s = ht_scene_set_camera(h.scene, zero.as_ptr(), far.as_ptr(), up.as_ptr(), 40.0);
        fails(s, INVALID, "within +-1e15");
        fails(
            ht_scene_set_thin_lens(h.scene, 2e18, 4.0),
            INVALID,
            "aperture_radius = 2000000000000000000",
        );
        fails(
            ht_scene_set_thin_lens(h.scene, 0.1, 2e18),
            INVALID,
            "focus_distance",
        );
        let hair = h.hair_material();
        let mut points = xyzr(&small_fur());
        points[5][1] = -1e19;
        let counts = small_fur().counts;
        let s = ht_scene_add_curves_xyzr(h.scene, &xyzr_desc(&points, &counts), hair, &mut 0);
        fails(s, INVALID, "control point 5 = ");
        let wall = h.diffuse_material([0.5; 3]);
        let positions = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1e19, 0.0];
        let i = [0u32, 1, 2];
        let s = ht_scene_add_mesh(
            h.scene,
            3,
            positions.as_ptr(),
            null(),
            1,
            i.as_ptr(),
            wall,
            &mut 0,
        );
        fails(s, INVALID, "vertex 2 = ");
        let (e, one) = ([1.0f32, 0.0, 0.0], [1.0f32; 3]);
        let s = ht_scene_add_rect_light(
            h.scene,
            far.as_ptr(),
            e.as_ptr(),
            up.as_ptr(),
            one.as_ptr(),
            false,
        );
        fails(s, INVALID, "rect light corner");
        assert_eq!(h.scene().geometries as usize, 1);
        let (status, rgb) = render_c(&h, &settings(16));
        assert_eq!(status, HT_OK, "{}", last_error());
        assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));

        // Should a ray Embree refuses ever be formed, it is a miss, not an abort.
        let scene = scene_mut(h.scene).ok().unwrap();
        let (world, _) = scene.prepare(&sized(1, 1), &NoStages).unwrap();
        let bad = Ray::new(Vec3::new(1e19, 0.0, 0.0), Vec3::NEG_X);
        assert!(world.tracer.scene().intersect(&bad, None).is_none());
        let nan = Ray::new(Vec3::new(f32::NAN, 0.0, 4.0), Vec3::NEG_Z);
        assert!(world.tracer.scene().intersect(&nan, None).is_none());
        assert!(!world.tracer.scene().occluded(&bad, None));
    }
}

/// The scene handle, moved to the render thread of a test (the test waits for it).
struct SendScene(*mut HtScene);
// SAFETY: only the render thread uses the scene while the test waits for it.
unsafe impl Send for SendScene {}

extern "C" fn stop(_done: u64, _total: u64, user: *mut c_void) -> bool {
    // SAFETY: the test's counter, alive until the render returns.
    unsafe { &*user.cast::<std::sync::atomic::AtomicU32>() }
        .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    false
}

/// 4e9 samples per pixel with a callback that cancels never returned: cancellation was
/// checked per 16 x 16 tile. Cancelled, the image is the passes that finished. The watchdog fails the test instead of hanging (a generous
/// bound, no timing claim: the render stops within a few tens of milliseconds).
#[test]
fn a_render_of_billions_of_samples_per_pixel_cancels() {
    let h = fur_scene(true);
    let scene = SendScene(h.scene);
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let scene = scene;
        let calls = std::sync::atomic::AtomicU32::new(0);
        let s = RenderSettings {
            spp: 4_000_000_000,
            ..settings(4)
        };
        let user = std::ptr::from_ref(&calls).cast_mut().cast();
        let mut rgb = vec![-1.0f32; 48];
        let none = [null_mut(); 3];
        // SAFETY: a live scene used by this thread alone; rgb holds 48 floats.
        let status = unsafe {
            render_raw(
                scene.0,
                &s,
                rgb.as_mut_ptr(),
                48,
                none,
                16,
                (Some(stop), user),
            )
        };
        tx.send((status, last_error(), calls.into_inner(), rgb))
            .unwrap();
    });
    let (status, message, calls, rgb) = rx
        .recv_timeout(Duration::from_secs(120))
        .expect("ht_render_with did not return after the callback cancelled");
    assert_eq!(status, HT_ERR_CANCELLED, "{message}");
    assert!(message.contains("cancelled"), "{message}");
    assert!(calls >= 1);
    // The render goes in passes of 8 spp: the first finished (and was stored) before the
    // callback's first answer, and no later one.
    let first_pass = RenderSettings {
        spp: 8,
        ..settings(4)
    };
    // The scene is no longer used by the thread, which has sent its result.
    let (status, expected) = render_c(&h, &first_pass);
    assert_eq!(status, HT_OK);
    assert_eq!(rgb, expected, "the pixels hold the first pass alone");
}

/// `depth == rgb` was accepted (overlapping outputs): any overlap between the buffers,
/// or with the settings, is refused and nothing is written.
#[test]
fn overlapping_render_buffers_are_refused() {
    unsafe {
        let h = fur_scene(true);
        let s = settings(4);
        let mut rgb = vec![-3.0f32; 48 + 16];
        let p = rgb.as_mut_ptr();
        let none = (None, null_mut());
        let call = |albedo: *mut f32, depth: *mut f32, strand: *mut f32| {
            render_raw(h.scene, &s, p, 48, [albedo, depth, strand], 16, none)
        };
        fails(
            call(null_mut(), p, null_mut()),
            INVALID,
            "rgb and depth overlap",
        );
        fails(
            call(p.add(40), null_mut(), null_mut()),
            INVALID,
            "rgb and albedo overlap",
        );
        fails(
            call(null_mut(), p.add(48), p.add(50)),
            INVALID,
            "depth and strand_id overlap",
        );
        let mut settings_in = HtSettings { settings: s };
        let sp = &raw mut settings_in;
        let status = ht_render_with(
            h.scene,
            sp,
            None,
            null_mut(),
            sp.cast(),
            3 * 16,
            null_mut(),
            null_mut(),
            null_mut(),
            16,
        );
        // The settings are not a float buffer's size or alignment, or they overlap.
        assert_eq!(status, INVALID, "{}", last_error());
        assert!(rgb.iter().all(|v| *v == -3.0), "a refused call wrote");
        let mut apart = vec![0.0f32; 16];
        let status = call(null_mut(), apart.as_mut_ptr(), null_mut());
        assert_eq!(status, HT_OK, "{}", last_error());
        assert!(apart.iter().any(|v| *v > 0.0));
    }
}

/// ht_image_write took no length (100000 x 100000 from a 12-float buffer crashed): the
/// length is checked, and a size whose product overflows is refused as such.
#[test]
fn image_writes_check_the_buffer_length() {
    unsafe {
        let path = CString::new(std::env::temp_dir().join("ht-len.exr").to_str().unwrap()).unwrap();
        let px = [0.5f32; 12];
        let s = ht_image_write(path.as_ptr(), 100_000, 100_000, 3, px.as_ptr(), px.len());
        fails(
            s,
            INVALID,
            "pixels_len = 12: must be width * height * channels = 100000 * 100000 * 3 = 30000000000",
        );
        let s = ht_image_write(path.as_ptr(), u32::MAX, u32::MAX, u32::MAX, px.as_ptr(), 12);
        fails(s, INVALID, "overflows");
        let s = ht_image_write(path.as_ptr(), 2, 2, 3, px.as_ptr(), usize::MAX);
        fails(s, INVALID, "pixels_len");
        // An address range that would run past the end of memory.
        let end = usize::MAX - 15;
        let s = ht_image_write(path.as_ptr(), 2, 2, 3, end as *const f32, 12);
        fails(s, INVALID, "do not fit in memory");
    }
}

/// A C bool read from host memory made any byte but 0 and 1 undefined behaviour; the
/// flag is an integer, checked.
#[test]
fn use_vertex_colors_is_checked_to_be_0_or_1() {
    unsafe {
        let h = Handles::new();
        let p = ht_hair_params_default();
        for (flag, ok) in [(0u8, true), (1, true), (2, false), (255, false)] {
            let v = HtHairVariation {
                use_vertex_colors: flag,
                ..ht_hair_variation_default()
            };
            let s = ht_scene_add_hair_material_varied(h.scene, &p, &v, &mut 0);
            if ok {
                assert_eq!(s, HT_OK, "{}", last_error());
            } else {
                fails(
                    s,
                    INVALID,
                    &format!("use_vertex_colors = {flag}: must be 0 or 1"),
                );
            }
        }
    }
}

/// Messages say what is wrong once (the status already names its kind), missing files are
/// i/o errors whatever their format, and reasons are the right ones.
#[test]
fn statuses_and_messages_are_consistent() {
    unsafe {
        let h = Handles::new();
        let mut p = ht_hair_params_default();
        p.beta_m = 2.0;
        fails(
            ht_scene_add_hair_material(h.scene, &p, &mut 0),
            INVALID,
            "beta_m = 2",
        );
        assert!(
            !last_error().contains("invalid argument"),
            "{}",
            last_error()
        );

        let hair = h.hair_material();
        let wall = h.diffuse_material([0.5; 3]);
        let dir = std::env::temp_dir().join(format!("ht-missing-{}", std::process::id()));
        for ext in ["hair", "obj", "ply", "exr"] {
            let path = CString::new(dir.join(format!("none.{ext}")).to_str().unwrap()).unwrap();
            let s = match ext {
                "hair" => ht_scene_add_hair_file(h.scene, path.as_ptr(), false, 0, 0, hair, &mut 0),
                "exr" => ht_scene_add_environment_map(h.scene, path.as_ptr(), 0.0, 1.0),
                _ => ht_scene_add_mesh_file(h.scene, path.as_ptr(), wall, &mut 0),
            };
            fails(s, HT_ERR_IO, &format!("none.{ext}"));
            assert!(!last_error().starts_with("i/o error"), "{}", last_error());
        }
        std::fs::create_dir_all(&dir).unwrap();
        let empty = dir.join("empty.obj");
        std::fs::write(&empty, "# nothing\n").unwrap();
        let path = CString::new(empty.to_str().unwrap()).unwrap();
        let s = ht_scene_add_mesh_file(h.scene, path.as_ptr(), wall, &mut 0);
        fails(s, INVALID, "at least one triangle");
        std::fs::remove_dir_all(&dir).unwrap();

        let one = [1.0f32; 3];
        let huge = [1e30f32, 1e30, 0.0];
        assert_eq!(
            ht_scene_add_distant_light(h.scene, huge.as_ptr(), one.as_ptr(), 1.0),
            HT_OK,
            "{}",
            last_error()
        );
        let s = ht_scene_add_distant_light(h.scene, huge.as_ptr(), one.as_ptr(), 95.0);
        fails(s, INVALID, "angular radius 95 degrees must be in [0, 90)");

        // Vertex colours are reflectances: 5 is refused, not clamped to 1.
        let mut strands = small_fur();
        let mut colors = vec![[0.5f32; 3]; strands.points.len()];
        colors[3] = [0.5, 5.0, 0.5];
        strands.colors = Some(colors);
        fails(
            h.add_strands(&strands, hair),
            INVALID,
            "colour 3 = [0.5, 5.0, 0.5]: each channel must be in [0, 1]",
        );

        // Out-parameters must be aligned for what is written through them.
        let mut ids = [0u32; 2];
        let odd = ids.as_mut_ptr().cast::<u8>().add(1).cast::<u32>();
        let s = ht_scene_add_diffuse_material(h.scene, one.as_ptr(), odd);
        fails(s, INVALID, "material_id = ");
        assert!(
            last_error().contains("not aligned to 4 bytes"),
            "{}",
            last_error()
        );
        let s = ht_scene_add_curves(h.scene, null(), hair, odd);
        fails(s, INVALID, "geom_id");
    }
}
