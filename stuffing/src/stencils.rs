//! The stencils that fill one BCC tetrahedron with the part of it inside
//! the surface (Labelle & Shewchuk 2007, the stencil step).
//!
//! After warping, every lattice vertex is inside (`+`), outside (`-`) or on
//! the surface (`0`), and every edge between a `+` and a `-` vertex carries
//! a cut point. By the counts (inside, zero, outside):
//!
//! | case | output |
//! |---|---|
//! | no `+` vertex | nothing |
//! | no `-` vertex | the whole tetrahedron |
//! | (1, 2, 1), (1, 1, 2), (1, 0, 3) | one tetrahedron: the `+` vertex, the `0` vertices, the cut points |
//! | (2, 1, 1) | a pyramid (apex the `0` vertex) over a quadrilateral: 2 tetrahedra |
//! | (2, 0, 2) | a triangular prism: 3 tetrahedra |
//! | (3, 0, 1) | a triangular prism (the tetrahedron minus its `-` corner): 3 tetrahedra |
//!
//! A quadrilateral that lies on a face of the lattice tetrahedron is shared
//! with the neighbouring lattice tetrahedron, so both must split it along
//! the same diagonal. Such a face has two `+` vertices `p`, `q` and a `-`
//! vertex `o`; the diagonal runs from one of `p`, `q` to the cut point on
//! the other's edge to `o`. Every BCC face has exactly one long edge:
//!
//! * if the long edge is `pq`, the lattice alone must decide, by the
//!   paper's **parity rule** (Labelle & Shewchuk 2007; its Sec. 3.3 and
//!   Fig. 3, as implementations cite it): the diagonal from `A ∈ {p, q}` to the
//!   cut point `C` on the other `+` vertex's edge points along
//!   `sign(A - C) = sign(A - o)` (per axis, in lattice coordinates), and
//!   exactly one of the two candidates has an odd number of positive
//!   components. A long edge between two cube corners (black vertices)
//!   takes the odd one, a long edge between two cube centres (red
//!   vertices) the even one. Both tetrahedra that share the face see the
//!   same `p`, `q`, `o`, so they agree. The rule also makes the two
//!   lattice-face quadrilaterals of a `++--` tetrahedron start at
//!   different `+` vertices, as in the paper's stencil for that case. (The
//!   rule is read from the paper's stencil figure as two independent
//!   implementations reproduce it, since the paper's text was not
//!   available here.)
//! * otherwise the long edge is `po` or `qo`, which both neighbours see
//!   too: the diagonal ends at the cut point on the long edge and starts
//!   at the other `+` vertex, as in the paper's stencils. (The opposite
//!   choice, from the `+` end of the long edge, lets the stencils fall to
//!   6.2° in the sampling test below.)
//!
//! A prism is split into 3 tetrahedra by coning from a vertex that two of
//! its quadrilateral diagonals touch; among the valid choices (and both
//! diagonals of the surface quadrilateral of a (2, 0, 2) prism, which no
//! neighbour shares) the one with the best smallest dihedral-angle sine
//! wins. With the rules above, the two lattice-face quadrilaterals of a
//! (3, 0, 1) prism that are not symmetric both end at the long edge's cut
//! point, and those of a (2, 0, 2) prism leave the surface quadrilateral
//! free, so a vertex touching two diagonals always exists.
//!
//! The sampling test draws 400,000 lattice tetrahedra per parameter pair
//! (random signs, cut points anywhere warping allows, warped vertices up to
//! α along any of their 14 edges but never both ends of one edge along it,
//! extremes drawn often) and checks the bounds
//! [`super::Params::dihedral_bounds_deg`] states for *these* stencils.

use glam::DVec3;

use super::cuts::Sign;
use super::quality::min_sine;

/// A vertex of the output: its id in the point numbering of the mesh
/// builder and its position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Point {
    pub(crate) id: u32,
    pub(crate) pos: DVec3,
}

/// One lattice tetrahedron with everything the stencils need. Vertex order
/// `[r1, r2, b1, b2]`: the long edges are (0, 1) and (2, 3).
#[derive(Debug, Clone, Copy)]
pub(crate) struct LatticeTet {
    pub(crate) v: [Point; 4],
    pub(crate) sign: [Sign; 4],
    /// Doubled lattice coordinates of each vertex (before warping): even
    /// for cube corners (black), odd for cube centres (red).
    pub(crate) coords: [[i64; 3]; 4],
    /// The cut point on edge (i, j), for `+`/`-` edges.
    pub(crate) cut: [[Option<Point>; 4]; 4],
}

/// How symmetric lattice-face quadrilaterals are split.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FaceRule {
    /// The paper's parity rule: a property of the face, shared by both
    /// tetrahedra that contain it.
    Parity,

    /// Deliberately wrong, for the tests: the diagonal from whichever end
    /// comes first in this tetrahedron's vertex list, as a stencil table
    /// in local vertex order would do. Neighbours disagree.
    #[cfg(test)]
    TetLocal,
}

fn long(i: usize, j: usize) -> bool {
    matches!((i.min(j), i.max(j)), (0, 1) | (2, 3))
}

/// Which of the inside vertices `p`, `q` of the lattice face `(p, q, o)`
/// carries the diagonal of the face's quadrilateral.
fn diagonal_end(t: &LatticeTet, p: usize, q: usize, o: usize, rule: FaceRule) -> usize {
    if long(p, q) {
        match rule {
            FaceRule::Parity => {
                let black = t.coords[p][0] & 1 == 0;
                if (positive_components(t.coords[p], t.coords[o]) % 2 == 1) == black {
                    p
                } else {
                    q
                }
            }

            #[cfg(test)]
            FaceRule::TetLocal => p.min(q),
        }
    } else {
        // The long edge is po or qo: the diagonal ends at the cut point on
        // the long edge, from the inside vertex of the short cut edge.
        if long(p, o) { q } else { p }
    }
}

/// The number of axes along which `a` lies above `b`.
fn positive_components(a: [i64; 3], b: [i64; 3]) -> u32 {
    (0..3).map(|k| u32::from(a[k] > b[k])).sum()
}

/// Appends the output tetrahedra of `t` (not yet oriented).
pub(crate) fn fill(t: &LatticeTet, rule: FaceRule, out: &mut Vec<[Point; 4]>) {
    let mut ins = [0usize; 4];
    let mut zeros = [0usize; 4];
    let mut outs = [0usize; 4];
    let (mut ni, mut nz, mut no) = (0, 0, 0);
    for k in 0..4 {
        match t.sign[k] {
            Sign::In => {
                ins[ni] = k;
                ni += 1;
            }
            Sign::Zero => {
                zeros[nz] = k;
                nz += 1;
            }
            Sign::Out => {
                outs[no] = k;
                no += 1;
            }
        }
    }
    if ni == 0 {
        return;
    }
    if no == 0 {
        out.push(t.v);
        return;
    }
    let v = |k: usize| t.v[k];
    let c = |i: usize, j: usize| cut(t, i, j);
    match (ni, nz, no) {
        (1, 2, 1) => out.push([v(ins[0]), v(zeros[0]), v(zeros[1]), c(ins[0], outs[0])]),
        (1, 1, 2) => out.push([
            v(ins[0]),
            v(zeros[0]),
            c(ins[0], outs[0]),
            c(ins[0], outs[1]),
        ]),
        (1, 0, 3) => out.push([
            v(ins[0]),
            c(ins[0], outs[0]),
            c(ins[0], outs[1]),
            c(ins[0], outs[2]),
        ]),
        (2, 1, 1) => {
            let (p, q, z, o) = (ins[0], ins[1], zeros[0], outs[0]);
            let (cp, cq) = (c(p, o), c(q, o));
            if diagonal_end(t, p, q, o, rule) == p {
                out.push([v(z), v(p), v(q), cq]);
                out.push([v(z), v(p), cq, cp]);
            } else {
                out.push([v(z), v(p), v(q), cp]);
                out.push([v(z), v(q), cq, cp]);
            }
        }
        (2, 0, 2) => {
            let (p, q, o1, o2) = (ins[0], ins[1], outs[0], outs[1]);
            let a = [v(p), c(p, o1), c(p, o2)];
            let b = [v(q), c(q, o1), c(q, o2)];
            let d01 = diagonal_end(t, p, q, o1, rule) == p;
            let d02 = diagonal_end(t, p, q, o2, rule) == p;
            prism(a, b, [Some(d01), Some(d02), None], out);
        }
        (3, 0, 1) => {
            let o = outs[0];
            let a = [v(ins[0]), v(ins[1]), v(ins[2])];
            let b = [c(ins[0], o), c(ins[1], o), c(ins[2], o)];
            let mut d = [None; 3];
            for (q, (i, j)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
                d[q] = Some(diagonal_end(t, ins[i], ins[j], o, rule) == ins[i]);
            }
            prism(a, b, d, out);
        }
        _ => unreachable!("the counts of a tetrahedron's four vertices sum to 4"),
    }
}

fn cut(t: &LatticeTet, i: usize, j: usize) -> Point {
    // Every edge between a `+` and a `-` vertex of a lattice tetrahedron
    // carries a live cut point: the cut finder visits every such edge, and
    // warping only removes cut points from edges that gained a `0` end.
    t.cut[i][j].unwrap_or(t.v[i])
}

/// Splits the triangular prism with triangles `a` and `b` (`a[k]` joined to
/// `b[k]`) into 3 tetrahedra. `diag[q]` for quadrilateral `q` in order
/// (0,1), (0,2), (1,2): `Some(true)` for the diagonal `a_i b_j`,
/// `Some(false)` for `a_j b_i` (`i < j`), `None` when free.
fn prism(a: [Point; 3], b: [Point; 3], diag: [Option<bool>; 3], out: &mut Vec<[Point; 4]>) {
    let mut best: Option<([[Point; 4]; 3], f64)> = None;
    for free in [true, false] {
        let d = diag.map(|x| x.unwrap_or(free));
        // Every vertex touching two diagonals gives a valid split.
        for apex in 0..6 {
            if let Some(tets) = split_prism(a, b, d, apex) {
                let q = tets
                    .iter()
                    .map(|t| min_sine(t.map(|p| p.pos)))
                    .fold(f64::INFINITY, f64::min);
                if best.as_ref().is_none_or(|(_, bq)| q > *bq) {
                    best = Some((tets, q));
                }
            }
        }
        if diag.iter().all(Option::is_some) {
            break;
        }
    }
    // The fixed diagonals never form a cycle (see the module docs), so
    // `best` is always set; a cycle would leave the cell empty rather
    // than emit an invalid tetrahedron (and fails the tests).
    debug_assert!(best.is_some(), "prism diagonals form a cycle");
    if let Some((tets, _)) = best {
        out.extend_from_slice(&tets);
    }
}

/// The 3 tetrahedra of a prism for fixed diagonals, coned from `apex`
/// (`k < 3`: `a[k]`, else `b[k - 3]`), or `None` when that vertex does not
/// touch two diagonals.
fn split_prism(a: [Point; 3], b: [Point; 3], d: [bool; 3], apex: usize) -> Option<[[Point; 4]; 3]> {
    const QUADS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
    // Diagonal-end counts: index k < 3 is a[k], 3 + k is b[k].
    let mut count = [0u8; 6];
    for (q, &(i, j)) in QUADS.iter().enumerate() {
        if d[q] {
            count[i] += 1;
            count[3 + j] += 1;
        } else {
            count[j] += 1;
            count[3 + i] += 1;
        }
    }
    if count[apex] != 2 {
        return None;
    }
    let (k, top) = (apex % 3, apex < 3);
    let (jj, kk) = match k {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    let q = QUADS.iter().position(|&x| x == (jj, kk)).unwrap_or(2);
    let ap = if top { a[k] } else { b[k] };
    let far = if top { b } else { a };
    // The quadrilateral opposite the apex, split by its own diagonal.
    let (t1, t2) = if d[q] {
        ([a[jj], a[kk], b[kk]], [a[jj], b[kk], b[jj]])
    } else {
        ([a[jj], a[kk], b[jj]], [a[kk], b[kk], b[jj]])
    };
    Some([
        [ap, far[0], far[1], far[2]],
        [ap, t1[0], t1[1], t1[2]],
        [ap, t2[0], t2[1], t2[2]],
    ])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::Params;
    use crate::lattice::{LONG_DIRS, SHORT_DIRS};
    use crate::quality::{dihedral_angles, signed_volume};

    /// A small deterministic generator (SplitMix64) for the sampling test.
    pub(crate) struct Rng(pub(crate) u64);
    impl Rng {
        pub(crate) fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        pub(crate) fn f64(&mut self) -> f64 {
            (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Where the test's decisions come from: random draws, or every
    /// combination of a grid (each continuous value at its two ends and its
    /// middle), enumerated like an odometer.
    enum Chooser {
        Random(Rng),
        Grid {
            digits: Vec<(usize, usize)>,
            at: usize,
        },
    }

    impl Chooser {
        /// One of `n` discrete options.
        fn pick(&mut self, n: usize) -> usize {
            match self {
                Chooser::Random(rng) => (rng.next_u64() % n as u64) as usize,
                Chooser::Grid { digits, at } => {
                    if *at == digits.len() {
                        digits.push((0, n));
                    }
                    *at += 1;
                    digits[*at - 1].0
                }
            }
        }
        /// A value in `[lo, hi]`; the ends are drawn often, as the worst
        /// cases sit there.
        fn range(&mut self, lo: f64, hi: f64) -> f64 {
            match self {
                Chooser::Random(rng) => match rng.next_u64() % 4 {
                    0 => lo,
                    1 => hi,
                    _ => lo + (hi - lo) * rng.f64(),
                },
                Chooser::Grid { .. } => lo + (hi - lo) * self.pick(3) as f64 / 2.0,
            }
        }
        /// Advances the grid to its next combination; false when done.
        fn next_combination(&mut self) -> bool {
            let Chooser::Grid { digits, at } = self else {
                return true;
            };
            *at = 0;
            while let Some((d, n)) = digits.pop() {
                if d + 1 < n {
                    digits.push((d + 1, n));
                    return true;
                }
            }
            false
        }
    }

    /// The reference BCC tetrahedron (h = 1) in doubled coordinates, in
    /// the `[r1, r2, b1, b2]` order.
    const TET: [[i64; 3]; 4] = [[1, 1, 1], [1, 1, 3], [0, 0, 2], [2, 0, 2]];

    /// Worst dihedral angles (degrees) over lattice tetrahedra: every
    /// combination of signs, warp directions and grid values of the warp
    /// distances and cut points, then `samples` random ones. Warped
    /// vertices move up to α along any of their 14 edges; cut points lie
    /// anywhere warping allows.
    pub(crate) fn worst_angles(
        params: Params,
        rule: FaceRule,
        samples: usize,
        seed: u64,
    ) -> (f64, f64) {
        worst_angles_ab(
            params.alpha_long(),
            params.alpha_short(),
            rule,
            samples,
            seed,
        )
    }

    pub(crate) fn worst_angles_ab(
        al: f64,
        as_: f64,
        rule: FaceRule,
        samples: usize,
        seed: u64,
    ) -> (f64, f64) {
        let mut worst = (180.0f64, 0.0f64);
        let mut grid = Chooser::Grid {
            digits: Vec::new(),
            at: 0,
        };
        loop {
            one_config(al, as_, rule, &mut grid, &mut worst);
            if !grid.next_combination() {
                break;
            }
        }
        let mut random = Chooser::Random(Rng(seed));
        for _ in 0..samples {
            one_config(al, as_, rule, &mut random, &mut worst);
        }
        worst
    }

    fn one_config(al: f64, as_: f64, rule: FaceRule, ch: &mut Chooser, worst: &mut (f64, f64)) {
        let pos0 = TET.map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * 0.5);
        let mut sign = [Sign::Out; 4];
        let mut pos = pos0;
        // The tetrahedron vertex each warped vertex moved towards, if any.
        let mut towards = [None; 4];
        for k in 0..4 {
            sign[k] = [Sign::In, Sign::Out, Sign::Zero][ch.pick(3)];
            if sign[k] == Sign::Zero {
                // Warped along one of the 14 lattice edges.
                let e = ch.pick(14);
                let (dir, alpha) = if e < 6 {
                    (LONG_DIRS[e], al)
                } else {
                    (SHORT_DIRS[e - 6], as_)
                };
                towards[k] = (0..4).find(|&j| (0..3).all(|a| TET[j][a] - TET[k][a] == dir[a]));
                let d = DVec3::new(dir[0] as f64, dir[1] as f64, dir[2] as f64) * 0.5;
                pos[k] += d * ch.range(0.0, alpha);
            }
        }
        // An edge has one cut point, and warping one end onto it discards
        // it: the two ends of an edge never both warp along that edge.
        if (0..4).any(|k| towards[k].is_some_and(|j| towards[j] == Some(k))) {
            return;
        }
        let mut v = [Point {
            id: 0,
            pos: DVec3::ZERO,
        }; 4];
        for k in 0..4 {
            v[k] = Point {
                id: k as u32,
                pos: pos[k],
            };
        }
        let mut cut = [[None; 4]; 4];
        let mut next = 4;
        for i in 0..4 {
            for j in i + 1..4 {
                if matches!(
                    (sign[i], sign[j]),
                    (Sign::In, Sign::Out) | (Sign::Out, Sign::In)
                ) {
                    let alpha = if long(i, j) { al } else { as_ };
                    let s = ch.range(alpha, 1.0 - alpha);
                    let p = Point {
                        id: next,
                        pos: pos[i] + (pos[j] - pos[i]) * s,
                    };
                    next += 1;
                    cut[i][j] = Some(p);
                    cut[j][i] = Some(p);
                }
            }
        }
        let t = LatticeTet {
            v,
            sign,
            coords: TET,
            cut,
        };
        let mut out = Vec::new();
        fill(&t, rule, &mut out);
        for tet in &out {
            let p = tet.map(|x| x.pos);
            assert!(signed_volume(p).abs() > 1e-9, "flat output tetrahedron");
            for a in dihedral_angles(p) {
                worst.0 = worst.0.min(a.to_degrees());
                worst.1 = worst.1.max(a.to_degrees());
            }
        }
    }

    #[test]
    fn stencils_keep_the_stated_angle_bounds_for_both_parameter_pairs() {
        let mut ok = true;
        for params in [Params::Angles10_7, Params::Angles8_9] {
            let (lo, hi) = worst_angles(params, FaceRule::Parity, 400_000, 7);
            let (blo, bhi) = params.dihedral_bounds_deg();
            eprintln!(
                "{params:?}: sampled worst angles {lo:.3}°, {hi:.3}° (bounds {blo}°, {bhi}°)"
            );
            ok &= lo >= blo && hi <= bhi;
        }
        assert!(ok);
    }

    #[test]
    #[ignore = "long: 4 million samples per pair, for the bounds in the docs"]
    fn stencil_bounds_with_more_samples() {
        for params in [Params::Angles10_7, Params::Angles8_9] {
            let (lo, hi) = worst_angles(params, FaceRule::Parity, 4_000_000, 11);
            eprintln!("{params:?}: {lo:.3}°, {hi:.3}°");
            let (blo, bhi) = params.dihedral_bounds_deg();
            assert!(lo >= blo && hi <= bhi);
        }
    }

    #[test]
    fn prism_with_cyclic_diagonals_is_refused_and_acyclic_ones_fill_it() {
        let p = |x: f64, y: f64, z: f64, id: u32| Point {
            id,
            pos: DVec3::new(x, y, z),
        };
        let a = [
            p(0.0, 0.0, 0.0, 0),
            p(1.0, 0.0, 0.0, 1),
            p(0.0, 1.0, 0.0, 2),
        ];
        let b = [
            p(0.0, 0.0, 1.0, 3),
            p(1.0, 0.0, 1.0, 4),
            p(0.0, 1.0, 1.0, 5),
        ];
        // a0-b1, a1-b2, a2-b0 ... as (0,1): true, (1,2): true, (0,2): false.
        assert!((0..6).all(|apex| split_prism(a, b, [true, false, true], apex).is_none()));
        let tets = split_prism(a, b, [true, true, true], 0).unwrap();
        let vol: f64 = tets
            .iter()
            .map(|t| signed_volume(t.map(|x| x.pos)).abs())
            .sum();
        assert!((vol - 0.5).abs() < 1e-12);
    }
}
