//! Scene descriptions: the example files and the demos parse and build, and every kind of
//! bad input is an error that names the file, the key and (while parsing) the line.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use hairtrace::Error;
use hairtrace::bsdf::SIGMA_A_PRESETS;
use hairtrace::description::{
    DEMOS, GroomSource, LightDesc, MaterialDesc, SceneDescription, Shutter, Transform, demo,
    quick_look,
};
use hairtrace::embree::{CurveBasis, Device};
use hairtrace::formats::hair::{Thickness, write_hair_file};
use hairtrace::render::PixelFilter;
use hairtrace::render::settings::Roulette;
use hairtrace::scene::GroomShape;
use hairtrace::scene::{FurBall, HairStyle};
use hairtrace::scene::{HairColor, HairModel};

/// The camera a render of the scene's own settings uses.
fn placed(scene: &hairtrace::Scene) -> hairtrace::scene::Camera {
    scene.placed_camera(&scene.settings).unwrap()
}

fn device() -> Arc<Device> {
    Arc::new(Device::new(Some(1)).unwrap())
}

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes")
}

/// A fresh folder for one test's files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "hairtrace-description-{}-{name}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Fewer strands, so that building stays quick.
fn shrink(desc: &mut SceneDescription) {
    for g in &mut desc.grooms {
        match &mut g.source {
            GroomSource::FurBall(f) => f.strands = 300,
            GroomSource::Scalp(s) => s.strands = 300,
            GroomSource::File { .. }
            | GroomSource::Strands(_)
            | GroomSource::ControlPoints { .. } => {}
        }
    }
}

fn parse(text: &str) -> hairtrace::Result<SceneDescription> {
    SceneDescription::from_toml(text, Path::new("/scenes"), "test.toml")
}

/// The message of a parse error, checked to be an invalid-argument error.
fn parse_error(text: &str) -> String {
    match parse(text) {
        Err(Error::InvalidArg(m)) => m,
        other => panic!("expected an invalid-argument error, got {other:?}"),
    }
}

fn build_error(text: &str) -> Error {
    match parse(text).unwrap().build(device()) {
        Err(e) => e,
        Ok(_) => panic!("expected {text} to fail to build"),
    }
}

fn assert_contains(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "{message:?} should contain {p:?}");
    }
}

/// A valid scene to break one piece at a time.
const BASE: &str = r#"
[materials.brown]
type = "hair"
melanin = [1.3, 0.2]

[materials.skin]
type = "diffuse"
albedo = [0.6, 0.5, 0.4]

[[groom]]
procedural = "fur_ball"
material = "brown"
[groom.params]
strands = 50

[[mesh]]
shape = "sphere"
radius = 1.0
material = "skin"

[[light]]
type = "environment"
radiance = [1, 1, 1]
"#;

#[test]
fn example_scenes_parse_and_build() {
    let mut found = 0;
    for entry in std::fs::read_dir(examples()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let desc = SceneDescription::from_file(&path).unwrap();
            let built = desc
                .build(device())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            assert_eq!(built.settings.width, desc.render.width);
            assert!(placed(&built).forward().is_normalized());
            found += 1;
        }
    }
    assert!(found >= 2, "only {found} example scenes");
}

#[test]
fn example_keys_reach_the_description() {
    let desc = SceneDescription::from_file(&examples().join("scalp.toml")).unwrap();
    let g = &desc.grooms[0];
    assert_eq!(g.basis, Some(CurveBasis::CatmullRom));
    assert_eq!(g.shape, GroomShape::Auto);
    assert_eq!(
        g.transform,
        Transform::Trs {
            translate: [0.0; 3],
            rotate_deg: [0.0, 60.0, 0.0],
            scale: 1.0
        }
    );
    let GroomSource::Scalp(s) = &g.source else {
        panic!("not a scalp: {:?}", g.source)
    };
    assert_eq!(
        (s.style, s.strands, s.segments),
        (HairStyle::Curly, 2000, 40)
    );
    let MaterialDesc::Hair(h) = &desc.materials["dark"] else {
        panic!("not hair")
    };
    assert_eq!(
        h.color,
        HairColor::Melanin {
            eumelanin: 2.0,
            pheomelanin: 0.4
        }
    );
    assert_eq!((h.beta_m, h.tip_absorption), (0.25, 0.7));
    assert_eq!(desc.camera.eye, None);
    assert!(matches!(desc.lights[0], LightDesc::Rect { .. }));
}

#[test]
fn every_demo_builds() {
    for name in DEMOS {
        let mut desc = demo(name).unwrap();
        shrink(&mut desc);
        let built = desc
            .build(device())
            .unwrap_or_else(|e| panic!("demo {name}: {e}"));
        assert_eq!((built.settings.width, built.settings.height), (640, 480));
    }
    let e = demo("furry").unwrap_err().to_string();
    assert_contains(&e, &["furry", "furball, furnace, scalp"]);
}

#[test]
fn cli_style_overrides_reach_the_settings() {
    let mut desc = parse(BASE).unwrap();
    desc.render.spp = 3;
    desc.render.width = 64;
    desc.render.height = 32;
    desc.render.path.max_depth = 12;
    let built = desc.build(device()).unwrap();
    assert_eq!(built.settings.spp, 3);
    assert_eq!((built.settings.width, built.settings.height), (64, 32));
    assert_eq!(built.settings.path.max_depth, 12);
}

#[test]
fn misspelt_keys_name_the_key_and_line() {
    let e = parse_error("[render]\nwidth = 64\nspp_count = 4\n");
    assert_contains(&e, &["test.toml:3:1", "spp_count", "spp"]);

    // The second groom's table: the line is the key's, not the first groom's.
    let text = format!("{BASE}\n[[groom]]\nfile = \"a.hair\"\nmaterail = \"brown\"\n");
    let line = text
        .lines()
        .position(|l| l.starts_with("materail"))
        .unwrap()
        + 1;
    let e = parse_error(&text);
    assert_contains(&e, &[&format!("test.toml:{line}:"), "materail"]);

    let e = parse_error("[camera]\nfov = 30\n");
    assert_contains(&e, &["test.toml:2:1", "`fov`", "fov_deg"]);
}

#[test]
fn bad_choices_list_the_valid_ones() {
    let e = parse_error(&BASE.replace(
        "material = \"brown\"",
        "material = \"brown\"\nbasis = \"bspine\"",
    ));
    assert_contains(
        &e,
        &["bspine", "linear", "bezier", "bspline", "catmull_rom"],
    );

    let e = parse_error(&BASE.replace("procedural = \"fur_ball\"", "procedural = \"hedgehog\""));
    assert_contains(&e, &["hedgehog", "fur_ball", "scalp"]);

    let e = parse_error(&BASE.replace("strands = 50", "strands = 50\nstrandz = 3"));
    let line = BASE.lines().position(|l| l == "strands = 50").unwrap() + 2;
    assert_contains(
        &e,
        &[
            &format!("test.toml:{line}:"),
            "groom[0].params.strandz",
            "clumping",
        ],
    );

    let e = parse_error(&BASE.replace("strands = 50", "strands = -50"));
    assert_contains(&e, &["groom[0].params.strands", "-50"]);

    let e = parse_error(&BASE.replace("type = \"environment\"", "type = \"sun\""));
    assert_contains(&e, &["sun", "environment", "distant", "rect"]);
}

#[test]
fn absorption_presets_by_name() {
    for (name, sigma_a) in SIGMA_A_PRESETS {
        let text = BASE.replace("melanin = [1.3, 0.2]", &format!("preset = \"{name}\""));
        let desc = parse(&text).unwrap();
        let MaterialDesc::Hair(h) = &desc.materials["brown"] else {
            panic!("a hair material");
        };
        assert_eq!(h.color, HairColor::SigmaA(sigma_a), "{name}");
    }
    let e = parse_error(&BASE.replace("melanin = [1.3, 0.2]", "preset = \"auburn\""));
    assert_contains(&e, &["materials.brown", "\"auburn\"", "red_brown", "white"]);
    // A preset is one more way to give the absorption: never together with another.
    for other in [
        "melanin = [1.3, 0.2]",
        "sigma_a = [1, 1, 1]",
        "color = [0.5, 0.4, 0.3]",
    ] {
        let e = parse_error(&BASE.replace(
            "melanin = [1.3, 0.2]",
            &format!("{other}\npreset = \"black\""),
        ));
        assert_contains(&e, &["materials.brown", "exactly one of", "`preset`"]);
    }
    let e = parse_error(&BASE.replace(
        "albedo = [0.6, 0.5, 0.4]",
        "albedo = [0.6, 0.5, 0.4]\npreset = \"black\"",
    ));
    assert_contains(&e, &["materials.skin.preset", "diffuse"]);
}

/// `model = "huang"` takes `roughness` and `aspect`; each model refuses the other's keys,
/// and a bad aspect fails the build naming the material.
#[test]
fn hair_models_by_name() {
    let huang = BASE.replace(
        "melanin = [1.3, 0.2]",
        "melanin = [1.3, 0.2]\nmodel = \"huang\"\nroughness = 0.2\naspect = 0.65",
    );
    let MaterialDesc::Hair(h) = &parse(&huang).unwrap().materials["brown"] else {
        panic!("a hair material");
    };
    assert_eq!(
        h.model,
        HairModel::Huang {
            roughness: 0.2,
            aspect: 0.65
        }
    );
    let MaterialDesc::Hair(h) = &parse(BASE).unwrap().materials["brown"] else {
        panic!("a hair material");
    };
    assert_eq!(h.model, HairModel::Chiang);
    let e =
        parse_error(&BASE.replace("melanin = [1.3, 0.2]", "melanin = [1.3, 0.2]\naspect = 0.7"));
    assert_contains(&e, &["materials.brown.aspect", "model \"chiang\""]);
    let e = parse_error(&huang.replace("roughness = 0.2", "beta_m = 0.2"));
    assert_contains(&e, &["materials.brown.beta_m", "model \"huang\""]);
    let e = parse_error(&BASE.replace(
        "melanin = [1.3, 0.2]",
        "melanin = [1.3, 0.2]\nmodel = \"marschner\"",
    ));
    assert_contains(&e, &["test.toml:", "marschner", "chiang", "huang"]);
    let e = build_error(&huang.replace("aspect = 0.65", "aspect = 1.5")).to_string();
    assert_contains(&e, &["brown", "aspect = 1.5"]);
    // The scene renders: a thin groom, the far field.
    let mut desc = parse(&huang).unwrap();
    shrink(&mut desc);
    let mut scene = hairtrace::Scene::from_description(&desc, device()).unwrap();
    let image = scene
        .render(Default::default(), &hairtrace::NoProgress)
        .unwrap();
    assert!(image.film.rgb().iter().all(|v| v.is_finite() && *v >= 0.0));
}

#[test]
fn entries_must_make_each_choice_once() {
    let both = BASE.replace(
        "procedural = \"fur_ball\"",
        "procedural = \"fur_ball\"\nfile = \"x.hair\"",
    );
    let e = parse_error(&both);
    assert_contains(&e, &["test.toml:", "groom[0]", "`file`", "`procedural`"]);

    let e = parse_error(&BASE.replace(
        "melanin = [1.3, 0.2]",
        "melanin = [1.3, 0.2]\ncolor = [0.5, 0.4, 0.3]",
    ));
    assert_contains(&e, &["materials.brown", "sigma_a", "melanin", "color"]);

    let e = parse_error(&BASE.replace(
        "albedo = [0.6, 0.5, 0.4]",
        "albedo = [0.6, 0.5, 0.4]\nbeta_m = 0.3",
    ));
    assert_contains(
        &e,
        &[
            "materials.skin.beta_m",
            "does not apply to a diffuse material",
        ],
    );

    let e = parse_error(&BASE.replace("radius = 1.0", "radius = 1.0\nhalf_size = 3"));
    assert_contains(&e, &["mesh[0].half_size", "sphere"]);

    let e = parse_error(&BASE.replace(
        "radiance = [1, 1, 1]",
        "radiance = [1, 1, 1]\ndirection = [0, 1, 0]",
    ));
    assert_contains(&e, &["light[0].direction", "environment light"]);

    let e = parse_error("[[light]]\ntype = \"distant\"\nirradiance = [1, 1, 1]\n");
    assert_contains(&e, &["test.toml:1:", "light[0]", "needs `direction`"]);
}

#[test]
fn unknown_material_lists_the_defined_ones() {
    let text = format!("{BASE}\n[[groom]]\nprocedural = \"fur_ball\"\nmaterial = \"blond\"\n");
    let e = build_error(&text).to_string();
    assert_contains(
        &e,
        &[
            "test.toml: groom[1].material",
            "no material named \"blond\" (defined: brown, skin)",
        ],
    );
}

#[test]
fn materials_must_suit_the_geometry() {
    let e = build_error(&BASE.replace("material = \"skin\"", "material = \"brown\"")).to_string();
    assert_contains(&e, &["mesh[0].material", "\"brown\" is a hair material"]);

    let e = build_error(&BASE.replace(
        "material = \"brown\"\n[groom",
        "material = \"skin\"\n[groom",
    ))
    .to_string();
    assert_contains(&e, &["groom[0].material", "\"skin\" is a diffuse material"]);
}

#[test]
fn missing_files_are_io_errors_that_name_them() {
    let e = build_error(
        &BASE
            .replace("procedural = \"fur_ball\"", "file = \"nowhere/lost.hair\"")
            .replace("[groom.params]\nstrands = 50\n", ""),
    );
    let Error::Io(m) = &e else {
        panic!("expected an i/o error, got {e:?}")
    };
    assert_contains(m, &["test.toml: groom[0]", "/scenes/nowhere/lost.hair"]);

    let e = SceneDescription::from_file(Path::new("/no/such/scene.toml")).unwrap_err();
    assert!(
        matches!(&e, Error::Io(m) if m.contains("/no/such/scene.toml")),
        "{e:?}"
    );

    let e = quick_look(Path::new("/no/such/groom.hair")).unwrap_err();
    assert!(
        matches!(&e, Error::Io(m) if m.contains("/no/such/groom.hair")),
        "{e:?}"
    );
}

#[test]
fn render_keys_pick_the_filter_the_roulette_and_the_fidelity_knobs() {
    let d = parse(&format!(
        "[render]\nfilter = \"box\"\nroulette = \"throughput\"\nrr_depth = 3\n{BASE}"
    ))
    .unwrap();
    let s = d.render;
    assert_eq!(s.pixel_filter().unwrap(), PixelFilter::BOX);
    assert_eq!(
        (s.path.roulette, s.path.rr_depth),
        (Roulette::Throughput, 3)
    );
    let d = parse(&format!("[render]\nfilter_radius = 2\n{BASE}")).unwrap();
    assert_eq!(
        d.render.pixel_filter().unwrap(),
        PixelFilter::tent(2.0).unwrap()
    );
    let d = parse(&format!(
        "[render]\ndeep_bounce_depth = 3\nlobe_cull = 0.05\nlight_threshold = 0\n{BASE}"
    ))
    .unwrap();
    let s = d.render;
    assert_eq!(
        (
            s.path.deep_bounce_depth,
            s.path.lobe_cull,
            s.path.light_threshold
        ),
        (Some(3), 0.05, 0.0)
    );
    // The defaults: a tent of one pixel, roulette on sqrt(throughput) after two events,
    // the exact hair BSDF at every event.
    let s = parse(BASE).unwrap().render;
    assert_eq!(s.pixel_filter().unwrap(), PixelFilter::default());
    assert_eq!(
        (s.path.roulette, s.path.rr_depth),
        (Roulette::SqrtThroughput, 2)
    );
    assert_eq!((s.path.deep_bounce_depth, s.path.lobe_cull), (None, 0.0));
    assert_eq!(s.path.light_threshold, 0.03);

    for (keys, expect) in [
        (
            "filter = \"gauss\"",
            &["test.toml:2:1", "render.filter = gauss", "tent | box"][..],
        ),
        ("filter_radius = 0", &["render.filter_radius = 0", "(0, 8]"]),
        (
            "roulette = \"maybe\"",
            &["render.roulette = maybe", "sqrt | throughput"],
        ),
        ("rr_depth = 0", &["render.rr_depth = 0", ">= 1"]),
        ("deep_bounce_depth = 0", &["render.deep_bounce_depth = 0"]),
        ("lobe_cull = 1.5", &["render.lobe_cull = 1.5", "[0, 1)"]),
        (
            "light_threshold = -1",
            &["render.light_threshold = -1", ">= 0"],
        ),
        ("spp = \"many\"", &["render.spp = many", "an integer"]),
        ("crop = [1, 2]", &["render.crop = 1,2", "x0,y0,x1,y1"]),
    ] {
        let e = parse_error(&format!("[render]\n{keys}\n{BASE}"));
        assert_contains(&e, expect);
    }
    // Rules between settings are checked when the scene is built.
    let e = build_error(&format!(
        "[render]\nmax_depth = 4\ndeep_bounce_depth = 5\n{BASE}"
    ));
    assert_contains(
        &e.to_string(),
        &["render", "deep_bounce_depth = 5", "max_depth = 4"],
    );
}

/// The peer benchmark's scenes are scene files like any other: they parse and build (the
/// command line's `export` tests write them for the peer).
#[test]
fn bench_scenes_build() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/scenes");
    let mut found = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        // The real grooms' files are made on demand by bench/real_grooms.py.
        let real = path
            .file_stem()
            .is_some_and(|s| s.to_string_lossy().starts_with("real_"));
        if path.extension().is_some_and(|e| e == "toml") && !real {
            let mut desc = SceneDescription::from_file(&path).unwrap();
            shrink(&mut desc);
            desc.build(device())
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            found += 1;
        }
    }
    assert!(found >= 4, "only {found} bench scenes");
}

/// Grooms and meshes take a transform as `rotate`/`translate`/`scale` or as a `matrix`, the
/// same map either way: turns about x, then y, then z (Blender's XYZ Euler), radii scaled.
/// A matrix that would flatten round fibres, and both forms at once, are refused; a mirror
/// keeps them round.
#[test]
fn transforms_turn_scale_and_move_grooms_and_meshes() {
    let groom = |transform: &str| {
        let text = BASE.replace(
            "material = \"brown\"\n[groom.params]",
            &format!("material = \"brown\"\n{transform}\n[groom.params]"),
        );
        parse(&text).unwrap().grooms[0]
            .placed_strands()
            .unwrap()
            .remove(0)
            .strands
    };
    let plain = groom("");
    let trs = groom("rotate = [90, 0, 90]\nscale = 2\ntranslate = [1, 2, 3]");
    // Rx(90) then Rz(90): (x, y, z) -> (x, -z, y) -> (z, x, y); times 2, then moved.
    let matrix = "matrix = [[0, 0, 2, 1], [2, 0, 0, 2], [0, 2, 0, 3], [0, 0, 0, 1]]";
    let by_matrix = groom(matrix);
    for ((p, q), m) in plain.points.iter().zip(&trs.points).zip(&by_matrix.points) {
        let want = [2.0 * p[2] + 1.0, 2.0 * p[0] + 2.0, 2.0 * p[1] + 3.0];
        for k in 0..3 {
            assert!((q[k] - want[k]).abs() < 1e-5, "{q:?} {want:?}");
            assert!((m[k] - want[k]).abs() < 1e-5, "{m:?} {want:?}");
        }
    }
    assert_eq!(trs.radii[0], 2.0 * plain.radii[0]);
    assert!((by_matrix.radii[0] - 2.0 * plain.radii[0]).abs() < 1e-7);
    // A mesh goes where its groom goes.
    let mesh = |transform: &str| {
        let text = BASE.replace("radius = 1.0", &format!("radius = 1.0\n{transform}"));
        parse(&text).unwrap().meshes[0]
            .mesh(Shutter::default())
            .unwrap()
    };
    let (a, b) = (
        mesh("rotate = [90, 0, 90]\nscale = 2\ntranslate = [1, 2, 3]"),
        mesh(matrix),
    );
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((0..3).all(|k| (p[k] - q[k]).abs() < 1e-5), "{p:?} {q:?}");
    }

    for (bad, want) in [
        (
            "matrix = [[1, 0, 0, 0], [0, 2, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]",
            "radii can follow a uniform scale only",
        ),
        (
            "matrix = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [1, 0, 0, 1]]",
            "last row 0 0 0 1",
        ),
        ("rotate = [nan, 0, 0]", "rotate"),
    ] {
        let text = BASE.replace(
            "strands = 50",
            &format!(
                "strands = 50\n[[groom]]\nprocedural = \"fur_ball\"\nmaterial = \"brown\"\n{bad}"
            ),
        );
        let e = build_error(&text).to_string();
        assert_contains(&e, &["groom[1]", want]);
    }
    let e = parse_error(&BASE.replace(
        "radius = 1.0",
        &format!("radius = 1.0\n{matrix}\nscale = 2"),
    ));
    assert_contains(
        &e,
        &["mesh[0]", "scale", "does not apply to a `matrix` transform"],
    );
}

#[test]
fn bad_values_name_their_entry() {
    let e = build_error(&BASE.replace("radiance = [1, 1, 1]", "radiance = [-1, 1, 1]")).to_string();
    assert_contains(&e, &["test.toml: light[0]", "radiance", "-1"]);

    let e = parse_error(&format!("[render]\nwidth = 0\n{BASE}"));
    assert_contains(&e, &["test.toml:2:1: render", "width = 0"]);

    let e = build_error(&BASE.replace("strands = 50", "strands = 0")).to_string();
    assert_contains(&e, &["groom[0]", "strands"]);

    let e = build_error(&BASE.replace("radius = 1.0", "radius = 1.0\nscale = -2")).to_string();
    assert_contains(&e, &["mesh[0]", "scale = -2"]);

    let e = build_error(&BASE.replace(
        "[[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n",
        "",
    ))
    .to_string();
    assert_contains(&e, &["test.toml", "no lights"]);

    let e = build_error(&format!("[camera]\neye = [0, 0, 5]\n{BASE}")).to_string();
    assert_contains(&e, &["camera", "`eye` and `target`"]);
}

#[test]
fn quick_look_frames_a_hair_file_and_paths_follow_the_scene_file() {
    let dir = scratch("quick_look");
    let strands = FurBall {
        strands: 100,
        segments: 4,
        ..FurBall::default()
    }
    .build()
    .unwrap();
    let hair = dir.join("ball.hair");
    write_hair_file(&hair, &strands, Thickness::Diameter).unwrap();

    // The file does not say which curve its points draw: none is assumed for it.
    let mut look = quick_look(&hair).unwrap();
    assert_eq!(look.grooms[0].basis, None);
    assert_eq!(look.grooms[0].shape, GroomShape::Auto);
    let m = look.build(device()).err().unwrap().to_string();
    assert!(
        m.contains("ball.hair") && m.contains("does not say which curve"),
        "{m}"
    );
    look.grooms[0].basis = Some(CurveBasis::BSpline);
    let built = look.build(device()).unwrap();
    // The automatic camera looks at the groom's centre, the origin.
    let to_centre = (-placed(&built).eye()).normalize();
    assert!(placed(&built).forward().dot(to_centre) > 0.999);

    // A scene file next to the groom names it by a relative path; a transform moves it and
    // the automatic camera follows.
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        "[materials.h]\ntype = \"hair\"\ncolor = [0.6, 0.4, 0.2]\n\n[[groom]]\nfile = \"ball.hair\"\nbasis = \"bspline\"\n\
         thickness = \"radius\"\ntranslate = [10, 0, 0]\nscale = 2\nmaterial = \"h\"\n\n\
         [[light]]\ntype = \"distant\"\ndirection = [0, 1, 0]\nirradiance = [1, 1, 1]\n",
    )
    .unwrap();
    let desc = SceneDescription::from_file(&scene).unwrap();
    assert_eq!(
        desc.grooms[0].source,
        GroomSource::File {
            path: dir.join("ball.hair"),
            thickness: Thickness::Radius,
            frame: None,
        }
    );
    let built = desc.build(device()).unwrap();
    let to_centre = (Vec3::new(10.0, 0.0, 0.0) - placed(&built).eye()).normalize();
    assert!(placed(&built).forward().dot(to_centre) > 0.999);
    // Twice the size: the camera stands about twice as far away.
    let mut look = quick_look(&hair).unwrap();
    look.grooms[0].basis = Some(CurveBasis::BSpline);
    let near = look_distance(&look);
    let far = placed(&built).eye().distance(Vec3::new(10.0, 0.0, 0.0));
    assert!((far / near - 2.0).abs() < 0.05, "{near} -> {far}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn look_distance(desc: &SceneDescription) -> f32 {
    placed(&desc.build(device()).unwrap()).eye().length()
}

#[test]
fn documented_format_parses() {
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("src/description/mod.rs"),
    )
    .unwrap();
    let doc: String = source
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .skip_while(|l| *l != "```toml")
        .skip(1)
        .take_while(|l| *l != "```")
        .collect::<Vec<_>>()
        .join("\n");
    let desc = parse(&doc).unwrap_or_else(|e| panic!("{e}\n{doc}"));
    assert_eq!(
        (desc.grooms.len(), desc.meshes.len(), desc.lights.len()),
        (2, 2, 3)
    );
    assert_eq!(desc.render.crop, Some([0, 0, 320, 240]));
}
