//! The Rust vertex that bench/c_bsdf compares the C and C++ calls with, on the inputs
//! bench.c and hits.h draw (their generator, their order of draws, their two materials,
//! alternating), timed with their protocol: 41 interleaved rounds over 4096 inputs, medians
//! of ns per vertex. From a hit, as vertex.cpp: the frame and h (`hair_frame_offset`, the
//! renderer's and the C ABI's), `HairBsdf::at`, f |cos| and pdf toward the light, and a
//! sample with its weight turned to world space; and in the local frame, `at` + `eval` +
//! `sample`. Run by bench/c_bsdf/run (`cargo bench -p hairtrace-benches --bench c_vertex`).

use glam::Vec3;
use hairtrace::bsdf::sigma_a_from_melanin;
use hairtrace::math::hair_frame_offset;
use hairtrace::{HairBsdf, HairParams};
use std::hint::black_box;
use std::time::Instant;

const N: usize = 4096;
const ROUNDS: usize = 41;

/// hits.h's xorshift64*: 24 bits in [0, 1).
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / 16_777_216.0
    }

    fn unit(&mut self) -> [f32; 3] {
        let z = 2.0 * self.uniform() - 1.0;
        // bench.c's 6.2831853f is this f32.
        let phi = std::f32::consts::TAU * self.uniform();
        let r = (1.0 - z * z).max(0.0).sqrt();
        [z, r * phi.cos(), r * phi.sin()]
    }

    /// hits.h's `bench_hit`, operation for operation: tangent, ray, axis point, radius,
    /// light and u.
    fn hit(&mut self) -> Hit {
        let (t, d, light) = (self.unit(), self.unit(), self.unit());
        let u = [self.uniform(), self.uniform(), self.uniform()];
        let mut h = 2.0 * self.uniform() - 1.0;
        let y = [
            t[1] * d[2] - t[2] * d[1],
            t[2] * d[0] - t[0] * d[2],
            t[0] * d[1] - t[1] * d[0],
        ];
        let n = (y[0] * y[0] + y[1] * y[1] + y[2] * y[2]).sqrt();
        if n < 1e-3 {
            h = 0.0;
        }
        let (radius, axis) = (0.03f32, [0.5f32, -0.25, 1.0]);
        let s = if n < 1e-3 { 0.0 } else { h * radius / n };
        let org: [f32; 3] = std::array::from_fn(|c| axis[c] + y[c] * s - 4.0 * d[c]);
        Hit {
            tangent: t.into(),
            org: org.into(),
            dir: d.into(),
            axis: axis.into(),
            radius,
            light: light.into(),
            u,
        }
    }
}

/// A renderer's hit and what its vertex needs (hits.h's `BenchHit`).
struct Hit {
    tangent: Vec3,
    org: Vec3,
    dir: Vec3,
    axis: Vec3,
    radius: f32,
    light: Vec3,
    u: [f32; 3],
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut blond = HairParams {
        beta_m: 0.12,
        alpha: -3.0,
        ..HairParams::default()
    };
    blond.sigma_a = sigma_a_from_melanin(0.3, 0.2).expect("valid melanin");
    let bsdfs = [HairParams::default(), blond].map(|p| HairBsdf::new(&p).expect("valid"));
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let inputs: Vec<(f32, Vec3, Vec3, [f32; 3])> = (0..N)
        .map(|_| {
            let h = 2.0 * rng.uniform() - 1.0;
            let (wo, wi) = (rng.unit(), rng.unit());
            let u = [rng.uniform(), rng.uniform(), rng.uniform()];
            (h, wo.into(), wi.into(), u)
        })
        .collect();
    let mut hit_rng = Rng(0x51ed_2701_f3a5_c7b9);
    let hits: Vec<Hit> = (0..N).map(|_| hit_rng.hit()).collect();
    let from_hit = || {
        for (i, k) in hits.iter().enumerate() {
            let (frame, offset) = hair_frame_offset(k.tangent, k.dir, k.org, k.axis, k.radius);
            let h = offset.clamp(-1.0, 1.0) as f32;
            let point = bsdfs[i & 1].at(h, frame.to_local(-k.dir.normalize()));
            let wi = frame.to_local(k.light);
            let e = point.eval(wi);
            black_box((e.f * wi.z.abs(), e.pdf));
            let s = point.sample(k.u).map(|s| {
                let f_cos = s.f * s.wi.z.abs();
                (frame.to_world(s.wi), f_cos, f_cos / s.pdf, s.pdf)
            });
            black_box(s);
        }
    };
    let vertex = || {
        for (i, &(h, wo, wi, u)) in inputs.iter().enumerate() {
            let point = bsdfs[i & 1].at(h, wo);
            black_box(point.eval(wi));
            black_box(point.sample(u));
        }
    };
    let points: Vec<_> = (inputs.iter().enumerate())
        .map(|(i, &(h, wo, _, _))| bsdfs[i & 1].at(h, wo))
        .collect();
    let at = || {
        for (i, &(h, wo, _, _)) in inputs.iter().enumerate() {
            black_box(bsdfs[i & 1].at(h, wo));
        }
    };
    let eval = || {
        for (p, &(_, _, wi, _)) in points.iter().zip(&inputs) {
            black_box(p.eval(wi));
        }
    };
    let sample = || {
        for (p, &(_, _, _, u)) in points.iter().zip(&inputs) {
            black_box(p.sample(u));
        }
    };
    let methods: [(&str, &dyn Fn()); 5] = [
        (
            "Rust vertex from a hit (frame, at, eval, sample)",
            &from_hit,
        ),
        ("Rust vertex (at + eval + sample)", &vertex),
        ("Rust HairBsdf::at", &at),
        ("Rust HairPoint::eval", &eval),
        ("Rust HairPoint::sample", &sample),
    ];
    let mut ns = vec![Vec::with_capacity(ROUNDS); methods.len()];
    for _ in 0..ROUNDS {
        for (k, (_, run)) in methods.iter().enumerate() {
            let t0 = Instant::now();
            run();
            ns[k].push(t0.elapsed().as_secs_f64() * 1e9 / N as f64);
        }
    }
    for ((name, _), ns) in methods.iter().zip(ns) {
        println!("{name:<48} {:8.1}", median(ns));
    }
}
