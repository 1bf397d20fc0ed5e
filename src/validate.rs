//! The checks every input goes through, written once so that each refusal reads the same:
//! `name = value: must be ...`, naming what the caller called it.

use crate::error::{Result, invalid_arg};
use glam::Vec3;

/// The largest magnitude, in world units, of a coordinate or a camera length the library
/// accepts. Embree refuses rays whose origin or direction has a component beyond about
/// 1.8e18 (and aborts on them); positions a thousand times below that keep every ray the
/// renderer forms between them (camera, lens, hits, lights) well inside.
pub const MAX_COORDINATE: f32 = 1e15;

/// Relative difference between the scales of the three axes, and between their directions
/// and right angles, above which a linear map is not a uniform scale.
const UNIFORM_SCALE_TOLERANCE: f64 = 1e-4;

/// The scale of a linear map given by the images of the three axes, when it scales them
/// alike (turns and mirrors allowed): radii can follow such a scale and fibres stay round.
/// Else an error naming `what` and the three scales.
pub(crate) fn uniform_scale(what: &str, axes: [[f64; 3]; 3]) -> Result<f64> {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let s = axes.map(|a| dot(a, a).sqrt());
    let mean = (s[0] + s[1] + s[2]) / 3.0;
    let tol = UNIFORM_SCALE_TOLERANCE * mean;
    let skew = [(0, 1), (1, 2), (0, 2)].map(|(i, j)| dot(axes[i], axes[j]).abs());
    if !(mean.is_finite() && mean > 0.0)
        || s.iter().any(|x| (x - mean).abs() > tol)
        || skew.iter().any(|&d| d > tol * mean)
    {
        return Err(invalid_arg!(
            "{what} scales the axes by {s:?} (or shears them): radii can follow a uniform \
             scale only"
        ));
    }
    Ok(mean)
}

/// `v` is finite and > 0.
pub(crate) fn positive(name: &str, v: f32) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(invalid_arg!("{name} = {v}: must be finite and > 0"))
    }
}

/// `v` is finite and >= 0.
pub(crate) fn non_negative(name: &str, v: f32) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(invalid_arg!("{name} = {v}: must be finite and >= 0"))
    }
}

/// `v` is finite and its magnitude at most [`MAX_COORDINATE`].
pub(crate) fn length(name: &str, v: f32) -> Result<()> {
    if v.is_finite() && v.abs() <= MAX_COORDINATE {
        Ok(())
    } else {
        Err(invalid_arg!(
            "{name} = {v}: must be finite and within +-{MAX_COORDINATE:e}"
        ))
    }
}

/// Every component of `v` is finite and within +-[`MAX_COORDINATE`].
pub(crate) fn position(name: &str, v: Vec3) -> Result<()> {
    if v.is_finite() && v.abs().max_element() <= MAX_COORDINATE {
        Ok(())
    } else {
        Err(invalid_arg!(
            "{name} = {v}: every coordinate must be finite and within +-{MAX_COORDINATE:e}"
        ))
    }
}

/// The first of `points` (x, y, z first) that [`position`] refuses, named `{what} {i}`.
pub(crate) fn positions<const N: usize>(what: &str, points: &[[f32; N]]) -> Result<()> {
    let xyz = |p: &[f32; N]| Vec3::new(p[0], p[1], p[2]);
    match points.iter().position(|p| position("", xyz(p)).is_err()) {
        Some(i) => position(&format!("{what} {i}"), xyz(&points[i])),
        None => Ok(()),
    }
}

/// `v` scaled to unit length; any finite non-zero vector has a direction, even one whose
/// squared length overflows (it is scaled down first).
pub(crate) fn direction(name: &str, v: Vec3) -> Result<Vec3> {
    let largest = v.abs().max_element();
    if !v.is_finite() || largest == 0.0 {
        return Err(invalid_arg!(
            "{name} = {v}: must be finite and not zero (it is a direction)"
        ));
    }
    Ok((v / largest).normalize())
}

/// Every channel of every colour is finite and in [0, 1] (a reflectance: hair colours
/// become absorption); the error names the first bad one.
pub(crate) fn colors(colors: &[[f32; 3]]) -> Result<()> {
    match colors
        .iter()
        .position(|c| !c.iter().all(|v| (0.0..=1.0).contains(v)))
    {
        Some(i) => Err(invalid_arg!(
            "colour {i} = {:?}: each channel must be in [0, 1] (a reflectance)",
            colors[i]
        )),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_name_the_value() {
        assert!(positive("r", 1e-30).is_ok() && non_negative("r", 0.0).is_ok());
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = positive("radius", bad).unwrap_err().to_string();
            assert!(e.contains("radius = ") && e.contains("> 0"), "{e}");
        }
        assert!(
            non_negative("s", -0.5)
                .unwrap_err()
                .to_string()
                .contains("s = -0.5")
        );
        assert!(colors(&[[0.0, 1.0, 0.5]]).is_ok());
        let e = colors(&[[0.0, 5.0, 0.5]]).unwrap_err().to_string();
        assert!(e.contains("colour 0") && e.contains("[0, 1]"), "{e}");
        assert!(length("focus", 1e15).is_ok() && length("focus", 2e15).is_err());
        let e = positions("point", &[[0.0; 4], [0.0, 1e19, 0.0, 1.0]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("point 1 = ") && e.contains("within"), "{e}");
        let d = direction("d", Vec3::new(1e30, 1e30, 0.0)).unwrap();
        assert!(
            (d - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6,
            "{d}"
        );
        let d = direction("d", Vec3::new(1e-30, 0.0, 0.0)).unwrap();
        assert_eq!(d, Vec3::X);
        assert!(direction("d", Vec3::ZERO).is_err());
        let e = colors(&[[0.0; 3], [0.0, f32::NAN, 0.0]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("colour 1"), "{e}");
    }
}
