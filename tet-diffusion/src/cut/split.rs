//! Exact cuts: the tetrahedra a level set `s(x) = 0` crosses are split
//! along it, so that the cut surface is made of faces whose vertices lie on
//! `s = 0` (for a plane, flat to rounding).
//!
//! The guarantee on the shape of the new tets follows isosurface stuffing
//! (Labelle & Shewchuk 2007): a vertex within [`SNAP`] of an edge's length
//! of the surface is first *snapped* onto it (moved to the edge's crossing
//! point), when that keeps its tets valid, so that every remaining crossing
//! point lies at least `SNAP` from both ends of its edge; each crossed tet
//! is then cut by a fixed stencil — a tet, a pyramid (2 tets) or a prism
//! (3 tets) per side — whose quadrilaterals are split by the diagonal from
//! their smallest vertex index, the rule of Dompierre et al. (1999) that
//! makes the tets on both sides of every face agree and always splits a
//! prism. A snap is accepted only when no tet around the vertex gets a
//! dihedral angle below `min(SNAP_MIN_DIHEDRAL_DEGREES, its own)`.
//!
//! The smallest dihedral angle of the tets a cut creates depends on the
//! parent tets; [`MIN_CREATED_DIHEDRAL_DEGREES`] is the bound measured on
//! the data folder's meshes (see the constant).

use std::collections::HashMap;

use glam::DVec3;
use rayon::prelude::*;

use crate::TetMesh;
use crate::mesh::{dihedral_angles, volume6};

/// A vertex closer to the surface than this fraction of a crossing edge's
/// length (measured along the edge) is snapped onto the surface.
pub const SNAP: f64 = 0.2;

/// A snap may not make a tet's smallest dihedral angle drop below this (or
/// below its value before the snap, if that is smaller), degrees.
pub const SNAP_MIN_DIHEDRAL_DEGREES: f64 = 5.0;

/// The documented bound: no tet an exact cut creates has a dihedral angle
/// below this, degrees — the crate's threshold of a poorly shaped tet
/// (TransCut Sec. 6), which the relaxation cut keeps too. Measured, not
/// proved: on plane cuts of `bunny_500k` (smallest angle of its own
/// 1.63°) the smallest created angle was 0.97°–1.68° (the tests check
/// three planes; the `cuts` example surveys random ones). It is not a
/// guarantee on meshes with slivers: on `bunny_50k` (smallest angle of its
/// own 0.41°) a random plane cut created a 0.28° tet, so below the parent
/// mesh's own smallest angle the created angle can fall further.
pub const MIN_CREATED_DIHEDRAL_DEGREES: f64 = 0.5;

/// Which sides of the surface to keep.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Keep {
    /// `s ≤ 0` only (a cut).
    Negative,
    /// Both, each tet on one side (a fracture).
    Both,
}

/// A mesh split along a level set.
#[derive(Debug, Clone)]
pub(crate) struct Split {
    /// The old vertices (snapped ones moved), then one per crossing edge.
    pub(crate) positions: Vec<DVec3>,
    /// For each new vertex `positions.len() − new.len() + k`: the edge
    /// `(a, b)` it lies on and its fraction `t` from `a`.
    pub(crate) new: Vec<(u32, u32, f64)>,
    /// Tets, positively oriented, of the kept side(s).
    pub(crate) tets: Vec<[u32; 4]>,
    /// Per output tet: the tet of the input mesh it lies in.
    pub(crate) parent: Vec<u32>,
    /// Per output tet: whether it is a piece of a split tet (else it is the
    /// input tet itself, possibly with snapped corners).
    pub(crate) piece: Vec<bool>,
    /// Per output tet: the side, −1 (`s ≤ 0`) or +1.
    pub(crate) side: Vec<i8>,
    /// Per vertex of `positions`: whether it was snapped onto the surface.
    pub(crate) moved: Vec<bool>,
    /// Vertices snapped onto the surface.
    pub(crate) snapped: usize,
    /// Input tets split.
    pub(crate) split_tets: usize,
}

/// The smallest dihedral angle of a tet, degrees.
pub(crate) fn min_dihedral_deg(c: &[DVec3; 4]) -> f64 {
    dihedral_angles(c)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
        .to_degrees()
}

/// The point where `level` crosses zero on the edge `a → b` (given
/// `sa = s(a) < 0 < sb = s(b)` or the reverse), and its fraction from `a`:
/// the linear guess refined by the Illinois method (for a plane the guess
/// is already exact to rounding).
fn crossing(
    level: &(dyn Fn(DVec3) -> f64 + Sync),
    a: DVec3,
    b: DVec3,
    sa: f64,
    sb: f64,
) -> (DVec3, f64) {
    let (mut t0, mut f0, mut t1, mut f1) = (0.0, sa, 1.0, sb);
    let mut t = f0 / (f0 - f1);
    let scale = sa.abs().max(sb.abs());
    for _ in 0..40 {
        let f = level(a + (b - a) * t);
        if f.abs() <= 1e-14 * scale {
            break;
        }
        if (f < 0.0) == (f0 < 0.0) {
            (t0, f0) = (t, f);
            f1 *= 0.5;
        } else {
            (t1, f1) = (t, f);
            f0 *= 0.5;
        }
        t = t0 + (t1 - t0) * f0 / (f0 - f1);
        if !(t > 0.0 && t < 1.0) {
            t = 0.5 * (t0 + t1);
        }
    }
    (a + (b - a) * t, t)
}

/// Snaps the vertices near the surface onto it (in ascending order, each
/// checked against its neighbours' current positions, so the result does
/// not depend on the number of threads). Updates `positions` and `s`;
/// returns which moved.
fn snap(
    mesh: &TetMesh,
    level: &(dyn Fn(DVec3) -> f64 + Sync),
    positions: &mut [DVec3],
    s: &mut [f64],
) -> Vec<bool> {
    let n = positions.len();
    // Candidates: a crossing edge within SNAP of the vertex.
    let near = |v: usize, positions: &[DVec3], s: &[f64]| -> Option<(DVec3, f64)> {
        if s[v] == 0.0 {
            return None;
        }
        let on_boundary = mesh.boundary_index(v).is_some();
        let mut best: Option<(DVec3, f64)> = None;
        for &u in mesh.one_ring(v) {
            let u = u as usize;
            if s[u] == 0.0 || (s[u] < 0.0) == (s[v] < 0.0) {
                continue;
            }
            // A vertex of the object's surface slides along the surface.
            if on_boundary && mesh.boundary_index(u).is_none() {
                continue;
            }
            let t = s[v] / (s[v] - s[u]);
            if t < SNAP && best.is_none_or(|b| t < b.1) {
                best = Some((crossing(level, positions[v], positions[u], s[v], s[u]).0, t));
            }
        }
        best
    };
    let candidates: Vec<usize> = (0..n)
        .into_par_iter()
        .with_min_len(4096)
        .filter(|&v| near(v, positions, s).is_some())
        .collect();
    let mut moved = vec![false; n];
    for v in candidates {
        let Some((target, _)) = near(v, positions, s) else {
            continue;
        };
        let ok = mesh.vertex_tets(v).iter().all(|&t| {
            let tet = mesh.tets()[t as usize];
            let before = tet.map(|u| positions[u as usize]);
            let after = tet.map(|u| {
                if u as usize == v {
                    target
                } else {
                    positions[u as usize]
                }
            });
            volume6(&after) > 0.0
                && min_dihedral_deg(&after)
                    >= SNAP_MIN_DIHEDRAL_DEGREES.min(min_dihedral_deg(&before))
        });
        if ok {
            positions[v] = target;
            s[v] = 0.0;
            moved[v] = true;
        }
    }
    moved
}

/// Splits `mesh` along `level = 0`, keeping the side(s) `keep` says.
pub(crate) fn split(mesh: &TetMesh, level: &(dyn Fn(DVec3) -> f64 + Sync), keep: Keep) -> Split {
    let mut positions = mesh.positions().to_vec();
    // A vertex within rounding of the surface (1e-12 of the mesh's size)
    // is on it: a vertex an earlier cut put there stays there, and its
    // edges are not cut again a rounding error away from it.
    let (lo, hi) = positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    let on = 1e-12 * (hi - lo).length();
    let mut s: Vec<f64> = positions
        .par_iter()
        .map(|&x| {
            let s = level(x);
            if s.abs() <= on { 0.0 } else { s }
        })
        .collect();
    let mut moved = snap(mesh, level, &mut positions, &mut s);
    let snapped = moved.iter().filter(|&&m| m).count();
    let sign = |v: u32| -> i8 {
        let x = s[v as usize];
        if x < 0.0 {
            -1
        } else if x > 0.0 {
            1
        } else {
            0
        }
    };
    let crossed =
        |tet: &[u32; 4]| tet.iter().any(|&v| sign(v) < 0) && tet.iter().any(|&v| sign(v) > 0);
    // One new vertex per crossing edge, numbered in edge order.
    let mut edges: Vec<(u32, u32)> = mesh
        .tets()
        .par_iter()
        .filter(|t| crossed(t))
        .flat_map_iter(|t| {
            let t = *t;
            crate::mesh::EDGES.into_iter().filter_map(move |[i, j]| {
                let (a, b) = (t[i].min(t[j]), t[i].max(t[j]));
                (sign(a) * sign(b) < 0).then_some((a, b))
            })
        })
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let first = positions.len() as u32;
    let points: Vec<(DVec3, f64)> = edges
        .par_iter()
        .map(|&(a, b)| {
            let (a, b) = (a as usize, b as usize);
            crossing(level, positions[a], positions[b], s[a], s[b])
        })
        .collect();
    let index: HashMap<(u32, u32), u32> = edges
        .iter()
        .enumerate()
        .map(|(k, &e)| (e, first + k as u32))
        .collect();
    let new = edges
        .iter()
        .zip(&points)
        .map(|(&(a, b), &(_, t))| (a, b, t))
        .collect();
    positions.extend(points.iter().map(|p| p.0));
    moved.resize(positions.len(), false);
    let cut_point = |a: u32, b: u32| index[&(a.min(b), a.max(b))];

    let mut out = Split {
        positions,
        new,
        tets: Vec::new(),
        parent: Vec::new(),
        piece: Vec::new(),
        side: Vec::new(),
        moved,
        snapped,
        split_tets: 0,
    };
    let sides: &[i8] = match keep {
        Keep::Negative => &[-1],
        Keep::Both => &[-1, 1],
    };
    for (t, tet) in mesh.tets().iter().enumerate() {
        if !crossed(tet) {
            let side = if tet.iter().any(|&v| sign(v) > 0) {
                1
            } else {
                -1
            };
            if sides.contains(&side) {
                out.push(*tet, t, false, side);
            }
            continue;
        }
        out.split_tets += 1;
        for &side in sides {
            for child in stencil(tet, side, &sign, &cut_point) {
                out.push(child, t, true, side);
            }
        }
    }
    out
}

impl Split {
    /// Appends a tet, positively oriented.
    fn push(&mut self, mut tet: [u32; 4], parent: usize, piece: bool, side: i8) {
        if volume6(&tet.map(|v| self.positions[v as usize])) < 0.0 {
            tet.swap(2, 3);
        }
        self.tets.push(tet);
        self.parent.push(parent as u32);
        self.piece.push(piece);
        self.side.push(side);
    }
}

/// The tets of the part of `tet` on `side` (−1: `s ≤ 0`, +1: `s ≥ 0`) of a
/// crossing: vertices by global index, cut points by `cut(a, b)`.
fn stencil(
    tet: &[u32; 4],
    side: i8,
    sign: &dyn Fn(u32) -> i8,
    cut: &dyn Fn(u32, u32) -> u32,
) -> Vec<[u32; 4]> {
    let mine: Vec<u32> = tet.iter().copied().filter(|&v| sign(v) == side).collect();
    let zero: Vec<u32> = tet.iter().copied().filter(|&v| sign(v) == 0).collect();
    let other: Vec<u32> = tet.iter().copied().filter(|&v| sign(v) == -side).collect();
    match (mine.len(), zero.len(), other.len()) {
        // A corner: the vertex, the zero vertices and the cut points.
        (1, _, _) => {
            let a = mine[0];
            let mut t = vec![a];
            t.extend(&zero);
            t.extend(other.iter().map(|&o| cut(a, o)));
            vec![[t[0], t[1], t[2], t[3]]]
        }
        // A pyramid: apex the zero vertex, base in the face of the two
        // vertices and the other one.
        (2, 1, 1) => {
            let (a, b, o) = (mine[0], mine[1], other[0]);
            pyramid(zero[0], [a, b, cut(b, o), cut(a, o)])
        }
        // A prism between the edge (a, b) and the cut points.
        (2, 0, 2) => {
            let (a, b) = (mine[0], mine[1]);
            let (o, p) = (other[0], other[1]);
            prism([a, cut(a, o), cut(a, p)], [b, cut(b, o), cut(b, p)])
        }
        // A prism between the face (a, b, c) and the cut points.
        (3, 0, 1) => {
            let o = other[0];
            prism(
                [mine[0], mine[1], mine[2]],
                [cut(mine[0], o), cut(mine[1], o), cut(mine[2], o)],
            )
        }
        _ => unreachable!("a crossed tet has a vertex on each side"),
    }
}

/// Two tets of the pyramid with apex `z` over the quadrilateral `q` (in
/// cyclic order), split by the diagonal from its smallest index.
fn pyramid(z: u32, q: [u32; 4]) -> Vec<[u32; 4]> {
    let m = (0..4).min_by_key(|&k| q[k]).unwrap_or(0);
    let [a, b, c, d] = [q[m], q[(m + 1) % 4], q[(m + 2) % 4], q[(m + 3) % 4]];
    vec![[z, a, b, c], [z, a, c, d]]
}

/// Three tets of the prism with triangles `a` and `b` (`a[i]` joined to
/// `b[i]`), split by Dompierre et al.'s rule: every quadrilateral by the
/// diagonal from its smallest index.
fn prism(a: [u32; 3], b: [u32; 3]) -> Vec<[u32; 4]> {
    // Rotate (and swap the triangles) so that the smallest index is a[0].
    let all = [a[0], a[1], a[2], b[0], b[1], b[2]];
    let m = (0..6).min_by_key(|&k| all[k]).unwrap_or(0);
    let (a, b) = if m < 3 { (a, b) } else { (b, a) };
    let r = m % 3;
    let a = [a[r], a[(r + 1) % 3], a[(r + 2) % 3]];
    let b = [b[r], b[(r + 1) % 3], b[(r + 2) % 3]];
    // The quadrilaterals at a[0] are split from it; the corner tet at a[0]
    // leaves a pyramid over (a1, a2, b2, b1) with apex a[0].
    let mut tets = vec![[a[0], b[0], b[1], b[2]]];
    tets.extend(pyramid(a[0], [a[1], a[2], b[2], b[1]]));
    tets
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every face of the split mesh is shared by two tets or lies on the
    /// boundary: building the mesh validates that (no non-manifold face),
    /// and the volume is that of the half-space clipped tets.
    #[test]
    fn every_stencil_of_one_tet_fills_its_side_exactly() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let mesh = TetMesh::new(&p, &[[0, 1, 2, 3]]).unwrap();
        // Planes giving each sign pattern, some through vertices; no
        // crossing is within SNAP of a vertex, so nothing snaps.
        let planes = [
            (DVec3::new(0.1, 0.1, 0.1), DVec3::ONE), // 1 | 3
            (DVec3::new(0.5, 0.0, 0.0), DVec3::new(1.0, 1.0, -1.0)), // 2 | 2
            (DVec3::new(0.5, 0.0, 0.0), DVec3::new(1.0, -1.0, 0.0)), // 3 | 1
            (DVec3::ZERO, DVec3::new(1.0, -1.0, 0.3)), // 1 | 0 0 | 2
            (DVec3::ZERO, DVec3::new(1.0, 0.0, -1.0)), // 1 | 0 0 | 1
        ];
        for (point, normal) in planes {
            let n = normal.normalize();
            let level = move |x: DVec3| (x - point).dot(n);
            let both = split(&mesh, &level, Keep::Both);
            let volume = |side: i8| -> f64 {
                both.tets
                    .iter()
                    .zip(&both.side)
                    .filter(|(_, s)| **s == side)
                    .map(|(t, _)| volume6(&t.map(|v| both.positions[v as usize])) / 6.0)
                    .sum()
            };
            assert_eq!(both.snapped, 0);
            let (neg, pos) = (volume(-1), volume(1));
            assert!((neg + pos - 1.0 / 6.0).abs() < 1e-14, "{neg} + {pos}");
            let split_mesh = TetMesh::new(&both.positions, &both.tets).unwrap();
            assert_eq!(split_mesh.reoriented(), 0);
            for (t, tet) in both.tets.iter().enumerate() {
                for &v in tet {
                    let s = level(both.positions[v as usize]);
                    assert!(s * f64::from(both.side[t]) >= -1e-15, "{s}");
                }
            }
        }
    }
}
