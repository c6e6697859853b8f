//! Dihedral angles and cotangent weights of tetrahedra: what decides
//! whether a mesh is usable for finite elements (TransCut Sec. 6: the
//! cotangent weights of slivers blow up).

use glam::DVec3;

/// The six interior dihedral angles of the tetrahedron `p`, in radians, at
/// the edges (0,1), (0,2), (0,3), (1,2), (1,3), (2,3). A degenerate
/// tetrahedron gives NaN angles.
pub fn dihedral_angles(p: [DVec3; 4]) -> [f64; 6] {
    let mut out = [0.0; 6];
    for (k, (i, j)) in EDGES.iter().enumerate() {
        let (a, b) = opposite(*i, *j);
        out[k] = dihedral(p[*i], p[*j], p[a], p[b]);
    }
    out
}

/// The edges of a tetrahedron in the order [`dihedral_angles`] uses.
pub const EDGES: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// The two vertices not on edge `(i, j)`.
fn opposite(i: usize, j: usize) -> (usize, usize) {
    let mut rest = (0..4).filter(|&k| k != i && k != j);
    let a = rest.next().unwrap_or(0);
    let b = rest.next().unwrap_or(0);
    (a, b)
}

/// Interior angle at edge `(p, q)` between the faces through `a` and `b`.
fn dihedral(p: DVec3, q: DVec3, a: DVec3, b: DVec3) -> f64 {
    let e = (q - p).normalize();
    let u = (a - p) - e * e.dot(a - p);
    let v = (b - p) - e * e.dot(b - p);
    (u.dot(v) / (u.length() * v.length()))
        .clamp(-1.0, 1.0)
        .acos()
}

/// Smallest sine of the six dihedral angles: small for both slivers (angles
/// near 0) and caps (angles near 180°). Used to choose between valid
/// triangulations of a cut cell.
pub(crate) fn min_sine(p: [DVec3; 4]) -> f64 {
    let s = dihedral_angles(p)
        .iter()
        .map(|a| a.sin())
        .fold(f64::INFINITY, f64::min);
    if s.is_nan() { 0.0 } else { s }
}

/// Signed volume: positive when `p[1] - p[0]`, `p[2] - p[0]`, `p[3] - p[0]`
/// form a right-handed frame.
pub fn signed_volume(p: [DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0
}

/// Quality summary of a tetrahedral mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quality {
    /// Smallest dihedral angle, degrees.
    pub min_dihedral_deg: f64,
    /// Largest dihedral angle, degrees.
    pub max_dihedral_deg: f64,
    /// Smallest cotangent of a dihedral angle: the per-element cotangent
    /// weight of the P1 Laplacian is `|e_kl| cot θ_kl / 6` for the edge
    /// opposite `kl`, so this (dimensionless) range bounds the weights.
    pub min_cot: f64,
    /// Largest cotangent of a dihedral angle.
    pub max_cot: f64,
    /// Smallest tetrahedron volume (positive for a valid mesh).
    pub min_volume: f64,
}

/// Dihedral-angle and cotangent ranges over all tetrahedra (in parallel,
/// with an order-independent reduction: the result does not depend on the
/// number of threads).
pub fn quality(positions: &[DVec3], tets: &[[u32; 4]]) -> Quality {
    use rayon::prelude::*;
    let init = Quality {
        min_dihedral_deg: f64::INFINITY,
        max_dihedral_deg: f64::NEG_INFINITY,
        min_cot: f64::INFINITY,
        max_cot: f64::NEG_INFINITY,
        min_volume: f64::INFINITY,
    };
    let merge = |a: Quality, b: Quality| Quality {
        min_dihedral_deg: a.min_dihedral_deg.min(b.min_dihedral_deg),
        max_dihedral_deg: a.max_dihedral_deg.max(b.max_dihedral_deg),
        min_cot: a.min_cot.min(b.min_cot),
        max_cot: a.max_cot.max(b.max_cot),
        min_volume: a.min_volume.min(b.min_volume),
    };
    tets.par_iter()
        .map(|t| {
            let p = t.map(|v| positions.get(v as usize).copied().unwrap_or(DVec3::NAN));
            let mut q = init;
            for a in dihedral_angles(p) {
                let d = a.to_degrees();
                let d = if d.is_nan() { 0.0 } else { d };
                q.min_dihedral_deg = q.min_dihedral_deg.min(d);
                q.max_dihedral_deg = q.max_dihedral_deg.max(d);
                let c = 1.0 / a.tan();
                let c = if c.is_finite() { c } else { f64::INFINITY };
                q.min_cot = q.min_cot.min(c);
                q.max_cot = q.max_cot.max(c);
            }
            let v = signed_volume(p);
            q.min_volume = if v.is_nan() { f64::NEG_INFINITY } else { v };
            q
        })
        .reduce(|| init, merge)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_tetrahedron_has_all_angles_arccos_one_third() {
        let p = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ];
        for a in dihedral_angles(p) {
            assert!((a - (1.0f64 / 3.0).acos()).abs() < 1e-12);
        }
    }

    #[test]
    fn corner_tetrahedron_has_right_angles_at_the_axes() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let a = dihedral_angles(p);
        // Edges (0,1), (0,2), (0,3) lie on the axes: 90°.
        for angle in &a[..3] {
            assert!((angle - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        }
        // Edge (1,2): between the face z = 0 and the slanted face.
        assert!((a[3] - (1.0f64 / 3f64.sqrt()).acos()).abs() < 1e-12);
        assert!((signed_volume(p) - 1.0 / 6.0).abs() < 1e-15);
    }
}
