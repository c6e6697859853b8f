//! Editing coloured meshes without resampling (Sec. 3.3): exact 1-to-4
//! subdivision, deleting and adding faces, and changing face resolutions
//! (Sec. 3.2, the painting system's "on-the-fly adjustment of local
//! resolution", Sec. 5.1). Vertex moves need nothing: samples live on
//! primitives, not at positions.
//!
//! Topology edits build a new sample array and copy every sample they keep
//! (the indices of Fig. 10 change, the values do not): the cost is a copy
//! of the array, and only the primitives an edit touches get new values.
//! [`MeshColors::set_face_resolutions`] works in place: it resamples only
//! the faces it is given and the edges whose resolution follows them, and
//! returns a [`ResolutionChange`] that undoes it exactly.

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use crate::filter::{FINEST, Store, edge_point, eval, lattice, triangle};
use crate::parallel::map_ordered;
use crate::structure::{
    MeshColors, interior_index, lattice_points, level_of, move_segments, sample_position,
    samples_per_edge, samples_per_face,
};
use crate::topology::NO_FACE;
use crate::topology::Topology;
use crate::{Error, MAX_CHANNELS};

/// Corners of the four children of a face, as lattice points of the
/// parent at resolution 2: `v0, v1, v2` at `2·e_k`, midpoints between.
const CHILD_CORNERS: [[[u32; 3]; 3]; 4] = [
    [[2, 0, 0], [1, 1, 0], [1, 0, 1]],
    [[1, 1, 0], [0, 2, 0], [0, 1, 1]],
    [[1, 0, 1], [0, 1, 1], [0, 0, 2]],
    [[0, 1, 1], [1, 0, 1], [1, 1, 0]],
];

/// The result of [`MeshColors::subdivide`].
#[derive(Debug, Clone, PartialEq)]
pub struct Subdivided {
    /// The colours on the subdivided mesh: each face of resolution `R` is
    /// four faces of `R/2`, every sample at the same place with the same
    /// value.
    pub colors: MeshColors,
    /// The new faces: face `f`'s children are `4f .. 4f + 4` (corner,
    /// corner, corner, centre; see [`child_of`]).
    pub faces: Vec<[u32; 3]>,
    /// New vertex `V + e` is the midpoint of old edge `e`, these vertices.
    pub midpoints: Vec<[u32; 2]>,
}

impl Subdivided {
    /// Vertex positions of the subdivided mesh: the old ones, then edge
    /// midpoints (a caller applying a smoothing scheme moves them after;
    /// the colours do not depend on positions).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if `old` has fewer positions than the
    /// mesh had vertices.
    pub fn positions(&self, old: &[Vec3]) -> Result<Vec<Vec3>, Error> {
        let need = self.colors.topology.vertex_count - self.midpoints.len();
        if old.len() < need {
            return Err(Error::ChannelMismatch {
                what: "vertex positions",
                expected: need,
                got: old.len(),
            });
        }
        let mut p = old[..need].to_vec();
        p.extend(
            self.midpoints
                .iter()
                .map(|&[a, b]| 0.5 * (old[a as usize] + old[b as usize])),
        );
        Ok(p)
    }
}

/// Which child of a subdivided face holds the point with parent
/// barycentrics `b`, and its barycentrics there (Fig. 5: the texture
/// coordinates that keep lookups where they were).
pub fn child_of(b: [f32; 3]) -> (usize, [f32; 3]) {
    if b[0] >= 0.5 {
        let (c1, c2) = (2.0 * b[1], 2.0 * b[2]);
        (0, [1.0 - c1 - c2, c1, c2])
    } else if b[1] >= 0.5 {
        let (c0, c2) = (2.0 * b[0], 2.0 * b[2]);
        (1, [c0, 1.0 - c0 - c2, c2])
    } else if b[2] >= 0.5 {
        let (c0, c1) = (2.0 * b[0], 2.0 * b[1]);
        (2, [c0, c1, 1.0 - c0 - c1])
    } else {
        (3, [1.0 - 2.0 * b[0], 1.0 - 2.0 * b[1], 1.0 - 2.0 * b[2]])
    }
}

impl MeshColors {
    /// 1-to-4 subdivision of every face, carrying the colours over exactly
    /// (Sec. 3.3): a face of resolution `R` becomes four of `R/2`, edge
    /// samples split between the halves of their edge, the middle edge
    /// sample becomes the new vertex's colour. Nothing is interpolated.
    ///
    /// # Errors
    /// [`Error::CannotSubdivide`] naming a face of resolution 1 (its four
    /// children would need samples it does not have).
    pub fn subdivide(&self) -> Result<Subdivided, Error> {
        if let Some(f) = self.face_level.iter().position(|&n| n == 0) {
            return Err(Error::CannotSubdivide { face: f });
        }
        let t = &self.topology;
        let v0 = t.vertex_count as u32;
        let mut faces = Vec::with_capacity(4 * t.faces.len());
        let mut levels = Vec::with_capacity(4 * t.faces.len());
        for (f, face) in t.faces.iter().enumerate() {
            let m = t.face_edges[f].map(|e| v0 + e);
            let [a, b, c] = *face;
            faces.extend([
                [a, m[0], m[2]],
                [m[0], b, m[1]],
                [m[2], m[1], c],
                [m[1], m[2], m[0]],
            ]);
            levels.extend([self.face_level[f] - 1; 4]);
        }
        let topology = Topology::new(t.vertex_count + t.edges.len(), &faces)?;
        let mut colors = MeshColors::with_levels(topology, levels, self.channels)?;
        let c = self.channels;
        let mut value = vec![0.0f32; c];
        for f in 0..t.faces.len() {
            let lf = self.face_level[f];
            for (child, corners) in CHILD_CORNERS.iter().enumerate() {
                let g = 4 * f + child;
                for a in lattice_points(1 << (lf - 1)) {
                    let Some(i) = colors.lattice_index(g, a) else {
                        continue;
                    };
                    let parent =
                        [0, 1, 2].map(|m| (0..3).map(|k| a[k] * corners[k][m]).sum::<u32>());
                    value.fill(0.0);
                    lattice(self, f, FINEST, lf, parent, 1.0, false, &mut value);
                    colors.sample_at_mut(i).copy_from_slice(&value);
                }
            }
        }
        Ok(Subdivided {
            colors,
            faces,
            midpoints: t.edges.clone(),
        })
    }

    /// The same colours without the faces `remove` (their interior samples
    /// go; vertices stay; an edge left with one face keeps its samples,
    /// refined by interpolation if that face is finer, which leaves its
    /// colours unchanged).
    ///
    /// # Errors
    /// [`Error::MissingFace`].
    pub fn delete_faces(&self, remove: &[usize]) -> Result<MeshColors, Error> {
        let n = self.face_count();
        let mut gone = vec![false; n];
        for &f in remove {
            if f >= n {
                return Err(Error::MissingFace { face: f, count: n });
            }
            gone[f] = true;
        }
        let keep: Vec<usize> = (0..n).filter(|&f| !gone[f]).collect();
        let faces: Vec<[u32; 3]> = keep.iter().map(|&f| self.topology.faces[f]).collect();
        let levels = keep.iter().map(|&f| self.face_level[f]).collect();
        let origin: Vec<Option<usize>> = keep.iter().map(|&f| Some(f)).collect();
        let topology = Topology::new(self.topology.vertex_count, &faces)?;
        self.rebuild(topology, levels, &origin)
    }

    /// The same colours with `faces` added at `resolutions`, over
    /// `vertex_count` vertices (at least the current count; new vertices
    /// start at zero). The new faces' edge and interior samples start as
    /// the linear interpolation of their vertex colours; existing samples
    /// are kept (an existing edge that a coarser new face now shares is
    /// sub-sampled to its resolution, the continuity rule).
    ///
    /// # Errors
    /// As for [`Topology::new`] and [`MeshColors::new`].
    pub fn add_faces(
        &self,
        faces: &[[u32; 3]],
        resolutions: &[u32],
        vertex_count: usize,
    ) -> Result<MeshColors, Error> {
        if resolutions.len() != faces.len() {
            return Err(Error::ResolutionCount {
                got: resolutions.len(),
                faces: faces.len(),
            });
        }
        let n = self.face_count();
        let mut all = self.topology.faces.clone();
        all.extend_from_slice(faces);
        let mut levels = self.face_level.clone();
        for (k, &r) in resolutions.iter().enumerate() {
            levels.push(level_of(n + k, r)?);
        }
        let origin: Vec<Option<usize>> = (0..all.len()).map(|f| (f < n).then_some(f)).collect();
        let topology = Topology::new(vertex_count.max(self.topology.vertex_count), &all)?;
        self.rebuild(topology, levels, &origin)
    }

    /// The same colours with face `face` at resolution `resolution`: only
    /// that face is resampled (by linear filtering of its old samples), and
    /// those of its edges whose resolution (the lowest of their faces)
    /// changes, which keeps them continuous. Every other sample is kept.
    ///
    /// # Errors
    /// [`Error::MissingFace`], [`Error::BadResolution`].
    pub fn set_face_resolution(&self, face: usize, resolution: u32) -> Result<MeshColors, Error> {
        if face >= self.face_count() {
            return Err(Error::MissingFace {
                face,
                count: self.face_count(),
            });
        }
        let mut levels = self.face_level.clone();
        levels[face] = level_of(face, resolution)?;
        let origin: Vec<Option<usize>> = (0..self.face_count()).map(Some).collect();
        self.rebuild(self.topology.clone(), levels, &origin)
    }

    /// New colours on `topology` at `levels`, new face `g` coming from old
    /// face `origin[g]` (or new). Vertices keep their index.
    fn rebuild(
        &self,
        topology: Topology,
        levels: Vec<u8>,
        origin: &[Option<usize>],
    ) -> Result<MeshColors, Error> {
        let mut out = MeshColors::with_levels(topology, levels, self.channels)?;
        let c = self.channels;
        let shared = self.topology.vertex_count.min(out.topology.vertex_count);
        out.samples[..shared * c].copy_from_slice(&self.samples[..shared * c]);
        let old_edges: HashMap<[u32; 2], usize> = self
            .topology
            .edges
            .iter()
            .enumerate()
            .map(|(e, &k)| (k, e))
            .collect();
        let mut value = vec![0.0f32; c];
        for e in 0..out.topology.edges.len() {
            let key = out.topology.edges[e];
            let le = out.edge_level[e];
            let first = out.edge_offset[e];
            match old_edges.get(&key) {
                Some(&old) if self.edge_level[old] == le => {
                    let len = ((1usize << le) - 1) * c;
                    let from = self.edge_offset[old] * c;
                    out.samples[first * c..first * c + len]
                        .copy_from_slice(&self.samples[from..from + len]);
                }
                Some(&old) => {
                    // Evaluate the old edge's function at the new positions:
                    // copies when coarser, interpolation when finer.
                    let lp = le.max(self.edge_level[old]);
                    for s in 1..1u32 << le {
                        value.fill(0.0);
                        edge_point(
                            self,
                            old,
                            FINEST,
                            lp,
                            s << (lp - le),
                            1.0,
                            false,
                            &mut value,
                        );
                        out.sample_at_mut(first + s as usize - 1)
                            .copy_from_slice(&value);
                    }
                }
                None => {
                    let r = 1u32 << le;
                    for s in 1..r {
                        let t = s as f32 / r as f32;
                        for (ch, v) in value.iter_mut().enumerate() {
                            let (a, b) = (
                                out.samples[key[0] as usize * c + ch],
                                out.samples[key[1] as usize * c + ch],
                            );
                            *v = (1.0 - t) * a + t * b;
                        }
                        out.sample_at_mut(first + s as usize - 1)
                            .copy_from_slice(&value);
                    }
                }
            }
        }
        for g in 0..out.face_level.len() {
            let r = 1u32 << out.face_level[g];
            let first = out.face_offset[g];
            let count = crate::samples_per_face(r) as usize;
            match origin.get(g).copied().flatten() {
                Some(f) if self.face_level[f] == out.face_level[g] => {
                    let from = self.face_offset[f] * c;
                    out.samples[first * c..(first + count) * c]
                        .copy_from_slice(&self.samples[from..from + count * c]);
                }
                Some(f) => {
                    for i in 1..r {
                        for j in 1..r - i {
                            let b = sample_position(r, i, j).map(|x| x as f32);
                            eval(self, f, b, FINEST, false, &mut value);
                            let at = first + crate::structure::interior_index(r, i, j);
                            out.sample_at_mut(at).copy_from_slice(&value);
                        }
                    }
                }
                None => {
                    let face = out.topology.faces[g];
                    for i in 1..r {
                        for j in 1..r - i {
                            let b = sample_position(r, i, j);
                            for (ch, v) in value.iter_mut().enumerate() {
                                *v = (0..3)
                                    .map(|k| {
                                        b[k] * f64::from(out.vertex_at(face[k] as usize, 0)[ch])
                                    })
                                    .sum::<f64>() as f32;
                            }
                            let at = first + crate::structure::interior_index(r, i, j);
                            out.sample_at_mut(at).copy_from_slice(&value);
                        }
                    }
                }
            }
        }
        Ok(out)
    }
}

/// What one [`MeshColors::set_face_resolutions`] did, and all an undo
/// needs: the resolution and the samples, before the change, of every face
/// and edge it resampled — nothing else (Sec. 5.1's undo: deltas, never
/// whole copies).
///
/// Undo is [`MeshColors::revert_resolutions`], which restores those
/// samples bit for bit; redo is `set_face_resolutions(&change.requests())`
/// on the reverted colours, which is deterministic and so gives the same
/// samples (and an equal record) again.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolutionChange {
    channels: usize,
    /// The validated requests, in order: face and level.
    requests: Vec<(u32, u8)>,
    /// Resampled faces in the order first touched: face, level before,
    /// level after.
    faces: Vec<(u32, u8, u8)>,
    /// Their interior samples before, concatenated in `faces` order.
    face_values: Vec<f32>,
    /// Resampled edges (their resolution changed): edge, level before,
    /// level after.
    edges: Vec<(u32, u8, u8)>,
    /// Their samples before, concatenated in `edges` order.
    edge_values: Vec<f32>,
}

impl ResolutionChange {
    /// The requests as given (face, resolution), for redo.
    pub fn requests(&self) -> Vec<(usize, u32)> {
        self.requests
            .iter()
            .map(|&(f, n)| (f as usize, 1u32 << n))
            .collect()
    }

    /// The faces that were resampled, each once: `(face, resolution
    /// before, resolution after)`. A face asked for at its own resolution
    /// is not resampled and not listed.
    pub fn faces(&self) -> impl ExactSizeIterator<Item = (usize, u32, u32)> + '_ {
        self.faces
            .iter()
            .map(|&(f, a, b)| (f as usize, 1u32 << a, 1u32 << b))
    }

    /// The edges whose resolution changed (the lowest of their faces,
    /// Sec. 3.2), each once: `(edge, resolution before, resolution after)`.
    pub fn edges(&self) -> impl ExactSizeIterator<Item = (usize, u32, u32)> + '_ {
        self.edges
            .iter()
            .map(|&(e, a, b)| (e as usize, 1u32 << a, 1u32 << b))
    }

    /// Whether nothing changed (every request was a face's own resolution).
    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Heap bytes this record holds (its capacity, not just its length).
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + self.requests.capacity() * std::mem::size_of::<(u32, u8)>()
            + (self.faces.capacity() + self.edges.capacity()) * std::mem::size_of::<(u32, u8, u8)>()
            + (self.face_values.capacity() + self.edge_values.capacity()) * 4
    }
}

/// New samples of some primitives (faces or edges), by index: a slot per
/// primitive, so that reads during a batch cost an array access.
struct Overlay {
    slot: Vec<u32>,
    keys: Vec<usize>,
    values: Vec<Vec<f32>>,
}

impl Overlay {
    const NONE: u32 = u32::MAX;

    fn new(n: usize) -> Self {
        Self {
            slot: vec![Self::NONE; n],
            keys: Vec::new(),
            values: Vec::new(),
        }
    }

    #[inline]
    fn get(&self, i: usize) -> Option<&[f32]> {
        match self.slot[i] {
            Self::NONE => None,
            k => Some(&self.values[k as usize]),
        }
    }

    #[inline]
    fn contains(&self, i: usize) -> bool {
        self.slot[i] != Self::NONE
    }

    /// Sets (or replaces) primitive `i`'s samples.
    fn insert(&mut self, i: usize, values: Vec<f32>) {
        match self.slot[i] {
            Self::NONE => {
                self.slot[i] = self.keys.len() as u32;
                self.keys.push(i);
                self.values.push(values);
            }
            k => self.values[k as usize] = values,
        }
    }
}

/// One face's resolution change within a batch, planned before any value
/// is computed.
struct Step {
    face: usize,
    /// The face's level before this step.
    from: u8,
    /// The face's level after it.
    to: u8,
    /// Each local edge: `(edge, level before this step, level after)`.
    plan: [(usize, u8, u8); 3],
    /// The wave this step is computed in: after every earlier step that
    /// wrote what it reads, and not before any earlier step that read what
    /// it writes.
    wave: u32,
}

impl MeshColors {
    /// The steps of a batch with their edge plans and waves, the record's
    /// old values taken at each primitive's first change, and whether a
    /// face was lowered. Leaves the levels as they were (the plan needs the
    /// levels each step sees, so they are set as the batch would, then put
    /// back for the values to be computed wave by wave).
    fn plan_steps(&mut self, record: &mut ResolutionChange) -> (Vec<Step>, bool) {
        let c = self.channels;
        // Per face and edge: 1 + the wave of the last step that wrote it
        // (0: none yet, so not yet in the record), and the latest wave
        // that read it.
        let mut face_written = vec![0u32; self.face_level.len()];
        let mut face_read = vec![0u32; self.face_level.len()];
        let mut edge_written = vec![0u32; self.edge_level.len()];
        let mut edge_read = vec![0u32; self.edge_level.len()];
        let mut steps = Vec::new();
        let mut lowered = false;
        for &(f, n1) in &record.requests {
            let f = f as usize;
            let n0 = self.face_level[f];
            if n0 == n1 {
                continue;
            }
            lowered |= n1 < n0;
            let plan = self.edge_plan(f, n1);
            // A step reads its face and its three edges, and writes the
            // face and the edges whose level changes.
            let mut wave = face_written[f].max(face_read[f]);
            for &(e, le0, le1) in &plan {
                wave = wave.max(edge_written[e]);
                if le0 != le1 {
                    wave = wave.max(edge_read[e]);
                }
            }
            face_read[f] = face_read[f].max(wave);
            if face_written[f] == 0 {
                record.faces.push((f as u32, n0, n1));
                let at = self.face_offset[f] * c;
                let len = samples_per_face(1 << n0) as usize * c;
                record
                    .face_values
                    .extend_from_slice(&self.samples[at..at + len]);
            }
            face_written[f] = wave + 1;
            self.face_level[f] = n1;
            for &(e, le0, le1) in &plan {
                edge_read[e] = edge_read[e].max(wave);
                if le0 == le1 {
                    continue;
                }
                if edge_written[e] == 0 {
                    record.edges.push((e as u32, le0, le1));
                    let at = self.edge_offset[e] * c;
                    let len = samples_per_edge(1 << le0) as usize * c;
                    record
                        .edge_values
                        .extend_from_slice(&self.samples[at..at + len]);
                }
                edge_written[e] = wave + 1;
                self.edge_level[e] = le1;
            }
            steps.push(Step {
                face: f,
                from: n0,
                to: n1,
                plan,
                wave,
            });
        }
        for step in steps.iter().rev() {
            for &(e, le0, le1) in step.plan.iter().rev() {
                if le0 != le1 {
                    self.edge_level[e] = le0;
                }
            }
            self.face_level[step.face] = step.from;
        }
        (steps, lowered)
    }

    /// Face `f`'s local edges: `(edge, level now, level once `f` is at
    /// level `n1`)` — the lowest level of an edge's faces (Sec. 3.2).
    fn edge_plan(&self, f: usize, n1: u8) -> [(usize, u8, u8); 3] {
        self.topology.face_edges[f].map(|e| {
            let e = e as usize;
            let after = self.topology.edge_faces[e]
                .iter()
                .filter(|&&g| g != NO_FACE)
                .map(|&g| {
                    if g as usize == f {
                        n1
                    } else {
                        self.face_level[g as usize]
                    }
                })
                .min()
                .unwrap_or(n1);
            (e, self.edge_level[e], after)
        })
    }
}

/// The new samples of one step's face and of its edges whose level
/// changes (`None` for the others), computed from `staged`, which holds
/// the colours as the step sees them.
fn resample_step(staged: &Staged<'_>, step: &Step) -> (Vec<f32>, [Option<Vec<f32>>; 3]) {
    let c = staged.mc.channels;
    let mut value = [0.0f32; MAX_CHANNELS];
    let value = &mut value[..c];
    let r = 1u32 << step.to;
    let mut fv = Vec::with_capacity(samples_per_face(r) as usize * c);
    if step.to > staged.mc.face_level[step.face] {
        raise_face(staged, step, &mut fv, value);
    } else {
        for i in 1..r {
            for j in 1..r - i {
                let b = sample_position(r, i, j).map(|x| x as f32);
                eval(staged, step.face, b, FINEST, false, value);
                fv.extend_from_slice(value);
            }
        }
    }
    let mut ev: [Option<Vec<f32>>; 3] = [None, None, None];
    for (slot, &(e, le0, le1)) in ev.iter_mut().zip(&step.plan) {
        if le0 == le1 {
            continue;
        }
        let lp = le0.max(le1);
        let mut v = Vec::with_capacity(samples_per_edge(1 << le1) as usize * c);
        for s in 1..1u32 << le1 {
            value.fill(0.0);
            edge_point(staged, e, FINEST, lp, s << (lp - le1), 1.0, false, value);
            v.extend_from_slice(value);
        }
        *slot = Some(v);
    }
    (fv, ev)
}

/// A raised face's new samples into `fv`: what `eval` at each new
/// sample's barycentrics gives (the linear filter of the face's current
/// colours), the same products summed in the same order, bit for bit.
/// The new sample `(i, j)` of resolution `R = r·2^d` has the barycentrics
/// `(i, j, R − i − j) / R`, exact in `f32` (dyadic), so `triangle` gives
/// the lattice triangle and weights `eval` computes; a triangle of three
/// interior samples (most of them) is read straight from the face's
/// block, any other point through `lattice`.
fn raise_face(staged: &Staged<'_>, step: &Step, fv: &mut Vec<f32>, value: &mut [f32]) {
    let c = staged.mc.channels;
    let f = step.face;
    // The level `eval` reads the face at: the one the batch left it at.
    let from = staged.mc.face_level[f];
    let (r, big) = (1u32 << from, 1u32 << step.to);
    let scale = 1.0 / big as f32;
    let old = staged.face_block(f, r);
    for i in 1..big {
        for j in 1..big - i {
            let b = [i, j, big - i - j].map(|x| x as f32 * scale);
            let (pts, ws) = triangle(b, r);
            value.fill(0.0);
            if pts.iter().all(|p| p[0] >= 1 && p[1] >= 1 && p[2] >= 1) {
                for (p, &w) in pts.iter().zip(&ws) {
                    let at = interior_index(r, p[0], p[1]) * c;
                    for (o, &x) in value.iter_mut().zip(&old[at..at + c]) {
                        *o += w * x;
                    }
                }
            } else {
                for (p, &w) in pts.iter().zip(&ws) {
                    lattice(staged, f, FINEST, from, *p, w, false, value);
                }
            }
            fv.extend_from_slice(value);
        }
    }
}

/// The mesh colours as a batch sees them between two of its steps: levels
/// already updated in `mc`, the new samples of resampled faces and edges
/// in the overlays, every other sample where it was.
struct Staged<'a> {
    mc: &'a MeshColors,
    faces: &'a Overlay,
    edges: &'a Overlay,
}

impl Staged<'_> {
    /// Face `f`'s interior samples at its current resolution `r`.
    fn face_block(&self, f: usize, r: u32) -> &[f32] {
        let len = samples_per_face(r) as usize * self.mc.channels;
        match self.faces.get(f) {
            Some(values) => &values[..len],
            None => {
                let at = self.mc.face_offset[f] * self.mc.channels;
                &self.mc.samples[at..at + len]
            }
        }
    }
}

impl Store for Staged<'_> {
    #[inline]
    fn colors(&self) -> &MeshColors {
        self.mc
    }
    #[inline]
    fn vertex_at(&self, v: usize, level: u8) -> &[f32] {
        self.mc.vertex_at(v, level)
    }
    #[inline]
    fn edge_at(&self, e: usize, level: u8, s: u32) -> &[f32] {
        let c = self.mc.channels;
        match self.edges.get(e) {
            Some(values) => &values[(s as usize - 1) * c..s as usize * c],
            None => self.mc.edge_at(e, level, s),
        }
    }
    #[inline]
    fn face_at(&self, f: usize, level: u8, idx: usize) -> &[f32] {
        let c = self.mc.channels;
        match self.faces.get(f) {
            Some(values) => &values[idx * c..(idx + 1) * c],
            None => self.mc.face_at(f, level, idx),
        }
    }
}

impl MeshColors {
    /// Changes the resolution of many faces in place (Sec. 3.2 mixed
    /// resolutions; the "on-the-fly adjustment of local resolution" of the
    /// painting system, Sec. 5.1): `changes` is a list of `(face,
    /// resolution)`, each resolution a power of two up to
    /// `2^`[`crate::MAX_LEVEL`].
    ///
    /// The result is exactly (bit for bit, samples and layout) that of
    /// calling [`MeshColors::set_face_resolution`] for each pair in order:
    /// a face is resampled by linear filtering of its current colours, and
    /// an edge whose resolution (the lowest of its faces) changes is
    /// resampled from its current samples (copies when coarser, linear
    /// interpolation when finer), which keeps shared edges continuous. A
    /// face listed twice is resampled twice. Every other sample keeps its
    /// value.
    ///
    /// **Cost**: the resampling is proportional to the samples of the
    /// faces and edges touched; the layout of Fig. 10 stays contiguous, so
    /// the samples after the first touched primitive move once (one
    /// `memcpy`-speed pass, not one per face), and the per-edge and
    /// per-face indices after it are renumbered. The steps are resampled
    /// in waves: a step joins the first wave after every earlier step that
    /// changed its face or edges, and not before an earlier step that read
    /// what it changes; a wave's steps (the faces of a detail brush fall
    /// into a handful of waves) are resampled on all threads with the
    /// `rayon` feature, with the same result at any thread count.
    ///
    /// Returns what undoes it ([`MeshColors::revert_resolutions`]).
    ///
    /// # Errors
    /// Checked before anything changes (an error leaves the colours as
    /// they were): [`Error::MissingFace`] naming the first face out of
    /// range, [`Error::BadResolution`] naming the face whose resolution is
    /// not a power of two in `1..=2^MAX_LEVEL`, [`Error::TooLarge`] when
    /// the resulting layout would exceed [`crate::MAX_SAMPLE_VALUES`].
    ///
    /// # Example
    /// ```
    /// use mesh_colors::{MeshColors, Topology};
    /// let topology = Topology::new(4, &[[0, 1, 2], [2, 1, 3]])?;
    /// let mut colors = MeshColors::uniform(topology, 2, 3)?;
    /// colors.samples_mut().iter_mut().enumerate().for_each(|(i, x)| *x = i as f32);
    /// let before = colors.clone();
    /// let change = colors.set_face_resolutions(&[(0, 8), (1, 4)])?;
    /// assert_eq!(colors.face_resolution(0), Some(8));
    /// assert_eq!(colors.edge_resolution(1), Some(4)); // the shared edge
    /// colors.revert_resolutions(&change)?;
    /// assert_eq!(colors, before);
    /// assert!(colors.set_face_resolutions(&[(0, 4), (7, 2)]).is_err());
    /// assert_eq!(colors, before); // nothing changed
    /// # Ok::<(), mesh_colors::Error>(())
    /// ```
    pub fn set_face_resolutions(
        &mut self,
        changes: &[(usize, u32)],
    ) -> Result<ResolutionChange, Error> {
        let face_count = self.face_count();
        let mut requests = Vec::with_capacity(changes.len());
        for &(f, r) in changes {
            if f >= face_count {
                return Err(Error::MissingFace {
                    face: f,
                    count: face_count,
                });
            }
            requests.push((f as u32, level_of(f, r)?));
        }
        self.check_budget(&requests)?;
        let c = self.channels;
        let mut record = ResolutionChange {
            channels: c,
            requests,
            faces: Vec::new(),
            face_values: Vec::new(),
            edges: Vec::new(),
            edge_values: Vec::new(),
        };
        let (steps, lowered) = self.plan_steps(&mut record);
        let mut face_new = Overlay::new(face_count);
        let mut edge_new = Overlay::new(self.edge_level.len());
        let waves = steps.iter().map(|s| s.wave).max().map_or(0, |w| w + 1);
        let mut order: Vec<usize> = (0..steps.len()).collect();
        order.sort_by_key(|&k| steps[k].wave); // stable: sequence order within a wave
        let mut at = 0;
        for _ in 0..waves {
            let len = order[at..]
                .iter()
                .take_while(|&&k| steps[k].wave == steps[order[at]].wave)
                .count();
            let wave = &order[at..at + len];
            at += len;
            // Every step of a wave reads what the earlier waves left and
            // writes what no other step of the wave reads, so computing
            // them at once gives the values of the sequential order.
            let staged = Staged {
                mc: self,
                faces: &face_new,
                edges: &edge_new,
            };
            let samples = wave
                .iter()
                .map(|&k| samples_per_face(1 << steps[k].to) as usize)
                .sum();
            let values = map_ordered(wave, samples, |&k| resample_step(&staged, &steps[k]));
            for (&k, (fv, ev)) in wave.iter().zip(values) {
                let step = &steps[k];
                face_new.insert(step.face, fv);
                self.face_level[step.face] = step.to;
                for (&(e, _, le1), v) in step.plan.iter().zip(ev) {
                    let Some(v) = v else { continue };
                    edge_new.insert(e, v);
                    self.edge_level[e] = le1;
                }
            }
        }
        for x in &mut record.faces {
            x.2 = self.face_level[x.0 as usize];
        }
        for x in &mut record.edges {
            x.2 = self.edge_level[x.0 as usize];
        }
        self.relayout(&face_new, &edge_new);
        let touched: Vec<usize> = record.faces.iter().map(|x| x.0 as usize).collect();
        self.update_vertex_levels(&touched, lowered);
        record.requests.shrink_to_fit();
        record.faces.shrink_to_fit();
        record.face_values.shrink_to_fit();
        record.edges.shrink_to_fit();
        record.edge_values.shrink_to_fit();
        Ok(record)
    }

    /// Undoes a [`MeshColors::set_face_resolutions`]: the faces and edges it
    /// resampled get their resolutions and samples back, bit for bit.
    /// Changes made after it must be undone first (undo is last in, first
    /// out); samples painted since on *other* primitives are kept.
    ///
    /// # Errors
    /// [`Error::StaleUndo`] naming the face or edge that is not at the
    /// resolution the change left it at, or the channel count that
    /// differs (the record belongs to another state); nothing changes then.
    pub fn revert_resolutions(&mut self, change: &ResolutionChange) -> Result<(), Error> {
        if change.channels != self.channels {
            return Err(Error::StaleUndo {
                what: "channels",
                index: change.channels,
                reason: "differ from these colours' channel count",
            });
        }
        for &(f, _, after) in &change.faces {
            if self.face_level.get(f as usize) != Some(&after) {
                return Err(Error::StaleUndo {
                    what: "face",
                    index: f as usize,
                    reason: "is not at the resolution the change left it at",
                });
            }
        }
        for &(e, _, after) in &change.edges {
            if self.edge_level.get(e as usize) != Some(&after) {
                return Err(Error::StaleUndo {
                    what: "edge",
                    index: e as usize,
                    reason: "is not at the resolution the change left it at",
                });
            }
        }
        let c = self.channels;
        let mut face_old = Overlay::new(self.face_level.len());
        let mut at = 0;
        let mut lowered = false;
        for &(f, before, after) in &change.faces {
            let len = samples_per_face(1 << before) as usize * c;
            face_old.insert(f as usize, change.face_values[at..at + len].to_vec());
            at += len;
            self.face_level[f as usize] = before;
            lowered |= before < after;
        }
        let mut edge_old = Overlay::new(self.edge_level.len());
        let mut at = 0;
        for &(e, before, _) in &change.edges {
            let len = samples_per_edge(1 << before) as usize * c;
            edge_old.insert(e as usize, change.edge_values[at..at + len].to_vec());
            at += len;
            self.edge_level[e as usize] = before;
        }
        self.relayout(&face_old, &edge_old);
        let touched: Vec<usize> = change.faces.iter().map(|x| x.0 as usize).collect();
        self.update_vertex_levels(&touched, lowered);
        Ok(())
    }

    /// Checks that applying `requests` (validated face, level) keeps the
    /// layout within [`crate::MAX_SAMPLE_VALUES`].
    fn check_budget(&self, requests: &[(u32, u8)]) -> Result<(), Error> {
        let mut last: HashMap<usize, u8> = HashMap::new();
        for &(f, n) in requests {
            last.insert(f as usize, n);
        }
        let level = |f: usize| last.get(&f).copied().unwrap_or(self.face_level[f]);
        let mut total = self.sample_count() as i128;
        let mut edges = HashSet::new();
        for (&f, &n) in &last {
            total += i128::from(samples_per_face(1 << n))
                - i128::from(samples_per_face(1 << self.face_level[f]));
            for e in self.topology.face_edges[f] {
                if !edges.insert(e) {
                    continue;
                }
                let e = e as usize;
                let le = self.topology.edge_faces[e]
                    .iter()
                    .filter(|&&g| g != NO_FACE)
                    .map(|&g| level(g as usize))
                    .min()
                    .unwrap_or(0);
                total += i128::from(samples_per_edge(1 << le))
                    - i128::from(samples_per_edge(1 << self.edge_level[e]));
            }
        }
        let values = total.max(0) as u128 * self.channels as u128;
        if values > u128::from(crate::MAX_SAMPLE_VALUES) {
            return Err(Error::TooLarge {
                what: "the mesh colours after the resolution change",
                requested: u64::try_from(values).unwrap_or(u64::MAX),
                budget: crate::MAX_SAMPLE_VALUES,
                unit: "f32 values",
            });
        }
        Ok(())
    }

    /// Rewrites the sample array after the levels of the primitives in
    /// `faces` and `edges` changed: those get the given values (at their
    /// new level), the others keep theirs. The samples before the first
    /// such primitive stay in place; the rest move once, in place.
    fn relayout(&mut self, faces: &Overlay, edges: &Overlay) {
        let c = self.channels;
        let first_edge = edges.keys.iter().copied().min();
        let first_face = faces.keys.iter().copied().min();
        let (e0, f0, start) = match (first_edge, first_face) {
            (Some(e), _) => (e, 0, self.edge_offset[e]),
            (None, Some(f)) => (self.edge_offset.len(), f, self.face_offset[f]),
            (None, None) => return,
        };
        // Each primitive from there on moves (kept) or is rewritten.
        let mut segments = Vec::new();
        let mut next = start;
        for e in e0..self.edge_offset.len() {
            let n = samples_per_edge(1 << self.edge_level[e]) as usize;
            segments.push((self.edge_offset[e], next, n, !edges.contains(e)));
            self.edge_offset[e] = next;
            next += n;
        }
        for f in f0..self.face_offset.len() {
            let n = samples_per_face(1 << self.face_level[f]) as usize;
            segments.push((self.face_offset[f], next, n, !faces.contains(f)));
            self.face_offset[f] = next;
            next += n;
        }
        move_segments(&mut self.samples, c, &segments, next);
        for (&e, v) in edges.keys.iter().zip(&edges.values) {
            let at = self.edge_offset[e] * c;
            self.samples[at..at + v.len()].copy_from_slice(v);
        }
        for (&f, v) in faces.keys.iter().zip(&faces.values) {
            let at = self.face_offset[f] * c;
            self.samples[at..at + v.len()].copy_from_slice(v);
        }
    }

    /// Brings the vertex levels (the finest of each vertex's faces) up to
    /// date after the faces `touched` changed level: raised in place, or
    /// recomputed over all faces when one was lowered.
    fn update_vertex_levels(&mut self, touched: &[usize], lowered: bool) {
        if lowered {
            self.vertex_level.fill(0);
            for (face, &n) in self.topology.faces.iter().zip(&self.face_level) {
                for &v in face {
                    let l = &mut self.vertex_level[v as usize];
                    *l = (*l).max(n);
                }
            }
        } else {
            for &f in touched {
                let n = self.face_level[f];
                for v in self.topology.faces[f] {
                    let l = &mut self.vertex_level[v as usize];
                    *l = (*l).max(n);
                }
            }
        }
    }
}
