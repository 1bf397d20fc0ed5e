//! The `auto` curve shape: strands that the camera sees thinner than a pixel are traced as
//! flat ribbons facing the ray, the others as round tubes.
//!
//! A ribbon facing the ray covers, seen from the ray's origin, what the tube covers, so it
//! blocks the same light and is hit across the same h. It differs in the depth of the hit
//! (by up to a radius) and at end caps and joints, differences that a strand thinner than a
//! pixel hides inside the pixel. A flat linear curve costs Embree 1.5-1.8x less per ray than
//! a round one. On the bench scenes the ribbons' images differ from the tubes' by under a
//! third of a bench render's own noise (RMSE at equal samples 2-4% higher; README, "Curve
//! shapes").

use crate::embree::CurveShape;
use crate::error::Result;
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;

/// How a groom's strands are given to Embree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GroomShape {
    /// Every strand a round tube.
    Round,
    /// Every strand a ribbon facing the ray.
    Flat,
    /// Per strand, flat when it is thinner than a pixel from the camera, else round.
    #[default]
    Auto,
}

impl GroomShape {
    /// The shape the groom is built with before the camera is known (`Auto`: round, until
    /// [`share_out`] picks its thin strands).
    pub fn built(self) -> CurveShape {
        match self {
            GroomShape::Flat => CurveShape::Flat,
            GroomShape::Round | GroomShape::Auto => CurveShape::Round,
        }
    }
}

impl From<CurveShape> for GroomShape {
    fn from(shape: CurveShape) -> Self {
        match shape {
            CurveShape::Round => GroomShape::Round,
            CurveShape::Flat => GroomShape::Flat,
        }
    }
}

/// One flag per strand: whether every control point's diameter is at most one pixel of an
/// image `height` pixels tall, seen from `camera`'s eye at the point's distance.
pub fn thin_strands(curves: &Curves, camera: &Camera, height: u32) -> Vec<bool> {
    let (eye, spread) = (camera.eye(), camera.pixel_spread(height));
    (0..curves.strands().strand_count())
        .map(|s| {
            curves
                .strand_points(s)
                .iter()
                .all(|&[x, y, z, r]| 2.0 * r <= spread * eye.distance(glam::Vec3::new(x, y, z)))
        })
        .collect()
}

/// `curves` (built round) as the geometries an `auto` groom is traced with: its thick
/// strands round, its thin ones flat ([`thin_strands`]), without a copy when all are one
/// or the other.
pub fn share_out(curves: Curves, camera: &Camera, height: u32) -> Result<Vec<Curves>> {
    let thin = thin_strands(&curves, camera, height);
    if thin.iter().all(|&t| t) {
        return Ok(vec![curves.with_shape(CurveShape::Flat)]);
    }
    if !thin.iter().any(|&t| t) {
        return Ok(vec![curves.with_shape(CurveShape::Round)]);
    }
    let thick: Vec<bool> = thin.iter().map(|&t| !t).collect();
    Ok([
        curves.subset(&thick, CurveShape::Round)?,
        curves.subset(&thin, CurveShape::Flat)?,
    ]
    .into_iter()
    .flatten()
    .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embree::CurveBasis;
    use glam::Vec3;

    /// Two vertical strands of radius 0.01 in front of a camera at the origin looking down
    /// -z: one at distance 1, one at distance 100.
    fn near_and_far() -> Curves {
        let (near, far) = (-1.0, -100.0);
        let points = vec![
            [0.0, 0.0, near, 0.01],
            [0.0, 0.1, near, 0.01],
            [0.0, 0.0, far, 0.01],
            [0.0, 0.1, far, 0.01],
        ];
        Curves::from_control_points(points, &[2, 2], None, CurveBasis::Linear, CurveShape::Round)
            .unwrap()
    }

    fn camera() -> Camera {
        // 2 tan(30 deg / 2) = 0.536 of height per unit distance.
        Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 30.0, 1.0).unwrap()
    }

    #[test]
    fn a_strand_is_thin_when_its_diameter_is_at_most_a_pixel() {
        let c = near_and_far();
        // Pixel side at distance d: 0.536 d / height. Diameter 0.02.
        // height 10: near pixel 0.054, far 5.4: both thin.
        assert_eq!(thin_strands(&c, &camera(), 10), [true, true]);
        // height 100: near pixel 0.0054 < 0.02 (thick), far 0.54 (thin).
        assert_eq!(thin_strands(&c, &camera(), 100), [false, true]);
        // height 5000: far pixel 0.0107 < 0.02: both thick.
        assert_eq!(thin_strands(&c, &camera(), 5000), [false, false]);
    }

    #[test]
    fn share_out_splits_only_a_mixed_groom() {
        let one = |h| {
            let parts = share_out(near_and_far(), &camera(), h).unwrap();
            parts.iter().map(|p| p.shape()).collect::<Vec<_>>()
        };
        assert_eq!(one(10), [CurveShape::Flat]);
        assert_eq!(one(5000), [CurveShape::Round]);
        assert_eq!(one(100), [CurveShape::Round, CurveShape::Flat]);
        let parts = share_out(near_and_far(), &camera(), 100).unwrap();
        let ids = |p: &Curves| p.strands().locate(0).unwrap().id;
        assert_eq!((ids(&parts[0]), ids(&parts[1])), (0, 1));
    }
}
