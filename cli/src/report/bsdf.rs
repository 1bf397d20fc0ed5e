//! BSDF section: nanoseconds per call of each way the library evaluates and samples the
//! Chiang hair BSDF, against its accuracy relative to the f64 reference model of the BSDF
//! tests (tests/bsdf/common/reference.rs, compiled in here so that both judge by the same
//! formulas), over hard cases and over random in-range inputs; then the Huang model's
//! points beside Chiang's ([`huang`], judged by tests/bsdf/common/huang_reference.rs).

use super::markdown::{figure, num, table};
use super::plots::{Labels, Series, log_log};
use super::{Context, median};
use glam::Vec3;
use hairtrace::{BsdfEval, HairBsdf, HairParams, HairPoint, Lobes, Result};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;
use std::time::Instant;

mod huang;

#[path = "../../../tests/bsdf/common/huang_reference.rs"]
mod huang_reference;
#[path = "../../../tests/bsdf/common/pbrt_f32.rs"]
mod pbrt_f32;
#[allow(dead_code)] // the tests use more of it than the report does
#[path = "../../../tests/bsdf/common/reference.rs"]
mod reference;
#[allow(dead_code)]
#[path = "../../../tests/bsdf/common/sphere.rs"]
mod sphere;

use pbrt_f32::PbrtHair;
use reference::RefHair;
use sphere::{normalize, tilt, uniform_sphere};

/// One evaluation input.
#[derive(Clone, Copy)]
struct Input {
    h: f32,
    wo: Vec3,
    wi: Vec3,
    u: [f32; 3],
}

/// The inputs of one parameter set.
struct Set {
    bsdf: HairBsdf,
    reference: RefHair,
    /// The accuracy tests' yardstick: pbrt-v3's evaluation in f32 with libm's special
    /// functions, beside the library's own fast exp and log.
    port: PbrtHair,
    inputs: Vec<Input>,
    /// The inputs as `eval_batch` takes them, and its outputs.
    batch: Batch,
}

#[derive(Default)]
struct Batch {
    h: Vec<f32>,
    wo: Vec<[f32; 3]>,
    wi: Vec<[f32; 3]>,
    f: Vec<[f32; 3]>,
    pdf: Vec<f32>,
}

/// h at and next to the fibre's edges and centre.
const HARD_HS: [f32; 5] = [-1.0, -1.0 + 1e-6, 0.0, 1.0 - 1e-6, 1.0];

/// A direction of hard-case kind `kind` (0..4 for wo, 0..7 for wi): random; near either
/// end of the tangent (1e-7 rad, up to 1e-4 rad, or at sin(theta) = 0.99999 as in pbrt's
/// own hard cases); grazing the fibre's normal plane; and, for wi, wo itself, its
/// opposite, and half a turn away in azimuth.
fn hard_direction(kind: usize, wo: [f64; 3], g: &mut Pcg64) -> [f64; 3] {
    let near_tangent = |g: &mut Pcg64, sign: f64| {
        let angle = match g.random_range(0..3) {
            0 => 1e-7,
            1 => g.random_range(0.0..1e-4),
            _ => 0.99999f64.acos(),
        };
        tilt([sign, 0.0, 0.0], angle, g)
    };
    match kind {
        1 => near_tangent(g, 1.0),
        2 => near_tangent(g, -1.0),
        3 => {
            let z = g.random_range(-1e-4..1e-4);
            let phi: f64 = g.random_range(-std::f64::consts::PI..std::f64::consts::PI);
            normalize([phi.sin(), phi.cos(), z])
        }
        4 => wo,
        5 => wo.map(|c| -c),
        6 => {
            let phi = wo[2].atan2(wo[1]) + std::f64::consts::PI;
            let t: f64 = g.random_range(-1.5..1.5);
            [t.sin(), t.cos() * phi.cos(), t.cos() * phi.sin()]
        }
        _ => uniform_sphere(g),
    }
}

fn v3(w: [f64; 3]) -> Vec3 {
    Vec3::new(w[0] as f32, w[1] as f32, w[2] as f32)
}

fn set(params: HairParams, inputs: Vec<Input>) -> Result<Set> {
    let p = &params;
    Ok(Set {
        bsdf: HairBsdf::new(p)?,
        port: PbrtHair::new(p),
        reference: RefHair::new(
            p.sigma_a.map(f64::from),
            p.eta.into(),
            p.beta_m.into(),
            p.beta_n.into(),
            p.alpha.into(),
        ),
        batch: Batch {
            h: inputs.iter().map(|x| x.h).collect(),
            wo: inputs.iter().map(|x| x.wo.to_array()).collect(),
            wi: inputs.iter().map(|x| x.wi.to_array()).collect(),
            f: vec![[0.0; 3]; inputs.len()],
            pdf: vec![0.0; inputs.len()],
        },
        inputs,
    })
}

/// The hard-case grid: roughness, absorption and tilt at their ends, each parameter set
/// with every h of [`HARD_HS`] plus a random one, crossed with every wo and wi kind.
fn hard_sets(quick: bool, g: &mut Pcg64) -> Result<Vec<Set>> {
    let betas: &[f32] = if quick {
        &[0.01, 1.0]
    } else {
        &[0.01, 0.1, 0.3, 1.0]
    };
    let sigmas: &[[f32; 3]] = &[[0.0; 3], HairParams::default().sigma_a, [1e3; 3]];
    let alphas: &[f32] = if quick { &[2.0] } else { &[0.0, 2.0, 20.0] };
    let mut out = Vec::new();
    for &beta_m in betas {
        for &beta_n in betas {
            for &sigma_a in sigmas {
                for &alpha in alphas {
                    let params = HairParams {
                        sigma_a,
                        eta: 1.55,
                        beta_m,
                        beta_n,
                        alpha,
                    };
                    let mut inputs = Vec::new();
                    for h in HARD_HS.into_iter().chain([g.random_range(-1.0..=1.0)]) {
                        for wo_kind in 0..4 {
                            let wo = hard_direction(wo_kind, [0.0; 3], g);
                            for wi_kind in 0..7 {
                                let wi = hard_direction(wi_kind, wo, g);
                                let u = [g.random(), g.random(), g.random()];
                                inputs.push(Input {
                                    h,
                                    wo: v3(wo),
                                    wi: v3(wi),
                                    u,
                                });
                            }
                        }
                    }
                    out.push(set(params, inputs)?);
                }
            }
        }
    }
    Ok(out)
}

/// Random parameter sets over the valid ranges (roughness log-uniform, eta away from the
/// ill-conditioned 1.0001, absorption none or log-uniform) with uniform h, wo and wi.
fn random_sets(sets: usize, per_set: usize, g: &mut Pcg64) -> Result<Vec<Set>> {
    (0..sets)
        .map(|_| {
            let params = HairParams {
                sigma_a: random_sigma_a(g),
                eta: random_eta(g),
                beta_m: random_roughness(g),
                beta_n: random_roughness(g),
                alpha: random_tilt(g),
            };
            let inputs = (0..per_set).map(|_| random_input(g)).collect();
            set(params, inputs)
        })
        .collect()
}

/// Absorption per channel: none one time in five, else log-uniform over [0.01, 10].
fn random_sigma_a(g: &mut Pcg64) -> [f32; 3] {
    std::array::from_fn(|_| {
        if g.random_range(0..5) == 0 {
            0.0
        } else {
            10f32.powf(g.random_range(-2.0..1.0))
        }
    })
}

/// eta over [1.05, 3], away from the ill-conditioned 1.0001.
fn random_eta(g: &mut Pcg64) -> f32 {
    g.random_range(1.05..=3.0)
}

/// A roughness, log-uniform over its valid [0.01, 1].
fn random_roughness(g: &mut Pcg64) -> f32 {
    10f32.powf(g.random_range(-2.0..=0.0)).clamp(0.01, 1.0)
}

/// A cuticle tilt in degrees over its valid [-20, 20].
fn random_tilt(g: &mut Pcg64) -> f32 {
    g.random_range(-20.0..=20.0)
}

/// Uniform h, wo and wi and random numbers to sample with.
fn random_input(g: &mut Pcg64) -> Input {
    Input {
        h: g.random_range(-1.0..=1.0),
        wo: v3(uniform_sphere(g)),
        wi: v3(uniform_sphere(g)),
        u: [g.random(), g.random(), g.random()],
    }
}

/// Relative errors below this absolute size of f |wi.z| (or pdf) are f32 underflow, not
/// inaccuracy (as in the BSDF sweep test).
const ABS_FLOOR: f64 = 1e-30;

/// Max and RMS relative error of f (per channel) and pdf at `wi` against the reference,
/// accumulated into `acc`. Directions exactly along the
/// tangent have no azimuth, so no reference value to compare with: they are left out.
fn accumulate(acc: &mut Errors, s: &Set, x: &Input, wi: Vec3, got: BsdfEval) {
    let along = |w: Vec3| w.y == 0.0 && w.z == 0.0;
    if along(x.wo) || along(wi) {
        return;
    }
    let d = |w: Vec3| [w.x as f64, w.y as f64, w.z as f64];
    let want = s.reference.eval(x.h as f64, d(x.wo), d(wi));
    let cos = if wi.z == 0.0 {
        1.0
    } else {
        (wi.z as f64).abs()
    };
    let pairs = [
        (got.f.x as f64, want.f[0], cos),
        (got.f.y as f64, want.f[1], cos),
        (got.f.z as f64, want.f[2], cos),
        (got.pdf as f64, want.pdf, 1.0),
    ];
    let at = || {
        let p = s.bsdf.params();
        format!(
            "h = {}, wo = {:?}, wi = {:?}, sigma_a = {:?}, eta {}, beta_m {}, beta_n {}, \
             alpha {}",
            x.h,
            x.wo.to_array(),
            wi.to_array(),
            p.sigma_a,
            p.eta,
            p.beta_m,
            p.beta_n,
            p.alpha
        )
    };
    for (what, (g, w, scale)) in ["f red", "f green", "f blue", "pdf"].iter().zip(pairs) {
        acc.add(what, g, w, scale, at);
    }
}

/// Relative errors gathered over inputs: the largest (and where), their sum of squares
/// and count.
#[derive(Default)]
struct Errors {
    max: f64,
    worst: String,
    sum_sq: f64,
    n: usize,
}

impl Errors {
    /// Adds the relative error of `got` (what it is: `what`) against `want`, unless the
    /// error times `scale` is below [`ABS_FLOOR`]; `at` says where, for the worst.
    fn add(&mut self, what: &str, got: f64, want: f64, scale: f64, at: impl Fn() -> String) {
        let err = (got - want).abs();
        if err * scale <= ABS_FLOOR {
            return;
        }
        let rel = err / want.abs().max(1e-300);
        if rel > self.max {
            self.worst = format!("{what} {got:.4e} against {want:.4e} at {}", at());
            self.max = rel;
        }
        self.sum_sq += rel * rel;
        self.n += 1;
    }

    fn rms(&self) -> f64 {
        (self.sum_sq / self.n.max(1) as f64).sqrt()
    }
}

/// Per input, the direction a call evaluated at and what it gave (None: no sample).
type Outputs = Vec<Option<(Vec3, BsdfEval)>>;

/// A way of calling the BSDF: its name, what one timed call does, and the results it
/// gives (for the accuracy check), per parameter set.
struct Variant {
    name: &'static str,
    /// Times every input of a set once; returns the calls made.
    time: fn(&mut Set) -> usize,
    /// (wi, f and pdf) for every input of a set; None for a call that returns no value.
    outputs: Option<fn(&mut Set) -> Outputs>,
}

fn eval_outputs(s: &mut Set) -> Outputs {
    s.inputs
        .iter()
        .map(|x| Some((x.wi, s.bsdf.eval(x.h, x.wo, x.wi))))
        .collect()
}

fn port_outputs(s: &mut Set) -> Outputs {
    s.inputs
        .iter()
        .map(|x| {
            let (f, pdf) = s.port.eval(x.h, x.wo.to_array(), x.wi.to_array());
            Some((
                x.wi,
                BsdfEval {
                    f: Vec3::from_array(f),
                    pdf,
                },
            ))
        })
        .collect()
}

fn sample_outputs(s: &mut Set) -> Outputs {
    s.inputs
        .iter()
        .map(|x| {
            let r = s.bsdf.sample(x.h, x.wo, x.u)?;
            Some((r.wi, BsdfEval { f: r.f, pdf: r.pdf }))
        })
        .collect()
}

/// What a path vertex gets from a point of `lobes` (at + eval + sample), per input.
fn vertex(s: &Set, x: &Input, lobes: Lobes) -> (BsdfEval, Option<hairtrace::BsdfSample>) {
    let p = s.bsdf.at_lobes(x.h, x.wo, lobes);
    (p.eval(x.wi), p.sample(x.u))
}

/// The evaluations and samples of points of `lobes`, judged against the whole model.
fn lobes_outputs(s: &Set, lobes: Lobes) -> Outputs {
    s.inputs
        .iter()
        .flat_map(|x| {
            let (e, sample) = vertex(s, x, lobes);
            [
                Some((x.wi, e)),
                sample.map(|r| (r.wi, BsdfEval { f: r.f, pdf: r.pdf })),
            ]
        })
        .collect()
}

/// Lane 0 of `eval_across`: the model at the input's own offset (the other lanes are at
/// its shifts across the fibre).
fn across_outputs(s: &mut Set) -> Outputs {
    s.inputs
        .iter()
        .map(|x| {
            let a = s.bsdf.at(x.h, x.wo).eval_across(x.wi)?;
            Some((
                x.wi,
                BsdfEval {
                    f: a.f[0],
                    pdf: a.pdf[0],
                },
            ))
        })
        .collect()
}

fn batch_outputs(s: &mut Set) -> Outputs {
    run_batch(s);
    let b = &s.batch;
    (s.inputs.iter().zip(b.f.iter().zip(&b.pdf)))
        .map(|(x, (f, &pdf))| {
            let f = Vec3::from_array(*f);
            Some((x.wi, BsdfEval { f, pdf }))
        })
        .collect()
}

fn run_batch(s: &mut Set) {
    let b = &mut s.batch;
    (s.bsdf.eval_batch(&b.h, &b.wo, &b.wi, &mut b.f, &mut b.pdf)).expect("slices of one length");
}

/// Calls `call` on every input of a set, the inputs hidden from the optimiser; returns
/// the calls made.
fn each<R>(s: &Set, call: impl Fn(&Input) -> R) -> usize {
    for x in &s.inputs {
        black_box(call(black_box(x)));
    }
    s.inputs.len()
}

/// Calls `call` 8 times on one prepared point per input (with the call's index): what
/// a point's later calls cost once its (h, wo) work is done, amortised as a renderer
/// would over its light and BSDF samples. Returns the calls made.
fn per_point<R>(s: &Set, call: impl Fn(&HairPoint, &Input, usize) -> R) -> usize {
    for x in &s.inputs {
        let p = s.bsdf.at(black_box(x.h), black_box(x.wo));
        for k in 0..8 {
            black_box(call(&p, black_box(x), k));
        }
    }
    s.inputs.len() * 8
}

const VARIANTS: [Variant; 12] = [
    Variant {
        name: "HairBsdf::eval",
        time: |s| each(s, |x| s.bsdf.eval(x.h, x.wo, x.wi)),
        outputs: Some(eval_outputs),
    },
    Variant {
        name: "HairBsdf::sample",
        time: |s| each(s, |x| s.bsdf.sample(x.h, x.wo, x.u)),
        outputs: Some(sample_outputs),
    },
    Variant {
        name: "HairPoint: at + eval + sample (a path vertex)",
        time: |s| {
            each(s, |x| {
                let p = s.bsdf.at(x.h, x.wo);
                (p.eval(x.wi), p.sample(x.u))
            })
        },
        outputs: Some(eval_outputs),
    },
    Variant {
        name: "HairBsdf::at (prepare a point)",
        time: |s| each(s, |x| s.bsdf.at(x.h, x.wo)),
        outputs: None,
    },
    Variant {
        name: "HairPoint::eval (one at per 8 evals, per eval)",
        time: |s| per_point(s, |p, x, k| p.eval(if k % 2 == 0 { x.wi } else { -x.wi })),
        outputs: Some(eval_outputs),
    },
    Variant {
        name: "HairPoint::sample (one at per 8 samples, per sample)",
        time: |s| {
            per_point(s, |p, x, k| {
                p.sample(x.u.map(|u| (u + k as f32 * 0.125).fract()))
            })
        },
        outputs: Some(sample_outputs),
    },
    Variant {
        name: "HairPoint::eval_across (8 offsets; one at per 8 calls, per call)",
        time: |s| {
            per_point(s, |p, x, k| {
                p.eval_across(if k % 2 == 0 { x.wi } else { -x.wi })
            })
        },
        outputs: Some(across_outputs),
    },
    Variant {
        name: "HairPoint, lobes culled below 0.01: at + eval + sample",
        time: |s| each(s, |x| vertex(s, x, Lobes::Culled(0.01))),
        outputs: Some(|s| lobes_outputs(s, Lobes::Culled(0.01))),
    },
    Variant {
        name: "HairPoint, lobes culled below 0.1: at + eval + sample",
        time: |s| each(s, |x| vertex(s, x, Lobes::Culled(0.1))),
        outputs: Some(|s| lobes_outputs(s, Lobes::Culled(0.1))),
    },
    Variant {
        name: "HairPoint, merged lobe (deep bounces): at + eval + sample",
        time: |s| each(s, |x| vertex(s, x, Lobes::Merged)),
        // It keeps each (h, wo)'s energy, not the model's value at any one direction:
        // its error is the render section's to measure.
        outputs: None,
    },
    Variant {
        name: "pbrt-v3's eval in plain f32, libm special functions (the tests' port)",
        time: |s| each(s, |x| s.port.eval(x.h, x.wo.to_array(), x.wi.to_array())),
        outputs: Some(port_outputs),
    },
    Variant {
        name: "HairBsdf::eval_batch (per element)",
        time: |s| {
            run_batch(s);
            s.inputs.len()
        },
        outputs: Some(batch_outputs),
    },
];

/// Median ns per call of `v` over `reps` rounds of every set.
fn time_variant(v: &Variant, sets: &mut [Set], reps: usize) -> f64 {
    timed(reps, || sets.iter_mut().map(|s| (v.time)(s)).sum())
}

/// Median ns per call of `round` (which returns the calls it made) over `reps` rounds.
fn timed(reps: usize, mut round: impl FnMut() -> usize) -> f64 {
    let rounds = (0..reps)
        .map(|_| {
            let start = Instant::now();
            let calls = round();
            start.elapsed().as_secs_f64() * 1e9 / calls as f64
        })
        .collect();
    median(rounds)
}

/// The relative errors of `outputs` over the sets; None for a call without outputs.
fn accuracy(outputs: Option<fn(&mut Set) -> Outputs>, sets: &mut [Set]) -> Option<Errors> {
    let outputs = outputs?;
    let mut acc = Errors::default();
    for s in sets {
        let outs = outputs(s);
        // A lobes variant gives an eval and a sample per input.
        let per_input = outs.len() / s.inputs.len().max(1);
        let inputs = s
            .inputs
            .iter()
            .flat_map(|x| std::iter::repeat_n(x, per_input));
        for (x, out) in inputs.zip(outs) {
            let Some((wi, e)) = out else { continue };
            accumulate(&mut acc, s, x, wi, e);
        }
    }
    Some(acc)
}

/// A plot of ns per call against relative error, one bar a call.
fn pareto(ctx: &Context, file: &str, title: &str, caption: &str, series: &[Series]) -> Result<()> {
    let labels = Labels {
        title,
        x: "ns per call",
        y: "relative error against the f64 reference",
        caption,
    };
    log_log(&ctx.path(file), &labels, series)
}

pub fn steps(_: &Context) -> u64 {
    VARIANTS.len() as u64 + 1 + huang::STEPS
}

pub fn section(ctx: &Context) -> Result<String> {
    let mut g = Pcg64::seed_from_u64(2024);
    ctx.step("BSDF inputs");
    let mut hard = hard_sets(ctx.quick, &mut g)?;
    let mut random = if ctx.quick {
        random_sets(8, 256, &mut g)?
    } else {
        random_sets(64, 1024, &mut g)?
    };
    let reps = if ctx.quick { 3 } else { 15 };
    ctx.done();
    let mut rows = Vec::new();
    let mut series = Vec::new();
    let mut worst = Vec::new();
    for v in &VARIANTS {
        ctx.step(format!("BSDF {}", v.name));
        let ns = time_variant(v, &mut random, reps);
        let hard_errors = accuracy(v.outputs, &mut hard);
        let random_errors = accuracy(v.outputs, &mut random);
        let max_rms = |e: &Option<Errors>| {
            e.as_ref()
                .map_or((f64::NAN, f64::NAN), |e| (e.max, e.rms()))
        };
        let ((hard_max, hard_rms), (random_max, random_rms)) =
            (max_rms(&hard_errors), max_rms(&random_errors));
        if let Some(e) = hard_errors.filter(|_| worst.is_empty()) {
            worst.push(format!("The worst hard case of `{}`: {}.", v.name, e.worst));
        }
        rows.push(vec![
            "Chiang".to_owned(),
            format!("`{}`", v.name),
            num(ns, 3),
            num(hard_max, 2),
            num(hard_rms, 2),
            num(random_max, 2),
            num(random_rms, 2),
        ]);
        // A bar from the typical error (RMS over random inputs) to the worst (max over
        // the hard cases).
        series.push(Series {
            name: v.name.to_owned(),
            points: vec![(ns, random_rms), (ns, hard_max)],
            line: true,
        });
        ctx.done();
    }
    let hard_inputs: usize = hard.iter().map(|s| s.inputs.len()).sum();
    let random_inputs: usize = random.iter().map(|s| s.inputs.len()).sum();
    let caption = ctx.machine.caption(
        1,
        &format!(
            "median of {reps} rounds over {random_inputs} random inputs; bars from RMS \
             error over them to max error over {hard_inputs} hard cases, seed 2024"
        ),
    );
    let file = "bsdf_pareto.png";
    pareto(
        ctx,
        file,
        "Chiang hair BSDF: ns per call against relative error",
        &caption,
        &series,
    )?;
    Ok(format!(
        "Each way of calling the Chiang hair BSDF (`HairBsdf`, round fibres: every row of \
         the first table), timed with `std::time::Instant` on one thread (ns per call: the \
         median of {reps} rounds, each over every random input), and its relative error in \
         f (each channel) and pdf against the f64 reference model of the BSDF tests. Sampling is judged by the f and pdf it returns against the reference \
         at the direction it drew. Values whose error in f |cos| or pdf is below 1e-30 \
         (f32 underflow) and directions exactly along the fibre (no azimuth) are left \
         out. Hard cases: roughness 0.01 to 1, no, brown and huge absorption, tilt 0 to 20 \
         degrees, h at and next to +-1 and 0, wo and wi within 1e-7 rad, 1e-4 rad and at \
         sin(theta) = 0.99999 of the tangent, grazing, wi = +-wo and half a turn away. \
         Random: {} parameter sets over the valid ranges (eta from 1.05), uniform h, wo, wi. \
         The point rows time what a renderer's path vertex does; `HairBsdf::at` alone is \
         the (h, wo) work a prepared point saves. `HairPoint::eval_across` is next-event \
         estimation's evaluation at eight offsets across the fibre in one call, judged by \
         its lane at the input's own offset. The culled and merged rows are the \
         renderer's fidelity knobs `lobe_cull` and `deep_bounce_depth` at one vertex, their \
         eval and sample both judged against the whole model (culling's error is the \
         dropped lobes'); the merged lobe keeps only each (h, wo)'s energy, not the \
         model's value at any one direction, so its error is measured in the render \
         section. The library's special functions are its own fast exp and log \
         (`math::fast`); the port row is pbrt-v3's evaluation in plain f32 with libm's exp, \
         log and Bessel series (the accuracy tests' yardstick, \
         tests/bsdf/common/pbrt_f32.rs), eval only: it has no hard-case RMS, since it \
         gives no finite value at h = +-1 without absorption.\n\n{}\n{}\n\n{}{}",
        random.len(),
        table(
            &[
                "model",
                "variant",
                "ns per call",
                "max rel. error (hard)",
                "RMS rel. error (hard)",
                "max rel. error (random)",
                "RMS rel. error (random)"
            ],
            &rows
        ),
        worst.join(" "),
        figure(file, "BSDF Pareto plot", &caption),
        huang::part(ctx, reps)?,
    ))
}
