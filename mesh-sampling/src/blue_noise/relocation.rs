//! The dense packing's second step: farthest-point relocation on the
//! candidate pool, a greedy form of Schlömer, Heck & Deussen's
//! farthest-point optimisation ("Farthest-Point Optimized Point Sets with
//! Maximized Minimum Distance", HPG 2011) restricted to the candidates.
//!
//! After elimination, the kept point with the smallest spacing (its
//! nearest-neighbour distance over twice its own packing radius, the
//! quantity whose minimum is ρ), or else its nearest neighbour, is taken
//! out and put back at the unused candidate farthest from every kept
//! point (the centre of the largest hole the pool offers), as long as that
//! hole is worth more than the smallest spacing: the minimum never falls,
//! and the loop stops when neither of the closest pair can move (or after
//! as many moves as points). Every point
//! stays one of the sampler's candidates, with all of its fields.
//!
//! With radii `r_k` that vary (a density), a point `i`'s spacing is
//! `s_i = d(i, nearest) / (2 r_i)`, as in
//! [`relative_radius_with_density`](super::relative_radius_with_density),
//! and a hole at candidate `c` is worth
//! `h_c = min_j d(c, j) / (2 max(r_c, r_j))` over the kept points `j`: the
//! least spacing that putting a point at `c` would leave to `c` and to its
//! neighbours. Spacings are capped at 1 (a hexagonal packing), so every
//! query has a bounded radius.
//!
//! Deterministic: one sequential loop over exact keys, ties broken by
//! index; the initial keys are computed in parallel but each is a function
//! of the positions alone.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use std::num::NonZero;

use kiddo::SquaredEuclidean;

use super::elimination::Tree;

/// Spacings at or above this count as perfect (a hexagonal packing).
const CAP: f64 = 1.0;

/// A non-negative finite `f64` as an integer with the same order.
#[inline]
fn ordered(x: f64) -> u64 {
    debug_assert!(x >= 0.0);
    x.to_bits()
}

struct State<'a> {
    tree: &'a Tree,
    points: &'a [[f32; 3]],
    radii: &'a [f32],
    /// The largest radius: a query of `2 · CAP · r_hi` finds every kept
    /// point whose own disk reaches a position.
    r_hi: f64,
    kept: Vec<bool>,
    /// Each kept point's spacing, exact.
    spacing: Vec<f64>,
    /// Min-heap of `(spacing, index)`; an entry is valid while the point
    /// is kept and its spacing equals the entry's.
    worst: BinaryHeap<Reverse<(u64, u32)>>,
    /// Max-heap of `(bound, index)` over unused candidates: every entry
    /// bounds its hole's value from above, so the first entry whose exact
    /// value equals its bound is the largest hole among those entered.
    holes: BinaryHeap<(u64, Reverse<u32>)>,
}

#[inline]
fn distance(a: &[f32; 3], b: &[f32; 3]) -> f64 {
    let d = [
        f64::from(a[0]) - f64::from(b[0]),
        f64::from(a[1]) - f64::from(b[1]),
        f64::from(a[2]) - f64::from(b[2]),
    ];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

impl State<'_> {
    fn r(&self, k: usize) -> f64 {
        f64::from(self.radii[k])
    }

    /// Candidates within `reach` of candidate `k` (including `k`).
    fn around(&self, k: usize, reach: f64) -> impl Iterator<Item = usize> + '_ {
        let reach = reach as f32;
        self.tree
            .within_unsorted::<SquaredEuclidean>(&self.points[k], reach * reach)
            .into_iter()
            .map(|nb| nb.item as usize)
    }

    /// The spacing of candidate `k` against the kept points other than
    /// itself, measured with its own radius.
    fn own_spacing(&self, k: usize) -> f64 {
        let two_r = 2.0 * self.r(k);
        self.around(k, two_r * CAP)
            .filter(|&j| j != k && self.kept[j])
            .map(|j| distance(&self.points[k], &self.points[j]) / two_r)
            .fold(CAP, f64::min)
    }

    /// The value of a hole at candidate `c` (not kept): the least spacing
    /// a point there would leave.
    fn hole(&self, c: usize) -> f64 {
        let rc = self.r(c);
        self.around(c, 2.0 * CAP * rc.max(self.r_hi))
            .filter(|&j| j != c && self.kept[j])
            .map(|j| distance(&self.points[c], &self.points[j]) / (2.0 * rc.max(self.r(j))))
            .fold(CAP, f64::min)
    }

    /// The smallest current spacing and its point, dropping stale entries.
    fn peek_worst(&mut self) -> Option<(f64, u32)> {
        while let Some(&Reverse((s, i))) = self.worst.peek() {
            let k = i as usize;
            if self.kept[k] && ordered(self.spacing[k]) == s {
                return Some((self.spacing[k], i));
            }
            self.worst.pop();
        }
        None
    }

    /// The largest hole among the entered candidates, taken off the heap.
    fn pop_hole(&mut self) -> Option<(f64, u32)> {
        while let Some((bound, Reverse(c))) = self.holes.pop() {
            let k = c as usize;
            if self.kept[k] {
                continue;
            }
            let exact = self.hole(k);
            if ordered(exact) == bound {
                return Some((exact, c));
            }
            self.holes.push((ordered(exact), Reverse(c)));
        }
        None
    }

    fn set_spacing(&mut self, k: usize, s: f64) {
        self.spacing[k] = s;
        self.worst.push(Reverse((ordered(s), k as u32)));
    }

    /// Keeps candidate `h`: its spacing, and its neighbours' that it
    /// lowers.
    fn insert(&mut self, h: usize) {
        self.kept[h] = true;
        let s = self.own_spacing(h);
        self.set_spacing(h, s);
        let near: Vec<usize> = self
            .around(h, 2.0 * CAP * self.r_hi)
            .filter(|&j| j != h && self.kept[j])
            .collect();
        for j in near {
            let v = distance(&self.points[h], &self.points[j]) / (2.0 * self.r(j));
            if v < self.spacing[j] {
                self.set_spacing(j, v);
            }
        }
    }

    /// The kept point nearest to kept point `k`, if one is within its
    /// capped reach.
    fn nearest_kept(&self, k: usize) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        for j in self.around(k, 2.0 * CAP * self.r(k)) {
            if j != k && self.kept[j] {
                let d = distance(&self.points[k], &self.points[j]);
                if best.is_none_or(|(b, i)| (d, j) < (b, i)) {
                    best = Some((d, j));
                }
            }
        }
        best.map(|(_, j)| j)
    }

    /// Moves kept point `x` into the largest hole if that hole is worth
    /// more than `worst`, the smallest spacing; otherwise leaves it.
    fn try_move(&mut self, x: usize, worst: f64) -> bool {
        self.remove(x, worst);
        match self.pop_hole() {
            Some((value, h)) if value > worst => {
                self.insert(h as usize);
                true
            }
            other => {
                if let Some((value, h)) = other {
                    self.holes.push((ordered(value), Reverse(h)));
                }
                self.insert(x);
                false
            }
        }
    }

    /// Drops kept point `w`: the neighbours whose nearest it was get their
    /// spacing anew, and the candidates around it (which it was closest
    /// to) are entered as holes with an upper bound of their value.
    fn remove(&mut self, w: usize, floor: f64) {
        self.kept[w] = false;
        let near: Vec<usize> = self.around(w, 2.0 * CAP * self.r_hi).collect();
        for &j in &near {
            if j == w {
                continue;
            }
            if self.kept[j] {
                let v = distance(&self.points[w], &self.points[j]) / (2.0 * self.r(j));
                if v <= self.spacing[j] {
                    let s = self.own_spacing(j);
                    self.set_spacing(j, s);
                }
            }
        }
        for j in near {
            if !self.kept[j]
                && j != w
                && distance(&self.points[w], &self.points[j]) < 2.0 * CAP * self.r(j)
            {
                let bound = self.own_spacing(j);
                if bound > floor {
                    self.holes.push((ordered(bound), Reverse(j as u32)));
                }
            }
        }
        let bound = self.own_spacing(w);
        if bound > floor {
            self.holes.push((ordered(bound), Reverse(w as u32)));
        }
    }
}

/// Moves kept points (`kept`, indices into `points`) into the largest
/// holes of the pool until no move raises the smallest spacing; returns
/// the kept indices, ascending, as many as were given.
pub(crate) fn relocate(tree: &Tree, points: &[[f32; 3]], radii: &[f32], kept: &[u32]) -> Vec<u32> {
    let m = points.len();
    if kept.len() < 2 || kept.len() >= m {
        return kept.to_vec();
    }
    let mut flags = vec![false; m];
    for &k in kept {
        flags[k as usize] = true;
    }
    let r_hi = radii.iter().copied().fold(0.0f32, f32::max);
    let mut state = State {
        tree,
        points,
        radii,
        r_hi: f64::from(r_hi),
        kept: flags,
        spacing: vec![CAP; m],
        worst: BinaryHeap::new(),
        holes: BinaryHeap::new(),
    };
    // Exact spacings of the kept points, and an upper bound of every
    // unused candidate's hole (its nearest kept point measured with its
    // own radius only, which can only overstate the hole), from a k-d tree
    // of the kept points: in parallel, each a function of the positions
    // alone.
    let kept_xyz: Vec<[f32; 3]> = kept.iter().map(|&k| points[k as usize]).collect();
    let kept_tree = Tree::new_from_slice(&kept_xyz);
    let two = NonZero::new(2).expect("2 is not zero");
    let of = |k: usize| {
        let p = &points[k];
        let nearest = if state.kept[k] {
            kept_tree
                .nearest_n::<SquaredEuclidean>(p, two)
                .into_iter()
                .find(|nb| kept[nb.item as usize] as usize != k)
        } else {
            Some(kept_tree.nearest_one::<SquaredEuclidean>(p))
        };
        nearest.map_or(CAP, |nb| {
            let j = kept[nb.item as usize] as usize;
            (distance(p, &points[j]) / (2.0 * state.r(k))).min(CAP)
        })
    };
    #[cfg(feature = "rayon")]
    let initial: Vec<f64> = {
        use rayon::prelude::*;
        (0..m).into_par_iter().with_min_len(1024).map(of).collect()
    };
    #[cfg(not(feature = "rayon"))]
    let initial: Vec<f64> = (0..m).map(of).collect();
    drop(kept_tree);
    let floor = kept
        .iter()
        .map(|&k| initial[k as usize])
        .fold(CAP, f64::min);
    for (k, &v) in initial.iter().enumerate() {
        if state.kept[k] {
            state.set_spacing(k, v);
        } else if v > floor {
            state.holes.push((ordered(v), Reverse(k as u32)));
        }
    }
    for _ in 0..kept.len() {
        let Some((s_w, w)) = state.peek_worst() else {
            break;
        };
        if s_w >= CAP {
            break;
        }
        // Move the worst point, or else its nearest neighbour (moving
        // either one widens the closest pair).
        let w = w as usize;
        let partner = state.nearest_kept(w);
        let moved = std::iter::once(w)
            .chain(partner)
            .any(|x| state.try_move(x, s_w));
        if !moved {
            break;
        }
    }
    (0..m as u32).filter(|&k| state.kept[k as usize]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_crowded_point_moves_into_the_hole() {
        // Kept: 0, 1 (close together) and 2; candidate 3 is a hole far
        // from all of them, candidate 4 one next to point 2.
        let points = [
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.8, 0.0],
            [1.05, 0.0, 0.0],
        ];
        let radii = [0.5f32; 5];
        let tree = Tree::new_from_slice(&points);
        let kept = relocate(&tree, &points, &radii, &[0, 1, 2]);
        assert_eq!(kept.len(), 3);
        assert!(
            kept.contains(&3) && kept.contains(&2) && !kept.contains(&4),
            "{kept:?}"
        );
        // Nothing to gain: a single pair, no hole.
        assert_eq!(relocate(&tree, &points, &radii, &[0, 2]), vec![0, 2]);
        assert_eq!(
            relocate(&tree, &points[..2], &radii[..2], &[0, 1]),
            vec![0, 1]
        );
    }
}
