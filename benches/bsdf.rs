//! Single-thread cost of the hair BSDF entry points on random in-range inputs.
//! `eval_batch` is reported per evaluation (throughput in elements) so that it compares
//! directly with the scalar `eval`. The `huang` group: the Huang model's points (near
//! and far field, an elliptical fibre of aspect 0.65) on the same inputs.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec2;
use glam::Vec3;
use hairtrace::{HairBsdf, HairParams, HuangBsdf, HuangParams};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::hint::black_box;

const N: usize = 4096;

struct Inputs {
    h: Vec<f32>,
    wo: Vec<[f32; 3]>,
    wi: Vec<[f32; 3]>,
    u: Vec<[f32; 3]>,
}

fn unit(rng: &mut Pcg64) -> [f32; 3] {
    let z: f32 = rng.random_range(-1.0..1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let r = (1.0 - z * z).max(0.0).sqrt();
    [z, r * phi.cos(), r * phi.sin()]
}

fn inputs() -> Inputs {
    let mut rng = Pcg64::seed_from_u64(7);
    Inputs {
        h: (0..N).map(|_| rng.random_range(-1.0..1.0)).collect(),
        wo: (0..N).map(|_| unit(&mut rng)).collect(),
        wi: (0..N).map(|_| unit(&mut rng)).collect(),
        u: (0..N)
            .map(|_| [rng.random(), rng.random(), rng.random()])
            .collect(),
    }
}

fn bench(c: &mut Criterion) {
    let bsdf = HairBsdf::new(&HairParams::default()).unwrap();
    let inp = inputs();
    let v = |a: [f32; 3]| Vec3::from_array(a);
    let mut g = c.benchmark_group("hair");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("eval", |b| {
        b.iter(|| {
            for i in 0..N {
                black_box(bsdf.eval(inp.h[i], v(inp.wo[i]), v(inp.wi[i])));
            }
        })
    });
    g.bench_function("pdf", |b| {
        b.iter(|| {
            for i in 0..N {
                black_box(bsdf.pdf(inp.h[i], v(inp.wo[i]), v(inp.wi[i])));
            }
        })
    });
    g.bench_function("sample", |b| {
        b.iter(|| {
            for i in 0..N {
                black_box(bsdf.sample(inp.h[i], v(inp.wo[i]), inp.u[i]));
            }
        })
    });
    // The per-wi part alone: (h, wo) prepared once per shading point, as a path tracer
    // does for next-event estimation plus BSDF sampling at the same vertex.
    let points: Vec<_> = (0..N).map(|i| bsdf.at(inp.h[i], v(inp.wo[i]))).collect();
    g.bench_function("point_eval", |b| {
        b.iter(|| {
            for (i, p) in points.iter().enumerate() {
                black_box(p.eval(v(inp.wi[i])));
            }
        })
    });
    g.bench_function("point_sample", |b| {
        b.iter(|| {
            for (i, p) in points.iter().enumerate() {
                black_box(p.sample(inp.u[i]));
            }
        })
    });
    let mut f = vec![[0.0; 3]; N];
    let mut pdf = vec![0.0; N];
    g.bench_function("eval_batch", |b| {
        b.iter(|| {
            bsdf.eval_batch(&inp.h, &inp.wo, &inp.wi, &mut f, &mut pdf)
                .unwrap();
            black_box(&f);
        })
    });
    g.finish();
    huang(c, &inp);
}

fn huang(c: &mut Criterion, inp: &Inputs) {
    let bsdf = HuangBsdf::new(&HuangParams {
        aspect: 0.65,
        ..HuangParams::default()
    })
    .unwrap();
    let v = |a: [f32; 3]| Vec3::from_array(a);
    let major = Vec2::from_angle(0.5);
    let mut g = c.benchmark_group("huang");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function("point", |b| {
        b.iter(|| {
            for i in 0..N {
                black_box(bsdf.near(inp.h[i], v(inp.wo[i]), major, [0.5; 2]));
            }
        })
    });
    for (name, far) in [("near", false), ("far", true)] {
        let points: Vec<_> = (0..N)
            .map(|i| {
                let (h, wo) = (inp.h[i], v(inp.wo[i]));
                if far {
                    bsdf.far(h, wo, major, [0.5; 2])
                } else {
                    bsdf.near(h, wo, major, [0.5; 2])
                }
            })
            .collect();
        g.bench_function(format!("{name}_point_eval"), |b| {
            b.iter(|| {
                for (i, p) in points.iter().enumerate() {
                    black_box(p.eval(v(inp.wi[i])));
                }
            })
        });
        g.bench_function(format!("{name}_point_sample"), |b| {
            b.iter(|| {
                for (i, p) in points.iter().enumerate() {
                    black_box(p.sample(inp.u[i]));
                }
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
