//! Weighted sample elimination (Yuksel 2015, Sec. 3–4) on one tile, with a
//! radius per candidate: each point `k` claims a disk of radius `2 r_k`,
//! every candidate `i` inside it gets the weight
//! `w_ik = (1 − d̂_ik / (2 r_k))^α` with `d̂_ik = max(d_ik, 2 r_min,k)`
//! (Eq. 1 with the weight limiting of Sec. 4.1), and the candidate with the
//! largest total weight is removed until the tile's share of the target is
//! left.
//!
//! With one radius for all candidates this is the paper's algorithm. With
//! `r_k ∝ 1/√p(x_k)` (the candidates' own density) the expected weight of a
//! candidate is the same everywhere, so elimination thins every region by
//! the same factor and the output keeps the candidates' density.
//!
//! Frozen points (the kept points of neighbouring tiles done earlier) add
//! their disks' weights but are never removed: a candidate crowding a
//! frozen point carries that weight to the end and goes early, which is
//! what the paper's single queue would do to a pair across the border.
//! Weights are recomputed from the grid when a candidate goes instead of
//! being stored (Yuksel stores them; for 5–14 candidates per point the
//! lists were most of the memory).

use super::grid::Local;
use super::heap::BucketQueue;

/// The weight function's parameters.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Weights {
    /// The exponent α (8 in the paper).
    pub(crate) alpha: f64,
    /// `r_min,k / r_k = β (1 − (N/M)^γ)` (Sec. 4.1), 0 for no limiting.
    pub(crate) min_ratio: f64,
}

impl Weights {
    /// `w = (1 − max(d, 2 r_min) / (2 r))^α` for `d < 2 r`, else 0, with
    /// `d²` given.
    #[inline]
    fn of(&self, d2: f32, r: f32) -> f64 {
        let two_r = 2.0 * f64::from(r);
        let d = f64::from(d2).sqrt().max(two_r * self.min_ratio);
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

/// When a tile's elimination stops.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    /// When this many of its candidates and near ghosts together are left:
    /// the count of its own floats with the weights, as in one global
    /// queue.
    Total(usize),
    /// When exactly this many of its own candidates are left (ghosts go
    /// at the rate the weights say).
    Own(usize),
}

/// Eliminates the tile's candidates and ghosts (the points of `local` that
/// are not frozen), heaviest first, until `stop`. Returns, per point of
/// `local`, whether it is kept (frozen points always are). Deterministic:
/// the weights are summed in cell order and the queue breaks ties by its
/// stacks' order.
///
/// The tile's disks are listed once (point, weight; 8 bytes an entry,
/// about 3.6 entries per candidate per output point) so that a removal
/// walks a list instead of querying the grid: the lists live for one tile
/// only.
pub(crate) fn eliminate(local: &Local, stop: Stop, weights: Weights) -> Vec<bool> {
    let n = local.len();
    let mut total: Vec<f64> = local
        .frozen
        .iter()
        .map(|&f| if f { f64::NEG_INFINITY } else { 0.0 })
        .collect();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut entries: Vec<(u32, f32)> = Vec::new();
    offsets.push(0u32);
    for k in 0..n {
        let r = local.r[k];
        local.within(&local.xyz[k], 2.0 * r, |i, d2| {
            if i != k && !local.frozen[i] {
                let w = weights.of(d2, r);
                if w > 0.0 {
                    total[i] += w;
                    entries.push((i as u32, w as f32));
                }
            }
        });
        offsets.push(entries.len() as u32);
    }
    let mut queue = BucketQueue::new(total);
    let mut own = (0..n).filter(|&j| local.own(j)).count();
    // Points counted by Stop::Total: all but the far ghosts.
    let mut counted = (0..n)
        .filter(|&j| !local.frozen[j] && !local.far[j])
        .count();
    let go_on = |own: usize, counted: usize| match stop {
        Stop::Total(t) => counted > t,
        Stop::Own(keep) => own > keep,
    };
    while go_on(own, counted) {
        let Some(k) = queue.pop() else { break };
        let k = k as usize;
        own -= usize::from(local.own(k));
        counted -= usize::from(!local.far[k]);
        for &(i, w) in &entries[offsets[k] as usize..offsets[k + 1] as usize] {
            // Removed keys are −∞ and stay so.
            queue.decrease(i, f64::from(w));
        }
    }
    (0..n)
        .map(|j| local.frozen[j] || queue.contains(j as u32))
        .collect()
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
        assert_eq!(w.of(4.0, 1.0), 0.0);
        assert_eq!(w.of(9.0, 1.0), 0.0);
        // Weight limiting: closer than 2 r_min counts as 2 r_min.
        let limited = Weights {
            alpha: 8.0,
            min_ratio: 0.25,
        };
        assert_eq!(limited.of(0.0, 1.0), limited.of(0.25, 1.0));
        assert!((limited.of(0.25, 1.0) - 0.75f64.powi(8)).abs() < 1e-15);
        // A non-integer exponent takes the general path.
        let a = Weights {
            alpha: 2.5,
            min_ratio: 0.0,
        };
        assert!((a.of(1.0, 1.0) - 0.5f64.powf(2.5)).abs() < 1e-15);
    }

    fn local(points: &[[f32; 3]], r: f32, frozen: &[usize]) -> Local {
        Local::of_points(points, r, frozen, [-1.0; 3], [6.0, 1.0, 1.0])
    }

    fn kept(l: &Local, flags: &[bool]) -> Vec<u32> {
        let mut k: Vec<u32> = (0..l.len())
            .filter(|&j| flags[j] && !l.frozen[j])
            .map(|j| l.global[j])
            .collect();
        k.sort_unstable();
        k
    }

    #[test]
    fn removes_the_crowded_point_first_and_never_a_frozen_one() {
        // Three points close together and one far away: the middle of the
        // cluster has the largest weight.
        let points = [
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.2, 0.0, 0.0],
            [5.0, 0.0, 0.0],
        ];
        let w = Weights {
            alpha: 8.0,
            min_ratio: 0.0,
        };
        let l = local(&points, 0.5, &[]);
        assert_eq!(kept(&l, &eliminate(&l, Stop::Own(3), w)), vec![0, 2, 3]);
        let two = kept(&l, &eliminate(&l, Stop::Own(2), w));
        assert_eq!(two.len(), 2);
        assert!(two.contains(&3));
        // The middle point frozen: one of its neighbours goes instead.
        let l = local(&points, 0.5, &[1]);
        let flags = eliminate(&l, Stop::Own(2), w);
        assert_eq!(kept(&l, &flags).len(), 2);
        assert!(flags.iter().filter(|&&f| f).count() == 3);
        assert!(kept(&l, &flags).contains(&3));
    }
}
