//! Mesh colours (Yuksel, Keyser & House 2010): colour on the vertices,
//! edges and faces of a mesh, converted from a UV texture, looked up at
//! surface points, baked back to an atlas, saved and loaded.

use std::path::PathBuf;

use mesh_colors::MipMap;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use trilux::{ColorMesh, ConvertOptions};

use crate::arrays::{self, Int};
use crate::error::{Failure, Kind, detached};
use crate::mesh::{Mesh, image_from, image_to, mesh_arg, path_arg};

/// Mesh colours of a mesh (Yuksel, Keyser & House 2010, *Mesh Colors*,
/// ACM TOG 29(2)): per face a resolution `R = 2^n`, samples on vertices
/// (Eq. 1), edges (Eq. 2) and faces (Eq. 3), no UVs and so no seams.
/// Linear RGB, 3 channels, when converted from a texture.
///
/// They live on the mesh welded by position (`vertices`, `faces`; face
/// `f` is face `f` of the mesh they were made from), so points drawn by
/// `sample_surface` on that mesh look up by `(face_index, barycentric)`.
#[pyclass(module = "trilux")]
pub(crate) struct MeshColors {
    surface: ColorMesh,
    colors: mesh_colors::MeshColors,
    mip: Option<MipMap>,
}

fn points_arg(
    face: &Bound<'_, PyAny>,
    barycentric: &Bound<'_, PyAny>,
) -> PyResult<Vec<(u32, [f32; 3])>> {
    let faces = arrays::values_i64(face, "face")?;
    let bary = arrays::rows_f64::<3>(barycentric, "barycentric")?;
    if faces.len() != bary.len() {
        return Err(Failure::input(format!(
            "face has {} entries and barycentric {} rows: one per point",
            faces.len(),
            bary.len()
        ))
        .into());
    }
    faces
        .iter()
        .zip(&bary)
        .enumerate()
        .map(|(i, (&f, b))| {
            let f = u32::try_from(f)
                .map_err(|_| Failure::input(format!("face: entry {i} is {f}, not a face index")))?;
            Ok((f, b.map(|x| x as f32)))
        })
        .collect()
}

#[pymethods]
impl MeshColors {
    /// Converts a textured mesh: each face gets a resolution from the
    /// texels its UVs cover (about `density` samples per texel, faces at
    /// most level `max_level`, at most `max_samples` samples in all, by
    /// default the texture's texel count), each sample the bilinear
    /// texture value at its UV, averaged across seams.
    ///
    /// `mesh` needs UVs (a `trilux.Mesh` read from a file, or a
    /// `trimesh.Trimesh` with `visual.uv`). `image`: the texture, an
    /// `(H, W, C)` array (uint8 decoded from sRGB, floats taken as linear)
    /// or an image file; by default the mesh's own textures (its
    /// materials', or a trimesh's `visual.material.image`).
    #[staticmethod]
    #[pyo3(signature = (mesh, image = None, *, density = 1.0, max_level = Int::Value(8), max_samples = None),
        text_signature = "(mesh, image=None, *, density=1.0, max_level=8, max_samples=None)")]
    fn from_texture(
        py: Python<'_>,
        mesh: &Bound<'_, PyAny>,
        image: Option<&Bound<'_, PyAny>>,
        density: f64,
        max_level: Int,
        max_samples: Option<Int>,
    ) -> PyResult<Self> {
        let max_level: u8 = max_level.to("max_level", "0..256")?;
        let max_samples: Option<usize> = max_samples
            .map(|m| arrays::count(&m, "max_samples"))
            .transpose()?;
        let mesh = mesh_arg(mesh, None)?;
        let image = match image {
            None => None,
            Some(i) if arrays::is_path(i)? => {
                let path = path_arg(i, "image")?;
                Some(detached(py, || Ok(trilux_io::image::read(&path)?))?)
            }
            Some(i) => Some(image_from(i, "image", true)?),
        };
        let options = ConvertOptions {
            density,
            max_level,
            max_samples,
        };
        let (surface, colors) = detached(py, || {
            Ok(trilux::to_mesh_colors(&mesh, image.as_ref(), &options)?)
        })?;
        Ok(Self {
            surface,
            colors,
            mip: None,
        })
    }

    /// Reads a `.meshcolors` file made for `mesh` (checked: the file's
    /// topology must be the welded mesh's, else `trilux.InputError` naming
    /// the first face that differs).
    #[staticmethod]
    fn load(py: Python<'_>, path: &Bound<'_, PyAny>, mesh: &Bound<'_, PyAny>) -> PyResult<Self> {
        let path: PathBuf = path_arg(path, "path")?;
        let mesh = mesh_arg(mesh, None)?;
        let (surface, colors, mip) = detached(py, || {
            let surface = ColorMesh::new(&mesh)?;
            let (colors, mip) = mesh_colors::file::load(&path).map_err(|e| {
                let mut f = Failure::from(e);
                if f.kind == Kind::File {
                    f.message = format!("{}: {}", path.display(), f.message);
                }
                f
            })?;
            surface.check(&colors, &path)?;
            Ok((surface, colors, mip))
        })?;
        Ok(Self {
            surface,
            colors,
            mip,
        })
    }

    /// Writes a `.meshcolors` file (with the MIP-map, when `lookup` with
    /// `filter='mip'` built one); a folder that does not exist raises
    /// `trilux.FileError`.
    fn save(&self, py: Python<'_>, path: &Bound<'_, PyAny>) -> PyResult<()> {
        let path = path_arg(path, "path")?;
        crate::mesh::check_folder(&path)?;
        detached(py, || {
            Ok(mesh_colors::file::save(
                &path,
                &self.colors,
                self.mip.as_ref(),
            )?)
        })
    }

    /// The colour at surface points: `face` `(n,)` integer face indices,
    /// `barycentric` `(n, 3)` (as `sample_surface(...,
    /// return_barycentric=True)` returns them). `filter`: `'linear'`
    /// (Fig. 7, the default), `'nearest'`, or `'mip'` (trilinear between
    /// MIP levels, Sec. 4; give `footprint`, `(n,)` the footprint's size
    /// in barycentric units). Returns `(n, channels)` float32.
    #[pyo3(signature = (face, barycentric, *, filter = "linear", footprint = None))]
    fn lookup<'py>(
        &mut self,
        py: Python<'py>,
        face: &Bound<'py, PyAny>,
        barycentric: &Bound<'py, PyAny>,
        filter: &str,
        footprint: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let points = points_arg(face, barycentric)?;
        let c = self.colors.channels();
        let mut out = vec![0.0f32; points.len() * c];
        match filter {
            "linear" => {
                let colors = &self.colors;
                detached(py, || Ok(colors.linear_into(&points, &mut out)?))?;
            }
            "nearest" => {
                let colors = &self.colors;
                detached(py, || {
                    for (p, o) in points.iter().zip(out.chunks_exact_mut(c)) {
                        colors.nearest(p.0 as usize, p.1, o)?;
                    }
                    Ok(())
                })?;
            }
            "mip" => {
                let Some(footprint) = footprint else {
                    return Err(
                        Failure::input("filter='mip' needs footprint= (one per point)").into(),
                    );
                };
                let footprints: Vec<f32> = arrays::values_f64(footprint, "footprint")?
                    .into_iter()
                    .map(|x| x as f32)
                    .collect();
                if self.mip.is_none() {
                    let colors = &self.colors;
                    self.mip = Some(detached(py, || Ok(colors.mip_map()))?);
                }
                let mip = self
                    .mip
                    .as_ref()
                    .ok_or_else(|| Failure::input("no MIP-map"))?;
                detached(py, || {
                    Ok(mip.trilinear_into(&points, &footprints, &mut out)?)
                })?;
            }
            other => {
                return Err(Failure::input(format!(
                    "filter: {other:?} is not one of 'linear', 'nearest', 'mip'"
                ))
                .into());
            }
        }
        arrays::matrix(py, out, c)
    }

    /// Bakes the colours into a texture atlas: returns `(mesh, image)`,
    /// a `trilux.Mesh` with one vertex per face corner and atlas UVs
    /// (face `f` is face `f` of the mesh), and the atlas, `(H, W, 4)`
    /// float32 linear RGBA. Bilinear filtering of the atlas reproduces the
    /// linear filter. `gutter`: texels between blocks.
    #[pyo3(signature = (*, gutter = Int::Value(1)), text_signature = "($self, *, gutter=1)")]
    fn bake<'py>(&self, py: Python<'py>, gutter: Int) -> PyResult<Bound<'py, PyTuple>> {
        let gutter: u32 = gutter.to("gutter", "0..2**32")?;
        let options = mesh_colors::atlas::Options {
            gutter,
            ..Default::default()
        };
        let (mesh, image) = detached(py, || {
            let atlas = mesh_colors::atlas::bake(&self.colors, &options)?;
            Ok(trilux::atlas_mesh(&self.surface, &atlas, None))
        })?;
        let mesh = Bound::new(py, Mesh::plain(mesh))?.into_any();
        PyTuple::new(py, [mesh, image_to(py, &image)?])
    }

    /// The number of channels of each sample.
    #[getter]
    fn channels(&self) -> usize {
        self.colors.channels()
    }

    /// The number of faces.
    #[getter]
    fn face_count(&self) -> usize {
        self.colors.face_count()
    }

    /// The number of samples (vertices, edges and faces together).
    #[getter]
    fn sample_count(&self) -> usize {
        self.colors.sample_count()
    }

    /// Each face's resolution `R`, `(m,)` int64.
    #[getter]
    fn resolutions<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let r = (0..self.colors.face_count())
            .map(|f| i64::from(self.colors.face_resolution(f).unwrap_or(0)))
            .collect();
        arrays::vector(py, r)
    }

    /// All samples, `(sample_count, channels)` float32 (a copy).
    #[getter]
    fn samples<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::matrix(py, self.colors.samples().to_vec(), self.colors.channels())
    }

    /// The welded surface's vertices, `(n, 3)` float64.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::absolute_positions(py, self.surface.origin, &self.surface.positions)
    }

    /// The welded surface's faces, `(m, 3)` int64.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::index_matrix(py, &self.surface.faces)
    }

    fn __repr__(&self) -> String {
        format!(
            "trilux.MeshColors({} faces, {} samples, {} channels)",
            self.colors.face_count(),
            self.colors.sample_count(),
            self.colors.channels()
        )
    }
}
