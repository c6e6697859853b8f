//! TransCut's linear system (Sec. 3.2, Eq. 4–14): the cotangent edge
//! weights `w_ij` of Eq. 10, the row sums `V_i μ`, the boundary term
//! `2 S_i / (3A)` of Eq. 13, and the right-hand side of Eq. 12.
//!
//! The three RGB systems share one sparsity pattern (the mesh's graph);
//! only their values differ. Each row is assembled on its own, from the
//! tets around its vertex in ascending order, so assembly runs in
//! parallel with results that do not depend on the number of threads,
//! `M` is symmetric bit for bit, and re-assembling some rows (painting)
//! gives exactly the values of a full assembly.

#![expect(
    clippy::needless_range_loop,
    reason = "RGB loops index several per-channel arrays by one channel index"
)]

use rayon::prelude::*;
use sprs::CsMat;

use crate::geometry::{edge_index, tet_geometry};
use crate::mesh::TetMesh;

/// Per-tet geometry: volume and the geometric part of Eq. 10.
#[derive(Debug, Clone)]
pub(crate) struct Geometry {
    /// `V_t`, mesh units³.
    pub(crate) volume: Vec<f64>,
    /// For each edge `(i, j)` of [`EDGES`](crate::geometry::EDGES): `−(1/6) |kl| cot θ_kl`, where
    /// `kl` is the opposite edge and `θ_kl` the dihedral angle there.
    pub(crate) weights: Vec<[f64; 6]>,
}

impl Geometry {
    pub(crate) fn new(mesh: &TetMesh) -> Self {
        let (volume, weights) = (0..mesh.tets().len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|t| tet_geometry(&mesh.corners(t)))
            .unzip();
        Self { volume, weights }
    }

    /// `Σ_t −(1/6) |kl| cot θ_kl` over the tets sharing the edge from `i`
    /// to its `k`-th one-ring vertex.
    pub(crate) fn edge_weight(&self, mesh: &TetMesh, i: usize, k: usize) -> f64 {
        let j = mesh.one_ring(i)[k];
        let mut w = 0.0;
        for &t in mesh.vertex_tets(i) {
            let tet = mesh.tets()[t as usize];
            if let Some(b) = tet.iter().position(|&v| v == j) {
                let a = tet.iter().position(|&v| v as usize == i).unwrap_or(0);
                w += self.weights[t as usize][edge_index(a.min(b), a.max(b))];
            }
        }
        w
    }
}

/// Per-tet coefficients in mesh units: `κ_t` (units) and `μa_t`
/// (units⁻¹) per channel.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Coefficients {
    pub(crate) kappa: Vec<[f64; 3]>,
    pub(crate) mu: Vec<[f64; 3]>,
}

/// The pattern of `M`: each row's columns are the vertex and its one-ring,
/// ascending.
pub(crate) fn pattern(mesh: &TetMesh) -> (Vec<usize>, Vec<usize>) {
    let n = mesh.vertex_count();
    let mut indptr = Vec::with_capacity(n + 1);
    let mut indices = Vec::with_capacity(mesh.edge_count() * 2 + n);
    indptr.push(0);
    for i in 0..n {
        let ring = mesh.one_ring(i);
        let split = ring.partition_point(|&j| (j as usize) < i);
        indices.extend(ring[..split].iter().map(|&j| j as usize));
        indices.push(i);
        indices.extend(ring[split..].iter().map(|&j| j as usize));
        indptr.push(indices.len());
    }
    (indptr, indices)
}

/// Index in [`EDGES`](crate::geometry::EDGES) of the local edge between corners `a` and `b`
/// (either order; the diagonal entries are unused).
const EDGE_OF: [[usize; 4]; 4] = [[0, 0, 1, 2], [0, 0, 3, 4], [1, 3, 0, 5], [2, 4, 5, 0]];

/// Row `i` of the three systems into `out` (one `[r, g, b]` per stored
/// entry of the row): Eq. 13–14. The tets around `i` are visited in ascending order
/// and each adds its three edges and its volume term in a fixed order, so
/// a row has the same bits whether assembled alone or with all others.
pub(crate) fn row(
    mesh: &TetMesh,
    geometry: &Geometry,
    coefficients: &Coefficients,
    boundary: f64,
    i: usize,
    out: &mut [[f64; 3]],
) {
    out.fill([0.0; 3]);
    let diag = mesh.one_ring(i).partition_point(|&j| (j as usize) < i);
    let diag_slot = diag as u32;
    for (&t, slots) in mesh.vertex_tets(i).iter().zip(mesh.vertex_slots(i)) {
        let t = t as usize;
        let a = slots.iter().position(|&s| s == diag_slot).unwrap_or(0);
        let kappa = coefficients.kappa[t];
        let g = &geometry.weights[t];
        for (b, &slot) in slots.iter().enumerate() {
            if b == a {
                continue;
            }
            let g = g[EDGE_OF[a][b]];
            let pos = slot as usize;
            for c in 0..3 {
                // M_ij = 4 w_ij (Eq. 14); M_ii = −4 Σ_j w_ij + … (Eq. 13).
                let w = 4.0 * kappa[c] * g;
                out[pos][c] += w;
                out[diag][c] -= w;
            }
        }
        let v = geometry.volume[t];
        for c in 0..3 {
            out[diag][c] += v * coefficients.mu[t][c];
        }
    }
    let s = mesh.vertex_areas()[i];
    if s > 0.0 {
        for c in 0..3 {
            out[diag][c] += boundary * s;
        }
    }
}

/// Rows per parallel task.
const ROWS: usize = 512;

/// The three matrices of Eq. 13–14. `a` is the boundary factor `A`.
pub(crate) fn assemble(
    mesh: &TetMesh,
    geometry: &Geometry,
    coefficients: &Coefficients,
    a: f64,
) -> [CsMat<f64>; 3] {
    let n = mesh.vertex_count();
    let (indptr, indices) = pattern(mesh);
    let boundary = 2.0 / (3.0 * a);
    let nnz = indices.len();
    let mut data = [vec![0.0; nnz], vec![0.0; nnz], vec![0.0; nnz]];
    // Disjoint blocks of whole rows, filled in parallel; each row goes
    // through a small buffer straight into the three value arrays.
    let mut blocks = Vec::with_capacity(n.div_ceil(ROWS));
    let [mut r, mut g, mut b] = data.each_mut().map(|d| d.as_mut_slice());
    for k in 0..n.div_ceil(ROWS) {
        let (lo, hi) = (k * ROWS, ((k + 1) * ROWS).min(n));
        let len = indptr[hi] - indptr[lo];
        let (rb, rt) = r.split_at_mut(len);
        let (gb, gt) = g.split_at_mut(len);
        let (bb, bt) = b.split_at_mut(len);
        blocks.push((lo, hi, [rb, gb, bb]));
        (r, g, b) = (rt, gt, bt);
    }
    blocks.into_par_iter().for_each(|(lo, hi, mut block)| {
        let mut out = Vec::new();
        for i in lo..hi {
            let (s, e) = (indptr[i] - indptr[lo], indptr[i + 1] - indptr[lo]);
            out.resize(e - s, [0.0; 3]);
            row(mesh, geometry, coefficients, boundary, i, &mut out);
            for (c, values) in block.iter_mut().enumerate() {
                for (x, v) in values[s..e].iter_mut().zip(&out) {
                    *x = v[c];
                }
            }
        }
    });
    let [r, g, b] = data;
    [
        CsMat::new((n, n), indptr.clone(), indices.clone(), r),
        CsMat::new((n, n), indptr.clone(), indices.clone(), g),
        CsMat::new((n, n), indptr, indices, b),
    ]
}

/// Re-assembles the given rows of the three matrices in place.
pub(crate) fn reassemble_rows(
    mesh: &TetMesh,
    geometry: &Geometry,
    coefficients: &Coefficients,
    a: f64,
    rows: &[u32],
    matrices: &mut [CsMat<f64>; 3],
) {
    let boundary = 2.0 / (3.0 * a);
    let updates: Vec<(usize, Vec<[f64; 3]>)> = rows
        .par_iter()
        .map(|&i| {
            let i = i as usize;
            let len = mesh.one_ring(i).len() + 1;
            let mut out = vec![[0.0; 3]; len];
            row(mesh, geometry, coefficients, boundary, i, &mut out);
            (i, out)
        })
        .collect();
    for (c, m) in matrices.iter_mut().enumerate() {
        let data = m.data_mut();
        for (i, out) in &updates {
            let start = mesh.row_start(*i);
            for (k, v) in out.iter().enumerate() {
                data[start + k] = v[c];
            }
        }
    }
}

/// Eq. 12: `b_i = 8 S_i q_i / (3 A (1 − F_dr))` on the boundary, 0 inside.
/// `q` holds one RGB value per boundary vertex.
pub(crate) fn rhs(mesh: &TetMesh, q: &[[f64; 3]], a: f64, fdr: f64) -> [Vec<f64>; 3] {
    let n = mesh.vertex_count();
    let scale = 8.0 / (3.0 * a * (1.0 - fdr));
    let mut b = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
        let s = mesh.vertex_areas()[v as usize];
        for c in 0..3 {
            b[c][v as usize] = scale * s * q[k][c];
        }
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EDGES;
    use crate::mesh::tests::cube;
    use glam::DVec3;

    #[test]
    fn eq10_matches_the_dihedral_cotangent() {
        let c = [
            DVec3::new(0.1, 0.0, 0.2),
            DVec3::new(1.3, 0.1, 0.0),
            DVec3::new(0.2, 0.9, 0.1),
            DVec3::new(0.3, 0.4, 1.1),
        ];
        let (_, w) = tet_geometry(&c);
        for (e, [i, j]) in EDGES.iter().enumerate() {
            let [k, l] = EDGES[5 - e];
            let (_, cot) = crate::geometry::dihedral(c[k], c[l], c[*i], c[*j]);
            let expected = -c[k].distance(c[l]) * cot / 6.0;
            assert!((w[e] - expected).abs() < 1e-12, "{e}: {} {expected}", w[e]);
        }
    }

    #[test]
    fn eq10_matches_the_face_normal_form() {
        // w_ijt = κ S_i S_j (n_i · n_j) / (9 V_t) (the paper's appendix).
        let c = [
            DVec3::new(0.1, 0.0, 0.2),
            DVec3::new(1.3, 0.1, 0.0),
            DVec3::new(0.2, 0.9, 0.1),
            DVec3::new(0.3, 0.4, 1.1),
        ];
        let (v, w) = tet_geometry(&c);
        // Area vector of the face opposite vertex a, pointing toward a.
        let area = |a: usize| {
            let f = crate::geometry::OUTWARD_FACES[a].map(|k| c[k]);
            -(f[1] - f[0]).cross(f[2] - f[0]) * 0.5
        };
        for (e, [a, b]) in EDGES.iter().enumerate() {
            let expected = area(*a).dot(area(*b)) / (9.0 * v);
            assert!((w[e] - expected).abs() < 1e-12, "{e}: {} {expected}", w[e]);
        }
    }

    #[test]
    fn many_blocks_one_and_two_threads_agree_bit_for_bit() {
        // 2197 vertices: several row blocks and one-ring blocks.
        let (p, t) = cube(12, 1.0);
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let mesh = TetMesh::new(&p, &t).unwrap();
                    let g = Geometry::new(&mesh);
                    let nt = t.len();
                    let coefficients = Coefficients {
                        kappa: (0..nt)
                            .map(|k| [0.3 + 0.01 * (k % 7) as f64, 0.2, 0.1])
                            .collect(),
                        mu: (0..nt).map(|k| [0.05 * (k % 3) as f64, 0.1, 0.0]).collect(),
                    };
                    let m = assemble(&mesh, &g, &coefficients, 2.6);
                    // Every row again on its own: the same bits.
                    let mut out = Vec::new();
                    for i in 0..mesh.vertex_count() {
                        let (s, e) = (m[0].indptr().index(i), m[0].indptr().index(i + 1));
                        out.resize(e - s, [0.0; 3]);
                        row(&mesh, &g, &coefficients, 2.0 / (3.0 * 2.6), i, &mut out);
                        for c in 0..3 {
                            let alone: Vec<f64> = out.iter().map(|v| v[c]).collect();
                            assert_eq!(&m[c].data()[s..e], alone.as_slice());
                        }
                    }
                    m.map(|mc| mc.data().to_vec())
                })
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn symmetric_positive_definite_and_row_sums() {
        let (p, t) = cube(4, 2.0);
        let mesh = TetMesh::new(&p, &t).unwrap();
        let g = Geometry::new(&mesh);
        let nt = t.len();
        let coefficients = Coefficients {
            kappa: (0..nt)
                .map(|k| [0.3 + 0.01 * (k % 7) as f64, 0.2, 0.1])
                .collect(),
            mu: (0..nt).map(|k| [0.05 * (k % 3) as f64, 0.1, 0.0]).collect(),
        };
        let a = crate::fresnel::boundary_factor(1.3);
        let m = assemble(&mesh, &g, &coefficients, a);
        for mc in &m {
            // Bit-for-bit symmetric.
            let t = mc.transpose_view().to_csr();
            assert_eq!(mc.data(), t.data());
            // Row sums: Σ_t V_t μ_t + 2 S_i / (3A) (the cot part sums to 0).
            for (i, r) in mc.outer_iterator().enumerate() {
                let s: f64 = r.iter().map(|(_, v)| v).sum();
                let d = r.get(i).copied().unwrap();
                assert!(d > 0.0);
                assert!(
                    s.abs() <= 1e-12 * d.abs() + 2.0 / (3.0 * a) * mesh.vertex_areas()[i] + 1.0
                );
            }
        }
        // Positive definite: xᵀ M x > 0 for a few vectors, via Cholesky-free
        // check: CG converges (it breaks down on an indefinite matrix).
        let mut x = vec![0.0; mesh.vertex_count()];
        let b: Vec<f64> = (0..x.len()).map(|i| (i % 5) as f64).collect();
        let r = multires::cg(&m[2], &b, &mut x, &multires::SolveOptions::default()).unwrap();
        assert!(r.converged());
        let mut y = vec![0.0; x.len()];
        for k in 0..20 {
            let v: Vec<f64> = (0..x.len())
                .map(|i| ((i * 7 + k * 13) % 11) as f64 - 5.0)
                .collect();
            multires::matrix::mul_vec(&m[1], &v, &mut y);
            assert!(v.iter().zip(&y).map(|(a, b)| a * b).sum::<f64>() > 0.0);
        }
    }
}
