//! Numerical building blocks of the hair model: the lane abstraction that lets one
//! implementation run on scalars and on SIMD vectors, and the special functions.

pub mod bessel;
pub mod curve_basis;
pub(crate) mod fast;
pub(crate) mod frame;
pub(crate) mod lanes;
pub(crate) mod sampling;
pub mod time_steps;

pub use curve_basis::{CurveBasis, CurveShape};
pub use frame::{Frame, hair_frame_offset};
pub use lanes::Lanes;
pub use time_steps::time_step;

/// A 64-bit finaliser with full avalanche (the SplitMix64 output function): nearby keys,
/// such as neighbouring pixels or strand ids, get unrelated hashes.
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Two numbers in [0, 1), unrelated to `u` and to other `n`'s: the top 24 bits and the 24
/// below them of `mix64` of u's bits (first << 32 | second) xor n x 2^64 over phi.
pub(crate) fn hashed_pair(u: [f32; 2], n: u64) -> [f32; 2] {
    let key = (u64::from(u[0].to_bits()) << 32) | u64::from(u[1].to_bits());
    let z = mix64(key ^ n.wrapping_mul(0x9e37_79b9_7f4a_7c15));
    let unit = |bits: u64| (bits >> 40) as f32 / (1u64 << 24) as f32;
    [unit(z), unit(z << 24)]
}

/// Rec. 709 luminance of linear RGB: the weight of a colour for importance sampling.
pub fn luminance(rgb: glam::Vec3) -> f32 {
    rgb.dot(glam::Vec3::new(0.2126, 0.7152, 0.0722))
}

/// sqrt that treats tiny negative round-off as zero instead of returning NaN.
#[inline(always)]
pub(crate) fn safe_sqrt<T: Lanes>(x: T) -> T {
    x.max(T::splat(0.0)).sqrt()
}

/// sqrt(1 - x^2) for x in [-1, 1], as (1 - x)(1 + x): near |x| = 1, 1 - x is exact where
/// 1 - x^2 would lose the low digits of x^2 (up to 2.5e-5 relative near x = 0.9998).
#[inline(always)]
pub(crate) fn cos_from_sin<T: Lanes>(x: T) -> T {
    let one = T::splat(1.0);
    safe_sqrt((one - x) * (one + x))
}
