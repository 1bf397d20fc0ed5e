//! The checks every host's entry point makes on a call's BSDF inputs (the C ABI's, the
//! Python package's): the model clamps h and reads angles from a direction's components,
//! so an input outside its domain would give a wrong value silently rather than an error.
//! The compares are inline, for loops over batches; the messages out of line.

use super::huang::MIN_ACROSS_SQUARED;
use crate::error::{Error, Result, invalid_arg};
use glam::{Vec2, Vec3};

/// Largest accepted |length - 1| of a direction.
pub const UNIT_TOLERANCE: f32 = 1e-3;

/// Whether `v` is a finite unit vector to [`UNIT_TOLERANCE`]; false for NaN.
#[inline(always)]
pub fn is_unit(v: Vec3) -> bool {
    // Squared length against the squared bounds: no square root on the hot path.
    let (lo, hi) = (
        (1.0 - UNIT_TOLERANCE).powi(2),
        (1.0 + UNIT_TOLERANCE).powi(2),
    );
    let len2 = v.length_squared();
    len2 >= lo && len2 <= hi
}

/// `v` if it is a finite unit vector (to [`UNIT_TOLERANCE`]); `name` names it in the error.
#[inline(always)]
pub fn check_dir(v: Vec3, name: &str) -> Result<Vec3> {
    if is_unit(v) {
        Ok(v)
    } else {
        Err(not_unit(v, name))
    }
}

#[cold]
#[inline(never)]
fn not_unit(v: Vec3, name: &str) -> Error {
    invalid_arg!(
        "{name} = {v}: must be a finite unit vector (length {}, tolerance {UNIT_TOLERANCE})",
        v.length()
    )
}

/// `h` if it is in [-1, 1].
#[inline(always)]
pub fn check_h(h: f32) -> Result<f32> {
    if (-1.0..=1.0).contains(&h) {
        Ok(h)
    } else {
        Err(not_in_range(h))
    }
}

#[cold]
#[inline(never)]
fn not_in_range(h: f32) -> Error {
    invalid_arg!("h = {h}: must be in [-1, 1]")
}

/// `u` if its numbers are in [0, 1) (a sample's three, a Huang point's two of jitter).
#[inline(always)]
pub fn check_u<const N: usize>(u: [f32; N], name: &str) -> Result<[f32; N]> {
    if u.iter().all(|x| (0.0..1.0).contains(x)) {
        Ok(u)
    } else {
        Err(not_uniform(&u, name))
    }
}

#[cold]
#[inline(never)]
fn not_uniform(u: &[f32], name: &str) -> Error {
    let bad = u.iter().position(|x| !(0.0..1.0).contains(x)).unwrap_or(0);
    invalid_arg!("{name}[{bad}] = {}: must be in [0, 1)", u[bad])
}

/// The (y, z) direction of an elliptical section's major axis `major` (in the hair frame),
/// for [`crate::HuangBsdf::near`]: refused where it is not finite, or lies along the fibre
/// (zero included), where the model's fallback would turn the section silently. The
/// message shows `given`, the axis as the caller gave it (in its own frame).
#[inline(always)]
pub fn check_major(major: Vec3, given: Vec3, name: &str) -> Result<Vec2> {
    let across = Vec2::new(major.y, major.z);
    let usable =
        major.is_finite() && across.length_squared() > MIN_ACROSS_SQUARED * major.length_squared();
    if usable {
        Ok(across)
    } else {
        Err(not_across(given, name))
    }
}

#[cold]
#[inline(never)]
fn not_across(major: Vec3, name: &str) -> Error {
    if major.is_finite() {
        invalid_arg!(
            "{name} = {major}: lies along the fibre (or is zero): the major axis must point \
             across it"
        )
    } else {
        invalid_arg!("{name} = {major}: must be finite")
    }
}
