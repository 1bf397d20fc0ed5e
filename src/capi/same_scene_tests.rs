//! One scene, every front end: a TOML scene file, the C ABI, the Rust `Scene` filled by
//! name, and a USD groom in each render the same pixels, because they are one scene type
//! (`crate::Scene`) that frames an automatic camera the same way. (Python's is checked
//! against the command line and the C library in python/tests/test_same_pixels.py.)

use super::HtStatus;
use super::geometry::*;
use super::lights::*;
use super::scene::*;
use super::scene_tests::{Handles, last_error, small_fur};
use super::settings_tests::Named;
use crate::Scene;
use crate::bsdf::HairParams;
use crate::description::{
    CameraDesc, EnvironmentSource, GroomDesc, GroomSource, LightDesc, MaterialDesc,
    SceneDescription, has_extension,
};
use crate::embree::{CurveBasis, Device};
use crate::formats::convert::{ConvertOptions, ConvertSource, convert};
use crate::formats::hair::{Thickness, write_hair_file};
use crate::render::{Aovs, NoProgress};
use crate::scene::{GroomShape, HairColor, HairMaterial};
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::sync::Arc;

const SIZE: (u32, u32) = (40, 30);
const SETTINGS: [(&str, &str); 4] = [
    ("spp", "4"),
    ("seed", "11"),
    ("threads", "2"),
    ("max_depth", "8"),
];
const EYE: [f32; 3] = [0.3, 0.4, 4.0];
const SKY: [f32; 3] = [0.3, 0.35, 0.4];
const SUN_DIR: [f32; 3] = [1.0, 1.0, 1.0];
const SUN: [f32; 3] = [2.0, 2.0, 1.8];

/// The small fur ball as a `.hair` file and as the `.usda` that `hairtrace convert` writes
/// of it, in a fresh folder.
fn groom_files() -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("hairtrace-same-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (hair, usda) = (dir.join("fur.hair"), dir.join("fur.usda"));
    write_hair_file(&hair, &small_fur(), Thickness::Diameter).unwrap();
    let bspline = ConvertOptions {
        basis: Some(CurveBasis::BSpline),
        ..ConvertOptions::default()
    };
    convert(ConvertSource::File(&hair), &usda, &bspline).unwrap();
    (hair, usda)
}

/// The scene file: the groom `file`, the C ABI's default hair, sky and sun, the camera if
/// asked (else an automatic one), every setting of `SETTINGS`.
fn toml_render(file: &Path, camera: bool) -> Vec<u32> {
    let [r, g, b] = HairParams::default().sigma_a;
    let mut text = format!("[render]\nwidth = {}\nheight = {}\n", SIZE.0, SIZE.1);
    for (k, v) in SETTINGS {
        text += &format!("{k} = {v}\n");
    }
    if camera {
        text += &format!("[camera]\neye = {EYE:?}\ntarget = [0, 0, 0]\nfov_deg = 40\n");
    }
    // A .hair file says no basis of its own; a USD file says its prims'.
    let basis = match has_extension(file, "hair") {
        true => "basis = \"bspline\"\n",
        false => "",
    };
    text += &format!(
        "[materials.hair]\ntype = \"hair\"\nsigma_a = [{r:?}, {g:?}, {b:?}]\n\
         [[groom]]\nfile = {:?}\n{basis}material = \"hair\"\n\
         [[light]]\ntype = \"environment\"\nradiance = {SKY:?}\n\
         [[light]]\ntype = \"distant\"\ndirection = {SUN_DIR:?}\nirradiance = {SUN:?}\n",
        file.display().to_string()
    );
    let desc = SceneDescription::from_toml(&text, Path::new("."), "same.toml").unwrap();
    let mut built = desc.build(Arc::new(Device::new(Some(2)).unwrap())).unwrap();
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// The same through the Rust API: an empty `Scene` filled by name, settings by field.
fn rust_render(file: &Path, camera: bool) -> Vec<u32> {
    let mut scene = rust_scene(camera);
    let hair = HairMaterial {
        color: HairColor::SigmaA(HairParams::default().sigma_a),
        ..HairMaterial::default()
    };
    scene
        .set_material("hair", &MaterialDesc::Hair(hair))
        .unwrap();
    let source = GroomSource::File {
        path: file.to_path_buf(),
        thickness: Thickness::Diameter,
        frame: None,
    };
    let groom = GroomDesc {
        basis: has_extension(file, "hair").then_some(CurveBasis::BSpline),
        shape: GroomShape::Auto,
        ..GroomDesc::new(source, "hair")
    };
    scene.add_groom("fur", &groom).unwrap();
    rust_pixels(&mut scene)
}

/// An empty Rust `Scene` of `SIZE` and `SETTINGS`, lit by the sky and the sun, its camera
/// at `EYE` if asked (else an automatic one).
pub(super) fn rust_scene(camera: bool) -> Scene {
    let mut scene = Scene::new(Arc::new(Device::new(Some(2)).unwrap()));
    (scene.settings.width, scene.settings.height) = SIZE;
    for (k, v) in SETTINGS {
        scene.settings.set(k, v).unwrap();
    }
    if camera {
        let view = CameraDesc {
            eye: Some(EYE),
            target: Some([0.0; 3]),
            fov_deg: 40.0,
            ..CameraDesc::default()
        };
        scene.set_camera(&view).unwrap();
    }
    let sky = LightDesc::Environment {
        source: EnvironmentSource::Uniform(SKY),
        rotation_deg: 0.0,
        scale: 1.0,
    };
    scene.add_light(&sky).unwrap();
    let sun = LightDesc::Distant {
        direction: SUN_DIR,
        irradiance: SUN,
        angular_radius_deg: 0.0,
    };
    scene.add_light(&sun).unwrap();
    scene
}

/// The bits of a Rust scene's render.
pub(super) fn rust_pixels(scene: &mut Scene) -> Vec<u32> {
    let out = scene.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// The same through the C ABI: the groom added by `add`, settings by name.
fn c_render(add: impl FnOnce(&Handles, u32) -> HtStatus, camera: bool) -> Vec<u32> {
    let h = Handles::new();
    let hair = h.hair_material();
    assert_eq!(add(&h, hair), HtStatus::HT_OK, "{}", last_error());
    c_lights(&h, camera);
    c_pixels(&h)
}

/// `rust_scene`'s sky, sun and camera (if asked) on a C scene.
pub(super) fn c_lights(h: &Handles, camera: bool) {
    unsafe {
        assert_eq!(
            ht_scene_add_environment(h.scene, SKY.as_ptr()),
            HtStatus::HT_OK
        );
        let s = ht_scene_add_distant_light(h.scene, SUN_DIR.as_ptr(), SUN.as_ptr(), 0.0);
        assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        if camera {
            let (target, up) = ([0.0f32; 3], [0.0f32, 1.0, 0.0]);
            let s = ht_scene_set_camera(h.scene, EYE.as_ptr(), target.as_ptr(), up.as_ptr(), 40.0);
            assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
        }
    }
}

/// The bits of a C scene's render of `SIZE` and `SETTINGS`, set by name.
pub(super) fn c_pixels(h: &Handles) -> Vec<u32> {
    let (w, h_) = (SIZE.0.to_string(), SIZE.1.to_string());
    let mut pairs = vec![("width", w.as_str()), ("height", h_.as_str())];
    pairs.extend(SETTINGS);
    let (s, rgb) = Named::new(&pairs).render_rgb(h.scene, (SIZE.0 * SIZE.1) as usize);
    assert_eq!(s, HtStatus::HT_OK, "{}", last_error());
    rgb.iter().map(|v| v.to_bits()).collect()
}

fn c_hair(file: &Path) -> impl FnOnce(&Handles, u32) -> HtStatus {
    let path = CString::new(file.to_str().unwrap()).unwrap();
    move |h, material| unsafe {
        ht_scene_add_hair_file(
            h.scene,
            path.as_ptr(),
            false,
            HT_CURVE_BSPLINE,
            HT_CURVE_AUTO,
            material,
            &mut 0,
        )
    }
}

fn c_usd(file: &Path) -> impl FnOnce(&Handles, u32) -> HtStatus {
    let path = CString::new(file.to_str().unwrap()).unwrap();
    move |h, material| unsafe {
        let (mut first, mut count) = (0, 0);
        ht_scene_add_usd_file(
            h.scene,
            path.as_ptr(),
            HT_CURVE_AUTO,
            material,
            &mut first,
            &mut count,
        )
    }
}

/// Panics, with the count of differing values rather than the images, unless `got` is
/// `want` bit for bit.
fn assert_same(got: &[u32], want: &[u32], what: &str) {
    let differ = got.iter().zip(want).filter(|(a, b)| a != b).count();
    assert!(
        got.len() == want.len() && differ == 0,
        "{what}: {differ} of {} values differ",
        want.len()
    );
}

#[test]
fn toml_c_rust_and_usd_render_the_same_scene_bit_for_bit() {
    let (hair, usda) = groom_files();
    let reference = toml_render(&hair, true);
    assert!(reference.iter().any(|&v| f32::from_bits(v) > 0.0));
    assert_same(&toml_render(&usda, true), &reference, "TOML, USD groom");
    assert_same(&c_render(c_hair(&hair), true), &reference, "C, .hair groom");
    assert_same(&c_render(c_usd(&usda), true), &reference, "C, USD groom");
    assert_same(&rust_render(&hair, true), &reference, "Rust, .hair groom");
    assert_same(&rust_render(&usda, true), &reference, "Rust, USD groom");
    // Without a camera, C and TOML frame the same content alike. (A USD groom is framed
    // by its authored bounds widened by its largest radius, a `.hair` one point by point,
    // so the two sources frame a little differently.)
    let framed = toml_render(&hair, false);
    assert_same(
        &c_render(c_hair(&hair), false),
        &framed,
        "C framed, .hair groom",
    );
    assert_same(
        &rust_render(&hair, false),
        &framed,
        "Rust framed, .hair groom",
    );
    let framed = toml_render(&usda, false);
    assert_same(
        &c_render(c_usd(&usda), false),
        &framed,
        "C framed, USD groom",
    );
}
