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

/// The near or far point.
pub fn point(
    b: &HuangBsdf,
    far: bool,
    h: f32,
    wo: Vec3,
    major: Vec2,
    jitter: [f32; 2],
) -> HuangPoint {
    if far {
        b.far(h, wo, major, jitter)
    } else {
        b.near(h, wo, major, jitter)
    }
}
