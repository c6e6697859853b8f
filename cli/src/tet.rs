//! trilux-io tetrahedral meshes → solver positions, surfaces, quality.

use glam::DVec3;
use trilux_io::mesh::{Object, TriMesh};
use trilux_io::tet::TetMesh;

/// The node positions as `[x, y, z]` rows, the form multires'
/// `Weights::Positions` (and the solvers built on it) take.
pub fn positions_f64(mesh: &TetMesh) -> Vec<[f64; 3]> {
    mesh.positions.iter().map(|p| p.to_array()).collect()
}

/// The boundary of a tetrahedral mesh as a triangle mesh (outward
/// triangles, `f32` positions, only the boundary's vertices), for previews
/// and sampling.
pub fn surface(mesh: &TetMesh) -> TriMesh {
    let boundary = mesh.boundary();
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let indices: Vec<[u32; 3]> = boundary
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut map[v as usize];
                if *slot == u32::MAX {
                    *slot = positions.len() as u32;
                    positions.push(mesh.positions[v as usize].as_vec3());
                }
                *slot
            })
        })
        .collect();
    TriMesh {
        objects: vec![Object {
            name: String::new(),
            triangles: 0..indices.len(),
            material: None,
        }],
        positions,
        indices,
        ..TriMesh::default()
    }
}

/// The six interior dihedral angles of a tetrahedron, in degrees: 0° and
/// 180° for a flat one, NaN where a face has no area (two corners
/// coincide).
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

/// A stuffed mesh (`tet_stuffing`) as trilux-io's, to write.
pub fn from_stuffing(mesh: &tet_stuffing::TetMesh, origin: DVec3) -> TetMesh {
    TetMesh {
        positions: mesh.positions.iter().map(|&p| p + origin).collect(),
        tets: mesh.tets.clone(),
        ..TetMesh::default()
    }
}
