//! Spatial order for what Embree reads: items sorted along a Morton curve through their
//! centres, so that items near one another in space are near one another in memory.
//!
//! Embree's curve build and traversal spend most of their time fetching control points
//! (docs/large-grooms.md); fetched in an order unrelated to space, each fetch misses the
//! cache. The strands of a groom (`Curves::spatially_ordered`) follow a Morton curve; the
//! segments of a large curve geometry are cut into compact parts by median splits, each
//! built by Embree as a small scene of its own (`CurveGeometry`, `SceneBuilder`).

use std::ops::Range;

use glam::Vec3;
use rayon::prelude::*;

use crate::Result;
use crate::threads;

/// The indices `0..n` sorted by the 30-bit Morton code of `centre(i)` on a 1024^3 grid
/// over the centres' bounds; ties keep index order, so the order is a pure function of the
/// centres (whatever the thread count). A non-finite centre sorts as the grid's corner.
/// `n` is at most `u32::MAX`, as every count Embree indexes is. Runs on threads of its own
/// ([`threads::scoped`]); fails only if they cannot start.
pub(crate) fn morton_order(
    n: usize,
    centre: impl Fn(usize) -> Vec3 + Sync + Send,
) -> Result<Vec<u32>> {
    debug_assert!(u32::try_from(n).is_ok());
    threads::scoped(0, || {
        let finite = |c: Vec3| c.is_finite().then_some(c);
        let (lo, hi) = finite_bounds((0..n).into_par_iter().map(&centre));
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
    })
}

/// The indices `0..n` cut in two at the median of their centres along the longest axis of
/// the centres' bounds, each half again, until every part holds at most `most`: the
/// indices in that order, and the parts as ranges of it (in order, covering it). Ties are
/// broken by index, so the result is a pure function of the centres (whatever the thread
/// count); non-finite centres are left out of the bounds and sort by `f32::total_cmp`.
/// `n` is at most `u32::MAX`.
pub(crate) fn median_split(
    n: usize,
    most: usize,
    centre: impl Fn(usize) -> Vec3 + Sync + Send,
) -> Result<(Vec<u32>, Vec<Range<u32>>)> {
    debug_assert!(u32::try_from(n).is_ok());
    threads::scoped(0, || {
        // Each index beside its centre, so that every pass reads one contiguous array.
        let mut items: Vec<(Vec3, u32)> = (0..n)
            .into_par_iter()
            .map(|i| (centre(i), i as u32))
            .collect();
        let parts = split(&mut items, most.max(1), 0);
        (items.into_par_iter().map(|(_, i)| i).collect(), parts)
    })
}

fn split(items: &mut [(Vec3, u32)], most: usize, start: u32) -> Vec<Range<u32>> {
    let len = items.len() as u32;
    if items.len() <= most {
        return std::iter::once(start..start + len).collect();
    }
    let (lo, hi) = finite_bounds(items.par_iter().map(|&(c, _)| c));
    // The longest axis, the first of equal ones.
    let axis = (hi - lo).max(Vec3::ZERO).max_position();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
    });
    let (left, right) = items.split_at_mut(mid);
    let (mut parts, rest) = rayon::join(
        || split(left, most, start),
        || split(right, most, start + mid as u32),
    );
    parts.extend(rest);
    parts
}

/// The bounds (lower, upper) of the finite points among `points`; empty (lower above
/// upper) when there is none.
fn finite_bounds(points: impl ParallelIterator<Item = Vec3>) -> (Vec3, Vec3) {
    let empty = || (Vec3::INFINITY, Vec3::NEG_INFINITY);
    points
        .filter(|c| c.is_finite())
        .fold(empty, |(lo, hi), c| (lo.min(c), hi.max(c)))
        .reduce(empty, |a, b| (a.0.min(b.0), a.1.max(b.1)))
}

/// The mean position of control points (x, y, z, radius): the centre a strand or a
/// segment is ordered by. The origin for no points.
pub(crate) fn centroid(points: &[[f32; 4]]) -> Vec3 {
    let sum = points
        .iter()
        .fold(Vec3::ZERO, |a, p| a + Vec3::new(p[0], p[1], p[2]));
    sum / points.len().max(1) as f32
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
        let order = morton_order(centres.len(), |i| centres[i]).unwrap();
        assert_eq!(order, [2, 4, 5, 1, 3, 0]);
        // Cells of one octant come before the next: (0,0,0) < (1,0,0) < (0,1,0) < (0,0,1).
        assert_eq!(morton(glam::UVec3::new(1, 0, 0)), 1);
        assert_eq!(morton(glam::UVec3::new(0, 1, 0)), 2);
        assert_eq!(morton(glam::UVec3::new(0, 0, 1)), 4);
        assert_eq!(morton(glam::UVec3::splat(1023)), (1 << 30) - 1);
        assert!(morton_order(0, |_| Vec3::ZERO).unwrap().is_empty());
    }

    #[test]
    fn median_cuts_make_compact_parts_of_at_most_the_size() {
        // 8 x 2 points on a grid, numbered column by column in a scrambled order.
        let cell = |i: usize| {
            let c = (i * 5) % 16;
            Vec3::new((c % 8) as f32, (c / 8) as f32, 0.0)
        };
        let (order, parts) = median_split(16, 4, cell).unwrap();
        assert_eq!(parts, [0..4, 4..8, 8..12, 12..16]);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..16).collect::<Vec<u32>>());
        // Cut along x (the longest axis) twice: each part is a 2 x 2 block of the grid.
        for (k, part) in parts.iter().enumerate() {
            for &i in &order[part.start as usize..part.end as usize] {
                assert_eq!(cell(i as usize).x as usize / 2, k, "{order:?}");
            }
        }
        // Equal centres are cut by index; a NaN goes last; a small set stays whole.
        let (order, parts) =
            median_split(5, 2, |i| if i == 1 { Vec3::NAN } else { Vec3::ZERO }).unwrap();
        assert_eq!(parts, [0..2, 2..3, 3..5]);
        let mut first = [order[0], order[1]];
        first.sort_unstable();
        assert_eq!((first, &order[2..]), ([0, 2], &[3, 4, 1][..]));
        let (order, parts) = median_split(3, 8, |_| Vec3::ONE).unwrap();
        assert_eq!((order, parts.len(), &parts[0]), (vec![0, 1, 2], 1, &(0..3)));
    }
}
