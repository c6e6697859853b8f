//! TransCut's cut (Sec. 5): remove the tets lying entirely on the cut
//! side, drop orphaned vertices, and relax the remaining cut-side vertices
//! toward the cross-section.

use glam::DVec3;
use rayon::prelude::*;

use std::time::Instant;

use super::{Cut, CutReport, CutTimes, ms};
use crate::geometry::{dihedral_angles, volume6};
use crate::quality::POOR_DIHEDRAL_DEGREES;
use crate::{Error, Object, TetMesh};

/// The relaxation step of the paper, `x ← x + ρ (x′ − x)`.
pub(crate) const RHO: f64 = 0.1;

impl Object {
    /// [`CutMethod::Relax`](super::CutMethod::Relax): removes every tet whose four vertices lie on the
    /// cut side, removes orphaned vertices, keeps each remaining tet's
    /// original id, then relaxes the remaining cut-side vertices that were
    /// inside the object toward the cross-section for `relax_sweeps` sweeps, `x ← x + ρ (x′ − x)`
    /// with `ρ = 0.1` and `x′` the mean of the one-ring — never across the
    /// cut, and never making a tet's smallest dihedral angle drop below
    /// 0.5° (or below its current value, if already smaller). The matrix
    /// and lights are rebuilt, `φ` carried to the surviving vertices.
    /// A fractured piece that is cut can no longer be recombined.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite or zero plane/stroke,
    /// [`Error::CutRemovesEverything`].
    pub(super) fn cut_relax(&mut self, cut: &Cut, relax_sweeps: usize) -> Result<CutReport, Error> {
        let start = Instant::now();
        let mesh = &self.mesh;
        let n = mesh.vertex_count();
        let side: Vec<f64> = mesh.positions().par_iter().map(|&x| cut.side(x)).collect();
        let keep: Vec<usize> = (0..mesh.tets().len())
            .into_par_iter()
            .filter(|&t| mesh.tets()[t].iter().any(|&v| side[v as usize] <= 0.0))
            .collect();
        if keep.is_empty() {
            return Err(Error::CutRemovesEverything {
                tets: mesh.tets().len(),
            });
        }
        let mut new_index = vec![u32::MAX; n];
        for &t in &keep {
            for &v in &mesh.tets()[t] {
                new_index[v as usize] = 0;
            }
        }
        let mut old_of_new = Vec::new();
        for (v, slot) in new_index.iter_mut().enumerate() {
            if *slot == 0 {
                *slot = old_of_new.len() as u32;
                old_of_new.push(v);
            }
        }
        let removed_tets = mesh.tets().len() - keep.len();
        let removed_vertices = n - old_of_new.len();
        let mut split_ms = ms(start);
        let start = Instant::now();
        let mut new_mesh = mesh.subset(&keep, &new_index, &old_of_new)?;
        let mut mesh_ms = ms(start);
        let start = Instant::now();
        let mut positions = new_mesh.positions().to_vec();
        // Only vertices inside the object before the cut move: the object's
        // own surface keeps its shape.
        let inside: Vec<bool> = old_of_new
            .iter()
            .map(|&v| mesh.boundary_index(v).is_none())
            .collect();
        let (moved, sweeps) = relax(&new_mesh, cut, &inside, &mut positions, relax_sweeps);
        split_ms += ms(start);
        let start = Instant::now();
        if moved > 0 {
            // Every move kept its tets positively oriented: same topology.
            new_mesh.move_vertices(positions);
        }
        let phi = std::array::from_fn(|c| old_of_new.iter().map(|&v| self.phi[c][v]).collect());
        mesh_ms += ms(start);
        self.mesh = new_mesh;
        self.phi = phi;
        self.lineage = None;
        let [assembly_ms, lights_ms] = self.rebuild();
        Ok(CutReport {
            removed_tets,
            removed_vertices,
            moved_vertices: moved,
            sweeps,
            split_tets: 0,
            created_tets: 0,
            created_vertices: 0,
            min_created_dihedral: f64::INFINITY,
            times: CutTimes {
                split_ms,
                mesh_ms,
                assembly_ms,
                lights_ms,
            },
        })
    }
}

/// The paper's relaxation, one vertex at a time in ascending order (so
/// each move is checked against its neighbours' current positions).
/// Returns (vertices moved at least once, sweeps done).
fn relax(
    mesh: &TetMesh,
    cut: &Cut,
    inside: &[bool],
    positions: &mut [DVec3],
    sweeps: usize,
) -> (usize, usize) {
    let movable: Vec<usize> = (0..positions.len())
        .filter(|&v| inside[v] && cut.side(positions[v]) > 0.0)
        .collect();
    let mut moved = vec![false; positions.len()];
    let mut done = 0;
    let min_dihedral = |c: &[DVec3; 4]| {
        dihedral_angles(c)
            .into_iter()
            .fold(f64::INFINITY, f64::min)
            .to_degrees()
    };
    for _ in 0..sweeps {
        let mut any = false;
        for &v in &movable {
            let ring = mesh.one_ring(v);
            let mean =
                ring.iter().map(|&j| positions[j as usize]).sum::<DVec3>() / ring.len() as f64;
            let x = positions[v];
            let candidate = x + (mean - x) * RHO;
            if candidate == x || cut.side(candidate) < 0.0 {
                continue;
            }
            let ok = mesh.vertex_tets(v).iter().all(|&t| {
                let tet = mesh.tets()[t as usize];
                let before = tet.map(|u| positions[u as usize]);
                let after = tet.map(|u| {
                    if u as usize == v {
                        candidate
                    } else {
                        positions[u as usize]
                    }
                });
                volume6(&after) > 0.0
                    && min_dihedral(&after) >= POOR_DIHEDRAL_DEGREES.min(min_dihedral(&before))
            });
            if ok {
                positions[v] = candidate;
                moved[v] = true;
                any = true;
            }
        }
        done += 1;
        if !any {
            break;
        }
    }
    (moved.iter().filter(|&&m| m).count(), done)
}
