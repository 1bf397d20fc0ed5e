//! The `auto` curve shape: strands that the camera sees thinner than a pixel are traced as
//! flat ribbons facing the ray, the others as round tubes.
//!
//! A ribbon facing the ray covers, seen from the ray's origin, what the tube covers, so it
//! blocks the same light and is hit across the same h. It differs in the depth of the hit
//! (by up to a radius) and at end caps and joints, differences that a strand thinner than a
//! pixel hides inside the pixel. A flat linear curve costs Embree 1.5-1.8x less per ray than
//! a round one. On the bench scenes the ribbons' images differ from the tubes' by under a
//! third of a bench render's own noise (RMSE at equal samples 2-4% higher; docs/measurements.md, "Curve
//! shapes").
//!
//! A thin Catmull-Rom strand whose curve stays within [`POLYLINE_PIXELS`] of a pixel of
//! its polyline is traced as flat linear ribbons through its own points (a Catmull-Rom
//! curve passes through them), shaded with the curve's tangent: Embree's flat Catmull-Rom
//! ribbons are intersected piece by piece as it goes, which costs the demo 1.25x the time.

use glam::Vec3;

use crate::embree::{CurveBasis, CurveShape};
use crate::error::Result;
use crate::scene::camera::Camera;
use crate::scene::curves::{Curves, catmull_rom_coefficients};

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

/// How far, in pixels, a thin Catmull-Rom strand's curve may stray from its polyline for
/// the polyline to be traced instead ([`straight_strands`]).
pub const POLYLINE_PIXELS: f32 = 0.05;

/// One flag per strand of Catmull-Rom `curves` (all false for other bases): whether every
/// segment's curve, at a quarter, half and three quarters of it, lies within
/// [`POLYLINE_PIXELS`] of a pixel of its chord, seen from `camera`'s eye. (A bent segment
/// strays most at its middle, an S-shaped one near its quarters.)
pub fn straight_strands(curves: &Curves, camera: &Camera, height: u32) -> Vec<bool> {
    let strands = curves.strands().strand_count();
    if curves.basis() != CurveBasis::CatmullRom {
        return vec![false; strands];
    }
    let (eye, spread) = (camera.eye(), camera.pixel_spread(height));
    (0..strands)
        .map(|s| {
            curves.strand_points(s).windows(4).all(|w| {
                let p: [Vec3; 4] = std::array::from_fn(|k| Vec3::from_slice(&w[k][..3]));
                chord_stray(p) <= POLYLINE_PIXELS * spread * eye.distance(0.5 * (p[1] + p[2]))
            })
        })
        .collect()
}

/// The largest distance, at u = 1/4, 1/2 and 3/4, between the Catmull-Rom segment of
/// control points `p` (from p[1] to p[2]) and its chord.
fn chord_stray(p: [Vec3; 4]) -> f32 {
    let [c1, c2, c3] = catmull_rom_coefficients(p);
    [0.25f32, 0.5, 0.75]
        .map(|u| (p[1] + u * (c1 + u * (c2 + u * c3))).distance(p[1].lerp(p[2], u)))
        .into_iter()
        .fold(0.0, f32::max)
}

/// How one strand of an `auto` groom is traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Round,
    Flat,
    /// A thin Catmull-Rom strand whose curve stays close to its polyline: flat linear
    /// ribbons through its points ([`Curves::catmull_rom_polyline`]), which Embree traces
    /// faster than its own flat Catmull-Rom ribbons, with a smaller BVH.
    Polyline,
}

impl Part {
    /// `curves` traced as this part.
    fn shape(self, curves: Curves) -> Curves {
        match self {
            Part::Round => curves.with_shape(CurveShape::Round),
            Part::Flat => curves.with_shape(CurveShape::Flat),
            Part::Polyline => curves.catmull_rom_polyline(),
        }
    }
}

/// `curves` (built round) as the geometries an `auto` groom is traced with: its thick
/// strands round, its thin ones flat ([`thin_strands`]), the thin Catmull-Rom ones that
/// [`straight_strands`] passes as polylines; without a copy when all are one kind.
pub fn share_out(curves: Curves, camera: &Camera, height: u32) -> Result<Vec<Curves>> {
    let thin = thin_strands(&curves, camera, height);
    let straight = straight_strands(&curves, camera, height);
    let parts: Vec<Part> = thin
        .iter()
        .zip(&straight)
        .map(|(&thin, &straight)| match (thin, straight) {
            (false, _) => Part::Round,
            (true, false) => Part::Flat,
            (true, true) => Part::Polyline,
        })
        .collect();
    let first = parts.first().copied().unwrap_or(Part::Flat);
    if parts.iter().all(|&p| p == first) {
        return Ok(vec![first.shape(curves)]);
    }
    let mut out = Vec::new();
    for part in [Part::Round, Part::Flat, Part::Polyline] {
        let keep: Vec<bool> = parts.iter().map(|&p| p == part).collect();
        if let Some(subset) = curves.subset(&keep, CurveShape::Round)? {
            out.push(part.shape(subset));
        }
    }
    Ok(out)
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

    /// Two thin Catmull-Rom strands at distance 1 from the camera, 0.1 long in 4 segments:
    /// one straight, one zig-zagging by 0.01 (a tenth of its own length).
    fn straight_and_bent() -> Curves {
        let (straight, bent): (Vec<[f32; 4]>, Vec<[f32; 4]>) = (0..5)
            .map(|i| {
                let y = 0.025 * i as f32;
                let x = if i % 2 == 1 { 0.01 } else { 0.0 };
                ([0.0, y, -1.0, 1e-4], [0.05 + x, y, -1.0, 1e-4])
            })
            .unzip();
        let strands = crate::scene::Strands {
            points: straight
                .iter()
                .chain(&bent)
                .map(|p| [p[0], p[1], p[2]])
                .collect(),
            radii: vec![1e-4; 10],
            counts: vec![5, 5],
            colors: None,
        };
        Curves::from_strands(&strands, CurveBasis::CatmullRom, CurveShape::Round).unwrap()
    }

    #[test]
    fn thin_catmull_rom_strands_close_to_their_polyline_are_traced_as_it() {
        let c = straight_and_bent();
        // Pixel side at distance 1: 0.536 / height. The bent strand's curve strays up to
        // about 0.002 from its chords: under 1/20 of a pixel at height 10, far over it
        // at 500.
        assert_eq!(straight_strands(&c, &camera(), 10), [true, true]);
        assert_eq!(straight_strands(&c, &camera(), 500), [true, false]);
        assert_eq!(
            straight_strands(&near_and_far(), &camera(), 10),
            [false, false]
        );
        let parts = share_out(c.clone(), &camera(), 500).unwrap();
        let kinds: Vec<_> = parts
            .iter()
            .map(|p| (p.basis(), p.shape(), p.catmull_rom_tangents()))
            .collect();
        assert_eq!(
            kinds,
            [
                (CurveBasis::CatmullRom, CurveShape::Flat, false),
                (CurveBasis::Linear, CurveShape::Flat, true),
            ]
        );
        let ids = |p: &Curves| p.strands().locate(0).unwrap().id;
        assert_eq!((ids(&parts[0]), ids(&parts[1])), (1, 0));
        // The polyline runs through the strand's own points.
        assert_eq!(parts[1].strand_points(0), &c.strand_points(0)[1..6]);
        // Only thin strands: at height 5000 both are a pixel wide or more.
        let whole = share_out(c, &camera(), 5000).unwrap();
        assert_eq!(whole.len(), 1);
        assert_eq!(whole[0].shape(), CurveShape::Round);
    }
}
