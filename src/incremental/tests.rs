//! The Rust host's scene: edits of a material, a light or the camera render as a fresh
//! build would, without a build; new geometry and settings that need a build rebuild
//! (never refused) and render as a fresh scene; bad edits change nothing.

use std::path::Path;
use std::sync::Arc;

use crate::description::{
    CameraDesc, GroomDesc, GroomSource, LightDesc, MaterialDesc, SceneDescription,
};
use crate::embree::Device;
use crate::render::{Aovs, NoProgress};
use crate::scene::material::{HairColor, HairMaterial};
use crate::scene::{GroomShape, ScalpPatch};
use crate::{Error, Scene};

/// An `auto` fur ball over a ground quad, sky and sun, seen from `z` at 32 x 32 pixels:
/// every strand thinner than a pixel from z = 4 and farther. `brown` and `floor` are the
/// materials' sigma_a and albedo; `rect` adds a rect light.
fn scene(z: f32, brown: [f32; 3], floor: [f32; 3], rect: bool) -> SceneDescription {
    let rect = if rect {
        "[[light]]\ntype = \"rect\"\ncorner = [-1, 2, 2]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, -2]\nradiance = [3, 3, 3]\n"
    } else {
        ""
    };
    let text = format!(
        r#"
[render]
# Level of detail off: a farther view would cut the strands otherwise than the kept build.
lod_pixels = 0
width = 32
height = 32
spp = 4
seed = 5
threads = 2

[camera]
eye = [0, 0.5, {z}]
target = [0, 0, 0]
fov_deg = 40

[materials.brown]
type = "hair"
sigma_a = {brown:?}
absorption_variation = 0.3

[materials.floor]
type = "diffuse"
albedo = {floor:?}

[[groom]]
procedural = "fur_ball"
shape = "auto"
material = "brown"

[groom.params]
strands = 300
segments = 8

[[mesh]]
shape = "ground"
y = -1.2
half_size = 3
material = "floor"

[[light]]
type = "environment"
radiance = [0.3, 0.35, 0.4]

[[light]]
type = "distant"
direction = [1, 1, 1]
irradiance = [2, 2, 1.8]
angular_radius_deg = 2
{rect}"#
    );
    SceneDescription::from_toml(&text, Path::new("."), "edits test").unwrap()
}

fn build(d: &SceneDescription) -> (Scene, Arc<Device>) {
    let device = Arc::new(Device::new(Some(2)).unwrap());
    (d.build(device.clone()).unwrap(), device)
}

fn image(scene: &mut Scene) -> Vec<u32> {
    let out = scene.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// The image of `d` built afresh.
fn fresh(d: &SceneDescription) -> Vec<u32> {
    image(&mut build(d).0)
}

/// The `[camera]` of [`scene`] at `z`.
fn camera(z: f32) -> CameraDesc {
    CameraDesc {
        eye: Some([0.0, 0.5, z]),
        target: Some([0.0; 3]),
        fov_deg: 40.0,
        ..CameraDesc::default()
    }
}

/// Each edit changes the image, leaves the scene's and the device's build counts at 1,
/// and gives the image of the description built with it from the start.
#[test]
fn edits_of_a_material_a_light_and_the_camera_render_as_a_fresh_build_without_one() {
    let (brown, red) = ([0.5447, 0.9061, 1.781], [0.1, 0.6, 1.2]);
    let (grey, blue) = ([0.6; 3], [0.2, 0.4, 0.8]);
    let (mut built, device) = build(&scene(4.0, brown, grey, false));
    let mut last = image(&mut built);
    let mut check = |built: &mut Scene, want: SceneDescription, what: &str| {
        let now = image(built);
        assert_eq!(built.builds(), 1, "{what} built again");
        assert_eq!(device.builds(), 1, "{what} built the BVH again");
        assert!(now != last, "{what} changed nothing");
        assert!(
            now == fresh(&want),
            "{what}: not the image of a fresh build"
        );
        last = now;
    };

    let red_hair = MaterialDesc::Hair(HairMaterial {
        color: HairColor::SigmaA(red),
        absorption_variation: 0.3,
        ..HairMaterial::default()
    });
    built.set_material("brown", &red_hair).unwrap();
    check(&mut built, scene(4.0, red, grey, false), "a hair material");
    built
        .set_material("floor", &MaterialDesc::Diffuse { albedo: blue })
        .unwrap();
    check(
        &mut built,
        scene(4.0, red, blue, false),
        "a diffuse material",
    );
    let with_rect = scene(4.0, red, blue, true);
    built.add_light(&with_rect.lights[2]).unwrap();
    check(&mut built, with_rect, "a light");
    // Farther: every strand stays a ribbon, so the shapes hold and a fresh build agrees.
    built.set_camera(&camera(5.0)).unwrap();
    check(&mut built, scene(5.0, red, blue, true), "a farther camera");
}

/// What the build does not serve is built again, never refused, and renders as a fresh
/// scene: a nearer camera on `auto` strands, then each setting that needs a build; a
/// setting that does not needs no build.
#[test]
fn views_and_settings_the_build_does_not_serve_build_again() {
    let grey = [0.6; 3];
    let brown = [0.5447, 0.9061, 1.781];
    let (mut built, _) = build(&scene(4.0, brown, grey, false));
    image(&mut built);
    built.settings.spp = 2;
    built.settings.seed = 9;
    image(&mut built);
    assert_eq!(built.builds(), 1, "spp and seed need no build");

    // Nearer, strands are wider than the build chose their shapes for.
    built.set_camera(&camera(2.0)).unwrap();
    let mut want = scene(2.0, brown, grey, false);
    want.render = built.settings;
    assert!(image(&mut built) == fresh(&want), "a nearer camera");
    assert_eq!(built.builds(), 2);

    // A taller image: pixels smaller than the build shaped the strands for.
    built.settings.height = 48;
    want.render.height = 48;
    assert!(image(&mut built) == fresh(&want), "a taller image");
    assert_eq!(built.builds(), 3);
    // A wider one sees them no smaller: the camera follows it, with no build.
    built.settings.width = 48;
    want.render.width = 48;
    assert!(image(&mut built) == fresh(&want), "a wider image");
    assert_eq!(built.builds(), 3);
    for (i, (name, value)) in [("lod_pixels", "0.5"), ("curve_parts", "off")]
        .into_iter()
        .enumerate()
    {
        built.settings.set(name, value).unwrap();
        want.render.set(name, value).unwrap();
        assert!(image(&mut built) == fresh(&want), "{name} = {value}");
        assert_eq!(built.builds(), 4 + i as u64, "{name} = {value} built again");
    }
}

/// A groom added after a render builds again, and the scene renders as one made with
/// it from the start; so does one removed.
#[test]
fn a_groom_added_after_a_render_builds_again_as_a_fresh_scene() {
    let without = scene(4.0, [0.5447, 0.9061, 1.781], [0.6; 3], false);
    let mut with = without.clone();
    let mut scalp = GroomDesc::new(
        GroomSource::Scalp(ScalpPatch {
            strands: 200,
            segments: 6,
            ..ScalpPatch::default()
        }),
        "brown",
    );
    scalp.shape = GroomShape::Round;
    with.grooms.push(scalp.clone());
    let (mut built, _) = build(&without);
    let before = image(&mut built);
    assert_eq!(built.add_groom("groom[1]", &scalp).unwrap(), 1);
    assert!(!built.is_built());
    let after = image(&mut built);
    assert_eq!(built.builds(), 2);
    assert!(after != before, "the groom changed nothing");
    assert!(after == fresh(&with), "not the image of a fresh scene");
    // A name in use is refused; a removal builds again, as the scene without it.
    assert!(built.add_groom("groom[1]", &scalp).is_err());
    built.remove_geometry("groom[1]").unwrap();
    assert!(
        image(&mut built) == before,
        "not the scene without the groom"
    );
    assert_eq!(built.builds(), 3);
}

/// A scene made empty and filled by name renders as its description does.
#[test]
fn a_scene_filled_by_name_renders_as_its_description() {
    let d = scene(4.0, [0.5447, 0.9061, 1.781], [0.6; 3], true);
    let mut s = Scene::new(Arc::new(Device::new(Some(2)).unwrap()));
    s.settings = d.render;
    s.set_camera(&d.camera).unwrap();
    // Geometry may name a material defined later.
    s.add_groom("fur", &d.grooms[0]).unwrap();
    s.add_mesh("floor", &d.meshes[0]).unwrap();
    for (name, m) in &d.materials {
        s.set_material(name, m).unwrap();
    }
    for l in &d.lights {
        s.add_light(l).unwrap();
    }
    assert!(image(&mut s) == fresh(&d));
    assert_eq!(s.builds(), 1);
}

#[test]
fn bad_edits_are_refused_and_change_nothing() {
    let d = scene(4.0, [0.5447, 0.9061, 1.781], [0.6; 3], false);
    let (mut built, _) = build(&d);
    let before = image(&mut built);
    let hair = MaterialDesc::Hair(HairMaterial::default());
    let floor = MaterialDesc::Diffuse { albedo: [0.1; 3] };
    let refused = |e: Error, words: &str| assert!(e.to_string().contains(words), "{e}");
    refused(
        built.set_material("brown", &floor).unwrap_err(),
        "curves need a hair material",
    );
    refused(
        built.set_material("floor", &hair).unwrap_err(),
        "meshes need a diffuse material",
    );
    let bright = MaterialDesc::Diffuse { albedo: [2.0; 3] };
    assert!(built.set_material("floor", &bright).is_err());
    refused(built.set_lights(&[]).unwrap_err(), "no lights");
    let dark = [LightDesc::Distant {
        direction: [0.0; 3],
        irradiance: [1.0; 3],
        angular_radius_deg: 0.0,
    }];
    refused(built.set_lights(&dark).unwrap_err(), "light[0]");
    refused(
        built
            .set_camera(&CameraDesc {
                eye: Some([0.0; 3]),
                ..CameraDesc::default()
            })
            .unwrap_err(),
        "camera",
    );
    assert!(
        image(&mut built) == before,
        "a refused edit changed the image"
    );
    assert_eq!(built.builds(), 1);
}

/// Every host's scene refuses a render whose `isa` is not its device's: the device's pin
/// is what it renders with.
#[test]
fn a_render_cannot_repin_the_scene_s_device() {
    let isa = crate::embree::Isa::widest_here().expect("an x86-64 CPU");
    let d = scene(4.0, [0.5447, 0.9061, 1.781], [0.6; 3], false);
    let (mut built, _) = build(&d);
    let mut other = built.settings;
    other.isa = Some(isa);
    let e = (built.render_with(&other, Aovs::default(), &NoProgress)).unwrap_err();
    assert!(e.to_string().contains("pinned"), "{e}");
    let mut pinned =
        Scene::from_description(&d, Arc::new(Device::pinned(Some(2), Some(isa)).unwrap())).unwrap();
    pinned
        .render_with(&other, Aovs::default(), &NoProgress)
        .unwrap();
}
