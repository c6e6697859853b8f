//! Sampled points → a point cloud: PLY data, which
//! `trilux_io::mesh::gltf::Points::from` turns into a glTF `POINTS`
//! primitive.

use mesh_sampling::SurfacePoint;
use rayon::prelude::*;
use trilux_io::mesh::TriMesh;
use trilux_io::mesh::ply::PlyData;

/// A point cloud of sampled points on `mesh`: positions; normals (the
/// interpolated shading normal when the mesh has normals, else the
/// triangle's); the mesh's UVs interpolated at the point (glTF convention;
/// the PLY writer converts) when it has UVs; the triangle of each point
/// (PLY `face_id`); and the mesh's origin (far-from-origin scans keep
/// their coordinates). Attributes are taken from `mesh` at each
/// point's face and barycentrics, so points drawn on a re-parameterised
/// copy of the mesh (the same triangles in the same order) get `mesh`'s
/// UVs.
///
/// # Example
/// ```
/// use mesh_sampling::{SurfaceSampler, UniformSampler};
/// let mesh = trilux::shapes::torus(16, 8);
/// let points = UniformSampler::new(trilux::mesh_ref(&mesh))?.sample_n(7, 100)?;
/// let cloud = trilux::point_cloud(&mesh, &points);
/// assert_eq!(cloud.positions.len(), 100);
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
pub fn point_cloud(mesh: &TriMesh, points: &[SurfacePoint]) -> PlyData {
    let corners = |p: &SurfacePoint| mesh.indices.get(p.face as usize).copied();
    let positions = points.par_iter().map(|p| p.position).collect();
    let normals = match &mesh.normals {
        Some(n) => points
            .par_iter()
            .map(|p| {
                corners(p)
                    .map(|t| {
                        let [a, b, c] = t.map(|v| n[v as usize]);
                        let w = p.barycentric;
                        (a * w[0] + b * w[1] + c * w[2]).normalize_or(p.normal)
                    })
                    .unwrap_or(p.normal)
            })
            .collect(),
        None => points.par_iter().map(|p| p.normal).collect(),
    };
    let uvs = mesh.uvs.as_ref().map(|uv| {
        points
            .par_iter()
            .map(|p| {
                corners(p)
                    .map(|t| {
                        let [a, b, c] = t.map(|v| uv[v as usize]);
                        let w = p.barycentric;
                        a + (b - a) * w[1] + (c - a) * w[2]
                    })
                    .unwrap_or_default()
            })
            .collect()
    });
    let face_ids = points.par_iter().map(|p| p.face).collect();
    PlyData {
        positions,
        origin: mesh.origin,
        normals: Some(normals),
        uvs,
        face_ids: Some(face_ids),
        ..PlyData::default()
    }
}
