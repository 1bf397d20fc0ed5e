//! No NaN, no infinity, no negative value anywhere in range: random parameters, offsets,
//! section turns and directions, with the hard cases mixed in (tangent-parallel and
//! grazing directions, wo = +-wi, h at the edges, the smallest aspect and roughness, the
//! largest tilt), and the stated rules for a major axis of no direction and a NaN h.

use super::{huang, point};
use crate::common::{random_u, rng};
use glam::{Vec2, Vec3};
use rand::Rng;

fn random_dir(g: &mut impl Rng) -> Vec3 {
    match g.random_range(0..8) {
        0 => Vec3::X * if g.random() { 1.0 } else { -1.0 },
        1 => Vec3::new(1.0, 1e-7, -1e-8).normalize(),
        2 => Vec3::new(0.0, g.random_range(-1.0..1.0), 1e-7).normalize_or(Vec3::Y),
        _ => {
            let z: f32 = g.random_range(-1.0..1.0);
            let phi: f32 = g.random_range(0.0..std::f32::consts::TAU);
            let r = (1.0 - z * z).sqrt();
            Vec3::new(z, r * phi.cos(), r * phi.sin())
        }
    }
}

#[test]
fn huang_sweep_is_finite() {
    let mut g = rng(4646);
    for i in 0..20_000 {
        let pick = |g: &mut rand_pcg::Pcg64, lo: f32, hi: f32, edge: bool| {
            if edge {
                if g.random() { lo } else { hi }
            } else {
                g.random_range(lo..=hi)
            }
        };
        let edge = i % 4 == 0;
        let sigma = if g.random() {
            [0.0; 3]
        } else {
            [g.random_range(0.0..20.0), 0.5, 3.0]
        };
        let b = huang(
            sigma,
            pick(&mut g, 1.0001, 3.0, edge),
            pick(&mut g, 0.01, 1.0, edge),
            pick(&mut g, 0.05, 1.0, edge),
            pick(&mut g, -20.0, 20.0, edge),
        );
        let h = match g.random_range(0..6) {
            0 => -1.0,
            1 => 1.0,
            2 => f32::NAN,
            _ => g.random_range(-1.0..1.0),
        };
        let major = match g.random_range(0..6) {
            0 => Vec2::ZERO,
            1 => Vec2::NAN,
            _ => Vec2::from_angle(g.random_range(0.0..7.0)),
        };
        let wo = random_dir(&mut g);
        let jitter = match g.random_range(0..5) {
            0 => [f32::NAN, 2.5],
            1 => [0.0, 0.99999994],
            _ => [g.random(), g.random()],
        };
        let p = point(&b, [1, 2, 4][g.random_range(0..3)], h, wo, major, jitter);
        let mut wis = vec![wo, -wo, random_dir(&mut g), random_dir(&mut g)];
        if let Some(s) = p.sample(random_u(&mut g)) {
            assert!(
                s.pdf > 0.0 && s.f.is_finite() && s.f.min_element() >= 0.0,
                "{b:?} {h} {wo} {s:?}"
            );
            let w = s.f * s.wi.z.abs() / s.pdf;
            assert!(w.is_finite(), "{b:?} {h} {wo} {s:?}");
            assert!((s.wi.length() - 1.0).abs() < 1e-3, "{b:?} {h} {wo} {s:?}");
            wis.push(s.wi);
        }
        for wi in wis {
            let e = p.eval(wi);
            assert!(
                e.f.is_finite() && e.f.min_element() >= 0.0 && e.pdf.is_finite() && e.pdf >= 0.0,
                "{b:?} h {h} wo {wo} wi {wi}: {e:?}"
            );
        }
    }
}

/// A major axis of no direction is y, a NaN h is 0, a jitter is taken modulo 1 and one
/// that is not finite is 0 (docs/conventions.md, section 4b).
#[test]
fn huang_stated_rules() {
    let b = huang([0.3; 3], 1.55, 0.3, 0.6, 2.0);
    let wo = Vec3::new(0.2, 0.0, 0.98).normalize();
    let wi = Vec3::new(-0.1, 0.7, 0.3).normalize();
    let j = [0.25, 0.5];
    let want = b.near(0.4, wo, Vec2::X, j).eval(wi);
    assert_eq!(b.near(0.4, wo, Vec2::ZERO, j).eval(wi), want);
    assert_eq!(b.near(0.4, wo, Vec2::NAN, j).eval(wi), want);
    // Modulo 1 up to the rounding of the shifted nodes.
    let shifted = b.near(0.4, wo, Vec2::X, [1.25, -0.5]).eval(wi);
    assert!((shifted.f - want.f).abs().max_element() < 1e-5 * want.f.max_element());
    assert!((shifted.pdf - want.pdf).abs() < 1e-5 * want.pdf);
    let zero = b.near(0.4, wo, Vec2::X, [0.0; 2]).eval(wi);
    assert_eq!(
        b.near(0.4, wo, Vec2::X, [f32::NAN, f32::INFINITY]).eval(wi),
        zero
    );
    assert_eq!(
        b.near(f32::NAN, wo, Vec2::X, j).eval(wi),
        b.near(0.0, wo, Vec2::X, j).eval(wi)
    );
}
