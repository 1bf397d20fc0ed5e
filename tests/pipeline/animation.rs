//! Animated grooms read at a frame: USD time samples (interpolated as USD defines them, the
//! stage's rates honoured, points moved by their velocities where the count changes),
//! per-frame `.hair` sequences and the scene's `[animation]` table. A frame renders bit for
//! bit as the same groom written as a still at that frame; faults name the prim and the
//! time.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hairtrace::description::SceneDescription;
use hairtrace::embree::Device;
use hairtrace::formats::hair::{Thickness, write_hair_file};
use hairtrace::formats::usd::{read_usd_file, read_usd_file_at};
use hairtrace::incremental::ControlPoints;
use hairtrace::scene::{GroomShape, Strands};
use hairtrace::{Aovs, NoProgress, Scene};

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-anim-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A stage of two linear strands under a moving Xform, in metres, with `meta` (its rates
/// and range).
/// `points`, `widths` and `translate` are the attributes' bodies (a default value, or
/// `.timeSamples = { ... }`). Every number is a short binary fraction, so that USD's
/// interpolation halfway between two samples is exact.
fn stage(meta: &str, translate: &str, points: &str, widths: &str) -> String {
    format!(
        "#usda 1.0\n(\nmetersPerUnit = 1\n{meta}\n)\ndef Xform \"Groom\"\n{{\n\
         double3 xformOp:translate{translate}\n\
         uniform token[] xformOpOrder = [\"xformOp:translate\"]\n\
         def BasisCurves \"hair\"\n{{\nuniform token type = \"linear\"\n\
         int[] curveVertexCounts = [2, 2]\npoint3f[] points{points}\nfloat[] widths{widths}\n}}\n}}\n"
    )
}

const RANGE: &str = "startTimeCode = 1\nendTimeCode = 3";

fn animated() -> String {
    stage(
        RANGE,
        ".timeSamples = { 1: (0, 0, 0), 3: (0.5, 0, 0) }",
        ".timeSamples = { 1: [(0, 0, 0), (0, 1, 0), (0.25, 0, 0), (0.25, 1, 0)], \
         3: [(0, 0, 0), (0.5, 1, 0), (0.25, 0, 0), (0.75, 1, 0)] }",
        ".timeSamples = { 1: [0.03125, 0.015625, 0.03125, 0.015625], \
         3: [0.0625, 0.015625, 0.03125, 0.046875] }",
    )
}

/// The same groom written as a still at frame 2, halfway between the samples.
fn still_at_2() -> String {
    stage(
        "",
        " = (0.25, 0, 0)",
        " = [(0, 0, 0), (0.25, 1, 0), (0.25, 0, 0), (0.5, 1, 0)]",
        " = [0.046875, 0.015625, 0.03125, 0.03125]",
    )
}

/// A scene of `groom` (a file in `dir`; linear, for a `.hair` file) with `animation` as its
/// `[animation]` table.
fn scene(dir: &Path, groom: &str, animation: &str) -> SceneDescription {
    let basis = if groom.ends_with(".hair") {
        "basis = \"linear\""
    } else {
        ""
    };
    let text = format!(
        "[render]\nwidth = 32\nheight = 24\nspp = 2\nthreads = 1\n{animation}\n\
         [camera]\neye = [0.5, 0.5, 3]\ntarget = [0.5, 0.5, 0]\n\
         [materials.h]\ntype = \"hair\"\nmelanin = [0.5, 0.1]\n\
         [[groom]]\nfile = \"{groom}\"\nmaterial = \"h\"\n{basis}\n\
         [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n"
    );
    SceneDescription::from_toml(&text, dir, "anim.toml").unwrap()
}

fn pixels(desc: SceneDescription) -> Vec<u32> {
    let mut built = desc.build(Arc::new(Device::new(Some(1)).unwrap())).unwrap();
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

fn error(r: hairtrace::Result<impl std::fmt::Debug>) -> String {
    r.expect_err("an error").to_string()
}

#[test]
fn frame_f_of_an_animated_stage_renders_bit_for_bit_as_the_stage_written_still_at_f() {
    let dir = scratch("still");
    std::fs::write(dir.join("anim.usda"), animated()).unwrap();
    std::fs::write(dir.join("still.usda"), still_at_2()).unwrap();
    let at_2 = read_usd_file_at(&dir.join("anim.usda"), Some(2.0)).unwrap();
    let still = read_usd_file(&dir.join("still.usda")).unwrap();
    assert_eq!(at_2.curves[0].control, still.curves[0].control);
    // The transform moved too: the first strand's root is at x = 0.25.
    assert_eq!(at_2.curves[0].control[0][0], 0.25);

    let frame_2 = pixels(scene(&dir, "anim.usda", "[animation]\nframe = 2"));
    let sky = frame_2.iter().filter(|&&v| v == 1.0f32.to_bits()).count();
    assert!(sky + 10 < frame_2.len(), "the hair is in view");
    assert!(frame_2 == pixels(scene(&dir, "still.usda", "")));
    // Another frame is another image; a read as a still takes the first samples.
    let frame_3 = pixels(scene(&dir, "anim.usda", "[animation]\nframe = 3"));
    assert!(frame_2 != frame_3);
    let first = read_usd_file(&dir.join("anim.usda")).unwrap();
    let at_1 = read_usd_file_at(&dir.join("anim.usda"), Some(1.0)).unwrap();
    assert_eq!(first.curves[0].control, at_1.curves[0].control);

    // `at_frame` (the CLI's --frame) is the same as the table's frame.
    let mut desc = scene(&dir, "anim.usda", "");
    desc.at_frame(2.0).unwrap();
    assert!(pixels(desc) == frame_2);
}

#[test]
fn a_frame_is_read_at_the_stages_time_codes_per_frame() {
    let dir = scratch("rates");
    // 48 time codes a second and 24 frames: frame 2 is time code 4, between the samples at
    // 2 and 6.
    let text = stage(
        "timeCodesPerSecond = 48\nframesPerSecond = 24",
        " = (0, 0, 0)",
        ".timeSamples = { 2: [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)], \
         6: [(0, 0, 0), (1, 1, 0), (1, 0, 0), (2, 1, 0)] }",
        " = [0.03125] (interpolation = \"constant\")",
    );
    std::fs::write(dir.join("rates.usda"), text).unwrap();
    let grooms = read_usd_file_at(&dir.join("rates.usda"), Some(2.0)).unwrap();
    assert_eq!(grooms.curves[0].control[1][0], 0.5);
    assert_eq!(grooms.time_range(), Some((2.0, 6.0)));
    // Frames 1 to 3 are the animation; frame 4 is past it.
    let e = error(read_usd_file_at(&dir.join("rates.usda"), Some(4.0)));
    assert!(
        e.contains("frame 4 (time code 8) is outside the animation"),
        "{e}"
    );
    assert!(e.contains("frames 1 to 3"), "{e}");
}

/// Curves whose count grows between two samples (hair being born): the points between them
/// move from the earlier sample by its velocities, per second, as UsdGeomPointBased defines;
/// with no velocities they are undefined, and the read is refused naming the prim and time.
#[test]
fn points_whose_count_changes_move_by_their_velocities_or_are_refused() {
    let dir = scratch("velocities");
    let text = |velocities: &str| {
        format!(
            "#usda 1.0\ndef BasisCurves \"hair\"\n{{\nuniform token type = \"linear\"\n\
             int[] curveVertexCounts.timeSamples = {{ 1: [2], 2: [2, 2] }}\n\
             point3f[] points.timeSamples = {{ 1: [(0, 0, 0), (0, 1, 0)], \
             2: [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)] }}\n{velocities}\n\
             float[] widths = [0.03125] (interpolation = \"constant\")\n}}\n"
        )
    };
    let path = dir.join("born.usda");
    // 24 time codes a second (USD's fallback): half a frame is 1/48 s.
    std::fs::write(
        &path,
        text("vector3f[] velocities.timeSamples = { 1: [(24, 0, 0), (48, 0, 0)] }"),
    )
    .unwrap();
    let grooms = read_usd_file_at(&path, Some(1.5)).unwrap();
    let strands = grooms.curves[0].authored();
    assert_eq!(strands.points, vec![[0.5, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    // On the sample, the second sample's two strands.
    assert_eq!(
        read_usd_file_at(&path, Some(2.0)).unwrap().curves[0].authored_counts,
        [2, 2]
    );

    std::fs::write(&path, text("")).unwrap();
    let e = error(read_usd_file_at(&path, Some(1.5)));
    for part in [
        "/hair",
        "frame 1.5",
        "time codes 1 (2 points) and 2 (4 points)",
        "no velocities",
    ] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
}

#[test]
fn a_bad_sample_or_frame_is_refused_naming_the_prim_and_the_time() {
    let dir = scratch("faults");
    let nan = stage(
        RANGE,
        " = (0, 0, 0)",
        ".timeSamples = { 1: [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)], \
         3: [(0, 0, 0), (nan, 1, 0), (1, 0, 0), (1, 1, 0)] }",
        " = [0.03125] (interpolation = \"constant\")",
    );
    std::fs::write(dir.join("nan.usda"), nan).unwrap();
    let e = error(read_usd_file_at(&dir.join("nan.usda"), Some(2.0)));
    for part in ["nan.usda", "/Groom/hair at frame 2 (time code 2)", "point"] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
    // The first sample is sound: the still reads.
    read_usd_file(&dir.join("nan.usda")).unwrap();

    std::fs::write(dir.join("anim.usda"), animated()).unwrap();
    let e = error(read_usd_file_at(&dir.join("anim.usda"), Some(5.0)));
    assert!(
        e.contains("frame 5 (time code 5) is outside the animation: time codes 1 to 3"),
        "{e}"
    );
    // The scene's own frames bound it too, before anything is read.
    let text = "[animation]\nframes = [1, 2]\nframe = 3\n";
    let e = error(SceneDescription::from_toml(text, &dir, "shot.toml"));
    assert!(
        e.contains("frame 3 is outside the shot's frames 1 to 2"),
        "{e}"
    );
    let e = error(SceneDescription::from_toml(
        "[animation]\nframes = [4, 2]\n",
        &dir,
        "s.toml",
    ));
    assert!(e.contains("the first frame is after the last"), "{e}");
    // A still has one image for every frame.
    std::fs::write(dir.join("still.usda"), still_at_2()).unwrap();
    let still = read_usd_file(&dir.join("still.usda")).unwrap();
    assert_eq!(still.time_range(), None);
    assert_eq!(
        read_usd_file_at(&dir.join("still.usda"), Some(40.0)).unwrap(),
        still
    );
}

fn two_strands(x: f32) -> Strands {
    Strands {
        points: vec![
            [x, 0.0, 0.0],
            [x, 1.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.75, 1.0, 0.0],
        ],
        radii: vec![0.02; 4],
        counts: vec![2, 2],
        colors: None,
    }
}

#[test]
fn a_hair_sequence_reads_the_file_of_the_frame() {
    let dir = scratch("sequence");
    for (frame, x) in [(1, 0.0), (2, 0.25)] {
        let path = dir.join(format!("groom.{frame:04}.hair"));
        write_hair_file(&path, &two_strands(x), Thickness::Diameter).unwrap();
    }
    let frame_2 = pixels(scene(&dir, "groom.####.hair", "[animation]\nframe = 2"));
    assert!(frame_2 == pixels(scene(&dir, "groom.0002.hair", "")));
    assert!(frame_2 != pixels(scene(&dir, "groom.####.hair", "[animation]\nframe = 1")));

    let build = |d: SceneDescription| d.build(Arc::new(Device::new(Some(1)).unwrap())).map(|_| ());
    let e = error(build(scene(&dir, "groom.####.hair", "")));
    assert!(
        e.contains("a sequence of per-frame files: give the frame"),
        "{e}"
    );
    let e = error(build(scene(
        &dir,
        "groom.####.hair",
        "[animation]\nframe = 3",
    )));
    assert!(e.contains("groom.0003.hair does not exist"), "{e}");
    let e = error(build(scene(
        &dir,
        "groom.####.hair",
        "[animation]\nframe = 1.5",
    )));
    assert!(e.contains("whole frames"), "{e}");
}

/// With the shutter open, a USD groom read at a frame moves over it: its curves are the
/// stage read where the shutter opens and where it closes (and evenly between, taking in
/// the samples inside), the same bits as a host's strands given those two time steps.
#[test]
fn an_open_shutter_reads_the_stage_at_its_time_steps() {
    let dir = scratch("shutter");
    let path = dir.join("anim.usda");
    std::fs::write(&path, animated()).unwrap();
    let mut desc = scene(&dir, "anim.usda", "[animation]\nframe = 1");
    desc.render.set("shutter_close", "1").unwrap();
    let blurred = pixels(desc.clone());
    desc.render.set("shutter_close", "0").unwrap();
    assert!(
        blurred != pixels(desc.clone()),
        "the groom moves over the shutter"
    );

    // The same strands from host buffers at frames 1 and 2, where the shutter opens and
    // closes (no sample lies between).
    desc.render.set("shutter_close", "1").unwrap();
    assert!(host_steps(&desc, &path, &[1.0, 2.0]) == blurred);
}

/// The pixels of `desc` with its grooms replaced by the strands of the stage at `path`
/// read at each of `frames`, handed over as a host's time steps.
fn host_steps(desc: &SceneDescription, path: &Path, frames: &[f64]) -> Vec<u32> {
    let mut steps =
        (frames.iter()).map(|&f| read_usd_file_at(path, Some(f)).unwrap().curves.remove(0));
    let first = steps.next().unwrap();
    let mut host = desc.clone();
    host.grooms.clear();
    let mut scene =
        Scene::from_description(&host, Arc::new(Device::new(Some(1)).unwrap())).unwrap();
    let points = ControlPoints {
        points: first.control.into(),
        later_steps: steps.map(|s| s.control.into()).collect(),
        counts: first.control_counts,
        colors: None,
        basis: first.layout.basis,
    };
    scene
        .add_control_points("hair", points, GroomShape::Auto, "h")
        .unwrap();
    let out = scene.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// `motion_steps` asks for more time steps than the samples inside the shutter give: the
/// stage is read at that many, evenly from the opening to the closing, bit for bit the
/// host's strands given those steps; past Embree's most it is refused.
#[test]
fn motion_steps_reads_the_stage_at_that_many_steps() {
    let dir = scratch("motion-steps");
    let path = dir.join("anim.usda");
    std::fs::write(&path, animated()).unwrap();
    let mut desc = scene(&dir, "anim.usda", "[animation]\nframe = 1");
    desc.render.set("shutter_close", "1").unwrap();
    desc.render.set("motion_steps", "3").unwrap();
    let blurred = pixels(desc.clone());
    assert!(
        host_steps(&desc, &path, &[1.0, 1.5, 2.0]) == blurred,
        "three steps are not the stage at 1, 1.5 and 2"
    );

    let refused = desc
        .render
        .set("motion_steps", "130")
        .unwrap_err()
        .to_string();
    assert!(refused.contains("motion_steps"), "{refused}");
}

/// `strands` as float4 control points (a linear `.hair` file's strands are its control
/// points).
fn xyzr(strands: &Strands) -> Vec<[f32; 4]> {
    (strands.points.iter().zip(&strands.radii))
        .map(|(&[x, y, z], &r)| [x, y, z, r])
        .collect()
}

/// With the shutter open, a `.hair` sequence read at a frame moves over it: its time steps
/// are the files of the frames where the shutter opens and closes, and evenly between,
/// blended linearly between two files (as USD interpolates its samples), the same bits as a
/// host's strands given those steps. Files of other strands, or missing, are refused by
/// name.
#[test]
fn an_open_shutter_reads_a_hair_sequence_at_its_time_steps() {
    let dir = scratch("hair-shutter");
    for (frame, x) in [(1, 0.0), (2, 0.25), (3, 0.75)] {
        let path = dir.join(format!("groom.{frame:04}.hair"));
        write_hair_file(&path, &two_strands(x), Thickness::Diameter).unwrap();
    }
    let at = |frame: f64, shutter: (&str, &str)| {
        let mut desc = scene(
            &dir,
            "groom.####.hair",
            &format!("[animation]\nframe = {frame}"),
        );
        desc.render.set("shutter_open", shutter.0).unwrap();
        desc.render.set("shutter_close", shutter.1).unwrap();
        desc
    };
    let host = |desc: &SceneDescription, steps: &[f32]| {
        let mut host = desc.clone();
        host.grooms.clear();
        let mut scene =
            Scene::from_description(&host, Arc::new(Device::new(Some(1)).unwrap())).unwrap();
        let points = ControlPoints {
            points: xyzr(&two_strands(steps[0])).into(),
            later_steps: steps[1..]
                .iter()
                .map(|&x| xyzr(&two_strands(x)).into())
                .collect(),
            counts: vec![2, 2],
            colors: None,
            basis: hairtrace::embree::CurveBasis::Linear,
        };
        scene
            .add_control_points("hair", points, GroomShape::Auto, "h")
            .unwrap();
        let out = scene.render(Aovs::default(), &NoProgress).unwrap();
        out.film
            .rgb()
            .iter()
            .map(|v| v.to_bits())
            .collect::<Vec<u32>>()
    };

    // Frames 1 and 2: the two files.
    let blurred = at(1.0, ("0", "1"));
    let pixels_blurred = pixels(blurred.clone());
    assert!(
        pixels_blurred != pixels(at(1.0, ("0", "0"))),
        "the groom moves"
    );
    assert!(pixels_blurred == host(&blurred, &[0.0, 0.25]));
    // Frames 1.5 to 2.5: halfway between the files, then frame 2's file, then halfway on.
    let centred = at(2.0, ("-0.5", "0.5"));
    assert!(pixels(centred.clone()) == host(&centred, &[0.125, 0.25, 0.5]));

    let build = |d: SceneDescription| d.build(Arc::new(Device::new(Some(1)).unwrap())).map(|_| ());
    let e = error(build(at(3.0, ("0", "1"))));
    for part in [
        "groom.0004.hair does not exist",
        "the shutter of frame 3 spans frames 3 to 4",
    ] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
    let mut three = two_strands(0.5);
    three.points.extend([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    three.radii.extend([0.02; 2]);
    three.counts.push(2);
    write_hair_file(&dir.join("groom.0003.hair"), &three, Thickness::Diameter).unwrap();
    let e = error(build(at(2.0, ("0", "1"))));
    for part in [
        "groom.0003.hair (3 strands, 6 points)",
        "groom.0002.hair (2 strands, 4 points)",
    ] {
        assert!(e.contains(part), "{part:?} in {e}");
    }
}
