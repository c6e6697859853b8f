//! Area-uniform sampling (the uniform-mesh-sampling article): a triangle
//! with probability proportional to its area, from the guide-table CDF of
//! `discrete-sampling`, then a uniform point in it.

use discrete_sampling::{DiscreteSampler, GuideTable};
use rand::Rng;
use rand::distr::Distribution;

use crate::parallel::{BLOCK, check_points, for_each_chunk, unit};
use crate::point::{Frame, uniform_barycentric};
use crate::{Error, MeshRef, SurfacePoint, SurfaceSampler};

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
        self.blocks(rng, out, |face, bary| self.point(face, bary));
    }

    /// The positions of [`sample_n`](SurfaceSampler::sample_n)'s points,
    /// computed without the rest of each point.
    fn sample_positions(&self, seed: u64, n: usize) -> Result<Vec<[f32; 3]>, Error> {
        check_points(n as f64)?;
        let mut out = vec![[0.0f32; 3]; n];
        for_each_chunk(seed, &mut out, |rng, chunk| {
            self.blocks(rng, chunk, |face, [_, w1, w2]| {
                self.frames[face as usize].at(w1, w2).to_array()
            });
        });
        Ok(out)
    }
}

impl UniformSampler<'_> {
    /// Fills `out` with `make(face, barycentrics)` for blocks of draws:
    /// the block's triangles first, by the guide table's batch search (one
    /// `u64` each), then the points (two `u64` each).
    #[inline]
    fn blocks<R: rand::Rng + ?Sized, T>(
        &self,
        rng: &mut R,
        out: &mut [T],
        make: impl Fn(u32, [f32; 3]) -> T,
    ) {
        let mut faces = [0usize; BLOCK];
        for block in out.chunks_mut(BLOCK) {
            let faces = &mut faces[..block.len()];
            self.triangles.sample_into(rng, faces);
            for (slot, &face) in block.iter_mut().zip(faces.iter()) {
                let u0 = unit(rng.next_u64());
                *slot = make(face as u32, uniform_barycentric(u0, unit(rng.next_u64())));
            }
        }
    }
}
