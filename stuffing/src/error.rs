//! The crate's one error type.

/// Why a surface could not be turned into tetrahedra.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The triangle list is empty.
    #[error("the surface has no triangles: there is nothing to fill")]
    NoTriangles,
    /// A vertex used by a triangle has a NaN or infinite coordinate.
    #[error("vertex {vertex} has a NaN or infinite coordinate")]
    NonFinitePosition {
        /// Index into the position slice.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {index}, but there are only {vertices} vertices")]
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of positions given.
        vertices: usize,
    },
    /// The lattice spacing is zero, negative, NaN or infinite.
    #[error("the lattice spacing h = {h} is not a positive finite length")]
    InvalidSpacing {
        /// The spacing given.
        h: f64,
    },
    /// The winding-number accuracy parameter is out of range.
    #[error("the winding-number accuracy beta = {beta} must be finite and at least 1")]
    InvalidBeta {
        /// The value given.
        beta: f64,
    },
    /// The lattice at this spacing would exceed the memory bound.
    #[error(
        "a lattice of spacing h = {h:e} over this surface needs {} vertices, more than the \
         limit of {limit} (about {limit_mib} MiB); choose a larger h",
        count(*vertices)
    )]
    LatticeTooLarge {
        /// The spacing given.
        h: f64,
        /// Lattice vertices that spacing needs (`u128::MAX`: beyond 10^36).
        vertices: u128,
        /// The limit ([`super::Options::max_lattice_vertices`]).
        limit: usize,
        /// The limit's approximate memory, in MiB.
        limit_mib: usize,
    },
    /// The mesh at this spacing would have more tetrahedra than the bound.
    #[error(
        "at spacing h = {h:e} the mesh would have about {estimated} tetrahedra, more than the \
         limit of {limit}; choose a larger h (or a graded mesh with a raised limit)"
    )]
    TooManyTetrahedra {
        /// The spacing given.
        h: f64,
        /// Tetrahedra of the uniform mesh (6 per inside lattice vertex).
        estimated: u128,
        /// The limit ([`super::Options::max_tets`]).
        limit: usize,
    },
    /// No lattice vertex lies inside the surface at this spacing, though
    /// some of its triangles bound a volume: the volume is thinner than
    /// the lattice (a smaller `h` holds it).
    #[error(
        "the surface encloses no volume at h = {h} (winding number above 1/2 at no lattice \
         vertex): it is thinner than h"
    )]
    EmptyVolume {
        /// The spacing used.
        h: f64,
    },
    /// No triangle of the surface bounds a volume: the winding number is on
    /// the same side of 1/2 in front of and behind every one (an open
    /// sheet, a single triangle, a doubled wall), so no spacing gives
    /// tetrahedra.
    #[error(
        "the surface encloses no volume: none of its {triangles} triangles bounds one (the \
         winding number is on the same side of 1/2 in front of and behind each: an open sheet \
         or a doubled wall); no spacing changes that, close the surface or give it thickness"
    )]
    OpenSurface {
        /// Number of triangles given.
        triangles: usize,
    },
    /// The envelope ([`super::Options::envelope`]) is not a fraction of
    /// the diagonal strictly between 0 and 1.
    #[error("the envelope {eps} must be a fraction of the bounding-box diagonal between 0 and 1")]
    InvalidEnvelope {
        /// The value given.
        eps: f64,
    },
    /// A grading option is out of range.
    #[error("the graded lattice's {what} is out of range: {value}")]
    InvalidGrading {
        /// Which setting.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The second surface of [`crate::surface_distance`] (the boundary
    /// measured against the input) is not a valid triangle soup.
    #[error("the boundary surface: {0}")]
    InBoundary(Box<Error>),
}

/// A vertex count for a message: "more than 10^36" for the saturated one.
fn count(n: u128) -> String {
    if n == u128::MAX {
        "more than 10^36".to_string()
    } else {
        n.to_string()
    }
}
