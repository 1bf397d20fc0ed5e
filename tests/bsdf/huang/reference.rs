//! The f32 Huang model against its f64 reference (tests/bsdf/common/huang_reference.rs).

use super::{huang, point};
use crate::common::huang_reference::RefHuang;
use crate::common::{random_u, rng};
use glam::{Vec2, Vec3};
use rand::Rng;

/// Largest accepted error of f |wi.z| (relative to the largest channel, or 1e-3) and of
/// the pdf (relative, or to 1e-3).
const TOLERANCE: f64 = 1e-3;

#[test]
fn huang_f32_against_f64_reference() {
    let mut g = rng(2022);
    let (mut worst_f, mut worst_pdf) = (0.0f64, 0.0f64);
    for _ in 0..3000 {
        let roughness: f32 = g.random_range(0.05..1.0);
        let aspect: f32 = g.random_range(0.3..1.0);
        let eta: f32 = g.random_range(1.2..2.0);
        let alpha: f32 = g.random_range(-10.0..10.0);
        let sigma = [g.random_range(0.0..2.0), 0.5, 0.0];
        let b = huang(sigma, eta, roughness, aspect, alpha);
        let h: f32 = g.random_range(-0.98..0.98);
        let turn: f32 = g.random_range(0.0..std::f32::consts::TAU);
        let jitter: [f32; 2] = [g.random(), g.random()];
        let dir = |g: &mut rand_pcg::Pcg64| {
            let z: f32 = g.random_range(-0.95..0.95);
            let phi: f32 = g.random_range(0.0..std::f32::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            Vec3::new(z, r * phi.cos(), r * phi.sin())
        };
        let wo = dir(&mut g);
        let shifts = [1, 1, 1, 1, 2, 2, 4][g.random_range(0..7)];
        let p = point(&b, shifts, h, wo, Vec2::from_angle(turn), jitter);
        // Directions near the lobes: sampled ones, and one at random.
        let mut wis = vec![dir(&mut g)];
        for _ in 0..3 {
            if let Some(s) = p.sample(random_u(&mut g)) {
                wis.push(s.wi);
            }
        }
        let (s, c) = (f64::from(turn)).sin_cos();
        let reference = RefHuang::new(
            sigma.map(f64::from),
            eta.into(),
            roughness.into(),
            aspect.into(),
            alpha.into(),
        );
        let d3 = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
        for wi in wis {
            let e = p.eval(wi);
            let (rf, rp) = reference.eval(shifts, h, d3(wo), d3(wi), [c, s], jitter);
            let scale = rf.iter().cloned().fold(0.0, f64::max).max(1e-3);
            let fc = e.f * wi.z.abs();
            for c in 0..3 {
                let err = (f64::from(fc[c]) - rf[c]).abs() / scale;
                worst_f = worst_f.max(err);
                assert!(
                    err < TOLERANCE,
                    "f[{c}] {} vs {} at {b:?} h {h} wo {wo} wi {wi} shifts {shifts}",
                    fc[c],
                    rf[c]
                );
            }
            let err = (f64::from(e.pdf) - rp).abs() / rp.max(1e-3);
            worst_pdf = worst_pdf.max(err);
            assert!(
                err < TOLERANCE,
                "pdf {} vs {rp} at {b:?} h {h} wo {wo} wi {wi} shifts {shifts}",
                e.pdf
            );
        }
    }
    println!("largest relative error: f {worst_f:.2e}, pdf {worst_pdf:.2e}");
}
