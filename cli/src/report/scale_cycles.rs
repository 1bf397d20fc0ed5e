//! The scale section's comparison with Blender Cycles: the stage benchmark's 1080p
//! Catmull-Rom scalp (bench/stages/scalp_1m_catmull_rom_1080p.toml, the groom and view
//! of issue 20's first-pixel target) at each strand count, hairtrace and Cycles each in a
//! process of its own, so that both peak memories are a whole process's.

use super::Context;
use super::markdown::{num, table};
use super::peers::blender_python;
use crate::export::export_for_peer;
use hairtrace::{Error, Result, SceneDescription};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The scene, in the stage benchmark's folder beside the bench scenes.
const SCENE: &str = "scalp_1m_catmull_rom_1080p";

fn scene_path(ctx: &Context) -> PathBuf {
    super::scene_path(&ctx.scenes.join("../stages"), SCENE)
}

const STRANDS: [usize; 3] = [10_000, 100_000, 1_000_000];

/// Two runs per strand count (hairtrace, Cycles) when Cycles runs here.
pub fn steps(ctx: &Context) -> u64 {
    if ctx.quick || blender_python().is_err() {
        0
    } else {
        2 * STRANDS.len() as u64
    }
}

/// The comparison's Markdown: a table, or why it was not run.
pub fn section(ctx: &Context) -> Result<String> {
    let python = match (ctx.quick, blender_python()) {
        (true, _) => return Ok(not_run("`--quick` leaves it out")),
        (false, Err(why)) => return Ok(not_run(&why)),
        (false, Ok(python)) => python,
    };
    let dir = std::env::temp_dir().join(format!("hairtrace-report-scale-{}", std::process::id()));
    let rows = compare(ctx, &python, &dir);
    // The exported grooms are hundreds of MB at 10^6 strands: removed even after a failure.
    let _ = std::fs::remove_dir_all(&dir);
    let threads = ctx.machine.threads.to_string();
    Ok(format!(
        "**Against Blender Cycles.** `{SCENE}.toml` (Catmull-Rom round, 16 segments, \
         1920x1080 x 1 spp: at this view every strand is wider than a pixel, so `auto` \
         builds it all round) at each strand count, one run each, {threads} threads: \
         hairtrace's time to the first pixel (its build and its first finished tile, \
         `--stats`; from 2^20 segments the groom is built in parts, each when a ray first \
         reaches it, so its render includes their builds) against Cycles' \
         synchronisation time (its scene sync and BVH build, from the EXR header's \
         stamps); the whole 1-spp frame (build and render) of each; and each process's \
         peak resident memory (`/usr/bin/time`), Blender's own code and data included. \
         Both renderers run Embree's curve build.\n\n{}",
        table(
            &[
                "strands",
                "hairtrace first pixel s",
                "Cycles sync s",
                "ratio",
                "hairtrace frame s",
                "Cycles frame s",
                "ratio",
                "hairtrace peak MiB",
                "Cycles peak MiB",
                "ratio",
            ],
            &rows?
        )
    ))
}

fn not_run(why: &str) -> String {
    format!(
        "**Against Blender Cycles: not run.** {why}. `HT_BENCH_VENV` naming a virtual \
         environment with Blender's Python module (bench/README.md) includes it.\n"
    )
}

/// One row per strand count: hairtrace's and Cycles' build seconds and peak memory.
fn compare(ctx: &Context, python: &Path, dir: &Path) -> Result<Vec<Vec<String>>> {
    let io = |e: std::io::Error| Error::io(dir, e);
    std::fs::create_dir_all(dir).map_err(io)?;
    let path = scene_path(ctx);
    let source = std::fs::read_to_string(&path).map_err(|e| Error::io(&path, e))?;
    let hairtrace = &ctx.hairtrace;
    let cycles = ctx.scenes.join("../cycles.py");
    let threads = ctx.machine.threads.to_string();
    let mut rows = Vec::new();
    for strands in STRANDS {
        ctx.step(format!(
            "scale: hairtrace, {strands} strands at 1080p (own process)"
        ));
        let scene = dir.join(format!("scalp_{strands}.toml"));
        std::fs::write(&scene, with_strands(&source, strands)?).map_err(io)?;
        let ht_stats = dir.join("hairtrace.json");
        let mut render = Command::new(hairtrace);
        render
            .arg("render")
            .arg(&scene)
            .args(["--threads", &threads, "-o"])
            .arg(dir.join("hairtrace.exr"))
            .arg("--stats")
            .arg(&ht_stats);
        let ht_peak = peak_mib(render, dir)?;
        let first_pixel = seconds(&ht_stats, "first_pixel_seconds")?;
        let frame = seconds(&ht_stats, "build_seconds")? + seconds(&ht_stats, "seconds")?;
        ctx.done();

        ctx.step(format!("scale: Cycles, {strands} strands at 1080p"));
        let peer = dir.join("peer");
        let desc = SceneDescription::from_file(&scene)?;
        export_for_peer(&desc, &peer)?;
        let cycles_stats = dir.join("cycles.json");
        let mut render = Command::new(python);
        render
            .arg(&cycles)
            .arg(peer.join("scene.json"))
            .args(["--spp", "1", "--threads", &threads, "--max-depth"])
            .arg(desc.render.path.max_depth.to_string())
            .arg("-o")
            .arg(dir.join("cycles.exr"))
            .arg("--stats")
            .arg(&cycles_stats);
        let cycles_peak = peak_mib(render, dir)?;
        let sync = seconds(&cycles_stats, "sync_seconds")?;
        let cycles_frame = sync + seconds(&cycles_stats, "render_seconds")?;
        ctx.done();
        rows.push(vec![
            strands.to_string(),
            num(first_pixel, 3),
            num(sync, 3),
            num(first_pixel / sync, 2),
            num(frame, 3),
            num(cycles_frame, 3),
            num(frame / cycles_frame, 2),
            num(ht_peak, 4),
            num(cycles_peak, 4),
            num(ht_peak / cycles_peak, 2),
        ]);
    }
    Ok(rows)
}

/// The scene file with its groom's strand count set: the benchmark's own line replaced,
/// refused if the file no longer has exactly one.
fn with_strands(source: &str, strands: usize) -> Result<String> {
    const LINE: &str = "strands = 1000000\n";
    if source.matches(LINE).count() != 1 {
        return Err(Error::InvalidArg(format!(
            "{SCENE}.toml: expected one `{}` line",
            LINE.trim()
        )));
    }
    Ok(source.replace(LINE, &format!("strands = {strands}\n")))
}

/// Runs `command` under `/usr/bin/time` and returns its peak resident memory, MiB.
fn peak_mib(command: Command, dir: &Path) -> Result<f64> {
    let file = dir.join("time.txt");
    let program = command.get_program().to_owned();
    let out = Command::new("/usr/bin/time")
        .arg("-f")
        .arg("%M")
        .arg("-o")
        .arg(&file)
        .arg(&program)
        .args(command.get_args())
        .output()
        .map_err(|e| Error::io(Path::new("/usr/bin/time (scripts/setup installs it)"), e))?;
    if !out.status.success() {
        return Err(Error::InvalidArg(format!(
            "{} failed: {}",
            Path::new(&program).display(),
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )));
    }
    let text = std::fs::read_to_string(&file).map_err(|e| Error::io(&file, e))?;
    let kib: f64 = text
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .ok_or_else(|| Error::InvalidArg(format!("{}: no peak memory", file.display())))?;
    Ok(kib / 1024.0)
}

/// A number from a stats file.
fn seconds(path: &Path, key: &str) -> Result<f64> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let json: Value = serde_json::from_str(&text)
        .map_err(|e| Error::InvalidArg(format!("{}: {e}", path.display())))?;
    json[key]
        .as_f64()
        .ok_or_else(|| Error::InvalidArg(format!("{}: no {key}", path.display())))
}
