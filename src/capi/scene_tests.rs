//! Tests of the scene-building calls of the C ABI, and the helpers the render tests share.

use super::HtStatus;
use super::bsdf::HtHairParams;
use super::geometry::*;
use super::lights::*;
use super::materials::*;
use super::scene::*;
use crate::capi::bsdf::ht_hair_params_default;
use crate::capi::ht_last_error;
use crate::embree::{MemoryMonitor, padding_for};
use crate::formats::hair::{Thickness, write_hair_file};
use crate::scene::NoStages;
use crate::scene::material::HairColor;
use crate::scene::{FurBall, Strands};
use std::ffi::CStr;
use std::ptr::{null, null_mut};

pub(crate) fn last_error() -> String {
    unsafe { CStr::from_ptr(ht_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// Default render settings for an image of `width` x `height`.
pub(crate) fn sized(width: u32, height: u32) -> crate::render::settings::RenderSettings {
    crate::render::settings::RenderSettings {
        width,
        height,
        ..Default::default()
    }
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
        Self::on(|out| unsafe { ht_device_new(2, out) })
    }

    /// A scene on the device `new_device` makes.
    pub(crate) fn on(new_device: impl FnOnce(*mut *mut HtDevice) -> HtStatus) -> Self {
        let (mut device, mut scene) = (null_mut(), null_mut());
        assert_eq!(new_device(&mut device), HtStatus::HT_OK);
        // SAFETY: a live device.
        assert_eq!(unsafe { ht_scene_new(device, &mut scene) }, HtStatus::HT_OK);
        Handles { device, scene }
    }

    pub(crate) fn scene(&self) -> &HtScene {
        unsafe { &*self.scene }
    }

    pub(crate) fn hair_material(&self) -> u32 {
        unsafe {
            let mut id = u32::MAX;
            let p = ht_hair_params_default();
            assert_eq!(
                ht_scene_add_hair_material(self.scene, &p, &mut id),
                HtStatus::HT_OK
            );
            id
        }
    }

    pub(crate) fn diffuse_material(&self, albedo: [f32; 3]) -> u32 {
        unsafe {
            let mut id = u32::MAX;
            let s = ht_scene_add_diffuse_material(self.scene, albedo.as_ptr(), &mut id);
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            id
        }
    }

    /// Adds `strands` through `ht_scene_add_curves`.
    pub(crate) fn add_strands(&self, strands: &Strands, material: u32) -> HtStatus {
        unsafe {
            let desc = curves_desc(strands);
            ht_scene_add_curves(self.scene, &desc, material, &mut 0)
        }
    }

    /// Adds a single triangle in front of the origin.
    pub(crate) fn add_triangle(&self, material: u32) -> HtStatus {
        unsafe {
            let positions = [-3.0f32, -3.0, -1.5, 3.0, -3.0, -1.5, 0.0, 3.0, -1.5];
            let indices = [0u32, 1, 2];
            let (p, i) = (positions.as_ptr(), indices.as_ptr());
            ht_scene_add_mesh(self.scene, 3, p, null(), 1, i, material, &mut 0)
        }
    }
}

impl Drop for Handles {
    fn drop(&mut self) {
        unsafe {
            assert_eq!(ht_scene_free(self.scene), HtStatus::HT_OK);
            assert_eq!(ht_device_free(self.device), HtStatus::HT_OK);
        }
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
    unsafe {
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
        assert!(h.scene().geometries == 0 && h.scene().scene.light_names().count() == 0);
    }
}

#[test]
fn invalid_values_name_the_argument_and_add_nothing() {
    unsafe {
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
        assert!(h.scene().materials == 0);

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
            points: { desc.points.cast::<u8>().add(1).cast() },
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
        assert!(h.scene().geometries == 0);

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
            HtStatus::HT_ERR_IO,
            "sky.exr",
        );
        assert!(h.scene().scene.light_names().count() == 0);
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
        assert!(h.scene().scene.camera().eye.is_none());
    }
}

#[test]
fn geometry_from_buffers_and_files_gets_consecutive_ids() {
    unsafe {
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
        let Some(c) = h.scene().scene.kept_curves(1) else {
            panic!("curves expected");
        };
        assert_eq!((c.vertices(), c.indices()), (&xyzr[..], &[0u32, 4, 5][..]));
        assert_eq!(
            c.strands().absorption(&c.strands().locate(2).unwrap(), 1.0),
            Some(HairColor::Color([0.5; 3]))
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
        assert_eq!(h.scene().geometries as usize, 5);
    }
}

#[test]
fn shared_xyzr_points_are_checked_then_read_in_place() {
    unsafe {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        let h = Handles::new();
        let hair = h.hair_material();
        let strands = small_fur();
        let points = xyzr(&strands);
        // The host's points in 16-byte aligned memory (u128 is 16-aligned), as Embree needs.
        let mut host = vec![0u128; points.len()];
        let floats =
            std::slice::from_raw_parts_mut(host.as_mut_ptr().cast::<f32>(), 4 * points.len());
        floats.copy_from_slice(points.as_flattened());
        let desc = HtCurvesXyzr {
            points: host.as_ptr().cast(),
            ..xyzr_desc(&points, &strands.counts)
        };
        assert_eq!(desc.points as usize % 16, 0);
        let add = |d: &HtCurvesXyzr| ht_scene_add_curves_xyzr_shared(h.scene, d, hair, &mut 0);
        let s = ht_scene_add_curves_xyzr_shared(h.scene, null(), hair, &mut 0);
        fails(s, NULL, "desc is NULL");
        let no_points = HtCurvesXyzr {
            points: null(),
            ..desc
        };
        fails(add(&no_points), NULL, "desc->points is NULL");
        let misaligned = HtCurvesXyzr {
            points: { desc.points.cast::<u8>().add(2).cast() },
            ..desc
        };
        fails(add(&misaligned), INVALID, "not aligned to 4 bytes");
        let short = HtCurvesXyzr {
            point_count: desc.point_count - 1,
            ..desc
        };
        fails(add(&short), INVALID, "counts add up");
        assert!(h.scene().geometries == 0);

        assert_eq!(add(&desc), HtStatus::HT_OK, "{}", last_error());
        let Some(c) = h.scene().scene.kept_curves(0) else {
            panic!("curves expected");
        };
        assert_eq!(c.vertices().as_ptr().cast(), desc.points);
        assert_eq!(c.vertices(), &points[..]);
        // Only the index buffer and the strand table are the scene's.
        let indices = (strands.segment_count() + padding_for::<u32>()) * 4;
        assert_eq!(c.heap_bytes(), indices + c.strands().heap_bytes());
    }
}

/// Bytes hairtrace holds for a scene of curves: what it keeps to rebuild, and the built
/// tracer (what the two share counted once, `SharedBuffer::heap_bytes`).
fn held_bytes(scene: &HtScene) -> usize {
    let kept = scene.scene.kept_curves_bytes();
    kept + scene.scene.world().map_or(0, |w| w.tracer.heap_bytes())
}

/// Memory of a built groom through each entry point: sharing saves the one copy of the
/// control points that the scene and the tracer share, and Embree copies them in neither
/// case.
/// `--nocapture` prints bytes per segment.
#[test]
fn shared_xyzr_points_cost_neither_hairtrace_nor_embree_memory() {
    unsafe {
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
        let [copied, shared] = [false, true].map(|host_points| {
            let add = if host_points {
                ht_scene_add_curves_xyzr_shared
            } else {
                ht_scene_add_curves_xyzr
            };
            let h = Handles::new();
            let monitor = MemoryMonitor::attach(h.scene().scene.device().clone());
            let hair = h.hair_material();
            assert_eq!(add(h.scene, &desc, hair, &mut 0), HtStatus::HT_OK);
            add_sky(&h);
            scene_mut(h.scene)
                .ok()
                .unwrap()
                .prepare(&sized(1, 1), &NoStages)
                .unwrap();
            let held = held_bytes(h.scene());
            // The scene's curves and the tracer's read the same points: the host's,
            // or, copied, one copy in spatial order behind an `Arc`.
            let Some(c) = h.scene().scene.kept_curves(0) else {
                panic!("curves expected");
            };
            let at = c.vertices().as_ptr();
            assert_eq!(tracer_points(h.scene()), at);
            assert_eq!(at.cast() == desc.points, host_points);
            (held, monitor.current() as usize)
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
        // One copy of the points, and the strand tables (the scene's and the tracer's)
        // name each strand in spatial order: 4 bytes each.
        assert_eq!(copied.0 - shared.0, vertex_bytes + 2 * 4 * STRANDS);
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

/// The control points the built tracer's first geometry reads.
fn tracer_points(scene: &HtScene) -> *const [f32; 4] {
    tracer_curves(scene).vertices().as_ptr()
}

/// The built tracer's first geometry.
fn tracer_curves(scene: &HtScene) -> &crate::embree::CurveGeometry {
    let world = scene.scene.world().expect("built");
    match world.tracer.scene().geometry(0) {
        Some(crate::embree::Geometry::Curves(c)) => c,
        _ => panic!("curves expected"),
    }
}

/// The first render orders a copied groom once and keeps it so: a rebuild (here for an
/// added mesh) traces the same points, neither sorted nor copied again, cut into the same
/// parts where it is large (2^18 segments, `curve_parts = "on"`), and gives the image a
/// scene built once gives.
#[test]
fn a_rebuild_reuses_the_ordered_points() {
    use crate::render::settings::{CurveParts, RenderSettings};
    let large = FurBall {
        strands: 1 << 14,
        segments: 16,
        ..FurBall::default()
    };
    for (strands, curve_parts) in [
        (small_fur(), CurveParts::Auto),
        (large.build().unwrap(), CurveParts::On),
    ] {
        rebuilt_as_built_once(
            &strands,
            &RenderSettings {
                spp: 2,
                curve_parts,
                ..sized(16, 16)
            },
        );
    }
}

/// A uniform grey sky.
fn add_sky(h: &Handles) {
    // SAFETY: a live scene and three floats.
    let status = unsafe { ht_scene_add_environment(h.scene, [0.5f32; 3].as_ptr()) };
    assert_eq!(status, HtStatus::HT_OK);
}

fn rebuilt_as_built_once(strands: &Strands, settings: &crate::render::settings::RenderSettings) {
    let render = |h: &Handles| {
        let scene = scene_mut(h.scene).ok().unwrap();
        let (world, camera) = scene.prepare(settings, &NoStages).unwrap();
        let (aovs, quiet) = (crate::render::Aovs::default(), &crate::render::NoProgress);
        let out = crate::render::renderer::render(world, &camera, settings, aovs, quiet);
        (out.unwrap().film.rgb().iter())
            .map(|v| v.to_bits())
            .collect::<Vec<_>>()
    };
    let h = Handles::new();
    let hair = h.hair_material();
    assert_eq!(h.add_strands(strands, hair), HtStatus::HT_OK);
    add_sky(&h);
    let given = h.scene().scene.kept_curves(0).unwrap().vertices().to_vec();
    render(&h);
    let ordered = tracer_points(h.scene());
    let parts = tracer_curves(h.scene()).parts().map(<[_]>::as_ptr);
    let large = settings.curve_parts == crate::render::settings::CurveParts::On;
    assert_eq!(parts.is_some(), large);
    let Some(kept) = h.scene().scene.kept_curves(0) else {
        panic!("curves expected");
    };
    assert_eq!(kept.vertices().as_ptr(), ordered);
    assert_ne!(
        kept.vertices(),
        &given[..],
        "the strands were put in spatial order"
    );

    let floor = h.diffuse_material([0.5; 3]);
    assert_eq!(h.add_triangle(floor), HtStatus::HT_OK);
    assert!(!h.scene().scene.is_built());
    let rebuilt = render(&h);
    assert_eq!(tracer_points(h.scene()), ordered);
    assert_eq!(tracer_curves(h.scene()).parts().map(<[_]>::as_ptr), parts);

    let once = Handles::new();
    let hair = once.hair_material();
    assert_eq!(once.add_strands(strands, hair), HtStatus::HT_OK);
    add_sky(&once);
    let floor = once.diffuse_material([0.5; 3]);
    assert_eq!(once.add_triangle(floor), HtStatus::HT_OK);
    assert_eq!(rebuilt, render(&once));
}

#[test]
fn pinned_devices_take_embree_isa_names_only() {
    // SAFETY: NUL-terminated names or NULL, and a local out-parameter.
    unsafe {
        for isa in [null(), c"sse2".as_ptr()] {
            let mut device = null_mut();
            assert_eq!(ht_device_new_pinned(1, isa, &mut device), HtStatus::HT_OK);
            assert_eq!(ht_device_free(device), HtStatus::HT_OK);
        }
        let mut device = null_mut();
        assert_eq!(
            ht_device_new_pinned(1, c"sse4.2".as_ptr(), &mut device),
            HtStatus::HT_ERR_INVALID_ARG
        );
        assert!(device.is_null());
    }
    assert!(
        last_error().contains("isa = \"sse4.2\": must be one of sse2, avx, avx2, avx512"),
        "{}",
        last_error()
    );
}

/// A USD stage adds one geometry per BasisCurves prim, with consecutive ids and the prim's
/// own basis; bad arguments and files are refused with their status and add nothing.
#[test]
fn usd_file_adds_one_geometry_per_basis_curves_prim() {
    let h = Handles::new();
    unsafe {
        let hair = h.hair_material();
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/usd/");
        let path = std::ffi::CString::new(format!("{dir}all_bases.usdc")).unwrap();
        let (mut first, mut count) = (u32::MAX, u32::MAX);
        fails(
            ht_scene_add_usd_file(h.scene, path.as_ptr(), 0, hair, &mut first, null_mut()),
            HtStatus::HT_ERR_NULL_ARG,
            "geom_count",
        );
        let missing = c"/nonexistent/groom.usda";
        let s = ht_scene_add_usd_file(h.scene, missing.as_ptr(), 0, hair, &mut first, &mut count);
        fails(s, HtStatus::HT_ERR_IO, "/nonexistent/groom.usda");
        assert!(h.scene().geometries == 0);
        let s = ht_scene_add_usd_file(h.scene, path.as_ptr(), 0, hair, &mut first, &mut count);
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        assert_eq!((first, count), (0, 10));
        assert_eq!(h.scene().geometries as usize, 10);
        let s = ht_scene_add_usd_file(h.scene, path.as_ptr(), 0, hair, &mut first, &mut count);
        assert_eq!((s, first, count), (HtStatus::HT_OK, 10, 10));
    }
}
