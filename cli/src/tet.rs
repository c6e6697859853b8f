//! trilux-io tetrahedral meshes → solver positions, surfaces, quality;
//! solved objects → pictures and glTF surfaces with their radiance.

use glam::{DVec3, Vec3};
use tet_diffusion::Light;
use trilux_io::mesh::gltf::{Attribute, AttributeValues, VertexData};
use trilux_io::mesh::{Object, TriMesh};
use trilux_io::tet::TetMesh;

/// The node positions as `[x, y, z]` rows, the form multires'
/// `Weights::Positions` (and the solvers built on it) take.
pub fn positions_f64(mesh: &TetMesh) -> Vec<[f64; 3]> {
    mesh.positions.iter().map(|p| p.to_array()).collect()
}

/// The boundary of a tetrahedral mesh as a triangle mesh (outward
/// triangles, only the boundary's vertices), for previews, sampling and
/// glTF. Its `f32` positions are relative to an origin chosen as the
/// readers choose one ([`trilux_io::mesh::recenter`]): zero unless the
/// coordinates are far from it, so a far-away mesh keeps its precision.
pub fn surface(mesh: &TetMesh) -> TriMesh {
    let boundary = mesh.boundary();
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let mut used = Vec::new();
    let indices: Vec<[u32; 3]> = boundary
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut map[v as usize];
                if *slot == u32::MAX {
                    *slot = used.len() as u32;
                    used.push(mesh.positions[v as usize]);
                }
                *slot
            })
        })
        .collect();
    let (origin, positions) = trilux_io::mesh::recenter(&used);
    TriMesh {
        objects: vec![Object {
            name: String::new(),
            triangles: 0..indices.len(),
            material: None,
        }],
        origin,
        positions,
        indices,
        ..TriMesh::default()
    }
}

/// The six interior dihedral angles of a tetrahedron, in degrees, at the
/// edges (2,3), (1,3), (1,2), (0,3), (0,2), (0,1): 0° and 180° for a flat
/// one, NaN where a face has no area (two corners coincide). Any file's
/// tets, flat or inverted; tet-stuffing's and tet-diffusion's (which
/// need a proper tet) give the same angles (tested).
pub fn dihedral_angles(p: [DVec3; 4]) -> [f64; 6] {
    // Outward-or-inward normal of the face opposite each vertex; the angle
    // at the edge shared by faces k and l is π minus the angle between
    // their outward normals.
    let faces = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];
    let normal = |k: usize| {
        let [a, b, c] = faces[k].map(|i| p[i]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        // Orient away from the opposite vertex.
        if n.dot(p[k] - a) > 0.0 { -n } else { n }
    };
    let n = [0, 1, 2, 3].map(normal);
    let pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    pairs.map(|(k, l)| {
        if n[k] == DVec3::ZERO || n[l] == DVec3::ZERO {
            return f64::NAN;
        }
        180.0 - n[k].dot(n[l]).clamp(-1.0, 1.0).acos().to_degrees()
    })
}

/// The smallest and largest dihedral angle over all tetrahedra, in
/// degrees (`None` without tetrahedra or with a face of no area).
pub fn dihedral_range(mesh: &TetMesh) -> Option<(f64, f64)> {
    let mut range: Option<(f64, f64)> = None;
    for t in &mesh.tets {
        let p = t.map(|v| {
            mesh.positions
                .get(v as usize)
                .copied()
                .unwrap_or(DVec3::NAN)
        });
        for a in dihedral_angles(p) {
            if a.is_nan() {
                return None;
            }
            range = Some(range.map_or((a, a), |(lo, hi)| (lo.min(a), hi.max(a))));
        }
    }
    range
}

/// The mesh as tet-diffusion takes it (absolute positions in the file's
/// unit): inverted tetrahedra re-oriented, degenerate ones an error.
///
/// # Errors
/// tet-diffusion's, naming the tetrahedron.
pub fn diffusion_mesh(mesh: &TetMesh) -> Result<tet_diffusion::TetMesh, tet_diffusion::Error> {
    tet_diffusion::TetMesh::new(&mesh.positions, &mesh.tets)
}

/// The nodes [`drop_unused_nodes`] took out of a file's mesh, and how to
/// put per-node results back in the file's numbering (what TetGen and
/// meshio users expect of a `.vtu` written from their mesh).
#[derive(Debug, Clone)]
pub struct DroppedNodes {
    /// The mesh as read, every node kept.
    pub original: TetMesh,
    /// `map[new] = old`: each node of the solver's mesh in `original`.
    pub map: Vec<u32>,
    /// The dropped nodes (0-based, as `original` numbers them), ascending.
    pub dropped: Vec<u32>,
}

impl DroppedNodes {
    /// What to tell the user: the file, how many nodes, the first one.
    pub fn warning(&self, path: &std::path::Path) -> String {
        format!(
            "{}: {} node{} used by no tetrahedron (first: node {}, 0-based) dropped before \
             solving; per-node results are written back in the file's numbering, NaN there",
            path.display(),
            self.dropped.len(),
            if self.dropped.len() == 1 {
                " is"
            } else {
                "s are"
            },
            self.dropped[0],
        )
    }

    /// Whether `positions` are the kept nodes, in order: the solver's mesh
    /// is still the file's (no cut or fracture changed it).
    pub fn is_solved(&self, positions: &[DVec3]) -> bool {
        positions.len() == self.map.len()
            && self
                .map
                .iter()
                .zip(positions)
                .all(|(&old, p)| self.original.positions[old as usize] == *p)
    }

    /// Per-node `values` of the solver's mesh in the file's numbering:
    /// NaN at the dropped nodes (no tetrahedron gives them a value).
    pub fn scatter(&self, values: &[f64]) -> Vec<f64> {
        let mut out = vec![f64::NAN; self.original.positions.len()];
        for (&old, &v) in self.map.iter().zip(values) {
            out[old as usize] = v;
        }
        out
    }
}

/// `mesh` without the nodes no tetrahedron uses (their rows of a
/// diffusion system would be empty, which tet-diffusion refuses), and
/// what was dropped; `None` when every node is used.
pub fn drop_unused_nodes(mesh: TetMesh) -> (TetMesh, Option<DroppedNodes>) {
    let dropped = mesh.unused_nodes();
    if dropped.is_empty() {
        return (mesh, None);
    }
    let (compact, map) = mesh.without_unused_nodes();
    (
        compact,
        Some(DroppedNodes {
            original: mesh,
            map,
            dropped,
        }),
    )
}

/// A stuffed mesh (`tet_stuffing`) as trilux-io's, to write.
pub fn from_stuffing(mesh: &tet_stuffing::TetMesh, origin: DVec3) -> TetMesh {
    TetMesh {
        positions: mesh.positions.iter().map(|&p| p + origin).collect(),
        tets: mesh.tets.clone(),
        ..TetMesh::default()
    }
}

/// The lattice spacing `trilux tetra` uses without `--size`: 1/40 of the
/// diagonal of the bounding box of the triangles' vertices (in `f64`: an
/// `f32` diagonal overflows for coordinates near 10³⁸); 0 without
/// triangles.
pub fn default_spacing(mesh: &TriMesh) -> f64 {
    let (lo, hi) = crate::mesh::bounds(mesh).unwrap_or_default();
    (hi.as_dvec3() - lo.as_dvec3()).length() / 40.0
}

/// A boundary to draw: positions, triangles, (unused) colours, normals.
type Shape = (Vec<Vec3>, Vec<[u32; 3]>, Vec<[f32; 3]>, Vec<Vec3>);

/// A rendered picture, and what the tone map needs to expose the objects
/// alone.
#[derive(Debug, Clone)]
pub struct Picture {
    /// Linear radiance (RGBA), the objects over the background gradient:
    /// what the EXR holds.
    pub image: trilux_io::image::Image,
    /// Per pixel (row-major), the fraction of it the objects cover.
    pub coverage: Vec<f32>,
    /// The background gradient alone.
    pub background: trilux_io::image::Image,
}

/// The objects' boundaries shaded per pixel with the radiance in air
/// toward the eye ([`fragment_radiance`]: `J⁺` interpolated from the
/// vertices, `F_t` from each fragment's direction to the eye), plus a
/// Blinn–Phong specular term of the directional and point lights.
pub fn render(
    objects: &[tet_diffusion::Object],
    lights: &[Light],
    size: u32,
    view: Option<Vec3>,
) -> Picture {
    use crate::preview::{Camera, Renderer};
    let shapes: Vec<Shape> = objects
        .iter()
        .map(|o| {
            let m = o.mesh();
            let positions: Vec<Vec3> = o.display_positions().iter().map(|p| p.as_vec3()).collect();
            (
                positions,
                m.boundary().to_vec(),
                Vec::new(),
                display_normals(o),
            )
        })
        .collect();
    let all: Vec<Vec3> = shapes.iter().flat_map(|s| s.0.iter().copied()).collect();
    let camera = match crate::preview::bounds(&all) {
        Some((lo, hi)) => match view {
            Some(from) => Camera::fit_from(lo, hi, from),
            None => Camera::fit(lo, hi),
        },
        None => Camera::fit(Vec3::splat(-1.0), Vec3::ONE),
    };
    let mut r = Renderer::new(size, size, camera);
    for (o, (positions, faces, _, normals)) in objects.iter().zip(&shapes) {
        let m = o.mesh();
        let mut flux = vec![[0.0f32; 3]; m.vertex_count()];
        for (&v, j) in m.boundary_vertices().iter().zip(o.boundary_flux()) {
            flux[v as usize] = j.map(|x| x as f32);
        }
        let eta = o.eta();
        let scale = (1.0 / (4.0 * std::f64::consts::PI)) as f32;
        r.draw_mesh(positions, faces, |f| {
            let t = faces[f.face as usize];
            let b = f.barycentric;
            let mut j = [0.0f32; 3];
            for k in 0..3 {
                for (ch, x) in j.iter_mut().enumerate() {
                    *x += b[k] * flux[t[k] as usize][ch];
                }
            }
            let n = (normals[t[0] as usize] * b[0]
                + normals[t[1] as usize] * b[1]
                + normals[t[2] as usize] * b[2])
                .normalize_or(f.normal);
            let mut c = fragment_radiance(j, n, f.to_eye, eta);
            add_specular(&mut c, lights, n, f, scale);
            c
        });
    }
    Picture {
        image: r.image(),
        coverage: r.coverage(),
        background: r.background(),
    }
}

/// Adds the Blinn–Phong highlight of the directional and point lights at
/// fragment `f` (shading normal `n`; `scale` = 1/4π) to `c`.
fn add_specular(
    c: &mut [f32; 3],
    lights: &[Light],
    n: Vec3,
    f: &crate::preview::Fragment,
    scale: f32,
) {
    for light in lights {
        let (l, rgb) = match light {
            Light::Directional {
                to_light,
                irradiance,
            } => (to_light.as_vec3().normalize_or_zero(), *irradiance),
            Light::Point {
                position,
                intensity,
            } => (
                (position.as_vec3() - f.position).normalize_or_zero(),
                *intensity,
            ),
            Light::Environment(_) => continue,
        };
        let h = (l + f.to_eye).normalize_or_zero();
        let spec = 0.04 * n.dot(h).max(0.0).powf(80.0) * f32::from(n.dot(l) > 0.0) * scale;
        for (x, c) in c.iter_mut().zip(rgb) {
            *x += spec * c as f32;
        }
    }
}

/// The object's outward vertex normals turned by its display transform.
fn display_normals(o: &tet_diffusion::Object) -> Vec<Vec3> {
    let turn = o.transform().matrix3;
    o.mesh()
        .vertex_normals()
        .iter()
        .map(|n| (turn * *n).normalize_or_zero().as_vec3())
        .collect()
}

/// The boundary triangles of `mesh` numbered by their place in
/// [`boundary_vertices`](tet_diffusion::TetMesh::boundary_vertices): the
/// numbering of [`Object::radiance`](tet_diffusion::Object::radiance) and
/// [`Object::boundary_flux`](tet_diffusion::Object::boundary_flux), so a
/// surface of the boundary vertices alone takes them as they are (what
/// `trilux view` sends the page, and [`radiance_surface`] writes).
pub fn boundary_triangles(mesh: &tet_diffusion::TetMesh) -> Vec<[u32; 3]> {
    mesh.boundary()
        .iter()
        // Every corner of a boundary triangle is a boundary vertex.
        .map(|t| t.map(|v| mesh.boundary_index(v as usize).unwrap_or(0) as u32))
        .collect()
}

/// The name of each piece in [`radiance_surface`]'s mesh (its glTF node
/// and mesh): `piece K`, K from 0 as the pieces are given.
pub fn piece_name(k: usize) -> String {
    format!("piece {k}")
}

/// The boundary surfaces of solved objects (the pieces of a session, or
/// of a fracture) as one triangle mesh with per-vertex data, one
/// [`Object`] range per piece (named by [`piece_name`]): what
/// [`write_radiance_gltf`] writes.
///
/// - Positions: the boundary vertices of each piece in the display frame
///   ([`Object::display_positions`](tet_diffusion::Object::display_positions):
///   fractured pieces where they were moved, as the pictures show them),
///   in the mesh's own unit (as the VTU and TetGen exports; glTF viewers
///   take them as metres), relative to a global shift for coordinates far
///   from zero ([`trilux_io::mesh::recenter`], written as the node's
///   translation). Normals: the outward vertex normals, turned likewise.
///   Triangles: [`boundary_triangles`], outward.
/// - Material: none of its own, so the writer gives the pieces its unlit
///   one ([`trilux_io::mesh::gltf::UNLIT_MATERIAL`]): the vertex colours
///   are the final colour, which a lit material would shade again.
/// - `COLOR_0` ([`VertexData::colors`]): the linear outgoing radiance at
///   normal exitance ([`Object::radiance`](tet_diffusion::Object::radiance)`(None)`),
///   divided by `white` and clamped to `[0, 1]`, alpha 1. Pass the
///   picture's [`exposure_white`] (as `trilux diffuse` and `trilux view`'s
///   export do), and a viewer that shows the vertex colours unlit shows
///   the PNG's exposure: the brightest 1 % of the picture at white, the
///   rest linear below it (the PNG's pixels also carry the view-dependent
///   Fresnel factor and the specular highlight, which per-vertex colours
///   cannot).
/// - `_RADIANCE` (VEC3): the same radiance unscaled and unclamped, linear
///   RGB in W/(mm² sr).
/// - `_PHI` (VEC3): the fluence φ at each boundary vertex, one value per
///   colour channel (the diffusion is solved per channel), as
///   [`Object::fluence`](tet_diffusion::Object::fluence).
///
/// # Errors
/// [`Error::Invalid`](crate::Error::Invalid) for no objects, a `white`
/// that is not a positive finite number, or a radiance or φ that is not
/// finite (naming the piece and the vertex).
pub fn radiance_surface(
    objects: &[tet_diffusion::Object],
    white: f32,
) -> crate::Result<(TriMesh, VertexData)> {
    use crate::Error::Invalid;
    if objects.is_empty() {
        return Err(Invalid(
            "no objects: a radiance surface needs at least one".into(),
        ));
    }
    if !(white.is_finite() && white > 0.0) {
        return Err(Invalid(format!(
            "the exposure's white {white}: must be a positive finite radiance"
        )));
    }
    let mut absolute = Vec::new();
    let mut normals = Vec::new();
    let mut indices = Vec::new();
    let mut parts = Vec::new();
    let mut colors = Vec::new();
    let mut radiance = Vec::new();
    let mut phi = Vec::new();
    for (k, o) in objects.iter().enumerate() {
        let m = o.mesh();
        let bv = m.boundary_vertices();
        let base = absolute.len() as u32;
        let first = indices.len();
        let display = o.display_positions();
        let turned = display_normals(o);
        absolute.extend(bv.iter().map(|&v| display[v as usize]));
        normals.extend(bv.iter().map(|&v| turned[v as usize]));
        indices.extend(
            boundary_triangles(m)
                .into_iter()
                .map(|t| t.map(|i| i + base)),
        );
        parts.push(Object {
            name: piece_name(k),
            triangles: first..indices.len(),
            // The writer's unlit material: the radiance is the whole
            // colour, which a lit material would shade a second time.
            material: None,
        });
        let fluence = o.fluence();
        for (i, (&v, l)) in bv.iter().zip(o.radiance(None)).enumerate() {
            let f = fluence[v as usize];
            if !l.iter().chain(&f).all(|x| x.is_finite()) {
                return Err(Invalid(format!(
                    "{} (boundary vertex {i}, node {v}): the radiance {l:?} or φ {f:?} is not \
                     finite (is the object solved?)",
                    piece_name(k)
                )));
            }
            let l = Vec3::from_array(l.map(|x| x as f32));
            let c = (l / white).clamp(Vec3::ZERO, Vec3::ONE);
            colors.push([c.x, c.y, c.z, 1.0]);
            radiance.push(l);
            phi.push(Vec3::from_array(f.map(|x| x as f32)));
        }
    }
    let (origin, positions) = trilux_io::mesh::recenter(&absolute);
    let mesh = TriMesh {
        positions,
        origin,
        indices,
        normals: Some(normals),
        objects: parts,
        ..TriMesh::default()
    };
    let data = VertexData {
        colors: Some(colors),
        attributes: vec![
            Attribute {
                name: "RADIANCE".into(),
                values: AttributeValues::Vec3(radiance),
            },
            Attribute {
                name: "PHI".into(),
                values: AttributeValues::Vec3(phi),
            },
        ],
    };
    Ok((mesh, data))
}

/// Writes [`radiance_surface`]`(objects, white)` as glTF by extension:
/// `.glb`, or `.gltf` with its `.bin` beside it
/// ([`crate::output::write_gltf`]: atomic; an existing file, the `.bin`
/// too, is refused unless `overwrite`). Returns the files written.
///
/// # Errors
/// [`radiance_surface`]'s, [`Error::Exists`](crate::Error::Exists), and
/// the writer's (an extension other than `.glb` or `.gltf`, I/O).
pub fn write_radiance_gltf(
    path: &std::path::Path,
    objects: &[tet_diffusion::Object],
    white: f32,
    overwrite: bool,
) -> crate::Result<Vec<std::path::PathBuf>> {
    let (mesh, data) = radiance_surface(objects, white)?;
    crate::output::write_gltf(path, overwrite, |tmp| {
        trilux_io::mesh::gltf::write_with(tmp, &mesh, &data)
    })
}

/// The picture of a session as `trilux view` exports it: every piece, lit
/// by the first piece's lights (all pieces share them), seen from `view`
/// ([`render`]).
pub fn render_session(session: &tet_diffusion::Session, size: u32, view: Option<Vec3>) -> Picture {
    let lights = session.pieces()[0].lights();
    render(session.pieces(), &lights, size, view)
}

/// The radiance in air toward the eye at a fragment: the hemispherical
/// flux `J⁺` meeting the boundary from inside (interpolated from the
/// vertices, [`Object::boundary_flux`](tet_diffusion::Object::boundary_flux)) times `F_t(n·v) / (π η²)`
/// ([`tet_diffusion::fresnel::exit_radiance_factor`]), with `n` the unit
/// outward normal and `v` the unit direction from *this* fragment to the
/// eye — not the camera's central direction, which makes `F_t` up to 35 %
/// too large at the limb of a perspective view. Linear RGB, W/(mm² sr).
pub fn fragment_radiance(flux: [f32; 3], normal: Vec3, to_eye: Vec3, eta: f64) -> [f32; 3] {
    let cos = f64::from(normal.dot(to_eye));
    let f = tet_diffusion::fresnel::exit_radiance_factor(cos, eta) as f32;
    flux.map(|j| j * f)
}

/// The exposure's white: the 99th-percentile luminance of the pixels the
/// objects cover fully (of those they cover at all when none is fully
/// covered; 1 when nothing is covered). The background never counts, so a
/// dim or back-lit object is exposed as brightly as a bright one.
pub fn exposure_white(picture: &Picture) -> f32 {
    let covered = |full: bool| -> Vec<f32> {
        let mut lum: Vec<f32> = picture
            .image
            .pixels
            .iter()
            .zip(&picture.coverage)
            .filter(|&(_, &c)| if full { c >= 1.0 } else { c > 0.0 })
            .map(|(p, _)| trilux_io::image::luminance([p[0], p[1], p[2]]))
            .filter(|l| *l > 0.0)
            .collect();
        lum.sort_by(f32::total_cmp);
        lum
    };
    let mut lum = covered(true);
    if lum.is_empty() {
        lum = covered(false);
    }
    lum.get(lum.len() * 99 / 100)
        .copied()
        .unwrap_or(1.0)
        .max(1e-12)
}

/// Exposure so that the brightest 1 % of the objects' pixels reach white
/// ([`exposure_white`]), the background gradient left as it is (a pixel
/// the objects do not cover is copied unchanged; an edge pixel scales only
/// its covered part), then the PNG writer's sRGB encoding.
#[allow(
    clippy::needless_range_loop,
    reason = "each of R, G, B reads three per-channel arrays"
)]
pub fn tone_map(picture: &Picture) -> trilux_io::image::Image {
    let white = exposure_white(picture);
    let pixels = picture
        .image
        .pixels
        .iter()
        .zip(&picture.coverage)
        .zip(&picture.background.pixels)
        .map(|((p, &c), bg)| {
            if c <= 0.0 {
                return *p;
            }
            let behind = 1.0 - c;
            let mut out = [0.0, 0.0, 0.0, 1.0];
            for k in 0..3 {
                let object = (p[k] - behind * bg[k]).max(0.0);
                out[k] = object / white + behind * bg[k];
            }
            out
        })
        .collect();
    trilux_io::image::Image {
        pixels,
        ..picture.image.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three dihedral-angle functions the dependency graph keeps
    /// (this one for any file's tets, tet-stuffing's, tet-diffusion's for
    /// validated meshes) agree on the same random tets.
    #[test]
    fn dihedral_angles_agree_with_the_crates_that_own_them() {
        let mut rng = test_support::SplitMix64(24);
        for _ in 0..200 {
            let p: [DVec3; 4] =
                std::array::from_fn(|_| DVec3::new(rng.f64(), rng.f64(), rng.f64()));
            let here = dihedral_angles(p);
            let stuffing = tet_stuffing::dihedral_angles(p).map(f64::to_degrees);
            let Ok(mesh) = tet_diffusion::TetMesh::new(&p, &[[0, 1, 2, 3]]) else {
                continue; // too flat for the solver's mesh
            };
            // The solver's mesh may have re-oriented the tet (swapping
            // corners 0 and 1), which permutes the edges.
            let swapped = mesh.tets()[0] != [0, 1, 2, 3];
            let diffusion = mesh.dihedral_angles(0).map(f64::to_degrees);
            // Edge e of (0,1) (0,2) (0,3) (1,2) (1,3) (2,3) is angle 5 − e
            // here (the pair of faces opposite its two other corners).
            for e in 0..6 {
                let d = if swapped { [0, 3, 4, 1, 2, 5][e] } else { e };
                assert!((here[5 - e] - stuffing[e]).abs() < 1e-8, "{p:?} edge {e}");
                assert!((stuffing[e] - diffusion[d]).abs() < 1e-8, "{p:?} edge {e}");
            }
        }
    }

    /// A marble ball of radius 1 (10 mm) lit from +x, solved, broken in two
    /// by the plane x = 0.1; the second piece moved far from the origin
    /// (so the file needs a global shift).
    fn two_lit_pieces() -> [tet_diffusion::Object; 2] {
        let (p, t) = tet_diffusion::kuhn_ball(6, 1.0);
        let mesh = tet_diffusion::TetMesh::new(&p, &t).unwrap();
        let marble = tet_diffusion::Medium::measured("marble").unwrap();
        let mut o = tet_diffusion::Object::homogeneous(mesh, 10.0, marble, 1.3).unwrap();
        o.add_light(Light::Directional {
            to_light: DVec3::X,
            irradiance: [1.0; 3],
        })
        .unwrap();
        let [mut a, mut b] = o.fracture(DVec3::new(0.1, 0.0, 0.0), DVec3::X).unwrap();
        let far = DVec3::new(2.0e6, -3.0, 0.5);
        a.set_transform(glam::DAffine3::from_translation(far));
        b.set_transform(glam::DAffine3::from_translation(far + 0.3 * DVec3::X));
        a.solve().unwrap();
        b.solve().unwrap();
        [a, b]
    }

    /// The median luminance of the pieces' radiance: about half the
    /// vertices clamp at it.
    fn median_white(pieces: &[tet_diffusion::Object]) -> f32 {
        let mut lum: Vec<f32> = pieces
            .iter()
            .flat_map(|o| o.radiance(None))
            .map(|l| trilux_io::image::luminance(l.map(|x| x as f32)))
            .collect();
        lum.sort_by(f32::total_cmp);
        lum[lum.len() / 2]
    }

    #[test]
    fn a_radiance_surface_is_each_pieces_boundary_with_its_radiance_and_phi() {
        let pieces = two_lit_pieces();
        let white = median_white(&pieces);
        let (mesh, data) = radiance_surface(&pieces, white).unwrap();
        assert_eq!(mesh.objects.len(), 2);
        assert!(mesh.origin.x > 1.9e6, "{}", mesh.origin);
        let colors = data.colors.as_ref().unwrap();
        let radiance = match data.attribute("RADIANCE") {
            Some(AttributeValues::Vec3(v)) => v,
            other => panic!("{other:?}"),
        };
        let phi = match data.attribute("PHI") {
            Some(AttributeValues::Vec3(v)) => v,
            other => panic!("{other:?}"),
        };
        let normals = mesh.normals.as_ref().unwrap();
        let (mut base, mut clamped) = (0usize, 0);
        for (k, o) in pieces.iter().enumerate() {
            let m = o.mesh();
            let bv = m.boundary_vertices();
            let part = &mesh.objects[k];
            assert_eq!(part.name, format!("piece {k}"));
            assert_eq!(part.triangles.len(), m.boundary().len());
            // The same triangles, in the boundary vertices' numbering.
            for (t, b) in mesh.indices[part.triangles.clone()]
                .iter()
                .zip(m.boundary())
            {
                assert_eq!(t.map(|i| bv[i as usize - base]), *b);
            }
            let display = o.display_positions();
            let l = o.radiance(None);
            let f = o.fluence();
            for (i, &v) in bv.iter().enumerate() {
                let j = base + i;
                let p = mesh.origin + mesh.positions[j].as_dvec3();
                assert!(p.distance(display[v as usize]) < 1e-6, "{p} {k} {i}");
                let n = (o.transform().matrix3 * m.vertex_normals()[v as usize]).as_vec3();
                assert!(normals[j].distance(n) < 1e-6);
                let expected = Vec3::from_array(l[i].map(|x| x as f32));
                assert_eq!(radiance[j], expected);
                assert_eq!(phi[j], Vec3::from_array(f[v as usize].map(|x| x as f32)));
                for c in 0..3 {
                    let shown = (expected[c] / white).min(1.0);
                    assert_eq!(colors[j][c], shown);
                }
                assert_eq!(colors[j][3], 1.0);
                clamped += usize::from(expected.max_element() > white);
            }
            base += bv.len();
        }
        assert_eq!(base, mesh.positions.len());
        // The white matters: some clamp, some do not.
        assert!(clamped > base / 4 && clamped < base, "{clamped} of {base}");
        // The side facing the light (+x) is brighter than the far side.
        let local_x: Vec<f64> = pieces
            .iter()
            .flat_map(|o| {
                let p = o.mesh().positions();
                o.mesh()
                    .boundary_vertices()
                    .iter()
                    .map(|&v| p[v as usize].x)
            })
            .collect();
        let side = |lit: bool| {
            let js: Vec<usize> = (0..base)
                .filter(|&j| {
                    if lit {
                        local_x[j] > 0.5
                    } else {
                        local_x[j] < -0.5
                    }
                })
                .collect();
            js.iter().map(|&j| radiance[j].x).sum::<f32>() / js.len() as f32
        };
        let (lit, dark) = (side(true), side(false));
        assert!(lit > 2.0 * dark && dark > 0.0, "{lit} {dark}");
    }

    #[test]
    fn a_radiance_gltf_reads_back_validates_and_is_not_overwritten_silently() {
        let pieces = two_lit_pieces();
        let dir = tempfile::tempdir().unwrap();
        let white = median_white(&pieces);
        let (mesh, data) = radiance_surface(&pieces, white).unwrap();
        for name in ["r.glb", "r.gltf"] {
            let path = dir.path().join(name);
            write_radiance_gltf(&path, &pieces, white, false).unwrap();
            test_support::gltf::validate(&path);
            let scene = trilux_io::mesh::gltf::read_scene(&path).unwrap();
            let back = &scene.vertex_data;
            assert!(back.colors == data.colors, "{name}: the colours differ");
            for a in &data.attributes {
                let got = back.attribute(&a.name);
                assert!(got == Some(&a.values), "{name}: {} differs", a.name);
            }
            assert_eq!(back.attributes.len(), 2);
            assert_eq!(scene.mesh.indices, mesh.indices);
            let names: Vec<&str> = scene.mesh.objects.iter().map(|o| o.name.as_str()).collect();
            assert_eq!(names, ["piece 0", "piece 1"]);
            let far = mesh.absolute_positions();
            for (a, b) in scene.mesh.absolute_positions().iter().zip(&far) {
                assert!(a.distance(*b) < 1e-3, "{a} {b}");
            }
            // Refused without overwrite, kept as it was; replaced with it
            // (the colours are in the .bin of a .gltf).
            let bytes = || {
                let mut b = std::fs::read(&path).unwrap();
                if name.ends_with("gltf") {
                    b.extend(std::fs::read(path.with_extension("bin")).unwrap());
                }
                b
            };
            let before = bytes();
            let e = write_radiance_gltf(&path, &pieces, 2.0 * white, false).unwrap_err();
            assert!(matches!(e, crate::Error::Exists(_)), "{e}");
            assert!(bytes() == before, "{name}: changed");
            write_radiance_gltf(&path, &pieces, 2.0 * white, true).unwrap();
            assert!(bytes() != before, "{name}: not replaced");
        }
        // A .gltf's .bin in the way is refused too, and nothing is moved.
        let lone = dir.path().join("lone.gltf");
        std::fs::write(dir.path().join("lone.bin"), "keep").unwrap();
        let e = write_radiance_gltf(&lone, &pieces, white, false).unwrap_err();
        assert!(e.to_string().contains("lone.bin"), "{e}");
        assert!(!lone.exists());
        // No temporary files left behind.
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["lone.bin", "r.bin", "r.glb", "r.gltf"]);
    }

    #[test]
    fn a_radiance_surface_refuses_what_it_cannot_show() {
        let pieces = two_lit_pieces();
        for white in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let e = radiance_surface(&pieces, white).unwrap_err().to_string();
            assert!(e.contains("the exposure's white"), "{e}");
        }
        let e = radiance_surface(&[], 1.0).unwrap_err().to_string();
        assert!(e.starts_with("no objects"), "{e}");
        let [mut a, _] = pieces;
        let n = a.mesh().vertex_count();
        let mut phi = vec![1.0; n];
        let v = a.mesh().boundary_vertices()[3] as usize;
        phi[v] = f64::NAN;
        a.set_phi([phi, vec![1.0; n], vec![1.0; n]]).unwrap();
        let e = radiance_surface(std::slice::from_ref(&a), 1.0)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with(&format!("piece 0 (boundary vertex 3, node {v})")),
            "{e}"
        );
    }

    #[test]
    fn dropped_nodes_scatter_back_to_the_files_numbering() {
        let mesh = TetMesh {
            positions: vec![
                DVec3::splat(5.0),
                DVec3::ZERO,
                DVec3::X,
                DVec3::splat(7.0),
                DVec3::Y,
                DVec3::Z,
            ],
            tets: vec![[1, 2, 4, 5]],
            ..TetMesh::default()
        };
        let (compact, dropped) = drop_unused_nodes(mesh.clone());
        let dropped = dropped.unwrap();
        assert_eq!(compact.tets, [[0, 1, 2, 3]]);
        assert_eq!(
            compact.positions,
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
        );
        assert_eq!(dropped.dropped, [0, 3]);
        let back = dropped.scatter(&[10.0, 20.0, 40.0, 50.0]);
        assert!(back[0].is_nan() && back[3].is_nan());
        assert_eq!(
            [back[1], back[2], back[4], back[5]],
            [10.0, 20.0, 40.0, 50.0]
        );
        let text = dropped.warning(std::path::Path::new("m.node"));
        assert!(text.starts_with("m.node: 2 nodes are used by no tetrahedron (first: node 0"));
        assert!(dropped.is_solved(&compact.positions));
        assert!(!dropped.is_solved(&mesh.positions));
        let (same, none) = drop_unused_nodes(compact.clone());
        assert!(none.is_none());
        assert_eq!(same, compact);
        assert!(tet_diffusion::TetMesh::new(&same.positions, &same.tets).is_ok());
        assert!(tet_diffusion::TetMesh::new(&mesh.positions, &mesh.tets).is_err());
    }
}
