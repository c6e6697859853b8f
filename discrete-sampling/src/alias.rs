//! Walker's alias method, built by Vose's O(n) algorithm (Vose 1991).

use rand::distr::Distribution;

use crate::weights::{ONE_MINUS_EPSILON, checked_total, clamp_unit, unit_f64};
use crate::{DiscreteSampler, Error};

/// One column of the table: below `threshold` the column's own entry,
/// above it the alias. Packed so a sample touches one cache line.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Column {
    threshold: f64,
    alias: u32,
}

/// A discrete distribution sampled in constant time by Walker's alias
/// method, with the table built by Vose's algorithm.
///
/// `u · n` picks a column and its fractional part decides between the
/// column's entry and its alias, so one `u64` of randomness makes one sample
/// (rand_distr's `WeightedAliasIndex` draws two).
///
/// Unlike the CDF samplers, the alias method does not keep the order of `u`:
/// neighbouring variates can give distant entries, and an entry's variates
/// are scattered over several columns. Use [`GuideTable`](crate::GuideTable)
/// with stratified or low-discrepancy variates; there is no `invert`.
///
/// # Performance
/// Build: three passes, `16 n` bytes of table plus `8 n` for
/// [`pdf`](DiscreteSampler::pdf) and `8 n` of scratch during the build.
/// Sample: one load, no search.
///
/// # Example
/// ```
/// use discrete_sampling::{AliasTable, DiscreteSampler};
/// use rand::distr::Distribution;
/// use rand::SeedableRng;
///
/// let table = AliasTable::new(&[1.0, 2.0, 0.0, 1.0])?;
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(1);
/// let mut counts = [0usize; 4];
/// for _ in 0..10_000 {
///     counts[table.sample(&mut rng)] += 1;
/// }
/// assert_eq!(counts[2], 0);
/// assert!((table.pdf(1) - 0.5).abs() < 1e-15);
/// # Ok::<(), discrete_sampling::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct AliasTable {
    columns: Vec<Column>,
    /// `w_i / Σw`, for `pdf` only (kept out of the sampling cache lines).
    probabilities: Vec<f64>,
    /// `n` as `f64`.
    len_f: f64,
}

impl AliasTable {
    /// Builds the alias table of `weights`.
    ///
    /// # Errors
    /// See [`Error`]: empty, NaN, infinite, negative or all-zero weights.
    pub fn new<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        let total = checked_total(weights)?;
        let n = weights.len();
        let scale = n as f64 / total;

        // Scaled weights: mean 1. Entries below 1 are "small" and donate the
        // rest of their column to a "large" one.
        let mut scaled = Vec::with_capacity(n);
        let mut probabilities = Vec::with_capacity(n);
        let mut small: Vec<u32> = Vec::new();
        let mut large: Vec<u32> = Vec::new();
        let mut heaviest = 0usize;
        for (i, &w) in weights.iter().enumerate() {
            let w: f64 = w.into();
            let p = w * scale;
            if p < 1.0 {
                small.push(i as u32);
            } else {
                large.push(i as u32);
            }
            if w > weights[heaviest].into() {
                heaviest = i;
            }
            scaled.push(p);
            probabilities.push(w / total);
        }

        let mut columns: Vec<Column> = (0..n)
            .map(|i| Column {
                threshold: 1.0,
                alias: i as u32,
            })
            .collect();
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            columns[s as usize] = Column {
                threshold: scaled[s as usize],
                alias: l,
            };
            // Vose's stable form: (p_l + p_s) - 1, not p_l - (1 - p_s).
            let rest = (scaled[l as usize] + scaled[s as usize]) - 1.0;
            scaled[l as usize] = rest;
            if rest < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // What is left is full columns up to rounding (threshold 1, alias
        // itself). A zero weight can only be left over through rounding; it
        // must still never be drawn, so it hands its whole column away.
        for s in small {
            if probabilities[s as usize] == 0.0 {
                columns[s as usize] = Column {
                    threshold: 0.0,
                    alias: heaviest as u32,
                };
            }
        }
        Ok(Self {
            columns,
            probabilities,
            len_f: n as f64,
        })
    }

    /// Heap memory used, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.columns.len() * size_of::<Column>() + self.probabilities.len() * size_of::<f64>()
    }

    /// The probability the table actually realises for each entry:
    /// `(threshold_i + Σ_{k: alias_k = i} (1 − threshold_k)) / n`. Equal to
    /// [`pdf`](DiscreteSampler::pdf) up to rounding; exposed so tests and
    /// sceptical users can check the table exactly.
    pub fn realized_probabilities(&self) -> Vec<f64> {
        let mut mass = vec![0.0f64; self.columns.len()];
        for (k, c) in self.columns.iter().enumerate() {
            mass[k] += c.threshold;
            mass[c.alias as usize] += 1.0 - c.threshold;
        }
        for m in &mut mass {
            *m /= self.len_f;
        }
        mass
    }

    #[inline]
    fn pick(&self, u: f64) -> (usize, f64, Column) {
        let x = u * self.len_f;
        let k = (x as usize).min(self.columns.len() - 1);
        let column = self.columns[k];
        (k, x - k as f64, column)
    }
}

impl DiscreteSampler for AliasTable {
    fn from_weights<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        Self::new(weights)
    }

    fn len(&self) -> usize {
        self.columns.len()
    }

    fn pdf(&self, index: usize) -> f64 {
        self.probabilities.get(index).copied().unwrap_or(0.0)
    }

    #[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
    fn sample_remapped(&self, u: f64) -> (usize, f64) {
        let (k, frac, c) = self.pick(clamp_unit(u));
        let (index, rest) = if frac < c.threshold {
            (k, frac / c.threshold)
        } else {
            (c.alias as usize, (frac - c.threshold) / (1.0 - c.threshold))
        };
        // NaN (0/0 in a degenerate column) becomes 0 through max.
        (index, rest.max(0.0).min(ONE_MINUS_EPSILON))
    }

    #[inline]
    fn sample_u(&self, u: f64) -> usize {
        let (k, frac, c) = self.pick(clamp_unit(u));
        if frac < c.threshold {
            k
        } else {
            c.alias as usize
        }
    }

    #[inline]
    fn sample_rng<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        let (k, frac, c) = self.pick(unit_f64(rng));
        if frac < c.threshold {
            k
        } else {
            c.alias as usize
        }
    }
}

impl Distribution<usize> for AliasTable {
    #[inline]
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.sample_rng(rng)
    }
}
