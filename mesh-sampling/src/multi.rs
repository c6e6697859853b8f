//! Several meshes at once (the uniform-mesh-sampling article, last
//! section): a small CDF over the meshes by total area (or total density
//! mass) above one sampler per mesh. Replacing or editing one mesh
//! rebuilds only its own table and the top-level one, not a CDF over every
//! triangle of the scene.

use discrete_sampling::{DiscreteSampler, GuideTable};
use rand::distr::Distribution;

use crate::parallel::{for_each_chunk, unit};
use crate::{DensitySampler, Error, MeshRef, SurfacePoint, UniformSampler};

/// A point and the mesh it lies on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeshPoint {
    /// Index of the mesh in the sampler.
    pub mesh: usize,
    /// The point; its `pdf` is with respect to the area of all meshes.
    pub point: SurfacePoint,
}

/// Draws points uniformly over the union of several meshes: density
/// `1 / ΣA` for the meshes' total area.
#[derive(Debug, Clone)]
pub struct MultiMeshSampler<'a> {
    meshes: Vec<UniformSampler<'a>>,
    top: GuideTable,
    density: f32,
}

impl<'a> MultiMeshSampler<'a> {
    /// Builds one sampler per mesh and the table over their areas.
    ///
    /// # Errors
    /// [`Error::Empty`] for no meshes; [`Error::InMesh`] naming the first
    /// invalid mesh.
    pub fn new(meshes: impl IntoIterator<Item = MeshRef<'a>>) -> Result<Self, Error> {
        let meshes = meshes
            .into_iter()
            .enumerate()
            .map(|(index, mesh)| {
                UniformSampler::new(mesh).map_err(|e| Error::InMesh {
                    index,
                    error: Box::new(e),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let (top, density) = Self::top(&meshes)?;
        Ok(Self {
            meshes,
            top,
            density,
        })
    }

    fn top(meshes: &[UniformSampler<'a>]) -> Result<(GuideTable, f32), Error> {
        if meshes.is_empty() {
            return Err(Error::Empty);
        }
        let areas: Vec<f64> = meshes.iter().map(UniformSampler::total_area).collect();
        let total: f64 = areas.iter().sum();
        let top = GuideTable::new(&areas).map_err(|_| Error::NoArea {
            triangles: meshes.iter().map(|m| m.mesh().indices.len()).sum(),
        })?;
        Ok((top, (1.0 / total) as f32))
    }

    /// Replaces mesh `index` (after an edit, or with another mesh),
    /// rebuilding only its table and the top-level one.
    ///
    /// # Errors
    /// [`Error::NoSuchMesh`], or [`Error::InMesh`] if the new mesh is
    /// invalid; the sampler is unchanged then.
    pub fn replace(&mut self, index: usize, mesh: MeshRef<'a>) -> Result<(), Error> {
        let count = self.meshes.len();
        if index >= count {
            return Err(Error::NoSuchMesh { index, count });
        }
        let sampler = UniformSampler::new(mesh).map_err(|e| Error::InMesh {
            index,
            error: Box::new(e),
        })?;
        let old = std::mem::replace(&mut self.meshes[index], sampler);
        match Self::top(&self.meshes) {
            Ok((top, density)) => {
                self.top = top;
                self.density = density;
                Ok(())
            }
            Err(e) => {
                self.meshes[index] = old;
                Err(e)
            }
        }
    }

    /// Number of meshes.
    pub fn len(&self) -> usize {
        self.meshes.len()
    }

    /// Always `false`: a sampler has at least one mesh.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The total area of all meshes.
    pub fn total_area(&self) -> f64 {
        self.meshes.iter().map(UniformSampler::total_area).sum()
    }

    /// Density (w.r.t. area of all meshes) on triangle `face` of mesh
    /// `mesh`: `1 / ΣA`, or 0 for a zero-area triangle or no such mesh.
    pub fn pdf(&self, mesh: usize, face: usize) -> f32 {
        match self.meshes.get(mesh) {
            Some(m) if m.pdf(face) > 0.0 => self.density,
            _ => 0.0,
        }
    }

    /// The point for uniform variates `u = [u0, u1]`: `u0` picks the mesh
    /// and, through its remapped remainder, the triangle and the first
    /// barycentric variate. Variates outside `[0, 1)` are clamped into it,
    /// NaN counting as 0.
    pub fn sample_u(&self, u: [f64; 2]) -> MeshPoint {
        let (mesh, rest) = self.top.sample_remapped(u[0]);
        let mut point = self.meshes[mesh].sample_u([rest, u[1]]);
        point.pdf = self.density;
        MeshPoint { mesh, point }
    }

    /// `n` points from `seed`, the same on any number of threads.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] if `n` exceeds [`MAX_POINTS`](crate::MAX_POINTS).
    pub fn sample_n(&self, seed: u64, n: usize) -> Result<Vec<MeshPoint>, Error> {
        sample_points(self, seed, n)
    }
}

impl Distribution<MeshPoint> for MultiMeshSampler<'_> {
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> MeshPoint {
        let u0 = unit(rng.next_u64());
        let u1 = unit(rng.next_u64());
        self.sample_u([u0, u1])
    }
}

/// Draws points over several meshes, each with its own density (a
/// texture, per-face or per-vertex weights, approximate or exact): mesh
/// `i` with probability `M_i / ΣM` for the total masses `M_i` of its
/// [`DensitySampler`] (its `∫ f dA`), then a point from that sampler. The
/// densities should share a scale (the same texture units), as they do
/// for one emitter split over several meshes.
#[derive(Debug, Clone)]
pub struct MultiDensitySampler<'a> {
    meshes: Vec<DensitySampler<'a>>,
    top: GuideTable,
    /// Per mesh, `M_i / ΣM`: a point's density over the union is its
    /// density on its own mesh times this.
    shares: Vec<f64>,
}

impl<'a> MultiDensitySampler<'a> {
    /// The table over the samplers' masses.
    ///
    /// # Errors
    /// [`Error::Empty`] for no sampler.
    pub fn new(meshes: impl IntoIterator<Item = DensitySampler<'a>>) -> Result<Self, Error> {
        let meshes: Vec<DensitySampler<'a>> = meshes.into_iter().collect();
        let (top, shares) = Self::top(&meshes)?;
        Ok(Self {
            meshes,
            top,
            shares,
        })
    }

    fn top(meshes: &[DensitySampler<'a>]) -> Result<(GuideTable, Vec<f64>), Error> {
        if meshes.is_empty() {
            return Err(Error::Empty);
        }
        let masses: Vec<f64> = meshes.iter().map(DensitySampler::total_mass).collect();
        let total: f64 = masses.iter().sum();
        // Every sampler has a positive finite mass, so this cannot fail.
        let top = GuideTable::new(&masses).map_err(|_| Error::ZeroDensity {
            triangles: meshes.iter().map(|m| m.mesh().indices.len()).sum(),
        })?;
        Ok((top, masses.iter().map(|m| m / total).collect()))
    }

    /// Replaces the sampler of mesh `index` (after an edit of the mesh or
    /// its density), rebuilding only the top-level table.
    ///
    /// # Errors
    /// [`Error::NoSuchMesh`]; the sampler is unchanged then.
    pub fn replace(&mut self, index: usize, sampler: DensitySampler<'a>) -> Result<(), Error> {
        let count = self.meshes.len();
        if index >= count {
            return Err(Error::NoSuchMesh { index, count });
        }
        self.meshes[index] = sampler;
        (self.top, self.shares) = Self::top(&self.meshes)?;
        Ok(())
    }

    /// Number of meshes.
    pub fn len(&self) -> usize {
        self.meshes.len()
    }

    /// Always `false`: a sampler has at least one mesh.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The total mass `ΣM` over all meshes.
    pub fn total_mass(&self) -> f64 {
        self.meshes.iter().map(DensitySampler::total_mass).sum()
    }

    /// The density (w.r.t. the area of all meshes) at barycentrics of
    /// `face` of mesh `mesh`; 0 for no such mesh or face.
    pub fn pdf(&self, mesh: usize, face: usize, barycentric: [f32; 3]) -> f32 {
        match self.meshes.get(mesh) {
            Some(m) => (f64::from(m.pdf(face, barycentric)) * self.shares[mesh]) as f32,
            None => 0.0,
        }
    }

    /// `n` points from `seed`, the same on any number of threads.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] if `n` exceeds [`MAX_POINTS`](crate::MAX_POINTS).
    pub fn sample_n(&self, seed: u64, n: usize) -> Result<Vec<MeshPoint>, Error> {
        sample_points(self, seed, n)
    }
}

impl Distribution<MeshPoint> for MultiDensitySampler<'_> {
    /// One `u64` for the mesh, then the mesh's own sampler.
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> MeshPoint {
        let mesh = self.top.sample_rng(rng);
        let mut point = self.meshes[mesh].sample(rng);
        point.pdf = (f64::from(point.pdf) * self.shares[mesh]) as f32;
        MeshPoint { mesh, point }
    }
}

/// `n` points of `sampler` from `seed`, in chunks with their own streams.
fn sample_points(
    sampler: &(impl Distribution<MeshPoint> + Sync),
    seed: u64,
    n: usize,
) -> Result<Vec<MeshPoint>, Error> {
    crate::parallel::check_points(n as f64)?;
    let mut out = vec![MeshPoint::default(); n];
    for_each_chunk(seed, &mut out, |rng, chunk| {
        for slot in chunk {
            *slot = sampler.sample(rng);
        }
    });
    Ok(out)
}
