//! The quality report of a tet mesh: its dihedral angles, the poorly
//! shaped tets whose cotangent weights blow up, and the ranges of the
//! edge weights and lengths. Apart from [`crate::mesh`], since it needs
//! the assembly's edge weights and the mesh must not.

use rayon::prelude::*;

use crate::assembly::Geometry;
use crate::mesh::TetMesh;

/// Tets whose minimal dihedral angle is below this many degrees are
/// "poorly shaped" (TransCut Sec. 6, Limitations).
pub const POOR_DIHEDRAL_DEGREES: f64 = 0.5;

/// Shape statistics of a mesh (angles in degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quality {
    /// Smallest dihedral angle of any tetrahedron.
    pub min_dihedral: f64,
    /// Largest dihedral angle of any tetrahedron.
    pub max_dihedral: f64,
    /// Tetrahedra whose smallest dihedral angle is below
    /// [`POOR_DIHEDRAL_DEGREES`] (0.5°): their cotangent weights are huge.
    pub poor_tets: usize,
    /// Smallest and largest geometric edge weight
    /// `Σ_t −(1/6) |kl| cot θ_kl` (Eq. 10 without `κ`), in mesh units.
    pub edge_weight_range: [f64; 2],
    /// Shortest and longest edge, in mesh units.
    pub edge_length_range: [f64; 2],
    /// Mean edge length, in mesh units.
    pub mean_edge_length: f64,
}

impl TetMesh {
    /// The quality report: dihedral angles, poorly shaped tets, the range
    /// of the cotangent edge weights and of the edge lengths.
    pub fn quality(&self) -> Quality {
        let (min, max, poor) = (0..self.tets().len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| {
                let a = self.dihedral_angles(t);
                let lo = a.iter().copied().fold(f64::INFINITY, f64::min);
                let hi = a.iter().copied().fold(0.0, f64::max);
                (lo, hi, usize::from(lo.to_degrees() < POOR_DIHEDRAL_DEGREES))
            })
            .reduce(
                || (f64::INFINITY, 0.0, 0),
                |a, b| (a.0.min(b.0), a.1.max(b.1), a.2 + b.2),
            );
        let weights = Geometry::new(self);
        let mut w = [f64::INFINITY, f64::NEG_INFINITY];
        let mut len = [f64::INFINITY, 0.0f64];
        let mut total = 0.0;
        for i in 0..self.vertex_count() {
            for (k, &j) in self.one_ring(i).iter().enumerate() {
                if (j as usize) > i {
                    let g = weights.edge_weight(self, i, k);
                    w = [w[0].min(g), w[1].max(g)];
                    let l = self.positions()[i].distance(self.positions()[j as usize]);
                    len = [len[0].min(l), len[1].max(l)];
                    total += l;
                }
            }
        }
        Quality {
            min_dihedral: min.to_degrees(),
            max_dihedral: max.to_degrees(),
            poor_tets: poor,
            edge_weight_range: w,
            edge_length_range: len,
            mean_edge_length: total / self.edge_count().max(1) as f64,
        }
    }
}
