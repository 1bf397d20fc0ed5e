//! A built scene edited through the Rust API (`BuiltScene::set_material`, `set_lights`,
//! a new camera): no BVH build, and the image of the description built with the edits.

use std::path::Path;
use std::sync::Arc;

use crate::description::{LightDesc, MaterialDesc, SceneDescription};
use crate::embree::Device;
use crate::render::{Aovs, NoProgress};
use crate::scene::camera::Camera;
use crate::scene::detail_view::DetailView;
use crate::scene::material::{HairColor, HairMaterial};
use crate::{BuiltScene, Error};
use glam::Vec3;

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

fn build(d: &SceneDescription) -> (BuiltScene, Arc<Device>) {
    let device = Arc::new(Device::new(Some(2)).unwrap());
    (d.build(device.clone()).unwrap(), device)
}

fn image(built: &BuiltScene) -> Vec<u32> {
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// Each edit changes the image, leaves the device's build count at 1, and gives the image
/// of the description built with it from the start.
#[test]
fn edits_of_a_built_scene_render_as_a_fresh_build_without_one() {
    let (brown, red) = ([0.5447, 0.9061, 1.781], [0.1, 0.6, 1.2]);
    let (grey, blue) = ([0.6; 3], [0.2, 0.4, 0.8]);
    let (mut built, device) = build(&scene(4.0, brown, grey, false));
    let mut last = image(&built);
    let fresh = |d: SceneDescription| image(&build(&d).0);
    let mut check = |built: &BuiltScene, want: SceneDescription, what: &str| {
        let now = image(built);
        assert_eq!(device.builds(), 1, "{what} built the BVH again");
        assert!(now != last, "{what} changed nothing");
        assert!(now == fresh(want), "{what}: not the image of a fresh build");
        last = now;
    };

    let red_hair = MaterialDesc::Hair(HairMaterial {
        color: HairColor::SigmaA(red),
        absorption_variation: 0.3,
        ..HairMaterial::default()
    });
    built.set_material("brown", &red_hair).unwrap();
    check(&built, scene(4.0, red, grey, false), "a hair material");
    built
        .set_material("floor", &MaterialDesc::Diffuse { albedo: blue })
        .unwrap();
    check(&built, scene(4.0, red, blue, false), "a diffuse material");
    let with_rect = scene(4.0, red, blue, true);
    built.set_lights(&with_rect.lights).unwrap();
    check(&built, with_rect, "a light");
    // Farther: every strand stays a ribbon, so the shapes hold and a fresh build agrees.
    built.camera = camera(5.0);
    assert!(built.world.tracer.serves(&DetailView::new(
        built.camera,
        32,
        built.settings.lod_pixels
    )));
    check(&built, scene(5.0, red, blue, true), "a farther camera");

    // Nearer and with more pixels, strands are wider than the build assumed: refused.
    built.camera = camera(2.0);
    built.settings.width = 800;
    built.settings.height = 800;
    let err = built.render(Aovs::default(), &NoProgress).unwrap_err();
    assert!(err.to_string().contains("build the scene again"), "{err}");
    assert_eq!(device.builds(), 1);
}

/// The camera of [`scene`] at `z`.
fn camera(z: f32) -> Camera {
    Camera::new(Vec3::new(0.0, 0.5, z), Vec3::ZERO, Vec3::Y, 40.0, 1.0).unwrap()
}

#[test]
fn bad_edits_are_refused_and_change_nothing() {
    let d = scene(4.0, [0.5447, 0.9061, 1.781], [0.6; 3], false);
    let (mut built, _) = build(&d);
    let before = image(&built);
    let hair = MaterialDesc::Hair(HairMaterial::default());
    let floor = MaterialDesc::Diffuse { albedo: [0.1; 3] };
    let refused = |e: Error, words: &str| assert!(e.to_string().contains(words), "{e}");
    refused(
        built.set_material("nothing", &hair).unwrap_err(),
        "\"nothing\"",
    );
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
    assert!(image(&built) == before, "a refused edit changed the image");
}
