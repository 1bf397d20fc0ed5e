//! USD meshes and cameras read at a frame and over the shutter: frame F of an animated
//! Mesh or Camera prim renders bit for bit as the stage written still at F, a USD camera is
//! the camera its transform and lens describe (tenths of a scene unit for the lens, the
//! stage's axes and units), an open shutter reads both at its time steps, and bad input is
//! refused naming the prim, the attribute and the time.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hairtrace::description::{MeshDesc, MeshSource, SceneDescription};
use hairtrace::embree::Device;
use hairtrace::formats::units::{StageUnits, UpAxis};
use hairtrace::formats::usd::{Prims, read_usd_prims_at};
use hairtrace::glam::Vec3;
use hairtrace::scene::{Camera, Mesh};
use hairtrace::{Aovs, NoProgress, Scene};

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-usdm-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const HEADER: &str = "#usda 1.0\n(\nmetersPerUnit = 1\nstartTimeCode = 1\nendTimeCode = 3\n)\n";

/// A quad under a moving Xform, its far edge swinging back; `counts`, `indices`, `points`
/// and `translate` are the attributes' bodies. Every number is a short binary fraction,
/// so that USD's interpolation halfway between two samples is exact.
fn mesh_stage(counts: &str, indices: &str, points: &str, translate: &str) -> String {
    format!(
        "{HEADER}def Xform \"World\"\n{{\ndouble3 xformOp:translate{translate}\n\
         uniform token[] xformOpOrder = [\"xformOp:translate\"]\n\
         def Mesh \"quad\"\n{{\nint[] faceVertexCounts{counts}\nint[] faceVertexIndices{indices}\n\
         point3f[] points{points}\n}}\n}}\n"
    )
}

fn animated_mesh() -> String {
    mesh_stage(
        " = [4]",
        " = [0, 1, 2, 3]",
        ".timeSamples = { 1: [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], \
         3: [(-1, -1, 0), (1, -1, -0.5), (1, 1, -0.5), (-1, 1, 0)] }",
        ".timeSamples = { 1: (0, 0, 0), 3: (0.5, 0, 0) }",
    )
}

fn mesh_still_at_2() -> String {
    mesh_stage(
        " = [4]",
        " = [0, 1, 2, 3]",
        " = [(-1, -1, 0), (1, -1, -0.25), (1, 1, -0.25), (-1, 1, 0)]",
        " = (0.25, 0, 0)",
    )
}

/// A camera sliding along x and zooming out, `translate` and `focal` its attributes'
/// bodies.
fn camera_stage(translate: &str, focal: &str, extra: &str) -> String {
    format!(
        "{HEADER}def Camera \"cam\"\n{{\ndouble3 xformOp:translate{translate}\n\
         uniform token[] xformOpOrder = [\"xformOp:translate\"]\nfloat focalLength{focal}\n\
         float verticalAperture = 24\n{extra}}}\n"
    )
}

fn animated_camera() -> String {
    camera_stage(
        ".timeSamples = { 1: (0, 0, 4), 3: (1, 0, 4) }",
        ".timeSamples = { 1: 50.0, 3: 40.0 }",
        "",
    )
}

/// A scene of `body` (its `[camera]` and `[[mesh]]` entries) with `animation` as its
/// `[animation]` table, in `dir`.
fn scene(dir: &Path, body: &str, animation: &str) -> SceneDescription {
    let text = format!(
        "[render]\nwidth = 32\nheight = 24\nspp = 2\nthreads = 1\n{animation}\n\
         [materials.d]\ntype = \"diffuse\"\nalbedo = [0.7, 0.5, 0.3]\n{body}\n\
         [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n"
    );
    SceneDescription::from_toml(&text, dir, "usd.toml").unwrap()
}

const EYE: &str = "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\n";
const SPHERE: &str = "[[mesh]]\nshape = \"sphere\"\nradius = 1\nmaterial = \"d\"\n";

fn device() -> Arc<Device> {
    Arc::new(Device::new(Some(1)).unwrap())
}

fn pixels(desc: SceneDescription) -> Vec<u32> {
    let mut built = desc.build(device()).unwrap();
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

fn camera_of(desc: &SceneDescription) -> hairtrace::Result<Camera> {
    Scene::from_description(desc, device())?.placed_camera(&desc.render)
}

fn error(r: hairtrace::Result<impl std::fmt::Debug>) -> String {
    r.expect_err("an error").to_string()
}

fn usd_mesh(file: &str) -> String {
    format!("[[mesh]]\nfile = \"{file}\"\nmaterial = \"d\"\n")
}

#[test]
fn frame_f_of_an_animated_usd_mesh_renders_bit_for_bit_as_the_mesh_written_still_at_f() {
    let dir = scratch("mesh");
    std::fs::write(dir.join("anim.usda"), animated_mesh()).unwrap();
    std::fs::write(dir.join("still.usda"), mesh_still_at_2()).unwrap();
    let body = |file| format!("{EYE}{}", usd_mesh(file));
    let frame_2 = pixels(scene(&dir, &body("anim.usda"), "[animation]\nframe = 2"));
    let sky = frame_2.iter().filter(|&&v| v == 1.0f32.to_bits()).count();
    assert!(sky + 100 < frame_2.len(), "the quad is in view");
    assert!(frame_2 == pixels(scene(&dir, &body("still.usda"), "")));
    assert!(frame_2 != pixels(scene(&dir, &body("anim.usda"), "[animation]\nframe = 3")));
    // The quad is fanned into two triangles, the Xform's translation applied.
    let read = read_usd_prims_at(&dir.join("anim.usda"), Some(2.0), Prims::Meshes).unwrap();
    assert_eq!(read.meshes[0].triangles, [[0, 1, 2], [0, 2, 3]]);
    assert_eq!(read.meshes[0].points[1], [1.25, -1.0, -0.25]);
}

#[test]
fn frame_f_of_an_animated_usd_camera_renders_bit_for_bit_as_the_camera_written_still_at_f() {
    let dir = scratch("camera");
    std::fs::write(dir.join("anim.usda"), animated_camera()).unwrap();
    let still = camera_stage(" = (0.5, 0, 4)", " = 45", "");
    std::fs::write(dir.join("still.usda"), still).unwrap();
    let body = |file| format!("[camera]\nusd = \"{file}\"\n{SPHERE}");
    let frame_2 = pixels(scene(&dir, &body("anim.usda"), "[animation]\nframe = 2"));
    assert!(frame_2 == pixels(scene(&dir, &body("still.usda"), "")));
    assert!(frame_2 != pixels(scene(&dir, &body("anim.usda"), "[animation]\nframe = 3")));
}

/// The vertical field of view of a lens is 2 atan(verticalAperture / (2 focalLength)).
fn fov(focal: f64) -> f64 {
    f64::from((2.0 * (12.0 / focal).atan()).to_degrees() as f32)
}

/// A USD camera at a frame is the `[camera]` of its eye, view and field of view; over an
/// open shutter, the `[camera]` with those at the shutter's closing as
/// `[camera.shutter_close]`.
#[test]
fn a_usd_camera_is_the_camera_its_transform_and_lens_describe_and_moves_over_the_shutter() {
    let dir = scratch("camera-pose");
    std::fs::write(dir.join("anim.usda"), animated_camera()).unwrap();
    let usd = format!("[camera]\nusd = \"anim.usda\"\nprim = \"/cam\"\n{SPHERE}");
    let at_1 = scene(&dir, &usd, "[animation]\nframe = 1");
    let toml = format!(
        "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 3]\nfov_deg = {:?}\n{SPHERE}",
        fov(50.0)
    );
    assert_eq!(
        camera_of(&at_1).unwrap(),
        camera_of(&scene(&dir, &toml, "")).unwrap()
    );

    let mut blurred = at_1.clone();
    blurred.render.set("shutter_close", "1").unwrap();
    let moving = camera_of(&blurred).unwrap();
    assert!(moving.moves());
    let mut toml = scene(
        &dir,
        &format!(
            "{toml}[camera.shutter_close]\neye = [0.5, 0, 4]\ntarget = [0.5, 0, 3]\n\
             fov_deg = {:?}\n",
            fov(45.0)
        ),
        "",
    );
    toml.render.set("shutter_close", "1").unwrap();
    assert_eq!(moving, camera_of(&toml).unwrap());
    assert!(pixels(blurred) == pixels(toml));
}

/// A Z-up centimetre stage: the camera looks down its -z, the stage's down; its lens of
/// 50 tenths of a centimetre at f/2 is a thin lens of radius 50 x 0.1 / (2 x 2) cm,
/// focused at 300 cm.
#[test]
fn a_usd_cameras_lens_is_in_tenths_of_a_scene_unit_and_its_pose_in_the_stages_axes() {
    let dir = scratch("camera-units");
    let text = "#usda 1.0\n(\nupAxis = \"Z\"\nmetersPerUnit = 0.01\n)\ndef Camera \"cam\"\n{\n\
                double3 xformOp:translate = (0, 0, 500)\n\
                uniform token[] xformOpOrder = [\"xformOp:translate\"]\n\
                float focalLength = 50\nfloat verticalAperture = 24\nfloat fStop = 2\n\
                float focusDistance = 300\n}\n";
    std::fs::write(dir.join("cam.usda"), text).unwrap();
    let read = read_usd_prims_at(&dir.join("cam.usda"), None, Prims::Cameras).unwrap();
    let units = StageUnits::new(UpAxis::Z, 0.01).unwrap();
    let eye = Vec3::from_array(units.to_world([0.0, 0.0, 500.0]));
    let want = Camera::new(eye, eye - Vec3::Y, -Vec3::Z, fov(50.0) as f32, 1.5)
        .unwrap()
        .with_thin_lens(
            (50.0 * 0.1 / (2.0 * 2.0) * 0.01) as f32,
            (300.0 * 0.01) as f32,
        )
        .unwrap();
    assert_eq!(read.cameras[0].camera(1.5).unwrap(), want);
}

/// A deforming USD mesh over an open shutter is the mesh read where the shutter opens
/// with its points where it closes as a later time step, bit for bit.
#[test]
fn an_open_shutter_reads_a_usd_mesh_at_its_time_steps() {
    let dir = scratch("mesh-shutter");
    let path = dir.join("anim.usda");
    std::fs::write(&path, animated_mesh()).unwrap();
    let mut desc = scene(
        &dir,
        &format!("{EYE}{}", usd_mesh("anim.usda")),
        "[animation]\nframe = 1",
    );
    desc.render.set("shutter_close", "1").unwrap();
    let blurred = pixels(desc.clone());
    let at = |frame| {
        let read = read_usd_prims_at(&path, Some(frame), Prims::Meshes).unwrap();
        read.meshes[0].clone()
    };
    let (open, close) = (at(1.0), at(2.0));
    let mut host = desc.clone();
    host.meshes = vec![MeshDesc::new(
        MeshSource::Triangles(Mesh {
            positions: open.points.clone(),
            triangles: open.triangles.clone(),
            normals: None,
            later_positions: vec![close.points],
        }),
        "d",
    )];
    assert!(pixels(host) == blurred);
    desc.render.set("shutter_close", "0").unwrap();
    assert!(pixels(desc) != blurred, "the mesh moves over the shutter");
}

#[test]
fn bad_usd_meshes_and_cameras_are_refused_naming_the_prim_the_attribute_and_the_time() {
    let dir = scratch("bad");
    let quad = " = [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)]";
    let read = |name: &str, text: String, frame: Option<f64>, shutter: bool| {
        std::fs::write(dir.join(name), text).unwrap();
        let mut desc = scene(&dir, &format!("{EYE}{}", usd_mesh(name)), "");
        if let Some(f) = frame {
            desc.at_frame(f).unwrap();
        }
        if shutter {
            desc.render.set("shutter_close", "1").unwrap();
        }
        error(Scene::from_description(&desc, device()).map(|_| ()))
    };
    let e = read(
        "range.usda",
        mesh_stage(" = [4]", " = [0, 1, 2, 4]", quad, " = (0, 0, 0)"),
        None,
        false,
    );
    assert!(
        e.contains("/World/quad")
            && e.contains("faceVertexIndices[3] = 4: out of range for 4 points"),
        "{e}"
    );
    let e = read(
        "sum.usda",
        mesh_stage(" = [3, 3]", " = [0, 1, 2, 3]", quad, " = (0, 0, 0)"),
        None,
        false,
    );
    assert!(
        e.contains("/World/quad")
            && e.contains("faceVertexCounts add up to 6 but faceVertexIndices has 4"),
        "{e}"
    );
    let nan = mesh_stage(
        " = [4]",
        " = [0, 1, 2, 3]",
        ".timeSamples = { 1: [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], \
         3: [(-1, -1, 0), (1, -1, 0), (1, nan, 0), (-1, 1, 0)] }",
        " = (0, 0, 0)",
    );
    let e = read("nan.usda", nan, Some(3.0), false);
    assert!(
        e.contains("/World/quad at frame 3 (time code 3)") && e.contains("points: point 2"),
        "{e}"
    );
    let topology = mesh_stage(
        " = [4]",
        ".timeSamples = { 1: [0, 1, 2, 3], 3: [1, 2, 3, 0] }",
        quad,
        " = (0, 0, 0)",
    );
    let e = read("topology.usda", topology, Some(2.0), true);
    assert!(
        e.contains("/World/quad at frame 3") && e.contains("faceVertexIndices differ"),
        "{e}"
    );

    // Cameras: two and no prim named, a lens with no focus, a prim that is not there.
    let two = format!("{HEADER}def Camera \"a\"\n{{\n}}\ndef Camera \"b\"\n{{\n}}\n");
    std::fs::write(dir.join("two.usda"), two).unwrap();
    let camera = |body: &str| {
        let desc = scene(&dir, &format!("[camera]\n{body}\n{SPHERE}"), "");
        error(camera_of(&desc))
    };
    let e = camera("usd = \"two.usda\"");
    assert!(e.contains("2 Camera prims (/a, /b)"), "{e}");
    let e = camera("usd = \"two.usda\"\nprim = \"/c\"");
    assert!(e.contains("no Camera prim at /c"), "{e}");
    let blurry = camera_stage(" = (0, 0, 4)", " = 50", "float fStop = 2\n");
    std::fs::write(dir.join("lens.usda"), blurry).unwrap();
    let e = camera("usd = \"lens.usda\"");
    assert!(e.contains("/cam") && e.contains("focusDistance = 0"), "{e}");
    let e = camera("usd = \"lens.usda\"\neye = [0, 0, 1]");
    assert!(e.contains("no other key but `prim`"), "{e}");
}

/// A scene file's `[camera.shutter_close]` moves the camera only with the shutter open
/// (its keys absent keep the opening's), and an automatic camera, which has no pose to
/// start from, refuses one.
#[test]
fn a_scene_files_camera_moves_to_its_shutter_close_pose_with_the_shutter_open() {
    let dir = scratch("close");
    let body = format!("{EYE}[camera.shutter_close]\neye = [1, 0, 4]\n{SPHERE}");
    let mut desc = scene(&dir, &body, "");
    let still = camera_of(&desc).unwrap();
    assert!(!still.moves());
    desc.render.set("shutter_close", "0.5").unwrap();
    let moving = camera_of(&desc).unwrap();
    assert!(moving.moves());
    assert_eq!(moving.at(0.0), still);
    let close = Camera::new(
        Vec3::X * 1.0 + Vec3::Z * 4.0,
        Vec3::ZERO,
        Vec3::Y,
        35.0,
        32.0 / 24.0,
    );
    assert_eq!(moving.at(1.0), close.unwrap());
    let automatic = format!("[camera.shutter_close]\neye = [1, 0, 4]\n{SPHERE}");
    let e = error(camera_of(&scene(&dir, &automatic, "")));
    assert!(e.contains("an automatic camera does not move"), "{e}");
}
