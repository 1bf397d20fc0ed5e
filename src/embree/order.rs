//! Spatial order for what Embree reads: items sorted along a Morton curve through their
//! centres, so that items near one another in space are near one another in memory.
//!
//! Embree's curve build and traversal spend most of their time fetching control points
//! (docs/large-grooms.md); fetched in an order unrelated to space, each fetch misses the
//! cache. The strands of a groom (`Curves::spatially_ordered`) and the segments Embree is
//! handed (`CurveGeometry`) both take this order.

use glam::Vec3;
use rayon::prelude::*;

/// The indices `0..n` sorted by the 30-bit Morton code of `centre(i)` on a 1024^3 grid
/// over the centres' bounds; ties keep index order, so the order is a pure function of the
/// centres (whatever the thread count). A non-finite centre sorts as the grid's corner.
/// `n` is at most `u32::MAX`, as every count Embree indexes is.
pub(crate) fn morton_order(n: usize, centre: impl Fn(usize) -> Vec3 + Sync) -> Vec<u32> {
    debug_assert!(u32::try_from(n).is_ok());
    let finite = |c: Vec3| c.is_finite().then_some(c);
    let (lo, hi) = (0..n)
        .into_par_iter()
        .filter_map(|i| finite(centre(i)))
        .fold(
            || (Vec3::INFINITY, Vec3::NEG_INFINITY),
            |(lo, hi), c| (lo.min(c), hi.max(c)),
        )
        .reduce(
            || (Vec3::INFINITY, Vec3::NEG_INFINITY),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let scale = 1023.0 / (hi - lo).max_element().max(f32::MIN_POSITIVE);
    let mut keys: Vec<u64> = (0..n)
        .into_par_iter()
        .map(|i| {
            let cell =
                finite(centre(i)).map_or(glam::UVec3::ZERO, |c| ((c - lo) * scale).as_uvec3());
            (u64::from(morton(cell)) << 32) | i as u64
        })
        .collect();
    keys.par_sort_unstable();
    keys.into_par_iter().map(|k| k as u32).collect()
}

/// The 30-bit Morton code of a cell of a 1024^3 grid: its coordinates' bits interleaved.
fn morton(p: glam::UVec3) -> u32 {
    let spread = |v: u32| {
        let mut v = v.min(1023);
        v = (v | (v << 16)) & 0x0300_00ff;
        v = (v | (v << 8)) & 0x0300_f00f;
        v = (v | (v << 4)) & 0x030c_30c3;
        (v | (v << 2)) & 0x0924_9249
    };
    spread(p.x) | (spread(p.y) << 1) | (spread(p.z) << 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_follow_the_curve_and_ties_keep_their_order() {
        // Along x, out of order, with a tie (1 and 3), a NaN and an infinity.
        let centres = [
            Vec3::new(3.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::NAN,
            Vec3::new(f32::INFINITY, 0.0, 0.0),
        ];
        let order = morton_order(centres.len(), |i| centres[i]);
        assert_eq!(order, [2, 4, 5, 1, 3, 0]);
        // Cells of one octant come before the next: (0,0,0) < (1,0,0) < (0,1,0) < (0,0,1).
        assert_eq!(morton(glam::UVec3::new(1, 0, 0)), 1);
        assert_eq!(morton(glam::UVec3::new(0, 1, 0)), 2);
        assert_eq!(morton(glam::UVec3::new(0, 0, 1)), 4);
        assert_eq!(morton(glam::UVec3::splat(1023)), (1 << 30) - 1);
        assert!(morton_order(0, |_| Vec3::ZERO).is_empty());
    }
}
