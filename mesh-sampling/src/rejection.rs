//! Rejection sampling with a density texture, the baseline of Šik &
//! Křivánek 2013 (Sec. 3.2): a uniform point, accepted with probability
//! `f(m(x)) / M` for the texture's maximum `M`. Exact for the filtered
//! density, but it accepts only `mean / M` of its proposals.

use glam::Vec2;
use rand::Rng;
use rand::distr::Distribution;

use crate::parallel::{BLOCK, unit};
use crate::point::uniform_barycentric;
use crate::{DensityTexture, Error, MeshRef, SurfacePoint, SurfaceSampler, UniformSampler};

/// Draws points with density proportional to a texture by rejection from
/// the uniform distribution. Prefer [`DensitySampler`](crate::DensitySampler);
/// this is the baseline it is measured against.
#[derive(Debug, Clone)]
pub struct RejectionSampler<'a> {
    uniform: UniformSampler<'a>,
    uvs: &'a [Vec2],
    texture: &'a DensityTexture,
    /// `M`: the largest texel.
    bound: f64,
    /// `1 / ∫ f dA`, for the points' pdf.
    norm: f64,
    acceptance: f64,
}

impl<'a> RejectionSampler<'a> {
    /// Builds the area table and integrates the texture over the mesh
    /// exactly (for the points' pdf).
    ///
    /// # Errors
    /// As for [`UniformSampler::new`]; [`Error::MissingUvs`],
    /// [`Error::NonFiniteUv`]; [`Error::IntegrationTooLarge`] for UVs that
    /// tile a varying texture too many times to integrate it exactly;
    /// [`Error::ZeroDensity`] when the texture is zero on the whole mesh;
    /// [`Error::AcceptanceTooLow`] below [`MIN_ACCEPTANCE`](crate::MIN_ACCEPTANCE).
    pub fn new(mesh: MeshRef<'a>, texture: &'a DensityTexture) -> Result<Self, Error> {
        let uniform = UniformSampler::new(mesh)?;
        let uvs = crate::density::texture_uvs(&mesh)?;
        crate::density::check_integration(&mesh, uvs, texture)?;
        let faces = mesh.indices.len();
        let mass: f64 = crate::density::map_faces(faces >= 1 << 15, faces, |f| {
            crate::density::exact_mass(&mesh, uvs, texture, f)
        })
        .iter()
        .sum();
        if mass.is_nan() || mass <= 0.0 {
            return Err(Error::ZeroDensity { triangles: faces });
        }
        let bound = f64::from(texture.max());
        let acceptance = mass / (uniform.total_area() * bound);
        crate::density::check_acceptance(acceptance)?;
        Ok(Self {
            acceptance,
            uniform,
            uvs,
            texture,
            bound,
            norm: 1.0 / mass,
        })
    }

    /// The expected fraction of proposals accepted: `∫ f dA / (A · M)`.
    pub fn acceptance(&self) -> f64 {
        self.acceptance
    }

    /// The integral of the texture over the mesh.
    pub fn total_mass(&self) -> f64 {
        1.0 / self.norm
    }

    /// The density (w.r.t. area) at barycentrics of `face`: 0 for a
    /// triangle that does not exist, a zero-area triangle, or barycentrics
    /// that are NaN or infinite.
    pub fn pdf(&self, face: usize, barycentric: [f32; 3]) -> f32 {
        if self.uniform.pdf(face) == 0.0 || !barycentric.iter().all(|b| b.is_finite()) {
            return 0.0;
        }
        let tri = self.uniform.mesh().indices[face];
        let [a, b, c] = tri.map(|i| self.uvs[i as usize].as_dvec2());
        let [_, u, v] = barycentric.map(f64::from);
        (self.texture.eval(a + (b - a) * u + (c - a) * v) * self.norm) as f32
    }

    /// The unnormalised density at `bary` of `face`.
    #[inline]
    fn density_at(&self, face: u32, bary: [f32; 3]) -> f64 {
        let tri = self.uniform.mesh().indices[face as usize];
        let [a, b, c] = tri.map(|i| self.uvs[i as usize].as_dvec2());
        let [_, u, v] = bary.map(f64::from);
        self.texture.eval(a + (b - a) * u + (c - a) * v)
    }

    /// Heap memory of the sampler (its area table and triangle frames).
    pub fn memory_bytes(&self) -> usize {
        self.uniform.memory_bytes()
    }
}

/// Four `u64` of the random stream per proposal.
impl SurfaceSampler for RejectionSampler<'_> {
    /// Proposals in blocks (the triangles by the table's batch search,
    /// then the points and their tests), the accepted ones kept in order:
    /// the same speed-ups as the other samplers' batches, so that the
    /// comparison is fair.
    fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [SurfacePoint]) {
        let mut faces = [0usize; BLOCK];
        let mut filled = 0;
        while filled < out.len() {
            self.uniform.faces_into(rng, &mut faces);
            for &face in &faces {
                let face = face as u32;
                let u0 = unit(rng.next_u64());
                let bary = uniform_barycentric(u0, unit(rng.next_u64()));
                let f = self.density_at(face, bary);
                if unit(rng.next_u64()) * self.bound < f && filled < out.len() {
                    let mut point = self.uniform.point(face, bary);
                    point.pdf = (f * self.norm) as f32;
                    out[filled] = point;
                    filled += 1;
                }
            }
        }
    }
}

impl Distribution<SurfacePoint> for RejectionSampler<'_> {
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> SurfacePoint {
        loop {
            let (face, bary) = self.uniform.pick(rng);
            let f = self.density_at(face, bary);
            if unit(rng.next_u64()) * self.bound < f {
                let mut point = self.uniform.point(face, bary);
                point.pdf = (f * self.norm) as f32;
                return point;
            }
        }
    }
}
