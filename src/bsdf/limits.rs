//! The ranges the hair model accepts, in one place: parameters, colour inversion and the
//! C ABI all check against these.

use crate::error::{Result, invalid_arg};

/// Valid range of both roughnesses.
pub(crate) const BETA_RANGE: (f32, f32) = (0.01, 1.0);
/// Largest accepted index of refraction (the lower bound 1 is excluded).
pub(crate) const ETA_MAX: f32 = 3.0;
/// Smallest accepted aspect (minor over major axis) of an elliptical fibre: thinner is a
/// ribbon, which the flat curves model.
pub(crate) const ASPECT_MIN: f32 = 0.05;
/// Largest accepted |alpha| in degrees.
pub(crate) const ALPHA_MAX_DEG: f32 = 20.0;

/// Checks a roughness against [`BETA_RANGE`]; `name` goes into the message.
pub(crate) fn check_beta(name: &str, beta: f32) -> Result<()> {
    let (lo, hi) = BETA_RANGE;
    if beta >= lo && beta <= hi {
        Ok(())
    } else {
        Err(invalid_arg!("{name} = {beta}: must be in [{lo}, {hi}]"))
    }
}
