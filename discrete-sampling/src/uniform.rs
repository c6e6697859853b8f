//! Uniform variates: how one `u64` becomes a `u` in `[0, 1)`, how callers'
//! variates are clamped, and the batch loop every sampler shares.

/// The largest `f64` below one; uniform variates are clamped to it.
pub(crate) const ONE_MINUS_EPSILON: f64 = 1.0 - f64::EPSILON / 2.0;

/// Clamps a caller's variate into `[0, 1)`; NaN becomes 0.
#[inline]
#[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
pub(crate) fn clamp_unit(u: f64) -> f64 {
    u.max(0.0).min(ONE_MINUS_EPSILON)
}

/// `2⁻⁶⁴`.
const TWO_POW_MINUS_64: f64 = 1.0 / 18_446_744_073_709_551_616.0;

/// The 53 random bits of a variate, kept at the top of a `u64`: the variate
/// is `u = bits · 2⁻⁶⁴` exactly, the same value as `(x >> 11) · 2⁻⁵³`.
///
/// Samplers work on these bits with integer arithmetic (a 64×64→128-bit
/// multiply instead of float-to-integer conversions, which are slow on
/// common CPUs) and convert to `f64` only when they need to compare with the
/// CDF. Defined here rather than taken from `rand` so that a fixed seed gives
/// the same samples whatever `rand` version the caller links.
#[inline]
pub(crate) fn variate_bits(x: u64) -> u64 {
    x & !0x7FF
}

/// The `f64` value of variate bits (exact: at most 53 significant bits).
#[inline]
pub(crate) fn bits_to_unit(bits: u64) -> f64 {
    // Not through i64: measured, that form makes the 2D sampler twice as
    // slow (probably the signed conversion's partial register write waiting
    // on a preceding division) and gains nothing in 1D.
    bits as f64 * TWO_POW_MINUS_64
}

/// The bits of a value `x ∈ [0, 1]`: `⌊x · 2⁶³⌋ · 2` (1 saturates to
/// `2⁶⁴ − 2`). Monotone in `x`, and for every `u` made by [`bits_to_unit`]
/// it gives that variate's bits back.
///
/// Through `i64`: one signed conversion, where `as u64` needs a branch on
/// `2⁶³`.
#[inline]
pub(crate) fn value_bits(x: f64) -> u64 {
    ((x * 9_223_372_036_854_775_808.0) as i64 as u64) << 1
}

/// The bits of a caller's variate, clamped to `[0, 1)` first.
#[inline]
pub(crate) fn unit_to_bits(u: f64) -> u64 {
    value_bits(clamp_unit(u))
}

/// `⌊bits · n / 2⁶⁴⌋`: the slot of a variate among `n` equal slots, and the
/// position inside that slot in units of `2⁻⁶⁴`.
#[inline]
pub(crate) fn scale_bits(bits: u64, n: u64) -> (usize, u64) {
    let x = u128::from(bits) * u128::from(n);
    ((x >> 64) as usize, x as u64)
}

/// One uniform `f64` in `[0, 1)` from one `u64` of `rng`.
#[inline]
pub(crate) fn unit_f64<R: rand::Rng + ?Sized>(rng: &mut R) -> f64 {
    bits_to_unit(variate_bits(rng.next_u64()))
}

/// Variates drawn ahead per batch step: large enough to amortise the loop,
/// small enough to stay in L1.
const BATCH: usize = 256;

/// Fills `out` with `draw(bits)` for successive variates of `rng` (see
/// [`variate_bits`]), in the same order as one-at-a-time sampling.
///
/// The random numbers are generated in a loop of their own, which the
/// compiler can unroll across the generator's dependency chain, and the
/// searches then run with no dependency between samples, so the core
/// overlaps their cache misses. This is why batches are faster per sample.
#[inline]
pub(crate) fn fill_batch<R, T>(rng: &mut R, out: &mut [T], draw: impl Fn(u64) -> T)
where
    R: rand::Rng + ?Sized,
{
    let mut bits = [0u64; BATCH];
    for chunk in out.chunks_mut(BATCH) {
        let bits = &mut bits[..chunk.len()];
        for b in bits.iter_mut() {
            *b = rng.next_u64();
        }
        for (slot, &b) in chunk.iter_mut().zip(bits.iter()) {
            *slot = draw(variate_bits(b));
        }
    }
}

/// Fills `out` with `draw(bits_0, bits_1)` for successive pairs of variates
/// of `rng`, in the same order as one-at-a-time sampling (see
/// [`fill_batch`]).
#[inline]
pub(crate) fn fill_batch_pairs<R, T>(rng: &mut R, out: &mut [T], draw: impl Fn(u64, u64) -> T)
where
    R: rand::Rng + ?Sized,
{
    let mut bits = [0u64; 2 * BATCH];
    for chunk in out.chunks_mut(BATCH) {
        let bits = &mut bits[..2 * chunk.len()];
        for b in bits.iter_mut() {
            *b = rng.next_u64();
        }
        for (slot, pair) in chunk.iter_mut().zip(bits.chunks_exact(2)) {
            *slot = draw(variate_bits(pair[0]), variate_bits(pair[1]));
        }
    }
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
    fn clamp_unit_keeps_variates_below_one() {
        assert_eq!(clamp_unit(f64::NAN), 0.0);
        assert_eq!(clamp_unit(-3.0), 0.0);
        assert!(clamp_unit(1.0) < 1.0);
        assert_eq!(clamp_unit(0.25), 0.25);
        assert_eq!(bits_to_unit(variate_bits(u64::MAX)), ONE_MINUS_EPSILON);
        assert_eq!(bits_to_unit(variate_bits(0x7FF)), 0.0);
        for x in [0u64, 0x800, 0x1234_5678_9ABC_D800, u64::MAX] {
            let b = variate_bits(x);
            assert_eq!(bits_to_unit(b), (x >> 11) as f64 / (1u64 << 53) as f64);
            assert_eq!(unit_to_bits(bits_to_unit(b)), b);
        }
        assert_eq!(unit_to_bits(2.0), variate_bits(u64::MAX));
        assert_eq!(scale_bits(1 << 63, 10), (5, 0));
    }
}
