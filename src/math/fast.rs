//! Inline scalar exp, asin and atan2 for the BSDF's hot path. The libm calls cost a
//! function call each (13 per evaluation) and handle errno and cases the model never
//! reaches. These use the classic range reductions with short polynomials (Cephes'
//! coefficients for asin and atan; the Taylor series for exp on |r| <= ln2/2): about
//! 2 ulp, measured against f64 in the unit tests below.

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Rounds to the nearest integer (ties to even) for |x| < 2^22 without a libm call:
/// adding and removing 1.5 * 2^23 drops the fraction bits.
#[inline(always)]
pub fn round(x: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0;
    (x + MAGIC) - MAGIC
}

/// e^x; 0 below -87.3 (where f32 goes subnormal), +inf above 88.7, NaN for NaN.
#[inline(always)]
pub fn exp(x: f32) -> f32 {
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    if !(x > -87.33) {
        return if x.is_nan() { x } else { 0.0 };
    }
    if x > 88.72 {
        return f32::INFINITY;
    }
    let n = round(x * std::f32::consts::LOG2_E);
    let r = x - n * LN2_HI - n * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0
                    + r * (1.0 / 24.0
                        + r * (1.0 / 120.0 + r * (1.0 / 720.0 + r * (1.0 / 5040.0)))))));
    // 2^n through the exponent bits; n in [-126, 128], split in two to stay in range.
    let n = n as i32;
    let half = n / 2;
    let pow = |k: i32| f32::from_bits(((k + 127) as u32) << 23);
    p * pow(half) * pow(n - half)
}

/// asin(x) for x in [-1, 1].
#[inline(always)]
pub fn asin(x: f32) -> f32 {
    let a = x.abs();
    let (z, s, big) = if a > 0.5 {
        let z = 0.5 * (1.0 - a);
        (z, z.sqrt(), true)
    } else {
        (a * a, a, false)
    };
    let p = ((((4.216_32e-2 * z + 2.418_131_1e-2) * z + 4.547_002_6e-2) * z + 7.495_300_3e-2) * z
        + 1.666_675_2e-1)
        * z
        * s
        + s;
    let r = if big { FRAC_PI_2 - 2.0 * p } else { p };
    r.copysign(x)
}

/// atan2(y, x) with the quadrant conventions of `f32::atan2` (atan2(0, 0) = 0).
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (num, den) = if ay > ax { (ax, ay) } else { (ay, ax) };
    let t = if den > 0.0 { num / den } else { 0.0 };
    // atan(t) for t in [0, 1]: reduce t > tan(pi/8) around pi/4.
    let (t, base) = if t > 0.414_213_57 {
        ((t - 1.0) / (t + 1.0), FRAC_PI_4)
    } else {
        (t, 0.0)
    };
    let z = t * t;
    let mut a = base
        + (((8.053_744_5e-2 * z - 1.387_768_5e-1) * z + 1.997_771_1e-1) * z - 3.333_294_9e-1)
            * z
            * t
        + t;
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if x < 0.0 {
        a = PI - a;
    }
    a.copysign(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f32, b: f64) -> f64 {
        (f64::from(a) - b).abs() / b.abs().max(1e-30)
    }

    #[test]
    fn exp_is_accurate_and_saturates() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -87.0 + 175.0 * i as f32 / 200_000.0;
            worst = worst.max(rel(exp(x), f64::from(x).exp()));
        }
        assert!(worst < 3e-7, "exp worst relative error {worst}");
        assert_eq!(exp(-100.0), 0.0);
        assert_eq!(exp(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp(100.0), f32::INFINITY);
        assert!(exp(f32::NAN).is_nan());
    }

    #[test]
    fn asin_is_accurate() {
        let mut worst = 0.0f64;
        for i in 0..=200_000 {
            let x = -1.0 + 2.0 * i as f32 / 200_000.0;
            let want = f64::from(x).asin();
            worst = worst.max((f64::from(asin(x)) - want).abs() / want.abs().max(1e-3));
        }
        assert!(worst < 3e-7, "asin worst error {worst}");
        assert_eq!(asin(1.0), FRAC_PI_2);
        assert_eq!(asin(0.0), 0.0);
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
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert_eq!(atan2(0.0, -1.0), PI);
        assert_eq!(atan2(1.0, 0.0), FRAC_PI_2);
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
}
