//! trilux-io tetrahedral meshes → solver positions, surfaces, quality.

use glam::{DVec3, Vec3};
use tet_diffusion::Light;
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
