//! pbrt-v4 scenes: the fixtures in tests/fixtures/pbrt (written in pbrt-v4's syntax, laid
//! out as pbrt's own hair scenes are) read into the numbers pbrt means; unsupported input
//! warns, or is refused, naming its file and line; the fixture renders.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hairtrace::Error;
use hairtrace::bsdf::sigma_a_from_melanin;
use hairtrace::description::{
    EnvironmentSource, GroomDesc, GroomSource, LightDesc, MaterialDesc, MeshSource,
};
use hairtrace::embree::{CurveBasis, Device};
use hairtrace::formats::pbrt::PbrtScene;
use hairtrace::render::{Aovs, NO_STRAND, NoProgress};
use hairtrace::scene::GroomShape;
use hairtrace::scene::{HairColor, HairMaterial};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pbrt")
}

fn fixture() -> PbrtScene {
    PbrtScene::from_file(&fixtures().join("hair.pbrt")).unwrap()
}

/// A camera, WorldBegin and a light, then `body` from line 4 on.
fn scene(body: &str) -> hairtrace::Result<PbrtScene> {
    let text = format!("LookAt 0 0 5  0 0 0  0 1 0\nWorldBegin\nLightSource \"infinite\"\n{body}");
    PbrtScene::from_text(&text, &fixtures(), "t.pbrt")
}

fn control_points(s: &PbrtScene, groom: usize) -> (&[[f32; 4]], &[u32]) {
    match &s.description.grooms[groom].source {
        GroomSource::ControlPoints { points, counts, .. } => (points, counts),
        other => panic!("expected control points, got {other:?}"),
    }
}

fn close(a: &[f32], b: &[f32], tolerance: f32) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tolerance)
}

fn bezier(c: &[[f32; 4]], t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    let w = [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t];
    std::array::from_fn(|k| (0..4).map(|i| w[i] * c[i][k]).sum())
}

fn bspline(c: &[[f32; 4]], t: f32) -> [f32; 4] {
    let s = 1.0 - t;
    let w = [
        s * s * s / 6.0,
        (3.0 * t * t * t - 6.0 * t * t + 4.0) / 6.0,
        (-3.0 * t * t * t + 3.0 * t * t + 3.0 * t + 1.0) / 6.0,
        t * t * t / 6.0,
    ];
    std::array::from_fn(|k| (0..4).map(|i| w[i] * c[i][k]).sum())
}

/// The basis a pbrt groom's control points are laid out for.
fn basis(g: &GroomDesc) -> CurveBasis {
    g.strand_curves().unwrap().basis()
}

#[test]
fn the_fixture_reads_into_pbrts_numbers() {
    let s = fixture();
    let d = &s.description;
    assert_eq!(d.grooms.len(), 3, "one groom per (material, shape, basis)");

    // Included strands: NamedMaterial "brown", Translate 0 0.5 0, pbrt's left-handed
    // camera mirrored through x = 0; widths 0.03 to 0.006 linear over 2 segments.
    let g = &d.grooms[0];
    assert_eq!(
        (g.material.as_str(), basis(g), g.shape),
        ("brown", CurveBasis::Bezier, GroomShape::Round)
    );
    let (points, counts) = control_points(&s, 0);
    assert_eq!(counts, [7, 7, 7]);
    let p = [
        [0.0, 0.0, 0.0],
        [0.0, 0.1, 0.0],
        [0.02, 0.2, 0.0],
        [0.02, 0.3, 0.0],
        [0.02, 0.4, 0.0],
        [0.0, 0.5, 0.05],
        [0.0, 0.6, 0.1],
    ];
    for (j, (got, q)) in points[..7].iter().zip(p).enumerate() {
        let radius = (0.03 + (0.006 - 0.03) * j as f32 / 6.0) / 2.0;
        let want = [-q[0], q[1] + 0.5, q[2], radius];
        assert!(close(got, &want, 1e-6), "point {j}: {got:?} != {want:?}");
    }
    // Second strand, x = 0.2 in the file.
    assert!(close(&points[7], &[-0.2, 0.5, 0.0, 0.015], 1e-6));

    // Scale 2 2 2: points and widths doubled; the anonymous material of both.
    let (points, counts) = control_points(&s, 1);
    assert_eq!(
        (basis(&d.grooms[1]), d.grooms[1].shape),
        (CurveBasis::Bezier, GroomShape::Flat)
    );
    assert_eq!(counts, [4]);
    assert!(close(
        &points[1],
        &[-1.0, 0.4, 0.0, (0.02 - 0.01 / 3.0)],
        1e-6
    ));
    // The width varies linearly along the curve, as pbrt's does.
    for t in [0.0, 0.25, 0.5, 1.0] {
        let r = bezier(points, t)[3];
        assert!((r - (0.02 + (0.01 - 0.02) * t)).abs() < 1e-6, "t {t}: {r}");
    }
    let (points, _) = control_points(&s, 2);
    assert_eq!(basis(&d.grooms[2]), CurveBasis::BSpline);
    assert!(close(&points[4], &[1.0, 1.6, 0.0, 0.01], 1e-6));
    assert_eq!(d.grooms[1].material, d.grooms[2].material);

    // Materials: pbrt's defaults where the file is silent.
    let MaterialDesc::Hair(brown) = &d.materials["brown"] else {
        panic!("brown is hair");
    };
    let pbrt_hair = |color, beta_m, alpha| HairMaterial {
        color,
        eta: 1.55,
        beta_m,
        beta_n: 0.3,
        alpha,
        ..HairMaterial::default()
    };
    let melanin = HairColor::Melanin {
        eumelanin: 1.3,
        pheomelanin: 0.2,
    };
    assert_eq!(*brown, pbrt_hair(melanin, 0.25, 2.0));
    let MaterialDesc::Hair(black) = &d.materials[&d.grooms[1].material] else {
        panic!("the anonymous material is hair");
    };
    let eight = HairColor::Melanin {
        eumelanin: 8.0,
        pheomelanin: 0.0,
    };
    assert_eq!(*black, pbrt_hair(eight, 0.3, 3.0));
    assert_eq!(
        d.materials["ground"],
        MaterialDesc::Diffuse { albedo: [0.3; 3] }
    );
    assert_eq!(d.materials.len(), 3, "only materials that shapes use");
    // Our melanin conversion is pbrt-v4's HairBxDF::SigmaAFromConcentration.
    let (eu, pheo) = ([0.419f32, 0.697, 1.37], [0.187f32, 0.4, 1.05]);
    let pbrt: [f32; 3] = std::array::from_fn(|i| 1.3 * eu[i] + 0.2 * pheo[i]);
    assert!(close(&sigma_a_from_melanin(1.3, 0.2).unwrap(), &pbrt, 1e-6));

    // Lights: rgb L as given; the distant light from (0, 10, 10) turned 30 degrees about
    // +y, then mirrored; its scale multiplies L.
    assert_eq!(
        d.lights[0],
        LightDesc::Environment {
            source: EnvironmentSource::Uniform([0.4, 0.45, 0.5]),
            rotation_deg: 0.0,
            scale: 1.0
        }
    );
    let LightDesc::Distant {
        direction,
        irradiance,
        angular_radius_deg,
    } = d.lights[1]
    else {
        panic!("a distant light");
    };
    let h = std::f32::consts::FRAC_1_SQRT_2;
    let (s30, c30) = 30f32.to_radians().sin_cos();
    assert!(
        close(&direction, &[-s30 * h, h, c30 * h], 1e-6),
        "{direction:?}"
    );
    assert!(close(&irradiance, &[2.0, 1.8, 1.6], 1e-6));
    assert_eq!(angular_radius_deg, 0.0);

    // Camera, film, sampler and integrator values.
    let c = &d.camera;
    assert_eq!(c.eye, Some([0.0, 1.0, 6.0]));
    assert_eq!(c.target, Some([0.0, 1.0, 5.0]));
    assert_eq!((c.up, c.fov_deg), ([0.0, 1.0, 0.0], 30.0));
    let r = &d.render;
    assert_eq!(
        (r.width, r.height, r.spp, r.path.max_depth),
        (64, 48, 4, 16)
    );
    assert_eq!(s.film_filename.as_deref(), Some(Path::new("hair.exr")));
    assert_eq!(d.meshes.len(), 1);
}

#[test]
fn unsupported_statements_of_the_fixture_warn_with_their_line() {
    let s = fixture();
    let at = |place: &str, what: &str| {
        assert!(
            s.warnings
                .iter()
                .any(|w| w.contains(place) && w.contains(what)),
            "no warning at {place} about {what}: {:#?}",
            s.warnings
        );
    };
    at("hair.pbrt:8: Sampler \"zsobol\"", "only \"pixelsamples\"");
    at("hair.pbrt:9: Integrator \"volpath\"", "only \"maxdepth\"");
    at("hair.pbrt:10: PixelFilter", "ignored");
    at("hair.pbrt:28: Shape \"trianglemesh\"", "\"point2 uv\"");
    at("strands.pbrt:6: Shape \"curve\"", "\"float foo\"");
    assert_eq!(s.warnings.len(), 5, "{:#?}", s.warnings);
}

#[test]
fn more_warnings_name_their_line_and_count_repeats() {
    let s = scene(concat!(
        "ReverseOrientation\n",
        "Texture \"t\" \"spectrum\" \"imagemap\" \"string filename\" \"x.png\"\n",
        "Material \"hair\" \"texture reflectance\" \"t\"\n",
        "Shape \"curve\" \"string type\" \"ribbon\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0] \"normal N\" [0 0 1 0 0 1]\n",
        "Shape \"curve\" \"string type\" \"ribbon\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0] \"normal N\" [0 0 1 0 0 1]\n",
        "Shape \"curve\" \"string type\" \"ribbon\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0] \"normal N\" [0 0 1 0 0 1]\n",
    ))
    .unwrap();
    let w = &s.warnings;
    let has = |needle: &str| w.iter().any(|x| x.contains(needle));
    assert!(has("t.pbrt:4: ReverseOrientation"), "{w:#?}");
    assert!(has("t.pbrt:5: Texture: ignored"), "{w:#?}");
    assert!(has(
        "t.pbrt:6: Material \"hair\": parameter \"reflectance\" is the texture \"t\""
    ));
    assert!(
        has(
            "t.pbrt:7: Shape \"curve\": ribbon curves are drawn as flat curves facing the ray: their normals \"N\" are ignored (and 2 more like it)"
        ),
        "{w:#?}"
    );
    // The texture left pbrt's default colour: eumelanin 1.3.
    let m = s.description.materials.values().next().unwrap();
    assert!(
        matches!(m, MaterialDesc::Hair(h) if h.color == HairColor::Melanin { eumelanin: 1.3, pheomelanin: 0.0 })
    );
}

#[test]
fn refused_input_names_its_line() {
    let cases: &[(&str, &str)] = &[
        ("Sphere 1", "t.pbrt:4: unknown directive \"Sphere\""),
        (
            "Shape \"curve\" \"point3 P\" [ 0 0 0",
            "t.pbrt:4: parameter \"P\": no `]`",
        ),
        ("\nShape \"curve", "t.pbrt:5: unterminated string"),
        (
            "Material \"hair\" \"float eta\" nan",
            "t.pbrt:4: parameter \"eta\" has no value",
        ),
        (
            "Material \"hair\" \"float eta\" 1e400",
            "t.pbrt:4: 1e400 is not a finite number",
        ),
        (
            "Material \"hair\"\nShape \"curve\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0] \"float width\" -1",
            "t.pbrt:5: Shape \"curve\": width = -1: must be >= 0",
        ),
        (
            "Material \"hair\"\nShape \"curve\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0 0 4 0]",
            "t.pbrt:5: Shape \"curve\": 5 control points do not make a degree 3 bezier curve",
        ),
        (
            "Shape \"curve\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0]",
            "t.pbrt:4: Shape \"curve\": curves need a hair material; theirs is diffuse",
        ),
        (
            "Material \"hair\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]",
            "t.pbrt:5: Shape \"trianglemesh\": a hair material on a surface",
        ),
        (
            "Material \"conductor\"\n\nShape \"sphere\"",
            "t.pbrt:6: Shape \"sphere\": its material cannot be rendered: t.pbrt:4: Material \"conductor\": material type \"conductor\" is not supported",
        ),
        (
            "Shape \"disk\" \"float radius\" 1",
            "t.pbrt:4: Shape \"disk\": only \"curve\", \"trianglemesh\", \"plymesh\" and \"sphere\"",
        ),
        (
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 3]",
            "t.pbrt:4: Shape \"trianglemesh\": index 3 is not a vertex",
        ),
        (
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1]",
            "2 indices: not whole triangles",
        ),
        (
            "LightSource \"point\"",
            "t.pbrt:4: LightSource \"point\": only \"infinite\" and \"distant\"",
        ),
        (
            "LightSource \"infinite\" \"rgb L\" [1 1 1] \"string filename\" \"sky.exr\"",
            "t.pbrt:4: LightSource \"infinite\": give either \"L\" or \"filename\"",
        ),
        (
            "LightSource \"infinite\" \"string filename\" \"missing.exr\"",
            "image error: t.pbrt:4: LightSource \"infinite\": cannot read",
        ),
        (
            "LightSource \"distant\" \"spectrum L\" [400 1 700 1]",
            "t.pbrt:4: LightSource \"distant\": parameter \"spectrum L\": only \"rgb\" colours",
        ),
        (
            "LightSource \"distant\" \"point3 from\" [1 1 1] \"point3 to\" [1 1 1]",
            "\"from\" and \"to\" must differ",
        ),
        (
            "AreaLightSource \"diffuse\"",
            "t.pbrt:4: AreaLightSource: emitting shapes are not supported",
        ),
        (
            "ObjectBegin \"a\"",
            "t.pbrt:4: ObjectBegin: object instancing",
        ),
        (
            "NamedMaterial \"nope\"",
            "t.pbrt:4: NamedMaterial: no material named \"nope\"",
        ),
        ("AttributeEnd", "t.pbrt:4: AttributeEnd without its Begin"),
        ("AttributeBegin", "AttributeBegin without AttributeEnd"),
        (
            "Camera \"perspective\"",
            "t.pbrt:4: Camera after WorldBegin",
        ),
        (
            "Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 7]",
            "t.pbrt:4: expected 16 numbers and `]`",
        ),
        ("Rotate 10 0 0 0", "t.pbrt:4: Rotate about a zero axis"),
        ("Include \"missing.pbrt\"", "i/o error: t.pbrt:4: Include: "),
        (
            "Shape \"plymesh\" \"string filename\" \"missing.ply\"",
            "t.pbrt:4: Shape \"plymesh\"",
        ),
        (
            "Material \"hair\" \"float eta\" 1 \"float eta\" 2",
            "parameter \"eta\" given twice",
        ),
    ];
    for (body, message) in cases {
        let e = match scene(body) {
            Ok(_) => panic!("{body:?} should be refused"),
            Err(e) => e.to_string(),
        };
        assert!(
            e.contains(message),
            "{body:?}:\n  {e}\nshould contain\n  {message}"
        );
    }
    let e = PbrtScene::from_text("Shape \"curve\"", Path::new("."), "t.pbrt").unwrap_err();
    assert!(matches!(e, Error::InvalidArg(m) if m == "t.pbrt:1: Shape before WorldBegin"));
}

#[test]
fn the_image_is_pbrts_not_its_mirror() {
    // pbrt's camera space is left-handed: a point on +x appears on the image's left for
    // this camera, so the scene is mirrored. A `Scale -1 1 1` before LookAt makes the
    // camera right-handed, as ours, and nothing is mirrored.
    let curve =
        "Material \"hair\"\nShape \"curve\" \"point3 P\" [0.5 0 0 0.5 1 0 0.5 2 0 0.5 3 0]\n";
    let x = |s: &PbrtScene| control_points(s, 0).0[0][0];
    assert_eq!(x(&scene(curve).unwrap()), -0.5);
    let text = format!(
        "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n{curve}"
    );
    let flipped = PbrtScene::from_text(&text, Path::new("."), "t.pbrt").unwrap();
    assert_eq!(x(&flipped), 0.5);
    assert_eq!(flipped.description.camera.eye, Some([0.0, 0.0, 5.0]));
}

#[test]
fn fov_spans_the_shorter_side_and_a_bspline_width_is_linear() {
    let text = "Film \"rgb\" \"integer xresolution\" 48 \"integer yresolution\" 64\n\
                Camera \"perspective\" \"float fov\" 30\nWorldBegin\nMaterial \"hair\"\n\
                Shape \"curve\" \"string basis\" \"bspline\" \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0 0 4 0] \
                \"float width0\" 1 \"float width1\" 0.5";
    let s = PbrtScene::from_text(text, Path::new("."), "t.pbrt").unwrap();
    let want = 2.0 * (15f32.to_radians().tan() * 64.0 / 48.0).atan().to_degrees();
    assert!((s.description.camera.fov_deg - want).abs() < 1e-4);
    let (points, _) = control_points(&s, 0);
    // Two segments, the radius from 0.5 to 0.25 linearly over the whole curve.
    for (segment, u, t) in [(0, 0.0, 0.0), (0, 0.5, 0.25), (1, 0.0, 0.5), (1, 1.0, 1.0)] {
        let r = bspline(&points[segment..segment + 4], u)[3];
        assert!((r - (0.5 - 0.25 * t)).abs() < 1e-6, "t {t}: {r}");
    }
}

/// A fresh folder for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-pbrt-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn includes_refuse_cycles_and_depth() {
    let dir = scratch("includes");
    std::fs::write(dir.join("a.pbrt"), "WorldBegin\nInclude \"b.pbrt\"\n").unwrap();
    std::fs::write(dir.join("b.pbrt"), "\nInclude \"a.pbrt\"\n").unwrap();
    let e = PbrtScene::from_file(&dir.join("a.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a.pbrt:2: Include: ") && e.contains("b.pbrt:2: Include: "),
        "{e}"
    );
    assert!(e.contains("included from itself (an include cycle)"), "{e}");

    for i in 0..40 {
        std::fs::write(
            dir.join(format!("d{i}.pbrt")),
            format!("Include \"d{}.pbrt\"\n", i + 1),
        )
        .unwrap();
    }
    std::fs::write(dir.join("d40.pbrt"), "").unwrap();
    let e = PbrtScene::from_file(&dir.join("d0.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("includes nested deeper than 32"), "{e}");
}

#[test]
fn many_strands_become_one_groom() {
    let mut body = String::from("Material \"hair\"\n");
    for i in 0..50_000 {
        let x = i as f32 * 1e-3;
        body.push_str(&format!(
            "Shape \"curve\" \"string type\" \"cylinder\" \"point3 P\" [{x} 0 0 {x} 1 0 {x} 2 0 {x} 3 0] \"float width0\" 0.01 \"float width1\" 0.002\n"
        ));
    }
    let s = scene(&body).unwrap();
    assert_eq!(s.description.grooms.len(), 1);
    let (points, counts) = control_points(&s, 0);
    assert_eq!((counts.len(), points.len()), (50_000, 200_000));
}

#[test]
fn the_fixture_renders() {
    let mut d = fixture().description;
    (
        d.render.width,
        d.render.height,
        d.render.spp,
        d.render.threads,
    ) = (48, 36, 2, Some(1));
    let mut built = d.build(Arc::new(Device::new(Some(1)).unwrap())).unwrap();
    let aovs = Aovs {
        strand_id: true,
        ..Aovs::default()
    };
    let out = built.render(aovs, &NoProgress).unwrap();
    let rgb = out.film.rgb();
    assert!(rgb.iter().all(|v| v.is_finite() && *v >= 0.0));
    let mean = rgb.iter().sum::<f32>() / rgb.len() as f32;
    assert!(mean > 0.05, "mean {mean}");
    let hair = out
        .film
        .strand_id()
        .unwrap()
        .iter()
        .filter(|&&s| s != NO_STRAND)
        .count();
    assert!(hair > 10, "only {hair} pixels see a strand");
}

#[test]
fn a_plymesh_is_read_and_placed() {
    let dir = scratch("ply");
    std::fs::write(
        dir.join("quad.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0\n1 0 0\n1 0 1\n0 0 1\n4 0 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scene.pbrt"),
        "LookAt 0 1 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
         LightSource \"infinite\"\nTranslate 0 -1 0\nScale 2 2 2\n\
         Shape \"plymesh\" \"string filename\" \"quad.ply\"\n",
    )
    .unwrap();
    let s = PbrtScene::from_file(&dir.join("scene.pbrt")).unwrap();
    let MeshSource::Triangles(mesh) = &s.description.meshes[0].source else {
        panic!("an inline mesh");
    };
    assert_eq!(mesh.triangles.len(), 2);
    // Scaled, moved down, mirrored through x = 0 for pbrt's camera.
    assert_eq!(
        mesh.positions,
        [
            [0.0, -1.0, 0.0],
            [-2.0, -1.0, 0.0],
            [-2.0, -1.0, 2.0],
            [0.0, -1.0, 2.0]
        ]
    );
    assert_eq!(
        s.description.meshes[0].material,
        "(pbrt's default diffuse material)"
    );
}

#[test]
fn an_equal_area_environment_map_keeps_pbrts_directions() {
    // A square map whose channels mark, in pbrt's light frame, R: +y (v > 1/2), G: +x
    // (u > 1/2), B: +z (the inner diamond). pbrt's directions, mirrored for its camera,
    // must find the same marks in our lat-long texels.
    let n = 32;
    let mut pixels = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let (u, v) = ((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let diamond = (u - 0.5).abs() + (v - 0.5).abs() < 0.5;
            pixels.extend([v > 0.5, u > 0.5, diamond].map(|b| f32::from(u8::from(b))));
        }
    }
    let dir = scratch("envmap");
    let options = hairtrace::image::WriteOptions::default();
    hairtrace::image::write_image(&dir.join("sky.exr"), n, n, 3, &pixels, &options).unwrap();
    let text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n\
                LightSource \"infinite\" \"string filename\" \"sky.exr\" \"float scale\" 2\n";
    let s = PbrtScene::from_text(text, &dir, "t.pbrt").unwrap();
    let LightDesc::Environment {
        source: EnvironmentSource::LatLong { width, height, rgb },
        scale,
        ..
    } = &s.description.lights[0]
    else {
        panic!("a lat-long environment");
    };
    assert_eq!((*width, *height, *scale), (2 * n, n, 2.0));
    let mut wrong = 0;
    for row in 0..*height {
        let theta = std::f32::consts::PI * (row as f32 + 0.5) / *height as f32;
        for col in 0..*width {
            let phi = 2.0 * std::f32::consts::PI * (col as f32 + 0.5) / *width as f32;
            // Our lat-long direction (scene::envmap), then back to pbrt's frame (x mirrored).
            let d = [
                theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            ];
            let texel = &rgb[(row * width + col) * 3..][..3];
            let want = d.map(|c| f32::from(u8::from(c > 0.0)));
            let (x, y, z) = (want[0], want[1], want[2]);
            if texel != [y, x, z] {
                wrong += 1;
            }
        }
    }
    // Only texels along the boundaries may round to the other side.
    assert!(
        wrong * 10 < width * height,
        "{wrong} of {} texels",
        width * height
    );
    let built = s.description.build(Arc::new(Device::new(Some(1)).unwrap()));
    assert!(built.is_ok());
}

/// Laid out as the hair scenes of pbrt-v4's scene collection: a camera `Transform`, a Film
/// `iso`, an equal-area map under rotations, gzipped strands in a subfolder, and a sphere
/// placed in the camera's frame.
#[test]
fn a_scene_laid_out_as_pbrts_hair_scenes() {
    use std::io::Write;
    let dir = scratch("collection");
    std::fs::create_dir_all(dir.join("geometry")).unwrap();
    let strands = "Shape \"curve\" \"string type\" \"cylinder\" \
                   \"point3 P\" [0 0 0 0 1 0 0 2 0 0 3 0] \"float width0\" 0.2 \"float width1\" 0.1\n";
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(strands.repeat(3).as_bytes()).unwrap();
    std::fs::write(dir.join("geometry/strands.pbrt.gz"), gz.finish().unwrap()).unwrap();
    let options = hairtrace::image::WriteOptions::default();
    hairtrace::image::write_image(&dir.join("sky.exr"), 4, 4, 3, &[0.5; 48], &options).unwrap();
    std::fs::write(
        dir.join("scene.pbrt"),
        "Integrator \"volpath\" \"integer maxdepth\" [ 32 ]\n\
         Transform [ 1 0 0 0  0 1 0 0  0 0 1 0  0 -1 10 1 ]\n\
         Film \"rgb\" \"float iso\" [ 400 ] \"integer xresolution\" 16 \"integer yresolution\" 16\n\
         Camera \"perspective\" \"float fov\" [ 32 ] \"float shutterclose\" 0.5\n\
         WorldBegin\n\
         AttributeBegin\n  Rotate -120 1 0 0\n  Rotate 120 0 0 1\n\
           LightSource \"infinite\" \"string filename\" \"sky.exr\"\nAttributeEnd\n\
         Material \"hair\" \"float beta_m\" 0.25 \"float eumelanin\" 2\n\
         Include \"geometry/strands.pbrt.gz\"\n\
         AttributeBegin\nCoordSysTransform \"camera\"\n\
         Material \"diffuse\" \"rgb reflectance\" [.1 .1 .1]\n\
         Translate 0 2 25\nShape \"sphere\" \"float radius\" 3\nAttributeEnd\n",
    )
    .unwrap();
    let s = PbrtScene::from_file(&dir.join("scene.pbrt")).unwrap();
    let d = &s.description;
    assert_eq!(control_points(&s, 0).1, [4, 4, 4]);
    // Film gain: shutter 0.5 x iso 400 / 100 = 2.
    assert!(matches!(&d.lights[0], LightDesc::Environment { scale, .. } if *scale == 2.0));
    // The camera at world (0, 1, -10) (the inverse of its transform), looking down +z.
    assert_eq!(d.camera.eye, Some([0.0, 1.0, -10.0]));
    assert_eq!(d.camera.target, Some([0.0, 1.0, -9.0]));
    // The sphere 25 ahead of the camera and 2 up, in world space.
    let MeshSource::Triangles(sphere) = &d.meshes[0].source else {
        panic!("an inline mesh");
    };
    let n = sphere.positions.len() as f32;
    let centre = sphere
        .positions
        .iter()
        .fold([0.0f32; 3], |c, p| std::array::from_fn(|k| c[k] + p[k] / n));
    assert!(close(&centre, &[0.0, 3.0, 15.0], 1e-3), "{centre:?}");
    assert!(d.build(Arc::new(Device::new(Some(1)).unwrap())).is_ok());
}

#[test]
fn a_steeply_tapered_bspline_keeps_its_curve_and_widths() {
    // One segment from width 0.03 to 0.001: the B-spline's outer points would need
    // negative widths, so the curve comes as its Bezier form.
    let p = [
        [0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 2.0, 0.0],
        [1.0, 3.0, 1.0],
    ];
    let flat: Vec<String> = p.iter().flatten().map(|v: &f32| v.to_string()).collect();
    let body = format!(
        "Material \"hair\"\nShape \"curve\" \"string basis\" \"bspline\" \"point3 P\" [{}] \
         \"float width0\" 0.03 \"float width1\" 0.001\n",
        flat.join(" ")
    );
    let s = scene(&body).unwrap();
    assert_eq!(basis(&s.description.grooms[0]), CurveBasis::Bezier);
    let (points, _) = control_points(&s, 0);
    let original: Vec<[f32; 4]> = p.iter().map(|q| [-q[0], q[1], q[2], 0.0]).collect();
    for t in [0.0, 0.3, 0.7, 1.0] {
        let got = bezier(points, t);
        let want = bspline(&original, t);
        assert!(
            close(&got[..3], &want[..3], 1e-6),
            "t {t}: {got:?} {want:?}"
        );
        assert!(
            (got[3] - (0.03 + (0.001 - 0.03) * t) / 2.0).abs() < 1e-7,
            "t {t}"
        );
    }
}
