//! The dense packing's second step: farthest-point relocation on one
//! tile's candidates, a greedy form of Schlömer, Heck & Deussen's
//! farthest-point optimisation ("Farthest-Point Optimized Point Sets with
//! Maximized Minimum Distance", HPG 2011) restricted to the candidates.
//!
//! After elimination, the tile's kept point with the smallest spacing (its
//! nearest-neighbour distance over twice its own packing radius, the
//! quantity whose minimum is ρ), or else its nearest neighbour, is taken
//! out and put back at the unused candidate farthest from every kept
//! point (the centre of the largest hole the tile offers), as long as that
//! hole is worth more than the smallest spacing: the minimum never falls,
//! and the loop stops when neither of the closest pair can move (or after
//! as many moves as points). Frozen points (earlier tiles') count as kept
//! neighbours but never move, so a close pair across the border is
//! widened from this side. Every point stays one of the sampler's
//! candidates, with all of its fields.
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
//! index.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::grid::Local;

/// Spacings at or above this count as perfect (a hexagonal packing).
const CAP: f64 = 1.0;

/// A non-negative finite `f64` as an integer with the same order.
#[inline]
fn ordered(x: f64) -> u64 {
    debug_assert!(x >= 0.0);
    x.to_bits()
}

struct State<'a> {
    local: &'a Local,
    /// The largest radius: a query of `2 · CAP · r_hi` finds every kept
    /// point whose own disk reaches a position.
    r_hi: f64,
    kept: Vec<bool>,
    /// Each kept point's spacing, exact.
    spacing: Vec<f64>,
    /// Min-heap of `(spacing, index)` over movable kept points; an entry
    /// is valid while the point is kept and its spacing equals the entry's.
    worst: BinaryHeap<Reverse<(u64, u32)>>,
    /// Max-heap of `(bound, index)` over unused candidates: every entry
    /// bounds its hole's value from above, so the first entry whose exact
    /// value equals its bound is the largest hole among those entered.
    holes: BinaryHeap<(u64, Reverse<u32>)>,
    /// A reused buffer for query results.
    near: Vec<usize>,
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
        f64::from(self.local.r[k])
    }

    fn d(&self, a: usize, b: usize) -> f64 {
        distance(&self.local.xyz[a], &self.local.xyz[b])
    }

    /// Candidates within `reach` of point `k` (including `k`), into
    /// `self.near` (taken out; give it back with `self.near = …`).
    fn around(&mut self, k: usize, reach: f64) -> Vec<usize> {
        let mut near = std::mem::take(&mut self.near);
        near.clear();
        // A hair wider in f32, so no point within the f64 reach is lost.
        let reach = (reach * (1.0 + 1e-6)) as f32;
        self.local
            .within(&self.local.xyz[k], reach, |j, _| near.push(j));
        near
    }

    /// The spacing of point `k` against the kept points other than itself,
    /// measured with its own radius.
    fn own_spacing(&self, k: usize) -> f64 {
        let two_r = 2.0 * self.r(k);
        let mut s = CAP;
        let reach = (two_r * CAP * (1.0 + 1e-6)) as f32;
        self.local.within(&self.local.xyz[k], reach, |j, _| {
            if j != k && self.kept[j] {
                s = s.min(self.d(k, j) / two_r);
            }
        });
        s
    }

    /// The value of a hole at candidate `c` (not kept): the least spacing
    /// a point there would leave.
    fn hole(&self, c: usize) -> f64 {
        let rc = self.r(c);
        let reach = (2.0 * CAP * rc.max(self.r_hi) * (1.0 + 1e-6)) as f32;
        let mut s = CAP;
        self.local.within(&self.local.xyz[c], reach, |j, _| {
            if j != c && self.kept[j] {
                s = s.min(self.d(c, j) / (2.0 * rc.max(self.r(j))));
            }
        });
        s
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

    /// Keeps candidate `h`: its spacing, and its movable neighbours' that
    /// it lowers.
    fn insert(&mut self, h: usize) {
        self.kept[h] = true;
        let s = self.own_spacing(h);
        self.set_spacing(h, s);
        let near = self.around(h, 2.0 * CAP * self.r_hi);
        for &j in &near {
            if j != h && self.kept[j] && self.local.own(j) {
                let v = self.d(h, j) / (2.0 * self.r(j));
                if v < self.spacing[j] {
                    self.set_spacing(j, v);
                }
            }
        }
        self.near = near;
    }

    /// The kept point nearest to point `k`, if one is within its capped
    /// reach.
    fn nearest_kept(&self, k: usize) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        let reach = (2.0 * CAP * self.r(k)) as f32;
        self.local.within(&self.local.xyz[k], reach, |j, _| {
            if j != k && self.kept[j] {
                let d = self.d(k, j);
                let key = (d, self.local.global[j] as usize);
                if best.is_none_or(|b| key < (b.0, self.local.global[b.1] as usize)) {
                    best = Some((d, j));
                }
            }
        });
        best.map(|(_, j)| j)
    }

    /// Moves kept point `x` into the largest hole if that hole is worth
    /// more than `worst`, the smallest spacing; otherwise leaves it.
    fn try_move(&mut self, x: usize, worst: f64) -> bool {
        if !self.local.own(x) {
            return false;
        }
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

    /// Drops kept point `w`: the movable neighbours whose nearest it was
    /// get their spacing anew, and the candidates around it (which it was
    /// closest to) are entered as holes with an upper bound of their value.
    fn remove(&mut self, w: usize, floor: f64) {
        self.kept[w] = false;
        let near = self.around(w, 2.0 * CAP * self.r_hi);
        for &j in &near {
            if j != w && self.kept[j] && self.local.own(j) {
                let v = self.d(w, j) / (2.0 * self.r(j));
                if v <= self.spacing[j] {
                    let s = self.own_spacing(j);
                    self.set_spacing(j, s);
                }
            }
        }
        for &j in &near {
            if !self.kept[j] && self.local.own(j) && j != w && self.d(w, j) < 2.0 * CAP * self.r(j)
            {
                let bound = self.own_spacing(j);
                if bound > floor {
                    self.holes.push((ordered(bound), Reverse(j as u32)));
                }
            }
        }
        self.near = near;
        let bound = self.own_spacing(w);
        if bound > floor {
            self.holes.push((ordered(bound), Reverse(w as u32)));
        }
    }
}

/// Moves the tile's kept points (`kept[j]` for the points of `local`;
/// frozen points and kept ghosts are neighbours that stay) into the largest holes among its
/// unused candidates until no move raises the smallest spacing; returns
/// the new flags, as many kept as were given.
pub(crate) fn relocate(local: &Local, kept: Vec<bool>) -> Vec<bool> {
    let m = local.len();
    let movable = (0..m).filter(|&j| kept[j] && local.own(j)).count();
    let unused = (0..m).filter(|&j| !kept[j] && local.own(j)).count();
    if movable == 0 || unused == 0 {
        return kept;
    }
    let r_hi = local.r.iter().copied().fold(0.0f32, f32::max);
    let mut state = State {
        local,
        r_hi: f64::from(r_hi),
        kept,
        spacing: vec![CAP; m],
        worst: BinaryHeap::new(),
        holes: BinaryHeap::new(),
        near: Vec::new(),
    };
    // Exact spacings of the movable kept points, and an upper bound of
    // every unused candidate's hole (its nearest kept point measured with
    // its own radius only, which can only overstate the hole).
    let initial: Vec<f64> = (0..m)
        .map(|k| {
            if local.own(k) {
                state.own_spacing(k)
            } else {
                CAP
            }
        })
        .collect();
    let floor = (0..m)
        .filter(|&k| state.kept[k] && local.own(k))
        .map(|k| initial[k])
        .fold(CAP, f64::min);
    for (k, &v) in initial.iter().enumerate() {
        if !local.own(k) {
            continue;
        }
        if state.kept[k] {
            state.set_spacing(k, v);
        } else if v > floor {
            state.holes.push((ordered(v), Reverse(k as u32)));
        }
    }
    for _ in 0..movable {
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
    state.kept
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local(points: &[[f32; 3]], frozen: &[usize]) -> Local {
        Local::of_points(points, 0.5, frozen, [-1.0; 3], [2.0, 2.0, 1.0])
    }

    fn kept_of(l: &Local, flags: &[bool]) -> Vec<u32> {
        let mut k: Vec<u32> = (0..l.len())
            .filter(|&j| flags[j])
            .map(|j| l.global[j])
            .collect();
        k.sort_unstable();
        k
    }

    fn flags(l: &Local, kept: &[u32]) -> Vec<bool> {
        (0..l.len()).map(|j| kept.contains(&l.global[j])).collect()
    }

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
        let l = local(&points, &[]);
        let kept = kept_of(&l, &relocate(&l, flags(&l, &[0, 1, 2])));
        assert_eq!(kept.len(), 3);
        assert!(
            kept.contains(&3) && kept.contains(&2) && !kept.contains(&4),
            "{kept:?}"
        );
        // Nothing to gain: a single pair, no hole.
        assert_eq!(kept_of(&l, &relocate(&l, flags(&l, &[0, 2]))), vec![0, 2]);
        let l2 = local(&points[..2], &[]);
        assert_eq!(
            kept_of(&l2, &relocate(&l2, flags(&l2, &[0, 1]))),
            vec![0, 1]
        );
        // Point 0 frozen: its crowded partner 1 moves instead, and 0 stays.
        let l = local(&points, &[0]);
        let kept = kept_of(&l, &relocate(&l, flags(&l, &[0, 1, 2])));
        assert_eq!(kept.len(), 3);
        assert!(
            kept.contains(&0) && kept.contains(&3) && !kept.contains(&1),
            "{kept:?}"
        );
    }
}
