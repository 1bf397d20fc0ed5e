//! `hairtrace convert`: grooms between .hair and USD. Round trips are exact to the bit, a
//! written stage reads back as the very curves hairtrace draws through the .hair points,
//! cubic USD curves are sampled (linear) or refused, and the converter's output stays the
//! file that usd-core validated (tests/fixtures/usd/check_converted.py).

use std::path::{Path, PathBuf};

use crate::description::{GroomDesc, GroomSource};
use crate::embree::{CurveBasis, CurveShape};
use crate::formats::convert::{ConvertOptions, ConvertSource, basis_named, convert};
use crate::formats::hair::{
    HEADER_BYTES, Thickness, read_hair_file, read_hair_tag, write_hair_file,
};
use crate::formats::units::{StageUnits, UpAxis};
use crate::formats::usd::{Layout, UsdCurves, Wrap, read_usd_file};
use crate::scene::Strands;
use crate::scene::curves::Curves;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/usd")
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hairtrace-convert-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// Options with `basis`, or none for "".
fn opts(basis: &str) -> ConvertOptions {
    ConvertOptions {
        basis: (!basis.is_empty()).then(|| basis_named(basis).unwrap()),
        ..ConvertOptions::default()
    }
}

fn run(from: &Path, to: &Path, basis: &str) -> crate::Result<Vec<String>> {
    convert(ConvertSource::File(from), to, &opts(basis)).map(|c| c.notes)
}

/// A small groom with values that have no short decimal form (thirds, tenths, tiny and
/// large magnitudes), strands of different lengths, varying radii and colours.
fn groom(colours: bool) -> Strands {
    let counts = vec![2u32, 5, 3, 4];
    let n: usize = counts.iter().map(|&c| c as usize).sum();
    let points = (0..n)
        .map(|i| {
            let i = i as f32;
            [0.1 * i - 1.0 / 3.0, 1e-7 + i * 0.7, 12345.678 - i / 7.0]
        })
        .collect();
    let radii = (0..n)
        .map(|i| 0.004 + 1e-4 * (i % 3) as f32 / 3.0)
        .collect();
    let colors = colours.then(|| {
        (0..n)
            .map(|i| [0.1 * (i % 10) as f32, 1.0 / 3.0, 0.9 - 0.05 * i as f32])
            .collect()
    });
    Strands {
        points,
        radii,
        counts,
        colors,
    }
}

/// A strand of extreme values: subnormal, negative zero, the coordinate limit, radii from
/// 1e-30 to 1e10.
fn extremes() -> Strands {
    Strands {
        points: vec![
            [0.0, 0.0, 0.0],
            [1e-40, -0.0, 1.1754944e-38],
            [1e15, -1e15, 123456789.0],
            [0.1, 0.2, 0.3],
            [-3.4028e-3, 7.0e-12, 16777217.0],
        ],
        radii: vec![1e-30, 2.5e-8, 1e10, 0.3333333, 0.004],
        counts: vec![5],
        colors: Some(vec![
            [0.0, 1.0, 1e-40],
            [0.5; 3],
            [1.0; 3],
            [0.1, 0.2, 0.3],
            [1e-7; 3],
        ]),
    }
}

/// .hair -> .usda -> .hair gives the same strands to the bit for every basis (counts,
/// points, radii and colours), and a .hair file that convert wrote, which says its curve
/// and units, comes back byte for byte with no basis given.
#[test]
fn hair_to_usd_to_hair_is_exact() {
    for (name, strands) in [
        ("plain", groom(false)),
        ("coloured", groom(true)),
        ("extremes", extremes()),
    ] {
        let hair = tmp(&format!("g{name}.hair"));
        write_hair_file(&hair, &strands, Thickness::Diameter).unwrap();
        for basis in ["linear", "bspline", "catmull_rom", "bezier"] {
            let usd = tmp(&format!("g{name}_{basis}.usda"));
            let back = tmp(&format!("g{name}_{basis}.hair"));
            assert!(run(&hair, &usd, basis).unwrap().is_empty());
            assert!(run(&usd, &back, "").unwrap().is_empty());
            let got = read_hair_file(&back, Thickness::Diameter).unwrap();
            // Equal as numbers: a negative zero comes back as 0 (openusd prints integral
            // floats as integers, and the reader's transform adds +0).
            assert_eq!(got, strands, "{basis} {name}");
            if name == "extremes" {
                assert_eq!(got.points[1][1].to_bits(), 0);
            } else {
                let bytes = |p: &Path| std::fs::read(p).unwrap()[HEADER_BYTES..].to_vec();
                assert_eq!(bytes(&back), bytes(&hair), "{basis} {name}");
            }
            let tag = read_hair_tag(&back).unwrap().unwrap();
            let drawn = Layout::of_polylines(basis_named(basis).unwrap());
            assert_eq!((tag.layout, tag.units), (drawn, StageUnits::WORLD));
            // The tagged file goes round again to the same bytes, with no basis given.
            let (usd2, back2) = (
                tmp(&format!("g{name}_{basis}_2.usda")),
                tmp(&format!("g{name}_{basis}_2.hair")),
            );
            run(&back, &usd2, "").unwrap();
            run(&usd2, &back2, "").unwrap();
            assert_eq!(
                std::fs::read(&back2).unwrap(),
                std::fs::read(&back).unwrap()
            );
        }
    }
    // An untagged .hair file has no curve of its own to convert.
    let hair = tmp("gplain.hair");
    let m = run(&hair, &tmp("nobasis.usda"), "")
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("does not say which curve") && m.contains("gplain.hair"),
        "{m}"
    );
}

/// Every cubic basis and wrap USD has, in a Z-up stage in centimetres, goes to .hair and back
/// to the same stage: the same layout, points, widths and colours to the bit, and the same
/// up axis and unit.
#[test]
fn usd_of_every_cubic_basis_and_wrap_round_trips_through_hair() {
    for (basis, counts, wrap) in [
        ("bspline", "[4, 6]", "nonperiodic"),
        ("bspline", "[3, 5]", "pinned"),
        ("bspline", "[3, 7]", "periodic"),
        ("catmullRom", "[4, 6]", "nonperiodic"),
        ("catmullRom", "[3, 7]", "pinned"),
        ("catmullRom", "[3, 7]", "periodic"),
        ("bezier", "[4, 7]", "nonperiodic"),
        ("bezier", "[4, 7]", "pinned"),
        ("bezier", "[3, 6]", "periodic"),
    ] {
        let n: usize = counts
            .trim_matches(['[', ']'])
            .split(", ")
            .map(|c| c.parse::<usize>().unwrap())
            .sum();
        let points: Vec<String> = (0..n)
            .map(|i| {
                format!(
                    "({}, {}, {})",
                    0.1 * i as f32 + 1.0 / 3.0,
                    (i * i) as f32 / 7.0,
                    1.5 - i as f32
                )
            })
            .collect();
        let widths: Vec<String> = (0..n)
            .map(|i| format!("{}", 0.02 - 0.001 * i as f32))
            .collect();
        let colors: Vec<String> = (0..n)
            .map(|i| format!("({}, 0.5, 0.25)", i as f32 / n as f32))
            .collect();
        let src = tmp(&format!("rt_{basis}_{wrap}.usda"));
        std::fs::write(
            &src,
            format!(
                "#usda 1.0\n(\n    metersPerUnit = 0.01\n    upAxis = \"Z\"\n)\n\
                 def BasisCurves \"c\"\n{{\n\
                 uniform token type = \"cubic\"\nuniform token basis = \"{basis}\"\n\
                 uniform token wrap = \"{wrap}\"\nint[] curveVertexCounts = {counts}\n\
                 point3f[] points = [{}]\nfloat[] widths = [{}] (interpolation = \"vertex\")\n\
                 color3f[] primvars:displayColor = [{}] (interpolation = \"vertex\")\n}}\n",
                points.join(", "),
                widths.join(", "),
                colors.join(", ")
            ),
        )
        .unwrap();
        let (hair, usda) = (
            tmp(&format!("rt_{basis}_{wrap}.hair")),
            tmp(&format!("rt_{basis}_{wrap}_back.usda")),
        );
        assert!(run(&src, &hair, "").unwrap().is_empty());
        assert!(run(&hair, &usda, "").unwrap().is_empty());
        let (a, b) = (read_usd_file(&src).unwrap(), read_usd_file(&usda).unwrap());
        assert_eq!(a.units, b.units, "{basis} {wrap}");
        assert_eq!(a.units.up_axis, UpAxis::Z);
        assert_eq!(a.curves[0].layout, b.curves[0].layout, "{basis} {wrap}");
        let bits = |c: &UsdCurves| {
            (
                c.control
                    .iter()
                    .flatten()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>(),
                c.authored_counts.clone(),
                c.point_colors.clone(),
            )
        };
        assert_eq!(bits(&a.curves[0]), bits(&b.curves[0]), "{basis} {wrap}");
        // And the .hair file renders as the stage does: the same control points in the world.
        let desc = |path: &Path| {
            GroomDesc::new(
                GroomSource::File {
                    path: path.to_path_buf(),
                    thickness: Thickness::Diameter,
                    frame: None,
                },
                "",
            )
        };
        let from_hair = desc(&hair).placed_strands().unwrap();
        let from_usd = desc(&src).placed_strands().unwrap();
        assert_eq!(from_hair[0].strands, from_usd[0].strands, "{basis} {wrap}");
        let layouts = [from_hair[0].curves.layout(), from_usd[0].curves.layout()];
        assert_eq!(layouts[0], layouts[1], "{basis} {wrap}");
    }
}

/// The written stage, read by hairtrace's USD reader, is the curve hairtrace draws through
/// the .hair points with that basis: the same Embree control points (phantom ends included),
/// counts, bounds and radii.
#[test]
fn written_usda_reads_back_as_the_curves_of_the_hair_file() {
    let strands = groom(true);
    let hair = tmp("drawn.hair");
    write_hair_file(&hair, &strands, Thickness::Diameter).unwrap();
    for (basis, drawn) in [
        ("linear", CurveBasis::Linear),
        ("bspline", CurveBasis::BSpline),
        ("catmull_rom", CurveBasis::CatmullRom),
    ] {
        let usda = tmp(&format!("drawn_{basis}.usda"));
        run(&hair, &usda, basis).unwrap();
        let stage = read_usd_file(&usda).unwrap();
        assert_eq!(stage.units, StageUnits::WORLD);
        let [c] = stage.curves.as_slice() else {
            panic!("one prim expected")
        };
        assert_eq!(c.layout.basis, drawn);
        assert_eq!(c.authored_counts, strands.counts);
        assert_eq!(Some(c.bounds), strands.bounds());
        let (lo, hi) = (strands.radii.iter().copied())
            .fold((f32::INFINITY, 0.0f32), |(lo, hi), r| {
                (lo.min(r), hi.max(r))
            });
        assert_eq!(c.radius_range, (lo, hi));
        let want = Curves::from_strands(&strands, drawn, CurveShape::Round).unwrap();
        assert_eq!(c.control, want.vertices(), "{basis}");
        // Colours are per point (vertex interpolation).
        assert_eq!(c.point_colors, strands.colors, "{basis}");
    }
}

/// Prims written by usd-core in the three forms a .hair file can hold go to .hair and back
/// to USD, and read the same: control points, counts, bounds, radii, colours.
#[test]
fn usd_to_hair_to_usd_keeps_the_curves() {
    let same = |a: &UsdCurves, b: &UsdCurves, what: &str| {
        assert_eq!(a.layout, b.layout, "{what}");
        assert_eq!(a.control, b.control, "{what}");
        assert_eq!(a.control_counts, b.control_counts, "{what}");
        assert_eq!(a.authored_counts, b.authored_counts, "{what}");
        assert_eq!(a.bounds, b.bounds, "{what}");
        assert_eq!(a.radius_range, b.radius_range, "{what}");
        assert_eq!(a.colors, b.colors, "{what}");
        assert_eq!(a.point_colors, b.point_colors, "{what}");
    };
    // case0: linear; case5: pinned B-spline; case8: pinned Catmull-Rom (usd-core's files).
    for (case, basis) in [
        ("case0", "linear"),
        ("case5", "bspline"),
        ("case8", "catmull_rom"),
    ] {
        let src = fixtures().join(format!("{case}.usda"));
        let (hair, usda) = (tmp(&format!("{case}.hair")), tmp(&format!("{case}.usda")));
        run(&src, &hair, basis).unwrap();
        run(&hair, &usda, basis).unwrap();
        let (a, b) = (read_usd_file(&src).unwrap(), read_usd_file(&usda).unwrap());
        same(&a.curves[0], &b.curves[0], case);
    }
    // A Z-up stage keeps its points as authored, and the .hair file says Z-up.
    let z_up = tmp("z_up.usda");
    let text = std::fs::read_to_string(fixtures().join("case0.usda")).unwrap();
    std::fs::write(&z_up, text.replace("upAxis = \"Y\"", "upAxis = \"Z\"")).unwrap();
    assert!(run(&z_up, &tmp("z_up.hair"), "linear").unwrap().is_empty());
    let tag = read_hair_tag(&tmp("z_up.hair")).unwrap().unwrap();
    assert_eq!(tag.units, StageUnits::new(UpAxis::Z, 0.01).unwrap());
    // The linear prim of a nested, scaled and turned stage, in world space; the stage's
    // other prims have no colours, so none are written, and a note says so.
    let hair = tmp("all_bases_linear.hair");
    let all = read_usd_file(&fixtures().join("all_bases.usda")).unwrap();
    let linear = &all.curves[0];
    assert_eq!(linear.layout.basis, CurveBasis::Linear);
    let notes = run(&fixtures().join("all_bases.usda"), &hair, "linear").unwrap();
    assert!(
        notes.iter().any(|n| n.contains("colours not written")),
        "{notes:?}"
    );
    let back = read_hair_file(&hair, Thickness::Diameter).unwrap();
    let world: Vec<[f32; 3]> = linear.control.iter().map(|p| [p[0], p[1], p[2]]).collect();
    assert_eq!(back.points[..world.len()], world[..]);
    assert!(back.colors.is_none());
    // Colours of a pinned B-spline, authored per vertex: the .hair file gets them per point,
    // and they come back to USD unchanged.
    let src = tmp("coloured.usda");
    std::fs::write(
        &src,
        "#usda 1.0\ndef BasisCurves \"c\"\n{\n\
         uniform token type = \"cubic\"\nuniform token basis = \"bspline\"\n\
         uniform token wrap = \"pinned\"\nint[] curveVertexCounts = [3, 4]\n\
         point3f[] points = [(0,0,0),(0,1,0),(0.5,2,0),(1,0,0),(1,1,0.5),(1,2,0),(1.5,3,0)]\n\
         float[] widths = [0.01] (interpolation = \"constant\")\n\
         color3f[] primvars:displayColor = [(1,0,0),(0,1,0),(0,0,1),(0.2,0.4,0.6),(1,1,1),\
         (0,0,0),(0.5,0.5,0.5)] (interpolation = \"vertex\")\n}\n",
    )
    .unwrap();
    let (hair, usda) = (tmp("coloured.hair"), tmp("coloured_back.usda"));
    run(&src, &hair, "bspline").unwrap();
    run(&hair, &usda, "bspline").unwrap();
    let a = &read_usd_file(&src).unwrap().curves[0];
    assert_eq!(
        read_hair_file(&hair, Thickness::Diameter).unwrap().colors,
        a.point_colors
    );
    same(a, &read_usd_file(&usda).unwrap().curves[0], "coloured");
}

/// Cubic curves go to .hair as they are; a basis other than their own is refused, with the
/// ways out named; with the linear basis they are sampled onto the curve.
#[test]
fn cubic_curves_are_sampled_for_linear_or_refused() {
    // case4: nonperiodic B-spline, curves of 4 and 6 points (1 and 3 segments).
    let src = fixtures().join("case4.usda");
    let hair = tmp("case4.hair");
    for basis in ["catmull_rom", "bezier"] {
        let m = run(&src, &hair, basis).unwrap_err().to_string();
        assert!(m.contains("--basis linear") && m.contains("/hair"), "{m}");
        assert!(m.contains("leave --basis out"), "{m}");
    }
    for basis in ["bspline", ""] {
        assert!(run(&src, &hair, basis).unwrap().is_empty());
        let tag = read_hair_tag(&hair).unwrap().unwrap();
        assert_eq!(
            (tag.layout.basis, tag.layout.wrap),
            (CurveBasis::BSpline, Wrap::Nonperiodic)
        );
    }
    let notes = run(&src, &hair, "linear").unwrap();
    assert!(notes.iter().any(|n| n.contains("sampled")), "{notes:?}");
    let s = read_hair_file(&hair, Thickness::Diameter).unwrap();
    let k = ConvertOptions::default().samples_per_segment;
    assert_eq!(s.counts, [k + 1, 3 * k + 1]);
    // The samples lie on the B-spline: its value at a segment's start and middle.
    let c = &read_usd_file(&src).unwrap().curves[0].control;
    for (seg, at, weights) in [
        (0, 0, [1.0, 4.0, 1.0, 0.0].map(|w| w / 6.0)),
        (0, k as usize / 2, [1.0, 23.0, 23.0, 1.0].map(|w| w / 48.0)),
        (0, k as usize, [0.0, 1.0, 4.0, 1.0].map(|w| w / 6.0)),
    ] {
        let want: [f32; 4] =
            std::array::from_fn(|j| (0..4).map(|i| weights[i] * c[seg + i][j]).sum::<f32>());
        let got = s.points[at];
        for j in 0..3 {
            assert!((got[j] - want[j]).abs() < 1e-5, "{at}: {got:?} {want:?}");
        }
        assert!((s.radii[at] - want[3]).abs() < 1e-7);
    }
    // The density is the caller's: 3 segments per curve segment; 0 is refused.
    let three = ConvertOptions {
        samples_per_segment: 3,
        ..opts("linear")
    };
    convert(ConvertSource::File(&src), &hair, &three).unwrap();
    let s = read_hair_file(&hair, Thickness::Diameter).unwrap();
    assert_eq!(s.counts, [4, 10]);
    let none = ConvertOptions {
        samples_per_segment: 0,
        ..opts("linear")
    };
    let m = convert(ConvertSource::File(&src), &hair, &none).unwrap_err();
    assert!(m.to_string().contains("at least 1"), "{m}");
    // A whole stage of every basis and wrap goes to linear .hair; melanin has nowhere to go.
    let notes = run(&fixtures().join("all_bases.usdc"), &hair, "linear").unwrap();
    assert!(notes.iter().any(|n| n.contains("melanin")), "{notes:?}");
    assert_eq!(
        read_hair_file(&hair, Thickness::Diameter)
            .unwrap()
            .strand_count(),
        20
    );
}

/// A scene file's grooms go out one prim each, in world space and with their own basis; a
/// .hair file takes them only when they share one layout.
#[test]
fn scene_grooms_convert_with_their_bases() {
    let scene = tmp("two.toml");
    std::fs::write(
        &scene,
        "[materials.h]\ntype = \"hair\"\nmelanin = [1, 0]\n\
         [[groom]]\nprocedural = \"fur_ball\"\nmaterial = \"h\"\ntranslate = [5, 0, 0]\n\
         [groom.params]\nstrands = 20\nsegments = 4\n\
         [[groom]]\nprocedural = \"scalp\"\nmaterial = \"h\"\nbasis = \"linear\"\n\
         [groom.params]\nstrands = 10\nsegments = 3\n",
    )
    .unwrap();
    let usda = tmp("two.usda");
    let done = run(&scene, &usda, "bspline").unwrap();
    assert!(done.is_empty());
    let stage = read_usd_file(&usda).unwrap();
    let bases: Vec<_> = stage.curves.iter().map(|c| c.layout.basis).collect();
    assert_eq!(bases, [CurveBasis::BSpline, CurveBasis::Linear]);
    assert_eq!(stage.curves[0].authored_counts, [5; 20]);
    assert!(
        stage.curves[0].bounds.0[0] > 3.0,
        "{:?}",
        stage.curves[0].bounds
    );
    let m = run(&scene, &tmp("two.hair"), "bspline")
        .unwrap_err()
        .to_string();
    assert!(m.contains("groom1") && m.contains("--basis linear"), "{m}");
    assert!(
        m.contains("linear bezier nonperiodic") && m.contains("cubic bspline pinned"),
        "{m}"
    );
}

/// Bad paths and unknown extensions are refused before anything is written.
#[test]
fn bad_paths_and_extensions_are_named() {
    let hair = tmp("bad.hair");
    write_hair_file(&hair, &groom(false), Thickness::Diameter).unwrap();
    for (from, to, want) in [
        (hair.clone(), tmp("out.obj"), "unknown output extension"),
        (tmp("missing.hair"), tmp("out.usda"), "missing.hair"),
        (hair.clone(), tmp("no/such/dir/out.usda"), "does not exist"),
        (tmp("two.txt"), tmp("out.usda"), "unknown input extension"),
        (hair.clone(), tmp("again.hair"), "both .hair"),
        (fixtures().join("case0.usda"), tmp("x.usda"), "both USD"),
        // openusd's crate files are refused by Pixar's library: text only.
        (hair.clone(), tmp("x.usdc"), "write .usda"),
        (hair.clone(), tmp("x.usdz"), "write .usda"),
    ] {
        if want == "unknown input extension" {
            std::fs::write(&from, "x").unwrap();
        }
        let m = run(&from, &to, "bspline").unwrap_err().to_string();
        assert!(m.contains(want), "{m}");
        assert!(!to.exists(), "{}", to.display());
    }
}

/// The converter's .usda for a fixed groom is the file that usd-core checked
/// (check_converted.py: a valid stage, schema and values equal to the .hair), byte for byte:
/// a change to the writer shows here, and then the file must be checked again. The crate
/// file usd-core made of it converts back to the same .hair bytes.
/// `HT_BLESS_CONVERTED=1` rewrites both fixtures.
#[test]
fn converted_usda_is_the_file_usd_core_validated() {
    let (hair, want) = (
        fixtures().join("converted.hair"),
        fixtures().join("converted.usda"),
    );
    if std::env::var_os("HT_BLESS_CONVERTED").is_some() {
        write_hair_file(&hair, &groom(true), Thickness::Diameter).unwrap();
        run(&hair, &want, "bspline").unwrap();
    }
    assert_eq!(
        read_hair_file(&hair, Thickness::Diameter).unwrap(),
        groom(true)
    );
    let out = tmp("converted.usda");
    run(&hair, &out, "bspline").unwrap();
    assert!(
        std::fs::read(&out).unwrap() == std::fs::read(&want).unwrap(),
        "the converter's output changed: check it with check_converted.py, then bless it"
    );
    // usd-core's crate file of that stage comes back as the same strands, saying their curve
    // and units.
    let back = tmp("converted_back.hair");
    run(&fixtures().join("converted_by_usd_core.usdc"), &back, "").unwrap();
    let bytes = |p: &Path| std::fs::read(p).unwrap()[HEADER_BYTES..].to_vec();
    assert_eq!(bytes(&back), bytes(&hair));
    let tag = read_hair_tag(&back).unwrap().unwrap();
    assert_eq!(tag.layout, Layout::of_polylines(CurveBasis::BSpline));
    assert_eq!(tag.units, StageUnits::WORLD);
}
