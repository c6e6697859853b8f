//! Validation of weights and the normalised cumulative distribution every
//! sampler starts from.

use crate::Error;

/// Largest number of entries: tables store indices as `u32`.
pub(crate) const MAX_ENTRIES: usize = u32::MAX as usize;

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
    // Fast path without early exit: the checks fold into one flag, so the
    // loop is the sum's dependency chain and nothing else. Only a bad input
    // pays for the second pass that finds and names the first offender.
    let mut total = 0.0f64;
    let mut all_valid = true;
    for &w in weights {
        let w: f64 = w.into();
        all_valid &= (0.0..f64::INFINITY).contains(&w);
        total += w;
    }
    if !all_valid {
        return Err(first_invalid(weights));
    }
    if total == f64::INFINITY {
        return Err(Error::TotalOverflow);
    }
    if total == 0.0 {
        return Err(Error::AllZero { len: weights.len() });
    }
    Ok(total)
}

/// The error for the first NaN, infinite or negative weight (there is one).
#[cold]
fn first_invalid<W: Copy + Into<f64>>(weights: &[W]) -> Error {
    for (index, &w) in weights.iter().enumerate() {
        let w: f64 = w.into();
        if w.is_nan() {
            return Error::NaN { index };
        }
        if w.is_infinite() {
            return Error::Infinite { index, value: w };
        }
        if w < 0.0 {
            return Error::Negative { index, value: w };
        }
    }
    unreachable!("first_invalid is only called when a weight is invalid")
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
    let scale = 1.0 / total;
    let mut running = 0.0f64;
    for &w in weights {
        running += w.into();
        cdf.push(running * scale);
    }
    // `total * (1 / total)` may miss 1 by an ulp. Every value equal to the
    // last one (the trailing zero weights and whatever rounds alike) becomes
    // exactly 1; the values before it are at most the float below 1, so the
    // CDF stays monotone.
    let last = cdf[weights.len()];
    for c in cdf.iter_mut().rev() {
        if *c != last {
            break;
        }
        *c = 1.0;
    }
    Ok(cdf)
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
}
