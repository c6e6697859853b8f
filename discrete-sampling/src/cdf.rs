//! The normalised cumulative distribution that the CDF samplers share, and
//! everything that depends only on it: probabilities, inversion, remapping.

use std::ops::Deref;

use crate::Error;
use crate::uniform::remap;
use crate::weights::checked_total;

/// The normalised CDF with a leading zero: `cdf[0] = 0`, `cdf[i + 1]` is the
/// mass of entries `0..=i`, and `cdf[n] = 1` exactly.
///
/// Sums are accumulated and stored in `f64`: in `f32` a dim entry added to a
/// large running sum is rounded away and becomes unreachable. A zero weight
/// gives two equal neighbours, an empty interval that no variate falls into.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Cdf(Vec<f64>);

impl Cdf {
    /// Validates `weights` and builds their CDF.
    pub(crate) fn new<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        let total = checked_total(weights)?;
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        cdf.push(0.0);
        // Normalised by division, not by multiplying with `1 / total`: for
        // a subnormal total that reciprocal is infinite (weights
        // [5e-324, 1e-323] would give a CDF of [0, inf, NaN]), and for a
        // total above 2^1022 it is subnormal and has lost bits. A division
        // is correctly rounded for every finite positive total.
        let mut running = 0.0f64;
        for &w in weights {
            running += w.into();
            cdf.push(running / total);
        }
        // `running / total` may miss 1 by an ulp. Every value equal to
        // the last one (the trailing zero weights and whatever rounds alike)
        // becomes exactly 1; the values before it are at most the float
        // below 1, so the CDF stays monotone.
        let last = cdf[weights.len()];
        for c in cdf.iter_mut().rev() {
            if *c != last {
                break;
            }
            *c = 1.0;
        }
        Ok(Self(cdf))
    }

    /// Number of entries (one less than the number of CDF values).
    pub(crate) fn entries(&self) -> usize {
        self.0.len() - 1
    }

    /// The width of entry `index`'s interval: the probability that inversion
    /// realises (0 out of range).
    pub(crate) fn pdf(&self, index: usize) -> f64 {
        if index < self.entries() {
            self.0[index + 1] - self.0[index]
        } else {
            0.0
        }
    }

    /// The start of entry `index`'s interval, if it is not empty.
    pub(crate) fn invert(&self, index: usize) -> Option<f64> {
        (self.pdf(index) > 0.0).then(|| self.0[index])
    }

    /// `index` with the position of `u` inside its interval.
    #[inline]
    pub(crate) fn remapped(&self, index: usize, u: f64) -> (usize, f64) {
        (index, remap(u, self.0[index], self.0[index + 1]))
    }
}

impl Deref for Cdf {
    type Target = [f64];

    fn deref(&self) -> &[f64] {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_is_exactly_one_at_the_end_and_flat_over_zeros() {
        let cdf = Cdf::new(&[0.1f32, 0.0, 0.7, 0.0, 0.0]).unwrap();
        assert_eq!(cdf.len(), 6);
        assert_eq!(cdf[0], 0.0);
        assert_eq!(cdf[1], cdf[2]);
        assert_eq!(cdf[3], 1.0);
        assert_eq!(cdf[5], 1.0);
    }
}
