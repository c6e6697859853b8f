//! TransCut's graph hierarchy (Sec. 4.1): each coarser level keeps an
//! independent set of the finer level's vertices, chosen in parallel by
//! hashed codes, enhanced until every fine edge is still represented, with
//! edges between kept vertices that were within two rings of each other;
//! and the interpolation of Eq. 16 from each level to the next finer one.

use std::sync::atomic::{AtomicBool, Ordering::Relaxed};

use rayon::prelude::*;
use sprs::CsMat;

use crate::Error;
use crate::graph::Graph;
use crate::matrix::{assemble, check_square};

/// The interpolation weights `λ_ij` of Eq. 16 between a dropped vertex
/// `i` and a kept neighbour `j`. Indices are those of the original
/// (level-0) system, at every level.
#[derive(Clone, Copy)]
pub enum Weights<'a> {
    /// `λ_ij = 1`: plain averages.
    Uniform,
    /// `λ_ij = 1 / |x_i − x_j|` (the paper's choice), positions as arrays.
    Positions(&'a [[f64; 3]]),
    /// As [`Positions`](Self::Positions), for positions of any type that is
    /// `AsRef<[f64; 3]>` (glam's `DVec3`), read in place: pass
    /// `Weights::Points(&mesh.positions)` with a `Vec<DVec3>`, no copy.
    Points(&'a dyn PositionList),
    /// Any positive weight of an edge, such as a conductance.
    Custom(&'a (dyn Fn(usize, usize) -> f64 + Sync)),
}

/// Vertex positions the hierarchy can read in place: implemented for
/// `Vec<P>` and `&[P]` of any `P: AsRef<[f64; 3]>` (glam's `DVec3`
/// implements it), so a mesh's own position buffer goes in without a copy.
pub trait PositionList: Sync {
    /// Number of positions.
    fn count(&self) -> usize;
    /// Position `i` (`i < count()`).
    fn position(&self, i: usize) -> [f64; 3];
}

impl<P: AsRef<[f64; 3]> + Sync> PositionList for Vec<P> {
    fn count(&self) -> usize {
        self.len()
    }
    fn position(&self, i: usize) -> [f64; 3] {
        *self[i].as_ref()
    }
}

impl<P: AsRef<[f64; 3]> + Sync> PositionList for &[P] {
    fn count(&self) -> usize {
        self.len()
    }
    fn position(&self, i: usize) -> [f64; 3] {
        *self[i].as_ref()
    }
}

impl std::fmt::Debug for Weights<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Uniform => write!(f, "Uniform"),
            Self::Positions(p) => write!(f, "Positions({} points)", p.len()),
            Self::Points(p) => write!(f, "Points({} points)", p.count()),
            Self::Custom(_) => write!(f, "Custom"),
        }
    }
}

impl Weights<'_> {
    fn get(&self, i: usize, j: usize) -> f64 {
        match (self.position(i), self.position(j)) {
            (Some(a), Some(b)) => 1.0 / dist(a, b),
            _ => match self {
                Self::Custom(f) => f(i, j),
                _ => 1.0,
            },
        }
    }

    /// Number of positions, for the variants that have them.
    fn position_count(&self) -> Option<usize> {
        match self {
            Self::Positions(x) => Some(x.len()),
            Self::Points(p) => Some(p.count()),
            _ => None,
        }
    }

    /// Position `i`, for the variants that have positions.
    fn position(&self, i: usize) -> Option<[f64; 3]> {
        match self {
            Self::Positions(x) => Some(x[i]),
            Self::Points(p) => Some(p.position(i)),
            _ => None,
        }
    }
}

/// How deep to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HierarchyOptions {
    /// Stop coarsening once a level has at most this many vertices.
    pub coarsest: usize,
    /// At most this many levels, the original included.
    pub max_levels: usize,
    /// Run the enhancement step (re-insert vertices until every edge
    /// between two dropped vertices still has a kept common neighbour).
    /// The cascade's interpolation needs it; a Galerkin V-cycle does not.
    pub enhance: bool,
    /// Seed of the vertex codes' random bits.
    pub seed: u32,
    /// Whether to correct Eq. 16's weights so that interpolation
    /// reproduces linear functions of position (needs
    /// [`Weights::Positions`]).
    pub linear_precision: bool,
    /// With `linear_precision`, interpolate a dropped vertex whose kept
    /// neighbours do not surround it from the kept vertices of its 2-ring
    /// too (beyond Eq. 16, which uses the 1-ring only).
    pub wide_interpolation: bool,
}

impl Default for HierarchyOptions {
    fn default() -> Self {
        Self {
            coarsest: 2_000,
            max_levels: 12,
            enhance: true,
            seed: 0x7A5C_0DE5,
            linear_precision: false,
            wide_interpolation: false,
        }
    }
}

/// One coarsening step, from level `l` to `l + 1`.
#[derive(Debug, Clone)]
pub struct Coarsening {
    /// The level-`l` indices of the kept vertices, ascending; kept vertex
    /// `k` is vertex `k` of level `l + 1`.
    pub kept: Vec<u32>,
    /// How many of them the independent set chose, before enhancement.
    pub independent: usize,
    /// Eq. 16 as a `n_l × n_{l+1}` matrix `P`: row `i` is `e_k` for a kept
    /// vertex, the weights `λ_ij / λ_i` over its kept neighbours otherwise.
    pub interpolation: CsMat<f64>,
    /// Level-`l` index → level-`l + 1` index, `u32::MAX` if dropped.
    pub(crate) coarse_index: Vec<u32>,
}

impl Coarsening {
    /// Whether level-`l` vertex `i` is kept.
    #[inline]
    pub fn is_kept(&self, i: usize) -> bool {
        self.coarse_index[i] != u32::MAX
    }
}

/// The levels' graphs and the steps between them.
#[derive(Debug, Clone)]
pub struct Hierarchy {
    /// `graphs[l]` is `G^l`; `graphs[0]` is the matrix's graph.
    pub graphs: Vec<Graph>,
    /// `steps[l]` coarsens level `l` into level `l + 1`.
    pub steps: Vec<Coarsening>,
    /// `original[l][k]`: the level-0 index of vertex `k` of level `l`.
    pub original: Vec<Vec<u32>>,
}

impl Hierarchy {
    /// Builds the hierarchy of `a`'s graph, in parallel; the result does
    /// not depend on the number of threads.
    ///
    /// # Errors
    /// [`Error::NotCsr`], [`Error::NotSquare`], [`Error::NotFiniteEntry`],
    /// [`Error::DimensionMismatch`] for positions of the wrong length,
    /// [`Error::BadWeight`] for a weight that is not positive and finite
    /// (coincident positions), [`Error::TooLarge`] beyond 2³² unknowns.
    pub fn new(
        a: &CsMat<f64>,
        weights: Weights<'_>,
        options: &HierarchyOptions,
    ) -> Result<Self, Error> {
        Self::build(a, weights, options, |graph, step| {
            Ok(coarse_graph(graph, step))
        })
    }

    /// [`new`](Self::new) with the next level's graph made by `next` from
    /// the current graph and step (an algebraic multigrid takes the graph
    /// of its Galerkin operator).
    pub(crate) fn build(
        a: &CsMat<f64>,
        weights: Weights<'_>,
        options: &HierarchyOptions,
        mut next: impl FnMut(&Graph, &Coarsening) -> Result<Graph, Error>,
    ) -> Result<Self, Error> {
        let n = check_square(a)?;
        if n > u32::MAX as usize {
            return Err(Error::TooLarge(n));
        }
        if let Some(count) = weights.position_count() {
            if count != n {
                return Err(Error::DimensionMismatch {
                    what: "positions",
                    expected: n,
                    found: count,
                });
            }
            for i in 0..n {
                let p = weights.position(i).unwrap_or([0.0; 3]);
                if let Some(&value) = p.iter().find(|c| !c.is_finite()) {
                    return Err(Error::NotFiniteVector {
                        what: "positions",
                        index: i,
                        value,
                    });
                }
            }
        }
        if options.linear_precision && weights.position_count().is_none() {
            return Err(Error::InvalidOption(
                "linear_precision needs Weights::Positions or Weights::Points",
            ));
        }
        if options.max_levels == 0 {
            return Err(Error::InvalidOption("max_levels must be at least 1"));
        }
        let mut graphs = vec![Graph::from_matrix(a)];
        let mut original = vec![(0..n as u32).collect::<Vec<_>>()];
        let mut steps = Vec::new();
        while graphs.len() < options.max_levels {
            let (graph, ids) = (&graphs[graphs.len() - 1], &original[original.len() - 1]);
            if graph.len() <= options.coarsest.max(1) {
                break;
            }
            let seed = options.seed ^ (graphs.len() as u32).wrapping_mul(0x9E37_79B9);
            let step = coarsen(graph, ids, weights, seed, options)?;
            // A level that barely shrinks costs more than it helps.
            if step.kept.len() as f64 > 0.9 * graph.len() as f64 {
                break;
            }
            let next = next(graph, &step)?;
            original.push(step.kept.iter().map(|&k| ids[k as usize]).collect());
            graphs.push(next);
            steps.push(step);
        }
        Ok(Self {
            graphs,
            steps,
            original,
        })
    }

    /// Number of levels, the original included.
    pub fn levels(&self) -> usize {
        self.graphs.len()
    }

    /// Vertices per level.
    pub fn sizes(&self) -> Vec<usize> {
        self.graphs.iter().map(Graph::len).collect()
    }
}

/// A 32-bit integer hash (a variant of the "lowbias32" mixer).
#[inline]
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^ (x >> 16)
}

/// The paper's 32-bit codes: random high bits from a hash of the index,
/// the index itself in the low bits, so that codes are distinct and the
/// order has no pattern of the numbering.
pub(crate) fn codes(n: usize, seed: u32) -> Vec<u32> {
    let index_bits = usize::BITS - n.saturating_sub(1).leading_zeros();
    (0..n as u32)
        .into_par_iter()
        .map(|i| {
            if index_bits >= 32 {
                i
            } else {
                (hash(i ^ seed) >> index_bits << index_bits) | i
            }
        })
        .collect()
}

/// Moves an independent set of the candidates `q` (all flagged in `in_q`)
/// into `kept`: each round keeps every candidate whose code is below those
/// of its candidate neighbours, then removes it and them from the
/// candidates. Two neighbours are never kept in the same round, so the
/// rounds run in parallel without races.
pub(crate) fn independent_set(
    graph: &Graph,
    codes: &[u32],
    mut q: Vec<u32>,
    in_q: &[AtomicBool],
    kept: &[AtomicBool],
) {
    while !q.is_empty() {
        let picked: Vec<u32> = q
            .par_iter()
            .copied()
            .filter(|&i| {
                graph.neighbors(i as usize).iter().all(|&j| {
                    !in_q[j as usize].load(Relaxed) || codes[i as usize] < codes[j as usize]
                })
            })
            .collect();
        picked.par_iter().for_each(|&i| {
            kept[i as usize].store(true, Relaxed);
            in_q[i as usize].store(false, Relaxed);
            for &j in graph.neighbors(i as usize) {
                in_q[j as usize].store(false, Relaxed);
            }
        });
        q = q
            .into_par_iter()
            .filter(|&i| in_q[i as usize].load(Relaxed))
            .collect();
    }
}

/// Whether `i` and `j` have a common neighbour in `kept`.
fn share_kept(graph: &Graph, kept: &[AtomicBool], i: usize, j: usize) -> bool {
    let (a, b) = (graph.neighbors(i), graph.neighbors(j));
    let (mut x, mut y) = (0, 0);
    while x < a.len() && y < b.len() {
        match a[x].cmp(&b[y]) {
            std::cmp::Ordering::Less => x += 1,
            std::cmp::Ordering::Greater => y += 1,
            std::cmp::Ordering::Equal => {
                if kept[a[x] as usize].load(Relaxed) {
                    return true;
                }
                x += 1;
                y += 1;
            }
        }
    }
    false
}

/// The vertices to keep (independent set, then enhancement) and the
/// interpolation to them.
fn coarsen(
    graph: &Graph,
    original: &[u32],
    weights: Weights<'_>,
    seed: u32,
    options: &HierarchyOptions,
) -> Result<Coarsening, Error> {
    let n = graph.len();
    let codes = codes(n, seed);
    let in_q: Vec<AtomicBool> = (0..n).map(|_| AtomicBool::new(true)).collect();
    let kept: Vec<AtomicBool> = (0..n).map(|_| AtomicBool::new(false)).collect();
    independent_set(graph, &codes, (0..n as u32).collect(), &in_q, &kept);
    let independent = kept.iter().filter(|k| k.load(Relaxed)).count();
    if options.enhance {
        loop {
            // Mark both ends of each dropped–dropped edge that no kept common
            // neighbour represents at the coarser level (Fig. 3's problem).
            let marked: Vec<AtomicBool> = (0..n).map(|_| AtomicBool::new(false)).collect();
            (0..n).into_par_iter().for_each(|i| {
                if kept[i].load(Relaxed) {
                    return;
                }
                for &j in graph.neighbors(i) {
                    let j = j as usize;
                    if j > i && !kept[j].load(Relaxed) && !share_kept(graph, &kept, i, j) {
                        marked[i].store(true, Relaxed);
                        marked[j].store(true, Relaxed);
                    }
                }
            });
            let q: Vec<u32> = (0..n as u32)
                .into_par_iter()
                .filter(|&i| marked[i as usize].load(Relaxed))
                .collect();
            if q.is_empty() {
                break;
            }
            independent_set(graph, &codes, q, &marked, &kept);
        }
    }
    let kept_list: Vec<u32> = (0..n as u32)
        .into_par_iter()
        .filter(|&i| kept[i as usize].load(Relaxed))
        .collect();
    let mut coarse_index = vec![u32::MAX; n];
    for (k, &i) in kept_list.iter().enumerate() {
        coarse_index[i as usize] = k as u32;
    }
    // Eq. 16's weights, checked before they are normalised.
    let bad = (0..n).into_par_iter().find_map_first(|i| {
        if coarse_index[i] != u32::MAX {
            return None;
        }
        graph.neighbors(i).iter().find_map(|&j| {
            if coarse_index[j as usize] == u32::MAX {
                return None;
            }
            let (oi, oj) = (original[i] as usize, original[j as usize] as usize);
            let w = weights.get(oi, oj);
            (!(w > 0.0 && w.is_finite())).then_some(Error::BadWeight {
                i: oi,
                j: oj,
                value: w,
            })
        })
    });
    if let Some(e) = bad {
        return Err(e);
    }
    let interpolation = assemble(n, kept_list.len(), |i, out| {
        if coarse_index[i] != u32::MAX {
            out.push((coarse_index[i] as usize, 1.0));
            return;
        }
        let start = out.len();
        let mut total = 0.0;
        for &j in graph.neighbors(i) {
            let k = coarse_index[j as usize];
            if k != u32::MAX {
                let w = weights.get(original[i] as usize, original[j as usize] as usize);
                total += w;
                out.push((k as usize, w));
            }
        }
        for (_, w) in &mut out[start..] {
            *w /= total;
        }
        if options.linear_precision && weights.position_count().is_some() {
            let at = |k: usize| weights.position(original[k] as usize).unwrap_or([0.0; 3]);
            let neighbours: Vec<[f64; 3]> = graph
                .neighbors(i)
                .iter()
                .filter(|&&j| coarse_index[j as usize] != u32::MAX)
                .map(|&j| at(j as usize))
                .collect();
            if linear_correction(at(i), &neighbours, &mut out[start..])
                || !options.wide_interpolation
            {
                return;
            }
            // The kept 1-ring does not surround the vertex: interpolate from
            // the kept vertices of its 2-ring as well.
            out.truncate(start);
            let mut ring: Vec<u32> = graph.neighbors(i).to_vec();
            for &j in graph.neighbors(i) {
                if coarse_index[j as usize] == u32::MAX {
                    ring.extend_from_slice(graph.neighbors(j as usize));
                }
            }
            ring.sort_unstable();
            ring.dedup();
            let mut points = Vec::new();
            let mut total = 0.0;
            for &j in &ring {
                let (j, k) = (j as usize, coarse_index[j as usize]);
                let d = dist(at(i), at(j));
                if k != u32::MAX && j != i && d > 0.0 {
                    total += 1.0 / d;
                    out.push((k as usize, 1.0 / d));
                    points.push(at(j));
                }
            }
            for (_, w) in &mut out[start..] {
                *w /= total;
            }
            linear_correction(at(i), &points, &mut out[start..]);
        }
    });
    Ok(Coarsening {
        kept: kept_list,
        independent,
        interpolation,
        coarse_index,
    })
}

/// Moves normalised weights `w` (of points `p`) as little as possible, in
/// the norm `Σ δ_j² / w_j`, so that `Σ w_j = 1` and `Σ w_j p_j = x`: the
/// interpolation then reproduces linear functions. Directions in which the
/// points do not spread around `x` (fewer than four, coplanar) are left
/// as they are.
#[allow(
    clippy::needless_range_loop,
    reason = "4×4 dense algebra reads clearest with indices"
)]
fn linear_correction(x: [f64; 3], p: &[[f64; 3]], w: &mut [(usize, f64)]) -> bool {
    // Rows of A: 1 and the three offsets; residual r = c − A w.
    let row = |j: usize, k: usize| if k == 0 { 1.0 } else { p[j][k - 1] - x[k - 1] };
    let mut g = [[0.0f64; 4]; 4];
    let mut r = [0.0f64; 4];
    for (j, &(_, wj)) in w.iter().enumerate() {
        for a in 0..4 {
            r[a] -= row(j, a) * wj;
            for b in 0..4 {
                g[a][b] += row(j, a) * wj * row(j, b);
            }
        }
    }
    r[0] += 1.0;
    // Solve G λ = r by Cholesky, skipping directions with a vanishing pivot.
    let scale = (0..4).map(|a| g[a][a]).fold(0.0f64, f64::max);
    let mut l = [[0.0f64; 4]; 4];
    let mut live = [false; 4];
    for a in 0..4 {
        let mut d = g[a][a];
        for k in 0..a {
            d -= l[a][k] * l[a][k];
        }
        if d <= 1e-9 * scale {
            continue;
        }
        live[a] = true;
        l[a][a] = d.sqrt();
        for b in a + 1..4 {
            let mut s = g[b][a];
            for k in 0..a {
                s -= l[b][k] * l[a][k];
            }
            l[b][a] = s / l[a][a];
        }
    }
    let mut y = [0.0f64; 4];
    for a in 0..4 {
        if live[a] {
            let s = r[a] - (0..a).map(|k| l[a][k] * y[k]).sum::<f64>();
            y[a] = s / l[a][a];
        }
    }
    let mut lambda = [0.0f64; 4];
    for a in (0..4).rev() {
        if live[a] {
            let s = y[a] - (a + 1..4).map(|k| l[k][a] * lambda[k]).sum::<f64>();
            lambda[a] = s / l[a][a];
        }
    }
    for (j, (_, wj)) in w.iter_mut().enumerate() {
        let delta: f64 = (0..4).map(|a| row(j, a) * lambda[a]).sum();
        *wj += *wj * delta;
    }
    live.iter().all(|&l| l)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// `E^{l+1}`: kept vertices joined when some dropped vertex neighbours
/// both (two rings apart), or when they were adjacent at level `l`;
/// sorted and deduplicated.
fn coarse_graph(graph: &Graph, step: &Coarsening) -> Graph {
    let ci = &step.coarse_index;
    let mut edges: Vec<(u32, u32)> = (0..graph.len())
        .into_par_iter()
        .flat_map_iter(|i| {
            let nb = graph.neighbors(i);
            let mut out = Vec::new();
            if ci[i] != u32::MAX {
                for &j in nb {
                    if j as usize > i && ci[j as usize] != u32::MAX {
                        out.push((ci[i], ci[j as usize]));
                    }
                }
            } else {
                let kept: Vec<u32> = nb
                    .iter()
                    .map(|&j| ci[j as usize])
                    .filter(|&k| k != u32::MAX)
                    .collect();
                for (x, &a) in kept.iter().enumerate() {
                    for &b in &kept[x + 1..] {
                        out.push((a.min(b), a.max(b)));
                    }
                }
            }
            out
        })
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    Graph::from_sorted_edges(step.kept.len(), &edges)
}
