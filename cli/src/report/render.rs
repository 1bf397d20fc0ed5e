//! Render section: each fidelity or sampling knob on each bench scene, as RMSE against a
//! long reference render versus path-tracing seconds, at a few sample counts (an
//! equal-time convergence curve per knob). A knob is one line of [`KNOBS`].

use super::markdown::{figure, num, table};
use super::plots::{Labels, Series, log_log};
use super::{Context, all_scene_names, bench_scene, median};
use hairtrace::description::{GroomSource, MaterialDesc, SceneDescription};
use hairtrace::embree::CurveBasis;
use hairtrace::image::{Image, compare};
use hairtrace::render::settings::Filter;
use hairtrace::scene::{GroomShape, HairModel};
use hairtrace::{Aovs, Error, NoProgress, Result};
use std::sync::Arc;

/// What a knob changes: the scene description.
#[derive(Clone, PartialEq)]
pub struct Variant {
    pub desc: SceneDescription,
}

/// A named change to the reference settings. An edit that fails means the knob does not
/// apply to this build or scene; the report says so and goes on.
struct Knob {
    name: &'static str,
    edit: fn(&mut Variant) -> Result<()>,
}

const fn knob(name: &'static str, edit: fn(&mut Variant) -> Result<()>) -> Knob {
    Knob { name, edit }
}

/// The knobs measured, against the reference settings (the scene as written with a
/// one-pixel box filter and MIS). The first is the reference settings themselves.
const KNOBS: &[Knob] = &[
    knob("reference settings", |_| Ok(())),
    knob("shape flat", |v| set_shape(v, GroomShape::Flat)),
    knob("shape auto", |v| set_shape(v, GroomShape::Auto)),
    knob("basis linear", |v| set_basis(v, CurveBasis::Linear)),
    knob("basis bspline", |v| set_basis(v, CurveBasis::BSpline)),
    knob("strategy light", |v| set(v, "strategy", "light")),
    knob("strategy bsdf", |v| set(v, "strategy", "bsdf")),
    knob("rr_depth 1", |v| set(v, "rr_depth", "1")),
    knob("rr_depth 8", |v| set(v, "rr_depth", "8")),
    knob("roulette throughput", |v| set(v, "roulette", "throughput")),
    knob("roulette_scale off", |v| set(v, "roulette_scale", "off")),
    knob("max_depth 16", |v| set(v, "max_depth", "16")),
    knob("max_depth 4", |v| set(v, "max_depth", "4")),
    knob("filter tent", |v| set(v, "filter", "tent")),
    knob("deep_bounce_depth 1", |v| {
        set_chiang(v, "deep_bounce_depth", "1")
    }),
    knob("deep_bounce_depth 2", |v| {
        set_chiang(v, "deep_bounce_depth", "2")
    }),
    knob("deep_bounce_depth 4", |v| {
        set_chiang(v, "deep_bounce_depth", "4")
    }),
    knob("lobe_cull 0.01", |v| set_chiang(v, "lobe_cull", "0.01")),
    knob("lobe_cull 0.1", |v| set_chiang(v, "lobe_cull", "0.1")),
    knob("light_threshold 0", |v| set(v, "light_threshold", "0")),
    knob("light_offsets hit", |v| {
        set_chiang(v, "light_offsets", "hit")
    }),
    knob("allocation uniform", |v| set(v, "allocation", "uniform")),
    knob("noise_target 0.05", |v| set(v, "noise_target", "0.05")),
];

/// A render setting, by name.
fn set(v: &mut Variant, key: &str, value: &str) -> Result<()> {
    v.desc.render.set(key, value)
}

/// A render setting only the Chiang model reads (lobe culling, the merged lobe, light
/// offsets across the fibre): on a scene whose hair is all Huang it would change nothing.
fn set_chiang(v: &mut Variant, key: &str, value: &str) -> Result<()> {
    if !hair_models(&v.desc).contains(&HairModel::Chiang) {
        return Err(Error::InvalidArg("the Huang model does not read it".into()));
    }
    set(v, key, value)
}

/// The hair models of a scene's materials, each once.
fn hair_models(desc: &SceneDescription) -> Vec<HairModel> {
    let mut models = Vec::new();
    for m in desc.materials.values() {
        match m {
            MaterialDesc::Hair(h) if !models.contains(&h.model) => models.push(h.model),
            _ => {}
        }
    }
    models
}

/// What a scene's heading says of its hair: "Chiang model", "Huang model, aspect 0.65".
fn model_names(desc: &SceneDescription) -> String {
    let names: Vec<String> = (hair_models(desc).into_iter())
        .map(|m| match m {
            HairModel::Chiang => "Chiang model".to_owned(),
            HairModel::Huang { roughness, aspect } => {
                format!("Huang model, roughness {roughness}, aspect {aspect}")
            }
        })
        .collect();
    names.join("; ")
}

fn set_shape(v: &mut Variant, shape: GroomShape) -> Result<()> {
    v.desc.grooms.iter_mut().for_each(|g| g.shape = shape);
    Ok(())
}

fn set_basis(v: &mut Variant, basis: CurveBasis) -> Result<()> {
    v.desc.grooms.iter_mut().for_each(|g| g.basis = Some(basis));
    Ok(())
}

/// The seed of every reference: no timed render uses it (a render sharing the
/// reference's seed shares its first samples and looks too good).
pub const REFERENCE_SEED: u64 = 1_000_003;

/// Sizes of one run: the sample counts of each curve and the reference's.
struct Plan {
    /// Fractions of the scene's spp rendered per knob, each with its own seed.
    spp: Vec<u32>,
    reference_spp: u32,
}

fn plan(ctx: &Context, desc: &SceneDescription) -> Plan {
    let spp = desc.render.spp.max(4);
    Plan {
        spp: if ctx.quick {
            vec![1, 2, 4]
        } else {
            vec![spp / 4, spp / 2, spp]
        },
        reference_spp: if ctx.quick { 64 } else { 8 * spp },
    }
}

/// The bench scenes: every `*.toml` of the scenes folder (quick: the fur ball under a
/// uniform sky, the one under an HDR map and a small key light, where next-event
/// estimation matters, and the fur ball in the Huang model, round and elliptical).
pub fn scene_names(ctx: &Context) -> Result<Vec<String>> {
    if ctx.quick {
        return Ok(QUICK_SCENES.map(String::from).to_vec());
    }
    let mut names = all_scene_names(ctx)?;
    // The real grooms (made on demand by bench/real_grooms.py) have a section of their own.
    names.retain(|name| !name.starts_with("real_"));
    Ok(names)
}

/// The scenes of a quick run.
pub const QUICK_SCENES: [&str; 4] = [
    "fur_ball",
    "hdr_fur_ball",
    "huang_fur_ball",
    "huang_oval_fur_ball",
];

/// A bench scene with the reference settings; quick: a tenth of the strands at a quarter
/// of the size.
fn reference_variant(ctx: &Context, name: &str) -> Result<Variant> {
    let mut desc = bench_scene(ctx, name)?;
    // Round tubes, the exact shape, whatever the scene's default: the shape knobs are
    // measured against them.
    desc.grooms
        .iter_mut()
        .for_each(|g| g.shape = GroomShape::Round);
    desc.render.filter = Filter::Box;
    if ctx.quick {
        desc.render.width = (desc.render.width / 4).max(16);
        desc.render.height = (desc.render.height / 4).max(16);
        fewer_strands(&mut desc, 10);
    }
    Ok(Variant { desc })
}

/// Divides the strand count of every procedural groom by `factor` (quick runs).
pub fn fewer_strands(desc: &mut SceneDescription, factor: usize) {
    for g in &mut desc.grooms {
        match &mut g.source {
            GroomSource::FurBall(f) => f.strands = (f.strands / factor).max(100),
            GroomSource::Scalp(s) => s.strands = (s.strands / factor).max(100),
            _ => {}
        }
    }
}

/// A built variant, ready to render at any spp and seed.
pub struct Built(hairtrace::Scene);

impl Built {
    pub fn new(v: &Variant) -> Result<Built> {
        let device = Arc::new(v.desc.render.device()?);
        Ok(Built(v.desc.build(device)?))
    }

    /// The image (RGB, linear) and the path-tracing seconds and rays per camera sample.
    pub fn render(&mut self, spp: u32, seed: u64) -> Result<(Image, f64, f64)> {
        self.0.settings.spp = spp;
        self.0.settings.seed = seed;
        let out = self.0.render(Aovs::default(), &NoProgress)?;
        let window = out.film.crop();
        let image = Image::new(
            window.width() as usize,
            window.height() as usize,
            3,
            out.film.rgb().to_vec(),
        );
        let s = out.stats;
        Ok((image, s.seconds, s.rays as f64 / s.samples.max(1) as f64))
    }
}

/// One knob's runs at one sample count: their seconds, and the error and rays per sample
/// of the first (the same in every run).
struct Runs {
    spp: u32,
    seconds: Vec<f64>,
    rmse: f64,
    rays: f64,
}

/// One knob's measurements on one scene.
struct Curve {
    name: &'static str,
    /// (spp, seconds, RMSE, rays per sample) per sample count.
    points: Vec<(u32, f64, f64, f64)>,
}

/// The reference is a render of the reference settings too, so its own noise adds to
/// every measured mean square error: the reference settings' MSE at n spp times
/// n / reference_spp. The first curve (the reference settings) measures
/// MSE(n) (1 + n / reference_spp) at its last point, which gives that term; it is taken out
/// of every point, as bench/peer.py does.
fn remove_reference_noise(curves: &mut [Curve], reference_spp: u32) {
    let Some(&(n, _, rmse, _)) = curves.first().and_then(|c| c.points.last()) else {
        return;
    };
    let ratio = f64::from(n) / f64::from(reference_spp);
    let reference_mse = rmse * rmse * ratio / (1.0 + ratio);
    for p in curves.iter_mut().flat_map(|c| c.points.iter_mut()) {
        p.2 = (p.2 * p.2 - reference_mse).max(0.0).sqrt();
    }
}

/// Timed runs of each knob at each sample count, taken knob after knob in turn so that
/// the machine's drift falls on every knob alike; the table and plot give their median.
fn rounds(ctx: &Context) -> usize {
    if ctx.quick { 1 } else { 3 }
}

pub fn steps(ctx: &Context) -> u64 {
    let scenes = scene_names(ctx).map_or(1, |s| s.len() as u64);
    scenes * (KNOBS.len() * rounds(ctx) + 1) as u64
}

pub fn section(ctx: &Context) -> Result<String> {
    let mut text = format!(
        "Each knob changes one setting of the reference settings (the bench scene as \
         written, a one-pixel box filter, MIS) and renders the scene at three sample counts \
         (seeds 1, 2, 3). Its error is the RMSE over the RGB channels against a render of \
         the reference settings at 8x the scene's samples with a seed no timed render uses, \
         with the reference's own noise (estimated from the reference settings' renders) \
         taken out. Its time is the path tracing alone (the scene build is in the scale \
         section), the median of {} runs taken knob after knob in turn. A knob that \
         changes the image (shape, basis, max depth, filter, the hair fidelity knobs \
         `deep_bounce_depth` and `lobe_cull`) shows its bias as a floor its curve cannot go \
         below; one that only changes noise moves \
         its curve sideways. The tent filter's floor is partly the blur it adds by design, \
         not error. Efficiency is 1 / (RMSE^2 x seconds) at the scene's spp, relative to \
         the reference settings'. Each scene names its hair model (Chiang's round fibres, \
         or Huang's elliptical ones: the `huang_` scenes); the Huang model reads neither \
         `deep_bounce_depth`, `lobe_cull` nor `light_offsets`, so those knobs are not \
         measured on its scenes.\n\n",
        rounds(ctx)
    );
    for name in scene_names(ctx)? {
        text += &scene_section(ctx, &name)?;
    }
    Ok(text)
}

fn scene_section(ctx: &Context, name: &str) -> Result<String> {
    let base = reference_variant(ctx, name)?;
    let plan = plan(ctx, &base.desc);
    ctx.step(format!("{name}: reference, {} spp", plan.reference_spp));
    let (reference, reference_seconds, _) =
        Built::new(&base)?.render(plan.reference_spp, REFERENCE_SEED)?;
    ctx.done();
    let rounds = rounds(ctx);
    let mut built = Vec::new();
    let mut skipped = Vec::new();
    for knob in KNOBS {
        ctx.step(format!("{name}: {}, building", knob.name));
        let mut v = base.clone();
        match (knob.edit)(&mut v) {
            Err(e) => skipped.push(format!("`{}` (not applicable: {})", knob.name, e.detail())),
            Ok(()) if v == base && !built.is_empty() => {
                skipped.push(format!("`{}` (the scene's own setting)", knob.name));
            }
            Ok(()) => {
                built.push((knob.name, Built::new(&v)?));
                continue;
            }
        }
        (0..rounds).for_each(|_| ctx.done());
    }
    // Round 0 measures each point's error too: a seed gives the same image every round.
    let mut measured: Vec<Vec<Runs>> = (0..built.len()).map(|_| Vec::new()).collect();
    for round in 0..rounds {
        for ((knob, b), points) in built.iter_mut().zip(&mut measured) {
            ctx.step(format!("{name}: {knob}, run {}/{rounds}", round + 1));
            for (i, (seed, &spp)) in (1..).zip(&plan.spp).enumerate() {
                let (image, seconds, rays) = b.render(spp, seed)?;
                if round == 0 {
                    let rmse = compare(&image, &reference)?.rmse;
                    points.push(Runs {
                        spp,
                        seconds: vec![seconds],
                        rmse,
                        rays,
                    });
                } else {
                    points[i].seconds.push(seconds);
                }
            }
            ctx.done();
        }
    }
    let mut curves: Vec<Curve> = (built.iter().zip(measured))
        .map(|((knob, _), points)| Curve {
            name: knob,
            points: (points.into_iter())
                .map(|r| (r.spp, median(r.seconds), r.rmse, r.rays))
                .collect(),
        })
        .collect();
    drop(built);
    remove_reference_noise(&mut curves, plan.reference_spp);
    let r = &base.desc.render;
    let caption = ctx.machine.caption(
        ctx.machine.threads,
        &format!(
            "{name}, {}x{}, {:?} spp (seeds 1..{}), reference {} spp seed {REFERENCE_SEED}",
            r.width,
            r.height,
            plan.spp,
            plan.spp.len(),
            plan.reference_spp
        ),
    );
    let file = format!("render_{name}.png");
    let series: Vec<Series> = curves
        .iter()
        .map(|c| Series {
            name: c.name.to_owned(),
            points: c.points.iter().map(|p| (p.1, p.2)).collect(),
            line: true,
        })
        .collect();
    log_log(
        &ctx.path(&file),
        &Labels {
            title: &format!("{name}: RMSE against path-tracing time"),
            x: "seconds",
            y: "RMSE",
            caption: &caption,
        },
        &series,
    )?;
    let efficiency = |p: &(u32, f64, f64, f64)| 1.0 / (p.2 * p.2 * p.1);
    let base_eff = curves
        .first()
        .and_then(|c| c.points.last())
        .map_or(f64::NAN, efficiency);
    let rows: Vec<Vec<String>> = curves
        .iter()
        .map(|c| {
            let last = c.points.last().expect("one point per sample count");
            let mut row = vec![format!("`{}`", c.name)];
            row.extend(c.points.iter().map(|p| num(p.2, 3)));
            row.extend([
                num(last.1, 3),
                num(last.3, 3),
                num(efficiency(last) / base_eff, 3),
            ]);
            row
        })
        .collect();
    let rmse_headers: Vec<String> = plan
        .spp
        .iter()
        .map(|s| format!("RMSE at {s} spp"))
        .collect();
    let last_spp = plan.spp.last().copied().unwrap_or(0);
    let mut header: Vec<&str> = vec!["knob"];
    header.extend(rmse_headers.iter().map(String::as_str));
    let secs = format!("seconds at {last_spp} spp");
    header.extend([
        secs.as_str(),
        "rays per sample",
        "efficiency vs reference settings",
    ]);
    let mut text = format!(
        "### {name}\n\nHair: {}. Reference: {} spp in {} s.\n\n{}\n",
        model_names(&base.desc),
        plan.reference_spp,
        num(reference_seconds, 3),
        table(&header, &rows)
    );
    let best = (curves.iter())
        .filter_map(|c| Some((c.name, efficiency(c.points.last()?) / base_eff)))
        .filter(|(_, e)| e.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((knob, gain)) = best {
        text += &format!(
            "Most efficient at {last_spp} spp here: `{knob}`, {}x the reference settings.\n\n",
            num(gain, 3)
        );
    }
    if !skipped.is_empty() {
        text += &format!("Not measured here: {}.\n\n", skipped.join("; "));
    }
    text += &figure(&file, &format!("{name} render Pareto plot"), &caption);
    Ok(text)
}
