//! The `auto` curve shape: strands that the camera sees thinner than a pixel are traced as
//! flat ribbons facing the ray, the others as round tubes.
//!
//! A ribbon facing the ray covers, seen from the ray's origin, what the tube covers, so it
//! blocks the same light, and is hit evenly across its width as the tube is (a cubic
//! ribbon's h is the offset across the flat quad struck: `tracer::hair_hit`); its hit moves
//! to where the ray enters the tube (`tracer::tube_entry`). It differs at end caps and
//! joints, which a strand thinner than a pixel hides inside the pixel. Embree intersects a
//! cubic ribbon as quads along chords of its curve; thin strands get as many quads
//! per segment as keep them within the level of detail's tolerance of the curve in this
//! view ([`lod::ribbon_quads`]), up to Embree's most. A flat linear
//! curve costs Embree less per ray than a round one (docs/measurements.md, "Curve shapes").
//!
//! With a level of detail (`lod_pixels` > 0), the thin strands of every basis are traced
//! as flat linear ribbons through points on their curves, as few as keep the curve within
//! `lod_pixels` of them (`lod.rs`), shaded with the curve's tangent: Embree builds and
//! traces linear ribbons faster than cubic ones, and Catmull-Rom and Bezier curves are
//! converted to B-splines in its build.

use glam::Vec3;

use crate::embree::{CurveBasis, CurveShape};
use crate::error::Result;
use crate::scene::camera::Camera;
use crate::scene::curves::Curves;
use crate::scene::lod;

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
    /// `share_out` picks its thin strands for the view).
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

/// One flag per strand: whether every control point's diameter, at every time step, is at
/// most one pixel of an image `height` pixels tall, seen from `camera`'s eye at the point's
/// distance.
pub fn thin_strands(curves: &Curves, camera: &Camera, height: u32) -> Vec<bool> {
    let (eye, spread) = (camera.eye(), camera.pixel_spread(height));
    (0..curves.strands().strand_count())
        .map(|s| {
            (0..curves.time_steps()).all(|step| {
                (curves.strand_points_at(s, step).iter())
                    .all(|&[x, y, z, r]| 2.0 * r <= spread * eye.distance(Vec3::new(x, y, z)))
            })
        })
        .collect()
}

/// How one strand of an `auto` groom is traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Part {
    Round,
    Flat,
    /// A thin strand with a level of detail: flat linear ribbons through points on its
    /// curve ([`lod::polylines`]).
    Polyline,
}

/// `curves` (built round) as the geometries an `auto` groom is traced with: its thick
/// strands round, its thin ones ([`thin_strands`]) flat, or with `lod_pixels` > 0 as
/// polylines within that many pixels of their curves; without a copy when all are one
/// kind. Curves in motion keep their thin strands flat curves: a polyline is chosen for
/// one shape of a strand, and the ribbons' quads are chosen over every time step.
pub fn share_out(
    curves: Curves,
    camera: &Camera,
    height: u32,
    lod_pixels: f32,
) -> Result<Vec<Curves>> {
    lod::check_pixels(lod_pixels)?;
    let thin_part = if lod_pixels > 0.0 && curves.time_steps() == 1 {
        Part::Polyline
    } else {
        Part::Flat
    };
    let parts: Vec<Part> = (thin_strands(&curves, camera, height).into_iter())
        .map(|thin| if thin { thin_part } else { Part::Round })
        .collect();
    // Each part's geometries: polylines of the thin strands, and those too bent for
    // their budget as their own flat curves.
    let ribbons = |curves| cubic_ribbons(curves, camera, height, lod_pixels);
    let shape = |part, curves: Curves| -> Result<Vec<Curves>> {
        Ok(match part {
            Part::Round => vec![curves.with_shape(CurveShape::Round)],
            Part::Flat => vec![ribbons(curves)?],
            Part::Polyline => {
                let (lines, native) = lod::polylines(curves, camera, height, lod_pixels)?;
                let native = native.map(ribbons).transpose()?;
                native.into_iter().chain(lines).collect()
            }
        })
    };
    let first = parts.first().copied().unwrap_or(Part::Flat);
    if parts.iter().all(|&p| p == first) {
        return shape(first, curves);
    }
    let mut out = Vec::new();
    for part in [Part::Round, thin_part] {
        let keep: Vec<bool> = parts.iter().map(|&p| p == part).collect();
        if let Some(subset) = curves.subset(&keep, CurveShape::Round)? {
            out.extend(shape(part, subset)?);
        }
    }
    Ok(out)
}

/// Thin strands as flat curves, intersected in as many quads per segment as keep every
/// strand within the level of detail's tolerance of its curve (`lod::ribbon_quads`;
/// without a level of detail, its default tolerance), at most Embree's most. One geometry
/// for all: a geometry per count copied the groom's points, a second copy of the largest
/// grooms at the peak (docs/measurements.md, "Ribbons' quads at the silhouette").
fn cubic_ribbons(curves: Curves, camera: &Camera, height: u32, lod_pixels: f32) -> Result<Curves> {
    let curves = curves.with_shape(CurveShape::Flat);
    if curves.basis() == CurveBasis::Linear {
        return Ok(curves);
    }
    let tolerance = if lod_pixels > 0.0 {
        lod_pixels
    } else {
        lod::DEFAULT_LOD_PIXELS
    };
    let quads = lod::ribbon_quads(&curves, camera, height, tolerance)?;
    Ok(curves.with_ribbon_quads(quads))
}

#[cfg(test)]
mod tests {
    use super::*;
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
        for lod in [0.0, 0.25] {
            let one = |h| {
                let parts = share_out(near_and_far(), &camera(), h, lod).unwrap();
                parts.iter().map(|p| p.shape()).collect::<Vec<_>>()
            };
            assert_eq!(one(10), [CurveShape::Flat]);
            assert_eq!(one(5000), [CurveShape::Round]);
            assert_eq!(one(100), [CurveShape::Round, CurveShape::Flat]);
            let parts = share_out(near_and_far(), &camera(), 100, lod).unwrap();
            let ids = |p: &Curves| p.strands().locate(0).unwrap().id;
            assert_eq!((ids(&parts[0]), ids(&parts[1])), (0, 1));
        }
    }

    /// Two Catmull-Rom strands of radius 1e-4 in 4 segments: one at distance 1 from the
    /// camera, one at distance 100.
    fn catmull_rom_near_and_far() -> Curves {
        let points: Vec<[f32; 3]> = [-1.0f32, -100.0]
            .iter()
            .flat_map(|&z| (0..5).map(move |i| [0.01 * (i % 2) as f32, 0.025 * i as f32, z]))
            .collect();
        let strands = crate::scene::Strands {
            radii: vec![1e-4; points.len()],
            points,
            counts: vec![5, 5],
            colors: None,
        };
        Curves::from_strands(&strands, CurveBasis::CatmullRom, CurveShape::Round).unwrap()
    }

    #[test]
    fn a_level_of_detail_traces_the_thin_strands_as_polylines_of_their_curves() {
        let c = catmull_rom_near_and_far();
        let kinds = |h, lod| {
            (share_out(c.clone(), &camera(), h, lod).unwrap().iter())
                .map(|p| (p.basis(), p.shape(), p.truth().is_some()))
                .collect::<Vec<_>>()
        };
        let (native, polyline) = (
            (CurveBasis::CatmullRom, CurveShape::Flat, false),
            (CurveBasis::Linear, CurveShape::Flat, true),
        );
        // Pixel side 0.536 d / height; diameter 2e-4. Height 10: both thin.
        assert_eq!(kinds(10, 0.0), [native]);
        assert_eq!(kinds(10, 0.25), [polyline]);
        // Height 5000: the near strand (pixel 1.07e-4) is thick and stays round.
        let round = (CurveBasis::CatmullRom, CurveShape::Round, false);
        assert_eq!(kinds(5000, 0.25), [round, polyline]);
        let parts = share_out(c.clone(), &camera(), 5000, 0.25).unwrap();
        // The polylines keep the strand's number, and their curve is the strand's.
        assert_eq!(parts[1].strands().locate(0).unwrap().id, 1);
        let truth = parts[1].truth().unwrap().curves();
        assert_eq!(truth.strand_points(0), c.strand_points(1));
        let e = share_out(c, &camera(), 10, -1.0).unwrap_err();
        assert!(e.to_string().contains("tolerance -1"), "{e}");
    }
}
