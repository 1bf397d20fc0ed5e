//! pbrt-v4's image environment maps, resampled for our environment light. pbrt stores a
//! sphere of directions in a square image with the equal-area octahedral mapping of
//! Clarberg (2008); our environment is a lat-long image (+y up, `scene::envmap`). Each
//! lat-long texel takes the square's texel that pbrt would look up (nearest, as pbrt
//! does) for the texel centre's direction, taken into the light's frame.

use std::f64::consts::{FRAC_2_PI, PI};

use glam::{DMat3, DVec2, DVec3};

use crate::error::{Result, invalid_arg};
use crate::image::Image;

/// The point of [0, 1]^2 where the equal-area octahedral map puts the unit direction `d`.
pub(super) fn sphere_to_square(d: DVec3) -> DVec2 {
    let a = d.abs();
    // Distance from the square's centre (or corner, below the equator), so that equal
    // areas of the sphere cover equal areas of the square.
    let r = (1.0 - a.z).max(0.0).sqrt();
    let (big, small) = (a.x.max(a.y), a.x.min(a.y));
    let mut phi = if big == 0.0 {
        0.0
    } else {
        (small / big).atan() * FRAC_2_PI
    };
    if a.x < a.y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        (u, v) = (1.0 - v, 1.0 - u);
    }
    DVec2::new(u.copysign(d.x) + 1.0, v.copysign(d.y) + 1.0) * 0.5
}

/// Resamples the square `image` into lat-long RGB texels (width, height, values), with
/// `light_from_render` taking our directions into the light's frame.
pub(super) fn latlong_from_equal_area(
    image: &Image,
    light_from_render: DMat3,
) -> Result<(usize, usize, Vec<f32>)> {
    let n = image.width;
    if n == 0 || image.height != n {
        return Err(invalid_arg!(
            "a pbrt-v4 environment map must be square (equal-area octahedral); this one is \
             {} x {}",
            image.width,
            image.height
        ));
    }
    if image.channels < 3 {
        return Err(invalid_arg!("an environment map needs R, G and B channels"));
    }
    // 2N x N: twice the square's texels, so that no square texel is lost.
    let (width, height) = (2 * n, n);
    let mut out = Vec::with_capacity(width * height * 3);
    for row in 0..height {
        let theta = PI * (row as f64 + 0.5) / height as f64;
        for col in 0..width {
            let phi = 2.0 * PI * (col as f64 + 0.5) / width as f64;
            // Our lat-long direction of (u, v), see scene::envmap.
            let d = DVec3::new(
                -theta.sin() * phi.sin(),
                theta.cos(),
                theta.sin() * phi.cos(),
            );
            let uv = sphere_to_square((light_from_render * d).normalize());
            let x = ((uv.x * n as f64) as usize).min(n - 1);
            let y = ((uv.y * n as f64) as usize).min(n - 1);
            let at = (y * n + x) * image.channels;
            out.extend_from_slice(&image.pixels[at..at + 3]);
        }
    }
    Ok((width, height, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_map_puts_the_poles_and_axes_where_pbrt_does() {
        let close = |d: DVec3, uv: [f64; 2]| {
            let got = sphere_to_square(d.normalize());
            assert!(got.abs_diff_eq(DVec2::from_array(uv), 1e-12), "{d}: {got}");
        };
        close(DVec3::Z, [0.5, 0.5]);
        close(DVec3::X, [1.0, 0.5]);
        close(DVec3::Y, [0.5, 1.0]);
        close(-DVec3::X, [0.0, 0.5]);
        close(DVec3::new(0.0, 0.0, -1.0), [1.0, 1.0]);
        close(DVec3::new(1.0, 1.0, 0.0), [0.75, 0.75]);
    }

    #[test]
    fn only_square_rgb_maps_are_taken() {
        let image = |width, height, channels| {
            Image::new(
                width,
                height,
                channels,
                vec![0.5; width * height * channels],
            )
        };
        let e = latlong_from_equal_area(&image(8, 4, 3), DMat3::IDENTITY).unwrap_err();
        assert!(e.to_string().contains("must be square"), "{e}");
        let e = latlong_from_equal_area(&image(4, 4, 1), DMat3::IDENTITY).unwrap_err();
        assert!(e.to_string().contains("R, G and B"), "{e}");
        let (w, h, rgb) = latlong_from_equal_area(&image(4, 4, 4), DMat3::IDENTITY).unwrap();
        assert_eq!((w, h, rgb), (8, 4, vec![0.5; 96]));
    }

    #[test]
    fn equal_areas_of_the_sphere_cover_equal_areas_of_the_square() {
        // Directions uniform on the sphere (a Fibonacci lattice) land uniformly on the
        // square: each quarter of it gets a quarter of them.
        let n = 20_000;
        let mut quarters = [0usize; 4];
        for i in 0..n {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let phi = i as f64 * PI * (3.0 - 5f64.sqrt());
            let r = (1.0 - z * z).sqrt();
            let uv = sphere_to_square(DVec3::new(r * phi.cos(), r * phi.sin(), z));
            let inner = (uv - 0.5).abs();
            quarters[usize::from(inner.x + inner.y > 0.5) * 2 + usize::from(uv.x > 0.5)] += 1;
        }
        // Inside the diamond |u - 1/2| + |v - 1/2| < 1/2 lies the upper hemisphere: half.
        let upper = quarters[0] + quarters[1];
        assert!((upper as f64 / n as f64 - 0.5).abs() < 1e-3, "{quarters:?}");
        let right = quarters[1] + quarters[3];
        assert!((right as f64 / n as f64 - 0.5).abs() < 1e-2, "{quarters:?}");
    }
}
