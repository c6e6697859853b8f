//! Cutting (TransCut Sec. 5) by a plane or by a stroke swept along the
//! view direction, two ways ([`CutMethod`]):
//!
//! - **exact** (the default, beyond the paper): the tets the cut surface
//!   crosses are split along it, so that the cross-section lies on the
//!   surface (for a plane, flat to rounding), with a bound on the angles
//!   of the tets it creates ([`split`]);
//! - **relax** (the paper's): the tets entirely on the cut side are
//!   removed and the remaining cut-side vertices relaxed toward the
//!   cross-section, which leaves the face as jagged as the
//!   mesh where the relaxation cannot reach.
//!
//! Either way the system is rebuilt and `φ` carried over as the warm
//! start (interpolated along the edge for a vertex the cut creates).

use std::time::Instant;

use glam::DVec3;

use crate::error::finite_vec;
use crate::{Error, Object, TetMesh};

mod relax;
pub(crate) mod split;

pub use split::{ANGLE_BOUND_DEGREES, ANGLE_BOUND_FRACTION, created_angle_bound};

/// What to cut away.
#[derive(Debug, Clone, PartialEq)]
pub enum Cut {
    /// Removes the half-space `(x − point) · normal > 0`.
    Plane {
        /// A point of the plane, mesh units.
        point: DVec3,
        /// The normal, pointing into the removed side.
        normal: DVec3,
    },
    /// A polyline drawn on the screen, swept along the viewing direction
    /// `view` (from the eye into the scene): removes what lies to its left
    /// as the viewer sees it. Each point is classified by the segment
    /// closest to it in the screen plane.
    Stroke {
        /// At least two points, mesh units.
        points: Vec<DVec3>,
        /// The viewing direction.
        view: DVec3,
    },
}

impl Cut {
    /// Checks the cut's values.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite or zero plane/stroke, or a
    /// stroke of fewer than two points.
    pub fn check(&self) -> Result<(), Error> {
        let nonzero = |what: &str, v: DVec3| -> Result<(), Error> {
            finite_vec(what, v)?;
            if v.length_squared() == 0.0 {
                return Err(Error::BadArgument {
                    what: format!("the length of {what}"),
                    value: 0.0,
                    need: "it must be non-zero",
                });
            }
            Ok(())
        };
        match self {
            Self::Plane { point, normal } => {
                finite_vec("the cut plane's point", *point)?;
                nonzero("the cut plane's normal", *normal)
            }
            Self::Stroke { points, view } => {
                nonzero("the stroke's view direction", *view)?;
                if points.len() < 2 {
                    return Err(Error::BadArgument {
                        what: "the number of stroke points".into(),
                        value: points.len() as f64,
                        need: "a cutting stroke needs at least two points",
                    });
                }
                for (k, p) in points.iter().enumerate() {
                    finite_vec(&format!("stroke point {k}"), *p)?;
                }
                Ok(())
            }
        }
    }

    /// Signed distance-like side of `x`: positive on the removed side.
    pub fn side(&self, x: DVec3) -> f64 {
        match self {
            Self::Plane { point, normal } => (x - *point).dot(normal.normalize()),
            Self::Stroke { points, view } => {
                let d = view.normalize();
                let flat = |p: DVec3| p - d * p.dot(d);
                let xf = flat(x);
                let mut best = (f64::INFINITY, 0.0);
                for w in points.windows(2) {
                    let (a, b) = (flat(w[0]), flat(w[1]));
                    let s = b - a;
                    let len2 = s.length_squared();
                    if len2 == 0.0 {
                        continue;
                    }
                    let t = ((xf - a).dot(s) / len2).clamp(0.0, 1.0);
                    let dist = xf.distance(a + s * t);
                    if dist < best.0 {
                        let left = s.cross(d).normalize();
                        best = (dist, (xf - a).dot(left));
                    }
                }
                best.1
            }
        }
    }
}

/// How [`Object::cut`] cuts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CutMethod {
    /// Split the tets the cut surface crosses along it (snapping vertices
    /// within 0.2 of an edge's length of it onto it first): the cross-section lies on
    /// the surface, and every tet the cut makes from an input tet `P` (a
    /// piece of it, or `P` with snapped corners) has a smallest dihedral
    /// angle of at least [`created_angle_bound`]`(θ(P)) =
    /// min(`[`ANGLE_BOUND_DEGREES`]` = 0.5°, `[`ANGLE_BOUND_FRACTION`]` = 0.25 ·
    /// θ(P))`, `θ(P)` the smallest dihedral angle of `P` before the cut.
    /// Guaranteed: the cut snaps further vertices to keep it and, when no
    /// snap can, fails with [`Error::CutAngleBound`].
    #[default]
    Exact,
    /// TransCut's cut (Sec. 5): remove the tets entirely on the cut side,
    /// then relax the remaining cut-side vertices toward the cross-section
    /// for `sweeps` sweeps (`x ← x + ρ (x′ − x)`, `ρ = 0.1`).
    Relax {
        /// Relaxation sweeps.
        sweeps: usize,
    },
}

/// What a cut did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CutReport {
    /// Tetrahedra removed whole.
    pub removed_tets: usize,
    /// Vertices removed (no tet left around them).
    pub removed_vertices: usize,
    /// Vertices moved: by the relaxation (at least once), or snapped onto
    /// the cut surface by the exact cut.
    pub moved_vertices: usize,
    /// Relaxation sweeps done (fewer than asked when nothing could move;
    /// 0 for the exact cut).
    pub sweeps: usize,
    /// Tetrahedra the exact cut split (0 for the relaxation).
    pub split_tets: usize,
    /// Tetrahedra the split made (0 for the relaxation).
    pub created_tets: usize,
    /// Vertices the exact cut created on crossing edges.
    pub created_vertices: usize,
    /// The smallest dihedral angle, degrees, of the tets the exact cut made
    /// or whose corners it snapped (∞ when there are none, and for the
    /// relaxation).
    pub min_created_dihedral: f64,
    /// Where the cut's time went.
    pub times: CutTimes,
}

/// Wall-clock time of a cut's phases, ms (for benchmarks; it varies from
/// run to run, unlike the rest of [`CutReport`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CutTimes {
    /// Classifying the vertices and moving or splitting: the exact cut's
    /// snap and split, the relaxation's removal and sweeps.
    pub split_ms: f64,
    /// Building the new [`TetMesh`] (adjacency, boundary, its areas and
    /// normals) and carrying `φ` over.
    pub mesh_ms: f64,
    /// The per-tet geometry and the three matrices.
    pub assembly_ms: f64,
    /// Re-tracing the lights' shadows and the right-hand sides.
    pub lights_ms: f64,
}

impl Object {
    /// Cuts the object by `cut` with `method` (see [`CutMethod`]): keeps
    /// the side `cut.side(x) ≤ 0`, removes orphaned vertices, rebuilds the
    /// matrices and the lights' shadows, and carries `φ` over as the warm
    /// start (a created vertex gets `φ` interpolated along its edge).
    /// Tets left whole keep their original id; each piece of a split tet
    /// gets a new one, with its parent's medium, so that painting one
    /// piece leaves its siblings alone. A fractured piece that is cut can
    /// no longer be recombined.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a non-finite or zero plane/stroke,
    /// [`Error::CutRemovesEverything`], [`Error::CutAngleBound`] (exact cut
    /// only); the object is then unchanged.
    pub fn cut(&mut self, cut: &Cut, method: CutMethod) -> Result<CutReport, Error> {
        cut.check()?;
        match method {
            CutMethod::Relax { sweeps } => self.cut_relax(cut, sweeps),
            CutMethod::Exact => self.cut_exact(cut),
        }
    }

    /// [`CutMethod::Exact`].
    fn cut_exact(&mut self, cut: &Cut) -> Result<CutReport, Error> {
        let old_tets = self.mesh.tets().len();
        let old_vertices = self.mesh.vertex_count();
        let level = |x: DVec3| cut.side(x);
        let start = Instant::now();
        let split = split::split(&self.mesh, &level, split::Keep::Negative)?;
        if split.tets.is_empty() {
            return Err(Error::CutRemovesEverything { tets: old_tets });
        }
        let split_ms = ms(start);
        let start = Instant::now();
        let parts = self.split_parts(&split, true)?;
        let mesh_ms = ms(start);
        let whole = split.piece.iter().filter(|&&p| !p).count();
        let report = CutReport {
            removed_tets: old_tets - whole - split.split_tets,
            removed_vertices: (old_vertices + split.new.len()) - parts.mesh.vertex_count(),
            moved_vertices: split.snapped,
            sweeps: 0,
            split_tets: split.split_tets,
            created_tets: split.piece.iter().filter(|&&p| p).count(),
            created_vertices: split.new.len(),
            min_created_dihedral: parts.min_created_dihedral,
            times: CutTimes::default(),
        };
        self.mesh = parts.mesh;
        self.media = parts.media;
        self.phi = parts.phi;
        self.lineage = None;
        let [assembly_ms, lights_ms] = self.rebuild();
        Ok(CutReport {
            times: CutTimes {
                split_ms,
                mesh_ms,
                assembly_ms,
                lights_ms,
            },
            ..report
        })
    }

    /// The mesh, media and `φ` of a split (its tets' vertices renumbered in
    /// ascending order when `compact`, dropping the unused ones).
    pub(crate) fn split_parts(
        &self,
        split: &split::Split,
        compact: bool,
    ) -> Result<SplitParts, Error> {
        let total = split.positions.len();
        let mut index: Vec<u32> = if compact {
            vec![u32::MAX; total]
        } else {
            (0..total as u32).collect()
        };
        if compact {
            for &v in split.tets.iter().flatten() {
                index[v as usize] = 0;
            }
        }
        let mut kept = Vec::with_capacity(total);
        for (v, slot) in index.iter_mut().enumerate() {
            if *slot != u32::MAX {
                *slot = kept.len() as u32;
                kept.push(v);
            }
        }
        let positions: Vec<DVec3> = kept.iter().map(|&v| split.positions[v]).collect();
        let tets: Vec<[u32; 4]> = split
            .tets
            .iter()
            .map(|t| t.map(|v| index[v as usize]))
            .collect();
        let old = self.mesh.vertex_count();
        let phi = std::array::from_fn(|c| {
            let p = &self.phi[c];
            kept.iter()
                .map(|&v| match v.checked_sub(old) {
                    None => p[v],
                    Some(k) => {
                        let (a, b, t) = split.new[k];
                        p[a as usize] * (1.0 - t) + p[b as usize] * t
                    }
                })
                .collect()
        });
        let mut media = self.media.clone();
        let ids = self.mesh.original_ids();
        let original: Vec<u32> = split
            .parent
            .iter()
            .zip(&split.piece)
            .map(|(&t, &piece)| {
                let id = ids[t as usize];
                if piece {
                    media.push(media[id as usize]);
                    (media.len() - 1) as u32
                } else {
                    id
                }
            })
            .collect();
        let mut min_created_dihedral = f64::INFINITY;
        for (t, tet) in split.tets.iter().enumerate() {
            let touched = split.piece[t] || tet.iter().any(|&v| split.moved[v as usize]);
            if touched {
                let c = tet.map(|v| split.positions[v as usize]);
                min_created_dihedral = min_created_dihedral.min(split::min_dihedral_deg(&c));
            }
        }
        // The tets left whole keep their adjacency: only the faces around
        // the split are matched again.
        let from: Vec<u32> = split
            .parent
            .iter()
            .zip(&split.piece)
            .map(|(&t, &piece)| if piece { crate::mesh::NONE } else { t })
            .collect();
        let mesh = self
            .mesh
            .derived(positions, tets, original, &from, &index[..old])?;
        Ok(SplitParts {
            mesh,
            media,
            phi,
            min_created_dihedral,
        })
    }
}

/// Milliseconds since `start`.
pub(crate) fn ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// What a split object is made of.
pub(crate) struct SplitParts {
    pub(crate) mesh: TetMesh,
    pub(crate) media: Vec<crate::Medium>,
    pub(crate) phi: [Vec<f64>; 3],
    pub(crate) min_created_dihedral: f64,
}
