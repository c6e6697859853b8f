//! TransCut's multi-resolution solve (Sec. 4.2): solve the coarsest
//! level's system (Eq. 17) to convergence with BiCGSTAB, interpolate it
//! (Eq. 16) to each finer level and improve it there with a few BiCGSTAB
//! iterations, then finish on the original system with CG from that start.

use sprs::CsMat;

use crate::Error;
use crate::coarse::{galerkin, restrict_by_selection, substituted};
use crate::hierarchy::{Hierarchy, HierarchyOptions, Weights};
use crate::krylov::{
    Monitor, Report, SolveOptions, bicgstab_checked, jacobi_cg_checked, no_monitor, nonzero,
    pcg_checked,
};
use crate::matrix::{check_square, check_symmetric, check_vector, mul_vec, transpose};

/// Which coarse systems the cascade solves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CoarseSystem {
    /// The paper's Eq. 17: `S M P` with right-hand side `S b`. Each kept
    /// vertex keeps its own equation, so a coarse vertex carries the mass
    /// (absorption) and source of one fine vertex but couples to
    /// neighbours further away: the coarse problem diffuses further than
    /// the fine one.
    #[default]
    Substituted,
    /// `Pᵀ M P` with right-hand side `Pᵀ b`: each kept vertex sums the
    /// equations of the dropped vertices that interpolate from it, so mass,
    /// sources and diffusion stay in proportion, and the system stays
    /// symmetric positive definite.
    Galerkin,
}

/// How the coarse levels are solved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CascadeOptions {
    /// How the hierarchy is built.
    pub hierarchy: HierarchyOptions,
    /// Which coarse systems.
    pub system: CoarseSystem,
    /// The coarsest level's solve ("to convergence"). Its
    /// `require_convergence` is not used: a coarsest level that does not
    /// converge hands over to the next finer one (reported in
    /// [`CascadeReport::fallbacks`]).
    pub coarsest: SolveOptions,
    /// BiCGSTAB iterations on each intermediate level.
    pub intermediate_iterations: usize,
}

impl Default for CascadeOptions {
    fn default() -> Self {
        Self {
            hierarchy: HierarchyOptions {
                coarsest: 20_000,
                max_levels: 4,
                ..HierarchyOptions::default()
            },
            system: CoarseSystem::Substituted,
            coarsest: SolveOptions::new(1e-4, 500),
            intermediate_iterations: 2,
        }
    }
}

impl CascadeOptions {
    /// Beyond the paper, and faster on absorbing media: Galerkin coarse
    /// systems solved by CG, on three levels coarsened without
    /// enhancement, with interpolation weights corrected to reproduce
    /// linear functions (from the 2-ring where the kept 1-ring does not
    /// surround a vertex). The interpolated start is then within about 1%
    /// of the solution on the benchmark (a few % when the diffusion length
    /// is only a few cells). Needs [`Weights::Positions`].
    pub fn galerkin() -> Self {
        Self {
            hierarchy: HierarchyOptions {
                coarsest: 2_000,
                max_levels: 3,
                enhance: false,
                linear_precision: true,
                wide_interpolation: true,
                ..HierarchyOptions::default()
            },
            system: CoarseSystem::Galerkin,
            coarsest: SolveOptions::new(1e-1, 1_000),
            intermediate_iterations: 1,
        }
    }
}

/// What a cascade solve did. Read it: with
/// [`SolveOptions::require_convergence`] off, a cascade whose final CG
/// stopped short is still `Ok`.
#[must_use = "a solve may stop before its tolerance: check `finest.converged()`"]
#[derive(Debug, Clone, PartialEq)]
pub struct CascadeReport {
    /// The level whose solve converged and started the cascade.
    pub start_level: usize,
    /// Coarse levels whose solve did not converge, so the next finer level
    /// was solved instead (the paper's fallback).
    pub fallbacks: Vec<(usize, Report)>,
    /// Each coarse level's solve, from the start level up to level 1.
    pub coarse: Vec<(usize, Report)>,
    /// The final CG solve on the original system.
    pub finest: Report,
}

/// The hierarchy and its coarse systems, built once per matrix.
#[derive(Debug, Clone)]
pub struct Cascade {
    hierarchy: Hierarchy,
    /// `matrices[l - 1]` is level `l`'s matrix.
    matrices: Vec<CsMat<f64>>,
    /// `Pᵀ` of each step, for Galerkin right-hand sides (empty for Eq. 17,
    /// which restricts by selection).
    restrict: Vec<CsMat<f64>>,
    options: CascadeOptions,
}

impl Cascade {
    /// Builds the hierarchy of `m` and the coarse matrices of Eq. 17.
    ///
    /// # Errors
    /// Those of [`Hierarchy::new`], and [`Error::NotSymmetric`] (the
    /// cascade ends in CG on `m`).
    ///
    /// # Example
    /// ```
    /// use multires::{grid, Cascade, CascadeOptions, SolveOptions, Weights};
    /// let p = grid::diffusion([16, 16, 16], 5.0)?;
    /// let options = CascadeOptions::default();
    /// let cascade = Cascade::new(&p.matrix, Weights::Positions(&p.positions), &options)?;
    /// let mut x = vec![0.0; p.rhs.len()];
    /// let report = cascade.solve(&p.matrix, &p.rhs, &mut x, &SolveOptions::default())?;
    /// assert!(report.finest.converged());
    /// # Ok::<(), multires::Error>(())
    /// ```
    pub fn new(
        m: &CsMat<f64>,
        weights: Weights<'_>,
        options: &CascadeOptions,
    ) -> Result<Self, Error> {
        let hierarchy = Hierarchy::new(m, weights, &options.hierarchy)?;
        // The cascade ends in CG on `m`: refuse a non-symmetric matrix
        // now rather than at every solve's end.
        check_symmetric(m)?;
        let mut matrices: Vec<CsMat<f64>> = Vec::with_capacity(hierarchy.steps.len());
        for step in &hierarchy.steps {
            let finer = matrices.last().unwrap_or(m);
            let coarse = match options.system {
                CoarseSystem::Substituted => substituted(finer, step),
                CoarseSystem::Galerkin => galerkin(finer, step),
            };
            matrices.push(coarse);
        }
        let restrict = match options.system {
            CoarseSystem::Substituted => Vec::new(),
            CoarseSystem::Galerkin => hierarchy
                .steps
                .iter()
                .map(|step| transpose(&step.interpolation))
                .collect(),
        };
        Ok(Self {
            hierarchy,
            matrices,
            restrict,
            options: *options,
        })
    }

    /// BiCGSTAB for the paper's non-symmetric systems, CG for Galerkin's
    /// symmetric positive definite ones (one mat-vec per iteration, not two).
    fn coarse_solve(
        &self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolveOptions,
    ) -> Result<Report, Error> {
        // Coarse levels never fail the solve: a coarsest level that does
        // not converge is a fallback, an intermediate one runs a fixed
        // number of iterations. Their matrices were built here from a
        // checked one.
        match self.options.system {
            CoarseSystem::Substituted => bicgstab_checked(a, b, x, options, &mut no_monitor()),
            CoarseSystem::Galerkin => {
                let jacobi = crate::Jacobi::new(a)?;
                pcg_checked(a, b, x, &jacobi, options, &mut no_monitor())
            }
        }
    }

    /// Stored entries of each level's matrix, level 1 first.
    pub fn nonzeros(&self) -> Vec<usize> {
        self.matrices.iter().map(CsMat::nnz).collect()
    }

    /// The hierarchy.
    pub fn hierarchy(&self) -> &Hierarchy {
        &self.hierarchy
    }

    /// Level `l`'s matrix (`l ≥ 1`).
    pub fn matrix(&self, level: usize) -> Option<&CsMat<f64>> {
        self.matrices.get(level.checked_sub(1)?)
    }

    /// Solves `m x = b`. `m` is the matrix the cascade was built from, or
    /// one with the same pattern whose values changed a little (painted
    /// materials): the coarse levels then give a slightly worse start and
    /// the final CG still solves `m` exactly. `x` is the warm start of the
    /// coarsest level (by selection) and receives the solution.
    ///
    /// # Errors
    /// Those of [`crate::cg`] for `m`, `b` and `x` (including
    /// [`Error::NotSymmetric`]), and [`Error::CascadeNotConverged`] when the
    /// final CG does not reach the tolerance and
    /// [`SolveOptions::require_convergence`] is on (coarse levels that do
    /// not converge are fallbacks, never errors).
    pub fn solve(
        &self,
        m: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolveOptions,
    ) -> Result<CascadeReport, Error> {
        self.solve_monitored(m, b, x, options, &mut |_, _| {
            std::ops::ControlFlow::Continue(())
        })
    }

    /// [`solve`](Self::solve) calling `monitor` with iteration 0 when the
    /// interpolated start reaches level 0, then after every CG iteration;
    /// a `Break` stops it there.
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_monitored(
        &self,
        m: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        options: &SolveOptions,
        monitor: Monitor<'_>,
    ) -> Result<CascadeReport, Error> {
        let n = check_square(m)?;
        check_symmetric(m)?;
        let sizes = self.hierarchy.sizes();
        if n != sizes[0] {
            return Err(Error::DimensionMismatch {
                what: "matrix given to the cascade",
                expected: sizes[0],
                found: n,
            });
        }
        check_vector("right-hand side", b, n)?;
        check_vector("start vector", x, n)?;
        let steps = &self.hierarchy.steps;
        // Right-hand sides and warm starts of every level, by selection.
        let mut rhs = vec![b.to_vec()];
        let mut start = vec![x.to_vec()];
        for (l, step) in steps.iter().enumerate() {
            let finer = &rhs[rhs.len() - 1];
            rhs.push(match self.restrict.get(l) {
                None => restrict_by_selection(finer, step),
                Some(pt) => {
                    let mut coarse = vec![0.0; step.kept.len()];
                    mul_vec(pt, finer, &mut coarse);
                    coarse
                }
            });
            start.push(restrict_by_selection(&start[start.len() - 1], step));
        }
        let mut level = steps.len();
        let mut fallbacks = Vec::new();
        let mut coarse = Vec::new();
        // The coarsest level that converges starts the cascade.
        let mut current: Option<Vec<f64>> = None;
        while level > 0 {
            let mut xl = start[level].clone();
            let report = self.coarse_solve(
                &self.matrices[level - 1],
                &rhs[level],
                &mut xl,
                &self.options.coarsest,
            )?;
            if report.converged() {
                coarse.push((level, report));
                current = Some(xl);
                break;
            }
            fallbacks.push((level, report));
            level -= 1;
        }
        let start_level = level;
        if let Some(mut xc) = current {
            for l in (0..start_level).rev() {
                let mut xf = vec![0.0; sizes[l]];
                mul_vec(&steps[l].interpolation, &xc, &mut xf);
                if l == 0 {
                    x.copy_from_slice(&xf);
                    break;
                }
                let few = SolveOptions {
                    max_iterations: self.options.intermediate_iterations,
                    ..self.options.coarsest
                };
                let report = self.coarse_solve(&self.matrices[l - 1], &rhs[l], &mut xf, &few)?;
                coarse.push((l, report));
                xc = xf;
            }
        }
        if monitor(0, x).is_break() {
            let mut r = vec![0.0; n];
            let scale = crate::vector::norm(b);
            let residual = crate::krylov::residual_into(m, b, x, &mut r) / nonzero(scale);
            let finest = Report {
                stop: crate::Stop::Interrupted,
                iterations: 0,
                residual,
            };
            return Ok(CascadeReport {
                start_level,
                fallbacks,
                coarse,
                finest,
            });
        }
        let finest = jacobi_cg_checked(m, b, x, options, monitor)?;
        let report = CascadeReport {
            start_level,
            fallbacks,
            coarse,
            finest,
        };
        match options.settle(finest) {
            Ok(_) => Ok(report),
            Err(_) => Err(Error::CascadeNotConverged {
                report: Box::new(report),
                tolerance: options.tolerance,
            }),
        }
    }
}
