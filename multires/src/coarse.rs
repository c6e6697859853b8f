//! Coarse systems (Sec. 4.2). TransCut substitutes the interpolation of
//! Eq. 16 into the equations of the kept vertices (Eq. 17): the coarse
//! matrix is `S M P` and the coarse right-hand side `S b`, with `S` the
//! selection of the kept rows. The result is not symmetric. The V-cycle
//! uses the Galerkin operator `Pᵀ M P` instead, which stays symmetric
//! positive definite.

use sprs::CsMat;

use crate::hierarchy::Coarsening;
use crate::matrix::{assemble, product, transpose};

/// Eq. 17 and the formulas after it: for a kept vertex `i`,
/// `M'_ii = M_ii + Σ_{j∈K(i)} M_ij λ_ji/λ_j`,
/// `M'_ij = [j ∈ R(i)] M_ij + Σ_{k∈K(i)∩N(j)} M_ik λ_kj/λ_k`,
/// where `R(i)` are `i`'s kept neighbours, `K(i)` its dropped ones, and
/// `λ_kj/λ_k` is row `k` of the interpolation. Rows in parallel.
pub fn substituted(m: &CsMat<f64>, step: &Coarsening) -> CsMat<f64> {
    let p = &step.interpolation;
    let (mp, pp) = (m.indptr(), p.indptr());
    let (mp, pp) = (mp.to_proper(), pp.to_proper());
    let coarse = step.kept.len();
    assemble(coarse, coarse, |row, out| {
        let i = step.kept[row] as usize;
        for e in mp[i]..mp[i + 1] {
            let (j, m_ij) = (m.indices()[e], m.data()[e]);
            if step.is_kept(j) {
                // M_ii, and M_ij for j ∈ R(i).
                out.push((step.coarse_index[j] as usize, m_ij));
            } else {
                // j ∈ K(i): its interpolation spreads M_ij over R(j).
                for f in pp[j]..pp[j + 1] {
                    out.push((p.indices()[f], m_ij * p.data()[f]));
                }
            }
        }
    })
}

/// The coarse right-hand side `S b`: the kept entries.
pub fn restrict_by_selection(b: &[f64], step: &Coarsening) -> Vec<f64> {
    step.kept.iter().map(|&i| b[i as usize]).collect()
}

/// The selection `S` (`n_{l+1} × n_l`) as a matrix, for checks.
pub fn selection(step: &Coarsening, fine: usize) -> CsMat<f64> {
    assemble(step.kept.len(), fine, |k, out| {
        out.push((step.kept[k] as usize, 1.0))
    })
}

/// The Galerkin coarse operator `Pᵀ M P`.
pub fn galerkin(m: &CsMat<f64>, step: &Coarsening) -> CsMat<f64> {
    let p = &step.interpolation;
    product(&transpose(p), &product(m, p))
}
