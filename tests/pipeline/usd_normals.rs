//! A groom's curve normals orient its elliptical fibres (the Huang model's `aspect`): USD's
//! `normals` and `primvars:normals`, and Blender's `primvars:custom_normal`, read, turned
//! by the prim's transform, and refused when malformed.

use std::path::Path;
use std::sync::Arc;

use hairtrace::description::SceneDescription;
use hairtrace::embree::Device;
use hairtrace::{Aovs, NoProgress};

use crate::usd::refused;

/// The strands' points: three horizontal Catmull-Rom strands along x, bending in z.
const POINTS: [[f32; 3]; 12] = [
    [-1.0, -0.4, 0.0],
    [-0.3, -0.4, 0.1],
    [0.3, -0.4, -0.1],
    [1.0, -0.4, 0.0],
    [-1.0, 0.0, 0.0],
    [-0.3, 0.0, -0.1],
    [0.3, 0.0, 0.1],
    [1.0, 0.0, 0.0],
    [-1.0, 0.4, 0.0],
    [-0.3, 0.4, 0.1],
    [0.3, 0.4, 0.0],
    [1.0, 0.4, 0.0],
];

/// A prim of the strands whose points are `place`d, with `extra` (attributes, xformOps) in it.
fn strands_placed(extra: &str, place: impl Fn([f32; 3]) -> [f32; 3]) -> String {
    let points: Vec<String> = (POINTS.iter())
        .map(|&p| format!("({:?}, {:?}, {:?})", place(p)[0], place(p)[1], place(p)[2]))
        .collect();
    format!(
        "#usda 1.0\ndef BasisCurves \"c\"\n{{\nint[] curveVertexCounts = [4, 4, 4]\n\
         point3f[] points = [{}]\n\
         float[] widths = [0.25] (interpolation = \"constant\")\n\
         uniform token type = \"cubic\"\nuniform token basis = \"catmullRom\"\n\
         uniform token wrap = \"pinned\"\n{extra}\n}}\n",
        points.join(", ")
    )
}

/// The strands as they are, with `extra` in the prim.
fn strands(extra: &str) -> String {
    strands_placed(extra, |p| p)
}

/// The image's bits of `file` in `dir` under flattened Huang fibres, lit by a sky and a sun.
fn render(dir: &Path, file: &str, device: &Arc<Device>) -> Vec<u32> {
    let toml = format!(
        "[render]\nwidth = 24\nheight = 24\nspp = 2\n\
         [materials.h]\ntype = \"hair\"\nmelanin = [1, 0.3]\nmodel = \"huang\"\naspect = 0.4\nroughness = 0.2\n\
         [[groom]]\nfile = \"{file}\"\nmaterial = \"h\"\n\
         [[light]]\ntype = \"environment\"\nradiance = [0.3, 0.3, 0.3]\n\
         [[light]]\ntype = \"distant\"\ndirection = [0.3, 0.6, 1]\nirradiance = [3, 3, 3]\n"
    );
    let desc = SceneDescription::from_toml(&toml, dir, "normals.toml").unwrap();
    let out = desc
        .build(device.clone())
        .unwrap()
        .render(Aovs::default(), &NoProgress)
        .unwrap();
    out.film.rgb().iter().map(|x| x.to_bits()).collect()
}

/// Normals along world up are the default orientation of these strands (up made
/// perpendicular to a tangent with no up in it): bit for bit the image without normals.
/// Normals along z turn every section a quarter turn: another image, the same whichever
/// of the three names carries them, and the same as normals along y under a transform
/// that turns y into z (the points authored turned back, so that the world's are the same).
#[test]
fn curve_normals_orient_the_fibres_by_every_name_and_transform() {
    let dir = std::env::temp_dir().join(format!("hairtrace-usd-normals-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let write = |name: &str, text: String| std::fs::write(dir.join(name), text).unwrap();
    let vertex = |name: &str, n: &str| {
        format!(
            "normal3f[] {name} = [{}] (interpolation = \"vertex\")",
            [n; 12].join(", ")
        )
    };
    write("plain.usda", strands(""));
    write("up.usda", strands(&vertex("normals", "(0, 1, 0)")));
    write("z.usda", strands(&vertex("normals", "(0, 0, 1)")));
    write("minus_z.usda", strands(&vertex("normals", "(0, 0, -1)")));
    write(
        "z_primvar.usda",
        strands(&format!(
            "{}\n{}",
            vertex("primvars:normals", "(0, 0, 1)"),
            vertex("normals", "(0, 1, 0)")
        )),
    );
    write(
        "z_blender.usda",
        strands("float3[] primvars:custom_normal = [(0, 0, 3)] (interpolation = \"constant\")"),
    );
    // Rows are the images of the axes: y to z, z to -y.
    let turn = "matrix4d xformOp:transform = ((1, 0, 0, 0), (0, 0, 1, 0), (0, -1, 0, 0), \
                (0, 0, 0, 1))\nuniform token[] xformOpOrder = [\"xformOp:transform\"]";
    write(
        "z_turned.usda",
        strands_placed(
            &format!("{turn}\n{}", vertex("normals", "(0, 1, 0)")),
            |[x, y, z]| [x, z, -y],
        ),
    );
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let image = |file: &str| render(&dir, file, &device);
    let plain = image("plain.usda");
    assert!(
        image("up.usda") == plain,
        "normals along up are not the default"
    );
    let z = image("z.usda");
    assert!(z != plain, "normals along z changed nothing");
    let differing = z.iter().zip(&plain).filter(|(a, b)| a != b).count();
    assert!(
        differing > z.len() / 20,
        "{differing} of {} values differ",
        z.len()
    );
    // The ellipse is the same turned half a turn; a normal's negative parts were once
    // clamped to 0, which left (0, 0, -1) no direction and the default's image.
    let minus_z = image("minus_z.usda");
    let differing = minus_z.iter().zip(&plain).filter(|(a, b)| a != b).count();
    assert!(
        differing > z.len() / 20,
        "normals along -z: {differing} of {} values differ from the default's",
        z.len()
    );
    assert!(
        image("z_primvar.usda") == z,
        "primvars:normals does not come first"
    );
    assert!(
        image("z_blender.usda") == z,
        "Blender's custom_normal is not read"
    );
    assert!(
        image("z_turned.usda") == z,
        "the prim's transform does not turn its normals"
    );
}

/// Malformed normals are refused naming the prim and the attribute: the wrong count for
/// their interpolation, a NaN, the wrong type.
#[test]
fn malformed_normals_are_refused_naming_the_attribute() {
    for (name, extra, want) in [
        (
            "normals_count",
            "normal3f[] normals = [(0, 1, 0), (0, 1, 0)]",
            "normals has 2 values for Vertex interpolation: 12 expected",
        ),
        (
            "normals_nan",
            "normal3f[] normals = [(0, nan, 0)] (interpolation = \"constant\")",
            "normals[0] = [0.0, NaN, 0.0]: must be finite",
        ),
        (
            "normals_type",
            "float[] primvars:custom_normal = [1]",
            "primvars:custom_normal: expected",
        ),
    ] {
        let m = refused(strands(extra), &format!("{name}.usda"));
        assert!(
            m.contains(&format!("{name}.usda: /c: {want}")),
            "{name}: {m}"
        );
    }
}
