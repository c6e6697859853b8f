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
    /// Connected parts (through shared welded vertices).
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
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(faces.len() * 3 / 2);
    for f in &faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    // Parts by union-find over the faces' vertices.
    let mut parent: Vec<u32> = (0..welded.len() as u32).collect();
    fn find(parent: &mut [u32], mut x: u32) -> u32 {
        while parent[x as usize] != x {
            parent[x as usize] = parent[parent[x as usize] as usize];
            x = parent[x as usize];
        }
        x
    }
    for f in &faces {
        for k in 1..3 {
            let (a, b) = (find(&mut parent, f[0]), find(&mut parent, f[k]));
            if a != b {
                parent[a as usize] = b;
            }
        }
    }
    let parts = (0..welded.len() as u32)
        .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
        .count();
    let boundary: Vec<(u32, u32)> = edges
        .iter()
        .filter(|&(_, &n)| n == 1)
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
        non_manifold_edges: edges.values().filter(|&&n| n > 2).count(),
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
