//! What every single-mesh sampler offers beyond one point at a time:
//! deterministic parallel batches.

use rand::Rng;
use rand::distr::Distribution;

use crate::parallel::{check_points, for_each_chunk, for_each_chunk_via, stream};
use crate::{Error, SurfacePoint};

/// A sampler of points on a mesh, with batch APIs whose output depends
/// only on the seed, never on the number of threads: points come in
/// chunks of 16,384, each from its own random stream seeded by
/// `(seed, chunk index)`, and the chunks run on all threads with the
/// `rayon` feature.
pub trait SurfaceSampler: Distribution<SurfacePoint> + Sync {
    /// Fills `out` with independent points drawn from `rng`.
    fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [SurfacePoint]) {
        for slot in out {
            *slot = self.sample(rng);
        }
    }

    /// `n` points from `seed`.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] if `n` exceeds [`MAX_POINTS`](crate::MAX_POINTS)
    /// (checked before allocating; stream them instead).
    fn sample_n(&self, seed: u64, n: usize) -> Result<Vec<SurfacePoint>, Error> {
        check_points(n as f64)?;
        let mut out = vec![SurfacePoint::default(); n];
        for_each_chunk(seed, &mut out, |rng, chunk| self.sample_into(rng, chunk));
        Ok(out)
    }

    /// The positions of the points of [`sample_n`](Self::sample_n), as
    /// plain `[x, y, z]`: a point cloud in a sixth of the memory (the
    /// output of trimesh's `sample_surface` or Open3D's
    /// `sample_points_uniformly`), which for 10⁷ points is also faster to
    /// allocate and write.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] if `n` exceeds [`MAX_POINTS`](crate::MAX_POINTS).
    fn sample_positions(&self, seed: u64, n: usize) -> Result<Vec<[f32; 3]>, Error> {
        check_points(n as f64)?;
        // Zeroed arrays come from the allocator as zero pages, written once.
        let mut out = vec![[0.0f32; 3]; n];
        for_each_chunk_via(
            seed,
            &mut out,
            |rng, chunk| self.sample_into(rng, chunk),
            |p: &SurfacePoint| p.position.to_array(),
        );
        Ok(out)
    }

    /// The points of [`sample_n`](Self::sample_n), handed chunk by chunk
    /// to `consume(index of the chunk's first point, chunk)` (from several
    /// threads at once, in no particular order) instead of being stored:
    /// for streaming millions of points into a renderer or a file.
    fn sample_stream(&self, seed: u64, n: usize, consume: impl Fn(usize, &[SurfacePoint]) + Sync) {
        stream(seed, n, |rng, chunk| self.sample_into(rng, chunk), consume);
    }
}
