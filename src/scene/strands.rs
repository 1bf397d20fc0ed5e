//! A groom as plain data: control points of many strands, concatenated.

use crate::error::{Result, invalid_arg};
use crate::validate;

/// Strands of control points. Radii are radii (not the diameters that USD, Alembic and
/// .hair thickness use), one per control point.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Strands {
    /// Control points of all strands, strand after strand.
    pub points: Vec<[f32; 3]>,
    /// Radius of each control point (same length as `points`).
    pub radii: Vec<f32>,
    /// Number of control points of each strand (each >= 2).
    pub counts: Vec<u32>,
    /// Optional linear RGB colour of each control point.
    pub colors: Option<Vec<[f32; 3]>>,
}

impl Strands {
    pub fn strand_count(&self) -> usize {
        self.counts.len()
    }

    pub fn point_count(&self) -> usize {
        self.points.len()
    }

    /// Number of segments between consecutive control points.
    pub fn segment_count(&self) -> usize {
        self.counts
            .iter()
            .map(|&c| c.saturating_sub(1) as usize)
            .sum()
    }

    /// First control point index of each strand.
    pub fn offsets(&self) -> impl Iterator<Item = usize> + '_ {
        self.counts.iter().scan(0usize, |acc, &c| {
            let start = *acc;
            *acc += c as usize;
            Some(start)
        })
    }

    /// Axis-aligned bounds of the control points (not widened by the radii);
    /// None when there are no points.
    pub fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let first = *self.points.first()?;
        Some(self.points.iter().fold((first, first), |(lo, hi), p| {
            (
                std::array::from_fn(|i| lo[i].min(p[i])),
                std::array::from_fn(|i| hi[i].max(p[i])),
            )
        }))
    }

    /// Checks that the arrays agree and every value is usable: at least two points per
    /// strand, counts that add up, finite points, finite radii > 0, finite colours >= 0.
    pub fn validate(&self) -> Result<()> {
        let total: u64 = self.counts.iter().map(|&c| u64::from(c)).sum();
        if total != self.points.len() as u64 {
            return Err(invalid_arg!(
                "strand counts add up to {total} points but {} points are given",
                self.points.len()
            ));
        }
        if let Some(s) = self.counts.iter().position(|&c| c < 2) {
            return Err(invalid_arg!(
                "strand {s} has {} control points: at least 2 are needed",
                self.counts[s]
            ));
        }
        if self.radii.len() != self.points.len() {
            return Err(invalid_arg!(
                "{} radii for {} points",
                self.radii.len(),
                self.points.len()
            ));
        }
        validate::positions("point", &self.points)?;
        if let Some(i) = self.radii.iter().position(|r| !(r.is_finite() && *r > 0.0)) {
            return Err(invalid_arg!(
                "radius {i} = {}: must be finite and > 0",
                self.radii[i]
            ));
        }
        if let Some(colors) = &self.colors {
            if colors.len() != self.points.len() {
                return Err(invalid_arg!(
                    "{} colours for {} points",
                    colors.len(),
                    self.points.len()
                ));
            }
            validate::colors(colors)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_strands() -> Strands {
        Strands {
            points: vec![
                [0.0; 3],
                [0.0, 1.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [1.0, 2.0, 0.5],
            ],
            radii: vec![0.1; 5],
            counts: vec![2, 3],
            colors: None,
        }
    }

    #[test]
    fn counts_offsets_and_bounds() {
        let s = two_strands();
        s.validate().unwrap();
        assert_eq!(
            (s.strand_count(), s.point_count(), s.segment_count()),
            (2, 5, 3)
        );
        assert_eq!(s.offsets().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(s.bounds(), Some(([0.0, 0.0, 0.0], [1.0, 2.0, 0.5])));
    }

    #[test]
    fn bad_strands_are_named() {
        let mut s = two_strands();
        s.counts = vec![1, 4];
        assert!(s.validate().unwrap_err().to_string().contains("strand 0"));
        let mut s = two_strands();
        s.radii[3] = 0.0;
        assert!(s.validate().unwrap_err().to_string().contains("radius 3"));
        let mut s = two_strands();
        s.points[2][1] = f32::NAN;
        assert!(s.validate().unwrap_err().to_string().contains("point 2"));
        let mut s = two_strands();
        s.counts = vec![2, 2];
        assert!(s.validate().unwrap_err().to_string().contains("add up"));
    }
}
