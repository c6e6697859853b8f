//! The reference formulation, the P1 finite-element system of Arbree et
//! al. 2011 (see [`P1Matrices`]).

use glam::{DMat3, DVec3};
use rayon::prelude::*;
use sprs::CsMat;

use crate::assembly::{Coefficients, pattern};
use crate::geometry::OUTWARD_FACES;
use crate::mesh::{Csr, TetMesh};

/// How the element integrals are computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integration {
    /// Closed-form element matrices.
    ClosedForm,
    /// Numerical quadrature at 27 points per tet, 9 per triangle.
    Quadrature,
}

/// The P1 matrices in the pattern of TransCut's `M` (per RGB channel where
/// they depend on the material), mesh units ([`Object::fem_reference`](crate::Object::fem_reference)).
///
/// The reference formulation: the P1 finite-element system of Arbree et
/// al. 2011 for the same diffusion equation and boundary condition,
///
/// `∫ κ ∇φ·∇v + ∫ μa φ v + (1/2A) ∮ φ v = (2 / (A (1 − F_dr))) ∮ q v`,
///
/// with consistent mass and boundary matrices, assembled independently of
/// TransCut's cotangent formula, in two ways: closed-form element matrices
/// (`∇β_a = S_a n_a / (3V)`, Eq. 4; mass `V (1 + δ_ab) / 20`; boundary
/// `area (1 + δ_ab) / 12`), and numerical quadrature (collapsed
/// Gauss–Legendre, 27 points per tet and 9 per boundary triangle, exact for
/// these integrands) evaluating the coefficients and basis functions at
/// every point, as Arbree et al. do (their material varies inside a tet;
/// ours is constant per tet, and the quadrature still samples it per point).
///
/// **The exact relation.** TransCut's matrix is
/// `M = 4 (K + lumped(Mμ) + lumped(B) / (2A))` and its right-hand side
/// `b = 4 × lumped P1 load` (lumping = row sums on the diagonal): the
/// cotangent weights of Eq. 10 are the P1 stiffness entries, and Eq. 13's
/// `V_i μ` and `2 S_i / 3A` are 4 × the lumped mass and boundary mass.
#[derive(Debug, Clone)]
pub struct P1Matrices {
    /// `K_ij = ∫ κ ∇β_i · ∇β_j`.
    pub stiffness: [CsMat<f64>; 3],
    /// `∫ μa β_i β_j` (consistent).
    pub mass: [CsMat<f64>; 3],
    /// `∮ β_i β_j` over the boundary (consistent).
    pub boundary: CsMat<f64>,
}

impl P1Matrices {
    /// The consistent P1 system `K + Mμ + B / (2A)`.
    pub fn consistent(&self, a: f64) -> [CsMat<f64>; 3] {
        [0, 1, 2].map(|c| {
            let data = self.stiffness[c]
                .data()
                .iter()
                .zip(self.mass[c].data())
                .zip(self.boundary.data())
                .map(|((k, m), b)| k + m + b / (2.0 * a))
                .collect();
            self.with_data(data)
        })
    }

    /// `4 (K + lumped(Mμ) + lumped(B) / (2A))`: TransCut's `M`, up to
    /// rounding.
    pub fn lumped_times_four(&self, a: f64) -> [CsMat<f64>; 3] {
        [0, 1, 2].map(|c| {
            let mut data: Vec<f64> = self.stiffness[c].data().to_vec();
            let indptr = self.boundary.indptr().raw_storage().to_vec();
            let indices = self.boundary.indices();
            for i in 0..self.boundary.rows() {
                let (s, e) = (indptr[i], indptr[i + 1]);
                let m: f64 = self.mass[c].data()[s..e].iter().sum();
                let b: f64 = self.boundary.data()[s..e].iter().sum();
                let d = s + indices[s..e].partition_point(|&j| j < i);
                data[d] += m + b / (2.0 * a);
                for x in &mut data[s..e] {
                    *x *= 4.0;
                }
            }
            self.with_data(data)
        })
    }

    /// The consistent load `(2 / (A (1 − F_dr))) B q` for per-vertex
    /// (all vertices; interior ones are ignored) irradiance `q`.
    pub fn load(&self, q: &[f64], a: f64, fdr: f64) -> Vec<f64> {
        let mut b = vec![0.0; q.len()];
        multires::matrix::mul_vec(&self.boundary, q, &mut b);
        let s = 2.0 / (a * (1.0 - fdr));
        b.iter_mut().for_each(|x| *x *= s);
        b
    }

    fn with_data(&self, data: Vec<f64>) -> CsMat<f64> {
        CsMat::new(
            self.boundary.shape(),
            self.boundary.indptr().raw_storage().to_vec(),
            self.boundary.indices().to_vec(),
            data,
        )
    }
}

/// Gauss–Legendre on `[0, 1]`, 3 points (exact to degree 5).
const GAUSS: [(f64, f64); 3] = [
    (0.112_701_665_379_258_3, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// Barycentric coordinates and weights of the collapsed (Duffy) rule on the
/// reference tet, weights summing to 1/6.
fn tet_rule() -> Vec<([f64; 4], f64)> {
    let mut rule = Vec::with_capacity(27);
    for (u, wu) in GAUSS {
        for (v, wv) in GAUSS {
            for (w, ww) in GAUSS {
                let (x, y, z) = (u, (1.0 - u) * v, (1.0 - u) * (1.0 - v) * w);
                let jac = (1.0 - u) * (1.0 - u) * (1.0 - v);
                rule.push(([1.0 - x - y - z, x, y, z], wu * wv * ww * jac));
            }
        }
    }
    rule
}

/// The same on the reference triangle, weights summing to 1/2.
fn triangle_rule() -> Vec<([f64; 3], f64)> {
    let mut rule = Vec::with_capacity(9);
    for (u, wu) in GAUSS {
        for (v, wv) in GAUSS {
            let (x, y) = (u, (1.0 - u) * v);
            rule.push(([1.0 - x - y, x, y], wu * wv * (1.0 - u)));
        }
    }
    rule
}

/// Assembles the P1 matrices of `mesh` with per-tet coefficients.
pub(crate) fn assemble(
    mesh: &TetMesh,
    coefficients: &Coefficients,
    how: Integration,
) -> P1Matrices {
    let n = mesh.vertex_count();
    let (indptr, indices) = pattern(mesh);
    let faces = vertex_faces(mesh);
    let tet_rule = tet_rule();
    let tri_rule = triangle_rule();
    // Each row from its own tets and faces, so the result does not depend
    // on the number of threads.
    let rows: Vec<Vec<[f64; 7]>> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let cols = &indices[indptr[i]..indptr[i + 1]];
            let mut out = vec![[0.0; 7]; cols.len()];
            let at = |j: u32| cols.partition_point(|&c| c < j as usize);
            for &t in mesh.vertex_tets(i) {
                let t = t as usize;
                let tet = mesh.tets()[t];
                let a = tet.iter().position(|&v| v as usize == i).unwrap_or(0);
                let c = mesh.corners(t);
                let (kappa, mu) = (coefficients.kappa[t], coefficients.mu[t]);
                let (k, m) = match how {
                    Integration::ClosedForm => {
                        let (k, m) = closed_form_row(&c, a);
                        (
                            kappa.map(|x| k.map(|k| x * k)),
                            mu.map(|x| m.map(|m| x * m)),
                        )
                    }
                    // The material is sampled at every quadrature point (it
                    // is constant per tet here; Arbree et al.'s varies).
                    Integration::Quadrature => quadrature_row(&c, a, &tet_rule, |_| (kappa, mu)),
                };
                for b in 0..4 {
                    let e = &mut out[at(tet[b])];
                    for ch in 0..3 {
                        e[ch] += k[ch][b];
                        e[3 + ch] += m[ch][b];
                    }
                }
            }
            for &f in faces.row(i) {
                let face = mesh.boundary()[f as usize];
                let a = face.iter().position(|&v| v as usize == i).unwrap_or(0);
                let p = face.map(|v| mesh.positions()[v as usize]);
                let bm = match how {
                    Integration::ClosedForm => {
                        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                        [0, 1, 2].map(|b| area * if a == b { 2.0 } else { 1.0 } / 12.0)
                    }
                    Integration::Quadrature => triangle_row(&p, a, &tri_rule),
                };
                for b in 0..3 {
                    out[at(face[b])][6] += bm[b];
                }
            }
            out
        })
        .collect();
    let flat: Vec<[f64; 7]> = rows.concat();
    let matrix = |k: usize| {
        CsMat::new(
            (n, n),
            indptr.clone(),
            indices.clone(),
            flat.iter().map(|v| v[k]).collect(),
        )
    };
    P1Matrices {
        stiffness: [matrix(0), matrix(1), matrix(2)],
        mass: [matrix(3), matrix(4), matrix(5)],
        boundary: matrix(6),
    }
}

/// Row `a` of the closed-form element stiffness (without κ) and mass
/// (without μ): `V ∇β_a·∇β_b` with `∇β_a = S_a n_a / (3V)`, and
/// `V (1 + δ_ab) / 20`.
fn closed_form_row(c: &[DVec3; 4], a: usize) -> ([f64; 4], [f64; 4]) {
    let v = crate::geometry::volume6(c) / 6.0;
    // Area vector of the face opposite x_b, pointing toward x_b.
    let area = |b: usize| {
        let f = OUTWARD_FACES[b].map(|k| c[k]);
        (f[1] - f[0]).cross(f[2] - f[0]) * -0.5
    };
    let ga = area(a) / (3.0 * v);
    let k = [0, 1, 2, 3].map(|b| v * ga.dot(area(b) / (3.0 * v)));
    let m = [0, 1, 2, 3].map(|b| v * if a == b { 2.0 } else { 1.0 } / 20.0);
    (k, m)
}

/// Row `a` of the element stiffness and mass by quadrature, per channel:
/// the basis gradients from the inverse Jacobian, the basis values and the
/// coefficients `(κ, μa)` at every point.
fn quadrature_row(
    c: &[DVec3; 4],
    a: usize,
    rule: &[([f64; 4], f64)],
    material: impl Fn(DVec3) -> ([f64; 3], [f64; 3]),
) -> ([[f64; 4]; 3], [[f64; 4]; 3]) {
    let jac = DMat3::from_cols(c[1] - c[0], c[2] - c[0], c[3] - c[0]);
    let det = jac.determinant();
    let inv = jac.inverse();
    let g123 = [inv.row(0), inv.row(1), inv.row(2)];
    let grad = [-(g123[0] + g123[1] + g123[2]), g123[0], g123[1], g123[2]];
    let mut k = [[0.0; 4]; 3];
    let mut m = [[0.0; 4]; 3];
    for (bary, w) in rule {
        let dv = w * det;
        let x = c[0] * bary[0] + c[1] * bary[1] + c[2] * bary[2] + c[3] * bary[3];
        let (kappa, mu) = material(x);
        for b in 0..4 {
            let stiffness = dv * grad[a].dot(grad[b]);
            let mass = dv * bary[a] * bary[b];
            for ch in 0..3 {
                k[ch][b] += kappa[ch] * stiffness;
                m[ch][b] += mu[ch] * mass;
            }
        }
    }
    (k, m)
}

/// Row `a` of a boundary triangle's mass matrix by quadrature.
fn triangle_row(p: &[DVec3; 3], a: usize, rule: &[([f64; 3], f64)]) -> [f64; 3] {
    let twice_area = (p[1] - p[0]).cross(p[2] - p[0]).length();
    let mut m = [0.0; 3];
    for (bary, w) in rule {
        for b in 0..3 {
            m[b] += w * twice_area * bary[a] * bary[b];
        }
    }
    m
}

/// Vertex → boundary triangles.
fn vertex_faces(mesh: &TetMesh) -> Csr {
    let n = mesh.vertex_count();
    let mut offsets = vec![0usize; n + 1];
    for f in mesh.boundary() {
        for &v in f {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut items = vec![0u32; offsets[n]];
    for (k, f) in mesh.boundary().iter().enumerate() {
        for &v in f {
            items[fill[v as usize]] = k as u32;
            fill[v as usize] += 1;
        }
    }
    Csr { offsets, items }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_exactly() {
        let t: f64 = tet_rule().iter().map(|r| r.1).sum();
        assert!((t - 1.0 / 6.0).abs() < 1e-15);
        // ∫ λ0² over the reference tet = 2 · 3! / 5! · (1/6)·6 = 1/60.
        let l2: f64 = tet_rule().iter().map(|(b, w)| w * b[0] * b[0]).sum();
        assert!((l2 - 1.0 / 60.0).abs() < 1e-15);
        let l01: f64 = tet_rule().iter().map(|(b, w)| w * b[0] * b[3]).sum();
        assert!((l01 - 1.0 / 120.0).abs() < 1e-15);
        let s: f64 = triangle_rule().iter().map(|(b, w)| w * b[1] * b[2]).sum();
        assert!((s - 1.0 / 24.0).abs() < 1e-15);
    }
}
