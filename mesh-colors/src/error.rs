//! The one error type of this crate.

/// Why mesh colours could not be built, edited, converted or read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A face resolution is not a power of two or is above the cap.
    #[error(
        "face {face}: resolution {resolution} is not a power of two in 1..={max}",
        max = 1u32 << crate::MAX_LEVEL
    )]
    BadResolution {
        /// The face.
        face: usize,
        /// The resolution asked for.
        resolution: u64,
    },
    /// A face names a vertex that does not exist.
    #[error("face {face} references vertex {vertex}, but there are only {count} vertices")]
    MissingVertex {
        /// The face.
        face: usize,
        /// The vertex index it names.
        vertex: u32,
        /// The number of vertices.
        count: usize,
    },
    /// A face uses the same vertex twice, so it has no area to colour.
    #[error("face {face} repeats vertex {vertex}")]
    DegenerateFace {
        /// The face.
        face: usize,
        /// The repeated vertex.
        vertex: u32,
    },
    /// More than two faces share an edge. Mesh colours need each edge to
    /// have one or two sides; split such an edge (duplicate its vertices
    /// for the extra faces) before colouring.
    #[error("edge ({a}, {b}) is shared by faces {faces:?} (at most two allowed)")]
    NonManifoldEdge {
        /// The edge's smaller vertex.
        a: u32,
        /// The edge's larger vertex.
        b: u32,
        /// Three of the faces that share it.
        faces: [usize; 3],
    },
    /// The number of resolutions does not match the number of faces.
    #[error("{got} face resolutions for {faces} faces")]
    ResolutionCount {
        /// Resolutions given.
        got: usize,
        /// Faces in the mesh.
        faces: usize,
    },
    /// Attribute data with the wrong number of channels or values.
    #[error("{what}: expected {expected} values, got {got}")]
    ChannelMismatch {
        /// Which input.
        what: &'static str,
        /// The number expected.
        expected: usize,
        /// The number given.
        got: usize,
    },
    /// A channel count of zero or above [`crate::MAX_CHANNELS`].
    #[error("a sample needs 1..={max} channels, got {0}", max = crate::MAX_CHANNELS)]
    BadChannels(usize),
    /// A face index out of range.
    #[error("face {face} does not exist (the mesh has {count})")]
    MissingFace {
        /// The face index.
        face: usize,
        /// The number of faces.
        count: usize,
    },
    /// An operation that needs every face at resolution ≥ 2 met a face at 1.
    #[error("face {face} has resolution 1 and cannot be split 1-to-4 without resampling")]
    CannotSubdivide {
        /// The face.
        face: usize,
    },
    /// A texture with zero size or a data length that does not match.
    #[error("texture {width}×{height}×{channels} needs {expected} values, got {got}")]
    BadTexture {
        /// Width.
        width: usize,
        /// Height.
        height: usize,
        /// Channels.
        channels: usize,
        /// Values needed.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// A face of a multi-texture conversion names a texture that is not
    /// in the list.
    #[error("face {face} names texture {texture}, but there are only {count} textures")]
    MissingTexture {
        /// The face.
        face: usize,
        /// The texture index it names.
        texture: usize,
        /// The number of textures.
        count: usize,
    },
    /// A non-finite UV or position.
    #[error("{what} {index} is not finite (NaN or infinite)")]
    NonFinite {
        /// "uv" or "position".
        what: &'static str,
        /// The corner or vertex index.
        index: usize,
    },
    /// A `.meshcolors` file that cannot be read.
    #[error("invalid .meshcolors data at byte {offset}: {reason}")]
    File {
        /// The file, for [`crate::file::load`] (`None` for bytes or a
        /// stream). Not part of the message: the caller names the file.
        path: Option<std::path::PathBuf>,
        /// Byte offset where the problem was found.
        offset: u64,
        /// What was wrong.
        reason: String,
    },
    /// An I/O failure while writing or reading a `.meshcolors` stream; the
    /// `std::io::Error` is the source.
    #[error("cannot read or write mesh colours")]
    Io {
        /// The file, for [`crate::file::save`] and [`crate::file::load`]
        /// (`None` for a stream). Not part of the message, as with
        /// `std::io::Error`: the caller names the file it passed.
        path: Option<std::path::PathBuf>,
        /// What the operating system said.
        #[source]
        source: IoError,
    },
    /// An allocation sized by arguments (or a file) would exceed its budget.
    #[error("{what} would need {requested} {unit}, more than the budget of {budget}")]
    TooLarge {
        /// What would be allocated.
        what: &'static str,
        /// How much it would need.
        requested: u64,
        /// The budget ([`crate::MAX_SAMPLE_VALUES`], [`crate::atlas::MAX_SIDE`]).
        budget: u64,
        /// The unit of both numbers.
        unit: &'static str,
    },
    /// An undo record (a [`crate::undo::Delta`] or an
    /// [`crate::edit::ResolutionChange`]) applied to mesh colours it does not
    /// describe: another mesh, or a state it was not taken from (an undo
    /// applied twice, or out of order).
    #[error("the undo record does not fit these mesh colours: {what} {index} {reason}")]
    StaleUndo {
        /// The element that does not fit ("face", "edge", "sample",
        /// "channels").
        what: &'static str,
        /// Its index (or the count, for "channels").
        index: usize,
        /// How it differs from the record.
        reason: &'static str,
    },
    /// An argument outside the values it can take.
    #[error("argument `{argument}` {reason}")]
    InvalidArgument {
        /// The argument's name.
        argument: &'static str,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// Mesh colours loaded for a mesh they do not belong to.
    #[error("the mesh colours belong to a mesh with {stored}, but this mesh has {expected}")]
    WrongMesh {
        /// The fingerprint of the mesh the colours were made for.
        stored: crate::Fingerprint,
        /// The fingerprint of the mesh they were loaded for.
        expected: crate::Fingerprint,
    },
}

/// The `std::io::Error` behind [`Error::Io`], shared so that [`Error`]
/// stays `Clone`; two compare equal when their [`std::io::ErrorKind`]s do.
#[derive(Debug, Clone)]
pub struct IoError(pub std::sync::Arc<std::io::Error>);

impl PartialEq for IoError {
    fn eq(&self, other: &Self) -> bool {
        self.0.kind() == other.0.kind()
    }
}

impl std::fmt::Display for IoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for IoError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}
