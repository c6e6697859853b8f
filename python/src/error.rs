//! The exceptions: `trilux.Error` and its subclasses, each carrying the
//! Rust error's message unchanged.
//!
//! | exception | bases | raised for |
//! |---|---|---|
//! | `trilux.Error` | `Exception` | the base of all below |
//! | `trilux.InputError` | `Error`, `ValueError` | arguments and data the Rust crates refuse (bad arrays, weights, options, meshes; data a trilux-io writer refuses) |
//! | `trilux.FileError` | `Error`, `OSError` | a file that cannot be read, written or parsed, a path whose extension names no format or whose folder does not exist (trilux-io's errors: the message names the file and line) |
//! | `trilux.InternalError` | `Error`, `RuntimeError` | a Rust panic (a bug): never a crash of the interpreter |

use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyType};

/// The four classes, made once per interpreter by running a few lines of
/// Python (PyO3's `create_exception!` takes one base, and `InputError`
/// must be both a `trilux.Error` and a `ValueError`).
struct Classes {
    error: Py<PyType>,
    input: Py<PyType>,
    file: Py<PyType>,
    internal: Py<PyType>,
}

static CLASSES: PyOnceLock<Classes> = PyOnceLock::new();

const DEFINITIONS: &str = r#"
class Error(Exception):
    """The base of every exception trilux raises; the message is the Rust
    crate's, unchanged."""
    __module__ = "trilux"

class InputError(Error, ValueError):
    """An argument or input data that trilux refuses (a bad array, weight,
    option or mesh); the message names the argument and the element."""
    __module__ = "trilux"

class FileError(Error, OSError):
    """A file that cannot be read, written or parsed; the message names the
    file, the line or byte, and what was wrong."""
    __module__ = "trilux"

class InternalError(Error, RuntimeError):
    """A Rust panic: a bug in trilux (please report it with the message)."""
    __module__ = "trilux"
"#;

fn classes(py: Python<'_>) -> PyResult<&Classes> {
    CLASSES.get_or_try_init(py, || {
        let scope = PyDict::new(py);
        let code = std::ffi::CString::new(DEFINITIONS)
            .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
        py.run(&code, Some(&scope), Some(&scope))?;
        let get = |name: &str| -> PyResult<Py<PyType>> {
            Ok(scope
                .get_item(name)?
                .ok_or_else(|| pyo3::exceptions::PyRuntimeError::new_err(name.to_owned()))?
                .cast_into::<PyType>()?
                .unbind())
        };
        Ok(Classes {
            error: get("Error")?,
            input: get("InputError")?,
            file: get("FileError")?,
            internal: get("InternalError")?,
        })
    })
}

/// Adds the classes to the module.
pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let c = classes(py)?;
    m.add("Error", c.error.bind(py))?;
    m.add("InputError", c.input.bind(py))?;
    m.add("FileError", c.file.bind(py))?;
    m.add("InternalError", c.internal.bind(py))?;
    Ok(())
}

/// Which exception an error becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Input,
    File,
    Internal,
}

/// An error on its way to Python: its class and the Rust message. Made
/// without the GIL (inside `Python::detach`) and raised after.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Failure {
    pub(crate) kind: Kind,
    pub(crate) message: String,
}

impl Failure {
    /// A `trilux.InputError` with `message`.
    pub(crate) fn input(message: impl Into<String>) -> Self {
        Self {
            kind: Kind::Input,
            message: message.into(),
        }
    }

    /// A `trilux.FileError` when `path` is a directory where a file of
    /// `what` was expected (the readers would only see its empty
    /// extension).
    pub(crate) fn if_directory(path: &std::path::Path, what: &str) -> Result<()> {
        if path.is_dir() {
            return Err(Self {
                kind: Kind::File,
                message: format!("{}: is a directory, not {what}", path.display()),
            });
        }
        Ok(())
    }
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> Self {
        Python::attach(|py| match classes(py) {
            Ok(c) => {
                let ty = match f.kind {
                    Kind::Input => &c.input,
                    Kind::File => &c.file,
                    Kind::Internal => &c.internal,
                };
                PyErr::from_type(ty.bind(py).clone(), f.message)
            }
            Err(e) => e,
        })
    }
}

impl From<trilux_io::Error> for Failure {
    /// A `FileError`, except for data a writer refuses
    /// ([`trilux_io::ErrorKind::InvalidInput`]: a field of the wrong
    /// length, a non-finite position, a colour out of range): a problem
    /// of the arrays given, so an `InputError` as the Python layer's own
    /// checks raise.
    fn from(e: trilux_io::Error) -> Self {
        let kind = match e.kind {
            trilux_io::ErrorKind::InvalidInput(_) => Kind::Input,
            _ => Kind::File,
        };
        Self {
            kind,
            message: chain(&e),
        }
    }
}

impl From<trilux::Error> for Failure {
    fn from(e: trilux::Error) -> Self {
        let kind = match &e {
            trilux::Error::Io(_) | trilux::Error::File { .. } | trilux::Error::Exists(_) => {
                Kind::File
            }
            _ => Kind::Input,
        };
        let message = match &e {
            // The command line's way to give a texture is not Python's.
            trilux::Error::MissingTexture => "the mesh has no material with a texture: give one \
                (MeshColors.from_texture(mesh, image), image an array or an image file)"
                .to_string(),
            _ => chain(&e),
        };
        Self { kind, message }
    }
}

/// The algorithm crates' errors are about arguments and data.
macro_rules! input_error {
    ($($t:ty),*) => {$(
        impl From<$t> for Failure {
            fn from(e: $t) -> Self {
                Self::input(chain(&e))
            }
        }
    )*};
}
input_error!(discrete_sampling::Error);

// The messages below are the crates' own, reworded where they name a Rust
// item or a command-line flag (`length_unit_mm`, `h`, `sample_stream`,
// `--texture`, "the approximate mode") instead of the Python argument the
// caller can change (`unit_mm`, `spacing`, `count`, `method=`): the
// Python user reads them, not the Rust one.

/// "…; use the approximate mode" in Python's words.
const APPROXIMATE: (&str, &str) = (
    "(use the approximate mode)",
    "(use method='subdivision', the default with a texture)",
);

impl From<mesh_sampling::Error> for Failure {
    fn from(e: mesh_sampling::Error) -> Self {
        use mesh_sampling::Error as E;
        match &e {
            E::TooManyPoints { requested, budget } => Self::input(format!(
                "count: {requested} points is more than one call returns (at most {budget} = \
                 2**{}); ask for fewer, and call again with another seed for more",
                budget.trailing_zeros()
            )),
            E::IntegrationTooLarge { .. } | E::AcceptanceTooLow { .. } => {
                Self::input(chain(&e).replace(APPROXIMATE.0, APPROXIMATE.1).replace(
                    "for the exact mode or rejection sampling",
                    "for method='exact' or method='rejection'",
                ))
            }
            // The crate's message names `Options::max_pieces`, which
            // Python does not expose.
            E::TooManyPieces { needed, budget } => Self::input(format!(
                "density: this mesh needs at least {needed} pieces (one or more per \
                 triangle), more than the density sampler's budget of {budget}; with a density \
                 texture, method='rejection' needs no pieces, else sample a mesh with fewer \
                 triangles"
            )),
            _ => Self::input(chain(&e)),
        }
    }
}

impl From<tet_diffusion::Error> for Failure {
    fn from(e: tet_diffusion::Error) -> Self {
        use tet_diffusion::Error as E;
        // Python calls a tet mesh's positions `nodes` (trilux.Object,
        // load_tets), so the mesh's checks say "node".
        let message = match &e {
            E::NonFinitePosition { vertex, position } => format!(
                "nodes: node {vertex} has a non-finite position [{}, {}, {}]",
                position[0], position[1], position[2]
            ),
            E::IndexOutOfRange {
                tet,
                index,
                vertices,
            } => format!(
                "tets: row {tet} references node {index}, but there are only {vertices} nodes"
            ),
            E::RepeatedVertex { tet, index } => format!("tets: row {tet} repeats node {index}"),
            E::UnusedVertex { vertex, count } => format!(
                "nodes: node {vertex} is used by no tetrahedron ({count} such nodes); drop unused nodes \
                 (and renumber tets) before making the Object"
            ),
            E::DegenerateTet {
                tet,
                vertices,
                volume,
            } => format!(
                "tets: row {tet} (nodes {vertices:?}) has zero volume ({volume:e}): its nodes are coplanar"
            ),
            E::BadArgument { what, value, need } if what == "length_unit_mm" => {
                format!("unit_mm is {value}: {need}")
            }
            E::BadArgument { what, value, need } if what == "the index of refraction eta" => {
                format!("eta (the index of refraction) is {value}: {need}")
            }
            _ => chain(&e),
        };
        Self::input(message)
    }
}

impl From<tet_stuffing::Error> for Failure {
    fn from(e: tet_stuffing::Error) -> Self {
        use tet_stuffing::Error as E;
        // The stuffing's `h` is tetrahedralize's `spacing`.
        let message = match &e {
            E::InvalidSpacing { h } => {
                format!("spacing: {h} is not a positive finite length (mesh units)")
            }
            E::LatticeTooLarge {
                h,
                vertices,
                limit,
                limit_mib,
            } => {
                let vertices = if *vertices == u128::MAX {
                    "more than 10^36".to_string()
                } else {
                    vertices.to_string()
                };
                format!(
                    "spacing={h:e}: the lattice over this surface needs {vertices} vertices, more \
                     than the limit of {limit} (about {limit_mib} MiB); choose a larger spacing"
                )
            }
            E::TooManyTetrahedra {
                h,
                estimated,
                limit,
            } => format!(
                "spacing={h:e}: the mesh would have about {estimated} tetrahedra, more than the \
                 limit of {limit}; choose a larger spacing (or graded=True)"
            ),
            E::EmptyVolume { h } => format!(
                "the surface encloses no volume at spacing={h} (winding number above 1/2 at no \
                 lattice vertex): it is thinner than the spacing; try a smaller spacing"
            ),
            E::OpenSurface { triangles } => format!(
                "the surface encloses no volume: none of its {triangles} triangles bounds one (an \
                 open sheet or a doubled wall, by the winding number), so no spacing gives \
                 tetrahedra; close the surface or give it thickness"
            ),
            E::InvalidEnvelope { eps } => format!(
                "envelope={eps}: the envelope is a fraction of the bounding box's diagonal, \
                 between 0 and 1 (e.g. 0.002)"
            ),
            _ => chain(&e),
        };
        Self::input(message)
    }
}

impl From<mesh_colors::Error> for Failure {
    fn from(e: mesh_colors::Error) -> Self {
        let kind = match &e {
            mesh_colors::Error::Io { .. } | mesh_colors::Error::File { .. } => Kind::File,
            _ => Kind::Input,
        };
        Self {
            kind,
            message: chain(&e),
        }
    }
}

/// An error's message with its causes, joined by ": " (as the `trilux`
/// command prints them).
pub(crate) fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

/// `Result` with a [`Failure`].
pub(crate) type Result<T> = std::result::Result<T, Failure>;

/// Runs `f` without the GIL (so that other Python threads run, and rayon
/// uses every core), turning a Rust panic into `trilux.InternalError`
/// instead of PyO3's `PanicException`.
pub(crate) fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> Result<T> + Send,
) -> PyResult<T> {
    py.detach(|| guarded(f)).map_err(PyErr::from)
}

/// `f`, with a panic caught and reported as [`Kind::Internal`].
pub(crate) fn guarded<T>(f: impl FnOnce() -> Result<T>) -> Result<T> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(Failure {
            kind: Kind::Internal,
            message: format!("internal error (a bug in trilux, please report it): {what}"),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Python user cannot set Rust's `Options`: the piece budget's
    /// message names what they can change instead.
    #[test]
    fn too_many_pieces_names_python_remedies() {
        let f = Failure::from(mesh_sampling::Error::TooManyPieces {
            needed: 5_000_000,
            budget: 4_194_304,
        });
        assert_eq!(f.kind, Kind::Input);
        assert!(f.message.contains("5000000 pieces"), "{}", f.message);
        assert!(f.message.contains("method='rejection'"), "{}", f.message);
        assert!(!f.message.contains("Options::"), "{}", f.message);
    }

    /// Data a trilux-io writer refuses is an `InputError`; a file that
    /// cannot be read or written stays a `FileError`.
    #[test]
    fn a_writers_refusal_of_the_data_is_an_input_error() {
        let refused = trilux_io::Error {
            path: "a.glb".into(),
            location: None,
            kind: trilux_io::ErrorKind::InvalidInput("vertex 3 has a non-finite position".into()),
        };
        let f = Failure::from(refused);
        assert_eq!(f.kind, Kind::Input);
        assert_eq!(
            f.message,
            "a.glb: cannot write this data: vertex 3 has a non-finite position"
        );
        let missing = trilux_io::Error {
            path: "a.glb".into(),
            location: None,
            kind: trilux_io::ErrorKind::Io(std::io::ErrorKind::NotFound.into()),
        };
        assert_eq!(Failure::from(missing).kind, Kind::File);
    }

    /// The rejection steps' messages say `method=`, not "the approximate
    /// mode" or "the exact mode".
    #[test]
    fn rejection_messages_name_the_method_argument() {
        let errors = [
            mesh_sampling::Error::AcceptanceTooLow {
                acceptance: 1e-12,
                minimum: 1e-9,
            },
            mesh_sampling::Error::IntegrationTooLarge {
                cells: 1e12,
                budget: 1 << 30,
            },
        ];
        for e in errors {
            let f = Failure::from(e);
            assert_eq!(f.kind, Kind::Input);
            assert!(f.message.contains("method='subdivision'"), "{}", f.message);
            assert!(!f.message.contains(" mode"), "{}", f.message);
        }
    }
}
