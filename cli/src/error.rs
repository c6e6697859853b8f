//! The one error type of the adapters.

use std::path::PathBuf;

/// Why an adapter could not turn a file's data into an algorithm crate's
/// input (or back). Every message names the input and the problem.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing a file failed (the message names the file, the
    /// line or byte, and the problem).
    #[error(transparent)]
    Io(#[from] trilux_io::Error),
    /// mesh-sampling refused the mesh or the density (the source says
    /// why).
    #[error("sampling")]
    Sampling(#[from] mesh_sampling::Error),
    /// mesh-colors refused the mesh, the texture or the file (the source
    /// says why).
    #[error("mesh colours")]
    Colors(#[from] mesh_colors::Error),
    /// The mesh has no texture coordinates but the operation needs them.
    #[error("{what} needs texture coordinates, and the mesh has none")]
    MissingUvs {
        /// The operation.
        what: &'static str,
    },
    /// No texture was given and the mesh's materials have none.
    #[error(
        "the mesh has no material with a texture: give one (for the command line: --texture IMAGE)"
    )]
    MissingTexture,
    /// A `.meshcolors` file was made for another mesh.
    #[error(
        "{path}: these mesh colours belong to a mesh of {file_vertices} vertices and {file_faces} faces, but the mesh (welded) has {mesh_vertices} vertices and {mesh_faces} faces{detail}"
    )]
    WrongMesh {
        /// The `.meshcolors` file.
        path: PathBuf,
        /// Vertices the file's topology has.
        file_vertices: usize,
        /// Faces the file's topology has.
        file_faces: usize,
        /// Vertices of the welded mesh.
        mesh_vertices: usize,
        /// Faces of the welded mesh.
        mesh_faces: usize,
        /// Which face differs, when the counts agree.
        detail: String,
    },
    /// An argument out of its range.
    #[error("{0}")]
    Invalid(String),
    /// A command-line argument that is malformed, out of range, or given
    /// without the argument it goes with: the command line itself is
    /// wrong, whatever the files hold (the `trilux` command exits with 2
    /// for it, as for its parser's own errors).
    #[error("{0}")]
    Usage(String),
    /// The output exists and overwriting was not asked for.
    #[error("{0}: the file exists; pass --force to overwrite it")]
    Exists(PathBuf),
    /// What went wrong at a place: a file, an argument as typed, or a
    /// step ("the solve failed"); the source says what. The place is
    /// shown, the source is not (print the chain, joined by `": "`).
    #[error("{place}")]
    At {
        /// The file, the argument as typed, or the step.
        place: String,
        /// Whether the command line itself is wrong (the `trilux` command
        /// exits with 2 for it).
        usage: bool,
        /// What is wrong there.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// An I/O failure outside trilux-io (temporary files, renames); the
    /// `std::io::Error` is the source.
    #[error("{}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// Whether the command line is what is wrong ([`Error::Usage`], or an
    /// [`Error::At`] that says so): the `trilux` command exits with 2.
    pub fn is_usage(&self) -> bool {
        match self {
            Error::Usage(_) => true,
            Error::At { usage, .. } => *usage,
            _ => false,
        }
    }

    /// The file or argument this error's own message starts with, when it
    /// names one.
    pub fn place(&self) -> Option<String> {
        match self {
            Error::At { place, .. } => Some(place.clone()),
            Error::Io(e) => Some(e.path.display().to_string()),
            Error::WrongMesh { path, .. } | Error::Exists(path) | Error::File { path, .. } => {
                Some(path.display().to_string())
            }
            _ => None,
        }
    }
}

/// Short for `Result<T, Error>`.
pub type Result<T> = std::result::Result<T, Error>;
