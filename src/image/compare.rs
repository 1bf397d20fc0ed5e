//! How far apart two renders of the same frame are: the error measure behind every
//! speed-against-error figure (efficiency = 1 / (RMSE^2 x seconds)).

use super::Image;
use crate::Result;
use crate::error::invalid_arg;

/// Differences between an image and a reference, over their RGB channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Root mean square of the per-channel differences.
    pub rmse: f64,
    /// Largest absolute per-channel difference.
    pub max_abs: f64,
    /// Mean of every RGB value of each image: a bias shows here first.
    pub mean: f64,
    pub reference_mean: f64,
}

/// Compares `image` with `reference`: same size, at least three channels each (the first
/// three are RGB; alpha and AOVs are ignored). Sums in f64, so that a 4k frame's RMSE does
/// not depend on summation order.
pub fn compare(image: &Image, reference: &Image) -> Result<Comparison> {
    let values = rgb_values(&[image, reference])?;
    let (a, b) = (&values[0], &values[1]);
    let n = a.len().max(1) as f64;
    let (mut sq, mut max_abs) = (0.0, 0.0f64);
    for (x, y) in a.iter().zip(b) {
        let d = x - y;
        sq += d * d;
        max_abs = max_abs.max(d.abs());
    }
    Ok(Comparison {
        rmse: (sq / n).sqrt(),
        max_abs,
        mean: a.iter().sum::<f64>() / n,
        reference_mean: b.iter().sum::<f64>() / n,
    })
}

/// The RGB values of renders of one frame, in f64, pixel by pixel: the images must have
/// the same size, at least three channels each (alpha and AOVs are ignored) and finite
/// values.
pub(super) fn rgb_values(images: &[&Image]) -> Result<Vec<Vec<f64>>> {
    let first = images
        .first()
        .ok_or_else(|| invalid_arg!("no images to compare"))?;
    for img in images {
        if (img.width, img.height) != (first.width, first.height) {
            return Err(invalid_arg!(
                "images differ in size: {}x{} against {}x{}",
                img.width,
                img.height,
                first.width,
                first.height
            ));
        }
        if img.channels < 3 {
            return Err(invalid_arg!(
                "RGB images needed: one has {} channels",
                img.channels
            ));
        }
    }
    images
        .iter()
        .map(|img| {
            let rgb: Vec<f64> = img
                .pixels
                .chunks_exact(img.channels)
                .flat_map(|p| p[..3].iter().map(|&v| f64::from(v)))
                .collect();
            match rgb.iter().find(|v| !v.is_finite()) {
                Some(v) => Err(invalid_arg!("images must be finite: found {v}")),
                None => Ok(rgb),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(pixels: Vec<f32>, channels: usize) -> Image {
        Image::new(2, 1, channels, pixels)
    }

    #[test]
    fn rmse_of_known_differences() {
        let a = image(vec![1.0, 2.0, 3.0, 0.0, 0.0, 0.0], 3);
        // Alpha is ignored.
        let b = image(vec![1.0, 2.0, 5.0, 9.0, 0.0, 0.0, 2.0, 7.0], 4);
        let c = compare(&a, &b).unwrap();
        assert!((c.rmse - (8.0f64 / 6.0).sqrt()).abs() < 1e-12, "{c:?}");
        assert_eq!(c.max_abs, 2.0);
        assert_eq!(c.mean, 1.0);
        assert!((c.reference_mean - 10.0 / 6.0).abs() < 1e-12);
        assert_eq!(compare(&a, &a).unwrap().rmse, 0.0);
    }

    #[test]
    fn mismatches_are_errors() {
        let a = image(vec![0.0; 6], 3);
        let wide = Image::new(3, 1, 3, vec![0.0; 9]);
        assert!(compare(&a, &wide).unwrap_err().to_string().contains("size"));
        assert!(compare(&image(vec![0.0; 2], 1), &a).is_err());
        let nan = image(vec![f32::NAN, 0.0, 0.0, 0.0, 0.0, 0.0], 3);
        assert!(
            compare(&nan, &a)
                .unwrap_err()
                .to_string()
                .contains("finite")
        );
    }
}
