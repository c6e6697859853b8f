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
//!
//! In parallel: the candidates (in Morton order) are cut into tiles of
//! [`TILE`] consecutive candidates, a number fixed by the candidate count
//! alone. A candidate is *interior* when no disk links it to another tile
//! (neither its own disk's members nor the disks it lies in). First each
//! tile, on its own thread, eliminates its interior candidates down to
//! [`TILE_KEEP`] times their share of the target (`⌈interior · 3N / M⌉`):
//! a removal there only changes weights inside the tile, so the tiles are
//! independent. Then one queue over everything left (the tiles' borders
//! and survivors) eliminates down to the target, sequentially. The result
//! depends on the candidate count and the weights only, never on the
//! number of threads.

use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;

use super::heap::BucketQueue;

/// Candidates per neighbour-list chunk (fixed, so that the lists do not
/// depend on the number of threads).
const CHUNK: usize = 4096;

/// Candidates per tile of the parallel first pass (fixed, so that the
/// result does not depend on the number of threads); runs of fewer than
/// two tiles' worth of candidates are eliminated in one pass.
const TILE: usize = 1 << 15;

/// How far the parallel first pass thins a tile's interior: to this many
/// times its share of the target. Not to the share itself: a tile sees
/// its border candidates at full density (only the pass after removes
/// them), so thinning to the share removes too many of its own candidates
/// next to the border and leaves a sparse band there (ρ 0.685 at
/// N = 10⁵ from 5N candidates on the data meshes, against 0.691–0.692 for
/// one queue). Stopping at 3× leaves the last removals to the global
/// queue, which sees the borders thinned too: ρ 0.6905–0.692, for about
/// 15% more time than thinning to the share.
const TILE_KEEP: f64 = 3.0;

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

/// Eliminates candidates at `points` (disk radii `radii`; `tree` is the
/// k-d tree over `points`) until `target` are left. Deterministic: the lists are built in fixed chunks and the
/// heap breaks ties by index.
pub(crate) fn eliminate(
    tree: &Tree,
    points: &[[f32; 3]],
    radii: &[f32],
    target: usize,
    weights: Weights,
) -> Eliminated {
    eliminate_in_tiles(tree, points, radii, target, weights, TILE)
}

/// [`eliminate`] with tiles of `tile` candidates (`usize::MAX`: one
/// queue throughout).
fn eliminate_in_tiles(
    tree: &Tree,
    points: &[[f32; 3]],
    radii: &[f32],
    target: usize,
    weights: Weights,
    tile: usize,
) -> Eliminated {
    let lists = Neighbours::build(tree, points, radii, weights);
    debug_assert_eq!(lists.len(), points.len());
    // Each candidate's total weight, summed in candidate order.
    let mut total = vec![0.0f64; points.len()];
    for k in 0..points.len() {
        for &(i, w) in lists.of(k) {
            total[i as usize] += f64::from(w);
        }
    }
    let mut removed = Vec::with_capacity(points.len().saturating_sub(target));
    if points.len() / 2 >= tile {
        removed = thin_tiles(&lists, &mut total, target, tile);
    }
    let mut heap = BucketQueue::new(total);
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

/// Whether each candidate shares a disk with a candidate of another tile
/// (tiles of `tile` consecutive candidates).
fn border(lists: &Neighbours, m: usize, tile: usize) -> Vec<bool> {
    let mut border = vec![false; m];
    for k in 0..m {
        for &(i, _) in lists.of(k) {
            if i as usize / tile != k / tile {
                border[k] = true;
                border[i as usize] = true;
            }
        }
    }
    border
}

/// The first pass: every tile eliminates its interior candidates down to
/// `⌈interior · TILE_KEEP · target / M⌉`, the tiles on all threads. Removed candidates'
/// totals become −∞, the others' are lowered by their removed neighbours.
/// Returns the removed candidates, tile after tile, each tile's in the
/// order it removed them.
fn thin_tiles(lists: &Neighbours, total: &mut [f64], target: usize, tile: usize) -> Vec<u32> {
    let m = total.len();
    let border = border(lists, m, tile);
    let keep = (TILE_KEEP * target as f64 / m as f64).min(1.0);
    let thin = |(t, tot): (usize, &mut [f64])| thin_tile(lists, tot, t * tile, &border, keep);
    #[cfg(feature = "rayon")]
    let removed: Vec<Vec<u32>> = {
        use rayon::prelude::*;
        total.par_chunks_mut(tile).enumerate().map(thin).collect()
    };
    #[cfg(not(feature = "rayon"))]
    let removed: Vec<Vec<u32>> = total.chunks_mut(tile).enumerate().map(thin).collect();
    removed.concat()
}

/// One tile of [`thin_tiles`]: `tot` holds the totals of candidates
/// `start..start + tot.len()`. An interior candidate's disk lies in the
/// tile, so its removal touches `tot` only.
fn thin_tile(
    lists: &Neighbours,
    tot: &mut [f64],
    start: usize,
    border: &[bool],
    keep: f64,
) -> Vec<u32> {
    let inside = |j: usize| !border[start + j];
    let keys: Vec<f64> = (0..tot.len())
        .map(|j| if inside(j) { tot[j] } else { f64::NEG_INFINITY })
        .collect();
    let interior = (0..tot.len()).filter(|&j| inside(j)).count();
    let kept = (interior as f64 * keep).ceil() as usize;
    let mut queue = BucketQueue::new(keys);
    let mut removed = Vec::with_capacity(interior.saturating_sub(kept));
    while queue.len() > kept {
        let Some(j) = queue.pop() else { break };
        let k = start + j as usize;
        removed.push(k as u32);
        for &(i, w) in lists.of(k) {
            let local = i as usize - start;
            if inside(local) {
                queue.decrease(local as u32, f64::from(w));
            } else {
                tot[local] -= f64::from(w);
            }
        }
    }
    for (j, t) in tot.iter_mut().enumerate() {
        if inside(j) {
            *t = queue.key(j as u32);
        }
    }
    removed
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
        let tree = Tree::new_from_slice(&points);
        let e = eliminate(&tree, &points, &radii, 3, w);
        assert_eq!(e.removed, vec![1]);
        assert_eq!(e.survivors, vec![0, 2, 3]);
        let e = eliminate(&tree, &points, &radii, 2, w);
        assert_eq!(e.survivors.len(), 2);
        assert!(e.survivors.contains(&3));
    }

    /// ρ of `eliminate_in_tiles` on uniform candidates over the unit
    /// square (5 per output point, in Morton order as `blue_noise` sorts
    /// them), with tiles of `tile` candidates.
    fn rho_in_tiles(tile: usize) -> f64 {
        use rand::{RngExt, SeedableRng};
        let n = 4000;
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut points: Vec<[f32; 3]> = (0..5 * n)
            .map(|_| [rng.random::<f32>(), rng.random::<f32>(), 0.0])
            .collect();
        let morton = |p: &[f32; 3]| {
            let (x, y) = ((p[0] * 65535.0) as u32, (p[1] * 65535.0) as u32);
            (0..16).fold(0u64, |c, b| {
                c | u64::from((x >> b) & 1) << (2 * b) | u64::from((y >> b) & 1) << (2 * b + 1)
            })
        };
        points.sort_by_key(morton);
        let radii = vec![(1.0 / (2.0 * 3f64.sqrt() * n as f64)).sqrt() as f32; points.len()];
        let w = Weights {
            alpha: 8.0,
            min_ratio: 0.65 * (1.0 - 0.2f64.powf(1.5)),
        };
        let tree = Tree::new_from_slice(&points);
        let e = eliminate_in_tiles(&tree, &points, &radii, n, w, tile);
        let kept: Vec<glam::Vec3> = e
            .survivors
            .iter()
            .map(|&i| glam::Vec3::from(points[i as usize]))
            .collect();
        assert_eq!(kept.len(), n);
        super::super::relative_radius(&kept, 1.0)
    }

    #[test]
    fn tiles_keep_the_spacing_of_one_queue() {
        // Ten tiles, a third of the candidates on a border: a first pass
        // that thinned the tiles' interiors to their share (TILE_KEEP = 1)
        // left sparse bands along the borders, ρ about 0.01 below one
        // queue's.
        let one_queue = rho_in_tiles(usize::MAX);
        let tiled = rho_in_tiles(2048);
        assert!(one_queue > 0.68, "{one_queue}");
        assert!(
            tiled > one_queue - 0.003,
            "tiled {tiled}, one queue {one_queue}"
        );
    }
}
