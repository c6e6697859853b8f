//! A dense Cholesky factorisation for the V-cycle's coarsest level, which
//! is small enough (a few hundred unknowns) that `n³/3` flops are cheaper
//! than iterating.
//!
//! The coarsest operator of a pure-Neumann problem is singular (positive
//! semidefinite, the constants in its null space), so the factorisation
//! is the semidefinite one (Higham, *Accuracy and Stability of Numerical
//! Algorithms*, 2nd ed., Sec. 10.3): a pivot that vanishes relative to its
//! diagonal entry marks a null direction; its column of `L` is zero (in a
//! semidefinite matrix the rest of that Schur-complement column vanishes
//! with it) and the solve sets that unknown to zero. The solve is then the
//! symmetric positive semidefinite generalised inverse
//! `G = (E L̃⁻¹)ᵀ (E L̃⁻¹)` (`L̃` is `L` with a unit diagonal at the zero
//! pivots, `E` zeroes those unknowns), with `A G b = b` for every `b` in
//! the range of `A`: exact on consistent systems, symmetric, so CG's
//! theory holds for the V-cycle built on it.

use sprs::CsMat;

use crate::Error;

/// A pivot at most this fraction of its diagonal entry is a null
/// direction: round-off leaves about `n ε` of it in an exact zero.
const NULL_PIVOT: f64 = 1e-10;

/// `A = L Lᵀ`, `L` stored row-major in the lower triangle; a zero
/// diagonal entry of `L` marks a null direction of `A`.
#[derive(Debug, Clone)]
pub(crate) struct Cholesky {
    n: usize,
    l: Vec<f64>,
}

impl Cholesky {
    pub(crate) fn new(a: &CsMat<f64>) -> Result<Self, Error> {
        let n = a.rows();
        let mut l = vec![0.0; n * n];
        for (v, (i, j)) in a.iter() {
            l[i * n + j] += *v;
        }
        for j in 0..n {
            let diagonal = l[j * n + j];
            let mut d = diagonal;
            for k in 0..j {
                d -= l[j * n + k] * l[j * n + k];
            }
            let null = diagonal > 0.0 && d.abs() <= NULL_PIVOT * diagonal;
            if null {
                // A null direction: its column of L is zero.
                for i in j..n {
                    l[i * n + j] = 0.0;
                }
                continue;
            }
            if !(d > 0.0 && d.is_finite()) {
                return Err(Error::NotPositiveDefinite {
                    size: n,
                    pivot: j,
                    value: d,
                });
            }
            let d = d.sqrt();
            l[j * n + j] = d;
            for i in j + 1..n {
                let mut s = l[i * n + j];
                for k in 0..j {
                    s -= l[i * n + k] * l[j * n + k];
                }
                l[i * n + j] = s / d;
            }
        }
        Ok(Self { n, l })
    }

    /// `x ← A⁻¹ b`, or `x ← G b` with the generalised inverse `G` of the
    /// module's documentation when `A` is singular (null unknowns are 0).
    pub(crate) fn solve(&self, b: &[f64], x: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        let divide = |s: f64, d: f64| if d > 0.0 { s / d } else { 0.0 };
        for i in 0..n {
            let mut s = b[i];
            for k in 0..i {
                s -= l[i * n + k] * x[k];
            }
            x[i] = divide(s, l[i * n + i]);
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..n {
                s -= l[k * n + i] * x[k];
            }
            x[i] = divide(s, l[i * n + i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sprs::TriMat;

    /// The path Laplacian with free ends (pure Neumann) is singular with
    /// the constants as null space. For a consistent `b` (summing to 0)
    /// the solve is a solution: `A x = b`, and for `b = e_0 − e_{n−1}` the
    /// closed form is `x_i − x_{i+1} = 1`. The generalised inverse is
    /// symmetric: `u · G v = v · G u`.
    #[test]
    fn solves_a_singular_consistent_system() {
        let n = 12;
        let mut t = TriMat::new((n, n));
        for i in 0..n - 1 {
            t.add_triplet(i, i, 1.0);
            t.add_triplet(i + 1, i + 1, 1.0);
            t.add_triplet(i, i + 1, -1.0);
            t.add_triplet(i + 1, i, -1.0);
        }
        let a: CsMat<f64> = t.to_csr();
        let c = Cholesky::new(&a).unwrap();
        let mut b = vec![0.0; n];
        b[0] = 1.0;
        b[n - 1] = -1.0;
        let mut x = vec![0.0; n];
        c.solve(&b, &mut x);
        for i in 0..n - 1 {
            assert!((x[i] - x[i + 1] - 1.0).abs() < 1e-9, "{x:?}");
        }
        let mut y = vec![0.0; n];
        crate::matrix::mul_vec(&a, &x, &mut y);
        assert!(y.iter().zip(&b).all(|(y, b)| (y - b).abs() < 1e-9));
        let u: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
        let v: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
        let (mut gu, mut gv) = (vec![0.0; n], vec![0.0; n]);
        c.solve(&u, &mut gu);
        c.solve(&v, &mut gv);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
        assert!((dot(&u, &gv) - dot(&v, &gu)).abs() < 1e-9);
        assert!(dot(&u, &gu) >= -1e-12, "G is semidefinite");
    }

    #[test]
    fn solves_a_small_spd_system() {
        let mut t = TriMat::new((3, 3));
        for (i, j, v) in [
            (0, 0, 4.0),
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 1, 3.0),
            (1, 2, -1.0),
            (2, 1, -1.0),
            (2, 2, 2.0),
        ] {
            t.add_triplet(i, j, v);
        }
        let a: CsMat<f64> = t.to_csr();
        let c = Cholesky::new(&a).unwrap();
        let mut x = vec![0.0; 3];
        c.solve(&[1.0, 2.0, 3.0], &mut x);
        let mut y = vec![0.0; 3];
        crate::matrix::mul_vec(&a, &x, &mut y);
        for (y, b) in y.iter().zip([1.0, 2.0, 3.0]) {
            assert!((y - b).abs() < 1e-12);
        }
        let mut t = TriMat::new((2, 2));
        t.add_triplet(0, 0, 1.0);
        t.add_triplet(1, 1, -1.0);
        assert!(matches!(
            Cholesky::new(&t.to_csr()),
            Err(Error::NotPositiveDefinite { pivot: 1, .. })
        ));
        // Indefinite with a positive diagonal: still refused.
        let mut t = TriMat::new((2, 2));
        for (i, j, v) in [(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 1.0)] {
            t.add_triplet(i, j, v);
        }
        assert!(matches!(
            Cholesky::new(&t.to_csr()),
            Err(Error::NotPositiveDefinite { pivot: 1, .. })
        ));
    }
}
