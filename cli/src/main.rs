//! The hairtrace command line: `render` a scene file, a .hair groom or a built-in demo;
//! `info` describes a .hair groom; `lobes` prints how a hair splits energy between its
//! lobes; `compare` measures how far a render is from a reference; `export` writes a
//! scene for a peer renderer; `report` measures speed against error and writes REPORT.md;
//! `convert` takes grooms between .hair and USD; `farm` writes render-farm jobs whose tiles
//! `assemble` puts together.

mod export;
mod farm;
mod files;
mod report;
mod settings;

use clap::{Args, Parser, Subcommand};
use export::export_for_peer;
use glam::Vec3;
use hairtrace::bsdf::{
    DEFAULT_EUMELANIN, sigma_a_from_color, sigma_a_from_melanin, sigma_a_preset,
};
use hairtrace::description::{self, GroomSource, MaterialDesc, SceneDescription, has_extension};
use hairtrace::embree::CurveBasis;
use hairtrace::farm::{self as tiles, frame_path, tile_path};
use hairtrace::formats::convert::{self, ConvertOptions, ConvertSource};
use hairtrace::formats::hair::{Thickness, info_report, read_hair_file, read_hair_tag};
use hairtrace::formats::pbrt::PbrtScene;
use hairtrace::formats::{SceneFormat, usd};
use hairtrace::image::{self, Placement, WriteOptions};
use hairtrace::render::settings::RenderSettings;
use hairtrace::render::{Aovs, Progress, RenderStats};
use hairtrace::scene::HairColor;
use hairtrace::scene::{GroomShape, Stage, StageProgress};
use hairtrace::{HairBsdf, HairParams, HuangBsdf, HuangParams};
use indicatif::{ProgressBar, ProgressStyle};
use settings::{SettingArgs, Variant};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "hairtrace",
    version,
    about = "Physically based hair and fur rendering"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file (.toml), a bare groom (.hair: automatic camera, default light
    /// and brown hair) or a built-in demo, and write the image (the extension picks the
    /// format: .exr linear float, .png/.jpg/.tif sRGB).
    Render(Box<RenderArgs>),
    /// Print the energy of the R, TT, TRT and residual lobes (averaged over the fiber's
    /// width) for a range of outgoing angles.
    Lobes(LobesArgs),
    /// Print a .hair groom's strand, point and segment counts, bounds and radius range
    /// (per BasisCurves prim for USD); for a .pbrt scene, the same per groom, its meshes,
    /// lights, camera and warnings.
    Info(InfoArgs),
    /// Write a scene (file or demo) for a peer renderer: world-space .hair grooms, OBJ
    /// meshes and scene.json, what bench/peer hands to Blender Cycles.
    Export(ExportArgs),
    /// Compare an image with a reference of the same size: RMSE, largest difference and
    /// both means over the RGB channels (one JSON line with --json).
    Compare(CompareArgs),
    /// Whether renders converge to references: each side two or more seeds of one frame;
    /// the means of square pixel blocks against the noise the seeds show (z-scores), and
    /// the frame's mean difference. Exits with 3 when the difference is beyond noise.
    Bias(BiasArgs),
    /// Measure speed against error (BSDF variants, render knobs on the bench scenes, scaling
    /// with strand count, Blender Cycles if installed, a gallery) and write REPORT.md with
    /// its PNG plots.
    Report(ReportArgs),
    /// Convert grooms between .hair and USD BasisCurves: IN is a .hair file, a USD file, or
    /// a scene file (.toml: its grooms in world space); OUT is .hair or .usda.
    Convert(ConvertArgs),
    /// List every render setting (name, values, default, doc) as a Markdown table: what a
    /// scene's [render] table, `render --NAME`/`--set NAME=VALUE` and the C ABI's
    /// `ht_settings_set` take.
    Settings,
    /// Assemble a frame from the tiles `render --tile I/N` wrote: every tile must be
    /// there, hold its window, and come from the same render (scene, settings, seed, ISA,
    /// hairtrace version, as their EXR headers say); the frame keeps that header.
    Assemble(AssembleArgs),
    /// Write a render-farm job for a scene: an Open Job Description template (what AWS
    /// Deadline Cloud and `openjd run` take) and/or a Slurm job-array script, frames x
    /// tiles rendered with the ISA pinned, then one assembly per frame (docs/farm.md).
    Farm(Box<FarmArgs>),
}

#[derive(Args)]
struct AssembleArgs {
    /// The frame to write (.exr); its tiles are beside it, as `render --tile` names them
    /// (`frame.tile-I-of-N.exr`).
    frame: PathBuf,
    /// How many tiles the frame was split into.
    #[arg(long)]
    tiles: u32,
    /// The frame number, for a FRAME with a run of # (`frame.####.exr`).
    #[arg(long = "frame")]
    frame_number: Option<u32>,
}

#[derive(Args)]
struct FarmArgs {
    /// A scene description (.toml), a pbrt-v4 scene (.pbrt) or a groom (.hair, USD), as
    /// `render` takes it (the Slurm script names it by its absolute path, the OpenJD
    /// template relative to its own folder).
    scene: Option<PathBuf>,
    /// A built-in scene instead of a file: furball (the default), furnace, scalp.
    #[arg(long, conflicts_with = "scene")]
    demo: Option<String>,
    /// The frames, F or FIRST-LAST; frame F is rendered with seed F, and an animated
    /// scene's groom files are read at it. Default: the scene's `[animation] frames`, else 1.
    #[arg(long)]
    frames: Option<String>,
    /// Tiles per frame (a grid, `render --tile`).
    #[arg(long, default_value_t = 4)]
    tiles: u32,
    /// The frames' path, with a run of # for the frame number (`shots/a/frame.####.exr`;
    /// made absolute). The tiles go beside it.
    #[arg(long, value_name = "PATTERN.exr")]
    output: PathBuf,
    /// The hairtrace binary the tasks run (a job parameter: the workers' path may differ).
    #[arg(long, default_value = "hairtrace")]
    hairtrace: String,
    /// Write the Open Job Description template (JSON) here.
    #[arg(long, value_name = "FILE.json")]
    openjd: Option<PathBuf>,
    /// Write the Slurm job script here (`bash FILE` submits it).
    #[arg(long, value_name = "FILE.sh")]
    slurm: Option<PathBuf>,
    /// The render settings every task uses, over the scene's: spp, isa and threads become
    /// the job's parameters (isa must be pinned), the others are fixed in its commands.
    #[command(flatten)]
    settings: SettingArgs,
}

#[derive(Args)]
struct ReportArgs {
    /// Tiny sizes (under a minute): checks that the report is produced, measures little.
    #[arg(long)]
    quick: bool,
    /// The folder to write REPORT.md and its plots into (created if missing).
    #[arg(short, long, default_value = "report")]
    output: PathBuf,
    /// The bench scenes (run from the repository's root, the default finds them).
    #[arg(long, default_value = "bench/scenes")]
    scenes: PathBuf,
    /// Take the peer section from an earlier `bench/peer --json FILE` run instead of
    /// running Blender Cycles.
    #[arg(long, value_name = "FILE.json")]
    peers: Option<PathBuf>,
}

#[derive(Args)]
struct ConvertArgs {
    /// IN OUT, or only OUT with --demo.
    #[arg(required = true, num_args = 1..=2, value_name = "IN OUT")]
    files: Vec<PathBuf>,
    /// A built-in scene's groom instead of a file: furball, furnace, scalp.
    #[arg(long)]
    demo: Option<String>,
    /// The curve drawn through a .hair file's points (as a scene's `basis`): linear, bezier,
    /// bspline or catmull_rom; needed for a file that does not say its own (one that
    /// `convert` did not write). From USD, linear samples cubic curves into polylines; by
    /// default every prim keeps its own basis and wrap.
    #[arg(long, value_parser = parse_basis)]
    basis: Option<CurveBasis>,
    /// Read and write .hair thickness as a radius instead of a diameter (the default).
    #[arg(long)]
    thickness_is_radius: bool,
    /// Polyline segments per curve segment when --basis linear samples cubic USD curves.
    #[arg(long, default_value_t = ConvertOptions::default().samples_per_segment)]
    samples: u32,
}

#[derive(Args)]
struct ExportArgs {
    /// A scene description (.toml).
    scene: Option<PathBuf>,
    /// A built-in scene instead of a file.
    #[arg(long, conflicts_with = "scene")]
    demo: Option<String>,
    /// The folder to write into (created if missing).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args)]
struct CompareArgs {
    image: PathBuf,
    reference: PathBuf,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct BiasArgs {
    /// Renders of the way under test, one per seed.
    #[arg(long, num_args = 2.., required = true)]
    images: Vec<PathBuf>,
    /// Renders of the reference way, one per seed (seeds none of `--images` used).
    #[arg(long, num_args = 2.., required = true)]
    references: Vec<PathBuf>,
    /// Side of a block in pixels.
    #[arg(long, default_value_t = 8)]
    block: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct RenderArgs {
    /// A scene description (.toml), a pbrt-v4 scene (.pbrt) or a groom (.hair, or USD
    /// BasisCurves: .usd, .usda, .usdc, .usdz).
    scene: Option<PathBuf>,
    /// A built-in scene instead of a file: furball (the default), furnace, scalp.
    #[arg(long, conflicts_with = "scene")]
    demo: Option<String>,
    /// Curve shape of every groom, over the scene's: auto (the default: a ribbon facing the
    /// ray where a strand is at most a pixel wide, a tube elsewhere), round or flat.
    #[arg(long, value_parser = ["auto", "round", "flat"])]
    shape: Option<String>,
    /// The curve drawn through the points of every .hair and procedural groom, over the
    /// scene's: linear, bezier, bspline or catmull_rom. A .hair file that does not say its
    /// own (only `hairtrace convert` writes it) needs one.
    #[arg(long, value_parser = parse_basis)]
    basis: Option<CurveBasis>,
    /// Also write the render's figures (seconds of path tracing, scene build seconds,
    /// seconds of each stage: read, curves, bvh, render; camera samples, rays) to this
    /// JSON file: what benchmarks read.
    #[arg(long, value_name = "FILE.json")]
    stats: Option<PathBuf>,
    /// The hair's absorption preset, for a bare .hair groom: red_brown, light_brown,
    /// dark_brown, black, white (default: brown from melanin).
    #[arg(long, value_parser = parse_preset)]
    preset: Option<[f32; 3]>,
    /// Output image.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    settings: SettingArgs,
    /// Also write these AOVs, each to OUT's name with `.albedo`, `.depth` or `.strand`
    /// before the extension: albedo (RGB), depth (camera distance), strand (strand id).
    #[arg(long, value_delimiter = ',', value_parser = ["albedo", "depth", "strand"])]
    aov: Vec<String>,
    /// One more image of the same scene, after the main one: OUT with these settings
    /// changed (spp, seed, fidelity knobs, a noise target...), e.g. `--variant
    /// 'ref.exr:spp=1024 seed=9'`. Repeatable. A variant renders from the main image's
    /// build unless it changes what the build depends on (lod_pixels, curve_parts, or a
    /// size whose pixels an `auto` groom was not shaped for): then it builds again first.
    #[arg(long, value_name = "OUT:NAME=VALUE ...", value_parser = Variant::parse)]
    variant: Vec<Variant>,
    /// Render tile I of N (from 1; a grid over the frame, the same on every machine)
    /// instead of the whole frame: -o then names the frame (.exr), and the tile goes beside
    /// it as `NAME.tile-I-of-N.exr` (an AOV's as `NAME.AOV.tile-I-of-N.exr`), for
    /// `hairtrace assemble`.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    tile: Option<(u32, u32)>,
    /// The frame number: the frame of the animation the scene's groom files are read at
    /// (USD time samples, the file of a `groom.####.hair` sequence), replacing the scene's
    /// own `[animation] frame`; it also replaces the run of # in -o (`frame.####.exr` with
    /// 7: `frame.0007.exr`) and is written into the image's header.
    #[arg(long = "frame")]
    frame_number: Option<u32>,
}

#[derive(Args)]
struct InfoArgs {
    /// The .hair, USD (.usd, .usda, .usdc, .usdz) or .pbrt file.
    file: PathBuf,
    /// Read the file's thickness as a radius instead of a diameter (the default).
    #[arg(long)]
    thickness_is_radius: bool,
}

#[derive(Args)]
struct LobesArgs {
    /// Eumelanin concentration (about 0.3 blonde, 1.3 brown, 8 black).
    #[arg(long, default_value_t = DEFAULT_EUMELANIN)]
    eumelanin: f32,
    /// Pheomelanin concentration (red).
    #[arg(long, default_value_t = 0.0)]
    pheomelanin: f32,
    /// Take sigma_a from a reflectance colour "r,g,b" instead of melanin.
    #[arg(long, value_parser = parse_list::<f32, 3>, conflicts_with_all = ["eumelanin", "pheomelanin"])]
    color: Option<[f32; 3]>,
    /// Take sigma_a from a named preset instead of melanin: red_brown, light_brown,
    /// dark_brown, black, white.
    #[arg(long, value_parser = parse_preset, conflicts_with_all = ["eumelanin", "pheomelanin", "color"])]
    preset: Option<[f32; 3]>,
    /// Longitudinal roughness, [0.01, 1].
    #[arg(long, default_value_t = HairParams::default().beta_m)]
    beta_m: f32,
    /// Azimuthal roughness, [0.01, 1].
    #[arg(long, default_value_t = HairParams::default().beta_n)]
    beta_n: f32,
    /// Cuticle tilt in degrees.
    #[arg(long, default_value_t = HairParams::default().alpha)]
    alpha: f32,
    /// Index of refraction.
    #[arg(long, default_value_t = HairParams::default().eta)]
    eta: f32,
    /// The hair model: chiang (round fibres) or huang (elliptical, GGX microfacets).
    #[arg(long, default_value = "chiang", value_parser = ["chiang", "huang"])]
    model: String,
    /// Huang's GGX roughness, [0.01, 1].
    #[arg(long, default_value_t = HuangParams::default().roughness)]
    roughness: f32,
    /// Huang's aspect (minor over major axis), [0.05, 1]; the major axis faces the viewer.
    #[arg(long, default_value_t = HuangParams::default().aspect)]
    aspect: f32,
}

/// N comma-separated values, e.g. "0.8,0.5,0.3" or "0,0,64,48".
fn parse_list<T: std::str::FromStr, const N: usize>(s: &str) -> Result<[T; N], String>
where
    T::Err: std::fmt::Display,
{
    let v: Vec<T> = s
        .split(',')
        .map(|x| x.trim().parse::<T>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    v.try_into()
        .map_err(|_| format!("{s:?}: expected {N} comma-separated numbers"))
}

/// "I/N", tile I of N.
fn parse_tile(s: &str) -> Result<(u32, u32), String> {
    let [i, n] = s
        .split_once('/')
        .map(|(i, n)| [i, n].map(|v| v.trim().parse::<u32>()))
        .ok_or_else(|| format!("{s:?}: must be I/N, tile I of N"))?;
    Ok((
        i.map_err(|e| format!("{s:?}: {e}"))?,
        n.map_err(|e| format!("{s:?}: {e}"))?,
    ))
}

fn parse_basis(name: &str) -> Result<CurveBasis, String> {
    convert::basis_named(name).map_err(|e| e.detail())
}

/// A named absorption preset's sigma_a.
fn parse_preset(name: &str) -> Result<[f32; 3], String> {
    sigma_a_preset(name).map_err(|e| e.detail())
}

fn lobes(args: &LobesArgs) -> hairtrace::Result<()> {
    let sigma_a = match (args.color, args.preset) {
        (Some(c), _) => sigma_a_from_color(c, args.beta_n)?,
        (None, Some(p)) => p,
        (None, None) => sigma_a_from_melanin(args.eumelanin, args.pheomelanin)?,
    };
    let params = HairParams {
        sigma_a,
        eta: args.eta,
        beta_m: args.beta_m,
        beta_n: args.beta_n,
        alpha: args.alpha,
    };
    if args.model == "huang" {
        return huang_lobes(args, &params);
    }
    let bsdf = HairBsdf::new(&params)?;
    println!(
        "sigma_a = ({:.4}, {:.4}, {:.4}), eta {}, beta_m {}, beta_n {}, alpha {} deg",
        sigma_a[0], sigma_a[1], sigma_a[2], params.eta, params.beta_m, params.beta_n, params.alpha
    );
    println!(
        "lobe energy (R G B), averaged over h in [-1, 1]; Mp and Np integrate to 1, so each lobe carries Ap"
    );
    println!(
        "{:>8}  {:^20}  {:^20}  {:^20}  {:^20}  {:^20}",
        "theta_o", "R", "TT", "TRT", "residual", "total"
    );
    const STEPS: usize = 1000;
    for deg in [0.0f32, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
        let t = deg.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let mut sum = [Vec3::ZERO; 4];
        // Midpoint rule over h: the offset of a ray that hits the fiber is uniform.
        for i in 0..STEPS {
            let h = -1.0 + (2 * i + 1) as f32 / STEPS as f32;
            for (s, e) in sum.iter_mut().zip(bsdf.lobe_energies(h, wo)) {
                *s += e / STEPS as f32;
            }
        }
        let total = sum.iter().copied().sum::<Vec3>();
        print_lobe_row(deg, sum, total);
    }
    Ok(())
}

/// One row of `lobes`: theta_o, the four lobes' RGB and a last RGB column.
fn print_lobe_row(deg: f32, lobes: [Vec3; 4], last: Vec3) {
    let cell = |v: Vec3| format!("{:.3} {:.3} {:.3}", v.x, v.y, v.z);
    println!(
        "{:>7}°  {:^20}  {:^20}  {:^20}  {:^20}  {:^20}",
        deg,
        cell(lobes[0]),
        cell(lobes[1]),
        cell(lobes[2]),
        cell(lobes[3]),
        cell(last)
    );
}

/// `lobes` for the Huang model: each lobe's energy before its last interface's masking
/// (an upper bound) and the albedo its sampler measures (the model's true energy), both
/// averaged over the fibre's width.
fn huang_lobes(args: &LobesArgs, chiang: &HairParams) -> hairtrace::Result<()> {
    let params = HuangParams {
        sigma_a: chiang.sigma_a,
        eta: chiang.eta,
        roughness: args.roughness,
        aspect: args.aspect,
        alpha: chiang.alpha,
    };
    let bsdf = HuangBsdf::new(&params)?;
    let s = params.sigma_a;
    println!(
        "sigma_a = ({:.4}, {:.4}, {:.4}), eta {}, roughness {}, aspect {}, alpha {} deg (Huang)",
        s[0], s[1], s[2], params.eta, params.roughness, params.aspect, params.alpha
    );
    println!(
        "lobe energy (R G B) before the last interface's masking, and the albedo sampled, averaged over h"
    );
    println!(
        "{:>8}  {:^20}  {:^20}  {:^20}  {:^20}  {:^20}",
        "theta_o", "R", "TT", "TRT", "residual", "albedo"
    );
    const STEPS: usize = 200;
    const SAMPLES: usize = 256;
    for deg in [0.0f32, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
        let t = deg.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let mut sum = [Vec3::ZERO; 4];
        let mut albedo = Vec3::ZERO;
        for i in 0..STEPS {
            let h = -1.0 + (2 * i + 1) as f32 / STEPS as f32;
            let jitter = [
                (i as f32 * 0.618_034).fract(),
                (i as f32 * 0.414_214).fract(),
            ];
            let point = bsdf.near(h, wo, glam::Vec2::X, jitter);
            for (s, e) in sum.iter_mut().zip(point.lobe_energies()) {
                *s += e / STEPS as f32;
            }
            for k in 0..SAMPLES {
                let u = [
                    (k as f32 + 0.5) / SAMPLES as f32,
                    (k as f32 * 0.754_878).fract(),
                    (k as f32 * 0.569_840).fract(),
                ];
                if let Some(x) = point.sample(u) {
                    albedo += x.f * x.wi.z.abs() / x.pdf / (STEPS * SAMPLES) as f32;
                }
            }
        }
        print_lobe_row(deg, sum, albedo);
    }
    Ok(())
}

/// A progress bar on stderr, named `prefix`, with an ETA if `eta`.
fn stage_bar(prefix: &'static str, eta: bool) -> ProgressBar {
    let template = if eta {
        "{prefix:>6} {bar:40} {percent:>3}% {elapsed_precise} eta {eta_precise} {msg}"
    } else {
        "{prefix:>6} {bar:40} {percent:>3}% {elapsed_precise} {msg}"
    };
    ProgressBar::new(STAGE_STEPS)
        .with_style(ProgressStyle::with_template(template).expect("a valid progress template"))
        .with_prefix(prefix)
}

/// Steps of a build stage's bar (its progress is a fraction).
const STAGE_STEPS: u64 = 1000;

/// One bar per build stage, each left on screen with its time when the next starts.
#[derive(Default)]
struct StageBars(std::sync::Mutex<Option<(Stage, ProgressBar)>>);

impl StageProgress for StageBars {
    fn update(&self, stage: Stage, fraction: f64) -> bool {
        let mut current = self.0.lock().unwrap_or_else(|e| e.into_inner());
        if current.as_ref().is_none_or(|(s, _)| *s != stage) {
            if let Some((_, bar)) = current.take() {
                bar.finish();
            }
            *current = Some((stage, stage_bar(stage.name(), false)));
        }
        if let Some((_, bar)) = current.as_ref() {
            bar.set_position((fraction * STAGE_STEPS as f64).round() as u64);
        }
        true
    }
}

impl StageBars {
    /// Leaves the last stage's bar on screen.
    fn finish(&self) {
        if let Some((_, bar)) = self.0.lock().unwrap_or_else(|e| e.into_inner()).take() {
            bar.finish();
        }
    }
}

/// The render's progress bar.
struct Bar(ProgressBar);

impl Progress for Bar {
    fn update(&self, done: u64, total: u64) -> bool {
        // OpenImageIO loads beside the render once its threads run, unless it started
        // with a groom's read (`render`): loading holds the loader's lock, which starting
        // a thread also takes, so opened during the build it stalled the build's thread
        // pools (docs/measurements.md, "Start-up").
        hairtrace::image::preload_shim();
        self.0.set_length(total);
        self.0.set_position(done);
        true
    }

    fn pass(&self, samples_per_pixel: u32, noise: Option<f32>) {
        self.0.set_message(match noise {
            Some(n) => format!("{samples_per_pixel} spp, noise {:.2}%", 100.0 * n),
            None => format!("{samples_per_pixel} spp"),
        });
    }
}

/// The scene a command names: a scene file, a bare .hair groom or a demo (by default
/// the fur ball).
fn load_scene(scene: Option<&PathBuf>, demo: Option<&str>) -> hairtrace::Result<SceneDescription> {
    let Some(path) = scene else {
        return description::demo(demo.unwrap_or("furball"));
    };
    let description = SceneDescription::load(path)?;
    for note in &description.notes {
        eprintln!("hairtrace: warning: {note}");
    }
    Ok(description)
}

fn export(args: &ExportArgs) -> hairtrace::Result<()> {
    let description = load_scene(args.scene.as_ref(), args.demo.as_deref())?;
    export_for_peer(&description, &args.output)
}

/// What the header calls a scene: a file by its name (the same on every machine of a farm,
/// wherever its folder is mounted), a demo as `demo:NAME`.
fn scene_label(scene: Option<&PathBuf>, demo: Option<&str>) -> String {
    match scene {
        Some(path) => path
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned(),
        None => format!("demo:{}", demo.unwrap_or("furball")),
    }
}

/// `-o` with its run of # replaced by the frame number, if one is given.
fn numbered(output: &Path, frame: Option<u32>) -> hairtrace::Result<PathBuf> {
    frame.map_or_else(|| Ok(output.to_path_buf()), |f| frame_path(output, f))
}

impl RenderArgs {
    /// Where an image of the frame goes: the image itself, or its tile.
    fn placed(&self, image: PathBuf) -> PathBuf {
        match self.tile {
            Some((i, n)) => tile_path(&image, i, n),
            None => image,
        }
    }

    /// The frame `output` names (its run of # filled), refused now, before minutes of
    /// work, when the writer would not take it or its tile.
    fn checked_frame(&self, output: &Path) -> hairtrace::Result<PathBuf> {
        let frame = numbered(output, self.frame_number)?;
        if self.tile.is_some() && !has_extension(&frame, "exr") {
            return Err(hairtrace::Error::InvalidArg(format!(
                "--tile: {} must be an .exr (float pixels, and the header assemble checks)",
                frame.display()
            )));
        }
        image::check_output_path(&self.placed(frame.clone()))?;
        Ok(frame)
    }
}

fn render(args: &RenderArgs) -> hairtrace::Result<()> {
    let frame = args.checked_frame(&args.output)?;
    let mut description = load_scene(args.scene.as_ref(), args.demo.as_deref())?;
    if let Some(f) = args.frame_number {
        description.at_frame(f64::from(f))?;
    }
    if let Some(sigma_a) = args.preset {
        if !args
            .scene
            .as_ref()
            .is_some_and(|p| has_extension(p, "hair"))
        {
            return Err(hairtrace::Error::InvalidArg(
                "--preset is for a bare .hair groom; a scene file names it in its \
                 [materials.NAME] (preset = \"...\")"
                    .into(),
            ));
        }
        for m in description.materials.values_mut() {
            if let MaterialDesc::Hair(h) = m {
                h.color = HairColor::SigmaA(sigma_a);
            }
        }
    }
    if let Some(basis) = args.basis {
        for g in &mut description.grooms {
            match &g.source {
                GroomSource::File { path, .. } if usd::is_usd_path(path) => {
                    return Err(hairtrace::Error::InvalidArg(format!(
                        "--basis: {} is USD, whose prims each say their own",
                        path.display()
                    )));
                }
                GroomSource::ControlPoints { .. } => {}
                _ => g.basis = Some(basis),
            }
        }
    }
    if let Some(shape) = &args.shape {
        let shape = match shape.as_str() {
            "round" => GroomShape::Round,
            "flat" => GroomShape::Flat,
            _ => GroomShape::Auto,
        };
        for g in &mut description.grooms {
            g.shape = shape;
        }
    }
    // Overrides go into the description, so that the camera's aspect follows the size.
    args.settings.apply(&mut description.render)?;
    if let Some((i, n)) = args.tile {
        let r = &mut description.render;
        if r.crop.is_some() {
            return Err(hairtrace::Error::InvalidArg(
                "--tile and crop both choose the pixels to render: give one".into(),
            ));
        }
        r.crop = Some(tiles::tile_window(r.width, r.height, i, n)?);
    }
    // Every variant is checked before the build, so that a typo does not wait for it.
    let mut renders = vec![(frame.clone(), description.render)];
    for v in &args.variant {
        renders.push((
            args.checked_frame(&v.output)?,
            v.settings(&description.render)?,
        ));
    }
    let build_start = std::time::Instant::now();
    let device = Arc::new(description.render.device()?);
    // A groom read from a file keeps the main thread busy alone for a while: OpenImageIO
    // loads beside that read (otherwise once the render's threads run, `Bar::update`).
    // After the device: Embree's start loads libraries of its own, which would wait.
    let reads_files =
        (description.grooms.iter()).any(|g| matches!(g.source, GroomSource::File { .. }));
    if reads_files {
        hairtrace::image::preload_shim();
    }
    let bars = StageBars::default();
    let mut built = description.build_with(device, &bars)?;
    bars.finish();
    let build_seconds = build_start.elapsed().as_secs_f64();
    let label = scene_label(args.scene.as_ref(), args.demo.as_deref());
    for (i, (frame, settings)) in renders.iter().enumerate() {
        let s = render_frame(args, &mut built, settings, frame, &label)?;
        // The figures of the first render: what benchmarks read.
        if let (0, Some(path)) = (i, &args.stats) {
            let json = serde_json::json!({
                "seconds": s.seconds,
                "build_seconds": build_seconds,
                // The build, then the render's first finished tile.
                "first_pixel_seconds": s.first_tile_seconds.map(|t| build_seconds + t),
                "parts_built": s.parts_built,
                "part_build_seconds": s.part_build_seconds,
                "stage_seconds": Stage::ALL
                    .iter()
                    .map(|&st| (st.name().to_owned(), built.stages().get(st).into()))
                    .chain([("render".to_owned(), s.seconds.into())])
                    .collect::<serde_json::Map<_, _>>(),
                "samples": s.samples,
                "rays": s.rays,
                "spp": s.spp,
                "noise": s.noise,
                "threads": settings.threads.unwrap_or_else(rayon::current_num_threads),
            });
            files::write_file(path, format!("{json}\n"))?;
        }
    }
    Ok(())
}

/// Renders one image of the built world with `settings` and writes it (its tile, with
/// `--tile`) and its AOVs to `frame`'s names, with the render's header.
fn render_frame(
    args: &RenderArgs,
    built: &mut hairtrace::Scene,
    settings: &RenderSettings,
    frame: &Path,
    label: &str,
) -> hairtrace::Result<RenderStats> {
    let output = args.placed(frame.to_path_buf());
    let bar = stage_bar("render", true);
    let wants = |name: &str| args.aov.iter().any(|a| a == name);
    let aovs = Aovs {
        albedo: wants("albedo"),
        depth: wants("depth"),
        strand_id: wants("strand"),
    };
    let aov_paths: Vec<(PathBuf, &str)> = args
        .aov
        .iter()
        .map(|a| (args.placed(tiles::tagged_path(frame, a)), a.as_str()))
        .collect();
    for (path, _) in &aov_paths {
        image::check_output_path(path)?;
    }
    let out = built.render_with(settings, aovs, &Bar(bar.clone()))?;
    bar.finish_and_clear();
    let window = out.film.crop();
    let mut attributes = tiles::header(settings, label);
    if let Some((i, n)) = args.tile {
        attributes.push((format!("{}tile", tiles::PREFIX), format!("{i}/{n}")));
    }
    if let Some(f) = args.frame_number {
        attributes.push((format!("{}frame", tiles::PREFIX), f.to_string()));
    }
    let opts = WriteOptions {
        placement: Some(Placement {
            x: window.x0 as usize,
            y: window.y0 as usize,
            full_width: settings.width as usize,
            full_height: settings.height as usize,
        }),
        attributes,
        ..WriteOptions::default()
    };
    let write = |path: &PathBuf, channels: usize, pixels: &[f32]| {
        let (w, h) = (window.width() as usize, window.height() as usize);
        image::write_image(path, w, h, channels, pixels, &opts)
    };
    // The AOVs first: an image at `output` means that its render finished.
    for (path, name) in &aov_paths {
        let (channels, pixels) = match *name {
            "albedo" => (3, out.film.albedo()),
            "depth" => (1, out.film.depth()),
            _ => (1, out.film.strand_id()),
        };
        write(
            path,
            channels,
            pixels.expect("the film keeps every AOV asked for"),
        )?;
    }
    write(&output, 3, out.film.rgb())?;
    let s = out.stats;
    let noise = s
        .noise
        .map_or(String::new(), |n| format!(", noise {:.2}%", 100.0 * n));
    eprintln!(
        "{}: {}x{} at {} spp{noise} in {:.2} s, {:.3} Msamples/s, {:.2} Mrays/s, peak memory {}",
        output.display(),
        window.width(),
        window.height(),
        s.spp,
        s.seconds,
        s.samples as f64 / s.seconds / 1e6,
        s.rays as f64 / s.seconds / 1e6,
        peak_memory()
    );
    if out.film.rejected_samples() > 0 {
        eprintln!(
            "warning: {} samples were not finite and were dropped",
            out.film.rejected_samples()
        );
    }
    Ok(s)
}

/// The process's peak resident memory, from Linux's /proc ("unknown" elsewhere).
fn peak_memory() -> String {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .map(|l| l[6..].trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

fn info(args: &InfoArgs) -> hairtrace::Result<()> {
    match SceneFormat::of(&args.file)? {
        SceneFormat::Pbrt => {
            print!("{}", PbrtScene::from_file(&args.file)?.info_report());
            return Ok(());
        }
        SceneFormat::Usd => {
            print!("{}", usd::info_report(&usd::read_usd_file(&args.file)?));
            return Ok(());
        }
        SceneFormat::Toml => {
            return Err(hairtrace::Error::InvalidArg(format!(
                "{}: a TOML scene: `info` describes .hair, USD and pbrt files",
                args.file.display()
            )));
        }
        SceneFormat::Hair => {}
    }
    let thickness = if args.thickness_is_radius {
        Thickness::Radius
    } else {
        Thickness::Diameter
    };
    let strands = read_hair_file(&args.file, thickness)?;
    print!("{}", info_report(&strands));
    match read_hair_tag(&args.file)? {
        Some(tag) => {
            let (kind, basis, wrap) = tag.layout.tokens();
            println!("curves:   {kind} {basis} {wrap}, {}", tag.units.describe());
        }
        None => println!("curves:   not said: render and convert it with --basis"),
    }
    Ok(())
}

fn convert_groom(args: &ConvertArgs) -> hairtrace::Result<()> {
    let (source, output) = match (&args.demo, args.files.as_slice()) {
        (Some(name), [out]) => (ConvertSource::Demo(name), out),
        (None, [input, out]) => (ConvertSource::File(input), out),
        (Some(_), _) => {
            return Err(hairtrace::Error::InvalidArg(
                "with --demo, give only OUT".into(),
            ));
        }
        (None, _) => {
            return Err(hairtrace::Error::InvalidArg(
                "give IN and OUT (or --demo NAME and OUT)".into(),
            ));
        }
    };
    let opts = ConvertOptions {
        basis: args.basis,
        thickness: if args.thickness_is_radius {
            Thickness::Radius
        } else {
            Thickness::Diameter
        },
        samples_per_segment: args.samples,
    };
    let spinner =
        ProgressBar::new_spinner().with_message(format!("converting to {}", output.display()));
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    let result = convert::convert(source, output, &opts);
    spinner.finish_and_clear();
    let done = result?;
    for note in &done.notes {
        eprintln!("hairtrace: note: {note}");
    }
    eprintln!(
        "{}: {} strands, {} points from {} groom{}",
        output.display(),
        done.strands,
        done.points,
        done.prims,
        if done.prims == 1 { "" } else { "s" }
    );
    Ok(())
}

fn assemble(args: &AssembleArgs) -> hairtrace::Result<()> {
    let frame = numbered(&args.frame, args.frame_number)?;
    let done = tiles::assemble(&frame, args.tiles)?;
    eprintln!(
        "{}: {} tiles assembled into the {}x{} frame",
        frame.display(),
        done.tiles,
        done.width,
        done.height
    );
    Ok(())
}

fn farm_job(args: &FarmArgs) -> hairtrace::Result<()> {
    let mut description = load_scene(args.scene.as_ref(), args.demo.as_deref())?;
    args.settings.apply(&mut description.render)?;
    let scene = match (&args.scene, &args.demo) {
        (Some(path), _) => {
            farm::Scene::File(std::path::absolute(path).map_err(|e| hairtrace::Error::io(path, e))?)
        }
        (None, demo) => farm::Scene::Demo(demo.clone().unwrap_or_else(|| "furball".into())),
    };
    let output =
        std::path::absolute(&args.output).map_err(|e| hairtrace::Error::io(&args.output, e))?;
    let frames = match (&args.frames, description.frames) {
        (Some(frames), _) => frames.clone(),
        (None, Some((first, last))) => format!("{first}-{last}"),
        (None, None) => "1".into(),
    };
    // The shot's own frames refuse one outside them here, before anything is submitted.
    let (first, last) = farm::parse_frames(&frames)?;
    for f in [first, last] {
        description.clone().at_frame(f64::from(f))?;
    }
    let job = farm::Job::new(
        scene,
        &description.render,
        &args.settings,
        &frames,
        args.tiles,
        output,
        args.hairtrace.clone(),
    )?;
    if args.openjd.is_none() && args.slurm.is_none() {
        return Err(hairtrace::Error::InvalidArg(
            "farm: name the job to write: --openjd FILE.json and/or --slurm FILE.sh".into(),
        ));
    }
    if let Some(path) = &args.openjd {
        let folder = std::path::absolute(path).map_err(|e| hairtrace::Error::io(path, e))?;
        let folder = folder.parent().unwrap_or(Path::new("/"));
        let (template, undefaulted) = job.openjd(folder);
        files::write_file(path, template)?;
        eprintln!(
            "{}: Open Job Description template ({})",
            path.display(),
            job.summary()
        );
        for name in undefaulted {
            eprintln!(
                "hairtrace: note: {name} has no default (Open Job Description takes only \
                 paths inside the template's folder): give it at submission, -p {name}=PATH"
            );
        }
    }
    if let Some(path) = &args.slurm {
        files::write_file(path, job.slurm())?;
        eprintln!(
            "{}: Slurm job script, `bash {}` submits it ({})",
            path.display(),
            path.display(),
            job.summary()
        );
    }
    Ok(())
}

fn compare(args: &CompareArgs) -> hairtrace::Result<()> {
    let c = image::compare(
        &image::read_image(&args.image)?,
        &image::read_image(&args.reference)?,
    )?;
    if args.json {
        let json = serde_json::json!({
            "rmse": c.rmse,
            "max_abs": c.max_abs,
            "mean": c.mean,
            "reference_mean": c.reference_mean,
        });
        println!("{json}");
    } else {
        println!(
            "RMSE {:.6}, max |difference| {:.6}, mean {:.6} (reference {:.6})",
            c.rmse, c.max_abs, c.mean, c.reference_mean
        );
    }
    Ok(())
}

/// `Ok(true)` when the images are within noise of the references.
fn bias(args: &BiasArgs) -> hairtrace::Result<bool> {
    let read = |paths: &[PathBuf]| {
        paths
            .iter()
            .map(|p| image::read_image(p))
            .collect::<hairtrace::Result<Vec<_>>>()
    };
    let b = image::block_bias(&read(&args.images)?, &read(&args.references)?, args.block)?;
    if args.json {
        let json = serde_json::json!({
            "block": b.block,
            "blocks": b.blocks,
            "z_mean": b.z_mean,
            "z_rms": b.z_rms,
            "z_max": b.z_max,
            "worst_block": [b.worst.0, b.worst.1],
            "over_two": b.over_two,
            "noise_calibration": b.noise_calibration,
            "mean_difference": b.mean_difference,
            "mean_difference_sigma": b.mean_difference_sigma,
            "within_noise": b.within_noise(),
        });
        println!("{json}");
    } else {
        println!(
            "{} blocks of {}x{}: z mean {:+.3}, rms {:.3}, max {:.2} (the block at {}, {}), \
             {:.1}% over 2 (noise alone: 4.6%); frame mean {:+.3}% +- {:.3}%; {}",
            b.blocks,
            b.block,
            b.block,
            b.z_mean,
            b.z_rms,
            b.z_max,
            b.worst.0,
            b.worst.1,
            100.0 * b.over_two,
            100.0 * b.mean_difference,
            100.0 * b.mean_difference_sigma,
            if b.within_noise() {
                "within noise"
            } else {
                "BEYOND NOISE"
            }
        );
    }
    Ok(b.within_noise())
}

fn main() -> ExitCode {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`hairtrace lobes | head`) would
    // panic; a command-line tool ends quietly there instead, as other Unix tools do.
    // SAFETY: signal() with SIG_DFL has no preconditions, and no other thread runs yet.
    unsafe { libc::signal(libc::SIGPIPE, libc::SIG_DFL) };
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help and version go to stdout as clap writes them.
        Err(e) if !e.use_stderr() => e.exit(),
        // Usage errors in one line, like every other error.
        Err(e) => {
            let text = e.render().to_string();
            let lines: Vec<&str> = text
                .lines()
                .map(str::trim)
                .filter(|l| {
                    !l.is_empty()
                        && !l.starts_with("For more information")
                        && !l.starts_with("Usage:")
                })
                .collect();
            eprintln!(
                "hairtrace: {} (see --help)",
                lines.join(" ").trim_start_matches("error: ")
            );
            return ExitCode::from(2);
        }
    };
    let result = match &cli.command {
        Command::Render(a) => render(a),
        Command::Lobes(a) => lobes(a),
        Command::Info(a) => info(a),
        Command::Compare(a) => compare(a),
        Command::Bias(a) => match bias(a) {
            Ok(false) => return ExitCode::from(3),
            other => other.map(|_| ()),
        },
        Command::Export(a) => export(a),
        Command::Report(a) => report::run(&report::ReportOptions {
            quick: a.quick,
            output: a.output.clone(),
            scenes: a.scenes.clone(),
            peers: a.peers.clone(),
        }),
        Command::Convert(a) => convert_groom(a),
        Command::Settings => {
            print!("{}", settings::markdown());
            Ok(())
        }
        Command::Assemble(a) => assemble(a),
        Command::Farm(a) => farm_job(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hairtrace: {e}");
            ExitCode::FAILURE
        }
    }
}
