//! Inversion of the CDF by binary search: the textbook method (pbrt's
//! `SampleDiscrete`, rand's `WeightedIndex`) and the baseline of the paper.

use rand::distr::Distribution;

use crate::cdf::Cdf;
use crate::uniform::{bits_to_unit, clamp_unit, fill_batch, unit_f64};
use crate::{DiscreteSampler, Error, InvertibleSampler};

/// A discrete distribution sampled by binary search in its `f64` CDF.
///
/// # Performance
/// Build: one pass, `8 (n + 1)` bytes. Sample: `⌈log₂ n⌉` dependent loads,
/// which miss the cache once the CDF outgrows it; prefer
/// [`GuideTable`](crate::GuideTable), which returns the same index for every
/// `u` in one or two loads.
///
/// # Example
/// ```
/// use discrete_sampling::{CdfBisection, DiscreteSampler, InvertibleSampler};
/// let d = CdfBisection::new(&[1.0, 0.0, 3.0])?;
/// assert_eq!(d.sample_u(0.1), 0);
/// assert_eq!(d.sample_u(0.3), 2); // index 1 has weight 0: never drawn
/// assert_eq!(d.pdf(2), 0.75);
/// assert_eq!(d.invert(2), Some(0.25));
/// # Ok::<(), discrete_sampling::Error>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CdfBisection {
    /// `cdf[0] = 0`, `cdf[i + 1]` = mass of `0..=i`, `cdf[n] = 1`.
    cdf: Cdf,
}

impl CdfBisection {
    /// Builds the CDF of `weights`.
    ///
    /// # Errors
    /// See [`Error`]: empty, NaN, infinite, negative or all-zero weights.
    pub fn new<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        Ok(Self {
            cdf: Cdf::new(weights)?,
        })
    }

    /// The normalised CDF, `len() + 1` values from 0 to 1.
    pub fn cdf(&self) -> &[f64] {
        &self.cdf
    }

    /// Heap memory used, in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.cdf.len() * size_of::<f64>()
    }

    /// The index for a `u` already in `[0, 1)`: the first `i` with
    /// `cdf[i + 1] > u`, which skips every zero-width interval.
    #[inline]
    fn search(&self, u: f64) -> usize {
        self.cdf[1..].partition_point(|&c| c <= u)
    }
}

impl DiscreteSampler for CdfBisection {
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
        self.search(unit_f64(rng))
    }

    fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [usize]) {
        fill_batch(rng, out, |bits| self.search(bits_to_unit(bits)));
    }
}

impl InvertibleSampler for CdfBisection {
    fn invert(&self, index: usize) -> Option<f64> {
        self.cdf.invert(index)
    }
}

impl Distribution<usize> for CdfBisection {
    #[inline]
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.sample_rng(rng)
    }
}
