//! The unit tests' mesh: a wavy `n × n` grid of the unit square, two
//! triangles per cell (the integration tests have their own in
//! `tests/support`).

use glam::Vec3;

/// Vertex positions and faces of the grid.
pub(crate) fn wavy_grid(n: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
            positions.push(Vec3::new(u, v, 0.1 * (7.0 * u).sin() * (5.0 * v).cos()));
        }
    }
    let at = |x: u32, y: u32| y * (n + 1) + x;
    let mut faces = Vec::new();
    for y in 0..n {
        for x in 0..n {
            faces.push([at(x, y), at(x + 1, y), at(x + 1, y + 1)]);
            faces.push([at(x, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    (positions, faces)
}
