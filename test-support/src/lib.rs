//! Helpers shared by the tests of the trilux workspace, one copy each
//! instead of files included by `#[path]` across crates: where the real
//! data is ([`data`]), Pearson's chi-square test with an exact p-value
//! ([`stats`]), the Khronos glTF-Validator on written glTF files
//! ([`gltf`]), and a small seeded generator ([`SplitMix64`]).
//!
//! A path-only dev-dependency (`test-support = { workspace = true }` with
//! no version): `cargo package` strips it from a published crate's
//! manifest, so it is never published and never needed by users.

pub mod data;
pub mod gltf;
pub mod stats;

/// SplitMix64 (Steele, Lea and Flood 2014, as in Vigna's reference
/// code): deterministic, seedable, and enough to place test points. Not
/// for the samplers' own randomness, which is `rand`'s.
#[derive(Debug, Clone)]
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)` with 53 random bits.
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[0, 1)` with 24 random bits.
    pub fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in `0..n` (`n > 0`; the modulo bias is below 2⁻³² for the
    /// small `n` tests use).
    pub fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }

    /// Barycentric coordinates uniform over a triangle (all > 0 almost
    /// surely): a point of the unit square folded into the triangle.
    pub fn barycentric(&mut self) -> [f32; 3] {
        let (mut u, mut v) = (self.f32(), self.f32());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        [u, v, 1.0 - u - v]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_the_reference_sequence() {
        // The first outputs of Vigna's splitmix64.c seeded with 0.
        let mut r = SplitMix64(0);
        assert_eq!(r.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.next_u64(), 0x6E78_9E6A_A1B9_65F4);
        assert_eq!(r.next_u64(), 0x06C4_5D18_8009_454F);
    }

    #[test]
    fn unit_floats_stay_in_the_half_open_interval() {
        let mut r = SplitMix64(7);
        for _ in 0..10_000 {
            let (a, b) = (r.f64(), r.f32());
            assert!((0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
        }
    }
}
