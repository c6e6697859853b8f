//! The mesh a sampler reads: borrowed plain data, validated once.

use glam::{Vec2, Vec3};

use crate::Error;

/// A triangle mesh as slices, the way `trilux-io` and most renderers hold
/// it: positions, three vertex indices per triangle, and optional
/// per-vertex shading normals and texture coordinates.
#[derive(Debug, Clone, Copy)]
pub struct MeshRef<'a> {
    /// Vertex positions.
    pub positions: &'a [Vec3],
    /// Triangles as vertex indices (counter-clockwise when seen from the
    /// side the geometric normal points to).
    pub indices: &'a [[u32; 3]],
    /// Per-vertex shading normals.
    pub normals: Option<&'a [Vec3]>,
    /// Per-vertex texture coordinates.
    pub uvs: Option<&'a [Vec2]>,
}

impl<'a> MeshRef<'a> {
    /// A mesh of positions and triangles only.
    pub fn new(positions: &'a [Vec3], indices: &'a [[u32; 3]]) -> Self {
        Self {
            positions,
            indices,
            normals: None,
            uvs: None,
        }
    }

    /// Checks what a sampler relies on: at least one triangle, indices in
    /// range, finite positions of the referenced vertices, attribute
    /// arrays as long as the positions.
    ///
    /// # Errors
    /// The first problem found, with the triangle or vertex it concerns.
    pub fn validate(&self) -> Result<(), Error> {
        if self.indices.is_empty() {
            return Err(Error::Empty);
        }
        if self.indices.len() > u32::MAX as usize {
            return Err(Error::TooLarge(self.indices.len()));
        }
        let count = self.positions.len();
        for (attribute, len) in [
            ("normals", self.normals.map(<[Vec3]>::len)),
            ("uvs", self.uvs.map(<[Vec2]>::len)),
        ] {
            if let Some(len) = len.filter(|&l| l != count) {
                return Err(Error::AttributeLength {
                    attribute,
                    len,
                    count,
                });
            }
        }
        for (triangle, tri) in self.indices.iter().enumerate() {
            for &vertex in tri {
                let Some(p) = self.positions.get(vertex as usize) else {
                    return Err(Error::IndexOutOfRange {
                        triangle,
                        vertex,
                        count,
                    });
                };
                if !p.is_finite() {
                    return Err(Error::NonFinitePosition {
                        vertex: vertex as usize,
                    });
                }
            }
        }
        Ok(())
    }

    /// The corners of triangle `face`; `None` if there is no such
    /// triangle or it names a vertex that does not exist.
    #[inline]
    pub fn corners(&self, face: usize) -> Option<[Vec3; 3]> {
        let [a, b, c] = *self.indices.get(face)?;
        let p = |i: u32| self.positions.get(i as usize).copied();
        Some([p(a)?, p(b)?, p(c)?])
    }

    /// The area of triangle `face`, computed in `f64`; 0 where
    /// [`corners`](Self::corners) is `None`.
    pub fn area(&self, face: usize) -> f64 {
        self.corners(face).map_or(0.0, |corners| {
            let [a, b, c] = corners.map(Vec3::as_dvec3);
            0.5 * (b - a).cross(c - a).length()
        })
    }
}

/// A test mesh: an `n × n` grid of vertices with uneven heights, two
/// triangles per cell, and per-vertex shading normals that vary.
#[cfg(test)]
pub(crate) fn test_grid(n: u32) -> (Vec<glam::Vec3>, Vec<glam::Vec3>, Vec<[u32; 3]>) {
    use glam::Vec3;
    let positions = (0..n * n)
        .map(|k| Vec3::new((k % n) as f32, (k / n) as f32, ((k * 7) % 5) as f32 * 0.3))
        .collect();
    let normals = (0..n * n)
        .map(|k| Vec3::new(0.1 * (k % 3) as f32, 0.2, 1.0).normalize())
        .collect();
    let mut indices = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            indices.push([a, a + 1, a + n]);
            indices.push([a + 1, a + n + 1, a + n]);
        }
    }
    (positions, normals, indices)
}
