//! USD BasisCurves read against Pixar's own library: the fixtures in tests/fixtures/usd were
//! written by usd-core (make_fixtures.py), and expected.json holds what usd-core reports for
//! each prim; hairtrace's reader must agree, for the text and the binary file alike. Then
//! each fixture renders, and bad files are refused with a message.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use hairtrace::Error;
use hairtrace::description::{SceneDescription, quick_look};
use hairtrace::embree::{CurveShape, Device};
use hairtrace::formats::units::{StageUnits, UpAxis};
use hairtrace::formats::usd::{UsdGrooms, read_usd_file};
use hairtrace::render::NO_STRAND;
use hairtrace::scene::HairColor;
use hairtrace::{Aovs, NoProgress};
use serde_json::Value;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/usd")
}

fn expected() -> Value {
    let text = std::fs::read_to_string(fixtures().join("expected.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn close(a: f64, b: f64, what: &str) {
    assert!(
        (a - b).abs() <= 1e-5 * (1.0 + b.abs()),
        "{what}: hairtrace {a}, usd-core {b}"
    );
}

fn check_against_usd_core(name: &str, grooms: &UsdGrooms, want: &Value) {
    assert_eq!(
        grooms.units.up_axis.name(),
        want["upAxis"].as_str().unwrap(),
        "{name}"
    );
    close(
        grooms.units.meters_per_unit,
        want["metersPerUnit"].as_f64().unwrap(),
        name,
    );
    let prims = want["prims"].as_object().unwrap();
    assert_eq!(
        grooms.curves.len(),
        prims.len(),
        "{name}: BasisCurves prims"
    );
    for c in &grooms.curves {
        let w = &prims[&c.path];
        let at = format!("{name} {}", c.path);
        assert_eq!(
            c.authored_counts.len() as u64,
            w["curves"].as_u64().unwrap(),
            "{at}"
        );
        let points: u64 = c.authored_counts.iter().map(|&n| u64::from(n)).sum();
        assert_eq!(points, w["points"].as_u64().unwrap(), "{at}");
        assert_eq!(c.segments as u64, w["segments"].as_u64().unwrap(), "{at}");
        for k in 0..3 {
            close(
                c.bounds.0[k].into(),
                w["bounds"][0][k].as_f64().unwrap(),
                &at,
            );
            close(
                c.bounds.1[k].into(),
                w["bounds"][1][k].as_f64().unwrap(),
                &at,
            );
        }
        close(
            c.radius_range.0.into(),
            w["radius"][0].as_f64().unwrap(),
            &at,
        );
        close(
            c.radius_range.1.into(),
            w["radius"][1].as_f64().unwrap(),
            &at,
        );
    }
    let ignored: &[&str] = if name.starts_with("all_bases") {
        &["/groom/head (Sphere)"]
    } else {
        &[]
    };
    assert_eq!(grooms.ignored, ignored, "{name}");
}

/// Every fixture usd-core described, text and binary.
fn fixture_names() -> Vec<String> {
    let names: Vec<String> = expected().as_object().unwrap().keys().cloned().collect();
    assert!(names.len() >= 22, "{names:?}");
    names
}

#[test]
fn usda_and_usdc_agree_with_usd_core() {
    let want = expected();
    for name in fixture_names() {
        let grooms = read_usd_file(&fixtures().join(&name)).unwrap();
        check_against_usd_core(&name, &grooms, &want[&name]);
    }
}

/// A text fixture and the crate file usd-core wrote of it read to the same grooms, bit for
/// bit (the text is read through the reader's fast path for numeric arrays).
#[test]
fn usda_and_usdc_of_the_same_curves_read_identically() {
    let names: Vec<String> = fixture_names()
        .into_iter()
        .filter(|n| n.ends_with(".usda"))
        .collect();
    assert!(names.len() >= 11, "{names:?}");
    for name in names {
        let text = read_usd_file(&fixtures().join(&name)).unwrap();
        let crate_file = read_usd_file(&fixtures().join(name.replace(".usda", ".usdc"))).unwrap();
        assert_eq!(format!("{text:?}"), format!("{crate_file:?}"), "{name}");
    }
}

#[test]
fn every_fixture_renders_a_visible_image() {
    let device = Arc::new(Device::new(Some(1)).unwrap());
    for name in fixture_names() {
        let mut desc = quick_look(&fixtures().join(&name)).unwrap();
        // Thicker fibres, so that a tiny image shows even the shortest fixture.
        desc.grooms[0].radius_scale = 4.0;
        desc.render.width = 48;
        desc.render.height = 32;
        desc.render.spp = 1;
        let mut built = desc.build(device.clone()).unwrap();
        let aovs = Aovs {
            strand_id: true,
            ..Aovs::default()
        };
        let out = built.render(aovs, &NoProgress).unwrap();
        let ids = out.film.strand_id().unwrap();
        let hair = ids.iter().filter(|&&s| s != NO_STRAND).count();
        assert!(hair >= 3, "{name}: {hair} of {} pixels see hair", ids.len());
        let rgb = out.film.rgb();
        assert!(
            rgb.iter().all(|v| v.is_finite()) && rgb.iter().any(|&v| v > 0.0),
            "{name}"
        );
    }
}

pub(crate) fn refused(text: impl AsRef<[u8]>, name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("hairtrace-usd-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    match read_usd_file(&path) {
        Err(Error::InvalidArg(m)) => m,
        other => panic!("{name}: expected an invalid-argument error, got {other:?}"),
    }
}

const HEADER: &str = "#usda 1.0\n";

fn curves_prim(body: &str) -> String {
    format!("{HEADER}def BasisCurves \"c\"\n{{\n{body}\n}}\n")
}

/// A Z-up stage in centimetres, as Blender's and Maya's exporters write them, renders
/// upright with the automatic camera: a vertical strand along the stage's +z and a
/// horizontal one across its top come out vertical and on top in the image, and the groom
/// is read in metres.
#[test]
fn a_z_up_stage_renders_upright_in_metres() {
    let text = format!(
        "{HEADER}(\n    upAxis = \"Z\"\n    metersPerUnit = 0.01\n)\ndef Xform \"Groom\"\n{{\n\
         def BasisCurves \"hair\"\n{{\nuniform token type = \"linear\"\n\
         int[] curveVertexCounts = [2, 2]\n\
         point3f[] points = [(0, 0, 0), (0, 0, 20), (-10, 0, 20), (10, 0, 20)]\n\
         float[] widths = [0.4] (interpolation = \"constant\")\n}}\n}}\n"
    );
    let dir = std::env::temp_dir().join(format!("hairtrace-zup-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("z_up.usda");
    std::fs::write(&path, text).unwrap();
    let grooms = read_usd_file(&path).unwrap();
    assert_eq!(grooms.units, StageUnits::new(UpAxis::Z, 0.01).unwrap());

    let mut desc = quick_look(&path).unwrap();
    let placed = desc.grooms[0].placed_strands().unwrap();
    // The stage's +z is +y, in metres; its +y is -z.
    let [x, y, z] = placed[0].strands.points[1];
    assert!(
        x == 0.0 && (y - 0.2).abs() < 1e-7 && z == 0.0,
        "{:?}",
        [x, y, z]
    );
    assert!((placed[0].strands.radii[0] - 0.002).abs() < 1e-9);
    (desc.render.width, desc.render.height, desc.render.spp) = (48, 48, 1);
    let mut built = desc.build(Arc::new(Device::new(Some(1)).unwrap())).unwrap();
    let aovs = Aovs {
        strand_id: true,
        ..Aovs::default()
    };
    let ids = built
        .render(aovs, &NoProgress)
        .unwrap()
        .film
        .strand_id()
        .unwrap()
        .to_vec();
    // Rows (top first) and columns of each strand's pixels.
    let extent = |strand: f32| {
        let (rows, cols): (Vec<usize>, Vec<usize>) = (ids.iter().enumerate())
            .filter(|&(_, &s)| s == strand)
            .map(|(i, _)| (i / 48, i % 48))
            .unzip();
        let span = |v: &[usize]| v.iter().max().unwrap() - v.iter().min().unwrap();
        let mean = rows.iter().sum::<usize>() as f32 / rows.len() as f32;
        (span(&rows), span(&cols), mean)
    };
    let (vertical, horizontal) = (extent(0.0), extent(1.0));
    assert!(
        vertical.0 > 3 * vertical.1,
        "the vertical strand is tall: {vertical:?}"
    );
    assert!(
        horizontal.1 > 3 * horizontal.0,
        "the top strand is wide: {horizontal:?}"
    );
    assert!(
        horizontal.2 < vertical.2,
        "the top strand is above: {horizontal:?} {vertical:?}"
    );
}

/// The faults real exporters make are refused with a message that names the file, the prim
/// and the attribute at fault (here inside an Xform, as DCCs write them).
#[test]
fn real_file_faults_name_the_prim_and_the_attribute() {
    let prim = |kind: &str, basis: &str, wrap: &str, counts: &str, points: usize, widths: usize| {
        let points: Vec<String> = (0..points)
            .map(|i| format!("({i}, {}, 0)", i * i))
            .collect();
        let widths: Vec<&str> = vec!["0.01"; widths];
        format!(
            "{HEADER}(\n    upAxis = \"Z\"\n    metersPerUnit = 1\n)\ndef Xform \"Hair\"\n{{\n\
             def BasisCurves \"strands\"\n{{\nuniform token type = \"{kind}\"\n\
             uniform token basis = \"{basis}\"\nuniform token wrap = \"{wrap}\"\n\
             int[] curveVertexCounts = {counts}\npoint3f[] points = [{}]\n\
             float[] widths = [{}] (interpolation = \"vertex\")\n}}\n}}\n",
            points.join(", "),
            widths.join(", ")
        )
    };
    for (name, text, want) in [
        (
            "counts_do_not_sum",
            prim("cubic", "catmullRom", "pinned", "[4, 4]", 7, 7),
            "curveVertexCounts add up to 8 points but points has 7",
        ),
        (
            "widths_length",
            prim("cubic", "catmullRom", "pinned", "[4, 3]", 7, 6),
            "widths has 6 values for Vertex interpolation: 7 expected",
        ),
        (
            "cubic_too_few",
            prim("cubic", "bspline", "nonperiodic", "[4, 3]", 7, 7),
            "curveVertexCounts[1] = 3: cubic bspline nonperiodic curves have at least 4 points",
        ),
        (
            "periodic_too_short",
            prim("cubic", "catmullRom", "periodic", "[5, 2]", 7, 7),
            "curveVertexCounts[1] = 2: cubic catmullRom periodic curves have at least 3 points",
        ),
    ] {
        let m = refused(text, &format!("{name}.usda"));
        assert!(
            m.contains(&format!("{name}.usda: /Hair/strands: {want}")),
            "{name}: {m}"
        );
    }
}

/// A tuple with another count of numbers than its type's is refused, naming the prim and
/// the attribute, wherever it is in the array (openusd alone would read it and fill the
/// missing numbers).
#[test]
fn tuples_of_the_wrong_size_are_refused() {
    let points = |list: &str| {
        curves_prim(&format!(
            "uniform token type = \"linear\"\nint[] curveVertexCounts = [2]\n\
             point3f[] points = [{list}]\nfloat[] widths = [0.1] (interpolation = \"constant\")"
        ))
    };
    for (name, list, element) in [
        ("short_first", "(0, 0), (1, 1, 1)", 0),
        ("short_last", "(0, 0, 0), (1, 1)", 1),
        ("long", "(0, 0, 0), (1, 1, 1, 1)", 1),
    ] {
        let m = refused(points(list), &format!("{name}.usda"));
        assert!(
            m.contains(&format!(
                "/c.points: element {element} is a tuple of another size"
            )),
            "{name}: {m}"
        );
    }
}

#[test]
fn bad_files_are_refused_with_a_message() {
    let ok = "int[] curveVertexCounts = [4]\npoint3f[] points = [(0,0,0),(0,1,0),(0,2,0),(0,3,0)]\nfloat[] widths = [0.1] (interpolation = \"constant\")\nuniform token type = \"linear\"";
    // The valid prim reads, so that each case below fails for its own reason.
    let dir = std::env::temp_dir().join(format!("hairtrace-usd-ok-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("ok.usda"), curves_prim(ok)).unwrap();
    assert_eq!(read_usd_file(&dir.join("ok.usda")).unwrap().curves.len(), 1);

    let cases: &[(&str, String, &str)] = &[
        ("empty", String::new(), "not a readable USD stage"),
        (
            "garbage",
            "\u{0}\u{1}PXR-USDC garbage".to_string(),
            "not a readable USD stage",
        ),
        (
            "truncated",
            curves_prim(ok)[..60].to_string(),
            "not a readable USD stage",
        ),
        (
            "counts_sum",
            curves_prim(&ok.replace("[4]", "[5]")),
            "add up to 5 points",
        ),
        (
            "huge_count",
            curves_prim(&ok.replace("[4]", "[2147483647]")),
            "add up to 2147483647",
        ),
        (
            "negative",
            curves_prim(&ok.replace("[4]", "[-4]")),
            "negative",
        ),
        (
            "wrong_type",
            curves_prim(&ok.replace("float[] widths = [0.1]", "string widths = \"x\"")),
            "widths: expected float[]",
        ),
        (
            "no_widths",
            curves_prim(&ok.replace("float[] widths = [0.1] (interpolation = \"constant\")", "")),
            "no widths",
        ),
        (
            "widths_len",
            curves_prim(&ok.replace("[0.1] (interpolation = \"constant\")", "[0.1, 0.2]")),
            "widths has 2 values for Vertex",
        ),
        // usd-core counts a pinned curve's varying values as its points - 2: 2 for 4.
        (
            "pinned_varying_len",
            curves_prim(
                &ok.replace(
                    "\"linear\"",
                    "\"cubic\"\nuniform token basis = \"bspline\"\nuniform token wrap = \"pinned\"",
                )
                .replace(
                    "[0.1] (interpolation = \"constant\")",
                    "[0.1, 0.2, 0.3, 0.4] (interpolation = \"varying\")",
                ),
            ),
            "widths has 4 values for Varying interpolation: 2 expected",
        ),
        (
            "pinned_varying_two_points",
            curves_prim(
                &ok.replace(
                    "\"linear\"",
                    "\"cubic\"\nuniform token basis = \"bspline\"\nuniform token wrap = \"pinned\"",
                )
                .replace("[4]", "[2]")
                .replace("(0,0,0),(0,1,0),(0,2,0),(0,3,0)", "(0,0,0),(0,1,0)")
                .replace(
                    "[0.1] (interpolation = \"constant\")",
                    "[0.1] (interpolation = \"varying\")",
                ),
            ),
            "a pinned curve of 2 points has no varying values",
        ),
        (
            "zero_width",
            curves_prim(&ok.replace("[0.1]", "[0]")),
            "widths[0] = 0",
        ),
        (
            "nan_point",
            curves_prim(&ok.replace("(0,3,0)", "(0,nan,0)")),
            "point 3 = [0, NaN, 0]: every coordinate must be finite",
        ),
        (
            // Finite, but past what Embree's rays can reach (CI's fuzzing found this one).
            "huge_point",
            curves_prim(&ok.replace("(0,3,0)", "(0,3e29,0)")),
            "point 3 = [0, 3000000000000000000000000000",
        ),
        (
            "scaled_past_the_limit",
            format!(
                "{HEADER}def Xform \"x\"\n{{\nfloat3 xformOp:scale = (1e15, 1e15, 1e15)\nuniform token[] xformOpOrder = [\"xformOp:scale\"]\ndef BasisCurves \"c\"\n{{\n{ok}\n}}\n}}\n"
            ),
            "point (in world space) 2",
        ),
        (
            // Every authored point is inside the limit; the reflected end point 2 p3 - p2 is not.
            "phantom_past_the_limit",
            curves_prim(&ok.replace("(0,3,0)", "(0,9e14,0)").replace(
                "\"linear\"",
                "\"cubic\"\nuniform token basis = \"catmullRom\"\nuniform token wrap = \"pinned\"",
            )),
            "control point (the wrap's end points included) 5",
        ),
        (
            "bezier_count",
            curves_prim(&ok.replace("\"linear\"", "\"cubic\"").replace(
                "[4]",
                "[4]\nuniform token basis = \"bezier\"\nuniform token wrap = \"periodic\"",
            )),
            "curveVertexCounts[0] = 4: cubic bezier periodic curves have a multiple of 3 points",
        ),
        (
            "basis",
            curves_prim(&ok.replace("\"linear\"", "\"cubic\"\nuniform token basis = \"hermite\"")),
            "basis \"hermite\"",
        ),
        (
            "wrap",
            curves_prim(&format!("{ok}\nuniform token wrap = \"closed\"")),
            "wrap \"closed\"",
        ),
        (
            "nonuniform",
            format!(
                "{HEADER}def Xform \"x\"\n{{\nfloat3 xformOp:scale = (1, 2, 1)\nuniform token[] xformOpOrder = [\"xformOp:scale\"]\ndef BasisCurves \"c\"\n{{\n{ok}\n}}\n}}\n"
            ),
            "uniform scale only",
        ),
        (
            "cycle",
            format!("{HEADER}def \"a\" (references = @cycle.usda@</a>)\n{{\n}}\n"),
            "composition failed",
        ),
        // Malformed numeric arrays: the reader's own text fast path gives them to openusd.
        (
            "point_not_a_number",
            curves_prim(&ok.replace("(0,3,0)", "(0,3,0x)")),
            "failed to parse USDA layer: tuple has too many elements (expected 3)",
        ),
        (
            "count_not_an_int",
            curves_prim(&ok.replace("[4]", "[4.5]")),
            "failed to parse USDA layer: Failed to parse i32 from '4.5'",
        ),
        (
            "array_not_closed",
            curves_prim(&ok.replace("(0,3,0)]", "(0,3,0)")),
            "failed to parse USDA layer: Punctuation token expected",
        ),
    ];
    for (name, text, want) in cases {
        let m = refused(text, &format!("{name}.usda"));
        assert!(m.contains(want), "{name}: {m}");
        assert!(
            m.contains(&format!("{name}.usda")),
            "{name}: the message names the file: {m}"
        );
    }
}

#[test]
fn truncated_and_corrupted_crate_files_are_refused() {
    let good = std::fs::read(fixtures().join("all_bases.usdc")).unwrap();
    for cut in [16, 88, good.len() / 2, good.len() - 1] {
        let m = refused(&good[..cut], &format!("cut{cut}.usdc"));
        assert!(m.contains(&format!("cut{cut}.usdc")), "{m}");
    }
    // Counts set beyond the file inside the tables: tests/pipeline/usd_crate.rs.
    let mut bad = good.clone();
    bad[8..16].fill(0xFF);
    let m = refused(&bad, "bad_toc.usdc");
    assert!(m.contains("not a readable USD stage"), "{m}");
}

/// `[[groom]] file =` takes a USD stage: its prims render with the entry's material and
/// placement, and moving the entry moves the framed hair (the automatic camera follows).
#[test]
fn scene_files_take_usd_grooms() {
    let scene = |translate: f32| {
        format!(
            "[render]\nwidth = 24\nheight = 16\nspp = 1\n\
             [materials.h]\ntype = \"hair\"\nmelanin = [0.5, 0.1]\nuse_vertex_colors = true\n\
             [[groom]]\nfile = \"all_bases.usdc\"\nmaterial = \"h\"\ntranslate = [{translate}, 0, 0]\n\
             [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n"
        )
    };
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let mut eyes = Vec::new();
    for t in [0.0, 5.0] {
        let desc = SceneDescription::from_toml(&scene(t), &fixtures(), "usd.toml").unwrap();
        let mut built = desc.build(device.clone()).unwrap();
        let out = built.render(Aovs::default(), &NoProgress).unwrap();
        assert!(out.film.rgb().iter().all(|v| v.is_finite()));
        eyes.push(built.placed_camera(&built.settings).unwrap().eye());
    }
    assert!((eyes[1].x - eyes[0].x - 5.0).abs() < 1e-3, "{eyes:?}");
}

/// A USD groom says its own basis and its widths are diameters: the `[[groom]]` keys that
/// would say otherwise for a .hair file are refused, naming the key, not silently ignored.
#[test]
fn scene_files_refuse_hair_keys_on_usd_grooms() {
    for key in ["basis = \"linear\"", "thickness = \"radius\""] {
        let toml = format!(
            "[materials.h]\ntype = \"hair\"\nmelanin = [0.5, 0.1]\n\
             [[groom]]\nfile = \"all_bases.usda\"\nmaterial = \"h\"\n{key}\n"
        );
        let m = SceneDescription::from_toml(&toml, &fixtures(), "usd.toml")
            .unwrap_err()
            .to_string();
        let name = key.split(' ').next().unwrap();
        assert!(
            m.contains(&format!("groom[0].{name}")) && m.contains("does not apply to a USD groom"),
            "{m}"
        );
    }
    // The keys that do apply (shape, radius_scale, placement) are still taken.
    let toml = "[materials.h]\ntype = \"hair\"\nmelanin = [0.5, 0.1]\n\
                [[groom]]\nfile = \"all_bases.usda\"\nmaterial = \"h\"\nshape = \"flat\"\n\
                radius_scale = 2.0\nscale = 3.0\n";
    let desc = SceneDescription::from_toml(toml, &fixtures(), "usd.toml").unwrap();
    assert_eq!(desc.grooms[0].radius_scale, 2.0);
}

/// `primvars:melanin` (eumelanin per curve) reaches each strand as melanin, as authored:
/// no colour and no beta_n in between.
#[test]
fn melanin_primvar_gives_each_strand_its_absorption() {
    let grooms = read_usd_file(&fixtures().join("all_bases.usdc")).unwrap();
    let c = grooms.curves.iter().find(|c| c.melanin.is_some()).unwrap();
    assert_eq!(c.melanin.as_deref(), Some(&[0.3f32, 1.5][..]));
    let curves = c.curves(CurveShape::Round, 1.0, |p| p).unwrap();
    let idx = curves.strands();
    // Segment 0 is in strand 0 (4 points: 1 segment), the last in strand 1.
    let last = curves.indices().len() as u32 - 1;
    for (prim, eumelanin) in [(0, 0.3f32), (last, 1.5)] {
        assert_eq!(
            idx.absorption(&idx.locate(prim).unwrap(), 0.5),
            Some(HairColor::Melanin {
                eumelanin,
                pheomelanin: 0.0
            })
        );
    }
    let ok = "int[] curveVertexCounts = [2, 2]\npoint3f[] points = [(0,0,0),(0,1,0),(1,0,0),(1,1,0)]\nfloat[] widths = [0.1] (interpolation = \"constant\")\nuniform token type = \"linear\"";
    for (name, primvar, want) in [
        (
            "mel_negative",
            "float[] primvars:melanin = [-1]",
            "must be finite and >= 0",
        ),
        (
            "mel_count",
            "float[] primvars:melanin = [1, 2, 3] (interpolation = \"uniform\")",
            "3 values for Uniform",
        ),
        (
            "mel_and_color",
            "float[] primvars:melanin = [1]\ncolor3f[] primvars:displayColor = [(1, 0, 0)]",
            "give one",
        ),
    ] {
        let m = refused(
            curves_prim(&format!("{ok}\n{primvar}")),
            &format!("{name}.usda"),
        );
        assert!(m.contains(want), "{name}: {m}");
    }
}

/// Black hair from USD renders as black hair: a groom whose `primvars:melanin` is 8 (a
/// material with `use_vertex_colors`) gives, bit for bit, the image and albedo of the same
/// curves without the primvar under a material of `melanin = [8, 0]`. Through a colour
/// (inverted at beta_n, darker than 1e-4 in blue) it came out far lighter.
#[test]
fn black_usd_melanin_renders_as_the_material_melanin() {
    let dir = std::env::temp_dir().join(format!("hairtrace-usd-black-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let prim = |primvar: &str| {
        curves_prim(&format!(
            "int[] curveVertexCounts = [4, 4, 4]\n\
             point3f[] points = [(-0.4,-1,0),(-0.3,0,0.1),(-0.4,1,0),(-0.3,2,0), \
             (0,-1,0),(0.1,0,-0.1),(0,1,0),(0.1,2,0), (0.4,-1,0),(0.3,0,0),(0.4,1,0.1),(0.3,2,0)]\n\
             float[] widths = [0.2] (interpolation = \"constant\")\n\
             uniform token type = \"cubic\"\nuniform token basis = \"catmullRom\"\n{primvar}"
        ))
    };
    std::fs::write(
        dir.join("black.usda"),
        prim("float[] primvars:melanin = [8]"),
    )
    .unwrap();
    std::fs::write(dir.join("plain.usda"), prim("")).unwrap();
    let device = Arc::new(Device::new(Some(1)).unwrap());
    let render = |file: &str, material: &str| {
        let toml = format!(
            "[render]\nwidth = 24\nheight = 24\nspp = 2\n\
             [materials.h]\ntype = \"hair\"\n{material}\n\
             [[groom]]\nfile = \"{file}\"\nmaterial = \"h\"\n\
             [[light]]\ntype = \"environment\"\nradiance = [1, 1, 1]\n\
             [[light]]\ntype = \"distant\"\ndirection = [0, 0, -1]\nirradiance = [3, 3, 3]\n"
        );
        let desc = SceneDescription::from_toml(&toml, &dir, "black.toml").unwrap();
        let aovs = Aovs {
            albedo: true,
            ..Aovs::default()
        };
        let out = desc
            .build(device.clone())
            .unwrap()
            .render(aovs, &NoProgress)
            .unwrap();
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        (bits(out.film.rgb()), bits(out.film.albedo().unwrap()))
    };
    let material = render("plain.usda", "melanin = [8, 0]\nbeta_n = 0.4");
    let groom = render(
        "black.usda",
        "color = [0.9, 0.8, 0.7]\nbeta_n = 0.4\nuse_vertex_colors = true",
    );
    assert!(
        material == groom,
        "the groom's melanin 8 is not the material's"
    );
    // The groom's melanin is what decides: the material's own colour is another image.
    let own = render("black.usda", "color = [0.9, 0.8, 0.7]\nbeta_n = 0.4");
    assert!(own != groom, "the groom's melanin changed nothing");
}
