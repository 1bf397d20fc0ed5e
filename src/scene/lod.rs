//! Level of detail from the view: a strand the camera sees thinner than a pixel is traced as
//! flat linear ribbons through points on its true curve, as few as keep the curve within a
//! tolerance, in pixels, of its polyline.
//!
//! Each strand's curve (any basis) is cut by bisection of its parameter: first at the
//! segment ends nearest the middle, then within a segment at halves, down to
//! `MIN_PIECE` of a segment. A piece is kept when a bound on the curve's distance from
//! the piece's chord is within the tolerance at the curve's distance from the eye. The
//! bound, on each cubic part of the piece between segment ends, is the Hermite form of the
//! curve's offset across the chord: at most the larger end offset plus 4/27 of the two end
//! slopes (an arc's sagitta is overestimated by a fifth). A straight strand is one piece,
//! a wavy one gets more pieces than segments where it bends; a Catmull-Rom strand whose
//! segments pass keeps exactly its own points. A strand that would need more than its
//! budget of pieces stops being cut as soon as it passes it, and stays a curve.
//!
//! The ribbons' hits are mapped back to the curve's parameter (`TrueCurves::locate`) and
//! take its tangent, position along the strand and colours. The image moves by the
//! tolerance at most, inside pixels a thinner strand only grazes (docs/large-grooms.md,
//! "Level of detail", has what each tolerance costs and changes).

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use crate::embree::{CurveBasis, CurveShape, DEFAULT_RIBBON_QUADS, MAX_RIBBON_QUADS};
use crate::error::{Result, invalid_arg};
use crate::scene::camera::Camera;
use crate::scene::curves::{Curves, SegmentCurve};
use crate::threads;

/// The default tolerance, in pixels, between a thin strand's curve and its polyline: the
/// largest measured whose bias stays below flat ribbons' own for every basis (fur ball,
/// 256 spp, RMSE over the noise: Catmull-Rom 1.04x, B-spline 1.06x at 0.02 px, against
/// 1.10x and 1.19x at 0.05 and 1.08x for flat ribbons; docs/large-grooms.md). Looser
/// tolerances that make the bench scalp's wavy strands polylines add primitives, memory
/// and, past 0.1 px, bias (docs/large-grooms.md, "Tolerance and budget").
pub const DEFAULT_LOD_PIXELS: f32 = 0.02;

/// The shortest piece, as a fraction of a segment: a bound on the points per segment
/// whatever the tolerance.
const MIN_PIECE: f32 = 1.0 / 64.0;

/// The most pieces a cubic strand's polyline may have per segment of its curve: past
/// that, Embree builds the strand's own flat cubic ribbons faster (on the 10^6 scalp,
/// about 3 to 5x a linear segment's build time per cubic segment) and in less memory.
/// With 4, the bench scalp's wavy strands (2.4 pieces per segment at 0.1 px) all became
/// polylines, and at 10^6 strands they took 2.3x the memory and traced slower.
const MAX_PIECES_PER_SEGMENT: usize = 2;

/// Strands sampled per parallel task.
const CHUNK: usize = 4096;

/// Checks a tolerance: finite and >= 0 (0: no level of detail).
pub fn check_pixels(pixels: f32) -> Result<()> {
    if pixels.is_finite() && pixels >= 0.0 {
        Ok(())
    } else {
        Err(invalid_arg!(
            "level-of-detail tolerance {pixels} pixels: must be finite and >= 0 (0: off)"
        ))
    }
}

/// `curves` as flat linear ribbons through points on their curves, within `pixels` of a
/// pixel of an image `height` pixels tall seen from `camera`'s eye (`Curves::polylines`),
/// and, apart, the strands that would need more than `MAX_PIECES_PER_SEGMENT` pieces
/// per segment, as their own flat curves. Either is `None` when it has no strand.
pub fn polylines(
    curves: Curves,
    camera: &Camera,
    height: u32,
    pixels: f32,
) -> Result<(Option<Curves>, Option<Curves>)> {
    check_pixels(pixels)?;
    let sampler = Sampler {
        eye: camera.eye(),
        per_distance: pixels * camera.pixel_spread(height),
        budget: if curves.basis() == CurveBasis::Linear {
            usize::MAX
        } else {
            MAX_PIECES_PER_SEGMENT
        },
    };
    let strands = curves.strands().strand_count();
    // Each chunk's points, parameters and counts, in strand order whatever the threads.
    let chunks: Vec<Polylines> = threads::scoped(0, || {
        (0..strands.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut out = Polylines::default();
                for s in c * CHUNK..strands.min((c + 1) * CHUNK) {
                    sampler.strand(&curves, s, &mut out);
                }
                out
            })
            .collect()
    })?;
    let mut all = Polylines::default();
    let total = |f: fn(&Polylines) -> usize| chunks.iter().map(f).sum::<usize>();
    all.points.reserve_exact(total(|c| c.points.len()) + 1);
    all.params.reserve_exact(total(|c| c.params.len()));
    all.counts.reserve_exact(strands);
    // Strand by strand, those within the budget.
    let mut keep = Vec::with_capacity(strands);
    for chunk in chunks {
        let mut at = 0;
        for (&count, &kept) in chunk.counts.iter().zip(&chunk.kept) {
            let n = count as usize;
            if kept {
                all.points.extend_from_slice(&chunk.points[at..at + n]);
                all.params.extend_from_slice(&chunk.params[at..at + n]);
                all.counts.push(count);
            }
            keep.push(kept);
            at += n;
        }
    }
    if keep.iter().all(|&k| k) {
        // Linear strands that keep every point are their own polylines: traced as they
        // are, their hits need no mapping back onto a second copy (4% to 25% of the
        // bench's linear fur balls' render time, docs/measurements.md, "Faster rays").
        if curves.basis() == CurveBasis::Linear && all.points.as_slice() == curves.vertices() {
            return Ok((Some(curves.with_shape(CurveShape::Flat)), None));
        }
        return Ok((
            Some(Curves::polylines(
                curves,
                all.points,
                &all.counts,
                all.params,
            )?),
            None,
        ));
    }
    // No strand within its budget: the curves themselves, flat, without a second copy of
    // the groom beside them (at 10^6 strands, 1.1 GiB more at the peak).
    if keep.iter().all(|&k| !k) {
        return Ok((None, Some(curves.with_shape(CurveShape::Flat))));
    }
    let native = curves.subset(
        &keep.iter().map(|k| !k).collect::<Vec<_>>(),
        CurveShape::Flat,
    )?;
    let lines = match curves.subset(&keep, CurveShape::Flat)? {
        Some(truth) => Some(Curves::polylines(
            truth,
            all.points,
            &all.counts,
            all.params,
        )?),
        None => None,
    };
    Ok((lines, native))
}

/// The quad counts Embree may intersect a flat cubic segment in, fewest first: its
/// default, then up to its most.
const RIBBON_QUADS: [u32; 3] = [DEFAULT_RIBBON_QUADS, 8, MAX_RIBBON_QUADS];

/// The fewest quads per segment of [`RIBBON_QUADS`] that keep every ribbon of cubic
/// `curves` within `pixels` of its curve, seen from `camera` in an image `height` pixels
/// tall; the most where even they do not.
///
/// Embree's ribbon quads run along chords of the curve, at even steps of its parameter.
/// Where a strand turns in the view, as a crown's strands do at the silhouette, the
/// default's chords cut the turn short, and the ribbon covers less than the strand there
/// (docs/measurements.md, "Ribbons' quads at the silhouette"). The bound is a chord's
/// largest distance from a curve: an eighth of its parameter step squared times the
/// second derivative across the line of sight, largest at a segment end (it is linear).
/// Curves in motion take the largest turn over their time steps: between two steps the
/// curve's second derivative is the blend of theirs, no longer than the longer of them.
pub fn ribbon_quads(curves: &Curves, camera: &Camera, height: u32, pixels: f32) -> Result<u32> {
    check_pixels(pixels)?;
    let (eye, per_distance) = (camera.eye(), pixels * camera.pixel_spread(height));
    let steps = curves.time_steps();
    let turn = threads::scoped(0, || {
        (0..curves.indices().len() as u32)
            .into_par_iter()
            .flat_map_iter(|prim| (0..steps).filter_map(move |k| curves.segment_curve_at(prim, k)))
            .map(|curve| turn_over_distance(&curve, eye))
            .reduce(|| 0.0, f32::max)
    })?;
    let within = |n: u32| turn <= (n * n) as f32 * 8.0 * per_distance;
    Ok((RIBBON_QUADS.into_iter().find(|&n| within(n))).unwrap_or(MAX_RIBBON_QUADS))
}

/// A segment's largest second derivative across the line of sight from `eye`, over its
/// nearest distance from it.
fn turn_over_distance(curve: &SegmentCurve, eye: Vec3) -> f32 {
    let points = [0.0, 0.5, 1.0].map(|u| curve.at(u).truncate());
    let sight = (points[1] - eye).normalize_or_zero();
    let across = |u: f32| {
        let d = curve.second_derivative(u).truncate();
        (d - d.dot(sight) * sight).length()
    };
    let near = points
        .iter()
        .map(|p| p.distance(eye))
        .fold(f32::MAX, f32::min);
    across(0.0).max(across(1.0)) / near
}

#[derive(Default)]
struct Polylines {
    points: Vec<[f32; 4]>,
    params: Vec<f32>,
    counts: Vec<u32>,
    /// Whether each strand fits its budget (one past it leaves no points here).
    kept: Vec<bool>,
}

struct Sampler {
    eye: Vec3,
    /// The tolerance per unit of distance from the eye.
    per_distance: f32,
    /// The most pieces per segment.
    budget: usize,
}

impl Sampler {
    /// Appends strand `s`'s polyline to `out`, or none past its budget: the points of
    /// strands that stay curves are dropped as they are made, not once every strand is
    /// sampled (at 10^6 strands, a gigabyte at the peak).
    fn strand(&self, curves: &Curves, s: usize, out: &mut Polylines) {
        let segments = self.segments(curves, s);
        let most = self.budget.saturating_mul(segments.len()).saturating_add(1);
        let strand = Strand {
            segments: &segments,
            sampler: self,
        };
        let points = strand.polyline(out, most);
        out.counts.push(points.unwrap_or(0) as u32);
        out.kept.push(points.is_some());
    }

    /// Strand `s`'s segments, with what the refinement reads at their ends.
    fn segments(&self, curves: &Curves, s: usize) -> Vec<Segment> {
        (curves.strands().first_segment(s))
            .into_iter()
            .flat_map(|first| first.prims())
            .filter_map(|prim| curves.segment_curve(prim))
            .map(|curve| Segment::new(curve, self.eye))
            .collect()
    }
}

/// A segment's curve, with what [`Strand::fits`] reads at its two ends, which the
/// refinement visits again at each level: computed once.
struct Segment {
    curve: SegmentCurve,
    /// At u = 0 and u = 1: the point, the derivative and the distance from the eye.
    ends: [End; 2],
}

#[derive(Clone, Copy)]
struct End {
    point: Vec4,
    derivative: Vec4,
    eye_distance: f32,
}

impl Segment {
    fn new(curve: SegmentCurve, eye: Vec3) -> Self {
        Segment {
            curve,
            ends: [0.0, 1.0].map(|u| End::on(&curve, u, eye)),
        }
    }

    /// What [`End`] holds at `u`: the stored end where `u` is 0 or 1.
    fn at(&self, u: f32, eye: Vec3) -> End {
        match u {
            0.0 => self.ends[0],
            1.0 => self.ends[1],
            _ => End::on(&self.curve, u, eye),
        }
    }
}

impl End {
    fn on(curve: &SegmentCurve, u: f32, eye: Vec3) -> Self {
        let point = curve.at(u);
        End {
            point,
            derivative: curve.derivative(u),
            eye_distance: eye.distance(point.truncate()),
        }
    }
}

/// One strand's segments, with the tolerance.
struct Strand<'a> {
    segments: &'a [Segment],
    sampler: &'a Sampler,
}

impl Strand<'_> {
    /// Appends the strand's polyline to `out` and returns its number of points, or appends
    /// nothing and returns `None` when it would have more than `most`.
    fn polyline(&self, out: &mut Polylines, most: usize) -> Option<usize> {
        if self.segments.is_empty() {
            return Some(0);
        }
        let before = out.points.len();
        let end = self.segments.len() as f32;
        let (root, tip) = (self.point(0.0), self.point(end));
        out.points.push(root.to_array());
        out.params.push(0.0);
        if self.refine(0.0, root, end, tip, out, before.saturating_add(most)) {
            return Some(out.points.len() - before);
        }
        out.points.truncate(before);
        out.params.truncate(before);
        None
    }

    /// The segment holding parameter `t` (a segment end belongs to the segment it starts,
    /// the tip to the last), and `t`'s parameter in it.
    fn segment(&self, t: f32) -> (&Segment, f32) {
        let j = (t as usize).min(self.segments.len() - 1);
        (&self.segments[j], t - j as f32)
    }

    fn point(&self, t: f32) -> Vec4 {
        let (segment, u) = self.segment(t);
        segment.at(u, self.sampler.eye).point
    }

    /// Appends the points after `a` up to `b` (both on the curve, at `pa` and `pb`), or
    /// stops, returning false, once `out` would hold more than `most` points: a strand past
    /// its budget is not refined further (down to `MIN_PIECE`) only to be dropped.
    fn refine(&self, a: f32, pa: Vec4, b: f32, pb: Vec4, out: &mut Polylines, most: usize) -> bool {
        if b - a > MIN_PIECE && !self.fits(a, pa, b, pb) {
            // Segment ends are whole numbers: cut at the one nearest the middle first.
            let m = if b - a > 1.0 {
                ((a + b) * 0.5).floor()
            } else {
                (a + b) * 0.5
            };
            let pm = self.point(m);
            return self.refine(a, pa, m, pm, out, most) && self.refine(m, pm, b, pb, out, most);
        }
        if out.points.len() >= most {
            return false;
        }
        out.points.push(pb.to_array());
        out.params.push(b);
        true
    }

    /// Whether the curve from `a` to `b` stays within the tolerance of the chord `pa`-`pb`.
    fn fits(&self, a: f32, pa: Vec4, b: f32, pb: Vec4) -> bool {
        let (p0, p1) = (pa.truncate(), pb.truncate());
        let along = (p1 - p0).normalize_or_zero();
        let across = |v: Vec4| {
            let v = v.truncate();
            (v - v.dot(along) * along).length()
        };
        let eye = self.sampler.eye;
        let mut x = a;
        while x < b {
            let (segment, u0) = self.segment(x);
            let u1 = u0 + (b - x).min(1.0 - u0);
            let (e0, e1) = (segment.at(u0, eye), segment.at(u1, eye));
            let span = u1 - u0;
            let offset = across(e0.point - pa).max(across(e1.point - pa));
            let slopes = span * (across(e0.derivative) + across(e1.derivative));
            let near = e0.eye_distance.min(e1.eye_distance);
            if offset + 4.0 / 27.0 * slopes > self.sampler.per_distance * near {
                return false;
            }
            x += span;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Strands;

    /// A camera at the origin looking down -z: a pixel of an image 100 pixels tall is
    /// 0.00536 wide per unit of distance.
    fn camera() -> Camera {
        Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 30.0, 1.0).unwrap()
    }

    const HEIGHT: u32 = 100;

    /// `curves` as polylines, every strand within its budget.
    fn all_polylines(curves: Curves, pixels: f32) -> Curves {
        let (lines, native) = polylines(curves, &camera(), HEIGHT, pixels).unwrap();
        assert!(native.is_none(), "strands past their budget at {pixels} px");
        lines.unwrap()
    }

    /// Three strands of 12 segments 2 to 3 units from the eye, seen across: straight,
    /// gently wavy and curly (one wave, and 2.5 waves).
    fn strands() -> Strands {
        let mut points = Vec::new();
        for (k, (amplitude, waves)) in [(0.0f32, 0.0f32), (0.02, 1.0), (0.01, 2.5)]
            .into_iter()
            .enumerate()
        {
            for i in 0..13 {
                let y = i as f32 / 12.0;
                let x = 0.3 * k as f32 + amplitude * (std::f32::consts::TAU * waves * y).sin();
                points.push([x, y - 0.5, -2.0 - y]);
            }
        }
        Strands {
            radii: (0..points.len())
                .map(|i| 1e-4 * (1.0 + (i % 13) as f32 / 13.0))
                .collect(),
            colors: Some(
                (0..points.len())
                    .map(|i| [(i % 13) as f32 / 12.0, 0.5, 0.0])
                    .collect(),
            ),
            counts: vec![13; 3],
            points,
        }
    }

    /// Distance from `p` to the segment `a`-`b`.
    fn to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
        let d = b - a;
        let t = if d == Vec3::ZERO {
            0.0
        } else {
            ((p - a).dot(d) / d.dot(d)).clamp(0.0, 1.0)
        };
        p.distance(a + t * d)
    }

    /// Pieces of each strand's polyline.
    fn pieces(lines: &Curves) -> Vec<u32> {
        (0..lines.strands().strand_count())
            .map(|s| lines.strands().first_segment(s).unwrap().segments)
            .collect()
    }

    /// The curve at 64 points per segment against the polyline piece its parameter falls
    /// in: the largest distance, in pixels of an image `height` pixels tall seen from
    /// `camera`, at the point's distance from the eye.
    fn worst_pixels(lines: &Curves, strand: usize, camera: &Camera, height: u32) -> f32 {
        let truth = lines.truth().unwrap();
        let curve = truth.curves();
        let first = curve.strands().first_segment(strand).unwrap();
        let points = lines.strand_points(strand);
        let start = lines.indices()
            [lines.strands().first_segment(strand).unwrap().first_prim as usize]
            as usize;
        let params = &truth.params()[start..start + points.len()];
        let spread = camera.pixel_spread(height);
        let mut worst = 0.0f32;
        for prim in first.prims() {
            let seg = curve.segment_curve(prim).unwrap();
            for k in 0..=64 {
                let u = k as f32 / 64.0;
                let t = (prim - first.first_prim) as f32 + u;
                let piece = params
                    .windows(2)
                    .position(|w| w[0] <= t && t <= w[1])
                    .unwrap();
                let p = seg.at(u).truncate();
                let [a, b] = [piece, piece + 1].map(|i| Vec3::from_slice(&points[i][..3]));
                worst = worst.max(to_segment(p, a, b) / (spread * p.distance(camera.eye())));
            }
        }
        worst
    }

    #[test]
    fn polylines_keep_every_curve_point_within_the_tolerance_in_fewer_pieces_where_straight() {
        let strands = strands();
        for basis in CurveBasis::ALL {
            let curves = Curves::from_strands(&strands, basis, CurveShape::Round).unwrap();
            let mut previous = vec![u32::MAX; 3];
            for pixels in [0.1, 0.25, 0.5] {
                let lines = all_polylines(curves.clone(), pixels);
                assert_eq!(
                    (lines.basis(), lines.shape()),
                    (CurveBasis::Linear, CurveShape::Flat)
                );
                let n = pieces(&lines);
                for s in 0..3 {
                    let worst = worst_pixels(&lines, s, &camera(), HEIGHT);
                    assert!(
                        worst <= pixels,
                        "{basis:?} strand {s} at {pixels} px: a curve point {worst} px off"
                    );
                    // A looser tolerance never takes more pieces.
                    assert!(n[s] <= previous[s], "{basis:?} {pixels} px: {n:?}");
                    // Every point is on the curve, at its parameter.
                    let truth = lines.truth().unwrap();
                    let first = lines.strands().first_segment(s).unwrap();
                    for prim in first.prims() {
                        let i = lines.indices()[prim as usize] as usize;
                        let (at, u) = truth.locate(s as u32, i as u32, 0.0).unwrap();
                        let on = truth.curves().segment_curve(at.first_prim + at.segment);
                        let p = Vec4::from_array(lines.vertices()[i]);
                        assert!(on.unwrap().at(u).distance(p) < 1e-6, "{basis:?}");
                    }
                }
                // The straight strand is one piece; the curly one needs more pieces than
                // the wavy one (as many, when both keep every linear segment).
                assert_eq!(n[0], 1, "{basis:?} {pixels} px");
                assert!(n[1] < n[2] || n[1] == 12, "{basis:?} {pixels} px: {n:?}");
                previous = n;
            }
            // At a thousandth, past two pieces a segment, it stays a flat curve of its own.
            let (lines, native) = polylines(curves.clone(), &camera(), HEIGHT, 0.001).unwrap();
            if basis != CurveBasis::Linear {
                let native = native.unwrap();
                assert_eq!((native.basis(), native.shape()), (basis, CurveShape::Flat));
                let ids = |c: &Curves| {
                    (0..c.strands().strand_count())
                        .map(|s| c.strands().first_segment(s).unwrap().id)
                        .collect::<Vec<_>>()
                };
                let lines = lines.unwrap();
                let most = (MAX_PIECES_PER_SEGMENT * 12) as u32;
                assert!(pieces(&lines).iter().all(|&n| n <= most), "{basis:?}");
                let mut all = [ids(&lines), ids(&native)].concat();
                all.sort();
                assert_eq!(all, [0, 1, 2], "{basis:?}");
            }
        }
    }

    /// Linear strands whose every point is kept are traced as themselves, flat, with no
    /// copy to map hits back onto; one merged piece brings the mapping back.
    #[test]
    fn linear_strands_that_keep_every_point_are_their_own_polylines() {
        let all = strands();
        let bent = Strands {
            points: all.points[13..].to_vec(),
            radii: all.radii[13..].to_vec(),
            colors: all.colors.as_ref().map(|c| c[13..].to_vec()),
            counts: vec![13; 2],
        };
        let curves = Curves::from_strands(&bent, CurveBasis::Linear, CurveShape::Round).unwrap();
        let lines = all_polylines(curves.clone(), 0.001);
        assert!(lines.truth().is_none());
        assert_eq!(lines.shape(), CurveShape::Flat);
        assert_eq!(
            (lines.vertices(), lines.indices()),
            (curves.vertices(), curves.indices())
        );
        // The straight strand merges into one piece: its hits map back.
        let curves = Curves::from_strands(&all, CurveBasis::Linear, CurveShape::Round).unwrap();
        assert!(all_polylines(curves, 0.001).truth().is_some());
    }

    /// The bench scalp's strands (bench/stages/scalp_1m.toml: 16 segments over four
    /// waves) from the bench camera at 160 pixels, every strand under a pixel wide: every
    /// point of every curve stays within the tolerance of the polyline, whichever strands
    /// fit their budget at each tolerance measured for the default (at 0.25 px, some).
    #[test]
    fn the_bench_scalps_polylines_stay_within_the_tolerance_at_the_views_footprint() {
        let scalp = crate::scene::ScalpPatch {
            strands: 200,
            segments: 16,
            ..Default::default()
        };
        let strands = scalp.build().unwrap();
        let eye = Vec3::new(4.5, 0.2, 4.5);
        let camera = Camera::new(eye, Vec3::new(0.0, -0.6, 0.0), Vec3::Y, 40.0, 1.0).unwrap();
        let height = 160;
        for basis in [CurveBasis::BSpline, CurveBasis::CatmullRom] {
            let curves = Curves::from_strands(&strands, basis, CurveShape::Round).unwrap();
            let thin = crate::scene::ribbons::thin_strands(&curves, &camera, height);
            assert!(
                thin.iter().all(|&t| t),
                "{basis:?}: a strand over a pixel wide"
            );
            for pixels in [DEFAULT_LOD_PIXELS, 0.05, 0.1, 0.25] {
                let (lines, _) = polylines(curves.clone(), &camera, height, pixels).unwrap();
                if pixels == 0.25 {
                    assert!(lines.is_some(), "{basis:?}: every strand past its budget");
                }
                let Some(lines) = lines else { continue };
                for s in 0..lines.strands().strand_count() {
                    let worst = worst_pixels(&lines, s, &camera, height);
                    assert!(
                        worst <= pixels,
                        "{basis:?} {pixels} px, strand {s}: a curve point {worst} px off"
                    );
                }
            }
        }
    }

    /// Where every segment passes, a Catmull-Rom strand's polyline is its own points (the
    /// curve runs through them).
    #[test]
    fn a_catmull_rom_polyline_cut_at_segment_ends_is_the_strands_own_points() {
        let strands = strands();
        let curves =
            Curves::from_strands(&strands, CurveBasis::CatmullRom, CurveShape::Round).unwrap();
        let lines = all_polylines(curves, 0.5);
        let truth = lines.truth().unwrap();
        let start = 13 + 2;
        let own = &truth.curves().vertices()[start + 1..start + 14];
        let first = lines.indices()[lines.strands().first_segment(1).unwrap().first_prim as usize];
        let params = &truth.params()[first as usize..];
        let points = lines.strand_points(1);
        let mut whole = 0;
        for (p, &t) in points.iter().zip(params) {
            // The tip is the last segment's end, a sum of its coefficients.
            if t.fract() == 0.0 && t < 12.0 {
                assert_eq!(*p, own[t as usize], "at {t}");
                whole += 1;
            }
        }
        assert!(whole >= 2, "{whole} points at segment ends");
    }

    /// A strand's refinement stops as soon as its polyline passes the most points it may
    /// have, leaving nothing, and a strand at exactly that many is refined as without a
    /// limit.
    #[test]
    fn the_refinement_stops_past_the_budget_and_not_at_it() {
        let curves =
            Curves::from_strands(&strands(), CurveBasis::CatmullRom, CurveShape::Flat).unwrap();
        let sampler = Sampler {
            eye: Vec3::ZERO,
            per_distance: 0.02 * camera().pixel_spread(HEIGHT),
            budget: usize::MAX,
        };
        for s in 0..3 {
            let segments = sampler.segments(&curves, s);
            let strand = Strand {
                segments: &segments,
                sampler: &sampler,
            };
            let mut free = Polylines::default();
            let n = strand.polyline(&mut free, usize::MAX).unwrap();
            assert_eq!(free.points.len(), n);
            let mut at = Polylines::default();
            assert_eq!(strand.polyline(&mut at, n), Some(n), "strand {s}");
            assert_eq!((at.points, at.params), (free.points, free.params));
            let mut past = Polylines::default();
            assert_eq!(strand.polyline(&mut past, n - 1), None, "strand {s}");
            assert!(past.points.is_empty() && past.params.is_empty());
            // The curly strand has more points than segments: the limit falls inside its
            // refinement.
            assert!(s < 2 || n > segments.len(), "strand {s}: {n} points");
        }
    }

    #[test]
    fn a_bad_tolerance_is_refused() {
        let curves =
            Curves::from_strands(&strands(), CurveBasis::BSpline, CurveShape::Round).unwrap();
        for bad in [f32::NAN, -0.5, f32::INFINITY] {
            let e = polylines(curves.clone(), &camera(), HEIGHT, bad).unwrap_err();
            assert!(e.to_string().contains("tolerance"), "{e}");
        }
    }
}
