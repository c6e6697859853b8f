//! Shared test meshes, and the seeded generator of test-support (the
//! crate has no `rand` dependency and tests need no more than this).

#![allow(dead_code, reason = "each test binary uses a subset")]

use glam::Vec3;

/// SplitMix64, the workspace's one copy (test-support).
#[allow(unused_imports, reason = "each test binary uses a subset")]
pub(crate) use test_support::SplitMix64 as Rng;

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
