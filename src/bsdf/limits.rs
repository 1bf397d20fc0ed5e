//! The ranges the hair model accepts, in one place: parameters, colour inversion and the
//! C ABI all check against these.

use crate::error::{Result, invalid_arg};
use crate::validate::non_negative;

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

/// Checks the parameters both hair models share: sigma_a (each channel finite, >= 0), eta
/// in (1, [`ETA_MAX`]] and the tilt alpha (degrees) within [`ALPHA_MAX_DEG`].
pub(crate) fn check_shared(sigma_a: &[f32; 3], eta: f32, alpha: f32) -> Result<()> {
    for (c, &s) in sigma_a.iter().enumerate() {
        non_negative(&format!("sigma_a[{c}]"), s)?;
    }
    if !(eta > 1.0 && eta <= ETA_MAX) {
        return Err(invalid_arg!("eta = {eta}: must be in (1, {ETA_MAX}]"));
    }
    if alpha.is_nan() || alpha.abs() > ALPHA_MAX_DEG {
        return Err(invalid_arg!(
            "alpha = {alpha} degrees: must be in [-{ALPHA_MAX_DEG}, {ALPHA_MAX_DEG}]"
        ));
    }
    Ok(())
}
