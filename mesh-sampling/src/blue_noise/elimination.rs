//! Weighted sample elimination (Yuksel 2015, Sec. 3–4) with a radius per
//! candidate: each candidate `k` claims a disk of radius `2 r_k`, every
//! other candidate `i` inside it gets the weight
//! `w_ik = (1 − d̂_ik / (2 r_k))^α` with `d̂_ik = max(d_ik, 2 r_min,k)`
//! (Eq. 1 with the weight limiting of Sec. 4.1), and the candidate with the
//! largest total weight is removed until the target count is left.
//!
//! With one radius for all candidates this is the paper's algorithm. With
//! `r_k ∝ 1/√p(x_k)` (the candidates' own density) the expected weight of a
//! candidate is the same everywhere, so elimination thins every region by
//! the same factor and the output keeps the candidates' density.

use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;

use super::heap::BucketQueue;

/// Candidates per neighbour-list chunk (fixed, so that the lists do not
/// depend on the number of threads).
const CHUNK: usize = 4096;

/// The k-d tree over candidate positions (32 points per leaf).
pub(crate) type Tree = ImmutableKdTree<f32, u32, 3, 32>;

/// The weight function's parameters.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Weights {
    /// The exponent α (8 in the paper).
    pub(crate) alpha: f64,
    /// `r_min,k / r_k = β (1 − (N/M)^γ)` (Sec. 4.1), 0 for no limiting.
    pub(crate) min_ratio: f64,
}

impl Weights {
    /// `w = (1 − max(d, 2 r_min) / (2 r))^α` for `d < 2 r`, else 0.
    #[inline]
    fn of(&self, d: f64, r: f64) -> f64 {
        let two_r = 2.0 * r;
        let d = d.max(two_r * self.min_ratio);
        if d >= two_r {
            return 0.0;
        }
        let x = 1.0 - d / two_r;
        if self.alpha == 8.0 {
            let x2 = x * x;
            let x4 = x2 * x2;
            x4 * x4
        } else {
            x.powf(self.alpha)
        }
    }
}

/// For each candidate `k`, the candidates inside its disk and their weight
/// contributions, stored chunk by chunk.
struct Neighbours {
    chunks: Vec<ChunkLists>,
}

struct ChunkLists {
    /// `offsets[j]..offsets[j + 1]` are the entries of the chunk's `j`-th
    /// candidate.
    offsets: Vec<u32>,
    entries: Vec<(u32, f32)>,
}

impl Neighbours {
    fn build(tree: &Tree, points: &[[f32; 3]], radii: &[f32], weights: Weights) -> Self {
        let chunk = |(c, pts): (usize, &[[f32; 3]])| {
            let mut offsets = Vec::with_capacity(pts.len() + 1);
            let mut entries = Vec::new();
            offsets.push(0);
            for (j, p) in pts.iter().enumerate() {
                let k = c * CHUNK + j;
                let r = radii[k];
                let reach = 2.0 * r;
                for nb in tree.within_unsorted::<SquaredEuclidean>(p, reach * reach) {
                    if nb.item as usize != k {
                        let w = weights.of(f64::from(nb.distance).sqrt(), f64::from(r));
                        if w > 0.0 {
                            entries.push((nb.item, w as f32));
                        }
                    }
                }
                offsets.push(entries.len() as u32);
            }
            ChunkLists { offsets, entries }
        };
        #[cfg(feature = "rayon")]
        let chunks = {
            use rayon::prelude::*;
            points.par_chunks(CHUNK).enumerate().map(chunk).collect()
        };
        #[cfg(not(feature = "rayon"))]
        let chunks = points.chunks(CHUNK).enumerate().map(chunk).collect();
        Self { chunks }
    }

    #[inline]
    fn of(&self, k: usize) -> &[(u32, f32)] {
        let c = &self.chunks[k / CHUNK];
        let j = k % CHUNK;
        &c.entries[c.offsets[j] as usize..c.offsets[j + 1] as usize]
    }

    fn len(&self) -> usize {
        self.chunks.iter().map(|c| c.offsets.len() - 1).sum()
    }
}

/// The candidates left after eliminating down to `target`, in ascending
/// order, and the ones removed, in the order they were removed.
pub(crate) struct Eliminated {
    pub(crate) survivors: Vec<u32>,
    pub(crate) removed: Vec<u32>,
}

/// Eliminates candidates at `points` (disk radii `radii`) until `target`
/// are left. Deterministic: the lists are built in fixed chunks and the
/// heap breaks ties by index.
pub(crate) fn eliminate(
    points: &[[f32; 3]],
    radii: &[f32],
    target: usize,
    weights: Weights,
) -> Eliminated {
    let tree = Tree::new_from_slice(points);
    let lists = Neighbours::build(&tree, points, radii, weights);
    debug_assert_eq!(lists.len(), points.len());
    // Each candidate's total weight, summed in candidate order.
    let mut total = vec![0.0f64; points.len()];
    for k in 0..points.len() {
        for &(i, w) in lists.of(k) {
            total[i as usize] += f64::from(w);
        }
    }
    let mut heap = BucketQueue::new(total);
    let mut removed = Vec::with_capacity(points.len().saturating_sub(target));
    while heap.len() > target {
        let Some(k) = heap.pop() else { break };
        removed.push(k);
        for &(i, w) in lists.of(k as usize) {
            // −∞ − w stays −∞: removed neighbours need no test.
            heap.decrease(i, f64::from(w));
        }
    }
    let survivors = (0..points.len() as u32)
        .filter(|&i| heap.contains(i))
        .collect();
    Eliminated { survivors, removed }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weight_function_matches_the_paper() {
        let w = Weights {
            alpha: 8.0,
            min_ratio: 0.0,
        };
        assert_eq!(w.of(0.0, 1.0), 1.0);
        assert!((w.of(1.0, 1.0) - 0.5f64.powi(8)).abs() < 1e-15);
        assert_eq!(w.of(2.0, 1.0), 0.0);
        assert_eq!(w.of(3.0, 1.0), 0.0);
        // Weight limiting: closer than 2 r_min counts as 2 r_min.
        let limited = Weights {
            alpha: 8.0,
            min_ratio: 0.25,
        };
        assert_eq!(limited.of(0.0, 1.0), limited.of(0.5, 1.0));
        assert!((limited.of(0.5, 1.0) - 0.75f64.powi(8)).abs() < 1e-15);
        // A non-integer exponent takes the general path.
        let a = Weights {
            alpha: 2.5,
            min_ratio: 0.0,
        };
        assert!((a.of(1.0, 1.0) - 0.5f64.powf(2.5)).abs() < 1e-15);
    }

    #[test]
    fn removes_the_crowded_point_first() {
        // Three points close together and one far away: the middle of the
        // cluster has the largest weight.
        let points = [
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [5.0, 0.0, 0.0],
        ];
        let radii = [0.5f32; 4];
        let w = Weights {
            alpha: 8.0,
            min_ratio: 0.0,
        };
        let e = eliminate(&points, &radii, 3, w);
        assert_eq!(e.removed, vec![1]);
        assert_eq!(e.survivors, vec![0, 2, 3]);
        let e = eliminate(&points, &radii, 2, w);
        assert_eq!(e.survivors.len(), 2);
        assert!(e.survivors.contains(&3));
    }
}
