//! The naive sampler of the uniform-mesh-sampling article: a triangle
//! chosen uniformly, whatever its area. **Biased**: small triangles get as
//! many points as large ones. Kept as the baseline the article starts
//! from, and to show that the statistical tests can fail.

use rand::distr::Distribution;

use crate::parallel::unit;
use crate::point::{Frame, uniform_barycentric};
use crate::{Error, MeshRef, SurfacePoint, SurfaceSampler};

/// Draws a triangle uniformly among those of non-zero area, then a uniform
/// point in it. Its density is `1 / (N · A_f)` on triangle `f`, which it
/// reports correctly, so it is still usable (slower to converge) in an
/// importance-sampling estimator; it is not uniform over the surface.
#[derive(Debug, Clone)]
pub struct NaiveSampler<'a> {
    mesh: MeshRef<'a>,
    /// The triangles of non-zero area.
    faces: Vec<u32>,
    /// Their densities `1 / (N · A_f)`, computed once.
    densities: Vec<f32>,
}

impl<'a> NaiveSampler<'a> {
    /// Validates `mesh` and lists its non-degenerate triangles.
    ///
    /// # Errors
    /// As for [`UniformSampler::new`](crate::UniformSampler::new).
    pub fn new(mesh: MeshRef<'a>) -> Result<Self, Error> {
        mesh.validate()?;
        let faces: Vec<u32> = (0..mesh.indices.len())
            .filter(|&f| mesh.area(f) > 0.0)
            .map(|f| f as u32)
            .collect();
        if faces.is_empty() {
            return Err(Error::NoArea {
                triangles: mesh.indices.len(),
            });
        }
        let n = faces.len() as f64;
        let densities = faces
            .iter()
            .map(|&f| (1.0 / (n * mesh.area(f as usize))) as f32)
            .collect();
        Ok(Self {
            mesh,
            faces,
            densities,
        })
    }

    /// Density (w.r.t. area) on triangle `face`: `1 / (N · A_face)`.
    pub fn pdf(&self, face: usize) -> f32 {
        let area = self.mesh.area(face);
        if area > 0.0 {
            (1.0 / (self.faces.len() as f64 * area)) as f32
        } else {
            0.0
        }
    }
}

impl Distribution<SurfacePoint> for NaiveSampler<'_> {
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> SurfacePoint {
        let x = unit(rng.next_u64()) * self.faces.len() as f64;
        let k = (x as usize).min(self.faces.len() - 1);
        let bary = uniform_barycentric(x - k as f64, unit(rng.next_u64()));
        let face = self.faces[k];
        let frame = Frame::new(&self.mesh, face as usize);
        SurfacePoint::in_frame(&self.mesh, &frame, face, bary, self.densities[k])
    }
}

/// Two `u64` of the random stream per point.
impl SurfaceSampler for NaiveSampler<'_> {}
