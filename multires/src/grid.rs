//! Test systems that need no mesh: the 7-point graph Laplacian plus a
//! mass term on a 3D grid, the finite-difference diffusion equation
//! `−κ∇²φ + μφ = q` with κ = 1 and unit spacing.

use sprs::CsMat;

use crate::Error;
use crate::matrix::assemble;

/// A linear system with the positions of its unknowns.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The symmetric positive definite matrix.
    pub matrix: CsMat<f64>,
    /// The right-hand side.
    pub rhs: Vec<f64>,
    /// The grid point of each unknown.
    pub positions: Vec<[f64; 3]>,
}

/// The diffusion system on an `n[0] × n[1] × n[2]` grid whose diffusion
/// length `√(κ/μ)` is `length` cells: `A = L + I / length²` with `L` the
/// graph Laplacian (degree on the diagonal, −1 per neighbour; no-flux
/// boundaries), lit from one side: `b = 1` on the face `x = 0`, 0
/// elsewhere. Unknown `(x, y, z)` has index `x + n₀ (y + n₁ z)`.
///
/// # Errors
/// [`Error::InvalidOption`] for a dimension of 0, a length that is not
/// positive and finite, or more than 2³² unknowns.
pub fn diffusion(n: [usize; 3], length: f64) -> Result<Problem, Error> {
    if n.contains(&0) {
        return Err(Error::InvalidOption("grid dimensions must be at least 1"));
    }
    if !(length > 0.0 && length.is_finite()) {
        return Err(Error::InvalidOption(
            "diffusion length must be positive and finite",
        ));
    }
    let total = n.iter().try_fold(1usize, |a, &d| a.checked_mul(d));
    if total.is_none_or(|t| t > u32::MAX as usize) {
        return Err(Error::InvalidOption("grid larger than 2³² unknowns"));
    }
    let total = n[0] * n[1] * n[2];
    let mass = 1.0 / (length * length);
    let coords = |i: usize| [i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1])];
    let stride = [1, n[0], n[0] * n[1]];
    let matrix = assemble(total, total, |i, out| {
        let c = coords(i);
        let mut degree = 0.0;
        for axis in 0..3 {
            if c[axis] > 0 {
                out.push((i - stride[axis], -1.0));
                degree += 1.0;
            }
            if c[axis] + 1 < n[axis] {
                out.push((i + stride[axis], -1.0));
                degree += 1.0;
            }
        }
        out.push((i, degree + mass));
    });
    let rhs = (0..total)
        .map(|i| if coords(i)[0] == 0 { 1.0 } else { 0.0 })
        .collect();
    let positions = (0..total).map(|i| coords(i).map(|c| c as f64)).collect();
    Ok(Problem {
        matrix,
        rhs,
        positions,
    })
}

/// A grid of about `unknowns` points, as cubic as possible.
pub fn cube_for(unknowns: usize) -> [usize; 3] {
    let side = (unknowns as f64).cbrt().round().max(1.0) as usize;
    [side, side, side]
}
