//! Ragged arrays, items of varying lengths laid end to end (a groom's strands in its
//! control points, index buffer and colours), written in parallel. At ten million strands
//! the serial copies of the points took half of the curves stage, most of it the kernel
//! faulting in fresh pages, which threads fault in side by side (docs/large-grooms.md).

use std::ops::Range;

use crate::Result;
use crate::threads;

/// Items per task: enough that the split costs nothing beside the copies.
const GRAIN: usize = 4096;

/// Where each item starts in the array laid out from `lengths`, the array's length last.
pub(crate) fn starts(lengths: impl Iterator<Item = usize>) -> Vec<usize> {
    let mut starts = Vec::with_capacity(lengths.size_hint().0 + 1);
    starts.push(0);
    starts.extend(lengths.scan(0, |end, n| {
        *end += n;
        Some(*end)
    }));
    starts
}

/// The array of `starts` (from [`starts`]) with `spare` elements of spare capacity, item
/// `i`'s elements `starts[i]..starts[i + 1]` written by `fill(i, ..)`, items in parallel
/// on threads of the library's own ([`threads::scoped`]) when there are more than one
/// task's [`GRAIN`] (fewer are not worth starting threads for). It starts zeroed, from
/// fresh pages where it is large, so each page is first touched by the thread that fills
/// it. Fails only if the threads cannot start.
pub(crate) fn filled<T: Copy + Default + Send>(
    starts: &[usize],
    spare: usize,
    fill: impl Fn(usize, &mut [T]) + Sync,
) -> Result<Vec<T>> {
    let len = starts.last().copied().unwrap_or(0);
    let mut out = vec![T::default(); len + spare];
    out.truncate(len);
    let items = 0..starts.len().saturating_sub(1);
    if items.len() > GRAIN {
        threads::scoped(0, || fill_items(items, starts, &mut out, &fill))?;
    } else if !items.is_empty() {
        fill_items(items, starts, &mut out, &fill);
    }
    Ok(out)
}

/// Fills `out`, the elements of `items`, halving the items until a task holds [`GRAIN`].
fn fill_items<T: Send>(
    items: Range<usize>,
    starts: &[usize],
    out: &mut [T],
    fill: &(impl Fn(usize, &mut [T]) + Sync),
) {
    let base = starts[items.start];
    if items.len() <= GRAIN {
        for i in items {
            fill(i, &mut out[starts[i] - base..starts[i + 1] - base]);
        }
        return;
    }
    let mid = items.start + items.len() / 2;
    let (left, right) = out.split_at_mut(starts[mid] - base);
    rayon::join(
        || fill_items(items.start..mid, starts, left, fill),
        || fill_items(mid..items.end, starts, right, fill),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_are_laid_end_to_end_each_filled_by_its_own_call() {
        let lengths: Vec<usize> = (0..3 * GRAIN + 7).map(|i| i % 5).collect();
        let starts = starts(lengths.iter().copied());
        assert_eq!(starts.len(), lengths.len() + 1);
        assert_eq!(*starts.last().unwrap(), lengths.iter().sum::<usize>());
        let out: Vec<u32> = filled(&starts, 3, |i, out| {
            assert_eq!(out.len(), lengths[i]);
            for (k, o) in out.iter_mut().enumerate() {
                *o = (i * 8 + k) as u32;
            }
        })
        .unwrap();
        let expected: Vec<u32> = (lengths.iter().enumerate())
            .flat_map(|(i, &n)| (0..n).map(move |k| (i * 8 + k) as u32))
            .collect();
        assert_eq!(out, expected);
        assert!(out.capacity() >= out.len() + 3);
    }

    #[test]
    fn no_items_give_an_empty_array() {
        let out: Vec<u8> = filled(&starts(std::iter::empty()), 0, |_, _| unreachable!()).unwrap();
        assert!(out.is_empty());
        let out: Vec<u8> = filled(&[], 0, |_, _| unreachable!()).unwrap();
        assert!(out.is_empty());
    }
}
