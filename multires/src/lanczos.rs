//! The condition number of a (preconditioned) SPD matrix estimated from
//! CG's own coefficients, at no extra mat-vec: CG's `α_j`, `β_j` are the
//! Lanczos tridiagonal `T_k` in disguise, and the extreme eigenvalues of
//! `T_k` (its Ritz values) close in on those of `M⁻¹A` from inside
//! (Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed.,
//! Sec. 6.7.3). The estimate `κ(T_k)` grows towards `κ(M⁻¹A)` as `k` does
//! and never exceeds it (in exact arithmetic): a lower bound that a solver
//! choice can act on as soon as it is large enough.

/// CG's Lanczos matrix, one iteration at a time.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lanczos {
    diagonal: Vec<f64>,
    /// `off[j]` couples rows `j` and `j + 1`.
    off: Vec<f64>,
    last_alpha: f64,
}

impl Lanczos {
    /// An empty matrix (a new CG run).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds iteration `j`: its step `alpha` (`α_j`) and the `beta`
    /// (`β_{j−1}`) that made its direction (ignored for `j = 0`).
    /// Non-finite or non-positive coefficients (a breakdown) are ignored.
    pub fn push(&mut self, alpha: f64, beta: f64) {
        if !(alpha.is_finite() && alpha > 0.0 && beta.is_finite() && beta >= 0.0) {
            return;
        }
        if self.diagonal.is_empty() {
            self.diagonal.push(1.0 / alpha);
        } else {
            let previous = self.last_alpha;
            self.diagonal.push(1.0 / alpha + beta / previous);
            self.off.push(beta.sqrt() / previous);
        }
        self.last_alpha = alpha;
    }

    /// Iterations taken in.
    pub fn len(&self) -> usize {
        self.diagonal.len()
    }

    /// Whether no iteration was taken in.
    pub fn is_empty(&self) -> bool {
        self.diagonal.is_empty()
    }

    /// The smallest and largest eigenvalues of `T_k` (Sturm-sequence
    /// bisection to 10⁻¹² relative); `None` when empty.
    pub fn extremes(&self) -> Option<(f64, f64)> {
        let k = self.diagonal.len();
        if k == 0 {
            return None;
        }
        // Gershgorin bounds.
        let radius = |j: usize| {
            let left = if j > 0 { self.off[j - 1].abs() } else { 0.0 };
            let right = if j + 1 < k { self.off[j].abs() } else { 0.0 };
            left + right
        };
        let lo = (0..k)
            .map(|j| self.diagonal[j] - radius(j))
            .fold(f64::INFINITY, f64::min);
        let hi = (0..k)
            .map(|j| self.diagonal[j] + radius(j))
            .fold(f64::NEG_INFINITY, f64::max);
        let smallest = self.bisect(lo, hi, 1);
        let largest = self.bisect(lo, hi, k);
        Some((smallest, largest))
    }

    /// `κ(T_k) = λ_max / λ_min`, a lower estimate of the condition number
    /// of `M⁻¹A` (infinite when `λ_min ≤ 0`, which rounding allows).
    pub fn condition(&self) -> Option<f64> {
        let (lo, hi) = self.extremes()?;
        Some(if lo > 0.0 { hi / lo } else { f64::INFINITY })
    }

    /// The smallest `x` in `[lo, hi]` with at least `count` eigenvalues
    /// `≤ x`: the `count`-th eigenvalue.
    fn bisect(&self, mut lo: f64, mut hi: f64, count: usize) -> f64 {
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.below(mid) >= count {
                hi = mid;
            } else {
                lo = mid;
            }
            if hi - lo <= 1e-12 * hi.abs().max(lo.abs()) {
                break;
            }
        }
        0.5 * (lo + hi)
    }

    /// Eigenvalues `< x` (Sturm count: negative pivots of `T − x I`).
    fn below(&self, x: f64) -> usize {
        let mut count = 0;
        let mut q = 1.0;
        for j in 0..self.diagonal.len() {
            let coupling = if j > 0 {
                self.off[j - 1] * self.off[j - 1]
            } else {
                0.0
            };
            q = self.diagonal[j] - x - if j > 0 { coupling / q } else { 0.0 };
            if q == 0.0 {
                q = f64::EPSILON * (self.diagonal[j].abs() + x.abs()).max(f64::MIN_POSITIVE);
            }
            if q < 0.0 {
                count += 1;
            }
        }
        count
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Block3, Progress, SolveOptions};
    use std::ops::ControlFlow;

    #[test]
    fn ritz_values_of_a_known_tridiagonal() {
        // T = tridiag(−1, 2, −1) of size k has eigenvalues
        // 2 − 2 cos(jπ/(k+1)); as CG coefficients: fill it directly.
        let k = 12;
        let t = Lanczos {
            diagonal: vec![2.0; k],
            off: vec![-1.0; k - 1],
            last_alpha: 1.0,
        };
        let (lo, hi) = t.extremes().unwrap();
        let exact = |j: usize| 2.0 - 2.0 * (j as f64 * std::f64::consts::PI / (k + 1) as f64).cos();
        assert!((lo - exact(1)).abs() < 1e-10 && (hi - exact(k)).abs() < 1e-10);
    }

    #[test]
    fn the_estimate_grows_to_the_condition_number_from_below() {
        // tridiag(−1, 2, −1): Jacobi divides by a constant, so the
        // preconditioned condition number is the matrix's,
        // cot²(π / (2 (n + 1))).
        let n = 40;
        let mut t = sprs::TriMat::new((n, n));
        for i in 0..n {
            t.add_triplet(i, i, 2.0);
            if i + 1 < n {
                t.add_triplet(i, i + 1, -1.0);
                t.add_triplet(i + 1, i, -1.0);
            }
        }
        let a: &sprs::CsMat<f64> = &t.to_csr();
        let block = Block3::new([a, a, a]).unwrap();
        let mut x = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x0, x1, x2] = &mut x;
        let b = vec![1.0; n];
        let mut t = Lanczos::new();
        let mut seen = Vec::new();
        let mut pairs = Vec::new();
        let mut monitor = |p: &Progress<'_>| {
            let (alpha, beta) = p.coefficients();
            pairs.push((alpha[0], beta[0]));
            t.push(alpha[0], beta[0]);
            seen.push(t.condition().unwrap());
            ControlFlow::Continue(())
        };
        let _ = block
            .cg(
                [&b, &b, &b],
                [x0, x1, x2],
                &SolveOptions::new(1e-12, 200),
                Some(&mut monitor),
            )
            .unwrap();
        // Each estimate is at most the last (rounding aside), and the
        // last, after CG has seen the whole spectrum, is close to the
        // preconditioned matrix's condition number (computed densely).
        let kappa = (std::f64::consts::PI / (2.0 * (n + 1) as f64))
            .tan()
            .powi(-2);
        assert!(
            seen.windows(2).all(|w| w[1] >= w[0] * (1.0 - 1e-9)),
            "{seen:?}"
        );
        let last = *seen.last().unwrap();
        assert!(
            last <= kappa * (1.0 + 1e-6) && last >= 0.9 * kappa,
            "{last} vs {kappa}"
        );
        // A wrong twin (the off-diagonal without its square root) is far
        // from it: the test can tell.
        let mut wrong = t.clone();
        for (j, off) in wrong.off.iter_mut().enumerate() {
            *off = pairs[j + 1].1 / pairs[j].0;
        }
        let w = wrong.condition().unwrap();
        assert!((w / kappa - 1.0).abs() > 0.1, "{w} vs {kappa}");
    }
}
