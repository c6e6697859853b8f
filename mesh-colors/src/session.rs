//! The painting system's document (Sec. 5.1): mesh colours being painted,
//! with the gestures a 3D paint tool offers — brush strokes (falloff
//! hardness, pen pressure, mix / add / multiply / erase, X-mirror, only
//! what the painter sees), fill of a connected part, the eyedropper, and
//! the detail brush that raises or lowers face resolution where it
//! passes — each one step of undo, and a log of edits that replays bit
//! for bit.
//!
//! A [`PaintSession`] owns the colours and everything derived from them
//! (the [`Painter`]'s spatial index, per-sample normals); a server or a
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

use glam::{DVec3, Vec3};

use crate::Error;
use crate::edit::ResolutionChange;
use crate::paint::Painter;
use crate::parallel::for_each_mut;
use crate::structure::{
    MeshColors, Site, lattice_points, move_segments, sample_position, samples_per_edge,
    samples_per_face,
};
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
    painter: Painter,
    /// Per sample, its shading normal (see [`normal_at`]).
    normals: Vec<Vec3>,
    /// Per vertex, the area-weighted sum of its faces' normals.
    vertex_normals: Vec<Vec3>,
    history: History,
    log: Vec<Edit>,
    open: Option<OpenStroke>,
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
        let cell = grid_cell(&positions, colors.topology().faces());
        let sites = colors.sites();
        let painter = Painter::with_sites(&colors, &positions, &sites, cell)?;
        let vertex_normals = vertex_normals(colors.topology().faces(), &positions);
        let faces = colors.topology().faces();
        let normals = sites
            .iter()
            .map(|s| normal_at(faces, &vertex_normals, s))
            .collect();
        Ok(Self {
            positions,
            colors,
            base,
            occluder,
            painter,
            normals,
            vertex_normals,
            history: History::new(history),
            log: Vec::new(),
            open: None,
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
        self.log.push(edit);
        Ok(changed)
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
        self.painter
            .for_each_within(dab.center, dab.radius, |i, d| hits.push((i, d)));
        // The grid's cells come in hash order: sort so the recorder, and
        // the list of changes, are the same on every run.
        hits.sort_unstable_by_key(|&(i, _)| i);
        for (i, d) in hits {
            if !self.seen(brush.eye, i) {
                continue;
            }
            let w = brush.weight(d, dab.radius, dab.pressure);
            self.blend(brush, i, w, recorder, changed)?;
        }
        Ok(())
    }

    /// Whether sample `i` is painted from `eye`: facing it and unhidden.
    fn seen(&self, eye: Option<Vec3>, i: usize) -> bool {
        let Some(eye) = eye else {
            return true;
        };
        let p = self.painter.sample_positions()[i];
        if self.normals[i].dot(eye - p) <= 0.0 {
            return false;
        }
        self.occluder.as_ref().is_none_or(|o| !o.blocked(eye, p))
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
        let before = Numbering::of(&self.colors);
        let change = self.colors.set_face_resolutions(changes)?;
        let faces = resampled(&change);
        self.reindex(&before, &Resampled::of(&self.colors, &change));
        self.history.push(Step::Resolution(change));
        Ok(Changed::Layout(faces))
    }

    /// Undo (`back`) or redo one step.
    fn walk(&mut self, back: bool) -> Result<Changed, Error> {
        let before = Numbering::of(&self.colors);
        let step = if back {
            self.history.undo(&mut self.colors)?
        } else {
            self.history.redo(&mut self.colors)?
        };
        let (changed, change) = match step {
            None => (Changed::Nothing, None),
            Some(Step::Paint(d)) => (
                Changed::Samples(d.runs().iter().flat_map(|&(s, n)| s..s + n).collect()),
                None,
            ),
            Some(Step::Resolution(r)) => (
                Changed::Layout(resampled(r)),
                Some(Resampled::of(&self.colors, r)),
            ),
        };
        if let Some(resampled) = change {
            self.reindex(&before, &resampled);
        }
        Ok(changed)
    }

    /// Brings what depends on the sample numbering (the brush's grid, the
    /// samples' positions and normals) to the numbering after `change`,
    /// which left the colours numbered as `before` said. The samples of
    /// the primitives `change` resampled get new positions and normals;
    /// the others move to their new numbers (one pass, as the colours'
    /// samples moved); the grid is indexed again (two passes, no
    /// geometry). The result equals a session built on these colours
    /// from scratch. Also gives back the spare capacity the change left,
    /// so the memory reported is what the colours need.
    fn reindex(&mut self, before: &Numbering, resampled: &Resampled) {
        self.colors.shrink_to_fit();
        let mc = &self.colors;
        let Resampled { edge_new, face_new } = resampled;
        let segments = before.segments(mc, edge_new, face_new);
        let total = mc.sample_count();
        let cell = self.painter.cell();
        let painter = std::mem::replace(
            &mut self.painter,
            Painter::from_positions(Vec::new(), cell, mc.channels()),
        );
        let mut positions = painter.into_positions();
        move_segments(&mut positions, 1, &segments, total);
        move_segments(&mut self.normals, 1, &segments, total);
        // Each resampled primitive's samples on their own (on all threads
        // for a large change), written in place: no list of them to
        // gather and copy after.
        let (vertices, vertex_normals) = (&self.positions, &self.vertex_normals);
        let faces = mc.topology().faces();
        // Each resampled edge's and face's samples are one run of the new
        // numbering, the runs in increasing order (edges before faces):
        // each gets its own part of the positions and normals to write.
        let mut runs: Vec<(Run, usize, usize)> = (0..edge_new.len())
            .filter(|&e| edge_new[e])
            .map(|e| {
                let n = samples_per_edge(1 << mc.edge_level[e]) as usize;
                (Run::Edge(e), mc.edge_offset[e], n)
            })
            .collect();
        runs.extend((0..face_new.len()).filter(|&f| face_new[f]).map(|f| {
            let n = samples_per_face(1 << mc.face_level[f]) as usize;
            (Run::Face(f), mc.face_offset[f], n)
        }));
        let samples = runs.iter().map(|r| r.2).sum();
        let mut jobs = Vec::with_capacity(runs.len());
        let (mut rest_p, mut rest_n) = (&mut positions[..], &mut self.normals[..]);
        let mut done = 0;
        for (run, start, len) in runs {
            let skip = start.saturating_sub(done);
            let (Some((_, p)), Some((_, n))) = (
                std::mem::take(&mut rest_p).split_at_mut_checked(skip),
                std::mem::take(&mut rest_n).split_at_mut_checked(skip),
            ) else {
                break;
            };
            let (Some((mine_p, p)), Some((mine_n, n))) =
                (p.split_at_mut_checked(len), n.split_at_mut_checked(len))
            else {
                break;
            };
            (rest_p, rest_n) = (p, n);
            done = start + len;
            jobs.push((run, start, mine_p, mine_n));
        }
        for_each_mut(&mut jobs, samples, |(run, start, p, n)| {
            if let Run::Face(f) = *run
                && place_face(mc, f, vertices, vertex_normals, p, n)
            {
                return;
            }
            let mut place = |i: usize, site: Site| {
                let Some(k) = i.checked_sub(*start).filter(|&k| k < p.len()) else {
                    return;
                };
                p[k] = site.position(mc.topology(), vertices).map_or_else(
                    || vertices.get(i).copied().unwrap_or_default(),
                    |x| x.as_vec3(),
                );
                n[k] = normal_at(faces, vertex_normals, &site);
            };
            match *run {
                Run::Edge(e) => mc.edge_sites(e, &mut place),
                Run::Face(f) => mc.face_sites(f, &mut place),
            }
        });
        // No shrink_to_fit: the spare capacity a raise leaves serves the
        // next one without another copy (these are not the colours'
        // reported memory).
        self.painter = Painter::from_positions(positions, cell, mc.channels());
    }
}

/// A resampled primitive whose samples [`PaintSession::reindex`] places.
#[derive(Clone, Copy)]
enum Run {
    Edge(usize),
    Face(usize),
}

/// Which edges and faces a resolution change (or its undo) resampled.
struct Resampled {
    edge_new: Vec<bool>,
    face_new: Vec<bool>,
}

impl Resampled {
    fn of(colors: &MeshColors, change: &ResolutionChange) -> Self {
        let mut edge_new = vec![false; colors.edge_level.len()];
        for (e, _, _) in change.edges() {
            edge_new[e] = true;
        }
        let mut face_new = vec![false; colors.face_level.len()];
        for (f, _, _) in change.faces() {
            face_new[f] = true;
        }
        Self { edge_new, face_new }
    }
}

/// Where the edges' and faces' samples started before a resolution change
/// (the vertices' never move): what [`PaintSession::reindex`] moves the
/// per-sample data from.
struct Numbering {
    edge_offset: Vec<usize>,
    face_offset: Vec<usize>,
}

impl Numbering {
    fn of(colors: &MeshColors) -> Self {
        Self {
            edge_offset: colors.edge_offset.clone(),
            face_offset: colors.face_offset.clone(),
        }
    }

    /// The moves `(old first sample, new first sample, samples, kept)`
    /// from this numbering to that of `colors`, in layout order, for
    /// `move_segments`; resampled primitives (`edge_new`, `face_new`) are
    /// not kept.
    fn segments(
        &self,
        colors: &MeshColors,
        edge_new: &[bool],
        face_new: &[bool],
    ) -> Vec<(usize, usize, usize, bool)> {
        let edges = (0..edge_new.len()).map(|e| {
            let n = samples_per_edge(1 << colors.edge_level[e]) as usize;
            (self.edge_offset[e], colors.edge_offset[e], n, !edge_new[e])
        });
        let faces = (0..face_new.len()).map(|f| {
            let n = samples_per_face(1 << colors.face_level[f]) as usize;
            (self.face_offset[f], colors.face_offset[f], n, !face_new[f])
        });
        edges.chain(faces).collect()
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

/// Face `f`'s interior samples' positions and normals into `p` and `n`
/// (in the order of its samples): what [`Site::position`] and
/// [`normal_at`] give, the same sums in the same order, with the corners
/// read once per face instead of per sample. False (nothing written)
/// when a corner is missing.
fn place_face(
    mc: &MeshColors,
    f: usize,
    vertices: &[Vec3],
    vertex_normals: &[Vec3],
    p: &mut [Vec3],
    n: &mut [Vec3],
) -> bool {
    let (Some(face), Some(r)) = (mc.topology().faces().get(f), mc.face_resolution(f)) else {
        return false;
    };
    let corner = |k: usize| {
        let v = face[k] as usize;
        Some((vertices.get(v)?.as_dvec3(), *vertex_normals.get(v)?))
    };
    let (Some(c0), Some(c1), Some(c2)) = (corner(0), corner(1), corner(2)) else {
        return false;
    };
    let corners = [c0, c1, c2];
    let mut slots = p.iter_mut().zip(n.iter_mut());
    for i in 1..r {
        for j in 1..r - i {
            let b = sample_position(r, i, j);
            let mut q = DVec3::ZERO;
            let mut m = Vec3::ZERO;
            for (&b, &(cp, _)) in b.iter().zip(&corners) {
                q += b * cp;
            }
            for (&b, &(_, cn)) in b.iter().zip(&corners) {
                m += b as f32 * cn;
            }
            if let Some((ps, ns)) = slots.next() {
                *ps = q.as_vec3();
                *ns = m.normalize_or_zero();
            }
        }
    }
    true
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
        let mut positions = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
                positions.push(Vec3::new(u, v, 0.1 * (7.0 * u).sin() * (5.0 * v).cos()));
            }
        }
        let at = |x: u32, y: u32| y * (n + 1) + x;
        let mut faces = Vec::new();
        for y in 0..n {
            for x in 0..n {
                faces.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
                faces.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
            }
        }
        let topology = Topology::new(positions.len(), &faces).unwrap();
        let levels: Vec<u32> = (0..faces.len()).map(|f| 1 << (f * 7 % 4)).collect();
        let mut colors = MeshColors::new(topology, &levels, 3).unwrap();
        for (i, x) in colors.samples_mut().iter_mut().enumerate() {
            *x = (i as f32 * 0.37).sin();
        }
        (positions, colors)
    }

    /// What a session built from scratch on the colours indexes.
    fn assert_index_as_new(s: &PaintSession, what: &str) {
        let fresh = PaintSession::new(
            s.positions.clone(),
            s.colors.clone(),
            s.base.clone(),
            1,
            None,
        )
        .unwrap();
        let bits = |v: &[Vec3]| -> Vec<[u32; 3]> {
            v.iter().map(|p| p.to_array().map(f32::to_bits)).collect()
        };
        assert_eq!(
            bits(s.painter.sample_positions()),
            bits(fresh.painter.sample_positions()),
            "{what}: positions"
        );
        assert_eq!(bits(&s.normals), bits(&fresh.normals), "{what}: normals");
        for k in 0..20 {
            let centre = s.positions[(k * 37) % s.positions.len()];
            let radius = 0.02 + 0.05 * (k % 5) as f32;
            let hits = |p: &Painter| {
                let mut v = Vec::new();
                p.for_each_within(centre, radius, |i, d| v.push((i, d.to_bits())));
                v.sort_unstable();
                v
            };
            assert_eq!(hits(&s.painter), hits(&fresh.painter), "{what}: dab {k}");
        }
    }

    #[test]
    fn the_index_after_detail_undo_and_redo_equals_one_built_from_scratch() {
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
            assert_index_as_new(&s, &format!("step {step}, {edit:?}"));
        }
    }
}
