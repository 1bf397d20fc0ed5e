//! The Huang model (`HuangBsdf`): sampling against its pdf (chi-square), the energy of a
//! non-absorbing fibre (furnace), finite values over the whole input range, and the f32
//! evaluation against an f64 reference.

mod chi2;
mod furnace;
mod reference;
mod sweep;

use glam::{Vec2, Vec3};
use hairtrace::{HuangBsdf, HuangParams, HuangPoint};

pub fn huang(sigma_a: [f32; 3], eta: f32, roughness: f32, aspect: f32, alpha: f32) -> HuangBsdf {
    let p = HuangParams {
        sigma_a,
        eta,
        roughness,
        aspect,
        alpha,
    };
    HuangBsdf::new(&p).unwrap_or_else(|e| panic!("HuangBsdf::new({p:?}): {e}"))
}

/// The point of `shifts` offsets: 1 the near field, 2 the far field, 4 the far field
/// that weighs sampled lights.
pub fn point(
    b: &HuangBsdf,
    shifts: usize,
    h: f32,
    wo: Vec3,
    major: Vec2,
    jitter: [f32; 2],
) -> HuangPoint {
    match shifts {
        1 => b.near(h, wo, major, jitter),
        2 => b.far(h, wo, major, jitter),
        4 => b.far_lit(h, wo, major, jitter),
        _ => panic!("no Huang point of {shifts} offsets"),
    }
}
