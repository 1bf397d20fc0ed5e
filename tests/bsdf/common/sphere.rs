//! Directions on the sphere in the fiber frame (x = tangent), random directions of the
//! kinds the tests need, and f32-ulp perturbations used to measure conditioning.

use rand::Rng;
use std::f64::consts::PI;

/// Unit direction with sin(theta) = x and phi = atan2(z, y).
pub fn dir(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st, ct * cp, ct * sp]
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

pub fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// Uniform direction on the unit sphere.
pub fn uniform_sphere(rng: &mut impl Rng) -> [f64; 3] {
    let z: f64 = rng.random_range(-1.0..=1.0);
    let phi: f64 = rng.random_range(-PI..PI);
    let r = ((1.0 - z) * (1.0 + z)).sqrt();
    [z, r * phi.cos(), r * phi.sin()]
}

/// Rotation of v by `angle` about the unit axis k (Rodrigues).
pub fn rotate(v: [f64; 3], k: [f64; 3], angle: f64) -> [f64; 3] {
    let (s, c) = angle.sin_cos();
    let kxv = cross(k, v);
    let kv = dot(k, v);
    [
        v[0] * c + kxv[0] * s + k[0] * kv * (1.0 - c),
        v[1] * c + kxv[1] * s + k[1] * kv * (1.0 - c),
        v[2] * c + kxv[2] * s + k[2] * kv * (1.0 - c),
    ]
}

/// v rotated by exactly `angle` about a random axis perpendicular to v.
pub fn tilt(v: [f64; 3], angle: f64, rng: &mut impl Rng) -> [f64; 3] {
    loop {
        let k = cross(v, uniform_sphere(rng));
        if norm(k) > 1e-3 {
            return normalize(rotate(v, normalize(k), angle));
        }
    }
}

/// The f32 `steps` ulps away from x (negative steps go down); +-0 handled.
pub fn f32_step(x: f32, steps: i32) -> f32 {
    let mut y = x;
    for _ in 0..steps.unsigned_abs() {
        y = if steps > 0 { next_up(y) } else { next_down(y) };
    }
    y
}

fn next_up(x: f32) -> f32 {
    if x.is_nan() || x == f32::INFINITY {
        return x;
    }
    if x == 0.0 {
        return f32::from_bits(1);
    }
    let b = x.to_bits();
    f32::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

fn next_down(x: f32) -> f32 {
    -next_up(-x)
}

/// Rounds a direction to f32 (as the crate receives it).
pub fn round_f32(w: [f64; 3]) -> [f32; 3] {
    [w[0] as f32, w[1] as f32, w[2] as f32]
}

/// Widens an f32 direction to f64 (exactly).
pub fn widen(w: [f32; 3]) -> [f64; 3] {
    [w[0] as f64, w[1] as f64, w[2] as f64]
}

/// Every component moved by -1, 0 or +1 ulp at random: one of the f32 vectors that are
/// as good a rounding of the same unit direction as `w` itself.
pub fn ulp_jitter(w: [f32; 3], rng: &mut impl Rng) -> [f32; 3] {
    w.map(|c| f32_step(c, rng.random_range(-1..=1)))
}
