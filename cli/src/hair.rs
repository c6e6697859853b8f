//! Grown strands → curves the files artists import hold (USD
//! `BasisCurves`, glTF lines, Cem Yuksel's `.hair`).

use mesh_sampling::Strands;
use trilux_io::curves::Curves;

/// The strands as curves of `segments + 1` points each, with their
/// widths and, per curve, the root's face, barycentrics, normal and UV
/// (when every root has one), so a renderer can re-attach them.
///
/// # Example
/// ```
/// use mesh_sampling::{HairOptions, StrandParams, SurfaceSampler, UniformSampler, grow_strands};
/// let mesh = trilux::shapes::torus(16, 8);
/// let roots = UniformSampler::new(trilux::mesh_ref(&mesh))?.sample_n(7, 10)?;
/// let strands = grow_strands(&roots, &HairOptions::default(), |_| StrandParams::straight(0.1))?;
/// let curves = trilux::hair::curves(&strands);
/// assert_eq!((curves.counts.len(), curves.points.len()), (10, 90));
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
pub fn curves(strands: &Strands) -> Curves {
    into_curves(strands.clone(), glam::DVec3::ZERO)
}

/// [`curves`] without copying the points (they are moved), put back in
/// a file's frame: `origin` (a far mesh's `TriMesh::origin`, which the
/// strands' points are relative to) added in `f32`.
pub fn into_curves(mut strands: Strands, origin: glam::DVec3) -> Curves {
    if origin != glam::DVec3::ZERO {
        let o = origin.as_vec3();
        strands.points.iter_mut().for_each(|p| *p += o);
    }
    let per = strands.points_per_strand() as u32;
    let roots = &strands.roots;
    let uvs: Option<Vec<_>> = roots.iter().map(|r| r.uv).collect();
    Curves {
        counts: vec![per; roots.len()],
        faces: Some(roots.iter().map(|r| r.face).collect()),
        barycentrics: Some(roots.iter().map(|r| r.barycentric).collect()),
        normals: Some(roots.iter().map(|r| r.normal).collect()),
        uvs: uvs.filter(|_| !roots.is_empty()),
        points: strands.points,
        widths: strands.widths,
    }
}
