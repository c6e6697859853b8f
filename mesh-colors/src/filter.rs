//! Two-dimensional filtering (Sec. 4.1): nearest and linear lookups from
//! the barycentric coordinates of a point, the three cases of Fig. 7.
//!
//! One code path serves the finest samples ([`MeshColors`]) and every MIP
//! level ([`crate::MipMap`]) through the [`Store`] trait.

use crate::Error;
use crate::structure::{MeshColors, edge_param, interior_index};

/// Where a lookup reads samples: the finest level, or a MIP pyramid.
pub(crate) trait Store {
    /// The structure: topology and per-primitive levels.
    fn colors(&self) -> &MeshColors;
    /// Vertex `v`'s sample at `level` (≤ its level).
    fn vertex_at(&self, v: usize, level: u8) -> &[f32];
    /// Edge `e`'s sample `s` (`1..2^level`) at `level` (≤ its level).
    fn edge_at(&self, e: usize, level: u8, s: u32) -> &[f32];
    /// Face `f`'s interior sample `idx` at `level` (≤ its level).
    fn face_at(&self, f: usize, level: u8, idx: usize) -> &[f32];
}

impl Store for MeshColors {
    #[inline]
    fn colors(&self) -> &MeshColors {
        self
    }
    #[inline]
    fn vertex_at(&self, v: usize, _level: u8) -> &[f32] {
        let c = self.channels;
        &self.samples[v * c..(v + 1) * c]
    }
    #[inline]
    fn edge_at(&self, e: usize, _level: u8, s: u32) -> &[f32] {
        let c = self.channels;
        let i = self.edge_offset[e] + s as usize - 1;
        &self.samples[i * c..(i + 1) * c]
    }
    #[inline]
    fn face_at(&self, f: usize, _level: u8, idx: usize) -> &[f32] {
        let c = self.channels;
        let i = self.face_offset[f] + idx;
        &self.samples[i * c..(i + 1) * c]
    }
}

/// The query level meaning "the finest level of every primitive".
pub(crate) const FINEST: u8 = u8::MAX;

#[inline(always)]
fn add(out: &mut [f32], v: &[f32], w: f32) {
    for (o, x) in out.iter_mut().zip(v) {
        *o += w * x;
    }
}

/// Vertex `v` seen at query level `q`.
#[inline]
fn vertex<S: Store>(s: &S, v: u32, q: u8) -> &[f32] {
    let v = v as usize;
    s.vertex_at(v, q.min(s.colors().vertex_level[v]))
}

/// Node `i` (`0..=2^le`) of edge `e` at edge level `le`: its end vertices
/// or its stored samples.
#[inline]
fn edge_node<S: Store>(s: &S, e: usize, q: u8, le: u8, i: u32) -> &[f32] {
    let [a, b] = s.colors().topology.edges[e];
    if i == 0 {
        vertex(s, a, q)
    } else if i == 1 << le {
        vertex(s, b, q)
    } else {
        s.edge_at(e, le, i)
    }
}

/// Adds `w ×` the value of edge `e` at canonical position `p / 2^lp`, a
/// lattice point of a face at level `lp ≥` the edge's level: a stored
/// sample, or (between two, when the face is finer than the edge) their
/// linear interpolation, the continuity rule.
#[inline]
#[allow(
    clippy::too_many_arguments,
    reason = "the hot path keeps its inputs in registers"
)]
pub(crate) fn edge_point<S: Store>(
    s: &S,
    e: usize,
    q: u8,
    lp: u8,
    p: u32,
    w: f32,
    nearest: bool,
    out: &mut [f32],
) {
    let le = q.min(s.colors().edge_level[e]);
    let d = lp - le;
    let i = p >> d;
    let rem = p & ((1 << d) - 1);
    if rem == 0 {
        add(out, edge_node(s, e, q, le, i), w);
    } else if nearest {
        let up = u32::from(2 * rem >= 1 << d);
        add(out, edge_node(s, e, q, le, i + up), w);
    } else {
        let fr = rem as f32 / (1u32 << d) as f32;
        add(out, edge_node(s, e, q, le, i), w * (1.0 - fr));
        add(out, edge_node(s, e, q, le, i + 1), w * fr);
    }
}

/// Adds `w ×` lattice point `a` (summing to `2^lf`) of face `f` seen at
/// query level `q` (face level `lf = min(q, n_f)`).
#[inline]
#[allow(
    clippy::too_many_arguments,
    reason = "the hot path keeps its inputs in registers"
)]
pub(crate) fn lattice<S: Store>(
    s: &S,
    f: usize,
    q: u8,
    lf: u8,
    a: [u32; 3],
    w: f32,
    nearest: bool,
    out: &mut [f32],
) {
    let r = 1u32 << lf;
    // Inside first (the common case, a MIP level's neighbours above all):
    // with all three positive none is `r`, so neither test below holds.
    if a[0] > 0 && a[1] > 0 && a[2] > 0 {
        add(out, s.face_at(f, lf, interior_index(r, a[0], a[1])), w);
        return;
    }
    let mc = s.colors();
    let face = mc.topology.faces[f];
    for k in 0..3 {
        if a[k] == r {
            add(out, vertex(s, face[k], q), w);
            return;
        }
    }
    for m in 0..3 {
        if a[m] == 0 {
            let k = (m + 1) % 3;
            let e = mc.topology.face_edges[f][k] as usize;
            edge_point(s, e, q, lf, edge_param(face, k, a, r), w, nearest, out);
            return;
        }
    }
    add(out, s.face_at(f, lf, interior_index(r, a[0], a[1])), w);
}

/// Where a barycentric point lies: on a vertex, on an edge (with its
/// canonical parameter), or inside the face (clamped, not normalised).
#[derive(Clone, Copy)]
pub(crate) enum Place {
    Vertex(u32),
    Edge(usize, f32),
    Inside([f32; 3]),
}

/// Classifies a lookup point. Coordinates ≤ 0 (or NaN) are on the
/// boundary; the edge parameter is computed from the two coordinates of
/// the edge's vertices in canonical order, so that both faces of the edge
/// compute the same number.
#[inline]
pub(crate) fn place(mc: &MeshColors, f: usize, b: [f32; 3]) -> Place {
    let c = b.map(|x| if x > 0.0 { x } else { 0.0 });
    let zeros = c.iter().filter(|&&x| x == 0.0).count();
    let face = mc.topology.faces[f];
    match zeros {
        0 => Place::Inside(c),
        1 => {
            let m = (0..3).find(|&m| c[m] == 0.0).unwrap_or(0);
            let k = (m + 1) % 3;
            let k1 = (k + 1) % 3;
            let (cs, ce) = if face[k] < face[k1] {
                (c[k], c[k1])
            } else {
                (c[k1], c[k])
            };
            let e = mc.topology.face_edges[f][k] as usize;
            Place::Edge(e, ce / (cs + ce))
        }
        2 => {
            let k = (0..3).find(|&k| c[k] > 0.0).unwrap_or(0);
            Place::Vertex(face[k])
        }
        // No weight anywhere: read the face centre.
        _ => Place::Inside([1.0; 3]),
    }
}

/// The value on edge `e` at canonical parameter `t ∈ [0, 1]`, query level
/// `q`: a function of the edge alone.
#[inline]
fn on_edge<S: Store>(s: &S, e: usize, q: u8, t: f32, nearest: bool, out: &mut [f32]) {
    let le = q.min(s.colors().edge_level[e]);
    let re = 1u32 << le;
    let x = t * re as f32;
    let i = (x as u32).min(re - 1);
    let fr = x - i as f32;
    if nearest {
        add(out, edge_node(s, e, q, le, i + u32::from(fr >= 0.5)), 1.0);
    } else {
        add(out, edge_node(s, e, q, le, i), 1.0 - fr);
        add(out, edge_node(s, e, q, le, i + 1), fr);
    }
}

/// The lattice triangle of Fig. 7 holding the point with (clamped,
/// unnormalised) barycentrics `c` on a face of resolution `r`, and its
/// weights: `w = RP − B` (case a) or `[1, 1, 1] − w` (case b).
#[inline(always)]
pub(crate) fn triangle(c: [f32; 3], r: u32) -> ([[u32; 3]; 3], [f32; 3]) {
    let scale = r as f32 / (c[0] + c[1] + c[2]);
    let (x, y) = (c[0] * scale, c[1] * scale);
    let i = (x as u32).min(r - 1);
    let j = (y as u32).min(r - 1 - i);
    let (fx, fy) = (x - i as f32, y - j as f32);
    let k = r - i - j;
    if fx + fy <= 1.0 || k == 1 {
        (
            [[i, j, k], [i + 1, j, k - 1], [i, j + 1, k - 1]],
            [1.0 - fx - fy, fx, fy],
        )
    } else {
        (
            [[i + 1, j + 1, k - 2], [i + 1, j, k - 1], [i, j + 1, k - 1]],
            [fx + fy - 1.0, 1.0 - fy, 1.0 - fx],
        )
    }
}

/// Evaluates face `f` at barycentrics `b` at query level `q` into `out`
/// (overwritten).
#[inline]
pub(crate) fn eval<S: Store>(s: &S, f: usize, b: [f32; 3], q: u8, nearest: bool, out: &mut [f32]) {
    eval_at(s, f, place(s.colors(), f, b), q, nearest, out);
}

/// As [`eval`], for a point already classified by [`place`].
#[inline]
pub(crate) fn eval_at<S: Store>(s: &S, f: usize, at: Place, q: u8, nearest: bool, out: &mut [f32]) {
    out.fill(0.0);
    let mc = s.colors();
    let c = match at {
        Place::Vertex(v) => {
            add(out, vertex(s, v, q), 1.0);
            return;
        }
        Place::Edge(e, t) => {
            on_edge(s, e, q, t, nearest, out);
            return;
        }
        Place::Inside(c) => c,
    };
    let lf = q.min(mc.face_level[f]);
    let r = 1u32 << lf;
    let (pts, ws) = triangle(c, r);
    if !nearest && pts.iter().all(|p| p[0] >= 1 && p[1] >= 1 && p[2] >= 1) {
        // The whole lattice triangle is inside the face (the common case
        // on fine faces): three interior samples, no vertex or edge.
        for t in 0..3 {
            let idx = interior_index(r, pts[t][0], pts[t][1]);
            add(out, s.face_at(f, lf, idx), ws[t]);
        }
        return;
    }
    if nearest {
        let best = if ws[0] >= ws[1] && ws[0] >= ws[2] {
            0
        } else if ws[1] >= ws[2] {
            1
        } else {
            2
        };
        lattice(s, f, q, lf, pts[best], 1.0, true, out);
    } else {
        for t in 0..3 {
            lattice(s, f, q, lf, pts[t], ws[t], false, out);
        }
    }
}

/// Checks a lookup's face index and output length.
#[inline]
pub(crate) fn check(mc: &MeshColors, f: usize, out: &[f32]) -> Result<(), Error> {
    if f >= mc.face_level.len() {
        return Err(Error::MissingFace {
            face: f,
            count: mc.face_level.len(),
        });
    }
    if out.len() != mc.channels {
        return Err(Error::ChannelMismatch {
            what: "lookup output",
            expected: mc.channels,
            got: out.len(),
        });
    }
    Ok(())
}

impl MeshColors {
    /// Nearest filtering (Fig. 8a): the sample of highest weight at the
    /// point with barycentrics `b` (weight `k` for corner `k`; negative
    /// weights are clamped to 0 and the rest normalised).
    ///
    /// # Errors
    /// [`Error::MissingFace`], or [`Error::ChannelMismatch`] when
    /// `out.len() != channels()`.
    #[inline]
    pub fn nearest(&self, face: usize, b: [f32; 3], out: &mut [f32]) -> Result<(), Error> {
        check(self, face, out)?;
        eval(self, face, b, FINEST, true, out);
        Ok(())
    }

    /// Linear filtering (Sec. 4.1, Fig. 7–8b): the three nearest samples
    /// blended by their barycentric weights. On an edge, the value depends
    /// only on the edge (see the continuity rule on [`MeshColors`]).
    ///
    /// # Errors
    /// As for [`MeshColors::nearest`].
    #[inline]
    pub fn linear(&self, face: usize, b: [f32; 3], out: &mut [f32]) -> Result<(), Error> {
        check(self, face, out)?;
        eval(self, face, b, FINEST, false, out);
        Ok(())
    }
}
