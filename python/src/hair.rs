//! `trilux.grow_hair`: hair strands grown from points on a mesh
//! (mesh-sampling's `grow_strands_with`), returned as arrays and, with
//! `path=`, written as USD text, `.hair` or glTF (trilux-io's curves).

use pyo3::prelude::*;
use pyo3::types::PyDict;

use mesh_sampling::{HairOptions, StrandParams, SurfacePoint, grow_strands_with};

use crate::arrays::{self, Int};
use crate::error::{Failure, Result, detached};
use crate::mesh::{check_extension, mesh_arg, path_arg};

/// What `path=` may end in.
const HAIR_EXTENSIONS: [&str; 5] = ["usda", "usd", "hair", "glb", "gltf"];

/// How far a barycentric coordinate may fall below 0, and its row's sum
/// from 1: `sample_surface` returns `f32` coordinates, rounded.
const BARYCENTRIC_TOLERANCE: [f64; 2] = [1e-6, 1e-3];

/// Each row of `barycentric` a point of its triangle: no coordinate
/// below 0 and their sum 1 (within [`BARYCENTRIC_TOLERANCE`]); else the
/// root would be off the surface.
fn check_barycentric(bary: &[[f64; 3]]) -> PyResult<()> {
    let [below, sum] = BARYCENTRIC_TOLERANCE;
    let bad = |b: &[f64; 3]| {
        !(b.iter().all(|&x| x >= -below) && (b.iter().sum::<f64>() - 1.0).abs() <= sum)
    };
    match bary.iter().position(bad) {
        None => Ok(()),
        Some(i) => {
            let [a, b, c] = bary[i];
            Err(Failure::input(format!(
                "barycentric[{i}] = [{a}, {b}, {c}]: not barycentric coordinates (each must be \
                 >= 0 and the three sum to 1 within {sum}); the root would be off the surface"
            ))
            .into())
        }
    }
}

/// A per-root parameter: one value for all roots, or one per root.
struct PerRoot {
    values: Vec<f64>,
}

impl PerRoot {
    fn new(
        obj: Option<&Bound<'_, PyAny>>,
        name: &'static str,
        default: f64,
        n: usize,
    ) -> PyResult<Self> {
        let values = match obj {
            None => vec![default],
            Some(o) => arrays::values_f64(o, name)?,
        };
        if values.len() != 1 && values.len() != n {
            return Err(Failure::input(format!(
                "{name}: one value or one per root ({n}), got {}",
                values.len()
            ))
            .into());
        }
        Ok(Self { values })
    }

    /// Degrees (0 to 180, as `--hair-comb` and Blender's UI take them)
    /// to the radians the library takes, each checked first so that an
    /// error names the value as given.
    fn degrees_to_radians(mut self, name: &str) -> PyResult<Self> {
        if let Some((i, v)) = self
            .values
            .iter()
            .enumerate()
            .find(|(_, v)| !(0.0..=180.0).contains(*v))
        {
            return Err(Failure::input(format!(
                "{name}[{i}] = {v}: must be in [0, 180] degrees from the normal"
            ))
            .into());
        }
        self.values.iter_mut().for_each(|v| *v = v.to_radians());
        Ok(self)
    }

    fn at(&self, i: usize) -> f32 {
        let v = if self.values.len() == 1 {
            self.values[0]
        } else {
            self.values[i]
        };
        v as f32
    }
}

/// Hair strands grown from points on a mesh (Šik & Křivánek 2013, Sec.
/// 6: the roots are what `sample_surface` returns, with
/// `return_barycentric=True`).
///
/// Each root at `(face_index[i], barycentric[i])` on `mesh` grows a
/// polyline of `segments` segments (`segments + 1` points, the root
/// first) along the mesh's interpolated normal (the face's normal when
/// the mesh has none), `length` long (mesh units), tilted `comb_angle`
/// degrees (0 to 180, as the CLI's `--hair-comb` and Blender's UI) from
/// the normal toward the world direction `comb` (not zero; its part in
/// the tangent plane), curled around its axis (`curl_radius` at the tip,
/// `curl_turns` turns), jittered by `noise` at the tip, and pulled the
/// fraction `clump` of the way (at the tip) toward the strand of the
/// nearest of `clumps` centre roots drawn from `seed`. `length`,
/// `comb_angle`, `curl_radius`, `curl_turns`, `noise`, `clump`, `width`
/// and `tip_width` take one value or one per root (a painted map looked
/// up at the roots). Widths taper linearly from `width` (default 1 % of
/// the length) to `tip_width`.
///
/// Returns a dict: `points` `(S, segments + 1, 3)` float64 in the mesh's
/// coordinates, `widths` `(S, segments + 1)` float32, and per root
/// `face_index` `(S,)` int64, `barycentric` `(S, 3)` float64, `normal`
/// `(S, 3)` float64 (the direction grown along) and `uv` `(S, 2)`
/// float64 (OpenGL convention) or `None` without UVs. With `path`, also
/// writes the strands by extension: `.usda` or `.usd` (USD text:
/// `BasisCurves` and the roots as `Points`, metres, Y up), `.hair` (Cem
/// Yuksel's format) or `.glb`/`.gltf` (lines and root points); an
/// existing file is replaced, as `trilux.save` and `trilux.save_points`
/// replace theirs. `barycentric` rows must be barycentric (each >= 0,
/// summing to 1 within 1e-3). Same seed, same strands on any number of
/// threads. Raises `trilux.InputError` naming the argument (and
/// the root) for bad values, `trilux.FileError` for an unwritable path.
/// The GIL is released.
#[pyfunction]
#[pyo3(signature = (mesh, face_index, barycentric, length, *, segments = Int::Value(8), comb = None,
    comb_angle = None, curl_radius = None, curl_turns = None, noise = None, clumps = Int::Value(0),
    clump = None, width = None, tip_width = None, seed = None, path = None))]
#[allow(clippy::too_many_arguments, reason = "the Python keyword arguments")]
pub(crate) fn grow_hair<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    face_index: &Bound<'py, PyAny>,
    barycentric: &Bound<'py, PyAny>,
    length: &Bound<'py, PyAny>,
    segments: Int,
    comb: Option<&Bound<'py, PyAny>>,
    comb_angle: Option<&Bound<'py, PyAny>>,
    curl_radius: Option<&Bound<'py, PyAny>>,
    curl_turns: Option<&Bound<'py, PyAny>>,
    noise: Option<&Bound<'py, PyAny>>,
    clumps: Int,
    clump: Option<&Bound<'py, PyAny>>,
    width: Option<&Bound<'py, PyAny>>,
    tip_width: Option<&Bound<'py, PyAny>>,
    seed: Option<Int>,
    path: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mesh = mesh_arg(mesh, None)?;
    let faces = arrays::values_i64(face_index, "face_index")?;
    let bary = arrays::rows_f64::<3>(barycentric, "barycentric")?;
    let n = faces.len();
    if bary.len() != n {
        return Err(Failure::input(format!(
            "barycentric: {} rows for {n} face indices",
            bary.len()
        ))
        .into());
    }
    check_barycentric(&bary)?;
    let segments = u32::try_from(arrays::count(&segments, "segments")?).unwrap_or(u32::MAX);
    let clumps = arrays::count(&clumps, "clumps")?;
    let seed = arrays::seed(seed.as_ref())?;
    let comb = match comb {
        None => glam::Vec3::ZERO,
        Some(c) => {
            let v = arrays::values_f64(c, "comb")?;
            let [x, y, z] = v[..] else {
                return Err(Failure::input(format!(
                    "comb: a direction (3 values), got {}",
                    v.len()
                ))
                .into());
            };
            let v = glam::DVec3::new(x, y, z);
            // As `--hair-comb`: a direction, not zero (leave `comb` out
            // for no comb).
            if !(v.is_finite() && v != glam::DVec3::ZERO) {
                return Err(Failure::input(format!(
                    "comb = [{x}, {y}, {z}]: a direction must be finite and not zero (leave \
                     comb out for strands along the normal)"
                ))
                .into());
            }
            v.as_vec3()
        }
    };
    let per_root = |obj, name, default| PerRoot::new(obj, name, default, n);
    let length = per_root(Some(length), "length", 0.0)?;
    let params = [
        per_root(comb_angle, "comb_angle", 0.0)?.degrees_to_radians("comb_angle")?,
        per_root(curl_radius, "curl_radius", 0.0)?,
        per_root(curl_turns, "curl_turns", 0.0)?,
        per_root(noise, "noise", 0.0)?,
        per_root(clump, "clump", 0.0)?,
        per_root(tip_width, "tip_width", 0.0)?,
    ];
    let width = width.map(|w| per_root(Some(w), "width", 0.0)).transpose()?;
    let path = path.map(|p| path_arg(p, "path")).transpose()?;
    if let Some(p) = &path {
        check_extension(p, &HAIR_EXTENSIONS, "hair strands", "write")?;
        crate::mesh::check_folder(p)?;
    }
    let strands = detached(py, || -> Result<_> {
        let surface = trilux::mesh_ref(&mesh);
        let roots = faces
            .iter()
            .zip(&bary)
            .enumerate()
            .map(|(i, (&f, b))| {
                let face = u32::try_from(f).map_err(|_| {
                    Failure::input(format!("face_index[{i}] = {f}: not a face of the mesh"))
                })?;
                SurfacePoint::on(&surface, face, b.map(|v| v as f32), 0.0)
                    .map_err(|e| Failure::input(format!("face_index[{i}]: {e}")))
            })
            .collect::<Result<Vec<_>>>()?;
        let options = HairOptions {
            segments,
            seed,
            clumps,
            widths: true,
        };
        let [comb_angle, curl_radius, curl_turns, noise, clump, tip_width] = &params;
        let strands = grow_strands_with(&roots, &options, |i, _| {
            let length = length.at(i);
            StrandParams {
                length,
                comb,
                comb_angle: comb_angle.at(i),
                curl_radius: curl_radius.at(i),
                curl_turns: curl_turns.at(i),
                noise: noise.at(i),
                clump: clump.at(i),
                width: width.as_ref().map_or(0.01 * length, |w| w.at(i)),
                tip_width: tip_width.at(i),
            }
        })
        .map_err(|e| match e {
            mesh_sampling::Error::InvalidStrandParameter {
                root,
                parameter,
                value,
                expected,
            } => {
                // The Python argument has the field's name.
                Failure::input(format!("{parameter}[{root}] = {value}: must be {expected}"))
            }
            e => Failure::from(e),
        })?;
        if let Some(p) = &path {
            let curves = trilux::hair::into_curves(strands.clone(), mesh.origin);
            trilux_io::curves::write(p, &curves)?;
        }
        Ok(strands)
    })?;
    let k = strands.points_per_strand();
    let out = PyDict::new(py);
    let points = arrays::absolute_positions(py, mesh.origin, &strands.points)?;
    out.set_item(
        "points",
        points.call_method1("reshape", ((strands.len(), k, 3),))?,
    )?;
    let widths = strands.widths.clone().unwrap_or_default();
    out.set_item(
        "widths",
        arrays::matrix(py, widths, k)?.call_method1("reshape", ((strands.len(), k),))?,
    )?;
    let roots = &strands.roots;
    out.set_item(
        "face_index",
        arrays::vector(
            py,
            roots
                .iter()
                .map(|r| i64::from(r.face))
                .collect::<Vec<i64>>(),
        ),
    )?;
    let b: Vec<f64> = roots
        .iter()
        .flat_map(|r| r.barycentric.map(f64::from))
        .collect();
    out.set_item("barycentric", arrays::matrix(py, b, 3)?)?;
    let normals: Vec<glam::Vec3> = roots.iter().map(|r| r.normal).collect();
    out.set_item("normal", arrays::vectors(py, &normals)?)?;
    let uv: Option<Vec<glam::Vec2>> = roots.iter().map(|r| r.uv).collect();
    match uv.filter(|_| mesh.uvs.is_some()) {
        Some(uv) => out.set_item("uv", arrays::uvs(py, &uv)?)?,
        None => out.set_item("uv", py.None())?,
    }
    Ok(out)
}
