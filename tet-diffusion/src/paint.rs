//! Painting (TransCut Sec. 5): a stroke of 3D points changes the material
//! of the tets near it by a Gaussian weight of the distance from each tet
//! centre to the closest stroke point; only the matrix rows of the
//! affected tets' vertices are re-assembled, which gives exactly the
//! values of a full re-assembly.

use glam::DVec3;
use rayon::prelude::*;

use crate::assembly::reassemble_rows;
use crate::error::finite_vec;
use crate::{Error, Medium, Object};

/// A paint stroke.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Points of the stroke, mesh units (on or inside the surface).
    pub points: Vec<DVec3>,
    /// Standard deviation `σ` of the Gaussian, mesh units; tets whose
    /// centre is farther than `3σ` from every point are untouched.
    pub radius: f64,
    /// The medium painted.
    pub medium: Medium,
    /// Weight at distance 0, in `[0, 1]`: a tet becomes
    /// `(1 − w) old + w medium` with `w = strength · exp(−d² / 2σ²)`.
    pub strength: f64,
}

/// What a stroke changed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PaintReport {
    /// Tetrahedra whose medium changed.
    pub tets: usize,
    /// Matrix rows re-assembled.
    pub rows: usize,
}

impl Object {
    /// Paints `stroke` into the material and updates the affected rows.
    /// The next [`solve`](Object::solve) starts from the current `φ`.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for no points, a non-finite point, a radius
    /// that is not positive and finite, a strength outside `[0, 1]`, or a
    /// bad medium.
    pub fn paint(&mut self, stroke: &Stroke) -> Result<PaintReport, Error> {
        self.paint_recorded(stroke).map(|(report, _)| report)
    }

    /// Paints `medium`, all of it, into every tetrahedron whose centre `c`
    /// is on the side `(c − point) · normal > 0` of a plane (the side a
    /// [`Cut::Plane`](crate::Cut::Plane) of the same plane removes), and
    /// updates the affected rows as [`paint`](Self::paint) does.
    ///
    /// `point` is a point of the plane and `normal` its normal toward the
    /// painted side, both in mesh units (the normal need not be a unit
    /// vector). The report counts the tetrahedra painted (including any
    /// that already had `medium`) and the rows re-assembled.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite point or normal, a zero
    /// normal, or a bad medium.
    pub fn paint_half_space(
        &mut self,
        point: DVec3,
        normal: DVec3,
        medium: Medium,
    ) -> Result<PaintReport, Error> {
        finite_vec("the painted half-space's point", point)?;
        finite_vec("the painted half-space's normal", normal)?;
        if normal.length_squared() == 0.0 {
            return Err(Error::BadArgument {
                what: "the length of the painted half-space's normal".into(),
                value: 0.0,
                need: "it must be non-zero",
            });
        }
        medium.check("the painted medium")?;
        let mesh = &self.mesh;
        let tets: Vec<u32> = (0..mesh.tets().len())
            .filter(|&t| (mesh.tet_center(t) - point).dot(normal) > 0.0)
            .map(|t| t as u32)
            .collect();
        for &t in &tets {
            self.media[mesh.original_ids()[t as usize] as usize] = medium;
        }
        let rows = self.update_rows_of(&tets);
        Ok(PaintReport {
            tets: tets.len(),
            rows,
        })
    }

    /// [`paint`](Self::paint), also returning each changed tet (mesh index)
    /// with the medium it had, which [`restore_media`](Self::restore_media)
    /// puts back.
    pub(crate) fn paint_recorded(
        &mut self,
        stroke: &Stroke,
    ) -> Result<(PaintReport, Vec<(u32, Medium)>), Error> {
        stroke.check()?;
        let grid = self
            .centres
            .get_or_init(|| std::sync::Arc::new(CentreGrid::new(&self.mesh)))
            .clone();
        let mesh = &self.mesh;
        let reach = 3.0 * stroke.radius;
        let reach2 = reach.powi(2);
        // Candidates from the grid (every tet whose centre is within the
        // reach of a point, ascending), then exactly the test of every
        // tet: the same tets and weights as testing them all.
        let candidates = grid.near(&stroke.points, reach);
        let weights: Vec<(usize, f64)> = candidates
            .into_par_iter()
            .with_min_len(1024)
            .map(|t| t as usize)
            .filter_map(|t| {
                let c = mesh.tet_center(t);
                let d2 = stroke
                    .points
                    .iter()
                    .map(|p| p.distance_squared(c))
                    .fold(f64::INFINITY, f64::min);
                (d2 <= reach2).then(|| {
                    (
                        t,
                        stroke.strength * (-d2 / (2.0 * stroke.radius * stroke.radius)).exp(),
                    )
                })
            })
            .collect();
        let mut previous = Vec::with_capacity(weights.len());
        for &(t, w) in &weights {
            let id = mesh.original_ids()[t] as usize;
            previous.push((t as u32, self.media[id]));
            self.media[id] = self.media[id].lerp(&stroke.medium, w);
        }
        let tets: Vec<u32> = weights.iter().map(|&(t, _)| t as u32).collect();
        let rows = self.update_rows_of(&tets);
        Ok((
            PaintReport {
                tets: weights.len(),
                rows,
            },
            previous,
        ))
    }

    /// The current medium of each tet (mesh index) `list` names, in its
    /// order: what puts them back after a [`restore_media`](Self::restore_media)
    /// of `list` (undo re-deriving a replaced hierarchy visits the media of
    /// an earlier state and returns).
    pub(crate) fn current_media(&self, list: &[(u32, Medium)]) -> Vec<(u32, Medium)> {
        let ids = self.mesh.original_ids();
        list.iter()
            .filter_map(|&(t, _)| {
                let id = *ids.get(t as usize)? as usize;
                Some((t, *self.media.get(id)?))
            })
            .collect()
    }

    /// Puts back the media [`paint_recorded`](Self::paint_recorded)
    /// returned (mesh tet index, medium), in reverse order so that a tet
    /// listed twice gets its first value, and re-assembles their rows.
    pub(crate) fn restore_media(&mut self, previous: &[(u32, Medium)]) -> usize {
        for &(t, m) in previous.iter().rev() {
            let id = self.mesh.original_ids()[t as usize] as usize;
            self.media[id] = m;
        }
        let tets: Vec<u32> = previous.iter().map(|&(t, _)| t).collect();
        self.update_rows_of(&tets)
    }

    /// Recomputes the coefficients of mesh tets `tets` from their media
    /// and re-assembles the rows of their vertices; returns the rows.
    fn update_rows_of(&mut self, tets: &[u32]) -> usize {
        let mut rows: Vec<u32> = Vec::new();
        for &t in tets {
            let t = t as usize;
            let (kappa, mu) = self.tet_coefficients(self.mesh.original_ids()[t]);
            self.coefficients.kappa[t] = kappa;
            self.coefficients.mu[t] = mu;
            rows.extend_from_slice(&self.mesh.tets()[t]);
        }
        rows.sort_unstable();
        rows.dedup();
        self.values_changed |= !rows.is_empty();
        self.block_current &= rows.is_empty();
        let a = self.boundary_factor();
        reassemble_rows(
            &self.mesh,
            &self.geometry,
            &self.coefficients,
            a,
            &rows,
            &mut self.matrices,
        );
        rows.len()
    }
}

impl Stroke {
    /// Checks the stroke's values.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for no points, a non-finite point, a radius
    /// that is not positive and finite, a strength outside `[0, 1]`, or a
    /// bad medium.
    pub fn check(&self) -> Result<(), Error> {
        let stroke = self;
        if stroke.points.is_empty() {
            return Err(Error::BadArgument {
                what: "the number of paint stroke points".into(),
                value: 0.0,
                need: "a stroke needs at least one point",
            });
        }
        for (k, p) in stroke.points.iter().enumerate() {
            finite_vec(&format!("paint stroke point {k}"), *p)?;
        }
        if !(stroke.radius.is_finite() && stroke.radius > 0.0) {
            return Err(Error::BadArgument {
                what: "the paint stroke's radius".into(),
                value: stroke.radius,
                need: "it must be positive and finite",
            });
        }
        if !(0.0..=1.0).contains(&stroke.strength) {
            return Err(Error::BadArgument {
                what: "the paint stroke's strength".into(),
                value: stroke.strength,
                need: "it must be in [0, 1]",
            });
        }
        stroke.medium.check("the painted medium")?;
        Ok(())
    }
}

/// Tet centres binned in a uniform grid of about [`PER_CELL`] tets a cell
/// over the centres' bounding box (a counting sort, once per mesh): the
/// brush looks at the cells its reach overlaps, not at every tet.
#[derive(Debug)]
pub(crate) struct CentreGrid {
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    /// Cell `k`'s tets are `tets[start[k]..start[k + 1]]`, ascending.
    start: Vec<u32>,
    tets: Vec<u32>,
}

/// Tets per grid cell, on average.
const PER_CELL: f64 = 8.0;

impl CentreGrid {
    pub(crate) fn new(mesh: &crate::TetMesh) -> Self {
        let centres: Vec<DVec3> = (0..mesh.tets().len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| mesh.tet_center(t))
            .collect();
        let (lo, hi) = centres
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &c| {
                (a.min(c), b.max(c))
            });
        let n = centres.len().max(1) as f64;
        let extent = if centres.is_empty() {
            DVec3::ONE
        } else {
            (hi - lo).max(DVec3::splat(1e-12))
        };
        let lo = if centres.is_empty() { DVec3::ZERO } else { lo };
        // Cubic cells, about PER_CELL centres each over the box (at most
        // 2²⁴ cells, so a flat mesh does not make a huge grid).
        let cell = (extent.x * extent.y * extent.z * PER_CELL / n)
            .cbrt()
            .max(extent.max_element() / 256.0);
        let dims = [extent.x, extent.y, extent.z].map(|e| ((e / cell) as usize + 1).min(256));
        let index = |c: DVec3| -> usize {
            let k = ((c - lo) / cell).to_array();
            let i: [usize; 3] = std::array::from_fn(|a| (k[a].max(0.0) as usize).min(dims[a] - 1));
            (i[2] * dims[1] + i[1]) * dims[0] + i[0]
        };
        let cells = dims[0] * dims[1] * dims[2];
        let mut start = vec![0u32; cells + 1];
        let keys: Vec<usize> = centres.iter().map(|&c| index(c)).collect();
        for &k in &keys {
            start[k + 1] += 1;
        }
        for k in 0..cells {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut tets = vec![0u32; keys.len()];
        for (t, &k) in keys.iter().enumerate() {
            tets[fill[k] as usize] = t as u32;
            fill[k] += 1;
        }
        Self {
            lo,
            cell,
            dims,
            start,
            tets,
        }
    }

    /// The tets (ascending, each once) of the cells within `reach` of
    /// any of `points`: every tet whose centre is within `reach` of one.
    pub(crate) fn near(&self, points: &[DVec3], reach: f64) -> Vec<u32> {
        let cells = self.dims.iter().product::<usize>();
        let mut seen = vec![false; cells];
        let mut out = Vec::new();
        // A margin far above the rounding of the cell indices.
        let reach = reach + 1e-6 * self.cell;
        for &p in points {
            let range = |a: usize, v: f64| {
                let lo = ((v - reach - self.lo[a]) / self.cell).floor();
                let hi = ((v + reach - self.lo[a]) / self.cell).floor();
                let max = self.dims[a] as f64 - 1.0;
                (lo.clamp(0.0, max) as usize, hi.clamp(0.0, max) as usize)
            };
            let (x, y, z) = (range(0, p.x), range(1, p.y), range(2, p.z));
            for k in z.0..=z.1 {
                for j in y.0..=y.1 {
                    for i in x.0..=x.1 {
                        let c = (k * self.dims[1] + j) * self.dims[0] + i;
                        if !std::mem::replace(&mut seen[c], true) {
                            let (a, b) = (self.start[c] as usize, self.start[c + 1] as usize);
                            out.extend_from_slice(&self.tets[a..b]);
                        }
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }
}
