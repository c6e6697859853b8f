//! Warping (Labelle & Shewchuk 2007): a lattice vertex is
//! *violated* by a cut point on one of its edges that lies closer to it
//! than `α` times the edge's length (`α_long` on long edges, `α_short` on
//! short ones). A violated vertex moves onto its closest violating cut
//! point and becomes a surface vertex (`f = 0`); the cut points on all of
//! its edges are discarded, since those edges now end on the surface.
//!
//! The vertices are processed in increasing id order, one after another, so
//! that the result never depends on the number of threads (the paper allows
//! any order: the guarantee holds for each).

use glam::DVec3;

use super::cuts::{Cut, Sign, find};
use super::lattice::{Lattice, edge_key};

/// Warps the violated vertices; returns the new positions of the warped
/// ones, sorted by vertex id.
pub(crate) fn warp(
    lattice: &Lattice,
    signs: &mut [Sign],
    cuts: &mut [Cut],
    alpha_long: f64,
    alpha_short: f64,
) -> Vec<(u32, DVec3)> {
    let h = lattice.h;
    let long_len = h;
    let short_len = h * 3f64.sqrt() / 2.0;
    // (vertex, distance, cut index) for every violation.
    let mut violations: Vec<(u32, f64, usize)> = Vec::new();
    for (i, c) in cuts.iter().enumerate() {
        let (alpha, len) = if c.long {
            (alpha_long, long_len)
        } else {
            (alpha_short, short_len)
        };
        let da = c.pos.distance(lattice.position(c.a));
        let db = c.pos.distance(lattice.position(c.b));
        if da < alpha * len {
            violations.push((c.a, da, i));
        }
        if db < alpha * len {
            violations.push((c.b, db, i));
        }
    }
    violations.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut warped = Vec::new();
    let mut nbrs = Vec::with_capacity(14);
    let mut k = 0;
    while k < violations.len() {
        let v = violations[k].0;
        let mut end = k;
        while end < violations.len() && violations[end].0 == v {
            end += 1;
        }
        // The closest cut point that is still there.
        if let Some(&(_, _, ci)) = violations[k..end].iter().find(|x| cuts[x.2].alive) {
            warped.push((v, cuts[ci].pos));
            signs[v as usize] = Sign::Zero;
            lattice.neighbors(v, &mut nbrs);
            for &(n, _) in &nbrs {
                if let Some(j) = find(cuts, edge_key(v, n)) {
                    cuts[j].alive = false;
                }
            }
        }
        k = end;
    }
    warped
}
