//! Points on surfaces: `sample_surface` (trimesh's `sample.sample_surface`
//! shape), `blue_noise` and `sample_surface_even` (point-cloud-utils' and
//! trimesh's Poisson-disk shapes), over mesh-sampling's samplers.

use std::sync::{Arc, Mutex};

use glam::DVec3;
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Channel, Density, DensitySampler, DensityTexture, Mode,
    Options, RejectionSampler, SurfacePoint, SurfaceSampler, UniformSampler,
};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadwriteArray};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use trilux_io::mesh::TriMesh;

use crate::arrays::{self, Int};
use crate::error::{Failure, Kind, Result, detached};
use crate::mesh::{mesh_arg, path_arg};

/// Which values to return besides positions and faces.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Want {
    barycentric: bool,
    pdf: bool,
    normal: bool,
}

/// The arrays of a batch of points: numpy arrays, allocated by numpy
/// under the GIL and filled without it. numpy asks the kernel for huge
/// pages for large arrays (`madvise(MADV_HUGEPAGE)`), so the first writes
/// to a 10⁷-point result (320 MB) fault 2 MB pages, not 80 000 pages of
/// 4 KB as a `Vec` filled first and then handed to numpy did, on a
/// machine whose transparent huge pages are `madvise` (the default of
/// Debian and Ubuntu).
pub(crate) struct Points<'py> {
    positions: Bound<'py, PyArray2<f64>>,
    faces: Bound<'py, PyArray1<i64>>,
    barycentric: Option<Bound<'py, PyArray2<f64>>>,
    pdf: Option<Bound<'py, PyArray1<f64>>>,
    normals: Option<Bound<'py, PyArray2<f64>>>,
}

/// The arrays of [`Points`] as slices (C order), to fill without the GIL.
struct Slices<'a> {
    positions: &'a mut [f64],
    faces: &'a mut [i64],
    barycentric: Option<&'a mut [f64]>,
    pdf: Option<&'a mut [f64]>,
    normals: Option<&'a mut [f64]>,
}

/// A freshly made array's data as a slice (it is always contiguous).
fn slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: &'a mut PyReadwriteArray<'_, T, D>,
) -> PyResult<&'a mut [T]> {
    a.as_slice_mut().map_err(|e| {
        Failure {
            kind: Kind::Internal,
            message: format!("output array: {e}"),
        }
        .into()
    })
}

impl<'py> Points<'py> {
    /// Zeroed arrays for `n` points (the count checked by the caller).
    fn zeros(py: Python<'py>, n: usize, want: Want) -> Self {
        Self {
            positions: PyArray2::zeros(py, [n, 3], false),
            faces: PyArray1::zeros(py, n, false),
            barycentric: want.barycentric.then(|| PyArray2::zeros(py, [n, 3], false)),
            pdf: want.pdf.then(|| PyArray1::zeros(py, n, false)),
            normals: want.normal.then(|| PyArray2::zeros(py, [n, 3], false)),
        }
    }

    /// Runs `f` on the arrays without the GIL.
    fn fill<T: Send>(
        &self,
        py: Python<'py>,
        f: impl FnOnce(Slices<'_>) -> Result<T> + Send,
    ) -> PyResult<T> {
        let mut positions = self.positions.readwrite();
        let mut faces = self.faces.readwrite();
        let mut barycentric = self.barycentric.as_ref().map(|a| a.readwrite());
        let mut pdf = self.pdf.as_ref().map(|a| a.readwrite());
        let mut normals = self.normals.as_ref().map(|a| a.readwrite());
        let slices = Slices {
            positions: slice(&mut positions)?,
            faces: slice(&mut faces)?,
            barycentric: barycentric.as_mut().map(slice).transpose()?,
            pdf: pdf.as_mut().map(slice).transpose()?,
            normals: normals.as_mut().map(slice).transpose()?,
        };
        detached(py, || f(slices))
    }

    /// From points already drawn (blue noise).
    fn of(py: Python<'py>, points: &[SurfacePoint], origin: DVec3, want: Want) -> PyResult<Self> {
        let out = Self::zeros(py, points.len(), want);
        out.fill(py, |mut slices| {
            let sinks = Sinks::new(&mut slices, points.len().max(1));
            sinks.write(0, points, origin);
            Ok(())
        })?;
        Ok(out)
    }

    /// The Python tuple: `(points, face_index[, barycentric][, pdf][, normals])`.
    fn into_tuple(self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let mut items = vec![self.positions.into_any(), self.faces.into_any()];
        items.extend(self.barycentric.map(Bound::into_any));
        items.extend(self.pdf.map(Bound::into_any));
        items.extend(self.normals.map(Bound::into_any));
        PyTuple::new(py, items)
    }
}

/// The output arrays cut into blocks of `block` points, each behind its
/// own lock: the sampler's chunks (filled on several threads at once)
/// write their own blocks, so the locks are never contended when a
/// chunk is a block, and any chunk size stays correct.
struct Sinks<'a> {
    block: usize,
    positions: Vec<Mutex<&'a mut [f64]>>,
    faces: Vec<Mutex<&'a mut [i64]>>,
    barycentric: Option<Vec<Mutex<&'a mut [f64]>>>,
    pdf: Option<Vec<Mutex<&'a mut [f64]>>>,
    normals: Option<Vec<Mutex<&'a mut [f64]>>>,
}

fn blocks<T>(data: &mut [T], size: usize) -> Vec<Mutex<&mut [T]>> {
    data.chunks_mut(size.max(1)).map(Mutex::new).collect()
}

fn put<T, const K: usize>(
    parts: &[Mutex<&mut [T]>],
    block: usize,
    start: usize,
    values: impl Fn(usize) -> [T; K],
    len: usize,
) {
    let mut i = start;
    while i < start + len {
        let b = i / block;
        let end = (start + len).min((b + 1) * block);
        // A poisoned lock means another chunk panicked; that panic is
        // reported, so this chunk's values do not matter.
        let mut part = match parts[b].lock() {
            Ok(p) => p,
            Err(p) => p.into_inner(),
        };
        for k in i..end {
            let at = (k - b * block) * K;
            let v = values(k - start);
            for (slot, x) in part[at..at + K].iter_mut().zip(v) {
                *slot = x;
            }
        }
        i = end;
    }
}

impl<'a> Sinks<'a> {
    fn new(out: &'a mut Slices<'_>, block: usize) -> Self {
        Self {
            block,
            positions: blocks(out.positions, 3 * block),
            faces: blocks(out.faces, block),
            barycentric: out.barycentric.as_deref_mut().map(|b| blocks(b, 3 * block)),
            pdf: out.pdf.as_deref_mut().map(|p| blocks(p, block)),
            normals: out.normals.as_deref_mut().map(|n| blocks(n, 3 * block)),
        }
    }

    fn write(&self, start: usize, chunk: &[SurfacePoint], origin: DVec3) {
        let b = self.block;
        let n = chunk.len();
        put(
            &self.positions,
            b,
            start,
            |k| (origin + chunk[k].position.as_dvec3()).to_array(),
            n,
        );
        put(&self.faces, b, start, |k| [i64::from(chunk[k].face)], n);
        if let Some(s) = &self.barycentric {
            put(s, b, start, |k| chunk[k].barycentric.map(f64::from), n);
        }
        if let Some(s) = &self.pdf {
            put(s, b, start, |k| [f64::from(chunk[k].pdf)], n);
        }
        if let Some(s) = &self.normals {
            put(s, b, start, |k| chunk[k].normal.as_dvec3().to_array(), n);
        }
    }
}

/// The chunk size of mesh-sampling's batches (documented on
/// `SurfaceSampler`): blocks of this size take one lock per chunk.
const CHUNK: usize = 16_384;

fn draw<S: SurfaceSampler>(sampler: &S, seed: u64, origin: DVec3, out: &mut Slices<'_>) {
    let n = out.faces.len();
    let sinks = Sinks::new(out, CHUNK);
    sampler.sample_stream(seed, n, |start, chunk| sinks.write(start, chunk, origin));
}

/// `Ok` if `n` points fit in `mesh_sampling::MAX_POINTS`: the check
/// `sample_n` makes, before the arrays are allocated; the message is the
/// Python one (crate::error words mesh-sampling's for Python).
fn check_count(n: usize) -> Result<()> {
    if n as u64 > mesh_sampling::MAX_POINTS as u64 {
        return Err(mesh_sampling::Error::TooManyPoints {
            requested: n as f64,
            budget: mesh_sampling::MAX_POINTS,
        }
        .into());
    }
    Ok(())
}

/// Where the density comes from.
pub(crate) enum DensityArg {
    None,
    Texture(DensityTexture),
    PerFace(Vec<f32>),
    PerVertex(Vec<f32>),
}

fn channel_arg(channel: Option<&Bound<'_, PyAny>>, channels: usize) -> PyResult<Channel> {
    let Some(c) = channel else {
        return Ok(if channels >= 3 {
            Channel::Luminance
        } else {
            Channel::Index(0)
        });
    };
    let index = |i: i64| {
        if (0..channels as i64).contains(&i) {
            Ok(Channel::Index(i as usize))
        } else {
            Err(PyErr::from(Failure::input(format!(
                "channel: {i} is not a channel of a {channels}-channel density image (0..{})",
                channels - 1
            ))))
        }
    };
    if let Ok(i) = c.extract::<i64>() {
        return index(i);
    }
    let name: String = c.extract().map_err(|_| {
        Failure::input("channel: expected 'r', 'g', 'b', 'a', 'luminance' or an index")
    })?;
    let i = match name.to_ascii_lowercase().as_str() {
        "luminance" | "l" | "y" => return Ok(Channel::Luminance),
        "r" | "red" => 0,
        "g" | "green" => 1,
        "b" | "blue" => 2,
        "a" | "alpha" => 3,
        _ => {
            return Err(Failure::input(format!(
                "channel: {name:?} is not one of 'r', 'g', 'b', 'a', 'luminance'"
            ))
            .into());
        }
    };
    index(i)
}

/// The density texture of `density`: a path (read with its stored values,
/// no sRGB decoding, as `trilux sample --density` reads it) or an image
/// array (`(H, W)` weights or `(H, W, C)`; integer dtypes scaled to
/// `[0, 1]`), row 0 at the top (`v = 1` in OpenGL UVs).
fn density_texture(
    density: &Bound<'_, PyAny>,
    channel: Option<&Bound<'_, PyAny>>,
) -> PyResult<DensityTexture> {
    if arrays::is_path(density)? {
        let path = path_arg(density, "density")?;
        let options = trilux_io::image::ReadOptions {
            raw: true,
            ..Default::default()
        };
        let image = trilux_io::image::read_with(&path, options).map_err(Failure::from)?;
        let channel = channel_arg(channel, 4)?;
        return Ok(trilux::density_texture(&image, channel).map_err(Failure::from)?);
    }
    let a = arrays::image_array(density, "density")?;
    let channel = channel_arg(channel, a.channels)?;
    Ok(
        DensityTexture::from_channels(a.width, a.height, &a.values, a.channels, channel)
            .map_err(Failure::from)?,
    )
}

fn weights(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f32>> {
    Ok(arrays::values_f64(obj, what)?
        .into_iter()
        .map(|w| w as f32)
        .collect())
}

/// The density arguments of `sample_surface` and `blue_noise`: at most one
/// of `density`, `face_weight`, `vertex_weight`.
pub(crate) fn density_arg(
    density: Option<&Bound<'_, PyAny>>,
    channel: Option<&Bound<'_, PyAny>>,
    face_weight: Option<&Bound<'_, PyAny>>,
    vertex_weight: Option<&Bound<'_, PyAny>>,
) -> PyResult<DensityArg> {
    let given = [
        density.is_some(),
        face_weight.is_some(),
        vertex_weight.is_some(),
    ];
    if given.iter().filter(|&&g| g).count() > 1 {
        return Err(
            Failure::input("give at most one of density, face_weight and vertex_weight").into(),
        );
    }
    if channel.is_some() && density.is_none() {
        return Err(
            Failure::input("channel: only with density (an image or an image file)").into(),
        );
    }
    Ok(match (density, face_weight, vertex_weight) {
        (Some(d), _, _) => DensityArg::Texture(density_texture(d, channel)?),
        (_, Some(w), _) => DensityArg::PerFace(weights(w, "face_weight")?),
        (_, _, Some(w)) => DensityArg::PerVertex(weights(w, "vertex_weight")?),
        _ => DensityArg::None,
    })
}

/// A sampling method.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Method {
    Uniform,
    Subdivision,
    Exact,
    Rejection,
}

fn method_arg(method: Option<&str>, density: &DensityArg) -> Result<Method> {
    let m = match method {
        None => match density {
            DensityArg::None => Method::Uniform,
            DensityArg::Texture(_) => Method::Subdivision,
            DensityArg::PerFace(_) | DensityArg::PerVertex(_) => Method::Exact,
        },
        Some("uniform") => Method::Uniform,
        Some("subdivision") => Method::Subdivision,
        Some("exact") => Method::Exact,
        Some("rejection") => Method::Rejection,
        Some(other) => {
            return Err(Failure::input(format!(
                "method: {other:?} is not one of 'uniform', 'subdivision', 'exact', 'rejection'"
            )));
        }
    };
    match (m, density) {
        (Method::Uniform, DensityArg::None) => Ok(m),
        (Method::Uniform, _) => Err(Failure::input(
            "method='uniform' samples by area: drop the density, or choose 'subdivision' or 'exact'",
        )),
        (_, DensityArg::None) => Err(Failure::input(format!(
            "method={:?} needs a density (density=, face_weight= or vertex_weight=)",
            method.unwrap_or_default()
        ))),
        (
            Method::Subdivision | Method::Rejection,
            DensityArg::PerFace(_) | DensityArg::PerVertex(_),
        ) => Err(Failure::input(
            "face and vertex weights are sampled exactly: use method='exact' (or no method)",
        )),
        _ => Ok(m),
    }
}

/// Runs `f` on the sampler that `density` and `method` ask for.
fn with_sampler<T>(
    mesh: &TriMesh,
    density: &DensityArg,
    method: Method,
    f: impl FnOnce(Sampler<'_>) -> Result<T>,
) -> Result<T> {
    let mesh_ref = trilux::mesh_ref(mesh);
    let options = |mode| Options {
        mode,
        ..Options::default()
    };
    match (density, method) {
        (DensityArg::None, _) => f(Sampler::Uniform(UniformSampler::new(mesh_ref)?)),
        (DensityArg::Texture(t), Method::Rejection) => {
            f(Sampler::Rejection(RejectionSampler::new(mesh_ref, t)?))
        }
        (DensityArg::Texture(t), Method::Exact) => f(Sampler::Density(
            DensitySampler::with_options(mesh_ref, Density::Texture(t), &options(Mode::Exact))?,
        )),
        (DensityArg::Texture(t), _) => f(Sampler::Density(DensitySampler::with_options(
            mesh_ref,
            Density::Texture(t),
            &options(Mode::Approximate),
        )?)),
        (DensityArg::PerFace(w), _) => {
            // trimesh's meaning: face i with probability ∝ w_i, so the
            // density over the face is w_i / A_i (none on a face of no area).
            if w.len() != mesh.indices.len() {
                return Err(mesh_sampling::Error::WeightLength {
                    what: "face",
                    len: w.len(),
                    expected: mesh.indices.len(),
                }
                .into());
            }
            let per_area: Vec<f32> = w
                .iter()
                .enumerate()
                .map(|(f, &w)| {
                    let a = mesh_ref.area(f);
                    if a > 0.0 && w.is_finite() && w >= 0.0 {
                        (f64::from(w) / a) as f32
                    } else if a > 0.0 {
                        w
                    } else {
                        0.0
                    }
                })
                .collect();
            f(Sampler::Density(DensitySampler::new(
                mesh_ref,
                Density::PerFace(&per_area),
            )?))
        }
        (DensityArg::PerVertex(w), _) => f(Sampler::Density(DensitySampler::new(
            mesh_ref,
            Density::PerVertex(w),
        )?)),
    }
}

/// One of the samplers.
pub(crate) enum Sampler<'a> {
    Uniform(UniformSampler<'a>),
    Density(DensitySampler<'a>),
    Rejection(RejectionSampler<'a>),
}

/// Random points on a mesh, uniform by area or with a density
/// (Šik & Křivánek 2013, *Fast Random Sampling of Triangular Meshes*).
///
/// The call shape of `trimesh.sample.sample_surface(mesh, count)`:
/// returns `(points, face_index)`, `points` an `(count, 3)` float64 array
/// in the mesh's coordinates and `face_index` a `(count,)` int64 array,
/// then, in this order and only when asked, `barycentric` `(count, 3)`
/// float64, `pdf` `(count,)` float64 (density w.r.t. area, per mesh unit²,
/// for multiple importance sampling) and `normals` `(count, 3)` float64
/// (the triangles' geometric normals).
///
/// `mesh`: a `trilux.Mesh`, a `trimesh.Trimesh` (or anything with
/// `.vertices` and `.faces`; its `visual.uv` is used for a density
/// texture) or a `(vertices, faces)` pair. `density`: an image array
/// (`(H, W)` or `(H, W, C)`, row 0 at the top, integer dtypes scaled to
/// `[0, 1]`) or an image file (values as stored), looked up at the UVs
/// (`uv=`, `(n, 2)`, OpenGL convention, replaces the mesh's);
/// `channel` picks `'r'`, `'g'`, `'b'`, `'a'`, `'luminance'` (the default
/// for colour images, Rec. 709) or an index. `face_weight` `(m,)`:
/// trimesh's meaning, face `i` is chosen with probability proportional to
/// `face_weight[i]` (not multiplied by its area; uniform within it).
/// `vertex_weight` `(n,)`: a density per vertex, linear over each face
/// (probability ∝ density × area). Weights are finite and `>= 0`; both
/// are sampled exactly.
/// `method`: `'uniform'` (default without a density), `'subdivision'`
/// (the paper's adaptive subdivision, default with a texture), `'exact'`
/// (the bilinear density itself) or `'rejection'` (the paper's
/// baseline). `seed` (default 0): the same seed gives the same points, on
/// any number of threads, bit for bit the Rust `sample_n(seed, count)`.
///
/// Raises `trilux.InputError` (a `ValueError`) for bad arguments, meshes
/// or densities, with the Rust message; `trilux.FileError` for an
/// unreadable density file. The GIL is released while sampling.
#[pyfunction]
#[pyo3(signature = (mesh, count, *, density = None, uv = None, channel = None, face_weight = None,
    vertex_weight = None, method = None, seed = None, return_barycentric = false, return_pdf = false,
    return_normal = false))]
#[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
pub(crate) fn sample_surface<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    count: Int,
    density: Option<&Bound<'py, PyAny>>,
    uv: Option<&Bound<'py, PyAny>>,
    channel: Option<&Bound<'py, PyAny>>,
    face_weight: Option<&Bound<'py, PyAny>>,
    vertex_weight: Option<&Bound<'py, PyAny>>,
    method: Option<&str>,
    seed: Option<Int>,
    return_barycentric: bool,
    return_pdf: bool,
    return_normal: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let n = arrays::count(&count, "count")?;
    let seed = arrays::seed(seed.as_ref())?;
    let mesh: Arc<TriMesh> = mesh_arg(mesh, uv)?;
    let density = density_arg(density, channel, face_weight, vertex_weight)?;
    let method = method_arg(method, &density)?;
    let want = Want {
        barycentric: return_barycentric,
        pdf: return_pdf,
        normal: return_normal,
    };
    let origin = mesh.origin;
    check_count(n)?;
    let points = Points::zeros(py, n, want);
    points.fill(py, |mut out| {
        with_sampler(&mesh, &density, method, |s| {
            match &s {
                Sampler::Uniform(s) => draw(s, seed, origin, &mut out),
                Sampler::Density(s) => draw(s, seed, origin, &mut out),
                Sampler::Rejection(s) => draw(s, seed, origin, &mut out),
            }
            Ok(())
        })
    })?;
    points.into_tuple(py)
}

/// Blue-noise (Poisson-disk) points on a mesh that follow a density,
/// chosen among candidates from the sampler `sample_surface` would use.
///
/// `packing='dense'` (the default): weighted sample elimination (Yuksel
/// 2015, *Sample Elimination for Generating Poisson Disk Sample Sets*) of
/// `14 × count` candidates, then farthest-point relocation (the closest
/// points move into the largest holes among the candidates; after
/// Schlömer, Heck & Deussen 2011): relative radius ρ ≈ 0.76 on the data
/// meshes, as point-cloud-utils' and MeshLab's Poisson-disk sampling
/// (0.75–0.77). `packing='elimination'`: elimination of `5 × count`
/// candidates alone, ρ ≈ 0.69, about 6× faster (Open3D's
/// `sample_points_poisson_disk` is the same algorithm). ρ is half the
/// smallest distance between two points over the radius of a hexagonal
/// packing of as many disks (Lagae & Dutré 2008).
///
/// Give `count` (exactly this many points) or `radius` (the points of a
/// hexagonal packing of disks of this radius, in mesh units: neighbours
/// end up about `2 × radius` apart; point-cloud-utils'
/// `sample_mesh_poisson_disk(v, f, -1, radius=...)` is the same idea).
/// `density`, `uv`, `channel`, `face_weight`, `vertex_weight` and
/// `method` (`'subdivision'` or `'exact'`) as for `sample_surface`; with a
/// density the local spacing scales as `1/sqrt(density)`.
/// `progressive=True` orders the points so that every prefix of length
/// `count / 2**j` is itself well spread (Sec. 5; about twice the time;
/// with the dense packing the prefixes have elimination's spacing, the
/// whole set the dense one).
///
/// Returns `(points, face_index)`, `(N, 3)` float64 and `(N,)` int64, and
/// the optional arrays, as `sample_surface`; same seed, same points (bit
/// for bit Rust's `mesh_sampling::blue_noise` with
/// `BlueNoiseOptions::dense()` or `::default()`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (mesh, count = None, *, radius = None, density = None, uv = None, channel = None,
    face_weight = None, vertex_weight = None, method = None, seed = None, progressive = false,
    packing = None, return_barycentric = false, return_pdf = false, return_normal = false))]
#[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
pub(crate) fn blue_noise<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    count: Option<Int>,
    radius: Option<f64>,
    density: Option<&Bound<'py, PyAny>>,
    uv: Option<&Bound<'py, PyAny>>,
    channel: Option<&Bound<'py, PyAny>>,
    face_weight: Option<&Bound<'py, PyAny>>,
    vertex_weight: Option<&Bound<'py, PyAny>>,
    method: Option<&str>,
    seed: Option<Int>,
    progressive: bool,
    packing: Option<&str>,
    return_barycentric: bool,
    return_pdf: bool,
    return_normal: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let base = packing_options(packing)?;
    let target = match (count, radius) {
        (Some(c), None) => BlueNoiseTarget::Count(arrays::count(&c, "count")?),
        (None, Some(r)) => BlueNoiseTarget::Radius(radius_arg(r)?),
        _ => return Err(Failure::input("give exactly one of count and radius").into()),
    };
    let dense = base.packing == mesh_sampling::Packing::Dense;
    let seed = arrays::seed(seed.as_ref())?;
    let mesh = mesh_arg(mesh, uv)?;
    let density = density_arg(density, channel, face_weight, vertex_weight)?;
    let method = method_arg(method, &density)?;
    if method == Method::Rejection {
        return Err(Failure::input(
            "blue_noise: method='rejection' is not offered (use 'subdivision' or 'exact')",
        )
        .into());
    }
    let want = Want {
        barycentric: return_barycentric,
        pdf: return_pdf,
        normal: return_normal,
    };
    let options = BlueNoiseOptions {
        progressive,
        ..base
    };
    let origin = mesh.origin;
    let points = detached(py, || {
        with_sampler(&mesh, &density, method, |s| {
            match &s {
                Sampler::Uniform(s) => mesh_sampling::blue_noise(s, target, seed, &options),
                Sampler::Density(s) => mesh_sampling::blue_noise(s, target, seed, &options),
                Sampler::Rejection(_) => {
                    return Err(Failure::input("blue_noise: no rejection sampling"));
                }
            }
            .map_err(|e| blue_noise_failure(e, target, dense))
        })
    })?;
    Points::of(py, &points, origin, want)?.into_tuple(py)
}

/// A `radius` argument of `blue_noise` / `sample_surface_even`: finite and
/// positive, else an error naming it.
fn radius_arg(r: f64) -> Result<f64> {
    if r > 0.0 && r.is_finite() {
        Ok(r)
    } else {
        Err(Failure::input(format!(
            "radius: {r} is not a positive finite length (mesh units)"
        )))
    }
}

/// mesh-sampling's blue-noise errors in Python's words: its budget
/// messages name Rust options (`BlueNoiseOptions::max_memory_bytes`,
/// "fewer candidates per point"); here they name the argument the caller
/// gave (`asked`: `count` or `radius` as the caller gave it) and the
/// arguments that help.
fn blue_noise_failure(e: mesh_sampling::Error, asked: BlueNoiseTarget, dense: bool) -> Failure {
    let mesh_sampling::Error::InvalidOption(text) = &e else {
        return e.into();
    };
    let body = text.strip_prefix("blue noise: ").unwrap_or(text);
    let over_budget =
        body.contains("candidates need about") || body.contains("more than a run can index");
    if !over_budget {
        return Failure::input(format!("blue_noise: {body}"));
    }
    let body = body
        .replace(" (BlueNoiseOptions::max_memory_bytes)", "")
        .replace("; ask for fewer points or fewer candidates per point", "");
    let (argument, remedy) = match asked {
        BlueNoiseTarget::Count(n) => (format!("count={n}"), "ask for fewer points (count)"),
        BlueNoiseTarget::Radius(r) => (format!("radius={r}"), "use a larger radius"),
    };
    // Fewer candidates per point help a run that is over the memory
    // budget, not one that asks for more points than a run can index.
    let elimination = if dense && body.contains("candidates need about") {
        ", or packing='elimination' (5 candidates per point instead of 14)"
    } else {
        ""
    };
    Failure::input(format!("{argument}: {body}; {remedy}{elimination}"))
}

/// The options of `packing` (`None` is the dense packing).
fn packing_options(packing: Option<&str>) -> std::result::Result<BlueNoiseOptions, Failure> {
    match packing {
        None | Some("dense") => Ok(BlueNoiseOptions::dense()),
        Some("elimination") => Ok(BlueNoiseOptions::default()),
        Some(other) => Err(Failure::input(format!(
            "blue_noise: packing='{other}' is not a packing (use 'dense' or 'elimination')"
        ))),
    }
}

/// Evenly spread points, in trimesh's shape
/// (`trimesh.sample.sample_surface_even(mesh, count, radius=None,
/// seed=None)` → `(points, face_index)`), by `blue_noise` with its
/// default (dense) packing: exactly `count`
/// points when `radius` is `None`; with `radius` (the smallest distance
/// between points, as trimesh means it) the points of disks of radius
/// `radius / 2`, progressively ordered and cut to at most `count`.
#[pyfunction]
#[pyo3(signature = (mesh, count, radius = None, seed = None))]
pub(crate) fn sample_surface_even<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    count: Int,
    radius: Option<f64>,
    seed: Option<Int>,
) -> PyResult<Bound<'py, PyTuple>> {
    let n = arrays::count(&count, "count")?;
    let seed = arrays::seed(seed.as_ref())?;
    let mesh = mesh_arg(mesh, None)?;
    // What the caller asked for (trimesh's radius is the distance between
    // points), for the messages; and what blue_noise is given.
    let (asked, target, progressive) = match radius {
        None => (BlueNoiseTarget::Count(n), BlueNoiseTarget::Count(n), false),
        Some(r) => {
            let r = radius_arg(r)?;
            (
                BlueNoiseTarget::Radius(r),
                BlueNoiseTarget::Radius(r / 2.0),
                true,
            )
        }
    };
    let options = BlueNoiseOptions {
        progressive,
        ..BlueNoiseOptions::dense()
    };
    let origin = mesh.origin;
    let points = detached(py, || {
        let sampler = UniformSampler::new(trilux::mesh_ref(&mesh))?;
        let mut points = mesh_sampling::blue_noise(&sampler, target, seed, &options)
            .map_err(|e| blue_noise_failure(e, asked, true))?;
        points.truncate(n);
        Ok(points)
    })?;
    Points::of(py, &points, origin, Want::default())?.into_tuple(py)
}

/// Points scattered by rate (mesh-sampling's `scatter`, the meaning of
/// "density" in Blender's Distribute Points on Faces and Houdini's
/// Scatter): a Poisson process of `rate × density` points per unit area
/// (mesh units), so the count is random, about `rate × ∫ density dA`.
/// `rate` and `max_density` must be positive (0 is an `InputError`, as in
/// `trilux sample --rate` and the paint page).
///
/// Each face draws Poisson(`rate × max_density × area`) candidates from
/// its own stream, seeded by `seed` and the face index, each with a fixed
/// threshold; a candidate is kept where the density beats it. So the
/// points on a face depend only on the seed, the face and the density on
/// it: editing the density elsewhere leaves them bit for bit, raising it
/// only adds points and lowering it only removes them (state
/// `max_density` for that: candidates depend on it).
///
/// `density`: an image array or file looked up at the UVs (`uv=`,
/// `channel=` as for `sample_surface`); `face_density` `(m,)`: a density
/// per face (points per unit area × value, unlike `sample_surface`'s
/// `face_weight`); `vertex_density` `(n,)`: per vertex, linear over each
/// face; none: density 1. `max_density`: the density's ceiling (default:
/// its own maximum, 1 without a density); a value above it is an
/// `InputError` naming the face, or with `clamp=True` counts as the
/// ceiling.
///
/// Returns `(points, face_index)`, `(N, 3)` float64 and `(N,)` int64, in
/// face order, and the optional arrays as `sample_surface` (the pdf is
/// the intensity `rate × density` at each point, points per unit area).
/// Bit for bit Rust's `mesh_sampling::scatter` with the same options; the
/// same on any number of threads. The GIL is released.
#[pyfunction]
#[pyo3(signature = (mesh, rate, *, density = None, uv = None, channel = None, face_density = None,
    vertex_density = None, max_density = None, clamp = false, seed = None,
    return_barycentric = false, return_pdf = false, return_normal = false))]
#[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
pub(crate) fn scatter<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    rate: f64,
    density: Option<&Bound<'py, PyAny>>,
    uv: Option<&Bound<'py, PyAny>>,
    channel: Option<&Bound<'py, PyAny>>,
    face_density: Option<&Bound<'py, PyAny>>,
    vertex_density: Option<&Bound<'py, PyAny>>,
    max_density: Option<f64>,
    clamp: bool,
    seed: Option<Int>,
    return_barycentric: bool,
    return_pdf: bool,
    return_normal: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let seed = arrays::seed(seed.as_ref())?;
    let mesh = mesh_arg(mesh, uv)?;
    let given = [density, face_density, vertex_density];
    if given.iter().flatten().count() > 1 {
        return Err(
            Failure::input("give at most one of density, face_density and vertex_density").into(),
        );
    }
    let density = match (face_density, vertex_density) {
        (Some(w), _) => DensityArg::PerFace(weights(w, "face_density")?),
        (_, Some(w)) => DensityArg::PerVertex(weights(w, "vertex_density")?),
        _ => density_arg(density, channel, None, None)?,
    };
    if channel.is_some() && !matches!(density, DensityArg::Texture(_)) {
        return Err(
            Failure::input("channel: only with density (an image or an image file)").into(),
        );
    }
    let want = Want {
        barycentric: return_barycentric,
        pdf: return_pdf,
        normal: return_normal,
    };
    check_rate(rate, max_density)?;
    let options = mesh_sampling::ScatterOptions {
        max_density,
        clamp,
        seed,
        ..mesh_sampling::ScatterOptions::new(rate)
    };
    let origin = mesh.origin;
    let points = detached(py, || {
        let mesh_ref = trilux::mesh_ref(&mesh);
        let density = match &density {
            DensityArg::None => mesh_sampling::ScatterDensity::Uniform,
            DensityArg::Texture(t) => Density::Texture(t).into(),
            DensityArg::PerFace(w) => Density::PerFace(w).into(),
            DensityArg::PerVertex(w) => Density::PerVertex(w).into(),
        };
        mesh_sampling::scatter(mesh_ref, density, &options).map_err(|e| scatter_failure(e, rate))
    })?;
    Points::of(py, &points, origin, want)?.into_tuple(py)
}

/// `rate` and `max_density` positive, as `trilux sample --rate R
/// --max-density M` and the paint page take them: a rate of 0 (or a
/// ceiling of 0, which leaves no density to sample) is a mistake to tell,
/// not an empty result (the library itself takes 0).
fn check_rate(rate: f64, max_density: Option<f64>) -> PyResult<()> {
    if !(rate.is_finite() && rate > 0.0) {
        return Err(Failure::input(format!(
            "rate: {rate} must be a positive number (points per unit area)"
        ))
        .into());
    }
    if let Some(m) = max_density.filter(|m| !(m.is_finite() && *m > 0.0)) {
        return Err(Failure::input(format!(
            "max_density: {m} must be a positive number (leave it out for the density's own \
             maximum)"
        ))
        .into());
    }
    Ok(())
}

/// mesh-sampling's scatter errors in Python's words: the rate and the
/// ceiling by their argument names.
fn scatter_failure(e: mesh_sampling::Error, rate: f64) -> Failure {
    use mesh_sampling::Error as E;
    match e {
        E::InvalidDensity(r) => Failure::input(format!(
            "rate: {r} is not a finite number >= 0 (points per unit area)"
        )),
        E::InvalidMaxDensity(m) => {
            Failure::input(format!("max_density: {m} is not a finite number >= 0"))
        }
        E::TooManyPoints { requested, budget } => Failure::input(format!(
            "rate: {rate} per unit area asks for about {requested:.0} candidates (rate × \
             max_density × area), more than one call returns (at most {budget}); lower the rate \
             or max_density"
        )),
        e => e.into(),
    }
}
