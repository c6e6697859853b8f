//! The crate's one error type.

/// What is wrong with a solver's or a hierarchy's input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// The matrix is stored column-major; the solvers read rows.
    #[error("the matrix is stored as CSC; convert it with `to_csr()`")]
    NotCsr,
    /// A linear system needs a square matrix.
    #[error("the matrix is {rows}×{cols}, not square")]
    NotSquare {
        /// Rows of the matrix.
        rows: usize,
        /// Columns of the matrix.
        cols: usize,
    },
    /// A vector (right-hand side, start vector, positions) has the wrong length.
    #[error("the {what} has {found} entries, the matrix has {expected} rows")]
    DimensionMismatch {
        /// Which input.
        what: &'static str,
        /// The matrix's size.
        expected: usize,
        /// The input's length.
        found: usize,
    },
    /// A matrix entry is NaN or infinite.
    #[error("matrix entry ({row}, {col}) is {value}")]
    NotFiniteEntry {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The entry.
        value: f64,
    },
    /// A vector entry is NaN or infinite.
    #[error("entry {index} of the {what} is {value}")]
    NotFiniteVector {
        /// Which input.
        what: &'static str,
        /// Index of the entry.
        index: usize,
        /// The entry.
        value: f64,
    },
    /// Jacobi preconditioning divides by the diagonal; CG also needs it
    /// positive (a symmetric positive definite matrix has a positive
    /// diagonal).
    #[error("diagonal entry {row} is {value}: {need}")]
    BadDiagonal {
        /// Row of the diagonal entry (0 when it is not stored).
        row: usize,
        /// The entry.
        value: f64,
        /// What the solver needs of it.
        need: &'static str,
    },
    /// Interpolation weights must be positive and finite.
    #[error("interpolation weight between vertices {i} and {j} is {value}")]
    BadWeight {
        /// One end of the edge (index in the original system).
        i: usize,
        /// The other end.
        j: usize,
        /// The weight (with positions: 1 / distance).
        value: f64,
    },
    /// Option values out of their range.
    #[error("invalid option: {0}")]
    InvalidOption(&'static str),
    /// The coarsest V-cycle operator could not be factored.
    #[error(
        "the coarsest operator ({size} unknowns) is not positive definite (pivot {pivot} is {value})"
    )]
    NotPositiveDefinite {
        /// Unknowns at the coarsest level.
        size: usize,
        /// Where the Cholesky factorisation failed.
        pivot: usize,
        /// The failing pivot.
        value: f64,
    },
    /// Indices are stored in 32 bits in the hierarchy.
    #[error("{0} unknowns is more than the hierarchy's 32-bit indices allow")]
    TooLarge(usize),
}
