//! Area-uniform sampling (the uniform-mesh-sampling article): a triangle
//! with probability proportional to its area, from the guide-table CDF of
//! `discrete-sampling`, then a uniform point in it.

use discrete_sampling::{DiscreteSampler, GuideTable};
use rand::Rng;
use rand::distr::Distribution;

use crate::parallel::{BLOCK, check_points, for_each_chunk, unit};
use crate::point::{Frame, uniform_barycentric};
use crate::prefetch::prefetch;
use crate::{Error, MeshRef, SurfacePoint, SurfaceSampler};

mod grouped;

pub use grouped::GROUP;

/// Draws points uniformly over a mesh's surface: density `1 / A` for a
/// total area `A`. Zero-area triangles are never drawn.
///
/// # Example
/// ```
/// use glam::Vec3;
/// use mesh_sampling::{MeshRef, SurfaceSampler, UniformSampler};
/// use rand::distr::Distribution;
/// use rand::SeedableRng;
///
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
/// let indices = [[0, 1, 2], [1, 3, 2]];
/// let sampler = UniformSampler::new(MeshRef::new(&positions, &indices))?;
/// let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(7);
/// let p = sampler.sample(&mut rng);
/// assert!((p.pdf - 1.0).abs() < 1e-6); // unit square
/// let cloud = sampler.sample_n(42, 10_000).unwrap(); // parallel, deterministic
/// assert_eq!(cloud.len(), 10_000);
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct UniformSampler<'a> {
    mesh: MeshRef<'a>,
    triangles: GuideTable,
    /// Per triangle, its corner, edges and normal: one memory access.
    frames: Vec<Frame>,
    total_area: f64,
    /// `1 / total_area`, the density of every reachable point.
    density: f32,
}

impl<'a> UniformSampler<'a> {
    /// Validates `mesh` and builds the area CDF (areas summed in `f64`).
    ///
    /// # Errors
    /// [`Error`] for an empty mesh, an index out of range, a non-finite
    /// position, attribute arrays of the wrong length, or no area at all.
    pub fn new(mesh: MeshRef<'a>) -> Result<Self, Error> {
        mesh.validate()?;
        let areas: Vec<f64> = (0..mesh.indices.len()).map(|f| mesh.area(f)).collect();
        let total_area: f64 = areas.iter().sum();
        let triangles = GuideTable::new(&areas).map_err(|_| Error::NoArea {
            triangles: areas.len(),
        })?;
        Ok(Self {
            mesh,
            triangles,
            frames: Frame::all(&mesh),
            total_area,
            density: (1.0 / total_area) as f32,
        })
    }

    /// The mesh sampled.
    pub fn mesh(&self) -> &MeshRef<'a> {
        &self.mesh
    }

    /// Heap memory of the sampler (its area table and triangle frames).
    pub fn memory_bytes(&self) -> usize {
        self.triangles.memory_bytes() + self.frames.len() * size_of::<Frame>()
    }

    /// The total surface area.
    pub fn total_area(&self) -> f64 {
        self.total_area
    }

    /// Density (w.r.t. area) of any point of triangle `face`: `1 / A`, or 0
    /// for a zero-area triangle (never drawn). For multiple importance
    /// sampling when a ray hits the mesh.
    pub fn pdf(&self, face: usize) -> f32 {
        if self.triangles.pdf(face) > 0.0 {
            self.density
        } else {
            0.0
        }
    }

    /// The point for uniform variates `u = [u0, u1]` in `[0, 1)²`: `u0`
    /// picks the triangle and, through its remapped remainder, the first
    /// barycentric variate; `u1` is the second. Variates outside `[0, 1)`
    /// are clamped into it and NaN counts as 0 (as in `discrete-sampling`).
    /// For stratified or low-discrepancy variates; the random-number
    /// paths use three variates instead, which is faster (no division, no
    /// unpredictable branch).
    pub fn sample_u(&self, u: [f64; 2]) -> SurfacePoint {
        let (face, rest) = self.triangles.sample_remapped(u[0]);
        self.point(face as u32, uniform_barycentric(rest, u[1]))
    }

    /// A triangle and barycentrics from three `u64` of `rng`: one for the
    /// triangle, two for the point.
    #[inline]
    pub(crate) fn pick<R: Rng + ?Sized>(&self, rng: &mut R) -> (u32, [f32; 3]) {
        let face = self.triangles.sample_rng(rng) as u32;
        let u0 = unit(rng.next_u64());
        (face, uniform_barycentric(u0, unit(rng.next_u64())))
    }

    /// Fills `faces` with triangles drawn by area (the table's batch
    /// search, one `u64` each).
    #[inline]
    pub(crate) fn faces_into<R: Rng + ?Sized>(&self, rng: &mut R, faces: &mut [usize]) {
        self.triangles.sample_into(rng, faces);
    }

    /// The point at `bary` of `face`, with the uniform density.
    #[inline]
    pub(crate) fn point(&self, face: u32, bary: [f32; 3]) -> SurfacePoint {
        let frame = &self.frames[face as usize];
        SurfacePoint::in_frame(&self.mesh, frame, face, bary, self.density)
    }
}

impl UniformSampler<'_> {
    /// Blender's "Distribute Points on Faces" behaviour: each triangle
    /// draws its own number of points, its expected count
    /// `points_per_unit_area · A_f` rounded down or up at random (up with
    /// the probability of the fraction), and their positions, all from a
    /// random stream seeded by `(seed, triangle index)`. Editing part of a
    /// mesh therefore leaves the points of the other triangles unchanged,
    /// as long as their indices stay the same. Points come in triangle
    /// order, the same on any number of threads; their total is random,
    /// with mean `points_per_unit_area · A`.
    ///
    /// # Errors
    /// [`Error::InvalidDensity`] for a negative, NaN or infinite density;
    /// [`Error::TooManyPoints`] when the count could exceed
    /// [`MAX_POINTS`](crate::MAX_POINTS) (`points_per_unit_area · A` plus
    /// one per triangle for the rounding), checked before allocating.
    pub fn sample_stable(
        &self,
        seed: u64,
        points_per_unit_area: f64,
    ) -> Result<Vec<SurfacePoint>, Error> {
        if !(points_per_unit_area >= 0.0 && points_per_unit_area.is_finite()) {
            return Err(Error::InvalidDensity(points_per_unit_area));
        }
        let faces = self.mesh.indices.len() as f64;
        check_points(points_per_unit_area * self.total_area + faces)?;
        let triangle = |face: usize| -> Vec<SurfacePoint> {
            let area = self.mesh.area(face);
            if area <= 0.0 {
                return Vec::new();
            }
            let mut rng = crate::parallel::chunk_rng(seed, face);
            let expected = points_per_unit_area * area;
            let whole = expected.floor();
            let extra = unit(rng.next_u64()) < expected - whole;
            let count = whole as usize + usize::from(extra);
            (0..count)
                .map(|_| {
                    let bary = uniform_barycentric(unit(rng.next_u64()), unit(rng.next_u64()));
                    self.point(face as u32, bary)
                })
                .collect()
        };
        Ok(crate::parallel::per_face(self.mesh.indices.len(), triangle))
    }
}

impl Distribution<SurfacePoint> for UniformSampler<'_> {
    /// Three `u64` of `rng`: the triangle, then the point.
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> SurfacePoint {
        let (face, bary) = self.pick(rng);
        self.point(face, bary)
    }
}

/// Three `u64` of the random stream per point.
impl SurfaceSampler for UniformSampler<'_> {
    /// Computed in blocks: first the block's triangles, by the guide
    /// table's batch search (one `u64` each), then its points (two `u64`
    /// each), so that the memory accesses of neighbouring samples overlap
    /// instead of waiting for each other. The points differ from those of
    /// repeated [`sample`](Distribution::sample) calls, which interleave
    /// the variates.
    fn sample_into<R: rand::Rng + ?Sized>(&self, rng: &mut R, out: &mut [SurfacePoint]) {
        self.blocks(rng, out, true, |face, bary| self.point(face, bary));
    }

    /// The positions of [`sample_n`](SurfaceSampler::sample_n)'s points,
    /// computed without the rest of each point.
    fn sample_positions(&self, seed: u64, n: usize) -> Result<Vec<[f32; 3]>, Error> {
        check_points(n as f64)?;
        let mut out = vec![[0.0f32; 3]; n];
        for_each_chunk(seed, &mut out, |rng, chunk| {
            self.blocks(rng, chunk, false, |face, [_, w1, w2]| {
                self.frames[face as usize].at(w1, w2).to_array()
            });
        });
        Ok(out)
    }
}

impl UniformSampler<'_> {
    /// Fills `out` with `make(face, barycentrics)` for blocks of draws,
    /// as a software pipeline of [`DEPTH`] blocks: each turn draws a new
    /// block's triangles (the guide table's batch search, one `u64` each)
    /// and its variates (two `u64` per point) and prefetches their frames
    /// (and corner indices, for shading normals); prefetches the corners'
    /// normals of the block before it; and computes the points of the
    /// oldest block, whose lines have arrived meanwhile. A triangle's
    /// frame is a random line of a table that outgrows the cache on a
    /// large mesh (4.4 MB on the bunny): without the pipeline each point
    /// waited for its own miss. The random numbers are drawn in the order
    /// of the plain blockwise loop (a block's triangles, then its points'
    /// variates), so the points are the same bit for bit. `shading`: the
    /// points read the mesh's shading normals (their lines are fetched).
    #[inline]
    fn blocks<R: rand::Rng + ?Sized, T>(
        &self,
        rng: &mut R,
        out: &mut [T],
        shading: bool,
        make: impl Fn(u32, [f32; 3]) -> T,
    ) {
        let blocks = out.len().div_ceil(BLOCK);
        let mut ring = [Ahead::EMPTY; DEPTH];
        // Positions alone (`shading` false) read no normals: none to fetch.
        let normals = self.mesh.normals.filter(|_| shading);
        for t in 0..blocks + DEPTH - 1 {
            if t < blocks {
                let s = &mut ring[t % DEPTH];
                s.len = (out.len() - t * BLOCK).min(BLOCK);
                self.triangles.sample_into(rng, &mut s.face[..s.len]);
                for xi in &mut s.xi[..s.len] {
                    *xi = [rng.next_u64(), rng.next_u64()];
                }
                for &f in &s.face[..s.len] {
                    prefetch(&self.frames, f);
                    if normals.is_some() {
                        prefetch(self.mesh.indices, f);
                    }
                }
            }
            if let (Some(n), Some(b)) = (normals, t.checked_sub(1).filter(|&b| b < blocks)) {
                let s = &ring[b % DEPTH];
                for &f in &s.face[..s.len] {
                    for i in self.mesh.indices[f] {
                        prefetch(n, i as usize);
                    }
                }
            }
            if let Some(b) = t.checked_sub(DEPTH - 1).filter(|&b| b < blocks) {
                let s = &ring[b % DEPTH];
                let block = &mut out[b * BLOCK..][..s.len];
                for ((slot, &face), &[x1, x2]) in block.iter_mut().zip(&s.face).zip(&s.xi) {
                    *slot = make(face as u32, uniform_barycentric(unit(x1), unit(x2)));
                }
            }
        }
    }
}

/// Blocks in flight in [`UniformSampler::blocks`]: one drawing its
/// triangles and fetching their frames, one fetching its normals, one
/// computing its points.
const DEPTH: usize = 3;

/// One block of [`UniformSampler::blocks`]' pipeline.
#[derive(Clone, Copy)]
struct Ahead {
    len: usize,
    face: [usize; BLOCK],
    /// The two `u64` of each point in its triangle.
    xi: [[u64; 2]; BLOCK],
}

impl Ahead {
    const EMPTY: Self = Self {
        len: 0,
        face: [0; BLOCK],
        xi: [[0; 2]; BLOCK],
    };
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;

    /// The pipeline gives the plain blockwise loop's points: a block's
    /// triangles, then its points' variates, block after block.
    #[test]
    fn the_pipeline_draws_the_blockwise_loops_points() {
        let n = 12u32;
        let (positions, normals, indices) = crate::mesh::test_grid(n);
        let with_normals = MeshRef {
            normals: Some(&normals),
            ..MeshRef::new(&positions, &indices)
        };
        for mesh in [MeshRef::new(&positions, &indices), with_normals] {
            let sampler = UniformSampler::new(mesh).unwrap();
            // Whole blocks, a partial last block, and fewer than one.
            for count in [3 * BLOCK, 5 * BLOCK + 17, BLOCK - 1, 1, 0] {
                let mut got = vec![SurfacePoint::default(); count];
                sampler.sample_into(&mut rand_pcg::Pcg64Mcg::seed_from_u64(5), &mut got);
                let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(5);
                let mut want = Vec::new();
                let mut faces = [0usize; BLOCK];
                for start in (0..count).step_by(BLOCK) {
                    let len = (count - start).min(BLOCK);
                    sampler.faces_into(&mut rng, &mut faces[..len]);
                    for &face in &faces[..len] {
                        let u0 = unit(rng.next_u64());
                        let bary = uniform_barycentric(u0, unit(rng.next_u64()));
                        want.push(sampler.point(face as u32, bary));
                    }
                }
                assert_eq!(got, want, "{count} points");
            }
        }
    }
}
