//! The last step of a tiled elimination: the tiles stop at about their
//! share (plus a margin, [`OVERSHOOT`](super::tiles)), so that no tile is
//! forced to an exact count its piece of surface cannot hold; the run then
//! has a few more points than asked for, and this removes the surplus,
//! closest first: the kept point whose spacing (nearest-neighbour distance
//! over twice its own packing radius, the quantity whose minimum is ρ) is
//! smallest goes, its neighbours' spacings are brought up to date, and so
//! on. The rare close pairs where tiles meet go first, so the trim also
//! raises the minimum spacing.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::num::NonZero;

use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;

/// Neighbours looked at when a point's nearest has been removed.
const NEAREST: usize = 16;

/// The indices (ascending, into `pts`) of `n` of the points `pts`
/// (`[x, y, z]` and radius `r`), after removing the `pts.len() - n` with the
/// smallest spacing one at a time. Deterministic: exact keys, ties by
/// index, and the initial spacings are each a function of the points.
pub(crate) fn trim(pts: &[[f32; 3]], r: &[f32], n: usize) -> Vec<u32> {
    let m = pts.len();
    if n >= m {
        return (0..m as u32).collect();
    }
    let tree: ImmutableKdTree<f32, u32, 3, 32> = ImmutableKdTree::new_from_slice(pts);
    let spacing = |i: usize, removed: &[bool], k: usize| -> f64 {
        let k = NonZero::new(k.min(m)).unwrap_or(NonZero::<usize>::MIN);
        tree.nearest_n::<SquaredEuclidean>(&pts[i], k)
            .into_iter()
            .find(|nb| nb.item as usize != i && !removed[nb.item as usize])
            .map_or(f64::INFINITY, |nb| {
                f64::from(nb.distance).sqrt() / (2.0 * f64::from(r[i]))
            })
    };
    let mut removed = vec![false; m];
    // Nothing is removed yet: the nearest other point is the second hit.
    let first = |i: usize| spacing(i, &removed, 2);
    #[cfg(feature = "rayon")]
    let initial: Vec<f64> = {
        use rayon::prelude::*;
        (0..m)
            .into_par_iter()
            .with_min_len(1024)
            .map(first)
            .collect()
    };
    #[cfg(not(feature = "rayon"))]
    let initial: Vec<f64> = (0..m).map(first).collect();
    // Min-heap of (spacing, index); spacings only grow as points go, so a
    // stale entry is re-entered with its current value.
    let mut heap: BinaryHeap<Reverse<(u64, u32)>> = initial
        .iter()
        .enumerate()
        .map(|(i, s)| Reverse((s.to_bits(), i as u32)))
        .collect();
    drop(initial);
    let mut left = m;
    while left > n {
        let Some(Reverse((key, i))) = heap.pop() else {
            break;
        };
        let i = i as usize;
        if removed[i] {
            continue;
        }
        let now = spacing(i, &removed, NEAREST);
        if now.to_bits() > key {
            heap.push(Reverse((now.to_bits(), i as u32)));
            continue;
        }
        removed[i] = true;
        left -= 1;
    }
    (0..m as u32).filter(|&i| !removed[i as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn removes_the_closest_points_first() {
        // A row spaced 1 apart with two extra points squeezed in.
        let mut pts: Vec<[f32; 3]> = (0..10).map(|i| [i as f32, 0.0, 0.0]).collect();
        pts.push([3.1, 0.0, 0.0]);
        pts.push([7.2, 0.0, 0.0]);
        let r = vec![0.5f32; pts.len()];
        let kept = trim(&pts, &r, 10);
        assert_eq!(kept.len(), 10);
        // One of each close pair went.
        let has = |i: u32| kept.contains(&i);
        assert!(has(3) ^ has(10), "{kept:?}");
        assert!(has(7) ^ has(11), "{kept:?}");
        assert_eq!(trim(&pts, &r, 12).len(), 12);
    }
}
