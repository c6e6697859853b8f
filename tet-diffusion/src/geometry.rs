//! Per-tet geometry, a leaf below the mesh and the assembly: the local
//! faces and edges of a tetrahedron, its signed volume, its dihedral
//! angles and the geometric part of Eq. 10's weights. Nothing here knows a
//! mesh; [`crate::mesh`] and [`crate::assembly`] both build on it.

use glam::DVec3;

/// The faces of tetrahedron `(0, 1, 2, 3)` opposite each vertex, with
/// outward normals (right-hand rule) when it is positively oriented,
/// `det[p1 − p0, p2 − p0, p3 − p0] > 0`.
pub(crate) const OUTWARD_FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// The six edges of a tetrahedron as local vertex pairs; edge `e` and edge
/// `5 − e` are opposite (they share no vertex).
pub(crate) const EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// `det[b − a, c − a, d − a]`, six times the signed volume.
#[inline]
pub(crate) fn volume6(p: &[DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))
}

/// The dihedral angle (radians) of a tetrahedron at edge `(a, b)`, between
/// the faces `(a, b, c)` and `(a, b, d)`, with its cotangent.
#[inline]
pub(crate) fn dihedral(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    let e = (b - a).normalize();
    let u = (c - a) - e * (c - a).dot(e);
    let v = (d - a) - e * (d - a).dot(e);
    let cos = u.dot(v);
    let sin = u.cross(v).length();
    (sin.atan2(cos), cos / sin)
}

/// The six dihedral angles of a tetrahedron at [`EDGES`].
pub(crate) fn dihedral_angles(c: &[DVec3; 4]) -> [f64; 6] {
    EDGES.map(|[a, b]| {
        let [o1, o2] = EDGES[5 - edge_index(a, b)];
        dihedral(c[a], c[b], c[o1], c[o2]).0
    })
}

/// Index in [`EDGES`] of the local edge `(a, b)`, `a < b`.
#[inline]
pub(crate) fn edge_index(a: usize, b: usize) -> usize {
    match (a, b) {
        (0, 1) => 0,
        (0, 2) => 1,
        (0, 3) => 2,
        (1, 2) => 3,
        (1, 3) => 4,
        _ => 5,
    }
}

/// Volume and Eq. 10's geometric weights of one tet.
///
/// For edge `(i, j)` with opposite edge `kl`, `E = x_l − x_k`,
/// `a = x_i − x_k`, `b = x_j − x_k`: the components of `a` and `b`
/// orthogonal to `E` span the dihedral angle `θ_kl`, so
/// `|kl| cot θ_kl = (|E|² a·b − (a·E)(b·E)) / 6V` (their cross product has
/// length `|(a × b)·E| / |E| = 6V / |kl|`): the cotangent without
/// trigonometry or square roots.
pub(crate) fn tet_geometry(c: &[DVec3; 4]) -> (f64, [f64; 6]) {
    let v6 = volume6(c);
    let scale = -1.0 / (6.0 * v6);
    let weights = std::array::from_fn(|e| {
        let [i, j] = EDGES[e];
        let [k, l] = EDGES[5 - e];
        let edge = c[l] - c[k];
        let (a, b) = (c[i] - c[k], c[j] - c[k]);
        // −(1/6) |kl| cot θ_kl
        scale * (edge.length_squared() * a.dot(b) - a.dot(edge) * b.dot(edge))
    });
    (v6 / 6.0, weights)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dihedral_of_regular_tet() {
        let c = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        for a in dihedral_angles(&c) {
            assert!((a.cos() - 1.0 / 3.0).abs() < 1e-12);
        }
    }
}
