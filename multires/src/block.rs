//! Three symmetric positive definite systems with one sparsity pattern —
//! TransCut's red, green and blue matrices, whose medium changes the values
//! but never the mesh — checked once and solved together.
//!
//! A mat-vec is memory-bound: streaming the matrix costs more than the
//! arithmetic. Stored as one pattern (32-bit columns) with each entry's
//! three values side by side, and with the three channels' vectors
//! interleaved, one pass over the matrix serves all three channels: 28
//! bytes per entry instead of three passes of 16. The CG recurrences stay
//! those of three independent solves (each channel its own `α`, `β`, stop
//! and restarts, as [`crate::pcg`] does them), so a block solve gives what
//! three separate solves give, to rounding.

use std::ops::ControlFlow;

use rayon::prelude::*;
use sprs::CsMat;

use crate::Error;
use crate::krylov::{Best, Preconditioner, Report, SolveOptions, Stop, nonzero};
use crate::matrix::{check_square, check_vector};
use crate::vector::CHUNK;

/// The number of systems a [`Block3`] holds.
pub const CHANNELS: usize = 3;

/// Rows per parallel task of the block mat-vec.
const ROWS: usize = 1 << 11;

/// One value per channel.
type Lanes = [f64; CHANNELS];

/// Three square matrices with one sparsity pattern, validated once
/// (square, finite, same pattern, symmetric, positive diagonal) so that
/// solves on them check only their vectors.
#[derive(Debug, Clone)]
pub struct Block3 {
    /// Row `k` of the block is row `order[k]` of the matrices: a
    /// breadth-first numbering (Cuthill–McKee without the degree sort),
    /// so that a row's columns are near it and the mat-vec's reads of
    /// `p` hit the cache. A mesh's own numbering scatters them: on
    /// bunny_500k three entries in four lie over 4 096 rows away.
    order: Vec<u32>,
    offsets: Vec<usize>,
    cols: Vec<u32>,
    /// Entry `k` of the block is entry `source[k]` of the matrices.
    source: Vec<u32>,
    /// The matrices' own pattern (row offsets and columns), to check new
    /// values against in one sequential pass.
    source_offsets: Vec<usize>,
    source_cols: Vec<u32>,
    values: Vec<Lanes>,
    /// `1 / a_ii` per row and channel: the Jacobi preconditioner.
    inverse_diagonal: Vec<Lanes>,
}

/// What a block solve's monitor sees after each iteration.
#[derive(Debug, Clone, Copy)]
pub struct Progress<'a> {
    iteration: usize,
    residual: Lanes,
    alpha: Lanes,
    beta: Lanes,
    running: [bool; CHANNELS],
    x: &'a [Vec<f64>; CHANNELS],
    order: &'a [u32],
}

impl Progress<'_> {
    /// Iterations done (the same for every channel still running).
    pub fn iteration(&self) -> usize {
        self.iteration
    }

    /// Each channel's relative residual `‖r‖ / ‖b‖` from the CG
    /// recurrence (the true one at its last restart for a channel that
    /// has stopped).
    pub fn residual(&self) -> Lanes {
        self.residual
    }

    /// Whether each channel is still iterating.
    pub fn running(&self) -> [bool; CHANNELS] {
        self.running
    }

    /// Each channel's CG step length `α_j = (r_j·z_j) / (p_j·A p_j)` of
    /// this iteration `j`, and the `β_{j−1}` that made its direction
    /// `p_j = z_j + β_{j−1} p_{j−1}` (0 on a run's first iteration). With
    /// them a monitor builds CG's Lanczos matrix — diagonal
    /// `1/α_j + β_{j−1}/α_{j−1}`, off-diagonal `√β_{j−1}/α_{j−1}` (Saad,
    /// *Iterative Methods for Sparse Linear Systems*, Sec. 6.7.3) — whose
    /// extreme eigenvalues estimate those of the preconditioned matrix.
    pub fn coefficients(&self) -> (Lanes, Lanes) {
        (self.alpha, self.beta)
    }

    /// Channel `c`'s current iterate, in the matrices' numbering (a copy:
    /// the block iterates in its own order). `None` for `c ≥ 3`.
    pub fn solution(&self, c: usize) -> Option<Vec<f64>> {
        let x = self.x.get(c)?;
        let mut out = vec![0.0; x.len()];
        for (&i, &v) in self.order.iter().zip(x) {
            out[i as usize] = v;
        }
        Some(out)
    }
}

/// Called after every iteration of a block solve; `Break` stops all
/// channels ([`Stop::Interrupted`]).
pub type BlockMonitor<'m> = &'m mut dyn FnMut(&Progress<'_>) -> ControlFlow<()>;

impl Block3 {
    /// The three matrices as one block.
    ///
    /// # Errors
    /// [`Error::NotCsr`], [`Error::NotSquare`], [`Error::NotFiniteEntry`]
    /// for a matrix on its own; [`Error::PatternMismatch`] when a matrix
    /// differs from the first in size or stored entries;
    /// [`Error::NotSymmetric`] (the values of some channel are not
    /// symmetric, within `10⁻¹⁰` of the entry's scale), [`Error::BadDiagonal`]
    /// (a diagonal entry ≤ 0 or not stored), [`Error::TooLarge`] for more
    /// than 2³² − 1 rows.
    pub fn new(a: [&CsMat<f64>; CHANNELS]) -> Result<Self, Error> {
        check_matrices(a)?;
        let n = a[0].rows();
        let nnz = a[0].nnz();
        if u32::try_from(n.max(nnz)).is_err() {
            return Err(Error::TooLarge(n.max(nnz)));
        }
        let indptr = a[0].indptr();
        let offsets = indptr.to_proper().to_vec();
        let cols0 = a[0].indices();
        let order = breadth_first(&offsets, cols0);
        let mut rank = vec![0u32; n];
        for (k, &i) in order.iter().enumerate() {
            rank[i as usize] = k as u32;
        }
        let mut new_offsets = Vec::with_capacity(n + 1);
        new_offsets.push(0);
        for &i in &order {
            let len = offsets[i as usize + 1] - offsets[i as usize];
            new_offsets.push(new_offsets[new_offsets.len() - 1] + len);
        }
        let mut cols = vec![0u32; nnz];
        let mut source = vec![0u32; nnz];
        // Each new row: the old row's entries, renumbered, in their order
        // (the mat-vec needs no sorted rows).
        row_chunks(&new_offsets, &mut cols, &mut source)
            .into_par_iter()
            .for_each(|(first, cols, source)| {
                let mut at = 0;
                for &i in &order[first..(first + ROWS).min(n)] {
                    for e in offsets[i as usize]..offsets[i as usize + 1] {
                        cols[at] = rank[cols0[e]];
                        source[at] = e as u32;
                        at += 1;
                    }
                }
            });
        let source_cols: Vec<u32> = cols0.par_iter().map(|&j| j as u32).collect();
        let mut block = Self {
            order,
            offsets: new_offsets,
            cols,
            source,
            source_offsets: offsets,
            source_cols,
            values: Vec::new(),
            inverse_diagonal: Vec::new(),
        };
        block.set_values(a)?;
        Ok(block)
    }

    /// The block of new values for the same pattern — a paint stroke or
    /// a material change, which move values but not the mesh — without
    /// renumbering: a pass over the entries instead of
    /// [`new`](Self::new)'s search and sorts.
    ///
    /// # Errors
    /// As [`new`](Self::new); [`Error::PatternMismatch`] when a matrix's
    /// pattern is not the block's.
    pub fn refreshed(&self, a: [&CsMat<f64>; CHANNELS]) -> Result<Self, Error> {
        check_matrices(a)?;
        let mut next = self.clone_structure();
        next.set_values(a)?;
        Ok(next)
    }

    fn clone_structure(&self) -> Self {
        Self {
            order: self.order.clone(),
            offsets: self.offsets.clone(),
            cols: self.cols.clone(),
            source: self.source.clone(),
            source_offsets: self.source_offsets.clone(),
            source_cols: self.source_cols.clone(),
            values: Vec::new(),
            inverse_diagonal: Vec::new(),
        }
    }

    /// Checks that every matrix has the block's pattern (the renumbered
    /// entry `k` is entry `source[k]` of each), then gathers the values,
    /// checks symmetry and takes the inverse diagonal.
    fn set_values(&mut self, a: [&CsMat<f64>; CHANNELS]) -> Result<(), Error> {
        let n = self.rows();
        for (channel, m) in a.iter().enumerate() {
            if m.rows() != n {
                return Err(Error::BlockSize {
                    channel,
                    rows: m.rows(),
                    expected: n,
                });
            }
            let indptr = m.indptr();
            let indptr = indptr.to_proper();
            let cols = m.indices();
            let same = *indptr == self.source_offsets[..]
                && cols
                    .par_chunks(1 << 16)
                    .zip(self.source_cols.par_chunks(1 << 16))
                    .all(|(a, b)| a.iter().zip(b).all(|(&a, &b)| a == b as usize));
            if !same {
                let so = &self.source_offsets;
                let row = (0..n)
                    .find(|&i| {
                        let (ours, theirs) = (so[i]..so[i + 1], indptr[i]..indptr[i + 1]);
                        ours.len() != theirs.len()
                            || self.source_cols[ours]
                                .iter()
                                .zip(&cols[theirs])
                                .any(|(&a, &b)| a as usize != b)
                    })
                    .unwrap_or(n);
                return Err(Error::PatternMismatch { channel, row });
            }
        }
        let data = a.map(|m| m.data());
        self.values = self
            .source
            .par_iter()
            .map(|&e| {
                let e = e as usize;
                [data[0][e], data[1][e], data[2][e]]
            })
            .collect();
        self.check_symmetric()?;
        let mut inverse_diagonal = vec![[0.0; CHANNELS]; n];
        let bad = inverse_diagonal
            .par_iter_mut()
            .enumerate()
            .find_map_first(|(k, inv)| {
                let (cols, vals) = self.row(k);
                let d = cols
                    .iter()
                    .position(|&j| j as usize == k)
                    .map_or([0.0; CHANNELS], |e| vals[e]);
                for c in 0..CHANNELS {
                    if d[c] <= 0.0 {
                        return Some((c, self.order[k] as usize, d[c]));
                    }
                    inv[c] = 1.0 / d[c];
                }
                None
            });
        if let Some((channel, row, value)) = bad {
            return Err(Error::InMatrix {
                channel,
                error: Box::new(Error::BadDiagonal {
                    row,
                    value,
                    need: "Jacobi-preconditioned CG needs a positive diagonal",
                }),
            });
        }
        self.inverse_diagonal = inverse_diagonal;
        Ok(())
    }

    /// Rows (and columns) of each matrix.
    pub fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// Stored entries of the pattern.
    pub fn nnz(&self) -> usize {
        self.cols.len()
    }

    /// Bytes of its arrays (about 40 per entry).
    pub fn bytes(&self) -> usize {
        let n = self.rows();
        let nnz = self.nnz();
        nnz * (4 + 4 + 4 + 24) + (n + 1) * 16 + n * (4 + 24)
    }

    fn row(&self, i: usize) -> (&[u32], &[Lanes]) {
        let range = self.offsets[i]..self.offsets[i + 1];
        (&self.cols[range.clone()], &self.values[range])
    }

    /// Symmetry of the three matrices. The entry-by-entry check (below)
    /// looks up each mirror `(j, i)` in another row: a cache miss per
    /// entry on a mesh's scattered numbering, 100–200 ms at 10⁶ entries.
    /// So first a streaming test: `A` is symmetric exactly when
    /// `uᵀ A w = wᵀ A u` for all `u, w`; with `u, w` pseudo-random
    /// (a hash of the index, computed, not loaded), any asymmetry
    /// larger than rounding shows, in one pass over the rows. Only when it
    /// fails does the exact check run, to name the entry.
    fn check_symmetric(&self) -> Result<(), Error> {
        let n = self.rows();
        let partial: Vec<[Lanes; 3]> = (0..n)
            .into_par_iter()
            .with_min_len(ROWS)
            .fold(
                || [[0.0; CHANNELS]; 3],
                |mut acc, i| {
                    let (cols, vals) = self.row(i);
                    let (ui, wi) = probe(i);
                    for (&j, v) in cols.iter().zip(vals) {
                        let (uj, wj) = probe(j as usize);
                        for c in 0..CHANNELS {
                            acc[0][c] += v[c] * ui * wj;
                            acc[1][c] += v[c] * wi * uj;
                            acc[2][c] += (v[c] * ui * wj).abs();
                        }
                    }
                    acc
                },
            )
            .collect();
        let sums = partial.iter().fold([[0.0; CHANNELS]; 3], |mut s, p| {
            for k in 0..3 {
                for c in 0..CHANNELS {
                    s[k][c] += p[k][c];
                }
            }
            s
        });
        let symmetric =
            (0..CHANNELS).all(|c| (sums[0][c] - sums[1][c]).abs() <= 1e-10 * sums[2][c]);
        if symmetric {
            Ok(())
        } else {
            self.check_symmetric_entries()
        }
    }

    /// Every stored `(i, j)` has a stored `(j, i)` with the same three
    /// values up to rounding (the rule of [`crate::cg`]'s check); rows
    /// have no duplicates (`sprs` guarantees it), so the mirror is found
    /// by a scan of the (short) row.
    fn check_symmetric_entries(&self) -> Result<(), Error> {
        let n = self.rows();
        let lookup = |i: usize, j: usize| -> Option<Lanes> {
            let (cols, vals) = self.row(i);
            cols.iter().position(|&c| c as usize == j).map(|k| vals[k])
        };
        let zero = [0.0; CHANNELS];
        let bad = (0..n).into_par_iter().find_map_first(|i| {
            let (cols, vals) = self.row(i);
            let d_i = lookup(i, i).unwrap_or(zero);
            cols.iter().zip(vals).find_map(|(&j, &v)| {
                let j = j as usize;
                if j <= i {
                    return None;
                }
                let w = lookup(j, i).unwrap_or(zero);
                let d_j = lookup(j, j).unwrap_or(zero);
                (0..CHANNELS).find_map(|c| {
                    let scale = v[c]
                        .abs()
                        .max(w[c].abs())
                        .max((d_i[c] * d_j[c]).abs().sqrt());
                    ((v[c] - w[c]).abs() > 1e-10 * scale).then_some((c, i, j, v[c], w[c]))
                })
            })
        });
        match bad {
            Some((channel, row, col, value, transposed)) => Err(Error::InMatrix {
                channel,
                error: Box::new(Error::NotSymmetric {
                    row: self.order[row] as usize,
                    col: self.order[col] as usize,
                    value,
                    transposed,
                }),
            }),
            None => Ok(()),
        }
    }

    /// `y_c ← A_c x_c` for the three channels in one pass.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] for a vector of the wrong length.
    pub fn mul_vec(&self, x: [&[f64]; CHANNELS], y: [&mut [f64]; CHANNELS]) -> Result<(), Error> {
        let n = self.rows();
        for v in x {
            check_length("vector", v.len(), n)?;
        }
        for v in &y {
            check_length("output vector", v.len(), n)?;
        }
        let xs: Vec<Lanes> = self
            .order
            .par_iter()
            .map(|&i| std::array::from_fn(|c| x[c][i as usize]))
            .collect();
        let mut ys = vec![[0.0; CHANNELS]; n];
        self.mul_dot(&xs, &mut ys);
        for (c, y) in y.into_iter().enumerate() {
            for (&i, v) in self.order.iter().zip(&ys) {
                y[i as usize] = v[c];
            }
        }
        Ok(())
    }

    /// Row `i` of the three matrices times the vectors whose entries
    /// `x(j)` gives (the three channels' at column `j`).
    #[inline]
    fn row_times(&self, i: usize, x: impl Fn(usize) -> Lanes) -> Lanes {
        let (cols, vals) = self.row(i);
        let mut s = [0.0; CHANNELS];
        for (&j, v) in cols.iter().zip(vals) {
            let xj = x(j as usize);
            s[0] += v[0] * xj[0];
            s[1] += v[1] * xj[1];
            s[2] += v[2] * xj[2];
        }
        s
    }

    /// `q ← A p` (interleaved), returning `p_c · q_c` per channel, the
    /// partial sums added in chunk order (the same on any number of
    /// threads).
    fn mul_dot(&self, p: &[Lanes], q: &mut [Lanes]) -> Lanes {
        let partial: Vec<Lanes> = q
            .par_chunks_mut(ROWS)
            .enumerate()
            .map(|(chunk, q)| {
                let first = chunk * ROWS;
                let mut dot = [0.0; CHANNELS];
                for (k, q) in q.iter_mut().enumerate() {
                    let i = first + k;
                    *q = self.row_times(i, |j| p[j]);
                    for c in 0..CHANNELS {
                        dot[c] += p[i][c] * q[c];
                    }
                }
                dot
            })
            .collect();
        sum_lanes(&partial)
    }

    /// `r_c ← b_c − A_c x_c` for the channels in `which`, returning each
    /// `‖r_c‖` (0 for the others, whose `r` is left as it was).
    fn residual_into(
        &self,
        b: &[Vec<f64>; CHANNELS],
        x: &[Vec<f64>; CHANNELS],
        which: [bool; CHANNELS],
        r: &mut [Lanes],
    ) -> Lanes {
        let partial: Vec<Lanes> = r
            .par_chunks_mut(ROWS)
            .enumerate()
            .map(|(chunk, r)| {
                let first = chunk * ROWS;
                let mut sq = [0.0; CHANNELS];
                for (k, r) in r.iter_mut().enumerate() {
                    let i = first + k;
                    let s = self.row_times(i, |j| [x[0][j], x[1][j], x[2][j]]);
                    for c in (0..CHANNELS).filter(|&c| which[c]) {
                        r[c] = b[c][i] - s[c];
                        sq[c] += r[c] * r[c];
                    }
                }
                sq
            })
            .collect();
        sum_lanes(&partial).map(f64::sqrt)
    }

    /// `‖b_c − A_c x‖` for one channel's vector `x` (`r` is scratch; a
    /// short stop's rare path, so the other two lanes' products are
    /// simply wasted).
    fn channel_residual(&self, c: usize, b: &[f64], x: &[f64], r: &mut [f64]) -> f64 {
        let partial: Vec<f64> = r
            .par_chunks_mut(ROWS)
            .enumerate()
            .map(|(chunk, r)| {
                let first = chunk * ROWS;
                let mut sq = 0.0;
                for (k, r) in r.iter_mut().enumerate() {
                    let i = first + k;
                    *r = b[i] - self.row_times(i, |j| [x[j]; CHANNELS])[c];
                    sq += *r * *r;
                }
                sq
            })
            .collect();
        partial.iter().sum::<f64>().sqrt()
    }

    /// Jacobi-preconditioned CG on the three systems at once, each from
    /// its start vector `x[c]`: [`crate::cg`]'s iterations (its stops,
    /// restarts and best-iterate rule, per channel) with one pass over the
    /// matrix per iteration for all three, the update, preconditioner and
    /// dot products fused into one more.
    ///
    /// # Errors
    /// [`Error::DimensionMismatch`] or [`Error::NotFiniteVector`] for a
    /// vector, [`Error::InvalidOption`] for a bad tolerance, and
    /// [`Error::ChannelNotConverged`] (the first channel that stopped
    /// short, with every channel's report) when
    /// [`SolveOptions::require_convergence`] is on.
    pub fn cg(
        &self,
        b: [&[f64]; CHANNELS],
        x: [&mut [f64]; CHANNELS],
        options: &SolveOptions,
        monitor: Option<BlockMonitor<'_>>,
    ) -> Result<[Report; CHANNELS], Error> {
        self.solve(b, x, Precondition::Jacobi, options, monitor)
    }

    /// CG preconditioned by `m[c]` for channel `c` (a [`crate::VCycle`]
    /// per channel, say), the three systems at once as in
    /// [`cg`](Self::cg): the mat-vecs share one pass over the matrix, the
    /// preconditioners run one channel after the other.
    ///
    /// # Errors
    /// As [`cg`](Self::cg).
    pub fn pcg(
        &self,
        b: [&[f64]; CHANNELS],
        x: [&mut [f64]; CHANNELS],
        m: [&dyn Preconditioner; CHANNELS],
        options: &SolveOptions,
        monitor: Option<BlockMonitor<'_>>,
    ) -> Result<[Report; CHANNELS], Error> {
        self.solve(b, x, Precondition::Each(m), options, monitor)
    }

    fn solve(
        &self,
        b: [&[f64]; CHANNELS],
        mut x: [&mut [f64]; CHANNELS],
        m: Precondition<'_>,
        options: &SolveOptions,
        monitor: Option<BlockMonitor<'_>>,
    ) -> Result<[Report; CHANNELS], Error> {
        let n = self.rows();
        const RHS: [&str; CHANNELS] = [
            "right-hand side of channel 0",
            "right-hand side of channel 1",
            "right-hand side of channel 2",
        ];
        const START: [&str; CHANNELS] = [
            "start vector of channel 0",
            "start vector of channel 1",
            "start vector of channel 2",
        ];
        for c in 0..CHANNELS {
            check_vector(RHS[c], b[c], n)?;
            check_vector(START[c], x[c], n)?;
        }
        options.check()?;
        let mut no_monitor = |_: &Progress<'_>| ControlFlow::Continue(());
        let monitor = monitor.unwrap_or(&mut no_monitor);
        let mut solve = Solve::new(self, b, &x, m, options);
        let reports = solve.run(monitor);
        solve.write_back(&mut x);
        for (channel, report) in reports.iter().enumerate() {
            if options.settle(*report).is_err() {
                return Err(Error::ChannelNotConverged {
                    channel,
                    reports,
                    tolerance: options.tolerance,
                });
            }
        }
        Ok(reports)
    }
}

/// How a block solve preconditions.
#[derive(Clone, Copy)]
enum Precondition<'a> {
    /// The block's own diagonal, fused into the update pass.
    Jacobi,
    /// A preconditioner per channel.
    Each([&'a dyn Preconditioner; CHANNELS]),
}

/// How one channel's CG run ended (before the true residual decides).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum RunEnd {
    /// The recurrence reached the tolerance, or the iteration cap came.
    Normal,
    /// A recurrence scalar vanished or stopped being finite.
    Broke,
    /// The monitor said stop.
    Interrupted,
}

/// One channel's state across runs (restarts).
struct Lane {
    /// `‖b‖` (1 for `b = 0`).
    scale: f64,
    /// The true relative residual at the last restart.
    residual: f64,
    /// The recurrence's relative residual now.
    recurrence: f64,
    rz: f64,
    alpha: f64,
    beta: f64,
    done: usize,
    best: Option<Best>,
    report: Option<Report>,
}

/// A block solve in progress: the interleaved vectors and the lanes.
struct Solve<'s> {
    a: &'s Block3,
    /// `b` and `x` in the block's order.
    b: [Vec<f64>; CHANNELS],
    x: [Vec<f64>; CHANNELS],
    m: Precondition<'s>,
    options: &'s SolveOptions,
    r: Vec<Lanes>,
    z: Vec<Lanes>,
    p: Vec<Lanes>,
    q: Vec<Lanes>,
    /// A contiguous vector for one channel's residual or preconditioner.
    scratch: [Vec<f64>; 2],
    lanes: [Lane; CHANNELS],
}

impl<'s> Solve<'s> {
    fn new(
        a: &'s Block3,
        b: [&[f64]; CHANNELS],
        x: &[&mut [f64]; CHANNELS],
        m: Precondition<'s>,
        options: &'s SolveOptions,
    ) -> Self {
        let n = a.rows();
        let ordered =
            |v: &[f64]| -> Vec<f64> { a.order.par_iter().map(|&i| v[i as usize]).collect() };
        let b = b.map(ordered);
        let x = std::array::from_fn(|c| ordered(x[c]));
        let scales: Lanes = std::array::from_fn(|c| nonzero(norm(&b[c])));
        let lane = |c: usize| Lane {
            scale: scales[c],
            residual: f64::INFINITY,
            recurrence: f64::INFINITY,
            rz: 0.0,
            alpha: 0.0,
            beta: 0.0,
            done: 0,
            best: None,
            report: None,
        };
        Self {
            a,
            b,
            x,
            m,
            options,
            r: vec![[0.0; CHANNELS]; n],
            z: vec![[0.0; CHANNELS]; n],
            p: vec![[0.0; CHANNELS]; n],
            q: vec![[0.0; CHANNELS]; n],
            // Only a preconditioner of its own needs them (a short stop
            // makes the first when it needs it).
            scratch: match m {
                Precondition::Jacobi => [Vec::new(), Vec::new()],
                Precondition::Each(_) => [vec![0.0; n], vec![0.0; n]],
            },
            lanes: std::array::from_fn(lane),
        }
    }

    /// Puts the iterates back into the caller's vectors, in their order.
    fn write_back(&self, x: &mut [&mut [f64]; CHANNELS]) {
        for (x, ours) in x.iter_mut().zip(&self.x) {
            for (&i, &v) in self.a.order.iter().zip(ours) {
                x[i as usize] = v;
            }
        }
    }

    fn running(&self) -> [bool; CHANNELS] {
        std::array::from_fn(|c| self.lanes[c].report.is_none())
    }

    fn run(&mut self, monitor: BlockMonitor<'_>) -> [Report; CHANNELS] {
        let all = [true; CHANNELS];
        let norms = self.a.residual_into(&self.b, &self.x, all, &mut self.r);
        let tolerance = self.options.tolerance;
        let mut starting = [false; CHANNELS];
        for c in 0..CHANNELS {
            let lane = &mut self.lanes[c];
            lane.residual = norms[c] / lane.scale;
            lane.recurrence = lane.residual;
            lane.best = Some(Best::new(&self.x[c], lane.residual));
            if lane.residual <= tolerance {
                lane.report = Some(report(Stop::Converged, 0, lane.residual));
            } else if self.options.max_iterations == 0 {
                self.finish_short(c, Stop::MaxIterations);
            } else {
                starting[c] = true;
            }
        }
        self.begin_runs(starting);
        while self.running().iter().any(|&r| r) {
            let mut ends: [Option<RunEnd>; CHANNELS] = [None; CHANNELS];
            let pq = self.a.mul_dot(&self.p, &mut self.q);
            let mut stepping = self.running();
            for c in 0..CHANNELS {
                if !stepping[c] {
                    continue;
                }
                let alpha = self.lanes[c].rz / pq[c];
                if alpha.is_finite() && pq[c] > 0.0 {
                    self.lanes[c].alpha = alpha;
                } else {
                    stepping[c] = false;
                    ends[c] = Some(RunEnd::Broke);
                }
            }
            let (rr, rz_next) = self.update(stepping);
            for c in 0..CHANNELS {
                if !stepping[c] {
                    continue;
                }
                let lane = &mut self.lanes[c];
                lane.recurrence = rr[c].sqrt() / lane.scale;
                lane.done += 1;
                let (alpha, p) = (lane.alpha, &self.p);
                if let Some(best) = lane.best.as_mut() {
                    best.step_by(&self.x[c], lane.recurrence, |i, x| x - alpha * p[i][c]);
                }
            }
            let iteration = self.lanes.iter().map(|l| l.done).max().unwrap_or(0);
            let progress = Progress {
                iteration,
                residual: std::array::from_fn(|c| self.lanes[c].recurrence),
                alpha: std::array::from_fn(|c| {
                    if stepping[c] {
                        self.lanes[c].alpha
                    } else {
                        0.0
                    }
                }),
                beta: std::array::from_fn(|c| if stepping[c] { self.lanes[c].beta } else { 0.0 }),
                running: self.running(),
                x: &self.x,
                order: &self.a.order,
            };
            let interrupted = monitor(&progress).is_break();
            for c in 0..CHANNELS {
                if !stepping[c] {
                    continue;
                }
                let lane = &mut self.lanes[c];
                if interrupted {
                    ends[c] = Some(RunEnd::Interrupted);
                } else if lane.recurrence <= tolerance || lane.done >= self.options.max_iterations {
                    ends[c] = Some(RunEnd::Normal);
                } else {
                    let beta = rz_next[c] / lane.rz;
                    if beta.is_finite() {
                        lane.beta = beta;
                        lane.rz = rz_next[c];
                    } else {
                        ends[c] = Some(RunEnd::Broke);
                    }
                }
            }
            let continuing: [bool; CHANNELS] =
                std::array::from_fn(|c| stepping[c] && ends[c].is_none());
            self.next_directions(continuing);
            // The true residuals of the channels whose run ended, in one
            // pass over the matrix.
            let ending: [bool; CHANNELS] = std::array::from_fn(|c| ends[c].is_some());
            let mut restarting = [false; CHANNELS];
            if ending.iter().any(|&e| e) {
                let norms = self.a.residual_into(&self.b, &self.x, ending, &mut self.r);
                for c in 0..CHANNELS {
                    if let Some(end) = ends[c] {
                        restarting[c] = self.end_run(c, end, norms[c]);
                    }
                }
            }
            self.begin_runs(restarting);
        }
        std::array::from_fn(|c| {
            self.lanes[c]
                .report
                .unwrap_or(report(Stop::Breakdown, 0, f64::NAN))
        })
    }

    /// A new CG run for the channels in `which` from their current `r`:
    /// `z = M⁻¹ r`, `p = z`.
    fn begin_runs(&mut self, which: [bool; CHANNELS]) {
        if !which.iter().any(|&w| w) {
            return;
        }
        let rz = self.precondition(which);
        for c in 0..CHANNELS {
            if which[c] {
                self.lanes[c].rz = rz[c];
                self.lanes[c].beta = 0.0;
            }
        }
        self.p
            .par_chunks_mut(CHUNK)
            .zip(self.z.par_chunks(CHUNK))
            .for_each(|(p, z)| {
                for (p, z) in p.iter_mut().zip(z) {
                    for c in 0..CHANNELS {
                        if which[c] {
                            p[c] = z[c];
                        }
                    }
                }
            });
    }

    /// `z_c ← M_c⁻¹ r_c` for the channels in `which`, returning `r_c · z_c`.
    fn precondition(&mut self, which: [bool; CHANNELS]) -> Lanes {
        match self.m {
            Precondition::Jacobi => {
                let d = &self.a.inverse_diagonal;
                let partial: Vec<Lanes> = self
                    .z
                    .par_chunks_mut(CHUNK)
                    .zip(self.r.par_chunks(CHUNK).zip(d.par_chunks(CHUNK)))
                    .map(|(z, (r, d))| {
                        let mut rz = [0.0; CHANNELS];
                        for ((z, r), d) in z.iter_mut().zip(r).zip(d) {
                            for c in 0..CHANNELS {
                                if which[c] {
                                    z[c] = d[c] * r[c];
                                    rz[c] += r[c] * z[c];
                                }
                            }
                        }
                        rz
                    })
                    .collect();
                sum_lanes(&partial)
            }
            Precondition::Each(m) => {
                let mut rz = [0.0; CHANNELS];
                for c in 0..CHANNELS {
                    if !which[c] {
                        continue;
                    }
                    // The preconditioner works in the matrices' order.
                    let [rc, zc] = &mut self.scratch;
                    let order = &self.a.order;
                    for (&i, r) in order.iter().zip(&self.r) {
                        rc[i as usize] = r[c];
                    }
                    m[c].apply(rc, zc);
                    self.z
                        .par_iter_mut()
                        .zip(order)
                        .for_each(|(z, &i)| z[c] = zc[i as usize]);
                    rz[c] = dot(rc, zc);
                }
                rz
            }
        }
    }

    /// `x_c += α_c p_c`, `r_c −= α_c q_c` for the channels in `which`, then
    /// `z = M⁻¹ r`; returns `‖r_c‖²` and `r_c · z_c`. With Jacobi all of it
    /// is one pass.
    fn update(&mut self, which: [bool; CHANNELS]) -> (Lanes, Lanes) {
        let alpha: Lanes = std::array::from_fn(|c| self.lanes[c].alpha);
        let jacobi = matches!(self.m, Precondition::Jacobi);
        let d = &self.a.inverse_diagonal;
        let [x0, x1, x2] = &mut self.x;
        let partial: Vec<(Lanes, Lanes)> = x0
            .par_chunks_mut(CHUNK)
            .zip(x1.par_chunks_mut(CHUNK))
            .zip(x2.par_chunks_mut(CHUNK))
            .zip(
                self.r
                    .par_chunks_mut(CHUNK)
                    .zip(self.z.par_chunks_mut(CHUNK)),
            )
            .zip(self.p.par_chunks(CHUNK).zip(self.q.par_chunks(CHUNK)))
            .zip(d.par_chunks(CHUNK))
            .map(|(((((x0, x1), x2), (r, z)), (p, q)), d)| {
                let mut rr = [0.0; CHANNELS];
                let mut rz = [0.0; CHANNELS];
                let xs = [x0, x1, x2];
                for i in 0..r.len() {
                    for c in 0..CHANNELS {
                        if which[c] {
                            xs[c][i] += alpha[c] * p[i][c];
                            r[i][c] -= alpha[c] * q[i][c];
                            rr[c] += r[i][c] * r[i][c];
                            if jacobi {
                                z[i][c] = d[i][c] * r[i][c];
                                rz[c] += r[i][c] * z[i][c];
                            }
                        }
                    }
                }
                (rr, rz)
            })
            .collect();
        let rr = sum_lanes(&partial.iter().map(|p| p.0).collect::<Vec<_>>());
        let rz = if jacobi {
            sum_lanes(&partial.iter().map(|p| p.1).collect::<Vec<_>>())
        } else {
            self.precondition(which)
        };
        (rr, rz)
    }

    /// `p_c ← z_c + β_c p_c` for the channels in `which`.
    fn next_directions(&mut self, which: [bool; CHANNELS]) {
        if !which.iter().any(|&w| w) {
            return;
        }
        let beta: Lanes = std::array::from_fn(|c| self.lanes[c].beta);
        self.p
            .par_chunks_mut(CHUNK)
            .zip(self.z.par_chunks(CHUNK))
            .for_each(|(p, z)| {
                for (p, z) in p.iter_mut().zip(z) {
                    for c in 0..CHANNELS {
                        if which[c] {
                            p[c] = z[c] + beta[c] * p[c];
                        }
                    }
                }
            });
    }

    /// The end of channel `c`'s run, as in [`crate::pcg`]: the true
    /// residual (`norm`, with `r` holding `b − A x`) decides between
    /// stopping and a restart. Returns whether the channel restarts.
    fn end_run(&mut self, c: usize, end: RunEnd, norm: f64) -> bool {
        let lane = &mut self.lanes[c];
        let before = lane.residual;
        lane.residual = norm / lane.scale;
        lane.recurrence = lane.residual;
        let (residual, done) = (lane.residual, lane.done);
        let tolerance = self.options.tolerance;
        if end == RunEnd::Broke || !residual.is_finite() {
            self.finish_short(c, Stop::Breakdown);
            return false;
        }
        if end == RunEnd::Interrupted {
            self.lanes[c].report = Some(report(Stop::Interrupted, done, residual));
            return false;
        }
        let capped = done >= self.options.max_iterations;
        if residual > tolerance && residual >= before && !capped {
            // A restart that gains nothing would loop.
            self.finish_short(c, Stop::Stagnated);
            return false;
        }
        if let Some(best) = self.lanes[c].best.as_mut() {
            best.restarted(residual);
        }
        if residual <= tolerance {
            self.lanes[c].report = Some(report(Stop::Converged, done, residual));
            false
        } else if capped {
            self.finish_short(c, Stop::MaxIterations);
            false
        } else {
            true
        }
    }

    /// Stops channel `c` short of its tolerance with the best iterate it
    /// saw in `x` (finite, never worse than its start).
    fn finish_short(&mut self, c: usize, stop: Stop) {
        let (a, b) = (self.a, &self.b[c]);
        let lane = &mut self.lanes[c];
        let scale = lane.scale;
        let scratch = &mut self.scratch[0];
        scratch.resize(a.rows(), 0.0);
        let residual = match lane.best.take() {
            Some(best) => best.restore_with(&mut self.x[c], lane.residual, |v| {
                a.channel_residual(c, b, v, scratch) / scale
            }),
            None => lane.residual,
        };
        lane.residual = residual;
        lane.report = Some(report(stop, lane.done, residual));
    }
}

/// A breadth-first numbering of the graph of a symmetric pattern
/// (`order[k]` is the `k`-th row visited), each component from its
/// lowest-numbered vertex, so that every row's neighbours are numbered
/// close to it (Cuthill–McKee's locality, without its degree sort or
/// peripheral start, which matter for fill-in, not for a mat-vec's
/// cache). Serial and deterministic.
fn breadth_first(offsets: &[usize], cols: &[usize]) -> Vec<u32> {
    let n = offsets.len() - 1;
    let mut order: Vec<u32> = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    for start in 0..n {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        order.push(start as u32);
        let mut k = order.len() - 1;
        while k < order.len() {
            let i = order[k] as usize;
            for &j in &cols[offsets[i]..offsets[i + 1]] {
                if !seen[j] {
                    seen[j] = true;
                    order.push(j as u32);
                }
            }
            k += 1;
        }
    }
    order
}

/// The block's rows in chunks of [`ROWS`]: `(first row, its columns, its
/// values)` per chunk, for filling them in parallel.
fn row_chunks<'a>(
    offsets: &[usize],
    mut cols: &'a mut [u32],
    mut values: &'a mut [u32],
) -> Vec<(usize, &'a mut [u32], &'a mut [u32])> {
    let n = offsets.len() - 1;
    let mut out = Vec::with_capacity(n.div_ceil(ROWS));
    for first in (0..n).step_by(ROWS) {
        let len = offsets[(first + ROWS).min(n)] - offsets[first];
        let (c, rest_c) = std::mem::take(&mut cols).split_at_mut(len);
        let (v, rest_v) = std::mem::take(&mut values).split_at_mut(len);
        out.push((first, c, v));
        cols = rest_c;
        values = rest_v;
    }
    out
}

/// Each matrix on its own (CSR, square, finite), its errors naming it.
fn check_matrices(a: [&CsMat<f64>; CHANNELS]) -> Result<(), Error> {
    for (channel, m) in a.into_iter().enumerate() {
        check_square(m).map_err(|error| Error::InMatrix {
            channel,
            error: Box::new(error),
        })?;
    }
    Ok(())
}

/// Two pseudo-random values in `[−1, 1)` for index `i` (SplitMix64).
fn probe(i: usize) -> (f64, f64) {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let unit = |bits: u64| (bits >> 11) as f64 * (1.0 / (1u64 << 53) as f64) * 2.0 - 1.0;
    (
        unit(z),
        unit(z.rotate_left(32).wrapping_mul(0x2545_F491_4F6C_DD1D)),
    )
}

fn report(stop: Stop, iterations: usize, residual: f64) -> Report {
    Report {
        stop,
        iterations,
        residual,
    }
}

fn check_length(what: &'static str, found: usize, expected: usize) -> Result<(), Error> {
    if found == expected {
        Ok(())
    } else {
        Err(Error::DimensionMismatch {
            what,
            expected,
            found,
        })
    }
}

/// Per-chunk partial sums added in chunk order.
fn sum_lanes(partial: &[Lanes]) -> Lanes {
    partial.iter().fold([0.0; CHANNELS], |mut s, p| {
        for c in 0..CHANNELS {
            s[c] += p[c];
        }
        s
    })
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    crate::vector::dot(a, b)
}

fn norm(a: &[f64]) -> f64 {
    crate::vector::norm(a)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{VCycle, VCycleOptions, Weights, cg, grid, pcg};

    /// Three channels of one grid problem: the matrix plus a different
    /// absorption per channel (same pattern), and three right-hand sides.
    /// Matrices, right-hand sides and grid positions.
    type Channels = ([CsMat<f64>; 3], [Vec<f64>; 3], Vec<[f64; 3]>);

    fn channels(n: usize) -> Channels {
        let p = grid::diffusion([n, n, n], 4.0).unwrap();
        let shift = [0.0, 0.5, 3.0];
        let a = shift.map(|s| {
            let mut m = p.matrix.clone();
            let rows = m.rows();
            for i in 0..rows {
                *m.get_mut(i, i).unwrap() *= 1.0 + s;
            }
            m
        });
        let b = [1.0, 0.3, -2.0].map(|w| {
            p.rhs
                .iter()
                .enumerate()
                .map(|(i, v)| v * w + (i % 7) as f64 * 1e-3)
                .collect()
        });
        (a, b, p.positions)
    }

    /// `block.cg` from `x = 0`: its result and the iterates.
    fn cg_from_zero(
        block: &Block3,
        b: [&[f64]; 3],
        options: &SolveOptions,
        monitor: Option<BlockMonitor<'_>>,
    ) -> (Result<[Report; 3], Error>, [Vec<f64>; 3]) {
        let n = block.rows();
        let mut x = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x0, x1, x2] = &mut x;
        (block.cg(b, [x0, x1, x2], options, monitor), x)
    }

    #[test]
    fn a_block_solve_is_three_separate_solves() {
        let (a, b, _) = channels(12);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let options = SolveOptions::new(1e-9, 500);
        let mut x = [
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
        ];
        let [x0, x1, x2] = &mut x;
        let reports = block
            .cg([&b[0], &b[1], &b[2]], [x0, x1, x2], &options, None)
            .unwrap();
        for c in 0..3 {
            let mut alone = vec![0.0; block.rows()];
            let single = cg(&a[c], &b[c], &mut alone, &options).unwrap();
            assert!(reports[c].converged());
            // The same recurrence, to rounding: the same iteration count
            // give or take one, and the same solution.
            assert!(
                reports[c].iterations.abs_diff(single.iterations) <= 1,
                "{c}: {reports:?} vs {single:?}"
            );
            let diff = x[c]
                .iter()
                .zip(&alone)
                .map(|(u, v)| (u - v).abs())
                .fold(0.0, f64::max);
            let size = alone.iter().map(|v| v.abs()).fold(0.0, f64::max);
            assert!(diff <= 1e-7 * size, "{c}: {diff} of {size}");
        }
        // Channels stop on their own: the most absorbing converges first.
        assert!(reports[2].iterations < reports[0].iterations);
    }

    #[test]
    fn block_pcg_with_v_cycles_matches_pcg() {
        let (a, b, positions) = channels(10);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let v: Vec<VCycle<'_>> = a
            .iter()
            .map(|m| {
                VCycle::new(m, Weights::Positions(&positions), &VCycleOptions::default()).unwrap()
            })
            .collect();
        let options = SolveOptions::new(1e-8, 200);
        let mut x = [
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
        ];
        let [x0, x1, x2] = &mut x;
        let reports = block
            .pcg(
                [&b[0], &b[1], &b[2]],
                [x0, x1, x2],
                [&v[0], &v[1], &v[2]],
                &options,
                None,
            )
            .unwrap();
        for c in 0..3 {
            let mut alone = vec![0.0; block.rows()];
            let single = pcg(&a[c], &b[c], &mut alone, &v[c], &options).unwrap();
            // The same iterations, to rounding (the block sums in its own order).
            assert!(
                reports[c].iterations.abs_diff(single.iterations) <= 1,
                "{c}: {:?} vs {single:?}",
                reports[c]
            );
            assert!(reports[c].residual <= 1e-8);
        }
    }

    #[test]
    fn the_monitor_sees_each_iteration_and_can_stop_all_channels() {
        let (a, b, _) = channels(8);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let mut x = [
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
            vec![0.0; block.rows()],
        ];
        let [x0, x1, x2] = &mut x;
        let mut seen = Vec::new();
        let mut monitor = |p: &Progress<'_>| {
            seen.push((p.iteration(), p.residual()));
            if p.iteration() == 3 {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        };
        let options = SolveOptions::new(1e-12, 100);
        let reports = block
            .cg(
                [&b[0], &b[1], &b[2]],
                [x0, x1, x2],
                &options,
                Some(&mut monitor),
            )
            .unwrap();
        assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), [1, 2, 3]);
        // CG's residual need not fall every step, but it is reported.
        assert!(
            seen.iter()
                .all(|s| s.1.iter().all(|r| r.is_finite() && *r > 0.0))
        );
        for r in reports {
            assert_eq!((r.stop, r.iterations), (Stop::Interrupted, 3));
        }
    }

    #[test]
    fn short_solves_are_errors_naming_the_channel_or_reports() {
        let (a, b, _) = channels(8);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let n = block.rows();
        let err = cg_from_zero(
            &block,
            [&b[0], &b[1], &b[2]],
            &SolveOptions::new(1e-12, 2),
            None,
        )
        .0
        .unwrap_err();
        assert!(
            matches!(err, Error::ChannelNotConverged { channel: 0, reports, .. } if reports.iter().all(|r| r.stop == Stop::MaxIterations && r.iterations == 2)),
            "{err}"
        );
        // A zero right-hand side is solved at once (x = 0).
        let zero = vec![0.0; n];
        let reports = cg_from_zero(
            &block,
            [&zero, &b[1], &zero],
            &SolveOptions::new(1e-8, 500),
            None,
        )
        .0
        .unwrap();
        assert_eq!(reports[0].iterations, 0);
        assert!(reports[1].iterations > 0);
    }

    #[test]
    fn bad_blocks_and_vectors_are_named() {
        let (a, b, _) = channels(5);
        let other = grid::diffusion([5, 5, 6], 4.0).unwrap().matrix;
        let err = Block3::new([&a[0], &other, &a[2]]).unwrap_err();
        assert_eq!(
            err.to_string(),
            "matrix 1 of the block has 150 rows, matrix 0 has 125"
        );
        // Same size, another pattern from row 0 on: (i, i ± 1) against
        // (i, i ± 2).
        let band = |k: usize| {
            let mut t = sprs::TriMat::new((6, 6));
            for i in 0..6 {
                t.add_triplet(i, i, 4.0);
                if i + k < 6 {
                    t.add_triplet(i, i + k, -1.0);
                    t.add_triplet(i + k, i, -1.0);
                }
            }
            t.to_csr::<usize>()
        };
        let (one, two) = (band(1), band(2));
        assert!(matches!(
            Block3::new([&one, &one, &two]),
            Err(Error::PatternMismatch { channel: 2, row: 0 })
        ));
        let mut skew = a[2].clone();
        *skew.get_mut(0, 1).unwrap() += 0.5;
        let err = Block3::new([&a[0], &a[1], &skew]).unwrap_err();
        assert!(
            matches!(&err, Error::InMatrix { channel: 2, error }
                if matches!(**error, Error::NotSymmetric { row: 0, col: 1, .. }
                    | Error::NotSymmetric { row: 1, col: 0, .. })),
            "{err}"
        );
        assert!(
            err.to_string()
                .starts_with("matrix 2 of the block: CG needs a symmetric")
        );
        let mut negative = a[1].clone();
        *negative.get_mut(4, 4).unwrap() = -1.0;
        assert!(matches!(
            Block3::new([&a[0], &negative, &a[2]]),
            Err(Error::InMatrix { channel: 1, .. })
        ));
        let mut nan = a[0].clone();
        *nan.get_mut(3, 3).unwrap() = f64::NAN;
        let err = Block3::new([&a[0], &a[1], &nan]).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("matrix 2 of the block: matrix entry (3, 3) is NaN"),
            "{err}"
        );
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let n = block.rows();
        let mut x = [vec![0.0; n], vec![f64::NAN; n], vec![0.0; n]];
        let [x0, x1, x2] = &mut x;
        let err = block
            .cg(
                [&b[0], &b[1], &b[2]],
                [x0, x1, x2],
                &SolveOptions::default(),
                None,
            )
            .unwrap_err();
        assert!(
            matches!(
                err,
                Error::NotFiniteVector {
                    what: "start vector of channel 1",
                    index: 0,
                    ..
                }
            ),
            "{err}"
        );
        let short = vec![1.0; n - 1];
        let mut y = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [y0, y1, y2] = &mut y;
        assert!(matches!(
            block.cg(
                [&b[0], &short, &b[2]],
                [y0, y1, y2],
                &SolveOptions::default(),
                None
            ),
            Err(Error::DimensionMismatch { .. })
        ));
    }

    #[test]
    fn refreshed_values_solve_as_a_new_block() {
        let (a, b, _) = channels(6);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let scaled: Vec<CsMat<f64>> = a.iter().map(|m| m.map(|v| 2.0 * v)).collect();
        let block = block
            .refreshed([&scaled[0], &scaled[1], &scaled[2]])
            .unwrap();
        let fresh = Block3::new([&scaled[0], &scaled[1], &scaled[2]]).unwrap();
        let n = block.rows();
        let solve = |block: &Block3| {
            let (r, x) = cg_from_zero(
                block,
                [&b[0], &b[1], &b[2]],
                &SolveOptions::new(1e-10, 500),
                None,
            );
            (x, r.unwrap())
        };
        assert_eq!(solve(&block), solve(&fresh));
        // Half the solution of the unscaled system.
        let mut half = vec![0.0; n];
        let _ = cg(&a[0], &b[0], &mut half, &SolveOptions::new(1e-10, 500)).unwrap();
        let x = solve(&block).0;
        assert!(
            x[0].iter()
                .zip(&half)
                .all(|(u, v)| (2.0 * u - v).abs() <= 1e-7 * v.abs().max(1e-3))
        );
        // Another pattern is refused.
        let other = grid::diffusion([6, 6, 7], 4.0).unwrap().matrix;
        assert!(matches!(
            block.refreshed([&scaled[0], &other, &scaled[2]]),
            Err(Error::BlockSize { channel: 1, .. })
        ));
        assert_eq!(solve(&block), solve(&fresh));
    }

    #[test]
    fn the_block_mat_vec_is_three_mat_vecs() {
        let (a, b, _) = channels(6);
        let block = Block3::new([&a[0], &a[1], &a[2]]).unwrap();
        let n = block.rows();
        let mut y = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [y0, y1, y2] = &mut y;
        block.mul_vec([&b[0], &b[1], &b[2]], [y0, y1, y2]).unwrap();
        for c in 0..3 {
            let mut single = vec![0.0; n];
            crate::matrix::mul_vec(&a[c], &b[c], &mut single);
            let scale = single.iter().map(|v| v.abs()).fold(0.0, f64::max);
            for (u, v) in single.iter().zip(&y[c]) {
                assert!((u - v).abs() <= 1e-13 * scale, "{u} vs {v}");
            }
        }
    }
}
