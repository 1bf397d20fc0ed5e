//! exp and atan2 (and ln, for the samplers) for the BSDF's hot path, written once over [`Lanes`] so that the
//! scalar and the batched evaluation compute the same bits. They use the classic range
//! reductions with short polynomials (Cephes' coefficients for atan, the Taylor
//! series of e^r on |r| <= ln2/2) and cost no function call: about 2 ulp, measured
//! against f64 in the unit tests below.

// Coefficients are quoted as published, digits beyond f32 included.
#![allow(clippy::excessive_precision)]

use super::Lanes;
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, LOG2_E, PI};

/// Nearest integer (ties to even) for |x| < 2^22: adding and removing 1.5 * 2^23 drops
/// the fraction bits, with no libm call (baseline x86-64 has no rounding instruction).
#[inline(always)]
pub fn round<T: Lanes>(x: T) -> T {
    let magic = T::splat(12_582_912.0);
    (x + magic) - magic
}

/// e^x for x <= 0 (every exponent in the hair model is): 0 below -87.3, where f32 would
/// go subnormal.
#[inline(always)]
pub(crate) fn exp_neg<T: Lanes>(x: T) -> T {
    const LOWEST: f32 = -87.33;
    let c = T::splat;
    let xc = x.max(c(LOWEST)).min(c(0.0));
    let n = round(xc * c(LOG2_E));
    // ln 2 split in a short high part (exact times n) and the rest.
    let r = xc - n * c(0.693_359_4) - n * c(-2.121_944_4e-4);
    let p = c(1.0)
        + r * (c(1.0)
            + r * (c(0.5)
                + r * (c(1.0 / 6.0)
                    + r * (c(1.0 / 24.0)
                        + r * (c(1.0 / 120.0) + r * (c(1.0 / 720.0) + r * c(1.0 / 5040.0)))))));
    T::select(x.lt(c(LOWEST)), c(0.0), p * n.pow2i())
}

/// atan2(y, x) with the conventions of `f32::atan2`, signed zeros included.
#[inline(always)]
pub fn atan2<T: Lanes>(y: T, x: T) -> T {
    let c = T::splat;
    let (ax, ay) = (x.abs(), y.abs());
    let steep = ay.gt(ax);
    let num = T::select(steep, ax, ay);
    let den = T::select(steep, ay, ax);
    // atan(num / den) on [0, 1]: above tan(pi/8) it is pi/4 + atan((num - den) / (num +
    // den)), so that one division serves both ranges (num - den is exact near num = den).
    let reduce = num.gt(c(0.414_213_57) * den);
    let base = T::select(reduce, c(FRAC_PI_4), c(0.0));
    let n = T::select(reduce, num - den, num);
    let d = T::select(reduce, num + den, den);
    let t = T::select(d.gt(c(0.0)), n / d, c(0.0));
    let z = t * t;
    let a = base
        + (((c(8.053_744_5e-2) * z - c(1.387_768_5e-1)) * z + c(1.997_771_1e-1)) * z
            - c(3.333_294_9e-1))
            * z
            * t
        + t;
    let a = T::select(steep, c(FRAC_PI_2) - a, a);
    let left = c(1.0).copysign(x).lt(c(0.0));
    T::select(left, c(PI) - a, a).copysign(y)
}

/// ln(x) for finite x > 0 (scalar: only the samplers need it): x = m 2^e with m in
/// [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s) with s = (m - 1) / (m + 1), |s| < 0.172, from
/// its odd series to s^9. 0 gives -inf; subnormals are scaled up first.
#[inline(always)]
pub(crate) fn ln(x: f32) -> f32 {
    if x <= 0.0 {
        return if x == 0.0 {
            f32::NEG_INFINITY
        } else {
            f32::NAN
        };
    }
    let (x, bias) = if x < f32::MIN_POSITIVE {
        (x * 16_777_216.0, -24)
    } else {
        (x, 0)
    };
    let bits = x.to_bits() as i32;
    // Exponent relative to sqrt(1/2), so that the mantissa lands around 1.
    let e = (bits - 0x3f35_04f3) >> 23;
    let m = f32::from_bits((bits - (e << 23)) as u32);
    let e = e + bias;
    let s = (m - 1.0) / (m + 1.0);
    let z = s * s;
    let series = 2.0 * s * (1.0 + z * (1.0 / 3.0 + z * (0.2 + z * (1.0 / 7.0 + z * (1.0 / 9.0)))));
    e as f32 * std::f32::consts::LN_2 + series
}

#[cfg(test)]
mod tests {
    use super::*;
    use wide::f32x8;

    #[test]
    fn exp_is_accurate_and_underflows_to_zero() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -87.0 * i as f32 / 200_000.0;
            let want = f64::from(x).exp();
            worst = worst.max((f64::from(exp_neg(x)) - want).abs() / want);
        }
        assert!(worst < 3e-7, "exp worst relative error {worst}");
        assert_eq!(exp_neg(0.0f32), 1.0);
        assert_eq!(exp_neg(-100.0f32), 0.0);
        assert_eq!(exp_neg(f32::NEG_INFINITY), 0.0);
    }

    #[test]
    fn atan2_is_accurate_in_every_quadrant() {
        let mut worst = 0.0f64;
        for i in 0..2000 {
            let a = -3.2 + 6.4 * i as f64 / 2000.0;
            for r in [1e-30f64, 1e-3, 1.0, 1e20] {
                let (y, x) = ((r * a.sin()) as f32, (r * a.cos()) as f32);
                let want = f64::from(y).atan2(f64::from(x));
                worst = worst.max((f64::from(atan2(y, x)) - want).abs());
            }
        }
        assert!(worst < 5e-7, "atan2 worst absolute error {worst}");
        // Small angles keep their relative precision: the BSDF's azimuthal offsets are
        // atan2 of small cross products, in the narrow logistics' tails.
        let mut worst_rel = 0.0f64;
        for i in 0..=4000 {
            let a = 10f64.powf(-7.0 + 6.5 * i as f64 / 4000.0);
            for (y, x) in [(a.sin(), a.cos()), (-a.sin(), -a.cos())] {
                let (y, x) = (y as f32, x as f32);
                let want = f64::from(y).atan2(f64::from(x));
                let got = f64::from(atan2(y, x));
                worst_rel = worst_rel.max(((got - want) / want).abs());
            }
        }
        println!("atan2 worst relative error at small angles {worst_rel:.2e}");
        assert!(
            worst_rel < 3e-7,
            "atan2 worst relative error at small angles {worst_rel}"
        );
        for (y, x) in [
            (0.0f32, 0.0f32),
            (0.0, -0.0),
            (-0.0, -0.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (1.0, 0.0),
        ] {
            assert_eq!(
                atan2(y, x).to_bits(),
                y.atan2(x).to_bits(),
                "atan2({y}, {x})"
            );
        }
    }

    #[test]
    fn ln_is_accurate_over_the_whole_range() {
        let mut worst = 0.0f64;
        let mut x = 1e-44f32;
        while x < 1e38 {
            for k in 0..64 {
                let v = x * (1.0 + k as f32 / 64.0);
                let want = f64::from(v).ln();
                worst = worst.max((f64::from(ln(v)) - want).abs() / want.abs().max(1.0));
            }
            x *= 2.0;
        }
        assert!(worst < 3e-7, "ln worst error {worst}");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(0.0), f32::NEG_INFINITY);
        assert!(ln(-1.0).is_nan());
    }

    #[test]
    fn round_is_to_nearest() {
        for (x, r) in [
            (0.4f32, 0.0f32),
            (0.6, 1.0),
            (-2.6, -3.0),
            (1e6 + 0.7, 1e6 + 1.0),
        ] {
            assert_eq!(round(x), r);
        }
    }

    /// The batch path relies on this: eight lanes give the scalar function's bits.
    #[test]
    fn vector_lanes_equal_scalar_bits() {
        let xs: [f32; 8] = [-0.0, -1e-8, -0.3, -1.0, -17.5, -60.0, -87.2, -90.0];
        let ys: [f32; 8] = [0.0, -0.0, 0.3, -0.7, 1.0, -1.0, 0.999, 0.5];
        let e = exp_neg(f32x8::new(xs)).to_array();
        let t = atan2(f32x8::new(ys), f32x8::new(xs)).to_array();
        for k in 0..8 {
            assert_eq!(e[k].to_bits(), exp_neg(xs[k]).to_bits());
            assert_eq!(t[k].to_bits(), atan2(ys[k], xs[k]).to_bits());
        }
    }
}
