//! Triangle meshes: `trilux.Mesh` (what `trilux.load` returns), files in
//! and out, and duck-typed meshes (`.vertices` / `.faces`, a
//! `trimesh.Trimesh` with its `visual.uv` and texture image) turned into
//! the `TriMesh` the `trilux` library's adapters take.
//!
//! **UVs** cross the Python boundary in the OpenGL / OBJ / trimesh
//! convention (`v = 0` at the bottom row of the image), and images as
//! numpy arrays row 0 first (the top row, as PIL and imageio give them).
//! Inside, `TriMesh` UVs are glTF's (`v = 0` at row 0): the flip
//! `v ↦ 1 − v` happens here, on the way in and out, and nowhere else.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DVec3, Vec2, Vec3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use trilux_io::image::Image;
use trilux_io::mesh::gltf::VertexData;
use trilux_io::mesh::{Material as IoMaterial, Object, TriMesh};

use crate::arrays;
use crate::error::{Failure, Kind, detached};

/// A triangle mesh as trilux holds it: `float32` positions relative to an
/// `origin` (kept in `float64`, so georeferenced scans keep their
/// precision), triangles, and the normals, UVs and materials (with
/// decoded textures) the file had.
///
/// `Mesh(vertices, faces, uv=None, normals=None)` makes one from arrays;
/// `trilux.load(path)` reads one. A `Mesh` has `.vertices` and `.faces`
/// like a `trimesh.Trimesh`, so it goes wherever a mesh is asked for, and
/// `trimesh.Trimesh(m.vertices, m.faces)` turns it into one. A glTF
/// file's per-vertex colours and `_NAME` attributes are `colors` and
/// `attributes`.
#[pyclass(module = "trilux", frozen)]
pub(crate) struct Mesh {
    pub(crate) inner: Arc<TriMesh>,
    /// A glTF file's `COLOR_0` and `_NAME` attributes (empty otherwise).
    pub(crate) data: VertexData,
}

impl Mesh {
    /// A mesh without colours or attributes.
    pub(crate) fn plain(inner: TriMesh) -> Self {
        Self {
            inner: Arc::new(inner),
            data: VertexData::default(),
        }
    }
}

fn flip_v(uv: [f64; 2]) -> Vec2 {
    Vec2::new(uv[0] as f32, (1.0 - uv[1]) as f32)
}

/// `positions` (absolute, `f64`) relative to the shift trilux-io's
/// readers choose (zero unless the coordinates are far from it).
fn recentered(positions: &[[f64; 3]]) -> (DVec3, Vec<Vec3>) {
    let points: Vec<DVec3> = positions.iter().map(|&p| DVec3::from_array(p)).collect();
    trilux_io::mesh::recenter(&points)
}

/// A `TriMesh` of arrays: vertices `(n, 3)`, faces `(m, 3)`, optional UVs
/// `(n, 2)` (OpenGL convention) and normals `(n, 3)`.
pub(crate) fn from_arrays(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    uv: Option<&Bound<'_, PyAny>>,
    normals: Option<&Bound<'_, PyAny>>,
) -> PyResult<TriMesh> {
    let positions = arrays::rows_f64::<3>(vertices, "vertices")?;
    let n = positions.len();
    let indices = arrays::index_rows::<3>(faces, "faces", n, ("vertex", "vertices"))?;
    let (origin, positions) = recentered(&positions);
    let uvs = uv.map(|uv| per_vertex::<2>(uv, "uv", n)).transpose()?;
    let normals = normals
        .map(|a| per_vertex::<3>(a, "normals", n))
        .transpose()?;
    let m = indices.len();
    Ok(TriMesh {
        positions,
        origin,
        indices,
        normals: normals.map(|v| v.iter().map(|p| DVec3::from_array(*p).as_vec3()).collect()),
        uvs: uvs.map(|v| v.into_iter().map(flip_v).collect()),
        objects: vec![Object {
            name: String::new(),
            triangles: 0..m,
            material: None,
        }],
        ..TriMesh::default()
    })
}

fn per_vertex<const K: usize>(
    obj: &Bound<'_, PyAny>,
    what: &str,
    n: usize,
) -> PyResult<Vec<[f64; K]>> {
    let rows = arrays::rows_f64::<K>(obj, what)?;
    if rows.len() != n {
        return Err(Failure::input(format!(
            "{what}: {} rows for {n} vertices (one per vertex)",
            rows.len()
        ))
        .into());
    }
    Ok(rows)
}

/// An image given as a numpy array (or anything `numpy.asarray` takes, a
/// PIL image included) as trilux-io's linear RGBA `Image`: integer images
/// are scaled to `[0, 1]`, and with `srgb` their colour channels decoded
/// from sRGB (as trilux-io decodes PNG and JPEG colour textures); float
/// images are taken as linear. One channel is grey, two grey and alpha.
pub(crate) fn image_from(obj: &Bound<'_, PyAny>, what: &str, srgb: bool) -> PyResult<Image> {
    let a = arrays::image_array(obj, what)?;
    let decode = |x: f32| {
        if srgb && a.integer {
            trilux_io::image::srgb_to_linear(x)
        } else {
            x
        }
    };
    let pixels = a
        .values
        .chunks_exact(a.channels)
        .map(|p| match a.channels {
            1 => [decode(p[0]), decode(p[0]), decode(p[0]), 1.0],
            2 => [decode(p[0]), decode(p[0]), decode(p[0]), p[1]],
            3 => [decode(p[0]), decode(p[1]), decode(p[2]), 1.0],
            _ => [decode(p[0]), decode(p[1]), decode(p[2]), p[3]],
        })
        .collect();
    Ok(Image {
        width: a.width as u32,
        height: a.height as u32,
        pixels,
    })
}

/// An `Image` as an `(H, W, 4)` float32 array (linear RGBA).
pub(crate) fn image_to<'py>(py: Python<'py>, image: &Image) -> PyResult<Bound<'py, PyAny>> {
    let data: Vec<f32> = image.pixels.iter().flatten().copied().collect();
    arrays::image(py, data, image.height as usize, image.width as usize, 4)
}

/// The texture image of a trimesh-like visual: `visual.material.image`
/// (trimesh's `SimpleMaterial`) or `visual.material.baseColorTexture`
/// (its `PBRMaterial`), when there is one.
///
/// trimesh's placeholder (`empty_material`: at most 4 texels of one
/// colour, made for a file with UVs and no texture) counts as no texture.
///
/// A texture that cannot be read (trimesh without Pillow hands out a
/// placeholder that raises when touched) is left out with a Python
/// `UserWarning` instead of failing the call: the geometry is intact, and
/// only a density or mesh colours taken from the texture need it (they
/// then say the mesh has no texture).
fn visual_texture(visual: &Bound<'_, PyAny>) -> PyResult<Option<Image>> {
    let Ok(material) = visual.getattr("material") else {
        return Ok(None);
    };
    for name in ["image", "baseColorTexture"] {
        let Ok(img) = material.getattr(name) else {
            continue;
        };
        if img.is_none() {
            continue;
        }
        let place = format!("mesh.visual.material.{name}");
        return match image_from(&img, &place, true) {
            // trimesh's placeholder is not the file's texture: a call that
            // needs one then says the mesh has none, instead of baking one grey.
            Ok(image) if is_placeholder(&image) => Ok(None),
            Ok(image) => Ok(Some(image)),
            Err(e) => {
                let py = visual.py();
                let message = format!(
                    "{place} could not be read ({}); the mesh is used without its texture",
                    e.value(py)
                );
                warn_user(py, &message)?;
                Ok(None)
            }
        };
    }
    Ok(None)
}

/// A texture of at most 4 texels, all one colour: what trimesh's
/// `empty_material` holds for a file with UVs and no texture.
fn is_placeholder(image: &Image) -> bool {
    image.pixels.len() <= 4 && image.pixels.windows(2).all(|w| w[0] == w[1])
}

/// A Python `UserWarning` with this message.
pub(crate) fn warn_user(py: Python<'_>, message: &str) -> PyResult<()> {
    let message = std::ffi::CString::new(message.replace('\0', " "))
        .unwrap_or_else(|_| c"trilux: a warning could not be formatted".to_owned());
    let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
    PyErr::warn(py, category.as_any(), &message, 1)
}

/// The mesh a function was given: a `trilux.Mesh` (used as it is), an
/// object with `.vertices` and `.faces` (a `trimesh.Trimesh`: its
/// `visual.uv` and texture image come along), or a `(vertices, faces)`
/// pair. `uv`, when given, replaces the mesh's UVs.
pub(crate) fn mesh_arg(
    obj: &Bound<'_, PyAny>,
    uv: Option<&Bound<'_, PyAny>>,
) -> PyResult<Arc<TriMesh>> {
    if let Ok(m) = obj.cast::<Mesh>() {
        let inner = m.get().inner.clone();
        return match uv {
            None => Ok(inner),
            Some(uv) => {
                let n = inner.positions.len();
                let uvs = per_vertex::<2>(uv, "uv", n)?;
                let mut copy = (*inner).clone();
                copy.uvs = Some(uvs.into_iter().map(flip_v).collect());
                Ok(Arc::new(copy))
            }
        };
    }
    if obj.hasattr("vertices")? && obj.hasattr("faces")? {
        let visual = obj.getattr("visual").ok();
        let own_uv = match &visual {
            Some(v) if uv.is_none() => v.getattr("uv").ok().filter(|u| !u.is_none()),
            _ => None,
        };
        let mut mesh = from_arrays(
            &obj.getattr("vertices")?,
            &obj.getattr("faces")?,
            uv.or(own_uv.as_ref()),
            None,
        )?;
        if let Some(image) = visual.as_ref().map(visual_texture).transpose()?.flatten() {
            mesh.materials.push(IoMaterial {
                name: "texture".into(),
                diffuse: [1.0; 3],
                diffuse_texture: None,
                diffuse_image: Some(image),
                wrap: Default::default(),
                scalar_images: Vec::new(),
            });
            for o in &mut mesh.objects {
                o.material = Some(0);
            }
        }
        return Ok(Arc::new(mesh));
    }
    if let Ok((v, f)) = obj.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
        return Ok(Arc::new(from_arrays(&v, &f, uv, None)?));
    }
    let name = obj.get_type().name()?.to_string();
    Err(Failure::input(format!(
        "mesh: expected a trilux.Mesh, an object with .vertices and .faces (a trimesh.Trimesh), \
         or a (vertices, faces) pair; got {name}"
    ))
    .into())
}

/// A path argument.
pub(crate) fn path_arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<PathBuf> {
    obj.extract::<PathBuf>()
        .map_err(|_| Failure::input(format!("{what}: expected a path (str or os.PathLike)")).into())
}

/// A `trilux.FileError` with `message`.
pub(crate) fn file_error(message: String) -> PyErr {
    Failure {
        kind: Kind::File,
        message,
    }
    .into()
}

/// The lowercased extension of `path`, `None` when it has none (or ends
/// in a bare `.`).
pub(crate) fn extension(path: &Path) -> Option<String> {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .filter(|e| !e.is_empty())
}

/// `.a, .b or .c`.
fn listed(extensions: &[&str]) -> String {
    let dotted: Vec<String> = extensions.iter().map(|e| format!(".{e}")).collect();
    match dotted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => dotted.concat(),
    }
}

/// Checks that `path`'s extension is one of `extensions` (lower case),
/// which pick the format of `what` ("a mesh", "points"), and returns it:
/// otherwise a `trilux.FileError` naming the path and the extensions
/// accepted, with `verb` ("write", "read") in the advice.
pub(crate) fn check_extension(
    path: &Path,
    extensions: &[&str],
    what: &str,
    verb: &str,
) -> PyResult<String> {
    let accepted = listed(extensions);
    match extension(path) {
        None => Err(file_error(format!(
            "{}: the path has no extension, and the extension picks the format of {what} \
             ({verb} {accepted})",
            path.display()
        ))),
        Some(ext) if !extensions.contains(&ext.as_str()) => Err(file_error(format!(
            "{}: unknown extension {ext:?} for {what} ({verb} {accepted})",
            path.display()
        ))),
        Some(ext) => Ok(ext),
    }
}

/// Checks that the folder a file is to be written in exists: otherwise a
/// `trilux.FileError` naming the path given and the folder (the writer's
/// own error would name the first file it opens: the `.bin` of a
/// `.gltf`, the `.ele` of a `.node`).
pub(crate) fn check_folder(path: &Path) -> PyResult<()> {
    let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) else {
        return Ok(());
    };
    if folder.is_dir() {
        return Ok(());
    }
    let why = if folder.exists() {
        "is not a folder"
    } else {
        "does not exist"
    };
    Err(file_error(format!(
        "{}: the folder {} {why}",
        path.display(),
        folder.display()
    )))
}

/// The extensions `save` writes a mesh to.
const MESH_EXTENSIONS: [&str; 4] = ["obj", "ply", "glb", "gltf"];

#[pymethods]
impl Mesh {
    /// A mesh of arrays: vertices `(n, 3)` (any real dtype), faces `(m, 3)`
    /// (any integer dtype, indices into the vertices), and optionally
    /// per-vertex UVs `(n, 2)` (OpenGL convention, `v = 0` at the image's
    /// bottom row) and normals `(n, 3)`.
    #[new]
    #[pyo3(signature = (vertices, faces, uv = None, normals = None))]
    fn new(
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        uv: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        Ok(Self::plain(from_arrays(vertices, faces, uv, normals)?))
    }

    /// Vertex positions, `(n, 3)` float64, in the file's coordinates
    /// (`origin` added back).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::absolute_positions(py, self.inner.origin, &self.inner.positions)
    }

    /// Triangles, `(m, 3)` int64 vertex indices, counter-clockwise as the
    /// file orders them.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::index_matrix(py, &self.inner.indices)
    }

    /// Per-vertex texture coordinates, `(n, 2)` float64, OpenGL convention
    /// (`v = 0` at the image's bottom row, as trimesh's `visual.uv`), or
    /// `None`.
    #[getter]
    fn uv<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .uvs
            .as_deref()
            .map(|uv| arrays::uvs(py, uv))
            .transpose()
    }

    /// Per-vertex normals, `(n, 3)` float64, or `None` when the file had
    /// none.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.inner
            .normals
            .as_deref()
            .map(|n| arrays::vectors(py, n))
            .transpose()
    }

    /// Per-vertex colours of a glTF file (`COLOR_0`), float32 linear RGB
    /// in `[0, 1]`: `(n, 3)`, or `(n, 4)` RGBA when an alpha is not 1; or
    /// `None` (other formats, or a file without them). `trilux.save`
    /// writes them back only when given:
    /// `trilux.save(path, m, colors=m.colors, attributes=m.attributes)`.
    #[getter]
    fn colors<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.data
            .colors
            .as_ref()
            .map(|c| crate::gltf::colours_out(py, c))
            .transpose()
    }

    /// A glTF file's per-vertex `_NAME` attributes: a dict of names
    /// without the underscore (`_PHI` is `"PHI"`) to float32 arrays,
    /// `(n,)` or `(n, k)`, as `trilux.save(..., attributes=)` takes them;
    /// empty for other formats.
    #[getter]
    fn attributes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::gltf::attributes_out(py, &self.data.attributes)
    }

    /// The global shift, `(3,)` float64: zero for ordinary files, the
    /// centre of the bounding box for coordinates far from zero.
    #[getter]
    fn origin<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(py, self.inner.origin.to_array().to_vec())
    }

    /// The materials, each a dict: `name`, `diffuse` (linear RGB),
    /// `texture` (an `(H, W, 4)` float32 linear RGBA array or `None`),
    /// `texture_path` (the file it names, or `None`).
    #[getter]
    fn materials<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for m in &self.inner.materials {
            let d = PyDict::new(py);
            d.set_item("name", &m.name)?;
            d.set_item("diffuse", m.diffuse.to_vec())?;
            match &m.diffuse_image {
                Some(img) => d.set_item("texture", image_to(py, img)?)?,
                None => d.set_item("texture", py.None())?,
            }
            d.set_item("texture_path", m.diffuse_texture.clone())?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// What the reader skipped or replaced without refusing the file, a
    /// list of str: a missing `.mtl` or texture, `f v/vt/vn` corners
    /// without `vt` lines, PLY elements or properties it does not read, a
    /// glTF texture whose image is only in an extension, a glTF file's
    /// points (which `trilux.load_points` reads). Each names the
    /// file, the line or element and what was skipped (as `trilux info`
    /// prints them); empty for an intact file or a mesh made of arrays.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner
            .warnings
            .iter()
            .map(ToString::to_string)
            .collect()
    }

    /// The named parts: a list of `(name, first_face, end_face,
    /// material_index or None)`.
    #[getter]
    fn objects(&self) -> Vec<(String, usize, usize, Option<usize>)> {
        self.inner
            .objects
            .iter()
            .map(|o| {
                (
                    o.name.clone(),
                    o.triangles.start,
                    o.triangles.end,
                    o.material,
                )
            })
            .collect()
    }

    fn __repr__(&self) -> String {
        let names: Vec<&str> = self
            .data
            .attributes
            .iter()
            .map(|a| a.name.as_str())
            .collect();
        format!(
            "trilux.Mesh({} vertices, {} faces{}{}{}{})",
            self.inner.positions.len(),
            self.inner.indices.len(),
            if self.inner.uvs.is_some() { ", uv" } else { "" },
            if self.inner.normals.is_some() {
                ", normals"
            } else {
                ""
            },
            if self.data.colors.is_some() {
                ", colors"
            } else {
                ""
            },
            if names.is_empty() {
                String::new()
            } else {
                format!(", attributes {}", names.join(", "))
            },
        )
    }
}

/// Reads a triangle mesh: OBJ (with its MTL and textures), glTF/GLB or
/// PLY, by extension. Raises `trilux.FileError` naming the file and line.
/// What the reader skipped without refusing the file (a missing texture,
/// an element it does not read) is in the mesh's `warnings`. A glTF
/// file's per-vertex colours and `_NAME` attributes are the mesh's
/// `colors` and `attributes`; its points (`POINTS` primitives, as
/// `save_points` writes them) are not part of the mesh: a warning says
/// so, and `trilux.load_points` reads them.
#[pyfunction]
pub(crate) fn load(py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<Mesh> {
    let path = path_arg(path, "path")?;
    Failure::if_directory(&path, "a mesh file (.obj, .gltf, .glb or .ply)")?;
    if !crate::gltf::is_gltf(&path) {
        let inner = detached(py, || Ok(TriMesh::read(&path)?))?;
        return Ok(Mesh::plain(inner));
    }
    let scene = detached(py, || Ok(trilux_io::mesh::gltf::read_scene(&path)?))?;
    let mut inner = scene.mesh;
    let points = scene.points.positions.len();
    if points > 0 {
        // trilux-io's own warning (which `read` adds, `read_scene` does
        // not) names a Rust function; this one names the Python one.
        inner.warnings.push(trilux_io::Warning {
            path: path.clone(),
            location: None,
            message: format!(
                "the file also holds {points} points (POINTS primitives), which a triangle mesh \
                 does not keep; trilux.load_points(path) reads them"
            ),
        });
    }
    Ok(Mesh {
        inner: Arc::new(inner),
        data: scene.vertex_data,
    })
}

/// Writes a triangle mesh (a `trilux.Mesh`, a `trimesh.Trimesh` or a
/// `(vertices, faces)` pair) by extension: OBJ (with MTL and textures),
/// PLY, or glTF (`.glb`, one file; `.gltf` with a `.bin` of the same name
/// beside it), with the mesh's normals, UVs and materials (textures
/// embedded). An existing file is replaced. A path without one of these
/// extensions, or in a folder that does not exist, raises
/// `trilux.FileError`; a vertex that is not finite, `trilux.InputError`.
///
/// glTF files also keep, per vertex, `colors` (`COLOR_0`): `(n, 3)` or
/// `(n, 4)` floats in [0, 1], linear as glTF says (values within 1e-5 of
/// [0, 1], float32 rounding, are clamped into it), or `uint8` taken as
/// 8-bit sRGB (trimesh's `visual.vertex_colors`) and decoded; and
/// `attributes`: a dict of names to `(n,)` or `(n, k)` arrays (k from 1
/// to 4), written as glTF's `_NAME` attributes: the name is prefixed
/// with `_` (`"PHI"` is written `_PHI`, `"COLOR_0"` `_COLOR_0`; a name
/// given with the underscore keeps its one), which three.js shows as
/// `geometry.attributes._phi` and Blender as `_PHI`. Attributes are
/// stored as float32, as glTF requires of them: floats are rounded to
/// float32, and integers must be exact in it (every one up to 2**24 =
/// 16777216 in magnitude is; give floats to accept rounding). With
/// another extension they raise `trilux.InputError`, as does a colour
/// outside [0, 1] (by more than 1e-5) or not finite, a wrong number of
/// rows, a non-finite value or a name that is not ASCII letters, digits
/// and `_`. `trilux.load` gives them back (`Mesh.colors`,
/// `Mesh.attributes`).
#[pyfunction]
#[pyo3(signature = (path, mesh, *, colors = None, attributes = None))]
pub(crate) fn save(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    mesh: &Bound<'_, PyAny>,
    colors: Option<&Bound<'_, PyAny>>,
    attributes: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let path = path_arg(path, "path")?;
    check_extension(&path, &MESH_EXTENSIONS, "a mesh", "write")?;
    check_folder(&path)?;
    let mesh = mesh_arg(mesh, None)?;
    check_finite_vertices(&mesh)?;
    let n = mesh.positions.len();
    let data = crate::gltf::vertex_data(&path, colors, attributes, n, ("vertex", "vertices"))?;
    detached(py, || match &data {
        Some(data) => Ok(trilux_io::mesh::gltf::write_with(&path, &mesh, data)?),
        None => Ok(mesh.write(&path)?),
    })
}

/// A `trilux.InputError` naming the first vertex of `mesh` whose position
/// is not finite (or, finite in float64, too far from the others to be
/// held in float32 relative to the origin): every format's reader refuses
/// such a file.
fn check_finite_vertices(mesh: &TriMesh) -> PyResult<()> {
    let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) else {
        return Ok(());
    };
    let absolute = (mesh.origin + mesh.positions[i].as_dvec3()).to_array();
    let why = if absolute.iter().all(|v| v.is_finite()) {
        "is too far from the other vertices to be stored in float32"
    } else {
        "is not finite"
    };
    Err(Failure::input(format!(
        "mesh: vertex {i} {why} ({})",
        crate::gltf::row_text(&absolute)
    ))
    .into())
}
