//! TransCut (Li et al., *TransCut: Interactive Rendering of Translucent
//! Cutouts*): the diffusion approximation of subsurface scattering solved
//! on a tetrahedral mesh, lit, cut, painted, fractured and rendered.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use tet_diffusion::{Cut, Light, Medium, Stroke};

use crate::arrays::{self, Int};
use crate::error::{Failure, detached};
use crate::mesh::{image_from, warn_user};
use crate::tets::{tets_in, tets_out};

/// The names of the measured media (Jensen et al. 2001, Fig. 5, in mm⁻¹),
/// for `Object(..., medium=NAME)` and `Object.paint`.
#[pyfunction]
pub(crate) fn media() -> Vec<&'static str> {
    tet_diffusion::MEASURED.iter().map(|m| m.0).collect()
}

/// A medium: a measured one by name, or `(sigma_a, sigma_s_prime)`, two
/// RGB triples in mm⁻¹.
fn medium_arg(obj: &Bound<'_, PyAny>) -> PyResult<Medium> {
    if let Ok(name) = obj.extract::<String>() {
        return Ok(Medium::measured(&name).map_err(Failure::from)?);
    }
    let (a, s): ([f64; 3], [f64; 3]) = obj.extract().map_err(|_| {
        Failure::input("medium: expected a measured medium's name (trilux.media()) or (sigma_a, sigma_s_prime), two RGB triples in 1/mm")
    })?;
    let m = Medium {
        sigma_a: a,
        sigma_s_prime: s,
    };
    m.check("medium").map_err(Failure::from)?;
    Ok(m)
}

fn vec3_arg(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<DVec3> {
    let v: [f64; 3] = obj
        .extract()
        .map_err(|_| Failure::input(format!("{what}: expected three numbers")))?;
    Ok(DVec3::from_array(v))
}

/// A translucent object (TransCut, Li et al.): a tetrahedral mesh
/// `nodes` `(n, 3)` (mesh units) and `tets` `(m, 4)`, a `medium` (a name
/// from `trilux.media()`, default `'marble'`, or `(sigma_a,
/// sigma_s_prime)` in mm⁻¹), `unit_mm` millimetres per mesh unit (1000
/// for a mesh in metres; the coefficients are per mm), `eta` the relative
/// index of refraction of the boundary. The cotangent-weight diffusion
/// matrix (Eq. 4–14) is assembled here; `solve` runs the multi-resolution
/// solver with the GIL released.
///
/// Tetrahedra may come in either orientation: one with negative signed
/// volume (`det[p1 - p0, p2 - p0, p3 - p0] < 0`, an inverted tet) is
/// re-oriented by swapping its first two nodes, so `Object.mesh` returns
/// every tet with positive volume; a tet of (numerically) zero volume, a
/// repeated node, an unused node or a NaN node raises `trilux.InputError`
/// naming the row or node.
///
/// `solve` issues a `UserWarning` for each channel in which a medium's
/// diffusion length is below the mesh's mean edge length (the mesh is too
/// coarse to resolve it), before solving; `render`, `radiance` and
/// `fluence` issue one when the object has not been solved since it was
/// made or changed (`add_light`, `cut`, `paint`, `fracture`,
/// `recombine`): their values are then of the last solution (zero before
/// the first).
#[pyclass(module = "trilux")]
pub(crate) struct Object {
    inner: tet_diffusion::Object,
    lights: Vec<Light>,
    /// Whether `solve` ran after the last change (else `render`,
    /// `radiance` and `fluence` warn).
    solved: bool,
}

impl Object {
    fn unsolved(inner: tet_diffusion::Object, lights: Vec<Light>) -> Self {
        Self {
            inner,
            lights,
            solved: false,
        }
    }

    /// The `UserWarning` of `what` (`Object.render`, …) on an object not
    /// solved since its last change.
    fn warn_if_unsolved(&self, py: Python<'_>, what: &str) -> PyResult<()> {
        if self.solved {
            return Ok(());
        }
        warn_user(
            py,
            &format!(
                "{what}: the object has not been solved since it was made or last changed \
                 (add_light, cut, paint, fracture, recombine): the values are of the last \
                 solution (zero before the first); call solve() first"
            ),
        )
    }
}

/// The messages of `solve`'s `UserWarning`s: one per channel that some
/// medium cannot resolve, however many media (a `paint` stroke gives each
/// tet it blends its own medium, and a warning per medium would be
/// thousands), naming the shortest diffusion length and a tet with it.
fn resolution_warnings(found: &[tet_diffusion::ResolutionWarning]) -> Vec<String> {
    (0..3)
        .filter_map(|c| {
            let of_channel: Vec<_> = found.iter().filter(|w| w.channel == c).collect();
            let shortest = of_channel
                .iter()
                .min_by(|a, b| a.diffusion_length_mm.total_cmp(&b.diffusion_length_mm))?;
            let colour = ["red", "green", "blue"][c];
            let (l, e, t) = (
                shortest.diffusion_length_mm,
                shortest.edge_length_mm,
                shortest.tet,
            );
            let media = match of_channel.len() {
                1 => format!("the diffusion length {l:.3} mm (the medium of tetrahedron {t})"),
                n => format!(
                    "the diffusion length of {n} media, down to {l:.3} mm (the medium of \
                     tetrahedron {t}),"
                ),
            };
            Some(format!(
                "Object.solve: in the {colour} channel {media} is below the mesh's mean edge \
                 length {e:.3} mm: the mesh is too coarse to resolve the light's fall-off there; \
                 refine it (tetrahedralize with a smaller spacing)"
            ))
        })
        .collect()
}

fn solve_report<'py>(
    py: Python<'py>,
    r: &tet_diffusion::SolveReport,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("levels", r.levels)?;
    d.set_item(
        "iterations",
        r.channels.iter().map(|c| c.iterations).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "residuals",
        r.channels.iter().map(|c| c.residual).collect::<Vec<_>>(),
    )?;
    d.set_item("hierarchy_ms", r.hierarchy_ms)?;
    d.set_item("solve_ms", r.solve_ms)?;
    d.set_item("solver", r.choice.solver.to_string())?;
    d.set_item("solver_choice", r.choice.to_string())?;
    Ok(d)
}

#[pymethods]
impl Object {
    #[new]
    #[pyo3(signature = (nodes, tets, *, medium = None, unit_mm = 1.0, eta = 1.3))]
    fn new(
        py: Python<'_>,
        nodes: &Bound<'_, PyAny>,
        tets: &Bound<'_, PyAny>,
        medium: Option<&Bound<'_, PyAny>>,
        unit_mm: f64,
        eta: f64,
    ) -> PyResult<Self> {
        let (positions, tets) = tets_in(nodes, tets)?;
        let medium = match medium {
            Some(m) => medium_arg(m)?,
            None => Medium::measured("marble").map_err(Failure::from)?,
        };
        let inner = detached(py, || {
            let mesh = tet_diffusion::TetMesh::new(&positions, &tets)?;
            Ok(tet_diffusion::Object::homogeneous(
                mesh, unit_mm, medium, eta,
            )?)
        })?;
        Ok(Self::unsolved(inner, Vec::new()))
    }

    /// Adds a light and returns its index: `direction` (toward the light)
    /// with `irradiance` (RGB, W/mm²) for a distant light; or `position`
    /// (mesh units) with `intensity` (RGB, W/sr) for a point light; or
    /// `envmap`, an equirectangular HDR image `(H, W, 3)` (linear).
    #[pyo3(signature = (direction = None, *, irradiance = (1.0, 1.0, 1.0), position = None,
        intensity = (1.0, 1.0, 1.0), envmap = None, envmap_samples = Int::Value(256)),
        text_signature = "($self, direction=None, *, irradiance=..., position=None, intensity=..., envmap=None, envmap_samples=256)")]
    #[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
    fn add_light(
        &mut self,
        py: Python<'_>,
        direction: Option<&Bound<'_, PyAny>>,
        irradiance: (f64, f64, f64),
        position: Option<&Bound<'_, PyAny>>,
        intensity: (f64, f64, f64),
        envmap: Option<&Bound<'_, PyAny>>,
        envmap_samples: Int,
    ) -> PyResult<usize> {
        let envmap_samples: usize = envmap_samples.to("envmap_samples", "1..")?;
        if envmap_samples == 0 {
            return Err(Failure::input(
                "envmap_samples: 0 is not in 1.. (an environment light needs at least one sample)",
            )
            .into());
        }
        let light = match (direction, position, envmap) {
            (Some(d), None, None) => Light::Directional {
                to_light: vec3_arg(d, "direction")?,
                irradiance: [irradiance.0, irradiance.1, irradiance.2],
            },
            (None, Some(p), None) => Light::Point {
                position: vec3_arg(p, "position")?,
                intensity: [intensity.0, intensity.1, intensity.2],
            },
            (None, None, Some(e)) => {
                let image = image_from(e, "envmap", true)?;
                let rgb: Vec<[f32; 3]> = image.pixels.iter().map(|p| [p[0], p[1], p[2]]).collect();
                let env = tet_diffusion::Environment::new(
                    &rgb,
                    image.width as usize,
                    image.height as usize,
                    envmap_samples,
                )
                .map_err(Failure::from)?;
                Light::Environment(Arc::new(env))
            }
            _ => {
                return Err(Failure::input(
                    "add_light: give exactly one of direction, position and envmap",
                )
                .into());
            }
        };
        let obj = &mut self.inner;
        let l = light.clone();
        let index = detached(py, || Ok(obj.add_light(l)?))?;
        self.lights.push(light);
        self.solved = false;
        Ok(index)
    }

    /// Solves the diffusion equation for `φ` (three channels); returns a
    /// report dict: `levels`, `iterations` and `residuals` per channel,
    /// `hierarchy_ms`, `solve_ms`, `solver` (which ran: "Jacobi-PCG" or
    /// "V-cycle-PCG", chosen by the system) and `solver_choice` (why). Before solving, a `UserWarning` for each
    /// channel in which a medium's diffusion length is below the mesh's
    /// mean edge length (too coarse a mesh to resolve it). `solver`:
    /// "auto" (chosen by the system), "jacobi" or "vcycle" (forced).
    #[pyo3(signature = (solver = "auto"))]
    fn solve<'py>(&mut self, py: Python<'py>, solver: &str) -> PyResult<Bound<'py, PyDict>> {
        self.inner.settings.method = match solver {
            "auto" => tet_diffusion::Method::Auto,
            "jacobi" => tet_diffusion::Method::JacobiPcg,
            "vcycle" => tet_diffusion::Method::VCyclePcg,
            other => {
                return Err(Failure::input(format!(
                    "solver: {other:?} is not 'auto', 'jacobi' or 'vcycle'"
                ))
                .into());
            }
        };
        for w in resolution_warnings(&self.inner.warnings()) {
            warn_user(py, &w)?;
        }
        let obj = &mut self.inner;
        let r = detached(py, || Ok(obj.solve()?))?;
        self.solved = true;
        solve_report(py, &r)
    }

    /// Outgoing radiance at the boundary vertices (Eq. 3), `(k, 3)`
    /// float64, row `i` for node `boundary_vertices[i]`; toward `toward`
    /// (a direction) with the Fresnel factor, or its hemispherical value.
    #[pyo3(signature = (toward = None))]
    fn radiance<'py>(
        &self,
        py: Python<'py>,
        toward: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let toward = toward.map(|t| vec3_arg(t, "toward")).transpose()?;
        self.warn_if_unsolved(py, "Object.radiance")?;
        let obj = &self.inner;
        let r = detached(py, || Ok(obj.radiance(toward)))?;
        arrays::matrix(py, r.into_iter().flatten().collect(), 3)
    }

    /// `φ` per node and channel, `(n, 3)` float64 (the fluence).
    #[getter]
    fn fluence<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.warn_if_unsolved(py, "Object.fluence")?;
        arrays::matrix(py, self.inner.fluence().into_iter().flatten().collect(), 3)
    }

    /// Removes the half-space `(x - point) · normal > 0`. `method`:
    /// `'exact'` (the default: the tets the plane crosses are split along
    /// it) or `'relax'` (TransCut's Sec. 5: whole tets removed, the
    /// cross-section relaxed for `relax_sweeps` sweeps). Returns
    /// `removed_tets`, `removed_vertices`, `moved_vertices`, `sweeps`,
    /// `split_tets`, `created_tets`, `created_vertices`,
    /// `min_created_dihedral` (degrees). Solve again after.
    #[pyo3(signature = (point, normal, *, method = "exact", relax_sweeps = Int::Value(20)),
        text_signature = "($self, point, normal, *, method=\"exact\", relax_sweeps=20)")]
    fn cut<'py>(
        &mut self,
        py: Python<'py>,
        point: &Bound<'py, PyAny>,
        normal: &Bound<'py, PyAny>,
        method: &str,
        relax_sweeps: Int,
    ) -> PyResult<Bound<'py, PyDict>> {
        let relax_sweeps: usize = relax_sweeps.to("relax_sweeps", "0..")?;
        let method = match method {
            "exact" => tet_diffusion::CutMethod::Exact,
            "relax" => tet_diffusion::CutMethod::Relax {
                sweeps: relax_sweeps,
            },
            other => {
                return Err(
                    Failure::input(format!("method: {other:?} is not 'exact' or 'relax'")).into(),
                );
            }
        };
        let cut = Cut::Plane {
            point: vec3_arg(point, "point")?,
            normal: vec3_arg(normal, "normal")?,
        };
        let obj = &mut self.inner;
        let r = detached(py, || Ok(obj.cut(&cut, method)?))?;
        self.solved = false;
        let d = PyDict::new(py);
        d.set_item("removed_tets", r.removed_tets)?;
        d.set_item("removed_vertices", r.removed_vertices)?;
        d.set_item("moved_vertices", r.moved_vertices)?;
        d.set_item("sweeps", r.sweeps)?;
        d.set_item("split_tets", r.split_tets)?;
        d.set_item("created_tets", r.created_tets)?;
        d.set_item("created_vertices", r.created_vertices)?;
        d.set_item("min_created_dihedral", r.min_created_dihedral)?;
        Ok(d)
    }

    /// Paints `medium` into a soft ball (a Gaussian of standard deviation
    /// `radius` around `center`, weight `strength` at the centre); returns
    /// the number of tetrahedra changed.
    #[pyo3(signature = (center, radius, medium, *, strength = 1.0))]
    fn paint(
        &mut self,
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        radius: f64,
        medium: &Bound<'_, PyAny>,
        strength: f64,
    ) -> PyResult<usize> {
        let stroke = Stroke {
            points: vec![vec3_arg(center, "center")?],
            radius,
            medium: medium_arg(medium)?,
            strength,
        };
        let obj = &mut self.inner;
        let changed = detached(py, || Ok(obj.paint(&stroke)?))?.tets;
        self.solved = false;
        Ok(changed)
    }

    /// Splits the object along the plane through `point` with `normal`
    /// into two objects (the lights are copied), which `recombine` joins
    /// again exactly. `offset` moves the second piece along `normal` for
    /// display (mesh units).
    #[pyo3(signature = (point, normal, *, offset = 0.0))]
    fn fracture<'py>(
        &self,
        py: Python<'py>,
        point: &Bound<'py, PyAny>,
        normal: &Bound<'py, PyAny>,
        offset: f64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (p, n) = (vec3_arg(point, "point")?, vec3_arg(normal, "normal")?);
        let obj = &self.inner;
        let [a, mut b] = detached(py, || Ok(obj.fracture(p, n)?))?;
        b.set_transform(DAffine3::from_translation(n.normalize_or_zero() * offset));
        let wrap =
            |o| Bound::new(py, Object::unsolved(o, self.lights.clone())).map(Bound::into_any);
        PyTuple::new(py, [wrap(a)?, wrap(b)?])
    }

    /// Joins two pieces of one `fracture` into the object they came from.
    #[staticmethod]
    fn recombine(py: Python<'_>, a: PyRef<'_, Object>, b: PyRef<'_, Object>) -> PyResult<Object> {
        let (ia, ib) = (&a.inner, &b.inner);
        let inner = detached(py, || Ok(tet_diffusion::Object::recombine(ia, ib)?))?;
        Ok(Object::unsolved(inner, a.lights.clone()))
    }

    /// A picture: the boundary with the radiance toward the camera (Eq. 3)
    /// plus the lights' specular highlights, `size × size`, as an
    /// `(H, W, 3)` float32 linear RGB array. `view`: the direction from
    /// the object toward the eye. `exposure='auto'` scales the brightest
    /// 1 % of the object's pixels to 1 (as `trilux diffuse` writes its
    /// PNG); `None` keeps the radiance.
    #[pyo3(signature = (*, view = None, size = Int::Value(512), exposure = Some("auto")),
        text_signature = "($self, *, view=None, size=512, exposure=...)")]
    fn render<'py>(
        &self,
        py: Python<'py>,
        view: Option<&Bound<'py, PyAny>>,
        size: Int,
        exposure: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        render_objects(
            py,
            std::slice::from_ref(&self.inner),
            &self.lights,
            view,
            size,
            exposure,
            || self.warn_if_unsolved(py, "Object.render"),
        )
    }

    /// `(nodes, tets)` of the current mesh (after cuts), `(n, 3)` float64
    /// and `(m, 4)` int64.
    #[getter]
    fn mesh<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let m = self.inner.mesh();
        PyTuple::new(py, tets_out(py, m.positions(), m.tets())?)
    }

    /// The boundary triangles, `(b, 3)` int64 node indices (outward).
    #[getter]
    fn boundary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        arrays::index_matrix(py, self.inner.mesh().boundary())
    }

    /// The nodes on the boundary, `(k,)` int64: row `i` of `radiance` is
    /// node `boundary_vertices[i]`.
    #[getter]
    fn boundary_vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        arrays::vector(
            py,
            self.inner
                .mesh()
                .boundary_vertices()
                .iter()
                .map(|&v| i64::from(v))
                .collect(),
        )
    }

    fn __repr__(&self) -> String {
        let m = self.inner.mesh();
        format!(
            "trilux.Object({} nodes, {} tetrahedra, {} mm per unit, {} lights)",
            m.vertex_count(),
            m.tets().len(),
            self.inner.length_unit_mm(),
            self.lights.len()
        )
    }
}

/// The picture of `render` and `Object.render`; `warn` issues the
/// not-solved warnings, after the arguments are checked (a call that
/// raises does not also warn).
#[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
fn render_objects<'py>(
    py: Python<'py>,
    objects: &[tet_diffusion::Object],
    lights: &[Light],
    view: Option<&Bound<'py, PyAny>>,
    size: Int,
    exposure: Option<&str>,
    warn: impl FnOnce() -> PyResult<()>,
) -> PyResult<Bound<'py, PyAny>> {
    let size = size.value("size", "1..8192")?;
    let size = match u32::try_from(size) {
        Ok(s) if (1..=8192).contains(&s) => s,
        _ => return Err(Failure::input(format!("size: {size} is not in 1..8192")).into()),
    };
    let auto = match exposure {
        None => false,
        Some("auto") => true,
        Some(other) => {
            return Err(
                Failure::input(format!("exposure: {other:?} is not 'auto' or None")).into(),
            );
        }
    };
    let view: Option<Vec3> = view
        .map(|v| vec3_arg(v, "view").map(|v| v.as_vec3()))
        .transpose()?;
    warn()?;
    let image = detached(py, || {
        let picture = trilux::tet::render(objects, lights, size, view);
        Ok(if auto {
            trilux::tet::tone_map(&picture)
        } else {
            picture.image
        })
    })?;
    let data: Vec<f32> = image
        .pixels
        .iter()
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    arrays::image(py, data, image.height as usize, image.width as usize, 3)
}

/// Renders several objects together (the pieces of a `fracture`, at
/// their display offsets) with the lights of the first: as
/// `Object.render`.
#[pyfunction]
#[pyo3(signature = (objects, *, view = None, size = Int::Value(512), exposure = Some("auto")),
    text_signature = "(objects, *, view=None, size=512, exposure=...)")]
pub(crate) fn render<'py>(
    py: Python<'py>,
    objects: Vec<PyRef<'py, Object>>,
    view: Option<&Bound<'py, PyAny>>,
    size: Int,
    exposure: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    // The renderer takes a slice of objects: copies, for pieces held by
    // separate Python objects.
    let inner: Vec<tet_diffusion::Object> = objects.iter().map(|o| o.inner.clone()).collect();
    let lights = objects
        .first()
        .map(|o| o.lights.clone())
        .unwrap_or_default();
    let warn = || {
        objects
            .iter()
            .enumerate()
            .try_for_each(|(i, o)| o.warn_if_unsolved(py, &format!("render (objects[{i}])")))
    };
    render_objects(py, &inner, &lights, view, size, exposure, warn)
}
