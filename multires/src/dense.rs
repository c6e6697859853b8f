//! A dense Cholesky factorisation for the V-cycle's coarsest level, which
//! is small enough (a few hundred unknowns) that `n³/3` flops are cheaper
//! than iterating.

use sprs::CsMat;

use crate::Error;

/// `A = L Lᵀ`, `L` stored row-major in the lower triangle.
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
            let mut d = l[j * n + j];
            for k in 0..j {
                d -= l[j * n + k] * l[j * n + k];
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

    /// `x ← A⁻¹ b`.
    pub(crate) fn solve(&self, b: &[f64], x: &mut [f64]) {
        let (n, l) = (self.n, &self.l);
        for i in 0..n {
            let mut s = b[i];
            for k in 0..i {
                s -= l[i * n + k] * x[k];
            }
            x[i] = s / l[i * n + i];
        }
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..n {
                s -= l[k * n + i] * x[k];
            }
            x[i] = s / l[i * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sprs::TriMat;

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
    }
}
