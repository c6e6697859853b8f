//! Light sampling for renderers: `Emitter`, an emissive mesh sampled by
//! area, per-triangle power or emitted power inside triangles (Šik &
//! Křivánek 2013, Sec. 5.3), with radiance and pdfs in area and solid-angle
//! measure, over mesh-sampling's `Emitter`.
//!
//! The Rust `Emitter` borrows its mesh and texture, so it lives on a
//! thread of its own that owns them: built once there, it answers each
//! call's job (a closure run against it) until the Python object is
//! dropped, when the thread ends. Calls wait for their job without the
//! GIL.

use std::sync::Arc;
use std::sync::mpsc;

use glam::{DVec3, Vec3};
use mesh_sampling::{
    Emission, EmissionTexture, Emitter as RustEmitter, EmitterOptions, Filter, LightSample, Sides,
    Strategy, Wrap,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use trilux_io::mesh::TriMesh;

use crate::arrays::{self, Int};
use crate::error::{Failure, Kind, Result, chain, guarded};
use crate::mesh::{image_from, mesh_arg, path_arg};

/// A call's work, run on the emitter's thread.
type Job = Box<dyn for<'a> FnOnce(&RustEmitter<'a>) + Send>;

/// What the emitter's thread owns besides the mesh.
enum Source {
    Texture(EmissionTexture, f32),
    PerFace(Vec<[f32; 3]>),
}

/// What a built emitter reports once.
#[derive(Debug, Clone)]
struct Info {
    power: f64,
    triangle_power: Vec<f64>,
    defensive_fraction: f64,
}

/// An emissive mesh for a renderer's light sampling (next-event estimation
/// and multiple importance sampling), after Šik & Křivánek 2013, Sec. 5.3:
/// a luminaire that is a mesh with an image as its emission.
///
/// `mesh`: a `trilux.Mesh`, a `trimesh.Trimesh` (its `visual.uv` is used)
/// or a `(vertices, faces)` pair; `uv=` `(n, 2)` (OpenGL convention)
/// replaces its UVs. The emission is one of: `emission`, an image of
/// linear RGB radiance — an array `(H, W)`, `(H, W, 3)` or `(H, W, 4)`
/// (row 0 at the top; float values as they are, integer images scaled to
/// `[0, 1]` and decoded from sRGB; alpha ignored) or an image file (EXR and
/// HDR as stored, PNG and JPEG decoded from sRGB) — looked up at the UVs
/// (`filter` `'bilinear'` (default) or `'nearest'`; `wrap` `'repeat'`
/// (default), `'mirror'` or `'clamp'`) and multiplied by `scale`; or `face_radiance`, `(m, 3)` RGB radiance per
/// face. Radiance in your unit, lengths in the mesh's.
///
/// `strategy`: `'area'` (uniform by area, pbrt's and LuxCore's),
/// `'triangle-power'` (a triangle by its emitted power, uniform inside:
/// Falcor's, Cycles'), `'texture'` (default: by emitted power inside
/// triangles, the paper's subdivision) or `'texture-exact'` (exactly by
/// the luminance of the radiance). `two_sided=False` (default) emits from
/// the side the geometric normal points to (counter-clockwise corners).
///
/// Raises `trilux.InputError` for a bad mesh, emission or argument, with
/// the Rust message; `trilux.FileError` for an unreadable image. Building
/// and sampling release the GIL.
#[pyclass(module = "trilux", frozen)]
pub(crate) struct Emitter {
    jobs: mpsc::Sender<Job>,
    /// The process whose thread holds the emitter (a forked child has
    /// no such thread: a call there would wait forever).
    process: u32,
    origin: DVec3,
    faces: usize,
    strategy: Strategy,
    two_sided: bool,
    info: Info,
}

fn stopped() -> Failure {
    Failure {
        kind: Kind::Internal,
        message: "internal error (a bug in trilux, please report it): the emitter's thread stopped"
            .into(),
    }
}

fn strategy_arg(strategy: Option<&str>) -> Result<Strategy> {
    match strategy {
        None => Ok(Strategy::default()),
        Some(name) => Strategy::from_name(name).ok_or_else(|| {
            Failure::input(format!(
                "strategy: {name:?} is not one of 'area', 'triangle-power', 'texture', \
                 'texture-exact'"
            ))
        }),
    }
}

fn filter_arg(filter: Option<&str>) -> Result<Filter> {
    match filter {
        None | Some("bilinear") => Ok(Filter::Bilinear),
        Some("nearest") => Ok(Filter::Nearest),
        Some(other) => Err(Failure::input(format!(
            "filter: {other:?} is not one of 'bilinear', 'nearest'"
        ))),
    }
}

fn wrap_arg(wrap: Option<&str>) -> Result<Wrap> {
    match wrap {
        None | Some("repeat") => Ok(Wrap::Repeat),
        Some("mirror") => Ok(Wrap::MirroredRepeat),
        Some("clamp") => Ok(Wrap::ClampToEdge),
        Some(other) => Err(Failure::input(format!(
            "wrap: {other:?} is not one of 'repeat', 'mirror', 'clamp'"
        ))),
    }
}

/// The emission texture of `emission`: an image file or an image array.
fn texture_arg(emission: &Bound<'_, PyAny>) -> PyResult<EmissionTexture> {
    let image = if arrays::is_path(emission)? {
        let path = path_arg(emission, "emission")?;
        Failure::if_directory(&path, "an image")?;
        trilux_io::image::read(&path).map_err(Failure::from)?
    } else {
        image_from(emission, "emission", true)?
    };
    Ok(trilux::emission_texture(&image).map_err(Failure::from)?)
}

/// `(n, 3)` points (one per row) or one `(3,)` point for all `n`, made
/// relative to `origin` (the mesh's shift) in `f64`, then `f32`.
/// `toward(face, barycentric, reference)` for each hit when reference
/// points are given, else `alone(face, barycentric)`.
fn per_hit<T>(
    faces: &[usize],
    bary: &[[f32; 3]],
    references: Option<&[Vec3]>,
    toward: impl Fn(usize, [f32; 3], Vec3) -> T,
    alone: impl Fn(usize, [f32; 3]) -> T,
) -> Vec<T> {
    match references {
        Some(r) => faces
            .iter()
            .zip(bary)
            .zip(r)
            .map(|((&f, &b), &x)| toward(f, b, x))
            .collect(),
        None => faces.iter().zip(bary).map(|(&f, &b)| alone(f, b)).collect(),
    }
}

fn points_arg(obj: &Bound<'_, PyAny>, what: &str, n: usize, origin: DVec3) -> PyResult<Vec<Vec3>> {
    let np = obj.py().import("numpy")?;
    let ndim: usize = np
        .call_method1("ndim", (obj,))
        .and_then(|d| d.extract())
        .unwrap_or(2);
    let rows: Vec<[f64; 3]> = if ndim == 1 {
        let v = arrays::values_f64(obj, what)?;
        let p: [f64; 3] = v.try_into().map_err(|v: Vec<f64>| {
            Failure::input(format!(
                "{what}: expected a point (3,) or points (n, 3), got {} values",
                v.len()
            ))
        })?;
        vec![p; n]
    } else {
        arrays::rows_f64::<3>(obj, what)?
    };
    if rows.len() != n {
        return Err(Failure::input(format!(
            "{what}: {} points for {n} samples (give one point, or one per sample)",
            rows.len()
        ))
        .into());
    }
    if let Some(k) = rows.iter().position(|r| !r.iter().all(|x| x.is_finite())) {
        return Err(Failure::input(format!("{what}: row {k} is not finite")).into());
    }
    Ok(rows
        .iter()
        .map(|&r| (DVec3::from_array(r) - origin).as_vec3())
        .collect())
}

impl Emitter {
    /// Runs `f` against the emitter on its thread, without the GIL.
    fn run<T: Send + 'static>(
        &self,
        py: Python<'_>,
        f: impl for<'a> FnOnce(&RustEmitter<'a>) -> Result<T> + Send + 'static,
    ) -> PyResult<T> {
        if std::process::id() != self.process {
            return Err(Failure::input(
                "this Emitter was made in another process (before a fork): make it in the \
                 process that uses it",
            )
            .into());
        }
        let (tx, rx) = mpsc::channel();
        let job: Job = Box::new(move |e| {
            let _ = tx.send(guarded(|| f(e)));
        });
        let jobs = &self.jobs;
        py.detach(move || {
            jobs.send(job).map_err(|_| stopped())?;
            rx.recv().map_err(|_| stopped())?
        })
        .map_err(PyErr::from)
    }

    /// `face_index` `(n,)` and `barycentric` `(n, 3)` of the same length,
    /// faces checked in range.
    /// [`hits_arg`](Self::hits_arg) and, when given, one reference
    /// point per hit (`reference_points`: one `(3,)` or `(n, 3)`).
    #[allow(
        clippy::type_complexity,
        reason = "three parallel arrays, named at the call"
    )]
    fn hits_toward(
        &self,
        face_index: &Bound<'_, PyAny>,
        barycentric: &Bound<'_, PyAny>,
        reference_points: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(Vec<usize>, Vec<[f32; 3]>, Option<Vec<Vec3>>)> {
        let (faces, bary) = self.hits_arg(face_index, barycentric)?;
        let references = reference_points
            .map(|r| points_arg(r, "reference_points", faces.len(), self.origin))
            .transpose()?;
        Ok((faces, bary, references))
    }

    fn hits_arg(
        &self,
        face_index: &Bound<'_, PyAny>,
        barycentric: &Bound<'_, PyAny>,
    ) -> PyResult<(Vec<usize>, Vec<[f32; 3]>)> {
        let faces = self.faces_arg(face_index)?;
        let bary = arrays::rows_f64::<3>(barycentric, "barycentric")?;
        if bary.len() != faces.len() {
            return Err(Failure::input(format!(
                "barycentric: {} rows for {} entries of face_index",
                bary.len(),
                faces.len()
            ))
            .into());
        }
        Ok((faces, bary.iter().map(|b| b.map(|x| x as f32)).collect()))
    }

    /// `face_index` `(n,)`, each checked to be a face of the mesh.
    fn faces_arg(&self, face_index: &Bound<'_, PyAny>) -> PyResult<Vec<usize>> {
        arrays::values_i64(face_index, "face_index")?
            .iter()
            .enumerate()
            .map(|(k, &f)| {
                usize::try_from(f)
                    .ok()
                    .filter(|&f| f < self.faces)
                    .ok_or_else(|| {
                        PyErr::from(Failure::input(format!(
                            "face_index: entry {k} is {f}, not a face of the mesh (0..{})",
                            self.faces.saturating_sub(1)
                        )))
                    })
            })
            .collect()
    }
}

/// A vector of `[f32; K]` rows as an `(n, K)` float64 array.
fn rows_out<'py, const K: usize>(
    py: Python<'py>,
    rows: impl Iterator<Item = [f32; K]>,
) -> PyResult<Bound<'py, PyAny>> {
    let data: Vec<f64> = rows.flat_map(|r| r.map(f64::from)).collect();
    arrays::matrix(py, data, K)
}

/// The arrays of samples every sampling call returns: `positions`,
/// `normals`, `shading_normals`, `face_index`, `barycentric`, `radiance`
/// (of the emitting side) and `pdf_area`.
fn samples_dict<'py>(
    py: Python<'py>,
    samples: &[LightSample],
    origin: DVec3,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let data: Vec<f64> = samples
        .iter()
        .flat_map(|s| (origin + s.point.position.as_dvec3()).to_array())
        .collect();
    out.set_item("positions", arrays::matrix(py, data, 3)?)?;
    out.set_item(
        "normals",
        rows_out(py, samples.iter().map(|s| s.point.normal.to_array()))?,
    )?;
    out.set_item(
        "shading_normals",
        rows_out(
            py,
            samples
                .iter()
                .map(|s| s.point.shading_normal.unwrap_or(s.point.normal).to_array()),
        )?,
    )?;
    let faces: Vec<i64> = samples.iter().map(|s| i64::from(s.point.face)).collect();
    out.set_item("face_index", arrays::vector(py, faces))?;
    out.set_item(
        "barycentric",
        rows_out(py, samples.iter().map(|s| s.point.barycentric))?,
    )?;
    out.set_item(
        "radiance",
        rows_out(py, samples.iter().map(|s| s.radiance))?,
    )?;
    let pdf: Vec<f64> = samples.iter().map(|s| f64::from(s.pdf_area())).collect();
    out.set_item("pdf_area", arrays::vector(py, pdf))?;
    Ok(out)
}

#[pymethods]
impl Emitter {
    #[new]
    #[pyo3(signature = (mesh, emission = None, *, face_radiance = None, uv = None, scale = 1.0,
        strategy = None, two_sided = false, wrap = None, filter = None))]
    #[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
    fn new(
        py: Python<'_>,
        mesh: &Bound<'_, PyAny>,
        emission: Option<&Bound<'_, PyAny>>,
        face_radiance: Option<&Bound<'_, PyAny>>,
        uv: Option<&Bound<'_, PyAny>>,
        scale: f64,
        strategy: Option<&str>,
        two_sided: bool,
        wrap: Option<&str>,
        filter: Option<&str>,
    ) -> PyResult<Self> {
        let strategy = strategy_arg(strategy)?;
        let image_options = scale != 1.0 || wrap.is_some() || filter.is_some();
        let wrap = wrap_arg(wrap)?;
        let filter = filter_arg(filter)?;
        let mesh: Arc<TriMesh> = mesh_arg(mesh, uv)?;
        let source = match (emission, face_radiance) {
            (Some(e), None) => {
                if !(scale.is_finite() && scale >= 0.0 && scale <= f64::from(f32::MAX)) {
                    return Err(Failure::input(format!(
                        "scale: {scale} is not a finite factor >= 0"
                    ))
                    .into());
                }
                let texture = texture_arg(e)?.with_wrap(wrap).with_filter(filter);
                Source::Texture(texture, scale as f32)
            }
            (None, Some(r)) => {
                if image_options {
                    return Err(Failure::input(
                        "scale, wrap and filter apply to an emission image, not to face_radiance",
                    )
                    .into());
                }
                let rows = arrays::rows_f64::<3>(r, "face_radiance")?;
                Source::PerFace(rows.iter().map(|c| c.map(|x| x as f32)).collect())
            }
            _ => {
                return Err(Failure::input(
                    "give exactly one of emission (an image) and face_radiance ((m, 3) per face)",
                )
                .into());
            }
        };
        let options = EmitterOptions {
            strategy,
            sides: if two_sided { Sides::Both } else { Sides::Front },
            ..Default::default()
        };
        let (jobs, queue) = mpsc::channel::<Job>();
        let (ready, built) = mpsc::channel::<Result<Info>>();
        let origin = mesh.origin;
        let faces = mesh.indices.len();
        std::thread::Builder::new()
            .name("trilux-emitter".into())
            .spawn(move || {
                let mesh_ref = trilux::mesh_ref(&mesh);
                let emission = match &source {
                    Source::Texture(t, scale) => Emission::Texture {
                        texture: t,
                        scale: *scale,
                    },
                    Source::PerFace(rgb) => Emission::PerFace(rgb),
                };
                let built = guarded(|| {
                    let e = RustEmitter::new(mesh_ref, emission, &options)?;
                    let info = Info {
                        power: e.power(),
                        triangle_power: (0..mesh_ref.indices.len())
                            .map(|f| e.triangle_power(f).unwrap_or(0.0))
                            .collect(),
                        defensive_fraction: e.defensive_fraction(),
                    };
                    Ok((e, info))
                });
                let emitter = match built {
                    Ok((e, info)) => {
                        let _ = ready.send(Ok(info));
                        e
                    }
                    Err(f) => {
                        let _ = ready.send(Err(f));
                        return;
                    }
                };
                for job in queue {
                    job(&emitter);
                }
            })
            .map_err(|e| Failure {
                kind: Kind::Internal,
                message: format!("could not start the emitter's thread: {e}"),
            })?;
        let info = py
            .detach(move || built.recv().map_err(|_| stopped())?)
            .map_err(PyErr::from)?;
        Ok(Self {
            jobs,
            process: std::process::id(),
            origin,
            faces,
            strategy,
            two_sided,
            info,
        })
    }

    /// The total emitted power, `sides · π · ∫ Y(Le) dA` (Rec. 709
    /// luminance, the texture integrated exactly).
    #[getter]
    fn power(&self) -> f64 {
        self.info.power
    }

    /// The strategy's name.
    #[getter]
    fn strategy(&self) -> &'static str {
        self.strategy.name()
    }

    /// Whether both sides emit.
    #[getter]
    fn two_sided(&self) -> bool {
        self.two_sided
    }

    /// The share of `'texture'`'s points drawn by triangle power (when the
    /// image has black texels), else 0.
    #[getter]
    fn defensive_fraction(&self) -> f64 {
        self.info.defensive_fraction
    }

    /// The power emitted by each triangle, `(m,)` float64: the weights of
    /// a light BVH or light tree.
    fn triangle_power<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(py, self.info.triangle_power.clone())
    }

    /// `n` points drawn on the emitter with `seed` (default 0; the same on
    /// any number of threads), as a dict of arrays: `positions` `(n, 3)`,
    /// `normals` `(n, 3)` (geometric, the ones the pdfs use),
    /// `shading_normals` `(n, 3)` (interpolated, or the geometric ones
    /// when the mesh has none), `face_index` `(n,)` int64, `barycentric`
    /// `(n, 3)`, `radiance` `(n, 3)` (`Le` of the emitting side) and
    /// `pdf_area` `(n,)` (per mesh unit²). With `reference_points` (one
    /// point `(3,)`, or `(n, 3)` one per sample: the shading points) also
    /// `direction` `(n, 3)` (unit, from the reference point to the light
    /// point), `distance` `(n,)` and `pdf_solid_angle` `(n,)` (`pdf_area ·
    /// d² / |cos θ_l|`), and `radiance` is what arrives there: 0, like the
    /// pdf, from the back of a one-sided emitter (skip those samples).
    #[pyo3(signature = (n, reference_points = None, *, seed = None))]
    fn sample<'py>(
        &self,
        py: Python<'py>,
        n: Int,
        reference_points: Option<&Bound<'py, PyAny>>,
        seed: Option<Int>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let n = arrays::count(&n, "n")?;
        let seed = arrays::seed(seed.as_ref())?;
        let references = reference_points
            .map(|r| points_arg(r, "reference_points", n, self.origin))
            .transpose()?;
        let with_references = references.is_some();
        let (samples, toward) = self.run(py, move |e| {
            let samples = e.sample_n(seed, n)?;
            let toward: Vec<_> = match &references {
                Some(r) => samples
                    .iter()
                    .zip(r)
                    .map(|(s, &x)| e.toward(s, x))
                    .collect(),
                None => Vec::new(),
            };
            Ok((samples, toward))
        })?;
        let out = samples_dict(py, &samples, self.origin)?;
        if with_references {
            // What arrives at the reference points: 0 from the back.
            out.set_item("radiance", rows_out(py, toward.iter().map(|t| t.radiance))?)?;
            out.set_item(
                "direction",
                rows_out(py, toward.iter().map(|t| t.direction.to_array()))?,
            )?;
            let d: Vec<f64> = toward.iter().map(|t| f64::from(t.distance)).collect();
            out.set_item("distance", arrays::vector(py, d))?;
            let p: Vec<f64> = toward
                .iter()
                .map(|t| f64::from(t.pdf_solid_angle))
                .collect();
            out.set_item("pdf_solid_angle", arrays::vector(py, p))?;
        }
        Ok(out)
    }

    /// The density with which this emitter draws the points at
    /// `barycentric` `(n, 3)` of faces `face_index` `(n,)` (a BSDF-sampled
    /// ray's hits), `(n,)` float64: in solid angle at `reference_points`
    /// (one `(3,)` or `(n, 3)`, the rays' origins) when given — `pdf_area ·
    /// d² / |cos θ_l|`, 0 from the back of a one-sided emitter, exactly what
    /// `sample` returns for a sample there — else in area. No UV inversion,
    /// no extra ray: overlapping and tiled UVs are fine.
    #[pyo3(signature = (face_index, barycentric, reference_points = None))]
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        face_index: &Bound<'py, PyAny>,
        barycentric: &Bound<'py, PyAny>,
        reference_points: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (faces, bary, references) =
            self.hits_toward(face_index, barycentric, reference_points)?;
        let pdf = self.run(py, move |e| {
            Ok(per_hit(
                &faces,
                &bary,
                references.as_deref(),
                |f, b, x| f64::from(e.pdf_solid_angle(f, b, x)),
                |f, b| f64::from(e.pdf_area(f, b)),
            ))
        })?;
        Ok(arrays::vector(py, pdf))
    }

    /// The radiance `Le` `(n, 3)` leaving `barycentric` `(n, 3)` of faces
    /// `face_index` `(n,)`: toward `reference_points` (one `(3,)` or
    /// `(n, 3)`) when given, 0 from the back of a one-sided emitter.
    #[pyo3(signature = (face_index, barycentric, reference_points = None))]
    fn radiance<'py>(
        &self,
        py: Python<'py>,
        face_index: &Bound<'py, PyAny>,
        barycentric: &Bound<'py, PyAny>,
        reference_points: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (faces, bary, references) =
            self.hits_toward(face_index, barycentric, reference_points)?;
        let le = self.run(py, move |e| {
            Ok(per_hit(
                &faces,
                &bary,
                references.as_deref(),
                |f, b, x| e.radiance_toward(f, b, x),
                |f, b| e.radiance(f, b),
            ))
        })?;
        rows_out(py, le.into_iter())
    }

    /// Points inside given triangles, for a renderer that picks the
    /// triangle itself (a light BVH or light tree weighted by
    /// `triangle_power()`): one point of face `face_index[k]` for the
    /// variates `u[k]` (`(n, 2)` in `[0, 1)`, stratified or
    /// low-discrepancy welcome), distributed inside the triangle as the
    /// strategy does (uniformly for `'area'` and `'triangle-power'`, by the
    /// emission for the texture strategies). The dict of `sample` without
    /// a reference point; its `pdf_area` is the density **given the
    /// triangle**: multiply by your probability of choosing it.
    fn sample_in_triangle<'py>(
        &self,
        py: Python<'py>,
        face_index: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let faces = self.faces_arg(face_index)?;
        let u = arrays::rows_f64::<2>(u, "u")?;
        if u.len() != faces.len() {
            return Err(Failure::input(format!(
                "u: {} rows for {} entries of face_index",
                u.len(),
                faces.len()
            ))
            .into());
        }
        if let Some(k) = u
            .iter()
            .position(|r| !r.iter().all(|x| (0.0..1.0).contains(x)))
        {
            return Err(Failure::input(format!(
                "u: row {k} is [{}, {}], not in [0, 1)²",
                u[k][0], u[k][1]
            ))
            .into());
        }
        let samples = self.run(py, move |e| {
            faces
                .iter()
                .zip(&u)
                .enumerate()
                .map(|(k, (&f, &u))| {
                    e.sample_in_triangle(f, u).map_err(|err| {
                        Failure::input(format!("face_index: entry {k}: {}", chain(&err)))
                    })
                })
                .collect::<Result<Vec<LightSample>>>()
        })?;
        samples_dict(py, &samples, self.origin)
    }

    /// The density `(n,)` (per mesh unit², given the triangle) with which
    /// `sample_in_triangle` draws the points at `barycentric` `(n, 3)` of
    /// faces `face_index` `(n,)`: exactly the `pdf_area` its samples carry.
    fn pdf_in_triangle<'py>(
        &self,
        py: Python<'py>,
        face_index: &Bound<'py, PyAny>,
        barycentric: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let (faces, bary) = self.hits_arg(face_index, barycentric)?;
        let pdf = self.run(py, move |e| {
            Ok(faces
                .iter()
                .zip(&bary)
                .map(|(&f, &b)| f64::from(e.pdf_in_triangle(f, b)))
                .collect::<Vec<f64>>())
        })?;
        Ok(arrays::vector(py, pdf))
    }

    /// Every triangle's bounding box and geometric normal, for a light
    /// BVH: `(lower, upper, normal)`, three `(m, 3)` float64 arrays (the
    /// normal is the emitting side's of a one-sided emitter; zero for a
    /// degenerate triangle).
    fn triangle_bounds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let bounds = self.run(py, |e| {
            (0..e.mesh().indices.len())
                .map(|f| e.triangle_bounds(f).map_err(Failure::from))
                .collect::<Result<Vec<_>>>()
        })?;
        let origin = self.origin;
        let corner = |p: Vec3| (origin + p.as_dvec3()).to_array();
        let lower: Vec<f64> = bounds.iter().flat_map(|b| corner(b.min)).collect();
        let upper: Vec<f64> = bounds.iter().flat_map(|b| corner(b.max)).collect();
        PyTuple::new(
            py,
            [
                arrays::matrix(py, lower, 3)?,
                arrays::matrix(py, upper, 3)?,
                rows_out(py, bounds.iter().map(|b| b.normal.to_array()))?,
            ],
        )
    }

    fn __repr__(&self) -> String {
        format!(
            "trilux.Emitter({} faces, strategy={:?}, two_sided={}, power={})",
            self.faces,
            self.strategy.name(),
            if self.two_sided { "True" } else { "False" },
            self.info.power
        )
    }
}
