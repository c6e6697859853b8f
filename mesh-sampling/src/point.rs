//! What a sample carries, and the map from the unit square to a triangle.

use glam::{Vec2, Vec3};

use crate::{Error, MeshRef};

/// A point on the surface, with everything a renderer or scatterer needs.
///
/// It is stored as `(face, barycentrics)`, so [`SurfacePoint::on`] can
/// re-evaluate it on deformed vertex positions: an animated mesh keeps its
/// points (the hair application of Šik & Křivánek 2013).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SurfacePoint {
    /// The position.
    pub position: Vec3,
    /// The triangle it lies on.
    pub face: u32,
    /// Barycentric coordinates `[b0, b1, b2]` (summing to 1) with respect
    /// to the triangle's three vertices.
    pub barycentric: [f32; 3],
    /// The geometric normal of the triangle (unit, right-hand rule).
    pub normal: Vec3,
    /// The interpolated shading normal, when the mesh has normals.
    pub shading_normal: Option<Vec3>,
    /// The interpolated texture coordinate, when the mesh has UVs.
    pub uv: Option<Vec2>,
    /// Density with respect to surface area at this point.
    pub pdf: f32,
}

/// Barycentrics of a uniform point in a triangle from two uniform variates
/// (Šik & Křivánek 2013, Sec. 3.5: `u = 1 − √ξ₁`, `v = ξ₂ √ξ₁`). Variates
/// are clamped into `[0, 1]`, NaN counting as 0, so the point is always in
/// the closed triangle.
#[inline]
#[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
pub fn uniform_barycentric(xi1: f64, xi2: f64) -> [f32; 3] {
    let (xi1, xi2) = (xi1.max(0.0).min(1.0), xi2.max(0.0).min(1.0));
    let s = xi1.sqrt();
    let b0 = 1.0 - s;
    let b1 = xi2 * s;
    [b0 as f32, b1 as f32, (1.0 - b0 - b1).max(0.0) as f32]
}

impl SurfacePoint {
    /// The point at `barycentric` on triangle `face` of `mesh`, with the
    /// given density (barycentrics are used as given: NaN ones give a NaN
    /// position).
    ///
    /// # Errors
    /// [`Error::NoSuchFace`] if `face` is not a triangle of `mesh`, or
    /// [`Error::IndexOutOfRange`] if it names a vertex (or normal or UV)
    /// that does not exist.
    pub fn on(
        mesh: &MeshRef<'_>,
        face: u32,
        barycentric: [f32; 3],
        pdf: f32,
    ) -> Result<Self, Error> {
        let f = face as usize;
        let Some(tri) = mesh.indices.get(f) else {
            return Err(Error::NoSuchFace {
                face: f,
                count: mesh.indices.len(),
            });
        };
        let count = [
            Some(mesh.positions.len()),
            mesh.normals.map(<[Vec3]>::len),
            mesh.uvs.map(<[Vec2]>::len),
        ]
        .into_iter()
        .flatten()
        .min()
        .unwrap_or(0);
        if let Some(&vertex) = tri.iter().find(|&&i| i as usize >= count) {
            return Err(Error::IndexOutOfRange {
                triangle: f,
                vertex,
                count,
            });
        }
        Ok(Self::in_frame(
            mesh,
            &Frame::new(mesh, f),
            face,
            barycentric,
            pdf,
        ))
    }

    /// [`on`](Self::on) with the triangle's frame at hand: the samplers
    /// keep one per triangle, so that a point costs one memory access (one
    /// cache line) for its geometry and texture coordinate; the corner
    /// indices are read only for shading normals.
    #[inline]
    pub(crate) fn in_frame(
        mesh: &MeshRef<'_>,
        frame: &Frame,
        face: u32,
        barycentric: [f32; 3],
        pdf: f32,
    ) -> Self {
        let [w0, w1, w2] = barycentric;
        let lerp3 = |v: [Vec3; 3]| v[0] * w0 + v[1] * w1 + v[2] * w2;
        Self {
            position: frame.at(w1, w2),
            face,
            barycentric,
            normal: frame.normal(),
            shading_normal: mesh.normals.map(|n| {
                lerp3(mesh.indices[face as usize].map(|i| n[i as usize])).normalize_or_zero()
            }),
            uv: mesh.uvs.map(|_| frame.uv_at(w1, w2)),
            pdf,
        }
    }
}

/// A triangle as its first corner `a` and its edges `b − a` and `c − a`
/// (a point is `a + w1 (b − a) + w2 (c − a)`, exact when the corners share
/// a coordinate: a point on the plane z = 1 has z = 1 exactly, unlike
/// `w0 a + w1 b + w2 c`), and the same for its texture coordinates when
/// the mesh has them: 64 bytes, one cache line, so that a point reads one
/// line of its triangle. The unit normal (right-hand rule) is the edges'
/// cross product times a stored reciprocal length, bit for bit
/// `(b − a).cross(c − a).normalize_or_zero()`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct Frame {
    origin: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// `1 / |e1 × e2|`, or 0 where that is not finite and positive (the
    /// normal is then zero).
    normal_scale: f32,
    uv_origin: Vec2,
    uv_e1: Vec2,
    uv_e2: Vec2,
}

impl Frame {
    /// A word of the record (64 bytes, one cache line): reading it brings
    /// the whole frame into the cache.
    #[inline]
    pub(crate) fn touch(&self) -> u32 {
        self.origin.x.to_bits()
    }

    /// The frame of a triangle of a validated mesh (all zero otherwise).
    pub(crate) fn new(mesh: &MeshRef<'_>, face: usize) -> Self {
        let [a, b, c] = mesh.corners(face).unwrap_or_default();
        let [ta, tb, tc] = match (mesh.uvs, mesh.indices.get(face)) {
            (Some(t), Some(tri)) if tri.iter().all(|&i| (i as usize) < t.len()) => {
                tri.map(|i| t[i as usize])
            }
            _ => [Vec2::ZERO; 3],
        };
        let (e1, e2) = (b - a, c - a);
        let rcp = e1.cross(e2).length_recip();
        Self {
            origin: a,
            e1,
            e2,
            normal_scale: if rcp.is_finite() && rcp > 0.0 {
                rcp
            } else {
                0.0
            },
            uv_origin: ta,
            uv_e1: tb - ta,
            uv_e2: tc - ta,
        }
    }

    /// The point with barycentric weights `w1`, `w2` on the second and
    /// third corner.
    #[inline]
    pub(crate) fn at(&self, w1: f32, w2: f32) -> Vec3 {
        self.origin + self.e1 * w1 + self.e2 * w2
    }

    /// The texture coordinate there (zero for a mesh without UVs).
    #[inline]
    pub(crate) fn uv_at(&self, w1: f32, w2: f32) -> Vec2 {
        self.uv_origin + self.uv_e1 * w1 + self.uv_e2 * w2
    }

    /// The unit normal (right-hand rule; zero for a degenerate triangle).
    #[inline]
    pub(crate) fn normal(&self) -> Vec3 {
        if self.normal_scale > 0.0 {
            self.e1.cross(self.e2) * self.normal_scale
        } else {
            Vec3::ZERO
        }
    }

    /// The frames of every triangle of `mesh`.
    pub(crate) fn all(mesh: &MeshRef<'_>) -> Vec<Self> {
        (0..mesh.indices.len())
            .map(|f| Self::new(mesh, f))
            .collect()
    }
}
