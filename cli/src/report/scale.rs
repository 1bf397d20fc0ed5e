//! Scale section: how building and tracing grow with the strand count, per curve basis and
//! shape with and without the level of detail, where the time before the first pixel goes
//! (the library's build stages), and what each level of detail changes in the image.

use super::markdown::{figure, num, table};
use super::plots::{Labels, Series, log_log};
use super::render::{Built, REFERENCE_SEED, Variant};
use super::{Context, scene_path};
use hairtrace::description::{GroomSource, SceneDescription};
use hairtrace::embree::{CurveBasis, MemoryMonitor};
use hairtrace::image::compare;
use hairtrace::scene::{GroomShape, Stage};
use hairtrace::{Aovs, NoProgress, Result};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// A curve type: its name, basis, shape and level-of-detail tolerance (`lod_pixels`, None
/// for the setting's default; it acts on `auto` grooms only).
type CurveType = (&'static str, CurveBasis, GroomShape, Option<f32>);

/// The curve types compared: every basis at full detail (round), flat ribbons, and the
/// level of detail (`auto` at the default tolerance: at the section's 160 pixels every
/// strand of the scalp is thinner than a pixel).
const CURVES: [CurveType; 10] = [
    ("linear round", CurveBasis::Linear, GroomShape::Round, None),
    ("linear flat", CurveBasis::Linear, GroomShape::Flat, None),
    (
        "bspline round",
        CurveBasis::BSpline,
        GroomShape::Round,
        None,
    ),
    ("bspline flat", CurveBasis::BSpline, GroomShape::Flat, None),
    (
        "catmull_rom round",
        CurveBasis::CatmullRom,
        GroomShape::Round,
        None,
    ),
    ("bezier round", CurveBasis::Bezier, GroomShape::Round, None),
    ("linear lod", CurveBasis::Linear, GroomShape::Auto, None),
    ("bspline lod", CurveBasis::BSpline, GroomShape::Auto, None),
    (
        "catmull_rom lod",
        CurveBasis::CatmullRom,
        GroomShape::Auto,
        None,
    ),
    ("bezier lod", CurveBasis::Bezier, GroomShape::Auto, None),
];

/// The bases and tolerances whose bias is measured (0: flat ribbons, `auto` without a
/// level of detail), against round curves of the same basis.
const BIAS_BASES: [CurveBasis; 2] = [CurveBasis::BSpline, CurveBasis::CatmullRom];
const BIAS_TOLERANCES: [f32; 5] = [0.0, 0.02, 0.05, 0.1, 0.25];

/// Ten million strands, apart from the sweep (the groom takes a minute to make and 10 GiB
/// of memory): the default curves (B-spline `auto`, the level of detail) and round tubes.
const TEN_MILLION: [CurveType; 2] = [CURVES[7], CURVES[2]];

fn strand_counts(ctx: &Context) -> Vec<usize> {
    if ctx.quick {
        vec![1_000, 10_000]
    } else {
        vec![1_000, 10_000, 100_000, 1_000_000]
    }
}

/// One build and render of the scalp at one strand count and curve type.
struct Point {
    strands: usize,
    /// Seconds of each build stage (read or generate, curves, BVH), and the time to the
    /// first pixel: the whole build (lights and materials too) and the first render's
    /// first finished tile.
    stages: [f64; 3],
    build: f64,
    /// Seconds the first render spent building the parts its rays reached (a large groom
    /// is built in parts, each when a ray first reaches it), summed over its threads.
    parts: f64,
    /// Embree's peak allocation over the build and the first render, and the process's
    /// resident memory growth over them (the groom's own buffers included), MiB.
    embree_mib: f64,
    rss_mib: f64,
    /// Million rays traced per second, shading included, in a second render (every part
    /// it reaches built).
    mrays: f64,
}

/// The process's resident memory now, MiB (Linux; 0 elsewhere).
fn rss_mib() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            let line = s.lines().find(|l| l.starts_with("VmRSS:"))?;
            line.split_whitespace().nth(1)?.parse::<f64>().ok()
        })
        .map_or(0.0, |kib| kib / 1024.0)
}

/// The stage benchmark's scene, beside the bench scenes' folder.
pub fn scalp_path(scenes: &Path) -> PathBuf {
    scene_path(&scenes.join("../stages"), "scalp_1m")
}

/// The stage benchmark's scalp (bench/stages/scalp_1m.toml) at `strands`, one curve type.
fn scalp(
    ctx: &Context,
    strands: usize,
    (_, basis, shape, lod): CurveType,
) -> Result<SceneDescription> {
    let mut desc = SceneDescription::from_file(&scalp_path(&ctx.scenes))?;
    for g in &mut desc.grooms {
        (g.basis, g.shape) = (Some(basis), shape);
        if let GroomSource::Scalp(s) = &mut g.source {
            s.strands = strands;
        }
    }
    let r = &mut desc.render;
    (r.width, r.height, r.spp) = if ctx.quick {
        (32, 32, 1)
    } else {
        (160, 160, 4)
    };
    if let Some(lod) = lod {
        r.lod_pixels = lod;
    }
    Ok(desc)
}

fn measure(desc: &SceneDescription, strands: usize) -> Result<Point> {
    let device = Arc::new(desc.render.device()?);
    let monitor = MemoryMonitor::attach(device.clone());
    let rss = rss_mib();
    let start = Instant::now();
    let mut built = desc.build(device)?;
    let build = start.elapsed().as_secs_f64();
    let stages = Stage::ALL.map(|s| built.stages().get(s));
    let first = built.render(Aovs::default(), &NoProgress)?.stats;
    let rss_mib = rss_mib() - rss;
    let embree_mib = monitor.peak() as f64 / (1024.0 * 1024.0);
    let out = built.render(Aovs::default(), &NoProgress)?;
    Ok(Point {
        strands,
        stages,
        build: build + first.first_tile_seconds.unwrap_or(first.seconds),
        parts: first.part_build_seconds,
        embree_mib,
        rss_mib,
        mrays: out.stats.rays as f64 / out.stats.seconds / 1e6,
    })
}

pub fn steps(ctx: &Context) -> u64 {
    let ten_million = if ctx.quick { 0 } else { TEN_MILLION.len() };
    (CURVES.len() * strand_counts(ctx).len()
        + ten_million
        + BIAS_BASES.len() * (BIAS_TOLERANCES.len() + 1)) as u64
        + super::scale_cycles::steps(ctx)
}

pub fn section(ctx: &Context) -> Result<String> {
    let mut results: Vec<(&str, Vec<Point>)> = Vec::new();
    for curve in CURVES {
        let mut points = Vec::new();
        for strands in strand_counts(ctx) {
            ctx.step(format!("scale: {}, {strands} strands", curve.0));
            points.push(measure(&scalp(ctx, strands, curve)?, strands)?);
            ctx.done();
        }
        results.push((curve.0, points));
    }
    let probe = scalp(ctx, 0, CURVES[0])?;
    let caption = ctx.machine.caption(
        ctx.machine.threads,
        &format!(
            "scalp of bench/stages/scalp_1m.toml x 16 segments, rays/s at {}x{} x {} spp, seed {}",
            probe.render.width, probe.render.height, probe.render.spp, probe.render.seed
        ),
    );
    let curve = |name: String, pts: &[Point], value: &dyn Fn(&Point) -> f64| Series {
        name,
        points: pts.iter().map(|p| (p.strands as f64, value(p))).collect(),
        line: true,
    };
    // One series per curve type.
    let by_curve = |value: &dyn Fn(&Point) -> f64| -> Vec<Series> {
        (results.iter())
            .map(|(name, pts)| curve((*name).to_owned(), pts, value))
            .collect()
    };
    let plot = |file: &str, title: &str, y: &str, series: Vec<Series>| -> Result<String> {
        log_log(
            &ctx.path(file),
            &Labels {
                title,
                x: "strands",
                y,
                caption: &caption,
            },
            &series,
        )?;
        Ok(figure(file, title, &caption))
    };
    let mut figures = String::new();
    type Value = fn(&Point) -> f64;
    let per_curve: [(&str, &str, &str, Value); 3] = [
        (
            "scale_build.png",
            "Time to first pixel against strand count",
            "seconds",
            |p| p.build,
        ),
        (
            "scale_memory.png",
            "Embree memory (peak over the build and the first render)",
            "MiB",
            |p| p.embree_mib,
        ),
        ("scale_rays.png", "Rays per second", "Mrays/s", |p| p.mrays),
    ];
    for (file, title, y, value) in per_curve {
        figures += &plot(file, title, y, by_curve(&value))?;
    }
    // The stages of the round curves, each basis: where the time to first pixel goes.
    let stages = results
        .iter()
        .filter(|(name, _)| name.ends_with("round"))
        .flat_map(|(name, pts)| {
            Stage::ALL.iter().enumerate().map(move |(i, st)| {
                curve(format!("{name}: {}", st.name()), pts, &move |p: &Point| {
                    p.stages[i]
                })
            })
        })
        .collect();
    figures += &plot(
        "scale_stages.png",
        "Time to first pixel by stage",
        "seconds",
        stages,
    )?;
    let rows: Vec<Vec<String>> = results
        .iter()
        .flat_map(|(name, pts)| pts.iter().map(move |p| row(name, p)))
        .collect();
    let mut ten_million = Vec::new();
    if !ctx.quick {
        for curve in TEN_MILLION {
            ctx.step(format!("scale: {}, 10^7 strands", curve.0));
            ten_million.push(row(
                curve.0,
                &measure(&scalp(ctx, 10_000_000, curve)?, 10_000_000)?,
            ));
            ctx.done();
        }
    }
    let ten_million = if ten_million.is_empty() {
        String::new()
    } else {
        format!(
            "**Ten million strands**, the same scalp and view, the default curves and round \
             tubes (Cycles is not run at this size: its peak at 10^6 strands, below, \
             extrapolates past 50 GB):\n\n{}\n",
            table(&HEADER, &ten_million)
        )
    };
    let default_lod = hairtrace::RenderSettings::default().lod_pixels;
    Ok(format!(
        "The stage benchmark's scalp (16 segments per strand) built at each strand count \
         with each curve type, then rendered twice. Time to first pixel is the whole build \
         and the first render's first finished tile; the build's stages are the library's \
         own (generating the strands, converting them to curves, Embree's BVH build). From \
         2^20 segments a groom is built in parts, each when a ray first reaches it: `parts \
         s` is what the first render spent on them, summed over its threads. Memory: \
         Embree's own peak allocation over the build and the first render (its memory \
         monitor), and how much the process's resident memory grew (the groom's buffers \
         too; freed memory the allocator keeps makes it a lower bound after the first \
         build). Rays per second are the second render's. `lod` is the level of detail: `auto` curves with \
         `lod_pixels = {default_lod}` (the default), every strand here thinner than \
         a pixel and so traced as linear ribbons through points on its curve, or as flat \
         curves of its basis where it needs more than the budget of pieces.\n\n{}\n{ten_million}{}\n{}\n{figures}\n{}",
        table(&HEADER, &rows),
        advice(&results, ctx.machine.threads),
        super::scale_cycles::section(ctx)?,
        bias(ctx)?,
    ))
}

/// The columns of a [`row`].
const HEADER: [&str; 10] = [
    "curves",
    "strands",
    "read s",
    "curves s",
    "BVH s",
    "parts s",
    "first pixel s",
    "Embree MiB",
    "RSS growth MiB",
    "Mrays/s",
];

/// One build and render of curves `name`, as the table shows it.
fn row(name: &str, p: &Point) -> Vec<String> {
    let mut row = vec![name.to_owned(), p.strands.to_string()];
    row.extend(p.stages.iter().map(|s| num(*s, 3)));
    row.extend([
        num(p.parts, 3),
        num(p.build, 3),
        num(p.embree_mib, 3),
        num(p.rss_mib, 3),
        num(p.mrays, 3),
    ]);
    row
}

/// The scalp's strands for the bias table: enough that a pixel holds many strands, as in
/// the largest grooms, few enough for renders at many samples.
fn bias_strands(ctx: &Context) -> usize {
    if ctx.quick { 1_000 } else { 100_000 }
}

/// Each level of detail's bias: the scalp rendered at a tolerance against round curves of
/// its basis at 4x the samples with the render section's reference seed, with the noise
/// (round curves at the same samples and seed as the variants) taken out.
fn bias(ctx: &Context) -> Result<String> {
    let spp = if ctx.quick { 4 } else { 256 };
    let strands = bias_strands(ctx);
    let mut rows = Vec::new();
    for basis in BIAS_BASES {
        let name = format!("{basis:?}");
        let round = ("round", basis, GroomShape::Round, None);
        ctx.step(format!("scale: {name} round reference, {} spp", 4 * spp));
        let mut built = Built::new(&Variant {
            desc: scalp(ctx, strands, round)?,
        })?;
        let (reference, _, _) = built.render(4 * spp, REFERENCE_SEED)?;
        let (image, _, _) = built.render(spp, 1)?;
        drop(built);
        let noise = compare(&image, &reference)?.rmse;
        ctx.done();
        for lod in BIAS_TOLERANCES {
            ctx.step(format!("scale: {name} bias at {lod} px"));
            let desc = scalp(ctx, strands, ("auto", basis, GroomShape::Auto, Some(lod)))?;
            let (image, _, _) = Built::new(&Variant { desc })?.render(spp, 1)?;
            let c = compare(&image, &reference)?;
            let bias = (c.rmse * c.rmse - noise * noise).max(0.0).sqrt();
            rows.push(vec![
                name.clone(),
                if lod == 0.0 {
                    "0 (flat ribbons)".to_owned()
                } else {
                    num(f64::from(lod), 3)
                },
                num(c.rmse / noise, 3),
                num(bias / noise, 3),
                num(100.0 * (c.mean / c.reference_mean - 1.0), 2),
            ]);
            ctx.done();
        }
    }
    Ok(format!(
        "**What the level of detail changes in the image.** The scalp at {strands} strands, \
         `auto` curves at each tolerance (`lod_pixels`), {spp} spp seed 1, against round \
         curves of the same basis at {} spp with seed {REFERENCE_SEED}; the noise is the \
         round curves' own RMSE at {spp} spp seed 1 against that reference. The bias is \
         what the RMSE has beyond the noise, sqrt(RMSE^2 - noise^2).\n\n{}\n",
        4 * spp,
        table(
            &[
                "basis",
                "lod_pixels",
                "RMSE / noise",
                "bias / noise",
                "mean vs round %"
            ],
            &rows
        )
    ))
}

/// Where the time goes at the largest count, and what a user can do, from the numbers:
/// each suggestion is made only where this run measured a gain.
fn advice(results: &[(&str, Vec<Point>)], threads: usize) -> String {
    let last = |name: &str| {
        results
            .iter()
            .find(|(n, _)| *n == name)
            .and_then(|(_, p)| p.last())
    };
    let (Some(lr), Some(lf), Some(br)) = (
        last("linear round"),
        last("linear flat"),
        last("bspline round"),
    ) else {
        return String::new();
    };
    let stage_names = Stage::ALL.map(Stage::name);
    let shares: Vec<String> = stage_names
        .iter()
        .zip(br.stages)
        .map(|(n, s)| format!("{n} {}%", num(100.0 * s / br.build, 2)))
        .collect();
    let (biggest, biggest_seconds) = stage_names
        .iter()
        .zip(br.stages)
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(("", 0.0), |(n, s)| (*n, s));
    let mut text = format!(
        "**Where the time goes.** At {} strands the B-spline round scalp takes {} s to its \
         first pixel: {} (the rest is lights, materials and the first tile); the largest \
         stage is {biggest}. **What a user can do**, from these numbers:",
        br.strands,
        num(br.build, 3),
        shares.join(", "),
    );
    // A suggestion where the gain is worth it, else how small it was.
    let suggest = |gain: f64, worth: f64, yes: String, no: &str| {
        if gain > worth {
            format!("\n- {yes}")
        } else {
            format!("\n- {no} ({}x).", num(gain, 2))
        }
    };
    let build_gain = br.build / lr.build;
    text += &suggest(
        build_gain,
        1.1,
        format!(
            "`basis = \"linear\"` reaches the first pixel {}x sooner ({} s) with {} MiB of \
             Embree memory against {} MiB, where the groom has enough points that its \
             curvature within a segment does not show (the render section gives its error).",
            num(build_gain, 2),
            num(lr.build, 3),
            num(lr.embree_mib, 3),
            num(br.embree_mib, 3)
        ),
        "the basis changes the time to first pixel little here",
    );
    let trace_gain = lf.mrays / lr.mrays;
    text += &suggest(
        trace_gain,
        1.05,
        format!(
            "`shape = \"flat\"` traces {}x the rays per second of round curves ({} against \
             {} Mrays/s), for strands thinner than a pixel.",
            num(trace_gain, 2),
            num(lf.mrays, 3),
            num(lr.mrays, 3)
        ),
        "flat ribbons trace no faster than round curves here",
    );
    if let Some(bl) = last("bspline lod") {
        let (build_gain, trace_gain) = (br.build / bl.build, bl.mrays / br.mrays);
        text += &suggest(
            build_gain.max(trace_gain),
            1.05,
            format!(
                "`shape = \"auto\"` with its level of detail (the default) reaches the first \
                 pixel {}x sooner than round curves and traces {}x their rays per second \
                 ({} against {} Mrays/s), where the strands are thinner than a pixel; the \
                 bias table below gives what it changes in the image.",
                num(build_gain, 2),
                num(trace_gain, 2),
                num(bl.mrays, 3),
                num(br.mrays, 3)
            ),
            "the level of detail gains little here",
        );
    }
    if biggest == Stage::Bvh.name() && biggest_seconds > 0.5 * br.build {
        text += &format!(
            "\n- the BVH build, Embree's, runs on every thread the device has ({threads} here; \
             `--threads` or `[render] threads` sets them): a build on a machine with more \
             free cores is shorter."
        );
    }
    text + "\n\n"
}
