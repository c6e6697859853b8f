//! Inside/outside at the lattice vertices and the cut points on lattice
//! edges (Labelle & Shewchuk 2007, the algorithm's first two steps).
//!
//! The implicit function is `f = w - 1/2`, with `w` the generalized winding
//! number: a vertex is inside where `f > 0`. A *cut point* is placed on
//! every lattice edge whose ends are strictly inside and strictly outside,
//! at a zero of `f` on the edge. `f` jumps by ±1 where the edge crosses a
//! triangle and is smooth elsewhere, so the zero is first looked for at the
//! crossings (two evaluations decide whether `f` changes sign there: then
//! the cut point lies exactly on the input surface), and otherwise found by
//! bisection on the smooth part (across a hole, where the 1/2 level set
//! spans the opening).

use glam::DVec3;
use rayon::prelude::*;

use super::lattice::{Lattice, edge_key};
use super::winding::WindingNumber;

/// Lattice vertices per parallel work item: fixed, so that the output does
/// not depend on the number of threads.
const CHUNK: usize = 4096;

/// Where a vertex is relative to the surface (after warping, a vertex moved
/// onto the surface is `Zero`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Sign {
    /// `f < 0`.
    Out,
    /// `f = 0`: on the surface (exactly, or warped onto it).
    Zero,
    /// `f > 0`.
    In,
}

/// A cut point on the lattice edge `(a, b)`, `a < b`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cut {
    pub(crate) key: u64,
    pub(crate) a: u32,
    pub(crate) b: u32,
    pub(crate) long: bool,
    pub(crate) pos: DVec3,
    /// False once an end of the edge was warped onto the surface.
    pub(crate) alive: bool,
}

/// Classifies every lattice vertex with `inside(position)`; vertices on
/// the outer layer are outside without evaluation.
pub(crate) fn classify(
    lattice: &Lattice,
    wn: &WindingNumber,
    active: impl Fn(u32) -> bool + Sync,
) -> Vec<Sign> {
    let n = lattice.vertex_count();
    let mut signs = vec![Sign::Out; n];
    signs
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(chunk, out)| {
            for (k, s) in out.iter_mut().enumerate() {
                let id = (chunk * CHUNK + k) as u32;
                if lattice.on_outer_layer(id) || !active(id) {
                    continue;
                }
                let f = wn.fast(lattice.position(id)) - 0.5;
                *s = if f > 0.0 {
                    Sign::In
                } else if f < 0.0 {
                    Sign::Out
                } else {
                    Sign::Zero
                };
            }
        });
    signs
}

/// Cut points on every edge with one end inside and one outside, sorted by
/// edge key.
pub(crate) fn cut_points(lattice: &Lattice, wn: &WindingNumber, signs: &[Sign]) -> Vec<Cut> {
    let n = lattice.vertex_count();
    let chunks: Vec<Vec<Cut>> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|chunk| {
            let mut cuts = Vec::new();
            let mut nbrs = Vec::with_capacity(14);
            let mut hits = Vec::new();
            for id in chunk * CHUNK..((chunk + 1) * CHUNK).min(n) {
                let a = id as u32;
                if signs[id] == Sign::Zero {
                    continue;
                }
                lattice.neighbors(a, &mut nbrs);
                for &(b, long) in &nbrs {
                    // Each edge once, from its lower end.
                    if b < a || signs[b as usize] == Sign::Zero || signs[b as usize] == signs[id] {
                        continue;
                    }
                    let pa = lattice.position(a);
                    let pb = lattice.position(b);
                    let pos = zero_on_edge(wn, pa, pb, signs[id] == Sign::In, &mut hits);
                    cuts.push(Cut {
                        key: edge_key(a, b),
                        a,
                        b,
                        long,
                        pos,
                        alive: true,
                    });
                }
            }
            cuts
        })
        .collect();
    let mut cuts: Vec<Cut> = chunks.into_iter().flatten().collect();
    cuts.sort_unstable_by_key(|c| c.key);
    cuts
}

/// A zero of `w - 1/2` on the segment `pa -> pb`, where `pa` is inside iff
/// `a_inside` and `pb` is on the other side.
fn zero_on_edge(
    wn: &WindingNumber,
    pa: DVec3,
    pb: DVec3,
    a_inside: bool,
    hits: &mut Vec<(f64, i8)>,
) -> DVec3 {
    let at = |t: f64| pa + (pb - pa) * t;
    let inside = |t: f64| wn.fast(at(t)) > 0.5;
    wn.segment_hits(pa, pb, hits);
    // Try the surface crossings first: most cut points lie on a triangle.
    const PROBE: f64 = 1e-9;
    for &(t, _) in hits.iter().take(8) {
        let before = inside((t - PROBE).max(0.0));
        let after = inside((t + PROBE).min(1.0));
        if before != after {
            return at(t);
        }
    }
    // Bisection on the smooth part (holes): keep `lo` on a's side.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if inside(mid) == a_inside {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    at(0.5 * (lo + hi))
}

/// Index of the cut on edge `key`, if any.
pub(crate) fn find(cuts: &[Cut], key: u64) -> Option<usize> {
    cuts.binary_search_by_key(&key, |c| c.key).ok()
}
