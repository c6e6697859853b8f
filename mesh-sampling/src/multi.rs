//! Several meshes at once (the uniform-mesh-sampling article, last
//! section): a small CDF over the meshes by total area above one sampler
//! per mesh. Replacing or editing one mesh rebuilds only its own table and
//! the top-level one, not a CDF over every triangle of the scene.

use discrete_sampling::{DiscreteSampler, GuideTable};
use rand::distr::Distribution;

use crate::parallel::{for_each_chunk, unit};
use crate::{Error, MeshRef, SurfacePoint, UniformSampler};

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
    /// barycentric variate.
    pub fn sample_u(&self, u: [f64; 2]) -> MeshPoint {
        let (mesh, rest) = self.top.sample_remapped(u[0]);
        let mut point = self.meshes[mesh].sample_u([rest, u[1]]);
        point.pdf = self.density;
        MeshPoint { mesh, point }
    }

    /// `n` points from `seed`, the same on any number of threads.
    pub fn sample_n(&self, seed: u64, n: usize) -> Vec<MeshPoint> {
        let mut out = vec![MeshPoint::default(); n];
        for_each_chunk(seed, &mut out, |rng, chunk| {
            for slot in chunk {
                *slot = self.sample(rng);
            }
        });
        out
    }
}

impl Distribution<MeshPoint> for MultiMeshSampler<'_> {
    fn sample<R: rand::Rng + ?Sized>(&self, rng: &mut R) -> MeshPoint {
        let u0 = unit(rng.next_u64());
        let u1 = unit(rng.next_u64());
        self.sample_u([u0, u1])
    }
}
