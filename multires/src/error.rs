//! The crate's one error type.

/// What is wrong with a solver's or a hierarchy's input, or why a solve
/// did not deliver.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
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
    /// CG (and the V-cycle and cascade, which end in CG) need a symmetric
    /// matrix.
    #[error(
        "CG needs a symmetric matrix, but entry ({row}, {col}) is {value} and entry ({col}, {row}) is {transposed}; solve non-symmetric systems with bicgstab"
    )]
    NotSymmetric {
        /// Row of the first entry found without its mirror.
        row: usize,
        /// Its column.
        col: usize,
        /// `a[row][col]`.
        value: f64,
        /// `a[col][row]` (0 when not stored).
        transposed: f64,
    },
    /// The solve stopped before reaching its tolerance (iteration cap,
    /// breakdown or stagnation) while [`crate::SolveOptions::require_convergence`]
    /// was on. `x` holds the last iterate, whose true residual the report
    /// gives.
    #[error("the solve did not converge to the tolerance {tolerance:e}: it {report}")]
    NotConverged {
        /// What the solve did, with the residual of the returned `x`.
        report: crate::Report,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// The cascade's final CG stopped before reaching its tolerance while
    /// [`crate::SolveOptions::require_convergence`] was on.
    #[error("the cascade did not converge to the tolerance {tolerance:e}: its final CG {}", report.finest)]
    CascadeNotConverged {
        /// What every level did; `report.finest` has the true residual.
        report: Box<crate::CascadeReport>,
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// A [`crate::Block3`]'s matrices must share one sparsity pattern.
    #[error("matrix {channel} of the block stores other entries than matrix 0 in row {row}")]
    PatternMismatch {
        /// Which matrix (0-based) differs from the first.
        channel: usize,
        /// The first row that differs (the smaller size when the sizes do).
        row: usize,
    },
    /// A matrix of a [`crate::Block3`] has another size than the first.
    #[error("matrix {channel} of the block has {rows} rows, matrix 0 has {expected}")]
    BlockSize {
        /// Which matrix (0-based).
        channel: usize,
        /// Its rows.
        rows: usize,
        /// Matrix 0's rows.
        expected: usize,
    },
    /// What is wrong with one matrix of a [`crate::Block3`].
    #[error("matrix {channel} of the block: {error}")]
    InMatrix {
        /// Which matrix (0-based).
        channel: usize,
        /// The error of that matrix alone.
        error: Box<Error>,
    },
    /// A channel of a block solve stopped before reaching its tolerance
    /// while [`crate::SolveOptions::require_convergence`] was on.
    #[error("channel {channel} did not converge to the tolerance {tolerance:e}: it {}", reports[*channel])]
    ChannelNotConverged {
        /// The first channel that stopped short.
        channel: usize,
        /// Every channel's report (the true residual of its `x`).
        reports: [crate::Report; 3],
        /// The tolerance asked for.
        tolerance: f64,
    },
    /// A Matrix Market file could not be read.
    #[error("{}:{line}: {message}", path.display())]
    MatrixMarket {
        /// The file.
        path: std::path::PathBuf,
        /// 1-based line of the problem (0: the file as a whole).
        line: usize,
        /// What is wrong.
        message: String,
    },
}
