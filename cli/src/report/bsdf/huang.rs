//! The BSDF section's Huang part: what a point of the Huang model costs (building it, an
//! eval, a sample; near and far field) and how far its f |wi.z| and pdf are from the f64
//! reference of the BSDF tests (tests/bsdf/common/huang_reference.rs), beside a Chiang
//! point timed and judged the same way on the same inputs, so that the two models' costs
//! compare as a ratio.

use super::super::Context;
use super::super::markdown::{figure, num, table};
use super::super::plots::Series;
use super::huang_reference::RefHuang;
use super::reference::RefHair;
use super::{
    Errors, pareto, random_eta, random_input, random_roughness, random_sigma_a, random_tilt, timed,
};
use glam::{Vec2, Vec3};
use hairtrace::{BsdfEval, HairBsdf, HairParams, HuangBsdf, HuangParams, LocalBsdf, Result};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;

/// One input: the Chiang table's (h, wo, wi, numbers to sample with), and the section's
/// major axis and the jitter its visible normals are drawn from.
struct Input {
    at: super::Input,
    major: Vec2,
    jitter: [f32; 2],
}

/// A Huang parameter set with its reference, the Chiang model of the same absorption,
/// index and tilt (both roughnesses the Huang roughness) with its own, and the inputs.
struct Set {
    huang: HuangBsdf,
    reference: RefHuang,
    chiang: HairBsdf,
    chiang_reference: RefHair,
    inputs: Vec<Input>,
}

/// Random parameter sets over the valid ranges (roughness log-uniform, aspect from the
/// smallest valid 0.05 to round, eta away from the ill-conditioned 1.0001, absorption none
/// or log-uniform) with uniform h, wo, wi, major axis and jitter.
fn random_sets(sets: usize, per_set: usize, g: &mut Pcg64) -> Result<Vec<Set>> {
    (0..sets)
        .map(|_| {
            let p = HuangParams {
                sigma_a: random_sigma_a(g),
                eta: random_eta(g),
                roughness: random_roughness(g),
                aspect: g.random_range(0.05..=1.0),
                alpha: random_tilt(g),
            };
            let chiang = HairParams {
                sigma_a: p.sigma_a,
                eta: p.eta,
                beta_m: p.roughness,
                beta_n: p.roughness,
                alpha: p.alpha,
            };
            let f = f64::from;
            let inputs = (0..per_set)
                .map(|_| Input {
                    at: random_input(g),
                    major: Vec2::from_angle(g.random_range(0.0..std::f32::consts::TAU)),
                    jitter: [g.random(), g.random()],
                })
                .collect();
            Ok(Set {
                huang: HuangBsdf::new(&p)?,
                reference: RefHuang::new(
                    p.sigma_a.map(f),
                    f(p.eta),
                    f(p.roughness),
                    f(p.aspect),
                    f(p.alpha),
                ),
                chiang: HairBsdf::new(&chiang)?,
                chiang_reference: RefHair::new(
                    p.sigma_a.map(f),
                    f(p.eta),
                    f(p.roughness),
                    f(p.roughness),
                    f(p.alpha),
                ),
                inputs,
            })
        })
        .collect()
}

fn d3(w: Vec3) -> [f64; 3] {
    w.to_array().map(f64::from)
}

/// A model as the rows call it: its name, its calls' names and the reference's f |wi.z|
/// and pdf (its points are built by the closure [`measure`] takes).
struct Model {
    name: &'static str,
    calls: [&'static str; 3],
    reference: fn(&Set, &Input, Vec3) -> ([f64; 3], f64),
}

const CHIANG: Model = Model {
    name: "Chiang",
    calls: ["HairBsdf::at", "HairPoint::eval", "HairPoint::sample"],
    reference: |s, x, wi| {
        let want = s.chiang_reference.eval(x.at.h.into(), d3(x.at.wo), d3(wi));
        let cos = f64::from(wi.z.abs());
        (want.f.map(|f| f * cos), want.pdf)
    },
};

const NEAR: Model = Model {
    name: "Huang near",
    calls: ["HuangBsdf::near", "HuangPoint::eval", "HuangPoint::sample"],
    reference: |s, x, wi| huang_reference(s, x, wi, 1),
};

const FAR: Model = Model {
    name: "Huang far",
    calls: ["HuangBsdf::far", "HuangPoint::eval", "HuangPoint::sample"],
    reference: |s, x, wi| huang_reference(s, x, wi, 2),
};

const FAR_LIT: Model = Model {
    name: "Huang far, lit",
    calls: [
        "HuangBsdf::far_lit",
        "HuangPoint::eval",
        "HuangPoint::sample",
    ],
    reference: |s, x, wi| huang_reference(s, x, wi, 4),
};

/// The reference of the Huang point of `shifts` offsets.
fn huang_reference(s: &Set, x: &Input, wi: Vec3, shifts: usize) -> ([f64; 3], f64) {
    let major = x.major.to_array().map(f64::from);
    (s.reference).eval(shifts, x.at.h, d3(x.at.wo), d3(wi), major, x.jitter)
}

/// One model's figures: ns per point built, per eval and per sample, and the relative
/// errors of eval's and sample's f |wi.z| and pdf.
struct Measured {
    ns: [f64; 3],
    eval: [Errors; 2],
    sample: [Errors; 2],
}

/// Calls `call` 8 times on each input's prepared point (with the call's index), as a
/// renderer does over its light and BSDF samples; returns the calls made.
fn per_point<P, R>(
    sets: &[Set],
    points: &[Vec<P>],
    call: impl Fn(&P, &Input, usize) -> R,
) -> usize {
    let mut calls = 0;
    for (s, ps) in sets.iter().zip(points) {
        for (x, p) in s.inputs.iter().zip(ps) {
            for k in 0..8 {
                black_box(call(p, black_box(x), k));
            }
        }
        calls += 8 * ps.len();
    }
    calls
}

/// Times and judges `model`, whose points `build` makes, on one thread.
fn measure<'s, P: LocalBsdf>(
    ctx: &Context,
    sets: &'s [Set],
    reps: usize,
    model: Model,
    build: impl Fn(&'s Set, &Input) -> P,
) -> (Model, Measured) {
    ctx.step(format!("BSDF: {}", model.name));
    let build_ns = timed(reps, || {
        let mut calls = 0;
        for s in sets {
            for x in &s.inputs {
                black_box(build(s, black_box(x)));
            }
            calls += s.inputs.len();
        }
        calls
    });
    let points: Vec<Vec<P>> = (sets.iter())
        .map(|s| s.inputs.iter().map(|x| build(s, x)).collect())
        .collect();
    let eval_ns = timed(reps, || {
        per_point(sets, &points, |p, x, k| {
            p.eval(if k % 2 == 0 { x.at.wi } else { -x.at.wi })
        })
    });
    let sample_ns = timed(reps, || {
        per_point(sets, &points, |p, x, k| {
            p.sample(x.at.u.map(|u| (u + k as f32 * 0.125).fract()))
        })
    });
    let mut m = Measured {
        ns: [build_ns, eval_ns, sample_ns],
        eval: Default::default(),
        sample: Default::default(),
    };
    for (s, ps) in sets.iter().zip(&points) {
        for (x, p) in s.inputs.iter().zip(ps) {
            add(&mut m.eval, &model, s, x, x.at.wi, p.eval(x.at.wi));
            if let Some(r) = p.sample(x.at.u) {
                let e = BsdfEval { f: r.f, pdf: r.pdf };
                add(&mut m.sample, &model, s, x, r.wi, e);
            }
        }
    }
    ctx.done();
    (model, m)
}

/// The relative errors of f |wi.z| (per channel) and pdf at wi into `acc`.
fn add(acc: &mut [Errors; 2], model: &Model, s: &Set, x: &Input, wi: Vec3, got: BsdfEval) {
    let (f, pdf) = (model.reference)(s, x, wi);
    let at = || {
        format!(
            "h = {}, wo = {:?}, wi = {:?}, major axis {:?}, jitter {:?}, {:?}",
            x.at.h,
            x.at.wo.to_array(),
            wi.to_array(),
            x.major.to_array(),
            x.jitter,
            s.huang.params()
        )
    };
    let cos = f64::from(wi.z.abs());
    let what = format!("{}: f |wi.z|", model.name);
    for (c, want) in f.into_iter().enumerate() {
        acc[0].add(&what, f64::from(got.f[c]) * cos, want, 1.0, at);
    }
    let what = format!("{}: pdf", model.name);
    acc[1].add(&what, got.pdf.into(), pdf, 1.0, at);
}

/// RMS and max relative error over f and pdf together (the plot's bar).
fn pooled([f, pdf]: &[Errors; 2]) -> (f64, f64) {
    let n = (f.n + pdf.n).max(1) as f64;
    (((f.sum_sq + pdf.sum_sq) / n).sqrt(), f.max.max(pdf.max))
}

/// Progress steps of [`part`]: the inputs, then each model.
pub const STEPS: u64 = 5;

/// The Huang part's text, table and plot; `reps` rounds of timing as the Chiang table's.
pub fn part(ctx: &Context, reps: usize) -> Result<String> {
    ctx.step("BSDF: Huang inputs");
    let mut g = Pcg64::seed_from_u64(2022);
    let sets = if ctx.quick {
        random_sets(4, 64, &mut g)?
    } else {
        random_sets(32, 128, &mut g)?
    };
    ctx.done();
    let measured = [
        measure(ctx, &sets, reps, CHIANG, |s, x| {
            s.chiang.at(x.at.h, x.at.wo)
        }),
        measure(ctx, &sets, reps, NEAR, |s, x| {
            s.huang.near(x.at.h, x.at.wo, x.major, x.jitter)
        }),
        measure(ctx, &sets, reps, FAR, |s, x| {
            s.huang.far(x.at.h, x.at.wo, x.major, x.jitter)
        }),
        measure(ctx, &sets, reps, FAR_LIT, |s, x| {
            s.huang.far_lit(x.at.h, x.at.wo, x.major, x.jitter)
        }),
    ];
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (model, m) in &measured {
        let errors = [None, Some(&m.eval), Some(&m.sample)];
        let what = [
            "(prepare a point)",
            "(8 per point, per eval)",
            "(8 per point, per sample)",
        ];
        for i in 0..3 {
            let [f, pdf] = errors[i].map_or([(f64::NAN, f64::NAN); 2], |[f, p]| {
                [(f.max, f.rms()), (p.max, p.rms())]
            });
            rows.push(vec![
                model.name.to_owned(),
                format!("`{}` {}", model.calls[i], what[i]),
                num(m.ns[i], 3),
                num(f.0, 2),
                num(f.1, 2),
                num(pdf.0, 2),
                num(pdf.1, 2),
            ]);
            if let Some(e) = errors[i] {
                let (rms, max) = pooled(e);
                series.push(Series {
                    name: format!("{}: {}", model.name, model.calls[i]),
                    points: vec![(m.ns[i], rms), (m.ns[i], max)],
                    line: true,
                });
            }
        }
    }
    let chiang_eval = measured[0].1.ns[1];
    let ratio = |i: usize, call: usize| num(measured[i].1.ns[call] / chiang_eval, 3);
    let worst = (measured[1..].iter())
        .flat_map(|(_, m)| m.eval.iter().chain(&m.sample))
        .max_by(|a, b| a.max.total_cmp(&b.max))
        .map_or(String::new(), |e| {
            format!("The worst Huang case: {}.", e.worst)
        });
    let inputs: usize = sets.iter().map(|s| s.inputs.len()).sum();
    let caption = ctx.machine.caption(
        1,
        &format!(
            "median of {reps} rounds over {inputs} random inputs; bars from RMS to max \
             relative error of f |wi.z| and pdf over them, seed 2022"
        ),
    );
    let file = "bsdf_huang.png";
    let title = "Huang and Chiang points: ns per call against relative error";
    pareto(ctx, file, title, &caption, &series)?;
    Ok(format!(
        "### The Huang model beside Chiang\n\n\
         The Huang model's points (elliptical fibres, docs/conventions.md, section 4b), \
         near field (`HuangBsdf::near`, the fibre at one offset h) and far field \
         (`HuangBsdf::far`, averaged over two offsets across it; `HuangBsdf::far_lit`, \
         over four, where a renderer also weighs sampled lights), and a Chiang point \
         (`HairBsdf::at`) on the same inputs: {} random parameter sets over the valid \
         ranges (roughness 0.01 to 1 log-uniform, both Chiang roughnesses the Huang one; \
         aspect 0.05 to 1; eta 1.05 to 3; tilt up to 20 degrees; no or log-uniform \
         absorption), uniform h, wo, wi, section turn and node jitter. Each row is one \
         model's call, timed on one thread as above: building points, then 8 evals \
         (at wi and -wi) or 8 samples per built point, as a path vertex's light and BSDF \
         samples call it. Errors are relative, per channel of f |wi.z| and of the pdf, \
         against the f64 reference of each model's BSDF tests (the Huang one: \
         tests/bsdf/common/huang_reference.rs, the same visible normals in f64), values below \
         1e-30 left out; a sample is judged at the direction it drew. A Huang sample \
         evaluates the point at the direction it drew, but a draw lost to total internal \
         reflection returns before that, so a sample can cost less than an eval.\n\n\
         Here a Huang point's eval costs {}x a Chiang point's (near field) and {}x (far \
         field; {}x with four offsets); its sample {}x and {}x Chiang's sample; building \
         a near point costs as much as {} Chiang point evals, a far one {}.\n\n{}\n{}\n\n{}",
        sets.len(),
        ratio(1, 1),
        ratio(2, 1),
        ratio(3, 1),
        num(measured[1].1.ns[2] / measured[0].1.ns[2], 3),
        num(measured[2].1.ns[2] / measured[0].1.ns[2], 3),
        ratio(1, 0),
        ratio(2, 0),
        table(
            &[
                "model",
                "call",
                "ns per call",
                "max rel. error f \\|wi.z\\|",
                "RMS rel. error f \\|wi.z\\|",
                "max rel. error pdf",
                "RMS rel. error pdf",
            ],
            &rows
        ),
        worst,
        figure(file, "Huang BSDF Pareto plot", &caption),
    ))
}
