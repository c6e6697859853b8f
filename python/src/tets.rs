//! Tetrahedral meshes: isosurface stuffing (Labelle & Shewchuk 2007, on
//! generalized winding numbers, Barill et al. 2018), and TetGen / Gmsh /
//! MEDIT / VTU files.

use glam::DVec3;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use tet_stuffing as stuffing;

use crate::arrays;
use crate::error::{Failure, detached};
use crate::mesh::{check_extension, check_folder, mesh_arg, path_arg};

/// `(nodes, tets)` as numpy: `(n, 3)` float64 and `(m, 4)` int64.
pub(crate) fn tets_out<'py>(
    py: Python<'py>,
    positions: &[DVec3],
    tets: &[[u32; 4]],
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let nodes = positions.iter().flat_map(|p| p.to_array()).collect();
    Ok(vec![
        arrays::matrix(py, nodes, 3)?,
        arrays::index_matrix(py, tets)?,
    ])
}

/// `(nodes, tets)` arrays as plain data, indices checked.
pub(crate) fn tets_in(
    nodes: &Bound<'_, PyAny>,
    tets: &Bound<'_, PyAny>,
) -> PyResult<(Vec<DVec3>, Vec<[u32; 4]>)> {
    let nodes: Vec<DVec3> = arrays::rows_f64::<3>(nodes, "nodes")?
        .into_iter()
        .map(DVec3::from_array)
        .collect();
    let tets = arrays::index_rows::<4>(tets, "tets", nodes.len(), ("node", "nodes"))?;
    Ok((nodes, tets))
}

/// Fills a closed surface with tetrahedra by isosurface stuffing
/// (Labelle & Shewchuk 2007, *Isosurface Stuffing: Fast Tetrahedral
/// Meshes with Good Dihedral Angles*), inside decided by the generalized
/// winding number (Barill et al. 2018), so holes and overlaps are fine.
///
/// The shape of pytetwild's and tetgen's calls: returns `(nodes, tets)`,
/// `(n, 3)` float64 positions in the mesh's coordinates and `(m, 4)`
/// int64 node indices (positive volume), plus a report dict when
/// `return_report=True`: `tets`, `vertices`, `boundary_triangles`,
/// `spacing`, `min_dihedral_deg`, `max_dihedral_deg` (this mesh's
/// dihedral-angle range), `dihedral_bound_deg` (the `(min, max)` any
/// surface gets with these options: 9°–162°, 9°–165° with `envelope`),
/// how far the tets' boundary lies
/// from the surface — `hausdorff` (symmetric), `input_to_tets`,
/// `tets_to_input`, `mean_distance` in mesh units, `hausdorff_fraction` and
/// `mean_distance_fraction` of the bounding box's `diagonal`, measured at
/// `distance_points` (input, boundary) points — `left_out_triangles` and
/// `left_out_area_fraction` (input triangles that enclose no volume, also
/// a `UserWarning`), `hole_caps_fraction` and `hole_caps_to_input` (the
/// share of boundary points capping holes of the surface, left out of
/// `tets_to_input`, and their farthest distance), `envelope`,
/// `fitted_vertices`, `split_edges` and `sharp_edges` (the fit, see
/// below), and `seconds`. Measuring the distances costs up to
/// as much again as the stuffing on inputs of 10⁵ triangles.
///
/// `spacing`: the lattice spacing in mesh units (default: 1/40 of the
/// bounding box's diagonal, as `trilux tetra`); `graded=True` makes the
/// tetrahedra coarser deep inside (an octree). `envelope` (a fraction of
/// the diagonal between 0 and 1, e.g. 0.002; default None, off) fits the
/// boundary to the surface: boundary vertices move onto tips, creases and
/// thin parts farther than it from the boundary, keeping every dihedral
/// angle at 10° or more, and splits boundary edges where moves are not
/// enough (at most 3× the tetrahedra); not a guarantee, the report's
/// `hausdorff` says how near it came, `fitted_vertices`, `split_edges`
/// and `sharp_edges` what it did. The
/// GIL is released.
#[pyfunction]
#[pyo3(signature = (mesh, *, spacing = None, graded = false, envelope = None, return_report = false))]
pub(crate) fn tetrahedralize<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    spacing: Option<f64>,
    graded: bool,
    envelope: Option<f64>,
    return_report: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let mesh = mesh_arg(mesh, None)?;
    let h = spacing.unwrap_or_else(|| trilux::tet::default_spacing(&mesh));
    // The distance is always measured, as `trilux tetra` does: it finds the
    // open sheets the stuffing leaves out, which are warned of.
    let options = stuffing::Options {
        graded,
        envelope,
        ..stuffing::Options::new(h)
    };
    let stuffed = detached(py, || {
        Ok(stuffing::tetrahedralize(
            &mesh.positions,
            &mesh.indices,
            &options,
        )?)
    })?;
    let out = trilux::tet::from_stuffing(&stuffed, mesh.origin);
    let mut items = tets_out(py, &out.positions, &out.tets)?;
    if return_report {
        let r = &stuffed.report;
        let d = PyDict::new(py);
        d.set_item("tets", r.tets)?;
        d.set_item("vertices", r.vertices)?;
        d.set_item("boundary_triangles", r.boundary_triangles)?;
        d.set_item("spacing", h)?;
        d.set_item("min_dihedral_deg", r.min_dihedral_deg)?;
        d.set_item("max_dihedral_deg", r.max_dihedral_deg)?;
        d.set_item("dihedral_bound_deg", r.dihedral_bounds_deg)?;
        d.set_item("envelope", envelope)?;
        d.set_item("fitted_vertices", r.fitted_vertices)?;
        d.set_item("sharp_edges", r.sharp_edges)?;
        d.set_item("split_edges", r.split_edges)?;
        if let Some(m) = &r.distance {
            d.set_item("hausdorff", m.hausdorff)?;
            d.set_item("hausdorff_fraction", m.hausdorff_fraction())?;
            d.set_item("mean_distance", m.mean)?;
            d.set_item("mean_distance_fraction", m.mean_fraction())?;
            d.set_item("input_to_tets", m.input_to_tets)?;
            d.set_item("tets_to_input", m.tets_to_input)?;
            d.set_item("diagonal", m.diagonal)?;
            d.set_item("distance_points", (m.input_samples, m.boundary_samples))?;
            d.set_item("left_out_triangles", m.left_out_triangles)?;
            d.set_item("left_out_area_fraction", m.left_out_area)?;
            d.set_item("hole_caps_fraction", m.hole_caps)?;
            d.set_item("hole_caps_to_input", m.hole_caps_to_input)?;
        }
        d.set_item("seconds", r.elapsed.as_secs_f64())?;
        items.push(d.into_any());
    }
    if let Some(m) = stuffed
        .report
        .distance
        .as_ref()
        .filter(|m| m.left_out_triangles > 0)
    {
        crate::mesh::warn_user(
            py,
            &format!(
                "trilux.tetrahedralize: {} triangles ({:.2}% of the area) enclose no volume \
                 (open sheets or fins by the winding number) and are left out of the tetrahedra",
                m.left_out_triangles,
                100.0 * m.left_out_area
            ),
        )?;
    }
    PyTuple::new(py, items)
}

/// Reads a tetrahedral mesh: TetGen `.node`/`.ele`, Gmsh `.msh`, MEDIT
/// `.mesh`, by extension. Returns `(nodes, tets)`, `(n, 3)` float64 and
/// `(m, 4)` int64 (0-based, whatever the file's numbering), plus, when
/// `return_warnings=True`, the list of str naming what the reader skipped
/// without refusing the file (Gmsh elements that are not tetrahedra, for
/// one), each with the file and the section or line.
///
/// The tets come back as the file stores them, in its node order, not
/// re-oriented: a tet may have negative signed volume
/// (`det[p1 - p0, p2 - p0, p3 - p0] < 0`, an inverted tet).
/// `trilux.Object` accepts either orientation and re-orients an inverted
/// tet (its first two nodes swapped); `tetrahedralize` only makes tets of
/// positive volume.
#[pyfunction]
#[pyo3(signature = (path, *, return_warnings = false))]
pub(crate) fn load_tets<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    return_warnings: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    let path = path_arg(path, "path")?;
    Failure::if_directory(
        &path,
        "a tetrahedral mesh file (.node, .ele, .msh or .mesh)",
    )?;
    let mesh = detached(py, || Ok(trilux_io::tet::TetMesh::read(&path)?))?;
    let mut items = tets_out(py, &mesh.positions, &mesh.tets)?;
    if return_warnings {
        let warnings: Vec<String> = mesh.warnings.iter().map(ToString::to_string).collect();
        items.push(warnings.into_pyobject(py)?.into_any());
    }
    PyTuple::new(py, items)
}

/// Writes a tetrahedral mesh `(nodes (n, 3), tets (m, 4))` as TetGen
/// `.node` + `.ele`, MEDIT `.mesh` or VTK `.vtu`, by extension (a folder
/// that does not exist raises `trilux.FileError`).
#[pyfunction]
pub(crate) fn save_tets(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    nodes: &Bound<'_, PyAny>,
    tets: &Bound<'_, PyAny>,
) -> PyResult<()> {
    let path = path_arg(path, "path")?;
    check_folder(&path)?;
    let (positions, tets) = tets_in(nodes, tets)?;
    let mesh = trilux_io::tet::TetMesh {
        positions,
        tets,
        ..Default::default()
    };
    detached(py, || Ok(trilux_io::tet::write(&path, &mesh)?))
}

/// The extensions `save_points` writes and `load_points` reads.
pub(crate) const POINT_EXTENSIONS: [&str; 3] = ["ply", "glb", "gltf"];

/// Checks that every row of `rows` (the argument `what`) is finite: a
/// `trilux.InputError` naming the first that is not.
fn finite_rows(rows: &[[f64; 3]], what: &str) -> PyResult<()> {
    match rows.iter().position(|r| !r.iter().all(|v| v.is_finite())) {
        None => Ok(()),
        Some(i) => Err(Failure::input(format!(
            "{what}: row {i} is not finite ({})",
            crate::gltf::row_text(&rows[i])
        ))
        .into()),
    }
}

/// Writes a point cloud by extension: PLY (binary little-endian, as
/// `trilux sample` writes it) or glTF (`.glb`, or `.gltf` with its `.bin`:
/// a `POINTS` primitive). `points` `(n, 3)`, optional `normals` `(n, 3)`
/// and `face_index` `(n,)` (PLY `face_id`, glTF `_FACE`, which keeps ids
/// below 2**24). glTF stores unit normals: a normal is normalised, and a
/// zero one becomes `(0, 0, 1)` (PLY keeps them as given). A point or
/// normal that is not finite raises `trilux.InputError`; a path without
/// one of these extensions, or in a folder that does not exist,
/// `trilux.FileError`.
///
/// glTF files also keep `colors` and `attributes` per point, as
/// `trilux.save` writes them per vertex: colours linear in [0, 1] (within
/// 1e-5 clamped) or uint8 sRGB; attributes stored as float32 under the
/// name prefixed with `_` (`FACE` is `face_index`'s name there). With
/// another extension they raise `trilux.InputError`. An existing file is
/// replaced. `trilux.load_points` reads the file back.
#[pyfunction]
#[pyo3(signature = (path, points, *, normals = None, face_index = None, colors = None, attributes = None))]
pub(crate) fn save_points(
    py: Python<'_>,
    path: &Bound<'_, PyAny>,
    points: &Bound<'_, PyAny>,
    normals: Option<&Bound<'_, PyAny>>,
    face_index: Option<&Bound<'_, PyAny>>,
    colors: Option<&Bound<'_, PyAny>>,
    attributes: Option<&Bound<'_, PyAny>>,
) -> PyResult<()> {
    let path = path_arg(path, "path")?;
    check_extension(&path, &POINT_EXTENSIONS, "points", "write")?;
    check_folder(&path)?;
    let gltf = crate::gltf::is_gltf(&path);
    let p = arrays::rows_f64::<3>(points, "points")?;
    finite_rows(&p, "points")?;
    let absolute: Vec<DVec3> = p.iter().copied().map(DVec3::from_array).collect();
    let (origin, positions) = trilux_io::mesh::recenter(&absolute);
    if let Some(i) = positions.iter().position(|q| !q.is_finite()) {
        return Err(Failure::input(format!(
            "points: row {i} ({}) is too far from the other points to be stored in float32",
            crate::gltf::row_text(&p[i])
        ))
        .into());
    }
    let n = positions.len();
    let normals = normals
        .map(|a| {
            let rows = arrays::rows_f64::<3>(a, "normals")?;
            if rows.len() != n {
                return Err(PyErr::from(Failure::input(format!(
                    "normals: {} rows for {n} points",
                    rows.len()
                ))));
            }
            finite_rows(&rows, "normals")?;
            Ok(rows
                .into_iter()
                .map(|r| DVec3::from_array(r).as_vec3())
                .collect())
        })
        .transpose()?;
    let face_ids = face_index
        .map(|a| {
            let ids = arrays::values_i64(a, "face_index")?;
            if ids.len() != n {
                return Err(PyErr::from(Failure::input(format!(
                    "face_index: {} entries for {n} points",
                    ids.len()
                ))));
            }
            ids.iter()
                .enumerate()
                .map(|(i, &f)| {
                    u32::try_from(f).map_err(|_| {
                        PyErr::from(Failure::input(format!("face_index: entry {i} is {f}")))
                    })
                })
                .collect::<PyResult<Vec<u32>>>()
        })
        .transpose()?;
    let data = crate::gltf::vertex_data(&path, colors, attributes, n, ("point", "points"))?;
    if gltf {
        if let Some((i, f)) = face_ids
            .iter()
            .flatten()
            .enumerate()
            .find(|(_, f)| **f >= trilux_io::mesh::gltf::FACE_ID_LIMIT)
        {
            return Err(Failure::input(format!(
                "face_index: entry {i} is {f}; glTF stores face ids as float32, exact below \
                 2**24 = 16777216 (write .ply for meshes with more triangles)"
            ))
            .into());
        }
        let vertex_data = data.unwrap_or_default();
        let face = trilux_io::mesh::gltf::FACE_ATTRIBUTE;
        if face_ids.is_some() && vertex_data.attribute(face).is_some() {
            return Err(Failure::input(format!(
                "attributes: {face} is where face_index goes in a glTF file; rename it"
            ))
            .into());
        }
        let cloud = trilux_io::mesh::gltf::Points {
            positions,
            origin,
            normals,
            uvs: None,
            faces: face_ids,
            vertex_data,
        };
        return detached(py, || {
            Ok(trilux_io::mesh::gltf::write_points(&path, &cloud)?)
        });
    }
    let data = trilux_io::mesh::ply::PlyData {
        positions,
        origin,
        normals,
        face_ids,
        ..Default::default()
    };
    detached(py, || {
        Ok(trilux_io::mesh::ply::write(
            &path,
            &data,
            trilux_io::mesh::ply::Format::BinaryLittleEndian,
        )?)
    })
}
