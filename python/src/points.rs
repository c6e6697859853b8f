//! Point clouds back out of files: `trilux.load_points` reads what
//! `trilux.save_points` writes (PLY, or a glTF file's `POINTS`
//! primitives) into a `trilux.Points`, whose properties are named as
//! `save_points`' arguments, so that
//! `save_points(path, c.points, normals=c.normals, face_index=c.face_index,
//! colors=c.colors, attributes=c.attributes)` writes it again.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use trilux_io::mesh::gltf::Points as IoPoints;

use crate::arrays;
use crate::error::{Failure, detached};
use crate::mesh::{check_extension, path_arg};
use crate::tets::POINT_EXTENSIONS;

/// A point cloud read from a file (`trilux.load_points`): positions and
/// whichever of normals, face indices, colours, named attributes and UVs
/// the file has (`None`, or an empty dict, when it has not).
#[pyclass(module = "trilux", frozen)]
pub(crate) struct Points {
    inner: IoPoints,
    warnings: Vec<String>,
}

#[pymethods]
impl Points {
    /// Positions, `(n, 3)` float64, in the file's coordinates (`origin`
    /// added back).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::absolute_positions(py, self.inner.origin, &self.inner.positions)
    }

    /// Per-point normals, `(n, 3)` float64 (unit length from a glTF
    /// file, whose writer normalises them), or `None`.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .normals
            .as_deref()
            .map(|n| arrays::vectors(py, n))
            .transpose()
    }

    /// The triangle each point lies on, `(n,)` int64 (PLY `face_id`, glTF
    /// `_FACE`), or `None`.
    #[getter]
    fn face_index<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.inner
            .faces
            .as_ref()
            .map(|f| arrays::vector(py, f.iter().map(|&i| i64::from(i)).collect::<Vec<i64>>()))
    }

    /// Per-point colours, float32 linear RGB in `[0, 1]`: `(n, 3)`, or
    /// `(n, 4)` RGBA when an alpha is not 1; or `None`. A PLY file's
    /// 8-bit colours are decoded from sRGB, as `save_points` takes
    /// `uint8` colours.
    #[getter]
    fn colors<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .vertex_data
            .colors
            .as_ref()
            .map(|c| crate::gltf::colours_out(py, c))
            .transpose()
    }

    /// Named per-point values: a dict of names to float32 arrays, `(n,)`
    /// or `(n, k)`: a glTF file's `_NAME` attributes under the name
    /// without the underscore (`_HEIGHT` is `"HEIGHT"`), a PLY file's
    /// other vertex properties under theirs. Empty when there are none.
    #[getter]
    fn attributes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::gltf::attributes_out(py, &self.inner.vertex_data.attributes)
    }

    /// Per-point texture coordinates, `(n, 2)` float64, OpenGL convention
    /// (`v = 0` at the image's bottom row, as `Mesh.uv`), or `None`.
    #[getter]
    fn uv<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .uvs
            .as_deref()
            .map(|uv| arrays::uvs(py, uv))
            .transpose()
    }

    /// The global shift, `(3,)` float64, as `Mesh.origin`.
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(py, self.inner.origin.to_array().to_vec())
    }

    /// What the reader skipped without refusing the file, a list of str
    /// naming the file (as `Mesh.warnings`): PLY properties it does not
    /// read, a file's triangles (which `trilux.load` reads).
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }

    fn __len__(&self) -> usize {
        self.inner.positions.len()
    }

    fn __repr__(&self) -> String {
        let mut parts = vec![format!("{} points", self.inner.positions.len())];
        let has = [
            ("normals", self.inner.normals.is_some()),
            ("face_index", self.inner.faces.is_some()),
            ("colors", self.inner.vertex_data.colors.is_some()),
            ("uv", self.inner.uvs.is_some()),
        ];
        parts.extend(has.iter().filter(|h| h.1).map(|h| h.0.to_string()));
        let names: Vec<&str> = self
            .inner
            .vertex_data
            .attributes
            .iter()
            .map(|a| a.name.as_str())
            .collect();
        if !names.is_empty() {
            parts.push(format!("attributes {}", names.join(", ")));
        }
        format!("trilux.Points({})", parts.join(", "))
    }
}

/// Reads a point cloud, by extension: PLY (the vertices, with `nx ny
/// nz`, `face_id`, colours and other properties) or glTF (`.glb`,
/// `.gltf`: every `POINTS` primitive). What `save_points` writes comes
/// back: `points` (float64), `normals`, `face_index` (int64), `colors`
/// and `attributes` (float32, as glTF stores them), each `None` (or an
/// empty dict) when the file has none. A file's triangles are not points:
/// they are left out with a warning (`trilux.load` reads them). Raises
/// `trilux.FileError` naming the file, as `load` does.
#[pyfunction]
pub(crate) fn load_points(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Points> {
    let path = path_arg(path, "path")?;
    Failure::if_directory(&path, "a point file (.ply, .glb or .gltf)")?;
    let ext = check_extension(&path, &POINT_EXTENSIONS, "points", "read")?;
    let (inner, warnings) = detached(py, || {
        let shown = path.display();
        if ext == "ply" {
            let ply = trilux_io::mesh::ply::read(&path)?;
            let mut warnings: Vec<String> = ply.warnings.iter().map(ToString::to_string).collect();
            if !ply.triangles.is_empty() {
                warnings.push(format!(
                    "{shown}: the file's {} triangles are left out of the points (its vertices); \
                     trilux.load reads the mesh",
                    ply.triangles.len()
                ));
            }
            return Ok((IoPoints::from(&ply), warnings));
        }
        let scene = trilux_io::mesh::gltf::read_scene(&path)?;
        let mut warnings: Vec<String> = scene
            .mesh
            .warnings
            .iter()
            .map(ToString::to_string)
            .collect();
        let triangles = scene.mesh.indices.len();
        if triangles > 0 {
            let which = if scene.points.positions.is_empty() {
                "holds no points (POINTS primitives) but"
            } else {
                "also holds"
            };
            warnings.push(format!(
                "{shown}: the file {which} a mesh of {triangles} triangles, which are not \
                 points; trilux.load reads it"
            ));
        }
        Ok((scene.points, warnings))
    })?;
    Ok(Points { inner, warnings })
}
