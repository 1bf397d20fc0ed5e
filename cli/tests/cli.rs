//! The command line as a user meets it: the main job prints its table, `info` describes
//! a groom or a pbrt scene, and every error is one line on stderr with a non-zero exit.

use hairtrace::formats::hair::{Thickness, read_hair_file, write_hair_file};
use hairtrace::formats::usd::read_usd_file;
use hairtrace::scene::FurBall;
use std::process::{Command, Output};

fn hairtrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args(args)
        .output()
        .expect("run hairtrace")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn assert_one_line_error(o: &Output, needle: &str) {
    assert!(!o.status.success(), "expected a failure");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "error must be one line: {err:?}"
    );
    assert!(err.contains(needle), "{err:?} should mention {needle:?}");
}

#[test]
fn lobes_prints_energies_that_add_up() {
    let o = hairtrace(&["lobes", "--color", "1,1,1"]);
    assert!(o.status.success(), "{o:?}");
    let out = stdout(&o);
    // White fibres lose nothing: every row's total is 1 in each channel.
    let rows: Vec<_> = out.lines().filter(|l| l.contains('°')).collect();
    assert_eq!(rows.len(), 7, "{out}");
    for row in rows {
        let totals: Vec<f32> = row
            .split_whitespace()
            .rev()
            .take(3)
            .map(|v| v.parse().unwrap())
            .collect();
        assert!(totals.iter().all(|t| (t - 1.0).abs() < 2e-3), "{row}");
    }
}

#[test]
fn lobes_refuses_bad_parameters() {
    assert_one_line_error(&hairtrace(&["lobes", "--beta-m", "5"]), "beta_m");
    assert_one_line_error(&hairtrace(&["lobes", "--eumelanin", "nan"]), "eumelanin");
}

#[test]
fn info_describes_a_groom() {
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_info.hair");
    let groom = FurBall {
        strands: 100,
        segments: 8,
        ..FurBall::default()
    }
    .build()
    .unwrap();
    write_hair_file(&path, &groom, Thickness::Diameter).unwrap();
    let o = hairtrace(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{o:?}");
    let out = stdout(&o);
    for want in [
        "strands:  100",
        "points:   900",
        "segments: 800",
        "bounds:",
        "radius:",
    ] {
        assert!(out.contains(want), "{want:?} missing from:\n{out}");
    }
}

#[test]
fn info_errors_are_one_line() {
    assert_one_line_error(
        &hairtrace(&["info", "/nonexistent/groom.hair"]),
        "/nonexistent/groom.hair",
    );
    let bad = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bad.hair");
    std::fs::write(&bad, b"HAIR but far too short").unwrap();
    let o = hairtrace(&["info", bad.to_str().unwrap()]);
    assert!(!o.status.success());
}

fn tmp(name: &str) -> String {
    std::path::Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// The default demo renders to EXR and PNG, and the summary line reports the run.
#[test]
fn render_default_demo_to_exr_and_png() {
    for ext in ["exr", "png"] {
        let out = tmp(&format!("cli_demo.{ext}"));
        let o = hairtrace(&[
            "render", "--width", "48", "--height", "36", "--spp", "2", "-o", &out,
        ]);
        assert!(o.status.success(), "{o:?}");
        let img = hairtrace::image::read_image(std::path::Path::new(&out)).unwrap();
        assert_eq!((img.width, img.height), (48, 36));
        assert!(img.pixels.iter().all(|v| v.is_finite()));
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("Mrays/s") && err.contains("peak memory"),
            "{err}"
        );
    }
}

/// A bare groom renders with the automatic camera and default look.
#[test]
fn render_a_bare_hair_file() {
    let path = tmp("cli_quick.hair");
    let groom = FurBall {
        strands: 200,
        segments: 6,
        ..FurBall::default()
    }
    .build()
    .unwrap();
    write_hair_file(std::path::Path::new(&path), &groom, Thickness::Diameter).unwrap();
    let out = tmp("cli_quick.exr");
    // The file does not say which curve its points draw: no basis is assumed for it.
    assert_one_line_error(
        &hairtrace(&["render", &path, "--width", "32", "-o", &out]),
        "does not say which curve its points draw",
    );
    assert!(stdout(&hairtrace(&["info", &path])).contains("curves:   not said"));
    let o = hairtrace(&[
        "render", &path, "--basis", "bspline", "--width", "32", "--height", "32", "--spp", "2",
        "-o", &out,
    ]);
    assert!(o.status.success(), "{o:?}");
    let img = hairtrace::image::read_image(std::path::Path::new(&out)).unwrap();
    assert!(img.pixels.iter().any(|v| *v > 0.0));

    // A named absorption preset: white hair has a higher albedo than black.
    let mean = |preset: &str| {
        let out = tmp(&format!("cli_quick_{preset}.exr"));
        let o = hairtrace(&[
            "render", &path, "--basis", "bspline", "--width", "32", "--height", "32", "--spp", "2",
            "--preset", preset, "--aov", "albedo", "-o", &out,
        ]);
        assert!(o.status.success(), "{o:?}");
        let albedo = out.replace(".exr", ".albedo.exr");
        let img = hairtrace::image::read_image(std::path::Path::new(&albedo)).unwrap();
        img.pixels.iter().sum::<f32>() / img.pixels.len() as f32
    };
    let (white, black) = (mean("white"), mean("black"));
    assert!(
        white > 3.0 * black && black > 0.0,
        "white {white}, black {black}"
    );
    // Only a bare groom takes it: a scene file names its own.
    assert_one_line_error(
        &hairtrace(&["render", "--demo", "scalp", "--preset", "black", "-o", &out]),
        "[materials.NAME]",
    );
    assert_one_line_error(
        &hairtrace(&["render", &path, "--preset", "auburn", "-o", &out]),
        "known: red_brown, light_brown, dark_brown, black, white",
    );
}

#[test]
fn lobes_takes_a_preset() {
    let o = hairtrace(&["lobes", "--preset", "dark_brown"]);
    assert!(o.status.success(), "{o:?}");
    assert!(
        stdout(&o).starts_with("sigma_a = (0.9000, 1.2800, 2.6600)"),
        "{}",
        stdout(&o)
    );
    assert_one_line_error(
        &hairtrace(&["lobes", "--preset", "black", "--color", "1,1,1"]),
        "--color",
    );
}

fn pbrt_fixture() -> String {
    concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/fixtures/pbrt/hair.pbrt"
    )
    .to_string()
}

/// A pbrt-v4 scene renders at the Film's size unless told otherwise, its warnings on
/// stderr with their lines; `info` describes its grooms.
#[test]
fn render_and_describe_a_pbrt_scene() {
    let out = tmp("cli_pbrt.exr");
    let o = hairtrace(&["render", &pbrt_fixture(), "--spp", "1", "-o", &out]);
    assert!(o.status.success(), "{o:?}");
    let img = hairtrace::image::read_image(std::path::Path::new(&out)).unwrap();
    assert_eq!((img.width, img.height), (64, 48), "the Film's resolution");
    assert!(img.pixels.iter().all(|v| v.is_finite()));
    assert!(img.pixels.iter().any(|v| *v > 0.0));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("warning: ") && err.contains("hair.pbrt:10: PixelFilter"),
        "{err}"
    );
    assert!(err.contains("Film filename hair.exr is not used"), "{err}");

    let o = hairtrace(&["info", &pbrt_fixture()]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    assert!(
        text.contains("groom[0]: material \"brown\", Round Bezier curves: 3 strands, 21 control points, 6 segments"),
        "{text}"
    );
    assert!(text.contains("strands.pbrt:6: Shape \"curve\""), "{text}");

    let bad = tmp("cli_bad.pbrt");
    std::fs::write(&bad, "WorldBegin\nShape \"disk\"\n").unwrap();
    assert_one_line_error(
        &hairtrace(&["info", &bad]),
        "cli_bad.pbrt:2: Shape \"disk\"",
    );
}

#[test]
fn render_errors_are_one_line() {
    let out = tmp("cli_never.exr");
    assert_one_line_error(
        &hairtrace(&["render", "/nonexistent/groom.hair", "-o", &out]),
        "/nonexistent/groom.hair",
    );
    assert_one_line_error(
        &hairtrace(&["render", "--demo", "teapot", "-o", &out]),
        "teapot",
    );
    assert_one_line_error(
        &hairtrace(&["render", "--spp", "1", "-o", "/nonexistent/dir/out.exr"]),
        "/nonexistent/dir",
    );
    assert_one_line_error(
        &hairtrace(&["render", "--spp", "1", "-o", &tmp("cli_out.bmpx")]),
        "bmpx",
    );
    let bad = tmp("cli_bad.toml");
    std::fs::write(&bad, "[render]\nwidht = 10\n").unwrap();
    assert_one_line_error(&hairtrace(&["render", &bad, "-o", &out]), "widht");
    assert_one_line_error(&hairtrace(&["render", "--spp", "0", "-o", &out]), "spp");
}

/// `--aov` writes the albedo, depth and strand-id images beside the beauty image.
#[test]
fn render_writes_aovs() {
    let out = tmp("cli_aov.exr");
    let o = hairtrace(&[
        "render",
        "--width",
        "32",
        "--height",
        "24",
        "--spp",
        "1",
        "--aov",
        "albedo,depth,strand",
        "-o",
        &out,
    ]);
    assert!(o.status.success(), "{o:?}");
    let read = |name: &str| hairtrace::image::read_image(std::path::Path::new(&tmp(name))).unwrap();
    let (albedo, depth, strand) = (
        read("cli_aov.albedo.exr"),
        read("cli_aov.depth.exr"),
        read("cli_aov.strand.exr"),
    );
    assert_eq!(
        (albedo.channels, depth.channels, strand.channels),
        (3, 1, 1)
    );
    // The fur ball fills the middle of the frame: a strand id and a positive depth there.
    let centre = 12 * 32 + 16;
    assert!(strand.pixels[centre] >= 0.0 && depth.pixels[centre] > 0.0);
    assert_one_line_error(
        &hairtrace(&["render", "--aov", "normals", "-o", &out]),
        "normals",
    );
}

/// `--crop` renders exactly the full frame's pixels of the window (EXR keeps the bits).
#[test]
fn render_crop_matches_the_full_frame() {
    let (full, part) = (tmp("cli_full.exr"), tmp("cli_crop.exr"));
    let common = [
        "render", "--width", "32", "--height", "24", "--spp", "2", "--seed", "5",
    ];
    for (out, crop) in [(&full, None), (&part, Some("8,4,24,20"))] {
        let mut args: Vec<&str> = common.to_vec();
        if let Some(c) = crop {
            args.extend(["--crop", c]);
        }
        args.extend(["-o", out.as_str()]);
        let o = hairtrace(&args);
        assert!(o.status.success(), "{o:?}");
    }
    let read = |p: &str| hairtrace::image::read_image(std::path::Path::new(p)).unwrap();
    let (f, c) = (read(&full), read(&part));
    assert_eq!((c.width, c.height), (16, 16));
    for y in 0..16 {
        for x in 0..16 {
            let (i, j) = (3 * ((y + 4) * 32 + x + 8), 3 * (y * 16 + x));
            assert_eq!(f.pixels[i..i + 3], c.pixels[j..j + 3], "pixel ({x}, {y})");
        }
    }
    assert_one_line_error(
        &hairtrace(&[
            "render",
            "--width",
            "32",
            "--crop",
            "8,4,40,20",
            "-o",
            &part,
        ]),
        "crop",
    );
}

/// `--variant` renders more images from the one build, each the image its own command
/// would give; a variant of what the build depends on builds again, as its command would.
#[test]
fn variants_render_from_one_build_as_their_own_commands_would() {
    let (main, variant, alone) = (
        tmp("cli_variant_main.exr"),
        tmp("cli_variant_spp.exr"),
        tmp("cli_variant_alone.exr"),
    );
    let common = ["render", "--width", "24", "--height", "16", "--spp", "2"];
    let spec = format!("{variant}:spp=4 seed=3");
    let mut args = common.to_vec();
    args.extend(["-o", &main, "--variant", &spec]);
    let o = hairtrace(&args);
    assert!(o.status.success(), "{o:?}");
    // One summary line per image, from one build.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("at 2 spp") && err.contains("at 4 spp"),
        "{err}"
    );
    let mut args = common.to_vec();
    args.extend(["--set", "spp=4", "--set", "seed=3", "-o", &alone]);
    let o = hairtrace(&args);
    assert!(o.status.success(), "{o:?}");
    let read = |p: &str| hairtrace::image::read_image(std::path::Path::new(p)).unwrap();
    assert_eq!(read(&variant).pixels, read(&alone).pixels);
    assert_ne!(read(&variant).pixels, read(&main).pixels);

    let (wider, wider_alone) = (
        tmp("cli_variant_wider.exr"),
        tmp("cli_variant_wider_alone.exr"),
    );
    let spec = format!("{wider}:width=48");
    let mut args = common.to_vec();
    args.extend(["-o", &main, "--variant", &spec]);
    let o = hairtrace(&args);
    assert!(o.status.success(), "{o:?}");
    let mut args = common.to_vec();
    args.extend(["--set", "width=48", "-o", &wider_alone]);
    assert!(hairtrace(&args).status.success());
    assert_eq!(read(&wider).pixels, read(&wider_alone).pixels);
    let mut args = common.to_vec();
    args.extend(["-o", &main, "--variant", "no-colon.exr"]);
    assert_one_line_error(&hairtrace(&args), "OUT:NAME=VALUE");
    // A tile of a variant is an .exr, as the main image's is.
    let png = format!("{}:spp=4", tmp("cli_variant_tile.png"));
    let mut args = common.to_vec();
    args.extend(["--tile", "1/2", "-o", &main, "--variant", &png]);
    assert_one_line_error(&hairtrace(&args), "must be an .exr");
}

/// `bias` finds a change of the image that seeds cannot explain, and nothing where only
/// the seeds differ; a side of one seed has no noise to measure and is refused.
#[test]
fn bias_tells_a_change_from_noise() {
    let render = |seed: &str, depth: &str| {
        let out = tmp(&format!("cli_bias_{seed}_{depth}.exr"));
        let o = hairtrace(&[
            "render",
            "--width",
            "64",
            "--height",
            "48",
            "--spp",
            "16",
            "--seed",
            seed,
            "--max-depth",
            depth,
            "-o",
            &out,
        ]);
        assert!(o.status.success(), "{o:?}");
        out
    };
    let (a1, a2) = (render("1", "64"), render("2", "64"));
    let (b1, b2) = (render("3", "64"), render("4", "64"));
    let (c1, c2) = (render("5", "1"), render("6", "1"));
    // Blocks of 16 pixels: a block of 8 all sky but one pixel of the ball's edge has its
    // noise measured by two seeds a side as next to none (the few strands crossing that
    // pixel come out alike in both), and called some seeds' same renders beyond noise
    // (docs/measurements.md, "One strand tip under `auto` camera rays").
    let o = hairtrace(&[
        "bias",
        "--images",
        &a1,
        &a2,
        "--references",
        &b1,
        &b2,
        "--block",
        "16",
        "--json",
    ]);
    assert!(o.status.success(), "{o:?}");
    let b: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(
        (b["within_noise"].as_bool(), b["block"].as_u64()),
        (Some(true), Some(16)),
        "{b}"
    );
    // Direct light alone is darker than every bounce, though little on the demo: the
    // renders are large and sampled enough for that to stand far beyond noise (smaller
    // ones left it near the bound, where any change to the renderer could flip it), exit
    // status 3.
    let o = hairtrace(&[
        "bias",
        "--images",
        &c1,
        &c2,
        "--references",
        &b1,
        &b2,
        "--block",
        "16",
    ]);
    assert_eq!(o.status.code(), Some(3), "{o:?}");
    assert!(stdout(&o).contains("BEYOND NOISE"), "{}", stdout(&o));
    assert_one_line_error(
        &hairtrace(&["bias", "--images", &a1, "--references", &b1, &b2]),
        "--images",
    );
}

/// What the peer benchmark drives: a box-filtered render with its figures in JSON,
/// `compare` against another seed, `export` for Cycles.
#[test]
fn render_stats_compare_and_export() {
    let small = [
        "--width", "32", "--height", "24", "--spp", "2", "--filter", "box",
    ];
    let render = |seed: &str, out: &str, stats: &str| {
        let mut args = vec!["render", "--seed", seed, "-o", out, "--stats", stats];
        args.extend(small);
        let o = hairtrace(&args);
        assert!(o.status.success(), "{o:?}");
    };
    let (a, b) = (tmp("cli_seed1.exr"), tmp("cli_seed2.exr"));
    let stats = tmp("cli_stats.json");
    render("1", &a, &stats);
    render("2", &b, &tmp("cli_stats2.json"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&stats).unwrap()).unwrap();
    assert_eq!(s["samples"], 32 * 24 * 2);
    assert_eq!(s["spp"], 2);
    assert!(s["rays"].as_u64().unwrap() >= 32 * 24 * 2, "{s}");
    assert!(s["seconds"].as_f64().unwrap() > 0.0 && s["build_seconds"].as_f64().is_some());
    // Every stage's seconds, the render's as above, adding up to no more than the build.
    let stage = |name: &str| s["stage_seconds"][name].as_f64().unwrap_or(-1.0);
    assert_eq!(stage("render"), s["seconds"].as_f64().unwrap());
    let built: f64 = ["read", "curves", "bvh"].map(stage).iter().sum();
    assert!(
        ["read", "curves", "bvh"].iter().all(|n| stage(n) >= 0.0),
        "{s}"
    );
    assert!(
        built > 0.0 && built <= s["build_seconds"].as_f64().unwrap(),
        "{s}"
    );
    // The first pixel: the build and the first finished tile, within the render. A groom
    // this small is built whole: no part built in the render.
    let (build, render) = (s["build_seconds"].as_f64().unwrap(), stage("render"));
    let first = s["first_pixel_seconds"].as_f64().unwrap_or(-1.0);
    assert!(build <= first && first <= build + render, "{s}");
    assert_eq!(
        (s["parts_built"].as_u64(), s["part_build_seconds"].as_f64()),
        (Some(0), Some(0.0))
    );

    let o = hairtrace(&["compare", &a, &b, "--json"]);
    assert!(o.status.success(), "{o:?}");
    let c: serde_json::Value = serde_json::from_str(&stdout(&o)).unwrap();
    let rmse = c["rmse"].as_f64().unwrap();
    assert!(rmse > 0.0 && rmse < 1.0, "two seeds differ by noise: {c}");
    let o = hairtrace(&["compare", &a, &a]);
    assert!(stdout(&o).starts_with("RMSE 0.000000"), "{}", stdout(&o));

    // Another size is an error, in one line.
    let wide = tmp("cli_wide.exr");
    let o = hairtrace(&[
        "render", "--width", "40", "--height", "24", "--spp", "1", "-o", &wide,
    ]);
    assert!(o.status.success(), "{o:?}");
    assert_one_line_error(&hairtrace(&["compare", &wide, &a]), "size");
    assert_one_line_error(
        &hairtrace(&["render", "--filter", "gauss", "-o", &a]),
        "gauss",
    );

    let dir = tmp("cli_export");
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/../bench/scenes/fur_ball.toml");
    let o = hairtrace(&["export", scene, "-o", &dir]);
    assert!(o.status.success(), "{o:?}");
    let json = std::fs::read_to_string(format!("{dir}/scene.json")).unwrap();
    assert!(json.contains("groom0.hair") && json.contains("\"fov_y_deg\": 33.0"));
    // The demo's camera is automatic: not exportable, and said so.
    assert_one_line_error(&hairtrace(&["export", "-o", &dir]), "eye and target");
}

fn usd_fixture(name: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/usd")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// `info` on a USD stage describes each BasisCurves prim and names what it ignored; a bare
/// USD groom renders like a bare .hair; a bad one is a one-line error.
#[test]
fn info_and_render_read_usd() {
    let o = hairtrace(&["info", &usd_fixture("all_bases.usdc")]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    assert_eq!(text.matches("\nprim /groom/inner/").count(), 10, "{text}");
    for needle in [
        "upAxis Y, metersPerUnit 0.01",
        "(CatmullRom, Pinned)",
        "  strands:  2\n  points:   11\n  segments: 3\n",
        "ignored:  /groom/head (Sphere)",
    ] {
        assert!(text.contains(needle), "{needle:?} in {text}");
    }
    let out = tmp("cli_usd.exr");
    let o = hairtrace(&[
        "render",
        &usd_fixture("case4.usda"),
        "--width",
        "32",
        "--height",
        "32",
        "--spp",
        "2",
        "-o",
        &out,
    ]);
    assert!(o.status.success(), "{o:?}");
    let bad = tmp("cli_bad.usda");
    std::fs::write(
        &bad,
        "#usda 1.0\ndef BasisCurves \"c\" {\nint[] curveVertexCounts = [3]\n}\n",
    )
    .unwrap();
    assert_one_line_error(&hairtrace(&["info", &bad]), "cli_bad.usda");
}

/// A procedural groom goes to USD and back: `convert` takes a scene file or a demo, writes
/// a stage that `info` reads, and the stage converts back to the same .hair strands; the
/// summary names what was written; bad paths and extensions are one-line errors.
#[test]
fn convert_takes_a_procedural_groom_to_usd_and_back() {
    let scene = tmp("cli_convert.toml");
    std::fs::write(
        &scene,
        "[materials.h]\ntype = \"hair\"\nmelanin = [1, 0]\n\
         [[groom]]\nprocedural = \"fur_ball\"\nmaterial = \"h\"\n\
         [groom.params]\nstrands = 50\nsegments = 6\n",
    )
    .unwrap();
    let (usda, hair, again) = (
        tmp("cli_convert.usda"),
        tmp("cli_convert.hair"),
        tmp("cli_convert_again.usda"),
    );
    let o = hairtrace(&["convert", &scene, &usda]);
    assert!(o.status.success(), "{o:?}");
    let said = String::from_utf8_lossy(&o.stderr);
    assert!(
        said.contains("50 strands, 350 points from 1 groom"),
        "{said}"
    );
    let info = stdout(&hairtrace(&["info", &usda]));
    assert!(
        info.contains("prim /Groom/groom0 (BSpline, Pinned)\n  strands:  50\n  points:   350"),
        "{info}"
    );
    assert!(hairtrace(&["convert", &usda, &hair]).status.success());
    let info_hair = stdout(&hairtrace(&["info", &hair]));
    assert!(
        info_hair.contains("strands:  50\npoints:   350\n"),
        "{info_hair}"
    );
    assert!(
        info_hair.contains("curves:   cubic bspline pinned, upAxis Y, metersPerUnit 1"),
        "{info_hair}"
    );
    // And round again reads the same.
    assert!(hairtrace(&["convert", &hair, &again]).status.success());
    let info_again = stdout(&hairtrace(&["info", &again]));
    assert_eq!(info_again, info);
    // A demo's groom, by name.
    let demo = tmp("cli_convert_demo.usda");
    assert!(
        hairtrace(&["convert", "--demo", "furnace", &demo])
            .status
            .success()
    );
    assert!(stdout(&hairtrace(&["info", &demo])).contains("strands:  10000"));
    for (args, needle) in [
        (vec![scene.as_str(), "out.obj"], "unknown output extension"),
        (vec!["missing.hair", usda.as_str()], "missing.hair"),
        (
            vec!["--demo", "furnace", &scene, &usda],
            "with --demo, give only OUT",
        ),
        (vec![usda.as_str(), "/no/such/dir/x.hair"], "does not exist"),
        (vec!["--basis", "cubic", &hair, &usda], "unknown basis"),
        (
            vec!["--basis", "catmull_rom", &usd_fixture("case4.usda"), &hair],
            "--basis linear",
        ),
    ] {
        let mut all = vec!["convert"];
        all.extend(args);
        assert_one_line_error(&hairtrace(&all), needle);
    }
}

/// `--deep-bounce-depth`, `--lobe-cull` and `--light-threshold` reach the renderer: a deep-bounce depth of
/// `--max-depth` is the exact image bit for bit (EXR keeps the bits), an earlier one
/// and culling change it; out-of-range values are one-line errors naming the setting.
#[test]
fn render_takes_the_fidelity_knobs() {
    let common = [
        "render",
        "--width",
        "24",
        "--height",
        "24",
        "--spp",
        "2",
        "--max-depth",
        "4",
    ];
    let image = |name: &str, knob: &[&str]| {
        let out = tmp(name);
        let mut args: Vec<&str> = common.to_vec();
        args.extend(knob);
        args.extend(["-o", out.as_str()]);
        let o = hairtrace(&args);
        assert!(o.status.success(), "{o:?}");
        hairtrace::image::read_image(std::path::Path::new(&out))
            .unwrap()
            .pixels
    };
    let exact = image("cli_exact.exr", &[]);
    // A flag and `--set` are the same setting.
    assert_eq!(
        image("cli_set.exr", &["--set", "deep_bounce_depth=4"]),
        exact
    );
    assert_eq!(
        image("cli_set_cull.exr", &["--set", "lobe_cull=0.2"]),
        image("cli_flag_cull.exr", &["--lobe-cull", "0.2"])
    );
    assert_eq!(image("cli_deep4.exr", &["--deep-bounce-depth", "4"]), exact);
    assert_ne!(image("cli_deep1.exr", &["--deep-bounce-depth", "1"]), exact);
    assert_ne!(image("cli_cull.exr", &["--lobe-cull", "0.2"]), exact);
    assert_ne!(
        image("cli_every_shadow_ray.exr", &["--light-threshold", "0"]),
        exact
    );
    let out = tmp("cli_knob_error.exr");
    for (knob, value, needle) in [
        ("--deep-bounce-depth", "5", "deep_bounce_depth = 5"),
        ("--deep-bounce-depth", "0", "deep_bounce_depth = 0"),
        ("--lobe-cull", "1", "lobe_cull = 1"),
        ("--light-threshold", "inf", "light_threshold = inf"),
        ("--set", "spp=0", "spp = 0: must be >= 1"),
        ("--set", "spp", "NAME=VALUE"),
        (
            "--set",
            "sample_count=4",
            "sample_count: not a render setting",
        ),
    ] {
        let mut args: Vec<&str> = common.to_vec();
        args.extend([knob, value, "-o", out.as_str()]);
        assert_one_line_error(&hairtrace(&args), needle);
    }
}

/// docs/settings.md holds the schema exactly as `hairtrace settings` prints it, so the
/// documentation cannot drift from the code.
#[test]
fn the_settings_doc_is_the_schema() {
    let o = hairtrace(&["settings"]);
    assert!(o.status.success(), "{o:?}");
    let table = stdout(&o);
    assert!(table.contains("| `light_threshold` |"), "{table}");
    let doc = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/settings.md"),
    )
    .unwrap();
    assert!(
        doc.contains(&table),
        "docs/settings.md lacks the table `hairtrace settings` prints; paste it in:\n{table}"
    );
}

/// A scene for `export`: a linear fur ball, a ground, a sky and a sun.
const PEER_SCENE: &str = r#"
[render]
width = 32
height = 24
[camera]
eye = [0, 0, 5]
target = [0, 0, 0]
fov_deg = 30
[materials.brown]
type = "hair"
melanin = [1.3, 0.0]
[materials.floor]
type = "diffuse"
albedo = [0.5, 0.5, 0.5]
[[groom]]
procedural = "fur_ball"
basis = "linear"
material = "brown"
[groom.params]
strands = 50
segments = 4
[[mesh]]
shape = "ground"
y = -2
half_size = 3
material = "floor"
[[light]]
type = "environment"
radiance = [0.5, 0.5, 0.5]
scale = 2
[[light]]
type = "distant"
direction = [0, 1, 0]
irradiance = [3, 3, 3]
angular_radius_deg = 2
"#;

/// `hairtrace export` of `text` (a scene file's) into a fresh folder `name`: the command's
/// output, the folder, and the scene as the library reads it.
fn export(text: &str, name: &str) -> (Output, String, hairtrace::SceneDescription) {
    let (scene, dir) = (tmp(&format!("{name}.toml")), tmp(name));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::write(&scene, text).unwrap();
    let description = hairtrace::SceneDescription::load(scene.as_ref()).unwrap();
    (hairtrace(&["export", &scene, "-o", &dir]), dir, description)
}

fn scene_json(dir: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(format!("{dir}/scene.json")).unwrap()).unwrap()
}

/// Every committed bench scene exports for the peer (the real-groom scenes' files are made
/// by bench/real_grooms.py; bench/peer exports them itself).
#[test]
fn bench_scenes_export_for_the_peer() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scenes");
    let mut found = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().into_owned();
        if path.extension().is_some_and(|e| e == "toml") && !name.starts_with("real_") {
            let out = tmp(&format!("cli_peer_{name}"));
            let o = hairtrace(&["export", &path.to_string_lossy(), "-o", &out]);
            assert!(o.status.success(), "{name}: {o:?}");
            assert!(std::path::Path::new(&out).join("scene.json").is_file());
            found += 1;
        }
    }
    assert!(found >= 4, "only {found} bench scenes");
}

/// The Huang model goes out with its roughness and aspect; a USD groom read at a frame
/// under an open shutter goes out as its file (for the peer's own USD import) with the frame
/// and the shutter, and is refused with a transform the import would not apply.
#[test]
fn a_huang_material_and_a_moving_usd_groom_go_out_as_the_peer_reads_them() {
    // The bench scene `name`'s export.
    let exported = |name: &str| {
        let bench = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scenes");
        let out = tmp(&format!("cli_peer_read_{name}"));
        let scene = bench.join(format!("{name}.toml"));
        let o = hairtrace(&["export", &scene.to_string_lossy(), "-o", &out]);
        assert!(o.status.success(), "{o:?}");
        scene_json(&out)
    };
    let json = exported("swaying_blur");
    assert_eq!(json["motion"]["frame"], 6.0);
    assert_eq!(json["motion"]["shutter"], serde_json::json!([-0.25, 0.25]));
    let usd = json["grooms"][0]["usd"].as_str().unwrap();
    assert!(
        usd.starts_with('/') && usd.ends_with("swaying.usda"),
        "{usd}"
    );
    assert_eq!(json["grooms"][0]["material"]["model"], "chiang");

    let json = exported("huang_oval_fur_ball");
    let m = &json["grooms"][0]["material"];
    assert_eq!(
        (m["model"].as_str(), m["aspect"].as_f64()),
        (Some("huang"), Some(0.65))
    );
    assert_eq!(m["roughness"].as_f64(), Some(0.3));
    assert!(m.get("beta_m").is_none(), "{m}");
    // Still: no motion, no file to import.
    assert!(json.get("motion").is_none() && json["grooms"][0].get("usd").is_none());

    let usd =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenes/swaying.usda");
    let text = format!(
        "[render]\nshutter_close = 0.5\n[animation]\nframe = 2\n[camera]\neye = [0, 0, 2]\n\
         target = [0, 0, 0]\n[materials.h]\ntype = \"hair\"\nmelanin = [1, 0]\n\
         [[groom]]\nfile = {:?}\nmaterial = \"h\"\nscale = 2.0\n",
        usd.to_string_lossy()
    );
    let (o, ..) = export(&text, "cli_peer_moving_placed");
    assert_one_line_error(&o, "groom[0]: a moving USD groom is exported as its file");
    // A sequence of per-frame stages has no one file whose time samples the peer imports.
    let frames = tmp("cli_peer_usd_sequence");
    std::fs::create_dir_all(&frames).unwrap();
    for f in [2, 3] {
        std::fs::copy(&usd, format!("{frames}/sway.{f:04}.usda")).unwrap();
    }
    let sequence = format!("{frames}/sway.####.usda");
    let (o, ..) = export(
        &text
            .replace(&*usd.to_string_lossy(), &sequence)
            .replace("scale = 2.0\n", ""),
        "cli_peer_moving_sequence",
    );
    assert_one_line_error(
        &o,
        &format!("groom[0]: {sequence} is a sequence of per-frame files"),
    );
    // A camera that moves over the shutter has no still pose to export.
    let text = text.replace("scale = 2.0\n", "") + "[camera.shutter_close]\neye = [0, 0, 3]\n";
    let (o, ..) = export(&text, "cli_peer_moving_camera");
    assert_one_line_error(&o, "a moving camera is not exported");
}

/// A USD groom's curve normals go out beside its `.hair` file, one per point, in the world
/// as hairtrace reads them: the Z-up stage turned, the entry's scale applied, signs kept.
#[test]
fn curve_normals_go_out_in_the_world() {
    let usd = tmp("cli_peer_normals.usda");
    std::fs::write(
        &usd,
        "#usda 1.0\n(\n    upAxis = \"Z\"\n    metersPerUnit = 1\n)\n\
         def BasisCurves \"c\"\n{\nint[] curveVertexCounts = [2, 2]\n\
         point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (1, 1, 0)]\n\
         float[] widths = [0.1] (interpolation = \"constant\")\n\
         uniform token type = \"linear\"\n\
         float3[] primvars:custom_normal = [(0, -1, 0), (0, 0, 1), (0.6, 0, -0.8), (-1, 0, 0)] \
         (interpolation = \"vertex\")\n}\n",
    )
    .unwrap();
    let text = format!(
        "[camera]\neye = [0, 0, 4]\ntarget = [0, 0, 0]\n[materials.h]\ntype = \"hair\"\n\
         melanin = [1, 0]\n[[groom]]\nfile = {usd:?}\nmaterial = \"h\"\nscale = 2.0\n"
    );
    let (o, dir, _) = export(&text, "cli_peer_normals");
    assert!(o.status.success(), "{o:?}");
    assert_eq!(scene_json(&dir)["grooms"][0]["normals"], "groom0.normals");
    let bytes = std::fs::read(format!("{dir}/groom0.normals")).unwrap();
    let normals: Vec<f32> = (bytes.chunks_exact(4))
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    // A Z-up stage's (x, y, z) is the world's (x, z, -y); then twice as long.
    let want = [0.0, 0.0, 2.0, 0.0, 2.0, 0.0, 1.2, -1.6, 0.0, -2.0, 0.0, 0.0];
    assert_eq!(normals, want);
}

#[test]
fn a_scene_goes_out_whole() {
    let (o, dir, d) = export(PEER_SCENE, "cli_peer_whole");
    assert!(o.status.success(), "{o:?}");
    let json = scene_json(&dir);
    assert_eq!(json["width"], 32);
    assert_eq!(json["camera"]["fov_y_deg"], 30.0);
    let groom = &json["grooms"][0];
    assert_eq!(groom["basis"], "linear");
    assert!(
        groom.get("normals").is_none(),
        "a procedural groom has no normals"
    );
    let sigma_a = hairtrace::bsdf::sigma_a_from_melanin(1.3, 0.0).unwrap();
    let exported = groom["material"]["sigma_a"][1].as_f64().unwrap() as f32;
    assert_eq!(exported, sigma_a[1], "f32 values survive the text exactly");
    // The environment's scale is folded into its radiance.
    assert_eq!(json["lights"][0]["radiance"][0], 1.0);
    assert_eq!(json["lights"][1]["type"], "distant");
    let path = format!("{dir}/groom0.hair");
    let strands = read_hair_file(path.as_ref(), Thickness::Diameter).unwrap();
    assert_eq!(strands, d.grooms[0].placed_strands().unwrap()[0].strands);
    let obj = std::fs::read_to_string(format!("{dir}/mesh0.obj")).unwrap();
    assert!(obj.lines().any(|l| l.starts_with("vn ")) && obj.contains("f 1//1"));
}

/// A USD groom goes out at its own basis (pinned Catmull-Rom, as Blender writes it), its
/// authored points in the world (the stage's centimetres in metres); a prim Cycles cannot
/// draw is named.
#[test]
fn usd_grooms_export_at_their_own_basis() {
    let usd = usd_fixture("case8.usda");
    let text = PEER_SCENE
        .replace(
            "procedural = \"fur_ball\"\nbasis = \"linear\"",
            &format!("file = {usd:?}"),
        )
        .replace("[groom.params]\nstrands = 50\nsegments = 4\n", "");
    let (o, dir, _) = export(&text, "cli_peer_usd");
    assert!(o.status.success(), "{o:?}");
    assert_eq!(scene_json(&dir)["grooms"][0]["basis"], "catmull-rom");
    let path = format!("{dir}/groom0.hair");
    let strands = read_hair_file(path.as_ref(), Thickness::Diameter).unwrap();
    let prim = &read_usd_file(usd.as_ref()).unwrap().curves[0];
    assert_eq!(strands.counts, prim.authored_counts);
    assert_eq!(
        strands.points[1],
        prim.authored().points[1].map(|v| v * 0.01)
    );
    // Nonperiodic B-splines (case4) have no Cycles curve.
    let (o, _, _) = export(&text.replace("case8.usda", "case4.usda"), "cli_peer_usd4");
    assert_one_line_error(&o, "cubic bspline nonperiodic");
}

#[test]
fn what_a_peer_cannot_render_is_refused() {
    for (from, to, expect) in [
        ("eye = [0, 0, 5]\ntarget = [0, 0, 0]", "", "eye and target"),
        (
            "basis = \"linear\"",
            "basis = \"bspline\"",
            "no Cycles equivalent",
        ),
        (
            "melanin = [1.3, 0.0]",
            "melanin = [1.3, 0.0]\nabsorption_variation = 0.2",
            "varies per strand",
        ),
    ] {
        let (o, _, _) = export(&PEER_SCENE.replace(from, to), "cli_peer_refused");
        assert_one_line_error(&o, expect);
    }
}

/// `info` says an animated stage's time range and what moves; `render --frame` reads the
/// groom at that frame (a frame past the stage's animation is refused in one line).
#[test]
fn info_lists_the_animation_and_render_reads_the_frame() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap();
    let usda = root.join("examples/scenes/swaying.usda");
    let o = hairtrace(&["info", usda.to_str().unwrap()]);
    assert!(o.status.success(), "{o:?}");
    let text = stdout(&o);
    assert!(
        text.contains(
            "time:     time codes 1 to 24 (frames 1 to 24), 24 time codes and 24 frames per second"
        ),
        "{text}"
    );
    assert!(text.contains("animated: /Groom/hair.points"), "{text}");

    let scene = root.join("examples/scenes/swaying.toml");
    let pattern = tmp("cli_sway.#.exr");
    let render = |frame: &str| {
        hairtrace(&[
            "render",
            scene.to_str().unwrap(),
            "--width",
            "32",
            "--height",
            "24",
            "--spp",
            "1",
            "--seed",
            "1",
            "--frame",
            frame,
            "-o",
            &pattern,
        ])
    };
    for frame in ["1", "12"] {
        let o = render(frame);
        assert!(o.status.success(), "{o:?}");
    }
    let pixels = |p: &str| {
        hairtrace::image::read_image(std::path::Path::new(p))
            .unwrap()
            .pixels
    };
    let (a, b) = (tmp("cli_sway.1.exr"), tmp("cli_sway.12.exr"));
    assert!(
        pixels(&a) != pixels(&b),
        "the groom moves between frames 1 and 12"
    );
    assert_one_line_error(
        &render("30"),
        "frame 30 is outside the shot's frames 1 to 24",
    );
}

/// Output into a closed pipe ends the command quietly, not with a panic.
#[test]
fn a_closed_pipe_ends_the_output_quietly() {
    let o = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!(
            "'{}' lobes | head -n 1",
            env!("CARGO_BIN_EXE_hairtrace")
        ))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("panicked"), "{err}");
    assert_eq!(stdout(&o).lines().count(), 1);
}
