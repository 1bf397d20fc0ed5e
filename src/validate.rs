//! The checks every input goes through, written once so that each refusal reads the same:
//! `name = value: must be ...`, naming what the caller called it.

use crate::error::{Result, invalid_arg};

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

/// Every channel of every colour is finite and >= 0; the error names the first bad one.
pub(crate) fn colors(colors: &[[f32; 3]]) -> Result<()> {
    match colors
        .iter()
        .position(|c| !c.iter().all(|v| v.is_finite() && *v >= 0.0))
    {
        Some(i) => Err(invalid_arg!(
            "colour {i} = {:?}: must be finite and >= 0",
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
        assert!(colors(&[[0.0, 1.0, 2.0]]).is_ok());
        let e = colors(&[[0.0; 3], [0.0, f32::NAN, 0.0]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("colour 1"), "{e}");
    }
}
