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
    #[error(
        "a point rate (points per unit area, or per unit mass of a density) must be finite and >= 0, got {0}"
    )]
    InvalidDensity(f64),
    /// The mesh has more triangles than a sampler can index.
    #[error("{0} triangles is more than a sampler can index")]
    TooLarge(usize),
    /// A density texture of width or height 0.
    #[error("the density texture is {width}×{height}: it has no texels")]
    EmptyTexture {
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// A texture whose `width × height` overflows `usize`.
    #[error("the density texture is {width}×{height}: more texels than can be indexed")]
    TextureTooLarge {
        /// Its width.
        width: usize,
        /// Its height.
        height: usize,
    },
    /// The texel data does not match the texture size.
    #[error("the density texture needs {expected} values, got {len}")]
    TextureSize {
        /// Values needed.
        expected: usize,
        /// Values given.
        len: usize,
    },
    /// A texel that is negative, NaN or infinite.
    #[error("density texel ({x}, {y}) is {value}: densities must be finite and >= 0")]
    InvalidTexel {
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// The value.
        value: f32,
    },
    /// A channel the pixels do not have.
    #[error("channel {channel:?} asked of {channels}-channel pixels")]
    InvalidChannel {
        /// The channel asked for.
        channel: crate::Channel,
        /// Channels per pixel.
        channels: usize,
    },
    /// A texture density asked of a mesh without texture coordinates.
    #[error("a texture density needs texture coordinates, and the mesh has none")]
    MissingUvs,
    /// A texture coordinate that is NaN or infinite.
    #[error("vertex {vertex} has a non-finite texture coordinate")]
    NonFiniteUv {
        /// The vertex.
        vertex: usize,
    },
    /// Per-face or per-vertex weights of the wrong length.
    #[error("{what} weights: {len} given for {expected} {}", plural(.what))]
    WeightLength {
        /// "face" or "vertex".
        what: &'static str,
        /// Weights given.
        len: usize,
        /// Faces or vertices of the mesh.
        expected: usize,
    },
    /// A per-face or per-vertex weight that is negative, NaN or infinite.
    #[error("{what} {index} has weight {value}: weights must be finite and >= 0")]
    InvalidWeight {
        /// "face" or "vertex".
        what: &'static str,
        /// Its index.
        index: usize,
        /// The weight.
        value: f32,
    },
    /// The density is zero on the whole mesh.
    #[error(
        "the density is zero everywhere on the mesh ({triangles} triangles): nothing to sample"
    )]
    ZeroDensity {
        /// The number of triangles.
        triangles: usize,
    },
    /// A subdivision option out of range.
    #[error("invalid option: {0}")]
    InvalidOption(String),
    /// Even one piece per triangle exceeds the piece budget.
    #[error(
        "the density needs at least {needed} pieces, more than the budget of {budget} \
         (Options::max_pieces)"
    )]
    TooManyPieces {
        /// Pieces needed at the coarsest subdivision.
        needed: u128,
        /// The budget.
        budget: usize,
    },
    /// A call would return more points than [`MAX_POINTS`](crate::MAX_POINTS).
    #[error(
        "{} points is too large a count: at most {budget} points are returned at \
         once (use sample_stream for more, or a lower rate)", count(.requested)
    )]
    TooManyPoints {
        /// The number of points asked for (or an upper bound of it).
        requested: f64,
        /// The budget, [`MAX_POINTS`](crate::MAX_POINTS).
        budget: usize,
    },
    /// The exact integral of the density over the mesh would visit too
    /// many texel cells (UV footprints that tile a varying texture many
    /// times).
    #[error(
        "integrating the density exactly over the mesh would visit {cells} texel cells, more \
         than the budget of {budget}: its UVs tile the texture too many times for the exact \
         mode or rejection sampling (use the approximate mode)"
    )]
    IntegrationTooLarge {
        /// Cells to visit.
        cells: f64,
        /// The budget, [`MAX_INTEGRATION_CELLS`](crate::MAX_INTEGRATION_CELLS).
        budget: u64,
    },
    /// A rejection sampler would accept too few of its proposals to
    /// finish in reasonable time.
    #[error(
        "the sampler would accept only {acceptance:e} of its proposals, below the minimum of \
         {minimum:e}: the density's maximum is too far above its mean on this mesh (use the \
         approximate mode)"
    )]
    AcceptanceTooLow {
        /// The expected fraction of proposals accepted.
        acceptance: f64,
        /// The minimum, [`MIN_ACCEPTANCE`](crate::MIN_ACCEPTANCE).
        minimum: f64,
    },
    /// An emitter's emission is zero on the whole mesh.
    #[error("the emission is zero everywhere on the mesh ({triangles} triangles): nothing emits")]
    NoEmission {
        /// The number of triangles.
        triangles: usize,
    },
    /// A triangle asked to be sampled alone has no area or emits nothing.
    #[error("triangle {face} has no area or no emission: there is nothing to sample in it")]
    DarkTriangle {
        /// The triangle.
        face: usize,
    },
    /// An emission scale that is negative, NaN or infinite.
    #[error("the emission scale is {0}: it must be finite and >= 0")]
    InvalidScale(f32),
    /// Per-face radiance of the wrong length.
    #[error("per-face radiance: {len} given for {expected} faces")]
    RadianceLength {
        /// Radiances given.
        len: usize,
        /// Faces of the mesh.
        expected: usize,
    },
    /// An emission texel with a channel that is negative, NaN or infinite.
    #[error(
        "emission texel ({x}, {y}) has {} = {value}: radiance must be finite and >= 0",
        ["R", "G", "B"][*.channel]
    )]
    InvalidRadianceTexel {
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// The channel: 0, 1 or 2 for R, G, B.
        channel: usize,
        /// The value.
        value: f32,
    },
    /// A per-face radiance channel that is negative, NaN or infinite.
    #[error("face {face} has a radiance channel of {value}: radiance must be finite and >= 0")]
    InvalidRadiance {
        /// The face.
        face: usize,
        /// The channel's value.
        value: f32,
    },
    /// A hair strand parameter that is NaN or out of range.
    #[error("root {root}: strand {parameter} is {value}, but it must be {expected}")]
    InvalidStrandParameter {
        /// The root (index into the roots given).
        root: usize,
        /// The [`StrandParams`](crate::StrandParams) field.
        parameter: &'static str,
        /// Its value.
        value: f32,
        /// What it must be.
        expected: &'static str,
    },
    /// A hair root a strand cannot grow from.
    #[error("root {root} cannot grow a strand: {reason}")]
    InvalidRoot {
        /// The root (index into the roots given).
        root: usize,
        /// Why.
        reason: &'static str,
    },
    /// A scatter's ceiling that is negative, NaN or infinite.
    #[error("max_density must be finite and >= 0, got {0}")]
    InvalidMaxDensity(f64),
    /// A scatter's density outside `[0, max_density]` (or NaN) on a face.
    #[error(
        "the density on face {face} is {value}, outside [0, max_density = {max}]: raise \
         max_density, or clamp to it"
    )]
    DensityOutOfRange {
        /// The face.
        face: usize,
        /// The density found there (the face's largest weight, or the
        /// value at a candidate point).
        value: f64,
        /// The ceiling, `max_density`.
        max: f64,
    },
    /// A triangle index that does not exist.
    #[error("there is no triangle {face}: the mesh has {count}")]
    NoSuchFace {
        /// The index given.
        face: usize,
        /// The number of triangles.
        count: usize,
    },
}

/// The plural of "face" or "vertex", for messages.
fn plural(what: &str) -> &str {
    match what {
        "vertex" => "vertices",
        "face" => "faces",
        other => other,
    }
}

/// A count that may be an upper bound computed in `f64`: the integer when
/// `f64` holds it exactly, else about so much.
fn count(n: &f64) -> String {
    let n = *n;
    if n.is_finite() && n.abs() < 2f64.powi(53) {
        format!("{n:.0}")
    } else {
        format!("about {n:.3e}")
    }
}
