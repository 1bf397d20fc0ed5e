//! Render farms through the command line: tiles (`render --tile`) assembled (`assemble`)
//! into the whole-frame render bit for bit, tiles that do not belong together refused, no
//! tile left by a task killed while writing it, and the job `hairtrace farm` writes run by
//! openjd-cli, the reference runner of Open Job Description, and by a one-node Slurm
//! (`scripts/slurm-farm`). The library's side of ISA pinning is tested in
//! tests/pipeline/farm.rs.

use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use hairtrace::image::{Image, WriteOptions, read_image, write_image};

/// The demo at a size that renders in a blink, pinned, with the seed of frame 5.
const SCENE: [&str; 12] = [
    "--demo", "furball", "--width", "48", "--height", "36", "--spp", "2", "--isa", "sse2",
    "--seed", "5",
];

fn hairtrace(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hairtrace"))
        .args(args)
        .output()
        .expect("run hairtrace")
}

fn ok(o: Output) -> Output {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

/// An empty folder of this name under the test target's scratch folder.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn text(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `render` of the demo with `extra` flags (which may override the scene's).
fn render(extra: &[&str]) -> Output {
    hairtrace(
        &["render"]
            .into_iter()
            .chain(SCENE)
            .chain(extra.iter().copied())
            .collect::<Vec<_>>(),
    )
}

/// Renders tile `i` of 4 of `frame` with `extra` flags (two threads: not the whole
/// render's one).
fn tile(frame: &Path, i: u32, extra: &[&str]) -> Output {
    let t = format!("{i}/4");
    let mut args = vec!["--threads", "2", "--tile", &t, "-o", text(frame)];
    args.extend(extra);
    render(&args)
}

fn assemble(frame: &Path) -> Output {
    hairtrace(&["assemble", "--tiles", "4", text(frame)])
}

fn hairtrace_header(image: &Image) -> Vec<(String, String)> {
    let mut h: Vec<_> = image
        .attributes
        .iter()
        .filter(|(n, _)| n.starts_with("hairtrace:"))
        .cloned()
        .collect();
    h.sort();
    h
}

/// `a` and `b` hold the same pixels, bit for bit, in the same frame, with the same header.
fn assert_same_frame(a: &Path, b: &Path) {
    let (a, b) = (read_image(a).unwrap(), read_image(b).unwrap());
    assert_eq!(
        (a.width, a.height, a.channels),
        (b.width, b.height, b.channels)
    );
    assert_eq!(a.placement, b.placement);
    let bits = |i: &Image| i.pixels.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    let differ = bits(&a)
        .iter()
        .zip(bits(&b))
        .filter(|(x, y)| **x != *y)
        .count();
    assert_eq!(differ, 0, "{differ} of {} values differ", a.pixels.len());
    assert_eq!(hairtrace_header(&a), hairtrace_header(&b));
    assert!(!hairtrace_header(&a).is_empty());
}

/// Four tiles rendered by four processes, with another thread count than the whole
/// render, assemble into that render: the same bits, the same frame, the same header
/// (every setting, the scene, the kernels and the version); so do the tiles of an AOV.
#[test]
fn tiles_assemble_into_the_whole_frame_bit_for_bit() {
    let dir = scratch("farm_assemble");
    let (whole, frame) = (dir.join("whole.exr"), dir.join("frame.exr"));
    ok(render(&[
        "--threads",
        "1",
        "--aov",
        "depth",
        "-o",
        text(&whole),
    ]));
    for i in 1..=4 {
        ok(tile(&frame, i, &["--aov", "depth"]));
    }
    let tile2 = read_image(&dir.join("frame.tile-2-of-4.exr")).unwrap();
    assert_eq!(
        (tile2.placement.x, tile2.placement.y),
        (24, 0),
        "the EXR data window"
    );
    assert_eq!(tile2.attribute("hairtrace:tile"), Some("2/4"));
    ok(assemble(&frame));
    assert_same_frame(&frame, &whole);
    // An AOV's tiles assemble the same way, under its own name.
    let depth = dir.join("frame.depth.exr");
    ok(assemble(&depth));
    assert_same_frame(&depth, &dir.join("whole.depth.exr"));
}

/// The error of an assembly that must fail, which must leave no frame behind.
fn refusal(frame: &Path) -> String {
    let o = assemble(frame);
    assert!(
        !o.status.success(),
        "assembled tiles that do not make the frame"
    );
    assert!(
        !frame.exists(),
        "a refused assembly wrote {}",
        frame.display()
    );
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    err
}

/// A missing tile, a tile holding another window, and tiles of another seed, sample count,
/// ISA or hairtrace version are each refused with a message naming the tile and what is
/// wrong; with the right tile back, the frame assembles.
#[test]
fn assemble_refuses_a_missing_or_mismatched_tile() {
    let dir = scratch("farm_refusals");
    let frame = dir.join("frame.exr");
    for i in 1..=4 {
        ok(tile(&frame, i, &[]));
    }
    let third = dir.join("frame.tile-3-of-4.exr");
    let good = read_image(&third).unwrap();

    std::fs::remove_file(&third).unwrap();
    let err = refusal(&frame);
    assert!(
        err.contains("tile 3 of 4") && err.contains(text(&third)),
        "{err}"
    );

    ok(tile(&frame, 3, &["--set", "seed=6"]));
    let err = refusal(&frame);
    assert!(
        err.contains(text(&third)) && err.contains("seed = 6, where seed = 5"),
        "{err}"
    );

    ok(tile(&frame, 3, &["--set", "spp=1"]));
    assert!(refusal(&frame).contains("spp = 1, where spp = 2"));

    if hairtrace::embree::Isa::Avx2.runs_here() {
        ok(tile(&frame, 3, &["--set", "isa=avx2"]));
        assert!(refusal(&frame).contains("isa = avx2, where isa = sse2"));
    }

    // Tile 2's window, at tile 3's name.
    ok(render(&["--crop", "24,0,48,18", "-o", text(&third)]));
    let err = refusal(&frame);
    assert!(
        err.contains("holds the window 24,0,48,18") && err.contains("is 0,18,24,36"),
        "{err}"
    );

    // The good tile as another hairtrace version would have written it.
    let mut attributes = good.attributes.clone();
    for (name, value) in &mut attributes {
        if name == "hairtrace:version" {
            *value = "0.0.1".into();
        }
    }
    let opts = WriteOptions {
        placement: Some(good.placement),
        attributes,
        ..WriteOptions::default()
    };
    write_image(&third, good.width, good.height, 3, &good.pixels, &opts).unwrap();
    let version = refusal(&frame);
    assert!(
        version.contains(&format!(
            "version = 0.0.1, where version = {}",
            hairtrace::VERSION
        )),
        "{version}"
    );

    ok(tile(&frame, 3, &[]));
    ok(assemble(&frame));
}

/// A task killed while it writes its tile (here by the file-size limit, SIGXFSZ, after a
/// few kB) leaves its temporary file but no tile, so assembly refuses the frame; rerunning
/// that one task gives the exact frame.
#[test]
fn a_task_killed_while_writing_leaves_no_tile_and_its_rerun_gives_the_frame() {
    let dir = scratch("farm_killed");
    let (whole, frame) = (dir.join("whole.exr"), dir.join("frame.exr"));
    ok(render(&["--threads", "1", "-o", text(&whole)]));
    for i in [1, 2, 4] {
        ok(tile(&frame, i, &[]));
    }
    let limited = Command::new("sh")
        .args(["-c", "ulimit -f 2 && exec \"$0\" \"$@\""])
        .arg(env!("CARGO_BIN_EXE_hairtrace"))
        .arg("render")
        .args(SCENE)
        .args(["--tile", "3/4", "-o", text(&frame)])
        .output()
        .unwrap();
    assert_eq!(limited.status.signal(), Some(25), "SIGXFSZ: {limited:?}");
    let third = dir.join("frame.tile-3-of-4.exr");
    assert!(!third.exists(), "a killed task left a tile");
    let partial = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(".frame.tile-3-of-4.exr.")
        });
    assert!(
        partial,
        "the task was to be killed mid-write, leaving its temporary file"
    );
    assert!(refusal(&frame).contains("tile 3 of 4"));

    ok(tile(&frame, 3, &[]));
    ok(assemble(&frame));
    assert_same_frame(&frame, &whole);
}

/// The venv with openjd-cli 0.8 under target/ (made once, then reused), or None when PyPI
/// cannot be reached (said on stderr). One test thread makes it; the others wait.
fn openjd() -> Option<PathBuf> {
    static VENV: std::sync::OnceLock<Option<PathBuf>> = std::sync::OnceLock::new();
    VENV.get_or_init(make_openjd_venv).clone()
}

fn make_openjd_venv() -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_TARGET_TMPDIR")).join("openjd-venv");
    let bin = venv.join("bin/openjd");
    if bin.exists() {
        return Some(bin);
    }
    let run = |c: &mut Command| {
        c.output()
            .expect("python3 (scripts/setup installs python3-venv)")
    };
    let made = run(Command::new("python3").args(["-m", "venv"]).arg(&venv));
    assert!(made.status.success(), "python3 -m venv: {made:?}");
    let pip = run(Command::new(venv.join("bin/pip")).args(["install", "-q", "openjd-cli==0.8.*"]));
    if !pip.status.success() {
        let err = String::from_utf8_lossy(&pip.stderr);
        let _ = std::fs::remove_dir_all(&venv);
        let offline = [
            "Network is unreachable",
            "Failed to establish",
            "Temporary failure in name resolution",
            "Could not fetch URL",
            "No matching distribution",
        ];
        assert!(
            offline.iter().any(|o| err.contains(o)),
            "pip install openjd-cli: {err}"
        );
        eprintln!("SKIPPED: PyPI is unreachable, so openjd-cli cannot be installed: {err}");
        return None;
    }
    Some(bin)
}

/// `openjd run` of the whole job (the Assemble step and the Render step it depends on),
/// with job parameters `params`, which must succeed.
fn run_job(openjd: &Path, template: &Path, params: &[&str]) {
    let run = Command::new(openjd)
        .arg("run")
        .arg(template)
        .args(["--step", "Assemble", "--run-dependencies"])
        .args(params)
        .output()
        .unwrap();
    let log = String::from_utf8_lossy(&run.stdout);
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "openjd run: {log}{err}");
}

/// The Open Job Description template of `hairtrace farm`, run by openjd-cli: 2 frames x 4
/// tiles, then the assembly of each frame, equal bit for bit to the frame rendered whole
/// with that frame's seed.
#[test]
fn openjd_cli_runs_the_farm_template_into_the_whole_frames() {
    let Some(openjd) = openjd() else { return };
    let dir = scratch("farm_openjd");
    std::fs::create_dir(dir.join("out")).unwrap();
    let template = dir.join("job.json");
    ok(hairtrace(&[
        "farm",
        "--demo",
        "furball",
        "--width",
        "48",
        "--height",
        "36",
        "--spp",
        "2",
        "--isa",
        "sse2",
        "--threads",
        "1",
        "--frames",
        "1-2",
        "--tiles",
        "4",
        "--output",
        text(&dir.join("out/frame.####.exr")),
        "--hairtrace",
        env!("CARGO_BIN_EXE_hairtrace"),
        "--openjd",
        text(&template),
    ]));
    let check = Command::new(&openjd)
        .arg("check")
        .arg(&template)
        .output()
        .unwrap();
    assert!(check.status.success(), "openjd check: {check:?}");
    run_job(&openjd, &template, &[]);
    for f in [1, 2] {
        let whole = dir.join(format!("whole.{f}.exr"));
        let (seed, frame) = (format!("seed={f}"), f.to_string());
        ok(render(&[
            "--threads",
            "1",
            "--set",
            &seed,
            "--frame",
            &frame,
            "-o",
            text(&dir.join("whole.#.exr")),
        ]));
        assert_same_frame(&dir.join(format!("out/frame.000{f}.exr")), &whole);
    }
}

/// `farm SCENE SIZE --frames FRAMES --tiles 2` into `DIR/out/f.##.exr`, its Open Job
/// Description template run by openjd-cli with the scene given at submission: farm's
/// output.
fn run_scene_job(openjd: &Path, dir: &Path, scene: &Path, size: &[&str], frames: &str) -> Output {
    let template = dir.join("job.json");
    let output = dir.join("out/f.##.exr");
    let mut args = vec!["farm", text(scene)];
    args.extend(size);
    args.extend([
        "--frames",
        frames,
        "--tiles",
        "2",
        "--output",
        text(&output),
    ]);
    args.extend(["--hairtrace", env!("CARGO_BIN_EXE_hairtrace")]);
    args.extend(["--openjd", text(&template)]);
    let farm = ok(hairtrace(&args));
    run_job(
        openjd,
        &template,
        &["-p", &format!("Scene={}", text(scene))],
    );
    farm
}

/// A scene file outside the template's folder: the template gives `Scene` no default (the
/// specification takes none outside its folder), farm says so, and the job runs with the
/// scene given at submission into the whole frame.
#[test]
fn openjd_cli_runs_a_scene_file_given_at_submission() {
    let Some(openjd) = openjd() else { return };
    let dir = scratch("farm_openjd_scene");
    std::fs::create_dir(dir.join("out")).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let scene = root.join("examples/scenes/fur_ball.toml");
    let size = [
        "--width", "32", "--height", "24", "--spp", "1", "--isa", "sse2",
    ];
    let farm = run_scene_job(&openjd, &dir, &scene, &size, "3");
    let note = String::from_utf8_lossy(&farm.stderr);
    assert!(note.contains("Scene has no default"), "{note}");
    let mut whole = vec!["render", text(&scene)];
    whole.extend(size);
    let pattern = dir.join("whole.#.exr");
    whole.extend(["--seed", "3", "--frame", "3", "-o", text(&pattern)]);
    ok(hairtrace(&whole));
    assert_same_frame(&dir.join("out/f.03.exr"), &dir.join("whole.3.exr"));
}

/// Three frames of an animated groom (examples/scenes/swaying.toml: USD time samples) run
/// by openjd-cli, 2 tiles each: every assembled frame equals the whole render of that frame
/// bit for bit, and the shot's frames are the job's by default.
#[test]
fn openjd_cli_renders_the_frames_of_an_animated_groom() {
    let Some(openjd) = openjd() else { return };
    let dir = scratch("farm_openjd_animated");
    std::fs::create_dir(dir.join("out")).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let scene = root.join("examples/scenes/swaying.toml");
    let size = [
        "--width",
        "32",
        "--height",
        "24",
        "--spp",
        "1",
        "--isa",
        "sse2",
        "--threads",
        "1",
    ];
    run_scene_job(&openjd, &dir, &scene, &size, "1-3");
    for f in ["1", "2", "3"] {
        let mut whole = vec!["render", text(&scene)];
        whole.extend(size);
        let pattern = dir.join("whole.#.exr");
        whole.extend(["--seed", f, "--frame", f, "-o", text(&pattern)]);
        ok(hairtrace(&whole));
        assert_same_frame(
            &dir.join(format!("out/f.0{f}.exr")),
            &dir.join(format!("whole.{f}.exr")),
        );
    }
    // Without --frames, the job is the shot's frames; one outside them is refused.
    let shot = dir.join("shot.json");
    let mut args = vec!["farm", text(&scene)];
    args.extend(size);
    let output = dir.join("out/f.##.exr");
    args.extend(["--output", text(&output), "--openjd", text(&shot)]);
    ok(hairtrace(&args));
    assert!(text_of(&shot).contains("\"1-24\""), "{}", text_of(&shot));
    let mut args = vec!["farm", text(&scene)];
    args.extend(size);
    args.extend([
        "--frames",
        "20-30",
        "--output",
        text(&output),
        "--openjd",
        text(&shot),
    ]);
    let refused = hairtrace(&args);
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        !refused.status.success() && err.contains("frame 30 is outside the shot's frames 1 to 24"),
        "{err}"
    );
}

fn text_of(p: &Path) -> String {
    std::fs::read_to_string(p).unwrap()
}

/// The Slurm job script of `hairtrace farm`, submitted to a one-node Slurm cluster that
/// `scripts/slurm-farm` starts on localhost (and stops): three frames of an animated groom,
/// each assembled frame equal to the whole render of that frame bit for bit. The daemons
/// run as root, so other users skip it.
#[test]
fn slurm_runs_the_farm_job_array_into_the_whole_frames() {
    // SAFETY: geteuid has no preconditions.
    if unsafe { geteuid() } != 0 {
        eprintln!("SKIPPED: scripts/slurm-farm starts Slurm's daemons, which needs root");
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let out = Command::new(root.join("scripts/slurm-farm"))
        .env("HAIRTRACE", env!("CARGO_BIN_EXE_hairtrace"))
        .output()
        .expect("run scripts/slurm-farm (slurm-wlm and munge come from scripts/setup)");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "scripts/slurm-farm failed: {err}");
    assert!(
        err.contains("every frame equals the whole render of that frame bit for bit"),
        "{err}"
    );
}

unsafe extern "C" {
    fn geteuid() -> u32;
}

#[test]
fn the_command_line_refuses_an_unknown_isa_in_one_line() {
    let out = hairtrace(&[
        "render", "--demo", "furball", "--isa", "sse4.2", "-o", "x.exr",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("isa = sse4.2: must be sse2 | avx | avx2 | avx512"),
        "{err}"
    );
}

/// `farm` refuses a job whose tiles could not assemble or whose frames would overwrite
/// each other, before anything is submitted.
#[test]
fn farm_refuses_an_unpinned_isa_a_crop_and_an_output_without_a_frame_number() {
    let dir = scratch("farm_refused_jobs");
    let job = dir.join("job.json");
    let out = dir.join("frame.####.exr");
    let farm = |extra: &[&str]| {
        let mut args = vec!["farm", "--demo", "furball", "--openjd", text(&job)];
        args.extend(extra);
        hairtrace(&args)
    };
    for (extra, says) in [
        (vec!["--output", text(&out)], "pin the ISA"),
        (
            vec!["--isa", "sse2", "--crop", "0,0,8,8", "--output", text(&out)],
            "remove crop",
        ),
        (
            vec!["--isa", "sse2", "--output", text(&dir.join("frame.exr"))],
            "one run of #",
        ),
        (
            vec!["--isa", "sse2", "--output", text(&dir.join("frame.#.png"))],
            "must be an .exr",
        ),
        (
            vec!["--isa", "sse2", "--frames", "3-1", "--output", text(&out)],
            "FIRST <= LAST",
        ),
    ] {
        let o = farm(&extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(says),
            "{extra:?}: {err}"
        );
        assert!(!job.exists());
    }
}
