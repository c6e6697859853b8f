//! SplitMix64 (Steele, Lea & Flood 2014): the small fixed-seed stream the
//! crate's tests and examples draw from, included by path.

/// A SplitMix64 stream.
pub(crate) struct Random(pub(crate) u64);

impl Random {
    /// The next number, uniform in [0, 1).
    pub(crate) fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}
