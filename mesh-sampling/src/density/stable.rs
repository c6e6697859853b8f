//! Blender's per-triangle ("stable") mode with a density.

use discrete_sampling::DiscreteSampler;
use rand::Rng;

use super::DensitySampler;
use super::weights::piece_fraction;
use crate::parallel::unit;
use crate::{Error, SurfacePoint};

impl<S: DiscreteSampler + Sync> DensitySampler<'_, S> {
    /// Blender's per-triangle mode with a density: each triangle draws its
    /// own number of points, `points_per_unit_mass` times its mass
    /// `∫ p dA` rounded down or up at random, and their positions, all
    /// from a random stream seeded by `(seed, triangle index)`, so editing
    /// part of a mesh (or of its weights) leaves the points of the other
    /// triangles unchanged. In exact mode the triangle's proposals are
    /// counted that way and thinned by the rejection step, which keeps the
    /// expected count `points_per_unit_mass · ∫ p dA` exactly. Points come
    /// in triangle order, the same on any number of threads; their
    /// density field is the sampler's `pdf` times `points_per_unit_mass ·
    /// total_mass()`.
    ///
    /// # Errors
    /// [`Error::InvalidDensity`] for a negative, NaN or infinite rate;
    /// [`Error::TooManyPoints`] when the count could exceed
    /// [`MAX_POINTS`](crate::MAX_POINTS) (the rate times the proposal mass,
    /// plus one per triangle), checked before allocating.
    pub fn sample_stable(
        &self,
        seed: u64,
        points_per_unit_mass: f64,
    ) -> Result<Vec<SurfacePoint>, Error> {
        if !(points_per_unit_mass >= 0.0 && points_per_unit_mass.is_finite()) {
            return Err(Error::InvalidDensity(points_per_unit_mass));
        }
        let faces = self.mesh.indices.len() as f64;
        let proposal_mass = self.total_mass() / self.acceptance;
        crate::parallel::check_points(points_per_unit_mass * proposal_mass + faces)?;
        let texture = self.exact_texture();
        let triangle = |face: usize| -> Vec<SurfacePoint> {
            let Some(range) = self.face_range(face) else {
                return Vec::new();
            };
            let area = self.mesh.area(face);
            // The face's proposal masses, accumulated for the choice.
            let mut cumulative = Vec::with_capacity(range.len());
            let mut sum = 0.0;
            for p in range.clone().map(|k| self.table.get(k)) {
                sum += f64::from(p.value) * area * piece_fraction(p.part);
                cumulative.push(sum);
            }
            if sum.is_nan() || sum <= 0.0 {
                return Vec::new();
            }
            let mut rng = crate::parallel::chunk_rng(seed, face);
            let expected = points_per_unit_mass * sum;
            let whole = expected.floor();
            let extra = unit(rng.next_u64()) < expected - whole;
            let count = whole as usize + usize::from(extra);
            let mut points = Vec::with_capacity(count);
            for _ in 0..count {
                let target = unit(rng.next_u64()) * sum;
                let k = cumulative
                    .partition_point(|&c| c <= target)
                    .min(cumulative.len() - 1);
                let piece = self.table.get(range.start + k);
                let xi1 = unit(rng.next_u64());
                let bary = self.place(piece, xi1, unit(rng.next_u64()));
                match texture {
                    None => points.push(self.point(piece, bary, self.value(piece, bary))),
                    Some(texture) => {
                        let [_, u, v] = bary.map(f64::from);
                        let f = texture.eval(self.uv_at(face, u, v));
                        if unit(rng.next_u64()) * f64::from(piece.value) < f {
                            points.push(self.point(piece, bary, f));
                        }
                    }
                }
            }
            points
        };
        Ok(crate::parallel::per_face(self.mesh.indices.len(), triangle))
    }
}
