//! Scattering by rate: a Poisson point process on the surface whose
//! intensity is `rate × density(x)` points per unit area (the meaning of
//! "density" in Blender's Distribute Points on Faces and Houdini's
//! Scatter), built so that points stay put while the density is edited
//! and the mesh deforms.
//!
//! Each face `f` draws, from its own random stream seeded by
//! `(seed, f)`, a Poisson(`rate × max_density × area_f`) number of
//! *candidates*: uniform barycentrics and a uniform threshold `u` each.
//! A candidate is kept iff `u × max_density < density(candidate)`. This is
//! thinning (Lewis & Shedler 1979): the kept points are a Poisson process
//! of intensity `rate × density`. Since the candidates depend only on the
//! seed, the face's index and its area, and each keeps its threshold
//! (the fixed-candidate scheme of Gaffer/Cortex):
//!
//! - a face whose density did not change keeps bit-identical points,
//!   whatever changed elsewhere (locality);
//! - raising the density (pointwise `≥`) only adds points, lowering it
//!   only removes them, so a groom does not flicker while it is painted;
//! - an edit costs the edited faces only ([`Scatter::update_faces`]).
//!
//! Points are stored as `(face, barycentric)` inside each [`SurfacePoint`],
//! so [`SurfacePoint::on`] carries them onto a deformed mesh (Šik &
//! Křivánek 2013, Sec. 6, "coherence during animation").

use std::fmt;
use std::ops::Range;

use glam::Vec2;
use rand::Rng;
use rand::distr::Distribution;
use rand_distr::Poisson;

use crate::density::{map_faces, texture_uvs};
use crate::parallel::{check_points, chunk_rng, unit};
use crate::point::{Frame, uniform_barycentric};
use crate::{Density, Error, MeshRef, SurfacePoint};

/// Faces per parallel task of a full build (a fixed split: the result
/// does not depend on it, each face having its own stream).
const FACE_CHUNK: usize = 1024;

/// How far above the ceiling an interpolated density may round and still
/// count as the ceiling (relative).
const ROUNDING: f64 = 1e-6;

/// Where a scatter's density comes from: a value `≥ 0` at every point of
/// the surface, at most the scatter's `max_density`.
#[derive(Clone, Copy)]
pub enum ScatterDensity<'a> {
    /// Density 1 everywhere: `rate` points per unit area.
    Uniform,
    /// A texture at the mesh's UVs (bilinear or nearest, as the texture
    /// says), per-face or per-vertex (linear) weights.
    Density(Density<'a>),
    /// Any function of `(face, barycentric)`: for example a painted
    /// mesh-colours channel evaluated at the point.
    Function(&'a (dyn Fn(usize, [f32; 3]) -> f32 + Sync)),
}

impl fmt::Debug for ScatterDensity<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Uniform => f.write_str("Uniform"),
            Self::Density(d) => f.debug_tuple("Density").field(d).finish(),
            Self::Function(_) => f.write_str("Function(..)"),
        }
    }
}

impl<'a> From<Density<'a>> for ScatterDensity<'a> {
    fn from(density: Density<'a>) -> Self {
        Self::Density(density)
    }
}

/// What a scatter is asked for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScatterOptions {
    /// Points per unit area (in the mesh's unit) where the density is 1.
    pub rate: f64,
    /// The ceiling of the density, which sets the candidates: `rate ×
    /// max_density` of them per unit area. `None` takes the density's own
    /// maximum (1 for [`ScatterDensity::Uniform`], the largest texel or
    /// weight); a [`ScatterDensity::Function`] needs it stated. State it
    /// (1.0 for a channel painted in `[0, 1]`) when the density will be
    /// edited: the superset and locality properties hold for edits under
    /// the same ceiling.
    pub max_density: Option<f64>,
    /// The seed: the points are a function of the seed, the mesh and the
    /// density, on any number of threads.
    pub seed: u64,
    /// A density above `max_density` (by more than a relative 10⁻⁶ of
    /// rounding, which counts as the ceiling) is an
    /// [`Error::DensityOutOfRange`] (`false`, the default) or is taken as `max_density` (`true`: every
    /// candidate there is kept, so the intensity saturates at `rate ×
    /// max_density`).
    pub clamp: bool,
}

impl ScatterOptions {
    /// `rate` points per unit area of density 1, the density's own
    /// maximum as the ceiling, seed 0, no clamping.
    pub fn new(rate: f64) -> Self {
        Self {
            rate,
            max_density: None,
            seed: 0,
            clamp: false,
        }
    }
}

/// What [`Scatter::update_faces`] changed, so that a caller (a GPU
/// buffer) can upload only that.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ScatterUpdate {
    /// The faces whose points were recomputed: sorted, without
    /// repetitions. Their points are [`Scatter::face_range`] of each.
    pub faces: Vec<u32>,
    /// `None` when every recomputed face kept its number of points: only
    /// the ranges of `faces` were rewritten, in place. Otherwise the index
    /// in [`Scatter::points`] of the first face whose count changed:
    /// before it, only the ranges of `faces` changed, and from it on the
    /// points must be re-read (in memory, the update may have moved the
    /// points before it instead, but [`Scatter::points`] indexes them as
    /// before).
    pub moved_from: Option<usize>,
}

/// The density resolved against a mesh: validated once per build or
/// update, evaluated per candidate.
#[derive(Clone, Copy)]
enum Field<'a> {
    Uniform,
    Texture(&'a crate::DensityTexture, &'a [Vec2]),
    PerFace(&'a [f32]),
    PerVertex(&'a [f32]),
    Function(&'a (dyn Fn(usize, [f32; 3]) -> f32 + Sync)),
}

impl<'a> Field<'a> {
    /// Checks `density` against `mesh`: UVs for a texture, the weights'
    /// length and values.
    fn new(mesh: &MeshRef<'a>, density: ScatterDensity<'a>) -> Result<Self, Error> {
        Ok(match density {
            ScatterDensity::Uniform => Self::Uniform,
            ScatterDensity::Function(f) => Self::Function(f),
            ScatterDensity::Density(Density::Texture(t)) => Self::Texture(t, texture_uvs(mesh)?),
            ScatterDensity::Density(Density::PerFace(w)) => {
                check_weights("face", w, mesh.indices.len())?;
                Self::PerFace(w)
            }
            ScatterDensity::Density(Density::PerVertex(w)) => {
                check_weights("vertex", w, mesh.positions.len())?;
                Self::PerVertex(w)
            }
        })
    }

    /// The density's own maximum, when it has one without a search.
    fn own_max(&self) -> Option<f64> {
        let largest = |w: &[f32]| w.iter().fold(0.0f32, |m, &x| m.max(x));
        match self {
            Self::Uniform => Some(1.0),
            Self::Texture(t, _) => Some(f64::from(t.max())),
            Self::PerFace(w) | Self::PerVertex(w) => Some(f64::from(largest(w))),
            Self::Function(_) => None,
        }
    }

    /// The largest density on `face` when it is known exactly from the
    /// weights (checked against the ceiling before any candidate, so that
    /// the error does not depend on where candidates fall).
    fn face_max(&self, mesh: &MeshRef<'_>, face: usize) -> Option<f64> {
        match self {
            Self::PerFace(w) => Some(f64::from(w[face])),
            Self::PerVertex(w) => Some(
                mesh.indices[face]
                    .iter()
                    .map(|&i| f64::from(w[i as usize]))
                    .fold(0.0, f64::max),
            ),
            _ => None,
        }
    }

    /// The density at `barycentric` of `face`.
    #[inline]
    fn at(&self, mesh: &MeshRef<'_>, face: usize, barycentric: [f32; 3]) -> f64 {
        let [b0, b1, b2] = barycentric.map(f64::from);
        match *self {
            Self::Uniform => 1.0,
            Self::Texture(texture, uvs) => {
                let [a, b, c] = mesh.indices[face].map(|i| uvs[i as usize].as_dvec2());
                texture.eval(a + (b - a) * b1 + (c - a) * b2)
            }
            Self::PerFace(w) => f64::from(w[face]),
            Self::PerVertex(w) => {
                let t = mesh.indices[face].map(|i| f64::from(w[i as usize]));
                t[0] * b0 + t[1] * b1 + t[2] * b2
            }
            Self::Function(f) => f64::from(f(face, barycentric)),
        }
    }
}

/// [`DensitySampler`](crate::DensitySampler)'s weight check, with the
/// same errors.
fn check_weights(what: &'static str, w: &[f32], expected: usize) -> Result<(), Error> {
    if w.len() != expected {
        return Err(Error::WeightLength {
            what,
            len: w.len(),
            expected,
        });
    }
    match w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
        Some(index) => Err(Error::InvalidWeight {
            what,
            index,
            value: w[index],
        }),
        None => Ok(()),
    }
}

/// Points scattered by rate over a mesh, kept per face so that an edit
/// of the density on some faces is redone at the cost of those faces.
///
/// The points are one flat array in face order (within a face, in the
/// order of its candidates), with per-face offsets: face `f`'s points are
/// `points()[offsets()[f]..offsets()[f + 1]]`. Each point's `pdf` is the
/// process's intensity there, `rate × density` points per unit area (so
/// a point kept after its density was raised reports the new value; its
/// position, face and barycentrics are bit-identical).
///
/// # Performance
/// A build costs the candidates, `rate × max_density × area` of them
/// (about 100 ns each on 2 cores, the `scatter` example); an update, the
/// candidates of its faces, plus, when a face's count changed, a move of
/// the points on the smaller side of the edit (the buffer keeps about 6 %
/// free on each side for that). Memory: 72 bytes a point and that room,
/// and a 64-byte frame and a 4-byte offset per face.
///
/// # Example
/// ```
/// use glam::Vec3;
/// use mesh_sampling::{Density, MeshRef, Scatter, ScatterDensity, ScatterOptions, SurfacePoint};
///
/// // A unit square; 2,000 candidates per unit area of density 1.
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
/// let indices = [[0, 1, 2], [1, 3, 2]];
/// let mesh = MeshRef::new(&positions, &indices);
/// let options = ScatterOptions { max_density: Some(1.0), seed: 7, ..ScatterOptions::new(2000.0) };
///
/// let mut weights = vec![0.25f32, 0.25];
/// let mut scatter = Scatter::new(mesh, Density::PerFace(&weights).into(), &options)?;
/// let before = scatter.face_points(0).to_vec();
///
/// // Paint face 1 brighter: face 0 keeps its points bit for bit, face 1
/// // keeps its old points and gains more.
/// let old_face1 = scatter.face_points(1).to_vec();
/// weights[1] = 0.75;
/// let update = scatter.update_faces(&[1], Density::PerFace(&weights).into())?;
/// assert_eq!(update.faces, [1]);
/// assert_eq!(scatter.face_points(0), &before[..]);
/// let new_face1: Vec<Vec3> = scatter.face_points(1).iter().map(|p| p.position).collect();
/// assert!(new_face1.len() > old_face1.len());
/// assert!(old_face1.iter().all(|p| new_face1.contains(&p.position)));
/// // The same points as a full rebuild with the new weights.
/// let rebuilt = Scatter::new(mesh, Density::PerFace(&weights).into(), &options)?;
/// assert_eq!(scatter.points(), rebuilt.points());
///
/// // Deform the mesh: each point rides along on its face.
/// let lifted: Vec<Vec3> = positions.iter().map(|p| *p + Vec3::Z * p.x).collect();
/// let deformed = MeshRef::new(&lifted, &indices);
/// for p in scatter.points() {
///     let q = SurfacePoint::on(&deformed, p.face, p.barycentric, p.pdf)?;
///     assert!((q.position.z - q.position.x).abs() < 1e-5);
/// }
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Scatter<'a> {
    mesh: MeshRef<'a>,
    rate: f64,
    max_density: f64,
    seed: u64,
    clamp: bool,
    frames: Vec<Frame>,
    /// The points are `buffer[base..base + len]`; the room on both sides
    /// lets an update move whichever side of an edit holds fewer points.
    buffer: Vec<SurfacePoint>,
    base: usize,
    len: usize,
    /// `offsets[f]..offsets[f + 1]` are face `f`'s points (from `base`).
    offsets: Vec<u32>,
}

/// Free slots kept on each side of the points, for `len` points: about
/// 6 %, so that most edits move points within the buffer.
fn headroom(len: usize) -> usize {
    len / 16 + 1024
}

impl<'a> Scatter<'a> {
    /// Scatters points over `mesh` with intensity `rate × density` per unit
    /// area, on all threads with the `rayon` feature (the result does not
    /// depend on their number).
    ///
    /// # Errors
    /// The mesh's errors ([`MeshRef::validate`]); [`Error::MissingUvs`] or
    /// [`Error::NonFiniteUv`] for a texture; [`Error::WeightLength`] or
    /// [`Error::InvalidWeight`] for weights; [`Error::InvalidDensity`] for
    /// a negative, NaN or infinite rate; [`Error::InvalidMaxDensity`] for
    /// such a ceiling, or [`Error::InvalidOption`] when a function density
    /// has none; [`Error::TooManyPoints`] when the expected number of
    /// candidates, `rate × max_density × total area`, exceeds
    /// [`MAX_POINTS`](crate::MAX_POINTS) (checked before allocating);
    /// [`Error::DensityOutOfRange`] naming the first face (in face order)
    /// whose density exceeds the ceiling (per-face and per-vertex weights
    /// are checked on the whole face, a texture or function at the
    /// candidates) or is negative or NaN, unless `clamp` is set (a
    /// negative or NaN value is an error even then).
    pub fn new(
        mesh: MeshRef<'a>,
        density: ScatterDensity<'_>,
        options: &ScatterOptions,
    ) -> Result<Self, Error> {
        Self::build(mesh, density, options, true)
    }

    /// [`new`](Self::new), with room on both sides of the points for
    /// updates when `room`.
    fn build(
        mesh: MeshRef<'a>,
        density: ScatterDensity<'_>,
        options: &ScatterOptions,
        room: bool,
    ) -> Result<Self, Error> {
        mesh.validate()?;
        let rate = options.rate;
        if !(rate >= 0.0 && rate.is_finite()) {
            return Err(Error::InvalidDensity(rate));
        }
        let field = Field::new(&mesh, density)?;
        let max_density = match options.max_density.or_else(|| field.own_max()) {
            Some(m) if m >= 0.0 && m.is_finite() => m,
            Some(m) => return Err(Error::InvalidMaxDensity(m)),
            None => {
                return Err(Error::InvalidOption(
                    "a density function needs max_density, the ceiling of its values".into(),
                ));
            }
        };
        let faces = mesh.indices.len();
        let many = faces >= 4 * FACE_CHUNK;
        let area: f64 = map_faces(many, faces, |f| mesh.area(f)).iter().sum();
        // The expected candidates bound the expected points; a Poisson
        // count exceeds its mean by more than a few √mean only with
        // negligible probability.
        check_points(rate * max_density * area)?;
        let mut scatter = Self {
            mesh,
            rate,
            max_density,
            seed: options.seed,
            clamp: options.clamp,
            frames: Frame::all(&mesh),
            buffer: Vec::new(),
            base: 0,
            len: 0,
            offsets: Vec::new(),
        };
        let chunks = map_faces(many, faces.div_ceil(FACE_CHUNK), |c| {
            let mut points = Vec::new();
            let mut ends = Vec::with_capacity(FACE_CHUNK);
            for face in c * FACE_CHUNK..((c + 1) * FACE_CHUNK).min(faces) {
                scatter.face(&field, face, &mut points)?;
                ends.push(points.len());
            }
            Ok((points, ends))
        });
        let len: usize = chunks
            .iter()
            .map(|c| c.as_ref().map_or(0, |(p, _)| p.len()))
            .sum();
        let pad = if room { headroom(len) } else { 0 };
        let mut buffer = Vec::with_capacity(len + 2 * pad);
        buffer.resize(pad, SurfacePoint::default());
        let mut offsets = Vec::with_capacity(faces + 1);
        offsets.push(0);
        for chunk in chunks {
            let (chunk_points, ends) = chunk?;
            let start = buffer.len() - pad;
            offsets.extend(ends.iter().map(|&e| (start + e) as u32));
            buffer.extend_from_slice(&chunk_points);
        }
        buffer.resize(len + 2 * pad, SurfacePoint::default());
        scatter.buffer = buffer;
        (scatter.base, scatter.len) = (pad, len);
        scatter.offsets = offsets;
        Ok(scatter)
    }

    /// The candidates of `face` thinned by `field`, appended to `out`.
    fn face(
        &self,
        field: &Field<'_>,
        face: usize,
        out: &mut Vec<SurfacePoint>,
    ) -> Result<(), Error> {
        let max = self.max_density;
        if let Some(m) = field.face_max(&self.mesh, face)
            && m > max
            && !self.clamp
        {
            return Err(Error::DensityOutOfRange {
                face,
                value: m,
                max,
            });
        }
        let mean = self.rate * max * self.mesh.area(face);
        if mean.is_nan() || mean <= 0.0 {
            return Ok(());
        }
        let mut rng = chunk_rng(self.seed, face);
        // The mean is below MAX_POINTS (checked), far inside Poisson's
        // domain; the draw is a whole number.
        let count = Poisson::new(mean).map_or(0.0, |p| p.sample(&mut rng)) as u64;
        for _ in 0..count {
            // Every candidate takes its three variates whether or not it
            // is kept: the stream, hence the candidates, never depend on
            // the density.
            let barycentric = uniform_barycentric(unit(rng.next_u64()), unit(rng.next_u64()));
            let threshold = unit(rng.next_u64()) * max;
            let mut value = field.at(&self.mesh, face, barycentric);
            if !(value >= 0.0 && value <= max) {
                // A value interpolated from weights at the ceiling can
                // round above it (barycentrics summing to 1 + ε): that
                // is the ceiling, not an error.
                if value > max && (self.clamp || value <= max * (1.0 + ROUNDING)) {
                    value = max;
                } else {
                    return Err(Error::DensityOutOfRange { face, value, max });
                }
            }
            if threshold < value {
                out.push(SurfacePoint::in_frame(
                    &self.mesh,
                    &self.frames[face],
                    face as u32,
                    barycentric,
                    (self.rate * value) as f32,
                ));
            }
        }
        Ok(())
    }

    /// Re-thins the candidates of `faces` (any order, repetitions allowed)
    /// with `density`, which must differ from the density the scatter
    /// holds only on those faces: the points are then exactly those
    /// [`Scatter::new`] gives with `density` and the same options (and
    /// the same ceiling). Costs the faces' candidates, plus, when a face's
    /// count changed, moving the points on one side of it (in place).
    ///
    /// # Errors
    /// [`Error::NoSuchFace`] for a face that is not a triangle of the mesh;
    /// the density's errors as for [`Scatter::new`]. On an error the
    /// scatter is unchanged.
    pub fn update_faces(
        &mut self,
        faces: &[u32],
        density: ScatterDensity<'_>,
    ) -> Result<ScatterUpdate, Error> {
        let count = self.mesh.indices.len();
        if let Some(&face) = faces.iter().find(|&&f| f as usize >= count) {
            return Err(Error::NoSuchFace {
                face: face as usize,
                count,
            });
        }
        let mut faces = faces.to_vec();
        faces.sort_unstable();
        faces.dedup();
        let field = Field::new(&self.mesh, density)?;
        let fresh = map_faces(faces.len() >= 64, faces.len(), |k| {
            let mut points = Vec::new();
            self.face(&field, faces[k] as usize, &mut points)
                .map(|()| points)
        });
        let fresh = fresh.into_iter().collect::<Result<Vec<_>, _>>()?;
        let moved_from = faces
            .iter()
            .zip(&fresh)
            .find(|(f, p)| self.face_range(**f as usize).len() != p.len())
            .map(|(&f, _)| self.offsets[f as usize] as usize);
        match moved_from {
            None => {
                for (&f, points) in faces.iter().zip(&fresh) {
                    let range = self.face_range(f as usize);
                    let at = self.base + range.start;
                    self.buffer[at..at + range.len()].copy_from_slice(points);
                }
            }
            Some(_) => self.repack(&faces, &fresh),
        }
        Ok(ScatterUpdate { faces, moved_from })
    }

    /// Rewrites the points with `fresh[k]` as the points of `faces[k]`
    /// (sorted): the runs of faces in between shift by the counts' change
    /// before them. Within the buffer, the whole array may shift too, so
    /// the run with the most points stays put and only the others move;
    /// without room for that, the points go to a new buffer.
    fn repack(&mut self, faces: &[u32], fresh: &[Vec<SurfacePoint>]) {
        let at = |f: usize| self.offsets[f] as usize;
        // Run k: the unchanged faces before `faces[k]` (after the
        // previous one), the last run after the last face; each with its
        // old range and its shift (from `base`).
        let mut runs = Vec::with_capacity(faces.len() + 1);
        let mut starts = Vec::with_capacity(faces.len()); // new start of faces[k]
        let mut deltas = Vec::with_capacity(faces.len()); // its change of count
        let (mut next, mut shift) = (0, 0isize);
        for (&f, points) in faces.iter().zip(fresh) {
            let f = f as usize;
            runs.push((at(next)..at(f), shift));
            starts.push(at(f).wrapping_add_signed(shift));
            deltas.push(points.len() as isize - (at(f + 1) - at(f)) as isize);
            shift += deltas[deltas.len() - 1];
            next = f + 1;
        }
        runs.push((at(next)..self.len, shift));
        let len = self.len.wrapping_add_signed(shift);
        match self.anchor(&runs, len) {
            Some(anchor) => self.shift_runs(&runs, anchor),
            None => self.regrow(&runs, len),
        }
        for (&start, points) in starts.iter().zip(fresh) {
            let at = self.base + start;
            self.buffer[at..at + points.len()].copy_from_slice(points);
        }
        self.len = len;
        // Offsets after the first changed face: shifted by the change of
        // the counts of the changed faces before them.
        let (mut k, mut shift) = (0, 0isize);
        for f in faces[0] as usize + 1..self.offsets.len() {
            while k < faces.len() && (faces[k] as usize) < f {
                shift += deltas[k];
                k += 1;
            }
            self.offsets[f] = (self.offsets[f] as isize + shift) as u32;
        }
    }

    /// The shift of the runs that stay put: the one with the most points
    /// among those for which the `len` new points fit in the buffer.
    fn anchor(&self, runs: &[(Range<usize>, isize)], len: usize) -> Option<isize> {
        let mut by_shift: Vec<(isize, usize)> = runs.iter().map(|(r, s)| (*s, r.len())).collect();
        by_shift.sort_unstable();
        by_shift.dedup_by(|b, a| {
            let same = a.0 == b.0;
            if same {
                a.1 += b.1;
            }
            same
        });
        by_shift.sort_unstable_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        by_shift.into_iter().map(|(s, _)| s).find(|&s| {
            self.base
                .checked_add_signed(-s)
                .is_some_and(|base| base + len <= self.buffer.len())
        })
    }

    /// Moves each run by its shift less `anchor`, in place, and the base
    /// by `−anchor`.
    fn shift_runs(&mut self, runs: &[(Range<usize>, isize)], anchor: isize) {
        let base = self.base;
        let to = |start: usize, s: isize| (base + start).wrapping_add_signed(s - anchor);
        let from = |r: &Range<usize>| base + r.start..base + r.end;
        // A run moving right can only overwrite the old place of runs
        // that also move right and lie after it (the order of the points
        // is kept), so those go first, from the end; symmetrically, runs
        // moving left go from the start.
        for (range, s) in runs.iter().rev().filter(|(_, s)| *s > anchor) {
            self.buffer.copy_within(from(range), to(range.start, *s));
        }
        for (range, s) in runs.iter().filter(|(_, s)| *s < anchor) {
            self.buffer.copy_within(from(range), to(range.start, *s));
        }
        self.base = base.wrapping_add_signed(-anchor);
    }

    /// Copies the runs, at their shifts, into a new buffer with room on
    /// both sides for `len` points (the new faces' points are written by
    /// the caller).
    fn regrow(&mut self, runs: &[(Range<usize>, isize)], len: usize) {
        let pad = headroom(len);
        let mut buffer = vec![SurfacePoint::default(); len + 2 * pad];
        for (range, s) in runs {
            let to = (pad + range.start).wrapping_add_signed(*s);
            buffer[to..to + range.len()]
                .copy_from_slice(&self.buffer[self.base + range.start..self.base + range.end]);
        }
        self.buffer = buffer;
        self.base = pad;
    }

    /// All points, in face order.
    pub fn points(&self) -> &[SurfacePoint] {
        &self.buffer[self.base..self.base + self.len]
    }

    /// The points, consumed.
    pub fn into_points(self) -> Vec<SurfacePoint> {
        let mut buffer = self.buffer;
        buffer.truncate(self.base + self.len);
        buffer.drain(..self.base);
        buffer
    }

    /// Per-face offsets into [`points`](Self::points): `faces + 1`
    /// entries, face `f`'s points at `offsets[f]..offsets[f + 1]`.
    pub fn offsets(&self) -> &[u32] {
        &self.offsets
    }

    /// The indices of face `face`'s points (empty for no such face).
    pub fn face_range(&self, face: usize) -> Range<usize> {
        let next = face.checked_add(1).and_then(|g| self.offsets.get(g));
        match (self.offsets.get(face), next) {
            (Some(&a), Some(&b)) => a as usize..b as usize,
            _ => 0..0,
        }
    }

    /// The points of face `face` (empty for no such face).
    pub fn face_points(&self, face: usize) -> &[SurfacePoint] {
        &self.points()[self.face_range(face)]
    }

    /// The mesh.
    pub fn mesh(&self) -> &MeshRef<'a> {
        &self.mesh
    }

    /// Points per unit area where the density is 1.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// The ceiling in use (stated, or the density's own maximum at
    /// construction).
    pub fn max_density(&self) -> f64 {
        self.max_density
    }

    /// Heap memory of the scatter: points (with the room kept for
    /// updates), offsets and per-face frames.
    pub fn memory_bytes(&self) -> usize {
        self.buffer.capacity() * size_of::<SurfacePoint>()
            + self.offsets.capacity() * size_of::<u32>()
            + self.frames.capacity() * size_of::<Frame>()
    }
}

/// The points of [`Scatter::new`], without keeping the scatter.
///
/// # Errors
/// As for [`Scatter::new`].
pub fn scatter(
    mesh: MeshRef<'_>,
    density: ScatterDensity<'_>,
    options: &ScatterOptions,
) -> Result<Vec<SurfacePoint>, Error> {
    Scatter::build(mesh, density, options, false).map(Scatter::into_points)
}

#[cfg(test)]
mod tests;
