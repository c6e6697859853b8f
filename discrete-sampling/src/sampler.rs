//! The interface shared by the 1D samplers.

use crate::Error;
use crate::uniform::{bits_to_unit, fill_batch, unit_f64};

/// A discrete distribution over `0..len()` that can be sampled by inversion
/// of a uniform variate.
///
/// Implemented by [`CdfBisection`](crate::CdfBisection),
/// [`GuideTable`](crate::GuideTable) and [`AliasTable`](crate::AliasTable), so
/// code such as [`Distribution2D`](crate::Distribution2D) can be written once
/// for all three. You never need to implement it to use the crate.
pub trait DiscreteSampler: Sized {
    /// Builds the distribution from non-negative weights (any type that
    /// converts to `f64` losslessly: `f32`, `f64`, `u32`, `i32`, …).
    ///
    /// # Errors
    /// [`Error`] naming the first NaN, infinite or negative weight, or an
    /// empty or all-zero slice.
    fn from_weights<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error>;

    /// Number of entries, including those of weight zero.
    fn len(&self) -> usize;

    /// Always `false`: a distribution has at least one entry.
    fn is_empty(&self) -> bool {
        false
    }

    /// Probability of drawing `index` (0 for a zero weight or an index out of
    /// range). This is the probability the sampler realises, so it is what a
    /// renderer should use for multiple importance sampling.
    fn pdf(&self, index: usize) -> f64;

    /// Heap memory used, in bytes.
    fn memory_bytes(&self) -> usize;

    /// Draws the entry for a uniform variate `u` in `[0, 1)` and returns it
    /// with the remapped remainder of `u`: a fresh uniform variate in
    /// `[0, 1)` that the caller may reuse (as pbrt does). Values of `u`
    /// outside `[0, 1)` are clamped; NaN counts as 0.
    fn sample_remapped(&self, u: f64) -> (usize, f64);

    /// Draws the entry for a uniform variate `u` (see
    /// [`sample_remapped`](Self::sample_remapped)).
    fn sample_u(&self, u: f64) -> usize {
        self.sample_remapped(u).0
    }

    /// Draws one entry using one `u64` of `rng`.
    fn sample_rng<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> usize {
        self.sample_u(unit_f64(rng))
    }

    /// Fills `out` with independent draws, one `u64` of `rng` each, the
    /// same draws as calling [`sample_rng`](Self::sample_rng) in a loop but
    /// faster: the random numbers are generated ahead in small blocks and
    /// the searches overlap.
    fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [usize]) {
        fill_batch(rng, out, |bits| self.sample_u(bits_to_unit(bits)));
    }
}

/// A sampler that keeps the order of the inversion method: a larger `u`
/// never gives a smaller index, so stratified and low-discrepancy variates
/// stay stratified, and each entry owns one interval of `[0, 1)`.
pub trait InvertibleSampler: DiscreteSampler {
    /// The smallest `u` that draws `index` (the start of its CDF interval),
    /// or `None` when no `u` does: an index out of range or of probability 0.
    ///
    /// `sample_u(invert(i)?) == i` for every reachable `i`.
    fn invert(&self, index: usize) -> Option<f64>;
}
