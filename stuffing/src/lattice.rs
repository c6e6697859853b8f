//! The body-centred cubic (BCC) lattice of Labelle & Shewchuk 2007:
//! the corners of a cubic grid of spacing `h` ("black" vertices) plus the
//! cube centres ("red" vertices). Its edges are the grid's axis-parallel
//! edges and the centre-to-centre edges (both of length `h`, the *long*
//! edges), and the centre-to-corner edges (length `√3 h / 2`, the *short*
//! edges). Every BCC tetrahedron has two long edges, opposite each other:
//! the edge between two face-adjacent cube centres and one edge of their
//! shared face.
//!
//! Vertices are addressed by *doubled* integer coordinates `(x, y, z)`, in
//! units of `h / 2`: black vertices have even coordinates, red ones odd.
//! The ids are dense: black vertices first, then red ones, both in x-fastest
//! order, so the same lattice always numbers its vertices the same way.

use glam::DVec3;

/// Directions to the 6 long-edge neighbours, in doubled coordinates.
pub(crate) const LONG_DIRS: [[i64; 3]; 6] = [
    [2, 0, 0],
    [-2, 0, 0],
    [0, 2, 0],
    [0, -2, 0],
    [0, 0, 2],
    [0, 0, -2],
];

/// Directions to the 8 short-edge neighbours, in doubled coordinates.
pub(crate) const SHORT_DIRS: [[i64; 3]; 8] = [
    [-1, -1, -1],
    [1, -1, -1],
    [-1, 1, -1],
    [1, 1, -1],
    [-1, -1, 1],
    [1, -1, 1],
    [-1, 1, 1],
    [1, 1, 1],
];

/// A finite BCC lattice: `n` cubes along each axis from `origin`.
#[derive(Debug, Clone)]
pub(crate) struct Lattice {
    pub(crate) origin: DVec3,
    pub(crate) h: f64,
    /// Cubes per axis.
    pub(crate) n: [usize; 3],
}

impl Lattice {
    /// Number of black (corner) vertices.
    pub(crate) fn black_count(&self) -> usize {
        (self.n[0] + 1) * (self.n[1] + 1) * (self.n[2] + 1)
    }

    /// Number of red (centre) vertices.
    pub(crate) fn red_count(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }

    /// Number of vertices.
    pub(crate) fn vertex_count(&self) -> usize {
        self.black_count() + self.red_count()
    }

    /// Vertices a lattice of `n` cubes per axis has, without overflow.
    pub(crate) fn vertex_count_for(n: [u128; 3]) -> u128 {
        (n[0] + 1) * (n[1] + 1) * (n[2] + 1) + n[0] * n[1] * n[2]
    }

    /// Doubled coordinates of a vertex.
    pub(crate) fn coords(&self, id: u32) -> [i64; 3] {
        let id = id as usize;
        let nb = self.black_count();
        if id < nb {
            let (sx, sy) = (self.n[0] + 1, self.n[1] + 1);
            let i = id % sx;
            let j = (id / sx) % sy;
            let k = id / (sx * sy);
            [2 * i as i64, 2 * j as i64, 2 * k as i64]
        } else {
            let r = id - nb;
            let (sx, sy) = (self.n[0], self.n[1]);
            let i = r % sx;
            let j = (r / sx) % sy;
            let k = r / (sx * sy);
            [2 * i as i64 + 1, 2 * j as i64 + 1, 2 * k as i64 + 1]
        }
    }

    /// The vertex at doubled coordinates `c`, if it is in the lattice.
    pub(crate) fn id(&self, c: [i64; 3]) -> Option<u32> {
        let odd = c[0] & 1;
        if c[1] & 1 != odd || c[2] & 1 != odd || c.iter().any(|&v| v < 0) {
            return None;
        }
        let half = [c[0] / 2, c[1] / 2, c[2] / 2];
        if odd == 0 {
            let s = [self.n[0] + 1, self.n[1] + 1, self.n[2] + 1];
            if (0..3).any(|a| half[a] as usize >= s[a]) {
                return None;
            }
            let id = half[0] as usize + s[0] * (half[1] as usize + s[1] * half[2] as usize);
            Some(id as u32)
        } else {
            if (0..3).any(|a| half[a] as usize >= self.n[a]) {
                return None;
            }
            let id = self.black_count()
                + half[0] as usize
                + self.n[0] * (half[1] as usize + self.n[1] * half[2] as usize);
            Some(id as u32)
        }
    }

    /// Unwarped position of a vertex.
    pub(crate) fn position(&self, id: u32) -> DVec3 {
        let c = self.coords(id);
        self.origin + DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * (0.5 * self.h)
    }

    /// Whether the vertex lies on the lattice's outer layer (black vertices
    /// on the box, red vertices of the boundary cubes): it is outside by
    /// construction, since the box pads the surface's bounds by `2h`.
    pub(crate) fn on_outer_layer(&self, id: u32) -> bool {
        let c = self.coords(id);
        (0..3).any(|a| c[a] <= 1 || c[a] >= 2 * self.n[a] as i64 - 1)
    }

    /// The 14 lattice neighbours of a vertex (those that exist), with
    /// `true` for long edges.
    pub(crate) fn neighbors(&self, id: u32, out: &mut Vec<(u32, bool)>) {
        out.clear();
        let c = self.coords(id);
        for d in LONG_DIRS {
            if let Some(n) = self.id([c[0] + d[0], c[1] + d[1], c[2] + d[2]]) {
                out.push((n, true));
            }
        }
        for d in SHORT_DIRS {
            if let Some(n) = self.id([c[0] + d[0], c[1] + d[1], c[2] + d[2]]) {
                out.push((n, false));
            }
        }
    }

    /// The 12 BCC tetrahedra "owned" by red vertex `red` (index among the
    /// red vertices): for each axis, the 4 tetrahedra spanned by this cube
    /// centre, the next centre along the axis, and one edge of their shared
    /// face. Vertex order `[r1, r2, b1, b2]`: the long edges are (0, 1) and
    /// (2, 3). Tetrahedra whose second centre is outside the lattice are
    /// skipped.
    pub(crate) fn red_tets(&self, red: usize, out: &mut Vec<[u32; 4]>) {
        out.clear();
        let r1 = (self.black_count() + red) as u32;
        let c = self.coords(r1);
        for axis in 0..3 {
            let mut c2 = c;
            c2[axis] += 2;
            let Some(r2) = self.id(c2) else { continue };
            let (b, d) = ((axis + 1) % 3, (axis + 2) % 3);
            // The shared face's corners, in cyclic order.
            let corner = |sb: i64, sd: i64| {
                let mut p = c;
                p[axis] += 1;
                p[b] += sb;
                p[d] += sd;
                self.id(p)
                    .expect("a face between two cubes has its corners")
            };
            let ring = [corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)];
            for m in 0..4 {
                out.push([r1, r2, ring[m], ring[(m + 1) % 4]]);
            }
        }
    }
}

/// Canonical key of the edge between two vertices.
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    (u64::from(lo) << 32) | u64::from(hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice() -> Lattice {
        Lattice {
            origin: DVec3::new(-1.0, 2.0, 0.5),
            h: 0.5,
            n: [4, 3, 5],
        }
    }

    #[test]
    fn ids_and_coordinates_round_trip() {
        let l = lattice();
        for id in 0..l.vertex_count() as u32 {
            assert_eq!(l.id(l.coords(id)), Some(id));
        }
        assert_eq!(l.id([1, 2, 1]), None);
        assert_eq!(l.id([-2, 0, 0]), None);
    }

    #[test]
    fn bcc_tets_have_the_lattice_shape_and_fill_the_inner_box() {
        let l = lattice();
        let mut tets = Vec::new();
        let mut volume = 0.0;
        for red in 0..l.red_count() {
            l.red_tets(red, &mut tets);
            for t in &tets {
                let p = t.map(|v| l.position(v));
                assert!((p[0].distance(p[1]) - l.h).abs() < 1e-12);
                assert!((p[2].distance(p[3]) - l.h).abs() < 1e-12);
                for (i, j) in [(0, 2), (0, 3), (1, 2), (1, 3)] {
                    assert!((p[i].distance(p[j]) - l.h * 3f64.sqrt() / 2.0).abs() < 1e-12);
                }
                let v = (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
                assert!((v.abs() - l.h.powi(3) / 12.0).abs() < 1e-12);
                volume += v.abs();
                // The order the stencils rely on: cube centres (odd doubled
                // coordinates) first, then cube corners.
                assert!(t[..2].iter().all(|&v| l.coords(v)[0] & 1 == 1));
                assert!(t[2..].iter().all(|&v| l.coords(v)[0] & 1 == 0));
            }
        }
        // Each pair of face-adjacent cubes owns a bipyramid of volume h³/3.
        let [x, y, z] = l.n;
        let pairs = (x - 1) * y * z + x * (y - 1) * z + x * y * (z - 1);
        assert!((volume - pairs as f64 * l.h.powi(3) / 3.0).abs() < 1e-9);
    }
}
