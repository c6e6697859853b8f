//! `TriMesh` → `mesh_sampling::MeshRef`, and what a person checks of a
//! mesh before a long run.

use glam::Vec3;
use mesh_sampling::MeshRef;
use trilux_io::mesh::TriMesh;

/// The mesh as mesh-sampling borrows it: positions, triangles, and the
/// normals and UVs the file had. No copy and no flip: `TriMesh` UVs are
/// glTF's (v down, row 0 at `v = 0`), which is what `DensityTexture`
/// expects of images stored top row first.
///
/// # Example
/// ```
/// use trilux_io::mesh::TriMesh;
/// let mesh = trilux::shapes::icosphere(2);
/// let sampler = mesh_sampling::UniformSampler::new(trilux::mesh_ref(&mesh))?;
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
pub fn mesh_ref(mesh: &TriMesh) -> MeshRef<'_> {
    MeshRef {
        positions: &mesh.positions,
        indices: &mesh.indices,
        normals: mesh.normals.as_deref(),
        uvs: mesh.uvs.as_deref(),
    }
}

/// The axis-aligned bounding box of the vertices the triangles use
/// (`None` without triangles). Unused vertices (the Stanford bunny has
/// 1,113) do not count.
pub fn bounds(mesh: &TriMesh) -> Option<(Vec3, Vec3)> {
    let mut it = mesh
        .indices
        .iter()
        .flatten()
        .filter_map(|&i| mesh.positions.get(i as usize));
    let first = *it.next()?;
    Some(it.fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))))
}

/// Edge statistics of a triangle soup after welding equal positions: the
/// number of connected parts, boundary edges, non-manifold edges, and
/// boundary loops (holes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Shape {
    /// Vertices after welding equal positions (used ones only).
    pub welded_vertices: usize,
    /// Connected parts: faces joined through shared (welded) edges.
    pub parts: usize,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with three or more faces.
    pub non_manifold_edges: usize,
    /// Closed loops of boundary edges (holes).
    pub holes: usize,
}

/// Parts, holes and edge counts of `mesh`, welded by position.
pub fn shape(mesh: &TriMesh) -> Shape {
    use std::collections::HashMap;
    let (welded, faces, _) = mesh_colors::weld(&mesh.positions, &mesh.indices);
    let used = {
        let mut used = vec![false; welded.len()];
        for &v in faces.iter().flatten() {
            used[v as usize] = true;
        }
        used
    };
    // Per edge: its face count and its first face.
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(faces.len() * 3 / 2);
    // Parts by union-find over faces that share an edge, as trimesh's
    // `split` and MeshLab's connected components count them: parts that
    // touch at a single vertex (Suzanne's eyes) stay apart.
    let mut parent: Vec<u32> = (0..faces.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for (i, f) in faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            let entry = edges.entry((a.min(b), a.max(b))).or_insert((0, i as u32));
            entry.0 += 1;
            let (r, q) = (find(&mut parent, entry.1), find(&mut parent, i as u32));
            if r != q {
                parent[r as usize] = q;
            }
        }
    }
    let parts = (0..faces.len() as u32)
        .filter(|&f| find(&mut parent, f) == f)
        .count();
    let boundary: Vec<(u32, u32)> = edges
        .iter()
        .filter(|&(_, &(n, _))| n == 1)
        .map(|(&e, _)| e)
        .collect();
    // Holes: connected components of the boundary edges.
    let mut bparent: HashMap<u32, u32> = HashMap::new();
    for &(a, b) in &boundary {
        bparent.entry(a).or_insert(a);
        bparent.entry(b).or_insert(b);
    }
    fn bfind(p: &mut HashMap<u32, u32>, mut x: u32) -> u32 {
        loop {
            let up = p[&x];
            if up == x {
                return x;
            }
            let upup = p[&up];
            p.insert(x, upup);
            x = up;
        }
    }
    for &(a, b) in &boundary {
        let (ra, rb) = (bfind(&mut bparent, a), bfind(&mut bparent, b));
        if ra != rb {
            bparent.insert(ra, rb);
        }
    }
    let keys: Vec<u32> = bparent.keys().copied().collect();
    let holes = keys
        .into_iter()
        .filter(|&v| bfind(&mut bparent, v) == v)
        .count();
    Shape {
        welded_vertices: used.iter().filter(|&&u| u).count(),
        parts,
        boundary_edges: boundary.len(),
        non_manifold_edges: edges.values().filter(|&&(n, _)| n > 2).count(),
        holes,
    }
}

/// A guess at the length unit from the size of the bounding box's
/// diagonal: scans in metres are about 0.1–10, in millimetres 10–10⁴.
pub fn unit_guess(diagonal: f32) -> &'static str {
    if !(diagonal.is_finite() && diagonal > 0.0) {
        "unknown"
    } else if diagonal < 5.0 {
        "metres (or unitless)"
    } else if diagonal < 5_000.0 {
        "millimetres or centimetres"
    } else {
        "millimetres or smaller"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed surface of a tetrahedron at `offset`, its four corners
    /// numbered from `first`.
    fn tet_surface(offset: Vec3, first: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z].map(|p| p + offset);
        let f =
            [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]].map(|t: [u32; 3]| t.map(|i| i + first));
        (p.to_vec(), f.to_vec())
    }

    fn two_tets(offset: Vec3) -> TriMesh {
        let (mut positions, mut indices) = tet_surface(Vec3::ZERO, 0);
        let (p, f) = tet_surface(offset, 4);
        positions.extend(p);
        indices.extend(f);
        TriMesh {
            positions,
            indices,
            ..Default::default()
        }
    }

    #[test]
    fn parts_touching_at_a_vertex_stay_apart() {
        // The second tetrahedron's first corner is the first one's (1, 0,
        // 0): one shared (welded) vertex and no shared edge, as Suzanne's
        // eyes touch her head.
        let s = shape(&two_tets(Vec3::X));
        assert_eq!(s.welded_vertices, 7);
        assert_eq!((s.parts, s.holes, s.boundary_edges), (2, 0, 0));
        assert_eq!(s.non_manifold_edges, 0);
        // Apart: two parts; one tetrahedron: one.
        assert_eq!(shape(&two_tets(Vec3::splat(5.0))).parts, 2);
        let (positions, indices) = tet_surface(Vec3::ZERO, 0);
        let one = TriMesh {
            positions,
            indices,
            ..Default::default()
        };
        assert_eq!(shape(&one).parts, 1);
    }

    #[test]
    fn faces_sharing_an_edge_are_one_part_with_its_hole() {
        // Two triangles on one edge (an open quad): one part, one hole of
        // four boundary edges.
        let mesh = TriMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            indices: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let s = shape(&mesh);
        assert_eq!((s.parts, s.holes, s.boundary_edges), (1, 1, 4));
    }
}
