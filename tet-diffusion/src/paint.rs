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
        let mesh = &self.mesh;
        let reach2 = (3.0 * stroke.radius).powi(2);
        let weights: Vec<(usize, f64)> = (0..mesh.tets().len())
            .into_par_iter()
            .with_min_len(1024)
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
