//! What a reader skipped or could not use without refusing the file: a
//! PLY element it does not read, a missing material library or texture,
//! face corners naming texture coordinates the file does not have.
//!
//! The readers return the mesh and a list of these ([`TriMesh::warnings`],
//! [`TetMesh::warnings`]), so that nothing is dropped in silence and an
//! intact mesh is never refused over a side file.
//!
//! [`TriMesh::warnings`]: crate::mesh::TriMesh::warnings
//! [`TetMesh::warnings`]: crate::tet::TetMesh::warnings

use std::fmt;
use std::path::{Path, PathBuf};

use crate::error::Location;

/// One thing a reader skipped or replaced by a default: the file, where
/// in it (when there is one place), and what was skipped, in words a
/// user can act on ("element `edge` (12 records) is not read").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Warning {
    /// The file the warning is about (the mesh, or a side file such as
    /// its `.mtl`).
    pub path: PathBuf,
    /// The line or byte offset, when the warning is about one place.
    pub location: Option<Location>,
    /// What was skipped or replaced, and why.
    pub message: String,
}

impl Warning {
    /// A warning about `path` at `location`.
    pub(crate) fn new(path: &Path, location: Option<Location>, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            location,
            message: message.into(),
        }
    }
}

impl fmt::Display for Warning {
    /// `FILE: line N: MESSAGE`, as [`crate::Error`] is shown.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Some(location) => write!(f, "{}: {location}: {}", self.path.display(), self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}
