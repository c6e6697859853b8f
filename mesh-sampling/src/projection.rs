//! A texture mapping for meshes that have none.

use glam::{Vec2, Vec3};

use crate::{Error, MeshRef};

/// A spherical projection about the bounding-box centre: `u` is the
/// longitude (`atan2(z, x)`), `v` the polar angle from +y, both scaled to
/// `[0, 1]`. Every corner gets its own vertex, so a triangle across the
/// `u = 0 | 1` seam can take `u + 1` on one side and stay a small triangle
/// in UV space (with [`Wrap::Repeat`](crate::Wrap::Repeat) the texture
/// continues across). Returns positions, UVs and indices of the new mesh,
/// whose triangle `f` is triangle `f` of the input.
///
/// # Errors
/// Those of [`MeshRef::validate`] (no triangles, an index out of range, a
/// non-finite position).
#[expect(clippy::type_complexity, reason = "the three arrays of a mesh")]
pub fn spherical_uvs(
    positions: &[Vec3],
    indices: &[[u32; 3]],
) -> Result<(Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>), Error> {
    MeshRef::new(positions, indices).validate()?;
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let centre = (lo + hi) * 0.5;
    let project = |p: Vec3| {
        let d = (p - centre).normalize_or(Vec3::Y);
        let u = 0.5 + d.z.atan2(d.x) / std::f32::consts::TAU;
        let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
        Vec2::new(u, v)
    };
    let mut out_positions = Vec::with_capacity(indices.len() * 3);
    let mut uvs = Vec::with_capacity(indices.len() * 3);
    let mut out_indices = Vec::with_capacity(indices.len());
    for tri in indices {
        let corners = tri.map(|i| positions[i as usize]);
        let mut uv = corners.map(project);
        // Unwrap u so that no edge crosses the seam the long way round.
        for k in 1..3 {
            let du = uv[k].x - uv[0].x;
            if du > 0.5 {
                uv[k].x -= 1.0;
            } else if du < -0.5 {
                uv[k].x += 1.0;
            }
        }
        let base = out_positions.len() as u32;
        out_positions.extend(corners);
        uvs.extend(uv);
        out_indices.push([base, base + 1, base + 2]);
    }
    Ok((out_positions, uvs, out_indices))
}
