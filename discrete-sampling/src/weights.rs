//! Validation of weights: the first pass of every constructor.

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
}
