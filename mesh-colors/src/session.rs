//! The painting system's document (Sec. 5.1): mesh colours being painted,
//! with the gestures a 3D paint tool offers — brush strokes (falloff
//! hardness, pen pressure, mix / add / multiply / erase, X-mirror, only
//! what the painter sees), fill of a connected part, the eyedropper, and
//! the detail brush that raises or lowers face resolution where it
//! passes — each one step of undo, and a log of edits that replays bit
//! for bit.
//!
//! A [`PaintSession`] owns the colours and an index of the mesh's faces
//! that finds the samples under a brush (no resolution change touches
//! it); a server or a
//! script drives it with [`PaintSession::apply`] and reads back which
//! samples changed ([`Changed`]) to update a GPU copy incrementally.
//! Undo keeps deltas ([`crate::undo`]), never copies of the colours.
//!
//! Painting "what the user sees" (Blender's projected brush; painters'
//! most common complaint is a brush that paints through a thin wall) needs
//! the eye: a stroke that carries [`Brush::eye`] touches only samples
//! whose shading normal faces the eye and, with an [`Occluder`], that the
//! eye sees unobstructed. The occluder is the caller's (a BVH ray cast):
//! this crate stays free of a ray tracer.

use std::sync::Arc;

use glam::Vec3;

use crate::Error;
use crate::edit::ResolutionChange;
use crate::reach::{Hit, Reach};
use crate::structure::{MeshColors, Site, lattice_points};
use crate::undo::{History, Recorder, Step};

/// Answers whether the surface hides a point from an eye.
pub trait Occluder: Send + Sync + std::fmt::Debug {
    /// Whether the segment from `eye` to `point` meets the surface before
    /// it reaches `point`'s neighbourhood (the implementor's tolerance
    /// keeps the point's own face from hiding it).
    fn blocked(&self, eye: Vec3, point: Vec3) -> bool;
}

/// How a brush combines its colour with a sample, by the weight `w` of its
/// falloff at the sample (`x` the sample's value, `c` the brush's).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BrushMode {
    /// `x + w (c − x)`: towards the colour.
    Mix,
    /// `x + w c`: accumulate (densities, masks).
    Add,
    /// `x (1 + w (c − 1))`: darken by the colour (1 leaves it).
    Multiply,
    /// `x + w (b − x)`, `b` the base colour: back to the start.
    Erase,
}

/// What a stroke or a fill paints with.
#[derive(Debug, Clone, PartialEq)]
pub struct Brush {
    /// How the colour is combined.
    pub mode: BrushMode,
    /// The values for channels `first_channel ..< first_channel +
    /// color.len()` (RGB on channels 0–2, a scalar channel alone, …); the
    /// other channels are untouched. Unused by [`BrushMode::Erase`] except
    /// for which channels it restores.
    pub color: Vec<f32>,
    /// The first channel `color` paints.
    pub first_channel: usize,
    /// Scales the falloff weight, 0 to 1.
    pub strength: f32,
    /// The share of the radius painted at full weight, 0 (soft) to 1
    /// (hard edge); beyond it the weight falls smoothly to 0 at the rim.
    pub hardness: f32,
    /// Also paint mirrored across the plane `x = mirror_x` (X symmetry).
    pub mirror_x: Option<f32>,
    /// Paint only samples whose normal faces this point and, with the
    /// session's [`Occluder`], that it sees: the camera's position.
    pub eye: Option<Vec3>,
}

impl Brush {
    /// The falloff weight at distance `d` from a dab of radius `r` with
    /// pen pressure `pressure`: `strength · pressure · (1 − s²)²`, with `s`
    /// the distance beyond the hard core as a share of the soft rim (1 in
    /// the core, 0 at and beyond `r`, zero slope at the rim).
    pub fn weight(&self, d: f32, r: f32, pressure: f32) -> f32 {
        let x = d / r;
        if x >= 1.0 {
            return 0.0;
        }
        let h = self.hardness;
        let falloff = if x <= h {
            1.0
        } else {
            let s = (x - h) / (1.0 - h);
            let t = 1.0 - s * s;
            t * t
        };
        self.strength * pressure * falloff
    }

    /// Checks the brush against colours of `channels` channels.
    fn check(&self, channels: usize) -> Result<(), Error> {
        let bad = |argument, reason| Err(Error::InvalidArgument { argument, reason });
        if self.color.is_empty()
            || self
                .first_channel
                .checked_add(self.color.len())
                .is_none_or(|end| end > channels)
        {
            return bad("brush.color", "names channels the colours do not have");
        }
        if self.color.iter().any(|c| !c.is_finite()) {
            return bad("brush.color", "is not finite");
        }
        if !(0.0..=1.0).contains(&self.strength) {
            return bad("brush.strength", "must be within 0 to 1");
        }
        if !(0.0..=1.0).contains(&self.hardness) {
            return bad("brush.hardness", "must be within 0 to 1");
        }
        if self.mirror_x.is_some_and(|m| !m.is_finite()) {
            return bad("brush.mirror_x", "is not finite");
        }
        if self.eye.is_some_and(|e| !e.is_finite()) {
            return bad("brush.eye", "is not finite");
        }
        Ok(())
    }
}

/// One dab of a stroke: where the brush touched the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dab {
    /// The centre, on the surface, in the mesh's space.
    pub center: Vec3,
    /// The radius in the mesh's units (a page converts a screen-constant
    /// size at the dab's depth).
    pub radius: f32,
    /// Pen pressure, 0 to 1 (1 for a mouse).
    pub pressure: f32,
}

impl Dab {
    fn check(&self) -> Result<(), Error> {
        let bad = |argument, reason| Err(Error::InvalidArgument { argument, reason });
        if !self.center.is_finite() {
            return bad("dab.center", "is not finite");
        }
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return bad("dab.radius", "must be a positive length");
        }
        if !(0.0..=1.0).contains(&self.pressure) {
            return bad("dab.pressure", "must be within 0 to 1");
        }
        Ok(())
    }
}

/// One gesture, as the log keeps it: replaying the log on the starting
/// colours gives the same colours bit for bit.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// A stroke: its dabs in order, one undo step.
    Stroke {
        /// The brush.
        brush: Brush,
        /// The dabs.
        dabs: Vec<Dab>,
    },
    /// The connected part of the surface that contains `face` (faces
    /// joined by edges), painted at full falloff weight.
    Fill {
        /// A face of the part.
        face: usize,
        /// The brush (its strength applies; radius and hardness do not).
        brush: Brush,
    },
    /// The detail brush: every face within `radius` of `center` raised
    /// (`levels > 0`) or lowered by `levels` resolution levels (Sec. 3.2:
    /// the colours are resampled, shared edges stay continuous), within
    /// `0..=`[`crate::MAX_LEVEL`].
    Detail {
        /// The centre, in the mesh's space.
        center: Vec3,
        /// The radius.
        radius: f32,
        /// Levels up (positive) or down (negative).
        levels: i8,
    },
    /// Every face set to one resolution level.
    Resolution {
        /// The level (resolution `2^level`).
        level: u8,
    },
    /// Undo the last step.
    Undo,
    /// Redo the last undone step.
    Redo,
}

/// Which samples an edit changed, for an incremental upload.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Changed {
    /// Nothing.
    #[default]
    Nothing,
    /// These samples' values (sorted, each once); the layout is the same.
    Samples(Vec<u32>),
    /// These faces' resolutions changed (sorted): the sample numbering is
    /// new.
    Layout(Vec<usize>),
}

/// The mesh colours being painted, their history and their log (see the
/// [module docs](self)).
#[derive(Debug)]
pub struct PaintSession {
    positions: Vec<Vec3>,
    colors: MeshColors,
    base: Vec<f32>,
    occluder: Option<Arc<dyn Occluder>>,
    /// Finds the samples under a dab.
    reach: Reach,
    /// Per vertex, the area-weighted sum of its faces' normals.
    vertex_normals: Vec<Vec3>,
    history: History,
    log: Vec<Edit>,
    open: Option<OpenStroke>,
    /// How to take back the last edit, when it changed resolutions
    /// ([`PaintSession::withdraw`]).
    withdraw: Option<Withdraw>,
}

/// What the last edit did to the history when it changed resolutions.
#[derive(Debug, Clone, Copy)]
enum Withdraw {
    /// Pushed a new step (a detail change or a global resolution).
    Pushed,
    /// Undid a step.
    Undid,
    /// Redid a step.
    Redid,
}

/// A stroke being painted dab by dab ([`PaintSession::begin_stroke`]).
#[derive(Debug)]
struct OpenStroke {
    brush: Brush,
    dabs: Vec<Dab>,
    recorder: Recorder,
}

impl PaintSession {
    /// A session on `colors` over a mesh with vertex `positions`; `base` is
    /// the colour erase restores (one value per channel); `history` is the
    /// number of undo steps kept; `occluder`, if any, hides what the eye
    /// cannot see from strokes that carry one.
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] for a `base` of the wrong length or too
    /// few positions, [`Error::NonFinite`] for a non-finite position or
    /// base value.
    pub fn new(
        positions: Vec<Vec3>,
        colors: MeshColors,
        base: Vec<f32>,
        history: usize,
        occluder: Option<Arc<dyn Occluder>>,
    ) -> Result<Self, Error> {
        if base.len() != colors.channels() {
            return Err(Error::ChannelMismatch {
                what: "base colour",
                expected: colors.channels(),
                got: base.len(),
            });
        }
        if let Some(i) = base.iter().position(|b| !b.is_finite()) {
            return Err(Error::NonFinite {
                what: "base colour channel",
                index: i,
            });
        }
        let t = colors.topology();
        crate::paint::check_vertex_positions(t.vertex_count(), &positions)?;
        let faces = t.faces();
        let reach = Reach::new(faces, &positions, grid_cell(&positions, faces));
        let vertex_normals = vertex_normals(faces, &positions);
        Ok(Self {
            positions,
            colors,
            base,
            occluder,
            reach,
            vertex_normals,
            history: History::new(history),
            log: Vec::new(),
            open: None,
            withdraw: None,
        })
    }

    /// The colours as painted so far.
    pub fn colors(&self) -> &MeshColors {
        &self.colors
    }

    /// The vertex positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// The undo history.
    pub fn history(&self) -> &History {
        &self.history
    }

    /// Keeps the undo history within `bytes` from now on (the oldest
    /// steps are dropped, the newest always kept; see
    /// [`History::with_budget`]). A replay must set the same budget to
    /// allow the same undos.
    pub fn limit_history_bytes(&mut self, bytes: usize) {
        self.history.set_budget(bytes);
    }

    /// Heap bytes the undo holds: the history's steps and the delta of a
    /// stroke still being painted.
    pub fn undo_memory_bytes(&self) -> usize {
        self.history.memory_bytes() + self.open.as_ref().map_or(0, |o| o.recorder.memory_bytes())
    }

    /// Every edit applied, in order (undo and redo included).
    pub fn log(&self) -> &[Edit] {
        &self.log
    }

    /// Starts a stroke painted as its dabs arrive (a pointer being
    /// dragged): [`Self::add_dabs`] paints them, [`Self::end_stroke`]
    /// makes the stroke one undo step and logs it as one
    /// [`Edit::Stroke`], which replays to the same colours. A stroke still
    /// open is ended first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming the brush's bad field.
    pub fn begin_stroke(&mut self, brush: Brush) -> Result<(), Error> {
        brush.check(self.colors.channels())?;
        self.end_stroke();
        self.open = Some(OpenStroke {
            brush,
            dabs: Vec::new(),
            recorder: Recorder::new(&self.colors),
        });
        Ok(())
    }

    /// Paints `dabs` with the open stroke's brush; returns the samples
    /// they changed (each once per call).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for a bad dab (none of `dabs` is painted
    /// then) or when no stroke is open.
    pub fn add_dabs(&mut self, dabs: &[Dab]) -> Result<Changed, Error> {
        for d in dabs {
            d.check()?;
        }
        let Some(mut open) = self.open.take() else {
            return Err(Error::InvalidArgument {
                argument: "dabs",
                reason: "arrived with no stroke begun",
            });
        };
        let mut changed = Vec::new();
        let result = self.paint_dabs(&open.brush, dabs, &mut open.recorder, &mut changed);
        open.dabs.extend_from_slice(dabs);
        self.open = Some(open);
        result?;
        changed.sort_unstable();
        changed.dedup();
        Ok(if changed.is_empty() {
            Changed::Nothing
        } else {
            Changed::Samples(changed)
        })
    }

    /// Ends the open stroke, if any: one undo step (none when it changed
    /// nothing) and one logged [`Edit::Stroke`].
    pub fn end_stroke(&mut self) {
        let Some(open) = self.open.take() else {
            return;
        };
        if !open.recorder.is_empty() {
            self.history.push(Step::Paint(open.recorder.finish()));
        }
        self.log.push(Edit::Stroke {
            brush: open.brush,
            dabs: open.dabs,
        });
    }

    /// Applies one gesture and logs it; returns which samples changed.
    /// An edit that fails changes nothing and is not logged. A stroke
    /// still open ([`Self::begin_stroke`]) is ended first.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming the field of a bad brush, dab or
    /// level, [`Error::MissingFace`] for a fill of a face that does not
    /// exist, and the errors of the resolution change.
    pub fn apply(&mut self, edit: Edit) -> Result<Changed, Error> {
        self.end_stroke();
        self.withdraw = None;
        let changed = match &edit {
            Edit::Stroke { brush, dabs } => self.stroke(brush, dabs)?,
            Edit::Fill { face, brush } => self.fill(*face, brush)?,
            Edit::Detail {
                center,
                radius,
                levels,
            } => self.detail(*center, *radius, *levels)?,
            Edit::Resolution { level } => self.resolution(*level)?,
            Edit::Undo => self.walk(true)?,
            Edit::Redo => self.walk(false)?,
        };
        if let Changed::Layout(_) = changed {
            self.withdraw = Some(match edit {
                Edit::Undo => Withdraw::Undid,
                Edit::Redo => Withdraw::Redid,
                _ => Withdraw::Pushed,
            });
        }
        self.log.push(edit);
        Ok(changed)
    }

    /// Takes back the last edit [`Self::apply`] applied, when it changed
    /// resolutions (a detail change, a global resolution, or an undo or
    /// redo of one), as if it had not been made: for a caller that cannot
    /// show the result (a GPU texture it does not fit). The colours and the
    /// history are as before it and the edit leaves the log; a new change
    /// had also dropped the steps undone before it, as any new edit does,
    /// and they stay dropped. Returns the faces resampled back.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming `edit` when the last edit changed
    /// no resolution or was already taken back, or `history` when the
    /// history keeps no steps (a limit of 0); nothing changes then.
    pub fn withdraw(&mut self) -> Result<Changed, Error> {
        let Some(how) = self.withdraw else {
            return Err(Error::InvalidArgument {
                argument: "edit",
                reason: "the last edit changed no resolution (or was taken back)",
            });
        };
        let step = match how {
            Withdraw::Pushed | Withdraw::Redid => self.history.undo(&mut self.colors)?,
            Withdraw::Undid => self.history.redo(&mut self.colors)?,
        };
        let Some(Step::Resolution(change)) = step else {
            return Err(Error::InvalidArgument {
                argument: "history",
                reason: "keeps no steps, so the change cannot be taken back",
            });
        };
        let faces = resampled(change);
        if let Withdraw::Pushed = how {
            self.history.drop_undone();
        }
        self.colors.shrink_to_fit();
        self.log.pop();
        self.withdraw = None;
        Ok(Changed::Layout(faces))
    }

    /// Replays `log` on a new session (the arguments of [`Self::new`]):
    /// the colours come out bit for bit as the logged session left them.
    ///
    /// # Errors
    /// As [`Self::new`], and the first failing edit's error with its
    /// position in the log ([`Error::InvalidArgument`] is returned as is).
    pub fn replay(
        positions: Vec<Vec3>,
        colors: MeshColors,
        base: Vec<f32>,
        history: usize,
        occluder: Option<Arc<dyn Occluder>>,
        log: &[Edit],
    ) -> Result<Self, Error> {
        let mut session = Self::new(positions, colors, base, history, occluder)?;
        for edit in log {
            session.apply(edit.clone())?;
        }
        Ok(session)
    }

    /// The colour under the eyedropper: the linear filter (Fig. 7) at
    /// `barycentric` on `face`.
    ///
    /// # Errors
    /// As [`MeshColors::linear`].
    pub fn pick(&self, face: usize, barycentric: [f32; 3]) -> Result<Vec<f32>, Error> {
        let mut out = vec![0.0; self.colors.channels()];
        self.colors.linear(face, barycentric, &mut out)?;
        Ok(out)
    }

    /// One stroke: every dab (and its mirror image) in order, one step.
    fn stroke(&mut self, brush: &Brush, dabs: &[Dab]) -> Result<Changed, Error> {
        brush.check(self.colors.channels())?;
        for d in dabs {
            d.check()?;
        }
        let mut recorder = Recorder::new(&self.colors);
        let mut changed = Vec::new();
        self.paint_dabs(brush, dabs, &mut recorder, &mut changed)?;
        Ok(self.finish(recorder, changed))
    }

    /// Paints `dabs` (and their mirror images) in order.
    fn paint_dabs(
        &mut self,
        brush: &Brush,
        dabs: &[Dab],
        recorder: &mut Recorder,
        changed: &mut Vec<u32>,
    ) -> Result<(), Error> {
        for d in dabs {
            let mirrored = brush.mirror_x.map(|m| Dab {
                center: Vec3::new(2.0 * m - d.center.x, d.center.y, d.center.z),
                ..*d
            });
            for dab in std::iter::once(*d).chain(mirrored) {
                self.dab(brush, &dab, recorder, changed)?;
            }
        }
        Ok(())
    }

    /// One dab: the samples within its radius that the eye (if any) sees.
    fn dab(
        &mut self,
        brush: &Brush,
        dab: &Dab,
        recorder: &mut Recorder,
        changed: &mut Vec<u32>,
    ) -> Result<(), Error> {
        let mut hits = Vec::new();
        self.reach.within(
            &self.colors,
            &self.positions,
            dab.center,
            dab.radius,
            &mut hits,
        );
        for hit in hits {
            if !self.seen(brush.eye, &hit) {
                continue;
            }
            let w = brush.weight(hit.distance, dab.radius, dab.pressure);
            self.blend(brush, hit.sample, w, recorder, changed)?;
        }
        Ok(())
    }

    /// Whether a sample is painted from `eye`: facing it and unhidden.
    fn seen(&self, eye: Option<Vec3>, hit: &Hit) -> bool {
        let Some(eye) = eye else {
            return true;
        };
        let normal = normal_at(
            self.colors.topology().faces(),
            &self.vertex_normals,
            &hit.site,
        );
        if normal.dot(eye - hit.position) <= 0.0 {
            return false;
        }
        self.occluder
            .as_ref()
            .is_none_or(|o| !o.blocked(eye, hit.position))
    }

    /// Blends sample `i` with weight `w`, recording its old value first.
    fn blend(
        &mut self,
        brush: &Brush,
        i: usize,
        w: f32,
        recorder: &mut Recorder,
        changed: &mut Vec<u32>,
    ) -> Result<(), Error> {
        let first = brush.first_channel;
        let base = &self.base[first..first + brush.color.len()];
        let Some(s) = self.colors.sample(i) else {
            return Ok(());
        };
        let old = &s[first..first + brush.color.len()];
        let new: Vec<f32> = old
            .iter()
            .zip(&brush.color)
            .zip(base)
            .map(|((&x, &c), &b)| match brush.mode {
                BrushMode::Mix => x + w * (c - x),
                BrushMode::Add => x + w * c,
                BrushMode::Multiply => x * (1.0 + w * (c - 1.0)),
                BrushMode::Erase => x + w * (b - x),
            })
            .collect();
        if new.iter().zip(old).all(|(a, b)| a.to_bits() == b.to_bits()) {
            return Ok(());
        }
        recorder.record(&self.colors, i)?;
        changed.push(i as u32);
        if let Some(s) = self.colors.sample_mut(i) {
            s[first..first + new.len()].copy_from_slice(&new);
        }
        Ok(())
    }

    /// Closes a paint step: pushes its delta, sorts the changed samples.
    fn finish(&mut self, recorder: Recorder, mut changed: Vec<u32>) -> Changed {
        if recorder.is_empty() {
            return Changed::Nothing;
        }
        self.history.push(Step::Paint(recorder.finish()));
        changed.sort_unstable();
        changed.dedup();
        Changed::Samples(changed)
    }

    /// Fills the connected part of the surface containing `face`.
    fn fill(&mut self, face: usize, brush: &Brush) -> Result<Changed, Error> {
        brush.check(self.colors.channels())?;
        let count = self.colors.face_count();
        if face >= count {
            return Err(Error::MissingFace { face, count });
        }
        let part = connected_part(&self.colors, face);
        let mut samples = Vec::new();
        for f in part {
            let r = self.colors.face_resolution(f).unwrap_or(1);
            samples.extend(lattice_points(r).filter_map(|a| self.colors.lattice_index(f, a)));
        }
        samples.sort_unstable();
        samples.dedup();
        let mut recorder = Recorder::new(&self.colors);
        let mut changed = Vec::new();
        for i in samples {
            self.blend(brush, i, brush.strength, &mut recorder, &mut changed)?;
        }
        Ok(self.finish(recorder, changed))
    }

    /// The detail brush: faces within `radius` of `center` up or down.
    fn detail(&mut self, center: Vec3, radius: f32, levels: i8) -> Result<Changed, Error> {
        Dab {
            center,
            radius,
            pressure: 1.0,
        }
        .check()?;
        let faces = self.colors.topology().faces();
        let changes: Vec<(usize, u32)> = (0..faces.len())
            .filter(|&f| {
                let [a, b, c] = faces[f].map(|v| self.positions[v as usize]);
                distance_to_triangle(center, a, b, c) <= radius
            })
            .filter_map(|f| {
                let level = i32::from(self.colors.face_level(f)?);
                let to = (level + i32::from(levels)).clamp(0, i32::from(crate::MAX_LEVEL));
                (to != level).then_some((f, 1u32 << to))
            })
            .collect();
        self.resample(&changes)
    }

    /// Every face to resolution `2^level`.
    fn resolution(&mut self, level: u8) -> Result<Changed, Error> {
        if level > crate::MAX_LEVEL {
            return Err(Error::InvalidArgument {
                argument: "level",
                reason: "is above the finest level mesh colours allow",
            });
        }
        let changes: Vec<(usize, u32)> = (0..self.colors.face_count())
            .filter(|&f| self.colors.face_level(f) != Some(level))
            .map(|f| (f, 1u32 << level))
            .collect();
        self.resample(&changes)
    }

    /// Applies resolution changes as one step and re-indexes the samples.
    fn resample(&mut self, changes: &[(usize, u32)]) -> Result<Changed, Error> {
        if changes.is_empty() {
            return Ok(Changed::Nothing);
        }
        let change = self.colors.set_face_resolutions(changes)?;
        let faces = resampled(&change);
        // What the change left spare goes back, so the memory reported
        // is what the colours need.
        self.colors.shrink_to_fit();
        self.history.push(Step::Resolution(change));
        Ok(Changed::Layout(faces))
    }

    /// Undo (`back`) or redo one step.
    fn walk(&mut self, back: bool) -> Result<Changed, Error> {
        let step = if back {
            self.history.undo(&mut self.colors)?
        } else {
            self.history.redo(&mut self.colors)?
        };
        Ok(match step {
            None => Changed::Nothing,
            Some(Step::Paint(d)) => {
                Changed::Samples(d.runs().iter().flat_map(|&(s, n)| s..s + n).collect())
            }
            Some(Step::Resolution(r)) => {
                let faces = resampled(r);
                self.colors.shrink_to_fit();
                Changed::Layout(faces)
            }
        })
    }
}

/// The faces a resolution change resampled, sorted.
fn resampled(change: &ResolutionChange) -> Vec<usize> {
    let mut faces: Vec<usize> = change.faces().map(|(f, _, _)| f).collect();
    faces.sort_unstable();
    faces
}

/// A grid cell of about a typical brush: 1/50 of the bounding box's
/// diagonal (1 for an empty or degenerate mesh).
fn grid_cell(positions: &[Vec3], faces: &[[u32; 3]]) -> f32 {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for &v in faces.iter().flatten() {
        if let Some(&p) = positions.get(v as usize) {
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    let cell = (hi - lo).length() / 50.0;
    if cell.is_finite() && cell > 0.0 {
        cell
    } else {
        1.0
    }
}

/// Per vertex, the sum of its faces' normals weighted by area.
fn vertex_normals(faces: &[[u32; 3]], positions: &[Vec3]) -> Vec<Vec3> {
    let mut vertex = vec![Vec3::ZERO; positions.len()];
    for f in faces {
        let [a, b, c] = f.map(|v| positions[v as usize]);
        // The cross product's length is twice the area: area-weighted.
        let n = (b - a).cross(c - a);
        for &v in f {
            vertex[v as usize] += n;
        }
    }
    vertex
}

/// A sample's shading normal: the area-weighted vertex normals
/// interpolated at its site (what the page shades with).
fn normal_at(faces: &[[u32; 3]], vertex: &[Vec3], site: &Site) -> Vec3 {
    let Some(f) = faces.get(site.face as usize) else {
        return Vec3::ZERO;
    };
    let mut n = Vec3::ZERO;
    for (b, &v) in site.barycentric.iter().zip(f) {
        n += *b as f32 * vertex[v as usize];
    }
    n.normalize_or_zero()
}

/// The faces joined to `face` through shared edges, in increasing order.
fn connected_part(colors: &MeshColors, face: usize) -> Vec<usize> {
    let t = colors.topology();
    let mut seen = vec![false; t.faces().len()];
    let mut stack = vec![face];
    seen[face] = true;
    let mut part = Vec::new();
    while let Some(f) = stack.pop() {
        part.push(f);
        for &e in &t.face_edges()[f] {
            for &g in &t.edge_faces()[e as usize] {
                let g = g as usize;
                if g < seen.len() && !seen[g] {
                    seen[g] = true;
                    stack.push(g);
                }
            }
        }
    }
    part.sort_unstable();
    part
}

/// The distance from `q` to triangle `abc`: to its plane when `q`
/// projects inside it (on the inner side of all three edges), else to the
/// nearest edge.
fn distance_to_triangle(q: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let n = (b - a).cross(c - a);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(p, r)| (r - p).cross(q - p).dot(n) >= 0.0);
    let area2 = n.length();
    if inside && area2 > 0.0 {
        return (q - a).dot(n).abs() / area2;
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|&(p, r)| {
            let d = r - p;
            let t = if d.length_squared() > 0.0 {
                ((q - p).dot(d) / d.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (p + d * t).distance(q)
        })
        .fold(f32::INFINITY, f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Topology;

    /// A wavy `n × n` grid of quads, two triangles each, at mixed levels.
    fn wavy(n: u32) -> (Vec<Vec3>, MeshColors) {
        let (positions, faces) = crate::test_mesh::wavy_grid(n);
        let topology = Topology::new(positions.len(), &faces).unwrap();
        let levels: Vec<u32> = (0..faces.len()).map(|f| 1 << (f * 7 % 4)).collect();
        let mut colors = MeshColors::new(topology, &levels, 3).unwrap();
        for (i, x) in colors.samples_mut().iter_mut().enumerate() {
            *x = (i as f32 * 0.37).sin();
        }
        (positions, colors)
    }

    /// The samples a dab reaches through the faces are those an index of
    /// the samples themselves, built from scratch on the colours as they
    /// are now ([`Painter`]: every sample at its site), finds within the
    /// radius: the same samples at the same distances, positions and
    /// shading normals, bit for bit.
    fn assert_reach_as_sample_index(s: &PaintSession, what: &str) {
        let cell = grid_cell(&s.positions, s.colors.topology().faces());
        let painter = crate::Painter::new(&s.colors, &s.positions, cell).unwrap();
        let sites = s.colors.sites();
        let faces = s.colors.topology().faces();
        let mut found = Vec::new();
        for k in 0..20 {
            let centre = s.positions[(k * 37) % s.positions.len()];
            let radius = 0.02 + 0.05 * (k % 5) as f32;
            let mut expected = Vec::new();
            painter.for_each_within(centre, radius, |i, d| {
                let p = painter.sample_positions()[i];
                let n = normal_at(faces, &s.vertex_normals, &sites[i]);
                expected.push((
                    i,
                    d.to_bits(),
                    p.to_array().map(f32::to_bits),
                    n.to_array().map(f32::to_bits),
                ));
            });
            expected.sort_unstable();
            s.reach
                .within(&s.colors, &s.positions, centre, radius, &mut found);
            let got: Vec<_> = found
                .iter()
                .map(|h| {
                    let n = normal_at(faces, &s.vertex_normals, &h.site);
                    (
                        h.sample,
                        h.distance.to_bits(),
                        h.position.to_array().map(f32::to_bits),
                        n.to_array().map(f32::to_bits),
                    )
                })
                .collect();
            assert!(!expected.is_empty(), "{what}: dab {k} reaches nothing");
            assert_eq!(got, expected, "{what}: dab {k}");
        }
    }

    #[test]
    fn a_withdrawn_resolution_change_leaves_colours_history_and_log_as_before() {
        let (positions, colors) = wavy(6);
        let centre = positions[20];
        let mut s = PaintSession::new(positions, colors, vec![0.5; 3], 50, None).unwrap();
        let detail = |levels| Edit::Detail {
            center: centre,
            radius: 0.3,
            levels,
        };
        // Nothing to take back yet, nor after a paint edit.
        assert!(s.withdraw().is_err());
        let brush = Brush {
            mode: BrushMode::Mix,
            color: vec![1.0, 0.0, 0.0],
            first_channel: 0,
            strength: 1.0,
            hardness: 0.5,
            mirror_x: None,
            eye: None,
        };
        s.apply(Edit::Fill { face: 3, brush }).unwrap();
        assert!(s.withdraw().is_err());
        let before = (s.colors.clone(), s.log.len(), s.history.undo_len());
        // A new change: back to before it, with nothing to redo.
        let changed = s.apply(detail(1)).unwrap();
        assert!(matches!(changed, Changed::Layout(_)));
        assert_ne!(s.colors, before.0);
        assert_eq!(s.withdraw().unwrap(), changed);
        assert_eq!(
            (s.colors.clone(), s.log.len(), s.history.undo_len()),
            before
        );
        assert_eq!(s.history.redo_len(), 0);
        assert!(s.withdraw().is_err(), "taken back once only");
        // The undo of a lowering (a raise): back to lowered, redo kept.
        s.apply(detail(-1)).unwrap();
        let lowered = (s.colors.clone(), s.log.len());
        s.apply(Edit::Undo).unwrap();
        s.withdraw().unwrap();
        assert_eq!((s.colors.clone(), s.log.len()), lowered);
        assert_eq!((s.history.undo_len(), s.history.redo_len()), (2, 0));
        // A redo of a raise: back to undone, the redo still there.
        s.apply(detail(1)).unwrap();
        s.apply(Edit::Undo).unwrap();
        let undone = (s.colors.clone(), s.log.len(), s.history.redo_len());
        s.apply(Edit::Redo).unwrap();
        s.withdraw().unwrap();
        assert_eq!(
            (s.colors.clone(), s.log.len(), s.history.redo_len()),
            undone
        );
        // The log replays to the same colours.
        let again = PaintSession::replay(
            s.positions.clone(),
            wavy(6).1,
            vec![0.5; 3],
            50,
            None,
            &s.log,
        )
        .unwrap();
        assert_eq!(again.colors, s.colors);
    }

    #[test]
    fn a_dab_reaches_the_samples_an_index_of_them_finds_after_detail_undo_and_redo() {
        let (positions, colors) = wavy(8);
        let mut s = PaintSession::new(positions, colors, vec![0.5; 3], 50, None).unwrap();
        // A fixed pseudo-random sequence (SplitMix64-like, seed 7).
        let mut state = 7u64;
        let mut next = move || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        for step in 0..40 {
            let edit = match next() % 6 {
                0 | 1 => {
                    let v = s.positions[(next() % s.positions.len() as u64) as usize];
                    Edit::Detail {
                        center: v,
                        radius: 0.05 + 0.3 * (next() % 100) as f32 / 100.0,
                        levels: [1, 2, -1, -2][(next() % 4) as usize],
                    }
                }
                2 => Edit::Resolution {
                    level: (next() % 4) as u8,
                },
                3 | 4 => Edit::Undo,
                _ => Edit::Redo,
            };
            s.apply(edit.clone()).unwrap();
            assert_reach_as_sample_index(&s, &format!("step {step}, {edit:?}"));
        }
    }
}
