//! The one error type of this crate.

/// Why a distribution could not be built.
///
/// Every constructor validates its whole input and names the first offending
/// entry, so a caller can point at the texel, light or triangle that is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The weight slice is empty: there is nothing to choose from.
    #[error("no weights: a distribution needs at least one entry")]
    Empty,
    /// A weight is NaN.
    #[error("weight {index} is NaN")]
    NaN {
        /// Position of the first NaN weight.
        index: usize,
    },
    /// A weight is +∞ or −∞.
    #[error("weight {index} is infinite ({value})")]
    Infinite {
        /// Position of the first infinite weight.
        index: usize,
        /// The weight itself.
        value: f64,
    },
    /// A weight is below zero.
    #[error("weight {index} is negative ({value}); weights must be >= 0")]
    Negative {
        /// Position of the first negative weight.
        index: usize,
        /// The weight itself.
        value: f64,
    },
    /// Every weight is zero, so no entry can be drawn.
    #[error("all {len} weights are zero: there is nothing to sample")]
    AllZero {
        /// Number of weights given.
        len: usize,
    },
    /// Each weight is finite but their sum overflows `f64`.
    #[error("the weights sum to infinity in f64; scale them down")]
    TotalOverflow,
    /// More entries than the `u32` indices of the tables can address.
    #[error("{len} entries is more than the {max} this sampler can index")]
    TooManyEntries {
        /// Number of weights given.
        len: usize,
        /// The largest supported number of entries.
        max: usize,
    },
    /// The weights of a 2D distribution do not fill `width × height`.
    #[error("a {width}×{height} distribution needs {expected} weights, got {len}")]
    DimensionMismatch {
        /// Requested width (columns).
        width: usize,
        /// Requested height (rows).
        height: usize,
        /// `width * height`, or `usize::MAX` when that overflows.
        expected: usize,
        /// Number of weights given.
        len: usize,
    },
    /// The lookup-table ratio is not in `(0, 1024]`.
    #[error("table ratio {ratio} is invalid: it must be above 0 and at most 1024")]
    InvalidRatio {
        /// The ratio given.
        ratio: f64,
    },
}
