//! The one error type of this crate: what went wrong, in which file, where.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file an error was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Location {
    /// A 1-based line of a text file.
    Line(usize),
    /// A byte offset into a binary file or section.
    Byte(usize),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(line) => write!(f, "line {line}"),
            Location::Byte(offset) => write!(f, "byte {offset}"),
        }
    }
}

/// What was wrong.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorKind {
    /// The file could not be opened, read or written; the
    /// `std::io::Error` is the source.
    #[error("could not read or write the file")]
    Io(#[source] std::io::Error),
    /// The extension names no format this crate reads or writes.
    #[error("the extension {0:?} names no format known here (expected one of {1})")]
    UnknownExtension(String, &'static str),
    /// The data ends before a declared record or section does.
    #[error("the file ends early: expected {0}")]
    Truncated(String),
    /// A token or record is not what the format allows here.
    #[error("expected {expected}, found {found:?}")]
    Syntax {
        /// What the format requires at this point.
        expected: String,
        /// What the file has (shortened).
        found: String,
    },
    /// A header declares more records than the rest of the file can hold;
    /// refused before anything is allocated.
    #[error(
        "the header declares {declared} {what}, but the {bytes_left} bytes left can hold at most {fit}"
    )]
    CountTooLarge {
        /// What is counted ("nodes", "tetrahedra", …).
        what: &'static str,
        /// The count the header declares.
        declared: u64,
        /// Bytes after the header.
        bytes_left: usize,
        /// How many records of the smallest legal size would fit.
        fit: u64,
    },
    /// An element references a node that does not exist.
    #[error("{element} {index} references node {node}, but there are only {count} nodes")]
    IndexOutOfRange {
        /// The kind of element ("tetrahedron", "face").
        element: &'static str,
        /// The element's position in the file (0-based).
        index: usize,
        /// The node reference as written in the file.
        node: i64,
        /// The number of nodes.
        count: usize,
    },
    /// A face corner of a surface file references a vertex, texture
    /// coordinate or normal the file does not have; names what is indexed
    /// in the format's own words ("texture coordinate 3 of face 0, but the
    /// file has 0 `vt` lines"). Boxed: it keeps [`Error`] small.
    #[error("{0}")]
    ReferenceOutOfRange(Box<Reference>),
    /// A coordinate is NaN or infinite.
    #[error("point {index} (0-based) has a non-finite coordinate ({value})")]
    NonFinite {
        /// The node's position in the file (0-based).
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A value the file holds cannot be represented (a coordinate too far
    /// from the others for `f32`, an id beyond `u32`).
    #[error("{0}")]
    OutOfRange(String),
    /// A valid file that uses a feature this crate does not read.
    #[error("the file uses {0}, which this reader does not support")]
    Unsupported(String),
    /// A codec (PNG, JPEG, HDR, EXR) could not decode or encode the data;
    /// its own error is the source.
    #[error("the {format} codec failed")]
    Codec {
        /// The format.
        format: &'static str,
        /// The codec's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// The file asks for more than the reader allows (image dimensions or
    /// memory), refused before decoding.
    #[error("refused before allocating: {0}")]
    LimitExceeded(String),
    /// A URI in the file points outside its folder (absolute, `..`, or a
    /// remote scheme), refused unless the caller allows it.
    #[error("URI {0:?} points outside the file's folder; allow it explicitly to read it")]
    OutsideFolder(String),
    /// What the caller asked to write is inconsistent (a field of the wrong
    /// length, a tetrahedron referencing a missing node).
    #[error("cannot write this data: {0}")]
    InvalidInput(String),
}

/// What an out-of-range face-corner reference indexes
/// ([`ErrorKind::ReferenceOutOfRange`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} {reference} of {element} {index}, but the file has {count} {records}")]
pub struct Reference {
    /// What is indexed ("vertex", "texture coordinate", "normal").
    pub what: &'static str,
    /// The reference as written in the file.
    pub reference: i64,
    /// The kind of element holding the reference ("face", "triangle").
    pub element: &'static str,
    /// The element's position in the file (0-based).
    pub index: usize,
    /// How many of what is indexed the file has.
    pub count: usize,
    /// What they are in the file ("`vt` lines", "vertices").
    pub records: &'static str,
}

/// A failure to read or write a file: the file, the line or byte offset
/// where it was found, and what was wrong. Nothing half-read is returned.
#[derive(Debug)]
pub struct Error {
    /// The file.
    pub path: PathBuf,
    /// Where in the file, when known.
    pub location: Option<Location>,
    /// What was wrong.
    pub kind: ErrorKind,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.location {
            Some(location) => write!(f, "{}: {location}: {}", self.path.display(), self.kind),
            None => write!(f, "{}: {}", self.path.display(), self.kind),
        }
    }
}

impl std::error::Error for Error {
    /// The I/O error or the codec's own error (PNG, JPEG, HDR, EXR, glTF
    /// JSON), whose own `source()` continues the chain.
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            ErrorKind::Io(e) => Some(e),
            ErrorKind::Codec { source, .. } => Some(source.as_ref()),
            _ => None,
        }
    }
}

impl Error {
    /// An error at no particular place in `path`.
    pub(crate) fn new(path: &Path, kind: ErrorKind) -> Self {
        Self {
            path: path.to_path_buf(),
            location: None,
            kind,
        }
    }

    /// An I/O error on `path`.
    pub(crate) fn io(path: &Path, error: std::io::Error) -> Self {
        Self::new(path, ErrorKind::Io(error))
    }
}

/// A foreign error whose `Display` already prints its own cause and whose
/// `source()` returns that cause too (image-rs's `ImageError` does both):
/// shown as its text, with the chain stopped here, so that a printer that
/// joins the chain with `": "` says the cause once.
pub(crate) struct Whole(pub(crate) Box<dyn std::error::Error + Send + Sync>);

impl fmt::Debug for Whole {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.0, f)
    }
}

impl fmt::Display for Whole {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

impl std::error::Error for Whole {}

/// The lowercased extension of `path` ("" when it has none), which picks
/// the format in every `read`.
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Short for `Result<T, Error>`.
pub type Result<T> = std::result::Result<T, Error>;
