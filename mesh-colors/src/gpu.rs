//! Real-time rendering (Sec. 5.3): every mesh colour and every MIP level
//! in 2D textures, with a per-face table that a fragment shader reads by a
//! flat face id, so the shader filters per face exactly as the CPU does.
//! WebGL2 has no texture buffers: a linear index `i` is the texel
//! `(i % W, i / W)` of a texture `W` texels wide, read with `texelFetch`.
//!
//! [`GpuLayout::new`] packs a [`MipMap`]; after a stroke,
//! [`MipMap::refresh`] and [`GpuLayout::refresh`] rewrite only the values
//! near the stroke and say which texel rectangles changed (for
//! `texSubImage2D`); after a resolution change
//! [`MipMap::refresh_resolutions`] and [`GpuLayout::refresh_resolutions`]
//! do the same for the resampled faces (which move to blocks of their new
//! size when they grew) and the table entries that point to them
//! ([`GpuLayout::update`] repacks everything); [`GpuLayout::lookup`] is the CPU
//! reference of the shader: it reads *only* the packed arrays, with the
//! formulas below, and equals [`MeshColors::nearest`],
//! [`MeshColors::linear`], [`MipMap::at_level`], [`MipMap::trilinear`] and
//! [`MipMap::anisotropic`] bit for bit (the tests check every filter on
//! meshes of mixed resolution).
//!
//! # Textures
//!
//! Both are row-major, row `y = 0` first (the order `texImage2D` uploads),
//! `W = width()` texels wide, linear index `t` at `(t % W, t / W)`.
//!
//! - **Samples**: `RGBA32F` (`internalFormat = gl.RGBA32F, format =
//!   gl.RGBA, type = gl.FLOAT`, read with `texelFetch` on a `sampler2D`
//!   with `NEAREST` filtering), [`GpuLayout::sample_texels`]: 4 `f32` per
//!   texel, little-endian as a `Float32Array` over the same bytes. Value
//!   `i` occupies `P = ⌈channels / 4⌉` texels from `t = i · P`; channel
//!   `ch` is component `ch % 4` of texel `i · P + ch / 4`; unused
//!   components are 0. Values are the colours' own, in their own units
//!   (no sRGB encoding: output conversion is the page's). Each vertex's,
//!   edge's and face's levels are a block of consecutive values, where
//!   the face table says. [`GpuLayout::new`] and [`GpuLayout::update`]
//!   lay the blocks out in [`MipMap::data`]'s order (value `i` is the
//!   `MipMap::data` index divided by the channel count) in
//!   `sample_height() = ⌈(values · P) / W⌉` rows, the last padded with
//!   zeros; [`GpuLayout::refresh_resolutions`] moves a primitive that
//!   grew to a block of its new size and leaves the others in place, so
//!   blocks may then come in any order with unused values between them
//!   (never read), and a repack for lack of room adds spare rows.
//! - **Face table**: `RGBA32UI` (`gl.RGBA32UI, gl.RGBA_INTEGER,
//!   gl.UNSIGNED_INT`, a `usampler2D`), [`GpuLayout::face_texels`]: face
//!   `f`'s [`FACE_WORDS`] = 8 words are texels `2f` and `2f + 1` (words
//!   `w0..w3` = `.rgba` of the first, `w4..w7` of the second):
//!
//!   | word | meaning |
//!   |---|---|
//!   | `w0` | `F`: value index of the face's interior, level 0 |
//!   | `w1, w2, w3` | `V_k`: value index of corner `k`'s vertex, level 0 |
//!   | `w4, w5, w6` | `E_k`: value index of local edge `k` (corner `k` → `k+1`), level 0 |
//!   | `w7` | bits 0–3 `n` (face level, `R = 2^n`), 4–7 / 8–11 / 12–15 `vl_k` (vertex levels), 16–19 / 20–23 / 24–27 `el_k` (edge levels), bit `28 + k` set when edge `k` runs canonically from corner `k` to corner `k + 1` (the corner's vertex index is the smaller) |
//!
//!   Levels are at most [`crate::MAX_LEVEL`]; `el_k ≤ n ≤ max vl_k`.
//!
//! # What a value index is
//!
//! Level `l` of a vertex is at `V_k + l` (`l ≤ vl_k`); sample `s`
//! (`1 ≤ s < 2^l`, counted from the edge's smaller vertex) of level `l` of
//! an edge at `E_k + (2^l − 1 − l) + s − 1` (`l ≤ el_k`); interior sample
//! `C_ij` (`i, j ≥ 1`, `i + j < 2^l`) of level `l` of the face at
//! `F + O(l) + (i − 1)(2^l − 1) − (i − 1)i/2 + (j − 1)`, with
//! `O(l) = Σ_{m<l} (2^m − 1)(2^m − 2)/2` (0, 0, 0, 3, 24, 129, …).
//!
//! # The lookup, as the shader computes it
//!
//! Inputs: the face `f` (flat), the barycentrics `b` (weight `k` for
//! corner `k`) and a query level `q` (`q = 255` means "every primitive at
//! its finest": nearest and linear filtering). Reading corner `k` at `q`
//! means its level `min(q, vl_k)`; edge `k` at `q` has level
//! `le = min(q, el_k)` and *node* `i ∈ 0..=2^le` is its start vertex
//! (`i = 0`), its end vertex (`i = 2^le`) or its sample `i`, where the
//! start is corner `k` if bit `28 + k` is set and corner `k + 1` if not.
//!
//! 1. **Place** (Fig. 7, and the continuity rule of Sec. 3.2):
//!    `c_k = b_k > 0 ? b_k : 0`. With two zeros, the point is corner `k`
//!    (the positive one): its value. With one zero `c_m`, it is on edge
//!    `k = (m + 1) % 3` at canonical parameter `t = c_e / (c_s + c_e)`,
//!    `c_s` and `c_e` the weights of its start and end corner; then
//!    `x = t · 2^le`, `i = min(⌊x⌋, 2^le − 1)`, `φ = x − i`, and the value
//!    is `(1 − φ)·node_i + φ·node_{i+1}` (nearest: `node_{i + (φ ≥ 0.5)}`).
//!    Otherwise the point is inside (all three zero: `c = (1, 1, 1)`).
//! 2. **Inside**, face level `lf = min(q, n)`, `r = 2^lf`:
//!    `s = r / (c_0 + c_1 + c_2)`, `x = c_0 s`, `y = c_1 s`,
//!    `i = min(⌊x⌋, r − 1)`, `j = min(⌊y⌋, r − 1 − i)`, `φx = x − i`,
//!    `φy = y − j`, `k = r − i − j`. If `φx + φy ≤ 1` or `k = 1`: lattice
//!    points `(i, j, k)`, `(i+1, j, k−1)`, `(i, j+1, k−1)` with weights
//!    `1 − φx − φy, φx, φy`; else `(i+1, j+1, k−2)`, `(i+1, j, k−1)`,
//!    `(i, j+1, k−1)` with `φx + φy − 1, 1 − φy, 1 − φx`. The value is
//!    `Σ w_t · L(a_t)` (nearest: `L` of the largest weight, the first on a
//!    tie).
//! 3. **A lattice point** `a` of resolution `r`: if `a_k = r`, corner `k`;
//!    if `a_m = 0`, edge `k = (m + 1) % 3` at canonical position
//!    `p = bit(28+k) ? a_{k+1} : r − a_{k+1}` in steps of `1/r`; with
//!    `d = lf − le`, `p = 2^d·i + ρ`: `node_i` if `ρ = 0`, else
//!    `(1 − ρ/2^d)·node_i + (ρ/2^d)·node_{i+1}` — a face finer than its
//!    edge interpolates the edge, which keeps the edge continuous —
//!    (nearest: `node_{i + (2ρ ≥ 2^d)}`); otherwise the interior sample
//!    `C_{a_0 a_1}` at level `lf`.
//! 4. **MIP levels**: `at_level(q)` is steps 1–3 at `q`. **Trilinear**
//!    from a footprint `w` (barycentric units): `λ = clamp(−log2 w, 0,
//!    MAX_LEVEL)` (`λ = MAX_LEVEL` for `w ≤ 0` or NaN), `l = ⌊λ⌋`,
//!    `α = λ − l`; the value at `l`, blended as `(1 − α)·v_l + α·v_{l+1}`
//!    unless `α = 0` or `l ≥` the level of the primitive the point lies
//!    on (`n` inside, `el_k` on edge `k`, `vl_k` on corner `k`).
//!    **Anisotropic** (Sec. 4.3) from the screen derivatives `∂b/∂x`,
//!    `∂b/∂y`: lengths on the equilateral triangle,
//!    `|d| = √((d_0 + d_1/2)² + (0.8660254 d_1)²)`; the longer is the
//!    major axis `D`, `N = clamp(⌈major / minor⌉, 1, max_samples)`
//!    (`max_samples` when `minor = 0`), level from
//!    `max(major / N, minor)`; `N = 1` is one trilinear lookup, else the
//!    mean of trilinear lookups at `b + τ·D` clamped to `≥ 0`,
//!    `τ = (m + ½)/N − ½`, `m = 0..N−1`.
//!
//! The CPU filters associate two products differently in one place, and
//! [`GpuLayout::lookup`] follows them to stay bit-identical: a MIP lookup
//! inside a face (at a level `q ≤ n`, or at or above the finest level of
//! the face's corners) first evaluates each lattice value `L(a_t)` and
//! then sums `w_t · L(a_t)` (the MIP map's per-face cache), while nearest,
//! linear and the remaining MIP case add `(w_t (1 − ρ/2^d))·node_i +
//! (w_t ρ/2^d)·node_{i+1}` directly. The two differ by at most an ulp or
//! two, far below the 1/255 of an 8-bit output; a shader may use either.
//!
//! [`MeshColors::nearest`]: crate::MeshColors::nearest
//! [`MeshColors::linear`]: crate::MeshColors::linear

use std::collections::BTreeMap;

use crate::filter::triangle;
use crate::mip::{FACE_LEVEL_OFFSET, MipMap, edge_level_offset, level_of_footprint};
use crate::structure::{MeshColors, interior_index};
use crate::{Error, MAX_CHANNELS, MAX_LEVEL};

/// Words per face in the face table (two `RGBA32UI` texels).
pub const FACE_WORDS: usize = 8;

/// The query level meaning "every primitive at its finest".
const FINEST: u8 = u8::MAX;

/// A filter of [`GpuLayout::lookup`], each the twin of a CPU filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Filter {
    /// [`crate::MeshColors::nearest`].
    Nearest,
    /// [`crate::MeshColors::linear`] (Fig. 7).
    Linear,
    /// [`MipMap::at_level`]: linear at one MIP level.
    Level(u8),
    /// [`MipMap::trilinear`] with this footprint (barycentric units).
    Trilinear {
        /// The filter width as a fraction of the face's edge.
        footprint: f32,
    },
    /// [`MipMap::anisotropic`] (Sec. 4.3).
    Anisotropic {
        /// Screen-space derivative of the barycentrics along x.
        db_dx: [f32; 3],
        /// Screen-space derivative of the barycentrics along y.
        db_dy: [f32; 3],
        /// The most probes (capped at [`MAX_PROBES`](crate::MAX_PROBES)).
        max_samples: u32,
    },
}

/// A rectangle of texels, in texels, `(x, y)` its lowest corner in the
/// row-major layout: the arguments of `texSubImage2D(target, 0, x, y,
/// width, height, …)`, whose data is the layout's texels from linear
/// index `y · W + x`, `width` per row (one row, or whole rows with
/// `x = 0`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TexelRect {
    /// First column.
    pub x: u32,
    /// First row.
    pub y: u32,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

/// What [`GpuLayout::update`] changed.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Changes {
    /// The textures' sizes changed (a resolution change): allocate them
    /// again with `texImage2D` from the whole arrays; the rectangles then
    /// cover everything.
    pub resized: bool,
    /// Changed rectangles of the sample texture.
    pub samples: Vec<TexelRect>,
    /// Changed rectangles of the face table.
    pub faces: Vec<TexelRect>,
}

impl Changes {
    /// Whether nothing changed.
    pub fn is_empty(&self) -> bool {
        !self.resized && self.samples.is_empty() && self.faces.is_empty()
    }
}

/// The packed arrays of a [`GpuLayout`], as plain data (to send to a page,
/// or to build a layout from).
#[derive(Debug, Clone, PartialEq)]
pub struct GpuParts {
    /// Texels per row, `W`.
    pub width: u32,
    /// Channels per sample.
    pub channels: usize,
    /// Faces in the table.
    pub face_count: usize,
    /// The sample texture, `4 · W · rows` values.
    pub samples: Vec<f32>,
    /// The face table, `4 · W · rows` words.
    pub faces: Vec<u32>,
}

/// All samples and MIP levels of mesh colours in 2D textures, with the
/// per-face table (see the [module documentation](self) for the exact
/// format and the shader's formulas).
#[derive(Debug, Clone, PartialEq)]
pub struct GpuLayout {
    max_width: u32,
    parts: GpuParts,
    /// Where each primitive's levels are in the sample texture (`None`
    /// for a layout built from parts: then value `i` of the pyramid is at
    /// texel `i · P`, as [`GpuLayout::new`] packs it).
    blocks: Option<Blocks>,
}

/// The sample texture's allocation: per vertex, edge and face, its block
/// of values `(first, room)` (its levels from `first`, `room` values
/// reserved), the free blocks by room, and the end of the values in use.
#[derive(Debug, Clone, PartialEq, Default)]
struct Blocks {
    vertex: Vec<(u32, u32)>,
    edge: Vec<(u32, u32)>,
    face: Vec<(u32, u32)>,
    /// The face levels the blocks hold (a pyramid of other levels needs
    /// [`GpuLayout::refresh_resolutions`]).
    face_level: Vec<u8>,
    /// Blocks given up by primitives that grew, by room (a `BTreeMap`
    /// so that allocation is the same on every run).
    free: BTreeMap<u32, Vec<u32>>,
    /// Values from here on are unused.
    end: usize,
}

impl Blocks {
    /// A block of `len` values: a free one of that room, else at the end.
    fn allocate(&mut self, len: u32) -> (u32, u32) {
        if let Some(at) = self.free.get_mut(&len).and_then(Vec::pop) {
            return (at, len);
        }
        let at = self.end as u32;
        self.end += len as usize;
        (at, len)
    }

    /// Gives up `block` (empty blocks are not kept).
    fn release(&mut self, block: (u32, u32)) {
        if block.1 > 0 {
            self.free.entry(block.1).or_default().push(block.0);
        }
    }

    /// The block of the primitive whose levels start at pyramid value
    /// `start`, as `(pyramid start, values, first value in the texture)`,
    /// for primitive `g` in pyramid order (vertices, edges, faces).
    fn primitive(&self, mip: &MipMap, g: usize) -> (usize, usize, usize) {
        let mc = &mip.colors;
        let (nv, ne) = (self.vertex.len(), self.edge.len());
        if g < nv {
            let len = mc.vertex_level[g] as usize + 1;
            (mip.vertex_offset[g], len, self.vertex[g].0 as usize)
        } else if g < nv + ne {
            let e = g - nv;
            let len = edge_level_offset(mc.edge_level[e] + 1);
            (mip.edge_offset[e], len, self.edge[e].0 as usize)
        } else {
            let f = g - nv - ne;
            let len = FACE_LEVEL_OFFSET[mc.face_level[f] as usize + 1];
            (mip.face_offset[f], len, self.face[f].0 as usize)
        }
    }

    /// Calls `copy(pyramid value, texture value, count)` for each part of
    /// `spans` (sorted, disjoint value spans of `mip`, which has these
    /// blocks' levels) within one primitive.
    fn pieces(
        &self,
        mip: &MipMap,
        spans: &[(usize, usize)],
        mut copy: impl FnMut(usize, usize, usize),
    ) {
        let n = self.vertex.len() + self.edge.len() + self.face.len();
        for &(a, b) in spans {
            // The last primitive starting at or before `a`.
            let (mut lo, mut hi) = (0, n);
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if self.primitive(mip, mid).0 <= a {
                    lo = mid + 1;
                } else {
                    hi = mid;
                }
            }
            let mut g = lo.saturating_sub(1);
            while g < n {
                let (start, len, at) = self.primitive(mip, g);
                if start >= b {
                    break;
                }
                let (from, to) = (a.max(start), b.min(start + len));
                if from < to {
                    copy(from, at + (from - start), to - from);
                }
                g += 1;
            }
        }
    }
}

/// The sample texels a [`GpuLayout`] needs for colours on `topology` with
/// every face at `resolution` (a power of two; beyond `2^MAX_LEVEL` it
/// counts as that) and `channels` channels: every MIP level of every
/// vertex, edge and face, `⌈channels / 4⌉` texels a value. Lets a caller
/// refuse a resolution before building colours that would not fit its
/// textures (the rows a layout has are these divided by its width).
pub fn uniform_sample_texels(topology: &crate::Topology, resolution: u32, channels: usize) -> u64 {
    let n = resolution.max(1).ilog2().min(u32::from(MAX_LEVEL)) as usize;
    let values = topology.vertex_count() as u64 * (n as u64 + 1)
        + topology.edges().len() as u64 * edge_level_offset(n as u8 + 1) as u64
        + topology.faces().len() as u64 * FACE_LEVEL_OFFSET[n + 1] as u64;
    values.saturating_mul(channels.div_ceil(4) as u64)
}

/// Changed spans closer than this many texels are uploaded as one.
const MERGE_GAP: usize = 64;

impl GpuLayout {
    /// Packs `mip` into textures at most `max_width` texels wide and
    /// `max_width` rows high (WebGL2's `MAX_TEXTURE_SIZE` bounds both; it
    /// is at least 2048). The width is `max_width`, or less when
    /// everything fits in one row.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] for `max_width = 0`;
    /// [`Error::TooLarge`] when the samples or the face table need more
    /// than `max_width` rows, or an index would not fit the table's `u32`.
    pub fn new(mip: &MipMap, max_width: u32) -> Result<Self, Error> {
        Self::packed(mip, max_width, false)
    }

    /// As [`GpuLayout::new`], with as many sample rows again spare (up to
    /// `max_width` rows, as a repack leaves them): room for the faces that
    /// [`GpuLayout::refresh_resolutions`] raises, so that the first raise
    /// after loading does not pack everything again. The spare rows are
    /// zeros after the first [`GpuLayout::used_sample_rows`].
    ///
    /// # Errors
    /// As for [`GpuLayout::new`].
    pub fn with_spare_rows(mip: &MipMap, max_width: u32) -> Result<Self, Error> {
        Self::packed(mip, max_width, true)
    }

    fn packed(mip: &MipMap, max_width: u32, spare: bool) -> Result<Self, Error> {
        if max_width == 0 {
            return Err(Error::InvalidArgument {
                argument: "max_width",
                reason: "must be at least 1 texel",
            });
        }
        let (parts, blocks) = pack(mip, max_width, spare)?;
        Ok(Self {
            max_width,
            parts,
            blocks: Some(blocks),
        })
    }

    /// A layout from its parts (for example received, or altered in a
    /// test). Lookups read out-of-range texels as 0 and clamp the levels,
    /// so inconsistent parts give wrong values, never a panic.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming the part whose size does not fit
    /// (`width` 0, `channels` outside `1..=MAX_CHANNELS`, an array whose
    /// length is not a whole number of rows, a face table shorter than
    /// `face_count` faces).
    pub fn from_parts(parts: GpuParts) -> Result<Self, Error> {
        let w = parts.width as usize;
        let bad = |argument, reason| Err(Error::InvalidArgument { argument, reason });
        if w == 0 {
            return bad("width", "must be at least 1 texel");
        }
        if parts.channels == 0 || parts.channels > MAX_CHANNELS {
            return bad("channels", "must be in 1..=MAX_CHANNELS");
        }
        if !parts.samples.len().is_multiple_of(4 * w) {
            return bad("samples", "is not a whole number of rows of 4 · width");
        }
        if !parts.faces.len().is_multiple_of(4 * w) {
            return bad("faces", "is not a whole number of rows of 4 · width");
        }
        if parts.faces.len() / FACE_WORDS < parts.face_count {
            return bad("faces", "holds fewer than face_count faces");
        }
        Ok(Self {
            max_width: parts.width,
            parts,
            blocks: None,
        })
    }

    /// The parts, as plain data.
    pub fn into_parts(self) -> GpuParts {
        self.parts
    }

    /// Texels per row, `W`, of both textures.
    pub fn width(&self) -> u32 {
        self.parts.width
    }

    /// Rows of the sample texture.
    pub fn sample_height(&self) -> u32 {
        (self.parts.samples.len() / (4 * self.parts.width as usize)) as u32
    }

    /// Rows of the sample texture that hold values: every row after them
    /// is zeros (spare room), so a page can be sent these and allocate
    /// [`GpuLayout::sample_height`].
    pub fn used_sample_rows(&self) -> u32 {
        let w = self.parts.width as usize;
        match &self.blocks {
            Some(b) => {
                let p = self.parts.channels.div_ceil(4);
                ((b.end * p).div_ceil(w).max(1) as u32).min(self.sample_height())
            }
            None => self.sample_height(),
        }
    }

    /// Rows of the face table.
    pub fn face_height(&self) -> u32 {
        (self.parts.faces.len() / (4 * self.parts.width as usize)) as u32
    }

    /// The sample texture: `4 · width() · sample_height()` values, RGBA
    /// per texel, row-major.
    pub fn sample_texels(&self) -> &[f32] {
        &self.parts.samples
    }

    /// The face table: `4 · width() · face_height()` words, RGBA per
    /// texel, row-major; face `f` at words `8f .. 8f + 8`.
    pub fn face_texels(&self) -> &[u32] {
        &self.parts.faces
    }

    /// Channels per sample.
    pub fn channels(&self) -> usize {
        self.parts.channels
    }

    /// Texels per value, `⌈channels / 4⌉`.
    pub fn texels_per_value(&self) -> usize {
        self.parts.channels.div_ceil(4)
    }

    /// Faces in the table.
    pub fn face_count(&self) -> usize {
        self.parts.face_count
    }

    /// Repacks `mip` (the same mesh after strokes or resolution changes)
    /// and returns the rectangles to upload again. The cost is one pass
    /// over both arrays; rectangles are merged across gaps of fewer than
    /// 64 texels.
    ///
    /// # Errors
    /// As for [`GpuLayout::new`] (the layout is unchanged then).
    pub fn update(&mut self, mip: &MipMap) -> Result<Changes, Error> {
        let (new, blocks) = pack(mip, self.max_width, false)?;
        let w = new.width as usize;
        let resized = new.width != self.parts.width
            || new.samples.len() != self.parts.samples.len()
            || new.faces.len() != self.parts.faces.len()
            || new.channels != self.parts.channels;
        let changes = if resized {
            Changes {
                resized: true,
                samples: whole(w, new.samples.len() / 4),
                faces: whole(w, new.faces.len() / 4),
            }
        } else {
            Changes {
                resized: false,
                samples: rects(
                    w,
                    diff(&self.parts.samples, &new.samples, |a, b| {
                        a.to_bits() == b.to_bits()
                    }),
                ),
                faces: rects(w, diff(&self.parts.faces, &new.faces, |a, b| a == b)),
            }
        };
        self.parts = new;
        self.blocks = Some(blocks);
        Ok(changes)
    }

    /// Rewrites only the values of `spans` (value indices `[start, end)`,
    /// as [`MipMap::refresh`] returns them after a stroke) from `mip`, and
    /// returns the rectangles whose texels changed. The cost follows the
    /// spans, not the mesh. `mip` must have the layout this was packed
    /// from (same resolutions); after a resolution change use
    /// [`GpuLayout::refresh_resolutions`] (or [`GpuLayout::update`]).
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming `mip` when its channel, face or
    /// value counts or its face resolutions differ from this layout's, or
    /// `spans` when a span leaves the values; nothing changes then.
    pub fn refresh(&mut self, mip: &MipMap, spans: &[(usize, usize)]) -> Result<Changes, Error> {
        let c = mip.colors.channels;
        let p = c.div_ceil(4);
        let values = mip.data.len() / c;
        let w = self.parts.width as usize;
        let same = match &self.blocks {
            Some(b) => {
                b.face_level == mip.colors.face_level
                    && b.vertex.len() == mip.vertex_offset.len()
                    && b.edge.len() == mip.edge_offset.len()
            }
            None => (values * p).div_ceil(w).max(1) == self.sample_height() as usize,
        };
        if c != self.parts.channels || mip.colors.face_level.len() != self.parts.face_count || !same
        {
            return Err(Error::InvalidArgument {
                argument: "mip",
                reason: "does not have this layout's channels, faces or values \
                         (after a resolution change, use refresh_resolutions)",
            });
        }
        let spans = checked_spans(spans, values)?;
        let samples = &mut self.parts.samples;
        let mut changed: Vec<(usize, usize)> = Vec::new();
        let mut run = |from: usize, at: usize, len: usize| {
            rewrite_run(samples, &mip.data, (from, at, len), (c, p), &mut changed);
        };
        match &self.blocks {
            Some(blocks) => blocks.pieces(mip, &spans, run),
            None => {
                for &(a, b) in &spans {
                    run(a, a, b - a);
                }
            }
        }
        Ok(Changes {
            resized: false,
            samples: rects(w, merged(changed)),
            faces: Vec::new(),
        })
    }

    /// Brings the textures up to date after a resolution change: `mip`
    /// as [`MipMap::refresh_resolutions`] left it, `spans` the value spans
    /// it returned. Each primitive keeps its block of the sample texture
    /// while its levels fit there (a face lowered keeps its room); one
    /// that grew gets a block of its new size — one given up by an earlier
    /// change, else after the values in use — and the block it left is
    /// kept for later. So only the values of `spans` and of the moved
    /// primitives are written, and only the table entries of faces whose
    /// levels or blocks changed: the rectangles returned, for
    /// `texSubImage2D`. The textures keep their size unless the sample
    /// texture is full: then everything is packed again as by
    /// [`GpuLayout::new`] with spare rows (as many rows again as needed, up
    /// to `max_width` rows) for the changes to come, and `resized` is set.
    /// Either way [`GpuLayout::lookup`] gives what a new layout of `mip`
    /// gives, bit for bit. The cost is a pass over the faces, edges and
    /// vertices (no values) and the values written.
    ///
    /// # Errors
    /// [`Error::InvalidArgument`] naming `mip` when its channels or face
    /// count differ from this layout's, or `spans` when a span leaves the
    /// values; [`Error::TooLarge`] as for [`GpuLayout::new`] when a repack
    /// does not fit. Nothing changes then.
    pub fn refresh_resolutions(
        &mut self,
        mip: &MipMap,
        spans: &[(usize, usize)],
    ) -> Result<Changes, Error> {
        let mc = &mip.colors;
        let c = mc.channels;
        if c != self.parts.channels || mc.face_level.len() != self.parts.face_count {
            return Err(Error::InvalidArgument {
                argument: "mip",
                reason: "does not have this layout's channels or faces",
            });
        }
        let spans = checked_spans(spans, mip.data.len() / c)?;
        let Some(mut blocks) = self.blocks.clone().filter(|b| {
            b.vertex.len() == mc.vertex_level.len() && b.edge.len() == mc.edge_level.len()
        }) else {
            return self.regrow(mip);
        };
        let (nv, ne) = (blocks.vertex.len(), blocks.edge.len());
        let n = nv + ne + blocks.face.len();
        let mut moved = Vec::new();
        for g in 0..n {
            let len = blocks.primitive(mip, g).1 as u32;
            let slot = if g < nv {
                blocks.vertex[g]
            } else if g < nv + ne {
                blocks.edge[g - nv]
            } else {
                blocks.face[g - nv - ne]
            };
            if len <= slot.1 {
                continue;
            }
            let new = blocks.allocate(len);
            blocks.release(slot);
            *(if g < nv {
                &mut blocks.vertex[g]
            } else if g < nv + ne {
                &mut blocks.edge[g - nv]
            } else {
                &mut blocks.face[g - nv - ne]
            }) = new;
            moved.push(g);
        }
        let p = c.div_ceil(4);
        let room = self.parts.samples.len() / 4 / p;
        if blocks.end > room || blocks.end > u32::MAX as usize {
            return self.regrow(mip);
        }
        blocks.face_level.clone_from(&mc.face_level);
        let samples = &mut self.parts.samples;
        let mut changed: Vec<(usize, usize)> = Vec::new();
        // Values `from..from + len` of the pyramid into texture values
        // from `at`.
        let mut write = |from: usize, at: usize, len: usize| {
            let (Some(values), Some(texels)) = (
                mip.data.get(from * c..(from + len) * c),
                samples.get_mut(at * p * 4..(at + len) * p * 4),
            ) else {
                return;
            };
            for (texels, value) in texels.chunks_exact_mut(4 * p).zip(values.chunks_exact(c)) {
                texels[..c].copy_from_slice(value);
                texels[c..].fill(0.0);
            }
            changed.push((at * p, (at + len) * p));
        };
        for &g in &moved {
            let (start, len, at) = blocks.primitive(mip, g);
            write(start, at, len);
        }
        blocks.pieces(mip, &spans, &mut write);
        let mut faces_changed = Vec::new();
        for f in 0..mc.face_level.len() {
            let words = face_words(mc, &blocks, f);
            if let Some(old) = self
                .parts
                .faces
                .get_mut(f * FACE_WORDS..(f + 1) * FACE_WORDS)
                && old != words
            {
                old.copy_from_slice(&words);
                faces_changed.push((2 * f, 2 * f + 2));
            }
        }
        self.blocks = Some(blocks);
        let w = self.parts.width as usize;
        Ok(Changes {
            resized: false,
            samples: rects(w, merged(changed)),
            faces: rects(w, merged(faces_changed)),
        })
    }

    /// Packs `mip` again with spare rows: every texel is new.
    fn regrow(&mut self, mip: &MipMap) -> Result<Changes, Error> {
        let (parts, blocks) = pack(mip, self.max_width, true)?;
        let w = parts.width as usize;
        let changes = Changes {
            resized: true,
            samples: whole(w, parts.samples.len() / 4),
            faces: whole(w, parts.faces.len() / 4),
        };
        self.parts = parts;
        self.blocks = Some(blocks);
        Ok(changes)
    }

    /// The filtered value at barycentrics `b` of face `face` into `out`
    /// (`channels()` values), read from the packed arrays alone by the
    /// formulas of the [module documentation](self); equal bit for bit to
    /// the CPU filter each [`Filter`] names.
    ///
    /// # Errors
    /// [`Error::MissingFace`], or [`Error::ChannelMismatch`] when
    /// `out.len() != channels()`.
    pub fn lookup(
        &self,
        face: usize,
        b: [f32; 3],
        filter: Filter,
        out: &mut [f32],
    ) -> Result<(), Error> {
        if face >= self.parts.face_count {
            return Err(Error::MissingFace {
                face,
                count: self.parts.face_count,
            });
        }
        if out.len() != self.parts.channels {
            return Err(Error::ChannelMismatch {
                what: "lookup output",
                expected: self.parts.channels,
                got: out.len(),
            });
        }
        let v = View::decode(self, face);
        match filter {
            Filter::Nearest => v.eval(v.place(b), FINEST, true, out),
            Filter::Linear => v.eval(v.place(b), FINEST, false, out),
            Filter::Level(l) => v.mip(v.place(b), l, out),
            Filter::Trilinear { footprint } => v.trilinear(b, level_of_footprint(footprint), out),
            Filter::Anisotropic {
                db_dx,
                db_dy,
                max_samples,
            } => v.anisotropic(b, db_dx, db_dy, max_samples, out),
        }
        Ok(())
    }

    /// Texel `t`'s four components, read at `(t % W, t / W)` (0 outside).
    #[inline]
    fn fetch(&self, t: usize) -> [f32; 4] {
        let w = self.parts.width as usize;
        let (x, y) = (t % w, t / w);
        let at = (y * w + x) * 4;
        match self.parts.samples.get(at..at + 4) {
            Some(s) => [s[0], s[1], s[2], s[3]],
            None => [0.0; 4],
        }
    }

    /// Adds `w ×` pyramid value `i` to `out`.
    #[inline]
    fn add(&self, i: usize, w: f32, out: &mut [f32]) {
        let p = self.texels_per_value();
        for (g, chunk) in out.chunks_mut(4).enumerate() {
            let texel = self.fetch(i * p + g);
            for (o, &x) in chunk.iter_mut().zip(&texel) {
                *o += w * x;
            }
        }
    }
}

/// Packs a pyramid at width `max_width` (checked ≥ 1), value `i` at
/// texel `i · P`; with `spare`, the sample texture gets half as many rows
/// again as it needs (at least one, at most `max_width` in all).
fn pack(mip: &MipMap, max_width: u32, spare: bool) -> Result<(GpuParts, Blocks), Error> {
    let mc = &mip.colors;
    let c = mc.channels;
    let p = c.div_ceil(4);
    let values = mip.data.len() / c;
    let texels = values.saturating_mul(p);
    let face_texels = mc.face_level.len().saturating_mul(2);
    let w = (max_width as usize).min(texels.max(face_texels).max(1));
    let rows = |n: usize| n.div_ceil(w).max(1);
    for (what, n) in [
        ("the sample texture", rows(texels)),
        ("the face table", rows(face_texels)),
    ] {
        if n > max_width as usize {
            return Err(Error::TooLarge {
                what,
                requested: n as u64,
                budget: u64::from(max_width),
                unit: "rows",
            });
        }
    }
    if values > u32::MAX as usize {
        return Err(Error::TooLarge {
            what: "the MIP pyramid's indices",
            requested: values as u64,
            budget: u64::from(u32::MAX),
            unit: "values",
        });
    }
    let sample_rows = if spare {
        // A detail brush raising a thousand faces of a converted model
        // adds half its samples again; a face that grows leaves its old
        // block free, so room for as much again spares most repacks.
        (2 * rows(texels)).min(max_width as usize)
    } else {
        rows(texels)
    };
    let mut samples = vec![0.0f32; sample_rows * w * 4];
    for (i, value) in mip.data.chunks_exact(c).enumerate() {
        for (ch, &x) in value.iter().enumerate() {
            samples[(i * p + ch / 4) * 4 + ch % 4] = x;
        }
    }
    let block = |at: usize, len: usize| (at as u32, len as u32);
    let blocks = Blocks {
        vertex: (0..mc.vertex_level.len())
            .map(|v| block(mip.vertex_offset[v], mc.vertex_level[v] as usize + 1))
            .collect(),
        edge: (0..mc.edge_level.len())
            .map(|e| block(mip.edge_offset[e], edge_level_offset(mc.edge_level[e] + 1)))
            .collect(),
        face: (0..mc.face_level.len())
            .map(|f| {
                block(
                    mip.face_offset[f],
                    FACE_LEVEL_OFFSET[mc.face_level[f] as usize + 1],
                )
            })
            .collect(),
        face_level: mc.face_level.clone(),
        free: BTreeMap::new(),
        end: values,
    };
    let mut faces = vec![0u32; rows(face_texels) * w * 4];
    for (f, words) in faces
        .chunks_exact_mut(FACE_WORDS)
        .take(mc.face_level.len())
        .enumerate()
    {
        words.copy_from_slice(&face_words(mc, &blocks, f));
    }
    let parts = GpuParts {
        width: w as u32,
        channels: c,
        face_count: mc.face_level.len(),
        samples,
        faces,
    };
    Ok((parts, blocks))
}

/// Face `f`'s entry in the table (see the module documentation), its
/// primitives where `blocks` put them.
fn face_words(mc: &MeshColors, blocks: &Blocks, f: usize) -> [u32; FACE_WORDS] {
    let t = &mc.topology;
    let face = t.faces[f];
    let fe = t.face_edges[f];
    let mut words = [0u32; FACE_WORDS];
    words[0] = blocks.face[f].0;
    let mut bits = u32::from(mc.face_level[f]);
    for k in 0..3 {
        let v = face[k] as usize;
        let e = fe[k] as usize;
        words[1 + k] = blocks.vertex[v].0;
        words[4 + k] = blocks.edge[e].0;
        bits |= u32::from(mc.vertex_level[v]) << (4 + 4 * k);
        bits |= u32::from(mc.edge_level[e]) << (16 + 4 * k);
        if face[k] < face[(k + 1) % 3] {
            bits |= 1 << (28 + k);
        }
    }
    words[7] = bits;
    words
}

/// Writes the pyramid's values `from..from + len` (of `data`, `c`
/// channels, `p` texels each) into texture values from `at`, those that
/// differ only, and adds the texels written to `changed` (joined across
/// gaps of fewer than [`MERGE_GAP`] texels).
fn rewrite_run(
    samples: &mut [f32],
    data: &[f32],
    (from, at, len): (usize, usize, usize),
    (c, p): (usize, usize),
    changed: &mut Vec<(usize, usize)>,
) {
    let (Some(values), Some(texels)) = (
        data.get(from * c..(from + len) * c),
        samples.get_mut(at * p * 4..(at + len) * p * 4),
    ) else {
        return;
    };
    for (k, (texels, value)) in texels
        .chunks_exact_mut(4 * p)
        .zip(values.chunks_exact(c))
        .enumerate()
    {
        for (g, (texel, chunk)) in texels.chunks_exact_mut(4).zip(value.chunks(4)).enumerate() {
            let mut new = [0.0f32; 4];
            new[..chunk.len()].copy_from_slice(chunk);
            if texel
                .iter()
                .zip(&new)
                .all(|(x, y)| x.to_bits() == y.to_bits())
            {
                continue;
            }
            texel.copy_from_slice(&new);
            let t = (at + k) * p + g;
            match changed.last_mut() {
                Some((_, end)) if t >= *end && t - *end < MERGE_GAP => *end = t + 1,
                _ => changed.push((t, t + 1)),
            }
        }
    }
}

/// `spans` sorted, or an error naming them when one leaves `values`.
fn checked_spans(spans: &[(usize, usize)], values: usize) -> Result<Vec<(usize, usize)>, Error> {
    if spans.iter().any(|&(a, b)| a > b || b > values) {
        return Err(Error::InvalidArgument {
            argument: "spans",
            reason: "has a span beyond the pyramid's values",
        });
    }
    let mut spans = spans.to_vec();
    spans.sort_unstable();
    Ok(spans)
}

/// Texel spans `[start, end)` sorted and joined across gaps of fewer than
/// [`MERGE_GAP`] texels.
fn merged(mut spans: Vec<(usize, usize)>) -> Vec<(usize, usize)> {
    spans.sort_unstable();
    let mut out: Vec<(usize, usize)> = Vec::with_capacity(spans.len());
    for (a, b) in spans {
        match out.last_mut() {
            Some((_, end)) if a < *end + MERGE_GAP => *end = (*end).max(b),
            _ if a < b => out.push((a, b)),
            _ => {}
        }
    }
    out
}

/// Spans `[start, end)` (in texels, 4 values each) where `a` and `b`
/// differ, merged across small gaps.
fn diff<T: Copy>(a: &[T], b: &[T], same: impl Fn(T, T) -> bool) -> Vec<(usize, usize)> {
    let mut spans: Vec<(usize, usize)> = Vec::new();
    for (t, (x, y)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
        if x.iter().zip(y).all(|(&p, &q)| same(p, q)) {
            continue;
        }
        match spans.last_mut() {
            Some((_, end)) if t - *end < MERGE_GAP => *end = t + 1,
            _ => spans.push((t, t + 1)),
        }
    }
    spans
}

/// The whole of `texels` texels at width `w`, as rectangles.
fn whole(w: usize, texels: usize) -> Vec<TexelRect> {
    rects(w, vec![(0, texels)])
}

/// Texel spans at width `w` as at most three rectangles each: the rest of
/// the first row, whole rows, the start of the last row.
fn rects(w: usize, spans: Vec<(usize, usize)>) -> Vec<TexelRect> {
    let mut out = Vec::new();
    for (mut start, end) in spans {
        let rect = |x: usize, y: usize, width: usize, height: usize| TexelRect {
            x: x as u32,
            y: y as u32,
            width: width as u32,
            height: height as u32,
        };
        if start % w != 0 {
            let stop = end.min((start / w + 1) * w);
            out.push(rect(start % w, start / w, stop - start, 1));
            start = stop;
        }
        let full = (end - start) / w;
        if full > 0 {
            out.push(rect(0, start / w, w, full));
            start += full * w;
        }
        if start < end {
            out.push(rect(0, start / w, end - start, 1));
        }
    }
    out
}

/// Where a point lies, in the face's own terms.
#[derive(Clone, Copy)]
enum Place {
    /// Corner `k`.
    Corner(usize),
    /// Local edge `k` at canonical parameter `t`.
    Edge(usize, f32),
    /// Inside, clamped barycentrics.
    Inside([f32; 3]),
}

/// One face's table entry, decoded.
struct View<'a> {
    g: &'a GpuLayout,
    face: usize,
    vertex: [usize; 3],
    edge: [usize; 3],
    n: u8,
    vl: [u8; 3],
    el: [u8; 3],
    /// Edge `k` starts (canonically) at corner `k`.
    forward: [bool; 3],
}

impl<'a> View<'a> {
    fn decode(g: &'a GpuLayout, f: usize) -> Self {
        let word = |w: usize| g.parts.faces.get(f * FACE_WORDS + w).copied().unwrap_or(0);
        let bits = word(7);
        let level = |shift: usize| (((bits >> shift) & 0xF) as u8).min(MAX_LEVEL);
        let n = level(0);
        Self {
            g,
            face: word(0) as usize,
            vertex: [1, 2, 3].map(|w| word(w) as usize),
            edge: [4, 5, 6].map(|w| word(w) as usize),
            n,
            vl: [0, 1, 2].map(|k| level(4 + 4 * k)),
            // An edge is never finer than its face (clamped, so that a
            // damaged table cannot make a level difference negative).
            el: [0, 1, 2].map(|k| level(16 + 4 * k).min(n)),
            forward: [0, 1, 2].map(|k| bits & (1 << (28 + k)) != 0),
        }
    }

    /// Adds `w ×` corner `k` seen at query level `q`.
    #[inline]
    fn corner(&self, k: usize, q: u8, w: f32, out: &mut [f32]) {
        self.g
            .add(self.vertex[k] + q.min(self.vl[k]) as usize, w, out);
    }

    /// Adds `w ×` node `i` of edge `k` at edge level `le`, query level `q`.
    #[inline]
    fn node(&self, k: usize, q: u8, le: u8, i: u32, w: f32, out: &mut [f32]) {
        let (start, end) = if self.forward[k] {
            (k, (k + 1) % 3)
        } else {
            ((k + 1) % 3, k)
        };
        if i == 0 {
            self.corner(start, q, w, out);
        } else if i == 1 << le {
            self.corner(end, q, w, out);
        } else {
            let at = self.edge[k] + edge_level_offset(le) + i as usize - 1;
            self.g.add(at, w, out);
        }
    }

    /// Adds `w ×` edge `k` at canonical lattice position `p / 2^lp`.
    #[allow(
        clippy::too_many_arguments,
        reason = "mirrors filter::edge_point, argument for argument"
    )]
    fn edge_point(&self, k: usize, q: u8, lp: u8, p: u32, w: f32, nearest: bool, out: &mut [f32]) {
        let le = q.min(self.el[k]);
        let d = lp - le;
        let i = p >> d;
        let rem = p & ((1 << d) - 1);
        if rem == 0 {
            self.node(k, q, le, i, w, out);
        } else if nearest {
            let up = u32::from(2 * rem >= 1 << d);
            self.node(k, q, le, i + up, w, out);
        } else {
            let fr = rem as f32 / (1u32 << d) as f32;
            self.node(k, q, le, i, w * (1.0 - fr), out);
            self.node(k, q, le, i + 1, w * fr, out);
        }
    }

    /// Adds `w ×` lattice point `a` (summing to `2^lf`) at query level `q`.
    fn lattice(&self, q: u8, lf: u8, a: [u32; 3], w: f32, nearest: bool, out: &mut [f32]) {
        let r = 1u32 << lf;
        if let Some(k) = (0..3).find(|&k| a[k] == r) {
            self.corner(k, q, w, out);
        } else if let Some(m) = (0..3).find(|&m| a[m] == 0) {
            let k = (m + 1) % 3;
            let t = a[(k + 1) % 3];
            let p = if self.forward[k] { t } else { r - t };
            self.edge_point(k, q, lf, p, w, nearest, out);
        } else {
            let at = self.face + FACE_LEVEL_OFFSET[lf as usize] + interior_index(r, a[0], a[1]);
            self.g.add(at, w, out);
        }
    }

    /// Step 1 of the module documentation.
    fn place(&self, b: [f32; 3]) -> Place {
        let c = b.map(|x| if x > 0.0 { x } else { 0.0 });
        match c.iter().filter(|&&x| x == 0.0).count() {
            0 => Place::Inside(c),
            1 => {
                let m = (0..3).find(|&m| c[m] == 0.0).unwrap_or(0);
                let k = (m + 1) % 3;
                let k1 = (k + 1) % 3;
                let (cs, ce) = if self.forward[k] {
                    (c[k], c[k1])
                } else {
                    (c[k1], c[k])
                };
                Place::Edge(k, ce / (cs + ce))
            }
            2 => Place::Corner((0..3).find(|&k| c[k] > 0.0).unwrap_or(0)),
            _ => Place::Inside([1.0; 3]),
        }
    }

    /// Steps 1–3, adding weighted nodes directly (nearest, linear).
    fn eval(&self, at: Place, q: u8, nearest: bool, out: &mut [f32]) {
        out.fill(0.0);
        match at {
            Place::Corner(k) => self.corner(k, q, 1.0, out),
            Place::Edge(k, t) => {
                let le = q.min(self.el[k]);
                let re = 1u32 << le;
                let x = t * re as f32;
                let i = (x as u32).min(re - 1);
                let fr = x - i as f32;
                if nearest {
                    self.node(k, q, le, i + u32::from(fr >= 0.5), 1.0, out);
                } else {
                    self.node(k, q, le, i, 1.0 - fr, out);
                    self.node(k, q, le, i + 1, fr, out);
                }
            }
            Place::Inside(c) => {
                let lf = q.min(self.n);
                let (pts, ws) = triangle(c, 1 << lf);
                if nearest {
                    let best = if ws[0] >= ws[1] && ws[0] >= ws[2] {
                        0
                    } else if ws[1] >= ws[2] {
                        1
                    } else {
                        2
                    };
                    self.lattice(q, lf, pts[best], 1.0, true, out);
                } else {
                    for t in 0..3 {
                        self.lattice(q, lf, pts[t], ws[t], false, out);
                    }
                }
            }
        }
    }

    /// A MIP lookup at level `q`: lattice values first, then weighted,
    /// where the MIP map's per-face cache does so (see the module docs).
    fn mip(&self, at: Place, q: u8, out: &mut [f32]) {
        let corner_level = self.vl.iter().copied().max().unwrap_or(0);
        let Place::Inside(c) = at else {
            self.eval(at, q, false, out);
            return;
        };
        if q > self.n && q < corner_level {
            self.eval(at, q, false, out);
            return;
        }
        let lf = q.min(self.n);
        let (pts, ws) = triangle(c, 1 << lf);
        let mut value = [0.0f32; MAX_CHANNELS];
        let value = &mut value[..out.len()];
        out.fill(0.0);
        for t in 0..3 {
            value.fill(0.0);
            self.lattice(q, lf, pts[t], 1.0, false, value);
            for (o, &x) in out.iter_mut().zip(value.iter()) {
                *o += ws[t] * x;
            }
        }
    }

    /// Trilinear at level `lambda` (step 4).
    fn trilinear(&self, b: [f32; 3], lambda: f32, out: &mut [f32]) {
        let at = self.place(b);
        let top = match at {
            Place::Corner(k) => self.vl[k],
            Place::Edge(k, _) => self.el[k],
            Place::Inside(_) => self.n,
        };
        let l0 = lambda.floor();
        let frac = lambda - l0;
        let l0 = l0 as u8;
        self.mip(at, l0, out);
        if l0 >= top || frac == 0.0 {
            return;
        }
        let mut fine = [0.0f32; MAX_CHANNELS];
        let fine = &mut fine[..out.len()];
        self.mip(at, l0 + 1, fine);
        for (o, &x) in out.iter_mut().zip(fine.iter()) {
            *o = (1.0 - frac) * *o + frac * x;
        }
    }

    /// Anisotropic filtering (step 4, Sec. 4.3).
    fn anisotropic(
        &self,
        b: [f32; 3],
        db_dx: [f32; 3],
        db_dy: [f32; 3],
        max_samples: u32,
        out: &mut [f32],
    ) {
        crate::mip::anisotropic_probes(b, db_dx, db_dy, max_samples, out, |p, lambda, o| {
            self.trilinear(p, lambda, o);
        });
    }
}
