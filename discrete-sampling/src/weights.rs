//! Validation of weights and the normalised cumulative distribution every
//! sampler starts from.

use crate::Error;

/// Largest number of entries: tables store indices as `u32`.
pub(crate) const MAX_ENTRIES: usize = u32::MAX as usize;

/// The largest `f64` below one; uniform variates are clamped to it.
pub(crate) const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// Clamps a caller's variate into `[0, 1)`; NaN becomes 0.
#[inline]
#[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
pub(crate) fn clamp_unit(u: f64) -> f64 {
    u.max(0.0).min(ONE_MINUS_EPSILON)
}

/// A uniform `f64` in `[0, 1)` from the top 53 bits of one `u64`.
///
/// Defined here rather than taken from `rand` so that a fixed seed gives the
/// same samples whatever `rand` version the caller links.
#[inline]
pub(crate) fn unit_f64<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Checks every weight and returns their sum, accumulated in `f64`.
///
/// # Errors
/// The first NaN, infinite or negative weight, an empty slice, an all-zero
/// slice, a sum that overflows, or more than [`MAX_ENTRIES`] entries.
pub(crate) fn checked_total<W: Copy + Into<f64>>(weights: &[W]) -> Result<f64, Error> {
    if weights.is_empty() {
        return Err(Error::Empty);
    }
    if weights.len() > MAX_ENTRIES {
        return Err(Error::TooManyEntries {
            len: weights.len(),
            max: MAX_ENTRIES,
        });
    }
    let mut total = 0.0f64;
    for (index, &w) in weights.iter().enumerate() {
        let w: f64 = w.into();
        // One comparison covers the common case; the slow path says why.
        if !(0.0..f64::INFINITY).contains(&w) {
            return Err(if w.is_nan() {
                Error::NaN { index }
            } else if w.is_infinite() {
                Error::Infinite { index, value: w }
            } else {
                Error::Negative { index, value: w }
            });
        }
        total += w;
    }
    if total == f64::INFINITY {
        return Err(Error::TotalOverflow);
    }
    if total == 0.0 {
        return Err(Error::AllZero { len: weights.len() });
    }
    Ok(total)
}

/// The normalised CDF with a leading zero: `cdf[0] = 0`, `cdf[i + 1]` is the
/// mass of entries `0..=i`, and `cdf[n] = 1` exactly.
///
/// Sums are accumulated and stored in `f64`: in `f32` a dim entry added to a
/// large running sum is rounded away and becomes unreachable. A zero weight
/// gives two equal neighbours, an empty interval that no variate falls into.
pub(crate) fn normalized_cdf<W: Copy + Into<f64>>(weights: &[W]) -> Result<Vec<f64>, Error> {
    let total = checked_total(weights)?;
    let mut cdf = Vec::with_capacity(weights.len() + 1);
    cdf.push(0.0);
    let mut running = 0.0f64;
    for &w in weights {
        running += w.into();
        // Division (not multiplication by 1/total) keeps the last value at
        // exactly 1: x / x == 1 in IEEE arithmetic.
        cdf.push(running / total);
    }
    debug_assert_eq!(cdf[weights.len()], 1.0);
    Ok(cdf)
}

/// Position of `u` inside the interval `[lo, hi)`, kept in `[0, 1)`.
#[inline]
pub(crate) fn remap(u: f64, lo: f64, hi: f64) -> f64 {
    ((u - lo) / (hi - lo)).min(ONE_MINUS_EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn errors_name_the_first_bad_index() {
        assert_eq!(checked_total::<f64>(&[]), Err(Error::Empty));
        assert_eq!(
            checked_total(&[1.0, f64::NAN, -1.0]),
            Err(Error::NaN { index: 1 })
        );
        assert_eq!(
            checked_total(&[1.0, 2.0, -0.5]),
            Err(Error::Negative {
                index: 2,
                value: -0.5
            })
        );
        assert_eq!(
            checked_total(&[f64::NEG_INFINITY]),
            Err(Error::Infinite {
                index: 0,
                value: f64::NEG_INFINITY
            })
        );
        assert_eq!(
            checked_total(&[0.0, -0.0, 0.0]),
            Err(Error::AllZero { len: 3 })
        );
        assert_eq!(
            checked_total(&[f64::MAX, f64::MAX]),
            Err(Error::TotalOverflow)
        );
        assert_eq!(checked_total(&[1u32, 2, 3]), Ok(6.0));
    }

    #[test]
    fn cdf_is_exactly_one_at_the_end_and_flat_over_zeros() {
        let cdf = normalized_cdf(&[0.1f32, 0.0, 0.7, 0.0, 0.0]).unwrap();
        assert_eq!(cdf.len(), 6);
        assert_eq!(cdf[0], 0.0);
        assert_eq!(cdf[1], cdf[2]);
        assert_eq!(cdf[3], 1.0);
        assert_eq!(cdf[5], 1.0);
    }

    #[test]
    fn clamp_unit_keeps_variates_below_one() {
        assert_eq!(clamp_unit(f64::NAN), 0.0);
        assert_eq!(clamp_unit(-3.0), 0.0);
        assert!(clamp_unit(1.0) < 1.0);
        assert_eq!(clamp_unit(0.25), 0.25);
    }
}
