//! The curve bases strands are drawn with and the surface a curve is traced as
//! ([`CurveShape`]): domain types of every layer from Embree's wrapper up, so they live
//! below it. This file is also the one home of the bases' maths: which control
//! points a segment reads, its polynomial (evaluation and derivatives: the level of detail,
//! sampling a curve into polylines) and the same segment in Bezier form (bounds from the
//! control hull, conversions between bases). Every layer that draws, bounds, converts or
//! reads curves asks these, so that no two of them can disagree on a basis.

use std::ops::{Add, Div, Mul, Sub};

/// The surface built around a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveShape {
    /// A true tube (swept sphere): the reference for close-ups.
    Round,
    /// A ribbon that always faces the ray: faster, approximate when seen up close.
    Flat,
}

impl CurveShape {
    pub const ALL: [CurveShape; 2] = [CurveShape::Round, CurveShape::Flat];
}

/// How the control points of a curve segment are interpolated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CurveBasis {
    /// Straight segments between consecutive points (cones in round mode).
    Linear,
    /// Cubic Bezier: segments of 4 points, consecutive segments share their end point.
    Bezier,
    /// Uniform cubic B-spline: each segment reads 4 consecutive points, overlapping by 3.
    BSpline,
    /// Catmull-Rom: each segment reads 4 consecutive points and runs from the 2nd to the 3rd.
    CatmullRom,
}

impl CurveBasis {
    pub const ALL: [CurveBasis; 4] = [
        CurveBasis::Linear,
        CurveBasis::Bezier,
        CurveBasis::BSpline,
        CurveBasis::CatmullRom,
    ];

    /// Control points one segment reads, starting at its index.
    pub(crate) fn points_per_segment(self) -> usize {
        match self {
            CurveBasis::Linear => 2,
            _ => 4,
        }
    }

    /// Index distance between consecutive segments of one strand.
    pub(crate) fn segment_stride(self) -> usize {
        match self {
            CurveBasis::Bezier => 3,
            _ => 1,
        }
    }

    /// Number of segments a strand of `points` control points has, or `None` when that
    /// count is not a valid strand in this basis.
    pub fn segments_for(self, points: usize) -> Option<usize> {
        let order = self.points_per_segment();
        if points < order {
            return None;
        }
        let spare = points - order;
        let stride = self.segment_stride();
        (spare % stride == 0).then_some(spare / stride + 1)
    }

    /// Row k holds the weights of a segment's control points in the coefficient of t^k of
    /// its polynomial (a linear segment's last two weights are 0: it reads two points).
    pub(crate) fn power_matrix(self) -> [[f64; 4]; 4] {
        const SIXTH: f64 = 1.0 / 6.0;
        match self {
            CurveBasis::Linear => [
                [1.0, 0.0, 0.0, 0.0],
                [-1.0, 1.0, 0.0, 0.0],
                [0.0; 4],
                [0.0; 4],
            ],
            CurveBasis::Bezier => [
                [1.0, 0.0, 0.0, 0.0],
                [-3.0, 3.0, 0.0, 0.0],
                [3.0, -6.0, 3.0, 0.0],
                [-1.0, 3.0, -3.0, 1.0],
            ],
            CurveBasis::BSpline => [
                [SIXTH, 4.0 * SIXTH, SIXTH, 0.0],
                [-0.5, 0.0, 0.5, 0.0],
                [0.5, -1.0, 0.5, 0.0],
                [-SIXTH, 0.5, -0.5, SIXTH],
            ],
            CurveBasis::CatmullRom => [
                [0.0, 1.0, 0.0, 0.0],
                [-0.5, 0.0, 0.5, 0.0],
                [1.0, -2.5, 2.0, -0.5],
                [-0.5, 1.5, -1.5, 0.5],
            ],
        }
    }

    /// The weights of a segment's control points at parameter t.
    pub(crate) fn weights(self, t: f64) -> [f64; 4] {
        let m = self.power_matrix();
        std::array::from_fn(|i| m[0][i] + t * (m[1][i] + t * (m[2][i] + t * m[3][i])))
    }

    /// The control points of the same segment in Bezier form, from the four points it reads
    /// (of a linear segment, the first two: the others are not read), in any vector type
    /// (`Vec4` for x, y, z and radius; `DVec3`): its control hull bounds it, and Embree
    /// traces a Bezier curve of them as the same curve.
    pub fn bezier_form<T, S>(self, [p0, p1, p2, p3]: [T; 4]) -> [T; 4]
    where
        T: Copy + Add<Output = T> + Sub<Output = T> + Mul<S, Output = T> + Div<S, Output = T>,
        S: From<f32>,
    {
        let k = |v: f32| S::from(v);
        match self {
            CurveBasis::Linear => [
                p0,
                (p0 * k(2.0) + p1) / k(3.0),
                (p0 + p1 * k(2.0)) / k(3.0),
                p1,
            ],
            CurveBasis::Bezier => [p0, p1, p2, p3],
            CurveBasis::BSpline => [
                (p0 + p1 * k(4.0) + p2) / k(6.0),
                (p1 * k(2.0) + p2) / k(3.0),
                (p1 + p2 * k(2.0)) / k(3.0),
                (p1 + p2 * k(4.0) + p3) / k(6.0),
            ],
            CurveBasis::CatmullRom => [p1, p1 + (p2 - p0) / k(6.0), p2 - (p3 - p1) / k(6.0), p2],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The polynomial and the Bezier form are the same curve: the Bezier form evaluated
    /// with Bernstein weights is the power form's value, for every basis, at every t.
    #[test]
    fn the_power_and_bezier_forms_agree() {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, -0.5),
            DVec3::new(2.5, 1.0, 1.0),
            DVec3::new(4.0, -1.0, 0.25),
        ];
        for basis in CurveBasis::ALL {
            let b = basis.bezier_form::<DVec3, f64>(p);
            for t in [0.0, 0.1, 0.25, 0.5, 0.9, 1.0] {
                let w = basis.weights(t);
                let power: DVec3 = (0..4).map(|i| p[i] * w[i]).sum();
                let bezier: DVec3 = (0..4)
                    .map(|i| b[i] * CurveBasis::Bezier.weights(t)[i])
                    .sum();
                assert!(
                    (power - bezier).length() < 1e-12,
                    "{basis:?} at {t}: {power} {bezier}"
                );
            }
            // The weights of a point add up to 1 (the curve moves with its points).
            assert!((basis.weights(0.3).iter().sum::<f64>() - 1.0).abs() < 1e-12);
        }
    }

    #[test]
    fn segments_per_basis() {
        assert_eq!(CurveBasis::Linear.segments_for(5), Some(4));
        assert_eq!(CurveBasis::Linear.segments_for(1), None);
        assert_eq!(CurveBasis::BSpline.segments_for(6), Some(3));
        assert_eq!(CurveBasis::CatmullRom.segments_for(3), None);
        assert_eq!(CurveBasis::Bezier.segments_for(7), Some(2));
        assert_eq!(CurveBasis::Bezier.segments_for(6), None);
    }
}
