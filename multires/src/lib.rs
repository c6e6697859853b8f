//! Sparse linear solvers for diffusion-type systems: Jacobi-preconditioned
//! CG and BiCGSTAB on [`sprs`] CSR matrices, and the parallel
//! multi-resolution solver of TransCut (Li et al., *TransCut: Interactive
//! Rendering of Translucent Cutouts*, Sec. 4) — a graph hierarchy built
//! from scratch in parallel whenever the matrix changes (after every cut),
//! then solved coarse to fine.
//!
//! - [`cg`], [`bicgstab`], [`pcg`]: warm start, relative-residual
//!   tolerance, iteration cap, and a [`Report`] that says whether they
//!   converged, in how many iterations, with the true final residual.
//!   Stopping short of the tolerance is an [`Error::NotConverged`]
//!   carrying that report unless [`SolveOptions::require_convergence`] is
//!   turned off; CG refuses non-symmetric matrices
//!   ([`Error::NotSymmetric`]).
//!   Mat-vecs and vector operations run in parallel with results that do
//!   not depend on the number of threads.
//! - [`Hierarchy`] (Sec. 4.1): per-vertex 32-bit codes (hashed random
//!   high bits, the index in the low bits); rounds of independent-set
//!   selection where a vertex whose code is below its candidate
//!   neighbours' is kept; the enhancement that re-inserts vertices until
//!   every edge between two dropped vertices has a kept common neighbour;
//!   coarse edges between kept vertices two rings apart, sorted and
//!   deduplicated; the interpolation of Eq. 16,
//!   `φ^l_i = Σ_{j∈R(i)} λ_ij φ^{l+1}_j / λ_i` with `λ_ij = 1/|x_i − x_j|`
//!   or caller-given weights.
//! - [`coarse`] (Sec. 4.2): Eq. 17's coarse systems `S M P`, `S b`, and
//!   the Galerkin operator `Pᵀ M P`.
//! - [`Cascade`]: the paper's solve — coarsest level by BiCGSTAB to
//!   convergence (falling back to the next finer level if it does not
//!   converge), a few BiCGSTAB iterations per intermediate level, CG on
//!   the original system. [`CascadeOptions::galerkin`] is the faster
//!   variant for absorbing media: Galerkin coarse systems and
//!   interpolation that reproduces linear functions (beyond the paper).
//! - [`VCycle`] (beyond the paper, which notes its interpolation could
//!   drive a full multigrid solver): a symmetric V-cycle (Galerkin coarse
//!   operators, damped Jacobi, exact coarsest solve) preconditioning CG.
//! - [`grid`]: the 7-point diffusion system on 3D grids, for tests and
//!   benchmarks.
//! - [`mtx`]: Matrix Market files, read and written.
//!
//! # Example
//! ```
//! use multires::{cg, grid, SolveOptions, VCycle, VCycleOptions, Weights};
//! let p = grid::diffusion([20, 20, 20], 6.0)?;
//! let options = SolveOptions::new(1e-8, 1_000);
//!
//! let mut plain = vec![0.0; p.rhs.len()];
//! let jacobi = cg(&p.matrix, &p.rhs, &mut plain, &options)?;
//!
//! let v = VCycle::new(&p.matrix, Weights::Positions(&p.positions), &VCycleOptions::default())?;
//! let mut x = vec![0.0; p.rhs.len()];
//! let multigrid = v.solve(&p.rhs, &mut x, &options)?;
//! assert!(multigrid.converged() && multigrid.iterations < jacobi.iterations);
//! # Ok::<(), multires::Error>(())
//! ```

// Each public item has one path: the solvers and their types from the
// root, the function families (`coarse`, `grid`, `matrix`, `mtx`) from
// their modules, the traits also from `prelude`.
mod block;
mod cascade;
pub mod coarse;
mod dense;
mod error;
mod graph;
pub mod grid;
mod hierarchy;
mod krylov;
mod lanczos;
pub mod matrix;
pub mod mtx;
mod vcycle;
mod vector;

/// The README's examples, compiled as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

pub use block::{Block3, BlockMonitor, CHANNELS, Progress};
pub use cascade::{Cascade, CascadeOptions, CascadeReport, CoarseSystem};
pub use error::Error;
pub use graph::Graph;
pub use hierarchy::{Coarsening, Hierarchy, HierarchyOptions, PositionList, Weights};
pub use krylov::{
    Jacobi, Monitor, Preconditioner, Report, SolveOptions, Stop, bicgstab, bicgstab_monitored, cg,
    cg_monitored, pcg, pcg_monitored,
};
pub use lanczos::Lanczos;
/// The `sprs` whose `CsMat` this crate's API takes, re-exported so that
/// callers build matrices with the same version.
pub use sprs;
pub use vcycle::{VCycle, VCycleOptions};

/// The traits a caller implements or calls through, to import at once:
/// `use multires::prelude::*;` (a [`Preconditioner`] of one's own, or
/// `apply` on [`Jacobi`] and [`VCycle`]; a [`PositionList`] over one's own
/// position buffer).
pub mod prelude {
    pub use crate::{PositionList, Preconditioner};
}
