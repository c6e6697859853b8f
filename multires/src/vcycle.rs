//! Beyond the paper: the hierarchy's interpolation (Eq. 16) as the
//! prolongation of an algebraic multigrid V-cycle, used as the
//! preconditioner of CG on the original system. Coarse operators are
//! Galerkin products `Pᵀ M P` (symmetric positive definite when `M` is),
//! restriction is `Pᵀ`, smoothing is damped Jacobi with as many sweeps
//! after the coarse correction as before it, and the coarsest level is
//! solved exactly by Cholesky — so the V-cycle is a symmetric positive
//! definite operator and CG's theory holds. On a singular but consistent
//! system (a pure Neumann Laplacian) the coarsest factorisation is the
//! semidefinite one and its solve a symmetric generalised inverse, exact
//! on the operator's range (see `dense`), so V-cycle-preconditioned CG
//! converges where plain CG does.

use std::borrow::Cow;
use std::sync::Arc;

use rayon::prelude::*;
use sprs::CsMat;

use crate::Error;
use crate::coarse::galerkin;
use crate::dense::Cholesky;
use crate::graph::Graph;
use crate::hierarchy::{Hierarchy, HierarchyOptions, Weights};
use crate::krylov::{Monitor, Preconditioner, Report, SolveOptions, pcg_checked};
use crate::matrix::{check_square, check_symmetric, inverse_diagonal, mul_vec, transpose};
use crate::vector::{CHUNK, norm, scale};

/// How the V-cycle is built and smooths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VCycleOptions {
    /// How the hierarchy is built (no enhancement by default: Galerkin
    /// operators keep every connection by themselves).
    pub hierarchy: HierarchyOptions,
    /// Jacobi sweeps before and after each coarse correction.
    pub sweeps: usize,
    /// Jacobi damping ω, lowered on a level where Gershgorin's bound on
    /// the eigenvalues of `D⁻¹A` says it would not smooth (ω ≤ 1.8/bound).
    pub damping: f64,
}

impl Default for VCycleOptions {
    fn default() -> Self {
        Self {
            hierarchy: HierarchyOptions {
                coarsest: 400,
                max_levels: 20,
                enhance: false,
                ..HierarchyOptions::default()
            },
            sweeps: 1,
            damping: 0.8,
        }
    }
}

/// Coarsest levels above this size are smoothed instead of factored.
const DENSE_LIMIT: usize = 3_000;

/// One level of the V-cycle below the original.
#[derive(Debug, Clone)]
struct Level {
    matrix: CsMat<f64>,
    /// `ω / a_ii`: the damped Jacobi step.
    inverse_diagonal: Vec<f64>,
}

impl Level {
    /// The level below `finer`: its Galerkin operator over `step` and
    /// its damped Jacobi step.
    fn below(finer: &CsMat<f64>, step: &crate::Coarsening, damping: f64) -> Result<Self, Error> {
        let matrix = galerkin(finer, step);
        let inverse_diagonal = damped_inverse_diagonal(&matrix, damping)?;
        Ok(Level {
            matrix,
            inverse_diagonal,
        })
    }
}

/// The exact factorisation of the coarsest operator (of `fine` when there
/// are no levels), unless it is too large to factor densely.
fn coarsest_of(levels: &[Level], fine: &CsMat<f64>) -> Result<Option<Cholesky>, Error> {
    let last = levels.last().map_or(fine, |l| &l.matrix);
    Ok(if last.rows() <= DENSE_LIMIT {
        Some(Cholesky::new(last)?)
    } else {
        None
    })
}

/// The V-cycle preconditioner of a matrix `m` it borrows (or owns, after
/// [`into_owned`](VCycle::into_owned)).
#[derive(Debug)]
pub struct VCycle<'m> {
    fine: Cow<'m, CsMat<f64>>,
    fine_inverse_diagonal: Vec<f64>,
    /// Levels 1.. (Galerkin operators).
    levels: Vec<Level>,
    /// `P_lᵀ` between level `l` and `l + 1` (`P_l` is the hierarchy's);
    /// shared with [`refreshed`](VCycle::refreshed) copies.
    restrict: Arc<Vec<CsMat<f64>>>,
    coarsest: Option<Cholesky>,
    options: VCycleOptions,
    hierarchy: Arc<Hierarchy>,
    work: std::sync::Mutex<Option<Work>>,
}

impl<'m> VCycle<'m> {
    /// Builds the hierarchy and the Galerkin operators of `m`
    /// (symmetric positive definite).
    ///
    /// # Errors
    /// Those of [`Hierarchy::new`]; [`Error::NotSymmetric`];
    /// [`Error::BadDiagonal`] for a diagonal entry ≤ 0; [`Error::NotPositiveDefinite`] if the coarsest operator
    /// is indefinite (a singular, semidefinite one is factored); [`Error::InvalidOption`] for a damping outside
    /// (0, 1].
    pub fn new(
        m: &'m CsMat<f64>,
        weights: Weights<'_>,
        options: &VCycleOptions,
    ) -> Result<Self, Error> {
        if !(options.damping > 0.0 && options.damping <= 1.0) {
            return Err(Error::InvalidOption("damping must be in (0, 1]"));
        }
        check_square(m)?;
        check_symmetric(m)?;
        let fine_inverse_diagonal = damped_inverse_diagonal(m, options.damping)?;
        // Each level's graph is that of its Galerkin operator, so the
        // coarsening follows the couplings the operator really has.
        // (Called only for the steps the hierarchy keeps.)
        let mut levels: Vec<Level> = Vec::new();
        let hierarchy = Hierarchy::build(m, weights, &options.hierarchy, |_, step| {
            let level = Level::below(
                levels.last().map_or(m, |l| &l.matrix),
                step,
                options.damping,
            )?;
            let graph = Graph::from_matrix(&level.matrix);
            levels.push(level);
            Ok(graph)
        })?;
        let restrict: Vec<CsMat<f64>> = hierarchy
            .steps
            .iter()
            .map(|s| transpose(&s.interpolation))
            .collect();
        let coarsest = coarsest_of(&levels, m)?;
        Ok(Self {
            fine: Cow::Borrowed(m),
            fine_inverse_diagonal,
            levels,
            restrict: Arc::new(restrict),
            coarsest,
            options: *options,
            hierarchy: Arc::new(hierarchy),
            work: std::sync::Mutex::new(None),
        })
    }

    /// The hierarchy.
    pub fn hierarchy(&self) -> &Hierarchy {
        &self.hierarchy
    }

    /// The same V-cycle holding its own copy of the matrix, so that it can
    /// be kept while the matrix it was built from changes: it then stays a
    /// symmetric positive definite preconditioner of the old matrix, and
    /// CG on a matrix whose values moved (painted materials, the same
    /// pattern) still converges with it, without paying for the hierarchy
    /// again — in more iterations the more the values moved (3× those of a
    /// fresh V-cycle in the test where a third of the diagonal grew 1.5×).
    pub fn into_owned(self) -> VCycle<'static> {
        VCycle {
            fine: Cow::Owned(self.fine.into_owned()),
            fine_inverse_diagonal: self.fine_inverse_diagonal,
            levels: self.levels,
            restrict: self.restrict,
            coarsest: self.coarsest,
            options: self.options,
            hierarchy: self.hierarchy,
            work: self.work,
        }
    }

    /// The same hierarchy (the coarsening and the prolongations `P` are
    /// kept) with its operators recomputed for `m`, a matrix of the same
    /// size whose values moved (painted materials): the Galerkin products
    /// `Pᵀ M P`, the smoothers' diagonals and the coarsest factorisation.
    /// Much cheaper than [`new`](Self::new) (no coarsening, no graphs),
    /// and it restores the convergence of a fresh V-cycle where the kept
    /// one slows down. With the matrix the V-cycle was built from, the
    /// operators are bit for bit those of [`new`](Self::new).
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] for a matrix of another size;
    /// those of [`new`](Self::new) for `m` itself.
    pub fn refreshed(&self, m: &CsMat<f64>) -> Result<VCycle<'static>, Error> {
        let n = check_square(m)?;
        if n != self.fine.rows() {
            return Err(Error::DimensionMismatch {
                what: "the refreshed matrix's rows",
                expected: self.fine.rows(),
                found: n,
            });
        }
        check_symmetric(m)?;
        let damping = self.options.damping;
        let fine_inverse_diagonal = damped_inverse_diagonal(m, damping)?;
        let mut levels: Vec<Level> = Vec::with_capacity(self.levels.len());
        for step in &self.hierarchy.steps {
            let finer = levels.last().map_or(m, |l| &l.matrix);
            levels.push(Level::below(finer, step, damping)?);
        }
        let coarsest = coarsest_of(&levels, m)?;
        Ok(VCycle {
            fine: Cow::Owned(m.clone()),
            fine_inverse_diagonal,
            levels,
            restrict: self.restrict.clone(),
            coarsest,
            options: self.options,
            hierarchy: self.hierarchy.clone(),
            work: std::sync::Mutex::new(None),
        })
    }

    /// How far `m`'s diagonal moved from that of the matrix the V-cycle
    /// was built for: the mean over rows of `min(1, |mᵢᵢ − aᵢᵢ| / aᵢᵢ)`
    /// (0 for the same diagonal, 1 when every row changed by 100% or
    /// more). A cheap proxy for how much the kept V-cycle has lost as a
    /// preconditioner of `m`, to decide when to [`refresh`](Self::refreshed)
    /// it. A matrix of another size gives 1.
    pub fn diagonal_drift(&self, m: &CsMat<f64>) -> f64 {
        let n = self.fine.rows();
        if m.rows() != n || m.cols() != n || n == 0 {
            return 1.0;
        }
        let now = crate::matrix::diagonal(m);
        let built = crate::matrix::diagonal(&self.fine);
        let sum: f64 = now
            .par_chunks(CHUNK)
            .zip(built.par_chunks(CHUNK))
            .map(|(d, a)| {
                d.iter()
                    .zip(a)
                    .map(|(&d, &a)| ((d - a) / a).abs().min(1.0))
                    .sum::<f64>()
            })
            .collect::<Vec<f64>>()
            .iter()
            .sum();
        sum / n as f64
    }

    /// Bytes this V-cycle holds apart from what it shares with the
    /// V-cycle it was [refreshed](Self::refreshed) from (the
    /// prolongations and the hierarchy's graphs): the matrix copy, the
    /// coarse operators, the smoothers' diagonals and the coarsest
    /// factorisation. What keeping an old V-cycle beside its refreshed
    /// copy costs.
    pub fn own_bytes(&self) -> usize {
        let csr = |m: &CsMat<f64>| m.nnz() * 12 + (m.rows() + 1) * 8;
        let levels: usize = self
            .levels
            .iter()
            .map(|l| csr(&l.matrix) + 8 * l.inverse_diagonal.len())
            .sum();
        let dense = self.coarsest.as_ref().map_or(0, |_| {
            let r = self
                .levels
                .last()
                .map_or(self.fine.rows(), |l| l.matrix.rows());
            8 * r * r
        });
        csr(&self.fine) + 8 * self.fine_inverse_diagonal.len() + levels + dense
    }

    /// Bytes of the operators, the prolongations and the hierarchy's
    /// index arrays (the matrix copy included), to budget kept copies.
    pub fn memory_bytes(&self) -> usize {
        let csr = |m: &CsMat<f64>| m.nnz() * 12 + (m.rows() + 1) * 8;
        let steps: usize = self
            .hierarchy
            .steps
            .iter()
            .map(|s| 2 * csr(&s.interpolation) + 4 * (s.kept.len() + s.coarse_index.len()))
            .sum();
        let graphs: usize = self
            .hierarchy
            .graphs
            .iter()
            .map(|g| 4 * (g.len() + 2 * g.edges()))
            .sum();
        self.own_bytes() + steps + graphs
    }

    /// Unknowns of the matrix it was built from.
    pub fn rows(&self) -> usize {
        self.fine.rows()
    }

    /// Stored entries of all operators divided by those of the original
    /// (the "operator complexity" of multigrid).
    pub fn operator_complexity(&self) -> f64 {
        let coarse: usize = self.levels.iter().map(|l| l.matrix.nnz()).sum();
        (self.fine.nnz() + coarse) as f64 / self.fine.nnz() as f64
    }

    /// Unknowns per level, the original first.
    pub fn level_rows(&self) -> Vec<usize> {
        (0..=self.levels.len())
            .map(|l| self.matrix(l).0.rows())
            .collect()
    }

    /// A coarse-grid approximation of `M⁻¹ r` (the correction that brings
    /// an iterate with residual `r` toward the solution): `r` restricted
    /// to level `level` (`Pᵀ` per step; clamped to the coarsest), that
    /// level's Galerkin system solved from zero by CG preconditioned by the
    /// V-cycle below it (or by the coarsest factorisation, exactly) to
    /// `options.tolerance` relative to the restricted residual, and the
    /// solution prolonged back to the original unknowns (`P` per step),
    /// with `sweeps[0]` damped Jacobi sweeps against the restricted
    /// residual on each intermediate level on the way up and `sweeps[1]`
    /// against `r` on the original level (one mat-vec each). Returns the
    /// coarse solve's report (for the coarse system) and the level used.
    ///
    /// This is the multi-resolution preview of TransCut (Sec. 4.2): a
    /// coarse level's solution interpolated to the fine vertices, at the
    /// cost of a few coarse iterations and one restriction and
    /// prolongation; a deterministic function of `r` (bit for bit on any
    /// number of threads), so it can stand as a state to warm-start from.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] for `r` or `z` of another length;
    /// those of [`crate::pcg`] on the coarse system.
    pub fn coarse_correction(
        &self,
        level: usize,
        r: &[f64],
        z: &mut [f64],
        [sweeps, fine_sweeps]: [usize; 2],
        options: &SolveOptions,
        monitor: Monitor<'_>,
    ) -> Result<(Report, usize), Error> {
        let n = self.fine.rows();
        for (what, len) in [("the residual", r.len()), ("the correction", z.len())] {
            if len != n {
                return Err(Error::DimensionMismatch {
                    what,
                    expected: n,
                    found: len,
                });
            }
        }
        let level = level.min(self.levels.len());
        if level == 0 {
            z.fill(0.0);
            let report = pcg_checked(&self.fine, r, z, self, options, monitor)?;
            return Ok((report, 0));
        }
        // Restricted residuals r_1..=r_level.
        let mut rs: Vec<Vec<f64>> = Vec::with_capacity(level);
        for l in 0..level {
            let mut next = vec![0.0; self.restrict[l].rows()];
            mul_vec(&self.restrict[l], rs.last().map_or(r, |v| v), &mut next);
            rs.push(next);
        }
        let b = &rs[level - 1];
        let mut e = vec![0.0; b.len()];
        let report = match (&self.coarsest, level == self.levels.len()) {
            (Some(c), true) => {
                c.solve(b, &mut e);
                let (a, _) = self.matrix(level);
                let mut t = vec![0.0; b.len()];
                mul_vec(a, &e, &mut t);
                t.iter_mut().zip(b).for_each(|(t, b)| *t = b - *t);
                let (res, scale) = (norm(&t), norm(b));
                Report {
                    stop: crate::Stop::Converged,
                    iterations: 1,
                    residual: if scale > 0.0 { res / scale } else { 0.0 },
                }
            }
            _ => {
                let (a, _) = self.matrix(level);
                let pre = FromLevel {
                    vcycle: self,
                    level,
                };
                pcg_checked(a, b, &mut e, &pre, options, monitor)?
            }
        };
        // Up: prolong, and smooth on the intermediate levels.
        for l in (0..level).rev() {
            let interpolation = &self.hierarchy.steps[l].interpolation;
            if l == 0 {
                mul_vec(interpolation, &e, z);
                if fine_sweeps > 0 {
                    let mut t = vec![0.0; n];
                    self.smooth(
                        &self.fine,
                        &self.fine_inverse_diagonal,
                        r,
                        z,
                        &mut t,
                        fine_sweeps,
                    );
                }
                break;
            }
            let mut up = vec![0.0; interpolation.rows()];
            mul_vec(interpolation, &e, &mut up);
            if sweeps > 0 {
                let (a, inv) = self.matrix(l);
                let mut t = vec![0.0; up.len()];
                self.smooth(a, inv, &rs[l - 1], &mut up, &mut t, sweeps);
            }
            e = up;
        }
        Ok((report, level))
    }

    fn matrix(&self, level: usize) -> (&CsMat<f64>, &[f64]) {
        match level {
            0 => (&*self.fine, &self.fine_inverse_diagonal),
            l => (
                &self.levels[l - 1].matrix,
                &self.levels[l - 1].inverse_diagonal,
            ),
        }
    }

    /// `z_from ← V r_from`: from level `from` down the levels (smooth
    /// from zero, restrict the residual), the exact coarsest solve, up the
    /// levels (prolong the correction, smooth again). `from = 0` is the
    /// whole V-cycle.
    fn cycle(&self, work: &mut Work, from: usize) {
        let coarse_levels = self.levels.len();
        for l in from..coarse_levels {
            let (a, inv) = self.matrix(l);
            let (r, z, t) = (&work.r[l], &mut work.z[l], &mut work.t[l]);
            self.smooth_from_zero(a, inv, r, z, t);
            // t ← r − A z, then r_{l+1} ← Pᵀ t.
            mul_vec(a, z, t);
            t.par_iter_mut().zip(r).for_each(|(t, r)| *t = r - *t);
            let (fine, coarse) = work.r.split_at_mut(l + 1);
            mul_vec(&self.restrict[l], &work.t[l], &mut coarse[0]);
            let _ = fine;
        }
        {
            let l = coarse_levels;
            let (a, inv) = self.matrix(l);
            let (r, z, t) = (&work.r[l], &mut work.z[l], &mut work.t[l]);
            match &self.coarsest {
                Some(c) => c.solve(r, z),
                None => {
                    self.smooth_from_zero(a, inv, r, z, t);
                    self.smooth(a, inv, r, z, t, 10 * self.options.sweeps.max(1));
                }
            }
        }
        for l in (from..coarse_levels).rev() {
            let (a, inv) = self.matrix(l);
            let (fine, coarse) = work.z.split_at_mut(l + 1);
            let t = &mut work.t[l];
            mul_vec(&self.hierarchy.steps[l].interpolation, &coarse[0], t);
            let z = &mut fine[l];
            z.par_iter_mut().zip(&*t).for_each(|(z, c)| *z += c);
            self.smooth(a, inv, &work.r[l], z, t, self.options.sweeps);
        }
    }

    /// `sweeps` damped Jacobi sweeps from `z = 0`; the first needs no
    /// mat-vec.
    fn smooth_from_zero(
        &self,
        a: &CsMat<f64>,
        inv: &[f64],
        r: &[f64],
        z: &mut [f64],
        t: &mut [f64],
    ) {
        if self.options.sweeps == 0 {
            z.fill(0.0);
            return;
        }
        scale(inv, r, z);
        self.smooth(a, inv, r, z, t, self.options.sweeps - 1);
    }

    /// `sweeps` damped Jacobi sweeps `z ← z + ω D⁻¹ (r − A z)`, `t` scratch.
    fn smooth(
        &self,
        a: &CsMat<f64>,
        inv: &[f64],
        r: &[f64],
        z: &mut [f64],
        t: &mut [f64],
        sweeps: usize,
    ) {
        for _ in 0..sweeps {
            mul_vec(a, z, t);
            z.par_chunks_mut(CHUNK)
                .zip(t.par_chunks(CHUNK))
                .zip(r.par_chunks(CHUNK).zip(inv.par_chunks(CHUNK)))
                .for_each(|((z, az), (r, d))| {
                    for k in 0..z.len() {
                        z[k] += d[k] * (r[k] - az[k]);
                    }
                });
        }
    }

    fn new_work(&self) -> Work {
        let sizes: Vec<usize> = (0..=self.levels.len())
            .map(|l| self.matrix(l).0.rows())
            .collect();
        let vectors = || sizes.iter().map(|&n| vec![0.0; n]).collect::<Vec<_>>();
        Work {
            r: vectors(),
            z: vectors(),
            t: vectors(),
        }
    }

    /// CG on the original system preconditioned by this V-cycle.
    ///
    /// # Errors
    /// Those of [`crate::pcg`] for `b` and `x`, and [`Error::NotConverged`]
    /// when the tolerance is not reached and
    /// [`SolveOptions::require_convergence`] is on.
    pub fn solve(&self, b: &[f64], x: &mut [f64], options: &SolveOptions) -> Result<Report, Error> {
        self.solve_monitored(b, x, options, &mut |_, _| {
            std::ops::ControlFlow::Continue(())
        })
    }

    /// [`solve`](Self::solve) calling `monitor` after every iteration.
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_monitored(
        &self,
        b: &[f64],
        x: &mut [f64],
        options: &SolveOptions,
        monitor: Monitor<'_>,
    ) -> Result<Report, Error> {
        // The matrix was checked (square, finite, symmetric) when the
        // V-cycle was built.
        options.settle(pcg_checked(&self.fine, b, x, self, options, monitor)?)
    }
}

/// `ω_l / a_ii` with `ω_l = min(ω, 1.8 / max_i Σ_j |a_ij| / a_ii)`:
/// Gershgorin bounds the eigenvalues of `D⁻¹A`, and damped Jacobi smooths
/// only while `ω λ < 2`.
fn damped_inverse_diagonal(a: &CsMat<f64>, omega: f64) -> Result<Vec<f64>, Error> {
    let inverse = inverse_diagonal(a, true)?;
    let bound = a
        .outer_iterator()
        .zip(&inverse)
        .map(|(row, d)| row.iter().map(|(_, v)| v.abs()).sum::<f64>() * d)
        .fold(0.0f64, f64::max);
    let omega = omega.min(1.8 / bound);
    Ok(inverse.into_iter().map(|d| omega * d).collect())
}

/// Per-level vectors of a cycle, kept between applications: allocating
/// (and first touching) them each time costs as much as a mat-vec.
#[derive(Debug)]
struct Work {
    r: Vec<Vec<f64>>,
    z: Vec<Vec<f64>>,
    t: Vec<Vec<f64>>,
}

impl Preconditioner for VCycle<'_> {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        // PCG applies the preconditioner from one thread at a time; the
        // lock only makes the V-cycle usable from several.
        let mut guard = self
            .work
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let work = guard.get_or_insert_with(|| self.new_work());
        work.r[0].copy_from_slice(r);
        self.cycle(work, 0);
        z.copy_from_slice(&work.z[0]);
    }
}

/// The V-cycle from one of its coarse levels down: the preconditioner of
/// that level's system in [`VCycle::coarse_correction`].
struct FromLevel<'v, 'm> {
    vcycle: &'v VCycle<'m>,
    level: usize,
}

impl Preconditioner for FromLevel<'_, '_> {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        let v = self.vcycle;
        let mut guard = v
            .work
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let work = guard.get_or_insert_with(|| v.new_work());
        work.r[self.level].copy_from_slice(r);
        v.cycle(work, self.level);
        z.copy_from_slice(&work.z[self.level]);
    }
}
