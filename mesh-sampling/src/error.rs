//! The one error type of this crate.

/// Why a sampler could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh has no triangles.
    #[error("the mesh has no triangles")]
    Empty,
    /// A triangle references a vertex that does not exist.
    #[error("triangle {triangle} references vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index it names.
        vertex: u32,
        /// The number of vertices.
        count: usize,
    },
    /// A vertex position is NaN or infinite.
    #[error("vertex {vertex} has a non-finite position")]
    NonFinitePosition {
        /// The vertex.
        vertex: usize,
    },
    /// A per-vertex attribute array does not match the positions.
    #[error("{attribute} has {len} entries for {count} vertices")]
    AttributeLength {
        /// "normals" or "uvs".
        attribute: &'static str,
        /// Its length.
        len: usize,
        /// The number of vertices.
        count: usize,
    },
    /// Every triangle has zero area (or zero weight): nothing to sample.
    #[error("the mesh has no area to sample ({triangles} triangles, all degenerate or weightless)")]
    NoArea {
        /// The number of triangles.
        triangles: usize,
    },
    /// One mesh of several is invalid.
    #[error("mesh {index}: {error}")]
    InMesh {
        /// Which mesh.
        index: usize,
        /// What is wrong with it.
        error: Box<Error>,
    },
    /// A mesh index that does not exist.
    #[error("there is no mesh {index} (there are {count})")]
    NoSuchMesh {
        /// The index given.
        index: usize,
        /// The number of meshes.
        count: usize,
    },
    /// A point density that is negative, NaN or infinite.
    #[error("points per unit area must be finite and >= 0, got {0}")]
    InvalidDensity(f64),
    /// The mesh has more triangles than a sampler can index.
    #[error("{0} triangles is more than a sampler can index")]
    TooLarge(usize),
}
