//! Motion through the C ABI: strands and meshes at each time step from host arrays, and
//! animated grooms read at a frame over the shutter of the settings given, render as the
//! Rust `Scene` and scene files render them; bad steps and frames are refused, named.

use super::HtStatus;
use super::geometry::*;
use super::lights::*;
use super::scene::ht_scene_set_camera;
use super::scene_tests::{Handles, fails, last_error};
use super::settings::HtSettings;
use super::settings_tests::Named;
use crate::Scene;
use crate::bsdf::HairParams;
use crate::description::{
    CameraDesc, EnvironmentSource, LightDesc, MaterialDesc, MeshDesc, MeshSource, SceneDescription,
};
use crate::embree::{CurveBasis, Device, SharedBuffer};
use crate::formats::hair::{Thickness, read_hair_file, write_hair_file};
use crate::incremental::ControlPoints;
use crate::render::{Aovs, NoProgress};
use crate::scene::{GroomShape, HairColor, HairMaterial, Mesh, Strands};
use std::ffi::CString;
use std::path::Path;
use std::ptr::null;
use std::sync::Arc;

const SIZE: (u32, u32) = (40, 30);
const SETTINGS: [(&str, &str); 5] = [
    ("spp", "4"),
    ("seed", "3"),
    ("threads", "2"),
    ("shutter_open", "-0.5"),
    ("shutter_close", "0.5"),
];
const SKY: [f32; 3] = [0.5, 0.5, 0.6];
const STRANDS: usize = 400;

/// Linear strands of 4 control points standing on a 20 x 20 grid, and the same strands
/// `dx` along x.
fn grid(dx: f32) -> Vec<[f32; 4]> {
    (0..STRANDS)
        .flat_map(|s| {
            let (x, z) = (
                (s % 20) as f32 * 0.1 - 1.0 + dx,
                (s / 20) as f32 * 0.1 - 1.0,
            );
            (0..4).map(move |k| [x + 0.05 * k as f32, k as f32 * 0.4 - 0.6, z, 0.01])
        })
        .collect()
}

fn c_render(pairs: &[(&str, &str)], steps: &[Vec<[f32; 4]>]) -> Vec<u32> {
    let h = Handles::new();
    let hair = h.hair_material();
    let counts = vec![4u32; STRANDS];
    let desc = HtCurvesXyzr {
        strand_count: STRANDS,
        point_counts: counts.as_ptr(),
        point_count: steps[0].len(),
        points: steps[0].as_ptr().cast(),
        colors: null(),
        basis: HT_CURVE_LINEAR,
        shape: HT_CURVE_ROUND,
    };
    let later: Vec<*const f32> = steps[1..].iter().map(|s| s.as_ptr().cast()).collect();
    unsafe {
        let s = ht_scene_add_curves_xyzr_motion(
            h.scene,
            &desc,
            later.as_ptr(),
            later.len(),
            hair,
            &mut 0,
        );
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    }
    c_under_the_sky(&h, pairs)
}

/// The C scene of `h` under the sky, rendered at `SIZE` with `pairs` set, as bits.
fn c_under_the_sky(h: &Handles, pairs: &[(&str, &str)]) -> Vec<u32> {
    let sky = unsafe { ht_scene_add_environment(h.scene, SKY.as_ptr()) };
    assert_eq!(sky, HtStatus::HT_OK);
    let (w, h_) = (SIZE.0.to_string(), SIZE.1.to_string());
    let mut all = vec![("width", w.as_str()), ("height", h_.as_str())];
    all.extend(pairs);
    let (s, rgb) = Named::new(&all).render_rgb(h.scene, (SIZE.0 * SIZE.1) as usize);
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    rgb.iter().map(|v| v.to_bits()).collect()
}

/// A Rust `Scene` of `SIZE` with every setting of `SETTINGS`.
fn rust_scene() -> Scene {
    let mut scene = Scene::new(Arc::new(Device::new(Some(2)).unwrap()));
    (scene.settings.width, scene.settings.height) = SIZE;
    for (k, v) in SETTINGS {
        scene.settings.set(k, v).unwrap();
    }
    scene
}

/// `scene` under the sky, rendered, as bits.
fn under_the_sky(mut scene: Scene) -> Vec<u32> {
    let sky = LightDesc::Environment {
        source: EnvironmentSource::Uniform(SKY),
        rotation_deg: 0.0,
        scale: 1.0,
    };
    scene.add_light(&sky).unwrap();
    let out = scene.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

fn rust_render(steps: &[Vec<[f32; 4]>]) -> Vec<u32> {
    let mut scene = rust_scene();
    let hair = HairMaterial {
        color: HairColor::SigmaA(HairParams::default().sigma_a),
        ..HairMaterial::default()
    };
    (scene.set_material("hair", &MaterialDesc::Hair(hair))).unwrap();
    let points = ControlPoints {
        points: SharedBuffer::from(steps[0].clone()),
        later_steps: steps[1..].iter().map(|s| s.clone().into()).collect(),
        counts: vec![4; STRANDS],
        colors: None,
        basis: CurveBasis::Linear,
    };
    (scene.add_control_points("grid", points, GroomShape::Round, "hair")).unwrap();
    under_the_sky(scene)
}

/// Three time steps from host arrays and the shutter set by name render bit for bit as the
/// Rust `Scene` renders the same control points; without the shutter, the same strands
/// render otherwise (at the opening).
#[test]
fn strands_in_motion_from_c_render_as_from_rust() {
    let steps = [grid(0.0), grid(0.05), grid(0.2)];
    let c = c_render(&SETTINGS, &steps);
    assert_eq!(c, rust_render(&steps));
    let still = c_render(&SETTINGS[..3], &steps);
    assert_ne!(c, still);
}

/// NULL later points, a NaN at a later step, and more steps than Embree takes are refused,
/// the message naming the array or the step.
#[test]
fn bad_time_steps_from_c_are_refused() {
    let h = Handles::new();
    let hair = h.hair_material();
    let counts = vec![4u32; STRANDS];
    let first = grid(0.0);
    let desc = HtCurvesXyzr {
        strand_count: STRANDS,
        point_counts: counts.as_ptr(),
        point_count: first.len(),
        points: first.as_ptr().cast(),
        colors: null(),
        basis: HT_CURVE_LINEAR,
        shape: HT_CURVE_ROUND,
    };
    let add = |later: *const *const f32, n: usize| unsafe {
        ht_scene_add_curves_xyzr_motion(h.scene, &desc, later, n, hair, &mut 0)
    };
    fails(add(null(), 1), HtStatus::HT_ERR_NULL_ARG, "later_points");
    let missing = [null::<f32>()];
    fails(
        add(missing.as_ptr(), 1),
        HtStatus::HT_ERR_NULL_ARG,
        "later_points[0]",
    );
    let mut nan = grid(0.1);
    nan[9][2] = f32::NAN;
    let second = grid(0.1);
    let later = [second.as_ptr().cast::<f32>(), nan.as_ptr().cast()];
    fails(
        add(later.as_ptr(), 2),
        HtStatus::HT_ERR_INVALID_ARG,
        "time step 2",
    );
    let many = vec![second.as_ptr().cast::<f32>(); HT_MAX_TIME_STEPS];
    fails(
        add(many.as_ptr(), HT_MAX_TIME_STEPS),
        HtStatus::HT_ERR_INVALID_ARG,
        "later_step_count",
    );
    // The good step alone is taken.
    assert_eq!(add(later.as_ptr(), 1), HtStatus::HT_OK, "{}", last_error());
}

/// A strip of `QUADS` quads along x at height `y`, two triangles each, and the same strip
/// bent by `bend` (its vertices lifted along z by `bend` times their x).
fn strip(bend: f32) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    const QUADS: u32 = 8;
    let positions = (0..=QUADS)
        .flat_map(|i| {
            let x = i as f32 * 0.25 - 1.0;
            [[x, -0.5, bend * x], [x, 0.5, bend * x]]
        })
        .collect();
    let triangles = (0..QUADS)
        .flat_map(|i| {
            [
                [2 * i, 2 * i + 2, 2 * i + 1],
                [2 * i + 1, 2 * i + 2, 2 * i + 3],
            ]
        })
        .collect();
    (positions, triangles)
}

const GREY: [f32; 3] = [0.6, 0.5, 0.4];
const MESH_EYE: [f32; 3] = [0.3, 0.2, 3.0];

/// The mesh at `steps` from C, under the sky, seen from `MESH_EYE`, with `pairs` set.
fn c_mesh_render(
    pairs: &[(&str, &str)],
    steps: &[Vec<[f32; 3]>],
    triangles: &[[u32; 3]],
) -> Vec<u32> {
    let h = Handles::new();
    let grey = h.diffuse_material(GREY);
    let later: Vec<*const f32> = steps[1..].iter().map(|s| s.as_ptr().cast()).collect();
    let (target, up) = ([0.0f32; 3], [0.0f32, 1.0, 0.0]);
    unsafe {
        let s = ht_scene_add_mesh_motion(
            h.scene,
            steps[0].len(),
            steps[0].as_ptr().cast(),
            later.as_ptr(),
            later.len(),
            triangles.len(),
            triangles.as_ptr().cast(),
            grey,
            &mut 0,
        );
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        let s = ht_scene_set_camera(
            h.scene,
            MESH_EYE.as_ptr(),
            target.as_ptr(),
            up.as_ptr(),
            40.0,
        );
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    }
    c_under_the_sky(&h, pairs)
}

/// The same mesh through the Rust `Scene`.
fn rust_mesh_render(steps: &[Vec<[f32; 3]>], triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut scene = rust_scene();
    let grey = MaterialDesc::Diffuse { albedo: GREY };
    scene.set_material("grey", &grey).unwrap();
    let mesh = Mesh {
        positions: steps[0].clone(),
        triangles: triangles.to_vec(),
        normals: None,
        later_positions: steps[1..].to_vec(),
    };
    let desc = MeshDesc::new(MeshSource::Triangles(mesh), "grey");
    scene.add_mesh("strip", &desc).unwrap();
    let view = CameraDesc {
        eye: Some(MESH_EYE),
        target: Some([0.0; 3]),
        fov_deg: 40.0,
        ..CameraDesc::default()
    };
    scene.set_camera(&view).unwrap();
    under_the_sky(scene)
}

/// A mesh deforming over three time steps from host arrays renders bit for bit as the Rust
/// `Scene` renders the same vertices; with the shutter closed it renders otherwise.
#[test]
fn a_deforming_mesh_from_c_renders_as_from_rust() {
    let (flat, triangles) = strip(0.0);
    let steps = [flat, strip(0.5).0, strip(1.0).0];
    let c = c_mesh_render(&SETTINGS, &steps, &triangles);
    assert_eq!(c, rust_mesh_render(&steps, &triangles));
    assert_ne!(c, c_mesh_render(&SETTINGS[..3], &steps, &triangles));
}

/// NULL later positions, a NaN at a later step, and more steps than Embree takes are
/// refused, the message naming the array or the step; nothing is added.
#[test]
fn bad_mesh_steps_from_c_are_refused() {
    let h = Handles::new();
    let grey = h.diffuse_material(GREY);
    let (first, triangles) = strip(0.0);
    let add = |later: *const *const f32, n: usize| unsafe {
        let (v, t) = (first.len(), triangles.len());
        let (p, i) = (first.as_ptr().cast(), triangles.as_ptr().cast());
        ht_scene_add_mesh_motion(h.scene, v, p, later, n, t, i, grey, &mut 0)
    };
    fails(add(null(), 1), HtStatus::HT_ERR_NULL_ARG, "later_positions");
    let missing = [null::<f32>()];
    fails(
        add(missing.as_ptr(), 1),
        HtStatus::HT_ERR_NULL_ARG,
        "later_positions[0]",
    );
    let misaligned = [first.as_ptr().cast::<u8>().wrapping_add(1).cast::<f32>()];
    fails(
        add(misaligned.as_ptr(), 1),
        HtStatus::HT_ERR_INVALID_ARG,
        "later_positions[0]",
    );
    let second = strip(0.5).0;
    let mut nan = strip(1.0).0;
    nan[3][1] = f32::NAN;
    let later = [second.as_ptr().cast::<f32>(), nan.as_ptr().cast()];
    fails(
        add(later.as_ptr(), 2),
        HtStatus::HT_ERR_INVALID_ARG,
        "time step 2: vertex 3",
    );
    let many = vec![second.as_ptr().cast::<f32>(); HT_MAX_TIME_STEPS];
    fails(
        add(many.as_ptr(), HT_MAX_TIME_STEPS),
        HtStatus::HT_ERR_INVALID_ARG,
        "later_step_count",
    );
    let hair = h.hair_material();
    let s = unsafe {
        let (v, t) = (first.len(), triangles.len());
        let (p, i) = (first.as_ptr().cast(), triangles.as_ptr().cast());
        ht_scene_add_mesh_motion(h.scene, v, p, later.as_ptr(), 1, t, i, hair, &mut 0)
    };
    fails(s, HtStatus::HT_ERR_INVALID_ARG, "hair");
    assert_eq!(h.scene().geometries, 0, "nothing was added");
    assert_eq!(add(later.as_ptr(), 1), HtStatus::HT_OK, "{}", last_error());
}

/// `examples/scenes/swaying.toml` without its ground, with the C ABI's default hair, small
/// and quick, its shutter `shutter` (open, close), at frame `frame`.
fn swaying(frame: f64, shutter: (&str, &str)) -> SceneDescription {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut desc = SceneDescription::load(&root.join("examples/scenes/swaying.toml")).unwrap();
    desc.meshes.clear();
    let hair = HairMaterial {
        color: HairColor::SigmaA(HairParams::default().sigma_a),
        ..HairMaterial::default()
    };
    desc.materials
        .insert("brown".into(), MaterialDesc::Hair(hair));
    (desc.render.width, desc.render.height) = SIZE;
    for (k, v) in SETTINGS[..3]
        .iter()
        .chain(&[("shutter_open", shutter.0), ("shutter_close", shutter.1)])
    {
        desc.render.set(k, v).unwrap();
    }
    desc.at_frame(frame).unwrap();
    desc
}

fn description_render(desc: &SceneDescription) -> Vec<u32> {
    let mut built = desc.build(Arc::new(Device::new(Some(2)).unwrap())).unwrap();
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// The scene of `desc` through the C ABI, its USD groom added by `add` with the settings
/// of the render.
fn c_swaying(
    desc: &SceneDescription,
    add: impl FnOnce(&Handles, *const HtSettings, u32) -> HtStatus,
) -> Vec<u32> {
    let h = Handles::new();
    let hair = h.hair_material();
    let (w, h_) = (SIZE.0.to_string(), SIZE.1.to_string());
    let (open, close) = (
        desc.render.get("shutter_open").unwrap(),
        desc.render.get("shutter_close").unwrap(),
    );
    let mut pairs = vec![("width", w.as_str()), ("height", h_.as_str())];
    pairs.extend(&SETTINGS[..3]);
    pairs.extend([
        ("shutter_open", open.as_str()),
        ("shutter_close", close.as_str()),
    ]);
    let settings = Named::new(&pairs);
    assert_eq!(
        add(&h, settings.0, hair),
        HtStatus::HT_OK,
        "{}",
        last_error()
    );
    let camera = &desc.camera;
    let up = [0.0f32, 1.0, 0.0];
    unsafe {
        let (eye, target) = (camera.eye.unwrap(), camera.target.unwrap());
        let s = ht_scene_set_camera(
            h.scene,
            eye.as_ptr(),
            target.as_ptr(),
            up.as_ptr(),
            camera.fov_deg,
        );
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        for light in &desc.lights {
            let s = match light {
                LightDesc::Environment {
                    source: EnvironmentSource::Uniform(sky),
                    ..
                } => ht_scene_add_environment(h.scene, sky.as_ptr()),
                LightDesc::Distant {
                    direction,
                    irradiance,
                    angular_radius_deg,
                } => ht_scene_add_distant_light(
                    h.scene,
                    direction.as_ptr(),
                    irradiance.as_ptr(),
                    *angular_radius_deg,
                ),
                other => panic!("swaying.toml has no {other:?}"),
            };
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        }
    }
    let (s, rgb) = settings.render_rgb(h.scene, (SIZE.0 * SIZE.1) as usize);
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    rgb.iter().map(|v| v.to_bits()).collect()
}

fn c_usd_at(path: &Path, frame: f64) -> impl FnOnce(&Handles, *const HtSettings, u32) -> HtStatus {
    let path = CString::new(path.to_str().unwrap()).unwrap();
    move |h, settings, material| unsafe {
        let (mut first, mut count) = (0, 0);
        let s = ht_scene_add_usd_file_at(
            h.scene,
            path.as_ptr(),
            frame,
            settings,
            HT_CURVE_AUTO,
            material,
            &mut first,
            &mut count,
        );
        assert!(s != HtStatus::HT_OK || count == 1);
        s
    }
}

/// The animated example read at frame 6 through the C ABI renders bit for bit as the scene
/// file read at that frame (`render --frame 6`), with the shutter closed and open: an open
/// shutter reads the stage's time steps over it from C as the scene file does.
#[test]
fn an_animated_usd_groom_at_a_frame_from_c_renders_as_the_scene_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let usda = root.join("examples/scenes/swaying.usda");
    let still = swaying(6.0, ("0", "0"));
    let reference = description_render(&still);
    assert_eq!(c_swaying(&still, c_usd_at(&usda, 6.0)), reference);
    assert_ne!(description_render(&swaying(12.0, ("0", "0"))), reference);
    // Frames 5.5 to 12.5: the time sample at 12 is a step of its own.
    let blurred = swaying(6.0, ("-0.5", "6.5"));
    let moving = description_render(&blurred);
    assert_ne!(moving, reference);
    assert_eq!(c_swaying(&blurred, c_usd_at(&usda, 6.0)), moving);
}

/// A frame that is not finite, or outside the animation, and settings that do not hold
/// together are refused, naming what is wrong; nothing is added.
#[test]
fn a_bad_frame_from_c_is_refused() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let usda = root.join("examples/scenes/swaying.usda");
    let h = Handles::new();
    let hair = h.hair_material();
    let add = |frame, settings| c_usd_at(&usda, frame)(&h, settings, hair);
    fails(
        add(f64::NAN, null()),
        HtStatus::HT_ERR_INVALID_ARG,
        "frame = NaN: must be finite",
    );
    fails(add(40.0, null()), HtStatus::HT_ERR_INVALID_ARG, "frame 40");
    let backwards = Named::new(&[("shutter_open", "0.5"), ("shutter_close", "0")]);
    fails(
        add(6.0, backwards.0),
        HtStatus::HT_ERR_INVALID_ARG,
        "the shutter closes before it opens",
    );
    assert_eq!(h.scene().geometries, 0, "nothing was added");
    assert_eq!(add(6.0, null()), HtStatus::HT_OK, "{}", last_error());
}

/// A two-file `.hair` sequence read at frame 1 through the C ABI with the shutter open over
/// [0, 1] renders bit for bit as the host's strands given the two files as time steps; a
/// missing file, a frame between files and files of other strands are refused, naming the
/// files.
#[test]
fn a_hair_sequence_at_a_frame_from_c_moves_over_the_shutter() {
    let dir = std::env::temp_dir().join(format!("hairtrace-c-sequence-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let steps = [grid(0.0), grid(0.1)];
    for (frame, step) in [(1, &steps[0]), (2, &steps[1])] {
        let strands = Strands {
            points: step.iter().map(|p| [p[0], p[1], p[2]]).collect(),
            radii: step.iter().map(|p| p[3]).collect(),
            counts: vec![4; STRANDS],
            colors: None,
        };
        let file = dir.join(format!("grid.{frame:04}.hair"));
        write_hair_file(&file, &strands, Thickness::Radius).unwrap();
    }
    let pattern = CString::new(dir.join("grid.####.hair").to_str().unwrap()).unwrap();
    let from_file = |frame: f64, pairs: &[(&str, &str)]| {
        let h = Handles::new();
        let hair = h.hair_material();
        let settings = Named::new(pairs);
        let s = unsafe {
            ht_scene_add_hair_file_at(
                h.scene,
                pattern.as_ptr(),
                frame,
                settings.0,
                true,
                HT_CURVE_LINEAR,
                HT_CURVE_ROUND,
                hair,
                &mut 0,
            )
        };
        (h, s)
    };
    let shutter = [("shutter_open", "0"), ("shutter_close", "1")];
    let (h, s) = from_file(1.0, &shutter);
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    let mut pairs = SETTINGS[..3].to_vec();
    pairs.extend(shutter);
    assert_eq!(c_under_the_sky(&h, &pairs), c_render(&pairs, &steps));

    fails(
        from_file(3.0, &shutter).1,
        HtStatus::HT_ERR_INVALID_ARG,
        "grid.0003.hair does not exist",
    );
    let (_, s) = from_file(2.0, &shutter);
    fails(
        s,
        HtStatus::HT_ERR_INVALID_ARG,
        "the shutter of frame 2 spans frames 2 to 3",
    );
    fails(
        from_file(1.5, &[]).1,
        HtStatus::HT_ERR_INVALID_ARG,
        "whole frames",
    );
    let mut fewer = read_hair_file(&dir.join("grid.0002.hair"), Thickness::Radius).unwrap();
    fewer.counts.pop();
    fewer.points.truncate(fewer.points.len() - 4);
    fewer.radii.truncate(fewer.radii.len() - 4);
    write_hair_file(&dir.join("grid.0002.hair"), &fewer, Thickness::Radius).unwrap();
    let (_, s) = from_file(1.0, &shutter);
    fails(
        s,
        HtStatus::HT_ERR_INVALID_ARG,
        "grid.0002.hair (399 strands",
    );
    assert!(
        last_error().contains("grid.0001.hair (400 strands"),
        "{}",
        last_error()
    );
}
