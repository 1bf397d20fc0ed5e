//! Tests of what a C host may change without a BVH build (materials, lights, a camera for
//! which the `auto` shapes still hold), of one build per render without a camera, and of
//! one automatic framing for the C ABI and scene descriptions.

use super::HtStatus;
use super::bsdf::{HtHairParams, ht_hair_params_default};
use super::geometry::*;
use super::lights::*;
use super::materials::*;
use super::render::*;
use super::render_tests::{bits, fur_scene, light, render_c, settings};
use super::scene::*;
use super::scene_tests::{Handles, curves_desc, fails, last_error, sized, small_fur};
use super::settings::HtSettings;
use super::settings_tests::Named;
use crate::description::{
    GroomDesc, GroomSource, LightDesc, MaterialDesc, MeshDesc, MeshSource, SceneDescription,
};
use crate::embree::{CurveBasis, Device};
use crate::render::settings::RenderSettings;
use crate::render::{Aovs, NoProgress};
use crate::scene::material::HairMaterial;
use crate::scene::{FurBall, GroomShape};
use std::ptr::{null, null_mut};
use std::sync::Arc;

/// What the edits of [`edits_keep_the_build_and_render_as_a_fresh_build`] change.
#[derive(Clone, Copy)]
struct Setup {
    hair: HtHairParams,
    variation: HtHairVariation,
    albedo: [f32; 3],
    rect_light: bool,
    eye: [f32; 3],
    lens: Option<(f32, f32)>,
}

impl Setup {
    fn first() -> Self {
        Setup {
            hair: ht_hair_params_default(),
            variation: ht_hair_variation_default(),
            albedo: [0.9; 3],
            rect_light: false,
            eye: [0.0, 0.0, 4.0],
            lens: None,
        }
    }

    /// A scene built with everything from the start: `auto` B-spline fur (ids 0: hair
    /// material, 1: diffuse), a triangle behind it, sky and sun, the camera.
    fn build(&self) -> Handles {
        let h = Handles::new();
        unsafe {
            let (mut hair, mut wall) = (0, 0);
            let s =
                ht_scene_add_hair_material_varied(h.scene, &self.hair, &self.variation, &mut hair);
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            let albedo = self.albedo.as_ptr();
            assert_eq!(
                ht_scene_add_diffuse_material(h.scene, albedo, &mut wall),
                HtStatus::HT_OK
            );
            let fur = small_fur();
            let desc = HtCurves {
                // Round: a kept `auto` build differs from a fresh one wherever the level of detail
                // of the new view would cut the strands otherwise.
                shape: HT_CURVE_ROUND,
                ..curves_desc(&fur)
            };
            assert_eq!(
                ht_scene_add_curves(h.scene, &desc, hair, &mut 0),
                HtStatus::HT_OK
            );
            assert_eq!(h.add_triangle(wall), HtStatus::HT_OK);
            light(&h, false);
        }
        self.edit(&h, None);
        h
    }

    /// Applies what differs from `before` (the camera and lens, without one).
    fn edit(&self, h: &Handles, before: Option<&Setup>) {
        unsafe {
            if before.is_some_and(|b| (b.hair, b.variation) != (self.hair, self.variation)) {
                let s = ht_scene_set_hair_material(h.scene, 0, &self.hair, &self.variation);
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            }
            if before.is_some_and(|b| b.albedo != self.albedo) {
                let s = ht_scene_set_diffuse_material(h.scene, 1, self.albedo.as_ptr());
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            }
            if self.rect_light && !before.is_some_and(|b| b.rect_light) {
                let (corner, u, v) = ([-1.0f32, 2.0, 2.0], [2.0f32, 0.0, 0.0], [0.0f32, 0.0, -2.0]);
                let (c, u, v) = (corner.as_ptr(), u.as_ptr(), v.as_ptr());
                let s = ht_scene_add_rect_light(h.scene, c, u, v, [3.0f32; 3].as_ptr(), false);
                assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
            }
            let (eye, target, up) = (self.eye.as_ptr(), [0.0f32; 3], [0.0f32, 1.0, 0.0]);
            let s = ht_scene_set_camera(h.scene, eye, target.as_ptr(), up.as_ptr(), 40.0);
            assert_eq!(s, HtStatus::HT_OK);
            if let Some((radius, focus)) = self.lens {
                assert_eq!(
                    ht_scene_set_thin_lens(h.scene, radius, focus),
                    HtStatus::HT_OK
                );
            }
        }
    }
}

fn builds(h: &Handles) -> u64 {
    h.scene().scene.builds()
}

/// A material, a light and a camera changed one after the other on a built scene: none
/// rebuilds its BVH (the device's build count stays at 1), each changes the image, and
/// each image is bit for bit the image of a scene built with everything from the start.
/// At 32 pixels every strand is a ribbon, from the first eye and from the farther one.
#[test]
fn edits_keep_the_build_and_render_as_a_fresh_build() {
    let s = settings(32);
    let first = Setup::first();
    let h = first.build();
    let (status, mut image) = render_c(&h, &s);
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    assert_eq!(builds(&h), 1);
    // Each step adds one change to the one before it.
    let mut steps = vec![Setup {
        hair: HtHairParams {
            sigma_a: [0.1, 0.6, 1.2],
            beta_m: 0.25,
            ..first.hair
        },
        ..first
    }];
    let next = |steps: &mut Vec<Setup>, change: fn(&mut Setup)| {
        let mut step = *steps.last().unwrap();
        change(&mut step);
        steps.push(step);
    };
    next(&mut steps, |s| {
        s.variation.absorption_variation = 0.4;
        s.variation.tip_absorption = 0.5;
    });
    next(&mut steps, |s| s.albedo = [0.2, 0.5, 0.8]);
    next(&mut steps, |s| s.rect_light = true);
    next(&mut steps, |s| s.eye = [0.0, 0.5, 5.0]);
    next(&mut steps, |s| s.lens = Some((0.05, 5.0)));
    let mut before = first;
    for (i, step) in steps.iter().enumerate() {
        step.edit(&h, Some(&before));
        let (status, edited) = render_c(&h, &s);
        assert_eq!(status, HtStatus::HT_OK, "step {i}: {}", last_error());
        assert_eq!(builds(&h), 1, "step {i} built the BVH again");
        assert!(bits(&edited) != bits(&image), "step {i} changed nothing");
        let fresh = step.build();
        assert!(
            bits(&render_c(&fresh, &s).1) == bits(&edited),
            "step {i}: not the fresh image"
        );
        (before, image) = (*step, edited);
    }
}

/// Bad edits are refused with the argument named, and change nothing: the next render is
/// the one before them, without a build.
#[test]
fn bad_material_edits_are_refused_and_change_nothing() {
    let s = settings(24);
    let h = Setup::first().build();
    let (_, before) = render_c(&h, &s);
    let p = ht_hair_params_default();
    let v = ht_hair_variation_default();
    unsafe {
        use HtStatus::{HT_ERR_INVALID_ARG as INVALID, HT_ERR_NULL_ARG as NULL};
        fails(
            ht_scene_set_hair_material(null_mut(), 0, &p, &v),
            NULL,
            "scene",
        );
        fails(
            ht_scene_set_hair_material(h.scene, 0, null(), &v),
            NULL,
            "params",
        );
        fails(
            ht_scene_set_hair_material(h.scene, 2, &p, &v),
            INVALID,
            "material_id = 2",
        );
        fails(
            ht_scene_set_hair_material(h.scene, 1, &p, &v),
            INVALID,
            "diffuse",
        );
        let bad = HtHairParams { beta_n: 2.0, ..p };
        fails(
            ht_scene_set_hair_material(h.scene, 0, &bad, &v),
            INVALID,
            "beta_n",
        );
        let bad = HtHairVariation {
            use_vertex_colors: 2,
            ..v
        };
        fails(
            ht_scene_set_hair_material(h.scene, 0, &p, &bad),
            INVALID,
            "use_vertex_colors",
        );
        let grey = [0.5f32; 3];
        fails(
            ht_scene_set_diffuse_material(null_mut(), 1, grey.as_ptr()),
            NULL,
            "scene",
        );
        fails(
            ht_scene_set_diffuse_material(h.scene, 1, null()),
            NULL,
            "albedo",
        );
        fails(
            ht_scene_set_diffuse_material(h.scene, 0, grey.as_ptr()),
            INVALID,
            "hair",
        );
        let bright = [1.5f32, 0.5, 0.5];
        fails(
            ht_scene_set_diffuse_material(h.scene, 1, bright.as_ptr()),
            INVALID,
            "1.5",
        );
        // NULL variation: none, the same as the default.
        assert_eq!(
            ht_scene_set_hair_material(h.scene, 0, &p, null()),
            HtStatus::HT_OK
        );
    }
    assert!(
        bits(&render_c(&h, &s).1) == bits(&before),
        "a refused edit changed the image"
    );
    assert_eq!(builds(&h), 1);
}

/// Without a camera the scene is framed from what was added, never from a BVH built for
/// it: one build per render, `auto` curves included (they used to take two).
#[test]
fn a_host_without_a_camera_builds_once() {
    let fur = small_fur();
    for shape in [HT_CURVE_ROUND, HT_CURVE_AUTO] {
        let h = Handles::new();
        let hair = h.hair_material();
        let desc = HtCurves {
            shape,
            ..curves_desc(&fur)
        };
        assert_eq!(
            unsafe { ht_scene_add_curves(h.scene, &desc, hair, &mut 0) },
            HtStatus::HT_OK
        );
        light(&h, false);
        let s = settings(24);
        let handle = HtSettings { settings: s };
        let status = unsafe { ht_scene_build_with(h.scene, &handle, None, null_mut()) };
        assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
        assert_eq!(builds(&h), 1, "shape {shape}");
        assert_eq!(render_c(&h, &s).0, HtStatus::HT_OK);
        assert_eq!(render_c(&h, &s).0, HtStatus::HT_OK);
        assert_eq!(builds(&h), 1, "shape {shape}");
    }
}

/// A build is kept for renders of other spp (the `auto` parts rule reads the first's), and
/// made again when the host changes `curve_parts`.
#[test]
fn a_change_of_curve_parts_builds_again() {
    let h = fur_scene(true);
    for (parts, spp, builds_then) in [("auto", "1", 1), ("auto", "64", 1), ("off", "64", 2)] {
        let named = Named::new(&[
            ("width", "16"),
            ("height", "16"),
            ("spp", spp),
            ("curve_parts", parts),
        ]);
        assert_eq!(named.render_rgb(h.scene, 16 * 16).0, HtStatus::HT_OK);
        assert_eq!(builds(&h), builds_then, "{parts} at {spp} spp");
    }
}

/// The same content through a scene description and through the C ABI, with no camera:
/// a small `auto` groom over a ground quad (which a scene file leaves out of the framing,
/// and the C ABI too when there is hair), one sun, a hair and a diffuse material. Both
/// frame the same camera and give the same image bit for bit.
#[test]
fn descriptions_and_the_c_abi_frame_the_same_camera() {
    let fur = FurBall {
        strands: 200,
        segments: 6,
        ..FurBall::default()
    };
    let sun = ([1.0f32, 2.0, 1.0], [3.0f32, 3.0, 2.8], 2.0f32);
    let (ground_y, half) = (-1.2, 3.0);
    let mut d = SceneDescription::default();
    d.render.width = 40;
    d.render.height = 30;
    d.render.spp = 4;
    d.render.seed = 3;
    d.render.threads = Some(2);
    d.materials
        .insert("hair".into(), MaterialDesc::Hair(HairMaterial::default()));
    d.materials
        .insert("floor".into(), MaterialDesc::Diffuse { albedo: [0.6; 3] });
    let mut groom = GroomDesc::new(GroomSource::FurBall(fur.clone()), "hair");
    groom.shape = GroomShape::Auto;
    d.grooms.push(groom);
    d.meshes.push(MeshDesc::new(
        MeshSource::Ground {
            y: ground_y,
            half_size: half,
        },
        "floor",
    ));
    d.lights.push(LightDesc::Distant {
        direction: sun.0,
        irradiance: sun.1,
        angular_radius_deg: sun.2,
    });
    let device = Arc::new(Device::new(Some(2)).unwrap());
    let mut built = d.build(device).unwrap();
    let toml = built.render(Aovs::default(), &NoProgress).unwrap();

    let h = Handles::new();
    let strands = fur.build().unwrap();
    unsafe {
        let hair = h.hair_material();
        let floor = h.diffuse_material([0.6; 3]);
        let desc = HtCurves {
            shape: HT_CURVE_AUTO,
            ..curves_desc(&strands)
        };
        assert_eq!(desc.basis, HT_CURVE_BSPLINE);
        assert_eq!(
            GroomDesc::new(GroomSource::FurBall(fur), "")
                .strand_curves()
                .unwrap()
                .basis(),
            CurveBasis::BSpline
        );
        assert_eq!(
            ht_scene_add_curves(h.scene, &desc, hair, &mut 0),
            HtStatus::HT_OK
        );
        let ground = crate::scene::shapes::ground(ground_y, half).unwrap();
        let (p, t) = (
            ground.positions.as_ptr().cast(),
            ground.triangles.as_ptr().cast(),
        );
        let normals = ground
            .normals
            .as_ref()
            .map_or(null(), |n| n.as_ptr().cast());
        let (v, n) = (ground.positions.len(), ground.triangles.len());
        let s = ht_scene_add_mesh(h.scene, v, p, normals, n, t, floor, &mut 0);
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let (dir, irradiance) = (sun.0.as_ptr(), sun.1.as_ptr());
        assert_eq!(
            ht_scene_add_distant_light(h.scene, dir, irradiance, sun.2),
            HtStatus::HT_OK
        );
    }
    let s = RenderSettings {
        width: 40,
        height: 30,
        spp: 4,
        seed: 3,
        threads: Some(2),
        ..RenderSettings::default()
    };
    let (status, rgb) = render_c(&h, &s);
    assert_eq!(status, HtStatus::HT_OK, "{}", last_error());
    let camera = (h.scene().scene.placed_camera(&sized(40, 30))).unwrap();
    assert_eq!(camera.eye(), built.placed_camera(&s).unwrap().eye());
    assert!(
        bits(&rgb) == bits(toml.film.rgb()),
        "the C image is not the description's"
    );
}

/// The `isa` setting cannot re-pin a C host's device: a render asking another ISA than
/// the device's is refused, with how to pin the device; on a device pinned to it, the
/// same render goes ahead.
#[test]
fn a_render_cannot_repin_its_device() {
    let isa = crate::embree::Isa::widest_here().expect("an x86-64 CPU");
    let named = Named::new(&[("width", "8"), ("height", "8"), ("isa", isa.name())]);
    let unpinned = fur_scene(true);
    let (status, _) = named.render_rgb(unpinned.scene, 64);
    fails(status, HtStatus::HT_ERR_INVALID_ARG, "ht_device_new_pinned");
    let name = std::ffi::CString::new(isa.name()).unwrap();
    let pinned = Handles::on(|out| unsafe { ht_device_new_pinned(2, name.as_ptr(), out) });
    let hair = pinned.hair_material();
    assert_eq!(pinned.add_strands(&small_fur(), hair), HtStatus::HT_OK);
    light(&pinned, true);
    assert_eq!(named.render_rgb(pinned.scene, 64).0, HtStatus::HT_OK);
}

/// `ht_scene_set_camera_motion` gives the camera of `ht_scene_set_camera` its pose at the
/// shutter's closing: the camera a render places is the one a description with that pose
/// as `[camera.shutter_close]` places, moving with the shutter open and still with it
/// closed; `ht_scene_set_camera` makes it still again, and a scene with no camera set, or
/// a NULL pose, is refused with the camera unchanged.
#[test]
fn a_c_host_moves_the_camera_over_the_shutter() {
    let h = Handles::new();
    let (eye, target, y) = ([0.0f32, 0.5, 4.0], [0.0f32, 0.0, 0.0], [0.0f32, 1.0, 0.0]);
    let (eye2, target2) = ([1.0f32, 0.5, 3.5], [0.2f32, 0.0, 0.0]);
    unsafe {
        fails(
            ht_scene_set_camera_motion(h.scene, eye2.as_ptr(), target2.as_ptr(), y.as_ptr(), 30.0),
            HtStatus::HT_ERR_INVALID_ARG,
            "ht_scene_set_camera first",
        );
        let set = ht_scene_set_camera(h.scene, eye.as_ptr(), target.as_ptr(), y.as_ptr(), 40.0);
        assert_eq!(set, HtStatus::HT_OK);
        fails(
            ht_scene_set_camera_motion(h.scene, eye2.as_ptr(), null(), y.as_ptr(), 30.0),
            HtStatus::HT_ERR_NULL_ARG,
            "target",
        );
        let moved =
            ht_scene_set_camera_motion(h.scene, eye2.as_ptr(), target2.as_ptr(), y.as_ptr(), 30.0);
        assert_eq!(moved, HtStatus::HT_OK);
    }
    let mut desc = SceneDescription::default();
    desc.camera.eye = Some(eye);
    desc.camera.target = Some(target);
    desc.camera.fov_deg = 40.0;
    desc.camera.shutter_close = Some(crate::description::PoseDesc {
        eye: Some(eye2),
        target: Some(target2),
        up: Some(y),
        fov_deg: Some(30.0),
    });
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let described = crate::Scene::from_description(&desc, device).unwrap();
    let mut open = RenderSettings::default();
    open.set("shutter_close", "0.5").unwrap();
    for settings in [open, RenderSettings::default()] {
        let placed = h.scene().scene.placed_camera(&settings).unwrap();
        assert_eq!(placed, described.placed_camera(&settings).unwrap());
        assert_eq!(placed.moves(), settings.motion_blur());
    }
    unsafe {
        let set = ht_scene_set_camera(h.scene, eye.as_ptr(), target.as_ptr(), y.as_ptr(), 40.0);
        assert_eq!(set, HtStatus::HT_OK);
    }
    assert!(!(h.scene().scene.placed_camera(&open).unwrap()).moves());
}
