//! Krylov solvers: Jacobi-preconditioned CG for symmetric positive
//! definite systems, CG with any symmetric preconditioner, and
//! Jacobi-preconditioned BiCGSTAB for the non-symmetric coarse systems.
//!
//! Every solver starts from the `x` it is given (a warm start), stops at a
//! relative residual `‖b − A x‖ / ‖b‖ ≤ tolerance` or after
//! `max_iterations`, and reports the residual of the `x` it returns,
//! recomputed from `b − A x` rather than taken from the recurrence (which
//! drifts in floating point); when the two disagree the solver restarts
//! from the current `x` instead of stopping early.

use std::ops::ControlFlow;

use sprs::CsMat;

use crate::Error;
use crate::matrix::{check_square, check_symmetric, check_vector, inverse_diagonal, mul_vec};
use crate::vector::{axpy, cg_update, dot, norm, scale as diagonal_scale, xpby};

/// When a solver stops, and whether stopping short is an error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveOptions {
    /// Relative residual `‖b − A x‖ / ‖b‖` to reach.
    pub tolerance: f64,
    /// Iterations allowed (one mat-vec each for CG, two for BiCGSTAB).
    pub max_iterations: usize,
    /// Turn a solve that does not reach `tolerance` — the iteration cap,
    /// a breakdown, or stagnation above the tolerance — into
    /// [`Error::NotConverged`] (carrying the [`Report`] with the true
    /// residual of `x`). CG leaves in `x` the best iterate by residual
    /// (finite, never worse than the start), BiCGSTAB the last one or the
    /// start, whichever is better. On by default; turn it
    /// off to take whatever a fixed budget of iterations gives (an
    /// interactive preview) and read [`Report::converged`] yourself. A
    /// monitor's `Break` is never an error.
    pub require_convergence: bool,
}

impl Default for SolveOptions {
    /// `10⁻⁶` in at most 10 000 iterations, non-convergence an error.
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 10_000,
            require_convergence: true,
        }
    }
}

impl SolveOptions {
    /// `tolerance` in at most `max_iterations`, non-convergence an error.
    pub fn new(tolerance: f64, max_iterations: usize) -> Self {
        Self {
            tolerance,
            max_iterations,
            require_convergence: true,
        }
    }

    /// The same options with non-convergence reported in the [`Report`]
    /// only, not as an error.
    pub fn allow_unconverged(self) -> Self {
        Self {
            require_convergence: false,
            ..self
        }
    }

    pub(crate) fn check(&self) -> Result<(), Error> {
        if !(self.tolerance >= 0.0 && self.tolerance.is_finite()) {
            return Err(Error::InvalidOption("tolerance must be finite and ≥ 0"));
        }
        Ok(())
    }

    /// The report, or [`Error::NotConverged`] when convergence is
    /// required and the solve stopped short for a reason of its own.
    pub(crate) fn settle(&self, report: Report) -> Result<Report, Error> {
        match report.stop {
            Stop::MaxIterations | Stop::Breakdown | Stop::Stagnated if self.require_convergence => {
                Err(Error::NotConverged {
                    report,
                    tolerance: self.tolerance,
                })
            }
            _ => Ok(report),
        }
    }
}

/// Why a solver stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// The relative residual reached the tolerance.
    Converged,
    /// The iteration cap came first.
    MaxIterations,
    /// A scalar of the recurrence vanished or stopped being finite (for
    /// CG: the matrix or preconditioner is not positive definite, or a
    /// singular system is inconsistent); `x` is the best finite iterate
    /// (CG), never worse than the start.
    Breakdown,
    /// The monitor asked to stop (a time budget, an outside error target).
    Interrupted,
    /// A restart from the current `x` no longer lowered the true residual:
    /// the accuracy floating point allows is reached above the tolerance.
    Stagnated,
}

/// What a solve did. Read it: with
/// [`SolveOptions::require_convergence`] off, a solve that stopped short is
/// still `Ok`.
#[must_use = "a solve may stop before its tolerance: check `converged()`"]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Report {
    /// Why it stopped.
    pub stop: Stop,
    /// Iterations done.
    pub iterations: usize,
    /// `‖b − A x‖ / ‖b‖` of the returned `x` (`‖b − A x‖` when `b = 0`).
    pub residual: f64,
}

impl Report {
    /// Whether the tolerance was reached.
    pub fn converged(&self) -> bool {
        self.stop == Stop::Converged
    }
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stop::Converged => "converged",
            Stop::MaxIterations => "reached the iteration cap",
            Stop::Breakdown => {
                "broke down (a recurrence scalar vanished or overflowed: for CG, the matrix or preconditioner is likely not positive definite)"
            }
            Stop::Interrupted => "was stopped by its monitor",
            Stop::Stagnated => "stagnated (restarts no longer lowered the residual)",
        })
    }
}

impl std::fmt::Display for Report {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} after {} iterations at relative residual {:.3e}",
            self.stop, self.iterations, self.residual
        )
    }
}

/// A symmetric positive definite approximation of `A⁻¹`, applied as
/// `z ← M⁻¹ r` in [`pcg`].
pub trait Preconditioner: Sync {
    /// `z ← M⁻¹ r`.
    fn apply(&self, r: &[f64], z: &mut [f64]);
}

/// Jacobi: `M = diag(A)`.
#[derive(Debug, Clone)]
pub struct Jacobi {
    inverse: Vec<f64>,
}

impl Jacobi {
    /// # Errors
    /// [`Error::BadDiagonal`] for a zero or negative diagonal entry, and
    /// the checks of [`cg`].
    pub fn new(a: &CsMat<f64>) -> Result<Self, Error> {
        check_square(a)?;
        Ok(Self {
            inverse: inverse_diagonal(a, true)?,
        })
    }
}

impl Preconditioner for Jacobi {
    fn apply(&self, r: &[f64], z: &mut [f64]) {
        diagonal_scale(&self.inverse, r, z);
    }
}

/// Called after every iteration with its number and the current `x`;
/// returning `ControlFlow::Break(())` stops the solver (an interactive
/// application's time budget, a benchmark's error target).
pub type Monitor<'m> = &'m mut dyn FnMut(usize, &[f64]) -> ControlFlow<()>;

pub(crate) fn no_monitor() -> impl FnMut(usize, &[f64]) -> ControlFlow<()> {
    |_, _| ControlFlow::Continue(())
}

/// Jacobi-preconditioned conjugate gradients for a symmetric positive
/// definite `a`, from the start vector `x`.
///
/// # Errors
/// [`Error::NotCsr`], [`Error::NotSquare`], [`Error::DimensionMismatch`],
/// [`Error::NotFiniteEntry`] / [`Error::NotFiniteVector`] for NaN or
/// infinite input, [`Error::BadDiagonal`] for a zero or negative diagonal,
/// [`Error::NotSymmetric`] for a matrix that is not symmetric (use
/// [`bicgstab`]), and [`Error::NotConverged`] when the tolerance is not
/// reached and [`SolveOptions::require_convergence`] is on.
///
/// # Example
/// ```
/// use multires::{cg, grid, SolveOptions};
/// let problem = grid::diffusion([8, 8, 8], 3.0)?;
/// let mut x = vec![0.0; problem.matrix.rows()];
/// let report = cg(&problem.matrix, &problem.rhs, &mut x, &SolveOptions::default())?;
/// assert!(report.converged() && report.residual <= 1e-6);
/// # Ok::<(), multires::Error>(())
/// ```
pub fn cg(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
) -> Result<Report, Error> {
    cg_monitored(a, b, x, options, &mut no_monitor())
}

/// [`cg`] calling `monitor` after every iteration.
///
/// # Errors
/// As [`cg`].
pub fn cg_monitored(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    check_square(a)?;
    check_symmetric(a)?;
    options.settle(jacobi_cg_checked(a, b, x, options, monitor)?)
}

/// [`cg_monitored`] for a matrix already checked by [`check_square`]
/// (scanning every entry for NaN once per solve is enough).
pub(crate) fn jacobi_cg_checked(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    let jacobi = Jacobi {
        inverse: inverse_diagonal(a, true)?,
    };
    pcg_checked(a, b, x, &jacobi, options, monitor)
}

/// Conjugate gradients preconditioned by `m` (symmetric positive definite).
///
/// # Errors
/// As [`cg`], without the diagonal check.
pub fn pcg(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    m: &impl Preconditioner,
    options: &SolveOptions,
) -> Result<Report, Error> {
    pcg_monitored(a, b, x, m, options, &mut no_monitor())
}

/// [`pcg`] calling `monitor` after every iteration.
///
/// # Errors
/// As [`pcg`].
pub fn pcg_monitored(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    m: &(impl Preconditioner + ?Sized),
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    check_square(a)?;
    check_symmetric(a)?;
    options.settle(pcg_checked(a, b, x, m, options, monitor)?)
}

/// [`pcg_monitored`] for a matrix already checked by [`check_square`]
/// (and, where it matters, [`check_symmetric`]); the report is returned
/// whatever the stop (see [`SolveOptions::settle`]).
pub(crate) fn pcg_checked(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    m: &(impl Preconditioner + ?Sized),
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    let n = a.rows();
    check_vector("right-hand side", b, n)?;
    check_vector("start vector", x, n)?;
    options.check()?;
    let scale = nonzero(norm(b));
    let mut r = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut p = vec![0.0; n];
    let mut q = vec![0.0; n];
    let mut done = 0;
    let mut residual = residual_into(a, b, x, &mut r) / scale;
    let mut best = Best::new(x, residual);
    let report = |stop, iterations, residual| Report {
        stop,
        iterations,
        residual,
    };
    while done < options.max_iterations && residual > options.tolerance {
        // One CG run; it ends when its recurrence says converged, then the
        // true residual decides whether to restart.
        m.apply(&r, &mut z);
        let mut rz = dot(&r, &z);
        p.copy_from_slice(&z);
        let mut broke = false;
        let mut interrupted = false;
        while done < options.max_iterations {
            mul_vec(a, &p, &mut q);
            let pq = dot(&p, &q);
            let alpha = rz / pq;
            if !(alpha.is_finite() && pq > 0.0) {
                broke = true;
                break;
            }
            let rr = cg_update(alpha, &p, &q, x, &mut r);
            best.step(x, rr.sqrt() / scale, alpha, &p);
            done += 1;
            if monitor(done, x).is_break() {
                interrupted = true;
                break;
            }
            if rr.sqrt() / scale <= options.tolerance {
                break;
            }
            let rz_next = precondition_dot(m, &r, &mut z);
            let beta = rz_next / rz;
            if !beta.is_finite() {
                broke = true;
                break;
            }
            rz = rz_next;
            xpby(&z, beta, &mut p);
        }
        let before = residual;
        residual = residual_into(a, b, x, &mut r) / scale;
        if broke || !residual.is_finite() {
            let residual = best.restore(a, b, x, &mut r, residual, scale);
            return Ok(report(Stop::Breakdown, done, residual));
        }
        if interrupted {
            return Ok(report(Stop::Interrupted, done, residual));
        }
        if residual > options.tolerance && residual >= before && done < options.max_iterations {
            // A restart that gains nothing would loop: the attainable accuracy is reached.
            let residual = best.restore(a, b, x, &mut r, residual, scale);
            return Ok(report(Stop::Stagnated, done, residual));
        }
        best.restarted(residual);
    }
    if residual <= options.tolerance {
        return Ok(report(Stop::Converged, done, residual));
    }
    let residual = best.restore(a, b, x, &mut r, residual, scale);
    Ok(report(Stop::MaxIterations, done, residual))
}

/// The best iterate of a CG solve by residual, kept so that a solve that
/// breaks down, stagnates or hits its cap returns the best `x` it saw
/// (finite, and never worse than the start) instead of the last one,
/// which on a semidefinite inconsistent system or an indefinite matrix
/// may have grown without bound.
///
/// Copies are rare: `x` is copied only when a step makes it worse than
/// the best so far right after the best (the best is then the previous
/// iterate, `x − α p`), so a monotone run copies nothing but its start.
pub(crate) struct Best {
    /// The start vector, the fallback of last resort.
    start: Vec<f64>,
    start_residual: f64,
    /// The best earlier iterate, when it is not the current `x`.
    saved: Option<(Vec<f64>, f64)>,
    /// The residual of the best iterate so far (the current `x` when
    /// `current_is_best`).
    residual: f64,
    current_is_best: bool,
}

impl Best {
    pub(crate) fn new(x: &[f64], residual: f64) -> Self {
        Self {
            start: x.to_vec(),
            start_residual: residual,
            saved: None,
            residual,
            current_is_best: true,
        }
    }

    /// After `x += α p` gave the recurrence residual `residual`.
    pub(crate) fn step(&mut self, x: &[f64], residual: f64, alpha: f64, p: &[f64]) {
        self.step_by(x, residual, |i, x| x - alpha * p[i]);
    }

    /// [`step`](Self::step) with the previous iterate's entry `i` given by
    /// `previous(i, x[i])` (a block solver's `p` is interleaved).
    pub(crate) fn step_by(
        &mut self,
        x: &[f64],
        residual: f64,
        previous: impl Fn(usize, f64) -> f64,
    ) {
        if residual < self.residual {
            self.residual = residual;
            self.current_is_best = true;
        } else if self.current_is_best {
            // The previous iterate was the best: keep it.
            let previous = match self.saved.take() {
                Some((mut v, _)) => {
                    v.iter_mut()
                        .zip(x)
                        .enumerate()
                        .for_each(|(i, (v, &x))| *v = previous(i, x));
                    v
                }
                None => x.iter().enumerate().map(|(i, &x)| previous(i, x)).collect(),
            };
            self.saved = Some((previous, self.residual));
            self.current_is_best = false;
        }
    }

    /// After a restart recomputed the true residual of `x` (which
    /// replaces the recurrence's when `x` was the best).
    pub(crate) fn restarted(&mut self, residual: f64) {
        if self.current_is_best || residual < self.residual {
            self.residual = residual;
            self.current_is_best = true;
        }
    }

    /// Puts the best of the current `x` (true residual `residual`), the
    /// saved iterate and the start into `x`, and returns its true
    /// residual (`r` is scratch).
    fn restore(
        self,
        a: &CsMat<f64>,
        b: &[f64],
        x: &mut [f64],
        r: &mut [f64],
        residual: f64,
        scale: f64,
    ) -> f64 {
        self.restore_with(x, residual, |saved| residual_into(a, b, saved, r) / scale)
    }

    /// [`restore`](Self::restore) with the relative residual of an
    /// iterate given by `residual_of`.
    pub(crate) fn restore_with(
        self,
        x: &mut [f64],
        residual: f64,
        mut residual_of: impl FnMut(&[f64]) -> f64,
    ) -> f64 {
        let mut chosen = if residual.is_finite() {
            residual
        } else {
            f64::INFINITY
        };
        if let Some((saved, _)) = self.saved {
            let saved_residual = residual_of(&saved);
            if saved_residual < chosen {
                x.copy_from_slice(&saved);
                chosen = saved_residual;
            }
        }
        if chosen > self.start_residual {
            x.copy_from_slice(&self.start);
            chosen = self.start_residual;
        }
        chosen
    }
}

/// `z ← M⁻¹ r`, returning `r · z`.
fn precondition_dot(m: &(impl Preconditioner + ?Sized), r: &[f64], z: &mut [f64]) -> f64 {
    m.apply(r, z);
    dot(r, z)
}

/// Jacobi-preconditioned BiCGSTAB (van der Vorst 1992, right
/// preconditioning) for a general non-singular `a`, from the start vector
/// `x`. Each iteration costs two mat-vecs.
///
/// # Errors
/// As [`cg`], with [`Error::BadDiagonal`] only for a zero diagonal entry
/// and no symmetry required.
pub fn bicgstab(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
) -> Result<Report, Error> {
    bicgstab_monitored(a, b, x, options, &mut no_monitor())
}

/// [`bicgstab`] calling `monitor` after every iteration.
///
/// # Errors
/// As [`bicgstab`].
pub fn bicgstab_monitored(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    check_square(a)?;
    options.settle(bicgstab_checked(a, b, x, options, monitor)?)
}

/// [`bicgstab_monitored`] for a matrix already checked by [`check_square`];
/// the report is returned whatever the stop.
pub(crate) fn bicgstab_checked(
    a: &CsMat<f64>,
    b: &[f64],
    x: &mut [f64],
    options: &SolveOptions,
    monitor: Monitor<'_>,
) -> Result<Report, Error> {
    let n = a.rows();
    check_vector("right-hand side", b, n)?;
    check_vector("start vector", x, n)?;
    options.check()?;
    let inverse = inverse_diagonal(a, false)?;
    let scale = nonzero(norm(b));
    let mut r = vec![0.0; n];
    let mut done = 0;
    let mut residual = residual_into(a, b, x, &mut r) / scale;
    // The start, put back if the solve ends worse than it began.
    let (start, start_residual) = (x.to_vec(), residual);
    let settle = |x: &mut [f64], stop: Stop, iterations: usize, residual: f64| {
        let worse = residual.is_nan() || residual > start_residual;
        if worse && stop != Stop::Converged && stop != Stop::Interrupted {
            x.copy_from_slice(&start);
        }
        Report {
            stop,
            iterations,
            residual: if worse && stop != Stop::Interrupted {
                start_residual
            } else {
                residual
            },
        }
    };
    let (mut p, mut v, mut y, mut s, mut z, mut t) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    while done < options.max_iterations && residual > options.tolerance {
        let shadow = r.clone();
        let (mut rho, mut alpha, mut omega) = (1.0, 1.0, 1.0);
        p.fill(0.0);
        v.fill(0.0);
        let mut broke = false;
        let mut interrupted = false;
        while done < options.max_iterations {
            let rho_next = dot(&shadow, &r);
            let beta = (rho_next / rho) * (alpha / omega);
            if rho_next == 0.0 || !beta.is_finite() {
                broke = true;
                break;
            }
            rho = rho_next;
            // p ← r + β (p − ω v)
            axpy(-omega, &v, &mut p);
            xpby(&r, beta, &mut p);
            diagonal_scale(&inverse, &p, &mut y);
            mul_vec(a, &y, &mut v);
            alpha = rho / dot(&shadow, &v);
            if !alpha.is_finite() {
                broke = true;
                break;
            }
            s.copy_from_slice(&r);
            axpy(-alpha, &v, &mut s);
            done += 1;
            if norm(&s) / scale <= options.tolerance {
                axpy(alpha, &y, x);
                interrupted = monitor(done, x).is_break();
                break;
            }
            diagonal_scale(&inverse, &s, &mut z);
            mul_vec(a, &z, &mut t);
            let tt = dot(&t, &t);
            omega = dot(&t, &s) / tt;
            if !(omega.is_finite() && omega != 0.0) {
                broke = true;
                break;
            }
            axpy(alpha, &y, x);
            axpy(omega, &z, x);
            r.copy_from_slice(&s);
            axpy(-omega, &t, &mut r);
            if monitor(done, x).is_break() {
                interrupted = true;
                break;
            }
            if norm(&r) / scale <= options.tolerance {
                break;
            }
        }
        let before = residual;
        residual = residual_into(a, b, x, &mut r) / scale;
        if !residual.is_finite() {
            return Ok(settle(x, Stop::Breakdown, done, residual));
        }
        if residual <= options.tolerance {
            break;
        }
        if interrupted {
            return Ok(settle(x, Stop::Interrupted, done, residual));
        }
        if broke && residual >= before {
            return Ok(settle(x, Stop::Breakdown, done, residual));
        }
        if !broke && residual >= before && done < options.max_iterations {
            return Ok(settle(x, Stop::Stagnated, done, residual));
        }
    }
    let stop = if residual <= options.tolerance {
        Stop::Converged
    } else {
        Stop::MaxIterations
    };
    Ok(settle(x, stop, done, residual))
}

/// `r ← b − A x`, returning `‖r‖`.
pub(crate) fn residual_into(a: &CsMat<f64>, b: &[f64], x: &[f64], r: &mut [f64]) -> f64 {
    mul_vec(a, x, r);
    xpby(b, -1.0, r);
    norm(r)
}

/// `‖b‖`, or 1 for `b = 0` (then the residual is absolute).
pub(crate) fn nonzero(v: f64) -> f64 {
    if v > 0.0 { v } else { 1.0 }
}
