//! MIP-maps per face, edge and vertex (Sec. 4.2: Eq. 5, the six-neighbour
//! edge rule, Eq. 6), trilinear filtering from a footprint, and
//! anisotropic filtering from screen-space derivatives (Sec. 4.3).

use crate::filter::{FINEST, Place, Store, check, edge_point, eval_at, lattice, place, triangle};
use crate::parallel::{join, map_ordered};
use crate::structure::{MeshColors, interior_index, move_segments, samples_per_face};
use crate::topology::NO_FACE;
use std::sync::{Arc, OnceLock};

use crate::{Error, MAX_CHANNELS, MAX_LEVEL};

/// Offset of level `l` within a face's levels: `Σ_{m<l} (2^m−1)(2^m−2)/2`.
const fn face_level_offsets() -> [usize; MAX_LEVEL as usize + 2] {
    let mut out = [0usize; MAX_LEVEL as usize + 2];
    let mut l = 1;
    while l < out.len() {
        out[l] = out[l - 1] + samples_per_face(1 << (l - 1)) as usize;
        l += 1;
    }
    out
}
pub(crate) const FACE_LEVEL_OFFSET: [usize; MAX_LEVEL as usize + 2] = face_level_offsets();

/// Offset of level `l` within an edge's levels: `Σ_{m<l} (2^m − 1)`.
#[inline]
pub(crate) fn edge_level_offset(l: u8) -> usize {
    (1usize << l) - 1 - l as usize
}

/// Which faces and edges meet at each vertex, in the orders
/// [`MipMap::new`] uses.
#[derive(Debug)]
struct Adjacency {
    vf_start: Vec<u32>,
    vf: Vec<u32>,
    vertex_edges: Vec<Vec<u32>>,
}

impl Adjacency {
    fn new(t: &crate::Topology) -> Self {
        let nv = t.vertex_count;
        let mut vf_start = vec![0u32; nv + 1];
        for face in &t.faces {
            for &v in face {
                vf_start[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            vf_start[v + 1] += vf_start[v];
        }
        let mut vf = vec![0u32; vf_start[nv] as usize];
        let mut fill = vf_start.clone();
        for (f, face) in t.faces.iter().enumerate() {
            for &v in face {
                vf[fill[v as usize] as usize] = f as u32;
                fill[v as usize] += 1;
            }
        }
        let mut vertex_edges: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for (e, &[a, b]) in t.edges.iter().enumerate() {
            vertex_edges[a as usize].push(e as u32);
            vertex_edges[b as usize].push(e as u32);
        }
        Self {
            vf_start,
            vf,
            vertex_edges,
        }
    }

    /// The faces around vertex `v`.
    fn faces_of(&self, v: usize) -> &[u32] {
        &self.vf[self.vf_start[v] as usize..self.vf_start[v + 1] as usize]
    }
}

/// Per-primitive offsets (in values) of the pyramid of `colors`:
/// vertices, edges, faces, and the total.
fn pyramid_offsets(colors: &MeshColors) -> (Vec<usize>, Vec<usize>, Vec<usize>, usize) {
    let mut next = 0usize;
    let mut place = |len: usize| {
        let at = next;
        next += len;
        at
    };
    let vertex_offset: Vec<usize> = colors
        .vertex_level
        .iter()
        .map(|&n| place(n as usize + 1))
        .collect();
    let edge_offset: Vec<usize> = colors
        .edge_level
        .iter()
        .map(|&n| place(edge_level_offset(n + 1)))
        .collect();
    let face_offset: Vec<usize> = colors
        .face_level
        .iter()
        .map(|&n| place(FACE_LEVEL_OFFSET[n as usize + 1]))
        .collect();
    (vertex_offset, edge_offset, face_offset, next)
}

/// The primitives one level of [`MipMap::refresh`] recomputes.
struct Subset {
    faces: Vec<usize>,
    edges: Vec<usize>,
    vertices: Vec<usize>,
}

impl Subset {
    /// The faces `faces` finer than `l`, and their edges and vertices
    /// finer than `l`, each once, in increasing order.
    fn of(mc: &MeshColors, faces: &[usize], l: u8) -> Self {
        let mut fs: Vec<usize> = faces
            .iter()
            .copied()
            .filter(|&f| mc.face_level[f] > l)
            .collect();
        let mut es: Vec<usize> = Vec::new();
        let mut vs: Vec<usize> = Vec::new();
        for &f in faces {
            for k in 0..3 {
                let e = mc.topology.face_edges[f][k] as usize;
                if mc.edge_level[e] > l {
                    es.push(e);
                }
                let v = mc.topology.faces[f][k] as usize;
                if mc.vertex_level[v] > l {
                    vs.push(v);
                }
            }
        }
        for list in [&mut fs, &mut es, &mut vs] {
            list.sort_unstable();
            list.dedup();
        }
        Self {
            faces: fs,
            edges: es,
            vertices: vs,
        }
    }
}

/// The indices of `list`, or `0..n` when there is no list.
fn ids(list: Option<&[usize]>, n: usize) -> impl Iterator<Item = usize> + '_ {
    let all = if list.is_none() { 0..n } else { 0..0 };
    list.into_iter().flatten().copied().chain(all)
}

/// The hexagonal neighbours of a lattice point (Eq. 5's six colours).
const HEX: [[i32; 3]; 6] = [
    [1, -1, 0],
    [-1, 1, 0],
    [1, 0, -1],
    [-1, 0, 1],
    [0, 1, -1],
    [0, -1, 1],
];

/// Mesh colours with every MIP level of every vertex, edge and face.
///
/// Level `l` of a face has resolution `2^l`, down to level 0 (its vertex
/// colours). A vertex has levels `0..=` the finest of its faces, an edge
/// `0..=` its own (the lowest of its faces, see [`MeshColors`]). Levels are
/// stored one after the other per primitive, coarsest first, so one index
/// per vertex, edge and face reaches all of them (Sec. 4.2). A query at
/// level `l` reads each primitive at `min(l, its finest)`, so every level
/// is one continuous colouring, identical on an edge from both sides.
#[derive(Debug, Clone)]
pub struct MipMap {
    pub(crate) colors: MeshColors,
    pub(crate) vertex_offset: Vec<usize>,
    pub(crate) edge_offset: Vec<usize>,
    pub(crate) face_offset: Vec<usize>,
    pub(crate) data: Vec<f32>,
    /// The lookup cache (see [`Cache`]), built by the first CPU lookup:
    /// a caller that only packs the pyramid for the GPU
    /// ([`crate::gpu::GpuLayout`]) never pays for it, and the refreshes
    /// keep it up to date only once it exists.
    pub(crate) cache: OnceLock<Cache>,
    /// The faces and edges around each vertex, built by the first refresh
    /// and kept (the mesh never changes; a stroke's refresh built it
    /// again every dab).
    adjacency: OnceLock<Arc<Adjacency>>,
}

/// A lookup cache of a [`MipMap`]: per face, every level's full lattice
/// (vertex and edge values copied in, interpolated where the edge is
/// coarser), so a lookup inside a face reads three values without
/// branching. Slot `l ≤ n_f` is the face seen at query level `l`; slot
/// `n_f + 1` at any level from the finest of its corners up (vertices
/// keep refining after a coarse face stops). Derived data: two pyramids
/// are equal whatever their caches hold.
#[derive(Debug, Clone, Default)]
pub(crate) struct Cache {
    /// Per face, its first value in `flat`.
    offset: Vec<usize>,
    flat: Vec<f32>,
    /// Per face, the finest level of its three corners.
    corner_level: Vec<u8>,
}

impl Cache {
    /// Moves the caches of the faces not `listed` to the layout of
    /// `colors` (whose resolutions differ only on listed faces); the
    /// listed faces' caches are left for the caller to fill.
    fn relayout(&mut self, colors: &MeshColors, listed: &[bool]) {
        let nf = colors.face_level.len();
        let mut segments = Vec::with_capacity(nf);
        let mut next = 0;
        let mut offset = Vec::with_capacity(nf);
        for (f, &n) in colors.face_level.iter().enumerate() {
            let len = FLAT_SLOT_OFFSET[n as usize + 2];
            segments.push((self.offset[f], next, len, !listed[f]));
            offset.push(next);
            next += len;
        }
        move_segments(&mut self.flat, colors.channels, &segments, next);
        self.offset = offset;
        self.corner_level = corner_levels(colors);
    }
}

/// Per face, the finest level of its three corners.
fn corner_levels(colors: &MeshColors) -> Vec<u8> {
    colors
        .topology
        .faces
        .iter()
        .map(|face| {
            face.iter()
                .map(|&v| colors.vertex_level[v as usize])
                .max()
                .unwrap_or(0)
        })
        .collect()
}

impl PartialEq for MipMap {
    fn eq(&self, other: &Self) -> bool {
        // The cache is a function of the rest.
        self.colors == other.colors
            && self.vertex_offset == other.vertex_offset
            && self.edge_offset == other.edge_offset
            && self.face_offset == other.face_offset
            && self
                .data
                .iter()
                .map(|x| x.to_bits())
                .eq(other.data.iter().map(|x| x.to_bits()))
    }
}

/// Lattice points of a face of resolution `r`: `(r + 1)(r + 2)/2`.
const fn lattice_len(r: usize) -> usize {
    (r + 1) * (r + 2) / 2
}

/// Offset of slot `s` within a face's cache: `Σ_{m<s} lattice_len(2^m)`.
const fn flat_slot_offsets() -> [usize; MAX_LEVEL as usize + 3] {
    let mut out = [0usize; MAX_LEVEL as usize + 3];
    let mut l = 1;
    while l < out.len() {
        out[l] = out[l - 1] + lattice_len(1 << (l - 1));
        l += 1;
    }
    out
}
const FLAT_SLOT_OFFSET: [usize; MAX_LEVEL as usize + 3] = flat_slot_offsets();

/// Row-major index of lattice point `(i, j, ·)` of resolution `r`.
#[inline(always)]
fn lattice_row_index(r: u32, i: u32, j: u32) -> usize {
    (i * (2 * r + 3 - i) / 2 + j) as usize
}

impl Store for MipMap {
    #[inline]
    fn colors(&self) -> &MeshColors {
        &self.colors
    }
    #[inline]
    fn vertex_at(&self, v: usize, level: u8) -> &[f32] {
        let c = self.colors.channels;
        let i = self.vertex_offset[v] + level as usize;
        &self.data[i * c..(i + 1) * c]
    }
    #[inline]
    fn edge_at(&self, e: usize, level: u8, s: u32) -> &[f32] {
        let c = self.colors.channels;
        let i = self.edge_offset[e] + edge_level_offset(level) + s as usize - 1;
        &self.data[i * c..(i + 1) * c]
    }
    #[inline]
    fn face_at(&self, f: usize, level: u8, idx: usize) -> &[f32] {
        let c = self.colors.channels;
        let i = self.face_offset[f] + FACE_LEVEL_OFFSET[level as usize] + idx;
        &self.data[i * c..(i + 1) * c]
    }
}

/// Adds `x` to the running sums `sum` (in f64, as Eq. 5 and 6 average).
fn accumulate(sum: &mut [f64], x: &[f32]) {
    for (s, &x) in sum.iter_mut().zip(x) {
        *s += f64::from(x);
    }
}

/// Writes `(centre + ½ Σ neighbours) / (1 + n/2)`: Eq. 5 for six
/// neighbours, Eq. 6 for a vertex of valence `n`, and the edge rule (two
/// on the edge, two from each face; one face on a boundary).
fn combine(centre: &[f32], sum: &[f64], n: usize, out: &mut [f32]) {
    let norm = 1.0 / (1.0 + 0.5 * n as f64);
    for ((o, &c), &s) in out.iter_mut().zip(centre).zip(sum) {
        *o = ((f64::from(c) + 0.5 * s) * norm) as f32;
    }
}

impl MipMap {
    /// Builds all MIP levels from the finest samples, level by level from
    /// the top: faces by Eq. 5, edges from their two on-edge and (per face)
    /// two off-edge neighbours, vertices by Eq. 6 with the nearest sample
    /// of every edge at the finer level (interpolated, by the continuity
    /// rule, on an edge coarser than that level). Sums are in `f64`.
    pub fn new(colors: MeshColors) -> Self {
        let mut mip = Self::zeroed(colors);
        mip.copy_finest();
        let mut vertex_edges: Vec<Vec<u32>> = vec![Vec::new(); mip.colors.topology.vertex_count];
        for (e, &[a, b]) in mip.colors.topology.edges.iter().enumerate() {
            vertex_edges[a as usize].push(e as u32);
            vertex_edges[b as usize].push(e as u32);
        }
        let top = mip.colors.vertex_level.iter().copied().max().unwrap_or(0);
        for l in (0..top).rev() {
            mip.build_level(l, &vertex_edges, None);
        }
        mip
    }

    /// The layout for `colors` with every value zero.
    pub(crate) fn zeroed(colors: MeshColors) -> Self {
        let (vertex_offset, edge_offset, face_offset, next) = pyramid_offsets(&colors);
        MipMap {
            data: vec![0.0; next * colors.channels],
            vertex_offset,
            edge_offset,
            face_offset,
            colors,
            cache: OnceLock::new(),
            adjacency: OnceLock::new(),
        }
    }

    /// The number of values (samples × channels) a pyramid of `colors`
    /// holds, without building it.
    pub(crate) fn len_for(colors: &MeshColors) -> u64 {
        let v: u64 = colors.vertex_level.iter().map(|&n| u64::from(n) + 1).sum();
        let e: u64 = colors
            .edge_level
            .iter()
            .map(|&n| edge_level_offset(n + 1) as u64)
            .sum();
        let f: u64 = colors
            .face_level
            .iter()
            .map(|&n| FACE_LEVEL_OFFSET[n as usize + 1] as u64)
            .sum();
        (v + e + f) * colors.channels as u64
    }

    /// The mesh colours (finest level) this pyramid was built from.
    pub fn colors(&self) -> &MeshColors {
        &self.colors
    }

    /// Gives the finest-level mesh colours back.
    pub fn into_colors(self) -> MeshColors {
        self.colors
    }

    /// Every level of every primitive, in the layout described on
    /// [`MipMap`]: vertices, then edges, then faces.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Replaces the MIP data (for example read from a file).
    ///
    /// # Errors
    /// [`Error::ChannelMismatch`] if the length is not this layout's.
    pub(crate) fn set_data(&mut self, data: Vec<f32>) -> Result<(), Error> {
        if data.len() != self.data.len() {
            return Err(Error::ChannelMismatch {
                what: "MIP data",
                expected: self.data.len(),
                got: data.len(),
            });
        }
        self.data = data;
        self.cache = OnceLock::new();
        Ok(())
    }

    /// The lookup cache of the pyramid as it is (see [`Cache`]).
    fn build_cache(&self) -> Cache {
        let mc = &self.colors;
        let c = mc.channels;
        let mut offset = Vec::with_capacity(mc.face_level.len());
        let mut next = 0;
        for &n in &mc.face_level {
            offset.push(next);
            next += FLAT_SLOT_OFFSET[n as usize + 2];
        }
        let mut flat = vec![0.0f32; next * c];
        for (f, &first) in offset.iter().enumerate() {
            self.fill_face_cache(f, first, &mut flat);
        }
        Cache {
            offset,
            flat,
            corner_level: corner_levels(mc),
        }
    }

    /// Writes face `f`'s cache, from `first` (in values), into `flat`.
    fn fill_face_cache(&self, f: usize, first: usize, flat: &mut [f32]) {
        let c = self.colors.channels;
        let n = self.colors.face_level[f];
        let len = FLAT_SLOT_OFFSET[n as usize + 2] * c;
        flat[first * c..first * c + len].fill(0.0);
        for slot in 0..=n + 1 {
            let (q, lf) = if slot <= n { (slot, slot) } else { (FINEST, n) };
            let r = 1u32 << lf;
            let base = first + FLAT_SLOT_OFFSET[slot as usize];
            for i in 0..=r {
                for j in 0..=r - i {
                    let at = (base + lattice_row_index(r, i, j)) * c;
                    lattice(
                        self,
                        f,
                        q,
                        lf,
                        [i, j, r - i - j],
                        1.0,
                        false,
                        &mut flat[at..at + c],
                    );
                }
            }
        }
    }

    /// Brings the pyramid up to date after finest samples of `colors`
    /// changed — a stroke, or its undo — at a cost that follows the
    /// faces near the change, not the mesh: `changed` lists the changed
    /// samples as runs `(first sample index, count)` (what
    /// [`crate::undo::Delta::runs`] gives). A level `l` value reads level
    /// `l + 1` of its own and its neighbours' primitives, so the faces
    /// recomputed grow by one ring of faces (sharing a vertex) per level
    /// below the finest. The result equals [`MipMap::new`] of `colors`
    /// bit for bit.
    ///
    /// Returns the spans `[start, end)` of values (indices into
    /// [`MipMap::data`] divided by the channel count) that were rewritten,
    /// sorted and disjoint, for [`crate::gpu::GpuLayout::refresh`].
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming `colors` when they do not have
    /// this pyramid's layout (channels, connectivity and face resolutions:
    /// after a resolution change, build a new pyramid) or `changed` when
    /// a run leaves the samples; nothing changes then.
    pub fn refresh(
        &mut self,
        colors: &MeshColors,
        changed: &[(u32, u32)],
    ) -> Result<Vec<(usize, usize)>, Error> {
        let mine = &self.colors;
        if colors.channels != mine.channels
            || colors.face_level != mine.face_level
            || colors.topology != mine.topology
        {
            return Err(Error::InvalidArgument {
                argument: "colors",
                reason: "do not have this pyramid's layout (after a resolution change, \
                         build a new MipMap)",
            });
        }
        let count = colors.sample_count();
        if changed
            .iter()
            .any(|&(start, len)| u64::from(start) + u64::from(len) > count as u64)
        {
            return Err(Error::InvalidArgument {
                argument: "changed",
                reason: "names a sample beyond the colours' samples",
            });
        }
        // `colors` has this pyramid's layout: read it from there.
        let c = colors.channels;
        let t = &colors.topology;
        let (nv, nf) = (t.vertex_count, t.faces.len());
        let adjacency = Arc::clone(self.adjacency.get_or_init(|| Arc::new(Adjacency::new(t))));
        let faces_of = |v: usize| adjacency.faces_of(v);
        // Copy the new finest values, and mark their faces.
        let mut dirty = vec![false; nf];
        let mut list: Vec<usize> = Vec::new();
        let mark = |f: usize, dirty: &mut Vec<bool>, list: &mut Vec<usize>| {
            if !dirty[f] {
                dirty[f] = true;
                list.push(f);
            }
        };
        let faces_start = colors.face_offset.first().copied().unwrap_or(count);
        let mut written = Vec::new();
        for &(start, len) in changed {
            for i in start as usize..start as usize + len as usize {
                let value = &colors.samples[i * c..(i + 1) * c];
                self.colors.samples[i * c..(i + 1) * c].copy_from_slice(value);
                let mc = colors;
                let at = if i < nv {
                    for &f in faces_of(i) {
                        mark(f as usize, &mut dirty, &mut list);
                    }
                    self.vertex_offset[i] + mc.vertex_level[i] as usize
                } else if i < faces_start {
                    let e = mc.edge_offset.partition_point(|&o| o <= i) - 1;
                    for &f in &t.edge_faces[e] {
                        if f != NO_FACE {
                            mark(f as usize, &mut dirty, &mut list);
                        }
                    }
                    self.edge_offset[e]
                        + edge_level_offset(mc.edge_level[e])
                        + (i - mc.edge_offset[e])
                } else {
                    let f = mc.face_offset.partition_point(|&o| o <= i) - 1;
                    mark(f, &mut dirty, &mut list);
                    self.face_offset[f]
                        + FACE_LEVEL_OFFSET[mc.face_level[f] as usize]
                        + (i - mc.face_offset[f])
                };
                self.data[at * c..(at + 1) * c].copy_from_slice(value);
                written.push((at, at + 1));
            }
        }
        Ok(self.recompute(colors, &adjacency, dirty, list, written))
    }

    /// Brings the pyramid up to date after the resolutions of `faces`
    /// changed ([`MeshColors::set_face_resolutions`] or
    /// [`MeshColors::revert_resolutions`]; pass the faces of its
    /// [`crate::edit::ResolutionChange::faces`]). Every other primitive
    /// keeps its levels (moved once to the new layout); the faces given,
    /// the edges and vertices whose resolution changed, and the rings
    /// around them that [`MipMap::refresh`] describes are recomputed. The
    /// result equals [`MipMap::new`] of `colors` bit for bit.
    ///
    /// Returns the spans `[start, end)` of values (in the new layout) that
    /// were rewritten, sorted and disjoint, as [`MipMap::refresh`] does,
    /// for [`crate::gpu::GpuLayout::refresh_resolutions`]: every value of
    /// a primitive whose levels changed is in them.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming `colors` when they are on another
    /// mesh or have other channels, or `faces` when it leaves out a face
    /// whose resolution differs; [`Error::MissingFace`] for a face out of
    /// range. Nothing changes then.
    pub fn refresh_resolutions(
        &mut self,
        colors: &MeshColors,
        faces: &[usize],
    ) -> Result<Vec<(usize, usize)>, Error> {
        if colors.channels != self.colors.channels || colors.topology != self.colors.topology {
            return Err(Error::InvalidArgument {
                argument: "colors",
                reason: "are not on this pyramid's mesh or have other channels",
            });
        }
        let nf = colors.face_level.len();
        let mut listed = vec![false; nf];
        for &f in faces {
            if f >= nf {
                return Err(Error::MissingFace { face: f, count: nf });
            }
            listed[f] = true;
        }
        if (0..nf).any(|f| !listed[f] && colors.face_level[f] != self.colors.face_level[f]) {
            return Err(Error::InvalidArgument {
                argument: "faces",
                reason: "leaves out a face whose resolution changed",
            });
        }
        let c = colors.channels;
        let t = &colors.topology;
        let adjacency = Arc::clone(self.adjacency.get_or_init(|| Arc::new(Adjacency::new(t))));
        let mut dirty = vec![false; nf];
        let mut list: Vec<usize> = Vec::new();
        let mut mark = |f: usize| {
            if !dirty[f] {
                dirty[f] = true;
                list.push(f);
            }
        };
        // An edge of a face given may have been resampled even at its old
        // resolution (coarsened and refined again in one batch).
        let mut near = vec![false; t.edges.len()];
        for f in (0..nf).filter(|&f| listed[f]) {
            for e in t.face_edges[f] {
                near[e as usize] = true;
            }
        }
        // Which primitives keep their levels (and move), in layout order.
        let old = &self.colors;
        let keep_vertex: Vec<bool> = (0..t.vertex_count)
            .map(|v| old.vertex_level[v] == colors.vertex_level[v])
            .collect();
        let keep_edge: Vec<bool> = (0..t.edges.len())
            .map(|e| old.edge_level[e] == colors.edge_level[e] && !near[e])
            .collect();
        let (vo, eo, fo, total) = pyramid_offsets(colors);
        let mut segments = Vec::with_capacity(vo.len() + eo.len() + fo.len());
        for v in 0..vo.len() {
            let len = colors.vertex_level[v] as usize + 1;
            segments.push((self.vertex_offset[v], vo[v], len, keep_vertex[v]));
        }
        for e in 0..eo.len() {
            let len = edge_level_offset(colors.edge_level[e] + 1);
            segments.push((self.edge_offset[e], eo[e], len, keep_edge[e]));
        }
        for f in 0..fo.len() {
            let len = FACE_LEVEL_OFFSET[colors.face_level[f] as usize + 1];
            segments.push((self.face_offset[f], fo[f], len, !listed[f]));
        }
        // The pyramid moves to the new layout while the colours' samples
        // are copied: two memory-bound passes over different arrays.
        let (data, samples) = (&mut self.data, &mut self.colors.samples);
        join(
            || move_segments(data, c, &segments, total),
            || samples.clone_from(&colors.samples),
        );
        (self.vertex_offset, self.edge_offset, self.face_offset) = (vo, eo, fo);
        if let Some(cache) = self.cache.get_mut() {
            cache.relayout(colors, &listed);
        }
        // The finest values of the primitives that did not move.
        let mut written = Vec::new();
        for v in (0..t.vertex_count).filter(|&v| !keep_vertex[v]) {
            let at = self.vertex_offset[v] + colors.vertex_level[v] as usize;
            written.push((at, at + 1));
            let at = at * c;
            self.data[at..at + c].copy_from_slice(&colors.samples[v * c..(v + 1) * c]);
            for &f in adjacency.faces_of(v) {
                mark(f as usize);
            }
        }
        for e in (0..t.edges.len()).filter(|&e| !keep_edge[e]) {
            let n = colors.edge_level[e];
            let (from, len) = (colors.edge_offset[e] * c, ((1usize << n) - 1) * c);
            let at = self.edge_offset[e] + edge_level_offset(n);
            written.push((at, at + len / c));
            let at = at * c;
            self.data[at..at + len].copy_from_slice(&colors.samples[from..from + len]);
            for &f in &t.edge_faces[e] {
                if f != NO_FACE {
                    mark(f as usize);
                }
            }
        }
        for f in (0..nf).filter(|&f| listed[f]) {
            let n = colors.face_level[f];
            let (from, len) = (
                colors.face_offset[f] * c,
                samples_per_face(1 << n) as usize * c,
            );
            let at = self.face_offset[f] + FACE_LEVEL_OFFSET[n as usize];
            written.push((at, at + len / c));
            let at = at * c;
            self.data[at..at + len].copy_from_slice(&colors.samples[from..from + len]);
            mark(f);
        }
        // The rest of the colours, reusing their allocations.
        let mine = &mut self.colors;
        mine.face_level.clone_from(&colors.face_level);
        mine.edge_level.clone_from(&colors.edge_level);
        mine.vertex_level.clone_from(&colors.vertex_level);
        mine.edge_offset.clone_from(&colors.edge_offset);
        mine.face_offset.clone_from(&colors.face_offset);
        Ok(self.recompute(colors, &adjacency, dirty, list, written))
    }

    /// Recomputes the levels below the finest of the faces `list` (marked
    /// in `dirty`) and one more ring of faces per level, then their
    /// caches; returns the value spans rewritten (see
    /// [`MipMap::refresh`]): `written`, the finest values the caller put
    /// in place, and the levels recomputed. Only those: a face of the
    /// outer rings has its coarse levels rewritten, not its finest (most
    /// of its values), so a page is sent no more than changed.
    fn recompute(
        &mut self,
        colors: &MeshColors,
        adjacency: &Adjacency,
        mut dirty: Vec<bool>,
        mut list: Vec<usize>,
        mut spans: Vec<(usize, usize)>,
    ) -> Vec<(usize, usize)> {
        let t = &colors.topology;
        let faces_of = |v: usize| adjacency.faces_of(v);
        let vertex_edges = &adjacency.vertex_edges;
        // One ring more per level, then that level of the ring's
        // primitives.
        let grow = |dirty: &mut Vec<bool>, list: &mut Vec<usize>| {
            let before = list.len();
            for k in 0..before {
                for v in t.faces[list[k]] {
                    for &g in faces_of(v as usize) {
                        if !dirty[g as usize] {
                            dirty[g as usize] = true;
                            list.push(g as usize);
                        }
                    }
                }
            }
        };
        let top = colors.vertex_level.iter().copied().max().unwrap_or(0);
        // Per primitive, the finest level recomputed (NONE: none). The
        // levels run from the top down, and a primitive once reached is
        // recomputed at every level below, down to 0: its levels 0..=top
        // are one span of its block.
        const NONE: u8 = u8::MAX;
        let mut face_top = vec![NONE; t.faces.len()];
        let mut edge_top = vec![NONE; t.edges.len()];
        let mut vertex_top = vec![NONE; t.vertex_count];
        for l in (0..top).rev() {
            grow(&mut dirty, &mut list);
            let subset = Subset::of(colors, &list, l);
            self.build_level(l, vertex_edges, Some(&subset));
            let firsts = [
                (&subset.faces, &mut face_top),
                (&subset.edges, &mut edge_top),
                (&subset.vertices, &mut vertex_top),
            ];
            for (ids, tops) in firsts {
                for &i in ids {
                    if tops[i] == NONE {
                        tops[i] = l;
                    }
                }
            }
        }
        let reached = |tops: &[u8]| {
            (0..tops.len())
                .filter(|&i| tops[i] != NONE)
                .map(|i| (i, tops[i] + 1))
                .collect::<Vec<_>>()
        };
        for (f, n) in reached(&face_top) {
            let o = self.face_offset[f];
            spans.push((o, o + FACE_LEVEL_OFFSET[n as usize]));
        }
        for (e, n) in reached(&edge_top) {
            let o = self.edge_offset[e];
            spans.push((o, o + edge_level_offset(n)));
        }
        for (v, n) in reached(&vertex_top) {
            let o = self.vertex_offset[v];
            spans.push((o, o + n as usize));
        }
        spans.sort_unstable();
        let mut merged: Vec<(usize, usize)> = Vec::with_capacity(spans.len());
        for (a, b) in spans {
            match merged.last_mut() {
                Some((_, end)) if a <= *end => *end = (*end).max(b),
                _ if a < b => merged.push((a, b)),
                _ => {}
            }
        }
        // Caches of every face touching a rewritten primitive, when there
        // is a cache.
        if let Some(mut cache) = self.cache.take() {
            grow(&mut dirty, &mut list);
            for &f in &list {
                self.fill_face_cache(f, cache.offset[f], &mut cache.flat);
            }
            self.cache = OnceLock::from(cache);
        }
        merged
    }

    /// A lookup at query level `q` of a point inside face `f`, from the
    /// cache when it holds that view of the face.
    #[inline]
    fn inside(&self, f: usize, at: Place, q: u8, out: &mut [f32]) {
        let Place::Inside(bc) = at else {
            eval_at(self, f, at, q, false, out);
            return;
        };
        let cache = self.cache.get_or_init(|| self.build_cache());
        let n = self.colors.face_level[f];
        let (slot, lf) = if q <= n {
            (q, q)
        } else if q >= cache.corner_level[f] {
            (n + 1, n)
        } else {
            eval_at(self, f, at, q, false, out);
            return;
        };
        let r = 1u32 << lf;
        let (pts, ws) = triangle(bc, r);
        let c = self.colors.channels;
        let base = cache.offset[f] + FLAT_SLOT_OFFSET[slot as usize];
        out.fill(0.0);
        for t in 0..3 {
            let at = (base + lattice_row_index(r, pts[t][0], pts[t][1])) * c;
            for (o, &x) in out.iter_mut().zip(&cache.flat[at..at + c]) {
                *o += ws[t] * x;
            }
        }
    }

    fn copy_finest(&mut self) {
        let mc = &self.colors;
        let c = mc.channels;
        for v in 0..mc.topology.vertex_count {
            let at = self.vertex_offset[v] + mc.vertex_level[v] as usize;
            self.data[at * c..(at + 1) * c].copy_from_slice(&mc.samples[v * c..(v + 1) * c]);
        }
        for e in 0..mc.edge_level.len() {
            let n = mc.edge_level[e];
            let len = ((1usize << n) - 1) * c;
            let at = (self.edge_offset[e] + edge_level_offset(n)) * c;
            let from = mc.edge_offset[e] * c;
            self.data[at..at + len].copy_from_slice(&mc.samples[from..from + len]);
        }
        for f in 0..mc.face_level.len() {
            let n = mc.face_level[f];
            let len = samples_per_face(1 << n) as usize * c;
            let at = (self.face_offset[f] + FACE_LEVEL_OFFSET[n as usize]) * c;
            let from = mc.face_offset[f] * c;
            self.data[at..at + len].copy_from_slice(&mc.samples[from..from + len]);
        }
    }

    /// Computes level `l` of every primitive finer than `l` from level
    /// `l + 1` (all of which exists already).
    /// (Only the faces, edges and vertices of `subset` when given.)
    ///
    /// Each primitive's values read level `l + 1` only and land in its own
    /// span of level `l`, so they are computed on all threads (see
    /// [`map_ordered`]) and written afterwards, the same at any thread
    /// count.
    fn build_level(&mut self, l: u8, vertex_edges: &[Vec<u32>], subset: Option<&Subset>) {
        let mc = &self.colors;
        let r = 1u32 << l;
        let faces: Vec<usize> = ids(subset.map(|s| &s.faces[..]), mc.face_level.len())
            .filter(|&f| mc.face_level[f] > l && r >= 3)
            .collect();
        let edges: Vec<usize> = ids(subset.map(|s| &s.edges[..]), mc.edge_level.len())
            .filter(|&e| mc.edge_level[e] > l && r >= 2)
            .collect();
        let vertices: Vec<usize> = ids(subset.map(|s| &s.vertices[..]), vertex_edges.len())
            .filter(|&v| mc.vertex_level[v] > l)
            .collect();
        let this = &*self;
        // About the samples each computes (a vertex or an edge sample
        // averages about six).
        let face_samples = faces.len() * samples_per_face(r) as usize;
        let edge_samples = edges.len() * r as usize * 6;
        let mut writes = map_ordered(&faces, face_samples, |&f| this.face_level_values(f, l));
        writes.extend(map_ordered(&edges, edge_samples, |&e| {
            this.edge_level_values(e, l)
        }));
        writes.extend(map_ordered(&vertices, vertices.len() * 6, |&v| {
            this.vertex_level_value(v, l, &vertex_edges[v])
        }));
        let c = self.colors.channels;
        for (at, values) in writes {
            self.data[at * c..at * c + values.len()].copy_from_slice(&values);
        }
    }

    /// Face `f`'s interior samples at level `l` (Eq. 5), from level
    /// `l + 1`: the first sample's index in `data` and the values, in
    /// interior order.
    fn face_level_values(&self, f: usize, l: u8) -> (usize, Vec<f32>) {
        let c = self.colors.channels;
        let r = 1u32 << l;
        let r2 = r << 1;
        // Level l + 1's interior samples: the centre (2i, 2j) of a level-l
        // sample (i, j ≥ 1, i + j < r) and its six neighbours all have
        // three positive coordinates, so all are interior samples of the
        // face, read straight from its block (as `lattice` would).
        let fine = self.face_offset[f] + FACE_LEVEL_OFFSET[l as usize + 1];
        let src = &self.data[fine * c..(fine + samples_per_face(r2) as usize) * c];
        let first = self.face_offset[f] + FACE_LEVEL_OFFSET[l as usize];
        let mut values = vec![0.0f32; samples_per_face(r) as usize * c];
        let mut sum = [0.0f64; MAX_CHANNELS];
        let sum = &mut sum[..c];
        let mut out = values.chunks_exact_mut(c);
        for i in 1..r {
            for j in 1..r - i {
                let (ci, cj) = (2 * i, 2 * j);
                sum.fill(0.0);
                for d in HEX {
                    let a = interior_index(
                        r2,
                        ci.wrapping_add_signed(d[0]),
                        cj.wrapping_add_signed(d[1]),
                    ) * c;
                    accumulate(sum, &src[a..a + c]);
                }
                let centre = interior_index(r2, ci, cj) * c;
                if let Some(val) = out.next() {
                    combine(&src[centre..centre + c], sum, 6, val);
                }
            }
        }
        (first, values)
    }

    /// Edge `e`'s samples at level `l` (the six-neighbour rule), from
    /// level `l + 1`: the first sample's index in `data` and the values.
    fn edge_level_values(&self, e: usize, l: u8) -> (usize, Vec<f32>) {
        let mc = &self.colors;
        let c = mc.channels;
        let q = l + 1;
        let r = 1u32 << l;
        let r2 = 1u32 << q;
        // Its level l + 1: node p (1 ≤ p < r2) at (p − 1)·c.
        let at = self.edge_offset[e] + edge_level_offset(q);
        let edge = &self.data[at * c..(at + r2 as usize - 1) * c];
        // Each face beside it: its level-(l + 1) interior samples, and
        // where the edge lies in it. The two neighbours a node takes from
        // a face lie one step inside it, so they are interior samples,
        // read straight from the block (as `lattice` would).
        let sides: Vec<(&[f32], [usize; 3], bool)> = (mc.topology.edge_faces[e].iter())
            .filter(|&&f| f != NO_FACE)
            .filter_map(|&f| {
                let f = f as usize;
                let k = (0..3).find(|&k| mc.topology.face_edges[f][k] as usize == e)?;
                let face = mc.topology.faces[f];
                let at = self.face_offset[f] + FACE_LEVEL_OFFSET[q as usize];
                let block = &self.data[at * c..(at + samples_per_face(r2) as usize) * c];
                Some((
                    block,
                    [k, (k + 1) % 3, (k + 2) % 3],
                    face[k] < face[(k + 1) % 3],
                ))
            })
            .collect();
        let (mut sum, mut val) = ([0.0f64; MAX_CHANNELS], [0.0f32; MAX_CHANNELS]);
        let (sum, val) = (&mut sum[..c], &mut val[..c]);
        let node = |p: u32| &edge[(p as usize - 1) * c..p as usize * c];
        let mut values = Vec::with_capacity((r as usize - 1) * c);
        for s in 1..r {
            sum.fill(0.0);
            accumulate(sum, node(2 * s - 1));
            accumulate(sum, node(2 * s + 1));
            let mut n = 2;
            for &(block, [k, k1, m], forward) in &sides {
                let t = if forward { 2 * s } else { r2 - 2 * s };
                let mut a = [0u32; 3];
                a[k] = r2 - t;
                a[k1] = t;
                for (dk, dk1) in [(1, 0), (0, 1)] {
                    let mut b = a;
                    b[k] -= dk;
                    b[k1] -= dk1;
                    b[m] += 1;
                    let i = interior_index(r2, b[0], b[1]) * c;
                    accumulate(sum, &block[i..i + c]);
                    n += 1;
                }
            }
            combine(node(2 * s), sum, n, val);
            values.extend_from_slice(val);
        }
        (self.edge_offset[e] + edge_level_offset(l), values)
    }

    /// Vertex `v`'s value at level `l` (Eq. 6) from level `l + 1` along
    /// its `edges`: its index in `data` and the value.
    fn vertex_level_value(&self, v: usize, l: u8, edges: &[u32]) -> (usize, Vec<f32>) {
        let mc = &self.colors;
        let c = mc.channels;
        let q = l + 1;
        let r2 = 1u32 << q;
        let (mut tmp, mut sum) = ([0.0f32; MAX_CHANNELS], [0.0f64; MAX_CHANNELS]);
        let (tmp, sum) = (&mut tmp[..c], &mut sum[..c]);
        for &e in edges {
            let e = e as usize;
            let p = if mc.topology.edges[e][0] as usize == v {
                1
            } else {
                r2 - 1
            };
            tmp.fill(0.0);
            edge_point(self, e, q, q, p, 1.0, false, tmp);
            accumulate(sum, tmp);
        }
        let mut val = vec![0.0f32; c];
        combine(self.vertex_at(v, q), sum, edges.len(), &mut val);
        (self.vertex_offset[v] + l as usize, val)
    }

    /// Linear filtering at MIP level `level` (clamped per primitive to its
    /// finest): the colouring of that level, continuous across edges.
    ///
    /// # Errors
    /// [`Error::MissingFace`] or [`Error::ChannelMismatch`].
    pub fn at_level(
        &self,
        face: usize,
        b: [f32; 3],
        level: u8,
        out: &mut [f32],
    ) -> Result<(), Error> {
        check(&self.colors, face, out)?;
        self.inside(face, place(&self.colors, face, b), level, out);
        Ok(())
    }

    /// Trilinear MIP filtering: the level is `λ = −log2(footprint)`, where
    /// `footprint` is the filter width in barycentric units (the fraction of
    /// the face's edge a pixel covers); the two levels around `λ` are
    /// filtered linearly and blended. Blending happens only when the two
    /// levels differ for the primitive the point lies on, so points on an
    /// edge get the same value from both faces.
    ///
    /// # Errors
    /// As for [`MipMap::at_level`].
    pub fn trilinear(
        &self,
        face: usize,
        b: [f32; 3],
        footprint: f32,
        out: &mut [f32],
    ) -> Result<(), Error> {
        check(&self.colors, face, out)?;
        self.trilinear_unchecked(face, b, level_of_footprint(footprint), out);
        Ok(())
    }

    #[inline]
    fn trilinear_unchecked(&self, face: usize, b: [f32; 3], lambda: f32, out: &mut [f32]) {
        let mc = &self.colors;
        let at = place(mc, face, b);
        let top = match at {
            Place::Vertex(v) => mc.vertex_level[v as usize],
            Place::Edge(e, _) => mc.edge_level[e],
            Place::Inside(_) => mc.face_level[face],
        };
        let l0 = lambda.floor();
        let frac = lambda - l0;
        let l0 = l0 as u8;
        self.inside(face, at, l0, out);
        if l0 >= top || frac == 0.0 {
            return;
        }
        let c = mc.channels;
        let mut fine = [0.0f32; MAX_CHANNELS];
        self.inside(face, at, l0 + 1, &mut fine[..c]);
        for (o, &x) in out.iter_mut().zip(&fine[..c]) {
            *o = (1.0 - frac) * *o + frac * x;
        }
    }

    /// Anisotropic filtering (Sec. 4.3) from the screen-space derivatives
    /// of the barycentrics, `db_dx` and `db_dy`. Lengths are measured on
    /// the equilateral triangle (where the sample lattice is regular). Up to
    /// `max_samples` trilinear probes, spaced along the longer axis of the
    /// pixel footprint and clamped into the face (mesh colours cannot reach
    /// across faces), are averaged at the level of the shorter axis.
    /// `max_samples` is capped at [`MAX_PROBES`].
    ///
    /// # Errors
    /// As for [`MipMap::at_level`].
    pub fn anisotropic(
        &self,
        face: usize,
        b: [f32; 3],
        db_dx: [f32; 3],
        db_dy: [f32; 3],
        max_samples: u32,
        out: &mut [f32],
    ) -> Result<(), Error> {
        check(&self.colors, face, out)?;
        let c = self.colors.channels;
        anisotropic_probes(
            b,
            db_dx,
            db_dy,
            max_samples,
            &mut out[..c],
            |p, lambda, o| {
                self.trilinear_unchecked(face, p, lambda, o);
            },
        );
        Ok(())
    }
}

/// Anisotropic filtering (Sec. 4.3) around a trilinear lookup
/// `trilinear(b, λ, out)`: the longer of the screen derivatives `∂b/∂x`,
/// `∂b/∂y` (lengths on the equilateral triangle) is the major axis; `N =
/// ⌈major / minor⌉` probes (1 to `max_samples`, at most [`MAX_PROBES`])
/// spaced along it at the level of `max(major / N, minor)`, averaged. The
/// CPU filter and the GPU layout's reference lookup share it, so they
/// agree to the bit.
pub(crate) fn anisotropic_probes(
    b: [f32; 3],
    db_dx: [f32; 3],
    db_dy: [f32; 3],
    max_samples: u32,
    out: &mut [f32],
    mut trilinear: impl FnMut([f32; 3], f32, &mut [f32]),
) {
    let metric = |d: [f32; 3]| {
        let (x, y) = (d[0] + 0.5 * d[1], d[1] * 0.866_025_4);
        (x * x + y * y).sqrt()
    };
    let (lx, ly) = (metric(db_dx), metric(db_dy));
    let (major, minor, axis) = if lx >= ly {
        (lx, ly, db_dx)
    } else {
        (ly, lx, db_dy)
    };
    let max_n = max_samples.clamp(1, MAX_PROBES) as f32;
    let n = if minor > 0.0 {
        (major / minor).ceil().clamp(1.0, max_n)
    } else {
        max_n
    };
    let lambda = level_of_footprint((major / n).max(minor));
    if n <= 1.0 {
        trilinear(b, lambda, out);
        return;
    }
    let c = out.len();
    let mut sum = [0.0f32; MAX_CHANNELS];
    let mut probe = [0.0f32; MAX_CHANNELS];
    let (sum, probe) = (&mut sum[..c], &mut probe[..c]);
    for k in 0..n as u32 {
        let t = (k as f32 + 0.5) / n - 0.5;
        let p = [0, 1, 2].map(|m| (b[m] + t * axis[m]).max(0.0));
        trilinear(p, lambda, probe);
        for (s, &x) in sum.iter_mut().zip(probe.iter()) {
            *s += x;
        }
    }
    for (o, &s) in out.iter_mut().zip(sum.iter()) {
        *o = s / n;
    }
}

/// The most probes an anisotropic lookup takes, whatever it is asked.
pub const MAX_PROBES: u32 = 64;

/// `λ = −log2(footprint)`, clamped to the levels that exist.
#[inline]
pub(crate) fn level_of_footprint(footprint: f32) -> f32 {
    if footprint.is_nan() || footprint <= 0.0 {
        return f32::from(MAX_LEVEL);
    }
    (-footprint.log2()).clamp(0.0, f32::from(MAX_LEVEL))
}

impl MeshColors {
    /// The MIP pyramid of these colours (see [`MipMap::new`]).
    pub fn mip_map(&self) -> MipMap {
        MipMap::new(self.clone())
    }
}

/// The query level that reads every primitive at its finest.
pub const FINEST_LEVEL: u8 = FINEST;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Topology;

    /// Eq. 5 at level `l` of face `f` through the general lattice lookup
    /// (vertices, edges and the face's interior alike): the reference the
    /// direct read of [`MipMap::face_level_values`] must equal bit for bit.
    fn face_level_by_lattice(m: &MipMap, f: usize, l: u8) -> Vec<f32> {
        let c = m.colors.channels;
        let (q, r) = (l + 1, 1u32 << l);
        let mut values = Vec::new();
        for i in 1..r {
            for j in 1..r - i {
                let centre = [2 * i, 2 * j, 2 * (r - i - j)];
                let mut sum = vec![0.0f64; c];
                for d in HEX {
                    let a = [0, 1, 2].map(|k| (centre[k] as i32 + d[k]) as u32);
                    let mut x = vec![0.0f32; c];
                    lattice(m, f, q, q, a, 1.0, false, &mut x);
                    accumulate(&mut sum, &x);
                }
                let mut val = vec![0.0f32; c];
                let idx = interior_index(1 << q, centre[0], centre[1]);
                combine(m.face_at(f, q, idx), &sum, 6, &mut val);
                values.extend(val);
            }
        }
        values
    }

    /// The edge rule at level `l` of edge `e` with every off-edge
    /// neighbour read through the general lattice lookup: the reference
    /// for [`MipMap::edge_level_values`].
    fn edge_level_by_lattice(m: &MipMap, e: usize, l: u8) -> Vec<f32> {
        let mc = &m.colors;
        let c = mc.channels;
        let (q, r) = (l + 1, 1u32 << l);
        let r2 = 1u32 << q;
        let mut values = Vec::new();
        for s in 1..r {
            let mut sum = vec![0.0f64; c];
            accumulate(&mut sum, m.edge_at(e, q, 2 * s - 1));
            accumulate(&mut sum, m.edge_at(e, q, 2 * s + 1));
            let mut n = 2;
            for &f in &mc.topology.edge_faces[e] {
                if f == NO_FACE {
                    continue;
                }
                let f = f as usize;
                let face = mc.topology.faces[f];
                let k = (0..3)
                    .find(|&k| mc.topology.face_edges[f][k] as usize == e)
                    .unwrap();
                let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                let t = if face[k] < face[k1] {
                    2 * s
                } else {
                    r2 - 2 * s
                };
                for (dk, dk1) in [(1, 0), (0, 1)] {
                    let mut b = [0u32; 3];
                    b[k] = r2 - t - dk;
                    b[k1] = t - dk1;
                    b[k2] = 1;
                    let mut x = vec![0.0f32; c];
                    lattice(m, f, q, q, b, 1.0, false, &mut x);
                    accumulate(&mut sum, &x);
                    n += 1;
                }
            }
            let mut val = vec![0.0f32; c];
            combine(m.edge_at(e, q, 2 * s), &sum, n, &mut val);
            values.extend(val);
        }
        values
    }

    #[test]
    fn levels_read_directly_equal_the_rules_through_the_lattice_lookup() {
        let (positions, faces) = crate::test_mesh::wavy_grid(6);
        let topology = Topology::new(positions.len(), &faces).unwrap();
        let levels: Vec<u32> = (0..faces.len()).map(|f| 1 << (f * 7 % 6)).collect();
        let mut colors = MeshColors::new(topology, &levels, 3).unwrap();
        for (i, x) in colors.samples_mut().iter_mut().enumerate() {
            *x = (i as f32 * 0.37).sin() * if i % 11 == 0 { -0.0 } else { 1.0 };
        }
        let m = MipMap::new(colors);
        let c = m.colors.channels;
        let mut checked = 0;
        for f in 0..faces.len() {
            for l in 2..m.colors.face_level[f] {
                let first = m.face_offset[f] + FACE_LEVEL_OFFSET[l as usize];
                let got = &m.data[first * c..][..samples_per_face(1 << l) as usize * c];
                let want = face_level_by_lattice(&m, f, l);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(got), bits(&want), "face {f}, level {l}");
                checked += 1;
            }
        }
        assert!(checked > 20, "{checked} face levels checked");
        let mut checked = 0;
        for e in 0..m.colors.edge_level.len() {
            for l in 1..m.colors.edge_level[e] {
                let first = m.edge_offset[e] + edge_level_offset(l);
                let got = &m.data[first * c..][..((1usize << l) - 1) * c];
                let want = edge_level_by_lattice(&m, e, l);
                let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(got), bits(&want), "edge {e}, level {l}");
                checked += 1;
            }
        }
        assert!(checked > 20, "{checked} edge levels checked");
    }
}
