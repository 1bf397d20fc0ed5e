//! Where the absorption coefficient sigma_a comes from: melanin concentrations, or a
//! desired diffuse-looking colour.

use super::limits::check_beta;
use crate::error::{Result, invalid_arg};
use crate::validate::non_negative;

/// Absorption of eumelanin and pheomelanin per unit concentration, linear RGB, per unit
/// fiber radius (d'Eon et al. 2011, as used by Chiang et al. 2016 and pbrt).
const EUMELANIN_SIGMA_A: [f32; 3] = [0.419, 0.697, 1.37];
const PHEOMELANIN_SIGMA_A: [f32; 3] = [0.187, 0.4, 1.05];

/// Named absorptions (sigma_a per unit fiber radius, linear RGB) of common hair colours,
/// the ones the scene format, the CLI and the C ABI take by name.
pub const SIGMA_A_PRESETS: [(&str, [f32; 3]); 5] = [
    ("red_brown", [0.09, 1.3, 2.6]),
    ("light_brown", [0.6, 1.3, 2.0]),
    ("dark_brown", [0.9, 1.28, 2.66]),
    ("black", [2.9, 5.1, 10.2]),
    ("white", [0.08, 0.09, 0.18]),
];

/// The sigma_a of the preset `name` (see [`SIGMA_A_PRESETS`]); an unknown name is an
/// error that lists the known ones.
pub fn sigma_a_preset(name: &str) -> Result<[f32; 3]> {
    SIGMA_A_PRESETS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, sigma_a)| sigma_a)
        .ok_or_else(|| {
            let names: Vec<&str> = SIGMA_A_PRESETS.iter().map(|(n, _)| *n).collect();
            invalid_arg!(
                "preset = {name:?}: no such absorption preset (known: {})",
                names.join(", ")
            )
        })
}

/// sigma_a from eumelanin and pheomelanin concentrations (finite, >= 0). About 8 is jet
/// black, 1.3 brown, 0.3 blonde; pheomelanin adds red.
pub fn sigma_a_from_melanin(eumelanin: f32, pheomelanin: f32) -> Result<[f32; 3]> {
    non_negative("eumelanin", eumelanin)?;
    non_negative("pheomelanin", pheomelanin)?;
    let sigma_a: [f32; 3] = std::array::from_fn(|i| {
        eumelanin * EUMELANIN_SIGMA_A[i] + pheomelanin * PHEOMELANIN_SIGMA_A[i]
    });
    // Finite inputs near f32::MAX overflow to an infinite sigma_a that the BSDF would
    // refuse later; refuse it here, where the cause is known.
    if !sigma_a.iter().all(|s| s.is_finite()) {
        return Err(invalid_arg!(
            "eumelanin = {eumelanin}, pheomelanin = {pheomelanin}: sigma_a overflows to \
             infinity (about 8 is jet black)"
        ));
    }
    Ok(sigma_a)
}

/// sigma_a that makes a fiber look like the reflectance `color` (each channel in (0, 1])
/// for azimuthal roughness beta_n: Chiang et al. 2016's fit,
/// sigma_a = (ln c / (5.969 - 0.215 b + 2.532 b^2 - 10.73 b^3 + 5.574 b^4 + 0.245 b^5))^2.
pub fn sigma_a_from_color(color: [f32; 3], beta_n: f32) -> Result<[f32; 3]> {
    check_beta("beta_n", beta_n)?;
    for (i, &c) in color.iter().enumerate() {
        if !(c > 0.0 && c <= 1.0) {
            let why = if c > 1.0 {
                "a fibre cannot reflect more than it receives"
            } else if c <= 0.0 {
                "0 would need infinite absorption"
            } else {
                "not a number"
            };
            return Err(invalid_arg!("color[{i}] = {c}: must be in (0, 1] ({why})"));
        }
    }
    let d = color_fit(beta_n);
    Ok(color.map(|c| {
        let r = f64::from(c).ln() / d;
        (r * r) as f32
    }))
}

/// The reflectance colour a fiber of absorption sigma_a looks like at roughness beta_n:
/// the inverse of [`sigma_a_from_color`] (for AOVs and previews; not range-checked).
pub(crate) fn color_from_sigma_a(sigma_a: [f32; 3], beta_n: f32) -> [f32; 3] {
    let d = color_fit(beta_n);
    sigma_a.map(|s| (-f64::from(s.max(0.0)).sqrt() * d).exp() as f32)
}

/// The denominator of Chiang's colour fit, a polynomial in beta_n.
fn color_fit(beta_n: f32) -> f64 {
    let b = f64::from(beta_n);
    5.969 - 0.215 * b + 2.532 * b.powi(2) - 10.73 * b.powi(3)
        + 5.574 * b.powi(4)
        + 0.245 * b.powi(5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn melanin_is_linear_and_checked() {
        let s = sigma_a_from_melanin(2.0, 1.0).unwrap();
        for i in 0..3 {
            let want = 2.0 * EUMELANIN_SIGMA_A[i] + PHEOMELANIN_SIGMA_A[i];
            assert!((s[i] - want).abs() < 1e-6);
        }
        assert!(sigma_a_from_melanin(-1.0, 0.0).is_err());
        let e = sigma_a_from_melanin(0.0, f32::NAN).unwrap_err().to_string();
        assert!(e.contains("pheomelanin"), "{e}");
        // Finite but overflowing concentrations are refused, not turned into inf.
        let e = sigma_a_from_melanin(f32::MAX, f32::MAX)
            .unwrap_err()
            .to_string();
        assert!(e.contains("overflows"), "{e}");
        assert!(sigma_a_from_melanin(1e37, 0.0).unwrap()[2].is_finite());
    }

    #[test]
    fn color_inversion_orders_and_limits() {
        // White needs no absorption; darker channels need more.
        assert_eq!(sigma_a_from_color([1.0; 3], 0.3).unwrap(), [0.0; 3]);
        let s = sigma_a_from_color([0.8, 0.5, 0.2], 0.3).unwrap();
        assert!(s[0] < s[1] && s[1] < s[2]);
        assert!(sigma_a_from_color([0.0, 0.5, 0.5], 0.3).is_err());
        let e = sigma_a_from_color([0.5, 1.5, 0.5], 0.3)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("color[1] = 1.5") && e.contains("more than"),
            "{e}"
        );
        let back = color_from_sigma_a(s, 0.3);
        for (b, c) in back.iter().zip([0.8, 0.5, 0.2]) {
            assert!((b - c).abs() < 1e-5, "{back:?}");
        }
        let e = sigma_a_from_color([0.5; 3], 0.0).unwrap_err().to_string();
        assert!(e.contains("beta_n"), "{e}");
    }
}
