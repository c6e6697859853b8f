//! The generalized winding number of a triangle soup (Jacobson, Kavan &
//! Sorkine-Hornung 2013), evaluated exactly or with the hierarchical
//! approximation of Barill, Dickson, Schmidt, Levin & Jacobson 2018
//! ("Fast Winding Numbers for Soups and Clouds").
//!
//! `w(q) = (1 / 4π) Σ_t Ω_t(q)`, where `Ω_t` is the signed solid angle of
//! triangle `t` seen from `q` (Van Oosterom & Strackee's formula). For a
//! closed, outward-oriented surface `w` is 1 inside and 0 outside; for a
//! surface with holes, several overlapping parts or flipped patches it is
//! a smooth harmonic function that still says "inside" where `w > 1/2`.
//!
//! The fast evaluation walks a bounding volume hierarchy: a node whose expansion
//! centre `p̃` is farther from `q` than `β` times its radius contributes
//! through the Taylor series of the dipole kernel about `p̃`, truncated after
//! the second term (the area-weighted normal `Σ a_t n_t` and the first
//! moment `Σ a_t (c_t - p̃) ⊗ n_t` of Barill et al.'s expansion for
//! triangle soups); nearer nodes are opened, and leaves are summed
//! exactly. `β` trades accuracy for speed; [`DEFAULT_BETA`] was chosen by
//! measurement against the exact sum (see its docs).

use std::f64::consts::PI;

use glam::{DMat3, DVec3};

use super::bvh::Bvh;
use super::error::Error;

/// The accuracy parameter used unless the caller picks another one.
///
/// Chosen by measurement against the exact sum (the `stuffing` example
/// prints the table for every data mesh: 2,000 random points in the
/// bounding box, β = 1.5, 2, 3). On the closed 43k-triangle bunny, β = 2
/// gives a largest absolute error of 0.03 with no point on the wrong side
/// of 1/2, about 200× faster than the exact sum; β = 1.5 doubles the error
/// for 1.4× more speed, β = 3 halves it for half the speed. Barill et al.
/// 2018 use the same value. Cut points do not depend on this
/// accuracy where the level set runs along the triangles: they are placed
/// on the triangle the edge crosses.
pub const DEFAULT_BETA: f64 = 2.0;

/// Far-field data of one tree node (Barill et al. 2018).
#[derive(Debug, Clone, Copy)]
struct Expansion {
    /// Area-weighted centroid of the node's triangles: the expansion centre.
    center: DVec3,
    /// `Σ a_t n_t`: the sum of the triangles' area vectors.
    normal: DVec3,
    /// `Σ (a_t n_t) ⊗ (c_t - center)`, the second-order moment.
    moment: DMat3,
    /// Distance from `center` to the farthest vertex of the node.
    radius: f64,
    /// Total area (weights the merge of two children).
    area: f64,
}

/// Generalized winding number of a triangle soup, with a prebuilt tree for
/// fast evaluation.
///
/// # Example
/// ```
/// use tet_stuffing::winding::WindingNumber;
/// use glam::DVec3;
/// // A tetrahedron with outward (counter-clockwise) faces.
/// let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
/// let t = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
/// let w = WindingNumber::new(&p, &t, 2.0).unwrap();
/// assert!((w.exact(DVec3::splat(0.1)) - 1.0).abs() < 1e-12);
/// assert!(w.fast(DVec3::splat(5.0)).abs() < 1e-3);
/// ```
#[derive(Debug, Clone)]
pub struct WindingNumber {
    positions: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    bvh: Bvh,
    expansions: Vec<Expansion>,
    beta: f64,
}

impl WindingNumber {
    /// Builds the tree over `triangles` (0-based indices into `positions`).
    ///
    /// # Errors
    /// [`Error::NoTriangles`], [`Error::NonFinitePosition`],
    /// [`Error::IndexOutOfRange`], or [`Error::InvalidBeta`] when `beta` is
    /// not finite or below 1 (below 1 the series is used where it does not
    /// converge).
    pub fn new(positions: &[DVec3], triangles: &[[u32; 3]], beta: f64) -> Result<Self, Error> {
        if !(beta.is_finite() && beta >= 1.0) {
            return Err(Error::InvalidBeta { beta });
        }
        super::validate_soup(positions.len(), triangles)?;
        for &t in triangles {
            for &v in &t {
                let p = positions[v as usize];
                if !p.is_finite() {
                    return Err(Error::NonFinitePosition { vertex: v as usize });
                }
            }
        }
        let bvh = Bvh::build(positions, triangles);
        let expansions = expansions(&bvh, positions, triangles);
        Ok(WindingNumber {
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            bvh,
            expansions,
            beta,
        })
    }

    /// The accuracy parameter β.
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// The same tree with another β (see [`WindingNumber::new`] for the
    /// allowed range).
    ///
    /// # Errors
    /// [`Error::InvalidBeta`].
    pub fn with_beta(mut self, beta: f64) -> Result<Self, Error> {
        if !(beta.is_finite() && beta >= 1.0) {
            return Err(Error::InvalidBeta { beta });
        }
        self.beta = beta;
        Ok(self)
    }

    /// The exact sum over all triangles: O(n) per query.
    pub fn exact(&self, q: DVec3) -> f64 {
        let mut sum = 0.0;
        for t in &self.triangles {
            sum += self.solid_angle(t, q);
        }
        sum / (4.0 * PI)
    }

    /// The hierarchical approximation (Barill et al. 2018): exact for the
    /// triangles near `q`, the second-order far-field series for clusters
    /// farther than `β` times their radius. O(log n) per query for points
    /// away from the surface.
    pub fn fast(&self, q: DVec3) -> f64 {
        self.fast_with(q, self.beta)
    }

    /// [`Self::fast`] with another accuracy `beta` (at least 1).
    pub(crate) fn fast_with(&self, q: DVec3, beta: f64) -> f64 {
        let beta2 = beta * beta;
        let mut sum = 0.0;
        // The tree is a median split of at most 2^32 triangles: its depth is
        // below 40, and depth-first traversal keeps at most depth + 1 nodes.
        let mut stack = [0u32; 64];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let n = stack[len] as usize;
            let e = &self.expansions[n];
            let r = e.center - q;
            let d2 = r.length_squared();
            if d2 > beta2 * e.radius * e.radius {
                sum += far_field(e, r, d2);
                continue;
            }
            let node = &self.bvh.nodes[n];
            if node.is_leaf() {
                let s = node.start as usize;
                for &t in &self.bvh.order[s..s + node.count as usize] {
                    sum += self.solid_angle(&self.triangles[t as usize], q);
                }
            } else {
                stack[len] = node.children[0];
                stack[len + 1] = node.children[1];
                len += 2;
            }
        }
        sum / (4.0 * PI)
    }

    /// Signed solid angle of one triangle seen from `q` (Van Oosterom &
    /// Strackee 1983), positive when `q` is behind the counter-clockwise
    /// normal.
    fn solid_angle(&self, t: &[u32; 3], q: DVec3) -> f64 {
        let a = self.positions[t[0] as usize] - q;
        let b = self.positions[t[1] as usize] - q;
        let c = self.positions[t[2] as usize] - q;
        solid_angle(a, b, c)
    }

    /// The positions the tree was built on.
    pub(crate) fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// The triangles the tree was built on.
    pub(crate) fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The tree over [`Self::triangles`].
    pub(crate) fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Crossings of the segment `a -> b` with the triangles, sorted by the
    /// segment parameter (used to place cut points exactly on the surface).
    pub(crate) fn segment_hits(&self, a: DVec3, b: DVec3, out: &mut Vec<(f64, i8)>) {
        self.bvh
            .segment_hits(&self.positions, &self.triangles, a, b, out);
    }
}

/// Signed solid angle of the triangle `(a, b, c)` (positions relative to
/// the viewer).
pub(crate) fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let la = a.length();
    let lb = b.length();
    let lc = c.length();
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * num.atan2(den)
}

/// Solid angle of a far cluster from its expansion: the dipole term plus
/// the first-moment term of the Taylor series of `r / |r|³` about the
/// expansion centre; `r = center - q`.
fn far_field(e: &Expansion, r: DVec3, d2: f64) -> f64 {
    let d = d2.sqrt();
    let inv3 = 1.0 / (d2 * d);
    let inv5 = inv3 / d2;
    let m = &e.moment;
    let trace = m.x_axis.x + m.y_axis.y + m.z_axis.z;
    // M_ij = A_i δ_j; the kernel's Jacobian is symmetric, so the
    // contraction is tr(M)/|r|³ - 3 rᵀ M r / |r|⁵.
    e.normal.dot(r) * inv3 + trace * inv3 - 3.0 * r.dot(*m * r) * inv5
}

/// Bottom-up expansions: children have larger indices than their parent.
fn expansions(bvh: &Bvh, positions: &[DVec3], triangles: &[[u32; 3]]) -> Vec<Expansion> {
    let mut out = vec![
        Expansion {
            center: DVec3::ZERO,
            normal: DVec3::ZERO,
            moment: DMat3::ZERO,
            radius: 0.0,
            area: 0.0,
        };
        bvh.nodes.len()
    ];
    for n in (0..bvh.nodes.len()).rev() {
        let node = &bvh.nodes[n];
        out[n] = if node.is_leaf() {
            let s = node.start as usize;
            let tris = &bvh.order[s..s + node.count as usize];
            leaf_expansion(tris, positions, triangles)
        } else {
            let [l, r] = node.children;
            merge(&out[l as usize], &out[r as usize])
        };
    }
    out
}

fn leaf_expansion(tris: &[u32], positions: &[DVec3], triangles: &[[u32; 3]]) -> Expansion {
    let mut area = 0.0;
    let mut weighted = DVec3::ZERO;
    let mut plain = DVec3::ZERO;
    let mut normal = DVec3::ZERO;
    for &t in tris {
        let [a, b, c] = corners(positions, triangles[t as usize]);
        let av = 0.5 * (b - a).cross(c - a);
        let ar = av.length();
        let centroid = (a + b + c) / 3.0;
        area += ar;
        weighted += ar * centroid;
        plain += centroid;
        normal += av;
    }
    let center = if area > 0.0 {
        weighted / area
    } else {
        plain / tris.len() as f64
    };
    let mut moment = DMat3::ZERO;
    let mut radius: f64 = 0.0;
    for &t in tris {
        let [a, b, c] = corners(positions, triangles[t as usize]);
        let av = 0.5 * (b - a).cross(c - a);
        let offset = (a + b + c) / 3.0 - center;
        moment += outer(av, offset);
        for p in [a, b, c] {
            radius = radius.max((p - center).length());
        }
    }
    Expansion {
        center,
        normal,
        moment,
        radius,
        area,
    }
}

fn merge(l: &Expansion, r: &Expansion) -> Expansion {
    let area = l.area + r.area;
    let center = if area > 0.0 {
        (l.area * l.center + r.area * r.center) / area
    } else {
        0.5 * (l.center + r.center)
    };
    // Shift each child's moment to the new centre:
    // Σ A ⊗ (c - p) = Σ A ⊗ (c - p_child) + (Σ A) ⊗ (p_child - p).
    let moment = l.moment
        + outer(l.normal, l.center - center)
        + r.moment
        + outer(r.normal, r.center - center);
    let radius =
        ((l.center - center).length() + l.radius).max((r.center - center).length() + r.radius);
    Expansion {
        center,
        normal: l.normal + r.normal,
        moment,
        radius,
        area,
    }
}

/// `a ⊗ b`: entry (i, j) is `a_i b_j`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

fn corners(positions: &[DVec3], t: [u32; 3]) -> [DVec3; 3] {
    [
        positions[t[0] as usize],
        positions[t[1] as usize],
        positions[t[2] as usize],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stuffing tests' UV sphere, centred at the origin.
    fn sphere(n: u32, radius: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        crate::tests::sphere(n, radius, DVec3::ZERO)
    }

    #[test]
    fn closed_sphere_is_one_inside_zero_outside_exactly() {
        let (p, t) = sphere(12, 1.0);
        let w = WindingNumber::new(&p, &t, 2.0).unwrap();
        assert!((w.exact(DVec3::new(0.1, -0.2, 0.3)) - 1.0).abs() < 1e-10);
        assert!(w.exact(DVec3::new(1.5, 0.2, 0.0)).abs() < 1e-10);
    }

    #[test]
    fn fast_agrees_with_exact_and_converges_as_beta_grows() {
        let (p, t) = sphere(40, 1.0);
        let queries: Vec<DVec3> = (0..200)
            .map(|i| {
                let f = f64::from(i);
                DVec3::new((f * 0.37).sin(), (f * 0.61).cos(), (f * 0.13).sin()) * 1.6
            })
            .collect();
        let mut last = f64::INFINITY;
        for beta in [1.5, 2.0, 4.0, 8.0] {
            let w = WindingNumber::new(&p, &t, beta).unwrap();
            let err = queries
                .iter()
                .map(|&q| (w.fast(q) - w.exact(q)).abs())
                .fold(0.0, f64::max);
            assert!(err < 0.02, "beta {beta}: error {err}");
            assert!(err <= last * 1.5 + 1e-12, "beta {beta}: {err} after {last}");
            last = err;
        }
    }

    #[test]
    fn open_hemisphere_has_winding_near_one_half_on_the_cut() {
        let (p, t) = sphere(20, 1.0);
        // Keep the upper half only: the disc z = 0 is an open hole.
        let upper: Vec<[u32; 3]> = t
            .into_iter()
            .filter(|tri| tri.iter().all(|&v| p[v as usize].z >= -1e-12))
            .collect();
        let w = WindingNumber::new(&p, &upper, 2.0).unwrap();
        let centre = w.exact(DVec3::new(0.0, 0.0, 1e-3));
        assert!((centre - 0.5).abs() < 0.01, "{centre}");
        assert!(w.exact(DVec3::new(0.0, 0.0, 0.5)) > 0.5);
        assert!(w.exact(DVec3::new(0.0, 0.0, -0.5)) < 0.5);
    }

    #[test]
    fn bad_input_is_an_error() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)];
        assert!(matches!(
            WindingNumber::new(&p, &[[0, 1, 2]], 2.0),
            Err(Error::NonFinitePosition { vertex: 2 })
        ));
        assert!(matches!(
            WindingNumber::new(&p, &[[0, 1, 3]], 2.0),
            Err(Error::IndexOutOfRange { .. })
        ));
        assert!(matches!(
            WindingNumber::new(&p, &[[0, 1, 1]], 0.5),
            Err(Error::InvalidBeta { .. })
        ));
    }
}
