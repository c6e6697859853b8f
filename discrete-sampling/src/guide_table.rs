//! The lookup-table accelerated CDF of Šik & Křivánek 2013, Sec. 4 (the
//! guide table of Chen & Asau 1974).
//!
//! `[0, 1)` is cut into `m` equal cells. For cell `k`, `C_k^begin` is the
//! first entry whose CDF value reaches the cell, and since
//! `C_k^end = C_{k+1}^begin` one index per cell suffices (Fig. 5). A sample
//! looks up the cell of `u` in constant time and bisects only inside
//! `[C_k^begin, C_{k+1}^begin]`, which for `m ≈ 4 n` is one or two entries.
//!
//! The cell of a value `x ∈ [0, 1]` is `(bits(x) · m) >> 64` with
//! `bits(x) = 2 ⌊x · 2⁶³⌋` (exactly the 53 bits of a variate), one integer
//! function ([`cell_of_bits`]) used both when the table is built (on CDF
//! values) and when it is searched (on the variate). Because it is monotone,
//! the answer always lies inside the stored range, with no exactness
//! argument about `k / m` in binary needed; and because it is integer
//! arithmetic, a draw whose cell holds a single entry never converts to or
//! compares floating point at all.

use rand::distr::Distribution;

use crate::cdf::Cdf;
use crate::uniform::{bits_to_unit, clamp_unit, fill_batch, scale_bits, value_bits, variate_bits};
use crate::{DiscreteSampler, Error, InvertibleSampler};

/// Cells per CDF entry used by [`GuideTable::new`].
///
/// The paper found about 4 best for mesh sampling (Fig. 7). The comparison
/// example measures 1/4, 1, 4 and 16 on this implementation: at 10⁵–10⁷
/// entries 4 is the best ratio or within 7% of it on every shape measured,
/// and 16 costs four times the memory for no consistent gain. At 10³ entries,
/// where any table sits in L1, 16 is 8–25% faster: pass it to
/// [`GuideTable::with_ratio`] for small, hot distributions.
pub const DEFAULT_RATIO: f64 = 4.0;

/// The largest table ratio [`GuideTable::with_ratio`] accepts.
pub const MAX_RATIO: f64 = 1024.0;

/// The table's memory budget: at most 2²⁸ cells (1 GiB). A larger
/// `ratio · n` is clamped to it, which changes the speed only, never an
/// index (the table is exact at any size).
pub const MAX_CELLS: usize = 1 << 28;

/// Tables at least this large are filled on several threads with `rayon`.
#[cfg(feature = "rayon")]
const PARALLEL_CELLS: usize = 1 << 20;

/// Cells handled by one task of the parallel fill (fixed, so the work split
/// never depends on the number of threads; the result never does either).
#[cfg(feature = "rayon")]
const CHUNK_CELLS: usize = 1 << 16;

/// A discrete distribution sampled by a lookup table over the codomain of its
/// `f64` CDF (Šik & Křivánek 2013, Sec. 4).
///
/// It returns exactly the index that [`CdfBisection`](crate::CdfBisection)
/// returns for every `u` (same CDF, same tie rule), so it keeps the order of
/// the inversion method, unlike an alias table, while being faster than
/// bisection.
///
/// # Performance
/// Build: two passes, `8 (n + 1) + 4 (m + 1)` bytes for `m = ratio · n`
/// cells. Sample: one table load plus one or two CDF loads on average; a
/// bisection only inside cells that hold many CDF steps (long runs of tiny
/// weights).
///
/// # Example
/// ```
/// use discrete_sampling::{DiscreteSampler, GuideTable};
/// use rand::distr::Distribution;
/// use rand::SeedableRng;
///
/// let lights = GuideTable::new(&[10.0f32, 1.0, 0.0, 5.0])?;
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
/// let light = lights.sample(&mut rng);
/// assert!(light != 2); // weight zero is never returned
/// let (i, u_reused) = lights.sample_remapped(0.5);
/// assert_eq!(i, 0);
/// assert!((u_reused - 0.8).abs() < 1e-12); // 0.5 is 80% into entry 0's interval
/// # Ok::<(), discrete_sampling::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct GuideTable {
    /// `cdf[0] = 0`, `cdf[i + 1]` = mass of `0..=i`, `cdf[n] = 1`.
    cdf: Cdf,
    /// `table[k]` = first entry `i` with `cell_of_value(cdf[i + 1]) >= k`;
    /// `table[m] = n - 1`.
    table: Vec<u32>,
    /// Number of cells `m`.
    cells: u64,
    /// Whether the CDF is small enough to stay in cache, so that reading it
    /// is cheaper than a mispredicted branch (see `search_bits`).
    cdf_in_cache: bool,
}

/// CDFs up to this many entries (1 MiB, within a typical L2) are treated as
/// cache-resident.
const CACHE_RESIDENT_ENTRIES: usize = 1 << 17;

/// The cell of a value from its bits `⌊x · 2⁶⁴⌋`. Monotone, which is all the
/// search needs; always below `cells`.
#[inline]
fn cell_of_bits(bits: u64, cells: u64) -> usize {
    scale_bits(bits, cells).0
}

/// The cell of a CDF value in `[0, 1]` (1 falls into the last cell).
#[inline]
fn cell_of_value(x: f64, cells: u64) -> usize {
    cell_of_bits(value_bits(x), cells)
}

impl GuideTable {
    /// Builds the distribution with [`DEFAULT_RATIO`] cells per entry.
    ///
    /// # Errors
    /// See [`Error`]: empty, NaN, infinite, negative or all-zero weights.
    pub fn new<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        Self::with_ratio(weights, DEFAULT_RATIO)
    }

    /// Builds the distribution with `round(ratio · n)` cells (at least one,
    /// at most [`MAX_CELLS`]).
    /// The paper's Fig. 7 varies this ratio from 1/4 to 16.
    ///
    /// # Errors
    /// [`Error::InvalidRatio`] unless `0 < ratio ≤ `[`MAX_RATIO`] (a larger
    /// table only costs memory: 4 bytes a cell), and the weight errors of
    /// [`new`](Self::new).
    pub fn with_ratio<W: Copy + Into<f64>>(weights: &[W], ratio: f64) -> Result<Self, Error> {
        if !(ratio > 0.0 && ratio <= MAX_RATIO) {
            return Err(Error::InvalidRatio { ratio });
        }
        Ok(Self::from_cdf(Cdf::new(weights)?, ratio))
    }

    /// Builds the table over an already validated, normalised CDF.
    fn from_cdf(cdf: Cdf, ratio: f64) -> Self {
        let n = cdf.len() - 1;
        let cells = ((n as f64 * ratio).round() as usize).clamp(1, MAX_CELLS);
        let mut table = vec![0u32; cells + 1];
        fill_table(&cdf, &mut table[..cells]);
        table[cells] = (n - 1) as u32;
        Self {
            cdf_in_cache: n <= CACHE_RESIDENT_ENTRIES,
            cdf,
            table,
            cells: cells as u64,
        }
    }

    /// Number of lookup-table cells.
    pub fn cells(&self) -> usize {
        self.table.len() - 1
    }

    /// The normalised CDF, `len() + 1` values from 0 to 1.
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }

    /// Heap memory used, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.cdf.len() * size_of::<f64>() + self.table.len() * size_of::<u32>()
    }

    /// The index of a variate given by its bits (`u = bits · 2⁻⁶⁴`): the
    /// first `i` with `cdf[i + 1] > u`. `unit` gives `u` itself; it is only
    /// called when the CDF must be compared, so the random-number path never
    /// converts a draw answered by the table alone.
    #[inline]
    fn search_with(&self, bits: u64, unit: impl Fn() -> f64) -> usize {
        let k = cell_of_bits(bits, self.cells);
        // The answer lies in [lo, hi] (see the module docs); there are
        // 1 + 1/ratio candidates on average.
        let lo = self.table[k] as usize;
        let hi = self.table[k + 1] as usize;
        if self.cdf_in_cache {
            // One or two candidates (all but a few percent of draws) without
            // a data-dependent branch: reading the cached CDF costs less than
            // mispredicting which case this is. With one candidate,
            // cdf[lo + 1] > u holds and nothing is added.
            if hi - lo <= 1 {
                return lo + usize::from(self.cdf[lo + 1] <= unit());
            }
        } else if lo == hi {
            // A cell inside one entry's interval: answered from the table
            // alone, without a second cache miss on the CDF.
            return lo;
        }
        self.search_between(unit(), lo, hi)
    }

    /// The index of variate bits from the random-number path.
    #[inline]
    fn search_bits(&self, bits: u64) -> usize {
        self.search_with(bits, || bits_to_unit(bits))
    }

    /// The index of a caller's variate `u`, already clamped to `[0, 1)`.
    #[inline]
    fn search(&self, u: f64) -> usize {
        self.search_with(value_bits(u), || u)
    }

    /// The answer among `lo..=hi` (`lo < hi`), knowing `cdf[hi + 1] > u`.
    #[inline]
    fn search_between(&self, u: f64, lo: usize, hi: usize) -> usize {
        // Bisection with a branch-free step (the comparison is a coin flip
        // the predictor cannot learn); its trip count depends on the range
        // only. The candidates are base..base + size.
        let mut base = lo;
        let mut size = hi - lo + 1;
        while size > 1 {
            let half = size / 2;
            // Entry base + half - 1 ends at cdf[base + half]; if that is <= u
            // the answer is at or after base + half.
            let step = usize::from(self.cdf[base + half] <= u).wrapping_neg() & half;
            base += step;
            size -= half;
        }
        base
    }
}

/// Fills `table[k]` for every cell `k < table.len()`, on several threads for
/// large tables when the `rayon` feature is on (same result either way).
fn fill_table(cdf: &[f64], table: &mut [u32]) {
    #[cfg(feature = "rayon")]
    if table.len() >= PARALLEL_CELLS {
        use rayon::prelude::*;
        let cells = table.len();
        table
            .par_chunks_mut(CHUNK_CELLS)
            .enumerate()
            .for_each(|(chunk, part)| fill_cells(cdf, cells, chunk * CHUNK_CELLS, part));
        return;
    }
    let cells = table.len();
    fill_cells(cdf, cells, 0, table);
}

/// Fills the cells `first_cell..first_cell + part.len()` of a table with
/// `cells` cells.
///
/// `table[k]`, the first entry whose cell is at least `k`, is also the number
/// of entries whose cell is below `k`, because cells grow with the index. So
/// the fill is a histogram of the entries' cells and a prefix sum, both
/// sequential passes.
fn fill_cells(cdf: &[f64], cells: usize, first_cell: usize, part: &mut [u32]) {
    let n = cdf.len() - 1;
    // The last entry ends at 1 and bounds every cell; it is never counted.
    let steps = &cdf[1..n];
    let m = cells as u64;
    let end_cell = first_cell + part.len();
    let start = steps.partition_point(|&c| cell_of_value(c, m) < first_cell);
    part.fill(0);
    for &c in &steps[start..] {
        let cell = cell_of_value(c, m);
        if cell + 1 >= end_cell {
            break;
        }
        part[cell + 1 - first_cell] += 1;
    }
    let mut below = start as u32;
    for slot in part.iter_mut() {
        below += *slot;
        *slot = below;
    }
}

impl DiscreteSampler for GuideTable {
    fn from_weights<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        Self::new(weights)
    }

    fn memory_bytes(&self) -> usize {
        Self::memory_bytes(self)
    }

    fn len(&self) -> usize {
        self.cdf.entries()
    }

    fn pdf(&self, index: usize) -> f64 {
        self.cdf.pdf(index)
    }

    #[inline]
    fn sample_remapped(&self, u: f64) -> (usize, f64) {
        let u = clamp_unit(u);
        self.cdf.remapped(self.search(u), u)
    }

    fn sample_u(&self, u: f64) -> usize {
        self.search(clamp_unit(u))
    }

    #[inline]
    fn sample_rng<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.search_bits(variate_bits(rng.next_u64()))
    }

    fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [usize]) {
        fill_batch(rng, out, |bits| self.search_bits(bits));
    }
}

impl InvertibleSampler for GuideTable {
    fn invert(&self, index: usize) -> Option<f64> {
        self.cdf.invert(index)
    }
}

impl Distribution<usize> for GuideTable {
    #[inline]
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.sample_rng(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::uniform::unit_to_bits;

    /// The table invariant, checked directly: every `u` in cell `k` has its
    /// answer inside `[table[k], table[k + 1]]`.
    #[test]
    fn table_brackets_every_answer() {
        let weights: Vec<f64> = (0..997)
            .map(|i| {
                if i % 7 == 0 {
                    0.0
                } else {
                    ((i * 37 % 101) as f64).powi(3)
                }
            })
            .collect();
        for ratio in [0.05, 0.25, 1.0, 4.0, 16.0] {
            let g = GuideTable::with_ratio(&weights, ratio).unwrap();
            for j in 0..20_000 {
                let u = j as f64 / 20_000.0;
                let k = cell_of_bits(unit_to_bits(u), g.cells);
                let answer = g.cdf[1..].partition_point(|&c| c <= u);
                assert!(g.table[k] as usize <= answer && answer <= g.table[k + 1] as usize);
                assert_eq!(g.search(u), answer);
                if bits_to_unit(unit_to_bits(u)) == u {
                    assert_eq!(g.search_bits(unit_to_bits(u)), answer);
                }
            }
        }
    }

    #[test]
    fn single_cell_is_plain_bisection() {
        let g = GuideTable::with_ratio(&[1.0, 2.0, 3.0, 4.0], 1e-9).unwrap();
        assert_eq!(g.cells(), 1);
        assert_eq!(g.sample_u(0.0), 0);
        assert_eq!(g.sample_u(0.95), 3);
    }

    #[test]
    fn rejects_bad_ratios() {
        for ratio in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e9] {
            let err = GuideTable::with_ratio(&[1.0], ratio).unwrap_err();
            assert!(matches!(err, Error::InvalidRatio { .. }));
        }
    }

    /// The parallel fill must equal the serial one cell for cell.
    #[cfg(feature = "rayon")]
    #[test]
    fn parallel_fill_equals_serial() {
        let weights: Vec<f64> = (0..400_000).map(|i| ((i % 1000) as f64).powi(2)).collect();
        let cdf = Cdf::new(&weights).unwrap();
        let cells = 3 * PARALLEL_CELLS / 2;
        let mut parallel = vec![0u32; cells];
        fill_table(&cdf, &mut parallel);
        let mut serial = vec![0u32; cells];
        fill_cells(&cdf, cells, 0, &mut serial);
        assert_eq!(parallel, serial);
    }
}
