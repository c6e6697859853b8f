//! Shared test meshes and a small deterministic random generator (the
//! crate has no `rand` dependency and tests need no more than this).

#![allow(dead_code, reason = "each test binary uses a subset")]

use glam::Vec3;

/// SplitMix64: deterministic, seedable, good enough to place test points.
pub(crate) struct Rng(pub(crate) u64);

impl Rng {
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[0, 1)`.
    pub(crate) fn f32(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    pub(crate) fn below(&mut self, n: u64) -> u64 {
        self.next_u64() % n
    }
    /// Uniform barycentrics (all > 0 almost surely).
    pub(crate) fn barycentric(&mut self) -> [f32; 3] {
        let (mut u, mut v) = (self.f32(), self.f32());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        [u, v, 1.0 - u - v]
    }
}

/// An `n × n` grid of the unit square (bumped in z so faces differ), two
/// triangles per cell, counter-clockwise.
pub(crate) fn grid(n: u32, bump: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = bump * ((5.0 * s).sin() * (3.0 * t).cos() + s * t);
            positions.push(Vec3::new(s, t, z));
        }
    }
    let at = |x: u32, y: u32| y * (n + 1) + x;
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            faces.push([at(x, y), at(x + 1, y), at(x, y + 1)]);
            faces.push([at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    (positions, faces)
}

/// The point of face `f` at barycentrics `b`.
pub(crate) fn point(positions: &[Vec3], face: [u32; 3], b: [f32; 3]) -> Vec3 {
    (0..3).map(|k| b[k] * positions[face[k] as usize]).sum()
}
