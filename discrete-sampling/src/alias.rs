//! Walker's alias method, built by Vose's O(n) algorithm (Vose 1991).

use rand::distr::Distribution;

use crate::uniform::{ONE_MINUS_EPSILON, fill_batch, scale_bits, unit_to_bits, variate_bits};
use crate::weights::checked_total;
use crate::{DiscreteSampler, Error};

/// One column of the table: below `threshold · 2⁻⁶⁴` the column's own
/// entry, above it the alias. The variate's position inside the column is
/// the low 64 bits of the product that picked the column, so the choice is
/// one integer comparison and exact to `2⁻⁶⁴`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Column {
    threshold: u64,
    alias: u32,
}

/// End of a list threaded through the `alias` fields during the build.
const NIL: u32 = u32::MAX;

/// `2⁶⁴` as `f64`.
const TWO_POW_64: f64 = 18_446_744_073_709_551_616.0;

/// A column's share `t` in 64-bit fixed point, truncated to a multiple of
/// `2⁻⁶³`; `t ≥ 1` gives a full column minus `2⁻⁶³`, `t ≤ 0` an empty one.
///
/// Through `i64`: one signed conversion, where `as u64` needs a branch on
/// `2⁶³` that is a coin flip between small and large entries.
#[inline]
fn fixed_threshold(t: f64) -> u64 {
    const TWO_POW_63: f64 = 9_223_372_036_854_775_808.0;
    ((t.min(1.0) * TWO_POW_63) as i64 as u64) << 1
}

/// The index of the largest value (the first of equals).
fn index_of_max(values: &[f64]) -> usize {
    let mut best = 0;
    for (i, &v) in values.iter().enumerate() {
        if v > values[best] {
            best = i;
        }
    }
    best
}

/// A fixed-point threshold as a fraction of the column (exact for every
/// value [`fixed_threshold`] makes: it has at most 53 significant bits).
#[inline]
fn threshold_fraction(threshold: u64) -> f64 {
    threshold as f64 / TWO_POW_64
}

/// A discrete distribution sampled in constant time by Walker's alias
/// method, with the table built by Vose's algorithm.
///
/// `u · n` picks a column and its fractional part decides between the
/// column's entry and its alias, both from one 64×64→128-bit product of the
/// variate's bits, so one `u64` of randomness makes one sample (rand_distr's
/// `WeightedAliasIndex` draws two).
///
/// Unlike the CDF samplers, the alias method does not keep the order of `u`:
/// neighbouring variates can give distant entries, and an entry's variates
/// are scattered over several columns. Use [`GuideTable`](crate::GuideTable)
/// with stratified or low-discrepancy variates; there is no `invert`.
///
/// # Performance
/// Build: two passes over the weights and one over the lists, `16 n` bytes
/// of table plus `8 n` for [`pdf`](DiscreteSampler::pdf), no scratch memory.
/// Sample: one load, one 64×64→128-bit multiply, no search, no branch.
///
/// # Precision
/// Each column's split is stored in 64-bit fixed point, and the build
/// charges every donor's stored (rounded) share to the entry that receives
/// the rest of its column, so the probability the table realises for an
/// entry (see [`realized_probabilities`](Self::realized_probabilities))
/// matches its share of the weights to about `10⁻¹⁶` absolute, like the
/// CDF samplers.
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
    /// `n` as `u64`, for the 128-bit product.
    len: u64,
}

impl AliasTable {
    /// Builds the alias table of `weights`.
    ///
    /// # Errors
    /// See [`Error`]: empty, NaN, infinite, negative or all-zero weights.
    pub fn new<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        let total = checked_total(weights)?;
        let n = weights.len();
        let n_f = n as f64;
        // By division: `1 / total` overflows for a subnormal total (see
        // `Cdf::new`).
        let probabilities: Vec<f64> = weights.iter().map(|&w| w.into() / total).collect();

        // Shares scaled to mean 1: entries below 1 are "small" and give the
        // rest of their column to a "large" one. A small entry's threshold is
        // final when it is classified; both lists are threaded through the
        // alias fields, which are free until an entry is settled. The
        // classification is a select, not a branch: small and large entries
        // alternate unpredictably.
        let (mut small_head, mut large_head) = (NIL, NIL);
        let mut columns = Vec::with_capacity(n);
        columns.extend(probabilities.iter().enumerate().map(|(i, &p)| {
            let scaled = p * n_f;
            let is_small = scaled < 1.0;
            let next = if is_small { small_head } else { large_head };
            small_head = if is_small { i as u32 } else { small_head };
            large_head = if is_small { large_head } else { i as u32 };
            Column {
                threshold: fixed_threshold(scaled),
                alias: next,
            }
        }));

        // Vose's pairing. Only the large entry at the head of its list has a
        // changing remainder, kept here in f64; it is charged exactly the
        // rounded share each donor keeps, so rounding is not lost.
        let (mut large, mut small) = (large_head, small_head);
        let mut rest = if large == NIL {
            0.0
        } else {
            probabilities[large as usize] * n_f
        };
        while small != NIL && large != NIL {
            let s = small as usize;
            small = columns[s].alias;
            columns[s].alias = large;
            // Vose's stable form: (p_l + p_s) - 1, not p_l - (1 - p_s).
            rest = (rest + threshold_fraction(columns[s].threshold)) - 1.0;
            if rest < 1.0 {
                // The large entry is now small: its remainder is its share.
                let l = large as usize;
                large = columns[l].alias;
                columns[l] = Column {
                    threshold: fixed_threshold(rest),
                    alias: small,
                };
                small = l as u32;
                if large != NIL {
                    rest = probabilities[large as usize] * n_f;
                }
            }
        }
        // What is left is full columns up to rounding: threshold 1, alias
        // itself. A zero weight can only be left over through rounding; it
        // must still never be drawn, so it hands its column to the heaviest.
        let mut heaviest = None;
        for mut i in [small, large] {
            while i != NIL {
                let at = i as usize;
                i = columns[at].alias;
                columns[at] = if probabilities[at] == 0.0 {
                    let to = *heaviest.get_or_insert_with(|| index_of_max(&probabilities));
                    Column {
                        threshold: 0,
                        alias: to as u32,
                    }
                } else {
                    Column {
                        threshold: u64::MAX,
                        alias: at as u32,
                    }
                };
            }
        }
        Ok(Self {
            columns,
            probabilities,
            len: n as u64,
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
            let t = threshold_fraction(c.threshold);
            mass[k] += t;
            mass[c.alias as usize] += 1.0 - t;
        }
        for m in &mut mass {
            *m /= self.len as f64;
        }
        mass
    }

    /// Column or alias for variate bits, chosen without a branch: the choice
    /// is a coin flip the branch predictor cannot learn.
    #[inline]
    fn select(&self, bits: u64) -> usize {
        let (k, frac) = scale_bits(bits, self.len);
        let c = self.columns[k];
        let keep = usize::from(frac < c.threshold).wrapping_neg();
        let alias = c.alias as usize;
        alias ^ ((alias ^ k) & keep)
    }
}

impl DiscreteSampler for AliasTable {
    fn from_weights<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        Self::new(weights)
    }

    fn memory_bytes(&self) -> usize {
        Self::memory_bytes(self)
    }

    fn len(&self) -> usize {
        self.columns.len()
    }

    fn pdf(&self, index: usize) -> f64 {
        self.probabilities.get(index).copied().unwrap_or(0.0)
    }

    #[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
    fn sample_remapped(&self, u: f64) -> (usize, f64) {
        let (k, frac) = scale_bits(unit_to_bits(u), self.len);
        let c = self.columns[k];
        let (f, t) = (frac as f64 / TWO_POW_64, threshold_fraction(c.threshold));
        let (index, rest) = if frac < c.threshold {
            (k, f / t)
        } else {
            (c.alias as usize, (f - t) / (1.0 - t))
        };
        // NaN (0/0 in a degenerate column) becomes 0 through max.
        (index, rest.max(0.0).min(ONE_MINUS_EPSILON))
    }

    #[inline]
    fn sample_u(&self, u: f64) -> usize {
        self.select(unit_to_bits(u))
    }

    #[inline]
    fn sample_rng<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.select(variate_bits(rng.next_u64()))
    }

    fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [usize]) {
        fill_batch(rng, out, |bits| self.select(bits));
    }
}

impl Distribution<usize> for AliasTable {
    #[inline]
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.sample_rng(rng)
    }
}
