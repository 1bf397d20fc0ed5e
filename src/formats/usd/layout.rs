//! UsdGeomBasisCurves' layouts turned into the control points Embree takes.
//!
//! USD describes each curve by `type`, `basis` and `wrap`; Embree knows only open curves of
//! one basis. The conversions, exact for positions:
//! - nonperiodic: the points as authored;
//! - pinned (B-spline, Catmull-Rom): one phantom point at each end, the end point reflected
//!   through its neighbour (`2 p0 - p1`), as the UsdGeom spec defines them, so that the curve
//!   starts at the first point and ends at the last; for linear and Bezier curves, pinned is
//!   the same as nonperiodic (the spec gives it meaning for B-spline and Catmull-Rom only);
//! - periodic: the first points repeated after the last, so that the closing segments exist
//!   (linear and Bezier: the first point; B-spline and Catmull-Rom: the first three).
//!
//! `widths` and `displayColor` with `varying` interpolation hold one value per segment end
//! (per segment for periodic curves), counted as usd-core's `ComputeVaryingDataSize` and
//! Hydra count them: a pinned B-spline or Catmull-Rom curve of n points has n - 1 segments
//! but n - 2 varying values, those of the same curve nonperiodic, so its two end segments
//! take the first and last values out to the end points ([`Layout::varying_ends`]);
//! radii are mapped to control points so that the basis reproduces those values at the
//! segment ends (exactly for linear, Bezier and Catmull-Rom, and for B-splines wherever the
//! widths change linearly), colours are taken as they are, since the renderer interpolates
//! colours between segment ends.

use glam::Vec3;

use crate::embree::CurveBasis;
use crate::error::{Result, invalid_arg};
use crate::scene::Strands;

/// UsdGeomBasisCurves' `wrap`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wrap {
    Nonperiodic,
    Pinned,
    Periodic,
}

/// How a primvar's values map onto the curves (`interpolation` metadata).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    Constant,
    Uniform,
    Varying,
    Vertex,
}

impl Interpolation {
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "constant" => Interpolation::Constant,
            "uniform" => Interpolation::Uniform,
            "varying" => Interpolation::Varying,
            "vertex" | "faceVarying" => Interpolation::Vertex,
            _ => return None,
        })
    }
}

/// One prim's curve layout: the basis Embree uses and the USD wrap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub basis: CurveBasis,
    pub wrap: Wrap,
}

impl Layout {
    /// The layout of the curve hairtrace draws through polylines read with `basis`
    /// (`Curves::from_strands`): nonperiodic linear, and pinned B-spline or Catmull-Rom, whose
    /// phantom end points are the ones hairtrace adds; Bezier strands are the Catmull-Rom
    /// curve in Bezier form.
    pub fn of_polylines(basis: CurveBasis) -> Layout {
        match basis {
            CurveBasis::Linear => Layout {
                basis,
                wrap: Wrap::Nonperiodic,
            },
            CurveBasis::BSpline => Layout {
                basis,
                wrap: Wrap::Pinned,
            },
            CurveBasis::CatmullRom | CurveBasis::Bezier => Layout {
                basis: CurveBasis::CatmullRom,
                wrap: Wrap::Pinned,
            },
        }
    }

    /// The tokens UsdGeom spells `type`, `basis` and `wrap` with.
    pub fn tokens(self) -> (&'static str, &'static str, &'static str) {
        let (kind, basis) = match self.basis {
            CurveBasis::Linear => ("linear", "bezier"),
            CurveBasis::Bezier => ("cubic", "bezier"),
            CurveBasis::BSpline => ("cubic", "bspline"),
            CurveBasis::CatmullRom => ("cubic", "catmullRom"),
        };
        let wrap = match self.wrap {
            Wrap::Nonperiodic => "nonperiodic",
            Wrap::Pinned => "pinned",
            Wrap::Periodic => "periodic",
        };
        (kind, basis, wrap)
    }

    /// The layout UsdGeom spells with these `type`, `basis` and `wrap` tokens.
    pub fn named(kind: &str, basis: &str, wrap: &str) -> Result<Layout> {
        Ok(Layout {
            basis: basis_of(kind, basis)?,
            wrap: wrap_of(wrap)?,
        })
    }

    /// Control points before the first authored one in Embree's layout of a curve (the
    /// pinned wrap's phantom point): the authored points of a curve are
    /// `control[lead..lead + n]`.
    pub fn lead(self) -> usize {
        usize::from(self.effective_wrap() == Wrap::Pinned)
    }

    /// Embree's control points (x, y, z, radius) of strands whose points are the authored
    /// points of curves of this layout, how many each curve has, and the strands' colours at
    /// every segment end. Errors name a curve whose point count makes no whole segment.
    #[allow(clippy::type_complexity)]
    pub fn control_points(
        self,
        strands: &Strands,
    ) -> Result<(Vec<[f32; 4]>, Vec<u32>, Option<Vec<[f32; 3]>>)> {
        let mut control = Vec::new();
        let mut counts = Vec::with_capacity(strands.counts.len());
        let mut colors = strands.colors.as_ref().map(|_| Vec::new());
        let (mut curve, mut ext) = (Vec::new(), Vec::new());
        for (i, (start, &n)) in strands.offsets().zip(&strands.counts).enumerate() {
            let n = n as usize;
            let segments = self.segments(n).ok_or_else(|| {
                let (kind, basis, wrap) = self.tokens();
                invalid_arg!(
                    "strand {i} has {n} points: {kind} {basis} {wrap} curves have {} points",
                    self.count_rule()
                )
            })?;
            let points = start..start + n;
            let xyzr: Vec<[f32; 4]> = (strands.points[points.clone()].iter())
                .zip(&strands.radii[points.clone()])
                .map(|(p, &r)| [p[0], p[1], p[2], r])
                .collect();
            curve.clear();
            // A phantom end's radius is reflected like its position, and kept only if > 0.
            self.extend(&xyzr, &mut curve, |p, end| {
                if p[3] > 0.0 {
                    p
                } else {
                    [p[0], p[1], p[2], end[3]]
                }
            });
            control.extend_from_slice(&curve);
            counts.push(curve.len() as u32);
            if let (Some(c), Some(out)) = (&strands.colors, &mut colors) {
                ext.clear();
                self.extend(&c[points], &mut ext, |c, _| c.map(|x| x.max(0.0)));
                let first = out.len();
                self.segment_ends(&ext, segments, out);
                clamp_colors(&mut out[first..]);
            }
        }
        Ok((control, counts, colors))
    }

    /// The wrap that changes anything for this basis (pinned means something for B-spline
    /// and Catmull-Rom only).
    fn effective_wrap(self) -> Wrap {
        match (self.basis, self.wrap) {
            (CurveBasis::Linear | CurveBasis::Bezier, Wrap::Pinned) => Wrap::Nonperiodic,
            (_, w) => w,
        }
    }

    /// Segments of a curve of `n` authored points, or None when `n` does not make whole
    /// segments of this layout.
    pub fn segments(self, n: usize) -> Option<usize> {
        let s = match (self.basis, self.effective_wrap()) {
            (CurveBasis::Linear, Wrap::Periodic) => (n >= 2).then_some(n),
            (CurveBasis::Linear, _) => (n >= 2).then(|| n - 1),
            (CurveBasis::Bezier, Wrap::Periodic) => (n >= 3 && n % 3 == 0).then_some(n / 3),
            (CurveBasis::Bezier, _) => (n >= 4 && (n - 1) % 3 == 0).then(|| (n - 1) / 3),
            (_, Wrap::Periodic) => (n >= 3).then_some(n),
            (_, Wrap::Pinned) => (n >= 2).then(|| n - 1),
            (_, Wrap::Nonperiodic) => (n >= 4).then(|| n - 3),
        };
        s.filter(|&s| s > 0)
    }

    /// The point counts [`Layout::segments`] takes, as a message says them.
    pub fn count_rule(self) -> &'static str {
        match (self.basis, self.effective_wrap()) {
            (CurveBasis::Linear, _) | (_, Wrap::Pinned) => "at least 2",
            (CurveBasis::Bezier, Wrap::Periodic) => "a multiple of 3",
            (CurveBasis::Bezier, _) => "3k + 1, at least 4",
            (_, Wrap::Periodic) => "at least 3",
            (_, Wrap::Nonperiodic) => "at least 4",
        }
    }

    /// Values a `varying` primvar holds for a curve of `segments` segments (usd-core's
    /// count: a pinned curve has those of its nonperiodic self, two fewer than its segment
    /// ends, none for two points).
    pub fn varying_count(self, segments: usize) -> usize {
        match self.effective_wrap() {
            Wrap::Periodic => segments,
            Wrap::Pinned => segments - 1,
            Wrap::Nonperiodic => segments + 1,
        }
    }

    /// The value at each segment end of a curve from its `varying` values `v`: as they are,
    /// but for a pinned curve, whose end segments reach the end points with the first and
    /// last values.
    pub fn varying_ends<T: Copy>(self, v: &[T]) -> Vec<T> {
        match (self.effective_wrap(), v) {
            (Wrap::Pinned, [first, .., last]) | (Wrap::Pinned, [first @ last]) => {
                let mut out = Vec::with_capacity(v.len() + 2);
                out.push(*first);
                out.extend_from_slice(v);
                out.push(*last);
                out
            }
            _ => v.to_vec(),
        }
    }

    /// Control points Embree reads for a curve of `n` authored points.
    pub fn embree_count(self, n: usize) -> usize {
        match (self.basis, self.effective_wrap()) {
            (_, Wrap::Nonperiodic) => n,
            (_, Wrap::Pinned) => n + 2,
            (CurveBasis::Linear | CurveBasis::Bezier, Wrap::Periodic) => n + 1,
            (_, Wrap::Periodic) => n + 3,
        }
    }

    /// Appends to `out` the control points Embree reads for one curve whose per-point values
    /// are `v` (positions, radii, ...). `phantom` turns a reflected end value into a usable
    /// one (radii must stay > 0).
    pub fn extend<const N: usize>(
        self,
        v: &[[f32; N]],
        out: &mut Vec<[f32; N]>,
        phantom: impl Fn([f32; N], [f32; N]) -> [f32; N],
    ) {
        let n = v.len();
        let reflect = |end: usize, next: usize| {
            let r = std::array::from_fn(|c| 2.0 * v[end][c] - v[next][c]);
            phantom(r, v[end])
        };
        match (self.basis, self.effective_wrap()) {
            (_, Wrap::Nonperiodic) => out.extend_from_slice(v),
            (_, Wrap::Pinned) => {
                out.push(reflect(0, 1));
                out.extend_from_slice(v);
                out.push(reflect(n - 1, n - 2));
            }
            (CurveBasis::Linear | CurveBasis::Bezier, Wrap::Periodic) => {
                out.extend_from_slice(v);
                out.push(v[0]);
            }
            (_, Wrap::Periodic) => {
                out.extend_from_slice(v);
                out.extend((0..3).map(|i| v[i % n]));
            }
        }
    }

    /// Per-point radii of one curve of `n` points from its `varying` radii `w` (see the
    /// module notes).
    pub fn varying_to_points(self, w: &[f32], n: usize) -> Vec<[f32; 1]> {
        let positive = |r: f32, fallback: f32| if r > 0.0 { r } else { fallback };
        match (self.basis, self.effective_wrap()) {
            (CurveBasis::Linear, _) => w.iter().map(|&r| [r]).collect(),
            // The segment ends of a pinned curve are its points.
            (_, Wrap::Pinned) => self.varying_ends(w).into_iter().map(|r| [r]).collect(),
            (CurveBasis::Bezier, wrap) => (0..n)
                .map(|i| {
                    let (j, k) = (i / 3, i % 3);
                    let a = w[j];
                    let b = if wrap == Wrap::Periodic {
                        w[(j + 1) % w.len()]
                    } else {
                        w[(j + 1).min(w.len() - 1)]
                    };
                    [a + (b - a) * k as f32 / 3.0]
                })
                .collect(),
            // A segment runs from the point after its first control point, which is where a
            // B-spline or Catmull-Rom curve with linearly changing control values has them.
            (_, Wrap::Periodic) => {
                let mut r = vec![[0.0]; n];
                for (k, &x) in w.iter().enumerate() {
                    r[(k + 1) % n] = [x];
                }
                r
            }
            (_, Wrap::Nonperiodic) => {
                let m = w.len();
                let mut r = Vec::with_capacity(n);
                r.push([positive(2.0 * w[0] - w[1], w[0])]);
                r.extend(w.iter().map(|&x| [x]));
                r.push([positive(2.0 * w[m - 1] - w[m - 2], w[m - 1])]);
                r
            }
        }
    }

    /// The value at each segment end (segments + 1 per curve) of a curve whose Embree control
    /// values are `c`: the basis evaluated at the segment's start, and at the last one's end.
    /// Signed: a colour's caller clamps (`clamp_colors`), a normal's keeps its sign.
    pub fn segment_ends(self, c: &[[f32; 3]], segments: usize, out: &mut Vec<[f32; 3]>) {
        let stride = self.basis.segment_stride();
        // The segment's start is its Bezier form's first point; the last segment end is the
        // start of one more segment, whose points past the curve are never weighed.
        let at = |first: usize| -> [f32; 3] {
            let p = |i: usize| Vec3::from(c[(first + i).min(c.len() - 1)]);
            let [start, ..] = self
                .basis
                .bezier_form::<Vec3, f32>([p(0), p(1), p(2), p(3)]);
            start.to_array()
        };
        out.extend((0..=segments).map(|s| at(s * stride)));
    }
}

/// Colours at segment ends made >= 0: a B-spline's weighted sum of colours >= 0 may round
/// below 0.
pub(crate) fn clamp_colors(colors: &mut [[f32; 3]]) {
    for c in colors {
        *c = c.map(|x| x.max(0.0));
    }
}

/// The Embree basis of a USD `type` and `basis`.
fn basis_of(kind: &str, basis: &str) -> Result<CurveBasis> {
    Ok(match (kind, basis) {
        ("linear", _) => CurveBasis::Linear,
        ("cubic", "bezier") => CurveBasis::Bezier,
        ("cubic", "bspline") => CurveBasis::BSpline,
        ("cubic", "catmullRom") => CurveBasis::CatmullRom,
        ("cubic", other) => {
            return Err(invalid_arg!(
                "basis \"{other}\" is not supported (bezier, bspline and catmullRom are)"
            ));
        }
        (other, _) => {
            return Err(invalid_arg!(
                "type \"{other}\" is not a BasisCurves type (linear or cubic)"
            ));
        }
    })
}

/// The `wrap` token.
fn wrap_of(name: &str) -> Result<Wrap> {
    Ok(match name {
        "nonperiodic" => Wrap::Nonperiodic,
        "pinned" => Wrap::Pinned,
        "periodic" => Wrap::Periodic,
        other => {
            return Err(invalid_arg!(
                "wrap \"{other}\" is not nonperiodic, pinned or periodic"
            ));
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pts(n: usize) -> Vec<[f32; 2]> {
        (0..n).map(|i| [i as f32, (i * i) as f32]).collect()
    }

    fn layout(basis: CurveBasis, wrap: Wrap) -> Layout {
        Layout { basis, wrap }
    }

    fn extended(l: Layout, v: &[[f32; 2]]) -> Vec<[f32; 2]> {
        let mut out = Vec::new();
        l.extend(v, &mut out, |p, _| p);
        assert_eq!(out.len(), l.embree_count(v.len()));
        out
    }

    /// usd-core 26.11's `ComputeVaryingDataSize` for one curve of n points: periodic n,
    /// nonperiodic and pinned n - 2 (B-spline, Catmull-Rom); the pinned curve's end
    /// segments take the end values.
    #[test]
    fn varying_counts_are_usd_cores() {
        for basis in [CurveBasis::BSpline, CurveBasis::CatmullRom] {
            for n in 2..9 {
                for (wrap, want) in [
                    (Wrap::Periodic, n),
                    (Wrap::Nonperiodic, n.max(3) - 2),
                    (Wrap::Pinned, n - 2),
                ] {
                    let l = layout(basis, wrap);
                    if let Some(s) = l.segments(n) {
                        assert_eq!(l.varying_count(s), want, "{basis:?} {wrap:?} {n}");
                    }
                }
            }
            let l = layout(basis, Wrap::Pinned);
            assert_eq!(l.varying_ends(&[1, 2, 3]), [1, 1, 2, 3, 3]);
            assert_eq!(l.varying_ends(&[4]), [4, 4, 4]);
            assert_eq!(
                layout(basis, Wrap::Nonperiodic).varying_ends(&[1, 2]),
                [1, 2]
            );
        }
    }

    #[test]
    fn pinned_adds_the_reflected_phantom_points_of_the_spec() {
        for basis in [CurveBasis::BSpline, CurveBasis::CatmullRom] {
            let l = layout(basis, Wrap::Pinned);
            let v = pts(3);
            // 2 p0 - p1 = (-1, -1); 2 p2 - p1 = (3, 7).
            assert_eq!(
                extended(l, &v),
                [[-1.0, -1.0], [0.0, 0.0], [1.0, 1.0], [2.0, 4.0], [3.0, 7.0]]
            );
            assert_eq!(l.segments(3), Some(2));
            assert_eq!(basis.segments_for(5), Some(2));
        }
        // Pinned means nothing more than nonperiodic for linear and Bezier curves.
        for basis in [CurveBasis::Linear, CurveBasis::Bezier] {
            assert_eq!(extended(layout(basis, Wrap::Pinned), &pts(4)), pts(4));
        }
    }

    #[test]
    fn periodic_repeats_the_first_points_to_close_the_curve() {
        let v = pts(3);
        let l = layout(CurveBasis::Linear, Wrap::Periodic);
        assert_eq!(extended(l, &v), [v[0], v[1], v[2], v[0]]);
        assert_eq!(
            (l.segments(3), CurveBasis::Linear.segments_for(4)),
            (Some(3), Some(3))
        );
        let l = layout(CurveBasis::Bezier, Wrap::Periodic);
        let v6 = pts(6);
        assert_eq!(extended(l, &v6)[6], v6[0]);
        assert_eq!(
            (l.segments(6), CurveBasis::Bezier.segments_for(7)),
            (Some(2), Some(2))
        );
        assert_eq!(l.segments(7), None);
        for basis in [CurveBasis::BSpline, CurveBasis::CatmullRom] {
            let l = layout(basis, Wrap::Periodic);
            assert_eq!(extended(l, &v), [v[0], v[1], v[2], v[0], v[1], v[2]]);
            assert_eq!((l.segments(3), basis.segments_for(6)), (Some(3), Some(3)));
        }
    }

    #[test]
    fn counts_that_make_no_whole_segment_are_refused() {
        assert_eq!(
            layout(CurveBasis::Bezier, Wrap::Nonperiodic).segments(5),
            None
        );
        assert_eq!(
            layout(CurveBasis::BSpline, Wrap::Nonperiodic).segments(3),
            None
        );
        assert_eq!(
            layout(CurveBasis::Linear, Wrap::Nonperiodic).segments(1),
            None
        );
        assert_eq!(
            layout(CurveBasis::CatmullRom, Wrap::Periodic).segments(2),
            None
        );
    }

    /// Varying radii reach the segment ends: each basis evaluated at the ends of the radii
    /// it was given returns the authored values (linear widths, so B-splines are exact too;
    /// a pinned B-spline's widths stop changing at its end segments, so there its ends are
    /// exact and the values between within a sixth of the step).
    #[test]
    fn varying_widths_are_the_radii_at_the_segment_ends() {
        for (basis, wrap, n, tolerance) in [
            (CurveBasis::Bezier, Wrap::Nonperiodic, 7, 1e-5),
            (CurveBasis::BSpline, Wrap::Nonperiodic, 6, 1e-5),
            (CurveBasis::CatmullRom, Wrap::Nonperiodic, 6, 1e-5),
            (CurveBasis::BSpline, Wrap::Pinned, 5, 0.25 / 6.0 + 1e-5),
            (CurveBasis::CatmullRom, Wrap::Pinned, 5, 1e-5),
        ] {
            let l = layout(basis, wrap);
            let s = l.segments(n).unwrap();
            let w: Vec<f32> = (0..l.varying_count(s))
                .map(|j| 1.0 + 0.25 * j as f32)
                .collect();
            let r = l.varying_to_points(&w, n);
            assert_eq!(r.len(), n, "{basis:?} {wrap:?}");
            let w = l.varying_ends(&w);
            let mut ext = Vec::new();
            l.extend(&r, &mut ext, |x, _| x);
            let as3: Vec<[f32; 3]> = ext.iter().map(|&[x]| [x / 10.0; 3]).collect();
            let mut ends = Vec::new();
            l.segment_ends(&as3, s, &mut ends);
            let got: Vec<f32> = ends.iter().map(|e| e[0] * 10.0).collect();
            assert_eq!(got.len(), w.len());
            for (g, want) in got.iter().zip(&w) {
                assert!(
                    (g - want).abs() < tolerance,
                    "{basis:?} {wrap:?}: {got:?} vs {w:?}"
                );
            }
            assert!((got[0] - w[0]).abs() < 1e-5 && (got[s] - w[s]).abs() < 1e-5);
        }
    }
}
